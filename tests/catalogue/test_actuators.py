"""Actuator entries: the MG996R-class servo against its own datasheet, and the servo mounts' geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely import affinity

from fabricate.catalogue import CATALOGUE, actuator
from fabricate.catalogue import actuators as act
from fabricate.drive import geometry as geo


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
    assert "handsontec" in a.source("stall_torque_nmm").lower()


def test_mg996r_spline_count_is_the_modelled_25t_at_the_futaba_3f_size():
    """25 teeth, entered from a public model and said so; the measured axle is the 3F spline's size (the
    standard the count belongs to: Ø5.92 head), so the count and the diameter describe one spline."""
    a = actuator("mg996r")
    assert a.spline is not None and a.spline.teeth == 25 and a.gap("spline.teeth") is None
    source = a.source("spline")
    assert "as modelled" in source and "Component_data.scad" in source and "FUTABA_3F_SPLINE" in source
    assert a.spline.diameter_mm == pytest.approx(5.92, abs=0.2)
    assert actuator("sg90").spline.teeth == actuator("mg90s").spline.teeth == 20  # the micro size stays 20T


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


def test_n20_d_shaft_is_the_modelled_flat_and_its_d_bore_keys_it():
    """The N20's D (Ø3, 2.5 from the flat to the far side, as modelled) cuts a D-bore that takes the shaft
    with the clearance all round and, turned by a few degrees, no longer does: the flat drives the part."""
    shaft = actuator("n20").shaft
    assert (shaft.diameter_mm, shaft.flats, shaft.across_flats_mm) == (3.0, 1, 2.5)
    assert "as modelled" in actuator("n20").source("shaft") and actuator("n20").gap("shaft.across_flats_mm") is None
    assert geo.shaft_flats(shaft) == 1
    centre, angle, clearance = np.array([4.0, -1.0]), 0.7, 0.15
    bore = shapely.Polygon(geo.shaft_bore(shaft, centre, angle, clearance).polygon(1e-4))
    d_profile = shapely.Polygon(geo.shaft_bore(shaft, centre, angle, 0.0).polygon(1e-4))
    u = np.array([math.cos(angle), math.sin(angle)])
    ring = np.asarray(bore.exterior.coords)
    flat, far = float(((ring - centre) @ u).max()), float(-((ring - centre) @ u).min())
    assert flat == pytest.approx(2.5 - 1.5 + clearance, abs=1e-9)  # the flat, exact
    assert far == pytest.approx(1.5 + clearance, abs=2e-4)  # the round side (chords of 1e-4 inside the arc)
    assert bore.contains(d_profile.buffer(clearance - 1e-3))  # the shaft goes in, with c on every side
    turned = affinity.rotate(d_profile, 20.0, origin=tuple(centre))
    assert not bore.contains(turned)  # and cannot turn in it
    assert bore.area < math.pi * (1.5 + clearance) ** 2  # not a round bore
