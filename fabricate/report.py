"""report.json and report.md: encoders only (they return text/bytes; the pipeline writes)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np


def jsonable(value: Any) -> Any:
    """Convert numpy scalars/arrays, tuples and non-finite floats into plain JSON values.

    Non-finite floats become ``None`` (JSON has no NaN); floats are rounded to 12 significant digits so
    the bytes do not depend on the last ulp of a platform's libm.
    """
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if not math.isfinite(value):
            return None
        return float(f"{value:.12g}")
    return value


def report_json(report: Mapping[str, Any]) -> bytes:
    """report.json bytes (UTF-8, 2-space indent, trailing newline)."""
    return (json.dumps(jsonable(report), indent=2, ensure_ascii=False) + "\n").encode("utf-8")


def _fmt(value: Any, digits: int = 4) -> str:
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_fmt(v, digits) for v in value) + "]"
    return str(value)


def _table(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_fmt(c) for c in row) + " |" for row in rows]
    return lines


def report_markdown(report: Mapping[str, Any], images: Sequence[str] = ()) -> str:
    """A human-readable summary of a report (report.md), linking the given image paths."""
    design = report.get("design", {})
    checks = report.get("checks", {})
    out = [f"# {design.get('name', 'design')} ({design.get('kind', '')})", ""]
    if design.get("description"):
        out += [design["description"], ""]
    out += [f"Template: `{design.get('template', '')}` · fabricate {design.get('fabricate_version', '')}", ""]
    verdict = "PASSED" if checks.get("passed") else "FAILED"
    out += [f"## Checks: {verdict}", ""]
    for failure in checks.get("failures", []):
        out.append(f"- {failure}")
    if checks.get("failures"):
        out.append("")
    mech = report.get("mechanism", {})
    if mech.get("joints"):
        out += ["## Mechanism (first pose)", ""]
        out += [f"Input range: {_fmt(mech.get('input_range_deg'))} ({mech.get('input_unit', 'deg')})", ""]
        out += _table(["point", "x mm", "y mm"], [[k, v[0], v[1]] for k, v in mech["joints"].items()])
        out += [""]
    synthesis = report.get("synthesis", {})
    if synthesis:
        out += ["## Synthesis", ""]
        scalars = [(k, v) for k, v in synthesis.items() if isinstance(v, (int, float, str, bool))]
        if "pose_error_mm" in synthesis and isinstance(synthesis["pose_error_mm"], Mapping):
            pe = synthesis["pose_error_mm"]
            scalars.insert(0, ("pose_error_mm (max / mean)", f"{_fmt(pe.get('max'))} / {_fmt(pe.get('mean'))}"))
        out += _table(["quantity", "value"], scalars) + [""]
    gears = report.get("gears", [])
    if gears:
        out += ["## Gears", ""]
        out += _table(["pair", "teeth", "module mm", "method", "centre mm", "TE deg", "backlash mm",
                       "interference mm²", "undercut", "min ρ mm"],
                      [[g.get("name"), g.get("teeth"), g.get("module_mm"), g.get("method"),
                        g.get("center_distance_mm"), g.get("transmission_error_deg"), g.get("backlash_mm"),
                        g.get("interference_area_mm2"), g.get("undercut"),
                        g.get("min_pitch_radius_of_curvature_mm")] for g in gears]) + [""]
    parts = report.get("parts", [])
    if parts:
        out += ["## Parts", ""]
        out += _table(["part", "process", "layer", "volume mm³", "holes (joint: Ø mm)", "STL", "DXF"],
                      [[p.get("name"), p.get("process"), p.get("layer"), p.get("volume_mm3"),
                        ", ".join(f"{h['joint']}: {h['diameter_mm']:.3f}" for h in p.get("holes", [])),
                        p.get("stl"), p.get("dxf")] for p in parts]) + [""]
    bom = report.get("bom", [])
    if bom:
        out += ["## Bill of materials", ""]
        keys = list(dict.fromkeys(k for row in bom for k in row))
        out += _table(keys, [[row.get(k, "") for k in keys] for row in bom]) + [""]
    inter = report.get("interference", {})
    if inter:
        out += ["## Interference", ""]
        out += [f"Poses: {inter.get('poses')} · pairs checked: {inter.get('pairs_checked')} · "
                f"smallest clearance: {_fmt(inter.get('min_clearance_mm'))} mm", ""]
        if inter.get("collisions"):
            out += _table(["a", "b", "input", "volume mm³"],
                          [[c.get("a"), c.get("b"), c.get("input_deg"), c.get("volume_mm3")]
                           for c in inter["collisions"]]) + [""]
        pairs = inter.get("pairs", [])
        if pairs:
            keys = [k for k in ("a", "b", "min_clearance_mm", "at_input", "kind") if k in pairs[0]]
            out += _table(keys, [[p.get(k) for k in keys] for p in pairs]) + [""]
    if images:
        out += ["## Pictures", ""]
        out += [f"![{path}]({path})" for path in images] + [""]
    files = report.get("files", [])
    if files:
        out += ["## Files", ""] + [f"- `{f}`" for f in files] + [""]
    return "\n".join(out)
