"""Levenberg-Marquardt refinement of six-bar seeds (synthesis/watt_six_bar/refine.py).

``refine`` takes the Jacobian's eight forward differences of every seed from one call of ``_residuals`` on the
stacked seeds, which is right only if a seed's residuals do not depend on the other rows of the call. The
tests check that premise bit for bit and compare ``refine`` with a plain one-column-at-a-time Jacobian.
"""

from __future__ import annotations

import numpy as np

from fabricate.synthesis.watt_six_bar import refine as rf
from fabricate.synthesis.watt_six_bar.statics import SixBarBatch

THETA = np.array([0.1, 0.5, 0.9, 1.3])
CHECK = np.linspace(0.1, 1.3, 11)


def _problem(n: int, seed: int) -> tuple[np.ndarray, SixBarBatch, np.ndarray, np.ndarray, np.ndarray]:
    """n random seeds (d, e, f, d0) around a finger with joints a, b and tip c, targets and boxes."""
    rng = np.random.default_rng(seed)
    template = SixBarBatch(np.array([40.0, 0.0]), np.array([65.0, -3.0]), np.array([85.0, -8.0]),
                           np.zeros((1, 2)), np.zeros((1, 2)), np.zeros((1, 2)), np.zeros((1, 2)), 0.1)
    lows, highs = [5, 5, 45, 5, 10, 15, -10, 10], [35, 20, 70, 20, 40, 35, 10, 30]
    seeds = np.column_stack([rng.uniform(lo, hi, n) for lo, hi in zip(lows, highs, strict=True)])
    tips = np.column_stack([rng.uniform(60, 90, 4), rng.uniform(-40, 0, 4)])
    return seeds, template, tips, seeds.min(axis=0) - 5.0, seeds.max(axis=0) + 5.0


def test_residuals_of_a_seed_do_not_depend_on_the_other_rows():
    """Each row of _residuals on a stack of 40 parameter sets (with the clearance check on, some rows not
    assembling) equals, bit for bit, the call on that row alone and on the stack's reversed order."""
    seeds, template, tips, _, _ = _problem(40, 1)
    params = seeds + np.random.default_rng(2).normal(scale=3.0, size=seeds.shape)
    args = (template, THETA, tips, np.full(8, 0.01), CHECK, 2.0)
    stacked = rf._residuals(params, seeds, *args)
    assert np.any(stacked == rf._NO_ASSEMBLY) and np.any(stacked[:, 6] > 0.0)  # both kinds of rows present
    reverse = rf._residuals(params[::-1], seeds[::-1], *args)[::-1]
    assert np.array_equal(stacked, reverse)
    for i in range(len(params)):
        assert np.array_equal(stacked[i], rf._residuals(params[i:i + 1], seeds[i:i + 1], *args)[0])


def _refine_column_by_column(seeds, template, theta, tips, lower, upper, iterations, theta_check, min_clearance):
    """refine's algorithm with the Jacobian built one column (one _residuals call) at a time."""
    p = np.clip(seeds, lower, upper)
    damping = np.full(len(p), 1e-2)
    args = (seeds, template, theta, tips, np.full(8, 0.01), theta_check, float(min_clearance))
    r = rf._residuals(p, *args)
    cost = np.einsum("ij,ij->i", r, r)
    h, eye = 1e-5, np.eye(8)
    for _ in range(iterations):
        jac = np.empty(r.shape + (8,))
        for k in range(8):
            jac[:, :, k] = (rf._residuals(p + h * eye[k], *args) - r) / h
        jtj = np.einsum("nik,nil->nkl", jac, jac)
        jtr = np.einsum("nik,ni->nk", jac, r)
        diag = np.einsum("nkk->nk", jtj)
        system = jtj + damping[:, None, None] * (np.eye(8) * (diag[:, None, :] + 1e-9))
        trial = np.clip(p + np.linalg.solve(system, -jtr[..., None])[..., 0], lower, upper)
        r_trial = rf._residuals(trial, *args)
        cost_trial = np.einsum("ij,ij->i", r_trial, r_trial)
        better = cost_trial < cost
        p = np.where(better[:, None], trial, p)
        r = np.where(better[:, None], r_trial, r)
        cost = np.where(better, cost_trial, cost)
        damping = np.clip(np.where(better, damping * 0.3, damping * 4.0), 1e-9, 1e9)
    return p


def test_refine_equals_the_column_by_column_jacobian():
    """refine (stacked Jacobian) gives the column-by-column algorithm's parameters bit for bit, with and
    without the clearance term, for 1 and 25 seeds; and it moves the seeds (the comparison is not idle)."""
    for n, seed in ((1, 3), (25, 4)):
        seeds, template, tips, lower, upper = _problem(n, seed)
        for check, clearance in ((None, 0.0), (CHECK, 2.0)):
            got = rf.refine(seeds, template, THETA, tips, lower, upper, iterations=12, theta_check=check,
                            min_clearance=clearance)
            want = _refine_column_by_column(seeds, template, THETA, tips, lower, upper, 12,
                                            np.zeros(0) if check is None else check, clearance)
            assert np.array_equal(got, want)
            assert not np.array_equal(got, np.clip(seeds, lower, upper))
