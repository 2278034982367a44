"""The strength check: every part and pin at its design load, over the whole motion.

Loads (:func:`design_loads`) come from the template's ``[load]`` and the synthesis' springs; the joint
reactions, gear torques and driver efforts at every pose from :func:`~fabricate.strength.statics.solve_statics`.
Each part then gets the closed-form models of :mod:`fabricate.strength.models`, each with its governing
pose:

- pins: shear (single or double, from the real stack on the pin) and bending (the stack's plate
  thicknesses and gaps);
- holes: bearing, tear-out (edge distance along the load, measured on the part's outline) and the
  net section across a pin-loaded hole (with its stress concentration);
- links: tension and in-plane bending at and between the holes, on sections cut from the part's real
  outline (free body: every load on one side of the cut), with the open-hole concentration at a hole;
- gears: Lewis root bending with the form factor of the equivalent spur gear of the sharpest pitch-curve
  curvature, and Hertz contact at the pitch point, from the transmitted torque.

Safety factor = allowable / stress; a part below ``[checks] min_safety_factor`` fails the build with the
part, the feature, the load that governs and what would fix it.

A check that cannot run is "not checked", never "passed": with no materials in the process profile, or
no load at all (no ``[load]`` and no springs), :attr:`StrengthResult.passed` is None and
:attr:`StrengthResult.reason` says why; no part gets a safety factor (at zero load every one would be
an infinite, meaningless "pass").
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely

from fabricate.errors import GeometryError
from fabricate.mechanism import Mechanism, Motion, Revolute, Slider
from fabricate.planar import rotation
from fabricate.strength import models
from fabricate.strength.section import cut_section, plate_polygon
from fabricate.strength.statics import BodyTorque, DriverEffort, PointForce, Statics, solve_statics

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
        return models.safety_factor(self.allowable_MPa, self.stress_MPa)


@dataclass(frozen=True)
class Loads:
    """Applied loads over the motion and what they are, for people.

    ``reaction``: with a known actuator effort, the object's resistance at the tip, a unit direction per
    pose whose magnitude the statics solve.
    """

    forces: tuple[PointForce, ...]
    torques: tuple[BodyTorque, ...]
    efforts: tuple[DriverEffort, ...]
    described: tuple[str, ...]
    reaction: PointForce | None = None


@dataclass
class StrengthResult:
    """Findings, the statics they come from and the report section."""

    findings: list[Finding]
    statics: Statics | None
    min_safety_factor: float
    inputs: np.ndarray
    curves: dict[str, np.ndarray] = field(default_factory=dict)
    loads: tuple[str, ...] = ()
    notes: list[str] = field(default_factory=list)
    reason: str | None = None  # why the check could not run (then nothing passed or failed)

    def per_part(self) -> dict[str, Finding]:
        worst: dict[str, Finding] = {}
        for f in self.findings:
            if f.part not in worst or f.safety_factor < worst[f.part].safety_factor:
                worst[f.part] = f
        return worst

    @property
    def passed(self) -> bool | None:
        """Whether every part keeps the safety factor; None when the check could not run (:attr:`reason`)."""
        if self.reason is not None:
            return None
        return all(f.safety_factor >= self.min_safety_factor for f in self.findings)

    def failures(self) -> list[str]:
        if self.reason is not None:
            return []
        out = []
        for name, f in sorted(self.per_part().items(), key=lambda kv: kv[1].safety_factor):
            if f.safety_factor >= self.min_safety_factor:
                continue
            out.append(f"strength: part {name}, {f.feature}: {f.stress_MPa:.1f} MPa under {f.load} at input "
                       f"{self.inputs[f.pose]:.4g} gives a safety factor {f.safety_factor:.2f} < "
                       f"{self.min_safety_factor:g} (allowable {f.allowable_MPa:g} MPa); {f.fix}")
        return out

    def report(self) -> dict[str, Any]:
        """report.json's ``strength`` section: ``passed`` (None: not checked, then ``reason`` says why),
        the loads and one row per part and pin (a part no load reaches has a null safety factor: JSON has
        no infinity)."""
        parts = []
        for name, f in sorted(self.per_part().items()):
            parts.append({"name": name, "min_safety_factor": _round(f.safety_factor), "feature": f.feature,
                          "input": f.load, "pose_input": _round(float(self.inputs[f.pose])),
                          "stress_MPa": _round(f.stress_MPa), "allowable_MPa": _round(f.allowable_MPa),
                          "fix": f.fix})
        out: dict[str, Any] = {"passed": self.passed}
        if self.reason is not None:
            out["reason"] = self.reason
        out.update({"required_safety_factor": self.min_safety_factor, "loads": list(self.loads), "parts": parts,
                    "notes": list(self.notes)})
        return out


def _round(x: float) -> float | None:
    """``x`` to 6 significant digits; None for a non-finite value (what report.json writes for it)."""
    return float(f"{x:.6g}") if math.isfinite(x) else None


#: Why the strength check did not run (``StrengthResult.reason``), in the words the CLI prints.
NO_MATERIALS = "no materials in the profile"
NO_LOAD = "no [load] in the template"


# -- loads -----------------------------------------------------------------------------------------

def _unit_rows(v: np.ndarray) -> np.ndarray:
    """Rows of ``v`` (n, 2) scaled to unit length; a zero row takes its nearest non-zero neighbour."""
    norm = np.hypot(v[:, 0], v[:, 1])
    ok = norm > 1e-12 * max(1.0, float(norm.max(initial=0.0)))
    if not ok.any():
        raise GeometryError("strength: the tip point does not move, so the tip load has no direction")
    good = np.flatnonzero(ok)
    nearest = good[np.clip(np.searchsorted(good, np.arange(len(v))), 0, len(good) - 1)]
    src = np.where(ok, np.arange(len(v)), nearest)
    return v[src] / norm[src][:, None]


def _joint_between(mechanism: Mechanism, a: str, b: str) -> Revolute | None:
    for j in mechanism.joints:
        if isinstance(j, Revolute) and {j.body_a, j.body_b} == {a, b}:
            return j
    return None


def design_loads(design: Any, mechanism: Mechanism, motion: Motion, hints: Mapping[str, Any]) -> Loads:
    """The template's ``[load]`` and the synthesis' springs as loads over the motion."""
    load = design.load
    forces: list[PointForce] = []
    torques: list[BodyTorque] = []
    efforts: list[DriverEffort] = []
    said: list[str] = []
    n = len(motion.inputs)
    reaction = None
    actuated = bool(load.input_force_N or load.input_torque_Nmm)
    if load.tip_force_N > 0.0 or actuated:
        point = load.tip_point or hints.get("tip_point")
        if not point or point not in mechanism.point_names():
            raise GeometryError(f"strength: load.tip_point {point!r} is not a named point of the mechanism")
        owners = [b for b, pad in (hints.get("pads") or {}).items() if pad.get("point") == point]
        body = owners[0] if owners else mechanism.point_owner(point)
        path = motion.point(point, body)
        if load.object_centre:
            centre = load.object_centre
            if centre not in mechanism.body(mechanism.ground).points:
                raise GeometryError(f"strength: load.object_centre {centre!r} is not a named point of the "
                                    f"ground {mechanism.ground!r}")
            against = _unit_rows(path - mechanism.body(mechanism.ground).point(centre))
            how = f"pushing away from {centre}"
        elif load.tip_force_deg is not None:
            a = math.radians(load.tip_force_deg)
            against = np.broadcast_to(np.array([math.cos(a), math.sin(a)]), path.shape).copy()
            how = f"at {load.tip_force_deg:g}° in the ground's frame"
        else:
            against = -_unit_rows(np.gradient(path, motion.inputs, axis=0))
            how = "opposing its motion"
        local = mechanism.body(body).point(point)
        if actuated:
            # the object at the tip holds what the actuator pushes: its force is solved, not given
            reaction = PointForce(body, local, against, name=f"object at {point}")
            said.append(f"the object at {point} holding the actuator, {how}")
        else:
            forces.append(PointForce(body, local, load.tip_force_N * against, name=f"tip force at {point}"))
            said.append(f"tip force {load.tip_force_N:g} N at {point}, {how}")
    if load.torque_Nmm > 0.0:
        body = load.torque_body
        if body not in mechanism.body_names or body == mechanism.ground:
            raise GeometryError(f"strength: load.torque_body {body!r} is not a moving body of the mechanism "
                                f"({', '.join(b for b in mechanism.body_names if b != mechanism.ground)})")
        turn = np.gradient(motion.pose(body)[:, 2], motion.inputs)
        sense = np.sign(np.where(turn == 0.0, 1.0, turn))
        torques.append(BodyTorque(body, mechanism.ground, -load.torque_Nmm * sense))
        said.append(f"torque {load.torque_Nmm:g} N·mm on {body}, resisting its turn")
    if load.springs:
        for spring in hints.get("springs", ()) or ():
            rate = float(spring.get("rate_Nmm_per_deg") or 0.0)
            joint = next((j for j in mechanism.joints if j.name == spring.get("joint")), None)
            if rate <= 0.0 or not isinstance(joint, Revolute):
                continue
            rel = np.degrees(motion.relative_angle(joint.body_b, joint.body_a))
            sense = 1.0 if rel[-1] >= rel[0] else -1.0
            deflection = float(spring.get("preload_deg") or 0.0) + sense * (rel - rel[0])
            # a return spring resists the closing: the torque on body_b is against its relative turn
            torques.append(BodyTorque(joint.body_b, joint.body_a, -sense * rate * np.maximum(deflection, 0.0),
                                      joint=joint.name))
            said.append(f"spring at {joint.name}, {rate:g} N·mm/° from {float(spring.get('preload_deg') or 0):g}° "
                        f"preload (up to {rate * float(np.max(deflection)):.0f} N·mm)")
    if (load.input_force_N or load.input_torque_Nmm) and mechanism.drivers:
        driver = mechanism.drivers[0]
        value = load.input_force_N if driver.kind == "slide" else load.input_torque_Nmm
        if value == 0.0:
            field_name = "input_torque_Nmm" if driver.kind == "angle" else "input_force_N"
            raise GeometryError(f"strength: the first driver is a{'n angle' if driver.kind == 'angle' else ' slide'}; "
                                f"give load.{field_name}")
        # the actuator pushes the way the motion goes
        if driver.law is not None:
            slope = np.asarray(driver.law(motion.inputs, 1), dtype=np.float64)
        else:
            slope = np.ones(n)
        sign = np.sign(np.where(slope == 0.0, 1.0, slope)) * np.sign(motion.inputs[-1] - motion.inputs[0] or 1.0)
        efforts.append(DriverEffort(0, value * sign))
        unit = "N" if driver.kind == "slide" else "N·mm"
        said.append(f"actuator {value:g} {unit} on the input")
    return Loads(tuple(forces), tuple(torques), tuple(efforts), tuple(said), reaction)


# -- the check ---------------------------------------------------------------------------------------

def _on_body_local(force: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """World forces (n, 2) in a body's frame."""
    return np.einsum("nji,nj->ni", rotation(pose[:, 2]), force)


