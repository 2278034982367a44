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
    """report.json bytes (UTF-8, 2-space indent, trailing newline).

    The text of ``json.dumps(jsonable(report), indent=2, ensure_ascii=False)``, written in one pass: with an
    indent, json encodes in pure Python through generators, and a report of many interference pairs (a laser
    underactuated finger: 17 000 rows) spent most of a second there. Anything that pass does not know (a value
    json would refuse, a cycle) goes the plain way, which then raises as before.
    """
    out: list[str] = []
    try:
        _write_json(report, "\n", out)
    except (_NotPlain, RecursionError):
        return (json.dumps(jsonable(report), indent=2, ensure_ascii=False) + "\n").encode("utf-8")
    out.append("\n")
    return "".join(out).encode("utf-8")


class _NotPlain(Exception):
    """A value :func:`_write_json` leaves to json (it would not be a JSON value after :func:`jsonable`)."""


_encode_str = json.encoder.encode_basestring  # what json.dumps uses for strings with ensure_ascii=False


def _write_json(value: Any, newline: str, out: list[str]) -> None:
    """Append ``jsonable(value)`` as json.dumps(indent=2) writes it; ``newline`` is a newline and this level's
    indent."""
    kind = type(value)  # the plain types first, without the abstract-class checks below
    if kind is str:
        out.append(_encode_str(value))
    elif kind is float:
        out.append(float.__repr__(float(f"{value:.12g}")) if math.isfinite(value) else "null")
    elif kind is bool:
        out.append("true" if value else "false")
    elif kind is int:
        out.append(int.__repr__(value))
    elif value is None:
        out.append("null")
    elif isinstance(value, str):
        out.append(_encode_str(value))
    elif isinstance(value, Mapping):
        items = {str(k): v for k, v in value.items()}  # jsonable's keys (equal strings collapse as there)
        _write_members([(_encode_str(k) + ": ", v) for k, v in items.items()], "{}", newline, out)
    elif isinstance(value, (list, tuple, np.ndarray)):
        seq = value.tolist() if isinstance(value, np.ndarray) else value
        if isinstance(seq, (list, tuple)):
            _write_members([("", item) for item in seq], "[]", newline, out)
        else:  # a 0-d array's tolist() is a scalar
            _write_json(seq, newline, out)
    elif isinstance(value, (bool, np.bool_)):
        out.append("true" if value else "false")
    elif isinstance(value, (int, np.integer)):
        out.append(int.__repr__(int(value)))
    elif isinstance(value, (float, np.floating)):
        number = float(value)
        out.append(float.__repr__(float(f"{number:.12g}")) if math.isfinite(number) else "null")
    else:
        raise _NotPlain(type(value).__name__)


def _write_members(members: list[tuple[str, Any]], brackets: str, newline: str, out: list[str]) -> None:
    """An object's or an array's members (each a prefix, ``"key": `` or nothing, and its value) between
    ``brackets``, one per line at the next indent, as json.dumps(indent=2) writes them (``{}``/``[]`` when empty)."""
    if not members:
        out.append(brackets)
        return
    inner = newline + "  "
    out.append(brackets[0])
    for k, (prefix, item) in enumerate(members):
        out.append(inner if k == 0 else "," + inner)
        out.append(prefix)
        _write_json(item, inner, out)
    out.append(newline + brackets[1])


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


#: ``checks.not_checked`` reason of a synthesis-only run (``fabricate synth``): no check ran.
SYNTH_ONLY = "synth only"


def not_checked(report: Mapping[str, Any]) -> list[tuple[str, str]]:
    """``(check, reason)`` of every check a report says did not run (``checks.not_checked``).

    Entries of the wrong shape (a hand-edited report) are skipped: this only words a summary, the schema
    check of ``fabricate check`` judges the file.
    """
    checks = report.get("checks")
    entries = checks.get("not_checked") if isinstance(checks, Mapping) else None
    if not isinstance(entries, list):
        return []
    return [(str(e.get("check")), str(e.get("reason"))) for e in entries
            if isinstance(e, Mapping) and e.get("check") and e.get("reason")]


