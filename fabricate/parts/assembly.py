"""How the parts go together: the stack on every pin from end to end, and the numbered assembly guide.

Pure functions of a :class:`~fabricate.parts.build.PartSet`: each pin passes through the parts of the
bodies it joins, with a spacer (a printed or purchased tube) or a washer between consecutive layers, and
a torsion spring on its extension where the joint has one (:mod:`fabricate.parts.springs`). The guide
(:func:`assembly_guide`) is a list of steps a person follows; :mod:`fabricate.export.guide` writes it as
assembly.md and draws a picture per step. Nothing here draws or writes.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fabricate.parts.partset import PartSet


@dataclass(frozen=True)
class StackItem:
    """One thing on a pin, bottom to top.

    Attributes
    ----------
    item : str
        Part name, or the spacer / washer's BOM item, or the spring's designation.
    kind : str
        ``part``, ``spacer``, ``washer``, ``clip`` (a retainer on the pin's end) or ``spring`` (beyond the stack).
    z_mm : (float, float)
        Bottom and top along the pin (mm, the assembly's z).
    note : str
        How it sits on the pin where that is not through a hole (``in its slot``: a slider's guide); the item
        stays the BOM's name.
    """

    item: str
    kind: str
    z_mm: tuple[float, float]
    note: str = ""

    @property
    def label(self) -> str:
        """The item as the guide's text names it: with its note in brackets."""
        return f"{self.item} ({self.note})" if self.note else self.item


@dataclass(frozen=True)
class PinStack:
    """A pin and what it carries, bottom to top."""

    pin: str
    diameter_mm: float
    length_mm: float
    z_mm: float
    items: tuple[StackItem, ...]


def _joints(pin_name: str) -> set[str]:
    # a compound pin's holes carry its whole name ("G1+G1r"); its joints are the parts of the name
    return set(pin_name.split("+")) | {pin_name}


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
            if part.role == "arbor" and not any(h.joint == f"arbor_{pin.joint}" for h in part.holes):
                continue  # a spring's arbor on another pin of the same plate
            # a pin through a body passes its hole, or rides in its slot (a slider's guide)
            on_hole = any(h.joint in joints for h in part.holes)
            if not on_hole and part.role in ("mount", "standoff"):
                continue  # the drive's mount plate and standoffs sit on the ground's screws, not on its pins
            note = "" if on_hole or not getattr(part, "slots", ()) else "in its slot"
            items.append(StackItem(part.name, "part", (round(part.z_mm, 6), round(part.z_mm + part.thickness_mm, 6)),
                                   note))
        printed = {round(part.z_mm, 6): part.name for part in partset.parts
                   if part.role == "spacer" and any(h.joint in joints for h in part.holes)}
        for spacer in partset.spacers:
            if spacer.joint != pin.joint:
                continue
            # the retention's kind where it gives one (a clip on the pin's end), else washer or spacer tube
            kind = {"clip": "clip", "washer": "washer"}.get(getattr(spacer, "kind", ""),
                                                            "washer" if spacer.washer else "spacer")
            z = (round(spacer.z_mm, 6), round(spacer.z_mm + spacer.length_mm, 6))
            # a spacer printed with the parts goes by its part name; a bought one by its standard designation,
            # else its size
            printed_name = printed.get(z[0]) if not spacer.washer else None
            size = f"{spacer.inner_diameter_mm:g}/{spacer.outer_diameter_mm:g} x {spacer.length_mm:.2f} mm"
            name = printed_name or getattr(spacer, "designation", "") or f"{kind} {size}"
            items.append(StackItem(name, kind, z))
        for spring in getattr(partset, "springs", ()) or ():
            if spring.pin == pin.joint:
                items.append(StackItem(spring.designation, "spring", (spring.z_mm[0], spring.z_mm[1])))
        items.sort(key=lambda s: (s.z_mm[0], s.z_mm[1], s.label))
        stacks.append(PinStack(pin.joint, float(pin.diameter_mm), float(pin.length_mm), float(pin.z_mm),
                               tuple(items)))
    return stacks


def assembly_steps(stacks: list[PinStack], copies: int = 1) -> list[str]:
    """Numbered steps for people: one per pin, the ground's pins first, each stack bottom to top."""
    steps = []
    for k, stack in enumerate(stacks, start=1):
        order = ", ".join(f"{s.label} ({s.kind}, z {s.z_mm[0]:.2f}–{s.z_mm[1]:.2f} mm)" if s.kind != "part"
                          else f"{s.label} (z {s.z_mm[0]:.2f}–{s.z_mm[1]:.2f} mm)" for s in stack.items)
        steps.append(f"{k}. Pin {stack.pin} (Ø{stack.diameter_mm:g} × {stack.length_mm:.2f} mm, from z "
                     f"{stack.z_mm:.2f} mm): slide on, bottom to top: {order}; then retain the pin.")
    if copies > 1:
        steps.append(f"{len(stacks) + 1}. Repeat steps 1–{len(stacks)} for each of the {copies} copies.")
    return steps


def stacks_report(stacks: list[PinStack]) -> list[dict[str, Any]]:
    """JSON-ready stacks for report.json (``assembly.pins``)."""
    return [{"pin": s.pin, "diameter_mm": s.diameter_mm, "length_mm": round(s.length_mm, 6),
             "z_mm": round(s.z_mm, 6),
             "stack": [{"item": i.label, "kind": i.kind, "z_mm": list(i.z_mm)} for i in s.items]} for s in stacks]


# -- the assembly guide (assembly.md): numbered steps a person follows ------------------------------------

#: Hex key across flats (mm) of socket head cap screws ISO 4762 and button head screws ISO 7380, by thread.
#: ISO 4762 table "s" and ISO 7380-1 table "s" as fastener makers print them (e.g. Würth, Bossard catalogues).
HEX_KEY_MM = {"ISO 4762": {"M2": 1.5, "M2.5": 2.0, "M3": 2.5, "M4": 3.0, "M5": 4.0, "M6": 5.0},
              "ISO 7380": {"M3": 2.0, "M4": 2.5, "M5": 3.0, "M6": 4.0}}
#: Words that mark a BOM row as the drive's (the actuator step takes it).
DRIVE_WORDS = ("actuator", "servo", "motor", "stepper", "horn", "tendon", "push rod", "lead screw", "lead-screw",
               "mount plate", "standoff")


@dataclass(frozen=True)
class MotionCheck:
    """What the final step of the guide checks: the input range and the tip's path.

    Attributes
    ----------
    input_range : (float, float)
        The driver's range, in ``unit``.
    unit : str
        ``deg`` or ``mm``.
    tip : str
        The tip point's name ('' when the design has none).
    tip_start, tip_end : (float, float) or None
        The tip at the first and the last pose (ground frame, mm).
    min_clearance_mm : float or None
        The interference proof's smallest clearance between moving parts.
    """

    input_range: tuple[float, float]
    unit: str = "deg"
    tip: str = ""
    tip_start: tuple[float, float] | None = None
    tip_end: tuple[float, float] | None = None
    min_clearance_mm: float | None = None


@dataclass(frozen=True)
class GuideItem:
    """Part or hardware fitted in a step: the BOM row's item and how many (per copy, or in all if shared)."""

    item: str
    kind: str
    qty: int
    shared: bool = False


@dataclass(frozen=True)
class GuideStep:
    """One numbered step of the assembly guide.

    Attributes
    ----------
    number : int
    title : str
    items : tuple of GuideItem
        Every BOM unit this step fits (the guide lists each unit of the BOM once per copy).
    text : tuple of str
        What to do, in order.
    tool : str
    placed : tuple of str
        Part names in place after this step (for its picture).
    new : tuple of str
        Part names this step adds (highlighted in its picture).
    pins : tuple of str
        Pins in place after this step; ``new_pins`` those this step adds.
    springs : tuple of str
        Spring joints in place after this step; ``new_springs`` those this step adds.
    actuator, new_actuator : bool
        Whether the actuator is in place after this step; whether this step mounts it.
    """

    number: int
    title: str
    items: tuple[GuideItem, ...]
    text: tuple[str, ...]
    tool: str
    placed: tuple[str, ...] = ()
    new: tuple[str, ...] = ()
    pins: tuple[str, ...] = ()
    new_pins: tuple[str, ...] = ()
    springs: tuple[str, ...] = ()
    new_springs: tuple[str, ...] = ()
    actuator: bool = False
    new_actuator: bool = False

    @property
    def picture(self) -> str:
        """Its picture's path in the output folder."""
        return f"assembly/step_{self.number:02d}.png"


def _words(obj: Any, *names: str) -> str:
    """The first of ``names`` that ``obj`` has as a non-empty attribute (or key), as text."""
    for name in names:
        value = obj.get(name) if isinstance(obj, dict) else getattr(obj, name, None)
        if value:
            return str(value)
    return ""


def _pin_words(pin: Any) -> str:
    """A pin as a shop names it (the parts layer's designation where it gives one)."""
    return _words(pin, "designation") or f"pin Ø{float(pin.diameter_mm):g} × {float(pin.length_mm):.2f} mm"


def _retention(pin: Any) -> tuple[str, str]:
    """How the pin is held (the parts layer's retention: ``press``, ``clip`` or ``cap``) and the tool for it."""
    scheme = str(getattr(pin, "retention", "") or "")
    ends = getattr(pin, "end_items", ((), ()))
    on_ends = "; ".join(f"{where}: {' + '.join(items)}" for where, items in zip(("bottom", "top"), ends, strict=False)
                        if items)
    if scheme == "press":
        bottom, top = (float(v) for v in getattr(pin, "protrusion_mm", (0.0, 0.0)))
        # the standard length's extra stands out of one face as a bare stub (parts/retention.py), flush at the other
        ends = ("flush with both faces" if max(bottom, top) <= 1e-9 else
                f"flush with the {'top' if bottom > top else 'bottom'} face, {max(bottom, top):.2f} mm out of the "
                f"{'bottom' if bottom > top else 'top'}")
        text = (f"press the pin into {getattr(pin, 'holder', '') or 'the part that holds it'} "
                f"({float(getattr(pin, 'engagement_mm', 0.0)):.3g} mm engaged, {ends})"
                "; it runs free in the other parts")
        return text, "bench vice or arbor press (press the pin in square, supporting the part round the hole)"
    if scheme == "clip":
        grooves = ", ".join(f"{g:.2f}" for g in getattr(pin, "grooves_mm", ()))
        text = (f"the pin runs in every part; clips in its grooves ({grooves} mm from its bottom end)"
                + (f", on its ends {on_ends}" if on_ends else ""))
        return text, "E-clip pliers or a flat screwdriver (to push each clip into its groove)"
    if scheme == "cap":
        return ("the pin runs in every part; bond its printed end caps onto both ends with retaining adhesive",
                "retaining adhesive, pin punch")
    return "retain the pin: a drop of retaining adhesive where it leaves the outer plates", "pin punch"


def _screw_tool(rows: Sequence[dict[str, Any]]) -> str:
    """The hex keys the screws of ``rows`` take (ISO 4762 / ISO 7380 by thread), smallest first."""
    keys = set()
    for row in rows:
        item = f"{row.get('item', '')} "
        for standard, sizes in HEX_KEY_MM.items():
            if standard in item:
                thread = next((t for t in sorted(sizes, key=len, reverse=True)
                               if re.search(rf"\b{re.escape(t)}\s*[×x ]", item)), None)
                if thread:
                    keys.add(sizes[thread])
    if not keys:
        return "screwdriver or hex key to suit the screws"
    return " and ".join(f"{k:g} mm hex key" for k in sorted(keys))


def _is_drive(row: dict[str, Any], actuator_words: str) -> bool:
    text = f"{row.get('item', '')} {row.get('description', '')} {row.get('role', '')}".lower()
    if row.get("kind") == "actuator" or (actuator_words and actuator_words.lower() in text):
        return True
    if "mounting screw for the ground part" in text:
        return False
    return any(word in text for word in DRIVE_WORDS)


def _actuator_words(actuator: Any) -> str:
    """The placed actuator's name for people ('' when there is none)."""
    if actuator is None:
        return ""
    entry = next((getattr(actuator, n) for n in ("entry", "actuator", "catalogue") if getattr(actuator, n, None)),
                 actuator)
    return _words(entry, "name", "model", "key") or _words(actuator, "name", "model", "key")


@dataclass(frozen=True)
class _GuideFacts:
    """What the guide reads from a part set, looked up once: the steps below take it as their input."""

    partset: PartSet
    rows: list[dict[str, Any]]
    copies: int
    by_name: dict[str, Any]
    stack_of: dict[str, PinStack]
    springs: dict[str, Any]
    actuator: Any
    act_words: str
    ground: list[str]

    @classmethod
    def of(cls, partset: PartSet, stacks: Sequence[PinStack]) -> _GuideFacts:
        actuator = getattr(partset, "actuator", None)
        return cls(partset, [dict(r) for r in partset.bom], max(int(partset.copies), 1),
                   {p.name: p for p in partset.parts}, {s.pin: s for s in stacks},
                   {sp.pin: sp for sp in getattr(partset, "springs", ()) or ()}, actuator,
                   _actuator_words(actuator), [p.name for p in partset.parts if p.role == "ground"])

    @property
    def ground_bodies(self) -> set[str]:
        return {self.by_name[n].body for n in self.ground}


@dataclass
class _GuideSteps:
    """The guide as it grows: each step takes its BOM units from ``units`` and records what is in place."""

    units: dict[str, list[GuideItem]]
    steps: list[GuideStep] = dataclasses.field(default_factory=list)
    placed: list[str] = dataclasses.field(default_factory=list)
    pins_in: list[str] = dataclasses.field(default_factory=list)
    springs_in: list[str] = dataclasses.field(default_factory=list)
    mounted: bool = False

    def add(self, key: str, title: str, text: Sequence[str], tool: str, new: Sequence[str] = (),
            new_pins: Sequence[str] = (), new_springs: Sequence[str] = (), new_actuator: bool = False) -> None:
        self.placed.extend(n for n in new if n not in self.placed)
        self.pins_in.extend(new_pins)
        self.springs_in.extend(new_springs)
        self.mounted = self.mounted or new_actuator
        self.steps.append(GuideStep(len(self.steps) + 1, title, tuple(self.units.pop(key, [])), tuple(text), tool,
                                    tuple(self.placed), tuple(new), tuple(self.pins_in), tuple(new_pins),
                                    tuple(self.springs_in), tuple(new_springs), self.mounted, new_actuator))


def assembly_guide(partset: PartSet, stacks: Sequence[PinStack], check: MotionCheck) -> tuple[GuideStep, ...]:
    """The numbered assembly guide of one part set (pure: no drawing, no files).

    Steps: the ground part with its mounting screws; one step per pin (the bodies reached from those already
    placed first), each followed by its spring where it carries one; the actuator; the other bought items; for
    several copies a repeat step and the items shared by all copies; a final check of the motion. Every unit
    of every BOM row is fitted in exactly one step (per copy; shared rows in all): the quantities the steps
    list add up to the BOM's.
    """
    facts = _GuideFacts.of(partset, stacks)
    order = _pin_order(facts)
    part_step = _part_steps(facts, order)
    guide = _GuideSteps(_deal_units(facts, part_step))
    _ground_step(guide, facts, part_step)
    for pin in order:
        _pin_steps(guide, facts, pin, part_step)
    _drive_step(guide, facts, part_step)
    _bought_steps(guide, facts.copies)
    _check_step(guide, check, bool(facts.springs))
    return tuple(guide.steps)


def _pin_order(facts: _GuideFacts) -> list[Any]:
    """The pins in the order they go in: from what is placed, outwards (ties: the part set's order)."""
    order: list[Any] = []
    reached = set(facts.ground_bodies)
    left = list(facts.partset.pins)
    while left:
        nxt = next((p for p in left if reached & set(p.bodies)), left[0])
        left.remove(nxt)
        order.append(nxt)
        reached |= set(nxt.bodies)
    return order


def _part_steps(facts: _GuideFacts, order: Sequence[Any]) -> dict[str, str]:
    """Which step each part comes in: its body's first pin (the ground first); a printed spacer with its pin."""
    part_step: dict[str, str] = {n: "ground" for n in facts.ground}
    seen_bodies = set(facts.ground_bodies)
    parts = facts.partset.parts
    for pin in order:
        stack = facts.stack_of.get(pin.joint)
        for item in stack.items if stack else ():
            if item.kind == "spacer" and item.item in facts.by_name:
                part_step.setdefault(item.item, f"pin:{pin.joint}")
        for body in pin.bodies:
            if body in seen_bodies:
                continue
            seen_bodies.add(body)
            for part in parts:
                if part.body == body and part.role not in ("spacer", "mount", "standoff", "arbor", "cap"):
                    part_step.setdefault(part.name, f"pin:{pin.joint}")
    for sp in facts.springs.values():
        if sp.arbor:
            part_step[sp.arbor] = f"spring:{sp.pin}"  # the coil's arbor goes on with the coil
    for part in parts:
        if part.role == "cap":  # a pin's bonded end cap, with its pin
            joint = next((h.joint for h in part.holes if h.joint in facts.stack_of), "")
            if joint:
                part_step.setdefault(part.name, f"pin:{joint}")
        part_step.setdefault(part.name, "drive" if part.role in ("mount", "standoff") else "ground")
    return part_step


def _deal_units(facts: _GuideFacts, part_step: dict[str, str]) -> dict[str, list[GuideItem]]:
    """Every BOM unit to one step: ``{step key: [GuideItem]}``.

    Step keys: "ground", "pin:<pin>", "spring:<pin>", "drive", "purchased", "shared drive", "shared", "check".
    """
    units: dict[str, list[GuideItem]] = {}

    def give(key: str, row: dict[str, Any], qty: int, shared: bool) -> None:
        if qty > 0:
            units.setdefault(key, []).append(GuideItem(str(row.get("item")), str(row.get("kind", "")), qty, shared))

    pins = facts.partset.pins
    stack_of, springs, act_words = facts.stack_of, facts.springs, facts.act_words
    pin_of_joint = {j: p.joint for p in pins for j in p.joint.split("+")} | {p.joint: p.joint for p in pins}
    for row in facts.rows:
        qty = int(row.get("qty", 0) or 0)
        shared = bool(row.get("shared")) or qty % facts.copies != 0
        per = qty if shared else qty // facts.copies
        kind = str(row.get("kind", ""))
        name = str(row.get("item", ""))
        joints = [pin_of_joint[j] for j in row.get("joints", []) or [] if j in pin_of_joint]
        if name in facts.by_name and kind not in ("pin", "washer", "spacer", "spring", "screw", "purchased"):
            give(part_step[name], row, per, shared)
        elif kind == "spring" and joints:
            _round_robin(give, [f"spring:{j}" if j in springs else f"pin:{j}" for j in joints], row, per, shared)
        elif joints and not _is_drive(row, act_words):
            # as many to each pin as its stack holds (washers, clips by designation); the rest dealt in turn
            held = {j: sum(i.item == name for i in stack_of[j].items) if j in stack_of else 0 for j in joints}
            _round_robin(give, [f"pin:{j}" for j in joints], row, per, shared,
                         [held[j] for j in joints] if kind not in ("pin",) else None)
        elif _is_drive(row, act_words):
            give("shared drive" if shared else "drive", row, per, shared)
        elif kind == "screw" or (row.get("joints") and all(str(j).startswith("mount_") for j in row["joints"])):
            give("ground", row, per, shared)  # the ground's mounting screws and their washers
        else:
            give("shared" if shared else "purchased", row, per, shared)
    return units


def _ground_step(guide: _GuideSteps, facts: _GuideFacts, part_step: dict[str, str]) -> None:
    """Step 1: the ground part, with its mounting screws."""
    new_ground = [n for n, k in part_step.items() if k == "ground"]
    screws = [r for r in facts.rows if r.get("kind") == "screw" and not _is_drive(r, facts.act_words)]
    text = [f"Lay {', '.join(new_ground) or 'the ground part'} flat on the bench, bottom face down (the z heights "
            "below are measured up from the bottom of the stack)."]
    if screws:
        text.append("Fix it to the base plate or the test stand with the screws below through its mounting holes; "
                    "do not tighten fully until the motion check.")
    guide.add("ground", "The ground part", text, _screw_tool(screws) if screws else "none", new_ground)


def _pin_steps(guide: _GuideSteps, facts: _GuideFacts, pin: Any, part_step: dict[str, str]) -> None:
    """A pin's step (its stack, bottom to top, and its retention), then its torsion spring's where it has one."""
    stack = facts.stack_of.get(pin.joint)
    new = [n for n, k in part_step.items() if k == f"pin:{pin.joint}"]
    arbors = {sp.arbor for sp in facts.springs.values()}
    on = [i for i in (stack.items if stack else ()) if i.kind != "spring" and i.item not in arbors]
    listing = "; ".join(f"{i.label} ({i.kind}, z {i.z_mm[0]:.2f}–{i.z_mm[1]:.2f} mm)" if i.kind != "part"
                        else f"{i.label} (z {i.z_mm[0]:.2f}–{i.z_mm[1]:.2f} mm)" for i in on)
    retention, tool = _retention(pin)
    spring = facts.springs.get(pin.joint)
    text = [f"Stack, bottom to top: {listing}.",
            f"Push {_pin_words(pin)} through the stack from z {float(pin.z_mm):.2f} mm; every part "
            "but the one that holds the pin must turn freely on it."]
    clip_over_coil = spring is not None and getattr(pin, "retention", "") == "clip" and not spring.arbor
    if clip_over_coil and spring is not None:
        text.append(f"Retention: {retention}. Fit the {'bottom' if spring.side == 'top' else 'top'} end's now; "
                    f"the {spring.side} end's go on over the torsion spring in the next step.")
    else:
        text.append(f"Retention: {retention}.")
        if spring is not None:
            text.append(f"The torsion spring goes on the pin's {spring.side} end in the next step.")
    guide.add(f"pin:{pin.joint}", f"Pin {pin.joint}", text, tool, new, new_pins=(pin.joint,))
    if spring is not None:
        guide.add(f"spring:{pin.joint}", f"Torsion spring at {spring.joint}", _spring_text(spring, clip_over_coil),
                  "long-nose pliers (to wind and place the legs)",
                  [n for n, k in part_step.items() if k == f"spring:{pin.joint}"], new_springs=(spring.joint,))


def _spring_text(spring: Any, clip_over_coil: bool) -> list[str]:
    """How to fit a torsion spring: the coil over its seat, the near leg hooked, the far leg wound and placed."""
    s = spring.spring
    upper = 1.0 if spring.hand == "RH" else -1.0
    far_turn = upper if spring.side == "top" else -upper
    way = "counter-clockwise" if far_turn > 0 else "clockwise"
    seat = (f"the arbor {spring.arbor} (bond it to {spring.near_part}'s face round the pin's {spring.side} "
            "end first, with retaining adhesive)" if spring.arbor else f"the pin's {spring.side} end")
    return [f"Slide the coil ({spring.hand} wound, Ø{s.wire_d_mm:.2f} mm wire, OD {s.outer_d_mm:.2f} mm) "
            f"over {seat} until it sits on {spring.near_part}.",
            f"Hook the near leg's bent end into the anchor hole in {spring.near_part} "
            f"(Ø{spring.anchor_hole_mm:.2f} mm, {spring.leg_radii_mm[0]:g} mm from the pin).",
            f"Wind the far leg {spring.deflection_deg[0]:.0f}° {way} (seen from above) and drop its end into "
            f"the anchor hole in {spring.far_part} ({spring.leg_radii_mm[1]:g} mm from the pin; the leg's "
            f"end runs {spring.leg_axial_mm[1]:.1f} mm along the pin to it).",
            "Fit the pin's end items over the coil now: its clip keeps the spring on the pin." if clip_over_coil
            else "The legs' ends in their anchor holes keep the coil in place."]


def _drive_step(guide: _GuideSteps, facts: _GuideFacts, part_step: dict[str, str]) -> None:
    """The actuator's step (its mount parts, the actuator and its screws), where the design has a drive."""
    actuator, act_words = facts.actuator, facts.act_words
    drive_parts = [n for n, k in part_step.items() if k == "drive"]
    if not (actuator is not None or "drive" in guide.units or drive_parts):
        return
    words = act_words or "the actuator"
    text = []
    if drive_parts:
        text.append(f"Fit {', '.join(drive_parts)} to the ground part.")
    driven = _words(actuator, "driven_body", "driven", "body") if actuator is not None else ""
    mount = _words(actuator, "ground_body", "ground") if actuator is not None else ""
    text.append(f"Mount {words}{' on ' + mount if mount else ''} with its screws; couple its output to "
                f"{driven or 'the driven part'} at the middle of its range before tightening the interface.")
    text += [str(note) for note in getattr(actuator, "notes", ()) or ()]
    drive_screws = [r for r in facts.rows if r.get("kind") == "screw" and _is_drive(r, act_words)]
    guide.add("drive", "The actuator", text, _screw_tool(drive_screws), drive_parts,
              new_actuator=actuator is not None)


def _bought_steps(guide: _GuideSteps, copies: int) -> None:
    """The other bought parts of each copy; for several copies the repeat step and the parts shared by all."""
    units = guide.units
    if "purchased" in units:
        guide.add("purchased", "Bought parts of each copy", ["Fit the bought parts below as their descriptions in "
                                                             "the bill of materials say."], "as the parts need")
    if copies > 1:
        last = len(guide.steps)
        guide.add("repeat", "The other copies", [f"Repeat steps 1–{last} for each of the {copies} copies."],
                  "as above")
    if "shared drive" in units or "shared" in units:
        units.setdefault("shared", []).extend(units.pop("shared drive", []))
        guide.add("shared", "Parts shared by all copies", [f"These are bought once for all {copies} copies: fit "
                                                           "them as their descriptions in the bill of materials "
                                                           "say."], "as the parts need")


def _check_step(guide: _GuideSteps, check: MotionCheck, has_springs: bool) -> None:
    """The last step, the motion check (after a step for any BOM row the rules above did not place)."""
    a, b = check.input_range
    text = [f"Move the input by hand through its whole range, {a:.4g} to {b:.4g} {check.unit}, slowly, and back."]
    if check.tip and check.tip_start and check.tip_end:
        text.append(f"Watch the tip point {check.tip}: it should go from ({check.tip_start[0]:.1f}, "
                    f"{check.tip_start[1]:.1f}) mm to ({check.tip_end[0]:.1f}, {check.tip_end[1]:.1f}) mm along "
                    "the path of previews/motion.gif.")
    text.append("Feel for an even effort: no tight spot, no knock, no part rubbing another" +
                (f" (the smallest designed clearance between moving parts is {check.min_clearance_mm:.2f} mm)"
                 if check.min_clearance_mm is not None else "") + ".")
    if has_springs:
        text.append("Let go at the end of the range: the springs must bring it back to the start.")
    text.append("Then tighten the screws, power the actuator and run the same range.")
    leftover = [item for key in list(guide.units) for item in guide.units.pop(key)]
    if leftover:  # a row the rules above did not place: still listed once
        guide.add("ground", "Other parts", ["Fit these as their descriptions in the bill of materials say."],
                  "as the parts need")
        guide.steps[-1] = dataclasses.replace(guide.steps[-1], items=tuple(leftover))
    guide.add("check", "Check the motion", text, "none (by hand), then the actuator's controller")


def _round_robin(give: Any, keys: Sequence[str], row: dict[str, Any], qty: int, shared: bool,
                 held: Sequence[int] | None = None) -> None:
    """Deal a row's units to its pins' steps: first what each pin's stack holds of it (``held``, in the
    row's joint order, as far as the units go), then the rest one at a time in turn."""
    counts = dict.fromkeys(keys, 0)
    left = qty
    for key, n in zip(keys, held or (), strict=False):
        take = min(n, left)
        counts[key] += take
        left -= take
    for k in range(left):
        counts[keys[k % len(keys)]] += 1
    for key, n in counts.items():
        give(key, row, n, shared)


def guide_report(steps: Sequence[GuideStep]) -> list[dict[str, Any]]:
    """JSON-ready steps (report.json's ``assembly.guide``)."""
    return [{"step": s.number, "title": s.title, "text": list(s.text), "tool": s.tool,
             "items": [{"item": i.item, "kind": i.kind, "qty": i.qty, "shared": i.shared} for i in s.items],
             "new_parts": list(s.new), "new_pins": list(s.new_pins), "new_springs": list(s.new_springs),
             "new_actuator": s.new_actuator, "picture": s.picture} for s in steps]