def _edge_distances(rings: list[np.ndarray], centre: np.ndarray, radius: float) -> np.ndarray:
    """Distance (mm) from a hole's centre to the part's boundary along each of the test directions."""
    polygon = shapely.Polygon(rings[0], rings[1:])
    boundary = polygon.boundary
    span = float(np.ptp(rings[0], axis=0).max()) * 2.0 + 10.0
    out = np.empty(_EDGE_DIRECTIONS)
    for k in range(_EDGE_DIRECTIONS):
        a = 2.0 * math.pi * k / _EDGE_DIRECTIONS
        u = np.array([math.cos(a), math.sin(a)])
        ray = shapely.LineString([centre + (radius + 1e-6) * u, centre + span * u])
        hit = ray.intersection(boundary)
        pts = shapely.get_coordinates(hit)
        out[k] = float(np.min(np.hypot(*(pts - centre).T))) if len(pts) else span
    return out


def _net_section_factors(plate: Any, hole: Any, thickness: float,
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


def _edge_along(values: np.ndarray, directions: np.ndarray, pick: Any = np.minimum) -> np.ndarray:
    """A per-direction table (``len(values)`` directions evenly round the circle from +x) read at each
    direction (n, 2): of the two measured neighbours, ``pick`` (the least edge distance, the largest stress
    factor), never optimistic."""
    count = len(values)
    ang = np.mod(np.arctan2(directions[:, 1], directions[:, 0]), 2.0 * math.pi)
    pos = ang / (2.0 * math.pi) * count
    k0 = np.floor(pos).astype(int) % count
    k1 = (k0 + 1) % count
    return pick(values[k0], values[k1])


def solved_loads(loads: Loads, magnitude: np.ndarray) -> Loads:
    """``loads`` with the object's solved reaction made a known force (for the free bodies)."""
    r = loads.reaction
    force = PointForce(r.body, r.local, np.asarray(r.force) * np.asarray(magnitude)[:, None], name=r.name)
    k = int(np.argmax(np.abs(magnitude)))
    said = tuple(d if not d.startswith("the object at") else
                 f"{d} (solved: up to {abs(float(magnitude[k])):.1f} N)" for d in loads.described)
    return Loads(loads.forces + (force,), loads.torques, loads.efforts, said, None)


def body_loads(mechanism: Mechanism, motion: Motion, statics: Statics, loads: Loads
               ) -> tuple[dict[str, list[tuple[np.ndarray, np.ndarray, str]]], dict[str, list[tuple[np.ndarray, str]]]]:
    """Every load each body receives over the motion, in equilibrium body by body.

    Returns
    -------
    point_loads : dict body -> list of (local point (2,) mm, world force (n, 2) N, joint name or '')
        Joint reactions, applied forces, slide-driver and slider forces.
    couples : dict body -> list of (torque (n,) N·mm, joint it acts at or '')
        Springs and angle-driver efforts.
    """
    revolutes = {j.name: j for j in mechanism.joints if isinstance(j, Revolute)}
    # forces each body receives: at its joints (pins), applied forces and couples, driver efforts
    body_point_loads: dict[str, list[tuple[np.ndarray, np.ndarray, str]]] = {}  # body -> (local point, world F, at)
    body_couples: dict[str, list[tuple[np.ndarray, str]]] = {}  # body -> (torque (n,), at joint)
    for name, j in revolutes.items():
        f = statics.joint_forces[name]
        body_point_loads.setdefault(j.body_a, []).append((mechanism.body(j.body_a).point(name), f, name))
        body_point_loads.setdefault(j.body_b, []).append((mechanism.body(j.body_b).point(name), -f, name))
    for pf in loads.forces:
        body_point_loads.setdefault(pf.body, []).append((np.asarray(pf.local), np.asarray(pf.force), ""))
    for t in loads.torques:
        body_couples.setdefault(t.body, []).append((np.asarray(t.torque), t.joint))
        body_couples.setdefault(t.reaction, []).append((-np.asarray(t.torque), t.joint))
    for k, d in enumerate(mechanism.drivers):
        carried = statics.driver_efforts[:, k]  # torque (angle) or force (slide) the driver puts on its body
        if d.kind == "angle":
            j = _joint_between(mechanism, d.body, d.reference)
            body_couples.setdefault(d.body, []).append((carried, j.name if j else ""))
            body_couples.setdefault(d.reference, []).append((-carried, j.name if j else ""))
        else:
            slider = next(s for s in mechanism.joints if isinstance(s, Slider) and s.name == d.joint)
            axis = np.asarray(slider.axis, dtype=np.float64) / math.hypot(*slider.axis)
            u = np.einsum("nij,j->ni", rotation(motion.pose(d.reference)[:, 2]), axis)
            body_point_loads.setdefault(d.body, []).append(
                (mechanism.body(d.body).point(d.joint), carried[:, None] * u, d.joint))
            body_point_loads.setdefault(d.reference, []).append(
                (mechanism.body(d.reference).point(d.joint), -carried[:, None] * u, d.joint))
    for s in (j for j in mechanism.joints if isinstance(j, Slider)):
        normal_local = np.array([-s.axis[1], s.axis[0]], dtype=np.float64) / math.hypot(*s.axis)
        nw = np.einsum("nij,j->ni", rotation(motion.pose(s.body_a)[:, 2]), normal_local)
        fn = statics.slider_forces[s.name][:, None] * nw
        body_point_loads.setdefault(s.body_b, []).append((mechanism.body(s.body_b).point(s.name), fn, s.name))
        body_point_loads.setdefault(s.body_a, []).append((mechanism.body(s.body_a).point(s.name), -fn, s.name))
        lock = statics.slider_torques[s.name]
        body_couples.setdefault(s.body_b, []).append((lock, s.name))
        body_couples.setdefault(s.body_a, []).append((-lock, s.name))
    for g in mechanism.gears:
        # the coupling acts as torques (the tooth force's push on the axes is added at the pins)
        lam = statics.gear_torques[g.name]
        slope = np.asarray(g.law(motion.relative_angle(g.gear_a, g.carrier), 1), dtype=np.float64)
        for body, coef, at in ((g.gear_b, 1.0, g.axis_b), (g.gear_a, -slope, g.axis_a),
                               (g.carrier, slope - 1.0, g.axis_a)):
            body_couples.setdefault(body, []).append((coef * lam, at))
    return body_point_loads, body_couples


def run_strength(design: Any, partset: Any, mechanism: Mechanism, motion: Motion, gear_pairs: list[Any],
                 hints: Mapping[str, Any]) -> StrengthResult:
    """Every part and pin at the design load over ``motion``; see the module docstring."""
    required = float(design.checks.min_safety_factor)
    material = design.process.part_material()
    pin_material = design.process.pin_material_spec()
    result = StrengthResult([], None, required, np.asarray(motion.inputs))
    if material is None or pin_material is None:
        result.reason = NO_MATERIALS
        return result
    loads = design_loads(design, mechanism, motion, hints)
    result.loads = loads.described
    if not loads.described:
        # nothing loads the parts: every stress would be 0 and every safety factor infinite
        # (every force, torque and effort of [load] is 0 then, and no spring of the synthesis acts)
        result.reason = NO_LOAD
        return result
    if any(float(sp.get("rate_Nmm_per_deg") or 0.0) > 0.0 for sp in hints.get("springs", ()) or ()):
        # the springs are bought parts (BOM rows with rate, preload, legs): their wire stress is the maker's
        # rating; what the check covers is the torque they put on the printed parts
        result.notes.append("springs are bought torsion springs (bom.csv): choose one rated for the torque "
                            "above; their torque loads the parts here")
    statics = solve_statics(mechanism, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    result.statics = statics
    if loads.reaction is not None:
        solved = statics.reaction_N
        loads = solved_loads(loads, solved)
        result.loads = loads.described
    chord = partset.chord_tolerance_mm
    parts = [p for p in partset.parts if p.role != "spacer"]
    revolutes = {j.name: j for j in mechanism.joints if isinstance(j, Revolute)}
    load_name = "; ".join(loads.described) or "no load"

    body_point_loads, body_couples = body_loads(mechanism, motion, statics, loads)

    # the gear coupling is a torque relation: the tooth force's push on the two axes comes on top of the
    # joints' reactions there (added as a magnitude: never less than the true vector sum)
    tooth_push: dict[str, np.ndarray] = {}
    for pair in gear_pairs:
        if pair.coupling in statics.gear_torques:
            fn = _tooth_normal_force(pair, statics.gear_torques[pair.coupling], motion)
            for axis in (pair.axis_a, pair.axis_b):
                tooth_push[axis] = tooth_push.get(axis, 0.0) + fn

    # -- pins --------------------------------------------------------------------------------------
    for pin in partset.pins:
        joints = [j for j in pin.joint.split("+") if j in revolutes]
        if not joints:
            continue
        force = np.zeros((len(motion.inputs), 2))
        for j in joints:
            force = force + statics.joint_forces[j] if len(joints) == 1 else np.maximum(
                force, np.abs(statics.joint_forces[j]))
        mag = np.hypot(force[:, 0], force[:, 1]) + sum((tooth_push.get(j, 0.0) for j in joints), np.zeros(1))
        i = int(np.argmax(mag))
        on_pin = sorted((p for p in parts if any(_joints_of(h) & set(joints) for h in p.holes)),
                        key=lambda p: p.z_mm)
        if len(on_pin) < 2:
            continue
        body_a = revolutes[joints[0]].body_a
        pairs = zip(on_pin, on_pin[1:], strict=False)
        planes = sum(1 for lo, hi in pairs if (lo.body == body_a) != (hi.body == body_a))
        planes = max(planes, 1)
        d = float(pin.diameter_mm)
        tau = np.asarray(models.pin_shear_stress(mag, d, planes), dtype=np.float64)
        result.findings.append(Finding(f"pin {pin.joint}", f"pin shear ({'double' if planes >= 2 else 'single'})",
                                       "pin", float(tau[i]), pin_material.shear_MPa, i,
                                       f"{mag[i]:.1f} N at {pin.joint}", "a thicker pin (process.pin_diameter_mm)",
                                       tau))
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
        result.findings.append(Finding(f"pin {pin.joint}", "pin bending", "pin", float(sigma[i]),
                                       pin_material.flexural_MPa, i, f"{mag[i]:.1f} N at {pin.joint}",
                                       "a thicker pin or a smaller layer gap", sigma))

    # holes that carry a mechanism joint (revolute, or a slider's guide pin); "A+B" is one pin for two
    carried = set(revolutes) | {j.name for j in mechanism.joints if isinstance(j, Slider)}

    # -- parts: holes and sections ---------------------------------------------------------------------
    for part in parts:
        share = sum(1 for p in parts if p.body == part.body) or 1
        rings = part.polygons(chord)
        plate = plate_polygon(rings)  # made and validated once: every cut below reads it
        pose = motion.pose(part.body)
        t = part.thickness_mm
        loads_local = []  # (local point, local force (n, 2), at joint)
        for local, f, at in body_point_loads.get(part.body, []):
            if at and at in revolutes and not any(at in _joints_of(h) for h in part.holes):
                continue
            loads_local.append((np.asarray(local, dtype=np.float64), _on_body_local(np.asarray(f) / share, pose), at))
        couples = [(np.asarray(c) / share, at) for c, at in body_couples.get(part.body, [])]
        holes = [h for h in part.holes if _joints_of(h) & carried]
        for h in holes:
            f = sum((lf for lp, lf, at in loads_local if at in _joints_of(h)), np.zeros((len(motion.inputs), 2)))
            push = sum((tooth_push.get(j, 0.0) for j in _joints_of(h)), np.zeros(1))
            mag = np.hypot(f[:, 0], f[:, 1]) + push / share
            if not np.any(mag > 0):
                continue
            i = int(np.argmax(mag))
            pin_d = h.pin_diameter_mm or h.diameter_mm
            bearing = np.asarray(models.bearing_stress(mag, pin_d, t), dtype=np.float64)
            result.findings.append(Finding(part.name, f"hole {h.joint} bearing", "hole", float(bearing[i]),
                                           material.compressive_MPa, i, f"{mag[i]:.1f} N at {h.joint}",
                                           "a thicker plate (process.thickness_mm) or a larger pin", bearing))
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
            result.findings.append(Finding(part.name, f"hole {h.joint} tear-out", "hole", float(tear[k]),
                                           material.shear_MPa, k,
                                           f"{mag[k]:.1f} N at {h.joint} (edge {e[k]:.2f} mm)",
                                           "more material round the hole (parts.boss_wall_mm / link_width_mm)",
                                           tear))
            # the net section across a pin-loaded hole, square to the load: Kt / area per load direction
            factor, kts = _net_section_factors(plate, h, t)
            if factor is None:
                continue
            per_pose = np.where(known, _edge_along(factor, unit, np.maximum), factor.max())
            net = mag * per_pose
            k = int(np.argmax(net))
            kt = float(_edge_along(kts, unit[k:k + 1], np.maximum)[0] if known[k] else kts[int(np.argmax(factor))])
            result.findings.append(Finding(part.name, f"net section at hole {h.joint} (Kt {kt:.2f})", "link",
                                           float(net[k]), material.tensile_MPa, k, f"{mag[k]:.1f} N at {h.joint}",
                                           "a wider link (parts.link_width_mm) or a thicker plate", net))
        # sections at and between every pair of holes: free body on one side of the cut
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
                        result.findings.append(finding)

    # -- gears -------------------------------------------------------------------------------------
    for pair in gear_pairs:
        if pair.coupling not in statics.gear_torques:
            continue
        _gear_findings(result, pair, statics.gear_torques[pair.coupling], mechanism, motion, parts, material)
    result.curves = {"inputs": np.asarray(motion.inputs)}
    for name, f in statics.joint_forces.items():
        result.curves[f"joint {name} (N)"] = np.hypot(f[:, 0], f[:, 1])
    return result


def _section_finding(part, sec, point, u, station, ha, hb, loads_local, couples, material, load_name):
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


def _joints_of(hole: Any) -> set[str]:
    """The joints a hole serves (a pin shared by coincident joints is named "A+B")."""
    return set(hole.joint.split("+"))


def _pressure_angle(pair: Any) -> float:
    """The pair's rack pressure angle (rad)."""
    spec = getattr(pair, "spec", None)
    return math.radians(float(getattr(spec, "pressure_angle_deg", 20.0)))


def _tooth_normal_force(pair: Any, torque_b: np.ndarray, motion: Motion) -> np.ndarray:
    """Tooth normal force (N) of a pair at every pose from the torque on gear b (pitch point on the line of
    centres, pressure angle from the pair)."""
    xa = motion.relative_angle(pair.body_a, pair.carrier)
    ratio = np.abs(np.asarray(pair.law(xa, 1), dtype=np.float64))
    r_b = pair.center_distance_mm / (1.0 + ratio)
    phi = _pressure_angle(pair)
    return np.abs(torque_b) / np.maximum(r_b, 1e-9) / math.cos(phi)


def _gear_findings(result, pair, torque_b, mechanism, motion, parts, material) -> None:
    """Lewis root bending and Hertz contact of one gear pair at every pose, under the statics' torque.

    At each pose the pitch point lies on the line of centres, ``r_a = a i / (1 + i)`` from axis a (``i`` the
    instantaneous ratio); the local radius of curvature of each pitch curve there makes the equivalent
    spur gear (``z_eq = 2 rho / m``) whose Lewis form factor the tooth gets, and the two radii (times
    sin phi) are the involute flanks' radii for Hertz. A concave stretch takes the rack's form factor
    and bears as a concave surface.
    """
    face = min((p.thickness_mm for p in parts if p.gear == pair.name), default=None)
    if face is None:
        return
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
    rho_a = _local_radius(pair.pitch_a, contact_a)
    rho_b = _local_radius(pair.pitch_b, contact_b)
    for gear, rho in (("a", rho_a), ("b", rho_b)):
        with np.errstate(divide="ignore", invalid="ignore"):
            teeth = np.where(np.isfinite(rho) & (rho > 0), 2.0 * rho / pair.module, np.inf)
        y = np.asarray(models.lewis_form_factor(teeth), dtype=np.float64)
        sigma = np.asarray(models.lewis_bending_stress(ft, pair.module, face, y), dtype=np.float64)
        i = int(np.argmax(sigma))
        body = pair.body_a if gear == "a" else pair.body_b
        name = next((p.name for p in parts if p.body == body and p.gear == pair.name), body)
        result.findings.append(Finding(name, f"gear {pair.name} tooth root (Lewis, Y {y[i]:.3f}, z_eq {teeth[i]:.1f})",
                                       "gear", float(sigma[i]), material.flexural_MPa, i,
                                       f"{ft[i]:.1f} N tangential", "a larger module (gears.module) or a thicker plate",
                                       sigma))
    fn = ft / math.cos(phi)
    flat = 1e9  # a straight pitch stretch: a flat flank for Hertz
    r1, r2 = models.involute_contact_radii(np.where(np.isfinite(rho_a), rho_a, flat),
                                           np.where(np.isfinite(rho_b), rho_b, flat), phi)
    hertz = np.asarray(models.hertz_line_contact_stress(fn, face, r1, r2, material.modulus_MPa, material.poisson,
                                                        material.modulus_MPa, material.poisson), dtype=np.float64)
    i = int(np.argmax(hertz))
    name = next((p.name for p in parts if p.gear == pair.name), pair.name)
    result.findings.append(Finding(name, f"gear {pair.name} tooth contact (Hertz)", "gear", float(hertz[i]),
                                   material.compressive_MPa, i, f"{fn[i]:.1f} N normal",
                                   "a larger module or a thicker plate", hertz))


def _local_radius(points: np.ndarray, at: np.ndarray) -> np.ndarray:
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
    nearest = np.argmin(np.sum((p[None, :, :] - at[:, None, :]) ** 2, axis=2), axis=1)
    return radius[nearest]
