"""``gears.module_mm = "auto"`` (fabricate/gears/auto.py): the smallest standard module the process makes and the
load allows.

The choice is checked against an independent scan written here: every module of the two DIN 780-1 series (typed
in again below, not imported), each cut with its module fixed, judged by the printability check's tip-land test,
the pair's own undercut / pointed-teeth / contact-ratio checks and the strength check's gear findings at the
template's load (statics solved here); the smallest that passes must be the one chosen, exactly (the candidates
are discrete, so the only tolerance is the printability check's 1e-9 mm on the tip land).

The default finger (seed 000) is the mechanism throughout: its sector pair on pitch curves the synthesis fixes.
"""

from __future__ import annotations

import dataclasses
import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from fabricate.checks.printability import check_printability
from fabricate.design import design_from_text, load_design
from fabricate.errors import SpecError
from fabricate.gears import build_gear_pairs, make_gear_pair
from fabricate.gears.auto import ModuleLimits, choose_module, module_limits, rack_tip_land_mm, standard_modules
from fabricate.gears.rack import rack_fit
from fabricate.gears.spec import GearSpec, parse_gear_spec
from fabricate.pipeline import _quiet, _synthesis_stage, run_build
from fabricate.process import ProcessOverride, process_override
from fabricate.strength.check import design_loads
from fabricate.strength.features import gear_findings
from fabricate.strength.statics import solve_statics
from fabricate.table import Table
from fabricate.templates import TEMPLATE_DIR

FINGER = TEMPLATE_DIR / "finger_five_bar_ncg.toml"
#: DIN 780-1 series 1 and 2 up to 2 mm, typed from the standard's table (the finger's pitch curves hold no more).
DIN_780_TO_2MM = sorted([0.05, 0.06, 0.08, 0.1, 0.12, 0.16, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.25,
                         1.5, 2.0, 0.055, 0.07, 0.09, 0.11, 0.14, 0.18, 0.22, 0.28, 0.35, 0.45, 0.55, 0.65, 0.75,
                         0.85, 0.95, 1.125, 1.375, 1.75])


def finger_text(module: str) -> str:
    """The default finger's template with its ``[gears] module_mm`` line set to ``module`` (TOML text)."""
    text = FINGER.read_text(encoding="utf-8")
    out, count = re.subn(r"(?m)^module_mm = .*$", f"module_mm = {module}", text)
    assert count == 1
    return out


def sla_with(**fields: float) -> ProcessOverride:
    """The shipped SLA profile with some top-level fields replaced (an FDM stand-in, a thicker plate...)."""
    text = (TEMPLATE_DIR / "process_sla.toml").read_text(encoding="utf-8")
    for key, value in fields.items():
        text, count = re.subn(rf"(?m)^{key} = \S+", f"{key} = {value}", text)
        assert count == 1
    return ProcessOverride(text=text, source="sla-variant.toml")


@pytest.fixture(scope="module")
def finger():
    """The default finger with module auto: design, mechanism, motion and hints (synthesised once)."""
    design = design_from_text(finger_text('"auto"'), FINGER)
    result, _, motion, _ = _synthesis_stage(design, _quiet, "build")
    return SimpleNamespace(design=design, mechanism=result.mechanism, motion=motion, hints=result.parts)


def with_process(finger, override: ProcessOverride):
    return design_from_text(finger_text('"auto"'), FINGER, override)


def at_angle(gears: GearSpec, degrees: float) -> GearSpec:
    """``gears`` cut at a fixed pressure angle, with the default dedendum and root fillet cut down to what the rack's
    tooth space holds there (:func:`fabricate.gears.rack.rack_fit`)."""
    dedendum = min(1.25, rack_fit(math.radians(degrees), 1.25)[0])
    fillet = min(0.38, rack_fit(math.radians(degrees), dedendum)[1])
    return dataclasses.replace(gears, pressure_angle_deg=degrees, dedendum=dedendum, root_fillet=fillet,
                               pressure_angle_candidates=())


