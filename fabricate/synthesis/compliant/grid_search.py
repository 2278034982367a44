"""Fast, certified minimisation of Delta N = F_n1 - F_n2 over the paper's parameter grid (Table 1).

Why it can be fast
------------------
For a fixed root angle alpha and seat length c the finger touching the can is a one-parameter family
of configurations (the contact path, closed form in phi2, sampled at ``samples`` points). At a
configuration t of that path the two torque balances give (eqs 3-6, with f = mu F_n)::

    F_n1 = N / D_s,  F_hover = N / D_h,  N = 180/pi * [k2 (phi2 + phi02) h1 - k1 (phi1 + phi01) h2]

so the springs enter only through N, and Delta N = F_n2 (D_h / D_s - 1) = G(t) depends on the
configuration alone. The four spring parameters only choose *where* on the path the hover force first
reaches F_n2. A grid point whose first crossing lies in the sample interval (t_{i-1}, t_i] gets
Delta N = G(t_{i-1}) + w (G(t_i) - G(t_{i-1})) with w in [0, 1] (linear interpolation, exactly what
:func:`evaluate_points` and :func:`brute_force` compute). So

1. every interval has an exact lower bound L_i: the least of that linear G over the part of the
   interval where both hinges keep ``hinge_margin`` off their stops and G >= 0 (both linear in w too)
   (:func:`interval_bounds`; 178 paths x about 33 intervals for the paper's grid, about 30 ms);
2. intervals are searched in order of L_i, path by path in order of their least L_i; the first ones
   give a good incumbent at once, and an interval with L_i >= the incumbent is dropped unsearched;
3. searching interval i of a path finds *every* grid point whose first crossing is there, without
   enumerating the grid: with h1 > 0 the hover condition at sample j reads ``k2 phi02 >= sigma_j``,
   ``sigma_j = (target_j + k1 (phi1_j + phi01) h2_j) / h1_j - k2 phi2_j`` depends on the triple
   (k1, k2, phi01) only; the first crossing is at i exactly when ``sigma_i <= k2 phi02 < min_{j<i}
   sigma_j``, an interval of phi02 found by one sorted search per triple. sigma and its running
   minimum are computed once per path (31 x 31 x 91 triples x path samples, vectorised);
4. the points found are valued with the same arithmetic as :func:`evaluate_points`, and those that
   beat the incumbent are re-evaluated by :func:`evaluate_points` itself (the reference).

The certificate (:class:`OptimumResult`): every grid point either crosses first in a searched interval
(then it was valued exactly), or in an interval whose bound ``pruned_bound`` >= the optimum, or it
never gives a valid grasp. The phi02 ranges are widened by a relative 1e-9 so that rounding between
the sigma form and the direct form of the hover condition cannot lose a point.

Objective and constraints. The paper minimises Delta N = F_n1 - F_n2 "with F_n2 satisfied" and does
not list its other constraints. We keep grasps that are physical: hover force reaching F_n2 on the
physical branch (tip on the can, rod pushing in hover and at rest), both hinges at least
``hinge_margin`` off their stops (else a stop, not the spring, carries the torque and eqs 4/6 do not
hold), and Delta N >= 0 (the resting grasp at least the hover force). Without the margin the search
runs into configurations with the tip hinge a fraction of a degree off its stop, where Delta N
crosses zero; that is a degenerate optimum, not a design.

The optimum is that of the sampled path (linear interpolation between samples), like
:func:`brute_force`; ``tests/test_compliant.py`` checks it against plain enumeration of a sub-grid
and the caller re-solves the winning point exactly (:func:`~fabricate.synthesis.compliant.model.solve_grasp`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.errors import SynthesisError
from fabricate.synthesis.compliant.model import (
    DEG_PER_RAD,
    ContactPath,
    GripperGeometry,
    Load,
    contact_path,
)


@dataclass(frozen=True)
class ParameterGrid:
    """The six searched axes (Table 1): alpha (rad), c (mm), k1, k2 (N·mm/deg), phi01, phi02 (rad).
    Each axis is ascending; k1, k2, phi01, phi02 are >= 0."""

    alpha: np.ndarray
    c: np.ndarray
    k1: np.ndarray
    k2: np.ndarray
    phi01: np.ndarray
    phi02: np.ndarray

    @property
    def size(self) -> int:
        return int(np.prod([len(a) for a in (self.alpha, self.c, self.k1, self.k2, self.phi01,
                                             self.phi02)]))


@dataclass(frozen=True)
class OptimumResult:
    """Best grid point, its Delta N (N) on the sampled path and the certificate of the search.

    ``pruned_bound`` (N) is the least interval bound of everything not searched (inf if all was
    searched); it is >= ``delta_n``, so no grid point left out can beat the optimum.
    ``lower_bound = min(pruned_bound, delta_n)``: no grid point at all has a smaller Delta N.
    ``points_evaluated`` counts the grid points whose first crossing lies in a searched interval
    (each valued exactly), ``points_verified`` those re-evaluated by :func:`evaluate_points`.
    """

    alpha: float
    c: float
    k1: float
    k2: float
    phi01: float
    phi02: float
    delta_n: float
    lower_bound: float
    pruned_bound: float
    grid_points: int
    points_evaluated: int
    points_verified: int
    paths: int
    paths_searched: int
    intervals: int
    intervals_searched: int


@dataclass
class _PathTable:
    """Per-(alpha, c) arrays along the contact path used by bound and evaluation."""

    phi1: np.ndarray
    phi2: np.ndarray
    h1: np.ndarray
    h2: np.ndarray
    target: np.ndarray       # F_n2 * D_h / (180/pi): the value N*pi/180 must reach
    g: np.ndarray            # Delta N at each sample (N)
    d11: np.ndarray
    d12: np.ndarray


def _table(path: ContactPath, load: Load) -> _PathTable | None:
    st = path.state
    if len(path.phi2) < 3:
        return None
    fn2 = load.hover_force
    den_s = st.d11 * st.h2 - st.d21 * st.h1
    den_h = den_s + load.mu * (st.d12 * st.h2 - st.d22 * st.h1)
    g = fn2 * (den_h / den_s - 1.0)
    return _PathTable(st.phi1, st.phi2, st.h1, st.h2, fn2 * den_h / DEG_PER_RAD, g, st.d11, st.d12)


def interval_bounds(tab: _PathTable, hinge_margin: float = 0.0) -> np.ndarray:
    """Least Delta N (N) any grid point whose hover force first reaches F_n2 in (t_{i-1}, t_i] can
    get, for every i (entry 0 is inf: a crossing at the first sample is not a valid grasp).

    The value there is ``G(w) = g[i-1] + w (g[i] - g[i-1])``; the admissible w are those in [0, 1]
    with phi1(w), phi2(w) >= ``hinge_margin`` and G(w) >= 0 (all linear in w), an interval
    [w_lo, w_hi]; G is linear, so its least value is at one end. The interval is widened by 1e-9 so
    the bound is never above a value :func:`evaluate_points` can compute; inf where no w is admissible.
    """
    n = len(tab.g)
    w_lo = np.zeros(n - 1)
    w_hi = np.ones(n - 1)
    for arr, floor in ((tab.phi1, hinge_margin), (tab.phi2, hinge_margin), (tab.g, 0.0)):
        a0 = arr[:-1] - floor
        slope = arr[1:] - arr[:-1]
        with np.errstate(divide="ignore", invalid="ignore"):
            root = -a0 / slope
        w_lo = np.where(slope > 0, np.maximum(w_lo, root), w_lo)
        w_hi = np.where(slope < 0, np.minimum(w_hi, root), w_hi)
        # flat: admissible everywhere or nowhere
        w_hi = np.where((slope == 0) & (a0 < 0), -1.0, w_hi)
    w_lo = np.clip(w_lo - 1e-9, 0.0, 1.0)
    w_hi = np.clip(w_hi + 1e-9, -1.0, 1.0)
    g0, dg = tab.g[:-1], np.diff(tab.g)
    least = np.maximum(np.minimum(g0 + w_lo * dg, g0 + w_hi * dg), 0.0)
    out = np.full(n, np.inf)
    out[1:] = np.where(w_lo <= w_hi, least, np.inf)
    return out


def _value_at_crossing(tab: _PathTable, i: np.ndarray, e0: np.ndarray, e1: np.ndarray, k1: np.ndarray,
                       phi01: np.ndarray, load: Load, hinge_margin: float) -> np.ndarray:
    """Delta N (N) of spring sets whose hover excess goes from e0 < 0 at sample i-1 to e1 >= 0 at
    sample i (linear interpolation of the crossing), NaN where the grasp is not valid."""
    w = np.clip(-e0 / np.where(e1 != e0, e1 - e0, 1.0), 0.0, 1.0)

    def at(arr: np.ndarray) -> np.ndarray:
        return arr[i - 1] + w * (arr[i] - arr[i - 1])

    dn = at(tab.g)
    ok = (at(tab.phi1) >= hinge_margin) & (at(tab.phi2) >= hinge_margin) & (dn >= 0)
    fn2 = load.hover_force
    s1 = k1 * DEG_PER_RAD * (at(tab.phi1) + phi01)
    # rod force must push (compression) in hover and in the static grasp
    fd_h = (s1 + fn2 * (at(tab.d11) + load.mu * at(tab.d12))) / at(tab.h1)
    fd_s = (s1 + (fn2 + dn) * at(tab.d11)) / at(tab.h1)
    ok &= (fd_h > 0) & (fd_s > 0)
    return np.where(ok, dn, np.nan)


def _excess(tab: _PathTable, j: int | np.ndarray | slice, k1: np.ndarray, k2: np.ndarray, phi01: np.ndarray,
            phi02: np.ndarray) -> np.ndarray:
    """N*pi/180 - target at sample(s) j: >= 0 once the hover force has reached F_n2."""
    n1 = k2 * (tab.phi2[j] + phi02) * tab.h1[j] - k1 * (tab.phi1[j] + phi01) * tab.h2[j]
    return n1 - tab.target[j]


def evaluate_points(tab: _PathTable, k1: np.ndarray, k2: np.ndarray, phi01: np.ndarray, phi02: np.ndarray,
                    load: Load, hinge_margin: float = 0.0) -> np.ndarray:
    """Delta N (N) of each spring set (arrays (m,)) on one path; NaN where the grasp is not valid:
    the hover force never reaches F_n2, or reaches it with a hinge within ``hinge_margin`` (rad) of
    its stop, or with the rod pulling, or with Delta N < 0 (resting grasp below the hover force).
    The crossing is interpolated linearly between path samples. The reference evaluation."""
    ex = _excess(tab, slice(None), k1[:, None], k2[:, None], phi01[:, None], phi02[:, None])
    above = ex >= 0
    i = np.argmax(above, axis=1)
    ok = above.any(axis=1) & (i > 0)
    i = np.where(ok, i, 1)
    rows = np.arange(len(k1))
    dn = _value_at_crossing(tab, i, ex[rows, i - 1], ex[rows, i], k1, phi01, load, hinge_margin)
    return np.where(ok, dn, np.nan)


def build_tables(geom: GripperGeometry, grid: ParameterGrid, load: Load, samples: int = 721,
                 hinge_margin: float = 0.0) -> list[tuple[int, int, _PathTable]]:
    """Contact-path tables for every (alpha, c) of the grid that can touch the can at all.
    (``hinge_margin`` is accepted for compatibility; the tables do not depend on it.)"""
    out = []
    for ia, alpha in enumerate(grid.alpha):
        for ic, c in enumerate(grid.c):
            g = GripperGeometry(geom.a1, geom.a2, geom.a3, geom.b, float(c), geom.d, geom.l1, geom.l2,
                                geom.r, float(alpha))
            tab = _table(contact_path(g, load.radius, load.mu, n=samples), load)
            if tab is not None:
                out.append((ia, ic, tab))
    return out


def brute_force(geom: GripperGeometry, grid: ParameterGrid, load: Load, samples: int = 721,
                hinge_margin: float = 0.0) -> np.ndarray:
    """Delta N at every grid point by plain enumeration (NaN where invalid); shape of the grid.
    Only for small grids (tests): the work is grid.size x samples."""
    out = np.full([len(a) for a in (grid.alpha, grid.c, grid.k1, grid.k2, grid.phi01, grid.phi02)], np.nan)
    mesh = np.meshgrid(grid.k1, grid.k2, grid.phi01, grid.phi02, indexing="ij")
    k1, k2, phi01, phi02 = (m.ravel() for m in mesh)
    for ia, ic, tab in build_tables(geom, grid, load, samples, hinge_margin):
        out[ia, ic] = evaluate_points(tab, k1, k2, phi01, phi02, load, hinge_margin).reshape(mesh[0].shape)
    return out


@dataclass
class _Search:
    """Incumbent and counters of one :func:`optimise` run."""

    value: float = np.inf
    where: tuple[int, ...] | None = None
    points: int = 0
    verified: int = 0

    def offer(self, value: float, where: tuple[int, ...]) -> None:
        # ties go to the smallest grid index, so the answer does not depend on the search order
        if value < self.value or (value == self.value and self.where is not None and where < self.where):
            self.value, self.where = value, where


#: relative widening of the phi02 ranges (sigma form against direct form of the hover condition)
_RANGE_TOLERANCE = 1e-9


def _search_path(tab: _PathTable, bounds: np.ndarray, grid: ParameterGrid, load: Load, hinge_margin: float,
                 head: tuple[int, int], state: _Search, max_cells: int = 4_000_000,
                 max_points: int = 1_000_000) -> np.ndarray:
    """Value every grid point of one (alpha, c) path whose first hover crossing lies in an interval
    with ``bounds[i] < state.value``, intervals in order of their bound; updates ``state``.

    ``max_cells`` caps the sigma table (triples x samples, one block of k1 at a time) and
    ``max_points`` the points valued at once. Returns the mask of intervals searched for every spring
    set (the others keep their bound).
    """
    k1, k2, p01, p02 = grid.k1, grid.k2, grid.phi01, grid.phi02
    searched = np.zeros(len(bounds), dtype=bool)
    wanted = np.nonzero(bounds < state.value)[0]
    if wanted.size == 0:
        return searched
    order = wanted[np.argsort(bounds[wanted], kind="stable")]
    m = int(wanted.max()) + 1
    per_k1 = len(p01) * len(k2) * m
    step = max(1, int(max_cells // per_k1))
    complete = np.ones(len(bounds), dtype=bool)
    for start in range(0, len(k1), step):
        k1_index = np.arange(start, min(start + step, len(k1)))
        # sigma_j for every triple (k1, phi01, k2) of this block, rows in C order of those three axes
        spring_c = k1[k1_index][:, None, None] * (tab.phi1[:m] + p01[None, :, None])
        a = (tab.target[:m] + spring_c * tab.h2[:m]) / tab.h1[:m]
        sigma = (a[:, :, None, :] - k2[None, None, :, None] * tab.phi2[:m]).reshape(-1, m)
        running = np.minimum.accumulate(sigma, axis=1)
        row_k1, row_p01, row_k2 = (ax.ravel() for ax in np.meshgrid(k1_index, np.arange(len(p01)),
                                                                     np.arange(len(k2)), indexing="ij"))
        k2_row = k2[row_k2]
        for i in order:
            if bounds[i] >= state.value:
                complete[i] = False
                continue
            s, r = sigma[:, i], running[:, i - 1]
            tol = _RANGE_TOLERANCE * (1.0 + np.abs(s) + np.abs(r))
            p_lo, p_hi = s - tol, r + tol                  # first crossing at i: p_lo <= k2 phi02 < p_hi
            rows = np.nonzero((p_lo < p_hi) & (p_lo <= k2_row * p02[-1]) & (p_hi > k2_row * p02[0]))[0]
            if rows.size == 0:
                continue
            kr = k2_row[rows]
            safe = np.where(kr > 0, kr, 1.0)
            # k2 = 0: k2 phi02 = 0 for every phi02, inside [p_lo, p_hi) by the row filter above
            lo = np.where(kr > 0, np.searchsorted(p02, p_lo[rows] / safe, side="left"), 0)
            hi = np.where(kr > 0, np.searchsorted(p02, p_hi[rows] / safe, side="left"), len(p02))
            counts = np.maximum(hi - lo, 0)
            state.points += int(counts.sum())
            # value the points in blocks of about max_points (bounded memory however many cross here)
            cuts = np.searchsorted(np.cumsum(counts), np.arange(max_points, counts.sum(), max_points))
            for part in np.split(np.arange(rows.size), cuts):
                c = counts[part]
                total = int(c.sum())
                if total == 0:
                    continue
                rep = np.repeat(rows[part], c)
                j02 = np.repeat(lo[part] - (np.cumsum(c) - c), c) + np.arange(total)
                kk1, kk2, pp01, pp02 = k1[row_k1[rep]], k2_row[rep], p01[row_p01[rep]], p02[j02]
                e0 = _excess(tab, i - 1, kk1, kk2, pp01, pp02)
                e1 = _excess(tab, i, kk1, kk2, pp01, pp02)
                dn = _value_at_crossing(tab, i, e0, e1, kk1, pp01, load, hinge_margin)
                _verify(tab, load, hinge_margin, head, state, dn, rep, row_k1, row_p01, row_k2, j02, grid)
    searched[order] = complete[order]
    return searched


def _verify(tab: _PathTable, load: Load, hinge_margin: float, head: tuple[int, int], state: _Search,
            dn: np.ndarray, rep: np.ndarray, row_k1: np.ndarray, row_p01: np.ndarray, row_k2: np.ndarray,
            j02: np.ndarray, grid: ParameterGrid) -> None:
    """Re-evaluate with :func:`evaluate_points`, smallest first, every point whose value beats the
    incumbent (a point let in by the range tolerance may cross elsewhere: its true value counts)."""
    pending = np.nonzero(dn <= state.value)[0]
    pending = pending[np.argsort(dn[pending], kind="stable")]
    while pending.size:
        batch, pending = pending[:256], pending[256:]
        r = rep[batch]
        i1, i2, j1, j2 = row_k1[r], row_k2[r], row_p01[r], j02[batch]
        true = evaluate_points(tab, grid.k1[i1], grid.k2[i2], grid.phi01[j1], grid.phi02[j2], load,
                               hinge_margin)
        state.verified += len(batch)
        for b in np.nonzero(np.isfinite(true))[0]:
            state.offer(float(true[b]), head + (int(i1[b]), int(i2[b]), int(j1[b]), int(j2[b])))
        pending = pending[dn[pending] <= state.value]


def optimise(geom: GripperGeometry, grid: ParameterGrid, load: Load, samples: int = 361,
             hinge_margin: float = 0.0) -> OptimumResult:
    """Least Delta N >= 0 over the whole grid, exactly (for the sampled path), and fast.

    Paths (alpha, c) in order of their least interval bound (:func:`interval_bounds`), on each path the
    intervals in order of their bound; an interval is searched (:func:`_search_path`: every grid point
    crossing there valued) only while its bound is below the best value found so far. The first
    interval searched seeds the incumbent; after it nearly every path and interval is dropped unseen.
    """
    tables = build_tables(geom, grid, load, samples)
    bounds = [interval_bounds(tab, hinge_margin) for _, _, tab in tables]
    least = np.array([b.min() for b in bounds])
    state = _Search()
    searched = [np.zeros(len(b), dtype=bool) for b in bounds]
    paths_searched = 0
    for t in np.argsort(least, kind="stable"):
        if least[t] >= state.value:
            break
        ia, ic, tab = tables[t]
        searched[t] = _search_path(tab, bounds[t], grid, load, hinge_margin, (ia, ic), state)
        paths_searched += 1
    if state.where is None:  # the template's grid, not fabricate, has no answer: exit 2 naming what to change
        raise SynthesisError("compliant_gripper: no point of the [optimisation] grid holds the object with both "
                             "hinges min_hinge_deg off their stops; widen the grid's ranges (k1, k2, phi01, "
                             "phi02, alpha, c) or lower min_hinge_deg")
    pruned = min((float(b[~s].min()) for b, s in zip(bounds, searched, strict=True) if (~s).any()),
                 default=np.inf)
    # the certificate: an interval is left unsearched only when its bound is not below the incumbent,
    # which only decreases, so everything not searched is bounded by at least the optimum
    if pruned < state.value:
        raise RuntimeError(f"compliant optimiser: unsearched bound {pruned} below the optimum {state.value}")
    ia, ic, i1, i2, j1, j2 = state.where
    return OptimumResult(alpha=float(grid.alpha[ia]), c=float(grid.c[ic]), k1=float(grid.k1[i1]),
                         k2=float(grid.k2[i2]), phi01=float(grid.phi01[j1]), phi02=float(grid.phi02[j2]),
                         delta_n=state.value, lower_bound=min(pruned, state.value), pruned_bound=pruned,
                         grid_points=grid.size, points_evaluated=state.points, points_verified=state.verified,
                         paths=len(tables), paths_searched=paths_searched,
                         intervals=int(sum(len(b) - 1 for b in bounds)),
                         intervals_searched=int(sum(s.sum() for s in searched)))
