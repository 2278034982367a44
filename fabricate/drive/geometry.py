"""Plan-view geometry of an actuator in a design: where its solids lie, what it cuts into the parts.

Pure functions of catalogue entries (:mod:`fabricate.catalogue.actuators`) and 2D placements; lengths in
mm, angles in radians. Nothing here knows a PartSet: :mod:`fabricate.drive.parts` puts the results into
the parts, the BOM and the interference proof.

Frames
------
A catalogue entry is drawn in its own frame: the output axis is z, +z out of the actuator, the origin on
the axis at the output face. A :class:`Placement` maps it into the frame of the body it is fixed to (the
driver's reference, the ground) and onto the stack's z: the axis at ``centre``, the entry's x axis turned
by ``angle`` about z, and either output up (``flip`` False: the actuator under the stack, its face at
``z_face``) or output down (``flip`` True: above the stack, y and z mirrored so the frame stays right
handed).

Interfaces
----------
- Servo: the horn's arm holes on one circle (the innermost that leaves the process's wall to the hub
  bore and room for a screw head beside the hub), a pilot hole for a thread-forming screw at each, a bore
  over the horn's hub (the horn's centre screw goes in and out through it). The screws go up through the
  horn's arms (opened to the screw's clearance), their heads under the arms, into the driven part.
- Shaft: a D-bore (one flat), a double-D bore (two flats) or a round bore, the shaft plus the running
  clearance and the process's hole compensation, as an exact line/arc contour.
- Mount: a plate on the flange the mounting holes are in (on the output side of it), with a cut-out for
  every box of the body that passes through the plate's thickness (a servo's case, a stepper's boss).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fabricate.catalogue.actuators import Actuator, Box, Horn, Shaft
from fabricate.catalogue.actuators import Hole as MountHole
from fabricate.catalogue.hardware import ISO4762, ISO4762_LENGTHS_MM, ISO7089, Screw, screw
from fabricate.errors import SpecError
from fabricate.parts.model import BulgePath
from fabricate.planar import rotation

#: A thread-forming screw driven into a printed or cut plastic plate: its pilot hole as a fraction of the
#: screw's nominal diameter. A design rule of ours (plastics take a pilot a little under the thread's
#: minor diameter of a machine screw); the process's hole compensation is added on top.
PILOT_FRACTION = 0.8
#: Thread engaged in a metal part's tapped hole, as a multiple of the nominal diameter (the usual minimum
#: for a steel screw in a tapped steel or aluminium hole).
TAPPED_ENGAGEMENT = 1.5


@dataclass(frozen=True)
class Placement:
    """Where an actuator sits: its frame in a body's plan frame and on the stack's z.

    Attributes
    ----------
    centre : (2,) array
        The output axis in the body's coordinates, mm.
    angle : float
        Rotation of the entry's x axis about z, rad.
    flip : bool
        False: output along +z (under the stack); True: along -z (over it).
    z_face : float
        Stack z of the entry's z = 0 (the output face), mm.
    """

    centre: np.ndarray
    angle: float
    flip: bool
    z_face: float

    def plan(self, xy: np.ndarray) -> np.ndarray:
        """Entry (x, y) -> body coordinates; (n, 2) or (2,)."""
        p = np.asarray(xy, dtype=np.float64)
        if self.flip:
            p = p * np.array([1.0, -1.0])
        out: np.ndarray = p @ rotation(self.angle).T + np.asarray(self.centre, dtype=np.float64)
        return out

    def z_range(self, z0: float, z1: float) -> tuple[float, float]:
        """Entry z range -> stack z range (low, high)."""
        a, b = (self.z_face - z0, self.z_face - z1) if self.flip else (self.z_face + z0, self.z_face + z1)
        return (min(a, b), max(a, b))


@dataclass(frozen=True)
class Solid:
    """A prism in a body's frame: outer ring (CCW) then hole rings (CW), between z0 and z1 (mm)."""

    name: str
    role: str  # "body", "output", "screw", "standoff"
    rings: tuple[np.ndarray, ...]
    z0: float
    z1: float


# -- rings -------------------------------------------------------------------------------------------------
def rectangle(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """The rectangle's corners, counter-clockwise; (4, 2)."""
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)


def placed_ring(ring: np.ndarray, placement: Placement) -> np.ndarray:
    """A ring of the entry's frame in the body's frame, still counter-clockwise (a flip mirrors it)."""
    out = placement.plan(ring)
    return out[::-1] if placement.flip else out


