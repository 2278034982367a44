"""The whole pipeline: template → spec → synthesis → mechanism → gears → parts → exports and checks.

Everything is computed in memory into ``{relative path: bytes}``; only :mod:`fabricate.output` touches
the file system, into a temporary sibling directory swapped into place when every file is written, so a
failed run never leaves half a result. report.json carries a manifest of every other file (size, sha256)
and the template text itself, so ``fabricate check DIR`` can verify the files and rebuild them.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import multiprocessing
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fabricate import __version__
from fabricate.bounds import blas_threads
from fabricate.errors import FabricateError, LockupError, SpecError, SynthesisError
from fabricate.mechanism import Mechanism, Motion
from fabricate.report import SYNTH_ONLY, report_json, report_markdown
from fabricate.spec import DesignSpec
from fabricate.synthesis import KINDS
from fabricate.synthesis.base import SynthesisResult

Progress = Callable[[str], None]


@dataclass
class BuildOutcome:
    """What a pipeline run produced.

    Attributes
    ----------
    exit_code : int
        0 all checks pass, 1 the design fails a check (files are still produced).
    report : dict
        The report.json content.
    files : dict
        ``{relative path: bytes}`` including report.json and report.md.
    """

    exit_code: int
    report: dict[str, Any]
    files: dict[str, bytes] = field(default_factory=dict)
    synthesis: SynthesisResult | None = None
    motion: Motion | None = None
    partset: Any = None
    gear_pairs: list[Any] = field(default_factory=list)
    checks: Any = None


def _quiet(_: str) -> None:
    pass


def design_section(design: DesignSpec, stage: str) -> dict[str, Any]:
    # the template's file name only: a folder in the report would make its bytes depend on where the
    # build ran (the template itself is embedded as template_text)
    section = {"name": design.name, "kind": design.kind, "template": Path(design.template).name,
               "fabricate_version": __version__, "description": design.description,
               "process": design.process.name, "stage": stage}
    if design.process_override is not None:  # --process: check rebuilds with the same profile
        section["process_override"] = {"source": design.process_override.source,
                                       "text": design.process_override.text}
    return section


def mechanism_section(mechanism: Mechanism, motion: Motion) -> dict[str, Any]:
    """DESIGN.md ``mechanism`` keys: every named point at the first pose, bodies with their points."""
    joints = {}
    for body in mechanism.bodies:
        for name in body.points:
            if name not in joints:
                joints[name] = motion.point(name, body.name)[0]
    return {
        "joints": {k: [float(v[0]), float(v[1])] for k, v in joints.items()},
        "bodies": {b.name: list(b.points) for b in mechanism.bodies},
        "input_range_deg": [float(mechanism.input_range[0]), float(mechanism.input_range[1])],
        "input_unit": mechanism.input_unit,
        "ground": mechanism.ground,
        "degrees_of_freedom": mechanism.degrees_of_freedom(),
        "drivers": len(mechanism.drivers),
    }


def synthesise(design: DesignSpec, progress: Progress = _quiet) -> SynthesisResult:
    progress(f"synthesis ({design.kind})")
    return KINDS[design.kind].synthesise(design)


def _synthesis_stage(design: DesignSpec, progress: Progress, stage: str
                     ) -> tuple[SynthesisResult, dict[str, Any], Motion | None, list[str]]:
    """Synthesis and the swept motion; a lock-up inside the range is a design failure, not an error."""
    result = synthesise(design, progress)
    report: dict[str, Any] = {"design": design_section(design, stage)}
    progress("sweep")
    try:
        motion = result.mechanism.sweep(design.checks.sweep_poses)
    except LockupError as exc:
        report["synthesis"] = result.report
        return result, report, None, [f"motion: {exc}"]
    report["mechanism"] = mechanism_section(result.mechanism, motion)
    report["synthesis"] = result.report
    return result, report, motion, []


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
def run_synth(design: DesignSpec, progress: Progress = _quiet) -> BuildOutcome:
    """Synthesis only: report.json with design, mechanism and synthesis, plus the method's plots."""
    result, report, motion, failures = _synthesis_stage(design, progress, "synth")
    progress("plots")
    files = synthesis_plots(result)
    # no check runs here: the report says so, so nothing reads as "checks passed"
    report["checks"] = {"passed": not failures, "failures": failures,
                        "not_checked": [{"check": name, "reason": SYNTH_ONLY}
                                        for name in ("interference", "gear mesh", "printability", "strength")]}
    return _finish(design, report, files, exit_code=1 if failures else 0, synthesis=result, motion=motion)


