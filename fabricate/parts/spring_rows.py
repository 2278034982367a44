"""A placed torsion spring as the other stages see it: its BOM rows, its report.json entry, its failures and
its solids for the interference sweep (:mod:`fabricate.parts.springs` places it).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.parts.model import circle_polygon
from fabricate.parts.springs import PlacedSpring

if TYPE_CHECKING:
    from fabricate.checks.items import SweepItem


def spring_bom_rows(springs: Sequence[PlacedSpring], copies: int = 1) -> list[dict[str, Any]]:
    """One BOM row per spring designation (quantity over all copies), in the BOM's row shape."""
    rows: dict[str, dict[str, Any]] = {}
    for sp in springs:
        row = rows.get(sp.designation)
        if row is not None:
            row["qty"] += copies
            row["joints"] = sorted(set(row["joints"]) | {sp.joint})
            continue
        s = sp.spring
        rows[sp.designation] = {
            "item": sp.designation, "designation": sp.designation, "kind": "spring", "qty": copies,
            "joints": [sp.joint],
            "wire_d_mm": round(s.wire_d_mm, 4), "mean_d_mm": round(s.mean_d_mm, 4),
            "active_turns": round(s.active_turns, 4), "legs_mm": [sp.leg_radii_mm[0], sp.leg_radii_mm[1]],
            "hand": sp.hand, "rate_Nmm_per_deg": round(s.rate_nmm_per_deg, 6),
            "preload_deg": round(sp.deflection_deg[0], 4), "description": sp.description()}
    return list(rows.values())


def with_spring_rows(bom: Sequence[Mapping[str, Any]], springs: Sequence[PlacedSpring],
                     copies: int = 1) -> list[dict[str, Any]]:
    """The BOM with its rate-only spring rows replaced by the placed springs' designations (in place of the
    first such row, so the row order stays)."""
    out: list[dict[str, Any]] = []
    done = False
    for row in bom:
        if row.get("kind") == "spring":
            if not done:
                out += spring_bom_rows(springs, copies)
                done = True
            continue
        out.append(dict(row))
    if not done:
        out += spring_bom_rows(springs, copies)
    return out


def springs_report(springs: Sequence[PlacedSpring]) -> list[dict[str, Any]]:
    """JSON-ready springs (report.json's ``springs``)."""
    out = []
    for sp in springs:
        s = sp.spring
        out.append({
            "joint": sp.joint, "pin": sp.pin, "designation": sp.designation, "hand": sp.hand,
            "material": s.material, "wire_d_mm": s.wire_d_mm, "mean_d_mm": s.mean_d_mm, "outer_d_mm": s.outer_d_mm,
            "active_turns": s.active_turns, "legs_mm": list(sp.leg_radii_mm), "leg_axial_mm": list(sp.leg_axial_mm),
            "free_angle_deg": sp.free_angle_deg, "rate_Nmm_per_deg": s.rate_nmm_per_deg,
            "deflection_deg": list(sp.deflection_deg), "max_torque_Nmm": s.max_torque_nmm,
            "body_length_mm": s.body_length_wound_mm, "z_mm": list(sp.z_mm), "side": sp.side,
            "near": {"part": sp.near_part, "anchor": [float(v) for v in sp.near_anchor]},
            "far": {"part": sp.far_part, "anchor": [float(v) for v in sp.far_anchor]},
            "anchor_hole_mm": sp.anchor_hole_mm, "stress_MPa": s.stress_mpa, "allowable_MPa": s.allowable_mpa,
            "passed": sp.passed})
    return out


def spring_failures(springs: Sequence[PlacedSpring]) -> list[str]:
    """One line per spring whose wire is stressed beyond its allowable, or that the motion turns back past free
    (strength failures)."""
    out = []
    for sp in springs:
        if sp.passed:
            continue
        s = sp.spring
        if not sp.within_series or s.stress_mpa > s.allowable_mpa * (1.0 + 1e-9):
            why = "" if sp.within_series else " (no music wire of the series up to Ø3.18 mm holds it)"
            out.append(f"spring at {sp.joint} ({sp.designation}): wire stress {s.stress_mpa:.0f} MPa over its "
                       f"allowable {s.allowable_mpa:.0f} MPa at {sp.deflection_deg[1]:.1f}° deflection{why}")
        if sp.deflection_deg[0] < -1e-6:
            out.append(f"spring at {sp.joint} ({sp.designation}): the motion turns it {-sp.deflection_deg[0]:.1f}° "
                       "back past free (it would open against its winding); give it more preload")
    return out


