"""Fits and pin retention: the process fields (press-fit interference, retention) and their bounds, the hole
sizes (nominal vs modelled), and the standard pin each retention scheme takes for a stack."""

from __future__ import annotations

import dataclasses

import pytest

from fabricate.catalogue.clips import e_clip
from fabricate.catalogue.pins import ISO2338_LENGTHS_MM, ISO8734_LENGTHS_MM, pin_lengths
from fabricate.errors import SpecError
from fabricate.parts.retention import (
    SHORT_OF_END,
    choose_holder,
    fill_layer_gap,
    hole_label,
    hole_size,
    plan_pin,
)
from fabricate.process import parse_process, process_override
from fabricate.table import Table


def _process(**fields):
    return parse_process(Table(dict(fields), "process"))


# -- the profile fields ------------------------------------------------------------------------------------
def test_shipped_profiles_state_their_fits():
    sla = _process(profile="sla")
    assert sla.retention == "press" and sla.press_fit_interference_mm == pytest.approx(0.05)  # standard resin
    assert _process(profile="sla", material="tough_resin").press_fit_interference_mm == pytest.approx(0.1)
    laser = _process(profile="laser")
    assert laser.retention == "clip" and laser.press_fit_interference_mm == 0.0  # acrylic takes no press fit
    ply = _process(profile="laser", material="birch_plywood", retention="press")
    assert ply.retention == "press" and ply.press_fit_interference_mm == pytest.approx(0.06)


def test_press_fit_in_acrylic_is_refused_naming_retention():
    with pytest.raises(SpecError) as err:
        _process(profile="laser", retention="press")
    assert err.value.path == "process.retention" and "acrylic" in err.value.message and "clip" in err.value.message


@pytest.mark.parametrize("fields, path", [
    ({"retention": "glue"}, "process.retention"),
    ({"press_fit_interference_mm": -0.01}, "process.press_fit_interference_mm"),
    ({"press_fit_interference_mm": 0.6}, "process.press_fit_interference_mm"),
    ({"press_fit_interference_mm": "tight"}, "process.press_fit_interference_mm"),
    ({"retention": "press", "press_fit_interference_mm": 0.0}, "process.retention"),
])
def test_bad_fit_values_are_spec_errors(fields, path):
    with pytest.raises(SpecError) as err:
        _process(profile="sla", **fields)
    assert err.value.path == path


def test_a_profile_override_keeps_the_fits_of_the_override():
    """--process laser replaces the template's fits too (they belong to the process, not the design)."""
    table = Table({"profile": "sla", "retention": "press", "press_fit_interference_mm": 0.08}, "process")
    spec = parse_process(table, process_override("laser"))
    assert spec.retention == "clip" and spec.press_fit_interference_mm == 0.0


def test_a_profile_without_the_fields_takes_its_methods_or_clip(tmp_path):
    """A --process file older than the fields: a shipped method's values, else clip (needs no interference)."""
    from fabricate.templates import TEMPLATE_DIR

    text = (TEMPLATE_DIR / "process_sla.toml").read_text()
    old = "\n".join(line for line in text.splitlines() if not line.startswith(("retention", "press_fit")))
    spec = parse_process(Table({}, "process"), dataclasses.replace(process_override("sla"), text=old))
    assert spec.retention == "press" and spec.press_fit_interference_mm == pytest.approx(0.05)
    other = old.replace('method = "sla"', 'method = "resin2"')
    spec = parse_process(Table({}, "process"), dataclasses.replace(process_override("sla"), text=other))
    assert spec.retention == "clip"


# -- hole sizes --------------------------------------------------------------------------------------------
def test_nominal_and_modelled_hole_sizes_are_kept_apart():
    sla = _process(profile="sla", pin_diameter_mm=2.0)
    press, running = hole_size(sla, 2.0, "press"), hole_size(sla, 2.0, "running")
    assert press.nominal_mm == pytest.approx(1.95) and press.modelled_mm == pytest.approx(2.15)
    assert running.nominal_mm == pytest.approx(2.5) and running.modelled_mm == pytest.approx(2.7)
    assert press.compensation_mm == pytest.approx(0.2) == running.compensation_mm
    assert hole_label("press", 1.95, 2.15, "sla") == "Ø1.95 press (CAD Ø2.15 incl. +0.2 sla compensation)"
    assert hole_label("running", 3.2, 3.2, "laser") == "Ø3.2 running"


# -- pins --------------------------------------------------------------------------------------------------
def test_press_pin_ends_inside_the_end_parts_when_a_standard_length_allows():
    sla = _process(profile="sla", pin_diameter_mm=2.0)
    plan = plan_pin("A", sla, (0.0, 6.3), "crank", (0.0, 3.0), end_thickness_mm=(3.0, 3.0))
    assert plan.choice.designation == "ISO 8734 2 × 6" and plan.length_mm in ISO8734_LENGTHS_MM
    # 0.3 mm short of the holder's (bottom) face, flush with the top: nothing sticks out of the stack
    assert plan.ends[0].protrusion_mm == pytest.approx(-0.3) and plan.ends[1].protrusion_mm == 0.0
    assert plan.engagement_mm == pytest.approx(2.7) and plan.z_mm == pytest.approx(0.3)
    # a pin as long as the stack whenever one is: no shortfall at all
    exact = plan_pin("A", sla, (0.0, 12.0), "crank", (0.0, 3.0), end_thickness_mm=(3.0, 3.0))
    assert exact.length_mm == 12.0 and exact.ends[0].protrusion_mm == exact.ends[1].protrusion_mm == 0.0


