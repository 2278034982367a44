"""Sweep throughput on Dask: points per second with 1 and 2 local workers (their ratio) and the per-task
overhead, side by side in one run.

    pip install -e ".[test]"          # dask distributed and pyarrow are in the test extra (and the sweep one)
    python tests/benchmarks/bench_sweep.py [--points 48] [--stage synth|build]

The sweep varies the elliptic gear pair's eccentricity (``gear_pair_elliptic``). Rows:

- in-process: the points run one after the other in this process (``run_point``), no Dask: the floor;
- Dask, 1 worker / 2 workers: ``run_sweep`` on a LocalCluster (cluster start-up and result writing
  included, as a user sees it); the ratio is the speed-up of the second worker;
- per-point overhead of a one-point task: (Dask 1 worker with batch 1 - in-process) / points;
- a no-op task's round trip: ``client.submit`` + ``result`` of a function that returns at once.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))


def _spec(points: int, stage: str, batch_seconds: float):
    import numpy as np

    from fabricate.sweep.spec import sweep_from_tables

    return sweep_from_tables({
        "sweep": {"template": "gear_pair_elliptic", "stage": stage, "name": "bench",
                  "metrics": ["synthesis.center_distance_mm"], "batch_seconds": batch_seconds},
        "vary": {"gear_pair.eccentricity": [float(e) for e in np.round(np.linspace(0.05, 0.45, points), 6)]},
        "set": {"checks.sweep_poses": 60},
    })


def _in_process(spec) -> float:
    from fabricate.sweep.task import run_point

    start = time.perf_counter()
    for i, values in enumerate(spec.points()):
        run_point(i, values, spec.point_id(values), spec.base, spec.field_parts(), spec.stage, list(spec.metrics))
    return time.perf_counter() - start


def _dask(spec, workers: int) -> float:
    from fabricate.sweep.runner import run_sweep

    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        outcome = run_sweep(spec, Path(tmp) / "out", workers=workers, quiet=True)
        elapsed = time.perf_counter() - start
    assert outcome.exit_code == 0 and outcome.done == outcome.total
    return elapsed


def _noop_round_trip(n: int = 200) -> float:
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        client.submit(int, 0, pure=False).result()  # warm
        times = []
        for i in range(n):
            t = time.perf_counter()
            client.submit(int, i, pure=False).result()
            times.append(time.perf_counter() - t)
    return statistics.median(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--points", type=int, default=48)
    parser.add_argument("--stage", choices=("synth", "build"), default="synth")
    args = parser.parse_args(argv)
    batched = _spec(args.points, args.stage, 1.0)
    single = _spec(args.points, args.stage, 0.01)  # one point per task (a point takes ~0.2 s)
    _in_process(_spec(2, args.stage, 1.0))  # warm the imports and caches of this process
    serial = _in_process(batched)
    one = _dask(batched, 1)
    two = _dask(batched, 2)
    one_single = _dask(single, 1)
    noop = _noop_round_trip()
    n = args.points
    rows = [
        ("in-process, one after the other", serial, n / serial, ""),
        ("Dask LocalCluster, 1 worker (batched ~1 s)", one, n / one, f"{serial / one:.2f} x in-process"),
        ("Dask LocalCluster, 2 workers (batched ~1 s)", two, n / two, f"{one / two:.2f} x 1 worker"),
        ("Dask LocalCluster, 1 worker, 1 point per task", one_single, n / one_single,
         f"{one_single / one:.2f} x batched time"),
    ]
    print(f"sweep of {n} points (gear_pair_elliptic, stage {args.stage}); wall times include cluster start-up\n")
    print("| run | wall s | points/s | ratio |\n|---|---:|---:|---|")
    for name, seconds, rate, ratio in rows:
        print(f"| {name} | {seconds:.2f} | {rate:.2f} | {ratio} |")
    print(f"\nper-point overhead of one-point tasks over in-process: {(one_single - serial) / n * 1000:.1f} ms "
          f"(cluster start-up included, spread over {n} points)")
    print(f"no-op task round trip (submit + result, median of 200): {noop * 1000:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
