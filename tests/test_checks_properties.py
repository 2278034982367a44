"""Check verdicts at their boundaries, with the measured values checked against closed forms here.

Written to kill mutants of ``fabricate/checks`` (see ``tests/benchmarks/mutation_report.md``): a clearance
just under the requirement fails, one just at it passes; the slack of the verdict is the chord tolerance.
"""

from __future__ import annotations

from functools import cache

import pytest

from fabricate.checks.interference import sweep_interference
from tests.conftest import make_four_bar
from tests.interference_fixtures import four_bar_parts

REQUIRED = 0.25  # mm radial clearance the process asks for
TOL = 0.002  # chord tolerance of the polygonised solids: the slack of the verdict


@cache
def four_bar_motion():
    mech = make_four_bar()
    return mech, mech.sweep(73)


def sweep_with_hole_clearance(clearance: float):
    mech, motion = four_bar_motion()
    parts = four_bar_parts(mech, clearance=clearance)
    return sweep_interference(parts, motion, chord_tolerance_mm=TOL, min_clearance_mm=REQUIRED)


@pytest.mark.parametrize("short_by", [2.5 * TOL, 4 * TOL, 0.012])
def test_clearance_just_under_the_requirement_fails(short_by):
    """Holes whose radial clearance is a few chord tolerances short of 0.25 mm: no collision, every pin
    pair measured within the chord tolerance of the designed clearance, and the verdict fails."""
    clearance = REQUIRED - short_by
    result = sweep_with_hole_clearance(clearance)
    assert not result.collisions
    pins = [p for p in result.pairs if p.relation == "pin"]
    assert pins
    for p in pins:
        assert clearance - TOL - 1e-9 <= p.min_clearance_mm <= clearance + 1e-9
    assert {(p.a, p.b) for p in result.too_close()} == {(p.a, p.b) for p in pins}
    assert not result.passed
    assert sum(f.startswith("clearance:") for f in result.failures()) == len(pins)
    report = {(r["a"], r["b"]): r for r in result.report()["pairs"]}
    assert not any(report[(p.a, p.b)]["ok"] for p in pins)


def test_clearance_at_the_requirement_passes():
    """Designed exactly at 0.25 mm the polygonised holes measure at most a chord tolerance less: passes."""
    result = sweep_with_hole_clearance(REQUIRED)
    pins = [p for p in result.pairs if p.relation == "pin"]
    for p in pins:
        assert REQUIRED - TOL - 1e-9 <= p.min_clearance_mm <= REQUIRED + 1e-9
    assert result.too_close() == []
    assert result.passed, result.failures()
    assert all(r["ok"] for r in result.report()["pairs"])
