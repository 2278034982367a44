"""STEP (ISO 10303-21, AP214) export of parts and the assembly as B-rep solids, through OCP.

Mechanical CAD (SolidWorks, Fusion, Onshape, FreeCAD) wants solids, not meshes: every part becomes a
planar face bounded by its exact profile (lines, true circular arcs for bulges, full circles for holes,
slots as inner wires) extruded by its thickness. A profile fused with polygons (gear teeth, hubs, pads)
arrives as a polygon within the chord tolerance of its curves; :mod:`fabricate.export.step_curves` puts
them back: polygonised circles as true arcs, gear flanks as a few smooth B-spline faces per tooth. Such a
solid's volume differs from the report's (the polygon's) by at most the chord tolerance times its curved
side area, which the file states (:mod:`fabricate.export.step_read`); elsewhere it is the report's exactly.

This module, :mod:`~fabricate.export.step_curves` and :mod:`~fabricate.export.step_read` are the only ones
importing OCP (the optional extra ``cad``: the ``cadquery-ocp-novtk`` wheel). It is imported lazily, inside
the functions, so the package works without it; :func:`step_available` says whether it is there.

Encoders return bytes and are deterministic: OCP writes files only, so each encoder writes into a private
temporary folder, reads the file back and deletes it; the header's time stamp, author, organisation and
originating system are set to fixed values (a rebuild gives the same bytes).
"""

from __future__ import annotations

import functools
import importlib.util
import math
import os
import re
import tempfile
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from fabricate.errors import FabricateError, GeometryError
from fabricate.export.occt import DESCRIPTION, downcast, quiet_occt, shape_volume, xcaf_document
from fabricate.export.step_curves import clean_path, profile_pieces, spline_edges
from fabricate.parts.model import BulgePath, Part

__all__ = ["assembly_step", "part_shape", "part_step", "step_available", "step_files"]

#: Fixed header values: STEP's FILE_NAME carries a time stamp and who wrote it; a rebuild must give the
#: same bytes, so none of it may depend on the clock, the user or the OCCT build.
HEADER_TIME_STAMP = "2000-01-01T00:00:00"
HEADER_SYSTEM = "fabricate"

#: Relative agreement of a solid's volume (OCCT's Gauss integration of exact planes and cylinders) with the
#: part's exact volume; measured ~1e-12, so 1e-9 leaves room without hiding a wrong hole or arc.
VOLUME_REL_TOL = 1e-9

#: Shortest edge kept (mm): a repeated vertex in a profile would make a zero-length edge, which OCCT refuses.
_MIN_EDGE_MM = 1e-9



@functools.lru_cache(maxsize=1)
def step_available() -> bool:
    """Whether OCP (the optional extra ``cad``) is installed, so STEP files can be written.

    Found by its import spec, not imported: importing OCP takes about 0.9 s and 220 MB, which a build's main
    process does not need (its STEP files are written by the picture child, where :func:`step_files` imports
    it). An OCP that is found but does not import fails there, named (:func:`_import_ocp`).
    """
    try:
        return importlib.util.find_spec("OCP") is not None
    except (ImportError, ValueError):  # a finder refusing it (ModuleNotFoundError), a module without __spec__
        return False


def _import_ocp() -> None:
    """Import OCP's STEP writer (the slow part: its one extension module), or say why it does not import.

    Raises
    ------
    FabricateError
        OCP is installed (:func:`step_available`) but its import fails: a broken ``cad`` extra.
    KeyboardInterrupt
        A Ctrl-C landing in the import: pybind11 reports any exception during a module's init as an
        ImportError, and a Ctrl-C must stay a Ctrl-C, not become a broken install.
    """
    try:
        import OCP.STEPCAFControl  # noqa: F401
    except ImportError as exc:
        cause = exc.__cause__ or exc.__context__
        while cause is not None:
            if isinstance(cause, KeyboardInterrupt):
                raise cause from None
            cause = cause.__cause__ or cause.__context__
        raise FabricateError(f"OCP (the 'cad' extra) is installed but does not import ({exc}): reinstall it "
                             "(pip install 'fabricate[cad]') or uninstall it to build without STEP") from exc


# ---------------------------------------------------------------------------------------------- building


def _vertex(point: np.ndarray) -> Any:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.gp import gp_Pnt

    return BRepBuilderAPI_MakeVertex(gp_Pnt(float(point[0]), float(point[1]), 0.0)).Vertex()


