"""Exporters against closed forms and independent readers, on hand-made parts (no synthesis, fast).

Written to kill mutants of ``fabricate/export`` (see ``tests/benchmarks/mutation_report.md``): the cut
path's outline grows and its slot shrinks by exactly kerf / 2, holes shrink by the kerf, nested parts keep
the spacing and the margin, and an STL is the part's prism.
"""

from __future__ import annotations

import dataclasses
import io
import math

import ezdxf
import numpy as np
import pytest
import shapely
import trimesh
from ezdxf import path as dxf_path

from fabricate.export.dxf import part_dxf, sheet_layout
from fabricate.export.stl import (
    SolidCache,
    mesh_problems,
    part_stl,
    plate_layout,
    validate_stl,
)
from fabricate.parts.model import BulgePath, Hole
from fabricate.parts.partset import SlottedPart
from tests.interference_fixtures import slot_outline, slot_part

KERF = 0.2
WIDTH = 8.0  # link width
LENGTH = 30.0  # hole to hole
HOLE = 3.2  # finished hole diameter
SLOT_L, SLOT_W = 10.0, 3.0  # guide slot: centre-to-centre length and width


def stadium_area(length: float, width: float) -> float:
    return width * length + math.pi * (width / 2) ** 2


def slotted_link() -> SlottedPart:
    """A rounded link with two pin holes and a stadium slot between them."""
    slot = BulgePath(slot_outline(SLOT_L, SLOT_W).vertices + [10.0, 0.0], np.array([0.0, 1.0, 0.0, 1.0]))
    holes = (Hole("A", np.array([0.0, 0.0]), HOLE, 3.0), Hole("B", np.array([LENGTH, 0.0]), HOLE, 3.0))
    return SlottedPart("rod", "rod", slot_outline(LENGTH, WIDTH), holes, 3.0, 0.0, 0, "laser", slots=(slot,))


def read(data: bytes):
    return ezdxf.read(io.StringIO(data.decode("utf-8"))).modelspace()


def contour(entity, flatten_mm: float = 1e-4) -> shapely.Polygon:
    """ezdxf's own flattening (its arcs are cubic Beziers: within ~3e-4 r of the true arc)."""
    return shapely.Polygon([(v.x, v.y) for v in dxf_path.make_path(entity).flattening(flatten_mm)])


def exact_area(entity) -> float:
    """Area of a closed LWPOLYLINE in closed form: the vertex polygon plus, for each bulge b over a chord
    c, the circular segment R^2 / 2 (theta - sin theta) with theta = 4 atan(b), R = c / (2 sin(theta / 2))."""
    pts = np.array(entity.get_points("xyb"))
    xy, bulges = pts[:, :2], pts[:, 2]
    nxt = np.roll(xy, -1, axis=0)
    area = 0.5 * float(np.sum(xy[:, 0] * nxt[:, 1] - nxt[:, 0] * xy[:, 1]))
    for p0, p1, b in zip(xy, nxt, bulges, strict=True):
        if b != 0.0:
            theta = 4.0 * math.atan(abs(b))
            radius = math.hypot(*(p1 - p0)) / (2.0 * math.sin(theta / 2.0))
            area += math.copysign(0.5 * radius * radius * (theta - math.sin(theta)), b)
    return area


@pytest.mark.parametrize("kerf", [0.0, KERF])
def test_cut_path_is_offset_by_half_the_kerf(kerf):
    """Closed forms: the outline is a stadium of width w + kerf, the slot one of width w_slot - kerf, the
    holes circles of diameter d - kerf, all at their modelled centres (read back through ezdxf)."""
    part = slotted_link()
    msp = read(part_dxf(part, kerf))
    entities = sorted(msp.query('LWPOLYLINE[layer=="CUT"]'), key=lambda e: -abs(exact_area(e)))
    assert len(entities) == 2
    assert exact_area(entities[0]) == pytest.approx(stadium_area(LENGTH, WIDTH + kerf), rel=1e-12)
    assert abs(exact_area(entities[1])) == pytest.approx(stadium_area(SLOT_L, SLOT_W - kerf), rel=1e-12)
    outline, slot = (contour(e) for e in entities)
    assert outline.bounds == pytest.approx((-(WIDTH + kerf) / 2, -(WIDTH + kerf) / 2,
                                            LENGTH + (WIDTH + kerf) / 2, (WIDTH + kerf) / 2), abs=2e-3)
    assert slot.bounds == pytest.approx((10.0 - (SLOT_W - kerf) / 2, -(SLOT_W - kerf) / 2,
                                         10.0 + SLOT_L + (SLOT_W - kerf) / 2, (SLOT_W - kerf) / 2), abs=2e-3)
    circles = sorted(msp.query('CIRCLE[layer=="CUT"]'), key=lambda e: e.dxf.center.x)
    assert [2 * c.dxf.radius for c in circles] == pytest.approx([HOLE - kerf, HOLE - kerf], abs=1e-9)
    np.testing.assert_allclose([(c.dxf.center.x, c.dxf.center.y) for c in circles], [(0.0, 0.0), (LENGTH, 0.0)],
                               atol=1e-12)
    # the engraved label sits inside the plate, clear of the holes and the slot
    (text,) = msp.query('TEXT[layer=="ENGRAVE"]')
    spot = shapely.Point(text.dxf.align_point.x, text.dxf.align_point.y)
    plate = outline.difference(slot)
    for c in circles:
        plate = plate.difference(shapely.Point(c.dxf.center.x, c.dxf.center.y).buffer(c.dxf.radius))
    assert plate.contains(spot)
    assert 0.3 <= text.dxf.height <= 5.0


def links(n: int = 7) -> list:
    return [slot_part(f"link{k}", f"link{k}", ("A", "B"), 20.0 + 6.0 * k, width=6.0 + k, pin=3.0,
                      clearance=0.1, process="laser") for k in range(n)]


