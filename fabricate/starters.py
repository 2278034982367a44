"""``fabricate init`` and ``fabricate coupon``: the files a user starts from (a copy of a design template or of a
process profile, and a calibration coupon with what to measure on it). Each takes the parsed command line and
returns the exit code; bad input is a :class:`~fabricate.errors.SpecError` (exit 2, nothing written).
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable
from pathlib import Path

from fabricate.errors import SpecError

EXIT_OK = 0


def init(args: argparse.Namespace) -> int:
    from fabricate.design import design_from_text
    from fabricate.templates import find_template, read_text

    if args.process is not None:
        return init_process(args)
    if args.output is not None:
        raise SpecError("-o", "names the profile copy of 'init --process'; a design copy is NAME.toml")
    if args.name is None:
        raise SpecError("NAME", "expected the new design's name (or --process to copy a process profile)")
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
    _write_new(target, text)
    print(f"wrote {target.name} (from {source.name}); build it with: fabricate build {target.name}")
    return EXIT_OK


def _write_new(target: Path, text: str) -> None:
    """Write ``text`` to a new file ``target``: ``init`` never overwrites one."""
    try:
        with open(target, "x", encoding="utf-8") as fh:
            fh.write(text)
    except FileExistsError as exc:
        raise SpecError(str(target), "exists already; init never overwrites a file") from exc
    except OSError as exc:
        raise SpecError(str(target), f"cannot be written: {exc.strerror}") from exc


def init_process(args: argparse.Namespace) -> int:
    """``init --process P [-o FILE]``: the shipped profile's text under a header saying how to use it."""
    from fabricate.coupon import profile_copy

    if args.name is not None:
        raise SpecError("NAME", "init --process writes a process profile: name its file with -o, not NAME")
    target = args.output if args.output is not None else Path(f"my_{args.process}.toml")
    text = profile_copy(args.process, target)
    _write_new(target, text)
    print(f"wrote {target} (from the shipped {args.process} profile); calibrate it with: fabricate coupon "
          f"--process {target}; build with: fabricate build TEMPLATE --process {target}")
    return EXIT_OK


def coupon(args: argparse.Namespace, say: Callable[[str], None]) -> int:
    from fabricate.coupon import coupon_files, coupon_process
    from fabricate.output import check_output_dir, write_output

    process = coupon_process(args.process, args.printer)
    target = args.output or Path("outputs") / f"coupon_{process.name}"
    protect = {} if args.process in shipped_profile_names() else {Path(args.process): "the process profile in use"}
    out = check_output_dir(target, force=args.force, protect=protect)
    files = coupon_files(process, str(args.process))
    write_output(files, out, force=args.force, protect=protect, warn=lambda msg: say(f"fabricate: warning: {msg}"))
    args.written = out
    print(f"coupon {process.name}: {', '.join(sorted(files))} -> {out} (README.md says what to measure)")
    return EXIT_OK


def shipped_profile_names() -> tuple[str, ...]:
    from fabricate.process import shipped_profiles

    return shipped_profiles()