def _kernel_failures() -> tuple[type[BaseException], ...]:
    """Exceptions of the numeric and geometry kernels that a design can provoke (not bugs of ours)."""
    import numpy as np
    import shapely.errors

    from fabricate.errors import GeometryError

    return (GeometryError, np.linalg.LinAlgError, shapely.errors.ShapelyError,  # GEOSException is one
            FloatingPointError, OverflowError, ZeroDivisionError, ValueError)


@blas_threads()  # one BLAS thread (fabricate.bounds.blas_threads: a whole build with two took 3x the CPU)
def run_build(design: DesignSpec, progress: Progress = _quiet, *,
              optional: OptionalOutputs | None = None) -> BuildOutcome:
    """The whole pipeline in memory.

    ``optional`` fixes the optional outputs (STEP) instead of making what this install can make.

    A geometry or numeric kernel failing after synthesis (GEOS, manifold, a singular matrix) is a design
    failure named in the report with the stage it happened in (exit code 1), never a bare exception.

    Raises
    ------
    SpecError, SynthesisError
        Invalid input or nothing feasible (the CLI exits 2 and writes nothing).
    """
    result, report, motion, failures = _synthesis_stage(design, progress, "build")
    if motion is None:
        report["checks"] = {"passed": False, "failures": failures}
        return _finish(design, report, {}, exit_code=1, synthesis=result)
    stage = ["gears"]
    try:
        return _build_stages(design, result, report, motion, progress, stage, optional)
    except (SpecError, SynthesisError):
        raise
    except _kernel_failures() as exc:
        if isinstance(exc, FabricateError):
            text = str(exc)
        else:
            text = f"{type(exc).__name__}: {exc}".strip().rstrip(":")
        failure = f"{stage[0]}: this design cannot be made ({text})"
        report["checks"] = {"passed": False, "failures": [failure]}
        return _finish(design, report, {}, exit_code=1, synthesis=result, motion=motion)


