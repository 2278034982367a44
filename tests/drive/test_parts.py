"""The actuator in the parts (``fabricate/drive/parts.py``): the driver pin replaced by the output everywhere,
the interface on the driven part and the mount on the ground where the catalogue puts them, the actuator's
solids in the interference proof (a placement that collides is reported), a shaft bore measured on the
exported mesh, a push rod's rod-end hole on the slider. Small mechanisms only (the conftest four-bar, a
slider-crank)."""

from __future__ import annotations

import dataclasses
import io
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
import trimesh

from fabricate.catalogue.actuators import NEMA17, SG90
from fabricate.checks.interference import sweep_interference
from fabricate.drive import geometry as geo
from fabricate.drive.parts import attach_actuator, sweep_items
from fabricate.drive.records import MOUNT_PART
from fabricate.drive.spec import ActuatorSpec
from fabricate.errors import SpecError
from fabricate.export.stl import SolidCache, part_stl
from fabricate.parts.build import build_parts
from fabricate.parts.spec import PartsSpec
from fabricate.templates import shipped_templates
from tests.conftest import make_four_bar
from tests.parts.test_build import slider_crank
from tests.parts.test_build_mounting import swing_mechanism


def design(process, model: str | None, **actuator) -> SimpleNamespace:
    return SimpleNamespace(name="test", process=process, parts=PartsSpec(mounting_holes=2),
                           gears=SimpleNamespace(hub_diameter_mm=None),
                           actuator=None if model is None else ActuatorSpec(model, **actuator))


def driven(process, model: str, mech=None, poses: int = 61, **actuator):
    mech = mech or make_four_bar()
    motion = mech.sweep(poses)
    bare = build_parts(design(process, None), mech, motion, [])
    return bare, attach_actuator(design(process, model, **actuator), mech, motion, bare), motion


def holes(part, prefix: str) -> list:
    return [h for h in part.holes if h.joint.startswith(prefix)]


def sweep(partset, motion, extra=None, clearance: float = 0.25):
    return sweep_interference(partset.parts, motion, chord_tolerance_mm=partset.chord_tolerance_mm,
                              min_clearance_mm=clearance, pins=partset.pins, spacers=partset.spacers,
                              extra=sweep_items(partset) if extra is None else extra)


def test_no_actuator_leaves_the_parts_alone(sla_process, four_bar):
    motion = four_bar.sweep(31)
    d = design(sla_process, None)
    bare = build_parts(d, four_bar, motion, [])
    assert attach_actuator(d, four_bar, motion, bare) is bare


@pytest.mark.parametrize("process", ["sla_process", "laser_process"])
def test_build_parts_attaches_the_designs_actuator(process, four_bar, request):
    process = request.getfixturevalue(process)
    motion = four_bar.sweep(31)
    ps = build_parts(design(process, "mg90s"), four_bar, motion, [])
    assert ps.actuator is not None and ps.actuator.model == "mg90s" and ps.part(MOUNT_PART).role == "mount"
    # a mounting hole a standoff stands on takes the standoff's screw, not a base screw as well
    used = {st.hole for st in ps.actuator.standoffs}
    assert used
    assert not [r for r in ps.bom if r["kind"] == "screw" and used & set(r.get("joints", []))]


def test_the_output_replaces_the_driver_pin_everywhere(sla_process):
    bare, ps, _ = driven(sla_process, "sg90")
    assert ps.actuator.removed_pin == "O" and ps.actuator.joint == "O"
    assert [p.joint for p in bare.pins if p.joint != "O"] == [p.joint for p in ps.pins]
    assert all(s.joint != "O" for s in ps.spacers)
    assert all(h.joint != "O" for p in ps.parts for h in p.holes)
    assert all("O" not in row.get("joints", []) for row in ps.bom)
    def count(bom, kind):
        return sum(r["qty"] for r in bom if r["kind"] == kind)

    assert count(ps.bom, "pin") == count(bare.bom, "pin") - 1
    # the pin's washers (and clips) leave the BOM with it, the other joints' stay
    at_o = [getattr(sp, "kind", "") or ("washer" if sp.washer else "spacer") for sp in bare.spacers if sp.joint == "O"]
    for kind in ("washer", "clip"):
        assert count(ps.bom, kind) == count(bare.bom, kind) - at_o.count(kind)
    items = {r["item"]: r for r in ps.bom}
    assert items[SG90.name]["qty"] == 1 and items[SG90.name]["source"] == "buy"
    assert {MOUNT_PART, "standoff_mount_1", "standoff_mount_2"} <= {p.name for p in ps.parts}
    summary = json.loads(json.dumps(ps.actuator.report()))  # JSON-ready
    assert summary["removed_pin"] == "O" and summary["mount_part"] == MOUNT_PART
    assert {f["designation"] for f in summary["fasteners"]} == {f.designation for f in ps.actuator.fasteners}


