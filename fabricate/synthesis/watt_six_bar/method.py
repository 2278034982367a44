"""The Watt-I six-bar finger's synthesis: curves and region (:mod:`.region`), force index K (:mod:`.statics`),
the choice (:mod:`.selection`), the mechanism, and the report's ``synthesis`` section with its checks: the
fingertip error at the positions through the generic solver, and K against an independent virtual-work
computation on that same mechanism."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import SynthesisError
from fabricate.hints import PadHint, PartHints
from fabricate.mechanism import Mechanism
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.watt_six_bar.burmester import distance_to_curve
from fabricate.synthesis.watt_six_bar.mechanism import build_mechanism, virtual_work_check
from fabricate.synthesis.watt_six_bar.refine import RefinedCandidates
from fabricate.synthesis.watt_six_bar.region import (
    FingerPositions,
    RegionInputs,
    SolutionRegion,
    coupler_motion,
    finger_positions,
    solution_region,
    stage_two_curves,
)
from fabricate.synthesis.watt_six_bar.selection import Choice, choose, refine_candidates, region_qualifies
from fabricate.synthesis.watt_six_bar.spec import WattSixBarSpec
from fabricate.synthesis.watt_six_bar.statics import JOINTS, SixBarBatch, assemble, force_index, joint_loads

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec
    from fabricate.synthesis.watt_six_bar.burmester import CubicCurve


def _reference_report(spec: WattSixBarSpec, finger: FingerPositions, inputs: RegionInputs) -> dict[str, Any]:
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


def _curve_d(finger: FingerPositions) -> CubicCurve:
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
    if spec.refine and not region_qualifies(spec, region):
        refined = refine_candidates(spec, region, finger, inputs, theta)
    choice = choose(spec, region, refined)

    mech = build_mechanism(name, finger, inputs.angles, choice.d, choice.e, choice.f, choice.d0)
    if mech.degrees_of_freedom() != 1:
        raise SynthesisError(f"six-bar has {mech.degrees_of_freedom()} degrees of freedom, expected 1")
    report = _report(spec, inputs, finger, region, refined, choice, mech, theta)

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.watt_six_bar import plots

        return plots.all_figures(spec, finger, region, refined, choice)

    data = {"region": region, "refined": refined, "choice": choice, "finger": finger, "inputs": inputs}
    parts = PartHints(tip_point="c", pads={"distal": PadHint("c", spec.tip_pad_radius_mm)})
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data=data, parts=parts)


def _report(spec: WattSixBarSpec, inputs: RegionInputs, finger: FingerPositions, region: SolutionRegion,
            refined: RefinedCandidates | None, choice: Choice, mech: Mechanism, theta: np.ndarray) -> dict[str, Any]:
    """The ``synthesis`` section: the choice, its checks through the generic solver, the region's counts."""
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

    report = {
        # "seed 004" is the Watt-I six-bar paper's number in the README's Templates table; the report's words
        # are kept as they were (builds stay byte-identical)
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
        "region": _region_report(spec, region),
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
    report["notes"] = _notes(spec, region, choice)
    if spec.reference:
        report["reference"] = _reference_report(spec, finger, inputs)
    return report


def _region_report(spec: WattSixBarSpec, region: SolutionRegion) -> dict[str, Any]:
    """The solution region's counts: points, defect-free, K within the limit, accepted, by branch pair."""
    one = region.stage_one
    return {
        "step_mm": spec.step_mm,
        "points": len(region),
        "points_without_circuit_defect": int(region.passes.sum()),
        "points_K_ok": int(np.sum(region.K <= spec.k_max)),
        "points_accepted": int(region.accepted.sum()),
        "points_clear_of_middle_link": int(np.sum(region.clearance >= spec.min_pin_to_middle_mm)),
        "branch_pairs": region.branch_pair_counts(),
        "branch_pairs_K_ok": region.branch_pair_counts(region.K <= spec.k_max),
        "curve_d_feasible_x_mm": {str(k): list(v) for k, v in one.feasible_ranges().items()},
    }


def _notes(spec: WattSixBarSpec, region: SolutionRegion, choice: Choice) -> list[str]:
    """What a reader of the report should know about where the choice came from."""
    notes = []
    if not region.passes.any():
        notes.append("every region point has a circuit defect (a loop must change assembly branch between "
                     "two positions), so the selection comes from the approximate refinement: it passes the "
                     f"positions within {spec.tip_tolerance_mm:g} mm at the fingertip but lies off the exact curves")
    if not choice.exact:
        notes.append("selected design is a refined candidate (see distance_to_curve_mm), seeded by region point "
                     f"{choice.region_index}")
    return notes


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
