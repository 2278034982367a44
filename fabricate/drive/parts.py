"""The actuator in the parts: its interface on the driven part, its mount on the ground, its solids.

:func:`attach_actuator` takes the parts of a design (a :class:`~fabricate.parts.build.PartSet`) and the
template's ``[actuator]`` and returns the parts with the actuator in them, its placement recorded as
:class:`PlacedActuator` (``PartSet.actuator``). It is the one step :func:`~fabricate.parts.build.build_parts`
calls after drawing the parts; without ``[actuator]`` nothing changes.

A rotary actuator (servo, gear motor, stepper) on an angle driver
    carries the driven body on its output: the driver joint's pin and its spacers go (from the pins, the
    spacers, the printed spacer parts and the BOM). The driven part gets the interface (a servo horn's screw
    holes and a bore over its hub, or a shaft bore with its flats, :mod:`fabricate.drive.geometry`) and a pad
    round it; the ground part's hole there becomes a clearance for what passes through it (the horn, the
    shaft). The actuator sits under the stack when the driven part is nearer its bottom, else over it, its
    body pointing away from what moves; a mount plate (part role ``"mount"``, the process's thickness) on its
    flange holds it, screwed to it, and stands on the ground part's mounting holes on standoffs (printed
    with an additive process, bought tubes for a cut one), fixed with screws whose clamp is the real stack.
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

from fabricate.catalogue.actuators import Hole as MountHole
from fabricate.catalogue.actuators import Shaft
from fabricate.catalogue.hardware import ISO4762, ISO7089, Screw, screw
from fabricate.drive import geometry as geo
from fabricate.errors import SpecError
from fabricate.mechanism import Driver, Mechanism, Motion, Revolute, Slider
from fabricate.parts import model
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.profiles import circle_hull, fuse_polygons
from fabricate.planar import inverse_transform_points, rotation

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.checks.interference import SweepItem
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
        return _Rotary(design, mechanism, motion, partset, entry, spec.driver, driver).attach()
    if driver.kind == "slide" and entry.kind in PUSHING:
        return _attach_rod_end(design, mechanism, motion, partset, entry, spec.driver, driver)
    want = "a servo, gear motor or stepper" if driver.kind == "angle" else "a tendon, push rod or linear actuator"
    raise SpecError("actuator.model", f"{entry.key!r} ({entry.kind}) cannot drive driver {spec.driver}, a "
                                      f"{driver.kind} driver of {driver.body!r}: it takes {want}")


def sweep_items(partset: Any, chord_tolerance_mm: float | None = None) -> list[SweepItem]:
    """The actuator's solids as interference-sweep items of kind ``"actuator"`` (none without an actuator)."""
    from fabricate.checks.interference import SweepItem

    placed: PlacedActuator | None = getattr(partset, "actuator", None)
    if placed is None:
        return []
    return [SweepItem(s.name, placed.body_of(s), "actuator", s.rings, s.z0, s.z1, frozenset([placed.joint])
                      if s.role == "output" else frozenset(), "", s)
            for s in placed.solids]


# -- shared helpers ------------------------------------------------------------------------------------------
def _hole(joint: str, centre: np.ndarray, nominal_mm: float, compensation_mm: float, pin_mm: float = 0.0,
          fit: str = "clearance") -> Hole:
    """A hole of nominal (fit) size ``nominal_mm``, modelled with the process's compensation added. A screw's
    pilot hole (``fit="tapped"``) is labelled a clearance while the part model has no such fit."""
    return Hole(joint, np.asarray(centre, dtype=np.float64), nominal_mm + compensation_mm, pin_mm,
                fit if fit in model.HOLE_FITS else "clearance", nominal_mm)


def _with(part: Part, **changes: Any) -> Part:
    """A copy of ``part`` with ``changes``; ``slots`` turns a plain part into a slotted one."""
    from fabricate.parts.build import SlottedPart

    if "slots" in changes and not isinstance(part, SlottedPart):
        base = {f.name: getattr(part, f.name) for f in dataclasses.fields(Part)}
        base.update(changes)
        return SlottedPart(**base)
    return dataclasses.replace(part, **changes)


def _fuse(outline: BulgePath, pad: BulgePath, tol: float) -> BulgePath:
    """The outline with a pad fused on (kept exact when the pad lies inside already)."""
    inside = shapely.Polygon(outline.polygon(tol)).buffer(1e-9).contains(shapely.Polygon(pad.polygon(tol)))
    return outline if inside else fuse_polygons(outline, [pad.polygon(tol)], tol)


def _body_part(partset: PartSet, body: str) -> Part:
    for p in partset.parts:
        if p.body == body and p.role not in ("spacer", "mount", "standoff"):
            return p
    raise SpecError("actuator.driver", f"body {body!r} has no part")


def _screw_size(d_mm: float) -> str:
    """The ISO 4762 size of nominal diameter ``d_mm``, else the largest below it."""
    sizes = sorted(ISO4762, key=lambda s: float(s.lstrip("M")))
    fits = [s for s in sizes if float(s.lstrip("M")) <= d_mm + 1e-9]
    return fits[-1] if fits else sizes[0]


def _bom_without(bom: Sequence[dict[str, Any]], pin: Any, spacers: Sequence[Any], removed_parts: set[str],
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


def _purchased(item: str, qty: int, description: str, **extra: Any) -> dict[str, Any]:
    return {"item": item, "kind": "purchased", "qty": qty, "joints": [], "description": description,
            "source": "buy", **extra}


def _screw_row(f: Fastener, copies: int) -> dict[str, Any]:
    return {"item": f.designation, "designation": f.designation, "kind": "screw", "qty": f.qty * copies,
            "joints": [], "source": "buy",
            "description": f.purpose, "clamp_mm": round(f.clamp_mm, 4), "engagement_mm": round(f.engagement_mm, 4)}


# -- rotary actuator on an angle driver ---------------------------------------------------------------------
def driver_joint(mechanism: Mechanism, driver: Driver) -> str:
    """The revolute joint an angle driver turns its body about: its ``joint`` if named, else the one joint
    between its body and its reference."""
    if driver.joint:
        return driver.joint
    found = [j.name for j in mechanism.joints if isinstance(j, Revolute)
             and {j.body_a, j.body_b} == {driver.body, driver.reference}]
    if len(found) != 1:
        raise SpecError("actuator.driver", f"the driver of {driver.body!r} turns it relative to "
                                           f"{driver.reference!r}, joined by {len(found)} revolute joints; "
                                           "an actuator needs exactly one axis")
    return found[0]


class _Rotary:
    """Placing a servo, gear motor or stepper on an angle driver (see the module docstring)."""

    def __init__(self, design: Any, mechanism: Mechanism, motion: Motion, partset: PartSet, entry: Actuator,
                 index: int, driver: Driver) -> None:
        self.design, self.mechanism, self.motion, self.ps = design, mechanism, motion, partset
        self.entry, self.index, self.driver = entry, index, driver
        self.process: ProcessSpec = design.process
        self.tol = float(partset.chord_tolerance_mm)
        self.joint = driver_joint(mechanism, driver)
        self.driven, self.ground = driver.body, driver.reference
        self.c = float(self.process.running_clearance_mm)
        self.comp = float(self.process.hole_compensation_mm)
        self.wall = float(self.process.min_wall_mm)
        self.notes: list[str] = []
        self.new_ground_holes: list[Hole] = []
        self.ground_arms: list[np.ndarray] = []

    # the pin the output replaces
    def _pin(self) -> Any:
        pins = [p for p in self.ps.pins if self.joint in p.joint.split("+")]
        if not pins:
            raise SpecError("actuator.driver", f"joint {self.joint!r} has no pin in the parts")
        pin = pins[0]
        if any(sp.joint in pin.joint.split("+") for sp in getattr(self.ps, "springs", ())):
            raise SpecError("actuator.driver", f"joint {self.joint!r} carries a torsion spring on its pin; an "
                                               "actuator's output cannot replace that pin")
        if set(pin.bodies) - {self.driven, self.ground}:
            raise SpecError("actuator.driver", f"joint {self.joint!r} joins {', '.join(pin.bodies)} on one pin; an "
                                               "actuator's output can only replace a pin between two bodies")
        return pin

    def _face(self, flip: bool, driven: Part) -> float:
        """Stack z of the output face with the actuator under (``flip`` False) or over the stack: a horn flush
        with the driven part; a shaft's tip flush with its far face, the motor and its plate clear of the
        stack (``inf`` when the shaft then does not reach half way into the driven part)."""
        entry, t = self.entry, float(self.process.thickness_mm)
        z_d, t_d = float(driven.z_mm), float(driven.thickness_mm)
        if entry.horn is not None:
            seat1 = geo.horn_seat_z(entry)[1]
            return z_d + t_d + seat1 if flip else z_d - seat1
        shaft = self._shaft()
        plate0 = geo.mount_plate_z(entry)
        top = max(geo.output_base_z(entry), plate0 + t)
        tapped = [h.thread for h in entry.mounting_holes or () if h.thread in ISO4762]
        if tapped:  # screws into the motor's tapped holes: their heads on the plate, toward the stack
            top = max(top, plate0 + t + max(ISO4762[s].head_h_mm for s in tapped))
        gap = float(self.process.layer_gap_mm)
        lo = min(p.z_mm for p in self.ps.parts)
        hi = max(p.z_mm + p.thickness_mm for p in self.ps.parts)
        if flip:
            z_face = max(z_d + shaft.length_mm, hi + gap + top)
            short = z_face - shaft.length_mm > z_d + 0.5 * t_d + 1e-9
        else:
            z_face = min(z_d + t_d - shaft.length_mm, lo - gap - top)
            short = z_face + shaft.length_mm < z_d + 0.5 * t_d - 1e-9
        return math.inf if short else z_face

    def _horn_layout(self, thickness_mm: float) -> tuple[float, str, float, Screw, tuple[MountHole, ...]]:
        """The horn's interface on a driven part ``thickness_mm`` thick: hub bore (nominal), screw size, pilot
        (nominal), the screw, and the arm holes used."""
        horn = self.entry.horn
        assert horn is not None  # called for a servo with a catalogued horn only
        bore = geo.hub_bore_mm(horn, self.c, 0.0)
        size = geo.horn_screw_size(horn)
        pilot = geo.PILOT_FRACTION * float(size.lstrip("M"))
        horn_screw = geo.screw_into(size, horn.arm_thickness_mm, thickness_mm)
        used = geo.horn_holes(horn, bore + self.comp, pilot + self.comp, self.wall, horn_screw.head_d_mm)
        return bore, size, pilot, horn_screw, used

    def _output_reach(self) -> float:
        """Radius (mm) the output sweeps about its axis: the horn cut back past its screws (and their heads),
        or the shaft."""
        horn = self.entry.horn
        if horn is None:
            return 0.5 * self._shaft().diameter_mm
        _, _, _, horn_screw, used = self._horn_layout(float(self.process.thickness_mm))
        r = max(math.hypot(h.x, h.y) for h in used)
        hole = min(h.diameter_mm for h in horn.arm_holes)
        return max(0.5 * horn.hub_d_mm, r + hole, r + 0.5 * horn_screw.head_d_mm)

    def _shaft(self) -> Shaft:
        """The output the driven part sits on without a horn: the motor's shaft, or a servo's spline (round:
        the part is pressed on it)."""
        entry = self.entry
        if entry.shaft is not None:
            return entry.shaft
        if entry.spline is not None:
            return Shaft(entry.spline.diameter_mm, entry.spline.length_mm, 0, None, None)
        raise SpecError("actuator.model", f"{entry.key!r} has no output shaft or spline in the catalogue")

    def _conflicts(self, flip: bool, driven: Part, z_face: float) -> float:
        """How badly the actuator on this side meets the other parts: 1 for a static part it passes through
        (the ground, which gets a clearance hole), 10 for each moving part that comes within reach of the
        axis: the output's (horn or shaft) between the driven part and the output face, the body's beyond."""
        if not math.isfinite(z_face):
            return math.inf
        entry = self.entry
        corners = [np.hypot(x, y) for b in entry.body or () for x in (b.x0, b.x1) for y in (b.y0, b.y1)]
        out_reach = self._output_reach()
        depth = min([b.z0 for b in entry.body or ()], default=0.0)
        near = (driven.z_mm + driven.thickness_mm, z_face) if flip else (z_face, driven.z_mm)
        far = geo.Placement(np.zeros(2), 0.0, flip, z_face).z_range(depth, 0.0)
        spans = [(near, out_reach), (far, max(corners, default=0.0))]
        picks = np.unique(np.linspace(0, len(self.motion.inputs) - 1, min(60, len(self.motion.inputs)))
                          .round().astype(int))
        axis = shapely.Point(*self.mechanism.body(self.driven).point(self.joint))
        pose_d = self.motion.pose(self.driven)[picks]
        cost = 0.0
        for part in self.ps.parts:
            z0, z1 = part.z_mm, part.z_mm + part.thickness_mm
            reach = max([r for (lo, hi), r in spans if z0 < hi - 1e-9 and z1 > lo + 1e-9], default=None)
            if part.body == self.driven or reach is None:
                continue
            if part.body == self.ground:
                cost += 1.0
                continue
            ring = part.outline.polygon(0.05)
            pose_b = self.motion.pose(part.body)[picks]
            for k in range(len(picks)):
                world = ring @ rotation(pose_b[k, 2]).T + pose_b[k, :2]
                local = inverse_transform_points(pose_d[k], world)
                if shapely.Polygon(local).distance(axis) < reach + self.c:
                    cost += 10.0
                    break
        return cost

    def _orient(self, angle: float, centre: np.ndarray, ground: Part, flip: bool, z_face: float) -> float:
        """The turn nearest ``angle`` (10 degree steps) at which the standoffs on the ground's mounting holes
        keep clear of the actuator's body between its mount plate and the ground part."""
        entry = self.entry
        mounting = [h for h in ground.holes if h.joint.startswith("mount_")]
        if not mounting or not entry.body:
            return angle
        pz = geo.mount_plate_z(entry)
        # the ground part's near face in the entry's z: the standoffs run from the plate up to it
        faces = [(g - z_face) if not flip else (z_face - g) for g in (ground.z_mm, ground.z_mm + ground.thickness_mm)]
        near = min(faces)
        boxes = [b for b in entry.body if b.z1 > pz + 1e-9 and b.z0 < near - 1e-9]
        rects = [geo.rectangle(b.x0 - self.c, b.y0 - self.c, b.x1 + self.c, b.y1 + self.c) for b in boxes]
        discs = [(np.asarray(h.centre, dtype=float), 0.5 * h.diameter_mm + max(self.wall, 0.25 * h.diameter_mm))
                 for h in mounting]
        for k in sorted(range(-18, 19), key=lambda k: (abs(k), k)):
            turn = angle + math.radians(10.0 * k)
            place = geo.Placement(centre, turn, flip, z_face)
            shapes = [shapely.Polygon(geo.placed_ring(r, place)) for r in rects]
            if all(shape.distance(shapely.Point(c)) >= r for shape in shapes for c, r in discs):
                return turn
        return angle

    def _standoff_sites(self, place: geo.Placement, ground: Part, lo: float, hi: float) -> list[Hole]:
        """Where the standoffs stand on the ground part (holes of the ground): its mounting holes that keep
        clear of the actuator (body, output) and of every part moving between the plate and the ground; else
        two new holes (``standoff_1``, ``standoff_2``), as far apart as the ground part's free material allows;
        none if it has none."""
        from fabricate.parts.build import swept_region

        entry, c = self.entry, self.c
        nominal = float(self.design.parts.mounting_hole_mm) + 2.0 * c
        hole_d = nominal + self.comp
        outer = hole_d + 2.0 * max(self.wall, 0.25 * hole_d)
        forbidden = []
        for b in entry.body or ():
            z0, z1 = place.z_range(b.z0, b.z1)
            if z0 < hi - 1e-9 and z1 > lo + 1e-9:
                forbidden.append(shapely.Polygon(geo.placed_ring(geo.rectangle(b.x0, b.y0, b.x1, b.y1), place)))
        out_reach = self._output_reach()
        forbidden.append(shapely.Point(*place.centre).buffer(out_reach, 64))
        t = float(self.process.thickness_mm)
        for mh in entry.mounting_holes or ():  # the plate's own screws: their holes and heads
            f = geo.fastening(entry, mh, t, c, self.comp)
            head = ISO4762[f.size].head_d_mm if f.tapped else 0.0
            radius = max(0.5 * f.plate_hole_mm + self.wall, 0.5 * head)
            forbidden.append(shapely.Point(*place.plan(np.array([mh.x, mh.y]))).buffer(radius, 32))
        if self.ground == self.mechanism.ground:
            moving = {p.body: p.outline for p in self.ps.parts if p.body != self.ground
                      and p.z_mm < hi - 1e-9 and p.z_mm + p.thickness_mm > lo + 1e-9}
            if moving:
                forbidden.append(swept_region(moving, self.motion))
        keep_out = shapely.union_all(forbidden).buffer(0.5 * outer + c)
        existing = [h for h in ground.holes if h.joint.startswith("mount_")]
        clear = [h for h in existing if not keep_out.contains(shapely.Point(h.centre))
                 and keep_out.distance(shapely.Point(h.centre)) > 0.0]
        if len(clear) >= min(2, len(existing)) and clear:
            return clear
        # new sites on the ground part's own material, clear of its holes
        inset = max(0.5 * outer, 0.5 * hole_d + self.wall)
        region = shapely.Polygon(ground.outline.polygon(0.05)).buffer(-inset)
        for h in ground.holes:
            region = region.difference(shapely.Point(h.centre).buffer(0.5 * (h.diameter_mm + hole_d) + self.wall))
        region = region.difference(keep_out)
        if region.is_empty or region.area < 1e-6:
            return self._standoff_arms(place, ground, keep_out, nominal, hole_d, outer) or clear
        xs, ys = np.meshgrid(*(np.arange(a, b + 0.25, 0.25) for a, b in
                               zip(region.bounds[:2], region.bounds[2:], strict=True)))
        pts = np.column_stack([xs.ravel(), ys.ravel()])
        pts = pts[shapely.contains_xy(region, pts[:, 0], pts[:, 1])]
        if len(pts) == 0:
            pts = np.array(region.representative_point().coords)
        if len(pts) == 1:
            picks = pts
        else:
            gaps = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1)) if len(pts) < 1500 else None
            if gaps is None:  # a coarse pair: the points farthest along the region's long direction
                u = pts - pts.mean(axis=0)
                axis = np.linalg.svd(u, full_matrices=False)[2][0]
                picks = pts[[int(np.argmin(u @ axis)), int(np.argmax(u @ axis))]]
            else:
                i, j = np.unravel_index(int(np.argmax(gaps)), gaps.shape)
                picks = pts[[i, j]] if gaps[i, j] >= outer + self.wall else pts[[i]]
        self.new_ground_holes = [_hole(f"actuator_standoff_{k + 1}", p, nominal, self.comp, fit="clearance")
                                 for k, p in enumerate(picks)]
        return list(self.new_ground_holes)

    def _standoff_arms(self, place: geo.Placement, ground: Part, keep_out: Any, nominal: float, hole_d: float,
                       outer: float) -> list[Hole]:
        """Two standoff sites off the ground part, each on an arm the ground part grows to reach it (in its own
        layer, clear of what moves there): the sites nearest the ground part that clear ``keep_out``, at least
        three standoffs apart. Sets :attr:`ground_arms`; [] when no site is found."""
        from fabricate.parts.build import swept_region

        if self.ground != self.mechanism.ground:
            return []
        body = shapely.Polygon(ground.outline.polygon(0.05))
        g0, g1 = ground.z_mm, ground.z_mm + ground.thickness_mm
        same_layer = {p.body: p.outline for p in self.ps.parts if p.body != self.ground
                      and p.z_mm < g1 - 1e-9 and p.z_mm + p.thickness_mm > g0 + 1e-9}
        swept = swept_region(same_layer, self.motion).buffer(self.c + 0.5) if same_layer else shapely.Polygon()
        boss = max(0.5 * outer, 0.5 * hole_d + self.wall)
        reach = max([math.hypot(x, y) for b in self.entry.body or () for x in (b.x0, b.x1) for y in (b.y0, b.y1)],
                    default=20.0) + 4.0 * outer
        xs, ys = np.meshgrid(*(np.arange(-reach, reach + 1.0, 1.0),) * 2)
        pts = np.column_stack([xs.ravel(), ys.ravel()]) + np.asarray(place.centre, dtype=float)
        pts = pts[~shapely.contains_xy(keep_out, pts[:, 0], pts[:, 1])]
        pts = pts[shapely.distance(keep_out, shapely.points(pts)) > 0.0]
        order = np.argsort(shapely.distance(body, shapely.points(pts)))
        sites: list[np.ndarray] = []
        arms: list[np.ndarray] = []
        for k in order:
            p = pts[k]
            if any(float(np.hypot(*(p - q))) < 3.0 * outer for q in sites):
                continue
            near = np.array(shapely.ops.nearest_points(body, shapely.Point(p))[0].coords[0])
            arm = circle_hull(np.array([near, p]), np.array([boss, boss])) if np.hypot(*(p - near)) > 1e-6 \
                else circle_hull(p[None, :], boss)
            ring = arm.polygon(0.05)
            if not swept.is_empty and shapely.Polygon(ring).intersects(swept):
                continue
            sites.append(p)
            arms.append(ring)
            if len(sites) == 2:
                break
        if len(sites) < 2:
            return []
        self.ground_arms = arms
        self.new_ground_holes = [_hole(f"actuator_standoff_{k + 1}", p, nominal, self.comp, fit="clearance")
                                 for k, p in enumerate(sites)]
        return list(self.new_ground_holes)

    def _away(self, centre: np.ndarray) -> np.ndarray:
        """Unit direction, in the ground body's frame, from what moves to the axis."""
        picks = np.unique(np.linspace(0, len(self.motion.inputs) - 1, min(30, len(self.motion.inputs)))
                          .round().astype(int))
        base = self.motion.pose(self.ground)
        pts = []
        for body in self.mechanism.bodies:
            if body.name == self.ground:
                continue
            for name in body.points:
                world = self.motion.point(name, body.name)[picks]
                pts += [inverse_transform_points(base[k], world[i][None, :])[0] for i, k in enumerate(picks)]
        if not pts:
            return np.array([0.0, -1.0])
        away = centre - np.mean(pts, axis=0)
        n = float(np.hypot(*away))
        return away / n if n > 1e-6 else np.array([0.0, -1.0])

    def _arm_angle(self) -> float:
        """Direction (driven frame) from the axis to the driven body's farthest other point: the horn's arms
        lie along the link."""
        body = self.mechanism.body(self.driven)
        centre = body.point(self.joint)
        others = [body.point(p) - centre for p in body.points if p != self.joint]
        others = [v for v in others if float(np.hypot(*v)) > 1e-9]
        if not others:
            return 0.0
        far = max(others, key=lambda v: float(np.hypot(*v)))
        return math.atan2(far[1], far[0])

    def attach(self) -> PartSet:
        entry, ps = self.entry, self.ps
        pin = self._pin()
        driven, ground = _body_part(ps, self.driven), _body_part(ps, self.ground)
        c_d = self.mechanism.body(self.driven).point(self.joint)
        c_g = self.mechanism.body(self.ground).point(self.joint)
        # the side whose parts keep clear of the actuator; the ground's side loses a tie (its hole would have
        # to clear the horn)
        faces = {side: self._face(side, driven) for side in (True, False)}
        costs = {side: self._conflicts(side, driven, faces[side]) + (0.5 if (ground.layer < driven.layer) != side
                                                                      else 0.0) for side in (True, False)}
        flip = min((True, False), key=lambda side: costs[side])
        z_face = faces[flip]
        if not math.isfinite(z_face):
            raise SpecError("actuator.model", f"{entry.key!r}: its shaft does not reach half way into the driven "
                                              f"part {driven.name} across the stack on either side")
        away = self._away(c_g)
        env = entry.envelope
        ex = np.array([0.5 * (env.x0 + env.x1), 0.5 * (env.y0 + env.y1)]) if env is not None else np.zeros(2)
        if flip:
            ex = ex * np.array([1.0, -1.0])
        # the body's centre (off the axis for a servo or a 28BYJ-48) points away from what moves
        angle = math.atan2(away[1], away[0]) - (math.atan2(ex[1], ex[0]) if float(np.hypot(*ex)) > 1e-6 else 0.0)
        angle = self._orient(angle, c_g, ground, flip, z_face)
        alpha = self._arm_angle()
        interface: list[str] = []
        solids: list[geo.Solid] = []
        fasteners: list[Fastener] = []
        slots: list[BulgePath] = []
        holes = [h for h in driven.holes if h.joint != pin.joint]
        t_d = float(driven.thickness_mm)
        pad_circles: list[tuple[np.ndarray, float]] = []
        if entry.horn is not None:
            horn, spline = entry.horn, entry.spline
            assert horn is not None and spline is not None  # a servo entry has both (catalogue)
            seat0, seat1 = geo.horn_seat_z(entry)
            bore, size, pilot, horn_screw, used = self._horn_layout(t_d)
            at = geo.horn_pattern(used, c_d, alpha, flip)
            holes.append(_hole("actuator_hub", c_d, bore, self.comp, fit="clearance"))
            interface.append("actuator_hub")
            for k, centre in enumerate(at):
                holes.append(_hole(f"actuator_horn_{k + 1}", centre, pilot, self.comp, fit="tapped"))
                interface.append(f"actuator_horn_{k + 1}")
                pad_circles.append((centre, 0.5 * (pilot + self.comp) + self.wall))
            pad_circles.append((c_d, 0.5 * (bore + self.comp) + self.wall))
            place_d = geo.Placement(c_d, alpha, flip, z_face)
            hole_d = min(h.diameter_mm for h in horn.arm_holes)
            arm = geo.trimmed_horn_ring(at, c_d, horn.hub_d_mm, hole_d, self.tol)
            arm0 = seat1 - horn.arm_thickness_mm
            solids += [geo.Solid("actuator_spline", "output", (geo.circle_ring(c_d, spline.diameter_mm, self.tol),),
                                 *place_d.z_range(0.0, seat0)),
                       geo.Solid("actuator_horn_hub", "output", (geo.circle_ring(c_d, horn.hub_d_mm, self.tol),),
                                 *place_d.z_range(seat0, seat1)),
                       geo.Solid("actuator_horn_arms", "output", (arm,), *place_d.z_range(arm0, seat1))]
            # the heads sit under the arms, between the horn's arms and the servo's face
            solids += [geo.Solid(f"actuator_horn_screw_{k + 1}", "screw",
                                 (geo.circle_ring(centre, horn_screw.head_d_mm, self.tol),),
                                 *place_d.z_range(arm0 - horn_screw.head_h_mm, arm0))
                       for k, centre in enumerate(at)]
            if arm0 - horn_screw.head_h_mm < 0.0:
                raise SpecError("actuator.model", f"{entry.key!r}: no room for a {size} head under the horn's arms")
            reach = max(float(np.max(np.hypot(*(arm - c_d).T))), 0.5 * horn.hub_d_mm)
            fasteners.append(Fastener(horn_screw.designation, len(at), "driven part to the horn, up through its "
                                      "arms into the part (taps into the part)", horn_screw.clamp_mm,
                                      horn_screw.engagement_mm))
            ring_r = math.hypot(used[0].x, used[0].y)
            self.notes.append(f"open the horn's arm holes {ring_r:g} mm from its axis to Ø"
                              f"{ISO7089[size][0]:g} mm for the {size} screws and cut the arms back one hole past "
                              "them; screw the horn to the driven part, press it on the spline, then drive the "
                              "horn's centre screw through the hub bore")
            # what passes the ground part: the horn where it overlaps its thickness, else the hub and its screw
            heads = ring_r + 0.5 * horn_screw.head_d_mm
            passing = [(geo.output_base_z(entry), seat0, spline.diameter_mm), (seat0, seat1, 2.0 * reach),
                       (arm0 - horn_screw.head_h_mm, arm0, 2.0 * heads)]
            default_clear = bore
        else:
            shaft = self._shaft()
            base = geo.output_base_z(entry)
            flats = geo.shaft_flats(shaft)
            radial = self.c + 0.5 * self.comp if flats else 0.5 * self.comp
            if entry.shaft is None:  # a servo's spline, no horn catalogued: the part is pressed on the spline
                press = float(getattr(self.process, "press_fit_interference_mm", 0.0) or 0.0)
                radial = 0.5 * (self.comp - press)
                self.notes.append(f"no horn in the catalogue: press the driven part onto the servo's Ø"
                                  f"{shaft.diameter_mm:g} mm spline (bore Ø{shaft.diameter_mm - press:g} mm "
                                  "nominal, the teeth cut their way) and fix it with the servo's centre screw")
            elif not flats:
                self.notes.append(f"the Ø{shaft.diameter_mm:g} mm shaft is round (no flat in the catalogue): "
                                  "the bore is a slip fit; secure the part with adhesive or a clamp")
            slots.append(geo.shaft_bore(shaft, c_d, alpha, radial))
            interface.append("actuator_shaft_bore" if entry.shaft is not None else "actuator_spline_bore")
            pad_circles.append((c_d, 0.5 * shaft.diameter_mm + radial + self.wall))
            place_d = geo.Placement(c_d, alpha, flip, z_face)
            solids.append(geo.Solid("actuator_shaft" if entry.shaft is not None else "actuator_spline", "output",
                                    (geo.circle_ring(c_d, shaft.diameter_mm, self.tol),),
                                    *place_d.z_range(base, shaft.length_mm)))
            passing = [(base, shaft.length_mm, shaft.diameter_mm)]
            default_clear = shaft.diameter_mm + 2.0 * self.c
        pad = circle_hull(np.array([c for c, _ in pad_circles]), np.array([r for _, r in pad_circles]))
        new_driven = _with(driven, outline=_fuse(driven.outline, pad, self.tol), holes=tuple(holes),
                           **({"slots": tuple(getattr(driven, "slots", ())) + tuple(slots)} if slots else {}))
        place_g = geo.Placement(c_g, angle, flip, z_face)
        # the ground's hole at the joint: a clearance for whatever of the output passes its thickness
        g0, g1 = float(ground.z_mm), float(ground.z_mm + ground.thickness_mm)
        clear = default_clear
        for z0, z1, diameter in passing:
            lo, hi = place_d.z_range(z0, z1)
            if lo < g1 - 1e-9 and hi > g0 + 1e-9:
                clear = max(clear, diameter + 2.0 * self.c)
        ground_holes = [h for h in ground.holes if h.joint != pin.joint]
        ground_holes.append(_hole("actuator_clearance", c_g, clear, self.comp, fit="clearance"))
        solids += geo.body_solids(entry, place_g)
        mount, mount_fasteners, standoffs, standoff_parts, mount_solids = self._mount(place_g, ground, flip)
        fasteners += mount_fasteners
        solids += mount_solids
        ground_pad = circle_hull(np.asarray(c_g, dtype=float)[None, :], 0.5 * (clear + self.comp) + self.wall)
        ground_holes += self.new_ground_holes
        outline = _fuse(ground.outline, ground_pad, self.tol)
        if self.ground_arms:
            outline = fuse_polygons(outline, list(self.ground_arms), self.tol)
        new_ground = _with(ground, outline=outline, holes=tuple(ground_holes))
        # the pin's spacers go with it (printed spacer parts too)
        removed = {p.name for p in ps.parts if p.role not in BODY_ROLES and any(h.joint == pin.joint for h in p.holes)}
        parts = []
        for p in ps.parts:
            if p.name in removed:
                continue
            parts.append(new_driven if p is driven else new_ground if p is ground else p)
        parts += [mount, *standoff_parts]
        pins = tuple(p for p in ps.pins if p is not pin)
        spacers = tuple(s for s in ps.spacers if s.joint != pin.joint)
        bom = _bom_without(ps.bom, pin, [s for s in ps.spacers if s.joint == pin.joint], removed,
                           [new_driven, new_ground], self.process, ps.copies)
        from fabricate.parts.bom import part_rows

        bom += part_rows([mount, *standoff_parts], self.process, ps.copies)
        bom.append(_purchased(entry.name, ps.copies, f"{entry.kind} driving {self.driven} about {self.joint} "
                              f"(catalogue {entry.key!r})", model=entry.key))
        bom += [_screw_row(f, ps.copies) for f in fasteners]
        tubes: dict[str, int] = {}
        for s in standoffs:
            if not s.printed:
                item = f"standoff tube {s.inner_diameter_mm:.3g}/{s.outer_diameter_mm:.3g} x {s.length_mm:.2f} mm"
                tubes[item] = tubes.get(item, 0) + ps.copies
        bom += [_purchased(item, qty, "actuator mount standoff, cut to length") for item, qty in tubes.items()]
        from fabricate.parts.build import overlapping_cuts

        warnings = tuple(ps.warnings) + tuple(w for w in overlapping_cuts([new_driven, new_ground, mount])
                                              if w not in ps.warnings)
        record = PlacedActuator(
            model=entry.key, name=entry.name, kind=entry.kind, driver=self.index, driver_kind="angle",
            joint=self.joint, driven_body=self.driven, ground_body=self.ground, axis=np.asarray(c_g, dtype=float),
            direction=away, angle=float(angle), z_face=float(z_face), flip=flip, removed_pin=pin.joint,
            interface=tuple(interface),
            mount_part=mount.name, fasteners=tuple(fasteners), standoffs=tuple(standoffs), solids=tuple(solids),
            notes=tuple(self.notes))
        return dataclasses.replace(ps, parts=tuple(parts), pins=pins, spacers=spacers, bom=bom,
                                   warnings=warnings, actuator=record)

    def _mount(self, place: geo.Placement, ground: Part, flip: bool
               ) -> tuple[Part, list[Fastener], list[Standoff], list[Part], list[geo.Solid]]:
        """The mount plate on the actuator's flange, its screws, and the standoffs to the ground part."""
        from fabricate.parts.build import SlottedPart, safe_name

        entry, process, tol = self.entry, self.process, self.tol
        t = float(process.thickness_mm)
        pz = geo.mount_plate_z(entry)
        z0, z1 = place.z_range(pz, pz + t)
        holes: list[Hole] = []
        circles: list[tuple[np.ndarray, float]] = []
        fasteners: list[Fastener] = []
        solids: list[geo.Solid] = []
        by_screw: dict[tuple[str, float, float, str], int] = {}
        for k, mh in enumerate(entry.mounting_holes or ()):
            f = geo.fastening(entry, mh, t, self.c, self.comp)
            centre = place.plan(np.array([mh.x, mh.y]))
            nominal = f.plate_hole_mm - self.comp
            holes.append(_hole(f"actuator_screw_{k + 1}", centre, nominal, self.comp,
                               fit="clearance" if f.tapped else "tapped"))
            circles.append((centre, 0.5 * f.plate_hole_mm + self.wall))
            s = screw(f.size, f.clamp_mm, f.engagement_mm)
            key = (s.designation, s.clamp_mm, s.engagement_mm,
                   "actuator to its mount plate" + (" (into its tapped holes)" if f.tapped
                                                     else " (taps into the plate)"))
            by_screw[key] = by_screw.get(key, 0) + 1
            if f.tapped:  # the head bears on the plate's far face from the actuator
                solids.append(geo.Solid(f"actuator_screw_head_{k + 1}", "fixing",
                                        (geo.circle_ring(centre, s.head_d_mm, tol),),
                                        *place.z_range(pz + t, pz + t + s.head_h_mm)))
        fasteners += [Fastener(d, n, purpose, clamp, engage) for (d, clamp, engage, purpose), n in by_screw.items()]
        slots = [BulgePath.polyline(geo.placed_ring(r, place)) for r in geo.plate_cutouts(entry, pz, pz + t, self.c)]
        for cut in slots:
            circles += [(v, self.wall) for v in cut.vertices]
        circles.append((np.asarray(place.centre, dtype=float), self.wall))
        standoffs: list[Standoff] = []
        standoff_parts: list[Part] = []
        g0, g1 = float(ground.z_mm), float(ground.z_mm + ground.thickness_mm)
        lo, hi = (g1, z0) if flip else (z1, g0)
        mounting = self._standoff_sites(place, ground, lo, hi) if hi - lo > 1e-6 else []
        if mounting:
            size = _screw_size(float(self.design.parts.mounting_hole_mm))
            d = float(size.lstrip("M"))
            printed = process.technique == "additive"
            count = 0
            for h in mounting:
                inner = float(h.diameter_mm)
                outer = inner + 2.0 * max(self.wall, 0.25 * inner)
                st = Standoff(h.joint, np.asarray(h.centre, dtype=float), inner, outer, hi - lo, lo, printed)
                standoffs.append(st)
                pilot = geo.PILOT_FRACTION * d
                name = h.joint.removeprefix("actuator_")
                holes.append(_hole(f"actuator_{name}", st.centre, pilot, self.comp, fit="tapped"))
                circles.append((st.centre, max(0.5 * outer, 0.5 * (pilot + self.comp) + self.wall)))
                ring = circle_hull(st.centre[None, :], 0.5 * outer)
                if printed:
                    standoff_parts.append(Part(name=safe_name(name if name.startswith("standoff") else
                                                              f"standoff_{name}"), body=self.ground, outline=ring,
                                               holes=(_hole(h.joint, st.centre, inner - self.comp, self.comp),),
                                               thickness_mm=st.length_mm, z_mm=st.z_mm, layer=ground.layer,
                                               process=process.name, role="standoff"))
                else:
                    solids.append(geo.Solid(name if name.startswith("standoff") else f"standoff_{name}", "standoff",
                                            (geo.circle_ring(st.centre, outer, tol),
                                             geo.circle_ring(st.centre, inner, tol)[::-1]), st.z_mm,
                                            st.z_mm + st.length_mm))
                count += 1
            fix = geo.screw_into(size, float(ground.thickness_mm) + (hi - lo), t)
            fasteners.append(Fastener(fix.designation, count, "mount plate to the ground part through the standoffs "
                                      "(taps into the plate)", fix.clamp_mm, fix.engagement_mm))
        else:
            self.notes.append("no place on the ground part for the mount's standoffs: fix the mount plate to the "
                              "same base as the ground part")
        outline = circle_hull(np.array([c for c, _ in circles]), np.array([r for _, r in circles]))
        layers = [p.layer for p in self.ps.parts]
        plate = SlottedPart(name=MOUNT_PART, body=self.ground, outline=outline, holes=tuple(holes), thickness_mm=t,
                            z_mm=z0, layer=max(layers) + 1 if flip else min(layers) - 1, process=process.name,
                            role="mount", slots=tuple(slots))
        return plate, fasteners, standoffs, standoff_parts, solids


# -- tendon, push rod or linear actuator on a slide driver -----------------------------------------------------
def _attach_rod_end(design: Any, mechanism: Mechanism, motion: Motion, ps: PartSet, entry: Actuator, index: int,
                    driver: Driver) -> PartSet:
    """A clevis hole on the slider part, on the slide axis past its guide slot's free end."""
    process: ProcessSpec = design.process
    tol = float(ps.chord_tolerance_mm)
    slider = next((j for j in mechanism.joints if isinstance(j, Slider) and j.name == driver.joint), None)
    if slider is None:
        raise SpecError("actuator.driver", f"the slide driver names no slider ({driver.joint!r})")
    rod = _body_part(ps, slider.body_b)
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
    hole = _hole("actuator_rod_end", centre, hole_nominal, comp, pin_mm, fit="running")
    new_rod = _with(rod, outline=_fuse(rod.outline, pad, tol), holes=tuple(rod.holes) + (hole,))
    parts = tuple(new_rod if p is rod else p for p in ps.parts)
    bom = _bom_without(ps.bom, None, (), set(), [new_rod], process, ps.copies)
    what = "tendon or push rod" if entry.kind == "tendon" else entry.name
    bom.append(_purchased(what, ps.copies, f"{entry.kind} pulling or pushing {slider.body_b} along {slider.name}, "
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
