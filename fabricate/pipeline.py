"""The whole pipeline: template → spec → synthesis → mechanism → gears → parts → exports and checks.

Everything is computed in memory into ``{relative path: bytes}``; only :func:`write_atomically` touches
the file system, into a temporary sibling directory renamed into place when every file is written, so a
failed run never leaves half a result.
"""

from __future__ import annotations

import multiprocessing
import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fabricate import __version__
from fabricate.errors import LockupError
from fabricate.mechanism import Mechanism, Motion
from fabricate.report import report_json, report_markdown
from fabricate.spec import TEMPLATE_DIR, DesignSpec
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


def template_label(path: Path) -> str:
    """How the report names a template: relative to the shipped folder or the working directory."""
    path = path.resolve()
    for base in (TEMPLATE_DIR.parent, Path.cwd()):
        try:
            return path.relative_to(base.resolve()).as_posix()
        except ValueError:
            continue
    return path.as_posix()


def design_section(design: DesignSpec) -> dict[str, Any]:
    return {"name": design.name, "kind": design.kind, "template": template_label(design.template),
            "fabricate_version": __version__, "description": design.description,
            "process": design.process.name}


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


def _synthesis_stage(design: DesignSpec, progress: Progress
                     ) -> tuple[SynthesisResult, dict[str, Any], Motion | None, list[str]]:
    """Synthesis and the swept motion; a lock-up inside the range is a design failure, not an error."""
    result = synthesise(design, progress)
    report: dict[str, Any] = {"design": design_section(design)}
    progress("sweep")
    try:
        motion = result.mechanism.sweep(design.checks.sweep_poses)
    except LockupError as exc:
        report["synthesis"] = result.report
        return result, report, None, [f"motion: {exc}"]
    report["mechanism"] = mechanism_section(result.mechanism, motion)
    report["synthesis"] = result.report
    return result, report, motion, []


def run_synth(design: DesignSpec, progress: Progress = _quiet) -> BuildOutcome:
    """Synthesis only: report.json with design, mechanism and synthesis, plus the method's plots."""
    result, report, motion, failures = _synthesis_stage(design, progress)
    progress("plots")
    files = {f"plots/{name}": data for name, data in sorted(result.figures().items())}
    report["checks"] = {"passed": not failures, "failures": failures}
    return _finish(report, files, exit_code=1 if failures else 0, synthesis=result, motion=motion)


def run_build(design: DesignSpec, progress: Progress = _quiet) -> BuildOutcome:
    """The whole pipeline in memory.

    Raises
    ------
    SpecError, SynthesisError
        Invalid input or nothing feasible (the CLI exits 2 and writes nothing).
    """
    from fabricate.checks import run_checks
    from fabricate.export import export_all, export_previews
    from fabricate.gears import build_gear_pairs
    from fabricate.parts.build import build_parts

    result, report, motion, failures = _synthesis_stage(design, progress)
    files: dict[str, bytes] = {}
    if motion is None:
        report["checks"] = {"passed": False, "failures": failures}
        return _finish(report, files, exit_code=1, synthesis=result)
    mechanism = result.mechanism
    progress("gears")
    gear_pairs = build_gear_pairs(mechanism, design.gears, design.process.chord_tolerance_mm)
    report["gears"] = [pair.report() for pair in gear_pairs]
    progress("parts")
    partset = build_parts(design, mechanism, motion, gear_pairs, result.parts)
    # pictures take as long as everything else: draw them in a forked child on the second core
    pictures = Background([result.figures, lambda: gear_pictures(gear_pairs),
                           lambda: export_previews(design, partset, motion)])
    progress("exports")
    exported, parts_report = export_all(design, partset, mechanism, motion, previews=False)
    files.update(exported)
    report["parts"] = parts_report
    report["bom"] = list(getattr(partset, "bom", []))
    progress("checks")
    checks = run_checks(design, partset, mechanism, motion, gear_pairs)
    report["interference"] = checks.interference
    failures = list(checks.failures)
    for pair in gear_pairs:
        failures += [f"gear {pair.name}: {text}" for text in pair.failures()]
    report["checks"] = {"passed": not failures, "failures": failures}
    progress("plots")
    for name, data in sorted(checks.figures().items()):
        files[f"plots/{name}"] = data
    files.update(pictures.result())
    return _finish(report, files, exit_code=0 if not failures else 1, synthesis=result, motion=motion,
                   partset=partset, gear_pairs=gear_pairs, checks=checks)


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


def _child(jobs: list[Callable[[], dict[str, bytes]]], conn: Any) -> None:
    try:
        conn.send((True, _run_jobs(jobs)))
    except BaseException as exc:  # the parent redoes the work serially and raises there
        conn.send((False, repr(exc)))
    finally:
        conn.close()


class Background:
    """Run jobs returning ``{path: bytes}`` in a forked child process while the caller goes on.

    Where ``fork`` is unavailable, or ``FABRICATE_SERIAL`` is set, or the child fails, the jobs run in
    the calling process when :meth:`result` is asked for, so the outcome never depends on it.
    """

    def __init__(self, jobs: list[Callable[[], dict[str, bytes]]]) -> None:
        self.jobs = jobs
        self._process = None
        if os.environ.get("FABRICATE_SERIAL") or "fork" not in multiprocessing.get_all_start_methods():
            return
        ctx = multiprocessing.get_context("fork")
        self._conn, sender = ctx.Pipe(duplex=False)
        self._process = ctx.Process(target=_child, args=(jobs, sender), daemon=True)
        self._process.start()
        sender.close()

    def result(self) -> dict[str, bytes]:
        if self._process is not None:
            try:
                ok, payload = self._conn.recv()
            except (EOFError, OSError):
                ok, payload = False, None
            self._conn.close()
            self._process.join()
            self._process = None
            if ok:
                return payload
        return _run_jobs(self.jobs)


def _finish(report: dict[str, Any], files: dict[str, bytes], **kw: Any) -> BuildOutcome:
    """Add report.json / report.md and the file list (every path relative to the output directory)."""
    images = [p for p in sorted(files) if p.endswith((".png", ".gif"))]
    report["files"] = sorted(set(files) | {"report.json", "report.md"})
    files["report.md"] = report_markdown(report, images).encode("utf-8")
    files["report.json"] = report_json(report)
    return BuildOutcome(report=report, files=files, **kw)


def write_atomically(files: dict[str, bytes], out_dir: Path) -> None:
    """Write every file into a temporary sibling of ``out_dir`` and rename it into place.

    An existing ``out_dir`` is replaced only after the new one is complete.
    """
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".tmp", dir=out_dir.parent))
    try:
        for rel, data in sorted(files.items()):
            target = tmp / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            with open(target, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
        os.chmod(tmp, 0o755)
        if out_dir.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".old", dir=out_dir.parent))
            os.rmdir(old)
            os.replace(out_dir, old)
            os.replace(tmp, out_dir)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, out_dir)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise

