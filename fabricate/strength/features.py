"""Each feature of a loaded part at its governing pose: pins, pin-loaded holes, link sections, gear teeth.

:func:`fabricate.strength.check.run_strength` solves the statics of the whole motion and hands every part
and pin its share of the loads (:class:`FeatureLoads`); the functions here apply the closed-form models of
:mod:`fabricate.strength.models` to one feature each and return :class:`Finding` s, the governing stress of
each over the motion.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.errors import GeometryError
from fabricate.mechanism import Mechanism, Motion, Revolute
from fabricate.planar import rotation
from fabricate.strength import gear_teeth, models
from fabricate.strength.section import Section, cut_section, plate_polygon
from fabricate.strength.statics import Statics

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.parts.bom import Pin
    from fabricate.parts.model import Hole, Part
    from fabricate.process import Material

#: Directions at which each hole's edge distance is measured (the worse neighbour between them).
_EDGE_DIRECTIONS = 72
#: Load directions at which the net section across a pin-loaded hole is cut (every 10 degrees).
_NET_DIRECTIONS = 36



@dataclass
class Finding:
    """The governing stress of one feature of one part."""

    part: str
    feature: str
    kind: str  # pin, hole, link, gear
    stress_MPa: float
    allowable_MPa: float
    pose: int
    load: str
    fix: str
    curve: np.ndarray | None = None  # stress (MPa) at every pose, for the plot

    @property
    def safety_factor(self) -> float:
        return float(models.safety_factor(self.allowable_MPa, self.stress_MPa))  # of two floats: a float


@dataclass(frozen=True)
class FeatureLoads:
    """What every feature's check reads once the statics are solved (one build's loads over its motion)."""

    motion: Motion
    statics: Statics
    revolutes: dict[str, Revolute]
    body_point_loads: dict[str, list[tuple[np.ndarray, np.ndarray, str]]]
    body_couples: dict[str, list[tuple[np.ndarray, str]]]
    tooth_push: dict[str, np.ndarray]
    load_name: str


def _on_body_local(force: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """World forces (n, 2) in a body's frame."""
    local: np.ndarray = np.einsum("nji,nj->ni", rotation(pose[:, 2]), force)
    return local


def _edge_distances(rings: list[np.ndarray], centre: np.ndarray, radius: float) -> np.ndarray:
    """Distance (mm) from a hole's centre to the part's boundary along each of the test directions."""
    polygon = shapely.Polygon(rings[0], rings[1:])
    boundary = polygon.boundary
    span = float(np.ptp(rings[0], axis=0).max()) * 2.0 + 10.0
    # every ray in one shapely call (the same GEOS intersection of each ray as one at a time, without 72 Python
    # round trips per hole); the directions from math.cos / math.sin as before (numpy's may differ in the last bit)
    angles = [2.0 * math.pi * k / _EDGE_DIRECTIONS for k in range(_EDGE_DIRECTIONS)]
    u = np.array([[math.cos(a), math.sin(a)] for a in angles])
    rays = shapely.linestrings(np.stack([centre + (radius + 1e-6) * u, centre + span * u], axis=1))
    pts, ray = shapely.get_coordinates(shapely.intersection(rays, boundary), return_index=True)
    # each ray's nearest hit (a min is exact in any order); span where a ray meets no boundary
    out = np.full(_EDGE_DIRECTIONS, np.inf)
    np.minimum.at(out, ray, np.hypot(*(pts - centre).T))
    out[np.bincount(ray, minlength=_EDGE_DIRECTIONS) == 0] = span
    return out


def _net_section_factors(plate: Any, hole: Hole, thickness: float,
                         directions: int = _NET_DIRECTIONS) -> tuple[np.ndarray | None, np.ndarray]:
    """Kt / net area (1/mm²) and Kt of the cut through a pin-loaded hole square to each of ``directions``
    load directions (a load and its opposite share the cut line: half of them are cut).

    Between two measured directions the larger factor is used (:func:`_edge_along` with ``np.maximum``).
    """
    half = directions // 2
    factor = np.zeros(directions)
    kts = np.ones(directions)
    for k in range(half):
        a = 2.0 * math.pi * k / directions
        try:
            sec = cut_section(plate, hole.centre, np.array([-math.sin(a), math.cos(a)]), thickness)
        except GeometryError:
            continue
        kts[k] = kts[k + half] = models.hole_stress_concentration(hole.diameter_mm, sec.width_mm + hole.diameter_mm,
                                                                  True)
        factor[k] = factor[k + half] = kts[k] / sec.area_mm2
    if not np.any(factor > 0):
        return None, kts
    return factor, kts


