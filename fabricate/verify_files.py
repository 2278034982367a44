"""Reading an output folder within bounds, and judging one file's bytes by the type its name says.

What ``fabricate check`` (:mod:`fabricate.verify`) reads, it reads through here, bounded by the manifest:
nothing in the folder decides how much is read or inflated.

- A path is walked one component at a time without following links (``O_NOFOLLOW`` below an open folder
  descriptor), and only a regular file is opened (``lstat``, then ``fstat`` of what was opened): a
  symbolic link (to anywhere, a folder on the way included), a FIFO, a socket or a device is named and
  never opened, so nothing outside the folder is read and nothing blocks (:class:`OutputFolder`).
- A file is read in chunks of :data:`CHUNK_BYTES`, hashed while reading, never past the limit the caller
  gives (its manifest size + 1 byte); a file larger on disk than that is named without reading a byte.
- A 3MF (a zip) is judged by its members' declared sizes and methods before anything is inflated (the
  standard library inflates deflate in bounded steps, never past a member's declared size; other methods
  are refused): a member inflating more than :data:`ARCHIVE_MAX_RATIO` times is a zip bomb, and members
  declaring more than :data:`ARCHIVE_MAX_INFLATED_BYTES` in all are not inflated. An image is judged by its
  header's pixel count (:data:`IMAGE_MAX_PIXELS`) before it is decoded.

:func:`content_problems` parses one file as what it claims to be, against the numbers the report gives (a
part STL is a closed solid of the reported volume, a 3MF has one closed object per part, a DXF passes
ezdxf's audit and cuts exactly the reported holes, images open, text is UTF-8).

Nothing here writes files.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import stat
import zipfile
from collections.abc import Mapping
from pathlib import Path, PurePosixPath
from typing import Any

from fabricate.errors import SpecError

#: Relative tolerance of a mesh volume against the report (the report rounds to 1e-4 mm^3; meshes carry
#: float32 vertices, 1e-7 relative).
VOLUME_REL_TOL = 1e-5
#: Absolute tolerance of a DXF hole diameter against the report (the report rounds to 1e-6 mm).
DIAMETER_TOL_MM = 2e-6
#: Bytes read at a time while hashing.
CHUNK_BYTES = 2**20
#: Largest inflated / compressed size of a 3MF member; fabricate's own 3MF packages measure 1.5-7.2
#: (XML of decimal coordinates), a zip bomb 1000.
ARCHIVE_MAX_RATIO = 50
#: Largest total inflated size of a 3MF's members (the shipped templates': under 1 MB).
ARCHIVE_MAX_INFLATED_BYTES = 256 * 2**20
#: Largest image (pixels) decoded; fabricate's pictures are at most 0.6 Mpixel (fixed figure sizes).
IMAGE_MAX_PIXELS = 16 * 2**20

_DIR_FD = os.open in os.supports_dir_fd and os.stat in os.supports_dir_fd
_O_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_O_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_O_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_O_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_O_BINARY = getattr(os, "O_BINARY", 0)


class Unreadable(Exception):
    """A path of the folder that ``check`` does not open; the message says what it is instead."""


class TooLargeToParse(Exception):
    """A file within its manifest size that is larger than ``check`` parses (the message says how)."""


def _kind(mode: int) -> str:
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "a regular file" if stat.S_ISREG(mode) else "not a regular file"


class OutputFolder:
    """An output folder opened for reading without following links (``with OutputFolder(d) as f:``).

    Where the platform has ``openat`` (``dir_fd``), each path is walked from a descriptor of the folder,
    one component at a time with ``O_NOFOLLOW``, so a link swapped in while checking is not followed
    either; elsewhere each component is ``lstat``-ed first.
    """

    def __init__(self, directory: str | Path) -> None:
        self.directory = Path(directory)
        self._fd: int | None = None
        if _DIR_FD:
            try:
                self._fd = os.open(self.directory, os.O_RDONLY | _O_DIRECTORY | _O_CLOEXEC)
            except OSError as exc:
                raise SpecError(str(self.directory), f"cannot be read ({exc.strerror or exc})") from None

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> OutputFolder:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def _link_target(self, where: str, dir_fd: int | None) -> str:
        try:
            return f" to {os.readlink(where, dir_fd=dir_fd)!r}"
        except (OSError, NotImplementedError):
            return ""

    def open(self, rel: str) -> tuple[int, os.stat_result]:
        """A read-only descriptor of the regular file ``rel`` (relative POSIX path) and its ``fstat``.

        Raises
        ------
        Unreadable
            ``rel`` is missing, or it or a folder on its way is a link, FIFO, socket, device or folder.
        """
        parts = PurePosixPath(rel).parts
        if not parts or rel.startswith("/") or any(p in (".", "..") for p in parts) or "\0" in rel:
            raise Unreadable("is not a path inside the folder")
        dir_fd = self._fd
        opened: list[int] = []
        try:
            for depth, name in enumerate(parts):
                where = name if dir_fd is not None else os.path.join(self.directory, *parts[:depth + 1])
                try:
                    info = os.stat(where, dir_fd=dir_fd, follow_symlinks=False)
                except FileNotFoundError:
                    raise Unreadable("missing") from None
                last = depth == len(parts) - 1
                link = self._link_target(where, dir_fd) if stat.S_ISLNK(info.st_mode) else ""
                never = " (check follows no links)" if link else ""
                if not last:
                    if not stat.S_ISDIR(info.st_mode):
                        folder = "/".join(parts[:depth + 1])
                        raise Unreadable(f"its folder {folder} is {_kind(info.st_mode)}{link}, not a folder{never}")
                    if dir_fd is not None:
                        dir_fd = os.open(name, os.O_RDONLY | _O_DIRECTORY | _O_NOFOLLOW | _O_CLOEXEC, dir_fd=dir_fd)
                        opened.append(dir_fd)
                    continue
                if not stat.S_ISREG(info.st_mode):
                    raise Unreadable(f"is {_kind(info.st_mode)}{link}, not a regular file{never}")
                fd = os.open(where, os.O_RDONLY | _O_NOFOLLOW | _O_NONBLOCK | _O_CLOEXEC | _O_BINARY, dir_fd=dir_fd)
                info = os.fstat(fd)
                if not stat.S_ISREG(info.st_mode):  # swapped between the lstat and the open
                    os.close(fd)
                    raise Unreadable(f"is {_kind(info.st_mode)}, not a regular file")
                return fd, info
            raise Unreadable("is not a path inside the folder")  # pragma: no cover - parts is never empty
        except OSError as exc:  # a link or other kind swapped in (ELOOP, ENOTDIR), permissions
            raise Unreadable(f"cannot be opened ({exc.strerror or exc})") from None
        finally:
            for fd in opened:
                os.close(fd)

    def lexists(self, rel: str) -> bool:
        """Whether anything (of any kind) is at ``rel``, without following a link."""
        try:
            fd, _info = self.open(rel)
        except Unreadable as exc:
            return str(exc) != "missing"
        os.close(fd)
        return True

    def read(self, rel: str, limit: int, keep: bool = True) -> tuple[bytes | None, int, str]:
        """At most ``limit`` bytes of ``rel``, read in chunks and hashed while reading.

        Returns
        -------
        data : bytes or None
            What was read; None when the file is larger on disk than ``limit`` (then nothing is read) or
            ``keep`` is false (then only the hash is kept).
        size : int
            The file's size: its ``fstat`` size, or the bytes read if more arrived while reading.
        sha256 : str
            Hex digest of the bytes read ('' when nothing was).

        Raises
        ------
        Unreadable
            See :meth:`open`.
        """
        fd, info = self.open(rel)
        try:
            if info.st_size > limit:
                return None, info.st_size, ""
            digest = hashlib.sha256()
            chunks = []
            count = 0
            while count < limit:
                chunk = os.read(fd, min(CHUNK_BYTES, limit - count))
                if not chunk:
                    break
                digest.update(chunk)
                if keep:
                    chunks.append(chunk)
                count += len(chunk)
            return (b"".join(chunks) if keep else None), max(info.st_size, count), digest.hexdigest()
        finally:
            os.close(fd)


def same_bytes(folder: OutputFolder, rel: str, expected: bytes) -> tuple[bool | None, str]:
    """Whether ``rel`` holds exactly ``expected`` (compared chunk by chunk; None: it cannot be opened), and
    why not when the sizes say so or why it cannot be opened."""
    try:
        fd, info = folder.open(rel)
    except Unreadable as exc:
        return None, str(exc)
    try:
        if info.st_size != len(expected):
            return False, f"{info.st_size} bytes, a rebuild writes {len(expected)}"
        offset = 0
        while offset <= len(expected):
            chunk = os.read(fd, CHUNK_BYTES)
            if not chunk:
                break
            if chunk != expected[offset:offset + len(chunk)]:
                return False, ""
            offset += len(chunk)
        return offset == len(expected), ""
    finally:
        os.close(fd)


def reject_constant(name: str) -> Any:
    """``json.loads``'s ``parse_constant``: NaN and Infinity are not JSON, and no fabricate file holds them."""
    raise ValueError(f"{name} is not JSON")


