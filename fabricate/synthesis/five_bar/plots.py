"""Figures of the five-bar gear finger synthesis (paper Figs 8, 9, 10 and 12) as PNG bytes.

Only this module imports matplotlib (Agg backend). Bytes are deterministic: no timestamps or software
tags in the PNG metadata, fixed size and dpi.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fabricate.plotting import figure, legend, png_bytes

#: Figure size (inches) and resolution shared by every plot.
FIGSIZE = (6.4, 4.8)
DPI = 100


def _png(fig: Any) -> bytes:
    return png_bytes(fig, DPI)


def _draw_finger(ax: Any, targets: Any, index: int, **style: Any) -> None:
    chain = np.array([targets.origin, targets.d[index], targets.c[index], targets.p[index]])
    ax.plot(chain[:, 0], chain[:, 1], "-o", ms=3, **style)


def _branch_lines(ax: Any, points: np.ndarray, branch: np.ndarray, mask: np.ndarray, **style: Any) -> None:
    """Plot each branch's samples as a polyline, broken where the mask is off."""
    label = style.pop("label", None)
    for b in np.unique(branch):
        idx = np.flatnonzero(branch == b)
        segment = np.where(mask[idx], 0.0, np.nan)
        xy = points[idx] + segment[:, None]
        ax.plot(xy[:, 0], xy[:, 1], label=label, **style)
        label = None


def hinge_curves_png(data: Any) -> bytes:
    """Fig 8: the A- and B-curves at the first pose with the finger and the chosen hinges."""
    fig = figure(FIGSIZE, 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    dom, t = data.domain, data.targets
    every = np.ones(len(dom.status), dtype=bool)
    _branch_lines(ax, dom.a, dom.family.branch, every, color="tab:blue", lw=0.8, label="hinge A curve")
    _branch_lines(ax, dom.b, dom.family.branch, every, color="tab:red", lw=0.8, label="hinge B curve")
    _draw_finger(ax, t, 0, color="0.3", lw=1.5, label="finger, pose 1")
    a, b = data.mechanism.body("link_AB").point("A"), data.mechanism.body("link_AB").point("B")
    ax.plot([a[0], b[0]], [a[1], b[1]], "k-", lw=2)
    ax.plot(*a, "bs", label=f"A ({a[0]:.2f}, {a[1]:.2f})")
    ax.plot(*b, "r^", label=f"B ({b[0]:.2f}, {b[1]:.2f})")
    span = np.concatenate([t.p, t.d, t.c, t.origin[None, :], a[None, :], b[None, :]])
    lo, hi = span.min(axis=0) - 40.0, span.max(axis=0) + 40.0
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.set_title("Hinge curves of A and B (first pose)")
    legend(ax, loc="best")
    return _png(fig)


def feasible_domain_png(data: Any) -> bytes:
    """Fig 9: the feasible parts of the hinge curves inside the limits box for A."""
    fig = figure((FIGSIZE[0] * 1.5, FIGSIZE[1]), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax_a, ax_b = fig.subplots(1, 2)
    dom, spec = data.domain, data.spec
    ok = dom.feasible
    for ax, points, name, colour in ((ax_a, dom.a, "A", "tab:blue"), (ax_b, dom.b, "B", "tab:red")):
        _branch_lines(ax, points, dom.family.branch, np.ones(len(ok), dtype=bool), color="0.8", lw=0.8,
                      label="hinge curve")
        _branch_lines(ax, points, dom.family.branch, ok, color=colour, lw=2.0, label="feasible")
        chosen = data.mechanism.body("link_AB").point(name)
        ax.plot(*chosen, "k*", ms=10, label=f"chosen {name}")
        if np.any(ok):
            window = points[ok]
            lo, hi = window.min(axis=0), window.max(axis=0)
            pad = max(2.0, 0.2 * float(np.max(hi - lo)))
            ax.set_xlim(lo[0] - pad, hi[0] + pad)
            ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        ax.set_xlabel("x / mm")
        ax.set_ylabel("y / mm")
        ax.set_title(f"Feasible domain of {name}")
    x0, x1 = spec.a_x_mm
    y0, y1 = spec.a_y_mm
    ax_a.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], "k--", lw=0.8, label="A limits")
    for ax in (ax_a, ax_b):
        legend(ax, loc="best")
    return _png(fig)


def gear_ratio_png(data: Any) -> bytes:
    """Fig 10: transmission ratio and pitch radii over the working range."""
    law = data.dyad.law
    fig = figure(FIGSIZE, 100)  # matplotlib's default dpi, as pyplot's figures had
    ax_i, ax_r = fig.subplots(2, 1, sharex=True)
    x = np.degrees(law.x)
    ax_i.plot(x, law.ratio, "b-", label="i = -dx_b/dx_a")
    ax_i.plot(np.degrees(law.knots_a), -law.law(law.knots_a, 1), "ko", ms=4, label="poses")
    ax_i.set_ylabel("transmission ratio")
    legend(ax_i)
    ax_r.plot(x, law.r_a, "g-", label="sun (O) pitch radius")
    ax_r.plot(x, law.r_b, "m-", label="planet (A) pitch radius")
    ax_r.set_xlabel("x_a: ground rotation relative to arm OA / deg")
    ax_r.set_ylabel("radius / mm")
    legend(ax_r)
    ax_i.set_title(f"Non-circular gear pair, centre distance {law.centre_distance:.2f} mm")
    return _png(fig)


def trajectory_png(data: Any) -> bytes:
    """Fig 12: fingertip trajectory of the solved mechanism with the target poses."""
    fig = figure(FIGSIZE, 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    t, motion = data.targets, data.motion
    tip = motion.point("P", "distal")
    ax.plot(tip[:, 0], tip[:, 1], "b-", lw=1.2, label="fingertip P (mechanism)")
    for i in range(len(t.p)):
        _draw_finger(ax, t, i, color="0.6", lw=1.0, label="target poses" if i == 0 else None)
        heading = t.p[i] - t.c[i]
        heading = 6.0 * heading / np.hypot(*heading)
        ax.arrow(*t.p[i], *heading, head_width=1.5, color="0.4")
    ax.plot(t.p[:, 0], t.p[:, 1], "kx", ms=8, label="target P")
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    err = data.position_error
    ax.set_title(f"Fingertip trajectory (pose error max {err.max():.3f} mm, mean {err.mean():.3f} mm)")
    legend(ax, loc="best")
    return _png(fig)


def five_bar_figures(data: Any) -> dict[str, bytes]:
    """All figures of a five-bar synthesis: ``{file name: PNG bytes}``."""
    return {
        "hinge_curves.png": hinge_curves_png(data),
        "feasible_domain.png": feasible_domain_png(data),
        "gear_ratio.png": gear_ratio_png(data),
        "trajectory.png": trajectory_png(data),
    }
