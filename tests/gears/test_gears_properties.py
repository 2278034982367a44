"""Gear properties a user depends on, with expected values from closed forms written here.

Written to kill mutants of ``fabricate/gears`` (see ``tests/benchmarks/mutation_report.md``): the sector's
hub is the hub that was asked for, and the transmission error is the larger of the two flank errors.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, Polygon

from fabricate.gears import GearSpec, make_gear_pair
from fabricate.gears.law import FormulaLaw

MODULE = 0.5
HUB_MM = 4.0  # hub diameter asked for


@cache
def sector_pair():
    spec = GearSpec(module_mm=MODULE, backlash_mm=0.05, compare_methods=False, hub_diameter_mm=HUB_MM)
    return make_gear_pair(FormulaLaw("0.8*x + 0.05*sin(2*x)"), 18.0, (0.1, 0.9), spec, closed=False,
                          chord_tolerance_mm=0.005, run_mesh_check=False)


@cache
def spur_pair(z: int = 24, module: float = 1.0, backlash: float = 0.1):
    """Two equal circular gears (law x_b = -x_a): exact involute spur gears."""
    spec = GearSpec(teeth=(z, z), module_mm=module, backlash_mm=backlash, compare_methods=False, mesh_steps=720)
    return make_gear_pair(FormulaLaw("x"), z * module, (0.0, 2 * np.pi), spec, closed=True)


def ray_extent(outline: np.ndarray, direction: np.ndarray) -> float:
    """Distance from the axis (origin) to the outline along ``direction`` (nearest crossing)."""
    ray = LineString([(0.0, 0.0), tuple(200.0 * direction)])
    hit = Polygon(outline).exterior.intersection(ray)
    return float(min(Point(0.0, 0.0).distance(g) for g in getattr(hit, "geoms", [hit])))


@pytest.mark.parametrize("gear", ["a", "b"])
def test_sector_hub_is_the_hub_asked_for(gear):
    """Away from the teeth the sector is its hub: the outline's extent there is the hub radius, and the
    area is at most the toothed fan (pitch curve pushed out by the addendum, closed at the axis) plus
    the hub disc."""
    pair = sector_pair()
    cut, pitch = (pair.cut_a, pair.pitch_a) if gear == "a" else (pair.cut_b, pair.pitch_b)
    outline = np.asarray(cut.outline)
    assert Polygon(outline).is_valid
    # opposite the teeth: the direction away from the mean direction of the pitch curve
    mean = np.mean(pitch / np.hypot(*pitch.T)[:, None], axis=0)
    away = -mean / np.hypot(*mean)
    for turn in (-0.5, 0.0, 0.5):  # three rays over the back of the hub
        c, s = np.cos(turn), np.sin(turn)
        d = np.array([c * away[0] - s * away[1], s * away[0] + c * away[1]])
        assert ray_extent(outline, d) == pytest.approx(HUB_MM / 2, abs=0.005)
    # area bound: the fan up to the tip curve plus the hub disc (generous: the fan uses 1.1 addendum)
    r = np.hypot(*pitch.T)[:, None]
    tip = pitch * (r + 1.1 * MODULE) / r
    fan = Polygon(np.vstack([[0.0, 0.0], tip]))
    if not fan.is_valid:
        fan = shapely.make_valid(fan)
    bound = fan.area + np.pi * (HUB_MM / 2) ** 2
    assert Polygon(outline).area <= bound
    # and the teeth are there: more than the fan up to the root curve
    root = pitch * (r - 1.25 * MODULE - 0.1) / r
    assert Polygon(outline).area > Polygon(np.vstack([[0.0, 0.0], root])).area


def test_spur_transmission_error_is_the_larger_flank_error():
    """For equal involute spur gears each flank's designed free play is backlash / (2 r) (the flank
    thinning j cos(alpha) / 4 over the base radius r cos(alpha), twice): the transmission error at a
    step is the larger of |play - designed| over the two flanks, and the report gives its maximum."""
    z, module, backlash = 24, 1.0, 0.1
    pair = spur_pair(z, module, backlash)
    mesh = pair.mesh
    r = z * module / 2
    lag = backlash / (2 * r)
    ok = np.isfinite(mesh.free_plus) & np.isfinite(mesh.free_minus)
    assert ok.mean() > 0.99
    err = np.maximum(np.abs(mesh.free_plus[ok] - lag), np.abs(mesh.free_minus[ok] - lag))
    np.testing.assert_allclose(np.abs(mesh.transmission_error[ok]), err, rtol=1e-9, atol=1e-15)
    assert pair.report()["transmission_error_deg"] == pytest.approx(np.degrees(err.max()), rel=1e-9)
    # total free rotation is the backlash over the pitch radius (closed form, 1 um)
    np.testing.assert_allclose((mesh.free_plus[ok] + mesh.free_minus[ok]) * r, backlash, atol=1e-3)
    # the errors of the two flanks differ: the max/min choice matters for this pair
    assert np.mean(np.abs(np.abs(mesh.free_plus[ok] - lag) - np.abs(mesh.free_minus[ok] - lag)) > 0) > 0.5


# -- outline helpers, each against its definition -------------------------------------------------
def test_flank_index_counts_half_pitches_from_the_origin():
    from fabricate.gears.teeth import flank_index

    p, origin = 2.0, 0.3
    # flank k sits at origin - p/4 + k p/2 on the pitch line (left flank of tooth 0 is 0)
    k = np.arange(-5, 6)
    u = origin - p / 4 + k * p / 2
    np.testing.assert_array_equal(flank_index(u, p, origin), k)
    np.testing.assert_array_equal(flank_index(u + 0.2 * p, p, origin), k)  # rounds to the nearest
    np.testing.assert_array_equal(flank_index(u - 0.2 * p, p, origin), k)
    out = flank_index(np.array([np.nan, np.inf]), p, origin)
    assert out.dtype == np.int64 and np.all(out < -(2**61))


def test_largest_polygon_of_collections():
    from fabricate.gears.teeth import _largest_polygon

    small, big = shapely.box(0, 0, 1, 1), shapely.box(5, 5, 8, 8)
    assert _largest_polygon(big) is big
    assert _largest_polygon(shapely.MultiPolygon([small, big])).equals(big)
    mixed = shapely.GeometryCollection([LineString([(0, 0), (9, 9)]), small, shapely.MultiPolygon([big])])
    assert _largest_polygon(mixed).equals(big)
    with pytest.raises(ValueError):
        _largest_polygon(shapely.GeometryCollection([LineString([(0, 0), (1, 1)])]))


def test_clean_ring_drops_closing_and_repeated_vertices():
    from fabricate.gears.teeth import _clean_ring

    square = np.array([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1], [0, 0]], dtype=float)
    np.testing.assert_array_equal(_clean_ring(square), [[0, 0], [1, 0], [1, 1], [0, 1]])
    np.testing.assert_array_equal(_clean_ring(square[:-1]), [[0, 0], [1, 0], [1, 1], [0, 1]])
    near = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 1e-12]], dtype=float)  # last repeats the first
    assert len(_clean_ring(near)) == 4


@pytest.mark.parametrize("tol", [1e-3, 0.02, 0.2])
def test_simplify_ring_keeps_every_dropped_vertex_within_the_tolerance(tol):
    from fabricate.gears.teeth import simplify_ring

    t = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    r = 10 + 0.8 * np.sin(7 * t) + 0.05 * np.sin(53 * t)
    ring = np.column_stack([r * np.cos(t), r * np.sin(t)])
    out = simplify_ring(ring, tol)
    assert 3 < len(out) < len(ring)
    # a subset of the input, in order
    idx = [int(np.flatnonzero(np.all(ring == v, axis=1))[0]) for v in out]
    assert idx == sorted(idx) and idx[0] == 0
    dist = shapely.distance(shapely.points(ring), shapely.LinearRing(out))
    assert dist.max() <= tol * (1 + 1e-9)
    assert dist.max() > 0.3 * tol  # not needlessly dense
    if tol < 0.01:
        assert len(out) > 100


@pytest.mark.parametrize(("radius", "tol"), [(2.0, 0.005), (0.5, 0.2), (20.0, 1e-4)])
def test_circle_points_chord_error(radius, tol):
    from fabricate.gears.teeth import circle_points

    pts = circle_points(radius, tol, start=0.3)
    n = len(pts)
    assert n >= 16
    np.testing.assert_allclose(np.hypot(*pts.T), radius, rtol=1e-12)
    sagitta = radius * (1 - np.cos(np.pi / n))
    assert sagitta <= tol * (1 + 1e-9)
    assert n == 16 or radius * (1 - np.cos(np.pi / (n - 1))) > tol  # the fewest points that do it
    assert Polygon(pts).exterior.is_ccw
    assert np.arctan2(pts[0, 1], pts[0, 0]) == pytest.approx(0.3)


# -- the gear-mesh check of an assembled motion ---------------------------------------------------
def fake_motion(x_a: np.ndarray, x_b: np.ndarray):
    """The three things check_gear_mesh reads from a Motion: relative angles, inputs, the input unit."""
    from types import SimpleNamespace

    angles = {"gear_a": x_a, "gear_b": x_b, "carrier": np.zeros_like(x_a)}
    return SimpleNamespace(relative_angle=lambda body, ref: angles[body] - angles[ref],
                           inputs=np.degrees(x_a), mechanism=SimpleNamespace(input_unit="deg"))


def test_gear_mesh_check_of_a_motion_on_the_law():
    """Spur pair driven exactly by its law: no failure, backlash = the designed 0.1 mm (closed form), the TE
    the larger flank error against the closed-form designed play at the motion's own angles."""
    from dataclasses import replace

    from fabricate.checks.gear_mesh import check_gear_mesh

    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.2, 1.4, 61)
    result = check_gear_mesh(pair, fake_motion(x, np.asarray(pair.law(x))))
    assert result.failures == ()
    assert result.law_error_rad < 1e-12
    assert result.steps == 61 and result.steps_without_contact == 0
    assert result.backlash_mm == pytest.approx((0.1, 0.1), abs=1e-3)
    lo, hi = result.backlash_allowed_mm
    assert lo < 0.1 < hi
    assert result.x_a_range_deg == pytest.approx((np.degrees(0.2), np.degrees(1.4)))
    assert result.interference_area_mm2 == 0.0
    lag = 0.1 / (2 * 12.0)  # backlash / (2 r), r = 12 mm
    from fabricate.gears.mesh import mesh_check

    own = mesh_check(pair, x_a_values=x)
    err = np.maximum(np.abs(own.free_plus - lag), np.abs(own.free_minus - lag))
    assert result.transmission_error_deg == pytest.approx(np.degrees(np.nanmax(err)), rel=1e-9)


