"""fabricate.export.stl encodes and reads STL with numpy as trimesh does: the same bytes, volumes and findings."""

from __future__ import annotations

import io

import numpy as np
import trimesh

from fabricate.export.stl import mesh_volume, stl_bytes, validate_stl


def _meshes() -> list[tuple[np.ndarray, np.ndarray]]:
    """A sphere off the origin (640 faces of every orientation), the same with a degenerate (zero-normal) face
    and a face of two equal corners added, and a thin sliver whose normals are near trimesh's zero length."""
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=7.3)
    v = np.asarray(sphere.vertices) + np.array([12.25, -3.5, 0.7])
    f = np.asarray(sphere.faces, dtype=np.int64)
    degenerate = np.vstack([f, [[0, 1, 1], [2, 2, 2]]])
    sliver = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-7, 0.0], [0.5, 0.0, 1e-7]])
    return [(v, f), (v, degenerate), (sliver, np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]))]


def test_stl_bytes_and_volume_are_trimeshs_to_the_bit():
    for v, f in _meshes():
        mesh = trimesh.Trimesh(vertices=v, faces=f, process=False)
        assert stl_bytes(v, f) == trimesh.exchange.stl.export_stl(mesh)
        assert mesh_volume(v, f) == float(mesh.volume)  # exact: report.json rounds it to 4 decimals
    assert stl_bytes(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)) == bytes(84)


def test_validate_stl_reads_as_trimesh_reads():
    """Closed, flipped-face and open meshes: the same findings as trimesh's reader (merged corners, watertight,
    winding, the volume of the read-back float32 corners)."""
    v, f = _meshes()[0]
    flipped = f.copy()
    flipped[5] = flipped[5, ::-1]
    for faces in (f, flipped, f[3:], f[:, ::-1]):
        data = stl_bytes(v, faces)
        mesh = trimesh.load(io.BytesIO(data), file_type="stl", process=True)
        expected = (["not watertight"] if not mesh.is_watertight else []) \
            + (["inconsistent winding"] if not mesh.is_winding_consistent else [])
        found = validate_stl(data, float(mesh.volume), rel_tol=0.0)  # the read-back volume exactly
        assert found[:len(expected)] == expected
        assert all(p.startswith("volume") and "not positive" in p for p in found[len(expected):])
    assert validate_stl(stl_bytes(v, f)) == []
    assert validate_stl(stl_bytes(v, flipped)) == ["inconsistent winding"]
