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
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.drive.editing import body_part, bom_without, fuse_pad, with_changes
from fabricate.drive.records import PUSHING, ROTARY, PlacedActuator, fit_hole, purchased_row
from fabricate.errors import SpecError
from fabricate.mechanism import Driver, Mechanism, Motion, Slider
from fabricate.parts.profiles import circle_hull
from fabricate.planar import inverse_transform_points, rotation

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.checks.items import SweepItem
    from fabricate.drive.spec import ActuatorSpec
    from fabricate.parts.partset import PartSet
    from fabricate.process import ProcessSpec


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
    from fabricate.parts.partset import overlapping_cuts

    warnings = tuple(ps.warnings) + tuple(w for w in overlapping_cuts([new_rod]) if w not in ps.warnings)
    record = PlacedActuator(
        model=entry.key, name=entry.name, kind=entry.kind, driver=index, driver_kind="slide", joint=slider.name,
        driven_body=slider.body_b, ground_body=slider.body_a, axis=at_ground, direction=axis_a, angle=0.0,
        z_face=float(rod.z_mm + 0.5 * rod.thickness_mm), flip=False, removed_pin="", interface=("actuator_rod_end",),
        mount_part="", fasteners=(), standoffs=(), solids=(),
        notes=(f"the {what} acts along the slide axis on a Ø{pin_mm:g} mm pin in the rod-end hole",))
    return dataclasses.replace(ps, parts=parts, bom=bom, warnings=warnings, actuator=record)
