"""Planar kinematic mapping and dyad-family tracing (fabricate.synthesis.five_bar.kinematic_mapping).

Fast and independent of the paper's finger (tests/synthesis/five_bar/test_five_bar.py synthesises it in a slow
fixture).
Expected values come from closed forms written out here (Bottema & Roth's image coordinates, explicit
rotation matrices, circles through hand-picked points, conics solved by hand), from a dyad built by hand
(four poses of a body whose moving point ``b`` runs on a circle about ``c``), or from a brute-force scan of
the circle-point curve that does not use the kinematic mapping at all. Tolerances are stated at each
assert.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.synthesis.five_bar import kinematic_mapping as km

displacement = st.tuples(st.floats(-200, 200), st.floats(-200, 200), st.floats(-3.1, 3.1))
point = st.tuples(st.floats(-100, 100), st.floats(-100, 100))


def rot(angle: float) -> np.ndarray:
    return np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])


def textbook_image(a: float, b: float, phi: float) -> np.ndarray:
    """Bottema & Roth / McCarthy: image of the rotation ``phi`` followed by the translation ``(a, b)``."""
    s, c = math.sin(phi / 2), math.cos(phi / 2)
    return np.array([a / 2 * s - b / 2 * c, a / 2 * c + b / 2 * s, s, c])


# -- image coordinates -------------------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(displacement)
def test_image_is_the_textbook_formula_and_fixes_the_pole(d):
    """The image of (e, f, v) is Bottema & Roth's formula, and (Z1/Z3, Z2/Z3) is the pole (fixed point).

    The pole check is geometric: the point ``P`` with ``R(v) P + (e, f) = P`` is computed here from the
    rotation matrix, not from the module (tolerance 1e-9 mm on displacements up to 200 mm).
    """
    e, f, v = d
    z = km.image_coordinates(np.array([d]))
    assert z.shape == (1, 4)
    assert np.allclose(z[0], textbook_image(e, f, v), rtol=0, atol=1e-12)
    if abs(math.sin(v / 2)) > 1e-3:
        pole = np.linalg.solve(np.eye(2) - rot(v), np.array([e, f]))
        assert np.allclose(z[0, :2] / z[0, 2], pole, rtol=1e-9, atol=1e-9)


def test_image_of_several_displacements_is_one_row_each():
    """An (n, 3) input gives n image rows in the input order (checked against the textbook formula)."""
    ds = [(10.0, -4.0, 0.3), (0.0, 0.0, 0.0), (-7.5, 2.0, -2.0)]
    z = km.image_coordinates(np.array(ds))
    assert z.shape == (3, 4)
    for row, d in zip(z, ds, strict=True):
        assert np.allclose(row, textbook_image(*d), rtol=0, atol=1e-15)
    # the identity maps to (0, 0, 0, 1)
    assert np.array_equal(z[1], [0.0, 0.0, 0.0, 1.0])


def test_image_is_computed_in_double_precision_for_float32_poses():
    """Poses stored as float32 (exactly representable values) still give float64 images accurate to
    1e-14: the precision of the result must not drop to the input's storage type (float32 arithmetic
    would be off by ~1e-7 relative)."""
    d32 = np.array([[123.456, -98.765, 1.234], [0.1, 0.2, -2.9]], dtype=np.float32)
    z = km.image_coordinates(d32)
    assert z.dtype == np.float64
    for row, d in zip(z, d32.astype(np.float64), strict=True):
        assert np.allclose(row, textbook_image(*d), rtol=0, atol=1e-14)


def test_displacement_from_image_is_computed_in_double_precision_for_float32_images():
    """A float32 image (exact values) inverts in float64: e, f, v from the matrix of eq 3 evaluated here
    in double precision, to 1e-12 (float32 arithmetic would be off by ~1e-5 mm)."""
    z32 = np.array([[12.25, -7.5, 0.375, 0.875], [-40.125, 3.0625, -0.5, 0.25]], dtype=np.float32)
    back = km.displacement_from_image(z32)
    assert back.dtype == np.float64
    for row, z in zip(back, z32.astype(np.float64), strict=True):
        z1, z2, z3, z4 = z
        h = z3 * z3 + z4 * z4
        expected = (2 * (z1 * z3 + z2 * z4) / h, 2 * (z2 * z3 - z1 * z4) / h, 2 * math.atan2(z3, z4))
        assert np.allclose(row, expected, rtol=1e-12, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(displacement, st.floats(0.05, 20.0), st.sampled_from([1.0, -1.0]), point)
def test_scaled_image_maps_points_like_the_rotation_matrix(d, scale, sign, q):
    """Any nonzero multiple of the image (also negative: Z and -Z are the same displacement) maps a
    moving point to ``R(v) q + (e, f)`` with R written out here (tolerance 1e-9 mm)."""
    e, f, v = d
    z = sign * scale * textbook_image(e, f, v)
    expected = rot(v) @ np.array(q) + np.array([e, f])
    assert np.allclose(km.map_points(z, np.array(q)), expected, rtol=0, atol=1e-9)
    back = km.displacement_from_image(z)[0]
    assert np.allclose(back[:2], [e, f], rtol=0, atol=1e-9)
    assert abs(math.remainder(back[2] - v, 2 * math.pi)) < 1e-12


# -- circle vectors and the side conditions -----------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-10.0, 10.0), min_size=8, max_size=8))
def test_side_condition_forms_are_the_quadratics_of_eq7(p):
    """``p^T S p`` of the two symmetric forms equals eq 7 written out here for any 8-vector (1e-9)."""
    p = np.array(p)
    s1, s2 = km.side_condition_forms()
    assert np.array_equal(s1, s1.T) and np.array_equal(s2, s2.T)
    q1 = p[0] * p[5] + p[1] * p[4] - p[2] * p[3]
    q2 = 2 * p[0] * p[6] - p[1] * p[3] - p[2] * p[4]
    assert abs(p @ s1 @ p - q1) < 1e-9 and abs(p @ s2 @ p - q2) < 1e-9
    assert np.allclose(km.side_conditions(p), [q1, q2], rtol=0, atol=1e-9)
    assert np.allclose(km.side_conditions(np.array([p, 2 * p])), [[q1, q2], [4 * q1, 4 * q2]], atol=1e-8)


def test_dyad_from_vector_decodes_a_batch():
    """A stack of circle vectors decodes row by row to the centres and circle points they were built from
    (1e-12 mm), whatever the scale and sign of each row."""
    dyads = [((1.0, 2.0), (-3.0, 4.0), 5.0), ((-40.0, 7.5), (12.0, -0.5), 30.0)]
    ps = np.array([k * km.circle_vector(np.array(c), np.array(b), r) for k, (c, b, r) in zip((1.0, -3.0), dyads,
                                                                                            strict=True)])
    centre, moving = km.dyad_from_vector(ps)
    assert centre.shape == (2, 2) and moving.shape == (2, 2)
    assert np.allclose(centre, [c for c, _, _ in dyads], atol=1e-12)
    assert np.allclose(moving, [b for _, b, _ in dyads], atol=1e-12)


# -- conic intersections ------------------------------------------------------------------------------


def circle_conic(cx: float, cy: float, r: float) -> np.ndarray:
    """Symmetric matrix of ``(x - cx)^2 + (y - cy)^2 - r^2`` in homogeneous (x, y, 1)."""
    return np.array([[1.0, 0.0, -cx], [0.0, 1.0, -cy], [-cx, -cy, cx * cx + cy * cy - r * r]])


def affine(points: list[np.ndarray]) -> np.ndarray:
    return np.array(sorted((x[0] / x[2], x[1] / x[2]) for x in points))


def test_two_circles_meet_in_their_two_real_points_only():
    """Circles of radius 1 about (0, 0) and (1, 0) meet at (1/2, +-sqrt(3)/2); their other two common
    points are the complex circular points, which must not be returned. Tolerance 1e-12."""
    found = km.conic_intersections(circle_conic(0.0, 0.0, 1.0), circle_conic(1.0, 0.0, 1.0))
    assert len(found) == 2
    for x in found:
        assert abs(np.linalg.norm(x) - 1.0) < 1e-12
    assert np.allclose(affine(found), [[0.5, -math.sqrt(3) / 2], [0.5, math.sqrt(3) / 2]], rtol=0, atol=1e-12)


def test_disjoint_circles_have_no_real_intersection():
    """Circles of radius 1 about (0, 0) and (5, 0) do not meet: no point is returned."""
    assert km.conic_intersections(circle_conic(0.0, 0.0, 1.0), circle_conic(5.0, 0.0, 1.0)) == []


def test_a_line_pair_meets_a_circle_in_four_points():
    """The degenerate conic ``x y = 0`` (the two axes) meets the circle of radius 2 about (1, 1) where
    solved by hand: x = 0 gives y = 1 +- sqrt(3), y = 0 gives x = 1 +- sqrt(3). Tolerance 1e-10."""
    axes = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
    r3 = math.sqrt(3.0)
    expected = np.array(sorted([(0.0, 1 - r3), (0.0, 1 + r3), (1 - r3, 0.0), (1 + r3, 0.0)]))
    found = km.conic_intersections(circle_conic(1.0, 1.0, 2.0), axes)
    assert len(found) == 4
    assert np.allclose(affine(found), expected, rtol=0, atol=1e-10)


def test_a_line_pair_given_first_meets_the_circle_in_the_same_four_points():
    """Regression: with the degenerate conic first, the pencil member at lam = 0 is that line pair itself;
    its lines must be met with the other conic (before the fix no point was returned). Same hand-solved
    points as above, tolerance 1e-10."""
    axes = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
    r3 = math.sqrt(3.0)
    expected = np.array(sorted([(0.0, 1 - r3), (0.0, 1 + r3), (1 - r3, 0.0), (1 + r3, 0.0)]))
    found = km.conic_intersections(axes, circle_conic(1.0, 1.0, 2.0))
    assert len(found) == 4
    assert np.allclose(affine(found), expected, rtol=0, atol=1e-10)


def test_ellipse_and_hyperbola_points_are_found_to_full_precision_at_any_scale():
    """``x^2 + 4 y^2 = 4`` and ``x y = 1/2`` meet at x^2 in {2 +- sqrt(3)} (x^4 - 4 x^2 + 1 = 0, solved
    with numpy.roots here), y = 1 / (2 x). A conic's matrix is only defined up to scale: scaling both, or
    each on its own by up to 1e8 (regression: a hyperbola 1e4 times smaller than the ellipse was taken for
    a degenerate conic and nothing was found), gives the same points, accurate to 1e-12."""
    ellipse = np.diag([1.0, 4.0, -4.0])
    hyperbola = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, -0.5]])
    xs = list(np.roots([1.0, 0.0, -4.0, 0.0, 1.0]).real)
    expected = np.array(sorted((x, 1 / (2 * x)) for x in xs))
    for s1, s2 in ((1.0, 1.0), (1e6, 1e6), (1e-6, 1e-6), (1.0, 1e-4), (1e3, 1e-5), (1e-8, 1.0), (1.0, 1e-8)):
        found = km.conic_intersections(s1 * ellipse, s2 * hyperbola)
        assert len(found) == 4
        assert np.allclose(affine(found), expected, rtol=0, atol=1e-12)


def projective(points: list[np.ndarray]) -> np.ndarray:
    """Unit homogeneous points with the sign fixed (largest entry positive), sorted: sign-free compare."""
    fixed = [x / np.linalg.norm(x) * np.sign(x[np.argmax(np.abs(x))]) for x in points]
    return np.array(sorted(tuple(x) for x in fixed))


def test_a_line_through_two_points_of_a_line_pair_meets_it_at_both_basis_points():
    """The line z = 0 spanned by e = (1, 0, 0) and f = (0, 1, 0) meets the axes ``x y = 0`` exactly at e
    and f: there a = c = 0 and only b is not zero (before the fix no point was returned). Exact."""
    axes = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
    found = km.line_meets_conic(np.eye(3)[:2], axes)
    assert len(found) == 2
    np.testing.assert_array_equal(projective(found), [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


@pytest.mark.parametrize("exponent", [-300, -200, -160, -100, -20, 0, 20, 100, 160, 300])
def test_line_meets_conic_at_any_scale_of_the_conic(exponent):
    """``x^2 - 3 y^2 = 0`` (scaled by 10^exponent) meets the line z = 0 at (sqrt(3), +-1, 0) / 2. Scales
    down to 1e-160 used to underflow b^2 - ac (at 1e-200 to 0: one wrong point, e, twice) and up to 1e160 to overflow
    it (1e160: a c = -inf, no point); each point must be the hand-solved one to 1e-15 and never a zero vector."""
    conic = 10.0**exponent * np.diag([1.0, -3.0, 0.0])
    found = km.line_meets_conic(np.eye(3)[:2], conic)
    assert len(found) == 2
    for x in found:
        assert abs(np.linalg.norm(x) - 1.0) < 1e-15
    expected = projective([np.array([math.sqrt(3.0), -1.0, 0.0]), np.array([math.sqrt(3.0), 1.0, 0.0])])
    np.testing.assert_allclose(projective(found), expected, rtol=0, atol=1e-15)


def test_line_meets_conic_with_a_basis_point_on_it_and_at_a_tangent():
    """e = (1, 0, 0) lies on ``y (x - y) = 0`` (a = 0): the points are e and (1, 1, 0). The line z = 0
    touches ``y^2 = 0`` at e only (a = b = 0, a double root): e, twice. ``x^2 + y^2 = 0`` has no real
    point on it, and ``z^2 = 0`` contains the whole line (no isolated points). Exact up to one rounding."""
    conic = np.array([[0.0, 0.5, 0.0], [0.5, -1.0, 0.0], [0.0, 0.0, 0.0]])
    found = km.line_meets_conic(np.eye(3)[:2], conic)
    s = 1.0 / math.sqrt(2.0)
    np.testing.assert_allclose(projective(found), [[s, s, 0.0], [1.0, 0.0, 0.0]], rtol=0, atol=1e-15)
    double = km.line_meets_conic(np.eye(3)[:2], np.diag([0.0, 1.0, 0.0]))
    np.testing.assert_array_equal(projective(double), [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert km.line_meets_conic(np.eye(3)[:2], np.diag([1.0, 1.0, 0.0])) == []
    assert km.line_meets_conic(np.eye(3)[:2], np.diag([0.0, 0.0, 1.0])) == []  # the line lies in it


# -- a four-pose problem with a dyad built by hand ----------------------------------------------------

#: The hand-built dyad: moving point B (moving frame) on a circle of radius R about the fixed centre C.
C_TRUE, B_TRUE, R_TRUE = np.array([10.0, 5.0]), np.array([-20.0, 8.0]), 30.0


#: A fixed generic 8 x 4 matrix (no zero minors) whose projection onto the null space spans it.
GENERIC_8X4 = np.cos(0.7 * np.arange(32.0).reshape(8, 4) ** 2 + 0.3)


@lru_cache(maxsize=1)
def four_pose_problem() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Four poses (e, f, v) of a body whose point B_TRUE lies on the circle (C_TRUE, R_TRUE) at the
    angles t: ``R(v) B + (e, f) = C + R (cos t, sin t)`` solved for (e, f) by hand. Returns the poses,
    the constraint matrix M and the 8 x 4 basis of the four smallest eigenvalues of M^T M."""
    poses = []
    for v, t in zip((0.1, 0.5, 0.9, 1.3), (0.2, 0.7, 1.3, 1.8), strict=True):
        e, f = C_TRUE + R_TRUE * np.array([math.cos(t), math.sin(t)]) - rot(v) @ B_TRUE
        poses.append((e, f, v))
    poses = np.array(poses)
    m = km.constraint_matrix(km.image_coordinates(poses))
    _, vectors = km.family_basis(m)
    null = vectors[:, :4]
    # the eigenvectors of a four-fold zero eigenvalue are any orthonormal set of its space, and LAPACK builds
    # pick different ones (kappa, the trace's samples and its branches all depend on the pick); the space's
    # projector does not: a canonical basis from it (QR with a positive diagonal) keeps the tests' numbers
    q, r = np.linalg.qr(null @ (null.T @ GENERIC_8X4))
    return poses, m, q * np.sign(np.diag(r))


