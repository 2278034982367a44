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
def test_the_exports_child_is_forked_before_the_gears(shipped_build, monkeypatch) -> None:
    """The exports' child imports the exporters while this process cuts the gears and makes the parts: it is
    forked before the gears (and before the gear pictures' child), and makes the full build's exports (a cold
    build: the child waits for the part set, then exports it)."""
    import fabricate.pipeline as pipeline
    from fabricate.background import Background
    from fabricate.build_stages import OptionalOutputs

    events: list[str] = []
    real_gears = pipeline._make_gears

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        events.append("exports child" if child.jobs and child.jobs[0].__name__ == "exports_job" else "child")
        return child

    monkeypatch.setattr(pipeline, "Background", spied)
    monkeypatch.setattr(pipeline, "_make_gears", lambda run: events.append("gears") or real_gears(run))
    built = run_build(load_design("gear_pair_elliptic"), optional=OptionalOutputs(step=False), pictures=False)
    assert events.index("exports child") < events.index("gears")
    full = shipped_build("gear_pair_elliptic")
    made = {rel for rel in built.files if rel not in CHANGED}
    assert made and made == {rel for rel in full.files if not rel.endswith((*PICTURES, ".step"))} - CHANGED
    assert [rel for rel in made if built.files[rel] != full.files[rel]] == []


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


def test_no_early_exports_child_where_the_cache_holds_the_exports(shipped_build, shared_stage_cache, monkeypatch):
    """A rebuild whose exports are stored (after a ``[load]`` edit, or none) forks no child to import the
    exporters: the exports come from the cache here, and a child forked after the parts draws the pictures."""
    import fabricate.pipeline as pipeline
    from fabricate.background import Background

    shipped_build("gear_pair_elliptic")  # fills the shared cache with every stage of this design
    events: list[str] = []

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        events.append("exports child" if child.jobs and child.jobs[0].__name__ == "exports_job" else "child")
        return child

    monkeypatch.setattr(pipeline, "Background", spied)
    with shared_stage_cache():
        again = run_build(load_design("gear_pair_elliptic"))
    assert again.files == shipped_build("gear_pair_elliptic").files
    assert "exports child" not in events


@pytest.mark.slow
def test_the_exports_child_is_forked_after_the_parts_where_the_stored_exports_were_another_builds(
        tmp_path, monkeypatch) -> None:
    """Exports stored for the build with STEP files, asked for without: no child is forked early (the cache held
    exports of this design), and after the parts, whose exports are not stored, the exports' child is forked then;
    the files are those of a build without the cache."""
    import fabricate.pipeline as pipeline
    from fabricate.background import Background
    from fabricate.build_stages import OptionalOutputs
    from tests.conftest import _stage_cache_in

    design = load_design("gear_pair_elliptic")
    events: list[str] = []
    real_gears = pipeline._make_gears

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        events.append("exports child" if child.jobs and child.jobs[0].__name__ == "exports_job" else "child")
        return child

    with _stage_cache_in(tmp_path):
        run_build(design, optional=OptionalOutputs(step=True, step_files={}), pictures=False)
        monkeypatch.setattr(pipeline, "Background", spied)
        monkeypatch.setattr(pipeline, "_make_gears", lambda run: events.append("gears") or real_gears(run))
        late = run_build(design, optional=OptionalOutputs(step=False), pictures=False)
    assert events.count("exports child") == 1 and events.index("exports child") > events.index("gears")
    cold = run_build(design, optional=OptionalOutputs(step=False), pictures=False)
    assert late.files == cold.files
