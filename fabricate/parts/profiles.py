"""Exact 2D part profiles: hulls of circles as line/arc paths, gear fusion, kerf offsets.

Every function takes and returns plain arrays or :class:`~fabricate.parts.model.BulgePath`; lengths in mm.
A hull of circles is kept exact (tangent lines and true arcs) so the DXF exporter can write it as a
closed LWPOLYLINE with bulges; a profile fused with a gear outline becomes a fine polyline because the
gear teeth are a polygon already (chord error within the tolerance it was built with).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from scipy.spatial import ConvexHull
from shapely.geometry import Polygon

from fabricate.errors import GeometryError
from fabricate.parts.model import BulgePath
from fabricate.planar import polygon_area

#: Sampling of each circle when finding which circles lie on a hull (the arcs are then exact).
_HULL_SAMPLES = 720


def circle_path(centre: np.ndarray, radius: float) -> BulgePath:
    """A full circle as a two-vertex bulge path (two counter-clockwise half circles)."""
    c = np.asarray(centre, dtype=np.float64)
    vertices = np.array([[c[0] + radius, c[1]], [c[0] - radius, c[1]]])
    return BulgePath(vertices, np.array([1.0, 1.0]))


def circle_hull(centres: np.ndarray, radii: np.ndarray | float) -> BulgePath:
    """Exact convex hull of circles: outer tangent lines joined by counter-clockwise arcs.

    Parameters
    ----------
    centres : (n, 2) array
        Circle centres, mm.
    radii : (n,) array or float
        Radii, mm (> 0).

    Returns
    -------
    BulgePath
        Counter-clockwise path; vertices are the tangent points, bulge 0 on the tangent lines and
        ``tan(turn / 4)`` on the arcs. Two equal circles give the rounded slot of a binary link.

    Notes
    -----
    Which circles lie on the hull, and in which order, is found from a dense sampling of every circle
    (a circle that protrudes less than ``r (1 - cos(pi / 720))`` may be missed, an error below 1e-5 r);
    the tangent points and arcs themselves are computed exactly.
    """
    centres = np.asarray(centres, dtype=np.float64).reshape(-1, 2)
    radii = np.broadcast_to(np.asarray(radii, dtype=np.float64), (len(centres),)).copy()
    if len(centres) == 0 or np.any(radii <= 0):
        raise GeometryError("circle_hull needs at least one circle of positive radius")
    # merge coincident circles (keep the largest)
    order: list[int] = []
    for i in np.argsort(-radii, kind="stable"):
        if all(np.hypot(*(centres[i] - centres[j])) + radii[i] > radii[j] + 1e-9 for j in order):
            order.append(int(i))
    order.sort()
    centres, radii = centres[order], radii[order]
    if len(centres) == 1:
        return circle_path(centres[0], float(radii[0]))
    angles = np.linspace(0.0, 2.0 * math.pi, _HULL_SAMPLES, endpoint=False)
    samples = (centres[:, None, :] + radii[:, None, None]
               * np.stack([np.cos(angles), np.sin(angles)], -1)[None]).reshape(-1, 2)
    owner = np.repeat(np.arange(len(centres)), _HULL_SAMPLES)
    hull_idx = _convex_hull_indices(samples)
    sequence: list[int] = []
    for k in owner[hull_idx]:
        if not sequence or sequence[-1] != k:
            sequence.append(int(k))
    while len(sequence) > 1 and sequence[0] == sequence[-1]:
        sequence.pop()
    if len(sequence) == 1:
        return circle_path(centres[sequence[0]], float(radii[sequence[0]]))
    m = len(sequence)
    # outward normal of the tangent from circle i to circle j (CCW travel, outside on the right)
    normals = []
    for a in range(m):
        i, j = sequence[a], sequence[(a + 1) % m]
        d = centres[j] - centres[i]
        length = float(np.hypot(*d))
        dh = d / length
        right = np.array([dh[1], -dh[0]])
        along = (radii[i] - radii[j]) / length
        normals.append(along * dh + math.sqrt(max(0.0, 1.0 - along * along)) * right)
    vertices: list[np.ndarray] = []
    bulges: list[float] = []
    for a in range(m):
        i = sequence[a]
        n_out = normals[a]
        n_in = normals[a - 1]  # tangent arriving at circle i
        turn = (math.atan2(n_out[1], n_out[0]) - math.atan2(n_in[1], n_in[0])) % (2.0 * math.pi)
        start = centres[i] + radii[i] * n_in
        end = centres[i] + radii[i] * n_out
        if turn > 1e-12 and np.hypot(*(end - start)) > 1e-9:
            vertices.append(start)
            bulges.append(math.tan(turn / 4.0))
        vertices.append(end)
        bulges.append(0.0)
    return BulgePath(np.array(vertices), np.array(bulges))


def _convex_hull_indices(points: np.ndarray) -> np.ndarray:
    """Indices of the convex hull vertices of ``points`` (n, 2), counter-clockwise (qhull)."""
    return np.asarray(ConvexHull(points).vertices, dtype=np.int64)


def fuse_polygons(path: BulgePath, extra: list[np.ndarray], chord_tolerance_mm: float) -> BulgePath:
    """Union of a profile with extra polygons (gear outlines, hubs) as one outer polyline.

    Parameters
    ----------
    path : BulgePath
        The body's own profile.
    extra : list of (n, 2) arrays
        Polygons in the same coordinates (counter-clockwise or not).
    chord_tolerance_mm : float
        Polygonisation of ``path`` before the union.

    Returns
    -------
    BulgePath
        Counter-clockwise straight-segment path of the union's outer boundary (enclosed gaps are
        filled: a plate has only its pin holes as holes).

    Raises
    ------
    GeometryError
        When the pieces do not join into one region.
    """
    shapes = [Polygon(path.polygon(chord_tolerance_mm))]
    shapes += [Polygon(np.asarray(p, dtype=np.float64)).buffer(0) for p in extra]
    union = shapely.union_all(shapes)
    if union.geom_type != "Polygon":
        raise GeometryError("fused profile falls apart into several pieces (gear not attached to its hub?)")
    ring = np.asarray(union.exterior.coords, dtype=np.float64)[:-1]
    ring = _drop_collinear(ring)
    if polygon_area(ring) < 0:
        ring = ring[::-1]
    # start at the lexicographically smallest vertex so the same input always gives the same bytes
    start = int(np.lexsort((ring[:, 1], ring[:, 0]))[0])
    return BulgePath.polyline(np.roll(ring, -start, axis=0))


def _drop_collinear(ring: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    prev = np.roll(ring, 1, axis=0)
    nxt = np.roll(ring, -1, axis=0)
    cross = (ring[:, 0] - prev[:, 0]) * (nxt[:, 1] - prev[:, 1]) - (ring[:, 1] - prev[:, 1]) * (
        nxt[:, 0] - prev[:, 0])
    span = np.hypot(nxt[:, 0] - prev[:, 0], nxt[:, 1] - prev[:, 1])
    keep = np.abs(cross) > tol * np.maximum(span, 1e-12)
    kept: np.ndarray = ring[keep]
    return kept


def _offset_polygon(path: BulgePath, distance_mm: float) -> BulgePath:
    """Offset of a straight-segment path by buffering (see :func:`offset_path`)."""
    polygon = shapely.Polygon(path.vertices)
    grown = polygon.buffer(distance_mm, quad_segs=32, join_style="round")
    if grown.geom_type != "Polygon" or grown.is_empty:
        raise GeometryError(f"offset by {distance_mm:g} mm splits or removes the profile")
    ring = _drop_collinear(np.asarray(grown.exterior.coords, dtype=np.float64)[:-1])
    if polygon_area(ring) < 0:
        ring = ring[::-1]
    start = int(np.lexsort((ring[:, 1], ring[:, 0]))[0])
    return BulgePath.polyline(np.roll(ring, -start, axis=0))


def _segment_normals(path: BulgePath) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals (for a CCW path) at the start and end of every segment; each (n, 2)."""
    v = path.vertices
    w = np.roll(v, -1, axis=0)
    chord = w - v
    length = np.hypot(chord[:, 0], chord[:, 1])
    length = np.where(length > 0, length, 1.0)
    tangent = chord / length[:, None]
    # an arc's tangent at its ends is the chord direction turned by -/+ half its included angle
    half = 2.0 * np.arctan(path.bulges)
    c, s = np.cos(half), np.sin(half)
    t_start = np.column_stack([c * tangent[:, 0] + s * tangent[:, 1], -s * tangent[:, 0] + c * tangent[:, 1]])
    t_end = np.column_stack([c * tangent[:, 0] - s * tangent[:, 1], s * tangent[:, 0] + c * tangent[:, 1]])
    right = np.array([[0.0, -1.0], [1.0, 0.0]])  # row vector t @ right = (ty, -tx), the right normal
    return t_start @ right, t_end @ right


