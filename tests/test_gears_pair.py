"""Gear pairs as the pipeline builds them (``fabricate/gears/pair.py``), with expected values from closed forms.

Written to kill mutants of ``fabricate/gears/pair.py`` (``tests/benchmarks/mutation.py``; survivors that
no output can show are listed in ``tests/benchmarks/mutation/equivalent.toml``): :func:`build_gear_pairs`
takes the centre distance, the names and the closedness from the mechanism's coupling; a law that does
not close is refused naming ``gears.closed``; closed pairs get the whole tooth counts nearest the module;
``GearPair.failures`` fires exactly when a limit is crossed; ``GearPair.report`` gives the pair's own
geometry; the exact-vs-approx deviation is the largest point-to-outline distance (against shapely).

The mechanisms are small real :class:`~fabricate.mechanism.Mechanism` objects built here (a carrier and
two gears on a constant-ratio law, ``x_b = -x_a`` or ``x_b = -x_a / 2``, whose pitch curves are circles):
every expected number follows from the points and laws written below.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from functools import cache
from types import SimpleNamespace

import numpy as np
import pytest
import shapely

from fabricate.errors import SpecError
from fabricate.gears import GearSpec, build_gear_pairs, make_gear_pair
from fabricate.gears.law import FormulaLaw
from fabricate.gears.pair import _deviation_um
from fabricate.mechanism import Body, Driver, GearCoupling, Mechanism, Revolute

TWO_PI = 2.0 * math.pi

# sector: carrier axis points off the origin and off the x axis (a 36-48-60 triangle), 5.30 rad of
# working range: more than a turn minus 1 rad, less than a full turn
SECTOR_OA, SECTOR_OB = (3.0, -2.0), (3.0 + 36.0, -2.0 + 48.0)
SECTOR_CENTRE_MM = 60.0
SECTOR_RANGE = (0.0, 5.30)
SECTOR_MODULE = 1.2
SECTOR_CHORD_MM = 0.05  # ten times the default 0.005 mm
# closed pair: gear b turns half a turn per turn of gear a (law x_b = -x_a / 2); the axis points are
# on gear a's body only (a 9-12-15 triangle), the range starts off zero and spans 2 pi - 1e-9 exactly
CLOSED_OA, CLOSED_OB = (2.0, 1.0), (2.0 + 9.0, 1.0 + 12.0)
CLOSED_CENTRE_MM = 15.0
CLOSED_LO = -0.5
CLOSED_HI = CLOSED_LO + (TWO_PI - 1e-9)


def mechanism(law, carrier_points, gear_a_points, working_range, name="mesh_ab") -> Mechanism:
    """Carrier ``arm``, gear a ``wheel`` on axis OA, gear b ``pinion`` on axis OB (pinned to the arm, or to
    the wheel when the arm has no point OB), one coupling ``name``."""
    bodies = (Body("arm", carrier_points), Body("wheel", gear_a_points), Body("pinion", {"OB": (0.0, 0.0)}))
    joints = (Revolute("OA", "arm", "wheel"), Revolute("OB", "arm" if "OB" in carrier_points else "wheel", "pinion"))
    coupling = GearCoupling(name, carrier="arm", gear_a="wheel", gear_b="pinion", law=law, axis_a="OA",
                            axis_b="OB", working_range=working_range)
    return Mechanism(name="gears", bodies=bodies, ground="arm", joints=joints, gears=(coupling,),
                     drivers=(Driver("angle", "wheel", "arm"),), input_range=(0.0, 10.0))


def sector_mechanism() -> Mechanism:
    return mechanism(FormulaLaw("x"), {"OA": SECTOR_OA, "OB": SECTOR_OB}, {"OA": (0.0, 0.0)}, SECTOR_RANGE)


def closed_mechanism() -> Mechanism:
    return mechanism(FormulaLaw("0.5*x"), {"OA": (0.0, 0.0)}, {"OA": CLOSED_OA, "OB": CLOSED_OB},
                     (CLOSED_LO, CLOSED_HI))


@cache
def sector():
    """The sector pair as the pipeline builds it (``spec.closed`` unset: the range decides), with its mesh."""
    (pair,) = build_gear_pairs(sector_mechanism(), GearSpec(module_mm=SECTOR_MODULE, compare_methods=False),
                               SECTOR_CHORD_MM)
    return pair


@cache
def closed():
    (pair,) = build_gear_pairs(closed_mechanism(), GearSpec(module_mm=1.0, compare_methods=False), 0.005)
    return pair


def tips(outline: np.ndarray, radius: float) -> int:
    """Teeth of an outline: runs of vertices (cyclic) farther from the axis than ``radius``."""
    out = np.hypot(*outline.T) > radius
    return int(np.count_nonzero(out & ~np.roll(out, 1)))


# -- build_gear_pairs ------------------------------------------------------------------------------
def test_build_gear_pairs_centre_distance_is_the_carrier_axis_distance():
    """The centre distance is |OB - OA| in the carrier (60 mm for the 36-48 offsets, axis points off the
    origin so that a sum instead of a difference shows), and the cut sector's pitch circles have radius
    a / 2 (ratio 1): the module and the teeth are those of that circle."""
    pair = sector()
    assert math.dist(SECTOR_OA, SECTOR_OB) == SECTOR_CENTRE_MM
    assert pair.center_distance_mm == pytest.approx(SECTOR_CENTRE_MM, rel=1e-12)
    assert pair.module == SECTOR_MODULE
    for pitch in (pair.pitch_a, pair.pitch_b):  # both pitch curves lie on the circle of radius 30 mm (1 um)
        np.testing.assert_allclose(np.hypot(*pitch.T), SECTOR_CENTRE_MM / 2, atol=1e-3)


def test_build_gear_pairs_sector_short_of_a_turn_is_open():
    """``spec.closed`` unset: a coupling range of 5.30 rad (more than a turn minus 1 rad, less than a full
    turn) makes a sector, not closed gears, and the sector's teeth cover the range plus the spare teeth."""
    pair = sector()
    assert pair.closed is False
    assert pair.working_range == SECTOR_RANGE
    # arc of the range on the 30 mm pitch circle over the circular pitch, plus at least a spare each side
    arc_teeth = SECTOR_CENTRE_MM / 2 * (SECTOR_RANGE[1] - SECTOR_RANGE[0]) / (math.pi * SECTOR_MODULE)
    assert min(pair.teeth) >= arc_teeth + 2


