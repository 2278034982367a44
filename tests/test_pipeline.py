"""The pipeline's report-only build (``run_build(..., report_only=True)``, what a build sweep's points make): the
full build's report without the files no report key is computed from (issue 27, item 4); its forked schedule."""

from __future__ import annotations

import os
import sys
from typing import NamedTuple

import pytest

from fabricate.background import Background
from fabricate.design import load_design
from fabricate.pipeline import BuildOutcome, run_build
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


class Child(NamedTuple):
    """One child a build made: the ``Background``, whether it forked when made, its ``hand_over`` and whether its
    jobs make the STEP files."""

    child: Background
    forked: bool
    hand_over: bool
    step: bool


class ForkedBuild(NamedTuple):
    """A build of the elliptic pair on the forked schedule, the children it made, and what was left after it: the
    warm and handed STEP workers (``background._WARM``, ``background._HANDED``) and this process's waiting ones."""

    outcome: BuildOutcome
    made: list[Child]
    warm: dict
    handed: list
    waiting: list[int]


@pytest.fixture(scope="module")
def forked_build() -> ForkedBuild:
    """The elliptic pair built once on the forked schedule with every child recorded, for the two tests that look at
    that schedule (its children and its bytes; where the STEP worker goes): one build between them instead of one
    each. What the build left is read right after it, before any other test runs."""
    import fabricate.pipeline as pipeline
    from fabricate import background

    made: list[Child] = []

    def spied(jobs, **kwargs):
        child = Background(jobs, **kwargs)
        made.append(Child(child, child.forked, kwargs.get("hand_over", True),
                          any(isinstance(job, background._Threaded) for job in jobs)))
        return child

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(pipeline, "Background", spied)
        patch.delenv("FABRICATE_SERIAL", raising=False)
        outcome = run_build(load_design("gear_pair_elliptic"))
    waiting = _waiting_workers() if sys.platform.startswith("linux") else []  # /proc: its test skips elsewhere
    return ForkedBuild(outcome, made, dict(background._WARM), list(background._HANDED), waiting)


@pytest.mark.slow
def test_the_forked_schedule_makes_the_serial_builds_bytes(forked_build, monkeypatch):
    """A build forks children while it runs its stages (the method's figures after synthesis, the gear pictures
    after the gears, the exports and the part set's pictures after the parts: ``pipeline._build_stages``); every
    file is the serial build's (``FABRICATE_SERIAL``: each job in this process when its result is asked for),
    report.json's bytes included, whose sections keep the serial order although the checks ran before the
    exports' sections were known here. The forked build is the module's (``forked_build``)."""
    import fabricate.pipeline as pipeline

    forked = forked_build.outcome
    exporting = [c.forked for c in forked_build.made if c.child.jobs and c.child.jobs[0].__name__ == "exports_job"]
    assert exporting == [True]
    # the synthesis plots, the gear pictures, the exports and the part set's pictures, the strength and drive plots
    assert sum(c.forked for c in forked_build.made) == 4
    made: list[tuple[Background, bool]] = []  # each child of the serial build, and whether it forked when made

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        made.append((child, child.forked))
        return child

    monkeypatch.setattr(pipeline, "Background", spied)
    monkeypatch.setenv("FABRICATE_SERIAL", "1")
    serial = run_build(load_design("gear_pair_elliptic"))
    assert made and not [child for child, forked in made if forked]
    assert not [child for child, _ in made if child.jobs and child.jobs[0].__name__ == "exports_job"]
    assert list(forked.report) == list(serial.report)
    assert sorted(forked.files) == sorted(serial.files)
    assert [rel for rel in forked.files if forked.files[rel] != serial.files[rel]] == []


def _kernel_failure_in(stage: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Make ``stage`` ("exports" or "checks") raise a GeometryError, in this process and in any child forked after."""
    import fabricate.checks
    import fabricate.export
    from fabricate.errors import GeometryError

    def failing(*args, **kwargs):
        raise GeometryError(f"no {stage} for this design")

    monkeypatch.setattr(fabricate.export if stage == "exports" else fabricate.checks,
                        "export_part_files" if stage == "exports" else "run_checks", failing)


@pytest.mark.slow
@pytest.mark.parametrize("stage", ["exports", "checks"])
def test_a_kernel_failure_reports_the_same_whether_the_exports_were_forked(stage, monkeypatch):
    """A geometry kernel failing in the exports (made by a forked child while this process runs the checks) or in
    the checks (while the child makes the exports) is the serial build's design failure: the stage a serial build
    fails in named, exit code 1, no exception, and report.json's bytes the serial build's (no check section where
    the exports failed; the exports' sections where the checks did)."""
    import fabricate.pipeline as pipeline
    from fabricate.build_stages import OptionalOutputs

    forks: list[bool] = []

    def spied(*args, **kwargs):
        child = Background(*args, **kwargs)
        if child.jobs and child.jobs[0].__name__ == "exports_job":
            forks.append(child.forked)
        return child

    monkeypatch.setattr(pipeline, "Background", spied)
    _kernel_failure_in(stage, monkeypatch)
    design = load_design("gear_pair_elliptic")
    no_step = OptionalOutputs(step=False)  # no OCP worker left computing after the failure
    forked = run_build(design, optional=no_step)
    assert forks == [True]  # the exports child forked
    monkeypatch.setenv("FABRICATE_SERIAL", "1")
    serial = run_build(design, optional=no_step)
    assert forked.exit_code == serial.exit_code == 1
    assert forked.failures == serial.failures == [f"{stage}: this design cannot be made (no {stage} for this design)"]
    assert "interference" not in forked.report and ("parts" in forked.report) == (stage == "checks")
    assert list(forked.report) == list(serial.report)
    assert forked.files == serial.files  # report.json's bytes included


def _waiting_workers() -> list[int]:
    """The pids of this process's live children that are :func:`fabricate.background.run_isolated` workers."""
    from pathlib import Path

    found = []
    for entry in Path("/proc").iterdir():
        try:
            stat = (entry / "stat").read_text()
            command = (entry / "cmdline").read_bytes()
        except OSError:  # not a process, or it ended while we looked
            continue
        state, ppid = stat[stat.rindex(")") + 2:].split()[:2]
        if int(ppid) == os.getpid() and state not in ("Z", "X") and b"_isolated_main" in command:
            found.append(int(entry.name))
    return found


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_only_the_child_that_makes_the_step_files_takes_the_prestarted_worker(forked_build):
    """The STEP worker ``run_build`` prestarts goes to the one child whose jobs include the STEP job (the early
    children and the plots' child leave it: a child that takes it kills it when collected, and the STEP job would
    start a cold one), and after the build no worker is left waiting or unreaped. The build is the module's
    (``forked_build``), what it left read right after it."""
    made = [(c.hand_over, c.step) for c in forked_build.made]  # each child's hand_over, and whether it makes STEP
    assert forked_build.outcome.exit_code == 0
    assert len(made) == 4 and sum(step for _, step in made) == 1  # two early children, the exports, the plots
    assert [hand_over for hand_over, _ in made] == [step for _, step in made]
    assert forked_build.warm == {} and forked_build.handed == []
    assert forked_build.waiting == []