def content_problems(rel: str, data: bytes, expected: Any) -> list[str]:
    """What is wrong with one file's bytes, read as the type its name says (empty: nothing found).

    Raises
    ------
    TooLargeToParse
        A 3MF whose members declare more than :data:`ARCHIVE_MAX_INFLATED_BYTES` (not inflated).
    """
    suffix = PurePosixPath(rel).suffix.lower()
    if suffix == ".stl":
        from fabricate.export.stl import validate_stl

        return validate_stl(data, expected, rel_tol=VOLUME_REL_TOL)
    if suffix == ".3mf":
        return _archive_problems(data) or _threemf_problems(data, expected)
    if suffix == ".dxf":
        from fabricate.export.dxf import read_dxf

        problems, diameters = read_dxf(data)
        if expected is not None and not problems:
            if len(diameters) != len(expected) or any(abs(a - b) > DIAMETER_TOL_MM
                                                       for a, b in zip(diameters, expected, strict=True)):
                problems.append(f"cut holes {_mm(diameters)} differ from the report's {_mm(expected)}")
        return problems
    if suffix in (".png", ".gif"):
        return _image_problems(data)
    if suffix == ".step":
        from fabricate.export.step import step_available
        from fabricate.export.step_read import step_problems

        return step_problems(data, expected) if step_available() else []
    if suffix == ".svg":
        import xml.etree.ElementTree as ET

        try:
            root = ET.fromstring(data)
        except ET.ParseError as exc:
            return [f"not readable SVG ({exc})"]
        if not root.tag.endswith("svg") or not str(root.get("width", "")).endswith("mm"):
            return ["not an SVG sized in millimetres"]
        return []
    if suffix in (".csv", ".md", ".json", ".txt", ".toml"):
        try:
            text = data.decode("utf-8")
            if suffix == ".csv":
                for _row in csv.reader(io.StringIO(text)):
                    pass
            elif suffix == ".json":
                json.loads(text, parse_constant=reject_constant)
        except (UnicodeDecodeError, ValueError, csv.Error) as exc:
            return [f"not readable {suffix[1:].upper()} ({exc})"]
        except RecursionError:
            return [f"not readable {suffix[1:].upper()} (nested too deeply)"]
    return []


