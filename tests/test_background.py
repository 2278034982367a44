"""fabricate.background.run_isolated: a call in a fresh interpreter, its result the call's own."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import pytest

from fabricate.background import Background, run_isolated


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


def test_prestarted_worker_serves_the_next_call():
    from fabricate import background

    background.prestart("tests.test_background")
    worker = background._WARM["tests.test_background"][0]
    pid, value = run_isolated("tests.test_background", "_pid_and_value", 4.0)
    assert pid == worker.pid and value == 2.0
    assert "tests.test_background" not in background._WARM  # used once
    pid, _ = run_isolated("tests.test_background", "_pid_and_value", 4.0)
    assert pid not in (worker.pid, os.getpid())  # the next call starts its own


def test_a_fork_hands_the_prestarted_worker_to_the_child():
    import pickle

    from fabricate import background

    background.prestart("tests.test_background")
    worker = background._WARM["tests.test_background"][0]
    read, write = os.pipe()
    child = os.fork()
    if child == 0:  # the child makes the call, through the worker it was handed
        try:
            os.close(read)
            os.write(write, pickle.dumps(run_isolated("tests.test_background", "_pid_and_value", 16.0)))
        finally:
            os._exit(0)
    os.close(write)
    assert background._WARM == {}  # the parent let go of it
    with os.fdopen(read, "rb") as answer:
        pid, value = pickle.loads(answer.read())
    os.waitpid(child, 0)
    assert pid == worker.pid and value == 4.0
    background._reap_handed(kill=False)
    assert worker.returncode == 0  # the parent reaped it: its time and memory are counted as the caller's


def test_a_fork_without_hand_over_leaves_the_prestarted_worker_for_a_later_child():
    from fabricate import background

    background.prestart("tests.test_background")
    worker = background._WARM["tests.test_background"][0]
    first = Background([lambda: {"a": b"1"}], hand_over=False)
    assert first.forked
    assert background._WARM["tests.test_background"][0] is worker  # still this process's to hand on
    assert first.result() == {"a": b"1"}
    second = Background([lambda: {"b": b"2"}])
    try:
        assert background._WARM == {}  # a default child takes it
        assert second.result() == {"b": b"2"}
    finally:
        second.cancel()
    assert worker.poll() is not None  # reaped with the child it was handed to


def _sleep_then(value: float) -> float:
    import time

    time.sleep(600)
    return value


def test_a_job_that_raises_stops_the_threaded_jobs_worker_before_the_error_leaves():
    """A threaded job waits on its worker (the STEP files); when another job raises, nobody will read its result:
    _run_jobs kills that worker and joins the thread before raising, so an API caller's process keeps no thread
    or process of a failed build (without this the worker slept on for ten minutes)."""
    import threading
    import time

    from fabricate import background
    from fabricate.background import in_thread

    serving: list = []

    def waiting() -> dict[str, bytes]:
        run_isolated("tests.test_background", "_sleep_then", 1.0)
        return {}

    def failing() -> dict[str, bytes]:
        while not background._SERVING:  # the thread's worker is serving its call: the kill is what ends it
            time.sleep(0.01)
        serving.extend(background._SERVING.values())
        raise RuntimeError("this design cannot be made")

    threads = threading.active_count()
    with pytest.raises(RuntimeError, match="cannot be made"):
        background._run_jobs([in_thread(waiting), failing])
    assert len(serving) == 1 and serving[0].poll() is not None  # killed and reaped
    assert threading.active_count() == threads
    assert background._SERVING == {} and background._ABANDONED == set()
