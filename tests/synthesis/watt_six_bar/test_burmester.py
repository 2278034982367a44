"""Generalized Burmester curves (fabricate.synthesis.watt_six_bar.burmester): closed-form checks.

Cubic root finding against polynomials built from their roots, distances against curves made of a circle
and a line (distance known in closed form), partners against the dyad's constant-length condition, and
the dtype / scale / warning promises of the small helpers. Expected values never come from the function
under test.
"""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import pytest

from fabricate.synthesis.watt_six_bar.burmester import (
    CubicCurve,
    PlaneMotion,
    _polish,
    cubic_real_roots,
    distance_to_curve,
    dyad_curve,
    grid_in_range,
    ground_motion,
    in_box,
    plane_motion,
    sample_curve,
)


def _from_roots(*roots: float) -> np.ndarray:
    """Coefficients (c0, c1, c2, c3) of the monic cubic prod (y - r), lowest power first."""
    a, b, c = roots
    return np.array([-a * b * c, a * b + b * c + c * a, -(a + b + c), 1.0])


def _rot(theta: float) -> np.ndarray:
    return np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])


def _tensor(poly: dict[tuple[int, int], float]) -> np.ndarray:
    """Symmetric tensor S with S_jkl v_j v_k v_l = sum coef x^a y^b for ``poly = {(a, b): coef}``, a + b <= 3."""
    s = np.zeros((3, 3, 3))
    for (a, b), coef in poly.items():
        idx = (0,) * a + (1,) * b + (2,) * (3 - a - b)
        perms = set(itertools.permutations(idx))
        for p in perms:
            s[p] += coef / len(perms)
    return s


def _times(p: dict[tuple[int, int], float], q: dict[tuple[int, int], float]) -> dict[tuple[int, int], float]:
    out: dict[tuple[int, int], float] = {}
    for (a, b), u in p.items():
        for (c, d), w in q.items():
            out[(a + c, b + d)] = out.get((a + c, b + d), 0.0) + u * w
    return out


def _circle(cx: float, cy: float, r: float) -> dict[tuple[int, int], float]:
    return {(2, 0): 1.0, (0, 2): 1.0, (1, 0): -2.0 * cx, (0, 1): -2.0 * cy, (0, 0): cx * cx + cy * cy - r * r}


def _curve(poly: dict[tuple[int, int], float]) -> CubicCurve:
    return CubicCurve(tensor=_tensor(poly), rows=np.zeros((3, 3, 3)))


# --- cubic_real_roots ---------------------------------------------------------------------------------


def test_three_real_roots_sorted_at_any_scale() -> None:
    """(y - 1)(y - 2)(y + 3) gives -3, 1, 2 ascending however the row is scaled (1e-3, 1, 1e3); 1e-12."""
    base = _from_roots(1.0, 2.0, -3.0)
    rows = np.stack([base * 1e-3, base, base * 1e3, -base])
    got = cubic_real_roots(rows)
    np.testing.assert_allclose(got, np.tile([-3.0, 1.0, 2.0], (4, 1)), rtol=0, atol=1e-12)


def test_one_real_root_goes_to_first_column() -> None:
    """(y - 2)(y^2 + 1): the complex pair is dropped, 2 in column 0 and NaN in 1, 2; batch shape kept."""
    row = np.array([-2.0, 1.0, -2.0, 1.0])  # (y - 2)(y^2 + 1) = y^3 - 2y^2 + y - 2
    got = cubic_real_roots(np.stack([row, 5.0 * row]).reshape(2, 1, 4))
    assert got.shape == (2, 1, 3)
    np.testing.assert_allclose(got[..., 0], 2.0, rtol=0, atol=1e-12)
    assert np.isnan(got[..., 1:]).all()


