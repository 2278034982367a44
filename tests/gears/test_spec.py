"""The ``[gears]`` table (:mod:`fabricate.gears.spec`): defaults, every documented range, the cross-field rules.

Expected values come from the module docstring (defaults and ranges) and from the closed forms of the
rack's tooth space (:func:`fabricate.gears.rack.rack_fit`, ``h_f <= (pi/4 - land) cot(alpha)``), never from
the parser itself. A value exactly at a documented limit must come back unchanged; one a relative 1e-9
(or one integer) past it must be refused with a :class:`~fabricate.errors.SpecError` naming
``gears.<key>``.
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from fabricate.bounds import MAX_MESH_STEPS, MAX_TEETH
from fabricate.errors import SpecError
from fabricate.gears.rack import MIN_ROOT_LAND, rack_fit
from fabricate.gears.spec import METHODS, MIN_MODULE_MM, GearSpec, parse_gear_spec
from fabricate.table import Table

#: The documented defaults, field by field (module docstring, "Keys").
DEFAULTS = {
    "module_mm": None, "pressure_angle_deg": 20.0, "addendum": 1.0, "dedendum": 1.25, "root_fillet": 0.38,
    "backlash_mm": 0.05, "method": "exact", "compare_methods": True, "spare_teeth": 1, "mesh_steps": 720,
    "closed": None, "teeth": None, "min_teeth": 8, "bore_mm": None, "hub_diameter_mm": None,
}

EPS = 1e-9


def _parse(**fields) -> GearSpec:
    return parse_gear_spec(Table(fields, "gears"))


def _refused(**fields) -> SpecError:
    with pytest.raises(SpecError) as info:
        _parse(**fields)
    return info.value


def _floor3(value: float) -> float:
    """A limit rounded down to 0.001 m, as an "at most" in a message must be (it must itself fit)."""
    return math.floor(value * 1000.0) / 1000.0


def _rack(pressure_deg: float, dedendum: float) -> tuple[float, float]:
    return rack_fit(math.radians(pressure_deg), dedendum)


# -- defaults ---------------------------------------------------------------------------------------
def test_empty_table_gives_the_documented_defaults():
    """``{}`` (an absent ``[gears]`` table) gives every documented default, with the documented types."""
    spec = _parse()
    for name, value in DEFAULTS.items():
        got = getattr(spec, name)
        assert got == value and type(got) is type(value), name
    # the module is chosen, so the pressure angle is too: Shigley's full-depth 20, 22.5, 25 deg, 20 first, each with
    # the default 1.25 m dedendum and a root fillet that fits the rack at it (the default 0.38 m at 20 deg, no
    # larger at the steeper angles, whose flanks leave less room at the root)
    candidates = spec.pressure_angle_candidates
    assert [c[0] for c in candidates] == [20.0, 22.5, 25.0]
    assert all(c[1] == 1.25 for c in candidates) and candidates[0][2] == 0.38
    assert all(0.0 < b[2] <= a[2] for a, b in zip(candidates, candidates[1:], strict=False))
    assert spec == GearSpec(**DEFAULTS, pressure_angle_candidates=candidates)


def test_dataclass_defaults_match_the_documented_ones():
    """``GearSpec()`` (used where no template exists) carries the same defaults as an empty table."""
    spec = GearSpec()
    for name, value in DEFAULTS.items():
        got = getattr(spec, name)
        assert got == value and type(got) is type(value), name


def test_spec_is_immutable():
    """A validated spec is frozen (shared between stages and used as a hashable value)."""
    spec = _parse(module_mm=1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.module_mm = 2.0  # type: ignore[misc]
    assert hash(spec) == hash(_parse(module_mm=1.0))


def test_defaults_fit_the_rack_at_20_degrees():
    """At the default 20 deg the standard 1.25 m dedendum and 0.38 m fillet fit (2.10 m, 0.443 m), so stay."""
    max_dedendum, max_fillet = _rack(20.0, 1.25)
    assert max_dedendum > 1.25 and max_fillet > 0.38
    spec = _parse(pressure_angle_deg=20.0)
    assert (spec.dedendum, spec.root_fillet) == (1.25, 0.38)


def test_every_key_is_read_into_its_own_field():
    """A table giving every key a non-default value returns each value in the field of the same name."""
    fields = {
        "module_mm": 1.5, "pressure_angle_deg": 18.0, "addendum": 0.9, "dedendum": 1.3, "root_fillet": 0.3,
        "backlash_mm": 0.08, "method": "approx", "compare_methods": False, "spare_teeth": 3, "mesh_steps": 1000,
        "closed": True, "teeth": [12, 30], "min_teeth": 10, "bore_mm": 3.0, "hub_diameter_mm": 8.0,
    }
    # 18 deg, dedendum 1.3: the tooth space holds 2.36 m and a 0.53 m fillet, so nothing adapts
    assert _rack(18.0, 1.3)[0] > 1.3 and _rack(18.0, 1.3)[1] > 0.3
    spec = _parse(**fields)
    expected = dict(fields, teeth=(12, 30))
    for name, value in expected.items():
        assert getattr(spec, name) == value, name
    assert type(spec.spare_teeth) is int and type(spec.mesh_steps) is int and type(spec.min_teeth) is int


# -- ranges -----------------------------------------------------------------------------------------
#: (key, lower limit, upper limit, other fields so that only the limit under test decides).
FLOAT_RANGES = [
    ("module_mm", MIN_MODULE_MM, 50.0, {}),
    ("pressure_angle_deg", 10.0, 35.0, {}),  # 35 deg: the default dedendum adapts (1.093 m > addendum 1)
    ("addendum", 0.3, 1.5, {"dedendum": 2.0}),  # 2.0 m fits at 20 deg (2.10 m) and exceeds 1.5
    ("dedendum", 0.5, 2.0, {"addendum": 0.3}),  # 0.3 < 0.5; 2.0 fits at 20 deg
    ("root_fillet", 0.0, 0.5, {"pressure_angle_deg": 15.0}),  # 15 deg, dedendum 1.25: fillet up to 0.561 m
    ("backlash_mm", 0.0, 1.0, {}),
]


def test_documented_constants():
    """The module's limits are the documented numbers (0.05 mm module; 720..7200 steps; 3..100 teeth)."""
    assert MIN_MODULE_MM == 0.05
    assert METHODS == ("exact", "approx")
    assert (MAX_MESH_STEPS, MAX_TEETH) == (7200, 100)


