"""``fabricate check DIR``: verify what is on disk against what fabricate wrote and would write again.

Three layers, each naming the file and how it differs:

1. **Manifest.** report.json (at most :data:`REPORT_MAX_BYTES`, of a ``schema_version`` this fabricate
   reads, validated against its schema, :mod:`fabricate.report_schema`, before any field is read) lists every
   other file with its size and sha256; each is compared, and a file the manifest does not list is reported.
2. **Contents by type.** Every file is parsed as what it claims to be, against the numbers the report
   gives: a part STL is a closed solid of the reported volume, the print plate holds all of them, the 3MF
   has one closed object per part, a part DXF passes ezdxf's audit and cuts exactly the reported holes,
   images open, CSV and Markdown are UTF-8 text.
3. **Rebuild.** The template text embedded in report.json is built again and every file compared byte
   for byte (builds are deterministic), which also catches an edited report.json.

Each layer runs in full only when the ones before found nothing: once a file differs from its manifest
entry the verdict is given, so only the differing files are parsed (to say how they differ) and nothing is
rebuilt; a folder with a wrong file (a 2 GB sparse file, a zip bomb) is rejected in milliseconds.

Bounded by the manifest: nothing in the folder decides how much ``check`` reads or inflates.

- A path is walked one component at a time without following links (``O_NOFOLLOW`` below an open folder
  descriptor), and only a regular file is opened (``lstat``, then ``fstat`` of what was opened): a
  symbolic link (to anywhere, a folder on the way included), a FIFO, a socket or a device is named and
  never opened, so nothing outside the folder is read and nothing blocks.
- A file larger on disk than its manifest entry is named without reading a byte; any other is read in
  chunks of :data:`CHUNK_BYTES`, hashed while reading, never past its manifest size + 1 byte. Only those
  bytes are parsed, and only up to :data:`PARSE_MAX_BYTES`.
- A 3MF (a zip) is judged by its members' declared sizes and methods before anything is inflated (the
  standard library inflates deflate in bounded steps, never past a member's declared size; other methods
  are refused): a member inflating more than
  :data:`ARCHIVE_MAX_RATIO` times is a zip bomb, and members declaring more than
  :data:`ARCHIVE_MAX_INFLATED_BYTES` in all are not inflated. An image is judged by its header's pixel
  count (:data:`IMAGE_MAX_PIXELS`) before it is decoded.

Optional outputs (STEP, the ``cad`` extra) are recorded in the report as written or skipped; the rebuild
makes the same set, so the verdict is the same on any install. STEP files that this install cannot make
are verified against the manifest and, in the rebuild, "not comparable here" (a note, not a failure).

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
from collections.abc import Callable, Mapping
from pathlib import Path, PurePosixPath
from typing import Any

from fabricate.errors import FabricateError, SpecError
from fabricate.export import copy_name
from fabricate.output import REPORT, foreign_entries
from fabricate.report_schema import schema_errors, version_problem

#: Relative tolerance of a mesh volume against the report (the report rounds to 1e-4 mm^3; meshes carry
#: float32 vertices, 1e-7 relative).
VOLUME_REL_TOL = 1e-5
#: Absolute tolerance of a DXF hole diameter against the report (the report rounds to 1e-6 mm).
DIAMETER_TOL_MM = 2e-6
#: Largest report.json read (bytes). The shipped templates write 20-60 kB; the largest a template within
#: the bounds of fabricate/bounds.py can ask for (5000 poses, 40 bodies) stays well under 10 MB.
REPORT_MAX_BYTES = 64 * 2**20
#: Largest file parsed by type (bytes); a larger one (its manifest says so and its hash matches) is
#: verified by hash and rebuild only, with a note. The shipped templates' largest file is a 3.8 MB STEP.
PARSE_MAX_BYTES = 64 * 2**20
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

_STEP_NOT_COMPARABLE = ("{n} STEP files not comparable here: OCP is not installed (pip install 'fabricate[cad]'), "
                        "so they were checked against the manifest only, not read back or rebuilt")


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


def _same_bytes(folder: OutputFolder, rel: str, expected: bytes) -> tuple[bool | None, str]:
    """Whether ``rel`` holds exactly ``expected`` (compared chunk by chunk; None: it cannot be opened)."""
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


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def _load_report(folder: OutputFolder) -> tuple[dict[str, Any] | None, bytes, list[str]]:
    """report.json, its bytes, and why it cannot be used (a report is returned only when valid)."""
    if not folder.lexists(REPORT):
        raise SpecError(str(folder.directory), "not a fabricate output folder (it has no report.json)")
    try:
        raw, size, _digest = folder.read(REPORT, REPORT_MAX_BYTES)
    except Unreadable as exc:
        return None, b"", [f"{REPORT}: {exc}"]
    if raw is None or size > REPORT_MAX_BYTES:
        return None, b"", [f"{REPORT}: {size} bytes, more than any report fabricate writes "
                           f"({REPORT_MAX_BYTES // 2**20} MB); not read"]
    try:
        report = json.loads(raw.decode("utf-8"), parse_constant=_no_constant)
    except (UnicodeDecodeError, ValueError) as exc:
        return None, raw, [f"{REPORT}: not valid JSON ({exc})"]
    except RecursionError:
        return None, raw, [f"{REPORT}: not valid JSON (nested too deeply)"]
    if not isinstance(report, dict) or not isinstance(report.get("design"), dict):
        return None, raw, [f"{REPORT}: not a fabricate report (no design section)"]
    if report.get("manifest") is None or report.get("manifest") == []:
        return None, raw, [f"{REPORT}: no manifest of the files (written by an older fabricate? build it again)"]
    version = version_problem(report)  # before the schema: a report of another version fails it for that reason
    if version is not None:
        return None, raw, [f"{REPORT}: {version}"]
    errors = schema_errors(report)
    if errors:
        return None, raw, [f"{REPORT}: {text}" for text in errors]
    return report, raw, []


def read_report(directory: str | Path) -> tuple[dict[str, Any] | None, list[str]]:
    """report.json of an output folder (size-bounded, schema-validated), or the reasons it cannot be used.

    Raises
    ------
    SpecError
        ``directory`` is not a folder or has no report.json: it is not a fabricate output at all.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise SpecError(str(directory), "not a folder")
    with OutputFolder(directory) as folder:
        report, _raw, problems = _load_report(folder)
    return report, problems


