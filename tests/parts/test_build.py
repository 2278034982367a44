"""Building parts from a mechanism (``fabricate/parts/build.py``) against hand geometry and closed forms.

Gear outlines placed in bodies whose joints sit at hand-picked coordinates (3-4-5 directions, so the
rotations are exact fractions), slider guide pins and slots against the stroke and the process sizes
worked out by hand, slotted parts' rings against shapely and the stadium area L w + pi w^2 / 4.

Written to kill mutants of ``fabricate/parts/build.py`` (see ``tests/benchmarks/mutation_report.md``).

Then (formerly tests/test_parts.py) the parts layer as a whole: exact profiles, hole and boss sizes, gear
fusion, layers, pins and spacers, BOM.
"""

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

from fabricate.catalogue.pins import ISO8734_LENGTHS_MM
from fabricate.errors import GeometryError, SpecError
from fabricate.hints import PadHint, PartHints, PurchasedItem, SpringHint
from fabricate.mechanism import Body, Driver, GearCoupling, LinearLaw, Mechanism, Revolute, Slider
from fabricate.parts.build import (
    _check_pin_webs,
    build_parts,
    derive_sizes,
    merge_coincident_pins,
)
from fabricate.parts.features import _guide_spacing, _segment_distance, pad_segment
from fabricate.parts.gear_seats import gear_outline_in_body
from fabricate.parts.layers import assign_layers
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.partset import CONFLICT_CHORD_MM, SlottedPart, overlapping_cuts, swept_region
from fabricate.parts.profiles import circle_hull, fuse_polygons, offset_path
from fabricate.parts.spec import PartsSpec, parse_parts_spec
from fabricate.planar import polygon_area, relative_poses, rotation, transform_points
from fabricate.table import Table
from tests.conftest import make_four_bar

# -- slotted parts: rings for meshing ---------------------------------------------------------------


def stadium(a: tuple[float, float], b: tuple[float, float], width: float) -> BulgePath:
    """Counter-clockwise stadium (slot) of the given width around the segment a-b."""
    return circle_hull(np.array([a, b], dtype=float), width / 2.0)


