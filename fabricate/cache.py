"""A content-addressed cache of stage results: edit one table of a template, rebuild, and only the stages that
read it run again.

A stage's result is stored under the sha256 of

- the stage's name,
- a canonical text (:func:`canonical`) of exactly the inputs the stage reads: the design's sections it reads
  (the frozen dataclasses of :class:`~fabricate.spec.DesignSpec`, field by field) and the keys of the stages
  whose results it takes (which are in turn functions of their own inputs), and
- the code that computes it (:func:`code_fingerprint`): fabricate's version, a hash of every ``.py``, ``.json``
  and ``.toml`` file of the package and of the shipped templates folder (an editable install whose source
  changed never gets a result of the older code), Python's version and the versions of the numeric and
  geometry libraries whose results end up in the files.

Two layers: an in-process one (pickled bytes, so a hit is a fresh object nobody else holds and behaves as a
disk hit does; bounded at :data:`MEMORY_MAX_BYTES`) and a disk one in the user cache folder
(:func:`cache_dir`: ``$FABRICATE_CACHE_DIR``, else ``$XDG_CACHE_HOME/fabricate``, else ``~/.cache/fabricate``),
bounded at ``$FABRICATE_CACHE_MAX_MB`` (default :data:`DEFAULT_MAX_MB`) by removing the least recently used
entries after a write. An entry is written atomically (a temporary file in the same folder, then
``os.replace``) and carries a header with its key and the sha256 of its pickle: a truncated, corrupt, foreign or
unreadable entry is a miss (and is removed), never an error. A result that cannot be pickled (a method's closure)
is simply not cached.

The cache is off unless a caller turns it on (:func:`use_cache`): the command line does for ``build``, ``synth``
and ``sweep`` unless ``--no-cache`` is given or ``$FABRICATE_NO_CACHE`` is set; ``fabricate check`` never does
(neither reads nor writes), so its verdict is always a rebuild from scratch. Pickles are only ever read from the
user's own cache folder (created with mode 0700).

The stages and the design sections each reads are stated with their key functions in
:mod:`fabricate.stage_keys` (``synthesis_key``, ``gears_key``, ``parts_key``, ...); ``tests/test_cache.py`` traces
the attributes each stage reads from the design on every shipped template and fails when a stage reads a field its
key leaves out.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import json
import math
import os
import pickle
import sys
import tempfile
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path, PurePath
from typing import Any, TypeVar

T = TypeVar("T")

#: Pickle protocol of every entry (fixed: a new Python's default must not change what is written).
PICKLE_PROTOCOL = 5
#: Default bound of the disk cache (``$FABRICATE_CACHE_MAX_MB`` overrides it): a build of the default finger
#: stores about 4.5 MB (STEP files included), the eight shipped templates 39 MB, so this holds about 100 builds.
DEFAULT_MAX_MB = 500
#: Bound of the in-process layer (pickled bytes held), least recently used dropped first.
MEMORY_MAX_BYTES = 256 * 1024 * 1024
#: The first bytes of every entry; the layout version is in it and in the folder name.
MAGIC = b"fabricate-cache-1\n"
#: The distributions whose versions are part of every key: their numbers or bytes end up in the outputs.
LIBRARIES = ("numpy", "scipy", "shapely", "trimesh", "manifold3d", "ezdxf", "matplotlib", "pillow",
             "cadquery-ocp", "cadquery-ocp-novtk", "mujoco")
#: What a key's code hash covers in the package (and the shipped templates folder).
SOURCE_SUFFIXES = (".py", ".json", ".toml")

_lock = threading.RLock()


def _new_lock() -> None:
    # a forked child (the build's picture child) must not inherit the lock held by another thread of its parent
    global _lock
    _lock = threading.RLock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_new_lock)
_enabled = False
_disk = True
_memory: OrderedDict[str, bytes] = OrderedDict()
_memory_bytes = 0
_fingerprint: str | None = None
#: Seconds the code fingerprint took in this process (measured once; see code_fingerprint).
fingerprint_seconds = 0.0
#: This process's counts of ``hits`` (memory or disk), ``misses`` and ``stores``, per stage: for tests and
#: benchmarks (a hit is not visible in the files, by design).
stats: dict[str, dict[str, int]] = {}


# -- the switch ------------------------------------------------------------------------------------------------

def enabled() -> bool:
    """Whether :func:`cached` reads and writes the cache now (see :func:`use_cache`)."""
    return _enabled and not os.environ.get("FABRICATE_NO_CACHE")


@contextmanager
def use_cache(on: bool = True, *, disk: bool = True) -> Iterator[None]:
    """Turn the cache on (or off) for the ``with`` block, process-wide (threads included), then restore.

    Parameters
    ----------
    on : bool
        Read and write stage results. ``$FABRICATE_NO_CACHE`` (any non-empty value) keeps it off regardless.
    disk : bool
        Use the disk layer too; False keeps the in-process layer only (e.g. a sweep's workers that share
        results within one run without writing to the user's folder).
    """
    global _enabled, _disk
    with _lock:
        before = (_enabled, _disk)
        _enabled, _disk = bool(on), bool(disk)
    try:
        yield
    finally:
        with _lock:
            _enabled, _disk = before


def clear_memory() -> None:
    """Forget the in-process layer (the disk layer stays)."""
    global _memory_bytes
    with _lock:
        _memory.clear()
        _memory_bytes = 0


# -- where -----------------------------------------------------------------------------------------------------

def cache_dir() -> Path:
    """The disk cache's folder: ``$FABRICATE_CACHE_DIR``, else ``$XDG_CACHE_HOME/fabricate``, else
    ``~/.cache/fabricate`` (entries go in its ``stages-1`` subfolder)."""
    given = os.environ.get("FABRICATE_CACHE_DIR")
    if given:
        return Path(given)
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg and Path(xdg).is_absolute():  # the XDG spec: a relative value is invalid and ignored
        return Path(xdg) / "fabricate"
    return Path.home() / ".cache" / "fabricate"


def max_bytes() -> int:
    """The disk layer's bound in bytes (``$FABRICATE_CACHE_MAX_MB``, default :data:`DEFAULT_MAX_MB`)."""
    text = os.environ.get("FABRICATE_CACHE_MAX_MB", "")
    try:
        mb = float(text) if text else DEFAULT_MAX_MB
    except ValueError:
        mb = DEFAULT_MAX_MB
    if not math.isfinite(mb) or mb < 0:
        mb = DEFAULT_MAX_MB
    return int(mb * 1024 * 1024)


def _entries_dir() -> Path:
    return cache_dir() / "stages-1"


# -- keys ------------------------------------------------------------------------------------------------------

def code_fingerprint() -> str:
    """sha256 of the code a result depends on, computed once per process.

    Covers fabricate's version, every ``.py``/``.json``/``.toml`` file of the package and of the shipped
    templates folder (path and content), Python's version, the machine, the pickle protocol and the versions
    of :data:`LIBRARIES`. About 10-30 ms (:data:`fingerprint_seconds` records it).
    """
    global _fingerprint, fingerprint_seconds
    if _fingerprint is not None:
        return _fingerprint
    import platform
    import time

    import fabricate
    from fabricate.templates import TEMPLATE_DIR

    start = time.perf_counter()
    digest = hashlib.sha256()
    digest.update(f"fabricate {fabricate.__version__}\npython {sys.version}\n{platform.machine()}\n"
                  f"pickle {PICKLE_PROTOCOL}\n".encode())
    versions = installed_versions()
    for name in LIBRARIES:
        digest.update(f"{name} {versions.get(_normal(name), '-')}\n".encode())
    digest.update(source_digest((Path(fabricate.__file__).resolve().parent, Path(TEMPLATE_DIR).resolve())).encode())
    _fingerprint = digest.hexdigest()
    fingerprint_seconds = time.perf_counter() - start
    return _fingerprint


def _normal(name: str) -> str:
    return name.lower().replace("-", "_").replace(".", "_")


def installed_versions() -> dict[str, str]:
    """``{normalised distribution name: version}`` of every distribution on ``sys.path``, from the names of
    their ``.dist-info``/``.egg-info`` folders (the first on the path wins, as for imports). One directory listing
    per path entry: ``importlib.metadata.version`` took ~10 ms a library on a busy machine."""
    found: dict[str, str] = {}
    for entry in sys.path:
        try:
            names = os.listdir(entry or ".")
        except OSError:
            continue
        for name in names:
            stem, dot, suffix = name.rpartition(".")
            if not dot or suffix not in ("dist-info", "egg-info") or "-" not in stem:
                continue
            dist, _, version = stem.partition("-")
            found.setdefault(_normal(dist), version.partition("-")[0])
    return found


def source_digest(roots: tuple[Path, ...]) -> str:
    """sha256 of every ``.py``/``.json``/``.toml`` file under ``roots`` (each file's path under its root and its
    content's sha256, in sorted order; ``__pycache__`` left out). A missing root counts as empty."""
    digest = hashlib.sha256()
    for root in roots:
        if not root.is_dir():
            continue
        files = sorted(p for p in root.rglob("*") if p.suffix in SOURCE_SUFFIXES and "__pycache__" not in p.parts
                       and p.is_file())
        for path in files:
            digest.update(f"{root.name}/{path.relative_to(root).as_posix()}\n".encode())
            digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


def canonical(value: Any) -> str:
    """A text that is equal for two values exactly when they are equal as a stage sees them.

    Numbers keep their type and every bit (``float.hex``: 0.1 and 0.1000000001 differ, and so do 1 and 1.0);
    dataclasses (the spec's frozen sections) are named by their class and listed field by field; mappings and
    sets are sorted; numpy arrays are their dtype, shape and the sha256 of their bytes.

    Raises
    ------
    TypeError
        For a value of any other type (a key must never silently drop an input).
    """
    out: list[str] = []
    _canonical(value, out)
    return "".join(out)


def _canonical(value: Any, out: list[str]) -> None:
    if value is None or isinstance(value, (bool, str)):
        out.append(json.dumps(value))
    elif isinstance(value, enum.Enum):
        out.append(f"enum:{type(value).__module__}.{type(value).__qualname__}.{value.name}")
    elif isinstance(value, int):
        out.append(f"i:{int(value)}")
    elif isinstance(value, float):
        out.append(f"f:{float(value).hex()}")
    elif isinstance(value, PurePath):
        out.append(f"path:{json.dumps(str(value))}")
    elif isinstance(value, bytes):
        out.append(f"bytes:{hashlib.sha256(value).hexdigest()}")
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        out.append(f"dc:{type(value).__module__}.{type(value).__qualname__}{{")
        for f in dataclasses.fields(value):
            out.append(f"{f.name}=")
            _canonical(getattr(value, f.name), out)
            out.append(",")
        out.append("}")
    elif isinstance(value, (list, tuple)):
        out.append("[" if isinstance(value, list) else "(")
        for item in value:
            _canonical(item, out)
            out.append(",")
        out.append("]" if isinstance(value, list) else ")")
    elif isinstance(value, Mapping):
        items = sorted((canonical(k), canonical(v)) for k, v in value.items())
        out.append("{" + ",".join(f"{k}:{v}" for k, v in items) + "}")
    elif isinstance(value, (set, frozenset)):
        out.append("set{" + ",".join(sorted(canonical(v) for v in value)) + "}")
    else:
        import numpy as np

        if isinstance(value, np.ndarray):
            data = np.ascontiguousarray(value)
            out.append(f"nd:{data.dtype.str}{data.shape}:{hashlib.sha256(data.tobytes()).hexdigest()}")
        elif isinstance(value, np.generic):
            _canonical(value.item(), out)
        else:
            raise TypeError(f"no canonical form for a {type(value).__module__}.{type(value).__qualname__}")


def stage_key(stage: str, key_parts: Any) -> str:
    """The entry's name: sha256 of the stage, the canonical text of ``key_parts`` and :func:`code_fingerprint`."""
    text = f"{stage}\n{code_fingerprint()}\n{canonical(key_parts)}"
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


# -- the store ---------------------------------------------------------------------------------------------------

def _count(stage: str, what: str) -> None:
    with _lock:
        stats.setdefault(stage, {"hits": 0, "misses": 0, "stores": 0})[what] += 1


def cached(stage: str, key_parts: Any, compute: Callable[[], T]) -> T:
    """``compute()``, or the result stored for the same stage and inputs.

    Parameters
    ----------
    stage : str
        The stage's name (part of the key; the statistics are per stage).
    key_parts : object
        Every input the stage reads, as values :func:`canonical` takes (a key function's result).
    compute : callable
        Makes the result when it is not stored. Exceptions pass through and nothing is stored.

    When the cache is off (:func:`enabled`), or ``key_parts`` has no canonical form, or the result cannot be
    pickled, this is ``compute()`` and nothing is stored. A hit is unpickled afresh each time (never an object
    another caller holds).
    """
    if not enabled():
        return compute()
    try:
        key = stage_key(stage, key_parts)
    except TypeError:  # a value without a canonical form: never guess a key
        return compute()
    data = _memory_get(key)
    if data is None and _disk:
        data = _disk_get(key)
        if data is not None:
            _memory_put(key, data)
    if data is not None:
        try:
            value: T = pickle.loads(data)
        except Exception:  # noqa: BLE001 - whatever a stale pickle raises, it is a miss
            _forget(key)
        else:
            _count(stage, "hits")
            return value
    _count(stage, "misses")
    value = compute()
    try:
        data = pickle.dumps(value, protocol=PICKLE_PROTOCOL)
    except Exception:  # noqa: BLE001 - a closure or a kernel object: not cacheable, still a result
        return value
    _memory_put(key, data)
    if _disk:
        _disk_put(key, data)
    _count(stage, "stores")
    return value


def stored(stage: str, key_parts: Any) -> bool:
    """Whether :func:`cached` would find an entry for ``stage`` and ``key_parts`` now (without reading it; an
    entry found here may still turn out corrupt, then it is a miss): lets a caller skip preparing work, such as
    starting the STEP worker, that a hit makes useless. False when the cache is off."""
    if not enabled():
        return False
    try:
        key = stage_key(stage, key_parts)
    except TypeError:
        return False
    with _lock:
        if key in _memory:
            return True
    return _disk and _entry_path(key).is_file()


def _memory_get(key: str) -> bytes | None:
    with _lock:
        data = _memory.get(key)
        if data is not None:
            _memory.move_to_end(key)
        return data


def _memory_put(key: str, data: bytes) -> None:
    global _memory_bytes
    if len(data) > MEMORY_MAX_BYTES // 4:
        return
    with _lock:
        if key in _memory:
            return
        _memory[key] = data
        _memory_bytes += len(data)
        while _memory_bytes > MEMORY_MAX_BYTES and _memory:
            _, old = _memory.popitem(last=False)
            _memory_bytes -= len(old)


def _forget(key: str) -> None:
    global _memory_bytes
    with _lock:
        old = _memory.pop(key, None)
        if old is not None:
            _memory_bytes -= len(old)
    try:
        _entry_path(key).unlink()
    except OSError:
        pass


def _entry_path(key: str) -> Path:
    return _entries_dir() / key[:2] / f"{key}.pkl"


def _disk_get(key: str) -> bytes | None:
    """The pickle stored under ``key``, or None: missing, unreadable, foreign or corrupt (then removed)."""
    path = _entry_path(key)
    try:
        blob = path.read_bytes()
    except (OSError, ValueError):
        return None
    head = len(MAGIC) + 64 + 1 + 64 + 1
    ok = (blob.startswith(MAGIC) and blob[len(MAGIC):len(MAGIC) + 64] == key.encode("ascii")
          and hashlib.sha256(blob[head:]).hexdigest().encode("ascii") == blob[len(MAGIC) + 65:head - 1])
    if not ok:
        try:
            path.unlink()
        except OSError:
            pass
        return None
    try:
        os.utime(path)  # least recently used goes first when the folder is over its bound
    except OSError:
        pass
    return blob[head:]


def _disk_put(key: str, data: bytes) -> None:
    """Store atomically (temporary file in the same folder, then ``os.replace``); a failure is silent."""
    path = _entry_path(key)
    header = MAGIC + key.encode("ascii") + b"\n" + hashlib.sha256(data).hexdigest().encode("ascii") + b"\n"
    tmp = None
    try:
        if not path.parent.is_dir():  # the cache's own folders private (their parents as the system makes them)
            cache_dir().mkdir(parents=True, exist_ok=True, mode=0o700)
            _entries_dir().mkdir(exist_ok=True, mode=0o700)
            path.parent.mkdir(exist_ok=True, mode=0o700)
        fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".pkl", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(header)
            fh.write(data)
        os.replace(tmp, path)
        tmp = None
    except OSError:
        return
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
    _evict(max_bytes())


def _evict(bound: int) -> None:
    """Remove the least recently used entries while the folder holds more than ``bound`` bytes (to 80 %)."""
    entries = []
    total = 0
    try:
        for sub in os.scandir(_entries_dir()):
            if not sub.is_dir(follow_symlinks=False):
                continue
            for entry in os.scandir(sub.path):
                if entry.name.endswith(".pkl") and entry.is_file(follow_symlinks=False):
                    st = entry.stat(follow_symlinks=False)
                    entries.append((st.st_mtime, st.st_size, entry.path))
                    total += st.st_size
    except OSError:
        return
    if total <= bound:
        return
    for _, size, path in sorted(entries):
        try:
            os.unlink(path)
        except OSError:
            continue
        total -= size
        if total <= 0.8 * bound:
            break