def test_range_contexts_fit_the_rack():
    """The helper fields of the range cases let only the bound decide (the tooth space holds the extremes)."""
    assert _rack(20.0, 2.0)[0] > 2.0 * (1 + EPS)  # dedendum 2.0 and just above fit at 20 deg
    assert _rack(15.0, 1.25)[1] > 0.5 * (1 + EPS)  # a 0.5 m fillet and just above fit at 15 deg
    assert _rack(20.0, 0.5)[1] > 0.38  # a 0.5 m root keeps the default fillet
    assert _rack(35.0, 1.25)[0] > 1.0  # 35 deg still leaves tip clearance for the default addendum
    assert _rack(35.0 * (1 + EPS), 1.25)[0] > 1.0  # ... and so does just past 35 deg: only the bound refuses


@pytest.mark.parametrize(("key", "low", "high", "context"), FLOAT_RANGES, ids=[r[0] for r in FLOAT_RANGES])
def test_float_at_its_limits_is_accepted(key, low, high, context):
    """Both ends of a closed range are valid and come back exactly."""
    for limit in (low, high):
        spec = _parse(**dict(context, **{key: limit}))
        assert getattr(spec, key) == limit


@pytest.mark.parametrize(("key", "low", "high", "context"), FLOAT_RANGES, ids=[r[0] for r in FLOAT_RANGES])
def test_float_just_outside_is_refused(key, low, high, context):
    """A relative 1e-9 below the lower / above the upper limit is refused, naming the field and the limit."""
    below = low * (1 - EPS) if low else -EPS
    err = _refused(**dict(context, **{key: below}))
    assert err.path == f"gears.{key}"
    assert err.message == f"expected a number >= {low:g}, got {below:g}"
    above = high * (1 + EPS)
    err = _refused(**dict(context, **{key: above}))
    assert err.path == f"gears.{key}"
    assert err.message == f"expected a number <= {high:g}, got {above:g}"


#: (key, lower limit, upper limit, other fields).
INT_RANGES = [
    ("spare_teeth", 1, 20, {}),
    ("mesh_steps", 720, MAX_MESH_STEPS, {}),
    ("min_teeth", 3, MAX_TEETH, {}),
]


