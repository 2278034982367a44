"""Watt-I six-bar finger by solution-region synthesis (seed 004, kind ``watt_six_bar``).

Template tables read here (see ``templates/finger_watt_six_bar.toml``):

``[finger]``     phalanx_lengths_mm (L1, L2, L3), theta1_deg / theta2_deg / theta3_deg (absolute angles
                 of a0-a, a-b, b-c from +x at the four positions), tip_pad_radius_mm.
``[boxes]``      d0, d, e, f: ``[x_min, x_max, y_min, y_max]`` at position 1, a0 at the origin (Table 3).
``[region]``     step_mm (x sampling of both curves), k_max, force_N, statics_samples, tip_tolerance_mm,
                 min_pin_to_middle_mm (pins d and e cross the middle link's layer: smallest distance
                 from its centreline a-b over the motion; 0 switches the check off).
``[selection]``  rule ("nearest" to ``target = [d_x, d0_x]`` or "least_k"), optional branches = [m, n],
                 refine (when no exact region point qualifies, look for approximate defect-free
                 mechanisms from the region points, see :mod:`.refine`), refine_seeds.
``[reference]``  optional published design (d, e, f, d0) to compare with; report only.

The pipeline: curves and region (:mod:`.region`), force index K (:mod:`.statics`),
selection, the six-bar :class:`~fabricate.mechanism.Mechanism` (bodies ground, proximal, middle, distal,
coupler, rocker; one angle driver proximal vs ground in degrees), and the checks reported in
``report["synthesis"]``: fingertip error at the positions through the generic solver, and K against
an independent virtual-work computation on that same mechanism.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.bounds import (
    MAX_FORCE_N,
    MAX_LENGTH_MM,
    MAX_REFINE_SEEDS,
    MAX_REGION_SAMPLES,
    MAX_STATICS_SAMPLES,
)
from fabricate.errors import SpecError, SynthesisError
from fabricate.mechanism import Body, Driver, Mechanism, Revolute
from fabricate.spec import DesignSpec
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.watt_six_bar.burmester import distance_to_curve
from fabricate.synthesis.watt_six_bar.refine import RefinedCandidates, merge, refine_region
from fabricate.synthesis.watt_six_bar.region import (
    FingerPositions,
    RegionInputs,
    SolutionRegion,
    coupler_motion,
    finger_positions,
    solution_region,
    stage_two_curves,
)
from fabricate.synthesis.watt_six_bar.statics import (
    JOINTS,
    SixBarBatch,
    assemble,
    force_index,
    joint_loads,
    lagrange_joint_forces,
)
from fabricate.table import Table

BOX_NAMES = ("d0", "d", "e", "f")


@dataclass(frozen=True)
class WattSixBarSpec:
    """Validated inputs of the Watt-I six-bar synthesis (mm, degrees as in the template)."""

    phalanx_lengths_mm: tuple[float, float, float]
    angles_deg: tuple[tuple[float, ...], ...]  # (3, 4): theta1, theta2, theta3 at positions 1..4
    boxes: tuple[tuple[str, tuple[float, float, float, float]], ...]
    tip_pad_radius_mm: float = 5.0
    step_mm: float = 0.2
    k_max: float = 20.0
    force_N: float = 1.0
    statics_samples: int = 41
    tip_tolerance_mm: float = 0.5
    min_pin_to_middle_mm: float = 0.0
    rule: str = "nearest"
    target: tuple[float, float] | None = None
    branches: tuple[int, int] | None = None
    refine: bool = True
    refine_seeds: int = 600
    reference: tuple[tuple[str, tuple[float, float]], ...] = ()

    def box(self, name: str) -> np.ndarray:
        return np.asarray(dict(self.boxes)[name], dtype=np.float64)

    def region_inputs(self) -> RegionInputs:
        return RegionInputs(lengths=np.asarray(self.phalanx_lengths_mm, dtype=np.float64),
                            angles=np.radians(np.asarray(self.angles_deg, dtype=np.float64)),
                            box_d=self.box("d"), box_e=self.box("e"), box_f=self.box("f"),
                            box_d0=self.box("d0"), step=self.step_mm, force=self.force_N,
                            statics_samples=self.statics_samples, tip_tolerance=self.tip_tolerance_mm,
                            min_clearance=self.min_pin_to_middle_mm)


def parse_spec(root: Table) -> WattSixBarSpec:
    """Read ``[finger]``, ``[boxes]``, ``[region]``, ``[selection]`` and the optional ``[reference]``."""
    finger = root.table("finger")
    lengths = finger.array("phalanx_lengths_mm", shape=(3,), positive=True, max=MAX_LENGTH_MM)
    angles = [finger.array(f"theta{k}_deg", shape=(4,), min=-360.0, max=360.0) for k in (1, 2, 3)]
    pad = finger.number("tip_pad_radius_mm", 5.0, positive=True, max=50.0)
    finger.finish()
    steps = np.diff(angles[0])
    if not (np.all(steps > 0) or np.all(steps < 0)):
        raise SpecError(finger.field("theta1_deg"), "the input angle must change monotonically over the "
                                                    "positions (it drives the finger)")
    if np.max(np.abs(angles[0][-1] - angles[0][0])) >= 180.0:
        raise SpecError(finger.field("theta1_deg"), "the input must turn less than 180 degrees")
    # the distal phalanx must move relative to the proximal one between every two positions, or the
    # dyad condition is empty (every point would be a "solution")
    distal_rel = np.diff(angles[2] - angles[0])
    if np.any(np.abs(distal_rel) < 0.1):
        raise SpecError(finger.field("theta3_deg"), "the distal phalanx must turn relative to the proximal "
                                                    "one between consecutive positions")

    boxes_t = root.table("boxes")
    boxes = []
    for name in BOX_NAMES:
        box = boxes_t.array(name, shape=(4,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
        if not (box[0] < box[1] and box[2] < box[3]):
            raise SpecError(boxes_t.field(name), "expected [x_min, x_max, y_min, y_max] with min < max")
        boxes.append((name, tuple(float(v) for v in box)))
    boxes_t.finish()

    region = root.table("region", {})
    step = region.number("step_mm", 0.2, positive=True, max=10.0)
    k_max = region.number("k_max", 20.0, positive=True, max=1e6)
    force = region.number("force_N", 1.0, positive=True, max=MAX_FORCE_N)
    samples = region.integer("statics_samples", 41, min=3, max=MAX_STATICS_SAMPLES)
    tol = region.number("tip_tolerance_mm", 0.5, positive=True, max=50.0)
    clearance = region.number("min_pin_to_middle_mm", 0.0, min=0.0, max=100.0)
    region.finish()
    box_d = dict(boxes)["d"]
    box_d0 = dict(boxes)["d0"]
    for name, box in (("d", box_d), ("d0", box_d0)):
        if (box[1] - box[0]) / step > MAX_REGION_SAMPLES:
            raise SpecError(region.field("step_mm"),
                            f"step too fine for the {name} box (over {MAX_REGION_SAMPLES} samples)")

    sel = root.table("selection", {})
    rule = sel.string("rule", "nearest", choices=("nearest", "least_k"))
    target = None
    if rule == "nearest":
        t = sel.array("target", shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
        target = (float(t[0]), float(t[1]))
    elif sel.has("target"):
        sel.array("target", shape=(2,))
    branches = None
    if sel.has("branches"):
        b = sel.array("branches", shape=(2,), min=1, max=3)
        if np.any(b != np.round(b)):
            raise SpecError(sel.field("branches"), "expected two whole numbers 1..3")
        branches = (int(b[0]), int(b[1]))
    refine = sel.boolean("refine", True)
    seeds = sel.integer("refine_seeds", 600, min=1, max=MAX_REFINE_SEEDS)
    sel.finish()

    reference: list[tuple[str, tuple[float, float]]] = []
    if root.has("reference"):
        ref = root.table("reference")
        for name in ("d", "e", "f", "d0"):
            p = ref.array(name, shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
            reference.append((name, (float(p[0]), float(p[1]))))
        ref.string("note", "")
        ref.finish()

    return WattSixBarSpec(
        phalanx_lengths_mm=tuple(float(v) for v in lengths),
        angles_deg=tuple(tuple(float(v) for v in row) for row in angles),
        boxes=tuple(boxes), tip_pad_radius_mm=pad, step_mm=step, k_max=k_max, force_N=force,
        statics_samples=samples, tip_tolerance_mm=tol, min_pin_to_middle_mm=clearance, rule=rule, target=target,
        branches=branches,
        refine=refine, refine_seeds=seeds, reference=tuple(reference))


# -- selection -------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Choice:
    """The selected design: joints at position 1 (mm), where it came from and its figures of merit."""

    d: np.ndarray
    e: np.ndarray
    f: np.ndarray
    d0: np.ndarray
    K: float
    clearance: float
    branch_pair: tuple[int, int]
    exact: bool  # a region point (on the curves) rather than a refined candidate
    region_index: int  # the region point, or the refinement's seed


def _candidate_pool(region: SolutionRegion, refined: RefinedCandidates | None):
    """Accepted region points and refined candidates as parallel arrays (+ whether exact, source index)."""
    idx = np.flatnonzero(region.accepted)
    cols = [region.d[idx], region.e[idx], region.f[idx], region.d0[idx], region.K[idx], region.clearance[idx],
            np.ones(len(idx), bool), idx]
    if refined is not None:
        r = np.flatnonzero(refined.accepted)
        extra = [refined.d[r], refined.e[r], refined.f[r], refined.d0[r], refined.K[r], refined.clearance[r],
                 np.zeros(len(r), bool), refined.seed[r]]
        cols = [np.concatenate([a, b]) for a, b in zip(cols, extra, strict=True)]
    return cols


def choose(spec: WattSixBarSpec, region: SolutionRegion, refined: RefinedCandidates | None) -> Choice:
    """Apply the template's rule to the accepted region points and refined candidates."""
    d, e, f, d0, k, clearance, exact, source = _candidate_pool(region, refined)
    mask = np.ones(len(d), bool)
    if spec.branches is not None:
        m, n = spec.branches
        mask &= (region.branch_d[source] == m) & (region.branch_d0[source] == n)
    # exact region points first: refined candidates only stand in when no region point qualifies
    if np.any(mask & exact):
        mask &= exact
    pick = np.flatnonzero(mask)
    if not len(pick):
        k_ok = region.K <= spec.k_max
        clear = region.clearance >= spec.min_pin_to_middle_mm
        raise SynthesisError(
            f"no six-bar passes the {len(spec.angles_deg[0])} positions within {spec.tip_tolerance_mm:g} mm "
            f"with K <= {spec.k_max:g} and pins {spec.min_pin_to_middle_mm:g} mm clear of the middle link "
            f"(region: {len(region)} points; without a circuit defect {int(region.passes.sum())}, "
            f"K ok {int(k_ok.sum())}, clear {int(clear.sum())}, defect-free and K ok "
            f"{int((region.passes & k_ok).sum())}; refined candidates accepted "
            f"{0 if refined is None else int(refined.accepted.sum())})")
    if spec.rule == "least_k":
        order = np.lexsort((~exact[pick], k[pick]))
    else:
        dist = np.round(np.hypot(d[pick, 0] - spec.target[0], d0[pick, 0] - spec.target[1]), 6)
        order = np.lexsort((k[pick], ~exact[pick], dist))
    j = int(pick[order[0]])
    src = int(source[j])
    return Choice(d=d[j], e=e[j], f=f[j], d0=d0[j], K=float(k[j]), clearance=float(clearance[j]),
                  branch_pair=(int(region.branch_d[src]), int(region.branch_d0[src])),
                  exact=bool(exact[j]), region_index=src)


