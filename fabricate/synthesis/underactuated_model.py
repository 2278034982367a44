"""Kinematics and statics of the push-rod driven underactuated finger of stacked four-bars (seed 001).

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

import numpy as np

from fabricate.planar import circle_circle_intersection, cross2, perp, unit


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


def _pick(points: np.ndarray | None, centre: np.ndarray, far: np.ndarray, sign: float) -> np.ndarray | None:
    """Of two circle intersections, the one that keeps the quadrilateral's open-pose orientation
    (sign of cross(Q - G, P - Q)): the same assembly mode, never the mirrored one."""
    if points is None or len(points) == 0:
        return None
    pts = np.atleast_2d(points)
    turn = cross2(pts - centre, far - pts)
    k = int(np.argmax(turn * sign))
    return pts[k] if turn[k] * sign > 0 else None


def _open_orientation(design: FingerDesign) -> np.ndarray:
    g = design.joint_points_open()
    q = g[:-2] + design.out_arm[:, None] * unit(design.out_angle)
    p = g[1:-1] + design.in_arm[:, None] * unit(design.in_angle)
    return np.sign(cross2(q - g[:-2], p - q))


def finger_pose(design: FingerDesign, q: np.ndarray, previous: FingerPose | None = None) -> FingerPose | None:
    """Solve every point from the relative phalanx angles ``q`` (n,), rad. None if a loop cannot close.

    The rockers are found from the tip backwards (circle about G_i of radius b_i meets circle about
    P_{i+1} of radius c_i); of the two roots the one with the open pose's orientation keeps the
    assembly mode. ``previous`` only helps to unwrap the rocker angles.
    """
    q = np.asarray(q, dtype=np.float64)
    n = design.n
    theta = np.cumsum(q)
    G = np.zeros((n + 1, 2))
    for i in range(n):
        G[i + 1] = G[i] + design.lengths[i] * unit(theta[i])
    c = design.coupler_lengths()
    orientation = _open_orientation(design)
    Q = np.zeros((n - 1, 2))
    P = np.zeros((n - 1, 2))
    psi = np.zeros(n - 1)
    # P_n rides on phalanx n
    P[n - 2] = G[n - 1] + design.in_arm[n - 2] * unit(design.in_angle[n - 2] + theta[n - 1])
    for i in range(n - 2, -1, -1):           # rocker i+1 (0-based i) about G[i]
        try:
            roots = circle_circle_intersection(G[i], design.out_arm[i], P[i], c[i])
        except ValueError:          # the loop cannot close here
            return None
        qi = _pick(roots, G[i], P[i], orientation[i])
        if qi is None:
            return None
        Q[i] = qi
        psi[i] = np.arctan2(*(qi - G[i])[::-1]) - design.out_angle[i]
        ref = previous.psi[i] if previous is not None else theta[i]
        psi[i] = ref + np.arctan2(np.sin(psi[i] - ref), np.cos(psi[i] - ref))   # unwrap near ref
        if i > 0:
            P[i - 1] = G[i] + design.in_arm[i - 1] * unit(design.in_angle[i - 1] + psi[i])
    K = design.crank * unit(design.crank_angle + psi[0])
    dy = K[1] - design.rod_y
    if abs(dy) >= design.link:
        return None
    S = np.array([K[0] - np.sqrt(design.link**2 - dy**2), design.rod_y])
    return FingerPose(q=q, theta=theta, G=G, Q=Q, P=P, psi=psi, K=K, S=S,
                      stroke=float(S[0] - design.rod_open_x()))


def stroke_gradient(design: FingerDesign, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """d(stroke)/dq_j (mm/rad), shape (n,), by central differences of :func:`finger_pose`."""
    base = finger_pose(design, q)
    out = np.zeros(design.n)
    for j in range(design.n):
        dq = np.zeros(design.n)
        dq[j] = step
        hi = finger_pose(design, q + dq, base)
        lo = finger_pose(design, q - dq, base)
        out[j] = (hi.stroke - lo.stroke) / (2 * step)
    return out


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
