"""Properties of the planar solver a user depends on, against closed forms written here.

These tests were written to kill mutants of ``fabricate/mechanism.py`` (see
``tests/benchmarks/mutation_report.md``): a sweep through a change point must be reported, not
followed silently onto the other assembly branch.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from fabricate.errors import LockupError
from fabricate.mechanism import Body, Driver, LinearLaw, Mechanism, Revolute
from tests.conftest import make_four_bar


def parallelogram(start_deg: float, end_deg: float, crank: float = 20.0, ground: float = 40.0) -> Mechanism:
    """A parallelogram four-bar O-A-B-D (crank = rocker, coupler = ground), assembled as a parallelogram.

    Closed form: on the parallelogram branch the rocker stays parallel to the crank (phi = theta) and the
    coupler keeps angle 0. At theta = 0 and pi every link is collinear: a change point, where the
    anti-parallelogram branch crosses this one and the constraint Jacobian is singular
    (d/dphi |B - A|^2 = -2 * ground * crank * sin(theta) changes sign).
    """
    th = math.radians(start_deg)
    return Mechanism(
        name="parallelogram",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (ground, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (crank, 0.0)}),
                Body("coupler", {"A": (0.0, 0.0), "B": (ground, 0.0)}),
                Body("rocker", {"D": (0.0, 0.0), "B": (crank, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker")),
        gears=(),
        drivers=(Driver("angle", "crank", "ground"),),
        input_range=(start_deg, end_deg),
        assembly={"crank": (0.0, 0.0, th),
                  "coupler": (crank * math.cos(th), crank * math.sin(th), 0.0),
                  "rocker": (ground, 0.0, th)},
    )


def test_parallelogram_away_from_change_points_follows_closed_form():
    """Control: between the change points the sweep is fine and phi = theta exactly."""
    motion = parallelogram(20.0, 160.0).sweep(57)
    theta = np.radians(motion.inputs)
    np.testing.assert_allclose(motion.pose("rocker")[:, 2], theta, atol=1e-9)
    np.testing.assert_allclose(motion.pose("coupler")[:, 2], 0.0, atol=1e-9)


@pytest.mark.parametrize(("start", "end"), [(60.0, 300.0), (-120.0, 120.0), (300.0, 60.0)])
def test_sweep_through_change_point_is_reported(start, end):
    """A linkage driven through a change point (all links collinear) must raise a branch-change error
    at that input, not flip to the anti-parallelogram silently or stop with a plain lock-up."""
    mech = parallelogram(start, end)
    with pytest.raises(LockupError, match="branch change") as info:
        mech.sweep(25)
    change_points = np.array([-180.0, 0.0, 180.0, 360.0])
    # the error names an input near the first change point on the way (within one sweep step)
    first = change_points[(change_points - start) * np.sign(end - start) > 0]
    first = first[np.argmin(np.abs(first - start))]
    assert abs(info.value.input_value - first) <= abs(end - start) / 24 + 1e-6  # input in degrees


def test_linear_law_and_its_derivatives_on_integer_input():
    """y = 0.5 x - 2, y' = 0.5, y'' = 0, also for an integer array (no truncation to int)."""
    law = LinearLaw(0.5, -2.0)
    x = np.array([0, 1, 3])
    np.testing.assert_array_equal(law(x), [-2.0, -1.5, -0.5])
    np.testing.assert_array_equal(law(x, 1), [0.5, 0.5, 0.5])
    np.testing.assert_array_equal(law(x, 2), [0.0, 0.0, 0.0])
    assert law(x, 1).dtype == np.float64 and law(x, 2).dtype == np.float64


def test_lookups_name_what_is_missing():
    mech = make_four_bar()
    with pytest.raises(KeyError, match="nobody"):
        mech.body("nobody")
    with pytest.raises(KeyError, match="Z9"):
        mech.point_owner("Z9")
    assert mech.point_names() == ("O", "D", "A", "B")
    assert mech.degrees_of_freedom() == 1  # 3 (4 - 1) - 2 * 4
    assert Body("b", {"P": (1, 2)}).point("P").dtype == np.float64


