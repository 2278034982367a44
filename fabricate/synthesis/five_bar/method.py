"""The five-bar NCG finger's synthesis: kinematic mapping, hinge curves, feasible domain, the chosen dyad and
its gear law, the solved mechanism, and the report's ``synthesis`` section."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import LockupError, SynthesisError
from fabricate.hints import PadHint, PartHints
from fabricate.mechanism import Mechanism, Motion
from fabricate.planar import rotation
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.five_bar import kinematic_mapping as km
from fabricate.synthesis.five_bar.domain import HingeDomain, hinge_domain, select_dyad
from fabricate.synthesis.five_bar.mechanism import DISTAL, LINK_AB, SelectedDyad, build_mechanism, pose_errors
from fabricate.synthesis.five_bar.spec import FiveBarSpec
from fabricate.synthesis.five_bar.targets import FingerTargets, finger_targets

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


@dataclass(frozen=True)
class FiveBarData:
    """Everything the plots and tests need (``SynthesisResult.data``)."""

    spec: FiveBarSpec
    targets: FingerTargets
    matrix: np.ndarray
    eigenvalues: np.ndarray
    eigenvectors: np.ndarray
    domain: HingeDomain
    dyad: SelectedDyad
    mechanism: Mechanism
    position_error: np.ndarray
    orientation_error: np.ndarray
    motion: Motion


def _floats(values: np.ndarray) -> list[float]:
    """Plain floats for JSON (adding 0.0 turns -0.0 into 0.0)."""
    return [float(v) + 0.0 for v in np.ravel(values)]


def _xy(v: np.ndarray) -> list[float]:
    return [float(v[0]), float(v[1])]


def _range(v: np.ndarray) -> list[float]:
    return [float(np.min(v)), float(np.max(v))]


def build_report(data: FiveBarData) -> dict[str, Any]:
    """JSON-ready ``synthesis`` section (lengths mm, angles deg)."""
    t, dyad, dom = data.targets, data.dyad, data.domain
    a = t.proximal_to_world(dyad.a_proximal)[0]
    b = t.distal_to_world(dyad.b_distal)[0]
    law = dyad.law
    samples = np.linspace(law.x[0], law.x[-1], 25)
    feasible = dom.feasible
    return {
        "method": "kinematic mapping + eigenvectors of M^T M, cubic-spline non-circular gear law",
        "poses": int(len(t.p)),
        "eigenvalues": _floats(data.eigenvalues),
        "kappa": float(dyad.kappa),
        "selection": {"rule": data.spec.select, "x_A_mm": data.spec.x_A_mm},
        "A_mm": _xy(a),
        "B_mm": _xy(b),
        "link_lengths_mm": {
            "OA": float(np.hypot(*(a - t.origin))), "OD": float(t.lengths[0]), "AD": float(np.hypot(*(a - t.d[0]))),
            "AB": float(np.hypot(*(b - a))), "BC": float(np.hypot(*(b - t.c[0]))), "DC": float(t.lengths[1]),
            "CP": float(t.lengths[2]), "BP": float(np.hypot(*(b - t.p[0]))),
        },
        "dyad_length_error_mm": float(dyad.length_error),
        "pose_error_mm": {"max": float(np.max(data.position_error)), "mean": float(np.mean(data.position_error)),
                          "per_pose": _floats(data.position_error)},
        "orientation_error_deg": {"max": float(np.degrees(np.max(np.abs(data.orientation_error)))),
                                  "mean": float(np.degrees(np.mean(np.abs(data.orientation_error)))),
                                  "per_pose": _floats(np.degrees(data.orientation_error))},
        "target_tip_mm": [_xy(p) for p in t.p],
        "gear_law": {
            "note": "x_a = ground minus arm O-A rotation, x_b = link A-B minus arm rotation; x_b = f(x_a)",
            "poses_x_a_deg": _floats(np.degrees(law.knots_a)),
            "poses_x_b_deg": _floats(np.degrees(law.knots_b)),
            "x_a_deg": _floats(np.degrees(samples)),
            "x_b_deg": _floats(np.degrees(law.law(samples))),
            "working_range_deg": _floats(np.degrees(law.working_range)),
        },
        "center_distance_mm": float(law.centre_distance),
        "transmission_ratio": _range(law.ratio),
        "pitch_radius_mm": {"sun_O": _range(law.r_a), "planet_A": _range(law.r_b)},
        "min_pitch_radius_of_curvature_mm": float(min(np.min(law.rho_a), np.min(law.rho_b))),
        "feasible_domain": {
            "curve_points": int(len(dom.status)),
            "feasible_points": int(np.sum(feasible)),
            "rejected": dom.rejected_counts(),
            "x_A_mm": _range(dom.a[feasible, 0]),
            "y_A_mm": _range(dom.a[feasible, 1]),
            "kappa": _range(dom.family.kappa[feasible]),
        },
    }


def synthesise(design: DesignSpec) -> SynthesisResult:
    """Synthesise the five-bar gear finger of a :class:`~fabricate.spec.DesignSpec`.

    Raises
    ------
    SynthesisError
        When the template's limits leave no feasible hinge (the message names the limit), or the
        selection rule's target lies outside the feasible domain.
    """
    spec: FiveBarSpec = design.method
    targets = finger_targets(spec)
    matrix = km.constraint_matrix(km.image_coordinates(targets.displacements))
    eigenvalues, eigenvectors = km.family_basis(matrix)
    basis4 = eigenvectors[:, :4]
    family = km.trace_family(basis4, spec.kappa_samples)

    def hinges(p: np.ndarray) -> np.ndarray:  # A and B at the first pose, (k, 4) mm
        centre, point = km.dyad_from_vector(p)
        return np.hstack([targets.origin + centre @ rotation(targets.angles[0, 0]).T,
                          targets.p[0] + point @ rotation(targets.angles[0, 2]).T])

    first = hinges(family.p)
    in_box = ((first[:, 0] >= spec.a_x_mm[0]) & (first[:, 0] <= spec.a_x_mm[1])
              & (first[:, 1] >= spec.a_y_mm[0]) & (first[:, 1] <= spec.a_y_mm[1]))
    family = km.refine_family(basis4, family, hinges, in_box, spec.curve_step_mm)
    domain = hinge_domain(spec, targets, family)
    dyad = select_dyad(spec, targets, domain, basis4, design.name)
    mech = build_mechanism(design.name, targets, dyad)
    sweep_poses = int(getattr(getattr(design, "checks", None), "sweep_poses", 360))
    try:
        position, orientation, _ = pose_errors(mech, targets)
        motion = mech.sweep(max(sweep_poses, 2))
    except LockupError as exc:
        raise SynthesisError(f"the selected dyad (A = {_xy(mech.body(LINK_AB).point('A'))} mm) gives a "
                             f"mechanism that cannot move through the poses: {exc}") from exc
    data = FiveBarData(spec=spec, targets=targets, matrix=matrix, eigenvalues=eigenvalues,
                       eigenvectors=eigenvectors, domain=domain, dyad=dyad, mechanism=mech,
                       position_error=position, orientation_error=orientation, motion=motion)

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.five_bar.plots import five_bar_figures

        return five_bar_figures(data)

    parts = PartHints(tip_point="P", pads={DISTAL: PadHint("P", spec.pad_radius_mm)})
    return SynthesisResult(mechanism=mech, report=build_report(data), figures=figures, data=data, parts=parts)