def _arc_circle(p0: np.ndarray, p1: np.ndarray, bulge: float) -> Any:
    """The circle (gp_Circ in z = 0) carrying the arc from ``p0`` to ``p1`` with ``bulge``, oriented so its
    parameter runs from ``p0`` to ``p1`` along the arc: axis +z for a counter-clockwise (positive) bulge."""
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt

    theta = 4.0 * math.atan(bulge)
    chord_vec = p1 - p0
    chord = float(np.hypot(*chord_vec))
    radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
    # same construction as fabricate.parts.model.arc_circle (the centre left of the chord for a CCW arc), not a
    # call to it: it rounds normal * (radius * cos) where this rounds (normal * radius) * cos, 17 of the shipped
    # templates' 153 arc centres differ by <= 3.6e-15 mm, so either one's order changes files (21 STEP, or tip.dxf)
    normal = np.array([-chord_vec[1], chord_vec[0]]) / chord
    centre = 0.5 * (p0 + p1) + math.copysign(1.0, theta) * normal * radius * math.cos(theta / 2.0)
    axis = gp_Dir(0.0, 0.0, 1.0 if theta > 0 else -1.0)
    start = (p0 - centre) / radius
    frame = gp_Ax2(gp_Pnt(float(centre[0]), float(centre[1]), 0.0), axis,
                   gp_Dir(float(start[0]), float(start[1]), 0.0))
    return gp_Circ(frame, radius)


def _path_wire(path: BulgePath, counter_clockwise: bool, what: str, chord_tolerance_mm: float) -> Any:
    """A closed wire of the path's lines, true arcs and B-spline runs, turned to the asked orientation.

    The path is split by :func:`fabricate.export.step_curves.profile_pieces`: its arcs and the polygonised
    circles in it become circular edges, smooth runs of short lines (gear flanks) a few B-splines each (see
    :func:`~fabricate.export.step_curves.spline_edges`). Vertices are made once and shared by the edges
    meeting there, so the wire closes exactly (no tolerance-based vertex matching).
    """
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire

    vertices = np.asarray(path.vertices, dtype=np.float64)
    bulges = np.asarray(path.bulges, dtype=np.float64)
    if (path.area() > 0) != counter_clockwise:
        # the reversed path visits the vertices backwards; each arc keeps its circle with the opposite sense
        vertices = vertices[::-1]
        bulges = -np.roll(bulges[::-1], -1)
    # a dropped (zero-length) segment merges its two vertices: keep the first of each run
    vertices, bulges = clean_path(vertices, bulges, _MIN_EDGE_MM)
    if len(vertices) < 2 or (len(vertices) == 2 and not np.any(bulges)):
        raise GeometryError(f"{what}: degenerate profile of {len(vertices)} edges")
    made: dict[int, Any] = {}

    def vertex(index: int) -> Any:
        if index not in made:
            made[index] = _vertex(vertices[index])
        return made[index]

    wire = BRepBuilderAPI_MakeWire()
    for piece in profile_pieces(vertices, bulges):
        if piece.kind == "spline":
            edges = spline_edges(piece.points, piece.start, len(vertices), vertex, chord_tolerance_mm)
        elif piece.kind == "arc":
            edges = [BRepBuilderAPI_MakeEdge(_arc_circle(vertices[piece.start], vertices[piece.end], piece.bulge),
                                             vertex(piece.start), vertex(piece.end))]
        else:
            edges = [BRepBuilderAPI_MakeEdge(vertex(piece.start), vertex(piece.end))]
        for edge in edges:
            if not edge.IsDone():
                raise GeometryError(f"{what}: edge from vertex {piece.start} of the profile could not be made")
            wire.Add(edge.Edge())
            if not wire.IsDone():
                raise GeometryError(f"{what}: the edge from vertex {piece.start} does not continue the profile")
    return wire.Wire()


