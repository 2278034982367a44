"""The registry of kinds: what ``[design] kind`` may name, and the three entry points of each.

A kind is a package of :mod:`fabricate.synthesis` with one shape (see that package's docstring) and three
entry points:

``parse_spec(root: Table) -> spec``
    Read the kind's own top-level tables of the template (every key it reads is marked used, unknown keys
    are errors) into a frozen dataclass: ``DesignSpec.method``.
``preflight(design: DesignSpec) -> None``
    Estimate the cost of the validated design where a product of counts drives memory or time (each field
    alone is already bounded by its parser), and refuse one over the budget with a
    :class:`~fabricate.errors.SpecError` naming the field; the constants are :mod:`fabricate.bounds`'.
``synthesise(design: DesignSpec) -> SynthesisResult``
    Pure computation: the :class:`~fabricate.mechanism.Mechanism`, the report's ``synthesis`` section, the
    figures and the parts hints; raises :class:`~fabricate.errors.SynthesisError` when nothing is feasible.

The registry is an explicit table (:data:`KINDS`, filled by :func:`register`, which refuses a name twice).
Each entry point is an :class:`EntryPoint`: the kind's package is imported when one is first called, so
reading the registry (the template parser's choices, ``fabricate list``) imports no kind and none of its
numeric dependencies.

Package names: the kind name is the template's public key, written in every template, report.json and
``mechanism.toml`` there is, so it cannot change; a package is named for its mechanism (``five_bar``,
``compliant``), and the mutation benchmark and the history follow those paths. Where the two differ the
registry states the mapping (:attr:`Kind.package`) rather than renaming either.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec
    from fabricate.synthesis.base import SynthesisResult
    from fabricate.table import Table


@dataclass(frozen=True)
class EntryPoint:
    """A function of a kind's package, imported on its first call.

    Attributes
    ----------
    module : str
        Dotted module name (``"fabricate.synthesis.five_bar"``).
    name : str
        The function's name in it.
    """

    module: str
    name: str

    def load(self) -> Callable[..., Any]:
        """The function itself (imports its module)."""
        function: Callable[..., Any] = getattr(importlib.import_module(self.module), self.name)
        return function

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.load()(*args, **kwargs)


@dataclass(frozen=True)
class Kind:
    """One kind of design.

    Attributes
    ----------
    name : str
        What ``[design] kind`` says.
    package : str
        The package that implements it (``fabricate.synthesis.<package>``).
    parse_spec, preflight, synthesise : callable
        Its entry points (see the module docstring).
    paper : str or None
        Short name of the paper the kind reproduces (the README's Templates table gives its seed number); None
        for a kind of no paper.
    """

    name: str
    package: str
    parse_spec: Callable[[Table], object]
    synthesise: Callable[[DesignSpec], SynthesisResult]
    preflight: Callable[[DesignSpec], None]
    paper: str | None = None


_REGISTRY: dict[str, Kind] = {}

#: Every registered kind by name (read-only: :func:`register` is the one way in).
KINDS: Mapping[str, Kind] = MappingProxyType(_REGISTRY)


def register(kind: Kind) -> Kind:
    """Add a kind to :data:`KINDS`.

    Raises
    ------
    ValueError
        When a kind of that name is registered already (two packages claiming one template key is a bug
        of fabricate, not of a template).
    """
    if kind.name in _REGISTRY:
        raise ValueError(f"double registration of kind {kind.name!r}: already {_REGISTRY[kind.name].package}")
    _REGISTRY[kind.name] = kind
    return kind


def package_kind(name: str, package: str, paper: str | None = None) -> Kind:
    """A :class:`Kind` whose entry points are the functions of that name in ``fabricate.synthesis.<package>``."""
    module = f"fabricate.synthesis.{package}"
    return Kind(name=name, package=module, parse_spec=EntryPoint(module, "parse_spec"),
                synthesise=EntryPoint(module, "synthesise"), preflight=EntryPoint(module, "preflight"),
                paper=paper)


register(package_kind("five_bar_ncg", "five_bar", paper="five-bar NCG finger"))
register(package_kind("watt_six_bar", "watt_six_bar", paper="Watt-I six-bar finger"))
register(package_kind("underactuated", "underactuated", paper="underactuated stacked four-bar finger"))
register(package_kind("compliant_gripper", "compliant", paper="compliant spring-hinge gripper"))
register(package_kind("gear_pair", "gear_pair"))
register(package_kind("linkage", "linkage"))
