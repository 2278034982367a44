"""The pipeline's report-only build (``run_build(..., report_only=True)``, what a build sweep's points make): the
full build's report without the files no report key is computed from (issue 27, item 4)."""

from __future__ import annotations

import pytest

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
