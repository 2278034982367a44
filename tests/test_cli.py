"""The command-line contract: exit codes, nothing written on bad input, atomic output, determinism,
and every shipped template built end to end."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fabricate.cli import main
from fabricate.output import write_atomically
from fabricate.templates import shipped_templates

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
def builds(built_folder):
    """Each shipped template built cold by the command into a folder: ``(exit code, folder)``, once per test
    session (``built_folder``; the second build, for determinism, is the session's in-memory ``shipped_build``).
    The folder is shared: these tests only read it."""

    def get(name: str) -> tuple[int, Path]:
        found = built_folder(name, read_only=True)
        return found.exit_code, found.path

    return get


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_template_states_its_load_and_every_part_keeps_a_safety_factor_of_two(shipped_build, name):
    """Issue 12: every shipped template states a design load and builds with every part and pin at a
    safety factor of at least 2 over the whole motion."""
    files = shipped_build(name).files
    report = json.loads(files["report.json"])
    strength = report["strength"]
    assert strength["loads"], "the template states no [load]"
    assert strength["required_safety_factor"] == 2.0 and strength["passed"] is True
    rated = {p["name"]: p for p in strength["parts"]}
    pinned = {j for p in report["hardware"]["pins"] for j in (p["pin"], *p["pin"].split("+"))}
    for part in report["parts"]:
        if part["role"] in ("mount", "standoff", "arbor"):
            # Step 14's drive mount plate and standoffs (on the actuator's screws) and a spring's arbor (bonded
            # to a part's face) carry no pin of the mechanism: the statics puts no load on them to rate
            assert not {h["joint"] for h in part["holes"]} & pinned, part["name"]
        elif part["role"] != "spacer":
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
    assert "plots/strength.png" in files
    assert "## Strength" in files["report.md"].decode()


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_template_builds_and_passes(builds, name):
    code, out = builds(name)
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


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_same_template_gives_byte_identical_files(builds, shipped_build, name):
    """Two builds of one template, one by the command into a folder and one in memory, give the same files."""
    _, one = builds(name)
    two = shipped_build(name).files
    files_one = sorted(p.relative_to(one).as_posix() for p in one.rglob("*") if p.is_file())
    assert files_one == sorted(two)
    differing = [rel for rel in files_one if (one / rel).read_bytes() != two[rel]]
    assert differing == []


def test_lockup_inside_the_range_is_a_design_failure(monkeypatch):
    """A mechanism that cannot move through its own range: exit 1 and the report says where."""
    import fabricate.pipeline as pipeline
    from fabricate.design import load_design
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


@pytest.mark.slow
def test_default_finger_rebuilt_from_its_mechanism_toml_gives_identical_parts(builds, tmp_path):
    """Issue 13: every build writes mechanism.toml, a linkage template of the same mechanism; built, it
    gives the default finger's parts, drawings, plates and gears byte for byte (and writes itself again)."""
    _, out = builds("finger_five_bar_ncg")
    template = tmp_path / "mechanism.toml"
    template.write_bytes((out / "mechanism.toml").read_bytes())
    assert "every law is written exactly" in template.read_text()
    again = tmp_path / "again"
    assert main(["build", str(template), "-o", str(again), "-q"]) == 0
    compared = 0
    for folder in ("parts", "drawings", "plates", "gears"):
        for path in sorted((out / folder).rglob("*")):
            if path.is_file():
                rel = path.relative_to(out)
                assert (again / rel).read_bytes() == path.read_bytes(), rel
                compared += 1
    assert compared >= 16
    first, second = ((d / "mechanism.toml").read_text().splitlines()[2:] for d in (out, again))
    assert [line for line in first if not line.startswith("description")] == \
        [line for line in second if not line.startswith("description")]


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_every_build_writes_a_mechanism_toml_that_rebuilds_its_motion(builds, name, tmp_path):
    """Every template's mechanism.toml loads as a linkage and moves as the build did: its points against the
    build's motion.csv at five poses (1e-6 mm where every law is exact; 1e-3 mm with a sampled law)."""
    import csv
    import io

    import numpy as np

    from fabricate.design import load_design
    from fabricate.pipeline import synthesise

    _, out = builds(name)
    path = tmp_path / "mechanism.toml"
    path.write_bytes((out / "mechanism.toml").read_bytes())
    design = load_design(path)
    assert design.kind == "linkage"
    exact = "every law is written exactly" in path.read_text()
    rows = list(csv.reader(io.StringIO((out / "motion.csv").read_text())))
    table = np.array(rows[1:], dtype=float)
    pick = np.linspace(0, len(table) - 1, 5).round().astype(int)
    motion = synthesise(design).mechanism.sweep(len(table))  # the build's inputs (the CSV rounds them)
    np.testing.assert_allclose(motion.inputs, table[:, 0], atol=5e-7)
    for k in range(1, len(rows[0]), 2):
        point = rows[0][k][:-2]
        np.testing.assert_allclose(motion.point(point)[pick], table[pick, k:k + 2], atol=1e-6 if exact else 1e-3,
                                   err_msg=point)
