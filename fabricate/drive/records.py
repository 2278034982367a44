"""The actuator's records: what a placement made (:class:`PlacedActuator`, its fasteners and standoffs), the
kinds and roles the drive knows, and the BOM rows and holes it adds. Pure data and small constructors; the
placement itself is :mod:`fabricate.drive.rotary` / :mod:`fabricate.drive.mount`, the entry point
:func:`fabricate.drive.parts.attach_actuator`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.catalogue.hardware import ISO4762
from fabricate.drive import geometry as geo
from fabricate.parts import model
from fabricate.parts.model import Hole

if TYPE_CHECKING:
    pass

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


def fit_hole(joint: str, centre: np.ndarray, nominal_mm: float, compensation_mm: float, pin_mm: float = 0.0,
          fit: str = "clearance") -> Hole:
    """A hole of nominal (fit) size ``nominal_mm``, modelled with the process's compensation added. A screw's
    pilot hole (``fit="tapped"``) is labelled a clearance while the part model has no such fit."""
    return Hole(joint, np.asarray(centre, dtype=np.float64), nominal_mm + compensation_mm, pin_mm,
                fit if fit in model.HOLE_FITS else "clearance", nominal_mm)


def screw_size(d_mm: float) -> str:
    """The ISO 4762 size of nominal diameter ``d_mm``, else the largest below it."""
    sizes = sorted(ISO4762, key=lambda s: float(s.lstrip("M")))
    fits = [s for s in sizes if float(s.lstrip("M")) <= d_mm + 1e-9]
    return fits[-1] if fits else sizes[0]


def purchased_row(item: str, qty: int, description: str, **extra: Any) -> dict[str, Any]:
    return {"item": item, "kind": "purchased", "qty": qty, "joints": [], "description": description,
            "source": "buy", **extra}


def screw_row(f: Fastener, copies: int) -> dict[str, Any]:
    return {"item": f.designation, "designation": f.designation, "kind": "screw", "qty": f.qty * copies,
            "joints": [], "source": "buy",
            "description": f.purpose, "clamp_mm": round(f.clamp_mm, 4), "engagement_mm": round(f.engagement_mm, 4)}