def test_gear_mesh_check_catches_a_motion_off_the_law_and_out_of_range():
    from dataclasses import replace

    from fabricate.checks.gear_mesh import check_gear_mesh

    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.2, 1.4, 31)
    off = check_gear_mesh(pair, fake_motion(x, np.asarray(pair.law(x)) + np.radians(0.5)))
    assert off.law_error_rad == pytest.approx(np.radians(0.5), rel=1e-9)
    assert any("departs from the gear law" in f for f in off.failures)
    sector = replace(sector_pair(), carrier="carrier")
    lo, hi = sector.working_range
    x = np.linspace(lo, hi + 0.2, 31)  # 11 deg past the cut range
    out = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
    assert any("outside the cut range" in f for f in out.failures)
    inside = check_gear_mesh(sector, fake_motion(x[x <= hi], np.asarray(sector.law(x[x <= hi]))))
    assert not any("outside the cut range" in f for f in inside.failures)


# -- ratio laws: formulas, samples, the elliptic family, the ratio check -----------------------------
def test_formula_constants_are_pi_and_e_at_every_angle():
    """``pi`` and ``e`` are the constants, not a function of x: pi + e x and its slope e (closed form), also
    at x = 0 (a constant must not divide by x) and for the complex step (slope exactly e)."""
    from fabricate.gears.law import compile_formula

    x = np.array([-2.0, 0.0, 0.5, 3.0])
    np.testing.assert_allclose(compile_formula("pi + e*x")(x), np.pi + np.e * x, rtol=1e-15)
    np.testing.assert_allclose(compile_formula("pi")(x), np.full(4, np.pi), rtol=1e-15)
    law = FormulaLaw("2.5*x + pi", sign=1.0)
    np.testing.assert_allclose(law(x), 2.5 * x + np.pi, rtol=1e-15)
    np.testing.assert_allclose(law(x, 1), np.full(4, 2.5), rtol=1e-15)
    np.testing.assert_allclose(FormulaLaw("e*x", sign=1.0)(x, 1), np.full(4, np.e), rtol=1e-15)
    np.testing.assert_allclose(compile_formula("+x - -2")(x), x + 2.0, rtol=1e-15)  # unary plus and minus
    # an integer angle array is read as float (numpy refuses integers to negative integer powers)
    np.testing.assert_allclose(FormulaLaw("x**x", sign=1.0)(np.array([-1, 1, 2])), [-1.0, 1.0, 4.0], rtol=1e-15)


def test_law_derivative_falls_back_to_central_differences():
    """A law that gives only its value and slope (nu >= 2 raises), and one that gives only its value:
    x_b = -(x + 0.1 sin x), so law'' = 0.1 sin x and law''' = 0.1 cos x (closed form); the central
    differences (h = 1e-4) are within 1e-7 of it."""
    from fabricate.gears.law import law_derivative

    def partial(x, nu=0):
        if nu == 0:
            return -(x + 0.1 * np.sin(x))
        if nu == 1:
            return -(1.0 + 0.1 * np.cos(x))
        raise ValueError("no higher derivatives")

    def value_only(x, nu=0):
        if nu:
            raise TypeError("only the value")
        return -(x + 0.1 * np.sin(x))

    x = np.linspace(-1.0, 2.0, 7)
    np.testing.assert_allclose(law_derivative(partial, x, 1), -(1.0 + 0.1 * np.cos(x)), atol=1e-15)
    np.testing.assert_allclose(law_derivative(partial, x, 2), 0.1 * np.sin(x), atol=1e-8)
    np.testing.assert_allclose(law_derivative(partial, x, 3), 0.1 * np.cos(x), atol=1e-7)
    np.testing.assert_allclose(law_derivative(value_only, x, 1), -(1.0 + 0.1 * np.cos(x)), atol=1e-8)
    np.testing.assert_allclose(law_derivative(value_only, x, 2), 0.1 * np.sin(x), atol=1e-6)


@pytest.mark.parametrize(("text", "words"), [("x +* 2", "invalid formula"), ("x + tau", "unknown name 'tau'"),
                                             ("gamma(x)", "'gamma' is not allowed"),
                                             ("sin(x, x)", "takes one argument"), ("x < 1", "unsupported expression")])
def test_formula_errors_name_the_field(text, words):
    from fabricate.errors import SpecError
    from fabricate.gears.law import compile_formula

    with pytest.raises(SpecError, match=words) as info:
        compile_formula(text, "gear_pair.law")
    assert info.value.path == "gear_pair.law"
    assert str(info.value).startswith("gear_pair.law: ")


@pytest.mark.parametrize("e", [1.0, 1.5, -0.1])
def test_elliptic_law_rejects_eccentricity_outside_0_1(e):
    """An ellipse needs 0 <= e < 1 (e = 1 is a parabola: the pitch radius A (1 - e) would be zero)."""
    from fabricate.errors import SpecError
    from fabricate.gears.law import elliptic_law

    with pytest.raises(SpecError, match="0 <= e < 1") as info:
        elliptic_law(e)
    assert info.value.path == "gear_pair.eccentricity"


def test_samples_law_through_three_samples_is_the_parabola():
    """Three samples are enough: the not-a-knot cubic through three points is the parabola through them
    (closed form x_b = -x_a - 0.1 x_a^2 here)."""
    from fabricate.gears.law import samples_law

    xa = np.array([0.0, 0.5, 1.5])
    law = samples_law(xa, -xa - 0.1 * xa**2)
    x = np.linspace(0.0, 1.5, 7)
    np.testing.assert_allclose(law(x), -x - 0.1 * x**2, atol=1e-12)
    np.testing.assert_allclose(law(x, 1), -1.0 - 0.2 * x, atol=1e-12)


@pytest.mark.parametrize(("xa", "xb", "words"), [
    ([0.0, 1.0], [0.0, -1.0], "at least 3 samples"),
    ([0.0, 1.0, 2.0], [0.0, np.nan, -2.0], "finite"),
    ([0.0, np.inf, 2.0], [0.0, -1.0, -2.0], "finite"),
    ([0.0, 2.0, 1.0], [0.0, -1.0, -2.0], "increase strictly"),
    ([0.0, 1.0, 1.0, 2.0], [0.0, -1.0, -1.0, -2.0], "increase strictly"),
])
def test_samples_law_rejects_bad_samples_naming_the_field(xa, xb, words):
    from fabricate.errors import SpecError
    from fabricate.gears.law import samples_law

    with pytest.raises(SpecError, match=words) as info:
        samples_law(np.array(xa), np.array(xb), "gear_pair.law_samples_deg")
    assert info.value.path == "gear_pair.law_samples_deg"


def test_check_ratio_names_the_first_angle_where_the_law_fails():
    """-sqrt(1 - x) is real up to x = 1 rad: the error names the first grid angle past 1 rad (not the first
    angle of the grid)."""
    from fabricate.errors import SpecError
    from fabricate.gears.law import check_ratio

    x = np.linspace(0.0, 2.0, 41)  # step 0.05 rad
    with pytest.raises(SpecError, match="not finite") as info:
        check_ratio(FormulaLaw("sqrt(1 - x)"), x, "gear_pair.law")
    assert info.value.path == "gear_pair.law"
    assert f"x_a = {np.degrees(x[x > 1.0][0]):.3f} deg" in str(info.value)


def test_check_ratio_rejects_a_zero_ratio():
    """A driven gear that stands still (law = const, ratio exactly 0) is not a gear pair."""
    from fabricate.errors import SpecError
    from fabricate.gears.law import check_ratio

    with pytest.raises(SpecError, match=r"ratio -?0 <= 0"):
        check_ratio(FormulaLaw("0.5"), np.linspace(0.0, 1.0, 5))
    ok = check_ratio(FormulaLaw("0.5*x"), np.linspace(0.0, 1.0, 5))  # control: ratio 0.5 everywhere
    np.testing.assert_allclose(ok, 0.5, rtol=1e-15)


def test_check_ratio_names_the_angle_of_the_most_negative_ratio():
    """x_b = -(x + 2 cos x): ratio 1 - 2 sin x, most negative at the grid angle nearest pi/2 (not at the
    start of the grid); the error gives that ratio and angle and names the field."""
    from fabricate.errors import SpecError
    from fabricate.gears.law import check_ratio

    x = np.linspace(0.0, 3.0, 31)
    ratio = 1.0 - 2.0 * np.sin(x)
    worst = x[np.abs(x - np.pi / 2).argmin()]
    with pytest.raises(SpecError) as info:
        check_ratio(FormulaLaw("x + 2*cos(x)"), x, "gear_pair.law")
    assert info.value.path == "gear_pair.law"
    assert f"ratio {ratio.min():.4g} <= 0 at x_a = {np.degrees(worst):.3f} deg" in str(info.value)


