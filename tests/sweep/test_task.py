"""A sweep point's row says what its build did not check (issue 23 item 5), so a sweep's best point is
never one that passed only because nothing was checked."""

from __future__ import annotations

import math

import pytest

from fabricate.sweep.task import EXIT_OK, evaluate
from fabricate.tomlwrite import dumps
from tests.test_not_checked import _tables

#: The builds below run on the session's shared stage cache under the keys tests/test_not_checked.py builds the same
#: four-bar with, so the session makes each of its two designs once (a served build is byte-identical to a cold one:
#: tests/test_cache.py); what is tested here is the row's reason, not the build.
SHARED_KEY = "tests/test_not_checked four_bar_nc load={load}"


@pytest.mark.slow
def test_a_point_built_without_a_load_says_strength_was_not_checked(shared_stage_cache) -> None:
    with shared_stage_cache(SHARED_KEY.format(load=False)):
        code, reason, report, _ = evaluate(dumps(_tables(load=False)), "build")
    assert code == EXIT_OK
    assert report is not None and report["strength"]["passed"] is None
    assert "strength not checked: no [load] in the template" in reason


@pytest.mark.slow
def test_a_checked_point_has_no_reason_and_a_synth_point_no_not_checked_note(shared_stage_cache) -> None:
    with shared_stage_cache(SHARED_KEY.format(load=True)):
        code, reason, report, _ = evaluate(dumps(_tables(load=True)), "build")
    assert (code, reason) == (EXIT_OK, "")
    assert report is not None and report["strength"]["passed"] is True
    code, reason, _, _ = evaluate(dumps(_tables(load=True)), "synth")
    assert (code, reason) == (EXIT_OK, "")


# -- points that share a synthesis (issue 27, item 4) -----------------------------------------------------

def test_synthesis_group_ignores_only_the_fields_synthesis_does_not_read() -> None:
    from fabricate.sweep.task import synthesis_group

    fields = [("load.torque_Nmm", ("load", "torque_Nmm")), ("process.thickness_mm", ("process", "thickness_mm")),
              ("parts.link_width_mm", ("parts", "link_width_mm")),
              ("checks.min_clearance_mm", ("checks", "min_clearance_mm")),
              ("design.description", ("design", "description"))]
    a = dict(zip((f for f, _ in fields), (150.0, 3.0, 6.0, 0.3, "x"), strict=True))
    b = dict(zip((f for f, _ in fields), (90.0, 4.0, 7.0, 0.4, "y"), strict=True))
    assert synthesis_group(fields, a) == synthesis_group(fields, b)
    for path, parts in (("gear_pair.eccentricity", ("gear_pair", "eccentricity")),
                        ("checks.sweep_poses", ("checks", "sweep_poses")), ("gears.module_mm", ("gears", "module_mm")),
                        ("finger.lengths_mm[0]", ("finger", "lengths_mm", 0)), ("design.name", ("design", "name"))):
        grown = [*fields, (path, parts)]
        assert synthesis_group(grown, {**a, path: 1}) != synthesis_group(grown, {**a, path: 2}), path
        assert synthesis_group(grown, {**a, path: 1}) == synthesis_group(grown, {**b, path: 1}), path


def test_a_grid_is_sent_group_by_group_whatever_its_field_order() -> None:
    """The grid's last field varies fastest: with the synthesis field last, its points would alternate between
    groups; sent in group order, each group's points follow each other (in index order), groups in the order of
    their first point, and every point is sent once."""
    from fabricate.sweep.runner import group_order
    from fabricate.sweep.spec import sweep_from_tables

    spec = sweep_from_tables({
        "sweep": {"template": "gear_pair_elliptic", "stage": "build", "metrics": ["synthesis.center_distance_mm"]},
        "vary": {"load.torque_Nmm": [50.0, 100.0, 150.0], "gear_pair.eccentricity": [0.1, 0.2]}})
    points = spec.points()
    assert [p["gear_pair.eccentricity"] for p in points] == [0.1, 0.2] * 3
    order = group_order(spec.field_parts(), points, [5, 0, 1, 2, 3, 4])
    assert order == [0, 2, 4, 1, 3, 5]
    assert [points[i]["gear_pair.eccentricity"] for i in order] == [0.1] * 3 + [0.2] * 3


