"""Closed-form strength models and cut sections (issue 12, step 9) against published worked examples.

The expected numbers and their sources are in ``tests/data/strength_examples.json``; each test states its
tolerance. The plate-with-hole model is also checked against a plane-stress finite-element solution
(scikit-fem, quadratic triangles) at the end of the file.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fabricate.errors import GeometryError
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.strength.gear_teeth import (
    hertz_line_contact_stress,
    involute_contact_radii,
    lewis_bending_stress,
    lewis_form_factor,
)
from fabricate.strength.models import (
    PIN_CLEARANCE_FACTOR,
    bearing_stress,
    hole_stress_concentration,
    net_section_stress,
    pin_bending_moment_double_shear,
    pin_bending_moment_single_shear,
    pin_bending_stress,
    pin_shear_stress,
    safety_factor,
    tearout_stress,
    torsion_spring_stress,
)
from fabricate.strength.section import Section, cut_section, side_of_cut

DATA = json.loads((Path(__file__).resolve().parents[1] / "data" / "strength_examples.json").read_text())
LBF = DATA["units"]["lbf_N"]
INCH = DATA["units"]["in_mm"]
PSI = LBF / INCH ** 2  # MPa per psi


def rectangle(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """Counter-clockwise rectangle ring, (4, 2)."""
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)


def hole_ring(centre: tuple[float, float], diameter: float, n: int = 64) -> np.ndarray:
    """Clockwise polygon inscribed in a circle with vertices at 0, 90, 180 and 270 degrees (n % 4 == 0)."""
    assert n % 4 == 0
    angles = -np.arange(n) * (2.0 * math.pi / n)
    return np.asarray(centre, dtype=np.float64) + 0.5 * diameter * np.column_stack([np.cos(angles), np.sin(angles)])


# -- Lewis ---------------------------------------------------------------------------------------------


def test_lewis_form_factor_reproduces_shigley_table_and_an_independent_table():
    table = DATA["lewis_table"]
    for key, y in table["exact"].items():
        teeth = math.inf if key == "rack" else float(key)
        assert lewis_form_factor(teeth) == pytest.approx(y, abs=1e-12)
    # another published tabulation agrees with Shigley's within about 1 % (tolerance 1.5 %)
    for key, y in table["cross_check"].items():
        if int(key) >= 12:
            assert lewis_form_factor(float(key)) == pytest.approx(y, rel=table["cross_check_tolerance_rel"])


def test_lewis_shigley_example_14_1():
    """Shigley Ex. 14-1 (a): Wt = F Y sigma_all / (Kv P), i.e. sigma = Kv Wt P / (F Y) = 10 kpsi; within 1 %."""
    ex = DATA["lewis"]
    y = lewis_form_factor(ex["teeth"])
    assert y == pytest.approx(ex["Y"], abs=1e-12)
    module = INCH / ex["diametral_pitch_per_in"]
    sigma = lewis_bending_stress(ex["Kv"] * ex["tangential_load_lbf"] * LBF, module, ex["face_width_in"] * INCH, y)
    assert sigma == pytest.approx(ex["allowable_stress_psi"] * PSI, rel=ex["tolerance_rel"])
    # the example's own numbers agree with each other: H = Wt V / 33000
    assert ex["tangential_load_lbf"] * ex["pitch_line_velocity_ft_min"] / 33000 == pytest.approx(ex["power_hp"],
                                                                                                 rel=0.01)


def test_lewis_form_factor_between_entries_outside_the_table_and_for_racks():
    # non-integer (equivalent) teeth fall between the neighbouring entries; Y never decreases with N
    assert 0.296 < lewis_form_factor(16.5) < 0.303
    grid = np.linspace(3.0, 2000.0, 4000)
    y = lewis_form_factor(grid)
    assert y.shape == grid.shape and np.all(np.diff(y) >= 0.0)
    # below 12 teeth: conservative against the extended published table (10: 0.201, 11: 0.226), and
    # continuous at 12
    cross = DATA["lewis_table"]["cross_check"]
    assert lewis_form_factor(10.0) < cross["10"] and lewis_form_factor(11.0) < cross["11"]
    assert lewis_form_factor(11.999) == pytest.approx(0.245, rel=1e-3)
    # a straight (inf) or concave (negative radius -> negative teeth) pitch segment: the rack value
    for teeth in (math.inf, -math.inf, -40.0, -3.0):
        assert lewis_form_factor(teeth) == 0.485
    assert lewis_form_factor(1e6) == pytest.approx(0.485, abs=1e-5)
    for bad in (0.0, math.nan):
        with pytest.raises(ValueError):
            lewis_form_factor(bad)


# -- pins, bearing, tear-out ---------------------------------------------------------------------------


@pytest.mark.parametrize("case", DATA["pin_double_shear"], ids=["hibbeler_1_61", "hibbeler_1_49"])
def test_pin_double_shear_hibbeler(case):
    """Hibbeler 8th ed. Problems 1-61 and 1-49 (pins in double shear, 18 mm): within 0.5 %."""
    tau = pin_shear_stress(case["pin_force_N"], case["pin_diameter_mm"], 2)
    assert tau == pytest.approx(case["shear_stress_MPa"], rel=case["tolerance_rel"])
    # single shear carries the whole force on one section
    assert pin_shear_stress(case["pin_force_N"], case["pin_diameter_mm"], 1) == pytest.approx(2.0 * tau)
    assert pin_shear_stress(-case["pin_force_N"], case["pin_diameter_mm"], 2) == pytest.approx(tau)


def test_pin_connected_bar_gere_1_8_14():
    """Gere Solution 1.8-14: at d = 24.7 mm, P = 49.4 kN the net tension is 140 MPa and the bearing 200 MPa
    (both within 0.5 %); the double-shear pin stays below its 80 MPa."""
    ex = DATA["pin_bar_gere"]
    load = ex["load_kN"] * 1e3
    assert bearing_stress(load, ex["pin_diameter_mm"], ex["thickness_mm"]) == pytest.approx(ex["bearing_MPa"],
                                                                                           rel=ex["tolerance_rel"])
    # the net section from the real geometry: a bar 60 wide with the hole, cut square to the load
    bar = rectangle(-50.0, -ex["bar_width_mm"] / 2, 50.0, ex["bar_width_mm"] / 2)
    section = cut_section([bar, hole_ring((0.0, 0.0), ex["pin_diameter_mm"])], [0.0, 0.0], [0.0, 1.0],
                          ex["thickness_mm"])
    assert section.width_mm == pytest.approx(ex["bar_width_mm"] - ex["pin_diameter_mm"], rel=1e-12)
    assert net_section_stress(load, 0.0, section, 1.0) == pytest.approx(ex["net_tension_MPa"],
                                                                        rel=ex["tolerance_rel"])
    tau = pin_shear_stress(load, ex["pin_diameter_mm"], 2)
    assert tau == pytest.approx(load / (2 * math.pi * ex["pin_diameter_mm"] ** 2 / 4))
    assert tau < ex["allowable_shear_MPa"]


def _max_moment_by_integration(loads: list[tuple[float, float, float]], n: int = 200_000,
                               until: float = -math.inf) -> float:
    """Largest |M| along a pin carrying uniform line loads (start, end, total force), from the free end at
    the first load to the last load's end (or ``until``): numerical statics."""
    x0 = min(a for a, _, _ in loads)
    x1 = max(max(b for _, b, _ in loads), until)
    x = np.linspace(x0, x1, n + 1)
    q = np.zeros(n + 1)
    for a, b, force in loads:
        q += np.where((x >= a) & (x <= b), force / (b - a), 0.0)
    shear = np.concatenate([[0.0], np.cumsum((q[1:] + q[:-1]) / 2 * np.diff(x))])
    moment = np.concatenate([[0.0], np.cumsum((shear[1:] + shear[:-1]) / 2 * np.diff(x))])
    return float(np.max(np.abs(moment)))


