"""Kinematics and statics of the underactuated stacked four-bar finger, driven by one push rod (its paper's
chapter).

Topology (the chapter's Fig 2.4-2.6, our names)
-----------------------------------------------
n phalanges; joint G_i is the proximal pin of phalanx i (G_1 on the palm). The finger is straight
along +x in the open pose and flexes counter-clockwise (positive relative angles ``q_i``); the palmar
side is +y. A rocker (the chapter's rigid triangle) turns about each G_i, i < n: it carries the
output arm b_i (point Q_i) and an input arm (point P_i, for rocker 1 the crank point K). Coupler c_i
joins Q_i to P_{i+1}, which is on rocker i+1 or, for the last quadrilateral, on phalanx n. So
quadrilateral i is G_i-Q_i-P_{i+1}-G_{i+1} with the sides of the chapter's eq 2.2,
``l_i + a_i - b_i - c_i = 0``: l_i the phalanx, b_i the input arm, c_i the coupler, a_i the output arm.
The push rod slides along the palm (line y = rod_y); the push link (the chapter's c in eq 2.9) joins
the rod's end S to K.

Bodies m = 3(n-1) + 3 (rod, push link, n-1 rockers, n-1 couplers, n phalanges), lower pairs
P_L = 4(n-1) + 4, so the mobility is 3m - 2 P_L = n (eq 2.1): the stroke and n-1 phalanx angles.

Positions are solved in closed form from the phalanx angles backwards (circle-circle intersections
on the open-pose branch); the stroke follows. Everything here is pure numpy.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.interpolate import CubicSpline

from fabricate.planar import cross2, perp, unit


@dataclass(frozen=True)
class FingerDesign:
    """Dimensions (mm) and arm directions at the open pose (rad, world = every phalanx frame there).

    Attributes
    ----------
    lengths : (n,) phalanx lengths G_i -> G_{i+1} (the last one to the tip).
    thickness : phalanx thickness; the palmar face is thickness/2 off the joint line.
    out_arm, out_angle : (n-1,) rocker output arms b_i (G_i -> Q_i).
    in_arm, in_angle : (n-1,) input arms a_i (G_{i+1} -> P_{i+1}) on rocker i+1 or phalanx n.
    crank, crank_angle : rocker-1 crank G_1 -> K driven by the push link.
    link : push link length S -> K.
    rod_y : y of the push-rod axis (mm).
    """

    lengths: np.ndarray
    thickness: float
    out_arm: np.ndarray
    out_angle: np.ndarray
    in_arm: np.ndarray
    in_angle: np.ndarray
    crank: float
    crank_angle: float
    link: float
    rod_y: float

    @property
    def n(self) -> int:
        return len(self.lengths)

    def joint_points_open(self) -> np.ndarray:
        """G_1..G_n and the tip at the open pose, shape (n+1, 2)."""
        x = np.concatenate([[0.0], np.cumsum(self.lengths)])
        return np.stack([x, np.zeros_like(x)], -1)

    def coupler_lengths(self) -> np.ndarray:
        """c_i from the open pose, shape (n-1,): the open pose is assembled by construction."""
        g = self.joint_points_open()
        q = g[:-2] + self.out_arm[:, None] * unit(self.out_angle)
        p = g[1:-1] + self.in_arm[:, None] * unit(self.in_angle)
        return np.hypot(*(p - q).T)

    @cached_property
    def loop_constants(self) -> tuple[np.ndarray, np.ndarray, float]:
        """Coupler lengths (n-1,), open-pose loop orientations (n-1,) and the rod's open x (mm),
        computed once per design: the closing solver evaluates thousands of poses of one design."""
        return self.coupler_lengths(), _open_orientation(self), self.rod_open_x()

    def rod_open_x(self) -> float:
        k = self.crank * unit(self.crank_angle)
        dy = k[1] - self.rod_y
        if abs(dy) >= self.link:
            raise ValueError("push link too short to reach the rod axis")
        return float(k[0] - np.sqrt(self.link**2 - dy**2))


@dataclass(frozen=True)
class FingerPose:
    """Every point of the finger at one configuration (mm, rad)."""

    q: np.ndarray            # (n,) relative phalanx angles
    theta: np.ndarray        # (n,) absolute phalanx angles
    G: np.ndarray            # (n+1, 2) joints and tip
    Q: np.ndarray            # (n-1, 2)
    P: np.ndarray            # (n-1, 2) P_2..P_n
    psi: np.ndarray          # (n-1,) rocker turn from the open pose (absolute)
    K: np.ndarray            # (2,)
    S: np.ndarray            # (2,)
    stroke: float


@dataclass(frozen=True)
class FingerPoses:
    """:class:`FingerPose` for m configurations at once (leading axis m); ``valid`` (m,) is False where
    a loop cannot close (the other entries there are meaningless)."""

    q: np.ndarray            # (m, n)
    theta: np.ndarray        # (m, n)
    G: np.ndarray            # (m, n+1, 2)
    Q: np.ndarray            # (m, n-1, 2)
    P: np.ndarray            # (m, n-1, 2)
    psi: np.ndarray          # (m, n-1)
    K: np.ndarray            # (m, 2)
    S: np.ndarray            # (m, 2)
    stroke: np.ndarray       # (m,)
    valid: np.ndarray        # (m,) bool

    def pose(self, k: int) -> FingerPose | None:
        """Configuration ``k`` as a :class:`FingerPose` (None if it does not close)."""
        if not self.valid[k]:
            return None
        return FingerPose(q=self.q[k], theta=self.theta[k], G=self.G[k], Q=self.Q[k], P=self.P[k],
                          psi=self.psi[k], K=self.K[k], S=self.S[k], stroke=float(self.stroke[k]))


def _open_orientation(design: FingerDesign) -> np.ndarray:
    g = design.joint_points_open()
    q = g[:-2] + design.out_arm[:, None] * unit(design.out_angle)
    p = g[1:-1] + design.in_arm[:, None] * unit(design.in_angle)
    return np.sign(cross2(q - g[:-2], p - q))


def finger_poses(design: FingerDesign, q: np.ndarray, psi_reference: np.ndarray | None = None) -> FingerPoses:
    """Vectorised :func:`finger_pose` over configurations ``q`` (m, n), rad.

    Of the two circle intersections for Q_i the one keeping the open pose's loop orientation
    (sign of cross(Q - G, P - Q)) is taken. With e the unit vector G_i -> P_{i+1}, the roots are
    ``base +- h perp(e)`` and that cross product is ``-+ h d``, so the root is
    ``base - sign * h * perp(e)`` and exists only for h > 0 (the loop closes with a non-zero turn).
    ``psi_reference`` (m, n-1) only unwraps the rocker angles (default: the phalanx angle theta_i).
    """
    q = np.atleast_2d(np.asarray(q, dtype=np.float64))
    m, n = q.shape
    couplers, orientation, rod_open_x = design.loop_constants
    theta = np.cumsum(q, axis=1)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    G = np.zeros((m, n + 1, 2))
    G[:, 1:, 0] = np.cumsum(design.lengths * cos_t, axis=1)
    G[:, 1:, 1] = np.cumsum(design.lengths * sin_t, axis=1)
    Q = np.zeros((m, n - 1, 2))
    P = np.zeros((m, n - 1, 2))
    psi = np.zeros((m, n - 1))
    valid = np.ones(m, dtype=bool)
    angle = design.in_angle[n - 2] + theta[:, n - 1]
    P[:, n - 2, 0] = G[:, n - 1, 0] + design.in_arm[n - 2] * np.cos(angle)
    P[:, n - 2, 1] = G[:, n - 1, 1] + design.in_arm[n - 2] * np.sin(angle)
    for i in range(n - 2, -1, -1):           # rocker i+1 (0-based i) about G[i]
        dx = P[:, i, 0] - G[:, i, 0]
        dy = P[:, i, 1] - G[:, i, 1]
        dist = np.hypot(dx, dy)
        ok = dist > 0.0
        dist = np.where(ok, dist, 1.0)
        b, c = design.out_arm[i], couplers[i]
        a = (b * b - c * c + dist * dist) / (2.0 * dist)
        h2 = b * b - a * a
        ok &= (h2 > 0.0) & (orientation[i] != 0.0)
        h = np.sqrt(np.where(ok, h2, 0.0))
        ex, ey = dx / dist, dy / dist
        Q[:, i, 0] = G[:, i, 0] + a * ex + orientation[i] * h * ey
        Q[:, i, 1] = G[:, i, 1] + a * ey - orientation[i] * h * ex
        valid &= ok
        raw = np.arctan2(Q[:, i, 1] - G[:, i, 1], Q[:, i, 0] - G[:, i, 0]) - design.out_angle[i]
        ref = psi_reference[:, i] if psi_reference is not None else theta[:, i]
        psi[:, i] = ref + np.arctan2(np.sin(raw - ref), np.cos(raw - ref))   # unwrap near ref
        if i > 0:
            angle = design.in_angle[i - 1] + psi[:, i]
            P[:, i - 1, 0] = G[:, i, 0] + design.in_arm[i - 1] * np.cos(angle)
            P[:, i - 1, 1] = G[:, i, 1] + design.in_arm[i - 1] * np.sin(angle)
    angle = design.crank_angle + psi[:, 0]
    K = design.crank * np.stack([np.cos(angle), np.sin(angle)], -1)
    rise = K[:, 1] - design.rod_y
    reach = design.link**2 - rise**2
    valid &= reach > 0.0
    S = np.stack([K[:, 0] - np.sqrt(np.where(valid, reach, 0.0)), np.full(m, design.rod_y)], -1)
    return FingerPoses(q=q, theta=theta, G=G, Q=Q, P=P, psi=psi, K=K, S=S, stroke=S[:, 0] - rod_open_x,
                       valid=valid)


def finger_pose(design: FingerDesign, q: np.ndarray, previous: FingerPose | None = None) -> FingerPose | None:
    """Solve every point from the relative phalanx angles ``q`` (n,), rad. None if a loop cannot close.

    The rockers are found from the tip backwards (circle about G_i of radius b_i meets circle about
    P_{i+1} of radius c_i); of the two roots the one with the open pose's orientation keeps the
    assembly mode. ``previous`` only helps to unwrap the rocker angles.
    """
    q = np.asarray(q, dtype=np.float64)
    ref = previous.psi[None, :] if previous is not None else None
    pose = finger_poses(design, q[None, :], ref).pose(0)
    if pose is None:
        return None
    return FingerPose(q=q, theta=pose.theta, G=pose.G, Q=pose.Q, P=pose.P, psi=pose.psi, K=pose.K,
                      S=pose.S, stroke=pose.stroke)


def stroke_gradient(design: FingerDesign, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """d(stroke)/dq_j (mm/rad), shape (n,), by central differences of :func:`finger_pose` (kept as
    the independent check of :func:`stroke_gradients` and of the force chain)."""
    q = np.asarray(q, dtype=np.float64)
    n = design.n
    stencil = q + step * np.concatenate([np.eye(n), -np.eye(n)])
    strokes = finger_poses(design, stencil).stroke
    return (strokes[:n] - strokes[n:]) / (2 * step)


def stroke_gradients(design: FingerDesign, poses: FingerPoses) -> np.ndarray:
    """d(stroke)/dq_j (mm/rad) at every configuration, shape (m, n), in closed form.

    Virtual work: a unit push on the rod with no springs needs, at joint j, exactly the moment
    ``ds/dq_j`` to be held. The force chain of :func:`contact_forces` gives that moment: push link
    force ``1 / u_SK.x``; each rocker passes the moment of its incoming link to its coupler; the
    moment about G_j of the coupler that drives the distal part (rocker j's input moment for
    j < n-1, coupler n-1's moment at P_n for the last joint). Not finite where the push link stands
    square to the rod (its dead point: the rod cannot turn the crank) or where a pose does not close.
    """
    n = poses.q.shape[1]
    u_sk = (poses.K - poses.S) / design.link                          # (m, 2)
    with np.errstate(divide="ignore", invalid="ignore"):              # inf/nan at the link's dead point
        force = u_sk / u_sk[:, :1]                                    # push link force for unit push
    arm = poses.K - poses.G[:, 0]
    grad = np.zeros_like(poses.q)
    for i in range(n - 1):
        moment_in = cross2(arm, force)                                # on rocker i about G_i
        grad[:, i] = moment_in
        coupler = poses.P[:, i] - poses.Q[:, i]
        coupler = coupler / np.hypot(coupler[:, 0], coupler[:, 1])[:, None]
        tension = moment_in / cross2(poses.Q[:, i] - poses.G[:, i], coupler)
        force = tension[:, None] * coupler
        arm = poses.P[:, i] - poses.G[:, i + 1]
    grad[:, n - 1] = cross2(arm, force)                               # coupler n-1 on phalanx n at P_n
    return grad


def transmission_ratios(pose: FingerPose) -> np.ndarray:
    """The chapter's E_i (eq 2.4-2.5): output-arm rate over input-arm rate of quadrilateral i with
    phalanx i held, shape (n-1,).

    ``A_i [theta_dot_{i+1}, phi_dot_2i] = theta_dot_i B_i`` with
    ``A_i = [[-a sin(theta_{i+1}), c sin(phi)], [a cos(theta_{i+1}), -c cos(phi)]]``,
    ``B_i = [-b sin(theta_i), b cos(theta_i)]``; E_i is the first entry of ``A_i^-1 B_i``.
    """
    n1 = len(pose.Q)
    out = np.zeros(n1)
    for i in range(n1):
        b_vec = pose.Q[i] - pose.G[i]
        a_vec = pose.P[i] - pose.G[i + 1]
        c_vec = pose.P[i] - pose.Q[i]
        a_mat = np.array([[-a_vec[1], c_vec[1]], [a_vec[0], -c_vec[0]]])
        b_rhs = np.array([-b_vec[1], b_vec[0]])
        out[i] = np.linalg.solve(a_mat, b_rhs)[0]
    return out


def crank_rate(design: FingerDesign, pose: FingerPose) -> float:
    """d(psi_1)/d(stroke) (rad/mm) of the push-rod slider-crank (eqs 2.9-2.12, derived again).

    With S = K - link u(phi_c) on the rod axis, ``ds/dpsi_1 = k sin(phi_c - psi') / cos(phi_c)``
    (psi' the crank's absolute angle). The printed eq 2.12, ``v sin(phi) / (a sin(theta_1 - phi))``,
    is the same relation with the rod axis along y; ours runs along x, as laid out here.
    """
    d = pose.K - pose.S
    phi_c = np.arctan2(d[1], d[0])
    crank_abs = design.crank_angle + pose.psi[0]
    return float(np.cos(phi_c) / (design.crank * np.sin(phi_c - crank_abs)))


def distal_rate(design: FingerDesign, pose: FingerPose) -> float:
    """dq_n/d(stroke) (rad/mm) with phalanges 1..n-1 held (eq 2.8: theta_dot_{n+1} = E_n...E_1 theta_dot_1)."""
    return float(np.prod(transmission_ratios(pose)) * crank_rate(design, pose))


def palmar_normal(theta: float) -> np.ndarray:
    """Unit normal on the palmar side (towards the flexion centre) of a phalanx at angle theta."""
    return unit(theta + np.pi / 2)


def contact_forces(design: FingerDesign, pose: FingerPose, push_force: float, spring_torque: np.ndarray,
                   contact_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normal contact forces (N) on every phalanx for a push force, by transmission through the
    two-force links (the chapter's section 2.4 force chain).

    Parameters
    ----------
    push_force : float
        Force on the rod along +x (N).
    spring_torque : (n,) array
        Return-spring torques at G_i, opposing flexion (N·mm).
    contact_points : (n, 2) array
        Where the object touches each phalanx (world, mm); the force is along -palmar normal.

    Returns
    -------
    forces : (n,) array
        Contact force magnitudes, positive pressing.
    link_forces : (n,) array
        Compression of the push link and of each coupler (N).

    Notes
    -----
    Push link: ``F_s = y_0 (u_SK . x)``. Rocker i: the moment of the incoming link force about G_i
    equals that of the outgoing coupler. Everything distal of G_i (phalanges i..n and the links they
    carry) then balances about G_i: coupler i's moment, the spring torque and the contact forces
    i..n, solved from the tip back.
    """
    n = design.n
    u_sk = (pose.K - pose.S) / design.link
    y = np.zeros(n)
    y[0] = push_force / u_sk[0]
    incoming = (pose.K - pose.G[0], y[0] * u_sk)
    coupler_dir = np.zeros((n - 1, 2))
    for i in range(n - 1):
        u = (pose.P[i] - pose.Q[i]) / np.hypot(*(pose.P[i] - pose.Q[i]))
        coupler_dir[i] = u
        moment_in = cross2(incoming[0], incoming[1])
        y[i + 1] = moment_in / cross2(pose.Q[i] - pose.G[i], u)
        if i + 1 < n - 1:
            incoming = (pose.P[i] - pose.G[i + 1], y[i + 1] * u)
    forces = np.zeros(n)
    for j in range(n - 1, -1, -1):
        if j < n - 1:
            drive = cross2(pose.Q[j] - pose.G[j], y[j + 1] * coupler_dir[j])
        else:
            drive = cross2(pose.P[n - 2] - pose.G[j], y[n - 1] * coupler_dir[n - 2])
        moment = drive - spring_torque[j]
        for m in range(j + 1, n):
            moment -= forces[m] * cross2(contact_points[m] - pose.G[j], palmar_normal(pose.theta[m]))
        forces[j] = moment / cross2(contact_points[j] - pose.G[j], palmar_normal(pose.theta[j]))
    return forces, y


def virtual_work_forces(design: FingerDesign, pose: FingerPose, push_force: float,
                        spring_torque: np.ndarray, contact_points: np.ndarray) -> np.ndarray:
    """Contact forces from virtual work: ``J^T f = F_s ds/dq - tau`` with
    ``J[m, j] = n_m . d(c_m)/dq_j = n_m . perp(c_m - G_j)`` for m >= j (used to check the force chain)."""
    n = design.n
    jac = np.zeros((n, n))
    for m in range(n):
        nm = palmar_normal(pose.theta[m])
        for j in range(m + 1):
            jac[m, j] = float(nm @ perp(contact_points[m] - pose.G[j]))
    rhs = push_force * stroke_gradient(design, pose.q) - spring_torque
    return np.linalg.solve(jac.T, rhs)


class PiecewiseLaw:
    """A driver law ``law(x, nu=0)`` made of cubic splines joined at given breaks (a kink at each).

    One interpolant through all samples smears the kink of an event over the neighbouring stroke
    intervals; split there each piece is smooth and the not-a-knot cubic is accurate to O(h^4).
    A piece of two samples is a straight line. Points of one piece closer than ``min_gap`` (mm) to
    the previous kept one are dropped (an event sample next to a grid sample would make a tiny interval).

    Parameters
    ----------
    x, y : (m,) arrays
        Strictly increasing samples (mm) and their values (rad).
    breaks : sequence of float
        Sample abscissae where the law may kink.
    """

    def __init__(self, x: np.ndarray, y: np.ndarray, breaks=(), min_gap: float = 1e-3):
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        inner = sorted(b for b in breaks if x[0] < b < x[-1])
        edges = [float(x[0]), *inner, float(x[-1])]
        self.breaks = np.array(inner)
        self.pieces = []
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            idx = np.nonzero((x >= a - 1e-12) & (x <= b + 1e-12))[0]
            keep = [idx[0]]
            for k in idx[1:-1]:
                if x[k] - x[keep[-1]] >= min_gap and x[idx[-1]] - x[k] >= min_gap:
                    keep.append(k)
            keep.append(idx[-1])
            self.pieces.append(CubicSpline(x[keep], y[keep]))

    def __call__(self, x, nu: int = 0):
        x_arr = np.asarray(x, dtype=np.float64)
        which = np.searchsorted(self.breaks, x_arr, side="right")
        out = np.empty(x_arr.shape)
        for k, piece in enumerate(self.pieces):
            mask = which == k
            if np.any(mask):
                out[mask] = piece(x_arr[mask], nu)
        return out if out.ndim else float(out)
