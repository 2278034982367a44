"""Underactuated stacked four-bar finger: mobility, velocity recursion, statics, closing."""

from __future__ import annotations

import json
import types
from pathlib import Path

import numpy as np
import pytest
import tomllib
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.errors import SpecError
from fabricate.planar import circle_circle_intersection, unit
from fabricate.synthesis import underactuated as ua
from fabricate.synthesis.underactuated.closing import ClosingMotion, closing_motion
from fabricate.synthesis.underactuated.mechanism import build_mechanism, mobility
from fabricate.synthesis.underactuated.model import (
    contact_forces,
    crank_rate,
    distal_rate,
    finger_pose,
    finger_poses,
    palmar_normal,
    stroke_gradient,
    stroke_gradients,
    transmission_ratios,
    virtual_work_forces,
)
from fabricate.synthesis.underactuated.settler import Settler, face_clearance, face_geometry
from fabricate.table import Table

ROOT = Path(__file__).resolve().parents[3]
DATA = json.loads((Path(__file__).resolve().parents[2] / "data" / "underactuated_closing.json").read_text())


def _raw() -> dict:
    raw = tomllib.loads((ROOT / "templates" / "finger_underactuated.toml").read_text())
    for key in ("design", "process", "checks"):
        raw.pop(key)
    return raw


SPEC = ua.parse_spec(Table(_raw()))
DESIGN = SPEC.design

angles = st.tuples(*[st.floats(0.0, 0.6) for _ in range(3)])


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_mobility_is_n(n):
    assert mobility(n)["dof"] == n
    assert mobility(n)["underactuation"] == n - 1


def test_mechanism_mobility_counts_like_the_chapter():
    motion = ClosingMotion(np.linspace(0, 5, 5), np.zeros((5, 3)), np.zeros((5, 3), bool), [], [], False)
    mech = build_mechanism(SPEC, motion, "f")
    assert mech.degrees_of_freedom() == 3
    assert len(mech.drivers) == 3          # slide + two phalanx angles


def _rotate_input_arm(pose, i, delta):
    """Quadrilateral i with phalanx i held: turn b_i by delta, re-close, return the turn of a_i."""
    g0, g1 = pose.G[i], pose.G[i + 1]
    b_vec = pose.Q[i] - g0
    q_new = g0 + np.array([[np.cos(delta), -np.sin(delta)], [np.sin(delta), np.cos(delta)]]) @ b_vec
    c = np.hypot(*(pose.P[i] - pose.Q[i]))
    a = np.hypot(*(pose.P[i] - g1))
    roots = circle_circle_intersection(g1, a, q_new, c)
    p_new = roots[np.argmin(np.hypot(*(roots - pose.P[i]).T))]
    before = np.arctan2(*(pose.P[i] - g1)[::-1])
    after = np.arctan2(*(p_new - g1)[::-1])
    return np.arctan2(np.sin(after - before), np.cos(after - before))


@settings(max_examples=25, deadline=None)
@given(angles)
def test_velocity_ratios_match_finite_differences(q):
    pose = finger_pose(DESIGN, np.array(q))
    if pose is None:
        return
    ratios = transmission_ratios(pose)
    h = 1e-6
    for i in range(DESIGN.n - 1):
        fd = (_rotate_input_arm(pose, i, h) - _rotate_input_arm(pose, i, -h)) / (2 * h)
        assert abs(fd - ratios[i]) < 1e-5 * max(1.0, abs(ratios[i]))
    # slider-crank and the distal chain: with phalanges 1..n-1 held, q_n and psi_1 follow the stroke
    dq = np.zeros(DESIGN.n)
    dq[-1] = h
    hi, lo = finger_pose(DESIGN, pose.q + dq, pose), finger_pose(DESIGN, pose.q - dq, pose)
    ds = hi.stroke - lo.stroke
    assert abs((hi.psi[0] - lo.psi[0]) / ds - crank_rate(DESIGN, pose)) < 1e-5 * abs(crank_rate(DESIGN, pose))
    assert abs(2 * h / ds - distal_rate(DESIGN, pose)) < 1e-5 * abs(distal_rate(DESIGN, pose))


@settings(max_examples=25, deadline=None)
@given(angles, st.floats(5.0, 80.0), st.tuples(*[st.floats(0.2, 0.8) for _ in range(3)]))
def test_force_chain_agrees_with_virtual_work(q, push, where):
    pose = finger_pose(DESIGN, np.array(q))
    if pose is None:
        return
    pts = np.array([pose.G[i] + where[i] * (pose.G[i + 1] - pose.G[i])
                    + 0.5 * DESIGN.thickness * palmar_normal(pose.theta[i]) for i in range(3)])
    tau = SPEC.spring_rates * (pose.q + SPEC.spring_preloads)
    chain, _ = contact_forces(DESIGN, pose, push, tau, pts)
    work = virtual_work_forces(DESIGN, pose, push, tau, pts)
    assert np.allclose(chain, work, rtol=1e-5, atol=1e-5)


