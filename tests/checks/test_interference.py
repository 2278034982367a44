"""Interference sweep: sampling of the worst overlap, parts-layer pins, the naive reference with pins and
spacers, and the wording and boundaries of the verdict, each against closed-form geometry.

Written to kill mutants of ``fabricate/checks/interference.py`` (see ``tests/benchmarks/mutation_report.md``).
The solids here are boxes (exact polygons at any chord tolerance) moved by hand-made motions, so every
overlap area and distance is a product of known lengths; circles are checked against pi r^2 within the
area an inscribed polygon of sagitta ``tol`` can lose (at most its perimeter times ``tol``).

Then (formerly tests/test_interference.py, with its own ``CHORD_TOL`` and ``motion_with_a``): exact volumes
and clearances against shapely, a deliberately colliding four-bar, and the naive all-pairs boolean reference.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from fabricate.checks.distance import Outline, RelativePoses, planar_clearance
from fabricate.checks.interference import OVERLAP_SAMPLES, naive_interference, sweep_interference
from fabricate.checks.items import PinSolid, pins_from_parts_layer
from fabricate.mechanism import Motion
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.planar import transform_points
from tests.conftest import make_four_bar
from tests.interference_fixtures import four_bar_parts

TOL = 0.002  # chord tolerance of the polygonised solids, mm


def box_part(name: str, body: str, size: tuple[float, float], z: float, thickness: float, *,
             centre: tuple[float, float] = (0.0, 0.0), holes: tuple[Hole, ...] = ()) -> Part:
    """A ``size`` rectangle centred on ``centre`` of its body frame, extruded from ``z`` by ``thickness``."""
    w, h = size
    cx, cy = centre
    outline = BulgePath.polyline(np.array([[cx - w / 2, cy - h / 2], [cx + w / 2, cy - h / 2],
                                           [cx + w / 2, cy + h / 2], [cx - w / 2, cy + h / 2]]))
    return Part(name, body, outline, holes, thickness, z, 0, "sla")


def motion_of(poses_b: np.ndarray, inputs: np.ndarray | None = None) -> Motion:
    """A bare Motion of bodies 'a' (at rest on the ground pose) and 'b' (``poses_b``), ground 'g'."""
    n = len(poses_b)
    inputs = np.arange(n, dtype=np.float64) if inputs is None else np.asarray(inputs, dtype=np.float64)
    return Motion(inputs=inputs, body_names=("g", "a", "b"), ground="g", free=("a", "b"),
                  q=np.stack([np.zeros((n, 3)), np.asarray(poses_b, dtype=np.float64)], axis=1),
                  mechanism=SimpleNamespace(input_unit="deg"))


# -- the worst overlap of a long colliding run -------------------------------------------------------
LEAD = 10  # poses before the run where B stands well clear of A
RUN = 200  # colliding poses


def sliding_boxes(peak: int):
    """A (20 x 4, z 0..2) at rest; B (20 x 4 shifted +1 in y, z 0.5..2.5) first 30 mm away, then over A
    with x offset ``0.01 + 0.05 |i - peak|`` at the i-th pose of the run. Overlap = (20 - offset) x 3 (y)
    x 1.5 (z) mm^3, largest only at ``peak``. Returns (parts, motion, offsets of all poses)."""
    offsets = np.concatenate([np.full(LEAD, 30.0), 0.01 + 0.05 * np.abs(np.arange(RUN) - peak)])
    poses_b = np.column_stack([offsets, np.full(len(offsets), 1.0), np.zeros(len(offsets))])
    parts = [box_part("A", "a", (20.0, 4.0), 0.0, 2.0), box_part("B", "b", (20.0, 4.0), 0.5, 2.0)]
    return parts, motion_of(poses_b), offsets


@pytest.mark.parametrize("peak", [3, 7, 100, 196, RUN - 1])
def test_worst_overlap_of_a_long_run_is_found_exactly(peak):
    """Longer runs than OVERLAP_SAMPLES are sampled, then refined next to the worst sample: the reported
    worst pose and volume must be the true maximum (closed form (20 - 0.01) x 3 x 1.5 mm^3 at the peak,
    1e-6), wherever it lies: just after the first sample, between the first two, mid-run, between the
    last two samples, on the last pose. Every evaluated volume equals the closed form at its pose (1e-9),
    no pose is evaluated twice, and the cost stays bounded: at most OVERLAP_SAMPLES spread samples plus
    the poses within two sample spacings (ceil(199 / 23) = 9 poses each) of the worst."""
    parts, motion, offsets = sliding_boxes(peak)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.pairs
    np.testing.assert_array_equal(pair.collision_indices, np.arange(LEAD, LEAD + RUN))
    assert pair.max_overlap_index == LEAD + peak
    assert pair.max_overlap_mm3 == pytest.approx((20.0 - 0.01) * 3.0 * 1.5, abs=1e-6)
    idx = pair.overlap_indices
    assert np.all(np.diff(idx) > 0)  # sorted, each pose once
    assert set(idx) <= set(pair.collision_indices)
    np.testing.assert_allclose(pair.overlap_mm3, (20.0 - offsets[idx]) * 3.0 * 1.5, atol=1e-9)
    spacing = math.ceil((RUN - 1) / (OVERLAP_SAMPLES - 1))
    assert len(idx) <= OVERLAP_SAMPLES + 2 * spacing
    assert len(idx) < RUN // 4
    # the report names the worst pose and its volume
    (row,) = result.report()["collisions"]
    assert row["input_deg"] == LEAD + peak
    assert row["volume_mm3"] == pytest.approx((20.0 - 0.01) * 4.5, abs=1e-6)
    assert row["poses_colliding"] == RUN


@pytest.mark.parametrize("run", [OVERLAP_SAMPLES - 1, OVERLAP_SAMPLES])
def test_short_colliding_run_is_evaluated_at_every_pose(run):
    """Up to OVERLAP_SAMPLES colliding poses, every one is evaluated (no sampling): the volumes are the
    closed form at each pose (1e-9) and the worst is the true peak."""
    peak = run // 3
    offsets = 0.01 + 0.05 * np.abs(np.arange(run) - peak)
    poses_b = np.column_stack([offsets, np.full(run, 1.0), np.zeros(run)])
    parts = [box_part("A", "a", (20.0, 4.0), 0.0, 2.0), box_part("B", "b", (20.0, 4.0), 0.5, 2.0)]
    (pair,) = sweep_interference(parts, motion_of(poses_b), chord_tolerance_mm=TOL, min_clearance_mm=0.25).pairs
    np.testing.assert_array_equal(pair.overlap_indices, np.arange(run))
    np.testing.assert_allclose(pair.overlap_mm3, (20.0 - offsets) * 4.5, atol=1e-9)
    assert pair.max_overlap_index == peak
    assert pair.max_overlap_mm3 == pytest.approx((20.0 - 0.01) * 4.5, abs=1e-6)


# -- verdict wording and boundaries ------------------------------------------------------------------
def test_collision_message_lists_each_run_of_inputs_with_unit_and_worst_volume():
    """B passes over A, stands clear for exactly one pose, and comes back: two runs of colliding inputs
    (a one-pose gap still splits them). The failure names the pair, both runs in the motion's unit and the
    worst overlap: (10 - 1) x 2 x 2 = 36 mm^3 at input 15 deg (B 10 x 2 offset 1 mm in x over A's 10 x 4,
    z overlap 2 mm)."""
    x = np.array([12.0, 5.0, 1.0, 11.0, 3.0, 2.0, 12.0])  # A spans |x| <= 5, B is 10 wide: overlap 10 - |x|
    poses_b = np.column_stack([x, np.zeros(7), np.zeros(7)])
    inputs = np.arange(7) * 5.0
    parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 2.0), 1.0, 3.0)]
    result = sweep_interference(parts, motion_of(poses_b, inputs), chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.collisions
    np.testing.assert_array_equal(pair.collision_indices, [1, 2, 4, 5])
    assert result.input_ranges(pair.collision_indices) == [(5.0, 10.0), (20.0, 25.0)]
    assert result.failures() == [
        "interference: A collides with B at input 5..10, 20..25 deg (largest overlap 36.000 mm^3 at 10 deg)"]
    assert result.report()["collisions"][0]["input_ranges"] == [[5.0, 10.0], [20.0, 25.0]]


@pytest.mark.parametrize("use_kernel", [False, True])
def test_clearance_exactly_at_required_less_tolerance_passes(use_kernel):
    """The verdict's slack is the chord tolerance, inclusive: boxes exactly 0.25 mm apart pass with a
    0.375 mm minimum and a 0.125 mm tolerance, and fail 1/64 mm closer with the clearance message (dyadic
    lengths, so every number is exact in binary)."""
    for gap, ok in ((0.25, True), (0.25 - 1 / 64, False)):
        poses_b = np.array([[10.0 + gap, 0.0, 0.0], [12.0, 0.0, 0.0]])
        parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 4.0), 0.0, 3.0)]
        result = sweep_interference(parts, motion_of(poses_b, [30.0, 40.0]), chord_tolerance_mm=0.125,
                                    min_clearance_mm=0.375, use_kernel=use_kernel)
        (pair,) = result.pairs
        assert not pair.collides
        assert pair.min_clearance_mm == pytest.approx(gap, abs=1e-9)
        assert pair.min_index == 0
        assert result.passed is ok
        assert result.report()["pairs"][0]["ok"] is ok
        if ok:
            assert result.too_close() == [] and result.failures() == []
        else:
            assert result.too_close() == [pair]
            assert result.failures() == [f"clearance: A and B come within {gap:.3f} mm at input 30 deg; "
                                         "the process needs 0.375 mm"]


# -- pins given as the parts layer's pins ------------------------------------------------------------
def test_pins_from_parts_layer_take_the_axis_of_their_first_body_hole():
    """Each parts-layer pin becomes a PinSolid fixed in the first of its bodies, on the centre of that
    body's hole for the pin's joint (not another joint's hole, not the other body's hole), with the pin's
    own diameter, z and length; a pin whose first body has no such hole is skipped (the pins after it
    still count); PinSolids pass through unchanged."""
    parts = [
        box_part("B", "b", (10.0, 10.0), 3.3, 3.0, holes=(Hole("J", np.array([-3.0, 1.0]), 2.5, 2.0),)),
        box_part("A", "a", (30.0, 10.0), 0.0, 3.0, holes=(Hole("K", np.array([9.0, 9.0]), 2.5, 2.0),
                                                          Hole("J", np.array([5.0, 0.0]), 2.5, 2.0))),
    ]
    ready = PinSolid("pin_Q", "Q", "b", np.array([1.0, 2.0]), 1.5, 0.0, 4.0)
    layer_pins = [
        ready,
        SimpleNamespace(joint="X", bodies=("c", "a"), diameter_mm=2.0, length_mm=5.0, z_mm=0.0),  # no hole
        SimpleNamespace(joint="J", bodies=("a", "b"), diameter_mm=2.2, length_mm=7.5, z_mm=-1.0),
    ]
    pins = pins_from_parts_layer(layer_pins, parts)
    assert len(pins) == 2
    passed, pin = pins
    assert passed is ready
    assert isinstance(pin, PinSolid)
    assert (pin.name, pin.joint, pin.body) == ("pin_J", "J", "a")
    assert pin.centre.dtype == np.float64
    np.testing.assert_array_equal(pin.centre, [5.0, 0.0])
    assert (pin.diameter_mm, pin.z_mm, pin.length_mm) == (2.2, -1.0, 7.5)


def two_plates_on_a_pin(pin_diameter: float, *, washer: bool = False):
    """Plate A (body a, z 0..3) and plate B (body b, z 3.3..6.3; optionally a washer on joint J carried by
    b fills the 0.3 mm between them), each with a 2.5 mm hole for joint J at the body origin; B turns 90 deg about J.
    The parts-layer pin (fixed in a) has ``pin_diameter``; the holes say 2.0 mm."""
    parts = [box_part("A", "a", (30.0, 10.0), 0.0, 3.0, centre=(10.0, 0.0),
                      holes=(Hole("J", np.zeros(2), 2.5, 2.0),)),
             box_part("B", "b", (30.0, 10.0), 3.3, 3.0, centre=(10.0, 0.0),
                      holes=(Hole("J", np.zeros(2), 2.5, 2.0),))]
    spacers = []
    if washer:
        spacers = [SimpleNamespace(joint="J", body="b", centre=np.zeros(2), inner_diameter_mm=2.5,
                                   outer_diameter_mm=5.0, z_mm=3.0, length_mm=0.3, washer=True)]
    th = np.radians(np.linspace(0.0, 90.0, 5))
    motion = motion_of(np.column_stack([np.zeros(5), np.zeros(5), th]), np.degrees(th))
    pins = [SimpleNamespace(joint="J", bodies=("a", "b"), diameter_mm=pin_diameter, length_mm=6.3, z_mm=0.0)]
    return parts, motion, pins, spacers


def annulus_mm2(d_out: float, d_in: float) -> tuple[float, float]:
    """Closed-form annulus area and the most two inscribed polygons of sagitta TOL can change it."""
    return math.pi / 4.0 * (d_out**2 - d_in**2), 2.0 * math.pi * (d_out + d_in) / 2.0 * TOL


def test_parts_layer_pin_sets_the_radial_clearance_of_the_sweep():
    """A 2.2 mm parts-layer pin in 2.5 mm holes (whose nominal pin is 2.0): the pin pair keeps the radial
    clearance (2.5 - 2.2) / 2 = 0.15 mm at every pose, within the chord tolerance, so the build fails the
    0.25 mm minimum on the pin; the pin is fixed in body a, so only B meets it."""
    parts, motion, pins, _ = two_plates_on_a_pin(2.2)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25, pins=pins)
    rows = {(p.a, p.b): p for p in result.pairs}
    assert set(rows) == {("A", "B"), ("B", "pin_J")}
    assert result.rigid_pairs == 1
    pin = rows[("B", "pin_J")]
    assert pin.relation == "pin"
    assert 0.15 - TOL - 1e-9 <= pin.min_clearance_mm <= 0.15 + 1e-9
    assert np.all(np.abs(pin.clearance - 0.15) <= TOL + 1e-9)
    assert rows[("A", "B")].min_clearance_mm == pytest.approx(0.3, abs=1e-9)
    assert [(p.a, p.b) for p in result.too_close()] == [("B", "pin_J")]


def test_naive_reference_uses_the_given_pins_and_spacers():
    """An oversized 2.8 mm parts-layer pin in the 2.5 mm holes, with a 0.3 mm washer on B: the naive
    boolean reference reports, at every pose, the annulus pi/4 (2.8^2 - 2.5^2) times B's 3 mm and times the
    washer's 0.3 mm (within the area inscribed polygons can lose), nothing between the stacked plates, and
    the same worst volumes and colliding poses as the sweep on the same input (1e-6)."""
    parts, motion, pins, spacers = two_plates_on_a_pin(2.8, washer=True)
    naive = naive_interference(parts, motion, chord_tolerance_mm=TOL, pins=pins, spacers=spacers)
    assert set(naive) == {("A", "B"), ("A", "washer_J"), ("B", "pin_J"), ("pin_J", "washer_J")}
    area, slack = annulus_mm2(2.8, 2.5)
    np.testing.assert_allclose(naive[("B", "pin_J")], area * 3.0, atol=slack * 3.0)
    np.testing.assert_allclose(naive[("pin_J", "washer_J")], area * 0.3, atol=slack * 0.3)
    # touching faces (A's top on the washer) give a volume of rounding size only (1e-9)
    assert np.all(np.abs(naive[("A", "B")]) <= 1e-9) and np.all(np.abs(naive[("A", "washer_J")]) <= 1e-9)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25, pins=pins,
                                spacers=spacers)
    assert {(p.a, p.b) for p in result.pairs} == set(naive)
    for p in result.pairs:
        np.testing.assert_array_equal(np.nonzero(naive[(p.a, p.b)] > 1e-6)[0], p.collision_indices)
        if p.collides:
            assert p.max_overlap_mm3 == pytest.approx(naive[(p.a, p.b)].max(), abs=1e-6)


# -- pins from the parts' holes ----------------------------------------------------------------------
def test_pins_from_holes_one_per_shared_joint_through_every_part():
    """One pin per joint whose pin holes are on two or more bodies: fixed in the body of the lowest part
    (ties by name), on that part's hole centre, with the holes' nominal pin diameter (also 1 mm and
    below), from the lowest bottom face to the highest top face. A pin hole on one body only (M, listed
    first) is a mounting hole and makes no pin, nor do screw holes (pin diameter 0) on two bodies."""
    from fabricate.checks.items import pins_from_holes

    parts = [
        box_part("L", "a", (20.0, 6.0), 1.0, 2.0, holes=(Hole("M", np.array([-5.0, 0.0]), 2.5, 2.0),
                                                         Hole("J", np.array([4.0, 0.0]), 1.4, 1.0),
                                                         Hole("S", np.array([8.0, 0.0]), 3.0, 0.0))),
        box_part("U", "b", (20.0, 6.0), 3.5, 2.0, holes=(Hole("J", np.zeros(2), 1.4, 1.0),
                                                         Hole("S", np.array([1.0, 1.0]), 3.0, 0.0))),
        box_part("W", "a", (20.0, 6.0), 6.0, 1.0, holes=(Hole("K", np.array([-1.0, -1.0]), 0.9, 0.6),)),
        box_part("V", "c", (20.0, 6.0), 0.5, 0.5, holes=(Hole("K", np.array([2.0, 2.0]), 0.9, 0.6),)),
        box_part("Q2", "d", (20.0, 6.0), 0.0, 1.0, holes=(Hole("T", np.array([3.0, 0.0]), 2.5, 2.0),)),
        box_part("Q1", "e", (20.0, 6.0), 0.0, 1.5, holes=(Hole("T", np.array([0.0, 3.0]), 2.5, 2.0),)),
    ]
    pins = {p.name: p for p in pins_from_holes(parts)}
    assert set(pins) == {"pin_J", "pin_K", "pin_T"}
    j, k, t = pins["pin_J"], pins["pin_K"], pins["pin_T"]
    assert (j.joint, j.body, j.diameter_mm, j.z_mm, j.length_mm) == ("J", "a", 1.0, 1.0, 4.5)  # 1.0 .. 3.5 + 2
    np.testing.assert_array_equal(j.centre, [4.0, 0.0])
    assert (k.joint, k.body, k.diameter_mm, k.z_mm, k.length_mm) == ("K", "c", 0.6, 0.5, 6.5)  # 0.5 .. 6 + 1
    np.testing.assert_array_equal(k.centre, [2.0, 2.0])
    assert (t.joint, t.body, t.diameter_mm, t.z_mm, t.length_mm) == ("T", "e", 2.0, 0.0, 1.5)
    np.testing.assert_array_equal(t.centre, [0.0, 3.0])


def test_one_millimetre_pin_from_the_holes_keeps_its_radial_clearance():
    """A 1.0 mm pin in 1.4 mm holes (the default pins, from the holes): the pin pair keeps (1.4 - 1.0) / 2
    = 0.2 mm at every pose within the chord tolerance, and fails a 0.25 mm minimum as too close."""
    parts = [box_part("A", "a", (30.0, 10.0), 0.0, 2.0, centre=(10.0, 0.0), holes=(Hole("J", np.zeros(2), 1.4, 1.0),)),
             box_part("B", "b", (30.0, 10.0), 2.3, 2.0, centre=(10.0, 0.0), holes=(Hole("J", np.zeros(2), 1.4, 1.0),))]
    th = np.radians(np.linspace(0.0, 60.0, 4))
    result = sweep_interference(parts, motion_of(np.column_stack([np.zeros(4), np.zeros(4), th])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    rows = {(p.a, p.b): p for p in result.pairs}
    assert set(rows) == {("A", "B"), ("B", "pin_J")}
    assert np.all(np.abs(rows[("B", "pin_J")].clearance - 0.2) <= TOL + 1e-9)
    assert [(p.a, p.b) for p in result.too_close()] == [("B", "pin_J")]


# -- spacers -----------------------------------------------------------------------------------------
def test_spacer_items_are_rings_of_the_spacers_not_modelled_as_parts():
    """Parts-layer tubes and washers become rings (outer circle CCW, bore CW, radii outer/2 and inner/2
    within the chord tolerance, on the spacer's centre) from z to z + length on their body. Skipped: a
    spacer already modelled as a spacer part (that body, that joint) and a zero-length one; kept: a
    0.3 mm washer. A second tube of the same name gets its list index appended."""
    from fabricate.checks.items import spacer_items
    from fabricate.planar import polygon_area

    modelled = Part("sleeve", "b", BulgePath.polyline(np.array([[-2.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]])),
                    (Hole("J", np.zeros(2), 2.5, 2.0),), 1.0, 3.0, 1, "sla", role="spacer")
    ns = SimpleNamespace
    spacers = [
        ns(joint="J", body="b", centre=np.zeros(2), inner_diameter_mm=2.5, outer_diameter_mm=4.0, z_mm=3.0,
           length_mm=1.0, washer=False),  # modelled by "sleeve"
        ns(joint="J", body="a", centre=np.zeros(2), inner_diameter_mm=2.5, outer_diameter_mm=4.0, z_mm=3.0,
           length_mm=0.0, washer=True),  # nothing to model
        ns(joint="J", body="a", centre=np.array([1.0, 2.0]), inner_diameter_mm=2.2, outer_diameter_mm=4.0,
           z_mm=3.0, length_mm=0.3, washer=True),
        ns(joint="J", body="a", centre=np.array([1.0, 2.0]), inner_diameter_mm=2.2, outer_diameter_mm=5.0,
           z_mm=3.3, length_mm=2.0),  # no washer attribute: a tube
        ns(joint="J", body="c", centre=np.zeros(2), inner_diameter_mm=2.2, outer_diameter_mm=5.0, z_mm=5.3,
           length_mm=2.0, washer=False),
    ]
    items = spacer_items(spacers, [modelled], TOL)
    assert [it.name for it in items] == ["washer_J", "tube_J", "tube_J_4"]
    assert [it.body for it in items] == ["a", "a", "c"]
    assert [(it.z0, it.z1) for it in items] == [(3.0, 3.3), (3.3, 5.3), (5.3, 7.3)]
    for it, sp in zip(items, spacers[2:], strict=True):
        assert it.kind == "spacer" and it.joints == frozenset({"J"}) and it.gear == "" and it.source is sp
        outer, bore = it.rings
        r_out = np.hypot(*(outer - sp.centre).T)
        r_in = np.hypot(*(bore - sp.centre).T)
        assert np.all(r_out <= sp.outer_diameter_mm / 2 + 1e-12) and np.all(r_out >= sp.outer_diameter_mm / 2 - TOL)
        assert np.all(r_in <= sp.inner_diameter_mm / 2 + 1e-12) and np.all(r_in >= sp.inner_diameter_mm / 2 - TOL)
        assert polygon_area(outer) > 0 > polygon_area(bore)


# -- gears in mesh and the report --------------------------------------------------------------------
def gear_pair(gap: float, gear_b: str = "g1"):
    """Two gear parts (boxes standing in for the teeth) of gear pair "g1" on bodies a and b, same layer,
    ``gap`` apart in x at the one pose."""
    a = Part("G1", "a", BulgePath.polyline(np.array([[-5.0, -2.0], [5.0, -2.0], [5.0, 2.0], [-5.0, 2.0]])), (),
             3.0, 0.0, 0, "sla", role="gear", gear="g1")
    b = Part("G2", "b", BulgePath.polyline(np.array([[-5.0, -2.0], [5.0, -2.0], [5.0, 2.0], [-5.0, 2.0]])), (),
             3.0, 0.0, 0, "sla", role="gear", gear=gear_b)
    return [a, b], motion_of(np.array([[10.0 + gap, 0.0, 0.0]]))


def test_meshing_gears_run_with_backlash_below_the_process_clearance():
    """Gear parts of one pair 0.05 mm apart (backlash) pass a 0.25 mm process minimum: the pair is
    "meshing", must keep 0 mm, and is left out of the sweep's minimum clearance (inf: the report writes
    null, valid JSON). The same parts in different pairs are an ordinary moving pair that fails."""
    import json

    parts, motion = gear_pair(0.05)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.pairs
    assert (pair.relation, pair.required_mm) == ("meshing", 0.0)
    assert pair.min_clearance_mm == pytest.approx(0.05, abs=1e-9)
    assert result.passed, result.failures()
    assert result.min_clearance_mm == math.inf
    report = result.report()
    assert report["min_clearance_mm"] is None
    json.dumps(report, allow_nan=False)
    parts, motion = gear_pair(0.05, gear_b="g2")
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    assert result.pairs[0].relation == "moving" and not result.passed
    assert result.report()["min_clearance_mm"] == pytest.approx(0.05, abs=1e-9)


def test_report_gives_lengths_to_the_micrometre():
    """report.json rounds lengths to 6 decimals (1 nm): plates stacked 0.1234567 mm apart over each other
    (clearance = that gap wherever they overlap in plan) report z gap and clearance 0.123457; side by side
    0.7654321 mm apart on one layer they report 0.765432."""
    plates = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 4.0), 3.1234567, 3.0)]
    result = sweep_interference(plates, motion_of(np.array([[2.0, 0.0, 0.0]])), chord_tolerance_mm=TOL,
                                min_clearance_mm=0.1)
    (row,) = result.report()["pairs"]
    assert row["z_gap_mm"] == 0.123457
    assert row["min_clearance_mm"] == 0.123457
    assert result.report()["min_clearance_mm"] == 0.123457
    side = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 4.0), 0.0, 3.0)]
    result = sweep_interference(side, motion_of(np.array([[10.7654321, 0.0, 0.0]])), chord_tolerance_mm=TOL,
                                min_clearance_mm=0.1)
    (row,) = result.report()["pairs"]
    assert row["min_clearance_mm"] == 0.765432 and result.report()["min_clearance_mm"] == 0.765432
    assert row["z_gap_mm"] == -3.0


def test_spacer_part_bears_on_the_parts_of_its_joint():
    """A spacer modelled as a part (role "spacer", carried by B) fills the 0.5 mm between plates A and B
    on joint J: it touches A's top face by design, so the pair is "bearing" (must keep 0 mm, may touch)
    and the build passes with clearance 0; the plates themselves keep their 0.5 mm layer gap."""
    hole = (Hole("J", np.zeros(2), 2.5, 2.0),)
    sleeve = Part("sleeve", "b", BulgePath.polyline(np.array([[-2.5, -2.5], [2.5, -2.5], [2.5, 2.5], [-2.5, 2.5]])),
                  hole, 0.5, 3.0, 1, "sla", role="spacer")
    parts = [box_part("A", "a", (30.0, 10.0), 0.0, 3.0, centre=(10.0, 0.0), holes=hole), sleeve,
             box_part("B", "b", (30.0, 10.0), 3.5, 3.0, centre=(10.0, 0.0), holes=hole)]
    th = np.radians(np.linspace(0.0, 90.0, 4))
    result = sweep_interference(parts, motion_of(np.column_stack([np.zeros(4), np.zeros(4), th])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25, pins=[])
    rows = {(p.a, p.b): p for p in result.pairs}
    assert set(rows) == {("A", "sleeve"), ("A", "B")}
    assert (rows[("A", "sleeve")].relation, rows[("A", "sleeve")].required_mm) == ("bearing", 0.0)
    assert rows[("A", "sleeve")].min_clearance_mm == 0.0 and not rows[("A", "sleeve")].collides
    assert rows[("A", "B")].relation == "joined"
    assert rows[("A", "B")].min_clearance_mm == pytest.approx(0.5, abs=1e-9)
    assert result.passed, result.failures()
    assert result.min_clearance_mm == pytest.approx(0.5, abs=1e-9)  # the bearing pair does not count


def washer_and_plate(z_plate: float, *, plate_is_part: bool = True):
    """A 0.3 mm washer on joint J (body a, z 3.0..3.3, bore 2.2, outside 6 mm) and a plate C on body c with
    no hole for J, bottom at ``z_plate``, lying over the washer in plan at every pose."""
    washer = SimpleNamespace(joint="J", body="a", centre=np.zeros(2), inner_diameter_mm=2.2, outer_diameter_mm=6.0,
                             z_mm=3.0, length_mm=0.3, washer=True)
    plate = box_part("C", "c", (20.0, 10.0), z_plate, 3.0, holes=(Hole("K", np.array([5.0, 0.0]), 2.5, 2.0),))
    n = 3
    motion = Motion(inputs=np.arange(n, dtype=np.float64), body_names=("g", "a", "c"), ground="g", free=("a", "c"),
                    q=np.stack([np.zeros((n, 3)), np.column_stack([np.linspace(-2, 2, n), np.zeros(n), np.zeros(n)])],
                               axis=1), mechanism=SimpleNamespace(input_unit="deg"))
    return [plate], motion, [washer]


def test_part_flush_on_a_washer_face_bears_and_a_part_above_it_keeps_the_clearance():
    """A plate sliding on a washer's end face (z gap exactly 0, not on the washer's joint) is "bearing":
    touching is its job, the build passes. Lifted 0.2 mm off the face it is an ordinary moving pair: it
    must keep 0.25 mm, and the 0.2 mm gap (the clearance where they overlap in plan) fails."""
    parts, motion, spacers = washer_and_plate(3.3)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25, spacers=spacers, pins=[])
    (pair,) = result.pairs
    assert (pair.a, pair.b, pair.relation, pair.required_mm) == ("C", "washer_J", "bearing", 0.0)
    assert pair.min_clearance_mm == 0.0 and not pair.collides
    assert result.passed, result.failures()
    parts, motion, spacers = washer_and_plate(3.5)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25, spacers=spacers, pins=[])
    (pair,) = result.pairs
    assert (pair.relation, pair.required_mm) == ("moving", 0.25)
    assert pair.min_clearance_mm == pytest.approx(0.2, abs=1e-9)
    assert result.too_close() == [pair]


def test_flush_plates_on_different_joints_must_keep_the_clearance():
    """Two plates on different bodies and joints, one right on top of the other (z gap 0) and overlapping
    in plan: they touch (clearance 0, no overlap volume), which is not allowed for moving parts: the
    verdict fails with a clearance message, not a collision."""
    parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0, holes=(Hole("J", np.zeros(2), 2.5, 2.0),)),
             box_part("B", "b", (10.0, 4.0), 3.0, 3.0, holes=(Hole("K", np.zeros(2), 2.5, 2.0),))]
    result = sweep_interference(parts, motion_of(np.array([[3.0, 0.0, 0.0]])), chord_tolerance_mm=TOL,
                                min_clearance_mm=0.25, pins=[])
    (pair,) = result.pairs
    assert (pair.relation, pair.z_gap_mm, pair.min_clearance_mm) == ("moving", 0.0, 0.0)
    assert not pair.collides
    assert result.failures() == ["clearance: A and B come within 0.000 mm at input 0 deg; the process needs 0.250 mm"]


@pytest.mark.parametrize("check", ["naive", "sweep"])
def test_a_degenerate_solid_is_named(check):
    """A part of zero width has no cross-section: the boolean reference and the sweep both refuse it
    with a GeometryError that names the solid (B), so the user can find the faulty input."""
    from fabricate.errors import GeometryError

    parts, motion, pins, _ = two_plates_on_a_pin(2.0)
    parts[1] = box_part("B", "b", (30.0, 0.0), 3.3, 3.0, centre=(10.0, 0.0))
    with pytest.raises(GeometryError, match=r"^B: empty cross-section"):
        if check == "naive":
            naive_interference(parts, motion, chord_tolerance_mm=TOL, pins=pins)
        else:
            sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.1, pins=pins)


# -- pairs one pose settles, and what the clearance curve shows ------------------------------------
def count_planar_poses(monkeypatch) -> dict[str, int]:
    """Count the poses handed to the planar engine (distances and overlap areas) during a sweep."""
    import fabricate.checks.interference as interference

    counts = {"distance": 0, "area": 0}

    def counted(name, fn):
        def wrapper(oa, ob, rel, *args):
            counts[name] += len(rel.q)
            return fn(oa, ob, rel, *args)
        return wrapper

    monkeypatch.setattr(interference, "planar_clearance", counted("distance", interference.planar_clearance))
    monkeypatch.setattr(interference, "overlap_areas", counted("area", interference.overlap_areas))
    return counts


def plates_on_an_off_origin_joint(b_poses: np.ndarray):
    """Plate A (body a, z 0..3) with joint J's 2.5 mm hole at (5, 0); plate B (body b, z 3.3..6.3) with its
    J hole at (-3, 1) of its frame; a 2 mm parts-layer pin on J fixed in a; a tube on J carried by b
    (bore 2.5, z 3.0..3.3) between them. Neither hole is at its body's origin."""
    hole_a, hole_b = np.array([5.0, 0.0]), np.array([-3.0, 1.0])
    parts = [box_part("A", "a", (30.0, 10.0), 0.0, 3.0, centre=(5.0, 0.0), holes=(Hole("J", hole_a, 2.5, 2.0),)),
             box_part("B", "b", (30.0, 10.0), 3.3, 3.0, centre=(-3.0, 1.0), holes=(Hole("J", hole_b, 2.5, 2.0),))]
    pins = [SimpleNamespace(joint="J", bodies=("a", "b"), diameter_mm=2.0, length_mm=6.3, z_mm=0.0)]
    tube = SimpleNamespace(joint="J", body="b", centre=hole_b, inner_diameter_mm=2.5, outer_diameter_mm=5.0,
                           z_mm=3.0, length_mm=0.3, washer=False)
    return parts, motion_of(b_poses), pins, [tube]


