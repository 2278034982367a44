"""The standalone gear pair's "synthesis": the template's law checked over the working range, the centre
distance, the carrier with its two gears, and the report's ``synthesis`` section."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from fabricate.errors import SpecError
from fabricate.gears.law import check_ratio
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.gear_pair.mechanism import build_mechanism, center_distance, make_law
from fabricate.synthesis.gear_pair.spec import GearPairSpec

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


def synthesise(design: DesignSpec) -> SynthesisResult:
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
    a = center_distance(spec, design, law, lo)
    x = np.linspace(lo, hi, 721)
    ratio = -np.asarray(law(x, 1))
    mech = build_mechanism(design.name, spec, law, a)
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
        from fabricate.synthesis.gear_pair.plots import gear_pair_figures

        return gear_pair_figures(law, (lo, hi), a)

    return SynthesisResult(mechanism=mech, report=report, figures=figures,
                           data={"law": law, "center_distance_mm": a})
