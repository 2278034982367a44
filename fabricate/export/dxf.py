"""DXF for laser cutting and CAD (with :mod:`fabricate.export.kinematic`, the only modules that import ezdxf).

Every document is R2010 in millimetres ($INSUNITS = 4, $MEASUREMENT = 1). Cut geometry goes on layer
``CUT`` (red): each outline is one closed LWPOLYLINE whose arcs are bulges, each hole a CIRCLE, each slot
a closed LWPOLYLINE. Nothing else is on ``CUT``. The laser kerf is applied to the cut path only: outlines
are offset out by kerf / 2 and holes in by kerf / 2 (a hole's CIRCLE is its modelled diameter minus the
kerf), so the finished part has the modelled size.

Labels go on ``ENGRAVE`` (blue). In a cut file (:attr:`DxfStyle.labels` ``"outlines"``) a label is the
outline of its text, closed bulge-free LWPOLYLINEs (:mod:`fabricate.export.labels`), never a TEXT entity: a
shop's software has not the font, or no text support at all (OpenSCAD: "Unsupported DXF Entity 'TEXT'").
A sheet (``cut/sheet_N.dxf``) holds its parts and nothing else: no border a shop cutting every contour would
cut; its size is the drawing limits ($LIMMIN/$LIMMAX) and extents. Its parts are all of one thickness, the
stock it is cut from (:func:`sized_sheets`: a 3 mm actuator plate beside 6 mm links gets a sheet of its own).

A drawing (``drawings/NAME.dxf``, for CAD, never sent to a cutter) keeps TEXT: its part name and hole notes
are to be read and edited in LibreCAD or FreeCAD, which draw TEXT in their own fonts.

A part's drawing (``drawings/NAME.dxf``, :attr:`DxfStyle.hole_labels`) also labels every hole on layer
``HOLES`` (never in a cut file): the NOMINAL hole and its fit, what the finished part should measure, and
apart from it the CAD (modelled) size with the process's compensation, e.g. ``Ø1.95 press (CAD Ø2.15 incl.
+0.2 sla compensation)``. The labels stand in a column right of the part, each with a leader to its hole.

Documents are written with ezdxf's fixed metadata (dates, GUIDs) so equal inputs give equal bytes.
"""

from __future__ import annotations

import contextlib
import io
from collections import OrderedDict
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import ezdxf
import numpy as np
import shapely
from ezdxf import units
from shapely.ops import polylabel

from fabricate.export.labels import Label, label_part
from fabricate.export.layout import Placement, fits, shelf_pack
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.profiles import offset_path, touching_pairs

#: Smallest text in a drawing (mm): ISO 3098 / ASME Y14.2 ask for at least 2.5 mm on printed drawings.
MIN_DRAWING_TEXT_MM = 2.5
#: The kinematic drawing's dimension style (its text and arrow sizes).
DIMSTYLE = "FABRICATE"

#: ACI colours: red for cutting, blue for engraving, grey for the sheet border, others for CAD drawings.
LAYERS = {"CUT": 1, "ENGRAVE": 5, "SHEET": 8, "LINKS": 7, "JOINTS": 3, "DIMENSIONS": 2, "LABELS": 4, "HOLES": 3}


@contextlib.contextmanager
def _fixed_metadata() -> Iterator[None]:
    """Write fixed dates and GUIDs (ezdxf's testing switch) for byte-identical output."""
    previous = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        yield
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = previous


def new_document(layers: Sequence[str] = ("CUT", "ENGRAVE"), dimensions: bool = False) -> Any:
    """An empty R2010 document in mm with the given layers (colours from :data:`LAYERS`).

    ``dimensions`` adds ezdxf's dimension styles (needed by the kinematic drawing only; the cut files
    stay small).
    """
    with _fixed_metadata():  # ezdxf stamps the creation time at new()
        doc = ezdxf.new("R2010", setup=["styles", "dimstyles"] if dimensions else False)
    doc.units = units.MM
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LUNITS"] = 2
    for name in layers:
        layer = doc.layers.add(name, color=LAYERS[name])
        if name == "SHEET":
            layer.dxf.plot = 0  # the sheet border is a guide, not a cut
    return doc