def test_lower_degree_rows() -> None:
    """c3 = 0: a quadratic y^2 - 1 gives -1, 1 (sorted, NaN last); a linear y - 2 gives 2; 1e-12."""
    got = cubic_real_roots(np.array([[-1.0, 0.0, 1.0, 0.0], [-2.0, 1.0, 0.0, 0.0], [6.0, -5.0, 1.0, 0.0]]))
    np.testing.assert_allclose(got[0, :2], [-1.0, 1.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[1, 0], 2.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[2, :2], [2.0, 3.0], rtol=0, atol=1e-12)
    assert np.isnan(got[0, 2]) and np.isnan(got[1, 1:]).all() and np.isnan(got[2, 2])


def test_negligible_leading_coefficients_are_dropped_relative_to_the_row() -> None:
    """c3 = 1e-14 of the largest coefficient counts as zero: y^2 - 1 (+1e-14 y^3) gives -1, 1 and no huge
    root near -1e14, whatever the overall scale of the row (1e-3, 1, 1e3); 1e-12."""
    row = np.array([-1.0, 0.0, 1.0, 1e-14])
    got = cubic_real_roots(np.stack([row * 1e-3, row, row * 1e3]))
    np.testing.assert_allclose(got[:, :2], np.tile([-1.0, 1.0], (3, 1)), rtol=0, atol=1e-12)
    assert np.isnan(got[:, 2]).all()


def test_leading_coefficient_threshold_is_exclusive() -> None:
    """A leading coefficient of exactly 1e-12 of the row's largest still counts as vanished (the test is
    ``> 1e-12``): y^2 - 1 + 1e-12 y^3 gives -1, 1 and no root near -1e12; 1e-9."""
    got = cubic_real_roots(np.array([[-1.0, 0.0, 1.0, 1e-12]]))
    np.testing.assert_allclose(got[0, :2], [-1.0, 1.0], rtol=0, atol=1e-9)
    assert np.isnan(got[0, 2])


def test_complex_roots_of_a_quadratic_are_dropped() -> None:
    """y^2 + 1/4 (roots +-i/2) and y^2 + 1e-18 (roots +-1e-9 i, imaginary part at the 1e-9 tolerance,
    exclusive) have no real roots: all NaN."""
    got = cubic_real_roots(np.array([[0.25, 0.0, 1.0, 0.0], [1e-18, 0.0, 1.0, 0.0]]))
    assert np.isnan(got).all()


def test_zero_and_nan_rows_give_nan_and_leave_others_alone() -> None:
    """An all-zero row and a row with a NaN coefficient give NaN roots without raising; the other rows of
    the batch keep their roots (1e-12)."""
    rows = np.array([[0.0, 0.0, 0.0, 0.0], [np.nan, 0.0, 0.0, 1.0], _from_roots(1.0, 2.0, -3.0)])
    got = cubic_real_roots(rows)
    assert np.isnan(got[:2]).all()
    np.testing.assert_allclose(got[2], [-3.0, 1.0, 2.0], rtol=0, atol=1e-12)


def test_polish_recovers_roots_given_to_1e_5() -> None:
    """Two Newton steps from roots off by 1e-5 (well inside the 1e-3 step guard) reach 1e-12: quadratic
    convergence needs the exact derivative c1 + 2 c2 y + 3 c3 y^2."""
    c = np.stack([_from_roots(1.0, 2.0, -3.0), 2.0 * _from_roots(-0.5, 4.0, 7.0)])
    exact = np.array([[-3.0, 1.0, 2.0], [-0.5, 4.0, 7.0]])
    got = _polish(exact + np.array([1e-5, -1e-5, 1e-5]), c)
    np.testing.assert_allclose(got, exact, rtol=0, atol=1e-12)


def test_polish_guards_are_exclusive_at_their_thresholds() -> None:
    """Both guards of the Newton polish are strict, like the leading-coefficient test of cubic_real_roots:
    at y = 0 on 1e-18 + 1e-14 y + y^3, P' is exactly 1e-14, which counts as vanished (``> 1e-14``), so the
    estimate is kept although the step (1e-4) would be short; on 1e-3 + y + y^3 the step P/P' is exactly
    1e-3 = 1e-3 (1 + |y|), the longest step refused (``<``). At y = 0 Horner's scheme gives P = c0 and P' = c1
    with no rounding, and 1e-3 / 1 and 1e-3 * (1 + 0) are the same double, so the thresholds are hit exactly;
    the expected result is the unchanged estimate, bit for bit."""
    c = np.array([[1e-18, 1e-14, 0.0, 1.0], [1e-3, 1.0, 0.0, 1.0]])
    roots = np.zeros((2, 1))
    np.testing.assert_array_equal(_polish(roots, c), roots)


# --- dyad_curve / partners ----------------------------------------------------------------------------


def _moving_plane() -> PlaneMotion:
    """Positions 2, 3 rotate and translate; position 4 is a pure translation by (3, 1)."""
    angles = [0.0, 0.3, -0.5, 0.0]
    trans = [[0.0, 0.0], [1.0, 2.0], [-2.0, 0.5], [3.0, 1.0]]
    return PlaneMotion(np.stack([_rot(a) for a in angles]), np.array(trans))


def test_dyad_curve_of_a_plane_with_itself_is_zero_without_warnings() -> None:
    """A dyad joining a plane to itself imposes nothing: all rows vanish and the curve tensor is exactly
    zero (finite, no division warning from the unit-scale normalisation)."""
    motion = _moving_plane()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        curve = dyad_curve(motion, motion)
    assert np.array_equal(curve.tensor, np.zeros((3, 3, 3)))


def test_dyad_curve_tensor_has_unit_largest_entry_for_small_motions() -> None:
    """Small displacements (0.01 mm, 0.001 rad) give a raw determinant tensor far below 1; the curve is
    still scaled to largest |entry| = 1 (1e-12)."""
    angles = np.array([0.0, 1e-3, -2e-3, 1.5e-3])
    origins = np.array([[0.0, 0.0], [0.01, 0.0], [0.0, 0.01], [-0.01, 0.005]])
    curve = dyad_curve(ground_motion(), plane_motion(origins, angles))
    assert abs(np.max(np.abs(curve.tensor)) - 1.0) < 1e-12


def test_partners_keep_the_dyad_length_and_ignore_the_rest_of_the_batch() -> None:
    """Partner Y of a curve point X (ground to moving plane) keeps |X - (R_i Y + t_i)| = |X - Y| at
    positions 2..4 (1e-9 relative), and is the same (1e-12 relative) when computed alone or together with a
    far point (1e12 mm, where the pure-translation position's row stays O(1) and the other rows are huge)."""
    moving = _moving_plane()
    curve = dyad_curve(ground_motion(), moving)
    sample = sample_curve(curve, np.array([1.5]))
    x = sample.points()[0, 0]
    assert np.isfinite(x).all()
    alone = curve.partners(x[None])[0]
    together = curve.partners(np.stack([x, 1e12 * np.array([-1.0, 3.0])]))[0]
    np.testing.assert_allclose(together, alone, rtol=1e-12)
    length = np.hypot(*(x - alone))
    for i in range(1, 4):
        moved = moving.rotations[i] @ alone + moving.translations[i]
        assert abs(np.hypot(*(x - moved)) - length) < 1e-9 * max(length, 1.0)


def test_partner_at_infinity_raises_no_warning() -> None:
    """A point whose (Y, 1) null vector is (0, 1, 0) (partner at infinity) gives a non-finite partner
    without a divide or invalid RuntimeWarning."""
    rows = np.zeros((3, 3, 3))
    rows[0, :, 2] = [1.0, 0.0, 0.0]
    rows[1, :, 2] = [0.0, 0.0, 1.0]
    rows[2, :, 2] = [1.0, 0.0, 1.0]
    curve = CubicCurve(tensor=np.zeros((3, 3, 3)), rows=rows)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        y = curve.partners(np.array([[0.0, 0.0]]))
    assert not np.isfinite(y).all()


def _rows_at_origin(m: np.ndarray) -> np.ndarray:
    """Row matrices whose system at X = (0, 0) is ``m`` (only the constant monomial column is set)."""
    rows = np.zeros((3, 3, 3))
    rows[:, :, 2] = m
    return rows


def test_partner_rank_test_is_relative_to_the_largest_singular_value() -> None:
    """The rows (1, 0, -1), (1, 0, -1), (1, d, -1 - 2d) all annihilate (1, 2, 1) exactly (d a power of two, so
    every entry and product is exact): the partner is Y = (1, 2). Their singular values are about
    (2.449, 1.414 d, 0), so second / first = 5.4e-10 for d = 2^-30 (below the documented 1e-9: nearly rank one,
    NaN) and 4.3e-9 for d = 2^-27 (a unique partner, (1, 2) to 1e-6; the null vector's conditioning is
    eps / 4.3e-9 ~ 5e-8). The verdict does not change when the rows are scaled by 1e-6 or 1e6. numpy's SVD
    confirms the ratios independently."""
    point = np.array([[0.0, 0.0]])
    for power, unique in ((30, False), (27, True)):
        d = 2.0**-power
        m = np.array([[1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, d, -1.0 - 2.0 * d]])
        np.testing.assert_array_equal(m @ [1.0, 2.0, 1.0], 0.0)
        sv = np.linalg.svd(m, compute_uv=False)
        assert (sv[1] / sv[0] > 1e-9) == unique
        for scale in (1.0, 1e-6, 1e6):
            y = CubicCurve(tensor=np.zeros((3, 3, 3)), rows=_rows_at_origin(scale * m)).partners(point)
            if unique:
                np.testing.assert_allclose(y, [[1.0, 2.0]], rtol=0, atol=1e-6)
            else:
                assert np.isnan(y).all()


def test_a_partner_at_infinity_leaves_the_other_points_of_the_batch_alone() -> None:
    """Rows A + x B (no y dependence): at X = (0, 0) the system A has null vector (0, 1, 0), a partner at
    infinity (NaN); at X = (1, 0) the system A + B = [(1, 0, -1), (0, 1, -2), (1, 1, -3)] (third row the sum
    of the others, rank 2) has null vector (1, 2, 1), partner (1, 2) by hand. Asked together, the first
    point's NaN must not spread to the second (1e-12)."""
    a = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]])
    b = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, -3.0], [0.0, 1.0, -4.0]])
    rows = _rows_at_origin(a)
    rows[:, :, 0] = b
    curve = CubicCurve(tensor=np.zeros((3, 3, 3)), rows=rows)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        y = curve.partners(np.array([[0.0, 0.0], [1.0, 0.0]]))
    assert np.isnan(y[0]).all()
    np.testing.assert_allclose(y[1], [1.0, 2.0], rtol=0, atol=1e-12)


