"""Five-bar NCG finger: five-bar finger with a non-circular gear pair (fabricate.synthesis.five_bar).

Expected numbers come from the paper (tests/data/five_bar_paper.json); tolerances are stated at each
assert. The IO-equation test re-derives the closed form (eqs 20-25) here, independently of the solver.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from fabricate.errors import LockupError, SpecError, SynthesisError
from fabricate.planar import transform_points
from fabricate.synthesis import five_bar as fb
from fabricate.synthesis.five_bar import kinematic_mapping as km
from fabricate.synthesis.five_bar.targets import finger_targets
from fabricate.table import Table
from fabricate.templates import TEMPLATE_DIR, read_toml

PAPER = json.loads((Path(__file__).resolve().parents[2] / "data" / "five_bar_paper.json").read_text())
TEMPLATE = TEMPLATE_DIR / "finger_five_bar_ncg.toml"


def template_root() -> dict:
    return read_toml(TEMPLATE)


def design_from(root: dict, sweep_poses: int = 90) -> SimpleNamespace:
    """A DesignSpec-like object carrying only what synthesise() reads."""
    return SimpleNamespace(name="finger_test", method=fb.parse_spec(Table(root)),
                           checks=SimpleNamespace(sweep_poses=sweep_poses))


@pytest.fixture(scope="module")
def paper_result():
    return fb.synthesise(design_from(template_root()))


# -- template and spec ------------------------------------------------------------------------------

def test_template_holds_the_paper_tables():
    spec = fb.parse_spec(Table(template_root()))
    assert spec.lengths_mm == tuple(PAPER["lengths_mm"])
    assert np.array_equal(np.array(spec.poses_deg), np.array(PAPER["poses_deg"]))
    for key, value in PAPER["limits"].items():
        assert getattr(spec, key) == tuple(value)
    assert spec.select == "x_A" and spec.x_A_mm == PAPER["chosen_A_mm"][0]


def test_template_loads_through_load_design():
    pytest.importorskip("fabricate.gears.spec")
    pytest.importorskip("fabricate.parts.spec")
    from fabricate.design import load_design

    design = load_design(TEMPLATE)
    assert design.kind == "five_bar_ncg"
    assert design.gears.module_mm == 0.5
    assert design.checks.sweep_poses == 360


def test_too_few_poses_names_the_field():
    root = template_root()
    root["finger"]["poses_deg"] = root["finger"]["poses_deg"][:3]
    with pytest.raises(SpecError) as err:
        fb.parse_spec(Table(root))
    assert err.value.path == "finger.poses_deg"


@pytest.mark.parametrize("section, key, value, path", [
    ("finger", "lengths_mm", [40.0, -28.0, 20.0], "finger.lengths_mm[1]"),
    ("synthesis", "ab_length_mm", [50.0, 40.0], "synthesis.ab_length_mm"),
    ("synthesis", "select", "closest", "synthesis.select"),
    ("synthesis", "typo_mm", 1.0, "synthesis.typo_mm"),
])
def test_bad_fields_name_their_path(section, key, value, path):
    root = template_root()
    root[section][key] = value
    with pytest.raises(SpecError) as err:
        fb.parse_spec(Table(root))
    assert err.value.path == path


def test_non_monotonic_proximal_angle_is_rejected():
    root = template_root()
    root["finger"]["poses_deg"][2][0] = 355.0
    with pytest.raises(SpecError, match="monotonic") as err:
        fb.parse_spec(Table(root))
    assert err.value.path == "finger.poses_deg"


# -- kinematic mapping ------------------------------------------------------------------------------

displacement = st.tuples(st.floats(-200, 200), st.floats(-200, 200), st.floats(-3.1, 3.1))
point = st.tuples(st.floats(-100, 100), st.floats(-100, 100))


@settings(max_examples=60, deadline=None)
@given(displacement, point)
def test_kinematic_mapping_round_trip(d, q):
    """eq 2 -> eq 3 reproduces the rigid displacement; the inverse recovers (e, f, v) at any scale."""
    z = km.image_coordinates(np.array([d]))[0]
    assert abs(z[2] ** 2 + z[3] ** 2 - 1.0) < 1e-12
    back = km.displacement_from_image(3.7 * z)[0]
    assert np.allclose(back[:2], d[:2], atol=1e-9)
    assert abs(math.remainder(back[2] - d[2], 2 * math.pi)) < 1e-12
    moved = km.map_points(z, np.array([q]))[0]
    assert np.allclose(moved, transform_points(np.array(d), np.array(q)), atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.lists(displacement, min_size=1, max_size=6), point, point, st.floats(1.0, 80.0))
def test_circle_vector_is_a_dyad(ds, centre, moving, radius):
    """A dyad's p meets eq 7, decodes to its centre and circle point, and M p is the circle residual."""
    p = km.circle_vector(np.array(centre), np.array(moving), radius)
    scale = max(1.0, float(np.abs(p).max())) ** 2
    assert np.all(np.abs(km.side_conditions(p)) < 1e-9 * scale)
    c, b = km.dyad_from_vector(-2.5 * p)
    assert np.allclose(c, centre, atol=1e-9) and np.allclose(b, moving, atol=1e-9)
    z = km.image_coordinates(np.array(ds))
    world = np.array([transform_points(np.array(d), np.array(moving)) for d in ds])
    # eq 5 with a0 = 1/2 is 0.5 (|X - c|^2 - r^2); eq 6 (hence M p) is eq 5 halved
    circle = 0.25 * (np.sum((world - centre) ** 2, axis=1) - radius ** 2)
    assert np.allclose(km.constraint_matrix(z) @ p, circle, atol=1e-7 * max(1.0, np.abs(circle).max()))


