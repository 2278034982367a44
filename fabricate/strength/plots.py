"""Stress over the motion: each part's governing stress as a fraction of its allowable (matplotlib only here)."""

from __future__ import annotations

from typing import Any

import numpy as np

from fabricate.plotting import figure, legend_below, png_bytes, series_styles
from fabricate.strength.check import StrengthResult

#: Parts drawn: the most loaded ones (the rest are in report.md's table).
MAX_PARTS = 12


def strength_figure(result: StrengthResult, input_unit: str, max_parts: int = MAX_PARTS) -> Any:
    """The figure :func:`strength_plot` renders (a matplotlib Figure, for callers that look at its artists).

    Each drawn part has its own colour (:func:`fabricate.plotting.series_styles`: no two alike however many
    are drawn) and a legend entry.
    """
    fig = figure((10.0, 4.5), 100)
    ax = fig.add_subplot(1, 1, 1)
    worst = sorted(result.per_part().values(), key=lambda f: f.safety_factor)[:max_parts]
    x = result.inputs
    drawn = [f for f in worst if f.curve is not None and len(f.curve) == len(x)]
    for f, style in zip(drawn, series_styles(len(drawn)), strict=True):
        ax.plot(x, np.asarray(f.curve) / f.allowable_MPa, lw=1.3, label=f"{f.part}: {f.feature}"[:70], **style)
    ax.axhline(1.0 / result.min_safety_factor, color="red", ls="--", lw=1.0,
               label=f"limit (safety factor {result.min_safety_factor:g})")
    ax.set_xlabel(f"input ({input_unit})")
    ax.set_ylabel("stress / allowable")
    ax.set_title("Strength over the motion: governing stress of each part")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, lw=0.3)
    # under the axes in two columns: entries of 70 characters at 8 pt, whole (fixed margins: tight_layout
    # would draw the figure twice)
    legend_below(fig, ax, 4.0)
    return fig


def strength_plot(result: StrengthResult, input_unit: str, max_parts: int = MAX_PARTS) -> bytes:
    """PNG of stress / allowable against the input for the most loaded parts and pins.

    A part's curve is its governing feature's stress at every pose divided by that feature's allowable;
    the red line is 1 / required safety factor (above it the part fails the check). Deterministic bytes.
    """
    return png_bytes(strength_figure(result, input_unit, max_parts))