def test_pin_on_its_hole_axis_keeps_one_clearance_from_one_pose(monkeypatch):
    """B turns about joint J (its hole stays on A's hole at (5, 0), the holes off both body origins): the
    pin (fixed in a) lies on the axis of B's hole and of the tube's bore at every pose, so each pin pair
    has one radial clearance, (2.5 - 2) / 2 mm within the chord tolerance, drawn as a flat exact line and
    reported at the first input; the stacked pairs (A-B on the 0.3 mm layer gap, A flush on the tube) are
    settled at their closest pose. Each of these four pairs costs the planar engine one pose, whatever
    the number of poses."""
    th = np.radians([0.0, 17.0, 41.0, 66.0, 90.0, 123.0, 150.0])
    rot = np.stack([np.column_stack([np.cos(th), -np.sin(th)]), np.column_stack([np.sin(th), np.cos(th)])], axis=1)
    xy = np.array([5.0, 0.0]) - rot @ np.array([-3.0, 1.0])
    parts, motion, pins, spacers = plates_on_an_off_origin_joint(np.column_stack([xy, th]))
    counts = count_planar_poses(monkeypatch)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25, pins=pins,
                                spacers=spacers)
    rows = {(p.a, p.b): p for p in result.pairs}
    assert set(rows) == {("A", "B"), ("A", "tube_J"), ("B", "pin_J"), ("pin_J", "tube_J")}
    for key in (("B", "pin_J"), ("pin_J", "tube_J")):
        p = rows[key]
        assert p.relation == "pin" and p.exact.all()
        assert np.ptp(p.clearance) == 0.0
        assert 0.25 - TOL - 1e-9 <= p.min_clearance_mm <= 0.25 + 1e-9
        assert p.min_index == 0
    assert rows[("A", "B")].min_clearance_mm == pytest.approx(0.3, abs=1e-9)
    assert rows[("A", "tube_J")].relation == "bearing" and rows[("A", "tube_J")].min_clearance_mm == 0.0
    assert result.passed, result.failures()
    assert counts == {"distance": 2, "area": 2}


