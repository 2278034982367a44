"""The generic planar solver against closed forms written independently here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.errors import LockupError, SpecError
from fabricate.mechanism import Body, Driver, GearCoupling, LinearLaw, Mechanism, Revolute, Slider
from tests.conftest import make_four_bar


def freudenstein_rocker(crank, coupler, rocker, ground, theta, upper=True):
    """Rocker angle of a four-bar by the Freudenstein/half-angle closed form (rad)."""
    ax, ay = crank * np.cos(theta), crank * np.sin(theta)
    big_a = 2.0 * rocker * (ground - ax)
    big_b = -2.0 * rocker * ay
    big_c = coupler**2 - rocker**2 - (ground - ax) ** 2 - ay**2
    # |D + rocker u(phi) - A| = coupler  <=>  A cos(phi) + B sin(phi) = C
    base = np.arctan2(big_b, big_a)
    spread = np.arccos(np.clip(big_c / np.hypot(big_a, big_b), -1.0, 1.0))
    return base + spread if upper else base - spread


def test_four_bar_matches_freudenstein_to_1e9():
    mech = make_four_bar()
    motion = mech.sweep(721)
    theta = np.radians(motion.inputs)
    b_closed = np.array([40.0, 0.0]) + 30.0 * np.column_stack(
        [np.cos(freudenstein_rocker(15, 40, 30, 40, theta)), np.sin(freudenstein_rocker(15, 40, 30, 40, theta))])
    b_generic = motion.point("B", "rocker")
    assert np.max(np.hypot(*(b_closed - b_generic).T)) < 1e-9


def test_sweep_keeps_link_lengths_and_is_continuous():
    motion = make_four_bar().sweep(361)
    a, b = motion.point("A"), motion.point("B", "coupler")
    assert np.max(np.abs(np.hypot(*(b - a).T) - 40.0)) < 1e-9
    assert np.max(np.abs(np.hypot(*(b - [40.0, 0.0]).T) - 30.0)) < 1e-9
    # one-degree input steps move the rocker smoothly: no jump to the other branch
    assert np.max(np.abs(np.diff(motion.pose("rocker")[:, 2]))) < math.radians(3.0)


def test_lower_branch_is_kept_when_assembled_there():
    motion = make_four_bar(upper=False).sweep(181)
    theta = np.radians(motion.inputs)
    phi = freudenstein_rocker(15, 40, 30, 40, theta, upper=False)
    b_closed = np.array([40.0, 0.0]) + 30.0 * np.column_stack([np.cos(phi), np.sin(phi)])
    assert np.max(np.hypot(*(b_closed - motion.point("B", "rocker")).T)) < 1e-9


def test_lockup_reported_with_input_value():
    # a non-Grashof linkage: the crank cannot turn past the angle where |O-D|... A-B-D triangle fails
    mech = make_four_bar(crank=25.0, coupler=30.0, rocker=20.0, ground=40.0, start_deg=0.0, end_deg=180.0)
    with pytest.raises(LockupError) as info:
        mech.sweep(181)
    # the coupler and rocker reach full stretch where |A - D| = coupler + rocker... or their difference
    # |A-D|^2 = 25^2 + 40^2 - 2*25*40 cos(theta) = 50^2 -> theta
    limit = math.degrees(math.acos((25**2 + 40**2 - 50**2) / (2 * 25 * 40)))
    assert info.value.input_value == pytest.approx(limit, abs=0.05)
    assert "lock-up" in str(info.value)


def test_solve_matches_sweep():
    mech = make_four_bar()
    poses = mech.solve(200.0)
    motion = mech.sweep(np.linspace(60.0, 200.0, 141))
    assert np.allclose(poses["rocker"], motion.pose("rocker")[-1], atol=1e-10)


def test_velocity_matches_finite_differences():
    mech = make_four_bar()
    s, h = 150.0, 1e-4
    motion = mech.sweep(np.array([60.0, s - h, s, s + h]))
    fd = (motion.pose("rocker")[3] - motion.pose("rocker")[1]) / (2 * h)
    vel = mech.velocity(motion.poses_at(2), s)["rocker"]
    assert np.allclose(vel, fd, atol=1e-6)


def test_slider_crank_against_closed_form():
    r, l = 10.0, 35.0
    th0 = math.radians(30.0)
    a = np.array([r * math.cos(th0), r * math.sin(th0)])
    x_b = a[0] + math.sqrt(l**2 - a[1] ** 2)
    mech = Mechanism(
        name="slider_crank",
        bodies=(Body("ground", {"O": (0.0, 0.0), "S": (0.0, 0.0)}), Body("crank", {"O": (0.0, 0.0), "A": (r, 0.0)}),
                Body("rod", {"A": (0.0, 0.0), "B": (l, 0.0)}), Body("slider", {"B": (0.0, 0.0), "S": (0.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "rod"), Revolute("B", "rod", "slider"),
                Slider("S", "ground", "slider", axis=(1.0, 0.0))),
        gears=(), drivers=(Driver("angle", "crank", "ground"),), input_range=(30.0, 330.0),
        assembly={"crank": (0, 0, th0), "rod": (a[0], a[1], math.atan2(-a[1], x_b - a[0])),
                  "slider": (x_b - 0.0, 0.0, 0.0)})
    motion = mech.sweep(301)
    th = np.radians(motion.inputs)
    expected = r * np.cos(th) + np.sqrt(l**2 - (r * np.sin(th)) ** 2)
    assert np.max(np.abs(motion.point("B", "slider")[:, 0] - expected)) < 1e-9
    assert np.max(np.abs(motion.point("B", "slider")[:, 1])) < 1e-9


def test_slide_driver_and_gear_coupling():
    # a rack-free check of the gear constraint: two gears on a fixed carrier with ratio -2
    mech = Mechanism(
        name="gears",
        bodies=(Body("frame", {"P": (0.0, 0.0), "Q": (30.0, 0.0)}), Body("g1", {"P": (0.0, 0.0)}),
                Body("g2", {"Q": (0.0, 0.0)})),
        ground="frame",
        joints=(Revolute("P", "frame", "g1"), Revolute("Q", "frame", "g2")),
        gears=(GearCoupling("pair", "frame", "g1", "g2", LinearLaw(-2.0, 0.1), "P", "Q"),),
        drivers=(Driver("angle", "g1", "frame"),), input_range=(0.0, 90.0),
        assembly={"g1": (0.0, 0.0, 0.0), "g2": (30.0, 0.0, 0.1)})
    motion = mech.sweep(91)
    assert np.allclose(motion.pose("g2")[:, 2], -2.0 * np.radians(motion.inputs) + 0.1, atol=1e-12)


def test_under_constrained_mechanism_is_rejected():
    with pytest.raises(SpecError, match="degree"):
        Mechanism(name="loose", bodies=(Body("g", {"O": (0, 0)}), Body("a", {"O": (0, 0)})), ground="g",
                  joints=(Revolute("O", "g", "a"),), gears=(), drivers=(), input_range=(0, 1))


def test_four_bar_without_its_driver_is_one_degree_of_freedom_short():
    """Four bars, four revolutes: 3 x 3 coordinates against 4 x 2 equations, one freedom left undriven
    (Gruebler's count; the three-body case above cannot tell 3 (n - 1) from 3 / (n - 1))."""
    mech = make_four_bar()
    with pytest.raises(SpecError) as err:
        Mechanism(name="loose", bodies=mech.bodies, ground=mech.ground, joints=mech.joints, gears=(), drivers=(),
                  input_range=(0, 1))
    assert err.value.path == "mechanism"
    assert "under-constrained: 1 degree(s)" in err.value.message


@pytest.mark.parametrize(("change", "path", "needle"), [
    ({"bodies": "twice"}, "mechanism.bodies", "body names must be unique"),
    ({"ground": "floor"}, "mechanism.ground", "unknown body 'floor'"),
    ({"joints": "stray"}, "mechanism.joints.O", "unknown body 'palm'"),
    ({"input_unit": "rad"}, "mechanism.input_unit", "expected 'deg' or 'mm', got 'rad'"),
])
def test_bad_mechanism_fields_are_named(change, path, needle):
    """A bad mechanism names the field (the path a template user looks up) and what was wrong with it."""
    base = make_four_bar()
    fields = {"name": "bad", "bodies": base.bodies, "ground": base.ground, "joints": base.joints, "gears": (),
              "drivers": base.drivers, "input_range": (0, 1), "input_unit": "deg"}
    if change.get("bodies"):
        fields["bodies"] = base.bodies + (base.bodies[1],)
    if change.get("ground"):
        fields["ground"] = change["ground"]
    if change.get("joints"):
        fields["joints"] = (Revolute("O", "ground", "palm"),) + base.joints[1:]
    if change.get("input_unit"):
        fields["input_unit"] = change["input_unit"]
    with pytest.raises(SpecError) as err:
        Mechanism(**fields)
    assert err.value.path == path
    assert needle in err.value.message


def test_joint_point_missing_is_named():
    with pytest.raises(SpecError, match="no point 'X'"):
        Mechanism(name="bad", bodies=(Body("g", {"O": (0, 0)}), Body("a", {"O": (0, 0)})), ground="g",
                  joints=(Revolute("X", "g", "a"),), gears=(), drivers=(), input_range=(0, 1))


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(crank=st.floats(5.0, 12.0), coupler=st.floats(35.0, 45.0), rocker=st.floats(25.0, 35.0),
       start=st.floats(0.0, 360.0))
def test_grashof_crank_rockers_turn_fully(crank, coupler, rocker, start):
    ground = 40.0
    # Grashof with the crank shortest: s + l <= p + q
    lengths = sorted([crank, coupler, rocker, ground])
    if lengths[0] != crank or lengths[0] + lengths[3] > lengths[1] + lengths[2] - 1.0:
        return
    motion = make_four_bar(crank, coupler, rocker, ground, start, start + 360.0).sweep(181)
    a, b = motion.point("A"), motion.point("B", "coupler")
    assert np.max(np.abs(np.hypot(*(b - a).T) - coupler)) < 1e-9
    phi = freudenstein_rocker(crank, coupler, rocker, ground, np.radians(motion.inputs))
    assert np.allclose(np.cos(motion.pose("rocker")[:, 2]), np.cos(phi), atol=1e-9)
