"""Command line: ``fabricate build|synth|check|list``.

Exit codes: 0 all checks pass; 1 the design fails a check (files are written, the report says why);
2 invalid input or usage (nothing is written).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from fabricate import __version__
from fabricate.errors import FabricateError, SpecError

DEFAULT_TEMPLATE = "finger_five_bar_ncg"
EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2


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
    b = sub.add_parser("build", help="the whole pipeline into an output directory")
    b.add_argument("template", nargs="?", default=DEFAULT_TEMPLATE,
                   help=f"template path or shipped name (default {DEFAULT_TEMPLATE})")
    b.add_argument("-o", "--output", type=Path, help="output directory (default outputs/<template name>/)")
    b.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    s = sub.add_parser("synth", help="synthesis only: report.json and plots")
    s.add_argument("template")
    s.add_argument("-o", "--output", type=Path)
    s.add_argument("-q", "--quiet", action="store_true")
    c = sub.add_parser("check", help="re-run the checks of a template or an output directory")
    c.add_argument("target", help="template, or a directory written by 'fabricate build'")
    c.add_argument("-q", "--quiet", action="store_true")
    sub.add_parser("list", help="templates shipped")
    return p


def _out_dir(args: argparse.Namespace, name: str) -> Path:
    return args.output if args.output is not None else Path("outputs") / name


def _summary(report: dict, out: Path | None) -> None:
    checks = report.get("checks", {})
    where = f" -> {out}" if out is not None else ""
    verdict = "passed" if checks.get("passed") else "FAILED"
    print(f"{report['design']['name']}: checks {verdict}{where}")
    for failure in checks.get("failures", []):
        print(f"  - {failure}")


def _check_directory(directory: Path, quiet: bool) -> int:
    """Re-run the checks of a build directory: its files are re-validated, its template rebuilt."""
    from fabricate.export.stl import validate_stl
    from fabricate.pipeline import run_build
    from fabricate.spec import TEMPLATE_DIR, load_design

    report_path = directory / "report.json"
    try:
        report = json.loads(report_path.read_text(encoding="utf-8"))
        template = report["design"]["template"]
    except (OSError, ValueError, KeyError) as exc:
        raise SpecError(str(report_path), f"not a fabricate output directory ({exc})") from exc
    problems: list[str] = []
    for rel in report.get("files", []):
        path = directory / rel
        if not path.is_file():
            problems.append(f"{rel}: missing")
        elif rel.endswith(".stl"):
            problems += [f"{rel}: {p}" for p in validate_stl(path.read_bytes())]
    candidates = [Path(template), TEMPLATE_DIR.parent / template]
    found = next((c for c in candidates if c.is_file()), None)
    if found is None:
        raise SpecError("design.template", f"template {template} of {directory} not found")
    outcome = run_build(load_design(found), _progress(quiet))
    failures = problems + list(outcome.report["checks"]["failures"])
    outcome.report["checks"] = {"passed": not failures, "failures": failures}
    _summary(outcome.report, None)
    return EXIT_OK if not failures else EXIT_FAILED


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from fabricate.pipeline import run_build, run_synth, write_atomically
    from fabricate.spec import load_design, shipped_templates

    try:
        if args.command == "list":
            from fabricate.spec import read_toml

            for path in shipped_templates():
                design = read_toml(path).get("design", {})
                print(f"{path.stem:28s} {design.get('kind', '?'):18s} {design.get('description', '')}")
            return EXIT_OK
        if args.command == "check":
            target = Path(args.target)
            if target.is_dir():
                return _check_directory(target, args.quiet)
            outcome = run_build(load_design(args.target), _progress(args.quiet))
            _summary(outcome.report, None)
            return outcome.exit_code
        design = load_design(args.template)
        runner = run_build if args.command == "build" else run_synth
        outcome = runner(design, _progress(args.quiet))
        out = _out_dir(args, design.name)
        write_atomically(outcome.files, out)
        if not args.quiet:
            _summary(outcome.report, out)
        return outcome.exit_code
    except FabricateError as exc:  # invalid input, nothing feasible, or a kernel failure: nothing written
        print(f"fabricate: error: {exc}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