def test_horn_pattern_and_hub_bore_on_the_driven_part(sla_process):
    _, ps, _ = driven(sla_process, "sg90")
    crank = ps.part("crank")
    c, comp = sla_process.running_clearance_mm, sla_process.hole_compensation_mm
    (hub,) = holes(crank, "actuator_hub")
    np.testing.assert_allclose(hub.centre, [0.0, 0.0], atol=1e-12)
    assert hub.diameter_mm == pytest.approx(SG90.horn.hub_d_mm + 2 * c + comp)
    # the crank runs O (0, 0) to A (15, 0): the horn's arms along it, on the 7 mm holes (the 5 mm ones would
    # leave 0.29 mm of wall to the hub bore)
    horn = holes(crank, "actuator_horn")
    assert sorted((round(h.centre[0], 9), round(h.centre[1], 9)) for h in horn) == [(-7.0, 0.0), (7.0, 0.0)]
    assert all(h.diameter_mm == pytest.approx(0.8 * 2.0 + comp) for h in horn)
    # the part takes them in: every hole keeps the process's wall inside the outline (a fused outline is a
    # polyline of chords inside the arcs: less the chord tolerance)
    outline = shapely.Polygon(crank.outline.polygon(0.001))
    wall = sla_process.min_wall_mm - ps.chord_tolerance_mm - 1e-9
    for h in horn + [hub]:
        assert outline.exterior.distance(shapely.Point(h.centre)) >= h.diameter_mm / 2 + wall
    heads = [s for s in ps.actuator.solids if s.role == "screw"]
    assert len(heads) == 2 and any(f.designation == "ISO 4762 M2 × 4" and f.qty == 2 for f in ps.actuator.fasteners)


def test_servo_mount_holes_and_pocket_match_the_catalogue(sla_process):
    _, ps, _ = driven(sla_process, "sg90")
    mount, placed = ps.part(MOUNT_PART), ps.actuator
    assert mount.role == "mount" and mount.body == "ground" and mount.thickness_mm == sla_process.thickness_mm
    a, b = (np.asarray(h.centre) for h in holes(mount, "actuator_screw"))
    tab_x = [h.x for h in SG90.mounting_holes]
    assert float(np.hypot(*(a - b))) == pytest.approx(max(tab_x) - min(tab_x))  # 2 × 13.97
    # the tab holes straddle the case centre, 6.19 mm behind the axle
    assert float(np.hypot(*((a + b) / 2 - placed.axis))) == pytest.approx(6.19)
    (pocket,) = mount.slots
    ring = shapely.Polygon(pocket.polygon(0.001))
    assert ring.area == pytest.approx((22.62 + 0.5) * (12.38 + 0.5))
    assert ring.contains(shapely.Point(placed.axis))  # the case passes through the plate round the axle
    # the plate lies on the tabs: its face at the catalogue's tab face, on the output side
    tab_face = placed.z_face + geo.mount_plate_z(SG90) if not placed.flip else placed.z_face - geo.mount_plate_z(SG90)
    assert (mount.z_mm if not placed.flip else mount.z_mm + mount.thickness_mm) == pytest.approx(tab_face)


