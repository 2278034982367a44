"""Output folders: the one place fabricate writes, and the rules that keep it from destroying anything.

An output folder (``-o``) may be new, empty, or a previous fabricate output; anything else is refused
before any work is done unless the user passes ``--force``. A previous output is recognised by its
``report.json`` and must hold nothing but the files that report lists, so a note the user dropped into
a build folder is never deleted silently. A file or symbolic link given as the folder, the current
folder (or one holding it) and a folder holding the template being built are refused even with
``--force``.

Writing goes into a temporary sibling (``.NAME.XXXXXXXX.tmp``) which is swapped with the old folder in one
atomic step (``renameat2(RENAME_EXCHANGE)`` on Linux; elsewhere two renames with Ctrl-C held off), so a
reader sees the old output or the new one, never half of either. Writers of one folder are serialised
by an exclusive lock on ``.NAME.lock`` beside it; whoever holds the lock first removes what killed runs
left behind (their ``.NAME.*.tmp`` / ``.NAME.*.old`` siblings), since only a lock holder ever makes them.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import glob
import json
import os
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError

try:  # POSIX advisory locks; elsewhere writers are not serialised (documented in the README)
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

REPORT = "report.json"
#: Room the temporary sibling's name needs beyond the folder's own name (".", ".", 8 random, ".tmp").
_SIBLING_EXTRA = 14


def _refuse(out: Path, why: str) -> SpecError:
    return SpecError(f"output folder {out}", why)


def previous_output(directory: Path) -> dict[str, Any] | None:
    """The report of a fabricate output folder, or None when ``directory`` is not one."""
    try:
        report = json.loads((directory / REPORT).read_text(encoding="utf-8"))
    except (OSError, ValueError):
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


def _name_max(existing: Path) -> int:
    try:
        return int(os.pathconf(existing, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return 255


def _nearest_existing(path: Path) -> Path:
    for candidate in (path, *path.parents):
        if os.path.lexists(candidate):
            return candidate
    return Path(path.anchor)


def check_output_dir(out: str | Path, *, force: bool = False, stage: str = "build",
                     protect: Sequence[Path] = ()) -> Path:
    """Decide before any work whether ``out`` may receive a fabricate output.

    Parameters
    ----------
    out : path
        The requested output folder.
    force : bool
        Replace a folder that holds other files (never a file, a link, the current folder or one holding
        a ``protect`` path).
    stage : str
        ``"build"`` or ``"synth"``; a synth output never replaces a build unless forced.
    protect : sequence of Path
        Paths that must survive (the template being built).

    Returns
    -------
    Path
        The absolute output folder.

    Raises
    ------
    SpecError
        Naming the folder and why it is refused (the CLI exits 2 having written nothing).
    """
    out = Path(os.path.abspath(out))
    if out == Path(out.anchor):
        raise _refuse(out, "is the root of the file system")
    existing = _nearest_existing(out.parent)
    if not existing.is_dir():
        raise _refuse(out, f"cannot be created: {existing} is a file, not a folder")
    limit = _name_max(existing)
    for part in out.parts[1:]:
        if len(os.fsencode(part)) > limit - _SIBLING_EXTRA:
            raise _refuse(out, f"name '{part[:40]}...' is {len(os.fsencode(part))} bytes long; at most "
                               f"{limit - _SIBLING_EXTRA} bytes per folder name")
    if os.path.islink(out):
        raise _refuse(out, "is a symbolic link; give the folder itself")
    if os.path.lexists(out) and not out.is_dir():
        raise _refuse(out, "is a file, not a folder")
    real = out.resolve()
    cwd = Path.cwd().resolve()
    if real == cwd or real in cwd.parents:
        raise _refuse(out, "is the current folder or holds it; name a new folder for the output")
    for path in protect:
        path = Path(path).resolve()
        if path == real or real in path.parents:
            raise _refuse(out, f"holds {path.name}, the template being built")
    if out.is_dir():
        _check_replaceable(out, force, stage)
    _probe_writable(existing, out)
    return out


def _check_replaceable(out: Path, force: bool, stage: str) -> None:
    try:
        entries = sorted(p.name for p in out.iterdir())
    except OSError as exc:
        raise _refuse(out, f"cannot be read: {exc.strerror}") from exc
    if not entries or force:
        return
    report = previous_output(out)
    if report is None:
        raise _refuse(out, f"holds files fabricate did not write ({', '.join(entries[:3])}"
                           f"{', ...' if len(entries) > 3 else ''}); choose a new or empty folder, or pass "
                           "--force to replace it")
    foreign = foreign_entries(out, report)
    if foreign:
        raise _refuse(out, f"is a fabricate output but also holds {', '.join(foreign[:3])}"
                           f"{', ...' if len(foreign) > 3 else ''}, which fabricate did not write; move "
                           "them out or pass --force to replace the folder")
    previous_stage = report["design"].get("stage", "build" if "parts" in report else "synth")
    if stage == "synth" and previous_stage == "build":
        raise _refuse(out, "holds a full build; 'synth' would replace it (pass --force, or choose another "
                           "folder)")


def _probe_writable(existing: Path, out: Path) -> None:
    # os.access says yes to root on a read-only folder and cannot see a read-only mount: try it
    try:
        probe = tempfile.mkdtemp(prefix=".fabricate-probe.", dir=existing)
        os.rmdir(probe)
    except OSError as exc:
        raise _refuse(out, f"cannot be written: {existing}: {exc.strerror}") from exc


@contextlib.contextmanager
def _locked(parent: Path, name: str) -> Iterator[None]:
    """Hold the exclusive lock of output ``parent/name`` (a no-op where there are no POSIX locks)."""
    if fcntl is None:  # pragma: no cover
        yield
        return
    path = parent / f".{name}.lock"
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        fcntl.flock(fd, fcntl.LOCK_EX)
        try:
            current = os.stat(path).st_ino
        except FileNotFoundError:
            current = None
        if current == os.fstat(fd).st_ino:
            break
        os.close(fd)  # the holder before us removed this lock file: lock the new one
    try:
        yield
    finally:
        # remove the file before unlocking: a waiter then sees it gone and locks a fresh one
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)
        os.close(fd)


def remove_leftovers(parent: Path, name: str) -> list[Path]:
    """Remove temporary siblings that killed runs left for output ``parent/name``; call under its lock."""
    removed = []
    for pattern in (f".{glob.escape(name)}.*.tmp", f".{glob.escape(name)}.*.old"):
        for path in sorted(parent.glob(pattern)):
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    path.unlink()
            removed.append(path)
    return removed


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux ``renameat2``); False where the system cannot."""
    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.EPERM):
        return False
    raise OSError(err, os.strerror(err), str(b))


