"""Underactuated stacked four-bar finger kernel (``synthesis/underactuated/model.py``) against independent computations.

Every expected value comes from code in this file that does not call the function under test:

* ``_open`` builds the open pose by hand (G_i on +x, Q_i = G_i + b_i u(out_i), P_{i+1} = G_{i+1} + a_i u(in_i));
* ``_reference`` solves every pose again with the law of cosines (angle at G_i between G_i->P_{i+1} and
  G_i->Q_i), picking the root on the same side of the line G_i->P_{i+1} as at the open pose, and closes
  the push link by Pythagoras; coupler and push-link lengths can be overridden, so the link
  compressions follow from virtual work (``-F dS_x/dc`` at fixed phalanx angles);
* contact forces come from virtual work with finite differences of the contact points (carried
  rigidly by their phalanges) and of the reference stroke;
* :class:`PiecewiseLaw` is compared with ``scipy.interpolate.CubicSpline`` built on the nodes we count
  by hand.

A few boundary tests need a configuration that sits *exactly* on a validity limit (tangent circles,
push link square to the rod, a horizontal coupler): they bisect to the limit and then walk a few dozen
floating-point neighbours for the one where the quantity, evaluated from the returned points with the
model's own formula, is exactly zero.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from fabricate.synthesis.underactuated.model import (
    FingerDesign,
    FingerPose,
    FingerPoses,
    PiecewiseLaw,
    contact_forces,
    finger_pose,
    finger_poses,
    stroke_gradient,
    stroke_gradients,
)


def _design(lengths, out_arm, out_deg, in_arm, in_deg, crank, crank_deg, link, rod_y, thickness=12.0) -> FingerDesign:
    return FingerDesign(np.array(lengths, float), thickness, np.array(out_arm, float), np.radians(out_deg),
                        np.array(in_arm, float), np.radians(in_deg), float(crank), math.radians(crank_deg),
                        float(link), float(rod_y))


# the template's finger (templates/finger_underactuated.toml, typed here) and others whose arms differ; PALMAR's
# second rocker points its output arm 20 deg to the palmar side, a loop orientation that depends on where G_2 is
TEMPLATE = _design([58, 34, 23], [11, 11], [-90, -90], [12, 8], [-60, -45], 14, -120, 30, -20, 14.0)
SKEW = _design([40, 27, 19], [9, 6.5], [-75, -110], [11, 7], [-40, -65], 13, -130, 28, -18)
FOUR = _design([45, 30, 22, 16], [10, 8, 6], [-95, -80, -100], [11, 8.5, 6], [-55, -35, -70], 12, -115, 26, -17)
TWO = _design([40, 25], [10], [-100], [9], [-50], 12, -120, 14, -18)
PALMAR = _design([45, 30, 20], [9, 8], [-80, 20], [10, 20], [-50, 80], 12, -120, 26, -17)


def _random_design(seed: int, n: int) -> FingerDesign:
    """Arms in every direction (so the open-pose loop orientation takes both signs); rod reachable."""
    rng = np.random.default_rng(seed)
    crank, crank_angle, link = rng.uniform(5, 15), rng.uniform(-np.pi, np.pi), rng.uniform(20, 40)
    return FingerDesign(rng.uniform(15, 60, n), 10.0, rng.uniform(5, 15, n - 1), rng.uniform(-np.pi, np.pi, n - 1),
                        rng.uniform(5, 15, n - 1), rng.uniform(-np.pi, np.pi, n - 1), crank, crank_angle, link,
                        crank * math.sin(crank_angle) - rng.uniform(0.2, 0.8) * link)


RANDOM = [_random_design(100 * n + s, n) for n in (2, 3, 4) for s in range(6)]
DESIGNS = [TEMPLATE, SKEW, FOUR, TWO, PALMAR, *RANDOM]


# ---------------------------------------------------------------- independent reference


def _u(t: float) -> np.ndarray:
    return np.array([math.cos(t), math.sin(t)])


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _open(d: FingerDesign):
    """Open pose by hand: joints on +x, arms at their open angles; couplers |Q_i P_{i+1}|; the side of
    Q_i relative to the line G_i -> P_{i+1} (+1 left, -1 right)."""
    n = len(d.lengths)
    G = [np.array([float(sum(d.lengths[:i])), 0.0]) for i in range(n + 1)]
    Q = [G[i] + d.out_arm[i] * _u(d.out_angle[i]) for i in range(n - 1)]
    P = [G[i + 1] + d.in_arm[i] * _u(d.in_angle[i]) for i in range(n - 1)]
    c = [math.dist(Q[i], P[i]) for i in range(n - 1)]
    side = [math.copysign(1.0, _cross(P[i] - G[i], Q[i] - G[i])) for i in range(n - 1)]
    return np.array(G), np.array(Q), np.array(P), c, side


def _phalanges(d: FingerDesign, q):
    theta = np.cumsum(np.asarray(q, float))
    G = [np.zeros(2)]
    for i in range(len(d.lengths)):
        G.append(G[-1] + d.lengths[i] * _u(theta[i]))
    return np.array(G), theta


def _reference(d: FingerDesign, q, couplers=None, link=None):
    """(pose dict, failed) for phalanx angles q. failed is None, a loop index or 'link'."""
    n = len(d.lengths)
    _, _, _, c_open, side = _open(d)
    c = c_open if couplers is None else couplers
    link = d.link if link is None else link
    G, theta = _phalanges(d, q)
    P, Q, psi = [None] * (n - 1), [None] * (n - 1), [None] * (n - 1)
    P[n - 2] = G[n - 1] + d.in_arm[n - 2] * _u(d.in_angle[n - 2] + theta[n - 1])
    for i in range(n - 2, -1, -1):
        v = P[i] - G[i]
        dist, b = math.hypot(*v), d.out_arm[i]
        if not abs(b - c[i]) < dist < b + c[i]:
            return None, i
        gamma = math.acos((b * b + dist * dist - c[i] ** 2) / (2 * b * dist))
        Q[i] = G[i] + b * _u(math.atan2(v[1], v[0]) + side[i] * gamma)
        raw = math.atan2(Q[i][1] - G[i][1], Q[i][0] - G[i][0]) - d.out_angle[i]
        psi[i] = raw + 2 * math.pi * round((theta[i] - raw) / (2 * math.pi))     # nearest to theta_i
        if i > 0:
            P[i - 1] = G[i] + d.in_arm[i - 1] * _u(d.in_angle[i - 1] + psi[i])
    K = d.crank * _u(d.crank_angle + psi[0])
    rise = K[1] - d.rod_y
    if abs(rise) >= link:
        return None, "link"
    S = np.array([K[0] - math.sqrt(link**2 - rise**2), d.rod_y])
    K0 = d.crank * _u(d.crank_angle)
    s_open = K0[0] - math.sqrt(d.link**2 - (K0[1] - d.rod_y) ** 2)
    return dict(G=G, Q=np.array(Q), P=np.array(P), psi=np.array(psi), K=K, S=S, theta=theta,
                stroke=S[0] - s_open), None


def _ref_stroke_gradient(d: FingerDesign, q, h=1e-5) -> np.ndarray:
    q = np.asarray(q, float)
    out = np.zeros(len(q))
    for j in range(len(q)):
        e = np.zeros(len(q))
        e[j] = h
        out[j] = (_reference(d, q + e)[0]["stroke"] - _reference(d, q - e)[0]["stroke"]) / (2 * h)
    return out


def _ulp_walk(t: float, count: int) -> np.ndarray:
    """t and its `count` floating-point neighbours on each side."""
    up, dn, out = t, t, [t]
    for _ in range(count):
        up, dn = np.nextafter(up, np.inf), np.nextafter(dn, -np.inf)
        out += [up, dn]
    return np.array(sorted(out))


def _bisect(f, lo: float, hi: float) -> float:
    f_lo = f(lo)
    assert f(hi) != f_lo
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if f(mid) == f_lo:
            lo = mid
        else:
            hi = mid
    return lo


def _h2(d: FingerDesign, poses: FingerPoses, i: int) -> np.ndarray:
    """Squared half-chord of loop i's circle intersection, from the returned G_i and P_{i+1} with the
    model's formula (used only to *find* an input on the tangency)."""
    dx = poses.P[:, i, 0] - poses.G[:, i, 0]
    dy = poses.P[:, i, 1] - poses.G[:, i, 1]
    dist = np.hypot(dx, dy)
    b, c = d.out_arm[i], d.coupler_lengths()[i]
    a = (b * b - c * c + dist * dist) / (2.0 * dist)
    return b * b - a * a