def independent_choice(finger, design, degrees: float | None = None) -> float | None:
    """Smallest module of :data:`DIN_780_TO_2MM` that the process can make and the load allows, or None (up to
    the first undercut one); at ``degrees`` when given, else at the design's own pressure angle."""
    if degrees is not None:
        design = dataclasses.replace(design, gears=at_angle(design.gears, degrees))
    loads = design_loads(design, finger.mechanism, finger.motion, finger.hints)
    statics = solve_statics(finger.mechanism, finger.motion, loads.forces, loads.torques, loads.efforts,
                            loads.reaction)
    material = design.process.part_material()
    required = design.checks.min_safety_factor
    (coupling,) = finger.mechanism.gears
    carrier = finger.mechanism.body(coupling.carrier)
    centre = float(np.hypot(*(carrier.point(coupling.axis_b) - carrier.point(coupling.axis_a))))
    for module in DIN_780_TO_2MM:
        spec = dataclasses.replace(design.gears, module_mm=module, compare_methods=False)
        try:
            pair = make_gear_pair(coupling.law, centre, coupling.working_range, spec, closed=False,
                                  name=coupling.name, coupling=coupling.name, carrier=coupling.carrier,
                                  body_a=coupling.gear_a, body_b=coupling.gear_b, run_mesh_check=False)
        except SpecError:
            continue
        if pair.checks["undercut"]:
            return None  # the undercut limit grows with the module, the pitch curves stay: so are all larger ones
        if pair.failures():  # pointed teeth, contact ratio
            continue
        if check_printability([], design.process, [pair]).failures:  # the tip land against min_feature_mm
            continue
        # the strength check's own findings, on stand-ins for the two gear parts at the process thickness
        parts = [SimpleNamespace(name=body, body=body, gear=pair.name, thickness_mm=design.process.thickness_mm)
                 for body in (pair.body_a, pair.body_b)]
        found = gear_findings(pair, statics.gear_torques[coupling.name], finger.mechanism, finger.motion, parts,
                              material)
        assert len(found) == 3  # Lewis on both gears, Hertz
        if all(f.safety_factor >= required for f in found):
            return module
    return None


def auto_pair(finger, design):
    limits = module_limits(design, finger.mechanism, finger.motion, finger.hints)
    (pair,) = build_gear_pairs(finger.mechanism, design.gears, design.process.chord_tolerance_mm, lambda: limits)
    return pair


def test_standard_modules_are_both_din_780_series_in_order():
    got = standard_modules()
    assert list(got) == sorted(set(got))  # ascending, no value twice
    assert [m for m in got if m <= 2.0] == DIN_780_TO_2MM
    assert got[0] == 0.05 and got[-1] == 50.0  # the spec's range of module_mm


@pytest.mark.parametrize(("fields", "expected"), [
    ({}, 0.45),  # the shipped SLA profile (0.3 mm features) with the template's 6 mm plates
    ({"min_feature_mm": 0.4, "thickness_mm": 6.0}, 0.65),  # an FDM-like 0.4 mm line, plates kept at 6 mm
])
def test_auto_module_is_the_smallest_an_independent_scan_accepts(finger, fields, expected):
    design = finger.design if not fields else with_process(finger, sla_with(**fields))
    pair = auto_pair(finger, design)
    assert independent_choice(finger, design) == expected
    assert pair.module == pytest.approx(expected, abs=1e-12)
    choice = pair.module_choice
    assert choice["found"] and choice["chosen_module_mm"] == expected
    assert not pair.failures()
    assert pair.checks["tip_land_min_mm"] >= design.process.min_feature_mm - 1e-9
    # every smaller standard module is listed as rejected, with its reason
    rejected = [r["module_mm"] for r in choice["rejected"]]
    assert rejected == [m for m in DIN_780_TO_2MM if m < expected]
    assert all(r["reasons"] for r in choice["rejected"])
    if fields:
        return
    # the chosen pair is the one a template fixing that module gets, mesh check included
    fixed = design_from_text(finger_text(str(expected)), FINGER, design.process_override)
    (same,) = build_gear_pairs(finger.mechanism, fixed.gears, fixed.process.chord_tolerance_mm)
    assert np.array_equal(same.outline_a, pair.outline_a) and np.array_equal(same.outline_b, pair.outline_b)
    assert same.mesh is not None and pair.mesh is not None
    assert same.report() == {k: v for k, v in pair.report().items() if k != "module_choice"}


