"""The OCP (OpenCascade) helpers the STEP writer and reader share: OCCT's messenger held quiet, the downcast
and volume of a shape across OCP 7 and 8, an XCAF document, and the FILE_DESCRIPTION the writer states. OCP is
imported inside the functions (the optional extra ``cad``).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

#: The writer's FILE_DESCRIPTION: arcs and splines that replaced a polygon's chords (gear flanks, fused
#: hubs) stand within the build's chord tolerance of them, so the solid's volume may differ from the report's
#: (the polygon's) by that tolerance times the area of its curved side faces, and no more.
DESCRIPTION = "fabricate: curves within {tolerance:.6g} mm of the part's polygon"


@contextlib.contextmanager
def quiet_occt() -> Iterator[None]:
    """OCCT's default messenger prints transfer statistics to stdout; a build writes nothing there
    (``-q``), so every printer is held at failures only while we read or write, then restored."""
    from OCP.Message import Message, Message_Fail

    printers = Message.DefaultMessenger_s().Printers()
    saved = [printers.Value(k) for k in range(1, printers.Length() + 1)]
    levels = [printer.GetTraceLevel() for printer in saved]
    for printer in saved:
        printer.SetTraceLevel(Message_Fail)
    try:
        yield
    finally:
        for printer, level in zip(saved, levels, strict=True):
            printer.SetTraceLevel(level)


def downcast(kind: str, shape: Any) -> Any:
    """``TopoDS.Solid`` / ``TopoDS.Face`` of a shape: a namespace function in OCP 8, a static method
    (``Solid_s``) in OCP 7."""
    from OCP import TopoDS as topods_module

    caster = topods_module.TopoDS
    return getattr(caster, kind)(shape) if hasattr(caster, kind) else getattr(caster, f"{kind}_s")(shape)


def shape_volume(shape: Any) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return float(props.Mass())


def xcaf_document() -> tuple[Any, Any]:
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    document = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    return document, XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