def document_bytes(doc: Any) -> bytes:
    """Encode a document as DXF bytes (fixed metadata, UTF-8 for R2007+)."""
    # ezdxf collects its required CLASS records in a set: their order would follow the process's
    # string-hash seed, so sort them (the order has no meaning to readers)
    doc.classes.add_required_classes(doc.dxfversion)  # write() adds them (from a set) unless present
    doc.classes.classes = OrderedDict(sorted(doc.classes.classes.items()))
    stream = io.StringIO()
    with _fixed_metadata():
        doc.write(stream)
    return stream.getvalue().encode("utf-8")


#: The latest parts' cut paths, by (id of the part, kerf): (the part, its outline, holes and slots). The part is
#: kept with its paths, so its id names no other object while the entry lives; parts are frozen.
_CUT_PATHS: OrderedDict[tuple[int, float], tuple[Part, BulgePath, list[tuple[np.ndarray, float]], list[BulgePath]]] \
    = OrderedDict()
#: Entries kept: a laser build asks for each part's path some eight times (its files, its sheet's, its areas).
_CUT_PATHS_KEPT = 64


def cut_geometry(part: Part, kerf_mm: float) -> tuple[BulgePath, list[tuple[np.ndarray, float]], list[BulgePath]]:
    """The laser path of a part: outline offset out by kerf/2, holes (centre, diameter) shrunk by the kerf,
    slots offset in by kerf/2. With no kerf this is the part's exact geometry.

    The offsets are worked out once per part and kerf (the latest :data:`_CUT_PATHS_KEPT`); every call returns
    new lists of the same (frozen) paths."""
    key = (id(part), float(kerf_mm))
    kept = _CUT_PATHS.get(key)
    if kept is None or kept[0] is not part:
        half = 0.5 * kerf_mm
        holes = [(_frozen(h.centre), h.diameter_mm - kerf_mm) for h in part.holes]
        slots = [offset_path(s, -half) for s in getattr(part, "slots", ())]
        kept = (part, offset_path(part.outline, half), holes, slots)
        _CUT_PATHS[key] = kept
        if len(_CUT_PATHS) > _CUT_PATHS_KEPT:
            _CUT_PATHS.popitem(last=False)
    _, outline, holes, slots = kept
    return outline, list(holes), list(slots)


def _frozen(point: Any) -> np.ndarray:
    """A read-only float copy of a point (shared by every caller of :func:`cut_geometry`)."""
    out = np.array(point, dtype=np.float64)
    out.setflags(write=False)
    return out


def cut_area(part: Part, kerf_mm: float) -> float:
    """Exact area (mm^2) the cut path encloses: the offset outline less the shrunk holes and slots (what a
    reader of the cut DXF's layer CUT measures)."""
    outline, holes, slots = cut_geometry(part, kerf_mm)
    return (abs(outline.area()) - sum(np.pi * d * d / 4.0 for _, d in holes)
            - sum(abs(s.area()) for s in slots))


def _label_spot(part: Part, text: str) -> tuple[np.ndarray, float]:
    """A point inside the part far from its edges and holes, and a text height that fits there.

    The point is the pole of inaccessibility of the plate (outline less holes); the height keeps the
    text (at most about 0.9 h per character wide) inside the largest circle around it.
    """
    polygon = shapely.Polygon(part.outline.polygon(0.05))
    for h in part.holes:
        polygon = polygon.difference(shapely.Point(h.centre).buffer(h.diameter_mm / 2.0, 16))
    for s in getattr(part, "slots", ()):
        polygon = polygon.difference(shapely.Polygon(s.polygon(0.05)))
    if polygon.is_empty:
        return np.asarray(part.outline.vertices.mean(axis=0)), 1.0
    if polygon.geom_type == "MultiPolygon":
        polygon = max(polygon.geoms, key=lambda g: g.area)
    spot = polylabel(polygon, tolerance=0.05)
    room = float(polygon.exterior.distance(spot))
    for ring in polygon.interiors:
        room = min(room, float(ring.distance(spot)))
    height = min(0.8 * room, 1.6 * room / (0.9 * max(1, len(text))))
    return np.array([spot.x, spot.y]), float(np.clip(round(height, 3), 0.3, 5.0))