def test_rack_tip_bounds_the_cut_tip_land_of_the_convex_finger(finger):
    # the shortcut that rejects a module without cutting it must never reject one the cut would accept
    (coupling,) = finger.mechanism.gears
    carrier = finger.mechanism.body(coupling.carrier)
    centre = float(np.hypot(*(carrier.point(coupling.axis_b) - carrier.point(coupling.axis_a))))
    for module in (0.2, 0.3, 0.45, 0.6, 0.75):
        spec = dataclasses.replace(finger.design.gears, module_mm=module, compare_methods=False)
        pair = make_gear_pair(coupling.law, centre, coupling.working_range, spec, closed=False, run_mesh_check=False)
        assert pair.checks["convex"]
        assert pair.checks["tip_land_min_mm"] < rack_tip_land_mm(module, spec)


def laser_3mm_at_20_deg(finger):
    """The finger for the laser on its 3 mm sheet (the template's 6 mm left out) at a fixed 20 deg."""
    text = re.sub(r"(?m)^thickness_mm = .*$", "", finger_text('"auto"'))
    design = design_from_text(text, FINGER, process_override("laser"))
    assert design.process.thickness_mm == 3.0 and design.gears.module_mm is None
    return dataclasses.replace(design, gears=at_angle(design.gears, 20.0))


def test_laser_finds_no_module_at_20_deg_on_3_mm_and_names_why(finger):
    design = laser_3mm_at_20_deg(finger)
    assert independent_choice(finger, design) is None
    pair = auto_pair(finger, design)
    choice = pair.module_choice
    assert not choice["found"] and choice["chosen_module_mm"] is None
    assert "pressure_angle" not in choice  # a fixed angle: the choice reads as before
    (words,) = [f for f in pair.failures() if f.startswith("module auto")]
    # the window between the 0.5 mm tip land and the undercut limit holds no standard module, and the contact
    # stress on 3 mm acrylic is too high at any module
    assert "m = 0.75: tip land" in words and "m = 0.8: undercut" in words and "Hertz contact" in words
    # built with the largest module short only of the process's and the load's limits
    assert pair.module == 0.75 and not pair.checks["undercut"]


def test_scan_cuts_only_modules_between_the_rack_tip_and_the_undercut(finger):
    """The bound on the search's time: on the convex finger no module whose rack tooth is too narrow at the tip is
    cut, and nothing past the first undercut one is tried (with the laser's 0.5 mm features: 0.6 ... 0.8)."""
    design = laser_3mm_at_20_deg(finger)
    limits = module_limits(design, finger.mechanism, finger.motion, finger.hints)
    (coupling,) = finger.mechanism.gears
    carrier = finger.mechanism.body(coupling.carrier)
    centre = float(np.hypot(*(carrier.point(coupling.axis_b) - carrier.point(coupling.axis_a))))
    cut: list[float] = []

    def make(spec):
        cut.append(spec.module_mm)
        return make_gear_pair(coupling.law, centre, coupling.working_range, spec, closed=False, name=coupling.name,
                              coupling=coupling.name, carrier=coupling.carrier, body_a=coupling.gear_a,
                              body_b=coupling.gear_b, run_mesh_check=False)

    pair, choice = choose_module(make, dataclasses.replace(design.gears, compare_methods=False), limits, convex=True)
    assert cut == [m for m in DIN_780_TO_2MM if rack_tip_land_mm(m, design.gears) >= 0.5 and m <= 0.8]
    assert cut == [0.6, 0.65, 0.7, 0.75, 0.8]
    assert [r["module_mm"] for r in choice["rejected"]] == [m for m in DIN_780_TO_2MM if m <= 0.8]
    assert pair.module == 0.75


