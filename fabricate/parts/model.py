"""Part model: exact 2D profiles (lines and arcs as bulge paths, circles for holes), their polygonisation
by a chord tolerance, and the :class:`Part` record every exporter and check reads.

A profile is kept exact so the DXF exporter can write true arcs (LWPOLYLINE bulges) and CIRCLEs; meshes
and booleans use :meth:`BulgePath.polygon` with an explicit chord tolerance (sagitta, mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fabricate.planar import polygon_area


@dataclass(frozen=True)
class BulgePath:
    """A closed path of straight and circular segments (the DXF LWPOLYLINE model).

    Attributes
    ----------
    vertices : (n, 2) float64 array
        Vertices in mm, counter-clockwise for an outer contour. The path closes from the last vertex
        back to the first.
    bulges : (n,) float64 array
        ``tan(included_angle / 4)`` of the segment from vertex i to vertex i+1: 0 for a line, positive
        for a counter-clockwise arc.
    """

    vertices: np.ndarray
    bulges: np.ndarray

    @staticmethod
    def polyline(vertices: np.ndarray) -> BulgePath:
        """A path of straight segments only."""
        v = np.asarray(vertices, dtype=np.float64)
        return BulgePath(v, np.zeros(len(v)))

    def polygon(self, chord_tolerance_mm: float) -> np.ndarray:
        """Vertices of the path with every arc split so its sagitta is at most ``chord_tolerance_mm``.

        Returns
        -------
        (m, 2) float64 array
            Polygon vertices (closed implicitly), on the exact curve. A new array at every call.
        """
        # parts, checks, strength and exports ask a path for its chords again and again (the finger: 179 calls
        # for 48 paths, 0.021 s CPU): made once per tolerance (the path is immutable), handed out as copies (a caller
        # may write into its array). Kept outside the dataclass fields: equality, the stage keys and pickles
        # (__getstate__) never see it
        memo: dict[float, np.ndarray] = self.__dict__.setdefault("_chords", {})
        found = memo.get(float(chord_tolerance_mm))
        if found is None:
            found = memo[float(chord_tolerance_mm)] = self._polygon(chord_tolerance_mm)
        return found.copy()

    def __getstate__(self) -> dict[str, Any]:
        """Pickled without the chords :meth:`polygon` keeps (made again on demand)."""
        return {k: v for k, v in self.__dict__.items() if k != "_chords"}

    def _polygon(self, chord_tolerance_mm: float) -> np.ndarray:
        """:meth:`polygon`, computed: each vertex, then the inner points of the arc that starts there (runs of
        straight segments copied as slices: a fused gear's outline has thousands of vertices and few arcs)."""
        v, n = self.vertices, len(self.vertices)
        out: list[np.ndarray] = []
        start = 0
        for i in np.flatnonzero(np.asarray(self.bulges)[:n] != 0.0).tolist():
            out.append(v[start:i + 1])
            out.append(arc_points(v[i], v[(i + 1) % n], float(self.bulges[i]), chord_tolerance_mm)[1:-1])
            start = i + 1
        if start < n:
            out.append(v[start:])
        return np.concatenate(out, axis=0)

    def distance(self, point: np.ndarray) -> float:
        """Exact distance (mm) from ``point`` (2,) to the path: to its straight segments and true arcs.

        A polygon of the path (chords inside its arcs) would overstate the distance to a concave arc by
        up to the chord sagitta; this is what wall checks measure against.
        """
        p = np.asarray(point, dtype=np.float64)
        n = len(self.vertices)
        best = math.inf
        for i in self._nearest_pieces(p) if n > 16 else range(n):
            p0, p1 = self.vertices[i], self.vertices[(i + 1) % n]
            b = float(self.bulges[i])
            chord_vec = p1 - p0
            chord2 = float(chord_vec @ chord_vec)
            if chord2 == 0.0:
                best = min(best, float(np.hypot(*(p - p0))))
                continue
            if b == 0.0:
                t = min(1.0, max(0.0, float((p - p0) @ chord_vec) / chord2))
                best = min(best, float(np.hypot(*(p - p0 - t * chord_vec))))
                continue
            centre, radius, theta = arc_circle(p0, p1, b)
            rel = p - centre
            a0 = math.atan2(p0[1] - centre[1], p0[0] - centre[0])
            # how far round the arc (in its own sense) the point's direction lies
            turn = (math.copysign(1.0, theta) * (math.atan2(rel[1], rel[0]) - a0)) % (2.0 * math.pi)
            if turn <= abs(theta):
                best = min(best, abs(float(np.hypot(*rel)) - radius))
            else:
                best = min(best, float(np.hypot(*(p - p0))), float(np.hypot(*(p - p1))))
        return best

    def _nearest_pieces(self, p: np.ndarray) -> np.ndarray:
        """Indices of the pieces (in order) that can be the nearest to ``p``: :meth:`distance` measures only these,
        the same way, so it returns the same float as over every piece (a min is exact whatever the order) at a
        fraction of the cost on a path of thousands of pieces (a fused gear's outline).

        Bounds, not the arcs' geometry: a piece is at least its chord's distance less its sagitta away (an arc of
        up to a half circle lies within its sagitta of the chord; a larger one is always measured), and at most
        as far as its nearer end (a straight piece: exactly its chord's distance). A piece whose lower bound
        exceeds the least upper bound by more than 1e-9 mm (+1e-9 relative, for rounding) cannot be the nearest.
        """
        p0 = self.vertices
        chord_vec = np.roll(p0, -1, axis=0) - p0
        chord2 = chord_vec[:, 0] ** 2 + chord_vec[:, 1] ** 2
        to_p0 = np.hypot(*(p - p0).T)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.clip(((p - p0) * chord_vec).sum(axis=1) / chord2, 0.0, 1.0)
        to_chord = np.where(chord2 == 0.0, to_p0, np.hypot(*(p - p0 - t[:, None] * chord_vec).T))
        bulge = np.abs(self.bulges)
        lower = np.where(bulge > 1.0, 0.0, to_chord - 0.5 * bulge * np.sqrt(chord2))  # sagitta = |b| chord / 2
        upper = np.where(bulge == 0.0, to_chord, np.minimum(to_p0, np.roll(to_p0, -1)))
        least = float(np.nanmin(upper)) if np.isfinite(upper).any() else math.inf
        if not math.isfinite(least):  # nothing to prune by: every piece
            return np.arange(len(p0))
        return np.flatnonzero(~(lower > least + 1e-9 + 1e-9 * least))

    def area(self) -> float:
        """Exact signed area (mm^2): polygon area plus the circular segments of the arcs."""
        area = polygon_area(self.vertices)
        n = len(self.vertices)
        for i in range(n):
            b = float(self.bulges[i])
            if b == 0.0:
                continue
            chord = float(np.hypot(*(self.vertices[(i + 1) % n] - self.vertices[i])))
            theta = 4.0 * math.atan(b)
            radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
            area += math.copysign(0.5 * radius * radius * (abs(theta) - math.sin(abs(theta))), theta)
        return area


def arc_circle(p0: np.ndarray, p1: np.ndarray, bulge: float) -> tuple[np.ndarray, float, float]:
    """Centre (2,), radius (mm) and signed included angle (rad) of the arc from ``p0`` to ``p1`` with ``bulge``."""
    theta = 4.0 * math.atan(bulge)
    chord_vec = p1 - p0
    chord = float(np.hypot(*chord_vec))
    radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
    # centre lies left of the chord for a positive (counter-clockwise) bulge
    normal = np.array([-chord_vec[1], chord_vec[0]]) / chord
    centre = 0.5 * (p0 + p1) + math.copysign(1.0, theta) * normal * (radius * math.cos(theta / 2.0))
    return centre, radius, theta


def arc_points(p0: np.ndarray, p1: np.ndarray, bulge: float, chord_tolerance_mm: float) -> np.ndarray:
    """Points on the arc from ``p0`` to ``p1`` with ``bulge`` (ends included), sagitta ≤ tolerance; (k, 2)."""
    centre, radius, theta = arc_circle(p0, p1, bulge)
    segments = circle_segments(radius, chord_tolerance_mm, abs(theta))
    a0 = math.atan2(p0[1] - centre[1], p0[0] - centre[0])
    angles = a0 + np.linspace(0.0, theta, segments + 1)
    pts = centre + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    pts[0], pts[-1] = p0, p1
    return pts


def circle_segments(radius: float, chord_tolerance_mm: float, sweep: float = 2.0 * math.pi) -> int:
    """Number of chords so that an arc of ``radius`` and ``sweep`` (rad) has sagitta ≤ tolerance."""
    if radius <= chord_tolerance_mm:
        return max(3, int(math.ceil(sweep / (2.0 * math.pi / 3.0))))
    step = 2.0 * math.acos(1.0 - chord_tolerance_mm / radius)
    return max(1 if sweep < 2.0 * math.pi else 3, int(math.ceil(sweep / step - 1e-9)))


def circle_polygon(centre: np.ndarray, diameter: float, chord_tolerance_mm: float,
                   clockwise: bool = False) -> np.ndarray:
    """Polygon inscribed in a circle with sagitta ≤ tolerance; (k, 2), counter-clockwise unless asked."""
    n = max(8, circle_segments(diameter / 2.0, chord_tolerance_mm))
    angles = np.arange(n) * (2.0 * math.pi / n)
    if clockwise:
        angles = -angles
    return np.asarray(centre, dtype=np.float64) + 0.5 * diameter * np.column_stack(
        [np.cos(angles), np.sin(angles)])


#: How a hole fits what goes through it: a pin that turns in it (``running``), a pin pressed into it
#: (``press``), a screw that passes it (``clearance``).
HOLE_FITS = ("running", "press", "clearance")


@dataclass(frozen=True)
class Hole:
    """A round hole through a part.

    Two sizes are kept apart: the NOMINAL diameter is the fit's (pin + 2 × running clearance, pin − press
    interference, screw + 2 × clearance): what the finished part should measure. The MODELLED diameter
    (``diameter_mm``, the CAD, STL and DXF size) is the nominal plus the process's hole compensation (SLA
    prints holes undersize, so the model's hole is larger).

    Attributes
    ----------
    joint : str
        Joint (or mounting point) it serves.
    centre : (2,) array
        Centre in part (body) coordinates, mm.
    diameter_mm : float
        Diameter as modelled (nominal plus the process compensation).
    pin_diameter_mm : float
        Nominal diameter of the pin it takes (0 for mounting holes with no pin).
    fit : str
        One of :data:`HOLE_FITS`.
    nominal_diameter_mm : float
        The fit's diameter, to measure on the finished part; 0 means "as modelled" (no compensation known).
    """

    joint: str
    centre: np.ndarray
    diameter_mm: float
    pin_diameter_mm: float = 0.0
    fit: str = "running"
    nominal_diameter_mm: float = 0.0

    @property
    def nominal_mm(self) -> float:
        """The nominal (finished) diameter: what to measure on the made part."""
        return self.nominal_diameter_mm if self.nominal_diameter_mm > 0.0 else self.diameter_mm

    @property
    def compensation_mm(self) -> float:
        """What the process adds to the nominal diameter in the model (modelled − nominal)."""
        return self.diameter_mm - self.nominal_mm


@dataclass(frozen=True)
class Part:
    """One manufacturable part: a plate of ``thickness_mm`` from ``z_mm`` up, outline with holes,
    fixed to ``body`` of the mechanism (coordinates are the body's).

    Attributes
    ----------
    name : str
        Unique part name (file stem).
    body : str
        Mechanism body it moves with.
    outline : BulgePath
        Outer contour, counter-clockwise, mm, body coordinates.
    holes : tuple of Hole
    thickness_mm, z_mm : float
        Plate thickness and height of its bottom face in the assembly.
    layer : int
        Layer index in the stack (0 at the bottom).
    process : str
        ``"sla"`` or ``"laser"``.
    role : str
        ``"link"``, ``"gear"``, ``"ground"``, ``"rod"``, ``"spacer"``.
    gear : str
        Name of the gear pair whose gear is fused into this part ('' if none).
    """

    name: str
    body: str
    outline: BulgePath
    holes: tuple[Hole, ...]
    thickness_mm: float
    z_mm: float
    layer: int
    process: str
    role: str = "link"
    gear: str = ""
    extra: dict[str, Any] = field(default_factory=dict, compare=False)

    def polygons(self, chord_tolerance_mm: float) -> list[np.ndarray]:
        """Outer contour (CCW) then every hole (CW) as polygons, for meshing and booleans."""
        outer = self.outline.polygon(chord_tolerance_mm)
        if polygon_area(outer) < 0:
            outer = outer[::-1]
        rings = [outer]
        for hole in self.holes:
            rings.append(circle_polygon(hole.centre, hole.diameter_mm, chord_tolerance_mm, clockwise=True))
        return rings

    def area_mm2(self) -> float:
        """Exact plate area: outline minus holes (mm^2)."""
        return abs(self.outline.area()) - sum(math.pi * h.diameter_mm ** 2 / 4.0 for h in self.holes)

    def volume_mm3(self) -> float:
        """Exact volume of the plate (mm^3)."""
        return self.area_mm2() * self.thickness_mm
