"""Six-bar position analysis and statics (synthesis/watt_six_bar/statics.py) against hand computations.

Every expected value comes from a computation written here, not from the function under test:

- closed-form circle intersections (3-4-5 triangles, integer-exact tangencies);
- an assembly by the law of cosines with complex numbers (:func:`_hand_poses`), a different formula
  from the module's projection onto the centre line;
- the equilibrium of all five moving links as one 15 x 15 linear system (:func:`_hand_equilibrium`):
  seven unknown joint force vectors and the input torque, no two-force-member shortcut;
- the virtual-work principle ``T dtheta1 + F . dm = 0`` with ``dm`` from central differences of the
  hand-assembled midpoint of e-c.

The two hand-made fingers are not symmetric (no joint on an axis, the middle phalanx bent one way in
one and the other way in the other) so that a swapped index, a dropped term or a wrong sign shows.
"""

from __future__ import annotations

import warnings
from contextlib import contextmanager

import numpy as np
import pytest

from fabricate.mechanism import Body, Driver, Mechanism, Revolute
from fabricate.planar import transform_points
from fabricate.synthesis.watt_six_bar.statics import (
    JOINTS,
    SixBarBatch,
    SixBarPoses,
    _circle_intersection,
    assemble,
    external_force,
    fingertip_errors,
    force_index,
    joint_loads,
    lagrange_joint_forces,
    middle_link_clearance,
    segment_distance,
    virtual_work_torque,
)

# Position-1 joints (mm) and theta1 there (rad). FLEXED: the middle phalanx turned clockwise from the
# proximal one (b right of a0->a); EXTENDED: turned counter-clockwise (b left of a0->a). Both assemble
# over theta1_start .. theta1_start - 40 deg (the flexing motion) and stop assembling for +40 deg.
FLEXED = {"a": (46.0, 19.5), "b": (75.5, 24.5), "c": (100.0, 21.0), "d": (45.0, 25.5), "e": (76.0, 16.0),
          "f": (47.0, 18.5), "d0": (-10.5, 8.5), "theta1_start": 0.25}
EXTENDED = {"a": (48.0, -15.0), "b": (77.0, -8.0), "c": (102.0, -8.5), "d": (51.0, -9.5), "e": (74.0, -17.5),
            "f": (48.0, -16.0), "d0": (-2.5, 13.5), "theta1_start": -0.1}
FINGERS = {"flexed": FLEXED, "extended": EXTENDED}
BODIES = ("proximal", "middle", "distal", "coupler", "rocker")


def _batch(finger: dict) -> SixBarBatch:
    p = {k: np.asarray(v, dtype=np.float64) for k, v in finger.items() if k != "theta1_start"}
    return SixBarBatch(p["a"], p["b"], p["c"], p["d"][None], p["e"][None], p["f"][None], p["d0"][None],
                       finger["theta1_start"])


def _flexion(finger: dict, n: int = 41, span_deg: float = -40.0) -> np.ndarray:
    return finger["theta1_start"] + np.radians(np.linspace(0.0, span_deg, n))


def _z(p) -> complex | np.ndarray:
    p = np.asarray(p, dtype=np.float64)
    return p[..., 0] + 1j * p[..., 1]


def _xy(z) -> np.ndarray:
    z = np.asarray(z)
    return np.stack([z.real, z.imag], -1)


def _cross(u, v):
    """z-component of u x v for complex numbers: Im(conj(u) v)."""
    return np.imag(np.conj(u) * v)


def _law_of_cosines_point(c1, r1, c2, r2, side):
    """Point at distance r1 from c1 and r2 from c2, left (side +1) or right (-1) of c1->c2 (complex)."""
    base = np.angle(c2 - c1)
    dist = np.abs(c2 - c1)
    gamma = np.arccos((r1 * r1 + dist * dist - r2 * r2) / (2.0 * r1 * dist))
    return c1 + r1 * np.exp(1j * (base + side * gamma))


def _hand_poses(finger: dict, theta1: np.ndarray) -> dict[str, np.ndarray]:
    """Joint positions (complex, (S,)) by rigid rotations and the law of cosines, on the position-1 branch."""
    p = {k: _z(v) for k, v in finger.items() if k != "theta1_start"}
    turn = np.exp(1j * (np.asarray(theta1) - finger["theta1_start"]))
    a, d = p["a"] * turn, p["d"] * turn
    d0 = np.full_like(a, p["d0"])
    side1 = np.sign(_cross(p["d0"] - p["d"], p["f"] - p["d"]))
    f = _law_of_cosines_point(d, abs(p["f"] - p["d"]), d0, abs(p["f"] - p["d0"]), side1)
    coupler = (f - d) / (p["f"] - p["d"])
    e = d + coupler / abs(coupler) * (p["e"] - p["d"])
    side2 = np.sign(_cross(p["e"] - p["a"], p["b"] - p["a"]))
    b = _law_of_cosines_point(a, abs(p["b"] - p["a"]), e, abs(p["b"] - p["e"]), side2)
    distal = (b - e) / (p["b"] - p["e"])
    c = e + distal / abs(distal) * (p["c"] - p["e"])
    return {"a0": np.zeros_like(a), "a": a, "b": b, "c": c, "d": d, "e": e, "f": f, "d0": d0}


