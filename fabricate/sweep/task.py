"""One sweep point, and a batch of them: what a Dask task runs (no Dask in here).

A point is a template like any other: it is validated, synthesised (``stage = "synth"``) or built (``"build"``),
and its report's metrics are read. A build point makes its report only (``run_build``'s ``report_only``: no
pictures, plots or STEP files, whose bytes no metric reads), unless a metric reads the list of files
(:data:`FILE_SECTIONS`); the best points are built again in full (:func:`build_point`). Whatever happens, the
point becomes a row; a bad point is a row with its exit code and reason, never an exception out of the task.

Points that differ only in fields synthesis does not read (:func:`synthesis_group`) share its result: a batch
runs with the in-process layer of the stage cache (:mod:`fabricate.cache`, never its disk layer), which lives as
long as the worker process, so a worker synthesises each group once, and a build sweep's later stages are
reused too wherever their own inputs agree (a point that only changes ``[load]`` re-runs the strength check
alone). The runner sends a group's points one after the other.
"""

from __future__ import annotations

import copy
import json
import math
import os
import sys
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any

from fabricate.sweep.paths import Metric

#: Exit codes of a row, as the CLI's: 0 passes, 1 fails a check, 2 invalid or infeasible, 3 internal error.
EXIT_OK, EXIT_FAILED, EXIT_INVALID, EXIT_INTERNAL = 0, 1, 2, 3

#: Template tables synthesis never reads (:func:`fabricate.stage_keys.synthesis_key`): a point that varies only fields
#: in these (and ``[checks]`` but its ``sweep_poses``) shares the synthesis of the other points of its group.
NOT_SYNTHESIS_TABLES = frozenset({"process", "parts", "load"})

#: Report sections where a report-only build (:func:`fabricate.pipeline.run_build`) differs from a full one: the
#: files it made (``files``, ``manifest``) and its STEP files "skipped" (``outputs``). Every other section is the
#: full build's; a build sweep with a metric under one of these builds its points in full.
FILE_SECTIONS = frozenset({"files", "manifest", "outputs"})


def report_only(metrics: Sequence[Metric]) -> bool:
    """Whether a build point's report-only build gives the same ``metrics`` as a full build (none reads a file
    list)."""
    return not any(m.section in FILE_SECTIONS for m in metrics)


def synthesis_group(fields: Sequence[tuple[str, Sequence[str | int]]], values: Mapping[str, Any]) -> str:
    """The values of a point's varied fields that synthesis may read, as a text: points with the same text share
    their synthesis (and its swept motion).

    A scheduling hint only: the cache's own key (:func:`fabricate.stage_keys.synthesis_key`, of the validated design)
    decides what is reused, so a field taken for one that synthesis reads when it does not costs a synthesis,
    never a wrong result. ``[process]``, ``[parts]``, ``[load]``, ``[checks]`` (but ``sweep_poses``) and
    ``design.description`` are the fields it does not read.
    """
    read = []
    for path, parts in fields:
        top = str(parts[0]) if parts else ""
        second = str(parts[1]) if len(parts) > 1 else ""
        if top in NOT_SYNTHESIS_TABLES or (top == "checks" and second != "sweep_poses") \
                or (top == "design" and second == "description"):
            continue
        read.append([path, values[path]])
    return json.dumps(read, sort_keys=True, default=str)


def peak_rss_mb() -> float:
    """This process's peak resident memory (MB; 0 where the platform does not say)."""
    try:
        import resource
    except ImportError:  # Windows
        return 0.0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1024.0 if sys.platform != "darwin" else peak / 1024.0 / 1024.0  # kB on Linux, bytes on macOS


#: What a point imports: the pipeline, then (a build point) the stages it imports as they run, and with them shapely,
#: trimesh, manifold3d and ezdxf (about 0.9 s of CPU, a build point's half).
POINT_MODULES = ("fabricate.design", "fabricate.pipeline", "fabricate.report", "fabricate.tomlwrite")
BUILD_MODULES = ("fabricate.gears", "fabricate.gears.auto", "fabricate.parts.build", "fabricate.parts.assembly",
                 "fabricate.parts.hardware_report", "fabricate.parts.spring_rows", "fabricate.strength.check",
                 "fabricate.strength.sizing", "fabricate.drive.check", "fabricate.drive.parts", "fabricate.checks",
                 "fabricate.checks.shop", "fabricate.export", "fabricate.export.dxf", "fabricate.export.stl",
                 "fabricate.export.svg", "fabricate.export.kinematic", "fabricate.export.guide",
                 "fabricate.export.mjcf", "fabricate.synthesis.linkage.exact")


def warm(stage: str = "synth") -> None:
    """Import what a point of ``stage`` runs: a Dask worker does once, at start-up and beside the other workers,
    rather than in its first point."""
    import importlib

    for name in POINT_MODULES + (BUILD_MODULES if stage == "build" else ()):
        importlib.import_module(name)


def point_text(base: Mapping[str, Any], fields: Sequence[tuple[str, Sequence[str | int]]],
               values: Mapping[str, Any]) -> str:
    """A point's template as TOML text: the base tables with the point's values set."""
    from fabricate.sweep.paths import set_path
    from fabricate.tomlwrite import dumps

    data = copy.deepcopy(dict(base))
    for path, parts in fields:
        set_path(data, parts, copy.deepcopy(values[path]))
    return dumps(data)


