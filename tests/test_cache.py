"""The stage cache (fabricate/cache.py): keys hold every input a stage reads and nothing else it could skip, a
cached rebuild after an edit is byte-identical to a cold build, a bad entry is a miss, and ``check`` never uses it.

Every test points ``$FABRICATE_CACHE_DIR`` at its own temporary folder (never the user's cache).
"""

from __future__ import annotations

import copy
import dataclasses
import os
import pickle
import shutil
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fabricate import cache, stage_keys
from fabricate.design import design_from_text, load_design
from fabricate.parts.spec import PartsSpec
from fabricate.templates import TEMPLATE_DIR
from tests.conftest import locked, session_folder, stage_cache_folder

DEFAULT = "finger_five_bar_ncg"


@pytest.fixture
def cache_dir(tmp_path, monkeypatch) -> Iterator[Path]:
    """A fresh, empty cache folder for this test, the in-process layer and the statistics forgotten."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("FABRICATE_CACHE_DIR", str(folder))
    monkeypatch.delenv("FABRICATE_NO_CACHE", raising=False)
    monkeypatch.delenv("FABRICATE_CACHE_MAX_MB", raising=False)
    cache.clear_memory()
    cache.stats.clear()
    yield folder
    cache.clear_memory()


def entries(folder: Path) -> list[Path]:
    return sorted(folder.rglob("*.pkl"))


def edited(old: str, new: str) -> str:
    """The default finger's template text with one edit (which must apply exactly once)."""
    text = (TEMPLATE_DIR / f"{DEFAULT}.toml").read_text(encoding="utf-8")
    assert text.count(old) == 1
    return text.replace(old, new)


# -- keys ----------------------------------------------------------------------------------------------------------

def test_canonical_keeps_every_bit_and_type():
    assert cache.canonical(0.1) != cache.canonical(float(np.nextafter(0.1, 1.0)))  # one bit apart
    assert cache.canonical(1) != cache.canonical(1.0) != cache.canonical(True)
    assert cache.canonical(0.0) != cache.canonical(-0.0)
    assert cache.canonical((1, 2)) != cache.canonical([1, 2])
    assert cache.canonical({"a": 1, "b": 2}) == cache.canonical({"b": 2, "a": 1})
    assert cache.canonical(np.array([1.0, 2.0])) != cache.canonical(np.array([1.0, 2.0000001]))
    assert cache.canonical(np.float64(0.5)) == cache.canonical(0.5)
    assert cache.canonical(None) != cache.canonical("None")
    with pytest.raises(TypeError, match="no canonical form"):
        cache.canonical(object())


def test_each_stage_key_moves_with_its_inputs_only():
    """An edit of a section moves exactly the keys of the stages that read it (the design sections as
    ``fabricate.cache`` documents them)."""
    base = design_from_text((TEMPLATE_DIR / f"{DEFAULT}.toml").read_text(encoding="utf-8"), f"{DEFAULT}.toml")
    stages = {"synthesis": stage_keys.synthesis_key, "gears": stage_keys.gears_key, "parts": stage_keys.parts_key,
              "checks": stage_keys.checks_key, "strength": stage_keys.strength_key, "drive": stage_keys.drive_key}

    def moved(design) -> set[str]:
        return {name for name, key in stages.items()
                if cache.stage_key(name, key(design)) != cache.stage_key(name, key(base))}

    def replace(section: str, **changes: Any):
        return dataclasses.replace(base, **{section: dataclasses.replace(getattr(base, section), **changes)})

    everything = set(stages)
    assert moved(base) == set()
    assert moved(replace("checks", sweep_poses=100)) == everything  # the motion's poses
    assert moved(replace("method", x_A_mm=15.2)) == everything
    assert moved(replace("process", chord_tolerance_mm=0.01)) == everything - {"synthesis"}
    assert moved(replace("process", hole_compensation_mm=0.15)) == everything - {"synthesis", "gears"}
    assert moved(replace("parts", mounting_hole_mm=2.5)) == everything - {"synthesis", "gears"}
    assert moved(replace("load", tip_force_N=1.2)) == {"strength", "drive"}
    assert moved(replace("checks", min_safety_factor=2.5)) == {"strength", "drive"}
    assert moved(replace("checks", min_clearance_mm=0.3)) == {"checks"}
    # a chosen module reads the process and the load: then a load edit moves the gears and all after them
    auto = replace("gears", module_mm=None)
    loaded = dataclasses.replace(auto, load=dataclasses.replace(auto.load, tip_force_N=1.2))
    assert cache.stage_key("gears", stage_keys.gears_key(loaded)) != \
        cache.stage_key("gears", stage_keys.gears_key(auto))
    assert cache.stage_key("synthesis", stage_keys.synthesis_key(loaded)) == \
        cache.stage_key("synthesis", stage_keys.synthesis_key(auto))


