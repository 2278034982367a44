"""fabricate.parts.model: BulgePath.distance measures only the pieces that can be nearest, to the same float;
BulgePath.polygon is every vertex then its arc's inner points, made once per tolerance and handed out as copies."""

from __future__ import annotations

import pickle

import numpy as np

from fabricate.parts.model import BulgePath, arc_points


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


def test_polygon_is_each_vertex_then_its_arcs_inner_points():
    """The chords of a path with straight runs, zero-length pieces and arcs (the last one closing the path) equal
    the piece-by-piece reference; a second call equals the first though the first's array was overwritten (a
    copy each time), another tolerance gives other chords, and a pickled path carries no chords."""
    path = _toothed_path(np.random.default_rng(2))
    bulges = np.r_[path.bulges[:-1], 0.7]  # an arc from the last vertex to the first
    bulges[6] = 0.0  # the zero-length piece straight (an arc there has no circle: NaN points)
    path = BulgePath(path.vertices, bulges)
    n = len(path.vertices)
    reference = np.concatenate([
        piece for i in range(n) for piece in (
            path.vertices[i][None, :],
            arc_points(path.vertices[i], path.vertices[(i + 1) % n], float(path.bulges[i]), 0.01)[1:-1]
            if path.bulges[i] != 0.0 else np.zeros((0, 2)))])
    first = path.polygon(0.01)
    assert np.array_equal(first, reference) and len(reference) > n + 80
    first[:] = 0.0
    assert np.array_equal(path.polygon(0.01), reference)
    assert len(path.polygon(0.001)) > len(reference)
    copy = pickle.loads(pickle.dumps(path))
    assert "_chords" not in copy.__dict__ and np.array_equal(copy.polygon(0.01), reference)
