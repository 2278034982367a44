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
