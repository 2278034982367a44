"""Torsion springs placed in their pin's stack: sized over the joint's real angle range, anchored, drawn.

Where a synthesis gives a return spring (:class:`~fabricate.hints.SpringHint`: joint, rate, preload, leg
length), :func:`place_springs` sizes a music-wire torsion spring with
:func:`fabricate.catalogue.springs.torsion_spring` over the deflection the motion really asks of it
(preload plus the joint's travel, with the strength check's sign convention) and places it:

* **On the pin's extension beyond the stack**, seated on the outer face of the end plate of one of the two
  bodies it joins (the end away from a pressed pin's holder first, so its press fit stays as it is). There
  the layers, spacers and washers of the stack stay as they are (a coil between two plates would push them
  apart and change every layer above), the pin keeps the coil on the joint's axis, and the pin's
  retention beyond the coil (a clip) also keeps the spring on. The pin grows by the coil's wound body
  length, as long as the lengthened pin is still a standard one its retention fits (:func:`_seat` asks
  the retention's own plan). Where it is not (a long coil on a thin pin: the gripper's 27 mm coil on its
  Ø3 pin, whose standard lengths end at 30 mm), the coil rides instead on a printed arbor tube bonded to
  that plate's face round the pin's end, as large as the coil's wound inside diameter allows.
* **Legs hooked into anchor holes in the two bodies.** The near leg runs out radially along the face of
  the plate it sits on and its end is bent axially into an anchor hole in that plate. The far leg runs out
  radially at the coil's far end, then axially back along the pin, outside the plates in between, into an
  anchor hole in the other body's plate. Each anchor is a hole of the leg wire plus the running clearance
  and the process's compensation, at the leg length from the pin where the plate has the process's wall
  around it; the far one also where its leg keeps the running clearance from the near plate over the
  whole motion (:func:`~fabricate.parts.spring_anchors.anchor_point`). The interference sweep proves the
  rest (:func:`spring_sweep_items`).
* **Wound the right way**: a torsion spring must be loaded to wind up (its coil closes); a right-hand coil
  winds up when its upper end turns counter-clockwise, seen from above, against its lower end.

A spring no wire of the series can make within its allowable stress is still placed (the thickest wire,
the largest coil: :func:`_overloaded`) and is a strength failure naming it (:func:`spring_failures`).
Nothing here draws or writes; :mod:`fabricate.parts.build` calls :func:`place_springs`, the strength stage
:func:`spring_failures` and :func:`springs_report`, the checks :func:`spring_sweep_items`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.catalogue._units import INCH_MM, KSI_MPA
from fabricate.catalogue.springs import (
    ALLOWABLE_FRACTION,
    ARBOR_RATIO,
    INDEX_RANGE,
    MIN_TURNS,
    MUSIC_WIRE_IN_KSI,
    TorsionSpring,
    curvature_factor,
    music_wire_modulus_mpa,
    rate_per_deg,
    torsion_spring,
)
from fabricate.errors import SpecError
from fabricate.mechanism import Mechanism, Motion, Revolute
from fabricate.parts.model import Hole, Part, circle_polygon
from fabricate.parts.spring_anchors import ANCHOR_POSES, anchor_point, plate_material, to_frame, towards

if TYPE_CHECKING:
    from fabricate.parts.bom import Pin
    from fabricate.process import ProcessSpec

@dataclass(frozen=True)
class PlacedSpring:
    """A torsion spring on its pin, with its anchors.

    Attributes
    ----------
    joint : str
        The spring's joint (a revolute of the mechanism).
    pin : str
        The pin it sits on (``joint`` itself, or a compound pin such as ``G1+G1r``).
    spring : TorsionSpring
        Wire, coil, turns, rate, stress and allowable (the catalogue's record).
    near_body, far_body : str
        The body whose end plate the coil sits on, and the other body of the joint.
    near_part, far_part : str
        The parts of those bodies the anchors are in.
    side : str
        ``"top"`` (the coil above the stack) or ``"bottom"``.
    pin_body : str
        The body the pin is fixed in (the coil is drawn on it: a coil is round, it reads the same in both).
    centre : (2,) array
        The pin's axis in ``pin_body`` coordinates, mm.
    z_mm : (float, float)
        The coil's span along the pin, wound up (mm, the assembly's z).
    near_anchor, far_anchor : (2,) arrays
        Anchor hole centres in the near and far bodies' coordinates, mm.
    near_axis, far_axis : (2,) arrays
        The pin's axis in the near and far bodies' coordinates, mm.
    leg_radii_mm : (float, float)
        Near and far anchor distance from the pin axis (the legs' radial lengths), mm.
    leg_axial_mm : (float, float)
        Near and far legs' axial runs from the coil's end into their anchor holes, mm.
    anchor_hole_mm : float
        Anchor hole diameter (wire, running clearance, process compensation).
    deflection_deg : (float, float)
        Least and largest deflection from free over the motion (the first pose is at the preload).
    hand : str
        ``"LH"`` or ``"RH"``: the coil's winding, so that the motion winds it up.
    free_angle_deg : float
        Angle between the legs when free, from the near leg to the far leg, counter-clockwise seen from
        above (+z), degrees in [0, 360).
    within_series : bool
        False when no wire of the series meets the stress: :attr:`spring` is then the thickest wire's
        largest coil, over its allowable.
    note : str
        What it is for (the synthesis' words).
    arbor : str
        The printed arbor part the coil rides on where the pin cannot be lengthened to carry it ('': the
        pin's extension carries it).
    """

    joint: str
    pin: str
    spring: TorsionSpring
    near_body: str
    far_body: str
    near_part: str
    far_part: str
    side: str
    pin_body: str
    centre: np.ndarray
    z_mm: tuple[float, float]
    near_anchor: np.ndarray
    far_anchor: np.ndarray
    near_axis: np.ndarray
    far_axis: np.ndarray
    leg_radii_mm: tuple[float, float]
    leg_axial_mm: tuple[float, float]
    anchor_hole_mm: float
    deflection_deg: tuple[float, float]
    hand: str
    free_angle_deg: float
    within_series: bool
    note: str = ""
    arbor: str = ""

    @property
    def anchor_joint(self) -> str:
        """The anchor holes' name on both parts (``spring_<joint>``)."""
        return f"spring_{self.joint}"

    @property
    def passed(self) -> bool:
        """Whether the wire's bending stress at the largest deflection is within its allowable, and the motion
        never turns the spring back past free (a torsion spring opened against its winding is loaded the way
        it must not be, and no longer returns the joint)."""
        return (self.within_series and self.spring.stress_mpa <= self.spring.allowable_mpa * (1.0 + 1e-9)
                and self.deflection_deg[0] >= -1e-6)

    @property
    def designation(self) -> str:
        """The spring as a spring maker is asked for it (the BOM's item)."""
        s = self.spring
        near, far = self.leg_radii_mm
        return (f"torsion spring, music wire Ø{s.wire_d_mm:.2f}, D {s.mean_d_mm:.2f}, {s.active_turns:.2f} turns, "
                f"legs {near:.1f}/{far:.1f} mm, {self.hand}")

    def description(self) -> str:
        """The rest a spring maker needs, in words (the BOM's description)."""
        s = self.spring
        near, far = self.leg_axial_mm
        return (f"{s.material} Ø{s.wire_d_mm:.3f} mm ({s.wire_d_in:.3f} in), OD {s.outer_d_mm:.2f} mm, close wound, "
                f"leg ends bent axially {near:.1f}/{far:.1f} mm, free leg angle {self.free_angle_deg:.0f}°, "
                f"{s.rate_nmm_per_deg:.4g} N·mm/°, wound {self.deflection_deg[0]:.1f}° at assembly; "
                f"{self.note}".rstrip("; "))


def _get(hint: Any, name: str, default: Any = None) -> Any:
    """A hint's field, from a :class:`~fabricate.hints.SpringHint` or a plain mapping."""
    if isinstance(hint, Mapping):
        return hint.get(name, default)
    return getattr(hint, name, default)


def spring_deflections(mechanism: Mechanism, motion: Motion, joint: Revolute, preload_deg: float
                       ) -> tuple[np.ndarray, float]:
    """Deflection from free (degrees) at every pose, and the sense (+1/-1) in which body_b turns against
    body_a to wind it up: the strength check's convention (a return spring resists the motion)."""
    rel = np.degrees(motion.relative_angle(joint.body_b, joint.body_a))
    sense = 1.0 if rel[-1] >= rel[0] else -1.0
    return preload_deg + sense * (rel - rel[0]), sense


def _overloaded(rate: float, work_deg: float, preload_nmm: float, legs: tuple[float, float],
                pin_mm: float) -> TorsionSpring:
    """The spring of the thickest wire of the series and its largest coil (least stress) when no wire
    meets the stress: the same formulas as :func:`~fabricate.catalogue.springs.torsion_spring`, stress over
    the allowable (reported as a failure, never shipped as passing)."""
    d_in, sut_ksi = MUSIC_WIRE_IN_KSI[-1]
    d = d_in * INCH_MM
    e = music_wire_modulus_mpa(d_in)
    sut = sut_ksi * KSI_MPA
    theta = preload_nmm / rate + work_deg
    a = e * d**4 / (10.8 * rate * 360.0)          # D·N fixed by the rate
    mean_d = max(min(INDEX_RANGE[1] * d, a / MIN_TURNS), d + pin_mm / ARBOR_RATIO)
    turns = a / mean_d
    wound = theta / 360.0
    m_max = rate * theta
    kb = curvature_factor(mean_d / d)
    return TorsionSpring(
        material="music wire", wire_d_mm=d, wire_d_in=d_in, mean_d_mm=mean_d, active_turns=turns,
        leg_lengths_mm=legs, rate_nmm_per_deg=rate_per_deg(e, d, mean_d, turns), preload_nmm=preload_nmm,
        preload_angle_deg=preload_nmm / rate, max_deflection_deg=theta, max_torque_nmm=m_max,
        inner_d_wound_mm=mean_d * turns / (turns + wound) - d, pin_diameter_mm=pin_mm,
        body_length_free_mm=d * (turns + 1.0), body_length_wound_mm=d * (turns + 1.0 + wound),
        index=mean_d / d, curvature_factor=kb, stress_mpa=kb * 32.0 * m_max / (math.pi * d**3),
        allowable_mpa=ALLOWABLE_FRACTION * sut, tensile_min_mpa=sut, modulus_mpa=e, sources=())


def _part_of(parts: Sequence[Part], body: str, joint: str) -> Part:
    """The part of ``body`` with the hole of pin ``joint``."""
    for part in parts:
        if part.body == body and part.role != "spacer" and any(h.joint == joint for h in part.holes):
            return part
    raise SpecError("springs", f"no part of body {body!r} holds pin {joint!r}")


def _ends(pin: Pin, parts_by: Mapping[str, Part], process: ProcessSpec) -> list[tuple[str, str]]:
    """The stack's ends whose outer plate is one of the spring's two bodies, as ``(side, body)``: the end
    away from a pressed pin's holder first (there the pin's press fit is left as it is)."""
    z0, z1 = float(pin.z_mm), float(pin.z_mm) + float(pin.length_mm)
    ends = [("top", b) for b, p in parts_by.items() if abs(p.z_mm + p.thickness_mm - z1) < 1e-6]
    ends += [("bottom", b) for b, p in parts_by.items() if abs(p.z_mm - z0) < 1e-6]
    press = process.retention == "press"
    ends.sort(key=lambda e: press and e[1] == pin.bodies[0])  # a stable sort
    return ends


def _on_pin(pin: Pin, parts: Sequence[Part], ends: Sequence[tuple[str, str]], length: float,
            process: ProcessSpec, ground: str) -> tuple[str, str] | None:
    """The first end where the pin lengthened by ``length`` is still a standard pin its retention fits (the
    retention's own plan, :func:`~fabricate.parts.retention.plan_pin`, is asked); None: no end."""
    from fabricate.parts.retention import plan_pin

    z0, z1 = float(pin.z_mm), float(pin.z_mm) + float(pin.length_mm)
    press = process.retention == "press"
    holder = pin.bodies[0]
    first = next((p for p in parts if p.body == holder and p.role != "spacer"
                  and any(h.joint == pin.joint for h in p.holes)), None)
    for side, body in ends:
        stack = (z0, z1 + length) if side == "top" else (z0 - length, z1)
        try:
            plan_pin(pin.joint, process, stack, holder if press and first is not None else "",
                     (first.z_mm, first.z_mm + first.thickness_mm) if first is not None else None)
        except SpecError:
            continue
        return side, body
    return None


def _room_blocked(pin: Pin, side: str, length: float, radius: float, parts: Sequence[Part], motion: Motion,
                  process: ProcessSpec) -> bool:
    """Whether a part of another stack comes within the running clearance of a coil of ``radius`` (mm) standing
    ``length`` mm beyond the ``side`` face of the pin's stack (with the pin's retention reach beyond it),
    anywhere over the motion: the room the layer order could not know of (it orders the stacks before the
    springs are placed)."""
    from fabricate.parts.layers import MAX_CONFLICT_POSES, min_distance_over_motion
    from fabricate.parts.retention import end_reach_mm
    from fabricate.planar import relative_poses

    z0, z1 = float(pin.z_mm), float(pin.z_mm) + float(pin.length_mm)
    reach = end_reach_mm(process, z1 - z0 + length)
    reach = 0.0 if not math.isfinite(reach) else reach
    room = (z1, z1 + length + reach) if side == "top" else (z0 - length - reach, z0)
    body = pin.bodies[0]
    hole = next((h for p in parts if p.body == body for h in p.holes if h.joint == pin.joint), None)
    if hole is None:
        return False
    disc = circle_polygon(np.asarray(hole.centre, dtype=np.float64), 2.0 * radius, process.chord_tolerance_mm)
    k = len(motion.inputs)
    pick = np.unique(np.linspace(0, max(k - 1, 0), min(k, MAX_CONFLICT_POSES)).round().astype(int))
    for part in parts:
        if part.body in pin.bodies and any(h.joint == pin.joint for h in part.holes):
            continue  # the pin's own stack
        if part.z_mm + part.thickness_mm <= room[0] + 1e-9 or part.z_mm >= room[1] - 1e-9:
            continue
        rel = relative_poses(motion.pose(body)[pick], motion.pose(part.body)[pick])
        clear = process.running_clearance_mm
        outline = part.outline.polygon(process.chord_tolerance_mm)
        if min_distance_over_motion(disc, outline, rel, within=clear) < clear:
            return True
    return False


def _arbor_mm(pin: Pin, process: ProcessSpec) -> float:
    """The least arbor tube: the pin's running hole with the process's wall round it."""
    from fabricate.parts.retention import hole_size

    return hole_size(process, float(pin.diameter_mm), "running").modelled_mm + 2.0 * process.min_wall_mm


def _sized(rate: float, work: float, preload: float, legs: tuple[float, float],
           arbor: float) -> tuple[TorsionSpring, bool]:
    """The catalogue's spring on an arbor of ``arbor`` mm, or the over-stressed stand-in (and False)."""
    try:
        return torsion_spring(rate, work, rate * preload, legs, arbor), True
    except SpecError:
        return _overloaded(rate, work, rate * preload, legs, arbor), False


def _arbor_part(name: str, near: Part, joint: str, diameter: float, z: tuple[float, float],
                process: ProcessSpec) -> Part:
    """A printed (or cut) tube the coil rides on, bonded to the near plate's outer face, its bore the pin's
    running hole."""
    from fabricate.parts.profiles import circle_hull
    from fabricate.parts.retention import hole_size

    centre = np.asarray(next(h.centre for h in near.holes if h.joint == joint), dtype=np.float64)
    bore = next(h for h in near.holes if h.joint == joint)
    size = hole_size(process, bore.pin_diameter_mm or float(process.pin_diameter_mm), "running")
    # its bore is named apart from the pin's holes: the pin does not reach into it (a pin's stack, its
    # bending span and its retention stay those of the plates)
    return Part(name=name, body=near.body, outline=circle_hull(centre[None, :], np.array([0.5 * diameter])),
                holes=(Hole(f"arbor_{joint}", centre, size.modelled_mm, 0.0, "running", size.nominal_mm),),
                thickness_mm=z[1] - z[0], z_mm=z[0], layer=near.layer, process=process.name, role="arbor")


@dataclass(frozen=True)
class _SpringAt:
    """A spring hint resolved on its joint and pin: what sizing, seating and anchoring it read."""

    name: str
    joint: Revolute
    k: int
    pin: Pin
    rate: float
    preload: float
    work: float
    legs: tuple[float, float]
    deflection: np.ndarray
    sense: float
    parts_by: dict[str, Part]


@dataclass(frozen=True)
class _Anchors:
    """The legs' anchor holes: centres and radii from the pin in the near and far plates, the hole (modelled
    mm), and the pin's axis in each body's frame."""

    near_at: np.ndarray
    near_r: float
    far_at: np.ndarray
    far_r: float
    hole: float
    axis: dict[str, np.ndarray]


def place_springs(hints: Sequence[Any], mechanism: Mechanism, motion: Motion, parts: Sequence[Part],
                  pins: Sequence[Pin], process: ProcessSpec,
                  ground: str = "") -> tuple[tuple[PlacedSpring, ...], list[Part], list[Pin]]:
    """Size and place every spring of the hints; the parts get their anchor holes, the pins their extension.

    Parameters
    ----------
    hints : sequence of SpringHint (or mappings with its fields)
        A rate of 0 means no spring there (the compliant optimum may set k1 = 0).
    mechanism, motion
        The joint's angle range over the motion sets the deflection.
    parts, pins
        The body parts (anchor holes are added to copies) and the pins (the spring's pin is lengthened by the
        coil's wound body).
    process : ProcessSpec
        Running clearance, hole compensation and minimum wall of the anchor holes; chord tolerance; the
        retention whose standard pins must still carry a lengthened pin.
    ground : str
        The ground body (a pressed pin's holder there leaves its mounting face flush).

    Returns
    -------
    (springs, parts, pins)

    Raises
    ------
    GeometryError
        A spring at a joint that is not a revolute of a pin, or a plate with no room for its anchor.
    """
    placed: list[PlacedSpring] = []
    parts = list(parts)
    pins = list(pins)
    for hint in hints:
        at = _spring_at(hint, mechanism, motion, parts, pins)
        if at is None:
            continue  # no spring there
        spring, within, (side, near), arbor_od = _seat_coil(at, parts, motion, process, ground)
        far = at.joint.body_a if near == at.joint.body_b else at.joint.body_b
        z, arbor = _fit_coil(at, spring, side, at.parts_by[near], arbor_od, parts, pins, process)
        anchors = _leg_anchors(at, spring, within, near, far, motion, process)
        _add_anchor_holes(parts, at, (near, far), anchors, process)
        placed.append(_placed(hint, at, spring, within, side, (near, far), z, arbor, anchors, motion, parts))
    return tuple(placed), parts, pins


def _spring_at(hint: Any, mechanism: Mechanism, motion: Motion, parts: Sequence[Part],
               pins: Sequence[Pin]) -> _SpringAt | None:
    """A hint on its revolute joint and pin, with the deflection the motion asks of it (None: a rate of 0)."""
    from fabricate.errors import GeometryError

    rate = float(_get(hint, "rate_Nmm_per_deg", 0.0) or 0.0)
    name = str(_get(hint, "joint", ""))
    if rate <= 0.0:
        return None
    joint = next((j for j in mechanism.joints if j.name == name), None)
    k = next((i for i, p in enumerate(pins) if name in p.joint.split("+")), None)
    if not isinstance(joint, Revolute) or k is None:
        raise GeometryError(f"spring at {name!r}: not a revolute joint with a pin")
    pin = pins[k]
    preload = float(_get(hint, "preload_deg", 0.0) or 0.0)
    legs_hint = _get(hint, "legs_mm")
    deflection, sense = spring_deflections(mechanism, motion, joint, preload)
    work = max(float(deflection.max()) - preload, 1e-6)
    try:
        parts_by = {b: _part_of(parts, b, pin.joint) for b in (joint.body_a, joint.body_b)}
    except SpecError as exc:
        raise GeometryError(f"spring at {name}: {exc}") from None
    # no leg length given: 2.5 x (pin + 2 mm), a design choice (long enough to reach past a boss)
    legs_default = float(legs_hint) if legs_hint else 2.5 * (float(pin.diameter_mm) + 2.0)
    return _SpringAt(name, joint, k, pin, rate, preload, work, (legs_default, legs_default), deflection, sense,
                     parts_by)


def _seat_coil(at: _SpringAt, parts: Sequence[Part], motion: Motion, process: ProcessSpec,
               ground: str) -> tuple[TorsionSpring, bool, tuple[str, str], float]:
    """The spring (and whether it is within the series), the end of the stack it sits on (side, near body),
    and the arbor's outside diameter (0: the coil rides on the pin's extension)."""
    from fabricate.errors import GeometryError

    pin = at.pin
    ends = _ends(pin, at.parts_by, process)
    spring, within = _sized(at.rate, at.work, at.preload, at.legs, float(pin.diameter_mm))
    # an end whose room beyond the stack no other part sweeps first (a stable sort)
    coil_r = 0.5 * spring.outer_d_mm + spring.wire_d_mm + process.running_clearance_mm
    ends.sort(key=lambda e: _room_blocked(pin, e[0], spring.body_length_wound_mm, coil_r, parts, motion,
                                          process))
    seat = _on_pin(pin, parts, ends, spring.body_length_wound_mm, process, ground)
    arbor_od = 0.0
    if seat is None and ends:
        # the coil cannot ride on the pin's extension: on a printed arbor round the pin's end, the coil
        # sized to clear the arbor as the catalogue clears a pin
        arbor_min = _arbor_mm(pin, process)
        spring, within = _sized(at.rate, at.work, at.preload, at.legs, arbor_min)
        arbor_od = max(arbor_min, math.floor(ARBOR_RATIO * spring.inner_d_wound_mm * 10.0 + 1e-9) / 10.0)
        seat = ends[0]
    if seat is None:
        raise GeometryError(f"spring at {at.name}: no end of pin {pin.joint}'s stack is one of the joint's plates "
                            "to seat the coil on")
    return spring, within, seat, arbor_od


def _fit_coil(at: _SpringAt, spring: TorsionSpring, side: str, near_part: Part, arbor_od: float,
              parts: list[Part], pins: list[Pin], process: ProcessSpec) -> tuple[tuple[float, float], str]:
    """Make room for the coil beyond the stack's ``side`` end: a printed arbor on the near plate (added to
    ``parts``), else the pin lengthened (in ``pins``). Returns the coil's z span and the arbor's name ('')."""
    pin = at.pin
    length = spring.body_length_wound_mm
    z_top = pin.z_mm + pin.length_mm
    z = (z_top, z_top + length) if side == "top" else (pin.z_mm - length, pin.z_mm)
    arbor = ""
    if arbor_od:
        # the coil rides on a printed arbor bonded to the near plate's outer face (the pin is not lengthened)
        arbor = f"spring_arbor_{at.name}"
        parts.append(_arbor_part(arbor, near_part, pin.joint, arbor_od, z, process))
    elif side == "top":
        pins[at.k] = replace(pin, length_mm=pin.length_mm + length)
    else:
        pins[at.k] = replace(pin, length_mm=pin.length_mm + length, z_mm=pin.z_mm - length)
    return z, arbor


def _leg_anchors(at: _SpringAt, spring: TorsionSpring, within: bool, near: str, far: str, motion: Motion,
                 process: ProcessSpec) -> _Anchors:
    """Where the legs' ends go: a hole for the leg wire in each plate, the far one clear of the near plate."""
    from fabricate.errors import GeometryError

    tol = process.chord_tolerance_mm
    near_part, far_part, legs = at.parts_by[near], at.parts_by[far], at.legs
    # anchors: the leg wire plus the running fit and the compensation, with the process's wall round it
    hole = spring.wire_d_mm + 2.0 * process.running_clearance_mm + process.hole_compensation_mm
    keep = 0.5 * hole + process.min_wall_mm
    r_min = 0.5 * spring.outer_d_mm + spring.wire_d_mm + process.running_clearance_mm
    axis = {b: next(h.centre for h in at.parts_by[b].holes if h.joint == at.pin.joint) for b in at.parts_by}
    pick = np.unique(np.linspace(0, len(motion.inputs) - 1, min(ANCHOR_POSES, len(motion.inputs)))
                     .round().astype(int))
    near_material, far_material = plate_material(near_part, tol), plate_material(far_part, tol)
    try:
        near_at, near_r = anchor_point(near_material, np.asarray(axis[near], dtype=np.float64), legs[0],
                                  r_min, keep)
        gap = 0.5 * spring.wire_d_mm + process.running_clearance_mm + tol
        far_at, far_r = anchor_point(far_material, np.asarray(axis[far], dtype=np.float64), legs[1], r_min, keep,
                                (near_material, motion.pose(far)[pick], motion.pose(near)[pick], gap))
    except SpecError:
        if within:
            raise GeometryError(f"spring at {at.name}: no place for its leg anchors in {near_part.name} and "
                                f"{far_part.name} within {legs[0]:g} mm of the pin; give longer legs or wider "
                                "plates") from None
        # a spring over its allowable fails the strength check by name; its anchors only stand in: out
        # from the pin towards each plate's middle, clear of the oversized coil
        near_r = far_r = max(legs[0], r_min)
        near_at = towards(near_material, np.asarray(axis[near], dtype=np.float64), near_r)
        far_at = towards(far_material, np.asarray(axis[far], dtype=np.float64), far_r)
    return _Anchors(near_at, near_r, far_at, far_r, hole, axis)


def _add_anchor_holes(parts: list[Part], at: _SpringAt, bodies: tuple[str, str], anchors: _Anchors,
                      process: ProcessSpec) -> None:
    """The legs' anchor holes into the near and far plates (copies in ``parts``)."""
    # a running fit for the leg's end: the nominal (finished) size apart from the process's compensation
    nominal = anchors.hole - process.hole_compensation_mm
    near_part, far_part = at.parts_by[bodies[0]], at.parts_by[bodies[1]]
    for part, centre in ((near_part, anchors.near_at), (far_part, anchors.far_at)):
        extra = Hole(f"spring_{at.name}", centre, anchors.hole, 0.0, "running", nominal)
        idx = next(i for i, p in enumerate(parts) if p.name == part.name)
        parts[idx] = replace(parts[idx], holes=tuple(parts[idx].holes) + (extra,))


def _placed(hint: Any, at: _SpringAt, spring: TorsionSpring, within: bool, side: str, bodies: tuple[str, str],
            z: tuple[float, float], arbor: str, anchors: _Anchors, motion: Motion,
            parts: Sequence[Part]) -> PlacedSpring:
    """The placed spring's record: its legs' runs, the hand it is wound and its free angle."""
    near, far = bodies
    near_part, far_part, pin, axis = at.parts_by[near], at.parts_by[far], at.pin, anchors.axis
    # axial runs: the near leg's end into its plate (half its thickness); the far leg from the coil's far
    # end back past the coil and the plates between, to the middle of the far plate
    mid_far = far_part.z_mm + 0.5 * far_part.thickness_mm
    far_end = z[1] if side == "top" else z[0]
    axial = (0.5 * near_part.thickness_mm, abs(far_end - mid_far))
    # which end is up: winding up = the upper leg turning counter-clockwise (seen from above) against the
    # lower one for a right-hand coil; the far body turns against the near one by sense (body_b vs body_a)
    far_turn = at.sense if far == at.joint.body_b else -at.sense
    upper_turn = far_turn if side == "top" else -far_turn
    hand = "RH" if upper_turn > 0 else "LH"
    # leg angle (near to far, in the near frame) at the first pose, less the preload the way it winds
    p0_near, p0_far = motion.pose(near)[0], motion.pose(far)[0]
    far_in_near = to_frame(np.asarray([anchors.far_at, axis[far]]), p0_far[None, :], p0_near[None, :])[0]
    v_far = far_in_near[0] - far_in_near[1]
    v_near = anchors.near_at - axis[near]
    assembled = math.degrees(math.atan2(v_far[1], v_far[0]) - math.atan2(v_near[1], v_near[0]))
    free = (assembled - far_turn * float(at.deflection[0])) % 360.0
    return PlacedSpring(
        joint=at.name, pin=pin.joint, spring=spring, near_body=near, far_body=far, near_part=near_part.name,
        far_part=far_part.name, side=side, pin_body=pin.bodies[0],
        centre=np.asarray(axis[pin.bodies[0]] if pin.bodies[0] in axis else
                          next(h.centre for p in parts if p.body == pin.bodies[0] for h in p.holes
                               if h.joint == pin.joint), dtype=np.float64),
        z_mm=(round(z[0], 6), round(z[1], 6)), near_anchor=np.asarray(anchors.near_at),
        far_anchor=np.asarray(anchors.far_at), near_axis=np.asarray(axis[near], dtype=np.float64),
        far_axis=np.asarray(axis[far], dtype=np.float64),
        leg_radii_mm=(round(float(anchors.near_r), 3), round(float(anchors.far_r), 3)),
        leg_axial_mm=(round(axial[0], 3), round(axial[1], 3)), anchor_hole_mm=anchors.hole,
        deflection_deg=(float(at.deflection.min()), float(at.deflection.max())), hand=hand, free_angle_deg=free,
        within_series=within, note=str(_get(hint, "note", "") or ""), arbor=arbor)
