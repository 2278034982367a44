"""Position analysis and statics of the Watt-I six-bar finger, vectorised over many mechanisms.

Bodies (the paper's Fig. 3): ground (a0, d0); proximal a0-a-d (driven by theta1); middle a-b; distal
b-c-e (c is the fingertip); coupler d-e-f; rocker d0-f. Two four-bar loops close in turn:

1. ground-proximal-coupler-rocker: ``f`` from circles about ``d`` and ``d0``;
2. proximal-middle-distal-coupler: ``b`` from circles about ``a`` and ``e`` (``e`` rides on the coupler).

Each loop keeps the assembly branch of position 1 (the side of ``f`` relative to d->d0 and of ``b``
relative to a->e); the branch can only change through a toggle, where the circles touch, and there the
joint forces grow without bound, so a finite force index also certifies a motion free of lock-up.

Statics (paper section 1.3, eq 7): a force ``F`` normal to e-c at its midpoint acts on the distal link,
the input torque ``T`` on the proximal link balances it. The middle link and the rocker carry no load
between their pins, so they are two-force members; the joint forces then follow link by link:

- distal, moments about e:  s1 (b - e) x u + (m - e) x F n = 0,  R_e = -s1 u - F n
- coupler, moments about d: (e - d) x (-R_e) + s2 (f - d) x w = 0, R_d = R_e - s2 w
- proximal:                 R_a0 = s1 u + R_d,  T = (a - a0) x s1 u + (d - a0) x R_d

with ``u`` the unit vector a->b, ``w`` the unit vector d0->f, ``s1``, ``s2`` the (signed) two-force
member loads. ``K = max |joint force| / |F|`` over the joints a0, a, b, d, e, f, d0 and the motion.
:func:`lagrange_joint_forces` solves the same equilibrium a second, independent way (virtual work
with constraint multipliers on a generic :class:`~fabricate.mechanism.Mechanism`) for the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.planar import cross2, perp, rotation, transform_points

#: Joints whose forces enter K, in report order (the paper's list for eq 7).
JOINTS = ("a0", "a", "b", "d", "e", "f", "d0")


@dataclass(frozen=True)
class SixBarBatch:
    """A batch of six-bar fingers at position 1 (world coordinates, mm; a0 is the origin).

    Attributes
    ----------
    a, b, c : (2,) arrays
        Phalanx joints and fingertip at position 1 (shared by the batch).
    d, e, f, d0 : (N, 2) arrays
        The synthesised joints of each mechanism.
    theta1_start : float
        theta1 at position 1, rad.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    e: np.ndarray
    f: np.ndarray
    d0: np.ndarray
    theta1_start: float

    def __len__(self) -> int:
        return len(self.d)

    def take(self, index: np.ndarray | slice) -> SixBarBatch:
        return SixBarBatch(self.a, self.b, self.c, self.d[index], self.e[index], self.f[index],
                           self.d0[index], self.theta1_start)


