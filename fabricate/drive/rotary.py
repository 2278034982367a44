"""A servo, gear motor or stepper on an angle driver: which side of the stack, which way its body points,
the interface it cuts into the driven part and the clearance in the ground part (:mod:`fabricate.drive.parts`
describes the whole; the mount plate and its standoffs are :mod:`fabricate.drive.mount`'s)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.catalogue.actuators import Hole as MountHole
from fabricate.catalogue.actuators import Shaft
from fabricate.catalogue.hardware import ISO4762, ISO7089, Screw
from fabricate.drive import geometry as geo
from fabricate.drive.editing import body_part, bom_without, fuse_pad, with_changes
from fabricate.drive.mount import MountPlacement
from fabricate.drive.records import BODY_ROLES, ROTARY, Fastener, PlacedActuator, fit_hole, purchased_row, screw_row
from fabricate.errors import SpecError
from fabricate.mechanism import Driver, Mechanism, Motion, Revolute
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.profiles import circle_hull, fuse_polygons
from fabricate.planar import inverse_transform_points, rotation

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.parts.partset import PartSet
    from fabricate.process import ProcessSpec


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


def motor_top_mm(entry: Actuator, thickness_mm: float) -> float:
    """Height (mm) above a shaft motor's output face of what stands toward the stack: the output's base, the
    mount plate (``thickness_mm``) and the heads of screws into the motor's tapped holes."""
    plate0 = geo.mount_plate_z(entry)
    top = max(geo.output_base_z(entry), plate0 + thickness_mm)
    tapped = [h.thread for h in entry.mounting_holes or () if h.thread in ISO4762]
    if tapped:  # screws into the motor's tapped holes: their heads on the plate, toward the stack
        top = max(top, plate0 + thickness_mm + max(ISO4762[s].head_h_mm for s in tapped))
    return top


def _rotary_drive(design: Any, mechanism: Mechanism) -> tuple[Actuator, Driver] | None:
    """The design's rotary actuator and the driver it drives, or None (no actuator, a pushing one, or one that
    does not resolve: the drive stage says why)."""
    spec = getattr(design, "actuator", None)
    if spec is None:
        return None
    try:
        entry = spec.entry()
    except SpecError:
        return None
    if spec.driver >= len(mechanism.drivers) or entry.kind not in ROTARY:
        return None
    return entry, mechanism.drivers[spec.driver]


def replaced_joint(design: Any, mechanism: Mechanism) -> str | None:
    """The joint whose pin a rotary actuator's output replaces (its driver's), or None (no rotary actuator, or
    one that does not resolve)."""
    found = _rotary_drive(design, mechanism)
    if found is None:
        return None
    _, driver = found
    return driver_joint(mechanism, driver) if driver.kind == "angle" else None


def output_depth(design: Any, mechanism: Mechanism) -> tuple[str, float] | None:
    """How deep in the stack the driven part of a shaft (or bare spline) output may lie: (driven body, mm from
    the stack's outer face to the part's near face) for which the output still reaches half way into the part
    with the motor and its plate clear of the stack (:meth:`RotaryPlacement._face`); the layer order keeps the
    driven part there (:func:`~fabricate.parts.layers.order_layers`). None for a horn (flush with the driven
    part), a pushing actuator or no actuator, and where the design's actuator does not resolve (the drive
    stage says why)."""
    found = _rotary_drive(design, mechanism)
    if found is None or found[0].horn is not None:
        return None
    entry, driver = found
    output = entry.shaft if entry.shaft is not None else entry.spline
    if driver.kind != "angle" or output is None:
        return None
    process = design.process
    t = float(process.thickness_mm)
    return driver.body, float(output.length_mm) - float(process.layer_gap_mm) - motor_top_mm(entry, t) - 0.5 * t