def signed_area(ring: np.ndarray) -> float:
    """Shoelace area of a ring (positive when counter-clockwise), written out here."""
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) to the segment a-b (closed form projection)."""
    d = b - a
    t = np.clip((points - a) @ d / float(d @ d), 0.0, 1.0)
    return np.hypot(*(points - a - t[:, None] * d).T)


def test_slotted_part_rings_are_outline_ccw_and_every_cut_cw():
    """A plate (40 x 20 mm rectangle) with a round hole, a slot given counter-clockwise, the same kind of
    slot given clockwise and a tiny slot (area 0.52 mm^2, below 1 mm^2): the exporter's rings are the
    outline counter-clockwise and every cut clockwise (a cut given either way), each slot ring lies on the
    exact stadium within the chord tolerance, and the plate area shapely computes from the rings is the
    rectangle minus the hole and the stadia L w + pi w^2 / 4 (closed form; tolerance: chord sagitta x
    perimeter of every ring)."""
    tol = 0.01
    outline = BulgePath.polyline(np.array([[0.0, 0.0], [40.0, 0.0], [40.0, 20.0], [0.0, 20.0]]))
    ccw = stadium((5.0, 5.0), (15.0, 5.0), 3.0)
    cw_given = stadium((20.0, 12.0), (20.0, 17.0), 2.0)
    cw_given = BulgePath(cw_given.vertices[::-1].copy(), -np.roll(cw_given.bulges[::-1], -1))
    tiny = stadium((30.0, 4.0), (30.4, 4.0), 0.6)
    assert cw_given.area() < 0 < tiny.area() < 1.0
    part = SlottedPart(name="plate", body="plate", outline=outline,
                       holes=(Hole("H", np.array([32.0, 14.0]), 4.0, 3.5),), thickness_mm=2.0, z_mm=0.0,
                       layer=0, process="laser", slots=(ccw, cw_given, tiny))
    rings = part.polygons(tol)
    assert len(rings) == 1 + 1 + 3
    assert signed_area(rings[0]) > 0
    assert all(signed_area(r) < 0 for r in rings[1:])
    slot_specs = [((5.0, 5.0), (15.0, 5.0), 3.0), ((20.0, 17.0), (20.0, 12.0), 2.0), ((30.0, 4.0), (30.4, 4.0), 0.6)]
    slot_area = 0.0
    for ring, (a, b, w) in zip(rings[2:], slot_specs, strict=True):
        a, b = np.array(a), np.array(b)
        on_curve = segment_distance(ring, a, b)
        np.testing.assert_allclose(on_curve, w / 2, atol=1e-9)  # every vertex on the exact stadium
        mids = 0.5 * (ring + np.roll(ring, -1, axis=0))
        assert np.all(w / 2 - segment_distance(mids, a, b) <= tol + 1e-9)  # no chord further in than the tolerance
        length = float(np.hypot(*(b - a)))
        exact = length * w + math.pi * w * w / 4
        assert abs(signed_area(ring)) == pytest.approx(exact, abs=tol * (2 * length + math.pi * w))
        slot_area += exact
    plate = shapely.Polygon(rings[0], rings[1:])
    assert plate.is_valid
    expected = 40.0 * 20.0 - math.pi * 4.0 ** 2 / 4 - slot_area
    assert plate.area == pytest.approx(expected, abs=tol * (120.0 + math.pi * 4.0 + 2 * 10 + 2 * 5 + 0.8 + 6 * math.pi))
    assert part.area_mm2() == pytest.approx(expected, rel=1e-12)


# -- gear outlines in their bodies ------------------------------------------------------------------

#: A marker "outline" in the gear frame and its images under the rotations by the 3-4-5 angles.
MARKER = np.array([[1.0, 0.0], [0.0, 1.0], [2.0, -1.0]])
#: rotated by atan2(8, 6): cos 0.6, sin 0.8
MARKER_68 = np.array([[0.6, 0.8], [-0.8, 0.6], [2.0, 1.0]])
#: rotated by atan2(-6, 8): cos 0.8, sin -0.6
MARKER_8M6 = np.array([[0.8, -0.6], [0.6, 0.8], [1.0, -2.0]])


def gear_train(carrier_points: dict[str, tuple[float, float]] | None, carrier: str = "arm") -> Mechanism:
    """Two gears about joints P and Q of an arm; every body's frame puts the joints off its origin.

    ``arm`` (ground) holds P and Q; in it Q - P = (6, 8). ``sun`` turns about P and also carries a point
    Q with Q - P = (8, -6) in its own frame; ``planet`` turns about Q at (4, 1). ``carrier_points`` replaces
    the arm's points (None keeps (2, -1) and (8, 7)); with ``carrier=None`` no gear coupling is recorded.
    """
    arm = carrier_points if carrier_points is not None else {"P": (2.0, -1.0), "Q": (8.0, 7.0)}
    gears = () if carrier is None else (GearCoupling("mesh", carrier=carrier, gear_a="sun", gear_b="planet",
                                                     law=LinearLaw(-1.5), axis_a="P", axis_b="Q"),)
    return Mechanism(
        name="gear_train",
        bodies=(Body("arm", {**arm, "P": (2.0, -1.0)}), Body("sun", {"P": (-3.0, 5.0), "Q": (5.0, -1.0)}),
                Body("planet", {"Q": (4.0, 1.0)})),
        ground="arm",
        joints=(Revolute("P", "arm", "sun"), Revolute("Q", "arm" if "Q" in arm else "sun", "planet")),
        gears=gears,
        drivers=(Driver("angle", "sun", "arm"), Driver("angle", "planet", "arm")),
        input_range=(0.0, 10.0),
    )


def gear_pair() -> SimpleNamespace:
    return SimpleNamespace(name="mesh", body_a="sun", body_b="planet", axis_a="P", axis_b="Q",
                           outline_a=MARKER, outline_b=2.0 * MARKER)


def test_gear_outline_turns_with_the_line_of_centres_in_the_carrier():
    """With a carrier that holds both axes, each gear is centred on its own body's axis point and turned
    by the direction of Q - P in the carrier, (6, 8): the marker maps to axis + (0.6 x - 0.8 y, 0.8 x + 0.6 y)
    (hand values; the sun's own Q - P, (8, -6), must not be used). Tolerance 1e-12 mm."""
    mech = gear_train(None)
    body, axis, placed = gear_outline_in_body(mech, gear_pair(), "a")
    assert (body, axis) == ("sun", "P")
    np.testing.assert_allclose(placed, np.array([-3.0, 5.0]) + MARKER_68, atol=1e-12)
    body, axis, placed = gear_outline_in_body(mech, gear_pair(), "b")
    assert (body, axis) == ("planet", "Q")
    np.testing.assert_allclose(placed, np.array([4.0, 1.0]) + 2.0 * MARKER_68, atol=1e-12)


@pytest.mark.parametrize("carrier", [None, "planet"], ids=["no_coupling", "carrier_without_both_axes"])
def test_gear_outline_without_a_usable_carrier_follows_body_a(carrier):
    """No coupling recorded for the pair, or a carrier that does not hold both axes (here the planet,
    which has Q but not P): the line of centres is taken in body a, where Q - P = (8, -6), so the marker
    maps to axis + (0.8 x + 0.6 y, -0.6 x + 0.8 y) (hand values). Tolerance 1e-12 mm."""
    mech = gear_train({"P": (2.0, -1.0)}, carrier=carrier)
    _, _, sun = gear_outline_in_body(mech, gear_pair(), "a")
    np.testing.assert_allclose(sun, np.array([-3.0, 5.0]) + MARKER_8M6, atol=1e-12)
    _, _, planet = gear_outline_in_body(mech, gear_pair(), "b")
    np.testing.assert_allclose(planet, np.array([4.0, 1.0]) + 2.0 * MARKER_8M6, atol=1e-12)


def test_gear_hub_from_the_gears_table(four_bar, sla_process):
    """``[gears] hub_diameter_mm = 14``: the planet (outline radius at most 6.4 mm) on the coupler is fused
    with a 14 mm hub, so the coupler plate covers the disc of radius 7 about A. A design slice with no
    gears table at all still builds, with the default hub (2 x boss radius = 4.7 mm): then the disc of
    radius 7 sticks out of the plate. Tolerance: the disc shrunk by 0.01 mm (chord tolerance 0.005)."""
    mech = sun_planet_four_bar(four_bar)
    motion = four_bar.sweep(25)
    pair = SimpleNamespace(name="sun_planet", body_a="ground", body_b="coupler", axis_a="O", axis_b="A",
                           outline_a=spur_like(9.0, 12, 0.4), outline_b=spur_like(6.0, 8, 0.4))
    disc = shapely.Point(0.0, 0.0).buffer(7.0 - 0.01, 256)  # A is the coupler's origin
    design = design_for(sla_process)
    design.gears = SimpleNamespace(hub_diameter_mm=14.0)
    hubbed = build_parts(design, mech, motion, [pair]).part("coupler")
    assert shapely.Polygon(hubbed.outline.polygon(0.005)).contains(disc)
    bare = SimpleNamespace(name="bare", process=sla_process, parts=PartsSpec())
    plain = build_parts(bare, mech, motion, [pair]).part("coupler")
    assert not shapely.Polygon(plain.outline.polygon(0.005)).contains(disc)
    assert plain.gear == hubbed.gear == "sun_planet"
    assert hubbed.role == "gear"  # a moving body carrying a gear is a gear part


def test_part_lookup_names_the_missing_part(four_bar, sla_process):
    """``PartSet.part`` finds a part by its name, and an unknown name raises a KeyError carrying that name
    (what a user scripting against the part set reads)."""
    partset = build_parts(design_for(sla_process), four_bar, four_bar.sweep(11), [])
    assert partset.part("rocker").body == "rocker"
    with pytest.raises(KeyError, match="no_such_part"):
        partset.part("no_such_part")


# -- sliders: guide pins and the slot ---------------------------------------------------------------

#: The slide axis (3, 4) (not a unit vector) and the rod's fixed angle to the ground, rad.
AXIS, ANGLE = (3.0, 4.0), 0.6
#: The stroke: the rod's point G runs from 3 mm behind to 5 mm beyond the ground's G along the axis.
STROKE = (-3.0, 5.0)


def tilted_slider(tail_side: float, across: float = 0.0) -> Mechanism:
    """A push rod alone on a guide: point G of the rod slides along (3, 4) through G = (10, -4) of the
    ground, the rod turned by 0.6 rad against the ground. The rod has a second point T 15 mm from G along
    the slide direction (``tail_side`` +1: ahead, -1: behind; 0: level with G) and ``across`` mm to the
    left of the slide line. The rod is listed first, so it is the first owner of G."""
    unit = np.array(AXIS) / 5.0
    c, s = math.cos(ANGLE), math.sin(ANGLE)
    axis_rod = np.array([c * unit[0] + s * unit[1], -s * unit[0] + c * unit[1]])  # the axis seen from the rod
    tail = tail_side * 15.0 * axis_rod + across * np.array([-axis_rod[1], axis_rod[0]])
    start = np.array([10.0, -4.0]) + STROKE[0] * unit
    return Mechanism(
        name="tilted_slider",
        bodies=(Body("rod", {"G": (0.0, 0.0), "T": (float(tail[0]), float(tail[1]))}),
                Body("ground", {"G": (10.0, -4.0)})),
        ground="ground",
        joints=(Slider("G", "ground", "rod", AXIS, ANGLE),),
        gears=(),
        drivers=(Driver("slide", "rod", "ground", joint="G"),),
        input_range=STROKE, input_unit="mm",
        assembly={"rod": (float(start[0]), float(start[1]), ANGLE)},
    )


@pytest.mark.parametrize("tail_side", [1.0, -1.0], ids=["tail_ahead", "tail_behind"])
def test_slider_guide_pins_and_slot(sla_process, tail_side):
    """Guide pins and slot of a tilted push rod, against hand geometry.

    - Pin ``G`` sits at the ground's slider point (10, -4); the guide pin ``G_guide`` one boss diameter plus
      two minimum walls further along the unit axis (0.6, 0.8), on the side away from the rod's other
      point T: boss radius = (2 + 2 x 0.25 + 0.2) / 2 + max(0.8, 1) = 2.35, spacing 2 x 2.35 + 2 x 0.8 = 6.3.
    - Over the whole motion (solver poses) both pins stay inside the slot, in the rod's frame.
    - The slot is the stadium of width hole = 2.7 mm over the stroke (8 mm) plus the spacing:
      area L w + pi w^2 / 4 with L = 14.3 (closed form); its centre line is where the pins travel.
    - The rod's outline is the convex hull of boss circles (radius 2.35) about its points G and T and about
      both ends of the pin travel (shapely hull of dense discs, within 0.01 mm^2).
    - Every pin hole records the nominal 2 mm pin (the interference and strength checks model the pin from
      it); mounting holes take no pin.
    - The rod's rings: outline CCW, hole and slot CW; the plate area = outline - hole - stadium.
    Tolerances: 1e-9 mm for hand-placed holes, 1e-6 for what goes through the solver.
    """
    mech = tilted_slider(tail_side)
    motion = mech.sweep(33)
    partset = build_parts(design_for(sla_process), mech, motion, [])
    hole_mm = 2.0 + 2 * 0.25 + 0.2
    boss = hole_mm / 2 + max(0.8, 2.0 / 2)
    spacing = 2 * boss + 2 * 0.8
    ground, rod = partset.part("ground"), partset.part("rod")
    guides = {h.joint: h for h in ground.holes if not h.joint.startswith("mount_")}
    assert set(guides) == {"G", "G_guide"}
    unit = np.array([0.6, 0.8])
    np.testing.assert_allclose(guides["G"].centre, [10.0, -4.0], atol=1e-9)
    np.testing.assert_allclose(guides["G_guide"].centre, np.array([10.0, -4.0]) - tail_side * spacing * unit,
                               atol=1e-9)
    # the guide pins are pressed into the ground (1.95 nominal, modelled with the 0.2 compensation); the rod
    # runs on them in its slot
    assert all(h.fit == "press" and h.diameter_mm == pytest.approx(2.0 - 0.05 + 0.2, abs=1e-12)
               and h.nominal_mm == pytest.approx(1.95, abs=1e-12) for h in guides.values())
    assert all(h.pin_diameter_mm == 2.0 for h in guides.values())
    assert all(h.pin_diameter_mm == 0.0 for h in ground.holes if h.joint.startswith("mount_"))
    assert sorted((p.joint, tuple(sorted(p.bodies))) for p in partset.pins) == [
        ("G", ("ground", "rod")), ("G_guide", ("ground", "rod"))]

    assert rod.role == "rod" and len(rod.slots) == 1
    slot = rod.slots[0]
    length = (STROKE[1] - STROKE[0]) + spacing
    exact = length * hole_mm + math.pi * hole_mm ** 2 / 4
    assert slot.area() == pytest.approx(exact, abs=1e-6)
    # where the pins travel, in the rod's frame (solver poses)
    local = []
    for pose in motion.pose("rod"):
        c, s = math.cos(pose[2]), math.sin(pose[2])
        for hole in guides.values():
            dx, dy = hole.centre - pose[:2]
            local.append([c * dx + s * dy, -s * dx + c * dy])
    local = np.array(local)
    reach = shapely.MultiPoint(local).convex_hull.buffer(hole_mm / 2, 256)
    slot_poly = shapely.Polygon(slot.polygon(0.001))
    assert slot_poly.symmetric_difference(reach).area < 1e-2
    pin_room = slot_poly.buffer(1e-6)
    assert all(pin_room.contains(shapely.Point(p).buffer(sla_process.pin_diameter_mm / 2, 64)) for p in local)
    # the rod plate: hull of the bosses about its own points and about both ends of the pin travel
    c, s = math.cos(ANGLE), math.sin(ANGLE)
    along = local @ np.array([c * 0.6 + s * 0.8, -s * 0.6 + c * 0.8])  # the unit axis seen from the rod
    travel_ends = local[[np.argmin(along), np.argmax(along)]]
    bosses = [shapely.Point(p).buffer(boss, 1024) for p in [*travel_ends, *mech.body("rod").points.values()]]
    hull = shapely.union_all(bosses).convex_hull
    assert rod.outline.area() == pytest.approx(hull.area, abs=1e-2)
    assert all(h.pin_diameter_mm == 2.0 for h in rod.holes)

    rings = rod.polygons(0.005)
    assert shapely.LinearRing(rings[0]).is_ccw
    assert not any(shapely.LinearRing(r).is_ccw for r in rings[1:])
    assert len(rings) == 1 + len(rod.holes) + 1
    plate = shapely.Polygon(rings[0], rings[1:])
    expected = rod.outline.area() - len(rod.holes) * math.pi * hole_mm ** 2 / 4 - exact
    assert plate.area == pytest.approx(expected, abs=0.005 * (bulge_length(rod.outline) + 3 * math.pi * hole_mm
                                                              + 2 * length))
    assert rod.area_mm2() == pytest.approx(expected, abs=1e-6)


def bulge_length(path: BulgePath) -> float:
    """Length of a bulge path (chords for lines, r x angle for arcs)."""
    total = 0.0
    for i, b in enumerate(path.bulges):
        chord = float(np.hypot(*(path.vertices[(i + 1) % len(path.vertices)] - path.vertices[i])))
        theta = 4 * math.atan(abs(float(b)))
        total += chord if b == 0 else chord / (2 * math.sin(theta / 2)) * theta
    return total


def test_a_slot_that_would_cut_into_a_rod_point_is_refused(sla_process):
    """A rod point T 2 mm beside the slide line, level with G: the guide slot (2.7 mm wide) along the line
    would cut into T's 2.7 mm hole whichever side the guide pin goes, so the build stops and names the
    slider, the rod and the point (the user has to move one of them)."""
    mech = tilted_slider(0.0, across=2.0)
    with pytest.raises(GeometryError, match=r"slider G: the guide slot in 'rod' runs into its point 'T'"):
        build_parts(design_for(sla_process), mech, mech.sweep(9), [])


# -- a curved fingertip pad and a gear on one body --------------------------------------------------

def test_curved_pad_and_gear_fuse_into_one_plate(four_bar, sla_process):
    """The coupler of the sun/planet four-bar carries the planet (about A) and a curved pad: the circular
    segment of the circle of radius 36 about its point C = (40, 36) cut off by the chord from B = (40, 0) to
    E = (76, 36). Its plate is the union of the hull of the bosses (radius 2.35) about A, B, C, E, the pad
    segment (the quarter disc beyond the chord x - y = 40), the planet outline (axis at A, turned by 0: A - O
    lies on +x in the crank) and its hub (diameter 2 x 2.35 = 4.7), each built here with shapely on dense
    circles. Tolerance: chord tolerance 0.005 mm x boundary length (~1.0 mm^2; the pad alone adds ~256 mm^2)."""
    bodies = tuple(Body("coupler", {**b.points, "C": (40.0, 36.0), "E": (76.0, 36.0)}) if b.name == "coupler" else b
                   for b in four_bar.bodies)
    padded = Mechanism(name="padded", bodies=bodies, ground=four_bar.ground, joints=four_bar.joints, gears=(),
                       drivers=four_bar.drivers, input_range=four_bar.input_range, assembly=four_bar.assembly)
    motion = padded.sweep(13)
    mech = sun_planet_four_bar(padded)  # the gear record only places the gears (as in the parts-layer tests below)
    planet = spur_like(6.0, 8, 0.4)
    pair = SimpleNamespace(name="sun_planet", body_a="ground", body_b="coupler", axis_a="O", axis_b="A",
                           outline_a=spur_like(9.0, 12, 0.4), outline_b=planet)
    hints = PartHints(pads={"coupler": PadHint("C", arc=("B", "E"))})
    coupler = build_parts(design_for(sla_process), mech, motion, [pair], hints).part("coupler")
    boss = (2.0 + 2 * 0.25 + 0.2) / 2 + 1.0
    points = [(0.0, 0.0), (40.0, 0.0), (40.0, 36.0), (76.0, 36.0)]
    hull = shapely.union_all([shapely.Point(p).buffer(boss, 1024) for p in points]).convex_hull
    beyond_chord = shapely.Polygon([(40.0, 0.0), (76.0, 36.0), (140.0, -28.0)])  # the side x - y > 40
    segment = shapely.Point(40.0, 36.0).buffer(36.0, 4096).intersection(beyond_chord)
    hub = shapely.Point(0.0, 0.0).buffer(2 * boss / 2, 1024)
    expected = shapely.union_all([hull, segment, shapely.Polygon(planet), hub])
    plate = shapely.Polygon(coupler.outline.polygon(0.005))
    chords = 0.005 * expected.length  # inscribed chords lose at most sagitta x boundary length
    assert plate.area == pytest.approx(expected.area, abs=chords)
    assert plate.symmetric_difference(expected).area < chords


def coupler_with_arc_pad(four_bar: Mechanism, process, pts: dict) -> Part:
    """The four-bar's coupler part with points C, E1, E2 added and a pad arc about C from E1 to E2."""
    bodies = tuple(Body("coupler", {**b.points, **pts}) if b.name == "coupler" else b for b in four_bar.bodies)
    mech = Mechanism(name="arc_pad", bodies=bodies, ground=four_bar.ground, joints=four_bar.joints, gears=(),
                     drivers=four_bar.drivers, input_range=four_bar.input_range, assembly=four_bar.assembly)
    hints = PartHints(pads={"coupler": PadHint("C", arc=("E1", "E2"))})
    return build_parts(design_for(process), mech, mech.sweep(7), [], hints).part("coupler")


def test_a_pad_arc_flatter_than_the_chord_tolerance_is_just_its_bosses(four_bar, sla_process):
    """A pad arc of 0.01 rad on a 10 mm circle about C = (30, 10) of the coupler (chord 0.1 mm, sagitta
    0.125 um < the 5 um chord tolerance): its segment is the chord itself, so the plate is the hull of the
    bosses about A, B, C, E1, E2 (built here with shapely on dense circles; tolerance 0.005 mm x boundary
    length). It once failed with shapely's bare ValueError (a two-point ring)."""
    a = 0.01
    pts = {"C": (30.0, 10.0), "E1": (40.0, 10.0), "E2": (30.0 + 10 * math.cos(a), 10.0 + 10 * math.sin(a))}
    coupler = coupler_with_arc_pad(four_bar, sla_process, pts)
    boss = (2.0 + 2 * 0.25 + 0.2) / 2 + 1.0
    points = [(0.0, 0.0), (40.0, 0.0), *pts.values()]
    expected = shapely.union_all([shapely.Point(p).buffer(boss, 1024) for p in points]).convex_hull
    plate = shapely.Polygon(coupler.outline.polygon(0.005))
    assert plate.symmetric_difference(expected).area < 0.005 * expected.length


def test_a_pad_arc_of_two_chords_adds_its_triangle(four_bar, sla_process):
    """At the largest chord tolerance (1 mm) a pad arc of 0.9 rad on a 36 mm circle about C = (20, -36) splits
    into two chords (each sagitta 36 (1 - cos 0.225) = 0.91 mm <= 1 < 3.58 mm for one chord): its segment is
    the triangle of the chord ends and the arc's midpoint, whose apex stands 3.58 mm off the chord, beyond the
    2.35 mm bosses (6.6 mm^2 of it beyond their hull, by shapely on dense circles). The plate holds the whole
    triangle and the apex is on its outline (1e-6 mm): at this tolerance the bosses themselves are coarse
    polygons, so the plate is not compared with dense circles."""
    import dataclasses

    process = dataclasses.replace(sla_process, chord_tolerance_mm=1.0)
    centre, r, half = np.array([20.0, -36.0]), 36.0, 0.45
    start = centre + r * np.array([math.sin(-half), -math.cos(-half)])
    end = centre + r * np.array([math.sin(half), -math.cos(half)])
    mid = centre + r * np.array([0.0, -1.0])
    pts = {"C": tuple(centre), "E1": tuple(start), "E2": tuple(end)}
    coupler = coupler_with_arc_pad(four_bar, process, pts)
    boss = (2.0 + 2 * 0.25 + 0.2) / 2 + 1.0
    points = [(0.0, 0.0), (40.0, 0.0), *pts.values()]
    hull = shapely.union_all([shapely.Point(p).buffer(boss, 1024) for p in points]).convex_hull
    triangle = shapely.Polygon([start, mid, end])
    assert triangle.difference(hull).area > 5.0  # the triangle matters (6.6 mm^2 beyond the bosses)
    plate = shapely.Polygon(coupler.outline.polygon(0.005))
    assert plate.buffer(1e-6).contains(triangle)  # the arc's midpoint, on the pad's true arc, is on the plate
    assert plate.exterior.distance(shapely.Point(mid)) < 1e-6


# -- a pin through a skipped layer: printed spacer, roles, heights, BOM -----------------------------

def test_printed_spacer_roles_heights_and_bill_of_materials(sla_process):
    """A compact four-bar (crank 12, coupler 25, rocker 20, ground 25 mm) with 10 mm wide links on SLA: the
    bosses crowd each other, so some pin skips layers. Checked against the stack by hand (t = 3, g = 0.3):

    - every body part sits at z = layer x (t + g), carries the process and its role (ground / link);
    - a pin between layers lo and hi with nothing in between gets a spacer of (hi - lo) (t + g) - t; when
      that is at least a plate thick it is printed as a part ``spacer_<pin>`` in the first body's frame: a
      disc of the boss diameter (10 mm) about the pin, bored 2.7 mm for the 2 mm pin, from z = lo (t + g) + t;
    - the BOM (two copies) lists every part twice, the two mounting screws (M2.5, as asked) per copy, no
      purchased spacer (it is printed), one washer per pin joining neighbouring layers; a ``copies`` hint of
      None means one set.
    """
    t, g = 3.0, 0.3
    mech = make_four_bar(12.0, 25.0, 20.0, 25.0)
    motion = mech.sweep(61)
    design = design_for(sla_process, PartsSpec(link_width_mm=10.0, mounting_hole_mm=2.5))
    partset = build_parts(design, mech, motion, [], PartHints(copies=2))
    layers = partset.layers
    # what the exporters read from the part set: the process and its plate, gap, kerf and chord tolerance
    assert (partset.process, partset.thickness_mm, partset.layer_gap_mm, partset.kerf_mm) == ("sla", t, g, 0.0)
    assert partset.chord_tolerance_mm == 0.005
    assert (partset.copies, partset.hints, partset.warnings) == (2, PartHints(copies=2), ())
    for part in partset.body_parts():
        assert part.z_mm == pytest.approx(layers[part.body] * (t + g), abs=1e-12)
        assert part.process == "sla"
        assert part.role == ("ground" if part.body == "ground" else "link")
    spacers = [p for p in partset.parts if p.role == "spacer"]
    expected_spacers = {}
    for joint in mech.joints:
        lo, hi = sorted((layers[joint.body_a], layers[joint.body_b]))
        length = (hi - lo) * (t + g) - t
        if length >= t:
            expected_spacers[f"spacer_{joint.name}"] = (joint, lo, length)
    assert expected_spacers, "the crowded four-bar must skip a layer somewhere"
    assert sorted(p.name for p in spacers) == sorted(expected_spacers)
    for part in spacers:
        joint, lo, length = expected_spacers[part.name]
        assert part.body == joint.body_a and part.process == "sla"
        centre = mech.body(joint.body_a).point(joint.name)
        assert part.thickness_mm == pytest.approx(length, abs=1e-12)
        assert part.z_mm == pytest.approx(lo * (t + g) + t, abs=1e-12)
        assert part.layer == lo + 1
        ring = shapely.Polygon(part.outline.polygon(0.001))
        assert ring.area == pytest.approx(math.pi * 5.0 ** 2, abs=2 * math.pi * 5.0 * 0.001)
        assert ring.centroid.distance(shapely.Point(centre)) < 1e-9
        (hole,) = part.holes
        assert hole.joint == joint.name and hole.diameter_mm == pytest.approx(2.7, abs=1e-12)
        assert hole.pin_diameter_mm == 2.0
        np.testing.assert_allclose(hole.centre, centre, atol=1e-12)
    bom = partset.bom
    rows = {r["item"]: r for r in bom if r["kind"] == "printed part"}
    assert set(rows) == {p.name for p in partset.parts} and all(r["qty"] == 2 for r in rows.values())
    # M2.5 through the 3 mm plate and a 0.5 mm washer, 1.5 d = 3.75 mm engaged: 7.25 -> the 8 mm screw
    assert [(r["item"], r["qty"]) for r in bom if r["kind"] == "screw"] == [("ISO 4762 M2.5 × 8", 2 * 2)]
    assert not [r for r in bom if r["kind"] == "spacer"]
    neighbours = sum(abs(layers[j.body_a] - layers[j.body_b]) == 1 for j in mech.joints)
    pin_washers = [r for r in bom if r["kind"] == "washer" and not r["joints"][0].startswith("mount_")]
    assert [r["item"] for r in pin_washers] == ["DIN 125-A 2.2"]  # one 0.3 mm washer fills each 0.3 mm gap
    assert sum(r["qty"] for r in pin_washers) == 2 * neighbours
    single = build_parts(design, mech, motion, [], PartHints(copies=None))
    assert single.copies == 1 and all(r["qty"] == 1 for r in single.bom if r["kind"] == "printed part")


def test_gaps_thinner_than_a_plate_stay_washers(sla_process):
    """SLA prints a spacer only when it is at least a plate (3 mm) thick and buys the thinner ones as washers.
    With a 2 mm layer gap the gaps between neighbouring layers are 2 mm: washers in the BOM (one per pin
    joining neighbouring layers), not printed parts; the pin skipping layers gets a printed spacer at least
    a plate thick ((hi - lo) (t + g) - t by hand)."""
    import dataclasses

    mech = make_four_bar(12.0, 25.0, 20.0, 25.0)
    process = dataclasses.replace(sla_process, layer_gap_mm=2.0)
    partset = build_parts(design_for(process, PartsSpec(link_width_mm=10.0)), mech, mech.sweep(61), [])
    t, layers = process.thickness_mm, partset.layers
    skips = {j.name: abs(layers[j.body_a] - layers[j.body_b]) for j in mech.joints}
    printed = {p.name: p.thickness_mm for p in partset.parts if p.role == "spacer"}
    assert printed == pytest.approx({f"spacer_{n}": k * (t + 2.0) - t for n, k in skips.items() if k > 1})
    # a 2 mm gap: six 0.3 mm DIN 125-A 2.2 washers (1.8 mm, the most that fits), 0.2 mm of axial play
    (washers,) = [r for r in partset.bom if r["kind"] == "washer" and not r["joints"][0].startswith("mount_")]
    assert washers["item"] == "DIN 125-A 2.2" and washers["length_mm"] == pytest.approx(0.3)
    assert washers["qty"] == 6 * sum(k == 1 for k in skips.values())


def test_overlapping_holes_are_refused_wherever_the_body_frame_sits(sla_process):
    """The four-bar with the crank's frame at the middle of the crank (O at (-7.5, 0), A at (7.5, 0)): a 15 mm
    pin makes the two 15.7 mm holes 15 mm apart run into each other, so the build refuses naming the pin
    field and both holes; the frame's origin must not matter (the holes are 15 mm apart, not 0)."""
    import dataclasses

    base = make_four_bar()
    th = math.radians(60.0)
    bodies = tuple(Body("crank", {"O": (-7.5, 0.0), "A": (7.5, 0.0)}) if b.name == "crank" else b for b in base.bodies)
    mech = Mechanism(name="centred", bodies=bodies, ground=base.ground, joints=base.joints, gears=(),
                     drivers=base.drivers, input_range=base.input_range,
                     assembly={**base.assembly, "crank": (7.5 * math.cos(th), 7.5 * math.sin(th), th)})
    fat = dataclasses.replace(sla_process, pin_diameter_mm=15.0)
    with pytest.raises(SpecError, match=r"process.pin_diameter_mm: 15 mm pins: holes O and A of part crank"):
        build_parts(design_for(fat), mech, mech.sweep(11), [])


# -- distances, guide side, overlapping cuts ------------------------------------------------------

@pytest.mark.parametrize(("point", "ends", "expected"), [
    ((0.25, 1.0), ((0.0, 0.0), (0.5, 0.0)), 1.0),  # beside a short (0.5 mm) segment: perpendicular
    ((0.1, -0.3), ((0.0, 0.0), (0.2, 0.0)), 0.3),
    ((-0.3, 0.4), ((0.0, 0.0), (0.5, 0.0)), 0.5),  # behind the first end: distance to that end
    ((0.8, 0.4), ((0.0, 0.0), (0.5, 0.0)), 0.5),  # beyond the second end
    ((4.0, 7.0), ((1.0, 3.0), (1.0, 3.0)), 5.0),  # a segment of zero length is its point
    ((2.0, 9.0), ((-3.0, 4.0), (7.0, -1.0)), 3.0 * math.sqrt(5.0)),  # beside a long tilted segment
])
def test_segment_distance_matches_the_closed_form(point, ends, expected):
    """The distance of a point to a segment: the perpendicular distance where the foot falls on the
    segment, the distance to the nearer end otherwise, the distance to the point for a zero-length
    segment (hand values: 3-4-5 triangles; for the tilted case |(5, 5) x (10, -5)| / sqrt 125 = 3 sqrt 5).
    Short segments (< 1 mm) included. Tolerance 1e-12 mm."""
    got = _segment_distance(np.array(point), np.array(ends))
    assert got == pytest.approx(expected, abs=1e-12)


def slot_clearance(others: list[tuple[float, float]], rod_point: np.ndarray, axis: np.ndarray,
                   s_min: float, s_max: float, e: float) -> float:
    """Clearance (mm) of the rod's other points from where two guide pins travel in the rod (one at the
    slider point, one e mm further along the axis in the reference body), by shapely."""
    travel = [rod_point - (s - off) * axis for s in (s_min, s_max) for off in (0.0, e)]
    segment = shapely.MultiPoint(travel).convex_hull
    return min(segment.distance(shapely.Point(p)) for p in others)


@pytest.mark.parametrize(("others", "s_min", "s_max"), [
    ([(8.0, 3.0)], 0.0, 5.0),  # beside the + side's extension only: the - side is clear of it
    ([(-8.0, 3.0)], 0.0, 5.0),
    ([(0.5, 3.0)], 0.0, 5.0),  # near the stroke's front end: the - side keeps it 3.04 mm away, + 3 mm
    ([(0.1, 3.0)], 0.0, 0.5),  # a stroke shorter than 1 mm
    ([(-5.5, 3.0)], 0.0, 5.0),
    ([(2.0, 1.0), (-9.0, 0.5)], -1.0, 3.0),
])
@pytest.mark.parametrize("turn", [0.0, math.atan2(4.0, 3.0)], ids=["axis_x", "axis_34"])
def test_guide_pin_goes_on_the_side_keeping_the_slot_clear(others, s_min, s_max, turn):
    """The second guide pin goes at +spacing or -spacing along the slide axis, whichever keeps the slot
    (the travel of both pins in the rod) further from the rod's other points; the clearances are
    computed here with shapely from the pins' travel, and the chosen side's clearance is the larger one
    (each case below differs by more than 1e-3 mm). The scene is given along x and turned by atan2(4, 3)
    about the slider point (3, -2)."""
    spacing = 6.3
    rod_point = np.array([3.0, -2.0])
    c, s = math.cos(turn), math.sin(turn)
    rot = np.array([[c, -s], [s, c]])
    axis = rot @ np.array([1.0, 0.0])
    placed = [tuple(rod_point + rot @ np.array(p)) for p in others]
    rod = Body("rod", {"G": tuple(rod_point), **{f"P{k}": p for k, p in enumerate(placed)}})
    plus = slot_clearance(placed, rod_point, axis, s_min, s_max, spacing)
    minus = slot_clearance(placed, rod_point, axis, s_min, s_max, -spacing)
    assert abs(plus - minus) > 1e-3
    expected = spacing if plus > minus else -spacing
    assert _guide_spacing(rod, "G", rod_point, axis, s_min, s_max, spacing) == expected


def test_guide_pin_side_ties_and_a_rod_without_other_points():
    """Other points mirror-placed so both sides clear them by exactly 2 mm: the first side (+spacing) is
    kept (the build does not flip on float noise). A side that clears by 1e-9 mm or less more than the
    other is a tie too, a side clearing by 2e-9 mm more wins. A rod with no other point takes +spacing."""
    axis, g = np.array([1.0, 0.0]), np.zeros(2)
    mirrored = Body("rod", {"G": (0.0, 0.0), "P": (8.0, 0.0), "Q": (-12.0, 0.0)})  # slots [-4, 6] / [-10, 0]
    assert _guide_spacing(mirrored, "G", g, axis, 0.0, 4.0, 6.0) == 6.0
    for extra, side in ((1e-9, 6.0), (2e-9, -6.0)):
        # P beside the + extension only, Q beside the - extension only: clearances 3 and 3 + extra
        rod = Body("rod", {"G": (0.0, 0.0), "P": (3.0, 3.0), "Q": (-7.0, 3.0 + extra)})
        assert _guide_spacing(rod, "G", g, axis, 0.0, 4.0, 6.0) == side
    assert _guide_spacing(Body("rod", {"G": (0.0, 0.0)}), "G", g, axis, 0.0, 4.0, 6.0) == 6.0


def test_overlapping_cuts_name_exactly_the_holes_that_meet():
    """Holes of one part run into each other when their centres are closer than the sum of their radii;
    the warning names both holes (in the part's order) and the overlap (sum of radii - distance, by hand),
    and names every slot a hole cuts into (distance of the hole's centre to the exact stadium less than
    its radius). Touching (zero web) is not an overlap. A part with nothing in the way gives no warning.

    Plate ``p``: A (10, 10) d 4 and B (12.5, 10) d 3 overlap by 1 mm; C (10, 14) d 4 touches A (distance 4);
    D (30, 10) d 2 and E (31.5, 10.5) d 1.2 overlap by 1.6 - sqrt(2.5) mm. Plate ``q`` with the slot
    (0, 0)-(40, 0), 2 mm wide: F (5, 1.8) d 2 runs in from the side (0.8 mm from the edge), G (41.9, 0) d 2 into
    the round end (0.9 mm from the arc; a coarse polygon of the arc, three chords, would put it 1.03 mm
    away), H (15, 0) d 1 sits in it, J (20, 2) d 2 touches the edge, K (30, 2.5) d 2 and
    L (-2.5, 0) d 2 clear it by 0.5 mm."""
    holes = (Hole("A", np.array([10.0, 10.0]), 4.0), Hole("B", np.array([12.5, 10.0]), 3.0),
             Hole("C", np.array([10.0, 14.0]), 4.0), Hole("D", np.array([30.0, 10.0]), 2.0),
             Hole("E", np.array([31.5, 10.5]), 1.2))
    in_slot = (Hole("F", np.array([5.0, 1.8]), 2.0), Hole("G", np.array([41.9, 0.0]), 2.0),
               Hole("H", np.array([15.0, 0.0]), 1.0), Hole("J", np.array([20.0, 2.0]), 2.0),
               Hole("K", np.array([30.0, 2.5]), 2.0), Hole("L", np.array([-2.5, 0.0]), 2.0))
    outline = BulgePath.polyline(np.array([[-5.0, -5.0], [45.0, -5.0], [45.0, 20.0], [-5.0, 20.0]]))
    plate = Part(name="p", body="p", outline=outline, holes=holes, thickness_mm=3.0, z_mm=0.0, layer=0,
                 process="sla")
    slotted = SlottedPart(name="q", body="q", outline=outline, holes=in_slot, thickness_mm=3.0, z_mm=0.0,
                          layer=1, process="sla", slots=(stadium((0.0, 0.0), (40.0, 0.0), 2.0),))
    clean = Part(name="r", body="r", outline=outline, holes=holes[:1] + holes[3:4], thickness_mm=3.0, z_mm=0.0,
                 layer=2, process="sla")
    found = overlapping_cuts([plate, slotted, clean])
    de = 1.6 - math.sqrt(1.5 ** 2 + 0.5 ** 2)
    assert found == [
        "part p: holes A and B overlap by 1.000 mm; move the joints apart or use a smaller pin",
        f"part p: holes D and E overlap by {de:.3f} mm; move the joints apart or use a smaller pin",
        "part q: hole F runs into a guide slot",
        "part q: hole G runs into a guide slot",
        "part q: hole H runs into a guide slot",
    ]


# -- the region the moving bodies sweep -------------------------------------------------------------

def placed_union(outlines: dict[str, BulgePath], motion, indices) -> shapely.Geometry:
    """Union (shapely) of each outline, polygonised at the conflict chord tolerance, placed at the given
    pose indices: x' = R(theta) x + (px, py), written out with cos and sin."""
    shapes = []
    for body, path in outlines.items():
        ring = path.polygon(CONFLICT_CHORD_MM)
        for x, y, th in motion.pose(body)[list(indices)]:
            c, s = math.cos(th), math.sin(th)
            shapes.append(shapely.Polygon(np.column_stack([c * ring[:, 0] - s * ring[:, 1] + x,
                                                           s * ring[:, 0] + c * ring[:, 1] + y])))
    return shapely.union_all(shapes)


def test_swept_region_is_the_union_of_the_outlines_at_every_pose():
    """A crank turned from 60 to 150 degrees over 13 poses and its coupler: the swept region is the
    union of each body's outline placed at every pose, the first and last (the extremes) included;
    compared with an independent shapely union (symmetric difference below 1e-6 mm^2). With no bodies
    the region is an empty polygon (area 0)."""
    mech = make_four_bar(start_deg=60.0, end_deg=150.0)
    motion = mech.sweep(13)
    outlines = {"crank": stadium((0.0, 0.0), (15.0, 0.0), 4.7), "coupler": stadium((0.0, 0.0), (40.0, 0.0), 4.7)}
    region = swept_region(outlines, motion)
    expected = placed_union(outlines, motion, range(13))
    assert region.area == pytest.approx(expected.area, abs=1e-6)
    assert region.symmetric_difference(expected).area < 1e-6
    # the first and the last pose matter here: leaving either out loses area
    assert placed_union(outlines, motion, range(1, 13)).area < expected.area - 1.0
    assert placed_union(outlines, motion, range(12)).area < expected.area - 1.0
    empty = swept_region({}, motion)
    assert isinstance(empty, shapely.Polygon) and empty.is_empty and empty.area == 0.0


def test_swept_region_samples_ninety_poses_evenly_on_a_long_sweep():
    """On a sweep of 181 poses the region is sampled at 90 poses spread evenly over the sweep, the first
    and the last included (index round(k x 180 / 89), k = 0..89); compared with an independent union at
    exactly those poses (symmetric difference below 1e-6 mm^2, while 91 or 50 poses differ by more)."""
    mech = make_four_bar(start_deg=60.0, end_deg=420.0)
    motion = mech.sweep(181)
    outlines = {"coupler": stadium((0.0, 0.0), (40.0, 0.0), 4.7)}
    region = swept_region(outlines, motion)
    picks = {round(k * 180 / 89) for k in range(90)}
    assert len(picks) == 90
    expected = placed_union(outlines, motion, sorted(picks))
    assert region.symmetric_difference(expected).area < 1e-6
    for other in (91, 50):
        alt = placed_union(outlines, motion, sorted({round(k * 180 / (other - 1)) for k in range(other)}))
        assert alt.symmetric_difference(expected).area > 1e-4


# -- fingertip pad segments -------------------------------------------------------------------------

@pytest.mark.parametrize("reverse", [False, True], ids=["ccw_ends", "cw_ends"])
@pytest.mark.parametrize("radius", [1.0, 36.0])
def test_pad_segment_is_ccw_whichever_way_the_ends_are_given(radius, reverse):
    """A quarter circle about (3, -2) from the end on +x to the end on +y (or the same two ends given the
    other way round): the ring is counter-clockwise (shoelace area > 0), every vertex lies on the chord's
    ends or the exact circle (1e-9 mm), on the far side of the chord, and its area is the circular
    segment r^2 (pi/2 - 1) / 2 (closed form; inscribed chords lose at most sagitta x arc length). The
    small case (r = 1, area 0.285 mm^2) is below 1 mm^2."""
    tol = 0.005
    centre = np.array([3.0, -2.0])
    ends = [centre + (radius, 0.0), centre + (0.0, radius)]
    start, end = ends[::-1] if reverse else ends
    ring = pad_segment(centre, start, end, tol)
    exact = 0.5 * radius ** 2 * (math.pi / 2 - 1.0)
    area = signed_area(ring)
    assert exact - tol * radius * math.pi / 2 <= area <= exact + 1e-12
    rel = ring - centre
    on_circle = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - radius) < 1e-9
    assert on_circle.all()  # the chord's ends are on the circle too
    assert np.all(rel[:, 0] + rel[:, 1] >= radius - 1e-9)  # beyond the chord x + y = r
    # the arc is split evenly and finely enough: sagitta of each piece within the tolerance
    chords = np.hypot(*np.diff(ring, axis=0).T)
    assert np.all(radius - np.sqrt(radius ** 2 - (chords / 2) ** 2) <= tol + 1e-12)


