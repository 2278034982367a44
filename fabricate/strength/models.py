"""Closed-form strength models for pin-jointed plate links, their pins, gear teeth and torsion springs.

Every function is a textbook formula with its assumptions and reference in its docstring; the tests
check each against a published worked example (``tests/data/strength_examples.json``).

Units: force N, length mm, stress MPa (= N/mm^2), moment N·mm, angles in radians. Forces and moments
enter as magnitudes (their sign does not matter); dimensions must be positive. The scalar models accept
floats or numpy arrays of equal (broadcastable) shape and return a float for scalar input.

Brittleness: the printed links are SLA resin or PMMA, brittle materials whose static strength is not
protected by local yielding at a notch, so the peak elastic stress (with the stress concentration
factor) is the one compared with the allowable stress, not the nominal stress.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from fabricate.errors import GeometryError

if TYPE_CHECKING:
    from fabricate.strength.section import Section

ArrayLike = float | np.ndarray


def _out(x: np.ndarray) -> ArrayLike:
    """A float for a 0-d result, the array otherwise."""
    return float(x) if np.ndim(x) == 0 else x


def _positive(name: str, value: ArrayLike) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(v) & (v > 0.0)):
        raise ValueError(f"{name} must be finite and positive, got {value}")
    return v


def _non_negative(name: str, value: ArrayLike) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(v) & (v >= 0.0)):
        raise ValueError(f"{name} must be finite and non-negative, got {value}")
    return v


def _magnitude(name: str, value: ArrayLike) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite, got {value}")
    return np.abs(v)


# -- pins --------------------------------------------------------------------------------------------


def pin_shear_stress(force_N: ArrayLike, pin_diameter_mm: ArrayLike, shear_planes: int) -> ArrayLike:
    """Average shear stress of a pin: ``tau = F / (n * pi * d^2 / 4)``.

    Assumes the load divides equally between the ``n`` shear planes (``n = 1`` lap joint, ``n = 2``
    clevis) and the shear is uniform over each circular section: the average shear stress of the
    mechanics-of-materials texts (Hibbeler, *Mechanics of Materials*, ch. 1; checked against his
    Problems 1-49 and 1-61). The peak transverse shear of a solid round pin is 4/3 of this; static pin
    design uses the average.

    Parameters
    ----------
    force_N : float or array
        Force carried by the pin (N).
    pin_diameter_mm : float or array
        Pin diameter (mm).
    shear_planes : int
        Number of shear planes, >= 1.

    Returns
    -------
    float or array
        Average shear stress (MPa).
    """
    if int(shear_planes) != shear_planes or shear_planes < 1:
        raise ValueError(f"shear_planes must be a positive integer, got {shear_planes}")
    f = _magnitude("force_N", force_N)
    d = _positive("pin_diameter_mm", pin_diameter_mm)
    return _out(f / (shear_planes * math.pi * d ** 2 / 4.0))


def pin_bending_moment_double_shear(force_N: ArrayLike, inner_thickness_mm: ArrayLike,
                                    outer_thickness_mm: ArrayLike, gap_mm: ArrayLike = 0.0) -> ArrayLike:
    """Largest bending moment of a clevis pin: ``M = F/2 * (a/2 + g + b/4)``.

    The pin is a beam through two outer plates (each ``a`` thick) and a middle plate (``b`` thick) with
    a gap ``g`` either side of the middle plate. Each plate bears on the pin uniformly over its thickness
    (the usual textbook clevis-pin model, pin loose in all three plates): the outer plates push ``F/2``
    each, the middle plate pulls ``F``. The moment peaks at mid-span (the tests check it against the
    beam statics of these loads)::

        M = F/2 * (a/2 + g + b/2) - F/2 * b/4 = F/2 * (a/2 + g + b/4)

    Parameters
    ----------
    force_N : float or array
        Total force the middle plate transmits (N).
    inner_thickness_mm : float or array
        Middle plate thickness ``b`` (mm).
    outer_thickness_mm : float or array
        Thickness ``a`` of each outer plate (mm).
    gap_mm : float or array
        Axial gap ``g`` between the middle plate and each outer plate (mm), >= 0.

    Returns
    -------
    float or array
        Largest pin bending moment (N·mm).
    """
    f = _magnitude("force_N", force_N)
    b = _positive("inner_thickness_mm", inner_thickness_mm)
    a = _positive("outer_thickness_mm", outer_thickness_mm)
    g = _non_negative("gap_mm", gap_mm)
    return _out(f / 2.0 * (a / 2.0 + g + b / 4.0))


def pin_bending_moment_single_shear(force_N: ArrayLike, thickness_a_mm: ArrayLike,
                                    thickness_b_mm: ArrayLike, gap_mm: ArrayLike = 0.0) -> ArrayLike:
    """Conservative bending moment of a pin joining two plates (lap joint): ``M = F (max(t_a, t_b)/2 + g)``.

    A single-shear pin has no second support: the two bearing resultants ``F`` act a distance
    ``e = t_a/2 + g + t_b/2`` apart, and the couple ``F e`` must come back from the plates through
    non-uniform bearing. How it splits between the plates depends on the fits, which for printed parts
    with running clearance are not known. Two standard idealisations:

    - the couple shared equally (pin loose in both plates): the moment at each plate's mid-plane is
      ``F e / 2 = F (t_a/2 + g + t_b/2) / 2``;
    - the pin built in at one plate face (press fit, bonded, or printed integral with one part) and
      loaded uniformly over the other plate's thickness, the clevis model's uniform-bearing assumption
      applied to a cantilever: ``M = F (t/2 + g)`` at the face of the supporting plate, ``t`` the loading
      plate.

    This returns the envelope of both, ``F (max(t_a, t_b)/2 + g)``, which is never less than ``F e / 2``
    (since ``max(t_a, t_b)/2 >= (t_a + t_b)/4``) and equals the worse cantilever.

    Parameters
    ----------
    force_N : float or array
        Force transmitted between the plates (N).
    thickness_a_mm, thickness_b_mm : float or array
        Plate thicknesses (mm).
    gap_mm : float or array
        Axial gap between the plates (mm), >= 0.

    Returns
    -------
    float or array
        Pin bending moment (N·mm).
    """
    f = _magnitude("force_N", force_N)
    ta = _positive("thickness_a_mm", thickness_a_mm)
    tb = _positive("thickness_b_mm", thickness_b_mm)
    g = _non_negative("gap_mm", gap_mm)
    return _out(f * (np.maximum(ta, tb) / 2.0 + g))


def pin_bending_stress(moment_Nmm: ArrayLike, pin_diameter_mm: ArrayLike) -> ArrayLike:
    """Bending stress of a solid round pin: ``sigma = M c / I = 32 M / (pi d^3)``.

    Parameters
    ----------
    moment_Nmm : float or array
        Bending moment (N·mm).
    pin_diameter_mm : float or array
        Pin diameter (mm).

    Returns
    -------
    float or array
        Largest bending stress at the pin surface (MPa).
    """
    m = _magnitude("moment_Nmm", moment_Nmm)
    d = _positive("pin_diameter_mm", pin_diameter_mm)
    return _out(32.0 * m / (math.pi * d ** 3))


# -- plates at a pin hole ------------------------------------------------------------------------------


def bearing_stress(force_N: ArrayLike, pin_diameter_mm: ArrayLike, thickness_mm: ArrayLike) -> ArrayLike:
    """Average bearing (contact) stress of a pin on a plate: ``sigma = F / (d t)``.

    The load spread over the projected area of the pin in the hole (Hibbeler, *Mechanics of
    Materials*, ch. 1; checked against Gere's Solution 1.8-14).

    Parameters
    ----------
    force_N : float or array
        Force between pin and plate (N).
    pin_diameter_mm : float or array
        Pin diameter (mm).
    thickness_mm : float or array
        Plate thickness bearing on the pin (mm).

    Returns
    -------
    float or array
        Bearing stress (MPa).
    """
    f = _magnitude("force_N", force_N)
    d = _positive("pin_diameter_mm", pin_diameter_mm)
    t = _positive("thickness_mm", thickness_mm)
    return _out(f / (d * t))


def tearout_stress(force_N: ArrayLike, edge_distance_mm: ArrayLike, hole_diameter_mm: ArrayLike,
                   thickness_mm: ArrayLike) -> ArrayLike:
    """Shear-out stress of the material between a loaded hole and the part edge: ``tau = F / (2 t (e - D/2))``.

    The pin pushes a plug of material out along two shear planes parallel to the load, each running
    from the hole's side to the edge (length ``e - D/2``); the simplified lug analysis of Bruhn /
    MechaniCalc "shear failure along two planes". ``e`` is measured from the hole centre to the part edge
    along the load direction.

    Parameters
    ----------
    force_N : float or array
        Force of the pin on the plate, towards the edge (N).
    edge_distance_mm : float or array
        Hole centre to part edge along the load (mm).
    hole_diameter_mm : float or array
        Hole diameter (mm).
    thickness_mm : float or array
        Plate thickness (mm).

    Returns
    -------
    float or array
        Average shear stress on the two planes (MPa).

    Raises
    ------
    GeometryError
        The hole reaches the edge (``e <= D/2``).
    """
    f = _magnitude("force_N", force_N)
    e = _positive("edge_distance_mm", edge_distance_mm)
    dh = _positive("hole_diameter_mm", hole_diameter_mm)
    t = _positive("thickness_mm", thickness_mm)
    ligament = e - dh / 2.0
    if np.any(ligament <= 0.0):
        raise GeometryError(f"hole of diameter {hole_diameter_mm} mm breaks the edge {edge_distance_mm} mm "
                            f"from its centre: no material to shear out")
    return _out(f / (2.0 * t * ligament))


#: Peterson's open-hole fit falls up to 1.4 % short of converged finite elements for large holes
#: (d/w = 0.7); this margin keeps the model above the elastic solution for 0 <= d/w <= 0.7.
OPEN_HOLE_MARGIN = 1.02

#: Pin-loaded lug fit (Frocht & Hill 1940 data, close-fitting pin, square-ended lug, end distance >= width)
#: is stated for this range of d/w.
_LUG_FIT_RANGE = (0.15, 0.75)

#: Frocht & Hill (Shigley Fig. A-15-12 note): "When clearance exists, increase Kt 35 to 50 percent."
#: Printed joints run with a radial clearance, so the upper end is applied.
PIN_CLEARANCE_FACTOR = 1.5


def _lug_kt_close_fit(ratio: float) -> float:
    """Net-section Kt of a pin-loaded lug with a close-fitting pin, cubic in d/w (see the caller)."""
    return 12.882 - 52.714 * ratio + 89.762 * ratio ** 2 - 51.667 * ratio ** 3


def hole_stress_concentration(hole_diameter_mm: float, width_mm: float, pin_loaded: bool, *,
                              pin_clearance: bool = True) -> float:
    """Stress concentration factor on the NET section of a plate of finite width with a central hole.

    The peak stress at the hole edge is ``Kt * F / ((w - d) t)`` for a tensile force ``F``.

    Open hole (``pin_loaded=False``), the plate loaded in tension far from the hole: the curve fit of
    Peterson's Chart 4.1 to Howland's (1930) elasticity solution (Pilkey & Pilkey, *Peterson's Stress
    Concentration Factors*, 3rd ed., Wiley 2008, Eq. for Chart 4.1; the same curve as Roark's Table 17.1
    ``3 - 3.13 x + 3.66 x^2 - 1.53 x^3``)::

        Kt_n = 2 + 0.284 (1 - d/w) - 0.600 (1 - d/w)^2 + 1.32 (1 - d/w)^3,   0 <= d/w < 1

    It gives Kirsch's 3.0 for a small hole and tends to 2 as the ligaments vanish; at d/w = 0.5 it gives
    2.157 against Howland's 2.16 (0.2 %). Converged plane-stress finite elements (quadratic triangles,
    ``tests/benchmarks/bench_strength_fe.py``) give slightly more for large holes, the fit falling short
    by 0.2 % at d/w = 0.3, 0.8 % at 0.5 and 1.4 % at 0.7 (Howland's series is least accurate there), so
    the fit is raised by :data:`OPEN_HOLE_MARGIN` = 2 % to stay on the safe side of the elastic
    solution over the whole range. Heywood's simpler ``2 + (1 - d/w)^3`` is lower still (2.125 at 0.5)
    and is not used.

    Pin-loaded hole (``pin_loaded=True``, a lug: the load enters through a pin bearing on one side of
    the hole and leaves through the plate on the other): the cubic fit of Peterson's chart for a
    square-ended lug with a close-fitting pin, end distance >= width, to Frocht & Hill's (1940)
    photoelastic data (Pilkey & Pilkey 3rd ed., Chart 5.12)::

        Kt_n = 12.882 - 52.714 (d/w) + 89.762 (d/w)^2 - 51.667 (d/w)^3,   0.15 <= d/w <= 0.75

    The coefficients are quoted from that chart as we know it and could not be re-read from a public
    copy (see the tests' data file); they reproduce the chart's shape (about 5.5 at d/w = 0.2, 2.5 at
    0.5, 2.0 at 0.75), and they lie 7 to 18 % above a plane-stress FE of the same lug with the pin load
    idealised as a cosine pressure (``tests/benchmarks/bench_strength_fe.py``), as expected: a real
    pin's contact is narrower than the cosine spread. Outside the fitted range the choice is
    conservative: below d/w = 0.15 the peak is held at the same multiple of the bearing stress
    ``F / (d t)`` as at 0.15 (an infinitely wide plate's peak scales with the bearing stress, so Kt_n
    grows as ``(w - d)/d``); above 0.75 the value at 0.75 is kept (the fit falls further). With
    ``pin_clearance`` (default; printed joints run with clearance) the factor is raised by
    :data:`PIN_CLEARANCE_FACTOR` = 1.5, the upper end of Frocht & Hill's "increase Kt 35 to 50 percent
    when clearance exists" (Shigley, *Mechanical Engineering Design*, Fig. A-15-12).

    Parameters
    ----------
    hole_diameter_mm : float
        Hole diameter ``d`` (mm).
    width_mm : float
        Plate width ``w`` across the hole (mm).
    pin_loaded : bool
        True for a hole loaded by a pin (lug), False for an open hole in a plate in tension.
    pin_clearance : bool
        Pin-loaded only: the pin runs with clearance (raise Kt by 50 %).

    Returns
    -------
    float
        Kt on the net section (dimensionless).

    Raises
    ------
    GeometryError
        The hole is as wide as the plate or wider.
    ValueError
        Non-positive width, negative diameter, or a pin-loaded hole of zero diameter.
    """
    w = float(_positive("width_mm", width_mm))
    d = float(_non_negative("hole_diameter_mm", hole_diameter_mm))
    if d >= w:
        raise GeometryError(f"hole of diameter {d} mm does not fit in a {w} mm wide section")
    ratio = d / w
    if not pin_loaded:
        x = 1.0 - ratio
        return OPEN_HOLE_MARGIN * (2.0 + 0.284 * x - 0.600 * x ** 2 + 1.32 * x ** 3)
    if d == 0.0:
        raise ValueError("a pin-loaded hole needs a positive diameter")
    lo, hi = _LUG_FIT_RANGE
    if ratio < lo:
        # Same peak / bearing-stress ratio as at the lower end of the fit: Kt_n * d / (w - d) constant.
        kt = _lug_kt_close_fit(lo) * (lo / (1.0 - lo)) * ((1.0 - ratio) / ratio)
    else:
        kt = _lug_kt_close_fit(min(ratio, hi))
    return kt * (PIN_CLEARANCE_FACTOR if pin_clearance else 1.0)


def net_section_stress(axial_N: ArrayLike, moment_Nmm: ArrayLike, section: Section, kt: float = 1.0) -> ArrayLike:
    """Peak normal stress on a cut section: ``sigma = Kt (|N| / A + |M| c / I)``.

    Axial force and in-plane bending moment (the moment vector normal to the plate) of everything on
    one side of the cut, taken about the section centroid; the bending stress is ``M c / I`` at the
    extreme fibre. The two add at the worse fibre (conservative when the worse fibre is not the one of
    the axial sign). The stress concentration factor multiplies both because SLA resin and PMMA are
    brittle: the notch peak, not the nominal stress, starts the crack (no yielding redistributes it).
    Using one Kt for both terms is conservative when ``kt`` is the tension factor: a central hole's
    in-plane bending Kt (on ``I_net = t (w^3 - d^3) / 12``, which is what :func:`cut_section` gives) is at
    most 2 and 1.0 below d/w = 0.5, its tension Kt at least 2 (Mott, *Machine Elements in Mechanical
    Design*, Figs. A18-4 and A18-5).

    Parameters
    ----------
    axial_N : float or (n,) array
        Axial force normal to the section (N), e.g. at every pose.
    moment_Nmm : float or (n,) array
        In-plane bending moment about the section centroid (N·mm).
    section : Section
        The cut section (:func:`fabricate.strength.section.cut_section`).
    kt : float
        Stress concentration factor on the net section, >= 1 (e.g. :func:`hole_stress_concentration`).

    Returns
    -------
    float or (n,) array
        Peak normal stress (MPa).
    """
    if not (math.isfinite(kt) and kt >= 1.0):
        raise ValueError(f"stress concentration factor must be >= 1, got {kt}")
    n = _magnitude("axial_N", axial_N)
    m = _magnitude("moment_Nmm", moment_Nmm)
    if section.area_mm2 <= 0.0 or section.inertia_mm4 <= 0.0:
        raise GeometryError("section has no material")
    return _out(kt * (n / section.area_mm2 + m * section.extreme_fibre_mm / section.inertia_mm4))


# -- gear teeth ---------------------------------------------------------------------------------------

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
    return _out(y)


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
    f = _magnitude("tangential_force_N", tangential_force_N)
    m = _positive("module_mm", module_mm)
    b = _positive("face_width_mm", face_width_mm)
    y = _positive("form_factor", form_factor)
    return _out(f / (b * m * y))


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
    f = _magnitude("normal_force_N", normal_force_N)
    b = _positive("face_width_mm", face_width_mm)
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
    return _out(np.sqrt(f * curvature / (math.pi * b * compliance)))


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
    return _out(r1 * s), _out(r2 * s)


# -- springs, margins --------------------------------------------------------------------------------


def torsion_spring_stress(torque_Nmm: ArrayLike, wire_diameter_mm: ArrayLike, coil_index: ArrayLike) -> ArrayLike:
    """Bending stress at the inside of the coil of a helical torsion spring: ``sigma = Ki 32 M / (pi d^3)``.

    The wire of a torsion spring is in bending; its curvature raises the stress at the inner fibre by
    ``Ki = (4 C^2 - C - 1) / (4 C (C - 1))`` (Wahl's curved-beam factor, Shigley Eq. 10-43),
    ``C = D/d`` the spring index (mean coil diameter over wire diameter).

    Parameters
    ----------
    torque_Nmm : float or array
        Moment on the spring (N·mm).
    wire_diameter_mm : float or array
        Wire diameter (mm).
    coil_index : float or array
        Spring index ``C = D/d``, > 1.

    Returns
    -------
    float or array
        Inner-fibre bending stress (MPa).
    """
    m = _magnitude("torque_Nmm", torque_Nmm)
    d = _positive("wire_diameter_mm", wire_diameter_mm)
    c = np.asarray(coil_index, dtype=np.float64)
    if not np.all(np.isfinite(c) & (c > 1.0)):
        raise ValueError(f"spring index D/d must exceed 1, got {coil_index}")
    ki = (4.0 * c ** 2 - c - 1.0) / (4.0 * c * (c - 1.0))
    return _out(ki * 32.0 * m / (math.pi * d ** 3))


def safety_factor(allowable_MPa: ArrayLike, stress_MPa: ArrayLike) -> ArrayLike:
    """Safety factor ``allowable / stress`` (``inf`` where the stress is zero).

    Parameters
    ----------
    allowable_MPa : float or array
        Allowable (failure) stress (MPa), > 0.
    stress_MPa : float or array
        Acting stress (MPa); its magnitude is used.

    Returns
    -------
    float or array
        Safety factor (dimensionless).
    """
    a = _positive("allowable_MPa", allowable_MPa)
    s = _magnitude("stress_MPa", stress_MPa)
    with np.errstate(divide="ignore"):
        return _out(np.where(s == 0.0, np.inf, a / np.where(s == 0.0, 1.0, s)))
