"""Pin retention and hole fits: how each pin is kept in, the hole every part has on it, and the standard
pin, washers and retainers that make up its stack.

Pure functions of the process profile (:class:`~fabricate.process.ProcessSpec`) and the catalogue
(:mod:`fabricate.catalogue.pins`, :mod:`~fabricate.catalogue.hardware`, :mod:`~fabricate.catalogue.clips`);
nothing here places parts or draws.

Fits
----
Two sizes of a hole are kept apart (:class:`HoleSize`):

- the NOMINAL diameter is the fit's: ``running`` pin + 2 × running clearance; ``press`` pin − the
  profile's press-fit interference; ``clearance`` (a screw) screw + 2 × running clearance. It is what the
  finished part should measure.
- the MODELLED diameter is the nominal plus the process's ``hole_compensation_mm`` (SLA prints holes
  undersize): the CAD, STL and drawing geometry.

Retention (the profile's ``retention``)
---------------------------------------
``press``  the pin is pressed into the part that holds it (``holder``, at an end of the stack where one has a
           hole) and runs in the others. It is the shortest standard pin over the stack, so every part runs
           on it over its whole thickness and the holder grips it over its whole thickness: flush at one end,
           the standard length's extra sticks out of the other as a bare stub (out of the top of the stack,
           or of the bottom where only the bottom has no layer beyond it: :func:`press_stub_at_bottom`). The
           layer order keeps the room the stub sweeps clear of other parts, as it does for a clip's end (a
           1.7 mm stub under ``linkage_stephenson``'s crank would hit its frame; under the ground the base
           needs a clearance hole, which the hardware report says).
``clip``   the pin runs in every part and sticks out at both ends far enough for a DIN 6799 retaining
           washer (groove width m + edge margin n); what the standard length has over goes equally to
           both ends, where standard washers (DIN 125-A / DIN 988) fill it under the clip as far as they
           go. Grooves are cut into an ISO 2338 (unhardened) pin.
``cap``    the pin runs in every part; a collar of the process's own stock (:func:`cap_height_mm` long,
           bore the running hole) is bonded onto each end.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.catalogue.clips import RetainingRing, e_clip
from fabricate.catalogue.hardware import Washer, fill_gap, washers_for_shaft
from fabricate.catalogue.pins import PinChoice, dowel_pin
from fabricate.errors import SpecError
from fabricate.process import ProcessSpec

if TYPE_CHECKING:
    from fabricate.parts.model import Part

_EPS = 1e-9
#: Pin standard of each retention: a press-fit pin is the hardened dowel a shop stocks; a clip needs a
#: groove, cut into an unhardened ISO 2338 pin (a hardened ISO 8734 pin cannot be grooved by hand).
PIN_STANDARD = {"press": "ISO 8734", "clip": "ISO 2338", "cap": "ISO 8734"}
#: Washers under a clip may leave this much (mm) of the pin's extra length open.
WASHER_GAP_TOL_MM = 0.05


@dataclass(frozen=True)
class HoleSize:
    """A hole's fit and its two diameters (mm): nominal (the fit's, to measure) and modelled (+ compensation)."""

    fit: str
    nominal_mm: float
    modelled_mm: float

    @property
    def compensation_mm(self) -> float:
        return self.modelled_mm - self.nominal_mm


def hole_size(process: ProcessSpec, diameter_mm: float, fit: str) -> HoleSize:
    """The hole a part has for a pin (or screw) of ``diameter_mm`` with ``fit``.

    Parameters
    ----------
    process : ProcessSpec
        ``running_clearance_mm``, ``press_fit_interference_mm``, ``hole_compensation_mm``.
    diameter_mm : float
        Nominal pin (or screw) diameter.
    fit : {"running", "press", "clearance"}
    """
    if fit in ("running", "clearance"):
        nominal = diameter_mm + 2.0 * process.running_clearance_mm
    elif fit == "press":
        nominal = diameter_mm - process.press_fit_interference_mm
    else:
        raise ValueError(f"unknown fit {fit!r}")
    return HoleSize(fit, nominal, nominal + process.hole_compensation_mm)


def cap_height_mm(process: ProcessSpec, pin_mm: float) -> float:
    """Length of a bonded end cap: the sheet for a cut process, else the pin's diameter (a bond as long as
    the pin is thick), at least the process's smallest feature."""
    if process.technique == "cut":
        return float(process.thickness_mm)
    return max(float(pin_mm), float(process.min_feature_mm))