def _short(rel: Any) -> str:
    text = str(rel)
    return repr(text if len(text) <= 80 else text[:80] + "...")


def _manifest(report: Mapping[str, Any]) -> tuple[dict[str, dict[str, Any]], list[str]]:
    entries: dict[str, dict[str, Any]] = {}
    problems = []
    for item in report.get("manifest", []):
        rel = item.get("path") if isinstance(item, dict) else None
        pure = PurePosixPath(rel) if isinstance(rel, str) else None
        # the schema admits only relative paths, sizes and hashes; this guard keeps it so for any caller
        if not isinstance(rel, str) or pure is None or pure.is_absolute() or ".." in pure.parts \
                or not isinstance(item.get("sha256"), str) or not isinstance(item.get("bytes"), int) \
                or isinstance(item.get("bytes"), bool):
            problems.append(f"{REPORT}: malformed manifest entry for {_short(rel)}")
            continue
        entries[rel] = item
    return entries, problems


def _expected_by_file(report: Mapping[str, Any]) -> dict[str, Any]:
    """What the report says each geometry file holds: volumes, hole diameters, object names and volumes.

    Drawings hold the finished holes, cut files the kerf-compensated ones; a plate or sheet holds every
    copy of every part the report places on it.
    """
    parts = [p for p in report.get("parts", []) if isinstance(p, dict)]
    expected: dict[str, Any] = {}
    plates: dict[int, list[tuple[str, float]]] = {}
    sheets: dict[int, list[float]] = {}
    for part in parts:
        volume = part.get("stl_volume_mm3")
        holes: list[dict[str, Any]] = [h for h in part.get("holes", []) if isinstance(h, dict)]
        finished = sorted(float(h.get("diameter_mm", 0.0)) for h in holes)
        cut = sorted(float(h.get("cut_diameter_mm", h.get("diameter_mm", 0.0))) for h in holes)
        if isinstance(part.get("stl"), str) and isinstance(volume, (int, float)):
            expected[part["stl"]] = float(volume)
        if isinstance(part.get("dxf"), str):
            expected[part["dxf"]] = finished
        if isinstance(part.get("cut_dxf"), str):
            expected[part["cut_dxf"]] = cut
        copies = int(part.get("copies", 1) or 1)
        for key in ("plate", "sheet"):
            indices = part.get(key, {}).get("index", []) if isinstance(part.get(key), dict) else []
            for k, number in enumerate(indices if isinstance(indices, list) else []):
                name = copy_name(part["name"], k, copies)
                if key == "plate":
                    plates.setdefault(number, []).append((name, float(volume or 0.0)))
                else:
                    sheets.setdefault(number, []).extend(cut)
    for number, items in plates.items():
        expected[f"plates/plate_{number}.stl"] = sum(v for _, v in items)
        expected[f"plates/plate_{number}.3mf"] = dict(items)
    for number, diameters in sheets.items():
        expected[f"cut/sheet_{number}.dxf"] = sorted(diameters)
    if parts:
        expected["assembly.3mf"] = {p.get("name"): p.get("stl_volume_mm3") for p in parts}
        # a STEP solid is exact: the profile's area times the thickness, one cylinder per hole
        solids = {p.get("name"): (float(p.get("volume_mm3") or 0.0), len(p.get("holes", []))) for p in parts}
        for part in parts:
            if isinstance(part.get("step"), str):
                expected[part["step"]] = {part.get("name"): solids[part.get("name")]}
        expected["assembly.step"] = solids
    return expected



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
        from fabricate.export.step import step_available, step_problems

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
                json.loads(text, parse_constant=_no_constant)
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


