"""Gears: laws, pitch curves (no slip), exact involute for constant ratio, outline validity."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import ellipe
from shapely.geometry import LineString, Polygon

from fabricate.errors import SpecError
from fabricate.gears import GearSpec, make_gear_pair
from fabricate.gears.law import FormulaLaw, elliptic_law
from fabricate.gears.pitch import PitchCurves
from fabricate.gears.spec import parse_gear_spec
from fabricate.planar import rotation
from fabricate.table import Table

DATA = json.loads((Path(__file__).parent / "data" / "gears_expected.json").read_text())
TWO_PI = 2 * np.pi


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