@contextlib.contextmanager
def _no_interrupt() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) off for a few system calls; it is delivered right after."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _write_tree(files: Mapping[str, bytes], root: Path) -> None:
    for rel, data in sorted(files.items()):
        rel_path = Path(rel)
        if rel_path.is_absolute() or ".." in rel_path.parts:
            raise ValueError(f"output path {rel} leaves the output folder")
        target = root / rel_path
        target.parent.mkdir(parents=True, exist_ok=True)
        with open(target, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    os.chmod(root, 0o755)


def write_atomically(files: Mapping[str, bytes], out_dir: str | Path,
                     before: Callable[[Path], Any] | None = None) -> Path:
    """Write ``{relative path: bytes}`` into a temporary sibling of ``out_dir`` and swap it into place.

    Under the folder's lock: leftovers of killed runs are removed, ``before(out_dir)`` runs (the caller's
    last word on whether the folder may be replaced), then the files are written and swapped in. An
    existing ``out_dir`` is replaced only once the new one is complete; on any failure (Ctrl-C included)
    the temporary folder is removed and the old output is left as it was.
    """
    out_dir = Path(os.path.abspath(out_dir))
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    with _locked(out_dir.parent, out_dir.name):
        remove_leftovers(out_dir.parent, out_dir.name)
        if before is not None:
            before(out_dir)
        _swap_in(files, out_dir)
    return out_dir


def _swap_in(files: Mapping[str, bytes], out_dir: Path) -> None:
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".tmp", dir=out_dir.parent))
    try:
        _write_tree(files, tmp)
        with _no_interrupt():
            if not os.path.lexists(out_dir):
                os.replace(tmp, out_dir)
                return
            if not _exchange(tmp, out_dir):
                old = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".old", dir=out_dir.parent))
                os.rmdir(old)
                os.replace(out_dir, old)
                os.replace(tmp, out_dir)
                tmp = old
        shutil.rmtree(tmp, ignore_errors=True)  # now the previous output
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_output(files: Mapping[str, bytes], out: str | Path, *, force: bool = False, stage: str = "build",
                 protect: Sequence[Path] = ()) -> Path:
    """Write a whole output folder safely: check it (again, under the lock), then :func:`write_atomically`.

    The folder is checked again under the lock because another writer may have filled it since the
    first check (its result, a fabricate output, may then be replaced).

    Raises
    ------
    SpecError
        The folder is refused or cannot be written (naming it and the system's reason).
    """
    out = Path(os.path.abspath(out))
    try:
        return write_atomically(files, out, before=lambda o: check_output_dir(o, force=force, stage=stage,
                                                                             protect=protect))
    except OSError as exc:
        where = exc.filename or out
        raise _refuse(out, f"cannot be written: {where}: {exc.strerror or exc}") from exc
