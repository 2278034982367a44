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

Then (formerly tests/test_gears.py) laws, pitch curves (no slip), exact involute for constant ratio and
outline validity, through :func:`make_gear_pair`.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from functools import cache
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import ellipe
from shapely.geometry import LineString, Polygon

from fabricate.errors import SpecError
from fabricate.gears import GearSpec, build_gear_pairs, make_gear_pair
from fabricate.gears.build import _deviation_um
from fabricate.gears.law import FormulaLaw, elliptic_law
from fabricate.gears.pitch import PitchCurves
from fabricate.gears.spec import parse_gear_spec
from fabricate.mechanism import Body, Driver, GearCoupling, Mechanism, Revolute
from fabricate.planar import rotation
from fabricate.table import Table

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
    # the closing counts 122:121 and 244:242 are 61 below and 61 above the 183 asked for: neither is searched
    # (were 122 found, the refusal would be the 100-teeth bound's, naming the module)
    (122, 121, 183.0, "gears.teeth", "no whole tooth counts near 183.0"),
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


# -- resource bounds: teeth per gear and mesh-check work -------------------------------------------
def closed_circles(spec: GearSpec, center_distance: float, formula: str = "x", name: str = "pair", **kwargs):
    """A closed pair on the constant-ratio law ``x_b = -k x_a`` (pitch circles of radii a k / (1 + k) and
    a / (1 + k)), over the turn from 0, without the mesh check."""
    return make_gear_pair(FormulaLaw(formula), center_distance, (0.0, TWO_PI), spec, closed=True, name=name,
                          run_mesh_check=False, **kwargs)


def test_mesh_step_bound_refuses_naming_mesh_steps_and_the_largest_count():
    """21 + 21 teeth at 7200 mesh steps is 302400 tooth-steps, over the bound of 300000 (``bounds``): refused
    naming ``gears.mesh_steps``, with the product, the time estimate (3.5e-5 s per tooth-step) and the most
    steps 42 teeth allow, 300000 // 42 = 7142 (exact message)."""
    from fabricate.bounds import MAX_MESH_STEP_TEETH, MESH_SECONDS_PER_TOOTH_STEP

    with pytest.raises(SpecError) as info:
        closed_circles(GearSpec(teeth=(21, 21), mesh_steps=7200, compare_methods=False), 50.0)
    assert info.value.path == "gears.mesh_steps"
    work = 7200 * 42
    assert work == 302400 > MAX_MESH_STEP_TEETH
    assert info.value.message == (f"7200 steps × 42 teeth = 302400 tooth-steps, over the bound of 300000 (about "
                                  f"{MESH_SECONDS_PER_TOOTH_STEP * work:.0f} s estimated); at most "
                                  f"{300000 // 42} steps")
    assert 300000 // 42 == 7142


def test_mesh_step_bound_accepts_exactly_the_bound():
    """25 + 25 teeth at 6000 steps is exactly 300000 tooth-steps: at the bound, not over it, so the pair is
    cut (50 mm between equal circles: module 2 * 25 / 25 = 2 mm)."""
    pair = closed_circles(GearSpec(teeth=(25, 25), mesh_steps=6000, compare_methods=False), 50.0,
                          chord_tolerance_mm=0.05)
    assert pair.teeth == (25, 25)
    assert pair.module == pytest.approx(2.0, rel=1e-9)


def test_tooth_bound_accepts_exactly_100_teeth():
    """Equal circles of radius 50 mm (a = 100 mm) at module 1 mm hold 2 * 50 / 1 = 100 teeth each: exactly the
    100-teeth bound, so the pair is cut with 100:100 teeth (and 100 tips on each outline)."""
    pair = closed_circles(GearSpec(module_mm=1.0, compare_methods=False), 100.0, chord_tolerance_mm=0.05)
    assert pair.teeth == (100, 100)
    assert pair.module == pytest.approx(1.0, rel=1e-9)
    assert tips(pair.outline_a, 50.5) == tips(pair.outline_b, 50.5) == 100


def test_tooth_bound_refuses_101_teeth_naming_the_module():
    """At module 0.99 mm the 50 mm circles ask for 100 / 0.99 = 101.01 teeth: 101:101 close the law but are
    over the 100-teeth bound; refused naming ``gears.module_mm`` (the template gave the module), with the
    module of 101 teeth, 100 / 101 mm, and the smallest module that fits, 100 / 101 * 101 / 100 = 1 mm."""
    with pytest.raises(SpecError) as info:
        closed_circles(GearSpec(module_mm=0.99, compare_methods=False), 100.0)
    assert info.value.path == "gears.module_mm"
    assert info.value.message == ("the pitch curves need 101 and 101 teeth at module 0.99 mm, over the bound of "
                                  "100 teeth per gear; use a module of at least 1 mm")


def test_tooth_bound_refuses_101_teeth_given_naming_the_teeth():
    """Tooth counts given by the template (101:101, past the template parser) are refused naming
    ``gears.teeth``, the field the template set."""
    with pytest.raises(SpecError) as info:
        closed_circles(GearSpec(teeth=(101, 101), compare_methods=False), 100.0)
    assert info.value.path == "gears.teeth"
    assert info.value.message.startswith("the pitch curves need 101 and 101 teeth at module 0.99 mm")


# -- closure tolerance of given tooth counts ---------------------------------------------------------
def test_given_teeth_close_the_law_within_a_millionth_of_its_turns():
    """Teeth 40:10 against a law turning gear b 4.000002 times: off by 2e-6 turns, 5e-7 of the 4 turns,
    inside the 1e-6 relative tolerance: the pair is cut with the teeth given. (A tolerance of 1e-6 / turns,
    2.5e-7 turns here, would refuse it.)"""
    pair = closed_circles(GearSpec(teeth=(40, 10), compare_methods=False), 50.0, formula="4.000002*x",
                          chord_tolerance_mm=0.05)
    assert pair.teeth == (40, 10)
    assert pair.module == pytest.approx(2 * 40.0 / 40, rel=1e-5)  # pitch circle of gear a: 50 * 4 / 5 = 40 mm


def test_given_teeth_off_by_more_than_a_millionth_of_the_turns_are_refused():
    """Teeth 10:40 against a law turning gear b 0.2500005 times: off by 5e-7 turns, 2e-6 of the 0.25 turns,
    outside the 1e-6 relative tolerance (a tolerance of 1e-6 / turns, 4e-6 turns here, would accept it):
    refused naming ``gears.teeth`` with the counts that would close the law, 10 / 0.2500005 = 39.99992."""
    with pytest.raises(SpecError) as info:
        closed_circles(GearSpec(teeth=(10, 40), compare_methods=False), 50.0, formula="0.2500005*x")
    assert info.value.path == "gears.teeth"
    assert info.value.message == (f"teeth 10:40 give 0.25 turns of b per turn of a but the law gives "
                                  f"{0.2500005:.6g}; use teeth [10, {10 / 0.2500005:.6g}] or a law that closes")


# -- the ratio must repeat over gear b's turn ------------------------------------------------------------
def test_law_whose_ratio_does_not_repeat_over_gear_b_is_refused():
    """x_b = -(2 x + 0.1 sin x) turns gear b exactly twice per turn of a (teeth 20:10 agree), but gear b
    closes after pi of gear a and the ratio 2 + 0.1 cos x does not repeat after pi (it changes by 0.2):
    refused naming ``gears.<name>.law`` with gear b's turn in degrees of a (exact message)."""
    with pytest.raises(SpecError) as info:
        closed_circles(GearSpec(teeth=(20, 10), compare_methods=False), 15.0, formula="2*x + 0.1*sin(x)",
                       name="mesh_q")
    assert info.value.path == "gears.mesh_q.law"
    assert info.value.message == ("the law does not close gear b: its ratio does not repeat after gear b's turn "
                                  "(180.00 deg of a); use a law periodic over that angle")


@pytest.mark.parametrize(("c", "closes"), [(5e-8, True), (1.5e-7, False)])
def test_ratio_repeats_within_1e7_of_the_largest_ratio(c, closes):
    """Ratio 2 + c cos x against itself half a turn on: it changes by up to 2c (at x = 0, a grid point),
    the tolerance is 1e-7 of the largest ratio 2 + c. c = 5e-8 changes it by 1e-7 < 2e-7: cut (a tolerance of
    1e-7 / (2 + c) would refuse it); c = 1.5e-7 by 3e-7 > 2e-7: refused. Teeth 20:10 at 15 mm (module 1)."""
    spec = GearSpec(teeth=(20, 10), compare_methods=False)
    if closes:
        pair = closed_circles(spec, 15.0, formula=f"2*x + {c!r}*sin(x)", chord_tolerance_mm=0.05)
        assert pair.teeth == (20, 10)
    else:
        with pytest.raises(SpecError) as info:
            closed_circles(spec, 15.0, formula=f"2*x + {c!r}*sin(x)")
        assert info.value.path == "gears.pair.law"
        assert info.value.message.startswith("the law does not close gear b")


# -- min_teeth: the module that would give enough teeth ------------------------------------------------
@pytest.mark.parametrize(("formula", "teeth"), [("2*x", (12, 6)), ("0.5*x", (6, 12))])
def test_too_few_teeth_are_refused_with_the_module_that_gives_min_teeth(formula, teeth):
    """A closed pair whose smaller gear has 6 teeth, below min_teeth = 8, is refused naming ``gears.teeth``
    with the largest module giving the smaller gear 8 teeth (exact message). At 15 mm with ratio 2 gear a's
    pitch circle is 20 mm across and b, the smaller, gets half of a's teeth: 20 pi / (pi * 8 * 2) = 1.25 mm;
    with ratio 1/2 gear a is 10 mm across and is itself the smaller: 10 pi / (pi * 8) = 1.25 mm."""
    with pytest.raises(SpecError) as info:
        closed_circles(GearSpec(teeth=teeth, compare_methods=False), 15.0, formula=formula)
    assert info.value.path == "gears.teeth"
    assert info.value.message == "6 teeth is below min_teeth = 8: use at least 8 teeth (module <= 1.25 mm)"


