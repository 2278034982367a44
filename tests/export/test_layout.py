"""Plate layout: the turn that fits (a quarter turn, across the diagonal, or none), and MaxRects packing that
keeps every part inside the usable area, apart by the spacing, on fewer plates than shelves where shelves
leave room beside tall parts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fabricate.export.layout import fits, fitting_angle, pack, shelf_pack
from fabricate.planar import rotation


def rect(w: float, h: float, angle_deg: float = 0.0) -> np.ndarray:
    """A w x h rectangle's corners, turned by angle_deg about its centre."""
    corners = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
    return corners @ rotation(math.radians(angle_deg)).T


def box_at(points: np.ndarray, angle: float) -> tuple[float, float]:
    q = points @ rotation(angle).T
    return tuple(np.ptp(q, axis=0))


def test_fitting_angle_keeps_a_box_that_fits():
    """A 100 x 50 rectangle turned 30 deg: its smallest box (100, 50) fits 130 x 80 as it is."""
    pts = rect(100, 50, 30)
    w, h = box_at(pts, fitting_angle(pts, 130, 80))
    assert (w, h) == (pytest.approx(100, abs=1e-9), pytest.approx(50, abs=1e-9))


def test_fitting_angle_turns_a_quarter_when_only_that_fits():
    """A 70 x 120 (tall) rectangle in a 130 x 80 area: only lying across fits."""
    pts = rect(120, 70, 90)
    w, h = box_at(pts, fitting_angle(pts, 130, 80))
    assert w <= 130 + 1e-9 and h <= 80 + 1e-9 and w == pytest.approx(120, abs=1e-9)


def test_fitting_angle_finds_the_diagonal():
    """A 135 x 10 rectangle is longer than the 130 x 80 area but fits across it (diagonal 152.6 mm);
    a 160 x 10 one does not fit at any turn."""
    pts = rect(135, 10)
    angle = fitting_angle(pts, 130, 80)
    assert angle is not None
    w, h = box_at(pts, angle)
    assert w <= 130 + 1e-9 and h <= 80 + 1e-9
    assert fitting_angle(rect(160, 10), 130, 80) is None


def _check_layout(outlines, placements, area, margin, spacing):
    """Every placed part inside the usable area, and the boxes of two parts on one plate at least the spacing
    apart (their placed points, not just the boxes the packer believes)."""
    boxes = []
    for pts, pl in zip(outlines, placements, strict=True):
        placed = pl.apply(pts)
        lo, hi = placed.min(axis=0), placed.max(axis=0)
        assert fits(pl, area, margin)
        assert np.all(lo >= margin - 1e-9) and np.all(hi <= np.array(area) - margin + 1e-9)
        assert np.allclose(hi - lo, pl.size, atol=1e-9)
        boxes.append((pl.sheet, lo, hi))
    for k, (sa, la, ha) in enumerate(boxes):
        for sb, lb, hb in boxes[k + 1:]:
            if sa == sb:
                gap = np.maximum(lb - ha, la - hb)
                assert np.max(gap) >= spacing - 1e-9


def test_pack_fills_beside_a_tall_part_where_shelves_cannot():
    """130 x 80 plate, margin = spacing = 4 (usable 122 x 72): a 60 x 72 block and three 50 x 20 bars. The
    block's shelf is 72 mm tall and holds one bar beside it (x 68..118); the next shelf would start at y 80:
    a second plate. MaxRects stacks the three bars beside the block (3 x 20 + 2 x 4 = 68 <= 72): one plate."""
    outlines = [rect(60, 72)] + [rect(50, 20)] * 3
    area, margin = (130.0, 80.0), 4.0
    packed = pack(outlines, area, margin, margin)
    shelved = shelf_pack(outlines, area, margin, margin)
    _check_layout(outlines, packed, area, margin, margin)
    _check_layout(outlines, shelved, area, margin, margin)
    assert len({p.sheet for p in packed}) == 1 < len({p.sheet for p in shelved}) == 2


def test_pack_places_a_part_that_fits_only_across_the_diagonal():
    outlines = [rect(135, 10), rect(20, 20)]
    area = (130.0, 80.0)
    packed = pack(outlines, area, 0.0, 2.0)
    _check_layout(outlines, packed, area, 0.0, 2.0)


def test_pack_gives_a_part_too_large_a_plate_of_its_own_and_reports_it():
    outlines = [rect(200, 10), rect(20, 20)]
    packed = pack(outlines, (130.0, 80.0), 4.0, 4.0)
    assert not fits(packed[0], (130.0, 80.0), 4.0) and fits(packed[1], (130.0, 80.0), 4.0)
    assert packed[0].sheet != packed[1].sheet


@pytest.mark.parametrize("seed", range(5))
def test_pack_random_parts_never_overlap(seed):
    """Random rectangles (5..60 mm sides, random turns), several plates' worth: inside and apart."""
    rng = np.random.default_rng(seed)
    outlines = [rect(*rng.uniform(5, 60, 2), rng.uniform(0, 180)) for _ in range(25)]
    area = (127.0, 80.0)
    _check_layout(outlines, pack(outlines, area, 4.0, 4.0), area, 4.0, 4.0)