def not_checked_notes(report: Mapping[str, Any]) -> list[str]:
    """``"<check> not checked: <reason>"`` per check that did not run, one reason given once for all
    the checks that share it (``"interference, gear mesh not checked: no poses in the motion"``)."""
    by_reason: dict[str, list[str]] = {}
    for check, reason in not_checked(report):
        by_reason.setdefault(reason, []).append(check)
    return [f"{', '.join(checks)} not checked: {reason}" for reason, checks in by_reason.items()]


def verdict(report: Mapping[str, Any], failures: Sequence[str] | None = None) -> str:
    """The one-line verdict people read: ``checks passed``, ``checks FAILED``, with what was not checked
    in brackets (``checks passed (strength not checked: no materials in the profile)``); a synthesis-only
    run says ``synthesis done (no checks run: synth only)``, never that checks passed.

    ``failures`` (default: the report's) decides passed or FAILED: ``check DIR`` adds its own findings.
    """
    checks = report.get("checks")
    checks = checks if isinstance(checks, Mapping) else {}
    if failures is None:
        failed = bool(checks.get("failures")) or checks.get("passed") is False
    else:
        failed = bool(failures)
    skipped = not_checked(report)
    design = report.get("design")
    stage = design.get("stage") if isinstance(design, Mapping) else None
    if stage == "synth" or any(reason == SYNTH_ONLY for _, reason in skipped):
        return "synthesis FAILED" if failed else f"synthesis done (no checks run: {SYNTH_ONLY})"
    text = "checks FAILED" if failed else "checks passed"
    notes = not_checked_notes(report)
    return f"{text} ({'; '.join(notes)})" if notes else text


def report_markdown(report: Mapping[str, Any], images: Sequence[str] = ()) -> str:
    """A human-readable summary of a report (report.md), linking the given image paths."""
    out = _verdict_lines(report)
    out += _contents(report)
    out += _mechanism_lines(report.get("mechanism", {}))
    out += _synthesis_lines(report.get("synthesis", {}))
    out += _gear_lines(report.get("gears", []))
    out += _part_lines(report.get("parts", []))
    if report.get("cut"):  # a laser build: its sheets, their utilisation, the part-number key and labels
        from fabricate.export.labels import cut_markdown

        out += cut_markdown(report["cut"])
    out += _assembly_lines(report.get("assembly", {}))
    bom = report.get("bom", [])
    if bom:
        out += ["## Bill of materials", ""]
        keys = list(dict.fromkeys(k for row in bom for k in row))
        out += _table(keys, [[row.get(k, "") for k in keys] for row in bom]) + [""]
    if report.get("hardware"):
        from fabricate.parts.hardware_report import hardware_markdown

        out += hardware_markdown(report["hardware"])
    strength = report.get("strength", {})
    if strength:
        out += strength_markdown(strength)
    if report.get("springs"):
        out += springs_markdown(report["springs"])
    if report.get("drive"):
        from fabricate.drive.check import drive_markdown

        out += drive_markdown(report["drive"])
    # the step pictures belong to assembly.md, not here
    images = [path for path in images if not path.startswith("assembly/")]
    if images:
        out += ["## Pictures", ""]
        out += [f"![{path}]({path})" for path in images] + [""]
    files = report.get("files", [])
    if files:
        out += ["## Files", ""] + [f"- `{f}`" for f in files] + [""]
    # the pair-by-pair table is long (86 rows for the gripper): an appendix, after everything people read first
    inter = report.get("interference", {})
    if inter:
        out += ["---", "", "Appendix.", ""] + interference_markdown(inter)
    return "\n".join(out)


