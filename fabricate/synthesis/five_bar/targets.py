"""Target poses of the five-bar NCG finger in world coordinates, and the gear law's samples from a dyad."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.planar import rotation, unit, wrap_angle
from fabricate.synthesis.five_bar.spec import FiveBarSpec


@dataclass(frozen=True)
class FingerTargets:
    """Target poses in world coordinates (mm, rad).

    Attributes
    ----------
    angles : (n, 3) array
        Absolute phalanx angles, unwrapped over the poses, the first pose's in (-pi, pi].
    origin : (2,) array
    d, c, p : (n, 2) arrays
        Joint D, joint C and fingertip P at every pose.
    displacements : (n, 3) array
        Pose of the distal frame (origin P, x along C->P) in the proximal frame (origin O, x along
        O->D): ``(e, f, v)``, the input of the kinematic mapping.
    """

    angles: np.ndarray
    origin: np.ndarray
    lengths: np.ndarray
    d: np.ndarray
    c: np.ndarray
    p: np.ndarray
    displacements: np.ndarray

    def distal_to_world(self, point: np.ndarray) -> np.ndarray:
        """World positions (n, 2) of a distal-frame point at every pose."""
        return self.p + np.einsum("nij,j->ni", rotation(self.angles[:, 2]), point)

    def proximal_to_world(self, point: np.ndarray) -> np.ndarray:
        """World positions (n, 2) of a proximal-frame point at every pose."""
        return self.origin + np.einsum("nij,j->ni", rotation(self.angles[:, 0]), point)

    def distal_to_proximal(self, point: np.ndarray) -> np.ndarray:
        """Proximal-frame positions (n, 2) of a distal-frame point at every pose."""
        e, f, v = self.displacements.T
        return np.einsum("nij,j->ni", rotation(v), point) + np.stack([e, f], -1)


def finger_targets(spec: FiveBarSpec) -> FingerTargets:
    """Joint positions and the distal-in-proximal displacements of the template's poses."""
    angles = np.unwrap(np.radians(np.asarray(spec.poses_deg, dtype=np.float64)), axis=0)
    # a whole number of turns moves the first pose into (-pi, pi] (Table 2 writes 0 deg as 360)
    angles = angles + (wrap_angle(angles[0]) - angles[0])
    lengths = np.asarray(spec.lengths_mm, dtype=np.float64)
    origin = np.asarray(spec.origin_mm, dtype=np.float64)
    d = origin + lengths[0] * unit(angles[:, 0])
    c = d + lengths[1] * unit(angles[:, 1])
    p = c + lengths[2] * unit(angles[:, 2])
    local = np.einsum("nji,nj->ni", rotation(angles[:, 0]), p - origin)  # R(-t1) (P - O)
    displacements = np.column_stack([local, angles[:, 2] - angles[:, 0]])
    return FingerTargets(angles=angles, origin=origin, lengths=lengths, d=d, c=c, p=p,
                         displacements=displacements)


# -- gear law ----------------------------------------------------------------------------------------

def dyad_angles(targets: FingerTargets, a_proximal: np.ndarray, b_distal: np.ndarray) -> np.ndarray:
    """Direction of A->B in the proximal frame at every pose (eq 10), unwrapped, rad."""
    b = targets.distal_to_proximal(b_distal) - a_proximal
    return np.unwrap(np.arctan2(b[:, 1], b[:, 0]))


def law_knots(targets: FingerTargets, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pose samples of the gear law from the dyad angles ``phi`` (rad).

    Bodies other than the proximal one use world coordinates of the first pose as body coordinates
    (so their angle is 0 there); the proximal body's angle is the absolute angle t1. Hence
    ``x_a = -t1`` and ``x_b = theta_AB - t1 = phi - phi_0 - t1_0``.
    """
    t1 = targets.angles[:, 0]
    return -t1, phi - phi[0] - t1[0]
