"""SVG for laser software (LightBurn, Glowforge, xTool, Inkscape): the DXF's cut geometry with exact arcs.

Every document is sized in millimetres (``width="…mm"`` with a ``viewBox`` in mm, so one user unit is one
millimetre) and drawn with y up as in the DXF (coordinates are flipped here, no transform for a reader to
mishandle). Conventions the shops follow: hairline strokes (0.01 mm) with no fill are vector operations,
coloured by operation: pure red ``#ff0000`` cuts, pure blue ``#0000ff`` engraves (the defaults of
LightBurn's layer palette and Glowforge's colour-to-step mapping; a process profile may set others).
Outlines are ``path`` elements whose arcs are SVG elliptical arcs with equal radii, holes are ``circle``
elements, labels the outlines of their text on the engrave colour (closed ``path`` elements, never a
``text`` element: a shop's software may lack the font or ignore text; see :mod:`fabricate.export.labels`);
a sheet's SVG is its parts and nothing else (no border). Cut order: holes and slots before the outline, so a part
is cut free last. Each hole's ``circle`` carries a ``title`` (shown by Inkscape, ignored by the cutter): its
nominal size and fit, the CAD size with the process's compensation, and the cut path's diameter (the
drawing's hole label, see :mod:`fabricate.export.dxf`). Encoders return bytes; nothing here writes files.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from fabricate.export.labels import Label
from fabricate.export.layout import Placement
from fabricate.parts.model import BulgePath, Part


# xml.sax.saxutils' escape and quoteattr, the same text: importing that module imports urllib.request, and
# with it http.client and ssl, which a build never uses
def escape(data: str) -> str:
    """``data`` with ``&``, ``<`` and ``>`` as XML entities (``xml.sax.saxutils.escape``)."""
    return data.replace("&", "&amp;").replace(">", "&gt;").replace("<", "&lt;")


def quoteattr(data: str) -> str:
    """``data`` escaped and quoted as an XML attribute value (``xml.sax.saxutils.quoteattr``)."""
    data = escape(data).replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#9;")
    if '"' not in data:
        return f'"{data}"'
    if "'" not in data:
        return f"'{data}'"
    return '"{}"'.format(data.replace('"', "&quot;"))

#: Stroke colours by operation (shop conventions, see the module docstring).
CUT_COLOUR, ENGRAVE_COLOUR = "#ff0000", "#0000ff"
#: A hairline: laser software treats it as a vector path, whatever its width.
STROKE_MM = 0.01


def _num(value: float) -> str:
    # 6 decimals (1 nm) like the 3MF; strip noise so equal geometry gives equal bytes
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


class _Canvas:
    """Coordinates into SVG user units: mm, y flipped about the canvas height."""

    def __init__(self, width_mm: float, height_mm: float) -> None:
        self.width = float(width_mm)
        self.height = float(height_mm)

    def xy(self, point: np.ndarray) -> str:
        return f"{_num(float(point[0]))} {_num(self.height - float(point[1]))}"

    def path(self, path: BulgePath, colour: str) -> str:
        """A closed BulgePath as one SVG path; bulge arcs become exact circular arcs."""
        v = np.asarray(path.vertices, dtype=np.float64)
        n = len(v)
        parts = [f"M {self.xy(v[0])}"]
        for i in range(n):
            p0, p1 = v[i], v[(i + 1) % n]
            bulge = float(path.bulges[i])
            if bulge == 0.0:
                if i < n - 1:
                    parts.append(f"L {self.xy(p1)}")
                continue
            theta = 4.0 * math.atan(bulge)  # included angle, positive counter-clockwise (y up)
            chord = float(np.hypot(*(p1 - p0)))
            radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
            large = 1 if abs(theta) > math.pi else 0
            # y is flipped: a counter-clockwise arc in the drawing is a negative-angle sweep in SVG space
            sweep = 0 if theta > 0 else 1
            parts.append(f"A {_num(radius)} {_num(radius)} 0 {large} {sweep} {self.xy(p1)}")
        parts.append("Z")
        return f'<path d="{" ".join(parts)}" {_stroke(colour)}/>'

    def circle(self, centre: np.ndarray, diameter: float, colour: str, title: str = "") -> str:
        head = (f'<circle cx="{_num(float(centre[0]))}" cy="{_num(self.height - float(centre[1]))}" '
                f'r="{_num(diameter / 2.0)}" {_stroke(colour)}')
        return f"{head}><title>{escape(title)}</title></circle>" if title else f"{head}/>"

    def outlines(self, rings: Sequence[np.ndarray], colour: str, title: str) -> str:
        """Closed polygons (a label's glyphs) as one path of straight segments, titled with the text."""
        d = " ".join("M " + " L ".join(self.xy(p) for p in ring) + " Z" for ring in rings)
        return f'<path d="{d}" {_stroke(colour)}><title>{escape(title)}</title></path>'

    def document(self, title: str, body: Sequence[str]) -> bytes:
        head = (f'<?xml version="1.0" encoding="UTF-8"?>\n'
                f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" '
                f'width="{_num(self.width)}mm" height="{_num(self.height)}mm" '
                f'viewBox="0 0 {_num(self.width)} {_num(self.height)}">\n'
                f"<title>{escape(title)}</title>\n")
        return (head + "\n".join(body) + "\n</svg>\n").encode("utf-8")


def _stroke(colour: str) -> str:
    return f'fill="none" stroke={quoteattr(colour)} stroke-width="{_num(STROKE_MM)}"'


def _part_elements(canvas: _Canvas, part: Part, kerf_mm: float, placement: Placement | None,
                   label: Label | str | None, min_text_mm: float, colours: tuple[str, str]) -> list[str]:
    from fabricate.export.dxf import DxfStyle, cut_geometry, engraved_label, hole_label

    outline, holes, slots = cut_geometry(part, kerf_mm)

    def place(points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, dtype=np.float64)
        return placement.apply(points) if placement is not None else points

    def placed(path: BulgePath) -> BulgePath:
        return BulgePath(place(path.vertices), np.asarray(path.bulges, dtype=np.float64))

    cut, engrave = colours
    elements = [f'<g id={quoteattr(part.name)}>']
    elements += [canvas.circle(place(centre[None, :])[0], diameter, cut,
                               f"{hole.joint}: {hole_label(part, hole)}; cut path Ø{_num(diameter)}")
                 for hole, (centre, diameter) in zip(part.holes, holes, strict=True)]
    elements += [canvas.path(placed(slot), cut) for slot in slots]
    elements.append(canvas.path(placed(outline), cut))
    if not isinstance(label, Label):  # the name (or text) where it fits at the smallest legible size, else none
        label = engraved_label(part, DxfStyle(min_text_mm=min_text_mm, labels="outlines"), label)
    if label is not None:
        elements.append(canvas.outlines([place(ring) for ring in label.polygons()], engrave, label.text))
    elements.append("</g>")
    return elements


def part_svg(part: Part, kerf_mm: float, *, min_text_mm: float = 0.0,
             colours: tuple[str, str] = (CUT_COLOUR, ENGRAVE_COLOUR), margin_mm: float = 1.0,
             label: Label | str | None = None) -> bytes:
    """SVG of one part's cut path (kerf-compensated like its DXF), on a canvas just around it.

    Parameters
    ----------
    part : Part
    kerf_mm : float
        Outlines are offset out and holes in by half of it (0: the finished size, for drawings).
    min_text_mm : float
        Labels smaller than this are left out (the process's smallest legible engraving).
    colours : (str, str)
        Cut and engrave stroke colours.
    margin_mm : float
        Empty border around the part.
    label : Label or str, optional
        The placed label, or a text to fit ("": none; default: the name where it fits at ``min_text_mm``,
        see :func:`fabricate.export.dxf.engraved_label`).
    """
    from fabricate.export.dxf import cut_geometry

    outline = cut_geometry(part, kerf_mm)[0].polygon(0.05)
    lo = outline.min(axis=0) - margin_mm
    hi = outline.max(axis=0) + margin_mm
    shift = Placement(0.0, -lo, 0, hi - lo)
    canvas = _Canvas(*(hi - lo))
    return canvas.document(part.name, _part_elements(canvas, part, kerf_mm, shift, label, min_text_mm, colours))


def sheet_svg(parts: Sequence[Part], kerf_mm: float, placements: Sequence[Placement], sheet_mm: tuple[float, float],
              sheet: int, *, title: str = "sheet", min_text_mm: float = 0.0,
              colours: tuple[str, str] = (CUT_COLOUR, ENGRAVE_COLOUR),
              labels: Sequence[Label | str | None] | None = None) -> bytes:
    """SVG of sheet number ``sheet``: the parts placed on it, the canvas the sheet's size (mm).

    ``labels``: each part's placed label, in the order of ``parts`` (default as :func:`part_svg`)."""
    canvas = _Canvas(*sheet_mm)
    body: list[str] = []
    for k, (part, placement) in enumerate(zip(parts, placements, strict=True)):
        if placement.sheet == sheet:
            body += _part_elements(canvas, part, kerf_mm, placement, None if labels is None else labels[k],
                                   min_text_mm, colours)
    return canvas.document(f"{title} {sheet + 1}", body)
