"""How the parts go together: the stack on every pin from end to end, and numbered assembly steps.

Pure functions of a :class:`~fabricate.parts.build.PartSet`: each pin passes through the parts of the
bodies it joins, with a spacer (a printed or purchased tube) or a washer between consecutive layers.
Nothing here draws or writes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fabricate.parts.build import PartSet


@dataclass(frozen=True)
class StackItem:
    """One thing on a pin, bottom to top.

    Attributes
    ----------
    item : str
        Part name, or the spacer / washer's BOM item.
    kind : str
        ``part``, ``spacer`` or ``washer``.
    z_mm : (float, float)
        Bottom and top along the pin (mm, the assembly's z).
    """

    item: str
    kind: str
    z_mm: tuple[float, float]


@dataclass(frozen=True)
class PinStack:
    """A pin and what it carries, bottom to top."""

    pin: str
    diameter_mm: float
    length_mm: float
    z_mm: float
    items: tuple[StackItem, ...]


def _joints(pin_name: str) -> set[str]:
    return set(pin_name.split("+"))


def pin_stacks(partset: PartSet) -> list[PinStack]:
    """The stack on every pin of a part set, bottom to top, in the part set's pin order.

    A body part is on a pin when the pin joins its body (through a hole at one of the pin's joints, or in
    the part's slot for a slider); spacers and washers come from the part set (one between each pair of
    joined layers).
    """
    stacks = []
    for pin in partset.pins:
        joints = _joints(pin.joint)
        items = []
        for part in partset.parts:
            if part.role == "spacer" or part.body not in pin.bodies:
                continue
            # a pin through a body passes its hole, or rides in its slot (a slider's guide)
            on_hole = any(h.joint in joints for h in part.holes)
            name = part.name if on_hole or not getattr(part, "slots", ()) else f"{part.name} (in its slot)"
            items.append(StackItem(name, "part", (round(part.z_mm, 6), round(part.z_mm + part.thickness_mm, 6))))
        printed = {round(part.z_mm, 6): part.name for part in partset.parts
                   if part.role == "spacer" and any(h.joint in joints for h in part.holes)}
        for spacer in partset.spacers:
            if spacer.joint != pin.joint:
                continue
            kind = "washer" if spacer.washer else "spacer"
            z = (round(spacer.z_mm, 6), round(spacer.z_mm + spacer.length_mm, 6))
            # a spacer printed with the parts goes by its part name; a bought one by its size
            printed_name = printed.get(z[0]) if not spacer.washer else None
            size = f"{spacer.inner_diameter_mm:g}/{spacer.outer_diameter_mm:g} x {spacer.length_mm:.2f} mm"
            name = printed_name or f"{kind} {size}"
            items.append(StackItem(name, kind, z))
        items.sort(key=lambda s: (s.z_mm[0], s.z_mm[1], s.item))
        stacks.append(PinStack(pin.joint, float(pin.diameter_mm), float(pin.length_mm), float(pin.z_mm),
                               tuple(items)))
    return stacks


def assembly_steps(stacks: list[PinStack], copies: int = 1) -> list[str]:
    """Numbered steps for people: one per pin, the ground's pins first, each stack bottom to top."""
    steps = []
    for k, stack in enumerate(stacks, start=1):
        order = ", ".join(f"{s.item} ({s.kind}, z {s.z_mm[0]:.2f}–{s.z_mm[1]:.2f} mm)" if s.kind != "part"
                          else f"{s.item} (z {s.z_mm[0]:.2f}–{s.z_mm[1]:.2f} mm)" for s in stack.items)
        steps.append(f"{k}. Pin {stack.pin} (Ø{stack.diameter_mm:g} × {stack.length_mm:.2f} mm, from z "
                     f"{stack.z_mm:.2f} mm): slide on, bottom to top: {order}; then retain the pin.")
    if copies > 1:
        steps.append(f"{len(stacks) + 1}. Repeat steps 1–{len(stacks)} for each of the {copies} copies.")
    return steps


def stacks_report(stacks: list[PinStack]) -> list[dict[str, Any]]:
    """JSON-ready stacks for report.json (``assembly.pins``)."""
    return [{"pin": s.pin, "diameter_mm": s.diameter_mm, "length_mm": round(s.length_mm, 6),
             "z_mm": round(s.z_mm, 6),
             "stack": [{"item": i.item, "kind": i.kind, "z_mm": list(i.z_mm)} for i in s.items]} for s in stacks]
