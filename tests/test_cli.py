"""The command-line contract: exit codes, nothing written on bad input, atomic output, determinism,
and every shipped template built end to end."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fabricate.cli import main
from fabricate.output import write_atomically
from fabricate.spec import shipped_templates

REPORT_KEYS = {"design", "mechanism", "synthesis", "gears", "parts", "interference", "strength", "checks", "files"}


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "design.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[design]\nkind = 'five_bar_ncg'\n", "design.name: missing required field"),
        ("[design]\nname = 'x'\nkind = 'teleporter'\n", "design.kind: expected one of"),
        ("[design]\nname = 'x'\nkind = 'gear_pair'\n[process]\nprofile = 'sla'\nmin_wall_mm = -1\n",
         "process.min_wall_mm: expected a positive number"),
        ("[design]\nname = 'x'\nkind = 'gear_pair'\n[checks]\nsweep_poses = 'many'\n",
         'checks.sweep_poses: expected a number, got "many"'),
        ("[design\nname = 'x'\n", "invalid TOML"),
        ("[design]\nname = '../escape'\nkind = 'gear_pair'\n", "design.name: expected a plain file name"),
    ],
)
def test_bad_input_exits_2_names_the_field_and_writes_nothing(tmp_path, capsys, text, needle):
    out = tmp_path / "out"
    code = main(["build", str(_write(tmp_path, text)), "-o", str(out), "-q"])
    assert code == 2
    assert needle in capsys.readouterr().err
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["design.toml"]


def test_missing_template_exits_2(tmp_path, capsys):
    assert main(["build", str(tmp_path / "nope.toml"), "-o", str(tmp_path / "o")]) == 2
    assert "template not found" in capsys.readouterr().err


def test_usage_error_exits_2(capsys):
    with pytest.raises(SystemExit) as info:
        main(["frobnicate"])
    assert info.value.code == 2


def test_write_atomically_replaces_only_when_complete(tmp_path):
    out = tmp_path / "build"
    write_atomically({"a.txt": b"1", "sub/b.txt": b"2"}, out)
    assert (out / "sub" / "b.txt").read_bytes() == b"2"

    files = {"a.txt": b"new", "z.txt": None}  # writing None fails half-way
    with pytest.raises(TypeError):
        write_atomically(files, out)  # type: ignore[arg-type]
    assert (out / "a.txt").read_bytes() == b"1"  # the old result is untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["build"]  # no temporary left behind
    write_atomically({"c.txt": b"3"}, out)
    assert sorted(p.name for p in out.iterdir()) == ["c.txt"]


def test_list_names_every_template(capsys):
    assert main(["list"]) == 0
    printed = capsys.readouterr().out
    for path in shipped_templates():
        assert path.stem in printed


TEMPLATES = [p.stem for p in shipped_templates()]


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    """Each shipped template built twice (determinism) — cached for the module."""
    cache: dict[str, tuple[int, Path, int, Path]] = {}

    def get(name: str):
        if name not in cache:
            root = tmp_path_factory.mktemp(name)
            code1 = main(["build", name, "-o", str(root / "one"), "-q"])
            code2 = main(["build", name, "-o", str(root / "two"), "-q"])
            cache[name] = (code1, root / "one", code2, root / "two")
        return cache[name]

    return get


@pytest.mark.parametrize("name", TEMPLATES)
def test_template_states_its_load_and_every_part_keeps_a_safety_factor_of_two(builds, name):
    """Issue 12: every shipped template states a design load and builds with every part and pin at a
    safety factor of at least 2 over the whole motion."""
    _, out, _, _ = builds(name)
    report = json.loads((out / "report.json").read_text())
    strength = report["strength"]
    assert strength["loads"], "the template states no [load]"
    assert strength["required_safety_factor"] == 2.0 and strength["passed"] is True
    rated = {p["name"]: p for p in strength["parts"]}
    for part in report["parts"]:
        if part["role"] != "spacer":
            assert part["name"] in rated, part["name"]
    for entry in rated.values():
        # null means the part carries no stress at this load (an infinite safety factor)
        assert entry["min_safety_factor"] is None or entry["min_safety_factor"] >= 2.0, entry
        if entry["min_safety_factor"] is not None:
            assert entry["stress_MPa"] * entry["min_safety_factor"] == pytest.approx(entry["allowable_MPa"], rel=1e-4)
    # something is loaded: the weakest part is within a factor 50 of its limit (a load that reaches no part
    # would pass vacuously)
    finite = [e["min_safety_factor"] for e in rated.values() if e["min_safety_factor"] is not None]
    assert finite and min(finite) < 50.0
    assert (out / "plots" / "strength.png").is_file()
    assert "## Strength" in (out / "report.md").read_text()


@pytest.mark.parametrize("name", TEMPLATES)
def test_template_builds_and_passes(builds, name):
    code, out, _, _ = builds(name)
    report = json.loads((out / "report.json").read_text())
    assert code == 0, report["checks"]["failures"]
    assert REPORT_KEYS <= set(report)
    assert report["checks"]["passed"] is True
    assert report["design"]["name"] == name
    for rel in report["files"]:
        assert (out / rel).is_file(), rel
    listed = set(report["files"])
    on_disk = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert listed == on_disk
    for part in report["parts"]:
        assert part["volume_mm3"] > 0 and (out / part["stl"]).is_file() and (out / part["dxf"]).is_file()
    inter = report["interference"]
    assert inter["poses"] >= 360 and inter["collisions"] == []


@pytest.mark.parametrize("name", TEMPLATES)
def test_same_template_gives_byte_identical_files(builds, name):
    _, one, _, two = builds(name)
    files_one = sorted(p.relative_to(one).as_posix() for p in one.rglob("*") if p.is_file())
    files_two = sorted(p.relative_to(two).as_posix() for p in two.rglob("*") if p.is_file())
    assert files_one == files_two
    differing = [rel for rel in files_one if (one / rel).read_bytes() != (two / rel).read_bytes()]
    assert differing == []


def test_lockup_inside_the_range_is_a_design_failure(monkeypatch):
    """A mechanism that cannot move through its own range: exit 1 and the report says where."""
    import fabricate.pipeline as pipeline
    from fabricate.spec import load_design
    from fabricate.synthesis.base import SynthesisResult
    from tests.conftest import make_four_bar

    locking = make_four_bar(crank=25.0, coupler=30.0, rocker=20.0, ground=40.0, start_deg=0.0, end_deg=180.0)
    monkeypatch.setattr(pipeline, "synthesise", lambda design, progress: SynthesisResult(locking, {"note": "x"}))
    for run in (pipeline.run_build, pipeline.run_synth):
        outcome = run(load_design("finger_five_bar_ncg"))
        assert outcome.exit_code == 1
        (failure,) = outcome.report["checks"]["failures"]
        assert failure.startswith("motion:") and "lock-up" in failure
        assert {"report.json", "report.md"} <= set(outcome.files)
