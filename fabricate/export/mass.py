"""Mass properties of the parts as exported: exact integrals over their STL meshes (the divergence theorem on
the triangles), at the process profile's density, summed per mechanism body (parallel axes).

:mod:`fabricate.export.mjcf` writes them into mechanism.xml; tests/export/test_mjcf.py holds them to trimesh's
mass properties of the same files.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from fabricate.parts.partset import PartSet

#: mm -> m
MM = 1e-3


@dataclass(frozen=True)
class MassProperties:
    """Mass (kg), centre of mass (3,) m and inertia tensor (3, 3) kg·m² about the centre of mass."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray


def stl_triangles(data: bytes) -> np.ndarray:
    """The triangles (m, 3, 3) of a binary STL, float64 of the file's float32 corners."""
    if len(data) < 84:
        raise ValueError("STL shorter than its header")
    (count,) = struct.unpack_from("<I", data, 80)
    record = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    if len(data) != 84 + count * record.itemsize:
        raise ValueError("not a binary STL of the size its header says")
    rows = np.frombuffer(data, dtype=record, count=count, offset=84)
    return np.asarray(rows["corners"], dtype=np.float64)


def mesh_mass_properties(triangles: np.ndarray, density: float) -> MassProperties:
    """Mass properties of the closed triangle mesh ``triangles`` (m, 3, 3) at ``density`` (exact for the
    polyhedron: each triangle and the origin span a tetrahedron, and their signed integrals add up).

    Units are the caller's: a mesh in mm at g/mm³ gives g, mm and g·mm².
    """
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    det = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x signed tetrahedron volume
    volume = float(det.sum()) / 6.0
    if not volume > 0.0:
        raise ValueError("the mesh encloses no volume (open, or wound inside out)")
    first = (det[:, None] * (a + b + c)).sum(axis=0) / 24.0
    # second moments of a tetrahedron with a vertex at the origin: det/120 (sum p_i p_j^T + (sum p)(sum p)^T)
    s = a + b + c
    second = (np.einsum("n,ni,nj->ij", det, a, a) + np.einsum("n,ni,nj->ij", det, b, b)
              + np.einsum("n,ni,nj->ij", det, c, c) + np.einsum("n,ni,nj->ij", det, s, s)) / 120.0
    com = first / volume
    second_com = second - volume * np.outer(com, com)
    inertia = np.trace(second_com) * np.eye(3) - second_com
    return MassProperties(density * volume, com, density * inertia)


def combine(items: Sequence[MassProperties]) -> MassProperties:
    """Several rigid pieces as one: total mass, common centre of mass, inertia about it (parallel axes)."""
    mass = sum(p.mass for p in items)
    if mass <= 0.0:
        return MassProperties(0.0, np.zeros(3), np.zeros((3, 3)))
    com = sum((p.mass * p.com for p in items), np.zeros(3)) / mass
    inertia = np.zeros((3, 3))
    for p in items:
        d = p.com - com
        inertia += p.inertia + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return MassProperties(mass, com, inertia)


def body_mass_properties(partset: PartSet, stl: Mapping[str, bytes], density_g_cm3: float
                         ) -> dict[str, MassProperties]:
    """Every body's mass properties in SI, from its parts' STL (``stl``: ``{part name: bytes}``) placed at
    the part's height, at ``density_g_cm3``."""
    per_body: dict[str, list[MassProperties]] = {}
    density = density_g_cm3 * 1e-3  # g/mm³
    for part in partset.parts:
        triangles = stl_triangles(stl[part.name]) + np.array([0.0, 0.0, part.z_mm])
        p = mesh_mass_properties(triangles, density)  # g, mm, g·mm²
        per_body.setdefault(part.body, []).append(MassProperties(p.mass * 1e-3, p.com * MM, p.inertia * 1e-9))
    return {body: combine(items) for body, items in per_body.items()}
