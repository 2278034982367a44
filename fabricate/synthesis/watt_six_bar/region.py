"""The solution region of the Watt-I six-bar finger (its paper's sections 1.2-1.3), vectorised.

Stage 1: the dyad d-e between the proximal plane (a0, theta1) and the distal plane (b, theta3) over the
four positions gives the cubic C_d (and C_e, the partner curve). Stage 2: for every feasible d (both d
and its partner e inside their coordinate boxes) the coupler d-e-f moves with d and the direction d->e;
the dyad d0-f between the ground and the coupler gives C_d0 (and C_f). A region point is a pair
(d on branch m of C_d, d0 on branch n of C_d0) sampled on a grid of x (step 0.2 mm in the paper),
plotted at (d_x, d0_x) and labelled (m, n). Every point gets the force index K; points that cannot
pass the four positions on one assembly branch (a circuit defect of either loop) are flagged.

Nothing here depends on the paper's numbers: they come in through :class:`RegionInputs`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.planar import unit
from fabricate.synthesis.watt_six_bar.burmester import (
    CubicCurve,
    CurveSample,
    PlaneMotion,
    cubic_real_roots,
    dyad_curve,
    grid_in_range,
    ground_motion,
    in_box,
    plane_motion,
    sample_curve,
)
from fabricate.synthesis.watt_six_bar.statics import (
    SixBarBatch,
    fingertip_errors,
    force_index,
    middle_link_clearance,
)


@dataclass(frozen=True)
class RegionInputs:
    """What the region needs (mm, rad).

    Attributes
    ----------
    lengths : (3,) array
        L1, L2, L3: a0-a, a-b, b-c.
    angles : (3, 4) array
        theta1, theta2, theta3 (absolute, from +x) at positions 1..4, rad.
    box_d, box_e, box_f, box_d0 : (4,) arrays
        (x_min, x_max, y_min, y_max) of each joint at position 1, a0 at the origin.
    step : float
        Sampling step of x on both curves, mm.
    force : float
        External force for K, N.
    statics_samples : int
        Number of theta1 values from position 1 to position 4 for the statics.
    tip_tolerance : float
        Largest fingertip error at the positions (mm) for a point to count as passing them.
    min_clearance : float
        Smallest distance (mm) the pins d and e must keep from the middle link a-b over the motion.
    """

    lengths: np.ndarray
    angles: np.ndarray
    box_d: np.ndarray
    box_e: np.ndarray
    box_f: np.ndarray
    box_d0: np.ndarray
    step: float
    force: float = 1.0
    statics_samples: int = 41
    tip_tolerance: float = 0.5
    min_clearance: float = 0.0


@dataclass(frozen=True)
class FingerPositions:
    """Joints a, b and fingertip c at the four positions (4, 2) mm, and the planes of the phalanges."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    proximal: PlaneMotion
    distal: PlaneMotion


def finger_positions(lengths: np.ndarray, angles: np.ndarray) -> FingerPositions:
    """Open-chain finger a0-a-b-c at every position: a = L1 u(t1), b = a + L2 u(t2), c = b + L3 u(t3)."""
    a = lengths[0] * unit(angles[0])
    b = a + lengths[1] * unit(angles[1])
    c = b + lengths[2] * unit(angles[2])
    return FingerPositions(a=a, b=b, c=c, proximal=plane_motion(np.zeros((4, 2)), angles[0]),
                           distal=plane_motion(b, angles[2]))


@dataclass(frozen=True)
class StageOne:
    """Curves C_d, C_e and the sampled, box-filtered C_d.

    ``sample.y[i, k]`` is branch k+1 of C_d at ``sample.x[i]``; ``feasible`` (n, 3) marks d in its box
    and its partner e in its box.
    """

    curve_d: CubicCurve
    curve_e: CubicCurve
    sample: CurveSample
    feasible: np.ndarray

    def feasible_ranges(self) -> dict[int, tuple[float, float]]:
        """x range (min, max) of the feasible points of each branch (branches with none are absent)."""
        out = {}
        for k in range(3):
            xs = self.sample.x[self.feasible[:, k]]
            if len(xs):
                out[k + 1] = (float(xs.min()), float(xs.max()))
        return out


def stage_one(inputs: RegionInputs, finger: FingerPositions) -> StageOne:
    """C_d, C_e and the feasible points of C_d on the x grid of the d box."""
    curve_d = dyad_curve(finger.proximal, finger.distal)
    curve_e = dyad_curve(finger.distal, finger.proximal)
    x = grid_in_range(inputs.box_d[0], inputs.box_d[1], inputs.step)
    sample = sample_curve(curve_d, x)
    feasible = in_box(sample.points(), inputs.box_d) & in_box(sample.partner, inputs.box_e)
    return StageOne(curve_d=curve_d, curve_e=curve_e, sample=sample, feasible=feasible)


def coupler_motion(finger: FingerPositions, d: np.ndarray, e: np.ndarray) -> PlaneMotion:
    """Displacements of the coupler plane (point d, line d->e) for d (..., 2), e (..., 2)."""
    d_pos = finger.proximal.apply(d)
    e_pos = finger.distal.apply(e)
    de = e_pos - d_pos
    return plane_motion(d_pos, np.arctan2(de[..., 1], de[..., 0]))


def stage_two_curves(finger: FingerPositions, d: np.ndarray, e: np.ndarray) -> tuple[CubicCurve, CubicCurve]:
    """C_d0 (ground side) and C_f (coupler side) for dyads d-e (..., 2): batched curves."""
    coupler = coupler_motion(finger, d, e)
    ground = ground_motion(d.shape[:-1])
    return dyad_curve(ground, coupler), dyad_curve(coupler, ground)


