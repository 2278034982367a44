"""Flat layouts of parts: the SLA print plate and the laser sheet nesting.

Each part is turned in its plane to its smallest bounding rectangle (tried in 1° steps over its convex
hull), then rectangles are packed in shelves (tallest first) inside the usable area. Rectangles never
overlap, so the parts inside them do not either; parts that do not fit go to further plates/sheets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

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
        pts = pts[ConvexHull(pts).vertices]  # the box of the hull is the box of the part
    angles = math.pi * np.arange(steps) / steps
    c, s = np.cos(angles), np.sin(angles)
    x = pts[None, :, 0] * c[:, None] - pts[None, :, 1] * s[:, None]
    y = pts[None, :, 0] * s[:, None] + pts[None, :, 1] * c[:, None]
    w, h = np.ptp(x, axis=1), np.ptp(y, axis=1)
    area = np.round(w * h, 6) + np.where(w + 1e-9 < h, 1e-3, 0.0)  # prefer lying down
    return float(angles[int(np.argmin(area))])  # first minimum: ties go to the smaller angle


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
    """
    width, height = area_mm
    boxes = []
    for pts in outlines:
        angle = best_angle(pts)
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


def fits(placement: Placement, area_mm: tuple[float, float], margin_mm: float) -> bool:
    """Whether a placed part lies inside the usable area of its sheet."""
    return bool(placement.size[0] <= area_mm[0] - 2 * margin_mm + 1e-9
                and placement.size[1] <= area_mm[1] - 2 * margin_mm + 1e-9)