def test_pad_segment_ends_must_be_on_one_circle():
    """The two chord ends must be equally far from the centre, within 1e-6 of the radius (1e-6 mm below a
    1 mm radius); a radius mismatch of exactly that much is still accepted. Both ends at the centre
    (radius 0) are refused. Hand cases about the origin along the axes, so the radii are exact."""
    centre = np.zeros(2)

    def quarter(r0: float, r1: float) -> np.ndarray:
        return pad_segment(centre, np.array([r0, 0.0]), np.array([0.0, r1]), 0.005)

    quarter(36.0, 36.0 + 1e-5)  # 2.8e-7 relative: accepted
    with pytest.raises(GeometryError, match="not one circle"):
        quarter(36.0, 36.0 + 5e-5)  # 1.4e-6 relative
    quarter(0.5, 0.5 + 0.5e-6)
    with pytest.raises(GeometryError, match="not one circle"):
        quarter(0.5, 0.5 + 1.5e-6)  # below 1 mm the allowance is 1e-6 mm, not relative
    r0, r1 = 10.013580322265625, 10.013590335845947  # differ by exactly fl(1e-6 x r0)
    assert abs(r1 - r0) == 1e-6 * r0
    quarter(r0, r1)
    with pytest.raises(GeometryError, match="not one circle"):
        pad_segment(centre, centre, centre, 0.005)


