"""A sweep's Dask cluster says nothing on the user's terminal: no traceback from the client's loop after a Ctrl-C,
no warning where another cluster holds Dask's HTTP port."""
from __future__ import annotations

import asyncio
import contextlib
import logging
import socket
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

    from fabricate.sweep.runner import EVENT_LOOP_LOGGERS, connect

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
