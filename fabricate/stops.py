"""Stop signals as exceptions: SIGINT, SIGTERM and SIGHUP end a command like Ctrl-C does, with every ``finally`` run.

The command line (:func:`fabricate.cli.main`) holds :func:`stop_on_signals` while a command runs.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Iterable, Iterator
from typing import Any

#: The signals that stop a command, and how its one line on stderr names each.
STOP_SIGNALS = {"SIGINT": "interrupted", "SIGTERM": "terminated (SIGTERM)", "SIGHUP": "hung up (SIGHUP)"}


class Stopped(KeyboardInterrupt):
    """A stopping signal (SIGINT, SIGTERM, SIGHUP) raised like Ctrl-C's KeyboardInterrupt.

    Being a KeyboardInterrupt, it runs every ``finally`` (the picture child is killed, a temporary folder
    removed) and stops cleanly whatever already stops cleanly on Ctrl-C (a sweep records its points).

    Parameters
    ----------
    signum : int
        The signal's number; the exit code is 128 + ``signum``.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


@contextlib.contextmanager
def stop_on_signals() -> Iterator[list[int]]:
    """Raise :class:`Stopped` on the first SIGINT, SIGTERM or SIGHUP while the command runs.

    Yields the list the received signal's number is put in. Later signals are ignored so the cleanup the
    first one started can finish (SIGKILL still ends the process, and its children die with it). A signal
    the caller ignores stays ignored (``nohup``, a background job) and a handler the caller installed (a
    program calling :func:`fabricate.cli.main`) stays in place. Only the main thread can have handlers.

    The handler can raise where Python cannot pass an exception on (a destructor, a garbage-collector callback:
    distributed registers one), and Python would print "Exception ignored in ..." with a traceback. While the
    command runs, such an exception is dropped once a stop is received (it is recorded here, and the run stops
    at its next stage or says it ended); every other one goes to the hook that was in place.
    """
    received: list[int] = []
    closing = [False]
    previous_hook = sys.unraisablehook

    def unraisable(unraisable: Any) -> None:
        if not (received or isinstance(unraisable.exc_value, Stopped)):
            previous_hook(unraisable)

    def stop(signum: int, frame: Any) -> None:
        if received or closing[0]:
            return
        if _importing(frame):
            # raised inside an import, it can fail a C extension's initialisation midway, and some abort the
            # process on that (nanobind and pybind11 modules make their enums through Python's enum module: a
            # SIGABRT or SIGSEGV instead of exit 143). The signal is sent again until the import is done
            _again(signum, closing)
            return
        received.append(signum)
        raise Stopped(signum)

    previous: dict[int, Any] = {}
    for name in STOP_SIGNALS:
        number = getattr(signal, name, None)
        if number is None or signal.getsignal(number) not in (signal.SIG_DFL, signal.default_int_handler):
            continue
        try:
            previous[number] = signal.signal(number, stop)
        except ValueError:  # not the main thread
            break
    sys.unraisablehook = unraisable
    try:
        yield received
    finally:
        closing[0] = True  # a signal now is too late to stop anything: the handlers go back as they were
        for number, handler in previous.items():
            signal.signal(number, handler)
        sys.unraisablehook = previous_hook


def _importing(frame: Any) -> bool:
    """Whether ``frame`` (a signal handler's) runs inside an import."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib._bootstrap"):
            return True
        frame = frame.f_back
    return False


def _again(signum: int, closing: list[bool]) -> None:
    """Send ``signum`` to this process again in 10 ms, unless the command is over by then."""
    import threading

    def send() -> None:
        if not closing[0]:
            os.kill(os.getpid(), signum)

    timer = threading.Timer(0.01, send)
    timer.daemon = True
    timer.start()


def signal_numbers(names: Iterable[str] = STOP_SIGNALS) -> set[int]:
    """The numbers of the signals ``names`` (``"SIGINT"``, ...) this platform has."""
    return {getattr(signal, name) for name in names if hasattr(signal, name)}


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold the stop signals off for a few system calls (a fork, a folder swap); they are handled right after.

    A stop between the two renames of the fallback swap never leaves the output folder missing, and one during a
    fork never lands in a fork hook (where Python prints its exception with a traceback and drops it) nor leaves
    a child no one holds.

    The signals are deferred at Python's level (a handler that only records them, then the old handlers back and
    the recorded signals raised again), not by ``pthread_sigmask``: a mask holds only for the calling thread, and a
    process-directed signal is delivered to any other thread (BLAS's workers) whose mask lets it through, whose C
    handler then runs the Python handler in the main thread at once. A forked child inherits the recording
    handler: it sets its own (:mod:`fabricate.background`).
    """
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield  # Python runs signal handlers in the main thread only: this thread is never interrupted
        return
    held: list[int] = []
    old = {}
    for signum in sorted(signal_numbers()):
        current = signal.getsignal(signum)
        if current in (signal.SIG_IGN, None):  # ignored by the caller (nohup), or set outside Python
            continue
        old[signum] = signal.signal(signum, lambda s, _f: held.append(s))
    try:
        yield
    finally:
        for signum, handler in old.items():
            signal.signal(signum, handler)
        for signum in dict.fromkeys(held):
            signal.raise_signal(signum)


@contextlib.contextmanager
def signals_held(names: Iterable[str]) -> Iterator[None]:
    """Block the signals ``names`` in this thread for the block, for the threads it starts (they inherit the mask)
    and the processes those start (they keep it across ``exec``). A signal that comes meanwhile waits and is
    handled as the mask is restored (or by another thread that lets it through: :func:`signals_deferred`). Nothing
    is blocked where there is no ``pthread_sigmask``."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, signal_numbers(names))
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