def test_pin_off_its_hole_axis_is_measured_at_every_pose():
    """B slides instead of turning: its hole (and the tube's bore) moves e = 0 .. 0.15 mm off the pin's
    axis, so the radial clearance is (2.5 - 2) / 2 - e at each pose (circles; the inscribed polygons
    read within the chord tolerance of it): it must be measured pose by pose, not taken from the first.
    A plate C on B's body without a hole for J stays far from the pin: an ordinary moving pair."""
    e = np.array([0.0, 0.05, 0.1, 0.15, 0.1])
    parts, motion, pins, spacers = plates_on_an_off_origin_joint(
        np.column_stack([8.0 + e, np.full(5, -1.0), np.zeros(5)]))
    parts.append(box_part("C", "b", (10.0, 10.0), 0.0, 3.0, centre=(60.0, 0.0),
                          holes=(Hole("K", np.array([60.0, 0.0]), 2.5, 2.0),)))
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.05, pins=pins,
                                spacers=spacers)
    rows = {(p.a, p.b): p for p in result.pairs}
    for key in (("B", "pin_J"), ("pin_J", "tube_J")):
        p = rows[key]
        assert p.exact.all()
        np.testing.assert_allclose(p.clearance, 0.25 - e, atol=TOL + 1e-9)
        assert p.min_index == 3
        assert p.kernel_gap_mm == pytest.approx(p.min_clearance_mm, abs=1e-6)
    assert rows[("C", "pin_J")].relation == "moving" and not rows[("C", "pin_J")].collides
    assert rows[("C", "pin_J")].min_clearance_mm >= 2.0  # the search length: a lower bound of ~50 mm