@pytest.mark.parametrize("a,b,g", [(3.0, 3.0, 0.0), (2.0, 5.0, 0.5), (4.0, 1.5, 1.0)])
def test_clevis_pin_moment_matches_beam_statics(a, b, g):
    """Uniform bearing over each plate (outer a, middle b, gaps g): the closed form equals the beam's
    largest moment from numerical integration of the loads (within 1e-4)."""
    force = 1000.0
    loads = [(0.0, a, force / 2), (a + g, a + g + b, -force), (a + 2 * g + b, 2 * a + 2 * g + b, force / 2)]
    expected = _max_moment_by_integration(loads)
    assert pin_bending_moment_double_shear(force, b, a, g) == pytest.approx(expected, rel=1e-4)


@settings(max_examples=50, deadline=None)
@given(st.floats(0.5, 10.0), st.floats(0.5, 10.0), st.floats(0.0, 3.0))
def test_single_shear_pin_moment_envelope(ta, tb, g):
    """The lap-joint moment is the worse cantilever (pin built in at one plate, uniform bearing on the
    other, by statics) and never below the equal-split model F e / 2."""
    force = 700.0
    m = pin_bending_moment_single_shear(force, ta, tb, g)
    assert m >= force * (ta / 2 + g + tb / 2) / 2 * (1 - 1e-12)
    # cantilever built in at the face of the thinner plate, loaded uniformly over the thicker one: the
    # moment at the support face
    t_load = max(ta, tb)
    expected = _max_moment_by_integration([(0.0, t_load, force)], 20_000, until=t_load + g)
    assert m == pytest.approx(expected, rel=1e-3)