def _build_stages(design: DesignSpec, result: SynthesisResult, report: dict[str, Any], motion: Motion,
                  progress: Progress, stage: list[str], optional: OptionalOutputs | None = None) -> BuildOutcome:
    """Gears, parts, exports, checks and pictures; ``stage[0]`` names the stage running (for failures)."""
    from fabricate.checks import run_checks
    from fabricate.export import STEP_SKIPPED, assembly_csv, export_all, export_previews, export_step, motion_csv
    from fabricate.export.step import step_available
    from fabricate.gears import build_gear_pairs
    from fabricate.parts.assembly import assembly_steps, pin_stacks, stacks_report
    from fabricate.parts.build import build_parts
    from fabricate.strength.check import run_strength
    from fabricate.strength.plots import strength_plot
    from fabricate.synthesis.linkage.exact import mechanism_toml

    def enter(name: str) -> None:
        stage[0] = name
        progress(name)

    files: dict[str, bytes] = {}
    mechanism = result.mechanism
    enter("gears")
    gear_pairs = build_gear_pairs(mechanism, design.gears, design.process.chord_tolerance_mm)
    report["gears"] = [pair.report() for pair in gear_pairs]
    sizing = None
    if design.parts.link_width_mm == "auto":
        enter("sizing")
        from fabricate.strength.sizing import size_link_width

        width, tried = size_link_width(design, mechanism, motion, gear_pairs, result.parts,
                                       lambda d: build_parts(d, mechanism, motion, gear_pairs, result.parts))
        design = dataclasses.replace(design, parts=dataclasses.replace(design.parts, link_width_mm=width))
        sizing = {"link_width_mm": width, "tried": [{"link_width_mm": w, "least_safety_factor": sf}
                                                    for w, sf in tried]}
    enter("parts")
    partset = build_parts(design, mechanism, motion, gear_pairs, result.parts)
    def step_job() -> dict[str, bytes]:
        if optional is None:
            return export_step(design, partset, motion)
        if not optional.step:
            return {}
        return dict(optional.step_files) if optional.step_files is not None else export_step(design, partset,
                                                                                             motion)

    # pictures take as long as everything else: draw them in a forked child on the second core
    pictures = Background([lambda: synthesis_plots(result), lambda: gear_pictures(gear_pairs),
                           lambda: export_previews(design, partset, motion), step_job])
    try:
        # inside the try: this may import OCP (slow), and a stop signal landing here must cancel the child
        with_step = step_available() if optional is None else optional.step
        report["notes"] = [] if with_step else [STEP_SKIPPED]
        # optional outputs as written or skipped: `check` rebuilds with the same set, so its verdict does not
        # depend on the checker's install (fabricate/verify.py)
        report["outputs"] = {"step": "written" if with_step else "skipped: OCP is not installed (extra 'cad')"}
        enter("exports")
        exported, parts_report = export_all(design, partset, mechanism, motion, previews=False, step=False,
                                             with_step=with_step)
        files.update(exported)
        report["parts"] = parts_report
        report["bom"] = list(getattr(partset, "bom", []))
        stacks = pin_stacks(partset)
        report["assembly"] = {"pins": stacks_report(stacks), "steps": assembly_steps(stacks, partset.copies)}
        files["assembly.csv"] = assembly_csv(stacks)
        files["motion.csv"] = motion_csv(mechanism, motion)
        files["mechanism.toml"] = mechanism_toml(design, mechanism, result.parts)
        enter("checks")
        checks = run_checks(design, partset, mechanism, motion, gear_pairs)
        report["interference"] = checks.interference
        failures = list(checks.failures)
        for pair in gear_pairs:
            failures += [f"gear {pair.name}: {text}" for text in pair.failures()]
        enter("strength")
        strength = run_strength(design, partset, mechanism, motion, gear_pairs, result.parts)
        report["strength"] = strength.report()
        if sizing is not None:
            report["strength"]["sizing"] = sizing
        failures += strength.failures()
        # passed is over the checks that ran; those that could not run are listed, never passed
        not_checked = [dict(entry) for entry in checks.not_checked]
        if strength.reason is not None:
            not_checked.append({"check": "strength", "reason": strength.reason})
        report["checks"] = {"passed": not failures, "failures": failures, "not_checked": not_checked}
        enter("plots")
        if strength.findings:
            files["plots/strength.png"] = strength_plot(strength, mechanism.input_unit)
        for name, data in sorted(checks.figures().items()):
            files[f"plots/{name}"] = data
        files.update(pictures.result())
    finally:
        pictures.cancel()
    return _finish(design, report, files, exit_code=0 if not failures else 1, synthesis=result, motion=motion,
                   partset=partset, gear_pairs=gear_pairs, checks=checks)


def synthesis_plots(result: SynthesisResult) -> dict[str, bytes]:
    """The synthesis method's figures, under ``plots/`` (the same paths for ``synth`` and ``build``)."""
    return {f"plots/{name}": data for name, data in sorted(result.figures().items())}


def gear_pictures(gear_pairs: list[Any]) -> dict[str, bytes]:
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


def _run_jobs(jobs: list[Callable[[], dict[str, bytes]]]) -> dict[str, bytes]:
    files: dict[str, bytes] = {}
    for job in jobs:
        files.update(job())
    return files