# -- the mechanism ---------------------------------------------------------------------------------

def _frame(origin: np.ndarray, angle: float, points: dict[str, np.ndarray]) -> dict[str, tuple[float, float]]:
    """World points at position 1 -> coordinates in a body frame at ``origin`` turned by ``angle``."""
    c, s = np.cos(angle), np.sin(angle)
    out = {}
    for name, p in points.items():
        v = np.asarray(p, dtype=np.float64) - origin
        out[name] = (float(c * v[0] + s * v[1]), float(-s * v[0] + c * v[1]))
    return out


def build_mechanism(name: str, finger: FingerPositions, angles: np.ndarray, d: np.ndarray, e: np.ndarray,
                    f: np.ndarray, d0: np.ndarray) -> Mechanism:
    """The Watt-I six-bar at position 1 as a generic :class:`Mechanism` (input theta1 in degrees)."""
    a, b, c = finger.a[0], finger.b[0], finger.c[0]
    a0 = np.zeros(2)
    th1, th2, th3 = angles[:, 0]
    de = float(np.arctan2(*(e - d)[::-1]))
    d0f = float(np.arctan2(*(f - d0)[::-1]))
    frames = {
        "proximal": (a0, th1, {"a0": a0, "a": a, "d": d}),
        "middle": (a, th2, {"a": a, "b": b}),
        "distal": (b, th3, {"b": b, "c": c, "e": e}),
        "coupler": (d, de, {"d": d, "e": e, "f": f}),
        "rocker": (d0, d0f, {"d0": d0, "f": f}),
    }
    bodies = [Body("ground", {"a0": (0.0, 0.0), "d0": (float(d0[0]), float(d0[1]))})]
    assembly = {}
    for body, (origin, angle, pts) in frames.items():
        bodies.append(Body(body, _frame(origin, angle, pts)))
        assembly[body] = (float(origin[0]), float(origin[1]), float(angle))
    joints = (Revolute("a0", "ground", "proximal"), Revolute("a", "proximal", "middle"),
              Revolute("b", "middle", "distal"), Revolute("d", "proximal", "coupler"),
              Revolute("e", "coupler", "distal"), Revolute("f", "coupler", "rocker"),
              Revolute("d0", "rocker", "ground"))
    return Mechanism(name=name, bodies=tuple(bodies), ground="ground", joints=joints, gears=(),
                     drivers=(Driver("angle", "proximal", "ground"),),
                     input_range=(float(np.degrees(angles[0, 0])), float(np.degrees(angles[0, -1]))),
                     input_unit="deg", assembly=assembly)


