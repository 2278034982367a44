"""Printability: webs around holes, the thin-feature opening, the rotated footprint, the build volume / sheet
verdicts, pins, gear tip lands and the report, each against closed-form geometry.

Written to kill mutants of ``fabricate/checks/printability.py``. The plates are polygons given vertex by
vertex (exact at any chord tolerance), so every web, footprint and opening depth is a closed form in the
lengths chosen here; webs are measured on the exact circles and arcs (never on their polygons, which
would overstate a web by up to the chord tolerance ``tol``), so they are checked to rounding. The
verdict boundaries (wall slack ``tol``, build area / height slack 1e-9, sheet thickness 1e-6, pin and tip
land 1e-9) are probed at the boundary and half / one and a half slacks either side.
"""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from fabricate.checks.printability import (
    PartPrintability,
    PrintabilityResult,
    check_printability,
    footprint,
    hole_walls,
    thin_feature,
)
from fabricate.parts.model import BulgePath, Hole, Part

TOL = 0.005  # chord tolerance of the SLA / laser fixtures, mm


def box_part(name: str, size: tuple[float, float], *, centre: tuple[float, float] = (0.0, 0.0),
             angle_deg: float = 0.0, holes: tuple[Hole, ...] = (), thickness: float = 3.0, role: str = "link",
             process: str = "sla") -> Part:
    """A ``size`` rectangle centred on ``centre`` and turned by ``angle_deg`` about it, ``thickness`` thick."""
    w, h = size
    corners = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
    a = math.radians(angle_deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    outline = BulgePath.polyline(corners @ rot.T + np.asarray(centre, dtype=np.float64))
    return Part(name, "b", outline, holes, thickness, 0.0, 0, process, role=role)


def poly_part(name: str, vertices, holes: tuple[Hole, ...] = (), thickness: float = 3.0) -> Part:
    """A plate with a polygonal outline (counter-clockwise ``vertices``)."""
    return Part(name, "b", BulgePath.polyline(np.array(vertices, dtype=np.float64)), holes, thickness, 0.0, 0, "sla")


def hole(joint: str, x: float, y: float, diameter: float) -> Hole:
    """A hole whose pin (2 mm) differs from its diameter, so a web must use the hole's diameter."""
    return Hole(joint, np.array([x, y]), diameter, 2.0)


def spike_plate(angle_deg: float, height: float = 10.0) -> list[tuple[float, float]]:
    """Plate [-10, 10] x [-10, 0] with an isosceles spike of apex angle ``angle_deg`` and ``height`` on top,
    apex at (0, height)."""
    half = height * math.tan(math.radians(angle_deg) / 2)
    return [(-10, -10), (10, -10), (10, 0), (half, 0), (0, height), (-half, 0), (-10, 0)]


def roof_tab_plate(r: float, length: float) -> list[tuple[float, float]]:
    """Plate [-10, 10] x [-10, 0] with a tab of width w = 2 r sin(pi/8) on top, apex (0, length), shoulders
    0.05 lower. A disc of radius r under the edge pokes into the tab's foot at most r - sqrt(r^2 - w^2/4)
    = r (1 - cos(pi/8)), at x = 0, right under the apex."""
    h = r * math.sin(math.pi / 8)
    return [(-10, -10), (10, -10), (10, 0), (h, 0), (h, length - 0.05), (0, length), (-h, length - 0.05),
            (-h, 0), (-10, 0)]


def pair(name: str, **checks: float) -> SimpleNamespace:
    return SimpleNamespace(name=name, checks=dict(checks))


def pin(joint: str, diameter: float) -> SimpleNamespace:
    return SimpleNamespace(joint=joint, diameter_mm=diameter)


# -- hole_walls ---------------------------------------------------------------------------------------
def test_web_of_a_single_hole_is_the_distance_to_the_nearest_side():
    """20 x 10 plate centred on 0, hole d = 3 at (4, 0): web = min(10 - 4, 5) - 1.5 = 3.5; at (7, 1): web
    = min(10 - 7, 5 - 1) - 1.5 = 1.5. Polygon sides are exact: tolerance 1e-12."""
    walls = hole_walls(box_part("p", (20, 10), holes=(hole("A", 4.0, 0.0, 3.0),)), TOL)
    assert [j for j, _ in walls] == ["A"]
    assert walls[0][1] == pytest.approx(3.5, abs=1e-12)
    walls = hole_walls(box_part("p", (20, 10), holes=(hole("B", 7.0, 1.0, 3.0),)), TOL)
    assert walls == [("B", pytest.approx(1.5, abs=1e-12))]


def test_web_of_a_hole_in_a_turned_plate():
    """The same plate turned by 30 deg about (5, -2), hole d = 2 at the plate's point (-6, 3): web =
    min(10 - 6, 5 - 3) - 1 = 1 (distance to the nearest side is invariant under the motion); 1e-9."""
    a = math.radians(30)
    x, y = 5 + (-6) * math.cos(a) - 3 * math.sin(a), -2 + (-6) * math.sin(a) + 3 * math.cos(a)
    part = box_part("p", (20, 10), centre=(5, -2), angle_deg=30, holes=(hole("C", x, y, 2.0),))
    assert hole_walls(part, TOL) == [("C", pytest.approx(1.0, abs=1e-9))]


def test_web_between_two_holes_is_the_gap_and_each_hole_sees_the_nearest_ring():
    """40 x 10 plate, A d = 2 at (-1.5, 0), B d = 4 at (2.5, 0): centre distance 4, gap 4 - 1 - 2 = 1 for
    both (the sides are 5 - 1 = 4 and 5 - 2 = 3 away), measured on the circles: 1e-12."""
    part = box_part("p", (40, 10), holes=(hole("A", -1.5, 0.0, 2.0), hole("B", 2.5, 0.0, 4.0)))
    walls = hole_walls(part, TOL)
    assert [j for j, _ in walls] == ["A", "B"]
    for _, web in walls:
        assert web == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("tol", [0.005, 0.05, 0.5])
def test_web_between_holes_facing_a_polygon_edge_is_not_overstated(sla_process, tol):
    """Regression: the web was measured to the other hole's inscribed polygon, which lies inside the
    circle, so with A's centre facing the midpoint of one of B's polygon edges a true web of 0.7925 mm
    (under the SLA limit 0.8 - 0.005) read 0.797 and passed. On the circles it is exact (1e-12) at any
    chord tolerance, and the build fails."""
    from fabricate.parts.model import circle_polygon

    n = len(circle_polygon(np.zeros(2), 4.0, tol))
    d = 0.7925 + 1.0 + 2.0
    phi = -math.pi / n
    part = box_part("p", (40, 20), holes=(hole("A", d * math.cos(phi), d * math.sin(phi), 2.0),
                                          hole("B", 0.0, 0.0, 4.0)))
    assert hole_walls(part, tol) == [("A", pytest.approx(0.7925, abs=1e-12)), ("B", pytest.approx(0.7925, abs=1e-12))]
    result = check_printability([part], dataclasses.replace(sla_process, chord_tolerance_mm=0.005))
    assert not result.passed


def test_web_to_a_concave_arc_is_measured_to_the_arc():
    """A 40 x 20 plate whose top edge dips in a semicircular notch of radius 5 about (0, 10) (bulge -1 from
    (5, 10) to (-5, 10): clockwise, into the plate); a hole d = 2 at (0, 3.5): web = (10 - 3.5) - 5 - 1 =
    0.5 exactly. The arc's chords lie in the notch, so a polygon would read up to the sagitta more. 1e-12
    at a coarse tolerance 0.4 (a few chords). A hole d = 1 at (7, 8) is nearer the top edge (2) than the
    notch's circle (sqrt(53) - 5 = 2.28): web 1.5."""
    vertices = np.array([[-20.0, -10.0], [20.0, -10.0], [20.0, 10.0], [5.0, 10.0], [-5.0, 10.0], [-20.0, 10.0]])
    bulges = np.array([0.0, 0.0, 0.0, -1.0, 0.0, 0.0])
    part = Part("notch", "b", BulgePath(vertices, bulges), (hole("A", 0.0, 3.5, 2.0),), 3.0, 0.0, 0, "sla")
    assert hole_walls(part, 0.4) == [("A", pytest.approx(0.5, abs=1e-12))]
    part = Part("notch", "b", BulgePath(vertices, bulges), (hole("A", 7.0, 8.0, 1.0),), 3.0, 0.0, 0, "sla")
    assert hole_walls(part, 0.4) == [("A", pytest.approx(1.5, abs=1e-12))]


def test_overlapping_and_outside_holes_have_negative_webs():
    """A hole inside another (d 2 concentric with d 4) has web 0 - 1 - 2 = -3; a hole centred 1 mm outside
    the plate's edge has web -1 - 1 = -2 (was the positive distance to the nearest ring). 1e-12."""
    part = box_part("p", (40, 20), holes=(hole("A", 0.0, 0.0, 2.0), hole("B", 0.0, 0.0, 4.0)))
    assert hole_walls(part, TOL) == [("A", pytest.approx(-3.0, abs=1e-12)), ("B", pytest.approx(-3.0, abs=1e-12))]
    part = box_part("p", (40, 20), holes=(hole("C", 21.0, 0.0, 2.0),))
    assert hole_walls(part, TOL) == [("C", pytest.approx(-2.0, abs=1e-12))]


def test_webs_of_three_holes_in_order():
    """40 x 10 plate: A d = 4 at (-15, 0) -> 5 - 2 = 3 (left side and long sides 5 away); B d = 6 at (10, 0)
    -> 5 - 3 = 2; C d = 2 at (0, 0) -> 5 - 1 = 4 (holes are >= 7 apart). Exact sides: 1e-12."""
    part = box_part("p", (40, 10), holes=(hole("A", -15, 0, 4.0), hole("B", 10, 0, 6.0), hole("C", 0, 0, 2.0)))
    assert hole_walls(part, TOL) == [("A", pytest.approx(3.0, abs=1e-12)), ("B", pytest.approx(2.0, abs=1e-12)),
                                     ("C", pytest.approx(4.0, abs=1e-12))]


def test_plate_without_holes_has_no_walls():
    """No hole, no web: an empty list."""
    assert hole_walls(box_part("p", (20, 10)), TOL) == []


# -- thin_feature -------------------------------------------------------------------------------------
def test_thick_plate_with_holes_has_no_thin_feature():
    """A 20 x 10 plate with two holes (webs >= 1.5 mm) opened by a 0.3 mm disc: its 90 deg corners are cut
    back r (sqrt 2 - 1) < r, the holes' corners are reflex: exactly 0.0."""
    part = box_part("p", (20, 10), holes=(hole("A", 4, 0, 3.0), hole("B", -5, 1, 2.0)))
    assert thin_feature(part, 0.3, TOL) == 0.0
    assert thin_feature(part, 2.0, TOL) == 0.0


@pytest.mark.parametrize("r", [0.15, 0.5])
def test_sixty_degree_corner_is_not_flagged(r):
    """A 60 deg spike: the opening's disc sits r / sin 30 = 2r from the apex, so the apex is 2r - r = r
    from the opened plate, exactly the corner allowance; the polygonal fillet adds < r (1 - cos 6 deg)
    < tol (0.005): exactly 0.0."""
    assert thin_feature(poly_part("spike", spike_plate(60.0)), 2 * r, TOL) == 0.0


def test_fifty_degree_spike_reaches_its_closed_form():
    """A 50 deg spike, r = 1: apex to the opened plate r / sin 25 deg - r, excess r / sin 25 deg - 2r =
    0.3662. The dilation rounds the apex's 130 deg turn with round(130 / 11.25) = 12 equal chords
    (quad_segs = 8), an even number, so a vertex lies on the bisector: exact to 1e-9."""
    r = 1.0
    expected = r / math.sin(math.radians(25.0)) - 2 * r
    assert thin_feature(poly_part("spike", spike_plate(50.0)), 2 * r, TOL) == pytest.approx(expected, abs=1e-9)


def test_thirty_degree_spike_is_flagged():
    """A 30 deg spike, SLA r = 0.15: excess r / sin 15 deg - 2r = 0.2796 > 0. The dilation's fillet is a
    polygon inside the arc, chord steps <= 1.5 x 90 / 8 deg, so the result lies in
    [exact, exact + r (1 - cos(3 pi / 64))]."""
    r = 0.15
    expected = r / math.sin(math.radians(15.0)) - 2 * r
    got = thin_feature(poly_part("spike", spike_plate(30.0)), 2 * r, TOL)
    assert expected - 1e-12 <= got <= expected + r * (1 - math.cos(3 * math.pi / 64))


@pytest.mark.parametrize("length", [4.0, 2.5])
def test_thin_tab_sticks_out_by_its_length_beyond_the_opened_plate(length):
    """Tab w = 2 r sin(pi/8) < 2r (r = 0.5) with apex at height L: the tab opens away except a bump of
    height r - r cos(pi/8) under the apex, so the apex is L - r (1 - cos(pi/8)) from the opened plate and
    the excess is L - 2r + r cos(pi/8). The erosion's fillets (8 chords of 11.25 deg per 90 deg) cross on a
    vertex at 22.5 deg and the dilation puts a vertex straight above it: exact to 1e-9."""
    r = 0.5
    expected = length - 2 * r + r * math.cos(math.pi / 8)
    assert thin_feature(poly_part("tab", roof_tab_plate(r, length)), 2 * r, TOL) == pytest.approx(expected,
                                                                                                  abs=1e-9)


def test_tab_excess_is_reported_only_beyond_the_chord_tolerance():
    """The roof tab (r = 0.5) with L = 2r - r cos(pi/8) + e: excess e. e = 1.5 tol is reported as itself
    (1e-9), e = 0.5 tol is within the slack: exactly 0.0."""
    r = 0.5
    base = 2 * r - r * math.cos(math.pi / 8)
    assert thin_feature(poly_part("tab", roof_tab_plate(r, base + 1.5 * TOL)), 2 * r, TOL) == pytest.approx(
        1.5 * TOL, abs=1e-9)
    assert thin_feature(poly_part("tab", roof_tab_plate(r, base + 0.5 * TOL)), 2 * r, TOL) == 0.0


def test_plate_thinner_than_the_feature_size_reaches_from_its_vertex_mean():
    """A 10 x 0.2 strip (plus a vertex (1, 0.1) on its top side) opened by a 0.3 mm disc is empty: the
    result is the largest distance of a vertex from the vertex mean (0.2, 0.02) (five vertices), i.e. from
    (-5, -0.1): hypot(5.2, 0.12). 1e-12."""
    strip = [(-5, -0.1), (5, -0.1), (5, 0.1), (1, 0.1), (-5, 0.1)]
    assert thin_feature(poly_part("strip", strip), 0.3, TOL) == pytest.approx(math.hypot(5.2, 0.12), abs=1e-12)
    # the same strip 30 mm off the origin: a distance from the mean, not from the origin (1e-12)
    far = [(x + 30.0, y - 7.0) for x, y in strip]
    assert thin_feature(poly_part("strip", far), 0.3, TOL) == pytest.approx(math.hypot(5.2, 0.12), abs=1e-12)


def test_thin_ring_reaches_from_the_mean_of_all_its_vertices():
    """A 24-gon of radius 5 with a hole d = 9.7 at (0.05, 0): every web < 0.3, the opening is empty. The
    outline's vertices average to 0, the hole's n (its polygon) to (0.05, 0): mean m = (0.05 n / (24 + n),
    0); the farthest vertex is (-5, 0): 5 + m. Tolerance 1e-9."""
    a = np.arange(24) * (2 * math.pi / 24)
    ring = np.column_stack([5 * np.cos(a), 5 * np.sin(a)])
    part = poly_part("ring", ring, holes=(hole("A", 0.05, 0.0, 9.7),))
    n = len(part.polygons(TOL)[1])
    assert thin_feature(part, 0.3, TOL) == pytest.approx(5 + 0.05 * n / (24 + n), abs=1e-9)


# -- footprint ----------------------------------------------------------------------------------------
def test_footprint_of_a_turned_rectangle_is_its_sides():
    """A 30 x 8 rectangle turned by 30 deg (and one 8 x 30 turned by 75 deg) about (3, 2), with a hole:
    (long, short) = (30, 8); 1e-9."""
    for size, angle in (((30.0, 8.0), 30.0), ((8.0, 30.0), 75.0)):
        part = box_part("p", size, centre=(3, 2), angle_deg=angle, holes=(hole("A", 3, 2, 3.0),))
        long_side, short_side = footprint(part, TOL)
        assert long_side == pytest.approx(30.0, abs=1e-9) and short_side == pytest.approx(8.0, abs=1e-9)


def test_footprint_of_an_obtuse_triangle_lies_on_its_longest_side():
    """Triangle (0, 0), (10, 0), (12, 3), obtuse at (10, 0): the smallest rectangle lies on the longest side
    c = sqrt(153), height 2 area / c = 30 / sqrt(153) (on a shorter side it would overhang). 1e-9."""
    long_side, short_side = footprint(poly_part("tri", [(0, 0), (10, 0), (12, 3)]), TOL)
    assert long_side == pytest.approx(math.sqrt(153.0), abs=1e-9)
    assert short_side == pytest.approx(30.0 / math.sqrt(153.0), abs=1e-9)


def test_footprint_ignores_holes():
    """A 20 x 10 plate with a hole of d = 6: the footprint is the outline's (20, 10), not the hole's; 1e-9."""
    assert footprint(box_part("p", (20, 10), holes=(hole("A", 0, 0, 6.0),)), TOL) == (
        pytest.approx(20.0, abs=1e-9), pytest.approx(10.0, abs=1e-9))


# -- check_printability: walls ------------------------------------------------------------------------
def test_wall_at_min_wall_minus_tolerance_passes_and_below_fails(sla_process):
    """tol = 0.125, min_wall = 1: the limit is 0.875. A 20 x 10 plate with a centred hole d = 8.25 has a
    web 5 - 4.125 = 0.875 exactly (binary fractions): passes. d = 8.25 + 2e-6 (web 0.875 - 1e-6) fails with
    one message naming part, hole, web and min wall to 3 decimals."""
    process = dataclasses.replace(sla_process, chord_tolerance_mm=0.125, min_wall_mm=1.0)
    ok = check_printability([box_part("plate", (20, 10), holes=(hole("A", 0, 0, 8.25),))], process)
    assert ok.passed and ok.failures == ()
    assert ok.parts[0].min_wall_mm == 0.875 and ok.parts[0].min_wall_hole == "A" and ok.parts[0].fits
    bad = check_printability([box_part("plate", (20, 10), holes=(hole("A", 0, 0, 8.25 + 2e-6),))], process)
    assert not bad.passed
    assert bad.failures == ("printability: plate has a 0.875 mm wall at hole A; the process needs 1.000 mm",)
    assert bad.parts[0].min_wall_mm == pytest.approx(0.875 - 1e-6, abs=1e-12)
    assert bad.parts[0].fits  # a thin wall is a failure, not a misfit


def test_wall_tolerance_is_the_chord_tolerance(sla_process):
    """With tol = 0.005 and min_wall = 1 the limit is 0.995: web 0.9975 (d = 8.005) passes, web 0.9925
    (d = 8.015) fails; with tol = 0.125 web 0.9925 passes."""
    process = dataclasses.replace(sla_process, min_wall_mm=1.0)
    assert check_printability([box_part("p", (20, 10), holes=(hole("A", 0, 0, 8.005),))], process).passed
    assert not check_printability([box_part("p", (20, 10), holes=(hole("A", 0, 0, 8.015),))], process).passed
    loose = dataclasses.replace(process, chord_tolerance_mm=0.125)
    assert check_printability([box_part("p", (20, 10), holes=(hole("A", 0, 0, 8.015),))], loose).passed


def test_weakest_hole_is_named(sla_process):
    """Webs A 3, B 2, C 4 (see test_webs_of_three_holes_in_order), min_wall 2.5: the row and the one failure
    name B with its 2 mm web; min_wall 1.5: passes, the row still names B with 2.0. 1e-12."""
    part = box_part("plate", (40, 10), holes=(hole("A", -15, 0, 4.0), hole("B", 10, 0, 6.0), hole("C", 0, 0, 2.0)))
    result = check_printability([part], dataclasses.replace(sla_process, min_wall_mm=2.5))
    assert result.failures == ("printability: plate has a 2.000 mm wall at hole B; the process needs 2.500 mm",)
    row = result.parts[0]
    assert row.min_wall_hole == "B" and row.min_wall_mm == pytest.approx(2.0, abs=1e-12)
    result = check_printability([part], dataclasses.replace(sla_process, min_wall_mm=1.5))
    assert result.passed and result.parts[0].min_wall_hole == "B"


def test_web_between_holes_is_measured_at_the_process_chord_tolerance(sla_process):
    """40 x 20 plate, A d = 2 at 0, B d = 4 at 4 (cos 22.5 deg, sin 22.5 deg): gap 4 - 1 - 2 = 1 (the sides
    are >= 8 away), the same at any chord tolerance (the circles, not their polygons): 1e-12."""
    a = math.radians(22.5)
    part = box_part("p", (40, 20), holes=(hole("A", 0, 0, 2.0), hole("B", 4 * math.cos(a), 4 * math.sin(a), 4.0)))
    for tol in (0.005, 0.3):
        row = check_printability([part], dataclasses.replace(sla_process, chord_tolerance_mm=tol)).parts[0]
        assert row.min_wall_mm == pytest.approx(1.0, abs=1e-12)


def test_part_without_holes_has_no_wall(sla_process):
    """No hole: min_wall_mm None, min_wall_hole '' in the row and None / '' in its report."""
    result = check_printability([box_part("plate", (20, 10))], sla_process)
    row = result.parts[0]
    assert result.passed and row.min_wall_mm is None and row.min_wall_hole == ""
    report = row.report()
    assert report["min_wall_mm"] is None and report["min_wall_hole"] == ""


# -- check_printability: thin features ----------------------------------------------------------------
def test_thin_tab_fails_with_its_depth(sla_process):
    """min_feature 1 (r = 0.5), roof tab of apex height 4: depth 4 - 1 + 0.5 cos(pi/8) = 3.46194; one failure
    naming the part, min_feature and the depth to 3 decimals; the row carries the depth (1e-9)."""
    process = dataclasses.replace(sla_process, min_feature_mm=1.0)
    result = check_printability([poly_part("tab", roof_tab_plate(0.5, 4.0))], process)
    depth = 3.0 + 0.5 * math.cos(math.pi / 8)
    assert result.failures == ("printability: tab has a feature thinner than 1.000 mm (reaching 3.462 mm beyond "
                               "the opened outline)",)
    assert result.parts[0].thin_feature_mm == pytest.approx(depth, abs=1e-9) and result.parts[0].fits


def test_any_reported_thin_feature_fails(sla_process):
    """min_feature 1 (r = 0.5), roof tab with apex at 2r - r cos(pi/8) + 1.5 tol: depth 1.5 tol = 0.0075 > 0,
    so the part fails with one message (any non-zero depth is a failure; 0.0075 sits on a rounding edge at 3
    decimals, so only 'reaching 0.00' is checked); the row's depth is 1.5 tol within 1e-9."""
    process = dataclasses.replace(sla_process, min_feature_mm=1.0)
    apex = 1.0 - 0.5 * math.cos(math.pi / 8) + 1.5 * TOL
    result = check_printability([poly_part("tab", roof_tab_plate(0.5, apex))], process)
    assert len(result.failures) == 1
    assert result.failures[0].startswith("printability: tab has a feature thinner than 1.000 mm (reaching 0.00")
    assert result.parts[0].thin_feature_mm == pytest.approx(1.5 * TOL, abs=1e-9)


def test_plate_without_thin_features_reports_zero(sla_process):
    """A 20 x 10 plate: thin_feature_mm is exactly 0.0 and nothing fails."""
    result = check_printability([box_part("plate", (20, 10), holes=(hole("A", 4, 0, 3.0),))], sla_process)
    assert result.passed and result.parts[0].thin_feature_mm == 0.0


# -- check_printability: build area and height (SLA) ---------------------------------------------------
def test_part_as_large_as_the_build_area_fits(sla_process):
    """Build area 130 x 80: a 130 x 80 part fits exactly, and so does 130 + 0.5e-9 x 80 + 0.5e-9 (slack
    1e-9); the row's footprint is (130, 80) (1e-9) and its thickness 3."""
    for extra in (0.0, 0.5e-9):
        result = check_printability([box_part("big", (130 + extra, 80 + extra))], sla_process)
        assert result.passed, result.failures
        row = result.parts[0]
        assert row.fits and row.thickness_mm == 3.0
        assert row.footprint_mm == (pytest.approx(130.0, abs=1e-9), pytest.approx(80.0, abs=1e-9))


@pytest.mark.parametrize("size", [(130 + 1.5e-9, 80.0), (130.0, 80 + 1.5e-9), (130 + 1e-6, 80.0),
                                  (130.0, 80 + 1e-6)])
def test_part_beyond_the_build_area_fails(sla_process, size):
    """Build area 130 x 80, slack 1e-9: a part 1.5e-9 or 1e-6 longer or wider fails, with one message
    giving its footprint to 0.1 mm and the build volume, and fits False."""
    result = check_printability([box_part("big", size)], sla_process)
    assert result.failures == ("printability: big (130.0 × 80.0 × 3 mm) does not fit the build volume "
                               "130 × 80 × 160 mm",)
    assert not result.passed and not result.parts[0].fits


@pytest.mark.parametrize("size", [(140.0, 50.0), (100.0, 90.0)])
def test_either_side_alone_can_miss_the_build_area(sla_process, size):
    """130 x 80 area: 140 x 50 misses on the long side only, 100 x 90 on the short side only; each fails."""
    result = check_printability([box_part("p", size)], sla_process)
    assert len(result.failures) == 1 and "does not fit the build volume" in result.failures[0]
    assert not result.parts[0].fits


def test_build_area_is_read_either_way_round(sla_process):
    """Build area given as (80, 130): a 130 x 80 part fits when turned 90 deg; a 129 x 81 part does not."""
    process = dataclasses.replace(sla_process, build_volume_mm=(80.0, 130.0, 160.0))
    assert check_printability([box_part("p", (130, 80))], process).passed
    result = check_printability([box_part("p", (129, 81))], process)
    assert result.failures == ("printability: p (129.0 × 81.0 × 3 mm) does not fit the build volume "
                               "80 × 130 × 160 mm",)


def test_turned_part_fits_by_its_rotated_rectangle(sla_process):
    """A 125 x 30 part turned by 45 deg has an axis-aligned box (155 / sqrt 2 = 109.6 mm square) that misses
    the 130 x 80 area, but its smallest rectangle (125, 30) fits."""
    result = check_printability([box_part("p", (125, 30), angle_deg=45, centre=(7, -3))], sla_process)
    assert result.passed and result.parts[0].fits
    assert result.parts[0].footprint_mm == (pytest.approx(125.0, abs=1e-9), pytest.approx(30.0, abs=1e-9))


def test_build_height_is_the_third_dimension(sla_process):
    """Build volume (130, 80, 160): a 160 mm thick part fits (and 160 + 0.5e-9, slack 1e-9), 160 + 1.5e-9
    and 161 do not; a part 100 mm thick (taller than the 80 mm y side) fits."""
    for thickness in (160.0, 160 + 0.5e-9, 100.0):
        result = check_printability([box_part("p", (20, 10), thickness=thickness)], sla_process)
        assert result.passed and result.parts[0].fits, thickness
    result = check_printability([box_part("p", (20, 10), thickness=160 + 1.5e-9)], sla_process)
    assert not result.passed and not result.parts[0].fits
    result = check_printability([box_part("p", (20, 10), thickness=161.0)], sla_process)
    assert result.failures == ("printability: p (20.0 × 10.0 × 161 mm) does not fit the build volume "
                               "130 × 80 × 160 mm",)
    assert not result.parts[0].fits and result.parts[0].thickness_mm == 161.0


def test_sla_spacer_is_judged_like_any_part(sla_process):
    """The spacer exemption is the laser sheet's: an SLA spacer taller than the build volume fails."""
    result = check_printability([box_part("s", (10, 10), thickness=200.0, role="spacer")], sla_process)
    assert result.failures == ("printability: s (10.0 × 10.0 × 200 mm) does not fit the build volume "
                               "130 × 80 × 160 mm",)
    assert not result.parts[0].fits


# -- check_printability: laser sheet ------------------------------------------------------------------
@pytest.mark.parametrize("thickness", [3.0, 3 + 0.5e-6, 3 - 0.5e-6])
def test_laser_part_as_thick_as_the_sheet_passes(laser_process, thickness):
    """Sheet 3 mm, slack 1e-6: 3, 3 +- 0.5e-6 pass, fits True."""
    result = check_printability([box_part("p", (50, 20), thickness=thickness, process="laser")], laser_process)
    assert result.passed and result.parts[0].fits and result.process == "laser"


@pytest.mark.parametrize("thickness", [3 + 1.5e-6, 3 - 1.5e-6, 2.0])
def test_laser_part_off_the_sheet_thickness_fails_once(laser_process, thickness):
    """Sheet 3 mm, slack 1e-6: 3 +- 1.5e-6 and 2 fail with exactly one failure, the thickness message (the
    part fits the 600 x 400 sheet); fits False."""
    result = check_printability([box_part("p", (50, 20), thickness=thickness, process="laser")], laser_process)
    assert result.failures == (f"printability: p is {thickness:g} mm thick, the sheet 3 mm",)
    assert not result.parts[0].fits


def test_laser_thickness_gives_the_sheet_message_not_the_build_volumes(laser_process):
    """A 4 mm laser part on a 3 mm sheet that fits its area: the thickness message only (not 'does not fit')."""
    result = check_printability([box_part("link", (50, 20), thickness=4.0, process="laser")], laser_process)
    assert result.failures == ("printability: link is 4 mm thick, the sheet 3 mm",)


def test_laser_spacer_need_not_be_sheet_thick(laser_process):
    """A 10 mm spacer (a tube, not cut from the sheet) passes and fits; one longer than the 600 x 400 sheet's
    721 mm diagonal fails with the sheet's 'does not fit' message only."""
    result = check_printability([box_part("sp", (10, 10), thickness=10.0, role="spacer", process="laser")],
                                laser_process)
    assert result.passed and result.parts[0].fits
    result = check_printability([box_part("sp", (801, 10), thickness=10.0, role="spacer", process="laser")],
                                laser_process)
    assert result.failures == ("printability: sp (801.0 × 10.0 × 10 mm) does not fit the sheet 600 × 400 × 3 mm",)
    assert not result.parts[0].fits


def test_laser_part_too_large_and_too_thick_gives_both_messages(laser_process):
    """800 x 20 x 4 on a 600 x 400 x 3 sheet: the thickness message, then the sheet's."""
    result = check_printability([box_part("p", (800, 20), thickness=4.0, process="laser")], laser_process)
    assert result.failures == ("printability: p is 4 mm thick, the sheet 3 mm",
                               "printability: p (800.0 × 20.0 × 4 mm) does not fit the sheet 600 × 400 × 3 mm")
    assert not result.parts[0].fits


def test_the_sheet_rules_follow_the_layout_not_the_name(laser_process, sla_process):
    """A sheet layout under another name keeps the sheet's rules (4 mm on a 3 mm sheet fails on thickness);
    the laser's name on a plate layout is judged by the build height (4 mm under 3 mm fails as 'build volume')."""
    router = dataclasses.replace(laser_process, name="router")
    result = check_printability([box_part("link", (50, 20), thickness=4.0)], router)
    assert result.failures == ("printability: link is 4 mm thick, the sheet 3 mm",) and result.process == "router"
    plate = dataclasses.replace(laser_process, layout="plate")
    result = check_printability([box_part("link", (50, 20), thickness=4.0, process="laser")], plate)
    assert result.failures == ("printability: link (50.0 × 20.0 × 4 mm) does not fit the build volume "
                               "600 × 400 × 3 mm",)
    named_sla = dataclasses.replace(sla_process, name="laser")  # additive on plates, whatever it is called
    assert check_printability([box_part("link", (50, 20), thickness=100.0)], named_sla).passed


def test_laser_sheet_area_boundary(laser_process):
    """Sheet 600 x 400: 600 x 400 fits, 600 + 1e-6 does not."""
    assert check_printability([box_part("p", (600, 400), process="laser")], laser_process).passed
    result = check_printability([box_part("p", (600 + 1e-6, 400), process="laser")], laser_process)
    assert result.failures == ("printability: p (600.0 × 400.0 × 3 mm) does not fit the sheet 600 × 400 × 3 mm",)


# -- check_printability: pins and gear tip lands ------------------------------------------------------
def test_pin_at_the_minimum_passes_and_below_fails(sla_process):
    """min_pin 1.5, slack 1e-9: 1.5 and 1.5 - 0.5e-9 pass; 1.5 - 1.5e-9 and 1.5 - 1e-6 fail; a 1.2 mm pin
    fails with a message naming its joint."""
    box = box_part("p", (20, 10))
    assert check_printability([box], sla_process, pins=[pin("O", 1.5), pin("A", 1.5 - 0.5e-9)]).passed
    for d in (1.5 - 1.5e-9, 1.5 - 1e-6):
        assert check_printability([box], sla_process, pins=[pin("B", d)]).failures == (
            "printability: pin B is 1.5 mm, the process needs 1.5 mm",)
    result = check_printability([box], sla_process, pins=[pin("O", 2.0), pin("D", 1.2)])
    assert result.failures == ("printability: pin D is 1.2 mm, the process needs 1.5 mm",)


def test_gear_tip_land_at_the_feature_size_passes_and_below_fails(sla_process):
    """min_feature 0.3, slack 1e-9: lands 0.3 and 0.3 - 0.5e-9 pass, 0.3 - 1.5e-9 and 0.25 fail naming the
    pair; a pair without the key reports inf and passes. tip_lands_mm maps every pair to its land."""
    box = box_part("p", (20, 10))
    pairs = [pair("g1", tip_land_min_mm=0.3), pair("g2", tip_land_min_mm=0.3 - 0.5e-9), pair("g3")]
    result = check_printability([box], sla_process, gear_pairs=pairs)
    assert result.passed
    assert result.tip_lands_mm == {"g1": 0.3, "g2": 0.3 - 0.5e-9, "g3": math.inf}
    result = check_printability([box], sla_process, gear_pairs=[pair("g4", tip_land_min_mm=0.3 - 1.5e-9)])
    assert len(result.failures) == 1 and result.failures[0].startswith("printability: gear g4 has a 0.300 mm")
    result = check_printability([box], sla_process, gear_pairs=[pair("g5", tip_land_min_mm=0.25)])
    assert result.failures == ("printability: gear g5 has a 0.250 mm tooth tip land; the process resolves "
                               "0.300 mm (use a larger module or a smaller addendum)",)
    assert result.tip_lands_mm == {"g5": 0.25}


# -- the whole verdict and the reports ----------------------------------------------------------------
def test_failures_come_part_by_part_then_gears_then_pins(sla_process):
    """Two bad parts, a bad gear pair and a bad pin: the failures in that order (walls, thin feature, fit per
    part), the rows in part order with their fits. The tab plate is 20 wide and 10 + 4 (apex) high."""
    process = dataclasses.replace(sla_process, min_wall_mm=2.5, min_feature_mm=1.0)
    web = box_part("web", (40, 10), holes=(hole("A", -15, 0, 4.0), hole("B", 10, 0, 6.0)))
    tab = poly_part("tab", roof_tab_plate(0.5, 4.0), thickness=170.0)
    result = check_printability([web, tab], process, gear_pairs=[pair("g", tip_land_min_mm=0.5)],
                                pins=[pin("P", 1.0)])
    assert result.failures == (
        "printability: web has a 2.000 mm wall at hole B; the process needs 2.500 mm",
        "printability: tab has a feature thinner than 1.000 mm (reaching 3.462 mm beyond the opened outline)",
        "printability: tab (20.0 × 14.0 × 170 mm) does not fit the build volume 130 × 80 × 160 mm",
        "printability: gear g has a 0.500 mm tooth tip land; the process resolves 1.000 mm (use a larger "
        "module or a smaller addendum)",
        "printability: pin P is 1 mm, the process needs 1.5 mm",
    )
    assert [(p.name, p.fits) for p in result.parts] == [("web", True), ("tab", False)]
    assert result.process == "sla" and not result.passed


def test_part_report_rounds_walls_and_features_to_6_digits_and_the_footprint_to_4():
    """round(x, 6) of the wall and the thin feature, round(x, 4) of the footprint sides; the rest as is."""
    row = PartPrintability("p", 1.23456789, "A", 0.98765432, (12.3456789, 1.23456789), 2.5, False)
    assert row.report() == {"name": "p", "min_wall_mm": 1.234568, "min_wall_hole": "A",
                            "thin_feature_mm": 0.987654, "footprint_mm": [12.3457, 1.2346],
                            "thickness_mm": 2.5, "fits": False}
    bare = PartPrintability("q", None, "", 0.0, (20.0, 10.0), 3.0, True)
    assert bare.report() == {"name": "q", "min_wall_mm": None, "min_wall_hole": "", "thin_feature_mm": 0.0,
                             "footprint_mm": [20.0, 10.0], "thickness_mm": 3.0, "fits": True}


def test_result_report_and_passed():
    """The result's report lists the parts' reports, the tip lands rounded to 6 digits and 'passed'
    (no failures)."""
    row = PartPrintability("p", 1.23456789, "A", 0.0, (20.0, 10.0), 3.0, True)
    ok = PrintabilityResult("sla", (row,), {"g": 0.12345678, "h": math.inf}, ())
    assert ok.passed
    assert ok.report() == {"process": "sla", "parts": [row.report()], "tip_land_mm": {"g": 0.123457, "h": math.inf},
                           "passed": True}
    bad = PrintabilityResult("laser", (), {}, ("printability: something",))
    assert not bad.passed
    assert bad.report() == {"process": "laser", "parts": [], "tip_land_mm": {}, "passed": False}


def test_report_of_a_checked_part(sla_process):
    """check_printability then report(): the hole's web 3.5 (20 x 10 plate, d = 3 at (4, 0)), no thin feature,
    footprint [20, 10], thickness 3, fits; passed."""
    result = check_printability([box_part("plate", (20, 10), holes=(hole("A", 4, 0, 3.0),))], sla_process)
    assert result.report() == {"process": "sla", "tip_land_mm": {}, "passed": True, "parts": [
        {"name": "plate", "min_wall_mm": 3.5, "min_wall_hole": "A", "thin_feature_mm": 0.0,
         "footprint_mm": [20.0, 10.0], "thickness_mm": 3.0, "fits": True}]}


# -- check_printability: the layout's margin, turns that fit, the printer --------------------------------------
def test_the_margin_is_part_of_the_build_area(sla_process):
    """Issue 26: the gripper's 129.88 x 45.07 mm palm was placed at x 4.0-133.9 on a 130 x 80 plate and passed.
    With the plates' 4 mm margin the usable area is 122 x 72: that palm (at every turn) fails, naming the part,
    its size, the area and the margin; without a margin it fits."""
    palm = box_part("palm", (129.88, 45.07))
    assert check_printability([palm], sla_process).passed
    result = check_printability([palm], sla_process, margin_mm=4.0)
    assert result.failures == ("printability: palm (129.9 × 45.1 × 3 mm) does not fit the build volume "
                               "130 × 80 × 160 mm inside its 4 mm margin (122 × 72 mm usable, at any rotation on "
                               "the plate)",)
    assert not result.parts[0].fits


def test_the_printer_is_named(sla_process):
    process = dataclasses.replace(sla_process, printer="prusa_sl1s", build_volume_mm=(127.0, 80.0, 150.0))
    result = check_printability([box_part("palm", (129.88, 45.07))], process, margin_mm=4.0)
    assert result.failures[0].startswith("printability: palm (129.9 × 45.1 × 3 mm) does not fit the prusa_sl1s "
                                         "build volume 127 × 80 × 150 mm inside its 4 mm margin")


@pytest.mark.parametrize(("size", "fits_area"), [((121.9, 71.9), True), ((122.1, 20.0), True),
                                                  ((100.0, 72.1), False), ((130.0, 10.0), True),
                                                  ((150.0, 10.0), False)])
def test_a_part_fits_if_some_turn_on_the_plate_fits(sla_process, size, fits_area):
    """Usable 122 x 72 (130 x 80, margin 4): 121.9 x 71.9 fits as it is; 122.1 x 20 and 130 x 10 only across
    the diagonal (141.6 mm); 100 x 72.1 is too wide both ways round and across (its short side exceeds 72 at
    every turn); 150 x 10 is longer than the diagonal."""
    result = check_printability([box_part("p", size, angle_deg=17.0)], sla_process, margin_mm=4.0)
    assert result.passed is fits_area and result.parts[0].fits is fits_area


def _plan_size(part, process) -> str:
    """A part's plan size as the check names it (long × short side of its smallest rotated rectangle, one
    decimal, mm), by rotating calipers: the smallest rectangle has a side on an edge of the convex hull."""
    from scipy.spatial import ConvexHull

    outline = part.polygons(process.chord_tolerance_mm)[0]
    hull = outline[ConvexHull(outline).vertices]
    edges = np.roll(hull, -1, axis=0) - hull
    best = None
    for angle in np.arctan2(edges[:, 1], edges[:, 0]):
        c, s = np.cos(-angle), np.sin(-angle)
        turned = hull @ np.array([[c, s], [-s, c]])
        sides = np.ptp(turned, axis=0)
        if best is None or sides[0] * sides[1] < best[0] * best[1]:
            best = sides
    return f"{max(best):.1f} × {min(best):.1f}"


@pytest.mark.slow
def test_the_gripper_palm_on_the_sl1s_fails_naming_it(shipped_build, shared_stage_cache):
    """Issue 26's reproduction: the gripper built for the SL1S (--printer prusa_sl1s) exits 1, the palm named
    with its size and the printer's area and margin, and no plate holds a part outside its bed. Built on the
    session's shared stage cache, which ``shipped_build`` fills with the gripper: its synthesis (no process field in
    its key) is served, every stage that reads the printer runs."""
    from fabricate.design import load_design
    from fabricate.pipeline import run_build

    shipped_build("gripper_compliant")
    with shared_stage_cache():
        outcome = run_build(load_design("gripper_compliant", None, "prusa_sl1s"))
    assert outcome.exit_code == 1
    size = _plan_size(next(p for p in outcome.partset.parts if p.name == "palm"), outcome.design.process)
    assert size.startswith("129.9 × ")  # the paper's 129.88 mm palm; its width follows the pin bosses
    assert (f"printability: palm ({size} × 12 mm) does not fit the prusa_sl1s build volume 127 × 80 × 150 mm "
            "inside its 4 mm margin (119 × 72 mm usable, at any rotation on the plate)") in outcome.failures
    palm = next(p for p in outcome.report["parts"] if p["name"] == "palm")
    assert palm["plate"]["fits"] is False
    assert all(p["plate"]["fits"] for p in outcome.report["parts"] if p["name"] != "palm")


@pytest.mark.slow
def test_the_gripper_palm_on_every_sla_preset_fits_or_is_named(shipped_build):
    """On each SLA preset the palm either fits at some turn inside the plate margin (and the check passes it)
    or the check names it with the preset's area."""
    from fabricate.catalogue.printers import printers_for
    from fabricate.design import load_design
    from fabricate.export.layout import fitting_angle

    outcome = shipped_build("gripper_compliant")
    palm = next(p for p in outcome.partset.parts if p.name == "palm")
    margin = outcome.design.parts.plate_spacing_mm
    verdicts = {}
    for name in printers_for("sla"):
        process = load_design("gripper_compliant", None, name).process
        result = check_printability([palm], process, margin_mm=margin)
        usable = (process.build_volume_mm[0] - 2 * margin, process.build_volume_mm[1] - 2 * margin)
        fits_area = fitting_angle(palm.polygons(process.chord_tolerance_mm)[0], *usable) is not None
        assert result.passed is fits_area
        if not fits_area:
            assert result.failures[0].startswith(f"printability: palm ({_plan_size(palm, process)} × 12 mm) does "
                                                 f"not fit the {name} build volume")
        verdicts[name] = fits_area
    assert verdicts["prusa_sl1s"] is False and verdicts["elegoo_saturn_3"] is True


def test_a_laser_part_as_thick_as_a_listed_stock_passes_and_no_other_thickness(laser_process):
    """On a 6 mm sheet with 3 and 6 mm stock listed (``stock_thickness_mm``) a 3 mm part passes and fits (the
    layout nests it on a 3 mm sheet); a 4 mm part still fails, the message naming the stock; without the list
    the 3 mm part fails as before."""
    six = dataclasses.replace(laser_process, thickness_mm=6.0, build_volume_mm=(600.0, 400.0, 6.0),
                              stock_thickness_mm=(3.0, 6.0))
    parts = [box_part(name, (50, 20), thickness=t, process="laser") for name, t in (("a", 6.0), ("b", 3.0))]
    result = check_printability(parts, six)
    assert result.passed and all(row.fits for row in result.parts)
    result = check_printability([box_part("c", (50, 20), thickness=4.0, process="laser")], six)
    assert result.failures == ("printability: c is 4 mm thick, the sheet 6 mm (stock: 3 mm)",)
    assert not result.parts[0].fits
    result = check_printability(parts, dataclasses.replace(six, stock_thickness_mm=()))
    assert result.failures == ("printability: b is 3 mm thick, the sheet 6 mm",)
