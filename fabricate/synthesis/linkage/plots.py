"""Figures of a declared linkage: the law of each gear pair (PNG bytes)."""

from __future__ import annotations

import numpy as np

from fabricate.mechanism import Mechanism


def gear_law_figures(mech: Mechanism) -> dict[str, bytes]:
    """``{gear_law_<pair>.png: PNG bytes}``: each gear pair's law and transmission ratio over its working range."""
    from fabricate.export.gear_plots import law_png

    out = {}
    for coupling in mech.gears:
        a = float(np.hypot(*(mech.body(coupling.carrier).point(coupling.axis_b)
                             - mech.body(coupling.carrier).point(coupling.axis_a))))
        out[f"gear_law_{coupling.name}.png"] = law_png(coupling.law, coupling.working_range, a)
    return out
