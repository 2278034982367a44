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
    # each conic is only defined up to scale: normalise them separately, so that neither looks degenerate
    c1, c2 = c1 / max(np.abs(c1).max(), 1e-300), c2 / max(np.abs(c2).max(), 1e-300)
    # the cubic through four exact samples of det(c1 + lam c2)
    coefficients = _CUBIC_FIT @ np.linalg.det(c1[None] + _CUBIC_SAMPLES[:, None, None] * c2[None])
    if abs(coefficients[0]) < 1e-14:  # c2 itself degenerate: it is the member at infinity
        roots = np.concatenate([[np.inf], np.roots(coefficients)])
    else:  # eigenvalues of the companion matrix (np.roots without its overhead)
        lead = coefficients[0]
        roots = np.linalg.eigvals(np.array([[-coefficients[1] / lead, -coefficients[2] / lead,
                                             -coefficients[3] / lead], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]))
    # plain Python numbers from here on: numpy's per-scalar overhead was most of a call's time (the
    # operations are the same IEEE ones, so the results are the same bits)
    lams = [r.real for r in roots.tolist() if _isinf(r) or abs(r.imag) <= 1e-9 * max(1.0, abs(r))]
    points: list[np.ndarray] = []
    for lam in lams:
        member = c2 if math.isinf(lam) else c1 + lam * c2
        values, vectors = np.linalg.eigh(member)
        order = np.argsort(np.abs(values))
        v1, v2 = values[order[1:]].tolist()
        vectors = vectors[:, order]
        if v1 * v2 >= 0.0:
            continue  # a definite (point) or double-line member: try another root
        w1, w2 = math.sqrt(abs(v1)), math.sqrt(abs(v2))
        # on the lines c1 = -lam c2: meet them with the conic farther from the member (c1 itself at lam = 0)
        other = c2 if abs(lam) < 1.0 else c1
        for line in (w1 * vectors[:, 1] + w2 * vectors[:, 2], w1 * vectors[:, 1] - w2 * vectors[:, 2]):
            points.extend(_polish(c1, c2, x) for x in line_meets_conic(_line_basis(line), other))
        break
    return [x for x in points if abs(x @ c1 @ x) < 1e-8 and abs(x @ c2 @ x) < 1e-8]


def _isinf(r: complex) -> bool:
    """``np.isinf`` of one root (a float, or a complex: infinite when either part is)."""
    return math.isinf(r.real) or math.isinf(r.imag)


def _norm(x: np.ndarray) -> float:
    """``np.linalg.norm`` of a 1-D float array, without its argument handling: the same ``sqrt(x . x)``."""
    return math.sqrt(x.dot(x))


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
    ec = e @ conic
    abc = (float(ec @ e), float(ec @ f), float((f @ conic) @ f))
    if any(math.isnan(v) for v in abc):
        return []  # as np.abs(abc).max() would be NaN below
    scale = max(abs(v) for v in abc)
    if not scale > 0.0:
        return []  # the line lies in the (degenerate) conic: no isolated points
    a, b, c = (v / scale for v in abc)
    disc = b * b - a * c
    if disc < 0.0:
        return []
    q = -(b + math.copysign(math.sqrt(disc), b))
    roots = [s * e + t * f for s, t in ((q, a), (c, q))]
    norms = [_norm(x) for x in roots]
    if min(norms) == 0.0:  # q = 0 with a = 0 or c = 0: a double root at e or f, carried by the other pair
        k = int(np.argmax(norms))
        roots, norms = [roots[k]] * 2, [norms[k]] * 2
    return [x / n for x, n in zip(roots, norms, strict=True)]


def _line_basis(line: np.ndarray) -> np.ndarray:
    """Two orthonormal homogeneous points (2, 3) spanning the projective line ``line . x = 0``."""
    l0, l1, l2 = line.tolist()
    axis = [0.0, 0.0, 0.0]
    axis[int(np.argmin(np.abs(line)))] = 1.0
    e = _cross(l0, l1, l2, *axis)
    e = e / _norm(e)
    f = _cross(l0, l1, l2, *e.tolist())
    return np.array([e, f / _norm(f)])


def _cross(a0: float, a1: float, a2: float, b0: float, b1: float, b2: float) -> np.ndarray:
    """``np.cross`` of two 3-vectors given by their components: the same products and differences."""
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _polish(c1: np.ndarray, c2: np.ndarray, x: np.ndarray, steps: int = 2) -> np.ndarray:
    """Newton steps on ``x^T c1 x = x^T c2 x = 0`` with the step orthogonal to ``x`` (unit sphere)."""
    for _ in range(steps):
        g1, g2 = c1 @ x, c2 @ x
        jac = np.array([2.0 * g1, 2.0 * g2, x])
        try:
            step = np.linalg.solve(jac, [-(x @ g1), -(x @ g2), 0.0])
        except np.linalg.LinAlgError:  # tangential intersection: keep the unpolished point
            return x
        x = x + step
        x = x / _norm(x)
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
    s1, s2 = _FORMS
    chart = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [kappa, 0.0, 0.0]])
    lift = basis4 @ chart  # (8, 3): p = lift @ (alpha, beta, gamma)
    out = []
    for x in conic_intersections(lift.T @ s1 @ lift, lift.T @ s2 @ lift):
        p = lift @ x
        out.append(p / _norm(p))
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
    for omega in omegas:
        kappa = float(np.cos(omega) / np.sin(omega))
        found = [p for p in solve_at_kappa(basis4, kappa) if abs(p[0]) >= min_centre_weight]
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
    new_k, new_b, new_p = [], [], []
    for branch in np.unique(fam.branch):
        idx = np.flatnonzero(fam.branch == branch)
        for j, k in zip(idx[:-1], idx[1:], strict=True):
            gap = float(np.linalg.norm(pos[k] - pos[j]))
            if not (keep[j] or keep[k]) or gap <= max_step:
                continue
            count = min(max_inserts, int(np.ceil(gap / max_step)) - 1)
            reference = fam.p[j]
            for t in np.linspace(0.0, 1.0, count + 2)[1:-1]:
                kappa = (1.0 - t) * fam.kappa[j] + t * fam.kappa[k]
                solutions = solve_at_kappa(basis4, kappa)
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
                     iterations: int = 48) -> tuple[float, np.ndarray]:
    """Root of ``func(p)`` between two samples ``(k0, p0)``, ``(k1, p1)`` of one branch, by bisection
    in kappa; at each step the solution nearest (in direction) to the last one keeps the branch.

    Returns
    -------
    (kappa, p) : float, (8,) array
        The end of the final bracket with the smaller ``|func|``.
    """
    f0, f1 = func(p0), func(p1)
    reference = p0
    for _ in range(iterations):
        k_mid = 0.5 * (k0 + k1)
        solutions = solve_at_kappa(basis4, k_mid)
        if not solutions:
            break
        p_mid = max(solutions, key=lambda q: abs(float(q @ reference)))
        f_mid = func(p_mid)
        if np.sign(f_mid) == np.sign(f0):
            k0, p0, f0 = k_mid, p_mid, f_mid
        else:
            k1, p1, f1 = k_mid, p_mid, f_mid
        reference = p_mid
    return (k0, p0) if abs(f0) <= abs(f1) else (k1, p1)