@pytest.mark.parametrize(("key", "low", "high", "context"), INT_RANGES, ids=[r[0] for r in INT_RANGES])
def test_integer_at_its_limits_is_accepted(key, low, high, context):
    """Both ends of an integer range are valid and come back as that int."""
    for limit in (low, high):
        got = getattr(_parse(**dict(context, **{key: limit})), key)
        assert got == limit and type(got) is int


@pytest.mark.parametrize(("key", "low", "high", "context"), INT_RANGES, ids=[r[0] for r in INT_RANGES])
def test_integer_next_outside_is_refused(key, low, high, context):
    """The integer before the lower / after the upper limit is refused, naming the field."""
    err = _refused(**dict(context, **{key: low - 1}))
    assert err.path == f"gears.{key}"
    assert err.message == f"expected a number >= {low:g}, got {low - 1:g}"
    err = _refused(**dict(context, **{key: high + 1}))
    assert err.path == f"gears.{key}"
    assert err.message == f"expected a number <= {high:g}, got {high + 1:g}"


@pytest.mark.parametrize("key", ["spare_teeth", "mesh_steps", "min_teeth"])
def test_integer_fields_refuse_fractions(key):
    """Counts are whole numbers: 1000.5 (inside every range's span) is refused naming the field."""
    err = _refused(**{key: 10.5 if key != "mesh_steps" else 1000.5})
    assert err.path == f"gears.{key}" and "whole number" in err.message


@pytest.mark.parametrize(("key", "high"), [("bore_mm", 50.0), ("hub_diameter_mm", 1000.0)])
def test_positive_lengths(key, high):
    """``bore_mm`` in (0, 50] and ``hub_diameter_mm`` in (0, 1000]: 0 refused, tiny and the maximum kept."""
    for value in (1e-9, high):
        assert getattr(_parse(**{key: value}), key) == value
    for value in (0.0, -1.0):
        err = _refused(**{key: value})
        assert err.path == f"gears.{key}"
        assert err.message == f"expected a positive number, got {value:g}"
    above = high * (1 + EPS)
    err = _refused(**{key: above})
    assert err.path == f"gears.{key}"
    assert err.message == f"expected a number <= {high:g}, got {above:g}"


@pytest.mark.parametrize("z", [3, MAX_TEETH])
def test_teeth_at_their_limits_are_accepted(z):
    """Tooth counts 3 and MAX_TEETH are valid (min_teeth 3 so the check against it does not decide)."""
    spec = _parse(teeth=[z, z], min_teeth=3)
    assert spec.teeth == (z, z)


@pytest.mark.parametrize(("teeth", "index", "message"), [
    ([3 * (1 - EPS), 10], 0, f"expected a number >= 3, got {3 * (1 - EPS):g}"),
    ([10, 2], 1, "expected a number >= 3, got 2"),
    ([MAX_TEETH * (1 + EPS), 10], 0, f"expected a number <= {MAX_TEETH}, got {MAX_TEETH * (1 + EPS):g}"),
    ([10, MAX_TEETH + 1], 1, f"expected a number <= {MAX_TEETH}, got {MAX_TEETH + 1}"),
])
def test_teeth_outside_their_range_name_the_entry(teeth, index, message):
    """An entry outside [3, MAX_TEETH] is refused naming ``gears.teeth[i]``."""
    err = _refused(teeth=teeth, min_teeth=3)
    assert err.path == f"gears.teeth[{index}]"
    assert err.message == message


# -- choices, booleans, teeth -----------------------------------------------------------------------
@pytest.mark.parametrize("method", ["exact", "approx"])
def test_methods_accepted(method):
    assert _parse(method=method).method == method


@pytest.mark.parametrize("method", ["Exact", "osculating", ""])
def test_unknown_method_refused(method):
    err = _refused(method=method)
    assert err.path == "gears.method"
    assert err.message == f"expected one of 'exact', 'approx', got \"{method}\""


@pytest.mark.parametrize("value", [True, False])
def test_booleans_given(value):
    """``compare_methods`` and ``closed`` return what the table says (``closed`` absent: None, not False)."""
    spec = _parse(compare_methods=value, closed=value)
    assert spec.compare_methods is value and spec.closed is value
    assert _parse(compare_methods=value).closed is None