# -- compound hinges -------------------------------------------------------------------------------

def test_pins_merge_only_where_their_holes_coincide():
    """Joints J (palm-a) and Jr (palm-b) whose holes in the palm are 0.3 mm apart along x, or 0.4 mm
    along y, stay two pins with their own holes; holes 3e-10 mm apart along each axis (solver noise) are
    one spot: one pin ``J+Jr`` through palm, a and b, with one palm hole (the first seen)."""
    joints = [("J", ("palm", "a")), ("Jr", ("palm", "b"))]
    for offset in ((0.3, 0.0), (0.0, 0.4)):
        other = np.array([1.0, 2.0]) + offset
        holes = [("J", "palm", np.array([1.0, 2.0])), ("J", "a", np.zeros(2)),
                 ("Jr", "palm", other), ("Jr", "b", np.zeros(2))]
        pins, out = merge_coincident_pins(joints, holes)
        assert pins == joints
        assert [(n, b) for n, b, _ in out] == [("J", "palm"), ("J", "a"), ("Jr", "palm"), ("Jr", "b")]
    noisy = np.array([1.0 + 3e-10, 2.0 - 3e-10])
    holes = [("J", "palm", np.array([1.0, 2.0])), ("J", "a", np.zeros(2)), ("Jr", "palm", noisy),
             ("Jr", "b", np.zeros(2))]
    pins, out = merge_coincident_pins(joints, holes)
    assert pins == [("J+Jr", ("palm", "a", "b"))]
    assert [(n, b) for n, b, _ in out] == [("J+Jr", "palm"), ("J+Jr", "a"), ("J+Jr", "b")]
    np.testing.assert_array_equal(out[0][2], [1.0, 2.0])


