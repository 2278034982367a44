"""Closed-form strength models of gear teeth: Lewis bending with the form factor of the tooth count, and
Hertz line contact on the involute radii of curvature.

Units and conventions as :mod:`fabricate.strength.models` (force N, length mm, stress MPa; scalars or
broadcastable arrays in, a float out for scalar input).
"""

from __future__ import annotations

import math

import numpy as np

from fabricate.errors import GeometryError
from fabricate.strength.models import ArrayLike, magnitude, positive, scalar_or_array

#: Lewis form factor Y for 20 deg full-depth involute teeth, diametral-pitch/module based (Y = y * pi):
#: Shigley's *Mechanical Engineering Design* (Budynas & Nisbett, 9th/10th ed.) Table 14-2; the rack is
#: the limit of infinitely many teeth.
LEWIS_TABLE_TEETH = np.array([12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 24, 26, 28, 30, 34, 38, 43, 50,
                              60, 75, 100, 150, 300, 400], dtype=np.float64)
LEWIS_TABLE_Y = np.array([0.245, 0.261, 0.277, 0.290, 0.296, 0.303, 0.309, 0.314, 0.322, 0.328, 0.331,
                          0.337, 0.346, 0.353, 0.359, 0.371, 0.384, 0.397, 0.409, 0.422, 0.435, 0.447,
                          0.460, 0.472, 0.480])
LEWIS_RACK_Y = 0.485


def lewis_form_factor(teeth: ArrayLike) -> ArrayLike:
    """Lewis form factor Y of a 20 deg full-depth involute tooth (module based, ``sigma = F / (b m Y)``).

    Interpolated in ``1/N`` (the table follows ``Y ~ a - b/N`` closely) between the entries of
    Shigley's Table 14-2 (12 teeth 0.245 ... 400 teeth 0.480) and the rack (0.485 at ``1/N = 0``), so
    the tabulated values are returned exactly.

    ``teeth`` may be non-integer: for a non-circular gear use the equivalent tooth count ``2 rho / m`` of
    the local pitch-curve curvature radius ``rho``. A concave pitch segment (negative ``rho``, negative
    teeth) or a straight one (``inf``) gets the rack value: its tooth roots are at least as wide as a
    rack's, so this is conservative. Below 12 teeth, outside the table, Y falls with the square of N
    (``0.245 (N/12)^2``): conservative against the 0.226 (11) and 0.201 (10 teeth) of extended tables
    and zero for a vanishing radius.

    Parameters
    ----------
    teeth : float or array
        (Equivalent) number of teeth; non-zero; ``inf`` or negative for a rack / concave segment.

    Returns
    -------
    float or array
        Y (dimensionless).
    """
    n = np.asarray(teeth, dtype=np.float64)
    if np.any(np.isnan(n) | (n == 0.0)):
        raise ValueError(f"teeth must be non-zero (inf or negative for a rack), got {teeth}")
    rack = ~np.isfinite(n) | (n < 0.0)
    safe = np.where(rack, 1e9, n)
    u = 1.0 / safe
    # np.interp needs ascending abscissae: 1/N runs from 0 (rack) up to 1/12.
    y = np.interp(u, np.concatenate([[0.0], 1.0 / LEWIS_TABLE_TEETH[::-1]]),
                  np.concatenate([[LEWIS_RACK_Y], LEWIS_TABLE_Y[::-1]]))
    small = safe < LEWIS_TABLE_TEETH[0]
    y = np.where(small, LEWIS_TABLE_Y[0] * (safe / LEWIS_TABLE_TEETH[0]) ** 2, y)
    y = np.where(rack, LEWIS_RACK_Y, y)
    return scalar_or_array(y)


def lewis_bending_stress(tangential_force_N: ArrayLike, module_mm: ArrayLike, face_width_mm: ArrayLike,
                         form_factor: ArrayLike) -> ArrayLike:
    """Lewis bending stress at a tooth root: ``sigma = F_t / (b m Y)``.

    The tooth is a cantilever of uniform strength (a parabola inscribed in the tooth) loaded at the tip
    by the whole tangential load, one tooth pair in contact, root fillet stress concentration not
    included (W. Lewis 1892; Shigley ch. 14 in SI form with ``P = 25.4 / m``). No velocity factor: the
    mechanisms here are quasi-static; multiply the force by ``Kv`` for running gears.

    Parameters
    ----------
    tangential_force_N : float or array
        Transmitted load tangent to the pitch curve (N).
    module_mm : float or array
        Module (mm).
    face_width_mm : float or array
        Face width, the gear thickness (mm).
    form_factor : float or array
        Lewis Y (:func:`lewis_form_factor`).

    Returns
    -------
    float or array
        Root bending stress (MPa).
    """
    f = magnitude("tangential_force_N", tangential_force_N)
    m = positive("module_mm", module_mm)
    b = positive("face_width_mm", face_width_mm)
    y = positive("form_factor", form_factor)
    return scalar_or_array(f / (b * m * y))


