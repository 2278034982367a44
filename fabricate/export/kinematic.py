"""The kinematic drawing (``drawings/kinematic.dxf``): joints, link centre lines and their dimensions at one pose.

Its documents come from :mod:`fabricate.export.dxf` (R2010 in mm, fixed metadata). Every text is black (by
layer, ACI 7) or blue (dimensions), which prints on white paper. The dimensions are aligned and linear ones
only: LibreCAD 2.2 draws no ordinate dimension and FreeCAD 0.20's importer reads one as the length of its
leader. Labels are placed where their box, measured with ezdxf's font metrics, meets no other text.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

import ezdxf
import ezdxf.bbox
import numpy as np
import shapely
import shapely.ops

from fabricate.errors import GeometryError
from fabricate.export.dxf import DIMSTYLE, MIN_DRAWING_TEXT_MM, document_bytes, new_document
from fabricate.planar import transform_points

if TYPE_CHECKING:
    from fabricate.mechanism import Mechanism


#: Layer colours for paper (ACI): 7 prints black on white (white on a dark screen), 5 is blue; never yellow
#: (2) or cyan (4), which vanish on white paper.
PAPER_COLOURS = {"LINKS": 7, "JOINTS": 7, "LABELS": 7, "DIMENSIONS": 5, "COORDINATES": 5}

#: Label candidates: distances of the label box from its point (text heights) and directions tried, in order
#: (up-right first, where the drawing always put it); past the first ring a leader joins label and point.
_RINGS = (0.5, 1.5, 3.0, 4.5, 6.5, 9.0, 12.0, 16.0, 21.0, 28.0, 36.0, 46.0, 60.0, 80.0, 110.0, 150.0)
_DIRECTIONS = tuple(math.radians(a) for a in (45, 135, -45, -135, 90, -90, 0, 180, 22.5, 157.5, -22.5, -157.5,
                                              67.5, 112.5, -67.5, -112.5))


def kinematic_dxf(mechanism: Mechanism, poses: Mapping[str, np.ndarray]) -> bytes:
    """Kinematic drawing at one pose: joints, link centre lines, link-length and joint-coordinate dimensions.

    Links get aligned dimensions of their length on layer ``DIMENSIONS``. Every joint is located from the
    world origin by linear dimensions on layer ``COORDINATES``: its x in rows below the drawing, its y in
    columns left of it (baseline dimensioning, shortest nearest; positive and negative values in separate
    rows, so no two texts meet). They are plain linear dimensions, which LibreCAD draws and FreeCAD reads at
    their value (ordinate dimensions are not drawn by LibreCAD and FreeCAD reads them as their leader's
    length). Each point is labelled with its names and world coordinates, the label placed where its box
    meets no other label, dimension text, circle or link line (a leader joins it to its point when it
    stands off).

    Parameters
    ----------
    mechanism : Mechanism
    poses : Mapping[str, (3,) array]
        World pose of every body (the first pose of the motion).
    """
    doc = new_document(("LINKS", "JOINTS", "DIMENSIONS", "LABELS"), dimensions=True)
    doc.layers.add("COORDINATES")
    for name, colour in PAPER_COLOURS.items():
        doc.layers.get(name).color = colour
    msp = doc.modelspace()
    joint_names = {j.name for j in mechanism.joints}
    world: dict[str, np.ndarray] = {}
    for body in mechanism.bodies:
        for name in body.points:
            world.setdefault(name, transform_points(poses[body.name], body.point(name)))
    span = max(1.0, float(np.ptp(np.array(list(world.values())), axis=0).max())) if world else 1.0
    text_h = round(max(MIN_DRAWING_TEXT_MM, span / 60.0), 3)
    # the sizes go in a dimension style of their own (readers ignore per-entity overrides) and in the
    # drawing's header variables, which LibreCAD sizes every dimension by
    sizes = {"dimtxt": text_h, "dimasz": text_h, "dimdec": 3, "dimlfac": 1.0, "dimexo": 0.5 * text_h,
             "dimexe": 0.5 * text_h, "dimgap": 0.3 * text_h, "dimtad": 1}
    doc.dimstyles.new(DIMSTYLE, dxfattribs=dict(sizes))  # ezdxf adds its name to the dict it is given
    for variable, value in sizes.items():
        doc.header[f"${variable.upper()}"] = value
    obstacles = _draw_links(msp, mechanism, poses, joint_names, text_h, sizes)  # what a label must not touch
    # points at one spot (a compound hinge) get one label and one pair of coordinate dimensions
    spots: dict[tuple[float, float], list[str]] = {}
    for name in sorted(world):
        spots.setdefault((round(float(world[name][0]), 6), round(float(world[name][1]), 6)), []).append(name)
    circles = []
    for names in spots.values():
        p = world[names[0]]
        is_joint = any(n in joint_names for n in names)
        radius = 0.6 * text_h if is_joint else 0.3 * text_h
        msp.add_circle(tuple(p), radius, dxfattribs={"layer": "JOINTS" if is_joint else "LABELS"})
        obstacles.append(shapely.Point(p).buffer(radius, quad_segs=4))
        circles.append((names, p, radius, is_joint))
    joints = [p for _, p, _, is_joint in circles if is_joint]
    if joints:
        # below and left of everything drawn so far (points, links and their dimensions)
        drawn_low = np.min([np.array(list(world.values())).min(axis=0)]
                           + [np.array(g.bounds[:2]) for g in obstacles], axis=0)
        obstacles += _coordinate_dimensions(msp, np.array(joints), drawn_low - 2.0 * text_h, text_h)
    # a label keeps a text height clear of every other point, so that it is read as its own point's
    clear = [shapely.Point(q).buffer(r + text_h, quad_segs=4) for _, q, r, _ in circles]  # each point's, once
    for k, (names, p, radius, _) in enumerate(circles):
        others = clear[:k] + clear[k + 1:]
        _place_label(msp, f"{', '.join(names)} ({p[0]:.3f}, {p[1]:.3f})", p, radius, text_h, obstacles,
                     shapely.union_all(others) if others else shapely.Polygon())
    return document_bytes(doc)


def _draw_links(msp: Any, mechanism: Mechanism, poses: Mapping[str, np.ndarray], joint_names: set[str],
                text_h: float, sizes: dict[str, float]) -> list[shapely.Geometry]:
    """Each link's centre line between every two of its body's joints (every two points of a body without
    joints) and its aligned length dimension, each pair once; returns what they draw (lines, dimension text
    boxes and lines) for the labels to keep off."""
    # link dimensions are tried out in a scratch document (a dimension's text box is known once rendered)
    scratch = new_document(("DIMENSIONS",), dimensions=True)
    scratch.dimstyles.new(DIMSTYLE, dxfattribs=dict(sizes))
    obstacles: list[shapely.Geometry] = []
    dimension_texts: list[shapely.Geometry] = []  # what a link dimension's text must not touch
    drawn: set[tuple[str, ...]] = set()
    for body in mechanism.bodies:
        names = [n for n in body.points if n in joint_names] or list(body.points)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                key = tuple(sorted((a, b)))
                pa = transform_points(poses[body.name], body.point(a))
                pb = transform_points(poses[body.name], body.point(b))
                length = float(np.hypot(*(pb - pa)))
                if key in drawn or length < 1e-6:
                    continue
                drawn.add(key)
                msp.add_line(tuple(pa), tuple(pb), dxfattribs={"layer": "LINKS"})
                obstacles.append(shapely.LineString([pa, pb]))
                distance = _link_dimension_offset(scratch.modelspace(), pa, pb, text_h, dimension_texts)
                dim = msp.add_aligned_dim(p1=tuple(pa), p2=tuple(pb), distance=distance, dimstyle=DIMSTYLE,
                                          dxfattribs={"layer": "DIMENSIONS"})
                dim.render()
                texts, lines = _dimension_shapes(dim.dimension)
                obstacles += texts + lines
                dimension_texts += texts
    return obstacles


def _link_dimension_offset(scratch: Any, pa: np.ndarray, pb: np.ndarray, text_h: float,
                           texts: list[Any]) -> float:
    """How far (mm, signed: which side) a link's aligned dimension stands off the link: 3 text heights on its
    left unless its text would then meet another dimension's; then the first of further offsets, either
    side, where it meets none (3 text heights when none is free)."""
    if not texts:  # no other dimension's text to meet: the first offset, without rendering a trial
        return 3.0 * text_h
    tree = shapely.STRtree(texts)
    for steps in (3.0, -3.0, 4.5, -4.5, 6.0, -6.0, 8.0, -8.0, 10.0, -10.0, 12.5, -12.5):
        trial = scratch.add_aligned_dim(p1=tuple(pa), p2=tuple(pb), distance=steps * text_h, dimstyle=DIMSTYLE)
        trial.render()
        boxes = dimension_text_boxes(trial.dimension)
        scratch.delete_entity(trial.dimension)
        if not any(len(tree.query(box.buffer(0.2 * text_h, join_style="mitre"), predicate="intersects"))
                   for box in boxes):
            return steps * text_h
    return 3.0 * text_h


def _coordinate_dimensions(msp: Any, joints: np.ndarray, low: np.ndarray, text_h: float) -> list[Any]:
    """Linear dimensions from the world origin to every joint's x (rows below ``low`` y) and y (columns left
    of ``low`` x); returns their text boxes and lines.

    Rows go out by length (a longer dimension's extension line then crosses no shorter one), positive values
    before negative ones; a value too short to hold its text between the arrows (which readers then set
    beside an arrow, along the row) goes to the outermost rows, where no extension line crosses that text.
    """
    boxes = []
    for axis, angle in ((0, 0.0), (1, 90.0)):
        values = sorted({round(float(v), 6) for v in joints[:, axis]} - {0.0},
                        key=lambda v: (abs(v) < 6.0 * text_h, v < 0, abs(v)))
        for row, value in enumerate(values):
            target = joints[np.argmin(np.abs(joints[:, axis] - value))]
            # 3.5 text heights a row: a text set on either side of its line (readers choose) meets no other row's
            base = [0.0, 0.0]
            base[1 - axis] = float(low[1 - axis] - 3.5 * text_h * row)
            dim = msp.add_linear_dim(base=tuple(base), p1=(0.0, 0.0), p2=tuple(float(c) for c in target),
                                     angle=angle, dimstyle=DIMSTYLE, dxfattribs={"layer": "COORDINATES"})
            dim.render()
            boxes += _dimension_marks(dim.dimension)
    return boxes


def dimension_text_boxes(dimension: Any) -> list[shapely.Polygon]:
    """Boxes (shapely, model space) of the text a rendered DIMENSION shows."""
    return _dimension_shapes(dimension)[0]


def _dimension_shapes(dimension: Any) -> tuple[list[shapely.Polygon], list[shapely.LineString]]:
    """What a rendered DIMENSION draws, as shapes a label must keep off: its text boxes and its lines (from one
    pass over its virtual entities: each pass renders the dimension's block again)."""
    boxes, lines = [], []
    for entity in dimension.virtual_entities():
        kind = entity.dxftype()
        if kind in ("MTEXT", "TEXT"):
            extents = ezdxf.bbox.extents([entity])
            boxes.append(shapely.box(extents.extmin.x, extents.extmin.y, extents.extmax.x, extents.extmax.y))
        elif kind == "LINE":
            lines.append(shapely.LineString([tuple(entity.dxf.start)[:2], tuple(entity.dxf.end)[:2]]))
    return boxes, lines


def _dimension_marks(dimension: Any) -> list[Any]:
    """What a rendered DIMENSION draws, as shapes a label must keep off: its text boxes and its lines."""
    boxes, lines = _dimension_shapes(dimension)
    return boxes + lines


def text_box(text: Any) -> shapely.Polygon:
    """Box (shapely, model space) of a TEXT entity, from ezdxf's font metrics."""
    extents = ezdxf.bbox.extents([text])
    return shapely.box(extents.extmin.x, extents.extmin.y, extents.extmax.x, extents.extmax.y)


def _place_label(msp: Any, label: str, p: np.ndarray, radius: float, text_h: float,
                 obstacles: list[Any], others: Any) -> None:
    """A point's label at the first candidate spot whose box (with a margin) meets no obstacle and not
    ``others`` (the region round the other points), with a leader from the point's circle when it stands
    off; the box and leader join the obstacles."""
    text = msp.add_text(label, height=text_h, dxfattribs={"layer": "LABELS"})
    text.set_placement((0.0, 0.0), align=ezdxf.enums.TextEntityAlignment.BOTTOM_LEFT)
    box = text_box(text)
    x0, y0, x1, y1 = box.bounds
    half = np.array([0.5 * (x1 - x0), 0.5 * (y1 - y0)])
    centre_offset = np.array([0.5 * (x0 + x1), 0.5 * (y0 + y1)])  # the box centre from the insert point
    tree = shapely.STRtree(obstacles)
    best = first_free = None
    # first a spot whose leader crosses no text; failing that (a point inside a crowd of texts) the first free box
    for index, centre, candidate in _free_boxes(p, radius, half, text_h, tree, others):
        ring, u = _CANDIDATE_RINGS[index], np.array(_CANDIDATE_DIRECTIONS[index])
        leader = None
        if ring > 1.5:
            near = shapely.ops.nearest_points(candidate, shapely.Point(p))[0]
            # from just outside the point's own circle (an obstacle too) to the box's nearest point
            leader = shapely.LineString([p + u * (radius + 0.1 * text_h), (near.x, near.y)])
        if first_free is None:
            first_free = (centre, leader, candidate)
        if leader is None or not _crosses_text(leader, obstacles, tree):
            best = (centre, leader, candidate)
            break
    best = best or first_free
    if best is None:  # the outermost ring lies beyond everything drawn: cannot happen
        raise GeometryError(f"kinematic drawing: no room for the label {label!r}")
    centre, leader, candidate = best
    insert = centre - centre_offset
    text.set_placement((float(insert[0]), float(insert[1])), align=ezdxf.enums.TextEntityAlignment.BOTTOM_LEFT)
    if leader is not None:
        (a, b) = leader.coords
        msp.add_line(tuple(a), tuple(b), dxfattribs={"layer": "LABELS"})
        obstacles.append(leader)
    obstacles.append(candidate)


#: The label candidates in the order they are tried, ring by ring: each one's ring and direction (cos, sin).
_CANDIDATE_RINGS = tuple(ring for ring in _RINGS for _ in _DIRECTIONS)
_CANDIDATE_DIRECTIONS = tuple((math.cos(a), math.sin(a)) for _ in _RINGS for a in _DIRECTIONS)
#: Candidates tested at once: two rings (most labels find room within the first few rings).
_CHUNK = 2 * len(_DIRECTIONS)


def _free_boxes(p: np.ndarray, radius: float, half: np.ndarray, text_h: float, tree: shapely.STRtree,
                others: Any) -> Iterator[tuple[int, np.ndarray, shapely.Polygon]]:
    """The candidate label boxes (half size ``half``) round point ``p`` whose box, with a margin of a quarter
    text height, meets no obstacle in ``tree`` and not ``others``, in candidate order: (index, box centre,
    box). Each box's centre puts its nearest side its ring's text heights beyond the circle along its
    direction. A chunk of candidates is tested at once (shapely's array functions, the same arithmetic and
    predicates as one at a time)."""
    margin = 0.25 * text_h
    rings, directions = np.array(_CANDIDATE_RINGS), np.array(_CANDIDATE_DIRECTIONS)
    for start in range(0, len(rings), _CHUNK):
        ring, u = rings[start:start + _CHUNK], directions[start:start + _CHUNK]
        reach = radius + ring * text_h + np.minimum(half[0] / np.maximum(np.abs(u[:, 0]), 1e-9),
                                                    half[1] / np.maximum(np.abs(u[:, 1]), 1e-9))
        centres = p + u * reach[:, None]
        low, high = centres - half, centres + half
        boxes = shapely.box(low[:, 0], low[:, 1], high[:, 0], high[:, 1])
        blocked = shapely.intersects(boxes, others)
        blocked[tree.query(shapely.buffer(boxes, margin, join_style="mitre"), predicate="intersects")[0]] = True
        for k in np.flatnonzero(~blocked):
            yield start + int(k), centres[k], boxes[k]


def _crosses_text(leader: shapely.LineString, obstacles: list[Any], tree: shapely.STRtree) -> bool:
    """Whether a leader crosses a text box (a rectangle) it does not start inside (a dimension's text over the
    point: no leader avoids it); crossing lines and the circles of close points is allowed."""
    start = shapely.Point(leader.coords[0])
    return any(obstacles[i].geom_type == "Polygon" and len(obstacles[i].exterior.coords) == 5
               and not obstacles[i].contains(start) for i in tree.query(leader, predicate="intersects"))
