"""The Dask side of a sweep: a client and the local cluster it owns, started quiet and warm, and closed again.

A sweep's processes say nothing on the user's terminal: its workers never hear the terminal's signals (this
process handles them and closes the cluster), and the event loops' tracebacks of a torn-down cluster are kept
from the user. The sweep itself (:mod:`fabricate.sweep.runner`) records every outcome.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
import warnings
from collections.abc import Iterator
from typing import Any

from fabricate.errors import SpecError
from fabricate.stops import signals_held
from fabricate.sweep.task import peak_rss_mb, warm


def connect(workers: int | None, scheduler: str | None) -> tuple[Any, Any]:
    """A Dask client and the local cluster it owns (None with ``scheduler``).

    Raises
    ------
    SpecError
        Dask is not installed, or the scheduler cannot be reached.
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise SpecError("sweep", "needs Dask distributed and pyarrow: pip install \"fabricate[sweep]\"") from None
    for name in ("distributed", "distributed.nanny", "distributed.scheduler", "distributed.worker",
                 "distributed.core", "distributed.client"):
        logging.getLogger(name).setLevel(logging.ERROR)
    _quiet_event_loops()
    if scheduler:
        try:
            client = Client(scheduler, timeout="15s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise SpecError("--scheduler", f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
        return client, None
    n = workers or default_workers()
    # one single-threaded process per core: a point is CPU-bound Python; the memory limit is Dask's share
    # of this machine per worker (a point stays within the template bounds' 4 GB)
    import dask

    # Dask starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which turns glibc's dynamic mmap threshold off: a
    # point's large numpy arrays are mapped and unmapped again every time (6x the page faults), and a build point
    # took 6-7 % more CPU in a worker than in this process. The local cluster's workers get a build's own thresholds
    # instead (fabricate.bounds.ROOMY_HEAP, as glibc's environment variables; distributed is imported above, so the
    # context restores Dask's setting)
    from fabricate.bounds import roomy_heap_environ

    environ = roomy_heap_environ()
    kept = {name: os.environ.get(name) for name in environ}  # the nanny sets them in this process's environment
    cluster = None
    try:
        with dask.config.set({f"distributed.nanny.pre-spawn-environ.{name}": value
                              for name, value in environ.items()}), _deaf_to_the_terminal():
            # the scheduler serves its HTTP routes even without a dashboard, on port 8787 where free: a second
            # sweep (or any Dask cluster) on this machine makes it warn "Port 8787 is already in use" on the
            # user's terminal, and it takes another port anyway
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message="Port 8787 is already in use", category=UserWarning)
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                       silence_logs=logging.ERROR)
        client = Client(cluster)
    except BaseException:
        close_cluster(None, cluster)  # a Ctrl-C held while it started is raised as the mask is restored
        raise
    finally:
        for name, value in kept.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
    return client, cluster


#: What a terminal sends its whole foreground process group: Ctrl-C and a hang-up.
TERMINAL_SIGNALS = ("SIGINT", "SIGHUP")


@contextlib.contextmanager
def _deaf_to_the_terminal() -> Iterator[None]:
    """Start a local cluster's processes with the terminal's signals blocked, so that only this process hears them.

    A Ctrl-C or hang-up goes to the whole foreground group: each Dask worker printed a KeyboardInterrupt traceback,
    and a hang-up killed multiprocessing's resource tracker (it ignores SIGINT and SIGTERM, not SIGHUP), whose
    relaunched self then printed a KeyError traceback for every name it never saw (it keeps the hang-up blocked;
    it ignores SIGINT itself). The threads the cluster starts
    inherit this thread's mask and its processes keep it across ``exec``; this process handles the signal and
    closes the cluster (the nanny stops its workers with SIGTERM, which stays open, and a worker exits when its
    parent dies). A signal that comes meanwhile waits, and is handled when the mask is restored.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    with signals_held(TERMINAL_SIGNALS):
        # the tracker first, from here: starting it (CPython 3.11-3.13) unblocks SIGINT and SIGTERM in the thread
        # that starts it, which would otherwise be the thread that goes on to start the workers
        with contextlib.suppress(ImportError, AttributeError, OSError):
            from multiprocessing import resource_tracker

            resource_tracker.ensure_running()
        with signals_held(TERMINAL_SIGNALS):  # again, after the tracker's start
            yield


def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # macOS, Windows
        return max(1, os.cpu_count() or 1)


def start_cluster(workers: int | None, scheduler: str | None, stage: str) -> tuple[Any, Any, int]:
    """Client and (local) cluster with their workers up and warm for ``stage``'s points, and how many workers;
    closed again when that fails."""
    client, cluster = connect(workers, scheduler)
    try:
        n_workers = _wait_for_workers(client, scheduler)
        _warm(client, stage)
    except BaseException:
        close_cluster(client, cluster)
        raise
    return client, cluster, n_workers


def worker_count(client: Any) -> int:
    """How many workers the scheduler knows now (all of them: newer distributed lists only 5 unless asked)."""
    info = client.scheduler_info(n_workers=-1) if _takes_n_workers(client) else client.scheduler_info()
    return len(info.get("workers", {}))


def _wait_for_workers(client: Any, scheduler: str | None) -> int:
    deadline = time.monotonic() + 60.0
    while True:
        n = worker_count(client)
        if n:
            return n
        if time.monotonic() > deadline:
            raise SpecError("--scheduler" if scheduler else "--workers", "no Dask worker joined within 60 s")
        time.sleep(0.2)


def _warm(client: Any, stage: str) -> None:
    """Every worker imports what a point of ``stage`` runs now, side by side, instead of in its first point."""
    try:
        client.run(warm, stage)
    except Exception:  # noqa: BLE001 - a worker that cannot run it will show why in its first point
        pass


def workers_cpu(client: Any) -> dict[str, float]:
    """``{worker address: its process's CPU seconds so far}`` (empty when they cannot say)."""
    try:
        return {str(k): float(v) for k, v in client.run(time.process_time).items()}
    except Exception:  # noqa: BLE001 - a figure for benchmarks
        return {}


def worker_peak_mb(client: Any) -> float:
    """The largest peak resident memory of the cluster's workers (MB), 0 when they cannot say."""
    try:
        peaks = client.run(peak_rss_mb)
        return max((float(v) for v in peaks.values()), default=0.0)
    except Exception:  # noqa: BLE001 - a figure for benchmarks, never a reason to fail a finished sweep
        return 0.0


def _takes_n_workers(client: Any) -> bool:
    import inspect

    return "n_workers" in inspect.signature(client.scheduler_info).parameters


#: The event loops' own loggers: tearing a cluster down (after Ctrl-C above all) can make a pending callback
#: raise, which tornado and asyncio log with a traceback; the sweep's outcome is already recorded by then.
EVENT_LOOP_LOGGERS = ("tornado.application", "tornado.general", "asyncio")


def _quiet_event_loops() -> None:
    """Keep the event loops' tracebacks from the user once a client can exist: a Ctrl-C while distributed's
    ``sync`` waits queues a ``cancel`` on the loop thread, which raises where the call had not begun (2026.8: a
    NameError on ``future``) and tornado logs at once, before the sweep's handler runs. The sweep records its
    outcome itself; quiet for the rest of the process (the loop thread can log after ``close()`` returns)."""
    for name in EVENT_LOOP_LOGGERS:
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def close_cluster(client: Any, cluster: Any) -> None:
    for thing in (client, cluster):
        if thing is not None:
            try:
                thing.close()
            except Exception:  # noqa: BLE001 - closing a broken cluster must not hide the sweep's outcome
                pass