# --- motions ------------------------------------------------------------------------------------------


def test_apply_returns_float64_for_integer_motion_and_points() -> None:
    """An integer-valued motion applied to integer points gives float64 positions (callers write NaN into
    them) equal to R_i X + t_i."""
    rot = np.array([[[1, 0], [0, 1]], [[0, -1], [1, 0]], [[-1, 0], [0, -1]], [[0, 1], [-1, 0]]])
    trans = np.array([[0, 0], [1, 2], [3, 4], [5, 6]])
    motion = PlaneMotion(rot, trans)
    got = motion.apply(np.array([2, 1]))
    assert got.dtype == np.float64
    np.testing.assert_array_equal(got, [[2.0, 1.0], [0.0, 4.0], [1.0, 3.0], [6.0, 4.0]])


def test_plane_motion_rounds_extended_precision_origins_to_float64() -> None:
    """Origins in extended precision give the same float64 translations as the float64-rounded origins."""
    origins = np.array([[0.0, 0.0], [1.0, 2.0], [-1.0, 3.0], [2.0, -1.0]]) + 1.0 / 3.0
    angles = np.array([0.0, 0.2, -0.3, 0.5])
    ext = plane_motion(origins.astype(np.longdouble) + np.longdouble(1e-17), angles)
    ref = plane_motion((origins.astype(np.longdouble) + np.longdouble(1e-17)).astype(np.float64), angles)
    assert ext.translations.dtype == np.float64
    np.testing.assert_array_equal(ext.translations, ref.translations)


