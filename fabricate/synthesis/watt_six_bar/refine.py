"""Approximate refinement of region points that suffer a circuit defect (our extension to the Watt-I six-bar paper).

Every point of the solution region passes the four positions *exactly* on some assembly of each loop,
but not necessarily on one continuous branch: when a loop must switch branch between two positions
(a circuit defect) the built finger misses the later positions by centimetres. With the paper's
printed Table 2 (angles rounded to whole degrees) every non-trivial dyad d-e of C_d has such a
defect in the loop proximal-middle-distal-coupler; the paper's mechanism 1 sits next to a change-point
four-bar (|ad| + |ab| ~ |be| + |de|) where rounding the input moves the curves by millimetres.

So, when asked, we look for mechanisms that pass the positions within a fingertip tolerance on one
continuous branch: a damped Gauss-Newton (Levenberg-Marquardt) run, vectorised over many seeds (the
region points themselves), on the eight coordinates of d, e, f, d0 inside their boxes, minimising the
fingertip errors at positions 2..4 (position 1 is exact by construction) plus a weak pull towards
the seed so each run stays near its region point. Results are candidates, not region points: they
are reported as such with their fingertip error, their distance to the exact curves and K.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.synthesis.watt_six_bar.statics import (
    SixBarBatch,
    assemble,
    fingertip_errors,
    force_index,
    middle_link_clearance,
    segment_distance,
)

#: Residual (mm) standing in for a position where a loop cannot close: large, so the step is refused.
_NO_ASSEMBLY = 1.0e3
#: Extra clearance (mm) the minimisation aims for beyond the template's limit.
_CLEARANCE_MARGIN = 0.1


@dataclass(frozen=True)
class RefinedCandidates:
    """Approximate mechanisms found from region seeds; arrays over M candidates.

    Attributes
    ----------
    d, e, f, d0 : (M, 2) arrays
        Joints at position 1, mm.
    seed : (M,) int array
        Index of the region point each run started from.
    tip_error : (M,) array
        Largest fingertip error at the four positions, mm.
    K : (M,) array
        Force index.
    clearance : (M,) array
        Smallest distance of d and e from the middle link a-b over the motion, mm.
    accepted : (M,) bool
        Within the tip tolerance, K limit, clearance and the boxes.
    """

    d: np.ndarray
    e: np.ndarray
    f: np.ndarray
    d0: np.ndarray
    seed: np.ndarray
    tip_error: np.ndarray
    K: np.ndarray
    clearance: np.ndarray
    accepted: np.ndarray

    def __len__(self) -> int:
        return len(self.d)


def _residuals(params: np.ndarray, seeds: np.ndarray, template: SixBarBatch, theta_positions: np.ndarray,
               tips: np.ndarray, pull: np.ndarray, theta_check: np.ndarray, min_clearance: float) -> np.ndarray:
    """(N, 6 + 1 + 8) residuals: fingertip misses at positions 2..4, the clearance shortfall of d and e
    from the middle link over ``theta_check`` (zero when clear), then pull * (params - anchor)."""
    batch = SixBarBatch(template.a, template.b, template.c, params[:, 0:2], params[:, 2:4],
                        params[:, 4:6], params[:, 6:8], template.theta1_start)
    n_pos = len(theta_positions) - 1
    checking = min_clearance > 0.0 and len(theta_check) > 0
    poses = assemble(batch, np.concatenate([theta_positions[1:], theta_check]) if checking
                     else theta_positions[1:])
    miss = (poses.c[:, :n_pos] - tips[None, 1:]).reshape(len(params), -1)
    bad = np.repeat(poses.margin[:, :n_pos] < 0.0, 2, axis=1) | ~np.isfinite(miss)
    miss = np.where(bad, _NO_ASSEMBLY, miss)
    shortfall = np.zeros((len(params), 1))
    if checking:
        gap = np.minimum(segment_distance(poses.e[:, n_pos:], poses.a[:, n_pos:], poses.b[:, n_pos:]),
                         segment_distance(poses.d[:, n_pos:], poses.a[:, n_pos:], poses.b[:, n_pos:]))
        gap = np.where(poses.margin[:, n_pos:] >= 0.0, gap, 0.0)
        # aim a little beyond the limit: the scoring samples the motion more finely than this check
        shortfall[:, 0] = np.maximum(0.0, min_clearance + _CLEARANCE_MARGIN - np.min(gap, axis=1))
    return np.concatenate([miss, shortfall, pull * (params - seeds)], axis=1)


def refine(seeds: np.ndarray, template: SixBarBatch, theta_positions: np.ndarray, tips: np.ndarray,
           lower: np.ndarray, upper: np.ndarray, iterations: int = 60, pull: np.ndarray | float = 0.01,
           anchor: np.ndarray | None = None, theta_check: np.ndarray | None = None,
           min_clearance: float = 0.0) -> np.ndarray:
    """Levenberg-Marquardt on every seed at once, kept inside ``lower``/``upper`` by clipping.

    Parameters
    ----------
    seeds : (N, 8) array
        Starting (d, e, f, d0), mm.
    template : SixBarBatch
        Supplies a, b, c at position 1 and theta1 there (its d, e, f, d0 are ignored).
    theta_positions : (4,) array
        theta1 at the positions, rad.
    tips : (4, 2) array
        Fingertip targets, mm.
    lower, upper : (8,) arrays
        Box bounds of (d, e, f, d0).
    pull : float or (8,) array
        Weight (mm per mm) of the pull towards ``anchor`` (default: the seeds) per coordinate.
    theta_check : (S,) array, optional
        Inputs (rad) at which d and e must keep ``min_clearance`` (mm) from the middle link a-b.

    Returns
    -------
    (N, 8) array of refined parameters.
    """
    p = np.clip(seeds, lower, upper)
    damping = np.full(len(p), 1e-2)
    anchor = seeds if anchor is None else anchor
    theta_check = np.zeros(0) if theta_check is None else np.asarray(theta_check, dtype=np.float64)
    args = (anchor, template, theta_positions, tips, np.broadcast_to(np.asarray(pull, dtype=np.float64), (8,)),
            theta_check, float(min_clearance))
    r = _residuals(p, *args)
    cost = np.einsum("ij,ij->i", r, r)
    h = 1e-5
    eye = np.eye(p.shape[1])
    # the eight forward differences of every seed in one call of _residuals (its rows do not depend on
    # each other): the per-call numpy overhead was most of the time for few seeds
    shifts = (h * eye)[:, None, :]
    stacked_args = (np.tile(anchor, (p.shape[1], 1)),) + args[1:]
    for _ in range(iterations):
        shifted = _residuals((p[None] + shifts).reshape(-1, p.shape[1]), *stacked_args)
        jac = np.empty(r.shape + (p.shape[1],))  # (N, residuals, 8) in memory, as the sums below expect
        jac[...] = ((shifted.reshape((p.shape[1],) + r.shape) - r) / h).transpose(1, 2, 0)
        jtj = np.einsum("nik,nil->nkl", jac, jac)
        jtr = np.einsum("nik,ni->nk", jac, r)
        diag = np.einsum("nkk->nk", jtj)
        system = jtj + damping[:, None, None] * (np.eye(p.shape[1]) * (diag[:, None, :] + 1e-9))
        step = np.linalg.solve(system, -jtr[..., None])[..., 0]
        trial = np.clip(p + step, lower, upper)
        r_trial = _residuals(trial, *args)
        cost_trial = np.einsum("ij,ij->i", r_trial, r_trial)
        better = cost_trial < cost
        p = np.where(better[:, None], trial, p)
        r = np.where(better[:, None], r_trial, r)
        cost = np.where(better, cost_trial, cost)
        damping = np.where(better, damping * 0.3, damping * 4.0)
        damping = np.clip(damping, 1e-9, 1e9)
    return p


def refine_region(seed_points: np.ndarray, seed_index: np.ndarray, template: SixBarBatch,
                  theta_positions: np.ndarray, tips: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                  theta_statics: np.ndarray, force: float, tip_tolerance: float, k_max: float,
                  min_clearance: float = 0.0, iterations: int = 60, pull: np.ndarray | float = 0.01,
                  anchor: np.ndarray | None = None, penalise_clearance: bool = True) -> RefinedCandidates:
    """Refine seeds, then score them like region points (fingertip error, K, clearance); duplicates removed.

    ``penalise_clearance=False`` leaves the clearance out of the minimisation (a faster first pass);
    it is still scored.
    """
    check = theta_statics[np.unique(np.linspace(0, len(theta_statics) - 1, 11).astype(int))]
    params = refine(seed_points, template, theta_positions, tips, lower, upper, iterations, pull, anchor,
                    check, min_clearance if penalise_clearance else 0.0)
    # runs that converge to the same mechanism: keep the first (0.01 mm grid)
    _, first = np.unique(np.round(params, 2), axis=0, return_index=True)
    first = np.sort(first)
    params, seed_index = params[first], seed_index[first]
    batch = SixBarBatch(template.a, template.b, template.c, params[:, 0:2], params[:, 2:4], params[:, 4:6],
                        params[:, 6:8], template.theta1_start)
    tip = np.nan_to_num(fingertip_errors(batch, theta_positions, tips).max(axis=1), nan=np.inf)
    k = force_index(batch, theta_statics, force)
    clearance = np.nan_to_num(middle_link_clearance(batch, theta_statics), nan=-np.inf)
    inside = np.all((params >= lower - 1e-9) & (params <= upper + 1e-9), axis=1)
    return RefinedCandidates(d=params[:, 0:2], e=params[:, 2:4], f=params[:, 4:6], d0=params[:, 6:8],
                             seed=seed_index, tip_error=tip, K=k, clearance=clearance,
                             accepted=inside & (tip <= tip_tolerance) & (k <= k_max)
                             & (clearance >= min_clearance))


def merge(first: RefinedCandidates, second: RefinedCandidates) -> RefinedCandidates:
    """Both sets of candidates in one (first's order, then second's)."""
    return RefinedCandidates(*(np.concatenate([getattr(first, name), getattr(second, name)])
                               for name in ("d", "e", "f", "d0", "seed", "tip_error", "K", "clearance",
                                            "accepted")))