def choose_holder(bodies: Sequence[str], layers: Mapping[str, int], with_hole: Sequence[str],
                  ground: str = "") -> str:
    """The body a pressed pin is held by: the first of ``bodies`` with a round hole for the pin (a slider's
    guide pin runs in the other body's slot) that sits at an end of the pin's stack; else the first with
    a hole. The ground is preferred at the top end (its bottom face is where it is mounted)."""
    holed = [b for b in bodies if b in with_hole] or list(bodies)
    occupied = [layers[b] for b in bodies]
    lo, hi = min(occupied), max(occupied)
    at_end = [b for b in holed if layers[b] in (lo, hi)]
    return at_end[0] if at_end else holed[0]


@dataclass(frozen=True)
class PinEnd:
    """What is on one end of a pin, beyond the stack face (next to the face first).

    Attributes
    ----------
    washers : tuple of Washer
        Standard washers filling the pin's extra length under the retainer.
    retainer : RetainingRing or None
        The clip at this end (``clip``).
    cap_mm : float
        Length of the bonded cap at this end (``cap``), else 0.
    protrusion_mm : float
        Length of pin beyond the stack face (negative: the pin ends inside the holder, short of its face).
    groove_from_end_mm : float or None
        Distance from the pin's end to the near edge of the clip's groove (what the maker marks).
    """

    washers: tuple[Washer, ...] = ()
    retainer: RetainingRing | None = None
    cap_mm: float = 0.0
    protrusion_mm: float = 0.0
    groove_from_end_mm: float | None = None

    @property
    def washer_mm(self) -> float:
        return sum(w.h_mm for w in self.washers)


@dataclass(frozen=True)
class PinPlan:
    """One pin as it is bought and fitted.

    Attributes
    ----------
    joint : str
    diameter_mm : float
    retention : str
        ``press``, ``clip`` or ``cap``.
    holder : str
        Body whose part the pin is pressed into (``press``), else ''.
    choice : PinChoice
        The standard pin (designation and length).
    stack_z_mm : (float, float)
        Bottom and top of the stack of parts and spacers the pin passes.
    allowance_mm : float
        Length the retention needs beyond the stack (both ends together).
    ends : (PinEnd, PinEnd)
        Bottom and top end.
    engagement_mm : float
        Length of pin inside the holder (``press``), else 0.
    """

    joint: str
    diameter_mm: float
    retention: str
    holder: str
    choice: PinChoice
    stack_z_mm: tuple[float, float]
    allowance_mm: float
    ends: tuple[PinEnd, PinEnd]
    engagement_mm: float = 0.0

    @property
    def length_mm(self) -> float:
        return float(self.choice.length_mm)

    @property
    def stack_mm(self) -> float:
        return self.stack_z_mm[1] - self.stack_z_mm[0]

    @property
    def z_mm(self) -> float:
        """Bottom of the pin."""
        return self.stack_z_mm[0] - self.ends[0].protrusion_mm


