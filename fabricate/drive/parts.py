"""The actuator in the parts: its interface on the driven part, its mount on the ground, its solids.

:func:`attach_actuator` takes the parts of a design (a :class:`~fabricate.parts.build.PartSet`) and the
template's ``[actuator]`` and returns the parts with the actuator in them, its placement recorded as
:class:`PlacedActuator` (``PartSet.actuator``). It is the one step :func:`~fabricate.parts.build.build_parts`
calls after drawing the parts; without ``[actuator]`` nothing changes.

A rotary actuator (servo, gear motor, stepper) on an angle driver
    carries the driven body on its output: the driver joint's pin and its spacers go (from the pins, the
    spacers, the pin's printed parts and the BOM). The driven part gets the interface (a servo horn's screw
    holes and a bore over its hub, a bore pressed on a servo's spline where no horn is catalogued, or a
    shaft bore with its flats, :mod:`fabricate.drive.geometry`) and a pad round it; the ground part's hole
    there becomes a clearance for what passes through it (the horn, the shaft). The actuator sits under or
    over the stack, on the side where its output and body meet fewest parts, its body pointing away from
    what moves (:mod:`fabricate.drive.rotary`); a mount plate (part role ``"mount"``, the process's
    thickness) on its flange holds it, screwed to it, and stands on the ground part on standoffs (printed
    with an additive process, bought tubes for a cut one), fixed with screws whose clamp is the real stack
    (:mod:`fabricate.drive.mount`).
A tendon, push rod or linear actuator on a slide driver
    pulls or pushes the slider: the slider part gets a rod-end hole (a clevis pin, running fit) beyond the
    end of its guide slot, on the slide axis, on a pad fused to it.

The interference proof sees the actuator's body, its output and the screw heads as solids of kind
``"actuator"`` (:func:`sweep_items`): the output and the horn screws move with the driven body (fastened to
it: never checked against its own part), the body and the standoffs are fixed to the ground (checked
against every moving part, and against the ground's own parts for overlap).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
import shapely.ops

from fabricate.catalogue.hardware import ISO4762
from fabricate.drive import geometry as geo
from fabricate.errors import SpecError
from fabricate.mechanism import Driver, Mechanism, Motion, Slider
from fabricate.parts import model
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.profiles import circle_hull, fuse_polygons
from fabricate.planar import inverse_transform_points, rotation

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.checks.items import SweepItem
    from fabricate.drive.spec import ActuatorSpec
    from fabricate.parts.build import PartSet
    from fabricate.process import ProcessSpec

ROTARY = ("servo", "gearmotor", "stepper")
PUSHING = ("tendon", "linear")
#: Roles of the parts that are bodies' plates (the rest, spacers, caps and arbors, belong to a pin).
BODY_ROLES = ("link", "gear", "ground", "rod", "mount", "standoff")
#: Roles of solids that move with the driven body (the rest are fixed to the ground body).
DRIVEN_ROLES = ("output", "screw")
#: Name of the mount plate part.
MOUNT_PART = "actuator_mount"


@dataclass(frozen=True)
class Fastener:
    """Screws of one kind the actuator's assembly uses.

    Attributes
    ----------
    designation : str
        As a shop names it (``"ISO 4762 M2 × 5"``).
    qty : int
        Per copy of the mechanism.
    purpose : str
        What it fastens (for the BOM and the assembly guide).
    clamp_mm, engagement_mm : float
        The stack it clamps and the thread it engages.
    """

    designation: str
    qty: int
    purpose: str
    clamp_mm: float
    engagement_mm: float


@dataclass(frozen=True)
class Standoff:
    """A tube between the mount plate and the ground part, on one of the ground's mounting holes.

    Attributes
    ----------
    hole : str
        The ground's mounting hole it stands on.
    centre : (2,) array
        Its axis in the ground body's coordinates, mm.
    inner_diameter_mm, outer_diameter_mm, length_mm, z_mm : float
    printed : bool
        True: a printed part (``standoff_N``); False: a bought tube.
    """

    hole: str
    centre: np.ndarray
    inner_diameter_mm: float
    outer_diameter_mm: float
    length_mm: float
    z_mm: float
    printed: bool


@dataclass(frozen=True)
class PlacedActuator:
    """What :func:`attach_actuator` placed (``PartSet.actuator``).

    Attributes
    ----------
    model, name, kind : str
        The catalogue key, its name and kind (``"servo"``...).
    driver : int
        Index of the mechanism's driver it drives.
    driver_kind : str
        ``"angle"`` or ``"slide"``.
    joint : str
        The driver joint (a revolute for an angle driver, the slider for a slide driver).
    driven_body, ground_body : str
        The body its output moves, the body it is fixed to (the driver's reference).
    axis : (2,) array
        Angle driver: the output axis in the ground body's coordinates. Slide driver: the rod end's centre
        at the first pose in the ground body's coordinates.
    direction : (2,) array
        Slide driver: the slide axis (unit) in the ground body's coordinates; angle driver: the direction the
        actuator's body points in (away from what moves).
    angle : float
        Angle driver: the catalogue frame's x axis turned by this (rad) about the axis in the ground body's
        frame (:class:`fabricate.drive.geometry.Placement`); 0 for a slide driver.
    z_face : float
        Stack z of the actuator's output face (servo top, motor face), mm; for a slide driver the mid-plane
        of the slider part.
    flip : bool
        True when the actuator sits over the stack, its output pointing down.
    removed_pin : str
        The pin the output replaces ('' when none).
    interface : tuple of str
        The driven part's new holes and cuts (hole or slot names).
    mount_part : str
        The mount plate's part name ('' when there is none).
    fasteners : tuple of Fastener
    standoffs : tuple of Standoff
    solids : tuple of geometry.Solid
        Body, output, screw-head and bought-standoff solids (driven-body solids have role ``"output"`` or
        ``"screw"``; ground ones ``"body"`` or ``"standoff"``), in their body's coordinates.
    notes : tuple of str
        What the maker should know (a horn cut back, a round shaft to secure).
    """

    model: str
    name: str
    kind: str
    driver: int
    driver_kind: str
    joint: str
    driven_body: str
    ground_body: str
    axis: np.ndarray
    direction: np.ndarray
    angle: float
    z_face: float
    flip: bool
    removed_pin: str
    interface: tuple[str, ...]
    mount_part: str
    fasteners: tuple[Fastener, ...]
    standoffs: tuple[Standoff, ...]
    solids: tuple[geo.Solid, ...]
    notes: tuple[str, ...] = ()

    def report(self) -> dict[str, Any]:
        """JSON-ready summary (mm, degrees): what was placed where, and what fastens it."""
        return {
            "model": self.model, "name": self.name, "kind": self.kind, "driver": self.driver,
            "driver_kind": self.driver_kind, "joint": self.joint, "driven_body": self.driven_body,
            "ground_body": self.ground_body, "axis_mm": [round(float(v), 6) for v in self.axis],
            "direction": [round(float(v), 6) for v in self.direction], "angle_deg": round(math.degrees(self.angle), 6),
            "z_face_mm": round(self.z_face, 6), "side": "over" if self.flip else "under",
            "removed_pin": self.removed_pin or None, "interface": list(self.interface),
            "mount_part": self.mount_part or None,
            "fasteners": [{"designation": f.designation, "qty": f.qty, "purpose": f.purpose,
                           "clamp_mm": round(f.clamp_mm, 4), "engagement_mm": round(f.engagement_mm, 4)}
                          for f in self.fasteners],
            "standoffs": [{"hole": s.hole, "length_mm": round(s.length_mm, 4), "printed": s.printed}
                          for s in self.standoffs],
            "solids": [s.name for s in self.solids], "notes": list(self.notes),
        }

    def body_of(self, solid: geo.Solid) -> str:
        """The body a solid moves with."""
        return self.driven_body if solid.role in DRIVEN_ROLES else self.ground_body


# -- entry points --------------------------------------------------------------------------------------------
def attach_actuator(design: Any, mechanism: Mechanism, motion: Motion, partset: PartSet) -> PartSet:
    """The parts with the design's ``[actuator]`` in them (unchanged when the design names none).

    Raises
    ------
    SpecError
        ``actuator.driver`` names no driver of the mechanism; the actuator's kind does not suit the driver's
        (``actuator.model``); the driver joint is a compound hinge, or a shaft too short for the stack.
    """
    spec: ActuatorSpec | None = getattr(design, "actuator", None)
    if spec is None:
        return partset
    entry = spec.entry()
    if spec.driver >= len(mechanism.drivers):
        raise SpecError("actuator.driver", f"driver {spec.driver}: the mechanism has {len(mechanism.drivers)} "
                                           f"driver(s) (0..{len(mechanism.drivers) - 1})")
    driver = mechanism.drivers[spec.driver]
    if driver.kind == "angle" and entry.kind in ROTARY:
        from fabricate.drive.rotary import RotaryPlacement  # it builds on this module's records and helpers

        return RotaryPlacement(design, mechanism, motion, partset, entry, spec.driver, driver).attach()
    if driver.kind == "slide" and entry.kind in PUSHING:
        return _attach_rod_end(design, mechanism, motion, partset, entry, spec.driver, driver)
    want = "a servo, gear motor or stepper" if driver.kind == "angle" else "a tendon, push rod or linear actuator"
    raise SpecError("actuator.model", f"{entry.key!r} ({entry.kind}) cannot drive driver {spec.driver}, a "
                                      f"{driver.kind} driver of {driver.body!r}: it takes {want}")


def sweep_items(partset: Any) -> list[SweepItem]:
    """The actuator's solids as interference-sweep items of kind ``"actuator"`` (none without an actuator)."""
    from fabricate.checks.items import SweepItem

    placed: PlacedActuator | None = getattr(partset, "actuator", None)
    if placed is None:
        return []
    return [SweepItem(s.name, placed.body_of(s), "actuator", s.rings, s.z0, s.z1, frozenset([placed.joint])
                      if s.role == "output" else frozenset(), "", s)
            for s in placed.solids]


# -- shared helpers ------------------------------------------------------------------------------------------
def fit_hole(joint: str, centre: np.ndarray, nominal_mm: float, compensation_mm: float, pin_mm: float = 0.0,
          fit: str = "clearance") -> Hole:
    """A hole of nominal (fit) size ``nominal_mm``, modelled with the process's compensation added. A screw's
    pilot hole (``fit="tapped"``) is labelled a clearance while the part model has no such fit."""
    return Hole(joint, np.asarray(centre, dtype=np.float64), nominal_mm + compensation_mm, pin_mm,
                fit if fit in model.HOLE_FITS else "clearance", nominal_mm)


def with_changes(part: Part, **changes: Any) -> Part:
    """A copy of ``part`` with ``changes``; ``slots`` turns a plain part into a slotted one."""
    from fabricate.parts.build import SlottedPart

    if "slots" in changes and not isinstance(part, SlottedPart):
        base = {f.name: getattr(part, f.name) for f in dataclasses.fields(Part)}
        base.update(changes)
        return SlottedPart(**base)
    return dataclasses.replace(part, **changes)


#: The fused outline's chords lie inside its arcs by at most the chord tolerance / this: walls measured on it
#: (the printability check) lose next to nothing against the exact outline.
FUSE_REFINE = 10.0


def fuse_pad(outline: BulgePath, pad: BulgePath, tol: float) -> BulgePath:
    """The outline with a pad fused on (kept exact when the pad lies inside already)."""
    fine = tol / FUSE_REFINE
    inside = shapely.Polygon(outline.polygon(tol)).buffer(1e-9).contains(shapely.Polygon(pad.polygon(tol)))
    return outline if inside else fuse_polygons(outline, [pad.polygon(fine)], fine)


def body_part(partset: PartSet, body: str) -> Part:
    for p in partset.parts:
        if p.body == body and p.role not in ("spacer", "mount", "standoff"):
            return p
    raise SpecError("actuator.driver", f"body {body!r} has no part")


def screw_size(d_mm: float) -> str:
    """The ISO 4762 size of nominal diameter ``d_mm``, else the largest below it."""
    sizes = sorted(ISO4762, key=lambda s: float(s.lstrip("M")))
    fits = [s for s in sizes if float(s.lstrip("M")) <= d_mm + 1e-9]
    return fits[-1] if fits else sizes[0]


def bom_without(bom: Sequence[dict[str, Any]], pin: Any, spacers: Sequence[Any], removed_parts: set[str],
                 changed: Sequence[Part], process: ProcessSpec, copies: int) -> list[dict[str, Any]]:
    """The BOM without one pin's hardware (the rows the parts layer makes for it and its ``spacers``, taken
    out of the grouped rows by item) and the removed parts, with the changed parts' rows renewed."""
    from fabricate.hints import PartHints
    from fabricate.parts.bom import bill_of_materials, part_rows

    fresh = {row["item"]: row for row in part_rows(list(changed), process, copies)}
    gone: dict[tuple[str, str], int] = {}
    if pin is not None:
        for row in bill_of_materials([pin], list(spacers), PartHints(), process, copies):
            key = (str(row["item"]), str(row["kind"]))
            gone[key] = gone.get(key, 0) + int(row["qty"])
    out = []
    for row in bom:
        item = str(row.get("item", ""))
        if item in removed_parts:
            continue
        if item in fresh:
            out.append(dict(fresh[item], **{k: v for k, v in row.items() if k not in fresh[item]}))
            continue
        key = (item, str(row.get("kind", "")))
        if key in gone:
            take = min(gone.pop(key), int(row.get("qty", 0)))
            joints = [j for j in row.get("joints", []) or [] if j != pin.joint]
            row = dict(row, qty=int(row["qty"]) - take, joints=joints)
            if row["qty"] <= 0:
                continue
        out.append(row)
    return out


def purchased_row(item: str, qty: int, description: str, **extra: Any) -> dict[str, Any]:
    return {"item": item, "kind": "purchased", "qty": qty, "joints": [], "description": description,
            "source": "buy", **extra}


def screw_row(f: Fastener, copies: int) -> dict[str, Any]:
    return {"item": f.designation, "designation": f.designation, "kind": "screw", "qty": f.qty * copies,
            "joints": [], "source": "buy",
            "description": f.purpose, "clamp_mm": round(f.clamp_mm, 4), "engagement_mm": round(f.engagement_mm, 4)}


# -- tendon, push rod or linear actuator on a slide driver -----------------------------------------------------
def _attach_rod_end(design: Any, mechanism: Mechanism, motion: Motion, ps: PartSet, entry: Actuator, index: int,
                    driver: Driver) -> PartSet:
    """A clevis hole on the slider part, on the slide axis past its guide slot's free end."""
    process: ProcessSpec = design.process
    tol = float(ps.chord_tolerance_mm)
    slider = next((j for j in mechanism.joints if isinstance(j, Slider) and j.name == driver.joint), None)
    if slider is None:
        raise SpecError("actuator.driver", f"the slide driver names no slider ({driver.joint!r})")
    rod = body_part(ps, slider.body_b)
    axis_a = np.asarray(slider.axis, dtype=np.float64)
    axis_a = axis_a / np.hypot(*axis_a)
    axis_b = rotation(-slider.angle) @ axis_a
    pin_mm = float(process.pin_diameter_mm)
    c, comp, wall = float(process.running_clearance_mm), float(process.hole_compensation_mm), float(process.min_wall_mm)
    hole_nominal = pin_mm + 2.0 * c
    body = mechanism.body(slider.body_b)
    line = body.point(slider.name)
    cuts = [s.polygon(tol) for s in getattr(rod, "slots", ())]
    material = np.concatenate(cuts) if cuts else line[None, :]
    others = [body.point(p) for p in body.points if p != slider.name]
    best: tuple[float, np.ndarray] | None = None
    for sign in (1.0, -1.0):
        u = sign * axis_b
        extent = float(np.max((material - line) @ u)) + (tol if cuts else 0.0)  # chords lie inside the arcs
        centre = line + u * (max(extent, 0.0) + wall + 0.5 * (hole_nominal + comp))
        score = min((float(np.hypot(*(centre - o))) for o in others), default=math.inf)
        if best is None or score > best[0] + 1e-9:
            best = (score, centre)
    assert best is not None
    centre = best[1]
    r = 0.5 * (hole_nominal + comp) + wall
    pad = circle_hull(np.array([line, centre]), np.array([r, r]))
    hole = fit_hole("actuator_rod_end", centre, hole_nominal, comp, pin_mm, fit="running")
    new_rod = with_changes(rod, outline=fuse_pad(rod.outline, pad, tol), holes=tuple(rod.holes) + (hole,))
    parts = tuple(new_rod if p is rod else p for p in ps.parts)
    bom = bom_without(ps.bom, None, (), set(), [new_rod], process, ps.copies)
    what = "tendon or push rod" if entry.kind == "tendon" else entry.name
    bom.append(purchased_row(what, ps.copies, f"{entry.kind} pulling or pushing {slider.body_b} along {slider.name}, "
                                          f"on a Ø{pin_mm:g} mm clevis pin in its rod-end hole", model=entry.key))
    base = motion.pose(slider.body_a)[0]
    world = motion.pose(slider.body_b)[0]
    at_ground = inverse_transform_points(base, (rotation(world[2]) @ centre + world[:2])[None, :])[0]
    from fabricate.parts.build import overlapping_cuts

    warnings = tuple(ps.warnings) + tuple(w for w in overlapping_cuts([new_rod]) if w not in ps.warnings)
    record = PlacedActuator(
        model=entry.key, name=entry.name, kind=entry.kind, driver=index, driver_kind="slide", joint=slider.name,
        driven_body=slider.body_b, ground_body=slider.body_a, axis=at_ground, direction=axis_a, angle=0.0,
        z_face=float(rod.z_mm + 0.5 * rod.thickness_mm), flip=False, removed_pin="", interface=("actuator_rod_end",),
        mount_part="", fasteners=(), standoffs=(), solids=(),
        notes=(f"the {what} acts along the slide axis on a Ø{pin_mm:g} mm pin in the rod-end hole",))
    return dataclasses.replace(ps, parts=parts, bom=bom, warnings=warnings, actuator=record)