# --- distance_to_curve --------------------------------------------------------------------------------


def test_distance_to_a_vertical_line_found_by_the_y_grid() -> None:
    """Circle (x+20)^2 + y^2 = 25 times the line x = 10.01, from the origin: the line (distance 10.01, foot
    (10.01, 0)) is nearer than the circle (15). Lines of constant x never meet the line (10.01 lies between
    grid values, so rounding noise cannot fake a crossing), only lines of constant y do; 1e-9."""
    curve = _curve(_times(_circle(-20.0, 0.0, 5.0), {(1, 0): 1.0, (0, 0): -10.01}))
    dist, foot = distance_to_curve(curve, np.array([0.0, 0.0]))
    assert abs(dist - 10.01) < 1e-9
    np.testing.assert_allclose(foot, [10.01, 0.0], rtol=0, atol=1e-9)


def test_distance_to_a_horizontal_line_found_by_the_x_grid() -> None:
    """Circle x^2 + (y+20)^2 = 25 times the line y = 10.01 (between grid values), from the origin:
    distance 10.01 at (0, 10.01), the circle is 15 away; 1e-9."""
    curve = _curve(_times(_circle(0.0, -20.0, 5.0), {(0, 1): 1.0, (0, 0): -10.01}))
    dist, foot = distance_to_curve(curve, np.array([0.0, 0.0]))
    assert abs(dist - 10.01) < 1e-9
    np.testing.assert_allclose(foot, [0.0, 10.01], rtol=0, atol=1e-9)


