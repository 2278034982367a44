"""Output folders: the one place fabricate writes, and the rules that keep it from destroying anything.

An output folder (``-o``) may be new, empty, or a previous fabricate output; anything else is refused
before any work is done unless the user passes ``--force``. A previous output is recognised by its
``report.json`` (a regular file: a link, FIFO or device of that name is not read; see
:mod:`fabricate.output_read`) and must hold nothing but the files that report lists, so a note the user
dropped into a build folder is never deleted silently. A file or symbolic link given as the folder, the
current folder (or one holding it) and a folder holding an input of the command (the template, the process
profile) are refused even with ``--force``.

Writing goes into a temporary sibling ``.NAME.fabricate-XXXXXXXXXXXXXXXX.tmp`` (16 random hex digits) which
is swapped with the old folder in one atomic step (``renameat2(RENAME_EXCHANGE)`` on Linux; elsewhere two
renames with Ctrl-C held off), so a reader sees the old output or the new one, never half of either. The
swap is checked (by inode) to have put the folder fabricate wrote in place of the folder it checked; if
anything else moved in meanwhile, the swap is undone and nothing is deleted.

Writers of one folder are serialised by an exclusive lock on ``.NAME.lock`` beside it. Before the lock
holder makes a sibling it records the sibling's random part (and the inode of the folder that will sit
there) in the lock file, and a run that ends removes its lock file; so records in a lock file are the trace
of a killed run, and the next holder removes exactly the siblings recorded there that are still real
folders of this user with the recorded inode. Any other ``.NAME.*.tmp`` / ``.NAME.*.old`` is left alone
and named in a warning. The random part has a fixed length and alphabet, so a sibling's name fixes the
output's name: those of ``a`` never match those of ``a.b``.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import re
import secrets
import shutil
import stat
import tempfile
import warnings
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError
from fabricate.output_read import CLOEXEC, NOFOLLOW, NONBLOCK, REPORT, foreign_entries, not_regular, previous_output
from fabricate.stops import signals_deferred

try:  # POSIX advisory locks; elsewhere writers are not serialised (documented in the README)
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

#: Random hex digits in a temporary sibling's name (fixed, so the name before them is unambiguous).
_TOKEN_HEX = 16
#: Room a sibling's name needs beyond the folder's own name: ".", ".fabricate-", the digits, ".tmp".
_SIBLING_EXTRA = 1 + len(".fabricate-") + _TOKEN_HEX + len(".tmp")
_SIBLING = re.compile(rf"\.(?P<name>.+)\.fabricate-(?P<token>[0-9a-f]{{{_TOKEN_HEX}}})\.(?P<kind>tmp|old)", re.S)
_RECORD = re.compile(rf"(?P<token>[0-9a-f]{{{_TOKEN_HEX}}})(?: (?P<dev>[0-9]+) (?P<ino>[0-9]+))?")

Identity = tuple[int, int]


class LeftAloneWarning(UserWarning):
    """A sibling of an output folder is named like fabricate's temporary folders, but fabricate cannot
    prove it made it, so it was not removed."""


def _refuse(out: Path, why: str) -> SpecError:
    return SpecError(f"output folder {out}", why)


def sibling_name(name: str, token: str, kind: str) -> str:
    """The name of a temporary (``kind="tmp"``) or backup (``"old"``) sibling of output folder ``name``."""
    return f".{name}.fabricate-{token}.{kind}"


def parse_sibling(entry: str) -> tuple[str, str, str] | None:
    """``(output folder name, token, kind)`` of a name made by :func:`sibling_name`, else None."""
    match = _SIBLING.fullmatch(entry)
    return (match["name"], match["token"], match["kind"]) if match else None


def _identity(path: Path) -> Identity | None:
    """``(device, inode)`` of ``path`` itself (a link is not followed), None when nothing is there."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    return st.st_dev, st.st_ino


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
                     protect: Sequence[Path] | Mapping[Path, str] = ()) -> Path:
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
    protect : sequence of Path, or mapping of Path to str
        Inputs of the command, which must survive even with ``force`` (the template being built, the
        process profile); a mapping says what each is ("the template being built").

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
    what = protect if isinstance(protect, Mapping) else dict.fromkeys(protect, "an input of this command")
    for given, role in what.items():
        given = Path(given)
        # the file itself and, if it is a link, the link: neither may be inside the folder replaced
        for path in {given.resolve(), given.parent.resolve() / given.name}:
            if path == real or real in path.parents:
                raise _refuse(out, f"holds {given.name}, {role}")
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
        odd = not_regular(out / REPORT)
        if odd:
            raise _refuse(out, f"holds a report.json that is {odd}, not one fabricate wrote (it is never opened); "
                               "choose a new or empty folder, or pass --force to replace it")
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


