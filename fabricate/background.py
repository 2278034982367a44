"""Jobs returning ``{relative path: bytes}`` run in a forked child while the build goes on (the pictures).

The pipeline's pictures take as long as everything else, so :class:`Background` draws them on the second
core; whatever happens to the child (no ``fork``, a daemon process, a crash, a kill), the caller gets the
same bytes, computed here if need be. :func:`run_isolated` runs one call in a fresh interpreter instead, for
work whose imports are large and needed nowhere else (the STEP writer's OCP).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import threading
from collections.abc import Callable
from typing import Any

from fabricate.stops import signals_deferred


class _Threaded:
    """A job that :func:`_run_jobs` starts in a thread of its own before the others (:func:`in_thread`)."""

    def __init__(self, job: Callable[[], dict[str, bytes]]) -> None:
        self.job = job

    def __call__(self) -> dict[str, bytes]:
        return self.job()


def in_thread(job: Callable[[], dict[str, bytes]]) -> Callable[[], dict[str, bytes]]:
    """Mark ``job`` to run in a thread beside the other jobs, started first.

    For a job that mostly waits on another process (:func:`run_isolated`: the STEP files), so that the
    pictures are drawn meanwhile instead of after it. Its files still come in the job's place in the list;
    its exception is raised once the other jobs are done.
    """
    return _Threaded(job)


def preceded(first: Callable[[], object], job: Callable[[], dict[str, bytes]]) -> Callable[[], dict[str, bytes]]:
    """``job`` run after ``first()`` (e.g. waiting for a :class:`Handoff`), in a thread of its own where ``job``
    was marked so (:func:`in_thread`)."""
    inner = job.job if isinstance(job, _Threaded) else job

    def after() -> dict[str, bytes]:
        first()
        return inner()

    return in_thread(after) if isinstance(job, _Threaded) else after


def _run_jobs(jobs: list[Callable[[], dict[str, bytes]]]) -> dict[str, bytes]:
    answers: dict[int, tuple[bool, Any]] = {}

    def run(k: int, job: Callable[[], dict[str, bytes]]) -> None:
        try:
            answers[k] = (True, job())
        except BaseException as exc:  # noqa: BLE001 - raised in the caller's thread, in the job's turn
            answers[k] = (False, exc)

    threads = {k: threading.Thread(target=run, args=(k, job), daemon=True)
               for k, job in enumerate(jobs) if isinstance(job, _Threaded)}
    for thread in threads.values():
        thread.start()
    try:
        for k, job in enumerate(jobs):
            if k not in threads:
                answers[k] = (True, job())
    except BaseException:  # nobody will read the threads' results: stop their processes before raising
        _abandon(list(threads.values()))
        raise
    for k, thread in threads.items():
        thread.join()
        ok, value = answers[k]
        if not ok:
            raise value
    files: dict[str, bytes] = {}
    for k in range(len(jobs)):  # in the jobs' order, whichever finished first
        files.update(answers[k][1])
    return files


class Handoff:
    """A value this process sends a forked child after the fork, for the child's jobs to wait for.

    The exports' child is forked before the parts exist, so that it imports what it needs while this process
    makes them; its jobs then wait here for the part set. Made before the fork: :meth:`send` (this process)
    pickles the value down a pipe, from a thread (a value larger than the pipe's buffer never makes this process
    wait for the child to read it); :meth:`get` returns it in the child, waiting until it comes, or here (the
    child failed and :class:`Background` runs its jobs in this process) the value kept by :meth:`send`.
    """

    def __init__(self) -> None:
        self._owner = os.getpid()
        self._read, self._write = os.pipe()
        self._lock = threading.Lock()
        self._sent = False
        self._value: Any = None

    def send(self, value: Any) -> None:
        """Send ``value`` (once); a child that is gone is no error: its jobs run here with the value kept."""
        import pickle
        import struct

        self._value, self._sent = value, True
        data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
        write, self._write = self._write, -1
        os.close(self._read)
        self._read = -1

        def writing() -> None:
            view = memoryview(struct.pack("<Q", len(data)) + data)
            try:
                while view:
                    view = view[os.write(write, view):]
            except OSError:  # EPIPE: the child is gone (the jobs run here)
                pass
            finally:
                os.close(write)

        threading.Thread(target=writing, daemon=True).start()

    def get(self) -> Any:
        """The value sent: in a forked child, read from the pipe (once; any thread may ask); here, the value kept.

        Raises
        ------
        EOFError
            In a child whose parent closed the pipe without sending (the child's jobs fail; the parent's
            :class:`Background` redoes them).
        """
        import pickle
        import struct

        with self._lock:
            if self._sent:
                return self._value
            if os.getpid() == self._owner:
                raise RuntimeError("Handoff.get before send, in the sending process")
            if self._write >= 0:  # the fork's copy: the parent's close then ends the read (EOF), not a wait
                os.close(self._write)
                self._write = -1
            size = struct.unpack("<Q", self._read_exactly(8))[0]
            self._value, self._sent = pickle.loads(self._read_exactly(size)), True
            return self._value

    def _read_exactly(self, size: int) -> bytes:
        chunks, left = [], size
        while left:
            chunk = os.read(self._read, min(left, 1 << 20))
            if not chunk:
                raise EOFError("the sending process closed the pipe before sending")
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)

    def close(self) -> None:
        """Close this process's ends of the pipe where :meth:`send` has not (never sent: the build failed)."""
        if os.getpid() != self._owner:
            return
        for name in ("_read", "_write"):
            fd = getattr(self, name)
            if fd >= 0:
                with contextlib.suppress(OSError):
                    os.close(fd)
                setattr(self, name, -1)


class Abandoned(Exception):
    """Raised in a thread of :func:`_run_jobs` whose result is no longer wanted (another job raised)."""


#: Threads whose job :func:`_run_jobs` gave up on: their :func:`run_isolated` calls end instead of starting over.
_ABANDONED: set[int] = set()
#: The worker serving each thread's :func:`run_isolated` call now, by thread: killed when the thread is abandoned.
_SERVING: dict[int, Any] = {}
_SERVING_LOCK = threading.Lock()


def _abandon(threads: list[threading.Thread]) -> None:
    """End ``threads`` (their jobs' results unwanted): each worker serving one is killed, so the thread's
    :func:`run_isolated` returns (:class:`Abandoned`) instead of waiting on it; then each is joined, so no
    thread or worker outlives the failure (an API caller's process would keep them running)."""
    for thread in threads:
        with _SERVING_LOCK:
            if thread.ident is None:
                continue
            _ABANDONED.add(thread.ident)
            proc = _SERVING.get(thread.ident)
        if proc is not None:
            with contextlib.suppress(OSError):
                proc.kill()
    for thread in threads:
        thread.join()
        with _SERVING_LOCK:
            _ABANDONED.discard(thread.ident or 0)


def _die_with_parent(parent: int) -> None:
    """Make this forked child die with ``parent``, even when the parent is killed by SIGKILL.

    On Linux the kernel sends SIGKILL when the parent goes (``PR_SET_PDEATHSIG``); the parent may have died
    between the fork and this call, so the parent is looked at again after the signal is armed. The death
    signal fires when the forking *thread* ends: :class:`Background` is collected or cancelled by the thread
    that made it, which therefore outlives the child.
    """
    import signal
    import sys

    if sys.platform.startswith("linux"):
        import ctypes

        pr_set_pdeathsig = 1
        try:
            ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # no prctl in this libc: the getppid check below still holds
            pass
    if os.getppid() != parent:  # orphaned already: nobody will read the result
        os._exit(1)


def _detach_from_caller() -> None:
    """Let the caller's signals kill the child at once, and give its stdout/stderr back.

    The CLI's handlers (SIGTERM or SIGHUP raised as an exception) are copied by the fork; in the child the
    default action is right, since it holds no file to clean up. A signal the caller ignores stays ignored.
    The child's fds 1 and 2 go to /dev/null, so a caller reading this process's output to the end never
    waits for the child, and the parent's unflushed buffers copied by the fork are not printed twice.
    """
    import signal

    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        number = getattr(signal, name, None)
        if number is not None and callable(signal.getsignal(number)):
            signal.signal(number, signal.SIG_DFL)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in (1, 2):
            os.dup2(devnull, fd)
    finally:
        os.close(devnull)