def _reach(d: FingerDesign, poses: FingerPoses) -> np.ndarray:
    """link^2 - (K_y - rod_y)^2 from the returned K (only to find an input on the push link's limit)."""
    rise = poses.K[:, 1] - d.rod_y
    return d.link**2 - rise**2


# ---------------------------------------------------------------- design helpers


def test_open_joints_and_couplers_by_hand():
    """SKEW (all four arms different): G = (0,0), (40,0), (67,0), (86,0); c_1 = |G_2 + 11 u(-40) - 9 u(-75)|,
    c_2 = |G_3 + 7 u(-65) - G_2 - 6.5 u(-110)| (degrees), written out with cos/sin; 1e-12 mm. A swapped arm
    or index changes them by millimetres. Shapes (n+1, 2) and (n-1,) for n = 2, 3, 4."""
    r = math.radians
    assert np.allclose(SKEW.joint_points_open(), [[0, 0], [40, 0], [67, 0], [86, 0]], rtol=0, atol=1e-12)
    c1 = math.hypot(40 + 11 * math.cos(r(-40)) - 9 * math.cos(r(-75)), 11 * math.sin(r(-40)) - 9 * math.sin(r(-75)))
    c2 = math.hypot(27 + 7 * math.cos(r(-65)) - 6.5 * math.cos(r(-110)),
                    7 * math.sin(r(-65)) - 6.5 * math.sin(r(-110)))
    assert np.allclose(SKEW.coupler_lengths(), [c1, c2], rtol=0, atol=1e-12)
    for d in (TWO, SKEW, FOUR):
        n = len(d.lengths)
        assert d.joint_points_open().shape == (n + 1, 2)
        assert d.coupler_lengths().shape == (n - 1,)
        assert np.allclose(d.coupler_lengths(), _open(d)[3], rtol=0, atol=1e-12)
        assert np.allclose(d.joint_points_open(), _open(d)[0], rtol=0, atol=1e-12)


def test_rod_open_x_by_hand_and_at_the_reach_limit():
    """rod_open_x = K_x - sqrt(link^2 - (K_y - rod_y)^2), K = crank u(crank_angle) (1e-12 mm). With the crank
    along +x (K = (10, 0) exactly) and the rod exactly one link length below or above K the link can only
    stand square to the rod: the code raises ValueError for |dy| >= link, so equality raises too; a rod
    2^-30 mm closer still gives the Pythagorean value."""
    for d in DESIGNS:
        k = d.crank * _u(d.crank_angle)
        assert d.rod_open_x() == pytest.approx(k[0] - math.sqrt(d.link**2 - (k[1] - d.rod_y) ** 2), abs=1e-12)
    for rod_y in (-25.0, 25.0, -25.5):
        d = dataclasses.replace(TEMPLATE, crank=10.0, crank_angle=0.0, link=25.0, rod_y=rod_y)
        with pytest.raises(ValueError, match="push link too short"):
            d.rod_open_x()
    d = dataclasses.replace(TEMPLATE, crank=10.0, crank_angle=0.0, link=25.0, rod_y=-25.0 + 2.0**-30)
    assert d.rod_open_x() == pytest.approx(10.0 - math.sqrt(25.0**2 - (25.0 - 2.0**-30) ** 2), abs=1e-12)


# ---------------------------------------------------------------- positions


