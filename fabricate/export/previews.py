"""Pictures of the assembly: a PNG at several poses (matplotlib) and a GIF of the motion (Pillow).

Both are deterministic: the PNG carries no software/date metadata and the GIF frames are drawn with
Pillow's rasteriser from fixed pixel maps. Parts are drawn bottom layer first, each part in its own colour
(:func:`fabricate.plotting.palette`: no two parts alike), holes as background discs.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.parts.model import Part, circle_polygon
from fabricate.planar import transform_points
from fabricate.plotting import DISTINCT_HEX, figure, gif_bytes, legend, palette_rgb255, png_bytes, rounded_xy

if TYPE_CHECKING:
    from fabricate.mechanism import Motion
    from fabricate.parts.assembly import PinStack

#: Part colours (RGB 0-255): the shared distinct palette (its first ten are matplotlib's tab10, as before).
PALETTE = palette_rgb255(len(DISTINCT_HEX))

#: Parts the motion GIF draws as outlines: the actuator's mount plate lies over the mechanism, and filled it
#: hid the gears, links and standoffs under it in every frame.
SEE_THROUGH_ROLES = ("mount",)

#: Outline tolerance (mm) for pictures.
PREVIEW_CHORD_MM = 0.05


def pose_indices(count: int, poses: int) -> list[int]:
    """``poses`` sweep indices spread evenly from the first to the last of ``count``."""
    if count <= 1 or poses <= 1:
        return [0]
    return sorted({int(round(v)) for v in np.linspace(0, count - 1, poses)})


def label_font() -> Any:
    """Pillow's built-in bitmap font: the same pixels on every machine (no system fonts)."""
    from PIL import ImageFont

    return getattr(ImageFont, "load_default_imagefont", ImageFont.load_default)()


def frame_label(value: float, unit: str) -> str:
    """The text drawn on a GIF frame: its input value."""
    return f"input {float(value):.1f} {unit}"


def part_colours(parts: Sequence[Part]) -> dict[str, int]:
    """A :data:`PALETTE` index per part, in part-list order: every part its own colour up to the palette's
    length (meshing gears on one layer, a link and its spacer, the eleventh part and the first all differ)."""
    return {part.name: k % len(PALETTE) for k, part in enumerate(parts)}


def _part_rgb(index: int) -> np.ndarray:
    return np.array(PALETTE[index], dtype=np.float64) / 255.0


def _shapes(parts: Sequence[Part]) -> list[tuple[Part, np.ndarray, list[tuple[np.ndarray, float]]]]:
    """(part, outline polygon, holes) drawn bottom layer first."""
    ordered = sorted(parts, key=lambda p: (p.z_mm, p.name))
    return [(p, p.outline.polygon(PREVIEW_CHORD_MM),
             [(np.asarray(h.centre, dtype=np.float64), h.diameter_mm / 2.0) for h in p.holes]
             + [(s.vertices.mean(axis=0), 0.0) for s in getattr(p, "slots", ())]) for p in ordered]