def _reason(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:2000]


def evaluate(text: str, stage: str, *, lean: bool = False) -> tuple[int, str, dict[str, Any] | None, Any]:
    """Validate and run one template text (``lean``: a build makes its report only, see :func:`report_only`).

    Returns
    -------
    exit_code, reason, report, outcome
        ``report`` is None when the point never got one (invalid or infeasible: exit code 2; a bug: 3).
    """
    from fabricate.design import design_from_text
    from fabricate.errors import FabricateError
    from fabricate.pipeline import run_build, run_synth

    try:
        design = design_from_text(text, "point.toml")
        outcome = run_build(design, report_only=lean) if stage == "build" else run_synth(design)
    except FabricateError as exc:
        return EXIT_INVALID, _reason(exc), None, None
    except MemoryError:
        return EXIT_INTERNAL, "out of memory", None, None
    except Exception as exc:  # noqa: BLE001 - a bug in one point must not end the sweep
        return EXIT_INTERNAL, f"internal error: {type(exc).__name__}: {_reason(exc)}", None, None
    from fabricate.report import SYNTH_ONLY, not_checked, not_checked_notes

    report = outcome.report
    failures = list(report.get("checks", {}).get("failures", []))
    # a passing point whose strength (say) was never checked says so in its reason, so a sweep's "best"
    # is never a point that passed only because nothing was checked; synth points all skip every check
    skipped = [n for n in not_checked_notes(report)
               if not any(r == SYNTH_ONLY for _, r in not_checked(report))]
    return outcome.exit_code, "; ".join(failures + skipped)[:2000], report, outcome


def run_point(index: int, values: Mapping[str, Any], pid: str, base: Mapping[str, Any],
              fields: Sequence[tuple[str, Sequence[str | int]]], stage: str,
              metrics: Sequence[Metric]) -> dict[str, Any]:
    """One row: ``point``, ``id``, the varied values, ``exit_code``, ``reason``, one float per metric (NaN
    where the report has no such key), and ``seconds`` (the run time, kept out of the result tables)."""
    start = time.perf_counter()
    try:
        text = point_text(base, fields, values)
    except (KeyError, TypeError, ValueError) as exc:  # the spec was checked; a value TOML cannot hold
        code, reason, report = EXIT_INVALID, f"cannot write this point's template: {_reason(exc)}", None
    else:
        code, reason, report, _ = evaluate(text, stage, lean=report_only(metrics))
    row: dict[str, Any] = {"point": int(index), "id": pid}
    row.update(values)
    row["exit_code"] = int(code)
    row["reason"] = reason
    for m in metrics:
        row[m.name] = m.read(report) if report is not None else math.nan
    row["seconds"] = round(time.perf_counter() - start, 4)
    return row


@contextmanager
def _serial() -> Iterator[None]:
    """``FABRICATE_SERIAL`` while a task runs, as it was after: a caller in its own process (the API, a test)
    keeps its forked picture child for its later builds."""
    before = os.environ.get("FABRICATE_SERIAL")
    os.environ["FABRICATE_SERIAL"] = before or "1"
    try:
        yield
    finally:
        if before is None:
            os.environ.pop("FABRICATE_SERIAL", None)


def run_batch(points: Sequence[tuple[int, Mapping[str, Any], str]], base: Mapping[str, Any],
              fields: Sequence[tuple[str, Sequence[str | int]]], stage: str,
              metrics: Sequence[Metric], cache: bool = False) -> list[dict[str, Any]]:
    """Rows of several points ``(index, values, id)``, run one after the other in this process (one Dask
    task).

    Plots that a build would draw in a forked child are drawn in this process: a Dask worker runs one task
    per core already. With ``cache``, stage results are kept in this process's memory (never on disk) and
    reused by this and later batches of the same process wherever a stage's inputs are the same.
    """
    from fabricate.cache import use_cache

    with _serial(), use_cache(cache, disk=False):
        return [run_point(i, values, pid, base, fields, stage, metrics) for i, values, pid in points]


def build_point(values: Mapping[str, Any], base: Mapping[str, Any],
                fields: Sequence[tuple[str, Sequence[str | int]]],
                cache: bool = False) -> tuple[int, str, dict[str, bytes]]:
    """A point built in full (the sweep's best points): exit code, reason and every output file (a build
    sweep's worker may still hold its stages, with ``cache``)."""
    from fabricate.cache import use_cache

    with _serial(), use_cache(cache, disk=False):
        code, reason, _report, outcome = evaluate(point_text(base, fields, values), "build")
    return code, reason, (dict(outcome.files) if outcome is not None else {})


def _plain(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return v


def row_json(row: Mapping[str, Any]) -> str:
    """A row as one JSON line (NaN as null), for the sweep's journal."""
    clean = {k: _plain(v) for k, v in row.items()}
    return json.dumps(clean, separators=(",", ":"), allow_nan=False)


def row_from_json(line: str, metrics: Sequence[Metric]) -> dict[str, Any]:
    """Inverse of :func:`row_json` (a missing metric reads back as NaN, an infinite one as inf)."""
    row = json.loads(line)
    for m in metrics:
        v = row.get(m.name)
        row[m.name] = math.nan if v is None else (float(v) if isinstance(v, str) else v)
    return row