# -- holes that run into each other ----------------------------------------------------------------

def plate_with(holes: tuple[Hole, ...]) -> Part:
    outline = BulgePath.polyline(np.array([[-5.0, -5.0], [20.0, -5.0], [20.0, 5.0], [-5.0, 5.0]]))
    return Part(name="plate", body="plate", outline=outline, holes=holes, thickness_mm=3.0, z_mm=0.0, layer=0,
                process="sla")


def test_touching_or_overlapping_pin_holes_are_refused(sla_process):
    """With wall 0.5, clearance 0.25 and no hole compensation (min pin 1.5 mm), holes O (0, 0) and A
    (2.5, 0) of 2.5 mm touch (web 0): refused, naming the holes in the part's order and the largest pin
    that leaves the wall: 2.5 - 0.5 - 2 x 0.25 = 1.5 mm, exactly the process's smallest pin, so it is
    offered. Holes 0.9 mm apart leave room for no pin of the process (largest -0.1 mm). Two joint names
    through one hole (merged pins, distance 0) and mounting holes are not checked against each other."""
    import dataclasses

    process = dataclasses.replace(sla_process, min_wall_mm=0.5, hole_compensation_mm=0.0, min_pin_mm=1.5)
    far = Hole("B", np.array([12.0, 0.0]), 2.5, 2.0)
    touching = plate_with((Hole("O", np.zeros(2), 2.5, 2.0), Hole("A", np.array([2.5, 0.0]), 2.5, 2.0), far))
    with pytest.raises(SpecError, match=r"holes O and A of part plate are 2.5 mm apart and would leave 0 mm of "
                                        r"wall between them \(the process needs 0.5 mm\); at most 1.5 mm$"):
        _check_pin_webs([touching], process)
    close = plate_with((Hole("O", np.zeros(2), 2.5, 2.0), Hole("A", np.array([0.0, 0.9]), 2.5, 2.0), far))
    with pytest.raises(SpecError, match=r"holes O and A of part plate are 0.9 mm apart .*; no pin of the "
                                        r"process fits; move the joints apart$"):
        _check_pin_webs([close], process)
    merged = plate_with((Hole("J", np.array([3.0, 1.0]), 2.5, 2.0), Hole("Jr", np.array([3.0, 1.0]), 2.5, 2.0),
                         Hole("mount_1", np.array([4.0, 1.0]), 2.5), far))
    _check_pin_webs([merged], process)  # no error