def test_a_key_holds_the_code_that_computes_it(monkeypatch, tmp_path):
    key = cache.stage_key("parts", ("x", 1.0))
    monkeypatch.setattr(cache, "_fingerprint", "0" * 64)  # other code: another key
    assert cache.stage_key("parts", ("x", 1.0)) != key
    # the source digest follows every source file's content, and only source files
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    (package / "a.py").write_text("x = 1\n")
    (package / "sub" / "data.json").write_text("{}")
    first = cache.source_digest((package,))
    (package / "sub" / "__pycache__").mkdir()
    (package / "sub" / "__pycache__" / "a.cpython-311.pyc").write_bytes(b"\0")
    (package / "notes.txt").write_text("not code")
    assert cache.source_digest((package,)) == first
    (package / "sub" / "data.json").write_text('{"a": 1}')
    assert cache.source_digest((package,)) != first


# -- the store -------------------------------------------------------------------------------------------------------

def test_a_hit_is_a_fresh_equal_object_from_memory_then_disk(cache_dir):
    made = []

    def compute() -> dict[str, Any]:
        made.append(1)
        return {"a": np.arange(3.0), "b": [1, 2]}

    assert not cache.stored("toy", ("k", 1))
    with cache.use_cache():
        assert not cache.stored("toy", ("k", 1))
        first = cache.cached("toy", ("k", 1), compute)
        assert cache.stored("toy", ("k", 1)) and not cache.stored("toy", ("k", 2))
        second = cache.cached("toy", ("k", 1), compute)
        cache.clear_memory()
        assert cache.stored("toy", ("k", 1))  # on disk
        third = cache.cached("toy", ("k", 1), compute)
        other = cache.cached("toy", ("k", 2), compute)
    assert len(made) == 2  # the first and the other key; the rest are hits
    assert second is not first and third is not first
    second["b"].append(3)  # a caller changing its copy changes no one else's
    assert first["b"] == third["b"] == [1, 2] and np.array_equal(third["a"], first["a"])
    assert other is not first
    assert cache.stats["toy"] == {"hits": 2, "misses": 2, "stores": 2}
    assert len(entries(cache_dir)) == 2
    if os.name == "posix":  # pickles are read back: only their owner may write the folders
        assert all(path.stat().st_mode & 0o077 == 0 for path in (cache_dir, entries(cache_dir)[0].parent,
                                                                    entries(cache_dir)[0].parent.parent))


def test_off_unless_turned_on_and_no_cache_env_wins(cache_dir, monkeypatch):
    made = []
    assert not cache.enabled()
    cache.cached("toy", 1, lambda: made.append(1))
    cache.cached("toy", 1, lambda: made.append(1))
    assert len(made) == 2 and entries(cache_dir) == []
    monkeypatch.setenv("FABRICATE_NO_CACHE", "1")
    with cache.use_cache():
        assert not cache.enabled()
        cache.cached("toy", 1, lambda: made.append(1))
    assert entries(cache_dir) == []
    with cache.use_cache(disk=False):  # the in-process layer alone
        monkeypatch.delenv("FABRICATE_NO_CACHE")
        cache.cached("toy", 2, lambda: made.append(1) or 5)
        assert cache.cached("toy", 2, lambda: made.append(1) or 6) == 5
    assert entries(cache_dir) == [] and len(made) == 4


@pytest.mark.parametrize("damage", ["truncated", "flipped byte", "foreign file", "other key", "empty",
                                    "a folder", "stale pickle"])
