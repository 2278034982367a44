"""The README's figures of the shipped hand-size sweep stay true: its generated block and PNG are what
``docs/make_readme_figures.py`` renders from the recorded run, and recorded points re-run through the sweep's
own task code keep their verdicts (issue 23: the table said 7 of 25 pass when the code gave 8)."""

from __future__ import annotations

import copy
import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "docs" / "make_readme_figures.py"


@pytest.fixture(scope="module")
def figures():
    """The script as a module (docs/ is not a package)."""
    spec = importlib.util.spec_from_file_location("make_readme_figures", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def record(figures):
    return figures.load_record()


def test_the_readme_block_and_png_are_rendered_from_the_recorded_sweep(figures, record):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert figures.stale_readme(readme, record, figures.PNG_PATH.read_bytes()) == []
    assert figures.readme_block(readme).count("\n| ") == 1 + 5  # the header and one row per middle length
    assert record["counts"] == figures.counts(record["points"])
    assert sum(record["counts"].values()) == len(record["points"])


def test_the_recorded_points_are_the_shipped_specs(figures, record):
    """A changed grid, map or template number makes the recording stale even before any verdict flips."""
    from fabricate.sweep import load_sweep

    spec = load_sweep(figures.SWEEP)
    assert [p["values"] for p in record["points"]] == spec.points()
    assert [p["point"] for p in record["points"]] == list(range(spec.count()))
    assert record["map"] == list(spec.map_fields)
    assert record["template"] == {"name": spec.template, "module_mm": spec.base["gears"]["module_mm"],
                                  "tip_force_N": spec.base["load"]["tip_force_N"]}


def test_a_stale_readme_or_recording_is_named(figures, record):
    """The check is not vacuous: a flipped verdict, an edited cell or a lost marker is reported."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    flipped = copy.deepcopy(record)
    passing = next(p for p in flipped["points"] if p["exit_code"] == 0)
    passing.update(exit_code=1, verdict="fail", failed_checks=["strength"])
    problems = figures.stale_readme(readme, flipped, None)
    assert len(problems) == 1 and "README.md" in problems[0] and figures.NAME in problems[0]
    block = figures.readme_block(readme)
    edited = readme.replace(block, block.replace(" ✓ |", " |", 1))
    assert figures.stale_readme(edited, record, None)
    assert "missing" in figures.stale_readme(readme.replace(figures.END, ""), record, None)[0]
    assert figures.stale_readme(readme, record, b"\x89PNG another picture")  # the PNG against its hash
    fresh = copy.deepcopy(record["points"][:3])
    fresh[1]["min_safety_factor"] = (fresh[1]["min_safety_factor"] or 0.0) + 0.5
    problems = figures.stale_points(record, fresh)
    assert len(problems) == 1 and problems[0].startswith(f"point {fresh[1]['point']} ")


@pytest.mark.slow
def test_recorded_verdicts_hold_for_a_passing_a_failing_and_an_infeasible_point(figures, record, monkeypatch):
    """The quickest recorded point of each verdict, re-run in this process through the function a sweep's
    Dask task runs: the same exit code, safety factor (as the table prints it) and failing checks. A code
    change that flips one turns this red; regenerate with ``python docs/make_readme_figures.py``."""
    monkeypatch.setenv("FABRICATE_SERIAL", "1")  # as in a Dask worker, and restored after the test
    chosen = []
    for code in (0, 1, 2):
        same = [p for p in record["points"] if p["exit_code"] == code]
        assert same, f"the recorded sweep has no point of exit code {code}"
        chosen.append(min(same, key=lambda p: (p["seconds"] or 0.0, p["point"])))
    fresh = figures.run_points([p["point"] for p in chosen])
    assert [p["values"] for p in fresh] == [p["values"] for p in chosen]
    assert figures.stale_points(record, fresh) == []
