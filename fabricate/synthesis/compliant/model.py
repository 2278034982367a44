"""Static force model of a finger of the compliant spring-hinge gripper (its paper's eqs 1-10).

Frame and names follow the paper (Fig 2): origin at the finger mount A, x horizontal pointing away
from the palm centre, y up. The root phalanx A-B (a1) hangs at the fixed angle ``alpha`` below the
mounting plate; the middle phalanx B-C (a2) turns by ``phi2`` at hinge B (large torsion spring k2);
the tip phalanx C-D (a3) turns by ``phi1`` at hinge C (small spring k1). Absolute phalanx angles are
measured clockwise from +x (downwards, i.e. closing): ``theta1 = alpha``, ``theta2 = alpha + phi2``,
``theta3 = alpha + phi1 + phi2``; a phalanx direction is ``e(t) = (cos t, -sin t)`` and its back-side
normal ``n(t) = (sin t, cos t)``.

The drive seat D-E (length c) stands on the tip at D = C + a3 e3, E = D + c n3. The two-force rod E-M
(length d) joins E to the vertical drive rod at x = l2; ``sin(gamma) = (l2 - E_x) / d`` (eq 9) and M is
above E (``cos(gamma) > 0``). The pad is the arc of radius r tangent to the tip axis at b + a3 from C
and curling towards n, so its centre is ``C + (a3 + b) e3 + r n3``; on a can of radius R (axis
vertical, in the palm centre) it touches at the centre minus r along x (eq 7).

Moments are clockwise-positive (the closing sense). With ``beta = pi + gamma - theta3`` (eq 8) the
rod's moment about C is ``Fd h1``, ``h1 = c sin(beta) - a3 cos(beta)``, and about B it is ``Fd h2``,
``h2 = h1 - a2 cos(phi1 + beta)`` (eqs 1-2); the normal force Fn of the can opposes with the arms
d11, d21 and the hover friction f (downwards on the finger) with d12, d22 (eqs 3-6). Each of these
was re-derived from the vector loop (see ``tests/test_compliant.py``, which checks the arms against
cross products of the posed points) and agrees with the printed forms.

Departure from the printed text: eq 10 prints the stroke as ``E_depth(phi) - d cos(gamma')`` with
gamma' of the straight finger, which mixes two poses. The drive rod travel is the depth of M now
minus the depth of M at the straight rest pose (phi1 = phi2 = 0); that is what we use. It only fixes
the origin of the stroke axis: forces are functions of the configuration, so F_n1, F_n2 and Delta N
do not depend on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from fabricate.errors import SpecError

#: N·mm per degree -> N·mm per radian (the paper's k·180/pi).
DEG_PER_RAD = 180.0 / np.pi


@dataclass(frozen=True)
class GripperGeometry:
    """Finger dimensions (mm) and the root angle ``alpha`` (rad). Names as in the paper."""

    a1: float
    a2: float
    a3: float
    b: float
    c: float
    d: float
    l1: float
    l2: float
    r: float
    alpha: float


@dataclass(frozen=True)
class Springs:
    """Torsion springs: rates ``k1`` (hinge C), ``k2`` (hinge B) in N·mm/deg, preloads in rad."""

    k1: float
    k2: float
    phi01: float
    phi02: float


@dataclass(frozen=True)
class Load:
    """The grasped can: diameter (mm), mass (kg), static friction, the paper's factor s, g (m/s^2)."""

    diameter: float
    mass: float
    mu: float
    safety: float
    g: float = 9.8

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def hover_force(self) -> float:
        """F_n2 = m g / (3 mu s) (N): friction mu F_n2 at each of three fingers carries mg/(3 s)."""
        return self.mass * self.g / (3.0 * self.mu * self.safety)


@dataclass(frozen=True)
class FingerState:
    """Every quantity of eqs 1-10 at a set of configurations (arrays of one shape, mm / rad)."""

    phi1: np.ndarray
    phi2: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    E: np.ndarray
    M: np.ndarray
    pad_centre: np.ndarray
    gamma: np.ndarray
    beta: np.ndarray
    h1: np.ndarray
    h2: np.ndarray
    d11: np.ndarray
    d21: np.ndarray
    d12: np.ndarray
    d22: np.ndarray
    contact_radius: np.ndarray
    stroke: np.ndarray