def test_a_bad_entry_is_a_miss_and_is_replaced(cache_dir, damage):
    with cache.use_cache():
        cache.cached("toy", "k", lambda: [1.5, 2.5])
    (path,) = entries(cache_dir)
    blob = path.read_bytes()
    if damage == "truncated":
        path.write_bytes(blob[:-3])
    elif damage == "flipped byte":  # the pickle still loads: only the checksum sees it
        path.write_bytes(blob[:-12] + bytes([blob[-12] ^ 1]) + blob[-11:])
    elif damage == "foreign file":
        path.write_bytes(b"PK\x03\x04 not ours")
    elif damage == "other key":
        other = cache.stage_key("toy", "other")
        path.write_bytes(blob.replace(path.stem.encode(), other.encode()))
    elif damage == "empty":
        path.write_bytes(b"")
    elif damage == "a folder":
        path.unlink()
        path.mkdir()
    elif damage == "stale pickle":  # a well-formed entry whose pickle names a class that no longer exists
        from collections import OrderedDict

        payload = pickle.dumps(OrderedDict(a=1), protocol=cache.PICKLE_PROTOCOL)
        cache._disk_put(path.stem, payload.replace(b"collections", b"nocollectio"))
        assert path.read_bytes().startswith(cache.MAGIC)
    cache.clear_memory()
    made = []
    with cache.use_cache():
        value = cache.cached("toy", "k", lambda: made.append(1) or [1.5, 2.5])
    assert value == [1.5, 2.5] and made == [1]
    if damage != "a folder":  # replaced by a good entry, read back as a hit
        cache.clear_memory()
        with cache.use_cache():
            assert cache.cached("toy", "k", lambda: made.append(1) or None) == [1.5, 2.5]
        assert made == [1]


def test_unpicklable_results_and_keys_are_computed_not_cached(cache_dir):
    made = []
    with cache.use_cache():
        for _ in range(2):
            assert cache.cached("toy", "k", lambda: made.append(1) or (lambda: 3))() == 3
            assert cache.cached("toy", object(), lambda: made.append(1) or 4) == 4
    assert len(made) == 4 and entries(cache_dir) == []


def test_the_folder_is_bounded_least_recently_used_first(cache_dir, monkeypatch):
    # 270 kB: three 100 kB entries are over it, and two are within 80 % of it
    monkeypatch.setenv("FABRICATE_CACHE_MAX_MB", str(270_000 / 2**20))
    with cache.use_cache():
        for i in range(3):
            cache.cached("toy", i, lambda i=i: bytes([i]) * 100_000)
            os.utime(cache._entry_path(cache.stage_key("toy", i)), (1e9 + i, 1e9 + i))  # distinct ages
        cache.clear_memory()
        assert cache.cached("toy", 1, lambda: b"recomputed") == bytes([1]) * 100_000  # a hit refreshes its age
        cache.cached("toy", 3, lambda: bytes([3]) * 100_000)
    names = {p.name for p in entries(cache_dir)}
    assert names == {cache._entry_path(cache.stage_key("toy", i)).name for i in (1, 3)}
    assert sum(p.stat().st_size for p in entries(cache_dir)) <= cache.max_bytes()


def test_cache_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("FABRICATE_CACHE_DIR", str(tmp_path / "a"))
    assert cache.cache_dir() == tmp_path / "a"
    monkeypatch.delenv("FABRICATE_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_dir() == tmp_path / "xdg" / "fabricate"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/ignored")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache.cache_dir() == tmp_path / "home" / ".cache" / "fabricate"


# -- the stages read only what their keys hold ---------------------------------------------------------------------

_TRACED: dict[type, type] = {}


def traced(obj: Any, prefix: str, log: set[str]) -> Any:
    """A copy of a frozen dataclass that adds ``prefix.field`` to ``log`` for every attribute read, nested
    dataclasses traced too."""
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        return obj
    base = type(obj)
    cls = _TRACED.get(base)
    if cls is None:
        names = {f.name for f in dataclasses.fields(base)}

        def __getattribute__(self: Any, name: str) -> Any:
            value = base.__getattribute__(self, name)
            if name.startswith("__") or name.startswith("_trace"):
                return value
            own = object.__getattribute__(self, "__dict__")
            if "_trace_log" not in own:  # made by dataclasses.replace of a traced one, which read every field
                return value
            path = f"{own['_trace_prefix']}.{name}".lstrip(".")
            own["_trace_log"].add(path)
            if name in names:
                kids = own["_trace_kids"]
                if name not in kids:
                    kids[name] = traced(value, path, own["_trace_log"])
                return kids[name]
            return value

        cls = _TRACED[base] = type(f"Traced{base.__name__}", (base,), {"__getattribute__": __getattribute__})
    new = copy.copy(obj)
    object.__setattr__(new, "__class__", cls)
    own = object.__getattribute__(new, "__dict__")
    own.update(_trace_prefix=prefix, _trace_log=log, _trace_kids={})
    return new


