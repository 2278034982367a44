"""The build's stages after synthesis, each a step on one :class:`BuildRun`: gears, parts, exports and the checks.

:mod:`fabricate.pipeline` runs them in order and schedules the pictures around them (forked children); each
stage reads what earlier stages left on the run and adds its own report sections and files, its result a
:mod:`fabricate.cache` entry keyed by the inputs it reads (:mod:`fabricate.stage_keys`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from fabricate import cache, stage_keys
from fabricate.mechanism import Mechanism, Motion
from fabricate.spec import DesignSpec
from fabricate.synthesis.base import SynthesisResult

if TYPE_CHECKING:
    from fabricate.checks import CheckReport
    from fabricate.drive.check import DriveResult
    from fabricate.gears.pair import GearPair
    from fabricate.parts.partset import PartSet
    from fabricate.strength.check import StrengthResult

Progress = Callable[[str], None]
#: What the exports stage computes (files, the parts' report entries, a cut process's ``cut`` section): one cache
#: entry, and what a forked export child hands back.
Exported = tuple[dict[str, bytes], list[dict[str, Any]], Any]


def _quiet(_: str) -> None:
    """No progress lines."""


@dataclass(frozen=True)
class OptionalOutputs:
    """Which optional outputs a build makes, when not what this install can make.

    ``fabricate check`` rebuilds a folder with the outputs its build recorded (``report.outputs``), so its
    verdict does not depend on the checker's install.

    Attributes
    ----------
    step : bool
        Write the STEP files (``parts/*.step``, ``assembly.step``) and report them as written.
    step_files : mapping of str to bytes, optional
        Files to hand over in place of a STEP export (the folder's own, verified against its manifest,
        where the checker has no OCP); None exports them.
    """

    step: bool
    step_files: Mapping[str, bytes] | None = None


@dataclass
class BuildRun:
    """One build in progress after synthesis: the stage running, and what the stages before it made.

    Each step of :func:`_build_stages` reads what earlier steps left here and adds its own part (report
    sections, files); :attr:`stage` names the step running, so a kernel failure inside it is reported with it.
    """

    design: DesignSpec  # the design being built: link sizing replaces it with the width it chose
    synthesis: SynthesisResult
    motion: Motion
    report: dict[str, Any]
    progress: Progress = _quiet
    optional: OptionalOutputs | None = None
    report_only: bool = False  # no pictures, plots or STEP files (:func:`run_build`)
    pictures: bool = True  # False: no pictures or plots, the rest a full build's (``build --no-pictures``)
    given: DesignSpec | None = None  # the design the caller gave (the outcome's); None: ``design``
    stage: str = "gears"
    files: dict[str, bytes] = field(default_factory=dict)
    gear_pairs: list[GearPair] = field(default_factory=list)
    sizing: dict[str, Any] | None = None
    partset: PartSet | None = None
    checks: CheckReport | None = None
    strength: StrengthResult | None = None
    drive: DriveResult | None = None
    failures: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.given is None:
            self.given = self.design

    @property
    def draws(self) -> bool:
        """Whether this build draws its pictures and plots (neither report-only nor without pictures)."""
        return self.pictures and not self.report_only

    @property
    def mechanism(self) -> Mechanism:
        return self.synthesis.mechanism

    def enter(self, stage: str) -> None:
        """Start ``stage``: it names any failure from here on, and the progress line shows it."""
        self.stage = stage
        self.progress(stage)


def make_gears(run: BuildRun) -> None:
    """One cut, checked gear pair per gear coupling: report.json's ``gears``."""
    from fabricate.gears import build_gear_pairs
    from fabricate.gears.auto import module_limits

    run.enter("gears")
    # gears.module_mm = "auto": the smallest standard module the process makes and the load allows
    run.gear_pairs = cache.cached("gears", stage_keys.gears_key(run.design), lambda: build_gear_pairs(
        run.mechanism, run.design.gears, run.design.process.chord_tolerance_mm,
        lambda: module_limits(run.design, run.mechanism, run.motion, run.synthesis.parts)))
    run.report["gears"] = [pair.report() for pair in run.gear_pairs]


def size_links(run: BuildRun) -> None:
    """``parts.link_width_mm = "auto"``: the width the strength check asks for replaces it in the design."""
    from fabricate.parts.build import build_parts
    from fabricate.strength.sizing import size_link_width

    run.enter("sizing")
    design, mechanism, motion, gear_pairs, hints = run.design, run.mechanism, run.motion, run.gear_pairs, \
        run.synthesis.parts
    width, tried = cache.cached("sizing", stage_keys.sizing_key(design), lambda: size_link_width(
        design, mechanism, motion, gear_pairs, hints, lambda d: build_parts(d, mechanism, motion, gear_pairs, hints)))
    run.design = dataclasses.replace(design, parts=dataclasses.replace(design.parts, link_width_mm=width))
    run.sizing = {"link_width_mm": width, "tried": [{"link_width_mm": w, "least_safety_factor": sf}
                                                    for w, sf in tried]}


def make_parts(run: BuildRun) -> None:
    """Every body as parts (plates, gears fused on), pins, spacers and the bill of materials."""
    from fabricate.parts.build import build_parts

    run.enter("parts")
    run.partset = cache.cached("parts", stage_keys.parts_key(run.design), lambda: build_parts(
        run.design, run.mechanism, run.motion, run.gear_pairs, run.synthesis.parts))


#: report.json's note (and the command's) for a build without its pictures.
PICTURES_SKIPPED = ("pictures skipped: built with --no-pictures (plots/, previews/, the gear pictures and "
                    "assembly/ step pictures are drawn by a build without it)")


def record_optional_outputs(run: BuildRun) -> bool:
    """Whether STEP files are made, recorded in report.json (``notes``, ``outputs``); returned."""
    from fabricate.export import STEP_SKIPPED
    from fabricate.export.step import step_available

    with_step = step_available() if run.optional is None else run.optional.step
    run.report["notes"] = ([] if with_step else [STEP_SKIPPED]) + ([] if run.pictures else [PICTURES_SKIPPED])
    # optional outputs as written or skipped: `check` rebuilds with the same set, so its verdict does not
    # depend on the checker's install (fabricate/verify.py)
    sweep_point = "skipped: a report-only build (a sweep point)"
    run.report["outputs"] = {"step": "written" if with_step and not run.report_only else
                             sweep_point if with_step else "skipped: OCP is not installed (extra 'cad')",
                             "pictures": "written" if run.draws else sweep_point if run.pictures else
                             "skipped: built with --no-pictures"}
    return with_step  # the exports name the STEP files a full build writes: a report-only one's parts are the same


def export_files(run: BuildRun, with_step: bool) -> Exported:
    """What :func:`export` computes, without the cache: run here or in the forked export child."""
    from fabricate.export import export_all

    assert run.partset is not None  # the parts stage ran
    sections: dict[str, Any] = {}  # a cut process adds its "cut" section: part of the cached result
    # the part files read no layout field: an entry of their own, reused after a layout edit
    files, parts = export_all(run.design, run.partset, run.mechanism, run.motion, previews=False, step=False,
                              with_step=with_step, sections=sections,
                              keep=lambda make: cache.cached("part_files", stage_keys.parts_key(run.design), make))
    return files, parts, sections.get("cut")


def export(run: BuildRun, with_step: bool, made: Callable[[], Exported] | None = None) -> None:
    """Part files, drawings, plates or sheets, the BOM and assembly, motion.csv and mechanism.toml.

    ``made`` hands over :func:`export_files`' result where a forked child computed it (the stage is then
    entered already, and the result stored here); None computes it here.
    """
    from fabricate.export import assembly_csv, motion_csv
    from fabricate.export.guide import guide_markdown, guide_steps
    from fabricate.parts.assembly import assembly_steps, guide_report, pin_stacks, stacks_report
    from fabricate.parts.hardware_report import hardware_report
    from fabricate.parts.spring_rows import springs_report
    from fabricate.synthesis.linkage.exact import mechanism_toml

    if made is None:
        run.enter("exports")
    assert run.partset is not None  # the parts stage ran
    exported, parts_report, cut = cache.cached("exports", stage_keys.exports_key(run.design, with_step),
                                               made or (lambda: export_files(run, with_step)))
    if cut is not None:
        run.report["cut"] = cut
    run.files.update(exported)
    run.report["parts"] = parts_report
    run.report["bom"] = list(getattr(run.partset, "bom", []))
    run.report["hardware"] = hardware_report(run.partset, run.design.process)  # pins, fits, what to measure
    if getattr(run.partset, "springs", ()):
        run.report["springs"] = springs_report(run.partset.springs)
    stacks = pin_stacks(run.partset)
    guide = guide_steps(run.partset, run.motion)  # assembly.md; its pictures are drawn by _picture_jobs
    run.report["assembly"] = {"pins": stacks_report(stacks), "steps": assembly_steps(stacks, run.partset.copies),
                              "guide": guide_report(guide)}
    run.files["assembly.md"] = guide_markdown(guide, run.design.name, run.partset.copies,
                                              pictures=run.pictures).encode("utf-8")
    run.files["assembly.csv"] = assembly_csv(stacks)
    run.files["motion.csv"] = motion_csv(run.mechanism, run.motion)
    run.files["mechanism.toml"] = mechanism_toml(run.design, run.mechanism, run.synthesis.parts)
    # the MuJoCo model: its meshes are the part STL files just exported (fabricate/export/mjcf.py)
    from fabricate.export.mjcf import mechanism_mjcf, simulation_section

    stl = {part.name: run.files[f"parts/{part.name}.stl"] for part in run.partset.parts}
    run.files["mechanism.xml"] = mechanism_mjcf(run.design, run.partset, run.mechanism, run.motion, run.gear_pairs,
                                                stl)
    run.report["simulation"] = simulation_section(run.design, run.partset, run.mechanism, run.motion)


def check(run: BuildRun) -> None:
    """Interference, gear mesh and printability (report.json's ``interference``), and the gear pairs' own."""
    from fabricate.checks import run_checks

    run.enter("checks")
    assert run.partset is not None  # the parts stage ran
    partset = run.partset
    run.checks = cache.cached("checks", stage_keys.checks_key(run.design), lambda: run_checks(
        run.design, partset, run.mechanism, run.motion, run.gear_pairs))
    run.report["interference"] = run.checks.interference
    run.failures = list(run.checks.failures)
    for pair in run.gear_pairs:
        run.failures += [f"gear {pair.name}: {text}" for text in pair.failures()]


def check_strength(run: BuildRun) -> None:
    """Every part and pin at the design load: report.json's ``strength`` (with the link sizing, if any)."""
    from fabricate.strength.check import run_strength

    run.enter("strength")
    assert run.partset is not None  # the parts stage ran
    partset = run.partset
    run.strength = cache.cached("strength", stage_keys.strength_key(run.design), lambda: run_strength(
        run.design, partset, run.mechanism, run.motion, run.gear_pairs, run.synthesis.parts))
    run.report["strength"] = run.strength.report()
    if run.sizing is not None:
        run.report["strength"]["sizing"] = run.sizing
    run.failures += run.strength.failures()


def check_drive(run: BuildRun) -> None:
    """The actuator against the input effort the statics compute at every pose: report.json's ``drive``."""
    from fabricate.drive.check import rate_mount, run_drive

    run.enter("drive")
    assert run.partset is not None  # the parts stage ran
    run.drive = run_drive(run.design, run.mechanism, run.motion, run.synthesis.parts, run.strength,
                          copies=run.partset.copies)
    rate_mount(run.drive, run.partset, run.design)  # the mount plate's holes against the reaction torque
    run.report["drive"] = run.drive.report()
    run.failures += run.drive.failures()


def verdict(run: BuildRun) -> None:
    """report.json's ``checks``: passed is over the checks that ran; those that could not run are listed,
    never passed."""
    assert run.checks is not None and run.strength is not None  # both checks ran
    not_checked = [dict(entry) for entry in run.checks.not_checked]
    if run.strength.reason is not None:
        not_checked.append({"check": "strength", "reason": run.strength.reason})
    if run.drive is not None and run.drive.reason is not None:
        not_checked.append({"check": "drive", "reason": run.drive.reason})
    run.report["checks"] = {"passed": not run.failures, "failures": run.failures, "not_checked": not_checked}