def _edge_along(values: np.ndarray, directions: np.ndarray,
                pick: Callable[[np.ndarray, np.ndarray], np.ndarray] = np.minimum) -> np.ndarray:
    """A per-direction table (``len(values)`` directions evenly round the circle from +x) read at each
    direction (n, 2): of the two measured neighbours, ``pick`` (the least edge distance, the largest stress
    factor), never optimistic."""
    count = len(values)
    ang = np.mod(np.arctan2(directions[:, 1], directions[:, 0]), 2.0 * math.pi)
    pos = ang / (2.0 * math.pi) * count
    k0 = np.floor(pos).astype(int) % count
    k1 = (k0 + 1) % count
    edge: np.ndarray = pick(values[k0], values[k1])
    return edge


def tooth_push_by_axis(gear_pairs: list[GearPair], statics: Statics, motion: Motion) -> dict[str, np.ndarray]:
    """The tooth normal force of every gear pair at each of its two axes (summed per axis), N per pose.

    The gear coupling is a torque relation: the tooth force's push on the two axes comes on top of the
    joints' reactions there (added as a magnitude: never less than the true vector sum).
    """
    tooth_push: dict[str, np.ndarray] = {}
    for pair in gear_pairs:
        if pair.coupling in statics.gear_torques:
            fn = _tooth_normal_force(pair, statics.gear_torques[pair.coupling], motion)
            for axis in (pair.axis_a, pair.axis_b):
                tooth_push[axis] = tooth_push.get(axis, 0.0) + fn
    return tooth_push


def pin_findings(pin: Pin, parts: list[Part], loaded: FeatureLoads, pin_material: Material) -> list[Finding]:
    """Shear and bending of one pin under the largest joint force it carries, from the real stack on it."""
    revolutes, statics, motion, tooth_push = loaded.revolutes, loaded.statics, loaded.motion, loaded.tooth_push
    joints = [j for j in pin.joint.split("+") if j in revolutes]
    if not joints:
        return []
    force = np.zeros((len(motion.inputs), 2))
    for j in joints:
        force = force + statics.joint_forces[j] if len(joints) == 1 else np.maximum(
            force, np.abs(statics.joint_forces[j]))
    mag = np.hypot(force[:, 0], force[:, 1]) + sum((tooth_push.get(j, 0.0) for j in joints), np.zeros(1))
    i = int(np.argmax(mag))
    on_pin = sorted((p for p in parts if any(_joints_of(h) & set(joints) for h in p.holes)),
                    key=lambda p: p.z_mm)
    if len(on_pin) < 2:
        return []
    body_a = revolutes[joints[0]].body_a
    pairs = zip(on_pin, on_pin[1:], strict=False)
    planes = sum(1 for lo, hi in pairs if (lo.body == body_a) != (hi.body == body_a))
    planes = max(planes, 1)
    d = float(pin.diameter_mm)
    tau = np.asarray(models.pin_shear_stress(mag, d, planes), dtype=np.float64)
    found = [Finding(f"pin {pin.joint}", f"pin shear ({'double' if planes >= 2 else 'single'})",
                     "pin", float(tau[i]), pin_material.shear_MPa, i,
                     f"{mag[i]:.1f} N at {pin.joint}", "a thicker pin (process.pin_diameter_mm)",
                     tau)]
    if planes >= 2 and len(on_pin) >= 3:
        mid = on_pin[1]
        outer = min(on_pin[0].thickness_mm, on_pin[2].thickness_mm)
        gap = max(0.0, mid.z_mm - (on_pin[0].z_mm + on_pin[0].thickness_mm))
        moment = models.pin_bending_moment_double_shear(mag, mid.thickness_mm, outer, gap)
    else:
        lo, hi = on_pin[0], on_pin[-1]
        gap = max(0.0, hi.z_mm - (lo.z_mm + lo.thickness_mm))
        moment = models.pin_bending_moment_single_shear(mag, lo.thickness_mm, hi.thickness_mm, gap)
    sigma = np.asarray(models.pin_bending_stress(moment, d), dtype=np.float64)
    found.append(Finding(f"pin {pin.joint}", "pin bending", "pin", float(sigma[i]),
                         pin_material.flexural_MPa, i, f"{mag[i]:.1f} N at {pin.joint}",
                         "a thicker pin or a smaller layer gap", sigma))
    return found