@pytest.mark.parametrize("d", DESIGNS, ids=lambda d: f"n{len(d.lengths)}")
def test_open_pose_is_the_hand_built_one(d):
    """At q = 0 every point is the hand-built open pose (the coupler lengths are taken from it, so it
    closes on the open-pose branch by construction): G, Q, P to 1e-9 mm, rocker turns 0 and stroke 0
    (1e-9). The random designs point their arms all round, so each loop's orientation takes both signs:
    a wrong sign picks the mirror root and moves Q_i by millimetres."""
    n = len(d.lengths)
    G, Q, P, _, _ = _open(d)
    poses = finger_poses(d, np.zeros((1, n)))
    assert poses.valid[0]
    assert np.allclose(poses.G[0], G, rtol=0, atol=1e-9)
    assert np.allclose(poses.Q[0], Q, rtol=0, atol=1e-9)
    assert np.allclose(poses.P[0], P, rtol=0, atol=1e-9)
    assert np.allclose(poses.psi[0], 0.0, rtol=0, atol=1e-9)
    assert abs(poses.stroke[0]) < 1e-9
    assert np.allclose(poses.K[0], d.crank * _u(d.crank_angle), rtol=0, atol=1e-9)


@pytest.mark.parametrize("d", DESIGNS, ids=lambda d: f"n{len(d.lengths)}")
def test_poses_match_the_law_of_cosines_solver(d):
    """At 40 random configurations (|q| < 0.6 rad) validity agrees with the reference and every point,
    rocker turn (unwrapped nearest theta_i, the documented default) and the stroke agree to 1e-9."""
    n = len(d.lengths)
    qs = np.random.default_rng(n + len(RANDOM)).uniform(-0.6, 0.6, (40, n))
    poses = finger_poses(d, qs)
    checked = 0
    for k, q in enumerate(qs):
        ref, failed = _reference(d, q)
        assert poses.valid[k] == (failed is None), (q, failed)
        if ref is None:
            continue
        checked += 1
        for name in ("G", "Q", "P", "K", "S", "psi", "theta"):
            assert np.allclose(getattr(poses, name)[k], ref[name], rtol=0, atol=1e-9), name
        assert abs(poses.stroke[k] - ref["stroke"]) < 1e-9
    assert checked >= 8


def test_every_loop_closes_at_valid_poses():
    """Loop closure on the returned points (1e-9 mm / rad): |Q_i - P_{i+1}| = hand coupler c_i,
    |Q_i - G_i| = b_i at angle out_i + psi_i, |P_{i+1} - G_{i+1}| = a_i at angle in_i + psi_{i+1} (phalanx n:
    in_{n-1} + theta_n), G_{i+1} - G_i = l_i u(q_1 + ... + q_i), |S - K| = link, S_y = rod_y,
    K = crank u(crank_angle + psi_1), stroke = S_x - S_x(open)."""
    for d in (TEMPLATE, SKEW, FOUR, TWO):
        n = len(d.lengths)
        c = _open(d)[3]
        qs = np.random.default_rng(5).uniform(-0.3, 1.2, (60, n))
        poses = finger_poses(d, qs)
        assert poses.valid.sum() >= 20
        for k in np.nonzero(poses.valid)[0]:
            G, Q, P, psi, K, S = (getattr(poses, f)[k] for f in ("G", "Q", "P", "psi", "K", "S"))
            theta = np.cumsum(qs[k])
            for i in range(n):
                assert np.allclose(G[i + 1] - G[i], d.lengths[i] * _u(theta[i]), rtol=0, atol=1e-9)
            for i in range(n - 1):
                assert abs(math.dist(Q[i], P[i]) - c[i]) < 1e-9
                assert np.allclose(Q[i] - G[i], d.out_arm[i] * _u(d.out_angle[i] + psi[i]), rtol=0, atol=1e-9)
                turn = psi[i + 1] if i + 1 < n - 1 else theta[n - 1]
                assert np.allclose(P[i] - G[i + 1], d.in_arm[i] * _u(d.in_angle[i] + turn), rtol=0, atol=1e-9)
            assert np.allclose(K, d.crank * _u(d.crank_angle + psi[0]), rtol=0, atol=1e-9)
            assert abs(math.dist(S, K) - d.link) < 1e-9 and S[1] == d.rod_y
            assert abs(poses.stroke[k] - (S[0] - d.rod_open_x())) < 1e-12


def test_poses_stay_on_the_open_branch():
    """Continuity of the assembly mode: at every valid pose each quadrilateral's orientation
    sign(cross(Q_i - G_i, P_{i+1} - Q_i)) is the one of the hand-built open pose (signs of both kinds
    occur among these designs, checked below)."""
    seen = set()
    for d in DESIGNS:
        n = len(d.lengths)
        G0, Q0, P0, _, _ = _open(d)
        open_sign = [math.copysign(1.0, _cross(Q0[i] - G0[i], P0[i] - Q0[i])) for i in range(n - 1)]
        seen.update(open_sign)
        poses = finger_poses(d, np.random.default_rng(9).uniform(-0.8, 0.8, (50, n)))
        for k in np.nonzero(poses.valid)[0]:
            for i in range(n - 1):
                g, qq, p = poses.G[k, i], poses.Q[k, i], poses.P[k, i]
                assert math.copysign(1.0, _cross(qq - g, p - qq)) == open_sign[i]
    assert seen == {-1.0, 1.0}


def test_valid_mask_is_the_and_of_every_loop_and_the_push_link():
    """TEMPLATE configurations chosen with the reference: only the distal loop fails (q_3 = -2.5: P_3
    swings out of reach of coupler 2), only the proximal loop fails, only the push link fails; next to
    valid ones in one batch. The mask is False exactly there, whatever the other loops say."""
    cases = {(0.0, 0.0, -2.5): 1, (0.0, -2.0, 0.0): 0, (2.4, 0.7, 0.1): "link", (0.3, 0.2, 0.1): None,
             (0.0, 0.0, 0.0): None, (1.0, 1.0, 1.0): None}
    qs = np.array(list(cases))
    for q, failed in cases.items():
        assert _reference(TEMPLATE, q)[1] == failed
    valid = finger_poses(TEMPLATE, qs).valid
    assert valid.dtype == bool
    assert valid.tolist() == [f is None for f in cases.values()]
    # the same configurations alone and in another order
    for k in (2, 0, 1, 3):
        assert finger_poses(TEMPLATE, qs[k]).valid.tolist() == [list(cases.values())[k] is None]


