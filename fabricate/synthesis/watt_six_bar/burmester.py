"""Generalized Burmester curves for four-position dyad synthesis (the Watt-I six-bar finger paper, eqs 1-6).

A dyad B-M joins two moving planes pi^1 and pi^2 (either may be the ground). Over four positions the
point ``X`` of pi^1 and its partner ``Y`` of pi^2 must keep their distance. With the displacement
``(R1_i, t1_i)`` of pi^1 and ``(R2_i, t2_i)`` of pi^2 from position 1 to position ``i``, the condition
``|R1_i X + t1_i - R2_i Y - t2_i|^2 = |X - Y|^2`` (eq 3) reads, after expansion,

    2 Y . [R2_i^T w_i + (I - R2_i^T R1_i) X] + |w_i|^2 - 2 w_i . R1_i X = 0,   w_i = t2_i - t1_i

(the ``|R1_i X|^2`` and ``|X|^2`` terms cancel). This is linear in ``Y`` and, row by row, linear in
``(x, y, 1)`` of ``X``: it is the paper's eq 4 ``C_i x + E_i y + F_i = 0`` with the roles written out.
Three positions ``i = 2, 3, 4`` give a 3x3 system in ``(Y, 1)`` whose determinant (eq 5) is a cubic in
``X``: the curve ``C_X`` (eq 6). We keep the cubic as a symmetric 3x3x3 tensor ``S`` in homogeneous
coordinates ``v = (x, y, 1)`` with ``P(v) = S_jkl v_j v_k v_l``; its cubic part is circular,
``(H1 x + H2 y)(x^2 + y^2)``, as eq 6 prints (tested). The partner ``Y`` of a curve point is the null
vector of the rank-2 system.

Branches (paper section 1.2): at a given ``x`` the cubic in ``y`` has one or three real roots; a single
root is branch 1, three roots are branches 1, 2, 3 from the lowest ``y`` up.

Everything is vectorised over leading batch axes; lengths in mm, angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.planar import rotation

#: Levi-Civita symbol: det(p, q, r) = eps_abc p_a q_b r_c.
_LEVI_CIVITA = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_i, _j, _k] = 1.0
    _LEVI_CIVITA[_i, _k, _j] = -1.0


@dataclass(frozen=True)
class PlaneMotion:
    """Displacements of a plane from position 1 to positions 1..4.

    Attributes
    ----------
    rotations : (..., 4, 2, 2) array
        ``R_i`` (identity for i = 1).
    translations : (..., 4, 2) array
        ``t_i`` in mm, so that a point ``X`` of the plane at position 1 is at ``R_i X + t_i``.
    """

    rotations: np.ndarray
    translations: np.ndarray

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Positions (..., 4, 2) of plane points given at position 1, ``points`` (..., 2)."""
        points = np.asarray(points, dtype=np.float64)
        return np.einsum("...iab,...b->...ia", self.rotations, points) + self.translations


def plane_motion(origins: np.ndarray, angles: np.ndarray) -> PlaneMotion:
    """Displacements of a plane given one of its points and its direction at every position.

    Parameters
    ----------
    origins : (..., 4, 2) array
        A point of the plane (e.g. a joint) at positions 1..4, mm.
    angles : (..., 4) array
        Direction of a line of the plane at positions 1..4, rad (eq 1's displacement matrix).
    """
    origins = np.asarray(origins, dtype=np.float64)
    angles = np.asarray(angles, dtype=np.float64)
    rot = rotation(angles - angles[..., :1])
    trans = origins - np.einsum("...iab,...b->...ia", rot, origins[..., 0, :])
    return PlaneMotion(rot, trans)


def ground_motion(shape: tuple[int, ...] = ()) -> PlaneMotion:
    """The fixed plane: identity displacements, batch ``shape``."""
    rot = np.broadcast_to(np.eye(2), shape + (4, 2, 2)).copy()
    return PlaneMotion(rot, np.zeros(shape + (4, 2)))


def dyad_row_matrices(first: PlaneMotion, second: PlaneMotion) -> np.ndarray:
    """Matrices ``A_i`` (i = 2, 3, 4) with row_i(X) = A_i @ (x, y, 1): the coefficients of (Y, 1).

    ``X`` is the dyad end in ``first``, ``Y`` its partner in ``second`` (both at position 1).

    Returns
    -------
    (..., 3, 3, 3) array
        ``A[..., i-2, r, c]``: coefficient ``r`` of (Y_x, Y_y, 1) from monomial ``c`` of (x, y, 1).
    """
    r1 = first.rotations[..., 1:, :, :]
    r2 = second.rotations[..., 1:, :, :]
    w = second.translations[..., 1:, :] - first.translations[..., 1:, :]
    r2t = np.swapaxes(r2, -1, -2)
    shape = w.shape[:-1]
    out = np.zeros(shape + (3, 3))
    out[..., :2, :2] = 2.0 * (np.eye(2) - r2t @ r1)
    out[..., :2, 2] = 2.0 * np.einsum("...ab,...b->...a", r2t, w)
    out[..., 2, :2] = -2.0 * np.einsum("...ba,...b->...a", r1, w)
    out[..., 2, 2] = np.einsum("...a,...a->...", w, w)
    return out