# -- pitch curves against closed forms -------------------------------------------------------------
def test_constant_ratio_pitch_curves_are_the_two_circles():
    """x_b = -x_a / 2 on a 30 mm centre distance: pitch circles r_a = 10, r_b = 20 mm (a i / (1 + i), a / (1 + i),
    i = 0.5); arc length s = r_a (x - x_ref); perimeters 2 pi r; frames of a circle (tangent, outward radial
    normal, curvature 1 / r); gear a at polar angle -x, gear b at pi - law(x)."""
    from fabricate.gears.pitch import PitchCurves

    law = FormulaLaw("0.5*x")
    pitch = PitchCurves(law, 30.0, (0.0, 2 * np.pi), x_ref=0.3, periods=(2 * np.pi, 4 * np.pi), intervals=64)
    x = np.array([0.1, 0.3, 1.0, 2.5, 6.0])
    np.testing.assert_allclose(pitch.ratio(x), 0.5, rtol=1e-12)
    np.testing.assert_allclose(pitch.speed(x), 10.0, rtol=1e-12)
    np.testing.assert_allclose(pitch.s_of_x(x), 10.0 * (x - 0.3), atol=1e-9)
    s = np.array([-3.0, 0.0, 7.0, 50.0])
    np.testing.assert_allclose(pitch.x_of_s(s), 0.3 + s / 10.0, atol=1e-9)
    assert pitch.perimeter_a == pytest.approx(20 * np.pi, rel=1e-12)
    assert pitch.perimeter_b == pytest.approx(40 * np.pi, rel=1e-12)
    np.testing.assert_allclose(pitch.wrap(np.array([-1.0, 70.0, 130.0]), "a"), np.mod([-1.0, 70.0, 130.0], 20 * np.pi))
    np.testing.assert_allclose(pitch.wrap(np.array([-1.0, 70.0, 130.0]), "b"), np.mod([-1.0, 70.0, 130.0], 40 * np.pi))
    np.testing.assert_allclose(pitch.curve(x, "a"), 10.0 * np.column_stack([np.cos(x), -np.sin(x)]), atol=1e-12)
    np.testing.assert_allclose(pitch.curve(x, "b"), -20.0 * np.column_stack([np.cos(x / 2), np.sin(x / 2)]), atol=1e-12)
    r, dr, ddr, th, dth = pitch.radii(x, "b")
    np.testing.assert_allclose([r, dr, ddr], [np.full(5, 20.0), np.zeros(5), np.zeros(5)], atol=1e-9)
    np.testing.assert_allclose(th, np.pi + x / 2, atol=1e-12)
    np.testing.assert_allclose(dth, 0.5, rtol=1e-12)
    fa = pitch.frames(10.0 * (x - 0.3), "a")  # at the arc lengths of x
    np.testing.assert_allclose(fa.point, 10.0 * np.column_stack([np.cos(x), -np.sin(x)]), atol=1e-8)
    np.testing.assert_allclose(fa.tangent, np.column_stack([-np.sin(x), -np.cos(x)]), atol=1e-9)
    np.testing.assert_allclose(fa.normal, np.column_stack([np.cos(x), -np.sin(x)]), atol=1e-9)
    np.testing.assert_allclose(fa.curvature, 0.1, rtol=1e-9)
    fb = pitch.frames(10.0 * (x - 0.3), "b")
    np.testing.assert_allclose(fb.tangent, np.column_stack([np.sin(x / 2), -np.cos(x / 2)]), atol=1e-9)
    np.testing.assert_allclose(fb.normal, -np.column_stack([np.cos(x / 2), np.sin(x / 2)]), atol=1e-9)
    np.testing.assert_allclose(fb.curvature, 0.05, rtol=1e-9)
    # closed gears repeat after their own perimeter: one turn later on a, 40 pi mm later on b
    np.testing.assert_allclose(pitch.frames(10.0 * (x - 0.3) + 20 * np.pi, "a").point, fa.point, atol=1e-8)
    np.testing.assert_allclose(pitch.frames(10.0 * (x - 0.3) + 40 * np.pi, "b").point, fb.point, atol=1e-8)
    # a pair whose gear b is the smaller (ratio 2, r_a = 20, r_b = 10 mm): gear a's arc length wraps at its own
    # perimeter 40 pi, not at gear b's 20 pi
    small_b = PitchCurves(FormulaLaw("2*x"), 30.0, (0.0, 2 * np.pi), periods=(2 * np.pi, np.pi), intervals=64)
    assert (small_b.perimeter_a, small_b.perimeter_b) == pytest.approx((40 * np.pi, 20 * np.pi), rel=1e-12)
    s_far = np.array([20 * np.pi + 5.0, 30 * np.pi])
    np.testing.assert_allclose(small_b.frames(s_far, "a").point,
                               20.0 * np.column_stack([np.cos(s_far / 20), -np.sin(s_far / 20)]), atol=1e-8)
    # by default arc length counts from x = 0
    default = PitchCurves(law, 30.0, (0.0, 2 * np.pi), intervals=64)
    np.testing.assert_allclose(default.s_of_x(np.array([0.0, 1.0])), [0.0, 10.0], atol=1e-9)
    assert len(default.nodes) == 65  # 64 intervals asked for


def test_pitch_curves_reject_a_law_that_reverses_inside_the_domain():
    """x_b = -(x - 0.012 tanh((x - 1.3) / 0.01)): ratio 1 - 1.2 sech^2((x - 1.3) / 0.01), negative only for
    |x - 1.3| < 0.0044 rad, positive at both ends of the domain: the construction check (a grid of
    4 x 512 + 1 angles, step 0.0015 rad) must find it."""
    from fabricate.errors import SpecError
    from fabricate.gears.pitch import PitchCurves

    law = FormulaLaw("x - 0.012*tanh((x - 1.3)/0.01)")
    with pytest.raises(SpecError, match="ratio"):
        PitchCurves(law, 30.0, (0.0, 3.0), intervals=512)
    PitchCurves(FormulaLaw("x - 0.008*tanh((x - 1.3)/0.01)"), 30.0, (0.0, 3.0), intervals=512)  # 1 - 0.8 sech^2 > 0


