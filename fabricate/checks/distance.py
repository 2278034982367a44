"""Fast exact planar clearance between two moving polygonal outlines (the narrow phase of the sweep).

Every part in this project is a prism: a planar outline (outer contour CCW, holes CW) extruded along z.
Two prisms whose z ranges overlap collide exactly when their outlines overlap in the plane, and their
3D clearance is the planar distance of the outlines; on disjoint z ranges the clearance is
``hypot(z gap, planar distance)``. So the whole sweep reduces to planar distances of posed outlines,
which this module computes for many poses at once, with numpy and a k-d tree, without building a
posed geometry per pose.

Method
------
The distance between two disjoint polygonal regions is attained between a vertex of one and an edge of
the other. So the signed distance of every vertex of B to the boundary of A (negative inside A's
material) and of every vertex of A to B's boundary, minimised, is the clearance; a negative value
means the outlines overlap. Two levels keep it cheap:

1. *Chunks*: each outline's vertices are grouped in runs of :data:`CHUNK` consecutive vertices with a
   bounding circle. A chunk whose centre is farther than ``search + radius + h/2`` from every vertex of
   the other outline (``h`` = longest edge after subdivision) cannot hold a vertex within ``search``
   of the other boundary, and is skipped.
2. *Vertices* of the surviving chunks: the ``k`` nearest vertices of the other outline give the
   candidate edges (the two edges at each); the exact point-to-segment distance and the side of the
   nearest edge give the signed distance. Edges are subdivided to at most ``h`` so a nearest edge always
   has an endpoint near the query point.

An outline lying wholly inside the other's material with no boundary nearby (a pin sunk into a plate)
has no vertex near the other boundary; a point-in-polygon test of one vertex per pose catches it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree

from fabricate.planar import polygon_area

#: Vertices per chunk of the outline hierarchy.
CHUNK = 24
#: Longest run of boundary (mm) in one chunk, so that a chunk's circle stays small.
CHUNK_SPAN_MM = 0.6
#: Nearest vertices whose edges are examined for each query point.
NEIGHBOURS = 8


@dataclass(frozen=True)
class RelativePoses:
    """Poses (x, y, theta) of frame B expressed in frame A, shape (n, 3) (mm, mm, rad)."""

    q: np.ndarray

    @staticmethod
    def between(pose_a: np.ndarray, pose_b: np.ndarray) -> RelativePoses:
        """From world poses of A and B, each (n, 3)."""
        pose_a = np.asarray(pose_a, dtype=np.float64)
        pose_b = np.asarray(pose_b, dtype=np.float64)
        c, s = np.cos(pose_a[:, 2]), np.sin(pose_a[:, 2])
        dx = pose_b[:, 0] - pose_a[:, 0]
        dy = pose_b[:, 1] - pose_a[:, 1]
        return RelativePoses(np.column_stack([c * dx + s * dy, -s * dx + c * dy, pose_b[:, 2] - pose_a[:, 2]]))

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
    """A planar region (outer contour CCW, holes CW) prepared for fast signed-distance queries.

    Parameters
    ----------
    rings : list of (k, 2) arrays
        Outer contour first, then holes, mm, in the body frame.
    max_edge_mm : float
        Edges longer than this are split into equal collinear pieces (the geometry is unchanged).
    """

    def __init__(self, rings: list[np.ndarray], max_edge_mm: float = 0.05) -> None:
        verts: list[np.ndarray] = []
        nxt: list[np.ndarray] = []
        runs: list[np.ndarray] = []  # per chunk: first vertex, vertex count, ring start, ring length
        start = 0
        oriented = []
        for k, ring in enumerate(rings):
            ring = _clean_ring(np.asarray(ring, dtype=np.float64))
            # outer CCW, holes CW: the material is on the left of every directed edge
            if (polygon_area(ring) > 0) != (k == 0):
                ring = ring[::-1]
            oriented.append(ring)
            dense = _subdivide(ring, max_edge_mm)
            n = len(dense)
            idx = np.arange(start, start + n)
            verts.append(dense)
            nxt.append(np.roll(idx, -1))
            # chunks: runs of at most CHUNK vertices spanning at most CHUNK_SPAN_MM of boundary; each
            # also holds the first vertex of the next run so that it covers its edges
            step = np.hypot(*(np.roll(dense, -1, axis=0) - dense).T)
            arc = np.concatenate([[0.0], np.cumsum(step)[:-1]])
            key = (arc // CHUNK_SPAN_MM).astype(np.int64) * (n + 1) + np.arange(n) // CHUNK
            starts = np.concatenate([[0], np.nonzero(np.diff(key))[0] + 1])
            ends = np.concatenate([starts[1:], [n]])  # the next run's first vertex, wrapping
            runs.append(np.column_stack([starts + start, ends - starts, np.full(len(starts), start),
                                         np.full(len(starts), n)]))
            start += n
        self.rings = oriented
        self.vertices = np.concatenate(verts)
        self.next = np.concatenate(nxt)
        self.prev = np.empty_like(self.next)
        self.prev[self.next] = np.arange(len(self.next))
        edges = self.vertices[self.next] - self.vertices
        length = np.hypot(edges[:, 0], edges[:, 1])
        self.max_edge = float(np.max(length))
        # longest edge at each vertex: a vertex whose edge crosses another boundary is this close to it
        self.vertex_edge = np.maximum(length, length[self.prev])
        self.tree = cKDTree(self.vertices)
        # padded table of chunk vertices: repeats of a chunk's last vertex do not change a minimum
        first, count, ring_start, ring_len = np.concatenate(runs).T
        width = int(count.max()) + 1
        offset = np.minimum(np.arange(width)[None, :], count[:, None])
        self.chunk_table = ring_start[:, None] + (first[:, None] - ring_start[:, None] + offset) % ring_len[:, None]
        members = self.vertices[self.chunk_table]
        self.chunk_centres = 0.5 * (members.min(axis=1) + members.max(axis=1))
        self.chunk_radii = np.max(np.hypot(*(members - self.chunk_centres[:, None, :]).transpose(2, 0, 1)), axis=1)
        self.chunk_edge = self.vertex_edge[self.chunk_table].max(axis=1)
        self.centre = 0.5 * (self.vertices.min(axis=0) + self.vertices.max(axis=0))
        self.radius = float(np.max(np.hypot(*(self.vertices - self.centre).T)))
        self.polygon = shapely.Polygon(oriented[0], oriented[1:])
        shapely.prepare(self.polygon)

    # -- queries -------------------------------------------------------------------------------
    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (mm) of points (m, 2) in this outline's frame to its boundary;
        negative inside the material. Exact when a nearest edge has an endpoint among the
        :data:`NEIGHBOURS` nearest vertices (always, unless edges are much longer than the vertex
        spacing nearby); otherwise within ``max_edge / 2``."""
        points = np.asarray(points, dtype=np.float64)
        if len(points) == 0:
            return np.empty(0)
        k = min(NEIGHBOURS, len(self.vertices))
        _, near = self.tree.query(points, k=k)
        near = near.reshape(len(points), k)
        seg = np.concatenate([near, self.prev[near]], axis=1)  # edges starting at these vertices
        p0 = self.vertices[seg]
        e = self.vertices[self.next[seg]] - p0
        rel = points[:, None, :] - p0
        t = np.clip(np.einsum("mkj,mkj->mk", rel, e) / np.einsum("mkj,mkj->mk", e, e), 0.0, 1.0)
        diff = rel - t[..., None] * e
        dist = np.hypot(diff[..., 0], diff[..., 1])
        best = np.argmin(dist, axis=1)
        rows = np.arange(len(points))
        d = dist[rows, best]
        s = seg[rows, best]
        tb = t[rows, best]
        # the nearest point is interior to an edge: inside iff left of it; at a vertex use both edges
        # (convex corner: left of both; reflex corner: left of either)
        vertex = np.where(tb >= 1.0, self.next[s], s)
        at_vertex = (tb <= 0.0) | (tb >= 1.0)
        v = self.vertices[vertex]
        e_in = v - self.vertices[self.prev[vertex]]
        e_out = self.vertices[self.next[vertex]] - v
        left_in = _cross(e_in, points - self.vertices[self.prev[vertex]]) > 0.0
        left_out = _cross(e_out, points - v) > 0.0
        convex = _cross(e_in, e_out) > 0.0
        inside_vertex = np.where(convex, left_in & left_out, left_in | left_out)
        inside_edge = _cross(e[rows, best], rel[rows, best]) > 0.0
        inside = np.where(at_vertex, inside_vertex, inside_edge)
        return np.where(inside, -d, d)

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Whether points (m, 2) lie in the material (boundary excluded)."""
        return shapely.contains_xy(self.polygon, points[:, 0], points[:, 1])


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _clean_ring(ring: np.ndarray) -> np.ndarray:
    """Drop a repeated closing vertex and consecutive duplicates (zero-length edges)."""
    if len(ring) > 1 and np.allclose(ring[0], ring[-1], rtol=0.0, atol=1e-12):
        ring = ring[:-1]
    step = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    return ring[step > 1e-12]


def _subdivide(ring: np.ndarray, max_edge: float) -> np.ndarray:
    """Insert collinear points so that no edge is longer than ``max_edge``."""
    nxt = np.roll(ring, -1, axis=0)
    length = np.hypot(*(nxt - ring).T)
    pieces = np.maximum(1, np.ceil(length / max_edge).astype(int))
    if np.all(pieces == 1):
        return ring
    first = np.repeat(np.cumsum(pieces) - pieces, pieces)
    t = (np.arange(int(pieces.sum())) - first) / np.repeat(pieces, pieces)
    return np.repeat(ring, pieces, axis=0) + t[:, None] * np.repeat(nxt - ring, pieces, axis=0)


def _one_way(target: Outline, mover: Outline, rel: RelativePoses, search_mm: float) -> np.ndarray:
    """Smallest signed distance of ``mover``'s vertices to ``target``'s boundary per pose (n,),
    ``+inf`` where no vertex comes within ``search_mm``; ``rel`` maps mover frame → target frame.

    Only vertices that can beat the pose's best so far are evaluated exactly. A vertex that proves an
    overlap lies within one of its own edges of the target boundary (that edge crosses it), so a vertex
    that close is always kept and an overlap is never pruned away.
    """
    n = len(rel.q)
    out = np.full(n, np.inf)
    centres = rel.apply(mover.chunk_centres)  # (n, c, 2)
    half_edge = 0.5 * target.max_edge
    # level 0: chunk circle against the target's bounding circle
    gap0 = (np.hypot(*(centres - target.centre).transpose(2, 0, 1)) - target.radius
            - mover.chunk_radii[None, :])
    pose_idx, chunk_idx = np.nonzero(gap0 < search_mm)
    if len(pose_idx) == 0:
        return out
    # level 1: chunk circle against the nearest target vertex; the boundary is within half an edge
    # of a vertex, so [d - r - h/2, d + r] brackets the chunk's distances to the boundary
    d_centre, _ = target.tree.query(centres[pose_idx, chunk_idx])
    radius = mover.chunk_radii[chunk_idx]
    best = np.full(n, search_mm)
    np.minimum.at(best, pose_idx, d_centre + radius)
    keep = d_centre - radius - half_edge <= np.maximum(best[pose_idx], mover.chunk_edge[chunk_idx])
    pose_idx, chunk_idx = pose_idx[keep], chunk_idx[keep]
    if len(pose_idx) == 0:
        return out
    # level 2: the vertices of the surviving chunks, first against the nearest target vertex
    members = mover.chunk_table[chunk_idx].ravel()
    owner = np.repeat(pose_idx, mover.chunk_table.shape[1])
    pts = rel.apply(mover.vertices[members], owner)
    d_vertex, _ = target.tree.query(pts)
    best = np.full(n, search_mm)
    np.minimum.at(best, owner, d_vertex)
    keep = d_vertex - half_edge <= np.maximum(best[owner], mover.vertex_edge[members])
    pts, owner = pts[keep], owner[keep]
    sd = target.signed_distance(pts)
    np.minimum.at(out, owner, sd)
    out[out > search_mm] = np.inf
    return out


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
        Distance (mm) between the regions where ≤ ``search_mm``; ``+inf`` where farther; negative
        (a penetration depth along the boundary) where they overlap.
    """
    n = len(rel.q)
    d = np.full(n, np.inf)
    # cheap probe first: a sample of vertices inside the other's material proves an overlap, and the
    # exact pass (which would only refine a penetration depth) is skipped for those poses
    overlapping = _probe_overlap(a, b, rel) | _probe_overlap(b, a, rel.inverse())
    d[overlapping] = -math.inf
    rest = np.nonzero(~overlapping)[0]
    if len(rest) == 0:
        return d
    sub = RelativePoses(rel.q[rest])
    d[rest] = np.minimum(_one_way(a, b, sub, search_mm), _one_way(b, a, sub.inverse(), search_mm))
    # wholly inside the other's material with no boundary near: one vertex per pose tells
    far = rest[~(d[rest] <= 0.0)]
    if len(far):
        b_in_a = a.contains(rel.apply(np.repeat(b.vertices[:1], len(far), axis=0), far))
        a_in_b = b.contains(rel.inverse().apply(np.repeat(a.vertices[:1], len(far), axis=0), far))
        d[far[b_in_a | a_in_b]] = -math.inf
    return d