# -- sectors: teeth follow from the range and the module ------------------------------------------------
def small_sector(spec: GearSpec, **kwargs):
    """A ratio-1 sector at 20 mm (pitch circles of radius 10 mm) over 0.5 rad (5 mm of pitch arc)."""
    return make_gear_pair(FormulaLaw("x"), 20.0, (0.0, 0.5), spec, closed=False, name="mesh_q",
                          run_mesh_check=False, chord_tolerance_mm=0.05, **kwargs)


def test_sector_refuses_tooth_counts_naming_the_teeth():
    """Tooth counts apply to closed pairs only: a sector given teeth is refused naming ``gears.teeth`` with
    both ways out (exact message)."""
    with pytest.raises(SpecError) as info:
        small_sector(GearSpec(teeth=(10, 10), compare_methods=False))
    assert info.value.path == "gears.teeth"
    assert info.value.message == ("tooth counts apply to closed pairs; a sector's teeth follow from its working "
                                  "range and module (leave teeth out or set closed = true)")


def test_sector_without_a_module_is_cut_at_half_a_millimetre():
    """No module in the template: a sector gets the SLA-sized 0.5 mm. Its teeth then follow in closed form:
    5 mm of arc is 5 / (0.5 pi) = 3.18 pitches; gear a's teeth sit at whole pitches from -2.25 to 3.18 + 2.25
    pitches (1.25 + 1 spare tooth each side), -2..5: 8 teeth; gear b's half a pitch off, -1.5..4.5: 7 teeth."""
    pair = small_sector(GearSpec(compare_methods=False))
    assert pair.module == 0.5
    assert pair.teeth == (8, 7)


@pytest.mark.parametrize(("module", "hub"), [(1.2, 2.0 + 4 * 1.2), (0.25, 2.0 + 2.0)])
def test_sector_hub_is_the_larger_of_bore_plus_2_mm_and_bore_plus_4_modules(module, hub):
    """With neither hub nor bore in the template the bore is the 2 mm SLA pin and the hub diameter
    max(bore + 2 mm, bore + 4 m): 6.8 mm at module 1.2, 4 mm at module 0.25. The sector's outline is closed
    by that hub disk: its nearest point to the axis lies on the hub circle, within the 0.05 mm chord
    tolerance."""
    pair = small_sector(GearSpec(module_mm=module, compare_methods=False))
    assert pair.hub_diameter_mm == pytest.approx(hub, rel=1e-12)
    assert (pair.bore_a_mm, pair.bore_b_mm) == (2.0, 2.0)
    for outline in (pair.outline_a, pair.outline_b):
        assert 0.5 * hub - 0.05 <= np.min(np.hypot(*outline.T)) <= 0.5 * hub + 1e-9


def test_sector_hub_given_by_the_template_is_kept():
    """A template's hub diameter (9 mm) is used as given: the attribute and the hub circle of the outlines."""
    pair = small_sector(GearSpec(module_mm=1.0, hub_diameter_mm=9.0, compare_methods=False))
    assert pair.hub_diameter_mm == 9.0
    for outline in (pair.outline_a, pair.outline_b):
        assert 4.5 - 0.05 <= np.min(np.hypot(*outline.T)) <= 4.5 + 1e-9


def test_backlash_up_to_a_quarter_pitch_is_cut_and_beyond_is_refused():
    """The backlash may be at most a quarter of the circular pitch (pi m / 4 = 0.785 mm at module 1): exactly
    that is cut, 0.79 mm is refused naming ``gears.backlash_mm`` with the limit (exact message)."""
    limit = 0.25 * (math.pi * 1.0)
    pair = small_sector(GearSpec(module_mm=1.0, backlash_mm=limit, compare_methods=False))
    assert pair.spec.backlash_mm == limit and pair.teeth == (6, 6)
    with pytest.raises(SpecError) as info:
        small_sector(GearSpec(module_mm=1.0, backlash_mm=0.79, compare_methods=False))
    assert info.value.path == "gears.backlash_mm"
    assert info.value.message == "backlash 0.79 mm is too large for module 1 mm; use backlash_mm <= 0.785"