def test_distance_to_a_small_oval_between_coarse_grid_lines() -> None:
    """A circle of radius 0.25 centred at (0.5, 0) times the line x = 10.01, from the origin: distance 0.25
    (foot (0.25, 0)) to the small circle, not 10.01 to the line; the fine grid must reach it; 1e-9."""
    curve = _curve(_times(_circle(0.5, 0.0, 0.25), {(1, 0): 1.0, (0, 0): -10.01}))
    dist, foot = distance_to_curve(curve, np.array([0.0, 0.0]))
    assert abs(dist - 0.25) < 1e-9
    np.testing.assert_allclose(foot, [0.25, 0.0], rtol=0, atol=1e-6)


def test_distance_default_span_is_40_mm() -> None:
    """A small circle (r 0.4) centred at (40.5, 40.5) lies outside the 40 mm window of x and y lines around
    the origin, so the default search only finds the line x = 200 (distance 200, 1e-9); with span=41 the
    circle is found (distance |(40.5, 40.5)| - 0.4; 1e-4, the projection onto so small a circle seen from
    57 mm converges slowly)."""
    curve = _curve(_times(_circle(40.5, 40.5, 0.4), {(1, 0): 1.0, (0, 0): -200.0}))
    dist, _ = distance_to_curve(curve, np.array([0.0, 0.0]))
    assert abs(dist - 200.0) < 1e-9
    dist41, _ = distance_to_curve(curve, np.array([0.0, 0.0]), span=41.0)
    assert abs(dist41 - (math.hypot(40.5, 40.5) - 0.4)) < 1e-4


def test_distance_far_from_the_origin_to_a_circle() -> None:
    """Only the offset from the point matters, not where the origin is: from P = (250, -180) to the circle of
    radius 20 centred at P + (18.1, 24.13) (times the far line x = 1000), the distance is
    |(18.1, 24.13)| - 20 (closed form) and the foot is P + (1 - 20 / |(18.1, 24.13)|) (18.1, 24.13); 1e-9. The
    refinement converges here (point nearer the circle than its radius), so the result is exact to rounding
    and far more accurate than the 0.02 mm grid alone."""
    point = np.array([250.0, -180.0])
    offset = np.array([18.1, 24.13])
    centre_distance = math.hypot(*offset)
    curve = _curve(_times(_circle(*(point + offset), 20.0), {(1, 0): 1.0, (0, 0): -1000.0}))
    dist, foot = distance_to_curve(curve, point)
    assert abs(dist - (centre_distance - 20.0)) < 1e-9
    np.testing.assert_allclose(foot, point + (1.0 - 20.0 / centre_distance) * offset, rtol=0, atol=1e-9)


def test_distance_far_from_the_origin_to_a_vertical_line() -> None:
    """The y-grid case of test_distance_to_a_vertical_line_found_by_the_y_grid moved to P = (137.3, -64.9): circle
    of radius 5 centred at P - (20, 0) (15 away) times the line x = P_x + 10.01 (10.01 away, foot P + (10.01, 0),
    closed form). Which grid's sample is nearer must be judged by the distance to P, not to the origin; 1e-9."""
    point = np.array([137.3, -64.9])
    curve = _curve(_times(_circle(point[0] - 20.0, point[1], 5.0), {(1, 0): 1.0, (0, 0): -(point[0] + 10.01)}))
    dist, foot = distance_to_curve(curve, point)
    assert abs(dist - 10.01) < 1e-9
    np.testing.assert_allclose(foot, point + [10.01, 0.0], rtol=0, atol=1e-9)


