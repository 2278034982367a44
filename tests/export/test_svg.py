"""SVG read back with a real SVG reader (svgelements) equals the DXF geometry read back with ezdxf:
outline area, exact arcs (one SVG arc per DXF bulge), holes (centres and diameters), kerf applied alike; labels
are engraved outlines (never ``text``), on the engrave colour."""

from __future__ import annotations

import io

import ezdxf
import numpy as np
import pytest
import shapely

from fabricate.export.dxf import part_dxf, sheet_layout
from fabricate.export.svg import CUT_COLOUR, ENGRAVE_COLOUR, part_svg, sheet_svg

svgelements = pytest.importorskip("svgelements")

KERF = 0.2  # a laser kerf: outlines out, holes in by 0.1 mm in both files

pytestmark = pytest.mark.slow  # every test reads two full template builds


@pytest.fixture(scope="module", params=["finger_five_bar_ncg", "finger_underactuated"])
def parts(request, shipped_build):
    return list(shipped_build(request.param).partset.parts)


def _read_svg(data: bytes):
    """The document, its height, its cut paths, its circles and its engraved paths (the labels)."""
    svg = svgelements.SVG.parse(io.BytesIO(data), ppi=25.4)  # 1 user unit = 1 mm
    assert not any(isinstance(e, svgelements.Text) for e in svg.elements())  # a shop takes no live text
    assert b"<text" not in data
    height = float(svg.viewbox.height)
    paths = [e for e in svg.elements() if isinstance(e, svgelements.Path)]
    circles = [e for e in svg.elements() if isinstance(e, svgelements.Circle)]
    engraved = [e for e in paths if str(e.stroke).lower() == ENGRAVE_COLOUR]
    cut = [e for e in paths if str(e.stroke).lower() == CUT_COLOUR]
    assert len(cut) + len(engraved) == len(paths)
    return svg, height, cut, circles, engraved


def _svg_polygon(path, height: float, n: int = 20000) -> shapely.Polygon:
    pts = np.asarray(path.npoint(np.linspace(0.0, 1.0, n)))
    return shapely.Polygon(np.column_stack([pts[:, 0], height - pts[:, 1]]))


def _dxf_polygon(polyline) -> shapely.Polygon:
    """An LWPOLYLINE read back through ezdxf's own arc geometry (bulge_to_arc), sampled every 0.05 degree:
    exact circular arcs (ezdxf.path would go through Bézier curves, 1.8e-4 off on a half circle)."""
    from ezdxf.math import bulge_to_arc

    pts = [tuple(map(float, p)) for p in polyline.get_points("xyb")]
    ring = []
    for i, (x, y, b) in enumerate(pts):
        x1, y1, _ = pts[(i + 1) % len(pts)]
        ring.append((x, y))
        if b == 0.0:
            continue
        centre, start, end, radius = bulge_to_arc((x, y), (x1, y1), b)
        if end < start:
            end += 2.0 * np.pi
        t = np.linspace(start, end, max(3, int(np.degrees(end - start) / 0.05)))[1:-1]
        arc = np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])
        ring += [tuple(q) for q in (arc if b > 0 else arc[::-1])]  # ezdxf runs a negative bulge end->start
    return shapely.Polygon(ring)


def _read_dxf(data: bytes):
    doc = ezdxf.read(io.StringIO(data.decode()))
    msp = doc.modelspace()
    polylines = list(msp.query('LWPOLYLINE[layer=="CUT"]'))
    circles = [(np.array(c.dxf.center)[:2], 2.0 * c.dxf.radius) for c in msp.query('CIRCLE[layer=="CUT"]')]
    return polylines, circles


def test_part_svg_equals_the_part_dxf(parts):
    for part in parts:
        svg, height, svg_paths, svg_circles, _ = _read_svg(part_svg(part, KERF))
        polylines, dxf_circles = _read_dxf(part_dxf(part, KERF))
        assert len(svg_paths) == len(polylines) and len(svg_circles) == len(dxf_circles), part.name
        dxf_poly = max((_dxf_polygon(e) for e in polylines), key=lambda g: g.area)
        svg_poly = max((_svg_polygon(p, height) for p in svg_paths), key=lambda g: g.area)
        # both read back independently and sampled (0.05 degree arcs; 20000 points): 2e-5 relative
        assert svg_poly.area == pytest.approx(dxf_poly.area, rel=2e-5), part.name
        # exact arcs: one SVG arc per DXF bulge, on every path
        svg_arcs = sorted(sum(isinstance(s, svgelements.Arc) for s in p.segments()) for p in svg_paths)
        dxf_arcs = sorted(int(np.count_nonzero(np.asarray(e.get_points("b"))[:, 0])) for e in polylines)
        assert svg_arcs == dxf_arcs, part.name
        # the canvas is shifted: compare positions relative to the outline's lower-left corner
        lo_svg = np.array(svg_poly.bounds[:2])
        lo_dxf = np.array(dxf_poly.bounds[:2])
        got = sorted((round(float(c.cx) - lo_svg[0], 4), round(height - float(c.cy) - lo_svg[1], 4),
                      round(2.0 * float(c.rx), 6)) for c in svg_circles)
        want = sorted((round(float(c[0]) - lo_dxf[0], 4), round(float(c[1]) - lo_dxf[1], 4), round(d, 6))
                      for c, d in dxf_circles)
        assert np.allclose(np.array(got), np.array(want), atol=2e-3) if got else not want, part.name


def test_svg_is_in_millimetres_with_operation_colours(parts):
    data = part_svg(parts[0], KERF)
    text = data.decode()
    assert 'width="' in text and 'mm" height="' in text and "viewBox=" in text
    svg, height, paths, circles, texts = _read_svg(data)
    width_mm = float(text.split('width="')[1].split("mm")[0])
    assert float(svg.viewbox.width) == pytest.approx(width_mm)  # one user unit is one millimetre
    for element in paths + circles:
        assert str(element.stroke).lower() == CUT_COLOUR and element.fill.value is None
    assert texts and all(t.fill.value is None for t in texts)  # the label: an outline on the engrave colour


def test_small_labels_are_left_out(parts):
    from fabricate.export.dxf import DxfStyle, engraved_label

    labels = [engraved_label(p, DxfStyle(labels="outlines")) for p in parts]
    heights = [label.height_mm for label in labels if label is not None]
    cut = float(np.median(heights))
    kept = sum(len(_read_svg(part_svg(p, KERF, min_text_mm=cut))[4]) for p in parts)
    assert kept == sum(h >= cut for h in heights) and kept < len(heights)
    # a part with no room for any label (a thin spacer ring) is engraved with nothing
    assert all(not _read_svg(part_svg(p, KERF))[4] for p, label in zip(parts, labels, strict=True) if label is None)


def test_sheet_svg_holds_every_part_of_its_sheet_inside_the_sheet(parts):
    sheet_mm = (300.0, 200.0)
    placements = sheet_layout(parts, KERF, sheet_mm, 5.0, 3.0)
    for sheet in sorted({p.sheet for p in placements}):
        svg, height, paths, circles, _ = _read_svg(sheet_svg(parts, KERF, placements, sheet_mm, sheet))
        on_sheet = [part for part, pl in zip(parts, placements, strict=True) if pl.sheet == sheet]
        assert float(svg.viewbox.width) == sheet_mm[0] and height == sheet_mm[1]
        assert len(circles) == sum(len(p.holes) for p in on_sheet)
        for path in paths:
            x0, y0, x1, y1 = _svg_polygon(path, height, 2000).bounds
            assert x0 >= 0 and y0 >= 0 and x1 <= sheet_mm[0] and y1 <= sheet_mm[1]