def _load_on_distal(mech: Mechanism, poses: dict[str, np.ndarray], force: float):
    """Midpoint of e-c and the force normal to e->c (turned +90 deg), world, from the distal pose."""
    from fabricate.planar import transform_points

    body = mech.body("distal")
    e = transform_points(poses["distal"], body.point("e"))
    c = transform_points(poses["distal"], body.point("c"))
    ec = c - e
    n = np.array([-ec[1], ec[0]]) / np.hypot(*ec)
    return 0.5 * (e + c), force * n


def virtual_work_check(mech: Mechanism, theta_deg: np.ndarray, force: float) -> dict[str, float]:
    """K and the input torque by the generic solver + constraint multipliers + virtual power."""
    from fabricate.synthesis.watt_six_bar.statics import virtual_work_torque

    motion = mech.sweep(theta_deg)
    k_max, torques, power_torques = 0.0, [], []
    local_mid = 0.5 * (mech.body("distal").point("e") + mech.body("distal").point("c"))
    for i in range(len(theta_deg)):
        poses = motion.poses_at(i)
        point, load = _load_on_distal(mech, poses, force)
        forces, torque = lagrange_joint_forces(mech, poses, point, load)
        k_max = max(k_max, max(forces[j] for j in JOINTS) / force)
        torques.append(torque)
        power_torques.append(virtual_work_torque(mech, motion, local_mid, "distal",
                                                 lambda p: _load_on_distal(mech, p, force), i))
    torques = np.asarray(torques)
    power = np.asarray(power_torques)
    return {"K": float(k_max), "torque_Nmm": torques, "torque_virtual_power_Nmm": power}


