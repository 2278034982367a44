"""Sweep throughput on Dask: points per second per worker with 1 and 2 local workers, for a synthesis sweep and a
build sweep, side by side in one run.

    pip install -e ".[test]"          # dask distributed and pyarrow are in the test extra (and the sweep one)
    python tests/benchmarks/bench_sweep.py [--stage synth|build|both] [--points N] [--overhead] [--full]

The sweeps vary the elliptic gear pair's eccentricity (``gear_pair_elliptic``, 60 poses): every point has its own
synthesis. A build point makes its report only (no pictures, plots or STEP files: ``run_build``'s ``report_only``);
``--full`` adds a metric that reads the file list (``count(files[*])``), so every point is built in full, as a build
sweep's points were before. Rows, for each stage:

- in-process: the points run one after the other in this process (``run_point``), no Dask: the floor;
- Dask, 1 worker / 2 workers: ``run_sweep`` on a LocalCluster. ``points/s`` counts the points' own wall time
  (``SweepOutcome.points_seconds``: first task sent to last row received, the workers already started and
  imported); ``command s`` is the whole call as a user sees it (cluster start-up, tables, plots included);
  ``main CPU s`` is this process's CPU in it (the scheduler, the client, the tables: taken from the workers'
  cores). The ratio is the second worker's speed-up of the points' rate;
- with ``--overhead``: a one-point-per-task sweep on one worker (the per-task cost) and a no-op task's round trip.

Each row also prints the 1-minute load average when it ended: on a machine shared with other work, a second
worker only helps if a second core is free.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

#: Each Dask run's largest worker peak memory, printed at the end.
PEAKS: list[str] = []
#: Per Dask run: the cores its workers had (CPU seconds over the points' wall time) and points per CPU second.
CORES: list[str] = []
#: Default points per stage (a synthesis point takes ~0.2 s, a report-only build point of 60 poses ~1.2 s on an idle
#: core): enough that the last task's wait (one worker done, the other on its last point) is a small part of the run.
DEFAULT_POINTS = {"synth": 48, "build": 32}


#: ``--full``: every build point built in full (a metric reading the file list), not report-only.
FULL = False


def _spec(points: int, stage: str, batch_seconds: float) -> Any:
    import numpy as np

    from fabricate.sweep.spec import sweep_from_tables

    metrics = ["synthesis.center_distance_mm"] + (["interference.min_clearance_mm"] if stage == "build" else []) \
        + (["count(files[*])"] if stage == "build" and FULL else [])
    return sweep_from_tables({
        "sweep": {"template": "gear_pair_elliptic", "stage": stage, "name": "bench",
                  "metrics": metrics, "batch_seconds": batch_seconds},
        "vary": {"gear_pair.eccentricity": [float(e) for e in np.round(np.linspace(0.05, 0.45, points), 6)]},
        "set": {"checks.sweep_poses": 60},
    })


def _in_process(spec: Any) -> float:
    from fabricate.sweep.task import run_batch

    points = [(i, values, spec.point_id(values)) for i, values in enumerate(spec.points())]
    start = time.perf_counter()
    run_batch(points, spec.base, spec.field_parts(), spec.stage, list(spec.metrics))
    return time.perf_counter() - start


def _dask(spec: Any, workers: int) -> tuple[float, float, float]:
    """(the points' own seconds, the whole call's seconds, this process's CPU seconds: the scheduler, the client
    and the tables it writes, which take a core's share from the workers). Prints the workers' peak memory."""
    from fabricate.sweep.runner import run_sweep

    with tempfile.TemporaryDirectory() as tmp:
        start, cpu = time.perf_counter(), time.process_time()
        outcome = run_sweep(spec, Path(tmp) / "out", workers=workers, quiet=True)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    assert outcome.exit_code == 0 and outcome.done == outcome.total, outcome
    PEAKS.append(f"{spec.stage}, {workers} worker{'s' if workers > 1 else ''}: {outcome.worker_peak_mb:.0f} MB")
    CORES.append(f"{spec.stage}, {workers} worker{'s' if workers > 1 else ''}: "
                 f"{outcome.worker_cpu_seconds / max(outcome.points_seconds, 1e-9):.2f} cores, "
                 f"{spec.count() / max(outcome.worker_cpu_seconds, 1e-9):.2f} points per worker CPU second")
    return outcome.points_seconds, elapsed, cpu


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


def _load() -> str:
    try:
        return f"{os.getloadavg()[0]:.1f}"
    except OSError:
        return "?"


def bench_stage(stage: str, n: int, overhead: bool) -> list[tuple[str, float, float, float, float, str, str]]:
    """Rows ``(run, points' seconds, whole call's seconds, main process CPU seconds, points/s per worker, ratio,
    load)`` of one stage."""
    _in_process(_spec(2, stage, 1.0))  # warm this process's imports
    batched = _spec(n, stage, 1.0)
    rows = []
    cpu = time.process_time()
    serial = _in_process(batched)
    rows.append(("in-process, one after the other", serial, serial, time.process_time() - cpu, n / serial, "",
                 _load()))
    one, one_all, one_cpu = _dask(batched, 1)
    rows.append(("Dask LocalCluster, 1 worker", one, one_all, one_cpu, n / one, f"{serial / one:.2f} x in-process",
                 _load()))
    two, two_all, two_cpu = _dask(batched, 2)
    rows.append(("Dask LocalCluster, 2 workers", two, two_all, two_cpu, n / two / 2,
                 f"**{one / two:.2f} x 1 worker** (command {one_all / two_all:.2f} x)", _load()))
    if overhead:
        single, single_all, single_cpu = _dask(_spec(n, stage, 0.001), 1)  # one point per task
        rows.append(("Dask, 1 worker, 1 point per task", single, single_all, single_cpu, n / single,
                     f"{(single - one) / n * 1000:.1f} ms a task over batched", _load()))
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--stage", choices=("synth", "build", "both"), default="both")
    parser.add_argument("--points", type=int, help=f"points of each sweep (default {DEFAULT_POINTS})")
    parser.add_argument("--overhead", action="store_true", help="also the per-task cost and a no-op round trip")
    parser.add_argument("--full", action="store_true", help="build points in full (pictures, plots, STEP files)")
    args = parser.parse_args(argv)
    global FULL
    FULL = args.full
    stages = ("synth", "build") if args.stage == "both" else (args.stage,)
    print(f"cores available: {len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else os.cpu_count()}"
          f", load average before: {_load()}\n")
    print(f"build points: {'in full (--full)' if args.full else 'report only'}")
    print("| stage | points | run | points' s | command s | main CPU s | points/s per worker | ratio | load after |\n"
          "|---|---:|---|---:|---:|---:|---:|---|---:|")
    for stage in stages:
        n = args.points or DEFAULT_POINTS[stage]
        for name, seconds, whole, cpu, rate, ratio, load in bench_stage(stage, n, args.overhead):
            print(f"| {stage} | {n} | {name} | {seconds:.2f} | {whole:.2f} | {cpu:.2f} | {rate:.2f} | {ratio} "
                  f"| {load} |", flush=True)
    print(f"\nworkers' peak resident memory: {'; '.join(PEAKS)}")
    print(f"cores the workers had (their CPU seconds over the points' wall time): {'; '.join(CORES)}")
    if args.overhead:
        print(f"\nno-op task round trip (submit + result, median of 200): {_noop_round_trip() * 1000:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
