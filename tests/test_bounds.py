"""Every input of issue 10 item 5 ends in a named outcome: exit 2 naming the field, or a build.

Absurd magnitudes, kernel failures a field provokes and resource-hungry counts exit 2 with
``fabricate: error: <field>: ...`` and write nothing; every pressure angle of the documented range
builds; a count exactly at its bound validates and one past it is refused naming the field.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from fabricate import bounds
from fabricate.cli import main
from fabricate.spec import TEMPLATE_DIR, load_design


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