def test_standoffs_fill_the_real_stack_and_the_screws_clamp_it(sla_process):
    _, ps, _ = driven(sla_process, "sg90")
    ground, mount = ps.part("ground"), ps.part(MOUNT_PART)
    for st in ps.actuator.standoffs:
        part = ps.part(f"standoff_{st.hole}")
        span = sorted([mount.z_mm, mount.z_mm + mount.thickness_mm, ground.z_mm, ground.z_mm + ground.thickness_mm])
        assert (part.z_mm, part.z_mm + part.thickness_mm) == pytest.approx((span[1], span[2]))
    fix = next(f for f in ps.actuator.fasteners if "standoffs" in f.purpose)
    st = ps.actuator.standoffs[0]
    assert fix.clamp_mm == pytest.approx(ground.thickness_mm + st.length_mm)
    assert 3.0 <= fix.engagement_mm  # at least a diameter of an M3 thread in the plate


def test_stepper_face_holes_and_shaft_reach(sla_process):
    _, ps, _ = driven(sla_process, "nema17")
    mount, placed = ps.part(MOUNT_PART), ps.actuator
    centres = np.array([h.centre for h in holes(mount, "actuator_screw")])
    gaps = sorted(float(np.hypot(*(p - q))) for i, p in enumerate(centres) for q in centres[i + 1:])
    assert gaps == pytest.approx([31.0] * 4 + [31.0 * math.sqrt(2)] * 2)
    np.testing.assert_allclose(centres.mean(axis=0), placed.axis, atol=1e-9)
    assert all(h.diameter_mm == pytest.approx(3.0 + 0.5 + 0.2) for h in holes(mount, "actuator_screw"))
    crank = ps.part("crank")
    (shaft,) = [s for s in placed.solids if s.name == "actuator_shaft"]
    # the shaft's tip is flush with the far face of the crank; the motor and its plate stay out of the stack
    tip = shaft.z0 if placed.flip else shaft.z1
    assert tip == pytest.approx(crank.z_mm if placed.flip else crank.z_mm + crank.thickness_mm)
    stack = [(p.z_mm, p.z_mm + p.thickness_mm) for p in ps.parts if p.role not in ("mount", "standoff")]
    for s in placed.solids:
        if s.role == "body":
            assert s.z1 <= min(z0 for z0, _ in stack) or s.z0 >= max(z1 for _, z1 in stack)
    assert shaft.z1 - shaft.z0 == pytest.approx(NEMA17.shaft.length_mm - geo.output_base_z(NEMA17))


def test_double_d_bore_measured_on_the_exported_mesh(sla_process):
    _, ps, _ = driven(sla_process, "28byj48")
    crank = ps.part("crank")
    mesh = trimesh.load(io.BytesIO(part_stl(crank, SolidCache(ps.chord_tolerance_mm))), file_type="stl")
    # the part lies on z = 0 in its own coordinates (STL floats are float32): the bore's ring is the bottom
    # face's vertices within 3.2 mm of the axis (the bore reaches 2.85, the outline round it 3.65)
    v = np.asarray(mesh.vertices)
    bore = v[(np.abs(v[:, 2]) < 1e-4) & (np.hypot(v[:, 0], v[:, 1]) < 3.2)][:, :2]
    assert len(bore) > 8
    c, comp = sla_process.running_clearance_mm, sla_process.hole_compensation_mm
    # the arms point along the crank (+x): the flats face ±x
    assert float(np.ptp(bore[:, 0])) == pytest.approx(3.0 + 2 * c + comp, abs=1e-3)
    assert float(np.ptp(bore[:, 1])) == pytest.approx(5.0 + 2 * c + comp, abs=2 * ps.chord_tolerance_mm + 1e-3)


def test_the_actuator_is_in_the_sweep_and_fastened_pairs_are_not_checked(sla_process):
    _, ps, motion = driven(sla_process, "sg90", poses=37)
    result = sweep(ps, motion)
    assert result.passed, result.failures()
    pairs = {(p.a, p.b): p.relation for p in result.pairs}
    names = {n for pair in pairs for n in pair}
    assert {"actuator_body_1", "actuator_body_2", "actuator_horn_arms", "actuator_spline"} <= names
    assert pairs[("coupler", "actuator_body_1")] == "moving"
    assert pairs[("ground", "actuator_body_1")] == "fixed"
    assert pairs[("actuator_spline", "actuator_body_1")] == "bearing"
    assert not any("crank" in pair and any(n.startswith("actuator_horn") for n in pair) for pair in pairs)


