"""Fits and pin retention: the process fields (press-fit interference, retention) and their bounds, the hole
sizes (nominal vs modelled), and the standard pin each retention scheme takes for a stack."""

from __future__ import annotations

import dataclasses
import math

import pytest

from fabricate.catalogue.clips import e_clip
from fabricate.catalogue.pins import ISO2338_LENGTHS_MM, ISO8734_LENGTHS_MM, pin_lengths
from fabricate.errors import SpecError
from fabricate.parts.retention import (
    choose_holder,
    end_radius_mm,
    end_reach_mm,
    fill_layer_gap,
    hole_label,
    hole_size,
    plan_pin,
    press_stub_at_bottom,
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
def test_press_pin_is_the_shortest_standard_pin_over_the_stack_flush_at_one_end():
    sla = _process(profile="sla", pin_diameter_mm=2.0)
    plan = plan_pin("A", sla, (0.0, 6.3), "crank", (0.0, 3.0))
    # 6 mm would end inside the stack: the next standard length, 8 mm, covers it
    assert plan.choice.designation == "ISO 8734 2 × 8" and plan.length_mm in ISO8734_LENGTHS_MM
    assert plan.length_mm >= plan.stack_mm + plan.allowance_mm and plan.allowance_mm == 0.0
    # flush with the bottom, the standard length's extra (1.7 mm) a bare stub out of the top
    assert plan.ends[0].protrusion_mm == 0.0 and plan.ends[1].protrusion_mm == pytest.approx(1.7)
    assert plan.ends[1].washers == () and plan.ends[1].retainer is None
    assert plan.engagement_mm == pytest.approx(3.0) and plan.z_mm == pytest.approx(0.0)
    # a stack a standard length long: flush at both ends
    exact = plan_pin("A", sla, (0.0, 12.0), "crank", (0.0, 3.0))
    assert exact.length_mm == 12.0 and exact.ends[0].protrusion_mm == exact.ends[1].protrusion_mm == 0.0


def test_press_pin_no_standard_length_covers_is_refused_naming_the_pin_diameter():
    sla = _process(profile="sla", pin_diameter_mm=3.0)
    assert pin_lengths(3.0, "ISO 8734")[-1] == 30.0
    with pytest.raises(SpecError) as err:  # the gripper's 3 x 12 mm plates: 36.6 mm, past Ø3's 30 mm
        plan_pin("A", sla, (0.0, 36.6), "palm", (0.0, 12.0))
    assert err.value.path == "process.pin_diameter_mm" and "longest ISO 8734" in err.value.message
    assert plan_pin("A", _process(profile="sla", pin_diameter_mm=4.0), (0.0, 36.6), "palm").length_mm == 40.0


def test_press_stub_sticks_out_of_the_top_unless_only_the_bottom_is_free():
    sla = _process(profile="sla", pin_diameter_mm=3.0)  # the shortest Ø3 ISO 8734 pin is 8 mm
    stubs = {}
    for free in ((False, True), (True, False), (False, False), (True, True)):
        plan = plan_pin("A", sla, (3.3, 9.6), "crank", (3.3, 6.3), free_ends=free)
        assert plan.length_mm == 8.0 and sorted(e.protrusion_mm for e in plan.ends) == pytest.approx([0.0, 1.7])
        stubs[free] = "bottom" if plan.ends[0].protrusion_mm > 0 else "top"
        assert stubs[free] == ("bottom" if press_stub_at_bottom(free) else "top")
        assert plan.z_mm == pytest.approx(1.6 if stubs[free] == "bottom" else 3.3)
    assert stubs == {(False, True): "top", (True, False): "bottom", (False, False): "top", (True, True): "top"}


def test_end_reach_is_the_stub_or_infinite_where_no_standard_pin_covers():
    sla = _process(profile="sla", pin_diameter_mm=3.0)
    assert end_reach_mm(sla, 6.3) == pytest.approx(1.7) and end_reach_mm(sla, 8.0) == 0.0
    assert end_reach_mm(sla, 9.6) == pytest.approx(0.4) and end_reach_mm(sla, 30.01) == math.inf
    assert end_radius_mm(sla) == 1.5  # the bare pin


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
