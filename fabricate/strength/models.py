"""Closed-form strength models for pin-jointed plate links, their pins and torsion springs (gear teeth:
:mod:`fabricate.strength.gear_teeth`), and the argument checks they share.

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


def scalar_or_array(x: np.ndarray) -> ArrayLike:
    """A float for a 0-d result, the array otherwise."""
    return float(x) if np.ndim(x) == 0 else x


def positive(name: str, value: ArrayLike) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(v) & (v > 0.0)):
        raise ValueError(f"{name} must be finite and positive, got {value}")
    return v


def non_negative(name: str, value: ArrayLike) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(v) & (v >= 0.0)):
        raise ValueError(f"{name} must be finite and non-negative, got {value}")
    return v


def magnitude(name: str, value: ArrayLike) -> np.ndarray:
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
    f = magnitude("force_N", force_N)
    d = positive("pin_diameter_mm", pin_diameter_mm)
    return scalar_or_array(f / (shear_planes * math.pi * d ** 2 / 4.0))


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
    f = magnitude("force_N", force_N)
    b = positive("inner_thickness_mm", inner_thickness_mm)
    a = positive("outer_thickness_mm", outer_thickness_mm)
    g = non_negative("gap_mm", gap_mm)
    return scalar_or_array(f / 2.0 * (a / 2.0 + g + b / 4.0))


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
    f = magnitude("force_N", force_N)
    ta = positive("thickness_a_mm", thickness_a_mm)
    tb = positive("thickness_b_mm", thickness_b_mm)
    g = non_negative("gap_mm", gap_mm)
    return scalar_or_array(f * (np.maximum(ta, tb) / 2.0 + g))


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
    m = magnitude("moment_Nmm", moment_Nmm)
    d = positive("pin_diameter_mm", pin_diameter_mm)
    return scalar_or_array(32.0 * m / (math.pi * d ** 3))


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
    f = magnitude("force_N", force_N)
    d = positive("pin_diameter_mm", pin_diameter_mm)
    t = positive("thickness_mm", thickness_mm)
    return scalar_or_array(f / (d * t))


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
    f = magnitude("force_N", force_N)
    e = positive("edge_distance_mm", edge_distance_mm)
    dh = positive("hole_diameter_mm", hole_diameter_mm)
    t = positive("thickness_mm", thickness_mm)
    ligament = e - dh / 2.0
    if np.any(ligament <= 0.0):
        raise GeometryError(f"hole of diameter {hole_diameter_mm} mm breaks the edge {edge_distance_mm} mm "
                            f"from its centre: no material to shear out")
    return scalar_or_array(f / (2.0 * t * ligament))


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
    w = float(positive("width_mm", width_mm))
    d = float(non_negative("hole_diameter_mm", hole_diameter_mm))
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
    n = magnitude("axial_N", axial_N)
    m = magnitude("moment_Nmm", moment_Nmm)
    if section.area_mm2 <= 0.0 or section.inertia_mm4 <= 0.0:
        raise GeometryError("section has no material")
    return scalar_or_array(kt * (n / section.area_mm2 + m * section.extreme_fibre_mm / section.inertia_mm4))


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
    m = magnitude("torque_Nmm", torque_Nmm)
    d = positive("wire_diameter_mm", wire_diameter_mm)
    c = np.asarray(coil_index, dtype=np.float64)
    if not np.all(np.isfinite(c) & (c > 1.0)):
        raise ValueError(f"spring index D/d must exceed 1, got {coil_index}")
    ki = (4.0 * c ** 2 - c - 1.0) / (4.0 * c * (c - 1.0))
    return scalar_or_array(ki * 32.0 * m / (math.pi * d ** 3))


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
    a = positive("allowable_MPa", allowable_MPa)
    s = magnitude("stress_MPa", stress_MPa)
    with np.errstate(divide="ignore"):
        return scalar_or_array(np.where(s == 0.0, np.inf, a / np.where(s == 0.0, 1.0, s)))