def _child(jobs: list[Callable[[], dict[str, bytes]]], conn: Any, parent: int = 0, receiver: Any = None) -> None:
    try:
        if parent:
            _die_with_parent(parent)
        _detach_from_caller()
        if receiver is not None:
            # the fork copied the parent's end of the pipe: holding it, this child would block forever on a
            # full pipe once the parent is gone, instead of failing with EPIPE
            receiver.close()
        conn.send((True, _run_jobs(jobs)))
    except BaseException as exc:  # the parent redoes the work serially and raises there
        with contextlib.suppress(BaseException):  # the parent may be gone: nothing is left to tell
            conn.send((False, repr(exc)))
    finally:
        conn.close()


def can_fork() -> bool:
    """Whether :class:`Background` forks here: not where ``fork`` is unavailable, ``FABRICATE_SERIAL`` is set, or
    this process is a daemon (e.g. a Dask worker: daemons may not have children)."""
    if os.environ.get("FABRICATE_SERIAL") or "fork" not in multiprocessing.get_all_start_methods():
        return False
    return not multiprocessing.current_process().daemon


class Background:
    """Run jobs returning ``{path: bytes}`` in a forked child process while the caller goes on.

    Where ``fork`` is unavailable, or ``FABRICATE_SERIAL`` is set, or this process is a daemon (a Dask
    worker), or the child fails, the jobs run in the calling process when :meth:`result` is asked for, so
    the outcome never depends on it. Call :meth:`cancel` in a ``finally``: the child is killed and reaped
    however the caller ends; on Linux it also dies with its parent (a SIGKILL of the parent included) and
    never holds the parent's stdout or stderr.

    Parameters
    ----------
    jobs : list of callables
        Each returns ``{path: bytes}``; :meth:`result` merges them in this order.
    fork : bool
        False: no child, the jobs run when :meth:`result` is asked for (a job whose result is stored).
    hand_over : bool
        Whether the child takes the workers :func:`prestart` started (for the job that calls them); False
        keeps them for a later child.
    """

    def __init__(self, jobs: list[Callable[[], dict[str, bytes]]], *, fork: bool = True,
                 hand_over: bool = True) -> None:
        self.jobs = jobs
        self._process = None
        self._handed: list[Any] = []
        if not fork or not can_fork():
            return
        ctx = multiprocessing.get_context("fork")
        before = {id(proc) for proc in _HANDED}
        self._conn, sender = ctx.Pipe(duplex=False)
        self._process = ctx.Process(target=_child, args=(jobs, sender, os.getpid(), self._conn), daemon=True)
        _KEEP_WORKERS[0] = not hand_over
        # a stop signal (Ctrl-C) waits until the fork is done: its exception never lands in a fork hook (printed
        # with a traceback and dropped) nor leaves a child no one holds; the child is killed and reaped first
        try:
            with signals_deferred():
                try:
                    self._process.start()
                    # the workers this fork handed over are this child's: reaped with it, not with another child
                    self._handed = [proc for proc in _HANDED if id(proc) not in before]
                except OSError:  # no fork now (EAGAIN, ENOMEM): the jobs run here when asked for
                    self._process = None
                    self._conn.close()
                finally:
                    _KEEP_WORKERS[0] = False
                    sender.close()
        except BaseException:
            self.cancel()
            raise

    @property
    def forked(self) -> bool:
        """Whether a child runs the jobs (else :meth:`result` runs them here)."""
        return self._process is not None

    def result(self) -> dict[str, bytes]:
        if self._process is not None:
            try:
                ok, payload = self._conn.recv()
            except Exception:  # noqa: BLE001 - EOF (the child died), a broken or unreadable pickle: redo it here
                ok, payload = False, None
            self._conn.close()
            self._process.join()
            self._process = None
            # the child's workers (prestart) are this process's children: reaped here, so their time and memory
            # are the build's. The child is gone with every answer it asked for; a worker it did not use (a
            # cached result) need not finish its warm-up
            _reap_handed(kill=True, procs=self._handed)
            if ok:
                return payload
        return _run_jobs(self.jobs)

    def cancel(self) -> None:
        """Kill the child if its result was never collected (the build failed or was interrupted).

        SIGKILL, not SIGTERM: the child writes no file, so nothing is lost, and no handler it may have
        inherited can delay it.
        """
        if self._process is not None:
            if self._process.pid is not None:  # started (a stop may land before the fork)
                self._process.kill()
                self._process.join()
            self._conn.close()
            self._process = None
            _reap_handed(kill=True, procs=self._handed)


