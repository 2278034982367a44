"""Pins, spacers and the bill of materials.

A pin at a joint passes through the layers of the two bodies it joins; its length is the stack from the
bottom of the lower layer to the top of the upper one. Layers in between that the pin skips are filled
by a spacer tube (so the bodies cannot slide along the pin); the axial gap between adjacent layers is a
washer.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.hints import PartHints
from fabricate.parts.layers import layer_z, skipped_gap, stack_span
from fabricate.process import Material, ProcessSpec

if TYPE_CHECKING:
    from fabricate.parts.model import Part


@dataclass(frozen=True)
class Pin:
    """A pin at a joint.

    Attributes
    ----------
    joint : str
        Pin name (joint names joined by ``+`` for a compound hinge).
    bodies : tuple of str
        Bodies it passes through; the first holds it.
    diameter_mm, length_mm : float
        Nominal diameter; length of the stack it passes through.
    z_mm : float
        Bottom of the stack.
    layers : (int, int)
        Lowest and highest layer it passes through.
    """

    joint: str
    bodies: tuple[str, ...]
    diameter_mm: float
    length_mm: float
    z_mm: float
    layers: tuple[int, int]


@dataclass(frozen=True)
class Spacer:
    """A tube on a pin between two non-adjacent layers (or a washer between adjacent ones).

    Attributes
    ----------
    joint : str
    body : str
        Body whose coordinates ``centre`` is given in (the body holding the pin).
    centre : (2,) array
    inner_diameter_mm, outer_diameter_mm, length_mm, z_mm : float
    lower_layer : int
    washer : bool
        True when it only fills the gap between adjacent layers.
    """

    joint: str
    body: str
    centre: np.ndarray
    inner_diameter_mm: float
    outer_diameter_mm: float
    length_mm: float
    z_mm: float
    lower_layer: int
    washer: bool


def pins_and_spacers(pin_joints: Sequence[tuple[str, tuple[str, ...]]], layers: Mapping[str, int],
                     pin_mm: float, hole_mm: float, boss_mm: float, thickness_mm: float, gap_mm: float,
                     centres: Mapping[tuple[str, str], np.ndarray] | None = None
                     ) -> tuple[list[Pin], list[Spacer]]:
    """Pins sized to their stacks and the spacers / washers between the layers they join.

    Parameters
    ----------
    pin_joints : sequence of (pin name, bodies)
        Each pin and the bodies it passes through; the first body holds it (and has its hole).
    layers : Mapping[str, int]
        Body -> layer.
    pin_mm, hole_mm, boss_mm : float
        Pin, hole and boss diameters (the spacer's bore and outer diameter).
    thickness_mm, gap_mm : float
        Layer thickness and axial gap.
    centres : Mapping[(body, pin), (2,) array], optional
        Pin positions in body coordinates (spacers are placed in the first body's coordinates).

    Returns
    -------
    (list of Pin, list of Spacer)
        One spacer (or washer) between each pair of consecutive layers the pin joins.
    """
    pins: list[Pin] = []
    spacers: list[Spacer] = []
    for name, bodies in pin_joints:
        occupied = sorted({layers[b] for b in bodies})
        z0, z1 = stack_span(occupied, thickness_mm, gap_mm)
        pins.append(Pin(joint=name, bodies=tuple(bodies), diameter_mm=pin_mm, length_mm=z1 - z0, z_mm=z0,
                        layers=(occupied[0], occupied[-1])))
        centre = np.asarray((centres or {}).get((bodies[0], name), np.zeros(2)), dtype=np.float64)
        for lo, hi in zip(occupied[:-1], occupied[1:], strict=True):
            length = skipped_gap(lo, hi, thickness_mm, gap_mm)
            if length <= 0.0:
                continue
            spacers.append(Spacer(joint=name, body=bodies[0], centre=centre, inner_diameter_mm=hole_mm,
                                  outer_diameter_mm=boss_mm, length_mm=length,
                                  z_mm=layer_z(lo, thickness_mm, gap_mm) + thickness_mm, lower_layer=lo,
                                  washer=hi - lo == 1))
    return pins, spacers


def _group(rows: list[dict[str, Any]], key: tuple[str, ...]) -> list[dict[str, Any]]:
    """Merge rows with equal ``key`` fields, summing ``qty`` and collecting ``joints``."""
    merged: dict[tuple[Any, ...], dict[str, Any]] = {}
    for row in rows:
        k = tuple(row[f] for f in key)
        if k in merged:
            merged[k]["qty"] += row["qty"]
            merged[k]["joints"] = sorted(set(merged[k]["joints"]) | set(row.get("joints", [])))
        else:
            merged[k] = dict(row)
    return list(merged.values())


def bill_of_materials(pins: Sequence[Pin], spacers: Sequence[Spacer], hints: PartHints,
                      process: ProcessSpec, copies: int = 1, mounting: int = 0,
                      mounting_mm: float = 3.0) -> list[dict[str, Any]]:
    """Bill of materials rows (JSON-ready), quantities multiplied by ``copies``.

    Rows have ``item``, ``kind`` (``pin``, ``spacer``, ``washer``, ``spring``, ``screw``, ``purchased``),
    ``qty``, a human ``description`` and the sizes in mm where they apply. An additive process prints its
    spacers with the parts (they are part rows, see :func:`part_rows`); a cut process buys them.
    """
    rows: list[dict[str, Any]] = []
    for pin in pins:
        rows.append({"item": f"pin {pin.diameter_mm:g} x {pin.length_mm:.2f} mm", "kind": "pin",
                     "diameter_mm": round(pin.diameter_mm, 4), "length_mm": round(pin.length_mm, 4),
                     "qty": copies, "joints": [pin.joint],
                     "description": "steel dowel pin, cut to the stack; retain with adhesive or clips"})
    for sp in spacers:
        kind = "washer" if sp.washer else "spacer"
        if not sp.washer and process.technique == "additive":
            continue  # printed with the parts: a part row of its own (see part_rows)
        made = "purchased"
        rows.append({"item": f"{kind} {sp.inner_diameter_mm:g}/{sp.outer_diameter_mm:g} x {sp.length_mm:.2f} mm",
                     "kind": kind, "inner_diameter_mm": round(sp.inner_diameter_mm, 4),
                     "outer_diameter_mm": round(sp.outer_diameter_mm, 4), "length_mm": round(sp.length_mm, 4),
                     "qty": copies, "joints": [sp.joint], "description": made})
    rows = _group(rows, ("item", "kind"))
    if mounting:
        rows.append({"item": f"screw M{mounting_mm:g}", "kind": "screw", "qty": mounting * copies,
                     "joints": [], "description": "mounting screw for the ground part"})
    for spring in hints.springs:
        if spring.rate_Nmm_per_deg <= 0.0:
            continue  # a zero rate means no spring there (the compliant optimum has k1 = 0)
        rows.append({"item": f"torsion spring at {spring.joint}", "kind": "spring",
                     "qty": copies, "joints": [spring.joint], "rate_Nmm_per_deg": spring.rate_Nmm_per_deg,
                     "preload_deg": spring.preload_deg, "legs_mm": spring.legs_mm, "description": spring.note})
    for item in hints.purchased:
        rows.append({"item": item.item, "kind": "purchased", "qty": item.qty * copies, "joints": [],
                     "description": item.note})
    # items shared by all copies (one drive for a three-finger gripper) are not multiplied
    for item in hints.purchased_shared:
        rows.append({"item": item.item, "kind": "purchased", "qty": item.qty, "joints": [],
                     "description": item.note, "shared": True})
    return rows


def part_rows(parts: Sequence[Part], process: ProcessSpec, copies: int = 1) -> list[dict[str, Any]]:
    """One BOM row per printed or cut part: process, material, quantity (all copies), volume and mass.

    Mass is the exact volume (profile area x thickness, mm^3) times the profile's density (g/cm^3).
    """
    kind = "cut part" if process.technique == "cut" else "printed part"
    rows = []
    for part in parts:
        volume = float(part.volume_mm3())
        rows.append({"item": part.name, "kind": kind, "qty": copies, "process": process.name,
                     "material": _material_name(process), "thickness_mm": round(float(part.thickness_mm), 4),
                     "volume_mm3": round(volume, 4), "mass_g": round(volume * process.density_g_cm3 / 1000.0, 6),
                     "joints": sorted({h.joint for h in part.holes}),
                     "description": f"{part.role} part, {_material_name(process) or process.name}"})
    return rows


def _material_name(process: ProcessSpec) -> str:
    """The part material for people: the profile material's name, else its key."""
    material: Material | None = process.part_material()
    return material.name if material is not None else process.material
