"""``[gears] module_mm = "auto"``: the smallest standard module the process can make and the load allows.

Candidates are the standard modules of DIN 780-1:1977 (Modulreihe für Zahnräder) series 1 and 2, 0.05 ... 50 mm
(the spec's range), smallest first. From 1 mm up the two series are ISO 54:1996's series I and II; ISO 54's
6.5 mm ("to be avoided") is left out, and DIN 780-1's series-2 values below 1 mm (0.055 ... 0.95) are kept.
Series 1 is preferred by the standards; the search takes both, so that "smallest" is the smallest a standard
cutter or a catalogue gear has.

A candidate is cut on the pitch curves the synthesis fixed (the centre distance is not ours to change) and
kept when all of these hold (the mesh check is left to the chosen pair, which the pipeline checks in full):

- it can be cut at all: :func:`~fabricate.gears.build.make_gear_pair` raises no :class:`SpecError` (the module
  against the pitch curvature and ``min_teeth``, the tooth and time bounds);
- the pair's own tooth checks pass (:meth:`GearPair.failures` without a mesh: no undercut beyond
  :func:`~fabricate.gears.checks.undercut_limit_mm`, no pointed teeth, contact ratio >= 1);
- the tooth tip land is at least the process's ``min_feature_mm`` (the printability check's test and tolerance,
  :func:`fabricate.checks.printability.check_printability`);
- at the stated ``[load]``, Lewis root bending of both gears and Hertz contact keep ``[checks]
  min_safety_factor`` (:func:`fabricate.strength.features.tooth_stresses`, the models the strength check uses,
  with the process's plate thickness as the face width, the torque on the gear from the same statics). Where
  the strength check cannot run (no materials, no load) this criterion is left out and the choice says so.

A closed pair's perimeters must hold whole teeth: a candidate module becomes the nearest tooth count that
closes the law, and the module the pitch curves then give (``perimeter_a / (pi z_a)``, within a few per cent
of the candidate) is the one judged and built; the report gives both.

The pressure angle: a template that fixes it (``pressure_angle_deg = 20``) gets the modules scanned at that angle.
Left out, or ``"auto"``, with the module chosen, the modules are scanned at 20 deg and, only when none passes
there, at 22.5 and then 25 deg (:data:`fabricate.gears.spec.STANDARD_PRESSURE_ANGLES_DEG`, the full-depth systems
of Shigley's Table 13-1); the first angle with a passing module is taken. A larger angle narrows the tooth tip
(the rack's tip land ``pi m / 2 - 2 h_a m tan alpha``) but lowers the undercut limit (``~ h_a m / sin^2 alpha``),
so on fixed pitch curves it opens a window of modules a fine process's tip land closes at 20 deg; and it lowers
the Hertz contact pressure as ``1 / sqrt(sin 2 alpha)`` (5 % from 20 to 22.5 deg, 8 % to 25 deg). The Lewis form
factors are the 20 deg table's at every angle: a larger angle's thicker root makes them conservative.

When no candidate passes, the pair is built with the largest module whose only faults are the process's and the
load's (tip land, strength), the one closest to passing, and :meth:`GearPair.failures` names what no standard module
satisfies (the build exits 1); with an automatic angle, at each angle tried. When only the Hertz contact fails, at
every module, the smallest module passing the rest is built. The scan stops at the first undercut module or the
first the pitch curves cannot hold (every larger one fails the same way), and a module whose rack tooth is already
too narrow at the tip is rejected without cutting it when the pitch curves are convex, so a choice cuts a handful of
candidates (seconds).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import GeometryError, SpecError
from fabricate.gears.spec import MIN_MODULE_MM, GearSpec

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.hints import PartHints
    from fabricate.mechanism import Mechanism, Motion
    from fabricate.process import Material
    from fabricate.spec import DesignSpec

#: DIN 780-1:1977 series 1 (preferred), mm; from 1 mm the same as ISO 54:1996 series I.
SERIES_1_MM = (0.05, 0.06, 0.08, 0.1, 0.12, 0.16, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9,
               1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0, 40.0, 50.0)
#: DIN 780-1:1977 series 2, mm; from 1 mm ISO 54:1996 series II (its 6.5, "to be avoided", left out).
SERIES_2_MM = (0.055, 0.07, 0.09, 0.11, 0.14, 0.18, 0.22, 0.28, 0.35, 0.45, 0.55, 0.65, 0.75, 0.85, 0.95,
               1.125, 1.375, 1.75, 2.25, 2.75, 3.5, 4.5, 5.5, 7.0, 9.0, 11.0, 14.0, 18.0, 22.0, 28.0, 36.0, 45.0)
SERIES_NAME = "DIN 780-1 series 1 and 2"
#: The process's and the load's criteria: a larger module helps them (the fallback when nothing passes).
_PROCESS_KINDS = frozenset({"tip_land", "lewis", "hertz"})


def standard_modules(lo: float = MIN_MODULE_MM, hi: float = 50.0) -> tuple[float, ...]:
    """Both series merged, ascending, within ``[lo, hi]`` mm."""
    return tuple(sorted(m for m in SERIES_1_MM + SERIES_2_MM if lo - 1e-12 <= m <= hi + 1e-12))


@dataclass(frozen=True)
class ToothLoad:
    """What the teeth must carry: the torque on gear b of each coupling at every pose, and the allowables.

    Attributes
    ----------
    torques : dict of str to ndarray
        Coupling name -> torque on its gear b (N·mm) per pose (the statics' ``gear_torques``).
    motion : Motion
    face_mm : float
        Face width, the plate thickness of the gears.
    material : Material
        The gears' material (Lewis against its flexural, Hertz against its compressive strength).
    required : float
        ``[checks] min_safety_factor``.
    """

    torques: dict[str, np.ndarray]
    motion: Motion
    face_mm: float
    material: Material
    required: float


@dataclass(frozen=True)
class ModuleLimits:
    """What a module must satisfy: the process's smallest feature and, where the strength check can run, the
    load (``load`` None: ``note`` says why strength is no criterion)."""

    min_feature_mm: float
    load: ToothLoad | None = None
    note: str = ""


def module_limits(design: DesignSpec, mechanism: Mechanism, motion: Motion, hints: PartHints) -> ModuleLimits:
    """The limits of ``design``'s process and load for an automatic module (see the module docstring).

    The statics are those of :func:`fabricate.strength.check.run_strength` (same loads, same solver), solved
    once here for the gear torques; the face width is the process thickness every plate is cut or printed at.
    """
    from fabricate.strength.check import NO_LOAD, NO_MATERIALS, design_loads
    from fabricate.strength.statics import solve_statics

    process = design.process
    minimum = float(process.min_feature_mm)
    material = process.part_material()
    if material is None or process.pin_material_spec() is None:
        return ModuleLimits(minimum, None, f"strength not a criterion: {NO_MATERIALS}")
    try:
        loads = design_loads(design, mechanism, motion, hints)
        if not loads.described:
            return ModuleLimits(minimum, None, f"strength not a criterion: {NO_LOAD}")
        statics = solve_statics(mechanism, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    except GeometryError as exc:
        # the strength stage reports it in its own words; the module is then chosen on the geometry alone
        return ModuleLimits(minimum, None, f"strength not a criterion: {exc}")
    load = ToothLoad({k: np.asarray(v, dtype=np.float64) for k, v in statics.gear_torques.items()}, motion,
                     float(process.thickness_mm), material, float(design.checks.min_safety_factor))
    return ModuleLimits(minimum, load)


@dataclass(frozen=True)
class Verdict:
    """Why one candidate module was rejected (empty ``reasons``: it passes), each reason with its kind."""

    module_mm: float  # the candidate (standard) module
    built_mm: float | None  # the module of the pair cut (a closed pair's whole teeth), None if none was cut
    reasons: tuple[tuple[str, str], ...]  # (kind, words)

    @property
    def passed(self) -> bool:
        return not self.reasons

    def report(self) -> dict[str, Any]:
        out: dict[str, Any] = {"module_mm": self.module_mm}
        if self.built_mm is not None and abs(self.built_mm - self.module_mm) > 1e-12:
            out["built_module_mm"] = round(self.built_mm, 6)
        out["reasons"] = [words for _, words in self.reasons]
        return out


def judge(pair: GearPair, limits: ModuleLimits) -> list[tuple[str, str]]:
    """Every criterion ``pair`` fails, as (kind, words); empty when its module is one the process can make.

    Kinds: ``undercut``, ``pointed``, ``contact_ratio`` (the pair's own checks), ``tip_land`` (the process),
    ``lewis``, ``hertz`` (the load).
    """
    from fabricate.strength.features import tooth_stresses

    out: list[tuple[str, str]] = []
    for words in pair.failures():  # no mesh yet: only the geometric checks
        kind = "undercut" if words.startswith("undercut") else "pointed" if words.startswith("pointed") else \
            "contact_ratio"
        out.append((kind, words))
    land = float(pair.checks["tip_land_min_mm"])
    if land < limits.min_feature_mm - 1e-9:  # printability's own tolerance
        out.append(("tip_land", f"tip land {land:.3f} mm < the process's minimum feature "
                                f"{limits.min_feature_mm:.3f} mm"))
    load = limits.load
    if load is not None and pair.coupling in load.torques:
        stresses = tooth_stresses(pair, load.torques[pair.coupling], load.motion, load.face_mm, load.material)
        root = max(float(np.max(sigma)) for sigma, _, _ in stresses.lewis.values())
        sf = _safety(load.material.flexural_MPa, root)
        if sf < load.required:
            out.append(("lewis", f"Lewis root bending {root:.1f} MPa: safety factor {sf:.2f} < {load.required:g}"))
        contact = float(np.max(stresses.hertz_MPa))
        sf = _safety(load.material.compressive_MPa, contact)
        if sf < load.required:
            # the contact pressure falls as 1 / sqrt(face width): the width that would keep the factor
            face = load.face_mm * (load.required / sf) ** 2
            out.append(("hertz", f"Hertz contact {contact:.1f} MPa: safety factor {sf:.2f} < {load.required:g} "
                                 f"on {load.face_mm:g} mm plates ({face:.2f} mm would keep {load.required:g})"))
    return out


def _safety(allowable: float, stress: float) -> float:
    return math.inf if stress <= 0.0 else float(allowable) / stress


def rack_tip_land_mm(module: float, spec: GearSpec) -> float:
    """Tip width of the generating rack's tooth, ``pi m / 2 - 2 h_a tan(alpha)`` (mm, before backlash).

    An external involute tooth is narrower at its tip than the rack that cuts it, the more so the fewer the
    teeth (ISO 21771's tip thickness ``d_a (s / d + inv alpha - inv alpha_a)`` falls below the rack's for any
    finite tooth count), so on a convex pitch curve this bounds the tip land from above.
    """
    return float(np.pi * module / 2.0 - 2.0 * spec.addendum * module * np.tan(spec.pressure_angle))


def choose_module(make: Callable[[GearSpec], GearPair], spec: GearSpec, limits: ModuleLimits, *,
                  convex: bool = False) -> tuple[GearPair, dict[str, Any]]:
    """The pair cut with the smallest standard module that passes :func:`judge`, and the choice for the report.

    With an automatic pressure angle (``spec.pressure_angle_candidates``) the modules are scanned at each
    standard angle in turn (20, 22.5, 25 deg) and the first angle at which one passes is taken: 20 deg is the
    standard basic rack, and a larger angle is what a gear designer turns to when the window between the tip
    land (narrower teeth tips at a larger angle) and the undercut (a larger angle allows a larger module on the
    same pitch curves) holds no module, or to lower the contact stress (``sigma_H^2 ~ 1 / sin 2 alpha``).

    Parameters
    ----------
    make : callable
        ``make(spec) -> GearPair``: the pair cut with ``spec`` (a fixed module), without its mesh check.
    spec : GearSpec
        The template's spec (``module_mm`` None: auto).
    limits : ModuleLimits
    convex : bool
        Both pitch curves are convex over the range the teeth cover: a module whose rack tip
        (:func:`rack_tip_land_mm`) is below the minimum feature is rejected without cutting it.

    Returns
    -------
    pair : GearPair
        Cut with the chosen module (or the fallback when none passes: see the module docstring).
    choice : dict
        report.json's ``gears[].module_choice``.

    Raises
    ------
    SpecError
        No standard module can be cut on these pitch curves at all (naming ``gears.module_mm``).
    """
    angles = spec.pressure_angle_candidates
    if not angles:
        scan = _scan(make, spec, limits, convex)
        if not scan.pairs:
            assert scan.first_error is not None  # every candidate raised
            raise SpecError("gears.module_mm", f"no standard module ({SERIES_NAME}) can be cut on these pitch "
                                               f"curves; the smallest: {scan.first_error.message}")
        return _choice(scan, limits)
    scans = []
    for degrees, dedendum, fillet in angles:
        at = replace(spec, pressure_angle_deg=degrees, dedendum=dedendum, root_fillet=fillet,
                     pressure_angle_candidates=())
        scans.append(_scan(make, at, limits, convex))
        if scans[-1].found:
            break
    cut = [sc for sc in scans if sc.pairs]
    if not cut:
        first = scans[0].first_error
        assert first is not None  # every candidate at every angle raised
        raise SpecError("gears.module_mm", f"no standard module ({SERIES_NAME}) can be cut on these pitch curves at "
                                           f"any pressure angle; the smallest: {first.message}")
    # none passing: of the angles whose closest module fails only the contact stress (no module helps it), the
    # largest (the lowest contact stress); else the standard 20 deg's closest
    only_contact = [sc for sc in cut if {k for k, _ in _closest(sc.verdicts).reasons} <= {"hertz"}]
    built = scans[-1] if scans[-1].found else (only_contact[-1] if only_contact else cut[0])
    pair, choice = _choice(built, limits)
    choice["pressure_angle_deg"] = built.degrees
    choice["pressure_angle"] = {"mode": "auto", "candidates_deg": [a for a, _, _ in angles],
                                "tried_deg": [sc.degrees for sc in scans], "source": ANGLE_SOURCE}
    choice["rejected"] = [dict(v.report(), pressure_angle_deg=sc.degrees) for sc in scans for v in sc.verdicts
                          if not v.passed]
    if not built.found:
        contact = all(_contact_everywhere(sc.verdicts) for sc in cut)
        words = [f"at {sc.degrees:g} deg: " + (_limits_words(sc.verdicts, contact=not contact) or "no other limit")
                 for sc in cut]
        if contact:  # one reason for every angle, worded once at the angle that comes closest
            best = cut[-1].verdicts
            words.insert(0, "the Hertz contact fails at every module and angle (the contact stress does not depend "
                            f"on the module: thicker plates or a lighter load), least at {cut[-1].degrees:g} deg: "
                            + next(w for v in best for k, w in v.reasons if k == "hertz"))
        choice["unsatisfied"] = (f"no standard module ({SERIES_NAME}) at pressure angle "
                                 f"{_angles_words([sc.degrees for sc in scans])} deg satisfies the process and the "
                                 f"load: {'; '.join(words)}; built with module {float(pair.module):.4g} mm at "
                                 f"{built.degrees:g} deg")
    return pair, choice


#: Where the automatic pressure angles come from (report.json's ``module_choice.pressure_angle.source``).
ANGLE_SOURCE = ("full-depth systems 20, 22.5, 25 deg of Shigley's Mechanical Engineering Design Table 13-1; "
                "20 deg is ISO 53's basic rack")


def _angles_words(degrees: list[float]) -> str:
    words = [f"{d:g}" for d in degrees]
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


@dataclass(frozen=True)
class _Scan:
    """The standard modules tried at one pressure angle, in order, and the pairs cut."""

    degrees: float
    verdicts: list[Verdict]
    pairs: dict[float, GearPair]
    first_error: SpecError | None

    @property
    def found(self) -> bool:
        return bool(self.verdicts) and self.verdicts[-1].passed


def _scan(make: Callable[[GearSpec], GearPair], spec: GearSpec, limits: ModuleLimits, convex: bool) -> _Scan:
    """Every standard module, smallest first, cut with ``spec``'s pressure angle and judged, up to the first that
    passes (or the first undercut one, or the first the pitch curves cannot hold once one could be cut)."""
    verdicts: list[Verdict] = []
    pairs: dict[float, GearPair] = {}
    first_error: SpecError | None = None
    for module in standard_modules():
        bound = rack_tip_land_mm(module, spec)
        if convex and bound < limits.min_feature_mm - 1e-9:
            # no need to cut it: a convex pitch curve's teeth are narrower at the tip than the rack's
            verdicts.append(Verdict(module, None, (("tip_land", f"tip land at most {bound:.3f} mm (the rack's; a "
                                                               "convex gear's is narrower) < the process's minimum "
                                                               f"feature {limits.min_feature_mm:.3f} mm"),)))
            continue
        trial = replace(spec, module_mm=module)
        try:
            pair = make(trial)
        except SpecError as exc:
            first_error = first_error or exc
            verdicts.append(Verdict(module, None, (("cut", f"{exc.path}: {exc.message}"),)))
            if pairs:
                break  # larger modules than one the pitch curves cannot hold fail the same way
            continue
        reasons = tuple(judge(pair, limits))
        verdicts.append(Verdict(module, float(pair.module), reasons))
        pairs[module] = pair
        if not reasons:
            break
        if any(kind == "undercut" for kind, _ in reasons):
            break  # the undercut limit grows with the module, the pitch curvature does not: every larger one is
    return _Scan(float(spec.pressure_angle_deg), verdicts, pairs, first_error)


def _choice(scan: _Scan, limits: ModuleLimits) -> tuple[GearPair, dict[str, Any]]:
    """The pair one scan builds (its passing module, else :func:`_closest`) and report.json's choice."""
    verdicts = scan.verdicts
    chosen = scan.pairs[verdicts[-1].module_mm] if scan.found else scan.pairs[_closest(verdicts).module_mm]
    choice: dict[str, Any] = {
        "mode": "auto",
        "series": SERIES_NAME,
        "found": scan.found,
        "chosen_module_mm": verdicts[-1].module_mm if scan.found else None,
        "built_module_mm": round(float(chosen.module), 6),
        "criteria": _criteria(limits),
        "rejected": [v.report() for v in verdicts if not v.passed],
    }
    if not scan.found:
        choice["unsatisfied"] = _unsatisfied(verdicts, float(chosen.module))
    return chosen, choice


def _closest(verdicts: list[Verdict]) -> Verdict:
    """The module to build when none passes.

    The smallest that fails nothing but a fault every candidate has (the Hertz contact, which no module changes);
    else the largest whose faults are all the process's or the load's (a larger module would help them); else the
    smallest that could be cut."""
    cut = [v for v in verdicts if v.built_mm is not None]
    everywhere = {"hertz"} if all(any(k == "hertz" for k, _ in v.reasons) for v in cut) else set()
    only = [v for v in cut if {k for k, _ in v.reasons} <= everywhere]
    if only:
        return only[0]
    closest = [v for v in cut if {k for k, _ in v.reasons} <= _PROCESS_KINDS]
    return closest[-1] if closest else cut[0]


def _criteria(limits: ModuleLimits) -> dict[str, Any]:
    load = limits.load
    out: dict[str, Any] = {"min_feature_mm": limits.min_feature_mm}
    if load is None:
        out.update({"strength": None, "note": limits.note})
    else:
        out.update({"strength": {"required_safety_factor": load.required, "face_width_mm": load.face_mm,
                                 "material": load.material.name}})
    return out


def _unsatisfied(verdicts: list[Verdict], built: float) -> str:
    """What no standard module satisfies, in words: per criterion the candidate that shows its limit."""
    return (f"no standard module ({SERIES_NAME}) satisfies the process and the load: " + _limits_words(verdicts)
            + f"; built with module {built:.4g} mm")


def _contact_everywhere(verdicts: list[Verdict]) -> bool:
    """Every module of one scan that was cut fails the Hertz contact."""
    cut = [v for v in verdicts if v.built_mm is not None]
    return bool(cut) and all(any(k == "hertz" for k, _ in v.reasons) for v in cut)


def _limits_words(verdicts: list[Verdict], contact: bool = True) -> str:
    """Per criterion the candidate of one scan that shows its limit (see :func:`_unsatisfied`); ``contact``: with
    the Hertz contact where it fails at every module."""
    parts = []
    cut = [v for v in verdicts if v.built_mm is not None]
    for kind in ("tip_land", "lewis"):  # a lower bound on the module: the largest that still fails
        failing = [v for v in cut if any(k == kind for k, _ in v.reasons)]
        if failing:
            v = failing[-1]
            parts.append(f"m = {v.module_mm:g}: {next(w for k, w in v.reasons if k == kind)}")
    for kind in ("undercut", "pointed", "contact_ratio", "cut"):  # an upper bound: the smallest that fails
        failing = [v for v in verdicts if any(k == kind for k, _ in v.reasons)
                   and v.module_mm > (cut[0].module_mm if cut else 0.0)]
        if failing:
            v = failing[0]
            parts.append(f"m = {v.module_mm:g}: {next(w for k, w in v.reasons if k == kind)}")
    hertz = [v for v in cut if any(k == "hertz" for k, _ in v.reasons)]
    if contact and hertz and len(hertz) == len(cut):
        words = next(w for k, w in hertz[-1].reasons if k == "hertz")
        parts.append(f"at every module (the contact stress does not depend on it: thicker plates or a lighter "
                     f"load): {words}")
    return "; ".join(parts)
