"""Kind ``gear_pair``: a standalone non-circular gear pair on a fixed carrier.

Template tables
---------------
``[gear_pair]``
    One of
      ``family = "elliptic"`` with ``eccentricity`` (0 <= e < 1): two equal ellipses about their foci, 1:1;
      ``law = "x + 0.03*sin(x)"``: the driven gear's angle as a formula in the driving angle ``x``
      (rad; the numpy functions of :data:`fabricate.gears.law.FUNCTIONS`, evaluated safely; at most
      :data:`~fabricate.bounds.MAX_EXPRESSION_LENGTH` characters and
      :data:`~fabricate.bounds.MAX_EXPRESSION_DEPTH` levels of nesting);
      ``law_samples_deg = [[x_a, x_b], ...]``: driven against driving angle (deg), a cubic spline.
    The driven angle is counted positive in its own sense of turning (external gears turn opposite
    ways): the coupling law is its negative.
    ``closed`` (default true): full gears; false: sectors over ``working_range_deg = [lo, hi]``.
    ``center_distance_mm``: the axis distance. For a closed pair it may be left out when
    ``[gears] module_mm`` and ``teeth`` are given (the centre distance then follows from whole teeth);
    given together with ``module_mm``, the module is adjusted to fit whole teeth.
    ``teeth = [z_a, z_b]`` (closed pairs; the same as ``[gears] teeth``).

The mechanism: body ``carrier`` (ground) holding the axes ``OA`` at the origin and ``OB`` at
``(center_distance, 0)``; ``gear_a`` turned by an angle driver over the working range (0..360 deg for a
closed pair), ``gear_b`` coupled by the law.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fabricate.bounds import MAX_TEETH, check_expression
from fabricate.errors import SpecError
from fabricate.gears.law import FormulaLaw, check_ratio, elliptic_formula, samples_law
from fabricate.gears.pitch import PitchCurves
from fabricate.mechanism import Body, Driver, GearCoupling, Mechanism, Revolute
from fabricate.synthesis.base import SynthesisResult
from fabricate.table import Table

PAIR_NAME = "pair"


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


def make_law(spec: GearPairSpec) -> tuple[Callable, str]:
    """The coupling law (external pair: negative slope) and a description of it."""
    if spec.family == "elliptic":
        text = elliptic_formula(spec.eccentricity)
        return FormulaLaw(text, sign=-1.0, path="gear_pair.family"), f"elliptic e = {spec.eccentricity:g}: {text}"
    if spec.family == "samples":
        arr = np.radians(np.asarray(spec.samples_deg))
        return samples_law(arr[:, 0], -arr[:, 1], "gear_pair.law_samples_deg"), "cubic spline through samples"
    return FormulaLaw(spec.formula, sign=-1.0, path="gear_pair.law"), spec.formula


def _center_distance(spec: GearPairSpec, design: Any, law: Callable, lo: float) -> float:
    """Centre distance: given, or from whole teeth of the requested module (closed pairs)."""
    if spec.center_distance_mm is not None:
        return spec.center_distance_mm
    teeth = spec.teeth or design.gears.teeth
    module = design.gears.module_mm
    if teeth is None or module is None:
        raise SpecError("gear_pair.center_distance_mm", "give center_distance_mm, or [gears] module_mm "
                                                         "together with teeth = [z_a, z_b]")
    unit = PitchCurves(law, 1.0, (lo, lo + 2 * np.pi), lo)
    perimeter = float(unit.s_of_x(np.array([lo + 2 * np.pi]))[0])
    # pitch curves scale with the centre distance: perimeter(a) = a * perimeter(1)
    return teeth[0] * np.pi * module / perimeter


def synthesise(design: Any) -> SynthesisResult:
    """Build the carrier + two gears mechanism for the template's law."""
    spec: GearPairSpec = design.method
    if spec.teeth is not None and design.gears.teeth is not None and tuple(spec.teeth) != tuple(design.gears.teeth):
        raise SpecError("gear_pair.teeth", f"{list(spec.teeth)} differs from gears.teeth "
                                           f"{list(design.gears.teeth)}; give it once")
    if spec.teeth is not None and design.gears.teeth is None:
        raise SpecError("gear_pair.teeth", "tooth counts of the cut gears are set in [gears] teeth; "
                                           "move teeth there")
    law, text = make_law(spec)
    lo, hi = (float(np.radians(v)) for v in spec.working_range_deg)
    check_ratio(law, np.linspace(lo, hi, 2049), "gear_pair.law")
    a = _center_distance(spec, design, law, lo)
    x = np.linspace(lo, hi, 721)
    ratio = -np.asarray(law(x, 1))
    carrier = Body("carrier", {"OA": (0.0, 0.0), "OB": (a, 0.0)})
    gear_a = Body("gear_a", {"OA": (0.0, 0.0)})
    gear_b = Body("gear_b", {"OB": (0.0, 0.0)})
    coupling = GearCoupling(PAIR_NAME, carrier="carrier", gear_a="gear_a", gear_b="gear_b", law=law,
                            axis_a="OA", axis_b="OB", working_range=(lo, hi))
    mech = Mechanism(name=design.name, bodies=(carrier, gear_a, gear_b), ground="carrier",
                     joints=(Revolute("OA", "carrier", "gear_a"), Revolute("OB", "carrier", "gear_b")),
                     gears=(coupling,), drivers=(Driver("angle", "gear_a", "carrier"),),
                     input_range=tuple(spec.working_range_deg), input_unit="deg",
                     assembly={"gear_a": (0.0, 0.0, lo), "gear_b": (a, 0.0, float(law(lo)))})
    r_a = a * ratio / (1 + ratio)
    report = {
        "method": "standalone non-circular gear pair",
        "law": text,
        "closed": spec.closed,
        "working_range_deg": list(spec.working_range_deg),
        "center_distance_mm": float(a),
        "transmission_ratio": [float(ratio.min()), float(ratio.max())],
        "pitch_radius_a_mm": [float(r_a.min()), float(r_a.max())],
        "pitch_radius_b_mm": [float((a - r_a).min()), float((a - r_a).max())],
    }

    def figures() -> dict[str, bytes]:
        from fabricate.export.gear_plots import law_png

        return {"gear_law.png": law_png(law, (lo, hi), a)}

    return SynthesisResult(mechanism=mech, report=report, figures=figures,
                           data={"law": law, "center_distance_mm": a}, parts={})
