"""Issue 23 item 5 and the related messages of item 7: nothing passes that was not checked.

A strength check without materials (a ``--process`` profile with no ``[materials]``) or without a load (a
template with no ``[load]``) and a synthesis-only run are reported as "not checked": the check's
``passed`` is null with a ``reason``, no safety factor is written (never ``inf``), ``checks.not_checked``
names them, the summary line says it in brackets and stderr carries a note, while the exit code stays 0
(the issue asks to report, not to fail).

The design is a small crank-rocker four-bar (24 poses) written here, so each build takes seconds. The loaded
and the unloaded design are each built by two tests: those builds run with the session's shared stage cache
(``shared_stage_cache``), so the second of each is served by the first's stages (byte-identical, per
tests/test_cache.py).
"""

from __future__ import annotations

import copy
import json
import math
import re
from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

import pytest

import fabricate
from fabricate.cli import _summary, main
from fabricate.report import not_checked_notes, report_json, verdict
from fabricate.templates import TEMPLATE_DIR
from fabricate.tomlwrite import dumps

NO_MATERIALS = "no materials in the profile"
NO_LOAD = "no [load] in the template"
DRIVE_NO_LOAD = "no [load] in the template: the input effort is zero (friction and inertia are not modelled)"

#: Crank O-A 15 mm, coupler A-B to (40, 30), rocker D-B 30 mm, ground O-D 40 mm: a Grashof crank-rocker.
FOUR_BAR: dict[str, Any] = {
    "design": {"name": "four_bar_nc", "kind": "linkage"},
    "process": {"profile": "sla", "pin_diameter_mm": 3.0},
    "checks": {"sweep_poses": 24},
    "load": {"torque_Nmm": 50.0, "torque_body": "rocker"},
    "actuator": {"model": "nema17"},  # a full-turn crank: the drive check runs where the load does
    "linkage": {
        "ground": "frame", "input_unit": "deg", "input_range": [0.0, 360.0],
        "bodies": [{"name": "frame", "points": {"O": [0.0, 0.0], "D": [40.0, 0.0]}},
                   {"name": "crank", "points": {"O": [0.0, 0.0], "A": [15.0, 0.0]}},
                   {"name": "coupler", "points": {"A": [15.0, 0.0], "B": [40.0, 30.0]}},
                   {"name": "rocker", "points": {"D": [40.0, 0.0], "B": [40.0, 30.0]}}],
        "joints": [{"name": "O", "type": "revolute", "bodies": ["frame", "crank"]},
                   {"name": "A", "type": "revolute", "bodies": ["crank", "coupler"]},
                   {"name": "B", "type": "revolute", "bodies": ["coupler", "rocker"]},
                   {"name": "D", "type": "revolute", "bodies": ["frame", "rocker"]}],
        "drivers": [{"joint": "O", "law": "linear"}],
    },
}


def _tables(load: bool = True) -> dict[str, Any]:
    tables = copy.deepcopy(FOUR_BAR)
    if not load:
        del tables["load"]
    return tables


def _profile_without_materials(tmp_path: Path) -> Path:
    """The shipped SLA profile with every ``[materials.*]`` table cut off (its other fields kept)."""
    text = (TEMPLATE_DIR / "process_sla.toml").read_text(encoding="utf-8")
    cut = re.search(r"(?m)^\[materials", text)
    assert cut is not None  # the shipped profile has materials: the cut removes them
    path = tmp_path / "no_materials.toml"
    path.write_text(text[:cut.start()], encoding="utf-8")
    return path


def _strict_json(path: Path) -> dict[str, Any]:
    """report.json read refusing ``Infinity``/``NaN`` (not JSON, though Python would write them)."""
    def refuse(token: str) -> None:
        raise AssertionError(f"{path.name} holds {token}")

    return json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)


def _cli(tmp_path: Path, capsys, name: str, tables: dict[str, Any], *extra: str,
         command: str = "build") -> tuple[int, str, str, Path]:
    template = tmp_path / f"{name}.toml"
    template.write_text(dumps(tables), encoding="utf-8")
    out = tmp_path / f"out_{name}"
    code = main([command, str(template), "-o", str(out), *extra])
    captured = capsys.readouterr()
    return code, captured.out, captured.err, out