def offset_path(path: BulgePath, distance_mm: float) -> BulgePath:
    """Offset a counter-clockwise closed path outwards by ``distance_mm`` (negative: inwards).

    A path with arcs (a circle hull: tangent-continuous at its arc ends) is offset exactly: vertices
    move along their normals and arcs keep their included angle. A polygon (a profile fused with gear
    teeth) is offset as its Minkowski sum with a disc (round joins, sagitta below 3e-4 of the distance),
    which trims the loops a vertex-by-vertex offset would make in tight concave corners.
    """
    if distance_mm == 0.0:
        return path
    if not np.any(path.bulges):
        return _offset_polygon(path, distance_mm)
    n_start, n_end = _segment_normals(path)
    n_in = np.roll(n_end, 1, axis=0)  # normal of the segment arriving at each vertex
    n_out = n_start
    dot = np.clip(np.einsum("ij,ij->i", n_in, n_out), -0.95, 1.0)
    shift = (n_in + n_out) / (1.0 + dot)[:, None]
    # the exact signed area: a polygon of the path at a chord tolerance near the radius (one circle offset by
    # its own radius) degenerates to a chord whose area is rounding noise of either sign
    if path.area() < 0:
        shift = -shift
    return BulgePath(path.vertices + distance_mm * shift, path.bulges.copy())


def touching_pairs(lines: Sequence[shapely.Geometry]) -> list[tuple[int, int]]:
    """Index pairs ``i < j`` of the geometries that touch, cross or overlap, each pair once (a laser would cut
    such contours twice, or cut one part into another)."""
    tree = shapely.STRtree(lines)
    return [(int(i), int(j)) for i, j in zip(*tree.query(lines, predicate="intersects"), strict=True) if i < j]
