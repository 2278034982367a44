"""Shared matplotlib plumbing for every plot module (kernel isolation: matplotlib is imported only here
and in the plot modules, lazily).

PNG bytes are deterministic: the Agg backend, a fixed dpi, and no ``Software`` tag in the metadata.

Every plot takes its series colours from :func:`palette` / :func:`series_styles` (distinct colours in a fixed
order, never cycling back to the first blue at the eleventh series) and its legend from :func:`legend`
(never smaller than :data:`MIN_LEGEND_PT`). :func:`figure_problems` states what a readable figure is; the
tests hold every plot a build writes to it.
"""

from __future__ import annotations

import colorsys
import io
import sys
from collections.abc import Sequence
from typing import Any

#: Smallest legend text (points): 11 px at the 100 dpi the plots are drawn at, readable at 100 % zoom.
MIN_LEGEND_PT = 8.0

#: Distinct series colours in their fixed order: matplotlib's tab10, then tab20's light shades and tab20b /
#: tab20c, keeping only colours at least 0.15 apart (RGB in 0..1, Euclidean) from every earlier one and dark
#: enough to see on white (luminance at most 0.85). Written out, so the order never depends on the matplotlib
#: version and Pillow-only pictures (the GIFs) need no matplotlib.
DISTINCT_HEX = ("1f77b4", "ff7f0e", "2ca02c", "d62728", "9467bd", "8c564b", "e377c2", "7f7f7f", "bcbd22", "17becf",
                "aec7e8", "ffbb78", "98df8a", "ff9896", "c49c94", "f7b6d2", "c7c7c7", "dbdb8d", "393b79", "5254a3",
                "6b6ecf", "9c9ede", "637939", "8ca252", "b5cf6b", "bd9e39", "e7ba52", "d6616b", "7b4173", "a55194",
                "6baed6", "e6550d", "fd8d3c", "fdd0a2", "31a354", "74c476", "636363", "969696")

#: Line styles of the series past each decade of colours: a line's style changes with its colour's family,
#: so the eleventh series (light blue) does not read as the first (blue) even in grey print.
SERIES_LINESTYLES = ("-", "--", "-.", ":")


def _hex_rgb(code: str) -> tuple[float, float, float]:
    return (int(code[0:2], 16) / 255.0, int(code[2:4], 16) / 255.0, int(code[4:6], 16) / 255.0)


def palette(n: int) -> list[tuple[float, float, float]]:
    """``n`` pairwise distinct RGB colours (0..1) in a fixed order.

    The first :data:`DISTINCT_HEX` colours are at least 0.15 apart; past them, hues spread by the golden
    angle at three lightness levels (still pairwise distinct, less far apart: draw that many series as small
    multiples or in a table instead).
    """
    base = [_hex_rgb(h) for h in DISTINCT_HEX]
    out = base[:max(0, n)]
    k = 0
    while len(out) < n:
        hue = (0.61803398875 * k) % 1.0
        value = (0.55, 0.75, 0.4)[k % 3]
        colour = tuple(round(c, 6) for c in colorsys.hsv_to_rgb(hue, 0.65, value))
        k += 1
        if colour not in out:
            out.append(colour)  # type: ignore[arg-type]  # three floats
    return out


def palette_rgb255(n: int) -> list[tuple[int, int, int]]:
    """:func:`palette` as 0..255 integers (Pillow's pictures)."""
    return [(round(255 * r), round(255 * g), round(255 * b)) for r, g, b in palette(n)]