class _Lock:
    """The held lock of one output folder; its file records the siblings the holder makes (see the module
    docstring). Without POSIX locks (``fd`` None) nothing is recorded, so no leftover is ever removed."""

    def __init__(self, fd: int | None, path: Path) -> None:
        self.fd = fd
        self.path = path
        #: Record lines to leave for the next holder: siblings of fabricate that could not be removed.
        self.keep: list[str] = []

    def records(self) -> dict[str, set[Identity | None]]:
        """What earlier (killed) holders recorded: for each token, the identities its sibling may have
        (None: recorded before the folder was made, so it can only be an empty folder)."""
        if self.fd is None:
            return {}
        data = os.pread(self.fd, 1 << 20, 0)
        found: dict[str, set[Identity | None]] = {}
        for line in data.decode("ascii", "replace").splitlines():
            match = _RECORD.fullmatch(line)
            if match:
                found.setdefault(match["token"], set()).add(
                    (int(match["dev"]), int(match["ino"])) if match["dev"] else None)
        return found

    def rewrite(self, lines: Sequence[str]) -> None:
        """Replace the records with ``lines``."""
        if self.fd is not None:
            os.ftruncate(self.fd, 0)
            if lines:
                os.write(self.fd, "".join(f"{line}\n" for line in lines).encode("ascii"))

    def record(self, token: str, ident: Identity | None = None) -> None:
        """Record a sibling before it exists. Not synced: a killed process's writes survive it, and a record
        lost with the machine only leaves a leftover alone (named in a warning), never removes a wrong one."""
        if self.fd is not None:
            os.write(self.fd, f"{token}{'' if ident is None else f' {ident[0]} {ident[1]}'}\n".encode("ascii"))


@contextlib.contextmanager
def folder_lock(out: Path, waiting: Callable[[], None] | None = None) -> Iterator[None]:
    """Hold the lock the writers of output folder ``out`` share (``.NAME.lock`` beside it) for a whole run.

    A sweep holds it from the check of its folder to its last file, so that a second sweep into the folder waits
    and then resumes what the first recorded, instead of appending to the same journal; a build into the folder
    waits too. ``out``'s parent must exist. ``waiting`` is called once where another run holds the lock.
    """
    with _locked(out.parent, out.name, waiting):
        yield


@contextlib.contextmanager
def _locked(parent: Path, name: str, waiting: Callable[[], None] | None = None) -> Iterator[_Lock]:
    """Hold the exclusive lock of output ``parent/name`` (nothing is locked where there are no POSIX locks);
    ``waiting`` is called once before blocking on another holder."""
    path = parent / f".{name}.lock"
    if fcntl is None:  # pragma: no cover
        yield _Lock(None, path)
        return
    while True:
        try:  # never through a link, never blocking on a FIFO someone named like the lock
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_APPEND | NOFOLLOW | NONBLOCK | CLOEXEC, 0o644)
        except OSError as exc:
            if exc.errno not in (errno.ELOOP, errno.EISDIR, errno.ENXIO):
                raise
            fd = None
        st = os.fstat(fd) if fd is not None else None
        if fd is None or st is None or not stat.S_ISREG(st.st_mode):
            if fd is not None:
                os.close(fd)
            raise _refuse(parent / name, f"its lock file {path} is not a plain file; fabricate makes it and "
                                         "removes it after writing: remove what is there")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            if waiting is not None:
                waiting()
                waiting = None
            fcntl.flock(fd, fcntl.LOCK_EX)
        if _identity(path) == (st.st_dev, st.st_ino):
            break
        os.close(fd)  # the holder before us removed this lock file: lock the new one
    lock = _Lock(fd, path)
    try:
        yield lock
    finally:
        try:
            if lock.keep:  # siblings fabricate made but could not remove: the next holder tries again
                lock.rewrite(lock.keep)
            else:
                # remove the file before unlocking: a waiter then sees it gone and locks a fresh one
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(path)
        finally:
            os.close(fd)


@dataclass
class Leftovers:
    """What :func:`remove_leftovers` found beside an output folder.

    Attributes
    ----------
    removed : list of Path
        Siblings fabricate made (recorded in the lock by a killed run), removed.
    left_alone : list of Path
        Siblings named like fabricate's (``.NAME.*.tmp``, ``.NAME.*.old``) that fabricate cannot prove it
        made: not touched.
    stuck : list of str
        Records of siblings fabricate made but could not remove (kept in the lock for the next run).
    """

    removed: list[Path] = field(default_factory=list)
    left_alone: list[Path] = field(default_factory=list)
    stuck: list[str] = field(default_factory=list)


