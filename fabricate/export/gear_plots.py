"""Pictures of gear pairs: the pair in mesh (PNG), the pair turning (GIF), the ratio law (PNG).

Encoders return bytes (deterministic: no timestamps, fixed sizes); only the pipeline writes files.
Gears are drawn in the carrier frame: axis A at the origin, axis B at ``(a, 0)``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.plotting import figure, gif_bytes, legend, palette, png_bytes, rounded_xy

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.mechanism import Law


def _figure(size: tuple[float, float] = (6.0, 4.0), dpi: int = 100) -> tuple[Any, Any]:
    fig = figure(size, dpi)
    return fig, fig.add_subplot(1, 1, 1)


def fill(ax: Any, x: np.ndarray, y: np.ndarray, **style: Any) -> Any:
    """What ``ax.fill(x, y, **style)`` adds for one outline (the same polygon and properties), without its data
    limit pass.

    ``Axes.add_patch`` takes a patch's data limits from every segment as a Bézier curve with its extrema, a
    Python loop that cost a third of a gear pair's picture (about a thousand segments per outline); a straight
    polygon's extrema are its vertices, so the limits are updated from them: the same box.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    x, y : (n,) arrays
        The outline, unclosed (as ``ax.fill`` takes it).
    **style
        As ``ax.fill``'s keywords (its aliases: ``lw``, ``ec``, ...), applied in the same order.
    """
    from matplotlib.cbook import normalize_kwargs
    from matplotlib.lines import Line2D
    from matplotlib.patches import Polygon

    # Axes.fill: Line2D's aliases normalised, a Polygon with no face colour of its own, then the keywords set
    poly = Polygon(np.column_stack((x, y)), facecolor=None, fill=True, closed=True)
    poly.set(**normalize_kwargs(style, Line2D))
    ax.add_artist(poly)
    ax.update_datalim(poly.get_path().vertices)
    return poly


def _placed(pair: GearPair, x_a: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Outlines and pitch curves of both gears at driving angle ``x_a`` in the carrier frame."""
    from fabricate.planar import rotation

    theta_b = float(pair.law(x_a))
    centre_b = np.array([pair.center_distance_mm, 0.0])
    ra, rb = rotation(x_a), rotation(theta_b)
    return (pair.outline_a @ ra.T, pair.outline_b @ rb.T + centre_b,
            pair.pitch_a @ ra.T, pair.pitch_b @ rb.T + centre_b)


def _draw_pair(ax: Any, pair: GearPair, x_a: float, zoom: bool) -> None:
    out_a, out_b, pitch_a, pitch_b = _placed(pair, x_a)
    teeth = pair.report()["teeth"]
    fill(ax, out_a[:, 0], out_a[:, 1], color="#4c72b0", alpha=0.55, lw=0.6, ec="#1f3b63",
         label=f"gear a, z = {teeth[0]}")
    fill(ax, out_b[:, 0], out_b[:, 1], color="#dd8452", alpha=0.55, lw=0.6, ec="#7a3d17",
         label=f"gear b, z = {teeth[1]}")
    # both pitch curves in one dark grey: the fill says whose each is, the legend what the dashes are
    ax.plot(pitch_a[:, 0], pitch_a[:, 1], "--", color="0.25", lw=0.5, label="pitch curves")
    ax.plot(pitch_b[:, 0], pitch_b[:, 1], "--", color="0.25", lw=0.5)
    for centre, bore in (((0.0, 0.0), pair.bore_a_mm), ((pair.center_distance_mm, 0.0), pair.bore_b_mm)):
        t = np.linspace(0, 2 * np.pi, 60)
        ax.plot(centre[0] + 0.5 * bore * np.cos(t), centre[1] + 0.5 * bore * np.sin(t), color="k", lw=0.6)
        ax.plot(*centre, "k+", ms=5)
    ax.set_aspect("equal")
    if zoom:
        r_a = float(pair.pitch_model.radii(np.array([x_a]), "a")[0][0])
        w = 6.0 * np.pi * pair.module
        ax.set_xlim(r_a - 0.6 * w, r_a + 0.6 * w)
        ax.set_ylim(-0.45 * w, 0.45 * w)


def pair_png(pair: GearPair, x_a: float) -> bytes:
    """The pair in mesh at driving angle ``x_a`` (rad): whole pair and a zoom on the pitch point."""
    return png_bytes(pair_figure(pair, x_a))


