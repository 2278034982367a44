"""Flat layouts of parts: the SLA print plate and the laser sheet nesting.

Each part is turned in its plane to its smallest bounding rectangle (tried in 1° steps over its convex
hull), or to an angle whose rectangle fits the usable area (a quarter turn, or across the diagonal), then
rectangles are packed inside the usable area (the plate or sheet less its margin): densely by MaxRects
(:func:`pack`, the print plates), or in shelves, tallest first (:func:`shelf_pack`, the laser sheets).
Rectangles never overlap, so the parts inside them do not either; parts that do not fit go to further
plates/sheets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fabricate.planar import rotation


@dataclass(frozen=True)
class Placement:
    """Where a part goes on a plate or sheet.

    Attributes
    ----------
    angle : float
        Rotation applied to the part's own coordinates first (rad).
    offset : (2,) array
        Translation applied after the rotation (mm).
    sheet : int
        Plate / sheet index (0 = the first).
    size : (2,) array
        Width and height of its bounding rectangle (mm), spacing excluded.
    """

    angle: float
    offset: np.ndarray
    sheet: int
    size: np.ndarray

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Map part points (n, 2) onto the plate / sheet."""
        placed: np.ndarray = np.asarray(points, dtype=np.float64) @ rotation(self.angle).T + self.offset
        return placed


def best_angle(points: np.ndarray, steps: int = 180) -> float:
    """Rotation (rad, a multiple of 1°) in [0, pi) giving the smallest axis-aligned bounding box.

    Ties go to the smaller angle, and a wider-than-tall box is preferred (shelves fill better).
    """
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) > 3:
        from scipy.spatial import ConvexHull  # here: the STEP worker imports this package without needing it

        pts = pts[ConvexHull(pts).vertices]  # the box of the hull is the box of the part
    angles = math.pi * np.arange(steps) / steps
    c, s = np.cos(angles), np.sin(angles)
    x = pts[None, :, 0] * c[:, None] - pts[None, :, 1] * s[:, None]
    y = pts[None, :, 0] * s[:, None] + pts[None, :, 1] * c[:, None]
    w, h = np.ptp(x, axis=1), np.ptp(y, axis=1)
    area = np.round(w * h, 6) + np.where(w + 1e-9 < h, 1e-3, 0.0)  # prefer lying down
    return float(angles[int(np.argmin(area))])  # first minimum: ties go to the smaller angle


def fitting_angle(points: np.ndarray, width: float, height: float, steps: int = 720) -> float | None:
    """A rotation (rad) that puts ``points`` in a ``width`` × ``height`` box, or None when none does.

    The smallest-box angle (:func:`best_angle`) when its box fits either way round (that angle, or a quarter
    turn more); else the fitting angle of smallest box among ``steps`` equal steps over half a turn (a long
    part may fit only across the diagonal).
    """
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) > 3:
        from scipy.spatial import ConvexHull

        pts = pts[ConvexHull(pts).vertices]
    angle = best_angle(pts)
    w, h = _box(pts, angle)
    if w <= width + 1e-9 and h <= height + 1e-9:
        return angle
    if h <= width + 1e-9 and w <= height + 1e-9:
        return angle + 0.5 * math.pi
    angles = math.pi * np.arange(steps) / steps
    c, s = np.cos(angles), np.sin(angles)
    x = pts[None, :, 0] * c[:, None] - pts[None, :, 1] * s[:, None]
    y = pts[None, :, 0] * s[:, None] + pts[None, :, 1] * c[:, None]
    ws, hs = np.ptp(x, axis=1), np.ptp(y, axis=1)
    ok = np.flatnonzero((ws <= width + 1e-9) & (hs <= height + 1e-9))
    if len(ok) == 0:
        return None
    return float(angles[ok[int(np.argmin(np.round(ws[ok] * hs[ok], 6)))]])


def _box(points: np.ndarray, angle: float) -> tuple[float, float]:
    q = np.asarray(points, dtype=np.float64) @ rotation(angle).T
    w, h = np.ptp(q, axis=0)
    return float(w), float(h)


