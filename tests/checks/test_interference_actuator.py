"""Actuator solids in the interference sweep (``extra`` items of kind ``"actuator"``): how they pair with
the parts (``_relation``) and that one pose settles a pair fixed to one body. Hand-placed boxes on the
conftest four-bar (ground plate at z 0..3, crank at 3.3..6.3 turning about O)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from fabricate.checks.interference import sweep_interference
from fabricate.checks.items import SweepItem
from fabricate.parts.build import build_parts
from fabricate.parts.spec import PartsSpec


def square(cx: float, cy: float, half: float) -> np.ndarray:
    return np.array([[cx - half, cy - half], [cx + half, cy - half], [cx + half, cy + half], [cx - half, cy + half]])


def item(name: str, body: str, role: str, ring: np.ndarray, z0: float, z1: float) -> SweepItem:
    return SweepItem(name, body, "actuator", (ring,), z0, z1, frozenset(), "", SimpleNamespace(role=role))


@pytest.fixture
def built(four_bar, sla_process):
    design = SimpleNamespace(name="t", process=sla_process, parts=PartsSpec(mounting_holes=0),
                             gears=SimpleNamespace(hub_diameter_mm=None))
    motion = four_bar.sweep(25)
    return build_parts(design, four_bar, motion, []), motion


def run(built, *extra):
    ps, motion = built
    return sweep_interference(ps.parts, motion, chord_tolerance_mm=ps.chord_tolerance_mm, min_clearance_mm=0.25,
                              pins=ps.pins, spacers=ps.spacers, extra=extra)


def pair(result, a: str, b: str):
    return next(p for p in result.pairs if {p.a, p.b} == {a, b})


def test_a_body_on_the_ground_may_touch_its_parts_but_not_cut_into_them(built):
    ground = built[0].part("ground")
    # flush under the ground plate, overlapping it in plan between its pins (pressed pins stick out below it since
    # they cover their stacks): touching is how it is fixed
    under = item("motor", "ground", "body", square(20.0, 0.0, 4.0), ground.z_mm - 10.0, ground.z_mm)
    result = run(built, under)
    p = pair(result, "ground", "motor")
    assert p.relation == "fixed" and p.required_mm == 0.0 and not p.collides
    assert p.min_clearance_mm == pytest.approx(0.0, abs=1e-9)
    assert not [f for f in result.failures() if "motor" in f]
    # one pose settles a pair of one body: the same value at every pose
    assert np.all(p.clearance == p.clearance[0]) and np.all(p.exact)
    # sunk 1 mm into the plate it is an overlap, at every pose
    sunk = item("motor", "ground", "body", square(20.0, 0.0, 4.0), ground.z_mm - 10.0, ground.z_mm + 1.0)
    result = run(built, sunk)
    p = pair(result, "ground", "motor")
    assert p.collides and len(p.collision_indices) == len(result.inputs)
    assert any("ground collides with motor" in f for f in result.failures())


def test_an_output_is_fastened_to_its_part_and_bears_on_its_own_body(built):
    crank = built[0].part("crank")
    horn = item("horn", "crank", "output", square(0.0, 0.0, 3.0), crank.z_mm + crank.thickness_mm,
                crank.z_mm + crank.thickness_mm + 2.0)
    case = item("case", "ground", "body", square(0.0, 0.0, 6.0), horn.z1, horn.z1 + 20.0)
    result = run(built, horn, case)
    names = {(p.a, p.b) for p in result.pairs}
    assert ("crank", "horn") not in names and ("horn", "crank") not in names  # screwed together: rigid
    p = pair(result, "horn", "case")
    assert p.relation == "bearing" and not p.collides  # the output turns on the actuator's face
    # the case against the moving crank and coupler is an ordinary moving pair
    assert pair(result, "crank", "case").relation == "moving"
    # a horn screw head (role "screw") is fastened to the crank too, but is held to the clearance by the case
    head = item("head", "crank", "screw", square(7.0, 0.0, 1.0), horn.z0, horn.z1)
    assert pair(run(built, head, case), "head", "case").relation == "moving"


def test_an_actuator_body_cutting_through_a_moving_part_is_a_collision(built):
    crank = built[0].part("crank")
    # a box in the crank's layer round the point A's circle: the crank sweeps through it
    box = item("case", "ground", "body", square(0.0, 15.0, 3.0), crank.z_mm, crank.z_mm + crank.thickness_mm)
    result = run(built, box)
    p = pair(result, "crank", "case")
    assert p.relation == "moving" and p.collides
    assert any("crank collides with case" in f for f in result.failures())