def _hand_load(pos: dict, force: float = 1.0):
    """Midpoint of e-c and the force of magnitude ``force`` along e->c turned +90 deg (times i)."""
    ec = pos["c"] - pos["e"]
    return 0.5 * (pos["e"] + pos["c"]), force * 1j * ec / np.abs(ec)


# joint -> (body the unknown force X_j acts on, body that receives -X_j); None is the ground
_JOINT_BODIES = {"a0": ("proximal", None), "a": ("middle", "proximal"), "b": ("distal", "middle"),
                 "d": ("coupler", "proximal"), "e": ("distal", "coupler"), "f": ("rocker", "coupler"),
                 "d0": ("rocker", None)}


def _hand_equilibrium(pos: dict, point: complex, load: complex) -> tuple[dict[str, float], float]:
    """Joint force magnitudes and the input torque at one pose, from the force and moment balance of
    every moving link (3 equations each, moments about the origin) solved as one linear system.

    Unknowns: X_j (2 each) for the seven joints in ``_JOINT_BODIES`` and T, the torque the ground
    (actuator) applies to the proximal link; ``load`` acts on the distal link at ``point``.
    """
    mat = np.zeros((15, 15))
    rhs = np.zeros(15)
    row = {name: 3 * k for k, name in enumerate(BODIES)}
    for k, (joint, bodies) in enumerate(_JOINT_BODIES.items()):
        px, py = pos[joint].real, pos[joint].imag
        for body, sign in zip(bodies, (1.0, -1.0), strict=True):
            if body is None:
                continue
            r = row[body]
            mat[r, 2 * k] += sign
            mat[r + 1, 2 * k + 1] += sign
            mat[r + 2, 2 * k] -= sign * py
            mat[r + 2, 2 * k + 1] += sign * px
    mat[row["proximal"] + 2, 14] = 1.0
    r = row["distal"]
    rhs[r:r + 3] = -np.array([load.real, load.imag, _cross(point, load)])
    x = np.linalg.solve(mat, rhs)
    return {j: float(np.hypot(x[2 * k], x[2 * k + 1])) for k, j in enumerate(_JOINT_BODIES)}, float(x[14])


def _at(pos: dict, i: int) -> dict:
    return {k: complex(v[i]) for k, v in pos.items()}


def _hand_mechanism(finger: dict) -> Mechanism:
    """The finger as a generic Mechanism: every body frame is the world frame at position 1, input theta1 -
    theta1_start in degrees."""
    p = {k: tuple(float(x) for x in v) for k, v in finger.items() if k != "theta1_start"}
    origin = (0.0, 0.0)
    bodies = (Body("ground", {"a0": origin, "d0": p["d0"]}),
              Body("proximal", {"a0": origin, "a": p["a"], "d": p["d"]}),
              Body("middle", {"a": p["a"], "b": p["b"]}),
              Body("distal", {"b": p["b"], "c": p["c"], "e": p["e"]}),
              Body("coupler", {"d": p["d"], "e": p["e"], "f": p["f"]}),
              Body("rocker", {"f": p["f"], "d0": p["d0"]}))
    joints = tuple(Revolute(j, b_plus, b_minus or "ground") for j, (b_plus, b_minus) in _JOINT_BODIES.items())
    return Mechanism(name="hand", bodies=bodies, ground="ground", joints=joints, gears=(),
                     drivers=(Driver("angle", "proximal", "ground"),), input_range=(0.0, -40.0),
                     assembly={b: (0.0, 0.0, 0.0) for b in BODIES})


@contextmanager
def _no_float_warnings():
    """numpy reports every floating-point error as a warning, and a warning fails the test."""
    with np.errstate(all="warn"), warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


# -- _circle_intersection -------------------------------------------------------------------------------

