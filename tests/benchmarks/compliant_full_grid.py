"""Benchmark: certified optimum of Delta N over the paper's full Table 1 grid (about 1.5e9 points).

Not part of the default test run. Prints the optimum, how much of the grid was valued and the bound
that covers the rest, and checks the result against ``tests/data/compliant_paper.json``. With
``--brute N`` it also values *every* grid point of the N paths (alpha, c) with the lowest interval
bounds by plain enumeration (:func:`evaluate_points`, 7.96e6 points a path) as an independent check
that nothing there beats the optimum (about 1-3 s a path).

    python tests/benchmarks/compliant_full_grid.py [--samples 121] [--brute N]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from fabricate.synthesis.compliant.grid_search import (
    ParameterGrid,
    build_tables,
    evaluate_points,
    interval_bounds,
    optimise,
)
from fabricate.synthesis.compliant.model import GripperGeometry, Load, Springs, contact_path, solve_grasp


def _brute_paths(geom, grid, load, samples, margin, count) -> list[tuple[float, float, float]]:
    """(alpha deg, c mm, least Delta N) of the ``count`` paths with the lowest interval bounds."""
    tables = build_tables(geom, grid, load, samples)
    least = [interval_bounds(tab, margin).min() for _, _, tab in tables]
    mesh = np.meshgrid(grid.k1, grid.k2, grid.phi01, grid.phi02, indexing="ij")
    flat = [m.ravel() for m in mesh]
    out = []
    for t in np.argsort(least, kind="stable")[:count]:
        ia, ic, tab = tables[t]
        best = np.inf
        for start in range(0, len(flat[0]), 200_000):
            part = [a[start:start + 200_000] for a in flat]
            values = evaluate_points(tab, *part, load, margin)
            if np.isfinite(values).any():
                best = min(best, float(np.nanmin(values)))
        out.append((float(np.degrees(grid.alpha[ia])), float(grid.c[ic]), best))
    return out


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=121)
    parser.add_argument("--brute", type=int, default=0, help="paths to enumerate in full as a check")
    args = parser.parse_args()
    data = json.loads((Path(__file__).resolve().parent.parent / "data" / "compliant_paper.json").read_text())
    geom = GripperGeometry(40, 40, 20, 20, 0.0, 70, 50, 60, 36, np.pi / 3)
    load = Load(85.0, 0.25, 0.27, 0.8)
    grid = ParameterGrid(np.radians(np.arange(60, 86, 5.0)), np.arange(0, 31.0), np.arange(0, 31.0),
                         np.arange(0, 31.0), np.radians(np.arange(0, 181, 2.0)), np.radians(np.arange(0, 181, 2.0)))
    margin = np.radians(5.0)
    start = time.perf_counter()
    res = optimise(geom, grid, load, samples=args.samples, hinge_margin=margin)
    took = time.perf_counter() - start
    g = GripperGeometry(40, 40, 20, 20, res.c, 70, 50, 60, 36, res.alpha)
    exact = solve_grasp(contact_path(g, load.radius, load.mu, n=1441),
                        Springs(res.k1, res.k2, res.phi01, res.phi02), load)
    print(f"grid points {res.grid_points:.3e}, valued {res.points_evaluated} (re-checked {res.points_verified}), "
          f"paths searched {res.paths_searched}/{res.paths}, intervals searched "
          f"{res.intervals_searched}/{res.intervals}, {took:.2f} s")
    print(f"optimum alpha={np.degrees(res.alpha):.0f} deg c={res.c:g} k1={res.k1:g} k2={res.k2:g} "
          f"phi01={np.degrees(res.phi01):.0f} deg phi02={np.degrees(res.phi02):.0f} deg")
    print(f"Delta N on the sampled path {res.delta_n:.6f} N, exact {exact.delta_n:.6f} N, "
          f"bound for everything not valued {res.pruned_bound:.6f} N")
    print(f"paper point Delta N (this model) {data['model_delta_N_N']:.4f} N")
    ok = exact.delta_n <= data["model_delta_N_N"] and abs(exact.delta_n
                                                          - data["full_grid_optimum"]["delta_N_N"]) < 2e-3
    if args.brute:
        start = time.perf_counter()
        for alpha, c, best in _brute_paths(geom, grid, load, args.samples, margin, args.brute):
            print(f"  plain enumeration alpha={alpha:.0f} deg c={c:g}: least Delta N {best:.6f} N")
            ok &= best >= res.delta_n
        print(f"  ({time.perf_counter() - start:.1f} s)")
    print("OK" if ok else "MISMATCH")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