# -- synthesis -------------------------------------------------------------------------------------

def _reference_report(spec: WattSixBarSpec, finger: FingerPositions, inputs: RegionInputs) -> dict:
    """How a published design (template ``[reference]``) fits these curves and positions."""
    ref = {k: np.asarray(v) for k, v in spec.reference}
    d, e, f, d0 = ref["d"], ref["e"], ref["f"], ref["d0"]
    dd = finger.proximal.apply(d)
    ee = finger.distal.apply(e)
    ff = coupler_motion(finger, d, e).apply(f)
    len_de = np.hypot(*(dd - ee).T)
    len_d0f = np.hypot(*(ff - d0).T)
    curve_d0, curve_f = stage_two_curves(finger, d, e)
    one_d = distance_to_curve(_curve_d(finger), d)[0]
    batch = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], d[None], e[None], f[None], d0[None],
                        float(inputs.angles[0, 0]))
    theta = np.linspace(inputs.angles[0, 0], inputs.angles[0, -1], inputs.statics_samples)
    from fabricate.synthesis.watt_six_bar.statics import fingertip_errors

    tip = fingertip_errors(batch, inputs.angles[0], finger.c)[0]
    return {
        "joints": {k: [float(v[0]), float(v[1])] for k, v in ref.items()},
        "dyad_length_residual_mm": {"de": float(np.ptp(len_de)), "d0f": float(np.ptp(len_d0f))},
        "distance_to_curve_mm": {"d": float(one_d), "d0": float(distance_to_curve(curve_d0, d0)[0]),
                                 "f": float(distance_to_curve(curve_f, f)[0])},
        "tip_error_mm": {"max": float(np.nanmax(tip)), "mean": float(np.nanmean(tip))},
        "K": float(force_index(batch, theta, inputs.force)[0]),
    }


