"""The ``[gear_pair]`` table of a standalone gear pair (kind ``gear_pair``, see the package docstring) -> a frozen
:class:`GearPairSpec`, and the estimate of its outlines' work (:func:`preflight`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fabricate.bounds import MAX_FRAME_TEETH, MAX_POSE_TEETH, MAX_TEETH, check_expression
from fabricate.errors import SpecError
from fabricate.gears.law import FormulaLaw
from fabricate.table import Table

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


@dataclass(frozen=True)
class GearPairSpec:
    """Validated ``[gear_pair]`` table (angles in degrees as written, lengths mm)."""

    family: str
    eccentricity: float | None
    formula: str | None
    samples_deg: tuple[tuple[float, float], ...] | None
    closed: bool
    working_range_deg: tuple[float, float]
    center_distance_mm: float | None
    teeth: tuple[int, int] | None


def parse_spec(root: Table) -> GearPairSpec:
    """Read ``[gear_pair]`` from the template root."""
    t = root.table("gear_pair")
    given = [k for k in ("family", "law", "law_samples_deg") if t.has(k)]
    if len(given) != 1:
        raise SpecError(t.path, "give exactly one of family, law, law_samples_deg"
                        + (f" (got {', '.join(given)})" if given else ""))
    family = t.string("family", "formula", choices=("elliptic", "formula"))
    ecc = None
    if family == "elliptic" and t.has("family"):
        ecc = t.number("eccentricity", min=0.0, max=0.95)
    formula = t.string("law", None)
    if formula is not None:
        check_expression(formula, t.field("law"))  # length and nesting depth, before anything compiles it
    samples = t.array("law_samples_deg", None, shape=(None, 2), min_rows=3, min=-3600.0, max=3600.0)
    if samples is not None and len(samples) > 10000:
        raise SpecError(t.field("law_samples_deg"), f"{len(samples)} samples, over the bound of 10000")
    if samples is not None:
        family = "samples"
    closed = t.boolean("closed", True)
    default_range = [0.0, 360.0] if closed else None
    if closed:
        rng = t.array("working_range_deg", default_range, shape=(2,), min=-3600.0, max=3600.0)
        rng = np.asarray(rng, dtype=np.float64)
        if abs(rng[1] - rng[0] - 360.0) > 1e-9:
            raise SpecError(t.field("working_range_deg"), "a closed pair turns through 360 deg; "
                                                          "leave working_range_deg out or set closed = false")
    else:
        rng = t.array("working_range_deg", shape=(2,), min=-3600.0, max=3600.0)
        if not rng[1] > rng[0]:
            raise SpecError(t.field("working_range_deg"), "expected [lo, hi] with lo < hi")
    center = t.number("center_distance_mm", None, positive=True, max=5000.0)
    teeth_arr = t.array("teeth", None, shape=(2,), min=3, max=MAX_TEETH)
    teeth = None
    if teeth_arr is not None:
        if np.any(teeth_arr != np.round(teeth_arr)):
            raise SpecError(t.field("teeth"), "expected whole numbers")
        teeth = (int(teeth_arr[0]), int(teeth_arr[1]))
    t.finish()
    if formula is not None:
        FormulaLaw(formula, path=t.field("law"))  # syntax and whitelist errors now, with the path
    if family == "samples" and closed:
        raise SpecError(t.field("law_samples_deg"), "samples describe a sector; set closed = false")
    if not closed and center is None:
        raise SpecError(t.field("center_distance_mm"), "a sector pair needs the centre distance")
    return GearPairSpec(family=family, eccentricity=ecc, formula=formula,
                        samples_deg=tuple((float(a), float(b)) for a, b in samples) if samples is not None else None,
                        closed=closed, working_range_deg=(float(rng[0]), float(rng[1])), center_distance_mm=center,
                        teeth=teeth)


def preflight(design: DesignSpec) -> None:
    """Refuse sweep poses or GIF frames × teeth over :data:`~fabricate.bounds.MAX_POSE_TEETH` /
    :data:`~fabricate.bounds.MAX_FRAME_TEETH` (the pair's toothed outlines dominate every stage).

    Raises
    ------
    SpecError
        Naming ``checks.sweep_poses`` or ``parts.gif_frames``, the estimate and the most that fit.
    """
    teeth = design.gears.teeth or design.method.teeth
    # without tooth counts the module decides them after synthesis: assume the most teeth allowed
    total = sum(teeth) if teeth else 2 * MAX_TEETH
    for field, count, bound, what in (
            ("checks.sweep_poses", design.checks.sweep_poses, MAX_POSE_TEETH, "poses"),
            ("parts.gif_frames", design.parts.gif_frames, MAX_FRAME_TEETH, "GIF frames")):
        if count * total > bound:
            raise SpecError(field, f"{count} {what} × {total} teeth = {count * total}, over the bound of {bound} "
                                   f"(every pose moves both toothed outlines); at most {max(1, bound // total)} "
                                   f"{what} with {total} teeth")