def measured_tip_land_mm(outline: np.ndarray, pitch: np.ndarray, addendum_mm: float) -> float:
    """The narrowest tooth tip on a cut outline, measured: runs of outline vertices at the addendum from the pitch
    curve (within 2 um), each run's length along the outline."""
    import shapely

    height = shapely.distance(shapely.LineString(pitch), shapely.points(outline))
    tip = np.abs(height - addendum_mm) <= 0.002
    step = np.hypot(*(np.roll(outline, -1, axis=0) - outline).T)
    lands, run = [], 0.0
    start = int(np.argmin(tip))  # a vertex off every tip: runs do not wrap
    for k in range(len(outline)):
        i = (start + k) % len(outline)
        if tip[i] and tip[(i + 1) % len(outline)]:
            run += float(step[i])
        elif run:
            lands.append(run)
            run = 0.0
    return min(lands)


@pytest.mark.slow
def test_laser_default_finger_takes_the_first_standard_angle_a_module_passes_at(finger):
    """``--process laser`` on the shipped finger (which fixes 0.5 mm and 20 deg for its SLA figures): the teeth are
    sized again for the laser, on the template's 6 mm plates (a stock the laser profile names). At 20 deg no standard
    module passes (tip land < 0.5 mm up to 0.75, undercut from 0.8); at 22.5 deg the independent scan's first is
    0.95 mm, and its tip land, measured on the cut outline, is the process's 0.5 mm."""
    design = load_design("finger_five_bar_ncg", "laser")
    assert design.gears.module_mm is None and design.process.thickness_mm == 6.0
    assert [a for a, _, _ in design.gears.pressure_angle_candidates] == [20.0, 22.5, 25.0]
    assert independent_choice(finger, design, 20.0) is None
    assert independent_choice(finger, design, 22.5) == 0.95
    pair = auto_pair(finger, design)
    choice = pair.module_choice
    assert choice["found"] and choice["chosen_module_mm"] == 0.95 and choice["pressure_angle_deg"] == 22.5
    assert pair.module == 0.95 and pair.spec.pressure_angle_deg == 22.5 and not pair.failures()
    assert choice["pressure_angle"]["tried_deg"] == [20.0, 22.5]
    assert {r["pressure_angle_deg"] for r in choice["rejected"]} == {20.0, 22.5}
    assert [r["module_mm"] for r in choice["rejected"] if r["pressure_angle_deg"] == 22.5] == [
        m for m in DIN_780_TO_2MM if m < 0.95]
    # the 22.5 deg rack's root fillet is cut down to fit its tooth space (0.38 m does not)
    assert pair.spec.root_fillet == pytest.approx(at_angle(design.gears, 22.5).root_fillet, rel=1e-12)
    assert pair.spec.root_fillet < 0.38
    lands = [measured_tip_land_mm(o, pc, pair.spec.addendum * pair.module)
             for o, pc in ((pair.outline_a, pair.pitch_a), (pair.outline_b, pair.pitch_b))]
    assert min(lands) >= design.process.min_feature_mm
    assert min(lands) == pytest.approx(pair.checks["tip_land_min_mm"], abs=1e-3)


