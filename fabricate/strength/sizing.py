"""``[parts] link_width_mm = "auto"``: the narrowest links that keep the required safety factor.

The width changes the link sections and the material round the holes; pins and gear teeth do not depend
on it, so only findings of kind ``link`` and ``hole`` decide. Stresses fall monotonically with the width
(bending roughly as 1/w², tension as 1/w), so a bracket and a bisection find the smallest passing width
to :data:`RESOLUTION_MM`; the search uses every ``stride``-th pose and the pipeline's final check then
runs over the whole motion.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from fabricate.mechanism import Mechanism, Motion
from fabricate.parts.spec import MAX_AUTO_WIDTH_MM
from fabricate.strength.check import run_strength

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.hints import PartHints
    from fabricate.parts.partset import PartSet
    from fabricate.spec import DesignSpec

#: Width resolution of the search (mm).
RESOLUTION_MM = 0.1
#: Most poses one trial checks (the final check runs over the whole motion).
MAX_SEARCH_POSES = 120


def _with_width(design: DesignSpec, width: float | None) -> DesignSpec:
    """``design`` with ``parts.link_width_mm = width``."""
    return dataclasses.replace(design, parts=dataclasses.replace(design.parts, link_width_mm=width))


def _coarse(motion: Motion, stride: int) -> Motion:
    """Every ``stride``-th pose of ``motion`` (the last one kept)."""
    idx = np.unique(np.r_[np.arange(0, len(motion.inputs), stride), len(motion.inputs) - 1])
    return dataclasses.replace(motion, inputs=motion.inputs[idx], q=motion.q[idx])


def size_link_width(design: DesignSpec, mechanism: Mechanism, motion: Motion, gear_pairs: list[GearPair],
                    hints: PartHints, build: Callable[[DesignSpec], PartSet], stride: int = 4
                    ) -> tuple[float, list[tuple[float, float]]]:
    """Smallest link width (mm, a multiple of :data:`RESOLUTION_MM`) whose links and holes keep
    ``design.checks.min_safety_factor``; :data:`MAX_AUTO_WIDTH_MM` if none does.

    Parameters
    ----------
    build : callable
        ``build(design) -> PartSet`` (the pipeline's parts stage).

    Returns
    -------
    width_mm : float
    tried : list of (width mm, least link/hole safety factor)
        Every evaluation, in order (for the report).
    """
    from fabricate.parts.build import derive_sizes

    required = float(design.checks.min_safety_factor)
    # at most ~MAX_SEARCH_POSES poses per trial, so a 5000-pose sweep stays within the minute a build has
    coarse = _coarse(motion, max(stride, math.ceil(len(motion.inputs) / MAX_SEARCH_POSES)))
    tried: list[tuple[float, float]] = []

    def least(width: float) -> float:
        trial = _with_width(design, width)
        result = run_strength(trial, build(trial), mechanism, coarse, gear_pairs, hints)
        value = min((f.safety_factor for f in result.findings if f.kind in ("link", "hole")), default=math.inf)
        tried.append((width, float(value)))
        return value

    def snap(width: float) -> float:
        return round(math.ceil(width / RESOLUTION_MM - 1e-9) * RESOLUTION_MM, 10)

    plain = dataclasses.replace(design.parts, link_width_mm=None)
    lo = snap(2.0 * derive_sizes(design.process, plain, hints).boss_radius_mm)
    sf = least(lo)
    if sf >= required:
        return lo, tried
    # bending stress falls about as 1/w^2: a first guess, then widen until it passes
    hi = snap(min(MAX_AUTO_WIDTH_MM, lo * math.sqrt(required / max(sf, 1e-6)) if math.isfinite(sf) else lo))
    while True:
        hi = max(hi, snap(lo + RESOLUTION_MM))
        sf = least(hi)
        if sf >= required:
            break
        if hi >= MAX_AUTO_WIDTH_MM:
            return MAX_AUTO_WIDTH_MM, tried
        lo, hi = hi, snap(min(MAX_AUTO_WIDTH_MM, hi * 1.5))
    while hi - lo > RESOLUTION_MM + 1e-9:
        mid = snap(0.5 * (lo + hi))
        if mid >= hi:
            break
        if least(mid) >= required:
            hi = mid
        else:
            lo = mid
    return hi, tried