def test_build_gear_pairs_names_where_the_pair_sits():
    """Name, coupling, carrier, bodies and axes come from the coupling (the parts layer places the gears by
    them): every one is the name written in the mechanism."""
    pair = sector()
    assert (pair.name, pair.coupling, pair.carrier) == ("mesh_ab", "mesh_ab", "arm")
    assert (pair.body_a, pair.body_b, pair.axis_a, pair.axis_b) == ("wheel", "pinion", "OA", "OB")
    report = pair.report()
    assert report["name"] == "mesh_ab" and report["coupling"] == "mesh_ab"
    assert report["bodies"] == ["wheel", "pinion"]


def test_build_gear_pairs_outlines_keep_the_process_chord_tolerance():
    """The outlines are simplified to the chord tolerance passed in (0.05 mm), not the default 0.005 mm:
    every dense-outline vertex lies within 0.05 mm of the outline, and somewhere farther than 0.005 mm."""
    pair = sector()
    for cut in (pair.cut_a, pair.cut_b):
        gap = shapely.distance(shapely.points(cut.dense), shapely.LinearRing(cut.outline))
        assert 0.005 < np.max(gap) <= SECTOR_CHORD_MM + 1e-9


def test_build_gear_pairs_centre_distance_from_gear_a_when_the_carrier_lacks_an_axis():
    """The carrier has OA only: the centre distance is |OB - OA| in gear a's body (15 mm for the 9-12
    offsets). The range spans exactly 2 pi - 1e-9 from -0.5 rad, so the pair is closed; gear b turns half
    a turn per turn of a, so z_b = 2 z_a, and the module is gear a's pitch-circle perimeter (radius
    a * 0.5 / 1.5 = 5 mm) over pi z_a."""
    assert CLOSED_HI - CLOSED_LO == TWO_PI - 1e-9  # the boundary case, exactly
    assert math.dist(CLOSED_OA, CLOSED_OB) == CLOSED_CENTRE_MM
    pair = closed()
    assert pair.closed is True
    assert pair.center_distance_mm == pytest.approx(CLOSED_CENTRE_MM, rel=1e-12)
    assert (pair.body_a, pair.axis_a, pair.axis_b) == ("wheel", "OA", "OB")
    z_a, z_b = pair.teeth
    assert z_b == 2 * z_a  # z_a / z_b = the law's 0.5 turns of b per turn of a
    r_a = CLOSED_CENTRE_MM * 0.5 / 1.5
    assert pair.module == pytest.approx(TWO_PI * r_a / (math.pi * z_a), rel=1e-9)
    assert z_a == 10  # 1 mm module asked for: 10 mm pitch diameter
    report = pair.report()
    assert report["teeth"] == [10, 20]
    assert report["min_pitch_radius_of_curvature_mm"] == pytest.approx(r_a, rel=1e-6)