def _reap_handed(kill: bool, procs: list[Any] | None = None) -> None:
    """Wait for (or kill) the workers handed to a forked child (:func:`prestart`): ``procs`` (those handed to
    one child), or every one."""
    procs = list(_HANDED) if procs is None else list(procs)
    _HANDED[:] = [proc for proc in _HANDED if all(proc is not p for p in procs)]
    while procs:
        proc = procs.pop()
        if kill:
            with contextlib.suppress(OSError):
                proc.kill()
        proc.wait()


#: Started workers of :func:`run_isolated` waiting for a call, by module: ``(process, pid of its starter)``.
_WARM: dict[str, tuple[Any, int]] = {}
#: Workers handed to a forked child, kept here until they end (so they are reaped, not warned about).
_HANDED: list[Any] = []
#: Set while :class:`Background` forks a child that must not take the waiting workers.
_KEEP_WORKERS = [False]


def _start_worker(preload: str = "", warm_up: str = "") -> Any:
    """A fresh interpreter running :func:`_isolated_main` (pipes to and from it), or None if none starts."""
    import subprocess
    import sys
    from pathlib import Path

    root = str(Path(__file__).resolve().parents[1])
    code = (f"import sys; sys.path.insert(0, {root!r}); "
            f"from fabricate.background import _isolated_main; _isolated_main({preload!r}, {warm_up!r})")
    try:
        return subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL)
    except OSError:  # no process now (EAGAIN, ENOMEM)
        return None


def prestart(module: str, warm_up: str = "") -> None:
    """Start the worker of the next :func:`run_isolated` call into ``module`` now: it imports ``module`` and
    calls its ``warm_up()`` (e.g. importing OCP) on a core the caller leaves idle, then waits for the call.

    At most one waits per module and process. A fork hands it to the child (:class:`Background`'s, which
    makes the call): the parent lets go of it, so it is never used twice. Unused, it ends when every process
    holding its pipe has ended, or with the process that started it.
    """
    _HANDED[:] = [proc for proc in _HANDED if proc.poll() is None]
    entry = _WARM.get(module)
    if entry is not None and entry[1] == os.getpid() and entry[0].poll() is None:
        return
    proc = _start_worker(module, warm_up)
    if proc is not None:
        _WARM[module] = (proc, os.getpid())


def _hand_over() -> None:
    """After a fork, in the parent: the waiting workers are the child's now (their pipes closed here), unless
    that child was forked with ``hand_over=False``."""
    if _KEEP_WORKERS[0]:
        return
    for proc, _ in _WARM.values():
        for pipe in (proc.stdin, proc.stdout):
            with contextlib.suppress(OSError):
                pipe.close()
        _HANDED.append(proc)
    _WARM.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_parent=_hand_over)