def _probe_overlap(target: Outline, mover: Outline, rel: RelativePoses, samples: int = 64) -> np.ndarray:
    """Poses (n,) where one of ~``samples`` evenly spread vertices of ``mover`` lies in ``target``."""
    step = max(1, len(mover.vertices) // samples)
    pts = rel.apply(mover.vertices[::step])  # (n, k, 2)
    inside = target.contains(pts.reshape(-1, 2)).reshape(pts.shape[:2])
    return inside.any(axis=1)


def overlap_areas(a: Outline, b: Outline, rel: RelativePoses) -> np.ndarray:
    """Area (mm^2) of the overlap of ``a`` and ``b`` posed by each of ``rel`` (n,), via shapely."""
    rings = b.rings
    counts = np.array([len(r) for r in rings])
    coords = np.concatenate(rings)
    n = len(rel.q)
    posed = rel.apply(coords)  # (n, m, 2)
    ring_id = np.repeat(np.arange(len(rings)), counts)
    ring_index = (np.arange(n)[:, None] * len(rings) + ring_id[None, :]).ravel()
    lr = shapely.linearrings(posed.reshape(-1, 2), indices=ring_index)
    polys = shapely.polygons(lr, indices=np.repeat(np.arange(n), len(rings)))
    return shapely.area(shapely.intersection(a.polygon, polys))