def part_findings(part: Part, parts: list[Part], carried: set[str], chord: float, loaded: FeatureLoads,
                   material: Material) -> list[Finding]:
    """Every hole that carries a joint (bearing, tear-out, net section) and every section at and between
    those holes of one part, under its share of its body's loads."""
    share = sum(1 for p in parts if p.body == part.body) or 1
    rings = part.polygons(chord)
    plate = plate_polygon(rings)  # made and validated once: every cut below reads it
    pose = loaded.motion.pose(part.body)
    t = part.thickness_mm
    loads_local = []  # (local point, local force (n, 2), at joint)
    for local, f, at in loaded.body_point_loads.get(part.body, []):
        if at and at in loaded.revolutes and not any(at in _joints_of(h) for h in part.holes):
            continue
        loads_local.append((np.asarray(local, dtype=np.float64), _on_body_local(np.asarray(f) / share, pose), at))
    couples = [(np.asarray(c) / share, at) for c, at in loaded.body_couples.get(part.body, [])]
    holes = [h for h in part.holes if _joints_of(h) & carried]
    found: list[Finding] = []
    for h in holes:
        found += _hole_findings(part, h, rings, plate, t, share, loads_local, loaded, material)
    found += _sections_between_holes(part, holes, plate, t, loads_local, couples, material, loaded.load_name)
    return found


def _hole_findings(part: Part, h: Hole, rings: list[np.ndarray], plate: Any, t: float, share: int,
                   loads_local: list[tuple[np.ndarray, np.ndarray, str]], loaded: FeatureLoads,
                   material: Material) -> list[Finding]:
    """Bearing, tear-out and the net section across one pin-loaded hole, each at its governing pose."""
    motion, tooth_push = loaded.motion, loaded.tooth_push
    f = sum((lf for lp, lf, at in loads_local if at in _joints_of(h)), np.zeros((len(motion.inputs), 2)))
    push = sum((tooth_push.get(j, 0.0) for j in _joints_of(h)), np.zeros(1))
    mag = np.hypot(f[:, 0], f[:, 1]) + push / share
    if not np.any(mag > 0):
        return []
    i = int(np.argmax(mag))
    pin_d = h.pin_diameter_mm or h.diameter_mm
    bearing = np.asarray(models.bearing_stress(mag, pin_d, t), dtype=np.float64)
    found = [Finding(part.name, f"hole {h.joint} bearing", "hole", float(bearing[i]),
                     material.compressive_MPa, i, f"{mag[i]:.1f} N at {h.joint}",
                     "a thicker plate (process.thickness_mm) or a larger pin", bearing)]
    edges = _edge_distances(rings, h.centre, 0.5 * h.diameter_mm)
    fmag = np.hypot(f[:, 0], f[:, 1])
    # where the load's direction is unknown (the tooth push is added as a magnitude) take the worst
    known = fmag >= 0.999 * mag
    unit = f / np.maximum(fmag, 1e-300)[:, None]
    e = np.where(known, _edge_along(edges, unit), edges.min())
    with np.errstate(divide="ignore", invalid="ignore"):
        tear = np.where(e > 0.5 * h.diameter_mm,
                        np.asarray(models.tearout_stress(mag, np.maximum(e, 0.5 * h.diameter_mm + 1e-9),
                                                         h.diameter_mm, t), dtype=np.float64), math.inf)
    k = int(np.argmax(tear))
    found.append(Finding(part.name, f"hole {h.joint} tear-out", "hole", float(tear[k]),
                         material.shear_MPa, k,
                         f"{mag[k]:.1f} N at {h.joint} (edge {e[k]:.2f} mm)",
                         "more material round the hole (parts.boss_wall_mm / link_width_mm)",
                         tear))
    # the net section across a pin-loaded hole, square to the load: Kt / area per load direction
    factor, kts = _net_section_factors(plate, h, t)
    if factor is None:
        return found
    per_pose = np.where(known, _edge_along(factor, unit, np.maximum), factor.max())
    net = mag * per_pose
    k = int(np.argmax(net))
    kt = float(_edge_along(kts, unit[k:k + 1], np.maximum)[0] if known[k] else kts[int(np.argmax(factor))])
    found.append(Finding(part.name, f"net section at hole {h.joint} (Kt {kt:.2f})", "link",
                         float(net[k]), material.tensile_MPa, k, f"{mag[k]:.1f} N at {h.joint}",
                         "a wider link (parts.link_width_mm) or a thicker plate", net))
    return found