@pytest.mark.slow
def test_fdm_default_finger_names_the_contact_no_module_or_angle_relieves(finger):
    """``--process fdm`` on the shipped finger: PLA's contact on the template's 6 mm plates keeps no safety factor 2
    at any module or standard angle (sigma_H^2 ~ 1 / (b sin 2 alpha)); the failure says so once, with the
    face width that would, and the pair is built at the angle where only the contact fails, least."""
    design = load_design("finger_five_bar_ncg", "fdm")
    assert design.gears.module_mm is None and design.process.thickness_mm == 6.0
    assert all(independent_choice(finger, design, a) is None for a in (20.0, 22.5, 25.0))
    pair = auto_pair(finger, design)
    choice = pair.module_choice
    assert not choice["found"] and choice["pressure_angle"]["tried_deg"] == [20.0, 22.5, 25.0]
    (words,) = [f for f in pair.failures() if f.startswith("module auto")]
    assert words.count("MPa: safety factor") == 1 and "fails at every module and angle" in words
    found = re.search(r"least at 25 deg: Hertz contact ([\d.]+) MPa: safety factor ([\d.]+) < 2 on 6 mm plates "
                      r"\(([\d.]+) mm would keep 2\)", words)
    assert found, words
    stress, sf, face = (float(g) for g in found.groups())
    pla = design.process.part_material()
    assert sf == pytest.approx(pla.compressive_MPa / stress, abs=0.006)
    assert face == pytest.approx(6.0 * (2.0 / (pla.compressive_MPa / stress)) ** 2, rel=0.01)
    # built where only the contact fails (22.5 deg: at 25 deg the tip land closes the window), tip land kept
    assert choice["pressure_angle_deg"] == 22.5 and pair.spec.pressure_angle_deg == 22.5
    assert pair.checks["tip_land_min_mm"] >= design.process.min_feature_mm - 1e-9 and not pair.checks["undercut"]


def test_closed_pair_auto_module_gives_whole_teeth_and_matches_a_scan_by_tooth_count():
    """A closed 2:1 pair on fixed pitch circles (r_a 5 mm, r_b 10 mm): each standard module m becomes the whole
    tooth count nearest 2 pi r_a / (pi m) and the module those teeth give; the choice must be what cutting those
    tooth counts (given as ``teeth``, the other path to a closed pair's module) accepts first."""
    from tests.gears.test_pair import closed_mechanism

    mech = closed_mechanism()
    (coupling,) = mech.gears
    limits = ModuleLimits(min_feature_mm=0.3)  # no load: geometry and the process only
    (pair,) = build_gear_pairs(mech, GearSpec(compare_methods=False), 0.005, lambda: limits)
    expected = None
    for module in DIN_780_TO_2MM:
        z_a = int(round(10.0 / module))
        if z_a < 8:
            break  # min_teeth
        spec = GearSpec(teeth=(z_a, 2 * z_a), compare_methods=False)
        try:
            cut = make_gear_pair(coupling.law, 15.0, coupling.working_range, spec, closed=True, run_mesh_check=False)
        except SpecError:  # over the tooth bound
            continue
        if not cut.failures() and cut.checks["tip_land_min_mm"] >= 0.3 - 1e-9:
            expected = (module, cut)
            break
    assert expected is not None
    module, cut = expected
    assert pair.teeth == cut.teeth and pair.teeth[1] == 2 * pair.teeth[0]
    assert pair.module == pytest.approx(10.0 / pair.teeth[0], rel=1e-9) == pytest.approx(cut.module, rel=1e-12)
    choice = pair.module_choice
    assert choice["chosen_module_mm"] == module and choice["built_module_mm"] == pytest.approx(pair.module, abs=1e-6)
    assert choice["criteria"]["strength"] is None


def test_module_auto_is_parsed_like_an_absent_module():
    assert parse_gear_spec(Table({"module_mm": "auto"}, "gears")).module_mm is None
    assert parse_gear_spec(Table({}, "gears")).module_mm is None
    with pytest.raises(SpecError, match='module in mm or "auto"'):
        parse_gear_spec(Table({"module_mm": "big"}, "gears"))


@pytest.mark.slow
def test_fixed_module_the_process_cannot_make_fails_the_build_naming_the_tip_land():
    outcome = run_build(design_from_text(finger_text("0.3"), FINGER))
    assert outcome.exit_code == 1
    failures = outcome.report["checks"]["failures"]
    assert any("tooth tip land" in f and "0.205" in f for f in failures), failures
    assert "module_choice" not in outcome.report["gears"][0]  # a fixed module is the template's, not chosen