def test_elliptic_pitch_curve_radius_derivatives_arc_length_and_curvature():
    """The 1:1 elliptic pair (e = 0.3, a = 30 mm): gear a is the ellipse r = p / (1 + e cos x) about its focus
    (p = A (1 - e^2), A = a / 2) at polar angle -x, gear b the same rolled: r_b = a - r_a. Radius derivatives
    against the closed form, arc length against quadrature of sqrt(r^2 + r'^2), curvature against the polar
    formula (r^2 + 2 r'^2 - r r'') / (r^2 + r'^2)^1.5, perimeter against 4 A E(e^2)."""
    from scipy.integrate import quad
    from scipy.special import ellipe

    from fabricate.gears.law import elliptic_law
    from fabricate.gears.pitch import PitchCurves

    e, a = 0.3, 30.0
    big_a = a / 2
    p = big_a * (1 - e * e)
    pitch = PitchCurves(elliptic_law(e), a, (0.0, 2 * np.pi), x_ref=0.5, periods=(2 * np.pi, 2 * np.pi), intervals=256)
    x = np.array([0.0, 0.7, 2.0, 3.5, 5.9])
    d = 1 + e * np.cos(x)
    r = p / d
    dr = p * e * np.sin(x) / d**2
    ddr = p * e * np.cos(x) / d**2 + 2 * p * e**2 * np.sin(x) ** 2 / d**3
    ra, dra, ddra, tha, dtha = pitch.radii(x, "a")
    np.testing.assert_allclose(ra, r, rtol=1e-12)
    np.testing.assert_allclose(dra, dr, atol=1e-9)
    np.testing.assert_allclose(ddra, ddr, rtol=1e-5)  # law''' by central differences (h = 1e-3)
    np.testing.assert_allclose(tha, -x, atol=0)
    np.testing.assert_allclose(dtha, -1.0, atol=0)
    assert np.shape(dtha) == x.shape  # documented (n,) arrays, not a broadcast scalar
    rb, drb, ddrb, _, _ = pitch.radii(x, "b")
    np.testing.assert_allclose([rb, drb, ddrb], [a - r, -dr, -ddr], rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(pitch.speed(x), np.hypot(r, dr), rtol=1e-8)  # law'' by central differences
    for xi in (0.0, 2.0, 5.9):
        want = quad(lambda t: np.hypot(p / (1 + e * np.cos(t)), p * e * np.sin(t) / (1 + e * np.cos(t)) ** 2),
                    0.5, xi, epsabs=1e-12, epsrel=1e-12)[0]
        assert pitch.s_of_x(np.array([xi]))[0] == pytest.approx(want, abs=1e-7)  # speed within 1e-8
    assert pitch.perimeter_a == pytest.approx(4 * big_a * ellipe(e * e), rel=1e-10)
    # a little before the domain (extrapolated from its first node) and for a scalar angle
    before = quad(lambda t: np.hypot(p / (1 + e * np.cos(t)), p * e * np.sin(t) / (1 + e * np.cos(t)) ** 2),
                  0.5, -0.05, epsabs=1e-12, epsrel=1e-12)[0]
    assert pitch.s_of_x(np.array([-0.05]))[0] == pytest.approx(before, abs=1e-7)
    assert pitch.s_of_x(0.7) == pytest.approx(pitch.s_of_x(np.array([0.7]))[0], abs=1e-12)
    sector = PitchCurves(elliptic_law(e), a, (0.0, 2.0), intervals=16)  # no periods: a sector
    assert np.isnan(sector.perimeter_a) and np.isnan(sector.perimeter_b)
    kappa = (r**2 + 2 * dr**2 - r * ddr) / (r**2 + dr**2) ** 1.5
    np.testing.assert_allclose(pitch.frames_at_x(x, "a").curvature, kappa, rtol=1e-6)
    # gear b: r_b = a - r_a at polar angle pi - law(x), turning at i = (1 - e^2) / (1 + e^2 + 2 e cos x)
    q = 1 + e * e + 2 * e * np.cos(x)
    i, di = (1 - e * e) / q, (1 - e * e) * 2 * e * np.sin(x) / q**2
    rb, drb, ddrb = a - r, -dr, -ddr
    r_t, r_tt = drb / i, (ddrb * i - drb * di) / i**3  # derivatives by the polar angle
    kappa_b = (rb**2 + 2 * r_t**2 - rb * r_tt) / (rb**2 + r_t**2) ** 1.5
    np.testing.assert_allclose(pitch.frames_at_x(x, "b").curvature, kappa_b, rtol=1e-6)
    # the two frames at one contact: tangents opposite in the world (rolling), points a apart
    s = pitch.s_of_x(x)
    np.testing.assert_allclose(pitch.x_of_s(s), x, atol=1e-12)
    np.testing.assert_allclose(np.hypot(*pitch.frames(s, "a").point.T) + np.hypot(*pitch.frames(s, "b").point.T),
                               a, atol=1e-9)


# -- gear checks without booleans: curvature, undercut, feasibility, contact ratio, pressure angle --------
class _Curvatures:
    """Stands in for PitchCurves where only the curvature of each gear's pitch curve is read."""

    def __init__(self, a, b):
        self.k = {"a": np.asarray(a, dtype=float), "b": np.asarray(b, dtype=float)}

    def frames_at_x(self, x, gear):
        from types import SimpleNamespace

        return SimpleNamespace(curvature=self.k[gear])


def test_curvature_summary_of_convex_and_concave_stretches():
    """Smallest convex radius = 1 / largest positive curvature, smallest concave radius = 1 / largest negative
    curvature magnitude, inf where there is none."""
    from fabricate.gears.checks import curvature_summary

    out = curvature_summary(_Curvatures([0.1, 0.2, -0.05, -0.25], [0.05, 0.04]), np.zeros(2))
    assert out == {"min_radius_of_curvature_a_mm": pytest.approx(5.0), "min_curvature_a_per_mm": -0.25,
                   "min_concave_radius_a_mm": pytest.approx(4.0),
                   "min_radius_of_curvature_b_mm": pytest.approx(20.0), "min_curvature_b_per_mm": 0.04,
                   "min_concave_radius_b_mm": np.inf}
    flat = curvature_summary(_Curvatures([0.0, -0.1], [0.0, 0.0]), np.zeros(2))
    assert flat["min_radius_of_curvature_a_mm"] == np.inf and flat["min_concave_radius_a_mm"] == pytest.approx(10.0)
    assert flat["min_radius_of_curvature_b_mm"] == np.inf and flat["min_concave_radius_b_mm"] == np.inf


def test_undercut_limit_is_the_classical_one():
    """Standard rack (h_f = 1.25 m, rho_f = 0.38 m, 20 deg): straight flank depth 1.25 - 0.38 (1 - sin 20) = 1.0 m,
    limit 1.0 m / sin^2(20 deg) = 8.55 m (z_min = 17.1 teeth)."""
    from fabricate.gears.checks import undercut_limit_mm
    from fabricate.gears.spec import GearSpec

    s = np.sin(np.radians(20.0))
    for m in (0.5, 1.0, 2.0):
        assert undercut_limit_mm(m, GearSpec()) == pytest.approx((1.25 - 0.38 * (1 - s)) * m / s**2, rel=1e-12)
    spec = GearSpec(pressure_angle_deg=25.0, dedendum=1.2, root_fillet=0.3)
    s25 = np.sin(np.radians(25.0))
    assert undercut_limit_mm(1.5, spec) == pytest.approx((1.2 - 0.3 * (1 - s25)) * 1.5 / s25**2, rel=1e-12)


def test_feasibility_limits_at_their_boundaries():
    """Module limit 2 rho / min_teeth (rho = 8 mm, 8 teeth: 2 mm) and concave radius limit 2 h_f m (2 mm module:
    5 mm): just inside passes, just outside raises naming the field and the largest module."""
    from fabricate.errors import SpecError
    from fabricate.gears.checks import check_feasible
    from fabricate.gears.spec import GearSpec

    spec = GearSpec()

    def curv(rho_a, rho_b, concave_a=np.inf, concave_b=np.inf):
        return {"min_radius_of_curvature_a_mm": rho_a, "min_radius_of_curvature_b_mm": rho_b,
                "min_concave_radius_a_mm": concave_a, "min_concave_radius_b_mm": concave_b}

    check_feasible(curv(8.0, 30.0), 2.0, spec)  # exactly 8 teeth on the osculating circle
    check_feasible(curv(30.0, 8.0), 1.999, spec)
    with pytest.raises(SpecError, match=r"needs module <= 2 mm") as info:
        check_feasible(curv(30.0, 8.0), 2.001, spec, "gear_pair.module_mm")
    assert info.value.path == "gear_pair.module_mm"
    assert "holds 7.996 teeth" not in str(info.value) and "holds 8.0 teeth (min_teeth = 8)" in str(info.value)
    check_feasible(curv(30.0, 30.0, 5.0, 9.0), 2.0, spec)  # concave radius exactly 2 h_f m (module 2)
    with pytest.raises(SpecError, match=r"concave with radius 4.9 mm; needs module <= 1.96 mm") as info:
        check_feasible(curv(30.0, 30.0, 9.0, 4.9), 2.0, spec)
    assert info.value.path == "gears.module_mm"


def test_contact_ratio_of_spur_gears_and_of_the_rack_limit():
    """Pitch circles 10 and 20 mm, module 2: the spur contact ratio
    (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin alpha) / (pi m cos alpha) with the addendum h_a = m; a
    flat or concave curve (curvature up to 1e-9 /mm) counts as a rack (addendum / sin alpha)."""
    from fabricate.gears.checks import local_contact_ratio
    from fabricate.gears.spec import GearSpec

    alpha = np.radians(20.0)
    m, ha = 2.0, 2.0

    def path(r):
        return np.sqrt((r + ha) ** 2 - (r * np.cos(alpha)) ** 2)

    spur = (path(10.0) + path(20.0) - 30.0 * np.sin(alpha)) / (np.pi * m * np.cos(alpha))
    got = local_contact_ratio(_Curvatures([0.1, 0.1], [0.05, 0.05]), np.zeros(2), m, GearSpec())
    np.testing.assert_allclose(got, spur, rtol=1e-12)
    rack = ha / np.sin(alpha)
    got = local_contact_ratio(_Curvatures([0.0, -0.2], [0.05, 1e-9]), np.zeros(2), m, GearSpec())
    want = [(rack + path(20.0) - 20.0 * np.sin(alpha)), 2 * rack]
    np.testing.assert_allclose(got, np.array(want) / (np.pi * m * np.cos(alpha)), rtol=1e-12)


def test_working_pressure_angles_of_the_elliptic_pair():
    """The ellipse's pitch tangent leans by mu = atan(e sin x / (1 + e cos x)) from the perpendicular to the
    line of centres (the polar tangent angle of r = p / (1 + e cos x)): the flanks work at 20 deg -/+ mu, the
    driving flank at 20 - mu (ranges over x); for circles (e = 0) both at exactly 20 deg."""
    from fabricate.gears.checks import pressure_angle_range_deg
    from fabricate.gears.law import elliptic_law
    from fabricate.gears.pitch import PitchCurves
    from fabricate.gears.spec import GearSpec

    x = np.array([0.0, 0.8, 2.0, 4.0])
    for e in (0.0, 0.3):
        pitch = PitchCurves(elliptic_law(e), 30.0, (0.0, 2 * np.pi), intervals=16)
        mu = np.degrees(np.arctan(e * np.sin(x) / (1 + e * np.cos(x))))
        out = pressure_angle_range_deg(pitch, x, GearSpec())
        drive, coast = np.abs(20.0 - mu), np.abs(20.0 + mu)
        # law'' by central differences: 1e-6 deg
        assert out["drive_flank_deg"] == pytest.approx([drive.min(), drive.max()], abs=1e-6)
        assert out["coast_flank_deg"] == pytest.approx([coast.min(), coast.max()], abs=1e-6)


# -- the basic rack and the envelope mappings against their geometry ---------------------------------
def test_basic_rack_is_flat_round_and_straight_flank():
    """Module 2, 20 deg, h_f = 1.25 m, rho_f = 0.38 m: the root flat on v = -h_f, the round at distance rho_f
    from its centre and tangent to both the flat and the flank line u = -p/4 + v tan(alpha), the flank
    points on that line up to v = (h_a + 0.02) m with the normal (-cos, sin); the right half the mirror
    image; gear b's cutter the reflection across the pitch line."""
    from fabricate.gears.rack import FLANK, FLAT_ROOT_A, ROUND_ROOT_A, basic_rack

    m, alpha, hf, rho = 2.0, np.radians(20.0), 2.5, 0.76
    p = np.pi * m
    rack = basic_rack(m, alpha, 1.25, 0.38, addendum=1.0, flank_points=11, round_points=7, flat_points=3)
    pts, nrm, el = rack.points, rack.normals, rack.element
    assert rack.pitch == pytest.approx(p)
    assert np.all(np.diff(pts[:, 0]) > 0)  # in order of increasing u
    np.testing.assert_allclose(np.hypot(*nrm.T), 1.0, rtol=1e-12)
    left = pts[:, 0] < 0
    assert pts[0, 0] == pytest.approx(-p / 2)
    flat = el == FLAT_ROOT_A
    np.testing.assert_allclose(pts[flat, 1], -hf, atol=1e-12)
    np.testing.assert_allclose(nrm[flat], [[0.0, 1.0]] * int(flat.sum()), atol=1e-12)
    # the round's centre: rho above the root, rho from the flank line on the tooth-space side
    cv = -hf + rho
    cu = -p / 4 + cv * np.tan(alpha) - rho / np.cos(alpha)
    rnd = (el == ROUND_ROOT_A) & left
    assert rnd.sum() == 7
    np.testing.assert_allclose(np.hypot(pts[rnd, 0] - cu, pts[rnd, 1] - cv), rho, rtol=1e-12)
    np.testing.assert_allclose(nrm[rnd], -(pts[rnd] - [cu, cv]) / rho, atol=1e-12)
    assert pts[rnd][0] == pytest.approx([cu, -hf])  # starts where the flat ends (tangent)
    fl = (el == FLANK) & left
    assert fl.sum() == 11
    line_u = -p / 4 + pts[fl, 1] * np.tan(alpha)
    np.testing.assert_allclose(pts[fl, 0], line_u, atol=1e-12)
    np.testing.assert_allclose(nrm[fl], [[-np.cos(alpha), np.sin(alpha)]] * 11, atol=1e-12)
    assert pts[fl, 1].max() == pytest.approx(1.02 * m)
    assert pts[fl, 1].min() == pytest.approx(cv - rho * np.sin(alpha))  # tangent point of the round
    np.testing.assert_allclose(rack.flank_u[fl], -p / 4)
    np.testing.assert_allclose(rack.flank_u[(el == FLANK) & ~left], p / 4)
    assert np.all(np.isnan(rack.flank_u[el != FLANK]))
    # mirror symmetry: (u, v) -> (-u, v) maps the profile onto itself, normals likewise (the period is
    # [-p/2, p/2): the first point's mirror image is the next period's first point)
    np.testing.assert_allclose(pts[1:][::-1] * [-1, 1], pts[1:], atol=1e-12)
    np.testing.assert_allclose(nrm[1:][::-1] * [-1, 1], nrm[1:], atol=1e-12)
    np.testing.assert_array_equal(el[1:][::-1], el[1:])
    b = rack.for_gear_b()
    np.testing.assert_allclose(b.points, pts * [1, -1])
    np.testing.assert_allclose(b.normals, nrm * [-1, 1])
    np.testing.assert_array_equal(b.element, el)
    assert b.pitch == rack.pitch
    np.testing.assert_array_equal(b.flank_u, rack.flank_u)
    no_round = basic_rack(m, alpha, 1.25, 0.0, flank_points=5, round_points=7, flat_points=3)
    assert not np.any(no_round.element == ROUND_ROOT_A)
    with pytest.raises(ValueError, match="root fillet too large"):
        basic_rack(m, alpha, 1.25, 1.25)


@pytest.mark.parametrize("deg", [14.5, 20.0, 25.0, 30.0])
def test_rack_fit_leaves_the_minimum_root_land(deg):
    """The deepest dedendum leaves a 0.02 m half land at the tooth space centre: (pi/4 - 0.02) / tan(alpha);
    the largest fillet for a dedendum puts the round's end 0.02 m from the half period (centre geometry as in
    the previous test), and never exceeds the dedendum."""
    from fabricate.gears.rack import MIN_ROOT_LAND, rack_fit

    alpha = np.radians(deg)
    max_hf, _ = rack_fit(alpha, 10.0)
    assert max_hf == pytest.approx((np.pi / 4 - MIN_ROOT_LAND) / np.tan(alpha), rel=1e-12)
    for hf in (0.6, 1.0, 1.25, 10.0):
        got_max, rho = rack_fit(alpha, hf)
        assert got_max == max_hf
        h = min(hf, max_hf)
        centre_u = -np.pi / 4 + (rho - h) * np.tan(alpha) - rho / np.cos(alpha)  # module 1
        if 0.0 < rho < h:
            assert centre_u + np.pi / 2 == pytest.approx(MIN_ROOT_LAND, abs=1e-12)
        else:
            assert rho in (0.0, h)
            assert centre_u + np.pi / 2 >= MIN_ROOT_LAND - 1e-12
    assert rack_fit(np.radians(20.0), 1.25)[1] > 0.38  # the standard 0.38 m fillet fits the standard rack
    assert rack_fit(np.radians(20.0), 0.1)[1] == pytest.approx(0.1)  # capped by a shallow root


def test_offset_contact_abscissa_and_envelope_mapping():
    """Offset thins the gear named (a: against the normal, b: along it); the contact abscissa is where the
    point's normal line meets the pitch line v = 0; the envelope places (u, v) at P + (u - s) t +/- v n."""
    from fabricate.gears.pitch import PitchFrames
    from fabricate.gears.rack import contact_abscissa, envelope, offset_profile

    pts = np.array([[0.3, -0.5], [1.0, 0.8], [-2.0, 0.2]])
    ang = np.radians([70.0, 110.0, 45.0])
    nrm = np.column_stack([np.cos(ang), np.sin(ang)])
    np.testing.assert_allclose(offset_profile(pts, nrm, 0.1, "a"), pts - 0.1 * nrm)
    np.testing.assert_allclose(offset_profile(pts, nrm, 0.1, "b"), pts + 0.1 * nrm)
    s = contact_abscissa(pts, nrm)
    t = -pts[:, 1] / nrm[:, 1]  # parameter along the normal where v = 0
    np.testing.assert_allclose(s, pts[:, 0] + t * nrm[:, 0], atol=1e-12)
    frames = PitchFrames(point=np.array([[1.0, 2.0]] * 3), tangent=np.array([[0.6, 0.8]] * 3),
                         normal=np.array([[-0.8, 0.6]] * 3), curvature=np.zeros(3))
    got_a, got_b = envelope(pts, s, frames, "a"), envelope(pts, s, frames, "b")
    for i in range(3):
        along = (pts[i, 0] - s[i]) * np.array([0.6, 0.8])
        np.testing.assert_allclose(got_a[i], [1.0, 2.0] + along + pts[i, 1] * np.array([-0.8, 0.6]), atol=1e-12)
        np.testing.assert_allclose(got_b[i], [1.0, 2.0] + along - pts[i, 1] * np.array([-0.8, 0.6]), atol=1e-12)


@pytest.mark.parametrize("radius", [12.0, -30.0, np.inf])
def test_osculating_frames_of_a_circle_are_the_circle(radius):
    """For a pitch circle of radius R (gear a: clockwise travel, outward normal; R < 0 concave, R = inf a
    straight line) the osculating frames at arc sigma from the tooth centre are the exact frames there,
    for tiny sigma (series branch) and large ones."""
    from fabricate.gears.pitch import PitchFrames
    from fabricate.gears.rack import osculating_frames

    k = 0.0 if np.isinf(radius) else 1.0 / radius
    phi = 0.7
    sigma = np.array([-5.0, -1e-9, 0.0, 3e-8, 2.0, 9.0])
    n = len(sigma)
    n0 = np.array([np.cos(phi), np.sin(phi)])
    t0 = np.array([np.sin(phi), -np.cos(phi)])
    p0 = np.array([4.0, -1.0])
    centre = PitchFrames(np.tile(p0, (n, 1)), np.tile(t0, (n, 1)), np.tile(n0, (n, 1)), np.full(n, k))
    got = osculating_frames(sigma + 10.0, np.full(n, 10.0), centre)
    # exact: turn by k sigma about the centre of curvature p0 - n0 / k (clockwise for k > 0)
    turn = k * sigma
    if k == 0.0:
        want_p = p0 + sigma[:, None] * t0
    else:
        c0 = p0 - n0 / k
        want_p = c0 + (np.cos(turn)[:, None] * n0 + np.sin(turn)[:, None] * t0) / k
    want_n = np.cos(turn)[:, None] * n0 + np.sin(turn)[:, None] * t0
    want_t = np.cos(turn)[:, None] * t0 - np.sin(turn)[:, None] * n0
    np.testing.assert_allclose(got.point, want_p, atol=1e-12)
    np.testing.assert_allclose(got.normal, want_n, atol=1e-15)
    np.testing.assert_allclose(got.tangent, want_t, atol=1e-15)
    np.testing.assert_array_equal(got.curvature, np.full(n, k))


# -- the mesh check's parts against closed forms and independent booleans ----------------------------------
def test_mesh_summary_of_given_arrays():
    """The summary of hand-made arrays: ranges over the steps with a contact pair, NaN steps counted, the
    TE the largest magnitude in degrees, the measured contact ratio the mean teeth in contact."""
    from fabricate.gears.pair import MeshResult

    nan = np.nan
    r = MeshResult(x_a=np.array([0.0, 0.1, 0.2, 0.3]), free_plus=np.array([0.01, nan, 0.02, 0.015]),
                   free_minus=np.array([0.02, nan, 0.01, 0.0]), backlash_mm=np.array([0.3, nan, 0.36, 0.15]),
                   transmission_error=np.array([-0.002, nan, 0.001, 0.0]),
                   contact_lag=np.array([0.01, nan, 0.02, 0.015]),
                   interference_area_mm2=np.array([0.0, 0.5, 0.0, 0.25]), teeth_in_contact=np.array([1, 0, 2, 2]))
    assert r.steps == 4
    assert r.summary() == {
        "steps": 4, "interference_area_mm2": 0.5, "backlash_mm": [0.15, 0.36],
        "transmission_error_deg": pytest.approx(np.degrees(0.002)),
        "contact_lag_deg": [pytest.approx(np.degrees(0.01)), pytest.approx(np.degrees(0.02))],
        "steps_without_contact_pair": 1, "teeth_in_contact": [0, 2], "contact_ratio_measured": 1.25}
    empty = MeshResult(x_a=np.zeros(2), free_plus=np.full(2, nan), free_minus=np.full(2, nan),
                       backlash_mm=np.full(2, nan), transmission_error=np.full(2, nan), contact_lag=np.full(2, nan),
                       interference_area_mm2=np.zeros(2))
    assert empty.summary() == {"steps": 2, "interference_area_mm2": 0.0, "backlash_mm": [None, None],
                               "transmission_error_deg": None, "contact_lag_deg": [None, None],
                               "steps_without_contact_pair": 2, "teeth_in_contact": None,
                               "contact_ratio_measured": None}


def test_designed_lag_on_both_flanks_of_the_elliptic_pair():
    """2 delta / d_B with delta = j cos(alpha) / 4 and d_B = r_b cos(alpha -/+ mu) (driving / coast flank),
    r_b = a - r_a and mu the ellipse's tangent lean (closed forms); for circles j / (2 r_b) on both."""
    from types import SimpleNamespace

    from fabricate.gears.law import elliptic_law
    from fabricate.gears.mesh import designed_lag
    from fabricate.gears.pitch import PitchCurves
    from fabricate.gears.spec import GearSpec

    x = np.array([0.0, 0.8, 2.0, 4.0])
    alpha, j, a = np.radians(20.0), 0.12, 30.0
    for e in (0.0, 0.3):
        pair = SimpleNamespace(spec=GearSpec(backlash_mm=j),
                               pitch_model=PitchCurves(elliptic_law(e), a, (0.0, 2 * np.pi), intervals=16))
        r_b = a - (a / 2) * (1 - e * e) / (1 + e * np.cos(x))
        mu = np.arctan(e * np.sin(x) / (1 + e * np.cos(x)))
        delta = j * np.cos(alpha) / 4
        left, right = designed_lag(pair, x)
        np.testing.assert_allclose(left, 2 * delta / (r_b * np.cos(alpha - mu)), rtol=1e-8)
        np.testing.assert_allclose(right, 2 * delta / (r_b * np.cos(alpha + mu)), rtol=1e-8)
        if e == 0.0:
            np.testing.assert_allclose(left, j / (2 * 15.0), rtol=1e-12)


def test_spur_mesh_contact_ratio_and_free_play_from_outlines():
    """Equal 24-tooth spur gears, module 1: the measured teeth in contact average the contact ratio
    (2 sqrt(r_a^2 - r_b^2) - a sin alpha) / (pi m cos alpha) = 1.602 (within one step of the 30 per tooth);
    the free play found by bisection on booleans of the outlines alone (an independent method) is the
    designed j / (2 r) each way within the outlines' chord error; the steps cover one turn of each gear."""
    from fabricate.gears.mesh import free_play_outlines

    pair = spur_pair()
    mesh = pair.mesh
    alpha = np.radians(20.0)
    ratio = (2 * np.sqrt(13.0**2 - (12.0 * np.cos(alpha)) ** 2) - 24.0 * np.sin(alpha)) / (np.pi * np.cos(alpha))
    assert np.mean(mesh.teeth_in_contact) == pytest.approx(ratio, abs=1 / 30)
    assert set(np.unique(mesh.teeth_in_contact)) == {1, 2}
    np.testing.assert_allclose(mesh.x_a, np.linspace(0.0, 2 * np.pi, 720, endpoint=False), atol=1e-12)
    np.testing.assert_array_equal(mesh.contact_lag, mesh.free_plus)
    x = np.array([0.05, 0.3, 1.0])
    plus, minus = free_play_outlines(pair.outline_a, pair.outline_b, pair.law, pair.center_distance_mm, x, pair.module)
    np.testing.assert_allclose(plus, 0.1 / 24.0, atol=2.5e-4)
    np.testing.assert_allclose(minus, 0.1 / 24.0, atol=2.5e-4)


def test_interference_area_against_the_whole_outlines():
    """Centres 0.4 mm too close: the clipped, shifted booleans give the area of the intersection of the whole
    posed outlines (shapely on raw coordinates); at the design distance there is none."""
    from dataclasses import replace

    from fabricate.gears.mesh import interference_areas

    pair = spur_pair()
    x = np.array([0.0, 0.11, 0.7])
    np.testing.assert_array_equal(interference_areas(pair, x), 0.0)
    close = replace(pair, center_distance_mm=pair.center_distance_mm - 0.4)
    got = interference_areas(close, x)

    def posed(outline, angle, dx):
        c, s = np.cos(angle), np.sin(angle)
        pts = np.asarray(outline)
        return Polygon(np.column_stack([c * pts[:, 0] - s * pts[:, 1] + dx, s * pts[:, 0] + c * pts[:, 1]]))

    want = [posed(pair.outline_a, xi, 0.0).intersection(posed(pair.outline_b, float(pair.law(xi)),
                                                                close.center_distance_mm)).area for xi in x]
    assert min(want) > 0.05
    np.testing.assert_allclose(got, want, rtol=1e-9)


@pytest.mark.parametrize(("shift", "words"), [(0.25, "outside 0.05..0.2 mm"), (-0.1, "outside 0.05..0.2 mm"),
                                              (-0.2, "backlash closes")])
def test_gear_mesh_check_judges_the_backlash_band(shift, words):
    """Centres moved apart by 0.25 mm or together by 0.1 mm: the involute backlash changes by about
    2 shift tan(20 deg) (0.282 or 0.027 mm), outside 0.5..2 x the designed 0.1 mm; 0.2 mm together closes it
    and the teeth overlap (reported at the input of the largest overlap); 0.05 mm together stays inside."""
    from dataclasses import replace

    from fabricate.checks.gear_mesh import check_gear_mesh, check_gear_meshes

    x = np.linspace(0.2, 0.6, 9)
    pair = replace(spur_pair(), carrier="carrier", center_distance_mm=24.0 + shift)
    result = check_gear_mesh(pair, fake_motion(x, np.asarray(pair.law(x))))
    assert [f for f in result.failures if words in f]
    expected = 0.1 + 2 * shift * np.tan(np.radians(20.0))
    if expected > 0:
        assert result.backlash_mm[0] == pytest.approx(expected, abs=0.01)
        assert result.interference_area_mm2 == 0.0
    else:
        assert result.interference_area_mm2 > 1e-3
        mesh = [f for f in result.failures if "teeth overlap" in f]
        assert len(mesh) == 1 and f"{result.interference_area_mm2:.3g} mm^2 at input" in mesh[0]
    assert result.report()["passed"] is False and not result.passed
    fine = replace(spur_pair(), carrier="carrier", center_distance_mm=24.0 - 0.05)
    ok = check_gear_meshes([fine], fake_motion(x, np.asarray(fine.law(x))))
    assert len(ok) == 1 and ok[0].failures == () and ok[0].passed
    assert ok[0].backlash_mm[0] == pytest.approx(0.1 - 0.1 * np.tan(np.radians(20.0)), abs=0.01)
    report = ok[0].report()
    assert report["steps"] == 9 and report["passed"] is True and report["name"] == fine.name
    assert report["backlash_allowed_mm"] == [0.05, 0.2]


def test_gear_mesh_check_tolerances_at_their_boundaries():
    """The law may be missed by 1e-6 rad (the solver's tolerance), no more; a sector may be left by 1e-9 rad, no
    more; poses past the sector's teeth are counted as out of mesh, named by the first such input."""
    from dataclasses import replace

    from fabricate.checks.gear_mesh import check_gear_mesh

    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.2, 0.4, 5)
    law = np.asarray(pair.law(x))
    assert check_gear_mesh(pair, fake_motion(x, law + 0.9e-6)).failures == ()
    off = check_gear_mesh(pair, fake_motion(x, law + 1.1e-6))
    assert len(off.failures) == 1 and "departs from the gear law" in off.failures[0]
    sector = replace(sector_pair(), carrier="carrier")
    lo, hi = sector.working_range
    for past, reported in ((0.5e-9, False), (2e-9, True)):
        x = np.linspace(lo, hi + past, 5)
        res = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
        assert any("outside the cut range" in f for f in res.failures) == reported
        x = np.linspace(lo - past, hi, 5)
        res = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
        assert any("outside the cut range" in f for f in res.failures) == reported
    x = np.linspace(hi - 0.05, hi + 0.6, 14)
    far = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
    out = [f for f in far.failures if "no flank pair in mesh" in f]
    assert len(out) == 1 and far.steps_without_contact > 0
    first = int(np.argmax(~np.isfinite(mesh_free(sector, x))))
    assert f"at {far.steps_without_contact} pose(s), first at input {np.degrees(x[first]):g} deg" in out[0]
    assert far.report()["steps_without_contact"] == far.steps_without_contact