def pair_figure(pair: GearPair, x_a: float) -> Any:
    """The figure :func:`pair_png` renders, with a legend naming each gear and the pitch curves."""
    fig = figure((10.0, 4.6), 110)
    ax1, ax2 = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    _draw_pair(ax1, pair, x_a, zoom=False)
    _draw_pair(ax2, pair, x_a, zoom=True)
    rep = pair.report()
    ax1.set_title(f"{pair.name}: z = {rep['teeth'][0]}/{rep['teeth'][1]}, m = {pair.module:.4g} mm, "
                  f"{pair.method}", fontsize=9)
    te = rep.get("transmission_error_deg")
    bl = rep.get("backlash_mm") or [None, None]
    ax2.set_title(f"x_a = {np.degrees(x_a):.1f} deg; TE = {te if te is None else f'{te:.2g}'} deg; "
                  f"backlash {bl[0] if bl[0] is None else f'{bl[0]:.3f}'} mm", fontsize=9)
    for ax in (ax1, ax2):
        ax.set_xlabel("x (mm)")
        ax.tick_params(labelsize=7)
    # one legend for both panels, under them (inside, it hid teeth of the zoom)
    handles, labels = ax1.get_legend_handles_labels()
    legend(fig, handles, labels, loc="lower center", ncol=len(handles), frameon=False)
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.16, top=0.92, wspace=0.15)
    return fig


def pair_gif(pair: GearPair, frames: int, size_px: int = 384, frame_ms: int = 80) -> bytes:
    """The pair turning through its working range, ``frames`` frames, as an animated GIF.

    Drawn with Pillow on a fixed palette (no per-frame quantising): fast and deterministic. The
    carrier frame is drawn with axis A at the origin and y up.
    """
    from PIL import Image, ImageDraw

    from fabricate.export.previews import label_font

    lo, hi = pair.working_range
    xs = np.linspace(lo, hi, int(frames), endpoint=not pair.closed)
    out_a0, out_b0, _, _ = _placed(pair, lo)
    centre_b = np.array([pair.center_distance_mm, 0.0])
    reach = 1.05 * max(np.abs(out_a0).max(), np.abs(out_b0 - centre_b).max())
    lo_xy = np.array([-reach, -reach])
    scale = size_px / float(pair.center_distance_mm + 2.0 * reach)
    width, height = size_px, max(16, int(round(2.0 * reach * scale)))

    def pixels(points: np.ndarray) -> list[float]:
        x = (points[:, 0] - lo_xy[0]) * scale
        y = height - (points[:, 1] - lo_xy[1]) * scale  # image y points down
        return rounded_xy(x, y)  # flat [x0, y0, ...]: what Pillow makes of a list of (x, y) pairs

    # index 0 white, 1 dark outline, 2 gear a, 3 gear b
    palette = [255, 255, 255, 40, 40, 40, 76, 114, 176, 221, 132, 82]
    palette += [0] * (768 - len(palette))
    # one blank frame on the palette and one font for every frame (a copy carries the palette: the same frames)
    blank = Image.new("P", (width, height), 0)
    blank.putpalette(palette)
    font = label_font()
    images = []
    for x in xs:
        out_a, out_b, _, _ = _placed(pair, float(x))
        image = blank.copy()
        draw = ImageDraw.Draw(image)
        draw.polygon(pixels(out_a), fill=2, outline=1)
        draw.polygon(pixels(out_b), fill=3, outline=1)
        for centre, bore in ((np.zeros(2), pair.bore_a_mm), (centre_b, pair.bore_b_mm)):
            cx, cy = pixels(centre[None, :])
            r = 0.5 * bore * scale
            draw.ellipse((cx - r, cy - r, cx + r, cy + r), fill=0, outline=1)
        draw.text((4, 4), f"gear a {np.degrees(x):.1f} deg", fill=1, font=font)
        images.append(image)
    return gif_bytes(images, frame_ms, optimize=False, disposal=1)


def law_png(law: Law, working_range: tuple[float, float], center_distance_mm: float) -> bytes:
    """The ratio law: driven against driving angle, and the transmission ratio."""
    return png_bytes(law_figure(law, working_range, center_distance_mm))


def law_figure(law: Law, working_range: tuple[float, float], center_distance_mm: float) -> Any:
    """The figure :func:`law_png` renders: two curves on twin axes, one legend naming both (and its axis)."""
    lo, hi = working_range
    x = np.linspace(lo, hi, 400)
    fig, ax = _figure((6.0, 3.6), 100)
    angle_colour, ratio_colour = palette(2)
    ax.plot(np.degrees(x), -np.degrees(np.asarray(law(x))), color=angle_colour,
            label="driven angle (deg, left axis)")
    ax.set_xlabel("driving angle x_a (deg)")
    ax.set_ylabel("driven angle (deg)", color=angle_colour)
    ax2 = ax.twinx()
    ax2.plot(np.degrees(x), -np.asarray(law(x, 1)), color=ratio_colour, ls="--", label="ratio i (right axis)")
    ax2.set_ylabel("transmission ratio i = -law'", color=ratio_colour)
    ax.set_title(f"gear law, centre distance {center_distance_mm:.3f} mm", fontsize=9)
    # one legend for both axes, on the twin (drawn last, so no curve crosses it)
    handles = ax.get_legend_handles_labels()[0] + ax2.get_legend_handles_labels()[0]
    legend(ax2, handles, [h.get_label() for h in handles], loc="best", framealpha=0.85)
    fig.subplots_adjust(left=0.12, right=0.86, bottom=0.14, top=0.9)
    return fig