def test_distance_where_the_refinement_does_not_settle_keeps_a_curve_point() -> None:
    """From P = (120, -75) to a circle of radius r = 10 whose centre C is 20.5 away (distance d = 10.5 > r):
    sliding along the tangent multiplies the angular error by d / r = 1.05 per iteration, so the projection
    wanders and must be rejected. Whatever happens, the returned foot must be a point of the curve
    (| |foot - C| - r | < 1e-9) at the returned distance (1e-12), and the distance may not undercut the exact
    20.5 - 10 (1e-9) nor exceed it by more than the grid allows: a sample within h sqrt(2) / 2 = 0.0141 mm
    of arc (h = 0.02 mm) is at most D s^2 / (2 r d) = 2e-5 mm farther. The tensor is only defined up to scale
    (CubicCurve docstring), so scaling it by 1e-12 must give the same answer (1e-12 relative)."""
    point = np.array([120.0, -75.0])
    centre = point + 20.5 * np.array([math.cos(0.3), math.sin(0.3)])
    base = _tensor(_times(_circle(*centre, 10.0), {(1, 0): 1.0, (0, 0): -(point[0] + 500.0)}))
    results = []
    for scale in (1.0, 1e-12):
        dist, foot = distance_to_curve(CubicCurve(tensor=scale * base, rows=np.zeros((3, 3, 3))), point)
        assert abs(math.hypot(*(foot - centre)) - 10.0) < 1e-9
        assert abs(math.hypot(*(foot - point)) - dist) < 1e-12
        assert 10.5 - 1e-9 <= dist <= 10.5 + 2e-5
        results.append(dist)
    np.testing.assert_allclose(results[1], results[0], rtol=1e-12)


def test_distance_to_a_cusp() -> None:
    """y^2 = x^3 seen from (-5, 0): along the curve |X - P|^2 = (x + 5)^2 + x^3 grows for x >= 0, so the nearest
    point is the cusp (0, 0) at distance 5 exactly, where the gradient vanishes. The refinement must stop there
    quietly (no division warning) and return (5, (0, 0)); 1e-12."""
    curve = _curve({(0, 2): 1.0, (3, 0): -1.0})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dist, foot = distance_to_curve(curve, np.array([-5.0, 0.0]))
    assert abs(dist - 5.0) < 1e-12
    np.testing.assert_allclose(foot, [0.0, 0.0], rtol=0, atol=1e-12)


def test_distance_to_a_curve_without_real_points_is_inf_at_the_float_point() -> None:
    """x^2 + y^2 + 1 has no real point: (inf, point) with the point as float64 even if given as integers."""
    dist, foot = distance_to_curve(_curve({(2, 0): 1.0, (0, 2): 1.0, (0, 0): 1.0}), np.array([3, 4]))
    assert dist == math.inf
    assert foot.dtype == np.float64
    np.testing.assert_array_equal(foot, [3.0, 4.0])


def test_gradient_matches_closed_form() -> None:
    """Gradient of P = ((x-1)^2 + y^2 - 4)(x + 2y - 3) against the hand-derived partials (1e-12 relative)."""
    curve = _curve(_times(_circle(1.0, 0.0, 2.0), {(1, 0): 1.0, (0, 1): 2.0, (0, 0): -3.0}))
    pts = np.array([[0.5, -1.0], [2.0, 3.0], [-4.0, 0.25]])
    x, y = pts.T
    q, lin = (x - 1.0) ** 2 + y**2 - 4.0, x + 2.0 * y - 3.0
    expected = np.stack([2.0 * (x - 1.0) * lin + q, 2.0 * y * lin + 2.0 * q], axis=-1)
    np.testing.assert_allclose(curve.gradient(pts), expected, rtol=1e-12)
    np.testing.assert_allclose(curve.evaluate(pts), q * lin, rtol=1e-12)


def test_y_polynomials_of_integer_abscissae_match_float() -> None:
    """Integer x (here 3e6 mm, whose cube overflows int64) gives the same coefficients as float x (1e-12)."""
    curve = _curve(_times(_circle(1.0, 0.0, 2.0), {(1, 0): 1.0, (0, 1): 2.0, (0, 0): -3.0}))
    x = np.array([3_000_000, -7])
    np.testing.assert_allclose(curve.y_polynomials(x), curve.y_polynomials(x.astype(float)), rtol=1e-12)


def test_in_box_is_closed_on_every_side() -> None:
    """Points on each edge of the box are inside; just outside each edge, and NaN, are outside."""
    box = np.array([0.0, 2.0, -1.0, 1.0])
    inside = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, -1.0], [1.0, 1.0]])
    outside = np.array([[-1e-9, 0.0], [2.0 + 1e-9, 0.0], [1.0, -1.0 - 1e-9], [1.0, 1.0 + 1e-9], [np.nan, 0.0]])
    assert in_box(inside, box).all()
    assert not in_box(outside, box).any()