def test_circle_intersection_of_3_4_5_triangles_with_sides_and_margin():
    """Circles about (0, 0) r 3 and (5, 0) r 4 meet at (1.8, +-2.4); circles about (1, 2) r 4 and (4, 6) r 3
    meet at (1, 6) (left of c1->c2) and (4.84, 3.12) (right): both by hand from the 3-4-5 triangle
    (distances checked: 16 = 0^2 + 4^2 = 3^2 + 0^2, and 3.84^2 + 1.12^2 = 16, 0.84^2 + 2.88^2 = 9).
    The second value is (h / r1)^2 with h the distance of the points from the centre line:
    (2.4 / 3)^2 = 0.64 and (2.4 / 4)^2 = 0.36. One vectorised call, shapes (2, 2) / (2,), to 1e-12."""
    c1 = np.array([[0.0, 0.0], [1.0, 2.0]])
    c2 = np.array([[5.0, 0.0], [4.0, 6.0]])
    r1, r2 = np.array([3.0, 4.0]), np.array([4.0, 3.0])
    left, m_left = _circle_intersection(c1, r1, c2, r2, np.array([1.0, 1.0]))
    right, m_right = _circle_intersection(c1, r1, c2, r2, np.array([-1.0, -1.0]))
    assert left.shape == (2, 2) and m_left.shape == (2,)
    np.testing.assert_allclose(left, [[1.8, 2.4], [1.0, 6.0]], atol=1e-12)
    np.testing.assert_allclose(right, [[1.8, -2.4], [4.84, 3.12]], atol=1e-12)
    np.testing.assert_allclose(m_left, [0.64, 0.36], rtol=1e-12)
    np.testing.assert_allclose(m_right, m_left, rtol=0, atol=0)


def test_circle_intersection_broadcasts_over_mechanisms_and_samples():
    """Shapes (N, S, 2) centres with (N, S) radii and an (N, 1) side give (N, S, 2) points and (N, S)
    margins; every point lies on both circles (1e-12) on the requested side of c1->c2."""
    rng = np.random.default_rng(7)
    c1 = rng.uniform(-5, 5, (3, 4, 2))
    c2 = c1 + rng.uniform(2, 4, (3, 4, 2))
    dist = np.linalg.norm(c2 - c1, axis=-1)
    r1 = 0.6 * dist + rng.uniform(0, 0.2, (3, 4))
    r2 = 0.7 * dist
    side = np.array([[1.0], [-1.0], [1.0]])
    point, margin = _circle_intersection(c1, r1, c2, r2, side)
    assert point.shape == (3, 4, 2) and margin.shape == (3, 4)
    np.testing.assert_allclose(np.linalg.norm(point - c1, axis=-1), r1, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(point - c2, axis=-1), r2, rtol=1e-12)
    u, v = c2 - c1, point - c1
    assert np.all(np.sign(u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]) == side)
    assert np.all((margin > 0) & (margin <= 1))


@pytest.mark.parametrize("c1, r1, c2, r2, touch", [
    ((0.0, 0.0), 3.0, (8.0, 0.0), 5.0, (3.0, 0.0)),     # outside each other: 3 + 5 = 8
    ((1.0, 2.0), 3.0, (1.0, -6.0), 5.0, (1.0, -1.0)),   # same, along -y
    ((0.0, 0.0), 5.0, (2.0, 0.0), 3.0, (5.0, 0.0)),     # one inside the other: 5 - 3 = 2
])
def test_tangent_circles_give_the_touching_point_and_exactly_zero(c1, r1, c2, r2, touch):
    """Tangent circles (a toggle): the single common point, and h^2 / r1^2 exactly 0 (neither a false
    "no assembly" nor a positive margin). The numbers are dyadic (the foot of the point divides the centre
    line at 3/8, 3/8 and 5/2), so every operation is exact in binary floating point on any platform."""
    point, margin = _circle_intersection(np.array(c1), np.array(r1), np.array(c2), np.array(r2), np.array(1.0))
    assert margin == 0.0
    np.testing.assert_array_equal(point, touch)


@pytest.mark.parametrize("c1, r1, c2, r2, expected", [
    ((0.0, 0.0), 1.0, (5.0, 0.0), 2.0, -3.84),    # apart: foot at x = 2.2, (1 - 2.2^2) / 1
    ((0.0, 0.0), 5.0, (1.0, 0.0), 1.0, -5.25),    # small one inside: foot at x = 12.5, 1 - 12.5^2 / 25
])
def test_circles_that_do_not_meet_have_a_negative_margin(c1, r1, c2, r2, expected):
    """Circles that do not meet: (r1^2 - x^2) / r1^2 < 0 with x = (r1^2 - r2^2 + L^2) / (2 L) the foot on the
    centre line (L the centre distance), by hand; to 1e-12."""
    _, margin = _circle_intersection(np.array(c1), np.array(r1), np.array(c2), np.array(r2), np.array(-1.0))
    assert margin == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("r1, r2", [(4.0, 1.0), (4.0, 4.0), (0.0, 3.0)])
def test_concentric_circles_or_zero_radius_mean_no_assembly_without_warnings(r1, r2):
    """Coincident centres (dist^2 = 0: x / 0 and 0 / 0 inside) or a zero first radius: no assembly, so the
    margin is negative, and no floating-point warning escapes (the screening runs this over millions of
    candidate mechanisms; numpy set to warn, warnings turned into errors)."""
    c1 = np.array([[2.0, 3.0]])
    c2 = c1 if r1 > 0 else np.array([[6.0, 3.0]])
    with _no_float_warnings():
        _, margin = _circle_intersection(c1, np.array([r1]), c2, np.array([r2]), np.array([1.0]))
    assert margin.shape == (1,) and margin[0] < 0.0


