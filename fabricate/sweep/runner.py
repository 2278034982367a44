"""Run a sweep on Dask distributed: a local cluster of processes by default, or an existing cluster.

The output folder holds:

- ``sweep.json``: the spec (as plain values), the counts and the best points; it marks the folder as a
  sweep's (a re-run of the same spec resumes it; another spec is refused);
- ``rows.jsonl``: the journal, one JSON row per finished point, appended (one ``write`` per finished task,
  flushed and synced) as tasks finish; a torn last line (a killed run) is dropped on resume;
- ``sweep.csv`` and ``sweep.parquet``: every finished point, sorted, rewritten atomically as rows arrive
  (at most every few seconds) and at the end;
- ``plots/``: each metric against each varied field, and the feasibility map;
- ``best/<rank>-point<index>/``: the best points built in full, each a normal ``fabricate build`` output.

A re-run into the same folder skips the points whose rows are done (exit codes 0, 1, 2; a point that hit
an internal error or lost its worker every time is run again).

Points are sent in the order of their synthesis group (:func:`fabricate.sweep.task.synthesis_group`: the points
that differ only in fields synthesis does not read, one after the other), and each worker process keeps the
stage results of its points in memory (:mod:`fabricate.cache`'s in-process layer) for as long as it lives: a
``--stage build`` sweep over ``[process]``, ``[parts]``, ``[load]`` or ``[checks]`` fields synthesises each
group once per worker instead of once per point.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import sys
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fabricate.output import folder_lock
from fabricate.sweep.cluster import close_cluster, connect, start_cluster, worker_count, worker_peak_mb, workers_cpu
from fabricate.sweep.folder import JOURNAL, SWEEP_JSON, Journal, prepare_folder, read_journal, sweep_record, write_file
from fabricate.sweep.spec import SweepSpec
from fabricate.sweep.task import EXIT_INTERNAL, build_point, run_batch, synthesis_group

#: Results are rewritten at most this often while a sweep runs (and always at its end).
FLUSH_SECONDS = 5.0
#: A task that raised (not a bad point: those are rows) is tried this many more times by Dask.
TASK_RETRIES = 2
#: Largest number of points in one task, whatever the timing says.
MAX_BATCH = 256

Progress = Callable[[str], None]


@dataclass
class SweepOutcome:
    """What a sweep did.

    Attributes
    ----------
    exit_code : int
        0 every point has its row; 1 some point ended in an internal error (its reason says why);
        130 interrupted (the rows done are kept; the same command resumes).
    out : Path
    total, done, resumed : int
        Points in the sweep, points with a row now, rows found from an earlier run.
    counts : dict
        Rows per exit code.
    """

    exit_code: int
    out: Path
    total: int
    done: int
    resumed: int
    counts: dict[str, int] = field(default_factory=dict)
    best: list[dict[str, Any]] = field(default_factory=list)
    seconds: float = 0.0
    workers: int = 0
    tasks: int = 0
    notes: list[str] = field(default_factory=list)
    #: Seconds from the first task sent to the last row received (the points' own wall time: no cluster start-up,
    #: tables, plots or best builds).
    points_seconds: float = 0.0
    #: Largest peak resident memory of a worker process (MB; 0 when unknown): its imports, its points and the
    #: stage results it keeps (see :data:`fabricate.bounds.WORKER_MB`).
    worker_peak_mb: float = 0.0
    #: CPU seconds the workers spent over ``points_seconds`` (all of them together; 0 when unknown): divided by
    #: ``points_seconds`` it is the cores they had, which on a machine shared with other work can be fewer than
    #: the workers.
    worker_cpu_seconds: float = 0.0


# -- Dask ----------------------------------------------------------------------------------------------------

def _bar(done: int, total: int, counts: Mapping[str, int], start: float, resumed: int) -> str:
    width = 28
    filled = int(width * done / total) if total else width
    rate = (done - resumed) / max(time.perf_counter() - start, 1e-9)
    left = (total - done) / rate if rate > 0 else math.inf
    eta = f"{int(left // 60)}:{int(left % 60):02d}" if math.isfinite(left) else "--:--"
    return (f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} points · "
            f"{counts.get('0', 0)} pass · {counts.get('1', 0)} fail · {counts.get('2', 0)} invalid"
            f"{f' · {counts.get(str(EXIT_INTERNAL))} errors' if counts.get(str(EXIT_INTERNAL)) else ''}"
            f" · {rate:.2f} pt/s · ETA {eta} ")


def _counts(rows: Mapping[str, Mapping[str, Any]]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for row in rows.values():
        key = str(row["exit_code"])
        counts[key] = counts.get(key, 0) + 1
    return dict(sorted(counts.items()))


def run_sweep(spec: SweepSpec, out: str | Path, *, workers: int | None = None, scheduler: str | None = None,
              quiet: bool = False, progress_bar: bool | None = None, log: Progress | None = None,
              protect: Sequence[Path] = (), cache: bool | None = None) -> SweepOutcome:
    """Run every point of ``spec`` not done yet in ``out``, then write the tables, plots and best builds.

    Parameters
    ----------
    spec : SweepSpec
    out : str or Path
        Output folder (new, empty, or an earlier run of this spec, which is resumed).
    workers : int, optional
        Processes of the local cluster (default: the cores this process may use); at most
        :func:`fabricate.bounds.max_workers` (a SpecError naming ``--workers`` past it).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); its workers need fabricate installed.
    quiet : bool
        No progress output.
    progress_bar : bool, optional
        Draw the progress bar on stderr (default: when stderr is a terminal).
    protect : sequence of Path
        The sweep's input files (spec, template): ``out`` may not be or hold one.
    cache : bool, optional
        Let each worker reuse stage results across its points, in its memory only (never the disk cache). Default:
        whether :mod:`fabricate.cache` is on here (:func:`fabricate.cache.use_cache`; the command line turns it on
        unless ``--no-cache``). The rows are the same either way.
    """
    if workers is not None:  # before anything is written: the cores and the memory bound the local processes
        from fabricate.bounds import check_workers

        check_workers(workers)
    out = Path(os.path.abspath(out))
    prepare_folder(out, spec, protect)  # bad input is refused before any wait, and before anything is written
    say = log or (lambda msg: None if quiet else print(msg, file=sys.stderr, flush=True))
    draw = (not quiet) and (sys.stderr.isatty() if progress_bar is None else progress_bar)
    if cache is None:
        from fabricate.cache import enabled

        cache = enabled()
    # one sweep writes a folder at a time: a second one waits, then resumes from the first one's journal (two
    # appending to one journal ran every point twice, and one's resume could cut the other's line in half).
    # A folder under folders that do not exist yet is nobody else's: nothing is made before the work starts
    held = folder_lock(out, lambda: say(f"sweep {spec.name}: waiting for another run writing {out}")) \
        if out.parent.is_dir() else contextlib.nullcontext()
    with held:
        return _sweep_in(spec, out, (workers, scheduler), protect, cache, (say, draw, quiet))


def _sweep_in(spec: SweepSpec, out: Path, connect_to: tuple[int | None, str | None], protect: Sequence[Path],
              cache: bool, talk: tuple[Progress, bool, bool]) -> SweepOutcome:
    """:func:`run_sweep` once it holds the folder (``connect_to``: its workers and scheduler; ``talk``: how it
    says what it does, whether it draws a progress bar, whether it is quiet)."""
    workers, scheduler = connect_to
    say, draw, quiet = talk
    resuming = prepare_folder(out, spec, protect)  # again: what a run that held the folder before left
    points = spec.points()
    ids = [spec.point_id(values) for values in points]
    by_id = dict(zip(ids, range(len(points)), strict=True))
    done = _journal_rows(out, spec, by_id) if resuming else {}
    resumed = len(done)
    order = group_order(spec.field_parts(), points, [i for i in range(len(points)) if ids[i] not in done])
    todo = deque((i, points[i], ids[i]) for i in order)
    start = time.perf_counter()
    client = cluster = None
    n_workers = 0
    if todo:  # a cluster that cannot be had is a usage error: nothing is written
        client, cluster, n_workers = start_cluster(workers, scheduler, spec.stage)
    out.mkdir(parents=True, exist_ok=True)
    write_file(out / SWEEP_JSON, _json(sweep_record(spec, {"points": len(points), "done": resumed, "complete": False})))
    hello = (f"sweep {spec.name}: {len(points)} points ({resumed} done earlier), stage {spec.stage}, "
             f"{n_workers} Dask worker{'s' if n_workers != 1 else ''}"
             f"{' at ' + scheduler if scheduler else ' (local cluster)'}" if todo else
             None if quiet else f"sweep {spec.name}: all {len(points)} points done earlier; writing the results")
    tasks, points_seconds, worker_cpu, interrupted = _journalled(
        client, spec, todo, done, out, (start, resumed, len(points)), draw, (say, hello), cache)
    if interrupted:
        # a stop can land between a row's journal write and its count: the journal is what a resume reads, so
        # the record counts what it holds (the same rows the resume will call "done earlier")
        done = _journal_rows(out, spec, by_id)
    rows = [done[pid] for pid in ids if pid in done]
    counts, best, notes, worker_peak, interrupted = _finish(
        out, spec, rows, done, len(points), interrupted, (client, cluster), connect_to, say, protect, cache)
    code = 130 if interrupted else (1 if counts.get(str(EXIT_INTERNAL)) else 0)
    return SweepOutcome(exit_code=code, out=out, total=len(points), done=len(rows), resumed=resumed,
                        counts=counts, best=best, seconds=time.perf_counter() - start, workers=n_workers,
                        tasks=tasks, notes=notes, points_seconds=points_seconds, worker_peak_mb=worker_peak,
                        worker_cpu_seconds=worker_cpu)


def _journalled(client: Any, spec: SweepSpec, todo: deque[tuple[int, dict[str, Any], str]],
                done: dict[str, dict[str, Any]], out: Path, counts: tuple[float, int, int], draw: bool,
                talk: tuple[Progress, str | None], cache: bool) -> tuple[int, float, float, bool]:
    """Say ``talk``'s line, then run the ``todo`` points on ``client``, each row into the journal as it comes:
    ``(tasks, seconds, the workers' CPU seconds, interrupted)``; a stop (Ctrl-C) ends the run with the rows done so
    far journalled."""
    start, resumed, total = counts
    say, hello = talk
    tasks, seconds, worker_cpu, interrupted = 0, 0.0, 0.0, False
    journal = Journal(out / JOURNAL)
    try:
        if hello is not None:
            say(hello)
        if todo:
            began, cpu = time.perf_counter(), workers_cpu(client)
            tasks = _run_points(client, spec, todo, done, journal, out, start, resumed, total, draw, say, cache)
            seconds = time.perf_counter() - began
            after = workers_cpu(client)
            worker_cpu = sum(after[w] - cpu[w] for w in after if w in cpu)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        journal.close()
        if draw:
            print(file=sys.stderr)
    return tasks, seconds, worker_cpu, interrupted


def _journal_rows(out: Path, spec: SweepSpec, by_id: Mapping[str, int]) -> dict[str, dict[str, Any]]:
    """The journal's rows of this spec's points that are done (not an internal error: those run again)."""
    return {pid: row for pid, row in read_journal(out, spec).items()
            if pid in by_id and row["exit_code"] != EXIT_INTERNAL}


def _finish(out: Path, spec: SweepSpec, rows: list[dict[str, Any]], done: Mapping[str, Mapping[str, Any]],
            total: int, interrupted: bool, dask: tuple[Any, Any], connect_to: tuple[int | None, str | None],
            say: Progress, protect: Sequence[Path], cache: bool
            ) -> tuple[dict[str, int], list[dict[str, Any]], list[str], float, bool]:
    """Write the tables and plots, build the best points (a complete, uninterrupted sweep), and the final
    sweep.json; then close the client and cluster (``dask``: either may be None). Returns the counts, the best
    points, the notes, the workers' peak memory (MB) and whether the sweep was interrupted."""
    client, cluster = dask
    try:
        _write_results(out, spec, rows)
        best: list[dict[str, Any]] = []
        if not interrupted and len(rows) == total:
            best = _best(spec, rows)
            if best:
                if client is None:
                    client, cluster = connect(*connect_to)
                _build_best(client, spec, best, out, say, protect, cache)
        counts = _counts(done)
        complete = len(rows) == total
        notes = _notes(spec, rows)
        write_file(out / SWEEP_JSON, _json(sweep_record(spec, {
            "points": total, "done": len(rows), "complete": complete, "counts": counts,
            "best": best, "notes": notes,
            "files": ["sweep.csv", "sweep.parquet", JOURNAL, "plots/", *(["best/"] if best else [])],
        })))
    except KeyboardInterrupt:
        interrupted = True
        counts, best, notes = _counts(done), [], []
    finally:
        worker_peak = worker_peak_mb(client) if client is not None and not interrupted else 0.0
        close_cluster(client, cluster)
    return counts, best, notes, worker_peak, interrupted


def group_order(fields: Sequence[tuple[str, Sequence[str | int]]], points: Sequence[Mapping[str, Any]],
                indices: Sequence[int]) -> list[int]:
    """``indices`` with the points of one synthesis group (:func:`fabricate.sweep.task.synthesis_group`) one after
    the other, groups in the order of their lowest index, each group's points in index order: a worker's cache
    then synthesises a group once, however the grid orders its fields."""
    groups: dict[str, int] = {}
    return sorted(sorted(indices),
                  key=lambda i: (groups.setdefault(synthesis_group(fields, points[i]), len(groups)), i))


def _json(data: Any) -> bytes:
    return (json.dumps(data, indent=1, sort_keys=False, allow_nan=False, default=str) + "\n").encode()


def _run_points(client: Any, spec: SweepSpec, todo: deque, done: dict[str, dict[str, Any]], journal: Journal,
                out: Path, start: float, resumed: int, total: int, draw: bool, say: Progress,
                cache: bool = False) -> int:
    """Submit batches, keep about two per worker in flight, and record rows as tasks finish. Returns the
    number of tasks submitted."""
    from distributed import as_completed

    base, parts, metrics = spec.base, spec.field_parts(), list(spec.metrics)
    # the base template and metrics go to the cluster once; every task refers to them
    shared = client.scatter([base, parts, metrics], broadcast=True, hash=False)
    batch_size = 1  # the first tasks measure a point's time; later batches aim at spec.batch_seconds
    timed: list[float] = []
    attempts: dict[str, int] = {}
    in_flight: dict[Any, list[tuple[int, Any, str]]] = {}
    queue = as_completed()
    last_flush = time.perf_counter()
    flush_every = FLUSH_SECONDS
    counts = _counts(done)
    submitted = 0

    def workers_now() -> int:
        try:
            return max(1, worker_count(client))
        except Exception:  # noqa: BLE001
            return 1

    def submit(batch: list[tuple[int, Any, str]]) -> None:
        nonlocal submitted
        submitted += 1
        fut = client.submit(run_batch, batch, shared[0], shared[1], spec.stage, shared[2], cache, pure=False,
                            retries=TASK_RETRIES)
        in_flight[fut] = batch
        queue.add(fut)

    def fill() -> None:
        want = 2 * workers_now()
        while todo and len(in_flight) < want:
            n = batch_share(batch_size, len(todo), want)
            submit([todo.popleft() for _ in range(n)])

    fill()
    try:
        while in_flight:
            fut = next(queue)
            batch = in_flight.pop(fut)
            try:
                rows = fut.result()
            except Exception as exc:  # noqa: BLE001 - a task that raised or lost its worker too often
                rows = []
                for item in batch:
                    pid = item[2]
                    attempts[pid] = attempts.get(pid, 0) + 1
                    if len(batch) > 1 or attempts[pid] < 2:
                        todo.appendleft(item)  # tried again alone
                    else:
                        rows.append(_error_row(spec, item, exc))
            if rows:
                journal.append(rows)
                for row in rows:
                    key = str(row["exit_code"])
                    counts[key] = counts.get(key, 0) + 1
                    done[str(row["id"])] = row
                    if row["exit_code"] != EXIT_INTERNAL:
                        timed.append(float(row.get("seconds", 0.0)))
                batch_size = next_batch_size(timed, spec.batch_seconds)
            if draw:
                print(_bar(len(done), total, counts, start, resumed), end="", file=sys.stderr, flush=True)
            if time.perf_counter() - last_flush > flush_every:
                began = time.perf_counter()
                _write_tables(out, spec, list(done.values()))
                last_flush = time.perf_counter()
                # a large sweep's tables take a while to write: keep that under a tenth of the main process
                flush_every = max(FLUSH_SECONDS, 10.0 * (last_flush - began))
            fill()
    except BaseException:
        for fut in list(in_flight):
            fut.cancel()
        raise
    return submitted


def next_batch_size(seconds: list[float], target: float) -> int:
    """Points per task so a task takes about ``target`` seconds, from the run times of recent points (the
    median of the last 64, so a worker's first point, which pays for its imports, does not set it)."""
    recent = sorted(seconds[-64:])
    if not recent:
        return 1
    typical = max(recent[len(recent) // 2], 1e-6)
    return int(min(MAX_BATCH, max(1, round(target / typical))))


def batch_share(batch_size: int, left: int, slots: int) -> int:
    """Points in the next task: ``batch_size``, but no more than an even share of the ``left`` points over the
    ``slots`` tasks kept in flight, so a sweep's last points are spread over every worker instead of one worker
    running a long last batch while the others wait."""
    return max(1, min(batch_size, -(-left // max(1, slots))))


def _error_row(spec: SweepSpec, item: tuple[int, Any, str], exc: BaseException) -> dict[str, Any]:
    index, values, pid = item
    name = type(exc).__name__
    why = ("its worker died running it every time it was tried (out of memory, or killed)"
           if name == "KilledWorker" else f"the task failed on the cluster: {name}: {' '.join(str(exc).split())}")
    row: dict[str, Any] = {"point": int(index), "id": pid, **values, "exit_code": EXIT_INTERNAL,
                           "reason": why[:2000]}
    for m in spec.metrics:
        row[m.name] = math.nan
    return row


def _notes(spec: SweepSpec, rows: list[dict[str, Any]]) -> list[str]:
    """A metric that no point's report has is most likely a misspelt key path: say so."""
    reported = [r for r in rows if r["exit_code"] in (0, 1)]
    if not reported:
        return []
    return [f'metric "{m.name}" is in no point\'s report (a misspelt key path? see report.json of one build)'
            for m in spec.metrics if all(math.isnan(r[m.name]) for r in reported)]


def _write_tables(out: Path, spec: SweepSpec, rows: list[dict[str, Any]]) -> None:
    from fabricate.sweep.tables import columns, csv_bytes, parquet_bytes

    fields = [f.path for f in spec.fields]
    names = [m.name for m in spec.metrics]
    write_file(out / "sweep.csv", csv_bytes(rows, columns(fields, names)))
    write_file(out / "sweep.parquet", parquet_bytes(rows, fields, names))


def _write_results(out: Path, spec: SweepSpec, rows: list[dict[str, Any]]) -> None:
    from fabricate.sweep.plots import sweep_plots

    _write_tables(out, spec, rows)
    plots = sweep_plots(rows, [f.path for f in spec.fields], [m.name for m in spec.metrics], spec.map_fields)
    for rel, data in plots.items():
        write_file(out / rel, data)


def _best(spec: SweepSpec, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The ``spec.best`` passing points, ranked by the best metric (ties by point index)."""
    if not spec.best or spec.best_metric is None:
        return []
    name = spec.best_metric.name
    sign = 1.0 if spec.best_goal == "min" else -1.0
    ok = [r for r in rows if r["exit_code"] == 0 and isinstance(r.get(name), float) and not math.isnan(r[name])]
    ok.sort(key=lambda r: (sign * r[name], r["point"]))
    return [{"rank": k + 1, "point": int(r["point"]), "id": r["id"], name: r[name],
             "values": {f.path: r[f.path] for f in spec.fields}} for k, r in enumerate(ok[:spec.best])]


def _build_best(client: Any, spec: SweepSpec, best: list[dict[str, Any]], out: Path, say: Progress,
                protect: Sequence[Path] = (), cache: bool = False) -> None:
    """Build the best points in full on the cluster and write each as a normal build output folder."""
    from fabricate.output import write_output
    from fabricate.output_read import MAX_REPORT_BYTES, read_regular
    from fabricate.sweep.task import point_text

    parts = spec.field_parts()
    wanted = []
    for entry in best:
        folder = out / "best" / f"{entry['rank']:02d}-point{entry['point']}"
        entry["folder"] = folder.relative_to(out).as_posix()
        data = read_regular(folder / "report.json", MAX_REPORT_BYTES)  # never a link, a FIFO or a device
        if data is not None:  # an earlier run built it: the same template gives the same files
            try:
                previous = json.loads(data.decode("utf-8"))
            except (ValueError, RecursionError):
                previous = None
            if isinstance(previous, dict) and previous.get("template_text") == point_text(spec.base, parts,
                                                                                        entry["values"]):
                continue
        wanted.append((entry, folder))
    if not wanted:
        return
    say(f"building the best {len(best)} point{'s' if len(best) != 1 else ''} in full")
    futures = [client.submit(build_point, entry["values"], spec.base, parts, cache, pure=False,
                             retries=TASK_RETRIES) for entry, _ in wanted]
    for (entry, folder), fut in zip(wanted, futures, strict=True):
        code, reason, files = fut.result()
        entry["build_exit_code"] = code
        if not files:
            entry["build_reason"] = reason
            continue
        write_output(files, folder, stage="build", protect=protect,
                     warn=lambda msg: print(f"fabricate: warning: {msg}", file=sys.stderr, flush=True))