@dataclass(frozen=True)
class SolutionRegion:
    """Every sampled six-bar of the region; arrays over the N points.

    Attributes
    ----------
    d, e, d0, f : (N, 2) arrays
        Joints at position 1, mm.
    branch_d, branch_d0 : (N,) int arrays
        m and n: the branch of d on C_d and of d0 on C_d0 (1..3).
    K : (N,) array
        Force index (inf where the motion cannot be assembled over the whole range).
    tip_error : (N,) array
        Largest fingertip error at the four positions on the branch of position 1, mm.
    passes : (N,) bool
        tip_error within the tolerance (no circuit defect).
    clearance : (N,) array
        Smallest distance of d and e from the middle link a-b over the motion, mm.
    accepted : (N,) bool
        passes, K <= the limit and the clearance kept.
    stage_one : StageOne
    """

    d: np.ndarray
    e: np.ndarray
    d0: np.ndarray
    f: np.ndarray
    branch_d: np.ndarray
    branch_d0: np.ndarray
    K: np.ndarray
    tip_error: np.ndarray
    passes: np.ndarray
    clearance: np.ndarray
    accepted: np.ndarray
    stage_one: StageOne

    def __len__(self) -> int:
        return len(self.d)

    def branch_pair_counts(self, mask: np.ndarray | None = None) -> dict[str, int]:
        """Number of points per branch pair label "m,n" (under ``mask``)."""
        mask = np.ones(len(self), bool) if mask is None else mask
        pairs, counts = np.unique(np.stack([self.branch_d[mask], self.branch_d0[mask]], 1), axis=0,
                                  return_counts=True)
        return {f"{int(m)},{int(n)}": int(c) for (m, n), c in zip(pairs, counts, strict=True)}


def solution_region(inputs: RegionInputs, k_max: float) -> SolutionRegion:
    """Sample the whole region and evaluate K for every point (vectorised)."""
    finger = finger_positions(inputs.lengths, inputs.angles)
    one = stage_one(inputs, finger)
    rows, cols = np.nonzero(one.feasible)
    d = np.stack([one.sample.x[rows], one.sample.y[rows, cols]], axis=1)
    e = one.sample.partner[rows, cols]
    curve_d0, _ = stage_two_curves(finger, d, e)
    x0 = grid_in_range(inputs.box_d0[0], inputs.box_d0[1], inputs.step)
    y0 = cubic_real_roots(curve_d0.y_polynomials(x0))  # (Nd, n0, 3)
    d0_all = np.stack([np.broadcast_to(x0[None, :, None], y0.shape), y0], axis=-1)
    keep = in_box(d0_all, inputs.box_d0)
    i_d, i_x, i_b = np.nonzero(keep)
    d0 = d0_all[i_d, i_x, i_b]
    # partners only where d0 is already in its box (the SVD is the costly part)
    sub = CubicCurve(tensor=curve_d0.tensor[i_d], rows=curve_d0.rows[i_d])
    f = sub.partners(d0[:, None, :])[:, 0, :]
    ok = in_box(f, inputs.box_f)
    i_d, i_b, d0, f = i_d[ok], i_b[ok], d0[ok], f[ok]
    d_sel, e_sel = d[i_d], e[i_d]
    batch = SixBarBatch(a=finger.a[0], b=finger.b[0], c=finger.c[0], d=d_sel, e=e_sel, f=f, d0=d0,
                        theta1_start=float(inputs.angles[0, 0]))
    theta = np.linspace(inputs.angles[0, 0], inputs.angles[0, -1], inputs.statics_samples)
    k = force_index(batch, theta, inputs.force) if len(batch) else np.zeros(0)
    tip = fingertip_errors(batch, inputs.angles[0], finger.c).max(axis=1) if len(batch) else np.zeros(0)
    passes = np.nan_to_num(tip, nan=np.inf) <= inputs.tip_tolerance
    if inputs.min_clearance > 0.0 and len(batch):
        clearance = np.nan_to_num(middle_link_clearance(batch, theta), nan=-np.inf)
    else:
        clearance = np.full(len(batch), np.inf)
    return SolutionRegion(d=d_sel, e=e_sel, d0=d0, f=f, branch_d=cols[i_d] + 1, branch_d0=i_b + 1, K=k,
                          tip_error=tip, passes=passes, clearance=clearance,
                          accepted=passes & (k <= k_max) & (clearance >= inputs.min_clearance), stage_one=one)


def select_point(region: SolutionRegion, rule: str, target: tuple[float, float] | None = None,
                 branches: tuple[int, int] | None = None) -> int:
    """Index of the selected region point among the accepted ones.

    ``rule="nearest"``: nearest ``target = (d_x, d0_x)`` in the region plane, ties to the smaller K;
    ``rule="least_k"``: the smallest K. ``branches = (m, n)`` restricts the choice to one branch pair.
    Returns -1 when no accepted point qualifies.
    """
    mask = region.accepted.copy()
    if branches is not None:
        mask &= (region.branch_d == branches[0]) & (region.branch_d0 == branches[1])
    idx = np.flatnonzero(mask)
    if not len(idx):
        return -1
    if rule == "least_k":
        key: tuple[np.ndarray, ...] = (region.K[idx],)
    else:
        assert target is not None, "rule 'nearest' needs a target"
        dist = np.hypot(region.d[idx, 0] - target[0], region.d0[idx, 0] - target[1])
        # the region plane repeats (d_x, d0_x) across branches: round to break ties by K
        key = (region.K[idx], np.round(dist, 9))
    return int(idx[np.lexsort(key)[0]])