def _curve_d(finger: FingerPositions):
    from fabricate.synthesis.watt_six_bar.burmester import dyad_curve

    return dyad_curve(finger.proximal, finger.distal)


def synthesise(design: DesignSpec) -> SynthesisResult:
    """Region, K, selection and the six-bar :class:`Mechanism` with its report and figures."""
    spec: WattSixBarSpec = design.method
    return synthesise_spec(spec, design.name)


def synthesise_spec(spec: WattSixBarSpec, name: str = "finger_watt_six_bar") -> SynthesisResult:
    """:func:`synthesise` on the kind's own spec (no generic tables needed; for tests and benchmarks)."""
    inputs = spec.region_inputs()
    finger = finger_positions(inputs.lengths, inputs.angles)
    region = solution_region(inputs, spec.k_max)
    theta = np.linspace(inputs.angles[0, 0], inputs.angles[0, -1], inputs.statics_samples)
    refined = None
    if spec.refine and not _region_qualifies(spec, region):
        refined = _refine(spec, region, finger, inputs, theta)
    choice = choose(spec, region, refined)

    mech = build_mechanism(name, finger, inputs.angles, choice.d, choice.e, choice.f, choice.d0)
    if mech.degrees_of_freedom() != 1:
        raise SynthesisError(f"six-bar has {mech.degrees_of_freedom()} degrees of freedom, expected 1")
    # fingertip through the generic solver: a dense sweep with the positions in it
    dense = np.unique(np.concatenate([np.degrees(theta), np.degrees(inputs.angles[0])]))
    dense = dense[::-1] if inputs.angles[0, -1] < inputs.angles[0, 0] else dense
    motion = mech.sweep(dense)
    at = [int(np.argmin(np.abs(dense - np.degrees(t)))) for t in inputs.angles[0]]
    tip = np.hypot(*(motion.point("c")[at] - finger.c).T)

    batch = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], choice.d[None], choice.e[None],
                        choice.f[None], choice.d0[None], float(inputs.angles[0, 0]))
    loads = joint_loads(assemble(batch, theta), inputs.force)
    check = virtual_work_check(mech, np.degrees(theta), inputs.force)
    torque = loads.torque[0]

    one = region.stage_one
    report = {
        "method": "generalized Burmester curves, solution region, force index K (seed 004)",
        "K": choice.K,
        "K_limit": spec.k_max,
        "K_virtual_work": check["K"],
        "K_relative_difference": abs(check["K"] - choice.K) / choice.K,
        "torque_Nmm": {"min": float(torque.min()), "max": float(torque.max())},
        "torque_virtual_power_max_difference_Nmm": float(np.max(np.abs(check["torque_virtual_power_Nmm"]
                                                                      - torque))),
        "joint_forces_max_N": {j: float(loads.forces[j].max()) for j in JOINTS},
        "pose_error_mm": {"max": float(tip.max()), "mean": float(tip.mean())},
        "pin_to_middle_link_mm": _clearance_of(finger, choice, theta),
        "pin_to_middle_link_limit_mm": spec.min_pin_to_middle_mm,
        "region": {
            "step_mm": spec.step_mm,
            "points": len(region),
            "points_without_circuit_defect": int(region.passes.sum()),
            "points_K_ok": int(np.sum(region.K <= spec.k_max)),
            "points_accepted": int(region.accepted.sum()),
            "points_clear_of_middle_link": int(np.sum(region.clearance >= spec.min_pin_to_middle_mm)),
            "branch_pairs": region.branch_pair_counts(),
            "branch_pairs_K_ok": region.branch_pair_counts(region.K <= spec.k_max),
            "curve_d_feasible_x_mm": {str(k): list(v) for k, v in one.feasible_ranges().items()},
        },
        "refined": None if refined is None else {
            "candidates": len(refined), "accepted": int(refined.accepted.sum()),
        },
        "selection": {"rule": spec.rule, "target_dx_d0x_mm": None if spec.target is None else list(spec.target),
                      "exact_region_point": choice.exact},
        "selected": {k: [float(v[0]), float(v[1])] for k, v in
                     (("d", choice.d), ("e", choice.e), ("f", choice.f), ("d0", choice.d0))},
        "branch_pair": list(choice.branch_pair),
        "distance_to_curve_mm": _selected_distances(finger, choice),
        "link_lengths_mm": {
            "a0a": float(inputs.lengths[0]), "ab": float(inputs.lengths[1]), "bc": float(inputs.lengths[2]),
            "a0d": float(np.hypot(*choice.d)), "ad": float(np.hypot(*(choice.d - finger.a[0]))),
            "de": float(np.hypot(*(choice.e - choice.d))), "df": float(np.hypot(*(choice.f - choice.d))),
            "ef": float(np.hypot(*(choice.f - choice.e))), "d0f": float(np.hypot(*(choice.f - choice.d0))),
            "be": float(np.hypot(*(choice.e - finger.b[0]))), "ce": float(np.hypot(*(choice.e - finger.c[0]))),
        },
        "degrees_of_freedom": mech.degrees_of_freedom(),
    }
    notes = []
    if not region.passes.any():
        notes.append("every region point has a circuit defect (a loop must change assembly branch between "
                     "two positions), so the selection comes from the approximate refinement: it passes the "
                     f"positions within {spec.tip_tolerance_mm:g} mm at the fingertip but lies off the exact curves")
    if not choice.exact:
        notes.append("selected design is a refined candidate (see distance_to_curve_mm), seeded by region point "
                     f"{choice.region_index}")
    report["notes"] = notes
    if spec.reference:
        report["reference"] = _reference_report(spec, finger, inputs)

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.watt_six_bar import plots

        return plots.all_figures(spec, finger, region, refined, choice)

    data = {"region": region, "refined": refined, "choice": choice, "finger": finger, "inputs": inputs}
    parts = {"pads": {"distal": {"point": "c", "radius_mm": spec.tip_pad_radius_mm}}, "tip_point": "c"}
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data=data, parts=parts)


