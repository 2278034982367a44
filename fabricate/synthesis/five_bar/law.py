"""Gear law of the five-bar finger: cubic spline through the poses and pitch curves by rolling.

The sun gear is fixed to the ground at O, the planet to link A-B at A; the carrier is the proximal body
(arm O-A). With ``x_a`` the ground's and ``x_b`` the link's rotation relative to the arm, the law is
``x_b = f(x_a)`` (a :class:`scipy.interpolate.CubicSpline` through the pose samples, eq 17). An external
pair turns the two ways relative to the carrier, so ``f' < 0`` and the ratio is ``i = -f'`` (eq 18).

Pitch radii (our derivation; the printed eq 19 does not roll without slip): equal rolled arcs
``r_a dx_a = r_b |dx_b|`` and ``r_a + r_b = |OA|`` give ``r_a = |OA| i / (1 + i)``, ``r_b = |OA| / (1 + i)``.
Angles in radians, lengths in mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from fabricate.gears.pitch import pitch_frames, pitch_radii

#: Samples of the gear law used for feasibility (ratio, curvature) and the report.
LAW_SAMPLES = 241


@dataclass(frozen=True)
class GearLaw:
    """The planet's rotation relative to the arm against the sun's (ground's), both rad.

    Attributes
    ----------
    law : CubicSpline
        ``x_b = law(x_a)`` through the pose samples (x_a increasing).
    knots_a, knots_b : (n,) arrays
        Pose samples in pose order.
    centre_distance : float
        |OA|, mm.
    x : (k,) array
        Dense samples of the working range.
    ratio, r_a, r_b, rho_a, rho_b : (k,) arrays
        Transmission ratio ``-law'``, pitch radii of sun (a) and planet (b), and the pitch curves'
        signed radii of curvature (positive: convex), mm.
    """

    law: CubicSpline
    knots_a: np.ndarray
    knots_b: np.ndarray
    centre_distance: float
    x: np.ndarray
    ratio: np.ndarray
    r_a: np.ndarray
    r_b: np.ndarray
    rho_a: np.ndarray
    rho_b: np.ndarray

    @property
    def working_range(self) -> tuple[float, float]:
        return float(self.x[0]), float(self.x[-1])


def gear_law(knots_a: np.ndarray, knots_b: np.ndarray, centre_distance: float) -> GearLaw:
    """Spline the law through the poses and derive the pitch curves by rolling without slip
    (:func:`fabricate.gears.pitch.pitch_radii` / :func:`~fabricate.gears.pitch.pitch_frames`, the same
    curves the gear generator cuts).

    Parameters
    ----------
    knots_a, knots_b : (n,) arrays
        ``x_a`` (ground relative to the arm) and ``x_b`` (A-B relative to the arm) at the poses, rad.
    centre_distance : float
        |OA|, mm.
    """
    order = np.argsort(knots_a)
    law = CubicSpline(knots_a[order], knots_b[order])
    x = np.linspace(knots_a[order[0]], knots_a[order[-1]], LAW_SAMPLES)
    a = centre_distance
    # the four calls below evaluate the spline and its derivatives at x sixteen times over: once each is enough
    once = _EvaluatedOnce(law, x)
    with np.errstate(divide="ignore", invalid="ignore"):
        r_a = pitch_radii(once, a, x, "a")[0]
        r_b = pitch_radii(once, a, x, "b")[0]
        # signed radius of curvature, positive where convex
        rho_a = 1.0 / pitch_frames(once, a, x, "a").curvature
        rho_b = 1.0 / pitch_frames(once, a, x, "b").curvature
    return GearLaw(law=law, knots_a=knots_a, knots_b=knots_b, centre_distance=a, x=x, ratio=-np.asarray(once(x, 1)),
                   r_a=r_a, r_b=r_b, rho_a=rho_a, rho_b=rho_b)


class _EvaluatedOnce:
    """``law(x, nu)`` that evaluates each derivative at the one array ``x`` (the same object) only once.

    The results are shared between callers, which only read them (the pitch functions build new arrays).
    """

    def __init__(self, law: CubicSpline, x: np.ndarray) -> None:
        self._law, self._x = law, x
        self._values: dict[int, np.ndarray] = {}

    def __call__(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray | float:
        if x is not self._x:
            return np.asarray(self._law(x, nu))
        if nu not in self._values:
            self._values[nu] = np.asarray(self._law(x, nu))
        return self._values[nu]