def stacked_boxes(x: np.ndarray, gap: float):
    """A (10 x 4, z 0..3) at rest; B (10 x 4, z 3 + gap ..) at (x_i, 3.5): in plan they overlap by
    (10 - x) x 0.5 where x < 10 and are x - 10 apart otherwise."""
    parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 4.0), 3.0 + gap, 3.0)]
    return parts, motion_of(np.column_stack([x, np.full(len(x), 3.5), np.zeros(len(x))]))


@pytest.mark.parametrize("gap", [0.3, 0.25])
def test_stacked_parts_clear_by_their_gap_are_settled_at_the_closest_pose(monkeypatch, gap):
    """B passes over A's corner on the next layer with a gap that alone meets the 0.25 mm minimum (also
    exactly at it): the clearance is the gap wherever they overlap in plan (here a corner of 0.5 x 0.5 mm^2
    at most), so the one pose where the parts come closest settles the pair: minimum = gap, exact there
    (the kernel agrees) and nowhere else (a lower bound of hypot(gap, planar distance) elsewhere, drawn
    dotted), with one overlap area and no distance asked of the planar engine."""
    x = np.array([12.0, 11.0, 9.6, 9.5, 9.7, 11.0, 12.0])
    parts, motion = stacked_boxes(x, gap)
    counts = count_planar_poses(monkeypatch)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.pairs
    true = np.hypot(gap, np.maximum(x - 10.0, 0.0))
    assert pair.min_index == 3 and pair.exact[3] and pair.exact.sum() == 1
    assert pair.min_clearance_mm == pytest.approx(gap, abs=1e-9)
    assert pair.kernel_gap_mm == pytest.approx(gap, abs=1e-6)
    assert np.all(pair.clearance <= true + 1e-9)
    assert not pair.collides and len(result.inputs[pair.collision_indices]) == 0  # integer pose indices
    row = result.report()["pairs"][0]
    assert row["exact"] is True and row["at_input"] == 3.0
    assert result.passed, result.failures()
    assert counts == {"distance": 0, "area": 1}


