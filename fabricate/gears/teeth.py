"""Tooth outlines of one gear: rack envelope (exact) or osculating-circle involute teeth (approx),
clipped by the tip curve, closed as a full gear or as a sector with a hub, cleaned and decimated.

Outlines are (n, 2) float64 in the gear frame (mm), counter-clockwise, no repeated closing vertex,
valid simple polygons (shapely) with a chord error below the requested tolerance: the dense outline's
vertices are exact envelope points spaced so that its own chord error is below 1 um (measured about
0.5 um for module 0.5 against a five times denser sampling), and the Douglas-Peucker decimation keeps
a subset of those vertices within ``tolerance - 1 um`` of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LinearRing, LineString, Polygon
from shapely.geometry.polygon import orient

from fabricate.gears.pitch import PitchCurves, PitchFrames
from fabricate.gears.rack import FLANK, RackProfile, contact_abscissa, envelope, offset_profile, osculating_frames


@dataclass(frozen=True)
class GearTeeth:
    """One cut gear.

    Attributes
    ----------
    outline : (n, 2) array
        Decimated outline, CCW, mm (gear frame).
    dense : (m, 2) array
        The outline before decimation, CCW.
    flanks : dict[int, (k, 2) array]
        Involute-flank points (inside the tip curve) by rack flank index ``j`` (even: left flank of a
        gear-a tooth, odd: right), for the mesh check.
    tooth_centres : (z,) array
        Rack abscissae (mm) of this gear's tooth centres.
    tip_land_min_mm : float
        Shortest tip land (length of outline on the tip curve per tooth), mm.
    self_intersecting : bool
        The raw envelope crossed itself (undercut: the fillet trochoid cut into the flank).
    root_radius_min_mm : float
        Smallest distance of the outline from the axis over the teeth, mm.
    """

    outline: np.ndarray
    dense: np.ndarray
    flanks: dict[int, np.ndarray]
    tooth_centres: np.ndarray
    tip_land_min_mm: float
    self_intersecting: bool
    root_radius_min_mm: float


def flank_index(flank_u: np.ndarray, pitch: float, origin: float) -> np.ndarray:
    """Rack flank index of pitch-line abscissae ``flank_u`` (left flank of the a-tooth at ``origin``
    is 0, its right flank 1, the next tooth's left flank 2, ...)."""
    index = np.rint((flank_u - origin + pitch / 4) / (pitch / 2))
    return np.where(np.isfinite(index), index, -(2**62)).astype(np.int64)


def _largest_polygon(geom: shapely.Geometry) -> Polygon:
    if geom.geom_type == "Polygon":
        return geom
    parts = [g for g in getattr(geom, "geoms", []) if g.geom_type == "Polygon"]
    parts += [p for g in getattr(geom, "geoms", []) if g.geom_type == "MultiPolygon" for p in g.geoms]
    if not parts:
        raise ValueError("no polygon")
    return max(parts, key=lambda g: g.area)


def _clean_ring(coords: np.ndarray) -> np.ndarray:
    """Drop the closing vertex and consecutive duplicates."""
    ring = np.asarray(coords, dtype=np.float64)
    if len(ring) > 1 and np.allclose(ring[0], ring[-1]):
        ring = ring[:-1]
    keep = np.ones(len(ring), dtype=bool)
    keep[1:] = np.hypot(*(np.diff(ring, axis=0).T)) > 1e-9
    ring = ring[keep]
    if np.hypot(*(ring[0] - ring[-1])) <= 1e-9:
        ring = ring[:-1]
    return ring


def _douglas_peucker(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Indices kept by Douglas-Peucker on an open polyline (both ends kept)."""
    keep = np.zeros(len(points), dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, len(points) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, b = points[i], points[j]
        d = b - a
        length = np.hypot(*d)
        rel = points[i + 1:j] - a
        if length < 1e-15:
            dist = np.hypot(rel[:, 0], rel[:, 1])
        else:
            # distance to the segment (not the infinite line), so the bound holds everywhere
            t = np.clip((rel @ d) / length**2, 0.0, 1.0)
            dist = np.hypot(*(rel - t[:, None] * d).T)
        k = int(np.argmax(dist))
        if dist[k] > tolerance:
            keep[i + 1 + k] = True
            stack.extend([(i, i + 1 + k), (i + 1 + k, j)])
    return np.flatnonzero(keep)


def simplify_ring(ring: np.ndarray, tolerance: float) -> np.ndarray:
    """Douglas-Peucker on a closed ring: every dropped vertex lies within ``tolerance`` of the result
    (split at vertex 0 and the vertex farthest from it)."""
    far = int(np.argmax(np.hypot(*(ring - ring[0]).T)))
    first = _douglas_peucker(ring[:far + 1], tolerance)
    second = _douglas_peucker(np.vstack([ring[far:], ring[:1]]), tolerance) + far
    idx = np.concatenate([first, second[1:-1]])
    kept: np.ndarray = ring[idx]
    return kept


def circle_points(radius: float, chord_tolerance: float, start: float = 0.0) -> np.ndarray:
    """A CCW circle polygon whose chord error is at most ``chord_tolerance``."""
    n = max(16, int(np.ceil(np.pi / np.arccos(max(-1.0, 1.0 - chord_tolerance / radius)))))
    ang = start + np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return radius * np.stack([np.cos(ang), np.sin(ang)], -1)


def cut_gear(pitch: PitchCurves, gear: str, rack: RackProfile, tooth_centres: np.ndarray, *,
             method: str, delta: float, addendum_mm: float, closed: bool, rack_origin: float,
             hub_radius_mm: float, chord_tolerance_mm: float, decimate: bool = True) -> GearTeeth:
    """Cut one gear by the rack.

    Parameters
    ----------
    pitch : PitchCurves
    gear : {"a", "b"}
    rack : RackProfile
        Gear a's cutter (gear b's is its reflection).
    tooth_centres : (z,) array
        Rack abscissae of this gear's tooth centres, mm, increasing.
    method : {"exact", "approx"}
    delta : float
        Normal offset of the flanks into the gear (half the backlash share), mm.
    addendum_mm : float
        Tip height over the pitch curve, mm.
    closed : bool
        Full gear (``tooth_centres`` cover one perimeter) or sector.
    rack_origin : float
        Abscissa of gear-a tooth 0 (flank numbering).
    hub_radius_mm : float
        Radius of the hub disk that closes a sector.
    chord_tolerance_mm : float
        Allowed chord error of the decimated outline.
    decimate : bool
        False skips the decimation (``outline`` is then the dense outline), for comparisons.
    """
    profile = rack if gear == "a" else rack.for_gear_b()
    z = len(tooth_centres)
    points = _rack_points(profile, rack.pitch, tooth_centres, delta, gear, closed)
    chain = _envelope_chain(pitch, gear, points, tooth_centres, method)
    tip = _tip_curve(pitch, gear, tooth_centres, rack.pitch, addendum_mm, closed)
    chain_poly, tip_poly, self_intersecting = _valid_polygons(chain, tip, closed)
    teeth = chain_poly.intersection(tip_poly)
    root_min = float(np.min(np.hypot(chain[:, 0], chain[:, 1])))
    if not closed:
        hub = Polygon(circle_points(min(hub_radius_mm, 0.95 * root_min), 0.2 * chord_tolerance_mm))
        teeth = teeth.union(hub)
    poly = orient(_largest_polygon(teeth), 1.0)
    dense = _clean_ring(np.asarray(poly.exterior.coords))
    dense_poly = Polygon(dense)
    budget = max(0.5 * chord_tolerance_mm, chord_tolerance_mm - 0.001)  # leave 1 um for the dense outline
    outline = simplify_ring(dense, budget) if decimate else dense
    if decimate and not Polygon(outline).is_valid:  # approx cut on a concave stretch: plain DP may cross itself
        simple = shapely.simplify(dense_poly, 0.5 * chord_tolerance_mm, preserve_topology=True)
        outline = _clean_ring(np.asarray(orient(_largest_polygon(simple), 1.0).exterior.coords))
    # tip lands: pieces of the outline lying on the tip curve (a pointed tooth has none)
    tip_curve = LinearRing(tip) if closed else LineString(tip)
    on_tip = dense_poly.exterior.intersection(tip_curve.buffer(1e-6))
    pieces = sorted(g.length for g in getattr(on_tip, "geoms", [on_tip]) if g.geom_type == "LineString")
    tip_land = float(pieces[0]) if len(pieces) >= z else 0.0
    flanks = _flanks(chain, points, tip_poly, dense_poly if self_intersecting else None, rack.pitch, rack_origin,
                     2 * z if closed else None)
    return GearTeeth(outline=outline, dense=dense, flanks=flanks,
                     tooth_centres=np.asarray(tooth_centres, dtype=np.float64), tip_land_min_mm=tip_land,
                     self_intersecting=self_intersecting, root_radius_min_mm=root_min)


@dataclass(frozen=True)
class _RackPoints:
    """The cutter's profile points over every tooth: their normals, profile element, rack abscissa on the
    flank (NaN off a flank) and the tooth each belongs to."""

    pts: np.ndarray
    normals: np.ndarray
    element: np.ndarray
    flank_u: np.ndarray
    owner: np.ndarray


def _rack_points(profile: RackProfile, p: float, tooth_centres: np.ndarray, delta: float, gear: str,
                 closed: bool) -> _RackPoints:
    """The cutter's profile repeated at every tooth centre (pitch ``p``), offset by ``delta`` into the gear; a
    sector's ends exactly where the next period would start."""
    z = len(tooth_centres)
    base = offset_profile(profile.points, profile.normals, delta, gear)
    k = len(base)
    pts = np.tile(base, (z, 1))
    pts[:, 0] += np.repeat(tooth_centres, k)
    normals = np.tile(profile.normals, (z, 1))
    element = np.tile(profile.element, z)
    flank_u = np.tile(profile.flank_u, z) + np.repeat(tooth_centres, k)
    owner = np.repeat(np.arange(z), k)  # the tooth each point belongs to (its osculating circle)
    if not closed:
        # a sector ends exactly where the next period would start (the space centre at the root)
        end = base[:1] + [tooth_centres[-1] + p, 0.0]
        pts = np.vstack([pts, end])
        normals = np.vstack([normals, profile.normals[:1]])
        element = np.concatenate([element, profile.element[:1]])
        flank_u = np.concatenate([flank_u, [np.nan]])
        owner = np.concatenate([owner, [z - 1]])
    return _RackPoints(pts, normals, element, flank_u, owner)


def _envelope_chain(pitch: PitchCurves, gear: str, points: _RackPoints, tooth_centres: np.ndarray,
                    method: str) -> np.ndarray:
    """The rack's envelope in the gear frame: on the pitch curve's frames (exact), or on each tooth's
    osculating circle (approx)."""
    s = contact_abscissa(points.pts, points.normals)
    if method == "exact":
        frames = pitch.frames(s, gear)
    else:
        owner = points.owner
        cf = pitch.frames(np.asarray(tooth_centres, dtype=np.float64), gear)
        per_point = PitchFrames(cf.point[owner], cf.tangent[owner], cf.normal[owner], cf.curvature[owner])
        frames = osculating_frames(s, np.asarray(tooth_centres, dtype=np.float64)[owner], per_point)
    return envelope(points.pts, s, frames, gear)


def _tip_curve(pitch: PitchCurves, gear: str, tooth_centres: np.ndarray, p: float, addendum_mm: float,
               closed: bool) -> np.ndarray:
    """The tip curve: the pitch curve offset outwards by the addendum (a sector's 1.5 pitches past its ends)."""
    if closed:
        perimeter = pitch.perimeter_a if gear == "a" else pitch.perimeter_b
        s_tip = np.linspace(0.0, perimeter, max(200, int(perimeter / p * 60)), endpoint=False)
    else:
        lo, hi = tooth_centres[0] - 1.5 * p, tooth_centres[-1] + 1.5 * p
        s_tip = np.linspace(lo, hi, max(100, int((hi - lo) / p * 60)))
    tf = pitch.frames(s_tip, gear)
    return tf.point + addendum_mm * tf.normal


def _valid_polygons(chain: np.ndarray, tip: np.ndarray, closed: bool) -> tuple[Polygon, Polygon, bool]:
    """The envelope and the tip curve as polygons (a sector's closed at the centre), each its largest valid
    piece; and whether the envelope crossed itself (undercut)."""
    origin = np.zeros((1, 2))
    if closed:
        chain_poly, tip_poly = Polygon(chain), Polygon(tip)
    else:
        chain_poly, tip_poly = Polygon(np.vstack([chain, origin])), Polygon(np.vstack([tip, origin]))
    self_intersecting = not chain_poly.is_valid
    if self_intersecting:
        chain_poly = _largest_polygon(shapely.make_valid(chain_poly))
    if not tip_poly.is_valid:
        tip_poly = _largest_polygon(shapely.make_valid(tip_poly))
    return chain_poly, tip_poly, self_intersecting


def _flanks(chain: np.ndarray, points: _RackPoints, tip_poly: Polygon, undercut: Polygon | None, p: float,
            rack_origin: float, count: int | None) -> dict[int, np.ndarray]:
    """The involute-flank points inside the tip curve by flank index (modulo ``count`` for a full gear), for
    the mesh check; with an undercut outline (``undercut``: the dense outline) only those still on it."""
    is_flank = points.element == FLANK
    inside = shapely.contains_xy(tip_poly, chain[:, 0], chain[:, 1])
    if undercut is not None:
        # undercut: the fillet trochoid cut away part of the flanks; keep only flank points that are
        # still on the outline (inside a thin band around it)
        band = undercut.buffer(1e-6, quad_segs=2).difference(undercut.buffer(-1e-6, quad_segs=2))
        inside &= shapely.contains_xy(band, chain[:, 0], chain[:, 1])
    keys = flank_index(points.flank_u, p, rack_origin)
    flanks: dict[int, np.ndarray] = {}
    for j in np.unique(keys[is_flank]):
        sel = is_flank & inside & (keys == j)
        if np.count_nonzero(sel) >= 2:
            flanks[int(j % count) if count else int(j)] = chain[sel]
    return flanks
