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
        Effort each driver puts on its body (N·mm for an angle, N for a slide): the known effort of an
        actuator, the multiplier of any other driver.
    residual : float
        Largest ``|Q + J^T lambda|`` over the motion (N or N·mm): equilibrium holds where it is tiny.
    reaction_N : (n,) array
        Solved magnitude of the unknown reaction (zeros when there is none).
    """

    joint_forces: dict[str, np.ndarray]
    slider_forces: dict[str, np.ndarray]
    slider_torques: dict[str, np.ndarray]
    gear_torques: dict[str, np.ndarray]
    driver_efforts: np.ndarray
    residual: float
    reaction_N: np.ndarray | None = None


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
                  torques: Sequence[BodyTorque] = (), efforts: Sequence[DriverEffort] = (),
                  reaction: PointForce | None = None) -> Statics:
    """Constraint forces at every pose of ``motion`` under the applied loads.

    A known driver effort (an actuator's force) is applied along its driver's coordinate and that
    driver's constraint is dropped: the other drivers (in the underactuated finger and the gripper they
    stand for the object and the stops) and the loads hold the mechanism against it.

    ``reaction`` is a force of unknown magnitude along given unit directions (``force``, (n, 2)): the
    object resisting the actuator at the tip. Its magnitude at every pose is solved with the multipliers
    (``Statics.reaction_N``).

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
    n_rows = n_rev + n_sl + n_g + len(mechanism.drivers)
    known = {e.index: np.broadcast_to(np.asarray(e.effort, dtype=np.float64), (n,)) for e in efforts}
    # an actuator of known effort is not a rigid constraint: its row leaves the system (the object or
    # the other drivers, which stand for stops and contacts, must hold the mechanism against it)
    keep = np.array([r for r in range(n_rows) if r - (n_rev + n_sl + n_g) not in known], dtype=np.int64)
    lam = np.zeros((n, n_rows))
    magnitude = np.zeros(n)
    unit = generalised_forces(mechanism, motion, [reaction], ()) if reaction is not None else None
    worst = 0.0
    for i in range(n):
        q = motion.q[i].reshape(-1)
        _, jac, _ = system.jacobian(q, float(motion.inputs[i]))
        applied = q_applied[i].copy()
        for k, effort in known.items():
            # a driver row is (coordinate - value(s)): its gradient is the coordinate's direction, so an
            # effort along the coordinate is that row times the effort
            applied += jac[n_rev + n_sl + n_g + k] * float(effort[i])
        system_t = jac[keep].T if unit is None else np.column_stack([jac[keep].T, unit[i]])
        sol, *_ = np.linalg.lstsq(system_t, -applied, rcond=None)
        miss = float(np.max(np.abs(applied + system_t @ sol), initial=0.0))
        scale = max(1.0, float(np.max(np.abs(applied), initial=0.0)))
        if not np.all(np.isfinite(sol)) or miss > 1e-6 * scale:
            what = ("nothing but the actuator holds the mechanism: a known input effort needs a load or "
                    "another driver (a stop, the object) to push against" if known else
                    "a dead point of the mechanism")
            raise GeometryError(f"statics: no equilibrium at input {float(motion.inputs[i]):.6g} "
                                f"{mechanism.input_unit} ({what})")
        worst = max(worst, miss)
        if unit is not None:
            magnitude[i] = sol[-1]
            sol = sol[:-1]
        lam[i, keep] = sol
        for k, effort in known.items():
            lam[i, n_rev + n_sl + n_g + k] = effort[i]
    joint_forces = {j.name: lam[:, 2 * k:2 * k + 2] for k, j in enumerate(revolutes)}
    slider_forces = {j.name: lam[:, n_rev + 2 * k + 1] for k, j in enumerate(sliders)}
    slider_torques = {j.name: lam[:, n_rev + 2 * k] for k, j in enumerate(sliders)}
    gear_torques = {g.name: lam[:, n_rev + n_sl + k] for k, g in enumerate(mechanism.gears)}
    return Statics(joint_forces=joint_forces, slider_forces=slider_forces, slider_torques=slider_torques,
                   gear_torques=gear_torques,
                   driver_efforts=lam[:, n_rev + n_sl + n_g:], residual=worst, reaction_N=magnitude)


def body_forces(mechanism: Mechanism, statics: Statics, body: str, joint: str) -> np.ndarray:
    """Force (n, 2) world N that ``body`` receives at revolute ``joint`` (either end of it)."""
    j = next(j for j in mechanism.joints if j.name == joint and isinstance(j, Revolute))
    if body == j.body_a:
        return statics.joint_forces[joint]
    if body == j.body_b:
        return -statics.joint_forces[joint]
    raise KeyError(f"{body} is not at joint {joint}")
