"""Reading STEP files back (through OCP): every solid named, measured and checked against the report.

The other half of :mod:`fabricate.export.step`: the exporter builds and writes solids, this module reads a
file as a CAD program would and says what it holds. OCP is imported inside the functions, like the
writer's, so the package imports without the optional extra ``cad``.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from fabricate.errors import GeometryError
from fabricate.export.occt import downcast, quiet_occt, shape_volume, xcaf_document

_DESCRIBED_TOLERANCE = re.compile(rb"FILE_DESCRIPTION\s*\(\s*\(\s*'fabricate: curves within ([0-9.eE+-]+) mm")


class StepSolid(NamedTuple):
    """One solid read back from a STEP file (see :func:`read_step`).

    Attributes
    ----------
    name : str
        Product name of the solid ('' when the file names none).
    volume_mm3 : float
        Volume of the solid, mm^3 (from the exact B-rep surfaces).
    n_cylindrical_faces : int
        Faces lying on a cylinder that close on themselves around its axis (a full 2π turn): holes. Arc
        segments of an outline or a slot give partial cylinders, counted in ``n_arc_faces`` instead.
    valid : bool
        The shape is one closed solid and OCCT's BRepCheck_Analyzer finds nothing wrong with it.
    n_arc_faces : int
        Partial cylindrical faces (outline and slot arcs).
    bounds : (2, 3) float64 array
        Tight axis-aligned bounding box (min, max) in mm, in the file's world frame (posed for an assembly).
    curved_area_mm2 : float
        Area of the faces that are neither planes nor holes (arcs, B-spline flanks).
    n_faces : int
        Every face of the solid.
    """

    name: str
    volume_mm3: float
    n_cylindrical_faces: int
    valid: bool
    n_arc_faces: int
    bounds: np.ndarray
    curved_area_mm2: float = 0.0
    n_faces: int = 0



def read_step(data: bytes) -> list[StepSolid]:
    """Every solid of a STEP file, named and measured, in the file's world frame.

    Parameters
    ----------
    data : bytes
        STEP file content.

    Returns
    -------
    list of StepSolid
        One per solid instance (an assembly's components posed), in file order; each a tuple
        ``(name, volume_mm3, n_cylindrical_faces, valid, n_arc_faces, bounds)``.

    Raises
    ------
    GeometryError
        When OCP cannot read the data as STEP.
    """
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Reader


    document, tool = xcaf_document()
    folder = tempfile.mkdtemp(prefix="fabricate-step-")
    path = os.path.join(folder, "in.step")
    try:
        with open(path, "wb") as handle:
            handle.write(data)
        reader = STEPCAFControl_Reader()
        reader.SetNameMode(True)
        with quiet_occt():
            status = reader.ReadFile(path)
            if status != IFSelect_RetDone:
                raise GeometryError(f"STEP not readable (reader status {status})")
            if not reader.Transfer(document):
                raise GeometryError("STEP read but not transferred to shapes")
    finally:
        if os.path.exists(path):
            os.remove(path)
        os.rmdir(folder)
    roots = _label_sequence()
    tool.GetFreeShapes(roots)
    out: list[StepSolid] = []
    for k in range(1, roots.Length() + 1):
        _collect(tool, roots.Value(k), None, out)
    return out


def _label_sequence() -> Any:
    """An empty sequence of XCAF labels (``OCP.collections`` in OCP 8, ``OCP.TDF`` in OCP 7)."""
    try:
        from OCP.collections import Sequence_TDF_Label
    except ImportError:
        from OCP.TDF import TDF_LabelSequence as Sequence_TDF_Label
    return Sequence_TDF_Label()


def _label_name(label: Any) -> str:
    from OCP.TDataStd import TDataStd_Name

    attribute = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attribute):
        return str(attribute.Get().ToExtString())
    return ""


def _collect(tool: Any, label: Any, location: Any, out: list[StepSolid]) -> None:
    """Solids under an XCAF label, composing the component locations on the way down."""
    from OCP.TDF import TDF_Label
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_ShapeTool

    location = location if location is not None else TopLoc_Location()
    if XCAFDoc_ShapeTool.IsAssembly_s(label):
        components = _label_sequence()
        XCAFDoc_ShapeTool.GetComponents_s(label, components, False)
        for k in range(1, components.Length() + 1):
            component = components.Value(k)
            referred = TDF_Label()
            XCAFDoc_ShapeTool.GetReferredShape_s(component, referred)
            placed = location.Multiplied(XCAFDoc_ShapeTool.GetLocation_s(component))
            _collect(tool, referred, placed, out)
        return
    shape = XCAFDoc_ShapeTool.GetShape_s(label).Moved(location)
    out.extend(_measure(shape, _label_name(label)))


def _measure(shape: Any, name: str) -> list[StepSolid]:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepTools import BRepTools
    from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer


    solids = []
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        solid = downcast("Solid", explorer.Current())
        full = partial = count = 0
        curved = 0.0
        faces = TopExp_Explorer(solid, TopAbs_FACE)
        while faces.More():
            face = downcast("Face", faces.Current())
            kind = BRepAdaptor_Surface(face).GetType()
            count += 1
            hole = False
            if kind == GeomAbs_Cylinder:
                u0, u1, _, _ = BRepTools.UVBounds_s(face)
                # a hole's wall goes once round its axis; an outline arc covers less than a turn
                hole = u1 - u0 > 2.0 * math.pi - 1e-9
                full, partial = full + hole, partial + (not hole)
            if kind != GeomAbs_Plane and not hole:
                props = GProp_GProps()
                BRepGProp.SurfaceProperties_s(face, props)
                curved += float(props.Mass())
            faces.Next()
        box = Bnd_Box()
        BRepBndLib.AddOptimal_s(solid, box, False, False)
        low, high = box.CornerMin(), box.CornerMax()
        solids.append(StepSolid(name, shape_volume(solid), full, bool(BRepCheck_Analyzer(solid).IsValid()), partial,
                                np.array([[low.X(), low.Y(), low.Z()], [high.X(), high.Y(), high.Z()]]), curved,
                                count))
        explorer.Next()
    return solids


def step_problems(data: bytes, expected: Mapping[str, tuple[float, int]] | None = None,
                  rel_tol: float = 1e-6) -> list[str]:
    """What is wrong with a STEP file against what the report says it holds (empty: nothing found).

    Parameters
    ----------
    data : bytes
        A part's or the assembly's STEP file.
    expected : Mapping[str, (float, int)], optional
        Part name -> (volume mm^3, number of holes), in file order: one entry for a part file, every
        part for ``assembly.step``. Without it only readability and validity are checked.
    rel_tol : float
        Relative volume tolerance, to which the chord tolerance the file states (:data:`DESCRIPTION`) times
        the area of its curved side faces is added: the report's volume is the polygon's, which those curves
        replaced within that tolerance.

    Returns
    -------
    list of str
        One sentence per problem, e.g. ``"solid ground: volume 812.5 mm^3, the report says 810.0"``.
    """
    try:
        solids = read_step(data)
    except GeometryError as exc:
        return [str(exc)]
    stated = _DESCRIBED_TOLERANCE.search(data[:4096])
    tolerance = float(stated.group(1)) if stated else 0.0
    problems = [f"solid {s.name or '?'}: not a valid solid" for s in solids if not s.valid]
    if not solids:
        problems.append("no solid")
    if expected is None:
        return problems
    names = [s.name for s in solids]
    if names != list(expected):
        return problems + [f"solids {names} differ from the report's parts {list(expected)}"]
    for solid in solids:
        volume, holes = expected[solid.name]
        if not abs(solid.volume_mm3 - volume) <= rel_tol * abs(volume) + tolerance * solid.curved_area_mm2:
            problems.append(f"solid {solid.name}: volume {solid.volume_mm3:.4f} mm^3, the report says {volume:.4f}")
        if solid.n_cylindrical_faces != holes:
            problems.append(f"solid {solid.name}: {solid.n_cylindrical_faces} hole cylinders, the report says {holes}")
    return problems