def test_solve_anywhere_matches_the_sweep():
    """solve(s) follows the first pose's branch to s: equal to the sweep there, at the start, at the end
    and far from the start (300 deg: a plain Newton from the assembly guess would not get there)."""
    mech = make_four_bar()
    motion = mech.sweep(np.array([60.0, 180.0, 360.0, 420.0]))
    for i, s in enumerate(motion.inputs):
        pose = mech.solve(float(s))
        for name in mech.body_names:
            np.testing.assert_allclose(pose[name], motion.pose(name)[i], atol=1e-9)


def test_sweep_default_count_cache_and_read_only_results():
    mech = make_four_bar()
    assert len(mech.sweep().inputs) == 361  # documented default
    first = mech.sweep(5)
    counts = [len(mech.sweep(n).inputs) for n in range(6, 17)]  # more sweeps than the cache holds
    assert counts == list(range(6, 17))
    again = mech.sweep(5)
    assert len(again.inputs) == 5
    np.testing.assert_array_equal(again.q, first.q)
    assert mech.sweep(9) is mech.sweep(9)  # the same motion object is shared, so it must be read-only
    motion = mech.sweep(9)
    assert mech.sweep([60, 90, 120]).inputs.dtype == np.float64  # integer inputs are degrees, not ints
    for array in (motion.inputs, motion.q):
        with pytest.raises(ValueError):
            array[0] = 0.0


def test_velocity_shapes_and_ground():
    mech = make_four_bar()
    motion = mech.sweep(7)
    v = mech.velocity(motion.poses_at(3), float(motion.inputs[3]))
    assert set(v) == set(mech.body_names)
    assert all(np.shape(v[name]) == (3,) for name in v)
    np.testing.assert_array_equal(v["ground"], np.zeros(3))
    assert motion.pose("ground").shape == (7, 3) and not motion.pose("ground").any()
    # the crank turns at the input rate (input in degrees)
    assert v["crank"][2] == pytest.approx(math.pi / 180.0, rel=1e-9)


def test_relative_angle_is_the_difference_of_body_angles():
    motion = make_four_bar().sweep(13)
    np.testing.assert_allclose(motion.relative_angle("coupler", "crank"),
                               motion.pose("coupler")[:, 2] - motion.pose("crank")[:, 2], atol=0)
    np.testing.assert_allclose(motion.relative_angle("crank", "ground"), np.radians(motion.inputs), atol=1e-9)


def test_joints_declared_with_ground_second_give_the_same_motion():
    """Revolutes may name the ground as their second body: the motion must not depend on the order."""
    mech = make_four_bar()
    flipped = Mechanism(
        name="four_bar_flipped", bodies=mech.bodies, ground="ground",
        joints=(Revolute("O", "crank", "ground"), Revolute("A", "coupler", "crank"),
                Revolute("B", "rocker", "coupler"), Revolute("D", "rocker", "ground")),
        gears=(), drivers=mech.drivers, input_range=mech.input_range, assembly=mech.assembly)
    a, b = mech.sweep(37), flipped.sweep(37)
    for name in ("crank", "coupler", "rocker"):
        np.testing.assert_allclose(b.pose(name), a.pose(name), atol=1e-9)


