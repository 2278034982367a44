"""Pin retention and hole fits: how each pin is kept in, the hole every part has on it, and the standard
pin, washers and retainers that make up its stack.

Pure functions of the process profile (:class:`~fabricate.process.ProcessSpec`) and the catalogue
(:mod:`fabricate.catalogue.hardware`); nothing here places parts or draws.

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
``press``  the pin is pressed into the part that holds it (``holder``) and runs in the others. It needs no
           length beyond the stack; the shortest standard pin at least as long as the stack is taken and
           what it has over sticks out of the holder's outer face (the holder grips it there), or, where
           the holder is the ground's bottom face (the mounting face) or in the middle of the stack, out of
           the top. Only when no standard length reaches the stack is the longest one pressed in short of
           the holder's outer face, engaging the holder by at least :func:`min_press_engagement`.
``clip``   the pin runs in every part and sticks out at both ends far enough for a DIN 6799 retaining
           washer (groove width m + edge margin n); what the standard length has over goes equally to
           both ends, where standard washers (DIN 125-A / DIN 988) fill it under the clip as far as they
           go. Grooves are cut into an ISO 2338 (unhardened) pin.
``cap``    the pin runs in every part; a collar of the process's own stock (:func:`cap_height_mm` long,
           bore the running hole) is bonded onto each end.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from fabricate.catalogue.hardware import (
    PinChoice,
    RetainingRing,
    Washer,
    dowel_pin,
    e_clip,
    fill_gap,
    pin_lengths,
)
from fabricate.errors import SpecError
from fabricate.process import ProcessSpec

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


def min_press_engagement(pin_mm: float, holder_thickness_mm: float) -> float:
    """Least length (mm) of a pressed pin inside its holder: its own diameter, or the whole holder when thinner."""
    return min(pin_mm, holder_thickness_mm)


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
             holder_z_mm: tuple[float, float] | None = None, holder_is_ground: bool = False) -> PinPlan:
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
    holder_is_ground : bool
        The holder is the ground, whose bottom face is its mounting face: nothing sticks out of it.

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
            return _plan_press(joint, d, standard, (z0, z1), holder, holder_z_mm, holder_is_ground)
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


def _washers(d: float, gap: float) -> tuple[Washer, ...]:
    """The fewest standard washers filling at most ``gap`` (none when none fits)."""
    if gap <= WASHER_GAP_TOL_MM:
        return ()
    try:
        return fill_gap(d, gap, gap - WASHER_GAP_TOL_MM)
    except SpecError:
        return ()


def _plan_press(joint: str, d: float, standard: str, stack: tuple[float, float], holder: str,
                holder_z: tuple[float, float] | None, holder_is_ground: bool) -> PinPlan:
    z0, z1 = stack
    length = z1 - z0
    hz = holder_z if holder_z is not None else (z0, z1)
    thickness = hz[1] - hz[0]
    at_bottom = abs(hz[0] - z0) < 1e-6
    at_top = abs(hz[1] - z1) < 1e-6
    # the end the pin sticks out of (or is pressed in short of): the holder's outer face, unless that
    # is the ground's mounting face or the holder is in the middle of the stack
    bottom = at_bottom and not (holder_is_ground or at_top)
    lengths = pin_lengths(d, standard)
    if lengths[-1] >= length - _EPS:
        choice = dowel_pin(d, length, standard)
        over = choice.length_mm - length
        ends = (PinEnd(protrusion_mm=over), PinEnd()) if bottom else (PinEnd(), PinEnd(protrusion_mm=over))
        return PinPlan(joint, d, "press", holder, choice, stack, 0.0, ends, thickness)
    # no standard length reaches: the longest, pressed in short of the holder's outer face
    need = min_press_engagement(d, thickness)
    short = length - lengths[-1]
    if not (at_bottom or at_top) or thickness - short < need - _EPS:
        raise SpecError("length", f"the stack is {length:g} mm; the longest {standard} Ø{d:g} pin is "
                        f"{lengths[-1]:g} mm, which leaves {max(0.0, thickness - short):.3g} mm in the holder "
                        f"{holder or '?'} (at least {need:g} mm needed)")
    choice = PinChoice(f"{standard} {d:g} × {lengths[-1]:g}", lengths[-1])
    recess = PinEnd(protrusion_mm=-short)
    ends = (recess, PinEnd()) if at_bottom else (PinEnd(), recess)
    return PinPlan(joint, d, "press", holder, choice, stack, 0.0, ends, thickness - short)


def washer_designation(w: Washer) -> str:
    """How the BOM names a washer: DIN 125-A by its bore where the washer is one (the shops' name), else its own."""
    return w.alt_designation if w.alt_designation and w.alt_designation.startswith("DIN 125") else w.designation


def fill_layer_gap(d: float, gap: float) -> tuple[Washer, ...]:
    """Standard washers for the axial gap between two adjacent layers (or a skipped layer's length).

    The fewest washers whose total is within :data:`WASHER_GAP_TOL_MM` of ``gap`` (never more); none when
    no catalogued washer is that thin (the gap is left as axial play).
    """
    if gap <= _EPS:
        return ()
    try:
        return fill_gap(d, gap, WASHER_GAP_TOL_MM)
    except SpecError:
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