@pytest.mark.parametrize("key", ["compare_methods", "closed"])
@pytest.mark.parametrize("value", [1, "true", 0.0])
def test_booleans_refuse_other_types(key, value):
    err = _refused(**{key: value})
    assert err.path == f"gears.{key}" and "expected true or false" in err.message


def test_teeth_become_a_tuple_of_int():
    """Whole-number entries (int or float in TOML) become ``(z_a, z_b)`` ints, in order."""
    for given in ([20, 31], [20.0, 31.0]):
        spec = _parse(teeth=given)
        assert spec.teeth == (20, 31)
        assert type(spec.teeth) is tuple and all(type(z) is int for z in spec.teeth)


@pytest.mark.parametrize(("teeth", "index"), [([20, 30.5], 1), ([20.5, 30], 0), ([12.25, 30.75], 0)])
def test_teeth_must_be_whole(teeth, index):
    """A fractional tooth count is refused naming the (first) fractional entry."""
    err = _refused(teeth=teeth)
    assert err.path == f"gears.teeth[{index}]"
    assert err.message == f"expected a whole number, got {teeth[index]:g}"


@pytest.mark.parametrize(("teeth", "count"), [([20], 1), ([20, 30, 40], 3)])
def test_teeth_need_two_entries(teeth, count):
    err = _refused(teeth=teeth)
    assert err.path == "gears.teeth" and err.message == f"expected 2 values, got {count}"


def test_unknown_key_refused():
    """A key the table does not know (a typo) is an error naming it, even next to valid keys."""
    for fields in ({"modul_mm": 1.0}, {"module_mm": 1.0, "teeth_count": [10, 20]}):
        err = _refused(**fields)
        assert err.message == "unknown field"
        assert err.path == "gears." + next(k for k in fields if k not in DEFAULTS)


# -- tip clearance ----------------------------------------------------------------------------------
@pytest.mark.parametrize(("addendum", "dedendum"), [(1.0, 1.0), (1.2, 1.1), (0.5, 0.5), (1.5, 1.25)])
def test_dedendum_must_exceed_addendum(addendum, dedendum):
    """Equal or shallower roots leave no tip clearance; the message suggests the standard 0.25 m more."""
    err = _refused(addendum=addendum, dedendum=dedendum)
    assert err.path == "gears.dedendum"
    assert err.message == (f"dedendum {dedendum:g} m must exceed addendum {addendum:g} m (tip clearance); "
                           f"use dedendum >= {addendum + 0.25:g}")


def test_default_dedendum_below_a_large_addendum():
    """Addendum 1.5 with the default 1.25 dedendum is refused on the dedendum (even at 35 deg)."""
    for pressure in (20.0, 35.0):
        err = _refused(addendum=1.5, pressure_angle_deg=pressure)
        assert err.path == "gears.dedendum"
        assert err.message.endswith("use dedendum >= 1.75")


def test_dedendum_just_above_addendum_accepted():
    spec = _parse(addendum=1.0, dedendum=1.0 + EPS)
    assert (spec.addendum, spec.dedendum) == (1.0, 1.0 + EPS)


# -- hub and bore -----------------------------------------------------------------------------------
@pytest.mark.parametrize(("bore", "hub"), [(3.0, 3.0), (3.0, 2.0), (50.0, 1e-9)])
def test_hub_must_exceed_bore(bore, hub):
    err = _refused(bore_mm=bore, hub_diameter_mm=hub)
    assert err.path == "gears.hub_diameter_mm"
    assert err.message == f"hub {hub:g} mm must be larger than the bore {bore:g} mm"


def test_hub_just_above_bore_and_either_alone_accepted():
    spec = _parse(bore_mm=3.0, hub_diameter_mm=3.0 * (1 + EPS))
    assert (spec.bore_mm, spec.hub_diameter_mm) == (3.0, 3.0 * (1 + EPS))
    spec = _parse(hub_diameter_mm=6.0)
    assert (spec.bore_mm, spec.hub_diameter_mm) == (None, 6.0)
    spec = _parse(bore_mm=6.0)
    assert (spec.bore_mm, spec.hub_diameter_mm) == (6.0, None)