def _parse(rel: str, data: bytes, expected: Any, notes: list[str]) -> list[str]:
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


def _check_files(folder: OutputFolder, report: Mapping[str, Any], notes: list[str]) -> list[str]:
    """Layer 1 for every file, then layer 2: every file when layer 1 found nothing, else only the files
    whose bytes differ from their manifest entry (to say how), so a wrong folder is judged in milliseconds."""
    entries, problems = _manifest(report)
    listed = {str(p) for p in report.get("files", []) if isinstance(p, str)}
    if entries and listed != set(entries) | {REPORT}:
        missing = sorted(set(entries) - listed)
        extra = sorted(listed - set(entries) - {REPORT})
        problems.append(f"{REPORT}: its file list and its manifest disagree (not listed: {missing[:5]}, "
                        f"not in the manifest: {extra[:5]})")
    matching, differing = [], []
    for rel, item in sorted(entries.items()):
        manifest_bytes = int(item["bytes"])
        try:  # hashed in chunks, nothing held; +1 byte: a file that grew while being read shows it
            _data, size, digest = folder.read(rel, manifest_bytes + 1, keep=False)
        except Unreadable as exc:
            problems.append(f"{rel}: {exc}")
            continue
        if size != manifest_bytes:
            problems.append(f"{rel}: {size} bytes on disk, {manifest_bytes} bytes in the manifest")
        elif digest != item["sha256"]:
            problems.append(f"{rel}: contents differ from the manifest (sha256 {digest[:12]}... against "
                            f"{item['sha256'][:12]}...)")
        else:
            matching.append(rel)
            continue
        if size <= manifest_bytes:  # within the manifest's size: its contents may say how it differs
            differing.append(rel)
    if entries:
        problems += [f"{rel}: not written by fabricate (not in the manifest)"
                     for rel in foreign_entries(folder.directory, report)]
    expected = _expected_by_file(report)
    for rel in differing if problems else matching:
        manifest_bytes = int(entries[rel]["bytes"])
        if manifest_bytes > PARSE_MAX_BYTES:
            notes.append(f"{rel}: {manifest_bytes} bytes, more than check parses ({PARSE_MAX_BYTES // 2**20} MB); "
                         "verified by its hash" + ("" if problems else " and the rebuild") + " only")
            continue
        try:
            data, _size, _digest = folder.read(rel, manifest_bytes)
        except Unreadable as exc:  # changed since it was hashed
            problems.append(f"{rel}: {exc}")
            continue
        if data is not None:  # None: it grew past its manifest size since it was hashed (named above)
            problems += _parse(rel, data, expected.get(rel), notes)
    return problems


def file_problems(directory: str | Path, report: Mapping[str, Any]) -> list[str]:
    """Layers 1 and 2: the manifest's sizes and hashes, files it does not list, and every file's contents.

    ``report`` must have passed the schema (:func:`read_report` returns only such a report).
    """
    with OutputFolder(directory) as folder:
        return _check_files(folder, report, [])


def _recorded_step(report: Mapping[str, Any]) -> bool | None:
    """Whether the folder's build wrote STEP files (None: a synth output, no such question)."""
    outputs = report.get("outputs")
    if isinstance(outputs, dict) and isinstance(outputs.get("step"), str):
        return outputs["step"].startswith("written")
    if report.get("design", {}).get("stage") == "synth":
        return None
    # written before the report recorded its optional outputs: the manifest tells
    return any(str(m.get("path")).endswith(".step") for m in report.get("manifest", []) if isinstance(m, dict))


def _folder_step_files(folder: OutputFolder, report: Mapping[str, Any]) -> dict[str, bytes]:
    """The folder's STEP files that match their manifest entries (stand-ins for a rebuild without OCP)."""
    entries, _problems = _manifest(report)
    found = {}
    for rel, item in entries.items():
        if not rel.endswith(".step"):
            continue
        try:
            data, size, digest = folder.read(rel, int(item["bytes"]))
        except Unreadable:
            continue
        if data is not None and size == item["bytes"] and digest == item["sha256"]:
            found[rel] = data
    return found