def concyclic(poses: np.ndarray, b: np.ndarray) -> float:
    """Scale-free determinant that vanishes iff the four positions of moving point b are concyclic."""
    world = np.array([rot(v) @ b + (e, f) for e, f, v in poses])
    rows = np.column_stack([np.sum(world ** 2, axis=1), world, np.ones(4)])
    return float(np.linalg.det(rows) / np.prod(np.linalg.norm(rows, axis=1)))


def true_kappa() -> float:
    """kappa = w4 / w1 of the hand-built dyad in the family basis (a projection, not a solve)."""
    _, _, basis4 = four_pose_problem()
    w = basis4.T @ km.circle_vector(C_TRUE, B_TRUE, R_TRUE)
    return float(w[3] / w[0])


def test_family_basis_spans_the_hand_built_dyad():
    """Four poses leave a 4-dimensional null space of M^T M (eigenvalues ascending, unit eigenvectors)
    that contains the hand-built dyad's circle vector (relative residual 1e-9)."""
    _, m, basis4 = four_pose_problem()
    values, vectors = km.family_basis(m)
    assert values.shape == (8,) and np.all(np.diff(values) >= 0)
    assert np.allclose(vectors.T @ vectors, np.eye(8), atol=1e-12)
    assert np.all(np.abs(values[:4]) < 1e-12 * values[-1]) and values[4] > 1e-9 * values[-1]
    p = km.circle_vector(C_TRUE, B_TRUE, R_TRUE)
    assert np.linalg.norm(p - basis4 @ (basis4.T @ p)) < 1e-9 * np.linalg.norm(p)


