"""The Python API under arguments of every wrong type (issue 23, item 6): each call succeeds or raises a
:class:`~fabricate.errors.FabricateError` (a SpecError naming the argument), never a TypeError,
AttributeError, OSError or any other exception a user would read as a bug in fabricate.

``run_build`` is replaced by a stub here: what is fuzzed is how the API takes its arguments, not the
pipeline (which the template fuzz and the build tests drive), so a call that gets past its arguments costs
nothing and a wrong type cannot hide behind a slow build.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fabricate
from fabricate.errors import FabricateError, SpecError
from fabricate.spec import DesignSpec
from fabricate.templates import TEMPLATE_DIR, read_toml
from tests.conftest import make_four_bar


class _PathLikeBytes:
    def __fspath__(self) -> bytes:
        return b"gear_pair_elliptic"


#: Values of the wrong type (or of the right type but unusable) for any argument.
WRONG: list[Any] = [
    None, 0, 42, -1, 10**400, 3.5, math.nan, math.inf, True, False, 1 + 2j, b"gear_pair_elliptic",
    bytearray(b"x"), "", " ", "\0", "a\0b", "x" * 5000, "\ud800", "../../no_such_folder/x", "/", ".", [], [1, 2],
    ("a", "b"), (), {}, {"design": 3}, {"design": {"name": object()}}, {1: {}}, set(), frozenset({1}), object(),
    Path(""), Path("/"), _PathLikeBytes(), np.float64(1.0), np.array([1.0, 2.0]), np.array("s"), Ellipsis, type,
    len, lambda: 0, SimpleNamespace(name="x"), range(3), iter([1]),
]
_self: dict[str, Any] = {}
_self["loop"] = _self  # a table that holds itself
WRONG.append(_self)


def _ids(values: list[Any]) -> list[str]:
    return [f"{i}-{type(v).__name__}" for i, v in enumerate(values)]


def _outcome_or_fabricate_error(call, *args, **kwargs) -> Any:
    """Run ``call``; anything but a return or a FabricateError fails the test, naming the exception."""
    try:
        return call(*args, **kwargs)
    except FabricateError as exc:
        assert str(exc), "an error with no message"
        return exc


@pytest.fixture(autouse=True)
def no_pipeline(monkeypatch):
    """run_build is a stub: a valid design returns a Build at once."""
    import fabricate.pipeline

    def stub(design: DesignSpec, pictures: bool = True) -> Any:
        assert isinstance(design, DesignSpec)
        return SimpleNamespace(exit_code=0, report={"checks": {"failures": []}}, files={"a.txt": b"a"})

    monkeypatch.setattr(fabricate.pipeline, "run_build", stub)


@pytest.fixture(scope="module")
def design() -> DesignSpec:
    return fabricate.load("gear_pair_elliptic")


@pytest.mark.parametrize("value", WRONG, ids=_ids(WRONG))
def test_load_and_build_take_any_value_as_the_design(value):
    for call in (fabricate.load, fabricate.build):
        result = _outcome_or_fabricate_error(call, value)
        assert isinstance(result, (SpecError, DesignSpec, fabricate.Build)), result


@pytest.mark.parametrize("value", [v for v in WRONG if v is not None], ids=_ids([v for v in WRONG if v is not None]))
def test_process_of_any_type_is_a_spec_error_naming_it(value, design):
    """None means "the template's own process"; every other wrong value is refused (or, for a string, a file
    that is not there), never a TypeError or AttributeError."""
    for call, first in ((fabricate.load, "gear_pair_elliptic"), (fabricate.build, design),
                        (fabricate.build, "gear_pair_elliptic")):
        result = _outcome_or_fabricate_error(call, first, process=value)
        assert isinstance(result, SpecError), result
        assert result.path in ("process", "--process"), result
        if not isinstance(value, (str, Path)):
            assert result.path == "process" and type(value).__name__ in result.message, result


@pytest.mark.parametrize("value", WRONG, ids=_ids(WRONG))
def test_from_mechanism_takes_any_value_for_each_argument(value):
    mech = make_four_bar()
    result = _outcome_or_fabricate_error(fabricate.from_mechanism, value)
    assert isinstance(result, SpecError) and result.path == "mechanism", result
    for keyword in ("process", "tip_point", "pads", "tables"):
        result = _outcome_or_fabricate_error(fabricate.from_mechanism, mech, **{keyword: value})
        assert isinstance(result, (SpecError, DesignSpec)), (keyword, result)
    result = _outcome_or_fabricate_error(fabricate.from_mechanism, dataclasses.replace(mech, assembly=value))
    assert isinstance(result, (SpecError, DesignSpec)), result
    if isinstance(result, SpecError):
        assert result.path.startswith("mechanism.assembly"), result
    pose = _outcome_or_fabricate_error(
        fabricate.from_mechanism, dataclasses.replace(mech, assembly={**mech.assembly, "crank": value}))
    assert isinstance(pose, DesignSpec) or pose.path == "mechanism.assembly.crank", pose  # range(3) is a pose
    result = _outcome_or_fabricate_error(fabricate.build, dataclasses.replace(mech, assembly=value))
    assert isinstance(result, (SpecError, fabricate.Build)), result
    result = _outcome_or_fabricate_error(fabricate.from_mechanism, dataclasses.replace(mech, name=value))
    assert isinstance(result, SpecError) and result.path == "mechanism.name" or isinstance(value, str), result


def test_a_mechanism_without_assembly_says_what_to_pass():
    """The issue's case: the message names mechanism.assembly, the body, and the call to write."""
    mech = dataclasses.replace(make_four_bar(), assembly={"crank": (0.0, 0.0, 1.0)})
    with pytest.raises(SpecError) as info:
        fabricate.from_mechanism(mech)
    assert info.value.path == "mechanism.assembly"
    assert "no first pose for body 'coupler' (nor for 'rocker')" in info.value.message
    assert 'assembly={"coupler": (x_mm, y_mm, angle_rad), ...}' in info.value.message
    assert "Mechanism(assembly=" in fabricate.from_mechanism.__doc__.replace("..., ", "")


