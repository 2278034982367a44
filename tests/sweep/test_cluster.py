"""A sweep's Dask cluster says nothing on the user's terminal: no traceback from the client's loop after a Ctrl-C,
no warning where another cluster holds Dask's HTTP port."""
from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import signal
import socket
import subprocess
import sys
import threading
import warnings

import pytest

pytest.importorskip("distributed")


class _InterruptedOnce(threading.Event):
    """An event whose first wait in the main thread raises KeyboardInterrupt, as a Ctrl-C landing there does."""

    armed = True

    def wait(self, timeout: float | None = None) -> bool:
        if _InterruptedOnce.armed and threading.current_thread() is threading.main_thread():
            _InterruptedOnce.armed = False
            raise KeyboardInterrupt
        return super().wait(timeout)


class _Records(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@pytest.mark.slow
def test_a_clusters_client_is_quiet_on_ctrl_c_and_beside_another_cluster(monkeypatch):
    """distributed's ``sync`` answers a KeyboardInterrupt by queuing a ``cancel`` on the loop thread, which
    raises NameError where the call had not started yet, and tornado logs that with a traceback at once. That
    printed on a sweep's stderr before its own handler ran (CI, 2026-11-27). Once the sweep's client exists,
    nothing the loops log reaches the user.

    The scheduler serves HTTP on port 8787 even without a dashboard; where that is taken (a second sweep, a
    notebook's cluster) distributed warned "Port 8787 is already in use" on the user's terminal."""
    import distributed.utils

    from fabricate.sweep.cluster import EVENT_LOOP_LOGGERS, connect

    # an earlier sweep in this process leaves them quiet: start from distributed's default (tornado.application at
    # ERROR, its parent at CRITICAL), so the test can fail.
    # distributed gives tornado's loggers their own stderr handler (no propagation): a handler of the test's
    # own sees what would be printed
    loggers = [logging.getLogger(name) for name in EVENT_LOOP_LOGGERS]
    levels = [logger.level for logger in loggers]
    seen = _Records()
    for logger in loggers:
        logger.setLevel(logging.ERROR)
        logger.addHandler(seen)
    with contextlib.ExitStack() as held:
        port = held.enter_context(socket.socket())
        with contextlib.suppress(OSError):  # taken already: by another test's cluster
            port.bind(("", 8787))
            port.listen()
        with warnings.catch_warnings(record=True) as warned:
            warnings.simplefilter("always")
            client, cluster = connect(1, None)
    assert [str(w.message) for w in warned if "8787" in str(w.message)] == []
    try:
        _InterruptedOnce.armed = True
        monkeypatch.setattr(distributed.utils.threading, "Event", _InterruptedOnce)
        with pytest.raises(KeyboardInterrupt):
            client.sync(asyncio.sleep, 0.05)
        assert not _InterruptedOnce.armed
        monkeypatch.undo()
        # the loop has run the queued cancel once a later call on it returns
        client.sync(asyncio.sleep, 0.05)
        client.sync(asyncio.sleep, 0.05)
        assert [(r.name, r.getMessage()) for r in seen.records] == []
    finally:
        client.close()
        cluster.close()
        for logger, level in zip(loggers, levels, strict=True):
            logger.removeHandler(seen)
            logger.setLevel(level)


@pytest.mark.slow
def test_a_local_clusters_workers_keep_freed_memory_as_a_build_does():
    """The local cluster's workers run with a build's glibc thresholds (fabricate.bounds.ROOMY_HEAP, set through
    glibc's environment variables), not Dask's MALLOC_TRIM_THRESHOLD_=65536 (which maps and unmaps a point's
    arrays again and again); Dask's own setting is restored after the cluster starts."""
    import dask

    from fabricate.bounds import roomy_heap_environ
    from fabricate.sweep.cluster import connect

    before = dask.config.get("distributed.nanny.pre-spawn-environ")
    environ = {name: value for name, value in os.environ.items() if name.startswith("MALLOC_")}
    client, cluster = connect(1, None)
    try:
        seen = client.run(lambda: (os.environ.get("MALLOC_TRIM_THRESHOLD_"), os.environ.get("MALLOC_MMAP_THRESHOLD_")))
    finally:
        client.close()
        cluster.close()
    heap = roomy_heap_environ()
    assert list(seen.values()) == [(heap["MALLOC_TRIM_THRESHOLD_"], heap["MALLOC_MMAP_THRESHOLD_"])]
    assert dask.config.get("distributed.nanny.pre-spawn-environ") == before
    # this process's environment as it was (the nanny writes the variables into it to pass them on)
    assert {name: value for name, value in os.environ.items() if name.startswith("MALLOC_")} == environ


# Started in a process of its own (a fresh resource tracker), then the whole group hears a Ctrl-C and a hang-up
# as from a terminal, which this script handles as a sweep does: its worker and the tracker must not.
DEAF = """
import os, signal, sys
from multiprocessing import resource_tracker
from fabricate.sweep.cluster import close_cluster, connect
heard = []
signal.signal(signal.SIGINT, lambda n, f: heard.append(n))
signal.signal(signal.SIGHUP, lambda n, f: heard.append(n))
client, cluster = connect(1, None)
worker = next(iter(client.run(os.getpid).values()))
tracker = resource_tracker._resource_tracker._pid
def blocked(pid):
    status = dict(line.split(':', 1) for line in open(f'/proc/{pid}/status').read().splitlines())
    return int(status['SigBlk'], 16)
held = signal.pthread_sigmask(signal.SIG_BLOCK, [])
masks = [blocked(worker), blocked(tracker), int(signal.SIGINT in held or signal.SIGHUP in held)]
os.killpg(0, signal.SIGINT)
os.killpg(0, signal.SIGHUP)
again = next(iter(client.run(os.getpid).values()))  # a round trip: the worker is alive and the same
print(masks[0], masks[1], masks[2], worker == again, sorted(heard), flush=True)
close_cluster(client, cluster)
"""


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_local_clusters_processes_never_hear_the_terminal(tmp_path):
    """Ctrl-C and a hang-up reach the terminal's whole foreground group. Before, each Dask worker printed a
    KeyboardInterrupt traceback, and a hang-up killed multiprocessing's resource tracker, whose relaunched self
    printed KeyError tracebacks. The cluster's processes start with both signals blocked; this process hears
    them (and closes the cluster), and its own mask is as before."""
    run = subprocess.run([sys.executable, "-c", DEAF], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                         start_new_session=True)
    assert run.returncode == 0, run.stderr
    worker_mask, tracker_mask, main_blocks, same_worker, heard = run.stdout.split(maxsplit=4)
    for number in (signal.SIGINT, signal.SIGHUP):
        assert int(worker_mask) & 1 << (number - 1), (signal.Signals(number).name, run.stdout)
    assert int(tracker_mask) & 1 << (signal.SIGHUP - 1), run.stdout  # it ignores SIGINT itself
    assert main_blocks == "0" and same_worker == "True"
    assert heard.strip() == str(sorted([int(signal.SIGINT), int(signal.SIGHUP)]))
    assert "Traceback" not in run.stderr and "Error" not in run.stderr, run.stderr