@dataclass(frozen=True)
class DxfStyle:
    """How a process wants its DXF: exact bulge arcs or line segments, and its smallest label.

    Attributes
    ----------
    arcs : str
        ``"bulge"``: arcs as LWPOLYLINE bulges (exact). ``"segments"``: arcs as straight segments whose
        sagitta is at most ``chord_tolerance_mm``, for readers that ignore bulges (OpenSCAD, older laser
        software). Holes stay CIRCLEs either way (every reader draws those).
    chord_tolerance_mm : float
    min_text_mm : float
        Labels that would be smaller are left out (0 keeps every label).
    hole_labels : bool
        Label every hole on layer ``HOLES`` with its nominal size, fit and compensation (drawings only: a
        cutter would engrave them).
    labels : str
        ``"text"``: the part's name as a TEXT entity (drawings). ``"outlines"``: the label's glyph outlines
        as closed polylines (cut files; see the module docstring).
    label_margin_mm : float
        Outlined labels keep this far inside the part and off its holes and slots.
    """

    arcs: str = "bulge"
    chord_tolerance_mm: float = 0.005
    min_text_mm: float = 0.0
    hole_labels: bool = False
    labels: str = "text"
    label_margin_mm: float = 0.5


EXACT = DxfStyle()


def add_part(msp: Any, part: Part, kerf_mm: float, placement: Placement | None = None,
             label: str | Label | None = None, style: DxfStyle = EXACT) -> None:
    """Draw a part's cut path (CUT) and its label (ENGRAVE) into a modelspace.

    Parameters
    ----------
    placement : Placement, optional
        Rotation and offset onto a sheet; None keeps the part's own coordinates.
    label : str or Label, optional
        Text engraved at the roomiest inside point (default: the part name; "" none), or a placed
        :class:`Label` (outlines; :func:`fabricate.export.labels.label_part`).
    style : DxfStyle
        Arcs as bulges or segments, the smallest label drawn, TEXT or outlined labels.
    """
    outline, holes, slots = cut_geometry(part, kerf_mm)

    def place(points: np.ndarray) -> np.ndarray:
        return placement.apply(points) if placement is not None else np.asarray(points, dtype=np.float64)

    for path in [outline] + slots:
        if style.arcs == "segments":
            path = BulgePath.polyline(path.polygon(style.chord_tolerance_mm))
        add_closed_polyline(msp, place(path.vertices), "CUT", path.bulges)
    for centre, diameter in holes:
        c = place(centre[None, :])[0]
        msp.add_circle((float(c[0]), float(c[1])), float(diameter) / 2.0, dxfattribs={"layer": "CUT"})
    if style.hole_labels:
        _hole_labels(msp, part, place)
    if style.labels == "outlines" or isinstance(label, Label):
        engraved = label if isinstance(label, Label) else engraved_label(part, style, label)
        if engraved is not None:
            for ring in engraved.polygons():
                add_closed_polyline(msp, place(ring), "ENGRAVE")
        return
    label = label if label is not None else part.name
    spot, height = _label_spot(part, label)
    if height < style.min_text_mm:  # the process cannot engrave it legibly
        return
    spot = place(spot[None, :])[0]
    text = msp.add_text(label, height=height, dxfattribs={"layer": "ENGRAVE"})
    text.set_placement((float(spot[0]), float(spot[1])), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)