def raw_polygon(path: BulgePath, chord_mm: float = 1e-3) -> shapely.Polygon:
    """A bulge path as a polygon sampled here from its raw vertices and bulges (arcs by their closed form:
    included angle 4 atan(b), centre on the chord's bisector)."""
    pts = []
    v, b = np.asarray(path.vertices, float), np.asarray(path.bulges, float)
    for i in range(len(v)):
        p0, p1 = v[i], v[(i + 1) % len(v)]
        pts.append(p0)
        if b[i] == 0.0:
            continue
        theta = 4.0 * math.atan(b[i])
        chord = p1 - p0
        c = float(np.hypot(*chord))
        radius = c / (2.0 * math.sin(abs(theta) / 2.0))
        mid = (p0 + p1) / 2
        left = np.array([-chord[1], chord[0]]) / c
        centre = mid + left * (c / 2.0) / math.tan(theta / 2.0)
        start = math.atan2(*(p0 - centre)[::-1])
        k = max(8, math.ceil(abs(theta) / (2 * math.acos(1 - chord_mm / radius))))
        t = start + theta * np.arange(1, k) / k
        pts.extend(np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)]))
    return shapely.Polygon(np.array(pts))


@pytest.mark.parametrize(("sheet", "margin", "spacing"), [((120.0, 60.0), 5.0, 2.0), ((90.0, 50.0), 3.0, 4.0)])
def test_nested_sheets_keep_spacing_and_margin(sheet, margin, spacing):
    """Every part is placed once; on each sheet the cut outlines (the part grown by kerf / 2, computed here
    from the raw path) are at least spacing + kerf apart and at least the margin inside the sheet, less
    the 0.05 mm chord of the polygons the nesting packs."""
    parts = links()
    layout = sheet_layout(parts, KERF, sheet, margin, spacing)
    assert len(layout) == len(parts)
    border = shapely.box(0.0, 0.0, *sheet)
    by_sheet: dict[int, list] = {}
    for part, placement in zip(parts, layout, strict=True):
        cut = raw_polygon(part.outline).buffer(KERF / 2, quad_segs=64)
        placed = shapely.Polygon(placement.apply(np.asarray(cut.exterior.coords)))
        assert placed.area == pytest.approx(cut.area, rel=1e-9)  # a rigid placement
        by_sheet.setdefault(placement.sheet, []).append(placed)
    assert sorted(by_sheet) == list(range(len(by_sheet)))  # no empty sheet in between
    for polys in by_sheet.values():
        for i, a in enumerate(polys):
            assert border.contains(a) and border.exterior.distance(a) >= margin - 0.05
            for b in polys[i + 1:]:
                assert a.distance(b) >= spacing + KERF - 0.1
    # the shelves are used: not needlessly many sheets
    total = sum(raw_polygon(p.outline).area for p in parts)
    assert len(by_sheet) <= math.ceil(4 * total / (sheet[0] * sheet[1])) + 1


def test_part_stl_is_the_prism_of_the_profile():
    """Volume of the STL read back by trimesh = (stadium - holes) x thickness within the chord error,
    bottom on z = 0, top at the thickness, footprint = the stadium's extent."""
    part = slot_part("crank", "crank", ("O", "A"), 15.0, width=6.0, pin=2.0, clearance=0.25, z=7.0)
    tol = 0.002
    data = part_stl(part, SolidCache(tol))
    mesh = trimesh.load(io.BytesIO(data), file_type="stl")
    holes = 2 * math.pi * (2.5 / 2) ** 2
    exact = (stadium_area(15.0, 6.0) - holes) * 3.0
    perimeter = 2 * 15.0 + math.pi * 6.0 + 2 * math.pi * 2.5
    assert abs(mesh.volume - exact) <= tol * perimeter * 3.0
    assert mesh.volume < exact  # inscribed polygons: never more than the exact solid
    assert validate_stl(data) == []
    np.testing.assert_allclose(mesh.bounds, [[-3.0, -3.0, 0.0], [18.0, 3.0, 3.0]], atol=tol)


def test_plate_keeps_parts_apart_and_inside():
    """Placed on the build plate the parts' footprints do not overlap, keep the spacing and stay inside the
    plate; each placed mesh keeps its part's volume (rigid placement)."""
    parts = [slot_part(f"p{k}", f"p{k}", ("A", "B"), 15.0 + 5 * k, width=6.0) for k in range(5)]
    cache = SolidCache(0.005)
    area, spacing = (60.0, 40.0), 3.0
    layout = plate_layout(parts, cache, area, spacing)
    meshes = []
    for p, pl in zip(parts, layout, strict=True):
        vertices, faces = cache.flat_mesh(p)
        meshes.append((np.column_stack([pl.apply(vertices[:, :2]), vertices[:, 2]]), faces))
    by_sheet: dict[int, list] = {}
    for (vertices, _faces), pl in zip(meshes, layout, strict=True):
        footprint = shapely.MultiPoint(vertices[:, :2]).convex_hull
        assert shapely.box(0, 0, *area).contains(footprint)
        assert shapely.box(0, 0, *area).exterior.distance(footprint) >= spacing - 0.05
        by_sheet.setdefault(pl.sheet, []).append(footprint)
    for footprints in by_sheet.values():
        for i, a in enumerate(footprints):
            for b in footprints[i + 1:]:
                assert a.distance(b) >= spacing - 0.1  # boxes of polygons inscribed at a 0.05 mm chord
    for p, (vertices, faces) in zip(parts, meshes, strict=True):
        placed = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
        assert mesh_problems(placed) == []
        assert placed.volume == pytest.approx(p.volume_mm3(), rel=1e-3)