# -- assemble -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", FINGERS)
def test_assemble_at_theta1_start_returns_position_1(name):
    """At theta1 = theta1_start the mechanism is in position 1: every joint where the batch puts it (1e-9 mm;
    rotation by exactly 0 and the same circles). This fixes the branch of both loops: the other assembly
    of the middle loop puts b at its mirror image about a-e, tens of mm away."""
    finger = FINGERS[name]
    batch = _batch(finger)
    poses = assemble(batch, np.array([finger["theta1_start"]]))
    for joint in ("a", "b", "c", "d", "e", "f", "d0"):
        np.testing.assert_allclose(getattr(poses, joint)[0, 0], finger[joint], atol=1e-9, err_msg=joint)
    assert poses.margin[0, 0] > 0.0


@pytest.mark.parametrize("name", FINGERS)
def test_assemble_keeps_every_link_rigid_and_the_branch(name):
    """Over the flexion (41 inputs): every distance within a link equals its position-1 value (1e-9 mm), no
    link is mirrored (the sign of the triangle a0-a-d, d-e-f, b-c-e areas), both loops stay on the branch
    of position 1 (side of f from d->d0, of b from a->e), the proximal link turned by exactly
    theta1 - theta1_start, and the joints equal the law-of-cosines assembly (1e-9 mm)."""
    finger = FINGERS[name]
    theta = _flexion(finger)
    poses = assemble(_batch(finger), theta)
    got = {j: _z(getattr(poses, j)[0]) for j in ("a", "b", "c", "d", "e", "f", "d0")}
    got["a0"] = np.zeros(len(theta), dtype=complex)
    ref = {j: _z(finger[j]) if j != "a0" else 0j for j in ("a0", "a", "b", "c", "d", "e", "f", "d0")}
    links = [("a0", "a"), ("a0", "d"), ("a", "d"), ("a", "b"), ("b", "c"), ("b", "e"), ("c", "e"),
             ("d", "e"), ("d", "f"), ("e", "f"), ("f", "d0"), ("a0", "d0")]
    for p, q in links:
        np.testing.assert_allclose(np.abs(got[p] - got[q]), abs(ref[p] - ref[q]), atol=1e-9, err_msg=f"{p}-{q}")
    for p, q, r in [("a0", "a", "d"), ("d", "e", "f"), ("b", "c", "e"), ("d", "d0", "f"), ("a", "e", "b")]:
        sign = np.sign(_cross(ref[q] - ref[p], ref[r] - ref[p]))
        assert sign != 0 and np.all(np.sign(_cross(got[q] - got[p], got[r] - got[p])) == sign), (p, q, r)
    np.testing.assert_allclose(np.angle(got["a"] / ref["a"]), theta - finger["theta1_start"], atol=1e-12)
    hand = _hand_poses(finger, theta)
    for j in got:
        np.testing.assert_allclose(_xy(got[j]), _xy(hand[j]), atol=1e-9, err_msg=j)
    assert np.all(poses.margin > 0.0)


def test_assemble_computes_in_double_precision_from_single_precision_angles():
    """Angles handed over as float32 (exactly representable in float64) give the joints of the same angles
    as float64 to 1e-12 mm: the analysis is done in double precision whatever the input dtype (a float32
    rotation would be off by ~1e-5 mm at these 100 mm radii)."""
    batch = _batch(FLEXED)
    theta32 = _flexion(FLEXED, 9).astype(np.float32)
    single = assemble(batch, theta32)
    double = assemble(batch, theta32.astype(np.float64))
    for joint in ("a", "b", "c", "d", "e", "f"):
        np.testing.assert_allclose(getattr(single, joint), getattr(double, joint), rtol=0, atol=1e-12)
        assert getattr(single, joint).dtype == np.float64


def test_assemble_flags_the_inputs_where_a_loop_cannot_close():
    """Extending the flexed finger (theta1 up to theta1_start + 40 deg) opens the ground loop: |d - d0|
    grows past |d - f| + |f - d0|. margin < 0 exactly where that hand check (or the same for the middle
    loop with the hand-assembled e) says the circles do not meet; inputs within 1e-6 mm of the limit are
    left out."""
    finger = FLEXED
    theta = _flexion(finger, 81, 40.0)
    poses = assemble(_batch(finger), theta)
    p = {k: _z(v) for k, v in finger.items() if k != "theta1_start"}
    turn = np.exp(1j * (theta - finger["theta1_start"]))
    d, a = p["d"] * turn, p["a"] * turn
    r1, r2 = abs(p["f"] - p["d"]), abs(p["f"] - p["d0"])
    slack1 = np.minimum(r1 + r2 - np.abs(d - p["d0"]), np.abs(d - p["d0"]) - abs(r1 - r2))
    with np.errstate(invalid="ignore"):
        e = _hand_poses(finger, theta)["e"]
    r3, r4 = abs(p["b"] - p["a"]), abs(p["b"] - p["e"])
    slack2 = np.where(slack1 > 0, np.minimum(r3 + r4 - np.abs(e - a), np.abs(e - a) - abs(r3 - r4)), -1.0)
    closes = np.minimum(slack1, slack2)
    clear = np.abs(closes) > 1e-6
    assert np.any(closes[clear] < 0) and np.any(closes[clear] > 0)
    np.testing.assert_array_equal(poses.margin[0, clear] >= 0.0, closes[clear] > 0)