def motor_reach(design: Any, mechanism: Mechanism) -> tuple[str, np.ndarray, float] | None:
    """Where a shaft (or bare spline) motor stands and how far its body reaches: (ground body, output axis in
    its coordinates, radius mm of the body's farthest corner from the axis), for the layer order to know which
    pins' ends the motor may meet (:func:`~fabricate.parts.layers.order_layers` ``near_motor``). None where
    :func:`output_depth` is None (no such motor)."""
    if output_depth(design, mechanism) is None:
        return None
    found = _rotary_drive(design, mechanism)
    assert found is not None  # output_depth resolved it
    entry, driver = found
    corners = [math.hypot(x, y) for b in entry.body or () for x in (b.x0, b.x1) for y in (b.y0, b.y1)]
    axis = np.asarray(mechanism.body(driver.reference).point(driver_joint(mechanism, driver)), dtype=np.float64)
    return driver.reference, axis, max(corners, default=0.0)


@dataclass(frozen=True)
class _Output:
    """The actuator's output on the driven part, as :meth:`RotaryPlacement.attach` passes it on.

    Attributes
    ----------
    place : geo.Placement
        The output's frame on the driven part.
    holes, slots : tuple
        The driven part's holes (its pin's hole gone, the interface's in) and its new slots (a shaft's bore).
    pad_circles : tuple of (centre, radius)
        Circles the driven part's outline grows to cover (a wall round each interface hole).
    interface : tuple of str
        The interface's hole and slot names.
    solids, fasteners : tuple
        The output's solids (spline, horn, shaft, screw heads) and its screws.
    passing : tuple of (z0, z1, diameter)
        What of the output may pass the ground part (output frame z, mm).
    default_clear : float
        The ground's clearance hole (nominal, mm) where something passes.
    """

    place: geo.Placement
    holes: tuple[Hole, ...]
    slots: tuple[BulgePath, ...]
    pad_circles: tuple[tuple[np.ndarray, float], ...]
    interface: tuple[str, ...]
    solids: tuple[geo.Solid, ...]
    fasteners: tuple[Fastener, ...]
    passing: tuple[tuple[float, float, float], ...]
    default_clear: float


