"""Figures of the Watt-I six-bar synthesis: C_d with its feasible segments, C_d0 for the chosen d, and the
solution region coloured by K. Each function returns PNG bytes (deterministic: no timestamps, fixed
sizes); nothing is written to disk here.
"""

from __future__ import annotations

import numpy as np

from fabricate.plotting import figure, legend, png_bytes
from fabricate.synthesis.watt_six_bar.burmester import CubicCurve, grid_in_range, sample_curve

_BRANCH_COLOURS = ("tab:blue", "tab:orange", "tab:green")


def _png(fig) -> bytes:
    return png_bytes(fig, 110)


def _view(boxes: list[np.ndarray], margin: float = 0.6) -> tuple[float, float, float, float]:
    lo = np.min([b[[0, 2]] for b in boxes], axis=0)
    hi = np.max([b[[1, 3]] for b in boxes], axis=0)
    span = hi - lo
    return (lo[0] - margin * span[0], hi[0] + margin * span[0], lo[1] - margin * span[1], hi[1] + margin * span[1])


def _draw_curve(ax, curve: CubicCurve, view, label: str, step: float) -> None:
    """Every branch of a cubic over the view as dots (a polyline would bridge the gaps between arcs)."""
    sample = sample_curve(curve, grid_in_range(view[0], view[1], step))
    pts = sample.points()
    for k in range(3):
        ax.plot(pts[:, k, 0], pts[:, k, 1], ".", ms=1.2, color=_BRANCH_COLOURS[k],
                label=f"{label} branch {k + 1}")


def _draw_box(ax, box: np.ndarray, name: str, colour: str = "0.3") -> None:
    import matplotlib.patches as patches

    ax.add_patch(patches.Rectangle((box[0], box[2]), box[1] - box[0], box[3] - box[2], fill=False,
                                   ls="--", lw=0.8, ec=colour))
    ax.annotate(f"{name} box", (box[0], box[3]), fontsize=7, color=colour, va="bottom")


def plot_curve_d(spec, region, choice) -> bytes:
    """C_d and C_e (whole curves near the boxes), the feasible segments of C_d and the chosen d, e."""
    one = region.stage_one
    box_d, box_e = spec.box("d"), spec.box("e")
    view = _view([box_d, box_e])
    fig = figure((8.0, 6.0), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    _draw_curve(ax, one.curve_d, view, "C_d", 0.05)
    sample_e = sample_curve(one.curve_e, grid_in_range(view[0], view[1], 0.05)).points()
    ax.plot(sample_e[..., 0].ravel(), sample_e[..., 1].ravel(), ".", ms=0.8, color="0.6", label="C_e")
    pts = one.sample.points()
    for k in range(3):
        sel = one.feasible[:, k]
        ax.plot(pts[sel, k, 0], pts[sel, k, 1], "o", ms=3.0, mfc="none", color=_BRANCH_COLOURS[k],
                label=f"feasible d, branch {k + 1}")
    _draw_box(ax, box_d, "d")
    _draw_box(ax, box_e, "e", "0.55")
    ax.plot(*choice.d, "k*", ms=10, label="selected d")
    ax.plot(*choice.e, "kx", ms=8, label="selected e")
    ref = dict(spec.reference)
    if ref:
        ax.plot(*ref["d"], "r*", ms=9, label="reference d")
    ax.set_xlim(view[0], view[1])
    ax.set_ylim(view[2], view[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title("Solution curve C_d of joint d (position 1) and its feasible segments")
    legend(ax, loc="lower right", markerscale=1)
    ax.grid(True, lw=0.3)
    return _png(fig)


def plot_curve_d0(spec, finger, choice) -> bytes:
    """C_d0 and C_f for the chosen dyad d-e, with the boxes and the chosen d0, f."""
    from fabricate.synthesis.watt_six_bar.region import stage_two_curves

    curve_d0, curve_f = stage_two_curves(finger, choice.d, choice.e)
    box_d0, box_f = spec.box("d0"), spec.box("f")
    view = _view([box_d0, box_f])
    fig = figure((8.0, 6.0), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    _draw_curve(ax, curve_d0, view, "C_d0", 0.05)
    sample_f = sample_curve(curve_f, grid_in_range(view[0], view[1], 0.05)).points()
    ax.plot(sample_f[..., 0].ravel(), sample_f[..., 1].ravel(), ".", ms=0.8, color="0.6", label="C_f")
    _draw_box(ax, box_d0, "d0")
    _draw_box(ax, box_f, "f", "0.55")
    ax.plot(*choice.d0, "k*", ms=10, label="selected d0")
    ax.plot(*choice.f, "kx", ms=8, label="selected f")
    ax.set_xlim(view[0], view[1])
    ax.set_ylim(view[2], view[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"C_d0 for d = ({choice.d[0]:.2f}, {choice.d[1]:.2f}) mm")
    legend(ax, loc="lower right", markerscale=1)
    ax.grid(True, lw=0.3)
    return _png(fig)


def plot_region(spec, region, refined, choice) -> bytes:
    """The solution region (d_x, d0_x) coloured by K; K > limit grey, circuit defects hollow."""
    fig = figure((8.0, 6.0), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    finite = np.isfinite(region.K)
    over = finite & (region.K > spec.k_max)
    ax.plot(region.d[over, 0], region.d0[over, 0], ",", color="0.75", label=f"K > {spec.k_max:g}")
    ok = finite & (region.K <= spec.k_max)
    clean = ok & region.passes
    defect = ok & ~region.passes
    # defect-free points as discs, points with a circuit defect as crosses, both coloured by K
    sc = ax.scatter(region.d[clean, 0], region.d0[clean, 0], c=region.K[clean], s=6, cmap="viridis",
                    vmin=0.0, vmax=spec.k_max, label=f"K <= {spec.k_max:g}")
    if np.any(defect):
        sc = ax.scatter(region.d[defect, 0], region.d0[defect, 0], c=region.K[defect], s=6, marker="x",
                        linewidths=0.5, cmap="viridis", vmin=0.0, vmax=spec.k_max,
                        label=f"K <= {spec.k_max:g}, circuit defect")
    if refined is not None and np.any(refined.accepted):
        acc = refined.accepted
        ax.scatter(refined.d[acc, 0], refined.d0[acc, 0], c=refined.K[acc], s=30, marker="D", cmap="viridis",
                   vmin=0.0, vmax=spec.k_max, edgecolors="k", linewidths=0.5, label="refined (defect-free)")
    ax.plot(choice.d[0], choice.d0[0], "k*", ms=14, label="selected")
    if spec.target is not None:
        ax.plot(*spec.target, "r+", ms=12, label="target")
    fig.colorbar(sc, ax=ax, label="force index K")
    ax.set_xlabel("d_x (mm)")
    ax.set_ylabel("d0_x (mm)")
    ax.set_title(f"Solution region (step {spec.step_mm:g} mm), coloured by K")
    legend(ax, loc="best", markerscale=1.5)
    ax.grid(True, lw=0.3)
    return _png(fig)


def all_figures(spec, finger, region, refined, choice) -> dict[str, bytes]:
    """Every figure of the kind by file name."""
    return {
        "curve_d.png": plot_curve_d(spec, region, choice),
        "curve_d0.png": plot_curve_d0(spec, finger, choice),
        "solution_region.png": plot_region(spec, region, refined, choice),
    }
