"""Shared fixtures: small mechanisms built from first principles (no template, no synthesis), the
process profiles, and every shipped template built once per test session (``shipped_build``).

Markers: ``slow`` (registered in pyproject.toml) marks full builds of shipped templates and other tests of
several seconds; ``python -m pytest -m "not slow"`` is the day-to-day subset, the whole suite the CI's.
Hypothesis runs without its wall-clock deadline and "too slow" health check: on a loaded machine those fail
a correct test (the suite must pass with the cores busy).
"""

from __future__ import annotations

import copy
import fcntl
import hashlib
import io
import json
import math
import os
import shutil
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager, redirect_stderr, redirect_stdout
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from fabricate import cache
from fabricate.design import load_design
from fabricate.export.step import step_available as _step_available
from fabricate.mechanism import Body, Driver, Mechanism, Revolute
from fabricate.pipeline import BuildOutcome, run_build
from fabricate.planar import circle_circle_intersection
from fabricate.process import ProcessSpec

# Test modules' own @settings(...) inherit what they do not set from this profile.
settings.register_profile("fabricate", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("fabricate")


@pytest.fixture(autouse=True, scope="session")
def _no_stage_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """The suite never touches the user's stage cache (fabricate/cache.py): its folder is a temporary one, and the
    cache is off (``FABRICATE_NO_CACHE``, which subprocesses inherit too), so a CLI build in one test never serves
    another's stages (one that monkeypatches a stage must see it run). tests/test_cache.py turns it on to test it."""
    patch = pytest.MonkeyPatch()
    patch.setenv("FABRICATE_CACHE_DIR", str(tmp_path_factory.mktemp("stage-cache")))
    patch.setenv("FABRICATE_NO_CACHE", "1")
    yield
    patch.undo()


def make_four_bar(crank: float = 15.0, coupler: float = 40.0, rocker: float = 30.0, ground: float = 40.0,
                  start_deg: float = 60.0, end_deg: float = 420.0, upper: bool = True) -> Mechanism:
    """A crank-rocker four-bar O-A-B-D (ground O-D on +x), crank driven from ``start_deg``.

    Bodies: ground (O, D), crank (O, A), coupler (A, B), rocker (D, B); each body's frame has its
    first joint at the origin and its second on +x.
    """
    th = math.radians(start_deg)
    a = np.array([crank * math.cos(th), crank * math.sin(th)])
    d = np.array([ground, 0.0])
    b = circle_circle_intersection(a, coupler, d, rocker)[0 if upper else 1]

    def frame(p0: np.ndarray, p1: np.ndarray) -> tuple[float, float, float]:
        return (float(p0[0]), float(p0[1]), math.atan2(p1[1] - p0[1], p1[0] - p0[0]))

    return Mechanism(
        name="four_bar",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (ground, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (crank, 0.0)}),
                Body("coupler", {"A": (0.0, 0.0), "B": (coupler, 0.0)}),
                Body("rocker", {"D": (0.0, 0.0), "B": (rocker, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker")),
        gears=(),
        drivers=(Driver("angle", "crank", "ground"),),
        input_range=(start_deg, end_deg),
        assembly={"crank": (0.0, 0.0, th), "coupler": frame(a, b), "rocker": frame(d, b)},
    )


@pytest.fixture
def four_bar() -> Mechanism:
    return make_four_bar()


@pytest.fixture
def sla_process() -> ProcessSpec:
    return ProcessSpec(name="sla", running_clearance_mm=0.25, hole_compensation_mm=0.2, min_wall_mm=0.8,
                       min_pin_mm=1.5, layer_gap_mm=0.3, thickness_mm=3.0, kerf_mm=0.0, min_feature_mm=0.3,
                       build_volume_mm=(130.0, 80.0, 160.0), pin_diameter_mm=2.0, chord_tolerance_mm=0.005)


@pytest.fixture
def laser_process() -> ProcessSpec:
    return ProcessSpec(name="laser", running_clearance_mm=0.1, hole_compensation_mm=0.0, min_wall_mm=3.0,
                       min_pin_mm=2.0, layer_gap_mm=0.5, thickness_mm=3.0, kerf_mm=0.2, min_feature_mm=0.5,
                       build_volume_mm=(600.0, 400.0, 3.0), pin_diameter_mm=3.0, chord_tolerance_mm=0.005,
                       technique="cut", layout="sheet", retention="clip", press_fit_interference_mm=0.0)


#: ``{template name: outcome}`` of this test process (each pytest-xdist worker has its own).
_SHIPPED_BUILDS: dict[str, BuildOutcome] = {}


def session_folder(factory: pytest.TempPathFactory) -> Path:
    """A folder every worker of this test session shares: pytest-xdist gives each worker its own basetemp
    inside one session folder (``pytest-N/popen-gwK``); without xdist the basetemp is the session's."""
    base = factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@contextmanager
def locked(path: Path) -> Iterator[None]:
    """The block under an exclusive lock on file ``path``, across the session's processes: the first worker to
    need a shared result makes it, the other waits and reads it."""
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        yield


@pytest.fixture(scope="session")
def shipped_build(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., BuildOutcome]:
    """``shipped_build(name, process=None)``: ``run_build(load_design(name, process))`` of a shipped template,
    built once per test session and shared by every test that only reads it.

    The first worker to ask builds it cold with the stage cache on, in a folder the session's workers share
    (an exclusive lock per template, so the other worker waits instead of building it too); every other
    worker's build is then served by the cache (whose byte-identity to a cold build tests/test_cache.py
    proves), about 0.3 s instead of 3-20 s. The cache is on only inside this call: the rest of the suite keeps
    ``FABRICATE_NO_CACHE`` and an empty in-process layer, so a test that monkeypatches a stage still sees it run.

    The outcome is shared: a test must not change it (copy what it edits). ``run_build`` is the real
    pipeline's, bound at import, so a module that monkeypatches ``fabricate.pipeline.run_build`` does not
    change what is cached here.
    """
    shared = session_folder(tmp_path_factory)
    store = stage_cache_folder(tmp_path_factory)

    def get(name: str, process: str | None = None) -> BuildOutcome:
        """``process``: a shipped profile's name, as ``--process`` gives it (``"laser"``, ``"fdm"``)."""
        key = name if process is None else f"{name}--process-{process}"
        if key not in _SHIPPED_BUILDS:
            design = load_design(name, process)
            with locked(shared / f"shipped-{key}.lock"), _stage_cache_in(store):
                _SHIPPED_BUILDS[key] = run_build(design)
        return _SHIPPED_BUILDS[key]

    return get


def stage_cache_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The stage cache folder ``shipped_build`` fills and ``shared_stage_cache`` uses, shared by the session's
    workers."""
    store = session_folder(tmp_path_factory) / "shipped-stage-cache"
    store.mkdir(exist_ok=True)
    return store


#: ``keep_verdicts``' verdicts in this process, by (file name, sha256 of its bytes, expectation, OCP there).
_VERDICTS: dict[tuple[str, str, str, bool], list[str]] = {}


def keep_verdicts(monkeypatch: pytest.MonkeyPatch, shared: Path | None = None) -> None:
    """``fabricate.verify_files.content_problems`` kept by content for the session: a check's reading of a file
    back (STEP with OCP, meshes, drawings, pictures) is most of its time once its rebuild is kept, and a
    tampering of one file leaves the others as they were. A file's verdict is a function of its name, bytes and
    expectation, and of whether OCP is there to read STEP; a changed file has another hash and is read for real.
    ``shared``: a folder where the verdicts are also kept for the session's other workers (a JSON file per key,
    made under a lock by the first to ask)."""
    import fabricate.export.step as step
    import fabricate.verify_files as verify_files

    real = verify_files.content_problems

    def kept(rel: str, data: bytes, expected: object) -> list[str]:
        key = (rel, hashlib.sha256(data).hexdigest(), repr(expected), step.step_available())
        if key not in _VERDICTS:
            if shared is None:
                _VERDICTS[key] = list(real(rel, data, expected))
            else:
                name = hashlib.sha256(repr(key).encode()).hexdigest()[:32]
                path = shared / f"{name}.json"
                with locked(shared / f"{name}.lock"):
                    if path.is_file():
                        _VERDICTS[key] = json.loads(path.read_text(encoding="utf-8"))
                    else:
                        _VERDICTS[key] = list(real(rel, data, expected))
                        path.with_suffix(".part").write_text(json.dumps(_VERDICTS[key]), encoding="utf-8")
                        path.with_suffix(".part").replace(path)
        return list(_VERDICTS[key])

    monkeypatch.setattr(verify_files, "content_problems", kept)


@contextmanager
def _stage_cache_in(store: Path) -> Iterator[None]:
    """The stage cache on in folder ``store`` for the block, its in-process layer and counts as they were after."""
    patch = pytest.MonkeyPatch()
    patch.setenv("FABRICATE_CACHE_DIR", str(store))
    patch.delenv("FABRICATE_NO_CACHE", raising=False)
    stats = copy.deepcopy(cache.stats)
    try:
        with cache.use_cache(True):
            yield
    finally:
        cache.clear_memory()
        cache.stats.clear()
        cache.stats.update(stats)
        patch.undo()


@pytest.fixture(scope="session")
def shared_stage_cache(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., AbstractContextManager[None]]:
    """``with shared_stage_cache(key): ...`` runs the block with the stage cache on, in the folder ``shipped_build``
    fills (shared by the session's workers), as ``shipped_build`` builds: for a test that needs a build of a
    design as it is, not the work of its stages (a ``fabricate check``'s rebuild, repeated builds of one design).
    ``key`` (e.g. a hash of the design) takes an exclusive lock for the block, so two workers that need the same
    design wait for one cold build instead of making two. Never for a test that patches a stage (a stage served
    by the cache does not run) or what the keys take from the install (``step_available``: a key holds the
    installed OCP's version, so a build that pretends OCP is missing would be served STEP files)."""
    shared = session_folder(tmp_path_factory)
    store = stage_cache_folder(tmp_path_factory)

    @contextmanager
    def block(key: str | None = None) -> Iterator[None]:
        if key is None:
            with _stage_cache_in(store):
                yield
            return
        name = hashlib.sha256(key.encode()).hexdigest()[:16]
        with locked(shared / f"stage-cache-{name}.lock"), _stage_cache_in(store):
            yield

    return block


@pytest.fixture
def serve_builds(monkeypatch: pytest.MonkeyPatch,
                 shared_stage_cache: Callable[..., AbstractContextManager[None]]) -> Callable[[], None]:
    """``serve_builds()``: from then on in the test, ``pipeline.run_build`` runs on the session's shared stage cache
    (:func:`shared_stage_cache`), also where its caller turns the cache off (``fabricate check``'s rebuild,
    ``fabricate.build``): for a test of what a build's caller does with a design the session built already (a
    served build is byte-identical to a cold one: tests/test_cache.py). Called after the test's own builds."""
    import fabricate.pipeline as pipeline

    def serve() -> None:
        real = pipeline.run_build

        def served(*args, **kwargs):
            with shared_stage_cache():  # the caller's own use_cache(False) is outside this block
                return real(*args, **kwargs)

        monkeypatch.setattr(pipeline, "run_build", served)

    return serve


class BuiltFolder(NamedTuple):
    """An output folder as ``fabricate build NAME -o DIR -q`` wrote it, that command's exit code, and what it
    printed (standard output, then standard error)."""

    path: Path
    exit_code: int
    output: str


#: ``{key: folder}`` of this test process: the session's shared folders it has already seen built.
_BUILT_FOLDERS: dict[str, BuiltFolder] = {}


@pytest.fixture(scope="session")
def built_folder(tmp_path_factory: pytest.TempPathFactory, _no_stage_cache: None) -> Callable[..., BuiltFolder]:
    """``built_folder(name, process=None, *, step=True, read_only=False)``: the folder ``fabricate build NAME -o DIR -q
    [--process PROCESS]`` writes, built once per test session (the real command in-process: its manifest, report
    and atomic writer) and handed out as a fresh copy a test may change freely.

    The build is cold (``FABRICATE_NO_CACHE``: no stage is served by the cache), so two of its files compared with
    ``shipped_build``'s are two independent builds. The first worker to ask builds it into a folder the session's
    workers share, under an exclusive lock per folder; the others copy it. ``step=False`` builds as an install
    without the ``cad`` extra does (``step_available`` False: no STEP files, "skipped" in the report).
    ``read_only=True`` gives the shared folder itself (no copy), which the test must then only read.

    The command runs with the real ``fabricate.pipeline.run_build`` and ``step_available``, whatever the asking
    test has patched (its module may memoise rebuilds or pretend OCP is missing).
    """
    import fabricate.export.step as step_module
    import fabricate.pipeline as pipeline
    from fabricate.cli import main

    shared = session_folder(tmp_path_factory) / "built-folders"
    shared.mkdir(exist_ok=True)

    def get(name: str, process: str | None = None, *, step: bool = True, read_only: bool = False) -> BuiltFolder:
        key = name + ("" if process is None else f"--process-{process}") + ("" if step else "--no-step")
        if key not in _BUILT_FOLDERS:
            home = shared / key
            home.mkdir(exist_ok=True)
            done = home / "exit_code"
            with locked(home / "lock"):
                if not done.exists():
                    patch = pytest.MonkeyPatch()
                    patch.setenv("FABRICATE_NO_CACHE", "1")
                    patch.setattr(pipeline, "run_build", run_build)
                    patch.setattr(step_module, "step_available", _step_available if step else lambda: False)
                    out, err = io.StringIO(), io.StringIO()
                    try:
                        with redirect_stdout(out), redirect_stderr(err):
                            code = main(["build", name, "-o", str(home / name), "-q",
                                         *([] if process is None else ["--process", process])])
                    finally:
                        patch.undo()
                    (home / "output").write_text(out.getvalue() + err.getvalue())
                    done.write_text(str(code))
                _BUILT_FOLDERS[key] = BuiltFolder(home / name, int(done.read_text()), (home / "output").read_text())
        found = _BUILT_FOLDERS[key]
        if read_only:
            return found
        target = tmp_path_factory.mktemp(key) / name
        shutil.copytree(found.path, target, symlinks=True)
        return found._replace(path=target)

    return get