def test_stacked_parts_closer_than_required_are_resolved_at_every_pose():
    """The same pass with a 0.2 mm layer gap (below the minimum): the curve of a failing pair is exact at
    every pose, hypot(0.2, planar distance) with the planar distance max(x - 10, 0) by hand (1e-9)."""
    x = np.array([11.5, 11.0, 9.6, 9.5, 9.7, 10.4, 11.5])
    parts, motion = stacked_boxes(x, 0.2)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.pairs
    assert pair.exact.all()
    np.testing.assert_allclose(pair.clearance, np.hypot(0.2, np.maximum(x - 10.0, 0.0)), atol=1e-9)
    assert result.too_close() == [pair]


def test_stacked_parts_apart_in_plan_keep_the_diagonal_clearance():
    """Stacked 0.3 mm apart in z and 1 mm apart in plan at every pose (never over each other): the
    clearance is the diagonal hypot(0.3, 1.0) mm, not the layer gap (1e-9)."""
    x = np.array([11.0, 11.0, 11.0])
    parts, motion = stacked_boxes(x, 0.3)
    (pair,) = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25).pairs
    assert pair.min_clearance_mm == pytest.approx(math.hypot(0.3, 1.0), abs=1e-9)
    assert pair.exact.all()


@pytest.mark.parametrize("tol", [TOL, 1e-4])
def test_clear_pair_reports_kernel_gap_and_no_overlap(tol):
    """Same-layer boxes 1.5, 0.75 and 3.5 mm apart (thin 10 x 1 bars side by side, bounding circles
    overlapping at every pose): the pair does not collide (empty integer pose arrays that index the
    inputs, no overlap volume); its minimum 0.75 mm is exact at pose 1 and confirmed by manifold3d's
    min_gap (1e-6), at any chord tolerance; beyond the 2 mm search length only the search length is known
    (a lower bound, not exact)."""
    parts = [box_part("A", "a", (10.0, 1.0), 0.0, 3.0), box_part("B", "b", (10.0, 1.0), 0.0, 3.0)]
    y = np.array([2.5, 1.75, 4.5])  # edge to edge: y - 1
    result = sweep_interference(parts, motion_of(np.column_stack([np.zeros(3), y, np.zeros(3)])),
                                chord_tolerance_mm=tol, min_clearance_mm=0.25)
    (pair,) = result.pairs
    assert not pair.collides
    for idx in (pair.collision_indices, pair.overlap_indices):
        assert len(idx) == 0 and len(result.inputs[idx]) == 0
    assert len(pair.overlap_mm3) == 0
    assert (pair.max_overlap_mm3, pair.max_overlap_index) == (0.0, 0)
    np.testing.assert_allclose(pair.clearance, [1.5, 0.75, 2.0], atol=1e-9)
    np.testing.assert_array_equal(pair.exact, [True, True, False])
    assert (pair.min_index, pair.min_clearance_mm) == (1, pytest.approx(0.75, abs=1e-9))
    assert pair.kernel_gap_mm == pytest.approx(0.75, abs=1e-6)
    assert result.report()["pairs"][0]["kernel_gap_mm"] == pytest.approx(0.75, abs=1e-6)