def test_solve_at_kappa_finds_the_hand_built_dyad():
    """At the kappa of the hand-built dyad, one unit solution is +-p/|p| (1e-9), and it decodes to the
    dyad's centre and circle point (1e-6 mm); every solution lies in the basis span with w4 = kappa w1
    and meets eq 7 (1e-9)."""
    _, m, basis4 = four_pose_problem()
    kappa = true_kappa()
    p_true = km.circle_vector(C_TRUE, B_TRUE, R_TRUE)
    p_true = p_true / np.linalg.norm(p_true)
    solutions = km.solve_at_kappa(basis4, kappa)
    assert 1 <= len(solutions) <= 4
    for p in solutions:
        assert abs(np.linalg.norm(p) - 1.0) < 1e-12
        w = basis4.T @ p
        assert np.linalg.norm(basis4 @ w - p) < 1e-9
        assert abs(w[3] - kappa * w[0]) < 1e-9
        assert np.all(np.abs(km.side_conditions(p)) < 1e-9)
    best = max(solutions, key=lambda q: abs(float(q @ p_true)))
    assert min(np.linalg.norm(best - p_true), np.linalg.norm(best + p_true)) < 1e-9
    centre, moving = km.dyad_from_vector(best)
    assert np.allclose(centre, C_TRUE, atol=1e-6) and np.allclose(moving, B_TRUE, atol=1e-6)