def _extent(shapes: list[Any], motion: Motion, indices: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    pts = []
    for i in indices:
        poses = motion.poses_at(i)
        for part, outline, _ in shapes:
            pts.append(transform_points(poses.get(part.body, np.zeros(3)), outline))
    allpts = np.concatenate(pts)
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    pad = 0.05 * float(max(hi - lo)) + 1.0
    return lo - pad, hi + pad


def assembly_png(parts: Sequence[Part], motion: Motion, poses: int = 4, tip_point: str | None = None,
                 title: str = "") -> bytes:
    """PNG of the assembly at ``poses`` poses spread over the motion, one panel each.

    Parameters
    ----------
    parts : sequence of Part
    motion : Motion
    poses : int
        Number of panels.
    tip_point : str, optional
        A point whose whole trajectory is drawn in every panel.
    title : str
        Figure title.
    """
    return png_bytes(assembly_figure(parts, motion, poses, tip_point, title), 100)


def assembly_figure(parts: Sequence[Part], motion: Motion, poses: int = 4, tip_point: str | None = None,
                    title: str = "") -> Any:
    """The figure :func:`assembly_png` renders: the panels, and below them a legend naming every part's
    colour (and the tip's path)."""
    from matplotlib.collections import PolyCollection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    shapes = _shapes(parts)
    part_colour = part_colours(parts)
    indices = pose_indices(len(motion.inputs), poses)
    lo, hi = _extent(shapes, motion, indices)
    trace = None
    if tip_point:
        try:
            trace = motion.point(tip_point)
        except KeyError:
            trace = None
    width = 3.2 * len(indices)
    # the legend under the panels: as many columns as fit the width, a row of 0.2 in each
    entries = len(parts) + (trace is not None)
    columns = max(1, min(entries, int(width // 1.9)))
    rows = -(-entries // columns)
    legend_in = 0.1 + 0.18 * rows
    panels_in = 3.4
    height = panels_in + legend_in
    fig = figure((width, height), 100)
    axes = fig.subplots(1, len(indices), squeeze=False, sharex=True, sharey=True)
    unit = getattr(motion.mechanism, "input_unit", "deg")
    for ax, i in zip(axes[0], indices, strict=True):
        body_poses = motion.poses_at(i)
        plates, faces, edges, holes_xy = [], [], [], []
        for part, outline, holes in shapes:
            pose = body_poses.get(part.body, np.zeros(3))
            colour = _part_rgb(part_colour[part.name])
            plates.append(transform_points(pose, outline))
            faces.append((*colour, 0.55))
            edges.append(tuple(colour * 0.6))
            for centre, radius in holes:
                if radius > 0:
                    holes_xy.append(transform_points(pose, circle_polygon(centre, 2 * radius, PREVIEW_CHORD_MM)))
        # one collection per panel: add_patch per shape costs more than the drawing; no data limits (autolim):
        # the view is set below, from the same extent for every panel
        ax.add_collection(PolyCollection(plates, facecolors=faces, edgecolors=edges, linewidths=0.6), autolim=False)
        ax.add_collection(PolyCollection(holes_xy, facecolors="white", edgecolors="0.3", linewidths=0.4),
                          autolim=False)
        if trace is not None:
            ax.plot(trace[:, 0], trace[:, 1], color="black", linewidth=0.6, linestyle="--")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_title(f"input {motion.inputs[i]:.1f} {unit}", fontsize=8)
        ax.tick_params(labelsize=6)
        ax.locator_params(nbins=4)
    axes[0][0].set_ylabel("y (mm)", fontsize=7)
    for ax in axes[0]:
        ax.set_xlabel("x (mm)", fontsize=7)
    if title:
        fig.suptitle(title, fontsize=9)
    # a legend of proxies in the parts' own face colours (each part named once, in part-list order)
    handles: list[Any] = [Patch(facecolor=(*_part_rgb(part_colour[part.name]), 0.55),
                                edgecolor=tuple(_part_rgb(part_colour[part.name]) * 0.6), label=part.name)
                          for part in parts]
    if trace is not None:
        handles.append(Line2D([], [], color="black", linewidth=0.6, linestyle="--", label=f"path of {tip_point}"))
    legend(fig, handles=handles, loc="lower center", ncol=columns, frameon=False, bbox_to_anchor=(0.5, 0.0),
           handlelength=1.5, columnspacing=1.2)
    # fixed margins (tight_layout costs more than the drawing itself): the panels keep their 3.4 in, the
    # legend takes the rest
    fig.subplots_adjust(left=0.06, right=0.99, bottom=(legend_in + 0.45) / height,
                        top=1.0 - 0.48 / height, wspace=0.08)
    return fig


def motion_gif(parts: Sequence[Part], motion: Motion, frames: int = 24, size_px: int = 360,
               frame_ms: int = 80) -> bytes:
    """Animated GIF of the motion there and back, drawn with Pillow.

    Parameters
    ----------
    parts : sequence of Part
    motion : Motion
    frames : int
        Poses on the way out (the way back repeats them in reverse).
    size_px : int
        Longest image side in pixels.
    frame_ms : int
        Frame duration.
    """
    from PIL import Image, ImageDraw

    shapes = _shapes(parts)
    part_colour = part_colours(parts)
    unit = motion.mechanism.input_unit
    indices = pose_indices(len(motion.inputs), frames)
    lo, hi = _extent(shapes, motion, indices)
    scale = size_px / float(max(hi - lo))
    width = max(16, int(round((hi[0] - lo[0]) * scale)))
    height = max(16, int(round((hi[1] - lo[1]) * scale)))

    def pixels(points: np.ndarray) -> list[float]:
        x = (points[:, 0] - lo[0]) * scale
        y = height - (points[:, 1] - lo[1]) * scale  # image y points down
        return rounded_xy(x, y)  # flat [x0, y0, ...]: what Pillow makes of a list of (x, y) pairs

    # a fixed palette: index 0 white, 1 outline grey, 2.. the layer colours (no per-frame quantising)
    # (the first ten colours always, so a GIF of up to ten parts keeps the bytes it had with a 10-colour palette)
    palette = [255, 255, 255, 40, 40, 40] + [c for rgb in PALETTE[:max(10, len(parts))] for c in rgb]
    palette += [0] * (768 - len(palette))
    # one blank frame on the palette and one font for every frame (a copy carries the palette: the same frames)
    blank = Image.new("P", (width, height), 0)
    blank.putpalette(palette)
    font = label_font()
    images = []
    for i in indices:
        image = blank.copy()
        draw = ImageDraw.Draw(image)
        body_poses = motion.poses_at(i)
        for part, outline, holes in shapes:
            pose = body_poses.get(part.body, np.zeros(3))
            colour = 2 + part_colour[part.name]
            ring = pixels(transform_points(pose, outline))
            if part.role in SEE_THROUGH_ROLES:  # its outline only: a filled mount plate hid the parts under it
                draw.line([*ring, *ring[:2]], fill=colour, width=2)
                continue
            draw.polygon(ring, fill=colour, outline=1)
            for centre, radius in holes:
                if radius > 0:
                    cx, cy = pixels(transform_points(pose, centre)[None, :])
                    r = radius * scale
                    draw.ellipse((cx - r, cy - r, cx + r, cy + r), fill=0)
        draw.text((4, 4), frame_label(motion.inputs[i], unit), fill=1, font=font)
        images.append(image)
    sequence = images + images[-2:0:-1]
    return gif_bytes(sequence, frame_ms, optimize=False, disposal=1)


def exploded_png(parts: Sequence[Part], poses: Mapping[str, np.ndarray], stacks: Sequence[PinStack],
                 title: str = "") -> bytes:
    """PNG of the assembly at one pose, exploded along the pins and drawn in oblique projection.

    Each part lies at its assembly height stretched so the layers stand apart; every pin is a dashed
    axis through the parts it carries, and each part is labelled. Parts are drawn bottom to top.

    Parameters
    ----------
    parts : sequence of Part
    poses : Mapping[str, (3,) array]
        World pose of every body (the first pose of the motion).
    stacks : sequence of PinStack
        From :func:`fabricate.parts.assembly.pin_stacks`.
    title : str
    """
    return png_bytes(exploded_figure(parts, poses, stacks, title), 100)


def _pin_centre(stack: PinStack, placed: Mapping[str, Any], poses: Mapping[str, np.ndarray]) -> np.ndarray | None:
    """Where ``stack``'s pin is in the plan (world xy): the centre of its hole in the first part of its stack
    that has one, else in any part that does (a printed spacer)."""
    # a compound pin's holes carry its whole name ("A+A_k"), a simple one its joint
    joints = set(stack.pin.split("+")) | {stack.pin}
    names = [item.item for item in stack.items if item.item in placed] + sorted(placed)
    for name in names:
        part = placed[name][2]
        hole = next((h for h in part.holes if h.joint in joints), None)
        if hole is not None:
            return transform_points(poses.get(part.body, np.zeros(3)), hole.centre)
    return None


def exploded_figure(parts: Sequence[Part], poses: Mapping[str, np.ndarray], stacks: Sequence[PinStack],
                    title: str = "") -> Any:
    """The figure :func:`exploded_png` renders. Each pin's axis is a line whose gid is ``"pin <name>"``."""
    from matplotlib.collections import PolyCollection

    shapes = _shapes(parts)
    part_colour = part_colours(parts)
    placed = {part.name: (transform_points(poses.get(part.body, np.zeros(3)), outline), holes, part)
              for part, outline, holes in shapes}
    plan = np.concatenate([outline for outline, _, _ in placed.values()])
    span = float(np.ptp(plan, axis=0).max()) or 1.0
    top = max((p.z_mm + p.thickness_mm for p in parts), default=1.0) or 1.0
    stretch = 0.9 * span / top  # the exploded stack as tall as the mechanism is wide
    lift = np.array([0.45, 0.75])  # oblique direction of the exploded z axis on the page

    def project(xy: np.ndarray, z: float) -> np.ndarray:
        return np.asarray(xy, dtype=np.float64) + z * stretch * lift

    fig = figure((7.0, 7.0), 100)
    ax = fig.add_subplot(1, 1, 1)
    for name in sorted(placed, key=lambda n: (placed[n][2].z_mm, n)):
        outline, holes, part = placed[name]
        colour = _part_rgb(part_colour[name])
        pose = poses.get(part.body, np.zeros(3))
        z_mid = part.z_mm + 0.5 * part.thickness_mm  # one face per part: the gaps are what is exploded
        face = project(outline, z_mid)
        ax.add_collection(PolyCollection([face], facecolors=[(*colour, 0.75)], edgecolors=[tuple(colour * 0.6)],
                                         linewidths=0.6))
        holes_xy = [project(transform_points(pose, circle_polygon(c, 2 * r, PREVIEW_CHORD_MM)), z_mid)
                    for c, r in holes if r > 0]
        ax.add_collection(PolyCollection(holes_xy, facecolors="white", edgecolors="0.3", linewidths=0.4))
        label = face.mean(axis=0)
        small = float(np.ptp(outline, axis=0).max()) < 0.15 * span  # a label would hide it: put it beside
        ax.annotate(name, label, fontsize=8, ha="left" if small else "center", va="center",
                    xytext=(8, 0) if small else (0, 0), textcoords="offset points",
                    bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none", "pad": 0.5})
    for stack in stacks:
        centre = _pin_centre(stack, placed, poses)
        if centre is None:  # no part has the pin's hole: nothing to draw it through
            continue
        ends = np.array([project(centre, stack.z_mm - 0.5), project(centre, stack.z_mm + stack.length_mm + 0.5)])
        ax.plot(ends[:, 0], ends[:, 1], color="black", lw=0.8, ls="--", gid=f"pin {stack.pin}")
        ax.annotate(f"pin {stack.pin}", ends[1], fontsize=8, xytext=(2, 2), textcoords="offset points")
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_axis_off()
    # hidden axis artists too: the title's placement otherwise measured the y axis (its ticks made, located and
    # labelled) for an offset text that an axes drawn without axes never shows
    ax.xaxis.set_visible(False)
    ax.yaxis.set_visible(False)
    ax.set_title(f"{title} exploded along the pins (z stretched x{stretch:.2g})" if title else "exploded",
                 fontsize=9)
    fig.subplots_adjust(left=0.02, right=0.98, bottom=0.02, top=0.94)
    return fig