def plan_pin(joint: str, process: ProcessSpec, stack_z_mm: tuple[float, float], holder: str = "",
             holder_z_mm: tuple[float, float] | None = None,
             free_ends: tuple[bool, bool] = (False, False)) -> PinPlan:
    """The standard pin for one joint and what goes on its ends.

    Parameters
    ----------
    joint : str
    process : ProcessSpec
        ``pin_diameter_mm``, ``retention`` and the washers' and caps' sizes.
    stack_z_mm : (float, float)
        Bottom and top of the stack the pin passes.
    holder : str
        The body holding a pressed pin (``press`` only).
    holder_z_mm : (float, float), optional
        Bottom and top of the holder's part (``press``).
    free_ends : (bool, bool)
        No layer lies beyond the stack's bottom / top: which end a pressed pin's extra length sticks out of
        (:func:`press_stub_at_bottom`).

    Raises
    ------
    SpecError
        No standard pin of the diameter and retention covers the stack (``process.pin_diameter_mm``).
    """
    d = float(process.pin_diameter_mm)
    scheme = process.retention
    standard = PIN_STANDARD[scheme]
    z0, z1 = float(stack_z_mm[0]), float(stack_z_mm[1])
    stack = z1 - z0
    try:
        if scheme == "press":
            return _plan_press(joint, d, standard, (z0, z1), holder, holder_z_mm, free_ends)
        if scheme == "clip":
            ring = e_clip(d)
            each = ring.protrusion_mm
            choice = dowel_pin(d, stack + 2.0 * each, standard)
            spare = 0.5 * (choice.length_mm - stack - 2.0 * each)
            ends = []
            for _ in range(2):
                washers = _washers(d, spare)
                left = spare - sum(w.h_mm for w in washers)
                ends.append(PinEnd(washers, ring, 0.0, sum(w.h_mm for w in washers) + each + left,
                                   ring.edge_margin_mm + left))
            return PinPlan(joint, d, scheme, "", choice, (z0, z1), 2.0 * each, (ends[0], ends[1]))
        cap = cap_height_mm(process, d)
        choice = dowel_pin(d, stack + 2.0 * cap, standard)
        half = 0.5 * (choice.length_mm - stack)
        end = PinEnd((), None, cap, half)
        return PinPlan(joint, d, scheme, "", choice, (z0, z1), 2.0 * cap, (end, end))
    except SpecError as exc:
        raise SpecError("process.pin_diameter_mm", f"pin {joint}: {exc.message}") from None


def end_reach_mm(process: ProcessSpec, stack_mm: float) -> float:
    """How far (mm) a pin on a stack ``stack_mm`` long, with what its retention puts on its ends (washers and
    a clip, or a cap), reaches beyond each end face: what the layer order keeps clear
    (:func:`~fabricate.parts.layers.order_layers`). A pressed pin's stub sticks out of ONE end only (the
    layer order's ``one_end``). Infinite where no standard pin covers the stack (the layer order counts such a
    stack as a violation: its pin would be a rod cut to length)."""
    try:
        plan = plan_pin("", process, (0.0, float(stack_mm)))
    except SpecError:
        return math.inf
    return max(max(e.protrusion_mm, e.cap_mm) for e in plan.ends)


def end_radius_mm(process: ProcessSpec) -> float:
    """Radius (mm) of what a pin's retention puts on its ends: the largest of the clip and the washers a pin of
    the profile takes, or the cap; the pin itself for a press fit (its bare stub)."""
    d = float(process.pin_diameter_mm)
    if process.retention == "clip":
        try:
            ring = e_clip(d).ring_od_mm
        except SpecError:
            return 0.0
        return 0.5 * max([ring] + [w.d2_mm for w in washers_for_shaft(d)])
    if process.retention == "cap":
        return 0.5 * (hole_size(process, d, "running").modelled_mm + 2.0 * max(process.min_wall_mm, 0.5 * d))
    return 0.5 * d


def _washers(d: float, gap: float) -> tuple[Washer, ...]:
    """The fewest standard washers filling at most ``gap`` (none when none fits)."""
    if gap <= WASHER_GAP_TOL_MM:
        return ()
    try:
        return fill_gap(d, gap, gap - WASHER_GAP_TOL_MM)
    except SpecError:
        return ()


def press_stub_at_bottom(free_ends: tuple[bool, bool]) -> bool:
    """Where a pressed pin's extra length sticks out: out of the bottom of its stack only where no layer lies
    below it and one lies above it; else out of the top. The layer order keeps that room clear by the same rule
    (:func:`~fabricate.parts.layers.order_layers` with ``one_end``)."""
    return bool(free_ends[0]) and not bool(free_ends[1])


