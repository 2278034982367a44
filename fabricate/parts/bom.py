"""Pins, spacers and the bill of materials.

A pin at a joint passes through the layers of the two bodies it joins; its stack runs from the bottom of
the lower layer to the top of the upper one. Layers in between that the pin skips are filled by a spacer
tube (so the bodies cannot slide along the pin); the axial gap between adjacent layers takes a washer.
:func:`pins_and_spacers` sizes the stacks; :func:`fabricate.parts.retention.retain_pins` then makes every pin
a standard one (its length from the ISO 8734 / ISO 2338 series, at or above the stack plus what its
retention needs) and every washer a standard one (DIN 125-A / DIN 988 / ISO 8738).

The BOM names hardware as a shop does (``designation``: ``ISO 8734 2 × 20``, ``DIN 125-A 2.2``,
``ISO 4762 M3 × 12``, ``DIN 6799 1.2``), counts it over all copies, and says for every row whether it is
printed, cut or bought (``source``: ``print``, ``cut``, ``buy``).
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
        Nominal diameter; length of the pin (the stack's, until
        :func:`~fabricate.parts.retention.retain_pins` makes it a standard pin).
    z_mm : float
        Bottom of the pin.
    layers : (int, int)
        Lowest and highest layer it passes through.
    designation : str
        The standard pin (``"ISO 8734 2 × 20"``); '' before retention.
    stack_mm : float
        Length of the stack of parts and spacers it passes (0 before retention: ``length_mm`` is the stack).
    stack_z_mm : (float, float)
        Bottom and top of that stack.
    retention : str
        ``press``, ``clip`` or ``cap`` (the process profile's).
    holder : str
        The body whose part the pin is pressed into (``press``), else ''.
    allowance_mm : float
        Pin length the retention needs beyond the stack (both ends together).
    protrusion_mm : (float, float)
        Pin beyond the stack at its bottom and top (negative: pressed in short of the holder's face).
    end_items : (tuple of str, tuple of str)
        Designations of what goes on the bottom and top ends (washers, then the clip).
    engagement_mm : float
        Length pressed into the holder (``press``).
    grooves_mm : tuple of float
        Clip grooves to cut: distance of each groove's lower edge from the pin's bottom end.
    caps_mm : (float, float)
        Length of the bonded end caps (``cap``).
    note : str
        Why the pin is not a standard one (cut from rod), else ''.
    """

    joint: str
    bodies: tuple[str, ...]
    diameter_mm: float
    length_mm: float
    z_mm: float
    layers: tuple[int, int]
    designation: str = ""
    stack_mm: float = 0.0
    stack_z_mm: tuple[float, float] = (0.0, 0.0)
    retention: str = ""
    holder: str = ""
    allowance_mm: float = 0.0
    protrusion_mm: tuple[float, float] = (0.0, 0.0)
    end_items: tuple[tuple[str, ...], tuple[str, ...]] = ((), ())
    engagement_mm: float = 0.0
    grooves_mm: tuple[float, ...] = ()
    caps_mm: tuple[float, float] = (0.0, 0.0)
    note: str = ""


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
        The layer below it (-1 below the bottom layer: an item on the pin's bottom end).
    washer : bool
        True when it is not a tube: a washer in the gap between adjacent layers, or a washer or clip on the
        pin's end.
    kind : str
        ``tube`` (printed or bought), ``washer`` or ``clip``; '' before retention.
    designation : str
        The standard item (``"DIN 125-A 2.2"``, ``"DIN 6799 1.2"``); '' for a tube.
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
    kind: str = ""
    designation: str = ""


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


def _pin_note(pin: Pin) -> str:
    """How a pin is fitted, for the BOM's description."""
    if pin.note:
        return f"steel pin, {pin.note}"
    if pin.retention == "press":
        where = (f"pressed {pin.engagement_mm:.3g} mm into {pin.holder}, short of its face"
                 if min(pin.protrusion_mm) < 0 else f"pressed into {pin.holder}")
        return f"steel dowel pin, {where}, runs in the other parts"
    if pin.retention == "clip":
        grooves = ", ".join(f"{g:.2f}" for g in pin.grooves_mm)
        return (f"steel dowel pin (unhardened, to groove), runs in every part; DIN 6799 clip at both ends in "
                f"grooves cut {grooves} mm from its bottom end")
    if pin.retention == "cap":
        return "steel dowel pin, runs in every part; a cap bonded onto each end"
    return "steel dowel pin, cut to the stack"


def bill_of_materials(pins: Sequence[Pin], spacers: Sequence[Spacer], hints: PartHints,
                      process: ProcessSpec, copies: int = 1, mounting: int = 0,
                      mounting_mm: float = 3.0, ground_thickness_mm: float | None = None) -> list[dict[str, Any]]:
    """Bill of materials rows (JSON-ready), quantities over all ``copies``.

    Rows have ``item``, ``designation`` (the standard item, where there is one), ``kind`` (``pin``,
    ``spacer``, ``washer``, ``clip``, ``spring``, ``screw``, ``purchased``), ``source`` (``buy`` for all of
    these), ``qty``, a human ``description`` and the sizes in mm where they apply. An additive process prints
    its spacer tubes with the parts (they are part rows, see :func:`part_rows`); a cut process buys them.

    Mounting screws (``mounting`` of them, size M``mounting_mm``) are ISO 4762 screws with an ISO 7089
    washer under the head, through ``ground_thickness_mm`` of ground plate into a tapped base with
    :data:`MOUNT_ENGAGEMENT` × d of thread engaged; their length is the standard one that reaches.
    """
    rows: list[dict[str, Any]] = []
    for pin in pins:
        name = pin.designation or f"pin {pin.diameter_mm:g} x {pin.length_mm:.2f} mm"
        row = {"item": name, "kind": "pin", "source": "buy",
               "diameter_mm": round(pin.diameter_mm, 4), "length_mm": round(pin.length_mm, 4),
               "qty": copies, "joints": [pin.joint], "description": _pin_note(pin)}
        if pin.designation:
            row["designation"] = pin.designation
        rows.append(row)
    for sp in spacers:
        kind = sp.kind or ("washer" if sp.washer else "spacer")
        if kind in ("spacer", "tube") and process.technique == "additive":
            continue  # printed with the parts: a part row of its own (see part_rows)
        if sp.designation:
            row = {"item": sp.designation, "designation": sp.designation, "kind": kind}
        else:
            label = "spacer" if kind in ("spacer", "tube") else kind
            row = {"item": f"{label} {sp.inner_diameter_mm:g}/{sp.outer_diameter_mm:g} x {sp.length_mm:.2f} mm",
                   "kind": "spacer" if kind == "tube" else kind}
        row.update({"source": "buy", "inner_diameter_mm": round(sp.inner_diameter_mm, 4),
                    "outer_diameter_mm": round(sp.outer_diameter_mm, 4), "length_mm": round(sp.length_mm, 4),
                    "qty": copies, "joints": [sp.joint],
                    "description": ("retaining washer (E-clip) in the pin's groove" if kind == "clip" else
                                    "tube cut to length" if kind in ("spacer", "tube") else "washer")})
        rows.append(row)
    rows = _group(rows, ("item", "kind"))
    if mounting:
        rows += mounting_rows([f"mount_{k + 1}" for k in range(mounting)], mounting_mm,
                              ground_thickness_mm or process.thickness_mm, copies)
    for spring in hints.springs:
        if spring.rate_Nmm_per_deg <= 0.0:
            continue  # a zero rate means no spring there (the compliant optimum has k1 = 0)
        rows.append({"item": f"torsion spring at {spring.joint}", "kind": "spring", "source": "buy",
                     "qty": copies, "joints": [spring.joint], "rate_Nmm_per_deg": spring.rate_Nmm_per_deg,
                     "preload_deg": spring.preload_deg, "legs_mm": spring.legs_mm, "description": spring.note})
    for item in hints.purchased:
        rows.append({"item": item.item, "kind": "purchased", "source": "buy", "qty": item.qty * copies,
                     "joints": [], "description": item.note})
    # items shared by all copies (one drive for a three-finger gripper) are not multiplied
    for item in hints.purchased_shared:
        rows.append({"item": item.item, "kind": "purchased", "source": "buy", "qty": item.qty, "joints": [],
                     "description": item.note, "shared": True})
    return rows


#: Thread engaged by a mounting screw in the user's tapped base, in screw diameters: 1.5 d, the usual
#: minimum in aluminium (steel takes 1 d); the screw's length follows from it and the clamped stack.
MOUNT_ENGAGEMENT = 1.5


def mounting_rows(holes: Sequence[str], size_mm: float, plate_mm: float, copies: int = 1) -> list[dict[str, Any]]:
    """BOM rows of the mounting screws in the ground's ``holes`` and the washers under their heads (see
    :func:`bill_of_materials`).

    Raises
    ------
    SpecError
        No standard screw or washer of the size (``parts.mounting_hole_mm``).
    """
    from fabricate.catalogue.hardware import screw, washer
    from fabricate.errors import SpecError

    size, count = f"M{size_mm:g}", len(holes)
    try:
        under = washer(size)
        chosen = screw(size, plate_mm + under.h_mm, MOUNT_ENGAGEMENT * size_mm)
    except SpecError as exc:
        raise SpecError("parts.mounting_hole_mm", f"mounting screws {size}: {exc.message}") from None
    name = under.alt_designation or under.designation
    return [
        {"item": chosen.designation, "designation": chosen.designation, "kind": "screw", "source": "buy",
         "diameter_mm": size_mm, "length_mm": chosen.length_mm, "qty": count * copies, "joints": sorted(holes),
         "description": (f"mounting screw for the ground part: clamps {chosen.clamp_mm:g} mm (plate and washer), "
                         f"engages {chosen.engagement_mm:g} mm of thread in a tapped base (at least "
                         f"{MOUNT_ENGAGEMENT:g} × d = {MOUNT_ENGAGEMENT * size_mm:g} mm)")},
        {"item": name, "designation": name, "kind": "washer", "source": "buy", "inner_diameter_mm": under.d1_mm,
         "outer_diameter_mm": under.d2_mm, "length_mm": under.h_mm, "qty": count * copies, "joints": sorted(holes),
         "description": "washer under a mounting screw's head"},
    ]


def with_sources(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The rows with a ``source`` each: ``print`` (printed part), ``cut`` (cut part), else ``buy``, where a row
    does not state one (rows made elsewhere, such as the springs' and the actuator's)."""
    out = []
    for row in rows:
        row = dict(row)
        if "source" not in row:
            kind = str(row.get("kind", ""))
            row["source"] = "print" if kind == "printed part" else "cut" if kind == "cut part" else "buy"
        out.append(row)
    return out


def part_rows(parts: Sequence[Part], process: ProcessSpec, copies: int = 1) -> list[dict[str, Any]]:
    """One BOM row per printed or cut part: process, material, quantity (all copies), volume and mass.

    Mass is the exact volume (profile area x thickness, mm^3) times the profile's density (g/cm^3).
    """
    kind = "cut part" if process.technique == "cut" else "printed part"
    rows = []
    for part in parts:
        volume = float(part.volume_mm3())
        rows.append({"item": part.name, "kind": kind, "source": "cut" if process.technique == "cut" else "print",
                     "qty": copies, "process": process.name,
                     "material": _material_name(process), "thickness_mm": round(float(part.thickness_mm), 4),
                     "volume_mm3": round(volume, 4), "mass_g": round(volume * process.density_g_cm3 / 1000.0, 6),
                     "joints": sorted({h.joint for h in part.holes}),
                     "description": f"{part.role} part, {_material_name(process) or process.name}"})
    return rows


def _material_name(process: ProcessSpec) -> str:
    """The part material for people: the profile material's name, else its key."""
    material: Material | None = process.part_material()
    return material.name if material is not None else process.material
