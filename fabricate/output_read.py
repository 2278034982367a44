"""Reading an output folder without trusting it: whether a folder is a previous fabricate output, and what
in it fabricate did not write.

A previous output is recognised by its ``report.json``: a regular file (a link, FIFO or device of that name
is never opened, so reading never blocks) of at most :data:`MAX_REPORT_BYTES` holding a fabricate report.
Its files are those the report lists (``files`` and ``manifest``); anything else in the folder is foreign.
:mod:`fabricate.output` refuses to replace a folder holding foreign files; ``fabricate check`` names them;
sweeps read their runs' reports through :func:`read_regular`.
"""

from __future__ import annotations

import json
import os
import stat
from collections.abc import Mapping
from pathlib import Path
from typing import Any

REPORT = "report.json"
#: Largest report.json read from an existing folder to decide whether it is a fabricate output (a linkage at
#: every documented bound writes a few MB); a larger one is not taken for a fabricate output.
MAX_REPORT_BYTES = 64 * 2**20
#: ``os.open`` flags every read and the lock use: never follow a link, never block on a FIFO, never leak the
#: descriptor into a child (0 where the system has no such flag).
NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
NONBLOCK = getattr(os, "O_NONBLOCK", 0)
CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def read_regular(path: Path, limit: int) -> bytes | None:
    """The bytes of ``path`` if it is a regular file of at most ``limit`` bytes, else None.

    A symbolic link, FIFO, device or socket is never opened for reading, so this never blocks: the path is
    checked with ``lstat``, then opened non-blocking without following a link and checked again on the
    open descriptor (it may have been swapped in between).
    """
    try:
        before = os.lstat(path)
        if not stat.S_ISREG(before.st_mode) or before.st_size > limit:
            return None
        fd = os.open(path, os.O_RDONLY | NOFOLLOW | NONBLOCK | CLOEXEC)
    except OSError:
        return None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or (st.st_dev, st.st_ino) != (before.st_dev, before.st_ino):
            return None
        chunks: list[bytes] = []
        total = 0
        while total <= limit:  # bounded even if the file grows while it is read
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)
            total += len(chunk)
        return None
    except OSError:
        return None
    finally:
        os.close(fd)


def not_regular(path: Path) -> str:
    """What ``path`` is if it exists but is not a regular file ("a FIFO"), else ""."""
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return ""
    kinds = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISSOCK, "a socket"),
             (stat.S_ISCHR, "a device"), (stat.S_ISBLK, "a device"), (stat.S_ISDIR, "a folder"))
    return next((what for test, what in kinds if test(mode)), "")


def previous_output(directory: Path) -> dict[str, Any] | None:
    """The report of a fabricate output folder, or None when ``directory`` is not one (its report.json is
    missing, not a regular file, larger than :data:`MAX_REPORT_BYTES` or not a fabricate report)."""
    data = read_regular(Path(directory) / REPORT, MAX_REPORT_BYTES)
    if data is None:
        return None
    try:
        report = json.loads(data.decode("utf-8"))
    except (ValueError, RecursionError):
        return None
    if not isinstance(report, dict) or not isinstance(report.get("design"), dict) \
            or "fabricate_version" not in report["design"] or not isinstance(report.get("files"), list):
        return None
    return report


def _written_by(report: Mapping[str, Any]) -> set[str]:
    listed = {str(p) for p in report.get("files", [])}
    listed |= {str(m.get("path")) for m in report.get("manifest", []) if isinstance(m, dict)}
    return listed | {REPORT}


def foreign_entries(directory: Path, report: Mapping[str, Any]) -> list[str]:
    """Files under ``directory`` (relative POSIX paths) that its report does not list, sorted."""
    listed = _written_by(report)
    found = []
    for root, dirs, names in os.walk(directory):
        dirs.sort()
        for name in sorted(names):
            rel = (Path(root) / name).relative_to(directory).as_posix()
            if rel not in listed:
                found.append(rel)
        for name in dirs:
            if os.path.islink(os.path.join(root, name)):  # os.walk does not enter it: it is foreign
                found.append((Path(root) / name).relative_to(directory).as_posix())
    return found
