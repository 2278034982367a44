"""The Python API (issue 13): README's example runs as written, and the API gives the CLI's bytes."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

import fabricate
from fabricate.templates import TEMPLATE_DIR, read_toml

README = Path(__file__).resolve().parents[1] / "README.md"


def _example() -> str:
    text = README.read_text(encoding="utf-8")
    match = re.search(r"<!-- api-example: run by tests/test_api.py -->\s*```python\n(.*?)```", text, re.DOTALL)
    assert match, "README lost its API example"
    return match.group(1)


@pytest.mark.slow
def test_readme_api_example_runs_and_writes_its_files(tmp_path, capsys, shipped_build, serve_builds):
    """README's example as written; the folder it writes holds exactly the build's files (the CLI writes
    through the same run_build and write_output), and its motion.csv is the mechanism's sweep.

    The example's ``fabricate.build`` runs on the session's shared stage cache, which ``shipped_build`` fills with
    the same shipped finger (byte-identical to a cold build: tests/test_cache.py): the example's code path runs as
    written, the finger's stages are not computed a second time."""

    shipped_build("finger_underactuated")
    serve_builds()
    here = os.getcwd()
    os.chdir(tmp_path)
    scope: dict = {}
    try:
        exec(compile(_example(), "README.md", "exec"), scope)
    finally:
        os.chdir(here)
    printed = capsys.readouterr().out.splitlines()
    assert printed[0] == "True []"
    out = tmp_path / "outputs" / "finger_underactuated"
    written = {p.relative_to(out).as_posix(): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert written == scope["result"].files
    _check_motion_csv(written["motion.csv"], scope["design"])


def _check_motion_csv(data: bytes, design) -> None:
    """motion.csv against the mechanism's own sweep: its columns are the named points, its rows the poses."""
    import csv
    import io

    import numpy as np

    from fabricate.pipeline import synthesise

    rows = list(csv.reader(io.StringIO(data.decode())))
    mech = synthesise(design).mechanism
    names = mech.point_names()
    assert rows[0] == ["input"] + [f"{n}_{a}" for n in names for a in ("x", "y")]
    motion = mech.sweep(design.checks.sweep_poses)  # the build sweeps [checks] sweep_poses poses
    table = np.array(rows[1:], dtype=float)
    assert table.shape == (len(motion.inputs), 1 + 2 * len(names))
    np.testing.assert_allclose(table[:, 0], motion.inputs, atol=5e-7)
    for k, name in enumerate(names):
        np.testing.assert_allclose(table[:, 1 + 2 * k:3 + 2 * k], motion.point(name), atol=5e-7)


def test_load_takes_a_dict_and_names_a_bad_field():
    tables = read_toml(TEMPLATE_DIR / "gear_pair_elliptic.toml")
    design = fabricate.load(tables)
    assert design.name == "gear_pair_elliptic" and design.kind == "gear_pair"
    # the text it embeds reads back as the same tables
    from fabricate.templates import parse_toml

    assert parse_toml(design.template_text, "x") == tables
    tables["gears"]["module_mm"] = -1.0
    with pytest.raises(fabricate.SpecError, match="gears.module_mm"):
        fabricate.load(tables)


@pytest.mark.slow
def test_a_mechanism_built_in_code_goes_through_the_same_pipeline():
    """A four-bar made with fabricate.mechanism (no template) is written as a linkage template, built,
    and passes; its motion.csv follows the original mechanism's sweep (the written linkage has other body
    frames, so this is a round trip through the template, not the same numbers copied)."""
    import csv
    import io

    import numpy as np

    from tests.conftest import make_four_bar

    mech = make_four_bar()
    design = fabricate.from_mechanism(mech, tip_point="B", pads={"rocker": {"point": "B", "radius_mm": 3.0}},
                                      tables={"load": {"tip_force_N": 2.0}, "process": {"pin_diameter_mm": 3.0}})
    assert design.kind == "linkage" and "[linkage]" in design.template_text
    result = fabricate.build(design)
    assert result.passed, result.failures
    rows = list(csv.reader(io.StringIO(result.files["motion.csv"].decode())))
    table = np.array(rows[1:], dtype=float)
    original = mech.sweep(table[:, 0])
    for name in ("A", "B"):
        k = rows[0].index(f"{name}_x")
        np.testing.assert_allclose(table[:, k:k + 2], original.point(name), atol=2e-6)


def test_a_geared_mechanism_built_in_code_is_the_mechanism_built():
    """A mechanism with a gear coupling (a spline law) goes over exactly: the design's mechanism sweeps to
    the same poses, bit for bit, as the one built in code."""
    import numpy as np
    from scipy.interpolate import CubicSpline

    from fabricate.mechanism import Body, GearCoupling, Mechanism, Revolute
    from fabricate.pipeline import synthesise
    from tests.conftest import make_four_bar

    four_bar = make_four_bar()
    # a wheel on the ground turned at -1/2 by a pinion on the crank
    x = np.linspace(-10.0, 10.0, 41)
    law = CubicSpline(x, -0.5 * x)
    ground = Body("ground", {**four_bar.body("ground").points, "W": (-30.0, 0.0)})
    geared = Mechanism(name="geared", bodies=(ground, *four_bar.bodies[1:], Body("wheel", {"W": (0.0, 0.0)})),
                       ground="ground", joints=(*four_bar.joints, Revolute("W", "ground", "wheel")),
                       gears=(GearCoupling("g", "ground", "crank", "wheel", law, "O", "W", (1.0, 7.5)),),
                       drivers=four_bar.drivers, input_range=four_bar.input_range,
                       assembly={**four_bar.assembly, "wheel": (-30.0, 0.0, float(law(np.radians(60.0))))})
    again = synthesise(fabricate.from_mechanism(geared)).mechanism
    inputs = np.linspace(60.0, 420.0, 37)
    a, b = geared.sweep(inputs), again.sweep(inputs)
    for body in ("crank", "coupler", "rocker", "wheel"):
        assert np.array_equal(a.pose(body), b.pose(body)), body


def test_build_takes_a_process_like_the_cli(monkeypatch):
    """build(..., process=) replaces the design's process as `--process` does, for a name and for a design
    already loaded (the pipeline is stubbed: this is about which design reaches it)."""
    import fabricate.pipeline

    seen = []
    monkeypatch.setattr(fabricate.pipeline, "run_build", lambda design, pictures=True: seen.append(design) or
                        fabricate.pipeline.BuildOutcome(exit_code=0, report={}, files={}, design=design))
    design = fabricate.load("gear_pair_elliptic")
    assert design.process.name == "sla"
    for given in (design, "gear_pair_elliptic"):
        result = fabricate.build(given, process="laser")
        assert result.design is seen[-1]
        assert seen[-1].process.name == "laser" and seen[-1].process.kerf_mm > 0
        assert seen[-1].process_override.source == "laser"
        assert seen[-1].template_text == design.template_text
    fabricate.build(design)
    assert seen[-1] is design
    with pytest.raises(fabricate.SpecError, match="--process: expected sla, fdm, laser or a process profile file"):
        fabricate.build(design, process="cnc")


def test_one_result_type_for_the_api_and_the_pipeline(tmp_path):
    """fabricate.Build is the pipeline's BuildOutcome (one type for one build): what the CLI, check and sweeps
    get from run_build is what the API returns, with the API's verdict, failures, not-checked and write."""
    from fabricate.pipeline import BuildOutcome
    from fabricate.report import report_json

    assert fabricate.Build is BuildOutcome
    design = fabricate.load("gear_pair_elliptic")
    report = {"design": {"name": "x", "fabricate_version": fabricate.__version__, "stage": "build"},
              "checks": {"passed": False, "failures": ["strength: link too thin"],
                         "not_checked": [{"check": "interference", "reason": "no poses in the motion"}]},
              "files": ["report.json", "a.txt"]}
    result = BuildOutcome(exit_code=1, report=report, files={"a.txt": b"x", "report.json": report_json(report)},
                          design=design)
    assert not result.passed and result.failures == ["strength: link too thin"]
    assert result.not_checked == ["interference not checked: no poses in the motion"]
    out = result.write(tmp_path / "out")
    assert sorted(p.name for p in out.iterdir()) == ["a.txt", "report.json"]
    assert BuildOutcome(exit_code=0, report={"checks": {"failures": []}}).passed
    with pytest.raises(fabricate.SpecError, match="^force: expected True or False"):
        result.write(tmp_path / "again", force="yes")
    with pytest.raises(fabricate.SpecError, match="^out: expected an output folder"):
        result.write(3)