def test_pin_bending_stress_is_mc_over_i():
    moment, d = 1500.0, 4.0
    inertia = math.pi * d ** 4 / 64.0
    assert pin_bending_stress(moment, d) == pytest.approx(moment * (d / 2) / inertia, rel=1e-12)
    assert pin_bending_stress(np.array([moment, -2 * moment]), d) == pytest.approx(
        [moment * (d / 2) / inertia, 2 * moment * (d / 2) / inertia])


def test_tearout_two_shear_planes_and_broken_edge():
    force, e, dh, t = 400.0, 5.0, 3.0, 2.0
    assert tearout_stress(force, e, dh, t) == pytest.approx(force / (2 * t * (e - dh / 2)), rel=1e-12)
    with pytest.raises(GeometryError):
        tearout_stress(force, 1.5, 3.0, t)
    with pytest.raises(ValueError):
        bearing_stress(force, 3.0, 0.0)


# -- holes: stress concentration and net sections ------------------------------------------------------


def test_open_hole_kt_against_howland_bhandari_and_kirsch():
    """Peterson's fit + 2 % margin: at or above each published value, at most 2.5 % above (chart readings 3 %)."""
    ex = DATA["open_hole"]
    margin = ex["margin"]
    howland = ex["howland"]
    kt = hole_stress_concentration(howland["d_over_w"] * 10.0, 10.0, False)
    assert howland["kt_net"] <= kt <= howland["kt_net"] * 1.025
    assert kt / margin == pytest.approx(howland["kt_net"], rel=0.005)  # the fit itself: Howland within 0.5 %
    b3 = ex["bhandari_5_3"]
    kt = hole_stress_concentration(b3["hole_mm"], b3["width_mm"], False)
    assert b3["kt_chart"] <= kt <= b3["kt_chart"] * 1.03
    small = hole_stress_concentration(1e-6, 10.0, False)
    assert ex["kirsch_small_hole_kt"] <= small <= ex["kirsch_small_hole_kt"] * 1.025
    ratios = np.linspace(0.0, 0.95, 96)
    kts = [hole_stress_concentration(r, 1.0, False) for r in ratios]
    assert np.all(np.diff(kts) < 0.0) and kts[-1] > 2.0
    with pytest.raises(GeometryError):
        hole_stress_concentration(10.0, 10.0, False)


def test_bhandari_example_5_1_peak_stress_on_the_cut_section():
    """Bhandari Ex. 5.1: P = 5 kN, 30 mm plate, 15 mm hole, t = 9 mm gives 80 MPa at the hole with Kt 2.16."""
    ex = DATA["open_hole"]["bhandari_5_1"]
    plate = rectangle(-60.0, -ex["width_mm"] / 2, 60.0, ex["width_mm"] / 2)
    section = cut_section([plate, hole_ring((0.0, 0.0), ex["hole_mm"])], [0.0, -3.0], [0.0, 2.0], ex["thickness_mm"])
    kt = hole_stress_concentration(ex["hole_mm"], ex["width_mm"], False)
    peak = net_section_stress(ex["load_N"], 0.0, section, kt)
    assert ex["peak_MPa"] <= peak <= ex["peak_MPa"] * 1.025
    assert net_section_stress(ex["load_N"], 0.0, section, ex["kt_chart"]) == pytest.approx(ex["peak_MPa"], rel=1e-9)