def test_collision_volume_without_the_kernel_is_the_planar_product():
    """With use_kernel=False the worst overlap is the planar overlap area times the z overlap: B (10 x 2,
    z 1..4) over A (10 x 4, z 0..3) offset 1 mm in x: (10 - 1) x 2 x 2 = 36 mm^3 (1e-9); no kernel gap."""
    parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 2.0), 1.0, 3.0)]
    result = sweep_interference(parts, motion_of(np.array([[1.0, 0.0, 0.0], [3.0, 0.0, 0.0]])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25, use_kernel=False)
    (pair,) = result.pairs
    assert pair.max_overlap_mm3 == pytest.approx(36.0, abs=1e-9) and pair.max_overlap_index == 0
    assert pair.kernel_gap_mm is None


def test_parts_touching_on_one_layer_touch_but_do_not_collide():
    """Two boxes on one layer edge to edge (B's left edge on A's right edge, exactly): clearance 0, which
    fails the minimum as too close, but no overlap volume and no collision."""
    parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 4.0), 0.0, 3.0)]
    result = sweep_interference(parts, motion_of(np.array([[10.0, 1.0, 0.0], [12.0, 1.0, 0.0]])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.pairs
    assert not pair.collides and result.collisions == []
    assert pair.min_clearance_mm == 0.0 and pair.min_index == 0
    assert result.too_close() == [pair]


def test_kernel_confirms_a_clearance_with_a_short_search(monkeypatch):
    """manifold3d's min_gap is fast only with a short search: the sweep asks it just beyond the planar
    clearance (here 0.75 mm, boxes side by side), within 0.05 mm of it, and gets the same gap back (1e-6)."""
    import fabricate.checks.interference as interference

    reaches = []

    class Recorded:
        def __init__(self, solid):
            self.solid = solid

        def min_gap(self, other, reach):
            reaches.append(reach)
            return self.solid.min_gap(other.solid, reach)

    posed_pair = interference._posed_pair
    monkeypatch.setattr(interference, "_posed_pair", lambda *args: [Recorded(s) for s in posed_pair(*args)])
    parts = [box_part("A", "a", (10.0, 1.0), 0.0, 3.0), box_part("B", "b", (10.0, 1.0), 0.0, 3.0)]
    result = sweep_interference(parts, motion_of(np.array([[0.0, 2.5, 0.0], [0.0, 1.75, 0.0]])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.pairs
    assert pair.kernel_gap_mm == pytest.approx(0.75, abs=1e-6)
    assert len(reaches) == 1 and 0.75 < reaches[0] <= 0.75 + 0.05


# -- the result's own fields and the report's rounding ---------------------------------------------
def test_without_the_kernel_no_solid_is_built_and_no_kernel_gap_is_reported(monkeypatch):
    """use_kernel=False keeps manifold3d out of the sweep: no solid is posed (the kernel's entry point is
    patched to fail), the clear pair has no kernel gap (None in the pair and in the report row) and its
    minimum is the planar one, 0.75 mm between bars side by side (1e-9)."""
    import fabricate.checks.interference as interference

    def no_kernel(*args):
        raise AssertionError("the kernel was asked with use_kernel=False")

    monkeypatch.setattr(interference, "_posed_pair", no_kernel)
    parts = [box_part("A", "a", (10.0, 1.0), 0.0, 3.0), box_part("B", "b", (10.0, 1.0), 0.0, 3.0)]
    result = sweep_interference(parts, motion_of(np.array([[0.0, 2.5, 0.0], [0.0, 1.75, 0.0]])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25, use_kernel=False)
    (pair,) = result.pairs
    assert pair.kernel_gap_mm is None
    assert result.report()["pairs"][0]["kernel_gap_mm"] is None
    assert (pair.min_index, pair.min_clearance_mm) == (1, pytest.approx(0.75, abs=1e-9))


def test_default_search_length_is_four_times_a_large_minimum():
    """Without a search length the sweep resolves planar distances up to max(DEFAULT_SEARCH_MM, 4 x the
    minimum clearance); with a minimum of DEFAULT_SEARCH_MM that is 4 x DEFAULT_SEARCH_MM (8 mm). Bars side by
    side 0.875 x and 1.125 x that far apart: the nearer distance is exact, the farther one reads the
    search length as a lower bound (1e-9). The result carries the minimum and the search length asked
    for, and the report the minimum."""
    from fabricate.checks.interference import DEFAULT_SEARCH_MM

    minimum = DEFAULT_SEARCH_MM
    search = 4.0 * minimum
    assert search > DEFAULT_SEARCH_MM
    gaps = np.array([0.875, 1.125]) * search
    parts = [box_part("A", "a", (10.0, 1.0), 0.0, 3.0), box_part("B", "b", (10.0, 1.0), 0.0, 3.0)]
    result = sweep_interference(parts, motion_of(np.column_stack([np.zeros(2), 1.0 + gaps, np.zeros(2)])),
                                chord_tolerance_mm=TOL, min_clearance_mm=minimum)
    assert result.search_length_mm == search
    assert result.min_clearance_required_mm == minimum
    assert result.report()["required_clearance_mm"] == minimum
    (pair,) = result.pairs
    np.testing.assert_allclose(pair.clearance, [gaps[0], search], atol=1e-9)
    np.testing.assert_array_equal(pair.exact, [True, False])


def test_given_search_length_and_minimum_are_the_results_fields():
    """An explicit search length (3 mm) and minimum clearance (0.4 mm) come back
    unchanged in the result (and the minimum in the report); bars 3.5 mm apart are beyond the search: a
    lower bound of 3 mm, not exact."""
    parts = [box_part("A", "a", (10.0, 1.0), 0.0, 3.0), box_part("B", "b", (10.0, 1.0), 0.0, 3.0)]
    result = sweep_interference(parts, motion_of(np.array([[0.0, 4.5, 0.0]])), chord_tolerance_mm=TOL,
                                min_clearance_mm=0.4, search_length_mm=3.0)
    assert result.search_length_mm == 3.0
    assert result.min_clearance_required_mm == 0.4
    assert result.report()["required_clearance_mm"] == 0.4
    (pair,) = result.pairs
    assert pair.clearance[0] == pytest.approx(3.0, abs=1e-9) and not pair.exact[0]


@pytest.mark.parametrize("dtype", [np.int64, np.float32])
def test_inputs_come_back_as_float64(dtype):
    """The result's inputs are float64 whatever the motion holds (integer degrees, float32), with the same
    values: 0, 15, 30 here (exact in both)."""
    motion = motion_of(np.array([[12.0, 0.0, 0.0]] * 3))
    motion = Motion(inputs=np.array([0, 15, 30], dtype=dtype), body_names=motion.body_names, ground=motion.ground,
                    free=motion.free, q=motion.q, mechanism=motion.mechanism)
    parts = [box_part("A", "a", (10.0, 4.0), 0.0, 3.0), box_part("B", "b", (10.0, 4.0), 0.0, 3.0)]
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    assert result.inputs.dtype == np.float64
    np.testing.assert_array_equal(result.inputs, [0.0, 15.0, 30.0])


def test_report_rounds_kernel_gap_and_overlap_volume_to_six_decimals():
    """report.json's kernel gap and overlap volume are rounded to 6 decimals like its other lengths: bars
    (10 x 1, one layer) 0.7654321 mm apart report a kernel gap of 0.765432; 10 x 1 x 1 boxes overlapping by
    0.12345678 mm in x overlap by 0.12345678 mm^3 (manifold3d's boolean, far within 1e-7 of it for boxes),
    reported as 0.123457."""
    bars = [box_part("A", "a", (10.0, 1.0), 0.0, 3.0), box_part("B", "b", (10.0, 1.0), 0.0, 3.0)]
    result = sweep_interference(bars, motion_of(np.array([[0.0, 1.7654321, 0.0]])), chord_tolerance_mm=TOL,
                                min_clearance_mm=0.25)
    (row,) = result.report()["pairs"]
    assert row["kernel_gap_mm"] == 0.765432
    cubes = [box_part("A", "a", (10.0, 1.0), 0.0, 1.0), box_part("B", "b", (10.0, 1.0), 0.0, 1.0)]
    result = sweep_interference(cubes, motion_of(np.array([[10.0 - 0.12345678, 0.0, 0.0]])),
                                chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    (pair,) = result.collisions
    assert pair.max_overlap_mm3 == pytest.approx(0.12345678, abs=1e-9)
    (row,) = result.report()["collisions"]
    assert row["volume_mm3"] == 0.123457


# -- arguments that are not solids -------------------------------------------------------------------
@pytest.mark.parametrize("diameter", [0.0, -2.0, math.nan])
def test_a_pin_without_a_positive_diameter_is_refused_by_name(diameter):
    """A zero pin has no outline and a negative one is a mirrored circle: the sweep names the pin's
    field (a SpecError, a ValueError) instead of failing inside numpy or checking a phantom solid."""
    from fabricate.errors import SpecError

    parts, motion, pins, _ = two_plates_on_a_pin(diameter)
    with pytest.raises(SpecError, match=r"pins\.pin_J\.diameter_mm"):
        sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.1, pins=pins)


@pytest.mark.parametrize("field, kwargs", [
    ("chord_tolerance_mm", {"chord_tolerance_mm": 0.0}),
    ("min_clearance_mm", {"min_clearance_mm": -0.1}),
    ("search_length_mm", {"search_length_mm": -1.0}),
])
def test_sweep_arguments_out_of_range_are_refused_by_name(field, kwargs):
    from fabricate.errors import SpecError

    parts, motion, pins, _ = two_plates_on_a_pin(2.0)
    args = {"chord_tolerance_mm": TOL, "min_clearance_mm": 0.1, "pins": pins} | kwargs
    with pytest.raises(SpecError, match=field):
        sweep_interference(parts, motion, **args)


def test_a_washer_whose_outside_is_not_outside_its_bore_is_refused():
    from fabricate.errors import SpecError

    parts, motion, pins, spacers = two_plates_on_a_pin(2.0, washer=True)
    bad = [SimpleNamespace(**(vars(spacers[0]) | {"outer_diameter_mm": 2.5}))]
    with pytest.raises(SpecError, match=r"^spacers\[0\]\.outer_diameter_mm: must exceed inner_diameter_mm \(2\.5\), "
                                        r"got 2\.5$"):
        sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.1, pins=pins, spacers=bad)


def test_a_triangle_and_a_zero_clearance_are_valid_sweep_inputs():
    """Three vertices are a solid (the degenerate-outline check needs fewer than 3 or no area), and a required
    clearance of 0 is allowed (only negative ones are refused): a 6 x 4 right triangle 1 mm beside a box sweeps
    without error and its clearance is the 1 mm gap (boxes and triangles are exact polygons: 1e-9)."""
    tri = Part("T", "b", BulgePath.polyline(np.array([[11.0, -2.0], [17.0, -2.0], [11.0, 2.0]])), (), 3.0, 0.0, 0,
               "sla")
    parts = [box_part("A", "a", (20.0, 4.0), 0.0, 3.0), tri]
    motion = motion_of(np.zeros((3, 3)))
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.0, pins=[])
    (pair,) = result.pairs
    assert pair.min_clearance_mm == pytest.approx(1.0, abs=1e-9)
    assert result.failures() == []


# == against shapely and the naive reference (formerly tests/test_interference.py) ===============================
CHORD_TOL = 0.005  # chord tolerance of the solids, mm
EXPECTED = json.loads((Path(__file__).resolve().parents[1] / "data" / "interference_four_bar.json").read_text())


def motion_with_a(poses_b: np.ndarray, pose_a: np.ndarray | None = None) -> Motion:
    """A bare Motion of bodies 'a' and 'b' (ground 'g'), one row per pose; no mechanism needed."""
    n = len(poses_b)
    pose_a = np.zeros((n, 3)) + (pose_a if pose_a is not None else 0.0)
    return Motion(inputs=np.arange(n, dtype=np.float64), body_names=("g", "a", "b"), ground="g",
                  free=("a", "b"), q=np.stack([pose_a, poses_b], axis=1),
                  mechanism=SimpleNamespace(input_unit="deg"))


def posed_box(size, pose) -> shapely.Polygon:
    w, h = size
    corners = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
    return shapely.Polygon(transform_points(pose, corners))


sizes = st.tuples(st.floats(2.0, 20.0), st.floats(2.0, 20.0))
poses = st.tuples(st.floats(-15.0, 15.0), st.floats(-15.0, 15.0), st.floats(-math.pi, math.pi))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(size_a=sizes, size_b=sizes, pose_a=poses, pose_b=poses, z_b=st.floats(-4.0, 4.0))
def test_box_overlap_volume_matches_analytic(size_a, size_b, pose_a, pose_b, z_b):
    """Two boxes at random rigid poses: reported volume = shapely area × z overlap (1e-6 relative),
    clearance = planar distance (z overlap) or hypot(z gap, planar distance) (1e-6 mm)."""
    pose_a, pose_b = np.array(pose_a), np.array(pose_b)
    thickness = 3.0
    area = posed_box(size_a, pose_a).intersection(posed_box(size_b, pose_b)).area
    planar = posed_box(size_a, pose_a).distance(posed_box(size_b, pose_b))
    z_overlap = min(thickness, z_b + thickness) - max(0.0, z_b)
    volume = area * max(z_overlap, 0.0)
    # keep away from the tangent cases where "touching" and "overlapping" are rounding apart
    assume(volume > 1e-3 or (volume == 0.0 and (planar > 1e-3 or z_overlap < -1e-3)))
    parts = [box_part("A", "a", size_a, 0.0, thickness), box_part("B", "b", size_b, z_b, thickness)]
    result = sweep_interference(parts, motion_with_a(pose_b[None, :], pose_a), chord_tolerance_mm=CHORD_TOL,
                                min_clearance_mm=0.25, search_length_mm=50.0)
    (pair,) = result.pairs
    if volume > 0.0:
        assert pair.collides
        # manifold3d resolves positions to ~1e-8 mm here: over a sliver's ~50 mm perimeter x 3 mm that is
        # ~1e-6 mm^3 absolute (a 0.003 mm^3 sliver once read 1.1e-8 mm^3 high)
        assert pair.max_overlap_mm3 == pytest.approx(volume, rel=1e-6, abs=1e-6)
        assert pair.overlap_mm3[0] == pytest.approx(volume, rel=1e-6, abs=1e-6)
        assert pair.min_clearance_mm == 0.0
    else:
        assert not pair.collides
        expected = planar if z_overlap > 0 else math.hypot(-z_overlap, planar)
        assert pair.min_clearance_mm == pytest.approx(expected, abs=1e-6)


@settings(max_examples=25, deadline=None)
@given(size_a=sizes, size_b=sizes, pose_b=poses, stacked=st.booleans())
def test_clearance_grows_when_moved_away(size_a, size_b, pose_b, stacked):
    """B moved step by step along the direction of the closest points: the clearance never drops
    (the distance of convex sets is convex in the shift with a positive slope at the start)."""
    pose_b = np.array(pose_b)
    a, b = posed_box(size_a, np.zeros(3)), posed_box(size_b, pose_b)
    assume(not a.intersects(b))
    pa, pb = shapely.shortest_line(a, b).coords
    u = np.array(pb) - np.array(pa)
    assume(np.hypot(*u) > 1e-3)
    u /= np.hypot(*u)
    shifts = np.linspace(0.0, 10.0, 21)
    poses_b = pose_b + np.column_stack([shifts * u[0], shifts * u[1], np.zeros_like(shifts)])
    z_b = 3.5 if stacked else 0.0
    parts = [box_part("A", "a", size_a, 0.0, 3.0), box_part("B", "b", size_b, z_b, 3.0)]
    result = sweep_interference(parts, motion_with_a(poses_b), chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25,
                                search_length_mm=100.0)
    (pair,) = result.pairs
    assert np.all(pair.exact)
    assert np.all(np.diff(pair.clearance) >= -1e-9)
    assert pair.clearance[-1] > pair.clearance[0] + (1.0 if not stacked else 0.0)


def test_planar_clearance_matches_shapely_at_every_pose():
    """The clipped-window distances equal shapely's plain distance (1e-9 mm) over a rotating pose set."""
    a = Outline(four_bar_parts(make_four_bar())[2].polygons(CHORD_TOL))  # coupler slot with two holes
    b = Outline(four_bar_parts(make_four_bar())[1].polygons(CHORD_TOL))  # crank
    th = np.linspace(0.0, 2.0 * math.pi, 90)
    rel = RelativePoses(np.column_stack([20.0 + 6.0 * np.cos(th), 9.0 + 2.0 * np.sin(3 * th), th]))
    d = planar_clearance(a, b, rel, search_mm=3.0)
    reference = shapely.distance(a.polygon, b.posed(rel))
    overlap = shapely.intersects(a.polygon, b.posed(rel))
    assert np.any(overlap) and np.any(~overlap)
    near = ~overlap & (reference < 3.0 - 1e-6)
    assert np.any(near)
    np.testing.assert_allclose(d[near], reference[near], atol=1e-9)
    assert np.all(d[overlap] < 0)
    assert np.all(np.isinf(d[~overlap & (reference > 3.0 + 1e-6)]))


@pytest.fixture(scope="module")
def four_bar_motion():
    mech = make_four_bar()
    return mech, mech.sweep(360)


def test_four_bar_passes_with_pin_and_layer_clearances(four_bar_motion):
    """The layered four-bar: no collision; joined links keep the layer gap (0.3 mm), pins keep the
    radial hole clearance 0.25 mm within the chord tolerance; every pair is reported."""
    mech, motion = four_bar_motion
    expected = EXPECTED["layered"]
    result = sweep_interference(four_bar_parts(mech), motion, chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25)
    assert result.passed, result.failures()
    rows = {(p.a, p.b): p for p in result.pairs}
    gap = expected["joined_layer_gap_mm"]
    assert rows[("crank", "coupler")].relation == "joined"
    assert rows[("crank", "coupler")].min_clearance_mm == pytest.approx(gap, abs=1e-9)
    assert rows[("crank", "coupler")].kernel_gap_mm == pytest.approx(gap, abs=1e-6)
    pin_rows = [p for p in result.pairs if p.relation == "pin"]
    assert len(pin_rows) == expected["pin_pairs"]
    for p in pin_rows:
        assert expected["pin_clearance_mm"] - CHORD_TOL <= p.min_clearance_mm <= expected["pin_clearance_mm"] + 1e-9
        assert p.kernel_gap_mm == pytest.approx(p.min_clearance_mm, abs=1e-6)
    report = result.report()
    assert report["poses"] == 360 and report["collisions"] == []
    assert report["pairs_checked"] == len(result.pairs) == expected["pairs_checked"]
    assert report["rigid_pairs_skipped"] == expected["rigid_pairs_skipped"]
    assert report["min_clearance_mm"] == pytest.approx(min(p.min_clearance_mm for p in pin_rows), abs=1e-6)


def test_forced_layer_collision_caught_with_pair_and_inputs(four_bar_motion):
    """The coupler forced onto the ground's layer: it sweeps over the ground link for part of the
    turn. The colliding inputs must be exactly those where shapely finds a positive overlap, the
    volume the largest shapely area × thickness (1e-6 relative), and the failure must say so."""
    mech, motion = four_bar_motion
    expected_case = EXPECTED["coupler_on_ground_layer"]
    parts = four_bar_parts(mech, layers=expected_case["layers"])
    result = sweep_interference(parts, motion, chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25)
    assert not result.passed
    # the coupler hits the ground link and the pin at O; the pin at A (fixed in the coupler) hits
    # the ground link
    assert {(p.a, p.b) for p in result.collisions} == {tuple(p) for p in expected_case["colliding_pairs"]}
    pair = next(p for p in result.collisions if (p.a, p.b) == ("ground", "coupler"))
    ground, coupler = Outline(parts[0].polygons(CHORD_TOL)), Outline(parts[2].polygons(CHORD_TOL))
    rel = RelativePoses.between(motion.pose("ground"), motion.pose("coupler"))
    areas = shapely.area(shapely.intersection(ground.polygon, coupler.posed(rel)))
    expected = np.nonzero(areas > 1e-9)[0]
    assert 0 < len(expected) < len(motion.inputs) - 100
    np.testing.assert_array_equal(pair.collision_indices, expected)
    assert pair.max_overlap_mm3 == pytest.approx(areas.max() * 3.0, rel=1e-6)
    report = next(c for c in result.report()["collisions"] if (c["a"], c["b"]) == ("ground", "coupler"))
    assert report["input_deg"] == pytest.approx(motion.inputs[int(np.argmax(areas))])
    assert report["volume_mm3"] == pytest.approx(areas.max() * 3.0, rel=1e-6)
    ((lo, hi),) = report["input_ranges"]
    assert lo == pytest.approx(motion.inputs[expected[0]]) and hi == pytest.approx(motion.inputs[expected[-1]])
    assert any(f.startswith("interference: ground collides with coupler at input") for f in result.failures())


def test_same_verdicts_as_naive_boolean_sweep(four_bar_motion):
    """Every pair's colliding poses equal those of manifold booleans at every pose (36 poses)."""
    mech, _ = four_bar_motion
    motion = mech.sweep(36)
    parts = four_bar_parts(mech, layers={"ground": 0, "crank": 1, "rocker": 1, "coupler": 1})
    result = sweep_interference(parts, motion, chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25)
    naive = naive_interference(parts, motion, chord_tolerance_mm=CHORD_TOL)
    assert set(naive) == {(p.a, p.b) for p in result.pairs}
    for p in result.pairs:
        np.testing.assert_array_equal(np.nonzero(naive[(p.a, p.b)] > 1e-6)[0], p.collision_indices)
    assert {(p.a, p.b) for p in result.collisions} == {("crank", "coupler"), ("coupler", "rocker"),
                                                        ("coupler", "pin_O")}


def test_clearance_under_minimum_fails_without_collision(four_bar_motion):
    """Holes only 0.1 mm bigger than the pin (radially): no collision, but under the 0.25 mm minimum."""
    mech, motion = four_bar_motion
    parts = four_bar_parts(mech, clearance=0.1)
    result = sweep_interference(parts, motion, chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25)
    assert not result.collisions
    assert {p.relation for p in result.too_close()} == {"pin"}
    assert any(f.startswith("clearance:") for f in result.failures())


def test_tube_on_a_pin_bears_and_keeps_pin_clearance(four_bar_motion):
    """A tube on pin A filling the skipped layer between crank (layer 1) and coupler (layer 3): it
    touches the crank's face by design (bearing, clearance 0 allowed), the pin runs in it with the
    radial clearance (2.5 - 2) / 2 mm, and the build passes."""
    mech, motion = four_bar_motion
    parts = four_bar_parts(mech, layers={"ground": 0, "crank": 1, "rocker": 1, "coupler": 3})
    crank, coupler = parts[1], parts[2]
    top = crank.z_mm + crank.thickness_mm
    tube = SimpleNamespace(joint="A", body="coupler", centre=np.zeros(2), inner_diameter_mm=2.5,
                           outer_diameter_mm=4.7, z_mm=top, length_mm=coupler.z_mm - top, washer=False)
    result = sweep_interference(parts, motion, chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25, spacers=[tube])
    assert result.passed, result.failures()
    rows = {(p.a, p.b): p for p in result.pairs}
    assert rows[("crank", "tube_A")].relation == "bearing"
    assert rows[("crank", "tube_A")].min_clearance_mm == 0.0
    assert not rows[("crank", "tube_A")].collides
    assert rows[("pin_A", "tube_A")].relation == "pin"
    assert 0.25 - CHORD_TOL <= rows[("pin_A", "tube_A")].min_clearance_mm <= 0.25


@settings(max_examples=40, deadline=None)
@given(x=st.floats(-30.0, 60.0), y=st.floats(-20.0, 20.0), theta=st.floats(-math.pi, math.pi),
       search=st.floats(0.2, 5.0))
def test_clipped_distance_equals_plain_distance(x, y, theta, search):
    """Non-convex outlines with holes (two slot links) at a random relative pose: the windowed
    distance equals shapely's distance on the whole outlines when within the search length (1e-9 mm),
    is +inf beyond it, 0 when touching and -inf when overlapping."""
    parts = four_bar_parts(make_four_bar())
    a, b = Outline(parts[2].polygons(CHORD_TOL)), Outline(parts[3].polygons(CHORD_TOL))
    rel = RelativePoses(np.array([[x, y, theta]]))
    (d,) = planar_clearance(a, b, rel, search)
    (poly_b,) = b.posed(rel)
    reference = shapely.distance(a.polygon, poly_b)
    assume(abs(reference - search) > 1e-6)
    if a.polygon.intersects(poly_b):
        assert d == (0.0 if a.polygon.touches(poly_b) else -math.inf)
    elif reference < search:
        assert d == pytest.approx(reference, abs=1e-9)
    else:
        assert d == math.inf


# -- the poses streamed in chunks (issue 27, item 5) -----------------------------------------------------
@pytest.mark.parametrize("layers", [None, "coupler_on_ground_layer"])
def test_a_sweep_streamed_seven_poses_at_a_time_equals_the_sweep_all_at_once(monkeypatch, four_bar_motion, layers):
    """The posed outlines are held a chunk of poses at a time (memory flat in the poses): seven poses a chunk
    gives every pair's clearance per pose, exactness, minimum and its pose, kernel gap, colliding poses and
    overlap volumes exactly (not approximately) as all 360 at once, for the clear four-bar and the colliding
    one; and no call posed more than seven copies at once."""
    import fabricate.checks.distance as distance

    mech, motion = four_bar_motion
    parts = four_bar_parts(mech, **({} if layers is None else {"layers": EXPECTED[layers]["layers"]}))

    def sweep(chunk: int) -> tuple[object, int]:
        held = [0]
        posed = Outline.posed

        def spy(self: Outline, rel: RelativePoses) -> np.ndarray:
            held[0] = max(held[0], len(rel.q))
            return posed(self, rel)

        monkeypatch.setattr(distance, "poses_per_chunk", lambda outline: chunk)
        monkeypatch.setattr(Outline, "posed", spy)
        result = sweep_interference(parts, motion, chord_tolerance_mm=CHORD_TOL, min_clearance_mm=0.25)
        monkeypatch.undo()
        return result, held[0]

    whole, held_whole = sweep(10 ** 9)
    chunked, held_chunked = sweep(7)
    assert held_whole > 100 and held_chunked == 7  # the near poses of a pair: up to all 360 at once
    assert (layers is None) == (not whole.collisions)
    assert len(chunked.pairs) == len(whole.pairs) > 0
    for a, b in zip(whole.pairs, chunked.pairs, strict=True):
        for name in ("a", "b", "relation", "z_gap_mm", "required_mm", "min_clearance_mm", "min_index",
                     "kernel_gap_mm", "max_overlap_mm3", "max_overlap_index"):
            assert getattr(a, name) == getattr(b, name), (a.a, a.b, name)
        for name in ("clearance", "exact", "collision_indices", "overlap_indices", "overlap_mm3"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert json.dumps(whole.report()) == json.dumps(chunked.report())
