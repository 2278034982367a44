"""Plot of clearance against input for the interference sweep (matplotlib only here)."""

from __future__ import annotations

from typing import Any

import numpy as np

from fabricate.checks.interference import InterferenceResult
from fabricate.plotting import figure, legend_below, png_bytes, series_styles

#: Pairs drawn: the closest ones (the others are in the report's table).
MAX_PAIRS = 12


def clearance_png(result: InterferenceResult, max_pairs: int = MAX_PAIRS) -> bytes:
    """PNG of the clearance of the closest pairs over the motion, with the required minimum.

    Exact values are drawn as solid lines, lower bounds (beyond the search length, or stacked parts
    away from their closest pose) dotted. Colliding poses are marked on the zero line.
    Deterministic bytes (no timestamps in the metadata).
    """
    return png_bytes(clearance_figure(result, max_pairs))


def clearance_figure(result: InterferenceResult, max_pairs: int = MAX_PAIRS) -> Any:
    """The figure :func:`clearance_png` renders: one colour per pair (never two alike), each in the legend."""
    # the plot's line is the running clearance: spacers bearing on their joint (and an actuator fixed to its
    # body's parts) touch by design and gear teeth are held to their backlash, so they are named in a note
    # instead of drawn under the line
    own_limits = ("bearing", "meshing", "fixed")
    shown = [p for p in result.pairs if p.relation not in own_limits]
    pairs = sorted(shown, key=lambda p: (p.min_clearance_mm, p.a, p.b))[:max_pairs]
    fig = figure((10.0, 4.5), 100)
    ax = fig.add_subplot(1, 1, 1)
    x = result.inputs
    top = result.search_length_mm
    for p, style in zip(pairs, series_styles(len(pairs)), strict=True):
        colour = style["color"]
        # the exact part solid whatever the pair's rank: dotted already means "a lower bound" here, so the
        # pairs past the tenth are told apart by their colour alone
        ax.plot(x, np.where(p.exact, p.clearance, np.nan), lw=1.4, color=colour,
                label=f"{p.a} – {p.b} ({p.relation})")
        # where only a lower bound is known (beyond the search length, or parts on other layers
        # away from their closest pose) draw it dotted
        ax.plot(x, np.where(p.exact, np.nan, p.clearance), lw=0.8, ls=":", color=colour)
        if p.collides:
            ax.plot(x[p.collision_indices], np.zeros(len(p.collision_indices)), "x", color=colour, ms=4)
    ax.axhline(result.min_clearance_required_mm, color="red", ls="--", lw=1.0,
               label=f"running clearance required {result.min_clearance_required_mm:g} mm")
    notes = []
    for relation, held_to in (("meshing", "backlash band (gear mesh check)"), ("bearing", "no overlap"),
                              ("fixed", "no overlap")):
        group = [p for p in result.pairs if p.relation == relation]
        if group:
            worst = min(p.min_clearance_mm for p in group)
            notes.append(f"not drawn: {len(group)} {relation} pair{'s' * (len(group) > 1)}, smallest gap "
                         f"{worst:.4g} mm, held to {held_to}")
    if notes:
        ax.text(0.01, 0.98, "\n".join(notes), transform=ax.transAxes, fontsize=8, va="top", ha="left",
                bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "0.7"})
    ax.set_xlabel(f"input ({result.input_unit})")
    ax.set_ylabel("clearance (mm)")
    ax.set_ylim(-0.05 * top, 1.05 * top)
    ax.set_title(f"Clearance over the motion ({len(x)} poses, {len(result.pairs)} pairs)")
    ax.grid(True, alpha=0.3)
    # under the axes in two columns, each entry whole (fixed margins: tight_layout would draw the figure twice)
    legend_below(fig, ax, 4.0)
    return fig
