"""``background.Handoff``: a value sent to a forked child after the fork (the exports' child, forked before the parts
exist, waits for the part set), and ``preceded``."""

from __future__ import annotations

import os
import threading

import pytest

from fabricate.background import Background, Handoff, can_fork, in_thread, preceded

pytestmark = pytest.mark.skipif(not can_fork(), reason="needs fork")


def test_a_value_sent_after_the_fork_reaches_the_childs_job() -> None:
    handoff = Handoff()
    parent = os.getpid()
    child = Background([lambda: {"value": handoff.get(), "pid": str(os.getpid()).encode()}])
    try:
        assert child.forked
        handoff.send(b"part set")
        got = child.result()
    finally:
        child.cancel()
        handoff.close()
    assert got["value"] == b"part set"
    assert int(got["pid"]) != parent  # read from the pipe by the child, not the value kept here


def test_sending_never_waits_for_the_child_to_read() -> None:
    """A value far larger than a pipe's buffer: :meth:`send` returns while the child has not begun to read (it
    waits for a gate this test opens only after ``send`` returned)."""
    big = os.urandom(4 << 20)
    gate_read, gate_write = os.pipe()
    handoff = Handoff()

    def job() -> dict[str, bytes]:
        os.read(gate_read, 1)
        return {"value": handoff.get()}

    child = Background([job])
    try:
        sender = threading.Thread(target=handoff.send, args=(big,), daemon=True)
        sender.start()
        sender.join(60)  # a hang guard, not a speed bound: send blocking on the child would never return
        assert not sender.is_alive()
        os.write(gate_write, b"x")
        assert child.result()["value"] == big
    finally:
        child.cancel()
        handoff.close()
        os.close(gate_read)
        os.close(gate_write)


def test_where_the_child_fails_its_jobs_run_here_with_the_value_kept() -> None:
    handoff = Handoff()
    parent = os.getpid()

    def job() -> dict[str, bytes]:
        if os.getpid() != parent:
            os._exit(3)  # the child dies before it reads
        return {"value": handoff.get()}

    child = Background([job])
    try:
        handoff.send([1.5, "x"])
        assert child.result() == {"value": [1.5, "x"]}
    finally:
        child.cancel()
        handoff.close()


def test_a_child_whose_parent_closed_without_sending_sees_the_end() -> None:
    handoff = Handoff()

    def job() -> dict[str, bytes]:
        try:
            handoff.get()
        except EOFError:
            return {"eof": str(os.getpid()).encode()}
        return {}

    child = Background([job])
    try:
        handoff.close()  # the build failed before the parts: nothing sent
        got = child.result()
    finally:
        child.cancel()
    assert int(got["eof"]) != os.getpid()


def test_get_before_send_in_the_sending_process_is_an_error() -> None:
    handoff = Handoff()
    try:
        with pytest.raises(RuntimeError, match="before send"):
            handoff.get()
    finally:
        handoff.close()


def test_preceded_runs_first_and_keeps_a_threaded_job_threaded() -> None:
    order: list[str] = []
    plain = preceded(lambda: order.append("first"), lambda: order.append("job") or {"a": b"1"})
    assert plain() == {"a": b"1"} and order == ["first", "job"]
    threaded = preceded(lambda: None, in_thread(lambda: {"b": b"2"}))
    assert type(threaded) is type(in_thread(lambda: {})) and threaded() == {"b": b"2"}


#: A stop signal landing while a child is forked: a fork hook of this script's sends SIGINT to the process itself.
STOP_IN_FORK = """
import multiprocessing, os, signal
from fabricate.background import Background

class Stop(BaseException):
    pass

def stop(*args):
    raise Stop()

signal.signal(signal.SIGINT, stop)
os.register_at_fork(after_in_parent=lambda: os.kill(os.getpid(), signal.SIGINT))
try:
    Background([lambda: {}])
except Stop:
    print("stopped", len(multiprocessing.active_children()))
else:
    print("not stopped")
"""


def test_a_stop_signal_during_a_fork_is_raised_after_it_and_the_child_reaped() -> None:
    """The signal waits until the fork is done (no traceback of a fork hook on stderr, no stop dropped); the
    exception comes from making the Background, whose child is killed and reaped first (none left)."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", STOP_IN_FORK], capture_output=True, text=True, timeout=300)
    assert done.stdout.split() == ["stopped", "0"], done.stdout + done.stderr
    assert done.stderr == ""
