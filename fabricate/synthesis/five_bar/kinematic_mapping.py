"""Planar kinematic mapping and the dyad-family synthesis of the five-bar NCG finger (its paper's eqs 1-14).

A planar displacement (rotation ``v``, translation ``(e, f)``) maps to homogeneous image coordinates
``Z = (Z1, Z2, Z3, Z4)`` (eq 2). A point ``b`` fixed in the moving frame stays on a circle of the fixed
frame (centre ``a``) over a set of displacements iff the 8-vector ``p`` of the circle (eq 6) satisfies
``M p = 0`` with one row of ``M`` per displacement (eq 11), plus two quadratic conditions (eq 7) which
say that ``p`` really comes from a circle point and a centre point.

With ``n`` poses ``M^T M`` has ``8 - n`` vanishing eigenvalues. Following the paper (eq 13) the
solution is spanned by the four eigenvectors of the smallest eigenvalues,
``p = alpha v1 + beta v2 + gamma v3 + kappa v4``; ``p`` is homogeneous, so we fix its scale by
``alpha``'s chart of the pencil: for each ``kappa = cot(omega)`` (eq 14) the coefficients
``(alpha : beta : gamma)`` with ``w = (alpha, beta, gamma, kappa * alpha)`` must lie on two conics in
the projective plane. Their (up to four) real intersections are found by the degenerate member of the
conic pencil, so every point of the curve whose ``w4 / w1`` equals ``kappa`` is found, none is missed
by a chart boundary except the single plane ``w1 = 0``.

Everything here is pure numpy; lengths in mm, angles in radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Index pairs (0-based) and coefficients of the two quadratic side conditions of eq 7:
#: ``p1 p6 + p2 p5 - p3 p4 = 0`` and ``2 p1 p7 - p2 p4 - p3 p5 = 0``.
_SIDE_CONDITIONS = (
    ((0, 5, 1.0), (1, 4, 1.0), (2, 3, -1.0)),
    ((0, 6, 2.0), (1, 3, -1.0), (2, 4, -1.0)),
)


def image_coordinates(displacements: np.ndarray) -> np.ndarray:
    """Kinematic image (eq 2) of planar displacements.

    Parameters
    ----------
    displacements : (n, 3) array
        Rows ``(e, f, v)``: translation (mm) and rotation (rad) of the moving frame in the fixed one,
        i.e. a moving point ``x`` lands at ``R(v) x + (e, f)``.

    Returns
    -------
    (n, 4) array
        ``(Z1, Z2, Z3, Z4)`` normalised so that ``Z3**2 + Z4**2 = 1``.
    """
    d = np.atleast_2d(np.asarray(displacements, dtype=np.float64))
    e, f, v = d[:, 0], d[:, 1], d[:, 2]
    s, c = np.sin(0.5 * v), np.cos(0.5 * v)
    return np.stack([0.5 * (e * s - f * c), 0.5 * (e * c + f * s), s, c], axis=-1)


def displacement_from_image(z: np.ndarray) -> np.ndarray:
    """Inverse of :func:`image_coordinates` (any scale of ``Z``); returns (n, 3) rows ``(e, f, v)``.

    The matrix of eq 3 gives ``e = 2 (Z1 Z3 + Z2 Z4)`` and ``f = 2 (Z2 Z3 - Z1 Z4)`` for
    ``Z3**2 + Z4**2 = 1``; a general scale divides by ``Z3**2 + Z4**2``.
    """
    z = np.atleast_2d(np.asarray(z, dtype=np.float64))
    z1, z2, z3, z4 = z.T
    norm = z3 * z3 + z4 * z4
    e = 2.0 * (z1 * z3 + z2 * z4) / norm
    f = 2.0 * (z2 * z3 - z1 * z4) / norm
    v = 2.0 * np.arctan2(z3, z4)
    return np.stack([e, f, v], axis=-1)


def map_points(z: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply the displacement with image ``z`` (4,) to moving-frame points (n, 2) by eq 3."""
    z1, z2, z3, z4 = np.asarray(z, dtype=np.float64)
    h = z3 * z3 + z4 * z4
    mat = np.array([[z4 * z4 - z3 * z3, -2.0 * z4 * z3, 2.0 * (z1 * z3 + z2 * z4)],
                    [2.0 * z4 * z3, z4 * z4 - z3 * z3, 2.0 * (z2 * z3 - z1 * z4)]]) / h
    pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
    return pts @ mat[:, :2].T + mat[:, 2]


