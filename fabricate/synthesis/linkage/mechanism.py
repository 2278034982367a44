"""The declared linkage's laws and mechanism (kind ``linkage``; the template side is
:mod:`fabricate.synthesis.linkage`).

- Gear laws: the template's driven angle ``y(x)`` (gear b's own sense) becomes the coupling law
  ``x_b = -y(x_a)`` of an external pair; a closed sampled law repeats through :class:`PeriodicTableLaw`.
- Driver laws: input to joint coordinate, 0 at the reference input (rad for an angle, mm for a slide).
- :class:`LinkageMechanism`: a :class:`~fabricate.mechanism.Mechanism` whose lock-ups name the driven
  joints and the joint nearest a dead point, assembled at the start of the range by continuation from the
  reference pose (every body's frame the world's there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

from fabricate.errors import LockupError, SpecError
from fabricate.gears.law import FormulaLaw, check_ratio, elliptic_formula
from fabricate.mechanism import Body, Driver, GearCoupling, Law, LinearLaw, Mechanism, Motion, Revolute, Slider

if TYPE_CHECKING:
    from fabricate.synthesis.linkage.declared import DriverSpec, JointSpec, LinkageGearSpec, LinkageSpec


# -- laws ------------------------------------------------------------------------------------------

def sampled_law(x: tuple[float, ...], y: tuple[float, ...], spline: str) -> Law:
    xa, ya = np.asarray(x), np.asarray(y)
    law: Law = PchipInterpolator(xa, ya) if spline == "pchip" else CubicSpline(xa, ya)
    return law


@dataclass(frozen=True)
class PeriodicTableLaw:
    """A sampled law that closes: ``y(x + P) = y(x) + (y_end - y_start)``, P the table's span.

    The linear part ``k x`` (k = mean slope) is taken out and the rest interpolated by a periodic cubic
    spline, so value, slope and curvature repeat after each period; ``sign`` makes it an external pair's
    coupling law (gear b turns the other way). Angles in radians.
    """

    x: tuple[float, ...]
    y: tuple[float, ...]
    sign: float = -1.0
    _slope: float = field(init=False, repr=False, compare=False)
    _spline: CubicSpline = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        x, y = np.asarray(self.x), np.asarray(self.y)
        slope = (y[-1] - y[0]) / (x[-1] - x[0])
        rest = y - slope * x
        rest[-1] = rest[0]  # exact closure of the periodic part (equal by construction up to rounding)
        object.__setattr__(self, "_slope", float(slope))
        object.__setattr__(self, "_spline", CubicSpline(x, rest, bc_type="periodic"))

    def __call__(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray | float:
        x = np.asarray(x, dtype=np.float64)
        out: np.ndarray = self._spline(x, nu)
        if nu == 0:
            out = out + self._slope * x
        elif nu == 1:
            out = out + self._slope
        return self.sign * out


def gear_law(g: LinkageGearSpec, path: str) -> tuple[Law, str]:
    """The coupling law ``x_b = law(x_a)`` (rad; an external pair: negative slope) and its description."""
    # the parser sets the fields of the law it read (and only those)
    if g.law == "constant":
        assert g.ratio is not None
        return LinearLaw(slope=-float(g.ratio)), f"constant ratio {g.ratio:g}"
    if g.law == "elliptic":
        assert g.eccentricity is not None
        text = elliptic_formula(g.eccentricity)
        return FormulaLaw(text, sign=-1.0, path=f"{path}.eccentricity"), f"elliptic e = {g.eccentricity:g}: {text}"
    if g.law == "expression":
        assert g.expression is not None
        return FormulaLaw(g.expression, sign=-1.0, path=f"{path}.expression"), g.expression
    assert g.x_deg is not None and g.y_deg is not None and g.spline is not None
    x, y = np.radians(g.x_deg), np.radians(g.y_deg)
    if g.spline == "periodic":
        return PeriodicTableLaw(tuple(x), tuple(y)), f"periodic cubic spline through {len(x)} samples"
    return NegatedLaw(sampled_law(tuple(x), tuple(y), g.spline)), f"{g.spline} spline through {len(x)} samples"


@dataclass(frozen=True)
class NegatedLaw:
    """``-law(x)``: a driven angle counted in gear b's own sense as an external pair's coupling law."""

    law: Law

    def __call__(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray | float:
        return -self.law(np.asarray(x, dtype=np.float64), nu)


def _check_gear_law(g: LinkageGearSpec, law: Law, path: str) -> None:
    """Ratio positive and finite over the working range; a closed law repeats its ratio after a turn."""
    lo, hi = np.radians(g.working_range_deg)
    x = np.linspace(lo, hi, 2049)
    check_ratio(law, x, f"{path}.law")
    if g.closed:
        ratio = -np.asarray(law(x, 1), dtype=np.float64)
        after = -np.asarray(law(x + 2 * np.pi, 1), dtype=np.float64)
        if np.max(np.abs(ratio - after)) > 1e-7 * np.max(np.abs(ratio)):
            raise SpecError(f"{path}.law", f"gear \"{g.name}\": a closed pair's law must repeat its ratio after a "
                                           "turn of gear a (y(x + 360) = y(x) + const); set closed = false or use "
                                           "a periodic law")


def _driver_law(d: DriverSpec, joint: JointSpec, at_reference: float) -> Law:
    """Input to the mechanism's joint coordinate (rad for an angle, mm for a slide).

    The template's joint value is 0 at the reference input; ``at_reference`` is the coordinate the
    mechanism measures there (0 for an angle; for a slide the offset along the axis of the slider's point
    from its guide's point, which need only lie on the slide line).
    """
    if d.law == "linear":
        slope = math.pi / 180.0 if joint.type == "revolute" else 1.0
        return LinearLaw(slope=slope, offset=at_reference - slope * d.reference)
    assert d.input is not None and d.value is not None and d.spline is not None  # a sampled law's table
    value = np.radians(d.value) if joint.type == "revolute" else np.asarray(d.value)
    return sampled_law(d.input, tuple(value + at_reference), d.spline)


# -- the mechanism -------------------------------------------------------------------------------

@dataclass(frozen=True)
class LinkageMechanism(Mechanism):
    """A declared linkage's mechanism: lock-ups name the driven joints and the joint at a dead point.

    ``unreachable`` holds the lock-up met on the way from the reference pose to the start of the range
    (then every sweep raises it: the start pose is not on the drawn branch).
    """

    unreachable: LockupError | None = None
    driven: tuple[str, ...] = ()

    def sweep(self, inputs: np.ndarray | int | None = None) -> Motion:
        if self.unreachable is not None:
            raise self.unreachable
        try:
            return super().sweep(inputs)
        except LockupError as exc:
            raise _explain(self, exc) from exc


def _explain(mech: Mechanism, exc: LockupError) -> LockupError:
    """The lock-up with the driven joints and the joint nearest a dead point (two links in line there)."""
    base = str(exc).rsplit(" (at input", 1)[0]
    driven = ", ".join(f"\"{j}\"" for j in getattr(mech, "driven", ()))
    text = f"{base}; driven joint {driven}"
    joint = _dead_point_joint(mech, exc.input_value)
    if joint is not None:
        text += f"; nearest dead point at joint \"{joint[0]}\" ({joint[1]} and {joint[2]} in line)"
    return LockupError(exc.input_value, text)


def _dead_point_joint(mech: Mechanism, s_lock: float) -> tuple[str, str, str] | None:
    """The revolute whose two bodies are most nearly in line just before ``s_lock`` (a toggle)."""
    s0 = mech.input_range[0]
    s_near = s_lock - 1e-3 * (s_lock - s0)
    if s_near == s0 or not np.isfinite(s_near):
        s_near = s0
    try:
        motion = Mechanism.sweep(mech, np.array([s0, s_near]) if s_near != s0 else np.array([s0]))
    except LockupError:
        return None
    i = len(motion.inputs) - 1
    best = None
    for j in mech.joints:
        if not isinstance(j, Revolute):
            continue
        arms = []
        for body in (j.body_a, j.body_b):
            b = mech.body(body)
            here = b.point(j.name)
            others = [b.point(p) - here for p in b.points if np.hypot(*(b.point(p) - here)) > 1e-6]
            if not others:
                break
            arm = max(others, key=lambda v: float(np.hypot(*v)))
            theta = motion.pose(body)[i, 2]
            c, s = math.cos(theta), math.sin(theta)
            arms.append(np.array([c * arm[0] - s * arm[1], s * arm[0] + c * arm[1]]))
        if len(arms) != 2:
            continue
        cross = arms[0][0] * arms[1][1] - arms[0][1] * arms[1][0]
        sine = abs(float(cross)) / float(np.hypot(*arms[0]) * np.hypot(*arms[1]))
        if best is None or sine < best[0]:
            best = (sine, j.name, j.body_a, j.body_b)
    return None if best is None else (best[1], f"\"{best[2]}\"", f"\"{best[3]}\"")


def build_mechanism(name: str, spec: LinkageSpec) -> LinkageMechanism:
    """The declared linkage as a :class:`LinkageMechanism`, assembled at the start of its range."""
    bodies = tuple(Body(b.name, {p: xy for p, xy in b.points}) for b in spec.bodies)
    joints_by_name = {j.name: j for j in spec.joints}
    bodies_spec = {b.name: b for b in spec.bodies}
    joints: list[Revolute | Slider] = []
    for j in spec.joints:
        if j.type == "revolute":
            joints.append(Revolute(j.name, j.bodies[0], j.bodies[1]))
        else:  # both frames are the world's at the reference pose: the relative angle is locked at 0
            assert j.axis is not None  # the parser requires a slider's axis
            joints.append(Slider(j.name, j.bodies[0], j.bodies[1], axis=j.axis, angle=0.0))
    gears = []
    for k, g in enumerate(spec.gears):
        path = f"linkage.gears[{k}]"
        law, _ = gear_law(g, path)
        _check_gear_law(g, law, path)
        lo, hi = (float(v) for v in np.radians(g.working_range_deg))
        gears.append(GearCoupling(g.name, carrier=g.carrier, gear_a=g.bodies[0], gear_b=g.bodies[1], law=law,
                                  axis_a=g.axes[0], axis_b=g.axes[1], working_range=(lo, hi)))
    drivers = []
    for d in spec.drivers:
        j = joints_by_name[d.joint]
        offset = 0.0
        if j.type == "slider":
            assert j.axis is not None
            pa, pb = (np.asarray(dict(b.points)[j.name]) for b in (bodies_spec[j.bodies[0]], bodies_spec[j.bodies[1]]))
            offset = float(np.dot(pb - pa, j.axis))
        law = _driver_law(d, j, offset)
        kind = "angle" if j.type == "revolute" else "slide"
        drivers.append(Driver(kind, body=j.bodies[1], reference=j.bodies[0], joint=j.name if kind == "slide" else "",
                              law=law))
    zero = {b.name: (0.0, 0.0, 0.0) for b in spec.bodies if b.name != spec.ground}
    common: dict[str, Any] = dict(name=name, bodies=bodies, ground=spec.ground, joints=tuple(joints),
                                  gears=tuple(gears), drivers=tuple(drivers), input_unit=spec.input_unit,
                                  driven=tuple(d.joint for d in spec.drivers))
    start, reference = spec.input_range[0], spec.reference
    if reference == start:
        return LinkageMechanism(input_range=spec.input_range, assembly=zero, **common)
    # from the reference pose (all frames at the world's) to the start, by continuation on the input
    way = LinkageMechanism(input_range=(reference, start), assembly=zero, **common)
    try:
        motion = way.sweep(np.array([reference, start]))
    except LockupError as exc:
        unreachable = LockupError(exc.input_value, f"{name}: cannot move from the reference pose (input "
                                                   f"{reference:g}) to the start of the range: "
                                                   f"{str(exc).rsplit(' (at input', 1)[0]}")
        return LinkageMechanism(input_range=spec.input_range, assembly=zero, unreachable=unreachable, **common)
    assembly: dict[str, tuple[float, float, float]] = {}
    for b in zero:
        x, y, theta = (float(v) for v in motion.pose(b)[-1])
        assembly[b] = (x, y, theta)
    return LinkageMechanism(input_range=spec.input_range, assembly=assembly, **common)