#: Four points in general position by construction: the corners of a 100 mm square, each moved by up to
#: 30 mm (random points would mostly be rejected as too close or nearly collinear).
jitter = st.tuples(st.floats(-30.0, 30.0), st.floats(-30.0, 30.0))


@settings(max_examples=40, deadline=None)
@given(st.lists(jitter, min_size=4, max_size=4), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_conic_intersections_find_the_base_points(offsets, u, v):
    """Two distinct conics of the pencil through four points meet exactly in those four points (c1 and c2 are
    the same conic when 1 + u v = 0: then every point of it is common, which hypothesis found at u = 1, v = -1)."""
    corners = ((-50.0, -50.0), (50.0, -50.0), (50.0, 50.0), (-50.0, 50.0))
    points = [(cx + dx, cy + dy) for (cx, cy), (dx, dy) in zip(corners, offsets, strict=True)]
    pts = np.array([[x, y, 1.0] for x, y in points])
    pairwise = [np.linalg.norm(np.cross(pts[i], pts[j])) for i in range(4) for j in range(i + 1, 4)]
    collinear = [abs(np.linalg.det(pts[[i, j, k]])) for i, j, k in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3))]
    assume(min(pairwise) > 5.0 and min(collinear) > 200.0 and abs(1.0 + u * v) > 0.05)
    rows = np.array([[x * x, x * y, y * y, x, y, 1.0] for x, y, _ in pts])
    null = np.linalg.svd(rows)[2][4:]  # the 2-dimensional pencil of conics through the points

    def conic(c):
        return np.array([[c[0], c[1] / 2, c[3] / 2], [c[1] / 2, c[2], c[4] / 2], [c[3] / 2, c[4] / 2, c[5]]])

    c1 = conic(null[0] + u * null[1])
    c2 = conic(null[1] - v * null[0])
    found = km.conic_intersections(c1, c2)
    found = np.array([x[:2] / x[2] for x in found if abs(x[2]) > 1e-12])
    assert len(found) >= 4
    for target in pts[:, :2]:
        assert np.min(np.hypot(*(found - target).T)) < 1e-5 * max(1.0, np.abs(target).max())


def test_finger_dyad_dc_is_an_exact_solution():
    """The finger's own dyad D-C (D fixed in O-D, C in the distal body) satisfies every row of M."""
    targets = finger_targets(fb.parse_spec(Table(template_root())))
    m = km.constraint_matrix(km.image_coordinates(targets.displacements))
    p = km.circle_vector(np.array([40.0, 0.0]), np.array([-20.0, 0.0]), 28.0)
    assert np.max(np.abs(m @ p)) < 1e-9 * np.abs(m).max() * np.abs(p).max()