def test_grid_in_range_rounds_to_1e_9() -> None:
    """Grid values are rounded to 9 decimals: a start of 0.1234567891234 prints as 0.123456789."""
    got = grid_in_range(0.1234567891234, 1.0, 0.25)
    np.testing.assert_array_equal(got, [0.123456789, 0.373456789, 0.623456789, 0.873456789])


def test_float32_and_integer_coefficients_are_solved_in_float64() -> None:
    """(y - 1)(y - 2)(y + 3) given as float32 or int64 gives -3, 1, 2 to 1e-12 (no float32 arithmetic)."""
    base = _from_roots(1.0, 2.0, -3.0)
    for row in (base.astype(np.float32), base.astype(np.int64)):
        np.testing.assert_allclose(cubic_real_roots(row[None]), [[-3.0, 1.0, 2.0]], rtol=0, atol=1e-12)


def test_close_roots_and_double_root() -> None:
    """Roots 0, 0.1, 0.2 (discriminant 4e-6, still three) come back sorted (1e-12); a double root
    (y - 1)^2 (y + 2) (discriminant 0) counts as the single-root case: one root (-2 or 1, 1e-6), NaN in
    columns 1, 2."""
    got = cubic_real_roots(np.stack([_from_roots(0.0, 0.1, 0.2), _from_roots(1.0, 1.0, -2.0)]))
    np.testing.assert_allclose(got[0], [0.0, 0.1, 0.2], rtol=0, atol=1e-12)
    assert min(abs(got[1, 0] + 2.0), abs(got[1, 0] - 1.0)) < 1e-6
    assert np.isnan(got[1, 1:]).all()


def test_polish_at_small_and_large_scales() -> None:
    """Newton polish from 1e-5 errors where |P'| < 1 (roots 0.1, 0.2, 0.3) and from 1e-4 errors at roots
    1000, 2000, 3000 (step guard 1e-3 (1 + |y|)) reaches 1e-12 relative."""
    small = np.array([0.1, 0.2, 0.3])
    got = _polish(small + 1e-5, _from_roots(*small)[None])
    np.testing.assert_allclose(got[0], small, rtol=1e-12)
    large = np.array([1000.0, 2000.0, 3000.0])
    got = _polish(large + 1e-4, _from_roots(*large)[None])
    np.testing.assert_allclose(got[0], large, rtol=1e-12)


