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
    # by default arc length counts from x = 0
    default = PitchCurves(law, 30.0, (0.0, 2 * np.pi), intervals=64)
    np.testing.assert_allclose(default.s_of_x(np.array([0.0, 1.0])), [0.0, 10.0], atol=1e-9)


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
    rb, drb, ddrb, _, _ = pitch.radii(x, "b")
    np.testing.assert_allclose([rb, drb, ddrb], [a - r, -dr, -ddr], rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(pitch.speed(x), np.hypot(r, dr), rtol=1e-8)  # law'' by central differences
    for xi in (0.0, 2.0, 5.9):
        want = quad(lambda t: np.hypot(p / (1 + e * np.cos(t)), p * e * np.sin(t) / (1 + e * np.cos(t)) ** 2),
                    0.5, xi, epsabs=1e-12, epsrel=1e-12)[0]
        assert pitch.s_of_x(np.array([xi]))[0] == pytest.approx(want, abs=1e-7)  # speed within 1e-8
    assert pitch.perimeter_a == pytest.approx(4 * big_a * ellipe(e * e), rel=1e-10)
    kappa = (r**2 + 2 * dr**2 - r * ddr) / (r**2 + dr**2) ** 1.5
    np.testing.assert_allclose(pitch.frames_at_x(x, "a").curvature, kappa, rtol=1e-6)
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
    """Module limit 2 rho / min_teeth (rho = 8 mm, 8 teeth: 2 mm) and concave radius limit 2 h_f m (1 mm module:
    2.5 mm): just inside passes, just outside raises naming the field and the largest module."""
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
    check_feasible(curv(30.0, 30.0, 2.5, 9.0), 1.0, spec)  # concave radius exactly 2 h_f m
    with pytest.raises(SpecError, match=r"concave with radius 2.49 mm; needs module <= 0.996 mm") as info:
        check_feasible(curv(30.0, 30.0, 9.0, 2.49), 1.0, spec)
    assert info.value.path == "gears.module_mm"


def test_contact_ratio_of_spur_gears_and_of_the_rack_limit():
    """Pitch circles 10 and 20 mm, module 1: the spur contact ratio
    (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin alpha) / (pi m cos alpha); a flat or concave curve
    counts as a rack (addendum / sin alpha)."""
    from fabricate.gears.checks import local_contact_ratio
    from fabricate.gears.spec import GearSpec

    alpha = np.radians(20.0)
    m, ha = 1.0, 1.0

    def path(r):
        return np.sqrt((r + ha) ** 2 - (r * np.cos(alpha)) ** 2)

    spur = (path(10.0) + path(20.0) - 30.0 * np.sin(alpha)) / (np.pi * m * np.cos(alpha))
    got = local_contact_ratio(_Curvatures([0.1, 0.1], [0.05, 0.05]), np.zeros(2), m, GearSpec())
    np.testing.assert_allclose(got, spur, rtol=1e-12)
    rack = ha / np.sin(alpha)
    got = local_contact_ratio(_Curvatures([0.0, -0.2], [0.05, 1e-10]), np.zeros(2), m, GearSpec())
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
