"""fabricate.background.run_isolated: a call in a fresh interpreter, its result the call's own."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import pytest

from fabricate.background import run_isolated


def _loaded(name: str) -> bool:
    """Whether module ``name`` is imported in the calling process (run in the fresh one by the test)."""
    return name in sys.modules


def _pid_and_value(value: float) -> tuple[int, float]:
    return os.getpid(), math.sqrt(value)


def test_run_isolated_runs_in_a_fresh_process_and_returns_the_result():
    import fabricate.pipeline  # noqa: F401 - loaded here, so a forked child would have it too

    pid, value = run_isolated("tests.test_background", "_pid_and_value", 2.0)
    assert pid != os.getpid() and value == math.sqrt(2.0)
    # a fresh interpreter, not a fork: it holds none of the caller's modules (nor their memory)
    assert _loaded("fabricate.pipeline")
    assert run_isolated("tests.test_background", "_loaded", "fabricate.pipeline") is False


def test_run_isolated_raises_the_calls_own_error_here():
    with pytest.raises(ValueError, match="math domain error"):
        run_isolated("math", "sqrt", -1.0)


def test_run_isolated_runs_here_when_no_process_starts(monkeypatch):
    def no_process(*_args, **_kwargs):
        raise OSError("EAGAIN")

    monkeypatch.setattr(subprocess, "Popen", no_process)
    pid, value = run_isolated("tests.test_background", "_pid_and_value", 9.0)
    assert pid == os.getpid() and value == 3.0


def test_in_thread_jobs_run_beside_the_others_and_keep_their_place():
    import threading

    from fabricate.background import _run_jobs, in_thread

    later_job_ran = threading.Event()

    def waits_for_the_later_job() -> dict[str, bytes]:
        # run one after the other, this job would wait for a job after it: it must already be running
        return {"b": b"1" if later_job_ran.wait(timeout=120) else b"0"}

    def later() -> dict[str, bytes]:
        later_job_ran.set()
        return {"c": b"c"}

    files = _run_jobs([lambda: {"a": b"a"}, in_thread(waits_for_the_later_job), later])
    assert files == {"a": b"a", "b": b"1", "c": b"c"} and list(files) == ["a", "b", "c"]


def test_in_thread_job_raises_its_error_in_its_turn():
    from fabricate.background import _run_jobs, in_thread

    def broken() -> dict[str, bytes]:
        raise ValueError("no STEP")

    with pytest.raises(ValueError, match="no STEP"):
        _run_jobs([lambda: {"a": b"a"}, in_thread(broken)])
