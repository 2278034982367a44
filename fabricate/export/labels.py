"""Part labels as outlines: text turned into closed polygons (mm) that a laser engraves as paths.

Shops take no live text (an SVG ``<text>`` or a DXF TEXT is drawn in whatever font the shop's software has,
or not at all: OpenSCAD reports "Unsupported DXF Entity 'TEXT'"), so a cut file's label is the glyph
outlines of the text, traced from the DejaVu Sans font that ships inside matplotlib (the same file on every
install, so equal text gives equal polygons) with matplotlib's :class:`~matplotlib.textpath.TextPath`. The
glyphs' quadratic Bézier curves are flattened here, each to a fixed number of chords chosen from the
tolerance, so the polygons carry no bulges and no curves.

A label is sized to fit: :func:`fit_label` finds the largest text, along the part's length or level, whose
box lies inside the part less its holes and slots with a margin all round. A part whose name cannot be
engraved at the process's smallest legible height gets its part number instead ("3"), and a part where
even that does not fit is left unlabelled; the report keys every number to its part and lists those left
out (:func:`label_parts`).

Heights are cap heights (of the letter H), the way a DXF TEXT's height is measured.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely.ops import polylabel

from fabricate.planar import rotation

if TYPE_CHECKING:
    from fabricate.parts.model import Part

#: The largest label engraved (cap height, mm): bigger text only takes longer to engrave.
MAX_LABEL_MM = 5.0
#: Glyph curves are flattened to chords whose sagitta is at most this fraction of the cap height.
CURVE_TOLERANCE = 0.002
#: Candidate centres per side of the grid searched for the roomiest spot.
GRID = 24


@lru_cache(maxsize=1)
def _font() -> Any:
    """DejaVu Sans from matplotlib's own data (never a system font: the outlines must not vary by machine)."""
    import matplotlib
    from matplotlib.font_manager import FontProperties

    return FontProperties(fname=str(Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"))


@lru_cache(maxsize=1)
def cap_height_em() -> float:
    """Cap height of the font as a fraction of its em (the letter H's height at size 1)."""
    from matplotlib.textpath import TextPath

    return float(TextPath((0.0, 0.0), "H", size=1.0, prop=_font()).vertices[:, 1].max())


@lru_cache(maxsize=256)
def _unit_outlines(text: str) -> tuple[np.ndarray, ...]:
    """The text's glyph contours at cap height 1, centred on its box; read-only arrays."""
    from matplotlib.path import Path as MplPath
    from matplotlib.textpath import TextPath

    if not text.strip():  # nothing to draw (matplotlib cannot build an empty path)
        return ()
    size = 1.0 / cap_height_em()
    path = TextPath((0.0, 0.0), text, size=size, prop=_font())
    # a quadratic Bézier's sagitta with k chords is at most |P0 - 2 P1 + P2| / (8 k^2)
    contours: list[list[np.ndarray]] = []
    current: list[np.ndarray] = []
    vertices, codes = path.vertices, path.codes
    i = 0
    while i < len(codes):
        code = codes[i]
        if code == MplPath.MOVETO:
            if len(current) > 2:
                contours.append(current)
            current = [vertices[i]]
            i += 1
        elif code == MplPath.LINETO:
            current.append(vertices[i])
            i += 1
        elif code == MplPath.CURVE3:
            p0, p1, p2 = current[-1], vertices[i], vertices[i + 1]
            bend = float(np.hypot(*(p0 - 2.0 * p1 + p2)))
            k = max(1, math.ceil(math.sqrt(bend / (8.0 * CURVE_TOLERANCE))))
            t = np.arange(1, k + 1)[:, None] / k
            current.extend((1 - t) ** 2 * p0 + 2 * (1 - t) * t * p1 + t ** 2 * p2)
            i += 2
        elif code == MplPath.CLOSEPOLY:
            if len(current) > 2:
                contours.append(current)
            current = []
            i += 1
        else:  # CURVE4: TrueType outlines have none; a chord keeps the contour closed
            current.append(vertices[i + 2])
            i += 3
    if len(current) > 2:
        contours.append(current)
    rings = []
    for contour in contours:
        ring = np.asarray(contour, dtype=np.float64)
        if np.allclose(ring[0], ring[-1]):
            ring = ring[:-1]
        keep = np.ones(len(ring), dtype=bool)  # drop repeated points (a curve ending on its start)
        keep[1:] = np.any(np.abs(np.diff(ring, axis=0)) > 1e-12, axis=1)
        ring = ring[keep]
        if len(ring) >= 3:
            rings.append(ring)
    if not rings:
        return ()
    every = np.vstack(rings)
    centre = 0.5 * (every.min(axis=0) + every.max(axis=0))
    out = []
    for ring in rings:
        ring = np.round(ring - centre, 9)  # stable bytes whatever the platform's last bit
        ring.setflags(write=False)
        out.append(ring)
    return tuple(out)


def text_outlines(text: str, height_mm: float) -> list[np.ndarray]:
    """Closed polygons (each (n, 2), first point not repeated) of ``text`` at cap height ``height_mm``,
    centred on the origin (the centre of the text's box), in mm."""
    return [ring * float(height_mm) for ring in _unit_outlines(text)]


def text_box(text: str) -> tuple[float, float]:
    """Width and height of the text's box at cap height 1 (descenders included)."""
    rings = _unit_outlines(text)
    if not rings:
        return 0.0, 0.0
    every = np.vstack(rings)
    w, h = np.ptp(every, axis=0)
    return float(w), float(h)


@dataclass(frozen=True)
class Label:
    """A label placed in a part's own coordinates.

    Attributes
    ----------
    text : str
    kind : str
        ``"name"`` (the part's name) or ``"number"`` (its part number, the report keys it).
    height_mm : float
        Cap height.
    centre : (2,) array
        Centre of the text's box (part coordinates, mm).
    angle : float
        Direction of the baseline (rad), in (-pi/2, pi/2] so the text never reads upside down.
    """

    text: str
    kind: str
    height_mm: float
    centre: np.ndarray = field(repr=False)
    angle: float

    def polygons(self) -> list[np.ndarray]:
        """The glyph outlines in part coordinates (closed polygons, mm)."""
        turn = rotation(self.angle).T
        return [ring @ turn + self.centre for ring in text_outlines(self.text, self.height_mm)]


def label_region(part: Part, margin_mm: float) -> Any:
    """Where a label may go: the part less its holes and slots, shrunk by ``margin_mm`` (a shapely geometry,
    possibly empty)."""
    region = shapely.Polygon(part.outline.polygon(0.05))
    if not region.is_valid:
        region = shapely.make_valid(region)
    cuts = [shapely.Point(h.centre).buffer(h.diameter_mm / 2.0, 32) for h in part.holes]
    cuts += [shapely.Polygon(s.polygon(0.05)) for s in getattr(part, "slots", ())]
    if cuts:
        region = region.difference(shapely.union_all(cuts))
    return region.buffer(-margin_mm, join_style="mitre") if margin_mm > 0 else region


def _segments(region: Any) -> np.ndarray:
    """Every boundary segment of a shapely (multi)polygon, (m, 2, 2)."""
    rings = []
    for poly in getattr(region, "geoms", [region]):
        if poly.geom_type != "Polygon" or poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            xy = np.asarray(ring.coords, dtype=np.float64)
            rings.append(np.stack([xy[:-1], xy[1:]], axis=1))
    return np.concatenate(rings) if rings else np.empty((0, 2, 2))


def _box_room(centres: np.ndarray, segments: np.ndarray, half_w: float, half_h: float) -> np.ndarray:
    """For each centre, the largest scale s for which the box of half-extents (s half_w, s half_h) about it
    meets no boundary segment: the Chebyshev distance to the boundary in coordinates scaled by the box.

    max(|x(t)|, |y(t)|) along a segment is convex and piecewise linear in t, so its minimum is at an end or
    where |x| = |y|: four candidates per segment, evaluated for every centre at once.
    """
    out = np.empty(len(centres))
    # segment ends in box units: x and y apart (a trailing axis of 2 is slow to reduce)
    sx, sy = segments[:, 0, 0] / half_w, segments[:, 0, 1] / half_h
    dx, dy = segments[:, 1, 0] / half_w - sx, segments[:, 1, 1] / half_h - sy
    cx, cy = centres[:, 0] / half_w, centres[:, 1] / half_h
    # where x(t) = y(t) and x(t) = -y(t): t = -(x0 - y0) / (dx - dy), t = -(x0 + y0) / (dx + dy); a segment
    # along that diagonal (|den| <= 1e-15) has no such point: dividing by infinity makes its t zero, its start
    dens = [np.where(np.abs(den) > 1e-15, den, np.inf) for den in (dx - dy, dx + dy)]
    for start in range(0, len(centres), 64):  # bounded memory: 64 centres x every segment at a time
        ax = sx[None, :] - cx[start:start + 64, None]
        ay = sy[None, :] - cy[start:start + 64, None]
        # the ends, then the two diagonal points (in place: the same operations, fewer arrays)
        best = np.minimum(np.maximum(np.abs(ax), np.abs(ay)), np.maximum(np.abs(ax + dx), np.abs(ay + dy)))
        t, x, y = np.empty_like(ax), np.empty_like(ax), np.empty_like(ax)
        for diagonal, den in enumerate(dens):
            if diagonal == 0:
                np.subtract(ay, ax, out=t)  # -(x0 - y0)
            else:
                np.negative(np.add(ax, ay, out=t), out=t)  # -(x0 + y0)
            np.minimum(np.maximum(np.divide(t, den, out=t), 0.0, out=t), 1.0, out=t)
            np.abs(np.add(np.multiply(t, dx, out=x), ax, out=x), out=x)
            np.abs(np.add(np.multiply(t, dy, out=y), ay, out=y), out=y)
            np.minimum(best, np.maximum(x, y, out=x), out=best)
        out[start:start + 64] = best.min(axis=1)
    return out


def fit_label(region: Any, text: str, kind: str = "name", max_height_mm: float = MAX_LABEL_MM) -> Label | None:
    """The largest ``text`` whose box lies inside ``region``, level or along the region's length.

    Parameters
    ----------
    region : shapely geometry
        From :func:`label_region`.
    text : str
    kind : str
        Stored on the :class:`Label`.
    max_height_mm : float
        Cap height never exceeded.

    Returns
    -------
    Label or None
        None when the region is empty or the text is.
    """
    width, height = text_box(text)
    if region.is_empty or width <= 0.0 or region.area <= 0.0:
        return None
    segments = _segments(region)
    # the long axis of the region's smallest rectangle: a link's label runs along the link
    rect = np.asarray(shapely.minimum_rotated_rectangle(region).exterior.coords)[:4]
    sides = np.diff(np.vstack([rect, rect[:1]]), axis=0)
    long_side = sides[int(np.argmax(np.hypot(sides[:, 0], sides[:, 1])))]
    along = math.atan2(float(long_side[1]), float(long_side[0]))
    along = (along + math.pi / 2.0) % math.pi - math.pi / 2.0  # read left to right, never upside down
    if along <= -math.pi / 2.0 + 1e-12:
        along += math.pi
    along = round(along, 9)
    angles = [0.0] if abs(along) < 1e-6 else [0.0, along]
    best: tuple[float, np.ndarray, float] | None = None  # (score, centre, angle)
    pole = polylabel(region if region.geom_type == "Polygon" else max(region.geoms, key=lambda g: g.area),
                     tolerance=0.05)
    for rank, angle in enumerate(angles):
        turn = rotation(-angle).T  # into the frame where the text runs along x
        segs = segments @ turn
        lo, hi = segs.reshape(-1, 2).min(axis=0), segs.reshape(-1, 2).max(axis=0)
        gx = lo[0] + (hi[0] - lo[0]) * (np.arange(GRID) + 0.5) / GRID
        gy = lo[1] + (hi[1] - lo[1]) * (np.arange(GRID) + 0.5) / GRID
        grid = np.stack(np.meshgrid(gx, gy), axis=-1).reshape(-1, 2)
        grid = np.vstack([np.array([[pole.x, pole.y]]) @ turn, grid])
        back = grid @ rotation(angle).T
        grid = grid[shapely.contains_xy(region, back[:, 0], back[:, 1])]
        if not len(grid):
            continue
        room = _box_room(grid, segs, width / 2.0, height / 2.0)
        k = int(np.argmax(room))
        centre, scale = grid[k], float(room[k])
        # refine about the best centre: a finer grid of one cell's size
        step = (hi - lo) / GRID
        fine = centre + np.stack(np.meshgrid(np.linspace(-1, 1, 9) * step[0],
                                             np.linspace(-1, 1, 9) * step[1]), axis=-1).reshape(-1, 2)
        back = fine @ rotation(angle).T
        fine = fine[shapely.contains_xy(region, back[:, 0], back[:, 1])]
        if len(fine):
            room_fine = _box_room(fine, segs, width / 2.0, height / 2.0)
            j = int(np.argmax(room_fine))
            if room_fine[j] > scale:
                centre, scale = fine[j], float(room_fine[j])
        # a level label wins unless the one along the part is 5 % taller (levels read more easily)
        score = scale * (1.0 if rank == 0 else 1.0 / 1.05)
        if best is None or score > best[0]:
            best = (score, centre @ rotation(angle).T, angle)
    if best is None:
        return None
    _, centre, angle = best
    unit = rotation(-angle).T
    scale = float(_box_room((centre @ unit)[None, :], segments @ unit, width / 2.0, height / 2.0)[0])
    # 0.1 % below the room: the box may touch nothing; rounded down to 1 µm for stable bytes
    cap = math.floor(min(max_height_mm, 0.999 * scale) * 1000.0) / 1000.0
    return Label(text=text, kind=kind, height_mm=cap, centre=np.round(centre, 6), angle=angle)


@dataclass(frozen=True)
class PartLabel:
    """What a part is labelled with, for the cut files and the report.

    Attributes
    ----------
    part : str
    number : str
        Its part number (the report's key from number to name).
    label : Label or None
        The engraved label, None when neither the name nor the number fits at ``min_height_mm``.
    """

    part: str
    number: str
    label: Label | None

    def report(self) -> dict[str, Any]:
        """``{part, number, text, kind, height_mm}`` (text, kind and height None when left unlabelled)."""
        lab = self.label
        return {"part": self.part, "number": self.number, "text": lab.text if lab else None,
                "kind": lab.kind if lab else None, "height_mm": lab.height_mm if lab else None}


def label_part(part: Part, number: str, min_height_mm: float, margin_mm: float,
               max_height_mm: float = MAX_LABEL_MM, text: str | None = None) -> PartLabel:
    """The part's name (or ``text``) if it fits at ``min_height_mm`` or more, else its number, else nothing."""
    region = label_region(part, margin_mm)
    floor = max(float(min_height_mm), 1e-3)
    for wanted, kind in ((part.name if text is None else text, "name"), (number, "number")):
        label = fit_label(region, wanted, kind, max_height_mm)
        if label is not None and label.height_mm >= floor:
            return PartLabel(part.name, number, label)
    return PartLabel(part.name, number, None)


def label_parts(parts: Sequence[Part], min_height_mm: float, margin_mm: float) -> dict[str, PartLabel]:
    """Every part's label, numbered 1, 2... in the order given (the part set's order)."""
    return {part.name: label_part(part, str(k), min_height_mm, margin_mm) for k, part in enumerate(parts, start=1)}


def cut_markdown(cut: Mapping[str, Any]) -> list[str]:
    """report.md's laser section from report.json's ``cut``: the sheets with their stock and utilisation, then
    the key from part number to part with what is engraved on each, and the parts left unlabelled."""
    out = ["## Laser sheets and labels", ""]
    sheets = cut.get("sheets", [])
    if sheets:
        out += ["| sheet | stock | size mm | parts | part area mm² | utilisation |", "|---|---|---|---|---|---|"]
        out += [f"| [{s['file']}]({s['file']}) | {s['stock']} | {s['size_mm'][0]:g} × {s['size_mm'][1]:g} | "
                f"{len(s['parts'])} | {s['part_area_mm2']:g} | {100.0 * s['utilisation']:.1f} % |" for s in sheets]
        if cut.get("utilisation") is not None:
            out += ["", f"Overall utilisation {100.0 * cut['utilisation']:.1f} % (part area / sheet area)."]
        out += [""]
    labels = cut.get("labels", [])
    if labels:
        out += ["Every part is engraved with its name, or with its number where the name does not fit:", ""]
        out += ["| no. | part | engraved |", "|---|---|---|"]
        for row in labels:
            if row["text"] is None:
                what = "**nothing** (no room even for the number)"
            else:
                what = f"{row['kind']} \"{row['text']}\" ({row['height_mm']:g} mm)"
            out.append(f"| {row['number']} | {row['part']} | {what} |")
        out += [""]
    if cut.get("unlabelled"):
        out += [f"Not labelled (too small for even a number): {', '.join(cut['unlabelled'])}.", ""]
    return out