def _sections_between_holes(part: Part, holes: list[Hole], plate: Any, t: float,
                            loads_local: list[tuple[np.ndarray, np.ndarray, str]],
                            couples: list[tuple[np.ndarray, str]], material: Material, load_name: str) -> list[Finding]:
    """Sections at and between every pair of holes: free body on one side of the cut."""
    found = []
    for a_idx in range(len(holes)):
        for b_idx in range(a_idx + 1, len(holes)):
            ha, hb = holes[a_idx], holes[b_idx]
            axis = hb.centre - ha.centre
            length = float(np.hypot(*axis))
            if length < 1e-9:
                continue
            u = axis / length
            for station in (0.0, 0.25, 0.5, 0.75, 1.0):
                point = ha.centre + station * axis
                try:
                    sec = cut_section(plate, point, np.array([-u[1], u[0]]), t)
                except GeometryError:
                    continue
                finding = _section_finding(part, sec, point, u, station, ha, hb, loads_local, couples,
                                           material, load_name)
                if finding is not None:
                    found.append(finding)
    return found


def _section_finding(part: Part, sec: Section, point: np.ndarray, u: np.ndarray, station: float, ha: Hole, hb: Hole,
                     loads_local: list[tuple[np.ndarray, np.ndarray, str]], couples: list[tuple[np.ndarray, str]],
                     material: Material, load_name: str) -> Finding | None:
    """Tension + bending on one cut of a part (``u`` the link axis, the cut square to it)."""
    n = next(iter(lf for _, lf, _ in loads_local)).shape[0] if loads_local else 0
    if n == 0:
        return None
    force = np.zeros((n, 2))
    moment = np.zeros(n)
    c = sec.centroid_mm
    for lp, lf, at in loads_local:
        side = float(np.dot(lp - point, u))
        # the cut through a hole's centre puts that hole's own load on the far side
        if side < -1e-9 or (abs(side) <= 1e-9 and at and at in _joints_of(ha) and station == 1.0):
            force += lf
            arm = lp - c
            moment += arm[0] * lf[:, 1] - arm[1] * lf[:, 0]
    for torque, at in couples:
        spot = ha.centre if at in _joints_of(ha) else hb.centre if at in _joints_of(hb) else None
        if spot is None:
            continue
        side = float(np.dot(spot - point, u))
        if side < -1e-9 or (abs(side) <= 1e-9 and station == 0.0):
            moment += torque
    axial = force @ u
    at_hole = station in (0.0, 1.0)
    hole = ha if station == 0.0 else hb
    kt = models.hole_stress_concentration(hole.diameter_mm, sec.width_mm + hole.diameter_mm, False) if at_hole else 1.0
    stress = np.asarray(models.net_section_stress(axial, moment, sec, kt), dtype=np.float64)
    k = int(np.argmax(stress))
    where = f"at hole {hole.joint}" if at_hole else f"between {ha.joint} and {hb.joint} ({station:.2f})"
    allowable = material.flexural_MPa if abs(moment[k]) * sec.extreme_fibre_mm / sec.inertia_mm4 > abs(
        axial[k]) / sec.area_mm2 else material.tensile_MPa
    return Finding(part.name, f"section {where}: N {axial[k]:.1f} N, M {moment[k]:.0f} N·mm"
                   + (f" (Kt {kt:.2f})" if at_hole else ""), "link", float(stress[k]), allowable, k, load_name,
                   "a wider link (parts.link_width_mm) or a thicker plate (process.thickness_mm)", stress)