def _plan_press(joint: str, d: float, standard: str, stack: tuple[float, float], holder: str,
                holder_z: tuple[float, float] | None, free_ends: tuple[bool, bool]) -> PinPlan:
    z0, z1 = stack
    hz = holder_z if holder_z is not None else (z0, z1)
    # the shortest standard pin over the stack: the holder grips it over its whole thickness and every part
    # runs on its full length; one end is flush, the standard length's extra sticks out of the other as a bare
    # stub, into room the layer order kept clear (press_stub_at_bottom)
    choice = dowel_pin(d, z1 - z0, standard)
    over = choice.length_mm - (z1 - z0)
    stub = PinEnd(protrusion_mm=over)
    ends = (stub, PinEnd()) if press_stub_at_bottom(free_ends) else (PinEnd(), stub)
    return PinPlan(joint, d, "press", holder, choice, stack, 0.0, ends, hz[1] - hz[0])


def washer_designation(w: Washer) -> str:
    """How the BOM names a washer: DIN 125-A by its bore where the washer is one (the shops' name), else its own."""
    return w.alt_designation if w.alt_designation and w.alt_designation.startswith("DIN 125") else w.designation


def fill_layer_gap(d: float, gap: float) -> tuple[Washer, ...]:
    """Standard washers for the axial gap between two adjacent layers (or a skipped layer's length).

    The fewest washers whose total is within :data:`WASHER_GAP_TOL_MM` of ``gap`` (never more); where no
    stack comes that close, the thickest stack that fits (what is left is axial play); none when no
    catalogued washer is that thin (the whole gap is axial play).
    """
    if gap <= _EPS:
        return ()
    tol = WASHER_GAP_TOL_MM
    while tol < gap + WASHER_GAP_TOL_MM:
        try:
            return fill_gap(d, gap, min(tol, gap))
        except SpecError:
            tol += WASHER_GAP_TOL_MM
    return ()


def measure_note(process: ProcessSpec, size: HoleSize, pin_mm: float) -> str:
    """What to measure on the finished part for a hole, in words: the nominal hole and its fit."""
    comp = size.compensation_mm
    made = "cut" if process.technique == "cut" else "printed"
    if size.fit == "press":
        fit = f"press fit on the Ø{pin_mm:g} pin ({process.press_fit_interference_mm:g} mm interference)"
    elif size.fit == "running":
        fit = f"running fit on the Ø{pin_mm:g} pin ({process.running_clearance_mm:g} mm radial clearance)"
    else:
        fit = f"clearance for an M{pin_mm:g} screw"
    cad = f"; CAD Ø{size.modelled_mm:.3g} includes {comp:+.3g} mm {process.name} compensation" if comp else ""
    return f"Ø{size.nominal_mm:.3g} {made}: {fit}{cad}"


def hole_label(fit: str, nominal_mm: float, modelled_mm: float, process_name: str) -> str:
    """A drawing's hole label: the nominal (finished) hole and fit, then the CAD size and compensation apart."""
    comp = modelled_mm - nominal_mm
    text = f"Ø{nominal_mm:.3f}".rstrip("0").rstrip(".") + f" {fit}"
    if abs(comp) > 1e-9:
        text += f" (CAD Ø{modelled_mm:.3f}".rstrip("0").rstrip(".") + f" incl. {comp:+.3g} {process_name} compensation)"
    return text