@pytest.mark.parametrize(("center", "module"), [(20.0, 1.0), (2.0, 0.1)])
def test_law_that_fails_where_the_sector_is_extended_is_refused_naming_the_law(center, module):
    """x_b = -(x - 0.5 sin x - x^3 / 30) has ratio 1 - 0.5 cos x - 0.1 x^2, positive over the working range
    (-3, 3) but negative beyond about 3.8 rad. The sector's pitch curves are extended by
    1.3 * margin / r_min, margin = (1.25 + 1 spare + 2.5) pi m + 5 m and r_min = a * 0.5 / 1.5 the smallest
    pitch radius (ratio 0.5 at x = 0): 3.88 rad = 222.6 deg, into the negative ratio: refused naming
    ``gears.<name>.law`` with the extension in degrees (the same at 20 mm / module 1 and at 2 mm / module 0.1,
    where r_min is 0.67 mm)."""
    margin = (1.25 + 1 + 2.5) * math.pi * module + 5 * module
    grow = 1.3 * margin / (center * 0.5 / 1.5)
    assert f"{math.degrees(grow):.1f}" == "222.6"
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("x - 0.5*sin(x) - x**3/30"), center, (-3.0, 3.0),
                       GearSpec(module_mm=module, compare_methods=False), closed=False, name="mesh_q",
                       run_mesh_check=False)
    assert info.value.path == "gears.mesh_q.law"
    message = info.value.message
    assert message.startswith("transmission ratio -") and " <= 0 at x_a = " in message
    assert message.endswith("(the law is extended 222.6 deg beyond the working range for the spare teeth; "
                            "widen the law's range or use fewer spare_teeth)")


@pytest.mark.parametrize(("hi", "teeth", "ends"), [(0.5, (8, 7), (-3.0, 6.0)), (0.175 * math.pi, (8, 8), (-3.0, 6.5))])
def test_sector_pitch_curves_run_a_pitch_beyond_the_outermost_teeth(hi, teeth, ends):
    """A sector's pitch curves (as drawn and as used by the strength check) run from one circular pitch
    before the first tooth of either gear to one pitch after the last. Ratio 1 at 20 mm, module 0.5: the
    range ends at 10 hi / p pitches (p = pi / 2 mm); gear a's teeth sit at whole pitches from -2 (1.25 + 1
    spare before 0) to floor(10 hi / p + 2.25), gear b's half a pitch off. For hi = 0.5 (3.18 pitches) a's
    last tooth, at 5, is the outermost: the curves span -3..6 pitches; for hi = 0.175 pi (3.5 pitches) b's,
    at 5.5: -3..6.5. On the 10 mm circles that is x_a = s / 10: gear a's pitch point at polar angle -x_a
    (listed CCW, from the far end), gear b's at pi + x_a (1e-9 mm)."""
    pair = make_gear_pair(FormulaLaw("x"), 20.0, (0.0, hi), GearSpec(compare_methods=False), closed=False,
                          run_mesh_check=False, chord_tolerance_mm=0.05)
    assert pair.teeth == teeth
    x0, x1 = (k * math.pi / 2 / 10 for k in ends)

    def on_circle(angle):
        return [10 * math.cos(angle), 10 * math.sin(angle)]

    np.testing.assert_allclose(pair.pitch_a[[0, -1]], [on_circle(-x1), on_circle(-x0)], atol=1e-9)
    np.testing.assert_allclose(pair.pitch_b[[0, -1]], [on_circle(math.pi + x0), on_circle(math.pi + x1)], atol=1e-9)


def test_sector_whose_gear_b_turns_a_full_turn_is_refused():
    """Ratio 2 at 30 mm (pitch circles 20 and 10 mm), module 1, range (0, 3): with its spare teeth gear a's
    pitch curve runs from 3 pitches before 0 to 22 pitches (60 mm of range is 19.1 pitches; a's last tooth is
    at floor(19.1 + 2.25) = 21), x_a from -3 pi / 20 = -0.47 to 22 pi / 20 = 3.46: 3.93 rad of gear a, less
    than a turn, but 7.85 rad of gear b: refused naming ``gears.<name>.closed`` (exact message)."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("2*x"), 30.0, (0.0, 3.0), GearSpec(module_mm=1.0, compare_methods=False),
                       closed=False, name="mesh_q", run_mesh_check=False)
    assert info.value.path == "gears.mesh_q.closed"
    assert info.value.message == "the sector with its spare teeth spans a full turn; use closed = true"


def test_ratio_sign_change_is_located_at_its_most_negative_sample():
    """x_b = -sin(x_a) over (0, 5): ratio cos x_a, most negative at pi. The ratio is sampled at 1025 points
    (every 5 / 1024 rad) before anything is built; the message names the sample nearest pi, 643 * 5 / 1024 rad
    = 179.889 deg, its ratio (-1 to 4 digits) and ``gears.<name>.law``."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("sin(x)"), 20.0, (0.0, 5.0), GearSpec(module_mm=0.5, compare_methods=False),
                       closed=False, name="mesh_q", run_mesh_check=False)
    assert info.value.path == "gears.mesh_q.law"
    assert f"{math.degrees(643 * 5 / 1024):.3f}" == "179.889"
    assert info.value.message == ("transmission ratio -1 <= 0 at x_a = 179.889 deg: an external gear pair needs "
                                  "the driven angle to change monotonically with the driving angle; use a "
                                  "monotonic law (ratio > 0 everywhere)")