def test_kinematic_drawing_of_a_bent_four_bar():
    """The kinematic DXF at one pose: a LINKS line and an aligned dimension of the link's true length for
    each pair of joints of a body, a JOINTS circle and a label with the world coordinates at each joint, a
    linear dimension from the origin for each distinct non-zero joint coordinate; units mm; the measurements
    read back equal the closed-form lengths."""
    from fabricate.export.kinematic import kinematic_dxf
    from tests.conftest import make_four_bar

    mech = make_four_bar()
    poses = mech.sweep(5).poses_at(2)  # crank at 240 deg
    msp = read(kinematic_dxf(mech, poses))
    th = math.radians(240.0)
    a = np.array([15 * math.cos(th), 15 * math.sin(th)])
    b = np.array(transform(poses["rocker"], (30.0, 0.0)))
    world = {"O": np.zeros(2), "D": np.array([40.0, 0.0]), "A": a, "B": b}
    assert math.hypot(*(b - a)) == pytest.approx(40.0, abs=1e-9)
    lines = set()
    for e in msp.query('LINE[layer=="LINKS"]'):
        ends = ((e.dxf.start.x, e.dxf.start.y), (e.dxf.end.x, e.dxf.end.y))
        lines.add(tuple(sorted(k for end in ends for k, p in world.items() if np.allclose(p, end, atol=1e-9))))
    assert lines == {("D", "O"), ("A", "O"), ("A", "B"), ("B", "D")}
    aligned = sorted(round(d.get_measurement(), 6) for d in msp.query('DIMENSION[layer=="DIMENSIONS"]')
                     if d.dimtype in (0, 1))  # linear (ezdxf writes the aligned ones rotated)
    assert aligned == [15.0, 30.0, 40.0, 40.0]
    joints = msp.query('CIRCLE[layer=="JOINTS"]')
    assert len(joints) == 4
    for name, p in world.items():
        assert any(np.allclose((c.dxf.center.x, c.dxf.center.y), p, atol=1e-9) for c in joints), name
    labels = [t.dxf.text for t in msp.query('TEXT[layer=="LABELS"]')]
    assert f"A ({a[0]:.3f}, {a[1]:.3f})" in labels and "D (40.000, 0.000)" in labels
    coordinates = msp.query('DIMENSION[layer=="COORDINATES"]')
    assert all(d.dimtype == 0 for d in coordinates)  # linear, never ordinate (LibreCAD draws none)
    # one per distinct non-zero coordinate: x of A, D, B; y of A, B (O and D lie on y = 0)
    measured = sorted(round(d.get_measurement(), 6) for d in coordinates)
    expected = sorted({round(abs(v), 6) for p in world.values() for v in p} - {0.0})
    assert measured == pytest.approx(expected, abs=1e-6)


def transform(pose, local):
    """A body point in the world: rotate by theta, then translate (written out here)."""
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    return (x + c * local[0] - s * local[1], y + s * local[0] + c * local[1])


def test_read_dxf_reports_unreadable_input_and_cut_diameters():
    from fabricate.export.dxf import audit_problems, read_dxf

    part = slotted_link()
    problems, diameters = read_dxf(part_dxf(part, KERF))
    assert problems == [] and audit_problems(part_dxf(part, KERF)) == []
    assert diameters == pytest.approx([HOLE - KERF, HOLE - KERF], abs=1e-9)
    assert read_dxf(b"\xff\xfe not text")[0][0].startswith("not UTF-8")
    assert read_dxf(b"0\nSECTION\n2\nNONSENSE\n")[0]  # something is reported


def test_cut_files_are_metric_with_fixed_layer_colours():
    """A cut DXF is in millimetres ($INSUNITS 4, $MEASUREMENT 1 metric, $LUNITS 2 decimal), with the layer
    colours laser software keys on (CUT red 1, ENGRAVE blue 5) and no dimension styles; a sheet border layer
    is not plotted; the kinematic drawing carries the dimension styles it uses."""
    from ezdxf import units

    from fabricate.export.dxf import document_bytes, new_document
    from fabricate.export.kinematic import kinematic_dxf
    from tests.conftest import make_four_bar

    doc = ezdxf.read(io.StringIO(part_dxf(slotted_link(), KERF).decode("utf-8")))
    assert doc.units == units.MM and doc.header["$MEASUREMENT"] == 1 and doc.header["$LUNITS"] == 2
    assert doc.dxfversion == "AC1024"  # R2010
    assert doc.layers.get("CUT").color == 1 and doc.layers.get("ENGRAVE").color == 5
    assert doc.layers.get("CUT").dxf.plot == 1
    assert "EZDXF" not in {s.dxf.name.upper() for s in doc.dimstyles}
    sheet = ezdxf.read(io.StringIO(document_bytes(new_document(("CUT", "ENGRAVE", "SHEET"))).decode("utf-8")))
    assert sheet.layers.get("SHEET").dxf.plot == 0 and sheet.layers.get("SHEET").color == 8
    mech = make_four_bar()
    drawing = ezdxf.read(io.StringIO(kinematic_dxf(mech, mech.sweep(3).poses_at(0)).decode("utf-8")))
    assert "EZDXF" in {s.dxf.name.upper() for s in drawing.dimstyles}
    assert drawing.units == units.MM


def plate_region(part) -> shapely.Geometry:
    """The plate (outline less holes and slots), from the raw paths and hole records."""
    plate = raw_polygon(part.outline)
    for h in part.holes:
        plate = plate.difference(shapely.Point(h.centre).buffer(h.diameter_mm / 2, quad_segs=64))
    for s in getattr(part, "slots", ()):
        plate = plate.difference(raw_polygon(s))
    return plate


def label_of(part):
    (text,) = read(part_dxf(part, 0.0)).query('TEXT[layer=="ENGRAVE"]')
    return shapely.Point(text.dxf.align_point.x, text.dxf.align_point.y), text.dxf.height, text.dxf.text