def test_traced_family_samples_cot_omega_and_holds_exact_dyads():
    """trace_family samples kappa = cot(omega) at the open-interval omegas written out here; every
    sample is a unit circle vector with M p = 0 and eq 7 (1e-9 relative), its centre and circle point are
    decoded from p, and its circle point makes the four positions concyclic (determinant computed here,
    without the kinematic mapping). Branch ids are 0, 1, 2, ... in order of first appearance, and
    consecutive samples of a branch are close (|cos| >= 0.9)."""
    poses, m, basis4 = four_pose_problem()
    samples = 60
    fam = km.trace_family(basis4, samples)
    omegas = [math.pi * (k + 1) / (samples + 1) for k in range(samples)]
    allowed = np.array([math.cos(o) / math.sin(o) for o in omegas])
    n = len(fam.kappa)
    assert n >= samples
    assert fam.kappa.dtype == np.float64 and fam.branch.dtype.kind == "i"
    assert fam.p.shape == (n, 8) and fam.centre.shape == (n, 2) and fam.point.shape == (n, 2)
    # each omega contributes its solutions with |p1| >= 1e-9, all of them (counted with solve_at_kappa)
    counts = [sum(abs(p[0]) >= 1e-9 for p in km.solve_at_kappa(basis4, k)) for k in allowed]
    expected = np.repeat(allowed, counts)
    assert fam.kappa.shape == expected.shape and np.allclose(fam.kappa, expected, rtol=1e-12, atol=1e-12)
    assert np.all(np.diff(np.arctan2(1.0, fam.kappa)) >= -1e-12)  # in omega order
    assert np.allclose(np.linalg.norm(fam.p, axis=1), 1.0, atol=1e-12)
    assert np.max(np.abs(m @ fam.p.T)) < 1e-9 * np.abs(m).max()
    assert np.max(np.abs(km.side_conditions(fam.p))) < 1e-9
    assert np.allclose(fam.centre, -fam.p[:, 3:5] / fam.p[:, :1], rtol=1e-12, atol=1e-9)
    assert np.allclose(fam.point, -fam.p[:, 1:3] / fam.p[:, :1], rtol=1e-12, atol=1e-9)
    assert max(abs(concyclic(poses, b)) for b in fam.point) < 1e-9
    first_seen = list(dict.fromkeys(fam.branch.tolist()))
    assert first_seen == list(range(len(first_seen)))
    for label in first_seen:
        ps = fam.p[fam.branch == label]
        assert np.all(np.abs(np.sum(ps[1:] * ps[:-1], axis=1)) >= 0.9)


def test_trace_family_drops_slider_solutions_below_the_centre_weight():
    """Solutions with |p1| below min_centre_weight are dropped (|p1| is computed here from p); with the
    weight at 0 nothing is dropped, so the default family is the weight-0 family minus those rows."""
    _, _, basis4 = four_pose_problem()
    everything = km.trace_family(basis4, 40, min_centre_weight=0.0)
    weights = np.abs(everything.p[:, 0])
    cut = float(np.median(weights))
    kept = km.trace_family(basis4, 40, min_centre_weight=cut)
    assert np.all(np.abs(kept.p[:, 0]) >= cut)
    assert len(kept.kappa) == int(np.sum(weights >= cut))
    default = km.trace_family(basis4, 40)
    assert len(default.kappa) == int(np.sum(weights >= 1e-9))


def test_a_branch_keeps_its_label_while_its_solution_moves_little():
    """Between consecutive omega samples, a solution and a previous one that are each other's closest
    (in |cos|, and at least 0.9) carry the same branch label: the greedy matching can pair neither with
    anything closer. The paper's curves are drawn and searched along these labels. Cosines computed here
    from the returned p."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 60)
    kappas = list(dict.fromkeys(fam.kappa.tolist()))
    checked = 0
    for before, after in zip(kappas[:-1], kappas[1:], strict=True):
        i_prev, i_next = np.flatnonzero(fam.kappa == before), np.flatnonzero(fam.kappa == after)
        dots = np.abs(fam.p[i_next] @ fam.p[i_prev].T)
        for a in range(len(i_next)):
            b = int(np.argmax(dots[a]))
            if dots[a, b] >= 0.9 and int(np.argmax(dots[:, b])) == a:
                assert fam.branch[i_next[a]] == fam.branch[i_prev[b]]
                checked += 1
    assert checked >= len(kappas)  # about two continuing branches per sample


def test_a_family_without_solutions_is_empty_with_the_documented_shapes():
    """With a centre weight above any unit vector's |p1| every solution is dropped: the family is empty,
    with shapes (0,), (0,), (0, 8), (0, 2), (0, 2) and float kappa / int branch ids."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 10, min_centre_weight=2.0)
    assert fam.kappa.shape == (0,) and fam.kappa.dtype == np.float64
    assert fam.branch.shape == (0,) and fam.branch.dtype.kind == "i"
    assert fam.p.shape == (0, 8) and fam.centre.shape == (0, 2) and fam.point.shape == (0, 2)


def brute_force_circle_points(poses: np.ndarray, box: float, lines: int) -> np.ndarray:
    """Circle points b in [-box, box]^2 found by scanning horizontal and vertical lines for sign changes of
    the concyclicity determinant and refining each by bisection (no kinematic mapping involved)."""
    found = []
    ts = np.linspace(-box, box, 401)
    for swap in (False, True):
        for u in np.linspace(-box, box, lines):
            def at(t: float, u: float = u, swap: bool = swap) -> np.ndarray:
                return np.array([u, t]) if swap else np.array([t, u])
            values = np.array([concyclic(poses, at(t)) for t in ts])
            for i in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0):
                lo, hi, f_lo = ts[i], ts[i + 1], values[i]
                for _ in range(40):
                    mid = 0.5 * (lo + hi)
                    f_mid = concyclic(poses, at(mid))
                    if np.sign(f_mid) == np.sign(f_lo):
                        lo, f_lo = mid, f_mid
                    else:
                        hi = mid
                found.append(at(0.5 * (lo + hi)))
    return np.array(found)


def circle_point(p: np.ndarray) -> np.ndarray:
    """The circle point b = -(p2, p3) / p1 of eq 6 (mm), written out here."""
    return -p[:, 1:3] / p[:, :1]