def shelf_pack(outlines: Sequence[np.ndarray], area_mm: tuple[float, float], margin_mm: float,
               spacing_mm: float) -> list[Placement]:
    """Place outlines without overlap in rectangles of ``area_mm`` (width, height).

    Parameters
    ----------
    outlines : sequence of (n, 2) arrays
        Part outlines in part coordinates (polygons), mm.
    area_mm : (float, float)
        Plate / sheet size.
    margin_mm, spacing_mm : float
        Free border and gap between parts.

    Returns
    -------
    list of Placement
        In the order of ``outlines``. A part larger than the usable area gets a sheet of its own
        (the caller reports it as not fitting).

    Each part lies at its smallest box (:func:`best_angle`), or at the turn that fits the usable area when that
    box does not (:func:`fitting_angle`). Shelves leave the room beside tall parts empty: :func:`pack` fills it.
    """
    width, height = area_mm
    usable = (width - 2 * margin_mm, height - 2 * margin_mm)
    boxes = []
    for pts in outlines:
        angle = fitting_angle(pts, *usable)  # the smallest box, unless only another turn fits
        angle = best_angle(pts) if angle is None else angle
        q = np.asarray(pts, dtype=np.float64) @ rotation(angle).T
        lo, hi = q.min(axis=0), q.max(axis=0)
        boxes.append((angle, lo, hi - lo))
    order = sorted(range(len(boxes)), key=lambda i: (-round(float(boxes[i][2][1]), 6),
                                                     -round(float(boxes[i][2][0]), 6), i))
    placements: dict[int, Placement] = {}
    sheet, x, y, shelf = 0, margin_mm, margin_mm, 0.0
    for i in order:
        angle, lo, size = boxes[i]
        if x > margin_mm and x + size[0] > width - margin_mm:
            x, y, shelf = margin_mm, y + shelf + spacing_mm, 0.0
        if y > margin_mm and y + size[1] > height - margin_mm:
            sheet, x, y, shelf = sheet + 1, margin_mm, margin_mm, 0.0
        offset = np.array([x, y]) - lo
        placements[i] = Placement(angle=angle, offset=offset, sheet=sheet, size=size.copy())
        x += size[0] + spacing_mm
        shelf = max(shelf, float(size[1]))
    return [placements[i] for i in range(len(boxes))]


def pack(outlines: Sequence[np.ndarray], area_mm: tuple[float, float], margin_mm: float,
         spacing_mm: float) -> list[Placement]:
    """Place outlines without overlap in rectangles of ``area_mm`` (width, height), densely: MaxRects.

    Each part is turned to its smallest box (:func:`best_angle`), or to an angle whose box fits the usable area
    (:func:`fitting_angle`: a quarter turn, or across the diagonal).
    Largest boxes first, each goes to the first plate/sheet that has room for it, into the free rectangle
    that leaves the shortest side over (best short side fit), either way round; placing it splits every free
    rectangle it overlaps into the largest rectangles around it (Jylänki, "A thousand ways to pack the bin",
    2010, MaxRects-BSSF). Unlike shelves, the room beside and above a tall part is used, so fewer plates.

    Parameters and result as :func:`shelf_pack`.
    """
    width, height = area_mm
    usable = (width - 2 * margin_mm, height - 2 * margin_mm)
    # each box keeps a spacing on its right and top; the bin grows by one spacing so the last box may touch
    # the usable area's edge
    bin_w, bin_h = usable[0] + spacing_mm, usable[1] + spacing_mm
    options: list[list[tuple[float, np.ndarray, np.ndarray]]] = []
    for pts in outlines:
        pts = np.asarray(pts, dtype=np.float64)
        angle = fitting_angle(pts, *usable)
        turns = [best_angle(pts)] if angle is None else [angle, angle + 0.5 * math.pi]
        choices = []
        for a in turns:
            q = pts @ rotation(a).T
            lo, hi = q.min(axis=0), q.max(axis=0)
            choices.append((a, lo, hi - lo))
        options.append(choices)
    order = sorted(range(len(options)), key=lambda i: (-round(float(np.prod(options[i][0][2])), 6),
                                                       -round(float(max(options[i][0][2])), 6), i))
    bins: list[list[tuple[float, float, float, float]]] = []  # free rectangles (x, y, w, h) of each bin
    placements: dict[int, Placement] = {}
    for i in order:
        spot: tuple[int, float, float, tuple[float, np.ndarray, np.ndarray]] | None = None
        for k, free in enumerate(bins):
            fit = _best_fit(free, options[i], spacing_mm)
            if fit is not None:
                spot = (k, *fit)
                break
        if spot is None:
            bins.append([(0.0, 0.0, bin_w, bin_h)])
            k = len(bins) - 1
            found = _best_fit(bins[k], options[i], spacing_mm)
            # a part larger than the bin at every rotation: alone on a plate/sheet of its own, at the corner
            spot = (k, *(found if found is not None else (0.0, 0.0, options[i][0])))
        k, x, y, (a, lo, size) = spot
        used = (x, y, float(size[0]) + spacing_mm, float(size[1]) + spacing_mm)
        bins[k] = _split(bins[k], used) if used[2] <= bin_w + 1e-9 and used[3] <= bin_h + 1e-9 else []
        placements[i] = Placement(angle=float(a), offset=np.array([margin_mm + x, margin_mm + y]) - lo, sheet=k,
                                  size=np.asarray(size, dtype=np.float64).copy())
    return [placements[i] for i in range(len(options))]


