"""Every body of a solved mechanism becomes a part: outline, pin holes, fused gears, layer and height.

Nothing here knows which paper a mechanism came from: the parts follow from the bodies' points, the
joints, the gear pairs, the process profile (``[process]``), the ``[parts]`` table and the synthesis
hints (pads, springs, purchased items, copies).

Shapes
------
- A body's profile is the exact convex hull of circles of the boss radius around each of its points
  (a rounded slot for a binary link; a single disc for a one-point body), plus the fingertip pad
  circle where a hint asks for one.
- Boss radius = hole radius + wall, wall = ``[parts] boss_wall_mm`` or max(process minimum wall, half the
  pin diameter; for laser also at least the sheet thickness, the minimum web); a requested link width
  widens it.
- A gear is fused (polygon union) with a hub to the body that carries it; the body's pin hole at the gear
  axis stays.
- A slider (push rod) becomes a rounded bar along the slide axis with a slot that runs on two guide pins
  fixed in the reference body (two pins so the rod cannot turn).
- The ground part gets mounting holes on the side away from the moving parts, pushed out until the
  screw heads clear everything that moves.
- Holes (:mod:`fabricate.parts.retention`): a NOMINAL size by fit — running pin + 2 x radial running
  clearance, press (the part holding a pressed pin) pin - the profile's interference, mounting screw
  + 2 x clearance — modelled with the process's hole compensation added (the laser kerf is applied by
  the DXF exporter only). Joints at one spot of a body (a compound hinge) share one hole and one pin.

Layers and pins
---------------
Bodies that come within the clearance of each other anywhere over the motion get different layers
(:mod:`fabricate.parts.layers`); meshing gears share one. The layers are then ordered so that no body
sweeps over a pin between the two layers it joins (there a spacer fills the skipped layers). Pins are
standard pins (ISO 8734 / ISO 2338) chosen for their stack and retention (:mod:`fabricate.parts.retention`);
spacers (SLA: printed parts when at least a layer thick) and standard washers fill the gaps.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.errors import GeometryError, SpecError
from fabricate.hints import PadHint, PartHints
from fabricate.mechanism import Mechanism, Motion, Revolute, Slider
from fabricate.parts.bom import (
    Spacer,
    bill_of_materials,
    mounting_rows,
    part_rows,
    pins_and_spacers,
    with_sources,
)
from fabricate.parts.features import pad_segment, slider_guides
from fabricate.parts.gear_seats import gear_outline_in_body, mesh_limits
from fabricate.parts.layers import (
    assign_layers,
    conflict_graph,
    layer_z,
    order_layers,
    pin_crossings,
    pin_neighbours,
)
from fabricate.parts.model import BulgePath, Hole, Part, circle_polygon
from fabricate.parts.partset import (
    CONFLICT_CHORD_MM,
    PartSet,
    SlottedPart,
    overlapping_cuts,
    safe_name,
    swept_region,
)
from fabricate.parts.profiles import circle_hull, fuse_polygons
from fabricate.parts.retention import cap_parts, choose_holder, end_radius_mm, end_reach_mm, hole_size, retain_pins
from fabricate.parts.spec import PartsSpec
from fabricate.parts.spring_rows import with_spring_rows
from fabricate.parts.springs import place_springs
from fabricate.process import ProcessSpec

if TYPE_CHECKING:  # the gears and the design sit above the parts layer
    from fabricate.gears.pair import GearPair
    from fabricate.spec import DesignSpec

@dataclass(frozen=True)
class Sizes:
    """Derived sizes (mm) of holes and bosses for a process."""

    pin_mm: float
    hole_mm: float
    boss_radius_mm: float
    mount_hole_mm: float
    mount_boss_radius_mm: float
    hub_mm: float
    hole_nominal_mm: float = 0.0
    press_hole_mm: float = 0.0
    press_nominal_mm: float = 0.0
    mount_nominal_mm: float = 0.0


def derive_sizes(process: ProcessSpec, parts: PartsSpec, hints: PartHints,
                 gear_hub_mm: float | None = None) -> Sizes:
    """Hole and boss sizes from the process and the ``[parts]`` table.

    Every hole has a nominal size by its fit (:func:`~fabricate.parts.retention.hole_size`) and is modelled
    with the process's hole compensation added (SLA prints holes undersize). The laser kerf is applied only to
    the cut path (DXF).
    """
    pin = process.pin_diameter_mm
    running, press = hole_size(process, pin, "running"), hole_size(process, pin, "press")
    hole = running.modelled_mm
    wall = parts.boss_wall_mm if parts.boss_wall_mm is not None else max(process.min_wall_mm, 0.5 * pin)
    if process.technique == "cut":
        wall = max(wall, process.thickness_mm)  # a web cut from sheet stock is at least the stock thick
    radius = hole / 2.0 + wall
    width = parts.link_width_mm if parts.link_width_mm is not None else hints.link_width_mm
    if width is not None:
        radius = max(radius, 0.5 * float(width))
    mounting = hole_size(process, parts.mounting_hole_mm, "clearance")
    mount = mounting.modelled_mm
    hub = parts.hub_diameter_mm or gear_hub_mm or 2.0 * radius
    return Sizes(pin_mm=pin, hole_mm=hole, boss_radius_mm=radius, mount_hole_mm=mount,
                 mount_boss_radius_mm=mount / 2.0 + wall, hub_mm=max(hub, hole + 2.0 * process.min_wall_mm),
                 hole_nominal_mm=running.nominal_mm, press_hole_mm=press.modelled_mm,
                 press_nominal_mm=press.nominal_mm, mount_nominal_mm=mounting.nominal_mm)


def build_parts(design: DesignSpec, mechanism: Mechanism, motion: Motion, gear_pairs: Sequence[GearPair],
                hints: PartHints | None = None) -> PartSet:
    """Turn a solved mechanism into parts.

    Parameters
    ----------
    design : DesignSpec
        Uses ``design.process``, ``design.parts`` and ``design.gears.hub_diameter_mm``.
    mechanism : Mechanism
    motion : Motion
        A sweep of the mechanism (layers are chosen over this motion).
    gear_pairs : sequence of GearPair
        Built gears; each gear is fused to the body that carries it.
    hints : PartHints, optional
        ``SynthesisResult.parts`` (pads, springs, purchased items, copies, link width).

    Returns
    -------
    PartSet

    Raises
    ------
    GeometryError
        When a hint names a point a body does not have, or a gear does not join its body.
    """
    hints = hints if hints is not None else PartHints()
    process: ProcessSpec = design.process
    parts_spec: PartsSpec = design.parts
    gear_hub = getattr(getattr(design, "gears", None), "hub_diameter_mm", None)
    sizes = derive_sizes(process, parts_spec, hints, gear_hub)
    tol = process.chord_tolerance_mm

    drawing = _Drawing.start(mechanism, sizes.boss_radius_mm)
    pin_joints = _add_joints(drawing, mechanism, motion, sizes, process)
    _add_pads(drawing, mechanism, hints.pads or {}, parts_spec, sizes.boss_radius_mm, tol)
    _add_gears(drawing, mechanism, gear_pairs, sizes.hub_mm, tol,
               mesh_limits(mechanism, motion, gear_pairs, process.running_clearance_mm),
               0.5 * sizes.hole_mm + process.min_wall_mm,
               explicit_hub=bool(parts_spec.hub_diameter_mm or gear_hub))
    outlines = _outlines(drawing, mechanism, motion, sizes, parts_spec, process)
    layers = _layers(outlines, drawing.holes, pin_joints, mechanism, motion, gear_pairs, sizes.boss_radius_mm,
                     design)
    pin_joints = _press_fits(drawing, pin_joints, layers, sizes, process, mechanism.ground)

    parts = _body_parts(drawing, mechanism, outlines, layers, process)
    pins, spacers = pins_and_spacers(pin_joints, layers, sizes.pin_mm, sizes.hole_mm, 2.0 * sizes.boss_radius_mm,
                                     process.thickness_mm, process.layer_gap_mm,
                                     {(body, h.joint): h.centre for body, hs in drawing.holes.items() for h in hs})
    # torsion springs on their pins' extensions: anchor holes in the parts, the pins lengthened
    springs, parts, pins = place_springs(hints.springs, mechanism, motion, parts, pins, process, mechanism.ground)
    parts += _printed_spacers(spacers, process, sizes.pin_mm)
    _check_pin_webs(parts, process)
    # standard pins over the stacks and their retention, standard washers (parts/retention.py)
    pins, spacers = retain_pins(pins, spacers, parts, process, mechanism.ground)
    parts += cap_parts(pins, parts, process)
    warnings = overlapping_cuts(parts)
    names = [p.name for p in parts]
    if len(set(names)) != len(names):
        raise GeometryError(f"part names collide after sanitising: {sorted(names)}")
    copies = hints.copies or 1
    bom = part_rows(parts, process, copies) + bill_of_materials(pins, spacers, hints, process, copies)
    bom = with_spring_rows(bom, springs, copies)
    partset = PartSet(parts=tuple(parts), bom=bom, pins=tuple(pins), spacers=tuple(spacers), layers=layers,
                      process=process.name, chord_tolerance_mm=tol, thickness_mm=process.thickness_mm,
                      layer_gap_mm=process.layer_gap_mm, kerf_mm=process.kerf_mm, copies=copies, hints=hints,
                      warnings=tuple(warnings), springs=springs)
    from fabricate.drive.parts import attach_actuator  # the drive sits above the parts layer

    partset = attach_actuator(design, mechanism, motion, partset)
    # the ground's mounting screws, but in the holes the actuator's standoffs stand on (the drive's screws)
    taken = {s.hole for s in partset.actuator.standoffs} if partset.actuator is not None else set()
    free = [h.joint for h in drawing.holes[mechanism.ground] if h.joint.startswith("mount_") and h.joint not in taken]
    screws = mounting_rows(free, parts_spec.mounting_hole_mm, process.thickness_mm, copies) if free else []
    return replace(partset, bom=with_sources(list(partset.bom) + screws))  # print / cut / buy on every row


@dataclass
class _Drawing:
    """The parts as :func:`build_parts` draws them up, per body name; each step adds to it.

    ``circles`` (centre, radius) span an outline's convex hull, ``fused`` polygons (gears, hubs, pad arcs)
    are united with it, ``holes`` and ``slots`` go through it; ``gears`` names the gear pairs a body carries.
    """

    circles: dict[str, list[tuple[np.ndarray, float]]]
    holes: dict[str, list[Hole]]
    slots: dict[str, list[BulgePath]]
    fused: dict[str, list[np.ndarray]]
    gears: dict[str, list[str]]

    @classmethod
    def start(cls, mechanism: Mechanism, radius: float) -> _Drawing:
        """A boss of ``radius`` round every point of every body, and nothing else yet."""
        names = [b.name for b in mechanism.bodies]
        return cls(circles={b.name: [(b.point(p), radius) for p in b.points] for b in mechanism.bodies},
                   holes={n: [] for n in names}, slots={n: [] for n in names}, fused={n: [] for n in names},
                   gears={n: [] for n in names})


def _add_joints(drawing: _Drawing, mechanism: Mechanism, motion: Motion, sizes: Sizes,
                process: ProcessSpec) -> list[tuple[str, tuple[str, ...]]]:
    """A pin hole in both bodies of every revolute joint, guide pins and a slot for every slider; joints at
    one spot of a body (a compound hinge) share one hole and one pin.

    Returns
    -------
    list of (pin name, bodies it joins; the first holds it)
    """
    pin_joints: list[tuple[str, tuple[str, ...]]] = []
    pin_holes: list[tuple[str, str, np.ndarray]] = []  # (pin name, body, centre): a round hole for the pin
    for joint in mechanism.joints:
        if isinstance(joint, Revolute):
            for body in (joint.body_a, joint.body_b):
                pin_holes.append((joint.name, body, mechanism.body(body).point(joint.name)))
            pin_joints.append((joint.name, (joint.body_a, joint.body_b)))
        elif isinstance(joint, Slider):
            guides = slider_guides(mechanism, motion, joint, sizes.boss_radius_mm, sizes.hole_mm, process.min_wall_mm)
            drawing.circles[joint.body_a] += [(centre, sizes.boss_radius_mm) for _, centre in guides.pins]
            drawing.slots[joint.body_b].append(guides.slot)
            drawing.circles[joint.body_b] += [(end, sizes.boss_radius_mm) for end in guides.ends]
            for name, centre in guides.pins:
                pin_holes.append((name, joint.body_a, centre))
                pin_joints.append((name, (joint.body_a, joint.body_b)))
    pin_joints, pin_holes = merge_coincident_pins(pin_joints, pin_holes)
    for name, body, centre in pin_holes:
        drawing.holes[body].append(Hole(name, centre, sizes.hole_mm, sizes.pin_mm, "running", sizes.hole_nominal_mm))
    return pin_joints


def _press_fits(drawing: _Drawing, pin_joints: Sequence[tuple[str, tuple[str, ...]]], layers: Mapping[str, int],
                sizes: Sizes, process: ProcessSpec, ground: str) -> list[tuple[str, tuple[str, ...]]]:
    """With ``retention = "press"``: each pin's holder (:func:`~fabricate.parts.retention.choose_holder`, a body
    with a round hole at an end of its stack) comes first among its bodies and its hole becomes the press fit.

    Returns
    -------
    list of (pin name, bodies; the holder first)
    """
    if process.retention != "press":
        return list(pin_joints)
    out = []
    for name, bodies in pin_joints:
        holed = [b for b in bodies if any(h.joint == name for h in drawing.holes[b])]
        holder = choose_holder(bodies, layers, holed, ground)
        drawing.holes[holder] = [replace(h, diameter_mm=sizes.press_hole_mm, fit="press",
                                         nominal_diameter_mm=sizes.press_nominal_mm) if h.joint == name else h
                                 for h in drawing.holes[holder]]
        out.append((name, (holder,) + tuple(b for b in bodies if b != holder)))
    return out


def _add_pads(drawing: _Drawing, mechanism: Mechanism, pads: Mapping[str, PadHint], parts_spec: PartsSpec,
              radius: float, tol: float) -> None:
    """Fingertip pads (the ``pads`` hint): a circle round the pad's point, or on a curved face the circular
    segment between two named points on the circle."""
    for body, pad in pads.items():
        if body not in drawing.circles:
            raise GeometryError(f"pad hint names unknown body {body!r}")
        points = mechanism.body(body).points
        if pad.point not in points:
            raise GeometryError(f"pad hint: body {body!r} has no point {pad.point!r}")
        r_pad = parts_spec.pad_radius_mm or (pad.radius_mm if pad.radius_mm is not None else radius)
        centre = mechanism.body(body).point(pad.point)
        if pad.arc is not None:
            ends = [mechanism.body(body).point(name) for name in pad.arc]
            drawing.circles[body] += [(ends[0], radius), (ends[1], radius)]
            segment = pad_segment(centre, ends[0], ends[1], tol)
            if len(segment) >= 3:  # an arc within the chord tolerance of its chord adds nothing to the hull
                drawing.fused[body].append(segment)
        else:
            drawing.circles[body].append((centre, max(r_pad, radius)))


def _add_gears(drawing: _Drawing, mechanism: Mechanism, gear_pairs: Sequence[GearPair], hub_mm: float,
               tol: float, limits: Mapping[tuple[str, str], float] | None = None, least: float = 0.0,
               explicit_hub: bool = False) -> None:
    """Each gear of each pair, with a hub round its axis, fused to the body that carries it.

    A boss (and a derived hub) round a gear's axis is cut back to its ``limits`` radius, no smaller than
    ``least`` (the hole and the process's minimum wall): the gear itself is the web round its bore, and a
    boss grown past the root (a laser's webs as thick as the stock) would collide with the mating gear's
    teeth. A hub the design sets (``hub_diameter_mm``) is kept as given."""
    limits = limits or {}
    for pair in gear_pairs:
        for side in ("a", "b"):
            body, axis, outline = gear_outline_in_body(mechanism, pair, side)
            centre = mechanism.body(body).point(axis)
            limit = max(limits.get((body, axis), math.inf), least)
            drawing.circles[body] = [(c, min(r, limit)) if float(np.hypot(*(c - centre))) < 1e-9 else (c, r)
                                     for c, r in drawing.circles[body]]
            hub = hub_mm if explicit_hub else min(hub_mm, 2.0 * limit)
            drawing.fused[body] += [outline, circle_polygon(centre, hub, tol)]
            drawing.gears[body].append(pair.name)


def _outline(drawing: _Drawing, body: str, radius: float, tol: float) -> BulgePath:
    """A body's outline: the exact hull of its circles (one boss of ``radius`` if none), fused with its polygons."""
    circles = drawing.circles
    centres = np.array([c for c, _ in circles[body]]) if circles[body] else np.zeros((1, 2))
    radii = np.array([r for _, r in circles[body]]) if circles[body] else np.array([radius])
    path = circle_hull(centres, radii)
    return fuse_polygons(path, drawing.fused[body], tol) if drawing.fused[body] else path


def _outlines(drawing: _Drawing, mechanism: Mechanism, motion: Motion, sizes: Sizes, parts_spec: PartsSpec,
              process: ProcessSpec) -> dict[str, BulgePath]:
    """Every body's outline, in body order, and the ground's mounting holes.

    The moving bodies are drawn first: the mounting holes keep clear of the region they sweep, and the
    ground's outline then takes in the mounting bosses.
    """
    ground, radius, tol = mechanism.ground, sizes.boss_radius_mm, process.chord_tolerance_mm
    outlines = {b.name: _outline(drawing, b.name, radius, tol) for b in mechanism.bodies if b.name != ground}
    _add_mounting(mechanism, motion, ground, drawing.circles, drawing.holes, drawing.fused, sizes, parts_spec,
                  swept_region(outlines, motion), process.running_clearance_mm)
    outlines[ground] = _outline(drawing, ground, radius, tol)
    return {b.name: outlines[b.name] for b in mechanism.bodies}


def _layers(outlines: Mapping[str, BulgePath], holes: Mapping[str, Sequence[Hole]],
            pin_joints: Sequence[tuple[str, tuple[str, ...]]], mechanism: Mechanism, motion: Motion,
            gear_pairs: Sequence[GearPair], radius: float, design: DesignSpec) -> dict[str, int]:
    """Body name -> layer (see :mod:`fabricate.parts.layers`).

    Bodies that come within the clearance of each other anywhere over the motion, or share a pin, get
    different layers; meshing gears share one. The layers are then ordered so that no body sweeps over a
    pin between the two layers it joins (a spacer fills the skipped layers there), nor over a clip's or cap's
    pin end beyond its stack, and a motor's short shaft reaches its driven part.
    """
    process = design.process
    clearance_mm = process.running_clearance_mm
    coarse = {n: p.polygon(CONFLICT_CHORD_MM) for n, p in outlines.items()}
    holes_at = {(body, h.joint): h.centre for body, hs in holes.items() for h in hs}
    poses = {n: motion.pose(n) for n in mechanism.body_names}
    on_one_pin = [(a, b) for _, bodies in pin_joints for i, a in enumerate(bodies) for b in bodies[i + 1:]]
    graph = conflict_graph(coarse, poses, clearance_mm + CONFLICT_CHORD_MM, always=on_one_pin)
    same = [(p.body_a, p.body_b) for p in gear_pairs]
    layers = assign_layers(graph, list(mechanism.body_names), same)
    # each pair's pin in the frame of its own body a (on a compound pin that is not always bodies[0])
    crossings = pin_crossings(coarse, poses, [(holes_at[(a, name)], a, b) for name, bodies in pin_joints
                                              for i, a in enumerate(bodies) for b in bodies[i + 1:]],
                              radius, clearance_mm + CONFLICT_CHORD_MM)
    from fabricate.drive.rotary import motor_reach, output_depth, replaced_joint  # the drive sits above parts

    depth = output_depth(design, mechanism)
    outer = [depth] if depth is not None else []
    end_r = end_radius_mm(process)
    if end_r <= 0.0:
        return order_layers(layers, crossings, outer=outer, thickness_mm=process.thickness_mm,
                            gap_mm=process.layer_gap_mm)
    # a clip's or cap's pin sticks out of its stack: the bodies that pass over its ends and the pins near it
    # keep off the room beyond its end faces (an empty layer gives it that room); the pin a motor's output
    # replaces is not built
    gone = replaced_joint(design, mechanism)
    kept = [(name, bodies) for name, bodies in pin_joints if gone not in name.split("+")]
    at = [(holes_at[(bodies[0], name)], bodies[0]) for name, bodies in kept]
    over = [(i, c) for i, ((centre, a), (_, bodies)) in enumerate(zip(at, kept, strict=True))
            for _, _, c in pin_crossings(coarse, poses, [(centre, a, a)], max(radius, end_r),
                                         clearance_mm + CONFLICT_CHORD_MM) if c not in bodies]
    # the pins whose ends a motor under or over the stack may meet: those within its body's reach of its axis
    motor = motor_reach(design, mechanism)
    near = None if motor is None else [i for i, j in pin_neighbours(at + [(motor[1], motor[0])], poses,
                                                                   motor[2] + end_r + clearance_mm)
                                       if j == len(at)]
    # a pin's end against a neighbour's stack: its spacers are bosses (radius) round the pin
    return order_layers(layers, crossings, pins=[tuple(bodies) for _, bodies in kept], end_crossings=over,
                        pin_pairs=pin_neighbours(at, poses, max(radius, end_r) + end_r + clearance_mm),
                        end_reach=lambda stack: end_reach_mm(process, stack), thickness_mm=process.thickness_mm,
                        gap_mm=process.layer_gap_mm, spare_layers=3, outer=outer,
                        one_end=process.retention == "press", near_motor=near, split=True)


def _body_parts(drawing: _Drawing, mechanism: Mechanism, outlines: Mapping[str, BulgePath],
                layers: Mapping[str, int], process: ProcessSpec) -> list[Part]:
    """One part per body, in body order, on its layer; a body with slots (a push rod) is a :class:`SlottedPart`."""
    thickness, gap = process.thickness_mm, process.layer_gap_mm
    parts: list[Part] = []
    for b in mechanism.bodies:
        gears, slots = drawing.gears[b.name], drawing.slots[b.name]
        role = "ground" if b.name == mechanism.ground else ("gear" if gears else ("rod" if slots else "link"))
        common: dict[str, Any] = dict(name=safe_name(b.name), body=b.name, outline=outlines[b.name],
                                      holes=tuple(drawing.holes[b.name]), thickness_mm=thickness,
                                      z_mm=layer_z(layers[b.name], thickness, gap), layer=layers[b.name],
                                      process=process.name, role=role, gear=",".join(gears))
        parts.append(SlottedPart(**common, slots=tuple(slots)) if slots else Part(**common))
    return parts


def _printed_spacers(spacers: Sequence[Spacer], process: ProcessSpec, pin_mm: float) -> list[Part]:
    """The spacers an additive process prints with the parts: those at least a plate thick (thinner gaps take
    washers). A cut process makes none (its spacers are tubes, bought)."""
    if process.technique != "additive":
        return []
    printed = [sp for sp in spacers if sp.length_mm >= process.thickness_mm - 1e-9]  # thin gaps: washers
    per_pin = {j: sum(q.joint == j for q in printed) for j in {q.joint for q in printed}}
    seen: dict[str, int] = {}
    parts = []
    for sp in printed:
        seen[sp.joint] = seen.get(sp.joint, 0) + 1
        suffix = f"_{seen[sp.joint]}" if per_pin[sp.joint] > 1 else ""
        parts.append(Part(name=safe_name(f"spacer_{sp.joint}{suffix}"), body=sp.body,
                          outline=circle_hull(sp.centre[None, :], sp.outer_diameter_mm / 2.0),
                          holes=(Hole(sp.joint, sp.centre, sp.inner_diameter_mm, pin_mm, "running",
                                      sp.inner_diameter_mm - process.hole_compensation_mm),),
                          thickness_mm=sp.length_mm, z_mm=sp.z_mm, layer=sp.lower_layer + 1,
                          process=process.name, role="spacer"))
    return parts


def _check_pin_webs(parts: Sequence[Part], process: ProcessSpec) -> None:
    """Refuse a pin so large that two joint holes of one part run into each other.

    Overlapping holes make the plate's outline an invalid polygon (no geometry kernel can build or
    check it), and the pin diameter is the field to blame: the message gives the largest pin that
    leaves the process's minimum wall between the two holes.
    """
    for part in parts:
        joint_holes = [h for h in part.holes if not h.joint.startswith("mount_")]
        for i, a in enumerate(joint_holes):
            for b in joint_holes[i + 1:]:
                distance = float(np.hypot(*(np.asarray(a.centre) - b.centre)))
                if distance < 1e-9:
                    continue  # one pin through two joint names (merged coincident pins)
                web = distance - 0.5 * (a.diameter_mm + b.diameter_mm)
                # a wall thinner than the process likes is a printability finding (exit 1, named by the
                # printability check); only holes that meet make the part impossible to build
                if web <= 0.0:
                    largest = (distance - process.min_wall_mm - 2.0 * process.running_clearance_mm
                               - process.hole_compensation_mm)
                    limit = (f"at most {math.floor(largest * 100) / 100:g} mm" if largest >= process.min_pin_mm
                             else "no pin of the process fits; move the joints apart")
                    raise SpecError("process.pin_diameter_mm",
                                    f"{process.pin_diameter_mm:g} mm pins: holes {a.joint} and {b.joint} of part "
                                    f"{part.name} are {distance:.3g} mm apart and would leave "
                                    f"{web:.3g} mm of wall between them (the process needs "
                                    f"{process.min_wall_mm:g} mm); {limit}")


def merge_coincident_pins(pin_joints: Sequence[tuple[str, tuple[str, ...]]],
                          pin_holes: Sequence[tuple[str, str, np.ndarray]]
                          ) -> tuple[list[tuple[str, tuple[str, ...]]], list[tuple[str, str, np.ndarray]]]:
    """Merge pins whose holes coincide in some body (e.g. joints ``G1`` palm-phalanx and ``G1r``
    palm-rocker at one spot of the palm) into one pin named ``G1+G1r`` through all their bodies.

    Returns
    -------
    (pins, holes)
        Pins as (name, bodies in first-seen order), holes as (pin name, body, centre), one per body and pin.
    """
    parent = {name: name for name, _ in pin_joints}

    def find(n: str) -> str:
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    spots: dict[tuple[str, float, float], str] = {}
    for name, body, centre in pin_holes:
        key = (body, round(float(centre[0]), 9), round(float(centre[1]), 9))
        if key in spots:
            a, b = find(spots[key]), find(name)
            if a != b:
                parent[b] = a
        else:
            spots[key] = name
    members: dict[str, list[str]] = {}
    for name, _ in pin_joints:
        members.setdefault(find(name), []).append(name)
    label = {root: "+".join(names) for root, names in members.items()}
    merged: dict[str, list[str]] = {}
    for name, bodies in pin_joints:
        seen = merged.setdefault(label[find(name)], [])
        seen += [b for b in bodies if b not in seen]
    holes_out: list[tuple[str, str, np.ndarray]] = []
    done: set[tuple[str, str]] = set()
    for name, body, centre in pin_holes:
        pin_body = (label[find(name)], body)
        if pin_body not in done:
            done.add(pin_body)
            holes_out.append((pin_body[0], body, centre))
    return [(name, tuple(bodies)) for name, bodies in merged.items()], holes_out


def _add_mounting(mechanism: Mechanism, motion: Motion, ground: str,
                  circles: dict[str, list[tuple[np.ndarray, float]]], holes: dict[str, list[Hole]],
                  fused_polys: dict[str, list[np.ndarray]], sizes: Sizes, parts_spec: PartsSpec,
                  swept: Any, clearance_mm: float) -> None:
    """Mounting holes on the ground part: a row on the side away from the moving bodies, pushed out until
    the screw heads (the mounting bosses) keep the clearance from everything that moves."""
    count = parts_spec.mounting_holes
    if count == 0:
        return
    own = np.array([c for c, _ in circles[ground]]) if circles[ground] else np.zeros((1, 2))
    moving = [motion.point(p, b.name) for b in mechanism.bodies if b.name != ground for p in b.points]
    swept_centre = np.concatenate(moving).mean(axis=0) if moving else own.mean(axis=0) + np.array([0.0, 1.0])
    away = own.mean(axis=0) - swept_centre
    norm = float(np.hypot(*away))
    direction = away / norm if norm > 1e-6 else np.array([0.0, -1.0])
    side = np.array([-direction[1], direction[0]])
    reach = float(np.max(own @ direction)) + sizes.boss_radius_mm
    for poly in fused_polys[ground]:
        reach = max(reach, float(np.max(poly @ direction)))
    r_mount = sizes.mount_boss_radius_mm
    pitch = 2.0 * r_mount + 2.0
    offsets = (np.arange(count) - 0.5 * (count - 1)) * pitch
    base = (own.mean(axis=0) @ side) * side + (reach + r_mount + 1.0) * direction
    # candidate rows every 0.5 mm outwards; the first whose bosses all clear the swept region wins
    steps = np.arange(0.0, 400.0, 0.5)
    centres = (base[None, None, :] + steps[:, None, None] * direction
               + offsets[None, :, None] * side[None, None, :])
    chosen = centres[0] if swept.is_empty else centres[-1]
    # +0.5 mm: the region is sampled at discrete poses; parts move a little between them. Rows in batches of
    # 16, nearest first: the first row that clears is usually within the first batch (~50x less distance work)
    for first in range(0, len(steps) if not swept.is_empty else 0, 16):
        batch = centres[first:first + 16]
        gaps = shapely.distance(shapely.points(batch.reshape(-1, 2)), swept).reshape(len(batch), count)
        ok = np.all(gaps >= r_mount + clearance_mm + 0.5, axis=1)
        if ok.any():
            chosen = batch[int(np.argmax(ok))]
            break
    for k, centre in enumerate(chosen):
        holes[ground].append(Hole(f"mount_{k + 1}", centre, sizes.mount_hole_mm, 0.0, "clearance",
                                  sizes.mount_nominal_mm))
        circles[ground].append((centre, r_mount))