def test_a_colliding_placement_is_reported(sla_process):
    _, ps, motion = driven(sla_process, "sg90", poses=37)
    coupler = ps.part("coupler")
    body = next(s for s in ps.actuator.solids if s.name == "actuator_body_1")
    # the servo's case lifted into the coupler's layer, where the coupler sweeps past the axle
    moved = dataclasses.replace(body, z0=coupler.z_mm, z1=coupler.z_mm + coupler.thickness_mm)
    solids = tuple(moved if s is body else s for s in ps.actuator.solids)
    bad = dataclasses.replace(ps, actuator=dataclasses.replace(ps.actuator, solids=solids))
    failures = sweep(bad, motion).failures()
    assert any("coupler collides with actuator_body_1" in f for f in failures), failures
    # and cut into the ground part it is fixed to: an overlap of one body's solids fails too
    ground = ps.part("ground")
    sunk = dataclasses.replace(body, z0=ground.z_mm, z1=ground.z_mm + ground.thickness_mm)
    solids = tuple(sunk if s is body else s for s in ps.actuator.solids)
    bad = dataclasses.replace(ps, actuator=dataclasses.replace(ps.actuator, solids=solids))
    assert any("ground collides with actuator_body_1" in f for f in sweep(bad, motion).failures())


def test_a_push_rod_gets_a_rod_end_hole_on_the_slide_axis(sla_process):
    mech = slider_crank()
    bare, ps, motion = driven(sla_process, "tendon", mech=mech, poses=21, force_N=10.0)
    rod = ps.part("rod")
    (end,) = holes(rod, "actuator_rod_end")
    assert end.pin_diameter_mm == sla_process.pin_diameter_mm
    assert end.centre[1] == pytest.approx(0.0, abs=1e-9)  # on the slide axis through the rod's point G
    slot = shapely.Polygon(rod.slots[0].polygon(0.001))
    assert slot.distance(shapely.Point(end.centre)) >= end.diameter_mm / 2 + sla_process.min_wall_mm - 1e-9
    assert shapely.Polygon(rod.outline.polygon(0.001)).contains(shapely.Point(end.centre).buffer(end.diameter_mm / 2))
    assert [p.joint for p in ps.pins] == [p.joint for p in bare.pins]  # a push rod replaces no pin
    assert ps.actuator.driver_kind == "slide" and ps.actuator.driven_body == "rod"
    assert sweep(ps, motion).passed


def test_an_actuator_that_does_not_suit_the_driver_is_a_spec_error(sla_process):
    with pytest.raises(SpecError, match="actuator.model"):
        driven(sla_process, "sg90", mech=slider_crank(), poses=11)
    with pytest.raises(SpecError, match="actuator.driver"):
        driven(sla_process, "sg90", poses=11, driver=3)


def test_without_mounting_holes_the_ground_takes_new_standoff_holes(sla_process):
    mech = make_four_bar()
    motion = mech.sweep(37)
    bare = build_parts(SimpleNamespace(**{**vars(design(sla_process, None)), "parts": PartsSpec(mounting_holes=0)}),
                       mech, motion, [])
    d = SimpleNamespace(**{**vars(design(sla_process, "mg996r")), "parts": PartsSpec(mounting_holes=0)})
    ps = attach_actuator(d, mech, motion, bare)
    ground, mount = ps.part("ground"), ps.part(MOUNT_PART)
    new = holes(ground, "actuator_standoff")
    assert len(new) == 2 and len(ps.actuator.standoffs) == 2
    assert {st.hole for st in ps.actuator.standoffs} == {h.joint for h in new}
    outline = shapely.Polygon(ground.outline.polygon(0.001))
    for h in new:
        # in the ground's material with a wall round the hole, and under a pilot hole of the plate
        assert outline.exterior.distance(shapely.Point(h.centre)) >= h.diameter_mm / 2 + sla_process.min_wall_mm - 0.01
        assert outline.contains(shapely.Point(h.centre))
        assert any(np.allclose(p.centre, h.centre) for p in holes(mount, "actuator_standoff"))
    # the standoffs keep clear of the servo's case (the sweep's "fixed" pairs) and of what moves
    result = sweep(ps, motion)
    assert result.passed, result.failures()
    assert any(p.relation == "fixed" and "standoff" in p.a + p.b for p in result.pairs)


