"""Command line: ``fabricate build|synth|check|sweep|list|init``.

Exit codes: 0 all checks pass; 1 the design fails a check (files are written, the report says why);
2 invalid input or usage (nothing is written); 3 an internal error (a bug: please report it with the
template); 130 interrupted (Ctrl-C; the previous output is left as it was).
"""

from __future__ import annotations

import argparse
import re
import sys
import time
from pathlib import Path
from typing import Any

from fabricate import __version__
from fabricate.errors import FabricateError, SpecError

DEFAULT_TEMPLATE = "finger_five_bar_ncg"
EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 1, 2, 3, 130


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # argparse exits 2 already; keep its message short
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"fabricate: error: {message}\n")


def _progress(quiet: bool):
    start = time.perf_counter()
    if quiet or not sys.stderr.isatty():
        return lambda _msg: None

    def report(msg: str) -> None:
        print(f"[{time.perf_counter() - start:6.2f} s] {msg}", file=sys.stderr, flush=True)

    return report


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="fabricate", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"fabricate {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    b = sub.add_parser("build", help="the whole pipeline into an output folder")
    b.add_argument("template", nargs="?", default=DEFAULT_TEMPLATE,
                   help=f"template path or shipped name (default {DEFAULT_TEMPLATE})")
    s = sub.add_parser("synth", help="synthesis only: report.json and plots")
    s.add_argument("template")
    for cmd, default in ((b, "outputs/<design name>/"), (s, "outputs/<design name>-synth/")):
        cmd.add_argument("-o", "--output", type=Path,
                         help=f"output folder (default {default}): new, empty, or a previous fabricate output")
        cmd.add_argument("--force", action="store_true",
                         help="replace an output folder that holds files fabricate did not write")
        cmd.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    c = sub.add_parser("check", help="verify an output folder (files, contents, rebuild) or check a template")
    c.add_argument("target", help="template, or a folder written by 'fabricate build'")
    c.add_argument("-q", "--quiet", action="store_true")
    for cmd in (b, s, c):
        cmd.add_argument("--process", metavar="sla|laser|PATH",
                         help="make it with this process profile instead of the template's (the template's "
                              "pin diameter is kept)")
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
    w.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    sub.add_parser("list", help="templates shipped")
    i = sub.add_parser("init", help="write an editable copy of a shipped template into the current folder")
    i.add_argument("name", help="name of the new design (writes NAME.toml)")
    i.add_argument("--from", dest="source", default=DEFAULT_TEMPLATE,
                   help=f"template to copy (default {DEFAULT_TEMPLATE})")
    return p


def _summary(report: dict, out: Path | None, failures: list[str] | None = None) -> None:
    checks = report.get("checks", {})
    failures = list(checks.get("failures", [])) if failures is None else failures
    where = f" -> {out}" if out is not None else ""
    print(f"{report['design']['name']}: checks {'passed' if not failures else 'FAILED'}{where}")
    for failure in failures:
        print(f"  - {failure}")
    for note in report.get("notes", []):
        print(f"  note: {note}")


def _build(args: argparse.Namespace) -> int:
    from fabricate.output import check_output_dir, write_output
    from fabricate.pipeline import run_build, run_synth
    from fabricate.spec import load_design

    design = load_design(args.template, args.process)
    stage = args.command
    default = Path("outputs") / (design.name if stage == "build" else f"{design.name}-synth")
    protect = [design.template]
    # refuse a bad output folder before the work, and again under the lock when writing
    out = check_output_dir(args.output or default, force=args.force, stage=stage, protect=protect)
    outcome = (run_build if stage == "build" else run_synth)(design, _progress(args.quiet))
    write_output(outcome.files, out, force=args.force, stage=stage, protect=protect)
    if not args.quiet:
        _summary(outcome.report, out)
    return outcome.exit_code


def _check(args: argparse.Namespace) -> int:
    from fabricate.pipeline import run_build
    from fabricate.spec import load_design

    target = Path(args.target)
    if not target.is_dir():
        outcome = run_build(load_design(args.target, args.process), _progress(args.quiet))
        _summary(outcome.report, None)
        return outcome.exit_code
    from fabricate.verify import verify_output

    if args.process:
        raise SpecError("--process", "a folder is checked with the process it was built with (see its report)")

    problems, report = verify_output(target, _progress(args.quiet))
    if report is None:
        print(f"{target}: FAILED")
        for problem in problems:
            print(f"  - {problem}")
        return EXIT_FAILED
    failures = problems + list(report.get("checks", {}).get("failures", []))
    _summary(report, None, failures)
    return EXIT_OK if not failures else EXIT_FAILED


def _value(text: str, where: str, many: bool) -> Any:
    """A command-line value: TOML (``[1, 2]``, ``0.5``, ``"x"``), else ``a,b,c`` or a bare word."""
    from fabricate.spec import parse_toml

    try:
        return parse_toml(f"v = {text}", where)["v"]
    except SpecError:
        pass
    if many and ":" not in text and "," in text:
        return [_value(part.strip(), where, False) for part in text.split(",")]
    return text