def _end_records(pin: Any, plan: PinPlan, centre: np.ndarray, top_layer: int) -> list[Any]:
    """Spacer records of what sits on the pin's ends beyond the stack (washers, then the clip), next to the
    stack face first; in the coordinates of the pin's first body, so they move with the pin."""
    from fabricate.parts.bom import Spacer

    out = []
    z0, z1 = plan.stack_z_mm
    for side, end in (("bottom", plan.ends[0]), ("top", plan.ends[1])):
        pieces: list[tuple[str, str, float, float, float]] = [
            ("washer", washer_designation(w), w.d1_mm, w.d2_mm, w.h_mm) for w in end.washers]
        if end.retainer is not None:
            ring = end.retainer
            # the ring stands in its groove: bore the pin (the groove is not modelled), its own thickness
            pieces.append(("clip", ring.designation, plan.diameter_mm, ring.ring_od_mm, ring.groove_w_mm))
        at = 0.0
        for kind, designation, inner, outer, length in pieces:
            z = z1 + at if side == "top" else z0 - at - length
            out.append(Spacer(joint=pin.joint, body=pin.bodies[0], centre=centre, inner_diameter_mm=inner,
                              outer_diameter_mm=outer, length_mm=length, z_mm=z,
                              lower_layer=top_layer if side == "top" else -1, washer=True, kind=kind,
                              designation=designation))
            at += length
    return out


def retain_pins(pins: Sequence[Any], spacers: Sequence[Any], parts: Sequence[Part], process: ProcessSpec,
                ground: str = "") -> tuple[list[Any], list[Any]]:
    """Standard pins and washers for the stacks the parts layer sized (:func:`~fabricate.parts.bom.pins_and_spacers`).

    Each pin becomes the standard pin :func:`plan_pin` picks for its stack (its ``length_mm`` and ``z_mm`` the
    pin's own, ``stack_mm`` the stack's), with its designation, retention, holder (its first body, for a
    press fit) and what stands on its ends. Washers between adjacent layers become standard washers (none
    where no catalogued washer is that thin: the gap stays as axial play); a cut process's bought tubes
    become stacks of standard washers where those fill them. Retention end pieces (washers under a clip,
    the clip) are added as spacer records, so the stacks, the BOM and the interference proof see them.

    Parameters
    ----------
    pins, spacers
        :class:`~fabricate.parts.bom.Pin` and :class:`~fabricate.parts.bom.Spacer` records (``z_mm`` and
        ``length_mm`` of a pin: its stack).
    parts : sequence of Part
        The body parts (holes give the pin's centre and the holder's plate).
    process : ProcessSpec
    ground : str
        The ground body (its bottom face is the mounting face).

    A pin no standard pin fits (a diameter outside the series, a stack longer than its longest length) is
    cut from rod to its stack, with no retention pieces; its ``note`` says why.

    Returns
    -------
    (pins, spacers)
    """
    d = float(process.pin_diameter_mm)
    lowest = min((p.layer for p in parts), default=0)
    highest = max((p.layer for p in parts), default=0)
    out_pins: list[Any] = []
    out_spacers: list[Any] = []
    for sp in spacers:
        if not sp.washer and process.technique == "additive":
            out_spacers.append(sp)  # a printed tube (a part of its own)
            continue
        washers = fill_layer_gap(d, float(sp.length_mm))
        if not washers and not sp.washer:
            out_spacers.append(replace(sp, kind="tube"))  # a bought tube cut to length
            continue
        z = float(sp.z_mm)
        for w in washers:
            out_spacers.append(replace(sp, inner_diameter_mm=w.d1_mm, outer_diameter_mm=w.d2_mm, length_mm=w.h_mm,
                                       z_mm=z, washer=True, kind="washer", designation=washer_designation(w)))
            z += w.h_mm
    for pin in pins:
        stack = (float(pin.z_mm), float(pin.z_mm) + float(pin.length_mm))
        first = next((p for p in parts if p.body == pin.bodies[0] and p.role != "spacer"
                      and any(h.joint == pin.joint for h in p.holes)), None)
        centre = (np.asarray(next(h.centre for h in first.holes if h.joint == pin.joint), dtype=np.float64)
                  if first is not None else np.zeros(2))
        press = process.retention == "press" and first is not None
        note = ""
        try:
            plan = plan_pin(pin.joint, process, stack, pin.bodies[0] if press else "",
                            (first.z_mm, first.z_mm + first.thickness_mm) if first is not None else None,
                            (int(pin.layers[0]) == lowest, int(pin.layers[1]) == highest))
        except SpecError as exc:
            # no standard pin (a diameter outside the series, a stack beyond its lengths): a pin cut from rod to
            # the stack, without retention pieces; the build goes on and says so
            plan = PinPlan(pin.joint, d, process.retention, pin.bodies[0] if press else "",
                           PinChoice("", round(stack[1] - stack[0], 6)), stack, 0.0, (PinEnd(), PinEnd()))
            note = f"{exc.message.split(': ', 1)[-1]}: cut a Ø{d:g} steel rod to {plan.length_mm:.2f} mm"
        ends = tuple(tuple(washer_designation(w) for w in e.washers)
                     + ((e.retainer.designation,) if e.retainer is not None else ()) for e in plan.ends)
        grooves = tuple(float(g) for g in (
            (plan.ends[0].groove_from_end_mm,) if plan.ends[0].groove_from_end_mm is not None else ()) + (
            (plan.length_mm - plan.ends[1].groove_from_end_mm - plan.ends[1].retainer.groove_w_mm,)
            if plan.ends[1].groove_from_end_mm is not None and plan.ends[1].retainer is not None else ()))
        out_pins.append(replace(pin, length_mm=plan.length_mm, z_mm=plan.z_mm, designation=plan.choice.designation,
                                stack_mm=plan.stack_mm, stack_z_mm=stack, retention=plan.retention,
                                holder=plan.holder, allowance_mm=plan.allowance_mm,
                                protrusion_mm=(plan.ends[0].protrusion_mm, plan.ends[1].protrusion_mm),
                                end_items=(ends[0], ends[1]), engagement_mm=plan.engagement_mm,
                                grooves_mm=grooves, caps_mm=(plan.ends[0].cap_mm, plan.ends[1].cap_mm), note=note))
        out_spacers += _end_records(pin, plan, centre, int(pin.layers[1]))
    return out_pins, out_spacers