def test_pin_loaded_hole_kt_fit_clearance_and_extensions():
    fit = DATA["pin_loaded_hole"]
    # printed joints run with clearance: the upper end of Frocht & Hill's "increase Kt 35 to 50 percent"
    assert PIN_CLEARANCE_FACTOR == fit["clearance_factor_range"][1]

    def close(r: float) -> float:
        return hole_stress_concentration(r, 1.0, True, pin_clearance=False)

    assert close(0.5) == pytest.approx(12.882 - 52.714 * 0.5 + 89.762 * 0.25 - 51.667 * 0.125, rel=1e-12)
    assert hole_stress_concentration(0.5, 1.0, True) == pytest.approx(1.5 * close(0.5), rel=1e-12)
    for r in (0.15, 0.3, 0.5, 0.7):  # a pin-loaded hole is always worse than an open one
        assert close(r) > hole_stress_concentration(r, 1.0, False)
    # continuous at both ends of the fitted range; held constant above it
    assert close(0.15 - 1e-9) == pytest.approx(close(0.15), rel=1e-6)
    assert close(0.9) == pytest.approx(close(0.75), rel=1e-12)
    # below the range the peak stays the same multiple of the bearing stress F / (d t)
    for r in (0.02, 0.05, 0.1):
        assert close(r) * r / (1 - r) == pytest.approx(close(0.15) * 0.15 / 0.85, rel=1e-12)
    with pytest.raises(ValueError):
        hole_stress_concentration(0.0, 1.0, True)


def test_net_section_stress_adds_axial_and_bending_at_the_extreme_fibre():
    t, w = 3.0, 8.0
    section = cut_section([rectangle(0.0, 0.0, 40.0, w)], [20.0, 0.0], [0.0, 1.0], t)
    axial, moment, kt = 250.0, 900.0, 1.7
    expected = kt * (axial / (w * t) + 6.0 * moment / (t * w ** 2))
    assert net_section_stress(axial, moment, section, kt) == pytest.approx(expected, rel=1e-12)
    assert net_section_stress(-axial, -moment, section, kt) == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ValueError):
        net_section_stress(axial, moment, section, 0.9)


# -- contact, springs, margins -------------------------------------------------------------------------


def test_hertz_pitch_point_contact_shigley_example_14_3():
    """Shigley Ex. 14-3: sigma_C = Cp sqrt(Kv Wt / (F cos phi) (1/r1 + 1/r2)) = 72 400 psi; within 1 %."""
    ex = DATA["hertz_gear"]
    phi = math.radians(ex["pressure_angle_deg"])
    r1, r2 = involute_contact_radii(ex["pinion_pitch_diameter_in"] / 2 * INCH, ex["gear_pitch_diameter_in"] / 2 * INCH,
                                    phi)
    assert r1 / INCH == pytest.approx(ex["r1_in"], abs=5e-4)
    assert r2 / INCH == pytest.approx(ex["r2_in"], abs=5e-4)
    normal = ex["Kv"] * ex["tangential_load_lbf"] * LBF / math.cos(phi)
    p = hertz_line_contact_stress(normal, ex["face_width_in"] * INCH, r1, r2, ex["E_pinion_psi"] * PSI,
                                  ex["nu_pinion"], ex["E_gear_psi"] * PSI, ex["nu_gear"])
    assert p / PSI == pytest.approx(ex["contact_stress_psi"], rel=ex["tolerance_rel"])
    # the example's elastic coefficient Cp = 1 / sqrt(pi * compliance)
    compliance = (1 - ex["nu_pinion"] ** 2) / ex["E_pinion_psi"] + (1 - ex["nu_gear"] ** 2) / ex["E_gear_psi"]
    assert 1 / math.sqrt(math.pi * compliance) == pytest.approx(ex["elastic_coefficient_psi05"], rel=1e-3)


@pytest.mark.parametrize("r1,r2", [(5.0, 12.0), (5.0, -12.0), (5.0, math.inf), (-20.0, 4.0)])
def test_hertz_matches_half_width_form_for_convex_concave_and_flat(r1, r2):
    """Shigley Eqs. 3-73/3-74: b = sqrt(2F/(pi l) * compliance / (1/d1 + 1/d2)), p = 2F/(pi b l), d = 2 rho."""
    force, length, e1, nu1, e2, nu2 = 120.0, 6.0, 2800.0, 0.35, 2.1e5, 0.3
    compliance = (1 - nu1 ** 2) / e1 + (1 - nu2 ** 2) / e2
    half = math.sqrt(2 * force / (math.pi * length) * compliance / (1 / (2 * r1) + 1 / (2 * r2)))
    expected = 2 * force / (math.pi * half * length)
    assert hertz_line_contact_stress(force, length, r1, r2, e1, nu1, e2, nu2) == pytest.approx(expected, rel=1e-12)


