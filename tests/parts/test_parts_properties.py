"""Part profiles and sizes against closed forms and shapely on raw coordinates.

Written to kill mutants of ``fabricate/parts`` (see ``tests/benchmarks/mutation_report.md``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.hints import PartHints
from fabricate.parts.build import derive_sizes
from fabricate.parts.model import BulgePath
from fabricate.parts.profiles import circle_hull, circle_path, fuse_polygons, offset_path
from fabricate.parts.spec import PartsSpec
from fabricate.planar import polygon_area


def test_sizes_closed_forms(sla_process, laser_process):
    """hole = pin + 2 c + compensation; wall = max(min wall, pin / 2) (laser: >= sheet thickness);
    boss = hole / 2 + wall; mount hole = screw + 2 c + compensation, its boss + wall; hub >= hole + 2 walls."""
    for process in (sla_process, laser_process):
        pin, c, comp = process.pin_diameter_mm, process.running_clearance_mm, process.hole_compensation_mm
        wall = max(process.min_wall_mm, 0.5 * pin)
        if process.name == "laser":
            wall = max(wall, process.thickness_mm)
        s = derive_sizes(process, PartsSpec(mounting_hole_mm=4.0), PartHints())
        assert s.pin_mm == pin
        assert s.hole_mm == pytest.approx(pin + 2 * c + comp, abs=1e-12)
        assert s.boss_radius_mm == pytest.approx((pin + 2 * c + comp) / 2 + wall, abs=1e-12)
        assert s.mount_hole_mm == pytest.approx(4.0 + 2 * c + comp, abs=1e-12)
        assert s.mount_boss_radius_mm == pytest.approx((4.0 + 2 * c + comp) / 2 + wall, abs=1e-12)
        assert s.hub_mm == pytest.approx(max(2 * s.boss_radius_mm, s.hole_mm + 2 * process.min_wall_mm), abs=1e-12)
        # an explicit boss wall and hub win (the hub still at least hole + 2 min walls)
        t = derive_sizes(process, PartsSpec(boss_wall_mm=5.0, hub_diameter_mm=30.0), PartHints())
        wall_t = max(5.0, process.thickness_mm) if process.name == "laser" else 5.0
        assert t.boss_radius_mm == pytest.approx(s.hole_mm / 2 + wall_t, abs=1e-12)
        assert t.hub_mm == pytest.approx(30.0, abs=1e-12)
        tiny = derive_sizes(process, PartsSpec(hub_diameter_mm=0.5), PartHints())
        assert tiny.hub_mm == pytest.approx(s.hole_mm + 2 * process.min_wall_mm, abs=1e-12)
        geared = derive_sizes(process, PartsSpec(), PartHints(), gear_hub_mm=25.0)
        assert geared.hub_mm == pytest.approx(25.0, abs=1e-12)


def test_circle_path_is_the_circle():
    path = circle_path(np.array([3.0, -2.0]), 4.0)
    assert path.area() == pytest.approx(math.pi * 16.0, rel=1e-12)
    poly = path.polygon(1e-4)
    np.testing.assert_allclose(np.hypot(*(poly - [3.0, -2.0]).T), 4.0, rtol=1e-12)
    assert polygon_area(poly) > 0


def test_hull_of_nested_and_coincident_circles():
    """A circle inside another adds nothing; two coincident circles are one; three circles in a row are
    the stadium of the outer two (closed forms)."""
    inner = circle_hull(np.array([[0.0, 0.0], [1.0, 0.5]]), np.array([5.0, 2.0]))
    assert inner.area() == pytest.approx(math.pi * 25.0, rel=1e-12)
    same = circle_hull(np.array([[2.0, 2.0], [2.0, 2.0]]), np.array([3.0, 3.0]))
    assert same.area() == pytest.approx(math.pi * 9.0, rel=1e-12)
    row = circle_hull(np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0]]), 2.0)
    assert row.area() == pytest.approx(20.0 * 4.0 + math.pi * 4.0, rel=1e-9)
    # unequal radii: area of the exact hull of two circles (closed form with the tangent angle)
    r1, r2, d = 4.0, 2.0, 12.0
    pear = circle_hull(np.array([[0.0, 0.0], [d, 0.0]]), np.array([r1, r2]))
    a = math.asin((r1 - r2) / d)
    expected = (r1 + r2) * d * math.cos(a) + (math.pi + 2 * a) * r1 ** 2 / 2 + (math.pi - 2 * a) * r2 ** 2 / 2
    assert pear.area() == pytest.approx(expected, rel=1e-9)
    assert polygon_area(pear.vertices) > 0  # counter-clockwise
    with pytest.raises(Exception, match="positive radius"):
        circle_hull(np.array([[0.0, 0.0]]), 0.0)


def test_offset_of_a_polyline_is_the_minkowski_sum():
    """A concave L (polyline): grown by d its area is shapely's buffer of the raw vertices, and shrinking
    gives the erosion; both counter-clockwise and starting at the lowest-leftmost vertex."""
    ell = BulgePath.polyline(np.array([[0, 0], [10, 0], [10, 3], [3, 3], [3, 10], [0, 10]], dtype=float))
    raw = shapely.Polygon(ell.vertices)
    for d in (0.4, -0.4):
        out = offset_path(ell, d)
        expected = raw.buffer(d, quad_segs=256, join_style="round")
        assert shapely.Polygon(out.vertices).area == pytest.approx(expected.area, abs=2e-3 * abs(d) * raw.length)
        assert shapely.Polygon(out.vertices).symmetric_difference(expected).area < 1e-2
        assert polygon_area(out.vertices) > 0
        first = out.vertices[0]
        assert tuple(first) == min(map(tuple, out.vertices))
    assert offset_path(ell, 0.0) is ell
    with pytest.raises(Exception, match="splits or removes"):
        offset_path(ell, -2.0)  # the 3 mm arms vanish


def test_fuse_fills_enclosed_gaps_and_drops_collinear_points():
    """A ring of four bars around an empty square: the fused plate is the outer square (gap filled), with
    no vertex in the middle of a straight edge."""
    base = BulgePath.polyline(np.array([[0, 0], [10, 0], [10, 2], [0, 2]], dtype=float))
    bars = [np.array([[8, 0], [10, 0], [10, 10], [8, 10]], dtype=float),
            np.array([[0, 8], [10, 8], [10, 10], [0, 10]], dtype=float),
            np.array([[0, 0], [2, 0], [2, 10], [0, 10]], dtype=float)]
    fused = fuse_polygons(base, bars, 0.01)
    assert shapely.Polygon(fused.vertices).area == pytest.approx(100.0, abs=1e-9)
    assert len(fused.vertices) == 4
    assert polygon_area(fused.vertices) > 0
    np.testing.assert_array_equal(fused.vertices[0], [0.0, 0.0])


def _reversed(path: BulgePath) -> BulgePath:
    """The same contour traversed the other way: vertices reversed, each arc's bulge negated on its reversed
    segment."""
    return BulgePath(path.vertices[::-1].copy(), -np.roll(path.bulges[::-1], -1))


@pytest.mark.parametrize("d", [0.7, -0.7])
def test_offset_of_a_hull_of_circles_is_the_hull_of_the_grown_circles(d):
    """A pear (radii 4 and 2, 12 mm apart) offset by d is the exact hull of the circles with radii + d: same
    vertices and bulges, area by the closed form; the same contour given clockwise is offset outwards too."""
    centres, radii = np.array([[0.0, 0.0], [12.0, 0.0]]), np.array([4.0, 2.0])
    pear = circle_hull(centres, radii)
    grown = circle_hull(centres, radii + d)
    out = offset_path(pear, d)
    np.testing.assert_allclose(out.vertices, grown.vertices, atol=1e-12)
    np.testing.assert_allclose(out.bulges, grown.bulges, atol=1e-12)
    r1, r2, dist = 4.0 + d, 2.0 + d, 12.0
    a = math.asin((r1 - r2) / dist)
    expected = (r1 + r2) * dist * math.cos(a) + (math.pi + 2 * a) * r1**2 / 2 + (math.pi - 2 * a) * r2**2 / 2
    assert out.area() == pytest.approx(expected, rel=1e-12)
    cw = _reversed(pear)
    assert cw.area() == pytest.approx(-pear.area(), rel=1e-12)
    assert abs(offset_path(cw, d).area()) == pytest.approx(expected, rel=1e-12)


def test_hull_of_three_circles_is_triangle_plus_band_plus_disc():
    """Equal circles (r = 1.5) at the corners of a triangle and a fourth inside it: the hull's area is the
    triangle's area + its perimeter x r + pi r^2 (closed form), the inner circle adds nothing; the path is
    counter-clockwise with three arcs whose turns add up to one full turn."""
    tri = np.array([[0.0, 0.0], [10.0, 0.0], [3.0, 7.0]])
    r = 1.5
    hull = circle_hull(np.vstack([tri, [[4.0, 2.0]]]), r)
    (ux, uy), (vx, vy) = tri[1] - tri[0], tri[2] - tri[0]
    area = 0.5 * abs(ux * vy - uy * vx)
    perimeter = sum(np.hypot(*(tri[(i + 1) % 3] - tri[i])) for i in range(3))
    assert hull.area() == pytest.approx(area + perimeter * r + math.pi * r * r, rel=1e-12)
    arcs = hull.bulges[hull.bulges != 0]
    assert len(arcs) == 3
    assert np.sum(4 * np.arctan(arcs)) == pytest.approx(2 * math.pi, rel=1e-12)
    assert polygon_area(hull.vertices) > 0
    # every vertex is a tangent point: at distance r from its nearest corner
    d = np.min(np.hypot(*(hull.vertices[:, None, :] - tri[None, :, :]).transpose(2, 0, 1)), axis=1)
    np.testing.assert_allclose(d, r, atol=1e-12)


@pytest.mark.parametrize("factor", [1.0, 1.5, 3.0, -0.5])
def test_offset_of_one_circle_by_its_radius_or_more_grows_it(factor):
    """One circle (r = 1.7779..., found by hypothesis) offset by r, 1.5 r, 3 r and -r/2 is the circle of radius
    r (1 + factor): area pi r^2 (1 + factor)^2, centre kept (the orientation test once polygonised the path at
    the offset distance: at a tolerance >= r the circle became a chord of area -6e-14 and the offset went
    inwards, to area 0)."""
    r = 1.7779459526761254
    centre = np.array([17.796331749077204, 21.5])
    out = offset_path(circle_hull(centre[None, :], np.array([r])), factor * r)
    assert out.area() == pytest.approx(math.pi * (r * (1 + factor)) ** 2, rel=1e-12)
    np.testing.assert_allclose(out.vertices.mean(axis=0), centre, atol=1e-12)


@pytest.mark.parametrize("d", [0.04, -0.04])
def test_offset_of_a_small_hull_keeps_unit_normals(d):
    """The pear scaled to a twentieth (radii 0.2 and 0.1 mm, 0.6 mm apart; every segment shorter than 1 mm):
    still the exact hull of the grown circles."""
    centres, radii = np.array([[0.0, 0.0], [0.6, 0.0]]), np.array([0.2, 0.1])
    out = offset_path(circle_hull(centres, radii), d)
    grown = circle_hull(centres, radii + d)
    np.testing.assert_allclose(out.vertices, grown.vertices, atol=1e-12)
    assert out.area() == pytest.approx(grown.area(), rel=1e-12)


def test_offset_of_a_tombstone_mitres_its_sharp_corners():
    """A 6 mm wide block with a semicircular top (radius 3) and two square bottom corners: grown by 0.5 mm the
    top is the semicircle of radius 3.5 and the bottom corners stay square (moved diagonally by 0.5 mm each
    way), so the area is 7 x (4 + 0.5) + pi 3.5^2 / 2 (closed form)."""
    w, h, r, d = 6.0, 4.0, 3.0, 0.5
    tomb = BulgePath(np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]), np.array([0.0, 0.0, 1.0, 0.0]))
    assert tomb.area() == pytest.approx(w * h + math.pi * r * r / 2, rel=1e-12)
    out = offset_path(tomb, d)
    np.testing.assert_allclose(out.vertices, [[-d, -d], [w + d, -d], [w + d, h], [-d, h]], atol=1e-12)
    assert out.area() == pytest.approx((w + 2 * d) * (h + d) + math.pi * (r + d) ** 2 / 2, rel=1e-12)


def test_polygon_offset_rounds_convex_corners_with_the_documented_sagitta():
    """A square grown by 2 mm: every vertex of the round corners lies on the exact offset (2 mm from the
    square), and the largest gap between a chord and the exact offset is the sagitta of 32 segments per
    quarter turn, 2 (1 - cos(pi / 128)) = 6.0e-4 mm (closed form; within 3e-4 of the distance as documented)."""
    square = BulgePath.polyline(np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float))
    out = offset_path(square, 2.0).vertices
    body = shapely.Polygon(square.vertices)
    dist = shapely.distance(shapely.points(out), body)
    np.testing.assert_allclose(dist, 2.0, atol=1e-9)
    mids = 0.5 * (out + np.roll(out, -1, axis=0))
    gap = 2.0 - shapely.distance(shapely.points(mids), body)
    assert gap.max() == pytest.approx(2.0 * (1 - math.cos(math.pi / 128)), rel=1e-6)
    assert gap.max() <= 3.02e-4 * 2.0


def test_fuse_starts_at_the_smallest_vertex_and_drops_points_on_slanted_edges():
    """A rotated square (45 deg, a diamond) with points in the middle of its slanted edges, fused with a bar
    that leaves part of one edge: the result starts at the lexicographically smallest vertex (least x, then
    least y), is counter-clockwise, keeps every corner and no point in the middle of an edge."""
    c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
    corners = np.array([[5 * c, -5 * s], [10 * c, 0.0], [5 * c, 5 * s], [0.0, 0.0]]) + [1.0, 2.0]
    mids = 0.5 * (corners + np.roll(corners, -1, axis=0))
    ring = np.empty((8, 2))
    ring[0::2], ring[1::2] = corners, mids
    base = BulgePath.polyline(ring)
    bar = np.array([[4.0, 1.0], [9.0, 1.0], [9.0, 1.5], [4.0, 1.5]])  # pokes out of the lower right edge
    fused = fuse_polygons(base, [bar], 0.01)
    union = shapely.union_all([shapely.Polygon(corners), shapely.Polygon(bar)])
    assert shapely.Polygon(fused.vertices).equals(union)
    assert polygon_area(fused.vertices) > 0
    assert tuple(fused.vertices[0]) == min(map(tuple, fused.vertices))
    assert len(fused.vertices) == len(shapely.Polygon(union.exterior).simplify(0).exterior.coords) - 1
    # every vertex is a true corner: not on the segment between its neighbours
    prev, nxt = np.roll(fused.vertices, 1, axis=0), np.roll(fused.vertices, -1, axis=0)
    for p, a, b in zip(fused.vertices, prev, nxt, strict=True):
        assert shapely.LineString([a, b]).distance(shapely.Point(p)) > 1e-6


@pytest.mark.parametrize("phi", [0.0, 0.7, 2.0])
@pytest.mark.parametrize("r2", [2.0, 4.5])
def test_hull_of_an_internally_tangent_circle_is_the_outer_circle(phi, r2):
    """A circle inside a larger one and touching it (at any angle) adds nothing: the hull is the outer circle."""
    centres = np.array([[0.0, 0.0], [(5.0 - r2) * math.cos(phi), (5.0 - r2) * math.sin(phi)]])
    hull = circle_hull(centres, np.array([5.0, r2]))
    assert hull.area() == pytest.approx(math.pi * 25.0, rel=1e-12)
    np.testing.assert_allclose(np.hypot(*hull.vertices.T), 5.0, rtol=1e-12)


@settings(max_examples=80, deadline=None)
@given(st.floats(-3.0, 3.0).filter(lambda b: abs(b) > 1e-3), st.floats(-30.0, 30.0), st.floats(-30.0, 30.0))
def test_bulge_path_distance_is_the_distance_to_its_true_arc(bulge, px, py):
    """BulgePath.distance of a one-arc path (a D shape: the arc from (-5, 0) to (5, 0) with ``bulge`` and the
    chord back) equals the smallest distance to 200 001 points sampled on the true arc and the chord, within
    the spacing of those samples (< 1e-3 mm here). Arcs of either sense up to |bulge| = 3 (an included angle
    of 4 atan 3 = 300 deg), points on every side of them."""
    path = BulgePath(np.array([[-5.0, 0.0], [5.0, 0.0]]), np.array([bulge, 0.0]))
    theta = 4.0 * math.atan(bulge)
    radius = 10.0 / (2.0 * abs(math.sin(theta / 2.0)))
    centre = np.array([0.0, math.copysign(1.0, theta) * radius * math.cos(theta / 2.0)])
    a0 = math.atan2(-centre[1], -5.0 - centre[0])
    angles = a0 + np.linspace(0.0, theta, 200_001)
    arc = centre + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    chord = np.column_stack([np.linspace(5.0, -5.0, 20_001), np.zeros(20_001)])
    samples = np.concatenate([arc, chord])
    p = np.array([px, py])
    brute = float(np.min(np.hypot(*(samples - p).T)))
    spacing = max(radius * abs(theta) / 200_000, 10.0 / 20_000)
    got = path.distance(p)
    assert got <= brute + 1e-12
    assert got >= brute - spacing


def test_bulge_path_distance_closed_forms():
    """A unit square (distance to the nearest side or corner) and a full disc made of two semicircles of
    radius 2 about 0 (|  |p| - 2 |): inside, outside, at the centre (2) and on the curve (0). 1e-12."""
    square = BulgePath.polyline(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    assert square.distance(np.array([0.5, 0.2])) == pytest.approx(0.2, abs=1e-12)
    assert square.distance(np.array([2.0, 2.0])) == pytest.approx(math.sqrt(2.0), abs=1e-12)
    assert square.distance(np.array([0.5, -3.0])) == pytest.approx(3.0, abs=1e-12)
    disc = BulgePath(np.array([[2.0, 0.0], [-2.0, 0.0]]), np.array([1.0, 1.0]))
    for point, expected in (((0.0, 0.0), 2.0), ((0.3, -0.4), 1.5), ((3.0, 4.0), 3.0), ((0.0, -2.0), 0.0),
                            ((-1.2, 1.6), 0.0)):
        assert disc.distance(np.array(point)) == pytest.approx(expected, abs=1e-12)