def run_isolated(module: str, function: str, *args: Any) -> Any:
    """``module.function(*args)`` run in a fresh Python process; its result (arguments and result pickled).

    A forked child carries its parent's resident memory (every kernel's libraries, a build's arrays) on top
    of what it imports itself; a fresh interpreter holds only what the call imports. That keeps OCP (220 MB
    resident once imported) out of every process that holds the rest of a build. The worker
    :func:`prestart` started is used where there is one. The result is the call's own either way: where the
    process cannot start, dies or the call raises, it runs again here (and raises here, if it does).

    Parameters
    ----------
    module, function : str
        Where the function is (``"fabricate.export.step"``, ``"step_files"``): it must be importable by name
        in a new process; this copy of fabricate is put first on its path.
    *args
        Picklable arguments.
    """
    import importlib

    me = threading.get_ident()
    entry = _WARM.pop(module, None)
    for proc in ([entry[0]] if entry is not None else []) + [None]:
        if me in _ABANDONED:  # (the worker it had was killed for it): no other worker, no call here
            break
        proc = proc if proc is not None else _start_worker()
        if proc is None:
            break
        with _SERVING_LOCK:  # registered, or abandoned before it could be: never both unseen
            abandoned = me in _ABANDONED
            if not abandoned:
                _SERVING[me] = proc
        if abandoned:
            with contextlib.suppress(OSError):
                proc.kill()
            proc.wait()
            break
        try:
            ok, value = _call(proc, module, function, args)
        finally:
            with _SERVING_LOCK:
                _SERVING.pop(me, None)
        if ok:
            return value
        if ok is False:  # the call raised: it raises here too
            break
    if me in _ABANDONED:
        raise Abandoned(f"{module}.{function}: its result is no longer wanted")
    return getattr(importlib.import_module(module), function)(*args)


def _call(proc: Any, module: str, function: str, args: tuple[Any, ...]) -> tuple[bool | None, Any]:
    """One call through worker ``proc``: ``(True, result)``; ``(False, None)`` where the call raised; ``(None,
    None)`` where the worker was lost (gone, killed, or not the one this call was sent to)."""
    import pickle
    import struct

    nonce = os.urandom(8)  # its answer carries it: never another call's answer (a worker is used once)
    payload = pickle.dumps((nonce, module, function, args), protocol=pickle.HIGHEST_PROTOCOL)
    try:
        try:
            proc.stdin.write(struct.pack("<Q", len(payload)) + payload)
            proc.stdin.close()
            out = proc.stdout.read()
        finally:
            for pipe in (proc.stdin, proc.stdout):
                with contextlib.suppress(OSError):
                    pipe.close()
            proc.wait()  # after a fork: not this process's child (ECHILD), which Popen takes as ended
    except (OSError, ValueError):  # a worker gone (EPIPE) or its pipe closed: another one, or here
        return None, None
    except BaseException:  # a stop signal while waiting: nothing is left to wait for
        with contextlib.suppress(OSError):
            proc.kill()
        raise
    try:
        answer_nonce, ok, value = pickle.loads(out)
    except Exception:  # noqa: BLE001 - a truncated or unreadable answer (the worker died): redo it
        return None, None
    return (bool(ok), value) if answer_nonce == nonce else (None, None)


def _isolated_main(preload: str = "", warm_up: str = "") -> None:
    """The fresh process of :func:`run_isolated`: ``preload`` imported (and its ``warm_up()`` called), then
    one call from stdin (length-prefixed: its pipe may stay open in other processes), its answer to stdout."""
    import importlib
    import pickle
    import struct
    import sys

    _die_with_parent(os.getppid())
    if preload:
        with contextlib.suppress(Exception):  # a failing warm-up fails the call itself, where it is reported
            loaded = importlib.import_module(preload)
            if warm_up:
                getattr(loaded, warm_up)()
    head = sys.stdin.buffer.read(8)
    if len(head) < 8:  # every caller let go of it: nothing to do
        return
    payload = sys.stdin.buffer.read(struct.unpack("<Q", head)[0])
    nonce, module, function, args = pickle.loads(payload)
    try:
        answer = (nonce, True, getattr(importlib.import_module(module), function)(*args))
    except Exception as exc:  # noqa: BLE001 - the caller runs it again and raises there
        answer = (nonce, False, repr(exc))
    sys.stdout.buffer.write(pickle.dumps(answer, protocol=pickle.HIGHEST_PROTOCOL))
    sys.stdout.buffer.flush()