def reads_covered(log: set[str], key_fields: set[str]) -> set[str]:
    """The reads in ``log`` no key field covers (a key field covers itself and everything under it)."""
    return {read for read in log
            if not any(read == f or read.startswith(f + ".") or f.startswith(read + ".") for f in key_fields)}


#: The design fields each stage's key holds (fabricate.cache's key functions, written out as paths).
SYNTHESIS = {"name", "kind", "method", "checks.sweep_poses", "gears", "actuator"}
GEARS = SYNTHESIS | {"gears", "process.chord_tolerance_mm"}
GEARS_CHOSEN = GEARS | {"process", "load", "checks", "parts", "actuator"}
PARTS_OF = ({f"parts.{f.name}" for f in dataclasses.fields(PartsSpec)} - {f"parts.{name}" for name in
            stage_keys.LAYOUT_FIELDS + stage_keys.PREVIEW_FIELDS}) | {"process", "gears", "actuator", "name", "kind"}
LAYOUT = {f"parts.{name}" for name in stage_keys.LAYOUT_FIELDS}
PREVIEWS = {f"parts.{name}" for name in stage_keys.PREVIEW_FIELDS}


@pytest.mark.slow
@pytest.mark.parametrize("variant", ["default", "laser, module auto"])
def test_every_stage_reads_only_what_its_key_holds(variant):
    """Trace every field each stage reads from the design: none is missing from its key (a missing one
    would serve a stale result after an edit of it)."""
    import fabricate.pipeline as pipeline

    text = (TEMPLATE_DIR / f"{DEFAULT}.toml").read_text(encoding="utf-8")
    if variant != "default":
        text = text.replace("module_mm = 0.5", 'module_mm = "auto"')
    design = design_from_text(text, f"{DEFAULT}.toml", None if variant == "default" else _laser())
    gears = GEARS_CHOSEN if stage_keys.module_is_chosen(design) else GEARS
    parts = gears | PARTS_OF
    log: set[str] = set()
    result, motion, _ = pipeline._synthesis_and_motion(traced(design, "", log), pipeline._quiet)
    assert reads_covered(log, SYNTHESIS) == set()
    run = pipeline.BuildRun(design, result, motion, {})
    for stage, step, fields in (("gears", pipeline._make_gears, gears), ("parts", pipeline._make_parts, parts)):
        log = set()
        run.design = traced(design, "", log)
        step(run)
        assert reads_covered(log, fields) == set(), stage
    run.design = design
    for name, index, fields in (("gear pictures", 1, gears), ("previews", 2, parts | PREVIEWS), ("guide", 4, parts)):
        log = set()
        run.design = traced(design, "", log)
        pipeline._picture_jobs(run)[index]()
        assert reads_covered(log, fields) == set(), name
    from fabricate.export import export_layout, export_part_files

    log = set()  # the part files: an entry keyed by the part set's inputs alone (no layout field)
    made = export_part_files(traced(design, "", log), run.partset, run.mechanism, run.motion)
    assert reads_covered(log, parts) == set()
    log = set()
    export_layout(traced(design, "", log), run.partset, made, False, {})
    assert reads_covered(log, parts | LAYOUT) == set()
    for stage, step, fields in (("checks", pipeline._check, parts | LAYOUT | {"checks.min_clearance_mm"}),
                                ("strength", pipeline._check_strength, parts | {"load", "checks.min_safety_factor"})):
        log = set()
        run.design = traced(design, "", log)
        step(run)
        assert reads_covered(log, fields) == set(), stage


def _laser():
    from fabricate.process import process_override

    return process_override("laser")


# -- whole builds ----------------------------------------------------------------------------------------------------