def test_refined_family_covers_the_brute_force_circle_point_curve():
    """refine_family with a 1 mm step on the circle point inside a 30 mm box brings every circle point of
    the brute-force scan in the box within 0.5 mm of a sample (the 80-sample trace alone misses some by
    more than 3 mm); inserted samples are exact dyads (M p = 0, 1e-9 relative), decoded from p, and the
    result is in omega order."""
    poses, m, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 80)
    box = 30.0
    keep = np.all(np.abs(circle_point(fam.p)) <= box, axis=1)
    refined = km.refine_family(basis4, fam, circle_point, keep, max_step=1.0)
    assert np.max(np.abs(m @ refined.p.T)) < 1e-9 * np.abs(m).max()
    assert np.allclose(refined.point, circle_point(refined.p), rtol=1e-12, atol=1e-9)
    assert np.allclose(refined.centre, -refined.p[:, 3:5] / refined.p[:, :1], rtol=1e-12, atol=1e-9)
    assert np.all(np.diff(np.arctan2(1.0, refined.kappa)) >= 0.0)
    scan = brute_force_circle_points(poses, box, 11)
    assert len(scan) >= 10
    assert max(np.min(np.linalg.norm(fam.point - target, axis=1)) for target in scan) > 3.0
    assert max(np.min(np.linalg.norm(refined.point - target, axis=1)) for target in scan) < 0.5


def test_refine_family_inserts_evenly_in_kappa_where_a_kept_branch_jumps():
    """Each gap of a branch with an end in keep and a jump g > max_step gets min(max_inserts,
    ceil(g / max_step) - 1) samples at evenly spaced kappa (a prefix of them if the branch is lost at a
    turning point), each continuing the branch (|cos| >= 0.95 to its neighbour, same sign as the sample
    it follows); gaps outside keep or below max_step get none. The expected kappas are computed here from
    the traced samples."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 40)
    order = np.argsort(np.arctan2(1.0, fam.kappa), kind="stable")
    fam = km._take(fam, order)
    keep = np.all(np.abs(circle_point(fam.p)) <= 30.0, axis=1)
    near = np.zeros_like(keep)
    near[int(np.argmax(np.abs(fam.p @ km.circle_vector(C_TRUE, B_TRUE, R_TRUE))))] = True
    # the last case: a 1 micron step leaves more than 200 inserts to a gap, and 200 is the default cap
    for step, max_inserts, kept in ((1.0, 200, keep), (0.5, 3, keep), (1e-3, None, near)):
        keep = kept
        kwargs = {} if max_inserts is None else {"max_inserts": max_inserts}
        max_inserts = 200 if max_inserts is None else max_inserts
        refined = km.refine_family(basis4, fam, circle_point, keep, max_step=step, **kwargs)
        assert len(refined.kappa) > len(fam.kappa) and refined.branch.dtype.kind == "i"
        pos = circle_point(fam.p)
        inserted_total = 0
        for label in np.unique(fam.branch):
            idx = np.flatnonzero(fam.branch == label)
            mine = refined.branch == label
            for j, k in zip(idx[:-1], idx[1:], strict=True):
                lo, hi = sorted((fam.kappa[j], fam.kappa[k]))
                between = np.flatnonzero(mine & (refined.kappa > lo) & (refined.kappa < hi))
                gap = float(np.linalg.norm(pos[k] - pos[j]))
                if not (keep[j] or keep[k]) or gap <= step:
                    assert between.size == 0
                    continue
                count = min(max_inserts, math.ceil(gap / step) - 1)
                expected = [fam.kappa[j] + (fam.kappa[k] - fam.kappa[j]) * (i + 1) / (count + 1)
                            for i in range(count)]
                got = refined.kappa[between]
                assert 0 < got.size <= count
                assert np.allclose(np.sort(got), np.sort(expected[:got.size]), rtol=0, atol=1e-12)
                chain = refined.p[np.sort(np.concatenate([between, np.flatnonzero(mine & np.isin(
                    refined.kappa, [fam.kappa[j], fam.kappa[k]]))]))]
                # measured: >= 0.99999 between inserts, >= 0.968 across the one wider step of a gap
                assert np.all(np.abs(np.sum(chain[1:] * chain[:-1], axis=1)) >= 0.95)
                # inserted vectors keep the sign of the sample they continue (no flips along the branch)
                assert np.all(np.sum(chain[1:-1] * chain[:-2], axis=1) > 0.0)
                inserted_total += got.size
        assert inserted_total == len(refined.kappa) - len(fam.kappa)


def test_refine_family_leaves_a_family_outside_keep_untouched():
    """With no sample in keep nothing is inserted: the same samples come back, in omega order."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 30)
    n = len(fam.kappa)
    backwards = np.lexsort((np.arange(n), -np.arctan2(1.0, fam.kappa)))  # omega descending, ties kept
    out = km.refine_family(basis4, km._take(fam, backwards), circle_point, np.zeros(n, bool), 1e-3)
    for name in ("kappa", "branch", "p", "centre", "point"):
        assert np.array_equal(getattr(out, name), getattr(fam, name)), name


def bracket_of_true_dyad(fam: km.DyadFamily) -> tuple[int, int]:
    """Indices of the consecutive samples of the hand-built dyad's branch whose kappas bracket its kappa."""
    p_true = km.circle_vector(C_TRUE, B_TRUE, R_TRUE)
    j = int(np.argmax(np.abs(fam.p @ p_true)))
    idx = np.flatnonzero(fam.branch == fam.branch[j])
    k_true = true_kappa()
    for lo, hi in zip(idx[:-1], idx[1:], strict=True):
        if (fam.kappa[lo] - k_true) * (fam.kappa[hi] - k_true) < 0:
            return int(lo), int(hi)
    raise AssertionError("no bracket")


def centre_x_error(p: np.ndarray) -> float:
    """x of the centre (eq 6, written out) minus the hand-built centre's x, mm."""
    return float(-p[3] / p[0] - C_TRUE[0])