def test_a_cut_process_buys_its_standoffs_and_sweeps_them(laser_process):
    _, ps, motion = driven(laser_process, "nema17", poses=37)
    assert not [p for p in ps.parts if p.role == "standoff"]
    standoffs = [s for s in ps.actuator.solids if s.role == "standoff"]
    assert len(standoffs) == len(ps.actuator.standoffs) == 2
    (tubes,) = [r for r in ps.bom if r["item"].startswith("standoff tube")]
    assert tubes["qty"] == 2 and tubes["source"] == "buy"
    mount = ps.part(MOUNT_PART)
    assert mount.thickness_mm == laser_process.thickness_mm  # cut from the same sheet
    result = sweep(ps, motion, clearance=laser_process.running_clearance_mm)
    mine = [f for f in result.failures() if "actuator" in f or "standoff" in f]
    assert not mine
    assert {p.relation for p in result.pairs if "standoff" in p.a + p.b} >= {"fixed", "moving"}


@pytest.mark.slow
@pytest.mark.parametrize("template", [p.stem for p in shipped_templates()])
def test_every_shipped_template_has_its_actuator_in_the_parts_and_the_proof(template, shipped_build):
    outcome = shipped_build(template)
    placed = outcome.partset.actuator
    assert placed is not None and placed.model == outcome.design.actuator.model
    driven_part = next(p for p in outcome.partset.parts if p.body == placed.driven_body
                       and p.role not in ("spacer", "cap", "arbor"))
    cuts = {h.joint for h in driven_part.holes} | ({"actuator_shaft_bore", "actuator_spline_bore"}
                                                     if getattr(driven_part, "slots", ()) else set())
    assert set(placed.interface) <= cuts
    pairs = outcome.report["interference"]["pairs"]
    names = {n for row in pairs for n in (row["a"], row["b"])}
    if placed.driver_kind == "angle":  # a rotary actuator: its mount in the parts, its solids in the proof
        assert outcome.partset.part(MOUNT_PART).role == "mount"
        assert placed.removed_pin and all(p.joint != placed.removed_pin for p in outcome.partset.pins)
        assert {s.name for s in placed.solids} <= names
        assert any(s.role == "body" for s in placed.solids)
    assert not [f for f in outcome.failures if "actuator" in f or "standoff" in f]


@pytest.mark.parametrize("model", ["sg90", "nema17"])
def test_the_grounds_hole_clears_what_passes_it_and_only_that(sla_process, model):
    c, comp = sla_process.running_clearance_mm, sla_process.hole_compensation_mm
    # a lever over a ground bar: the actuator goes over the lever, nothing passes the ground
    bare, ps, _ = driven(sla_process, model, mech=swing_mechanism(), poses=21)
    assert ps.actuator.flip
    (hole,) = holes(ps.part("ground"), "actuator_clearance")
    (pin_hole,) = [h for h in bare.part("ground").holes if h.joint == "O"]
    assert hole.diameter_mm == pytest.approx(pin_hole.diameter_mm)
    np.testing.assert_array_equal(ps.part("ground").outline.vertices, bare.part("ground").outline.vertices)
    # the four-bar's coupler sweeps over O above the crank: the actuator goes under, through the ground
    _, ps, _ = driven(sla_process, model, poses=21)
    assert not ps.actuator.flip
    (hole,) = holes(ps.part("ground"), "actuator_clearance")
    axis = ps.actuator.axis
    passing = [s for s in ps.actuator.solids if s.role in ("output", "screw")
               and s.z0 < ps.part("ground").z_mm + ps.part("ground").thickness_mm and s.z1 > ps.part("ground").z_mm]
    reach = max(float(np.max(np.hypot(*(s.rings[0] - axis).T))) for s in passing)
    # the hole is what passes plus the running clearance all round (the rings are inscribed polygons)
    assert hole.diameter_mm == pytest.approx(2 * reach + 2 * c + comp, abs=2 * ps.chord_tolerance_mm)
    outline = shapely.Polygon(ps.part("ground").outline.polygon(0.001))
    assert outline.exterior.distance(shapely.Point(axis)) >= hole.diameter_mm / 2 + sla_process.min_wall_mm - 1e-3
