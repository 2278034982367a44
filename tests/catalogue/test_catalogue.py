"""The hardware catalogue: every number sourced, and the pickers choose from the standard series."""

from __future__ import annotations

import ast
import dataclasses
import io
import math
import tokenize
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.catalogue import (
    CATALOGUE,
    actuator,
    clips,
    dowel_pin,
    e_clip,
    pins,
    screw,
    shim_ring,
    tendon,
    torsion_spring,
)
from fabricate.catalogue import actuators as act_mod
from fabricate.catalogue import hardware as hw
from fabricate.catalogue import springs as sp
from fabricate.errors import SpecError

CATALOGUE_DIR = Path(act_mod.__file__).parent
MODULES = ("_units.py", "actuators.py", "clips.py", "designations.py", "hardware.py", "pins.py", "springs.py",
           "tables.py")
#: Module-level names that are numerical tolerances, not catalogue data.
NOT_DATA = {"EPS"}


# --- every number has its source -------------------------------------------------------------------------


@pytest.mark.parametrize("module", MODULES)
def test_every_catalogue_number_has_a_source_comment_on_its_line(module):
    """A number in a module-level table or entry (anything but 0 and the unit sign 1) sits on a line
    that carries a comment saying where it comes from."""
    src = (CATALOGUE_DIR / module).read_text()
    commented = {tok.start[0] for tok in tokenize.generate_tokens(io.StringIO(src).readline)
                 if tok.type == tokenize.COMMENT}
    bare = []
    for node in ast.parse(src).body:
        if not isinstance(node, (ast.Assign, ast.AnnAssign)):
            continue
        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        if any(isinstance(t, ast.Name) and t.id in NOT_DATA for t in targets):
            continue
        for sub in ast.walk(node):
            if (isinstance(sub, ast.Constant) and isinstance(sub.value, (int, float))
                    and not isinstance(sub.value, bool) and sub.value not in (0, 1)
                    and sub.lineno not in commented):
                bare.append((sub.lineno, sub.value))
    assert not bare, f"{module}: numbers without a source comment on their line: {bare}"


def _numbers_in(value) -> bool:
    if value is None or isinstance(value, str):
        return False
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    if dataclasses.is_dataclass(value):
        return any(_numbers_in(getattr(value, f.name)) for f in dataclasses.fields(value))
    if isinstance(value, (tuple, list)):
        return any(_numbers_in(v) for v in value)
    return False


#: What each kind of actuator must state (a value with a source, or a stated gap).
REQUIRED = {
    "servo": ("body", "mounting_holes", "spline", "horn", "rated_torque_nmm", "stall_torque_nmm",
              "no_load_speed", "voltage_v"),
    "gearmotor": ("body", "mounting_holes", "shaft", "rated_torque_nmm", "stall_torque_nmm", "no_load_speed",
                  "voltage_v"),
    "stepper": ("body", "mounting_holes", "shaft", "rated_torque_nmm", "stall_torque_nmm", "no_load_speed",
                "voltage_v"),
    "linear": ("body", "mounting_holes", "rated_force_n", "stall_force_n", "no_load_speed", "voltage_v",
               "stroke_mm", "closed_length_mm"),
    "tendon": ("rated_force_n",),
}


@pytest.mark.parametrize("key", sorted(CATALOGUE))
def test_every_actuator_number_has_a_source_and_every_missing_value_a_reason(key):
    a = CATALOGUE[key]
    sources = dict(a.sources)
    gaps = dict(a.gaps)
    assert len(sources) == len(a.sources) and len(gaps) == len(a.gaps)    # no field listed twice
    for f in dataclasses.fields(a):
        if f.name in ("key", "name", "kind", "sources", "gaps"):
            continue
        value = getattr(a, f.name)
        if _numbers_in(value):
            text = sources.get(f.name, "")
            assert "http" in text, f"{key}.{f.name} has numbers but no source naming a document: {text!r}"
            assert f.name not in gaps, f"{key}.{f.name} is both given and listed missing"
        if dataclasses.is_dataclass(value):                 # a sub-value left out is a stated gap
            for sub in dataclasses.fields(value):
                if getattr(value, sub.name) is None:
                    assert f"{f.name}.{sub.name}" in gaps, f"{key}.{f.name}.{sub.name} is None without a reason"
    for name in REQUIRED[a.kind]:
        value = getattr(a, name)
        assert (value is not None and value != ()) or name in gaps, f"{key}.{name} neither given nor explained"
    for name, why in a.gaps:
        assert why.strip(), f"{key}: gap {name} has no reason"
        assert getattr(a, name.split(".")[0]) is not None or "." not in name


