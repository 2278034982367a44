"""Pitch curves of a non-circular pair from its ratio law, parameterised by rolled arc length.

Gear-frame convention (shared with parts and checks): at relative angle ``x_a`` the pitch point lies
on the line of centres at distance ``r_a = a i / (1 + i)`` from axis A, i.e. at polar angle ``-x_a``
in gear-a's frame, and at ``r_b = a / (1 + i)`` from axis B, at polar angle ``pi - law(x_a)`` in
gear-b's frame (``i = -law'``). Rolling without slip follows: ``ds_a = ds_b`` for every ``dx_a``
because ``r_b * i = r_a`` and ``dr_b = -dr_a`` (tested in ``tests/test_gears_pitch.py``).

Everything a tooth generator needs is a function of the rolled arc length ``s`` (mm, increasing with
``x_a``): the pitch point ``P``, the unit tangent ``t = dP/ds`` and the outward unit normal ``n``.
Gear a's pitch point runs clockwise in its frame (outward normal = ``t`` turned +90 degrees), gear b's
counter-clockwise (outward normal = ``t`` turned -90 degrees).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from fabricate.gears.law import check_ratio, law_derivative

if TYPE_CHECKING:
    from fabricate.mechanism import Law

# 8-point Gauss-Legendre rule on [0, 1]: arc length to ~1e-14 relative per grid interval
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


@dataclass(frozen=True)
class PitchFrames:
    """Pitch point, unit tangent, outward unit normal (each (n, 2), gear frame, mm) and the signed
    curvature (n,) in 1/mm (positive where the curve bends towards the gear's axis)."""

    point: np.ndarray
    tangent: np.ndarray
    normal: np.ndarray
    curvature: np.ndarray


class PitchCurves:
    """The two pitch curves of a pair over a domain of ``x_a``.

    Parameters
    ----------
    law : callable
        ``law(x, nu)`` (rad), external pair (``law' < 0``).
    center_distance : float
        Distance between the axes, mm.
    x_domain : (float, float)
        Range of ``x_a`` (rad) over which the curves are built (the working range plus spares).
    x_ref : float
        ``s(x_ref) = 0``.
    periods : (float, float) or None
        For closed gears, the ``x_a`` periods after which gear a and gear b repeat (``2 pi`` and
        ``2 pi z_b / z_a``); arc lengths are then wrapped by the perimeters.
    intervals : int
        Quadrature grid size.
    """

    def __init__(self, law: Law, center_distance: float, x_domain: tuple[float, float],
                 x_ref: float = 0.0, periods: tuple[float, float] | None = None,
                 intervals: int = 2048) -> None:
        self.law = law
        self.a = float(center_distance)
        self.x_domain = (float(x_domain[0]), float(x_domain[1]))
        self.x_ref = float(x_ref)
        self.periods = periods
        self.nodes = np.linspace(self.x_domain[0], self.x_domain[1], intervals + 1)
        check_ratio(law, np.linspace(self.x_domain[0], self.x_domain[1], 4 * intervals + 1))
        h = np.diff(self.nodes)
        xq = self.nodes[:-1, None] + h[:, None] * _GL_X[None, :]
        pieces = (self.speed(xq) * _GL_W[None, :]).sum(axis=1) * h
        cumulative = np.concatenate([[0.0], np.cumsum(pieces)])
        self.s_nodes = cumulative
        self.s_nodes = cumulative - self.s_of_x(np.array([self.x_ref]))[0]
        # x(s) as a cubic Hermite spline with the exact slope 1/speed at the nodes: interpolation
        # error ~ h^4 max|x''''| / 384, about 1e-13 rad for the default grid (no Newton steps needed)
        self._x_of_s: Callable[[np.ndarray], np.ndarray] = CubicHermiteSpline(self.s_nodes, self.nodes,
                                                                              1.0 / self.speed(self.nodes))
        if periods is not None:
            self.perimeter_a = float(self.s_of_x(np.array([self.x_ref + periods[0]]))[0])
            self.perimeter_b = float(self.s_of_x(np.array([self.x_ref + periods[1]]))[0])
        else:
            self.perimeter_a = self.perimeter_b = float("nan")

    # -- radii ---------------------------------------------------------------------------------
    def ratio(self, x: np.ndarray) -> np.ndarray:
        """Transmission ratio ``i = -law'(x)``."""
        return -law_derivative(self.law, x, 1)

    def radii(self, x: np.ndarray, gear: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                        np.ndarray]:
        """See :func:`pitch_radii`."""
        return pitch_radii(self.law, self.a, x, gear)

    def speed(self, x: np.ndarray) -> np.ndarray:
        """``ds/dx_a`` (mm/rad), the same for both gears (rolling without slip)."""
        r, dr, _, _, _ = self.radii(x, "a")
        speed: np.ndarray = np.hypot(r, dr)
        return speed

    # -- arc length ------------------------------------------------------------------------------
    def s_of_x(self, x: np.ndarray) -> np.ndarray:
        """Rolled arc length at ``x_a`` (mm), exact to quadrature precision inside the domain."""
        x = np.asarray(x, dtype=np.float64)
        k = np.clip(np.searchsorted(self.nodes, x, side="right") - 1, 0, len(self.nodes) - 2)
        x0 = self.nodes[k]
        h = x - x0
        xq = x0[..., None] + h[..., None] * _GL_X
        s: np.ndarray = self.s_nodes[k] + (self.speed(xq) * _GL_W).sum(axis=-1) * h
        return s

    def x_of_s(self, s: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`s_of_x` (Hermite interpolation, see ``__init__``)."""
        return self._x_of_s(np.asarray(s, dtype=np.float64))

    def wrap(self, s: np.ndarray, gear: str) -> np.ndarray:
        """Arc length reduced to one perimeter (closed gears); unchanged for sectors."""
        if self.periods is None:
            return np.asarray(s, dtype=np.float64)
        perimeter = self.perimeter_a if gear == "a" else self.perimeter_b
        wrapped: np.ndarray = np.mod(s, perimeter)
        return wrapped

    # -- frames ----------------------------------------------------------------------------------
    def frames_at_x(self, x: np.ndarray, gear: str) -> PitchFrames:
        """See :func:`pitch_frames`."""
        return pitch_frames(self.law, self.a, x, gear)

    def frames(self, s: np.ndarray, gear: str) -> PitchFrames:
        """:meth:`frames_at_x` at rolled arc length ``s`` (wrapped for closed gears)."""
        return self.frames_at_x(self.x_of_s(self.wrap(s, gear)), gear)

    def curve(self, x: np.ndarray, gear: str) -> np.ndarray:
        """Pitch points (n, 2) of ``gear`` at driving angles ``x`` (rad)."""
        r, _, _, th, _ = self.radii(x, gear)
        return r[..., None] * np.stack([np.cos(th), np.sin(th)], -1)


def pitch_radii(law: Law, center_distance: float, x: np.ndarray, gear: str
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Polar pitch radius of ``gear`` (``"a"`` or ``"b"``) and its first two x-derivatives, the polar angle
    and its x-derivative, at driving angles ``x`` (rad), from rolling without slip.

    Returns
    -------
    r, dr, ddr, theta, dtheta : (n,) arrays (mm, mm/rad, mm/rad^2, rad, -)
    """
    x = np.asarray(x, dtype=np.float64)
    a = float(center_distance)
    i = -law_derivative(law, x, 1)
    di = -law_derivative(law, x, 2)
    ddi = -law_derivative(law, x, 3)
    q = 1.0 + i
    # r_a = a i/(1+i) = a - a/(1+i); r_b = a/(1+i)
    rb = a / q
    drb = -a * di / q**2
    ddrb = -a * (ddi / q**2 - 2.0 * di**2 / q**3)
    if gear == "a":
        return a - rb, -drb, -ddrb, -x, -np.ones_like(x)
    return rb, drb, ddrb, np.pi - np.asarray(law(x), dtype=np.float64), i


def pitch_frames(law: Law, center_distance: float, x: np.ndarray, gear: str) -> PitchFrames:
    """Pitch point, tangent (direction of increasing s), outward normal and curvature (positive where
    the curve is convex) of ``gear`` at driving angles ``x`` (rad)."""
    r, dr, ddr, th, dth = pitch_radii(law, center_distance, x, gear)
    u = np.stack([np.cos(th), np.sin(th)], -1)
    v = np.stack([-np.sin(th), np.cos(th)], -1)
    # P = r u(theta(x)); P' = r' u + r theta' v; P'' = (r'' - r theta'^2) u + (2 r' theta' + r theta'') v
    # theta'' = 0 for gear a, -law'' for gear b
    ddth = np.zeros_like(r) if gear == "a" else -law_derivative(law, x, 2)
    d1 = dr[..., None] * u + (r * dth)[..., None] * v
    d2 = (ddr - r * dth**2)[..., None] * u + (2 * dr * dth + r * ddth)[..., None] * v
    speed = np.hypot(d1[..., 0], d1[..., 1])
    t = d1 / speed[..., None]
    if gear == "a":
        n = np.stack([-t[..., 1], t[..., 0]], -1)
    else:
        n = np.stack([t[..., 1], -t[..., 0]], -1)
    # curvature towards the axis: -(dt/ds).n = -(P''.n)/|P'|^2
    curvature = -(d2[..., 0] * n[..., 0] + d2[..., 1] * n[..., 1]) / speed**2
    return PitchFrames(r[..., None] * u, t, n, curvature)