def test_eigenvalues_three_vanish_and_fourth_is_small(paper_result):
    """Table 3: three zero eigenvalues and a small fourth.

    The paper prints 4.8e-3, 1.3907, 14.89, 1960.4; we get 3.96e-3, 0.988, 11.06, 1708 from Table 2
    as printed. The pattern (three zeros, then a gap of more than two decades) is the same; the
    values differ by 15-30 %, most likely because Table 2's angles were rounded ("取整") from the
    measured ones the authors computed with. We therefore assert the order of magnitude only.
    """
    ev = np.array(paper_result.report["eigenvalues"])
    assert ev.shape == (8,) and np.all(np.diff(ev) >= 0)
    assert np.all(np.abs(ev[:3]) < 1e-9 * ev[-1])
    assert PAPER["eigenvalues_table3"]["fourth"] / 3 < ev[3] < PAPER["eigenvalues_table3"]["fourth"] * 3
    assert ev[4] > 100 * ev[3]
    assert PAPER["eigenvalues_table3"]["seventh"] / 3 < ev[6] < PAPER["eigenvalues_table3"]["seventh"] * 3


# -- hinge curves and selection ------------------------------------------------------------------

def test_hinge_curves_pass_the_papers_choice(paper_result):
    """The chosen A lies within 0.3 mm of the paper's (15.13, -1.21), its B within 0.5 mm of (60.47, 13.69)."""
    rep = paper_result.report
    tol = PAPER["tolerances"]
    assert rep["A_mm"][0] == pytest.approx(PAPER["chosen_A_mm"][0], abs=1e-6)
    assert math.dist(rep["A_mm"], PAPER["chosen_A_mm"]) < tol["A_mm"]
    assert math.dist(rep["B_mm"], PAPER["chosen_B_mm"]) < tol["B_mm"]
    # the traced A-curve itself passes the paper's A (sampled: within the sample spacing too)
    dom = paper_result.data.domain
    assert np.min(np.hypot(*(dom.a - PAPER["chosen_A_mm"]).T)) < tol["A_mm"]
    # the chosen p is in the 4-eigenvector span and meets eq 7
    data = paper_result.data
    p = data.dyad.p
    basis = data.eigenvectors[:, :4]
    assert np.linalg.norm(p - basis @ (basis.T @ p)) < 1e-12
    assert np.all(np.abs(km.side_conditions(p)) < 1e-10)


def test_selection_does_not_depend_on_sampling(paper_result):
    """Coarse kappa sampling plus refinement and crossing bisection land on the same dyad."""
    root = template_root()
    root["synthesis"]["kappa_samples"] = 300
    coarse = fb.synthesise(design_from(root, sweep_poses=10)).report
    assert math.dist(coarse["A_mm"], paper_result.report["A_mm"]) < 1e-6
    assert math.dist(coarse["B_mm"], paper_result.report["B_mm"]) < 1e-6
    root["synthesis"]["x_A_mm"] = 22.0  # another point of the feasible domain
    other = fb.synthesise(design_from(root, sweep_poses=10)).report
    assert other["A_mm"][0] == pytest.approx(22.0, abs=1e-6)
    assert other["pose_error_mm"]["max"] < PAPER["mean_position_error_mm"]


def test_chosen_dyad_respects_the_limits(paper_result):
    rep = paper_result.report
    lengths = rep["link_lengths_mm"]
    assert 12.0 <= rep["A_mm"][0] <= 25.0 and -10.0 <= rep["A_mm"][1] <= 8.0
    assert 40.0 <= lengths["AB"] <= 50.0 and 10.0 <= lengths["BC"] <= 20.0
    assert rep["feasible_domain"]["feasible_points"] > 0
    # every feasible point lies in the A box; the domain is a proper subset of the curves
    dom = paper_result.data.domain
    a = dom.a[dom.feasible]
    assert np.all((a[:, 0] >= 12.0) & (a[:, 0] <= 25.0) & (a[:, 1] >= -10.0) & (a[:, 1] <= 8.0))
    assert rep["feasible_domain"]["feasible_points"] < rep["feasible_domain"]["curve_points"]