def _section(markdown: str, title: str) -> str:
    """The text of report.md's ``## title`` section (up to the next ``## ``)."""
    start = markdown.index(f"## {title}")
    end = markdown.find("\n## ", start + 1)
    return markdown[start:] if end < 0 else markdown[start:end]


# -- through the command line ---------------------------------------------------------------------------

@pytest.mark.slow
def test_profile_without_materials_is_not_checked_and_says_so(tmp_path, capsys):
    code, stdout, stderr, out = _cli(tmp_path, capsys, "nomat", _tables(), "--process",
                                     str(_profile_without_materials(tmp_path)))
    assert code == 0, stdout + stderr  # reported, not failed
    report = _strict_json(out / "report.json")
    strength = report["strength"]
    assert strength["passed"] is None and strength["reason"] == NO_MATERIALS
    assert strength["parts"] == []  # no safety factor for anything: nothing was computed
    assert report["checks"]["passed"] is True  # over the checks that ran: interference, gears, printing
    assert report["checks"]["not_checked"] == [{"check": "strength", "reason": NO_MATERIALS}]
    assert stdout.splitlines()[0] == f"four_bar_nc: checks passed (strength not checked: {NO_MATERIALS}) -> {out}"
    assert f"fabricate: note: strength not checked: {NO_MATERIALS}" in stderr.splitlines()
    md = (out / "report.md").read_text(encoding="utf-8")
    strength_md = _section(md, "Strength")
    assert f"not checked: {NO_MATERIALS}" in strength_md and "passed" not in strength_md
    assert f"- strength not checked: {NO_MATERIALS}" in _section(md, "Checks")
    assert not (out / "plots" / "strength.png").exists()


def _api_build(shared_stage_cache: Callable[..., AbstractContextManager[None]], load: bool) -> fabricate.Build:
    with shared_stage_cache(f"tests/test_not_checked four_bar_nc load={load}"):
        return fabricate.build(fabricate.load(_tables(load=load)), cache=True)


@pytest.mark.slow
def test_template_without_load_is_not_checked_and_writes_no_infinite_factor(tmp_path, capsys, shared_stage_cache):
    with shared_stage_cache("tests/test_not_checked four_bar_nc load=False"):
        code, stdout, stderr, out = _cli(tmp_path, capsys, "noload", _tables(load=False))
    assert code == 0, stdout + stderr
    report = _strict_json(out / "report.json")
    strength = report["strength"]
    assert strength["passed"] is None and strength["reason"] == NO_LOAD
    assert strength["parts"] == [] and strength["loads"] == []
    assert report["checks"]["not_checked"] == [{"check": "strength", "reason": NO_LOAD},
                                               {"check": "drive", "reason": DRIVE_NO_LOAD}]
    assert stdout.splitlines()[0] == (f"four_bar_nc: checks passed (strength not checked: {NO_LOAD}; drive not "
                                      f"checked: {DRIVE_NO_LOAD}) -> {out}")
    assert f"fabricate: note: strength not checked: {NO_LOAD}" in stderr.splitlines()
    md = (out / "report.md").read_text(encoding="utf-8")
    strength_md = _section(md, "Strength")
    assert f"not checked: {NO_LOAD}" in strength_md
    assert not re.search(r"\binf\b", strength_md) and "| part |" not in strength_md


def test_synth_never_says_checks_passed(tmp_path, capsys):
    code, stdout, stderr, out = _cli(tmp_path, capsys, "synth", _tables(), command="synth")
    assert code == 0, stdout + stderr
    assert stdout.splitlines()[0] == f"four_bar_nc: synthesis done (no checks run: synth only) -> {out}"
    assert "checks passed" not in stdout + stderr
    report = _strict_json(out / "report.json")
    assert {e["check"] for e in report["checks"]["not_checked"]} == {"interference", "gear mesh", "printability",
                                                                     "strength", "drive"}
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "## Checks: none run" in md and "PASSED" not in md


