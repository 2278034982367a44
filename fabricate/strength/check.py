"""The strength check: every part and pin at its design load, over the whole motion.

Loads (:func:`design_loads`) come from the template's ``[load]`` and the synthesis' springs; the joint
reactions, gear torques and driver efforts at every pose from :func:`~fabricate.strength.statics.solve_statics`.
Each part then gets the closed-form models of :mod:`fabricate.strength.models`, each with its governing
pose (:mod:`fabricate.strength.features`, one function per kind of feature):

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
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import GeometryError
from fabricate.mechanism import Mechanism, Motion, Revolute, Slider
from fabricate.parts.spring_rows import spring_failures
from fabricate.planar import rotation
from fabricate.strength.features import (
    FeatureLoads,
    Finding,
    gear_findings,
    part_findings,
    pin_findings,
    tooth_push_by_axis,
)
from fabricate.strength.statics import BodyTorque, DriverEffort, PointForce, Statics, solve_statics

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.hints import PartHints
    from fabricate.parts.partset import PartSet
    from fabricate.spec import DesignSpec
    from fabricate.strength.spec import LoadSpec


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
    spring_failures: list[str] = field(default_factory=list)  # springs over their wire's allowable

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
        return not self.spring_failures and all(f.safety_factor >= self.min_safety_factor for f in self.findings)

    def failures(self) -> list[str]:
        if self.reason is not None:
            return list(self.spring_failures)
        out = list(self.spring_failures)
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
    unit: np.ndarray = v[src] / norm[src][:, None]
    return unit


def _joint_between(mechanism: Mechanism, a: str, b: str) -> Revolute | None:
    for j in mechanism.joints:
        if isinstance(j, Revolute) and {j.body_a, j.body_b} == {a, b}:
            return j
    return None


def design_loads(design: DesignSpec, mechanism: Mechanism, motion: Motion, hints: PartHints) -> Loads:
    """The template's ``[load]`` and the synthesis' springs as loads over the motion."""
    load = design.load
    assert load is not None  # load_design reads [load] always (its defaults when the table is absent)
    forces: list[PointForce] = []
    torques: list[BodyTorque] = []
    efforts: list[DriverEffort] = []
    said: list[str] = []
    reaction = None
    actuated = bool(load.input_force_N or load.input_torque_Nmm)
    if load.tip_force_N > 0.0 or actuated:
        tip, words = _tip_load(load, mechanism, motion, hints, actuated)
        if actuated:
            reaction = tip
        else:
            forces.append(tip)
        said.append(words)
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
        for torque, words in _spring_torques(mechanism, motion, hints):
            torques.append(torque)
            said.append(words)
    if (load.input_force_N or load.input_torque_Nmm) and mechanism.drivers:
        effort, words = _actuator_effort(load, mechanism, motion)
        efforts.append(effort)
        said.append(words)
    return Loads(tuple(forces), tuple(torques), tuple(efforts), tuple(said), reaction)


def _tip_load(load: LoadSpec, mechanism: Mechanism, motion: Motion, hints: PartHints,
              actuated: bool) -> tuple[PointForce, str]:
    """The tip force, or with a known actuator effort the object's reaction at the tip (a unit direction per
    pose; the statics solve its magnitude), and its words."""
    point = load.tip_point or hints.tip_point
    if not point or point not in mechanism.point_names():
        raise GeometryError(f"strength: load.tip_point {point!r} is not a named point of the mechanism")
    owners = [b for b, pad in (hints.pads or {}).items() if pad.point == point]
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
        return (PointForce(body, local, against, name=f"object at {point}"),
                f"the object at {point} holding the actuator, {how}")
    return (PointForce(body, local, load.tip_force_N * against, name=f"tip force at {point}"),
            f"tip force {load.tip_force_N:g} N at {point}, {how}")


def _spring_torques(mechanism: Mechanism, motion: Motion,
                    hints: PartHints) -> list[tuple[BodyTorque, str]]:
    """The synthesis' return springs (a rate above 0 at a revolute joint) as torques, with their words."""
    out = []
    for spring in hints.springs:
        rate = spring.rate_Nmm_per_deg
        joint = next((j for j in mechanism.joints if j.name == spring.joint), None)
        if rate <= 0.0 or not isinstance(joint, Revolute):
            continue
        rel = np.degrees(motion.relative_angle(joint.body_b, joint.body_a))
        sense = 1.0 if rel[-1] >= rel[0] else -1.0
        deflection = spring.preload_deg + sense * (rel - rel[0])
        # a return spring resists the closing: the torque on body_b is against its relative turn
        out.append((BodyTorque(joint.body_b, joint.body_a, -sense * rate * np.maximum(deflection, 0.0),
                               joint=joint.name),
                    f"spring at {joint.name}, {rate:g} N·mm/° from {spring.preload_deg:g}° "
                    f"preload (up to {rate * float(np.max(deflection)):.0f} N·mm)"))
    return out


