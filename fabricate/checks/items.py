"""The solids of the interference sweep (:mod:`fabricate.checks.interference`) and how two of them relate.

A :class:`SweepItem` is one prism in its body's frame: a part, a pin (:class:`PinSolid`), a spacer (tube or
washer) or an actuator's solid. The constructors here turn the parts layer's records into items
(:func:`part_items`, :func:`pin_items`, :func:`spacer_items`, pins from the holes or from the parts layer's
pins); :func:`item_relation` names what two items are to each other (rigid, fixed, bearing, meshing, pin,
joined or moving), which decides what the sweep allows between them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import SpecError
from fabricate.parts.model import Part, circle_polygon

if TYPE_CHECKING:
    from fabricate.parts.bom import Pin, Spacer
    from fabricate.parts.model import Hole


@dataclass(frozen=True)
class PinSolid:
    """A pin: a cylinder fixed in ``body`` through the holes of joint ``joint``.

    Attributes
    ----------
    name, joint, body : str
    centre : (2,) array
        Axis position in the body's coordinates, mm.
    diameter_mm, z_mm, length_mm : float
        Diameter, height of its lower end and length, mm.
    """

    name: str
    joint: str
    body: str
    centre: np.ndarray
    diameter_mm: float
    z_mm: float
    length_mm: float


@dataclass(frozen=True)
class SweepItem:
    """One solid of the sweep in its body's frame: a part, a pin, a spacer or an actuator's solid."""

    name: str
    body: str
    # "part", "pin", "spacer" (a tube or washer on a pin) or "actuator" (an actuator's body, output, screw
    # head or mount standoff, :func:`fabricate.drive.parts.sweep_items`; its source's ``role`` says which)
    kind: str
    rings: tuple[np.ndarray, ...]   # outer CCW then holes CW, mm, body frame
    z0: float
    z1: float
    joints: frozenset[str]          # joints of its holes (parts) or its own joint (pins)
    gear: str = ""
    # what the item was made of, read by kind: the Part, the PinSolid or the parts layer's Spacer
    source: Any = field(default=None, compare=False, repr=False)


def part_items(parts: Sequence[Part], chord_tolerance_mm: float) -> list[SweepItem]:
    """Sweep items of parts (their polygons at the chord tolerance)."""
    return [SweepItem(p.name, p.body, "part", tuple(p.polygons(chord_tolerance_mm)), float(p.z_mm),
                      float(p.z_mm + p.thickness_mm), frozenset(h.joint for h in p.holes), p.gear, p)
            for p in parts]


def pins_from_holes(parts: Sequence[Part]) -> list[PinSolid]:
    """One pin per joint whose holes take a pin: through every part with that joint's hole, fixed in
    the body of the lowest of them, diameter the holes' nominal pin diameter."""
    by_joint: dict[str, list[tuple[Part, Hole]]] = {}
    for p in parts:
        for h in p.holes:
            if h.pin_diameter_mm > 0:
                by_joint.setdefault(h.joint, []).append((p, h))
    pins = []
    for joint, members in by_joint.items():
        if len({p.body for p, _ in members}) < 2:
            continue  # a hole with no partner on another body is a mounting hole
        members.sort(key=lambda m: (m[0].z_mm, m[0].name))
        base, hole = members[0]
        z0 = min(p.z_mm for p, _ in members)
        z1 = max(p.z_mm + p.thickness_mm for p, _ in members)
        pins.append(PinSolid(f"pin_{joint}", joint, base.body, np.asarray(hole.centre, dtype=np.float64),
                             float(hole.pin_diameter_mm), float(z0), float(z1 - z0)))
    return pins


def pins_from_parts_layer(pins: Sequence[PinSolid | Pin], parts: Sequence[Part]) -> list[PinSolid]:
    """PinSolids from the parts layer's pins (``joint``, ``bodies``, ``diameter_mm``, ``length_mm``,
    ``z_mm``): each fixed in the first of its bodies, on the axis of that body's hole for the joint.
    Objects that already are :class:`PinSolid` pass through."""
    out = []
    for pin in pins:
        if isinstance(pin, PinSolid):
            out.append(pin)
            continue
        body = pin.bodies[0]
        hole = next((h for p in parts if p.body == body for h in p.holes if h.joint == pin.joint), None)
        if hole is None:
            continue
        out.append(PinSolid(f"pin_{pin.joint}", pin.joint, body, np.asarray(hole.centre, dtype=np.float64),
                            float(pin.diameter_mm), float(pin.z_mm), float(pin.length_mm)))
    return out