def mesh_free(pair, x):
    from fabricate.gears.mesh import free_play

    plus, minus = free_play(pair, x)
    return plus + minus


@pytest.mark.parametrize("k", [1e-9, -1e-9])
def test_osculating_frames_of_a_nearly_straight_pitch_curve(k):
    """Curvature 1e-9 /mm over +-500 mm (k sigma <= 1e-6: the series branch): the point is
    P + sin(k s) / k t - 2 sin^2(k s / 2) / k n (the circle, written without cancellation), the bend
    k s^2 / 2 ~ 1e-4 mm must come out right to 1e-12 mm."""
    from fabricate.gears.pitch import PitchFrames
    from fabricate.gears.rack import osculating_frames

    sigma = np.array([-500.0, -120.0, 0.0, 3.0, 250.0, 500.0])
    n = len(sigma)
    t0, n0, p0 = np.array([0.6, -0.8]), np.array([0.8, 0.6]), np.array([3.0, 4.0])
    centre = PitchFrames(np.tile(p0, (n, 1)), np.tile(t0, (n, 1)), np.tile(n0, (n, 1)), np.full(n, k))
    got = osculating_frames(sigma, np.zeros(n), centre)
    along = np.sin(k * sigma) / k
    bend = 2 * np.sin(k * sigma / 2) ** 2 / k
    np.testing.assert_allclose(got.point, p0 + along[:, None] * t0 - bend[:, None] * n0, atol=1e-12, rtol=0)
    assert np.max(np.abs(bend)) > 1e-4  # the bend is there to be measured