def _mm(values: list[float]) -> str:
    return "[" + ", ".join(f"{v:.4f}" for v in values) + "] mm"


def _archive_problems(data: bytes) -> list[str]:
    """A zip's members judged by their declared sizes, before anything is inflated."""
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            members = archive.infolist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, ValueError) as exc:
        return [f"not a readable 3MF package ({type(exc).__name__}: {exc})"]
    for member in members:
        # the standard library inflates deflate in bounded steps, never past the declared size; bzip2 and
        # LZMA chunks are inflated whole, and fabricate writes neither
        if member.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            return [f"member {member.filename[:80]!r} is compressed with method {member.compress_type}, not "
                    "stored or deflate as 3MF packages are; not inflated"]
        if member.file_size > ARCHIVE_MAX_RATIO * max(member.compress_size, 1):
            return [f"member {member.filename[:80]!r} declares {member.file_size} bytes from {member.compress_size} "
                    f"compressed (more than {ARCHIVE_MAX_RATIO} times: a zip bomb?); not inflated"]
    total = sum(member.file_size for member in members)
    if total > ARCHIVE_MAX_INFLATED_BYTES:
        raise TooLargeToParse(f"its members declare {total} bytes, more than check inflates "
                              f"({ARCHIVE_MAX_INFLATED_BYTES // 2**20} MB)")
    return []


def _image_problems(data: bytes) -> list[str]:
    from PIL import Image

    try:
        with Image.open(io.BytesIO(data)) as image:
            width, height = image.size
            if width * height > IMAGE_MAX_PIXELS:  # judged by the header, before decoding a pixel
                return [f"an image of {width} x {height} pixels, more than fabricate draws "
                        f"({IMAGE_MAX_PIXELS // 2**20} Mpixel); not decoded"]
            image.verify()
        with Image.open(io.BytesIO(data)) as image:
            image.load()
    except Exception as exc:  # noqa: BLE001 - Pillow raises many types for a broken image
        return [f"not a readable image ({type(exc).__name__}: {exc})"]
    return []


def _threemf_problems(data: bytes, expected: Mapping[str, Any] | None) -> list[str]:
    from fabricate.export.stl import mesh_problems, read_3mf

    objects, problems = read_3mf(data)
    if problems or expected is None:
        return problems
    if list(objects) != list(expected):
        problems.append(f"objects {sorted(objects)} differ from the report's parts {sorted(map(str, expected))}")
    for name, mesh in objects.items():
        volume = expected.get(name)
        problems += [f"object {name}: {p}" for p in mesh_problems(
            mesh, float(volume) if isinstance(volume, (int, float)) else None, VOLUME_REL_TOL)]
    return problems


def parse_problems(rel: str, data: bytes, expected: Any, notes: list[str]) -> list[str]:
    """:func:`content_problems` of bytes read within the manifest's size, each finding named by file."""
    try:
        found = content_problems(rel, data, expected)
    except TooLargeToParse as exc:
        notes.append(f"{rel}: {exc}; verified by its hash and the rebuild only")
        return []
    except RecursionError:
        found = ["cannot be read (nested too deeply)"]
    except (ValueError, TypeError, KeyError, IndexError, OverflowError, UnicodeError, EOFError, OSError,
            zipfile.BadZipFile) as exc:  # a reader (ezdxf, trimesh, XML) meeting bytes no writer makes
        found = [f"cannot be read ({type(exc).__name__}: {exc})"]
    return [f"{rel}: {p}" for p in found]