def hertz_line_contact_stress(normal_force_N: ArrayLike, face_width_mm: ArrayLike, radius1_mm: ArrayLike,
                              radius2_mm: ArrayLike, e1_MPa: float, nu1: float, e2_MPa: float,
                              nu2: float) -> ArrayLike:
    """Maximum Hertz pressure between two parallel cylinders (line contact).

    ::

        p_max = sqrt( F (1/rho1 + 1/rho2) / (pi b ((1 - nu1^2)/E1 + (1 - nu2^2)/E2)) )

    Elastic, frictionless, the contact half-width small against the radii, load uniform along the face
    width ``b`` (Hertz 1881; Shigley's cylinder-contact equations with ``d = 2 rho``; for spur gears at
    the pitch point Shigley Eq. 14-14 with ``F = W_t / cos(phi)``). A concave surface has a negative
    radius (it must be larger in magnitude than the convex one); a flat has ``inf``.

    Parameters
    ----------
    normal_force_N : float or array
        Force normal to the contact (N).
    face_width_mm : float or array
        Contact length along the cylinders (mm).
    radius1_mm, radius2_mm : float or array
        Radii of curvature at the contact (mm); negative for concave, ``inf`` for flat.
    e1_MPa, e2_MPa : float
        Young's moduli (MPa).
    nu1, nu2 : float
        Poisson's ratios.

    Returns
    -------
    float or array
        Maximum contact pressure (MPa), the largest compressive stress.

    Raises
    ------
    GeometryError
        The surfaces are conformal or inverted (``1/rho1 + 1/rho2 <= 0``, e.g. two flats or a convex
        cylinder in a smaller concave one): no Hertz line contact.
    """
    f = magnitude("normal_force_N", normal_force_N)
    b = positive("face_width_mm", face_width_mm)
    r1 = np.asarray(radius1_mm, dtype=np.float64)
    r2 = np.asarray(radius2_mm, dtype=np.float64)
    if np.any(np.isnan(r1) | np.isnan(r2) | (r1 == 0.0) | (r2 == 0.0)):
        raise ValueError(f"radii of curvature must be non-zero (inf for flat), got {radius1_mm}, {radius2_mm}")
    curvature = 1.0 / r1 + 1.0 / r2
    if np.any(curvature <= 0.0):
        raise GeometryError(f"radii {radius1_mm}, {radius2_mm} mm are conformal or inverted: no line contact")
    for name, e, nu in (("1", e1_MPa, nu1), ("2", e2_MPa, nu2)):
        if not (math.isfinite(e) and e > 0.0 and -1.0 < nu < 0.5):
            raise ValueError(f"material {name}: need E > 0 and -1 < nu < 0.5, got E={e}, nu={nu}")
    compliance = (1.0 - nu1 ** 2) / e1_MPa + (1.0 - nu2 ** 2) / e2_MPa
    return scalar_or_array(np.sqrt(f * curvature / (math.pi * b * compliance)))


def involute_contact_radii(pitch_radius1: ArrayLike, pitch_radius2: ArrayLike,
                           pressure_angle: float) -> tuple[ArrayLike, ArrayLike]:
    """Radii of curvature of two involute flanks touching at the pitch point: ``rho_i = r_i sin(phi)``.

    The involute's radius of curvature is the length of its generating line from the base circle, which
    at the pitch point is ``r sin(phi)`` (Shigley Eq. 14-12). For the equivalent gears of a non-circular
    pair pass the local pitch-curve curvature radii (negative for a concave segment, ``inf`` for a
    straight one); the signs carry through.

    Parameters
    ----------
    pitch_radius1, pitch_radius2 : float or array
        Pitch radii, or local pitch-curve curvature radii (mm).
    pressure_angle : float
        Pressure angle (rad), in (0, pi/2).

    Returns
    -------
    (float or array, float or array)
        ``(rho1, rho2)`` in mm.
    """
    if not 0.0 < pressure_angle < math.pi / 2.0:
        raise ValueError(f"pressure angle must be in (0, pi/2) rad, got {pressure_angle}")
    s = math.sin(pressure_angle)
    r1 = np.asarray(pitch_radius1, dtype=np.float64)
    r2 = np.asarray(pitch_radius2, dtype=np.float64)
    return scalar_or_array(r1 * s), scalar_or_array(r2 * s)