def test_hertz_rejects_conformal_and_inverted_contacts():
    with pytest.raises(GeometryError):
        hertz_line_contact_stress(10.0, 5.0, math.inf, math.inf, 2800.0, 0.35, 2800.0, 0.35)
    with pytest.raises(GeometryError):
        hertz_line_contact_stress(10.0, 5.0, 5.0, -4.0, 2800.0, 0.35, 2800.0, 0.35)
    with pytest.raises(ValueError):
        hertz_line_contact_stress(10.0, 5.0, 5.0, 0.0, 2800.0, 0.35, 2800.0, 0.35)
    r1, r2 = involute_contact_radii(-30.0, math.inf, math.radians(20.0))
    assert r1 == pytest.approx(-30.0 * math.sin(math.radians(20.0))) and r2 == math.inf


def test_torsion_spring_stress_curvature_factor_and_shigley_example_10_8():
    """Ki(C = 10) = 1.08 (engineeringprep 484, within 0.1 %); Shigley Ex. 10-8: the yield torque 7.546 lbf in
    on 0.072 in wire, C = 7.247 gives Sy = 229.6 kpsi (within 1 %)."""
    ki = DATA["torsion_spring"]["ki_example"]
    moment, d = 100.0, 1.5
    nominal = 32 * moment / (math.pi * d ** 3)
    assert torsion_spring_stress(moment, d, ki["coil_index"]) / nominal == pytest.approx(ki["ki"], rel=1e-3)
    ex = DATA["torsion_spring"]["shigley"]
    c = ex["mean_diameter_in"] / ex["wire_diameter_in"]
    sigma = torsion_spring_stress(ex["torque_lbf_in"] * LBF * INCH, ex["wire_diameter_in"] * INCH, c)
    assert sigma / PSI == pytest.approx(ex["yield_psi"], rel=ex["tolerance_rel"])
    assert sigma / (32 * ex["torque_lbf_in"] * LBF * INCH / (math.pi * (ex["wire_diameter_in"] * INCH) ** 3)) == \
        pytest.approx(ex["ki"], rel=1e-3)
    with pytest.raises(ValueError):
        torsion_spring_stress(moment, d, 1.0)


def test_safety_factor():
    assert safety_factor(60.0, 20.0) == pytest.approx(3.0)
    assert safety_factor(60.0, -20.0) == pytest.approx(3.0)
    assert safety_factor(60.0, 0.0) == math.inf
    assert safety_factor(60.0, np.array([0.0, 30.0])) == pytest.approx([math.inf, 2.0])
    with pytest.raises(ValueError):
        safety_factor(0.0, 1.0)


# -- cut sections ----------------------------------------------------------------------------------------


def test_cut_section_rectangle_exact():
    t = 3.0
    section = cut_section([rectangle(0.0, 0.0, 10.0, 4.0)], [5.0, 1.0], [0.0, 1.0], t)
    assert section.width_mm == pytest.approx(4.0, rel=1e-12)
    assert section.area_mm2 == pytest.approx(4.0 * t, rel=1e-12)
    assert section.inertia_mm4 == pytest.approx(t * 4.0 ** 3 / 12.0, rel=1e-12)
    assert section.extreme_fibre_mm == pytest.approx(2.0, rel=1e-12)
    assert section.thickness_mm == t
    np.testing.assert_allclose(section.segments, [[-1.0, 3.0]], atol=1e-12)
    np.testing.assert_allclose(section.centroid_mm, [5.0, 2.0], atol=1e-12)
    # the direction's length and sign do not change the section
    other = cut_section([rectangle(0.0, 0.0, 10.0, 4.0)], [5.0, 1.0], [0.0, -7.0], t)
    assert other.inertia_mm4 == pytest.approx(section.inertia_mm4, rel=1e-12)
    np.testing.assert_allclose(other.segments, [[-3.0, 1.0]], atol=1e-12)


def test_cut_section_through_a_hole_parallel_axis_theorem():
    t, d = 3.0, 2.0
    rings = [rectangle(0.0, 0.0, 10.0, 4.0), hole_ring((5.0, 2.0), d)]
    section = cut_section(rings, [5.0, 0.0], [0.0, 1.0], t)
    np.testing.assert_allclose(section.segments, [[0.0, 1.0], [3.0, 4.0]], atol=1e-12)
    assert section.width_mm == pytest.approx(4.0 - d, rel=1e-12)
    # two 1 mm strips whose centres are 1.5 mm from the centroid
    strip = 1.0
    expected = 2 * (t * strip ** 3 / 12 + t * strip * 1.5 ** 2)
    assert section.inertia_mm4 == pytest.approx(expected, rel=1e-12)
    assert section.extreme_fibre_mm == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(section.centroid_mm, [5.0, 2.0], atol=1e-12)