def test_tangent_loop_is_invalid_and_its_neighbour_valid():
    """Two-phalanx finger, q_1 = 1: along q_2 loop 1 opens up at a tangency (coupler circle touching the
    rocker circle). At a q_2 where h^2 (evaluated from the returned points) is exactly 0 the root is a
    double one with no turn: the docstring's "exists only for h > 0" makes the pose invalid; a
    neighbour with h^2 ~ 1e-13 > 0 is valid and agrees with the reference solver (1e-6 mm: the
    reference's acos is ill-conditioned at a tangency)."""
    zero = positive = 0
    for q1 in (1.0, 1.1, 1.2, 0.95):
        t = _bisect(lambda s, q1=q1: bool(_h2(TWO, finger_poses(TWO, np.array([q1, s])), 0)[0] > 0), -1.6, -0.8)
        ts = _ulp_walk(t, 40)
        poses = finger_poses(TWO, np.stack([np.full_like(ts, q1), ts], -1))
        h2 = _h2(TWO, poses, 0)
        assert np.all(_reach(TWO, poses) > 1.0)          # the push link is far from its limit here
        assert not poses.valid[h2 <= 0].any()
        assert poses.valid[h2 > 0].all()
        zero += int(np.sum(h2 == 0))
        near = np.nonzero((h2 > 0) & (h2 < 1e-9))[0]
        positive += len(near)
        for k in near[:2]:
            ref, _ = _reference(TWO, poses.q[k])
            if ref is not None:
                assert np.allclose(poses.Q[k], ref["Q"], rtol=0, atol=1e-6)
    assert positive > 0
    if zero == 0:  # an exact tie depends on the platform's libm rounding: not probed here, not passed
        pytest.skip("no q_2 with h^2 exactly 0 on this platform's floating-point rounding")


def test_push_link_at_full_reach_is_invalid_and_its_neighbour_valid():
    """Two-phalanx finger: where the crank lifts K exactly one link length above the rod (link^2 -
    rise^2 == 0 from the returned K) the link stands square to the rod and the pose is invalid (the
    rod cannot move the crank; the model needs reach > 0). The neighbours with reach ~ 1e-12 are
    valid, S = (K_x - sqrt(reach), rod_y) to 1e-9 mm."""
    zero = near = 0
    for q1 in (0.3, 0.45, 0.5, 0.55, 0.35):
        t = _bisect(lambda s, q1=q1: bool(_reach(TWO, finger_poses(TWO, np.array([q1, s])))[0] > 0), -1.05, -0.3)
        ts = _ulp_walk(t, 40)
        poses = finger_poses(TWO, np.stack([np.full_like(ts, q1), ts], -1))
        reach = _reach(TWO, poses)
        assert np.all(_h2(TWO, poses, 0) > 1.0)             # the loop is far from its tangency here
        assert not poses.valid[reach <= 0].any()
        assert poses.valid[reach > 0].all()
        zero += int(np.sum(reach == 0))
        for k in np.nonzero((reach > 0) & (reach < 1e-9))[0]:
            near += 1
            assert abs(poses.S[k, 0] - (poses.K[k, 0] - math.sqrt(reach[k]))) < 1e-9
    assert near > 0
    if zero == 0:  # an exact tie depends on the platform's libm rounding: not probed here, not passed
        pytest.skip("no q with link^2 - rise^2 exactly 0 on this platform's floating-point rounding")