def _e(t: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(t), -np.sin(t)], -1)


def _n(t: np.ndarray) -> np.ndarray:
    return np.stack([np.sin(t), np.cos(t)], -1)


def _rod_top(geom: GripperGeometry, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """gamma (eq 9) and M for seat points E (..., 2); NaN where the rod cannot reach x = l2."""
    with np.errstate(invalid="ignore"):
        gamma = np.arcsin((geom.l2 - E[..., 0]) / geom.d)
    M = E + geom.d * np.stack([np.sin(gamma), np.cos(gamma)], -1)
    return gamma, M


def rest_drive_depth(geom: GripperGeometry) -> float:
    """y of M at the straight rest pose phi1 = phi2 = 0 (mm); the stroke is measured from here."""
    t = np.asarray(geom.alpha)
    E = (geom.a1 + geom.a2 + geom.a3) * _e(t) + geom.c * _n(t)
    return float(_rod_top(geom, E)[1][1])


def finger_state(geom: GripperGeometry, phi1: np.ndarray | float, phi2: np.ndarray | float,
                 can_radius: float | None = None) -> FingerState:
    """Positions, angles and moment arms of eqs 1-10 at configurations (phi1, phi2) (rad, any shape)."""
    phi1 = np.asarray(phi1, dtype=np.float64)
    phi2 = np.asarray(phi2, dtype=np.float64)
    phi1, phi2 = np.broadcast_arrays(phi1, phi2)
    t1 = np.full_like(phi1, geom.alpha)
    t2 = geom.alpha + phi2
    t3 = geom.alpha + phi1 + phi2
    B = geom.a1 * _e(t1)
    C = B + geom.a2 * _e(t2)
    D = C + geom.a3 * _e(t3)
    E = D + geom.c * _n(t3)
    pad = C + (geom.a3 + geom.b) * _e(t3) + geom.r * _n(t3)
    gamma, M = _rod_top(geom, E)
    beta = np.pi + gamma - t3                                                  # eq 8
    h1 = geom.c * np.sin(beta) - geom.a3 * np.cos(beta)                        # eq 1
    h2 = h1 - geom.a2 * np.cos(phi1 + beta)                                    # eq 2
    d11 = (geom.b + geom.a3) * np.sin(t3) - geom.r * np.cos(t3)                # eq 3
    d21 = geom.a2 * np.sin(t2) + d11                                           # eq 4
    d12 = -(geom.b + geom.a3) * np.cos(t3) + geom.r - geom.r * np.sin(t3)      # eq 5
    d22 = -geom.a2 * np.cos(t2) + d12                                          # eq 6
    contact_radius = geom.l1 + pad[..., 0] - geom.r                            # eq 7 (R of the can)
    stroke = rest_drive_depth(geom) - M[..., 1]                                # eq 10 (see module doc)
    return FingerState(phi1, phi2, B, C, D, E, M, pad, gamma, beta, h1, h2, d11, d21, d12, d22,
                       contact_radius, stroke)


def spring_torques(springs: Springs, phi1: np.ndarray | float,
                   phi2: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Left sides of eqs 1-6: ``k * 180/pi * (phi + phi0)`` at hinges C and B (N·mm)."""
    s1 = springs.k1 * DEG_PER_RAD * (np.asarray(phi1) + springs.phi01)
    s2 = springs.k2 * DEG_PER_RAD * (np.asarray(phi2) + springs.phi02)
    return s1, s2


def static_forces(state: FingerState, s1: np.ndarray, s2: np.ndarray,
                  friction: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Solve the two torque balances for (Fn, Fd) (N) at given spring torques.

    ``friction = 0``: eqs 3-4 (static load). ``friction = mu``: eqs 5-6 with f = mu Fn (hover). The
    rod force Fd > 0 means compression (the rod pushes).
    """
    den = (state.d11 * state.h2 - state.d21 * state.h1) + friction * (state.d12 * state.h2
                                                                        - state.d22 * state.h1)
    with np.errstate(divide="ignore", invalid="ignore"):
        fn = (s2 * state.h1 - s1 * state.h2) / den
        fd = (s1 + fn * (state.d11 + friction * state.d12)) / state.h1
    return fn, fd


def delta_n_factor(state: FingerState, mu: float) -> np.ndarray:
    """F_n1 / F_n2 - 1 at a configuration: the spring torques cancel, so Delta N = F_n2 * this."""
    den_s = state.d11 * state.h2 - state.d21 * state.h1
    with np.errstate(divide="ignore", invalid="ignore"):
        return mu * (state.d12 * state.h2 - state.d22 * state.h1) / den_s


def phi1_on_can(geom: GripperGeometry, phi2: np.ndarray | float, can_radius: float) -> np.ndarray:
    """phi1 that puts the pad on the can for each phi2 (eq 7 solved in closed form), NaN if none.

    Eq 7 reads ``(b + a3) cos t3 + r sin t3 = W``; with rho = hypot(b + a3, r), psi = atan2(r, b + a3)
    this is ``rho cos(t3 - psi) = W``. The root ``t3 = psi + acos(W / rho)`` is the branch with the tip
    turned in towards the can; the other one points the tip up and away.
    """
    phi2 = np.asarray(phi2, dtype=np.float64)
    t2 = geom.alpha + phi2
    w = can_radius - geom.l1 - geom.a1 * np.cos(geom.alpha) - geom.a2 * np.cos(t2) + geom.r
    rho = np.hypot(geom.b + geom.a3, geom.r)
    psi = np.arctan2(geom.r, geom.b + geom.a3)
    with np.errstate(invalid="ignore"):
        t3 = psi + np.arccos(w / rho)
    return t3 - t2


@dataclass(frozen=True)
class ContactPath:
    """The finger's configurations with the pad on the can, in order of increasing stroke.

    ``state`` holds eqs 1-10 at every sample; ``valid`` marks the physical branch: the rod reaches the
    drive (M above E), both hinges off their stops (phi >= 0), the touching point on the pad arc
    (tip pointing inwards, 90 deg <= theta3 <= 90 deg + pad arc), both force determinants positive.
    Samples stop at the first invalid one after the valid run, or where the stroke stops increasing.
    """

    phi2: np.ndarray
    state: FingerState
    geom: GripperGeometry
    can_radius: float
    mu: float


def contact_path(geom: GripperGeometry, can_radius: float, mu: float, n: int = 721,
                 phi2_max: float = np.pi / 2, pad_arc: float = np.pi / 2) -> ContactPath:
    """Sample the physical contact branch over ``phi2`` in [0, phi2_max] (rad).

    Returns an empty path (zero samples) when the pad cannot reach the can on the physical branch.
    """
    phi2 = np.linspace(0.0, phi2_max, n)
    phi1 = phi1_on_can(geom, phi2, can_radius)
    st = finger_state(geom, phi1, phi2)
    t3 = geom.alpha + phi1 + phi2
    den_s = st.d11 * st.h2 - st.d21 * st.h1
    den_h = den_s + mu * (st.d12 * st.h2 - st.d22 * st.h1)
    ok = (np.isfinite(phi1) & np.isfinite(st.gamma) & (phi1 >= 0.0) & (t3 >= np.pi / 2)
          & (t3 <= np.pi / 2 + pad_arc) & (den_s > 0) & (den_h > 0) & (st.h1 > 0))
    first = int(np.argmax(ok)) if ok.any() else n
    stop = first
    while stop < n and ok[stop] and (stop == first or st.stroke[stop] > st.stroke[stop - 1]):
        stop += 1
    keep = slice(first, stop)
    sub = FingerState(*(getattr(st, f)[keep] for f in FingerState.__dataclass_fields__))
    return ContactPath(phi2=phi2[keep], state=sub, geom=geom, can_radius=can_radius, mu=float(mu))


@dataclass(frozen=True)
class Grasp:
    """The grasp where the hover force reaches F_n2, and the static force at the same stroke."""

    phi1: float
    phi2: float
    stroke: float
    fn_static: float
    fn_hover: float
    fd_static: float
    fd_hover: float
    delta_n: float
    contact_stroke: float


def hover_force_on_path(path: ContactPath, springs: Springs, mu: float) -> np.ndarray:
    """Hover normal force (N) along a contact path for given springs (eqs 5-6 with f = mu Fn)."""
    s1, s2 = spring_torques(springs, path.state.phi1, path.state.phi2)
    return static_forces(path.state, s1, s2, friction=mu)[0]


def solve_grasp(path: ContactPath, springs: Springs, load: Load) -> Grasp | None:
    """The paper's procedure: find the stroke where the hover force first reaches F_n2 (eqs 5-7,
    8-10), then the static force F_n1 at that stroke (eqs 3-4). None if it is never reached, if it
    is reached with a hinge on its stop (first sample) or with the rod pulling.

    Raises
    ------
    SpecError
        ``load.mu`` is not the friction the path was sampled with: the path's validity (the hover
        determinant > 0) depends on it, and off the path the root search can land on that determinant's
        pole (a hover force of 2.2e11 N was returned).
    """
    if load.mu != path.mu:
        raise SpecError("load.mu", f"the contact path was sampled with mu = {path.mu:g}, the load has "
                                   f"mu = {load.mu:g}; sample the path with the load's friction")
    if len(path.phi2) < 2:
        return None
    fn2 = load.hover_force
    fh = hover_force_on_path(path, springs, load.mu)
    above = fh >= fn2
    if not above.any():
        return None
    i = int(np.argmax(above))
    if i == 0:
        return None

    def excess(p2: float) -> float:
        st = finger_state(path.geom, phi1_on_can(path.geom, p2, path.can_radius), p2)
        s1, s2 = spring_torques(springs, st.phi1, st.phi2)
        return float(static_forces(st, s1, s2, friction=load.mu)[0]) - fn2

    p2 = brentq(excess, path.phi2[i - 1], path.phi2[i], xtol=1e-14, rtol=1e-14)
    st = finger_state(path.geom, phi1_on_can(path.geom, p2, path.can_radius), p2)
    s1, s2 = spring_torques(springs, st.phi1, st.phi2)
    fnh, fdh = static_forces(st, s1, s2, friction=load.mu)
    fns, fds = static_forces(st, s1, s2)
    if fdh <= 0 or fds <= 0:
        return None
    # first touch: where the static force along the path turns positive (the free closing meets the can)
    fs_path = static_forces(path.state, *spring_torques(springs, path.state.phi1, path.state.phi2))[0]
    touching = np.nonzero(fs_path[: i + 1] >= 0)[0]
    contact_stroke = float(path.state.stroke[touching[0]]) if touching.size else float(st.stroke)
    return Grasp(phi1=float(st.phi1), phi2=float(p2), stroke=float(st.stroke), fn_static=float(fns),
                 fn_hover=float(fnh), fd_static=float(fds), fd_hover=float(fdh),
                 delta_n=float(fns - fnh), contact_stroke=contact_stroke)


def grasp_force_curve(path: ContactPath, springs: Springs, mu: float) -> tuple[np.ndarray, np.ndarray,
                                                                              np.ndarray]:
    """Grasp force against stroke on the can (paper Fig 3): (stroke mm, static Fn N, hover Fn N),
    from the first touch (static Fn = 0) on; empty arrays when the finger never presses the can."""
    st = path.state
    s1, s2 = spring_torques(springs, st.phi1, st.phi2)
    fs = static_forces(st, s1, s2)[0]
    fh = static_forces(st, s1, s2, friction=mu)[0]
    pressing = np.nonzero(fs >= 0)[0]
    if pressing.size == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    keep = slice(int(pressing[0]), None)
    return st.stroke[keep], fs[keep], fh[keep]