def test_cut_section_off_centre_hole_moves_the_centroid():
    t = 2.0
    rings = [rectangle(0.0, 0.0, 10.0, 10.0), hole_ring((5.0, 3.0), 2.0)]
    section = cut_section(rings, [5.0, 5.0], [0.0, 1.0], t)
    # material [0, 2] and [4, 10] in y
    lengths, centres = np.array([2.0, 6.0]), np.array([1.0, 7.0])
    ybar = float((lengths * centres).sum() / lengths.sum())
    expected = float((t * lengths ** 3 / 12 + t * lengths * (centres - ybar) ** 2).sum())
    assert section.inertia_mm4 == pytest.approx(expected, rel=1e-12)
    assert section.extreme_fibre_mm == pytest.approx(max(ybar, 10.0 - ybar), rel=1e-12)
    np.testing.assert_allclose(section.centroid_mm, [5.0, ybar], atol=1e-12)


def test_cut_section_missing_the_part_or_degenerate_input():
    ring = rectangle(0.0, 0.0, 10.0, 4.0)
    with pytest.raises(GeometryError):
        cut_section([ring], [0.0, 20.0], [1.0, 0.0], 3.0)
    with pytest.raises(GeometryError):  # touches a corner only
        cut_section([ring], [10.0, 4.0], [1.0, -1.0], 3.0)
    with pytest.raises(ValueError):
        cut_section([ring], [5.0, 2.0], [0.0, 0.0], 3.0)
    with pytest.raises(GeometryError):  # a self-intersecting outline
        cut_section([np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])], [0.5, 0.2], [0.0, 1.0], 1.0)
    with pytest.raises(ValueError):
        cut_section([ring], [5.0, 2.0], [0.0, 1.0], 0.0)


def test_cut_section_of_a_real_link_part():
    """A link from the parts layer (round ends, two holes), cut square to its axis through a hole: the net
    width is the width less the hole, within the chord tolerance of the polygonised circle."""
    w, length, d, t, tol = 8.0, 40.0, 2.5, 3.0, 0.01
    r = w / 2
    outline = BulgePath(np.array([[0.0, -r], [length, -r], [length, r], [0.0, r]]), np.array([0.0, 1.0, 0.0, 1.0]))
    part = Part("link", "b", outline, (Hole("A", np.array([0.0, 0.0]), d), Hole("B", np.array([length, 0.0]), d)),
                t, 0.0, 0, "sla")
    section = cut_section(part.polygons(tol), [length, 0.0], [0.0, 1.0], t)
    assert w - d - 1e-9 <= section.width_mm <= w - d + 2 * tol
    assert len(section.segments) == 2
    mid = cut_section(part.polygons(tol), [length / 2, 0.0], [0.0, 1.0], t)
    assert mid.width_mm == pytest.approx(w, rel=1e-12)
    assert mid.inertia_mm4 == pytest.approx(t * w ** 3 / 12, rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.floats(0.5, 60.0), st.floats(0.5, 60.0), st.floats(0.01, 0.99), st.floats(0.01, 0.99),
       st.floats(0.0, math.pi), st.floats(-math.pi, math.pi), st.floats(-100.0, 100.0), st.floats(-100.0, 100.0))
@example(0.5, 1.0, 0.5, 0.25, 1.0, 0.0, 0.0, 5e-324)
@example(0.5, 1.0, 0.5, 0.25, 1.0, 0.0, -1e-310, 1e-310)
def test_cut_section_width_is_the_chord_of_a_rectangle(a, b, fx, fy, angle, spin, ox, oy):
    """Any rectangle (moved and turned), any cut through an interior point: net width = chord, 1e-9 relative.
    The examples are a fresh machine's hypothesis find: a subnormal offset (5e-324, 1e-310 mm) made GEOS cut
    the 0.5 x 1 plate 6 % wide (0.808 for 0.760); subnormal coordinates are now taken as 0."""
    point_local = np.array([fx * a, fy * b])
    u_local = np.array([math.cos(angle), math.sin(angle)])
    # chord of the line through the point along u in [0, a] x [0, b]
    lo, hi = -math.inf, math.inf
    for p, ui, size in ((point_local[0], u_local[0], a), (point_local[1], u_local[1], b)):
        if abs(ui) > 1e-15:
            t0, t1 = sorted(((0.0 - p) / ui, (size - p) / ui))
            lo, hi = max(lo, t0), min(hi, t1)
    chord = hi - lo
    rot = np.array([[math.cos(spin), -math.sin(spin)], [math.sin(spin), math.cos(spin)]])
    offset = np.array([ox, oy])
    ring = rectangle(0.0, 0.0, a, b) @ rot.T + offset
    section = cut_section([ring], rot @ point_local + offset, rot @ u_local, 1.0)
    assert section.width_mm == pytest.approx(chord, rel=1e-9)


