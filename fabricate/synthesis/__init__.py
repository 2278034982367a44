"""Synthesis methods, one module per seed mechanism.

Each kind module provides

``parse_spec(root: fabricate.spec.Table) -> object``
    Read the kind's own top-level tables from the template root (every key it reads is marked used;
    unknown keys are errors) and return a frozen dataclass.
``synthesise(design: fabricate.spec.DesignSpec) -> SynthesisResult``
    Pure computation; raises :class:`~fabricate.errors.SynthesisError` when nothing is feasible.
"""

from __future__ import annotations

import importlib
from types import ModuleType


class _Kinds(dict):
    """Lazy registry: kind name -> module (imported on first use, so a kind's imports stay local)."""

    _modules = {
        "five_bar_ncg": "fabricate.synthesis.five_bar",
        "watt_six_bar": "fabricate.synthesis.watt_six_bar",
        "underactuated": "fabricate.synthesis.underactuated",
        "compliant_gripper": "fabricate.synthesis.compliant",
        "gear_pair": "fabricate.synthesis.gear_pair",
        "linkage": "fabricate.synthesis.linkage",
    }

    def __init__(self) -> None:
        super().__init__({k: None for k in self._modules})

    def __getitem__(self, kind: str) -> ModuleType:
        return importlib.import_module(self._modules[kind])


KINDS = _Kinds()
