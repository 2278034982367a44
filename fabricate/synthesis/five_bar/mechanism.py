"""The five-bar NCG finger as a :class:`~fabricate.mechanism.Mechanism`: five bodies and the sun-planet gear
pair of the chosen dyad, and its errors at the target poses."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.mechanism import Body, Driver, GearCoupling, Mechanism, Motion, Revolute
from fabricate.planar import wrap_angle
from fabricate.synthesis.five_bar.law import GearLaw
from fabricate.synthesis.five_bar.targets import FingerTargets

#: Body names (the paper's links): the proximal body O-D carries the arm O-A; the distal body B-C-P.
GROUND, PROXIMAL, LINK_AB, MIDDLE, DISTAL = "ground", "proximal", "link_AB", "middle", "distal"
GEAR_NAME = "sun_planet"


@dataclass(frozen=True)
class SelectedDyad:
    """The chosen dyad: circle vector, A (proximal frame), B (distal frame), its kappa and law."""

    p: np.ndarray
    kappa: float
    a_proximal: np.ndarray
    b_distal: np.ndarray
    law: GearLaw
    length_error: float


def build_mechanism(name: str, targets: FingerTargets, dyad: SelectedDyad) -> Mechanism:
    """The five-bar with its gear pair as a generic :class:`Mechanism`.

    Body coordinates: the proximal body uses its own frame (origin O, x along O->D), so its angle is
    the absolute proximal angle and the driver is the identity (input = t1 in degrees); every other
    body uses world coordinates of the first pose.
    """
    t1 = targets.angles[:, 0]
    a_world = targets.proximal_to_world(dyad.a_proximal)[0]
    b_world = targets.distal_to_world(dyad.b_distal)[0]
    d0, c0, p0 = targets.d[0], targets.c[0], targets.p[0]

    def pt(v: np.ndarray) -> tuple[float, float]:
        return float(v[0]), float(v[1])

    bodies = (
        Body(GROUND, {"O": pt(targets.origin)}),
        Body(PROXIMAL, {"O": (0.0, 0.0), "D": (float(targets.lengths[0]), 0.0), "A": pt(dyad.a_proximal)}),
        Body(LINK_AB, {"A": pt(a_world), "B": pt(b_world)}),
        Body(MIDDLE, {"D": pt(d0), "C": pt(c0)}),
        Body(DISTAL, {"B": pt(b_world), "C": pt(c0), "P": pt(p0)}),
    )
    joints = (Revolute("O", GROUND, PROXIMAL), Revolute("A", PROXIMAL, LINK_AB),
              Revolute("D", PROXIMAL, MIDDLE), Revolute("C", MIDDLE, DISTAL), Revolute("B", LINK_AB, DISTAL))
    gear = GearCoupling(GEAR_NAME, carrier=PROXIMAL, gear_a=GROUND, gear_b=LINK_AB, law=dyad.law.law,
                        axis_a="O", axis_b="A", working_range=dyad.law.working_range)
    assembly = {PROXIMAL: (float(targets.origin[0]), float(targets.origin[1]), float(t1[0]))}
    assembly.update({body: (0.0, 0.0, 0.0) for body in (LINK_AB, MIDDLE, DISTAL)})
    return Mechanism(name=name, bodies=bodies, ground=GROUND, joints=joints, gears=(gear,),
                     drivers=(Driver("angle", PROXIMAL, GROUND),),
                     input_range=(float(np.degrees(t1[0])), float(np.degrees(t1[-1]))),
                     input_unit="deg", assembly=assembly)


def pose_errors(mech: Mechanism, targets: FingerTargets) -> tuple[np.ndarray, np.ndarray, Motion]:
    """Fingertip position error (mm) and distal orientation error (rad) at every target pose.

    The mechanism is swept through the poses' input angles (continuation from the first pose), so the
    errors are those of the generic solver's assembly branch.
    """
    motion = mech.sweep(np.degrees(targets.angles[:, 0]))
    tip = motion.point("P", DISTAL)
    position = np.hypot(*(tip - targets.p).T)
    # the distal body's angle is 0 at the first pose (world coordinates of the first pose)
    orientation = wrap_angle(motion.pose(DISTAL)[:, 2] + targets.angles[0, 2] - targets.angles[:, 2])
    return position, np.asarray(orientation), motion