# -- layers: clearance between bodies, spacers on a compound pin ------------------------------------

def world(pose: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Body-frame points (n, 2) placed at a pose (x, y, theta), written out with cos and sin."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return np.column_stack([c * points[:, 0] - s * points[:, 1] + pose[0],
                            s * points[:, 0] + c * points[:, 1] + pose[1]])


def test_layering_sees_bodies_and_spacers_within_the_running_clearance(sla_process, monkeypatch):
    """The default four-bar with 24.76 mm wide links, the crank turning from 358 to 362 degrees over 61
    poses (so the bodies hardly move between samples). The crank (O-A) and the rocker (D-B) share no pin;
    their centre segments come 25 mm apart at the closest (shapely; A and D at crank angle 360), so their
    plates (stadia of radius 12.38 mm) come 0.24 mm apart, inside the 0.25 mm running clearance: the
    conflict graph the layering colours joins them, and they get different layers.

    The pin crossings (a body passing over the spacer that would fill skipped layers of a pin) are, for
    every pin (first body a, second body b) and every other body c, exactly the triples (a, b, c) where c's
    plate comes within the clearance of the spacer disc (boss radius about the pin) at some pose; computed
    here with shapely on the plates (0.001 mm polygons) in the world. Pairs measured between 0.25 and 0.35 mm
    (where the 0.05 mm conflict outlines may decide either way) are not judged; at least one pair lies below
    0.25 and the rest beyond 0.35. (Conflict graph and crossings are read by wrapping the layer functions.)"""
    import fabricate.parts.build as build

    seen = {}

    def spy(name, fn):
        def wrapped(*args, **kwargs):
            out = fn(*args, **kwargs)
            seen.setdefault(name, out)  # the first call: the spacer crossings (later ones: pin ends)
            return out
        monkeypatch.setattr(build, name, wrapped)

    spy("conflict_graph", build.conflict_graph)
    spy("pin_crossings", build.pin_crossings)
    mech = make_four_bar(start_deg=358.0, end_deg=362.0)
    motion = mech.sweep(61)
    o, a = motion.point("O", "crank"), motion.point("A", "crank")
    d, b = motion.point("D", "rocker"), motion.point("B", "rocker")
    crank = [shapely.LineString([o[i], a[i]]) for i in range(61)]
    rocker = [shapely.LineString([d[i], b[i]]) for i in range(61)]
    assert min(c.distance(r) for c, r in zip(crank, rocker, strict=True)) == pytest.approx(25.0, abs=1e-6)
    width = 24.76
    plates = [c.buffer(width / 2, 128).distance(r.buffer(width / 2, 128)) for c, r in zip(crank, rocker, strict=True)]
    assert min(plates) == pytest.approx(0.24, abs=1e-3)
    partset = build_parts(design_for(sla_process, PartsSpec(link_width_mm=width)), mech, motion, [])
    assert "rocker" in seen["conflict_graph"]["crank"]
    assert partset.layers["crank"] != partset.layers["rocker"]

    boss = width / 2
    outlines = {p.body: p.outline.polygon(0.001) for p in partset.body_parts()}
    near, judged = set(), set()
    for joint in mech.joints:
        first, second = joint.body_a, joint.body_b
        centre = mech.body(first).point(joint.name)
        for other in mech.body_names:
            if other in (first, second):
                continue
            gap = min(shapely.Point(world(pa, centre[None, :])[0]).buffer(boss, 128).distance(
                shapely.Polygon(world(pc, outlines[other])))
                for pa, pc in zip(motion.pose(first), motion.pose(other), strict=True))
            if gap < 0.25:
                near.add((first, second, other))
            if not 0.25 <= gap <= 0.35:
                judged.add((first, second, other))
    assert near
    assert {t for t in seen["pin_crossings"] if t in judged} == near
    assert set(seen["pin_crossings"]) <= {(j.body_a, j.body_b, c) for j in mech.joints for c in mech.body_names
                                          if c not in (j.body_a, j.body_b)}


def flapped_four_bar() -> Mechanism:
    """The default four-bar plus a flap turning with the crank about the ground's point Or, which sits
    on O: joints O (ground-crank) and Or (ground-flap) share one spot of the ground, a compound hinge
    through ground, crank and flap."""
    base = make_four_bar()
    bodies = tuple(Body("ground", {**b.points, "Or": (0.0, 0.0)}) if b.name == "ground" else b for b in base.bodies)
    return Mechanism(name="flapped", bodies=(*bodies, Body("flap", {"Or": (0.0, 0.0), "F": (10.0, 0.0)})),
                     ground="ground", joints=(*base.joints, Revolute("Or", "ground", "flap")), gears=(),
                     drivers=(*base.drivers, Driver("angle", "flap", "ground")), input_range=base.input_range,
                     assembly={**base.assembly, "flap": base.assembly["crank"]})


def test_spacer_check_gets_each_compound_pin_in_its_own_body_frame(sla_process, monkeypatch):
    """The flapped four-bar with the crank's frame moved off its pin (O at (3, 1) in the crank, same link): every
    pin handed to the spacer-crossing check, placed with its body a's poses, is at the pin's world position
    over the whole motion (1e-9 mm), for the compound pin's pairs (crank, flap) too (they were once given the
    pin in the first body's frame, the ground's, so the check looked for the crank-flap spacer 3.2 mm off)."""
    import fabricate.parts.build as build

    base = flapped_four_bar()
    shift = np.array([3.0, 1.0])
    bodies = tuple(Body("crank", {k: tuple(np.asarray(v) + shift) for k, v in b.points.items()})
                   if b.name == "crank" else b for b in base.bodies)
    x, y, th = base.assembly["crank"]
    origin = np.array([x, y]) - np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]]) @ shift
    mech = Mechanism(name="flapped_shifted", bodies=bodies, ground="ground", joints=base.joints, gears=(),
                     drivers=base.drivers, input_range=base.input_range,
                     assembly={**base.assembly, "crank": (float(origin[0]), float(origin[1]), th)})
    motion = mech.sweep(13)
    seen = []
    real = build.pin_crossings

    def spy(outlines, world_poses, pins, *args):
        seen.extend(pins)
        return real(outlines, world_poses, pins, *args)

    monkeypatch.setattr(build, "pin_crossings", spy)
    build_parts(design_for(sla_process), mech, motion, [])
    pairs = {(a, b) for _, a, b in seen}
    assert {("ground", "crank"), ("ground", "flap"), ("crank", "flap")} <= pairs
    world_pin = {frozenset(("ground", "crank")): motion.point("O", "ground"),
                 frozenset(("ground", "flap")): motion.point("Or", "ground"),
                 frozenset(("crank", "flap")): motion.point("O", "ground")}
    for centre, a, b in seen:
        if frozenset((a, b)) not in world_pin:
            continue
        pose = motion.pose(a)
        c, s_ = np.cos(pose[:, 2]), np.sin(pose[:, 2])
        placed = np.column_stack([c * centre[0] - s_ * centre[1], s_ * centre[0] + c * centre[1]]) + pose[:, :2]
        np.testing.assert_allclose(placed, world_pin[frozenset((a, b))], atol=1e-9, err_msg=f"{a}-{b}")


