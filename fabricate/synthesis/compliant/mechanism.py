"""One finger of the compliant gripper as a :class:`~fabricate.mechanism.Mechanism`: palm (ground), root,
middle, tip, two-force rod and the drive rod (a slider driven over the stroke)."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import PchipInterpolator

from fabricate.mechanism import Body, Driver, LinearLaw, Mechanism, Revolute, Slider
from fabricate.synthesis.compliant.closing import GripperMotion
from fabricate.synthesis.compliant.model import finger_state
from fabricate.synthesis.compliant.spec import CompliantSpec


def build_mechanism(spec: CompliantSpec, motion: GripperMotion, name: str) -> Mechanism:
    """One finger: palm (ground), root, middle, tip, two-force rod, drive rod (slider)."""
    g = spec.geometry
    st0 = finger_state(g, 0.0, 0.0)
    m0 = st0.M
    bodies = (
        Body("palm", {"A": (0.0, 0.0), "drive": (g.l2, float(m0[1]) + 30.0),
                      "palm_centre": (-g.l1, 0.0)}),
        Body("root", {"A": (0.0, 0.0), "B": (g.a1, 0.0)}),
        Body("middle", {"B": (0.0, 0.0), "C": (g.a2, 0.0)}),
        Body("tip", {"C": (0.0, 0.0), "D": (g.a3, 0.0), "E": (g.a3, g.c), "pad": (g.a3 + g.b, g.r),
                     "pad_start": (g.a3 + g.b, 0.0), "tip": (g.a3 + g.b + g.r, g.r)}),
        Body("two_force_rod", {"E": (0.0, 0.0), "M": (g.d, 0.0)}),
        Body("drive_rod", {"M": (0.0, 0.0), "drive": (0.0, 30.0)}),
    )
    joints = (Revolute("A", "palm", "root"), Revolute("B", "root", "middle"), Revolute("C", "middle", "tip"),
              Revolute("E", "tip", "two_force_rod"), Revolute("M", "two_force_rod", "drive_rod"),
              Slider("drive", "palm", "drive_rod", (0.0, -1.0)))
    # choose which hinge to prescribe: the other one is solved from the stroke, so it must keep the
    # stroke sensitive to it (the rod must not pass through that hinge)
    st = finger_state(g, motion.phi1, motion.phi2)
    sens_phi2, sens_phi1 = np.abs(st.h2).min(), np.abs(st.h1).min()
    if sens_phi2 >= sens_phi1:
        driver = Driver("angle", "tip", "middle", law=PchipInterpolator(motion.strokes, -motion.phi1))
    else:
        driver = Driver("angle", "middle", "root", law=PchipInterpolator(motion.strokes, -motion.phi2))
    drivers = (Driver("slide", "drive_rod", "palm", joint="drive"),
               Driver("angle", "root", "palm", law=LinearLaw(0.0, -g.alpha)), driver)
    e = np.array([np.cos(g.alpha), -np.sin(g.alpha)])
    e_vec = st0.E
    rod_dir = m0 - e_vec
    assembly = {"root": (0.0, 0.0, -g.alpha), "middle": (*(g.a1 * e), -g.alpha),
                "tip": (*((g.a1 + g.a2) * e), -g.alpha),
                "two_force_rod": (float(e_vec[0]), float(e_vec[1]), float(np.arctan2(rod_dir[1], rod_dir[0]))),
                "drive_rod": (float(m0[0]), float(m0[1]), 0.0)}
    return Mechanism(name=name, bodies=bodies, ground="palm", joints=joints, gears=(), drivers=drivers,
                     input_range=(0.0, float(motion.strokes[-1])), input_unit="mm", assembly=assembly)