def _verdict_lines(report: Mapping[str, Any]) -> list[str]:
    """The title, the design's description and template, the verdict with its failures, and the notes."""
    design = report.get("design", {})
    checks = report.get("checks", {})
    out = [f"# {design.get('name', 'design')} ({design.get('kind', '')})", ""]
    if design.get("description"):
        out += [design["description"], ""]
    out += [f"Template: `{design.get('template', '')}` · fabricate {design.get('fabricate_version', '')}", ""]
    if design.get("stage") == "synth":
        heading = "## Checks: none run (synth only; `fabricate build` runs them)"
    else:
        heading = f"## Checks: {'PASSED' if checks.get('passed') else 'FAILED'}"
    out += [heading, ""]
    for failure in checks.get("failures", []):
        out.append(f"- {failure}")
    if design.get("stage") != "synth":
        out += [f"- {note}" for note in not_checked_notes(report)]
    if checks.get("failures") or (design.get("stage") != "synth" and not_checked(report)):
        out.append("")
    for note in report.get("notes", []):
        out += [f"Note: {note}", ""]
    return out


def _mechanism_lines(mech: Mapping[str, Any]) -> list[str]:
    """The input range and the joints at the first pose."""
    if not mech.get("joints"):
        return []
    out = ["## Mechanism (first pose)", ""]
    out += [f"Input range: {_fmt(mech.get('input_range_deg'))} ({mech.get('input_unit', 'deg')})", ""]
    out += _table(["point", "x mm", "y mm"], [[k, v[0], v[1]] for k, v in mech["joints"].items()])
    return out + [""]


def _synthesis_lines(synthesis: Mapping[str, Any]) -> list[str]:
    """The synthesis' scalar results, the pose error first."""
    if not synthesis:
        return []
    scalars = [(k, v) for k, v in synthesis.items() if isinstance(v, (int, float, str, bool))]
    if "pose_error_mm" in synthesis and isinstance(synthesis["pose_error_mm"], Mapping):
        pe = synthesis["pose_error_mm"]
        scalars.insert(0, ("pose_error_mm (max / mean)", f"{_fmt(pe.get('max'))} / {_fmt(pe.get('mean'))}"))
    return ["## Synthesis", ""] + _table(["quantity", "value"], scalars) + [""]


def _gear_lines(gears: Sequence[Mapping[str, Any]]) -> list[str]:
    """A row per gear pair."""
    if not gears:
        return []
    return ["## Gears", ""] + _table(
        ["pair", "teeth", "module mm", "method", "centre mm", "TE deg", "backlash mm", "interference mm²",
         "undercut", "min ρ mm"],
        [[g.get("name"), g.get("teeth"), g.get("module_mm"), g.get("method"), g.get("center_distance_mm"),
          g.get("transmission_error_deg"), g.get("backlash_mm"), g.get("interference_area_mm2"), g.get("undercut"),
          g.get("min_pitch_radius_of_curvature_mm")] for g in gears]) + [""]


def _part_lines(parts: Sequence[Mapping[str, Any]]) -> list[str]:
    """A row per part: process, layer, volume, holes and its files."""
    if not parts:
        return []
    return ["## Parts", ""] + _table(
        ["part", "process", "layer", "volume mm³", "holes (joint: Ø mm)", "STL", "DXF"],
        [[p.get("name"), p.get("process"), p.get("layer"), p.get("volume_mm3"),
          ", ".join(f"{h['joint']}: {h['diameter_mm']:.3f}" for h in p.get("holes", [])),
          p.get("stl"), p.get("dxf")] for p in parts]) + [""]


def _assembly_lines(assembly: Mapping[str, Any]) -> list[str]:
    """Where the assembly guide is, and each pin's stack."""
    if not (assembly.get("steps") or assembly.get("guide")):
        return []
    out = ["## Assembly", ""]
    if assembly.get("guide"):
        out += [f"Follow [assembly.md](assembly.md): {len(assembly['guide'])} numbered steps, each with its "
                "picture, parts, hardware, retention and tool, ending with a check of the motion.", ""]
    if assembly.get("steps"):
        out += ["Each pin's stack from bottom to top (also in `assembly.csv`):", ""]
        out += list(assembly["steps"]) + [""]
    return out


