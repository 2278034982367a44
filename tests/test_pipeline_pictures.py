"""A build without its pictures (``fabricate build --no-pictures``, ``run_build(..., pictures=False)``): the quick
edit loop of issue 27. Every other file is the full build's; report.json says what was skipped, and ``check``
rebuilds a folder with the pictures its build drew."""

from __future__ import annotations

import json

import pytest

import fabricate
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


@pytest.mark.parametrize("name", ["gear_pair_elliptic", "finger_five_bar_ncg"])
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
    assert [n for n in quick.report["notes"] if n not in full.report["notes"]] == [
        n for n in quick.report["notes"] if n.startswith("pictures skipped")]
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
