"""Meshes for SLA printing: binary STL per part, the print plate, and a 3MF of the assembly.

Solids come from the manifold3d adapter (:mod:`fabricate.parts.solids`); trimesh only encodes and
validates. Every encoder returns bytes and is deterministic (no timestamps, no random ids): the 3MF
container is written here with fixed zip dates and ids numbered in part order.
"""

from __future__ import annotations

import io
import zipfile
from collections.abc import Mapping, Sequence
from typing import Any, cast

import numpy as np
import trimesh

from fabricate.export.layout import Placement, pack
from fabricate.parts.model import Part
from fabricate.parts.solids import mesh_arrays, part_solid, posed

#: Fixed zip entry date so the 3MF bytes do not depend on when they were written.
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)


class SolidCache:
    """Solids of parts, polygonised and extruded once per build.

    Parameters
    ----------
    chord_tolerance_mm : float
        Polygonisation tolerance of every profile.
    """

    def __init__(self, chord_tolerance_mm: float) -> None:
        self.tol = chord_tolerance_mm
        self._solids: dict[str, Any] = {}
        self._flat: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def solid(self, part: Part) -> Any:
        """The part's manifold solid at its assembly height."""
        if part.name not in self._solids:
            self._solids[part.name] = part_solid(part, self.tol)
        return self._solids[part.name]

    def flat_mesh(self, part: Part) -> tuple[np.ndarray, np.ndarray]:
        """Vertices (n, 3) and triangles (m, 3) of the part lying on z = 0 in its own coordinates."""
        if part.name not in self._flat:
            vertices, faces = mesh_arrays(self.solid(part))
            vertices = vertices.copy()
            vertices[:, 2] -= part.z_mm
            self._flat[part.name] = (vertices, faces)
        return self._flat[part.name]


