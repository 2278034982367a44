"""The whole pipeline: template → spec → synthesis → mechanism → gears → parts → exports and checks.

Everything is computed in memory into ``{relative path: bytes}``; only :mod:`fabricate.output` touches
the file system, into a temporary sibling directory swapped into place when every file is written, so a
failed run never leaves half a result. report.json carries a manifest of every other file (size, sha256)
and the template text itself, so ``fabricate check DIR`` can verify the files and rebuild them.
"""

from __future__ import annotations

import hashlib
import pickle
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fabricate import cache, stage_keys
from fabricate.arguments import path_argument, type_name
from fabricate.background import Background, Handoff, can_fork, in_thread, preceded
from fabricate.bounds import blas_threads, rare_collections
from fabricate.build_stages import BuildRun, Progress, _quiet, export_files
from fabricate.build_stages import OptionalOutputs as OptionalOutputs  # run_build's argument: public here
from fabricate.build_stages import check as _check
from fabricate.build_stages import check_drive as _check_drive
from fabricate.build_stages import check_strength as _check_strength
from fabricate.build_stages import export as _export
from fabricate.build_stages import make_gears as _make_gears
from fabricate.build_stages import make_parts as _make_parts
from fabricate.build_stages import record_optional_outputs as _record_optional_outputs
from fabricate.build_stages import size_links as _size_links
from fabricate.build_stages import verdict as _verdict
from fabricate.errors import FabricateError, LockupError, SpecError, SynthesisError
from fabricate.kinds import KINDS
from fabricate.mechanism import Motion
from fabricate.report import SYNTH_ONLY, not_checked_notes, report_json, report_markdown
from fabricate.report_schema import SCHEMA_VERSION
from fabricate.report_sections import design_section, mechanism_section
from fabricate.spec import DesignSpec
from fabricate.synthesis.base import SynthesisResult