def test_actuator_frames_put_the_output_on_the_z_axis_and_the_holes_in_the_flanges():
    """Servos: the spline leaves the top face at the origin; every tab hole lies inside a body box in
    x and y at the face it is on. Steppers: the holes lie on the body's mounting face (z = 0)."""
    for a in CATALOGUE.values():
        if not a.body or not a.mounting_holes:
            continue
        env = a.envelope
        assert env.z1 >= 0.0 >= env.z0                       # the output face is within the body's z span
        for h in a.mounting_holes:
            assert any(b.x0 < h.x < b.x1 and b.y0 < h.y < b.y1 and b.z0 <= h.z <= b.z1 for b in a.body), (
                a.key, h)
            assert not (abs(h.x) < 1e-9 and abs(h.y) < 1e-9)  # a hole is never on the output axis
    sg90 = actuator("sg90")
    assert max(b.z1 for b in sg90.body) == pytest.approx(0.0)
    # the two tab holes straddle the case; the axle is off the case centre, so they are not symmetric in x
    xs = sorted(h.x for h in sg90.mounting_holes)
    assert xs[0] < sg90.envelope.x0 + 5.0 and xs[1] > sg90.body[0].x1
    assert xs[0] + xs[1] == pytest.approx(-2 * 6.19)


def test_datasheet_units_are_converted():
    """kgf·cm, kg·mm, gf·cm, RPM and s/60° become N·mm and °/s (a factor of 10 lost would show)."""
    assert actuator("sg90").stall_torque_nmm == pytest.approx(1.8 * 9.80665 * 10)
    assert actuator("n20").stall_torque_nmm == pytest.approx(7.4 * 9.80665)
    assert actuator("28byj48").rated_torque_nmm == pytest.approx(300 * 9.80665 / 100)
    assert actuator("n20").no_load_speed == pytest.approx(130 * 6)
    assert actuator("sg90").no_load_speed == pytest.approx(600)
    assert actuator("l16").speed_unit == "mm/s" and actuator("sg90").speed_unit == "deg/s"


def test_tendon_takes_its_force_from_the_template_and_unknown_keys_are_refused():
    assert not CATALOGUE["tendon"].complete
    t = tendon(40.0)
    assert t.complete and t.rated_force_n == 40.0 and "template" in t.source("rated_force_n")
    assert t.body == () and t.envelope is None
    with pytest.raises(SpecError) as err:
        tendon(-1.0)
    assert err.value.path == "force_n"
    with pytest.raises(SpecError) as err:
        actuator("mg995")
    assert err.value.path == "actuator"


def test_complete_entries_have_body_mount_interface_and_rating():
    for a in CATALOGUE.values():
        if a.complete and a.kind != "tendon":
            assert a.body and a.mounting_holes
            assert a.spline is not None or a.shaft is not None or a.kind == "linear"
            assert (a.stall_torque_nmm or a.rated_torque_nmm or a.stall_force_n or a.rated_force_n)
    assert {k for k, a in CATALOGUE.items() if a.complete} >= {"sg90", "mg90s", "mg996r", "nema17", "28byj48"}


# --- dowel pins ------------------------------------------------------------------------------------------

PIN_DIAMETERS = (1.5, 2.0, 2.5, 3.0, 4.0, 5.0)


@pytest.mark.parametrize("standard", ["ISO 8734", "ISO 2338"])
@pytest.mark.parametrize("d", PIN_DIAMETERS)
def test_dowel_pin_picks_the_next_series_length(d, standard):
    series = pins.pin_lengths(d, standard)
    assert len(series) >= 5 and list(series) == sorted(series)
    lo, hi = series[0], series[-1]
    for need in [0.5, lo, lo + 0.01, *(0.5 * (a + b) for a, b in zip(series, series[1:], strict=False)), hi]:
        designation, length = dowel_pin(d, need, standard)
        assert length in series and length >= need
        shorter = [v for v in series if v < length]
        assert not shorter or shorter[-1] < need               # nothing shorter in the series would do
        assert designation == f"{standard} {d:g} × {length:g}"
    with pytest.raises(SpecError) as err:
        dowel_pin(d, hi + 0.01, standard)
    assert err.value.path == "min_length_mm"


def test_dowel_pin_examples_and_refusals():
    assert dowel_pin(2, 18.6) == ("ISO 8734 2 × 20", 20.0)     # the Ø2 × 18.60 pin
    assert dowel_pin(2, 12.3).length_mm == 14.0
    for d, path in ((1.8, "diameter_mm"), (0.0, "diameter_mm"), (float("nan"), "diameter_mm")):
        with pytest.raises(SpecError) as err:
            dowel_pin(d, 10)
        assert err.value.path == path
    with pytest.raises(SpecError) as err:
        dowel_pin(2, -1)
    assert err.value.path == "min_length_mm"
    with pytest.raises(SpecError) as err:
        dowel_pin(2, 10, "DIN 7")
    assert err.value.path == "standard"