def _contents(report: Mapping[str, Any]) -> list[str]:
    """The lines under the verdict: where the assembly guide is, and the interference proof in one line (its
    table is the appendix at the end)."""
    out = []
    if (report.get("assembly") or {}).get("guide"):
        out.append("Assembly guide: [assembly.md](assembly.md) (numbered steps with pictures).")
    inter = report.get("interference") or {}
    if inter and inter.get("passed") is not None:
        out.append(f"Interference: {inter.get('pairs_checked')} pairs over {inter.get('poses')} poses, "
                   f"{len(inter.get('collisions', []))} collisions, smallest clearance between moving parts "
                   f"{_fmt(inter.get('min_clearance_mm'))} mm; every pair in the appendix at the end.")
    return out + [""] if out else []


def springs_markdown(springs: Sequence[Mapping[str, Any]]) -> list[str]:
    """report.md's springs paragraph: each torsion spring as specified, its wire stress against the allowable."""
    out = ["## Springs", "",
           "Torsion springs (music wire), sized from the synthesis' rate and preload over the joint's travel, on "
           "their pin's extension beyond the stack, legs hooked into anchor holes; bending stress at the largest "
           "deflection against the wire's allowable (0.65 × its minimum tensile strength):", ""]
    out += _table(["joint", "spring", "deflection °", "max torque N·mm", "stress MPa", "allowable MPa", "verdict"],
                  [[s.get("joint"), s.get("designation"), s.get("deflection_deg"), s.get("max_torque_Nmm"),
                    s.get("stress_MPa"), s.get("allowable_MPa"), "passes" if s.get("passed") else "FAILS"]
                   for s in springs])
    return out + [""]


#: How each kind of contact in the interference sweep is judged, in the words report.md uses.
CONTACT_KINDS = {
    "moving": ("parts moving past each other", "the running clearance",
               "their closest approach over the motion keeps the running clearance"),
    "pin": ("a pin in its hole", "the running clearance",
            "the hole is the pin plus the running clearance (and the process's compensation)"),
    "joined": ("parts stacked on one pin", "the running clearance",
               "the layer gap between their faces keeps them apart axially"),
    "meshing": ("gear teeth in mesh", "the backlash band of the gear mesh check",
                "teeth must come close: their flank gap is the backlash, held to its band below, not to "
                "the running clearance"),
    "bearing": ("a spacer or washer on its parts", "no overlap (contact allowed)",
                "a spacer carries the axial load face to face: touching is its job, overlapping is not"),
}