def add_closed_polyline(msp: Any, xy: np.ndarray, layer: str, bulges: np.ndarray | None = None) -> Any:
    """A closed LWPOLYLINE through the points ``xy`` (n, 2), with ``bulges`` (n,) (none: straight), on ``layer``.

    The entity ``msp.add_lwpolyline(points, format="xyb", close=True)`` makes, its vertices given to ezdxf's
    vertex array at once (x, y, start width, end width, bulge: what ezdxf stores a point as): ezdxf's
    ``add_lwpolyline`` appends them one by one, copying the array at each (quadratic in the points: a text
    outline has hundreds). tests/export/test_dxf.py holds the two to the same bytes."""
    polyline = msp.add_lwpolyline((), format="xyb", close=True, dxfattribs={"layer": layer})
    values = np.zeros((len(xy), 5))
    values[:, :2] = xy
    if bulges is not None:
        values[:, 4] = bulges
    polyline.lwpoints.extend(values)
    return polyline


def hole_label(part: Part, hole: Hole) -> str:
    """A hole's label: nominal size and fit, then the CAD size and the compensation (see the module docstring)."""
    from fabricate.parts.retention import hole_label as label

    return label(hole.fit, hole.nominal_mm, hole.diameter_mm, part.process)


def _hole_labels(msp: Any, part: Part, place: Callable[[np.ndarray], np.ndarray]) -> None:
    """Label every hole on layer HOLES: a column of texts right of the part, a leader line to each hole."""
    if not part.holes:
        return
    height = MIN_DRAWING_TEXT_MM
    outline = place(part.outline.polygon(0.05))
    x_text = float(outline[:, 0].max()) + 2.0 * height
    centres = [place(np.asarray(h.centre, dtype=np.float64)[None, :])[0] for h in part.holes]
    order = sorted(range(len(part.holes)), key=lambda k: (-float(centres[k][1]), float(centres[k][0])))
    top = max(float(outline[:, 1].max()), max(float(c[1]) for c in centres))
    for row, k in enumerate(order):
        hole, c = part.holes[k], centres[k]
        y = top - row * 1.6 * height
        edge = (float(c[0]) + 0.5 * hole.diameter_mm, float(c[1]))
        msp.add_line(edge, (x_text - 0.5 * height, y), dxfattribs={"layer": "HOLES"})
        text = msp.add_text(f"{hole.joint}: {hole_label(part, hole)}", height=height, dxfattribs={"layer": "HOLES"})
        text.set_placement((x_text, y), align=ezdxf.enums.TextEntityAlignment.MIDDLE_LEFT)


def engraved_label(part: Part, style: DxfStyle, text: str | None = None) -> Label | None:
    """The outlined label a cut file engraves when it is given none: the part's name (or ``text``) if it fits
    at the style's smallest label, else nothing (the build numbers parts instead: see
    :func:`fabricate.export.labels.label_parts`)."""
    return label_part(part, "", style.min_text_mm, style.label_margin_mm, text=text).label


def part_dxf(part: Part, kerf_mm: float, style: DxfStyle = EXACT, label: Label | str | None = None) -> bytes:
    """DXF of one part in its own (body) coordinates (with the layer ``HOLES`` when the style labels holes).

    ``label``: the placed label of a cut file, or a text ("" none; default: see :func:`engraved_label`)."""
    doc = new_document(("CUT", "ENGRAVE", "HOLES") if style.hole_labels else ("CUT", "ENGRAVE"))
    add_part(doc.modelspace(), part, kerf_mm, label=label, style=style)
    return document_bytes(doc)


def by_thickness(parts: Sequence[Part]) -> dict[float, list[int]]:
    """The parts' indices grouped by thickness (each group is cut from its own stock), the groups in the order
    their first part comes; one group (every part in order) when all share one thickness."""
    groups: dict[float, list[int]] = {}
    for k, part in enumerate(parts):
        groups.setdefault(round(float(part.thickness_mm), 6), []).append(k)
    return groups