# -- fingertip_errors ------------------------------------------------------------------------------------

def test_fingertip_errors_against_hand_assembled_fingertip():
    """Distance of c from hand-picked targets at four inputs equals |c_hand - target| (1e-9 mm) with c from
    the law-of-cosines assembly; NaN at an input where the mechanism cannot be assembled (+35 deg)."""
    finger = EXTENDED
    theta = finger["theta1_start"] + np.radians([0.0, -13.0, -29.0, 35.0])
    targets = np.array([[102.0, -8.5], [95.0, -30.0], [80.0, -50.0], [90.0, 20.0]])
    with np.errstate(invalid="ignore"):
        c = _xy(_hand_poses(finger, theta)["c"])
    err = fingertip_errors(_batch(finger), theta, targets)
    assert err.shape == (1, 4)
    np.testing.assert_allclose(err[0, :3], np.hypot(*(c[:3] - targets[:3]).T), atol=1e-9)
    assert err[0, 0] < 1e-9
    assert np.isnan(err[0, 3])


def _toggle_batch() -> SixBarBatch:
    """The flexed finger with d, f, d0 in a line, f the midpoint: |d - d0| = |d - f| + |f - d0| (6-8-10
    triangles), so the ground loop is exactly at its toggle in position 1 (margin exactly 0: the foot
    divides d-d0 at 1/2 and (r1 / |d - d0|)^2 = 1/4, dyadic, exact in floating point)."""
    f = dict(FLEXED, f=(39.0, 17.5), d0=(33.0, 9.5))
    return _batch(f)


# -- external_force, joint_loads, force_index ------------------------------------------------------------

def _poses_of(points: dict[str, tuple[float, float]]) -> SixBarPoses:
    arr = {k: np.asarray(v, dtype=np.float64)[None, None] for k, v in points.items()}
    return SixBarPoses(margin=np.ones((1, 1)), **arr)


def test_external_force_is_a_unit_normal_at_the_midpoint_of_e_c():
    """e = (1, 2), c = (4, 6): midpoint (2.5, 4), e->c = (3, 4) turned +90 deg and normalised = (-0.8, 0.6);
    the default force is 1 N (K and the joint loads are per unit force); force=-2.5 scales it."""
    poses = _poses_of({"a": (0, 0), "b": (0, 0), "c": (4, 6), "d": (0, 0), "e": (1, 2), "f": (0, 0), "d0": (0, 0)})
    point, load = external_force(poses)
    np.testing.assert_allclose(point[0, 0], [2.5, 4.0], atol=1e-15)
    np.testing.assert_allclose(load[0, 0], [-0.8, 0.6], atol=1e-15)
    _, load = external_force(poses, -2.5)
    np.testing.assert_allclose(load[0, 0], [2.0, -1.5], atol=1e-15)


@pytest.mark.parametrize("name", FINGERS)
@pytest.mark.parametrize("force", [1.0, 2.5])
def test_joint_loads_match_the_hand_equilibrium_of_all_links(name, force):
    """Each joint force and the input torque over the flexion equal the solution of the 15 x 15 force and
    moment balance of the five links (rel 1e-9: both are exact up to rounding, the system is well
    conditioned away from toggles); they scale with the force (2.5 N)."""
    finger = FINGERS[name]
    theta = _flexion(finger, 11)
    loads = joint_loads(assemble(_batch(finger), theta), force)
    pos = _hand_poses(finger, theta)
    for i in range(len(theta)):
        at = _at(pos, i)
        forces, torque = _hand_equilibrium(at, *_hand_load(at, force))
        for j in JOINTS:
            assert loads.forces[j][0, i] == pytest.approx(forces[j], rel=1e-9), (j, i)
        assert loads.torque[0, i] == pytest.approx(torque, rel=1e-9), i
    assert loads.largest().shape == (1, len(theta))


