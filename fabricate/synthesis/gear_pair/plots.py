"""Figures of a standalone gear pair: its law and transmission ratio (PNG bytes)."""

from __future__ import annotations

from collections.abc import Callable


def gear_pair_figures(law: Callable, working_range: tuple[float, float], center_distance_mm: float
                      ) -> dict[str, bytes]:
    """``{"gear_law.png": PNG bytes}``: driven against driving angle and the ratio over the working range."""
    from fabricate.export.gear_plots import law_png

    return {"gear_law.png": law_png(law, working_range, center_distance_mm)}