def sheet_layout(parts: Sequence[Part], kerf_mm: float, sheet_mm: tuple[float, float], margin_mm: float,
                 spacing_mm: float) -> list[Placement]:
    """Nest the parts' cut outlines on sheets of ``sheet_mm`` (bounding-rectangle shelves, no overlap), each
    sheet holding parts of one thickness (:func:`by_thickness`: a sheet is one stock)."""
    outlines = [cut_geometry(p, kerf_mm)[0].polygon(0.05) for p in parts]
    groups = by_thickness(parts)
    if len(groups) <= 1:
        return shelf_pack(outlines, sheet_mm, margin_mm, spacing_mm + kerf_mm)
    placements: list[Placement] = [Placement(0.0, np.zeros(2), 0, np.zeros(2))] * len(parts)
    first = 0
    for members in groups.values():
        packed = shelf_pack([outlines[k] for k in members], sheet_mm, margin_mm, spacing_mm + kerf_mm)
        for k, pl in zip(members, packed, strict=True):
            placements[k] = Placement(pl.angle, pl.offset, first + pl.sheet, pl.size)
        first += 1 + max(pl.sheet for pl in packed)
    return placements


def sheet_dxf(parts: Sequence[Part], kerf_mm: float, placements: Sequence[Placement],
              sheet_mm: tuple[float, float], sheet: int = 0, style: DxfStyle = EXACT,
              labels: Sequence[Label | str | None] | None = None) -> bytes:
    """Sheet number ``sheet``: the parts placed on it, and nothing else (see the module docstring).

    ``labels``: each part's placed label, in the order of ``parts`` (default: see :func:`engraved_label`).
    The sheet's size is the drawing's limits and extents, so a viewer opens on the whole sheet."""
    doc = new_document(("CUT", "ENGRAVE"))
    msp = doc.modelspace()
    for k, (part, placement) in enumerate(zip(parts, placements, strict=True)):
        if placement.sheet == sheet:
            add_part(msp, part, kerf_mm, placement, label=None if labels is None else labels[k], style=style)
    corner = (float(sheet_mm[0]), float(sheet_mm[1]))
    msp.reset_limits((0.0, 0.0), corner)  # ezdxf writes the modelspace's limits to $LIMMIN / $LIMMAX
    msp.reset_extents((0.0, 0.0, 0.0), (*corner, 0.0))
    return document_bytes(doc)


@dataclass(frozen=True)
class Sheet:
    """One sheet of a laser layout: which standard stock it is and how much of it the parts use.

    Attributes
    ----------
    index : int
        From 0 (file ``cut/sheet_{index + 1}``).
    name : str
        The stock's name in the profile's ``[sheets]`` (e.g. Ponoko's ``"P2"``), or ``"bed"`` for the
        process's sheet (``build_volume_mm``) when the profile names none.
    size_mm : (float, float)
        Width and height as laid out (a stock may be used turned a quarter).
    part_area_mm2 : float
        Area of the parts on it (finished size: outline less holes and slots).
    cut_area_mm2 : float
        Area the sheet's cut paths enclose (kerf applied: what a reader of its layer CUT measures).
    parts : tuple of str
        The part names on it, one per copy, in layout order.
    thickness_mm : float
        The stock's thickness: every part on it is this thick (a layout nests each thickness on its own sheets).
    """

    index: int
    name: str
    size_mm: tuple[float, float]
    part_area_mm2: float
    cut_area_mm2: float
    parts: tuple[str, ...]
    thickness_mm: float = 0.0

    @property
    def utilisation(self) -> float:
        """Part area over sheet area."""
        return self.part_area_mm2 / (self.size_mm[0] * self.size_mm[1])

    def report(self) -> dict[str, Any]:
        """report.json's row of the sheet (see :func:`fabricate.export.cut_report`)."""
        return {"index": self.index + 1, "file": f"cut/sheet_{self.index + 1}.dxf", "stock": self.name,
                "thickness_mm": round(self.thickness_mm, 6), "size_mm": [round(v, 3) for v in self.size_mm],
                "part_area_mm2": round(self.part_area_mm2, 3),
                "cut_area_mm2": round(self.cut_area_mm2, 3),
                "utilisation": round(self.utilisation, 4), "parts": list(self.parts)}


