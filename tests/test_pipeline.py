"""The pipeline's report-only build (``run_build(..., report_only=True)``, what a build sweep's points make): the
full build's report without the files no report key is computed from (issue 27, item 4); its forked schedule."""

from __future__ import annotations

import pytest

from fabricate.background import Background
from fabricate.design import load_design
from fabricate.pipeline import run_build
from fabricate.sweep.task import FILE_SECTIONS

#: What a report-only build never makes: pictures (synthesis and gear plots, previews, the guide's) and STEP files.
SKIPPED_SUFFIXES = (".png", ".gif", ".step")


@pytest.mark.slow
@pytest.mark.parametrize(("name", "cached"), [("gear_pair_elliptic", False), ("finger_five_bar_ncg", True)])
def test_a_report_only_build_has_the_full_builds_report_without_pictures_or_step(
        name, cached, shipped_build, shared_stage_cache, monkeypatch) -> None:
    """Every report section but the file lists (``files``, ``manifest``) and ``outputs`` equals the full build's,
    and so does every file both make; no picture, plot or STEP file is made, no picture child forked, no STEP
    worker started. The elliptic pair is built cold (every stage computed again, without the pictures); the
    default finger's stages are served by the cache ``shipped_build`` filled (its full build took them from the
    same code), so what is tested there is what the pipeline does around its stages."""
    import fabricate.export
    import fabricate.pipeline as pipeline

    full = shipped_build(name)

    def refused(*args, **kwargs):
        raise AssertionError("a report-only build forked a picture child or started the STEP worker")

    monkeypatch.setattr(pipeline, "Background", refused)
    monkeypatch.setattr(fabricate.export, "prestart_step", refused)
    if cached:
        with shared_stage_cache():
            lean = run_build(load_design(name), report_only=True)
    else:
        lean = run_build(load_design(name), report_only=True)

    assert lean.exit_code == full.exit_code
    assert list(lean.report) == list(full.report)  # the same sections, in the same order
    for section in full.report:
        if section not in FILE_SECTIONS:
            assert lean.report[section] == full.report[section], section
    # STEP files as the full build made them (the cad extra) or skipped them (a core install), never made here
    assert lean.report["outputs"]["step"] == ("skipped: a report-only build (a sweep point)"
                                              if full.report["outputs"]["step"] == "written"
                                              else full.report["outputs"]["step"])

    made = set(lean.files)
    assert made < set(full.files)
    assert not [rel for rel in made if rel.endswith(SKIPPED_SUFFIXES)]
    assert [rel for rel in full.files if rel.endswith(SKIPPED_SUFFIXES)]  # the full build makes them
    assert all(lean.files[rel] == full.files[rel] for rel in made - {"report.json", "report.md"})
    assert lean.report["files"] == sorted(made)
    assert [m["path"] for m in lean.report["manifest"]] == sorted(made - {"report.json"})


def test_the_forked_schedule_makes_the_serial_builds_bytes(monkeypatch):
    """A build forks children while it runs its stages (the method's figures after synthesis, the gear pictures
    after the gears, the exports and the part set's pictures after the parts: ``pipeline._build_stages``); every
    file is the serial build's (``FABRICATE_SERIAL``: each job in this process when its result is asked for),
    report.json's bytes included, whose sections keep the serial order although the checks ran before the
    exports' sections were known here."""
    import fabricate.pipeline as pipeline

    made: list[tuple[Background, bool]] = []  # each child, and whether it forked when made

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        made.append((child, child.forked))
        return child

    monkeypatch.setattr(pipeline, "Background", spied)
    design = load_design("gear_pair_elliptic")
    forked = run_build(design)
    exporting = [forked for child, forked in made if child.jobs and child.jobs[0].__name__ == "exports_job"]
    assert exporting == [True]
    # the synthesis plots, the gear pictures, the exports and the part set's pictures, the strength and drive plots
    assert sum(forked for _, forked in made) == 4
    monkeypatch.setenv("FABRICATE_SERIAL", "1")
    made.clear()
    serial = run_build(design)
    assert made and not [child for child, forked in made if forked]
    assert not [child for child, _ in made if child.jobs and child.jobs[0].__name__ == "exports_job"]
    assert list(forked.report) == list(serial.report)
    assert sorted(forked.files) == sorted(serial.files)
    assert [rel for rel in forked.files if forked.files[rel] != serial.files[rel]] == []
