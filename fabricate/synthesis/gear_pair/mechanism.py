"""The standalone gear pair's coupling law and its :class:`~fabricate.mechanism.Mechanism`: body ``carrier``
(ground) holding the axes ``OA`` and ``OB``, ``gear_a`` turned by an angle driver, ``gear_b`` coupled by the
law."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from fabricate.errors import SpecError
from fabricate.gears.law import FormulaLaw, elliptic_formula, samples_law
from fabricate.gears.pitch import PitchCurves
from fabricate.mechanism import Body, Driver, GearCoupling, Law, Mechanism, Revolute
from fabricate.synthesis.gear_pair.spec import GearPairSpec

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec

PAIR_NAME = "pair"


def make_law(spec: GearPairSpec) -> tuple[Law, str]:
    """The coupling law (external pair: negative slope) and a description of it."""
    if spec.family == "elliptic":
        assert spec.eccentricity is not None  # the parser reads it for this family
        text = elliptic_formula(spec.eccentricity)
        return FormulaLaw(text, sign=-1.0, path="gear_pair.family"), f"elliptic e = {spec.eccentricity:g}: {text}"
    if spec.family == "samples":
        arr = np.radians(np.asarray(spec.samples_deg))
        return samples_law(arr[:, 0], -arr[:, 1], "gear_pair.law_samples_deg"), "cubic spline through samples"
    assert spec.formula is not None  # the parser reads it for this family
    return FormulaLaw(spec.formula, sign=-1.0, path="gear_pair.law"), spec.formula


def center_distance(spec: GearPairSpec, design: DesignSpec, law: Law, lo: float) -> float:
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


def build_mechanism(name: str, spec: GearPairSpec, law: Law, a: float) -> Mechanism:
    """The carrier and its two gears at centre distance ``a`` (mm), gear a driven over the working range."""
    lo, hi = (float(np.radians(v)) for v in spec.working_range_deg)
    carrier = Body("carrier", {"OA": (0.0, 0.0), "OB": (a, 0.0)})
    gear_a = Body("gear_a", {"OA": (0.0, 0.0)})
    gear_b = Body("gear_b", {"OB": (0.0, 0.0)})
    coupling = GearCoupling(PAIR_NAME, carrier="carrier", gear_a="gear_a", gear_b="gear_b", law=law,
                            axis_a="OA", axis_b="OB", working_range=(lo, hi))
    return Mechanism(name=name, bodies=(carrier, gear_a, gear_b), ground="carrier",
                     joints=(Revolute("OA", "carrier", "gear_a"), Revolute("OB", "carrier", "gear_b")),
                     gears=(coupling,), drivers=(Driver("angle", "gear_a", "carrier"),),
                     input_range=(spec.working_range_deg[0], spec.working_range_deg[1]), input_unit="deg",
                     assembly={"gear_a": (0.0, 0.0, lo), "gear_b": (a, 0.0, float(law(lo)))})
