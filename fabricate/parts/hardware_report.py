"""The pins, fits and hardware of a part set for people: report.json's ``hardware`` section (what is bought,
what each hole measures on the finished part) and its report.md lines. :mod:`fabricate.parts.retention` plans them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from fabricate.process import ProcessSpec

if TYPE_CHECKING:
    pass


def hardware_report(partset: Any, process: ProcessSpec) -> dict[str, Any]:
    """report.json's ``hardware``: the fits of the process, every pin as bought and fitted, and what to measure
    on the finished parts (JSON-ready).

    Parameters
    ----------
    partset : PartSet
        ``pins`` (after :func:`retain_pins`) and ``parts``.
    process : ProcessSpec
    """
    fits = {"retention": process.retention, "running_clearance_mm": process.running_clearance_mm,
            "press_fit_interference_mm": process.press_fit_interference_mm,
            "hole_compensation_mm": process.hole_compensation_mm, "kerf_mm": process.kerf_mm}
    pins = [{"pin": p.joint, "designation": p.designation or None, "diameter_mm": p.diameter_mm,
             "length_mm": round(float(p.length_mm), 6), "stack_mm": round(float(p.stack_mm or p.length_mm), 6),
             "allowance_mm": round(float(p.allowance_mm), 6), "retention": p.retention or process.retention,
             "holder": p.holder or None, "protrusion_mm": [round(float(v), 6) for v in p.protrusion_mm],
             "engagement_mm": round(float(p.engagement_mm), 6) or None,
             "ends": [list(items) for items in p.end_items], "grooves_mm": [round(g, 6) for g in p.grooves_mm],
             "note": p.note or None}
            for p in getattr(partset, "pins", ())]
    ground = next((p for p in getattr(partset, "parts", ()) if p.role == "ground"), None)
    under = [{"pin": p.joint, "protrusion_mm": round(float(p.protrusion_mm[0]), 6),
              "hole_mm": round(float(p.diameter_mm) + 1.0, 6)}
             for p in getattr(partset, "pins", ())
             if ground is not None and p.protrusion_mm[0] > 1e-9 and abs(p.stack_z_mm[0] - ground.z_mm) < 1e-6
             and ground.body in p.bodies]
    measure = []
    for part in getattr(partset, "parts", ()):
        for h in part.holes:
            measure.append({"part": part.name, "hole": h.joint, "fit": h.fit, "nominal_mm": round(h.nominal_mm, 6),
                            "modelled_mm": round(h.diameter_mm, 6), "compensation_mm": round(h.compensation_mm, 6),
                            "cut_mm": round(h.diameter_mm - process.kerf_mm, 6) if process.technique == "cut"
                            else None})
    return {"fits": fits, "pins": pins, "measure": measure, "under_ground": under}


def hardware_markdown(section: Mapping[str, Any]) -> list[str]:
    """report.md's "Pins, fits and what to measure" from report.json's ``hardware``."""
    fits = section.get("fits", {})
    out = ["## Pins, fits and what to measure", ""]
    scheme = fits.get("retention", "")
    comp = float(fits.get("hole_compensation_mm") or 0.0)
    words = {"press": f"each pin is pressed into the part that holds it ({fits.get('press_fit_interference_mm', 0):g} "
                      "mm diametral interference) and runs in the others",
             "clip": "each pin runs in every part and is held by a DIN 6799 clip in a groove at each end",
             "cap": "each pin runs in every part and is held by a cap bonded onto each end"}
    out += [f"Retention: {words.get(scheme, scheme)}; running holes are the pin + 2 × "
            f"{fits.get('running_clearance_mm', 0):g} mm. Hole sizes below are NOMINAL: what the finished part "
            "should measure (pin gauge or caliper)"
            + (f"; the CAD model's holes are {comp:+g} mm larger (process compensation, for holes that print "
               "undersize)." if comp else "."), ""]
    pins = section.get("pins", [])
    if pins:
        out += _md_table(["pin", "buy", "stack mm", "retention", "held by", "ends (bottom / top)", "beyond stack mm",
                          "grooves from bottom end mm"],
                         [[p["pin"], p.get("designation") or p.get("note") or "", f"{p['stack_mm']:.2f}",
                           p.get("retention", ""), p.get("holder") or "",
                           " / ".join(", ".join(e) or "–" for e in p.get("ends", [[], []])),
                           " / ".join(f"{v:+.2f}" for v in p.get("protrusion_mm", [])),
                           ", ".join(f"{g:.2f}" for g in p.get("grooves_mm", [])) or ""] for p in pins]) + [""]
    for u in section.get("under_ground", []):
        out += [f"Pin {u['pin']} sticks out {u['protrusion_mm']:.2f} mm under the ground part's mounting face: "
                f"drill a Ø{u['hole_mm']:g} mm clearance hole that deep in the base (or mount on standoffs).", ""]
    measure = list(section.get("measure", []))
    if measure:
        out += ["Measure on the finished parts:", ""]
        cut = any(m.get("cut_mm") is not None for m in measure)
        header = ["part", "hole", "fit", "measure Ø mm", "CAD Ø mm", "compensation mm"]
        header += ["cut path Ø mm"] if cut else []
        out += _md_table(header, [[m["part"], m["hole"], m["fit"], f"{m['nominal_mm']:.3f}",
                                   f"{m['modelled_mm']:.3f}", f"{m['compensation_mm']:+.3f}"]
                                  + ([f"{m['cut_mm']:.3f}"] if cut else []) for m in measure]) + [""]
    return out


def _md_table(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |" for row in rows]