class RotaryPlacement(MountPlacement):
    """Placing a servo, gear motor or stepper on an angle driver (see :mod:`fabricate.drive.parts`)."""

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
        self.resized_ground_holes: list[Hole] = []
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
        entry, t = self.entry, self._plate_mm()  # the mount plate's stock
        z_d, t_d = float(driven.z_mm), float(driven.thickness_mm)
        if entry.horn is not None:
            seat1 = geo.horn_seat_z(entry)[1]
            return z_d + t_d + seat1 if flip else z_d - seat1
        shaft = self._shaft()
        top = motor_top_mm(entry, t)
        gap = float(self.process.layer_gap_mm)
        lo = min(p.z_mm for p in self.ps.parts)
        hi = max(p.z_mm + p.thickness_mm for p in self.ps.parts)
        # a pin's end (its clip, washers) sticking out of the stack within the body's reach: the motor clears it
        corners = [np.hypot(x, y) for b in entry.body or () for x in (b.x0, b.x1) for y in (b.y0, b.y1)]
        reach = max(corners, default=0.0) + self.c
        at = shapely.Point(*self.mechanism.body(self.ground).point(self.joint))
        near = [(z0, z1) for geom, z0, z1 in self._pin_obstacles() if geom.distance(at) < reach]
        # clear of those where the shaft still reaches (else only of the parts: the interference proof names the
        # pin end the motor meets)
        for lo_, hi_ in ((min([lo] + [z0 for z0, _ in near]), max([hi] + [z1 for _, z1 in near])), (lo, hi)):
            if flip:
                z_face = max(z_d + shaft.length_mm, hi_ + gap + top)
                short = z_face - shaft.length_mm > z_d + 0.5 * t_d + 1e-9
            else:
                z_face = min(z_d + t_d - shaft.length_mm, lo_ - gap - top)
                short = z_face + shaft.length_mm < z_d + 0.5 * t_d - 1e-9
            if not short:
                return z_face
        return math.inf

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
        # pins, washers and tubes in the body's heights within its reach (its turn may still dodge them)
        body_reach = max(corners, default=0.0) + self.c
        at = shapely.Point(*self.mechanism.body(self.ground).point(self.joint))
        for geom, z0, z1 in self._pin_obstacles():
            if z0 < far[1] - 1e-9 and z1 > far[0] + 1e-9 and geom.distance(at) < body_reach:
                cost += 3.0
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
        """The part set with the actuator in its driver's pin's place: its side and orientation, its output's
        interface in the driven part, its clearance in the ground part, its mount, and the BOM's rows."""
        entry, ps = self.entry, self.ps
        pin = self._pin()
        driven, ground = body_part(ps, self.driven), body_part(ps, self.ground)
        c_g = self.mechanism.body(self.ground).point(self.joint)
        flip, z_face = self._side(driven, ground)
        away, angle = self._body_angle(c_g, ground, flip, z_face)
        out = (self._horn_output if entry.horn is not None else self._shaft_output)(driven, pin, flip, z_face)
        pad = circle_hull(np.array([c for c, _ in out.pad_circles]), np.array([r for _, r in out.pad_circles]))
        new_driven = with_changes(driven, outline=fuse_pad(driven.outline, pad, self.tol), holes=out.holes,
                                  **({"slots": tuple(getattr(driven, "slots", ())) + out.slots} if out.slots else {}))
        clear, passes, ground_holes = self._ground_clearance(ground, pin, c_g, out)
        place_g = geo.Placement(c_g, angle, flip, z_face)
        solids = [*out.solids, *geo.body_solids(entry, place_g)]
        mount, mount_fasteners, standoffs, standoff_parts, mount_solids = self._mount(place_g, ground, flip)
        fasteners = [*out.fasteners, *mount_fasteners]
        solids += mount_solids
        new_ground = self._ground_part(ground, c_g, clear, passes, ground_holes)
        # the pin's spacers go with it (printed spacer parts too)
        removed = {p.name for p in ps.parts if p.role not in BODY_ROLES and any(h.joint == pin.joint for h in p.holes)}
        parts = [new_driven if p is driven else new_ground if p is ground else p
                 for p in ps.parts if p.name not in removed]
        parts += [mount, *standoff_parts]
        bom = self._bom(pin, removed, [new_driven, new_ground], [mount, *standoff_parts], fasteners, standoffs)
        from fabricate.parts.partset import overlapping_cuts

        warnings = tuple(ps.warnings) + tuple(w for w in overlapping_cuts([new_driven, new_ground, mount])
                                              if w not in ps.warnings)
        record = PlacedActuator(
            model=entry.key, name=entry.name, kind=entry.kind, driver=self.index, driver_kind="angle",
            joint=self.joint, driven_body=self.driven, ground_body=self.ground, axis=np.asarray(c_g, dtype=float),
            direction=away, angle=float(angle), z_face=float(z_face), flip=flip, removed_pin=pin.joint,
            interface=out.interface,
            mount_part=mount.name, fasteners=tuple(fasteners), standoffs=tuple(standoffs), solids=tuple(solids),
            notes=tuple(self.notes))
        return dataclasses.replace(ps, parts=tuple(parts), pins=tuple(p for p in ps.pins if p is not pin),
                                   spacers=tuple(s for s in ps.spacers if s.joint != pin.joint), bom=bom,
                                   warnings=warnings, actuator=record)

    def _side(self, driven: Part, ground: Part) -> tuple[bool, float]:
        """Which side of the stack the actuator goes (``flip``: over it) and the stack z of its output face: the
        side whose parts keep clear of it; the ground's side loses a tie (its hole would have to clear the
        horn)."""
        faces = {side: self._face(side, driven) for side in (True, False)}
        costs = {side: self._conflicts(side, driven, faces[side]) + (0.5 if (ground.layer < driven.layer) != side
                                                                      else 0.0) for side in (True, False)}
        flip = min((True, False), key=lambda side: costs[side])
        z_face = faces[flip]
        if not math.isfinite(z_face):
            raise SpecError("actuator.model", f"{self.entry.key!r}: its shaft does not reach half way into the "
                                              f"driven part {driven.name} across the stack on either side")
        return flip, z_face

    def _body_angle(self, c_g: np.ndarray, ground: Part, flip: bool, z_face: float) -> tuple[np.ndarray, float]:
        """The direction away from what moves, and the body's angle about the axis (ground frame): the body's
        centre (off the axis for a servo or a 28BYJ-48) points away from what moves."""
        away = self._away(c_g)
        env = self.entry.envelope
        ex = np.array([0.5 * (env.x0 + env.x1), 0.5 * (env.y0 + env.y1)]) if env is not None else np.zeros(2)
        if flip:
            ex = ex * np.array([1.0, -1.0])
        angle = math.atan2(away[1], away[0]) - (math.atan2(ex[1], ex[0]) if float(np.hypot(*ex)) > 1e-6 else 0.0)
        return away, self._orient(angle, c_g, ground, flip, z_face)

    def _horn_output(self, driven: Part, pin: Any, flip: bool, z_face: float) -> _Output:
        """A servo's horn screwed to the driven part: hub bore, the arm screws' pilots, spline, horn and heads."""
        entry = self.entry
        horn, spline = entry.horn, entry.spline
        assert horn is not None and spline is not None  # a servo entry has both (catalogue)
        c_d = self.mechanism.body(self.driven).point(self.joint)
        alpha = self._arm_angle()
        holes = [h for h in driven.holes if h.joint != pin.joint]
        seat0, seat1 = geo.horn_seat_z(entry)
        bore, size, pilot, horn_screw, used = self._horn_layout(float(driven.thickness_mm))
        at = geo.horn_pattern(used, c_d, alpha, flip)
        holes.append(fit_hole("actuator_hub", c_d, bore, self.comp, fit="clearance"))
        interface = ["actuator_hub"]
        pad_circles: list[tuple[np.ndarray, float]] = []
        for k, centre in enumerate(at):
            holes.append(fit_hole(f"actuator_horn_{k + 1}", centre, pilot, self.comp, fit="tapped"))
            interface.append(f"actuator_horn_{k + 1}")
            pad_circles.append((centre, 0.5 * (pilot + self.comp) + self.wall))
        pad_circles.append((c_d, 0.5 * (bore + self.comp) + self.wall))
        place_d = geo.Placement(c_d, alpha, flip, z_face)
        hole_d = min(h.diameter_mm for h in horn.arm_holes)
        arm = geo.trimmed_horn_ring(at, c_d, horn.hub_d_mm, hole_d, self.tol)
        arm0 = seat1 - horn.arm_thickness_mm
        solids = [geo.Solid("actuator_spline", "output", (geo.circle_ring(c_d, spline.diameter_mm, self.tol),),
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
        fastener = Fastener(horn_screw.designation, len(at), "driven part to the horn, up through its "
                            "arms into the part (taps into the part)", horn_screw.clamp_mm, horn_screw.engagement_mm)
        ring_r = math.hypot(used[0].x, used[0].y)
        self.notes.append(f"open the horn's arm holes {ring_r:g} mm from its axis to Ø"
                          f"{ISO7089[size][0]:g} mm for the {size} screws and cut the arms back one hole past "
                          "them; screw the horn to the driven part, press it on the spline, then drive the "
                          "horn's centre screw through the hub bore")
        # what passes the ground part: the horn where it overlaps its thickness, else the hub and its screw
        heads = ring_r + 0.5 * horn_screw.head_d_mm
        passing = ((geo.output_base_z(entry), seat0, spline.diameter_mm), (seat0, seat1, 2.0 * reach),
                   (arm0 - horn_screw.head_h_mm, arm0, 2.0 * heads))
        return _Output(place_d, tuple(holes), (), tuple(pad_circles), tuple(interface), tuple(solids), (fastener,),
                       passing, bore)

    def _shaft_output(self, driven: Part, pin: Any, flip: bool, z_face: float) -> _Output:
        """A shaft (or a servo's bare spline) in a bore of the driven part: flats where the shaft has them."""
        entry = self.entry
        c_d = self.mechanism.body(self.driven).point(self.joint)
        alpha = self._arm_angle()
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
        place_d = geo.Placement(c_d, alpha, flip, z_face)
        solid = geo.Solid("actuator_shaft" if entry.shaft is not None else "actuator_spline", "output",
                          (geo.circle_ring(c_d, shaft.diameter_mm, self.tol),), *place_d.z_range(base, shaft.length_mm))
        return _Output(place_d, tuple(h for h in driven.holes if h.joint != pin.joint),
                       (geo.shaft_bore(shaft, c_d, alpha, radial),),
                       ((c_d, 0.5 * shaft.diameter_mm + radial + self.wall),),
                       ("actuator_shaft_bore" if entry.shaft is not None else "actuator_spline_bore",), (solid,), (),
                       ((base, shaft.length_mm, shaft.diameter_mm),), shaft.diameter_mm + 2.0 * self.c)

    def _ground_clearance(self, ground: Part, pin: Any, c_g: np.ndarray,
                          out: _Output) -> tuple[float, bool, list[Hole]]:
        """The ground's hole at the joint: a clearance for whatever of the output passes its thickness. Returns
        its nominal size, whether anything passes, and the ground's holes with it in the pin's hole's place."""
        g0, g1 = float(ground.z_mm), float(ground.z_mm + ground.thickness_mm)
        passes = []
        for z0, z1, diameter in out.passing:
            lo, hi = out.place.z_range(z0, z1)
            if lo < g1 - 1e-9 and hi > g0 + 1e-9:
                passes.append(diameter + 2.0 * self.c)
        old = next(h for h in ground.holes if h.joint == pin.joint)
        # nothing passes (the ground lies beyond the driven part): the pin's hole stays as it was
        clear = max([out.default_clear, *passes]) if passes else old.nominal_mm
        ground_holes = [h for h in ground.holes if h.joint != pin.joint]
        ground_holes.append(fit_hole("actuator_clearance", c_g, clear, self.comp, fit="clearance"))
        return clear, bool(passes), ground_holes

    def _ground_part(self, ground: Part, c_g: np.ndarray, clear: float, passes: bool,
                     ground_holes: list[Hole]) -> Part:
        """The ground part with the clearance (padded where the output passes) and what the mount changed in
        it (resized and new holes, arms out to the mount plate)."""
        ground_pad = circle_hull(np.asarray(c_g, dtype=float)[None, :], 0.5 * (clear + self.comp) + self.wall)
        resized = {h.joint: h for h in self.resized_ground_holes}
        holes = [resized.get(h.joint, h) for h in ground_holes] + self.new_ground_holes
        outline = fuse_pad(ground.outline, ground_pad, self.tol) if passes else ground.outline
        if self.ground_arms:
            outline = fuse_polygons(outline, list(self.ground_arms), self.tol)
        return with_changes(ground, outline=outline, holes=tuple(holes))

    def _bom(self, pin: Any, removed: set[str], changed: list[Part], added: list[Part],
             fasteners: list[Fastener], standoffs: Any) -> list[dict[str, Any]]:
        """The BOM without the pin and its spacers, with the changed and added parts, the actuator, its screws
        and its bought standoff tubes."""
        entry, ps = self.entry, self.ps
        bom = bom_without(ps.bom, pin, [s for s in ps.spacers if s.joint == pin.joint], removed, changed,
                          self.process, ps.copies)
        from fabricate.parts.bom import part_rows

        bom += part_rows(added, self.process, ps.copies)
        bom.append(purchased_row(entry.name, ps.copies, f"{entry.kind} driving {self.driven} about {self.joint} "
                                 f"(catalogue {entry.key!r})", model=entry.key))
        bom += [screw_row(f, ps.copies) for f in fasteners]
        tubes: dict[str, int] = {}
        for s in standoffs:
            if not s.printed:
                item = f"standoff tube {s.inner_diameter_mm:.3g}/{s.outer_diameter_mm:.3g} x {s.length_mm:.2f} mm"
                tubes[item] = tubes.get(item, 0) + ps.copies
        bom += [purchased_row(item, qty, "actuator mount standoff, cut to length") for item, qty in tubes.items()]
        return bom
