"""Quasi-static joint reactions of any :class:`~fabricate.mechanism.Mechanism` over its solved motion.

One method for every kind: with the constraints ``g(q, s) = 0`` of the mechanism (revolute joints,
sliders, gear couplings, drivers) and the applied generalised forces ``Q`` (forces at points, torques on
bodies, each as ``(Fx, Fy, M)`` per free body), equilibrium is ``Q + J^T lambda = 0`` (the principle of
virtual work with Lagrange multipliers). The multipliers are the constraint forces themselves:

- a revolute joint's pair is the force (N, world frame) its ``body_a`` receives from ``body_b``
  (the residual is ``p_a - p_b``);
- a gear coupling's multiplier is the torque (N·mm) on ``gear_b`` relative to the carrier, and
  ``-law'`` times it on ``gear_a``;
- a slider's pair is the locking torque (N·mm) and the normal force (N) on ``body_b``;
- a driver's multiplier is the effort (N·mm for an angle, N for a slide) its actuator or stop supplies.

Nothing here is specific to a paper: the six-bar method's own link-by-link statics is an independent
check of it (``tests/test_strength.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fabricate.errors import GeometryError
from fabricate.mechanism import Mechanism, Motion, Revolute, Slider, _System
from fabricate.planar import rotation


@dataclass(frozen=True)
class PointForce:
    """A force on ``body`` at its point ``local`` (body coordinates, mm); ``force`` (n, 2) world N per pose."""

    body: str
    local: np.ndarray
    force: np.ndarray
    name: str = ""


@dataclass(frozen=True)
class BodyTorque:
    """A couple (N·mm per pose, (n,)) on ``body`` and the opposite couple on ``reaction`` (a spring)."""

    body: str
    reaction: str
    torque: np.ndarray
    joint: str = ""


@dataclass(frozen=True)
class DriverEffort:
    """A known actuator effort on driver ``index`` (N for a slide, N·mm for an angle), per pose (n,)."""

    index: int
    effort: np.ndarray


@dataclass(frozen=True)
class Statics:
    """Constraint forces over a motion (n poses).

    Attributes
    ----------
    joint_forces : dict joint -> (n, 2) array
        Force on the joint's ``body_a`` from ``body_b`` (world frame, N); the pin carries its magnitude.
    slider_forces : dict joint -> (n,) array
        Normal force (N) on a slider's ``body_b`` along its axis turned +90° (in ``body_a``).
    slider_torques : dict joint -> (n,) array
        Locking torque (N·mm) on a slider's ``body_b``.
    gear_torques : dict pair -> (n,) array
        Torque (N·mm) ``gear_b`` receives relative to the carrier.
    driver_efforts : (n, d) array
        Effort each driver supplies (N·mm or N).
    residual : float
        Largest ``|Q + J^T lambda|`` over the motion (N or N·mm): equilibrium holds where it is tiny.
    """

    joint_forces: dict[str, np.ndarray]
    slider_forces: dict[str, np.ndarray]
    slider_torques: dict[str, np.ndarray]
    gear_torques: dict[str, np.ndarray]
    driver_efforts: np.ndarray
    residual: float


def generalised_forces(mechanism: Mechanism, motion: Motion, forces: Sequence[PointForce],
                       torques: Sequence[BodyTorque]) -> np.ndarray:
    """Applied generalised forces ``Q`` (n, 3m) on the free bodies: (Fx, Fy, M about the body origin)."""
    free = list(motion.free)
    n = len(motion.inputs)
    q_applied = np.zeros((n, 3 * len(free)))
    for f in forces:
        if f.body not in free:
            continue  # a force on the ground is carried by the ground
        k = free.index(f.body)
        pose = motion.pose(f.body)
        arm = np.einsum("nij,j->ni", rotation(pose[:, 2]), np.asarray(f.local, dtype=np.float64))
        load = np.broadcast_to(np.asarray(f.force, dtype=np.float64), (n, 2))
        q_applied[:, 3 * k:3 * k + 2] += load
        q_applied[:, 3 * k + 2] += arm[:, 0] * load[:, 1] - arm[:, 1] * load[:, 0]
    for t in torques:
        value = np.broadcast_to(np.asarray(t.torque, dtype=np.float64), (n,))
        if t.body in free:
            q_applied[:, 3 * free.index(t.body) + 2] += value
        if t.reaction in free:
            q_applied[:, 3 * free.index(t.reaction) + 2] -= value
    return q_applied


def solve_statics(mechanism: Mechanism, motion: Motion, forces: Sequence[PointForce] = (),
                  torques: Sequence[BodyTorque] = (), efforts: Sequence[DriverEffort] = ()) -> Statics:
    """Constraint forces at every pose of ``motion`` under the applied loads.

    Known driver efforts (an actuator's force) are applied as generalised forces along their driver's
    coordinate; the driver's multiplier then holds only what the applied loads leave over (for a driver
    that stands for the object or a stop, it is the effort that one supplies).

    Raises
    ------
    GeometryError
        If the constraint Jacobian is singular at a pose (a dead point: the statics have no finite
        solution there).
    """
    system = _System(mechanism)
    revolutes = [j for j in mechanism.joints if isinstance(j, Revolute)]
    sliders = [j for j in mechanism.joints if isinstance(j, Slider)]
    n = len(motion.inputs)
    q_applied = generalised_forces(mechanism, motion, forces, torques)
    n_rev, n_sl, n_g = 2 * len(revolutes), 2 * len(sliders), len(mechanism.gears)
    lam = np.zeros((n, n_rev + n_sl + n_g + len(mechanism.drivers)))
    worst = 0.0
    for i in range(n):
        q = motion.q[i].reshape(-1)
        _, jac, ds = system.jacobian(q, float(motion.inputs[i]))
        applied = q_applied[i].copy()
        for e in efforts:
            # a driver row is (coordinate - value(s)); its gradient is the coordinate's direction, so
            # an effort along the coordinate is that row times the effort
            row = jac[n_rev + n_sl + n_g + e.index]
            applied += row * float(np.broadcast_to(e.effort, (n,))[i])
        sol, *_ = np.linalg.lstsq(jac.T, -applied, rcond=None)
        miss = float(np.max(np.abs(applied + jac.T @ sol), initial=0.0))
        scale = max(1.0, float(np.max(np.abs(applied), initial=0.0)))
        if not np.all(np.isfinite(sol)) or miss > 1e-6 * scale:
            raise GeometryError(f"statics: no equilibrium at input {float(motion.inputs[i]):.6g} "
                                f"{mechanism.input_unit} (a dead point of the mechanism)")
        worst = max(worst, miss)
        lam[i] = sol
    joint_forces = {j.name: lam[:, 2 * k:2 * k + 2] for k, j in enumerate(revolutes)}
    slider_forces = {j.name: lam[:, n_rev + 2 * k + 1] for k, j in enumerate(sliders)}
    slider_torques = {j.name: lam[:, n_rev + 2 * k] for k, j in enumerate(sliders)}
    gear_torques = {g.name: lam[:, n_rev + n_sl + k] for k, g in enumerate(mechanism.gears)}
    return Statics(joint_forces=joint_forces, slider_forces=slider_forces, slider_torques=slider_torques,
                   gear_torques=gear_torques,
                   driver_efforts=lam[:, n_rev + n_sl + n_g:], residual=worst)


def body_forces(mechanism: Mechanism, statics: Statics, body: str, joint: str) -> np.ndarray:
    """Force (n, 2) world N that ``body`` receives at revolute ``joint`` (either end of it)."""
    j = next(j for j in mechanism.joints if j.name == joint and isinstance(j, Revolute))
    if body == j.body_a:
        return statics.joint_forces[joint]
    if body == j.body_b:
        return -statics.joint_forces[joint]
    raise KeyError(f"{body} is not at joint {joint}")
