"""Fast, certified minimisation of Delta N = F_n1 - F_n2 over the paper's parameter grid (Table 1).

Why it can be fast
------------------
For a fixed root angle alpha and seat length c the finger touching the can is a one-parameter family
of configurations (the contact path, closed form in phi2). At a configuration t of that path the two
torque balances give (eqs 3-6, with f = mu F_n)::

    F_n1 = N / D_s,  F_hover = N / D_h,  N = 180/pi * [k2 (phi2 + phi02) h1 - k1 (phi1 + phi01) h2]

so the springs enter only through N, and Delta N = F_n2 (D_h / D_s - 1) = G(t) depends on the
configuration alone. The four spring parameters only choose *where* on the path the hover force first
reaches F_n2. N is bilinear in (k, phi0), so over any box of spring parameters its range at each t is
exact from the box corners. That gives a valid lower bound of Delta N over a whole box: the least
G >= 0 over the path samples where a hover crossing is still possible for some member of the box
(not all members have crossed earlier, and some member has crossed here). Branch and bound over the
grid indices with that bound enumerates only boxes that could still win (about a quarter of the
~1.5e9 points for the paper's ranges, each box vectorised) and proves the rest cannot do better.

Objective and constraints. The paper minimises Delta N = F_n1 - F_n2 "with F_n2 satisfied" and does
not list its other constraints. We keep grasps that are physical: hover force reaching F_n2 on the
physical branch (tip on the can, rod pushing in hover and at rest), both hinges at least
``hinge_margin`` off their stops (else a stop, not the spring, carries the torque and eqs 4/6 do not
hold), and Delta N >= 0 (the resting grasp at least the hover force). Without the margin the search
runs into configurations with the tip hinge a fraction of a degree off its stop, where Delta N
crosses zero; that is a degenerate optimum, not a design.

The bound is exact up to the sampling of the contact path; within a sample interval the smooth G is
bracketed by its end values widened by the local second difference (a curvature allowance).
``tests/test_compliant.py`` checks the result against plain enumeration of a sub-grid.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from fabricate.synthesis.compliant_model import (
    DEG_PER_RAD,
    ContactPath,
    GripperGeometry,
    Load,
    contact_path,
)


@dataclass(frozen=True)
class ParameterGrid:
    """The six searched axes (Table 1): alpha (rad), c (mm), k1, k2 (N·mm/deg), phi01, phi02 (rad)."""

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
    """Best grid point, its Delta N (N) and the certificate of the search."""

    alpha: float
    c: float
    k1: float
    k2: float
    phi01: float
    phi02: float
    delta_n: float
    lower_bound: float
    grid_points: int
    points_evaluated: int
    boxes_bounded: int


@dataclass
class _PathTable:
    """Per-(alpha, c) arrays along the contact path used by bound and evaluation."""

    phi1: np.ndarray
    phi2: np.ndarray
    h1: np.ndarray
    h2: np.ndarray
    target: np.ndarray       # F_n2 * D_h / (180/pi): the value N*pi/180 must reach
    g: np.ndarray            # Delta N at each sample (N)
    g_margin: np.ndarray     # curvature allowance of G inside the interval ending at each sample
    d11: np.ndarray
    d12: np.ndarray
    allowed: np.ndarray      # both hinges at least the margin off their stops


def _table(path: ContactPath, load: Load, hinge_margin: float) -> _PathTable | None:
    st = path.state
    if len(path.phi2) < 3:
        return None
    fn2 = load.hover_force
    den_s = st.d11 * st.h2 - st.d21 * st.h1
    den_h = den_s + load.mu * (st.d12 * st.h2 - st.d22 * st.h1)
    g = fn2 * (den_h / den_s - 1.0)
    second = np.abs(np.diff(g, 2))
    margin = np.zeros_like(g)
    margin[1:] = np.maximum(np.concatenate([[second[0]], second]), np.concatenate([second, [second[-1]]]))
    allowed = (st.phi1 >= hinge_margin) & (st.phi2 >= hinge_margin)
    return _PathTable(st.phi1, st.phi2, st.h1, st.h2, fn2 * den_h / DEG_PER_RAD, g, margin, st.d11, st.d12,
                      allowed)


def _product_range(lo1: float, hi1: float, lo2: np.ndarray, hi2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    corners = np.stack([lo1 * lo2, lo1 * hi2, hi1 * lo2, hi1 * hi2])
    return corners.min(0), corners.max(0)


def _excess_range(tab: _PathTable, grid: ParameterGrid, box: tuple[tuple[int, int], ...]):
    """Least and greatest of N*pi/180 - target over a box of spring indices, at every path sample."""
    (k1a, k1b), (k2a, k2b), (p1a, p1b), (p2a, p2b) = box
    a_lo, a_hi = _product_range(grid.k2[k2a], grid.k2[k2b], tab.phi2 + grid.phi02[p2a], tab.phi2 + grid.phi02[p2b])
    b_lo, b_hi = _product_range(grid.k1[k1a], grid.k1[k1b], tab.phi1 + grid.phi01[p1a], tab.phi1 + grid.phi01[p1b])
    ta = np.stack([a_lo * tab.h1, a_hi * tab.h1])
    tb = np.stack([-b_lo * tab.h2, -b_hi * tab.h2])
    lo = ta.min(0) + tb.min(0) - tab.target
    hi = ta.max(0) + tb.max(0) - tab.target
    return lo, hi


def _lower_bound(tab: _PathTable, grid: ParameterGrid, box) -> float:
    """Least Delta N >= 0 any member of ``box`` can reach (inf if none has a valid hover crossing)."""
    lo, hi = _excess_range(tab, grid, box)
    n = len(lo)
    crossed_all = np.nonzero(lo >= 0)[0]
    last = int(crossed_all[0]) if crossed_all.size else n - 1
    idx = np.arange(1, last + 1)
    idx = idx[hi[idx] >= 0]
    if idx.size == 0:
        return np.inf
    idx = idx[tab.allowed[idx] | tab.allowed[idx - 1]]
    g0, g1 = tab.g[idx - 1], tab.g[idx]
    idx = idx[np.maximum(g0, g1) + tab.g_margin[idx] >= 0]      # Delta N < 0 throughout: excluded
    if idx.size == 0:
        return np.inf
    g0, g1 = tab.g[idx - 1], tab.g[idx]
    least = np.where(np.minimum(g0, g1) <= 0, 0.0, np.minimum(g0, g1) - tab.g_margin[idx])
    return float(max(least.min(), 0.0))


def evaluate_points(tab: _PathTable, k1: np.ndarray, k2: np.ndarray, phi01: np.ndarray, phi02: np.ndarray,
                    load: Load, hinge_margin: float = 0.0) -> np.ndarray:
    """Delta N (N) of each spring set (arrays (m,)) on one path; NaN where the grasp is not valid:
    the hover force never reaches F_n2, or reaches it with a hinge within ``hinge_margin`` (rad) of
    its stop, or with the rod pulling, or with Delta N < 0 (resting grasp below the hover force).
    The crossing is interpolated linearly between path samples."""
    n1 = (k2[:, None] * (tab.phi2 + phi02[:, None]) * tab.h1
          - k1[:, None] * (tab.phi1 + phi01[:, None]) * tab.h2)
    ex = n1 - tab.target
    above = ex >= 0
    i = np.argmax(above, axis=1)
    ok = above.any(axis=1) & (i > 0)
    i = np.where(ok, i, 1)
    rows = np.arange(len(k1))
    e0, e1 = ex[rows, i - 1], ex[rows, i]
    w = np.clip(-e0 / np.where(e1 != e0, e1 - e0, 1.0), 0.0, 1.0)

    def at(arr: np.ndarray) -> np.ndarray:
        return arr[i - 1] + w * (arr[i] - arr[i - 1])

    dn = at(tab.g)
    ok &= (at(tab.phi1) >= hinge_margin) & (at(tab.phi2) >= hinge_margin) & (dn >= 0)
    fn2 = load.hover_force
    s1 = k1 * DEG_PER_RAD * (at(tab.phi1) + phi01)
    # rod force must push (compression) in hover and in the static grasp
    fd_h = (s1 + fn2 * (at(tab.d11) + load.mu * at(tab.d12))) / at(tab.h1)
    fd_s = (s1 + (fn2 + dn) * at(tab.d11)) / at(tab.h1)
    ok &= (fd_h > 0) & (fd_s > 0)
    return np.where(ok, dn, np.nan)


def build_tables(geom: GripperGeometry, grid: ParameterGrid, load: Load, samples: int = 721,
                 hinge_margin: float = 0.0) -> list[tuple[int, int, _PathTable]]:
    """Contact-path tables for every (alpha, c) of the grid that can touch the can at all."""
    out = []
    for ia, alpha in enumerate(grid.alpha):
        for ic, c in enumerate(grid.c):
            g = GripperGeometry(geom.a1, geom.a2, geom.a3, geom.b, float(c), geom.d, geom.l1, geom.l2,
                                geom.r, float(alpha))
            tab = _table(contact_path(g, load.radius, load.mu, n=samples), load, hinge_margin)
            if tab is not None:
                out.append((ia, ic, tab))
    return out


def brute_force(geom: GripperGeometry, grid: ParameterGrid, load: Load, samples: int = 721,
                hinge_margin: float = 0.0) -> np.ndarray:
    """Delta N at every grid point by plain enumeration (NaN where invalid); shape of the grid.
    Only for small grids (tests): the work is grid.size x samples."""
    out = np.full([len(a) for a in (grid.alpha, grid.c, grid.k1, grid.k2, grid.phi01, grid.phi02)], np.nan)
    mesh = np.meshgrid(grid.k1, grid.k2, grid.phi01, grid.phi02, indexing="ij")
    flat = [m.ravel() for m in mesh]
    for ia, ic, tab in build_tables(geom, grid, load, samples, hinge_margin):
        out[ia, ic] = evaluate_points(tab, *flat, load, hinge_margin).reshape(mesh[0].shape)
    return out


def _enumerate_box(tab: _PathTable, grid: ParameterGrid, load: Load, hinge_margin: float,
                   box: tuple[tuple[int, int], ...], best: float = np.inf) -> tuple[float, tuple[int, ...]]:
    """Exact least Delta N >= 0 over every grid point of a box of (k1, k2, phi01, phi02) indices on
    one path (inf if none is valid and below ``best``).

    With h1 > 0 on the path the hover condition reads ``k2 phi02 >= sigma(t)`` with
    ``sigma = (target + k1 (phi1 + phi01) h2) / h1 - k2 phi2``; the first crossing for a preload is
    where the running minimum of sigma drops to ``k2 phi02``, found for all preloads at once by one
    sorted search (each row offset so the rows stay ordered).
    """
    k1_index, k2_index, p01_index, p02_index = (np.arange(lo, hi + 1) for lo, hi in box)
    k1 = grid.k1[k1_index][:, None, None]
    k2 = grid.k2[k2_index][None, :, None]
    p01 = grid.phi01[p01_index][None, None, :]
    phi02 = grid.phi02[p02_index]
    shape = (len(k1_index), len(k2_index), len(p01_index))
    n = len(tab.phi2)
    sigma = ((tab.target + (k1[..., None] * (tab.phi1 + p01[..., None])) * tab.h2) / tab.h1
             - k2[..., None] * tab.phi2)
    sigma = np.clip(sigma.reshape(-1, n), -_BIG / 4, _BIG / 4)
    running = np.minimum.accumulate(sigma, axis=1)
    rows = running.shape[0]
    offset = np.arange(rows)[:, None] * _BIG
    keys = (-running + offset).ravel()
    preload = (k2 * np.ones(shape)).reshape(-1)[:, None] * phi02[None, :]       # k2 phi02 (rows, P)
    queries = (-preload + offset)
    i = np.searchsorted(keys, queries.ravel(), side="left").reshape(rows, -1) - (np.arange(rows) * n)[:, None]
    ok = (i > 0) & (i < n)
    i = np.clip(i, 1, n - 1)
    r = np.arange(rows)[:, None]
    e0 = tab.h1[i - 1] * (preload - sigma[r, i - 1])
    e1 = tab.h1[i] * (preload - sigma[r, i])
    w = np.clip(-e0 / np.where(e1 != e0, e1 - e0, 1.0), 0.0, 1.0)

    dn = tab.g[i - 1] + w * (tab.g[i] - tab.g[i - 1])
    # only points that would improve on the best so far need the remaining checks
    cand = np.nonzero(ok & (dn >= 0) & (dn < best))
    if cand[0].size == 0:
        return np.inf, (0, 0, 0, 0)
    ic, wc, dnc = i[cand], w[cand], dn[cand]

    def at(arr: np.ndarray) -> np.ndarray:
        return arr[ic - 1] + wc * (arr[ic] - arr[ic - 1])

    ph1, ph2 = at(tab.phi1), at(tab.phi2)
    k1r = np.broadcast_to(k1, shape).reshape(-1)[cand[0]]
    p01r = np.broadcast_to(p01, shape).reshape(-1)[cand[0]]
    s1 = k1r * DEG_PER_RAD * (ph1 + p01r)
    fn2 = load.hover_force
    h1, d11 = at(tab.h1), at(tab.d11)
    good = (ph1 >= hinge_margin) & (ph2 >= hinge_margin)
    good &= ((s1 + fn2 * (d11 + load.mu * at(tab.d12))) / h1 > 0) & ((s1 + (fn2 + dnc) * d11) / h1 > 0)
    if not good.any():
        return np.inf, (0, 0, 0, 0)
    k = int(np.argmin(np.where(good, dnc, np.inf)))
    row, col = int(cand[0][k]), int(cand[1][k])
    a, b2, c1 = np.unravel_index(row, shape)
    return float(dnc[k]), (int(k1_index[a]), int(k2_index[b2]), int(p01_index[c1]), int(p02_index[col]))


_BIG = 1.0e9


def optimise(geom: GripperGeometry, grid: ParameterGrid, load: Load, samples: int = 361,
             hinge_margin: float = 0.0, leaf_size: int = 40000) -> OptimumResult:
    """Least Delta N >= 0 over the whole grid, exactly (up to the path sampling), and fast.

    Branch and bound: boxes of grid indices (one (alpha, c) slab each, split along the spring axis with
    the most indices) are taken in order of their lower bound (:func:`_lower_bound`, the least Delta N
    any member could reach); a box whose bound is not below the best value found so far is dropped,
    small boxes are enumerated exactly by :func:`_enumerate_box`. ``lower_bound`` is the least bound
    of everything dropped: no dropped grid point can beat the optimum.
    """
    tables = build_tables(geom, grid, load, samples, hinge_margin)
    full = ((0, len(grid.k1) - 1), (0, len(grid.k2) - 1), (0, len(grid.phi01) - 1), (0, len(grid.phi02) - 1))
    heap: list = []
    boxes = 0
    for t_index, (_, _, tab) in enumerate(tables):
        lb = _lower_bound(tab, grid, full)
        boxes += 1
        if np.isfinite(lb):
            heapq.heappush(heap, (lb, boxes, t_index, full))
    best = (np.inf, None)
    evaluated = 0
    dropped = np.inf
    while heap:
        lb, _, t_index, box = heapq.heappop(heap)
        if lb >= best[0]:
            dropped = min(dropped, lb)
            break
        ia, ic, tab = tables[t_index]
        sizes = [hi - lo + 1 for lo, hi in box]
        if int(np.prod(sizes)) <= leaf_size:
            value, where = _enumerate_box(tab, grid, load, hinge_margin, box, best[0])
            evaluated += int(np.prod(sizes))
            if value < best[0]:
                best = (value, (ia, ic) + where)
            continue
        dim = int(np.argmax(sizes))
        lo, hi = box[dim]
        mid = (lo + hi) // 2
        for part in ((lo, mid), (mid + 1, hi)):
            child = box[:dim] + (part,) + box[dim + 1:]
            clb = max(_lower_bound(tab, grid, child), lb)
            boxes += 1
            if clb < best[0]:
                heapq.heappush(heap, (clb, boxes, t_index, child))
            else:
                dropped = min(dropped, clb)
    if best[1] is None:
        raise ValueError("no grid point gives a valid grasp")
    ia, ic, i1, i2, j1, j2 = best[1]
    return OptimumResult(alpha=float(grid.alpha[ia]), c=float(grid.c[ic]), k1=float(grid.k1[i1]),
                         k2=float(grid.k2[i2]), phi01=float(grid.phi01[j1]), phi02=float(grid.phi02[j2]),
                         delta_n=best[0], lower_bound=float(min(dropped, best[0])),
                         grid_points=grid.size, points_evaluated=evaluated, boxes_bounded=boxes)