def test_polish_keeps_estimates_whose_newton_step_is_too_long() -> None:
    """A Newton step longer than 1e-3 (1 + |y|) means a near-double root: the estimate is returned unchanged
    (y = 0.0015 on y^3 - 9y, step ~0.0015; y = 0.0051 between the roots 0 and 0.01 of y (y - 0.01)(y - 5),
    step ~0.12). Where P' vanishes (triple roots of y^3 and (y - 2000)^3, and y = 0 on y^3 + 1e-30) the
    estimate is kept too, without divide or invalid warnings."""
    c = np.stack([np.array([0.0, -9.0, 0.0, 1.0]), _from_roots(0.0, 0.01, 5.0), _from_roots(0.0, 0.0, 0.0),
                  _from_roots(2000.0, 2000.0, 2000.0), np.array([1e-30, 0.0, 0.0, 1.0])])
    roots = np.array([[0.0015], [0.0051], [0.0], [2000.0], [0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = _polish(roots, c)
    np.testing.assert_array_equal(got, roots)


def test_sample_curve_of_a_batch_matches_single_curves() -> None:
    """Sampling two dyad curves at once (x given as integers, n = 3) gives, curve by curve, the same
    ordinates and partners as sampling each alone (1e-12), and float64 abscissae."""
    origins = np.array([[[0.0, 0.0], [1.0, 2.0], [-2.0, 0.5], [3.0, 1.0]],
                        [[0.0, 1.0], [2.0, 2.0], [-1.0, 0.5], [2.0, -1.0]]])
    angles = np.array([[0.0, 0.3, -0.5, 0.2], [0.1, 0.4, -0.2, 0.6]])
    batch = dyad_curve(ground_motion((2,)), plane_motion(origins, angles))
    x = np.array([-1, 0, 2])
    both = sample_curve(batch, x)
    assert both.x.dtype == np.float64 and both.x.shape == (2, 3)
    for k in range(2):
        one = sample_curve(dyad_curve(ground_motion(), plane_motion(origins[k], angles[k])), x.astype(float))
        np.testing.assert_allclose(both.y[k], one.y, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(both.partner[k], one.partner, rtol=1e-12, atol=1e-12)


def test_partners_are_invariant_to_a_huge_row_scale() -> None:
    """The partner system is homogeneous: rows scaled by 1e160 give the same partners (1e-12 relative)."""
    curve = dyad_curve(ground_motion(), _moving_plane())
    pts = sample_curve(curve, np.array([1.5, -2.0])).points()[:, 0]
    ref = curve.partners(pts)
    big = CubicCurve(tensor=curve.tensor, rows=curve.rows * 1e160).partners(pts)
    assert np.isfinite(ref).all()
    np.testing.assert_allclose(big, ref, rtol=1e-12)


def test_partners_of_a_nearly_rank_one_system_are_nan() -> None:
    """A system with singular values (2, 1e-9, 0), second/first = 5e-10 below the 1e-9 rank threshold, has
    no unique partner: NaN."""
    rows = np.zeros((3, 3, 3))
    rows[0, :, 2] = [1.0, 1.0, 0.0]
    rows[1, :, 2] = [1.0, 1.0, 0.0]
    rows[2, :, 2] = [0.0, 0.0, 1e-9]
    y = CubicCurve(tensor=np.zeros((3, 3, 3)), rows=rows).partners(np.array([[0.0, 0.0]]))
    assert np.isnan(y).all()


def test_plane_motion_rounds_extended_precision_angles_to_float64() -> None:
    """Angles in extended precision give float64 rotations equal to those of the float64-rounded angles."""
    origins = np.array([[0.0, 0.0], [1.0, 2.0], [-1.0, 3.0], [2.0, -1.0]])
    angles = np.array([0.0, 0.2, -0.3, 0.5]).astype(np.longdouble) + np.longdouble(1e-19)
    ext = plane_motion(origins, angles)
    ref = plane_motion(origins, angles.astype(np.float64))
    assert ext.rotations.dtype == np.float64 and ext.translations.dtype == np.float64
    np.testing.assert_array_equal(ext.rotations, ref.rotations)


def test_partners_of_a_zero_system_or_at_infinity_are_nan():
    """The docstring's promise: NaN where the null space is not unique or Y is at infinity. Rows that vanish
    exactly (every Y is a partner): NaN, not (0, 0). Rows whose null vector at (0, 0) is (0, 1, 0), a point at
    infinity: NaN, not +-inf."""
    zero = CubicCurve(tensor=np.zeros((3, 3, 3)), rows=np.zeros((3, 3, 3)))
    assert np.all(np.isnan(zero.partners(np.array([[1.0, 2.0]]))))
    rows = np.zeros((3, 3, 3))
    rows[0, :, 2] = (1.0, 0.0, 0.0)
    rows[1, :, 2] = (0.0, 0.0, 1.0)
    rows[2, :, 2] = (1.0, 0.0, 1.0)
    curve = CubicCurve(tensor=np.zeros((3, 3, 3)), rows=rows)
    assert np.all(np.isnan(curve.partners(np.array([[0.0, 0.0]]))))


@pytest.mark.parametrize("roots", [(5.0, 5.0, 5.00001), (3.0, 3.000001, 3.000003), (-2.0, -2.0, -2.0 + 1e-6)])
def test_clustered_roots_stay_sorted_and_near_the_cluster(roots):
    """Regression (found by helper-28): near a triple root the Newton polish walked up to its 1e-3 (1 + |y|)
    guard away from the roots on rounding noise (4.8e-3 off for (5, 5, 5.00001)) and returned them out of
    order. The roots of (y - a)(y - b)(y - c) must come back ascending (the documented order), each within
    1e-4 (1 + |a|) of the cluster (a triple root is only determined to about eps^(1/3) of its size)."""
    a, b, c = roots
    coefficients = np.array([-a * b * c, a * b + b * c + c * a, -(a + b + c), 1.0])
    got = cubic_real_roots(coefficients[None])[0]
    finite = got[np.isfinite(got)]
    assert len(finite) >= 1
    assert np.all(np.diff(finite) >= 0.0)
    assert np.all(np.abs(finite - np.mean(roots)) < 1e-4 * (1.0 + abs(a)))
