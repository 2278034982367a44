"""Statics over the motion and the strength check (issue 12).

Expected values come from closed forms written out here (two-force members, moment balances, virtual
power through the mechanism's own velocities), never from the code under test.
"""

from __future__ import annotations

import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest

from fabricate.cli import main
from fabricate.hints import PadHint, PartHints, SpringHint
from fabricate.strength.check import body_loads, design_loads, solved_loads
from fabricate.strength.spec import LoadSpec
from fabricate.strength.statics import BodyTorque, PointForce, solve_statics
from fabricate.templates import TEMPLATE_DIR
from tests.conftest import make_four_bar
from tests.parts.test_build import slider_crank


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def test_four_bar_statics_match_the_two_force_member_closed_form():
    """A torque on the rocker: the coupler is a two-force member along A-B, so its force follows from
    the rocker's moment balance about D and the crank torque from the crank's about O."""
    mech = make_four_bar()
    motion = mech.sweep(73)
    t_out = 250.0  # N·mm on the rocker (against the ground)
    st = solve_statics(mech, motion, torques=[BodyTorque("rocker", "ground", np.full(73, t_out))])
    a, b = motion.point("A", "crank"), motion.point("B", "rocker")
    o, d = np.zeros(2), np.array([40.0, 0.0])
    e = (b - a) / np.hypot(*(b - a).T)[:, None]
    c = -t_out / _cross(b - d, e)  # coupler force on the rocker is c e
    t_in = _cross(a - o, c[:, None] * e)  # the crank's driver balances the coupler's pull at A
    for joint in ("O", "A", "B", "D"):
        got = np.hypot(*st.joint_forces[joint].T)
        np.testing.assert_allclose(got, np.abs(c), rtol=1e-9, err_msg=joint)
    # joint B's pair is the force on its body_a (the coupler) from the rocker: -c e
    np.testing.assert_allclose(st.joint_forces["B"], -c[:, None] * e, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(st.driver_efforts[:, 0], t_in, rtol=1e-9, atol=1e-9)
    assert st.residual < 1e-9


def test_slider_crank_input_force_by_virtual_power():
    """A torque on the crank held by the slide driver: by virtual power F v_rod + T w_crank = 0, with the
    velocities from a finite difference of the solved motion (not the statics' Jacobian)."""
    mech = slider_crank()
    s = np.linspace(0.0, 8.0, 41)
    motion = mech.sweep(s)
    torque = 120.0
    st = solve_statics(mech, motion, torques=[BodyTorque("crank", "ground", np.full(len(s), torque))])
    crank_angle = np.unwrap(motion.pose("crank")[:, 2])
    w = np.gradient(crank_angle, s, edge_order=2)  # rad per mm of slide
    expected = -torque * w  # the driver's force along the slide (v_rod = 1 mm per mm)
    np.testing.assert_allclose(st.driver_efforts[1:-1, 0], expected[1:-1], rtol=2e-3)
    # the rod's guide holds the coupler's sideways push: the slider's normal force is not zero
    assert np.max(np.abs(st.slider_forces["G"])) > 1.0


def test_actuator_effort_is_held_by_the_object_at_the_tip():
    """A known crank torque with the object at the rocker's tip: the solved tip force does the same work
    (virtual power T w_crank + F (u . v_tip) = 0, velocities by finite differences of the motion)."""
    mech = make_four_bar()
    s = np.linspace(60.0, 160.0, 51)
    motion = mech.sweep(s)
    hints = PartHints(tip_point="B", pads={"rocker": PadHint("B")})
    loads = design_loads(_design(input_torque_Nmm=80.0), mech, motion, hints)
    assert loads.reaction is not None and not loads.forces
    st = solve_statics(mech, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    np.testing.assert_allclose(st.driver_efforts[:, 0], 80.0)
    w = np.radians(1.0)  # the crank turns 1 deg per unit input
    v_tip = np.gradient(motion.point("B", "rocker"), s, axis=0, edge_order=2)
    u = loads.reaction.force
    expected = -80.0 * w / np.sum(u * v_tip, axis=1)
    np.testing.assert_allclose(st.reaction_N[2:-2], expected[2:-2], rtol=2e-3)
    # with the actuator alone (no object), nothing holds the one-driver four-bar: a clear error
    from fabricate.errors import GeometryError

    with pytest.raises(GeometryError, match="nothing but the actuator"):
        solve_statics(mech, motion, efforts=loads.efforts)


def _design(**load) -> SimpleNamespace:
    return SimpleNamespace(load=LoadSpec(**load))


def test_tip_force_opposes_the_tip_motion_and_springs_follow_their_rate():
    mech = make_four_bar()
    motion = mech.sweep(np.linspace(60.0, 200.0, 61))
    hints = PartHints(tip_point="B", pads={"rocker": PadHint("B")}, springs=(SpringHint("D", 2.0, 10.0),))
    loads = design_loads(_design(tip_force_N=7.0), mech, motion, hints)
    (tip,) = loads.forces
    path = motion.point("B", "rocker")
    step = path[2:] - path[:-2]  # central differences, independent of the code's gradient
    moving = np.hypot(*step.T) > 0.2 * np.hypot(*step.T).max()  # away from the rocker's turning points
    np.testing.assert_allclose(np.hypot(*tip.force.T), 7.0, rtol=1e-12)
    cosine = np.sum(tip.force[1:-1] * step, axis=1) / (7.0 * np.hypot(*step.T))
    assert np.all(cosine[moving] < -0.99)
    (spring,) = loads.torques
    # rocker angle from its two points, independently of the motion's stored angle
    d_to_b = path - np.array([40.0, 0.0])
    rocker = np.degrees(np.unwrap(np.arctan2(d_to_b[:, 1], d_to_b[:, 0])))
    turned = np.abs(rocker - rocker[0])
    assert np.all(np.diff(turned) > 0.0)  # one way over this range: the deflection only grows
    np.testing.assert_allclose(np.abs(spring.torque), 2.0 * (10.0 + turned), rtol=1e-9)


@pytest.mark.parametrize("load", [{"tip_force_N": 5.0}, {"input_torque_Nmm": 40.0}])
def test_every_body_is_in_equilibrium_under_all_its_loads(load):
    """Joint reactions, the tip force (given, or solved against the actuator), springs and the drivers'
    efforts balance on each body (forces and moments), so a section's free body is the same from either
    side."""
    mech = make_four_bar()
    motion = mech.sweep(49)
    hints = PartHints(tip_point="B", pads={"rocker": PadHint("B")}, springs=(SpringHint("A", 3.0, 20.0),))
    loads = design_loads(_design(**load), mech, motion, hints)
    st = solve_statics(mech, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    if loads.reaction is not None:
        loads = solved_loads(loads, st.reaction_N)
    points, couples = body_loads(mech, motion, st, loads)
    for body in ("crank", "coupler", "rocker"):
        pose = motion.pose(body)
        force = np.zeros((49, 2))
        moment = np.zeros(49)
        for local, f, _ in points[body]:
            c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
            arm = np.column_stack([c * local[0] - s * local[1], s * local[0] + c * local[1]])
            force += f
            moment += _cross(arm, f)
        for torque, _ in couples.get(body, []):
            moment += torque
        assert np.max(np.abs(force)) < 1e-9, body
        assert np.max(np.abs(moment)) < 1e-7, body


def test_gripper_statics_reproduce_the_papers_rod_force():
    """Seed 003's grasp: the can's 4.50 N on the pad (horizontal, through the arc centre) and the spring at
    B give the two-force rod the paper's static force (eqs 3-4, the synthesis' own model), and leave the
    free hinge C (k1 = 0) unloaded. Two independent statics of one grasp agree to 1e-6 (measured 5e-10)."""
    from fabricate.design import load_design
    from fabricate.pipeline import synthesise

    design = load_design("gripper_compliant")
    result = synthesise(design)
    grasp = result.report["grasp"]
    # the template states F_n1 rounded to 4.5 N as the paper prints it; eqs 3-4 give it exactly
    exact = result.report["paper_optimum"]["F_n1_N"]
    assert exact == pytest.approx(4.5, abs=0.1)
    design = dataclasses.replace(design, load=dataclasses.replace(design.load, tip_force_N=exact))
    mech = result.mechanism
    s = np.linspace(mech.input_range[0], grasp["stroke_mm"], 60)
    motion = mech.sweep(s)
    loads = design_loads(design, mech, motion, result.parts)
    st = solve_statics(mech, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    rod = float(np.hypot(*st.joint_forces["E"][-1]))
    assert rod == pytest.approx(grasp["rod_force_static_N"], rel=1e-6)
    (spring,) = loads.torques
    assert abs(spring.torque[-1]) == pytest.approx(grasp["spring_torques_Nmm"][1], rel=1e-3)
    hinge_c = next(k for k, d in enumerate(mech.drivers) if d.kind == "angle" and d.body == "tip")
    assert abs(st.driver_efforts[-1, hinge_c]) < 1e-6 * abs(spring.torque[-1])


def test_point_force_on_the_ground_is_carried_by_the_ground():
    mech = make_four_bar()
    motion = mech.sweep(5)
    st = solve_statics(mech, motion, forces=[PointForce("ground", np.zeros(2), np.ones((5, 2)))])
    assert all(np.max(np.abs(f)) == 0.0 for f in st.joint_forces.values())


# -- the check through the pipeline ----------------------------------------------------------------

def _template(name: str, **replace: str) -> str:
    text = (TEMPLATE_DIR / f"{name}.toml").read_text(encoding="utf-8")
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    return text


@pytest.mark.slow
def test_weakened_finger_fails_naming_part_feature_and_load(tmp_path, capsys):
    """The underactuated finger pushed with 2000 N instead of its rated 20 N: exit 1, the files and a report that
    names the part, the feature, the load and the fix."""
    path = tmp_path / "weak.toml"
    path.write_text(_template("finger_underactuated", **{"input_force_N = 20.0": "input_force_N = 2000.0"}),
                    encoding="utf-8")
    code = main(["build", str(path), "-o", str(tmp_path / "out")])
    captured = capsys.readouterr()
    out = captured.out + captured.err
    assert code == 1
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    strength = report["strength"]
    assert strength["passed"] is False
    weak = [p for p in strength["parts"] if p["min_safety_factor"] < 2.0]
    assert weak
    worst = min(weak, key=lambda p: p["min_safety_factor"])
    # the worst part is named in the failure with its feature and the load that governs
    failure = next(f for f in report["checks"]["failures"] if f.startswith(f"strength: part {worst['name']},"))
    assert worst["feature"] in failure and worst["input"] in failure
    assert any("2000 N on the input" in load for load in strength["loads"])
    assert "safety factor" in failure and ("wider" in failure or "thicker" in failure or "larger" in failure)
    assert f"part {worst['name']}" in out
    # the stresses scale with the load: 2000 / 60 times the shipped design's (linear statics)
    assert worst["stress_MPa"] == pytest.approx(worst["allowable_MPa"] / worst["min_safety_factor"], rel=1e-4)
    assert (tmp_path / "out" / "plots" / "strength.png").is_file()


@pytest.mark.parametrize("field, value, message", [
    ("tip_force_N", "-1.0", "load.tip_force_N"),
    ("input_force_N", '"a lot"', "load.input_force_N"),
    ("tip_forse_N", "1.0", "load.tip_forse_N"),
])
def test_bad_load_field_exits_2_naming_it(tmp_path, capsys, field, value, message):
    path = tmp_path / "bad.toml"
    path.write_text(_template("finger_underactuated", **{"input_force_N = 20.0": f"{field} = {value}"}),
                    encoding="utf-8")
    code = main(["build", str(path), "-o", str(tmp_path / "out"), "-q"])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_unknown_material_exits_2_naming_the_field(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    text = _template("finger_underactuated", **{'profile = "sla"': 'profile = "sla"\nmaterial = "unobtainium"'})
    path.write_text(text, encoding="utf-8")
    assert main(["build", str(path), "-o", str(tmp_path / "out"), "-q"]) == 2
    err = capsys.readouterr().err
    assert "material" in err and "unobtainium" in err and "standard_resin" in err



def _four_bar_design(link_width, tip_force_N: float):
    from fabricate.design import load_design
    from fabricate.gears.spec import GearSpec
    from fabricate.parts.spec import PartsSpec

    # a real DesignSpec: the SLA profile of a shipped template (its materials, 3 mm pins), default gears and
    from fabricate.spec import ChecksSpec
    # checks, the parts and load under test (the kind's own spec is not read by the parts or the check)
    return dataclasses.replace(load_design("finger_watt_six_bar"), name="four_bar", gears=GearSpec(),
                               parts=PartsSpec(link_width_mm=link_width), checks=ChecksSpec(),
                               load=LoadSpec(tip_force_N=tip_force_N))


def test_auto_link_width_is_the_smallest_width_that_passes():
    """``link_width_mm = "auto"`` on a four-bar loaded at the rocker: the chosen width keeps every link and
    hole at the safety factor, 0.1 mm less does not (both checked over the whole motion)."""
    from fabricate.parts.build import build_parts
    from fabricate.strength.check import run_strength
    from fabricate.strength.sizing import RESOLUTION_MM, size_link_width

    mech = make_four_bar()
    motion = mech.sweep(121)
    hints = PartHints(tip_point="B", pads={"rocker": PadHint("B")})
    design = _four_bar_design("auto", 45.0)

    def build(d):
        return build_parts(d, mech, motion, [], hints)

    width, tried = size_link_width(design, mech, motion, [], hints, build)
    assert len(tried) <= 12 and width == pytest.approx(round(width / RESOLUTION_MM) * RESOLUTION_MM, abs=1e-9)

    def least(w: float) -> float:
        d = _four_bar_design(w, 45.0)
        result = run_strength(d, build(d), mech, motion, [], hints)
        return min(f.safety_factor for f in result.findings if f.kind in ("link", "hole"))

    default = least(None)
    # the plain bosses are too narrow at 45 N (25 N: no longer, with the holders' smaller press-fit holes)
    assert default < 2.0  # the sizing had work to do
    assert least(width) >= 2.0
    assert least(width - RESOLUTION_MM) < 2.0


def test_link_width_auto_is_read_and_other_words_are_refused():
    from fabricate.errors import SpecError
    from fabricate.parts.spec import parse_parts_spec
    from fabricate.table import Table

    assert parse_parts_spec(Table({"link_width_mm": "auto"}, "parts")).link_width_mm == "auto"
    with pytest.raises(SpecError, match="parts.link_width_mm"):
        parse_parts_spec(Table({"link_width_mm": "wide"}, "parts"))


def test_local_pitch_radius_is_the_curvature_radius_of_an_ellipse():
    """The Lewis/Hertz radius at a contact point against an ellipse's closed form
    rho = (a^2 sin^2 t + b^2 cos^2 t)^(3/2) / (a b), either way round the curve."""
    from fabricate.strength.features import local_radius

    a, b = 20.0, 12.0
    t = np.linspace(0.0, 2.0 * np.pi, 4001)[:-1]
    curve = np.column_stack([a * np.cos(t), b * np.sin(t)])
    probe_t = np.linspace(0.1, 6.0, 25)
    probe = np.column_stack([a * np.cos(probe_t), b * np.sin(probe_t)])
    expected = (a ** 2 * np.sin(probe_t) ** 2 + b ** 2 * np.cos(probe_t) ** 2) ** 1.5 / (a * b)
    np.testing.assert_allclose(local_radius(curve, probe), expected, rtol=2e-3)  # nearest of 4000 vertices
    np.testing.assert_allclose(local_radius(curve[::-1], probe), expected, rtol=2e-3)


def test_gear_contact_point_lies_on_both_pitch_curves_over_the_motion():
    """The pitch point the gear check reads (on the line of centres, r_a = a i / (1 + i) from axis a) is on
    gear a's and gear b's pitch curves at every pose of the elliptic pair."""
    from fabricate.design import load_design
    from fabricate.gears import build_gear_pairs
    from fabricate.pipeline import synthesise

    design = load_design("gear_pair_elliptic")
    mech = synthesise(design).mechanism
    (pair,) = build_gear_pairs(mech, design.gears, design.process.chord_tolerance_mm)
    motion = mech.sweep(73)
    xa = motion.relative_angle(pair.body_a, pair.carrier)
    xb = motion.relative_angle(pair.body_b, pair.carrier)
    i = np.abs(pair.law(xa, 1))
    r_a, r_b = pair.center_distance_mm * i / (1 + i), pair.center_distance_mm / (1 + i)
    on_a = r_a[:, None] * np.column_stack([np.cos(-xa), np.sin(-xa)])
    on_b = r_b[:, None] * np.column_stack([np.cos(np.pi - xb), np.sin(np.pi - xb)])
    spacing = max(np.hypot(*np.diff(pair.pitch_a, axis=0).T).max(), np.hypot(*np.diff(pair.pitch_b, axis=0).T).max())
    for curve, points in ((pair.pitch_a, on_a), (pair.pitch_b, on_b)):
        gap = np.min(np.hypot(*(curve[None, :, :] - points[:, None, :]).transpose(2, 0, 1)), axis=1)
        assert gap.max() < spacing


# -- a check that cannot run is "not checked" (issue 23) ---------------------------------------------

def test_zero_load_and_no_materials_are_not_checked_never_passed():
    """The four-bar with no load at all (no [load], no springs): every stress would be 0 and every safety
    factor infinite, so the check does not run: passed None, the reason, no finding, no failure, no part
    rated. The same with the profile's materials removed. The loaded control is checked (True or False)."""
    from fabricate.parts.build import build_parts
    from fabricate.strength.check import NO_LOAD, NO_MATERIALS, run_strength

    mech = make_four_bar()
    motion = mech.sweep(25)
    hints = PartHints(tip_point="B", pads={"rocker": PadHint("B")})
    loaded = _four_bar_design(None, 25.0)
    partset = build_parts(loaded, mech, motion, [], hints)
    control = run_strength(loaded, partset, mech, motion, [], hints)
    assert control.reason is None and isinstance(control.passed, bool) and control.findings
    assert "reason" not in control.report()

    assert _four_bar_design(None, 0.0).load == LoadSpec()  # what a template without [load] gets
    result = run_strength(_four_bar_design(None, 0.0), partset, mech, motion, [], hints)
    assert result.passed is None and result.reason == NO_LOAD
    assert result.findings == [] and result.failures() == [] and result.statics is None
    section = result.report()
    assert section["passed"] is None and section["reason"] == NO_LOAD and section["parts"] == []

    bare = SimpleNamespace(**vars(loaded))
    bare.process = dataclasses.replace(loaded.process, materials={})
    result = run_strength(bare, partset, mech, motion, [], hints)
    assert result.passed is None and result.reason == NO_MATERIALS and result.report()["parts"] == []


def test_an_unloaded_part_has_a_null_safety_factor_not_inf():
    """Within a checked run a part the load does not reach (zero stress) is written as null, never inf."""
    from fabricate.strength.check import StrengthResult
    from fabricate.strength.features import Finding

    result = StrengthResult([Finding("idle", "pin shear", "pin", 0.0, 50.0, 0, "no load", "none"),
                             Finding("busy", "pin shear", "pin", 10.0, 50.0, 1, "5 N", "thicker")],
                            None, 2.0, np.array([0.0, 1.0]))
    rows = {p["name"]: p for p in result.report()["parts"]}
    assert rows["idle"]["min_safety_factor"] is None and rows["busy"]["min_safety_factor"] == 5.0
    assert result.passed is True and result.report()["passed"] is True


# -- the poses streamed in chunks (issue 27, item 5) -----------------------------------------------------

def test_local_radius_a_point_at_a_time_equals_all_at_once(monkeypatch):
    """The nearest pitch vertex is found for a few contact points at a time (memory flat in the poses): one
    point a chunk gives exactly the radii of all at once, each row its own nearest vertex."""
    import fabricate.strength.features as features

    t = np.linspace(0.0, 2.0 * np.pi, 801)[:-1]
    curve = np.column_stack([20.0 * np.cos(t), 12.0 * np.sin(t)])
    probe = np.random.default_rng(7).uniform(-25.0, 25.0, (301, 2))
    whole = features.local_radius(curve, probe)
    monkeypatch.setattr(features, "NEAREST_VALUES_PER_CHUNK", 1)
    one = features.local_radius(curve, probe)
    np.testing.assert_array_equal(one, whole)
    assert len(np.unique(whole)) > 50  # the probes land on many different vertices
    assert features.local_radius(curve, np.zeros((0, 2))).shape == (0,)


def test_strength_streamed_seven_poses_at_a_time_equals_all_at_once(monkeypatch):
    """The elliptic gear pair's strength check (statics, pins, holes, links, gear teeth) over 120 poses with the
    gear contact's nearest pitch vertices found seven poses at a time: every finding (stress, pose, curve) and
    the joint force curves exactly as all poses at once."""
    import fabricate.strength.features as features
    from fabricate.design import load_design
    from fabricate.gears import build_gear_pairs
    from fabricate.parts.build import build_parts
    from fabricate.pipeline import synthesise
    from fabricate.strength.check import run_strength

    design = load_design("gear_pair_elliptic")
    synthesis = synthesise(design)
    mech = synthesis.mechanism
    motion = mech.sweep(120)
    gear_pairs = build_gear_pairs(mech, design.gears, design.process.chord_tolerance_mm)
    partset = build_parts(design, mech, motion, gear_pairs, synthesis.parts)

    def strength():
        return run_strength(design, partset, mech, motion, gear_pairs, synthesis.parts)

    whole = strength()
    vertices = max(len(p) for pair in gear_pairs for p in (pair.pitch_a, pair.pitch_b))
    monkeypatch.setattr(features, "NEAREST_VALUES_PER_CHUNK", 7 * vertices)
    chunked = strength()
    assert [f.kind for f in whole.findings].count("gear") > 0
    assert len(chunked.findings) == len(whole.findings)
    for a, b in zip(whole.findings, chunked.findings, strict=True):
        assert (a.part, a.feature, a.stress_MPa, a.pose) == (b.part, b.feature, b.stress_MPa, b.pose)
        np.testing.assert_array_equal(a.curve, b.curve)
    assert whole.curves.keys() == chunked.curves.keys()
    for key in whole.curves:
        np.testing.assert_array_equal(whole.curves[key], chunked.curves[key])
    assert json.dumps(whole.report()) == json.dumps(chunked.report())
