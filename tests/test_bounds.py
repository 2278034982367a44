"""Every input of issue 10 item 5 ends in a named outcome: exit 2 naming the field, or a build.

Absurd magnitudes, kernel failures a field provokes and resource-hungry counts exit 2 with
``fabricate: error: <field>: ...`` and write nothing; every pressure angle of the documented range
builds; a count exactly at its bound validates and one past it is refused naming the field.
"""

from __future__ import annotations

import os
import platform
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fabricate import bounds
from fabricate.cli import main
from fabricate.design import design_from_text, load_design
from fabricate.errors import SpecError
from fabricate.hints import PartHints
from fabricate.templates import TEMPLATE_DIR, parse_toml
from tests.synthesis.linkage.test_linkage import GEARED
from tests.toml_writer import toml_text


def _template(tmp_path: Path, name: str, edits: list[tuple[str, str]], extra: str = "") -> Path:
    """A copy of a shipped template with lines replaced (regex, replacement) and text appended."""
    text = (TEMPLATE_DIR / name).read_text(encoding="utf-8")
    for pattern, replacement in edits:
        text, count = re.subn(pattern, replacement, text, count=1, flags=re.MULTILINE)
        assert count == 1, pattern
    path = tmp_path / "t.toml"
    path.write_text(text + extra, encoding="utf-8")
    return path


