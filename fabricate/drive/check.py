"""The drive check: can the template's actuator supply the input effort the statics compute, at every pose?

The effort is the multiplier of the actuator's driver in :func:`fabricate.strength.statics.solve_statics`
under the template's ``[load]`` (the same loads, assembled once by :func:`fabricate.strength.check.design_loads`;
the strength check's own statics are reused when it ran): a torque (N·mm) for an angle driver, a force (N)
for a slide driver. A design made of several copies driven together (the gripper's three fingers on one
drive plate) needs the sum over the copies.

The rating it is held to is, in this order, the catalogue's rated (continuous) torque or force, else its
stall (or holding) value, at the catalogue's voltage; a tendon's is the template's ``force_N``. The check
passes when ``|effort| <= rating / margin`` at every pose (and a linear actuator's stroke covers the travel).

A check that cannot run is "not checked", never "passed": without ``[actuator]`` (nothing drives the
design), or without a load (the effort would be zero: friction and inertia are not modelled).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.errors import SpecError

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.drive.spec import ActuatorSpec
    from fabricate.mechanism import Driver, Mechanism, Motion
    from fabricate.spec import DesignSpec
    from fabricate.strength.check import StrengthResult
    from fabricate.strength.statics import Statics

#: Actuator kinds that turn (drive an angle driver) and that push or pull (drive a slide driver).
ROTARY = ("servo", "gearmotor", "stepper")
LINEAR = ("linear", "tendon")

#: Why the drive check did not run (``DriveResult.reason``), in the words the CLI prints.
NO_ACTUATOR = "no [actuator] in the template"
NO_LOAD = "no [load] in the template: the input effort is zero (friction and inertia are not modelled)"


@dataclass
class DriveResult:
    """The input effort over the motion against the actuator's rating (see the module docstring).

    Attributes
    ----------
    spec : ActuatorSpec or None
        The template's ``[actuator]``.
    actuator : Actuator or None
        Its catalogue entry (a tendon rated at ``force_N``).
    inputs : (n,) array
        The mechanism's input at every pose (``input_unit``).
    input_unit : str
    effort : (n,) array
        ``|effort|`` the actuator supplies at every pose, summed over the copies it drives (N·mm or N);
        empty when the check did not run.
    unit : str
        ``"N·mm"`` (angle driver) or ``"N"`` (slide driver).
    rating : float
        The rating the effort is held to (before the margin).
    rating_kind : str
        ``"rated"``, ``"stall"`` or ``"stated"`` (a tendon's ``force_N``).
    rating_source : str
        Where the rating comes from (the catalogue's source text).
    copies : int
        Copies of the mechanism the one actuator drives.
    travel : float
        The driver's travel over the motion (deg or mm, summed over direction changes).
    reason : str or None
        Why the check could not run (then it neither passes nor fails).
    notes : list of str
    mount_failures : list of str
        The mount plate's holes over-stressed by the reaction torque (:func:`rate_mount`).
    """

    spec: ActuatorSpec | None
    actuator: Actuator | None
    inputs: np.ndarray
    input_unit: str
    effort: np.ndarray = field(default_factory=lambda: np.zeros(0))
    unit: str = "N·mm"
    rating: float = 0.0
    rating_kind: str = ""
    rating_source: str = ""
    copies: int = 1
    travel: float = 0.0
    reason: str | None = None
    notes: list[str] = field(default_factory=list)
    mount_failures: list[str] = field(default_factory=list)

    @property
    def allowed(self) -> float:
        """The most the design may ask of the actuator: rating / margin."""
        return self.rating / self.spec.margin if self.spec is not None else 0.0

    @property
    def peak(self) -> int:
        """Index of the pose of the largest effort."""
        return int(np.argmax(self.effort))

    @property
    def least_margin(self) -> float:
        """Rating / largest effort (infinite at zero effort): the margin the design actually has."""
        need = float(self.effort[self.peak])
        return self.rating / need if need > 0.0 else math.inf

    @property
    def stroke_short(self) -> bool:
        """Whether the actuator's stroke (when it has one) is shorter than the driver's travel."""
        stroke = self.actuator.stroke_mm if self.actuator is not None else None
        return stroke is not None and self.unit == "N" and self.travel > stroke + 1e-9

    @property
    def passed(self) -> bool | None:
        """Whether the actuator drives the design at every pose; None when the check could not run."""
        if self.reason is not None:
            return None
        return bool(np.all(self.effort <= self.allowed)) and not self.stroke_short

    @property
    def time_s(self) -> float | None:
        """Time for the whole travel at the actuator's no-load speed (None when it has no speed)."""
        speed = self.actuator.no_load_speed if self.actuator is not None else None
        return self.travel / speed if speed else None

    def failures(self) -> list[str]:
        """One line per reason the actuator cannot drive the design (empty when it can or was not checked)."""
        if self.reason is not None or self.actuator is None or self.spec is None:
            return []
        out = list(self.mount_failures)
        a, k = self.actuator, self.peak
        if self.effort[k] > self.allowed:
            many = f" ({self.copies} copies)" if self.copies > 1 else ""
            out.append(f"drive: {a.name} ({a.key}) gives {self.rating:.4g} {self.unit} ({self.rating_kind}) / margin "
                       f"{self.spec.margin:g} = {self.allowed:.4g} {self.unit}, the design needs "
                       f"{self.effort[k]:.4g} {self.unit}{many} at input {self.inputs[k]:.4g} {self.input_unit}; "
                       "choose a stronger actuator or lower the [load]")
        if self.stroke_short:
            out.append(f"drive: {a.name} ({a.key}) strokes {a.stroke_mm:g} mm, the design's slide travels "
                       f"{self.travel:.4g} mm")
        return out

    def report(self) -> dict[str, Any]:
        """report.json's ``drive`` section (fabricate/report_schema.json)."""
        out: dict[str, Any] = {"passed": self.passed}
        if self.reason is not None:
            out["reason"] = self.reason
        if self.spec is not None and self.actuator is not None:
            a = self.actuator
            out["actuator"] = {"key": a.key, "name": a.name, "kind": a.kind, "voltage_V": a.voltage_v,
                               "source": self.spec.source}
            out["driver"] = self.spec.driver
            out["margin"] = self.spec.margin
        if self.reason is None and self.actuator is not None:
            k = self.peak
            out.update({
                "unit": self.unit, "copies": self.copies,
                "rating": _round(self.rating), "rating_kind": self.rating_kind, "rating_source": self.rating_source,
                "allowed": _round(self.allowed),
                "peak_effort": _round(float(self.effort[k])), "peak_input": _round(float(self.inputs[k])),
                "input_unit": self.input_unit, "least_margin": _round(self.least_margin),
                "travel": _round(self.travel), "travel_unit": "mm" if self.unit == "N" else "deg",
                "stroke_mm": self.actuator.stroke_mm,
                "speed": {"no_load": self.actuator.no_load_speed, "unit": self.actuator.speed_unit,
                          "full_travel_s": None if self.time_s is None else _round(self.time_s)},
            })
        out["notes"] = list(self.notes)
        return out


def _round(x: float) -> float | None:
    """``x`` to 6 significant digits; None for a non-finite value (JSON has no infinity)."""
    return float(f"{x:.6g}") if math.isfinite(x) else None


def rating(actuator: Actuator, unit: str) -> tuple[float, str, str]:
    """The rating a drive is held to: ``(value, "rated" | "stall" | "stated", source)``.

    The rated (continuous) value where the catalogue has one, else the stall (or holding) value; a torque
    for ``unit == "N·mm"``, a force for ``"N"``.
    """
    names = ("rated_torque_nmm", "stall_torque_nmm") if unit == "N·mm" else ("rated_force_n", "stall_force_n")
    for name, kind in zip(names, ("rated", "stall"), strict=True):
        value = getattr(actuator, name)
        if value is not None:
            source = dict(actuator.sources).get(name, "")
            if actuator.kind == "tendon":
                kind = "stated"
            return float(value), kind, source
    raise SpecError("actuator.model", f"{actuator.key!r} has no {'torque' if unit == 'N·mm' else 'force'} rating "
                                      "in the catalogue")


def driver_coordinate(mechanism: Mechanism, driver: Driver, inputs: np.ndarray) -> np.ndarray:
    """The driver's coordinate at every input: deg for an angle, mm for a slide (as the solver sets it)."""
    if driver.law is not None:
        value = np.asarray(driver.law(inputs), dtype=np.float64)
        value = np.broadcast_to(value, inputs.shape)
    elif driver.kind == "angle" and mechanism.input_unit == "deg":
        value = np.radians(inputs)
    else:
        value = np.asarray(inputs, dtype=np.float64)
    return np.degrees(value) if driver.kind == "angle" else np.asarray(value, dtype=np.float64)


def input_statics(design: DesignSpec, mechanism: Mechanism, motion: Motion, hints: Any,
                  strength: StrengthResult | None = None) -> Statics | None:
    """The statics under the design load: the strength check's when it solved them, else solved here with
    the same loads (:func:`fabricate.strength.check.design_loads`); None when nothing loads the design."""
    from fabricate.strength.check import design_loads
    from fabricate.strength.statics import solve_statics

    if strength is not None and strength.statics is not None:
        return strength.statics
    loads = design_loads(design, mechanism, motion, hints)
    if not loads.described:
        return None
    return solve_statics(mechanism, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)


def run_drive(design: DesignSpec, mechanism: Mechanism, motion: Motion, hints: Any,
              strength: StrengthResult | None = None, copies: int = 1) -> DriveResult:
    """The drive check of ``design.actuator`` over ``motion`` (see the module docstring).

    Raises
    ------
    SpecError
        ``actuator.driver`` names no driver of the mechanism, or ``actuator.model`` cannot drive its kind
        (a servo on a slide, a linear actuator on an angle).
    """
    spec = design.actuator
    inputs = np.asarray(motion.inputs, dtype=np.float64)
    if spec is None:
        return DriveResult(None, None, inputs, mechanism.input_unit, reason=NO_ACTUATOR)
    if spec.driver >= len(mechanism.drivers):
        raise SpecError("actuator.driver", f"the mechanism has {len(mechanism.drivers)} driver(s) "
                                           f"(0..{len(mechanism.drivers) - 1}), got {spec.driver}")
    driver = mechanism.drivers[spec.driver]
    actuator = spec.entry()
    fits = ROTARY if driver.kind == "angle" else LINEAR
    if actuator.kind not in fits:
        what = "an angle" if driver.kind == "angle" else "a slide"
        raise SpecError("actuator.model", f"driver {spec.driver} of this design is {what} ({driver.body} on "
                                          f"{driver.reference}): a {actuator.kind} cannot drive it; use one of "
                                          f"{', '.join(_keys_of(fits))}")
    unit = "N·mm" if driver.kind == "angle" else "N"
    value, kind, source = rating(actuator, unit)
    travel = float(np.sum(np.abs(np.diff(driver_coordinate(mechanism, driver, inputs)))))
    result = DriveResult(spec, actuator, inputs, mechanism.input_unit, unit=unit, rating=value, rating_kind=kind,
                         rating_source=source, copies=max(1, int(copies)), travel=travel)
    if result.copies > 1:
        result.notes.append(f"one actuator drives the {result.copies} copies of the mechanism together: the effort "
                            "is the sum over them")
    if kind == "stall":
        volts = f" at {actuator.voltage_v:g} V" if actuator.voltage_v is not None else ""
        result.notes.append(f"the catalogue gives no rated (continuous) value: the stall or holding value{volts} is "
                            "used, so the margin is all the reserve there is")
        if actuator.kind == "stepper":
            # no pull-out curve was found for the catalogued steppers (catalogue/actuators.py gaps): say so
            result.notes.append("a stepper's holding torque is its torque at standstill; its pull-out torque falls "
                                "with the step rate and depends on the driver (no pull-out curve in the catalogue): "
                                "the check assumes the motion is run slowly; at speed, hold the effort to the "
                                "maker's pull-out curve at that step rate")
    load = design.load
    if load is not None and spec.driver == 0 and (load.input_force_N or load.input_torque_Nmm):
        push = load.input_force_N if driver.kind == "slide" else load.input_torque_Nmm
        result.notes.append(f"the design load is the actuator's own effort ([load] {push:g} {unit}): the check says "
                            "the actuator gives it with the margin; limit the drive to it (more overloads the parts "
                            "the strength check holds to it)")
    statics = input_statics(design, mechanism, motion, hints, strength)
    if statics is None:
        result.reason = NO_LOAD
        return result
    result.effort = np.abs(np.asarray(statics.driver_efforts[:, spec.driver], dtype=np.float64)) * result.copies
    return result


def _keys_of(kinds: tuple[str, ...]) -> list[str]:
    from fabricate.catalogue.actuators import CATALOGUE
    from fabricate.drive.spec import catalogue_keys

    return [k for k in catalogue_keys() if CATALOGUE[k].kind in kinds]


def drive_markdown(section: Mapping[str, Any]) -> list[str]:
    """report.md's drive paragraph from report.json's ``drive`` section (lines, ending with a blank one)."""
    if not section:
        return []
    out = ["## Drive", ""]
    a = section.get("actuator") or {}
    if section.get("passed") is None:
        what = f"{a.get('name')} (`{a.get('key')}`): " if a else ""
        out += [f"Drive: {what}not checked: {section.get('reason') or 'no reason given'}.", ""]
        return out
    unit, iu = section.get("unit", ""), section.get("input_unit", "")
    verdict = "passed" if section.get("passed") else "FAILED"
    volts = f" at {a['voltage_V']:g} V" if a.get("voltage_V") is not None else ""
    out += [f"Actuator: **{a.get('name')}** (`{a.get('key')}`, {a.get('kind')}) on driver {section.get('driver')}"
            + (f" — {a['source']}" if a.get("source") else "") + ".", "",
            f"Drive check {verdict}: the input needs at most {_num(section.get('peak_effort'))} {unit} (at input "
            f"{_num(section.get('peak_input'))} {iu}); the actuator gives {_num(section.get('rating'))} {unit} "
            f"({section.get('rating_kind')}{volts}) / margin {_num(section.get('margin'))} = "
            f"{_num(section.get('allowed'))} {unit}. Least margin over the motion: "
            f"{_num(section.get('least_margin'))}. Effort over the motion: `plots/drive.png`.", ""]
    speed = section.get("speed") or {}
    if speed.get("full_travel_s") is not None:
        out += [f"Full travel ({_num(section.get('travel'))} {section.get('travel_unit')}) at the no-load speed "
                f"{_num(speed.get('no_load'))} {speed.get('unit')}: {_num(speed.get('full_travel_s'))} s.", ""]
    notes = section.get("notes") or []
    out += [f"- {n}" for n in notes]
    return out + ([""] if notes else [])


def _num(x: Any) -> str:
    return f"{x:.4g}" if isinstance(x, (int, float)) and not isinstance(x, bool) else str(x)


def rate_mount(result: DriveResult, partset: Any, design: DesignSpec) -> None:
    """The actuator's mount plate (role ``mount``) against the reaction torque: the peak effort ``T`` the
    motor gives comes back through its own fixing screws into the plate and out through the standoff screws
    into the ground part. A screw group at radii ``r_i`` about the output axis takes ``F_i = T r_i / sum r_j**2``
    (the rigid-plate share); each hole bears ``F / (d t)`` on the plate (``d`` the screw or hole, ``t`` the
    plate), held to the part material's compressive strength with ``[checks] min_safety_factor``. Adds a note
    with the numbers, and a failure below the factor; nothing where there is no plate, no rotary effort or no
    material."""
    import re

    placed = getattr(partset, "actuator", None)
    material = design.process.part_material()
    if (placed is None or not placed.mount_part or result.reason is not None or result.unit != "N·mm"
            or not len(result.effort) or material is None or result.actuator is None):
        return
    torque = float(result.effort[result.peak])
    plate = partset.part(placed.mount_part)
    t = float(plate.thickness_mm)
    groups: list[tuple[str, np.ndarray, float]] = []
    if placed.standoffs:
        sizes = [re.search(r"M(\d+(?:\.\d+)?)", f.designation) for f in placed.fasteners
                 if f.purpose.startswith("mount plate to the ground")]
        d = float(sizes[0].group(1)) if sizes and sizes[0] else min(s.inner_diameter_mm for s in placed.standoffs)
        radii = np.array([float(np.hypot(*(np.asarray(s.centre) - np.asarray(placed.axis)))) for s in placed.standoffs])
        groups.append(("standoff screws", radii, d))
    holes = result.actuator.mounting_holes or ()
    if holes:
        radii = np.array([math.hypot(h.x, h.y) for h in holes])
        groups.append(("actuator's fixing holes", radii, min(h.diameter_mm for h in holes)))
    need = float(design.checks.min_safety_factor)
    for what, radii, d in groups:
        if float(np.sum(radii ** 2)) <= 0.0:
            continue
        force = torque * float(np.max(radii)) / float(np.sum(radii ** 2))
        stress = force / (d * t)
        factor = material.compressive_MPa / stress if stress > 0.0 else math.inf
        line = (f"mount plate {placed.mount_part}, {what}: {len(radii)} at up to {float(np.max(radii)):.3g} mm from "
                f"the axis take the {torque:.4g} N·mm reaction as {force:.3g} N each, bearing {stress:.3g} MPa on "
                f"Ø{d:g} in the {t:g} mm plate: safety factor {factor:.3g} against {material.compressive_MPa:g} MPa "
                "compressive")
        result.notes.append(line)
        if factor < need:
            result.mount_failures.append(f"drive: {line} < {need:g}; a thicker plate (process.thickness_mm)")