@pytest.mark.slow
def test_a_build_sweep_synthesises_a_shared_synthesis_once_and_gives_the_same_rows(monkeypatch, tmp_path) -> None:
    """Two build points of a small loaded four-bar (tests/test_not_checked.py's, 24 poses: a report-only build
    of it took 0.32 s, of the shipped Stephenson six-bar at 60 poses 0.59 s, in a warm process) that differ only
    in [load]: in one batch with
    the cache it is synthesised once (the second point's synthesis is a cache hit); the second point's row (exit
    code, reason, metrics) is the same as its build on its own without the cache, and the two points' metrics
    differ (the load is read)."""
    import fabricate.pipeline as pipeline
    from fabricate import cache
    from fabricate.sweep.spec import sweep_from_tables
    from fabricate.sweep.task import run_batch

    template = tmp_path / "four_bar_nc.toml"
    template.write_text(dumps(_tables(load=True)), encoding="utf-8")
    spec = sweep_from_tables({
        "sweep": {"template": str(template), "stage": "build",
                  "metrics": ["interference.min_clearance_mm", "min(strength.parts[*].min_safety_factor)"]},
        "vary": {"load.torque_Nmm": [60.0, 150.0]}})
    batch = [(i, values, spec.point_id(values)) for i, values in enumerate(spec.points())]
    calls = []
    synthesise = pipeline.synthesise

    def spy(design, *args, **kwargs):
        calls.append(design.load.torque_Nmm)
        return synthesise(design, *args, **kwargs)

    monkeypatch.setattr(pipeline, "synthesise", spy)
    monkeypatch.delenv("FABRICATE_NO_CACHE", raising=False)  # the suite's default (tests/conftest.py): on here
    cache.clear_memory()
    before = dict(cache.stats.get("synthesis", {"hits": 0, "misses": 0}))
    shared = run_batch(batch, spec.base, spec.field_parts(), spec.stage, list(spec.metrics), cache=True)
    after = cache.stats["synthesis"]
    assert calls == [60.0]
    assert (after["misses"] - before.get("misses", 0), after["hits"] - before.get("hits", 0)) == (1, 1)
    cache.clear_memory()
    # the first point's row above was built from nothing (the memory layer was empty): the second is the one
    # that reused a result, so it is the one built again on its own
    (separate,) = run_batch(batch[1:], spec.base, spec.field_parts(), spec.stage, list(spec.metrics), cache=False)
    assert calls == [60.0, 150.0]
    assert not cache.enabled()  # the batch's switch is restored
    shared[1].pop("seconds"), separate.pop("seconds")
    assert shared[1] == separate
    name = "min(strength.parts[*].min_safety_factor)"
    assert shared[0][name] > shared[1][name] > 0.0


# -- a build point makes its report only (issue 27, item 4) ---------------------------------------------------

#: Metrics over every report section a build sweep may read (FILE_SECTIONS aside).
BUILD_METRICS = ["synthesis.center_distance_mm", "mechanism.degrees_of_freedom",
                 "max(gears[*].transmission_error_deg)", "count(parts[*])", "sum(parts[*].volume_mm3)",
                 "max(parts[*].stl_volume_mm3)", "count(parts[*].step)", "count(bom[*])", "count(hardware.pins[*])",
                 "count(assembly.steps[*])", "count(simulation.joints[*])", "interference.min_clearance_mm",
                 "min(interference.pairs[*].min_clearance_mm)", "min(strength.parts[*].min_safety_factor)",
                 "drive.margin", "checks.passed", "count(checks.failures[*])", "count(notes[*])"]


