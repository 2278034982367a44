"""Labels as outlines (fabricate.export.labels): glyph polygons from matplotlib's own font, sized to fit inside
the part less its holes with a margin, the part number where the name does not fit, none where nothing fits;
cut files carry them as closed bulge-free polylines / paths and never as text."""

from __future__ import annotations

import dataclasses
import io

import ezdxf
import numpy as np
import pytest
import shapely

from fabricate.export.dxf import DxfStyle, cut_file_problems, part_dxf, sheet_dxf, sheet_layout
from fabricate.export.labels import (
    Label,
    cut_markdown,
    fit_label,
    label_part,
    label_parts,
    label_region,
    text_box,
    text_outlines,
)
from fabricate.export.svg import part_svg
from fabricate.parts.model import BulgePath, Hole, Part

CUTTING = DxfStyle(min_text_mm=2.0, labels="outlines", label_margin_mm=0.5)


def bar(name: str = "link_long", length: float = 60.0, width: float = 10.0, hole: float = 3.2) -> Part:
    """A stadium link along x with a hole at each end (its area and room are known)."""
    r = width / 2.0
    outline = BulgePath(np.array([[0.0, -r], [length, -r], [length, r], [0.0, r]]),
                        np.array([0.0, 1.0, 0.0, 1.0]))
    holes = (Hole("A", np.array([0.0, 0.0]), hole), Hole("B", np.array([length, 0.0]), hole))
    return Part(name=name, body=name, outline=outline, holes=holes, thickness_mm=3.0, z_mm=0.0, layer=0,
                process="laser")


def turned(part: Part, angle: float) -> Part:
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    return dataclasses.replace(part, outline=BulgePath(part.outline.vertices @ rot.T, part.outline.bulges),
                               holes=tuple(dataclasses.replace(h, centre=np.asarray(h.centre) @ rot.T)
                                           for h in part.holes))


def test_outlines_are_closed_polygons_of_the_asked_cap_height_centred_and_repeatable():
    rings = text_outlines("H", 4.0)
    assert len(rings) == 1 and len(rings[0]) == 12  # the H is one closed 12-gon
    every = np.vstack(rings)
    assert np.ptp(every[:, 1]) == pytest.approx(4.0, abs=1e-6)  # cap height
    np.testing.assert_allclose(every.min(axis=0) + every.max(axis=0), 0.0, atol=1e-6)  # centred
    assert all(shapely.Polygon(r).is_valid for r in text_outlines("proximal_a8", 3.0))
    # the o of "o" is a ring: an outer contour and its counter
    assert len(text_outlines("o", 3.0)) == 2
    # equal text, equal polygons (the font ships inside matplotlib)
    again = text_outlines("proximal_a8", 3.0)
    assert all(np.array_equal(a, b) for a, b in zip(text_outlines("proximal_a8", 3.0), again, strict=True))
    w1, h1 = text_box("ab")
    w2, _ = text_box("abab")
    assert w2 > 1.9 * w1 and h1 > 1.0  # width grows with the text, descender-free box taller than cap height
    assert text_outlines("", 3.0) == [] and text_outlines("  ", 3.0) == []


def test_a_label_fits_inside_the_part_less_its_holes_with_its_margin():
    part = bar()
    margin = 0.5
    label = label_part(part, "1", 2.0, margin).label
    assert label is not None and label.kind == "name" and label.text == part.name
    region = label_region(part, margin)
    for ring in label.polygons():
        assert region.contains(shapely.Polygon(ring))
    # tall enough to read, and not taller than the bar's room allows (10 mm bar less two margins)
    assert 2.0 <= label.height_mm <= 10.0 - 2 * margin
    # the box of the label grown by 1 % would leave the region: it is as large as the room allows (or the cap)
    grown = Label(label.text, label.kind, label.height_mm * 1.01, label.centre, label.angle)
    assert label.height_mm == 5.0 or not all(region.contains(shapely.Polygon(r)) for r in grown.polygons())


def test_a_label_runs_along_a_turned_link():
    angle = np.radians(35.0)
    label = label_part(turned(bar(), angle), "1", 2.0, 0.5).label
    level = label_part(bar(), "1", 2.0, 0.5).label
    assert label is not None and label.angle == pytest.approx(angle, abs=np.radians(1.0))
    assert label.height_mm == pytest.approx(level.height_mm, rel=0.05)