# -- the solved mechanism ------------------------------------------------------------------------------

def test_mechanism_reaches_every_pose(paper_result):
    """Fingertip error at all five poses below the paper's mean 0.236 mm (solved by the generic Mechanism)."""
    rep = paper_result.report
    errors = np.array(rep["pose_error_mm"]["per_pose"])
    assert errors.shape == (5,)
    assert np.all(errors < PAPER["mean_position_error_mm"])
    assert rep["pose_error_mm"]["max"] == pytest.approx(errors.max())
    assert rep["orientation_error_deg"]["max"] < 1.0
    # the mechanism's own solve agrees with the report at the last pose
    mech = paper_result.mechanism
    t = paper_result.data.targets
    poses = mech.solve(float(np.degrees(t.angles[-1, 0])))
    tip = transform_points(poses["distal"], mech.body("distal").point("P"))
    assert math.dist(tip, t.p[-1]) == pytest.approx(errors[-1], abs=1e-9)


def test_mechanism_names_and_gear_convention(paper_result):
    mech = paper_result.mechanism
    points = set(mech.point_names())
    assert {"O", "A", "B", "C", "D", "P"} <= points
    gear = mech.gears[0]
    assert (gear.carrier, gear.gear_a, gear.gear_b, gear.axis_a, gear.axis_b) == \
        ("proximal", "ground", "link_AB", "O", "A")
    assert mech.degrees_of_freedom() == 1 and len(mech.drivers) == 1
    lo, hi = gear.working_range
    motion = paper_result.data.motion
    x_a = motion.relative_angle("ground", "proximal")
    assert lo - 1e-9 <= x_a.min() and x_a.max() <= hi + 1e-9
    assert paper_result.parts.tip_point == "P" and "distal" in (paper_result.parts.pads or {})


def _io_equation_tip(result, psi_deg: np.ndarray) -> np.ndarray:
    """Fingertip P from the paper's IO equation (eqs 20-25), derived here independently.

    eq 20: A and D turn with the input psi1 about O. eq 21: A-B's angle relative to the arm changes
    by G(x) - G(x0), x = ground rotation relative to the arm = -(psi1 - psi10) + x0. eq 22 printed
    has slips (sin for cos, l_AC / l_BC for l_DC); from |C - B| = BC with A at the origin, D on +x:
        k1 + (d / a) cos(psi3) - (d / c) cos(psi2) - cos(psi2 - psi3) = 0,
        k1 = (d^2 + a^2 + c^2 - b^2) / (2 a c),  a = AB, b = BC, c = DC, d = AD,
    psi2 = angle of A-B from A->D, psi3 = angle of D-C from A->D (same sense). eq 25: P is C plus
    CP turned by the fixed angle between B->C and C->P.
    """
    mech = result.mechanism
    law = mech.gears[0].law
    rep = result.report
    o = np.asarray(rep["target_tip_mm"][0]) * 0.0 + np.asarray(mech.body("ground").point("O"))
    a0, b0 = np.asarray(rep["A_mm"]), np.asarray(rep["B_mm"])
    t = result.data.targets
    d0, c0, p0 = t.d[0], t.c[0], t.p[0]
    psi10 = t.angles[0, 0]
    x0 = -psi10
    lab, lbc, ldc, lcp = (math.dist(a0, b0), math.dist(b0, c0), math.dist(d0, c0), math.dist(c0, p0))
    beta0 = math.atan2(*(b0 - a0)[::-1])
    eta2 = math.atan2(*(p0 - c0)[::-1]) - math.atan2(*(c0 - b0)[::-1])
    out = []
    branch = None
    for psi in np.radians(psi_deg):
        turn = psi - psi10
        rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
        a = o + rot @ (a0 - o)
        d = o + rot @ (d0 - o)
        x = x0 - turn
        beta = beta0 + turn + float(law(x)) - float(law(x0))
        ad = d - a
        dist = math.hypot(*ad)
        base = math.atan2(ad[1], ad[0])
        psi2 = beta - base
        k1 = (dist ** 2 + lab ** 2 + ldc ** 2 - lbc ** 2) / (2 * lab * ldc)
        pc, qs = dist / lab - math.cos(psi2), -math.sin(psi2)
        r = dist / ldc * math.cos(psi2) - k1
        phase, spread = math.atan2(qs, pc), math.acos(r / math.hypot(pc, qs))
        candidates = [phase + spread, phase - spread]
        if branch is None:  # the assembly branch of the first pose: C at c0
            cs = [d + ldc * np.array([math.cos(base + s), math.sin(base + s)]) for s in candidates]
            branch = int(np.argmin([math.dist(c, c0) for c in cs]))
        psi3 = candidates[branch]
        c = d + ldc * np.array([math.cos(base + psi3), math.sin(base + psi3)])
        b = a + lab * np.array([math.cos(beta), math.sin(beta)])
        bc = (c - b) / math.hypot(*(c - b))
        rot2 = np.array([[math.cos(eta2), -math.sin(eta2)], [math.sin(eta2), math.cos(eta2)]])
        out.append(c + lcp * (rot2 @ bc))
    return np.array(out)