@pytest.mark.slow
@pytest.mark.parametrize(("process", "code"), [("laser", None), ("fdm", 1)])
def test_process_builds_of_the_default_finger(process, code, shipped_build):
    """The whole build: the laser's gears and their strength pass (its other checks are the parts'); the FDM build
    exits 1 naming the contact no module or angle relieves."""
    outcome = shipped_build("finger_five_bar_ncg", process)
    failures = outcome.report["checks"]["failures"]
    gear = outcome.report["gears"][0]
    if code is None:
        assert outcome.exit_code in (0, 1)
        assert not [f for f in failures if "gear" in f or "tooth" in f or "module" in f], failures
        assert gear["module_choice"]["found"] and gear["pressure_angle_deg"] == 22.5
    else:
        assert outcome.exit_code == 1
        assert any("module auto: no standard module" in f and "at pressure angle 20, 22.5 or 25 deg" in f
                   for f in failures), failures
        assert gear["module_choice"]["found"] is False


@pytest.mark.parametrize(("dedendum", "angles"), [(None, [20.0, 22.5, 25.0]), (1.7, [20.0, 22.5]), (1.9, [20.0])])
def test_auto_pressure_angle_candidates_keep_what_the_template_gives(dedendum, angles):
    """An automatic angle is tried at the standard 20, 22.5, 25 deg, each with the default root fillet cut to fit;
    an angle whose rack cannot hold a dedendum the template gives is left out (rack_fit's limit there)."""
    table = {"pressure_angle_deg": "auto"} if dedendum is None else {"dedendum": dedendum}
    spec = parse_gear_spec(Table(table, "gears"))
    assert [a for a, _, _ in spec.pressure_angle_candidates] == angles
    for degrees, cut_dedendum, fillet in spec.pressure_angle_candidates:
        assert cut_dedendum == (dedendum or 1.25) <= rack_fit(math.radians(degrees), cut_dedendum)[0]
        assert fillet == pytest.approx(min(0.38, rack_fit(math.radians(degrees), cut_dedendum)[1]), rel=1e-12)
    assert spec.pressure_angle_deg == 20.0  # the preferred one, until a module is chosen


def test_a_fixed_pressure_angle_or_module_is_no_angle_choice():
    assert parse_gear_spec(Table({"pressure_angle_deg": 20.0}, "gears")).pressure_angle_candidates == ()
    assert parse_gear_spec(Table({"module_mm": 0.5}, "gears")).pressure_angle_candidates == ()
    assert parse_gear_spec(Table({"teeth": [20, 40]}, "gears")).pressure_angle_candidates == ()
    with pytest.raises(SpecError, match='"auto" is chosen together with the module') as info:
        parse_gear_spec(Table({"module_mm": 0.5, "pressure_angle_deg": "auto"}, "gears"))
    assert info.value.path == "gears.pressure_angle_deg"
    with pytest.raises(SpecError, match='an angle in degrees or "auto"'):
        parse_gear_spec(Table({"pressure_angle_deg": "steep"}, "gears"))


def test_process_sizes_the_teeth_again_unless_teeth_fix_the_module():
    """--process re-sizes teeth the template sized for its own process (module and angle become automatic); a module
    that with ``teeth`` sets a closed pair's centre distance is the design's and stays; --printer alone changes no
    process and keeps both."""
    own = load_design("finger_five_bar_ncg")
    assert (own.gears.module_mm, own.gears.pressure_angle_candidates) == (0.5, ())
    for process in ("laser", "fdm", "sla"):
        gears = load_design("finger_five_bar_ncg", process).gears
        assert gears.module_mm is None and len(gears.pressure_angle_candidates) == 3
    assert load_design("finger_five_bar_ncg", printer="elegoo_saturn_3").gears.module_mm == 0.5
    elliptic = load_design("gear_pair_elliptic", "laser").gears
    assert (elliptic.module_mm, elliptic.teeth, elliptic.pressure_angle_candidates) == (1.0, (30, 30), ())