def _region_qualifies(spec: WattSixBarSpec, region: SolutionRegion) -> bool:
    """Whether an exact region point can be selected (then no refinement is needed)."""
    mask = region.accepted
    if spec.branches is not None:
        mask = mask & (region.branch_d == spec.branches[0]) & (region.branch_d0 == spec.branches[1])
    return bool(np.any(mask))


def _clearance_of(finger: FingerPositions, choice: Choice, theta: np.ndarray) -> float:
    """Smallest distance of d and e from the middle link over the motion (mm) of the chosen design."""
    from fabricate.synthesis.watt_six_bar.statics import middle_link_clearance

    batch = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], choice.d[None], choice.e[None], choice.f[None],
                        choice.d0[None], float(theta[0]))
    return float(middle_link_clearance(batch, theta)[0])


def _selected_distances(finger: FingerPositions, choice: Choice) -> dict[str, float]:
    """Distance of the selected joints to C_d and (for its own d, e) to C_d0 and C_f; 0 for region points."""
    curve_d0, curve_f = stage_two_curves(finger, choice.d, choice.e)
    return {"d": float(distance_to_curve(_curve_d(finger), choice.d)[0]),
            "d0": float(distance_to_curve(curve_d0, choice.d0)[0]),
            "f": float(distance_to_curve(curve_f, choice.f)[0])}


