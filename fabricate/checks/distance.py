"""Exact planar clearance between two moving polygonal outlines (the narrow phase of the sweep).

Every part in this project is a prism: a planar outline (outer contour CCW, holes CW) extruded along z.
Two prisms whose z ranges overlap collide exactly when their outlines overlap in the plane, and their
3D clearance is the planar distance of the outlines; on disjoint z ranges the clearance is
``hypot(z gap, planar distance)``. So the sweep reduces to planar distances of posed outlines.

Method
------
All posed copies of outline B (in A's frame) are built in one vectorised shapely call. The overlap
test runs against A's prepared geometry for all poses at once. The distance of the poses that do not
overlap is taken on *clipped* outlines: when the distance ``d`` is at most ``search``, the closest
points lie in the window ``(bbox(A) ⊕ search) ∩ (bbox(B) ⊕ search)`` (a closest point of A is within
``d`` of B, hence in ``bbox(B) ⊕ d``, and in ``bbox(A)``), so clipping both outlines to that window
keeps the closest pair and the distance exactly, while GEOS only sees the few edges near the contact.
A window that is empty proves the distance exceeds ``search``. Successive poses differ little, so
the previous pose's distance plus the largest point displacement since then is tried first as the
search length (windows of a few edges, e.g. at the teeth in mesh), and the full search length only
when that guess proves too short.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely import lib as _geos

from fabricate.planar import polygon_area, relative_poses

#: Largest number of posed outline vertices held at once by :func:`planar_clearance` and :func:`overlap_areas`
#: (shapely geometry takes ~150 bytes a vertex: about 10 MB). The poses are streamed through in chunks of this
#: many vertices, so the memory of a sweep does not grow with its poses (a 400-vertex outline: 164 poses a
#: chunk; the chunk's shapely calls cost far less than its per-pose distances, so a smaller chunk costs no time).
POSED_VERTICES_PER_CHUNK = 65_536


def poses_per_chunk(outline: Outline) -> int:
    """Poses of ``outline`` posed at once within :data:`POSED_VERTICES_PER_CHUNK` vertices (at least one)."""
    return max(1, POSED_VERTICES_PER_CHUNK // max(1, len(outline.vertices)))


@dataclass(frozen=True)
class RelativePoses:
    """Poses (x, y, theta) of frame B expressed in frame A, shape (n, 3) (mm, mm, rad)."""

    q: np.ndarray

    @staticmethod
    def between(pose_a: np.ndarray, pose_b: np.ndarray) -> RelativePoses:
        """From world poses of A and B, each (n, 3)."""
        return RelativePoses(relative_poses(pose_a, pose_b))

    def inverse(self) -> RelativePoses:
        """Poses of frame A in frame B."""
        x, y, th = self.q[:, 0], self.q[:, 1], self.q[:, 2]
        c, s = np.cos(th), np.sin(th)
        return RelativePoses(np.column_stack([-(c * x + s * y), s * x - c * y, -th]))

    def apply(self, points: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """Map points of frame B into frame A.

        Parameters
        ----------
        points : (m, 2) array
            Points in frame B.
        index : (m,) int array, optional
            Pose of each point; without it every point is mapped by every pose, giving (n, m, 2).
        """
        if index is None:
            x, y, th = (self.q[:, k, None] for k in range(3))
        else:
            x, y, th = (self.q[index, k] for k in range(3))
        c, s = np.cos(th), np.sin(th)
        px, py = points[..., 0], points[..., 1]
        return np.stack([c * px - s * py + x, s * px + c * py + y], axis=-1)


class Outline:
    """A planar region (outer contour CCW, holes CW) in its body frame, ready for posed queries.

    Parameters
    ----------
    rings : list of (k, 2) arrays
        Outer contour first, then holes, mm.
    """

    def __init__(self, rings: list[np.ndarray]) -> None:
        oriented = []
        for k, ring in enumerate(rings):
            ring = _clean_ring(np.asarray(ring, dtype=np.float64))
            if (polygon_area(ring) > 0) != (k == 0):
                ring = ring[::-1]
            oriented.append(ring)
        self.rings = oriented
        self.vertices = np.concatenate(oriented)
        self.centre = 0.5 * (self.vertices.min(axis=0) + self.vertices.max(axis=0))
        self.radius = float(np.max(np.hypot(*(self.vertices - self.centre).T)))
        self.polygon = shapely.Polygon(oriented[0], oriented[1:])
        shapely.prepare(self.polygon)
        self.bounds = np.asarray(self.polygon.bounds)
        self.box = tuple(self.bounds.tolist())  # the same four numbers, as Python floats (the per-pose arithmetic)

    def posed(self, rel: RelativePoses) -> np.ndarray:
        """This outline moved by every pose of ``rel``: an (n,) array of shapely Polygons."""
        counts = np.array([len(r) for r in self.rings])
        n = len(rel.q)
        coords = rel.apply(self.vertices).reshape(-1, 2)
        ring_id = np.repeat(np.arange(len(self.rings)), counts)
        rings = shapely.linearrings(coords, indices=(np.arange(n)[:, None] * len(self.rings)
                                                     + ring_id[None, :]).ravel())
        polygons: np.ndarray = shapely.polygons(rings, indices=np.repeat(np.arange(n), len(self.rings)))
        return polygons


def _clean_ring(ring: np.ndarray) -> np.ndarray:
    """Drop a repeated closing vertex and consecutive duplicates (zero-length edges)."""
    if len(ring) > 1 and np.allclose(ring[0], ring[-1], rtol=0.0, atol=1e-12):
        ring = ring[:-1]
    step = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    return ring[step > 1e-12]


def planar_clearance(a: Outline, b: Outline, rel: RelativePoses, search_mm: float) -> np.ndarray:
    """Planar clearance between outline ``a`` and outline ``b`` posed by ``rel`` (B in A's frame).

    Parameters
    ----------
    a, b : Outline
    rel : RelativePoses
        (n, 3) poses of B's frame in A's frame.
    search_mm : float
        Distances beyond this are not resolved.

    Returns
    -------
    (n,) float64 array
        Distance (mm) between the regions where ≤ ``search_mm``; ``+inf`` where farther; 0 where
        the boundaries touch; ``-inf`` where the interiors overlap.
    """
    n = len(rel.q)
    out = np.full(n, np.inf)
    if n == 0:
        return out
    # poses follow each other closely: the previous distance plus the largest point displacement
    # since then bounds this one, and a window that small is much cheaper (retried at full size
    # when the guess proves too small); the displacements are of the whole run, and the guess carries
    # over from one chunk to the next, so the values do not depend on the chunk size
    centre = rel.apply(b.centre[None, :])[:, 0]
    step = np.hypot(*np.diff(centre, axis=0).T) + np.abs(np.diff(rel.q[:, 2])) * b.radius
    moved = np.concatenate([[math.inf], step])
    previous, previous_index = math.inf, -2
    chunk = poses_per_chunk(b)
    # the posed copies of B are shapely polygons held at once: pose them a chunk at a time so memory stays
    # bounded for any number of poses
    for lo in range(0, n, chunk):
        polys = b.posed(RelativePoses(rel.q[lo:lo + chunk]))
        meets = shapely.intersects(a.polygon, polys)
        if np.any(meets):
            idx = np.nonzero(meets)[0]
            touching = shapely.touches(a.polygon, polys[idx])
            out[lo + idx] = np.where(touching, 0.0, -math.inf)
        rest = np.nonzero(~meets)[0]
        if len(rest) == 0:
            continue
        bb = shapely.bounds(polys).tolist()
        for k in rest:
            i = lo + int(k)
            guess = previous + moved[i] + 1e-9 if previous_index == i - 1 else math.inf
            tried = guess < search_mm
            d = _clipped_distance(a, polys[k], bb[k], guess) if tried else math.inf
            if not (tried and d <= guess):  # no guess, or the guess was too short
                d = _clipped_distance(a, polys[k], bb[k], search_mm)
            if d <= search_mm:
                out[i] = d
            previous, previous_index = d, i
    return out


def _clipped_distance(a: Outline, poly_b: shapely.Polygon, bounds_b: list[float], search: float) -> float:
    """Distance of ``a`` and ``poly_b`` if at most ``search`` (exact), else a value > ``search``."""
    # called once per pose: plain floats and shapely's ufuncs (the same GEOS calls as shapely's public
    # functions, without their argument checks), for a sweep makes tens of thousands of these calls
    # at a distance of exactly ``search`` the closest points can lie on the window's edge, where clipping
    # leaves a zero-area slice that GEOS drops: the window is a hair wider than the search length
    pad = search * (1.0 + 1e-9) + 1e-12
    ax0, ay0, ax1, ay1 = a.box
    bx0, by0, bx1, by1 = bounds_b
    lo_x, lo_y = max(ax0, bx0) - pad, max(ay0, by0) - pad
    hi_x, hi_y = min(ax1, bx1) + pad, min(ay1, by1) + pad
    # boxes 2 x search apart or more on an axis: the parts are farther apart than search (which is > 0);
    # lo == hi would also hand GEOS a degenerate clip window, which it refuses
    if lo_x >= hi_x or lo_y >= hi_y:
        return math.inf
    clip_a = _geos.clip_by_rect(a.polygon, lo_x, lo_y, hi_x, hi_y)
    if _geos.is_empty(clip_a):
        return math.inf
    # B's closest point is within ``search`` of the clipped A (which holds A's closest point)
    cx0, cy0, cx1, cy1 = _geos.bounds(clip_a).tolist()
    clip_b = _geos.clip_by_rect(poly_b, max(lo_x, cx0 - pad), max(lo_y, cy0 - pad),
                                min(hi_x, cx1 + pad), min(hi_y, cy1 + pad))
    if _geos.is_empty(clip_b):
        return math.inf
    return float(_geos.distance(clip_a, clip_b))


def overlap_areas(a: Outline, b: Outline, rel: RelativePoses) -> np.ndarray:
    """Area (mm^2) of the overlap of ``a`` and ``b`` posed by each of ``rel`` (n,)."""
    chunk = poses_per_chunk(b)  # bounded memory, as above (each pose's area is its own)
    return np.concatenate([
        np.asarray(shapely.area(shapely.intersection(a.polygon, b.posed(RelativePoses(rel.q[i:i + chunk])))),
                   dtype=np.float64)
        for i in range(0, len(rel.q), chunk)] or [np.zeros(0)])