def test_off_axis_joint_points_follow_the_closed_form():
    """Joint points off their body's x axis (a ternary coupler, a bent rocker): the solver must rotate local
    points by the full rotation (both the sin and cos terms). Closed form: Freudenstein for the rocker,
    then the coupler point from the rigid triangle A-B-P."""
    from tests.test_mechanism import freudenstein_rocker

    crank, coupler, rocker, ground = 15.0, 40.0, 30.0, 40.0
    beta, gamma = 0.5, -0.7  # B's direction in the coupler frame, B's direction in the rocker frame
    p_local = np.array([12.0, 9.0])  # a coupler point off the A-B line
    base = make_four_bar(crank, coupler, rocker, ground, start_deg=60.0, end_deg=300.0)
    b_c = coupler * np.array([math.cos(beta), math.sin(beta)])
    b_r = rocker * np.array([math.cos(gamma), math.sin(gamma)])
    c0, r0 = base.assembly["coupler"], base.assembly["rocker"]
    mech = Mechanism(
        name="bent_four_bar",
        bodies=(base.body("ground"), base.body("crank"),
                Body("coupler", {"A": (0.0, 0.0), "B": tuple(b_c), "P": tuple(p_local)}),
                Body("rocker", {"D": (0.0, 0.0), "B": tuple(b_r)})),
        ground="ground", joints=base.joints, gears=(), drivers=base.drivers, input_range=base.input_range,
        assembly={"crank": base.assembly["crank"], "coupler": (c0[0], c0[1], c0[2] - beta),
                  "rocker": (r0[0], r0[1], r0[2] - gamma)})
    motion = mech.sweep(49)
    theta = np.radians(motion.inputs)
    phi = freudenstein_rocker(crank, coupler, rocker, ground, theta)
    b_world = np.column_stack([ground + rocker * np.cos(phi), rocker * np.sin(phi)])
    np.testing.assert_allclose(motion.point("B", "rocker"), b_world, atol=1e-9)
    np.testing.assert_allclose(motion.point("B", "coupler"), b_world, atol=1e-9)
    a_world = crank * np.column_stack([np.cos(theta), np.sin(theta)])
    np.testing.assert_allclose(motion.point("A", "coupler"), a_world, atol=1e-9)
    # P from the triangle: A + R(angle of AB - beta) p_local
    ang = np.arctan2(*(b_world - a_world)[:, ::-1].T) - beta
    p_world = a_world + np.column_stack([np.cos(ang) * p_local[0] - np.sin(ang) * p_local[1],
                                         np.sin(ang) * p_local[0] + np.cos(ang) * p_local[1]])
    np.testing.assert_allclose(motion.point("P"), p_world, atol=1e-9)


def test_millimetre_sized_linkage_follows_the_closed_form():
    """A linkage far smaller than 1 mm (0.2 mm crank): the branch guard scales with the mechanism, so
    ordinary steps are accepted and the result is Freudenstein's."""
    from tests.test_mechanism import freudenstein_rocker

    k = 0.02
    mech = make_four_bar(15 * k, 40 * k, 30 * k, 40 * k, start_deg=60.0, end_deg=420.0)
    motion = mech.sweep(25)
    theta = np.radians(motion.inputs)
    phi = freudenstein_rocker(15 * k, 40 * k, 30 * k, 40 * k, theta)
    np.testing.assert_allclose(motion.point("B", "rocker"),
                               np.column_stack([40 * k + 30 * k * np.cos(phi), 30 * k * np.sin(phi)]), atol=1e-10)


def test_gear_train_counts_the_coupling_and_follows_the_ratio():
    """Two gears on the ground coupled by a law: Gruebler 3 (3 - 1) - 2 * 2 - 1 = 1 degree of freedom, and
    the driven gear turns at the law's ratio (closed form theta_b = -0.5 theta_a)."""
    from fabricate.mechanism import GearCoupling

    mech = Mechanism(
        name="gear_train",
        bodies=(Body("ground", {"A": (0.0, 0.0), "B": (30.0, 0.0)}), Body("ga", {"A": (0.0, 0.0)}),
                Body("gb", {"B": (0.0, 0.0)})),
        ground="ground",
        joints=(Revolute("A", "ground", "ga"), Revolute("B", "ground", "gb")),
        gears=(GearCoupling("pair", "ground", "ga", "gb", LinearLaw(-0.5), "A", "B"),),
        drivers=(Driver("angle", "ga", "ground"),),
        input_range=(0.0, 90.0),
        assembly={"ga": (0.0, 0.0, 0.0), "gb": (30.0, 0.0, 0.0)},
    )
    assert mech.degrees_of_freedom() == 1
    motion = mech.sweep(7)
    np.testing.assert_allclose(motion.pose("gb")[:, 2], -0.5 * np.radians(motion.inputs), atol=1e-9)
    np.testing.assert_allclose(motion.point("B", "gb"), [[30.0, 0.0]] * 7, atol=1e-9)


