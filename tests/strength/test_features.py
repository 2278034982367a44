"""fabricate.strength.features: the edge distances round a pin hole (tear-out reads them)."""

from __future__ import annotations

import math

import numpy as np

from fabricate.strength.features import _EDGE_DIRECTIONS, _edge_distances


def _square(half: float, centre: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    cx, cy = centre
    return np.array([[cx - half, cy - half], [cx + half, cy - half], [cx + half, cy + half], [cx - half, cy + half]])


def test_edge_distances_are_the_nearest_boundary_along_each_direction():
    """A 20 mm square plate with a 4 mm hole 3 mm right of its centre and a 2 mm hole on the -y side: along each of
    the 72 directions from the pin's centre the distance to the nearest boundary crossing. Towards +x it is the
    near edge (7 mm); along -y the ray meets the other hole's wall first (1 mm off the centre line it would miss);
    along a diagonal the square's side at 7 / cos 45 deg."""
    centre = np.array([3.0, 0.0])
    other = np.array([[3.0 + 1.0 * math.cos(t), -5.0 - 1.0 * math.sin(t)]  # CW: a hole
                      for t in np.linspace(0.0, 2 * math.pi, 64, endpoint=False)])
    out = _edge_distances([_square(10.0), other], centre, 2.0)
    assert out.shape == (_EDGE_DIRECTIONS,)
    step = 360 // _EDGE_DIRECTIONS
    assert math.isclose(out[0], 7.0, abs_tol=1e-9)  # +x: the near side
    assert math.isclose(out[180 // step], 13.0, abs_tol=1e-9)  # -x: the far side
    assert math.isclose(out[45 // step], 7.0 * math.sqrt(2.0), abs_tol=1e-9)
    assert math.isclose(out[270 // step], 4.0, abs_tol=1e-9)  # -y: the other hole's top (5 - 1 below)
    assert math.isclose(out[90 // step], 10.0, abs_tol=1e-9)  # +y: the top side


def test_a_ray_that_meets_no_boundary_reads_the_span():
    """A centre outside the plate: the rays pointing away meet nothing and read the span (twice the plate's
    larger side plus 10 mm); those towards it read the near side."""
    out = _edge_distances([_square(5.0)], np.array([20.0, 0.0]), 1.0)
    span = 2.0 * 10.0 + 10.0
    assert out[0] == span  # +x: away from the plate
    assert math.isclose(out[_EDGE_DIRECTIONS // 2], 15.0, abs_tol=1e-9)  # -x: the near side at x = 5
