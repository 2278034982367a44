"""The registry of kinds (fabricate.kinds) and the one shape of every kind package (fabricate.synthesis)."""

from __future__ import annotations

import ast
import dataclasses
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

from fabricate.design import design_from_text
from fabricate.errors import SpecError
from fabricate.kinds import KINDS, EntryPoint, Kind, package_kind, register

#: Modules every kind package has (fabricate/synthesis/__init__.py describes each).
SHAPE = ("__init__.py", "spec.py", "method.py", "mechanism.py", "plots.py")


def test_a_kind_is_registered_once():
    before = dict(KINDS)
    for name in before:
        with pytest.raises(ValueError, match=f"double registration of kind '{name}'"):
            register(package_kind(name, "linkage"))
    assert dict(KINDS) == before  # the refused registration left the first one in place


def test_the_registry_is_read_only():
    with pytest.raises(TypeError):
        KINDS["mine"] = package_kind("mine", "linkage")  # type: ignore[index]
    assert "mine" not in KINDS


def test_the_registry_names_the_package_of_each_kind():
    packages = {name: kind.package for name, kind in KINDS.items()}
    assert packages == {
        "five_bar_ncg": "fabricate.synthesis.five_bar",
        "watt_six_bar": "fabricate.synthesis.watt_six_bar",
        "underactuated": "fabricate.synthesis.underactuated",
        "compliant_gripper": "fabricate.synthesis.compliant",
        "gear_pair": "fabricate.synthesis.gear_pair",
        "linkage": "fabricate.synthesis.linkage",
    }
    # the paper kinds say which paper (DESIGN.md's seed table); the two of no paper say none
    assert {name for name, kind in KINDS.items() if kind.paper} == {"five_bar_ncg", "watt_six_bar",
                                                                   "underactuated", "compliant_gripper"}


def test_reading_the_registry_imports_no_kind():
    # fabricate list and the template parser's choices read the names: no kind, no numpy
    code = ("import sys; from fabricate.kinds import KINDS; names = sorted(KINDS); "
            "print([m for m in sys.modules if m.startswith('fabricate.synthesis') or m == 'numpy'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


@pytest.mark.parametrize("name", sorted(KINDS))
def test_entry_points_are_the_package_functions(name):
    kind = KINDS[name]
    assert isinstance(kind, Kind)
    package = importlib.import_module(kind.package)
    assert sorted(package.__all__) == ["parse_spec", "preflight", "synthesise"]
    for field in ("parse_spec", "preflight", "synthesise"):
        entry = getattr(kind, field)
        assert isinstance(entry, EntryPoint)
        assert entry.load() is getattr(package, field)
    # parse_spec and preflight live in the kind's spec.py, synthesise in its method.py
    assert kind.parse_spec.load().__module__ == f"{kind.package}.spec"
    assert kind.preflight.load().__module__ == f"{kind.package}.spec"
    assert kind.synthesise.load().__module__ == f"{kind.package}.method"


@pytest.mark.parametrize("name", sorted(KINDS))
def test_every_kind_package_has_the_one_shape(name):
    folder = Path(importlib.import_module(KINDS[name].package).__file__).parent
    assert {p.name for p in folder.glob("*.py")} >= set(SHAPE)
    # __init__.py only exposes the entry points: a docstring, imports and __all__, no logic of its own
    tree = ast.parse((folder / "__init__.py").read_text(encoding="utf-8"))
    for node in tree.body[1:]:
        assert isinstance(node, ast.ImportFrom | ast.Import) or (
            isinstance(node, ast.Assign) and [t.id for t in node.targets] == ["__all__"]), ast.dump(node)[:80]


def test_an_unknown_kind_names_every_registered_one():
    text = '[design]\nname = "x"\nkind = "six_bar"\n'
    with pytest.raises(SpecError) as err:
        design_from_text(text, "x.toml")
    assert err.value.path == "design.kind"
    for name in KINDS:
        assert name in str(err.value)


def test_a_kind_is_a_frozen_record():
    with pytest.raises(dataclasses.FrozenInstanceError):
        KINDS["linkage"].package = "elsewhere"  # type: ignore[misc]
