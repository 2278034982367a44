"""Actuator geometry (``fabricate/drive/geometry.py``) against the catalogue's numbers and hand geometry:
placements turn and mirror the catalogue frame, the horn's pattern is the catalogue's rotated, shaft bores
measure the shaft plus the clearance across their flats, plates cut out what passes through them, screws
fit the holes they go through."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from fabricate.catalogue.actuators import BYJ48, NEMA17, SG90, Shaft
from fabricate.drive import geometry as geo


def extent(ring: np.ndarray, centre: np.ndarray, direction: float) -> tuple[float, float]:
    """How far a ring reaches from ``centre`` along +u and -u, u at ``direction`` (rad)."""
    u = np.array([math.cos(direction), math.sin(direction)])
    s = (ring - centre) @ u
    return float(s.max()), float(-s.min())


def test_placement_turns_then_mirrors_and_maps_z_both_ways():
    centre = np.array([3.0, -2.0])
    up = geo.Placement(centre, math.pi / 2, False, 10.0)
    np.testing.assert_allclose(up.plan(np.array([1.0, 0.0])), [3.0, -1.0], atol=1e-12)
    np.testing.assert_allclose(up.plan(np.array([0.0, 1.0])), [2.0, -2.0], atol=1e-12)
    assert up.z_range(-5.0, 2.0) == pytest.approx((5.0, 12.0))
    down = geo.Placement(centre, math.pi / 2, True, 10.0)
    # over the stack the catalogue's y is mirrored before the turn (z points down)
    np.testing.assert_allclose(down.plan(np.array([0.0, 1.0])), [4.0, -2.0], atol=1e-12)
    assert down.z_range(-5.0, 2.0) == pytest.approx((8.0, 15.0))
    square = geo.rectangle(0.0, 0.0, 2.0, 1.0)
    assert shapely.Polygon(geo.placed_ring(square, down)).exterior.is_ccw


@pytest.mark.parametrize("angle", [0.0, 0.7, -2.1])
def test_horn_pattern_is_the_catalogue_pattern_rotated_about_the_axis(angle):
    holes = SG90.horn.arm_holes
    centre = np.array([12.0, -4.0])
    got = geo.horn_pattern(holes, centre, angle)
    c, s = math.cos(angle), math.sin(angle)
    for (x, y), h in zip(got, holes, strict=True):
        assert x == pytest.approx(centre[0] + c * h.x - s * h.y, abs=1e-12)
        assert y == pytest.approx(centre[1] + s * h.x + c * h.y, abs=1e-12)


def test_horn_holes_are_the_innermost_ring_clear_of_the_hub_bore():
    horn = SG90.horn
    # bore 6.92 + 0.5 + 0.2 = 7.62, pilots 1.6 + 0.2: the 5 mm holes leave 5 - 0.9 - 3.81 = 0.29 mm of wall
    used = geo.horn_holes(horn, 7.62, 1.8, 0.8)
    assert sorted((h.x, h.y) for h in used) == [(-7.0, 0.0), (7.0, 0.0)]
    # a thin wall allowed: the 5 mm ring
    assert sorted(h.x for h in geo.horn_holes(horn, 7.62, 1.8, 0.2)) == [-5.0, 5.0]
    # a screw head too wide to sit beside the hub pushes it out again
    assert sorted(h.x for h in geo.horn_holes(horn, 7.62, 1.8, 0.2, head_d_mm=5.0)) == [-7.0, 7.0]


def test_horn_screw_taps_the_arm_hole_and_sits_in_the_part():
    assert geo.horn_screw_size(SG90.horn) == "M2"  # the smallest size over the Ø1.5 arm holes
    s = geo.screw_into("M2", SG90.horn.arm_thickness_mm, 3.0)
    # the longest ISO 4762 length whose tip stays in a 3 mm part: 4 mm (1.43 + 3 = 4.43 < 5)
    assert s.designation == "ISO 4762 M2 × 4"
    assert SG90.horn.arm_thickness_mm + 2.0 <= s.length_mm <= SG90.horn.arm_thickness_mm + 3.0


@pytest.mark.parametrize("clearance", [0.0, 0.35])
def test_double_d_bore_measures_the_shaft_plus_the_clearance(clearance):
    shaft = BYJ48.shaft  # Ø5, 3 across the flats (NopSCADlib)
    centre, angle = np.array([1.0, 2.0]), 0.4
    bore = geo.shaft_bore(shaft, centre, angle, clearance)
    ring = bore.polygon(1e-4)
    plus, minus = extent(ring, centre, angle)
    assert plus + minus == pytest.approx(3.0 + 2.0 * clearance, abs=1e-9)  # across the flats
    assert plus == pytest.approx(minus, abs=1e-9)
    side = extent(ring, centre, angle + math.pi / 2)
    assert sum(side) == pytest.approx(5.0 + 2.0 * clearance, abs=1e-3)  # across the round (chords inside)
    # the exact area: the circle less two circular segments
    r, h = 2.5 + clearance, 1.5 + clearance
    segment = r * r * math.acos(h / r) - h * math.sqrt(r * r - h * h)
    assert bore.area() == pytest.approx(math.pi * r * r - 2.0 * segment, rel=1e-12)


def test_d_bore_has_its_flat_across_flats_from_the_far_side():
    shaft = Shaft(diameter_mm=3.0, length_mm=9.0, flats=1, across_flats_mm=2.5, flat_length_mm=6.0)
    centre = np.zeros(2)
    ring = geo.shaft_bore(shaft, centre, math.pi / 3, 0.3).polygon(1e-4)
    plus, minus = extent(ring, centre, math.pi / 3)
    assert plus == pytest.approx(2.5 - 1.5 + 0.3, abs=1e-9)  # the flat
    assert minus == pytest.approx(1.5 + 0.3, abs=1e-6)  # the round side
    assert shapely.Polygon(ring).is_valid and shapely.Polygon(ring).exterior.is_ccw


def test_a_shaft_without_stated_flats_gets_a_round_bore():
    bore = geo.shaft_bore(NEMA17.shaft, np.zeros(2), 0.0, 0.1)
    assert bore.area() == pytest.approx(math.pi * 2.6 ** 2, rel=1e-12)


def test_servo_plate_cuts_out_the_case_and_stepper_plate_the_boss():
    pz = geo.mount_plate_z(SG90)
    assert pz == pytest.approx(-8.34)  # the tabs' top face (Kartchner: fore 8.34)
    (case,) = geo.plate_cutouts(SG90, pz, pz + 3.0, 0.25)
    x0, y0 = case.min(axis=0)
    x1, y1 = case.max(axis=0)
    assert (x1 - x0, y1 - y0) == pytest.approx((22.62 + 0.5, 12.38 + 0.5))
    assert 0.5 * (x0 + x1) == pytest.approx(-6.19)  # the case centre behind the axle
    (boss,) = geo.plate_cutouts(NEMA17, 0.0, 3.0, 0.25)
    assert boss.max(axis=0) - boss.min(axis=0) == pytest.approx([22.5, 22.5])
    assert geo.plate_cutouts(NEMA17, 5.0, 8.0, 0.25) == []


def test_fastenings_fit_the_mounting_holes():
    tab = geo.fastening(SG90, SG90.mounting_holes[0], 3.0, 0.25, 0.2)
    # Ø2.6 tab hole: M2 (ISO 7089 bore 2.2 passes, M2.5's 2.7 does not), through the 2.46 mm tab into the plate
    assert (tab.size, tab.tapped) == ("M2", False)
    assert tab.clamp_mm == pytest.approx(2.46) and tab.engagement_mm == 3.0
    assert tab.plate_hole_mm == pytest.approx(geo.PILOT_FRACTION * 2.0 + 0.2)
    face = geo.fastening(NEMA17, NEMA17.mounting_holes[0], 3.0, 0.25, 0.2)
    # the NEMA 17 holes are tapped M3: through the plate's clearance hole into the motor
    assert (face.size, face.tapped, face.clamp_mm) == ("M3", True, 3.0)
    assert face.plate_hole_mm == pytest.approx(3.0 + 0.5 + 0.2)
    assert face.engagement_mm == pytest.approx(geo.TAPPED_ENGAGEMENT * 3.0)
    lug = geo.fastening(BYJ48, BYJ48.mounting_holes[0], 3.0, 0.25, 0.2)
    assert (lug.size, lug.clamp_mm) == ("M3", pytest.approx(0.85))  # Ø4.2 passes M3 (3.2) not M4 (4.3)


def test_body_solids_are_the_catalogue_boxes_placed():
    place = geo.Placement(np.array([5.0, 5.0]), math.pi, False, -2.0)
    solids = geo.body_solids(NEMA17, place)
    assert [s.name for s in solids] == ["actuator_body_1", "actuator_body_2"]
    assert (solids[0].z0, solids[0].z1) == pytest.approx((-42.0, -2.0))
    assert shapely.Polygon(solids[0].rings[0]).area == pytest.approx(42.3 ** 2)
    assert geo.output_base_z(NEMA17) == 2.0 and geo.output_base_z(SG90) == 0.0