# -- teeth against min_teeth ------------------------------------------------------------------------
@pytest.mark.parametrize(("teeth", "min_teeth"), [([8, 30], None), ([30, 8], None), ([15, 15], 15),
                                                  ([100, 12], 12), ([3, 4], 3)])
def test_teeth_at_min_teeth_accepted(teeth, min_teeth):
    """The smaller count equal to min_teeth (default 8) is accepted, whichever gear has it."""
    fields = {"teeth": teeth} if min_teeth is None else {"teeth": teeth, "min_teeth": min_teeth}
    assert _parse(**fields).teeth == tuple(teeth)


@pytest.mark.parametrize(("teeth", "min_teeth"), [([7, 30], None), ([30, 7], None), ([12, 20], 15),
                                                  ([20, 12], 15), ([14, 14], 15), ([99, 99], 100)])
def test_teeth_below_min_teeth_refused(teeth, min_teeth):
    """The smaller of the two counts is checked; the message names it and min_teeth."""
    fields = {"teeth": teeth} if min_teeth is None else {"teeth": teeth, "min_teeth": min_teeth}
    err = _refused(**fields)
    assert err.path == "gears.teeth"
    least = min(teeth)
    bound = 8 if min_teeth is None else min_teeth
    assert err.message == f"{least} teeth is below min_teeth = {bound}; use more teeth (a smaller module)"


# -- the rack's tooth space -------------------------------------------------------------------------
STEEP = [22.5, 25.0, 30.0, 31.0, 31.5, 32.0, 33.0, 35.0]


@pytest.mark.parametrize("pressure", STEEP)
def test_defaults_adapt_to_a_steep_pressure_angle(pressure):
    """With defaults, dedendum and fillet are the template's or the largest that fit, whichever is smaller.

    ``rack_fit`` gives the deepest root the tooth space holds and the largest fillet for a root depth;
    the fillet is sized for the dedendum actually cut.
    """
    max_dedendum, _ = _rack(pressure, 1.25)
    dedendum = min(1.25, max_dedendum)
    fillet = min(0.38, _rack(pressure, dedendum)[1])
    spec = _parse(pressure_angle_deg=pressure)
    assert spec.dedendum == dedendum
    assert spec.root_fillet == fillet
    assert spec.pressure_angle_deg == pressure
    # the result fits: given explicitly it is kept
    again = _parse(pressure_angle_deg=pressure, dedendum=spec.dedendum, root_fillet=spec.root_fillet)
    assert (again.dedendum, again.root_fillet) == (spec.dedendum, spec.root_fillet)


@pytest.mark.parametrize("pressure", STEEP)
def test_documented_adaptation_thresholds(pressure):
    """Above about 22 deg the default fillet is reduced; above about 31 deg also the default dedendum.

    Closed forms: the dedendum limit is ``(pi/4 - 0.02) cot(alpha)`` = 1.25 at 31.48 deg; the fillet
    limit for the 1.25 root falls below 0.38 at about 22.2 deg.
    """
    spec = _parse(pressure_angle_deg=pressure)
    assert spec.root_fillet < 0.38
    crossing = math.degrees(math.atan((math.pi / 4 - MIN_ROOT_LAND) / 1.25))
    assert 31.4 < crossing < 31.5
    if pressure > crossing:
        assert spec.dedendum < 1.25
        assert spec.dedendum == pytest.approx((math.pi / 4 - MIN_ROOT_LAND) / math.tan(math.radians(pressure)))
    else:
        assert spec.dedendum == 1.25


@pytest.mark.parametrize("pressure", [10.0, 15.0, 20.0, 22.0])
def test_defaults_kept_below_the_thresholds(pressure):
    """Up to 22 deg the 0.38 m fillet still fits the 1.25 m root (0.386 m at 22 deg): nothing adapts."""
    assert _rack(pressure, 1.25)[1] > 0.38
    spec = _parse(pressure_angle_deg=pressure)
    assert (spec.dedendum, spec.root_fillet) == (1.25, 0.38)


@pytest.mark.parametrize(("pressure", "dedendum"), [(30.0, 1.4), (32.0, 1.25), (35.0, 1.25), (25.0, 1.7),
                                                    (33.0, 2.0), (21.0, 2.0)])