def constraint_matrix(z: np.ndarray) -> np.ndarray:
    """Matrix ``M`` of eq 11, one row per displacement image (n, 4) -> (n, 8)."""
    z = np.atleast_2d(np.asarray(z, dtype=np.float64))
    z1, z2, z3, z4 = z.T
    return np.stack([z1 * z1 + z2 * z2, z1 * z3 - z2 * z4, z2 * z3 + z1 * z4, z1 * z3 + z2 * z4,
                     z2 * z3 - z1 * z4, z3 * z4, z3 * z3 - z4 * z4, z3 * z3 + z4 * z4], axis=-1)


def circle_vector(centre: np.ndarray, moving_point: np.ndarray, radius: float) -> np.ndarray:
    """The 8-vector ``p`` (eq 6) of a dyad: ``moving_point`` (moving frame) on a circle about ``centre``.

    Derivation (our own; the printed eq 9 has sign and index slips): with the circle
    ``a0 (X^2 + Y^2) + 2 a1 X + 2 a2 Y + a3 = 0`` the centre is ``(-a1 / a0, -a2 / a0)``; we take
    ``a0 = 1/2``, so ``a1 = -cx / 2``, ``a2 = -cy / 2`` and ``a3 = (|c|^2 - r^2) / 2``.
    """
    cx, cy = np.asarray(centre, dtype=np.float64)
    x, y = np.asarray(moving_point, dtype=np.float64)
    a0, a1, a2 = 0.5, -0.5 * cx, -0.5 * cy
    a3 = 0.5 * (cx * cx + cy * cy - radius * radius)
    return np.array([2 * a0, -2 * a0 * x, -2 * a0 * y, 2 * a1, 2 * a2, 2 * (a2 * x - a1 * y),
                     -(a1 * x + a2 * y), 0.5 * (a3 + a0 * (x * x + y * y))])