@dataclass(frozen=True)
class CubicCurve:
    """A cubic ``P(x, y) = S_jkl v_j v_k v_l = 0`` with ``v = (x, y, 1)``; batchable.

    Attributes
    ----------
    tensor : (..., 3, 3, 3) array
        Symmetric coefficient tensor, scaled to unit largest entry (the curve is homogeneous in it).
    rows : (..., 3, 3, 3) array
        The dyad row matrices it came from (to find a point's partner).
    """

    tensor: np.ndarray
    rows: np.ndarray

    def evaluate(self, points: np.ndarray) -> np.ndarray:
        """P at ``points`` (..., n, 2) for a batch of curves (...), or (n, 2) for one; returns (..., n)."""
        v = _homogeneous(points)
        return np.einsum("...jkl,...nj,...nk,...nl->...n", self.tensor, v, v, v)

    def gradient(self, points: np.ndarray) -> np.ndarray:
        """(dP/dx, dP/dy) at ``points``, shape (..., n, 2)."""
        v = _homogeneous(points)
        g = 3.0 * np.einsum("...jkl,...nk,...nl->...nj", self.tensor, v, v)
        return g[..., :2]

    def y_polynomials(self, x: np.ndarray) -> np.ndarray:
        """Coefficients (c0, c1, c2, c3) of P(x, y) as a cubic in y at each ``x``; shape (..., n, 4).

        ``x`` is (n,) shared by all curves of the batch, or (..., n).
        """
        x = np.asarray(x, dtype=np.float64)
        s = self.tensor
        # v = p + y q with p = (x, 0, 1), q = (0, 1, 0); S symmetric so the mixed terms collapse
        sx = s[..., 0, :, :]
        s1 = s[..., 2, :, :]
        # S(p, p, p), S(q, p, p), S(q, q, p) as polynomials in x
        c0 = (sx[..., 0, 0, None] * x**3 + 3.0 * sx[..., 0, 2, None] * x**2
              + 3.0 * s1[..., 2, 0, None] * x + s1[..., 2, 2, None])
        qpp = (s[..., 1, 0, 0, None] * x**2 + 2.0 * s[..., 1, 0, 2, None] * x + s[..., 1, 2, 2, None])
        qqp = s[..., 1, 1, 0, None] * x + s[..., 1, 1, 2, None]
        c3 = np.broadcast_to(s[..., 1, 1, 1, None], np.broadcast_shapes(c0.shape, qqp.shape))
        return np.stack([c0, 3.0 * qpp, 3.0 * qqp, c3], axis=-1)

    def partners(self, points: np.ndarray) -> np.ndarray:
        """Partner points ``Y`` (..., n, 2) in the second plane of curve points ``X`` (..., n, 2).

        The 3x3 system rows ``A_i (x, y, 1)`` has rank 2 on the curve; ``(Y, 1)`` spans its null space.
        NaN where the null space is not unique or ``Y`` is at infinity.
        """
        v = _homogeneous(points)
        m = np.einsum("...irc,...nc->...nir", self.rows, v)
        scale = np.max(np.abs(m), axis=(-1, -2), keepdims=True)
        scale = np.where(scale > 0.0, scale, 1.0)
        _, sv, vt = np.linalg.svd(m / scale)
        null = vt[..., -1, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            y = null[..., :2] / null[..., 2:3]
            # rank 1 (both lower singular values ~0) means a whole line of partners: not a dyad; a zero system
            # (every row vanishes: sv all 0) has every Y as partner; a null vector with w = 0 is at infinity
            degenerate = (sv[..., 1] <= 1e-9 * sv[..., 0]) | ~np.all(np.isfinite(y), axis=-1)
        y[degenerate] = np.nan
        return y


def _homogeneous(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=np.float64)
    return np.concatenate([points, np.ones(points.shape[:-1] + (1,))], axis=-1)


def dyad_curve(first: PlaneMotion, second: PlaneMotion) -> CubicCurve:
    """The generalized Burmester curve of the dyad end in ``first`` (eq 5-6).

    det[A_2 v, A_3 v, A_4 v] expanded multilinearly: T_jkl = eps_abc A2_aj A3_bk A4_cl, symmetrised.
    """
    rows = dyad_row_matrices(first, second)
    t = np.einsum("abc,...aj,...bk,...cl->...jkl", _LEVI_CIVITA, rows[..., 0, :, :], rows[..., 1, :, :],
                  rows[..., 2, :, :])
    s = (t + t.transpose(_axes(t, 0, 2, 1)) + t.transpose(_axes(t, 1, 0, 2)) + t.transpose(_axes(t, 1, 2, 0))
         + t.transpose(_axes(t, 2, 0, 1)) + t.transpose(_axes(t, 2, 1, 0))) / 6.0
    scale = np.max(np.abs(s), axis=(-1, -2, -3), keepdims=True)
    scale = np.where(scale > 0.0, scale, 1.0)
    return CubicCurve(tensor=s / scale, rows=rows)


def _axes(t: np.ndarray, i: int, j: int, k: int) -> tuple[int, ...]:
    lead = tuple(range(t.ndim - 3))
    return lead + tuple(t.ndim - 3 + a for a in (i, j, k))


def cubic_real_roots(coefficients: np.ndarray) -> np.ndarray:
    """Real roots of cubics ``c0 + c1 y + c2 y^2 + c3 y^3``, split into branches.

    Parameters
    ----------
    coefficients : (..., 4) array

    Returns
    -------
    (..., 3) array
        Column ``k`` is branch ``k + 1``: one real root goes to column 0 (NaN in 1, 2); three real
        roots are sorted ascending. Where ``c3`` vanishes the curve has an asymptote parallel to y and
        the lower-degree roots are returned the same way (one root or two sorted, into columns 0..).
    """
    c = np.asarray(coefficients, dtype=np.float64)
    shape = c.shape[:-1]
    c = c.reshape(-1, 4)
    out = np.full((c.shape[0], 3), np.nan)
    norm = np.max(np.abs(c), axis=1)
    ok = norm > 0.0
    c = c / np.where(ok, norm, 1.0)[:, None]
    cubic = ok & (np.abs(c[:, 3]) > 1e-12)
    if np.any(cubic):
        cc = c[cubic]
        a2, a1, a0 = cc[:, 2] / cc[:, 3], cc[:, 1] / cc[:, 3], cc[:, 0] / cc[:, 3]
        comp = np.zeros((len(cc), 3, 3))
        comp[:, 0, :] = np.stack([-a2, -a1, -a0], axis=1)
        comp[:, 1, 0] = 1.0
        comp[:, 2, 1] = 1.0
        roots = np.linalg.eigvals(comp)
        # count real roots by the discriminant of the monic cubic, not by |imag| of noisy eigenvalues
        disc = 18 * a2 * a1 * a0 - 4 * a2**3 * a0 + a2**2 * a1**2 - 4 * a1**3 - 27 * a0**2
        three = disc > 0.0
        real = np.sort(roots.real, axis=1)
        single = roots.real[np.arange(len(cc)), np.argmin(np.abs(roots.imag), axis=1)]
        res = np.full((len(cc), 3), np.nan)
        res[three] = real[three]
        res[~three, 0] = single[~three]
        # polished roots of a tight cluster may cross: the documented order is ascending (NaN last)
        out[cubic] = np.sort(_polish(res, cc), axis=1)
    rest = np.flatnonzero(ok & ~cubic)
    for k in rest:  # rare: degree drops at this x
        r = np.roots(c[k, ::-1][np.argmax(np.abs(c[k, ::-1]) > 1e-12):])
        r = np.sort(r[np.abs(r.imag) < 1e-9].real)
        out[k, :len(r)] = r[:3]
    return out.reshape(shape + (3,))


def _polish(roots: np.ndarray, c: np.ndarray, steps: int = 2) -> np.ndarray:
    """Newton steps on the real roots (eigenvalues of a companion matrix lose a few digits)."""
    for _ in range(steps):
        y = roots
        p = c[:, 0:1] + y * (c[:, 1:2] + y * (c[:, 2:3] + y * c[:, 3:4]))
        dp = c[:, 1:2] + y * (2.0 * c[:, 2:3] + 3.0 * y * c[:, 3:4])
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(np.abs(dp) > 1e-14, p / dp, 0.0)
        # a Newton step larger than the root spacing would mean a near-double root: keep the eigenvalue;
        # near a multiple root Newton can also walk away (up to that limit) while |p| grows: keep only
        # steps that reduce the residual
        trial = y - step
        p_trial = c[:, 0:1] + trial * (c[:, 1:2] + trial * (c[:, 2:3] + trial * c[:, 3:4]))
        better = np.abs(p_trial) < np.abs(p)
        roots = np.where((np.abs(step) < 1e-3 * (1.0 + np.abs(y))) & better, trial, y)
    return roots


@dataclass(frozen=True)
class CurveSample:
    """Points of a cubic sampled at given x, one column per branch.

    Attributes
    ----------
    x : (..., n) array
        Abscissae, mm.
    y : (..., n, 3) array
        Ordinates of branches 1..3 (NaN where the branch has no point at that x), mm.
    partner : (..., n, 3, 2) array
        The partner point of the dyad in the other plane, mm.
    """

    x: np.ndarray
    y: np.ndarray
    partner: np.ndarray

    def points(self) -> np.ndarray:
        """(..., n, 3, 2) curve points."""
        x = np.broadcast_to(self.x[..., :, None], self.y.shape)
        return np.stack([x, self.y], axis=-1)


def sample_curve(curve: CubicCurve, x: np.ndarray) -> CurveSample:
    """Solve the curve at every ``x`` (shared (n,) or batched (..., n)) and find each point's partner."""
    x = np.asarray(x, dtype=np.float64)
    y = cubic_real_roots(curve.y_polynomials(x))
    xb = np.broadcast_to(x, y.shape[:-1])
    pts = np.stack([np.broadcast_to(xb[..., None], y.shape), y], axis=-1)
    flat = pts.reshape(pts.shape[:-3] + (-1, 2))
    partner = curve.partners(np.nan_to_num(flat)).reshape(pts.shape)
    partner[np.isnan(y)] = np.nan
    return CurveSample(x=xb, y=y, partner=partner)


def in_box(points: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Whether points (..., 2) lie in ``box = (x_min, x_max, y_min, y_max)`` (closed); NaN is outside."""
    with np.errstate(invalid="ignore"):
        return ((points[..., 0] >= box[0]) & (points[..., 0] <= box[1])
                & (points[..., 1] >= box[2]) & (points[..., 1] <= box[3]))


def grid_in_range(lo: float, hi: float, step: float) -> np.ndarray:
    """``lo, lo + step, ...`` up to ``hi`` inclusive (rounded to 1e-9 mm so 0.2 mm grids print exactly)."""
    n = int(np.floor((hi - lo) / step + 1e-9)) + 1
    return np.round(lo + step * np.arange(n), 9)


def distance_to_curve(curve: CubicCurve, point: np.ndarray, iterations: int = 50,
                      span: float = 40.0) -> tuple[float, np.ndarray]:
    """Euclidean distance from ``point`` (2,) to a single (unbatched) curve and the foot point.

    Sampled search on a fine grid of x and y lines within ``span`` mm of the point (robust where the
    curve has vertical tangents), refined by projecting with Newton steps along the gradient. Returns
    ``(inf, point)`` when no branch comes within ``span``.
    """
    point = np.asarray(point, dtype=np.float64)
    best = (np.inf, point)
    for axis in (0, 1):
        grid = point[axis] + np.linspace(-span, span, 4001)
        if axis == 0:
            pts = sample_curve(curve, grid).points().reshape(-1, 2)
        else:
            swapped = CubicCurve(tensor=curve.tensor[[1, 0, 2]][:, [1, 0, 2]][:, :, [1, 0, 2]], rows=curve.rows)
            ys = cubic_real_roots(swapped.y_polynomials(grid))
            pts = np.stack([ys, np.broadcast_to(grid[:, None], ys.shape)], -1).reshape(-1, 2)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if len(pts):
            k = int(np.argmin(np.hypot(*(pts - point).T)))
            dist = float(np.hypot(*(pts[k] - point)))
            if dist < best[0]:
                best = (dist, pts[k])
    foot = best[1].copy()
    for _ in range(iterations):  # orthogonal projection: move along the gradient to the zero set
        g = curve.gradient(foot[None])[0]
        val = curve.evaluate(foot[None])[0]
        gg = float(g @ g)
        if gg == 0.0:
            break
        foot = foot - val * g / gg
        # then slide along the tangent to the foot of the perpendicular
        t = np.array([-g[1], g[0]]) / np.sqrt(gg)
        foot = foot + t * float(t @ (point - foot))
    val = curve.evaluate(foot[None])[0]
    g = curve.gradient(foot[None])[0]
    if abs(val) / max(np.hypot(*g), 1e-300) < 1e-6:
        best = (min(best[0], float(np.hypot(*(foot - point)))), foot)
    return best