def _circle_wire(centre: np.ndarray, diameter_mm: float) -> Any:
    """A clockwise full-circle wire (an inner boundary of a face lying on +z)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt

    frame = gp_Ax2(gp_Pnt(float(centre[0]), float(centre[1]), 0.0), gp_Dir(0.0, 0.0, -1.0))
    edge = BRepBuilderAPI_MakeEdge(gp_Circ(frame, 0.5 * float(diameter_mm))).Edge()
    return BRepBuilderAPI_MakeWire(edge).Wire()


def part_shape(part: Part, chord_tolerance_mm: float, z_mm: float = 0.0) -> Any:
    """The part as an OCP B-rep solid: its profile in z = ``z_mm`` extruded by its thickness along +z.

    Parameters
    ----------
    part : Part
        Outline (lines and arcs, CCW or CW: turned CCW here), holes (full circles) and, for parts that
        have them, ``slots`` (closed bulge paths cut through the plate); mm in body coordinates.
    chord_tolerance_mm : float
        The build's chord tolerance (mm): how far the polygon of a fused profile is from its curves, so how
        far the arcs and B-splines put back may stand from the polygon (and the solid's volume from the
        part's); a tenth of it is the tolerance handed to OCCT's shape fixing.
    z_mm : float
        Height of the bottom face: 0 for the part's own file, ``part.z_mm`` for an assembly.

    Returns
    -------
    OCP.TopoDS.TopoDS_Solid

    Raises
    ------
    GeometryError
        When a face or solid cannot be made, or the result is not a valid closed solid of positive volume.
    """
    what = f"part {part.name}: STEP solid"
    try:
        return _solid(part, chord_tolerance_mm, z_mm, what)
    except Exception as exc:
        # OCCT's exceptions (StdFail_NotDone, Standard_ConstructionError, ...) share no Python base class
        # but their module; they mean this geometry cannot be made, which the pipeline reports as such
        if type(exc).__module__.startswith("OCP"):
            raise GeometryError(f"{what}: {type(exc).__name__} {exc}".rstrip()) from exc
        raise


def _solid(part: Part, chord_tolerance_mm: float, z_mm: float, what: str) -> Any:
    """:func:`part_shape` without the translation of OCCT's exceptions."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Transform
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Trsf, gp_Vec
    from OCP.ShapeFix import ShapeFix_Face
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    if not part.thickness_mm > 0:
        raise GeometryError(f"{what}: thickness {part.thickness_mm} mm")
    outer = _path_wire(part.outline, True, what, chord_tolerance_mm)
    face_maker = BRepBuilderAPI_MakeFace(outer, True)
    if not face_maker.IsDone():
        raise GeometryError(f"{what}: the outline is not a planar face")
    for hole in part.holes:
        face_maker.Add(_circle_wire(np.asarray(hole.centre, dtype=np.float64), hole.diameter_mm))
    for slot in getattr(part, "slots", ()):
        face_maker.Add(_path_wire(slot, False, what, chord_tolerance_mm))
    face = face_maker.Face()
    # the face is what can be wrong (a hole or slot crossing the outline or each other, a self-touching
    # outline); a prism of a valid planar face along its normal is valid by construction, and checking the
    # face costs a third of checking the solid (the wire self-intersection test is quadratic in the edges
    # of a gear outline)
    if not BRepCheck_Analyzer(face).IsValid():
        # tolerance-level defects (an arc end off its circle by rounding) mend; crossings do not, and the
        # area test below would catch a "mend" that changed the part
        fixer = ShapeFix_Face(face)
        fixer.SetPrecision(0.1 * chord_tolerance_mm)
        fixer.Perform()
        face = fixer.Face()
        if not BRepCheck_Analyzer(face).IsValid():
            raise GeometryError(f"{what}: not a valid face (a hole or slot crosses the outline or another)")
    prism = BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, float(part.thickness_mm)))
    if not prism.IsDone():
        raise GeometryError(f"{what}: the extrusion failed")
    explorer = TopExp_Explorer(prism.Shape(), TopAbs_SOLID)
    if not explorer.More():
        raise GeometryError(f"{what}: the extrusion is not a solid")
    solid = downcast("Solid", explorer.Current())
    # the solid must hold the part's volume (its path's area with arcs, minus holes and slots, times the
    # thickness), but where curves replaced a polygon's chords: each within the chord tolerance of them
    volume, expected = shape_volume(solid), part.volume_mm3()
    if not abs(volume - expected) <= VOLUME_REL_TOL * abs(expected) + volume_band_mm3(part, chord_tolerance_mm):
        raise GeometryError(f"{what}: volume {volume:.6f} mm^3, the part's is {expected:.6f} mm^3")
    if z_mm:
        lift = gp_Trsf()
        lift.SetTranslation(gp_Vec(0.0, 0.0, float(z_mm)))
        solid = downcast("Solid", BRepBuilderAPI_Transform(solid, lift, True).Shape())
    return solid


def volume_band_mm3(part: Part, chord_tolerance_mm: float) -> float:
    """How far the solid's volume may lie from the part's (:meth:`Part.volume_mm3`, its polygon's where the
    path is one): the chord tolerance times the thickness times the length of the straight segments of
    outline and slots, which arcs and splines within that tolerance of them may replace."""
    length = 0.0
    for path in (part.outline, *getattr(part, "slots", ())):
        v = np.asarray(path.vertices, dtype=np.float64)
        chords = np.hypot(*(np.roll(v, -1, axis=0) - v).T)
        length += float(chords[np.asarray(path.bulges) == 0.0].sum())
    return chord_tolerance_mm * part.thickness_mm * length