def require_positive(path: str, value: float) -> None:
    # a zero pin has no outline (the distance kernel's bounding box is empty) and a negative one is a
    # mirrored circle: neither is a solid, so say which field is wrong instead of checking nonsense
    if not (math.isfinite(value) and value > 0.0):
        raise SpecError(path, f"must be a finite number > 0, got {value!r}")


def pin_items(pins: Sequence[PinSolid], chord_tolerance_mm: float) -> list[SweepItem]:
    for p in pins:
        require_positive(f"pins.{p.name}.diameter_mm", float(p.diameter_mm))
        require_positive(f"pins.{p.name}.length_mm", float(p.length_mm))
    return [SweepItem(p.name, p.body, "pin",
                      (circle_polygon(p.centre, p.diameter_mm, chord_tolerance_mm),),
                      float(p.z_mm), float(p.z_mm + p.length_mm), frozenset([p.joint]), "", p)
            for p in pins]


def spacer_items(spacers: Sequence[Spacer], parts: Sequence[Part], chord_tolerance_mm: float) -> list[SweepItem]:
    """Tubes and washers of the parts layer (``joint``, ``body``, ``centre``, ``inner_diameter_mm``,
    ``outer_diameter_mm``, ``z_mm``, ``length_mm``) as rings; those already modelled as spacer parts
    (a part of role ``"spacer"`` on that body with a hole for the joint) are not repeated."""
    modelled = {(p.body, h.joint) for p in parts if p.role == "spacer" for h in p.holes}
    out: list[SweepItem] = []
    for k, sp in enumerate(spacers):
        if (sp.body, sp.joint) in modelled or sp.length_mm <= 0.0:
            continue
        require_positive(f"spacers[{k}].inner_diameter_mm", float(sp.inner_diameter_mm))
        if not float(sp.outer_diameter_mm) > float(sp.inner_diameter_mm):
            raise SpecError(f"spacers[{k}].outer_diameter_mm",
                            f"must exceed inner_diameter_mm ({sp.inner_diameter_mm!r}), got {sp.outer_diameter_mm!r}")
        centre = np.asarray(sp.centre, dtype=np.float64)
        rings = (circle_polygon(centre, sp.outer_diameter_mm, chord_tolerance_mm),
                 circle_polygon(centre, sp.inner_diameter_mm, chord_tolerance_mm, clockwise=True))
        name = f"{'washer' if getattr(sp, 'washer', False) else 'tube'}_{sp.joint}"
        if any(it.name == name for it in out):
            name = f"{name}_{k}"
        out.append(SweepItem(name, sp.body, "spacer", rings, float(sp.z_mm), float(sp.z_mm + sp.length_mm),
                             frozenset([sp.joint]), "", sp))
    return out


def item_relation(a: SweepItem, b: SweepItem) -> str:
    if a.body == b.body:
        # an actuator's body (or a standoff of its mount) is fixed to a body's parts, not part of them: it
        # may bear on them, it must not cut into them; its output and the horn screws are fastened to the
        # part they drive, and an actuator's own solids are one purchased piece
        fixed = [is_fixed_actuator(it) for it in (a, b)]
        if any(fixed) and "actuator" in (a.kind, b.kind) and not (a.kind == b.kind == "actuator"):
            return "fixed"
        return "rigid"
    roles = {getattr(it.source, "role", "") for it in (a, b)}
    if a.kind == b.kind == "actuator" and roles == {"output", "body"}:
        # the output turns in the actuator's own bearing, on its face: touching is its job
        return "bearing"
    if a.kind == "part" and b.kind == "part" and a.gear and a.gear == b.gear:
        return "meshing"
    if a.joints & b.joints:
        if "pin" in (a.kind, b.kind):
            return "pin"
        # a spacer on a pin bears on the parts of that joint: touching is its job
        return "bearing" if is_spacer(a) or is_spacer(b) else "joined"
    # a spacer's end faces sit flush on the layer faces around it: whatever else is flush there
    # slides on the end face (touching), it does not cut into it
    z_gap = max(a.z0, b.z0) - min(a.z1, b.z1)
    if (is_spacer(a) or is_spacer(b)) and abs(z_gap) < 1e-9:
        return "bearing"
    return "moving"


def is_fixed_actuator(item: SweepItem) -> bool:
    """An actuator solid fixed to its body's parts rather than fastened into them (body, standoff, screw
    head on the mount): see :data:`fabricate.drive.parts.DRIVEN_ROLES` for the others."""
    return item.kind == "actuator" and getattr(item.source, "role", "") not in ("output", "screw")


def is_spacer(item: SweepItem) -> bool:
    return item.kind == "spacer" or getattr(item.source, "role", "") == "spacer"