def sized_sheets(parts: Sequence[Part], kerf_mm: float, stock: Sequence[tuple[str, float, float]],
                 bed_mm: tuple[float, float], margin_mm: float,
                 spacing_mm: float) -> tuple[list[Placement], list[Sheet]]:
    """Nest the parts, each sheet holding parts of one thickness on the smallest standard stock that holds them.

    Each thickness is nested on its own sheets (:func:`by_thickness`: a sheet is cut from one stock), the
    thicknesses in the order their first part comes. The parts of a thickness are first nested on the largest
    stock that fits the bed (or the bed itself when the profile names no stock, or none fits), which fixes how
    many sheets there are and which parts go on each; then each sheet's parts are nested again on every smaller
    stock (as listed, then a quarter turn), smallest area first, and the first that holds them all on one sheet
    is that sheet's.

    Parameters
    ----------
    parts : sequence of Part
        Every part made (copies repeated).
    stock : sequence of (name, width, height)
        The profile's standard sheets (``ProcessSpec.sheets``).
    bed_mm : (float, float)
        The largest sheet the process takes (``build_volume_mm[:2]``).

    Returns
    -------
    placements : list of Placement
        In the order of ``parts``; ``sheet`` indexes ``sheets``.
    sheets : list of Sheet
    """
    def holds(size: tuple[float, float]) -> bool:
        return (size[0] <= bed_mm[0] + 1e-9 and size[1] <= bed_mm[1] + 1e-9) or (
            size[1] <= bed_mm[0] + 1e-9 and size[0] <= bed_mm[1] + 1e-9)

    usable = sorted(((name, (float(w), float(h))) for name, w, h in stock if holds((w, h))),
                    key=lambda s: (s[1][0] * s[1][1], s[1][0], s[0]))
    largest = usable[-1] if usable else ("bed", (float(bed_mm[0]), float(bed_mm[1])))
    outlines = [cut_geometry(p, kerf_mm)[0].polygon(0.05) for p in parts]
    placements: list[Placement] = [Placement(0.0, np.zeros(2), 0, np.zeros(2))] * len(parts)
    sheets: list[Sheet] = []
    for thickness, members in by_thickness(parts).items():
        packed = shelf_pack([outlines[k] for k in members], largest[1], margin_mm, spacing_mm + kerf_mm)
        for number in sorted({pl.sheet for pl in packed}):
            mine = [i for i, pl in enumerate(packed) if pl.sheet == number]
            placements, sheet = _sized_sheet(parts, outlines, [members[i] for i in mine], [packed[i] for i in mine],
                                             placements, len(sheets), thickness, usable, largest, kerf_mm,
                                             margin_mm, spacing_mm)
            sheets.append(sheet)
    return placements, sheets


def _sized_sheet(parts: Sequence[Part], outlines: Sequence[np.ndarray], on: list[int], placed: list[Placement],
                 placements: list[Placement], index: int, thickness: float,
                 usable: Sequence[tuple[str, tuple[float, float]]], largest: tuple[str, tuple[float, float]],
                 kerf_mm: float, margin_mm: float, spacing_mm: float) -> tuple[list[Placement], Sheet]:
    """Sheet ``index`` of :func:`sized_sheets`: parts ``on`` (as nested on the largest stock, ``placed``) on the
    smallest stock that holds them all; ``placements`` with theirs set."""
    chosen = largest
    for name, (w, h) in usable[:-1]:
        for size in dict.fromkeys(((w, h), (h, w))):
            trial = shelf_pack([outlines[k] for k in on], size, margin_mm, spacing_mm + kerf_mm)
            if all(pl.sheet == 0 and fits(pl, size, margin_mm) for pl in trial):
                chosen, placed = (name, size), trial
                break
        if chosen[0] != largest[0]:
            break
    for k, pl in zip(on, placed, strict=True):
        placements[k] = Placement(pl.angle, pl.offset, index, pl.size)
    return placements, Sheet(index, chosen[0], chosen[1], sum(parts[k].area_mm2() for k in on),
                             sum(cut_area(parts[k], kerf_mm) for k in on), tuple(parts[k].name for k in on), thickness)


