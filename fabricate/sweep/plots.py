"""Plots of a sweep as PNG bytes: each metric against each varied numeric field, and a feasibility map of
two fields (which points pass, fail a check, or are invalid or infeasible)."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

from fabricate.plotting import figure, legend, png_bytes

#: More plots than this are not drawn (a sweep of 16 fields x 64 metrics would make 1024).
MAX_PLOTS = 64

_OUTCOMES = (  # exit code, label, marker style
    (0, "passes every check", {"marker": "o", "color": "#1b7837"}),
    (1, "fails a check", {"marker": "s", "color": "#d6604d"}),
    (2, "invalid or infeasible", {"marker": "x", "color": "#4d4d4d"}),
    (3, "error", {"marker": "+", "color": "#762a83"}),
)


def slug(text: str) -> str:
    """A file-name-safe form of a field path or metric name."""
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_")[:80] or "x"


def _numeric(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(float(v))


def metric_plot(rows: Sequence[Mapping[str, Any]], field: str, metric: str) -> bytes:
    """``metric`` against ``field``: one marker per point, by outcome; points without the metric are not
    drawn (they are counted in the legend)."""
    fig = figure((6.4, 4.8), 100)
    ax = fig.add_subplot(1, 1, 1)
    for code, label, style in _OUTCOMES:
        pts = [(float(r[field]), float(r[metric])) for r in rows
               if r["exit_code"] == code and _numeric(r.get(field)) and _numeric(r.get(metric))]
        missing = sum(1 for r in rows if r["exit_code"] == code and not _numeric(r.get(metric)))
        if pts or missing:
            xs, ys = zip(*pts, strict=True) if pts else ((), ())
            extra = f", {missing} without it" if missing else ""
            ax.scatter(xs, ys, s=18, label=f"{label} ({len(pts)}{extra})",
                       facecolors="none" if code == 1 else None, **style)
    ax.set_xlabel(field)
    ax.set_ylabel(metric)
    ax.grid(True, alpha=0.3)
    legend(ax, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)
    fig.tight_layout()
    return png_bytes(fig)


def feasibility_map(rows: Sequence[Mapping[str, Any]], x: str, y: str) -> bytes:
    """Every point at (``x``, ``y``), marked by outcome: where the design stays feasible.

    When other varied fields put several points at one (``x``, ``y``), each spot is coloured by the share of
    its points that pass every check and labelled ``passing/points``.
    """
    fig = figure((6.0, 5.6), 100)
    ax = fig.add_subplot(1, 1, 1)
    spots: dict[tuple[float, float], list[int]] = {}
    for r in rows:
        if _numeric(r.get(x)) and _numeric(r.get(y)):
            spots.setdefault((float(r[x]), float(r[y])), []).append(int(r["exit_code"]))
    if all(len(codes) == 1 for codes in spots.values()):
        for code, label, style in _OUTCOMES:
            pts = [xy for xy, codes in spots.items() if codes[0] == code]
            if pts:
                xs, ys = zip(*pts, strict=True)
                ax.scatter(xs, ys, s=30, label=f"{label} ({len(pts)})", **style)
        # below the axes: a legend inside would hide points of a full grid
        legend(ax, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)
    else:
        xy = sorted(spots)
        share = [sum(c == 0 for c in spots[k]) / len(spots[k]) for k in xy]
        xs, ys = zip(*xy, strict=True)
        dots = ax.scatter(xs, ys, c=share, cmap="RdYlGn", vmin=0.0, vmax=1.0, s=60, edgecolors="k", linewidths=0.4)
        for (px, py) in xy:
            codes = spots[(px, py)]
            ax.annotate(f"{sum(c == 0 for c in codes)}/{len(codes)}", (px, py), textcoords="offset points",
                        xytext=(0, 7), ha="center", fontsize=7)
        fig.colorbar(dots, ax=ax, label="share of points passing every check")
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_title("feasibility")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return png_bytes(fig)


def sweep_plots(rows: Sequence[Mapping[str, Any]], fields: Sequence[str], metrics: Sequence[str],
                map_fields: Sequence[str]) -> dict[str, bytes]:
    """``{"plots/<metric>__vs__<field>.png": bytes, "plots/feasibility.png": bytes}`` for the numeric fields
    (at most :data:`MAX_PLOTS`)."""
    numeric = [f for f in fields if any(_numeric(r.get(f)) for r in rows)]
    out: dict[str, bytes] = {}
    if len(map_fields) == 2:
        out["plots/feasibility.png"] = feasibility_map(rows, map_fields[0], map_fields[1])
    for metric in metrics:
        for field in numeric:
            if len(out) >= MAX_PLOTS:
                return out
            out[f"plots/{slug(metric)}__vs__{slug(field)}.png"] = metric_plot(rows, field, metric)
    return out