def test_printed_spacers_on_one_compound_pin_are_numbered_bottom_up(sla_process, monkeypatch):
    """A compound hinge through ground, crank and flap, with the stack forced (the layer ordering is
    replaced here) to ground 0, coupler 1, crank 2, rocker 3, flap 4: the compound pin ``O+Or`` skips a
    layer twice, so it carries two printed spacers, named ``spacer_O_Or_1`` (from z = t = 3) and
    ``spacer_O_Or_2`` (from z = 2 (t + g) + t = 9.6), each (t + 2 g) = 3.6 mm long (by hand, t = 3,
    g = 0.3); the pins B (layers 1-3) and D (0-3) carry one printed spacer each, named without a number;
    A (layers 2 and 1) takes a washer."""
    import fabricate.parts.build as build

    forced = {"ground": 0, "coupler": 1, "crank": 2, "rocker": 3, "flap": 4}
    monkeypatch.setattr(build, "order_layers", lambda layers, crossings, **_: dict(forced))
    mech = flapped_four_bar()
    partset = build_parts(design_for(sla_process), mech, mech.sweep(13), [])
    assert partset.layers == forced
    spacers = {p.name: (p.z_mm, p.thickness_mm) for p in partset.parts if p.role == "spacer"}
    assert spacers == {"spacer_O_Or_1": pytest.approx((3.0, 3.6)), "spacer_O_Or_2": pytest.approx((9.6, 3.6)),
                       "spacer_B": pytest.approx((6.3, 3.6)), "spacer_D": pytest.approx((3.0, 6.9))}


# -- a body that just clears (or not) a pin's spacer; a guide pin in a guide slot ----------------------------

def stop_arm(gap: float) -> Mechanism:
    """A crank (O-A, 15 mm) turning a full circle about the ground's O, and a stop arm pinned at the ground's
    P = 25 u, held at the fixed angle phi = pi / 48 (a second driver with a zero-slope law), u = (cos phi,
    sin phi). The arm's other point Q is at 2 r + ``gap`` along u from O (r = 2.35, the SLA boss radius), so
    the arm's end boss is ``gap`` mm from a boss-sized spacer disc about O. The direction phi lies halfway
    between two corners of the 48-gon the spacer check draws around the spacer. Bodies listed ground, arm,
    crank: the colouring stacks them 0, 1, 2 unless something moves the arm."""
    phi = math.pi / 48
    u = np.array([math.cos(phi), math.sin(phi)])
    q = 2 * 2.35 + gap
    return Mechanism(
        name="stop_arm",
        bodies=(Body("ground", {"O": (0.0, 0.0), "P": (25.0 * u[0], 25.0 * u[1])}),
                Body("arm", {"P": (0.0, 0.0), "Q": (q - 25.0, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (15.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("P", "ground", "arm")), gears=(),
        drivers=(Driver("angle", "crank", "ground"), Driver("angle", "arm", "ground", law=LinearLaw(0.0, phi))),
        input_range=(0.0, 360.0), assembly={"crank": (0.0, 0.0, 0.0), "arm": (25.0 * u[0], 25.0 * u[1], phi)})


@pytest.mark.parametrize(("gap", "crosses"), [(0.22, True), (0.40, False)])
def test_a_body_within_the_running_clearance_of_a_spacer_is_kept_off_its_layers(sla_process, monkeypatch, gap,
                                                                                 crosses):
    """The stop arm's plate ends ``gap`` mm from the spacer (boss radius 2.35 mm about the crank pin O) that
    would fill the layers pin O skips (shapely on the 0.001 mm outline: within 1e-4 mm of ``gap``). All three
    bodies conflict (two pins; the crank sweeps over the arm), so they take three layers, ground 0, arm 1,
    crank 2 by body order: pin O skips the arm's layer. At 0.22 mm, inside the 0.25 mm running clearance (and
    0.03 mm outside what the 0.05 mm conflict outlines could lose), the arm would rub on that spacer: the
    spacer check must report (ground, crank, arm) and the arm must not sit between the ground's and the
    crank's layers. At 0.40 mm (beyond the clearance plus the outlines' 0.05 mm) nothing is reported and the
    stack stays as coloured. The arm does not move (margin between samples 0)."""
    import fabricate.parts.build as build

    calls = []
    real = build.pin_crossings

    def spy(*args):
        calls.append(real(*args))  # the first call: the spacer crossings (later ones: pin ends)
        return calls[-1]

    monkeypatch.setattr(build, "pin_crossings", spy)
    mech = stop_arm(gap)
    motion = mech.sweep(73)
    partset = build_parts(design_for(sla_process), mech, motion, [])
    pose = motion.pose("arm")
    assert np.ptp(pose, axis=0) == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    plate = shapely.Polygon(world(pose[0], partset.part("arm").outline.polygon(0.001)))
    assert shapely.Point(0.0, 0.0).buffer(2.35, 1024).distance(plate) == pytest.approx(gap, abs=1e-4)
    layers = partset.layers
    lo, hi = sorted((layers["ground"], layers["crank"]))
    assert sorted(layers.values()) == [0, 1, 2]
    seen = calls[0]
    if crosses:
        assert seen == [("ground", "crank", "arm")]
        assert not lo < layers["arm"] < hi, layers
    else:
        assert seen == []
        assert layers == {"ground": 0, "arm": 1, "crank": 2}


def stacked_rods(height: float) -> Mechanism:
    """Rod 1 slides along x on the ground (its point S1 through the ground's S1 at the origin, stroke 0 .. 10
    mm); rod 1 carries point S2 at (-5, ``height``), the guide of rod 2, which slides on rod 1 along (0, -1),
    half as far as rod 1 (a second driver, law 0.5 s)."""
    return Mechanism(
        name="stacked_rods",
        bodies=(Body("ground", {"S1": (0.0, 0.0)}), Body("rod1", {"S1": (0.0, 0.0), "S2": (-5.0, height)}),
                Body("rod2", {"S2": (0.0, 0.0)})),
        ground="ground",
        joints=(Slider("S1", "ground", "rod1", (1.0, 0.0)), Slider("S2", "rod1", "rod2", (0.0, -1.0))), gears=(),
        drivers=(Driver("slide", "rod1", "ground", joint="S1"),
                 Driver("slide", "rod2", "rod1", joint="S2", law=LinearLaw(0.5, 0.0))),
        input_range=(0.0, 10.0), input_unit="mm", assembly={"rod1": (0.0, 0.0, 0.0), "rod2": (-5.0, height, 0.0)})


@pytest.mark.parametrize(("height", "warned"), [(4.0, True), (10.0, False)])
def test_a_guide_pin_in_the_guiding_rods_own_slot_is_a_warning_of_the_part_set(sla_process, height, warned):
    """Rod 1 runs on two guide pins of the ground (its slot) and holds the two guide pins of rod 2. By hand
    (SLA: hole 2.7 mm, boss radius 2.35, guide spacing 2 x 2.35 + 2 x 0.8 = 6.3 mm): rod 2's second guide pin
    sits in rod 1 at S2 + 6.3 (0, -1) = (-5, h - 6.3); rod 1's slot is the 2.7 mm wide stadium along y = 0
    over x in [-10, 6.3]. At h = 4 that hole (radius 1.35) is 2.3 mm from the slot's centre line, less than
    1.35 + 1.35: it runs into the slot, so the part set, which is still built, carries exactly the warning
    naming rod 1 and the hole. At h = 10 it is 3.7 mm away: no warning. (The build's own refusal only looks
    at rod points, and S2 itself is h mm from the line.)"""
    mech = stacked_rods(height)
    partset = build_parts(design_for(sla_process), mech, mech.sweep(11), [])
    rod1 = partset.part("rod1")
    holes = {h.joint: h.centre for h in rod1.holes}
    np.testing.assert_allclose(holes["S2_guide"], [-5.0, height - 6.3], atol=1e-12)
    (slot,) = rod1.slots
    assert slot.area() == pytest.approx(16.3 * 2.7 + math.pi * 2.7 ** 2 / 4, abs=1e-9)
    expected = ("part rod1: hole S2_guide runs into a guide slot",) if warned else ()
    assert partset.warnings == expected


# == the parts layer as a whole (formerly tests/test_parts.py) ==================================================
DATA = json.loads((Path(__file__).resolve().parents[1] / "data" / "parts_expected.json").read_text())


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
    sla = derive_sizes(sla_process, PartsSpec(), PartHints())
    expected = DATA["sizes"]
    assert sla.hole_mm == pytest.approx(expected["sla_hole_mm"], abs=1e-9)  # 2 + 2*0.25 + 0.2
    assert sla.boss_radius_mm == pytest.approx(expected["sla_boss_radius_mm"], abs=1e-9)
    laser = derive_sizes(laser_process, PartsSpec(), PartHints())
    assert laser.hole_mm == pytest.approx(expected["laser_hole_mm"], abs=1e-9)  # 3 + 2*0.1
    # minimum web >= sheet thickness on the laser
    assert laser.boss_radius_mm - laser.hole_mm / 2 >= laser_process.thickness_mm - 1e-12
    wide = derive_sizes(sla_process, PartsSpec(link_width_mm=12.0), PartHints())
    assert wide.boss_radius_mm == pytest.approx(6.0)
    hinted = derive_sizes(sla_process, PartsSpec(), PartHints(link_width_mm=10.0))
    assert hinted.boss_radius_mm == pytest.approx(5.0)


# -- whole part sets --------------------------------------------------------------------------

@pytest.mark.parametrize("process_name", ["sla_process", "laser_process"])
def test_four_bar_parts(four_bar, process_name, request):
    process = request.getfixturevalue(process_name)
    motion = four_bar.sweep(181)
    partset = build_parts(design_for(process), four_bar, motion, [])
    sizes = derive_sizes(process, PartsSpec(), PartHints())
    by_body = {p.body: p for p in partset.body_parts()}
    assert set(by_body) == set(four_bar.body_names)
    for joint in four_bar.joints:
        for body in (joint.body_a, joint.body_b):
            hole = next(h for h in by_body[body].holes if h.joint == joint.name)
            np.testing.assert_allclose(hole.centre, four_bar.body(body).point(joint.name), atol=1e-12)
            pin = next(p for p in partset.pins if p.joint == joint.name)
            # the part holding a pressed pin has the press fit, the others the running fit (process profile)
            press = process.retention == "press" and body == pin.holder
            assert hole.fit == ("press" if press else "running")
            assert hole.diameter_mm == pytest.approx(sizes.press_hole_mm if press else sizes.hole_mm, abs=1e-9)
            assert hole.diameter_mm - hole.nominal_mm == pytest.approx(process.hole_compensation_mm, abs=1e-12)
        # bodies sharing a pin never share a layer
        assert partset.layers[joint.body_a] != partset.layers[joint.body_b]
    # a binary link is the rounded slot of its two bosses: area known in closed form
    crank = by_body["crank"]
    r, length = sizes.boss_radius_mm, 15.0
    area = 2 * r * length + math.pi * r * r - sum(math.pi * h.diameter_mm ** 2 / 4 for h in crank.holes)
    assert crank.area_mm2() == pytest.approx(area, rel=1e-12)
    assert crank.volume_mm3() == pytest.approx(area * process.thickness_mm, rel=1e-12)
    # ground carries the mounting holes
    assert sum(h.joint.startswith("mount_") for h in by_body["ground"].holes) == 2
    assert by_body["ground"].role == "ground"


def test_layers_keep_bodies_apart_over_the_motion(four_bar, sla_process):
    """Independent check: bodies in one layer never come within the clearance at any of 361 poses."""
    motion = four_bar.sweep(361)
    partset = build_parts(design_for(sla_process), four_bar, motion, [])
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
    partset = build_parts(design_for(sla_process), four_bar, four_bar.sweep(121), [])
    t, g = sla_process.thickness_mm, sla_process.layer_gap_mm
    for pin in partset.pins:
        lo, hi = pin.layers
        assert pin.stack_mm == pytest.approx((hi - lo) * (t + g) + t, abs=1e-12)
        assert pin.stack_z_mm[0] == pytest.approx(lo * (t + g), abs=1e-12)
        # the pin itself: a standard length, its ends beyond (or inside) the stack's faces
        assert pin.length_mm in ISO8734_LENGTHS_MM and pin.designation == f"ISO 8734 2 × {pin.length_mm:g}"
        assert pin.z_mm == pytest.approx(pin.stack_z_mm[0] - pin.protrusion_mm[0], abs=1e-12)
        assert pin.length_mm == pytest.approx(pin.stack_mm + sum(pin.protrusion_mm), abs=1e-12)
    spacer_total = {}
    for sp in partset.spacers:
        spacer_total[sp.joint] = spacer_total.get(sp.joint, 0.0) + sp.length_mm
    for pin in partset.pins:
        # plates plus spacers/washers fill the stack (0.3 mm gaps take one 0.3 mm DIN 125-A 2.2 washer)
        assert 2 * t + spacer_total.get(pin.joint, 0.0) == pytest.approx(pin.stack_mm, abs=1e-12)
    pins = [row for row in partset.bom if row["kind"] == "pin"]
    assert sum(row["qty"] for row in pins) == len(four_bar.joints)


def test_bom_copies_springs_and_purchased(four_bar, sla_process):
    hints = PartHints(copies=3, springs=(SpringHint("A", 30.0, 5.0, 10.0, "torsion"),),
                      purchased=(PurchasedItem("micro servo", 1, "driver"),),
                      purchased_shared=(PurchasedItem("base plate", 1, "holds all copies"),))
    partset = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [], hints)
    pins = sum(row["qty"] for row in partset.bom if row["kind"] == "pin")
    assert pins == 3 * len(four_bar.joints)
    assert next(r for r in partset.bom if r["kind"] == "spring")["qty"] == 3
    assert next(r for r in partset.bom if r["item"] == "micro servo")["qty"] == 3
    assert next(r for r in partset.bom if r["item"] == "base plate")["qty"] == 1
    json.dumps(partset.bom)  # JSON-ready


def test_pad_hint_adds_fingertip(four_bar, sla_process):
    plain = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [], PartHints())
    padded = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [],
                         PartHints(pads={"coupler": PadHint("B", 6.0)}))
    outline = shapely.Polygon(padded.part("coupler").outline.polygon(0.001))
    disc = shapely.Point(40.0, 0.0).buffer(6.0 - 1e-3, 256)
    assert outline.contains(disc)
    assert padded.part("coupler").area_mm2() > plain.part("coupler").area_mm2()
    with pytest.raises(GeometryError, match="no point"):
        build_parts(design_for(sla_process), four_bar, four_bar.sweep(11), [],
                    PartHints(pads={"coupler": PadHint("Z", 6.0)}))


def test_pad_hint_without_a_radius_is_a_boss_disc(four_bar, sla_process):
    # PadHint.radius_mm None: the boss radius, and at a joint point that boss is already there
    plain = build_parts(design_for(sla_process), four_bar, four_bar.sweep(11), [])
    padded = build_parts(design_for(sla_process), four_bar, four_bar.sweep(11), [],
                         PartHints(pads={"coupler": PadHint("B")}))
    assert padded.part("coupler").area_mm2() == pytest.approx(plain.part("coupler").area_mm2(), rel=1e-12)


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
    partset = build_parts(design_for(sla_process), mech, motion, [pair])
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
    partset = build_parts(design_for(sla_process), mech, motion, [])
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
    a = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [])
    b = build_parts(design_for(sla_process), four_bar, four_bar.sweep(61), [])
    assert [p.name for p in a.parts] == [p.name for p in b.parts]
    for p, q in zip(a.parts, b.parts, strict=True):
        np.testing.assert_array_equal(p.outline.vertices, q.outline.vertices)
    assert a.layers == b.layers and a.bom == b.bom


