"""Helical torsion springs sized from rate and angle by the standard formulas.

:func:`torsion_spring` picks the thinnest music wire of the supply series that gives a spring which

* has the requested rate, ``k' = E d⁴ / (10.8 D N)`` per turn (:data:`RATE_SOURCE`);
* stays within the wire's allowable bending stress at the largest deflection,
  ``σ = K_B · 32 M / (π d³)`` with ``K_B = (4C² − C − 1) / (4C (C − 1))`` (:data:`STRESS_SOURCE`);
* still clears its pin when wound up: the coil tightens to ``D' = D N / (N + θ/360)``
  (:data:`WINDUP_SOURCE`) and the pin may be at most :data:`ARBOR_RATIO` of the wound inside diameter
  (:data:`ARBOR_SOURCE`);
* has a spring index ``C = D/d`` a spring maker coils (:data:`INDEX_RANGE`).

The legs are taken as rigid: their own bending (which makes a real spring a little softer than the
coil formula) is not modelled, since no public source for its term was found; a spring maker trims the
turns to the measured rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fabricate.catalogue._units import INCH_MM, KSI_MPA
from fabricate.errors import SpecError

RATE_SOURCE = ("k' = E d^4 / (10.8 D N) per turn: Acxess Spring, 'Torsion Spring Rate' "
               "(http://acxesspring.com/torsion-spring-rate-force-constant.html); the constant 10.8 (not the "
               "theoretical 10.2) 'includes an empirical correction ... friction between coils': calculatorlib.com "
               "torsion-spring-calculator")
STRESS_SOURCE = ("sigma = K_B 32 M / (pi d^3): round wire in bending, eng-calculations.com 'Helical torsion spring "
                 "round'; K_B = (4C^2 - C - 1) / (4C (C - 1)), inner fibre: neutrondb.com torsion-spring-calculator "
                 "(SMI / IS 7906-3 / EN 13906-3)")
WINDUP_SOURCE = ("D' = D N / (N + theta/360): the active wire length pi D N is unchanged while the coil winds up by "
                 "theta/360 turns, so the mean diameter shrinks in proportion (the shrinking: neutrondb.com "
                 "torsion-spring-calculator, 'mean coil diameter decreases ... as the spring deflects')")
BODY_SOURCE = ("L = d (N + 1 + theta/360), close wound: Newcomb Spring, 'Torsion Spring Length' "
               "(https://www.newcombspring.com/resources/torsion-spring-length)")
ARBOR_SOURCE = ("arbor <= 0.9 x wound inside diameter: SPEC torsion springs catalogue, 'Suggested mandrel sizes "
                "allow about 10% clearance at the deflections listed' (https://www.biotek.hu/hu/ugyfelkapu/"
                "rugovalaszto/forgatorugok/switch_language/1728/585/49)")
INDEX_SOURCE = ("spring index C = D/d between 4 and 16: costcalculator.calculator.city torsion-spring-rate-calculator, "
                "'A standard manufacturing range is between 4 and 16'")
MODULUS_SOURCE = ("E of music wire A228 by diameter: Shigley's Mechanical Engineering Design, 9th ed., Table 10-5 "
                  "(https://digilib.universitaspertamina.ac.id/ebook/Shigley's%20Mechanical%20Engineering%20Design/"
                  "files/basic-html/page552.html)")
ALLOWABLE_SOURCE = ("allowable bending stress 0.65 x minimum tensile strength: the lower end of the elastic limit in "
                    "tension of music wire A228, 65-75 % of Sut, Shigley's Mechanical Engineering Design, 9th ed., "
                    "Table 10-5 (page552.html, as above)")
WIRE_SOURCE = ("music wire diameters and minimum tensile strengths: Interwire Group, music wire 'Tensile "
               "Requirements' table (https://www.interwiregroup.com/product/tinned-coated-music-wire/)")

#: Pin at most this fraction of the wound inside diameter (the catalogue's "about 10% clearance").
ARBOR_RATIO = 0.9  # ARBOR_SOURCE
#: Spring index range a spring maker coils.
INDEX_RANGE = (4.0, 16.0)  # INDEX_SOURCE
#: Allowable bending stress as a fraction of the wire's minimum tensile strength.
ALLOWABLE_FRACTION = 0.65  # ALLOWABLE_SOURCE: Shigley Table 10-5, music wire A228, tension 65-75 %
#: Fewest active turns accepted (a design choice, not a standard value: below two turns the legs,
#: which the rate formula ignores, dominate the spring).
MIN_TURNS = 2.0  # design choice (see above), not a catalogue value

#: Music wire (diameter in, minimum tensile strength ksi). Interwire "Tensile Requirements", column
#: "Tensile Strength KSI Min", rows 0.010 to 0.125 in.
MUSIC_WIRE_IN_KSI: tuple[tuple[float, float], ...] = (
    (0.010, 387), (0.011, 382), (0.012, 377), (0.013, 373), (0.014, 369),  # Interwire table rows
    (0.015, 365), (0.016, 362), (0.018, 356), (0.020, 350), (0.022, 345),  # Interwire table rows
    (0.024, 341), (0.026, 337), (0.028, 333), (0.030, 330), (0.032, 327),  # Interwire table rows
    (0.034, 324), (0.036, 321), (0.038, 318), (0.040, 315), (0.042, 313),  # Interwire table rows
    (0.045, 309), (0.048, 306), (0.051, 303), (0.055, 300), (0.059, 296),  # Interwire table rows
    (0.063, 293), (0.067, 290), (0.072, 287), (0.076, 284), (0.080, 282),  # Interwire table rows
    (0.085, 279), (0.090, 276), (0.095, 274), (0.100, 271), (0.102, 270),  # Interwire table rows
    (0.107, 268), (0.110, 267), (0.112, 266), (0.121, 263), (0.125, 261),  # Interwire table rows
)
#: Music wire A228 modulus E (MPa) by diameter (upper bound, inch). Shigley Table 10-5: d < 0.032 in
#: 203.4 GPa, 0.033-0.063 in 200 GPa, 0.064-0.125 in 196.5 GPa (0.032 in itself taken with the first row).
MUSIC_WIRE_E_MPA: tuple[tuple[float, float], ...] = (
    (0.0325, 203_400.0),  # Shigley Table 10-5, music wire A228, d < 0.032 in: E 203.4 GPa
    (0.0635, 200_000.0),  # Shigley Table 10-5, 0.033-0.063 in: E 200 GPa
    (0.1255, 196_500.0),  # Shigley Table 10-5, 0.064-0.125 in: E 196.5 GPa
)
MATERIALS = ("music wire",)


def music_wire_modulus_mpa(d_in: float) -> float:
    """Young's modulus (MPa) of music wire of diameter ``d_in`` (inch), from :data:`MUSIC_WIRE_E_MPA`."""
    for upper, e in MUSIC_WIRE_E_MPA:
        if d_in <= upper:
            return e
    raise SpecError("wire", f"no modulus for music wire of {d_in:g} in in the catalogue")


