"""Mounting holes on the ground part (``_add_mounting`` in ``fabricate/parts/build.py``).

The mounting screws fix the ground part to whatever carries the mechanism. What a user relies on:

- as many holes as ``[parts] mounting_holes`` asks, each the screw + 2 x clearance (+ SLA
  compensation), named ``mount_1`` ... ``mount_n`` in a fixed order along the row;
- the row is straight, across the direction away from the moving bodies, centred on the ground part,
  with a fixed web of 2 mm between neighbouring screw bosses;
- every screw head (the mounting boss) keeps the running clearance from everything that moves, and the
  row is pushed out no further than needed;
- the ground outline encloses every mounting boss, so each screw keeps its wall.

Expected values come from closed forms (sizes from the process by hand, a symmetric swing whose row
position is known exactly) or from independent shapely geometry built from the motion; never from the
function under test. Written to kill mutants of ``_add_mounting``.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely

from fabricate.hints import PadHint, PartHints
from fabricate.mechanism import Body, Driver, LinearLaw, Mechanism, Revolute, Slider
from fabricate.parts.build import Sizes, _add_mounting, build_parts
from fabricate.parts.spec import PartsSpec
from fabricate.planar import transform_points
from tests.conftest import make_four_bar
from tests.parts.test_build import design_for

CHORD = 0.01  # mm, chord tolerance of the polygons the tests build


def mounts(partset) -> list:
    """The ground part's mounting holes, in the order of their number (mount_1 first)."""
    holes = [h for h in partset.part("ground").holes if h.joint.startswith("mount_")]
    return sorted(holes, key=lambda h: int(h.joint.split("_")[1]))


def sla_sizes(process, screw_mm: float = 3.0) -> tuple[float, float, float]:
    """(mount hole diameter, mount boss radius, joint boss radius) worked out by hand for the SLA process:
    hole = screw + 2 c + compensation; wall = max(min wall, pin / 2); boss = hole / 2 + wall."""
    wall = max(process.min_wall_mm, 0.5 * process.pin_diameter_mm)
    mount_hole = screw_mm + 2.0 * process.running_clearance_mm + process.hole_compensation_mm
    pin_hole = process.pin_diameter_mm + 2.0 * process.running_clearance_mm + process.hole_compensation_mm
    return mount_hole, mount_hole / 2.0 + wall, pin_hole / 2.0 + wall


def away_direction(mechanism: Mechanism, motion) -> np.ndarray:
    """Unit vector from the centroid of every moving body point over the motion (mapped with the poses
    here) to the centroid of the ground's points: the side of the ground away from what moves."""
    moving = [transform_points(pose, body.point(p)) for body in mechanism.bodies if body.name != mechanism.ground
              for p in body.points for pose in motion.pose(body.name)]
    ground = mechanism.body(mechanism.ground)
    own = np.array([ground.point(p) for p in ground.points])
    away = own.mean(axis=0) - np.mean(moving, axis=0)
    return away / np.hypot(*away)


def moving_region(partset, motion) -> shapely.Geometry:
    """Union of every moving part's outline at every pose of the motion (independent swept region)."""
    shapes = []
    for part in partset.body_parts():
        if part.body == "ground":
            continue
        outline = part.outline.polygon(CHORD)
        shapes += [shapely.Polygon(transform_points(pose, outline)) for pose in motion.pose(part.body)]
    return shapely.union_all(shapes)