def _looks_like_ours(entry: str, name: str) -> bool:
    """Whether ``entry`` matches ``.NAME.*.tmp`` / ``.NAME.*.old`` (what fabricate once removed unasked)."""
    prefix = f".{name}."
    return entry.startswith(prefix) and entry.endswith((".tmp", ".old")) and len(entry) >= len(prefix) + 4


def remove_leftovers(parent: Path, name: str, made: Mapping[str, Collection[Identity | None]] | None = None
                     ) -> Leftovers:
    """Remove the siblings of output ``parent/name`` that killed runs of fabricate left; call under its lock.

    Parameters
    ----------
    parent, name : Path, str
        The output folder ``parent/name``.
    made : mapping of str to identities, optional
        The lock's records (:meth:`_Lock.records`): a sibling is removed only if its name carries a
        recorded token and it is a real folder (not a link) owned by this user whose ``(device, inode)``
        was recorded, or an empty folder recorded before it was made. Without records nothing is removed.

    Returns
    -------
    Leftovers
        What was removed, and what was left alone (to be named in a warning).
    """
    found = Leftovers()
    try:
        entries = sorted(os.listdir(parent))
    except OSError:
        return found
    uid = os.geteuid() if hasattr(os, "geteuid") else None
    for entry in entries:
        if not _looks_like_ours(entry, name):
            continue
        parsed = parse_sibling(entry)
        if parsed is not None and parsed[0] != name:
            continue  # another output's sibling (".a.b.fabricate-....tmp" for output "a"): not ours to judge
        path = parent / entry
        idents = set((made or {}).get(parsed[1], ())) if parsed else set()
        try:
            st = os.lstat(path)
        except FileNotFoundError:
            continue
        ident = (st.st_dev, st.st_ino)
        mine = parsed is not None and stat.S_ISDIR(st.st_mode) and (uid is None or st.st_uid == uid)
        if mine and parsed is not None and ident in idents:
            shutil.rmtree(path, ignore_errors=True)
            if _identity(path) == ident:
                found.stuck.append(f"{parsed[1]} {ident[0]} {ident[1]}")
            else:
                found.removed.append(path)
        elif mine and None in idents:  # made by a run killed before it recorded the inode: still empty
            try:
                os.rmdir(path)
                found.removed.append(path)
            except OSError:
                found.left_alone.append(path)
        else:
            found.left_alone.append(path)
    return found