@pytest.mark.parametrize("value", WRONG, ids=_ids(WRONG))
def test_write_takes_any_value_for_out_and_force(value, design, tmp_path, monkeypatch):
    here = tmp_path / "a" / "b" / "c"
    here.mkdir(parents=True)
    monkeypatch.chdir(here)  # a relative "out" that is accepted (" ", "../../no_such_folder/x") lands in tmp_path
    build = fabricate.Build(exit_code=0, report={}, files={"a.txt": b"a"}, design=design)
    result = _outcome_or_fabricate_error(build.write, value)
    assert isinstance(result, (SpecError, Path)), result
    result = _outcome_or_fabricate_error(build.write, tmp_path / "out", force=value)
    assert isinstance(result, (SpecError, Path)), result
    if not isinstance(value, bool):
        assert isinstance(result, SpecError) and result.path == "force", result


def _leaves(node: Any, prefix: tuple = ()) -> list[tuple]:
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    out = [prefix] if prefix else []
    for key, value in items:
        out += _leaves(value, prefix + (key,))
    return out


BASE = read_toml(TEMPLATE_DIR / "gear_pair_elliptic.toml")
LEAVES = _leaves(BASE)

toml_like = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8) | st.binary(max_size=4)
    | st.sampled_from([10**400, -(10**30), "\0", "\ud800", object(), 1 + 1j, np.int64(3), np.array([1, 2])]),
    lambda inner: st.lists(inner, max_size=4) | st.tuples(inner, inner)
    | st.dictionaries(st.text(max_size=6) | st.integers(0, 3), inner, max_size=4),
    max_leaves=12)


@settings(max_examples=150, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(path=st.sampled_from(LEAVES), value=toml_like)
def test_load_of_a_dict_with_any_value_anywhere(path, value):
    """A value of any type at any place of a valid template's tables: a design, or a SpecError (the field
    path in it when the value is the culprit)."""
    import copy

    tables = copy.deepcopy(BASE)
    node = tables
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    result = _outcome_or_fabricate_error(fabricate.load, tables)
    assert isinstance(result, (SpecError, DesignSpec)), result