def test_bisection_on_a_branch_lands_on_the_hand_built_dyad():
    """Bisecting x(centre) - C_TRUE.x between the traced samples of the hand-built dyad's branch that
    bracket it returns the dyad itself: centre and circle point within 1e-6 mm, whichever end of the bracket
    is given first; the kappa returned is that of the vector returned (w4 / w1 in the basis, 1e-12 relative)
    and the hand-built dyad's within 1e-6 relative. Not closer: the basis is an eigenvector set of M^T M
    for a four-fold zero eigenvalue, accurate to about eps * cond(M)^2, so the exact dyad's projection onto
    it (true_kappa) moves by ~5e-8 between LAPACK builds while the dyad found stays within 2e-9 mm."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 80)
    lo, hi = bracket_of_true_dyad(fam)
    assert centre_x_error(fam.p[lo]) * centre_x_error(fam.p[hi]) < 0
    for a, b in ((lo, hi), (hi, lo)):
        kappa, p = km.bisect_on_branch(basis4, centre_x_error, fam.kappa[a], fam.p[a], fam.kappa[b], fam.p[b])
        w = basis4.T @ p
        assert kappa == pytest.approx(w[3] / w[0], rel=1e-12)
        assert abs(kappa - true_kappa()) < 1e-6 * abs(true_kappa())
        centre, moving = km.dyad_from_vector(p)
        assert np.allclose(centre, C_TRUE, atol=1e-6) and np.allclose(moving, B_TRUE, atol=1e-6)


def test_a_short_bisection_returns_the_better_end_of_its_last_bracket():
    """With 0-4 iterations the result is the end of the last bracket with the smaller |func|. Expected
    from a brute-force scan: the branch's solutions at the 2^n + 1 evenly spaced kappas of the bracket
    (each the solution closest in direction to the hand-built dyad), the sign change among them, and the
    better of its two ends (kappa exact to 1e-12, p to 1e-9 up to sign)."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 80)
    lo, hi = bracket_of_true_dyad(fam)
    k0, k1 = fam.kappa[lo], fam.kappa[hi]
    p_true = km.circle_vector(C_TRUE, B_TRUE, R_TRUE)
    for iterations in range(5):
        n = 2 ** iterations
        grid = [k0 + (k1 - k0) * i / n for i in range(n + 1)]
        ps = [fam.p[lo]] + [max(km.solve_at_kappa(basis4, k), key=lambda q: abs(float(q @ p_true)))
                            for k in grid[1:-1]] + [fam.p[hi]]
        fs = [centre_x_error(q) for q in ps]
        i = next(i for i in range(n) if fs[i] * fs[i + 1] <= 0)
        best = i if abs(fs[i]) <= abs(fs[i + 1]) else i + 1
        kappa, p = km.bisect_on_branch(basis4, centre_x_error, k0, fam.p[lo], k1, fam.p[hi], iterations=iterations)
        assert abs(kappa - grid[best]) < 1e-12
        assert min(np.linalg.norm(p - ps[best]), np.linalg.norm(p + ps[best])) < 1e-9


def unit(angle: float) -> np.ndarray:
    return np.array([math.cos(angle), math.sin(angle), 0.0])


def test_branch_matching_pairs_each_solution_with_its_closest_previous_branch():
    """Greedy matching by |cos|: solutions 0.1 rad from branch 7 and 0.2 rad from branch 3 (signs
    ignored) take those labels even when the other branch is also within the 0.9 cosine threshold
    (cos 0.3 = 0.955); a branch is used once; a solution farther than acos(0.9) = 0.451 rad from every
    free branch starts a new one (-1). Angles chosen here so the cosines are known in closed form."""
    previous = [(unit(0.0), 7), (unit(0.3), 3)]
    assert km._match_branches([unit(0.1), -unit(0.5)], previous) == [7, 3]
    assert km._match_branches([-unit(0.5), unit(0.1)], previous) == [3, 7]
    # one solution near both branches: it keeps the closer one only
    assert km._match_branches([unit(0.05)], previous) == [7]
    assert km._match_branches([unit(0.26)], previous) == [3]
    # the closer solution wins the branch; the other one, 0.46 rad from branch 3, starts a new branch
    assert km._match_branches([unit(-0.16), unit(-0.02)], previous) == [-1, 7]
    assert km._match_branches([unit(1.0), unit(2.0)], previous) == [-1, -1]
    assert km._match_branches([unit(0.0)], []) == [-1]
    assert km._match_branches([], previous) == []
    # the threshold is a parameter: at 0.99 (8.1 degrees) a 0.2 rad neighbour is not matched
    assert km._match_branches([unit(0.5)], previous, min_dot=0.99) == [-1]


# -- double precision for float32 inputs, scale invariance, tangency, the Newton polish -----------------


def test_circle_vector_is_computed_in_double_precision_for_float32_input():
    """A float32 centre and circle point (exact float32 values) give the float64 vector of eq 6 written
    out here in double precision: p = (1, -x, -y, -cx, -cy, cx y - cy x, (cx x + cy y) / 2,
    (cx^2 + cy^2 - r^2 + x^2 + y^2) / 4), to 1e-12 relative (float32 arithmetic is off by ~1e-7)."""
    c32 = np.array([123.456, -98.765], dtype=np.float32)
    b32 = np.array([-12.345, 67.891], dtype=np.float32)
    r = 37.123
    for centre, point_ in ((c32, b32), (c32, b32.astype(np.float64)), (c32.astype(np.float64), b32)):
        p = km.circle_vector(centre, point_, r)
        assert p.dtype == np.float64
        cx, cy = (float(v) for v in c32)
        x, y = (float(v) for v in b32)
        expected = [1.0, -x, -y, -cx, -cy, cx * y - cy * x, (cx * x + cy * y) / 2,
                    (cx * cx + cy * cy - r * r + x * x + y * y) / 4]
        assert np.allclose(p, expected, rtol=1e-12, atol=0)


def test_dyad_from_vector_divides_in_double_precision_for_float32_input():
    """A float32 circle vector (exact values) decodes in float64: centre -(p4, p5) / p1 and point
    -(p2, p3) / p1 computed here in double precision, to 1e-14 relative (1/3 in float32 is off by 1e-8)."""
    p32 = np.array([3.0, 1.0, -2.0, 7.0, 5.0, 0.0, 0.0, 0.0], dtype=np.float32)
    centre, moving = km.dyad_from_vector(p32)
    assert centre.dtype == np.float64 and moving.dtype == np.float64
    assert np.allclose(centre, [-7.0 / 3.0, -5.0 / 3.0], rtol=1e-14, atol=0)
    assert np.allclose(moving, [-1.0 / 3.0, 2.0 / 3.0], rtol=1e-14, atol=0)


def test_map_points_is_computed_in_double_precision_for_float32_images():
    """A float32 image (exact values) maps points like the float64 matrix of eq 3 evaluated here
    (1e-12 mm); float32 arithmetic would be off by ~1e-5 mm."""
    z32 = np.array([12.3, -7.7, 0.3, 0.9], dtype=np.float32)
    q = np.array([[10.1, -3.3], [-45.6, 78.9]])
    z1, z2, z3, z4 = (float(v) for v in z32)
    h = z3 * z3 + z4 * z4
    rot_ = np.array([[z4 * z4 - z3 * z3, -2 * z4 * z3], [2 * z4 * z3, z4 * z4 - z3 * z3]]) / h
    shift = np.array([2 * (z1 * z3 + z2 * z4), 2 * (z2 * z3 - z1 * z4)]) / h
    moved = km.map_points(z32, q)
    assert moved.dtype == np.float64
    assert np.allclose(moved, q @ rot_.T + shift, rtol=0, atol=1e-12)