def swing_mechanism(lo_deg: float = 60.0, hi_deg: float = 120.0, ground_points: dict | None = None,
                    length: float = 20.0) -> Mechanism:
    """A ground bar L(-20, 0) O(0, 0) R(20, 0) (or ``ground_points``) with a lever O-A of ``length`` mm on
    O turning from ``lo_deg`` to ``hi_deg``; the default swing (symmetric about +y) stays above the bar."""
    th = math.radians(lo_deg)
    return Mechanism(
        name="swing",
        bodies=(Body("ground", ground_points or {"L": (-20.0, 0.0), "O": (0.0, 0.0), "R": (20.0, 0.0)}),
                Body("lever", {"O": (0.0, 0.0), "A": (length, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "lever"),),
        gears=(),
        drivers=(Driver("angle", "lever", "ground"),),
        input_range=(lo_deg, hi_deg),
        assembly={"lever": (0.0, 0.0, th)},
    )


def telescoping_lever() -> Mechanism:
    """The ground bar with a lever O-G turning 30 -> 120 deg and a rod sliding out along it: the rod's
    point G (listed after the lever, which has its own point G 10 mm out) runs from the lever's G to 30 mm
    beyond it. The two points named G are different points; the rod's is the one that moves out."""
    th = math.radians(30.0)
    return Mechanism(
        name="telescoping",
        bodies=(Body("ground", {"L": (-20.0, 0.0), "O": (0.0, 0.0), "R": (20.0, 0.0)}),
                Body("lever", {"O": (0.0, 0.0), "G": (10.0, 0.0)}),
                Body("rod", {"G": (0.0, 0.0), "T": (8.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "lever"), Slider("G", "lever", "rod", (1.0, 0.0), 0.0)),
        gears=(),
        drivers=(Driver("angle", "lever", "ground"),
                 Driver("slide", "rod", "lever", joint="G", law=LinearLaw(1.0 / 3.0, -10.0))),
        input_range=(30.0, 120.0),
        assembly={"lever": (0.0, 0.0, th), "rod": (10.0 * math.cos(th), 10.0 * math.sin(th), th)},
    )


def segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) to the segment a-b (closed form projection)."""
    d = b - a
    t = np.clip((points - a) @ d / float(d @ d), 0.0, 1.0)
    return np.hypot(*(points - a - t[:, None] * d).T)


def first_clear_row(xs: np.ndarray, tips: np.ndarray, r_lever: float, y0: float, need: float) -> float:
    """Closed form for a row of holes at x = ``xs`` moving down (-y) from ``y0`` in 0.5 mm steps past a
    lever pinned at the origin (a stadium of radius ``r_lever`` from O to each tip in ``tips``): the first
    y at which every hole is at least ``need`` from every pose of the lever."""
    def gap(y: float) -> float:
        row = np.column_stack([xs, np.full(len(xs), y)])
        return min(float(np.min(segment_distance(row, np.zeros(2), tip))) for tip in tips) - r_lever

    y = y0
    while gap(y) < need:
        y -= 0.5
    return y


# -- count, size, names -------------------------------------------------------------------------


@pytest.mark.parametrize("count", [0, 1, 2, 3, 5])
def test_mounting_hole_count_size_and_names(four_bar, sla_process, count):
    """``mounting_holes = n`` gives exactly n holes on the ground part (none on a moving part), named
    mount_1 ... mount_n, each the screw (M2.5 here) + 2 x running clearance + hole compensation across
    (closed form, 1e-12 mm) and taking no pin; the joint holes are untouched."""
    motion = four_bar.sweep(61)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=count, mounting_hole_mm=2.5)),
                          four_bar, motion, [])
    mount_hole, _, _ = sla_sizes(sla_process, screw_mm=2.5)
    holes = mounts(partset)
    assert [h.joint for h in holes] == [f"mount_{k + 1}" for k in range(count)]
    for h in holes:
        assert h.diameter_mm == pytest.approx(mount_hole, abs=1e-12)
        assert h.pin_diameter_mm == 0.0
    for part in partset.body_parts():
        if part.body != "ground":
            assert not any(h.joint.startswith("mount_") for h in part.holes)
    assert sorted(h.joint for h in partset.part("ground").holes if not h.joint.startswith("mount_")) == ["D", "O"]


def test_no_mounting_holes_leaves_the_ground_a_plain_link(four_bar, sla_process):
    """With ``mounting_holes = 0`` the ground bar O-D is just the rounded slot of its two joint bosses:
    area 2 r L + pi r^2 - the two holes (closed form, relative 1e-9): a running hole 2 + 2 x 0.25 + 0.2 where a
    pin runs, a press hole 2 - 0.05 + 0.2 where the ground holds the pin."""
    motion = four_bar.sweep(61)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=0)), four_bar, motion, [])
    _, _, r = sla_sizes(sla_process)
    running = sla_process.pin_diameter_mm + 2 * sla_process.running_clearance_mm + sla_process.hole_compensation_mm
    press = sla_process.pin_diameter_mm - sla_process.press_fit_interference_mm + sla_process.hole_compensation_mm
    ground = partset.part("ground")
    held = sum(p.holder == "ground" for p in partset.pins)
    holes = [press] * held + [running] * (2 - held)
    assert mounts(partset) == []
    assert ground.area_mm2() == pytest.approx(2 * r * 40.0 + math.pi * r * r - sum(math.pi * h ** 2 / 4 for h in holes),
                                              rel=1e-9)


# -- the row: where and in which order ----------------------------------------------------------


def test_swing_row_sits_just_outside_the_ground_bosses(sla_process):
    """A lever swinging 60-120 deg above a ground bar: nothing moves below the bar, so the row needs no
    pushing. It lies straight along x on the far side (y < 0), centred under O, at the closed-form height
    y = -(joint boss r + mount boss r + 1 mm) (the mounting bosses 1 mm clear of the joint bosses), with
    pitch = mount boss diameter + 2 mm, numbered left to right as seen from below (+x). Tolerance 1e-9 mm."""
    mech = swing_mechanism()
    motion = mech.sweep(31)
    _, r_mount, r_boss = sla_sizes(sla_process)
    pitch = 2.0 * r_mount + 2.0
    for count in (1, 2, 4):
        partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=count)), mech, motion, [])
        got = np.array([h.centre for h in mounts(partset)])
        want = np.column_stack([(np.arange(count) - 0.5 * (count - 1)) * pitch,
                                np.full(count, -(r_boss + r_mount + 1.0))])
        np.testing.assert_allclose(got, want, atol=1e-9)


def test_row_moves_out_past_a_pad_fused_to_the_ground(sla_process):
    """A circular pad (radius 20 mm about O, between points at -30 and -150 deg) fused to the ground bar
    reaches y = -20, further than any joint boss (y = -10 - boss r): the mounting row keeps its bosses
    1 mm outside the pad, at y = -(20 + mount boss r + 1) (closed form; tolerance the process chord
    tolerance, the pad arc being polygonised within it), x as for the bar alone (1e-9 mm)."""
    s3 = 10.0 * math.sqrt(3.0)
    base = swing_mechanism()
    ground = Body("ground", {"L": (-20.0, 0.0), "O": (0.0, 0.0), "R": (20.0, 0.0),
                             "P1": (s3, -10.0), "P2": (-s3, -10.0)})
    mech = Mechanism(name="swing_pad", bodies=(ground, base.bodies[1]), ground="ground", joints=base.joints,
                     gears=(), drivers=base.drivers, input_range=base.input_range, assembly=base.assembly)
    motion = mech.sweep(31)
    _, r_mount, r_boss = sla_sizes(sla_process)
    assert 10.0 + r_boss < 20.0  # the pad, not a boss, is the ground's furthest reach
    hints = PartHints(pads={"ground": PadHint("O", arc=("P1", "P2"))})
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=2)), mech, motion, [], hints)
    got = np.array([h.centre for h in mounts(partset)])
    pitch = 2.0 * r_mount + 2.0
    want = np.array([[-0.5 * pitch, -(20.0 + r_mount + 1.0)], [0.5 * pitch, -(20.0 + r_mount + 1.0)]])
    np.testing.assert_allclose(got[:, 0], want[:, 0], atol=1e-9)
    np.testing.assert_allclose(got[:, 1], want[:, 1], atol=sla_process.chord_tolerance_mm + 1e-9)


@pytest.mark.parametrize("count", [2, 3, 4])
@pytest.mark.parametrize("make", [make_four_bar, telescoping_lever], ids=["four_bar", "telescoping"])
def test_row_is_straight_even_centred_and_numbered_across_the_far_side(sla_process, make, count):
    """A four-bar, and a lever with a rod sliding out along it (two bodies with a point named G, the
    rod's moving out along the lever): with d the unit vector from the centroid of every moving body's
    own points over the motion (each mapped with its own body's poses, here) to the centroid of the
    ground's points, the holes lie on the far side (d . centre beyond every joint boss plus a mounting
    boss), mount_k to mount_k+1 is exactly pitch x (d turned +90 deg) (pitch = mount boss diameter + 2 mm:
    numbered left to right as seen from beyond the row), and the row is centred on the ground's points
    across d. Tolerance 1e-9 mm (the direction is an average over the sweep, rounding only)."""
    mech = make()
    motion = mech.sweep(61)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=count)), mech, motion, [])
    _, r_mount, r_boss = sla_sizes(sla_process)
    d = away_direction(mech, motion)
    side = np.array([-d[1], d[0]])
    centres = np.array([h.centre for h in mounts(partset)])
    ground = mech.body(mech.ground)
    own = np.array([ground.point(p) for p in ground.points])
    np.testing.assert_allclose(np.diff(centres, axis=0), np.tile((2.0 * r_mount + 2.0) * side, (count - 1, 1)),
                               atol=1e-9)
    assert centres.mean(axis=0) @ side == pytest.approx(own.mean(axis=0) @ side, abs=1e-9)
    along = centres @ d
    np.testing.assert_allclose(along, along[0], atol=1e-9)  # one straight row across d
    assert along[0] >= float(np.max(own @ d)) + r_boss + r_mount + 1.0 - 1e-9


# -- clearance from what moves ------------------------------------------------------------------


@pytest.mark.parametrize("count", [1, 2, 3])
def test_four_bar_screw_heads_clear_everything_that_moves(four_bar, sla_process, count):
    """Against the region every moving part sweeps over 181 poses (shapely, built here from the parts'
    outlines and the poses), every mounting boss keeps at least the running clearance: distance from the
    hole centre >= mount boss r + clearance (no tolerance: the parts keep 0.5 mm margin for this)."""
    motion = four_bar.sweep(181)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=count)), four_bar, motion, [])
    _, r_mount, _ = sla_sizes(sla_process)
    centres = np.array([h.centre for h in mounts(partset)])
    gaps = shapely.distance(shapely.points(centres), moving_region(partset, motion))
    assert np.all(gaps >= r_mount + sla_process.running_clearance_mm), gaps


@pytest.mark.parametrize("count", [1, 2, 3])
def test_wide_swing_pushes_the_row_out_to_the_first_step_that_clears(sla_process, count):
    """A lever swinging 300 deg (-60 to 240) sweeps below the ground bar on both sides, so the row must
    move out along -y. Closed form: the lever at each pose is the stadium of O-A with the joint boss
    radius, so a hole's gap to what moves is min over poses of (segment distance - boss r); candidate
    rows step out 0.5 mm at a time from y = -(joint boss r + mount boss r + 1); the row is the first whose
    every gap is >= mount boss r + clearance + 0.5 mm (margin for motion between sampled poses).
    Holes at that y and x as for an unobstructed row (1e-9 mm: the row before the chosen one misses the
    threshold by >= 0.099 mm, more than the 0.05 mm chord of the polygonised tip arcs, and the polygons
    lie inside the exact stadia so they only widen the chosen row's gaps). Cross-check against the
    dense swept region (181 poses, shapely): every gap >= mount boss r + clearance; the closest boss is
    within 1 mm of that (pose margin + one step), and half a step further in some boss is closer than
    the margin allows -- the row is pushed out no further than needed."""
    mech = swing_mechanism(-60.0, 240.0)
    motion = mech.sweep(181)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=count)), mech, motion, [])
    _, r_mount, r_boss = sla_sizes(sla_process)
    need = r_mount + sla_process.running_clearance_mm
    xs = (np.arange(count) - 0.5 * (count - 1)) * (2.0 * r_mount + 2.0)
    tips = np.array([transform_points(pose, np.array([20.0, 0.0])) for pose in motion.pose("lever")])
    y = first_clear_row(xs, tips, r_boss, -(r_boss + r_mount + 1.0), need + 0.5)
    assert y < -(r_boss + r_mount + 1.0) - 1.0  # the case pushes the row out
    centres = np.array([h.centre for h in mounts(partset)])
    np.testing.assert_allclose(centres, np.column_stack([xs, np.full(count, y)]), atol=1e-9)

    region = moving_region(partset, motion)
    gaps = shapely.distance(shapely.points(centres), region)
    assert np.all(gaps >= need), (gaps, need)
    assert float(gaps.min()) < need + 1.0, (gaps, need)
    inward = shapely.distance(shapely.points(centres + np.array([0.0, 0.5])), region)
    assert float(inward.min()) < need + 0.5, (inward, need)


def test_ground_outline_encloses_every_mounting_boss(four_bar, sla_process):
    """Each mounting hole has its full boss inside the ground outline: the distance from the hole centre
    to the outline's boundary is at least the mount boss radius (= hole / 2 + wall), less the chord
    tolerance; so the screw keeps the process wall all round."""
    motion = four_bar.sweep(61)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=3)), four_bar, motion, [])
    mount_hole, r_mount, _ = sla_sizes(sla_process)
    outline = shapely.Polygon(partset.part("ground").outline.polygon(CHORD))
    assert outline.is_valid
    for h in mounts(partset):
        point = shapely.Point(h.centre)
        assert outline.contains(point)
        assert outline.exterior.distance(point) >= r_mount - CHORD, h.joint
        assert r_mount - mount_hole / 2.0 == pytest.approx(max(sla_process.min_wall_mm,
                                                                0.5 * sla_process.pin_diameter_mm), abs=1e-12)


# -- nothing moves, or the moving parts are centred on the ground -------------------------------


@pytest.mark.parametrize("points", [{}, {"L": (-20.0, 3.0), "R": (20.0, 5.0)}], ids=["no_points", "two_points"])
def test_a_bare_ground_plate_gets_its_row_below(sla_process, points):
    """A mechanism that is nothing but its ground plate (no moving body; with no points at all, the parts
    layer stands a boss in at the origin): nothing to keep clear of, so the row goes on -y, centred
    across x on the plate's points, its bosses 1 mm below the lowest boss: y = min point y - joint boss r
    - mount boss r - 1 (closed form, 1e-9 mm), pitch = mount boss diameter + 2 mm; the plate encloses it."""
    mech = Mechanism(name="plate", bodies=(Body("ground", points),), ground="ground", joints=(), gears=(),
                     drivers=(), input_range=(0.0, 1.0))
    motion = mech.sweep(3)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=3)), mech, motion, [])
    _, r_mount, r_boss = sla_sizes(sla_process)
    ys = [y for _, y in points.values()] or [0.0]
    xs = [x for x, _ in points.values()] or [0.0]
    want = np.column_stack([np.mean(xs) + np.array([-1.0, 0.0, 1.0]) * (2.0 * r_mount + 2.0),
                            np.full(3, min(ys) - r_boss - r_mount - 1.0)])
    np.testing.assert_allclose([h.centre for h in mounts(partset)], want, atol=1e-9)
    outline = shapely.Polygon(partset.part("ground").outline.polygon(CHORD))
    assert all(outline.exterior.distance(shapely.Point(c)) >= r_mount - CHORD for c in want)


def test_a_lever_turning_right_round_the_ground_centre_puts_the_row_on_minus_y(sla_process):
    """A 20 mm lever on O turning a full turn in 12 steps of 30 deg above a bar L-O-R centred on O: the
    moving points' centroid is the ground's centre (to rounding, ~1e-15 mm), so there is no away side and
    the row goes on -y, pushed down past the lever (closed form as for the wide swing: first 0.5 mm step
    from y = -(joint boss r + mount boss r + 1) whose holes are all >= mount boss r + clearance + 0.5 from
    every pose of the lever; 1e-9 mm, the row before misses by 0.25 mm), x centred on O."""
    mech = swing_mechanism(0.0, 360.0)
    motion = mech.sweep(np.arange(12) * 30.0)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=2)), mech, motion, [])
    _, r_mount, r_boss = sla_sizes(sla_process)
    xs = np.array([-0.5, 0.5]) * (2.0 * r_mount + 2.0)
    tips = np.array([transform_points(pose, np.array([20.0, 0.0])) for pose in motion.pose("lever")])
    y = first_clear_row(xs, tips, r_boss, -(r_boss + r_mount + 1.0),
                        r_mount + sla_process.running_clearance_mm + 0.5)
    np.testing.assert_allclose([h.centre for h in mounts(partset)], np.column_stack([xs, [y, y]]), atol=1e-9)


def test_a_ground_half_a_millimetre_off_centre_takes_the_row_on_that_side(sla_process):
    """The same full-turn lever over a bar L(-20, 0) O R(21.5, 0): the ground's centre is 0.5 mm to +x of
    the moving points' centroid, a real (if small) away side: the row goes on +x, its bosses 1 mm beyond
    R's boss, x = 21.5 + joint boss r + mount boss r + 1, across y centred on the bar (y = -/+ half a
    pitch, mount_1 at -y: left to right seen from beyond the row). Closed form, 1e-9 mm; the lever (tip
    22.35 mm out) leaves more than the clearance there."""
    mech = swing_mechanism(0.0, 360.0, {"L": (-20.0, 0.0), "O": (0.0, 0.0), "R": (21.5, 0.0)})
    motion = mech.sweep(np.arange(12) * 30.0)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=2)), mech, motion, [])
    _, r_mount, r_boss = sla_sizes(sla_process)
    x = 21.5 + r_boss + r_mount + 1.0
    half = 0.5 * (2.0 * r_mount + 2.0)
    np.testing.assert_allclose([h.centre for h in mounts(partset)], [[x, -half], [x, half]], atol=1e-9)


def test_when_nothing_within_reach_clears_the_row_stops_at_the_end_of_the_search(sla_process):
    """A 450 mm lever 100 mm wide turning a full turn sweeps a disc of radius ~500 mm round the ground:
    no row within the 400 mm search (0.5 mm steps, 0 to 399.5 mm out) clears it, so the row is left at
    the last candidate, 399.5 mm beyond the innermost row: along d (computed here from the poses) at
    max(ground point . d) + joint boss r (50 mm, half the link width) + mount boss r + 1 + 399.5
    (closed form, 1e-9 mm), not somewhere inside the swept disc."""
    mech = swing_mechanism(0.0, 360.0, length=450.0)
    motion = mech.sweep(91)
    partset = build_parts(design_for(sla_process, PartsSpec(mounting_holes=1, link_width_mm=100.0)), mech,
                          motion, [])
    _, r_mount, _ = sla_sizes(sla_process)
    d = away_direction(mech, motion)
    own = np.array([[-20.0, 0.0], [0.0, 0.0], [20.0, 0.0]])
    along = float(np.max(own @ d)) + 50.0 + r_mount + 1.0 + 399.5
    (hole,) = mounts(partset)
    np.testing.assert_allclose(hole.centre, along * d, atol=1e-9)
    assert shapely.distance(shapely.Point(hole.centre), moving_region(partset, motion)) == 0.0


# -- the boundaries, on the function itself -----------------------------------------------------


def mount_row(ground_points: dict, moving: dict, swept, count: int = 1) -> np.ndarray:
    """Call the mounting step directly: ground bosses of radius 2 mm at ``ground_points``, one moving
    body whose points follow the world tracks ``moving`` (name -> (n, 2)), mounting bosses of radius 3 mm,
    clearance 0.5 mm (so a boss needs 3 + 0.5 + 0.5 = 4 mm from ``swept``, exactly). The centres."""
    mover = Body("mover", dict.fromkeys(moving, (0.0, 0.0)))
    mechanism = SimpleNamespace(bodies=[Body("ground", ground_points), mover])
    motion = SimpleNamespace(point=lambda name, body: np.asarray(moving[name], dtype=float))
    sizes = Sizes(pin_mm=2.0, hole_mm=2.5, boss_radius_mm=2.0, mount_hole_mm=3.0, mount_boss_radius_mm=3.0,
                  hub_mm=4.0)
    circles = {"ground": [(np.asarray(p, dtype=float), 2.0) for p in ground_points.values()]}
    holes: dict = {"ground": []}
    _add_mounting(mechanism, motion, "ground", circles, holes, {"ground": []}, sizes,
                  PartsSpec(mounting_holes=count), swept, 0.5)
    centres = np.array([h.centre for h in holes["ground"]])
    # each mounting hole also gets its boss circle on the ground (the outline is the hull of those)
    bosses = circles["ground"][len(ground_points):]
    np.testing.assert_array_equal(np.array([c for c, _ in bosses]).reshape(-1, 2), centres.reshape(-1, 2))
    assert all(r == 3.0 for _, r in bosses)
    return centres


def test_an_offset_of_one_micrometre_or_less_counts_as_centred():
    """Ground bosses at (0, 0) and (2e-6, 0), moving points at (+-20, 0): the ground's centre is exactly
    1e-6 mm (in floating point) off the moving centroid -- within the dead band, so the row goes on -y
    (centre (1e-6, -(2 + 3 + 1))); one float further out (the next double after 2e-6) the offset counts
    and the row goes on +x (centre (2e-6 + 6, 0)). Exact to 1e-12 mm."""
    moving = {"A": [[20.0, 0.0]], "B": [[-20.0, 0.0]]}
    empty = shapely.Polygon()
    centred = mount_row({"O": (0.0, 0.0), "G": (2e-6, 0.0)}, moving, empty)
    np.testing.assert_allclose(centred, [[1e-6, -6.0]], rtol=0, atol=1e-12)
    beyond = np.nextafter(2e-6, 1.0)
    off = mount_row({"O": (0.0, 0.0), "G": (beyond, 0.0)}, moving, empty)
    np.testing.assert_allclose(off, [[beyond + 6.0, 0.0]], rtol=0, atol=1e-12)


def test_a_screw_head_exactly_at_the_clearance_is_accepted():
    """A ground boss at O, the moving point above it (so the row goes on -y from y = -(2 + 3 + 1) = -6)
    and a strip of swept region 7 <= -y <= 8 across the row's way: the first row at least 4 mm (mount
    boss + clearance + 0.5 margin) from the strip is y = -12, exactly 4 mm from it (all values exact in
    floating point): the clearance is a minimum, met with equality, so the row is not pushed the extra
    0.5 mm. With a strip 0.25 mm lower the row moves on to the next step, y = -12.5."""
    moving = {"A": [[0.0, 10.0]]}
    at = mount_row({"O": (0.0, 0.0)}, moving, shapely.box(-50.0, -8.0, 50.0, -7.0))
    assert shapely.distance(shapely.Point(at[0]), shapely.box(-50.0, -8.0, 50.0, -7.0)) == 4.0
    np.testing.assert_array_equal(at, [[0.0, -12.0]])
    below = mount_row({"O": (0.0, 0.0)}, moving, shapely.box(-50.0, -8.25, 50.0, -7.0))
    np.testing.assert_array_equal(below, [[0.0, -12.5]])
