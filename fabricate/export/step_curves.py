"""Which curve each stretch of a part's profile is, for the STEP solid: lines, true arcs and smooth runs.

A part's outline reaches the exporters as a bulge path, but a profile fused with polygons (gear teeth, hubs,
pad arcs, the bosses of a body carrying them) is a union of polygons: every arc and every tooth flank
there is a chain of short lines, each vertex on the exact curve. A CAD user wants the curves back (to
measure a tooth, to fillet an edge), so the profile is split into pieces:

- an arc of the path (non-zero bulge) stays that arc;
- three or more consecutive lines whose vertices lie on one circle (within :data:`ON_CIRCLE_MM`), turning
  one way in equal steps of at most :data:`MAX_ARC_STEP`, are one true arc from the first vertex to the
  last: polygonised circles and arcs (bosses, hubs, circle hulls, pad arcs) put every vertex on the circle
  to rounding, at equal angles;
- what is left splits at corners (a turn much sharper than its neighbours' or above :data:`CORNER_DEG`)
  into runs; a run of three or more lines is a smooth curve (tooth flank with its root fillet) that the
  writer interpolates with a B-spline through its vertices, a shorter one stays lines.

:func:`spline_edges` makes a smooth run's B-spline edges (OCP, imported inside it like in
:mod:`fabricate.export.step`, which makes the other edges and the solid).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely

#: A vertex lies on a circle when its distance from the centre is the radius within this (mm) plus 1e-9 of
#: the radius. A polygonised circle's vertices are on it to rounding (~1e-14 mm); a vertex where a union
#: crossed two polygons, or a flank sample, is off it by far more (a sagitta, >= 1e-4 mm in practice).
ON_CIRCLE_MM = 1e-7

#: A turn above this (degrees) is a corner whatever its neighbours do.
CORNER_DEG = 45.0

#: A turn is also a corner when above 10 degrees and this many times its gentler neighbour's: on a smooth
#: curve the polygon's turns change slowly from vertex to vertex (the decimation spaces vertices by the
#: curvature), at a tooth tip or a union's seam they jump.
CORNER_RATIO = 2.5

#: Longest step (rad) between the vertices of a polygonised circle taken for an arc: under a quarter turn,
#: so a rectangle (whose corners lie on a circle, a quarter turn apart for a square) stays four lines. A
#: circle polygonised that coarsely (chord tolerance near its radius, fabricate.parts.model.circle_segments)
#: stays lines too.
MAX_ARC_STEP = 0.5 * math.pi - 1e-6

#: A flank's B-spline passes this many chord tolerances from each polygon vertex it replaces at most (the
#: vertices are points of the exact curve, so the curve stays that close to it there).
SPLINE_FIT_FACTOR = 0.1

#: Highest degree of a flank's single-span B-spline (a Bezier curve): degree 8 follows an involute flank
#: with its root fillet within the fit over a tooth of the shipped gears.
SPLINE_MAX_DEGREE = 8

#: How far (in chord tolerances) the interpolating spline may stand off the polygon before its run splits.
SPLINE_BAND_FACTOR = 1.2

#: Samples per polygon chord of the interpolating spline a flank's B-spline is fitted to.
SPLINE_SAMPLES = 4

#: Fewest lines in a run made one smooth curve (fewer stay lines).
MIN_SPLINE_LINES = 3


@dataclass(frozen=True)
class Piece:
    """One edge of a profile, from vertex ``start`` to vertex ``end`` of the cleaned path (``end`` may wrap
    to 0).

    Attributes
    ----------
    kind : {"line", "arc", "spline"}
    start, end : int
        Indices into the cleaned vertices.
    bulge : float
        The arc's bulge (``tan(included angle / 4)``, positive counter-clockwise); 0 otherwise.
    points : (k, 2) array
        Every vertex from ``start`` to ``end`` inclusive (the spline's interpolation points).
    """

    kind: str
    start: int
    end: int
    bulge: float
    points: np.ndarray


def clean_path(vertices: np.ndarray, bulges: np.ndarray, min_edge_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """The path without zero-length segments: a segment shorter than ``min_edge_mm`` merges its two vertices
    (the first is kept, with the bulge of the segment that leaves it)."""
    n = len(vertices)
    keep = [i for i in range(n) if float(np.hypot(*(vertices[(i + 1) % n] - vertices[i]))) > min_edge_mm]
    return vertices[keep], bulges[keep]


def _turns(vertices: np.ndarray) -> np.ndarray:
    """Signed turn (rad, positive left) at every vertex of a closed polygon."""
    d = np.roll(vertices, -1, axis=0) - vertices
    heading = np.arctan2(d[:, 1], d[:, 0])
    return np.asarray((heading - np.roll(heading, 1) + math.pi) % (2.0 * math.pi) - math.pi)


def _circle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Centre and radius of the circle through three points (None when they are collinear)."""
    ab, ac = b - a, c - a
    det = 2.0 * (ab[0] * ac[1] - ab[1] * ac[0])
    if abs(det) < 1e-12 * max(1.0, float(ab @ ab) * float(ac @ ac)):
        return None
    ux = (ac[1] * (ab @ ab) - ab[1] * (ac @ ac)) / det
    uy = (ab[0] * (ac @ ac) - ac[0] * (ab @ ab)) / det
    centre = a + np.array([ux, uy])
    return centre, float(np.hypot(ux, uy))


def _circle_run(vertices: np.ndarray, straight: np.ndarray, turns: np.ndarray, i: int, limit: int) -> int:
    """How many lines from vertex ``i`` on (at most ``limit``) have all their vertices on one circle,
    turning one way; 0 when fewer than three do."""
    n = len(vertices)
    if limit < 3 or not (straight[i] and straight[(i + 1) % n] and straight[(i + 2) % n]):
        return 0
    fit = _circle(vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n])
    if fit is None:
        return 0
    centre, radius = fit
    eps = ON_CIRCLE_MM + 1e-9 * radius
    sense = math.copysign(1.0, turns[(i + 1) % n])
    count, sweep, first = 0, 0.0, 0.0
    while count < limit and straight[(i + count) % n]:
        j = (i + count + 1) % n
        if abs(float(np.hypot(*(vertices[j] - centre))) - radius) > eps:
            break
        if count and math.copysign(1.0, turns[(i + count) % n]) != sense:
            break
        step = 2.0 * math.asin(min(1.0, float(np.hypot(*(vertices[j] - vertices[(i + count) % n]))) / (2 * radius)))
        if step > MAX_ARC_STEP or (count and abs(step - first) > 1e-6 * first):
            break  # not a polygonised circle: its steps are equal and short (a rectangle's corners are on one)
        if sweep + step >= 2.0 * math.pi - 1e-6:  # a full turn: leave the rest to the next arc
            break
        first = step if not count else first
        sweep += step
        count += 1
    return count if count >= 3 else 0