@pytest.mark.parametrize("name", ["A", "rod", "a_much_longer_part_name"])
def test_label_sits_at_the_roomiest_spot_and_fits(name):
    """The engraved label is centred near the plate's most inward point (within 5 % of the largest inscribed
    circle found here on a 0.05 mm grid) and its text box (0.9 h per character by h) stays clear of every
    edge, hole and slot."""
    part = dataclasses.replace(slotted_link(), name=name)
    plate = plate_region(part)
    spot, height, text = label_of(part)
    assert text == name
    room = plate.boundary.distance(spot)
    assert plate.contains(spot)
    x0, y0, x1, y1 = plate.bounds
    grid = shapely.points(np.stack(np.meshgrid(np.arange(x0, x1, 0.05), np.arange(y0, y1, 0.05)), -1).reshape(-1, 2))
    inside = grid[shapely.contains(plate, grid)]
    best = float(np.max(shapely.distance(plate.boundary, inside)))
    assert room >= 0.95 * best
    half_w, half_h = 0.45 * height * len(text), 0.5 * height
    assert math.hypot(half_w, half_h) <= room + 1e-9
    assert height >= 0.3 and (height == 5.0 or height >= 0.5 * min(0.8 * room, 1.6 * room / (0.9 * len(text))))
    assert height == round(height, 3)  # millimetres to 3 decimals


def test_label_text_is_centred_capped_and_can_be_named():
    """The label is middle-centred on its spot, never taller than 5 mm however roomy the plate, and an
    explicit label (a copy number on a sheet) replaces the part name."""
    from fabricate.export.dxf import add_part, new_document

    big = SlottedPart("B", "B", slot_outline(60.0, 40.0), (), 3.0, 0.0, 0, "laser")
    spot, height, _ = label_of(big)
    assert height == 5.0
    (text,) = read(part_dxf(big, 0.0)).query('TEXT[layer=="ENGRAVE"]')
    assert (text.dxf.halign, text.dxf.valign) == (1, 2)  # MIDDLE_CENTER
    doc = new_document()
    add_part(doc.modelspace(), slotted_link(), KERF, label="rod #2")
    assert [t.dxf.text for t in doc.modelspace().query("TEXT")] == ["rod #2"]


def test_label_goes_on_the_larger_piece_or_falls_back():
    """A slot across the whole plate splits it: the label goes on the larger piece. A plate eaten by its hole
    gets the outline's vertex centroid and a 1 mm text."""
    outline = slot_outline(40.0, 8.0)
    across = BulgePath(np.array([[9.0, -6.0], [11.0, -6.0], [11.0, 6.0], [9.0, 6.0]]), np.zeros(4))
    split = SlottedPart("split", "split", outline, (), 3.0, 0.0, 0, "laser", slots=(across,))
    spot, _, _ = label_of(split)
    assert spot.x > 11.0  # the 29 mm piece, not the 9 mm one
    eaten = SlottedPart("eaten", "eaten", slot_outline(2.0, 2.0), (Hole("A", np.array([1.0, 0.0]), 10.0, 3.0),),
                        3.0, 0.0, 0, "laser")
    spot, height, _ = label_of(eaten)
    assert (spot.x, spot.y) == pytest.approx(tuple(np.mean(eaten.outline.vertices, axis=0)))
    assert height == 1.0


def test_sheet_dxf_draws_the_first_sheet_with_its_placed_parts():
    """Sheet 0 of the cut file: no border (a shop would cut it), the sheet's rectangle is the drawing's limits,
    and every part placed on it is cut where the layout put it: outline area = the stadium grown by kerf / 2
    (closed form), centred on the placed centre of the part's outline, its holes placed likewise."""
    from fabricate.export.dxf import sheet_dxf

    parts = links()
    sheet = (120.0, 60.0)
    layout = sheet_layout(parts, KERF, sheet, 5.0, 2.0)
    doc = ezdxf.read(io.StringIO(sheet_dxf(parts, KERF, layout, sheet).decode("utf-8")))
    msp = doc.modelspace()
    assert {e.dxf.layer for e in msp} == {"CUT", "ENGRAVE"} and "SHEET" not in doc.layers
    assert tuple(doc.header["$LIMMIN"])[:2] == (0.0, 0.0) and tuple(doc.header["$LIMMAX"])[:2] == sheet
    outlines = [(exact_area(e), contour(e, 1e-3).centroid) for e in msp.query('LWPOLYLINE[layer=="CUT"]')]
    circles = [(c.dxf.center.x, c.dxf.center.y, 2 * c.dxf.radius) for c in msp.query('CIRCLE[layer=="CUT"]')]
    on_first = [(p, pl) for p, pl in zip(parts, layout, strict=True) if pl.sheet == 0]
    assert on_first
    for part, placement in on_first:
        length = float(np.hypot(*part.holes[1].centre))
        width = 2 * float(np.max(np.abs(part.outline.vertices[:, 1])))
        area = stadium_area(length, width + KERF)
        centre = placement.apply(np.array([[length / 2, 0.0]]))[0]
        assert any(a == pytest.approx(area, rel=1e-9) and c.distance(shapely.Point(centre)) < 1e-3
                   for a, c in outlines), part.name
        for hole in part.holes:
            x, y = placement.apply(np.asarray(hole.centre)[None, :])[0]
            assert any(abs(cx - x) < 1e-9 and abs(cy - y) < 1e-9 and d == pytest.approx(hole.diameter_mm - KERF)
                       for cx, cy, d in circles)