@pytest.mark.slow
def test_a_build_points_row_is_read_from_a_report_only_build_with_the_full_builds_values(
        shipped_build, monkeypatch) -> None:
    """A point that is the shipped elliptic pair (its eccentricity varied over its own value) gives, bit for bit,
    the metrics of the pair's full build, read from a report-only build (the row's path: no picture, plot or STEP
    file made)."""
    import fabricate.pipeline as pipeline
    from fabricate.sweep.spec import sweep_from_tables
    from fabricate.sweep.task import run_point

    full = shipped_build("gear_pair_elliptic").report
    spec = sweep_from_tables({"sweep": {"template": "gear_pair_elliptic", "stage": "build", "metrics": BUILD_METRICS},
                              "vary": {"gear_pair.eccentricity": [0.2]}})
    made = []
    real = pipeline.run_build

    def spy(*args, **kwargs):
        outcome = real(*args, **kwargs)
        made.append((kwargs.get("report_only"), sorted(outcome.files)))
        return outcome

    monkeypatch.setattr(pipeline, "run_build", spy)
    (values,) = spec.points()
    row = run_point(0, values, spec.point_id(values), spec.base, spec.field_parts(), "build", list(spec.metrics))
    ((lean, files),) = made
    assert lean is True and not [f for f in files if f.endswith((".png", ".gif", ".step"))]
    assert row["exit_code"] == (0 if full["checks"]["passed"] else 1)
    for m in spec.metrics:
        want = m.read(full)
        assert row[m.name] == want or (math.isnan(want) and math.isnan(row[m.name])), m.name
    assert not math.isnan(row["min(strength.parts[*].min_safety_factor)"])  # the metrics read real values
    assert row["count(parts[*])"] >= 4


@pytest.mark.parametrize(("metric", "lean"), [("interference.min_clearance_mm", True), ("count(files[*])", False),
                                              ("sum(manifest[*].bytes)", False), ("count(outputs.step)", False)])
def test_a_build_point_is_built_in_full_only_when_a_metric_reads_the_file_lists(metric, lean, monkeypatch) -> None:
    """``files``, ``manifest`` and ``outputs`` are where a report-only build differs: a metric under one of them
    makes the point a full build (its value as a full build's), any other a report-only one."""
    import fabricate.pipeline as pipeline
    from fabricate.errors import SpecError
    from fabricate.sweep.spec import sweep_from_tables
    from fabricate.sweep.task import EXIT_INVALID, report_only, run_point

    asked = []

    def stub(design, *args, **kwargs):  # no build: only how the point asked for one
        asked.append(kwargs.get("report_only", False))
        raise SpecError("stub", "not built")

    monkeypatch.setattr(pipeline, "run_build", stub)
    spec = sweep_from_tables({"sweep": {"template": "gear_pair_elliptic", "stage": "build",
                                        "metrics": ["synthesis.center_distance_mm", metric]},
                              "vary": {"gear_pair.eccentricity": [0.2]}})
    assert report_only(spec.metrics) is lean
    (values,) = spec.points()
    row = run_point(0, values, spec.point_id(values), spec.base, spec.field_parts(), "build", list(spec.metrics))
    assert row["exit_code"] == EXIT_INVALID and asked == [lean]


def test_a_build_worker_warms_up_with_modules_that_exist() -> None:
    """The runner's warm-up swallows a failure (the worker's first point would say why): a module renamed away
    must fail here instead of silently leaving the imports to the first point. In a fresh interpreter, where
    nothing else has imported them (this process's other tests have)."""
    import subprocess
    import sys

    code = ("import sys\nfrom fabricate.sweep.task import BUILD_MODULES, POINT_MODULES, warm\n"
            "before = [n for n in POINT_MODULES + BUILD_MODULES if n in sys.modules]\n"
            "warm('build')\n"
            "assert all(n in sys.modules for n in POINT_MODULES + BUILD_MODULES), 'not imported'\n"
            "print(len(before))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stderr
    assert int(run.stdout) < 10  # most of them were imported by warm itself