def test_press_pin_short_of_the_stack_keeps_two_thirds_of_each_end_part():
    sla = _process(profile="sla", pin_diameter_mm=3.0)
    longest = pin_lengths(3.0, "ISO 8734")[-1]
    plan = plan_pin("A", sla, (0.0, 36.6), "palm", (0.0, 12.0), end_thickness_mm=(12.0, 12.0))
    assert plan.length_mm == longest == 30.0
    # 6.6 mm short: the holder's end takes its third (4 mm), the top part the rest
    assert plan.ends[0].protrusion_mm == pytest.approx(-12.0 * SHORT_OF_END)
    assert plan.ends[1].protrusion_mm == pytest.approx(-(6.6 - 12.0 * SHORT_OF_END))
    assert plan.engagement_mm == pytest.approx(12.0 * (1 - SHORT_OF_END))
    with pytest.raises(SpecError) as err:  # 3 mm end parts cannot take 6.6 mm, and no pin reaches
        plan_pin("A", sla, (0.0, 36.6), "palm", (0.0, 3.0), end_thickness_mm=(3.0, 3.0))
    assert err.value.path == "process.pin_diameter_mm" and "longest ISO 8734" in err.value.message


def test_press_pin_that_must_stick_out_does_so_where_no_layer_lies_beyond():
    sla = _process(profile="sla", pin_diameter_mm=3.0)  # the shortest Ø3 ISO 8734 pin is 8 mm
    kwargs = dict(holder_z_mm=(3.3, 6.3), end_thickness_mm=(3.0, 3.0))
    top_free = plan_pin("A", sla, (3.3, 9.6), "crank", free_ends=(False, True), **kwargs)
    assert top_free.length_mm == 8.0 and top_free.length_mm >= top_free.stack_mm + top_free.allowance_mm
    assert top_free.ends[0].protrusion_mm == 0.0 and top_free.ends[1].protrusion_mm == pytest.approx(1.7)
    bottom_free = plan_pin("A", sla, (3.3, 9.6), "crank", free_ends=(True, False), **kwargs)
    assert bottom_free.ends[0].protrusion_mm == pytest.approx(1.7) and bottom_free.z_mm == pytest.approx(1.6)
    # layers on both sides: out of the holder's outer face (the holder grips it there)...
    boxed = plan_pin("A", sla, (3.3, 9.6), "crank", **kwargs)
    assert boxed.ends[0].protrusion_mm == pytest.approx(1.7)
    # ...but never out of the ground's mounting face
    ground = plan_pin("A", sla, (3.3, 9.6), "frame", holder_is_ground=True, **kwargs)
    assert ground.ends[0].protrusion_mm == 0.0 and ground.ends[1].protrusion_mm == pytest.approx(1.7)


def test_clip_pin_sticks_out_for_the_ring_at_both_ends():
    laser = _process(profile="laser")
    ring = e_clip(3.0)
    plan = plan_pin("B", laser, (0.0, 6.5))
    assert plan.choice.designation.startswith("ISO 2338 3 × ") and plan.length_mm in ISO2338_LENGTHS_MM
    assert plan.allowance_mm == pytest.approx(2 * (ring.groove_w_mm + ring.edge_margin_mm))
    assert plan.length_mm >= plan.stack_mm + plan.allowance_mm
    for end in plan.ends:
        assert end.retainer == ring
        # washers, the groove and what is left beyond it make up the end's protrusion
        assert end.washer_mm + ring.groove_w_mm + end.groove_from_end_mm == pytest.approx(end.protrusion_mm)
        assert end.groove_from_end_mm >= ring.edge_margin_mm
    assert sum(e.protrusion_mm for e in plan.ends) + plan.stack_mm == pytest.approx(plan.length_mm)


def test_cap_pin_takes_a_cap_at_each_end():
    sla = dataclasses.replace(_process(profile="sla", pin_diameter_mm=2.0), retention="cap")
    plan = plan_pin("C", sla, (0.0, 6.3))
    assert all(e.cap_mm == 2.0 and e.protrusion_mm >= 2.0 for e in plan.ends)
    assert plan.length_mm >= 6.3 + 4.0 and plan.length_mm in ISO8734_LENGTHS_MM


def test_holder_is_a_part_with_a_hole_at_an_end_of_the_stack():
    layers = {"a": 1, "b": 0, "c": 2}
    assert choose_holder(("a", "b", "c"), layers, ("a", "b", "c")) == "b"  # a is in the middle
    assert choose_holder(("a", "b"), {"a": 0, "b": 1}, ("b",)) == "b"  # a runs in its slot (guide pin)


def test_layer_gap_washers_are_standard_and_never_overfill():
    (washer,) = fill_layer_gap(2.0, 0.3)
    assert washer.alt_designation == "DIN 125-A 2.2" and washer.h_mm == 0.3
    assert fill_layer_gap(2.5, 0.1) == ()  # nothing that thin: the gap stays as axial play
    stack = fill_layer_gap(3.0, 4.0)
    assert 4.0 - 0.05 - 1e-9 <= sum(w.h_mm for w in stack) <= 4.0 + 1e-9