def _actuator_effort(load: LoadSpec, mechanism: Mechanism, motion: Motion) -> tuple[DriverEffort, str]:
    """The actuator's known force or torque on the first driver, pushing the way the motion goes."""
    n = len(motion.inputs)
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
    unit = "N" if driver.kind == "slide" else "N·mm"
    return DriverEffort(0, value * sign), f"actuator {value:g} {unit} on the input"


# -- the check ---------------------------------------------------------------------------------------

def solved_loads(loads: Loads, magnitude: np.ndarray) -> Loads:
    """``loads`` with the object's solved reaction made a known force (for the free bodies)."""
    r = loads.reaction
    assert r is not None  # called only for loads with a reaction
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
            joint = _joint_between(mechanism, d.body, d.reference)
            body_couples.setdefault(d.body, []).append((carried, joint.name if joint else ""))
            body_couples.setdefault(d.reference, []).append((-carried, joint.name if joint else ""))
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


def run_strength(design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion,
                 gear_pairs: list[GearPair],
                 hints: PartHints) -> StrengthResult:
    """Every part and pin at the design load over ``motion``; see the module docstring."""
    required = float(design.checks.min_safety_factor)
    material = design.process.part_material()
    pin_material = design.process.pin_material_spec()
    result = StrengthResult([], None, required, np.asarray(motion.inputs))
    # each torsion spring's wire against its allowable (fabricate/parts/springs.py): no part material needed
    result.spring_failures = [f"strength: {text}" for text in spring_failures(partset.springs)]
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
    if any(sp.rate_Nmm_per_deg > 0.0 for sp in hints.springs):
        # the springs are specified and their wire checked (report.json's springs); here their torque loads
        # the printed parts
        result.notes.append("the torsion springs (report.json's springs, bom.csv) are sized and their wire "
                            "stress checked against its allowable; their torque loads the parts here")
    statics = solve_statics(mechanism, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    result.statics = statics
    if loads.reaction is not None:
        solved = statics.reaction_N
        assert solved is not None  # solve_statics solves the reaction it is given
        loads = solved_loads(loads, solved)
        result.loads = loads.described
    chord = partset.chord_tolerance_mm
    parts = [p for p in partset.parts if p.role != "spacer"]
    revolutes = {j.name: j for j in mechanism.joints if isinstance(j, Revolute)}
    load_name = "; ".join(loads.described) or "no load"

    body_point_loads, body_couples = body_loads(mechanism, motion, statics, loads)
    loaded = FeatureLoads(motion, statics, revolutes, body_point_loads, body_couples,
                          tooth_push_by_axis(gear_pairs, statics, motion), load_name)
    for pin in partset.pins:
        result.findings += pin_findings(pin, parts, loaded, pin_material)

    # holes that carry a mechanism joint (revolute, or a slider's guide pin); "A+B" is one pin for two
    carried = set(revolutes) | {j.name for j in mechanism.joints if isinstance(j, Slider)}
    for part in parts:
        result.findings += part_findings(part, parts, carried, chord, loaded, material)

    # -- gears -------------------------------------------------------------------------------------
    for pair in gear_pairs:
        if pair.coupling not in statics.gear_torques:
            continue
        result.findings += gear_findings(pair, statics.gear_torques[pair.coupling], mechanism, motion, parts,
                                         material)
    result.curves = {"inputs": np.asarray(motion.inputs)}
    for name, f in statics.joint_forces.items():
        result.curves[f"joint {name} (N)"] = np.hypot(f[:, 0], f[:, 1])
    return result