#: One real edit per table of the default finger, and which stages its cached rebuild must reuse.
EDITS = {
    "parts": (("[checks]\n", "[parts]\nmounting_hole_mm = 2.5\n\n[checks]\n"), {"synthesis", "gears"}),
    # the plate layout only: every part, its pictures, the interference sweep and the strength stay
    "parts layout": (("[checks]\n", "[parts]\nplate_spacing_mm = 4.5\n\n[checks]\n"),
                     {"synthesis", "gears", "parts", "check_figures", "strength", "strength_plot", "drive_plot"}),
    "process": (("thickness_mm = 6.0 ", "hole_compensation_mm = 0.15\nthickness_mm = 6.0 "), {"synthesis", "gears"}),
    "load": (("tip_force_N = 1.5", "tip_force_N = 1.2"),
             {"synthesis", "gears", "parts", "exports", "checks", "check_figures"}),
    "checks": (("sweep_poses = 360 ", "min_safety_factor = 2.5\nsweep_poses = 360 "),
               {"synthesis", "gears", "parts", "exports", "checks", "check_figures"}),
}
PARENT = {"synthesis", "gears", "sizing", "parts", "exports", "checks", "check_figures", "strength", "strength_plot",
          "drive_plot"}
AFTER_PARTS = {"parts", "exports", "checks", "check_figures", "strength", "strength_plot", "drive_plot"}
RERUN = {"parts": AFTER_PARTS, "process": AFTER_PARTS, "parts layout": {"exports", "checks"},
         "load": {"strength", "strength_plot", "drive_plot"}, "checks": {"strength", "strength_plot", "drive_plot"}}


@pytest.fixture(scope="module")
def warmed(tmp_path_factory, shared_stage_cache) -> tuple[Path, Path]:
    """A cache folder warmed by a build of the unedited default finger, and that build's output folder.

    Made once per test session: the tests using it are dealt out to both pytest-xdist workers, so the first to ask
    builds it (under a lock, in the session's folder, which pytest-xdist's per-worker basetemps share) and the
    other waits and reuses it. The tests only read the two folders (they copy the cache; check writes nothing).

    The build runs on the session's shared stage cache (``shared_stage_cache``), where ``shipped_build`` has
    usually built the default finger already (else it is built cold there now), and the folder gets the entries
    that build read or wrote: a read or a write sets an entry's time (fabricate/cache.py), the picture child's
    too. Those are the entries a cold build into an empty folder writes, as the tests need; the shared folder's
    other entries (other designs, maybe written by the other worker meanwhile) may come along and are never read.
    """
    from fabricate.pipeline import run_build

    shared = session_folder(tmp_path_factory) / "test-cache-warm"
    shared.mkdir(exist_ok=True)
    folder, out = shared / "cache", shared / "out"
    with locked(shared / "lock"):
        if not (shared / "done").is_file():
            store = stage_cache_folder(tmp_path_factory)
            start = time.time() - 2.0  # file times come from a coarser clock than time.time()
            cache.clear_memory()
            with shared_stage_cache(f"tests/test_cache warmed {DEFAULT}"):
                assert cache.cache_dir() == store
                outcome = run_build(load_design(DEFAULT))
            touched = [p for p in entries(store) if p.stat().st_mtime >= start]
            assert touched
            for path in touched:
                target = folder / path.relative_to(store)
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(path, target)
            outcome.write(out)
            (shared / "done").touch()
    return folder, out


@pytest.mark.slow
@pytest.mark.parametrize("table", sorted(EDITS))
def test_a_cached_rebuild_after_an_edit_is_the_cold_build(table, warmed, cache_dir, tmp_path):
    """Edit one table of the default finger; the rebuild on the cache of the unedited build reuses the stages the
    edit does not reach and gives every file of a cold (uncached) build of the edited template, byte for byte."""
    from fabricate.pipeline import run_build

    shutil.copytree(warmed[0], cache_dir)
    (old, new), reused = EDITS[table]
    path = tmp_path / f"{DEFAULT}.toml"
    path.write_text(edited(old, new), encoding="utf-8")
    with cache.use_cache():
        warm = run_build(load_design(path))
    cold = run_build(load_design(path))
    assert sorted(warm.files) == sorted(cold.files)
    assert [rel for rel in cold.files if warm.files[rel] != cold.files[rel]] == []
    base = warmed[1]
    moved = [rel for rel in cold.files if not (base / rel).is_file() or (base / rel).read_bytes() != cold.files[rel]]
    assert moved  # a real edit: some output changes
    # the stages of this process (the forked child's pictures count in the child)
    hits = {stage for stage, counts in cache.stats.items() if counts["hits"] and stage in PARENT}
    missed = {stage for stage, counts in cache.stats.items() if counts["misses"] and stage in PARENT}
    assert hits == reused and missed == RERUN[table]