def test_explicit_dedendum_too_deep_refused_with_its_limit(pressure, dedendum):
    """A dedendum given explicitly is never reduced: it is refused with the limit rounded *down* to 0.001."""
    max_dedendum, _ = _rack(pressure, dedendum)
    assert dedendum > max_dedendum
    err = _refused(pressure_angle_deg=pressure, dedendum=dedendum)
    assert err.path == "gears.dedendum"
    assert err.message == (f"dedendum {dedendum:g} m does not fit the rack's tooth space at pressure angle "
                           f"{pressure:g} deg; at most {_floor3(max_dedendum):g} m")


def test_floor3_rounds_down():
    """The "at most" values of the rack cases: 1.32571 -> 1.325 (not 1.326), 0.45095 -> 0.45 (not 0.451)."""
    assert _floor3(_rack(30.0, 2.0)[0]) == 1.325
    assert _floor3(_rack(23.0, 1.1)[1]) == 0.45
    assert "at most 1.325 m" in _refused(pressure_angle_deg=30.0, dedendum=1.4).message
    assert "at most 0.45 m" in _refused(pressure_angle_deg=23.0, dedendum=1.1, root_fillet=0.5).message


@pytest.mark.parametrize("pressure", [25.0, 30.0, 33.0])
def test_explicit_dedendum_at_its_limit_is_kept(pressure):
    """Exactly the deepest root the tooth space holds fits (the limit is inclusive)."""
    max_dedendum, _ = _rack(pressure, 2.0)
    spec = _parse(pressure_angle_deg=pressure, dedendum=max_dedendum)
    assert spec.dedendum == max_dedendum
    assert spec.root_fillet == min(0.38, _rack(pressure, max_dedendum)[1])


@pytest.mark.parametrize(("pressure", "dedendum"), [(33.0, 1.15), (30.0, 1.3), (25.0, 1.6), (10.0, 2.0)])
def test_explicit_dedendum_that_fits_is_kept(pressure, dedendum):
    """A fitting explicit dedendum is not changed; the default fillet adapts to it."""
    assert dedendum <= _rack(pressure, dedendum)[0]
    spec = _parse(pressure_angle_deg=pressure, dedendum=dedendum)
    assert spec.dedendum == dedendum
    assert spec.root_fillet == min(0.38, _rack(pressure, dedendum)[1])


@pytest.mark.parametrize(("pressure", "dedendum", "fillet"), [
    (23.0, 1.1, 0.5),  # limit 0.45095: "at most 0.45"
    (30.0, None, 0.38),  # default root 1.25: limit 0.0757
    (25.0, None, 0.3),  # limit 0.2865
    (33.0, None, 0.1),  # default root reduced to 1.1786: no fillet fits
    (22.5, 1.25, 0.38),  # limit 0.3706
])
def test_explicit_fillet_too_large_refused_with_its_limit(pressure, dedendum, fillet):
    """A fillet given explicitly is refused, naming the dedendum actually cut and the limit rounded down."""
    fields = {"pressure_angle_deg": pressure, "root_fillet": fillet}
    if dedendum is not None:
        fields["dedendum"] = dedendum
    cut = min(1.25 if dedendum is None else dedendum, _rack(pressure, 2.0)[0])
    max_fillet = _rack(pressure, cut)[1]
    assert fillet > max_fillet
    err = _refused(**fields)
    assert err.path == "gears.root_fillet"
    assert err.message == (f"root fillet {fillet:g} m does not fit the rack's tooth space at pressure angle "
                           f"{pressure:g} deg with dedendum {cut:g} m; at most {_floor3(max_fillet):g} m")


@pytest.mark.parametrize(("pressure", "dedendum"), [(25.0, 1.25), (23.0, 1.1), (20.0, 2.0), (30.0, 1.3)])
def test_explicit_fillet_at_its_limit_is_kept(pressure, dedendum):
    """Exactly the largest fillet for the root fits (the limit is inclusive)."""
    max_fillet = _rack(pressure, dedendum)[1]
    spec = _parse(pressure_angle_deg=pressure, dedendum=dedendum, root_fillet=max_fillet)
    assert (spec.dedendum, spec.root_fillet) == (dedendum, max_fillet)


@pytest.mark.parametrize(("pressure", "fillet"), [(25.0, 0.2), (30.0, 0.05), (35.0, 0.0), (20.0, 0.44)])
def test_explicit_fillet_that_fits_is_kept(pressure, fillet):
    cut = min(1.25, _rack(pressure, 2.0)[0])
    assert fillet <= _rack(pressure, cut)[1]
    spec = _parse(pressure_angle_deg=pressure, root_fillet=fillet)
    assert (spec.dedendum, spec.root_fillet) == (cut, fillet)