def spring_sweep_items(springs: Sequence[PlacedSpring], chord_tolerance_mm: float) -> list[SweepItem]:
    """The springs as solids of the interference sweep.

    Each spring is four prisms: its coil (a ring from the wound inside to the free outside diameter over the
    wound body length) on the pin's body; the near leg's radial run along the face it sits on, on the near
    body; the far leg's radial run at the coil's far end and its axial run back to the far plate, on the far
    body. The coil's end bears on the plate it sits on (kind ``spacer``: touching is its job, an overlap is
    not); the legs share the anchor name with the coil (they are its wire: they touch it, never overlap).
    """
    from fabricate.checks.items import SweepItem

    items: list[SweepItem] = []
    tol = chord_tolerance_mm
    for sp in springs:
        s = sp.spring
        anchor = sp.anchor_joint
        ring = (circle_polygon(sp.centre, s.outer_d_mm, tol),
                circle_polygon(sp.centre, max(s.inner_d_wound_mm, s.pin_diameter_mm + 1e-3), tol, clockwise=True))
        # the coil bears on the plate it sits on, on its arbor and on its own legs: touching, never overlapping
        seats = [sp.pin, anchor] + ([f"arbor_{sp.pin}"] if sp.arbor else [])
        items.append(SweepItem(f"spring_{sp.joint}", sp.pin_body, "spacer", ring, sp.z_mm[0], sp.z_mm[1],
                               frozenset(seats), "", sp))
        d = s.wire_d_mm
        near_z = (sp.z_mm[0], sp.z_mm[0] + d) if sp.side == "top" else (sp.z_mm[1] - d, sp.z_mm[1])
        far_z = (sp.z_mm[1] - d, sp.z_mm[1]) if sp.side == "top" else (sp.z_mm[0], sp.z_mm[0] + d)
        r0 = 0.5 * s.outer_d_mm
        items.append(SweepItem(f"spring_{sp.joint}_leg_near", sp.near_body, "spring",
                               (_leg(sp.near_axis, sp.near_anchor, r0, d, tol),), near_z[0], near_z[1],
                               frozenset([anchor]), "", sp))
        items.append(SweepItem(f"spring_{sp.joint}_leg_far", sp.far_body, "spring",
                               (_leg(sp.far_axis, sp.far_anchor, r0, d, tol),), far_z[0], far_z[1],
                               frozenset([anchor]), "", sp))
        if sp.side == "top":
            run = (sp.z_mm[1] - sp.leg_axial_mm[1], sp.z_mm[1] - d)
        else:
            run = (sp.z_mm[0] + d, sp.z_mm[0] + sp.leg_axial_mm[1])
        items.append(SweepItem(f"spring_{sp.joint}_leg_far_axial", sp.far_body, "spring",
                               (circle_polygon(sp.far_anchor, d, tol),), run[0], run[1], frozenset([anchor]), "", sp))
    return items


def _leg(axis: np.ndarray, anchor: np.ndarray, r0: float, d: float, tol: float) -> np.ndarray:
    """A leg's radial run in plan: a stadium of the wire's width from the coil's outside to the anchor."""
    direction = np.asarray(anchor, dtype=np.float64) - axis
    length = float(np.hypot(*direction))
    u = direction / length
    start = axis + u * (r0 + 0.5 * d)  # its round start touches the coil's outside
    n = np.array([-u[1], u[0]])
    half = 0.5 * d
    arc = max(4, int(math.ceil(math.pi / (2.0 * math.acos(max(-1.0, 1.0 - tol / max(half, tol)))))))
    ang = np.linspace(-0.5 * math.pi, 0.5 * math.pi, arc + 1)
    end_cap = anchor + half * (np.outer(np.cos(ang), u) + np.outer(np.sin(ang), n))
    start_cap = start + half * (np.outer(np.cos(ang + math.pi), u) + np.outer(np.sin(ang + math.pi), n))
    return np.vstack([end_cap, start_cap])
