"""Cut gears (``fabricate/gears/teeth.py``) against closed forms written here.

Written to kill mutants of ``cut_gear`` and its helpers (see ``tests/benchmarks/mutation_report.md``). The
expected values come from the involute of a spur gear (tooth thickness, tip land, root radius), from the
rack-and-pitch-curve construction evaluated with the pitch frames (the root between two teeth is the pitch
curve offset inwards by the dedendum, the tooth tip is the pitch curve offset outwards by the addendum;
for the osculating-circle method the same offsets of the tooth's osculating circle), and from shapely.
Gears are cut straight by ``cut_gear`` (0.02-0.2 s each) and cached.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from fabricate.gears.law import FormulaLaw, elliptic_law
from fabricate.gears.pitch import PitchCurves
from fabricate.gears.rack import basic_rack
from fabricate.gears.teeth import (
    _clean_ring,
    _douglas_peucker,
    _largest_polygon,
    circle_points,
    cut_gear,
    simplify_ring,
)

ALPHA = np.radians(20.0)
DEDENDUM, FILLET, ADDENDUM = 1.25, 0.38, 1.0  # x module, the GearSpec defaults
TOL = 0.005  # chord tolerance, mm


def inv(t):
    return np.tan(t) - t


def delta_of(backlash: float) -> float:
    """Normal flank offset of each gear: a quarter of the backlash along the pressure line."""
    return backlash * np.cos(ALPHA) / 4


@cache
def spur_pitch(z: int, module: float) -> PitchCurves:
    """Law x_b = -x_a on centre distance z m: two pitch circles of radius z m / 2, closed."""
    return PitchCurves(FormulaLaw("x"), z * module, (0.0, 2 * np.pi), 0.0, (2 * np.pi, 2 * np.pi))


@cache
def spur(z: int = 24, module: float = 1.0, backlash: float = 0.1, decimate: bool = True, addendum: float = ADDENDUM,
         method: str = "exact", tol: float = TOL):
    """Gear a of the spur pair: tooth k centred at arc length k p (polar angle -k p / r)."""
    p = np.pi * module
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, addendum)
    return cut_gear(spur_pitch(z, module), "a", rack, np.arange(z) * p, method=method, delta=delta_of(backlash),
                    addendum_mm=addendum * module, closed=True, rack_origin=0.0, hub_radius_mm=2.0,
                    chord_tolerance_mm=tol, decimate=decimate)


SECTOR_LAW = "0.8*x + 0.05*sin(2*x)"  # pitch radius of gear a 10.7 mm +- 5 %, not symmetric
SECTOR_K = (-1, 0, 1, 2, 3)  # tooth indices of the sector (gear a: centres k p; gear b: (k + 1/2) p)


@cache
def sector_pitch() -> PitchCurves:
    return PitchCurves(FormulaLaw(SECTOR_LAW), 24.0, (-2.0, 3.0), 0.0)


@cache
def sector(gear: str = "a", module: float = 1.0, hub: float = 2.0, k: tuple = SECTOR_K, rack_points: int = 241):
    p = np.pi * module
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, ADDENDUM, flank_points=rack_points)
    centres = np.array(k, dtype=np.float64) * p + (0.0 if gear == "a" else 0.5 * p)
    return cut_gear(sector_pitch(), gear, rack, centres, method="exact", delta=delta_of(0.05),
                    addendum_mm=ADDENDUM * module, closed=False, rack_origin=0.0, hub_radius_mm=hub,
                    chord_tolerance_mm=TOL)


@cache
def elliptic(method: str, z: int = 24, e: float = 0.5):
    """Gear a of a closed 1:1 elliptic pair, z teeth (module = perimeter / (pi z) = 1.17 mm)."""
    pitch = PitchCurves(elliptic_law(e), 30.0, (0.0, 2 * np.pi), 0.0, (2 * np.pi, 2 * np.pi))
    module = pitch.perimeter_a / (np.pi * z)
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, ADDENDUM)
    centres = np.arange(z) * np.pi * module
    cut = cut_gear(pitch, "a", rack, centres, method=method, delta=delta_of(0.05), addendum_mm=module,
                   closed=True, rack_origin=0.0, hub_radius_mm=2.0, chord_tolerance_mm=TOL)
    return pitch, module, cut


def offset_points(pitch: PitchCurves, s: np.ndarray, gear: str, height: float) -> np.ndarray:
    """Pitch curve at arc length ``s`` moved ``height`` along its outward normal (the tip: +h_a, the root
    between teeth: -(h_f + delta))."""
    f = pitch.frames(np.asarray(s, dtype=np.float64), gear)
    return f.point + height * f.normal


def distance_to_ring(points: np.ndarray, ring: np.ndarray) -> np.ndarray:
    return shapely.distance(shapely.points(points), shapely.LinearRing(ring))


def material_arcs(outline: np.ndarray, radius: float, start: float) -> list[LineString]:
    """Pieces of the circle of ``radius`` about the axis inside the outline (a 200000-gon: sagitta < 1e-8 mm),
    the circle starting at polar angle ``start`` (in a space, so that no tooth is split in two)."""
    t = start + np.linspace(0.0, 2 * np.pi, 200001)
    circle = LineString(radius * np.column_stack([np.cos(t), np.sin(t)]))
    inside = shapely.line_merge(Polygon(outline).intersection(circle))
    return list(getattr(inside, "geoms", [inside]))


# -- helpers -------------------------------------------------------------------------------------
def test_circle_points_default_start_even_spacing_and_huge_tolerance():
    """The hub polygon: starts at angle 0 by default, n distinct vertices 2 pi / n apart (no closing
    duplicate, which would leave one chord 2 pi / (n - 1) long), and a tolerance beyond the diameter
    still gives the 16-gon of the radius."""
    pts = circle_points(2.0, 0.01)
    np.testing.assert_allclose(pts[0], [2.0, 0.0], atol=1e-15)
    n = len(pts)
    step = np.diff(np.unwrap(np.arctan2(pts[:, 1], pts[:, 0])))
    np.testing.assert_allclose(step, 2 * np.pi / n, rtol=1e-12)
    closing = np.hypot(*(pts[0] - pts[-1]))
    assert closing == pytest.approx(2 * 2.0 * np.sin(np.pi / n), rel=1e-12)
    big = circle_points(1.0, 5.0)
    assert len(big) == 16
    np.testing.assert_allclose(np.hypot(*big.T), 1.0, rtol=1e-12)


def test_clean_ring_keeps_the_last_vertex_after_a_leading_duplicate_and_drops_a_doubled_closing_vertex():
    """``_clean_ring`` drops only the closing vertex and consecutive repeats: a repeated first vertex
    is not a closing vertex, and a closing vertex written twice goes entirely (off the origin, so a
    sum instead of a difference of the end points would show)."""
    a, b, c = [1.0, 2.0], [3.0, 2.0], [3.0, 5.0]
    np.testing.assert_array_equal(_clean_ring(np.array([a, a, b, c])), [a, b, c])
    np.testing.assert_array_equal(_clean_ring(np.array([a, b, c, a, a])), [a, b, c])


def test_douglas_peucker_of_a_loop_keeps_the_far_side():
    """A polyline that returns to its start (first segment of zero length): the distance is then taken to
    the start point, so the vertex opposite the start is kept first and every vertex stays within the
    tolerance of the kept polyline."""
    t = np.linspace(0.0, 2 * np.pi, 101)  # 100 chords of the unit circle, the last point the first
    loop = np.column_stack([np.cos(t), np.sin(t)])
    loop[-1] = loop[0]
    idx = _douglas_peucker(loop, 0.01)
    assert idx[0] == 0 and idx[-1] == 100 and 50 in idx
    assert 4 < len(idx) < 101
    assert shapely.distance(shapely.points(loop), LineString(loop[idx])).max() <= 0.01 + 1e-12


def test_largest_polygon_of_a_line_is_a_value_error():
    """A geometry with no polygon and no parts is refused with the documented ValueError."""
    with pytest.raises(ValueError, match="no polygon"):
        _largest_polygon(LineString([(0, 0), (1, 1)]))


# -- a closed spur gear against the involute -------------------------------------------------------
def test_spur_gear_has_z_teeth_of_the_involute_thickness():
    """z = 24, m = 1, backlash 0.1: the pitch circle (r = 12) crosses exactly z teeth, each p/2 - j/2 thick
    (each gear's flanks are thinned by j cos(alpha) / 4 along the normal, j/4 along the pitch circle),
    centred at the tooth centres' polar angles -k p / r; tolerance 1 um (dense) and the chord tolerance
    (decimated)."""
    z, module, j = 24, 1.0, 0.1
    r, p = z * module / 2, np.pi * module
    cut = spur()
    for outline, tol in ((cut.dense, 1e-3), (cut.outline, TOL)):
        arcs = material_arcs(outline, r, start=p / 2 / r)  # the space centre after tooth 0
        assert len(arcs) == z
        np.testing.assert_allclose([a.length for a in arcs], p / 2 - j / 2, atol=tol)
        mid = np.array([a.interpolate(0.5, normalized=True).coords[0] for a in arcs])
        half = p / 2 / r  # angles counted from half a pitch before tooth 0, so none wraps
        got = np.sort(np.mod(np.arctan2(mid[:, 1], mid[:, 0]) + half, 2 * np.pi))
        want = np.sort(np.mod(-np.arange(z) * p / r + half, 2 * np.pi))
        np.testing.assert_allclose(got, want, atol=tol / r)


def test_spur_gear_tip_root_and_tip_land_are_the_closed_forms():
    """Tip radius r + m, root radius r - 1.25 m - delta (the offset root flat), every tooth reaching the
    tip circle at its centre line (within 0.5 um: the tip curve is sampled 60 times a pitch, sagitta
    0.03 um), and the tip land the involute tooth thickness on the tip circle
    s_a = 2 r_a (s / 2r + inv(alpha) - inv(alpha_a)), within 0.1 um."""
    z, module, j = 24, 1.0, 0.1
    r, p = z * module / 2, np.pi * module
    cut = spur()
    radius = np.hypot(*cut.dense.T)
    assert radius.max() == pytest.approx(r + module, abs=1e-9)
    root = r - DEDENDUM * module - delta_of(j)
    assert radius.min() == pytest.approx(root, abs=1e-6)
    assert cut.root_radius_min_mm == pytest.approx(root, abs=1e-6)
    centres = np.arange(z) * p
    tips = (r + module) * np.column_stack([np.cos(-centres / r), np.sin(-centres / r)])
    assert distance_to_ring(tips, cut.dense).max() < 5e-4
    r_a = r + module
    a_a = np.arccos(r * np.cos(ALPHA) / r_a)
    s_a = 2 * r_a * ((p / 2 - j / 2) / (2 * r) + inv(ALPHA) - inv(a_a))
    assert cut.tip_land_min_mm == pytest.approx(s_a, abs=1e-4)
    assert cut.self_intersecting is False
    np.testing.assert_array_equal(cut.tooth_centres, centres)


def test_spur_outline_is_ccw_valid_and_decimated_within_its_budget():
    """The outline is a valid CCW polygon, a subset of the dense outline with fewer vertices, every dense
    vertex within tolerance - 1 um of it, and not needlessly dense: the largest deviation uses more than
    half of that budget (a decimation at half the tolerance would stay below it); with ``decimate=False``
    the outline is the dense outline itself."""
    cut = spur()
    poly = Polygon(cut.outline)
    assert poly.is_valid and poly.exterior.is_ccw
    assert Polygon(cut.dense).exterior.is_ccw
    assert len(cut.outline) < len(cut.dense) / 5
    dense_set = {tuple(v) for v in cut.dense}
    assert all(tuple(v) in dense_set for v in cut.outline)
    dev = distance_to_ring(cut.dense, cut.outline)
    assert dev.max() <= TOL - 1e-3 + 1e-12
    assert dev.max() > 0.6 * TOL
    full = spur(decimate=False)
    np.testing.assert_array_equal(full.outline, full.dense)
    np.testing.assert_array_equal(full.dense, cut.dense)


def test_spur_flanks_are_numbered_around_the_gear():
    """A closed gear of z teeth has 2 z involute flanks, keyed 0 .. 2z - 1 (left flank of tooth k: 2k)."""
    cut = spur()
    assert sorted(cut.flanks) == list(range(48))
    # flank 2k is left of tooth k: on its side of the tooth centre line at polar angle -k p / r
    p, r = np.pi, 12.0
    for key in (0, 1, 10, 11):
        k = key // 2
        ang = np.arctan2(cut.flanks[key][:, 1], cut.flanks[key][:, 0]) + k * p / r
        ang = (ang + np.pi) % (2 * np.pi) - np.pi
        assert np.all(ang > 0) if key % 2 == 0 else np.all(ang < 0)


def test_pointed_teeth_have_no_tip_land():
    """With an addendum of 1.6 m the z = 24 involute teeth come to a point below the tip circle (the tooth
    thickness s_a of the closed form is negative at r + 1.6 m): no tooth touches the tip curve, the tip land
    is 0."""
    z, module, j = 24, 1.0, 0.1
    r = z * module / 2
    r_a = r + 1.6 * module
    s_a = 2 * r_a * ((np.pi / 2 - j / 2) / (2 * r) + inv(ALPHA) - inv(np.arccos(r * np.cos(ALPHA) / r_a)))
    assert s_a < 0
    cut = spur(addendum=1.6)
    assert cut.tip_land_min_mm == 0.0
    assert np.hypot(*cut.dense.T).max() < r_a - 0.01


def test_one_pointed_tooth_makes_the_tip_land_zero():
    """Elliptic gear (e = 0.5, z = 24) with an addendum of 1.6 m: the teeth near the minor axis still reach
    the tip curve (their tip point, the pitch curve offset by the addendum at the tooth centre, lies on the
    outline within 1e-6 mm) but the others come to a point short of it (more than 20 um): the shortest land
    is that of a pointed tooth, 0, not the shortest land of the teeth that have one."""
    pitch = PitchCurves(elliptic_law(0.5), 30.0, (0.0, 2 * np.pi), 0.0, (2 * np.pi, 2 * np.pi))
    z = 24
    module = pitch.perimeter_a / (np.pi * z)
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, 1.6)
    centres = np.arange(z) * np.pi * module
    cut = cut_gear(pitch, "a", rack, centres, method="exact", delta=delta_of(0.05), addendum_mm=1.6 * module,
                   closed=True, rack_origin=0.0, hub_radius_mm=2.0, chord_tolerance_mm=TOL)
    gap = distance_to_ring(offset_points(pitch, centres, "a", 1.6 * module), cut.dense)
    assert 2 <= np.count_nonzero(gap < 1e-6) <= z / 2
    assert np.count_nonzero(gap > 0.02) >= z / 2
    assert cut.tip_land_min_mm == 0.0


def test_undercut_gear_keeps_only_flank_points_on_the_outline():
    """z = 10 spur gear (below the 17-tooth undercut limit at 20 deg): the envelope crosses itself and the
    trochoid removes the lower flanks; every flank point reported lies on the final outline (within 2e-6 mm,
    the 1e-6 mm band) and inside the tip circle, and each of the 20 flanks keeps some points."""
    cut = spur(z=10)
    assert cut.self_intersecting is True
    assert sorted(cut.flanks) == list(range(20))
    pts = np.vstack(list(cut.flanks.values()))
    assert distance_to_ring(pts, cut.dense).max() < 2e-6
    assert np.hypot(*pts.T).max() <= 5.0 + 1.0 + 1e-9
    # the trochoid really removed the lower flanks: fewer than the rack's 241 flank samples are left on each
    assert max(len(v) for v in cut.flanks.values()) < 241


def test_undercut_concave_sector_keeps_only_flank_points_on_the_outline():
    """A sector on a pitch curve with a concave stretch (law 0.8 x + 0.1 sin 3x on 24 mm, module 0.3, which
    the pair's feasibility check accepts): its envelope crosses itself, and flank points cut away there lie
    up to 20 um inside the final outline; every flank point reported lies on the outline (within 2e-6 mm,
    the 1e-6 mm band), none of the cut-away ones."""
    module = 0.3
    pitch = PitchCurves(FormulaLaw("0.8*x + 0.1*sin(3*x)"), 24.0, (-0.6, 2.1), 0.0)
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, ADDENDUM)
    cut = cut_gear(pitch, "a", rack, np.arange(12, 20) * np.pi * module, method="exact", delta=delta_of(0.05),
                   addendum_mm=module, closed=False, rack_origin=0.0, hub_radius_mm=2.0, chord_tolerance_mm=TOL)
    assert cut.self_intersecting is True
    assert sorted(cut.flanks) == list(range(24, 40))
    pts = np.vstack(list(cut.flanks.values()))
    assert distance_to_ring(pts, cut.dense).max() < 2e-6


# -- sectors ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("gear", ["a", "b"])
def test_sector_spans_its_first_and_last_tooth_space_to_the_root(gear):
    """A sector ends at the centres of the spaces before its first and after its last tooth: the root
    points there (pitch curve offset inwards by 1.25 m + delta at k p -+ p/2) lie on the outline within
    1e-6 mm, and the tip curve points at each tooth centre (offset outwards by m) too, within 0.5 um."""
    pitch, p = sector_pitch(), np.pi
    cut = sector(gear)
    centres = cut.tooth_centres
    np.testing.assert_array_equal(centres, np.array(SECTOR_K) * p + (0.0 if gear == "a" else 0.5 * p))
    ends = offset_points(pitch, np.array([centres[0] - p / 2, centres[-1] + p / 2]), gear, -DEDENDUM - delta_of(0.05))
    assert distance_to_ring(ends, cut.dense).max() < 1e-6
    tips = offset_points(pitch, centres, gear, ADDENDUM)
    assert distance_to_ring(tips, cut.dense).max() < 5e-4
    # exactly the five teeth: five pieces of the outline reach 0.9 m beyond the pitch curve
    s = np.linspace(centres[0] - 2 * p, centres[-1] + 2 * p, 2000)
    band = Polygon(np.vstack([offset_points(pitch, s, gear, 0.9), offset_points(pitch, s[::-1], gear, 2.0)]))
    tips = Polygon(cut.dense).intersection(band)
    assert len(getattr(tips, "geoms", [tips])) == len(SECTOR_K)


def test_sector_of_nearly_a_full_turn_whose_tip_curve_overlaps_itself():
    """22 teeth of module 1.02 on a 12 mm pitch circle (0.98 of a turn; the sector's ends a pitch beyond the
    teeth span 0.98 turn, as a gear pair allows): the tip curve with its 1.5-pitch margins wraps past a full
    turn, so the fan that clips the tips overlaps itself and must be repaired. The outline is still the 22
    spur teeth: valid, every tooth reaching the tip circle at its centre (0.5 um), both end spaces down to
    the root (1e-6 mm), and 22 pieces of material on the pitch circle."""
    pitch = PitchCurves(FormulaLaw("x"), 24.0, (-1.0, 7.5), 0.0)
    module = 1.02
    p = np.pi * module
    centres = np.arange(22) * p
    assert centres[-1] - centres[0] + 2 * p < 24 * np.pi < centres[-1] - centres[0] + 3 * p
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, ADDENDUM)
    cut = cut_gear(pitch, "a", rack, centres, method="exact", delta=delta_of(0.05), addendum_mm=module,
                   closed=False, rack_origin=0.0, hub_radius_mm=2.0, chord_tolerance_mm=TOL)
    assert Polygon(cut.outline).is_valid and Polygon(cut.outline).exterior.is_ccw
    assert distance_to_ring(offset_points(pitch, centres, "a", module), cut.dense).max() < 5e-4
    ends = offset_points(pitch, np.array([centres[0] - p / 2, centres[-1] + p / 2]), "a",
                         -DEDENDUM * module - delta_of(0.05))
    assert distance_to_ring(ends, cut.dense).max() < 1e-6
    # start the circle in the gap between the sector's ends (polar angle +p / r: just before tooth 0)
    assert len(material_arcs(cut.dense, 12.0, start=p / 12.0)) == 22


def test_approx_sector_whose_plain_decimation_crosses_itself_still_gets_a_valid_outline():
    """Osculating-circle teeth on a concave pitch stretch (law 0.8 x + 0.1 sin 3x, module 0.5, gear b) leave
    notches narrower than the tolerance between neighbouring teeth: plain Douglas-Peucker of the dense
    outline at the 4 um budget crosses itself (checked here), so the outline is decimated preserving
    topology instead. It is still a valid CCW polygon with fewer vertices, every dense vertex within the
    5 um chord tolerance of it."""
    module = 0.5
    pitch = PitchCurves(FormulaLaw("0.8*x + 0.1*sin(3*x)"), 24.0, (-0.6, 2.1), 0.0)
    rack = basic_rack(module, ALPHA, DEDENDUM, FILLET, ADDENDUM)
    cut = cut_gear(pitch, "b", rack, (np.arange(15, 21) + 0.5) * np.pi * module, method="approx",
                   delta=delta_of(0.05), addendum_mm=module, closed=False, rack_origin=0.0, hub_radius_mm=2.0,
                   chord_tolerance_mm=TOL)
    assert Polygon(cut.dense).is_valid
    assert not Polygon(simplify_ring(cut.dense, TOL - 1e-3)).is_valid
    poly = Polygon(cut.outline)
    assert poly.is_valid and poly.exterior.is_ccw
    assert len(cut.outline) < len(cut.dense) / 5
    assert distance_to_ring(cut.dense, cut.outline).max() <= TOL


def test_sector_flank_keys_are_rack_flank_indices():
    """A sector's flanks keep the rack numbering (left flank of tooth k p: 2k, right: 2k + 1, here -2 .. 7),
    not reduced modulo 2 z as around a closed gear."""
    assert sorted(sector("a").flanks) == list(range(-2, 8))
    assert sorted(sector("a", k=(3, 4, 5)).flanks) == list(range(6, 12))


def tip_lands(cut) -> np.ndarray:
    """Lengths (sorted) of the runs of dense outline vertices on the tip curve of a gear-a sector: within
    0.1 um of the pitch curve offset by the addendum, sampled every 13 um (sagitta 2e-9 mm)."""
    c = cut.tooth_centres
    tip = offset_points(sector_pitch(), np.linspace(c[0] - 2 * np.pi, c[-1] + 2 * np.pi, 2000), "a", ADDENDUM)
    on = shapely.distance(shapely.points(cut.dense), LineString(tip)) < 1e-4
    lands = []
    for i in np.flatnonzero(on[1:] & ~on[:-1]) + 1:  # start of each run (none wraps: the hub is at the ends)
        stop = i + int(np.argmin(on[i:]))
        lands.append(LineString(cut.dense[i:stop]).length)
    return np.sort(lands)


def test_sector_tip_land_is_the_shortest_land():
    """The lands differ from tooth to tooth on a non-circular sector; the reported tip land is the
    shortest of the lands measured by :func:`tip_lands`, within 0.1 um (the tip land also counts the
    1e-6 mm band around the tip curve, about 3e-6 mm)."""
    lands = tip_lands(sector("a"))
    assert len(lands) == len(SECTOR_K)
    assert lands[1] - lands[0] > 1e-3  # the choice of the shortest matters
    assert sector("a").tip_land_min_mm == pytest.approx(lands[0], abs=1e-4)


def test_one_tooth_sector_has_its_tip_land():
    """A sector of one tooth (the tip curve meets the outline in one piece, not a collection) reports that
    land (measured by :func:`tip_lands`, within 0.1 um), and its two flanks 2 and 3."""
    one = sector("a", k=(1,))
    lands = tip_lands(one)
    assert len(lands) == 1 and lands[0] > 0.5
    assert one.tip_land_min_mm == pytest.approx(lands[0], abs=1e-4)
    assert sorted(one.flanks) == [2, 3]


def test_sector_hub_larger_than_the_root_shrinks_to_95_percent_of_it():
    """A hub asked wider than the root is cut to 0.95 x the smallest root radius, so the spaces stay:
    the outline's extent away from the teeth is that radius (within the hub's 0.2 x tolerance chords), and
    the area stays below the hub-free sector plus that disc."""
    big = sector("a", hub=100.0)
    r_hub = 0.95 * big.root_radius_min_mm
    pitch = sector_pitch()
    away = -pitch.frames(np.array([np.pi]), "a").point[0]
    away /= np.hypot(*away)
    ray = LineString([(0.0, 0.0), tuple(100.0 * away)])
    hit = Polygon(big.dense).exterior.intersection(ray)
    assert shapely.Point(0, 0).distance(hit) == pytest.approx(r_hub, abs=0.2 * TOL + 1e-9)
    assert Polygon(big.dense).area < Polygon(sector("a").dense).area + np.pi * r_hub**2


def test_coarse_rack_flank_of_two_points_is_kept():
    """A rack sampled with 3 points per flank leaves 2 of them inside the tip curve (the foot and the
    middle, 0.1 m below the pitch line): the least that makes a flank segment, and each flank is kept."""
    cut = sector("a", rack_points=3)
    assert sorted(cut.flanks) == list(range(-2, 8))
    assert {len(v) for v in cut.flanks.values()} == {2}


# -- non-circular: exact envelope against the osculating-circle approximation -----------------------
@pytest.mark.parametrize("method", ["exact", "approx"])
def test_elliptic_root_follows_the_pitch_curve_or_the_osculating_circle(method):
    """Between two teeth the exact gear's root is the pitch curve offset inwards by h = 1.25 m + delta; the
    approximated gear's root is its tooth's osculating circle (centre P - n / kappa) offset by h at arc
    -p/2 from the tooth centre. Each lies on its outline within 1e-6 mm; the two differ by more than 1 um
    (e = 0.5, z = 24), so each method's outline is told apart."""
    pitch, module, cut = elliptic(method)
    p, h, z = np.pi * module, DEDENDUM * module + delta_of(0.05), 24
    centres = np.arange(z) * p
    exact = offset_points(pitch, centres - p / 2, "a", -h)
    f = pitch.frames(centres, "a")
    rho = 1.0 / f.curvature[:, None]
    phi = -p / 2 / rho
    centre = f.point - rho * f.normal
    approx = centre + (rho - h) * (np.cos(phi) * f.normal + np.sin(phi) * f.tangent)
    assert np.max(np.hypot(*(exact - approx).T)) > 1e-3
    want = exact if method == "exact" else approx
    assert distance_to_ring(want, cut.dense).max() < 1e-6
    # both reach the tip curve at the tooth centres and are valid CCW outlines within the tolerance
    assert distance_to_ring(offset_points(pitch, centres, "a", module), cut.dense).max() < 5e-4
    assert Polygon(cut.outline).is_valid and Polygon(cut.outline).exterior.is_ccw
    assert distance_to_ring(cut.dense, cut.outline).max() <= TOL
