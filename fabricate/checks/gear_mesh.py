"""Gear mesh inside the assembly: the pairs turned through the angles the mechanism really takes.

The gears package checks each pair over its own working range; here the same mesh check
(:func:`fabricate.gears.mesh.mesh_check`) runs at the relative angles of the assembled motion, so a
motion that leaves the cut sector, a solver that does not follow the law, or a backlash that closes
somewhere in the real motion is caught. Findings are data (:class:`GearMeshResult`), not exceptions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.mechanism import Motion

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair

#: The assembly must follow the pair's law to this (rad): the solver's tolerance, with margin.
LAW_TOLERANCE_RAD = 1e-6
#: Relative angles may leave the working range by this much (rad) before the sector is "left".
RANGE_TOLERANCE_RAD = 1e-9
#: Backlash must stay within these multiples of the design backlash (and above zero).
BACKLASH_BAND = (0.5, 2.0)
#: Tooth overlap area (mm^2) at or below this is rounding (a larger one fails).
AREA_EPS_MM2 = 1e-6


@dataclass(frozen=True)
class GearMeshResult:
    """The mesh of one gear pair over the assembled motion.

    Attributes
    ----------
    name : str
        Pair name.
    steps : int
        Poses checked (the motion's poses).
    x_a_range_deg : (float, float)
        Range of gear a's angle relative to the carrier over the motion, degrees.
    working_range_deg : (float, float)
        The range the pair was cut for, degrees.
    law_error_rad : float
        Largest |x_b − law(x_a)| of the assembly.
    interference_area_mm2 : float
        Largest tooth overlap area.
    backlash_mm : (float, float)
        Smallest and largest backlash at the pitch curve (NaN when never in mesh).
    backlash_allowed_mm : (float, float)
    steps_without_contact : int
        Poses with no flank pair in mesh (teeth disengaged).
    transmission_error_deg : float
    failures : tuple of str
    """

    name: str
    steps: int
    x_a_range_deg: tuple[float, float]
    working_range_deg: tuple[float, float]
    law_error_rad: float
    interference_area_mm2: float
    backlash_mm: tuple[float, float]
    backlash_allowed_mm: tuple[float, float]
    steps_without_contact: int
    transmission_error_deg: float
    failures: tuple[str, ...]

    @property
    def passed(self) -> bool:
        return not self.failures

    def report(self) -> dict[str, Any]:
        """JSON-ready summary."""
        def num(v: float) -> float | None:
            return float(v) if np.isfinite(v) else None

        return {
            "name": self.name,
            "steps": self.steps,
            "x_a_range_deg": [float(v) for v in self.x_a_range_deg],
            "working_range_deg": [float(v) for v in self.working_range_deg],
            "law_error_rad": float(self.law_error_rad),
            "interference_area_mm2": float(self.interference_area_mm2),
            "backlash_mm": [num(v) for v in self.backlash_mm],
            "backlash_allowed_mm": [float(v) for v in self.backlash_allowed_mm],
            "steps_without_contact": int(self.steps_without_contact),
            "transmission_error_deg": num(self.transmission_error_deg),
            "passed": self.passed,
        }


def check_gear_mesh(pair: GearPair, motion: Motion) -> GearMeshResult:
    """Run the pair's mesh check at the assembly's relative angles and judge it.

    Parameters
    ----------
    pair : fabricate.gears.pair.GearPair
        With ``carrier``, ``body_a``, ``body_b``, ``law``, ``working_range``, ``spec.backlash_mm``.
    motion : Motion
        The assembled motion (each pose is one step of the check).

    Returns
    -------
    GearMeshResult
    """
    from fabricate.gears.mesh import mesh_check

    x_a = motion.relative_angle(pair.body_a, pair.carrier)
    x_b = motion.relative_angle(pair.body_b, pair.carrier)
    law_error = float(np.max(np.abs(x_b - np.asarray(pair.law(x_a), dtype=np.float64))))
    lo, hi = sorted(float(v) for v in pair.working_range)
    failures = []
    name = pair.name
    if law_error > LAW_TOLERANCE_RAD:
        failures.append(f"gear mesh {name}: the assembly departs from the gear law by "
                        f"{np.degrees(law_error):.3g} deg")
    if not pair.closed and (x_a.min() < lo - RANGE_TOLERANCE_RAD or x_a.max() > hi + RANGE_TOLERANCE_RAD):
        failures.append(f"gear mesh {name}: the motion turns gear a through "
                        f"{np.degrees(x_a.min()):.2f}..{np.degrees(x_a.max()):.2f} deg, outside the cut "
                        f"range {np.degrees(lo):.2f}..{np.degrees(hi):.2f} deg")
    mesh = mesh_check(pair, x_a_values=x_a)
    area = float(np.max(mesh.interference_area_mm2)) if mesh.steps else 0.0
    backlash = mesh.backlash_mm[np.isfinite(mesh.backlash_mm)]
    disengaged = int(np.count_nonzero(~np.isfinite(mesh.backlash_mm)))
    design = float(pair.spec.backlash_mm)
    allowed = (BACKLASH_BAND[0] * design, BACKLASH_BAND[1] * design)
    b_min = float(backlash.min()) if len(backlash) else float("nan")
    b_max = float(backlash.max()) if len(backlash) else float("nan")
    if area > AREA_EPS_MM2:
        k = int(np.argmax(mesh.interference_area_mm2))
        failures.append(f"gear mesh {name}: teeth overlap by {area:.3g} mm^2 at input "
                        f"{motion.inputs[k]:g} {motion.mechanism.input_unit}")
    if disengaged:
        k = int(np.nonzero(~np.isfinite(mesh.backlash_mm))[0][0])
        failures.append(f"gear mesh {name}: no flank pair in mesh at {disengaged} pose(s), first at input "
                        f"{motion.inputs[k]:g} {motion.mechanism.input_unit}")
    if len(backlash):
        if b_min <= 0.0:
            failures.append(f"gear mesh {name}: backlash closes ({b_min:.3g} mm): the teeth jam")
        elif b_min < allowed[0] or b_max > allowed[1]:
            failures.append(f"gear mesh {name}: backlash {b_min:.3g}..{b_max:.3g} mm outside "
                            f"{allowed[0]:.3g}..{allowed[1]:.3g} mm (design {design:.3g} mm)")
    te = mesh.transmission_error[np.isfinite(mesh.transmission_error)]
    return GearMeshResult(
        name=name, steps=int(mesh.steps),
        x_a_range_deg=(float(np.degrees(x_a.min())), float(np.degrees(x_a.max()))),
        working_range_deg=(float(np.degrees(lo)), float(np.degrees(hi))),
        law_error_rad=law_error, interference_area_mm2=area, backlash_mm=(b_min, b_max),
        backlash_allowed_mm=allowed, steps_without_contact=disengaged,
        transmission_error_deg=float(np.degrees(np.max(np.abs(te)))) if len(te) else float("nan"),
        failures=tuple(failures))


def check_gear_meshes(gear_pairs: Sequence[GearPair], motion: Motion) -> list[GearMeshResult]:
    """:func:`check_gear_mesh` for every pair."""
    return [check_gear_mesh(pair, motion) for pair in gear_pairs]