def test_kinematic_drawing_rules_for_ternary_links_free_points_and_hinges():
    """Links are drawn between the joints of a body (a ternary link: all three sides), between all its points
    when it has no joint, never twice and never at zero length (a compound hinge); joints and free points
    get circles of 0.6 and 0.3 text heights; the text height is span / 60 (at least 2.5 mm), the dimension
    style sized from it."""
    from types import SimpleNamespace

    from fabricate.export.kinematic import kinematic_dxf
    from fabricate.mechanism import Body

    bodies = (Body("base", {"O": (0.0, 0.0), "D": (40.0, 0.0), "Q": (20.0, 10.0)}),
              Body("tri", {"A": (0.0, 0.0), "B": (30.0, 0.0), "C": (10.0, 15.0), "F": (30.0, 15.0),
                           "R": (5.0, 5.0)}),
              Body("pad", {"T1": (0.0, 0.0), "T2": (0.5, 0.0)}),
              Body("hinge", {"O": (0.0, 0.0), "O2": (0.0, 0.0), "E": (0.0, -20.0)}),
              Body("again", {"D": (0.0, 0.0), "O": (-40.0, 0.0)}),
              Body("hinge2", {"H1": (0.0, 0.0), "H2": (0.0, 0.0), "N": (0.0, 0.2)}))
    joints = [SimpleNamespace(name=n) for n in ("O", "D", "A", "B", "C", "F", "O2", "E", "H1", "H2")]
    poses = {"base": np.zeros(3), "tri": np.array([200.0, 0.0, 0.0]), "pad": np.array([-20.0, -30.0, 0.0]),
             "hinge": np.zeros(3), "again": np.array([40.0, 0.0, 0.0]), "hinge2": np.array([10.0, -10.0, 0.0])}
    doc = ezdxf.read(io.StringIO(kinematic_dxf(SimpleNamespace(bodies=bodies, joints=joints), poses).decode()))
    msp = doc.modelspace()
    text_h = round(250.0 / 60.0, 3)  # span: the larger extent, x from -20 to 230 (y: -30 to 15)
    lengths = sorted(round(math.hypot(e.dxf.end.x - e.dxf.start.x, e.dxf.end.y - e.dxf.start.y), 6)
                     for e in msp.query('LINE[layer=="LINKS"]'))
    # O-D once (two bodies have it), all six pairs of the quaternary link A-B-C-F (not its free point R),
    # T1-T2 (no joints: its own points), O-E and O2-E (not O-O2), nothing for H1-H2 (one spot)
    quad = (30.0, math.hypot(10, 15), math.hypot(30, 15), math.hypot(20, 15), 15.0, 20.0)  # AB AC AF BC BF CF
    assert lengths == sorted(round(v, 6) for v in (40.0, *quad, 0.5, 20.0, 20.0))
    dims = msp.query("DIMENSION")
    assert all(d.dxf.layer in ("DIMENSIONS", "COORDINATES") for d in dims)
    linear = [d for d in dims if d.dimtype in (0, 1) and d.dxf.layer == "DIMENSIONS"]
    assert sorted(round(d.get_measurement(), 6) for d in linear) == lengths
    for d in linear:  # the dimension line stands 3 text heights off the link
        p2, p3, p = (np.array([v.x, v.y]) for v in (d.dxf.defpoint2, d.dxf.defpoint3, d.dxf.defpoint))
        u = (p3 - p2) / np.hypot(*(p3 - p2))
        assert abs(u[0] * (p - p2)[1] - u[1] * (p - p2)[0]) == pytest.approx(3 * text_h, abs=1e-6)
    style = doc.dimstyles.get("FABRICATE")
    assert style.dxf.dimtxt == pytest.approx(text_h) and style.dxf.dimasz == pytest.approx(text_h)
    assert style.dxf.dimexo == pytest.approx(0.5 * text_h) and style.dxf.dimexe == pytest.approx(0.5 * text_h)
    assert style.dxf.dimgap == pytest.approx(0.3 * text_h) and style.dxf.dimtad == 1 and style.dxf.dimdec == 3
    assert {round(t.dxf.height, 6) for t in msp.query("TEXT")} == {text_h}
    radii = {(c.dxf.layer, round(c.dxf.radius, 6)) for c in msp.query("CIRCLE")}
    assert radii == {("JOINTS", round(0.6 * text_h, 6)), ("LABELS", round(0.3 * text_h, 6))}
    assert len(msp.query('CIRCLE[layer=="JOINTS"]')) == 8  # O and O2 share one spot, H1 and H2 another
    assert len(msp.query('CIRCLE[layer=="LABELS"]')) == 5  # Q, R, T1, T2, N
    labels = {t.dxf.text: t for t in msp.query('TEXT[layer=="LABELS"]')}
    assert "O, O2 (0.000, 0.000)" in labels and "H1, H2 (10.000, -10.000)" in labels
    assert "N (10.000, -9.800)" in labels  # 0.2 mm away: a spot of its own
    d_label = labels["D (40.000, 0.000)"]
    assert (d_label.dxf.halign, d_label.dxf.valign) == (0, 1)  # BOTTOM_LEFT
    assert style.dxf.dimlfac == 1.0
    assert all(d.dxf.dimstyle == "FABRICATE" for d in dims)
    for d in (d for d in dims if d.dxf.layer == "COORDINATES"):  # from the origin to a joint, along x or y
        assert tuple(d.dxf.defpoint2)[:2] == (0.0, 0.0) and d.dxf.angle in (0.0, 90.0)
        assert d.get_measurement() == pytest.approx(abs(d.dxf.defpoint3[0 if d.dxf.angle == 0.0 else 1]))
    assert {layer.dxf.name for layer in doc.layers} >= {"LINKS", "JOINTS", "DIMENSIONS", "LABELS", "COORDINATES"}


def test_segment_style_and_minimum_text():
    """A process that wants line segments gets an outline without bulges whose vertices lie on the exact
    kerf-offset stadium and whose chords stay within its tolerance; labels under its minimum height go."""
    from fabricate.export.dxf import DxfStyle, sheet_dxf

    part = slotted_link()
    style = DxfStyle(arcs="segments", chord_tolerance_mm=0.01, min_text_mm=50.0)
    msp = read(part_dxf(part, KERF, style))
    outline = max(msp.query('LWPOLYLINE[layer=="CUT"]'), key=lambda e: len(e))
    pts = np.array(outline.get_points("xyb"))
    assert not pts[:, 2].any()
    r = (WIDTH + KERF) / 2
    # distance of each vertex from the stadium's spine (the segment between the hole centres) is r
    t = np.clip(pts[:, 0] / LENGTH, 0.0, 1.0)
    np.testing.assert_allclose(np.hypot(pts[:, 0] - t * LENGTH, pts[:, 1]), r, atol=1e-9)
    assert exact_area(outline) >= stadium_area(LENGTH, WIDTH + KERF) - 2 * 0.01 * (2 * LENGTH + 2 * math.pi * r)
    assert len(msp.query("TEXT")) == 0
    layout = sheet_layout([part], KERF, (120.0, 60.0), 5.0, 2.0)
    sheet = read(sheet_dxf([part], KERF, layout, (120.0, 60.0), 0, style))
    assert not any(np.array(e.get_points("xyb"))[:, 2].any() for e in sheet.query('LWPOLYLINE[layer=="CUT"]'))
    assert len(sheet.query("TEXT")) == 0
    # a label exactly at the process minimum is kept
    (text,) = read(part_dxf(part, KERF)).query("TEXT")
    at_minimum = DxfStyle(min_text_mm=text.dxf.height)
    assert len(read(part_dxf(part, KERF, at_minimum)).query("TEXT")) == 1