def series_styles(n: int) -> list[dict[str, Any]]:
    """``color`` and ``linestyle`` of ``n`` line series: pairwise distinct colours (:func:`palette`), and a
    new line style with each decade of colours."""
    return [{"color": colour, "linestyle": SERIES_LINESTYLES[(k // 10) % len(SERIES_LINESTYLES)]}
            for k, colour in enumerate(palette(n))]


def legend(ax: Any, *args: Any, fontsize: float | None = None, **kwargs: Any) -> Any:
    """``ax.legend(...)`` (an Axes or a Figure) with its text at least :data:`MIN_LEGEND_PT` points.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or matplotlib.figure.Figure
    *args, **kwargs
        As ``Axes.legend``.
    fontsize : float, optional
        Asked-for size; raised to :data:`MIN_LEGEND_PT`.
    """
    size = max(MIN_LEGEND_PT, float(fontsize) if fontsize is not None else MIN_LEGEND_PT)
    return ax.legend(*args, fontsize=size, **kwargs)


def legend_below(fig: Any, ax: Any, axes_height_in: float, columns: int = 2, **kwargs: Any) -> Any:
    """A legend of ``ax``'s series in ``columns`` columns under it, the figure grown to hold it.

    Long entries (a part, its feature and its Kt) keep their whole text at :data:`MIN_LEGEND_PT`, which a
    legend beside the axes cut at the figure's edge. Sets the figure's height and the axes' margins.

    Parameters
    ----------
    fig, ax
        The figure and its one axes.
    axes_height_in : float
        Height of the axes with its title and tick labels (inches).
    columns : int
    **kwargs
        As :func:`legend`.
    """
    handles, labels = ax.get_legend_handles_labels()
    rows = -(-len(handles) // max(1, columns))
    legend_in = 0.15 + 0.17 * rows  # 8 pt rows
    height = axes_height_in + legend_in
    width = fig.get_size_inches()[0]
    fig.set_size_inches(width, height)
    fig.subplots_adjust(left=0.8 / width, right=1.0 - 0.25 / width, bottom=(legend_in + 0.5) / height,
                        top=1.0 - 0.4 / height)
    return legend(fig, handles, labels, loc="lower center", ncol=columns, frameon=False,
                  bbox_to_anchor=(0.5, 0.0), **kwargs)


def _is_grey(rgba: Sequence[float]) -> bool:
    return max(rgba[:3]) - min(rgba[:3]) < 0.02


def _labelled(ax: Any) -> list[tuple[Any, str]]:
    handles, labels = ax.get_legend_handles_labels()
    return list(zip(handles, labels, strict=True))


def _style(artist: Any) -> tuple[Any, ...]:
    """How a legend entry's artist looks: colour (RGBA, rounded), line style and marker."""
    import numpy as np
    from matplotlib.colors import to_rgba

    def rounded(colour: Any) -> tuple[float, ...]:
        return tuple(round(float(c), 3) for c in colour)

    if hasattr(artist, "get_marker"):  # a Line2D: its colour, dashes and marker
        return (rounded(to_rgba(artist.get_color())), artist.get_linestyle(), artist.get_marker())
    # a collection (scatter) or a patch (fill): the face colour, or the edge's where the face is hollow
    faces = np.asarray(artist.get_facecolor(), dtype=float).reshape(-1, 4)
    edges = np.asarray(artist.get_edgecolor(), dtype=float).reshape(-1, 4)
    colour = faces[0] if len(faces) and faces[0][3] > 0 else (edges[0] if len(edges) else np.zeros(4))
    paths = artist.get_paths() if hasattr(artist, "get_paths") else []
    marker = len(paths[0].vertices) if len(paths) else 0  # a scatter's marker shape, by its vertex count
    return (rounded(colour), "", marker)


def series_colours(ax: Any) -> list[tuple[float, ...]]:
    """The colour of each labelled series of ``ax`` (its legend entries), in legend order."""
    return [_style(artist)[0] for artist, _ in _labelled(ax)]


def figure_problems(fig: Any) -> list[str]:
    """What makes ``fig`` hard to read, as sentences (an empty list: readable).

    - a legend's text under :data:`MIN_LEGEND_PT` points;
    - a labelled series that no legend of the figure lists;
    - two legend entries of one axes drawn alike (same colour, line style and marker);
    - an axes with unlabelled curves in two or more colours (other than greys) and no legend: a multi-curve
      plot a reader cannot decode.
    """
    import numpy as np
    from matplotlib.colors import to_rgba
    from matplotlib.lines import Line2D

    problems: list[str] = []
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)
    shown: set[str] = set()
    for leg in legends:
        for text in leg.get_texts():
            shown.add(text.get_text())
            if text.get_fontsize() < MIN_LEGEND_PT - 1e-9:
                problems.append(f"legend text {text.get_text()!r} is {text.get_fontsize():g} pt "
                                f"(< {MIN_LEGEND_PT:g})")
    for k, ax in enumerate(fig.axes):
        entries = _labelled(ax)
        for _, label in entries:
            if label not in shown:
                problems.append(f"axes {k}: series {label!r} is in no legend")
        styles: dict[tuple[Any, ...], str] = {}
        for artist, label in entries:
            style = _style(artist)
            if style in styles and styles[style] != label:
                problems.append(f"axes {k}: {styles[style]!r} and {label!r} are drawn alike")
            styles.setdefault(style, label)
        unlabelled = {tuple(round(c, 3) for c in to_rgba(line.get_color())) for line in ax.get_lines()
                      if isinstance(line, Line2D) and str(line.get_label()).startswith("_")
                      and np.size(line.get_xdata()) > 2}
        coloured = {c for c in unlabelled if not _is_grey(c)}
        if len(coloured) >= 2 and not entries and ax.get_legend() is None and not fig.legends:
            problems.append(f"axes {k}: {len(coloured)} colours of curves and no legend")
    return problems


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def load_agg() -> None:
    """Import what :func:`figure` draws with (matplotlib's object-oriented Agg API) now.

    A build calls it before it forks its picture child when both will draw: the child then inherits the
    modules instead of importing them again (a cold build imported matplotlib twice, once in each process).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.backends.backend_agg
    import matplotlib.figure  # noqa: F401 - imported for the child to inherit


def figure(size: tuple[float, float], dpi: float) -> Any:
    """A standalone figure (not registered with pyplot) on an Agg canvas."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def rounded_xy(x: Any, y: Any) -> list[float]:
    """``[x0, y0, x1, y1, ...]``, each ``round(float(v), 2)``: pixel coordinates for Pillow's drawing, vectorised.

    The same floats as Python's ``round`` (a GIF's bytes depend on them): ``rint(100 v) / 100`` is that
    value wherever ``100 v`` is computed on the same side of a half as its exact value; the few that lie
    within a millionth of a half are rounded by Python's (correctly rounded) ``round`` instead.

    Parameters
    ----------
    x, y : array_like
        Coordinates (pixels), one value per point.
    """
    import numpy as np

    values = np.column_stack([np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)]).ravel()
    if len(values) <= 16:  # a point or a few (a hole's centre): Python's round itself is quicker than numpy's calls
        return [round(v, 2) for v in values.tolist()]
    scaled = values * 100.0
    out = np.rint(scaled) / 100.0
    near = np.flatnonzero(np.abs(scaled - np.floor(scaled) - 0.5) < 1e-6)
    flat: list[float] = out.tolist()
    for k in near.tolist():
        flat[k] = round(float(values[k]), 2)
    return flat


def gif_bytes(images: list[Any], frame_ms: int, **options: Any) -> bytes:
    """Animated GIF (looping) of Pillow images."""
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=frame_ms, loop=0,
                   **options)
    return buffer.getvalue()


def png_bytes(fig: Any, dpi: float | None = None) -> bytes:
    """Render a figure to PNG bytes and release it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A standalone figure (:func:`figure`) or a pyplot-managed one.
    dpi : float, optional
        Resolution; the figure's own when omitted.
    """
    buffer = io.BytesIO()
    _savefig(fig, buffer, dpi if dpi is not None else fig.dpi)
    # only pyplot keeps a figure alive (a standalone one is freed with its last reference): importing pyplot
    # just to close it cost every build its import
    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close(fig)
    return buffer.getvalue()


def _savefig(fig: Any, buffer: io.BytesIO, dpi: float) -> None:
    """Every plot's one way to pixels (a test wraps it to look at each figure a build draws)."""
    fig.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