def test_map_points_returns_float64_whatever_the_type_of_the_points():
    """Points given as float32, integers or long double are taken as float64: the result is float64 and
    equal (1e-12 mm) to mapping the same points given as float64 (R(v) q + (e, f), v = 0.5, e = 3, f = -2)."""
    z = textbook_image(3.0, -2.0, 0.5)
    q = np.array([[1.0, 2.0], [-3.0, 4.0]])
    expected = q @ rot(0.5).T + np.array([3.0, -2.0])
    for typed in (q.astype(np.float32), q.astype(np.int64), q.astype(np.longdouble)):
        moved = km.map_points(z, typed)
        assert moved.dtype == np.float64
        assert np.allclose(moved, expected, rtol=0, atol=1e-12)


def test_constraint_matrix_is_computed_in_double_precision_for_float32_images():
    """A float32 image (exact values) gives the float64 row of eq 11 written out here, to 1e-12
    relative; products formed in float32 would be off by ~1e-7."""
    z32 = np.array([[12.3, -7.7, 0.3, 0.9], [-1.1, 2.2, -0.7, 0.6]], dtype=np.float32)
    m = km.constraint_matrix(z32)
    assert m.dtype == np.float64 and m.shape == (2, 8)
    for row, z in zip(m, z32.astype(np.float64), strict=True):
        z1, z2, z3, z4 = z
        expected = [z1 * z1 + z2 * z2, z1 * z3 - z2 * z4, z2 * z3 + z1 * z4, z1 * z3 + z2 * z4,
                    z2 * z3 - z1 * z4, z3 * z4, z3 * z3 - z4 * z4, z3 * z3 + z4 * z4]
        assert np.allclose(row, expected, rtol=1e-12, atol=0)


def test_side_conditions_are_computed_in_double_precision_for_float32_vectors():
    """A float32 8-vector (exact values) gives the float64 values of eq 7 written out here, to 1e-12
    relative (float32 products and differences would be off by ~1e-7)."""
    p32 = np.array([1.1, -2.3, 3.7, 0.9, -4.1, 5.3, 0.7, 2.9], dtype=np.float32)
    p = p32.astype(np.float64)
    q1 = p[0] * p[5] + p[1] * p[4] - p[2] * p[3]
    q2 = 2 * p[0] * p[6] - p[1] * p[3] - p[2] * p[4]
    values = km.side_conditions(p32)
    assert values.dtype == np.float64
    assert np.allclose(values, [q1, q2], rtol=1e-12, atol=0)


def test_negated_circle_meets_the_axes_in_its_four_axis_points():
    """A conic is defined up to any nonzero scale, also a negative one: ``-(x^2 + y^2 - 1)`` and the axes
    ``x y = 0`` meet at (+-1, 0) and (0, +-1). Each returned point is a unit vector on both conics
    (1e-12) and the affine points are those four (1e-12)."""
    circle = -np.diag([1.0, 1.0, -1.0])
    axes = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
    found = km.conic_intersections(circle, axes)
    assert len(found) == 4
    for x in found:
        assert abs(np.linalg.norm(x) - 1.0) < 1e-12
        assert abs(x @ circle @ x) < 1e-12 and abs(x @ axes @ x) < 1e-12
    assert np.allclose(affine(found), [[-1.0, 0.0], [0.0, -1.0], [0.0, 1.0], [1.0, 0.0]], rtol=0, atol=1e-12)


def test_a_nearly_degenerate_parabola_keeps_its_point_near_the_origin():
    """The parabola ``y w = x^2 + d w^2`` with d = 1e-100 meets the axes ``x y = 0`` at (0, d) and at its
    point at infinity (0 : 1 : 0) (on y = 0, ``x^2 = -d`` has no real root). The finite point is found
    (as a unit vector, 1e-12, with y / w = d to 1e-12 relative): its homogeneous coordinates are
    (0, d, 1), huge when scaled so that w is small."""
    d = 1e-100
    parabola = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -0.5], [0.0, -0.5, d]])
    axes = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
    found = km.conic_intersections(parabola, axes)
    assert len(found) == 2
    for x in found:
        assert abs(np.linalg.norm(x) - 1.0) < 1e-12
    finite = [x for x in found if abs(x[2]) > 0.5]
    at_infinity = [x for x in found if abs(x[2]) <= 0.5]
    assert len(finite) == 1 and len(at_infinity) == 1
    assert finite[0][0] == 0.0 and abs(finite[0][1] / finite[0][2] - d) < 1e-12 * d
    assert np.allclose(np.abs(at_infinity[0]), [0.0, 1.0, 0.0], rtol=0, atol=1e-12)