def _best_fit(free: list[tuple[float, float, float, float]], choices: list[tuple[float, np.ndarray, np.ndarray]],
              spacing_mm: float) -> tuple[float, float, tuple[float, np.ndarray, np.ndarray]] | None:
    """Best short side fit of any of ``choices`` (each box grown by the spacing) into the free rectangles:
    (x, y, choice), or None when none fits. Ties go to the lower, then the leftmost spot."""
    best, best_key = None, None
    for fx, fy, fw, fh in free:
        for choice in choices:
            w, h = float(choice[2][0]) + spacing_mm, float(choice[2][1]) + spacing_mm
            if w <= fw + 1e-9 and h <= fh + 1e-9:
                key = (round(min(fw - w, fh - h), 6), round(max(fw - w, fh - h), 6), round(fy, 6), round(fx, 6))
                if best_key is None or key < best_key:
                    best, best_key = (fx, fy, choice), key
    return best


def _split(free: list[tuple[float, float, float, float]],
           used: tuple[float, float, float, float]) -> list[tuple[float, float, float, float]]:
    """The free rectangles once ``used`` is taken: each one it overlaps becomes the (up to four) largest
    rectangles beside it; then none contained in another is kept."""
    ux, uy, uw, uh = used
    out = []
    for fx, fy, fw, fh in free:
        if ux >= fx + fw - 1e-9 or ux + uw <= fx + 1e-9 or uy >= fy + fh - 1e-9 or uy + uh <= fy + 1e-9:
            out.append((fx, fy, fw, fh))
            continue
        if ux > fx + 1e-9:
            out.append((fx, fy, ux - fx, fh))
        if ux + uw < fx + fw - 1e-9:
            out.append((ux + uw, fy, fx + fw - ux - uw, fh))
        if uy > fy + 1e-9:
            out.append((fx, fy, fw, uy - fy))
        if uy + uh < fy + fh - 1e-9:
            out.append((fx, uy + uh, fw, fy + fh - uy - uh))
    kept = []
    for j, r in enumerate(out):
        inside = any(k != j and o[0] <= r[0] + 1e-9 and o[1] <= r[1] + 1e-9 and r[0] + r[2] <= o[0] + o[2] + 1e-9
                     and r[1] + r[3] <= o[1] + o[3] + 1e-9 and (o != r or k < j) for k, o in enumerate(out))
        if not inside:
            kept.append(r)
    return kept


def fits(placement: Placement, area_mm: tuple[float, float], margin_mm: float) -> bool:
    """Whether a placed part lies inside the usable area of its sheet."""
    return bool(placement.size[0] <= area_mm[0] - 2 * margin_mm + 1e-9
                and placement.size[1] <= area_mm[1] - 2 * margin_mm + 1e-9)