def _assignments(items: list[str], flag: str, many: bool) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip() or not text.strip():
            raise SpecError(flag, f'expected FIELD=VALUE{"S" if many else ""}, got "{item}"')
        value = _value(text.strip(), f"{flag} {key.strip()}", many)
        if many and not isinstance(value, list) and not (isinstance(value, str) and ":" in value):
            value = [value]
        out[key.strip()] = value
    return out


def _sweep(args: argparse.Namespace) -> int:
    from fabricate.spec import parse_toml, read_text
    from fabricate.sweep.spec import find_sweep, sweep_from_tables

    source = find_sweep(args.spec)
    if source is not None:
        tables = parse_toml(read_text(source), str(source))
        base_dir: Path | None = source.parent
    else:
        tables = {"sweep": {"template": args.spec}}
        base_dir = None
    tables = {k: dict(v) if isinstance(v, dict) else v for k, v in tables.items()}
    sweep = tables.setdefault("sweep", {})
    tables.setdefault("vary", {}).update(_assignments(args.vary, "--vary", True))
    if args.set:
        tables.setdefault("set", {}).update(_assignments(args.set, "--set", False))
    for key in ("sampling", "samples", "seed", "stage", "best"):
        if getattr(args, key) is not None:
            sweep[key] = getattr(args, key)
    if args.metric:
        sweep["metrics"] = list(args.metric)
    if args.workers is not None and not 1 <= args.workers <= 512:
        raise SpecError("--workers", f"expected 1 .. 512 processes, got {args.workers}")
    spec = sweep_from_tables(tables, base_dir)
    from fabricate.sweep.runner import run_sweep

    out = args.output or Path("outputs") / f"{spec.name}-sweep"
    outcome = run_sweep(spec, out, workers=args.workers, scheduler=args.scheduler, quiet=args.quiet)
    if outcome.exit_code == EXIT_INTERRUPTED:
        print(f"fabricate: interrupted; {outcome.done} of {outcome.total} points are recorded in {outcome.out} "
              "(run the same command again to resume)", file=sys.stderr)
        return EXIT_INTERRUPTED
    if not args.quiet:
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
    from fabricate.spec import read_toml, shipped_templates

    for path in shipped_templates():
        design = read_toml(path).get("design", {})
        print(f"{path.stem:28s} {design.get('kind', '?'):18s} {design.get('description', '')}")
    from fabricate.spec import TEMPLATE_DIR

    for path in sorted((TEMPLATE_DIR / "sweeps").glob("*.toml")):
        sweep = read_toml(path).get("sweep", {})
        print(f"{path.stem:28s} {'sweep':18s} fabricate sweep {path.stem} ({sweep.get('template', '?')}, "
              f"stage {sweep.get('stage', 'synth')})")
    return EXIT_OK


def _init(args: argparse.Namespace) -> int:
    from fabricate.spec import design_from_text, find_template, read_text

    name = args.name[:-5] if args.name.endswith(".toml") else args.name
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}", name):
        raise SpecError("NAME", f"expected a plain design name (letters, digits, _ . -), got \"{args.name}\"")
    source = find_template(args.source)
    text = read_text(source)
    # the copy's [design] name is the new name, so its default output folder is its own
    text, count = re.subn(r'(?ms)^(\[design\][^\[]*?^\s*name\s*=\s*)("[^"\n]*"|\'[^\'\n]*\')',
                          lambda m: f'{m.group(1)}"{name}"', text, count=1)
    if count != 1:
        raise SpecError(str(source), "has no [design] name to replace")
    target = Path.cwd() / f"{name}.toml"
    design_from_text(text, target)  # the copy must be a valid template before it is written
    try:
        with open(target, "x", encoding="utf-8") as fh:
            fh.write(text)
    except FileExistsError as exc:
        raise SpecError(str(target), "exists already; init never overwrites a file") from exc
    except OSError as exc:
        raise SpecError(str(target), f"cannot be written: {exc.strerror}") from exc
    print(f"wrote {target.name} (from {source.name}); build it with: fabricate build {target.name}")
    return EXIT_OK


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "list":
            return _list()
        if args.command == "init":
            return _init(args)
        if args.command == "check":
            return _check(args)
        if args.command == "sweep":
            return _sweep(args)
        return _build(args)
    except FabricateError as exc:  # invalid input, nothing feasible, a refused folder: nothing written
        print(f"fabricate: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("fabricate: interrupted; nothing was written (a previous output is unchanged)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except MemoryError:
        print("fabricate: error: out of memory; a count or tolerance in the template asks for more than this "
              "machine has (see the bounds in README.md)", file=sys.stderr)
        return EXIT_USAGE
    except Exception as exc:  # noqa: BLE001 - the last line of defence: one line, never a traceback
        print(f"fabricate: internal error: {type(exc).__name__}: {exc} (a bug in fabricate {__version__}; "
              "please report it with the template)", file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
