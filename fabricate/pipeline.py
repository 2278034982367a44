"""The whole pipeline: template → spec → synthesis → mechanism → gears → parts → exports and checks.

Everything is computed in memory into ``{relative path: bytes}``; only :mod:`fabricate.output` touches
the file system, into a temporary sibling directory swapped into place when every file is written, so a
failed run never leaves half a result. report.json carries a manifest of every other file (size, sha256)
and the template text itself, so ``fabricate check DIR`` can verify the files and rebuild them.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fabricate import cache, stage_keys
from fabricate.arguments import path_argument, type_name
from fabricate.background import Background, in_thread
from fabricate.bounds import blas_threads, rare_collections
from fabricate.errors import FabricateError, LockupError, SpecError, SynthesisError
from fabricate.kinds import KINDS
from fabricate.mechanism import Mechanism, Motion
from fabricate.report import SYNTH_ONLY, not_checked_notes, report_json, report_markdown
from fabricate.report_schema import SCHEMA_VERSION
from fabricate.report_sections import design_section, mechanism_section
from fabricate.spec import DesignSpec
from fabricate.synthesis.base import SynthesisResult

if TYPE_CHECKING:
    from fabricate.checks import CheckReport
    from fabricate.drive.check import DriveResult
    from fabricate.gears.pair import GearPair
    from fabricate.parts.partset import PartSet
    from fabricate.strength.check import StrengthResult

Progress = Callable[[str], None]


@dataclass(frozen=True)
class BuildOutcome:
    """A finished run of the pipeline, in memory: the one result type of a build.

    :func:`run_build` and :func:`run_synth` return it, and so does the API's ``fabricate.build``, which
    calls it :class:`fabricate.Build`.

    Attributes
    ----------
    exit_code : int
        0 when every check that ran passes, 1 when the design fails one (the files are still made): the
        CLI's exit code.
    report : dict
        report.json's content (its keys: ``fabricate/report_schema.json``, described in ``docs/report.md``).
    files : dict
        Every output file, ``{path relative to the output folder: bytes}``, report.json and report.md included.
    design : DesignSpec or None
        The design the run was given (None only in a result made by hand, such as a test's stand-in).
    synthesis, motion, partset, gear_pairs, checks
        What the stages made, for callers that look past the files (None or empty where the run stopped
        before that stage).
    """

    exit_code: int
    report: dict[str, Any]
    files: dict[str, bytes] = field(default_factory=dict)
    design: DesignSpec | None = None
    synthesis: SynthesisResult | None = None
    motion: Motion | None = None
    partset: PartSet | None = None
    gear_pairs: list[GearPair] = field(default_factory=list)
    checks: CheckReport | None = None

    @property
    def passed(self) -> bool:
        """Whether no check that ran failed (the CLI's exit code 0). A check that could not run (strength
        without materials or a load) is not a failure: :attr:`not_checked` names it."""
        return self.exit_code == 0

    @property
    def not_checked(self) -> list[str]:
        """The checks that could not run, each with why (``"strength not checked: no [load] in the
        template"``); empty when everything was checked."""
        return not_checked_notes(self.report)

    @property
    def failures(self) -> list[str]:
        """Why the design fails, one line per failure (empty when it passes)."""
        return list(self.report.get("checks", {}).get("failures", []))

    def mujoco_model(self) -> Any:
        """The build's ``mechanism.xml`` loaded in MuJoCo (a ``mujoco.MjModel``, meshes from :attr:`files`);
        needs the ``sim`` extra. See :func:`fabricate.export.mjcf.load_model`."""
        from fabricate.export.mjcf import load_model

        return load_model(self.files)

    def write(self, out: str | Path, *, force: bool = False) -> Path:
        """Write the files to folder ``out`` atomically, with the CLI's rules: ``out`` must be new, empty or
        a previous fabricate output; ``force`` replaces another folder (never a file, a link or the
        current folder). Returns the folder written."""
        from fabricate.output import check_output_dir, write_output

        out = path_argument(out, "out", "an output folder")
        if not isinstance(force, bool):
            raise SpecError("force", f"expected True or False, got {type_name(force)}")
        stage = "synth" if self.report.get("design", {}).get("stage") == "synth" else "build"
        protect = [Path(self.design.template)] if self.design is not None else []
        check_output_dir(out, force=force, stage=stage, protect=protect)
        return write_output(self.files, out, force=force, stage=stage, protect=protect)


def _quiet(_: str) -> None:
    pass


def synthesise(design: DesignSpec, progress: Progress = _quiet) -> SynthesisResult:
    progress(f"synthesis ({design.kind})")
    return KINDS[design.kind].synthesise(design)


def _synthesis_stage(design: DesignSpec, progress: Progress, stage: str
                     ) -> tuple[SynthesisResult, dict[str, Any], Motion | None, list[str]]:
    """Synthesis and the swept motion; a lock-up inside the range is a design failure, not an error."""
    result, motion, lockup = cache.cached("synthesis", stage_keys.synthesis_key(design),
                                          lambda: _synthesis_and_motion(design, progress))
    # the schema version first: a reader learns which contract the rest follows before reading it
    report: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "design": design_section(design, stage)}
    if motion is None:
        report["synthesis"] = result.report
        return result, report, None, [f"motion: {lockup}"]
    report["mechanism"] = mechanism_section(result.mechanism, motion)
    report["synthesis"] = result.report
    return result, report, motion, []


def _synthesis_and_motion(design: DesignSpec, progress: Progress
                          ) -> tuple[SynthesisResult, Motion | None, str | None]:
    """Synthesis and its sweep, or the lock-up that stops the sweep: one entry of :mod:`fabricate.cache`."""
    result = stage_keys.storable_synthesis(synthesise(design, progress), design)
    progress("sweep")
    try:
        return result, result.mechanism.sweep(design.checks.sweep_poses), None
    except LockupError as exc:
        return result, None, str(exc)


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


@blas_threads()  # one BLAS thread: fabricate's systems are small, and threads only wait on busy cores
@rare_collections()
def run_synth(design: DesignSpec, progress: Progress = _quiet) -> BuildOutcome:
    """Synthesis only: report.json with design, mechanism and synthesis, plus the method's plots."""
    result, report, motion, failures = _synthesis_stage(design, progress, "synth")
    progress("plots")
    files = synthesis_plots(result)
    # no check runs here: the report says so, so nothing reads as "checks passed"
    report["checks"] = {"passed": not failures, "failures": failures,
                        "not_checked": [{"check": name, "reason": SYNTH_ONLY}
                                        for name in ("interference", "gear mesh", "printability", "strength",
                                                     "drive")]}
    return _finish(design, report, files, exit_code=1 if failures else 0, synthesis=result, motion=motion)


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
    def mechanism(self) -> Mechanism:
        return self.synthesis.mechanism

    def enter(self, stage: str) -> None:
        """Start ``stage``: it names any failure from here on, and the progress line shows it."""
        self.stage = stage
        self.progress(stage)


def _kernel_failures() -> tuple[type[BaseException], ...]:
    """Exceptions of the numeric and geometry kernels that a design can provoke (not bugs of ours)."""
    import numpy as np
    import shapely.errors

    from fabricate.errors import GeometryError

    return (GeometryError, np.linalg.LinAlgError, shapely.errors.ShapelyError,  # GEOSException is one
            FloatingPointError, OverflowError, ZeroDivisionError, ValueError)


@blas_threads()  # one BLAS thread (fabricate.bounds.blas_threads: a whole build with two took 3x the CPU)
@rare_collections()  # fewer garbage collections (fabricate.bounds.rare_collections: 0.29 -> 0.08 s CPU)
def run_build(design: DesignSpec, progress: Progress = _quiet, *,
              optional: OptionalOutputs | None = None, report_only: bool = False) -> BuildOutcome:
    """The whole pipeline in memory.

    ``optional`` fixes the optional outputs (STEP) instead of making what this install can make.
    ``report_only`` leaves out the files no report key is computed from: the pictures (synthesis and gear plots,
    previews, the assembly guide's), the STEP files and the strength, drive and clearance plots. Every section of
    its report is the full build's but ``files`` and ``manifest`` (the files it made) and ``outputs`` (STEP
    "skipped"): for a sweep point, which keeps its report's numbers only.

    A geometry or numeric kernel failing after synthesis (GEOS, manifold, a singular matrix) is a design
    failure named in the report with the stage it happened in (exit code 1), never a bare exception.

    Raises
    ------
    SpecError, SynthesisError
        Invalid input or nothing feasible (the CLI exits 2 and writes nothing).
    """
    if not report_only and (optional is None or (optional.step and optional.step_files is None)) and \
            not cache.stored("step", stage_keys.pictures_key(design, "step")):  # a stored STEP result needs no OCP
        from fabricate.export import prestart_step

        prestart_step()  # OCP imports in the STEP worker on the second core while synthesis runs
    result, report, motion, failures = _synthesis_stage(design, progress, "build")
    if motion is None:
        report["checks"] = {"passed": False, "failures": failures}
        return _finish(design, report, {}, exit_code=1, synthesis=result)
    run = BuildRun(design, result, motion, report, progress, optional, report_only)
    try:
        return _build_stages(run)
    except (SpecError, SynthesisError):
        raise
    except _kernel_failures() as exc:
        if isinstance(exc, FabricateError):
            text = str(exc)
        else:
            text = f"{type(exc).__name__}: {exc}".strip().rstrip(":")
        failure = f"{run.stage}: this design cannot be made ({text})"
        report["checks"] = {"passed": False, "failures": [failure]}
        return _finish(design, report, {}, exit_code=1, synthesis=result, motion=motion)


def _build_stages(run: BuildRun) -> BuildOutcome:
    """Gears, parts, then exports and checks while a forked child draws the pictures (and exports STEP)."""
    _make_gears(run)
    if run.design.parts.link_width_mm == "auto":
        _size_links(run)
    _make_parts(run)
    if not run.report_only and not cache.stored("previews", stage_keys.pictures_key(run.design, "previews")):
        # the child and this process both draw: matplotlib imported once, here, is the child's too
        from fabricate.plotting import load_agg

        load_agg()
    # pictures take as long as everything else: draw them in a forked child on the second core
    pictures = None if run.report_only else Background(_picture_jobs(run))
    try:
        # inside the try: this may import OCP (slow), and a stop signal landing here must cancel the child
        with_step = _record_optional_outputs(run)
        _export(run, with_step)
        _check(run)
        _check_strength(run)
        _check_drive(run)
        _verdict(run)
        if pictures is not None:
            _plots(run, pictures)
    finally:
        if pictures is not None:
            pictures.cancel()
    assert run.given is not None  # set in __post_init__
    return _finish(run.given, run.report, run.files, exit_code=0 if not run.failures else 1,
                   synthesis=run.synthesis, motion=run.motion, partset=run.partset, gear_pairs=run.gear_pairs,
                   checks=run.checks)


def _make_gears(run: BuildRun) -> None:
    """One cut, checked gear pair per gear coupling: report.json's ``gears``."""
    from fabricate.gears import build_gear_pairs
    from fabricate.gears.auto import module_limits

    run.enter("gears")
    # gears.module_mm = "auto": the smallest standard module the process makes and the load allows
    run.gear_pairs = cache.cached("gears", stage_keys.gears_key(run.design), lambda: build_gear_pairs(
        run.mechanism, run.design.gears, run.design.process.chord_tolerance_mm,
        lambda: module_limits(run.design, run.mechanism, run.motion, run.synthesis.parts)))
    run.report["gears"] = [pair.report() for pair in run.gear_pairs]


def _size_links(run: BuildRun) -> None:
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


def _make_parts(run: BuildRun) -> None:
    """Every body as parts (plates, gears fused on), pins, spacers and the bill of materials."""
    from fabricate.parts.build import build_parts

    run.enter("parts")
    run.partset = cache.cached("parts", stage_keys.parts_key(run.design), lambda: build_parts(
        run.design, run.mechanism, run.motion, run.gear_pairs, run.synthesis.parts))


def _picture_jobs(run: BuildRun) -> list[Callable[[], dict[str, bytes]]]:
    """The slow outputs, for the forked child: the method's plots, gear pictures, previews, STEP files."""
    from fabricate.export import export_previews, export_step

    assert run.partset is not None  # the parts stage ran
    result, gear_pairs, design, partset, motion = run.synthesis, run.gear_pairs, run.design, run.partset, run.motion
    optional = run.optional

    def step_files() -> dict[str, bytes]:
        return cache.cached("step", stage_keys.pictures_key(design, "step"),
                            lambda: export_step(design, partset, motion))

    def step_job() -> dict[str, bytes]:
        if optional is None:
            return step_files()
        if not optional.step:
            return {}
        return dict(optional.step_files) if optional.step_files is not None else step_files()

    from fabricate.export.guide import guide_picture_files

    # each job's result is a cache entry (fabricate.cache; the synthesis plots are the result's own figures')
    # the STEP job mostly waits on its own process (export_step): in a thread, the pictures are drawn meanwhile
    return [lambda: synthesis_plots(result),
            lambda: cache.cached("gear_pictures", stage_keys.pictures_key(design, "gear_pictures"),
                                 lambda: gear_pictures(gear_pairs)),
            lambda: cache.cached("previews", stage_keys.pictures_key(design, "previews"),
                                 lambda: export_previews(design, partset, motion)), in_thread(step_job),
            lambda: cache.cached("guide_pictures", stage_keys.pictures_key(design, "guide_pictures"),
                                 lambda: guide_picture_files(partset, motion))]


def _record_optional_outputs(run: BuildRun) -> bool:
    """Whether STEP files are made, recorded in report.json (``notes``, ``outputs``); returned."""
    from fabricate.export import STEP_SKIPPED
    from fabricate.export.step import step_available

    with_step = step_available() if run.optional is None else run.optional.step
    run.report["notes"] = [] if with_step else [STEP_SKIPPED]
    # optional outputs as written or skipped: `check` rebuilds with the same set, so its verdict does not
    # depend on the checker's install (fabricate/verify.py)
    run.report["outputs"] = {"step": "written" if with_step and not run.report_only else
                             "skipped: a report-only build (a sweep point)" if with_step else
                             "skipped: OCP is not installed (extra 'cad')"}
    return with_step  # the exports name the STEP files a full build writes: a report-only one's parts are the same


def _export(run: BuildRun, with_step: bool) -> None:
    """Part files, drawings, plates or sheets, the BOM and assembly, motion.csv and mechanism.toml."""
    from fabricate.export import assembly_csv, export_all, motion_csv
    from fabricate.export.guide import guide_markdown, guide_steps
    from fabricate.parts.assembly import assembly_steps, guide_report, pin_stacks, stacks_report
    from fabricate.parts.hardware_report import hardware_report
    from fabricate.parts.spring_rows import springs_report
    from fabricate.synthesis.linkage.exact import mechanism_toml

    run.enter("exports")
    assert run.partset is not None  # the parts stage ran
    partset = run.partset

    def make() -> tuple[dict[str, bytes], list[dict[str, Any]], Any]:
        sections: dict[str, Any] = {}  # a cut process adds its "cut" section: part of the cached result
        files, parts = export_all(run.design, partset, run.mechanism, run.motion, previews=False, step=False,
                                  with_step=with_step, sections=sections)
        return files, parts, sections.get("cut")

    exported, parts_report, cut = cache.cached("exports", stage_keys.exports_key(run.design, with_step), make)
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
    run.files["assembly.md"] = guide_markdown(guide, run.design.name, run.partset.copies).encode("utf-8")
    run.files["assembly.csv"] = assembly_csv(stacks)
    run.files["motion.csv"] = motion_csv(run.mechanism, run.motion)
    run.files["mechanism.toml"] = mechanism_toml(run.design, run.mechanism, run.synthesis.parts)
    # the MuJoCo model: its meshes are the part STL files just exported (fabricate/export/mjcf.py)
    from fabricate.export.mjcf import mechanism_mjcf, simulation_section

    stl = {part.name: run.files[f"parts/{part.name}.stl"] for part in run.partset.parts}
    run.files["mechanism.xml"] = mechanism_mjcf(run.design, run.partset, run.mechanism, run.motion, run.gear_pairs,
                                                stl)
    run.report["simulation"] = simulation_section(run.design, run.partset, run.mechanism, run.motion)


def _check(run: BuildRun) -> None:
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


def _check_strength(run: BuildRun) -> None:
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


def _check_drive(run: BuildRun) -> None:
    """The actuator against the input effort the statics compute at every pose: report.json's ``drive``."""
    from fabricate.drive.check import rate_mount, run_drive

    run.enter("drive")
    assert run.partset is not None  # the parts stage ran
    run.drive = run_drive(run.design, run.mechanism, run.motion, run.synthesis.parts, run.strength,
                          copies=run.partset.copies)
    rate_mount(run.drive, run.partset, run.design)  # the mount plate's holes against the reaction torque
    run.report["drive"] = run.drive.report()
    run.failures += run.drive.failures()


def _verdict(run: BuildRun) -> None:
    """report.json's ``checks``: passed is over the checks that ran; those that could not run are listed,
    never passed."""
    assert run.checks is not None and run.strength is not None  # both checks ran
    not_checked = [dict(entry) for entry in run.checks.not_checked]
    if run.strength.reason is not None:
        not_checked.append({"check": "strength", "reason": run.strength.reason})
    if run.drive is not None and run.drive.reason is not None:
        not_checked.append({"check": "drive", "reason": run.drive.reason})
    run.report["checks"] = {"passed": not run.failures, "failures": run.failures, "not_checked": not_checked}


def _plots(run: BuildRun, pictures: Background) -> None:
    """The strength and clearance plots, then the pictures the child drew."""
    from fabricate.strength.plots import strength_plot

    run.enter("plots")
    assert run.checks is not None and run.strength is not None  # both checks ran
    strength, drive, checks, unit = run.strength, run.drive, run.checks, run.mechanism.input_unit
    # {path: (cache stage, its key, drawer)}, looked up in the cache here so its counts are this process's
    plots: dict[str, tuple[str, Any, Callable[[], bytes]]] = {}
    if strength.findings:
        plots["plots/strength.png"] = ("strength_plot", stage_keys.strength_key(run.design),
                                       lambda: strength_plot(strength, unit))
    if drive is not None and drive.reason is None:
        from fabricate.drive.plots import drive_plot

        plots["plots/drive.png"] = ("drive_plot", stage_keys.drive_key(run.design), lambda: drive_plot(drive))
    todo = [path for path, (stage, key, _) in plots.items() if not cache.stored(stage, key)]
    # the picture child is done by now, or nearly: a second child draws these while this process draws the
    # clearance plot, or, where that is cached (a rebuild after a [load] or [checks] edit), the first of them
    mine = todo[:1] if cache.stored("check_figures", stage_keys.checks_key(run.design)) else []
    theirs = todo[len(mine):]

    def drawing(path: str) -> Callable[[], dict[str, bytes]]:
        return lambda: {path: plots[path][2]()}

    def taking(path: str, draw: Callable[[], bytes]) -> Callable[[], bytes]:
        return lambda: drawn[path] if path in drawn else draw()

    if theirs:
        from fabricate.plotting import load_agg

        load_agg()  # matplotlib imported once, before the fork, for the child and this process
    child = Background([drawing(path) for path in theirs]) if theirs else None
    drawn: dict[str, bytes] = {}
    try:
        figures = cache.cached("check_figures", stage_keys.checks_key(run.design), checks.figures)
        drawn.update({path: plots[path][2]() for path in mine})
        drawn.update(child.result() if child is not None else {})
    finally:
        if child is not None:
            child.cancel()
    for path, (stage, key, draw) in plots.items():
        run.files[path] = cache.cached(stage, key, taking(path, draw))
    for name, data in sorted(figures.items()):
        run.files[f"plots/{name}"] = data
    run.files.update(pictures.result())


def synthesis_plots(result: SynthesisResult) -> dict[str, bytes]:
    """The synthesis method's figures, under ``plots/`` (the same paths for ``synth`` and ``build``)."""
    return {f"plots/{name}": data for name, data in sorted(result.figures().items())}


def gear_pictures(gear_pairs: list[GearPair]) -> dict[str, bytes]:
    """Each gear pair in mesh (PNG, mid-range) and turning (GIF)."""
    if not gear_pairs:
        return {}
    from fabricate.export.gear_plots import pair_gif, pair_png

    files = {}
    for pair in gear_pairs:
        x_mid = 0.5 * (pair.working_range[0] + pair.working_range[1])
        files[f"gears/{pair.name}_mesh.png"] = pair_png(pair, x_mid)
        files[f"gears/{pair.name}_turning.gif"] = pair_gif(pair, 36)
    return files


def manifest(files: dict[str, bytes]) -> list[dict[str, Any]]:
    """Every file's path, size in bytes and sha256, sorted by path."""
    return [{"path": rel, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}
            for rel, data in sorted(files.items())]


def _finish(design: DesignSpec, report: dict[str, Any], files: dict[str, bytes], **kw: Any) -> BuildOutcome:
    """Add report.md, then report.json with the file list, the manifest of every other file and the
    template text (every path relative to the output directory)."""
    images = [p for p in sorted(files) if p.endswith((".png", ".gif"))]
    report["files"] = sorted(set(files) | {"report.json", "report.md"})
    files["report.md"] = report_markdown(report, images).encode("utf-8")
    report["manifest"] = manifest(files)
    report["template_text"] = design.template_text
    files["report.json"] = report_json(report)
    return BuildOutcome(report=report, files=files, design=design, **kw)