def test_sheet_dxf_paths_are_closed_and_parts_match_placements():
    from fabricate.export.dxf import sheet_dxf

    parts = links(3)
    layout = sheet_layout(parts, KERF, (120.0, 60.0), 5.0, 2.0)
    msp = read(sheet_dxf(parts, KERF, layout, (120.0, 60.0)))
    assert msp.query("LWPOLYLINE") and all(e.closed for e in msp.query("LWPOLYLINE"))
    with pytest.raises(ValueError):
        sheet_dxf(parts, KERF, layout[:-1], (120.0, 60.0))


# -- STL and 3MF encoders against meshes written here ------------------------------------------------
def box_mesh(size=(2.0, 3.0, 4.0), origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """A closed box, outward (counter-clockwise seen from outside) triangles: volume = the product of sizes."""
    sx, sy, sz = size
    v = np.array([[x, y, z] for z in (0, sz) for y in (0, sy) for x in (0, sx)], dtype=float) + origin
    faces = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                      [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return v, faces


def test_stl_of_a_box_reads_back_with_its_volume_and_findings():
    """The 2 x 3 x 4 box: 12 triangles, 84 + 50 x 12 bytes, volume 24 mm^3; and each defect is named: a
    missing face (not watertight), a flipped face (inconsistent winding), all faces flipped (negative
    volume), a wrong expected volume (beyond the relative tolerance only), short or truncated bytes."""
    from fabricate.export.stl import mesh_volume, stl_bytes

    v, f = box_mesh()
    data = stl_bytes(v, f)
    assert len(data) == 84 + 50 * 12 and int.from_bytes(data[80:84], "little") == 12
    assert mesh_volume(v, f) == pytest.approx(24.0, rel=1e-12)
    assert validate_stl(data) == []
    assert validate_stl(data, 24.0 * 1.0009) == []  # within 1e-3
    assert validate_stl(data, 24.0 * 1.0011) == ["volume 24 mm^3 differs from 24.0264 mm^3"]
    assert validate_stl(data, 25.0, rel_tol=0.05) == []
    assert "not watertight" in validate_stl(stl_bytes(v, f[1:]))
    flipped = f.copy()
    flipped[0] = flipped[0, ::-1]
    assert "inconsistent winding" in validate_stl(stl_bytes(v, flipped))
    assert validate_stl(stl_bytes(v, f[:, ::-1])) == ["volume -24 mm^3 is not positive"]
    assert validate_stl(data[:83]) == ["not a binary STL (83 bytes, shorter than its 84-byte header)"]
    assert validate_stl(data[:-50]) == [f"truncated or not a binary STL: {len(data) - 50} bytes, its header "
                                        f"announces 12 triangles ({len(data)} bytes)"]
    assert validate_stl(bytes(80) + (0).to_bytes(4, "little")) == ["no triangles"]


def test_plate_stl_keeps_each_shell():
    """Two boxes in one STL: 24 triangles, the volume of both (each keeps its own vertices), the extent of
    both."""
    from fabricate.export.stl import plate_stl

    a = box_mesh()
    b = box_mesh((1.0, 1.0, 1.0), origin=(10.0, 0.0, 0.0))
    data = plate_stl([a, b])
    assert validate_stl(data, 25.0, rel_tol=1e-9) == []
    mesh = trimesh.load(io.BytesIO(data), file_type="stl")
    assert len(mesh.faces) == 24
    np.testing.assert_allclose(mesh.bounds, [[0.0, 0.0, 0.0], [11.0, 3.0, 4.0]], atol=1e-6)


def test_3mf_round_trip_names_vertices_and_findings():
    """Two named objects (one name with XML specials) come back with their names, vertices (6 decimals)
    and triangles; the bytes are deterministic; a foreign unit, a repeated name, a bad index, an unreadable
    number and a non-zip are each reported."""
    import zipfile

    from fabricate.export.stl import model_3mf, read_3mf

    box = box_mesh()
    small = box_mesh((1.0, 1.0, 1.0), origin=(0.1234567, -5.0, 2.0))
    data = model_3mf([('a&b <"x">', *box), ("small", *small)], "T & <t>")
    assert data == model_3mf([('a&b <"x">', *box), ("small", *small)], "T & <t>")
    objects, problems = read_3mf(data)
    assert problems == []
    assert list(objects) == ['a&b <"x">', "small"]
    np.testing.assert_allclose(objects["small"].vertices, small[0], atol=5e-7)
    np.testing.assert_array_equal(objects["small"].faces, small[1])
    assert objects['a&b <"x">'].volume == pytest.approx(24.0, rel=1e-12)
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        assert z.namelist() == ["[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"]
        assert all(i.date_time == (1980, 1, 1, 0, 0, 0) for i in z.infolist())
        text = z.read("3D/3dmodel.model").decode()
    assert '<metadata name="Title">T &amp; &lt;t&gt;</metadata>' in text
    assert '<item objectid="1"/><item objectid="2"/>' in text

    def rewrite(model: str) -> bytes:
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as z:
            z.writestr("3D/3dmodel.model", model)
        return buf.getvalue()

    assert read_3mf(rewrite(text.replace('unit="millimeter"', 'unit="inch"')))[1] == ["unit is inch, not millimeter"]
    twice = model_3mf([("same", *box), ("same", *small)], "t")
    assert read_3mf(twice)[1] == ["object name same appears twice"]
    bad = text.replace('v3="1"/>', 'v3="99"/>', 1)
    assert read_3mf(rewrite(bad))[1] == ['object a&b <"x">: no triangles or triangle indices outside its vertices']
    assert "unreadable mesh" in read_3mf(rewrite(text.replace('x="2.000000"', 'x="two"', 1)))[1][0]
    objects, problems = read_3mf(b"not a zip")
    assert objects == {} and problems[0].startswith("not a readable 3MF package (BadZipFile")


def test_assembly_3mf_places_each_part_at_its_body_pose():
    """A 15 mm link posed at (10, 5, 90 deg): its object spans x in [10 - 3, 10 + 3], y in [5 - 3, 5 + 18] (the
    stadium turned a quarter), same volume; a part whose body has no pose stays where it is."""
    from fabricate.export.layout import Placement
    from fabricate.export.stl import assembly_3mf, placed_flat_mesh, read_3mf

    link = slot_part("link", "crank", ("O", "A"), 15.0, width=6.0, z=2.0)
    other = slot_part("other", "ground", ("P", "Q"), 10.0, width=6.0)
    cache = SolidCache(0.002)
    objects, problems = read_3mf(assembly_3mf([link, other], cache, {"crank": np.array([10.0, 5.0, np.pi / 2])}))
    assert problems == [] and list(objects) == ["link", "other"]
    np.testing.assert_allclose(objects["link"].bounds, [[7.0, 2.0, 2.0], [13.0, 23.0, 5.0]], atol=0.003)
    np.testing.assert_allclose(objects["other"].bounds, [[-3.0, -3.0, 0.0], [13.0, 3.0, 3.0]], atol=0.003)
    assert objects["link"].volume == pytest.approx(link.volume_mm3(), rel=1e-3)
    place = Placement(angle=np.pi, offset=np.array([50.0, 20.0]), sheet=0, size=np.array([21.0, 6.0]))
    vertices, faces = placed_flat_mesh(link, cache, place)
    flat_v, flat_f = cache.flat_mesh(link)
    np.testing.assert_array_equal(faces, flat_f)
    np.testing.assert_allclose(vertices[:, :2], np.column_stack([50.0 - flat_v[:, 0], 20.0 - flat_v[:, 1]]), atol=1e-9)
    np.testing.assert_array_equal(vertices[:, 2], flat_v[:, 2])
    assert flat_v[:, 2].min() == pytest.approx(0.0, abs=1e-9)  # lying on the plate, not at z = 2
    assert cache.solid(link) is cache.solid(link)


def tetra_mesh() -> tuple[np.ndarray, np.ndarray]:
    """An irregular tetrahedron, outward triangles: volume det(v1 - v0, v2 - v0, v3 - v0) / 6 = 5.55 / 6 mm^3."""
    v = np.array([[0.0, 0.0, 0.0], [2.0, 0.3, 0.0], [0.4, 1.5, 0.2], [0.5, 0.6, 2.0]])
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    return v, f


def test_stl_findings_at_their_boundaries():
    """A first triangle whose normal has a non-zero low byte (the count is the 4 bytes 80-83, not more); a single
    triangle is a triangle (not 'no triangles'); a closed mesh of zero volume and a small positive one; the
    volume tolerance is relative with a default of 1e-3 and strict."""
    from fabricate.export.stl import stl_bytes

    v, f = tetra_mesh()
    data = stl_bytes(v, f)
    assert data[84] != 0  # the first normal's first byte
    assert validate_stl(data, 5.55 / 6.0, rel_tol=1e-6) == []  # float32 corners
    single = validate_stl(stl_bytes(v[:3], f[:1]))
    assert "not watertight" in single and "no triangles" not in single
    flat = trimesh.Trimesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2], [0, 2, 1]]),
                           process=False)  # two faces back to back: closed, volume exactly 0
    with np.errstate(invalid="ignore"):  # trimesh divides by the zero volume for the centre of mass
        assert mesh_problems(flat) == ["volume 0 mm^3 is not positive"]
    small_v, small_f = box_mesh((0.5, 0.5, 0.5))
    assert mesh_problems(trimesh.Trimesh(small_v, small_f, process=False)) == []  # 0.125 mm^3
    box = trimesh.Trimesh(*box_mesh(), process=False)
    assert mesh_problems(box, 24.0, rel_tol=0.0) == []  # exactly the volume: no tolerance needed
    assert mesh_problems(box, 24.02) == []  # default 1e-3
    assert mesh_problems(box, 24.03) == ["volume 24 mm^3 differs from 24.03 mm^3"]