def _pose_location(pose: np.ndarray, z_mm: float) -> Any:
    """TopLoc_Location of a planar body pose (x mm, y mm, theta rad) lifted to ``z_mm``; the same motion
    as :func:`fabricate.planar.pose_matrix` applies to the meshes."""
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    rotate, move = gp_Trsf(), gp_Trsf()
    rotate.SetRotation(gp_Ax1(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(0.0, 0.0, 1.0)), float(pose[2]))
    move.SetTranslation(gp_Vec(float(pose[0]), float(pose[1]), float(z_mm)))
    return TopLoc_Location(move.Multiplied(rotate))


# ----------------------------------------------------------------------------------------------- writing


def _set_name(label: Any, name: str) -> None:
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name

    TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))


_FILE_NAME = re.compile(rb"FILE_NAME\(.*?\);\s*\n", re.DOTALL)
_OCCURRENCE_ID = re.compile(rb"(NEXT_ASSEMBLY_USAGE_OCCURRENCE\s*\(\s*')\d+'")
#: One whole occurrence entity, continuation lines included (the writer wraps it where the counter's digits
#: pushed it; after renumbering, the same entity is put on one line so the wrap no longer depends on them)
_OCCURRENCE_ENTITY = re.compile(rb"NEXT_ASSEMBLY_USAGE_OCCURRENCE\(.*?\);", re.DOTALL)
_CONTINUATION = re.compile(rb"\r?\n[ \t]*")


def _write(document: Any, title: str, chord_tolerance_mm: float) -> bytes:
    """The XCAF document as STEP AP214 bytes with a fixed header (see module docstring)."""
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs

    writer = STEPCAFControl_Writer()
    # global OCCT settings, set on every call (after the first writer exists: making it initialises the
    # STEP controller, which resets them to defaults) so the first file of a process is like the others.
    # No p-curves (write.surfacecurve.mode 0): every edge lies on planes or cylinders that any importer
    # intersects exactly; they would make the files 2.5 times larger and the writing slower
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetIVal_s("write.surfacecurve.mode", 0)
    Interface_Static.SetCVal_s("write.step.product.name", title)
    writer.SetNameMode(True)
    writer.SetColorMode(False)
    writer.SetLayerMode(False)
    folder = tempfile.mkdtemp(prefix="fabricate-step-")
    path = os.path.join(folder, "out.step")
    try:
        with quiet_occt():
            if not writer.Transfer(document, STEPControl_AsIs):
                raise GeometryError(f"{title}: STEP transfer failed")
            _fix_header(writer.ChangeWriter().Model(), title, chord_tolerance_mm)
            status = writer.Write(path)
        with open(path, "rb") as handle:
            data = handle.read()
    except OSError as exc:
        raise GeometryError(f"{title}: STEP could not be written ({exc})") from exc
    finally:
        if os.path.exists(path):
            os.remove(path)
        os.rmdir(folder)
    from OCP.IFSelect import IFSelect_RetDone

    if status != IFSelect_RetDone:
        raise GeometryError(f"{title}: STEP writer returned {status}")
    return _fixed_file_name(data, title)


def _fix_header(model: Any, title: str, chord_tolerance_mm: float) -> None:
    """Header entities with fixed values (name, time stamp, author, organisation, systems), and a description
    stating the chord tolerance its curves keep to (:data:`fabricate.export.step_read.DESCRIPTION`)."""
    from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
    from OCP.TCollection import TCollection_HAsciiString

    header = APIHeaderSection_MakeHeader(model)
    header.SetName(TCollection_HAsciiString(title))
    header.SetDescriptionValue(1, TCollection_HAsciiString(DESCRIPTION.format(tolerance=chord_tolerance_mm)))
    header.SetTimeStamp(TCollection_HAsciiString(HEADER_TIME_STAMP))
    header.SetAuthorValue(1, TCollection_HAsciiString(""))
    header.SetOrganizationValue(1, TCollection_HAsciiString(""))
    header.SetPreprocessorVersion(TCollection_HAsciiString(HEADER_SYSTEM))
    header.SetOriginatingSystem(TCollection_HAsciiString(HEADER_SYSTEM))
    header.SetAuthorisation(TCollection_HAsciiString(""))
    header.Apply(model)