def circle_ring(centre: np.ndarray, diameter: float, chord_tolerance_mm: float) -> np.ndarray:
    """A counter-clockwise polygon inscribed in a circle (at least 16 sides)."""
    r = 0.5 * diameter
    step = 2.0 * math.acos(max(-1.0, 1.0 - chord_tolerance_mm / r)) if r > chord_tolerance_mm else math.pi / 8
    n = max(16, int(math.ceil(2.0 * math.pi / step)))
    t = np.arange(n) * (2.0 * math.pi / n)
    return np.asarray(centre, dtype=np.float64) + r * np.column_stack([np.cos(t), np.sin(t)])


def box_solid(name: str, box: Box, placement: Placement, role: str = "body") -> Solid:
    """A catalogue box placed: its plan rectangle in the body's frame and its stack z range."""
    ring = placed_ring(rectangle(box.x0, box.y0, box.x1, box.y1), placement)
    z0, z1 = placement.z_range(box.z0, box.z1)
    return Solid(name, role, (ring,), z0, z1)


def body_solids(entry: Actuator, placement: Placement, prefix: str = "actuator") -> list[Solid]:
    """Every box of the entry's body, placed (none for an off-board drive)."""
    return [box_solid(f"{prefix}_body_{k + 1}" if len(entry.body or ()) > 1 else f"{prefix}_body", box, placement)
            for k, box in enumerate(entry.body or ())]


def output_base_z(entry: Actuator) -> float:
    """Entry z where the output leaves the body: the top of the highest box on the axis (a stepper's boss),
    else the face (0)."""
    tops = [b.z1 for b in entry.body or () if b.x0 < 0.0 < b.x1 and b.y0 < 0.0 < b.y1]
    return max([0.0, *tops])


# -- servo horn ----------------------------------------------------------------------------------------
def horn_seat_z(entry: Actuator) -> tuple[float, float]:
    """Entry z of the horn's bottom and top: its socket on the spline's tip (the spline reaches
    ``socket_depth`` into the hub), the hub ``hub_height`` tall; the arms are flush with the top."""
    if entry.horn is None or entry.spline is None:
        raise SpecError("actuator.model", f"{entry.key!r} has no horn on a spline")
    bottom = entry.spline.length_mm - entry.horn.socket_depth_mm
    return bottom, bottom + entry.horn.hub_height_mm


def hub_bore_mm(horn: Horn, clearance_mm: float, compensation_mm: float) -> float:
    """The bore over the horn's hub (mm): hub diameter + 2 × radial clearance + hole compensation."""
    return horn.hub_d_mm + 2.0 * clearance_mm + compensation_mm


def horn_screw_size(horn: Horn) -> str:
    """The ISO 4762 size for the horn's arm holes: the smallest size, M2 and up, whose nominal diameter
    exceeds the hole (the maker opens the hole to the screw's ISO 7089 washer bore)."""
    hole = min(h.diameter_mm for h in horn.arm_holes)
    for size in sorted(ISO4762, key=_nominal):
        if _nominal(size) > hole + 1e-9:
            return size
    raise SpecError("actuator.model", f"no catalogued screw fits a Ø{hole:g} mm horn hole")


def horn_holes(horn: Horn, bore_mm: float, screw_hole_mm: float, min_wall_mm: float,
               head_d_mm: float = 0.0) -> tuple[MountHole, ...]:
    """The arm holes the design uses: all those on the innermost circle that leaves ``min_wall_mm`` between a
    screw hole of ``screw_hole_mm`` and the hub bore, and room under the arm for a screw head of
    ``head_d_mm`` beside the hub (the horn's own frame)."""
    radii = sorted({round(math.hypot(h.x, h.y), 9) for h in horn.arm_holes})
    for r in radii:
        if (r - 0.5 * screw_hole_mm - 0.5 * bore_mm >= min_wall_mm - 1e-9
                and r - 0.5 * head_d_mm >= 0.5 * horn.hub_d_mm - 1e-9):
            return tuple(h for h in horn.arm_holes if abs(math.hypot(h.x, h.y) - r) < 1e-6)
    raise SpecError("actuator.model", f"the horn {horn.name!r} has no arm hole {min_wall_mm:g} mm clear of a "
                                      f"Ø{bore_mm:.3g} mm hub bore")


