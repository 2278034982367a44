"""The gear pictures' drawing helpers (``fabricate/export/gear_plots.py``)."""

from __future__ import annotations

import numpy as np

from fabricate.export.gear_plots import fill
from fabricate.plotting import figure, png_bytes


def _star(points: int = 300) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 2.0 * np.pi, points, endpoint=False)
    r = 10.0 + 3.0 * np.sin(7.0 * t)  # non-convex, away from the origin, like a gear's outline
    return 40.0 + r * np.cos(t), -5.0 + r * np.sin(t)


def test_fill_is_axes_fill_without_its_limit_pass():
    # the same polygon, properties, data limits and pixels as ax.fill, whose limits are autoscaled from
    x, y = _star()
    style = {"color": "#4c72b0", "alpha": 0.55, "lw": 0.6, "ec": "#1f3b63", "label": "gear a"}
    figures = []
    for draw in ("axes", "helper"):
        fig = figure((4.0, 3.0), 100)
        ax = fig.add_subplot(1, 1, 1)
        poly = ax.fill(x, y, **style)[0] if draw == "axes" else fill(ax, x, y, **style)
        ax.plot(x[:5], y[:5] - 20.0)  # a later artist: the limits are the union
        ax.legend()
        figures.append((fig, ax, poly))
    (fig_a, ax_a, a), (fig_b, ax_b, b) = figures
    assert np.array_equal(a.get_path().vertices, b.get_path().vertices)
    assert np.array_equal(a.get_path().codes, b.get_path().codes)
    for getter in ("get_facecolor", "get_edgecolor", "get_linewidth", "get_alpha", "get_label", "get_fill"):
        assert getattr(a, getter)() == getattr(b, getter)(), getter
    assert np.array_equal(ax_a.dataLim.get_points(), ax_b.dataLim.get_points())
    assert ax_b.dataLim.x1 > 49.0  # the polygon's own extent, not only the line's
    assert png_bytes(fig_a) == png_bytes(fig_b)
