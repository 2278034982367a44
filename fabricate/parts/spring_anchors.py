"""Where a torsion spring's legs are anchored: a hole for each leg's end in a plate, at the leg length from
the pin where the plate has the process's wall round it, the far one clear of the near plate over the motion
(:mod:`fabricate.parts.springs` places the spring and calls :func:`anchor_point`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.errors import SpecError

if TYPE_CHECKING:
    from fabricate.parts.model import Part

#: Poses (at most) over which an anchor's leg is kept clear of the other plate while placing it (the
#: interference sweep then checks every pose).
ANCHOR_POSES = 90
#: Angular step (degrees) of the anchor search round the pin.
ANCHOR_STEP_DEG = 2.0
#: Radial step (mm) by which an anchor moves in from the leg length when no place fits there.
ANCHOR_RADIAL_STEP_MM = 0.5


def plate_material(part: Part, tol: float) -> Any:
    """A part's plate as a shapely polygon (its holes cut), at chord tolerance ``tol``."""
    rings = part.polygons(tol)
    return shapely.Polygon(rings[0], [r for r in rings[1:]]).buffer(0)


def to_frame(points: np.ndarray, pose_from: np.ndarray, pose_to: np.ndarray) -> np.ndarray:
    """Points (k, 2) of a body at poses ``pose_from`` (n, 3) in the frame of a body at ``pose_to``: (n, k, 2)."""
    cf, sf = np.cos(pose_from[:, 2]), np.sin(pose_from[:, 2])
    wx = pose_from[:, None, 0] + cf[:, None] * points[None, :, 0] - sf[:, None] * points[None, :, 1]
    wy = pose_from[:, None, 1] + sf[:, None] * points[None, :, 0] + cf[:, None] * points[None, :, 1]
    dx, dy = wx - pose_to[:, None, 0], wy - pose_to[:, None, 1]
    ct, st = np.cos(pose_to[:, 2])[:, None], np.sin(pose_to[:, 2])[:, None]
    return np.stack([ct * dx + st * dy, -st * dx + ct * dy], axis=-1)


def anchor_point(material: Any, axis: np.ndarray, radius_max: float, radius_min: float, keep_in: float,
            clear_of: tuple[Any, np.ndarray, np.ndarray, float] | None = None) -> tuple[np.ndarray, float]:
    """An anchor hole centre round ``axis`` in a plate: the largest radius from ``radius_max`` down to
    ``radius_min`` with a place ``keep_in`` inside the plate's material (its wall round the hole), at the
    angle of most margin.

    ``clear_of`` = (other plate's material, this body's poses, the other's poses, gap): the leg must also
    stay ``gap`` outside the other plate at every pose (the far leg passing the near plate).
    """
    inner = material.buffer(-keep_in)
    angles = np.radians(np.arange(0.0, 360.0, ANCHOR_STEP_DEG))
    radius = radius_max
    while radius >= radius_min - 1e-9:
        pts = axis + radius * np.column_stack([np.cos(angles), np.sin(angles)])
        inside = shapely.contains_xy(inner, pts[:, 0], pts[:, 1])
        if inside.any():
            margin = np.where(inside, shapely.distance(inner.boundary, shapely.points(pts)), -np.inf)
            if clear_of is not None:
                other, own_poses, other_poses, gap = clear_of
                seen = to_frame(pts, own_poses, other_poses)            # (n, k, 2)
                dist = shapely.distance(other, shapely.points(seen.reshape(-1, 2))).reshape(seen.shape[:2])
                spare = dist.min(axis=0) - gap
                margin = np.where(spare >= 0.0, np.minimum(margin, spare), -np.inf)
            best = int(np.argmax(margin))
            if math.isfinite(float(margin[best])):
                return pts[best], radius
        radius -= ANCHOR_RADIAL_STEP_MM
    raise SpecError("springs", "no place for a leg anchor")


def towards(material: Any, axis: np.ndarray, radius: float) -> np.ndarray:
    """The point ``radius`` from ``axis`` towards the plate's centroid (any direction for a round plate)."""
    direction = np.array([material.centroid.x, material.centroid.y]) - axis
    norm = float(np.hypot(*direction))
    return axis + radius * (direction / norm if norm > 1e-9 else np.array([1.0, 0.0]))