def _refine(spec: WattSixBarSpec, region: SolutionRegion, finger: FingerPositions, inputs: RegionInputs,
            theta: np.ndarray) -> RefinedCandidates | None:
    """Seeds: region points that assemble over the motion, nearest the target (or lowest K) first."""
    usable = np.flatnonzero(np.isfinite(region.K) & ~region.passes)
    if spec.rule == "nearest":
        key = np.hypot(region.d[usable, 0] - spec.target[0], region.d0[usable, 0] - spec.target[1])
    else:
        key = region.K[usable]
    # half the seeds nearest the choice, half spread evenly over the rest: a run often lands far from
    # its seed (the defect-free mechanisms lie off the exact curves), so coverage matters as much
    order = usable[np.argsort(key, kind="stable")]
    near = order[:spec.refine_seeds // 2]
    rest = order[spec.refine_seeds // 2:]
    spread = rest[np.unique(np.linspace(0, len(rest) - 1, spec.refine_seeds - len(near)).astype(int))] \
        if len(rest) else rest
    seeds_idx = np.sort(np.concatenate([near, spread]))
    if not len(seeds_idx):
        return None
    seeds = np.concatenate([region.d[seeds_idx], region.e[seeds_idx], region.f[seeds_idx],
                            region.d0[seeds_idx]], axis=1)
    lower = np.array([spec.box(n)[[0, 2]] for n in ("d", "e", "f", "d0")]).ravel()
    upper = np.array([spec.box(n)[[1, 3]] for n in ("d", "e", "f", "d0")]).ravel()
    template = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], region.d[:0], region.e[:0], region.f[:0],
                           region.d0[:0], float(inputs.angles[0, 0]))
    args = (template, inputs.angles[0], finger.c, lower, upper, theta, inputs.force, inputs.tip_tolerance,
            spec.k_max, spec.min_pin_to_middle_mm)
    first = refine_region(seeds, seeds_idx, *args, penalise_clearance=False)
    fits = np.flatnonzero((first.tip_error <= inputs.tip_tolerance) & (first.K <= spec.k_max))
    if not len(fits) or (spec.rule != "nearest" and spec.min_pin_to_middle_mm <= 0.0):
        return first
    # second pass: slide the candidates that fit along their (approximate) family towards the target
    # (d_x, d0_x), the other coordinates only loosely held, now also pushed clear of the middle link
    ok = fits
    start = np.concatenate([first.d[ok], first.e[ok], first.f[ok], first.d0[ok]], axis=1)
    anchor = start.copy()
    pull = np.full(8, 0.002)
    if spec.rule == "nearest":
        anchor[:, 0], anchor[:, 6] = spec.target
        pull[[0, 6]] = 0.05
    second = refine_region(start, first.seed[ok], *args, iterations=100, pull=pull, anchor=anchor)
    return merge(first, second)