def _build(path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    out = tmp_path / "out"
    code = main(["build", str(path), "-o", str(out), "-q"])
    captured = capsys.readouterr()
    text = captured.out + captured.err
    assert "Traceback" not in text
    if code == 2:
        assert not out.exists(), "exit 2 must write nothing"
    return code, captured.err


def _assert_refused(path: Path, field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> str:
    code, err = _build(path, tmp_path, capsys)
    assert code == 2, err
    assert f"fabricate: error: {field}:" in err, err
    return err


FIVE_BAR = "finger_five_bar_ncg.toml"
GEARS = "gear_pair_elliptic.toml"


@pytest.mark.parametrize("value", ["1e300", "1e9"])
def test_absurd_phalanx_length_names_the_field(value: str, tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, FIVE_BAR, [(r"^lengths_mm = \[40\.0", f"lengths_mm = [{value}")])
    _assert_refused(path, "finger.lengths_mm[0]", tmp_path, capsys)


@pytest.mark.slow
def test_pin_too_large_for_the_link_names_pin_diameter_and_its_limit(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, FIVE_BAR, [(r'^profile = "sla"', 'profile = "sla"\npin_diameter_mm = 30')])
    err = _assert_refused(path, "process.pin_diameter_mm", tmp_path, capsys)
    assert "at most" in err


def test_chord_tolerance_below_its_bound_names_the_field(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, GEARS, [(r'^profile = "sla"', 'profile = "sla"\nchord_tolerance_mm = 1e-9')])
    _assert_refused(path, "process.chord_tolerance_mm", tmp_path, capsys)


def test_teeth_over_the_bound_names_the_field(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, GEARS, [(r"^teeth = \[30, 30\]", "teeth = [2000, 2000]")])  # from the issue
    _assert_refused(path, "gears.teeth[0]", tmp_path, capsys)


def test_sweep_poses_of_the_issue_are_refused(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, FIVE_BAR, [(r"^sweep_poses = 360", "sweep_poses = 100000")])
    _assert_refused(path, "checks.sweep_poses", tmp_path, capsys)


@pytest.mark.slow
@pytest.mark.parametrize("angle", [10, 24, 30, 35])
def test_every_documented_pressure_angle_builds(angle: int, tmp_path: Path, capsys) -> None:
    # steep angles narrow the rack's tooth space: the default root fillet (and dedendum) adapt, and
    # the gears may then fail a check (pointed teeth at 35 deg): exit 1 with a report, never an error
    path = _template(tmp_path, GEARS, [(r'^method = "exact"', f'method = "exact"\npressure_angle_deg = {angle}')])
    code, err = _build(path, tmp_path, capsys)
    assert code in (0, 1), err
    assert (tmp_path / "out" / "report.json").is_file()


def test_explicit_root_fillet_that_does_not_fit_names_its_limit(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, GEARS, [(r'^method = "exact"',
                                        'method = "exact"\npressure_angle_deg = 30\nroot_fillet = 0.5')])
    err = _assert_refused(path, "gears.root_fillet", tmp_path, capsys)
    assert "at most" in err


#: (template, regex of the line, its replacement with {value}, field, bound, step past the bound)
AT_BOUND = [
    (FIVE_BAR, r"^sweep_poses = 360", "sweep_poses = {value}", "checks.sweep_poses", bounds.MAX_SWEEP_POSES, 1),
    (FIVE_BAR, r"^kappa_samples = 501", "kappa_samples = {value}", "synthesis.kappa_samples",
     bounds.MAX_KAPPA_SAMPLES, 1),
    (FIVE_BAR, r"^curve_step_mm = 0.25", "curve_step_mm = {value}", "synthesis.curve_step_mm",
     bounds.MIN_CURVE_STEP_MM, -1e-4),
    (GEARS, r'^profile = "sla"', 'profile = "sla"\nchord_tolerance_mm = {value}', "process.chord_tolerance_mm",
     bounds.MIN_CHORD_TOLERANCE_MM, -1e-5),
    (GEARS, r'^method = "exact"', 'method = "exact"\nmesh_steps = {value}', "gears.mesh_steps",
     bounds.MAX_MESH_STEPS, 1),
    ("finger_underactuated.toml", r"^samples = 41", "samples = {value}", "push_rod.samples",
     bounds.MAX_STROKE_SAMPLES, 1),
    ("gripper_compliant.toml", r"^path_samples = 121", "path_samples = {value}", "optimisation.path_samples",
     int(bounds.MAX_SPRING_TABLE // (31 * 31 * 91)), 1),
    ("finger_watt_six_bar.toml", r"^statics_samples = 41", "statics_samples = {value}",
     "region.statics_samples", int(bounds.MAX_REGION_WORK // (201 * 101)), 1),
]


@pytest.mark.parametrize("name,pattern,line,field,bound,past", AT_BOUND, ids=[row[3] for row in AT_BOUND])
def test_count_at_its_bound_validates_and_past_it_is_refused(name: str, pattern: str, line: str, field: str,
                                                             bound: float, past: float, tmp_path: Path,
                                                             capsys) -> None:
    at = _template(tmp_path, name, [(pattern, line.format(value=bound))])
    load_design(at)  # validation (and the preflight estimate) accept the bound itself
    over = _template(tmp_path, name, [(pattern, line.format(value=bound + past))])
    _assert_refused(over, field, tmp_path, capsys)


def test_teeth_times_mesh_steps_over_the_bound_names_mesh_steps(tmp_path: Path, capsys) -> None:
    # each field is within its own bound; their product is not (refused before any tooth is cut)
    steps = f'method = "exact"\nmesh_steps = {bounds.MAX_MESH_STEPS}'
    teeth = f"teeth = [{bounds.MAX_TEETH}, {bounds.MAX_TEETH}]"
    path = _template(tmp_path, GEARS, [(r"^teeth = \[30, 30\]", teeth), (r'^method = "exact"', steps)])
    err = _assert_refused(path, "gears.mesh_steps", tmp_path, capsys)
    assert "at most" in err


def test_compliant_grid_axis_over_the_bound_names_the_axis(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, "gripper_compliant.toml", [(r"^phi01_deg = \[0.0, 180.0, 2.0\]",
                                                           "phi01_deg = [0.0, 180.0, 1e-300]")])
    _assert_refused(path, "optimisation.phi01_deg", tmp_path, capsys)


def test_gear_pair_poses_times_teeth_over_the_bound_names_sweep_poses(tmp_path: Path, capsys) -> None:
    # the most teeth are allowed, and so are the most poses, but not both: refused by the preflight estimate
    teeth = f"teeth = [{bounds.MAX_TEETH}, {bounds.MAX_TEETH}]"
    path = _template(tmp_path, GEARS, [(r"^teeth = \[30, 30\]", teeth)],
                     extra=f"\n[checks]\nsweep_poses = {bounds.MAX_SWEEP_POSES}\n")
    err = _assert_refused(path, "checks.sweep_poses", tmp_path, capsys)
    assert f"at most {bounds.MAX_POSE_TEETH // (2 * bounds.MAX_TEETH)}" in err


# -- issue 23 item 4: gear law expressions, the exact form, the linkage's solver work, --workers -----------

#: test_linkage's geared pair with an expression law (EXPRESSION is replaced by each test)
LINKAGE_GEARS = GEARED.replace("LAW", 'law = "expression"\nexpression = "EXPRESSION"')


def _padded(length: int) -> str:
    """A valid closed 1:1 law of exactly ``length`` characters (spaces pad it)."""
    return "x + 0.01*sin(x)".ljust(length)


def _linkage_refusal(expression: str) -> SpecError:
    with pytest.raises(SpecError) as info:
        design_from_text(LINKAGE_GEARS.replace("EXPRESSION", expression), "g.toml")
    return info.value


def test_linkage_gear_expression_at_its_length_bound_validates_and_past_it_is_refused() -> None:
    design_from_text(LINKAGE_GEARS.replace("EXPRESSION", _padded(bounds.MAX_EXPRESSION_LENGTH)), "g.toml")
    err = _linkage_refusal(_padded(bounds.MAX_EXPRESSION_LENGTH + 1))
    assert err.path == "linkage.gears[0].expression"
    assert f"{bounds.MAX_EXPRESSION_LENGTH + 1} characters, over the bound of {bounds.MAX_EXPRESSION_LENGTH}" \
        in err.message


def test_gear_pair_law_has_the_linkage_expressions_length_bound(tmp_path: Path, capsys) -> None:
    line = 'law = "{value}"\nteeth = [30, 30]'
    at = _template(tmp_path, GEARS, [(r'^family = "elliptic"\neccentricity = 0.2',
                                      line.format(value=_padded(bounds.MAX_EXPRESSION_LENGTH)))])
    load_design(at)
    over = _template(tmp_path, GEARS, [(r'^family = "elliptic"\neccentricity = 0.2',
                                        line.format(value=_padded(bounds.MAX_EXPRESSION_LENGTH + 1)))])
    err = _assert_refused(over, "gear_pair.law", tmp_path, capsys)
    assert f"over the bound of {bounds.MAX_EXPRESSION_LENGTH}" in err


def test_998_unary_minus_signs_are_a_named_input_error_not_an_internal_one(tmp_path: Path, capsys) -> None:
    # the expression of the issue: within the length bound, but 998 levels deep (it overflowed Python's stack)
    expression = "-" * 998 + "x"
    err = _linkage_refusal(expression)
    assert err.path == "linkage.gears[0].expression" and "nested more than" in err.message
    path = tmp_path / "deep.toml"
    path.write_text(LINKAGE_GEARS.replace("EXPRESSION", expression), encoding="utf-8")
    code, text = _build(path, tmp_path, capsys)
    assert code == 2 and "fabricate: error: linkage.gears[0].expression:" in text, text


def test_expression_nesting_at_its_depth_bound_validates_and_past_it_is_refused() -> None:
    # an even number of minus signs is the identity law; the name x is one level more
    at = "-" * (bounds.MAX_EXPRESSION_DEPTH - 2) + "x"
    bounds.check_expression(at, "law")
    design_from_text(LINKAGE_GEARS.replace("EXPRESSION", at), "g.toml")
    with pytest.raises(SpecError) as info:
        bounds.check_expression("-" * bounds.MAX_EXPRESSION_DEPTH + "x", "gear_pair.law")
    assert info.value.path == "gear_pair.law"
    # parentheses are no level: the syntax tree is what is compiled, one Python frame a level
    bounds.check_expression("(" * 50 + "x" + ")" * 50, "law")


def test_gear_pair_law_too_deep_exits_2_naming_the_field(tmp_path: Path, capsys) -> None:
    path = _template(tmp_path, GEARS, [(r'^family = "elliptic"\neccentricity = 0.2',
                                        'law = "' + "-" * 998 + 'x"\nteeth = [30, 30]')])
    _assert_refused(path, "gear_pair.law", tmp_path, capsys)


@pytest.fixture(scope="module")
def exact_text() -> str:
    """The exact form (mechanism.toml) of the shipped Stephenson six-bar, written without a build."""
    from fabricate.synthesis.linkage.exact import mechanism_toml
    from fabricate.synthesis.linkage.mechanism import build_mechanism

    design = load_design(TEMPLATE_DIR / "linkage_stephenson.toml")
    return mechanism_toml(design, build_mechanism(design.name, design.method), PartHints(copies=1)).decode("utf-8")


def test_exact_form_copies_at_the_bound_validate_and_past_it_are_refused(exact_text: str) -> None:
    assert "copies = 1\n" in exact_text
    design = design_from_text(exact_text.replace("copies = 1\n", f"copies = {bounds.MAX_COPIES}\n"), "m.toml")
    assert design.method.hints.copies == bounds.MAX_COPIES
    for bad in (bounds.MAX_COPIES + 1, 2000, 0, 2.5, "true"):
        with pytest.raises(SpecError) as info:
            design_from_text(exact_text.replace("copies = 1\n", f"copies = {bad}\n"), "m.toml")
        assert info.value.path == "linkage.hints.copies", info.value
        assert f"from 1 to {bounds.MAX_COPIES}" in info.value.message


def test_exact_form_points_per_body_at_the_bound_validate_and_past_it_are_refused(exact_text: str) -> None:
    data = parse_toml(exact_text, "m.toml")
    frame = data["linkage"]["bodies"][0]["points"]
    for count, refused in ((bounds.MAX_LINKAGE_POINTS, False), (bounds.MAX_LINKAGE_POINTS + 1, True)):
        points = dict(frame)
        points.update({f"extra{k}": [float(k), 1.0] for k in range(count - len(frame))})
        data["linkage"]["bodies"][0]["points"] = points
        text = toml_text(data)
        if refused:
            with pytest.raises(SpecError) as info:
                design_from_text(text, "m.toml")
            assert info.value.path == "linkage.bodies[0].points"
            assert f"{count} points, over the bound of {bounds.MAX_LINKAGE_POINTS}" in info.value.message
        else:
            design_from_text(text, "m.toml")


def test_exact_form_law_points_past_the_bound_are_refused(exact_text: str) -> None:
    data = parse_toml(exact_text, "m.toml")
    driver = data["linkage"]["drivers"][0]
    n = bounds.MAX_EXACT_LAW_POINTS + 1
    driver["law"] = {"type": "samples", "x": [float(k) for k in range(n)], "y": [0.0] * n}
    with pytest.raises(SpecError) as info:
        design_from_text(toml_text(data), "m.toml")
    assert info.value.path == "linkage.drivers[0].law.x"
    assert f"{n} points, over the bound of {bounds.MAX_EXACT_LAW_POINTS}" in info.value.message


def test_max_workers_is_bounded_by_the_cores_and_the_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    cores = bounds.available_cores()
    assert 1 <= bounds.max_workers() <= cores
    # memory for two workers and a half: two, however many cores
    monkeypatch.setattr(bounds, "available_cores", lambda: 64)
    monkeypatch.setattr(bounds, "available_memory_mb", lambda: 2.5 * bounds.WORKER_MB)
    assert bounds.max_workers() == 2
    bounds.check_workers(2)
    with pytest.raises(SpecError) as info:
        bounds.check_workers(3)
    assert info.value.path == "--workers" and "expected 1 .. 2 processes, got 3" in info.value.message
    assert "64 cores" in info.value.message and "holds 2" in info.value.message
    monkeypatch.setattr(bounds, "available_memory_mb", lambda: None)  # no /proc/meminfo: the cores bound
    assert bounds.max_workers() == 64
    monkeypatch.setattr(bounds, "available_memory_mb", lambda: 1.0)  # too little for one: still one
    assert bounds.max_workers() == 1


@pytest.mark.parametrize("workers", ["0", "513", "{over}"])
def test_sweep_workers_past_the_bound_exits_2_naming_the_limit(workers: str, tmp_path: Path, capsys) -> None:
    value = workers.format(over=bounds.max_workers() + 1)
    code = main(["sweep", "finger_hand_sizes", "-o", str(tmp_path / "s"), "--workers", value, "-q"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert f"fabricate: error: --workers: expected 1 .. {bounds.max_workers()} processes, got {value}" in err
    assert not (tmp_path / "s").exists()


def test_blas_threads_pins_and_restores(monkeypatch: pytest.MonkeyPatch) -> None:
    import numpy  # noqa: F401  (its OpenBLAS is the one pinned)

    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")  # the pin holds whatever the environment asks
    controls = bounds._openblas_controls()
    before = [int(get()) for get, _ in controls]
    with bounds.blas_threads(1):
        inside = [int(get()) for get, _ in controls]
    assert [int(get()) for get, _ in controls] == before
    assert all(n == 1 for n in inside)

    @bounds.blas_threads()
    def solve() -> list[int]:
        return [int(get()) for get, _ in controls]

    assert all(n == 1 for n in solve()) and all(n == 1 for n in solve())  # a decorator, every call
    assert [int(get()) for get, _ in controls] == before


def test_linkage_gear_expressions_in_all_past_their_bound_are_refused() -> None:
    gears = 4
    each = bounds.MAX_LINKAGE_EXPRESSION_CHARS // gears
    kw = dict(gears=gears, teeth=8, sliders=0, poses=100)
    design_from_text(_worst_linkage(expression=each, **kw), "w.toml")
    with pytest.raises(SpecError) as info:
        design_from_text(_worst_linkage(expression=each + 1, **kw), "w.toml")
    assert info.value.path == "linkage.gears[0].expression"
    assert f"{gears * (each + 1)} characters in all, over the bound of " \
           f"{bounds.MAX_LINKAGE_EXPRESSION_CHARS}" in info.value.message


def test_linkage_poses_times_bodies_at_the_bound_validate_and_past_it_are_refused() -> None:
    poses = bounds.MAX_LINKAGE_POSE_BODIES // bounds.MAX_LINKAGE_BODIES
    kw = dict(gears=0, sliders=0)  # revolutes only: the solver's estimate is not what binds
    design_from_text(_worst_linkage(poses=poses, **kw), "w.toml")
    with pytest.raises(SpecError) as info:
        design_from_text(_worst_linkage(poses=poses + 1, **kw), "w.toml")
    assert info.value.path == "checks.sweep_poses"
    assert f"over the bound of {bounds.MAX_LINKAGE_POSE_BODIES}" in info.value.message
    assert f"at most {poses} poses with {bounds.MAX_LINKAGE_BODIES} bodies" in info.value.message


def _worst_linkage(**kw: object) -> str:
    from tests.benchmarks.bench_bounds import worst_linkage

    return toml_text(worst_linkage(**kw))


def test_linkage_solver_estimate_refuses_poses_past_its_bound_and_names_the_most() -> None:
    # gear expressions of the most characters and the most sliders: each field is within its bound, and so are
    # the poses × bodies, but not the solver's work
    kw = dict(gears=2, teeth=12, expression=bounds.MAX_LINKAGE_EXPRESSION_CHARS // 2, sliders=18)
    poses = bounds.MAX_LINKAGE_POSE_BODIES // bounds.MAX_LINKAGE_BODIES  # the most poses × bodies allow
    with pytest.raises(SpecError) as info:
        design_from_text(_worst_linkage(poses=poses, **kw), "w.toml")
    assert info.value.path == "checks.sweep_poses", info.value
    assert "s of solving estimated" in info.value.message
    most = int(re.search(r"at most (\d+) poses", info.value.message).group(1))
    assert 361 < most < poses
    design_from_text(_worst_linkage(poses=most, **kw), "w.toml")  # the bound itself validates
    with pytest.raises(SpecError) as info:
        design_from_text(_worst_linkage(poses=most + 1, **kw), "w.toml")
    assert info.value.path == "checks.sweep_poses"


def test_linkage_gear_teeth_in_all_at_the_bound_validate_and_past_it_are_refused() -> None:
    per_gear = bounds.MAX_LINKAGE_GEAR_TEETH // 4  # two pairs
    poses = bounds.MAX_LINKAGE_POSE_TEETH // bounds.MAX_LINKAGE_GEAR_TEETH
    kw = dict(gears=2, expression=60, sliders=0, poses=poses)
    design_from_text(_worst_linkage(teeth=per_gear, **kw), "w.toml")
    with pytest.raises(SpecError) as info:
        design_from_text(_worst_linkage(teeth=per_gear + 1, **kw), "w.toml")
    assert info.value.path == "gears.teeth"
    assert f"{4 * (per_gear + 1)} teeth in all, over the bound of {bounds.MAX_LINKAGE_GEAR_TEETH}" \
        in info.value.message
    # the poses × teeth product: the most poses with these teeth, and one more
    with pytest.raises(SpecError) as info:
        design_from_text(_worst_linkage(teeth=per_gear, **{**kw, "poses": poses + 1}), "w.toml")
    assert info.value.path == "checks.sweep_poses" and f"at most {poses} poses" in info.value.message


def test_the_exact_form_of_the_largest_tables_is_a_valid_template() -> None:
    """A linkage whose driver table holds every sample the bound allows writes a mechanism.toml that is itself
    a valid template (within MAX_TEMPLATE_BYTES): the rebuild of a valid build is never refused; one sample
    more is refused up front, naming the field."""
    import copy

    import numpy as np

    from fabricate.bounds import MAX_LINKAGE_TABLE
    from fabricate.design import design_from_text
    from fabricate.errors import SpecError
    from fabricate.synthesis.linkage.exact import mechanism_toml
    from fabricate.synthesis.linkage.mechanism import build_mechanism
    from fabricate.templates import MAX_TEMPLATE_BYTES
    from fabricate.tomlwrite import dumps
    from tests.test_not_checked import FOUR_BAR

    def tables(n: int) -> dict:
        t = copy.deepcopy(FOUR_BAR)
        s = np.linspace(0.0, 360.0, n)
        # a non-linear table, so no two spline pieces share their coefficients
        t["linkage"]["drivers"] = [{"joint": "O", "law": "table", "input": s.tolist(),
                                    "value": (s + 10.0 * np.sin(np.radians(s))).tolist()}]
        return t

    design = design_from_text(dumps(tables(MAX_LINKAGE_TABLE)), "largest_table.toml")
    text = mechanism_toml(design, build_mechanism(design.name, design.method), PartHints(tip_point="B"))
    assert len(text) <= MAX_TEMPLATE_BYTES
    rebuilt = design_from_text(text.decode("utf-8"), "mechanism.toml")
    assert rebuilt.kind == "linkage"
    with pytest.raises(SpecError, match=r"linkage\.drivers.*4001 samples in all|linkage\.drivers\[0\]\.input"):
        design_from_text(dumps(tables(MAX_LINKAGE_TABLE + 1)), "too_large.toml")


def test_rare_collections_sets_the_thresholds_inside_and_restores_the_callers():
    import gc

    from fabricate.bounds import BUILD_GC_THRESHOLDS, rare_collections

    before = gc.get_threshold()
    with rare_collections():
        assert gc.get_threshold() == BUILD_GC_THRESHOLDS
    assert gc.get_threshold() == before
    with pytest.raises(ZeroDivisionError), rare_collections((5000, 5, 5)):
        assert gc.get_threshold() == (5000, 5, 5)
        1 / 0  # noqa: B018 - an exception in the block still restores the thresholds
    assert gc.get_threshold() == before


def test_a_build_runs_with_rare_collections_and_leaves_the_thresholds_as_they_were(monkeypatch):
    import gc

    from fabricate import pipeline
    from fabricate.bounds import BUILD_GC_THRESHOLDS

    seen = []
    monkeypatch.setattr(pipeline, "_synthesis_stage", lambda *a: (seen.append(gc.get_threshold()), 1 / 0))
    before = gc.get_threshold()
    with pytest.raises(ZeroDivisionError):
        pipeline.run_build(load_design("gear_pair_elliptic"), optional=pipeline.OptionalOutputs(step=False))
    assert seen == [BUILD_GC_THRESHOLDS] and gc.get_threshold() == before


GEAR_STAGE_FAULTS = """
import resource, sys
from fabricate.bounds import roomy_heap
if sys.argv[1] == "roomy":
    assert roomy_heap()
from fabricate.design import load_design
from fabricate.pipeline import BuildRun, _make_gears, _synthesis_stage
design = load_design("gear_pair_elliptic")
result, report, motion, _ = _synthesis_stage(design, lambda s: None, "build")
run = BuildRun(design, result, motion, report)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
_make_gears(run)
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc",
                    reason="mallopt's thresholds are glibc's")
def test_a_roomy_heap_spares_the_gear_stage_most_of_its_page_faults():
    """The gear stage's mesh check works in chunks of steps; with glibc's default thresholds each chunk's arrays are
    mapped, unmapped and faulted in again (~39k minor faults for the elliptic pair), with ROOMY_HEAP they are reused
    (~3k). Page faults count memory traffic, not time: the same on a busy machine. Bound: a third."""
    # glibc's own defaults in the first process: no MALLOC_* variable (a Dask nanny in this process may have set one)
    env = {**{k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}, "FABRICATE_NO_CACHE": "1"}
    counts = {}
    for mode in ("default", "roomy"):
        run = subprocess.run([sys.executable, "-c", GEAR_STAGE_FAULTS, mode], capture_output=True, text=True,
                             timeout=300, env=env)
        assert run.returncode == 0, run.stderr
        counts[mode] = int(run.stdout.split()[-1])
    assert counts["roomy"] * 3 < counts["default"], counts
