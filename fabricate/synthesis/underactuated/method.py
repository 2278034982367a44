"""The underactuated finger's synthesis: closing motion on the cylinder and free, final contact forces,
velocity ratios, the mechanism, the report's ``synthesis`` section and the parts hints (return springs, the
actuator)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from fabricate.errors import SynthesisError
from fabricate.hints import PadHint, PartHints, PurchasedItem, SpringHint
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.underactuated.closing import closing_motion, final_contact_forces
from fabricate.synthesis.underactuated.mechanism import build_mechanism, mobility
from fabricate.synthesis.underactuated.model import crank_rate, distal_rate, finger_pose, transmission_ratios
from fabricate.synthesis.underactuated.spec import UnderactuatedSpec

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


def synthesise(design: DesignSpec) -> SynthesisResult:
    """Closing motion, contact sequence, final forces, velocity ratios and the mechanism."""
    spec: UnderactuatedSpec = design.method
    d = spec.design
    motion = closing_motion(spec, with_object=True)
    if motion.strokes[-1] < 1e-3:  # the driver law needs a stroke to span (a 0.14 mm crank stopped at 0)
        raise SynthesisError(f"underactuated: the finger does not close: the push rod stops at stroke "
                             f"{motion.strokes[-1]:.3g} mm (the linkage locks or meets the object at once); "
                             "check the [push_rod] and [transmission] dimensions")
    free = closing_motion(spec, with_object=False, stroke=float(motion.strokes[-1]))
    final = final_contact_forces(spec, motion)
    mech = build_mechanism(spec, motion, design.name)
    pose_end = final["pose"]
    open_pose = finger_pose(d, np.zeros(d.n))
    assert open_pose is not None  # assembled by construction: FingerDesign takes the couplers from it
    report = {
        "mobility": {**mobility(d.n), "mechanism_dof": mech.degrees_of_freedom()},
        "phalanx_lengths_mm": d.lengths.tolist(),
        "dimensions_source": spec.source,
        "stroke_mm": spec.stroke,
        "push_force_N": spec.push_force,
        "contact_sequence": [f"phalanx{i + 1}" for i in motion.contact_order],
        "contact_strokes_mm": motion.contact_strokes,
        "contact_forces_N": {f"phalanx{i + 1}": float(f) for i, f in enumerate(final["forces_N"])},
        "link_forces_N": [float(v) for v in final["link_forces_N"]],
        "final_joint_angles_deg": np.degrees(motion.q[-1]).tolist(),
        "free_closing_joint_angles_deg": np.degrees(free.q[-1]).tolist(),
        "velocity_ratios": {
            "E_open": transmission_ratios(open_pose).tolist(),
            "E_final": transmission_ratios(pose_end).tolist(),
            "crank_rate_rad_per_mm_open": crank_rate(d, open_pose),
            "distal_rate_rad_per_mm_final": distal_rate(d, pose_end),
        },
    }
    springs = tuple(SpringHint(f"G{i + 1}", float(spec.spring_rates[i] * np.pi / 180.0),
                               float(np.degrees(spec.spring_preloads[i])), spec.spring_legs,
                               "return spring, opens the joint against its stop") for i in range(d.n))
    # the push rod's drive: a template's [actuator] places it (its BOM row, the drive check), so only without one
    # does the synthesis name what to buy; never both, which listed two drives per copy
    drive = () if design.actuator is not None else (
        PurchasedItem(f"linear actuator, stroke >= {spec.stroke:.0f} mm, force >= {spec.push_force:.0f} N", 1,
                      "drives the push rod"),)
    parts = PartHints(
        springs=springs,
        purchased=drive,
        tip_point="tip",
        pads={f"phalanx{d.n}": PadHint("tip", float(0.5 * d.thickness))},
    )

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.underactuated.plots import closing_figures
        return closing_figures(spec, motion, free, final)

    data = {"motion": motion, "free": free, "final": final, "spec": spec}
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data=data, parts=parts)
