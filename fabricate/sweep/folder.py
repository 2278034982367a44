"""A sweep's output folder: its record (sweep.json), the journal of finished points (rows.jsonl) that a
resumed sweep reads back, and the checks that it only ever writes into a folder of its own.
"""

from __future__ import annotations

import json
import os
import stat
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError
from fabricate.sweep.spec import SweepSpec
from fabricate.sweep.task import row_from_json, row_json

SWEEP_JSON = "sweep.json"
JOURNAL = "rows.jsonl"

def write_file(path: Path, data: bytes) -> None:
    """Replace ``path`` atomically: a temporary sibling, synced, then renamed over it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def sweep_record(spec: SweepSpec, extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    from fabricate import __version__

    return {"fabricate": __version__, "kind": "sweep", "spec": spec.describe(), "spec_digest": spec.digest,
            "template_text": spec.template_text, **(extra or {})}


#: Largest sweep.json read from an earlier run (it holds the spec, counts and best points: kilobytes).
MAX_RECORD_BYTES = 16 * 2**20
#: What fabricate writes at the top of a sweep folder, and what each must be (a link is never either).
_FOLDER_ENTRIES = {SWEEP_JSON: "file", JOURNAL: "file", "sweep.csv": "file", "sweep.parquet": "file",
                   "plots": "folder", "best": "folder"}


def _kind(path: Path) -> str:
    """``"file"``, ``"folder"`` or what else ``path`` itself is (a link is not followed); "" if absent."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return ""
    if stat.S_ISREG(mode):
        return "file"
    if stat.S_ISDIR(mode):
        return "folder"
    return next((what for test, what in ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO"),
                                         (stat.S_ISSOCK, "a socket")) if test(mode)), "a device")


def prepare_folder(out: Path, spec: SweepSpec, protect: Sequence[Path] = ()) -> bool:
    """Check the output folder before any work. Returns whether it holds an earlier run of this spec.

    Parameters
    ----------
    out : Path
    spec : SweepSpec
    protect : sequence of Path
        The inputs of the sweep (its spec file, its template): the folder may not be or hold one.

    Raises
    ------
    SpecError
        The folder is a file or a link, is or holds an input, holds files fabricate did not write, a sweep
        of another spec, or one of the names a sweep writes as something else (``rows.jsonl`` a link, a FIFO
        or a folder, say: it is never opened).
    """
    if os.path.lexists(out) and (out.is_symlink() or not out.is_dir()):
        raise SpecError(str(out), "is not a folder; a sweep writes into a new, empty or earlier sweep folder")
    real = out.resolve()
    for given in protect:
        given = Path(given)
        for path in {given.resolve(), given.parent.resolve() / given.name}:
            if path == real or real in path.parents:
                raise SpecError(str(out), f"holds {given.name}, an input of this sweep; choose another folder")
    if not out.exists():
        return False
    entries = sorted(p.name for p in out.iterdir())
    if not entries:
        return False
    for name, want in _FOLDER_ENTRIES.items():
        kind = _kind(out / name)
        if kind and kind != want:
            raise SpecError(str(out / name), f"is {kind}, not the {want} a sweep writes there (it is never "
                                             "opened or written through); remove it or choose another folder")
    marker = out / SWEEP_JSON
    if not marker.is_file():
        raise SpecError(str(out), f"holds files fabricate did not write ({', '.join(entries[:3])}"
                                  f"{', ...' if len(entries) > 3 else ''}); choose a new or empty folder")
    from fabricate.output_read import read_regular

    data = read_regular(marker, MAX_RECORD_BYTES)
    if data is None:
        raise SpecError(str(marker), f"cannot be read as a sweep's record (larger than {MAX_RECORD_BYTES} bytes, "
                                     "or unreadable)")
    try:
        previous = json.loads(data.decode("utf-8"))
    except (ValueError, RecursionError) as exc:
        raise SpecError(str(marker), f"cannot be read as a sweep's record: {exc}") from None
    if not isinstance(previous, dict) or previous.get("kind") != "sweep":
        raise SpecError(str(out), "holds a sweep.json fabricate did not write; choose a new or empty folder")
    if previous.get("spec_digest") != spec.digest or previous.get("spec") != spec.describe():
        raise SpecError(str(out), "holds a sweep of another spec (template, values, stage or metrics differ); "
                                  "choose another folder to keep both")
    return True


def _open_journal(path: Path, flags: int) -> int:
    """Open the journal without following a link or blocking on a FIFO; refuse anything but a plain file.

    Raises
    ------
    SpecError
        Naming the journal: it is a symbolic link, a FIFO, a device or a folder (nothing was written).
    """
    try:
        fd = os.open(path, flags | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
                     | getattr(os, "O_CLOEXEC", 0), 0o644)
    except OSError as exc:
        kind = _kind(path)
        if kind and kind != "file":
            raise SpecError(str(path), f"is {kind}, not the plain file a sweep's journal is; it is never "
                                       "written through: remove it or choose another folder") from None
        raise SpecError(str(path), f"cannot be opened: {exc.strerror}") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise SpecError(str(path), f"is {_kind(path) or 'not a plain file'}, not the plain file a sweep's "
                                   "journal is; it is never written through: remove it or choose another folder")
    return fd


def read_journal(out: Path, spec: SweepSpec) -> dict[str, dict[str, Any]]:
    """Rows of an earlier run by point id (a torn last line is cut off so appending can go on).

    Raises
    ------
    SpecError
        The journal is not a plain file (a link is never truncated through).
    """
    path = out / JOURNAL
    if not os.path.lexists(path):
        return {}
    fd = _open_journal(path, os.O_RDWR)
    with os.fdopen(fd, "r+b") as fh:
        data = fh.read()
        if data and not data.endswith(b"\n"):
            cut = data.rfind(b"\n") + 1
            fh.truncate(cut)
            data = data[:cut]
    rows: dict[str, dict[str, Any]] = {}
    for line in data.decode("utf-8", "replace").splitlines():  # a garbled line is not a row: it is run again
        try:
            row = row_from_json(line, spec.metrics)
        except ValueError:
            continue
        rows[str(row["id"])] = row
    return rows


class Journal:
    """Append-only rows file: one ``write`` of whole lines per finished task, flushed and synced."""

    def __init__(self, path: Path) -> None:
        self.path = path
        fd = _open_journal(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT)  # never appended through a link
        self._fh = os.fdopen(fd, "a", encoding="utf-8")

    def append(self, rows: list[dict[str, Any]]) -> None:
        self._fh.write("".join(row_json(r) + "\n" for r in rows))
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        self._fh.close()