def test_basic_rack_default_sampling():
    """Defaults as documented: addendum 1 m (flank sampled to 1.02 m), and per side 5 root-flat, 25 round and 241
    flank samples (the flank density keeps the envelope's chord error far below 1 um)."""
    from fabricate.gears.rack import FLANK, FLAT_ROOT_A, ROUND_ROOT_A, basic_rack

    rack = basic_rack(1.5, np.radians(20.0), 1.25, 0.38)
    left = rack.points[:, 0] < 0
    counts = [int(np.count_nonzero((rack.element == e) & left)) for e in (FLAT_ROOT_A, ROUND_ROOT_A, FLANK)]
    assert counts == [5, 25, 241]
    assert rack.points[:, 1].max() == pytest.approx(1.02 * 1.5)


def test_basic_rack_rejects_a_fillet_that_does_not_fit_either_way():
    """The root round must be smaller than the dedendum and its centre inside the tooth space: module 2, 20 deg,
    a 1.2 m round in a 1.25 m root has its centre beyond the half period (-p/2); a 0.5 m round in a 0.5 m root
    fits the space but is as deep as the root; 0.49 m in 0.5 m fits."""
    from fabricate.gears.rack import basic_rack

    alpha = np.radians(20.0)
    centre_u = -np.pi * 2 / 4 + ((2.4 - 2.5) * np.sin(alpha) - 2.4) / np.cos(alpha)
    assert centre_u < -np.pi * 2 / 2
    with pytest.raises(ValueError, match="root fillet too large"):
        basic_rack(2.0, alpha, 1.25, 1.2)
    with pytest.raises(ValueError, match="root fillet too large"):
        basic_rack(2.0, alpha, 0.5, 0.5)
    basic_rack(2.0, alpha, 0.5, 0.49, flank_points=5, round_points=5, flat_points=3)


# -- free play, contacts and the outline windows against closed forms and whole-outline booleans -----------------
@cache
def unequal_pair():
    """18/27 involute spur gears, module 1 (law x_b = -2 x_a / 3, r_a = 9, r_b = 13.5 mm)."""
    spec = GearSpec(teeth=(18, 27), module_mm=1.0, backlash_mm=0.1, compare_methods=False, mesh_steps=6)
    return make_gear_pair(FormulaLaw("2*x/3"), 22.5, (0.0, 2 * np.pi), spec, closed=True, run_mesh_check=False)


@cache
def module2_pair():
    """12-tooth spur gears of module 2 (r = 12 mm)."""
    spec = GearSpec(teeth=(12, 12), module_mm=2.0, backlash_mm=0.1, compare_methods=False, min_teeth=8)
    return make_gear_pair(FormulaLaw("x"), 24.0, (0.0, 2 * np.pi), spec, closed=True, run_mesh_check=False)


def posed_outline(outline, angle: float, dx: float = 0.0) -> Polygon:
    """The whole outline turned by ``angle`` about its axis, the axis moved to (dx, 0)."""
    c, s = np.cos(angle), np.sin(angle)
    pts = np.asarray(outline)
    return Polygon(np.column_stack([c * pts[:, 0] - s * pts[:, 1] + dx, s * pts[:, 0] + c * pts[:, 1]]))


def test_pad_flanks_puts_each_flank_in_the_row_of_its_key():
    """Flanks keyed 5, 3, 6 (4 missing, e.g. cut away): row = key - 3, the missing row all NaN and not present,
    shorter flanks NaN-padded to the longest."""
    from fabricate.gears.mesh import _pad_flanks

    f3, f5, f6 = np.array([[1.0, 2.0], [3.0, 4.0]]), np.full((3, 2), 5.0), np.array([[7.0, 8.0], [9.0, 0.5]])
    table, present, offset = _pad_flanks({5: f5, 3: f3, 6: f6})
    assert offset == 3 and table.shape == (4, 3, 2)
    np.testing.assert_array_equal(present, [True, False, True, True])
    np.testing.assert_array_equal(table[0, :2], f3)
    np.testing.assert_array_equal(table[2], f5)
    np.testing.assert_array_equal(table[3, :2], f6)
    assert np.isnan(table[1]).all() and np.isnan(table[0, 2]).all() and np.isnan(table[3, 2]).all()


