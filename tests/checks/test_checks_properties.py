"""Check verdicts at their boundaries, with the measured values checked against closed forms here.

Written to kill mutants of ``fabricate/checks`` (see ``tests/benchmarks/mutation_report.md``): a clearance
just under the requirement fails, one just at it passes; the slack of the verdict is the chord tolerance.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import shapely

from fabricate.checks.distance import Outline, RelativePoses, overlap_areas, planar_clearance
from fabricate.checks.interference import sweep_interference
from tests.conftest import make_four_bar
from tests.interference_fixtures import four_bar_parts

REQUIRED = 0.25  # mm radial clearance the process asks for
TOL = 0.002  # chord tolerance of the polygonised solids: the slack of the verdict


@cache
def four_bar_motion():
    mech = make_four_bar()
    return mech, mech.sweep(73)


def sweep_with_hole_clearance(clearance: float):
    mech, motion = four_bar_motion()
    parts = four_bar_parts(mech, clearance=clearance)
    return sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=REQUIRED)


@pytest.mark.parametrize("short_by", [2.5 * TOL, 4 * TOL, 0.012])
def test_clearance_just_under_the_requirement_fails(short_by):
    """Holes whose radial clearance is a few chord tolerances short of 0.25 mm: no collision, every pin
    pair measured within the chord tolerance of the designed clearance, and the verdict fails."""
    clearance = REQUIRED - short_by
    result = sweep_with_hole_clearance(clearance)
    assert not result.collisions
    pins = [p for p in result.pairs if p.relation == "pin"]
    assert pins
    for p in pins:
        assert clearance - TOL - 1e-9 <= p.min_clearance_mm <= clearance + 1e-9
    assert {(p.a, p.b) for p in result.too_close()} == {(p.a, p.b) for p in pins}
    assert not result.passed
    assert sum(f.startswith("clearance:") for f in result.failures()) == len(pins)
    report = {(r["a"], r["b"]): r for r in result.report()["pairs"]}
    assert not any(report[(p.a, p.b)]["ok"] for p in pins)


def test_clearance_at_the_requirement_passes():
    """Designed exactly at 0.25 mm the polygonised holes measure at most a chord tolerance less: passes."""
    result = sweep_with_hole_clearance(REQUIRED)
    pins = [p for p in result.pairs if p.relation == "pin"]
    for p in pins:
        assert REQUIRED - TOL - 1e-9 <= p.min_clearance_mm <= REQUIRED + 1e-9
    assert result.too_close() == []
    assert result.passed, result.failures()
    assert all(r["ok"] for r in result.report()["pairs"])


# -- distance kernel pieces against shapely on raw coordinates --------------------------------------
def _posed_shapely(ring: np.ndarray, pose) -> shapely.Polygon:
    x, y, th = pose
    c, s = np.cos(th), np.sin(th)
    return shapely.Polygon(np.column_stack([c * ring[:, 0] - s * ring[:, 1] + x, s * ring[:, 0] + c * ring[:, 1] + y]))


def test_relative_poses_inverse_and_apply():
    rng = np.random.default_rng(3)
    q = np.column_stack([rng.uniform(-20, 20, 9), rng.uniform(-20, 20, 9), rng.uniform(-4, 4, 9)])
    rel = RelativePoses(q)
    pts = rng.uniform(-5, 5, (6, 2))
    mapped = rel.apply(pts)  # (n, m, 2)
    assert mapped.shape == (9, 6, 2)
    for i in range(9):
        x, y, th = q[i]
        expected = pts @ np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]]) + [x, y]
        np.testing.assert_allclose(mapped[i], expected, atol=1e-12)
        back = rel.inverse().apply(mapped[i], np.full(6, i))
        np.testing.assert_allclose(back, pts, atol=1e-12)
    # between(): B in A's frame from two world poses
    pa, pb = q[:4], q[4:8]
    between = RelativePoses.between(pa, pb)
    for i in range(4):
        world = RelativePoses(pb[i:i + 1]).apply(pts)[0]
        in_a = RelativePoses(pa[i:i + 1]).inverse().apply(world)[0]
        np.testing.assert_allclose(between.apply(pts)[i], in_a, atol=1e-9)


def test_overlap_areas_and_clearance_match_shapely():
    """Overlap area and planar clearance of an L-shaped plate with a hole and a moving square, at poses
    that overlap, touch nearly and stand apart, against shapely on raw posed coordinates."""
    outer = np.array([[0, 0], [20, 0], [20, 6], [6, 6], [6, 20], [0, 20]], dtype=float)
    hole = np.array([[2, 2], [2, 4], [4, 4], [4, 2]], dtype=float)  # clockwise
    square = np.array([[0, 0], [3, 0], [3, 3], [0, 3]], dtype=float)
    a, b = Outline([outer, hole]), Outline([square])
    q = np.array([[8, 1, 0.0], [10, 5, 0.3], [8, 8, 0.1], [6.5, 6.5, 0.0], [12, 12, 1.0], [2.5, 2.5, 0.0],
                  [-1, -1, 0.5], [31, 30.5, 0.0]])
    rel = RelativePoses(q)
    plate = shapely.Polygon(outer, [hole])
    truth_area = [plate.intersection(_posed_shapely(square, p)).area for p in q]
    np.testing.assert_allclose(overlap_areas(a, b, rel), truth_area, atol=1e-9)
    truth_dist = np.array([plate.distance(_posed_shapely(square, p)) for p in q])
    got = planar_clearance(a, b, rel, search_mm=5.0)
    overlapping = np.asarray(truth_area) > 0
    assert overlapping.sum() == 4
    assert np.all(got[overlapping] == -np.inf)  # interiors overlap: -inf by contract
    near = (truth_dist <= 5.0) & ~overlapping
    np.testing.assert_allclose(got[near], truth_dist[near], atol=1e-9)
    far = (truth_dist > 5.0) & ~overlapping
    assert far.sum() == 1 and np.all(got[far] > 5.0)  # beyond the search length: a lower bound only


@pytest.mark.parametrize("gap", [10.0, 2 * (5.0 * (1.0 + 1e-9) + 1e-12)])
def test_clearance_when_the_search_windows_just_touch(gap):
    """Boxes 10 mm apart on both axes with a 5 mm search length: farther than the search, so +inf. The clip
    window's half-width is a hair over the search length (5 (1 + 1e-9) + 1e-12 mm): boxes exactly two of them apart
    give a zero-width window, which must not reach GEOS (it raises on an empty clip rectangle)."""
    a = Outline([np.array([[0, 0], [20, 0], [20, 20], [0, 20]], dtype=float)])
    b = Outline([np.array([[0, 0], [3, 0], [3, 3], [0, 3]], dtype=float)])
    got = planar_clearance(a, b, RelativePoses(np.array([[20.0 + gap, 20.0 + gap, 0.0]])), search_mm=5.0)
    assert got[0] == np.inf
    got = planar_clearance(a, b, RelativePoses(np.array([[20.0 + gap, 10.0, 0.0]])), search_mm=5.0)
    assert got[0] == np.inf


def test_input_ranges_are_contiguous_runs():
    result = sweep_with_hole_clearance(REQUIRED)
    x = result.inputs
    assert result.input_ranges(np.array([], dtype=int)) == []
    assert result.input_ranges(np.array([3])) == [(x[3], x[3])]
    assert result.input_ranges(np.array([0, 1, 2, 5, 6, 9])) == [(x[0], x[2]), (x[5], x[6]), (x[9], x[9])]


def test_outline_orients_its_rings_and_drops_repeated_vertices():
    """Rings given the wrong way round (outer clockwise, hole counter-clockwise) with a closing vertex and a
    doubled vertex: the outline is the plate minus the hole (area 600 - 16), outer CCW, hole CW; the centre and
    radius of its vertex box are the closed forms. Small rings (under 1 mm^2) are oriented too, and vertices
    1e-9 mm apart are distinct (only repeats within 1e-12 mm are dropped)."""
    from fabricate.planar import polygon_area

    shift = np.array([2.0, -3.0])
    outer = np.array([[0, 0], [0, 20], [30, 20], [30, 20], [30, 0], [0, 0]], dtype=float) + shift  # CW, closed
    hole = np.array([[8, 8], [12, 8], [12, 12], [8, 12]], dtype=float) + shift  # counter-clockwise
    out = Outline([outer, hole])
    assert [len(r) for r in out.rings] == [4, 4]
    assert polygon_area(out.rings[0]) == pytest.approx(600.0) and polygon_area(out.rings[1]) == pytest.approx(-16.0)
    assert out.polygon.area == pytest.approx(584.0)
    np.testing.assert_allclose(out.centre, [17.0, 7.0])
    assert out.radius == pytest.approx(np.hypot(15.0, 10.0))
    np.testing.assert_allclose(out.bounds, [2, -3, 32, 17])
    small = Outline([np.array([[0, 0], [1, 0], [1, 0.5], [0, 0.5]], dtype=float),  # 0.5 mm^2, CCW
                     np.array([[0.2, 0.1], [0.4, 0.1], [0.4, 0.3], [0.2, 0.3]], dtype=float)])  # 0.04 mm^2, CCW
    assert polygon_area(small.rings[0]) == pytest.approx(0.5) and polygon_area(small.rings[1]) == pytest.approx(-0.04)
    near = np.array([[100, 100], [110, 100], [110, 110], [100, 110], [100, 100 + 1e-9]], dtype=float)
    assert len(Outline([near]).rings[0]) == 5
    doubled_first = np.array([[0, 0], [0, 0], [5, 0], [5, 5], [0, 5]], dtype=float)
    np.testing.assert_array_equal(Outline([doubled_first]).rings[0], [[0, 0], [5, 0], [5, 5], [0, 5]])


@pytest.mark.parametrize("chunk", [1, 7, 8, 9, 10**6])
@pytest.mark.parametrize("shift", [(0.0, 0.0), (0.0, 50.0), (-40.0, 3.0)])
def test_clearance_and_overlap_do_not_depend_on_the_chunk_size(monkeypatch, chunk, shift):
    """The posed copies are built in chunks of POSED_VERTICES_PER_CHUNK vertices: any chunk size (one pose at a
    time, two at a time, all at once) gives the same distances and areas, equal to shapely on raw
    coordinates, wherever the plate lies; touching boundaries give exactly 0, a distance equal to the search
    length is resolved."""
    import fabricate.checks.distance as distance

    monkeypatch.setattr(distance, "POSED_VERTICES_PER_CHUNK", chunk)
    plate = np.array([[0, 0], [20, 0], [20, 6], [0, 6]], dtype=float) + shift
    square = np.array([[0, 0], [3, 0], [3, 3], [0, 3]], dtype=float)
    a, b = Outline([plate]), Outline([square])
    q = np.array([[5, 7, 0.0], [5, 6.5, 0.1], [5, 6, 0.0], [5, 8.5, 0.0], [4, 4, 0.2], [25, 2, 0.0], [5, 7, 0.0],
                  [40, 40, 0.0], [5, 10, 0.0], [-3, 1, 0.0]])
    q[:, :2] += shift
    got = distance.planar_clearance(a, b, RelativePoses(q), search_mm=4.0)
    truth = np.array([shapely.Polygon(plate).distance(_posed_shapely(square, p)) for p in q])
    area = np.array([shapely.Polygon(plate).intersection(_posed_shapely(square, p)).area for p in q])
    assert got[2] == 0.0  # the square's bottom edge lies on the plate's top edge
    assert got[4] == -np.inf and area[4] > 0
    assert got[7] == np.inf  # farther than the search length
    assert got[8] == pytest.approx(4.0, abs=1e-12)  # exactly the search length away: resolved, not +inf
    keep = (truth <= 4.0) & (area == 0)
    assert keep.sum() == 7
    np.testing.assert_allclose(got[keep], truth[keep], atol=1e-9)
    np.testing.assert_allclose(distance.overlap_areas(a, b, RelativePoses(q)), area, atol=1e-9)
    assert distance.overlap_areas(a, b, RelativePoses(np.zeros((0, 3)))).shape == (0,)
    assert distance.planar_clearance(a, b, RelativePoses(np.zeros((0, 3))), 4.0).shape == (0,)