def test_coupler_end_on_the_rocker_pivot_is_invalid_without_warnings():
    """P_2 exactly on G_1: the coupler circle is concentric with the rocker circle, no intersection. To hit
    it exactly in floating point the input arm is written as length -20 at 0 deg (the same arm as +20 at
    180 deg): with q = (0, 0) G_2 = (20, 0) and P_2 = G_2 - 20 (1, 0) = (0, 0). The open pose (arm at
    -60 deg -> 120 deg with the sign) is an equilateral loop, b = c = 20. The pose must be invalid and,
    like every batch evaluation, must not raise floating-point warnings (no division by the zero
    distance); the valid neighbours agree with the reference."""
    d = _design([20, 15], [20], [0], [-20], [-60], 10, -120, 20, -15)
    assert abs(d.coupler_lengths()[0] - 20.0) < 1e-12
    qs = np.array([[0.0, math.radians(60)], [0.0, math.radians(60) - 0.2], [0.1, math.radians(60) - 0.1]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        poses = finger_poses(d, qs)
    assert np.array_equal(poses.P[0, 0], [0.0, 0.0])
    assert poses.valid.tolist() == [False, True, True]
    for k in (1, 2):
        assert np.allclose(poses.Q[k], _reference(d, qs[k])[0]["Q"], rtol=0, atol=1e-9)


def test_scaling_the_design_scales_every_point_exactly():
    """All lengths times 2^-7 (a finger drawn in other units): points, stroke and S scale by exactly 2^-7
    (a power-of-two factor commutes with rounding), angles and validity are unchanged. Arms, distances
    and the link's reach all fall below 1 mm^2 there."""
    k = 2.0**-7
    small = dataclasses.replace(TEMPLATE, lengths=TEMPLATE.lengths * k, thickness=TEMPLATE.thickness * k,
                                out_arm=TEMPLATE.out_arm * k, in_arm=TEMPLATE.in_arm * k, crank=TEMPLATE.crank * k,
                                link=TEMPLATE.link * k, rod_y=TEMPLATE.rod_y * k)
    qs = np.vstack([np.random.default_rng(2).uniform(-0.3, 1.5, (30, 3)), [[0.0, 0.0, -2.5], [2.4, 0.7, 0.1]]])
    big, tiny = finger_poses(TEMPLATE, qs), finger_poses(small, qs)
    assert big.valid.sum() >= 20 and not big.valid.all()
    assert np.array_equal(tiny.valid, big.valid)
    v = big.valid
    for name in ("G", "Q", "P", "K", "S", "stroke"):
        assert np.array_equal(getattr(tiny, name)[v], getattr(big, name)[v] * k), name
    assert np.array_equal(tiny.psi[v], big.psi[v])


def test_psi_reference_picks_the_turn_nearest_the_reference():
    """psi_reference only unwraps the rocker angles: with a reference 2 pi k + delta (|delta| < 2.5 rad)
    away from the default turn the result is the default + 2 pi k (1e-9 rad) and every point is the
    same (1e-9 mm). finger_pose's ``previous`` does the same with its psi."""
    qs = np.random.default_rng(4).uniform(0.0, 1.0, (12, 3))
    base = finger_poses(TEMPLATE, qs)
    rng = np.random.default_rng(8)
    for turns in (-1, 1, 2):
        ref = base.psi + 2 * np.pi * turns + rng.uniform(-2.5, 2.5, base.psi.shape)
        got = finger_poses(TEMPLATE, qs, ref)
        assert np.allclose(got.psi, base.psi + 2 * np.pi * turns, rtol=0, atol=1e-9)
        for name in ("G", "Q", "P", "K", "S", "stroke"):
            assert np.allclose(getattr(got, name), getattr(base, name), rtol=0, atol=1e-9), name
        assert np.array_equal(got.valid, base.valid)
    previous = finger_pose(TEMPLATE, qs[0])
    wound = dataclasses.replace(previous, psi=previous.psi + 2 * np.pi)
    plain, unwrapped = finger_pose(TEMPLATE, qs[1]), finger_pose(TEMPLATE, qs[1], wound)
    assert np.allclose(unwrapped.psi, plain.psi + 2 * np.pi, rtol=0, atol=1e-9)
    assert np.allclose(unwrapped.Q, plain.Q, rtol=0, atol=1e-9)
    assert np.allclose(finger_pose(TEMPLATE, qs[1], previous).psi, plain.psi, rtol=0, atol=1e-12)


@pytest.mark.parametrize("d", [TWO, TEMPLATE, FOUR], ids=["n2", "n3", "n4"])
def test_shapes_follow_the_documentation(d):
    """FingerPoses: q, theta (m, n); G (m, n+1, 2); Q, P (m, n-1, 2); psi (m, n-1); K, S (m, 2); stroke, valid
    (m,). A single q (n,) is one configuration; FingerPose drops the leading axis."""
    n, m = len(d.lengths), 5
    poses = finger_poses(d, np.zeros((m, n)))
    shapes = dict(q=(m, n), theta=(m, n), G=(m, n + 1, 2), Q=(m, n - 1, 2), P=(m, n - 1, 2), psi=(m, n - 1),
                  K=(m, 2), S=(m, 2), stroke=(m,), valid=(m,))
    for name, shape in shapes.items():
        assert getattr(poses, name).shape == shape, name
    one = finger_poses(d, np.zeros(n))
    assert one.G.shape == (1, n + 1, 2) and one.valid.shape == (1,)
    pose = finger_pose(d, np.zeros(n))
    for name, shape in shapes.items():
        if name != "valid":
            assert np.shape(getattr(pose, name)) == shape[1:], name


def test_pose_k_returns_the_kth_configuration():
    """FingerPoses.pose(k) carries every field of row k (stroke as a float) and is None where the pose does
    not close."""
    qs = np.array([[0.2, 0.4, 0.1], [0.0, 0.0, -2.5], [0.9, 0.3, 0.6]])
    poses = finger_poses(TEMPLATE, qs)
    assert poses.pose(1) is None
    for k in (0, 2):
        pose = poses.pose(k)
        assert isinstance(pose, FingerPose) and isinstance(pose.stroke, float)
        for name in ("q", "theta", "G", "Q", "P", "psi", "K", "S"):
            assert np.array_equal(getattr(pose, name), getattr(poses, name)[k]), name
        assert np.array_equal(pose.q, qs[k])
        assert pose.stroke == poses.stroke[k]
    assert finger_pose(TEMPLATE, qs[1]) is None


def test_integer_angles_give_the_float_results():
    """Integer q (radians 0 and 1) give bitwise the float64 answer, with float64 q and theta: the kernel
    converts first. Otherwise stroke_gradients would fill an integer array and truncate the gradients."""
    qi = np.array([[0, 0, 0], [1, 0, 1], [0, 1, 1], [1, 1, 0]])
    qf = qi.astype(np.float64)
    pi, pf = finger_poses(TEMPLATE, qi), finger_poses(TEMPLATE, qf)
    assert pf.valid.all()
    for name in ("q", "theta", "G", "Q", "P", "psi", "K", "S", "stroke", "valid"):
        got = getattr(pi, name)
        assert got.dtype == getattr(pf, name).dtype, name
        assert np.array_equal(got, getattr(pf, name)), name
    assert pi.q.dtype == np.float64
    assert np.array_equal(stroke_gradients(TEMPLATE, pi), stroke_gradients(TEMPLATE, pf))
    single = finger_pose(TEMPLATE, [1, 0, 1])
    assert single.q.dtype == np.float64 and np.array_equal(single.q, qf[1])
    assert np.array_equal(single.G, pf.G[1]) and single.stroke == pf.stroke[1]
    assert np.array_equal(stroke_gradient(TEMPLATE, qi[1]), stroke_gradient(TEMPLATE, qf[1]))


# ---------------------------------------------------------------- stroke gradients


def _fd_stroke(d: FingerDesign, q: np.ndarray, h: float = 1e-5) -> np.ndarray:
    """Central differences of finger_poses' stroke, our own stencil."""
    n = len(q)
    plus = finger_poses(d, q + h * np.eye(n)).stroke
    minus = finger_poses(d, q - h * np.eye(n)).stroke
    return (plus - minus) / (2 * h)


@pytest.mark.parametrize("d", [TEMPLATE, SKEW, FOUR, TWO], ids=["template", "skew", "n4", "n2"])
def test_stroke_gradients_match_own_differences_and_the_reference(d):
    """ds/dq from stroke_gradient (differences, h = 1e-6) and stroke_gradients (closed form) against our
    central differences (h = 1e-5: truncation h^2 s'''/6 < 1e-8, rounding ~1e-13/h = 1e-8 mm/rad) of
    finger_poses and of the reference solver; tolerance 1e-6 mm/rad + 1e-7 relative. Also the
    directional derivative along a random v equals grad . v."""
    n = len(d.lengths)
    qs = np.random.default_rng(6).uniform(0.0, 0.8, (15, n))
    poses = finger_poses(d, qs)
    closed = stroke_gradients(d, poses)
    assert closed.shape == (15, n) and poses.valid.sum() >= 8
    for k in np.nonzero(poses.valid)[0]:
        ours = _fd_stroke(d, qs[k])
        ref = _ref_stroke_gradient(d, qs[k])
        assert np.allclose(ours, ref, rtol=1e-7, atol=1e-6)
        assert np.allclose(stroke_gradient(d, qs[k]), ours, rtol=1e-7, atol=1e-6)
        assert np.allclose(closed[k], ours, rtol=1e-7, atol=1e-6)
        v = np.random.default_rng(k).normal(size=n)
        directional = (finger_poses(d, qs[k] + 1e-5 * v).stroke - finger_poses(d, qs[k] - 1e-5 * v).stroke) / 2e-5
        assert abs(directional[0] - closed[k] @ v) < 1e-6 * (1 + abs(directional[0]))


def test_stroke_gradients_is_the_joint_moment_of_a_unit_push():
    """Virtual work: pushing the rod with F while the springs give exactly tau = F ds/dq (from
    stroke_gradients) leaves nothing for the object, so contact_forces are 0 (1e-6 N against forces of
    ~F)."""
    qs = np.random.default_rng(12).uniform(0.0, 0.8, (6, 3))
    poses = finger_poses(SKEW, qs)
    grads = stroke_gradients(SKEW, poses)
    for k in np.nonzero(poses.valid)[0]:
        pose = poses.pose(k)
        pts = np.array([pose.G[i] + 0.5 * (pose.G[i + 1] - pose.G[i]) for i in range(3)])
        forces, _ = contact_forces(SKEW, pose, 20.0, 20.0 * grads[k], pts)
        assert np.allclose(forces, 0.0, atol=1e-6)


def test_stroke_gradients_with_a_horizontal_coupler():
    """A coupler exactly horizontal (P_y - Q_y == 0.0 in the returned points, found by bisection and an ulp
    walk in q_1) is no special case: finite gradients equal to our differences (1e-6 mm/rad)."""
    def rise(t):
        p = finger_poses(TEMPLATE, np.array([t, 0.2, 0.3]))
        return (p.P[:, 0, 1] - p.Q[:, 0, 1])[0]

    t = _bisect(lambda s: bool(rise(s) > 0), -0.05, 0.0)
    ts = _ulp_walk(t, 40)
    poses = finger_poses(TEMPLATE, np.stack([ts, np.full_like(ts, 0.2), np.full_like(ts, 0.3)], -1))
    flat = np.nonzero(poses.P[:, 0, 1] - poses.Q[:, 0, 1] == 0.0)[0]
    if len(flat) == 0:  # an exact tie depends on the platform's libm rounding
        pytest.skip("no exactly horizontal coupler on this platform's floating-point rounding")
    grads = stroke_gradients(TEMPLATE, poses)
    for k in flat:
        assert np.allclose(grads[k], _fd_stroke(TEMPLATE, poses.q[k]), rtol=1e-7, atol=1e-6)


def test_stroke_gradients_not_finite_where_a_pose_does_not_close_and_silent():
    """Documented: not finite where a pose does not close (a loop or the push link). Those rows are
    NaN/inf, the valid rows finite and equal to the same poses evaluated alone; no floating-point warning
    (the division by the link's zero x-component is expected there)."""
    qs = np.array([[0.2, 0.3, 0.1], [0.0, 0.0, -2.5], [0.0, -2.0, 0.0], [2.4, 0.7, 0.1], [0.5, 0.5, 0.5]])
    poses = finger_poses(TEMPLATE, qs)
    assert poses.valid.tolist() == [True, False, False, False, True]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        grads = stroke_gradients(TEMPLATE, poses)
    assert np.all(np.isfinite(grads[poses.valid]))
    assert not np.any(np.isfinite(grads[~poses.valid]))
    alone = stroke_gradients(TEMPLATE, finger_poses(TEMPLATE, qs[[0, 4]]))
    assert np.array_equal(alone, grads[[0, 4]])


def _shifted_poses(poses: FingerPoses, t: np.ndarray) -> FingerPoses:
    return dataclasses.replace(poses, G=poses.G + t, Q=poses.Q + t, P=poses.P + t, K=poses.K + t, S=poses.S + t)


def test_statics_do_not_depend_on_the_frame_origin():
    """Moments are taken about the joints, so translating every point of a pose (and the contact points)
    by the same vector changes neither the stroke gradients nor the contact and link forces (1e-9
    relative). The model's poses put G_1 at the origin; a pose expressed in another frame must not
    silently change the statics."""
    t = np.array([13.0, -7.5])
    qs = np.random.default_rng(21).uniform(0.0, 0.8, (5, 3))
    poses = finger_poses(SKEW, qs)
    assert np.allclose(stroke_gradients(SKEW, _shifted_poses(poses, t)), stroke_gradients(SKEW, poses), rtol=1e-9)
    pose = poses.pose(0)
    moved = dataclasses.replace(pose, G=pose.G + t, Q=pose.Q + t, P=pose.P + t, K=pose.K + t, S=pose.S + t)
    pts = np.array([pose.G[i] + 0.6 * (pose.G[i + 1] - pose.G[i]) for i in range(3)])
    tau = np.array([30.0, 20.0, 10.0])
    f0, y0 = contact_forces(SKEW, pose, 25.0, tau, pts)
    f1, y1 = contact_forces(SKEW, moved, 25.0, tau, pts + t)
    assert np.allclose(f1, f0, rtol=1e-9, atol=1e-9) and np.allclose(y1, y0, rtol=1e-9, atol=1e-9)


# ---------------------------------------------------------------- contact and link forces


def _virtual_work_forces(d: FingerDesign, q, push: float, tau, where):
    """Contact forces (along -n_m on phalanx m) from J^T f = F ds/dq - tau, with J[m, j] = n_m . dc_m/dq_j by
    central differences of the contact point c_m carried rigidly by phalanx m, and ds/dq by differences of
    the reference stroke."""
    n = len(d.lengths)
    q = np.asarray(q, float)

    def points(qq):
        G, theta = _phalanges(d, qq)
        return np.array([G[m] + where[m] * d.lengths[m] * _u(theta[m])
                         + 0.5 * d.thickness * _u(theta[m] + np.pi / 2) for m in range(n)]), theta

    pts, theta = points(q)
    normals = np.array([_u(theta[m] + np.pi / 2) for m in range(n)])
    jac = np.zeros((n, n))
    h = 1e-6
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        dc = (points(q + e)[0] - points(q - e)[0]) / (2 * h)
        jac[:, j] = np.einsum("mk,mk->m", normals, dc)
    return np.linalg.solve(jac.T, push * _ref_stroke_gradient(d, q) - tau), pts


def _link_compressions(d: FingerDesign, q, push: float) -> np.ndarray:
    """Virtual work with the phalanges held: lengthening a link by delta moves the rod by dS_x, so
    F dS_x + y delta = 0 for its compression y. Push link first, then couplers 1..n-1 (central differences
    of the reference solver's S_x in the link's length, h = 1e-6 mm)."""
    n = len(d.lengths)
    c = list(_open(d)[3])
    h = 1e-6
    out = [-push * (_reference(d, q, link=d.link + h)[0]["S"][0] - _reference(d, q, link=d.link - h)[0]["S"][0])
           / (2 * h)]
    for i in range(n - 1):
        hi, lo = list(c), list(c)
        hi[i] += h
        lo[i] -= h
        out.append(-push * (_reference(d, q, couplers=hi)[0]["S"][0] - _reference(d, q, couplers=lo)[0]["S"][0])
                   / (2 * h))
    return np.array(out)


@pytest.mark.parametrize("d", [TEMPLATE, SKEW, FOUR, TWO], ids=["template", "skew", "n4", "n2"])
def test_contact_and_link_forces_by_virtual_work(d):
    """contact_forces against virtual work computed here (see the helpers): contact forces and the
    compressions of the push link and of every coupler, 1e-5 relative + 1e-5 N (the differences carry
    ~1e-8 relative error). A push link force of F / u_SK.x is the rod's x-balance; the couplers' follow
    from the rockers' moment balance, here from their effect on the rod's position instead."""
    n = len(d.lengths)
    rng = np.random.default_rng(31 + n)
    done = 0
    for q in rng.uniform(0.0, 0.8, (6, n)):
        pose = finger_pose(d, q)
        if pose is None:
            continue
        done += 1
        push, tau, where = rng.uniform(5, 60), rng.uniform(0, 40, n), rng.uniform(0.2, 0.9, n)
        expected, pts = _virtual_work_forces(d, q, push, tau, where)
        forces, links = contact_forces(d, pose, push, tau, pts)
        assert np.allclose(forces, expected, rtol=1e-5, atol=1e-5)
        assert np.allclose(links, _link_compressions(d, q, push), rtol=1e-5, atol=1e-5)
        u_sk = (pose.K - pose.S) / math.dist(pose.K, pose.S)
        assert links[0] == pytest.approx(push / u_sk[0], rel=1e-12)
    assert done >= 3


# ---------------------------------------------------------------- PiecewiseLaw


def _smooth(x):
    return np.sin(1.3 * x) + 0.1 * np.exp(0.4 * x)


def test_law_interpolates_every_node_and_each_piece_is_the_not_a_knot_spline():
    """Breaks at two samples split the data into three pieces; each piece equals scipy's CubicSpline
    through that piece's samples (1e-12), so every node is interpolated, the pieces are C1 inside
    (left/right derivatives at inner nodes agree to 1e-9), and nu=1 matches central differences of the
    law (h = 1e-5, error ~h^2 |y'''| < 1e-8). Scalar in, float out; array in, array out."""
    x = np.linspace(0.0, 10.0, 21)
    y = _smooth(x)
    law = PiecewiseLaw(x, y, breaks=[x[14], x[7]])
    assert np.array_equal(law.breaks, [x[7], x[14]])
    assert np.allclose(law(x), y, rtol=0, atol=1e-12)
    for lo, hi in ((0, 7), (7, 14), (14, 20)):
        ref = CubicSpline(x[lo:hi + 1], y[lo:hi + 1])
        xs = np.linspace(x[lo], x[hi], 53)[1:-1]
        assert np.allclose(law(xs), ref(xs), rtol=0, atol=1e-12)
        assert np.allclose(law(xs, 1), ref(xs, 1), rtol=0, atol=1e-12)
        for k in range(lo + 1, hi):
            assert abs(law(x[k] - 1e-9, 1) - law(x[k] + 1e-9, 1)) < 1e-7
    xs = np.linspace(0.05, 9.95, 40)
    xs = xs[np.min(np.abs(xs[:, None] - law.breaks[None]), axis=1) > 1e-3]
    assert np.allclose(law(xs, 1), (law(xs + 1e-5) - law(xs - 1e-5)) / 2e-5, atol=1e-8)
    assert isinstance(law(2.5), float) and law(np.array([2.5])).shape == (1,)


def test_a_break_keeps_the_kink():
    """y = |x - 3| on integer samples with a break at 3: each piece is a straight line (two-point pieces
    and collinear samples), so the left slope is -1 and the right +1 (1e-12). At the break itself the
    law takes the piece that starts there (the forward derivative +1); its value is the sample, 0."""
    x = np.arange(0.0, 7.0)
    law = PiecewiseLaw(x, np.abs(x - 3.0), breaks=[3.0])
    assert np.allclose(law(np.array([0.5, 2.0, 2.999]), 1), -1.0, atol=1e-12)
    assert np.allclose(law(np.array([3.001, 4.0, 5.5]), 1), 1.0, atol=1e-12)
    assert law(3.0, 1) == pytest.approx(1.0, abs=1e-12)
    assert law(3.0) == pytest.approx(0.0, abs=1e-12)
    smooth = PiecewiseLaw(x, np.abs(x - 3.0))
    assert abs(smooth(2.5, 1) + 1.0) > 0.01                   # without the break the kink is smeared


@pytest.mark.parametrize("k", [1, 4])
def test_breaks_at_the_second_and_second_last_samples(k):
    """A break at x[1] (or x[-2]) makes a two-sample end piece, a straight line: law(midpoint) is the mean
    of the two samples (1e-12) and the other piece is the spline through the rest."""
    x = np.arange(0.0, 6.0)
    y = _smooth(x)
    law = PiecewiseLaw(x, y, breaks=[x[k]])
    assert np.array_equal(law.breaks, [x[k]])
    line = (0, 1) if k == 1 else (4, 5)
    rest = slice(1, 6) if k == 1 else slice(0, 5)
    assert law(0.5 * (x[line[0]] + x[line[1]])) == pytest.approx(0.5 * (y[line[0]] + y[line[1]]), abs=1e-12)
    xs = np.linspace(x[rest][0], x[rest][-1], 31)[1:-1]
    assert np.allclose(law(xs), CubicSpline(x[rest], y[rest])(xs), rtol=0, atol=1e-12)


def test_breaks_at_or_outside_the_ends_are_ignored():
    """Breaks equal to the first or last sample or outside the samples do not split anything: the law is
    the single spline through all samples (1e-12) and has no breaks."""
    x = np.arange(0.0, 8.0)
    y = _smooth(x)
    law = PiecewiseLaw(x, y, breaks=[x[0], x[-1], -3.0, 11.0])
    assert law.breaks.size == 0 and len(law.pieces) == 1
    xs = np.linspace(0.0, 7.0, 71)
    assert np.allclose(law(xs), CubicSpline(x, y)(xs), rtol=0, atol=1e-12)


GAP_CASES = {
    # x (min_gap 0.25), indices kept by hand
    "gap equal to min_gap from the previous: kept": ([0.0, 0.25, 1.0, 1.5, 2.0], [0, 1, 2, 3, 4]),
    "gap under min_gap from the previous: dropped": ([1.0, 1.125, 2.0, 2.5, 3.0], [0, 2, 3, 4]),
    "gap equal to min_gap to the last: kept": ([0.0, 0.5, 1.0, 1.75, 2.0], [0, 1, 2, 3, 4]),
    "gap under min_gap to the last: dropped": ([0.0, 0.5, 1.0, 1.875, 2.0], [0, 1, 2, 4]),
    "measured from the kept neighbour": ([0.0, 0.125, 0.25, 0.375, 1.0, 2.0], [0, 2, 4, 5]),
}


@pytest.mark.parametrize("case", list(GAP_CASES))
def test_min_gap_drops_nodes_counted_by_hand(case):
    """min_gap = 0.25 on dyadic samples (differences exact): an inner node is kept iff it is >= 0.25 from
    the last kept node and >= 0.25 from the piece's last node (equality keeps it). The law equals
    CubicSpline through the kept nodes (1e-12) and, where a node was dropped, differs from the spline
    through all of them."""
    x, kept = (np.array(v) for v in GAP_CASES[case])
    y = _smooth(3 * x)
    law = PiecewiseLaw(x, y, min_gap=0.25)
    assert np.array_equal(law.pieces[0].x, x[kept])
    xs = np.linspace(x[0], x[-1], 97)
    assert np.allclose(law(xs), CubicSpline(x[kept], y[kept])(xs), rtol=0, atol=1e-12)
    if len(kept) < len(x):
        assert np.max(np.abs(law(xs) - CubicSpline(x, y)(xs))) > 1e-4


def test_min_gap_applies_per_piece_up_to_the_break():
    """With a break at 2 the gap to "the last node" is to the break sample on the left and to x[-1] on the
    right: 1.875 and 2.125 (0.125 from the break) are dropped, 1.75 and 2.25 (exactly 0.25) kept."""
    x = np.array([0.0, 1.0, 1.75, 1.875, 2.0, 2.125, 2.25, 3.0, 4.0])
    y = _smooth(3 * x)
    law = PiecewiseLaw(x, y, breaks=[2.0], min_gap=0.25)
    assert np.array_equal(law.pieces[0].x, [0.0, 1.0, 1.75, 2.0])
    assert np.array_equal(law.pieces[1].x, [2.0, 2.25, 3.0, 4.0])


def test_law_far_from_the_origin_keeps_its_end_nodes():
    """Samples at 2^15 + 0..7 mm (where 1e-12 is below half the float spacing) with a break at the fourth:
    still every node interpolated (1e-9) and each piece the spline through its own samples, the break
    sample belonging to both."""
    x = 2.0**15 + np.arange(0.0, 8.0)
    y = _smooth(x - 2.0**15)
    law = PiecewiseLaw(x, y, breaks=[x[3]])
    assert np.allclose(law(x), y, rtol=0, atol=1e-9)
    assert np.array_equal(law.pieces[0].x, x[:4]) and np.array_equal(law.pieces[1].x, x[3:])


def test_law_accepts_integer_samples():
    """Integer y, and int8 x whose differences (up to 200) overflow int8: the same law as for float64
    samples (bitwise on a grid), every node interpolated. Integer evaluation points give the float ones."""
    x8 = np.array([-100, -50, 0, 50, 100], dtype=np.int8)
    yi = np.array([3, -1, 4, 1, -5])
    ref = PiecewiseLaw(x8.astype(float), yi.astype(float))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        law = PiecewiseLaw(x8, yi)
    xs = np.linspace(-100.0, 100.0, 41)
    assert np.array_equal(law(xs), ref(xs))
    assert np.allclose(law(x8.astype(float)), yi, rtol=0, atol=1e-12)
    assert np.array_equal(law(np.array([-100, 3, 77])), ref(np.array([-100.0, 3.0, 77.0])))
    assert law(3) == ref(3.0)
