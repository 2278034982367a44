"""Parts layer: exact profiles, hole and boss sizes, gear fusion, layers, pins and spacers, BOM."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.errors import GeometryError, SpecError
from fabricate.mechanism import Body, Driver, GearCoupling, LinearLaw, Mechanism, Revolute, Slider
from fabricate.parts.build import build_parts, derive_sizes, gear_outline_in_body
from fabricate.parts.layers import assign_layers
from fabricate.parts.model import BulgePath
from fabricate.parts.profiles import circle_hull, fuse_polygons, offset_path
from fabricate.parts.spec import PartsSpec, parse_parts_spec
from fabricate.planar import polygon_area, relative_poses, rotation, transform_points
from fabricate.table import Table

DATA = json.loads((Path(__file__).parent / "data" / "parts_expected.json").read_text())


def design_for(process, parts: PartsSpec | None = None, name: str = "test"):
    """The slice of a DesignSpec the parts layer reads."""
    return SimpleNamespace(name=name, process=process, parts=parts or PartsSpec(),
                           gears=SimpleNamespace(hub_diameter_mm=None))


# -- [parts] table ----------------------------------------------------------------------------

def test_parts_spec_defaults_and_errors():
    assert parse_parts_spec(Table({}, "parts")) == PartsSpec()
    spec = parse_parts_spec(Table({"link_width_mm": 8, "mounting_holes": 3}, "parts"))
    assert spec.link_width_mm == 8.0 and spec.mounting_holes == 3
    with pytest.raises(SpecError, match="parts.link_widht_mm: unknown field"):
        parse_parts_spec(Table({"link_widht_mm": 8}, "parts"))
    with pytest.raises(SpecError, match="parts.boss_wall_mm"):
        parse_parts_spec(Table({"boss_wall_mm": -1}, "parts"))


# -- exact profiles ---------------------------------------------------------------------------

def test_rounded_slot_is_exact():
    r, length = 3.0, 40.0
    path = circle_hull(np.array([[0.0, 0.0], [length, 0.0]]), r)
    assert len(path.vertices) == 4
    np.testing.assert_allclose(sorted(path.bulges), [0, 0, 1, 1])  # two half circles, two lines
    assert path.area() == pytest.approx(2 * r * length + math.pi * r * r, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-30, 30), st.floats(-30, 30), st.floats(0.5, 6.0)), min_size=1, max_size=6))
def test_circle_hull_matches_dense_hull(circles):
    centres = np.array([c[:2] for c in circles])
    radii = np.array([c[2] for c in circles])
    path = circle_hull(centres, radii)
    discs = [shapely.Point(c).buffer(r, 512) for c, r in zip(centres, radii, strict=True)]
    reference = shapely.union_all(discs).convex_hull
    # the dense reference is inscribed: sagitta of 2048 chords on the largest circle
    tol = radii.max() * (1 - math.cos(math.pi / 2048)) * 4 * 2 * math.pi * (np.ptp(centres) + radii.max() + 1)
    assert path.area() > 0
    assert path.area() == pytest.approx(reference.area, abs=max(tol, 1e-6))
    # every circle lies inside the exact hull (within the polygonisation of the hull itself)
    hull = shapely.Polygon(path.polygon(1e-4)).buffer(1e-3)
    assert all(hull.contains(d) for d in discs)


def test_offset_path_grows_stadium_and_square_exactly():
    r, length, d = 2.5, 30.0, 0.1
    grown = offset_path(circle_hull(np.array([[0.0, 0.0], [length, 0.0]]), r), d)
    assert grown.area() == pytest.approx(2 * (r + d) * length + math.pi * (r + d) ** 2, rel=1e-12)
    square = BulgePath.polyline(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]))
    # Minkowski sum with a disc: 10^2 + 4*10*d + pi d^2 (round corners as 128-gon: area short by ~3e-4)
    assert offset_path(square, 0.5).area() == pytest.approx(100 + 20 + math.pi * 0.25, abs=5e-4)
    assert offset_path(square, -0.5).area() == pytest.approx(9.0 ** 2, rel=1e-12)
    # a comb with slots narrower than twice the offset: the grown outline stays one simple curve
    comb = [[0.0, 0.0], [10.0, 0.0], [10.0, 5.0]]
    for k in range(5):
        x = 10.0 - 2.0 * k
        comb += [[x - 0.9, 5.0], [x - 0.95, 2.0], [x - 1.05, 2.0], [x - 1.1, 5.0]]
    comb += [[0.0, 5.0]]
    grown = offset_path(BulgePath.polyline(np.array(comb)), 0.1)
    assert shapely.Polygon(grown.vertices).is_valid


def bulge_perimeter(path: BulgePath) -> float:
    """Exact length of a bulge path (chords for lines, r * angle for arcs)."""
    total = 0.0
    for i, b in enumerate(path.bulges):
        chord = float(np.hypot(*(path.vertices[(i + 1) % len(path.vertices)] - path.vertices[i])))
        if b == 0:
            total += chord
        else:
            theta = 4 * math.atan(abs(b))
            total += chord / (2 * math.sin(theta / 2)) * theta
    return total


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-30, 30), st.floats(-30, 30), st.floats(0.5, 6.0)), min_size=1, max_size=6),
       st.floats(0.01, 2.0))
def test_offset_hull_obeys_steiner_formula(circles, d):
    """For a convex set, area(offset by d) = area + perimeter * d + pi d^2 exactly."""
    path = circle_hull(np.array([c[:2] for c in circles]), np.array([c[2] for c in circles]))
    grown = offset_path(path, d)
    expected = path.area() + bulge_perimeter(path) * d + math.pi * d * d
    assert grown.area() == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_fuse_polygons_is_union_outline():
    path = circle_hull(np.array([[0.0, 0.0], [20.0, 0.0]]), 3.0)
    tri = np.array([[0.0, 0.0], [5.0, 10.0], [-5.0, 10.0]])
    fused = fuse_polygons(path, [tri], 0.001)
    expected = shapely.union_all([shapely.Polygon(path.polygon(0.001)), shapely.Polygon(tri)]).area
    assert fused.area() == pytest.approx(expected, rel=1e-9)
    assert polygon_area(fused.vertices) > 0
    with pytest.raises(GeometryError, match="falls apart"):
        fuse_polygons(path, [tri + [100.0, 0.0]], 0.001)


# -- sizes ------------------------------------------------------------------------------------

def test_hole_and_boss_sizes(sla_process, laser_process):
    sla = derive_sizes(sla_process, PartsSpec(), {})
    expected = DATA["sizes"]
    assert sla.hole_mm == pytest.approx(expected["sla_hole_mm"], abs=1e-9)  # 2 + 2*0.25 + 0.2
    assert sla.boss_radius_mm == pytest.approx(expected["sla_boss_radius_mm"], abs=1e-9)
    laser = derive_sizes(laser_process, PartsSpec(), {})
    assert laser.hole_mm == pytest.approx(expected["laser_hole_mm"], abs=1e-9)  # 3 + 2*0.1
    # minimum web >= sheet thickness on the laser
    assert laser.boss_radius_mm - laser.hole_mm / 2 >= laser_process.thickness_mm - 1e-12
    wide = derive_sizes(sla_process, PartsSpec(link_width_mm=12.0), {})
    assert wide.boss_radius_mm == pytest.approx(6.0)
    hinted = derive_sizes(sla_process, PartsSpec(), {"link_width_mm": 10.0})
    assert hinted.boss_radius_mm == pytest.approx(5.0)


# -- whole part sets --------------------------------------------------------------------------

@pytest.mark.parametrize("process_name", ["sla_process", "laser_process"])
def test_four_bar_parts(four_bar, process_name, request):
    process = request.getfixturevalue(process_name)
    motion = four_bar.sweep(181)
    partset = build_parts(design_for(process), four_bar, motion, [], {})
    sizes = derive_sizes(process, PartsSpec(), {})
    by_body = {p.body: p for p in partset.body_parts()}
    assert set(by_body) == set(four_bar.body_names)
    for joint in four_bar.joints:
        for body in (joint.body_a, joint.body_b):
            hole = next(h for h in by_body[body].holes if h.joint == joint.name)
            np.testing.assert_allclose(hole.centre, four_bar.body(body).point(joint.name), atol=1e-12)
            assert hole.diameter_mm == pytest.approx(sizes.hole_mm, abs=1e-9)
        # bodies sharing a pin never share a layer
        assert partset.layers[joint.body_a] != partset.layers[joint.body_b]
    # a binary link is the rounded slot of its two bosses: area known in closed form
    crank = by_body["crank"]
    r, length = sizes.boss_radius_mm, 15.0
    area = 2 * r * length + math.pi * r * r - 2 * math.pi * sizes.hole_mm ** 2 / 4
    assert crank.area_mm2() == pytest.approx(area, rel=1e-12)
    assert crank.volume_mm3() == pytest.approx(area * process.thickness_mm, rel=1e-12)
    # ground carries the mounting holes
    assert sum(h.joint.startswith("mount_") for h in by_body["ground"].holes) == 2
    assert by_body["ground"].role == "ground"


def test_layers_keep_bodies_apart_over_the_motion(four_bar, sla_process):
    """Independent check: bodies in one layer never come within the clearance at any of 361 poses."""
    motion = four_bar.sweep(361)
    partset = build_parts(design_for(sla_process), four_bar, motion, [], {})
    parts = partset.body_parts()
    for i, a in enumerate(parts):
        for b in parts[i + 1:]:
            if a.layer != b.layer:
                continue
            poly_a = shapely.Polygon(a.outline.polygon(0.01))
            rel = relative_poses(motion.pose(a.body), motion.pose(b.body))
            outline_b = b.outline.polygon(0.01)
            gaps = [shapely.Polygon(transform_points(p, outline_b)).distance(poly_a) for p in rel]
            assert min(gaps) >= sla_process.running_clearance_mm


def test_assign_layers_merges_gears_and_colours_greedily():
    graph = {"a": {"b", "c"}, "b": {"a", "c"}, "c": {"a", "b"}, "d": set()}
    layers = assign_layers(graph, ["a", "b", "c", "d"])
    assert len({layers["a"], layers["b"], layers["c"]}) == 3
    assert layers["d"] == 0
    merged = assign_layers({"a": {"b"}, "b": {"a", "c"}, "c": {"b"}}, ["a", "b", "c"], [("a", "c")])
    assert merged["a"] == merged["c"] != merged["b"]


def test_pins_and_spacers_fill_the_stack(four_bar, sla_process):
    partset = build_parts(design_for(sla_process), four_bar, four_bar.sweep(121), [], {})
    t, g = sla_process.thickness_mm, sla_process.layer_gap_mm
    for pin in partset.pins:
        lo, hi = pin.layers
        assert pin.length_mm == pytest.approx((hi - lo) * (t + g) + t, abs=1e-12)
        assert pin.z_mm == pytest.approx(lo * (t + g), abs=1e-12)
    spacer_total = {}
    for sp in partset.spacers:
        spacer_total[sp.joint] = spacer_total.get(sp.joint, 0.0) + sp.length_mm
    for pin in partset.pins:
        lo, hi = pin.layers
        # plates plus spacers/washers make up the whole pin length
        assert 2 * t + spacer_total.get(pin.joint, 0.0) == pytest.approx(pin.length_mm, abs=1e-12)
    pins = [row for row in partset.bom if row["kind"] == "pin"]
    assert sum(row["qty"] for row in pins) == len(four_bar.joints)


def test_bom_copies_springs_and_purchased(four_bar, sla_process):
    hints = {"copies": 3, "springs": [{"joint": "A", "rate_Nmm_per_deg": 30.0, "preload_deg": 5.0,
                                       "legs_mm": 10.0, "note": "torsion"}],
             "purchased": [{"item": "micro servo", "qty": 1, "note": "driver"}],
             "purchased_shared": [{"item": "base plate", "qty": 1, "note": "holds all copies"}]}
    partset = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [], hints)
    pins = sum(row["qty"] for row in partset.bom if row["kind"] == "pin")
    assert pins == 3 * len(four_bar.joints)
    assert next(r for r in partset.bom if r["kind"] == "spring")["qty"] == 3
    assert next(r for r in partset.bom if r["item"] == "micro servo")["qty"] == 3
    assert next(r for r in partset.bom if r["item"] == "base plate")["qty"] == 1
    json.dumps(partset.bom)  # JSON-ready


def test_pad_hint_adds_fingertip(four_bar, sla_process):
    plain = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [], {})
    padded = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [],
                         {"pads": {"coupler": {"point": "B", "radius_mm": 6.0}}})
    outline = shapely.Polygon(padded.part("coupler").outline.polygon(0.001))
    disc = shapely.Point(40.0, 0.0).buffer(6.0 - 1e-3, 256)
    assert outline.contains(disc)
    assert padded.part("coupler").area_mm2() > plain.part("coupler").area_mm2()
    with pytest.raises(GeometryError, match="no point"):
        build_parts(design_for(sla_process), four_bar, four_bar.sweep(11), [],
                    {"pads": {"coupler": {"point": "Z", "radius_mm": 6.0}}})


# -- gears fused to bodies ----------------------------------------------------------------------

def spur_like(radius: float, teeth: int, depth: float, n: int = 720) -> np.ndarray:
    """A spur-gear-like closed outline (n, 2), CCW, in its gear frame (stand-in for the gears layer)."""
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    r = radius + depth * np.cos(teeth * t)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def sun_planet_four_bar(four_bar: Mechanism) -> Mechanism:
    """The four-bar with a sun/planet record (sun on ground at O, planet on the coupler at A, carrier
    the crank), as in a five-bar gear finger; only its geometry is used here."""
    coupling = GearCoupling("sun_planet", carrier="crank", gear_a="ground", gear_b="coupler",
                            law=LinearLaw(-1.0), axis_a="O", axis_b="A", working_range=(0.0, 1.0))
    return Mechanism(name="geared", bodies=four_bar.bodies, ground=four_bar.ground, joints=four_bar.joints,
                     gears=(coupling,), drivers=four_bar.drivers, input_range=four_bar.input_range,
                     assembly=four_bar.assembly)


def test_gear_frame_maps_into_body(four_bar):
    mech = sun_planet_four_bar(four_bar)
    motion = four_bar.sweep(25)
    pair = SimpleNamespace(name="sun_planet", body_a="ground", body_b="coupler", axis_a="O", axis_b="A",
                           outline_a=spur_like(9.0, 12, 0.4), outline_b=spur_like(6.0, 8, 0.4))
    g = np.array([[9.0, 0.0], [0.0, 9.0], [3.0, -2.0]])
    beta = 0.0  # A - O in the crank frame lies on +x
    for side, body, axis in (("a", "ground", "O"), ("b", "coupler", "A")):
        name, joint, outline = gear_outline_in_body(mech, SimpleNamespace(**{**vars(pair), f"outline_{side}": g}),
                                                    side)
        assert (name, joint) == (body, axis)
        for i in range(0, 25, 6):
            carrier = motion.pose("crank")[i]
            x = motion.pose(body)[i, 2] - carrier[2]
            axis_carrier = four_bar.body("crank").point(axis)
            expected = transform_points(carrier, axis_carrier + g @ (rotation(beta) @ rotation(x)).T)
            np.testing.assert_allclose(transform_points(motion.pose(body)[i], outline), expected, atol=1e-9)


def test_gears_fused_with_hub_share_a_layer(four_bar, sla_process):
    mech = sun_planet_four_bar(four_bar)
    motion = four_bar.sweep(91)
    pair = SimpleNamespace(name="sun_planet", body_a="ground", body_b="coupler", axis_a="O", axis_b="A",
                           outline_a=spur_like(9.0, 12, 0.4), outline_b=spur_like(6.0, 8, 0.4))
    partset = build_parts(design_for(sla_process), mech, motion, [pair], {})
    assert partset.layers["ground"] == partset.layers["coupler"]
    ground, coupler = partset.part("ground"), partset.part("coupler")
    assert ground.gear == "sun_planet" and coupler.gear == "sun_planet"
    _, _, sun = gear_outline_in_body(mech, pair, "a")
    fused = shapely.Polygon(ground.outline.vertices)
    assert fused.buffer(1e-6).contains(shapely.Polygon(sun))
    # the hole on the gear axis survives the fusion
    assert any(h.joint == "O" for h in ground.holes)
    assert ground.area_mm2() > shapely.Polygon(sun).area - 3 * math.pi * 2.0 ** 2


# -- sliders -----------------------------------------------------------------------------------

def slider_crank() -> Mechanism:
    """A crank O-A turned by a push rod: the rod (G, B) slides along x in a guide on the ground at G,
    a coupler B-A joins it to the crank."""
    crank, coupler = 12.0, 30.0
    a = np.array([0.0, crank])
    b = np.array([-math.sqrt(coupler ** 2 - (crank - 5.0) ** 2), 5.0])
    return Mechanism(
        name="slider_crank",
        bodies=(Body("ground", {"O": (0.0, 0.0), "G": (-60.0, 5.0)}),
                Body("rod", {"G": (0.0, 0.0), "B": (float(b[0] + 60.0), 0.0)}),
                Body("coupler", {"B": (0.0, 0.0), "A": (coupler, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (crank, 0.0)})),
        ground="ground",
        joints=(Slider("G", "ground", "rod", (1.0, 0.0)), Revolute("B", "rod", "coupler"),
                Revolute("A", "coupler", "crank"), Revolute("O", "ground", "crank")),
        gears=(),
        drivers=(Driver("slide", "rod", "ground", joint="G"),),
        input_range=(0.0, 8.0), input_unit="mm",
        assembly={"rod": (-60.0, 5.0, 0.0),
                  "coupler": (float(b[0]), float(b[1]), math.atan2(a[1] - b[1], a[0] - b[0])),
                  "crank": (0.0, 0.0, math.pi / 2)},
    )


def test_slider_rod_gets_a_guide_slot(sla_process):
    mech = slider_crank()
    motion = mech.sweep(41)
    partset = build_parts(design_for(sla_process), mech, motion, [], {})
    rod = partset.part("rod")
    assert rod.role == "rod" and len(rod.slots) == 1
    ground = partset.part("ground")
    guides = [h for h in ground.holes if h.joint.startswith("G")]
    assert len(guides) == 2  # two guide pins stop the rod turning
    # over the whole motion both guide pins stay inside the slot (in rod coordinates)
    slot = shapely.Polygon(rod.slots[0].polygon(0.001)).buffer(1e-6)
    for i in range(len(motion.inputs)):
        for hole in guides:
            world = transform_points(np.zeros(3), hole.centre)
            local = (world - motion.pose("rod")[i, :2]) @ rotation(motion.pose("rod")[i, 2])
            pin = shapely.Point(local).buffer(sla_process.pin_diameter_mm / 2, 64)
            assert slot.contains(pin)
    assert partset.layers["rod"] != partset.layers["ground"]
    assert rod.area_mm2() == pytest.approx(rod.outline.area() - math.pi * rod.holes[0].diameter_mm ** 2 / 4
                                           - rod.slots[0].area(), rel=1e-12)


def test_same_input_same_parts(four_bar, sla_process):
    a = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [], {})
    b = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [], {})
    assert [p.name for p in a.parts] == [p.name for p in b.parts]
    for p, q in zip(a.parts, b.parts, strict=True):
        np.testing.assert_array_equal(p.outline.vertices, q.outline.vertices)
    assert a.layers == b.layers and a.bom == b.bom


def test_no_body_sweeps_over_a_spacer_between_its_layers(four_bar, sla_process):
    """Independent check over 181 poses: a body in a layer skipped by a pin keeps clear of its spacer.

    (The plain colouring of this four-bar puts the coupler, which sweeps over pin O, between the layers
    of the ground and the crank; the layer ordering must move it out.)"""
    motion = four_bar.sweep(181)
    partset = build_parts(design_for(sla_process), four_bar, motion, [], {})
    sizes = derive_sizes(sla_process, PartsSpec(), {})
    for pin in partset.pins:
        a, b = pin.bodies
        lo, hi = pin.layers
        centre = four_bar.body(a).point(pin.joint)
        spacer = shapely.Point(centre).buffer(sizes.boss_radius_mm, 256)
        for part in partset.body_parts():
            if part.body in (a, b) or not lo < part.layer < hi:
                continue
            rel = relative_poses(motion.pose(a), motion.pose(part.body))
            outline = part.outline.polygon(0.01)
            gaps = [shapely.Polygon(transform_points(p, outline)).distance(spacer) for p in rel]
            assert min(gaps) >= sla_process.running_clearance_mm, (pin.joint, part.name)


def test_order_layers_moves_a_crossing_body_out_of_the_pin_range():
    from fabricate.parts.layers import order_layers

    layers = {"a": 0, "c": 1, "b": 2}
    ordered = order_layers(layers, [("a", "b", "c")])
    lo, hi = sorted((ordered["a"], ordered["b"]))
    assert not lo < ordered["c"] < hi
    assert sorted(ordered.values()) == [0, 1, 2]
    assert order_layers(layers, []) == layers


def test_mounting_screws_clear_everything_that_moves(four_bar, sla_process):
    """Independent check at every pose: each mounting boss (screw head) keeps the clearance from every
    moving part."""
    motion = four_bar.sweep(181)
    partset = build_parts(design_for(sla_process), four_bar, motion, [], {})
    sizes = derive_sizes(sla_process, PartsSpec(), {})
    mounts = [h for h in partset.part("ground").holes if h.joint.startswith("mount_")]
    assert len(mounts) == 2
    for hole in mounts:
        head = shapely.Point(hole.centre).buffer(sizes.mount_boss_radius_mm, 256)
        for part in partset.body_parts():
            if part.body == "ground":
                continue
            outline = part.outline.polygon(0.01)
            gaps = [shapely.Polygon(transform_points(p, outline)).distance(head) for p in motion.pose(part.body)]
            assert min(gaps) >= sla_process.running_clearance_mm, (hole.joint, part.name, min(gaps))


def test_compound_hinge_shares_one_pin_and_hole():
    """Three bodies on one pin (joints J palm-a and Jr palm-b at one spot of the palm)."""
    from fabricate.parts.bom import pins_and_spacers
    from fabricate.parts.build import merge_coincident_pins

    joints = [("J", ("palm", "a")), ("Jr", ("palm", "b")), ("K", ("a", "b"))]
    holes = [("J", "palm", np.zeros(2)), ("J", "a", np.zeros(2)), ("Jr", "palm", np.zeros(2)),
             ("Jr", "b", np.zeros(2)), ("K", "a", np.array([10.0, 0.0])), ("K", "b", np.array([5.0, 0.0]))]
    pins, merged_holes = merge_coincident_pins(joints, holes)
    assert pins == [("J+Jr", ("palm", "a", "b")), ("K", ("a", "b"))]
    assert [(n, b) for n, b, _ in merged_holes] == [("J+Jr", "palm"), ("J+Jr", "a"), ("J+Jr", "b"),
                                                    ("K", "a"), ("K", "b")]
    t, g = 3.0, 0.3
    made, spacers = pins_and_spacers(pins, {"palm": 0, "a": 2, "b": 3}, 2.0, 2.7, 4.7, t, g)
    compound = made[0]
    assert compound.layers == (0, 3) and compound.length_mm == pytest.approx(3 * (t + g) + t)
    # a spacer between layers 0 and 2 (skipping 1), a washer between 2 and 3
    on_compound = [s for s in spacers if s.joint == "J+Jr"]
    assert [(s.lower_layer, s.washer) for s in on_compound] == [(0, False), (2, True)]
    assert on_compound[0].length_mm == pytest.approx(t + 2 * g)
    assert sum(s.length_mm for s in on_compound) + 3 * t == pytest.approx(compound.length_mm)


def test_overlapping_holes_name_the_pin_and_the_largest_that_fits(four_bar, sla_process):
    """A 15 mm pin on a 15 mm crank: its two holes (15.7 mm) run into each other and would cut the link in
    two, so the build refuses naming the pin field and the largest pin that leaves the process's wall;
    that pin builds, with the wall the process asks for."""
    import dataclasses

    from fabricate.errors import SpecError

    fat = dataclasses.replace(sla_process, pin_diameter_mm=15.0)
    with pytest.raises(SpecError, match=r"process.pin_diameter_mm: 15 mm pins: holes O and A of part crank") as info:
        build_parts(design_for(fat), four_bar, four_bar.sweep(11), [], {})
    largest = float(re.search(r"at most ([\d.]+) mm", str(info.value)).group(1))
    # closed form: centre distance 15 - wall - 2 x clearance - compensation
    assert largest == pytest.approx(15.0 - 0.8 - 2 * 0.25 - 0.2, abs=0.01)
    fits = build_parts(design_for(dataclasses.replace(sla_process, pin_diameter_mm=largest)), four_bar,
                       four_bar.sweep(11), [], {})
    crank = fits.part("crank")
    (o, a) = crank.holes[:2]
    assert np.hypot(*(o.centre - a.centre)) - 0.5 * (o.diameter_mm + a.diameter_mm) >= 0.8 - 1e-9
    assert fits.warnings == ()


def test_pad_segment_is_the_circular_segment():
    from fabricate.parts.features import pad_segment
    from fabricate.planar import polygon_area

    centre = np.array([40.0, 36.0])
    start, end = np.array([40.0, 0.0]), np.array([76.0, 36.0])  # a quarter arc of radius 36
    ring = pad_segment(centre, start, end, 0.005)
    exact = 0.5 * 36.0**2 * (math.pi / 2 - 1.0)
    assert polygon_area(ring) > 0
    # inscribed chords lose at most sagitta x arc length
    assert exact - 0.005 * 36.0 * math.pi / 2 <= polygon_area(ring) <= exact
    assert np.allclose(np.hypot(*(ring - centre).T)[1:-1], 36.0)  # every vertex but the chord ends lies on the arc
    assert np.all(ring[:, 0] - ring[:, 1] >= 40.0 - 1e-9)  # the segment lies beyond the chord x - y = 40
    with pytest.raises(GeometryError, match="not one circle"):
        pad_segment(centre, start, np.array([70.0, 36.0]), 0.005)
