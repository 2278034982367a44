"""manifold3d adapter: the only place parts become solids (kernel isolation).

Every constructor checks the manifold's ``status()`` and raises :class:`GeometryError` on failure.
"""

from __future__ import annotations

import manifold3d as m3d
import numpy as np

from fabricate.errors import GeometryError
from fabricate.parts.model import Part
from fabricate.planar import pose_matrix


def _checked(solid: m3d.Manifold, what: str) -> m3d.Manifold:
    status = solid.status()
    if status != m3d.Error.NoError:
        raise GeometryError(f"{what}: manifold3d reported {status.name}")
    return solid


def extrude_polygons(rings: list[np.ndarray], thickness_mm: float, z_mm: float = 0.0,
                     what: str = "extrusion") -> m3d.Manifold:
    """Extrude polygons (outer CCW, holes CW; (n, 2) mm) to a solid from ``z_mm`` to ``z_mm + thickness``."""
    section = m3d.CrossSection([np.ascontiguousarray(r, dtype=np.float64) for r in rings],
                               m3d.FillRule.Positive)
    if section.is_empty():
        raise GeometryError(f"{what}: empty cross-section")
    solid = section.extrude(float(thickness_mm))
    if z_mm:
        solid = solid.translate((0.0, 0.0, float(z_mm)))
    return _checked(solid, what)


def part_solid(part: Part, chord_tolerance_mm: float) -> m3d.Manifold:
    """The part as a solid in its body coordinates at its assembly height."""
    return extrude_polygons(part.polygons(chord_tolerance_mm), part.thickness_mm, part.z_mm, what=part.name)


def posed(solid: m3d.Manifold, pose: np.ndarray) -> m3d.Manifold:
    """The solid moved by a planar body pose (x, y, theta) (mm, mm, rad)."""
    mat = pose_matrix(pose)
    affine = np.array([[mat[0, 0], mat[0, 1], 0.0, mat[0, 2]],
                       [mat[1, 0], mat[1, 1], 0.0, mat[1, 2]],
                       [0.0, 0.0, 1.0, 0.0]])
    return solid.transform(affine)


def mesh_arrays(solid: m3d.Manifold) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float64 and triangles (m, 3) int64 of a solid."""
    mesh = solid.to_mesh()
    return (np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3],
            np.asarray(mesh.tri_verts, dtype=np.int64))