def _joints_of(hole: Hole) -> set[str]:
    """The joints a hole serves (a pin shared by coincident joints is named "A+B")."""
    return set(hole.joint.split("+"))


def _pressure_angle(pair: GearPair) -> float:
    """The pair's rack pressure angle (rad)."""
    spec = getattr(pair, "spec", None)
    return math.radians(float(getattr(spec, "pressure_angle_deg", 20.0)))


def _tooth_normal_force(pair: GearPair, torque_b: np.ndarray, motion: Motion) -> np.ndarray:
    """Tooth normal force (N) of a pair at every pose from the torque on gear b (pitch point on the line of
    centres, pressure angle from the pair)."""
    xa = motion.relative_angle(pair.body_a, pair.carrier)
    ratio = np.abs(np.asarray(pair.law(xa, 1), dtype=np.float64))
    r_b = pair.center_distance_mm / (1.0 + ratio)
    phi = _pressure_angle(pair)
    normal: np.ndarray = np.abs(torque_b) / np.maximum(r_b, 1e-9) / math.cos(phi)
    return normal


@dataclass(frozen=True)
class ToothStresses:
    """Lewis root bending of each gear and Hertz contact of a pair at every pose (:func:`tooth_stresses`).

    ``lewis`` maps the gear (``"a"``, ``"b"``) to its root stress (MPa), Lewis form factor and equivalent tooth
    count per pose; ``tangential_N`` and ``normal_N`` are the tooth loads they come from."""

    tangential_N: np.ndarray
    normal_N: np.ndarray
    lewis: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]
    hertz_MPa: np.ndarray


def tooth_stresses(pair: GearPair, torque_b: np.ndarray, motion: Motion, face_mm: float,
                   material: Material) -> ToothStresses:
    """Lewis root bending and Hertz contact of one gear pair at every pose, under the torque on gear b.

    At each pose the pitch point lies on the line of centres, ``r_a = a i / (1 + i)`` from axis a (``i`` the
    instantaneous ratio); the local radius of curvature of each pitch curve there makes the equivalent
    spur gear (``z_eq = 2 rho / m``) whose Lewis form factor the tooth gets, and the two radii (times
    sin phi) are the involute flanks' radii for Hertz. A concave stretch takes the rack's form factor
    and bears as a concave surface. The Hertz stress does not depend on the module (only on the pitch
    curves, the load and the face width): a larger module relieves the root, never the contact.
    """
    xa = motion.relative_angle(pair.body_a, pair.carrier)
    xb = motion.relative_angle(pair.body_b, pair.carrier)
    ratio = np.abs(np.asarray(pair.law(xa, 1), dtype=np.float64))
    a = pair.center_distance_mm
    r_a, r_b = a * ratio / (1.0 + ratio), a / (1.0 + ratio)
    ft = np.abs(torque_b) / np.maximum(r_b, 1e-9)
    phi = _pressure_angle(pair)
    # the contact in each gear's frame (pitch curves: x along the line of centres at relative angle 0)
    contact_a = r_a[:, None] * np.column_stack([np.cos(-xa), np.sin(-xa)])
    contact_b = r_b[:, None] * np.column_stack([np.cos(math.pi - xb), np.sin(math.pi - xb)])
    rho_a = local_radius(pair.pitch_a, contact_a)
    rho_b = local_radius(pair.pitch_b, contact_b)
    lewis = {}
    for gear, rho in (("a", rho_a), ("b", rho_b)):
        with np.errstate(divide="ignore", invalid="ignore"):
            teeth = np.where(np.isfinite(rho) & (rho > 0), 2.0 * rho / pair.module, np.inf)
        y = np.asarray(gear_teeth.lewis_form_factor(teeth), dtype=np.float64)
        sigma = np.asarray(gear_teeth.lewis_bending_stress(ft, pair.module, face_mm, y), dtype=np.float64)
        lewis[gear] = (sigma, y, teeth)
    fn = ft / math.cos(phi)
    flat = 1e9  # a straight pitch stretch: a flat flank for Hertz
    r1, r2 = gear_teeth.involute_contact_radii(np.where(np.isfinite(rho_a), rho_a, flat),
                                           np.where(np.isfinite(rho_b), rho_b, flat), phi)
    hertz = np.asarray(gear_teeth.hertz_line_contact_stress(fn, face_mm, r1, r2, material.modulus_MPa,
                                                        material.poisson, material.modulus_MPa, material.poisson),
                       dtype=np.float64)
    return ToothStresses(ft, fn, lewis, hertz)


