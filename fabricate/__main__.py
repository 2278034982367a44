"""``python -m fabricate`` and the ``fabricate`` command (:func:`entry`)."""

from __future__ import annotations

import os
import sys
import threading


def entry() -> None:
    """Run :func:`fabricate.cli.main` as a program, then leave without tearing the interpreter down.

    A build leaves millions of objects (matplotlib's, the stages' results) that an ordinary exit frees one by
    one and walks with the garbage collector: ~0.2 s after the last file is written and the result printed,
    15 % of a cached rebuild. Once :func:`main` has returned, every file is written and closed, every child
    reaped and both streams flushed here, so nothing is left for that teardown to do. A process with other
    threads, or with Dask loaded (``sweep``: its client and cluster close in their own exit hooks), exits the
    ordinary way; so does an exception (argparse's ``--help`` and usage errors).
    """
    try:
        from fabricate.cli import main
    except KeyboardInterrupt:
        # Ctrl-C in the first ~50 ms, while the command line loads and before its own handlers are in place:
        # Python's default handler would print a traceback from the middle of an import
        sys.stderr.write("fabricate: interrupted; nothing was written (a previous output is unchanged)\n")
        sys.exit(130)
    code = main()
    if code > 128:
        # stopped by a signal: a library the stop interrupted midway can complain from a destructor or a garbage
        # collector's callback as the interpreter goes down (distributed's GC timer asserts from then on); the
        # run's outcome is told, and this process only exits now
        sys.unraisablehook = lambda _unraisable: None
    try:
        for stream in (sys.stdout, sys.stderr):  # None where the stream was not open at all
            if stream is not None:
                stream.flush()
    except (OSError, ValueError):  # a stream gone: the ordinary exit deals with it as it always did
        sys.exit(code)
    if threading.active_count() > 1 or "distributed" in sys.modules:
        sys.exit(code)
    os._exit(code)


if __name__ == "__main__":  # a spawned worker process (Dask, multiprocessing) may import this module
    entry()
