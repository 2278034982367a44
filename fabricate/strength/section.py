"""Cross-sections cut from a part's real outline: the material a straight cut line crosses.

A link, gear web or boss is a plate of uniform thickness. A cut across it along a straight line meets
material in one or more intervals (several where the line crosses holes or re-entrant notches); the
section those intervals form carries the axial force and the in-plane bending moment of everything on
one side of the cut. :func:`cut_section` measures that section from the polygons the parts layer
produces (:meth:`fabricate.parts.model.Part.polygons`), so holes, bosses and fillets count exactly as
cut.

Units: mm; area mm^2; second moment mm^4.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from fabricate.errors import GeometryError

#: Intervals closer than this (mm) along the cut are one interval: GEOS may split a crossing at a ring
#: vertex that lies on the line, and a pair of touching pieces is one piece of material.
_MERGE_GAP_MM = 1e-9


@dataclass(frozen=True)
class Section:
    """The material of a plate on one straight cut line.

    Attributes
    ----------
    area_mm2 : float
        Full cross-section area, net width times thickness (mm^2).
    width_mm : float
        Net material length along the cut line: sum of the interval lengths (mm).
    inertia_mm4 : float
        Second moment of area for in-plane bending (the moment vector normal to the plate), about the
        section's centroid on the cut line: ``sum t * ((s1 - s)^3 - (s0 - s)^3) / 3`` over the intervals
        ``[s0, s1]`` with ``s`` the centroid (mm^4).
    extreme_fibre_mm : float
        Largest distance from the centroid to the end of an interval, ``c`` in ``M c / I`` (mm).
    thickness_mm : float
        Plate thickness (mm).
    segments : (k, 2) float64 array
        Material intervals ``[s0, s1]`` along the cut, ascending, as signed distances (mm) from the cut's
        reference point along the unit cut direction.
    centroid_mm : (2,) float64 array
        The section centroid: the point on the cut line at the area-weighted mean of the intervals (mm).
    """

    area_mm2: float
    width_mm: float
    inertia_mm4: float
    extreme_fibre_mm: float
    thickness_mm: float
    segments: np.ndarray
    centroid_mm: np.ndarray


def _unit_direction(direction: np.ndarray) -> np.ndarray:
    d = np.asarray(direction, dtype=np.float64).reshape(2)
    norm = float(np.hypot(d[0], d[1]))
    if not math.isfinite(norm) or norm == 0.0:
        raise ValueError(f"cut direction must be a finite non-zero vector, got {d.tolist()}")
    return d / norm


def _line_pieces(geometry: shapely.Geometry) -> list[np.ndarray]:
    """The (2, 2) end points of every line piece in an intersection result (points and empties dropped)."""
    if geometry.is_empty:
        return []
    if isinstance(geometry, shapely.LineString):
        coords = np.asarray(geometry.coords, dtype=np.float64)
        return [coords[[0, -1]]] if len(coords) >= 2 else []
    if isinstance(geometry, (shapely.MultiLineString, shapely.GeometryCollection)):
        return [p for g in geometry.geoms for p in _line_pieces(g)]
    return []  # a Point: the line only touches a vertex, no material width


def _flush_subnormal(xy: np.ndarray) -> np.ndarray:
    # GEOS mis-intersects when a coordinate is subnormal (|x| < 2.2e-308: a cut across a 0.5 x 1 plate
    # offset by 1e-310 mm came back 6 % wide); such a coordinate is 0 for any plate
    xy = np.asarray(xy, dtype=np.float64)
    return np.where(np.abs(xy) < np.finfo(np.float64).tiny, 0.0, xy)


def plate_polygon(rings: list[np.ndarray]) -> shapely.Polygon:
    """The valid shapely polygon of a plate's rings (outline, then holes): made once per part and handed to
    :func:`cut_section` for its many cuts.

    Raises
    ------
    GeometryError
        The rings do not form a valid polygon.
    ValueError
        No outline ring.
    """
    if not len(rings):
        raise ValueError("cut_section needs at least the outline ring")
    try:
        polygon = shapely.Polygon(_flush_subnormal(rings[0]), [_flush_subnormal(r) for r in rings[1:]])
    except (ValueError, shapely.errors.ShapelyError) as exc:
        raise GeometryError(f"cut_section: rings do not form a polygon: {exc}") from exc
    if polygon.is_empty or not polygon.is_valid:
        raise GeometryError(f"cut_section: invalid plate polygon ({shapely.is_valid_reason(polygon)})")
    shapely.prepare(polygon)
    return polygon


def cut_section(rings: list[np.ndarray] | shapely.Polygon, point: np.ndarray, direction: np.ndarray,
                thickness_mm: float) -> Section:
    """The section of a plate on the infinite line through ``point`` along ``direction``.

    Parameters
    ----------
    rings : list of (n, 2) float64 arrays, or a polygon from :func:`plate_polygon`
        The plate outline (counter-clockwise) then its holes (clockwise), mm: what
        :meth:`fabricate.parts.model.Part.polygons` returns. Orientation is not relied on.
    point : (2,) array
        A point on the cut line (mm). Interval positions are measured from it.
    direction : (2,) array
        Direction of the cut line; need not be unit length.
    thickness_mm : float
        Plate thickness (mm), > 0.

    Returns
    -------
    Section
        Every material interval on the line, with area, net width, in-plane second moment about the
        centroid and extreme fibre distance.

    Raises
    ------
    GeometryError
        The line misses the material (or only touches it at a point), or the rings do not form a valid
        polygon.
    ValueError
        Non-positive thickness, zero direction or no outline ring.
    """
    if not (math.isfinite(thickness_mm) and thickness_mm > 0.0):
        raise ValueError(f"plate thickness must be positive, got {thickness_mm}")
    u = _unit_direction(direction)
    p0 = np.asarray(point, dtype=np.float64).reshape(2)
    if not np.all(np.isfinite(p0)):
        raise ValueError(f"cut point must be finite, got {p0.tolist()}")
    p0 = _flush_subnormal(p0)
    polygon = rings if isinstance(rings, shapely.Polygon) else plate_polygon(rings)

    # A segment long enough to cross the whole part from wherever the reference point lies.
    xmin, ymin, xmax, ymax = polygon.bounds
    centre = np.array([(xmin + xmax) / 2.0, (ymin + ymax) / 2.0])
    reach = float(np.hypot(xmax - xmin, ymax - ymin)) + float(np.hypot(*(centre - p0))) + 1.0
    line = shapely.LineString([p0 - reach * u, p0 + reach * u])
    try:
        pieces = _line_pieces(polygon.intersection(line))
    except shapely.errors.ShapelyError as exc:
        raise GeometryError(f"cut_section: intersection failed: {exc}") from exc

    intervals = sorted(tuple(sorted(((a - p0) @ u, (b - p0) @ u))) for a, b in pieces)
    merged: list[list[float]] = []
    for s0, s1 in intervals:
        if merged and s0 - merged[-1][1] <= _MERGE_GAP_MM:
            merged[-1][1] = max(merged[-1][1], s1)
        else:
            merged.append([s0, s1])
    segments = np.array([m for m in merged if m[1] - m[0] > 0.0], dtype=np.float64).reshape(-1, 2)
    if len(segments) == 0:
        raise GeometryError(f"cut line through {p0.tolist()} along {u.tolist()} misses the part")

    s0, s1 = segments[:, 0], segments[:, 1]
    lengths = s1 - s0
    width = float(lengths.sum())
    centroid_s = float(((s1 ** 2 - s0 ** 2) / 2.0).sum() / width)
    inertia = float(thickness_mm * (((s1 - centroid_s) ** 3 - (s0 - centroid_s) ** 3) / 3.0).sum())
    fibre = float(max(abs(s0[0] - centroid_s), abs(s1[-1] - centroid_s)))
    return Section(area_mm2=width * thickness_mm, width_mm=width, inertia_mm4=inertia,
                   extreme_fibre_mm=fibre, thickness_mm=float(thickness_mm), segments=segments,
                   centroid_mm=p0 + centroid_s * u)


def side_of_cut(points: np.ndarray, point: np.ndarray, direction: np.ndarray) -> np.ndarray | float:
    """Signed distances of points from the cut line, positive on the left of ``direction``.

    Parameters
    ----------
    points : (m, 2) or (2,) array
        Points (mm), e.g. the joints where forces act on the part.
    point : (2,) array
        A point on the cut line (mm).
    direction : (2,) array
        Direction of the cut line; need not be unit length.

    Returns
    -------
    (m,) float64 array (or a float for one point)
        Distance (mm) from the line; > 0 left of the direction, < 0 right, 0 on the line.
    """
    u = _unit_direction(direction)
    rel = np.asarray(points, dtype=np.float64) - np.asarray(point, dtype=np.float64).reshape(2)
    d = u[0] * rel[..., 1] - u[1] * rel[..., 0]
    return float(d) if np.ndim(d) == 0 else d