def gear_findings(pair: GearPair, torque_b: np.ndarray, mechanism: Mechanism, motion: Motion, parts: list[Part],
                  material: Material) -> list[Finding]:
    """Lewis root bending and Hertz contact of one gear pair (:func:`tooth_stresses`) as findings, the face
    width the thinnest of the pair's parts."""
    face = min((p.thickness_mm for p in parts if p.gear == pair.name), default=None)
    if face is None:
        return []
    stresses = tooth_stresses(pair, torque_b, motion, face, material)
    ft, fn = stresses.tangential_N, stresses.normal_N
    found = []
    for gear in ("a", "b"):
        sigma, y, teeth = stresses.lewis[gear]
        i = int(np.argmax(sigma))
        body = pair.body_a if gear == "a" else pair.body_b
        name = next((p.name for p in parts if p.body == body and p.gear == pair.name), body)
        found.append(Finding(name, f"gear {pair.name} tooth root (Lewis, Y {y[i]:.3f}, z_eq {teeth[i]:.1f})",
                             "gear", float(sigma[i]), material.flexural_MPa, i, f"{ft[i]:.1f} N tangential",
                             "a larger module (gears.module_mm) or a thicker plate", sigma))
    hertz = stresses.hertz_MPa
    i = int(np.argmax(hertz))
    name = next((p.name for p in parts if p.gear == pair.name), pair.name)
    found.append(Finding(name, f"gear {pair.name} tooth contact (Hertz)", "gear", float(hertz[i]),
                         material.compressive_MPa, i, f"{fn[i]:.1f} N normal",
                         "a thicker plate or a lighter load (the contact stress does not depend on the module)", hertz))
    return found


#: Point-vertex pairs :func:`local_radius` compares at once (about 16 MB of differences).
NEAREST_VALUES_PER_CHUNK = 1_000_000


def local_radius(points: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Signed radius of curvature (mm; positive where the curve turns with its own sense, i.e. convex) of a
    pitch polyline at the vertex nearest each point of ``at`` (n, 2); inf where it is straight."""
    p = np.asarray(points, dtype=np.float64)
    prev, nxt = np.roll(p, 1, axis=0), np.roll(p, -1, axis=0)
    ab, bc, ca = np.hypot(*(p - prev).T), np.hypot(*(nxt - p).T), np.hypot(*(prev - nxt).T)
    cross = (p - prev)[:, 0] * (nxt - prev)[:, 1] - (p - prev)[:, 1] * (nxt - prev)[:, 0]
    sense = 1.0 if float(np.sum(p[:, 0] * nxt[:, 1] - nxt[:, 0] * p[:, 1])) >= 0 else -1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.where(cross != 0.0, sense * ab * bc * ca / (2.0 * cross), np.inf)
    # an open curve's end vertices have no neighbour on one side: take their inner neighbour's value
    radius[0], radius[-1] = radius[1], radius[-2]
    # the nearest vertex of a few points at a time: all at once is an (n, vertices, 2) array, 0.24 GB at 5000
    # poses of a 3000-vertex pitch curve (each row's argmin is its own, so the chunk size changes nothing)
    at = np.asarray(at, dtype=np.float64).reshape(-1, 2)
    chunk = max(1, NEAREST_VALUES_PER_CHUNK // max(1, len(p)))
    # dx * dx + dy * dy: the bits np.sum(d ** 2, axis=2) gives, without its (chunk, vertices, 2) temporaries and
    # its slow reduction over an axis of 2 (~4x faster)
    px, py = p[:, 0], p[:, 1]
    nearest = np.concatenate([np.argmin(np.square(px[None, :] - at[i:i + chunk, 0:1])
                                        + np.square(py[None, :] - at[i:i + chunk, 1:2]), axis=1)
                              for i in range(0, len(at), chunk)] or [np.zeros(0, dtype=np.intp)])
    nearest_radius: np.ndarray = radius[nearest]
    return nearest_radius
