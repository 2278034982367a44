"""Benchmark: certified optimum of Delta N over the paper's full Table 1 grid (about 1.5e9 points).

Not part of the default test run (about 1-2 minutes on 2 cores). Prints the optimum, the number of
grid points actually enumerated and the bound that covers the rest, and checks the result against
``tests/data/compliant_paper.json``.

    python tests/benchmarks/compliant_full_grid.py [path_samples]
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from fabricate.synthesis.compliant_model import GripperGeometry, Load, Springs, contact_path, solve_grasp
from fabricate.synthesis.compliant_optimise import ParameterGrid, optimise


def main() -> int:
    samples = int(sys.argv[1]) if len(sys.argv) > 1 else 121
    data = json.loads((Path(__file__).resolve().parent.parent / "data" / "compliant_paper.json").read_text())
    geom = GripperGeometry(40, 40, 20, 20, 0.0, 70, 50, 60, 36, np.pi / 3)
    load = Load(85.0, 0.25, 0.27, 0.8)
    grid = ParameterGrid(np.radians(np.arange(60, 86, 5.0)), np.arange(0, 31.0), np.arange(0, 31.0),
                         np.arange(0, 31.0), np.radians(np.arange(0, 181, 2.0)), np.radians(np.arange(0, 181, 2.0)))
    start = time.perf_counter()
    res = optimise(geom, grid, load, samples=samples, hinge_margin=np.radians(5.0))
    took = time.perf_counter() - start
    g = GripperGeometry(40, 40, 20, 20, res.c, 70, 50, 60, 36, res.alpha)
    exact = solve_grasp(contact_path(g, load.radius, load.mu, n=1441),
                        Springs(res.k1, res.k2, res.phi01, res.phi02), load)
    print(f"grid points {res.grid_points:.3e}, enumerated {res.points_evaluated:.3e}, "
          f"boxes bounded {res.boxes_bounded}, {took:.1f} s")
    print(f"optimum alpha={np.degrees(res.alpha):.0f} deg c={res.c:g} k1={res.k1:g} k2={res.k2:g} "
          f"phi01={np.degrees(res.phi01):.0f} deg phi02={np.degrees(res.phi02):.0f} deg")
    print(f"Delta N on the sampled path {res.delta_n:.5f} N, exact {exact.delta_n:.5f} N, "
          f"bound for everything not enumerated {res.lower_bound:.5f} N")
    print(f"paper point Delta N (this model) {data['model_delta_N_N']:.4f} N")
    ok = exact.delta_n <= data["model_delta_N_N"] and abs(exact.delta_n
                                                          - data["full_grid_optimum"]["delta_N_N"]) < 2e-3
    print("OK" if ok else "MISMATCH")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