def _rebuild(folder: OutputFolder, report: Mapping[str, Any], raw: bytes, progress: Callable[[str], None],
             notes: list[str]) -> tuple[list[str], dict[str, Any] | None]:
    from fabricate.export.step import step_available
    from fabricate.pipeline import OptionalOutputs, run_build, run_synth
    from fabricate.process import ProcessOverride
    from fabricate.spec import design_from_text

    text = report.get("template_text")
    design_info = report.get("design", {})
    if not isinstance(text, str) or not text:
        return [f"{REPORT}: no embedded template (template_text) to rebuild from"], None
    override = design_info.get("process_override")
    try:
        process = None
        if isinstance(override, dict):
            process = ProcessOverride(str(override.get("source")), str(override.get("text")))
        design = design_from_text(text, str(design_info.get("template") or "template.toml"), process)
    except SpecError as exc:
        return [f"{REPORT}: the embedded template is not valid: {exc}"], None
    runner = run_synth if design_info.get("stage") == "synth" else run_build
    step_written = _recorded_step(report)
    not_comparable: set[str] = set()
    stand_ins = None
    if step_written and not step_available():
        stand_ins = _folder_step_files(folder, report)
        not_comparable = {str(m["path"]) for m in report.get("manifest", []) if str(m["path"]).endswith(".step")}
        notes.append(_STEP_NOT_COMPARABLE.format(n=len(not_comparable)))
    try:
        if runner is run_build and step_written is not None:
            # the optional outputs the folder's build made, whatever this install can make
            outcome = run_build(design, progress, optional=OptionalOutputs(step_written, stand_ins))
        else:
            outcome = runner(design, progress)
    except FabricateError as exc:  # the embedded template no longer builds (nothing feasible, a bound)
        return [f"{REPORT}: the embedded template cannot be built again: {exc}"], None
    on_disk = {str(m.get("path")) for m in report.get("manifest", [])} | {REPORT}
    problems = []
    for rel in sorted((set(outcome.files) | on_disk) - not_comparable):
        if rel not in outcome.files:
            problems.append(f"{rel}: a rebuild of the embedded template does not write it")
            continue
        same: bool | None
        if rel == REPORT:
            same, why = raw == outcome.files[REPORT], ""
        else:
            same, why = _same_bytes(folder, rel, outcome.files[rel])
        if same is None:
            if rel not in on_disk:  # a manifest entry that cannot be read is named by the manifest layer
                problems.append(f"{rel}: {why} (a rebuild writes it)" if why != "missing"
                                else f"{rel}: missing (a rebuild writes it)")
        elif not same:
            problems.append(f"{rel}: differs from a rebuild of the embedded template" + (f" ({why})" if why else ""))
    return problems, outcome.report


def rebuild_problems(directory: str | Path, report: Mapping[str, Any],
                     progress: Callable[[str], None] = lambda _m: None) -> tuple[list[str], dict[str, Any] | None]:
    """Layer 3: build the embedded template again and compare every file byte for byte.

    Returns
    -------
    problems : list of str
    rebuilt_report : dict or None
        The fresh report (its check failures are the design's own), None when nothing could be rebuilt.
    """
    with OutputFolder(directory) as folder:
        loaded, raw, _problems = _load_report(folder)
        return _rebuild(folder, report, raw if loaded == report else b"", progress, [])


def verify_output(directory: str | Path, progress: Callable[[str], None] = lambda _m: None
                  ) -> tuple[list[str], dict[str, Any] | None]:
    """Every problem of an output folder: manifest, contents, rebuild (see the module docstring).

    Returns
    -------
    problems : list of str
        Each names the file and how it differs; empty when the folder is exactly what the template builds.
    report : dict or None
        The rebuilt report when a rebuild ran (its ``checks`` are the design's), else the one on disk; its
        ``notes`` end with what this check could not verify here (e.g. STEP files without OCP).

    Raises
    ------
    SpecError
        ``directory`` is not a fabricate output folder at all.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise SpecError(str(directory), "not a folder")
    notes: list[str] = []
    with OutputFolder(directory) as folder:
        report, raw, problems = _load_report(folder)
        if report is None:
            return problems, None
        progress("files")
        problems += _check_files(folder, report, notes)
        rebuilt: list[str] = []
        fresh: dict[str, Any] | None = None
        if problems:  # the verdict is given: a rebuild (seconds to a minute) would only repeat it per file
            notes.append("not compared with a rebuild: the files already differ from what fabricate wrote")
        else:
            progress("rebuild")
            rebuilt, fresh = _rebuild(folder, report, raw, progress, notes)
    final = fresh if fresh is not None else report
    if notes:  # a copy: the rebuilt report may be shared (cached) by the caller
        final = {**final, "notes": [*final.get("notes", []), *notes]}
    return problems + rebuilt, final