@pytest.mark.parametrize("name", FINGERS)
def test_input_torque_obeys_virtual_work(name):
    """T dtheta1 + F . dm = 0 (virtual work, the mechanism is ideal): T = -F . dm/dtheta1 with dm/dtheta1
    from central differences (h = 1e-6 rad) of the hand-assembled midpoint of e-c; agreement to rel 1e-6
    (difference error O(h^2) ~ 1e-12, rounding ~ 1e-16 * 100 mm / 1e-6)."""
    finger = FINGERS[name]
    theta = _flexion(finger, 6)
    h = 1e-6
    loads = joint_loads(assemble(_batch(finger), theta))
    for i, th in enumerate(theta):
        m_plus, _ = _hand_load(_at(_hand_poses(finger, np.array([th + h])), 0))
        m_minus, _ = _hand_load(_at(_hand_poses(finger, np.array([th - h])), 0))
        _, load = _hand_load(_at(_hand_poses(finger, np.array([th])), 0))
        dm = (m_plus - m_minus) / (2 * h)
        expected = -(load.real * dm.real + load.imag * dm.imag)
        assert loads.torque[0, i] == pytest.approx(expected, rel=1e-6, abs=1e-9), i


def test_force_index_is_the_largest_hand_joint_force_per_unit_force():
    """K = max over the joints a0, a, b, d, e, f, d0 and the 41 inputs of |joint force| / |F|, from the hand
    equilibrium (rel 1e-9); the same for every force magnitude and sign (joint forces are linear in F),
    and per mechanism for a batch of both fingers' joints (shared a, b, c of the flexed one)."""
    finger = FLEXED
    theta = _flexion(finger)
    pos = _hand_poses(finger, theta)
    k_hand = 0.0
    for i in range(len(theta)):
        at = _at(pos, i)
        forces, _ = _hand_equilibrium(at, *_hand_load(at, 1.0))
        k_hand = max(k_hand, max(forces[j] for j in JOINTS))
    batch = _batch(finger)
    k = force_index(batch, theta)
    assert k.shape == (1,) and k[0] == pytest.approx(k_hand, rel=1e-9)
    for force in (3.0, -2.5, 0.125):
        assert force_index(batch, theta, force)[0] == pytest.approx(k_hand, rel=1e-9), force
    two = SixBarBatch(batch.a, batch.b, batch.c, np.repeat(batch.d, 3, 0), np.repeat(batch.e, 3, 0),
                      np.repeat(batch.f, 3, 0), np.repeat(batch.d0, 3, 0), batch.theta1_start)
    np.testing.assert_allclose(force_index(two, theta, chunk=2), k_hand, rtol=1e-9)


def test_force_index_is_infinite_where_a_loop_cannot_close():
    """A motion that runs past the ground loop's limit (the flexed finger extended by 40 deg, see
    test_assemble_flags_the_inputs_where_a_loop_cannot_close) has no finite K: inf, not NaN, not the
    (finite, meaningless) forces computed on the clipped positions; the flexing motion is finite."""
    finger = FLEXED
    batch = _batch(finger)
    theta = _flexion(finger, 41, 40.0)
    assert force_index(batch, theta)[0] == np.inf
    assert np.isfinite(force_index(batch, _flexion(finger))[0])
    # each input past the limit on its own (the clipped positions put f on the line d-d0, where the
    # rounded loads come out finite at some inputs and infinite at others)
    margin = assemble(batch, theta).margin[0]
    for th in theta[margin < -1e-6]:
        assert force_index(batch, np.array([th]))[0] == np.inf, th


def test_force_index_is_infinite_at_an_exact_toggle():
    """At a toggle the coupler and rocker are in line and the joint forces are unbounded: K is inf even where
    the rounded positions would give a huge finite number. Position 1 of this batch is the toggle (d, f, d0
    collinear in integers, so the branch sign is exactly 0 on any platform): no branch, margin < 0 at every
    input (see test_a_mechanism_whose_first_position_is_a_toggle_is_never_assembled)."""
    batch = _toggle_batch()
    theta = np.array([FLEXED["theta1_start"], FLEXED["theta1_start"] - 0.05])
    assert np.all(assemble(batch, theta).margin < 0.0)
    assert force_index(batch, theta)[0] == np.inf


def test_joint_loads_at_a_toggle_are_unbounded_without_warnings():
    """Middle link a-b in line with b-e (a = (0, 0), b = (5, 0), e = (9, 0)): its load s1 needs a moment arm
    of zero, so the loads are not finite; joint_loads (run over whole batches) returns them without a
    floating-point warning (numpy set to warn, warnings turned into errors)."""
    poses = _poses_of({"a": (0.0, 0.0), "b": (5.0, 0.0), "c": (12.0, 4.0), "d": (3.0, 3.0), "e": (9.0, 0.0),
                       "f": (4.0, 7.0), "d0": (-2.0, 5.0)})
    with _no_float_warnings():
        loads = joint_loads(poses)
    assert not np.isfinite(loads.largest()[0, 0])


# -- lagrange_joint_forces, virtual_work_torque ----------------------------------------------------------