def test_no_body_sweeps_over_a_spacer_between_its_layers(four_bar, sla_process):
    """Independent check over 181 poses: a body in a layer skipped by a pin keeps clear of its spacer.

    (The plain colouring of this four-bar puts the coupler, which sweeps over pin O, between the layers
    of the ground and the crank; the layer ordering must move it out.)"""
    motion = four_bar.sweep(181)
    partset = build_parts(design_for(sla_process), four_bar, motion, [])
    sizes = derive_sizes(sla_process, PartsSpec(), PartHints())
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
    partset = build_parts(design_for(sla_process), four_bar, motion, [])
    sizes = derive_sizes(sla_process, PartsSpec(), PartHints())
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
        build_parts(design_for(fat), four_bar, four_bar.sweep(11), [])
    largest = float(re.search(r"at most ([\d.]+) mm", str(info.value)).group(1))
    # closed form: centre distance 15 - wall - 2 x clearance - compensation
    assert largest == pytest.approx(15.0 - 0.8 - 2 * 0.25 - 0.2, abs=0.01)
    fits = build_parts(design_for(dataclasses.replace(sla_process, pin_diameter_mm=largest)), four_bar,
                       four_bar.sweep(11), [])
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


def gear_overlap(partset, motion, pair) -> float:
    """Largest plan overlap (mm^2) of the two parts carrying ``pair``'s gears over ``motion``."""
    from fabricate.planar import rotation

    a = next(p for p in partset.parts if p.body == pair.body_a)
    b = next(p for p in partset.parts if p.body == pair.body_b)
    worst = 0.0
    for k in range(len(motion.inputs)):
        polys = []
        for part in (a, b):
            pose = motion.pose(part.body)[k]
            polys.append(shapely.Polygon(part.outline.polygon(0.01) @ rotation(pose[2]).T + pose[:2]))
        worst = max(worst, polys[0].intersection(polys[1]).area)
    return worst


def test_bosses_round_gear_axes_clear_the_mating_gear(monkeypatch):
    """A wall grown past the gears' roots (a laser's webs as thick as a 6 mm stock, here a requested 12 mm wall)
    is cut back round each gear's axis: the gears' parts never overlap, where the full bosses would."""
    import dataclasses

    from fabricate import pipeline
    from fabricate.design import load_design
    from fabricate.parts import build

    design = load_design("gear_pair_elliptic", "laser")
    design = dataclasses.replace(design, parts=dataclasses.replace(design.parts, boss_wall_mm=12.0))
    result, report, motion, _ = pipeline._synthesis_stage(design, pipeline._quiet, "build")
    run = pipeline.BuildRun(design, result, motion, report)
    pipeline._make_gears(run)
    (pair,) = run.gear_pairs
    partset = build_parts(design, result.mechanism, motion, run.gear_pairs, result.parts)
    assert gear_overlap(partset, motion, pair) == 0.0
    monkeypatch.setattr(build, "mesh_limits", lambda *args: {})
    full = build_parts(design, result.mechanism, motion, run.gear_pairs, result.parts)
    assert gear_overlap(full, motion, pair) > 1.0