def test_polar_tables_sort_each_flank_by_radius_with_unwrapped_angles():
    """Row 0: three points out of radius order whose angles cross +-pi; row 1 missing (all NaN); row 2 two points
    and padding. Keys radius + row * 1e6 ascending, angles continuous along the flank (3.0, 3.1, 3.2 rad, not
    wrapped to -3.08), padding NaN angles with keys above the row's radii, and each row's radius range
    (empty, [inf, -inf], for the missing row)."""
    from fabricate.gears.mesh import _polar_tables

    def polar(r, t):
        return [r * np.cos(t), r * np.sin(t)]

    nan = [np.nan, np.nan]
    table = np.array([[polar(5.0, 3.1), polar(4.0, 3.0), polar(6.0, 3.2)], [nan, nan, nan],
                      [polar(2.5, -0.2), polar(2.0, 0.1), nan]])
    key, phi, ranges = _polar_tables(table)
    key, phi = key.reshape(3, 3), phi.reshape(3, 3)
    np.testing.assert_allclose(key[0], [4.0, 5.0, 6.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(key[2, :2], [2e6 + 2.0, 2e6 + 2.5], rtol=0, atol=1e-9)
    assert np.all(np.diff(key.ravel()) >= 0)
    assert np.all((key[1] >= 1e6) & (key[1] < 2e6)) and 2e6 + 2.5 < key[2, 2] < 3e6
    np.testing.assert_allclose(phi[0], [3.0, 3.1, 3.2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(phi[2, :2], [0.1, -0.2], rtol=0, atol=1e-12)
    assert np.isnan(phi[1]).all() and np.isnan(phi[2, 2])
    np.testing.assert_allclose(ranges, [[4.0, 6.0], [np.inf, -np.inf], [2.0, 2.5]], rtol=0, atol=1e-12)


def test_window_chains_are_the_runs_of_a_polygon_within_the_angle():
    """A regular 12-gon (vertex k at k * 30 deg): each window is the run of consecutive vertices within the half
    angle of its centre, in ring order also across the ring's end, closed through the axis and padded with the
    axis to one length; one vertex, none, two across the end, all but one (the run skips it, not the whole
    ring)."""
    from fabricate.gears.mesh import _window_chains

    angles = np.arange(12) * np.pi / 6
    poly = 2.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    axis = [0.0, 0.0]

    def chain(run, width):
        return np.vstack([poly[run], np.tile(axis, (width - len(run), 1))])

    got = _window_chains(poly, np.array([np.pi / 2 + 0.05, -0.05, np.pi + np.pi / 12]), 0.8)
    want = [chain([2, 3, 4], 5), chain([11, 0, 1], 5), chain([5, 6, 7, 8], 5)]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    got = _window_chains(poly, np.array([angles[7] + 0.05, np.pi / 12, angles[9]]), 0.2)
    np.testing.assert_allclose(got, [chain([7], 2), chain([], 2), chain([9], 2)], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(_window_chains(poly, np.array([np.pi / 12]), 0.2), [[axis]])
    np.testing.assert_allclose(_window_chains(poly, np.array([-np.pi / 12]), 0.3), [chain([11, 0], 3)], atol=1e-12)
    got = _window_chains(poly, np.array([angles[5] - np.pi]), np.pi - 0.3)
    np.testing.assert_allclose(got, [chain([6, 7, 8, 9, 10, 11, 0, 1, 2, 3, 4], 12)], rtol=0, atol=1e-12)


@pytest.mark.parametrize("which", ["sector", "module 3", "1:2"])
def test_free_play_from_outlines_is_where_the_whole_outlines_touch(which):
    """free_play_outlines bisects on windows of the outlines (default bracket 0.02 rad, tolerance 1e-9 rad). The
    whole posed outlines (shapely, no windows) must be apart (overlap <= 1e-12 mm^2, its contact threshold) with
    gear b turned 0.999 of the returned play either way and overlap at 1.001 of it. Pairs: the non-circular
    sector (module 0.5), 12-tooth spur gears of module 3 (the windows scale with the module) and 12/24 spur
    gears (ratio 1/2); angles given as ints give the same; 2 modules closer, where the teeth already overlap at
    the law, the play is NaN."""
    from fabricate.gears.mesh import free_play_outlines

    if which == "sector":
        pair, x = sector_pair(), np.array([0.2, 0.5, 0.77])
    else:
        z, module, law = ((12, 12), 3.0, "x") if which == "module 3" else ((12, 24), 1.0, "x/2")
        spec = GearSpec(teeth=z, module_mm=module, backlash_mm=0.1, compare_methods=False, min_teeth=8)
        pair = make_gear_pair(FormulaLaw(law), (z[0] + z[1]) * module / 2, (0.0, 2 * np.pi), spec, closed=True,
                              run_mesh_check=False)
        x = np.array([0.05, 0.3])
    a, module = pair.center_distance_mm, pair.module
    plus, minus = free_play_outlines(pair.outline_a, pair.outline_b, pair.law, a, x, module)
    for k, xk in enumerate(x):
        gear_a = posed_outline(pair.outline_a, xk)
        theta = float(pair.law(np.array([xk]))[0])
        for play in (plus[k], -minus[k]):
            assert 5e-4 < abs(play) < 0.01
            assert gear_a.intersection(posed_outline(pair.outline_b, theta + 0.999 * play, a)).area <= 1e-12
            assert gear_a.intersection(posed_outline(pair.outline_b, theta + 1.001 * play, a)).area > 1e-12
    if which != "sector":  # whole radians given as ints are angles all the same
        ints = free_play_outlines(pair.outline_a, pair.outline_b, pair.law, a, [0, 1], module)
        floats = free_play_outlines(pair.outline_a, pair.outline_b, pair.law, a, np.array([0.0, 1.0]), module)
        np.testing.assert_array_equal(ints, floats)
    close = free_play_outlines(pair.outline_a, pair.outline_b, pair.law, a - 2 * module, x, module)
    assert np.isnan(close).all()
    theta = float(pair.law(x[:1])[0])
    closer = posed_outline(pair.outline_b, theta, a - 2 * module)
    assert posed_outline(pair.outline_a, x[0]).intersection(closer).area > 0.01


def test_unequal_spur_gears_free_play_contacts_and_default_steps():
    """18/27 spur gears, module 1, backlash 0.1 mm: each flank's free play is j / (2 r_b) = 0.1 / 27 rad at every
    step (exact involutes; 5e-7 rad, measured 2.1e-7), and the mean teeth in contact is the contact ratio
    (sqrt(10^2 - (9 cos a)^2) + sqrt(14.5^2 - (13.5 cos a)^2) - 22.5 sin a) / (pi cos a) = 1.580 (within 0.03 with
    20 steps per tooth of gear b). The default mesh steps turn gear a until gear b has turned once (1.5 turns, no
    end point: it repeats the start)."""
    from fabricate.gears.mesh import free_play, mesh_check

    pair = unequal_pair()
    x = np.linspace(0.0, 3 * np.pi, 540, endpoint=False)
    plus, minus, count = free_play(pair, x, return_contacts=True)
    np.testing.assert_allclose(plus, 0.1 / 27, rtol=0, atol=5e-7)
    np.testing.assert_allclose(minus, 0.1 / 27, rtol=0, atol=5e-7)
    alpha = np.radians(20.0)
    ratio = (np.sqrt(100 - (9 * np.cos(alpha)) ** 2) + np.sqrt(14.5**2 - (13.5 * np.cos(alpha)) ** 2)
             - 22.5 * np.sin(alpha)) / (np.pi * np.cos(alpha))
    assert np.mean(count) == pytest.approx(ratio, abs=0.03)
    assert set(np.unique(count)) == {1, 2}
    mesh = mesh_check(pair)  # spec.mesh_steps = 6
    np.testing.assert_allclose(mesh.x_a, np.arange(6) * 3 * np.pi / 6, rtol=0, atol=1e-12)
    np.testing.assert_allclose(mesh.backlash_mm, 0.1, atol=1e-5)
    np.testing.assert_array_equal(mesh.interference_area_mm2, 0.0)


def test_mesh_check_default_steps_of_a_sector_and_given_angles():
    """A sector is checked from the start to the end of its working range, both ends included; given angles
    (here a list of ints) are used as float radians."""
    from fabricate.gears.mesh import mesh_check

    pair = sector_pair()
    lo, hi = pair.working_range
    np.testing.assert_allclose(mesh_check(pair, steps=5).x_a, np.linspace(lo, hi, 5), rtol=1e-15)
    given = mesh_check(pair, x_a_values=[0, 1])
    assert given.x_a.dtype == np.float64 and given.x_a.tolist() == [0.0, 1.0]


def test_free_play_without_a_flank_on_either_gear():
    """Spur pair with gear a's driving flank 0 and gear b's driving flank 10 removed (as if cut away): the coast
    flanks are untouched (free_minus bit for bit); on the driving side the play is still j / (2 r) (5e-7 rad)
    wherever the whole pair had two teeth in contact (the other pair still touches), one contact fewer there,
    and it opens up where a removed flank was the only one touching."""
    import warnings
    from dataclasses import replace

    from fabricate.gears.mesh import free_play

    pair = spur_pair()
    x = pair.mesh.x_a
    full_plus, full_minus, full_count = free_play(pair, x, return_contacts=True)
    cut_a = replace(pair.cut_a, flanks={k: v for k, v in pair.cut_a.flanks.items() if k != 0})
    cut_b = replace(pair.cut_b, flanks={k: v for k, v in pair.cut_b.flanks.items() if k != 10})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no floating-point warnings on the way
        plus, minus, count = free_play(replace(pair, cut_a=cut_a, cut_b=cut_b), x, return_contacts=True)
    np.testing.assert_array_equal(minus, full_minus)
    assert np.all(plus >= full_plus)
    two = full_count == 2
    np.testing.assert_allclose(plus[two], 0.1 / 24, rtol=0, atol=5e-7)
    assert np.all(count <= full_count) and np.any(count[two] == 1)
    assert np.any(plus > 0.1 / 24 + 1e-3)


def test_free_play_of_radial_flank_pairs():
    """A stand-in pair at x_a = 0 with the law at 0 (gear a's points sit in gear b's frame at g - (a, 0)) whose
    flanks are radial segments about axis B, so each pair's gap is the angle between them (closed form, 1e-12 rad),
    near +-pi: driving flanks -2, 0, 2, 4 at 0.05, 0.05 + 1e-6, 0.05 + 4e-6, 0.3 rad, coast flanks -1, 1 at 0.04,
    0.02 rad. Gear b's flank -2 (its first row) is only its two end points, its flank 3 is missing, its last
    row short (padded). Free play 0.05 and 0.02 rad, two driving pairs within the 2e-6 rad contact tolerance.
    Gear a's points beyond gear b's radii lie at a gap of -0.5 rad and must not count; with only those there is no
    flank pair (NaN)."""
    import warnings
    from types import SimpleNamespace

    from fabricate.gears.mesh import free_play

    a = 20.0
    gaps = {-2: 0.05, -1: 0.04, 0: 0.05 + 1e-6, 1: 0.02, 2: 0.05 + 4e-6, 3: 0.01, 4: 0.3}

    def radial(centre, angle, radii):
        return np.column_stack([centre + radii * np.cos(angle), radii * np.sin(angle)])

    def stand_in(radii_a):
        flanks_a, flanks_b = {}, {}
        for k, gap in gaps.items():
            beta, sign = 3.05 + 0.02 * k, 1.0 if k % 2 == 0 else -1.0
            flanks_a[k] = np.vstack([radial(a, beta + sign * gap, radii_a),
                                     radial(a, beta - sign * 0.5, np.array([3.0, 7.0]))])
            if k != 3:
                flanks_b[k] = radial(0.0, beta, {-2: np.array([4.0, 6.0]), 4: np.array([4.0, 5.0, 6.0])}.get(
                    k, np.linspace(4.0, 6.0, 5)))
        zero = lambda x: np.zeros_like(np.asarray(x, dtype=float))  # noqa: E731
        return SimpleNamespace(pitch_model=SimpleNamespace(s_of_x=zero), law=zero, module=1.0, rack_origin=0.0,
                               closed=False, teeth=(4, 4), center_distance_mm=a, spec=GearSpec(),
                               cut_a=SimpleNamespace(flanks=flanks_a), cut_b=SimpleNamespace(flanks=flanks_b))

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no floating-point warnings on the way
        plus, minus, count = free_play(stand_in(np.array([4.25, 4.75, 5.25, 5.75])), np.zeros(1),
                                       return_contacts=True)
    np.testing.assert_allclose([plus[0], minus[0]], [0.05, 0.02], rtol=0, atol=1e-12)
    assert count.tolist() == [2]
    plus, minus = free_play(stand_in(np.array([3.5, 6.5])), np.zeros(1))
    assert np.isnan(plus).all() and np.isnan(minus).all()


@cache
def long_contact_sector():
    """Sector of equal circular gears, r = 32 mm (64 teeth a turn), 12 deg, addendum 1.3 m (not undercut)."""
    spec = GearSpec(module_mm=1.0, backlash_mm=0.1, compare_methods=False, pressure_angle_deg=12.0, addendum=1.3,
                    dedendum=1.6)
    return make_gear_pair(FormulaLaw("x"), 64.0, (0.0, 0.4), spec, closed=False, run_mesh_check=False)


def test_contact_ratio_of_a_long_contact_path():
    """Equal gears of r = 32 mm at 12 deg with addendum 1.3 m: the path of contact reaches 1.54 p from the pitch
    point each side, the contact ratio (2 sqrt(33.3^2 - (32 cos a)^2) - 64 sin a) / (pi cos a) = 3.066 is the mean
    teeth in contact over one pitch (200 steps: within 0.03); the free play is j / (2 r) each way (5e-7 rad)."""
    from fabricate.gears.mesh import free_play

    pair = long_contact_sector()
    x = 0.2 + (np.arange(200) / 200 - 0.5) * np.pi / 32
    plus, minus, count = free_play(pair, x, return_contacts=True)
    alpha = np.radians(12.0)
    ratio = (2 * np.sqrt(33.3**2 - (32 * np.cos(alpha)) ** 2) - 64 * np.sin(alpha)) / (np.pi * np.cos(alpha))
    assert ratio > 3.0
    assert np.mean(count) == pytest.approx(ratio, abs=0.03)
    np.testing.assert_allclose(plus, 0.1 / 64, rtol=0, atol=5e-7)
    np.testing.assert_allclose(minus, 0.1 / 64, rtol=0, atol=5e-7)


def test_no_teeth_in_contact_where_no_flank_pair_is_in_mesh():
    """The sector turned 0.8..1.2 rad before its working range (0.1..0.9 rad) or 0.8..1.1 rad past it: no flank
    pair shares a radius (free play NaN both ways), so no teeth are in contact: 0, not every driving flank of the
    window (their gaps are all inf, and inf <= inf + tolerance; 4 were counted). With steps inside the range,
    where 1 or 2 pairs touch and their mean is the local contact ratio of the osculating spur pairs (1.695; 1.708
    measured, within 0.03), the summary gives 0..2 teeth in contact and the contact ratio is the in-range count
    over all the steps (the steps without a pair add nothing)."""
    from fabricate.gears.mesh import free_play, mesh_check

    pair = sector_pair()
    lo, hi = pair.working_range
    x_out = np.concatenate([np.linspace(lo - 1.2, lo - 0.8, 9), np.linspace(hi + 0.8, hi + 1.1, 7)])
    plus, minus, count = free_play(pair, x_out, return_contacts=True)
    assert np.isnan(plus).all() and np.isnan(minus).all()
    np.testing.assert_array_equal(count, 0)
    x_in = np.linspace(lo, hi, 161)
    plus, minus, inside = free_play(pair, x_in, return_contacts=True)
    assert np.isfinite(plus).all() and set(np.unique(inside)) == {1, 2}
    assert np.mean(inside) == pytest.approx(pair.checks["contact_ratio"]["mean"], abs=0.03)
    summary = mesh_check(pair, x_a_values=np.concatenate([x_in, x_out])).summary()
    assert summary["steps_without_contact_pair"] == len(x_out)
    assert summary["teeth_in_contact"] == [0, 2]
    assert summary["contact_ratio_measured"] == pytest.approx(np.sum(inside) / (len(x_in) + len(x_out)), rel=1e-12)


@cache
def long_contact_spur_sector(radius: float, pressure_deg: float):
    """Sector of equal circular gears of module 1 with the spec's largest addendum, 1.5 m (dedendum 1.75 m)."""
    spec = GearSpec(module_mm=1.0, backlash_mm=0.1, compare_methods=False, pressure_angle_deg=pressure_deg,
                    addendum=1.5, dedendum=1.75)
    return make_gear_pair(FormulaLaw("x"), 2 * radius, (0.0, 0.4), spec, closed=False, run_mesh_check=False)


@pytest.mark.parametrize(("radius", "pressure_deg", "tol"), [(34.0, 12.0, 0.03), (50.0, 10.0, 0.04)])
def test_contact_ratio_of_a_contact_path_beyond_1_6_pitches(radius, pressure_deg, tol):
    """Equal gears with addendum 1.5 m, not undercut (r above the limit (1.75 - 0.38 (1 - sin a)) / sin^2 a, 33.5 and
    47.6 mm): r = 34 mm at 12 deg (68 teeth a turn) and r = 50 mm at 10 deg (100 teeth; the spec's smallest angle).
    The path of contact reaches (sqrt((r + 1.5)^2 - (r cos a)^2) - r sin a) / cos a = 1.74 and 2.07 p from the pitch
    point along the pitch line, beyond the fixed window of [-1.6 p, +1.9 p] the flanks were once taken from (which
    measured 3.335 and 3.675). The contact ratio (2 sqrt((r + 1.5)^2 - (r cos a)^2) - 2 r sin a) / (pi cos a) =
    3.482 and 4.141 is the mean teeth in contact over one pitch (200 steps; measured 3.485 and 4.170): within 0.03,
    and 0.04 for the larger gears, where a tip leaving its flank tangentially stays within CONTACT_TOLERANCE_RAD of
    touching a little longer. The free play is j / (2 r) each way (5e-7 rad)."""
    from fabricate.gears.mesh import free_play

    pair = long_contact_spur_sector(radius, pressure_deg)
    assert not pair.checks["undercut"] and not pair.checks["self_intersecting_envelope"]
    alpha = np.radians(pressure_deg)
    half_path = np.sqrt((radius + 1.5) ** 2 - (radius * np.cos(alpha)) ** 2) - radius * np.sin(alpha)
    assert half_path / np.cos(alpha) > 1.7 * np.pi  # beyond the old window
    x = 0.2 + (np.arange(200) / 200 - 0.5) * np.pi / radius
    plus, minus, count = free_play(pair, x, return_contacts=True)
    assert np.mean(count) == pytest.approx(2 * half_path / (np.pi * np.cos(alpha)), abs=tol)
    np.testing.assert_allclose(plus, 0.1 / (2 * radius), rtol=0, atol=5e-7)
    np.testing.assert_allclose(minus, 0.1 / (2 * radius), rtol=0, atol=5e-7)


def test_flank_window_holds_each_flank_of_a_small_closed_gear_once():
    """4/8-tooth spur gears of module 1 at 14.5 deg (min_teeth 3, bore 0.5 mm; undercut): the window would reach
    1 / (sin a cos a) m + p = 2.31 p either side (10 flanks), but gear a has only 8: it is kept to 8, reach
    (2 z - 1.5) p / 4 = 1.625 p. With 10, one of gear a's flanks is taken on two rack lines, the second pairing it
    with gear b's flank half a turn of gear b away: free_plus -2.89 rad at these steps (x_a = 0.889 + k pi/2),
    where the outlines do not overlap at all (interference area 0), so the play cannot be negative."""
    from fabricate.gears.mesh import flank_reach, free_play, interference_areas

    spec = GearSpec(teeth=(4, 8), module_mm=1.0, backlash_mm=0.1, compare_methods=False, min_teeth=3, bore_mm=0.5,
                    pressure_angle_deg=14.5)
    pair = make_gear_pair(FormulaLaw("x/2"), 6.0, (0.0, 2 * np.pi), spec, closed=True, run_mesh_check=False)
    assert flank_reach(pair) == pytest.approx(6.5 * np.pi / 4, rel=1e-12)
    x = 0.889 + np.arange(4) * np.pi / 2
    np.testing.assert_array_equal(interference_areas(pair, x), 0.0)
    plus, minus, count = free_play(pair, x, return_contacts=True)
    assert np.all(plus > 0.0125) and np.all(minus > 0.0125)  # at least j / (2 r_b)
    np.testing.assert_array_equal(count, 1)


@pytest.mark.parametrize("closer", [0.8, 3.0])
def test_mesh_check_of_an_overlapping_module_2_pair_in_chunks(monkeypatch, closer):
    """Module-2 spur gears 0.8 or 3 mm too close, checked in chunks of 2 steps: the interference area at each step
    is that of the whole posed outlines (shapely on raw coordinates, rtol 1e-9; the clip window must hold the
    overlap of teeth 4.5 mm high, out to 5 mm from the pitch point), the free play the unchunked one (negative:
    the teeth overlap, 0.8 mm closer); no steps give empty arrays."""
    from dataclasses import replace

    import fabricate.gears.mesh as mesh_module

    pair = module2_pair()
    close = replace(pair, center_distance_mm=pair.center_distance_mm - closer)
    x = np.array([0.0, 0.11, 0.3, 0.52, 0.7])
    monkeypatch.setattr(mesh_module, "MESH_VERTICES_PER_CHUNK", 2 * (len(pair.outline_a) + len(pair.outline_b)))
    got = mesh_module.mesh_check(close, x_a_values=x)
    want = [posed_outline(pair.outline_a, xi).intersection(
        posed_outline(pair.outline_b, float(pair.law(np.array([xi]))[0]), close.center_distance_mm)).area for xi in x]
    assert min(want) > 0.05
    np.testing.assert_allclose(got.interference_area_mm2, want, rtol=1e-9)
    plus, minus = mesh_module.free_play(close, x)
    np.testing.assert_array_equal(got.free_plus, plus)
    np.testing.assert_array_equal(got.free_minus, minus)
    if closer < 1.0:  # (3 mm closer the flanks' radii no longer pair up: NaN at some steps)
        assert np.all(plus + minus < 0)
    empty = mesh_module.mesh_check(pair, x_a_values=[])
    for values in (empty.x_a, empty.free_plus, empty.free_minus, empty.teeth_in_contact, empty.interference_area_mm2):
        assert values.shape == (0,)