@pytest.mark.parametrize("name", FINGERS)
def test_lagrange_joint_forces_match_the_hand_equilibrium(name):
    """On the finger as a generic Mechanism (bodies, pins, an angle driver), at two inputs: every joint force
    and the input torque from the constraint multipliers equal the hand equilibrium (rel 1e-8; the
    generic solver closes the loops to ~1e-10 mm)."""
    finger = FINGERS[name]
    mech = _hand_mechanism(finger)
    inputs = np.array([0.0, -17.0, -31.0])
    motion = mech.sweep(inputs)
    pos = _hand_poses(finger, finger["theta1_start"] + np.radians(inputs))
    for i in (1, 2):
        at = _at(pos, i)
        point, load = _hand_load(at)
        forces, torque = lagrange_joint_forces(mech, motion.poses_at(i), _xy(point), _xy(load))
        expected, expected_torque = _hand_equilibrium(at, point, load)
        assert set(forces) == set(JOINTS)
        for j in JOINTS:
            assert forces[j] == pytest.approx(expected[j], rel=1e-8), (j, i)
        assert torque == pytest.approx(expected_torque, rel=1e-8), i


def test_lagrange_joint_forces_compute_in_double_precision_from_single_precision_poses():
    """Body poses handed over as float32 give the forces of the same (exactly converted) poses as float64,
    to rel 1e-12: the multipliers are computed in double precision whatever the input dtype (float32
    sines and cosines would be off by ~1e-7)."""
    mech = _hand_mechanism(EXTENDED)
    poses = mech.sweep(np.array([0.0, -23.0])).poses_at(1)
    single = {k: v.astype(np.float32) for k, v in poses.items()}
    double = {k: v.astype(np.float64) for k, v in single.items()}
    point, load = np.array([88.0, -25.0]), np.array([0.6, -0.8])
    f32, t32 = lagrange_joint_forces(mech, single, point, load)
    f64, t64 = lagrange_joint_forces(mech, double, point, load)
    for j in JOINTS:
        assert f32[j] == pytest.approx(f64[j], rel=1e-12, abs=1e-12), j
    assert t32 == pytest.approx(t64, rel=1e-12)


def test_virtual_work_torque_of_the_six_bar_matches_the_hand_equilibrium():
    """virtual_work_torque on the generic mechanism (velocity of the midpoint of e-c from the solver's
    Jacobian) equals the torque of the hand equilibrium at the same inputs (rel 1e-7)."""
    finger = FLEXED
    mech = _hand_mechanism(finger)
    inputs = np.array([0.0, -9.0, -26.0])
    motion = mech.sweep(inputs)
    pos = _hand_poses(finger, finger["theta1_start"] + np.radians(inputs))
    mid_local = 0.5 * (np.asarray(finger["e"]) + np.asarray(finger["c"]))  # distal frame = world at position 1

    def load_of_pose(poses):
        e = transform_points(poses["distal"], np.asarray(finger["e"]))
        c = transform_points(poses["distal"], np.asarray(finger["c"]))
        ec = c - e
        return 0.5 * (e + c), np.array([-ec[1], ec[0]]) / np.hypot(*ec)

    for i in range(len(inputs)):
        at = _at(pos, i)
        _, expected = _hand_equilibrium(at, *_hand_load(at))
        got = virtual_work_torque(mech, motion, mid_local, "distal", load_of_pose, i)
        assert got == pytest.approx(expected, rel=1e-7), i


def test_virtual_work_torque_uses_the_drivers_relative_angle():
    """A four-bar O-A-B-D driven by the angle of the rocker relative to the coupler (not to the ground): the
    torque balancing a fixed force on the coupler is T = -F . dP / d(theta_rocker - theta_coupler), with
    both derivatives from central differences (h = 0.01 deg) of the solved motion; rel 1e-6 (difference
    error ~ (1.7e-4 rad)^2, solver noise ~ 1e-10 mm over 5e-3 mm steps)."""
    o, a, b, d, p = (0.0, 0.0), (4.0, 14.0), (37.0, 22.0), (41.0, 3.0), (25.0, 31.0)
    mech = Mechanism(
        name="relative", ground="ground", gears=(),
        bodies=(Body("ground", {"O": o, "D": d}), Body("crank", {"O": o, "A": a}),
                Body("coupler", {"A": a, "B": b, "P": p}), Body("rocker", {"D": d, "B": b})),
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker")),
        drivers=(Driver("angle", "rocker", "coupler"),), input_range=(0.0, 20.0),
        assembly={"crank": (0.0, 0.0, 0.0), "coupler": (0.0, 0.0, 0.0), "rocker": (0.0, 0.0, 0.0)})
    force = np.array([1.5, -2.0])
    h = 0.01
    motion = mech.sweep(np.array([0.0, 7.0 - h, 7.0, 7.0 + h, 15.0 - h, 15.0, 15.0 + h]))
    pts = motion.point("P", "coupler")
    rel = motion.relative_angle("rocker", "coupler")
    assert np.ptp(motion.relative_angle("crank", "ground")) > 0.1  # the whole linkage moves
    for i in (2, 5):
        got = virtual_work_torque(mech, motion, np.array(p), "coupler", lambda poses: (None, force), i)
        expected = -float(force @ (pts[i + 1] - pts[i - 1])) / (rel[i + 1] - rel[i - 1])
        assert got == pytest.approx(expected, rel=1e-6), i