# --- screws, washers, shims, E-clips ---------------------------------------------------------------------


@pytest.mark.parametrize("standard", ["ISO 4762", "ISO 7380"])
@pytest.mark.parametrize("clamp", [1.0, 3.2, 6.0, 11.5])
@pytest.mark.parametrize("engagement", [2.0, 4.5])
def test_screw_length_covers_clamp_and_engagement(standard, clamp, engagement):
    table, lengths, _ = hw.SCREW_SERIES[standard]
    for size, row in table.items():
        s = screw(size, clamp, engagement, standard)
        assert s.length_mm in lengths and row.min_length_mm <= s.length_mm <= row.max_length_mm
        assert s.length_mm >= clamp + engagement
        assert s.engagement_mm == pytest.approx(s.length_mm - clamp) and s.engagement_mm >= engagement
        assert s.thread_length_mm >= engagement
        shorter = [v for v in lengths if row.min_length_mm <= v < s.length_mm]
        assert not shorter or shorter[-1] < clamp + engagement   # the shortest that reaches
        assert s.designation == f"{standard} {size} × {s.length_mm:g}"
        assert s.head_d_mm > float(size[1:]) and s.head_h_mm > 0


def test_screw_refusals_name_the_field():
    cases = [(("M3", 40.0, 5.0), "clamp_mm"), (("M2", 10.0, 0.0), "engagement_mm"),
             (("M7", 5.0, 5.0), "size"), (("M3", -1.0, 5.0), "clamp_mm")]
    for args, path in cases:
        with pytest.raises(SpecError) as err:
            screw(*args)
        assert err.value.path == path
    with pytest.raises(SpecError) as err:
        screw("M2", 3.0, 3.0, "ISO 7380")                       # ISO 7380-1 starts at M3
    assert err.value.path == "size"
    with pytest.raises(SpecError) as err:
        screw("M3", 3.0, 3.0, "DIN 84")
    assert err.value.path == "standard"


def test_washers_and_shims():
    for size, row in hw.ISO7089.items():
        w = hw.washer(size)
        assert (w.d1_mm, w.d2_mm, w.h_mm) == row
        assert float(size[1:]) < w.d1_mm < w.d2_mm and w.h_mm > 0
        assert w.designation == f"ISO 7089 {size[1:]}" and w.alt_designation == f"DIN 125-A {row[0]:g}"
    assert hw.washer_for_shaft(2.0).d1_mm == 2.2 and hw.washer_for_shaft(2.3).d1_mm == 2.7
    assert hw.washer_for_shaft(3.0).designation == "ISO 7089 3"
    with pytest.raises(SpecError) as err:
        hw.washer_for_shaft(8.5)
    assert err.value.path == "diameter_mm"
    with pytest.raises(SpecError) as err:
        hw.washer("M7")
    assert err.value.path == "size"
    s = shim_ring(3, 0.5)
    assert (s.d1_mm, s.d2_mm, s.h_mm) == (3.0, 6.0, 0.5) and s.designation == "DIN 988 3 × 6 × 0.5"
    for args, path in (((2.0, 0.5), "shaft_mm"), ((3.0, 0.3), "thickness_mm")):
        with pytest.raises(SpecError) as err:
            shim_ring(*args)
        assert err.value.path == path


def test_e_clip_table_joins_up_and_each_pin_gets_a_groove_it_can_hold():
    rows = sorted(clips.DIN6799.items())
    for (_, a), (_, b) in zip(rows, rows[1:], strict=False):
        assert a[0] < b[0] and b[0] <= a[1]                     # ranges ascend and leave no gap
    for d in PIN_DIAMETERS:
        ring = e_clip(d)
        assert ring.shaft_min_mm < d <= ring.shaft_max_mm
        assert ring.groove_d_mm < d < ring.ring_od_mm           # a groove in the pin, a ring round it
        assert ring.groove_w_mm > ring.ring_s_mm                # the ring fits its groove
        assert ring.protrusion_mm == pytest.approx(ring.groove_w_mm + ring.edge_margin_mm)
    assert e_clip(2.0).groove_d_mm == 1.2 and e_clip(2.01).groove_d_mm == 1.5
    for d in (1.4, 9.5):
        with pytest.raises(SpecError) as err:
            e_clip(d)
        assert err.value.path == "shaft_mm"


# --- torsion springs -------------------------------------------------------------------------------------


