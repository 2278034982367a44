"""A build without its pictures (``fabricate build --no-pictures``, ``run_build(..., pictures=False)``): the quick
edit loop of issue 27. Every other file is the full build's; report.json says what was skipped, and ``check``
rebuilds a folder with the pictures its build drew."""

from __future__ import annotations

import json
import os

import pytest

import fabricate
from fabricate.build_stages import PICTURES_SKIPPED
from fabricate.cli import main
from fabricate.design import load_design
from fabricate.errors import SpecError
from fabricate.pipeline import run_build
from fabricate.sweep.task import FILE_SECTIONS

PICTURES = (".png", ".gif")
#: The files a build without pictures writes otherwise: the file lists and notes, and the guide's picture links.
CHANGED = {"report.json", "report.md", "assembly.md"}


def _refused(*args, **kwargs):
    raise AssertionError("a build without pictures drew a figure")


@pytest.mark.parametrize("name", ["gear_pair_elliptic", pytest.param("finger_five_bar_ncg", marks=pytest.mark.slow)])
def test_a_build_without_pictures_makes_every_other_file_of_the_full_build(
        name, shipped_build, shared_stage_cache, monkeypatch) -> None:
    """No PNG or GIF, no figure drawn; every other file byte for byte the full build's but report.json, report.md
    and assembly.md; every report section the full build's but the file lists, ``outputs`` and ``notes``."""
    import fabricate.plotting

    full = shipped_build(name)
    monkeypatch.setattr(fabricate.plotting, "_savefig", _refused)  # in this process and any forked child
    with shared_stage_cache():
        quick = run_build(load_design(name), pictures=False)

    pictures = {rel for rel in full.files if rel.endswith(PICTURES)}
    assert pictures  # the full build draws them
    assert set(quick.files) == set(full.files) - pictures
    assert [rel for rel in quick.files if rel not in CHANGED and quick.files[rel] != full.files[rel]] == []
    assert quick.exit_code == full.exit_code
    assert list(quick.report) == list(full.report)
    for section in set(full.report) - FILE_SECTIONS - {"notes"}:
        assert quick.report[section] == full.report[section], section
    assert full.report["outputs"]["pictures"] == "written"
    assert quick.report["outputs"] == {**full.report["outputs"], "pictures": "skipped: built with --no-pictures"}
    assert quick.report["notes"] == [*full.report["notes"], PICTURES_SKIPPED]
    assert [m["path"] for m in quick.report["manifest"]] == sorted(set(quick.files) - {"report.json"})

    # assembly.md: the same steps, parts and words, no picture links (each of the full guide's names a picture)
    full_guide = full.files["assembly.md"].decode().splitlines()
    quick_guide = quick.files["assembly.md"].decode().splitlines()
    links = [line for line in full_guide if line.startswith("![step ")]
    assert links and len(links) == sum(line.startswith("## Step ") for line in full_guide)
    assert not [line for line in quick_guide if line.startswith("![")]
    assert [line for line in quick_guide if line.startswith("## Step ") or line.startswith("- ")] == \
        [line for line in full_guide if line.startswith("## Step ") or line.startswith("- ")]
    assert "--no-pictures" in quick_guide[2] and "--no-pictures" not in full.files["assembly.md"].decode()
    assert "## Pictures" in full.files["report.md"].decode() and "## Pictures" not in quick.files["report.md"].decode()


@pytest.mark.slow
def test_check_rebuilds_a_folder_with_the_pictures_its_build_drew(tmp_path, capsys, monkeypatch) -> None:
    """``fabricate check`` of a ``--no-pictures`` folder passes: its rebuild draws no pictures either (one that drew
    them would write files the folder lacks, a failure). STEP off in both (the core install), for time."""
    import fabricate.export.step

    monkeypatch.setattr(fabricate.export.step, "step_available", lambda: False)
    folder = tmp_path / "quick"
    assert main(["build", "linkage_stephenson", "-o", str(folder), "-q", "--no-pictures"]) == 0
    assert "pictures skipped" in capsys.readouterr().out
    assert not [p for p in folder.rglob("*") if p.suffix in PICTURES]
    assert json.loads((folder / "report.json").read_text())["outputs"]["pictures"].startswith("skipped")
    assert main(["check", str(folder), "-q"]) == 0, capsys.readouterr().out


