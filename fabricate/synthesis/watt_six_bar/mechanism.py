"""The Watt-I six-bar finger as a :class:`~fabricate.mechanism.Mechanism` (bodies ground, proximal, middle,
distal, coupler, rocker; one angle driver proximal vs ground in degrees), and its statics by the generic solver
(an independent check of the force index K)."""

from __future__ import annotations

from typing import Any

import numpy as np

from fabricate.mechanism import Body, Driver, Mechanism, Revolute
from fabricate.synthesis.watt_six_bar.region import FingerPositions
from fabricate.synthesis.watt_six_bar.statics import JOINTS, lagrange_joint_forces


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


def _load_on_distal(mech: Mechanism, poses: dict[str, np.ndarray], force: float) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint of e-c and the force normal to e->c (turned +90 deg), world, from the distal pose."""
    from fabricate.planar import transform_points

    body = mech.body("distal")
    e = transform_points(poses["distal"], body.point("e"))
    c = transform_points(poses["distal"], body.point("c"))
    ec = c - e
    n = np.array([-ec[1], ec[0]]) / np.hypot(*ec)
    return 0.5 * (e + c), force * n


def virtual_work_check(mech: Mechanism, theta_deg: np.ndarray, force: float) -> dict[str, Any]:
    """K and the input torque by the generic solver + constraint multipliers + virtual power."""
    from fabricate.synthesis.watt_six_bar.statics import virtual_work_torque

    motion = mech.sweep(theta_deg)
    k_max = 0.0
    torque_rows: list[float] = []
    power_torques: list[float] = []
    local_mid = 0.5 * (mech.body("distal").point("e") + mech.body("distal").point("c"))
    for i in range(len(theta_deg)):
        poses = motion.poses_at(i)
        point, load = _load_on_distal(mech, poses, force)
        forces, torque = lagrange_joint_forces(mech, poses, point, load)
        k_max = max(k_max, max(forces[j] for j in JOINTS) / force)
        torque_rows.append(torque)
        power_torques.append(virtual_work_torque(mech, motion, local_mid, "distal",
                                                 lambda p: _load_on_distal(mech, p, force), i))
    torques = np.asarray(torque_rows)
    power = np.asarray(power_torques)
    return {"K": float(k_max), "torque_Nmm": torques, "torque_virtual_power_Nmm": power}