def _fixed_file_name(data: bytes, title: str) -> bytes:
    """The FILE_NAME header line rewritten to fixed values, whatever the OCCT version put there (the
    writer may stamp the time and its own name at write time, after :func:`_fix_header`)."""
    fixed = (f"FILE_NAME('{_step_string(title)}','{HEADER_TIME_STAMP}',(''),(''),'{HEADER_SYSTEM}',"
             f"'{HEADER_SYSTEM}','');\n").encode("ascii")
    data, count = _FILE_NAME.subn(lambda _: fixed, data, count=1)
    if count != 1:
        raise GeometryError(f"{title}: the STEP writer wrote no FILE_NAME header")
    # OCCT numbers assembly occurrences from a counter that lives as long as the process, so the second
    # assembly written gets ids 9, 10, ... where a fresh process writes 1, 2, ...: number them in file order
    occurrence = iter(range(1, 1 << 31))
    data = _OCCURRENCE_ID.sub(lambda m: m.group(1) + str(next(occurrence)).encode("ascii") + b"'", data)
    # the writer wrapped these lines at 72 columns counting the old id's digits (a 2-digit id moves the
    # break of a long entity by one token): put each occurrence on one line (STEP ignores line breaks
    # between tokens; names are written without newlines, see _step_string)
    return _OCCURRENCE_ENTITY.sub(lambda m: _CONTINUATION.sub(b"", m.group(0)), data)


def _step_string(text: str) -> str:
    """Text as a STEP string body: ASCII only (others become '?'), apostrophes doubled."""
    return text.encode("ascii", "replace").decode("ascii").replace("'", "''")


def part_step(part: Part, chord_tolerance_mm: float, shape: Any = None) -> bytes:
    """STEP AP214 of one part lying on z = 0 in its own (body) coordinates, like its STL; mm.

    Parameters
    ----------
    part : Part
    chord_tolerance_mm : float
        The build's chord tolerance (see :func:`part_shape`).
    shape : TopoDS_Solid, optional
        The part's solid from :func:`part_shape` when the caller has it already (built here otherwise).

    Returns
    -------
    bytes
        One named solid (product name = part name); deterministic.
    """
    document, tool = xcaf_document()
    label = tool.AddShape(shape if shape is not None else part_shape(part, chord_tolerance_mm), False)
    _set_name(label, part.name)
    return _write(document, part.name, chord_tolerance_mm)


def assembly_step(parts: Sequence[Part], poses: Mapping[str, np.ndarray], chord_tolerance_mm: float,
                  title: str = "assembly", shapes: Mapping[str, Any] | None = None) -> bytes:
    """STEP AP214 of the assembly at the given body poses: one named solid per part, mm.

    Each part is its flat solid (as in its own file) placed by its body's pose and lifted to its layer
    height ``z_mm``, the same placement :func:`fabricate.export.stl.assembly_3mf` gives the meshes.

    Parameters
    ----------
    parts : sequence of Part
    poses : Mapping[str, (3,) array]
        World pose of each body (x mm, y mm, theta rad); a body missing stays at the origin.
    chord_tolerance_mm : float
    title : str
        Name of the assembly product.
    shapes : Mapping[str, TopoDS_Solid], optional
        Part name -> its solid from :func:`part_shape` (built here for any part missing).

    Returns
    -------
    bytes
        Deterministic STEP text.
    """
    shapes = shapes or {}
    document, tool = xcaf_document()
    assembly = tool.NewShape()
    _set_name(assembly, title)
    for part in parts:
        shape = shapes.get(part.name)
        label = tool.AddShape(shape if shape is not None else part_shape(part, chord_tolerance_mm), False)
        _set_name(label, part.name)
        pose = np.asarray(poses.get(part.body, np.zeros(3)), dtype=np.float64)
        component = tool.AddComponent(assembly, label, _pose_location(pose, part.z_mm))
        _set_name(component, part.name)
    tool.UpdateAssemblies()
    return _write(document, title, chord_tolerance_mm)


def step_files(parts: Sequence[Part], poses: Mapping[str, np.ndarray], chord_tolerance_mm: float,
               title: str = "assembly") -> dict[str, bytes]:
    """Every STEP file of a build, each part's solid made once: ``parts/<name>.step`` per part and
    ``assembly.step`` at ``poses`` (see :func:`part_step`, :func:`assembly_step`).

    Returns
    -------
    dict[str, bytes]
        Path relative to the output folder -> content.
    """
    _import_ocp()
    shapes = {part.name: part_shape(part, chord_tolerance_mm) for part in parts}
    files = {f"parts/{part.name}.step": part_step(part, chord_tolerance_mm, shapes[part.name]) for part in parts}
    files["assembly.step"] = assembly_step(parts, poses, chord_tolerance_mm, title, shapes)
    return files
