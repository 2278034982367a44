"""The gear-mesh check of an assembled motion (``fabricate/checks/gear_mesh.py``): boundaries and reports.

Written to kill mutants of ``check_gear_mesh`` and ``GearMeshResult.report``: each tolerance admits a value
exactly at it, a motion never in mesh reports NaN/None instead of crashing, the overlap is reported at the
input of the largest overlap, and the backlash band is closed at both ends. Expected values are closed forms
(band edges 0.5 and 2 x the design backlash, ``law(0) = 0``) or independent shapely computations.
"""

from __future__ import annotations

import json
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from shapely.geometry import Polygon

from fabricate.checks.gear_mesh import check_gear_mesh
from tests.gears.test_gears_properties import fake_motion, sector_pair, spur_pair

DESIGN_MM = 0.1  # design backlash of the fake pair; band 0.5..2 x this


def fake_pair():
    """The pair attributes check_gear_mesh reads, law x_b = -x_a, closed (no range check)."""
    return SimpleNamespace(name="fake", body_a="gear_a", body_b="gear_b", carrier="carrier",
                           law=lambda x: -np.asarray(x, dtype=np.float64), working_range=(0.0, 2 * np.pi),
                           closed=True, spec=SimpleNamespace(backlash_mm=DESIGN_MM))


def judged(monkeypatch, area, backlash):
    """check_gear_mesh of the fake pair with the mesh measures replaced by the given per-pose arrays."""
    area, backlash = np.asarray(area, dtype=np.float64), np.asarray(backlash, dtype=np.float64)

    def mesh_check(pair, x_a_values):
        return SimpleNamespace(steps=len(x_a_values), interference_area_mm2=area, backlash_mm=backlash,
                               transmission_error=np.zeros(len(x_a_values)))

    monkeypatch.setattr("fabricate.gears.mesh.mesh_check", mesh_check)
    x = np.linspace(0.1, 0.5, len(area))
    return check_gear_mesh(fake_pair(), fake_motion(x, -x))


def test_law_error_exactly_at_the_tolerance_passes():
    """A motion off the law by exactly 1e-6 rad (at x_a = 0, where law(0) = 0) is within the solver's tolerance."""
    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.0, 0.4, 5)
    x_b = np.asarray(pair.law(x), dtype=np.float64)
    assert x_b[0] == 0.0
    x_b[0] = 1e-6
    result = check_gear_mesh(pair, fake_motion(x, x_b))
    assert result.law_error_rad == 1e-6
    assert result.failures == ()


@pytest.mark.parametrize("end", ["lo", "hi"])
def test_leaving_the_sector_by_exactly_the_range_tolerance_passes(end):
    """A sector turned exactly 1e-9 rad below its cut range, or above it, has not left it."""
    sector = replace(sector_pair(), carrier="carrier")
    lo, hi = sorted(float(v) for v in sector.working_range)
    x = np.linspace(lo, hi, 5)
    if end == "lo":
        x[0] = lo - 1e-9
    else:
        x[-1] = hi + 1e-9
    result = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
    assert not any("outside the cut range" in f for f in result.failures)


def test_a_motion_never_in_mesh_reports_nan_backlash_and_te_as_none():
    """Sector turned 0.7..0.9 rad past its teeth: every pose out of mesh, backlash and TE undefined (NaN), and
    the report says None for them (valid JSON), not NaN, and does not crash on the empty measures."""
    sector = replace(sector_pair(), carrier="carrier")
    hi = max(float(v) for v in sector.working_range)
    x = np.linspace(hi + 0.7, hi + 0.9, 5)
    result = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
    assert result.steps_without_contact == 5
    assert np.isnan(result.backlash_mm[0]) and np.isnan(result.backlash_mm[1])
    assert np.isnan(result.transmission_error_deg)
    report = result.report()
    assert report["backlash_mm"] == [None, None]
    assert report["transmission_error_deg"] is None
    json.dumps(report, allow_nan=False)


def test_report_of_a_meshing_motion_gives_the_backlash_and_te_numbers():
    """Spur pair on its law: the report carries the measured backlash (the designed 0.1 mm, closed form) and the
    transmission error as numbers, not None."""
    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.2, 0.4, 5)
    result = check_gear_mesh(pair, fake_motion(x, np.asarray(pair.law(x))))
    report = result.report()
    assert report["backlash_mm"] == pytest.approx([0.1, 0.1], abs=1e-3)
    assert isinstance(report["transmission_error_deg"], float)
    assert report["transmission_error_deg"] == result.transmission_error_deg


def test_overlap_is_reported_at_the_input_of_the_largest_overlap():
    """Spur pair 0.2 mm too close over one tooth pitch: the message names the input where the overlap (computed
    here with shapely from the posed outlines) is largest, not the first pose."""
    pair = replace(spur_pair(), carrier="carrier", center_distance_mm=24.0 - 0.2)
    x = np.linspace(0.2, 0.2 + 2 * np.pi / 24, 9)
    law = np.asarray(pair.law(x), dtype=np.float64)

    def posed(outline, angle, dx):
        c, s = np.cos(angle), np.sin(angle)
        pts = np.asarray(outline)
        return Polygon(np.column_stack([c * pts[:, 0] - s * pts[:, 1] + dx, s * pts[:, 0] + c * pts[:, 1]]))

    want = np.array([posed(pair.outline_a, a, 0.0).intersection(posed(pair.outline_b, b, pair.center_distance_mm)).area
                     for a, b in zip(x, law, strict=True)])
    k = int(np.argmax(want))
    assert want[k] > 1.1 * want[0]
    result = check_gear_mesh(pair, fake_motion(x, law))
    overlap = [f for f in result.failures if "teeth overlap" in f]
    assert len(overlap) == 1
    assert f"at input {np.degrees(x[k]):g} deg" in overlap[0]


def test_overlap_exactly_at_the_area_epsilon_is_rounding(monkeypatch):
    """An overlap of exactly 1e-6 mm^2 is rounding (no failure); 2e-6 mm^2 is an overlap."""
    band = [DESIGN_MM] * 3
    assert judged(monkeypatch, [0.0, 1e-6, 0.0], band).failures == ()
    over = judged(monkeypatch, [0.0, 2e-6, 0.0], band)
    assert len(over.failures) == 1 and "teeth overlap" in over.failures[0]


def test_backlash_band_is_closed_at_both_ends(monkeypatch):
    """Backlash exactly 0.5 x or 2 x the design backlash is inside the band; exactly 0 is a jam, not
    merely outside the band."""
    lo, hi = 0.5 * DESIGN_MM, 2.0 * DESIGN_MM
    assert judged(monkeypatch, [0.0, 0.0], [lo, DESIGN_MM]).failures == ()
    assert judged(monkeypatch, [0.0, 0.0], [DESIGN_MM, hi]).failures == ()
    jam = judged(monkeypatch, [0.0, 0.0], [0.0, DESIGN_MM])
    assert len(jam.failures) == 1 and "backlash closes" in jam.failures[0]
    assert "outside" not in jam.failures[0]
