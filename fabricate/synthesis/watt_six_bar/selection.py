"""Choosing one Watt-I six-bar: from the accepted solution-region points or, when none qualifies, from
approximate defect-free mechanisms refined from them (:mod:`.refine`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.errors import SynthesisError
from fabricate.synthesis.watt_six_bar.refine import RefinedCandidates, merge, refine_region
from fabricate.synthesis.watt_six_bar.region import FingerPositions, RegionInputs, SolutionRegion
from fabricate.synthesis.watt_six_bar.spec import WattSixBarSpec
from fabricate.synthesis.watt_six_bar.statics import SixBarBatch


@dataclass(frozen=True)
class Choice:
    """The selected design: joints at position 1 (mm), where it came from and its figures of merit."""

    d: np.ndarray
    e: np.ndarray
    f: np.ndarray
    d0: np.ndarray
    K: float
    clearance: float
    branch_pair: tuple[int, int]
    exact: bool  # a region point (on the curves) rather than a refined candidate
    region_index: int  # the region point, or the refinement's seed


def _candidate_pool(region: SolutionRegion, refined: RefinedCandidates | None):
    """Accepted region points and refined candidates as parallel arrays (+ whether exact, source index)."""
    idx = np.flatnonzero(region.accepted)
    cols = [region.d[idx], region.e[idx], region.f[idx], region.d0[idx], region.K[idx], region.clearance[idx],
            np.ones(len(idx), bool), idx]
    if refined is not None:
        r = np.flatnonzero(refined.accepted)
        extra = [refined.d[r], refined.e[r], refined.f[r], refined.d0[r], refined.K[r], refined.clearance[r],
                 np.zeros(len(r), bool), refined.seed[r]]
        cols = [np.concatenate([a, b]) for a, b in zip(cols, extra, strict=True)]
    return cols


def choose(spec: WattSixBarSpec, region: SolutionRegion, refined: RefinedCandidates | None) -> Choice:
    """Apply the template's rule to the accepted region points and refined candidates."""
    d, e, f, d0, k, clearance, exact, source = _candidate_pool(region, refined)
    mask = np.ones(len(d), bool)
    if spec.branches is not None:
        m, n = spec.branches
        mask &= (region.branch_d[source] == m) & (region.branch_d0[source] == n)
    # exact region points first: refined candidates only stand in when no region point qualifies
    if np.any(mask & exact):
        mask &= exact
    pick = np.flatnonzero(mask)
    if not len(pick):
        k_ok = region.K <= spec.k_max
        clear = region.clearance >= spec.min_pin_to_middle_mm
        raise SynthesisError(
            f"no six-bar passes the {len(spec.angles_deg[0])} positions within {spec.tip_tolerance_mm:g} mm "
            f"with K <= {spec.k_max:g} and pins {spec.min_pin_to_middle_mm:g} mm clear of the middle link "
            f"(region: {len(region)} points; without a circuit defect {int(region.passes.sum())}, "
            f"K ok {int(k_ok.sum())}, clear {int(clear.sum())}, defect-free and K ok "
            f"{int((region.passes & k_ok).sum())}; refined candidates accepted "
            f"{0 if refined is None else int(refined.accepted.sum())})")
    if spec.rule == "least_k":
        order = np.lexsort((~exact[pick], k[pick]))
    else:
        assert spec.target is not None  # the parser requires it for rule "nearest"
        dist = np.round(np.hypot(d[pick, 0] - spec.target[0], d0[pick, 0] - spec.target[1]), 6)
        order = np.lexsort((k[pick], ~exact[pick], dist))
    j = int(pick[order[0]])
    src = int(source[j])
    return Choice(d=d[j], e=e[j], f=f[j], d0=d0[j], K=float(k[j]), clearance=float(clearance[j]),
                  branch_pair=(int(region.branch_d[src]), int(region.branch_d0[src])),
                  exact=bool(exact[j]), region_index=src)


def region_qualifies(spec: WattSixBarSpec, region: SolutionRegion) -> bool:
    """Whether an exact region point can be selected (then no refinement is needed)."""
    mask = region.accepted
    if spec.branches is not None:
        mask = mask & (region.branch_d == spec.branches[0]) & (region.branch_d0 == spec.branches[1])
    return bool(np.any(mask))


def refine_candidates(spec: WattSixBarSpec, region: SolutionRegion, finger: FingerPositions,
                      inputs: RegionInputs, theta: np.ndarray) -> RefinedCandidates | None:
    """Approximate defect-free mechanisms refined from region points (None without a usable seed).

    Seeds: region points that assemble over the motion, nearest the target (or lowest K) first.
    """
    usable = np.flatnonzero(np.isfinite(region.K) & ~region.passes)
    if spec.rule == "nearest":
        assert spec.target is not None  # the parser requires it for this rule
        key = np.hypot(region.d[usable, 0] - spec.target[0], region.d0[usable, 0] - spec.target[1])
    else:
        key = region.K[usable]
    # half the seeds nearest the choice, half spread evenly over the rest: a run often lands far from
    # its seed (the defect-free mechanisms lie off the exact curves), so coverage matters as much
    order = usable[np.argsort(key, kind="stable")]
    near = order[:spec.refine_seeds // 2]
    rest = order[spec.refine_seeds // 2:]
    spread = rest[np.unique(np.linspace(0, len(rest) - 1, spec.refine_seeds - len(near)).astype(int))] \
        if len(rest) else rest
    seeds_idx = np.sort(np.concatenate([near, spread]))
    if not len(seeds_idx):
        return None
    seeds = np.concatenate([region.d[seeds_idx], region.e[seeds_idx], region.f[seeds_idx],
                            region.d0[seeds_idx]], axis=1)
    lower = np.array([spec.box(n)[[0, 2]] for n in ("d", "e", "f", "d0")]).ravel()
    upper = np.array([spec.box(n)[[1, 3]] for n in ("d", "e", "f", "d0")]).ravel()
    template = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], region.d[:0], region.e[:0], region.f[:0],
                           region.d0[:0], float(inputs.angles[0, 0]))
    args = (template, inputs.angles[0], finger.c, lower, upper, theta, inputs.force, inputs.tip_tolerance,
            spec.k_max, spec.min_pin_to_middle_mm)
    first = refine_region(seeds, seeds_idx, *args, penalise_clearance=False)
    fits = np.flatnonzero((first.tip_error <= inputs.tip_tolerance) & (first.K <= spec.k_max))
    if not len(fits) or (spec.rule != "nearest" and spec.min_pin_to_middle_mm <= 0.0):
        return first
    # second pass: slide the candidates that fit along their (approximate) family towards the target
    # (d_x, d0_x), the other coordinates only loosely held, now also pushed clear of the middle link
    ok = fits
    start = np.concatenate([first.d[ok], first.e[ok], first.f[ok], first.d0[ok]], axis=1)
    anchor = start.copy()
    pull = np.full(8, 0.002)
    if spec.rule == "nearest":
        assert spec.target is not None  # the parser requires it for this rule
        anchor[:, 0], anchor[:, 6] = spec.target
        pull[[0, 6]] = 0.05
    second = refine_region(start, first.seed[ok], *args, iterations=100, pull=pull, anchor=anchor)
    return merge(first, second)