@pytest.mark.parametrize(("hi", "teeth"), [(95.5 * 0.5 * math.pi / 30, (100, 100))])
def test_sector_of_exactly_100_teeth_is_cut(hi, teeth):
    """Ratio 1 at 60 mm (30 mm circles), module 0.5 (pitch pi / 2), a range of 95.5 pitches: gear a's teeth
    at -2..floor(95.5 + 2.25) = 97, 100 teeth; gear b's at -1.5..96.5, 100: at the 100-teeth bound, cut."""
    pair = make_gear_pair(FormulaLaw("x"), 60.0, (0.0, hi), GearSpec(module_mm=0.5, compare_methods=False),
                          closed=False, run_mesh_check=False, chord_tolerance_mm=0.05)
    assert pair.teeth == teeth


def test_sector_over_100_teeth_is_refused_before_it_is_cut():
    """Ratio 1 at 80 mm (40 mm circles), module 0.5, range 1.5 pi: 60 pi mm = 120 pitches of range plus
    1.25 + 1 spare each side: 124 teeth a gear by the sector's estimate (120 + 4.5, whole teeth), over the
    bound: refused naming ``gears.module_mm`` with the module that fits, 0.5 * 124 / 100 = 0.62 mm."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("x"), 80.0, (0.0, 1.5 * math.pi), GearSpec(module_mm=0.5, compare_methods=False),
                       closed=False, run_mesh_check=False)
    assert info.value.path == "gears.module_mm"
    assert info.value.message == ("the pitch curves need 124 and 124 teeth at module 0.5 mm, over the bound of 100 "
                                  "teeth per gear; use a module of at least 0.62 mm")


@pytest.mark.parametrize("formula", ["2*exp(x/2)", "-2*exp(-x/2)"])
def test_sector_pitch_curves_are_extended_by_the_margin_on_both_sides(formula):
    """Spare teeth need the pitch curves beyond the range: they are built at least
    margin = (1.25 + spare + 2.5) p + 5 m of arc beyond each end (p = pi m). Ratio e^(x/2) (or e^(-x/2)) at
    20 mm, module 1, range (0, 1): the pitch radius shrinks towards one end, so the first extension
    (1.3 margin / smallest radius) falls short there and is grown until both ends are covered."""
    pair = make_gear_pair(FormulaLaw(formula), 20.0, (0.0, 1.0), GearSpec(module_mm=1.0, compare_methods=False),
                          closed=False, run_mesh_check=False, chord_tolerance_mm=0.05)
    margin = (1.25 + 1 + 2.5) * math.pi + 5
    pitch = pair.pitch_model
    s_hi = float(pitch.s_of_x(np.array([1.0]))[0])
    assert pitch.s_nodes[0] < -margin and pitch.s_nodes[-1] > s_hi + margin


def test_closed_pair_reports_the_smallest_radius_of_curvature_over_the_whole_turn():
    """Two equal ellipses (e = 0.2, semi-major axis A = 20 mm, on foci 40 mm apart) turned from x_a = -pi/2:
    the pitch curves' smallest radius of curvature is A (1 - e^2) = 19.2 mm, at the ends of the major axis
    (x_a = 0 and pi), which the closed pair's 2049 samples of the turn from -pi/2 include. 1e-6 relative:
    the curvature takes a finite-difference second derivative of the law (about 1e-7 relative)."""
    from fabricate.gears.law import elliptic_law

    lo = -math.pi / 2
    pair = make_gear_pair(elliptic_law(0.2), 40.0, (lo, lo + TWO_PI), GearSpec(teeth=(20, 20), compare_methods=False),
                          closed=True, run_mesh_check=False, chord_tolerance_mm=0.05)
    assert pair.checks["min_pitch_radius_of_curvature_mm"] == pytest.approx(20.0 * (1 - 0.2**2), rel=1e-6)


def test_report_ranges_are_the_laws_extremes_over_the_working_range():
    """x_b = -(x_a - 0.5 cos x_a) over (0, pi): ratio 1 + 0.5 sin x_a, 1 at both ends and 1.5 at pi / 2, the
    middle of the working range (sampled at 721 points including it). At 20 mm the pitch radii a i / (1 + i)
    run from 10 to 12 mm on gear a and from 8 to 10 mm on gear b (1e-9 relative)."""
    pair = make_gear_pair(FormulaLaw("x - 0.5*cos(x)"), 20.0, (0.0, math.pi),
                          GearSpec(module_mm=0.5, compare_methods=False), closed=False, run_mesh_check=False,
                          chord_tolerance_mm=0.05)
    report = pair.report()
    assert report["transmission_ratio"] == pytest.approx([1.0, 1.5], rel=1e-9)
    assert report["pitch_radius_a_mm"] == pytest.approx([10.0, 12.0], rel=1e-9)
    assert report["pitch_radius_b_mm"] == pytest.approx([8.0, 10.0], rel=1e-9)


def test_a_law_whose_ratio_does_not_repeat_after_a_turn_of_gear_a_is_refused():
    """Regression (found by helper-31): x_b = 1.5 x + (0.2 / 3) sin(1.5 x) advances gear b by exactly 1.5 turns
    per turn of a (teeth 30:20 agree), but its ratio 1.5 + 0.1 cos(1.5 x) is 1.6 at 0 and 1.4 at 2 pi, so gear a's
    pitch curve jumps at the seam (r 15.385 -> 14.583 mm). Only gear b's closure was checked; now gear a's
    is too, naming gears.closed (the law or the closedness must change)."""
    with pytest.raises(SpecError) as info:
        make_gear_pair(FormulaLaw("1.5*x + (0.2/3)*sin(1.5*x)"), 25.0, (0.0, TWO_PI),
                       GearSpec(teeth=(30, 20), compare_methods=False), closed=True, name="mesh_q",
                       run_mesh_check=False)
    assert info.value.path == "gears.closed"
    assert info.value.message.startswith("the law does not close gear a: its ratio does not repeat")


@pytest.mark.parametrize("centre, teeth", [(16.0, (8, 8)), (20.0, (10, 10))])
def test_a_closed_pair_of_exactly_min_teeth_is_built(centre, teeth):
    """Regression (found by helper-31): equal circles of radius centre / 2 with z = min_teeth = 8 (or 10 with
    min_teeth 10) have module 2 rho / z exactly, the largest the feasibility check allows; the sampled curvature
    made the bound 2e-16 smaller and the pair was refused with 'needs module <= 2 mm'. Built, with the module
    centre / z (1e-12)."""
    spec = GearSpec(teeth=teeth, min_teeth=teeth[0], compare_methods=False)
    pair = make_gear_pair(FormulaLaw("x"), centre, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False,
                          chord_tolerance_mm=0.05)
    assert pair.teeth == teeth
    assert pair.module == pytest.approx(centre / teeth[0], abs=1e-12)


# == laws, pitch curves and teeth through make_gear_pair (formerly tests/test_gears.py) ==========================
DATA = json.loads((Path(__file__).resolve().parents[1] / "data" / "gears_expected.json").read_text())


# -- laws --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("text", ['__import__("os")', "x.real", "abs(x)", "y + 1", "(lambda: 1)()",
                                  "x +", "sin(x, 2)", "open('f')"])
def test_formula_rejects_anything_outside_the_whitelist(text):
    with pytest.raises(SpecError):
        FormulaLaw(text)


def test_formula_derivatives_match_analytic():
    law = FormulaLaw("x + 0.03*sin(x) + 0.1*exp(0.2*x)", sign=-1.0)
    x = np.linspace(-1.0, 7.0, 50)
    assert np.allclose(law(x), -(x + 0.03 * np.sin(x) + 0.1 * np.exp(0.2 * x)), atol=1e-14)
    assert np.allclose(law(x, 1), -(1 + 0.03 * np.cos(x) + 0.02 * np.exp(0.2 * x)), atol=1e-13)
    assert np.allclose(law(x, 2), -(-0.03 * np.sin(x) + 0.004 * np.exp(0.2 * x)), atol=1e-8)
    assert np.allclose(law(x, 3), -(-0.03 * np.cos(x) + 0.0008 * np.exp(0.2 * x)), atol=1e-5)


def test_elliptic_law_slope_and_closure():
    e = 0.3
    law = elliptic_law(e)
    x = np.linspace(0, TWO_PI, 101)
    assert np.allclose(-law(x, 1), (1 - e * e) / (1 + e * e + 2 * e * np.cos(x)), atol=1e-12)
    assert law(TWO_PI) == pytest.approx(-TWO_PI, abs=1e-12)


def test_gear_spec_defaults_and_errors():
    spec = parse_gear_spec(Table({}, "gears"))
    assert spec.pressure_angle_deg == 20.0 and spec.dedendum == 1.25 and spec.root_fillet == 0.38
    assert spec.mesh_steps >= 720 and spec.spare_teeth >= 1
    for bad, field in (({"mesh_steps": 100}, "gears.mesh_steps"), ({"method": "x"}, "gears.method"),
                       ({"teeth": [4, 30]}, "gears.teeth"), ({"modul_mm": 1}, "gears.modul_mm")):
        with pytest.raises(SpecError) as err:
            parse_gear_spec(Table(bad, "gears"))
        assert err.value.path == field


# -- pitch curves ----------------------------------------------------------------------------------
def test_pitch_curves_roll_without_slip_and_keep_centre_distance():
    law = FormulaLaw("x + 0.15*sin(x) + 0.05*sin(2*x)")
    a = 40.0
    pitch = PitchCurves(law, a, (0.0, TWO_PI), 0.0, (TWO_PI, TWO_PI))
    x = np.linspace(0.0, 1.5, 30001)
    pa, pb = pitch.curve(x, "a"), pitch.curve(x, "b")
    # no slip: equal rolled arc lengths (polylines, chord error ~1e-9 relative)
    la = np.sum(np.hypot(*np.diff(pa, axis=0).T))
    lb = np.sum(np.hypot(*np.diff(pb, axis=0).T))
    assert la == pytest.approx(lb, rel=1e-8)
    assert la == pytest.approx(pitch.s_of_x(np.array([1.5]))[0], rel=1e-8)
    # placed by the gear-frame convention both pitch points coincide on the line of centres
    k = np.arange(0, len(x), 1000)
    wa = np.einsum("nij,nj->ni", rotation(x[k]), pa[k])
    wb = np.einsum("nij,nj->ni", rotation(law(x[k])), pb[k]) + [a, 0.0]
    assert np.allclose(wa, wb, atol=1e-9)
    assert np.allclose(wa[:, 1], 0.0, atol=1e-9)
    # and the curves are tangent there
    fa, fb = pitch.frames_at_x(x[k], "a"), pitch.frames_at_x(x[k], "b")
    ta = np.einsum("nij,nj->ni", rotation(x[k]), fa.tangent)
    tb = np.einsum("nij,nj->ni", rotation(law(x[k])), fb.tangent)
    assert np.allclose(ta, tb, atol=1e-9)


def test_elliptic_pitch_curve_is_the_ellipse():
    e, a = 0.2, 30.0
    pitch = PitchCurves(elliptic_law(e), a, (0.0, TWO_PI), 0.0, (TWO_PI, TWO_PI))
    semi_major = a / 2
    assert pitch.perimeter_a == pytest.approx(4 * semi_major * ellipe(e * e), rel=1e-9)
    assert pitch.perimeter_b == pytest.approx(pitch.perimeter_a, rel=1e-12)
    k = pitch.frames_at_x(np.array([0.0, np.pi]), "a").curvature
    assert np.allclose(1 / k, semi_major * (1 - e * e), rtol=1e-6)  # b^2 / A at the major axis ends


# -- teeth -------------------------------------------------------------------------------------------
def _involute_error_um(outline, r, z, module, alpha, delta, centre_angle, spec):
    """Largest normal distance (um) of flank points from the analytic involute of the pitch circle."""
    radius = np.hypot(*outline.T)
    phi = np.arctan2(outline[:, 1], outline[:, 0])
    rel = (phi - centre_angle + np.pi / z) % (TWO_PI / z) - np.pi / z
    straight = (spec.dedendum - spec.root_fillet * (1 - np.sin(alpha))) * module
    form = np.hypot(r - straight, straight / np.tan(alpha))
    sel = (radius > form + 1e-3) & (radius < r + 0.999 * module)
    base = r * np.cos(alpha)
    a_r = np.arccos(base / radius[sel])

    def inv(t):
        return np.tan(t) - t

    half = (np.pi * module / 2 - 2 * delta / np.cos(alpha)) / (2 * r) + inv(alpha) - inv(a_r)
    err = (np.abs(rel[sel]) - half) * radius[sel] * np.cos(a_r)
    return int(np.count_nonzero(sel)), float(np.max(np.abs(err)) * 1000)


@pytest.mark.parametrize("case", DATA["constant_ratio_cases"])
def test_constant_ratio_gives_true_involute_spur_gears(case):
    z_a, z_b = case["teeth"]
    module = 1.0
    a = module * (z_a + z_b) / 2
    spec = GearSpec(teeth=(z_a, z_b), backlash_mm=case["backlash_mm"], compare_methods=False, min_teeth=8)
    pair = make_gear_pair(FormulaLaw(case["law"]), a, (0.0, TWO_PI), spec, closed=True,
                          chord_tolerance_mm=0.005, run_mesh_check=False)
    assert pair.module == pytest.approx(module, rel=1e-9)
    assert pair.teeth == (z_a, z_b)
    delta = case["backlash_mm"] * np.cos(spec.pressure_angle) / 4
    r_a, r_b = module * z_a / 2, module * z_b / 2
    # gear a's tooth 0 is centred at polar angle 0; gear b's first tooth half a pitch later (pi + p/2 / r_b)
    for outline, r, z, centre in ((pair.outline_a, r_a, z_a, 0.0), (pair.cut_a.dense, r_a, z_a, 0.0),
                                  (pair.outline_b, r_b, z_b, np.pi + np.pi * module / 2 / r_b),
                                  (pair.cut_b.dense, r_b, z_b, np.pi + np.pi * module / 2 / r_b)):
        count, err = _involute_error_um(outline, r, z, module, spec.pressure_angle, delta, centre, spec)
        assert count > 10 * z
        assert err < DATA["involute_tolerance_um"]


def _assert_valid_outline(outline, dense, tolerance):
    poly = Polygon(outline)
    assert poly.is_valid and poly.exterior.is_ccw
    steps = np.hypot(*np.diff(np.vstack([outline, outline[:1]]), axis=0).T)
    assert steps.min() > 1e-9  # no repeated vertices, no closing duplicate
    # chord error: every dense (exact) vertex lies within the tolerance of the decimated outline
    ring = LineString(np.vstack([outline, outline[:1]]))
    assert np.max(shapely.distance(shapely.points(dense), ring)) <= tolerance


@settings(max_examples=4, deadline=None)
@given(e=st.floats(0.0, 0.3), z=st.integers(20, 36))
def test_elliptic_pairs_have_valid_outlines(e, z):
    spec = GearSpec(teeth=(z, z), backlash_mm=0.05, compare_methods=False)
    pair = make_gear_pair(elliptic_law(e), 30.0, (0.0, TWO_PI), spec, closed=True, chord_tolerance_mm=0.005,
                          run_mesh_check=False)
    for cut in (pair.cut_a, pair.cut_b):
        _assert_valid_outline(cut.outline, cut.dense, 0.005)
    # the pitch perimeter holds exactly z teeth
    assert pair.pitch_model.perimeter_a == pytest.approx(z * np.pi * pair.module, rel=1e-12)


def test_sector_outline_contains_its_axis_and_pitch_curve():
    spec = GearSpec(module_mm=0.5, backlash_mm=0.05, compare_methods=False)
    pair = make_gear_pair(FormulaLaw("0.8*x + 0.05*sin(2*x)"), 18.0, (0.1, 0.9), spec, closed=False,
                          chord_tolerance_mm=0.005, run_mesh_check=False)
    for cut, pitch in ((pair.cut_a, pair.pitch_a), (pair.cut_b, pair.pitch_b)):
        _assert_valid_outline(cut.outline, cut.dense, 0.005)
        poly = Polygon(cut.outline)
        assert poly.contains(shapely.Point(0.0, 0.0))
        # the pitch curve runs through teeth and spaces alike (about half of it inside the material),
        # never farther than an addendum from the outline
        middle = pitch[len(pitch) // 4: 3 * len(pitch) // 4]
        inside = shapely.contains_xy(poly, middle[:, 0], middle[:, 1]).mean()
        assert 0.4 < inside < 0.6
        assert np.max(shapely.distance(shapely.points(middle), poly.exterior)) < spec.addendum * pair.module
    # the sector covers the working range plus a spare tooth each side: more teeth than the arc needs
    arc = pair.pitch_model.s_of_x(np.array([0.9]))[0]
    assert min(pair.teeth) >= arc / (np.pi * pair.module) + 2 * spec.spare_teeth


def test_approx_method_is_the_same_involute_for_a_constant_ratio():
    # the osculating circle of a circle is the circle: the approximation is exact there
    z, module = 24, 1.0
    spec = GearSpec(teeth=(z, z), method="approx", backlash_mm=0.03, compare_methods=True)
    pair = make_gear_pair(FormulaLaw("x"), z * module, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    delta = 0.03 * np.cos(spec.pressure_angle) / 4
    count, err = _involute_error_um(pair.cut_a.dense, z * module / 2, z, module, spec.pressure_angle, delta, 0.0,
                                    spec)
    assert count > 10 * z and err < DATA["involute_tolerance_um"]
    assert pair.checks["exact_vs_approx_max_deviation_um"] < 0.01


def test_small_gear_is_flagged_as_undercut():
    spec = GearSpec(teeth=(12, 12), compare_methods=False, min_teeth=8, backlash_mm=0.05)
    pair = make_gear_pair(FormulaLaw("x"), 12.0, (0.0, TWO_PI), spec, closed=True, run_mesh_check=False)
    assert pair.report()["undercut"]
    # radius of curvature 6 mm < h_l / sin^2(alpha) = 1.0 m / sin^2(20 deg) = 8.55 mm
    assert pair.checks["undercut_limit_radius_mm"] == pytest.approx(1.0 / np.sin(np.radians(20)) ** 2, rel=1e-3)
    assert any(text.startswith("undercut") for text in pair.failures())
    # the trochoid removed part of the flanks: the mesh check sees only what is left, consistently
    from fabricate.gears import mesh_check

    mesh = mesh_check(pair, steps=720)
    assert np.all(mesh.interference_area_mm2 == 0.0) and np.nanmin(mesh.backlash_mm) > 0.04
    assert np.mean(mesh.teeth_in_contact) < pair.checks["contact_ratio"]["min"]  # undercut shortens contact