def curvature_factor(index: float) -> float:
    """K_B = (4C² − C − 1) / (4C (C − 1)) for the inner fibre of a coil of index ``C`` (STRESS_SOURCE)."""
    c = index
    return (4.0 * c * c - c - 1.0) / (4.0 * c * (c - 1.0))


def rate_per_deg(e_mpa: float, d_mm: float, mean_d_mm: float, turns: float) -> float:
    """Torsion spring rate (N·mm per degree): ``E d⁴ / (10.8 D N)`` per turn, over 360 (RATE_SOURCE)."""
    return e_mpa * d_mm**4 / (10.8 * mean_d_mm * turns) / 360.0


@dataclass(frozen=True)
class TorsionSpring:
    """A helical torsion spring, fully specified (mm, N·mm, degrees, MPa).

    Angles are deflections from the free (unloaded) position: ``preload_angle_deg`` in the assembled
    position, ``max_deflection_deg`` at the end of the motion.
    """

    material: str
    wire_d_mm: float
    wire_d_in: float
    mean_d_mm: float
    active_turns: float
    leg_lengths_mm: tuple[float, float]
    rate_nmm_per_deg: float
    preload_nmm: float
    preload_angle_deg: float
    max_deflection_deg: float
    max_torque_nmm: float
    inner_d_wound_mm: float
    pin_diameter_mm: float
    body_length_free_mm: float
    body_length_wound_mm: float
    index: float
    curvature_factor: float
    stress_mpa: float
    allowable_mpa: float
    tensile_min_mpa: float
    modulus_mpa: float
    sources: tuple[str, ...]

    @property
    def outer_d_mm(self) -> float:
        return self.mean_d_mm + self.wire_d_mm

    @property
    def inner_d_mm(self) -> float:
        return self.mean_d_mm - self.wire_d_mm

    @property
    def designation(self) -> str:
        """As a spring maker is asked for it."""
        legs = "/".join(f"{v:g}" for v in self.leg_lengths_mm)
        return (f"Torsion spring, {self.material} Ø{self.wire_d_mm:.3f} mm ({self.wire_d_in:.3f} in), "
                f"OD {self.outer_d_mm:.2f} mm, {self.active_turns:.2f} active turns, legs {legs} mm, "
                f"{self.rate_nmm_per_deg:.4g} N·mm/°")