def audit_problems(data: bytes) -> list[str]:
    """Read DXF bytes back and list what ezdxf's auditor fixed or found (empty means clean)."""
    problems, _ = read_dxf(data)
    return problems


def read_dxf(data: bytes) -> tuple[list[str], list[float]]:
    """Read DXF bytes back: ezdxf's audit findings and the diameters of the circles on layer CUT.

    Returns
    -------
    problems : list of str
        Unreadable text or structure, and whatever the auditor fixed or found (empty means clean).
    cut_diameters_mm : list of float
        Diameter of every CIRCLE on layer CUT (the laser's holes), sorted.
    """
    try:
        doc = ezdxf.read(io.StringIO(data.decode("utf-8")))
    except UnicodeDecodeError as exc:
        return [f"not UTF-8 text (byte {exc.start})"], []
    except ezdxf.DXFError as exc:
        return [f"not a readable DXF ({exc})"], []
    auditor = doc.audit()
    problems = [str(e.message) for e in auditor.errors] + [str(f.message) for f in auditor.fixes]
    if doc.units != units.MM:
        problems.append(f"drawing units are {units.unit_name(doc.units)}, not mm")
    diameters = sorted(2.0 * float(e.dxf.radius) for e in doc.modelspace().query('CIRCLE[layer=="CUT"]'))
    return problems, diameters


def cut_file_problems(data: bytes) -> list[str]:
    """What a shop's preflight rejects in a cut DXF (empty: it takes the file as sent).

    Text of any kind (TEXT, MTEXT: the label must be outlines), a layer other than CUT and ENGRAVE, anything
    on CUT but closed LWPOLYLINEs and CIRCLEs, an open polyline, a contour crossing itself, and two CUT
    contours that touch, cross or repeat each other (a line the beam would cut twice).
    """
    from ezdxf import path as dxf_path

    problems, _ = read_dxf(data)
    if problems:
        return problems
    doc = ezdxf.read(io.StringIO(data.decode("utf-8")))
    rings: list[tuple[str, Any]] = []
    for e in doc.modelspace():
        kind, layer = e.dxftype(), e.dxf.layer
        where = f"{kind} on {layer}"
        if kind in ("TEXT", "MTEXT", "ATTRIB", "ATTDEF", "INSERT"):
            problems.append(f"{where}: live text or a block (a shop wants outlines)")
        elif layer not in ("CUT", "ENGRAVE"):
            problems.append(f"{where}: a layer that is neither a cut nor an engraving")
        elif kind == "LWPOLYLINE":
            if not getattr(e, "closed", False):
                problems.append(f"{where}: an open path")
            elif layer == "CUT":
                ring = shapely.LinearRing([(v.x, v.y) for v in dxf_path.make_path(e).flattening(0.001)])
                if not ring.is_simple:
                    problems.append(f"{where}: a contour crossing itself")
                rings.append((where, ring))
        elif kind == "CIRCLE" and layer == "CUT":
            rings.append((where, shapely.Point(e.dxf.center.x, e.dxf.center.y).buffer(e.dxf.radius, 64).exterior))
        elif layer == "CUT":
            problems.append(f"{where}: not a closed contour")
    problems += [f"{rings[i][0]} and {rings[j][0]} touch, cross or repeat (a line cut twice)"
                 for i, j in touching_pairs([ring for _, ring in rings])]
    return problems