def test_stroke_grows_with_every_joint_at_the_open_pose():
    assert np.all(stroke_gradient(DESIGN, np.zeros(3)) > 0)
    assert abs(finger_pose(DESIGN, np.zeros(3)).stroke) < 1e-12


def test_closing_on_cylinder_sequence_and_forces():
    res = ua.synthesise(types.SimpleNamespace(method=SPEC, name="finger", actuator=None))
    rep = res.report
    assert rep["contact_sequence"] == DATA["contact_sequence"]
    assert np.allclose(rep["contact_strokes_mm"], DATA["contact_strokes_mm"], atol=DATA["stroke_tolerance_mm"])
    forces = np.array(list(rep["contact_forces_N"].values()))
    assert np.all(forces > 0)
    assert np.allclose(forces, DATA["contact_forces_N"], atol=DATA["force_tolerance_N"])
    motion = res.data["motion"]
    assert motion.fallbacks == 0 and res.data["free"].fallbacks == 0     # every equilibrium by Newton
    assert np.allclose(rep["final_joint_angles_deg"], DATA["final_joint_angles_deg"],
                       atol=DATA["angle_tolerance_deg"])
    # stroke and sticking: each phalanx keeps its angle once it touched
    for i, s in zip(motion.contact_order, motion.contact_strokes, strict=True):
        after = motion.strokes >= s
        assert np.ptp(motion.q[after, i]) < 1e-9
    # the generic solver reproduces the closing motion from the drivers
    sweep = res.mechanism.sweep(motion.strokes)
    q_mech = np.stack([sweep.relative_angle("phalanx1", "palm"), sweep.relative_angle("phalanx2", "phalanx1"),
                       sweep.relative_angle("phalanx3", "phalanx2")], -1)
    assert np.allclose(q_mech, motion.q, atol=1e-6)
    final = finger_pose(DESIGN, motion.q[-1])
    gaps, _ = face_clearance(DESIGN, final, SPEC.cylinder_centre, SPEC.cylinder_radius)
    assert np.all(np.abs(gaps) < 1e-3)
    pngs = res.figures()
    assert set(pngs) == {"closing.png", "joint_angles.png"}


def test_spec_errors_name_the_field():
    raw = _raw()
    raw["transmission"]["output_arm_mm"] = [10.0]
    with pytest.raises(SpecError, match="transmission.output_arm_mm"):
        ua.parse_spec(Table(raw))
    raw = _raw()
    raw["push_rod"]["link_mm"] = 2.0
    with pytest.raises(SpecError, match="push_rod.link_mm"):
        ua.parse_spec(Table(raw))
    raw = _raw()
    raw["object"]["cylinder_centre_mm"] = [20.0, 10.0]
    with pytest.raises(SpecError, match="object.cylinder_centre_mm"):
        ua.parse_spec(Table(raw))


def test_unit_helper_consistency():
    assert np.allclose(palmar_normal(0.3), unit(0.3 + np.pi / 2))


@settings(max_examples=25, deadline=None)
@given(st.lists(angles, min_size=1, max_size=6))
def test_batched_poses_equal_single_poses(qs):
    batch = finger_poses(DESIGN, np.array(qs))
    for k, q in enumerate(qs):
        single = finger_pose(DESIGN, np.array(q))
        assert (single is None) == (not batch.valid[k])
        if single is not None:
            for field in ("G", "Q", "P", "psi", "K", "S"):
                assert np.allclose(getattr(batch, field)[k], getattr(single, field), rtol=0, atol=1e-12)
            assert abs(batch.stroke[k] - single.stroke) < 1e-12


def test_closed_form_stroke_gradient_matches_differences():
    qs = np.random.default_rng(7).uniform(0.0, 0.9, (40, 3))
    poses = finger_poses(DESIGN, qs)
    closed = stroke_gradients(DESIGN, poses)
    for k in range(len(qs)):
        fd = stroke_gradient(DESIGN, qs[k])
        # central differences with h = 1e-6 carry ~1e-10 mm/rad of rounding
        assert np.allclose(closed[k], fd, rtol=1e-7, atol=1e-8)
    # a wrong sign or a missing link in the chain would break this at the open pose
    assert np.all(closed[0] != 0)