def _bulge_of(points: np.ndarray, sense: float) -> float:
    """Bulge of the arc through ``points`` (on one circle, turning ``sense``) from the first to the last."""
    fit = _circle(points[0], points[len(points) // 2], points[-1])
    assert fit is not None  # three distinct points of a circle
    centre, _ = fit
    angles = np.unwrap(np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0]))
    theta = float(angles[-1] - angles[0])
    if math.copysign(1.0, theta) != sense:
        theta += sense * 2.0 * math.pi
    return math.tan(theta / 4.0)


def profile_pieces(vertices: np.ndarray, bulges: np.ndarray) -> list[Piece]:
    """Split a closed path (cleaned, see :func:`clean_path`) into lines, arcs and smooth runs (module docstring).

    Returns
    -------
    list of Piece
        In path order, each starting where the previous ended; together they go once round.
    """
    v = np.asarray(vertices, dtype=np.float64)
    b = np.asarray(bulges, dtype=np.float64)
    n = len(v)
    straight = b == 0.0
    turns = _turns(v)
    # 1. segments on one circle: arcs
    kind = np.where(straight, "", "arc").astype(object)
    arc_ends: dict[int, int] = {}  # start vertex of a recognised arc -> its number of lines
    i = 0
    start = int(np.argmin(straight)) if not straight.all() else 0  # begin at a path arc when there is one
    visited = 0
    while visited < n:
        k = (start + i) % n
        count = _circle_run(v, straight, turns, k, n - visited) if kind[k] == "" else 0
        if count:
            arc_ends[k] = count
            for m in range(count):
                kind[(k + m) % n] = "circle"
            i += count
            visited += count
        else:
            i += 1
            visited += 1
    # 2. corners: a vertex where a piece must end
    degrees = np.degrees(np.abs(turns))
    gentle = np.minimum(np.roll(degrees, 1), np.roll(degrees, -1))
    corner = (degrees > CORNER_DEG) | ((degrees > 10.0) & (degrees > CORNER_RATIO * gentle))
    breaks = corner | ~straight | ~np.roll(straight, 1)  # ends of path arcs too
    for k, count in arc_ends.items():
        breaks[k] = breaks[(k + count) % n] = True
    if not breaks.any():  # a smooth closed loop: cut it at its sharpest turn and opposite it
        first = int(np.argmax(degrees))
        breaks[first] = breaks[(first + n // 2) % n] = True
    # a vertex inside a recognised arc is no break, however sharply a coarse polygon turns there
    for k, count in arc_ends.items():
        for m in range(1, count):
            breaks[(k + m) % n] = False
    # 3. walk once round from a break, emitting pieces
    origin = int(np.argmax(breaks))
    pieces: list[Piece] = []
    k = origin
    while True:
        if kind[k] == "arc":
            end = (k + 1) % n
            pieces.append(Piece("arc", k, end, float(b[k]), v[[k, end]]))
        elif kind[k] == "circle" and k in arc_ends:
            end = (k + arc_ends[k]) % n
            points = v[[(k + m) % n for m in range(arc_ends[k] + 1)]]
            pieces.append(Piece("arc", k, end, _bulge_of(points, math.copysign(1.0, turns[(k + 1) % n])),
                                points))
        else:  # a line, or a run of lines up to the next break
            m = 1
            while kind[(k + m) % n] == "" and not breaks[(k + m) % n] and m < n:
                m += 1
            end = (k + m) % n
            points = v[[(k + j) % n for j in range(m + 1)]]
            if m >= MIN_SPLINE_LINES:
                pieces.append(Piece("spline", k, end, 0.0, points))
            else:
                pieces += [Piece("line", (k + j) % n, (k + j + 1) % n, 0.0, points[j:j + 2]) for j in range(m)]
        k = end
        if k == origin:
            return pieces


def spline_edges(points: np.ndarray, start: int, n: int, vertex: Callable[[int], Any],
                 chord_tolerance_mm: float) -> list[Any]:
    """OCP edges along a smooth run of polygon vertices (each a point of the exact curve), from vertex
    ``start`` of a closed path of ``n``; ``vertex(i)`` gives the path's shared vertex ``i``.

    The curve between the vertices is estimated by the cubic spline interpolating them (chord-length
    parameters; on a smooth run it lies far closer to the exact curve than the chords), sampled
    :data:`SPLINE_SAMPLES` times per chord. The edges are single-span B-splines (Bezier curves of degree 3
    to :data:`SPLINE_MAX_DEGREE`) fitted to those samples, as few as keep every sample within
    :data:`SPLINE_FIT_FACTOR` chord tolerances: a run one span cannot follow splits at its middle vertex,
    down to lines for three points or fewer.

    Single spans, because OCCT integrates a face's properties with one Gauss rule over its whole parameter
    range: over a many-span B-spline it misses the volume by ~0.2 % (FreeCAD reports that), over one span it
    is exact to rounding.
    """
    from OCP.GeomAPI import GeomAPI_Interpolate
    from OCP.gp import gp_Pnt

    try:  # OCP 8 names the handle arrays by their element type, OCP 7 by OCCT's classes
        from OCP.collections import HArray1_double, HArray1_gp_Pnt
    except ImportError:
        from OCP.TColgp import TColgp_HArray1OfPnt as HArray1_gp_Pnt
        from OCP.TColStd import TColStd_HArray1OfReal as HArray1_double

    k = len(points)
    if k < 4:
        return _fitted_edges(points, points, 1, start, n, vertex, chord_tolerance_mm)
    params = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    poles, knots = HArray1_gp_Pnt(1, k), HArray1_double(1, k)
    for j in range(k):
        poles.SetValue(j + 1, gp_Pnt(float(points[j, 0]), float(points[j, 1]), 0.0))
        knots.SetValue(j + 1, float(params[j]))
    interpolate = GeomAPI_Interpolate(poles, knots, False, 1e-10)
    # end tangents of the circles through the three points at each end: a natural spline's free ends swing
    # off the curve by several um where a run ends in high curvature (a flank at its tip corner)
    interpolate.Load(_end_tangent(points[:3]), -_end_tangent(points[::-1][:3]), True)
    interpolate.Perform()
    if not interpolate.IsDone():
        return _fitted_edges(points, points, 1, start, n, vertex, 0.0)  # lines
    curve = interpolate.Curve()
    fine = np.concatenate([np.linspace(params[j], params[j + 1], SPLINE_SAMPLES, endpoint=False)
                           for j in range(k - 1)] + [params[-1:]])
    samples = np.array([[curve.Value(float(t)).X(), curve.Value(float(t)).Y()] for t in fine])
    samples[::SPLINE_SAMPLES] = points  # the vertices themselves, not their rounded images
    # the exact curve is within the chord tolerance of the polygon: an interpolant that swings further
    # (SPLINE_BAND_FACTOR of it: a hidden corner, uneven spacing) is not the curve there; the run splits at
    # its middle vertex and each half is interpolated again, down to lines
    if shapely.distance(shapely.points(samples), shapely.LineString(points)).max() > \
            SPLINE_BAND_FACTOR * chord_tolerance_mm:
        half = k // 2
        return (spline_edges(points[:half + 1], start, n, vertex, chord_tolerance_mm)
                + spline_edges(points[half:], (start + half) % n, n, vertex, chord_tolerance_mm))
    return _fitted_edges(points, samples, SPLINE_SAMPLES, start, n, vertex, chord_tolerance_mm)


def _end_tangent(three: np.ndarray) -> Any:
    """Unit tangent (gp_Vec) at ``three[0]`` of the circle through three points, heading towards the others
    (their chord direction when they are collinear)."""
    from OCP.gp import gp_Vec

    a, b, c = three
    chord = c - a
    ab, ac = b - a, c - a
    det = 2.0 * (ab[0] * ac[1] - ab[1] * ac[0])
    if abs(det) < 1e-15:
        t = chord
    else:
        centre = a + np.array([ac[1] * (ab @ ab) - ab[1] * (ac @ ac), ab[0] * (ac @ ac) - ac[0] * (ab @ ab)]) / det
        radius = a - centre
        t = np.array([-radius[1], radius[0]])
        if t @ chord < 0:
            t = -t
    t = t / np.hypot(*t)
    return gp_Vec(float(t[0]), float(t[1]), 0.0)


def _fitted_edges(points: np.ndarray, samples: np.ndarray, per: int, start: int, n: int, vertex: Callable[[int], Any],
                  chord_tolerance_mm: float) -> list[Any]:
    """Single-span B-splines through ``samples`` (``per`` of them per chord of ``points``), split at middle
    vertices until each fits (see :func:`_spline_edges`); lines for three points or fewer."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.GeomAPI import GeomAPI_PointsToBSpline
    from OCP.gp import gp_Pnt

    try:
        from OCP.collections import Array1_gp_Pnt
    except ImportError:
        from OCP.TColgp import TColgp_Array1OfPnt as Array1_gp_Pnt

    k = len(points)
    if k < 4 or chord_tolerance_mm <= 0.0:
        return [BRepBuilderAPI_MakeEdge(vertex((start + j) % n), vertex((start + j + 1) % n)) for j in range(k - 1)]
    array = Array1_gp_Pnt(1, len(samples))
    for j, q in enumerate(samples):
        array.SetValue(j + 1, gp_Pnt(float(q[0]), float(q[1]), 0.0))
    limit = SPLINE_FIT_FACTOR * chord_tolerance_mm
    fit = GeomAPI_PointsToBSpline(array, 3, SPLINE_MAX_DEGREE, GeomAbs_C2, limit)
    if fit.IsDone() and fit.Curve().NbKnots() == 2:
        curve = fit.Curve()
        # the fit's parameters are the samples' chord lengths scaled to its range: the distance to the curve
        # at a sample's parameter bounds its distance to the curve from above
        chords = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(samples, axis=0).T))])
        first, last = curve.FirstParameter(), curve.LastParameter()
        ts = first + (last - first) * chords / chords[-1]
        if all(math.dist((curve.Value(float(t)).X(), curve.Value(float(t)).Y()), q) <= limit
               for t, q in zip(ts, samples, strict=True)):
            return [BRepBuilderAPI_MakeEdge(curve, vertex(start), vertex((start + k - 1) % n))]
    half = k // 2
    return (_fitted_edges(points[:half + 1], samples[:half * per + 1], per, start, n, vertex, chord_tolerance_mm)
            + _fitted_edges(points[half:], samples[half * per:], per, (start + half) % n, n, vertex,
                            chord_tolerance_mm))