def test_spec_closed_overrides_the_working_range():
    """``closed = false`` in the spec wins over a full-turn range: the full-turn sector is refused naming
    the coupling's ``closed`` field (a closed pair would be built if the range decided)."""
    spec = GearSpec(module_mm=1.0, compare_methods=False, closed=False)
    with pytest.raises(SpecError) as info:
        build_gear_pairs(closed_mechanism(), spec, 0.005)
    assert info.value.path == "gears.mesh_ab.closed"


# -- the closure of a closed pair ----------------------------------------------------------------
@pytest.mark.parametrize(("formula", "turns"), [("sin(x) - 0.1*x", "-0.1"), ("x*(2*pi - x)", "0"),
                                                ("x + sqrt(4 - x)", "nan")])
def test_law_that_does_not_close_is_refused_naming_gears_closed(formula, turns):
    """A closed external pair needs gear b to turn a positive number of times per turn of a. These laws
    have a positive ratio over the working range [0, 1] but turn b -0.1 times (sin(2 pi) = 0), exactly 0
    times (x (2 pi - x) vanishes at 0 and 2 pi) or not at all (sqrt of a negative at 2 pi): refused
    naming ``gears.closed`` with the number of turns."""
    spec = GearSpec(teeth=(10, 10), compare_methods=False)
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw(formula), 20.0, (0.0, 1.0), spec, closed=True, run_mesh_check=False)
    assert info.value.path == "gears.closed"
    message = info.value.message
    assert f"turns gear b {turns} times per turn of gear a" in message.replace("-0 ", "0 ")
    assert "positive" in message


# -- failures: each exactly when its limit is crossed --------------------------------------------
def with_checks(pair, **values):
    return replace(pair, checks={**pair.checks, **values})


def with_backlash(pair, low: float, high: float = 0.05):
    """The pair with its mesh's backlash running from ``low`` to ``high`` mm."""
    backlash = np.linspace(low, high, pair.mesh.steps)
    return replace(pair, mesh=replace(pair.mesh, backlash_mm=backlash))


def test_sector_has_no_failures():
    """The 60 mm ratio-1 sector at module 1.2 is fine: no failure, and every check on the right side."""
    pair = sector()
    assert pair.failures() == []
    summary = pair.mesh.summary()
    assert summary["backlash_mm"][0] > 0 and summary["interference_area_mm2"] <= 1e-6


def test_tip_land_failure_exactly_below_a_fifth_of_the_module():
    """Tip land >= 0.2 m is acceptable; below it the teeth are pointed, and the text gives both numbers."""
    pair = sector()
    limit = 0.2 * SECTOR_MODULE
    assert with_checks(pair, tip_land_min_mm=limit).failures() == []
    (text,) = with_checks(pair, tip_land_min_mm=0.17).failures()
    assert text.startswith("pointed teeth: tip land 0.17 mm < 0.24 mm")


def test_contact_ratio_failure_exactly_below_one():
    """A contact ratio of 1 keeps a tooth pair in contact; below 1 the teeth lose contact (number given)."""
    pair = sector()
    assert with_checks(pair, contact_ratio={"min": 1.0, "mean": 1.5}).failures() == []
    (text,) = with_checks(pair, contact_ratio={"min": 0.93, "mean": 1.5}).failures()
    assert text.startswith("contact ratio 0.930 < 1: the teeth lose contact")