def _circle_intersection(c1: np.ndarray, r1: np.ndarray, c2: np.ndarray, r2: np.ndarray,
                         side: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Intersection on ``side`` (+1 left of c1->c2, -1 right), vectorised; (point, h^2 / r1^2).

    A negative second value means the circles do not meet (no assembly).
    """
    dv = c2 - c1
    dist2 = np.einsum("...a,...a->...", dv, dv)
    with np.errstate(divide="ignore", invalid="ignore"):
        along = (r1 * r1 - r2 * r2 + dist2) / (2.0 * dist2)
        h2 = r1 * r1 / dist2 - along * along
        h = np.sqrt(np.maximum(h2, 0.0))
        point = c1 + along[..., None] * dv + (side * h)[..., None] * perp(dv)
        margin = h2 * dist2 / (r1 * r1)
    # coincident centres or a zero radius: no assembly to speak of
    return point, np.where(np.isfinite(margin), margin, -1.0)


@dataclass(frozen=True)
class SixBarPoses:
    """Joint positions over inputs: every array (N, S, 2) mm; ``margin`` (N, S) >= 0 when assembled."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    e: np.ndarray
    f: np.ndarray
    d0: np.ndarray
    margin: np.ndarray


def assemble(batch: SixBarBatch, theta1: np.ndarray) -> SixBarPoses:
    """Positions of every joint for inputs ``theta1`` (S,) rad, on the branch of position 1.

    ``margin`` is the smaller of the two loops' normalised (h / r)^2: zero at a toggle, negative
    where a loop cannot close (positions there are not meaningful) and at every input of a mechanism whose
    position 1 is itself a toggle (no branch to keep).
    """
    theta1 = np.asarray(theta1, dtype=np.float64)
    rot = rotation(theta1 - batch.theta1_start)  # (S, 2, 2) about a0 = origin
    d1, e1, f1, d01 = batch.d[:, None], batch.e[:, None], batch.f[:, None], batch.d0[:, None]
    a = np.broadcast_to(rot @ batch.a, (len(batch),) + rot.shape[:1] + (2,))
    d = np.einsum("sij,nj->nsi", rot, batch.d)
    d0 = np.broadcast_to(d01, d.shape)
    side1 = np.sign(cross2(batch.d0 - batch.d, batch.f - batch.d))[:, None]
    len_df = np.linalg.norm(f1 - d1, axis=-1)
    len_d0f = np.linalg.norm(f1 - d01, axis=-1)
    f, margin1 = _circle_intersection(d, np.broadcast_to(len_df, d.shape[:2]), d0,
                                      np.broadcast_to(len_d0f, d.shape[:2]), side1)
    # coupler rotation from position 1, then e rides on it
    turn = _angle(f - d) - _angle(f1 - d1)
    e = d + np.einsum("nsij,nsj->nsi", rotation(turn), np.broadcast_to(e1 - d1, d.shape))
    b1 = batch.b
    side2 = np.sign(cross2(batch.e - batch.a, b1 - batch.a))[:, None]
    len_ab = float(np.hypot(*(b1 - batch.a)))
    len_eb = np.linalg.norm(b1 - batch.e, axis=-1)[:, None]
    b, margin2 = _circle_intersection(a, np.full(d.shape[:2], len_ab), e, np.broadcast_to(len_eb, d.shape[:2]),
                                      side2)
    distal_turn = _angle(b - e) - _angle(b1 - e1)
    c = e + np.einsum("nsij,nsj->nsi", rotation(distal_turn), np.broadcast_to(batch.c - e1, d.shape))
    margin = np.minimum(margin1, margin2)
    # position 1 on a toggle (d, f, d0 or a, b, e collinear) names no branch: every position is unmeaningful
    margin = np.where((side1 == 0.0) | (side2 == 0.0), -1.0, margin)
    return SixBarPoses(a=a, b=b, c=c, d=d, e=e, f=f, d0=d0, margin=margin)


def _angle(v: np.ndarray) -> np.ndarray:
    return np.arctan2(v[..., 1], v[..., 0])


@dataclass(frozen=True)
class JointLoads:
    """Joint forces for a unit external force: magnitudes (N, S) per joint, input torque (N, S) N*mm."""

    forces: dict[str, np.ndarray]
    torque: np.ndarray

    def largest(self) -> np.ndarray:
        """Largest joint force at every sample, (N, S)."""
        return np.max(np.stack([self.forces[j] for j in JOINTS]), axis=0)


def external_force(poses: SixBarPoses, force: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Point of application (midpoint of e-c) and force vector normal to e-c, both (N, S, 2).

    The normal is e->c turned +90 degrees: with the finger flexing clockwise (negative angles) that is
    the push of a grasped object on the palm side of the distal phalanx. K does not depend on the sign.
    """
    ec = poses.c - poses.e
    n = perp(ec) / np.hypot(ec[..., 0], ec[..., 1])[..., None]
    return 0.5 * (poses.e + poses.c), force * n


def joint_loads(poses: SixBarPoses, force: float = 1.0) -> JointLoads:
    """Joint forces (N) and balancing input torque (N*mm) from the link-by-link equilibrium."""
    m, load = external_force(poses, force)
    ab = poses.b - poses.a
    u = ab / np.hypot(ab[..., 0], ab[..., 1])[..., None]
    d0f = poses.f - poses.d0
    w = d0f / np.hypot(d0f[..., 0], d0f[..., 1])[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        s1 = -cross2(m - poses.e, load) / cross2(poses.b - poses.e, u)
        r_e = -s1[..., None] * u - load
        s2 = cross2(poses.e - poses.d, r_e) / cross2(poses.f - poses.d, w)
        r_d = r_e - s2[..., None] * w
        r_a0 = s1[..., None] * u + r_d
        torque = cross2(poses.a, s1[..., None] * u) + cross2(poses.d, r_d)
    norm = np.linalg.norm
    forces = {"a0": norm(r_a0, axis=-1), "a": np.abs(s1), "b": np.abs(s1), "d": norm(r_d, axis=-1),
              "e": norm(r_e, axis=-1), "f": np.abs(s2), "d0": np.abs(s2)}
    return JointLoads(forces=forces, torque=torque)


def force_index(batch: SixBarBatch, theta1: np.ndarray, force: float = 1.0,
                chunk: int = 4096) -> np.ndarray:
    """K (eq 7) of every mechanism over inputs ``theta1`` (S,) rad; ``inf`` where a loop cannot close.

    Processed in chunks of mechanisms to bound memory.
    """
    out = np.empty(len(batch))
    for start in range(0, len(batch), chunk):
        part = batch.take(slice(start, start + chunk))
        poses = assemble(part, theta1)
        k = np.max(joint_loads(poses, force).largest(), axis=1) / abs(force)
        closed = np.all(poses.margin > 0.0, axis=1)
        out[start:start + chunk] = np.where(closed & np.isfinite(k), k, np.inf)
    return out


def fingertip_errors(batch: SixBarBatch, theta1_positions: np.ndarray,
                     tip_targets: np.ndarray) -> np.ndarray:
    """Distance (N, P) of the fingertip c from its target at each position, on the position-1 branch.

    A mechanism with a branch (circuit) defect reaches the other assembly at some position and shows
    an error of the order of the link lengths there; NaN where it cannot be assembled.
    """
    poses = assemble(batch, theta1_positions)
    err = np.hypot(*(poses.c - tip_targets[None]).transpose(2, 0, 1))
    return np.where(poses.margin >= 0.0, err, np.nan)


# -- independent check: virtual work with constraint multipliers ------------------------------------

def lagrange_joint_forces(mechanism, poses: dict[str, np.ndarray], point: np.ndarray, load: np.ndarray,
                          body: str = "distal") -> tuple[dict[str, float], float]:
    """Joint forces and input torque of a generic mechanism by the principle of virtual work.

    For constraints ``g(q) = 0`` (revolute joints: point of body_a minus point of body_b; the angle
    driver: theta_body - theta_reference - input), equilibrium under applied generalised forces ``Q``
    is ``Q + J^T lambda = 0``: the multipliers of a revolute are the force the joint applies to its
    ``body_a``; the driver's multiplier is the input torque. Nothing of the link-by-link statics
    above is used: the multipliers come from :func:`fabricate.strength.statics.solve_statics`.

    Parameters
    ----------
    mechanism : fabricate.mechanism.Mechanism
        Revolute joints and one angle driver.
    poses : dict
        World pose (3,) of every body (e.g. ``Motion.poses_at(i)``).
    point, load : (2,) arrays
        Point of application (world, mm) and force (N) on ``body``.

    Returns
    -------
    (dict joint -> |force| N, torque N*mm)
    """
    # the generic statics of the strength check (one pose): no second copy of the multiplier assembly
    from fabricate.mechanism import Motion
    from fabricate.strength.statics import PointForce, solve_statics

    free = tuple(b.name for b in mechanism.bodies if b.name != mechanism.ground)
    q = np.array([[np.asarray(poses[name], dtype=np.float64) for name in free]])
    motion = Motion(inputs=np.zeros(1), body_names=mechanism.body_names, ground=mechanism.ground, free=free, q=q,
                    mechanism=mechanism)
    pose = np.asarray(poses[body], dtype=np.float64)
    local = rotation(-pose[2]) @ (np.asarray(point, dtype=np.float64) - pose[:2])
    statics = solve_statics(mechanism, motion, [PointForce(body, local, np.asarray(load, dtype=np.float64)[None, :])])
    forces = {name: float(np.hypot(*f[0])) for name, f in statics.joint_forces.items()}
    # the driver row is theta_proximal - theta_ground: its multiplier is the torque ground applies
    return forces, float(statics.driver_efforts[0, -1])


def virtual_work_torque(mechanism, motion, point_local: np.ndarray, body: str, load_of_pose,
                        index: int) -> float:
    """Input torque (N*mm) balancing a load by virtual power: T * dtheta1 + load . dm = 0.

    ``dm/dtheta1`` comes from the generic solver's velocity (per input degree, converted to rad).
    ``load_of_pose(poses) -> (point (2,), force (2,))`` gives the load at that pose.
    """
    poses = motion.poses_at(index)
    s = float(motion.inputs[index])
    vel = mechanism.velocity(poses, s)
    pose = poses[body]
    arm = transform_points(pose, point_local) - pose[:2]
    v_point = vel[body][:2] + vel[body][2] * np.array([-arm[1], arm[0]])
    driver = mechanism.drivers[0]
    dtheta = vel[driver.body][2] - vel[driver.reference][2]
    _, load = load_of_pose(poses)
    return float(-np.dot(load, v_point) / dtheta)


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (...,) of points p from segments a-b, all (..., 2)."""
    ab = b - a
    t = np.einsum("...a,...a->...", p - a, ab) / np.einsum("...a,...a->...", ab, ab)
    foot = a + np.clip(t, 0.0, 1.0)[..., None] * ab
    return np.hypot(*(p - foot).transpose(-1, *range(p.ndim - 1)))


def middle_link_clearance(batch: SixBarBatch, theta1: np.ndarray, chunk: int = 4096) -> np.ndarray:
    """Smallest distance (N,) of the joints d and e from the middle link's centreline a-b, mm.

    The pins at d (proximal-coupler) and e (coupler-distal) join links on both sides of the middle
    phalanx's layer, so the middle link must pass them with room for its own width and the pins'
    spacers; NaN where the motion cannot be assembled.
    """
    out = np.empty(len(batch))
    for start in range(0, len(batch), chunk):
        poses = assemble(batch.take(slice(start, start + chunk)), theta1)
        gap = np.minimum(segment_distance(poses.e, poses.a, poses.b), segment_distance(poses.d, poses.a, poses.b))
        gap = np.where(poses.margin >= 0.0, gap, np.nan)
        out[start:start + chunk] = np.min(gap, axis=1)
    return out
