"""Template validation: every error names the field path and what was expected."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fabricate.errors import SpecError
from fabricate.spec import Table, check_array, find_template, parse_process, shipped_templates


def test_number_errors_name_the_path():
    t = Table({"finger": {"lengths_mm": [40, "x", 20]}})
    with pytest.raises(SpecError) as info:
        t.table("finger").array("lengths_mm", shape=(3,))
    assert info.value.path == "finger.lengths_mm[1]"
    assert 'expected a number, got "x"' in str(info.value)


@pytest.mark.parametrize(
    ("value", "kwargs", "needle"),
    [(-1.0, {"positive": True}, "positive"), (5.0, {"max": 2.0}, "<= 2"), (math.inf, {}, "finite"),
     (True, {}, "expected a number"), (1.5, {"integer": True}, "whole number"), ("3", {}, "expected a number")],
)
def test_number_rejections(value, kwargs, needle):
    with pytest.raises(SpecError, match=needle) as info:
        Table({"a": {"b": value}}).table("a").number("b", **kwargs)
    assert info.value.path == "a.b"


def test_missing_and_unknown_fields():
    t = Table({"x": 1.0, "typo": 2})
    with pytest.raises(SpecError, match="missing required field") as info:
        t.number("y")
    assert info.value.path == "y"
    t.number("x")
    with pytest.raises(SpecError, match="unknown field") as info:
        t.finish()
    assert info.value.path == "typo"


def test_array_shape_and_rows():
    with pytest.raises(SpecError, match="expected 3 values, got 2") as info:
        check_array([[1, 2, 3], [4, 5]], "poses_deg", shape=(None, 3))
    assert info.value.path == "poses_deg[1]"
    with pytest.raises(SpecError, match="at least 5 entries"):
        check_array([[1, 2, 3]], "poses_deg", shape=(None, 3), min_rows=5)
    arr = check_array([[1, 2, 3], [4, 5, 6]], "p", shape=(None, 3))
    assert arr.dtype == np.float64 and arr.shape == (2, 3)


def test_string_choices():
    with pytest.raises(SpecError, match="expected one of 'sla', 'laser'") as info:
        Table({"process": {"profile": "cnc"}}).table("process").string("profile", choices=("sla", "laser"))
    assert info.value.path == "process.profile"


def test_process_profile_and_override():
    sla = parse_process(Table({"profile": "sla", "running_clearance_mm": 0.3}, "process"))
    assert sla.name == "sla" and sla.running_clearance_mm == 0.3 and sla.hole_compensation_mm == 0.2
    laser = parse_process(Table({"profile": "laser"}, "process"))
    assert laser.kerf_mm == 0.2 and laser.min_wall_mm >= laser.thickness_mm
    with pytest.raises(SpecError, match="below the process minimum") as info:
        parse_process(Table({"profile": "sla", "pin_diameter_mm": 1.0}, "process"))
    assert info.value.path == "process.pin_diameter_mm"
    with pytest.raises(SpecError) as info:
        parse_process(Table({"profile": "sla", "kerf": 0.1}, "process"))
    assert info.value.path == "process.kerf"


def test_unknown_template_is_a_spec_error():
    with pytest.raises(SpecError, match="template not found"):
        find_template("no_such_design")


def test_shipped_templates_exclude_process_profiles():
    assert all(not p.name.startswith("process_") for p in shipped_templates())


@given(st.lists(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6), min_size=1,
                max_size=20))
def test_valid_number_lists_round_trip(values):
    assert np.array_equal(check_array(values, "v"), np.asarray(values, dtype=np.float64))


def test_gear_bore_must_match_the_pin(tmp_path):
    from fabricate.spec import load_design

    text = ("[design]\nname = 'g'\nkind = 'gear_pair'\n[gear_pair]\nfamily = 'elliptic'\neccentricity = 0.2\n"
            "closed = true\n[gears]\nmodule_mm = 1.0\nteeth = [30, 30]\nbore_mm = 3.0\n")
    path = tmp_path / "g.toml"
    path.write_text(text)
    with pytest.raises(SpecError, match="differs from the pin diameter 2 mm") as info:
        load_design(path)
    assert info.value.path == "gears.bore_mm"
    path.write_text(text.replace("[gear_pair]", "[process]\npin_diameter_mm = 3.0\n[gear_pair]"))
    assert load_design(path).gears.bore_mm == 3.0