def test_interference_failure_above_a_square_micrometre():
    """Overlap up to 1e-6 mm^2 is numerical noise; above it the mesh interferes (area given)."""
    pair = sector()
    steps = pair.mesh.steps
    at = replace(pair, mesh=replace(pair.mesh, interference_area_mm2=np.full(steps, 1e-6)))
    assert at.failures() == []
    area = np.zeros(steps)
    area[steps // 2] = 3e-6
    (text,) = replace(pair, mesh=replace(pair.mesh, interference_area_mm2=area)).failures()
    assert text == "interference: 3e-06 mm^2 of tooth overlap in mesh"


@pytest.mark.parametrize(("low", "words"), [(0.01, None), (0.0, "backlash 0 mm <= 0"),
                                            (-0.02, "backlash -0.02 mm <= 0")])
def test_backlash_failure_when_the_smallest_backlash_is_not_positive(low, words):
    """The teeth jam when the smallest backlash over the mesh is zero or negative (the largest, 0.05 mm,
    does not matter); the text gives the smallest."""
    failures = with_backlash(sector(), low).failures()
    if words is None:
        assert failures == []
    else:
        (text,) = failures
        assert text.startswith(words) and "the teeth jam" in text


def test_steps_without_a_flank_pair_are_a_failure():
    """A mesh step with no flank pair (NaN backlash) fails even when every other step has positive
    backlash; a mesh with no pair at all too. The text counts the steps."""
    pair = sector()
    steps = pair.mesh.steps
    backlash = np.full(steps, 0.05)
    backlash[[3, 7]] = np.nan
    (text,) = replace(pair, mesh=replace(pair.mesh, backlash_mm=backlash)).failures()
    assert text.startswith("mesh: 2 step(s) without a flank pair in mesh")
    none = replace(pair, mesh=replace(pair.mesh, backlash_mm=np.full(steps, np.nan)))
    (text,) = none.failures()
    assert text.startswith(f"mesh: {steps} step(s) without a flank pair in mesh")


def test_mesh_beyond_the_sector_counts_the_steps_without_teeth():
    """Turned 0.6 rad before its working range the sector runs out of teeth (its first tooth is centred
    2 pitches, 0.25 rad, before the range): the failure counts exactly the steps whose backlash is
    undefined, and there are some, but not all."""
    from fabricate.gears.mesh import mesh_check

    pair = sector()
    mesh = mesh_check(pair, np.linspace(SECTOR_RANGE[0] - 0.6, SECTOR_RANGE[0] + 0.1, 15))
    missing = int(np.count_nonzero(~np.isfinite(mesh.backlash_mm)))
    assert 0 < missing < 15
    failures = replace(pair, mesh=mesh).failures()
    assert f"mesh: {missing} step(s) without a flank pair in mesh (add spare teeth)" in failures


# -- report ----------------------------------------------------------------------------------------
def test_report_is_the_pairs_own_geometry():
    """report.json's entry: teeth counted on the outlines (tips beyond the pitch circle + half a module),
    the centre distance between the axis points, pitch radii and radius of curvature a / 2, ratio 1, the
    working range in degrees, the mesh's backlash; strict JSON."""
    pair = sector()
    report = pair.report()
    r = SECTOR_CENTRE_MM / 2
    counted = [tips(pair.outline_a, r + 0.5 * SECTOR_MODULE), tips(pair.outline_b, r + 0.5 * SECTOR_MODULE)]
    assert counted[0] != counted[1]  # the two counts differ for this range: their order matters
    assert report["teeth"] == counted
    assert report["center_distance_mm"] == pytest.approx(SECTOR_CENTRE_MM, rel=1e-12)
    assert report["module_mm"] == SECTOR_MODULE and report["closed"] is False
    assert report["min_pitch_radius_of_curvature_mm"] == pytest.approx(r, rel=1e-6)
    assert report["pitch_radius_a_mm"] == pytest.approx([r, r], rel=1e-9)
    assert report["pitch_radius_b_mm"] == pytest.approx([r, r], rel=1e-9)
    assert report["transmission_ratio"] == pytest.approx([1.0, 1.0], rel=1e-9)
    assert report["working_range_deg"] == pytest.approx([0.0, math.degrees(SECTOR_RANGE[1])], rel=1e-12)
    finite = np.isfinite(pair.mesh.backlash_mm)
    assert report["backlash_mm"] == [float(np.min(pair.mesh.backlash_mm[finite])),
                                     float(np.max(pair.mesh.backlash_mm[finite]))]
    assert report["outline_vertices"] == [len(pair.outline_a), len(pair.outline_b)]
    json.dumps(report, allow_nan=False)


def test_report_without_a_mesh_check_has_empty_mesh_numbers():
    """Without a mesh check the mesh numbers are null, the backlash a pair of nulls (the DESIGN.md shape)."""
    report = replace(sector(), mesh=None).report()
    assert report["backlash_mm"] == [None, None]
    for key in ("transmission_error_deg", "interference_area_mm2", "mesh_steps", "teeth_in_contact"):
        assert report[key] is None
    json.dumps(report, allow_nan=False)


def test_report_infinite_radius_of_curvature_is_null():
    """No convex stretch on the pitch curves gives an infinite smallest radius of curvature: JSON null."""
    report = with_checks(sector(), min_pitch_radius_of_curvature_mm=math.inf).report()
    assert report["min_pitch_radius_of_curvature_mm"] is None
    json.dumps(report, allow_nan=False)


# -- exact vs approx deviation -------------------------------------------------------------------
def ring_distance_um(main: np.ndarray, points: np.ndarray) -> float:
    """Largest distance (um) from ``points`` to the closed polyline ``main``, by shapely."""
    return 1000.0 * float(np.max(shapely.distance(shapely.points(points), shapely.LinearRing(main))))


def deviation(main: np.ndarray, points) -> float:
    return _deviation_um(SimpleNamespace(dense=np.asarray(main, float)),
                         SimpleNamespace(dense=np.atleast_2d(np.asarray(points, float))))


SQUARE = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
# a rectangle with a notch cut down to (9.5, 0.3): near (10, 0) the second-nearest vertex is the notch's
# bottom, two vertices away along the ring, and the nearest segment is the one before (10, 0)
NOTCH = [(0.0, 0.0), (10.0, 0.0), (10.0, 3.0), (9.5, 0.3), (0.0, 3.0)]


@pytest.mark.parametrize(("ring", "point", "expected"), [
    (SQUARE, (5.0, -1.0), 1.0),  # foot inside a long segment
    (SQUARE, (-0.6, -0.8), 1.0),  # beyond the start of the bottom edge: the corner is nearest
    (SQUARE, (10.6, -0.8), 1.0),  # beyond the end of the bottom edge
    (SQUARE, (10.8, 4.0), 0.8),  # beside the right edge
    (NOTCH, (9.9, -0.1), 0.1),
])
def test_deviation_is_the_point_to_segment_distance(ring, point, expected):
    """The deviation is the distance to the nearest point of the outline's segments (closed forms above,
    and shapely agrees), in micrometres (1e-9 relative)."""
    assert ring_distance_um(np.array(ring), np.array([point])) == pytest.approx(1000.0 * expected, rel=1e-12)
    assert deviation(ring, point) == pytest.approx(1000.0 * expected, rel=1e-9)


def test_deviation_of_circles_with_short_segments():
    """Points 20 um outside a 5 mm circle of 400 vertices (segments 79 um, shorter than 1 mm): the largest
    distance to the polygon, by shapely, at 1e-9 relative."""
    angles = np.linspace(0.0, TWO_PI, 400, endpoint=False)
    ring = 5.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    phase = angles[:97] + np.linspace(0.1, 0.9, 97) * (angles[1] - angles[0])
    points = 5.02 * np.column_stack([np.cos(phase), np.sin(phase)])
    assert deviation(ring, points) == pytest.approx(ring_distance_um(ring, points), rel=1e-9)
    assert 20.0 < deviation(ring, points) < 20.0 + 1000 * 5.0 * (1 - np.cos(np.pi / 400))


@cache
def compared_sector(method: str):
    spec = GearSpec(module_mm=0.5, backlash_mm=0.05, compare_methods=method == "exact", method=method)
    return make_gear_pair(FormulaLaw("0.8*x + 0.05*sin(2*x)"), 18.0, (0.1, 0.9), spec, closed=False,
                          run_mesh_check=False)


def test_exact_vs_approx_deviation_is_the_largest_outline_distance():
    """The reported exact-vs-approx deviation is the largest distance from the approx-cut dense outline of
    either gear to the exact-cut one, by shapely (1e-9 relative); a few micrometres for this gentle law."""
    exact, approx = compared_sector("exact"), compared_sector("approx")
    expected = max(ring_distance_um(exact.cut_a.dense, approx.cut_a.dense),
                   ring_distance_um(exact.cut_b.dense, approx.cut_b.dense))
    assert exact.checks["exact_vs_approx_max_deviation_um"] == pytest.approx(expected, rel=1e-9)
    assert exact.report()["exact_vs_approx_max_deviation_um"] == pytest.approx(expected, rel=1e-9)
    assert 0.5 < expected < 20.0


# -- tooth counts of a closed pair from the module -------------------------------------------------
def test_closed_pair_needs_teeth_or_a_module():
    """A closed pair with neither tooth counts nor a module has nothing to size its teeth: refused naming
    ``gears.teeth`` and both ways out."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("x"), 20.0, (0.0, TWO_PI), GearSpec(compare_methods=False), closed=True,
                       run_mesh_check=False)
    assert info.value.path == "gears.teeth"
    assert info.value.message == "a closed pair needs teeth = [z_a, z_b] or module_mm"


def test_closed_teeth_search_the_nearest_counts_that_close_the_law():
    """Law x_b = -1.4 x_a at 24 mm: pitch circles of 14 and 10 mm, so module 6.6 mm asks for
    2 * 14 / 6.6 = 4.24 teeth on gear a; whole counts closing the law are multiples of 7:5, and 3 to 6
    do not close it: the pair gets 7:5 teeth and the module that fits them, 2 * 14 / 7 = 4 mm."""
    spec = GearSpec(module_mm=6.6, min_teeth=3, compare_methods=False)
    pair = make_gear_pair(FormulaLaw("1.4*x"), 24.0, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    assert pair.teeth == (7, 5)
    assert pair.module == pytest.approx(2 * 14.0 / 7, rel=1e-9)


def test_no_whole_tooth_counts_close_an_irrational_law():
    """Gear b turns sqrt(2) times per turn of a: no whole counts within 60 of the 28.3 teeth the module asks
    for (2 r_a / m, r_a = 10 sqrt(2) mm) close it; refused naming ``gears.teeth`` with both numbers."""
    a = 10.0 * (1.0 + math.sqrt(2.0))  # pitch circles 10 sqrt(2) and 10 mm
    spec = GearSpec(module_mm=1.0, compare_methods=False)
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("sqrt(2)*x"), a, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    assert info.value.path == "gears.teeth"
    ideal = 2 * 10.0 * math.sqrt(2.0) / 1.0
    assert f"no whole tooth counts near {ideal:.1f} close the law ({math.sqrt(2.0):.6g} turns" \
        in info.value.message


def test_closed_teeth_take_the_count_nearest_the_module():
    """Law x_b = -2 x_a at 15 mm (pitch circles 10 and 5 mm), module 20 / 12.9 mm: 12.9 teeth asked for on
    gear a, and only even counts close the law; 12 is nearer than 14, so 12:6 teeth at module 20 / 12."""
    spec = GearSpec(module_mm=20.0 / 12.9, min_teeth=3, compare_methods=False)
    pair = make_gear_pair(FormulaLaw("2*x"), 15.0, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    assert pair.teeth == (12, 6)
    assert pair.module == pytest.approx(20.0 / 12, rel=1e-9)


def test_closed_teeth_accept_a_law_within_a_millionth_of_closing():
    """Gear b turns 1.0000002 times per turn of a: 20 / 1.0000002 = 19.999996 teeth is whole within the
    1e-6 relative tolerance (2e-5 teeth at 20), so the pair gets 20:20 teeth."""
    spec = GearSpec(module_mm=1.0, compare_methods=False)
    pair = make_gear_pair(FormulaLaw("1.0000002*x"), 20.0, (0.0, TWO_PI), spec, closed=True,
                          run_mesh_check=False)
    assert pair.teeth == (20, 20)


@pytest.mark.parametrize(("p", "q", "ideal", "path", "words"), [
    # the only closing count 121:120 is 60 below the 181 asked for: found, then over the 100-teeth bound
    (121, 120, 181.2, "gears.module_mm", "need 121 and 120 teeth"),
    # the only closing count 71:70 is 61 above the 10 asked for: not searched
    (71, 70, 10.2, "gears.teeth", "no whole tooth counts near 10.2"),
])
def test_closed_teeth_search_reaches_60_teeth_either_side(p, q, ideal, path, words):
    """Gear b turns p / q times per turn of a (p, q coprime): only multiples of p teeth on gear a close the
    law. The search covers 60 teeth either side of the count the module asks for (2 r_a / m)."""
    a = 20.0
    r_a = a * (p / q) / (1 + p / q)
    spec = GearSpec(module_mm=2 * r_a / ideal, compare_methods=False)
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw(f"({p}/{q})*x"), a, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    assert info.value.path == path
    assert words in info.value.message


def test_three_closing_teeth_are_refused_as_too_coarse():
    """Two equal ellipses (e = 0.05, semi-major axis 20 mm, on their foci 40 mm apart) at a module just
    inside the min_teeth = 3 limit (0.99 * 2 rho_min / 3, rho_min = A (1 - e^2)) ask for 3.04 teeth: the
    closing count is 3:3, whose module, perimeter / (3 pi) with perimeter 4 A E(e^2), exceeds the limit
    (an ellipse's perimeter is more than 2 pi rho_min): refused naming the module."""
    from scipy.special import ellipe

    from fabricate.gears.law import elliptic_law

    e, semi = 0.05, 20.0
    rho_min, perimeter = semi * (1 - e * e), 4 * semi * ellipe(e * e)
    module = 0.99 * 2 * rho_min / 3
    assert 3.0 < perimeter / (math.pi * module) < 3.5
    spec = GearSpec(module_mm=module, min_teeth=3, compare_methods=False)
    with pytest.raises(SpecError) as info:
        make_gear_pair(elliptic_law(e), 2 * semi, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    assert info.value.path == "gears.module_mm"
    words = info.value.message.split()
    assert words[0] == "module" and words[2:4] == ["mm", "too"]
    assert float(words[1]) == pytest.approx(perimeter / (3 * math.pi), rel=1e-5)  # printed with :g


# -- make_gear_pair's own input checks ---------------------------------------------------------------
@pytest.mark.parametrize("working_range", [(1.0, 1.0), (2.0, 1.0), (math.nan, 1.0), (0.0, math.inf),
                                           (-math.inf, 1.0), (0.0, math.nan)])
def test_a_working_range_that_is_not_a_finite_lo_below_hi_is_refused(working_range):
    """Empty, reversed or non-finite working ranges are refused before anything is cut, naming
    ``gears.<name>.working_range`` and the range given."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("x"), 20.0, working_range, GearSpec(module_mm=1.0, compare_methods=False),
                       closed=False, name="mesh_q", run_mesh_check=False)
    assert info.value.path == "gears.mesh_q.working_range"
    assert info.value.message == f"expected a finite range lo < hi, got {working_range}"


@pytest.mark.parametrize("distance", [0.0, -5.0, math.inf, math.nan])
def test_a_centre_distance_that_is_not_positive_and_finite_is_refused(distance):
    """A zero, negative or non-finite centre distance is refused naming ``gears.<name>.center_distance_mm``."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("x"), distance, (0.0, 1.0), GearSpec(module_mm=1.0, compare_methods=False),
                       closed=False, name="mesh_q", run_mesh_check=False)
    assert info.value.path == "gears.mesh_q.center_distance_mm"
    assert info.value.message == f"expected a positive distance, got {float(distance)}"


def test_a_small_centre_distance_is_accepted():
    """0.5 mm is a positive distance (the check is > 0, not >= 1): it passes the input check and is then
    refused for what it is — pitch radii of 0.25 mm cannot carry module-0.05 teeth — naming the law or the
    module, never the centre distance."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("x"), 0.5, (0.0, 1.0), GearSpec(module_mm=0.05, compare_methods=False),
                       closed=False, name="mesh_q", run_mesh_check=False)
    assert info.value.path != "gears.mesh_q.center_distance_mm"


def test_a_law_that_is_not_monotonic_over_the_range_is_refused_naming_it():
    """x_b = sin(x_a) has ratio -cos(x_a), which changes sign at pi/2: over (0, 3) the law is refused
    naming ``gears.<name>.law``; the ratio is sampled at 1025 points including both ends, so a sign change
    just inside the upper end, (0, pi/2 + 1e-3), is refused too."""
    for hi in (3.0, math.pi / 2 + 1e-3):
        with pytest.raises(SpecError) as info:
            make_gear_pair(FormulaLaw("sin(x)"), 20.0, (0.0, hi), GearSpec(module_mm=1.0, compare_methods=False),
                           closed=False, name="mesh_q", run_mesh_check=False)
        assert info.value.path == "gears.mesh_q.law"