def test_generic_solver_matches_the_io_equation(paper_result):
    mech = paper_result.mechanism
    inputs = np.linspace(*mech.input_range, 181)
    motion = mech.sweep(inputs)
    tip = motion.point("P", "distal")
    closed = _io_equation_tip(paper_result, inputs)
    assert np.max(np.hypot(*(tip - closed).T)) < PAPER["tolerances"]["io_equation_mm"]
    # continuity: no branch jump between neighbouring inputs (0.275 deg steps)
    steps = np.hypot(*np.diff(tip, axis=0).T)
    assert steps.max() < 3.0 * np.median(steps)


def test_driving_past_the_range_locks_up(paper_result):
    mech = paper_result.mechanism
    start = mech.input_range[0]
    with pytest.raises(LockupError) as err:
        mech.sweep(np.linspace(start, start + 120.0, 241))
    assert start < err.value.input_value < start + 120.0
    assert "at input" in str(err.value)


# -- gear law ---------------------------------------------------------------------------------------------

def test_gear_law_rolls_without_slip(paper_result):
    """Pitch curves built independently from the law: equal arc lengths, constant centre distance."""
    law = paper_result.data.dyad.law
    x = np.linspace(*law.working_range, 4001)
    ratio = -law.law(x, 1)
    assert np.all(np.isfinite(ratio)) and np.all(ratio > 0)
    a = law.centre_distance
    r_a = np.interp(x, law.x, law.r_a)
    r_b = np.interp(x, law.x, law.r_b)
    assert np.allclose(r_a + r_b, a, atol=1e-9)
    # sun pitch point at polar angle -x in its frame; planet's at pi - f(x): the curves' arc lengths
    sun = r_a[:, None] * np.column_stack([np.cos(-x), np.sin(-x)])
    fx = law.law(x)
    planet = r_b[:, None] * np.column_stack([np.cos(np.pi - fx), np.sin(np.pi - fx)])
    s_sun = np.cumsum(np.hypot(*np.diff(sun, axis=0).T))
    s_planet = np.cumsum(np.hypot(*np.diff(planet, axis=0).T))
    assert np.max(np.abs(s_sun - s_planet)) < 1e-4 * s_sun[-1]
    # r_a dx_a = r_b |dx_b| at the pose knots (the printed eq 19's r1 = a / (1 + i) would fail this)
    rep = paper_result.report
    assert 0.0 < rep["transmission_ratio"][0] <= rep["transmission_ratio"][1] < np.inf
    assert rep["min_pitch_radius_of_curvature_mm"] > 0
    # the law passes through the pose samples (x_b relative to the arm at each pose)
    assert np.allclose(law.law(law.knots_a), law.knots_b, atol=1e-12)


def test_gear_law_is_what_the_mechanism_follows(paper_result):
    motion = paper_result.data.motion
    x_a = motion.relative_angle("ground", "proximal")
    x_b = motion.relative_angle("link_AB", "proximal")
    assert np.allclose(x_b, paper_result.mechanism.gears[0].law(x_a), atol=1e-10)