@pytest.mark.slow
def test_a_loaded_design_with_materials_is_checked_and_lists_nothing(shared_stage_cache):
    """The control: the same four-bar with its load and the profile's materials is checked (a verdict of
    True or False, a finite factor per part) and ``not_checked`` is empty."""
    build = _api_build(shared_stage_cache, load=True)
    strength, checks = build.report["strength"], build.report["checks"]
    assert strength["passed"] is True and "reason" not in strength
    assert strength["parts"] and all(math.isfinite(p["min_safety_factor"]) for p in strength["parts"]
                                     if p["min_safety_factor"] is not None)
    assert checks["not_checked"] == [] and verdict(build.report) == "checks passed"
    assert build.report["interference"]["passed"] is True


# -- the summary and verdict from a report ----------------------------------------------------------------

def _report(stage: str = "build", failures: tuple[str, ...] = (), not_checked: Any = ()) -> dict[str, Any]:
    return {"design": {"name": "d", "stage": stage},
            "checks": {"passed": not failures, "failures": list(failures), "not_checked": not_checked}}


def test_summary_names_each_unchecked_check_once_per_reason(capsys):
    entries = [{"check": "interference", "reason": "no poses in the motion"},
               {"check": "gear mesh", "reason": "no poses in the motion"},
               {"check": "strength", "reason": NO_MATERIALS}]
    _summary(_report(not_checked=entries), Path("out"))
    captured = capsys.readouterr()
    assert captured.out.splitlines()[0] == ("d: checks passed (interference, gear mesh not checked: no poses in the "
                                            f"motion; strength not checked: {NO_MATERIALS}) -> out")
    assert captured.err.splitlines() == ["fabricate: note: interference, gear mesh not checked: no poses in the motion",
                                         f"fabricate: note: strength not checked: {NO_MATERIALS}"]


def test_summary_of_a_failure_keeps_failed_and_the_unchecked(capsys):
    _summary(_report(failures=("clearance: A and B",), not_checked=[{"check": "strength", "reason": NO_LOAD}]), None)
    lines = capsys.readouterr().out.splitlines()
    assert lines == [f"d: checks FAILED (strength not checked: {NO_LOAD})", "  - clearance: A and B"]


def test_check_dir_findings_fail_the_verdict_even_when_the_report_passed(capsys):
    _summary(_report(), None, ["report.md: differs from a rebuild"])
    assert capsys.readouterr().out.splitlines()[0] == "d: checks FAILED"


@pytest.mark.parametrize("not_checked", [None, "strength", [1, "x", {"check": "strength"}, {"reason": "r"}], {}])
def test_malformed_not_checked_is_ignored_not_a_crash(capsys, not_checked):
    """A hand-edited report.json: entries that are not {check, reason} are skipped in the wording."""
    report = _report(not_checked=not_checked)
    assert not_checked_notes(report) == []
    _summary(report, None)
    assert capsys.readouterr().out.splitlines() == ["d: checks passed"]


def test_synth_verdict_failed_or_done_never_passed():
    assert verdict(_report(stage="synth")) == "synthesis done (no checks run: synth only)"
    assert verdict(_report(stage="synth", failures=("motion: locks up",))) == "synthesis FAILED"


def test_report_json_writes_null_for_infinite_values():
    text = report_json({"strength": {"parts": [{"min_safety_factor": math.inf}], "x": -math.inf, "y": math.nan}})
    data = json.loads(text, parse_constant=lambda token: pytest.fail(f"non-JSON {token}"))
    assert data == {"strength": {"parts": [{"min_safety_factor": None}], "x": None, "y": None}}


@pytest.mark.slow
def test_the_api_names_what_was_not_checked(shared_stage_cache) -> None:
    """``Build.not_checked`` says what ``passed`` does not cover (issue 23 item 5)."""
    unloaded = _api_build(shared_stage_cache, load=False)
    assert unloaded.passed and unloaded.not_checked == ["strength not checked: " + NO_LOAD,
                                                        "drive not checked: " + DRIVE_NO_LOAD]
    loaded = _api_build(shared_stage_cache, load=True)
    assert loaded.passed and loaded.not_checked == []