@pytest.mark.slow
def test_a_layout_edit_reuses_the_part_files_and_makes_only_the_plates(cache_dir, tmp_path):
    """After a plate-spacing edit the exports stage runs again, but its part files (every part's STL and drawings,
    assembly.3mf, the kinematic drawing, bom.csv: no layout field read) are served; only the plates are made, and
    they move. Report-only builds (the exports made in this process, so their cache counts are this process's;
    no pictures, which a layout edit leaves alone anyway)."""
    from fabricate.pipeline import run_build

    (old, new), _ = EDITS["parts layout"]
    path = tmp_path / f"{DEFAULT}.toml"
    path.write_text(edited(old, new), encoding="utf-8")
    with cache.use_cache():
        before = run_build(load_design(DEFAULT), report_only=True)
        assert cache.stats["part_files"] == {"hits": 0, "misses": 1, "stores": 1}
        cache.stats.clear()
        after = run_build(load_design(path), report_only=True)
    assert cache.stats["part_files"] == {"hits": 1, "misses": 0, "stores": 0}
    assert cache.stats["exports"]["misses"] == 1
    moved = sorted(rel for rel in after.files if before.files.get(rel) != after.files[rel])
    plates = sorted(rel for rel in after.files if rel.startswith("plates/"))
    assert plates and set(plates) <= set(moved)
    assert not [rel for rel in moved if rel.startswith(("parts/", "drawings/"))]  # the part files: served


@pytest.mark.slow
def test_check_neither_reads_nor_writes_the_cache(warmed, cache_dir, tmp_path):
    """A cached build's folder passes check while the cache holds a poisoned entry that a cached build does serve
    (check's rebuild does not take it); and check touches no entry (no read: a read refreshes an entry's time;
    no write)."""
    from fabricate.cli import main

    shutil.copytree(warmed[0], cache_dir)
    out = warmed[1]
    poisoned = None
    for path in entries(cache_dir):
        value = pickle.loads(path.read_bytes()[len(cache.MAGIC) + 130:])
        if isinstance(value, tuple) and len(value) == 3 and isinstance(value[0], dict) and \
                any(rel.endswith(".dxf") for rel in value[0]):  # the exports stage: (files, parts report, cut)
            poisoned = sorted(rel for rel in value[0] if rel.endswith(".dxf"))[0]
            value[0][poisoned] += b"999\nPOISON\n"
            cache._disk_put(path.stem, pickle.dumps(value, protocol=cache.PICKLE_PROTOCOL))
    assert poisoned is not None
    cache.clear_memory()
    served = tmp_path / "served"
    assert main(["build", DEFAULT, "-o", str(served), "-q"]) == 0
    assert (served / poisoned).read_bytes().endswith(b"POISON\n")  # a cached build does take the entry
    for path in entries(cache_dir):
        os.utime(path, (1e9, 1e9))
    listing = {(p, p.stat().st_mtime, p.stat().st_size) for p in entries(cache_dir)}
    assert main(["check", str(out), "-q"]) == 0  # its rebuild's DXF is the true one, not the poisoned entry's
    assert main(["check", DEFAULT, "-q"]) == 0
    assert {(p, p.stat().st_mtime, p.stat().st_size) for p in entries(cache_dir)} == listing


@pytest.mark.slow
def test_synth_reuses_synthesis_and_its_plots(cache_dir):
    """``synth`` on a warm cache takes the synthesis and its figures from it (the figures closure itself is not
    stored: a stored result draws through the ``synthesis_plots`` entry) and gives the uncached files."""
    from fabricate.pipeline import run_synth

    design = load_design(DEFAULT)
    with cache.use_cache():
        cold = run_synth(design)
        cache.clear_memory()
        cache.stats.clear()
        warm = run_synth(design)
    assert cache.stats["synthesis"]["hits"] == 1 and cache.stats["synthesis_plots"] == {"hits": 1, "misses": 0,
                                                                                         "stores": 0}
    fresh = run_synth(design)
    assert warm.files == cold.files == fresh.files
    assert any(rel.startswith("plots/") for rel in fresh.files)