if TYPE_CHECKING:
    from fabricate.checks import CheckReport
    from fabricate.gears.pair import GearPair
    from fabricate.parts.partset import PartSet


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
              optional: OptionalOutputs | None = None, report_only: bool = False, pictures: bool = True
              ) -> BuildOutcome:
    """The whole pipeline in memory.

    ``optional`` fixes the optional outputs (STEP) instead of making what this install can make.
    ``report_only`` leaves out the files no report key is computed from: the pictures (synthesis and gear plots,
    previews, the assembly guide's), the STEP files and the strength, drive and clearance plots. Every section of
    its report is the full build's but ``files`` and ``manifest`` (the files it made) and ``outputs`` (STEP
    "skipped"): for a sweep point, which keeps its report's numbers only. ``pictures=False`` leaves out the
    pictures and plots only (``fabricate build --no-pictures``, for a quicker edit loop): every other file is the
    full build's, but report.json/report.md (``outputs.pictures``, a note, the file list) and assembly.md (no
    step pictures).

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
    run = BuildRun(design, result, motion, report, progress, optional, report_only, pictures=pictures)
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
    """Gears, parts, exports and checks, while forked children draw the pictures on the second core.

    This process runs the stages one after another; the second core takes each picture job as soon as what it
    draws exists (the method's figures after synthesis, the gear pictures after the gears) and, after the parts,
    one child makes the exports, then the previews and STEP files while this process runs the checks and draws
    their plots and the guide's pictures (the two halves take about as long: bench_build's per-stage table).
    That child is forked after synthesis and imports the exporters (ezdxf, trimesh: ~0.3 s) while the gears and
    parts are made, then waits for the part set (:class:`~fabricate.background.Handoff`).
    report.json's sections keep the order of a serial build.
    """
    jobs = _picture_jobs(run)
    children: list[Background | None] = []
    exports: Background | None = None
    handoff: Handoff | None = None
    # without pictures (--no-pictures), the exports' child makes the exports and the STEP files only
    part_jobs = jobs[2:4] if run.draws else jobs[3:4]
    try:
        children.append(_start(run, jobs[:1], "synthesis_plots", stage_keys.synthesis_key(run.design)))
        exports, handoff = _fork_exports(run, part_jobs)
        _make_gears(run)
        children.append(_start(run, jobs[1:2], "gear_pictures", stage_keys.pictures_key(run.design, "gear_pictures"),
                               bool(run.gear_pairs)))
        if run.design.parts.link_width_mm == "auto":
            _size_links(run)
        _make_parts(run)
        # inside the try: this may import OCP (slow), and a stop signal landing here must cancel the children
        with_step = _record_optional_outputs(run)
        exports, exporting = _start_exports(run, with_step, part_jobs, exports, handoff)
        before_checks = set(run.report)
        try:
            _check(run)
            _check_strength(run)
            _check_drive(run)
            _verdict(run)
            if run.draws:
                _plots(run)
                run.files.update(jobs[4]())  # the guide's pictures
        except Exception:
            if exporting:  # a serial build made the exports first: their failure wins, their sections come first
                stage = run.stage
                _collect_exports(run, with_step, exports, exporting, before_checks)
                run.stage = stage
            raise
        pictures = _collect_exports(run, with_step, exports, exporting, before_checks)
        run.stage = "plots"
        for child in children:
            run.files.update(child.result() if child is not None else {})
        run.files.update(pictures)
    finally:
        for child in [*children, exports]:
            if child is not None:
                child.cancel()
        if handoff is not None:
            handoff.close()
    assert run.given is not None  # set in __post_init__
    return _finish(run.given, run.report, run.files, exit_code=0 if not run.failures else 1,
                   synthesis=run.synthesis, motion=run.motion, partset=run.partset, gear_pairs=run.gear_pairs,
                   checks=run.checks)


def _start(run: BuildRun, jobs: list[Callable[[], dict[str, bytes]]], stage: str, key: Any,
           draws: bool = True, hand_over: bool = False) -> Background | None:
    """``jobs`` forked now, or (their result stored, or nothing to draw) run when their result is asked for;
    None in a report-only build (no pictures), and for a picture job of a build without pictures. ``hand_over``:
    the child makes the STEP files (Background)."""
    if run.report_only or not (run.pictures or hand_over):
        return None
    if draws and not cache.stored(stage, key):
        return _fork(run, jobs, hand_over)
    return Background(jobs, fork=False, hand_over=hand_over)


def _fork(run: BuildRun, jobs: list[Callable[[], dict[str, bytes]]], hand_over: bool) -> Background:
    """``jobs`` in a child forked now (:class:`Background`), matplotlib imported first where this build draws:
    once, for the child's pictures and this process's plots (without pictures, an exports child imports what its
    labels need itself)."""
    if run.pictures and can_fork():
        from fabricate.plotting import load_agg

        load_agg()
    return Background(jobs, hand_over=hand_over)


def _picture_jobs(run: BuildRun) -> list[Callable[[], dict[str, bytes]]]:
    """The slow outputs, for the forked children: the method's plots, gear pictures, previews, STEP files and the
    guide's pictures. Each reads ``run`` when it runs (a child reads it as it was at the fork): the synthesis
    plots need the synthesis, the gear pictures the gear pairs, the others the part set."""
    from fabricate.export import export_previews, export_step
    from fabricate.export.guide import guide_picture_files

    def partset() -> PartSet:
        assert run.partset is not None  # the parts stage ran before this job's child was forked
        return run.partset

    def step_files() -> dict[str, bytes]:
        return cache.cached("step", stage_keys.pictures_key(run.design, "step"),
                            lambda: export_step(run.design, partset(), run.motion))

    def step_job() -> dict[str, bytes]:
        if run.optional is None:
            return step_files()
        if not run.optional.step:
            return {}
        return dict(run.optional.step_files) if run.optional.step_files is not None else step_files()

    # each job's result is a cache entry (fabricate.cache; the synthesis plots are the result's own figures')
    # the STEP job mostly waits on its own process (export_step): in a thread, the pictures are drawn meanwhile
    return [lambda: synthesis_plots(run.synthesis),
            lambda: cache.cached("gear_pictures", stage_keys.pictures_key(run.design, "gear_pictures"),
                                 lambda: gear_pictures(run.gear_pairs)),
            lambda: cache.cached("previews", stage_keys.pictures_key(run.design, "previews"),
                                 lambda: export_previews(run.design, partset(), run.motion)), in_thread(step_job),
            lambda: cache.cached("guide_pictures", stage_keys.pictures_key(run.design, "guide_pictures"),
                                 lambda: guide_picture_files(partset(), run.motion))]


#: The export child's answer under this name (never a file's path): :func:`export_files`' result, pickled.
_EXPORTED = "\0exports"


def _warm_exports() -> None:
    """Import the exporters and their libraries (ezdxf, trimesh): the exports' child does, while the parts are made."""
    import fabricate.export.dxf
    import fabricate.export.kinematic
    import fabricate.export.labels
    import fabricate.export.stl
    import fabricate.export.svg
    import fabricate.parts.solids  # noqa: F401 - imported for the exports that follow


