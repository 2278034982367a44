"""Torsion springs in their pin's stack (``fabricate/parts/springs.py``).

The rate and the stress are recomputed here from the chosen wire, coil and turns with the textbook
formulas and constants written out again (not the catalogue's functions); the anchors are measured on
the parts' outlines and over the motion with shapely; the shipped springs are read from real builds.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely

from fabricate.hints import SpringHint
from fabricate.parts.build import build_parts
from fabricate.parts.spec import PartsSpec
from fabricate.parts.spring_rows import spring_bom_rows, spring_failures, with_spring_rows
from fabricate.parts.springs import place_springs
from tests.conftest import make_four_bar

#: Music wire A228 modulus by diameter (Shigley 9th ed. Table 10-5), written out again: d < 0.032 in
#: 203.4 GPa, 0.033-0.063 in 200 GPa, above 196.5 GPa.
INCH = 25.4


def modulus(d_mm: float) -> float:
    d_in = d_mm / INCH
    return 203_400.0 if d_in <= 0.0325 else (200_000.0 if d_in <= 0.0635 else 196_500.0)


def rate_from(d: float, mean_d: float, turns: float) -> float:
    """k = E d^4 / (10.8 D N) per turn, in N·mm per degree."""
    return modulus(d) * d**4 / (10.8 * mean_d * turns) / 360.0


def stress_from(d: float, mean_d: float, torque: float) -> float:
    """sigma = K_B 32 M / (pi d^3), K_B = (4C^2 - C - 1) / (4C (C - 1))."""
    c = mean_d / d
    return (4 * c * c - c - 1) / (4 * c * (c - 1)) * 32.0 * torque / (math.pi * d**3)


def four_bar_parts(sla_process):
    mech = make_four_bar()
    motion = mech.sweep(41)
    design = SimpleNamespace(name="t", process=sla_process, parts=PartsSpec(),
                             gears=SimpleNamespace(hub_diameter_mm=None))
    return mech, motion, build_parts(design, mech, motion, [])


def test_spring_rate_stress_and_place_recomputed(sla_process):
    mech, motion, partset = four_bar_parts(sla_process)
    hint = SpringHint("B", rate_Nmm_per_deg=0.2, preload_deg=30.0, legs_mm=12.0, note="return")
    springs, parts, pins = place_springs([hint], mech, motion, partset.parts, partset.pins, sla_process)
    (sp,) = springs
    s = sp.spring
    # the rate the wire, coil and turns give is the rate asked for (the turns are not rounded)
    assert rate_from(s.wire_d_mm, s.mean_d_mm, s.active_turns) == pytest.approx(0.2, rel=1e-9)
    # the deflection over the motion: preload plus the joint's travel (coupler against rocker)
    rel = np.degrees(motion.relative_angle("rocker", "coupler"))
    travel = abs(rel - rel[0]).max()
    assert sp.deflection_deg[1] == pytest.approx(30.0 + travel, rel=1e-9)
    assert stress_from(s.wire_d_mm, s.mean_d_mm, 0.2 * (30.0 + travel)) == pytest.approx(s.stress_mpa, rel=1e-9)
    assert s.stress_mpa <= s.allowable_mpa and sp.passed and not spring_failures(springs)
    # wound up, the coil still clears its pin (the catalogue's 10 % arbor clearance)
    assert s.inner_d_wound_mm >= s.pin_diameter_mm / 0.9 - 1e-9
    # the pin grows by the coil's wound body, which sits on the stack's end face
    old = next(p for p in partset.pins if p.joint == "B")
    new = next(p for p in pins if p.joint == "B")
    assert new.length_mm == pytest.approx(old.length_mm + s.body_length_wound_mm, rel=1e-12)
    stack_top, stack_bottom = old.z_mm + old.length_mm, old.z_mm
    assert sp.z_mm == pytest.approx((stack_top, stack_top + s.body_length_wound_mm)) if sp.side == "top" else \
        sp.z_mm == pytest.approx((stack_bottom - s.body_length_wound_mm, stack_bottom))
    # one anchor hole in each body's plate, a leg's length from the pin, with the process's wall round it
    for body, anchor in ((sp.near_body, sp.near_anchor), (sp.far_body, sp.far_anchor)):
        part = next(p for p in parts if p.body == body and p.role != "spacer")
        axis = next(h.centre for h in part.holes if h.joint == "B")
        hole = next(h for h in part.holes if h.joint == "spring_B")
        assert np.allclose(hole.centre, anchor)
        assert math.hypot(*(hole.centre - axis)) == pytest.approx(12.0, abs=1e-9)
        assert hole.diameter_mm == pytest.approx(s.wire_d_mm + 2 * sla_process.running_clearance_mm
                                                 + sla_process.hole_compensation_mm)
        rings = part.polygons(0.01)
        material = shapely.Polygon(rings[0], [r for r in rings[1:] if not np.allclose(r.mean(axis=0), anchor)])
        disc = shapely.Point(*anchor).buffer(hole.diameter_mm / 2 + sla_process.min_wall_mm - 0.02)
        assert material.contains(disc)
    # the far leg runs past the near plate: it keeps the running clearance from it at every pose
    near = next(p for p in parts if p.body == sp.near_body and p.role != "spacer")
    rings = near.polygons(0.01)
    near_poly = shapely.Polygon(rings[0], rings[1:])
    for i in range(len(motion.inputs)):
        pf, pn = motion.pose(sp.far_body)[i], motion.pose(sp.near_body)[i]
        c, s_ = math.cos(pf[2]), math.sin(pf[2])
        world = pf[:2] + np.array([c * sp.far_anchor[0] - s_ * sp.far_anchor[1],
                                   s_ * sp.far_anchor[0] + c * sp.far_anchor[1]])
        d = world - pn[:2]
        c, s_ = math.cos(pn[2]), math.sin(pn[2])
        local = np.array([c * d[0] + s_ * d[1], -s_ * d[0] + c * d[1]])
        gap = near_poly.distance(shapely.Point(*local)) - 0.5 * s.wire_d_mm
        assert gap >= sla_process.running_clearance_mm - 0.02
    # the BOM row names it as a spring maker is asked for it, and replaces the rate-only row
    (row,) = spring_bom_rows(springs, copies=2)
    assert row["qty"] == 2 and row["item"] == sp.designation and row["joints"] == ["B"]
    assert f"Ø{s.wire_d_mm:.2f}" in row["item"] and f"{s.active_turns:.2f} turns" in row["item"]
    assert row["item"].endswith(sp.hand) and sp.hand in ("LH", "RH")
    bom = with_spring_rows([{"item": "x", "kind": "pin", "qty": 2}, {"item": "torsion spring at B", "kind": "spring",
                                                                      "qty": 2}], springs, copies=2)
    assert [r["item"] for r in bom] == ["x", sp.designation]


def test_a_spring_no_wire_can_make_is_a_failure_naming_it(sla_process):
    mech, motion, partset = four_bar_parts(sla_process)
    hint = SpringHint("B", rate_Nmm_per_deg=40.0, preload_deg=180.0, legs_mm=12.0)
    springs, _, _ = place_springs([hint], mech, motion, partset.parts, partset.pins, sla_process)
    (sp,) = springs
    assert not sp.passed and sp.spring.stress_mpa > sp.spring.allowable_mpa
    (failure,) = spring_failures(springs)
    assert failure.startswith("spring at B") and "over its allowable" in failure
    # the stand-in is still the rate asked for, from the thickest wire
    assert rate_from(sp.spring.wire_d_mm, sp.spring.mean_d_mm, sp.spring.active_turns) == pytest.approx(40.0,
                                                                                                          rel=1e-9)


def test_a_spring_the_motion_turns_back_past_free_is_a_failure(sla_process):
    mech, motion, partset = four_bar_parts(sla_process)
    rel = np.degrees(motion.relative_angle("rocker", "coupler"))  # the crank turns round: B swings both ways
    back = float(rel[0] - rel.min())
    springs, _, _ = place_springs([SpringHint("B", 0.2, 10.0, 12.0)], mech, motion, partset.parts, partset.pins,
                                  sla_process)
    (sp,) = springs
    assert sp.deflection_deg[0] == pytest.approx(10.0 - back, rel=1e-9) and sp.deflection_deg[0] < 0
    (failure,) = spring_failures(springs)
    assert failure.startswith("spring at B") and f"{back - 10.0:.1f}° back past free" in failure


def test_no_spring_where_the_rate_is_zero(sla_process):
    mech, motion, partset = four_bar_parts(sla_process)
    springs, parts, pins = place_springs([SpringHint("B", 0.0)], mech, motion, partset.parts, partset.pins,
                                         sla_process)
    assert springs == () and list(pins) == list(partset.pins) and list(parts) == list(partset.parts)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["gripper_compliant", "finger_underactuated"])
def test_shipped_springs_within_allowable_and_in_their_pin_stack(shipped_build, name):
    outcome = shipped_build(name)
    springs = outcome.report["springs"]
    hinted = [s for s in outcome.partset.hints.springs if s.rate_Nmm_per_deg > 0]
    assert len(springs) == len(hinted) > 0
    bom = {r["item"]: r for r in outcome.report["bom"] if r["kind"] == "spring"}
    stacks = {s["pin"]: s for s in outcome.report["assembly"]["pins"]}
    for spring in springs:
        assert spring["stress_MPa"] <= spring["allowable_MPa"] and spring["passed"]
        assert stress_from(spring["wire_d_mm"], spring["mean_d_mm"], spring["max_torque_Nmm"]) == pytest.approx(
            spring["stress_MPa"], rel=1e-9)
        rate = next(h.rate_Nmm_per_deg for h in hinted if h.joint == spring["joint"])
        assert rate_from(spring["wire_d_mm"], spring["mean_d_mm"], spring["active_turns"]) == pytest.approx(
            rate, rel=1e-9)
        assert spring["designation"] in bom
        stack = stacks[spring["pin"]]
        items = [i for i in stack["stack"] if i["kind"] == "spring"]
        assert [i["item"] for i in items] == [spring["designation"]]
        # on the pin within its length, or (where the pin cannot be lengthened) on its printed arbor, listed
        # in the same stack over the same span, just beyond the plate the coil sits on
        z0, z1 = items[0]["z_mm"]
        arbors = [i for i in stack["stack"] if i["item"] == f"spring_arbor_{spring['joint']}"]
        if arbors:
            assert arbors[0]["z_mm"] == pytest.approx([z0, z1]) and arbors[0]["kind"] == "part"
            assert any(i["kind"] == "part" and (abs(i["z_mm"][0] - z1) < 1e-9 or abs(i["z_mm"][1] - z0) < 1e-9)
                       for i in stack["stack"] if i is not arbors[0])
        else:
            assert stack["z_mm"] - 1e-9 <= z0 < z1 <= stack["z_mm"] + stack["length_mm"] + 1e-9
        # the coil and its legs are solids of the interference proof, and keep their clearances
        pairs = [p for p in outcome.report["interference"]["pairs"]
                 if spring["joint"] in (p["a"].removeprefix("spring_").split("_leg")[0],
                                        p["b"].removeprefix("spring_").split("_leg")[0])]
        names = {n for p in pairs for n in (p["a"], p["b"])}
        assert {f"spring_{spring['joint']}", f"spring_{spring['joint']}_leg_far_axial"} <= names
        assert all(p["ok"] for p in pairs)
    assert not [f for f in outcome.report["checks"]["failures"] if "spring at" in f]


def _world(pose: np.ndarray, p: np.ndarray) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[:2] + np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])


def _leg_angle(sp, motion, i: int) -> float:
    """The far anchor's direction from the pin less the near anchor's, in the world at pose ``i`` (degrees)."""
    pf, pn = motion.pose(sp.far_body)[i], motion.pose(sp.near_body)[i]
    far = _world(pf, sp.far_anchor) - _world(pf, sp.far_axis)
    near = _world(pn, sp.near_anchor) - _world(pn, sp.near_axis)
    return math.degrees(math.atan2(far[1], far[0]) - math.atan2(near[1], near[0]))


@pytest.mark.parametrize(("joint", "body", "reference"), [("B", "rocker", "coupler"), ("D", "rocker", "ground")])
def test_the_hand_winds_up_and_the_free_angle_is_the_assembled_less_the_preload(sla_process, joint, body,
                                                                                reference):
    """Recomputed from the anchors over the motion: the far anchor's angle round the pin against the near one
    moves by the joint's travel, the way the deflection grows (s); the upper leg must turn counter-clockwise
    (seen from above) against the lower one for a right-hand coil to wind up."""
    mech, motion, partset = four_bar_parts(sla_process)
    springs, _, _ = place_springs([SpringHint(joint, 0.2, 30.0, 12.0)], mech, motion, partset.parts,
                                  partset.pins, sla_process)
    (sp,) = springs
    rel = np.degrees(motion.relative_angle(body, reference))
    i = int(np.argmax(abs(rel - rel[0])))
    turn = (_leg_angle(sp, motion, i) - _leg_angle(sp, motion, 0) + 180.0) % 360.0 - 180.0
    assert abs(turn) == pytest.approx(abs(rel[i] - rel[0]), abs=1e-6)  # the legs turn by the joint's travel
    s = math.copysign(1.0, turn)
    upper = s if sp.side == "top" else -s  # the far leg leaves the coil's far end
    assert sp.hand == ("RH" if upper > 0 else "LH")
    free = (_leg_angle(sp, motion, 0) - s * 30.0) % 360.0
    assert min(abs(free - sp.free_angle_deg), 360.0 - abs(free - sp.free_angle_deg)) == pytest.approx(0.0, abs=1e-6)


def test_the_strength_check_fails_a_spring_over_its_allowable_by_name(sla_process):
    from fabricate.strength.check import run_strength

    mech, motion, partset = four_bar_parts(sla_process)
    springs, parts, pins = place_springs([SpringHint("B", 40.0, 180.0, 12.0)], mech, motion, partset.parts,
                                         partset.pins, sla_process)
    import dataclasses

    loaded = dataclasses.replace(partset, parts=tuple(parts), pins=tuple(pins), springs=springs)
    design = SimpleNamespace(checks=SimpleNamespace(min_safety_factor=2.0), process=sla_process, load=None)
    result = run_strength(design, loaded, mech, motion, [], loaded.hints)
    failures = result.failures()
    assert any(f.startswith("strength: spring at B") and "over its allowable" in f for f in failures)
    assert result.passed is not True
