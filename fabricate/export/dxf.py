"""DXF for laser cutting and CAD (with :mod:`fabricate.export.kinematic`, the only modules that import ezdxf).

Every document is R2010 in millimetres ($INSUNITS = 4, $MEASUREMENT = 1). Cut geometry goes on layer
``CUT`` (red): each outline is one closed LWPOLYLINE whose arcs are bulges, each hole a CIRCLE, each slot
a closed LWPOLYLINE. Labels go on ``ENGRAVE`` (blue). The laser kerf is applied to the cut path only:
outlines are offset out by kerf / 2 and holes in by kerf / 2 (a hole's CIRCLE is its modelled diameter
minus the kerf), so the finished part has the modelled size.

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

from fabricate.export.layout import Placement, shelf_pack
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.profiles import offset_path

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


def cut_geometry(part: Part, kerf_mm: float) -> tuple[BulgePath, list[tuple[np.ndarray, float]], list[BulgePath]]:
    """The laser path of a part: outline offset out by kerf/2, holes (centre, diameter) shrunk by the kerf,
    slots offset in by kerf/2. With no kerf this is the part's exact geometry."""
    half = 0.5 * kerf_mm
    outline = offset_path(part.outline, half)
    holes = [(np.asarray(h.centre, dtype=np.float64), h.diameter_mm - kerf_mm) for h in part.holes]
    slots = [offset_path(s, -half) for s in getattr(part, "slots", ())]
    return outline, holes, slots


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
    """

    arcs: str = "bulge"
    chord_tolerance_mm: float = 0.005
    min_text_mm: float = 0.0
    hole_labels: bool = False


EXACT = DxfStyle()


def add_part(msp: Any, part: Part, kerf_mm: float, placement: Placement | None = None,
             label: str | None = None, style: DxfStyle = EXACT) -> None:
    """Draw a part's cut path (CUT) and its label (ENGRAVE) into a modelspace.

    Parameters
    ----------
    placement : Placement, optional
        Rotation and offset onto a sheet; None keeps the part's own coordinates.
    label : str, optional
        Text engraved at the roomiest inside point (default: the part name).
    style : DxfStyle
        Arcs as bulges or segments, and the smallest label drawn.
    """
    outline, holes, slots = cut_geometry(part, kerf_mm)

    def place(points: np.ndarray) -> np.ndarray:
        return placement.apply(points) if placement is not None else np.asarray(points, dtype=np.float64)

    for path in [outline] + slots:
        if style.arcs == "segments":
            path = BulgePath.polyline(path.polygon(style.chord_tolerance_mm))
        xy = place(path.vertices)
        msp.add_lwpolyline([(float(x), float(y), float(b)) for (x, y), b in zip(xy, path.bulges, strict=True)],
                           format="xyb", close=True, dxfattribs={"layer": "CUT"})
    for centre, diameter in holes:
        c = place(centre[None, :])[0]
        msp.add_circle((float(c[0]), float(c[1])), float(diameter) / 2.0, dxfattribs={"layer": "CUT"})
    if style.hole_labels:
        _hole_labels(msp, part, place)
    label = label if label is not None else part.name
    spot, height = _label_spot(part, label)
    if height < style.min_text_mm:  # the process cannot engrave it legibly
        return
    spot = place(spot[None, :])[0]
    text = msp.add_text(label, height=height, dxfattribs={"layer": "ENGRAVE"})
    text.set_placement((float(spot[0]), float(spot[1])), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)


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


def part_dxf(part: Part, kerf_mm: float, style: DxfStyle = EXACT) -> bytes:
    """DXF of one part in its own (body) coordinates (with the layer ``HOLES`` when the style labels holes)."""
    doc = new_document(("CUT", "ENGRAVE", "HOLES") if style.hole_labels else ("CUT", "ENGRAVE"))
    add_part(doc.modelspace(), part, kerf_mm, style=style)
    return document_bytes(doc)


def sheet_layout(parts: Sequence[Part], kerf_mm: float, sheet_mm: tuple[float, float], margin_mm: float,
                 spacing_mm: float) -> list[Placement]:
    """Nest the parts' cut outlines on sheets of ``sheet_mm`` (bounding-rectangle shelves, no overlap)."""
    outlines = [cut_geometry(p, kerf_mm)[0].polygon(0.05) for p in parts]
    return shelf_pack(outlines, sheet_mm, margin_mm, spacing_mm + kerf_mm)


def sheet_dxf(parts: Sequence[Part], kerf_mm: float, placements: Sequence[Placement],
              sheet_mm: tuple[float, float], sheet: int = 0, style: DxfStyle = EXACT) -> bytes:
    """Sheet number ``sheet``: its border (layer SHEET, not plotted) and the parts placed on it."""
    doc = new_document(("CUT", "ENGRAVE", "SHEET"))
    msp = doc.modelspace()
    msp.add_lwpolyline([(0.0, 0.0), (sheet_mm[0], 0.0), (sheet_mm[0], sheet_mm[1]), (0.0, sheet_mm[1])],
                       format="xy", close=True, dxfattribs={"layer": "SHEET"})
    for part, placement in zip(parts, placements, strict=True):
        if placement.sheet == sheet:
            add_part(msp, part, kerf_mm, placement, style=style)
    return document_bytes(doc)


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