def test_the_api_takes_pictures_as_a_flag() -> None:
    with pytest.raises(SpecError, match="pictures"):
        fabricate.build("gear_pair_elliptic", pictures="no")  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_build_without_pictures_never_imports_matplotlib_here(tmp_path) -> None:
    """The build's own process imports no matplotlib without pictures (its import is a sixth of the import floor);
    the exports' child imports what it needs itself."""
    import subprocess
    import sys

    code = ("import sys\nfrom fabricate.cli import main\n"
            f"code = main(['build', 'linkage_stephenson', '-o', {str(tmp_path / 'out')!r}, '-q', '--no-pictures'])\n"
            "print('matplotlib' in sys.modules, code)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600,
                          env={**os.environ, "FABRICATE_NO_CACHE": "1"})
    assert done.stdout.split()[-2:] == ["False", "0"], done.stdout + done.stderr
    assert (tmp_path / "out" / "parts").is_dir()


@pytest.fixture
def schedule(monkeypatch) -> list[str]:
    """What the build forks and when, in order: "exports child" (its first job is the exports'), "child" (any
    other), "gears" (the gear stage begins)."""
    import fabricate.pipeline as pipeline
    from fabricate.background import Background

    events: list[str] = []
    real_gears = pipeline._make_gears

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        events.append("exports child" if child.jobs and child.jobs[0].__name__ == "exports_job" else "child")
        return child

    monkeypatch.setattr(pipeline, "Background", spied)
    monkeypatch.setattr(pipeline, "_make_gears", lambda run: events.append("gears") or real_gears(run))
    return events


@pytest.mark.slow
def test_the_exports_child_is_forked_before_the_gears_or_else_after_the_parts(schedule, shipped_build,
                                                                              tmp_path) -> None:
    """A cold build forks the exports' child before the gears, to import the exporters while this process cuts
    the gears and makes the parts; the child waits for the part set and makes the full build's exports. Where the
    cache holds this design's exports for the other STEP choice (stored with STEP files, asked for without), no
    child is forked early, and after the parts, whose exports are not stored, the child is forked then: the files
    are the cold build's."""
    from fabricate.build_stages import OptionalOutputs
    from tests.conftest import _stage_cache_in

    design = load_design("gear_pair_elliptic")
    cold = run_build(design, optional=OptionalOutputs(step=False), pictures=False)
    assert schedule.count("exports child") == 1 and schedule.index("exports child") < schedule.index("gears")
    full = shipped_build("gear_pair_elliptic")
    made = {rel for rel in cold.files if rel not in CHANGED}
    assert made and made == {rel for rel in full.files if not rel.endswith((*PICTURES, ".step"))} - CHANGED
    assert [rel for rel in made if cold.files[rel] != full.files[rel]] == []

    with _stage_cache_in(tmp_path):
        run_build(design, optional=OptionalOutputs(step=True, step_files={}), pictures=False)
        schedule.clear()
        late = run_build(design, optional=OptionalOutputs(step=False), pictures=False)
    assert schedule.count("exports child") == 1 and schedule.index("exports child") > schedule.index("gears")
    assert late.files == cold.files


def test_no_early_exports_child_where_the_cache_holds_the_exports(schedule, shipped_build, shared_stage_cache):
    """A rebuild whose exports are stored (after a ``[load]`` edit, or none) forks no child to import the
    exporters: the exports come from the cache here, and a child forked after the parts draws the pictures."""
    shipped_build("gear_pair_elliptic")  # fills the shared cache with every stage of this design
    schedule.clear()
    with shared_stage_cache():
        again = run_build(load_design("gear_pair_elliptic"))
    assert again.files == shipped_build("gear_pair_elliptic").files
    assert "exports child" not in schedule