def test_the_number_stands_in_where_the_name_does_not_fit_and_nothing_where_neither_does():
    short = bar("a_rather_long_part_name", length=14.0, width=9.0)
    got = label_part(short, "7", 2.0, 0.5)
    assert got.label is not None and (got.label.kind, got.label.text) == ("number", "7")
    tiny = bar("tiny", length=1.0, width=4.5, hole=1.0)
    none = label_part(tiny, "8", 2.0, 0.5)
    assert none.label is None and none.report() == {"part": "tiny", "number": "8", "text": None, "kind": None,
                                                    "height_mm": None}
    labels = label_parts([bar(), short, tiny], 2.0, 0.5)
    assert [(k, v.number) for k, v in labels.items()] == [("link_long", "1"), ("a_rather_long_part_name", "2"),
                                                          ("tiny", "3")]
    lines = "\n".join(cut_markdown({"sheets": [], "labels": [v.report() for v in labels.values()],
                                    "unlabelled": ["tiny"]}))
    assert '| 2 | a_rather_long_part_name | number "2"' in lines and "tiny" in lines.split("Not labelled")[1]


def test_an_empty_region_or_text_gives_no_label():
    assert fit_label(shapely.Polygon(), "a") is None
    assert fit_label(shapely.box(0, 0, 10, 10), "") is None


def _read(data: bytes):
    return ezdxf.read(io.StringIO(data.decode("utf-8"))).modelspace()


def test_cut_dxf_and_svg_engrave_outlines_never_text():
    part = bar()
    label = label_part(part, "1", 2.0, 0.5).label
    msp = _read(part_dxf(part, 0.2, CUTTING, label=label))
    assert not msp.query("TEXT MTEXT")
    engraved = msp.query('LWPOLYLINE[layer=="ENGRAVE"]')
    assert len(engraved) == len(label.polygons())
    assert all(e.closed and not any(b for *_, b in e.get_points("xyb")) for e in engraved)  # bulge-free
    assert cut_file_problems(part_dxf(part, 0.2, CUTTING, label=label)) == []
    # the engraving is the label's outline, where the label is
    got = np.vstack([np.array(e.get_points("xy")) for e in engraved])
    np.testing.assert_allclose(got, np.vstack(label.polygons()), atol=1e-9)
    svg = part_svg(part, 0.2, min_text_mm=2.0, label=label).decode()
    assert "<text" not in svg and f"<title>{part.name}</title></path>" in svg
    # "" engraves nothing; the drawing style keeps its TEXT
    assert not _read(part_dxf(part, 0.2, CUTTING, label="")).query('*[layer=="ENGRAVE"]')
    assert len(_read(part_dxf(part, 0.0)).query("TEXT")) == 1


def test_a_sheet_is_its_parts_and_nothing_else():
    parts = [bar("a"), bar("b"), bar("c")]
    layout = sheet_layout(parts, 0.2, (181.0, 181.0), 5.0, 3.0)
    data = sheet_dxf(parts, 0.2, layout, (181.0, 181.0), 0, CUTTING)
    msp = _read(data)
    assert {e.dxf.layer for e in msp} == {"CUT", "ENGRAVE"}
    assert len(msp.query('LWPOLYLINE[layer=="CUT"]')) == 3 and len(msp.query("CIRCLE")) == 6
    assert cut_file_problems(data) == []


def test_cut_file_problems_names_text_borders_open_paths_and_repeated_lines():
    doc = ezdxf.new("R2010")
    doc.units = ezdxf.units.MM
    for name in ("CUT", "ENGRAVE", "SHEET"):
        doc.layers.add(name)
    msp = doc.modelspace()
    msp.add_text("x", dxfattribs={"layer": "ENGRAVE"})
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 100), (0, 100)], close=True, dxfattribs={"layer": "SHEET"})
    msp.add_lwpolyline([(0, 0), (10, 0), (10, 10)], close=False, dxfattribs={"layer": "CUT"})
    msp.add_circle((50, 50), 5, dxfattribs={"layer": "CUT"})
    msp.add_circle((50, 50), 5, dxfattribs={"layer": "CUT"})  # the same hole twice
    msp.add_line((0, 0), (1, 1), dxfattribs={"layer": "CUT"})
    stream = io.StringIO()
    doc.write(stream)
    problems = "\n".join(cut_file_problems(stream.getvalue().encode()))
    assert "TEXT on ENGRAVE" in problems and "LWPOLYLINE on SHEET" in problems
    assert "an open path" in problems and "LINE on CUT: not a closed contour" in problems
    assert "CIRCLE on CUT and CIRCLE on CUT touch, cross or repeat" in problems
