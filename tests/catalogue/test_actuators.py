"""Actuator entries: the MG996R-class servo against its own datasheet, and the servo mounts' geometry."""

from __future__ import annotations

import pytest

from fabricate.catalogue import CATALOGUE, actuator
from fabricate.catalogue import actuators as act


def test_mg996r_body_is_no_smaller_than_its_datasheet_drawing():
    """The body comes from a measured standard-size servo; it must enclose the MG996R drawing's case,
    tabs and tab height (so the interference proof never sees less than the real servo), and not by
    more than a millimetre (so it is the same size class, not a stand-in)."""
    a = actuator("mg996r")
    case, tabs = a.body
    dwg = act.MG996R_DRAWING
    measured = {"case_l": case.x1 - case.x0, "case_w": case.y1 - case.y0, "case_h": case.z1 - case.z0,
                "over_tabs": tabs.x1 - tabs.x0, "base_to_tabs": tabs.z0 - case.z0}
    for key, value in measured.items():
        assert dwg[key] <= value <= dwg[key] + 1.0, key


def test_mg996r_ratings_are_the_datasheets_at_4_8_volts():
    a = actuator("mg996r")
    assert a.complete and a.kind == "servo"
    assert a.stall_torque_nmm == pytest.approx(9.4 * 9.80665 * 10)   # 9.4 kgf·cm
    assert a.no_load_speed == pytest.approx(60 / 0.17)                # 0.17 s/60°
    assert a.voltage_v == 4.8 and a.rated_torque_nmm is None and a.gap("rated_torque_nmm")
    assert a.spline is not None and a.spline.teeth is None and a.gap("spline.teeth")
    assert "handsontec" in a.source("stall_torque_nmm").lower()


@pytest.mark.parametrize("key", [k for k, a in CATALOGUE.items() if a.kind == "servo"])
def test_servo_tab_holes_are_on_the_tabs_outside_the_case_and_symmetric(key):
    a = actuator(key)
    case, tabs = a.body
    cx = 0.5 * (case.x0 + case.x1)
    for h in a.mounting_holes:
        assert case.x1 < h.x < tabs.x1 or tabs.x0 < h.x < case.x0       # through a tab, clear of the case
        assert h.z == pytest.approx(tabs.z1)                              # on the tab's top face
        assert h.diameter_mm > 0
    xs = sorted(round(h.x - cx, 9) for h in a.mounting_holes)
    assert xs == sorted(-x for x in xs)                                   # symmetric about the case centre
    assert len(a.mounting_holes) in (2, 4)


def test_the_complete_entries_are_the_ones_a_template_may_name():
    """Which entries a build can use (body, mount, interface, rating): a regression here silently
    removes a template's actuator."""
    assert {k for k, a in CATALOGUE.items() if a.complete} == {"sg90", "mg90s", "mg996r", "nema17", "28byj48"}
    for key in ("n20", "l16"):
        a = actuator(key)
        assert not a.complete and a.gap("body") and a.gap("mounting_holes")