def screw_into(size: str, clamp_mm: float, depth_mm: float) -> Screw:
    """The longest standard screw of ``size`` through ``clamp_mm`` whose tip stays within a part ``depth_mm``
    thick (engaging at least one diameter), else the shortest that engages one diameter."""
    d = _nominal(size)
    row = ISO4762[size]
    fits = [length for length in ISO4762_LENGTHS_MM
            if clamp_mm + min(d, depth_mm) - 1e-9 <= length <= clamp_mm + depth_mm + 1e-9
            and row.min_length_mm - 1e-9 <= length <= row.max_length_mm + 1e-9]
    if fits:
        return screw(size, clamp_mm, max(fits) - clamp_mm)
    return screw(size, clamp_mm, min(d, depth_mm))


def horn_reach(horn: Horn) -> float:
    """Radius (mm) the uncut horn sweeps: its farthest arm hole plus one hole diameter."""
    return max(math.hypot(h.x, h.y) + h.diameter_mm for h in horn.arm_holes)


def horn_pattern(holes: Sequence[MountHole], centre: np.ndarray, angle: float, flip: bool = False) -> np.ndarray:
    """Arm-hole centres in a body's frame: the horn's pattern turned by ``angle`` about ``centre``; (k, 2)."""
    return Placement(np.asarray(centre, dtype=np.float64), angle, flip, 0.0).plan(
        np.array([[h.x, h.y] for h in holes], dtype=np.float64).reshape(-1, 2))


def trimmed_horn_ring(holes_xy: np.ndarray, centre: np.ndarray, hub_d: float, hole_d: float,
                      chord_tolerance_mm: float) -> np.ndarray:
    """The horn with its arms cut back one hole diameter past the holes used, in a body's frame (CCW):
    the hull of the hub circle and a circle of one hole diameter round each hole."""
    pts = [circle_ring(centre, hub_d, chord_tolerance_mm)]
    pts += [circle_ring(c, 2.0 * hole_d, chord_tolerance_mm) for c in holes_xy]
    return convex_ring(np.concatenate(pts))


def convex_ring(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of points (monotone chain); (m, 2)."""
    pts = np.unique(np.asarray(points, dtype=np.float64).round(12), axis=0)
    if len(pts) < 3:
        return pts

    def half(seq: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0.0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


# -- shaft bores ---------------------------------------------------------------------------------------
def shaft_flats(shaft: Shaft) -> int:
    """Flats the catalogue states (0 when it states none or no depth for them)."""
    if not shaft.flats or shaft.across_flats_mm is None:
        return 0
    return int(shaft.flats)


def shaft_bore(shaft: Shaft, centre: np.ndarray, angle: float, clearance_mm: float) -> BulgePath:
    """The bore a shaft turns the part with, as exact lines and arcs (CCW), in a body's frame.

    The shaft's circle and flats each grow by ``clearance_mm`` (radial: the running clearance plus half
    the process's hole compensation). One flat (D): at ``across_flats - d/2`` from the axis on the side
    ``angle`` points to; two (double-D): at ``± across_flats / 2``. A shaft without stated flats gets a
    round bore (a circle as two half arcs).

    Returns
    -------
    BulgePath
        Across the flats (D: flat to far side) it measures ``across_flats + 2 × clearance``; across the
        round, ``d + 2 × clearance``.
    """
    r = 0.5 * shaft.diameter_mm + clearance_mm
    c = np.asarray(centre, dtype=np.float64)
    turn = rotation(angle)
    flats = shaft_flats(shaft)
    if flats == 0:
        return BulgePath(np.array([[r, 0.0], [-r, 0.0]]) @ turn.T + c, np.array([1.0, 1.0]))
    af = float(shaft.across_flats_mm)  # type: ignore[arg-type]  # shaft_flats checked it
    if flats == 1:
        h = af - 0.5 * shaft.diameter_mm + clearance_mm  # the flat's distance from the axis, along +x
        if not -r < h < r:
            raise SpecError("actuator.model", f"D-shaft across flats {af:g} mm does not cut Ø{shaft.diameter_mm:g}")
        w = math.sqrt(r * r - h * h)
        # flat from (h, -w) to (h, w), then the long arc back round through -x
        sweep = 2.0 * math.pi - 2.0 * math.atan2(w, h)
        verts = np.array([[h, -w], [h, w]])
        bulges = np.array([0.0, math.tan(sweep / 4.0)])
    else:
        h = 0.5 * af + clearance_mm
        if not 0.0 < h < r:
            raise SpecError("actuator.model", f"double-D across flats {af:g} mm does not cut Ø{shaft.diameter_mm:g}")
        w = math.sqrt(r * r - h * h)
        arc = math.tan((math.pi - 2.0 * math.atan2(w, h)) / 4.0)
        verts = np.array([[h, -w], [h, w], [-h, w], [-h, -w]])
        bulges = np.array([0.0, arc, 0.0, arc])
    return BulgePath(verts @ turn.T + c, bulges)


# -- mount ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Fastening:
    """How one mounting hole is screwed: the screw size, which way it goes and the plate's hole.

    Attributes
    ----------
    size : str
        ISO 4762 size (``"M3"``).
    tapped : bool
        True: the screw goes through the plate into the actuator's tapped hole (the plate has a clearance
        hole); False: through the actuator's flange into a pilot hole in the plate (thread-forming).
    clamp_mm, engagement_mm : float
        What the screw clamps and the thread it engages (the plate's thickness is filled in by the caller
        where it is one of them: see :func:`fastening`).
    plate_hole_mm : float
        The plate's hole (mm, finished size with the process's compensation).
    """

    size: str
    tapped: bool
    clamp_mm: float
    engagement_mm: float
    plate_hole_mm: float


def _nominal(size: str) -> float:
    return float(size.lstrip("M"))


def screw_for_hole(hole: MountHole) -> str:
    """The ISO 4762 size for a mounting hole: its thread if tapped, else the largest size whose ISO 7089
    washer bore (a close clearance) still passes the hole."""
    if hole.thread:
        if hole.thread not in ISO4762:
            raise SpecError("actuator.model", f"no catalogued {hole.thread} screw")
        return hole.thread
    fits = [s for s in ISO4762 if s in ISO7089 and ISO7089[s][0] <= hole.diameter_mm + 1e-9]
    if not fits:
        raise SpecError("actuator.model", f"no catalogued screw passes a Ø{hole.diameter_mm:g} mm mounting hole")
    return max(fits, key=_nominal)


def flange_thickness(entry: Actuator, hole: MountHole) -> float:
    """Thickness (mm) of the flange a through hole is in: the box under the hole's face that holds it."""
    under = [b.z1 - b.z0 for b in entry.body or ()
             if b.x0 < hole.x < b.x1 and b.y0 < hole.y < b.y1 and abs(b.z1 - hole.z) < 1e-6]
    if not under:
        raise SpecError("actuator.model", f"{entry.key!r}: no flange under the mounting hole at "
                                          f"({hole.x:g}, {hole.y:g})")
    return min(under)