class QuadraticLaw:
    """theta = a + b s + c s^2 (rad) and its derivatives, written here."""

    def __init__(self, a: float, b: float, c: float) -> None:
        self.a, self.b, self.c = a, b, c

    def __call__(self, s, nu: int = 0):
        s = np.asarray(s, dtype=np.float64)
        if nu == 0:
            return self.a + self.b * s + self.c * s * s
        if nu == 1:
            return self.b + 2.0 * self.c * s
        if nu == 2:
            return np.full_like(s, 2.0 * self.c)
        return np.zeros_like(s)


def test_driver_law_sets_the_crank_angle_and_its_rate():
    """A driver with its own law: the crank angle is law(s) and the crank's velocity is law'(s) (closed
    form), the other bodies' rates match finite differences of the sweep."""
    base = make_four_bar(start_deg=60.0)
    law = QuadraticLaw(math.radians(60.0), 0.05, 0.004)
    mech = Mechanism(name="law_driven", bodies=base.bodies, ground="ground", joints=base.joints, gears=(),
                     drivers=(Driver("angle", "crank", "ground", law=law),), input_range=(0.0, 20.0),
                     assembly=base.assembly)
    motion = mech.sweep(41)
    np.testing.assert_allclose(motion.pose("crank")[:, 2], law(motion.inputs), atol=1e-9)
    for i in (5, 20, 33):
        s = float(motion.inputs[i])
        v = mech.velocity(motion.poses_at(i), s)
        assert v["crank"][2] == pytest.approx(0.05 + 0.008 * s, rel=1e-9)
        h = 1e-4
        fd = (mech.solve(s + h)["rocker"] - mech.solve(s - h)["rocker"]) / (2 * h)
        np.testing.assert_allclose(v["rocker"], fd, atol=1e-5)


def _velocity_matches_finite_differences(mech: Mechanism, count: int = 9, h: float = 1e-4, atol: float = 1e-5):
    motion = mech.sweep(count)
    lo, hi = sorted(mech.input_range)
    for i in range(1, count - 1):
        s = float(motion.inputs[i])
        if not (lo + h < s < hi - h):
            continue
        v = mech.velocity(motion.poses_at(i), s)
        ahead, behind = mech.solve(s + h), mech.solve(s - h)
        for name in mech.body_names:
            np.testing.assert_allclose(v[name], (ahead[name] - behind[name]) / (2 * h), atol=atol, err_msg=name)


@pytest.mark.slow
def test_velocity_of_off_axis_and_slider_mechanisms():
    """The constraint Jacobian (through velocity = -J^-1 dres/ds) against finite differences of the solved
    poses: a crank-slider (slider joint: projection and fixed-angle rows) and a four-bar whose joint points
    lie off their bodies' x axes (rotation-derivative terms of both coordinates)."""
    from tests.parts.test_build import slider_crank

    _velocity_matches_finite_differences(slider_crank())
    base = make_four_bar()
    beta = 0.6
    c0 = base.assembly["coupler"]
    bent = Mechanism(
        name="bent", bodies=(base.body("ground"), base.body("crank"),
                             Body("coupler", {"A": (0.0, 0.0), "B": (40.0 * math.cos(beta), 40.0 * math.sin(beta))}),
                             base.body("rocker")),
        ground="ground", joints=base.joints, gears=(), drivers=base.drivers, input_range=base.input_range,
        assembly={**base.assembly, "coupler": (c0[0], c0[1], c0[2] - beta)})
    _velocity_matches_finite_differences(bent)