def test_plate_stl_numbers_each_shell_after_the_previous_ones():
    """Three meshes of 8, 4 and 8 vertices: the triangles of each refer to its own vertices, so the plate is three
    closed shells with the sum of the volumes."""
    from fabricate.export.stl import plate_stl

    tv, tf = tetra_mesh()
    meshes = [box_mesh(), (tv + [10.0, 0.0, 0.0], tf), box_mesh((1.0, 1.0, 1.0), origin=(20.0, 0.0, 0.0))]
    data = plate_stl(meshes)
    assert validate_stl(data, 24.0 + 5.55 / 6.0 + 1.0, rel_tol=1e-6) == []  # float32 corners
    mesh = trimesh.load(io.BytesIO(data), file_type="stl")
    assert len(mesh.split(only_watertight=True)) == 3


def test_read_3mf_reads_every_object_and_checks_each_index():
    """The 3MF core default unit is the millimetre (no attribute: no finding); an object with an unreadable number
    or a bad index is reported and the objects after it are still read; no triangles, a negative index and an
    index equal to the vertex count are each reported; a triangle soup (unshared vertices) is read as it is, so
    it is not watertight."""
    import zipfile

    from fabricate.export.stl import model_3mf, read_3mf

    box = box_mesh()

    def model_text(objects) -> str:
        with zipfile.ZipFile(io.BytesIO(model_3mf(objects, "t"))) as z:
            return z.read("3D/3dmodel.model").decode()

    def rewrite(model: str) -> bytes:
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as z:
            z.writestr("3D/3dmodel.model", model)
        return buf.getvalue()

    text = model_text([("first", *box), ("second", *box)])
    objects, problems = read_3mf(rewrite(text.replace(' unit="millimeter"', "")))
    assert problems == [] and list(objects) == ["first", "second"]
    first = text.index('name="second"')
    bad_number = text[:first].replace('x="2.000000"', 'x="two"', 1) + text[first:]
    objects, problems = read_3mf(rewrite(bad_number))
    assert list(objects) == ["second"] and len(problems) == 1 and problems[0].startswith("object first: unreadable")
    for index in ("8", "-1"):
        bad = text[:first].replace('v3="1"/>', f'v3="{index}"/>', 1) + text[first:]
        objects, problems = read_3mf(rewrite(bad))
        assert list(objects) == ["second"]
        assert problems == ["object first: no triangles or triangle indices outside its vertices"]
    empty = model_text([("none", box[0], np.zeros((0, 3), dtype=int)), ("second", *box)])
    objects, problems = read_3mf(rewrite(empty))
    assert list(objects) == ["second"]
    assert problems == ["object none: no triangles or triangle indices outside its vertices"]
    soup_v = box[0][box[1]].reshape(-1, 3)  # each triangle with its own three vertices
    soup_f = np.arange(len(soup_v)).reshape(-1, 3)
    objects, problems = read_3mf(model_3mf([("soup", soup_v, soup_f)], "t"))
    assert problems == [] and len(objects["soup"].vertices) == 36
    assert "not watertight" in mesh_problems(objects["soup"])