def interference_markdown(inter: Mapping[str, Any]) -> list[str]:
    """report.md's interference section: one line per kind of contact (what it is held to and why it
    passes), then every pair, worst first (least margin over its requirement)."""
    if "passed" in inter and inter["passed"] is None:  # the sweep could not run: no table of nothing
        return ["## Interference", "", f"Interference: not checked: {inter.get('reason') or 'no reason given'} "
                f"(poses: {inter.get('poses')}, pairs checked: {inter.get('pairs_checked')}).", ""]
    pairs = [p for p in inter.get("pairs", []) if isinstance(p, Mapping)]
    collisions = inter.get("collisions", [])
    out = ["## Interference", "",
           f"Poses: {inter.get('poses')} · pairs checked: {inter.get('pairs_checked')} · collisions: "
           f"{len(collisions)} · smallest clearance between moving parts: {_fmt(inter.get('min_clearance_mm'))} mm "
           f"(required {_fmt(inter.get('required_clearance_mm'))} mm). Gear mesh and bearing contacts are "
           "held to their own limits:", ""]
    rows = []
    for kind, (what, held_to, why) in CONTACT_KINDS.items():
        group = [p for p in pairs if p.get("kind", p.get("relation")) == kind]
        if not group:
            continue
        worst = min(group, key=lambda p: (p.get("min_clearance_mm") is None, p.get("min_clearance_mm") or 0.0))
        passed = all(p.get("ok", True) for p in group)
        rows.append([what, len(group), worst.get("min_clearance_mm"), f"{worst.get('a')} – {worst.get('b')}",
                     held_to, ("passes: " + why) if passed else "FAILS"])
    out += _table(["contact", "pairs", "smallest gap mm", "closest pair", "held to", "verdict"], rows) + [""]
    for mesh in inter.get("gear_mesh", []):
        if isinstance(mesh, Mapping) and mesh.get("backlash_mm"):
            out += [f"Gear mesh {mesh.get('name')}: backlash {_fmt(mesh.get('backlash_mm'))} mm within "
                    f"{_fmt(mesh.get('backlash_allowed_mm'))} mm, interference area "
                    f"{_fmt(mesh.get('interference_area_mm2'))} mm², transmission error "
                    f"{_fmt(mesh.get('transmission_error_deg'))}°: {'passes' if mesh.get('passed') else 'FAILS'}.",
                    ""]
    if collisions:
        out += ["Collisions:", ""]
        out += _table(["a", "b", "input", "volume mm³"],
                      [[c.get("a"), c.get("b"), c.get("input_deg"), c.get("volume_mm3")] for c in collisions])
        out += [""]
    if pairs:
        def margin(p: Mapping[str, Any]) -> tuple[int, float, str, str]:
            gap = p.get("min_clearance_mm")
            gap = float("-inf") if gap is None or p.get("collides") else float(gap)
            return (0 if not p.get("ok", True) else 1, gap - float(p.get("required_mm") or 0.0),
                    str(p.get("a")), str(p.get("b")))

        out += ["Every pair, worst first (least margin over what it is held to):", ""]
        out += _table(["a", "b", "contact", "smallest gap mm", "required mm", "margin mm", "at input", "ok"],
                      [[p.get("a"), p.get("b"), p.get("kind", p.get("relation")), p.get("min_clearance_mm"),
                        p.get("required_mm"), margin(p)[1], p.get("at_input", p.get("input_deg")), p.get("ok")]
                       for p in sorted(pairs, key=margin)]) + [""]
    return out


def strength_markdown(strength: Mapping[str, Any]) -> list[str]:
    """report.md's strength section: the loads, then one row per part and pin, weakest first; a check that
    could not run says "not checked: <reason>" and has no table."""
    if strength.get("passed") is None:
        out = ["## Strength", "", f"Strength: not checked: {strength.get('reason') or 'no reason given'}. No part "
               "has a safety factor: none was computed.", ""]
        out += [f"- {note}" for note in strength.get("notes", [])]
        return out + ([""] if strength.get("notes") else [])
    verdict = "passed" if strength.get("passed") else "FAILED"
    out = ["## Strength", "",
           f"Every part and pin at the design load over the whole motion: {verdict} (safety factor = allowable / "
           f"stress, required {_fmt(strength.get('required_safety_factor'))}).", ""]
    loads = strength.get("loads") or ["no load stated ([load] in the template)"]
    out += ["Loads: " + "; ".join(loads) + ".", ""]

    def weakest(p: Mapping[str, Any]) -> tuple[bool, float]:
        sf = p.get("min_safety_factor")
        return (not isinstance(sf, (int, float)), sf if isinstance(sf, (int, float)) else 0.0)

    # a null safety factor: the load does not reach the part (zero stress), listed last
    out += _table(["part", "safety factor", "governing feature", "load", "at input", "stress MPa", "allowable MPa"],
                  [[p.get("name"), "unloaded" if p.get("min_safety_factor") is None else p.get("min_safety_factor"),
                    p.get("feature"), p.get("input"), p.get("pose_input"), p.get("stress_MPa"), p.get("allowable_MPa")]
                   for p in sorted(strength.get("parts", []), key=weakest)]) + [""]
    out += [f"- {note}" for note in strength.get("notes", [])]
    return out + ([""] if strength.get("notes") else [])
