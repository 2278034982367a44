"""Template files: where the shipped ones live, and reading and parsing any one of them.

A template (a design, or a process profile ``process_<name>.toml``) is a UTF-8 TOML file of at most
:data:`MAX_TEMPLATE_BYTES`. Every failure to find, read or parse one is a :class:`~fabricate.errors.SpecError`
naming the file (and the line, for TOML syntax); nothing here validates fields (that is
:class:`fabricate.table.Table`'s job) and nothing here writes files.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def _template_dir() -> Path:
    # A wheel carries the repository's templates/ as fabricate/templates (setup.py maps it there); a
    # source checkout or an editable install reads the one copy at the repository's top level.
    package = Path(__file__).resolve().parent
    inside = package / "templates"
    return inside if inside.is_dir() else package.parent / "templates"


#: Folder of the shipped templates and process profiles.
TEMPLATE_DIR = _template_dir()

#: Largest template file read (a design template is a few kB; this keeps a stray binary out of memory).
MAX_TEMPLATE_BYTES = 1_000_000


def path_kind(path: str | Path, what: str = "") -> str:
    """``"file"`` (a regular file, after links), ``"other"`` (a folder, FIFO, device...) or ``"missing"``.

    A path the system refuses to look at (a name too long, a NUL, no permission) is a :class:`SpecError`
    naming ``what`` (the argument) rather than an ``OSError``: it is the user's input, not fabricate's fault.
    """
    try:
        path = Path(path)
        if path.is_file():
            return "file"
        return "other" if path.exists() else "missing"
    except (TypeError, ValueError) as exc:  # a NUL in the name; a value that is no path at all
        raise SpecError(what, f"not a usable path: {exc}") from None
    except OSError as exc:
        raise SpecError(what, f"cannot look at {str(path)[:80]!r}: {exc.strerror}") from None


def find_template(name_or_path: str | Path) -> Path:
    """Resolve a template argument: an existing path, or a shipped template's name (with or without .toml)."""
    if not isinstance(name_or_path, (str, Path)):
        raise SpecError("template", "expected a template name or path (str or pathlib.Path), got "
                                    f"{type(name_or_path).__name__}")
    candidate = Path(name_or_path)
    kind = path_kind(candidate, "template")
    if kind == "file":
        return candidate
    if kind == "other":
        raise SpecError("", f"template {name_or_path} is not a file")
    stem = candidate.name[:-5] if candidate.name.endswith(".toml") else candidate.name
    shipped = TEMPLATE_DIR / f"{stem}.toml"
    if candidate.parent == Path(".") and not stem.startswith("process_") and path_kind(shipped) == "file":
        return shipped
    raise SpecError("", f"template not found: {name_or_path} (see 'fabricate list')")


def shipped_templates() -> list[Path]:
    """Design templates shipped in ``templates/`` (process profiles excluded)."""
    return sorted(p for p in TEMPLATE_DIR.glob("*.toml") if not p.name.startswith("process_"))


def read_text(path: Path) -> str:
    """A template's text: UTF-8 with or without a byte-order mark; anything else is a :class:`SpecError`."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_TEMPLATE_BYTES + 1)
    except OSError as exc:
        raise SpecError(str(path), f"cannot read: {exc.strerror}") from exc
    except ValueError as exc:  # a NUL in the path
        raise SpecError(repr(str(path)), f"cannot read: {exc}") from exc
    if len(data) > MAX_TEMPLATE_BYTES:
        raise SpecError(str(path), f"larger than {MAX_TEMPLATE_BYTES} bytes: not a design template")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SpecError(str(path), f"not UTF-8 text (byte {exc.start}: {data[exc.start:exc.start + 1]!r}); "
                                   "save the template as UTF-8") from exc


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML text; syntax errors become :class:`SpecError` naming ``source`` and the line."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(source, f"invalid TOML: {exc}") from exc
    except ValueError as exc:  # int() refuses an integer literal of more than sys.get_int_max_str_digits()
        raise SpecError(source, f"invalid TOML: a number too long to read ({str(exc).split(';')[0]})") from exc
    except RecursionError as exc:  # tomllib recurses per nesting level of arrays and inline tables
        raise SpecError(source, "invalid TOML: nested too deeply") from exc


def read_toml(path: Path) -> dict[str, Any]:
    """Read and parse a TOML file (see :func:`read_text`, :func:`parse_toml`)."""
    return parse_toml(read_text(path), str(path))