def _check_spring(s, rate, angle, preload, pin):
    """Recompute a spring from d, D, N by the formulas, independently of the sizing code."""
    wire_mm = [d_in * 25.4 for d_in, _ in sp.MUSIC_WIRE_IN_KSI]
    assert any(abs(s.wire_d_mm - w) < 1e-9 for w in wire_mm)   # a wire of the series
    d, big_d, n = s.wire_d_mm, s.mean_d_mm, s.active_turns
    e = 203_400.0 if s.wire_d_in < 0.0325 else 200_000.0 if s.wire_d_in < 0.0635 else 196_500.0
    k = e * d**4 / (10.8 * big_d * n) / 360.0                    # N·mm per degree
    assert k == pytest.approx(rate, rel=0.01)
    theta = preload / rate + angle
    m = rate * theta
    assert s.max_torque_nmm == pytest.approx(m) and s.max_deflection_deg == pytest.approx(theta)
    c = big_d / d
    kb = (4 * c * c - c - 1) / (4 * c * (c - 1))
    sigma = kb * 32 * m / (math.pi * d**3)
    assert s.stress_mpa == pytest.approx(sigma, rel=1e-6)
    assert sigma <= s.allowable_mpa * (1 + 1e-9)
    ksi = dict(sp.MUSIC_WIRE_IN_KSI)[s.wire_d_in]
    assert s.allowable_mpa == pytest.approx(0.65 * ksi * 6.894757, rel=1e-6)
    wound_inner = big_d * n / (n + theta / 360.0) - d
    assert wound_inner == pytest.approx(s.inner_d_wound_mm)
    assert wound_inner >= pin and 0.9 * wound_inner >= pin * (1 - 1e-9)
    assert 4.0 - 1e-9 <= c <= 16.0 + 1e-9 and n >= 2.0 - 1e-9
    assert s.body_length_wound_mm == pytest.approx(d * (n + 1 + theta / 360.0))
    assert s.outer_d_mm == pytest.approx(big_d + d) and s.inner_d_mm == pytest.approx(big_d - d)


@pytest.mark.parametrize(("rate", "angle", "preload", "legs", "pin"), [
    (2.0, 45.0, 10.0, 10.0, 2.0),
    (0.5, 90.0, 0.0, (8.0, 12.0), 2.0),
    (5.0, 60.0, 20.0, 12.0, 3.0),
    (0.05, 90.0, 0.0, 8.0, 1.5),
    (20.0, 30.0, 0.0, 15.0, 4.0),
])
def test_torsion_spring_meets_rate_stress_and_pin_clearance(rate, angle, preload, legs, pin):
    s = torsion_spring(rate, angle, preload, legs, pin)
    _check_spring(s, rate, angle, preload, pin)
    assert s.leg_lengths_mm == (legs if isinstance(legs, tuple) else (legs, legs))
    assert "music wire" in s.designation and len(s.sources) >= 5


@settings(max_examples=40, deadline=None)
@given(rate=st.floats(0.02, 30.0), angle=st.floats(5.0, 270.0), preload=st.floats(0.0, 50.0),
       pin=st.floats(1.0, 5.0))
def test_torsion_spring_is_valid_or_refused(rate, angle, preload, pin):
    try:
        s = torsion_spring(rate, angle, preload, 10.0, pin)
    except SpecError as err:
        assert err.path == "rate_nmm_per_deg"
        return
    _check_spring(s, rate, angle, preload, pin)


def test_a_stiffer_or_further_wound_spring_needs_thicker_wire():
    soft = torsion_spring(1.0, 60.0, 0.0, 10.0, 2.0)
    stiff = torsion_spring(10.0, 60.0, 0.0, 10.0, 2.0)
    far = torsion_spring(1.0, 240.0, 0.0, 10.0, 2.0)
    assert stiff.wire_d_mm > soft.wire_d_mm and far.wire_d_mm > soft.wire_d_mm


def test_impossible_spring_and_bad_inputs_raise_spec_error():
    with pytest.raises(SpecError) as err:
        torsion_spring(1000.0, 90.0, 0.0, 10.0, 2.0)             # no music wire takes 90000 N·mm
    assert err.value.path == "rate_nmm_per_deg"
    with pytest.raises(SpecError) as err:
        torsion_spring(0.01, 90.0, 0.0, 10.0, 60.0)              # Ø60 pin: over 16 × the thickest wire
    assert err.value.path == "rate_nmm_per_deg"
    bad = [({"rate_nmm_per_deg": -1.0}, "rate_nmm_per_deg"), ({"max_angle_deg": 0.0}, "max_angle_deg"),
           ({"preload_nmm": -2.0}, "preload_nmm"), ({"pin_diameter_mm": float("inf")}, "pin_diameter_mm"),
           ({"leg_length_mm": (5.0, 6.0, 7.0)}, "leg_length_mm"), ({"material": "steel"}, "material")]
    base = {"rate_nmm_per_deg": 1.0, "max_angle_deg": 45.0}
    for change, path in bad:
        with pytest.raises(SpecError) as err:
            torsion_spring(**{**base, **change})
        assert err.value.path == path