def _die_with_parent(parent: int) -> None:
    """Make this forked child die with ``parent``, even when the parent is killed by SIGKILL.

    On Linux the kernel sends SIGKILL when the parent goes (``PR_SET_PDEATHSIG``); the parent may have died
    between the fork and this call, so the parent is looked at again after the signal is armed. The death
    signal fires when the forking *thread* ends: :class:`Background` is collected or cancelled by the thread
    that made it, which therefore outlives the child.
    """
    import signal
    import sys

    if sys.platform.startswith("linux"):
        import ctypes

        pr_set_pdeathsig = 1
        try:
            ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # no prctl in this libc: the getppid check below still holds
            pass
    if os.getppid() != parent:  # orphaned already: nobody will read the result
        os._exit(1)


def _detach_from_caller() -> None:
    """Let the caller's signals kill the child at once, and give its stdout/stderr back.

    The CLI's handlers (SIGTERM or SIGHUP raised as an exception) are copied by the fork; in the child the
    default action is right, since it holds no file to clean up. A signal the caller ignores stays ignored.
    The child's fds 1 and 2 go to /dev/null, so a caller reading this process's output to the end never
    waits for the child, and the parent's unflushed buffers copied by the fork are not printed twice.
    """
    import signal

    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        number = getattr(signal, name, None)
        if number is not None and callable(signal.getsignal(number)):
            signal.signal(number, signal.SIG_DFL)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in (1, 2):
            os.dup2(devnull, fd)
    finally:
        os.close(devnull)


def _child(jobs: list[Callable[[], dict[str, bytes]]], conn: Any, parent: int = 0, receiver: Any = None) -> None:
    try:
        if parent:
            _die_with_parent(parent)
        _detach_from_caller()
        if receiver is not None:
            # the fork copied the parent's end of the pipe: holding it, this child would block forever on a
            # full pipe once the parent is gone, instead of failing with EPIPE
            receiver.close()
        conn.send((True, _run_jobs(jobs)))
    except BaseException as exc:  # the parent redoes the work serially and raises there
        with contextlib.suppress(BaseException):  # the parent may be gone: nothing is left to tell
            conn.send((False, repr(exc)))
    finally:
        conn.close()


class Background:
    """Run jobs returning ``{path: bytes}`` in a forked child process while the caller goes on.

    Where ``fork`` is unavailable, or ``FABRICATE_SERIAL`` is set, or this process is a daemon (a Dask
    worker), or the child fails, the jobs run in the calling process when :meth:`result` is asked for, so
    the outcome never depends on it. Call :meth:`cancel` in a ``finally``: the child is killed and reaped
    however the caller ends; on Linux it also dies with its parent (a SIGKILL of the parent included) and
    never holds the parent's stdout or stderr.
    """

    def __init__(self, jobs: list[Callable[[], dict[str, bytes]]]) -> None:
        self.jobs = jobs
        self._process = None
        if os.environ.get("FABRICATE_SERIAL") or "fork" not in multiprocessing.get_all_start_methods():
            return
        if multiprocessing.current_process().daemon:  # e.g. a Dask worker: daemons may not have children
            return
        ctx = multiprocessing.get_context("fork")
        self._conn, sender = ctx.Pipe(duplex=False)
        self._process = ctx.Process(target=_child, args=(jobs, sender, os.getpid(), self._conn), daemon=True)
        try:
            self._process.start()
        except OSError:  # no fork now (EAGAIN, ENOMEM): the jobs run here when asked for
            self._process = None
            self._conn.close()
        finally:
            sender.close()

    def result(self) -> dict[str, bytes]:
        if self._process is not None:
            try:
                ok, payload = self._conn.recv()
            except Exception:  # noqa: BLE001 - EOF (the child died), a broken or unreadable pickle: redo it here
                ok, payload = False, None
            self._conn.close()
            self._process.join()
            self._process = None
            if ok:
                return payload
        return _run_jobs(self.jobs)

    def cancel(self) -> None:
        """Kill the child if its result was never collected (the build failed or was interrupted).

        SIGKILL, not SIGTERM: the child writes no file, so nothing is lost, and no handler it may have
        inherited can delay it.
        """
        if self._process is not None:
            self._process.kill()
            self._process.join()
            self._conn.close()
            self._process = None


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
    return BuildOutcome(report=report, files=files, **kw)