def test_side_of_cut_signs():
    pts = np.array([[0.0, 1.0], [0.0, -2.0], [3.0, 0.0]])
    np.testing.assert_allclose(side_of_cut(pts, [0.0, 0.0], [2.0, 0.0]), [1.0, -2.0, 0.0])
    np.testing.assert_allclose(side_of_cut(pts, [0.0, 0.0], [0.0, 5.0]), [0.0, 0.0, -3.0])
    assert side_of_cut([1.0, 1.0], [0.0, 0.0], [1.0, 1.0]) == pytest.approx(0.0, abs=1e-15)


def test_section_is_a_frozen_record():
    section = cut_section([rectangle(0.0, 0.0, 2.0, 2.0)], [1.0, 1.0], [1.0, 0.0], 1.0)
    assert isinstance(section, Section)
    with pytest.raises(AttributeError):
        section.width_mm = 3.0  # type: ignore[misc]


# -- finite-element link: the net-section model is conservative -----------------------------------------


def quarter_plate_mesh(width: float, length: float, radius: float, m: int):
    """Triangle mesh of a quarter of a plate (x in [0, length/2], y in [0, width/2]) less a central hole.

    Near the hole a mapped mesh runs from the quarter circle to the square [0, width/2]^2 (2m segments
    round the arc, m layers graded towards the hole); beyond it a structured grid grows towards the
    loaded end. Returns a ``skfem.MeshTri``.
    """

    half = width / 2.0
    theta = (math.pi / 2.0) * np.arange(2 * m + 1) / (2 * m)
    arc = radius * np.column_stack([np.cos(theta), np.sin(theta)])
    i = np.arange(2 * m + 1)
    square = np.where((i <= m)[:, None], np.column_stack([np.full(i.shape, half), half * i / m]),
                      np.column_stack([half * (2 * m - i) / m, np.full(i.shape, half)]))
    grade = 1.12
    s = (grade ** np.arange(m + 1) - 1.0) / (grade ** m - 1.0)
    near = arc[:, None, :] + s[None, :, None] * (square - arc)[:, None, :]
    xs = [half]
    while xs[-1] < length / 2.0 - 1e-12:
        xs.append(min(xs[-1] + min(half / m * 1.15 ** len(xs), half / 2.0), length / 2.0))
    gx, gy = np.meshgrid(np.array(xs), half * np.arange(m + 1) / m, indexing="ij")
    far = np.stack([gx, gy], -1)
    return blocks_mesh([near, far])  # the two blocks share the nodes on x = width/2


def blocks_mesh(blocks: list[np.ndarray]):
    """One ``skfem.MeshTri`` from structured point blocks ((i, j, 2) arrays, two triangles per cell); nodes
    that blocks share (equal to 1e-9 mm) are merged and every triangle is made counter-clockwise."""
    from skfem import MeshTri

    points = np.concatenate([b.reshape(-1, 2) for b in blocks])
    tris = []
    offset = 0
    for block in blocks:
        idx = offset + np.arange(block.shape[0] * block.shape[1]).reshape(block.shape[:2])
        a, b, c, e = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
        tris += [np.column_stack([a, b, c]), np.column_stack([a, c, e])]
        offset += idx.size
    t = np.concatenate(tris)
    _, first, inverse = np.unique(np.round(points * 1e9).astype(np.int64), axis=0, return_index=True,
                                  return_inverse=True)
    p, t = points[first], inverse.ravel()[t]
    v = p[t]
    area = (v[:, 1, 0] - v[:, 0, 0]) * (v[:, 2, 1] - v[:, 0, 1]) - (v[:, 2, 0] - v[:, 0, 0]) * (v[:, 1, 1] - v[:, 0, 1])
    t[area < 0] = t[area < 0][:, [0, 2, 1]]
    return MeshTri(p.T.copy(), t.T.copy())