def fastening(entry: Actuator, hole: MountHole, plate_mm: float, clearance_mm: float,
              compensation_mm: float) -> Fastening:
    """How the mounting hole ``hole`` is screwed to a plate ``plate_mm`` thick (see :class:`Fastening`)."""
    size = screw_for_hole(hole)
    d = _nominal(size)
    if hole.thread:
        return Fastening(size, True, plate_mm, TAPPED_ENGAGEMENT * d,
                         d + 2.0 * clearance_mm + compensation_mm)
    return Fastening(size, False, flange_thickness(entry, hole), plate_mm, PILOT_FRACTION * d + compensation_mm)


def mount_plate_z(entry: Actuator) -> float:
    """Entry z of the mounting face: the plate lies on it, on the output side (every hole of an entry is
    on one face)."""
    faces = {round(h.z, 9) for h in entry.mounting_holes or ()}
    if len(faces) != 1:
        raise SpecError("actuator.model", f"{entry.key!r}: mounting holes on {len(faces)} faces, expected one")
    return float(faces.pop())


def plate_cutouts(entry: Actuator, plate_z0: float, plate_z1: float, clearance_mm: float) -> list[np.ndarray]:
    """Rectangles (entry frame, CCW) the plate must cut out: every box of the body that passes through the
    plate's entry z range, grown by ``clearance_mm``; overlapping rectangles are merged into their bounding
    rectangle."""
    rects = [[b.x0 - clearance_mm, b.y0 - clearance_mm, b.x1 + clearance_mm, b.y1 + clearance_mm]
             for b in entry.body or () if b.z0 < plate_z1 - 1e-9 and b.z1 > plate_z0 + 1e-9]
    merged = True
    while merged and len(rects) > 1:
        merged = False
        for i in range(len(rects)):
            for j in range(i + 1, len(rects)):
                a, b = rects[i], rects[j]
                if a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3]:
                    rects[i] = [min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])]
                    del rects[j]
                    merged = True
                    break
            if merged:
                break
    return [rectangle(*r) for r in rects]
