"""What every synthesis method hands to the rest of the pipeline."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from fabricate.hints import PartHints
from fabricate.mechanism import Mechanism


@dataclass(frozen=True)
class SynthesisResult:
    """Outcome of one synthesis method.

    Attributes
    ----------
    mechanism : Mechanism
        The selected design as a solvable mechanism (a gear pair's is its carrier and two gears).
    report : dict
        JSON-ready ``synthesis`` section of report.json (numbers as floats/lists, angles in degrees
        where the key says ``_deg``).
    figures : callable
        Returns ``{file name: PNG bytes}``; called by the pipeline only (plots are slow and optional).
    data : object
        Method-specific results (curves, regions, candidates) for tests and plots.
    parts : PartHints
        The method's hints for the parts layer (e.g. which body carries the fingertip pad, springs for the
        bill of materials); see :mod:`fabricate.hints`.
    """

    mechanism: Mechanism
    report: dict[str, Any]
    figures: Callable[[], dict[str, bytes]] = lambda: {}
    data: Any = None
    parts: PartHints = field(default_factory=PartHints)