def _fork_exports(run: BuildRun, pictures: list[Callable[[], dict[str, bytes]]],
                  steps: tuple[bool, ...] = (False, True)) -> tuple[Background | None, Handoff | None]:
    """The exports' child, forked now (after synthesis): it imports the exporters while this process makes the
    gears and parts, then waits for the part set (:func:`_start_exports` sends it) to make the exports and
    ``pictures`` (the previews, the STEP files). None where this process does not fork, in a report-only build,
    or where the cache holds the exports of the design as it is with STEP files or without (``steps``: a rebuild
    after a ``[load]`` edit, whose child forked after the parts draws the pictures only)."""
    if run.report_only or not can_fork() or any(
            cache.stored("exports", stage_keys.exports_key(run.design, step)) for step in steps):
        return None, None
    handoff = Handoff()

    def received() -> tuple[bool, bool]:
        """``(with_step, exporting)``; the design (link sizing may change it) and part set as made here."""
        run.design, run.partset, with_step, exporting = handoff.get()
        return with_step, exporting

    def exports_job() -> dict[str, bytes]:
        _warm_exports()
        with_step, exporting = received()
        if not exporting:  # the cache holds them after all
            return {}
        return {_EXPORTED: pickle.dumps(export_files(run, with_step), protocol=pickle.HIGHEST_PROTOCOL)}

    return _fork(run, [exports_job, *[preceded(received, job) for job in pictures]], hand_over=True), handoff


def _start_exports(run: BuildRun, with_step: bool, pictures: list[Callable[[], dict[str, bytes]]],
                   child: Background | None, handoff: Handoff | None) -> tuple[Background | None, bool]:
    """The part set sent to the exports' ``child`` (:func:`_fork_exports`; forked now where there was none and the
    exports of the design as link sizing left it are not stored), which makes the exports, then the part set's
    pictures (previews, STEP): ``(child, True)``; or the exports made here now (their result stored, no fork here,
    a report-only build) and a child for the pictures: ``(child, False)``, no child in a report-only build."""
    stored = cache.stored("exports", stage_keys.exports_key(run.design, with_step))
    if handoff is None and not stored:
        child, handoff = _fork_exports(run, pictures, (with_step,))
    if handoff is None:
        _export(run, with_step)
        return _start(run, pictures, "previews", stage_keys.pictures_key(run.design, "previews"), hand_over=True), False
    handoff.send((run.design, run.partset, with_step, not stored))
    if stored:
        _export(run, with_step)
    else:
        run.enter("exports")
    return child, not stored


def _collect_exports(run: BuildRun, with_step: bool, child: Background | None, exporting: bool,
                     before_checks: set[str]) -> dict[str, bytes]:
    """The pictures ``child`` drew; where it made the exports too, those are stored and reported here, their
    report sections before the checks' (where a serial build has them)."""
    if child is None:
        return {}
    if not exporting:
        return child.result()
    run.stage = "exports"  # a failure from here on is the exports' (the child failed: its jobs run here)
    checks = [key for key in run.report if key not in before_checks]
    try:
        files = child.result()
        made = files.pop(_EXPORTED)
        _export(run, with_step, made=lambda: pickle.loads(made))
    except BaseException:
        for key in checks:  # a serial build fails before the checks: its report has none of theirs
            run.report.pop(key, None)
        raise
    for key in checks:
        run.report[key] = run.report.pop(key)
    return files


def _plots(run: BuildRun) -> None:
    """The strength, drive and clearance plots."""
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
    mine = todo[:1] if cache.stored("check_figures", stage_keys.clearance_key(run.design)) else []
    theirs = todo[len(mine):]

    def drawing(path: str) -> Callable[[], dict[str, bytes]]:
        return lambda: {path: plots[path][2]()}

    def taking(path: str, draw: Callable[[], bytes]) -> Callable[[], bytes]:
        return lambda: drawn[path] if path in drawn else draw()

    # hand_over=False: a prestarted STEP worker waiting here (the exports stored) is for the pictures job, not these
    child = _fork(run, [drawing(path) for path in theirs], hand_over=False) if theirs else None
    drawn: dict[str, bytes] = {}
    try:
        figures = cache.cached("check_figures", stage_keys.clearance_key(run.design), checks.figures)
        drawn.update({path: plots[path][2]() for path in mine})
        drawn.update(child.result() if child is not None else {})
    finally:
        if child is not None:
            child.cancel()
    for path, (stage, key, draw) in plots.items():
        run.files[path] = cache.cached(stage, key, taking(path, draw))
    for name, data in sorted(figures.items()):
        run.files[f"plots/{name}"] = data


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
