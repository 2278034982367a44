"""Features a part gets besides its bosses and pin holes, as plan-view geometry in body coordinates: a
slider's guide pins and the slot they run in, and a fingertip pad's circular segment.

:func:`fabricate.parts.build.build_parts` adds them to the parts it draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fabricate.errors import GeometryError
from fabricate.mechanism import Mechanism, Motion, Slider
from fabricate.parts.model import BulgePath
from fabricate.parts.profiles import circle_hull
from fabricate.planar import polygon_area, rotation, wrap_angle


@dataclass(frozen=True)
class SliderGuides:
    """Two guide pins fixed in a slider's reference body (two, so the rod cannot turn) and the slot in the
    rod (the push rod's body) they run in.

    Attributes
    ----------
    pins : tuple of (str, (2,) array)
        Pin name (the first is the joint's, the second ``<joint>_guide``) and centre in the reference body.
    slot : BulgePath
        The slot's contour in the rod: it covers where both pins travel over the motion.
    ends : (2, 2) array
        The slot's end centres in the rod (the rod's outline takes in a boss round each).
    """

    pins: tuple[tuple[str, np.ndarray], ...]
    slot: BulgePath
    ends: np.ndarray


def slider_guides(mechanism: Mechanism, motion: Motion, joint: Slider, boss_radius_mm: float, hole_mm: float,
                  min_wall_mm: float) -> SliderGuides:
    """The guide pins and slot of a slider; the pins stand a boss and two walls apart.

    Raises
    ------
    GeometryError
        When the slot runs into another point (pin hole) of the rod.
    """
    axis_a, axis_b, s_min, s_max = _slider_travel(motion, joint)
    ref_point = mechanism.body(joint.body_a).point(joint.name)
    rod = mechanism.body(joint.body_b)
    rod_point = rod.point(joint.name)
    spacing = _guide_spacing(rod, joint.name, rod_point, axis_b, s_min, s_max,
                             2.0 * boss_radius_mm + 2.0 * min_wall_mm)
    pins = tuple((joint.name if k == 0 else f"{joint.name}_guide", ref_point + offset * axis_a)
                 for k, offset in enumerate((0.0, spacing)))
    # a guide pin at ref + e*axis sits at rod_point - (s - e)*axis_b in the rod: one slot covers both
    ends = np.array([rod_point - (s_max - min(spacing, 0.0)) * axis_b,
                     rod_point - (s_min - max(spacing, 0.0)) * axis_b])
    for other in rod.points:
        centre = rod.point(other)
        if other != joint.name and _segment_distance(centre, ends) < hole_mm:
            raise GeometryError(f"slider {joint.name}: the guide slot in {joint.body_b!r} runs into its "
                                f"point {other!r}; move the slider point or shorten the stroke")
    return SliderGuides(pins=pins, slot=circle_hull(ends, hole_mm / 2.0), ends=ends)


def _slider_travel(motion: Motion, joint: Slider) -> tuple[np.ndarray, np.ndarray, float, float]:
    """A slider's axis in both bodies and the rod's travel along it.

    Returns
    -------
    axis_a : (2,) unit axis in the reference body; axis_b : (2,) the same axis in the rod body;
    s_min, s_max : float, travel of the rod point along the axis (mm) over the motion.
    """
    axis_a = np.asarray(joint.axis, dtype=np.float64)
    axis_a = axis_a / np.hypot(*axis_a)
    axis_b = rotation(-joint.angle) @ axis_a
    pa = motion.point(joint.name, joint.body_a)
    pb = motion.point(joint.name, joint.body_b)
    theta_a = motion.pose(joint.body_a)[:, 2]
    axis_world = np.einsum("nij,j->ni", rotation(theta_a), axis_a)
    travel = np.einsum("ni,ni->n", pb - pa, axis_world)
    return axis_a, axis_b, float(travel.min()), float(travel.max())


def _segment_distance(point: np.ndarray, ends: np.ndarray) -> float:
    """Distance (mm) from a point to the segment between two ends (2, 2)."""
    d = ends[1] - ends[0]
    t = float(np.clip(np.dot(point - ends[0], d) / max(float(np.dot(d, d)), 1e-30), 0.0, 1.0))
    return float(np.hypot(*(point - ends[0] - t * d)))


def _guide_spacing(rod: Any, slider: str, rod_point: np.ndarray, axis_b: np.ndarray, s_min: float,
                   s_max: float, spacing: float) -> float:
    """Signed offset (mm, along the slide axis in the reference body) of the second guide pin.

    The slot in the rod covers where both guide pins travel; the second pin goes on the side that keeps
    the slot furthest from the rod's other points (its pin holes).
    """
    others = [rod.point(p) for p in rod.points if p != slider]
    if not others:
        return spacing
    best = (-math.inf, spacing)
    for e in (spacing, -spacing):
        ends = np.array([rod_point - (s_max - min(e, 0.0)) * axis_b, rod_point - (s_min - max(e, 0.0)) * axis_b])
        clearance = min(_segment_distance(p, ends) for p in others)
        if clearance > best[0] + 1e-9:
            best = (clearance, e)
    return best[1]


def pad_segment(centre: np.ndarray, start: np.ndarray, end: np.ndarray, chord_tolerance_mm: float) -> np.ndarray:
    """The circular segment cut from the circle about ``centre`` by the chord ``start``–``end`` (the minor
    arc's side), as a CCW polygon (n, 2) whose arc has sagitta ≤ the tolerance.

    Raises
    ------
    GeometryError
        When the two points are not on one circle about ``centre``.
    """
    r0, r1 = float(np.hypot(*(start - centre))), float(np.hypot(*(end - centre)))
    if abs(r0 - r1) > 1e-6 * max(r0, 1.0) or r0 == 0.0:
        raise GeometryError(f"pad arc ends are {r0:.4g} and {r1:.4g} mm from the pad centre: not one circle")
    turn = float(wrap_angle(np.arctan2(*(end - centre)[::-1]) - np.arctan2(*(start - centre)[::-1])))
    ring = BulgePath(np.array([start, end]), np.array([np.tan(turn / 4.0), 0.0])).polygon(chord_tolerance_mm)
    return ring if polygon_area(ring) > 0 else ring[::-1]
