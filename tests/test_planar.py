"""Tests of fabricate.planar's small geometry helpers."""

from __future__ import annotations

import numpy as np

from fabricate.planar import rotation, transform_points


def test_rotation_of_one_angle_is_the_stacked_rotation_to_the_bit():
    """One angle takes a shortcut past np.stack: it must give exactly the matrix of the stacked path (the
    solver's and every part's poses go through it), for a Python float, np.float64 and a 0-d array."""
    angles = np.random.default_rng(5).uniform(-40.0, 40.0, 300)
    stacked = rotation(angles)
    assert stacked.shape == (300, 2, 2)
    for k, theta in enumerate(angles):
        for value in (float(theta), theta, np.array(theta)):
            one = rotation(value)
            assert one.shape == (2, 2) and one.dtype == np.float64
            assert np.array_equal(one, stacked[k])
    np.testing.assert_allclose(rotation(0.5) @ rotation(-0.5), np.eye(2), atol=1e-15)


def test_stacked_rotation_is_cos_minus_sin_sin_cos_for_any_shape():
    """The stacked path fills one array: every matrix must be [[cos, -sin], [sin, cos]] of its own angle,
    in the angles' shape, and float32 angles stay float32 (as np.stack gave them)."""
    angles = np.random.default_rng(6).uniform(-7.0, 7.0, (4, 3))
    mats = rotation(angles)
    assert mats.shape == (4, 3, 2, 2)
    for idx in np.ndindex(4, 3):
        c, s = np.cos(angles[idx]), np.sin(angles[idx])
        assert np.array_equal(mats[idx], [[c, -s], [s, c]])
    assert rotation(angles.astype(np.float32)).dtype == np.float32
    assert rotation(np.empty(0)).shape == (0, 2, 2)


def test_transform_points_turns_then_moves():
    pose = np.array([3.0, -2.0, np.pi / 2])
    np.testing.assert_allclose(transform_points(pose, np.array([[1.0, 0.0], [0.0, 2.0]])),
                               [[3.0, -1.0], [1.0, -2.0]], atol=1e-12)