def _mesh(vertices: np.ndarray, faces: np.ndarray) -> trimesh.Trimesh:
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def stl_bytes(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """Binary STL of a triangle mesh (80-byte zero header, float32 normals and corners)."""
    return trimesh.exchange.stl.export_stl(_mesh(vertices, faces))


def mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Enclosed volume (mm^3) of a closed triangle mesh, vertices (n, 3) mm and triangles (m, 3)."""
    return float(_mesh(vertices, faces).volume)


def part_stl(part: Part, cache: SolidCache) -> bytes:
    """Binary STL of one part in its own coordinates, bottom face on z = 0 (its print orientation)."""
    return stl_bytes(*cache.flat_mesh(part))


def validate_stl(data: bytes, expected_volume_mm3: float | None = None,
                 rel_tol: float = 1e-3) -> list[str]:
    """Problems found by reading binary STL bytes back with trimesh (an empty list means a valid solid).

    Parameters
    ----------
    data : bytes
        Binary STL (what fabricate writes).
    expected_volume_mm3 : float, optional
        Also compare the volume with this value.
    rel_tol : float
        Relative volume tolerance.

    Returns
    -------
    list of str
        Human-readable problems: truncated, not watertight, inconsistent winding, non-positive volume,
        volume off.
    """
    # a binary STL is an 80-byte header, a triangle count and 50 bytes a triangle: check that first, or
    # trimesh falls back to its ASCII reader and reports something unrelated
    if len(data) < 84:
        return [f"not a binary STL ({len(data)} bytes, shorter than its 84-byte header)"]
    count = int.from_bytes(data[80:84], "little")
    if len(data) != 84 + 50 * count:
        return [f"truncated or not a binary STL: {len(data)} bytes, its header announces {count} triangles "
                f"({84 + 50 * count} bytes)"]
    try:
        mesh = trimesh.load(io.BytesIO(data), file_type="stl", process=True)
    except Exception as exc:  # noqa: BLE001 - any decoder failure is a finding
        return [f"cannot be read back: {exc}"]
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        return ["no triangles"]
    return mesh_problems(mesh, expected_volume_mm3, rel_tol)


def mesh_problems(mesh: trimesh.Trimesh, expected_volume_mm3: float | None = None,
                  rel_tol: float = 1e-3) -> list[str]:
    """What makes ``mesh`` not a closed solid of the expected volume (see :func:`validate_stl`)."""
    problems = []
    if not mesh.is_watertight:
        problems.append("not watertight")
    if not mesh.is_winding_consistent:
        problems.append("inconsistent winding")
    volume = float(mesh.volume)
    if not volume > 0:
        problems.append(f"volume {volume:.6g} mm^3 is not positive")
    if expected_volume_mm3 is not None and abs(volume - expected_volume_mm3) > rel_tol * abs(expected_volume_mm3):
        problems.append(f"volume {volume:.6g} mm^3 differs from {expected_volume_mm3:.6g} mm^3")
    return problems


def read_3mf(data: bytes) -> tuple[dict[str, trimesh.Trimesh], list[str]]:
    """The named objects of a 3MF (core spec) and what is wrong with the package.

    The container is read with the standard library (the 3MF writer above is ours too); each object's
    mesh is handed to trimesh, so callers validate it with :func:`mesh_problems`.

    Returns
    -------
    objects : dict[str, trimesh.Trimesh]
        Object name -> mesh, in file order (vertices in mm).
    problems : list of str
        Unreadable zip or XML, a unit other than millimetre, duplicate names, bad triangle indices.
    """
    import xml.etree.ElementTree as ET

    ns = "{http://schemas.microsoft.com/3dmanufacturing/core/2015/02}"
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            model = ET.fromstring(archive.read("3D/3dmodel.model"))
    except (zipfile.BadZipFile, KeyError, ET.ParseError, OSError, EOFError, ValueError) as exc:
        return {}, [f"not a readable 3MF package ({type(exc).__name__}: {exc})"]
    problems = []
    if model.get("unit", "millimeter") != "millimeter":
        problems.append(f"unit is {model.get('unit')}, not millimeter")
    objects: dict[str, trimesh.Trimesh] = {}
    for obj in model.iter(f"{ns}object"):
        name = obj.get("name") or f"object {obj.get('id')}"
        try:
            # a missing attribute is None: float(None) raises the TypeError reported below
            vertices = np.array([[float(cast(str, v.get(k))) for k in "xyz"] for v in obj.iter(f"{ns}vertex")])
            faces = np.array([[int(cast(str, t.get(k))) for k in ("v1", "v2", "v3")]
                              for t in obj.iter(f"{ns}triangle")])
        except (TypeError, ValueError) as exc:
            problems.append(f"object {name}: unreadable mesh ({exc})")
            continue
        if len(faces) == 0 or faces.min() < 0 or faces.max() >= len(vertices):
            problems.append(f"object {name}: no triangles or triangle indices outside its vertices")
            continue
        if name in objects:
            problems.append(f"object name {name} appears twice")
        objects[name] = _mesh(vertices, faces)
    return objects, problems


def plate_layout(parts: Sequence[Part], cache: SolidCache, build_area_mm: tuple[float, float],
                 spacing_mm: float) -> list[Placement]:
    """Placements of parts on the SLA build plate (x, y of the build volume).

    Parts are measured by the vertices of the meshes that are printed, so a placement's box is the
    printed part's box (a coarser outline could leave the mesh a sagitta outside the margin); they are packed
    densely (:func:`fabricate.export.layout.pack`), the spacing kept at the plate's edge too.
    """
    outlines = [cache.flat_mesh(p)[0][:, :2] for p in parts]
    return pack(outlines, build_area_mm, margin_mm=spacing_mm, spacing_mm=spacing_mm)


def plate_stl(meshes: Sequence[tuple[np.ndarray, np.ndarray]]) -> bytes:
    """One STL of several closed meshes (vertices (n, 3) mm, triangles (m, 3)): each keeps its own shell."""
    vertices_all, faces_all, base = [], [], 0
    for vertices, faces in meshes:
        vertices_all.append(vertices)
        faces_all.append(faces + base)
        base += len(vertices)
    return stl_bytes(np.concatenate(vertices_all), np.concatenate(faces_all))


def placed_flat_mesh(part: Part, cache: SolidCache, place: Placement) -> tuple[np.ndarray, np.ndarray]:
    """The part lying flat (z from 0) moved by its plate placement: vertices (n, 3) mm, triangles (m, 3)."""
    vertices, faces = cache.flat_mesh(part)
    return np.column_stack([place.apply(vertices[:, :2]), vertices[:, 2]]), faces


def assembly_3mf(parts: Sequence[Part], cache: SolidCache, poses: Mapping[str, np.ndarray],
                 title: str = "assembly") -> bytes:
    """3MF (core spec) of the assembly at the given body poses: one object per part, in mm.

    Parameters
    ----------
    parts : sequence of Part
    cache : SolidCache
    poses : Mapping[str, (3,) array]
        World pose of each body (x mm, y mm, theta rad); spacers move with their body.
    title : str
        Model title metadata.
    """
    objects = []
    for part in parts:
        solid = posed(cache.solid(part), np.asarray(poses.get(part.body, np.zeros(3)), dtype=np.float64))
        objects.append((part.name, *mesh_arrays(solid)))
    return model_3mf(objects, title)


def model_3mf(objects: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str) -> bytes:
    """3MF (core spec, unit millimetre) of named meshes ``(name, vertices (n, 3) mm, triangles (m, 3))``,
    one object and one build item each, ids in the given order; fixed zip dates, so equal input gives equal
    bytes."""
    resources, items = [], []
    for k, (name, vertices, faces) in enumerate(objects, start=1):
        # one %-format over plain Python numbers: the text f"{x:.6f}" and f"{a}" give per numpy scalar, ~5x faster
        vert_xml = ('<vertex x="%.6f" y="%.6f" z="%.6f"/>' * len(vertices)) % tuple(np.ravel(vertices).tolist())
        tri_xml = ('<triangle v1="%d" v2="%d" v3="%d"/>' * len(faces)) % tuple(np.ravel(faces).tolist())
        resources.append(f'<object id="{k}" name="{_xml_escape(name)}" type="model"><mesh>'
                         f"<vertices>{vert_xml}</vertices><triangles>{tri_xml}</triangles></mesh></object>")
        items.append(f'<item objectid="{k}"/>')
    model = ('<?xml version="1.0" encoding="UTF-8"?>\n'
             '<model unit="millimeter" xml:lang="en-US" '
             'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
             f'<metadata name="Title">{_xml_escape(title)}</metadata>'
             f'<resources>{"".join(resources)}</resources><build>{"".join(items)}</build></model>')
    content_types = ('<?xml version="1.0" encoding="UTF-8"?>\n'
                     '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
                     '<Default Extension="rels" '
                     'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
                     '<Default Extension="model" '
                     'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>')
    rels = ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
            '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
            'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>')
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, text in (("[Content_Types].xml", content_types), ("_rels/.rels", rels),
                           ("3D/3dmodel.model", model)):
            info = zipfile.ZipInfo(name, date_time=_ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, text.encode("utf-8"))
    return buffer.getvalue()


def _xml_escape(text: str) -> str:
    return (text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;"))
