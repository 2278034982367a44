"""Template validation: every error names the field path and what was expected."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fabricate.errors import SpecError
from fabricate.process import parse_process
from fabricate.table import Table, check_array, check_number
from fabricate.templates import find_template, shipped_templates


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
    from fabricate.design import load_design

    text = ("[design]\nname = 'g'\nkind = 'gear_pair'\n[gear_pair]\nfamily = 'elliptic'\neccentricity = 0.2\n"
            "closed = true\n[gears]\nmodule_mm = 1.0\nteeth = [30, 30]\nbore_mm = 3.0\n")
    path = tmp_path / "g.toml"
    path.write_text(text)
    with pytest.raises(SpecError, match="differs from the pin diameter 2 mm") as info:
        load_design(path)
    assert info.value.path == "gears.bore_mm"
    path.write_text(text.replace("[gear_pair]", "[process]\npin_diameter_mm = 3.0\n[gear_pair]"))
    assert load_design(path).gears.bore_mm == 3.0


# -- issue 23: a misspelt required key is named; names and numbers the system cannot take are SpecErrors ------

def test_a_missing_required_key_names_its_misspelling():
    """The whole message of the issue's example, from a shipped template with the typo: the unread key that
    looks like the missing one is named with the key it should be."""
    from fabricate.design import design_from_text
    from fabricate.templates import TEMPLATE_DIR

    text = (TEMPLATE_DIR / "finger_five_bar_ncg.toml").read_text(encoding="utf-8")
    assert text.count("\nlengths_mm =") == 1
    with pytest.raises(SpecError) as info:
        design_from_text(text.replace("\nlengths_mm =", "\nlenghts_mm ="), "typo.toml")
    assert str(info.value) == ('finger.lengths_mm: missing required field (found unknown "lenghts_mm": '
                               'did you mean "lengths_mm"?)')


@pytest.mark.parametrize(("present", "offered"), [
    ({"lenghts_mm": 1}, "lenghts_mm"),         # a transposition
    ({"Lengths_MM": 1}, "Lengths_MM"),         # the case alone
    ({"lengths": 1}, None),                    # a run of the key's words: another field ("teeth" / "min_teeth")
    ({"lengths_deg": 1}, None),                # another unit of the same quantity
    ({"heights_mm": 1}, None),                 # another word
    ({"lenghts_mm": 1, "x": 2}, "lenghts_mm"),
])
def test_did_you_mean_offers_only_a_likely_slip(present, offered):
    t = Table(present, "finger")
    with pytest.raises(SpecError) as info:
        t.array("lengths_mm")
    assert info.value.path == "finger.lengths_mm"
    hint = f' (found unknown "{offered}": did you mean "lengths_mm"?)' if offered else ""
    assert info.value.message == "missing required field" + hint


def test_did_you_mean_never_offers_a_key_already_read_or_a_series_sibling():
    t = Table({"theta1_deg": 1.0, "theta2_deg": 2.0, "lengths_mn": 3.0})
    t.number("lengths_mn")  # read: a valid field of this table, not a misspelling
    with pytest.raises(SpecError) as info:
        t.number("lengths_mm")
    assert info.value.message == "missing required field"
    with pytest.raises(SpecError) as info:
        t.number("theta3_deg")  # theta1_deg / theta2_deg are its siblings, not its misspellings
    assert info.value.message == "missing required field"


def test_no_required_field_of_a_shipped_template_is_offered_a_valid_field():
    """Every required key of every table the shipped templates have, against every key the same table's
    parser reads: none is close enough to be offered as a misspelling (so deleting a required field never
    names a valid field beside it as "unknown")."""
    import difflib
    import re
    from collections import defaultdict

    import fabricate.table as table_module
    from fabricate.design import load_design

    read: dict[str, set[str]] = defaultdict(set)
    required: dict[str, set[str]] = defaultdict(set)
    original = table_module.Table._get

    def recording(self, key, default):
        where = re.sub(r"\[\d+\]", "[]", self.path)
        read[where].add(key)
        if default is table_module._MISSING:
            required[where].add(key)
        return original(self, key, default)

    table_module.Table._get = recording
    try:
        for path in shipped_templates():
            load_design(path)
    finally:
        table_module.Table._get = original
    assert sum(map(len, required.values())) > 50  # the recording saw the parsers
    offered = [(where, key, other) for where, keys in required.items() for key in keys for other in read[where]
               if other != key and not table_module._different_field(key, other)
               and difflib.SequenceMatcher(None, key.lower(), other.lower()).ratio()
               >= table_module.MISSPELLING_CUTOFF]
    assert offered == []


@pytest.mark.parametrize(("name", "why"), [
    ("a\0b", "control character U+0000"), ("a\x01b", "control character U+0001"),
    ("a\x7fb", "control character U+007F"), ("a\u2028b", "line separator U+2028"), ("a\ud800", "surrogate"),
    (".", 'starts with "."'), ("..", 'starts with "."'), (".hidden", 'starts with "."'),
    ("a/b", 'holds "/"'), ("a\\b", 'holds "\\"'), ("a:b", 'holds ":"'), ("a*b", 'holds "*"'),
    ("a|b", 'holds "|"'), (" lead", "spaces at an end"), ("trail ", "spaces at an end"), ("trail.", 'ends with "."'),
    ("", "empty name"), ("x" * 101, "got 101 characters"), ("\u20ac" * 67, "(201 bytes)"),
])
def test_design_name_must_name_a_folder(name, why):
    from fabricate.spec import check_design_name

    with pytest.raises(SpecError) as info:
        check_design_name(name)
    assert info.value.path == "design.name"
    assert why in info.value.message
    assert "\0" not in str(info.value) and "\x01" not in str(info.value)  # shown escaped, never raw


@pytest.mark.parametrize("name", ["Fin_ger-1.2", "a b", "x" * 100, "\u00e9" * 100, "finger (v2)"])
def test_design_names_that_make_folders_are_kept(name):
    from fabricate.spec import check_design_name

    assert check_design_name(name) == name


def test_a_nul_in_the_template_design_name_is_a_spec_error():
    from fabricate.design import design_from_text
    from fabricate.templates import TEMPLATE_DIR

    text = (TEMPLATE_DIR / "gear_pair_elliptic.toml").read_text(encoding="utf-8")
    with pytest.raises(SpecError, match=r'got "gear\\u0000pair"') as info:
        design_from_text(text.replace('name = "gear_pair_elliptic"', 'name = "gear\\u0000pair"', 1), "g.toml")
    assert info.value.path == "design.name"


def test_integers_past_a_float_are_spec_errors():
    from fabricate.design import design_from_text
    from fabricate.templates import TEMPLATE_DIR

    text = (TEMPLATE_DIR / "gear_pair_elliptic.toml").read_text(encoding="utf-8")
    assert "\nmodule_mm = 1.0\n" in text
    with pytest.raises(SpecError, match="got an integer of 400 digits") as info:
        design_from_text(text.replace("\nmodule_mm = 1.0\n", f"\nmodule_mm = {'9' * 400}\n"), "g.toml")
    assert info.value.path == "gears.module_mm"
    with pytest.raises(SpecError, match="invalid TOML: a number too long to read") as info:
        design_from_text(text.replace("\nmodule_mm = 1.0\n", f"\nmodule_mm = {'9' * 5000}\n"), "g.toml")
    assert info.value.path == "g.toml"
    with pytest.raises(SpecError, match="got an integer of 401 digits") as info:
        check_number(-7 * 10**400, "x")
    assert info.value.path == "x"


def test_paths_the_system_refuses_are_spec_errors():
    from fabricate.process import process_override

    for argument, call in (("template", find_template), ("--process", process_override)):
        with pytest.raises(SpecError, match="File name too long") as info:
            call("x" * 5000)
        assert info.value.path == argument
    with pytest.raises(SpecError, match="template not found"):
        find_template("a\0b")
    with pytest.raises(SpecError, match="expected a template name or path"):
        find_template(42)