def dyad_from_vector(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre (fixed frame) and circle point (moving frame) of circle vector(s) ``p`` (..., 8).

    From eq 6: ``p1 = 2 a0``, ``p2 = -2 a0 x``, ``p3 = -2 a0 y``, ``p4 = 2 a1``, ``p5 = 2 a2``, so
    ``b = -(p2, p3) / p1`` and ``a = -(p4, p5) / p1`` (independent of the scale of ``p``).
    """
    p = np.asarray(p, dtype=np.float64)
    centre = -p[..., 3:5] / p[..., :1]
    point = -p[..., 1:3] / p[..., :1]
    return centre, point


def _forms() -> tuple[np.ndarray, np.ndarray]:
    forms = []
    for terms in _SIDE_CONDITIONS:
        s = np.zeros((8, 8))
        for i, j, c in terms:
            s[i, j] += 0.5 * c
            s[j, i] += 0.5 * c
        s.setflags(write=False)
        forms.append(s)
    return forms[0], forms[1]


#: :func:`side_condition_forms`, built once: :func:`solve_at_kappa` runs hundreds of times per synthesis.
_FORMS = _forms()


def side_condition_forms() -> tuple[np.ndarray, np.ndarray]:
    """Symmetric 8x8 matrices ``S`` with ``p^T S p`` equal to the two conditions of eq 7 (fresh copies)."""
    return _FORMS[0].copy(), _FORMS[1].copy()


def side_conditions(p: np.ndarray) -> np.ndarray:
    """Values of the two conditions of eq 7 for vector(s) ``p`` (..., 8) -> (..., 2)."""
    p = np.asarray(p, dtype=np.float64)
    return np.stack([p[..., 0] * p[..., 5] + p[..., 1] * p[..., 4] - p[..., 2] * p[..., 3],
                     2 * p[..., 0] * p[..., 6] - p[..., 1] * p[..., 3] - p[..., 2] * p[..., 4]], -1)


_CUBIC_SAMPLES = np.array([-1.0, 0.0, 1.0, 2.0])
#: Maps det(c1 + t c2) at the four samples to the cubic's coefficients (highest power first).
_CUBIC_FIT = np.linalg.inv(np.vander(_CUBIC_SAMPLES, 4))

# Batching. The solver below works on stacks: many conic pairs (all kappa samples of a trace), many lines,
# many points at once, so numpy's per-call overhead is paid once per stack instead of once per sample. Each
# stacked call is one that numpy evaluates matrix by matrix with the same kernel a single call uses
# (np.matmul: one BLAS gemm/gemv/dot per matrix; np.linalg det/eigvals/eigh/solve: one LAPACK call per matrix)
# or element by element (ufuncs), so every sample's result is the same bits as solving it alone.


def _dots(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Row-wise ``x[i] @ y[i]`` of (k, n) arrays, each the 1-D dot product numpy computes for one pair."""
    out: np.ndarray = np.matmul(x[:, None, :], y[:, :, None])[:, 0, 0]
    return out


def _norms(x: np.ndarray) -> np.ndarray:
    """Row-wise ``np.linalg.norm`` of a (k, n) array: ``sqrt(x . x)`` as numpy computes it for one row."""
    out: np.ndarray = np.sqrt(_dots(x, x))
    return out


def _vec_mat(x: np.ndarray, mats: np.ndarray) -> np.ndarray:
    """Row-wise ``x[i] @ mats[i]`` (vector times matrix) of (k, 3) and (k, 3, 3)."""
    out: np.ndarray = np.matmul(x[:, None, :], mats)[:, 0, :]
    return out


def _mat_vec(mats: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Row-wise ``mats[i] @ x[i]`` (matrix times vector) of (k, m, n) and (k, n)."""
    out: np.ndarray = np.matmul(mats, x[:, :, None])[:, :, 0]
    return out


def conic_intersections(c1: np.ndarray, c2: np.ndarray) -> list[np.ndarray]:
    """Real intersection points of two conics ``x^T C x = 0`` in the projective plane.

    Parameters
    ----------
    c1, c2 : (3, 3) symmetric arrays

    Returns
    -------
    list of (3,) unit vectors
        Homogeneous points (sign arbitrary), polished by Newton's method.

    Notes
    -----
    A real root ``lam`` of ``det(c1 + lam c2) = 0`` gives a degenerate conic of the pencil; when it is
    indefinite it is a pair of real lines through every real intersection point, and each line meets
    ``c1`` (``c2`` when ``|lam| < 1``: on the lines ``c1 = -lam c2``, and at ``lam = 0`` the lines lie in
    ``c1``) in the roots of a quadratic. Each conic is normalised on its own, so the result does not depend
    on their scales.
    """
    c1 = np.asarray(c1, dtype=np.float64)
    c2 = np.asarray(c2, dtype=np.float64)
    return _conic_intersections_many(c1[None], c2[None])[0]


def _conic_intersections_many(c1s: np.ndarray, c2s: np.ndarray) -> list[list[np.ndarray]]:
    """:func:`conic_intersections` of each pair of a stack (k, 3, 3), (k, 3, 3), solved together."""
    # each conic is only defined up to scale: normalise them separately, so that neither looks degenerate
    c1s = c1s / np.maximum(np.abs(c1s).max(axis=(1, 2)), 1e-300)[:, None, None]
    c2s = c2s / np.maximum(np.abs(c2s).max(axis=(1, 2)), 1e-300)[:, None, None]
    # the cubic through four exact samples of det(c1 + lam c2)
    dets = np.linalg.det(c1s[:, None] + _CUBIC_SAMPLES[None, :, None, None] * c2s[:, None])
    coefficients = np.matmul(_CUBIC_FIT, dets[:, :, None])[:, :, 0]
    lead = coefficients[:, 0]
    at_infinity = np.abs(lead) < 1e-14  # c2 itself degenerate: it is the member at infinity
    roots: list[list[complex]] = [[] for _ in range(len(c1s))]
    for i in np.flatnonzero(at_infinity).tolist():
        roots[i] = np.concatenate([[np.inf], np.roots(coefficients[i])]).tolist()
    cubic = np.flatnonzero(~at_infinity)
    if cubic.size:  # eigenvalues of the companion matrices (np.roots without its overhead)
        top = -coefficients[cubic, 1:] / lead[cubic, None]
        companion = np.zeros((cubic.size, 3, 3))
        companion[:, 0] = top
        companion[:, 1, 0] = companion[:, 2, 1] = 1.0
        for i, r in zip(cubic.tolist(), np.linalg.eigvals(companion).tolist(), strict=True):
            roots[i] = r
    # plain Python numbers for the roots: numpy's per-scalar overhead would dominate
    lams = [[r.real for r in rs if _isinf(r) or abs(r.imag) <= 1e-9 * max(1.0, abs(r))] for rs in roots]
    # the first real root of each pair whose member is indefinite (a pair of real lines), tried in rounds
    chosen: dict[int, tuple[float, np.ndarray, np.ndarray]] = {}
    tried = {i: 0 for i, ls in enumerate(lams) if ls}
    while tried:
        index = list(tried)
        lam = np.array([lams[i][tried[i]] for i in index])
        infinite = np.isinf(lam)
        members = c1s[index] + np.where(infinite, 0.0, lam)[:, None, None] * c2s[index]
        members[infinite] = c2s[index][infinite]
        values, vectors = np.linalg.eigh(members)
        # the two eigenvalues of largest magnitude (np.argsort's order) and their eigenvectors
        order = np.argsort(np.abs(values), axis=-1)[:, 1:]
        rows = np.arange(len(index))[:, None]
        values = values[rows, order]
        vectors = vectors.transpose(0, 2, 1)[rows, order]
        indefinite = (~(values[:, 0] * values[:, 1] >= 0.0)).tolist()
        for k, i in enumerate(index):
            if indefinite[k]:
                chosen[i] = (float(lam[k]), values[k], vectors[k])
                del tried[i]
            else:  # a definite (point) or double-line member (or NaN): next root
                tried[i] += 1
                if tried[i] == len(lams[i]):
                    del tried[i]
    pairs = sorted(chosen)
    if not pairs:
        return [[] for _ in range(len(c1s))]
    values = np.array([chosen[i][1] for i in pairs])
    vectors = np.array([chosen[i][2] for i in pairs])
    w1, w2 = np.sqrt(np.abs(values[:, 0])), np.sqrt(np.abs(values[:, 1]))
    v1, v2 = w1[:, None] * vectors[:, 0], w2[:, None] * vectors[:, 1]
    # two lines per pair, the "+" line first; on the lines c1 = -lam c2: meet them with the conic farther
    # from the member (c1 itself at lam = 0)
    lines = np.stack([v1 + v2, v1 - v2], axis=1).reshape(-1, 3)
    owner = np.repeat(pairs, 2)
    far = np.array([abs(chosen[i][0]) < 1.0 for i in pairs]).repeat(2)
    others = np.where(far[:, None, None], c2s[owner], c1s[owner])
    basis = _line_bases(lines)
    met = _lines_meet_conics(basis[:, 0], basis[:, 1], others)
    start = [x for found in met for x in found]
    if not start:
        return [[] for _ in range(len(c1s))]
    point_owner = np.repeat(owner, [len(found) for found in met])
    p1, p2 = c1s[point_owner], c2s[point_owner]
    x = _polish_many(p1, p2, np.array(start))
    ok = (np.abs(_dots(_vec_mat(x, p1), x)) < 1e-8) & (np.abs(_dots(_vec_mat(x, p2), x)) < 1e-8)
    out: list[list[np.ndarray]] = [[] for _ in range(len(c1s))]
    for i, row, good in zip(point_owner.tolist(), x, ok.tolist(), strict=True):
        if good:
            out[i].append(row)
    return out


def _isinf(r: complex) -> bool:
    """``np.isinf`` of one root (a float, or a complex: infinite when either part is)."""
    return math.isinf(r.real) or math.isinf(r.imag)


def line_meets_conic(basis: np.ndarray, conic: np.ndarray) -> list[np.ndarray]:
    """Real points where the projective line spanned by ``basis`` meets the conic ``x^T C x = 0``.

    Parameters
    ----------
    basis : (2, 3) array
        Two homogeneous points spanning the line.
    conic : (3, 3) symmetric array

    Returns
    -------
    list of (3,) unit vectors
        None when the roots are complex or the whole line lies in the conic; a tangent point twice.

    Notes
    -----
    With ``x = s e + t f`` the conic is ``a s^2 + 2 b st + c t^2 = 0``. Its roots are taken as the
    homogeneous pairs ``(q, a)`` and ``(c, q)`` with ``q = -(b + sign(b) sqrt(b^2 - ac))``: no division,
    so a coefficient ``a`` or ``c`` of any size (zero included, when ``e`` or ``f`` lies on the conic)
    gives the right point, and the two roots never cancel. The coefficients are scaled to unit size
    first, so ``b^2`` neither overflows nor underflows.
    """
    e, f = np.asarray(basis, dtype=np.float64)
    return _lines_meet_conics(e[None], f[None], np.asarray(conic, dtype=np.float64)[None])[0]


def _lines_meet_conics(e: np.ndarray, f: np.ndarray, conics: np.ndarray) -> list[list[np.ndarray]]:
    """:func:`line_meets_conic` of each line (bases ``e``, ``f``: (k, 3)) and conic (k, 3, 3) of a stack."""
    ec = _vec_mat(e, conics)
    abc = np.stack([_dots(ec, e), _dots(ec, f), _dots(_vec_mat(f, conics), f)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):  # the rows these would touch are dropped below
        scale = np.abs(abc).max(axis=1)  # NaN when a coefficient is
        # scale > 0: else the line lies in the (degenerate) conic: no isolated points
        a, b, c = (abc / scale[:, None]).T
        disc = b * b - a * c
        live = (scale > 0.0) & ~(disc < 0.0)
        q = -(b + np.copysign(np.sqrt(disc), b))
    out: list[list[np.ndarray]] = [[] for _ in range(len(e))]
    rows = np.flatnonzero(live)
    if not rows.size:
        return out
    e, f, a, c, q = e[rows], f[rows], a[rows, None], c[rows, None], q[rows, None]
    first, second = q * e + a * f, c * e + q * f
    n1, n2 = _norms(first), _norms(second)
    # q = 0 with a = 0 or c = 0: a double root at e or f, carried by the other pair
    double = np.where(n2 < n1, n2, n1) == 0.0  # min(n1, n2) == 0, NaN included as min() treats it
    if double.any():
        use_second = double & ((n2 > n1) | (np.isnan(n2) & ~np.isnan(n1)))  # np.argmax: the first maximum
        use_first = double & ~use_second
        first[use_second], n1[use_second] = second[use_second], n2[use_second]
        second[use_first], n2[use_first] = first[use_first], n1[use_first]
    x1, x2 = first / n1[:, None], second / n2[:, None]
    for k, i in enumerate(rows.tolist()):
        out[i] = [x1[k], x2[k]]
    return out


def _line_basis(line: np.ndarray) -> np.ndarray:
    """Two orthonormal homogeneous points (2, 3) spanning the projective line ``line . x = 0``."""
    basis: np.ndarray = _line_bases(np.asarray(line, dtype=np.float64)[None])[0]
    return basis


def _line_bases(lines: np.ndarray) -> np.ndarray:
    """:func:`_line_basis` of each row of (k, 3): (k, 2, 3)."""
    axis = np.zeros_like(lines)
    axis[np.arange(len(lines)), np.argmin(np.abs(lines), axis=1)] = 1.0
    e = _cross(lines, axis)
    e = e / _norms(e)[:, None]
    f = _cross(lines, e)
    return np.stack([e, f / _norms(f)[:, None]], axis=1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise ``np.cross`` of (k, 3) arrays: the same products and differences, without its argument handling."""
    a0, a1, a2 = a.T
    b0, b1, b2 = b.T
    out = np.empty_like(a)
    out[:, 0] = a1 * b2 - a2 * b1
    out[:, 1] = a2 * b0 - a0 * b2
    out[:, 2] = a0 * b1 - a1 * b0
    return out


def _polish(c1: np.ndarray, c2: np.ndarray, x: np.ndarray, steps: int = 2) -> np.ndarray:
    """Newton steps on ``x^T c1 x = x^T c2 x = 0`` with the step orthogonal to ``x`` (unit sphere)."""
    c1, c2 = np.asarray(c1, dtype=np.float64), np.asarray(c2, dtype=np.float64)
    polished: np.ndarray = _polish_many(c1[None], c2[None], np.asarray(x, dtype=np.float64)[None], steps)[0]
    return polished


def _polish_many(c1: np.ndarray, c2: np.ndarray, x: np.ndarray, steps: int = 2) -> np.ndarray:
    """:func:`_polish` of each point (k, 3) on its own conics (k, 3, 3): the points step together."""
    x = x.copy()
    active = np.arange(len(x))  # points still stepping: a tangential one keeps its last estimate
    for _ in range(steps):
        xa, a1, a2 = x[active], c1[active], c2[active]
        g1, g2 = _mat_vec(a1, xa), _mat_vec(a2, xa)
        jac = np.empty((len(xa), 3, 3))
        jac[:, 0], jac[:, 1], jac[:, 2] = 2.0 * g1, 2.0 * g2, xa
        rhs = np.zeros((len(xa), 3))
        rhs[:, 0], rhs[:, 1] = -_dots(xa, g1), -_dots(xa, g2)
        try:
            step = np.linalg.solve(jac, rhs[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:  # some tangential intersection: find which, one by one
            solved: list[np.ndarray | None] = []
            for k in range(len(active)):
                try:
                    solved.append(np.linalg.solve(jac[k], rhs[k]))
                except np.linalg.LinAlgError:
                    solved.append(None)
            keep = [k for k, s in enumerate(solved) if s is not None]
            active = active[keep]
            if not keep:
                break
            xa = xa[keep]
            step = np.array([solved[k] for k in keep])
        xa = xa + step
        x[active] = xa / _norms(xa)[:, None]
    return x


@dataclass(frozen=True)
class DyadFamily:
    """Points of the one-parameter dyad family (eq 13-14), one row per solution.

    Attributes
    ----------
    kappa : (m,) array
        ``cot(omega)`` of the sample.
    branch : (m,) int array
        Branch id: consecutive samples of one branch are joined in plots and crossing searches.
    p : (m, 8) array
        Unit circle vectors.
    centre : (m, 2) array
        Centre (fixed frame), mm.
    point : (m, 2) array
        Circle point (moving frame), mm.
    """

    kappa: np.ndarray
    branch: np.ndarray
    p: np.ndarray
    centre: np.ndarray
    point: np.ndarray


def family_basis(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All eigenvalues (ascending, (8,)) and unit eigenvectors (8, 8 columns) of ``M^T M``."""
    values, vectors = np.linalg.eigh(m.T @ m)
    return values, vectors


def solve_at_kappa(basis4: np.ndarray, kappa: float) -> list[np.ndarray]:
    """Unit circle vectors ``p`` in span(basis4) with ``w4 = kappa * w1`` meeting eq 7.

    Parameters
    ----------
    basis4 : (8, 4) array
        The four eigenvectors of the smallest eigenvalues.
    kappa : float
    """
    return _solve_many(basis4, [kappa])[0]


def _solve_many(basis4: np.ndarray, kappas: list[float]) -> list[list[np.ndarray]]:
    """:func:`solve_at_kappa` at each of ``kappas``, solved together (the same bits as one by one)."""
    s1, s2 = _FORMS
    charts = np.zeros((len(kappas), 4, 3))
    charts[:, 0, 0] = charts[:, 1, 1] = charts[:, 2, 2] = 1.0
    charts[:, 3, 0] = kappas
    lift = np.matmul(basis4, charts)  # (k, 8, 3): p = lift @ (alpha, beta, gamma)
    lift_t = lift.transpose(0, 2, 1)
    found = _conic_intersections_many(lift_t @ s1 @ lift, lift_t @ s2 @ lift)
    owner = np.repeat(np.arange(len(found)), [len(xs) for xs in found])
    out: list[list[np.ndarray]] = [[] for _ in found]
    if not owner.size:
        return out
    p = _mat_vec(lift[owner], np.array([x for xs in found for x in xs]))
    p = p / _norms(p)[:, None]
    for i, row in zip(owner.tolist(), p, strict=True):
        out[i].append(row)
    return out


def _match_branches(found: list[np.ndarray], previous: list[tuple[np.ndarray, int]],
                    min_dot: float = 0.9) -> list[int]:
    """Branch label of each new solution: greedy by the largest (sign-free) cosine to the previous
    sample's solutions, each previous branch used once; -1 for a new branch."""
    labels = [-1] * len(found)
    pairs = sorted(((abs(float(p @ q)), i, b) for i, p in enumerate(found) for q, b in previous), reverse=True)
    used: set[int] = set()
    for dot, i, b in pairs:
        if dot < min_dot:
            break
        if labels[i] < 0 and b not in used:
            labels[i] = b
            used.add(b)
    return labels


def trace_family(basis4: np.ndarray, samples: int, min_centre_weight: float = 1e-9) -> DyadFamily:
    """Trace the dyad family over ``omega`` in (0, pi) with ``kappa = cot(omega)`` (eq 14).

    Parameters
    ----------
    basis4 : (8, 4) array
        Eigenvectors of the four smallest eigenvalues of ``M^T M``.
    samples : int
        Number of ``omega`` samples, evenly spaced in the open interval.
    min_centre_weight : float
        Solutions with ``|p1|`` below this (a circle of infinite radius: a slider) are dropped.
    """
    omegas = np.linspace(0.0, np.pi, samples + 2)[1:-1]
    kappas, branches, ps = [], [], []
    previous: list[tuple[np.ndarray, int]] = []
    next_branch = 0
    sample_kappas = [float(np.cos(omega) / np.sin(omega)) for omega in omegas]
    for kappa, solutions in zip(sample_kappas, _solve_many(basis4, sample_kappas), strict=True):
        found = [p for p in solutions if abs(p[0]) >= min_centre_weight]
        labels = _match_branches(found, previous)
        current = []
        for p, label in zip(found, labels, strict=True):
            if label < 0:
                label, next_branch = next_branch, next_branch + 1
            current.append((p, label))
            kappas.append(kappa)
            branches.append(label)
            ps.append(p)
        previous = current
    p_arr = np.array(ps).reshape(-1, 8)
    centre, point = dyad_from_vector(p_arr)
    return DyadFamily(kappa=np.asarray(kappas, dtype=np.float64), branch=np.asarray(branches, dtype=int),
                      p=p_arr, centre=centre.reshape(-1, 2), point=point.reshape(-1, 2))


def refine_family(basis4: np.ndarray, family: DyadFamily, measure, keep: np.ndarray, max_step: float,
                  max_inserts: int = 200) -> DyadFamily:
    """Insert kappa samples where a branch jumps by more than ``max_step`` between two samples.

    ``kappa = cot(omega)`` sampled evenly in ``omega`` is coarse where the hinges move fast; only the
    gaps with an end in ``keep`` (e.g. inside the limits box) are refined, so the far, unbounded parts
    of the curves do not cost anything.

    Parameters
    ----------
    basis4 : (8, 4) array
    family : DyadFamily
    measure : callable
        Maps circle vectors (k, 8) to positions (k, d) whose distance is compared with ``max_step``
        (e.g. A and B at the first pose, mm).
    keep : (m,) bool array
        Samples whose gaps to their branch neighbours may be refined.
    max_step : float
    max_inserts : int
        Largest number of samples inserted into one gap.
    """
    order = np.argsort(np.arctan2(1.0, family.kappa), kind="stable")  # omega order
    fam = _take(family, order)
    keep = np.asarray(keep)[order]
    pos = measure(fam.p)
    # the gaps to fill and their kappas first, all solved in one stack; those past a lost branch are not used
    gaps: list[tuple[int, int, list[float]]] = []
    for branch in np.unique(fam.branch).tolist():
        idx = np.flatnonzero(fam.branch == branch)
        for j, k in zip(idx[:-1], idx[1:], strict=True):
            gap = float(np.linalg.norm(pos[k] - pos[j]))
            if not (keep[j] or keep[k]) or gap <= max_step:
                continue
            count = min(max_inserts, int(np.ceil(gap / max_step)) - 1)
            gaps.append((branch, j, [(1.0 - t) * fam.kappa[j] + t * fam.kappa[k]
                                     for t in np.linspace(0.0, 1.0, count + 2)[1:-1]]))
    solved = iter(_solve_many(basis4, [kappa for _, _, kappas in gaps for kappa in kappas]))
    new_k, new_b, new_p = [], [], []
    for branch, j, kappas in gaps:
        reference = fam.p[j]
        found = [next(solved) for _ in kappas]
        for kappa, solutions in zip(kappas, found, strict=True):
            if not solutions:
                break
            p = max(solutions, key=lambda q: abs(float(q @ reference)))
            if abs(float(p @ reference)) < 0.99 or abs(p[0]) < 1e-9:
                break  # lost the branch (a turning point between the samples)
            p = p if float(p @ reference) > 0 else -p
            new_k.append(kappa)
            new_b.append(branch)
            new_p.append(p)
            reference = p
    if not new_k:
        return fam
    p_all = np.vstack([fam.p, np.array(new_p)])
    kappa_all = np.concatenate([fam.kappa, new_k])
    branch_all = np.concatenate([fam.branch, new_b]).astype(int)
    order = np.argsort(np.arctan2(1.0, kappa_all), kind="stable")
    centre, point = dyad_from_vector(p_all[order])
    return DyadFamily(kappa=kappa_all[order], branch=branch_all[order], p=p_all[order], centre=centre,
                      point=point)


def _take(family: DyadFamily, index: np.ndarray) -> DyadFamily:
    return DyadFamily(kappa=family.kappa[index], branch=family.branch[index], p=family.p[index],
                      centre=family.centre[index], point=family.point[index])


def bisect_on_branch(basis4: np.ndarray, func, k0: float, p0: np.ndarray, k1: float, p1: np.ndarray,
                     iterations: int = 48, lookahead: int = 4) -> tuple[float, np.ndarray]:
    """Root of ``func(p)`` between two samples ``(k0, p0)``, ``(k1, p1)`` of one branch, by bisection
    in kappa; at each step the solution nearest (in direction) to the last one keeps the branch.

    The midpoints of the next ``lookahead`` steps, whichever way they go (``2**lookahead - 1`` kappas), are
    solved together and the steps then walk that tree: the same steps as one solve per step, for fewer
    solver calls.

    Returns
    -------
    (kappa, p) : float, (8,) array
        The end of the final bracket with the smaller ``|func|``.
    """
    f0, f1 = func(p0), func(p1)
    reference = p0
    done = 0
    while done < iterations:
        depth = max(1, min(lookahead, iterations - done))
        # the midpoint tree in heap order: node n's bracket halves into nodes 2n (lower) and 2n + 1 (upper)
        brackets = [(k0, k1)]
        kappas = []
        for lo, hi in brackets:
            mid = 0.5 * (lo + hi)
            kappas.append(mid)
            if len(brackets) < 2 ** depth - 1:
                brackets.extend([(lo, mid), (mid, hi)])
        solved = _solve_many(basis4, kappas)
        node = 0
        for _ in range(depth):
            solutions = solved[node]
            if not solutions:
                return (k0, p0) if abs(f0) <= abs(f1) else (k1, p1)
            k_mid = kappas[node]
            p_mid = max(solutions, key=lambda q: abs(float(q @ reference)))
            f_mid = func(p_mid)
            if np.sign(f_mid) == np.sign(f0):
                k0, p0, f0 = k_mid, p_mid, f_mid
                node = 2 * node + 2
            else:
                k1, p1, f1 = k_mid, p_mid, f_mid
                node = 2 * node + 1
            reference = p_mid
        done += depth
    return (k0, p0) if abs(f0) <= abs(f1) else (k1, p1)
