"""fabricate.parts.model: BulgePath.distance measures only the pieces that can be nearest, to the same float."""

from __future__ import annotations

import numpy as np

from fabricate.parts.model import BulgePath


def _toothed_path(rng: np.random.Generator) -> BulgePath:
    """A closed path of 240 pieces round a circle, alternately straight and arcs of either sense (a gear-like
    outline, concave and convex; two of them more than half circles), with some zero-length pieces."""
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, 240))
    radii = 20.0 + 1.5 * (np.arange(240) % 4 < 2)
    vertices = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    vertices[7] = vertices[6]  # a zero-length piece
    bulges = np.where(np.arange(240) % 3 == 0, rng.uniform(-0.6, 0.6, 240), 0.0)
    bulges[[30, 90]] = 1.8, -2.5  # two arcs of more than a half circle
    return BulgePath(vertices, bulges)


def test_distance_equals_the_min_over_every_piece(monkeypatch):
    rng = np.random.default_rng(1)
    path = _toothed_path(rng)
    points = np.vstack([rng.uniform(-30.0, 30.0, (20, 2)), path.vertices[::24],
                        path.vertices[::20] + rng.normal(0.0, 1e-6, (12, 2)), [[0.0, 0.0]]])
    pruned = [path.distance(p) for p in points]
    monkeypatch.setattr(BulgePath, "_nearest_pieces", lambda self, p: np.arange(len(self.vertices)))
    every = [path.distance(p) for p in points]
    assert pruned == every  # exactly: the nearest piece is always among those measured
    assert min(every) < 1e-5  # the points on the path are at ~0