def plain(outline: BulgePath, holes=(), slots=()) -> SlottedPart:
    return SlottedPart("A", "A", outline, tuple(holes), 3.0, 0.0, 0, "laser", slots=tuple(slots))


def rectangle(w: float, h: float, x0: float = 0.0, y0: float = 0.0) -> BulgePath:
    return BulgePath(np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]), np.zeros(4))


def disc(radius: float) -> BulgePath:
    """A full circle about the origin: two half-circle arcs (bulge 1)."""
    return BulgePath(np.array([[-radius, 0.0], [radius, 0.0]]), np.array([1.0, 1.0]))


def closed_form_height(room: float, text: str) -> float:
    return float(np.clip(round(min(0.8 * room, 1.6 * room / (0.9 * len(text))), 3), 0.3, 5.0))


@pytest.mark.parametrize("name", ["A", "LABEL12"])
def test_label_height_is_the_closed_form_of_the_room(name):
    """On a 6 x 20 rectangle the roomiest spots are its centre line (room = half the width, 3 mm): the
    label sits there with height round(min(0.8 room, 1.6 room / (0.9 len)), 3) exactly. On a disc of
    radius 3 the room is 3 less at most the 0.05 mm chord sagitta."""
    spot, height, _ = label_of(dataclasses.replace(plain(rectangle(6.0, 20.0)), name=name))
    assert spot.x == pytest.approx(3.0, abs=1e-9) and 3.0 <= spot.y <= 17.0
    assert height == closed_form_height(3.0, name)
    spot, height, _ = label_of(dataclasses.replace(plain(disc(3.0)), name=name))
    assert spot.distance(shapely.Point(0.0, 0.0)) <= 0.05
    assert closed_form_height(2.95, name) - 0.001 <= height <= closed_form_height(3.0, name)


def label_cases() -> dict[str, SlottedPart]:
    four = [Hole(str(k), np.array([sx * 1.6, sy * 1.6]), 0.4, 0.3) for k, (sx, sy) in
            enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)])]
    ell = BulgePath(np.array([[0.0, 0.0], [300.0, 0.0], [300.0, 40.0], [40.0, 40.0], [40.0, 200.0], [0.0, 200.0]]),
                    np.zeros(6))
    return {
        "L-plate": plain(ell),  # pole off the centroid: the search has to refine it
        "disc-slot": plain(rectangle(12.0, 12.0, -6.0, -6.0), slots=[disc(3.0)]),  # pole between slot and corner
        "four-holes": plain(rectangle(8.0, 8.0, -4.0, -4.0), holes=four),  # pole between the holes, edges far
        "off-hole": plain(rectangle(20.0, 20.0), holes=[Hole("H", np.array([6.0, 7.0]), 5.0, 3.0)]),
    }


@pytest.mark.parametrize("case", list(label_cases()))
def test_label_spot_is_the_roomiest_within_its_tolerance(case):
    """The label spot lies in the plate (outline less holes and slots, sampled here) with a room (shapely
    distance to the nearest edge, hole or slot) within 0.05 mm of the largest inscribed circle, and its
    height is the closed form of that room (to the 0.05 mm tolerance and rounding)."""
    part = label_cases()[case]
    plate = plate_region(part)
    spot, height, text = label_of(part)
    assert plate.contains(spot)
    room = plate.boundary.distance(spot)
    best = shapely.maximum_inscribed_circle(plate, 1e-4).length
    assert best - 0.05 <= room <= best + 1e-3
    assert closed_form_height(room - 0.05, text) - 0.001 <= height <= closed_form_height(room + 0.05, text)


def test_read_dxf_returns_the_auditors_messages():
    """A broken drawing (a layer name with '<', an undefined linetype) is reported with the auditor's own
    messages: the unfixable error and the fix, each naming what is wrong."""
    from fabricate.export.dxf import document_bytes, new_document, read_dxf

    doc = new_document()
    doc.modelspace().add_line((0.0, 0.0), (1.0, 1.0), dxfattribs={"layer": "BAD", "linetype": "MISSING"})
    data = document_bytes(doc).replace(b"\n  8\nBAD\n", b"\n  8\nB<D\n")
    problems, diameters = read_dxf(data)
    assert diameters == [] and len(problems) == 2
    assert problems[0].startswith('Invalid layer name "B<D" in LINE')
    assert "linetype" in problems[1] and "missing" in problems[1].lower()
