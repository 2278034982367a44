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
from ezdxf import bbox
from ezdxf import path as dxf_path

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


PONOKO = (("P1", 181.0, 181.0), ("P2", 384.0, 384.0), ("P3", 790.0, 384.0))


def test_each_sheet_is_the_smallest_standard_sheet_that_holds_its_parts():
    from fabricate.export.dxf import sized_sheets
    from fabricate.export.layout import fits

    few = [bar(f"l{k}", length=60.0, width=10.0) for k in range(3)]
    placements, sheets = sized_sheets(few, 0.2, PONOKO, (790.0, 384.0), 5.0, 3.0)
    assert [(s.name, s.size_mm) for s in sheets] == [("P1", (181.0, 181.0))]
    assert all(fits(pl, (181.0, 181.0), 5.0) for pl in placements)
    assert sheets[0].part_area_mm2 == pytest.approx(sum(p.area_mm2() for p in few))
    assert sheets[0].utilisation == pytest.approx(sheets[0].part_area_mm2 / 181.0 ** 2)
    # 40 bars 70 mm long do not fit a P1 (their area alone is larger), they do a P2
    many = [bar(f"l{k}", length=70.0, width=10.0) for k in range(40)]
    assert sum(p.area_mm2() for p in many) > 171.0 ** 2
    _, sheets = sized_sheets(many, 0.2, PONOKO, (790.0, 384.0), 5.0, 3.0)
    assert [s.name for s in sheets] == ["P2"] and sheets[0].parts == tuple(p.name for p in many)
    # more than the largest holds: full largest sheets, the rest on the smallest that holds it
    lots = [bar(f"l{k}", length=300.0, width=40.0) for k in range(13)]
    placements, sheets = sized_sheets(lots, 0.2, PONOKO, (790.0, 384.0), 5.0, 3.0)
    assert [s.name for s in sheets][:-1] == ["P3"] * (len(sheets) - 1) and sheets[-1].name in ("P2", "P3")
    assert sum(len(s.parts) for s in sheets) == len(lots)
    for pl in placements:
        assert fits(pl, sheets[pl.sheet].size_mm, 5.0)
    # a stock larger than the bed is never used; with none, the bed is the sheet
    _, sheets = sized_sheets(few, 0.2, (("huge", 2000.0, 2000.0),), (600.0, 400.0), 5.0, 3.0)
    assert [(s.name, s.size_mm) for s in sheets] == [("bed", (600.0, 400.0))]


def assert_shop_ready(out, report, process) -> None:
    """A laser build's folder as a shop gets it (called on every shipped template's ``--process laser`` build by
    tests/test_process_override.py): no text anywhere, nothing on CUT but part contours, none repeated or
    touching, every part labelled (name or number, matching the report) or listed unlabelled, and each sheet the
    stock it names, holding its parts, its utilisation their area over its own."""
    cut = report["cut"]
    labels = {row["part"]: row for row in cut["labels"]}
    assert sorted(labels) == sorted(p["name"] for p in report["parts"])
    assert sorted(cut["unlabelled"]) == sorted(n for n, row in labels.items() if row["text"] is None)
    assert len({row["number"] for row in labels.values()}) == len(labels)  # the key is one-to-one
    stock = {name: (w, h) for name, w, h in process.sheets}
    files = [f for f in report["files"] if f.startswith("cut/")]
    for rel in files:
        data = (out / rel).read_bytes()
        if rel.endswith(".svg"):
            assert b"<text" not in data, rel
            continue
        assert cut_file_problems(data) == [], rel
        msp = _read(data)
        if rel.startswith("cut/sheet_"):
            continue
        row = labels[rel[len("cut/"):-len(".dxf")]]
        engraved = msp.query('LWPOLYLINE[layer=="ENGRAVE"]')
        assert bool(engraved) == (row["text"] is not None), rel
        if row["text"] is not None:  # the outline is the text the report names, inside the part
            outline = max((shapely.Polygon([(v.x, v.y) for v in dxf_path.make_path(e).flattening(0.01)])
                           for e in msp.query('LWPOLYLINE[layer=="CUT"]')), key=lambda g: g.area)
            assert all(outline.contains(shapely.Polygon(np.array(e.get_points("xy")))) for e in engraved), rel
            svg = (out / rel.replace(".dxf", ".svg")).read_text()
            assert f"<title>{row['text']}</title></path>" in svg, rel
    areas = {p["name"]: p["area_mm2"] for p in report["parts"]}
    for sheet in cut["sheets"]:
        w, h = sheet["size_mm"]
        assert sorted((w, h)) == sorted(stock[sheet["stock"]]) if stock else sheet["stock"] == "bed"
        assert sheet["part_area_mm2"] == pytest.approx(sum(areas[n] for n in sheet["parts"]), abs=0.01)
        assert sheet["utilisation"] == pytest.approx(sheet["part_area_mm2"] / (w * h), abs=1e-4)
        msp = _read((out / sheet["file"]).read_bytes())
        box = bbox.extents(msp.query('*[layer=="CUT"]'))
        assert min(box.extmin.x, box.extmin.y) >= 0.0 and box.extmax.x <= w and box.extmax.y <= h, sheet["file"]
    assert report["interference"]["shop"]["parts_checked"] == len(report["parts"])



def _box_room_reference(centres, segments, half_w, half_h):
    """``_box_room`` written plainly, one centre at a time: the ends and the two diagonal points of each segment."""
    out = []
    for cx, cy in centres:
        best = np.inf
        for (x0, y0), (x1, y1) in segments:
            ax, ay = x0 / half_w - cx / half_w, y0 / half_h - cy / half_h
            dx, dy = x1 / half_w - x0 / half_w, y1 / half_h - y0 / half_h
            best = min(best, max(abs(ax), abs(ay)), max(abs(ax + dx), abs(ay + dy)))
            for sign in (1.0, -1.0):
                den = dx - sign * dy
                t = min(max(-(ax - sign * ay) / den, 0.0), 1.0) if abs(den) > 1e-15 else 0.0
                best = min(best, max(abs(ax + t * dx), abs(ay + t * dy)))
        out.append(best)
    return np.array(out)


def test_box_room_is_the_plain_computation_to_the_last_bit():
    """The in-place array arithmetic gives the very floats of the plain computation (a label's height and place
    are rounded from them into the cut files), segments along either diagonal of the box and centres on a
    segment's end included, for more than one chunk of 64 centres."""
    from fabricate.export.labels import _box_room

    rng = np.random.default_rng(7)
    segments = rng.normal(size=(40, 2, 2)) * 12.0
    segments[::4, 1] = segments[::4, 0] + np.array([2.0, 1.0])  # along the box's diagonal (half_w = 2 half_h)
    segments[1::4, 1] = segments[1::4, 0] + np.array([-2.0, 1.0])  # along the other one
    segments[2::4, 1, 1] = segments[2::4, 0, 1]  # level
    centres = np.vstack([rng.normal(size=(90, 2)) * 10.0, segments[:5, 0]])
    room = _box_room(centres, segments, 2.0, 1.0)
    assert np.array_equal(room, _box_room_reference(centres, segments, 2.0, 1.0))
    assert np.all(room[-5:] == 0.0) and np.all(room[:-5] > 0.0)
