"""Interference sweep: exact volumes and clearances against shapely, a deliberately colliding four-bar,
and the naive all-pairs boolean reference."""

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
from fabricate.checks.interference import naive_interference, sweep_interference
from fabricate.mechanism import Motion
from fabricate.parts.model import BulgePath, Part
from fabricate.planar import transform_points
from tests.conftest import make_four_bar
from tests.interference_fixtures import four_bar_parts

TOL = 0.005  # chord tolerance of the solids, mm
EXPECTED = json.loads((Path(__file__).parent / "data" / "interference_four_bar.json").read_text())


def box_part(name: str, body: str, size: tuple[float, float], z: float, thickness: float) -> Part:
    """A rectangle centred on its body origin, extruded from ``z``."""
    w, h = size
    outline = BulgePath.polyline(np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]]))
    return Part(name, body, outline, (), thickness, z, 0, "sla")


def motion_of(poses_b: np.ndarray, pose_a: np.ndarray | None = None) -> Motion:
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
    result = sweep_interference(parts, motion_of(pose_b[None, :], pose_a), chord_tolerance_mm=TOL,
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
    result = sweep_interference(parts, motion_of(poses_b), chord_tolerance_mm=TOL, min_clearance_mm=0.25,
                                search_length_mm=100.0)
    (pair,) = result.pairs
    assert np.all(pair.exact)
    assert np.all(np.diff(pair.clearance) >= -1e-9)
    assert pair.clearance[-1] > pair.clearance[0] + (1.0 if not stacked else 0.0)


def test_planar_clearance_matches_shapely_at_every_pose():
    """The clipped-window distances equal shapely's plain distance (1e-9 mm) over a rotating pose set."""
    a = Outline(four_bar_parts(make_four_bar())[2].polygons(TOL))  # coupler slot with two holes
    b = Outline(four_bar_parts(make_four_bar())[1].polygons(TOL))  # crank
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
    result = sweep_interference(four_bar_parts(mech), motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    assert result.passed, result.failures()
    rows = {(p.a, p.b): p for p in result.pairs}
    gap = expected["joined_layer_gap_mm"]
    assert rows[("crank", "coupler")].relation == "joined"
    assert rows[("crank", "coupler")].min_clearance_mm == pytest.approx(gap, abs=1e-9)
    assert rows[("crank", "coupler")].kernel_gap_mm == pytest.approx(gap, abs=1e-6)
    pin_rows = [p for p in result.pairs if p.relation == "pin"]
    assert len(pin_rows) == expected["pin_pairs"]
    for p in pin_rows:
        assert expected["pin_clearance_mm"] - TOL <= p.min_clearance_mm <= expected["pin_clearance_mm"] + 1e-9
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
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    assert not result.passed
    # the coupler hits the ground link and the pin at O; the pin at A (fixed in the coupler) hits
    # the ground link
    assert {(p.a, p.b) for p in result.collisions} == {tuple(p) for p in expected_case["colliding_pairs"]}
    pair = next(p for p in result.collisions if (p.a, p.b) == ("ground", "coupler"))
    ground, coupler = Outline(parts[0].polygons(TOL)), Outline(parts[2].polygons(TOL))
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
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
    naive = naive_interference(parts, motion, chord_tolerance_mm=TOL)
    assert set(naive) == {(p.a, p.b) for p in result.pairs}
    for p in result.pairs:
        np.testing.assert_array_equal(np.nonzero(naive[(p.a, p.b)] > 1e-6)[0], p.collision_indices)
    assert {(p.a, p.b) for p in result.collisions} == {("crank", "coupler"), ("coupler", "rocker"),
                                                        ("coupler", "pin_O")}


def test_clearance_under_minimum_fails_without_collision(four_bar_motion):
    """Holes only 0.1 mm bigger than the pin (radially): no collision, but under the 0.25 mm minimum."""
    mech, motion = four_bar_motion
    parts = four_bar_parts(mech, clearance=0.1)
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25)
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
    result = sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=0.25, spacers=[tube])
    assert result.passed, result.failures()
    rows = {(p.a, p.b): p for p in result.pairs}
    assert rows[("crank", "tube_A")].relation == "bearing"
    assert rows[("crank", "tube_A")].min_clearance_mm == 0.0
    assert not rows[("crank", "tube_A")].collides
    assert rows[("pin_A", "tube_A")].relation == "pin"
    assert 0.25 - TOL <= rows[("pin_A", "tube_A")].min_clearance_mm <= 0.25


@settings(max_examples=40, deadline=None)
@given(x=st.floats(-30.0, 60.0), y=st.floats(-20.0, 20.0), theta=st.floats(-math.pi, math.pi),
       search=st.floats(0.2, 5.0))
def test_clipped_distance_equals_plain_distance(x, y, theta, search):
    """Non-convex outlines with holes (two slot links) at a random relative pose: the windowed
    distance equals shapely's distance on the whole outlines when within the search length (1e-9 mm),
    is +inf beyond it, 0 when touching and -inf when overlapping."""
    parts = four_bar_parts(make_four_bar())
    a, b = Outline(parts[2].polygons(TOL)), Outline(parts[3].polygons(TOL))
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
