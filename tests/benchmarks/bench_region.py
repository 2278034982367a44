"""Benchmark: the whole Watt-I six-bar solution region at 0.2 mm with the force index K (seed 004).

Goal: <= 5 s on 2 cores for the template's region (curves, partners, 0.2 mm sampling of C_d and every
C_d0, K over 41 input angles, circuit-defect check). Run: ``python tests/benchmarks/bench_region.py``.
Prints a table: stage, time, points. The refinement and the mechanism checks are timed separately.
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "2")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "2")

import numpy as np  # noqa: E402

from fabricate.design import GENERIC_SECTIONS
from fabricate.synthesis import watt_six_bar as wsb  # noqa: E402
from fabricate.synthesis.watt_six_bar.method import synthesise_spec  # noqa: E402
from fabricate.synthesis.watt_six_bar.region import finger_positions, solution_region, stage_one  # noqa: E402
from fabricate.synthesis.watt_six_bar.spec import WattSixBarSpec  # noqa: E402
from fabricate.table import Table  # noqa: E402
from fabricate.templates import TEMPLATE_DIR, read_toml  # noqa: E402


def _spec() -> WattSixBarSpec:
    root = Table(read_toml(TEMPLATE_DIR / "finger_watt_six_bar.toml"))
    for generic in GENERIC_SECTIONS:
        if root.has(generic):
            root.table(generic)
    return wsb.parse_spec(root)


def _best_of(fn, repeat: int = 3):
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main() -> None:
    spec = _spec()
    inputs = spec.region_inputs()
    finger = finger_positions(inputs.lengths, inputs.angles)
    rows = []
    t, one = _best_of(lambda: stage_one(inputs, finger))
    rows.append(("stage 1: C_d, C_e, feasible d (0.2 mm)", t, int(one.feasible.sum())))
    t, region = _best_of(lambda: solution_region(inputs, spec.k_max))
    rows.append(("whole region + K (41 angles) + defects", t, len(region)))
    rows.append((f"  of which K <= {spec.k_max:g}", float("nan"), int(np.sum(region.K <= spec.k_max))))
    t, result = _best_of(lambda: synthesise_spec(spec), repeat=1)
    rows.append(("synthesise (region, refinement, mechanism, checks)", t, result.report["refined"]["candidates"]))
    print(f"{'stage':<54}{'time (s)':>10}{'points':>10}")
    for name, seconds, count in rows:
        time_text = "" if np.isnan(seconds) else f"{seconds:10.3f}"
        print(f"{name:<54}{time_text:>10}{count:>10}")
    goal = rows[1][1] <= 5.0
    print(f"goal: whole region with K <= 5 s: {'met' if goal else 'NOT met'} ({rows[1][1]:.2f} s)")


if __name__ == "__main__":
    main()
