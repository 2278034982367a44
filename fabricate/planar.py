"""Small planar geometry helpers shared by synthesis, parts and checks.

Points are float64 arrays of shape ``(2,)`` or ``(n, 2)`` in mm; angles in radians.
"""

from __future__ import annotations

import numpy as np


def rotation(theta: float | np.ndarray) -> np.ndarray:
    """Rotation matrix (or stack of them) for angle(s) ``theta`` in radians; shape (2, 2) or (n, 2, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    if isinstance(theta, float):  # one angle (np.float64 too): the same matrix without np.stack's overhead
        return np.array([[c, -s], [s, c]])
    # the entries placed into one array: the values np.stack([[c, -s], [s, c]]) gives, a few times faster
    out = np.empty(np.shape(c) + (2, 2), dtype=np.result_type(c, s))
    out[..., 0, 0] = c
    out[..., 0, 1] = -s
    out[..., 1, 0] = s
    out[..., 1, 1] = c
    return out


def unit(theta: float | np.ndarray) -> np.ndarray:
    """Unit vector(s) at angle ``theta``; shape (2,) or (n, 2)."""
    return np.stack([np.cos(theta), np.sin(theta)], -1)


def perp(v: np.ndarray) -> np.ndarray:
    """Vector(s) turned +90 degrees."""
    v = np.asarray(v, dtype=np.float64)
    return np.stack([-v[..., 1], v[..., 0]], -1)


def cross2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z-component of the cross product of 2D vectors."""
    z: np.ndarray = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return z


def transform_points(pose: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Map body-frame points to the world.

    Parameters
    ----------
    pose : (3,) array
        Body pose (x, y, theta) in mm, mm, rad.
    points : (n, 2) or (2,) array
        Points in body coordinates, mm.
    """
    pose = np.asarray(pose, dtype=np.float64)
    world: np.ndarray = np.asarray(points, dtype=np.float64) @ rotation(pose[2]).T + pose[:2]
    return world


def inverse_transform_points(pose: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Map world points into the frame of a body at ``pose`` (inverse of :func:`transform_points`)."""
    pose = np.asarray(pose, dtype=np.float64)
    local: np.ndarray = (np.asarray(points, dtype=np.float64) - pose[:2]) @ rotation(pose[2])
    return local


def pose_matrix(pose: np.ndarray) -> np.ndarray:
    """Homogeneous 3x3 matrix (or stack (n, 3, 3)) of pose(s) (x, y, theta)."""
    pose = np.asarray(pose, dtype=np.float64)
    out = np.zeros(pose.shape[:-1] + (3, 3))
    out[..., :2, :2] = rotation(pose[..., 2])
    out[..., :2, 2] = pose[..., :2]
    out[..., 2, 2] = 1.0
    return out


def relative_poses(pose_ref: np.ndarray, pose_body: np.ndarray) -> np.ndarray:
    """Poses (n, 3) of a body in the frame of a reference body, from both world poses (n, 3).

    The relative angle is the plain difference (not wrapped), so it stays continuous over a sweep.
    """
    pose_ref = np.asarray(pose_ref, dtype=np.float64)
    pose_body = np.asarray(pose_body, dtype=np.float64)
    c, s = np.cos(pose_ref[:, 2]), np.sin(pose_ref[:, 2])
    dx = pose_body[:, 0] - pose_ref[:, 0]
    dy = pose_body[:, 1] - pose_ref[:, 1]
    return np.column_stack([c * dx + s * dy, -s * dx + c * dy, pose_body[:, 2] - pose_ref[:, 2]])


def circle_circle_intersection(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> np.ndarray:
    """Both intersection points of two circles, left of c1→c2 first; shape (2, 2).

    Raises
    ------
    ValueError
        When the circles do not meet (the linkage cannot be assembled).
    """
    c1 = np.asarray(c1, dtype=np.float64)
    c2 = np.asarray(c2, dtype=np.float64)
    d_vec = c2 - c1
    d = float(np.hypot(*d_vec))
    if d == 0.0:
        raise ValueError("concentric circles")
    a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    h2 = r1 * r1 - a * a
    if h2 < 0.0:
        raise ValueError("circles do not intersect")
    h = np.sqrt(h2)
    e = d_vec / d
    base = c1 + a * e
    return np.array([base + h * perp(e), base - h * perp(e)])


def wrap_angle(theta: np.ndarray | float) -> np.ndarray | float:
    """Wrap angle(s) to (-pi, pi]."""
    return -((-np.asarray(theta) + np.pi) % (2.0 * np.pi) - np.pi)


def polygon_area(contour: np.ndarray) -> float:
    """Signed area (shoelace) of a closed contour (n, 2); positive when counter-clockwise."""
    x, y = contour[:, 0], contour[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