def cap_parts(pins: Sequence[Any], parts: Sequence[Part], process: ProcessSpec) -> list[Part]:
    """The bonded end caps of ``cap`` retention as parts of the process's own stock (printed, or cut from the
    sheet): a collar round each pin end, bore the running hole, wall the process's minimum, fixed to the pin's
    first body (so it turns with the pin). Their role is ``spacer`` (named ``cap_<pin>_<end>``): like a spacer
    each bears on the face next to it, which the interference proof allows (touching, never overlapping)."""
    from fabricate.parts.model import Hole, Part
    from fabricate.parts.profiles import circle_hull

    out: list[Part] = []
    for pin in pins:
        caps = getattr(pin, "caps_mm", (0.0, 0.0))
        if not any(caps):
            continue
        first = next((p for p in parts if p.body == pin.bodies[0] and any(h.joint == pin.joint for h in p.holes)),
                     None)
        if first is None:
            continue
        centre = np.asarray(next(h.centre for h in first.holes if h.joint == pin.joint), dtype=np.float64)
        size = hole_size(process, float(pin.diameter_mm), "running")
        outer = size.modelled_mm + 2.0 * max(process.min_wall_mm, 0.5 * float(pin.diameter_mm))
        z0, z1 = pin.stack_z_mm
        for side, length in (("bottom", caps[0]), ("top", caps[1])):
            if length <= 0.0:
                continue
            z = z1 if side == "top" else z0 - length
            out.append(Part(name=f"cap_{pin.joint}_{side}".replace("+", "_"), body=pin.bodies[0],
                            outline=circle_hull(centre[None, :], np.array([0.5 * outer])),
                            holes=(Hole(pin.joint, centre, size.modelled_mm, float(pin.diameter_mm), "running",
                                        size.nominal_mm),),
                            thickness_mm=float(length), z_mm=float(z), layer=first.layer, process=process.name,
                            role="spacer"))  # it bears on the stack's end face like a spacer does
    return out