# -- the constraint system against its definition, for sliders and gears on moving bodies ------------
def _rot(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def kitchen_sink(unit: str = "deg", slide_law=None) -> Mechanism:
    """Every constraint kind with both of its bodies moving (not solved, only evaluated): a slider on a
    turning rocker with a non-unit axis, an off-origin line point and a locked angle of 0.3 rad; a gear pair
    whose carrier turns; an angle driver and a slide driver whose reference turns."""
    from fabricate.mechanism import GearCoupling, Slider

    return Mechanism(
        name="sink",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (40.0, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "P": (15.0, 2.0)}),
                Body("rocker", {"D": (0.0, 0.0), "S": (5.0, 1.0), "H": (3.0, -2.0)}),
                Body("block", {"P": (0.0, 0.0), "S": (0.5, -0.3)}),
                Body("wheel", {"H": (0.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("D", "ground", "rocker"),
                Revolute("P", "crank", "block"), Slider("S", "rocker", "block", (1.0, 0.2), angle=0.3),
                Revolute("H", "rocker", "wheel")),
        gears=(GearCoupling("g", "rocker", "crank", "wheel", QuadraticLaw(0.1, -0.7, 0.2), "O", "H"),),
        drivers=(Driver("angle", "crank", "ground"), Driver("slide", "block", "rocker", joint="S", law=slide_law)),
        input_range=(0.0, 10.0), input_unit=unit,
        assembly={})


def sink_residual(q: np.ndarray, s: float, unit: str, slide_law) -> tuple[np.ndarray, np.ndarray]:
    """The residual and d/ds of ``kitchen_sink`` written out from the constraint definitions."""
    names = ["crank", "rocker", "block", "wheel"]
    pose = {"ground": np.zeros(3), **{n: q[3 * k:3 * k + 3] for k, n in enumerate(names)}}
    pts = {"ground": {"O": (0.0, 0.0), "D": (40.0, 0.0)}, "crank": {"O": (0.0, 0.0), "P": (15.0, 2.0)},
           "rocker": {"D": (0.0, 0.0), "S": (5.0, 1.0), "H": (3.0, -2.0)},
           "block": {"P": (0.0, 0.0), "S": (0.5, -0.3)}, "wheel": {"H": (0.0, 0.0)}}

    def w(body, p):
        return _rot(pose[body][2]) @ np.asarray(pts[body][p]) + pose[body][:2]

    th = {n: pose[n][2] for n in pose}
    res = []
    for p, a, b in (("O", "ground", "crank"), ("D", "ground", "rocker"), ("P", "crank", "block"),
                    ("H", "rocker", "wheel")):
        res.extend(w(a, p) - w(b, p))
    axis = np.array([1.0, 0.2]) / math.hypot(1.0, 0.2)
    normal = np.array([-axis[1], axis[0]])
    res.append(th["block"] - th["rocker"] - 0.3)
    res.append(float(np.dot(w("block", "S") - w("rocker", "S"), _rot(th["rocker"]) @ normal)))
    law = QuadraticLaw(0.1, -0.7, 0.2)
    res.append((th["wheel"] - th["rocker"]) - law(th["crank"] - th["rocker"]))
    angle, dangle = (math.radians(s), math.pi / 180) if unit == "deg" else (s, 1.0)
    res.append(th["crank"] - angle)
    slide, dslide = (float(slide_law(s)), float(slide_law(s, 1))) if slide_law is not None else (s, 1.0)
    res.append(float(np.dot(w("block", "S") - w("rocker", "S"), _rot(th["rocker"]) @ axis)) - slide)
    ds = np.zeros(len(res))
    ds[-2], ds[-1] = -dangle, -dslide
    return np.asarray(res), ds


@pytest.mark.parametrize(("unit", "slide_law"), [("deg", None), ("mm", None), ("deg", QuadraticLaw(1.0, 0.5, 0.1))])
def test_constraint_residual_and_jacobian_of_sliders_and_gears_on_moving_bodies(unit, slide_law):
    """Residual against the constraint definitions (closed form above), Jacobian against a central finite
    difference of that residual (h = 1e-6: error ~1e-9 here), d(residual)/ds against the driver laws,
    at random poses (not assembled: the definitions hold everywhere)."""
    from fabricate.mechanism import _System

    mech = kitchen_sink(unit, slide_law)
    system = _System(mech)
    assert system.free == ["crank", "rocker", "block", "wheel"]
    rng = np.random.default_rng(7)
    h = 1e-6
    for _ in range(4):
        q = np.concatenate([[*rng.uniform(-30, 30, 2), rng.uniform(-3, 3)] for _ in range(4)])
        s = float(rng.uniform(-5, 5))
        res, jac, ds = system.jacobian(q, s)
        want, want_ds = sink_residual(q, s, unit, slide_law)
        np.testing.assert_allclose(res, want, atol=1e-10)
        np.testing.assert_allclose(ds, want_ds, atol=1e-12)
        fd = np.column_stack([(sink_residual(q + h * e, s, unit, slide_law)[0]
                               - sink_residual(q - h * e, s, unit, slide_law)[0]) / (2 * h) for e in np.eye(len(q))])
        np.testing.assert_allclose(jac, fd, atol=1e-6)


def whitworth(angle: float = 0.3) -> Mechanism:
    """An inverted slider-crank (Whitworth quick return): a block pinned to the crank at P slides along a
    rocker turning about D; the slide line is off the rocker's axis and not unit length, the block turned
    by ``angle`` against the rocker."""
    from fabricate.mechanism import Slider

    th = math.radians(60.0)
    p = 15.0 * np.array([math.cos(th), math.sin(th)])
    phi = math.atan2(p[1], p[0] - 40.0)
    return Mechanism(
        name="whitworth",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (40.0, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "P": (15.0, 0.0)}),
                Body("rocker", {"D": (0.0, 0.0), "S": (5.0, 1.0)}),
                Body("block", {"P": (0.0, 0.0), "S": (0.5, -0.3)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("D", "ground", "rocker"),
                Revolute("P", "crank", "block"), Slider("S", "rocker", "block", (1.0, 0.2), angle=angle)),
        gears=(), drivers=(Driver("angle", "crank", "ground"),), input_range=(60.0, 420.0),
        assembly={"crank": (0.0, 0.0, th), "rocker": (40.0, 0.0, phi), "block": (p[0], p[1], phi + angle)})


def test_inverted_slider_crank_keeps_the_block_on_the_line_and_its_velocity():
    """Slider on a turning body: the block's point S stays on the rocker's line through S (direction
    (1, 0.2) in the rocker frame) with the block turned 0.3 rad against the rocker, P follows the crank
    circle, and the velocities match central differences of the solved poses (h = 1e-4 deg)."""
    mech = whitworth()
    motion = mech.sweep(25)
    theta = np.radians(motion.inputs)
    np.testing.assert_allclose(motion.point("P", "block"), 15.0 * np.column_stack([np.cos(theta), np.sin(theta)]),
                               atol=1e-9)
    np.testing.assert_allclose(motion.relative_angle("block", "rocker"), 0.3, atol=1e-12)
    rocker = motion.pose("rocker")
    u = np.column_stack([np.cos(rocker[:, 2]) - 0.2 * np.sin(rocker[:, 2]),
                         np.sin(rocker[:, 2]) + 0.2 * np.cos(rocker[:, 2])])
    rel = motion.point("S", "block") - motion.point("S", "rocker")
    np.testing.assert_allclose(rel[:, 0] * u[:, 1] - rel[:, 1] * u[:, 0], 0.0, atol=1e-9)  # parallel to u
    assert np.ptp(rel[:, 0] * u[:, 0] + rel[:, 1] * u[:, 1]) > 10.0  # and it really slides
    _velocity_matches_finite_differences(mech, count=7, h=1e-4, atol=1e-6)


def test_geared_five_bar_velocity_matches_finite_differences():
    """A five-bar whose two cranks are geared (theta_2 = pi + 0.05 - 1.1 theta_1 + 0.05 theta_1^2 about a
    ground carrier): the closed-form law holds over the sweep, and velocity() matches central differences
    of solve()."""
    from fabricate.mechanism import GearCoupling
    from fabricate.planar import circle_circle_intersection

    law = QuadraticLaw(math.pi + 0.05, -1.1, 0.05)
    t1 = math.radians(60.0)
    t2 = float(law(t1))
    a = 15.0 * np.array([math.cos(t1), math.sin(t1)])
    b = np.array([30.0, 0.0]) + 15.0 * np.array([math.cos(t2), math.sin(t2)])
    c = circle_circle_intersection(a, 25.0, b, 25.0)
    c = c[int(np.argmax(c[:, 1]))]
    mech = Mechanism(
        name="geared_five_bar",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (30.0, 0.0)}),
                Body("left", {"O": (0.0, 0.0), "A": (15.0, 0.0)}), Body("right", {"D": (0.0, 0.0), "B": (15.0, 0.0)}),
                Body("c1", {"A": (0.0, 0.0), "C": (25.0, 0.0)}), Body("c2", {"B": (0.0, 0.0), "C": (25.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "left"), Revolute("D", "ground", "right"), Revolute("A", "left", "c1"),
                Revolute("B", "right", "c2"), Revolute("C", "c1", "c2")),
        gears=(GearCoupling("pair", "ground", "left", "right", law, "O", "D"),),
        drivers=(Driver("angle", "left", "ground"),), input_range=(60.0, 110.0),
        assembly={"left": (0.0, 0.0, t1), "right": (30.0, 0.0, t2),
                  "c1": (*a, math.atan2(*(c - a)[::-1])), "c2": (*b, math.atan2(*(c - b)[::-1]))})
    motion = mech.sweep(7)
    np.testing.assert_allclose(motion.pose("right")[:, 2], law(np.radians(motion.inputs)), atol=1e-9)
    _velocity_matches_finite_differences(mech, count=7, h=1e-4, atol=1e-6)


@pytest.mark.parametrize("unit", ["deg", "mm"])
def test_driver_values_are_the_laws_own_to_the_bit(unit):
    """The solver evaluates linear laws and the degree conversion on floats, not through the law: its values
    must be exactly the law's (float(law(s)), float(law(s, 1))) and numpy's radians, or builds would move."""
    from fabricate.mechanism import _System

    law = LinearLaw(slope=0.37, offset=-1.3)
    mech = dataclasses.replace(make_four_bar(), drivers=(Driver("angle", "crank", "ground", law=law),), input_unit=unit)
    plain = dataclasses.replace(make_four_bar(), input_unit=unit)
    linear, identity = _System(mech), _System(plain)
    for s in np.random.default_rng(3).uniform(-400, 400, 200):
        assert linear._driver_value(mech.drivers[0], s) == (float(law(s)), float(law(s, 1)))
        want = (float(np.radians(s)), float(np.pi / 180)) if unit == "deg" else (float(s), 1.0)
        assert identity._driver_value(plain.drivers[0], s) == want


def test_continuation_reusing_the_end_jacobian_equals_fresh_starts():
    """A sweep's continuation starts from where the previous one ended and reuses that end's Jacobian: the
    poses must be exactly those of a system that computes every start afresh (and a start elsewhere, or at
    another input, must not reuse it)."""
    from fabricate.mechanism import _System

    mech = make_four_bar()
    inputs = np.linspace(*mech.input_range, 73)
    reused = _System(mech)
    q = reused.assemble(inputs[0])
    want = q
    for a, b in zip(inputs[:-1], inputs[1:], strict=True):
        q = reused.continue_to(q, a, b)
        fresh = _System(mech)
        want = fresh.continue_to(want.copy(), a, b)
        assert np.array_equal(q, want)
    # the start is not recomputed where the last one ended ...
    calls: list[float] = []
    jacobian = reused.jacobian
    reused.jacobian = lambda q_, s_: (calls.append(s_), jacobian(q_, s_))[1]  # type: ignore[method-assign]
    on = reused.continue_to(q, inputs[-1], inputs[-2])
    assert calls[0] != inputs[-1]
    # ... but the same q object at another input is: the end's d(residual)/ds would be the wrong one
    calls.clear()
    back = reused.continue_to(on, inputs[-1], inputs[-3])
    assert calls[0] == inputs[-1]
    assert np.array_equal(back, _System(mech).continue_to(on.copy(), inputs[-1], inputs[-3]))