# -- segment_distance, middle_link_clearance ---------------------------------------------------------------

@pytest.mark.parametrize("p, a, b, expected", [
    ((2.0, 5.0), (0.0, 1.0), (6.0, 1.0), 4.0),     # foot inside: perpendicular distance
    ((-3.0, 5.0), (0.0, 1.0), (6.0, 1.0), 5.0),    # before a: 3-4-5 to a
    ((9.0, -3.0), (0.0, 1.0), (6.0, 1.0), 5.0),    # past b (foot at 1.5 of the segment): 3-4-5 to b
    ((20.0, 1.0), (0.0, 1.0), (6.0, 1.0), 14.0),   # on the line, far past b (foot at 3.33)
    ((-0.7, 6.4), (1.0, 2.0), (4.0, 6.0), 4.0),    # slanted 3-4-5 segment: a + 0.5 (3, 4) + 4 (-0.8, 0.6)
    ((2.6, 10.8), (1.0, 2.0), (4.0, 6.0), 5.0),    # slanted, past b: b + 3 (0.6, 0.8) + 4 (-0.8, 0.6), foot 1.6
])
def test_segment_distance_closed_form(p, a, b, expected):
    """Distance from a point to a segment: perpendicular where the foot is on the segment, else to the
    nearer end; the points are built by hand from the segment's unit direction and normal (3-4-5
    triangles), to rel 1e-12."""
    got = segment_distance(np.array(p), np.array(a), np.array(b))
    assert float(got) == pytest.approx(expected, rel=1e-12)


def test_segment_distance_is_vectorised():
    """(N, S, 2) points against (N, S, 2) segments give (N, S) distances, each as its scalar case."""
    p = np.array([[[2.0, 5.0], [9.0, -3.0]], [[-3.0, 5.0], [2.6, 10.8]]])
    a = np.array([[[0.0, 1.0], [0.0, 1.0]], [[0.0, 1.0], [1.0, 2.0]]])
    b = np.array([[[6.0, 1.0], [6.0, 1.0]], [[6.0, 1.0], [4.0, 6.0]]])
    got = segment_distance(p, a, b)
    assert got.shape == (2, 2)
    np.testing.assert_allclose(got, [[4.0, 5.0], [5.0, 5.0]], rtol=1e-12)


def _hand_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """min(|p - a|, |p - b|, perpendicular distance where the foot falls between a and b) (complex)."""
    ab = b - a
    along = np.real(np.conj(ab) * (p - a)) / np.abs(ab)
    perp_dist = np.abs(_cross(ab, p - a)) / np.abs(ab)
    inside = (along >= 0) & (along <= np.abs(ab))
    return np.minimum(np.minimum(np.abs(p - a), np.abs(p - b)), np.where(inside, perp_dist, np.inf))


@pytest.mark.parametrize("name", FINGERS)
def test_middle_link_clearance_against_hand_positions(name):
    """Smallest distance of d and e from the segment a-b over the motion, from the hand assembly and a
    nearest-of-three distance (1e-9 mm); NaN when any input cannot be assembled."""
    finger = FINGERS[name]
    theta = _flexion(finger)
    pos = _hand_poses(finger, theta)
    expected = min(np.min(_hand_segment_distance(pos[j], pos["a"], pos["b"])) for j in ("d", "e"))
    got = middle_link_clearance(_batch(finger), theta)
    assert got.shape == (1,) and got[0] == pytest.approx(expected, abs=1e-9)
    assert np.isnan(middle_link_clearance(_batch(finger), _flexion(finger, 41, 40.0))[0])


def test_a_mechanism_whose_first_position_is_a_toggle_is_never_assembled():
    """Regression (found by helper-30): with d, f, d0 collinear at position 1 (d = (45, 25.5), f = (39, 17.5),
    d0 = (33, 9.5): f - d = (-6, -8), d0 - f = (-6, -8)) the branch sign is 0, and assemble put f on the d-d0
    centre line at every input (link d-f 9.898 mm instead of 10) while reporting a positive margin, so
    fingertip_errors gave a finite, wrong 2.01 mm. There is no branch to keep: the margin is negative at every
    input and the errors are NaN."""
    batch = SixBarBatch(np.array([46.0, 19.5]), np.array([75.5, 24.5]), np.array([100.0, 21.0]),
                        np.array([[45.0, 25.5]]), np.array([[76.0, 16.0]]), np.array([[39.0, 17.5]]),
                        np.array([[33.0, 9.5]]), 0.25)
    poses = assemble(batch, np.array([0.25, 0.24, 0.3]))
    assert np.all(poses.margin < 0.0)
    errors = fingertip_errors(batch, np.array([0.25, 0.24]), np.array([[100.0, 21.0]] * 2))
    assert np.all(np.isnan(errors))
