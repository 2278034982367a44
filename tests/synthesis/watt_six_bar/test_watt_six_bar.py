"""Watt-I six-bar finger: curves, region, K, selection, mechanism.

Expected numbers are in tests/data/watt_six_bar_paper.json (paper tables plus values measured with the
printed Table 2, each with the tolerance stated where it is asserted).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.design import GENERIC_SECTIONS
from fabricate.errors import SpecError
from fabricate.synthesis import watt_six_bar as wsb
from fabricate.synthesis.watt_six_bar.burmester import (
    cubic_real_roots,
    distance_to_curve,
    dyad_curve,
    grid_in_range,
    sample_curve,
)
from fabricate.synthesis.watt_six_bar.mechanism import _load_on_distal, build_mechanism, virtual_work_check
from fabricate.synthesis.watt_six_bar.method import synthesise_spec
from fabricate.synthesis.watt_six_bar.region import (
    RegionInputs,
    finger_positions,
    solution_region,
    stage_two_curves,
)
from fabricate.synthesis.watt_six_bar.spec import WattSixBarSpec
from fabricate.synthesis.watt_six_bar.statics import (
    JOINTS,
    SixBarBatch,
    assemble,
    fingertip_errors,
    force_index,
    joint_loads,
    lagrange_joint_forces,
)
from fabricate.table import Table
from fabricate.templates import TEMPLATE_DIR, read_toml

DATA = json.loads((Path(__file__).resolve().parents[2] / "data" / "watt_six_bar_paper.json").read_text())
TEMPLATE = TEMPLATE_DIR / "finger_watt_six_bar.toml"



def assert_grid_count(actual: int, expected: int) -> None:
    """A count of 0.2 mm grid points inside a region agrees with the recorded one within 0.2 % (at least 3).

    Whether a grid point on the region's boundary is in or out turns on the last digits of a root, which
    move with numpy/scipy patch releases (18521 against 18522 was seen); the region itself does not move.
    A zero stays exactly zero: "no point passes" is the finding, not a boundary effect.
    """
    if expected == 0:
        assert actual == 0
    else:
        assert abs(actual - expected) <= max(3, 2e-3 * expected), (actual, expected)

def _template_root(path: Path = TEMPLATE, edit=None) -> Table:
    data = read_toml(path)
    if edit is not None:
        edit(data)
    root = Table(data)
    for generic in GENERIC_SECTIONS:
        if root.has(generic):
            root.table(generic)
    return root


def _paper_spec() -> WattSixBarSpec:
    root = _template_root()
    spec = wsb.parse_spec(root)
    root.finish()
    return spec


def _inputs(case: dict) -> RegionInputs:
    boxes = {k: np.asarray(v, float) for k, v in case["boxes"].items()}
    return RegionInputs(lengths=np.asarray(case["phalanx_lengths_mm"], float),
                        angles=np.radians(np.asarray(case["theta_deg"], float)), box_d=boxes["d"],
                        box_e=boxes["e"], box_f=boxes["f"], box_d0=boxes["d0"], step=0.2)


@pytest.fixture(scope="module")
def paper_result():
    return synthesise_spec(_paper_spec())


@pytest.fixture(scope="module")
def paper_region():
    return solution_region(_inputs(DATA), DATA["k_max"])


# -- curves ------------------------------------------------------------------------------------------

def test_curve_is_circular_cubic_and_every_point_keeps_its_dyad_length():
    finger = finger_positions(np.asarray(DATA["phalanx_lengths_mm"]), np.radians(DATA["theta_deg"]))
    curve = dyad_curve(finger.proximal, finger.distal)
    s = curve.tensor
    # eq 6: cubic part H1 (x^3 + x y^2) + H2 (y^3 + x^2 y)
    assert s[0, 0, 0] == pytest.approx(3 * s[0, 1, 1], rel=1e-9)
    assert s[1, 1, 1] == pytest.approx(3 * s[0, 0, 1], rel=1e-9)
    sample = sample_curve(curve, grid_in_range(-50.0, 150.0, 0.5))
    pts, partner = sample.points(), sample.partner
    ok = np.isfinite(pts[..., 1]) & np.all(np.isfinite(partner), axis=-1)
    assert ok.sum() > 400
    d = finger.proximal.apply(pts[ok])
    e = finger.distal.apply(partner[ok])
    length = np.hypot(*(d - e).transpose(2, 0, 1))
    assert np.max(np.abs(length - length[:, :1])) < 1e-7  # mm


@settings(max_examples=25, deadline=None)
@given(lengths=st.tuples(*[st.floats(15.0, 60.0)] * 3),
       steps=st.lists(st.floats(-40.0, -3.0), min_size=9, max_size=9))
def test_the_middle_link_is_always_a_solution(lengths, steps):
    # a (proximal) and b (distal) are always a dyad: the middle phalanx itself. Any finger whose
    # joints flex (each phalanx turns by 3..40 degrees relative to the previous one per position)
    rel = np.zeros((3, 4))
    rel[:, 1:] = np.cumsum(np.reshape(steps, (3, 3)), axis=1)
    angles = np.cumsum(rel, axis=0)
    finger = finger_positions(np.asarray(lengths), np.radians(angles))
    curve_d = dyad_curve(finger.proximal, finger.distal)
    curve_e = dyad_curve(finger.distal, finger.proximal)
    # tensors are scaled to a unit largest entry, so |P(v)| is measured against |v|^3
    assert abs(curve_d.evaluate(finger.a[:1])[0]) <= 1e-11 * (1.0 + np.hypot(*finger.a[0])) ** 3
    assert abs(curve_e.evaluate(finger.b[:1])[0]) <= 1e-11 * (1.0 + np.hypot(*finger.b[0])) ** 3


@settings(max_examples=50, deadline=None)
@given(roots=st.lists(st.floats(-50.0, 50.0), min_size=3, max_size=3, unique=True),
       lead=st.floats(0.1, 10.0))
def test_cubic_real_roots_are_sorted_into_branches(roots, lead):
    r = np.sort(roots)
    if np.min(np.diff(r)) < 1e-2:
        return
    c = lead * np.poly(r)[::-1]  # c0 + c1 y + c2 y^2 + c3 y^3
    got = cubic_real_roots(c)
    assert np.allclose(got, r, atol=1e-6 * (1 + np.abs(r)))
    one = cubic_real_roots(np.array([1.0, 0.0, 0.0, 1.0]))  # y^3 = -1: one real root in branch 1
    assert one[0] == pytest.approx(-1.0) and np.all(np.isnan(one[1:]))


# -- the paper's mechanism 1 against the printed tables ------------------------------------------------

def test_paper_mechanism_1_fits_the_printed_positions():
    m1 = {k: np.asarray(v, float) for k, v in DATA["mechanism_1"].items()}
    measured = DATA["measured"]
    finger = finger_positions(np.asarray(DATA["phalanx_lengths_mm"]), np.radians(DATA["theta_deg"]))
    assert np.allclose(finger.c[0], m1["c"]) and np.allclose(finger.b[0], m1["b"])
    # dyad lengths over the four positions: the curve equations hold to 0.33 mm of length
    dd, ee = finger.proximal.apply(m1["d"]), finger.distal.apply(m1["e"])
    from fabricate.synthesis.watt_six_bar.region import coupler_motion

    ff = coupler_motion(finger, m1["d"], m1["e"]).apply(m1["f"])
    spread_de = np.ptp(np.hypot(*(dd - ee).T))
    spread_d0f = np.ptp(np.hypot(*(ff - m1["d0"]).T))
    assert spread_de == pytest.approx(measured["mechanism_1_dyad_length_spread_mm"]["de"], abs=2e-3)
    assert spread_d0f == pytest.approx(measured["mechanism_1_dyad_length_spread_mm"]["d0f"], abs=2e-3)
    assert spread_de < 0.33 and spread_d0f < 0.15
    batch = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], m1["d"][None], m1["e"][None], m1["f"][None],
                        m1["d0"][None], 0.0)
    tip = fingertip_errors(batch, np.radians(DATA["theta_deg"][0]), finger.c)[0]
    assert tip.max() == pytest.approx(measured["mechanism_1_tip_error_max_mm"], abs=2e-3)
    assert tip.max() < 0.5  # it passes the positions within 0.5 mm at the fingertip
    k = force_index(batch, np.radians(np.linspace(0.0, -40.0, 41)))[0]
    assert k == pytest.approx(measured["mechanism_1_K"], abs=2e-3)
    assert k <= DATA["k_max"]
    # ...but not within 0.3 mm of the exact curves: the problem is ill-conditioned there (see module notes)
    curve_d = dyad_curve(finger.proximal, finger.distal)
    curve_e = dyad_curve(finger.distal, finger.proximal)
    assert distance_to_curve(curve_d, m1["d"])[0] == pytest.approx(
        measured["mechanism_1_distance_to_curve_mm"]["d"], abs=0.01)
    assert distance_to_curve(curve_e, m1["e"])[0] == pytest.approx(
        measured["mechanism_1_distance_to_curve_mm"]["e"], abs=0.01)


def test_distance_to_curve_finds_a_known_offset():
    finger = finger_positions(np.asarray(DATA["phalanx_lengths_mm"]), np.radians(DATA["theta_deg"]))
    curve = dyad_curve(finger.proximal, finger.distal)
    sample = sample_curve(curve, np.array([45.0]))
    p = sample.points()[0, 0]
    normal = curve.gradient(p[None])[0]
    normal /= np.hypot(*normal)
    dist, foot = distance_to_curve(curve, p + 0.25 * normal)
    assert dist == pytest.approx(0.25, abs=1e-3)
    assert np.hypot(*(foot - p)) < 5e-3


# -- region ----------------------------------------------------------------------------------------------

def test_region_of_the_printed_tables(paper_region):
    measured = DATA["measured"]
    region = paper_region
    assert_grid_count(len(region), measured["region_points"])
    assert_grid_count(int(np.sum(region.K <= DATA["k_max"])), measured["region_points_K_ok"])
    assert_grid_count(int(region.passes.sum()), measured["region_points_without_circuit_defect"])
    ranges = region.stage_one.feasible_ranges()
    for key, (lo, hi) in measured["curve_d_feasible_x_mm"].items():
        assert ranges[int(key)] == pytest.approx((lo, hi), abs=1e-9)
    # every point is an exact solution: dyads keep their length at the four positions
    finger = finger_positions(np.asarray(DATA["phalanx_lengths_mm"]), np.radians(DATA["theta_deg"]))
    idx = np.linspace(0, len(region) - 1, 200).astype(int)
    from fabricate.synthesis.watt_six_bar.region import coupler_motion

    ff = coupler_motion(finger, region.d[idx], region.e[idx]).apply(region.f[idx])
    length = np.hypot(*(ff - region.d0[idx, None]).transpose(2, 0, 1))
    assert np.max(np.abs(length - length[:, :1])) < 1e-6
    # x on the 0.2 mm grid, boxes respected
    assert np.allclose(region.d[:, 0] / 0.2, np.round(region.d[:, 0] / 0.2), atol=1e-9)
    assert np.allclose(region.d0[:, 0] / 0.2, np.round(region.d0[:, 0] / 0.2), atol=1e-9)
    assert np.all((region.e[:, 0] >= 50) & (region.e[:, 0] <= 90) & (np.abs(region.f[:, 1]) <= 20))
    assert set(np.unique(region.branch_d)) <= {1, 2, 3} and set(np.unique(region.branch_d0)) <= {1, 2, 3}


def test_circuit_defect_is_seen_by_the_generic_solver(paper_region):
    # a region point flagged as defective really misses the positions when swept continuously
    region = paper_region
    j = int(np.flatnonzero(np.isfinite(region.K) & (region.K < 20))[0])
    finger = finger_positions(np.asarray(DATA["phalanx_lengths_mm"]), np.radians(DATA["theta_deg"]))
    angles = np.radians(np.asarray(DATA["theta_deg"]))
    mech = build_mechanism("defect", finger, angles, region.d[j], region.e[j], region.f[j], region.d0[j])
    motion = mech.sweep(np.linspace(0.0, -40.0, 41))
    tips = motion.point("c")[[0, 10, 25, 40]]
    err = np.hypot(*(tips - finger.c).T)
    assert err[0] < 1e-9
    assert err.max() == pytest.approx(region.tip_error[j], rel=1e-6)
    assert err.max() > 5.0


def test_statics_agrees_with_virtual_work_on_many_mechanisms(paper_region):
    region = paper_region
    finite = np.flatnonzero(np.isfinite(region.K) & (region.K < 200))
    finger = finger_positions(np.asarray(DATA["phalanx_lengths_mm"]), np.radians(DATA["theta_deg"]))
    angles = np.radians(np.asarray(DATA["theta_deg"]))
    for j in finite[np.linspace(0, len(finite) - 1, 4).astype(int)]:
        mech = build_mechanism("check", finger, angles, region.d[j], region.e[j], region.f[j], region.d0[j])
        theta = np.linspace(0.0, -40.0, 41)
        check = virtual_work_check(mech, theta, 1.0)
        assert check["K"] == pytest.approx(region.K[j], rel=1e-8)
        batch = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], region.d[j:j + 1], region.e[j:j + 1],
                            region.f[j:j + 1], region.d0[j:j + 1], 0.0)
        torque = joint_loads(assemble(batch, np.radians(theta))).torque[0]
        assert np.allclose(check["torque_Nmm"], torque, rtol=1e-8, atol=1e-9)
        assert np.allclose(check["torque_virtual_power_Nmm"], torque, rtol=1e-6, atol=1e-6)


def test_lagrange_forces_match_link_by_link_statics_joint_by_joint(paper_result):
    choice = paper_result.data["choice"]
    finger = paper_result.data["finger"]
    mech = paper_result.mechanism
    motion = mech.sweep(np.array([0.0, -17.0]))
    poses = motion.poses_at(1)
    point, load = _load_on_distal(mech, poses, 1.0)
    forces, torque = lagrange_joint_forces(mech, poses, point, load)
    batch = SixBarBatch(finger.a[0], finger.b[0], finger.c[0], choice.d[None], choice.e[None], choice.f[None],
                        choice.d0[None], 0.0)
    loads = joint_loads(assemble(batch, np.radians([-17.0])))
    for j in JOINTS:
        assert forces[j] == pytest.approx(loads.forces[j][0, 0], rel=1e-8)
    assert torque == pytest.approx(loads.torque[0, 0], rel=1e-8)


# -- the template's design ---------------------------------------------------------------------------------

def test_paper_template_builds_a_finger_that_passes_the_positions(paper_result):
    res = paper_result
    rep = res.report
    mech = res.mechanism
    assert mech.degrees_of_freedom() == 1 and rep["degrees_of_freedom"] == 1
    assert {b.name for b in mech.bodies} == {"ground", "proximal", "middle", "distal", "coupler", "rocker"}
    assert set(mech.point_names()) == {"a0", "a", "b", "c", "d", "e", "f", "d0"}
    assert mech.input_range == (0.0, -40.0)
    assert rep["pose_error_mm"]["max"] <= 0.5
    assert rep["K"] <= 20.0
    assert rep["K_relative_difference"] < 1e-9
    assert rep["torque_virtual_power_max_difference_Nmm"] < 1e-6
    sel = rep["selected"]
    assert abs(sel["d"][0] - 51.4) <= 0.5 and abs(sel["d0"][0] + 6.4) <= 0.5  # near mechanism 1
    assert_grid_count(rep["region"]["points"], DATA["measured"]["region_points"])
    assert rep["reference"]["tip_error_mm"]["max"] < 0.5
    # the full motion at the checks' resolution, no lock-up, and the fingertip through the positions
    motion = mech.sweep(361)
    tips = motion.point("c")[[0, 90, 225, 360]]
    assert np.max(np.hypot(*(tips - res.data["finger"].c).T)) <= 0.5
    assert res.parts.tip_point == "c" and res.parts.pads is not None and res.parts.pads["distal"].point == "c"
    json.dumps(rep)  # JSON-ready


def test_figures_are_deterministic_pngs(paper_result):
    first = paper_result.figures()
    assert set(first) == {"curve_d.png", "curve_d0.png", "solution_region.png"}
    for png in first.values():
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10000
    assert paper_result.figures()["solution_region.png"] == first["solution_region.png"]


def test_another_finger_gets_an_exact_defect_free_region_point():
    case = DATA["other_finger"]
    base = _paper_spec()
    spec = replace(base, phalanx_lengths_mm=tuple(case["phalanx_lengths_mm"]),
                   angles_deg=tuple(tuple(r) for r in case["theta_deg"]),
                   boxes=tuple((k, tuple(v)) for k, v in case["boxes"].items()), rule="least_k", target=None,
                   reference=())
    res = synthesise_spec(spec, "other")
    rep = res.report
    assert rep["selection"]["exact_region_point"] is True
    assert rep["refined"] is None  # exact points qualify: no approximate refinement
    assert rep["region"]["points_accepted"] > 100
    assert rep["pose_error_mm"]["max"] < 1e-6  # exact synthesis, one branch
    assert rep["K"] <= 20.0 and rep["K"] == pytest.approx(rep["K_virtual_work"], rel=1e-9)
    region = res.data["region"]
    assert rep["K"] == pytest.approx(np.min(region.K[region.accepted]))
    # the chosen joints lie on their curves
    finger = res.data["finger"]
    choice = res.data["choice"]
    assert distance_to_curve(dyad_curve(finger.proximal, finger.distal), choice.d)[0] < 1e-6
    curve_d0, curve_f = stage_two_curves(finger, choice.d, choice.e)
    assert distance_to_curve(curve_d0, choice.d0)[0] < 1e-6
    assert distance_to_curve(curve_f, choice.f)[0] < 1e-6


# -- spec ------------------------------------------------------------------------------------------

def test_parse_spec_reads_the_paper_tables():
    spec = _paper_spec()
    assert spec.phalanx_lengths_mm == tuple(DATA["phalanx_lengths_mm"])
    assert np.allclose(spec.angles_deg, DATA["theta_deg"])
    for name, box in DATA["boxes"].items():
        assert np.allclose(spec.box(name), box)
    assert spec.k_max == 20.0 and spec.step_mm == 0.2 and spec.rule == "nearest"


@pytest.mark.parametrize("edit, path", [
    (lambda t: t["boxes"].__setitem__("d", [70.0, 30.0, -20.0, 20.0]), "boxes.d"),
    (lambda t: t["finger"].__setitem__("theta1_deg", [0.0, -10.0, 5.0, -40.0]), "finger.theta1_deg"),
    (lambda t: t["finger"].__setitem__("theta2_deg", [0.0, -24.0, -62.0]), "finger.theta2_deg"),
    (lambda t: t["region"].__setitem__("stepp_mm", 0.2), "region.stepp_mm"),
    (lambda t: t["selection"].__setitem__("rule", "best"), "selection.rule"),
    (lambda t: t["finger"].__setitem__("phalanx_lengths_mm", [50.0, -30.0, 25.0]), "finger.phalanx_lengths_mm[1]"),
])
def test_parse_spec_names_the_bad_field(edit, path):
    with pytest.raises(SpecError) as err:
        wsb.parse_spec(_template_root(edit=edit))
    assert err.value.path == path


def test_selected_finger_keeps_its_pins_clear_and_does_not_collide(paper_result):
    rep = paper_result.report
    assert rep["pin_to_middle_link_mm"] >= rep["pin_to_middle_link_limit_mm"] == 5.0
    build = pytest.importorskip("fabricate.parts.build")
    interference = pytest.importorskip("fabricate.checks.interference")
    from fabricate.design import load_design

    design = load_design(TEMPLATE)
    mech = paper_result.mechanism
    motion = mech.sweep(91)
    partset = build.build_parts(design, mech, motion, [], paper_result.parts)
    result = interference.sweep_interference(partset.parts, motion, chord_tolerance_mm=0.05,
                                             min_clearance_mm=0.25)
    assert [(p.a, p.b) for p in result.collisions] == []


def test_boxes_that_no_joint_can_reach_raise_synthesis_error():
    from fabricate.errors import SynthesisError

    spec = _paper_spec()
    boxes = tuple((name, (200.0, 210.0, -20.0, 20.0)) if name == "d" else (name, box) for name, box in spec.boxes)
    with pytest.raises(SynthesisError, match="region: 0 points"):
        synthesise_spec(replace(spec, boxes=boxes))


def test_grid_starts_at_the_box_edge_and_stays_inside():
    assert np.allclose(grid_in_range(30.1, 31.0, 0.2), [30.1, 30.3, 30.5, 30.7, 30.9], atol=1e-12)
    grid = grid_in_range(-10.0, 10.0, 0.2)
    assert len(grid) == 101 and np.allclose(grid[[0, -1]], [-10.0, 10.0])