def _renameat2(a: Path, b: Path, flags: int) -> bool:
    """Linux ``renameat2(a, b, flags)``; False where the system cannot (then nothing was done)."""
    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd = -100
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), flags) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.EPERM):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (``RENAME_EXCHANGE``); False where the system cannot."""
    return _renameat2(a, b, 2)


def _rename_new(a: Path, b: Path) -> None:
    """Rename ``a`` to ``b`` only if nothing is at ``b`` (``RENAME_NOREPLACE`` where there is one)."""
    if _renameat2(a, b, 1):
        return
    if os.path.lexists(b):  # a plain rename would replace an empty folder or fail confusingly
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(b))
    os.rename(a, b)


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


def _warn_default(message: str) -> None:
    warnings.warn(message, LeftAloneWarning, stacklevel=4)


def write_atomically(files: Mapping[str, bytes], out_dir: str | Path,
                     before: Callable[[Path], Any] | None = None, *,
                     warn: Callable[[str], Any] | None = None) -> Path:
    """Write ``{relative path: bytes}`` into a temporary sibling of ``out_dir`` and swap it into place.

    Under the folder's lock: leftovers of killed runs are removed (only those the lock's records prove
    fabricate made; every other ``.NAME.*.tmp`` / ``.NAME.*.old`` is named by ``warn``, by default a
    :class:`LeftAloneWarning`), ``before(out_dir)`` runs (the caller's last word on whether the folder may
    be replaced), then the files are written and swapped in. An existing ``out_dir`` is replaced only once
    the new one is complete, and only if it is still the folder ``before`` saw; on any failure (Ctrl-C
    included) the temporary folder is removed and the old output is left as it was.

    Raises
    ------
    SpecError
        The folder or the temporary one changed while fabricate wrote (nothing replaced, nothing deleted).
    """
    out_dir = Path(os.path.abspath(out_dir))
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    say = warn or _warn_default
    with _locked(out_dir.parent, out_dir.name) as lock:
        found = remove_leftovers(out_dir.parent, out_dir.name, lock.records())
        lock.keep = list(found.stuck)
        lock.rewrite(lock.keep)  # the killed runs' records are done with; this run records its own
        for path in found.left_alone:
            say(f"left {path.name} alone: fabricate did not make it")
        if before is not None:
            before(out_dir)
        _swap_in(files, out_dir, lock, _identity(out_dir))
    return out_dir


def _changed(out: Path, what: str) -> SpecError:
    return _refuse(out, f"{what} while fabricate wrote the new output; nothing was replaced or deleted "
                        "(run the command again)")


def _remove_ours(path: Path, ident: Identity | None, lock: _Lock) -> None:
    """Remove folder ``path`` if it is still the one fabricate made (``ident``); else leave it."""
    if ident is None or _identity(path) != ident:
        return
    shutil.rmtree(path, ignore_errors=True)
    if _identity(path) == ident:  # e.g. a file in it cannot be removed: the next run tries again
        parsed = parse_sibling(path.name)
        if parsed is not None:
            lock.keep.append(f"{parsed[1]} {ident[0]} {ident[1]}")


def _swap_in(files: Mapping[str, bytes], out_dir: Path, lock: _Lock, checked: Identity | None) -> None:
    """Write ``files`` into a new sibling and put it at ``out_dir``, which must still be ``checked``."""
    parent, name = out_dir.parent, out_dir.name
    token = secrets.token_hex(_TOKEN_HEX // 2)
    tmp = parent / sibling_name(name, token, "tmp")
    lock.record(token)  # before the folder exists: a run killed right after mkdir leaves a recorded folder
    os.mkdir(tmp, 0o700)
    st = os.lstat(tmp)
    ours = (st.st_dev, st.st_ino)
    lock.record(token, ours)
    try:
        _write_tree(files, tmp)
        with signals_deferred():
            previous = _swap(tmp, ours, out_dir, checked, lock)
    except BaseException:
        _remove_ours(tmp, ours, lock)  # only if the folder there is still the one made here
        raise
    if previous is not None:
        _remove_ours(previous, checked, lock)  # the previous output, verified to be the one checked


def _swap(tmp: Path, ours: Identity, out_dir: Path, checked: Identity | None, lock: _Lock) -> Path | None:
    """Put folder ``tmp`` (identity ``ours``) at ``out_dir`` in place of ``checked`` (None: nothing).

    Returns where the previous output now is (to be removed), None when there was none.
    """
    if _identity(tmp) != ours:
        raise _changed(out_dir, f"its temporary folder {tmp.name} was replaced")
    if _identity(out_dir) != checked:
        raise _changed(out_dir, "it was created, replaced or removed" if checked is None or
                       _identity(out_dir) is None else "it was replaced by another folder")
    if checked is None:
        try:
            _rename_new(tmp, out_dir)
        except FileExistsError:
            raise _changed(out_dir, "it was created") from None
        if _identity(out_dir) != ours:
            raise _changed(out_dir, "it was replaced right after the swap")
        return None
    token = parse_sibling(tmp.name)[1]  # type: ignore[index]
    lock.record(token, checked)  # the previous output will be at tmp's name
    if _exchange(tmp, out_dir):
        if _identity(out_dir) == ours and _identity(tmp) == checked:
            return tmp
        # someone swapped a folder in between the checks and the exchange: put both back, delete nothing
        _exchange(tmp, out_dir)
        raise _changed(out_dir, "it or its temporary folder was replaced")
    old = tmp.parent / sibling_name(out_dir.name, secrets.token_hex(_TOKEN_HEX // 2), "old")
    lock.record(parse_sibling(old.name)[1], checked)  # type: ignore[index]
    os.rename(out_dir, old)
    if _identity(old) != checked:
        os.rename(old, out_dir)
        raise _changed(out_dir, "it was replaced by another folder")
    try:
        _rename_new(tmp, out_dir)
    except BaseException:
        with contextlib.suppress(OSError):
            _rename_new(old, out_dir)  # the previous output back in place
        raise
    if _identity(out_dir) != ours:
        raise _changed(out_dir, "it was replaced right after the swap")
    return old


def write_output(files: Mapping[str, bytes], out: str | Path, *, force: bool = False, stage: str = "build",
                 protect: Sequence[Path] | Mapping[Path, str] = (),
                 warn: Callable[[str], Any] | None = None) -> Path:
    """Write a whole output folder safely: check it (again, under the lock), then :func:`write_atomically`.

    The folder is checked again under the lock because another writer may have filled it since the
    first check (its result, a fabricate output, may then be replaced). ``warn`` receives one line per
    sibling left alone (default: a :class:`LeftAloneWarning`).

    Raises
    ------
    SpecError
        The folder is refused or cannot be written (naming it and the system's reason).
    """
    out = Path(os.path.abspath(out))
    try:
        return write_atomically(files, out, before=lambda o: check_output_dir(o, force=force, stage=stage,
                                                                             protect=protect), warn=warn)
    except OSError as exc:
        where = exc.filename or out
        raise _refuse(out, f"cannot be written: {where}: {exc.strerror or exc}") from exc
