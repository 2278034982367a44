"""Command line: ``fabricate build|synth|check|sweep|list|init|coupon``.

Exit codes: 0 all checks pass; 1 the design fails a check (files are written, the report says why);
2 invalid input or usage (nothing is written); 3 an internal error (a bug: please report it with the
template); 128 + N stopped by signal N: 130 Ctrl-C (SIGINT), 143 SIGTERM, 129 SIGHUP (the previous output
is left as it was, no temporary folder and no child process is left).

However a run ends, it ends here with one line on stderr and an exit code, never a traceback: SIGTERM and
SIGHUP are raised as an exception like Ctrl-C's, so every ``finally`` runs (the picture child is killed,
a half-written folder removed); a reader that closed stdout (``fabricate list | head -1``) or a terminal
that went away is not an error, and the exit code stays the command's own.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import os
import signal
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, NoReturn, TextIO

from fabricate import __version__
from fabricate.cache import use_cache
from fabricate.errors import FabricateError, SpecError
from fabricate.stops import STOP_SIGNALS, Stopped, stop_on_signals

DEFAULT_TEMPLATE = "finger_five_bar_ncg"
EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
HELP_EPILOG = ("exit codes: 0 every check passed; 1 the design fails a check (files are written, the report says "
               "why) or 'check' found a problem; 2 invalid input or usage (nothing is written); 3 a bug in "
               "fabricate (please report it); 130 Ctrl-C, 143 SIGTERM, 129 SIGHUP (128 + the signal: a previous "
               "output is left as it was, nothing half-written). -q hides progress only: the result line and "
               "any failures are always printed.")


class _Stream:
    """A text stream that goes quiet once it cannot be written (its reader closed the pipe, its terminal
    went away): delivering the result line is not worth failing a run that did its work for.

    Attributes
    ----------
    error : OSError or None
        The first write error that was not a reader going away (EPIPE) or a terminal hanging up (EIO).
    """

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self.gone = False
        self.error: OSError | None = None

    def _lost(self, exc: Exception) -> None:
        self.gone = True
        if isinstance(exc, OSError) and exc.errno not in (errno.EPIPE, errno.EIO, None):
            self.error = exc
        # Python flushes the stream once more at exit, and native code may write to the fd: both now land
        # in /dev/null instead of failing again (the recipe of Python's signal module documentation)
        with contextlib.suppress(Exception):
            fd = self._stream.fileno()
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, fd)
            os.close(devnull)

    def write(self, text: str) -> int:
        if not self.gone:
            try:
                try:
                    return self._stream.write(text)
                except UnicodeEncodeError:  # a file name that is not text (b"\xff"): shown escaped, no crash
                    encoding = getattr(self._stream, "encoding", None) or "utf-8"
                    return self._stream.write(text.encode(encoding, "backslashreplace").decode(encoding, "replace"))
            except OSError as exc:
                self._lost(exc)
            except ValueError as exc:
                if not getattr(self._stream, "closed", False):
                    raise
                self._lost(exc)  # the stream was closed
        return len(text)

    def flush(self) -> None:
        if not self.gone:
            try:
                self._stream.flush()
            except OSError as exc:
                self._lost(exc)
            except ValueError as exc:
                if not getattr(self._stream, "closed", False):
                    raise
                self._lost(exc)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


@contextlib.contextmanager
def _guarded_streams() -> Iterator[tuple[_Stream | None, _Stream | None]]:
    """sys.stdout and sys.stderr as :class:`_Stream` while the command runs; flushed before they go back."""
    saved = sys.stdout, sys.stderr
    out = _Stream(saved[0]) if saved[0] is not None else None
    err = _Stream(saved[1]) if saved[1] is not None else None
    if out is not None:
        sys.stdout = out  # type: ignore[assignment]
    if err is not None:
        sys.stderr = err  # type: ignore[assignment]
    try:
        yield out, err
    finally:
        for stream in (out, err):
            if stream is not None:
                stream.flush()
        sys.stdout, sys.stderr = saved


def _say(line: str) -> None:
    """One line on stderr: control characters of user text (a newline in a path) would make it several."""
    line = line.replace("\r", "\\r").replace("\n", "\\n")
    if sys.stderr is None:  # started with fd 2 closed (print would fall back to stdout)
        return
    with contextlib.suppress(Exception):  # stderr may be gone: the exit code still tells
        print(line, file=sys.stderr, flush=True)


QUIET_HELP = "no progress output (the result line and any failures are still printed)"
NO_CACHE_HELP = ("compute every stage afresh: neither read nor write the stage cache ($FABRICATE_CACHE_DIR, else "
                 "~/.cache/fabricate; $FABRICATE_NO_CACHE=1 turns it off everywhere; 'check' never uses it)")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # argparse exits 2 already; keep its message short
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"fabricate: error: {message}\n")


def _progress(quiet: bool, received: list[int]) -> Callable[[str], None]:
    """The stage callback: a progress line on a terminal (none with ``-q``), and a stop that was swallowed.

    A stop signal's :class:`Stopped` can be caught on its way by a library that catches BaseException (trimesh
    does, its mesh visuals' code included): the signal is still in ``received``, so the run stops at the next
    stage instead of finishing as if nothing was asked (a Ctrl-C test failed so in two suite runs of 2026-11-26)."""
    start = time.perf_counter()
    show = not (quiet or sys.stderr is None or not sys.stderr.isatty())

    def report(msg: str) -> None:
        if received:
            raise Stopped(received[0])
        if show:
            with contextlib.suppress(OSError, ValueError):  # a terminal gone ends the progress, not the run
                print(f"[{time.perf_counter() - start:6.2f} s] {msg}", file=sys.stderr, flush=True)

    return report


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="fabricate", description="Turn a template into a prototype to make: fabricate "
                                              "build|synth|check|sweep|list|init|coupon.", epilog=HELP_EPILOG)
    p.add_argument("--version", action="version", version=f"fabricate {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    b = sub.add_parser("build", help="the whole pipeline into an output folder")
    b.add_argument("template", nargs="?", default=DEFAULT_TEMPLATE,
                   help=f"template path or shipped name (default {DEFAULT_TEMPLATE})")
    b.add_argument("--no-pictures", action="store_true",
                   help="draw no pictures or plots (quicker, to iterate on the parts; the other files are the same)")
    s = sub.add_parser("synth", help="synthesis only: report.json and plots")
    s.add_argument("template")
    for cmd, default in ((b, "outputs/<design name>/"), (s, "outputs/<design name>-synth/")):
        cmd.add_argument("-o", "--output", type=Path,
                         help=f"output folder (default {default}): new, empty, or a previous fabricate output")
        cmd.add_argument("--force", action="store_true",
                         help="replace an output folder that holds files fabricate did not write")
        cmd.add_argument("-q", "--quiet", action="store_true", help=QUIET_HELP)
        cmd.add_argument("--no-cache", action="store_true", help=NO_CACHE_HELP)
    c = sub.add_parser("check", help="verify an output folder (files, contents, rebuild) or check a template")
    c.add_argument("target", help="template, or a folder written by 'fabricate build'")
    c.add_argument("-q", "--quiet", action="store_true", help=QUIET_HELP)
    for cmd in (b, s, c):
        cmd.add_argument("--process", metavar="sla|laser|PATH",
                         help="make it with this process profile instead of the template's (the template's "
                              "pin diameter is kept)")
        cmd.add_argument("--printer", metavar="NAME",
                         help="print on this printer preset (prusa_sl1s, prusa_mk4, ...: fabricate/catalogue/"
                              "printers.py): its build volume replaces the profile's and the template's")
    w = sub.add_parser("sweep", help="many designs from one template on Dask: tables, plots, the best built",
                       description="Run a design-space sweep: a spec (TOML with [sweep], [vary], [set]) or a "
                                   "template with --vary. Writes sweep.csv, sweep.parquet, plots/ and best/.")
    w.add_argument("spec", help="sweep spec (path or shipped name) or a design template (then --vary)")
    w.add_argument("--vary", action="append", default=[], metavar="FIELD=VALUES",
                   help="vary a template field: FIELD=start:stop:count, FIELD=a,b,c or FIELD='[[...], ...]' "
                        "(repeatable; adds to or replaces the spec's [vary])")
    w.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                   help="change a template field for every point (repeatable)")
    w.add_argument("--sampling", choices=("grid", "lhs", "sobol"))
    w.add_argument("--samples", type=int, help="points of an lhs or sobol sweep")
    w.add_argument("--seed", type=int, help="seed of the lhs/sobol sampler")
    w.add_argument("--stage", choices=("synth", "build"), help="synthesis only, or the whole build")
    w.add_argument("--metric", action="append", default=[], metavar="KEY.PATH",
                   help="a report.json key path to collect, e.g. synthesis.pose_error_mm.max or "
                        "'min(strength.parts[*].min_safety_factor)' (repeatable; replaces the spec's)")
    w.add_argument("--best", type=int, help="build this many of the best passing points in full")
    where = w.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help="processes of the local Dask cluster (default: the cores)")
    where.add_argument("--scheduler", metavar="ADDR", help="an existing Dask scheduler, e.g. tcp://host:8786")
    w.add_argument("-o", "--output", type=Path, help="output folder (default outputs/<name>-sweep/): new, empty, "
                                                     "or an earlier run of the same sweep, which is resumed")
    w.add_argument("-q", "--quiet", action="store_true", help=QUIET_HELP)
    w.add_argument("--no-cache", action="store_true", help=NO_CACHE_HELP)
    sub.add_parser("list", help="templates shipped")
    i = sub.add_parser("init", help="write an editable copy of a shipped template (or, with --process, of a "
                                     "process profile) into the current folder")
    i.add_argument("name", nargs="?", help="name of the new design (writes NAME.toml)")
    i.add_argument("--from", dest="source", default=DEFAULT_TEMPLATE,
                   help=f"template to copy (default {DEFAULT_TEMPLATE})")
    i.add_argument("--process", metavar="sla|fdm|laser",
                   help="copy this shipped process profile instead (default file my_<process>.toml); edit it "
                        "and build with --process FILE")
    i.add_argument("-o", "--output", type=Path, help="the profile copy's file (with --process)")
    k = sub.add_parser("coupon", help="a calibration coupon for a process: pin holes press to loose, a rack at "
                                      "the process's module, a kerf comb for a laser; README.md says what to "
                                      "measure and which profile field it sets")
    k.add_argument("--process", required=True, metavar="sla|fdm|laser|PATH",
                   help="the process profile (a shipped name or a profile file, e.g. one 'init --process' wrote)")
    k.add_argument("--printer", metavar="NAME", help="print on this printer preset (the coupon must fit it)")
    k.add_argument("-o", "--output", type=Path,
                   help="output folder (default outputs/coupon_<process>/): new or empty")
    k.add_argument("--force", action="store_true", help="replace an output folder that holds other files")
    return p


def _summary(report: dict, out: Path | None, failures: list[str] | None = None) -> None:
    """The result line (``NAME: checks passed -> DIR``, with what was not checked in brackets), the
    failures and notes; each check that could not run is also a note on stderr."""
    from fabricate.report import not_checked_notes, verdict

    checks = report.get("checks", {})
    failures = list(checks.get("failures", [])) if failures is None else failures
    where = f" -> {out}" if out is not None else ""
    print(f"{report['design']['name']}: {verdict(report, failures)}{where}")
    for failure in failures:
        print(f"  - {failure}")
    for note in report.get("notes", []):
        print(f"  note: {note}")
    if report.get("design", {}).get("stage") != "synth":  # synth: its line says no check ran
        for note in not_checked_notes(report):
            print(f"fabricate: note: {note}", file=sys.stderr)


def _output_holding(path: Path) -> Path | None:
    """The nearest of ``path`` and its parents that is a fabricate output folder (it has our report.json)."""
    from fabricate.output_read import previous_output

    for folder in (path, *path.parents):
        if previous_output(folder) is not None:
            return folder
    return None


def _default_output(name: str, template: Path, stage: str) -> Path:
    """The output folder when no ``-o`` is given: ``outputs/<name>/`` (``-synth`` for synth) under the current
    folder, or, for a template inside a fabricate output (a build's ``mechanism.toml``), ``<that folder>-rebuild``
    beside it (said on stderr, even with ``-q``: it is where the result goes): the default must neither hold
    the template (refused) nor nest a build inside a build.

    Raises
    ------
    SpecError
        The default would land inside a fabricate output folder (the current folder is in one).
    """
    suffix = "" if stage == "build" else "-synth"
    home = _output_holding(template.resolve().parent)
    if home is not None:
        default = home.parent / f"{home.name}-rebuild{suffix}"
        _say(f"fabricate: {template.name} is inside the output folder {home}: building into {default} "
             "beside it (-o chooses another folder)")
    else:
        default = Path("outputs") / f"{name}{suffix}"
    inside = _output_holding(Path(os.path.abspath(default)).parent)
    if inside is not None:
        beside = inside.parent / f"{name}{suffix}"
        beside = beside if beside != inside else inside.parent / f"{name}-2{suffix}"
        raise SpecError(f"the default output folder {default}", f"would be written inside {inside}, a fabricate "
                                                                "output folder, and become part of it; choose a "
                                                                f"folder outside it with -o (e.g. -o {beside})")
    return default


def _build(args: argparse.Namespace) -> int:
    from fabricate.bounds import roomy_heap
    from fabricate.design import load_design
    from fabricate.output import check_output_dir, write_output
    from fabricate.pipeline import run_build, run_synth
    from fabricate.process import shipped_profiles

    design = load_design(args.template, args.process, args.printer)
    stage = args.command
    target = args.output or _default_output(design.name, Path(design.template), stage)
    # inputs the build reads: never inside the folder replaced, even with --force
    protect = {Path(design.template): "the template being built"}
    if args.process and args.process not in shipped_profiles():
        protect[Path(args.process)] = "the process profile in use"
    # refuse a bad output folder before the work, and again under the lock when writing
    out = check_output_dir(target, force=args.force, stage=stage, protect=protect)
    roomy_heap()  # this process is the build's: fewer page faults (fabricate.bounds.ROOMY_HEAP)
    with use_cache(not args.no_cache):  # stage results reused across runs (fabricate/cache.py)
        progress = _progress(args.quiet, args.received)
        outcome = run_build(design, progress, pictures=not args.no_pictures) if stage == "build" else \
            run_synth(design, progress)
    if args.received:  # never write a result the user stopped (see _progress)
        raise Stopped(args.received[0])
    write_output(outcome.files, out, force=args.force, stage=stage, protect=protect,
                 warn=lambda msg: _say(f"fabricate: warning: {msg}"))
    args.written = out  # an interruption from here on comes after a complete write
    _summary(outcome.report, out)  # -q hides progress, never the result
    return outcome.exit_code


def _check(args: argparse.Namespace) -> int:
    from fabricate.design import load_design
    from fabricate.pipeline import run_build
    from fabricate.templates import find_template, path_kind

    target = Path(args.target)
    path_kind(target, "TARGET")  # a name the system refuses to look at (too long) is exit 2, not an OSError
    if not target.is_dir():
        if not os.path.lexists(target):
            try:
                find_template(args.target)  # a shipped template's name
            except SpecError:
                raise SpecError(args.target, "no such folder or template: 'check' takes a folder written by "
                                             "'fabricate build' or a template (a file, or a name from "
                                             "'fabricate list'), and neither exists") from None
        with use_cache(False):  # check never reads or writes the stage cache: its verdict is a fresh build
            design = load_design(args.target, args.process, args.printer)
            outcome = run_build(design, _progress(args.quiet, args.received))
        _summary(outcome.report, None)
        return outcome.exit_code
    from fabricate.verify import verify_output

    if args.process:
        raise SpecError("--process", "a folder is checked with the process it was built with (see its report)")
    if args.printer:
        raise SpecError("--printer", "a folder is checked with the printer it was built for (see its report)")

    with use_cache(False):
        problems, report = verify_output(target, _progress(args.quiet, args.received))
    if report is None:
        print(f"{target}: FAILED")
        for problem in problems:
            print(f"  - {problem}")
        return EXIT_FAILED
    failures = problems + list(report.get("checks", {}).get("failures", []))
    _summary(report, None, failures)
    return EXIT_OK if not failures else EXIT_FAILED


def _sweep(args: argparse.Namespace) -> int:
    from fabricate.sweep.spec import assignments, find_sweep, sweep_from_tables
    from fabricate.templates import parse_toml, read_text

    source = find_sweep(args.spec)
    if source is not None:
        tables = parse_toml(read_text(source), str(source))
        base_dir: Path | None = source.parent
    else:
        tables = {"sweep": {"template": args.spec}}
        base_dir = None
    tables = {k: dict(v) if isinstance(v, dict) else v for k, v in tables.items()}
    sweep = tables.setdefault("sweep", {})
    given = {"vary": assignments(args.vary, "--vary", True), "set": assignments(args.set or [], "--set", False)}
    for table, entries in given.items():
        if entries:
            if not isinstance(tables.setdefault(table, {}), dict):
                raise SpecError(table, "expected a table of field path = value")
            tables[table].update(entries)
    if not isinstance(sweep, dict):
        raise SpecError("sweep", "missing table [sweep]")
    # an error in an entry given on the command line ends "(given as --vary FIELD)"
    origins = {f"{table}.{key}": f"--{table} {key}" for table, entries in given.items() for key in entries}
    for key in ("sampling", "samples", "seed", "stage", "best"):
        if getattr(args, key) is not None:
            sweep[key] = getattr(args, key)
    if args.metric:
        sweep["metrics"] = list(args.metric)
    if args.workers is not None:  # local processes: the cores and the memory bound them
        from fabricate.bounds import check_workers

        check_workers(args.workers)
    spec = sweep_from_tables(tables, base_dir, origins=origins)
    from fabricate.sweep.runner import run_sweep

    out = args.output or Path("outputs") / f"{spec.name}-sweep"
    # the inputs (spec file, base template) are never inside the sweep's folder (as sweep_from_tables finds them)
    from fabricate.templates import find_template

    near = base_dir / spec.template if base_dir is not None else None
    template = near if near is not None and near.is_file() else find_template(spec.template)
    protect = [template] if source is None else [source, template]
    with use_cache(not args.no_cache):
        outcome = run_sweep(spec, out, workers=args.workers, scheduler=args.scheduler, quiet=args.quiet,
                            protect=protect)
    if outcome.exit_code == EXIT_INTERRUPTED:
        signum = args.received[0] if getattr(args, "received", None) else signal.SIGINT
        _say(f"fabricate: {STOP_SIGNALS[signal.Signals(signum).name]}; {outcome.done} of {outcome.total} points are "
             f"recorded in {outcome.out} (run the same command again to resume)")
        return 128 + signum
    # -q hides progress, never the result
    c = outcome.counts
    errors = f", {c['3']} internal errors" if c.get("3") else ""
    print(f"sweep {spec.name}: {outcome.total} points ({outcome.resumed} done earlier): {c.get('0', 0)} pass, "
          f"{c.get('1', 0)} fail a check, {c.get('2', 0)} invalid or infeasible{errors} -> {outcome.out}")
    for note in outcome.notes:
        print(f"  note: {note}")
    for entry in outcome.best:
        metric = spec.best_metric.name if spec.best_metric else ""
        verdict = {0: "", 1: " (its full build fails a check: see its report)"}.get(
            entry.get("build_exit_code", 0), f" (not built: {entry.get('build_reason', '')})")
        print(f"  best {entry['rank']}: point {entry['point']} {metric} = {entry.get(metric)!r} "
              f"-> {entry.get('folder', '')}{verdict}")
    return outcome.exit_code


def _list() -> int:
    from fabricate.templates import read_toml, shipped_templates

    for path in shipped_templates():
        design = read_toml(path).get("design", {})
        print(f"{path.stem:28s} {design.get('kind', '?'):18s} {design.get('description', '')}")
    from fabricate.templates import TEMPLATE_DIR

    for path in sorted((TEMPLATE_DIR / "sweeps").glob("*.toml")):
        sweep = read_toml(path).get("sweep", {})
        print(f"{path.stem:28s} {'sweep':18s} fabricate sweep {path.stem} ({sweep.get('template', '?')}, "
              f"stage {sweep.get('stage', 'synth')})")
    return EXIT_OK


def _text(exc: BaseException) -> str:
    try:
        return str(exc)
    except Exception:  # noqa: BLE001 - an exception that cannot describe itself is still reported
        return repr(type(exc))


def _stopped(args: argparse.Namespace | None, signum: int) -> str:
    """The last line of a run stopped by a signal: which signal, and what was written."""
    what = STOP_SIGNALS.get(signal.Signals(signum).name, signal.Signals(signum).name)
    written = getattr(args, "written", None)
    if written is not None:
        return f"fabricate: {what} after {written} was written (it is complete)"
    return f"fabricate: {what}; nothing was written (a previous output is unchanged)"


def _out_of_memory(args: argparse.Namespace | None) -> tuple[str, int]:
    command = getattr(args, "command", None)
    # the folder's files, not a template, took it
    if command == "check" and args is not None and Path(args.target).is_dir():
        return f"fabricate: error: out of memory while checking {args.target} (the folder was not verified)", \
            EXIT_FAILED
    if command == "sweep":
        return ("fabricate: error: out of memory; the sweep asks for more than this machine has (fewer --workers, "
                "or see the bounds in README.md)"), EXIT_USAGE
    return ("fabricate: error: out of memory; a count or tolerance in the template asks for more than this "
            "machine has (see the bounds in README.md)"), EXIT_USAGE


def _run(argv: list[str] | None, received: list[int]) -> int:
    args = None
    try:
        args = _parser().parse_args(argv)
        args.received = received
        if args.command == "list":
            return _list()
        if args.command == "init":
            from fabricate.starters import init

            return init(args)
        if args.command == "coupon":
            from fabricate.starters import coupon

            return coupon(args, _say)
        if args.command == "check":
            return _check(args)
        if args.command == "sweep":
            return _sweep(args)
        return _build(args)
    except FabricateError as exc:  # invalid input, nothing feasible, a refused folder: nothing written
        _say(f"fabricate: error: {_text(exc)}")
        return EXIT_USAGE
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM / SIGHUP raised as Stopped
        signum = getattr(exc, "signum", signal.SIGINT)
        _say(_stopped(args, signum))
        return 128 + signum
    except MemoryError:
        line, code = _out_of_memory(args)
        _say(line)
        return code
    except Exception as exc:  # noqa: BLE001 - the last line of defence: one line, never a traceback
        _say(f"fabricate: internal error: {type(exc).__name__}: {_text(exc)} (a bug in fabricate {__version__}; "
             "please report it with the template)")
        return EXIT_INTERNAL


def main(argv: list[str] | None = None) -> int:
    """Run one command; its exit code is returned (see the module docstring), one line on stderr at most
    for an error, never a traceback. Only argparse's SystemExit (``--help``, ``--version``, a usage error)
    leaves by an exception."""
    with _guarded_streams() as (out, _err), stop_on_signals() as received:
        code = _run(argv, received)
        if received and code != 128 + received[0]:
            # the signal's exception was swallowed on its way (it hit a destructor): the run ended anyway
            _say(f"fabricate: {STOP_SIGNALS[signal.Signals(received[0]).name]} as the run ended (its result "
                 "is complete)")
            return 128 + received[0]
        if out is not None:
            out.flush()
            if out.error is not None:  # a full disk under '> file'; a closed pipe or terminal is not an error
                _say(f"fabricate: error: cannot write to standard output: {out.error.strerror or out.error}")
                return max(code, EXIT_USAGE)
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