# -- failures and other fingers -----------------------------------------------------------------------

@pytest.mark.parametrize("key, value, needle", [
    ("a_x_mm", [100.0, 120.0], "a_x_mm"),
    ("bc_length_mm", [1.0, 2.0], "bc_length_mm"),
    ("x_A_mm", 26.0, "x_A_mm"),
])
def test_limits_leaving_nothing_raise_naming_the_limit(key, value, needle):
    root = template_root()
    root["synthesis"][key] = value
    root["synthesis"]["kappa_samples"] = 400
    with pytest.raises(SynthesisError, match=needle):
        fb.synthesise(design_from(root))


def test_a_different_finger_synthesises_or_fails_cleanly():
    """Other lengths, origin and a perturbed pose set synthesise; tight limits fail cleanly."""
    root = copy.deepcopy(template_root())
    root["finger"]["lengths_mm"] = [44.0, 26.0, 18.0]
    root["finger"]["origin_mm"] = [5.0, -3.0]
    poses = np.array(root["finger"]["poses_deg"]) - 360.0 + 15.0
    poses[1:, 1:] += [[1.0, -2.0], [2.5, 1.5], [-1.0, 2.0], [0.5, -1.5]]
    root["finger"]["poses_deg"] = poses.tolist()
    syn = root["synthesis"]
    syn.update({"select": "least_pose_error", "a_x_mm": [-30.0, 60.0], "a_y_mm": [-40.0, 40.0],
                "ab_length_mm": [20.0, 80.0], "bc_length_mm": [5.0, 40.0], "kappa_samples": 400,
                "curve_step_mm": 3.0})
    del syn["x_A_mm"]
    # these limits leave a feasible domain (measured: 61 of 1741 curve points, max error 0.04 mm)
    result = fb.synthesise(design_from(root, sweep_poses=30))
    rep = result.report
    assert rep["pose_error_mm"]["max"] < 2.0
    errors = np.array(rep["pose_error_mm"]["per_pose"])
    assert errors[0] < 1e-9  # the first pose is exact by construction
    assert rep["link_lengths_mm"]["OD"] == 44.0
    assert math.dist(result.mechanism.body("ground").point("O"), (5.0, -3.0)) == 0.0
    assert rep["feasible_domain"]["feasible_points"] > 0
    syn["ab_length_mm"] = [20.0, 21.0]
    with pytest.raises(SynthesisError, match="ab_length_mm"):
        fb.synthesise(design_from(root, sweep_poses=30))


def test_four_poses_give_an_exact_family():
    """With four poses the four smallest eigenvalues vanish and every traced dyad is exact."""
    root = template_root()
    root["finger"]["poses_deg"] = root["finger"]["poses_deg"][:4]
    spec = fb.parse_spec(Table(root))
    targets = finger_targets(spec)
    m = km.constraint_matrix(km.image_coordinates(targets.displacements))
    values, vectors = km.family_basis(m)
    assert np.all(np.abs(values[:4]) < 1e-9 * values[-1])
    family = km.trace_family(vectors[:, :4], 200)
    assert len(family.kappa) > 100
    assert np.max(np.abs(m @ family.p.T)) < 1e-6 * np.abs(m).max()


# -- figures ----------------------------------------------------------------------------------------------

def test_figures_are_deterministic_pngs(paper_result):
    first = paper_result.figures()
    assert set(first) == {"hinge_curves.png", "feasible_domain.png", "gear_ratio.png", "trajectory.png"}
    for blob in first.values():
        assert blob.startswith(b"\x89PNG\r\n\x1a\n") and len(blob) > 5000
    again = paper_result.figures()
    assert all(first[k] == again[k] for k in first)


def test_report_is_json_ready(paper_result):
    text = json.dumps(paper_result.report, allow_nan=False)
    rep = json.loads(text)
    assert len(rep["eigenvalues"]) == 8
    assert {"max", "mean"} <= set(rep["pose_error_mm"])
    assert len(rep["gear_law"]["poses_x_a_deg"]) == 5
