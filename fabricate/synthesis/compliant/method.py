"""The compliant gripper's synthesis: the grasp of the paper's procedure, the grasp force against stroke (Fig
3), the certified optimum over the Table 1 grid, the closing motion, the mechanism, the report's ``synthesis``
section and the parts hints (springs, rods, the drive shared by the fingers)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import SynthesisError
from fabricate.hints import PadHint, PartHints, PurchasedItem, SpringHint
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.compliant.closing import closing_motion
from fabricate.synthesis.compliant.grid_search import OptimumResult, optimise
from fabricate.synthesis.compliant.mechanism import build_mechanism
from fabricate.synthesis.compliant.model import (
    ContactPath,
    Grasp,
    GripperGeometry,
    Springs,
    contact_path,
    finger_state,
    grasp_force_curve,
    solve_grasp,
    spring_torques,
)
from fabricate.synthesis.compliant.spec import CompliantSpec

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec

#: Drive parts shared by all fingers (paper Fig 1): two lead-screw steppers move the tip and root
#: drive plates along two guide posts.
DRIVE_PARTS = (
    PurchasedItem("stepper motor with lead screw", 2, "tip drive (1) and root drive (2), Fig 1"),
    PurchasedItem("guide post", 2, "joins the motor plate and the finger-base plate (4)"),
    PurchasedItem("linear bearing", 4, "each guide post through both drive plates (5)"),
    PurchasedItem("lead-screw nut", 2, "one per drive plate (8)"),
    PurchasedItem("lead-screw support bearing", 2, "in the finger-base plate (12)"),
)


def paper_point(spec: CompliantSpec) -> tuple[ContactPath, Grasp]:
    """Grasp of the template's own parameters (the paper's optimum in the shipped template)."""
    path = contact_path(spec.geometry, spec.load.radius, spec.load.mu, n=max(spec.path_samples, 721),
                        pad_arc=spec.pad_arc)
    grasp = solve_grasp(path, spec.springs, spec.load)
    if grasp is None:
        raise SynthesisError("compliant_gripper: the hover force never reaches F_n2 = mg/(3 mu s) on the "
                             "physical branch (finger closing on the can, rod pushing)")
    return path, grasp


def _optimum_report(spec: CompliantSpec, result: OptimumResult) -> dict[str, Any]:
    g = spec.geometry
    geom = GripperGeometry(g.a1, g.a2, g.a3, g.b, result.c, g.d, g.l1, g.l2, g.r, result.alpha)
    springs = Springs(result.k1, result.k2, result.phi01, result.phi02)
    path = contact_path(geom, spec.load.radius, spec.load.mu, n=1441, pad_arc=spec.pad_arc)
    exact = solve_grasp(path, springs, spec.load)
    return {
        "alpha_rad": result.alpha, "c_mm": result.c, "k1": result.k1, "k2": result.k2,
        "phi01_rad": result.phi01, "phi02_rad": result.phi02,
        "delta_N_N": exact.delta_n if exact is not None else result.delta_n,
        "F_n1_N": exact.fn_static if exact is not None else None,
        "stroke_mm": exact.stroke if exact is not None else None,
        "grid_delta_N_N": result.delta_n,
        "certificate": {
            "grid_points": result.grid_points, "points_enumerated": result.points_evaluated,
            "paths": result.paths, "paths_searched": result.paths_searched,
            "intervals": result.intervals, "intervals_searched": result.intervals_searched,
            "points_verified": result.points_verified, "lower_bound_N": result.lower_bound,
            "pruned_bound_N": result.pruned_bound,
            "path_samples": spec.path_samples, "min_hinge_deg": float(np.degrees(spec.min_hinge)),
            "method": "exact lower bound of Delta N per (alpha, c, path interval); intervals below the "
                      "incumbent searched in bound order, every grid point crossing there valued exactly "
                      "(phi02 ranges from the running minimum of the hover threshold); the rest is "
                      "bounded by pruned_bound_N >= the optimum"},
    }


def synthesise(design: DesignSpec) -> SynthesisResult:
    """Grasp, Fig-3 curve, optimum, closing motion, mechanism and parts hints."""
    spec: CompliantSpec = design.method
    path, grasp = paper_point(spec)
    strokes, f_static, f_hover = grasp_force_curve(path, spec.springs, spec.load.mu)
    motion = closing_motion(spec, path, grasp)
    mech = build_mechanism(spec, motion, design.name)
    st = finger_state(spec.geometry, grasp.phi1, grasp.phi2)
    s1, s2 = spring_torques(spec.springs, grasp.phi1, grasp.phi2)
    report = {
        "F_n2_N": spec.load.hover_force,
        "paper_optimum": {"F_n1_N": grasp.fn_static, "F_n2_N": grasp.fn_hover, "delta_N_N": grasp.delta_n},
        "paper_printed": {"F_n1_N": 4.50, "F_n2_N": 3.78, "delta_N_N": 0.72,
                          "note": "read off the paper's Fig 3; eqs 3-6 at the hover pose give F_n1 above"},
        "grasp": {"stroke_mm": grasp.stroke, "first_touch_stroke_mm": grasp.contact_stroke,
                  "phi1_deg": float(np.degrees(grasp.phi1)), "phi2_deg": float(np.degrees(grasp.phi2)),
                  "rod_force_static_N": grasp.fd_static, "rod_force_hover_N": grasp.fd_hover,
                  "beta_deg": float(np.degrees(st.beta)), "gamma_deg": float(np.degrees(st.gamma)),
                  "spring_torques_Nmm": [float(s1), float(s2)]},
        "grasp_force_curve": {"stroke_mm": strokes[::10].tolist(), "F_static_N": f_static[::10].tolist(),
                              "F_hover_N": f_hover[::10].tolist()},
        "fingers": spec.fingers,
        "drive_parts": [{"item": p.item, "qty": p.qty, "note": p.note} for p in DRIVE_PARTS],
    }
    optimum = None
    if spec.grid is not None:
        optimum = optimise(spec.geometry, spec.grid, spec.load, samples=spec.path_samples,
                           hinge_margin=spec.min_hinge)
        report["optimum"] = _optimum_report(spec, optimum)
    g = spec.geometry
    parts = PartHints(
        springs=(SpringHint("C", spec.springs.k1, float(np.degrees(spec.springs.phi01)), spec.spring_legs,
                            "small torsion spring, tip hinge (k1)"),
                 SpringHint("B", spec.springs.k2, float(np.degrees(spec.springs.phi02)), spec.spring_legs,
                            "large torsion spring, middle hinge (k2)")),
        # per finger (the BOM layer multiplies these by the copies)
        purchased=(PurchasedItem("tip drive rod, 4 mm steel, threaded end", 1, "pushes the two-force rod"),
                   PurchasedItem("root push rod, 4 mm steel, threaded end", 1, "sets the root angle alpha"),
                   PurchasedItem("adjusting knob", 1, "sets the tip spring preload")),
        # once per gripper, shared by the fingers: listed apart so they are not multiplied
        purchased_shared=DRIVE_PARTS,
        copies=spec.fingers,
        copy_angle_deg=360.0 / spec.fingers,
        tip_point="tip",
        # the fingertip arc of radius r runs from its tangent point on the phalanx to the tip
        pads={"tip": PadHint("pad", g.r, ("pad_start", "tip"))},
    )

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.compliant.plots import compliant_figures
        return compliant_figures(spec, path, grasp, motion, optimum)

    data = {"path": path, "grasp": grasp, "motion": motion, "optimum": optimum,
            "force_curve": (strokes, f_static, f_hover)}
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data=data, parts=parts)