def plate_hole_peak_von_mises(width: float, length: float, hole_d: float, modulus: float, poisson: float,
                              traction: float, m: int) -> float:
    """Largest von Mises stress on the hole edge of a plate in uniform end traction, linear plane stress.

    Quarter model with symmetry planes x = 0 and y = 0, quadratic triangles; the stress at each hole-edge
    vertex is taken from the displacement gradient of every element touching it (no smoothing).
    """
    from skfem import Basis, CellBasis, ElementTriP2, ElementVector, FacetBasis, LinearForm, asm, condense, solve
    from skfem.models.elasticity import linear_elasticity, plane_stress

    radius = hole_d / 2.0
    mesh = quarter_plate_mesh(width, length, radius, m)
    element = ElementVector(ElementTriP2())
    basis = Basis(mesh, element)
    lam, mu = plane_stress(modulus, poisson)
    stiffness = asm(linear_elasticity(lam, mu), basis)
    end = FacetBasis(mesh, element, facets=mesh.facets_satisfying(lambda x: np.isclose(x[0], length / 2.0)))

    @LinearForm
    def pull(v, w):
        return traction * v[0]

    load = asm(pull, end)
    on_x0 = basis.get_dofs(lambda x: np.isclose(x[0], 0.0))
    on_y0 = basis.get_dofs(lambda x: np.isclose(x[1], 0.0))
    fixed = np.concatenate([on_x0.nodal["u^1"], on_x0.facet["u^1"], on_y0.nodal["u^2"], on_y0.facet["u^2"]])
    u = solve(*condense(stiffness, load, D=fixed))

    on_hole = np.isclose(np.hypot(mesh.p[0], mesh.p[1]), radius, atol=1e-9)
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    peak = 0.0
    for k in range(3):  # the gradient of every element at its k-th vertex
        cells = np.nonzero(on_hole[mesh.t[k]])[0]
        vertex = CellBasis(mesh, element, elements=cells, quadrature=(corners[k][:, None], np.array([0.5])))
        grad = vertex.interpolate(u).grad[:, :, :, 0]  # (2, 2, cells)
        exx, eyy, exy = grad[0, 0], grad[1, 1], 0.5 * (grad[0, 1] + grad[1, 0])
        sxx = modulus / (1 - poisson ** 2) * (exx + poisson * eyy)
        syy = modulus / (1 - poisson ** 2) * (eyy + poisson * exx)
        sxy = modulus / (1 + poisson) * exy
        peak = max(peak, float(np.max(np.sqrt(sxx ** 2 - sxx * syy + syy ** 2 + 3 * sxy ** 2))))
    return peak


def test_net_section_model_is_conservative_against_fe():
    """A 10 mm wide, 3 mm thick link plate (E 2800 MPa, nu 0.35) with a central 3 mm hole (d/w = 0.3),
    60 mm long, pulled by a uniform 10 MPa end traction: linear plane-stress FE (scikit-fem, P2 triangles,
    quarter model) against ``net_section_stress`` on the section cut through the hole with the open-hole Kt.

    Measured: FE peak von Mises at the hole 33.79 MPa (m = 12, 1.5k elements) and 33.75 MPa (m = 24, 5.3k
    elements; the two meshes differ by 0.11 %), i.e. Kt = 2.363 on the net section; closed form 34.35 MPa,
    1.018 x the FE peak (Peterson's fit alone is 0.2 % below the FE, the model's 2 % margin covers it).
    The test takes under 1 s.
    """
    pytest.importorskip("skfem")
    width, length, hole_d, t, traction = 10.0, 60.0, 3.0, 3.0, 10.0
    coarse = plate_hole_peak_von_mises(width, length, hole_d, 2800.0, 0.35, traction, 12)
    fine = plate_hole_peak_von_mises(width, length, hole_d, 2800.0, 0.35, traction, 24)
    assert abs(coarse - fine) / fine < 0.01  # mesh-converged to better than 1 %

    plate = rectangle(-length / 2, -width / 2, length / 2, width / 2)
    section = cut_section([plate, hole_ring((0.0, 0.0), hole_d)], [0.0, 0.0], [0.0, 1.0], t)
    kt = hole_stress_concentration(hole_d, width, False)
    closed = net_section_stress(traction * width * t, 0.0, section, kt)
    ratio = closed / fine
    print(f"\nFE peak von Mises {coarse:.3f} / {fine:.3f} MPa (m = 12 / 24), closed form {closed:.3f} MPa, "
          f"ratio {ratio:.4f}")
    assert 1.0 <= ratio <= 1.5
