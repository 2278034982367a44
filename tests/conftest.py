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
import math
import os
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from fabricate import cache
from fabricate.design import load_design
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


def _session_folder(factory: pytest.TempPathFactory) -> Path:
    """A folder every worker of this test session shares: pytest-xdist gives each worker its own basetemp
    inside one session folder (``pytest-N/popen-gwK``); without xdist the basetemp is the session's."""
    base = factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


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
    shared = _session_folder(tmp_path_factory)
    store = shared / "shipped-stage-cache"
    store.mkdir(exist_ok=True)

    def get(name: str, process: str | None = None) -> BuildOutcome:
        """``process``: a shipped profile's name, as ``--process`` gives it (``"laser"``, ``"fdm"``)."""
        key = name if process is None else f"{name}--process-{process}"
        if key not in _SHIPPED_BUILDS:
            design = load_design(name, process)
            patch = pytest.MonkeyPatch()
            patch.setenv("FABRICATE_CACHE_DIR", str(store))
            patch.delenv("FABRICATE_NO_CACHE", raising=False)
            stats = copy.deepcopy(cache.stats)
            try:
                with open(shared / f"shipped-{key}.lock", "w") as lock:
                    fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
                    with cache.use_cache(True):
                        _SHIPPED_BUILDS[key] = run_build(design)
            finally:
                cache.clear_memory()
                cache.stats.clear()
                cache.stats.update(stats)
                patch.undo()
        return _SHIPPED_BUILDS[key]

    return get