def test_a_circle_tangent_to_a_line_of_the_pair_gives_the_point_of_contact():
    """The circle ``(x - 1)^2 + y^2 = 1`` touches the line x = 0 at the origin; with the line pair
    ``x w = 0`` (x = 0 and the line at infinity, which meets the circle only in the complex circular
    points) the only real common point is the origin, a double root of the line's quadratic. It must be
    returned (every returned point is the origin, to 1e-12), not dropped as if the discriminant were
    negative."""
    circle = circle_conic(1.0, 0.0, 1.0)
    xw = np.array([[0.0, 0.0, 0.5], [0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    found = km.conic_intersections(circle, xw)
    assert len(found) >= 1
    for x in found:
        assert np.allclose(np.abs(x), [0.0, 0.0, 1.0], rtol=0, atol=1e-12)


def test_ellipse_and_hyperbola_with_a_vanishing_quadratic_pencil_coefficient():
    """``x^2 + 4 y^2 = 3`` and ``x^2 - y^2 = 1`` meet at (+-sqrt(1.4), +-sqrt(0.4)) (subtracting: 5 y^2 = 2).
    Their pencil ``det(c1 + lam c2) = -(1 + lam)(4 - lam)(-3 - lam)`` has a vanishing lam^2 coefficient
    (1 - 4 + 3), while c2 itself is regular: all four points are found, to 1e-12."""
    found = km.conic_intersections(np.diag([1.0, 4.0, -3.0]), np.diag([1.0, -1.0, -1.0]))
    a, b = math.sqrt(1.4), math.sqrt(0.4)
    assert len(found) == 4
    assert np.allclose(affine(found), [[-a, -b], [-a, b], [a, -b], [a, b]], rtol=0, atol=1e-12)


def test_line_basis_is_orthonormal_on_the_line_at_any_scale():
    """``_line_basis`` returns two unit, orthogonal points on the line (1e-12), and a line's coefficients are
    homogeneous: scaling it gives the same basis (1e-12), up to 8e153 for the line x + y = 0 (whose
    cross products then still have squares summing below the float64 limit)."""
    cases = [(np.array([3.0, -4.0, 1.0]), 1e150), (np.array([1.0, 1.0, 0.0]), 8e153),
             (np.array([0.2, -7.0, 5.0]), 1e150)]
    for line, big in cases:
        unit_line = line / np.linalg.norm(line)
        for scale in (1.0, 1e-3, big):
            e, f = km._line_basis(scale * line)
            assert abs(np.linalg.norm(e) - 1.0) < 1e-12 and abs(np.linalg.norm(f) - 1.0) < 1e-12
            assert abs(e @ f) < 1e-12
            assert abs(e @ unit_line) < 1e-12 and abs(f @ unit_line) < 1e-12
            assert np.allclose(np.array([e, f]), km._line_basis(line), rtol=0, atol=1e-12)


def newton_on_sphere(c1: np.ndarray, c2: np.ndarray, x: np.ndarray) -> np.ndarray:
    """One Newton step of ``x^T c x = 0`` for both conics with the step orthogonal to x, then x / |x|."""
    jac = np.array([2 * c1 @ x, 2 * c2 @ x, x])
    step = np.linalg.solve(jac, np.array([-(x @ c1 @ x), -(x @ c2 @ x), 0.0]))
    y = x + step
    return y / np.linalg.norm(y)


def test_polish_returns_to_a_transversal_intersection():
    """From a unit vector 1e-4 away from the intersection (1/2, sqrt(3)/2) of the unit circles about (0, 0)
    and (1, 0), the default polish lands on the exact point to 1e-12 (Newton converges quadratically)."""
    c1, c2 = circle_conic(0.0, 0.0, 1.0), circle_conic(1.0, 0.0, 1.0)
    exact = np.array([0.5, math.sqrt(3) / 2, 1.0])
    exact /= np.linalg.norm(exact)
    start = exact + 1e-4 * np.array([1.0, -2.0, 0.5])
    start /= np.linalg.norm(start)
    x = km._polish(c1, c2, start)
    assert np.allclose(x * np.sign(x[2]), exact, rtol=0, atol=1e-12)


def test_polish_does_two_newton_steps_by_default():
    """The default of ``steps`` is 2: from a start 0.05 away (not converged after two steps), the result
    equals two Newton steps on the sphere written out here (1e-14), and differs from three."""
    c1, c2 = circle_conic(0.0, 0.0, 1.0), circle_conic(1.0, 0.0, 1.0)
    start = np.array([0.5, math.sqrt(3) / 2, 1.0]) + 0.05 * np.array([1.0, -2.0, 0.5])
    start /= np.linalg.norm(start)
    two = newton_on_sphere(c1, c2, newton_on_sphere(c1, c2, start))
    three = newton_on_sphere(c1, c2, two)
    assert np.linalg.norm(two - three) > 1e-9
    assert np.allclose(km._polish(c1, c2, start), two, rtol=0, atol=1e-14)


# -- batching: a stack of samples solves each sample exactly as it would be solved alone ---------------------


def test_a_stack_of_kappas_gives_each_kappa_the_bits_it_gets_alone():
    """trace_family and refine_family solve many kappas in one stacked call; every sample must come out
    bit for bit as a call with that kappa alone (np.array_equal, not a tolerance: the shipped builds are
    byte-identical only if no stacked operation mixes samples). Checked on the hand-built problem and on a
    generic orthonormal basis, in stacks with the same kappa at different places."""
    rng = np.random.default_rng(3)
    bases = [four_pose_problem()[2], np.linalg.qr(rng.normal(size=(8, 4)))[0]]
    kappas = list(np.linspace(-4.0, 4.0, 37)) + [true_kappa(), 0.0, 1e-9, -250.0]
    for basis4 in bases:
        alone = [km.solve_at_kappa(basis4, k) for k in kappas]
        assert sum(len(found) for found in alone) > 40  # the stacks below hold real solutions
        for order in (np.arange(len(kappas)), rng.permutation(len(kappas))):
            stacked = km._solve_many(basis4, [kappas[i] for i in order])
            for i, found in zip(order, stacked, strict=True):
                assert len(found) == len(alone[i])
                assert all(np.array_equal(p, q) for p, q in zip(found, alone[i], strict=True))


def test_looking_ahead_does_not_change_the_bisection():
    """bisect_on_branch solves the midpoints of its next steps together (a tree of 2^lookahead - 1 kappas) and
    walks the tree: for every lookahead and iteration count the result is bit for bit that of plain bisection
    (lookahead 1, one solve per step), and the function is evaluated at the same points in the same order."""
    _, _, basis4 = four_pose_problem()
    fam = km.trace_family(basis4, 80)
    lo, hi = bracket_of_true_dyad(fam)
    for iterations in (0, 1, 3, 7, 48):
        runs = []
        for lookahead in (1, 2, 4, 5):
            seen: list[float] = []

            def func(p: np.ndarray, seen: list[float] = seen) -> float:
                seen.append(centre_x_error(p))
                return seen[-1]

            kappa, p = km.bisect_on_branch(basis4, func, fam.kappa[lo], fam.p[lo], fam.kappa[hi], fam.p[hi],
                                           iterations=iterations, lookahead=lookahead)
            runs.append((kappa, p, seen))
        kappa, p, seen = runs[0]
        assert len(seen) == 2 + iterations
        for other in runs[1:]:
            assert other[0] == kappa and np.array_equal(other[1], p) and other[2] == seen


def test_polishing_a_stack_keeps_each_point_as_if_polished_alone():
    """_polish_many steps many points together; a point whose Newton system is singular (here c2 = c1, and
    c2 = 0) keeps its last estimate as _polish does, and does not disturb the others (bitwise)."""
    rng = np.random.default_rng(4)
    c1 = rng.normal(size=(6, 3, 3))
    c1 = c1 + c1.transpose(0, 2, 1)
    c2 = rng.normal(size=(6, 3, 3))
    c2 = c2 + c2.transpose(0, 2, 1)
    c2[1], c2[4] = c1[1], 0.0
    x = rng.normal(size=(6, 3))
    x /= np.linalg.norm(x, axis=1)[:, None]
    many = km._polish_many(c1, c2, x)
    for i in range(6):
        assert np.array_equal(many[i], km._polish(c1[i], c2[i], x[i]))
    assert np.array_equal(many[1], x[1]) and np.array_equal(many[4], x[4])  # singular from the first step
    assert not np.array_equal(many[0], x[0])