def _angle_limit(addendum: float) -> float:
    """Steepest pressure angle (deg, down to 0.1) whose deepest root still exceeds ``addendum``."""
    limit = math.degrees(math.atan((math.pi / 4 - MIN_ROOT_LAND) / addendum))
    return math.floor(limit * 10) / 10


@pytest.mark.parametrize(("pressure", "addendum"), [(35.0, 1.2), (33.0, 1.2), (35.0, 1.1), (34.0, 1.24)])
def test_no_tip_clearance_left_names_the_pressure_angle(pressure, addendum):
    """With the default dedendum, a tooth space not deeper than the addendum is a pressure-angle error.

    E.g. 35 deg holds a 1.093 m root, not deeper than addendum 1.2; the largest angle for 1.2 is
    atan((pi/4 - 0.02) / 1.2) = 32.53 deg, "at most 32.5 deg".
    """
    max_dedendum, _ = _rack(pressure, 1.25)
    assert max_dedendum <= addendum < 1.25
    err = _refused(pressure_angle_deg=pressure, addendum=addendum)
    assert err.path == "gears.pressure_angle_deg"
    assert err.message == (f"at {pressure:g} deg the rack's tooth space is {max_dedendum:.3g} m deep, not deeper "
                           f"than the addendum {addendum:g} m; at most {_angle_limit(addendum):g} deg "
                           "with this addendum (or a smaller addendum)")


def test_angle_limit_closed_form():
    """The closed form for addendum 1.2 is 32.53 deg; 32.5 deg builds, 32.6 deg does not."""
    assert _angle_limit(1.2) == 32.5
    spec = _parse(pressure_angle_deg=32.5, addendum=1.2)
    assert spec.dedendum == _rack(32.5, 1.25)[0] > 1.2
    assert _refused(pressure_angle_deg=32.6, addendum=1.2).path == "gears.pressure_angle_deg"


def test_tooth_space_exactly_as_deep_as_the_addendum_is_refused():
    """Clearance must be positive: an addendum equal to the deepest root at 33 deg is refused."""
    addendum = _rack(33.0, 1.25)[0]
    err = _refused(pressure_angle_deg=33.0, addendum=addendum)
    assert err.path == "gears.pressure_angle_deg"
    assert f"at most {_angle_limit(addendum):g} deg" in err.message


def test_explicit_dedendum_takes_precedence_over_the_angle_error():
    """With the dedendum given, a too-deep value is reported on the dedendum, not the pressure angle."""
    err = _refused(pressure_angle_deg=35.0, addendum=1.2, dedendum=1.25)
    assert err.path == "gears.dedendum"
    assert err.message.endswith(f"at most {_floor3(_rack(35.0, 1.25)[0]):g} m")


# -- GearSpec helpers -------------------------------------------------------------------------------
@pytest.mark.parametrize("pressure", [10.0, 14.5, 20.0, 22.5, 35.0])
def test_pressure_angle_in_radians(pressure):
    assert GearSpec(pressure_angle_deg=pressure).pressure_angle == math.radians(pressure)
    assert _parse(pressure_angle_deg=pressure).pressure_angle == math.radians(pressure)


def test_default_pressure_angle_in_radians():
    assert GearSpec().pressure_angle == math.radians(20.0)


@pytest.mark.parametrize("module", [0.05, 0.5, 1.5, 50.0])
def test_module_or_returns_a_given_module(module):
    assert GearSpec(module_mm=module).module_or(3.0) == module
    assert _parse(module_mm=module).module_or(7) == module


def test_module_or_falls_back_to_the_default_as_float():
    """Absent module: the caller's default, converted to float (an int default stays usable as a length)."""
    for default in (2, 0.5, 3.25):
        got = GearSpec().module_or(default)
        assert got == default and type(got) is float
    got = _parse().module_or(1)
    assert got == 1.0 and type(got) is float


def test_module_or_treats_zero_as_given():
    """Only None means "choose"; a (parser-refused, but constructible) 0.0 is returned as is."""
    assert GearSpec(module_mm=0.0).module_or(5.0) == 0.0
