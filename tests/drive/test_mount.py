"""The actuator's mount plate (``fabricate/drive/mount.py``) on a cut process: the stock it is cut from (the
thickest the shop lists that takes the actuator's fixed features under the shop's rules) and the standoffs'
screw (the next larger ISO 4762 size where the design's is too short for the stack)."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import pytest

from fabricate.checks.shop import ShopRules, check_part
from fabricate.drive import geometry as geo
from fabricate.drive.mount import MountPlacement
from fabricate.drive.parts import attach_actuator
from fabricate.drive.records import MOUNT_PART
from fabricate.errors import SpecError
from fabricate.parts.build import build_parts
from fabricate.parts.spec import PartsSpec
from tests.conftest import make_four_bar
from tests.drive.test_parts import design, driven


def on_sheet(parts_process, process, model: str):
    """The conftest four-bar's parts as ``parts_process`` cuts them, ``model`` attached by ``process`` (the
    four-bar's stack at 6 mm is too deep for a servo's spline: the plate's stock is what is under test)."""
    mech = make_four_bar()
    motion = mech.sweep(37)
    return attach_actuator(design(process, model), mech, motion, build_parts(design(parts_process, None), mech,
                                                                              motion, []))


def test_a_servo_plate_on_a_6mm_sheet_is_cut_from_the_3mm_stock(laser_process, sla_process):
    six = dataclasses.replace(laser_process, thickness_mm=6.0, build_volume_mm=(600.0, 400.0, 6.0),
                              stock_thickness_mm=(3.0, 6.0))
    ps = on_sheet(sla_process, six, "mg996r")
    plate = ps.part(MOUNT_PART)
    assert plate.thickness_mm == 3.0
    assert check_part(plate, ShopRules.of(six, 3.0), six.kerf_mm) == []
    # the same plate at 6 mm (no thinner stock listed): the servo's tab holes sit too near its case for a
    # 6 mm sheet's web, and the shop check says so
    only_six = dataclasses.replace(six, stock_thickness_mm=(6.0,))
    ps6 = on_sheet(sla_process, only_six, "mg996r")
    plate6 = ps6.part(MOUNT_PART)
    assert plate6.thickness_mm == 6.0
    assert any("min_web_mm" in f for f in check_part(plate6, ShopRules.of(only_six), six.kerf_mm))


def test_a_3mm_sheet_and_a_printer_keep_their_own_thickness(laser_process, sla_process):
    three = dataclasses.replace(laser_process, stock_thickness_mm=(3.0, 6.0))  # never a thicker plate
    assert on_sheet(sla_process, three, "mg996r").part(MOUNT_PART).thickness_mm == 3.0
    _, ps, _ = driven(sla_process, "mg996r", poses=37)
    assert ps.part(MOUNT_PART).thickness_mm == sla_process.thickness_mm


def test_a_stack_too_tall_for_the_designs_screw_takes_the_next_size():
    mount = SimpleNamespace(design=SimpleNamespace(parts=PartsSpec(mounting_hole_mm=3.0)))
    assert MountPlacement._standoff_size(mount, 26.43, 3.0) == "M3"  # an M3 x 30 clamps it, 3.57 mm in the plate
    with pytest.raises(SpecError):
        geo.screw_into("M3", 29.43, 3.0)  # ISO 4762 M3 stops at 30 mm
    assert MountPlacement._standoff_size(mount, 29.43, 3.0) == "M4"
    assert geo.screw_into("M4", 29.43, 3.0).length_mm <= 40.0


@pytest.mark.slow
def test_the_laser_default_finger_builds_with_no_collision_and_within_the_shop_rules(shipped_build):
    """``fabricate build --process laser`` of the default finger (its 6 mm stock kept) passes: the gears' bosses
    clear the mating teeth, the servo's plate (3 mm stock, on its tabs) clears pin A's clip end and meets the
    shop's rules, the standoffs' M4 screws clamp the 23.4 mm stack, and the plate, as thick as a listed stock, is
    nested on a 3 mm sheet of its own (tests/export/test_dxf.py)."""

    outcome = shipped_build("finger_five_bar_ncg", "laser")
    report = outcome.report
    assert report["interference"]["passed"] and not report["interference"]["collisions"]
    assert report["interference"]["shop"]["passed"], report["interference"]["shop"]["failures"]
    assert outcome.failures == [] and outcome.exit_code == 0
    plate = outcome.partset.part(MOUNT_PART)
    assert plate.thickness_mm == 3.0 and outcome.partset.part("ground").thickness_mm == 6.0
    screws = [f for f in outcome.partset.actuator.fasteners if "standoffs" in f.purpose]
    assert [f.designation for f in screws] == ["ISO 4762 M4 × 35"]