def test_face_clearance_gradient_matches_differences():
    qs = np.random.default_rng(11).uniform(0.0, 0.9, (20, 3))
    centre, radius = SPEC.cylinder_centre, SPEC.cylinder_radius
    gaps, points, grads = face_geometry(DESIGN, finger_poses(DESIGN, qs), centre, radius)
    h = 1e-6
    for i in range(3):
        dq = np.zeros(3)
        dq[i] = h
        hi = face_geometry(DESIGN, finger_poses(DESIGN, qs + dq), centre, radius)[0]
        lo = face_geometry(DESIGN, finger_poses(DESIGN, qs - dq), centre, radius)[0]
        assert np.allclose(grads[:, :, i], (hi - lo) / (2 * h), atol=1e-6)
    single = face_clearance(DESIGN, finger_pose(DESIGN, qs[3]), centre, radius)
    assert np.allclose(single[0], gaps[3], atol=1e-12) and np.allclose(single[1], points[3], atol=1e-12)


def _frozen_before(touching, idx):
    hits = np.nonzero(touching[:idx].any(axis=0))[0]
    return int(hits.max()) + 1 if hits.size else 0


@pytest.mark.parametrize("with_object", [True, False])
def test_newton_equilibria_match_slsqp(with_object):
    """Every stroke sample of the closing (stops, contacts and frozen joints included) is the one SLSQP
    finds on the same problem from the same start. At 21 samples the stroke after the lock lies beyond
    the push link's reach, where Newton gives up and SLSQP (once) confirms the lock."""
    motion = closing_motion(SPEC, with_object=with_object, samples=21)
    assert motion.fallbacks == (1 if with_object else 0)
    settler = Settler(SPEC, with_object)
    last = len(motion.strokes) - (2 if with_object else 1)        # the lock sample comes from bisection
    for idx in range(1, last + 1):
        frozen = _frozen_before(motion.touching, idx) if with_object else 0
        ref, ok = settler._slsqp(motion.strokes[idx], motion.q[idx - 1], frozen)
        assert ok
        assert np.allclose(motion.q[idx], ref, atol=1e-7), idx
    if with_object:
        # the same lock as at the template's 41 samples (both located to 1e-6 mm)
        assert motion.touching[-1].all() and motion.contact_order == [0, 1, 2]
        assert abs(motion.strokes[-1] - DATA["contact_strokes_mm"][2]) < 1e-5
    else:
        assert np.all(motion.q[:, 2] == 0.0)      # the distal preload keeps joint 3 on its stop


def test_events_located_and_driver_laws_match_a_dense_solve():
    """Contacts and stop releases between stroke samples are located (not snapped to the 0.375 mm grid)
    and the drivers, split at them, follow a 601-sample solve (0.025 mm grid, events not located: an
    independent reference whose contact strokes are late by at most one step)."""
    res = ua.synthesise(types.SimpleNamespace(method=SPEC, name="finger", actuator=None))
    motion = res.data["motion"]
    dense = closing_motion(SPEC, samples=601, locate_events=False)
    step = SPEC.stroke / 600
    assert dense.contact_order == motion.contact_order
    for coarse, fine in zip(motion.contact_strokes, dense.contact_strokes, strict=True):
        assert -step - 1e-9 <= coarse - fine <= 1e-6          # located at or before the dense sample
        assert abs(coarse - fine) < 0.05
    # both contacts before the lock are events (with the stop releases they cause)
    assert all(np.min(np.abs(np.array(motion.events) - s)) < 1e-9 for s in motion.contact_strokes[:2])
    inside = dense.strokes <= motion.strokes[-1]
    for i, driver in enumerate(res.mechanism.drivers[1:]):
        law = driver.law
        assert np.max(np.abs(law(dense.strokes[inside]) - dense.q[inside, i])) < 1e-3   # rad
        # the derivative the mechanism's velocity solve uses, against differences of the law itself
        x = np.linspace(0.1, motion.strokes[-1] - 0.1, 97)
        x = x[np.min(np.abs(x[:, None] - np.array(motion.events)[None]), axis=1) > 2e-4]
        fd = (law(x + 1e-5) - law(x - 1e-5)) / 2e-5
        assert np.allclose(law(x, 1), fd, atol=1e-5)
        assert isinstance(law(1.0), float)
    # without locating, the coarse grid snaps the first contact to a sample 0.3 mm late
    snapped = closing_motion(SPEC, locate_events=False)
    assert snapped.contact_strokes[0] - dense.contact_strokes[0] > 0.3