def _positive(path: str, value: float, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpecError(path, f"expected a number, got {value!r}") from None
    if not math.isfinite(v) or v < 0.0 or (v == 0.0 and not allow_zero):
        raise SpecError(path, f"expected a {'non-negative' if allow_zero else 'positive'} finite number, "
                        f"got {value!r}")
    return v


def torsion_spring(rate_nmm_per_deg: float, max_angle_deg: float, preload_nmm: float = 0.0,
                   leg_length_mm: float | tuple[float, float] = 10.0, pin_diameter_mm: float = 2.0,
                   material: str = "music wire") -> TorsionSpring:
    """Size a helical torsion spring for a rate, a working angle and a preload.

    Parameters
    ----------
    rate_nmm_per_deg : float
        Spring rate (N·mm per degree of wind-up).
    max_angle_deg : float
        Working angle beyond the assembled (preloaded) position.
    preload_nmm : float
        Torque in the assembled position (0: the spring is free there).
    leg_length_mm : float or (float, float)
        Leg lengths from the coil axis (both legs alike if one number).
    pin_diameter_mm : float
        The pin the coil turns on.
    material : {"music wire"}

    Returns
    -------
    TorsionSpring
        The thinnest wire of :data:`MUSIC_WIRE_IN_KSI` that works, with the smallest coil for it.

    Raises
    ------
    SpecError
        A non-positive or non-finite input (the field named), an unknown material, or no wire of the
        series gives a spring that meets rate, stress, index and pin clearance at once.
    """
    k = _positive("rate_nmm_per_deg", rate_nmm_per_deg)
    work = _positive("max_angle_deg", max_angle_deg)
    m0 = _positive("preload_nmm", preload_nmm, allow_zero=True)
    pin = _positive("pin_diameter_mm", pin_diameter_mm)
    legs_in = leg_length_mm if isinstance(leg_length_mm, (tuple, list)) else (leg_length_mm, leg_length_mm)
    if len(legs_in) != 2:
        raise SpecError("leg_length_mm", f"expected one length or two, got {leg_length_mm!r}")
    legs = (_positive("leg_length_mm", legs_in[0]), _positive("leg_length_mm", legs_in[1]))
    if material not in MATERIALS:
        raise SpecError("material", f"expected one of {list(MATERIALS)}, got {material!r}")

    preload_deg = m0 / k
    duty = _Duty(rate=k, preload=m0, preload_deg=preload_deg, theta=preload_deg + work, pin=pin, legs=legs,
                 material=material)
    reasons: list[str] = []
    for d_in, sut_ksi in MUSIC_WIRE_IN_KSI:
        spring = _on_wire(duty, d_in, sut_ksi)
        if isinstance(spring, TorsionSpring):
            return spring
        reasons.append(spring)
    theta = duty.theta
    raise SpecError("rate_nmm_per_deg", f"no {material} torsion spring of {k:g} N·mm/° over {theta:g}° "
                    f"(preload {m0:g} N·mm) on a Ø{pin:g} mm pin from wire "
                    f"{MUSIC_WIRE_IN_KSI[0][0] * INCH_MM:.3f}-{MUSIC_WIRE_IN_KSI[-1][0] * INCH_MM:.3f} mm: "
                    + "; ".join(reasons[-3:]))


@dataclass(frozen=True)
class _Duty:
    """What a torsion spring must do: rate (N·mm/°), preload torque (N·mm) and its wind-up (°), the total
    deflection from free at the end of the motion (°), the pin (mm), the legs (mm) and the material."""

    rate: float
    preload: float
    preload_deg: float
    theta: float
    pin: float
    legs: tuple[float, float]
    material: str


def _on_wire(duty: _Duty, d_in: float, sut_ksi: float) -> TorsionSpring | str:
    """The smallest coil of wire ``d_in`` (inch; minimum tensile ``sut_ksi``) that does ``duty``, or why none
    does."""
    k, m0, preload_deg, theta, pin = duty.rate, duty.preload, duty.preload_deg, duty.theta, duty.pin
    turns_wound = theta / 360.0
    m_max = k * theta
    k_turn = k * 360.0
    c_lo, c_hi = INDEX_RANGE
    d = d_in * INCH_MM
    e = music_wire_modulus_mpa(d_in)
    sut = sut_ksi * KSI_MPA
    allow = ALLOWABLE_FRACTION * sut
    # D N is fixed by the rate (N = A / D), so the wound mean diameter A D / (A + θ D) rises with D
    a = e * d**4 / (10.8 * k_turn)
    need = d + pin / ARBOR_RATIO            # least wound mean diameter: pin / ratio inside, plus d
    d_lo = c_lo * d
    d_hi = min(c_hi * d, a / MIN_TURNS)
    if a <= need * turns_wound:
        return f"Ø{d:.3f}: coil cannot clear the pin wound up"
    d_lo = max(d_lo, need * a / (a - need * turns_wound))

    def stress(mean_d: float) -> float:
        return curvature_factor(mean_d / d) * 32.0 * m_max / (math.pi * d**3)

    if d_lo > d_hi:
        return f"Ø{d:.3f}: no coil between index {c_lo:g}..{c_hi:g} with >= {MIN_TURNS:g} turns clears the pin"
    if stress(d_hi) > allow:
        return f"Ø{d:.3f}: {stress(d_hi):.0f} MPa over {allow:.0f} MPa allowable"
    lo, hi = d_lo, d_hi
    if stress(lo) > allow:                  # K_B falls as C grows: the smallest coil within the stress
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if stress(mid) > allow else (lo, mid)
        lo = hi
    mean_d = math.ceil(lo * 100.0 - 1e-9) / 100.0   # a coil diameter to 0.01 mm, rounded up
    if mean_d > d_hi + 1e-12:
        mean_d = lo
    turns = a / mean_d
    wound_mean = mean_d * turns / (turns + turns_wound)
    return TorsionSpring(
        material=duty.material, wire_d_mm=d, wire_d_in=d_in, mean_d_mm=mean_d, active_turns=turns,
        leg_lengths_mm=duty.legs, rate_nmm_per_deg=rate_per_deg(e, d, mean_d, turns), preload_nmm=m0,
        preload_angle_deg=preload_deg, max_deflection_deg=theta, max_torque_nmm=m_max,
        inner_d_wound_mm=wound_mean - d, pin_diameter_mm=pin,
        body_length_free_mm=d * (turns + 1.0), body_length_wound_mm=d * (turns + 1.0 + turns_wound),
        index=mean_d / d, curvature_factor=curvature_factor(mean_d / d), stress_mpa=stress(mean_d),
        allowable_mpa=allow, tensile_min_mpa=sut, modulus_mpa=e,
        sources=(RATE_SOURCE, STRESS_SOURCE, WINDUP_SOURCE, BODY_SOURCE, ARBOR_SOURCE, INDEX_SOURCE,
                 MODULUS_SOURCE, ALLOWABLE_SOURCE, WIRE_SOURCE))
