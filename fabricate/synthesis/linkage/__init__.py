"""Kind ``linkage``: a planar linkage declared in the template, taken through the whole pipeline.

Nothing is synthesised: the template names the bodies with their points, the joints, the gear pairs and
the drivers, and this module validates them and builds the :class:`~fabricate.mechanism.Mechanism` the
rest of the pipeline (gears, parts, exports, interference, strength) works on unchanged.

Template tables
---------------
``[linkage]``
    ``ground`` (name of the fixed body), ``input_unit`` (``"deg"``: angle driver, ``"mm"``: slide driver),
    ``input_range = [start, end]`` (in ``input_unit``), optional ``tip_point`` (the point whose path is
    the output: previews, the strength tip load).
``[[linkage.bodies]]``
    ``name``, ``points = { NAME = [x, y], ... }``: **world** coordinates (mm) at the reference pose.
``[[linkage.joints]]``
    ``name``, ``type`` (``"revolute"`` or ``"slider"``), ``bodies = [a, b]``. A revolute joint ``J`` makes
    point ``J`` of both bodies coincide (they must be the same world point at the reference pose, within
    :data:`ASSEMBLY_GAP_MM`). A slider takes ``axis = [ux, uy]`` (world direction at the reference pose,
    fixed in ``a``): point ``J`` of ``b`` moves on the line through point ``J`` of ``a`` and the two bodies
    keep their relative angle.
``[[linkage.gears]]`` (optional)
    ``name``, ``carrier``, ``bodies = [gear_a, gear_b]``, ``axes = [JA, JB]`` (revolute joints joining the
    carrier to gear a and to gear b: their distance is the centre distance), ``law`` and its parameters,
    ``closed`` (default true), ``working_range_deg`` (range of gear a's angle against the carrier; default
    ``[0, 360]`` for a closed pair and the table's span for a table sector). The law gives the driven angle
    ``y`` (deg, counted in gear b's own sense, i.e. opposite to gear a's: an external pair) as a function
    of the driving angle ``x`` (deg), both measured from the reference pose, so ``y(0) = 0``:

    - ``"constant"``: ``ratio`` = driven turn / driving turn;
    - ``"elliptic"``: ``eccentricity`` in [0, 0.95]: two equal ellipses about their foci, 1:1 over a turn,
      the major axes on the line of centres at the reference pose (gear a's nearer vertex towards b);
    - ``"table"``: ``x_deg``, ``y_deg`` samples and ``spline`` (``"pchip"``, ``"cubic"`` or
      ``"periodic"``; a closed pair needs ``"periodic"``: the law then repeats after 360° of x with
      ``y(x + 360) = y(x) + y_end - y_start``);
    - ``"expression"``: ``expression``, a formula in ``x`` (radians) giving ``y`` (radians), e.g.
      ``"x + 0.2*sin(x)"`` (the functions of :data:`fabricate.gears.law.FUNCTIONS`; at most
      :data:`~fabricate.bounds.MAX_EXPRESSION_LENGTH` characters and
      :data:`~fabricate.bounds.MAX_EXPRESSION_DEPTH` levels of nesting, all of a linkage's together at most
      :data:`~fabricate.bounds.MAX_LINKAGE_EXPRESSION_CHARS` characters).
``[[linkage.drivers]]`` (one per degree of freedom)
    ``joint`` (a revolute: the angle of ``bodies[1]`` against ``bodies[0]``; a slider: the displacement of
    its point along the axis), ``law`` (``"linear"``: value = input - reference; degrees become radians
    for an angle; ``"table"``: ``input = [...]``, ``value = [...]`` in deg or mm, ``spline = "pchip" |
    "cubic"``), ``reference`` (the input at the reference pose; default ``input_range[0]``; one value
    for all drivers). Joint values are measured from the reference pose: a table must give 0 at it.
``[[linkage.pads]]`` (optional)
    ``body``, ``point``, ``radius_mm``: a pad disc fused to the body at the point (parts layer).

``exact = true`` (in ``[linkage]``)
    The exact form every build writes as ``mechanism.toml``: bodies with points in their own frames, the
    first pose's ``assembly``, joints and drivers as the mechanism has them, laws by their coefficients,
    and the parts ``hints``; see :mod:`fabricate.synthesis.linkage.exact`.

Reference pose and start
------------------------
Because points are world coordinates at the reference pose, every body's frame is the world frame there:
its pose is ``(0, 0, 0)`` when the input equals ``reference``. When ``reference`` is not the start of
the range the linkage is first moved by continuation from the reference pose to the start (so the start
pose is on the branch the template draws); a lock-up on that way is reported by the sweep (exit 1).

Validation
----------
Every error is a :class:`~fabricate.errors.SpecError` naming the field (``linkage.joints[3].bodies``) and,
for joints, the joint: unknown bodies or points, duplicate names, counts beyond :mod:`fabricate.bounds`
(and, by its preflight estimate, poses × bodies, the solver's work and the gears' teeth × poses),
a linkage that does not assemble at the reference pose, degrees of freedom (Gruebler, gears one
constraint each) that differ from the number of drivers. A lock-up inside the range is found by the
pipeline's sweep: a :class:`~fabricate.errors.LockupError` naming the input value, the driven joint and
the joint nearest a dead point (exit 1).
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fabricate.bounds import (
    MAX_LENGTH_MM,
    MAX_LINKAGE_BODIES,
    MAX_LINKAGE_DRIVERS,
    MAX_LINKAGE_GEARS,
    MAX_LINKAGE_JOINTS,
    MAX_LINKAGE_POINTS,
    MAX_LINKAGE_TABLE,
    blas_threads,
    check_expression,
)
from fabricate.errors import LockupError, SpecError
from fabricate.gears.law import FormulaLaw
from fabricate.mechanism import Mechanism
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.linkage.mechanism import build_mechanism, gear_law, sampled_law
from fabricate.table import Table, check_array

#: Largest distance (mm) between the two points of a revolute (or off a slider's line) at the reference
#: pose: the template's coordinates are the assembled linkage, not a guess.
ASSEMBLY_GAP_MM = 1e-6
#: Largest driven-gear angle (rad) a gear law may give at the reference pose (where both gears are at 0).
LAW_ZERO_TOLERANCE = 1e-9
#: Largest input magnitude: degrees (ten turns) or millimetres.
MAX_INPUT_DEG = 3600.0

GEAR_LAWS = ("constant", "elliptic", "table", "expression")
TABLE_SPLINES = ("pchip", "cubic", "periodic")


@dataclass(frozen=True)
class BodySpec:
    """One ``[[linkage.bodies]]`` entry: points in world mm at the reference pose."""

    name: str
    points: tuple[tuple[str, tuple[float, float]], ...]


@dataclass(frozen=True)
class JointSpec:
    """One ``[[linkage.joints]]`` entry; ``axis`` (unit, world at the reference pose) for sliders only."""

    name: str
    type: str
    bodies: tuple[str, str]
    axis: tuple[float, float] | None = None


@dataclass(frozen=True)
class LinkageGearSpec:
    """One ``[[linkage.gears]]`` entry (angles in degrees as written)."""

    name: str
    carrier: str
    bodies: tuple[str, str]
    axes: tuple[str, str]
    law: str
    closed: bool
    working_range_deg: tuple[float, float]
    ratio: float | None = None
    eccentricity: float | None = None
    x_deg: tuple[float, ...] | None = None
    y_deg: tuple[float, ...] | None = None
    spline: str | None = None
    expression: str | None = None


@dataclass(frozen=True)
class DriverSpec:
    """One ``[[linkage.drivers]]`` entry."""

    joint: str
    law: str
    reference: float
    input: tuple[float, ...] | None = None
    value: tuple[float, ...] | None = None
    spline: str | None = None


@dataclass(frozen=True)
class PadSpec:
    """One ``[[linkage.pads]]`` entry."""

    body: str
    point: str
    radius_mm: float


@dataclass(frozen=True)
class LinkageSpec:
    """Validated ``[linkage]`` table."""

    ground: str
    input_unit: str
    input_range: tuple[float, float]
    tip_point: str | None
    bodies: tuple[BodySpec, ...]
    joints: tuple[JointSpec, ...]
    gears: tuple[LinkageGearSpec, ...]
    drivers: tuple[DriverSpec, ...]
    pads: tuple[PadSpec, ...]

    @property
    def reference(self) -> float:
        """The input value at the reference pose (every driver's)."""
        return self.drivers[0].reference if self.drivers else self.input_range[0]


# -- parsing ---------------------------------------------------------------------------------------

def _name(t: Table, key: str = "name") -> str:
    value = t.string(key)
    if not value or len(value) > 64 or any(ord(c) < 32 for c in value) or value != value.strip():
        raise SpecError(t.field(key), f"expected a name of 1 to 64 characters without spaces at its ends, "
                                      f"got \"{value}\"")
    return value


def _count(tables: list[Table], path: str, bound: int, what: str) -> None:
    if len(tables) > bound:
        raise SpecError(path, f"{len(tables)} {what}, over the bound of {bound}")


def _unique(names: list[str], tables: list[Table], what: str) -> None:
    seen: set[str] = set()
    for name, t in zip(names, tables, strict=True):
        if name in seen:
            raise SpecError(t.field("name"), f"duplicate {what} name \"{name}\"")
        seen.add(name)


def _parse_body(t: Table) -> BodySpec:
    name = _name(t)
    raw = t.raw("points")
    if not isinstance(raw, dict) or not raw:
        raise SpecError(t.field("points"), "expected a table of named points, e.g. { O = [0.0, 0.0] }")
    if len(raw) > MAX_LINKAGE_POINTS:
        raise SpecError(t.field("points"), f"{len(raw)} points, over the bound of {MAX_LINKAGE_POINTS}")
    points = []
    for key, value in raw.items():
        if not key or len(key) > 64:
            raise SpecError(t.field("points"), f"expected point names of 1 to 64 characters, got \"{key}\"")
        xy = check_array(value, f"{t.field('points')}.{key}", shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
        points.append((key, (float(xy[0]), float(xy[1]))))
    t.finish()
    return BodySpec(name, tuple(points))


def _parse_joint(t: Table, bodies: dict[str, BodySpec]) -> JointSpec:
    name = _name(t)
    kind = t.string("type", choices=("revolute", "slider"))
    pair = t.strings("bodies")
    if len(pair) != 2:
        raise SpecError(t.field("bodies"), f"joint \"{name}\": expected two body names, got {len(pair)}")
    for body in pair:
        if body not in bodies:
            raise SpecError(t.field("bodies"), f"joint \"{name}\": unknown body \"{body}\" "
                                               f"(bodies: {', '.join(bodies)})")
    if pair[0] == pair[1]:
        raise SpecError(t.field("bodies"), f"joint \"{name}\": joins body \"{pair[0]}\" to itself")
    for body in pair:
        if name not in dict(bodies[body].points):
            raise SpecError(t.field("name"), f"joint \"{name}\": body \"{body}\" has no point \"{name}\" "
                                             "(a joint joins the points of its name in both bodies)")
    axis = None
    if kind == "slider":
        arr = t.array("axis", shape=(2,), min=-1e3, max=1e3)
        norm = float(np.hypot(*arr))
        if norm < 1e-9:
            raise SpecError(t.field("axis"), f"joint \"{name}\": the slide axis has no direction")
        axis = (float(arr[0] / norm), float(arr[1] / norm))
    elif t.has("axis"):
        raise SpecError(t.field("axis"), f"joint \"{name}\": axis applies to sliders only")
    t.finish()
    return JointSpec(name, kind, (pair[0], pair[1]), axis)


def _parse_gear(t: Table, bodies: dict[str, BodySpec], joints: dict[str, JointSpec]) -> LinkageGearSpec:
    name = _name(t)
    carrier = t.string("carrier")
    if carrier not in bodies:
        raise SpecError(t.field("carrier"), f"gear \"{name}\": unknown body \"{carrier}\"")
    pair = t.strings("bodies")
    axes = t.strings("axes")
    for key, values in (("bodies", pair), ("axes", axes)):
        if len(values) != 2:
            raise SpecError(t.field(key), f"gear \"{name}\": expected two names, got {len(values)}")
    for k in range(2):
        if pair[k] not in bodies:
            raise SpecError(t.field("bodies"), f"gear \"{name}\": unknown body \"{pair[k]}\"")
        if pair[k] == carrier:
            raise SpecError(t.field("bodies"), f"gear \"{name}\": a gear cannot be its own carrier \"{carrier}\"")
        joint = joints.get(axes[k])
        if joint is None or joint.type != "revolute":
            raise SpecError(t.field("axes"), f"gear \"{name}\": \"{axes[k]}\" is not a revolute joint")
        if set(joint.bodies) != {carrier, pair[k]}:
            raise SpecError(t.field("axes"), f"gear \"{name}\": joint \"{axes[k]}\" joins {list(joint.bodies)}, "
                                             f"not the carrier \"{carrier}\" and gear \"{pair[k]}\"")
    if pair[0] == pair[1]:
        raise SpecError(t.field("bodies"), f"gear \"{name}\": both gears are body \"{pair[0]}\"")
    law = t.string("law", choices=GEAR_LAWS)
    closed = t.boolean("closed", True)
    extra: dict[str, Any] = {}
    if law == "constant":
        extra["ratio"] = t.number("ratio", positive=True, min=0.01, max=100.0)
    elif law == "elliptic":
        extra["eccentricity"] = t.number("eccentricity", min=0.0, max=0.95)
    elif law == "expression":
        extra["expression"] = t.string("expression")
        check_expression(extra["expression"], t.field("expression"))  # length and depth before it is compiled
        FormulaLaw(extra["expression"], path=t.field("expression"))  # syntax now, with the path
    else:
        x = t.array("x_deg", shape=(None,), min_rows=3, min=-MAX_INPUT_DEG, max=MAX_INPUT_DEG)
        y = t.array("y_deg", shape=(None,), min_rows=3, min=-MAX_INPUT_DEG, max=MAX_INPUT_DEG)
        if len(x) > MAX_LINKAGE_TABLE:
            raise SpecError(t.field("x_deg"), f"{len(x)} samples, over the bound of {MAX_LINKAGE_TABLE}")
        if len(y) != len(x):
            raise SpecError(t.field("y_deg"), f"gear \"{name}\": {len(y)} values for {len(x)} x_deg samples")
        if np.any(np.diff(x) <= 0):
            raise SpecError(t.field("x_deg"), f"gear \"{name}\": x_deg must increase strictly")
        spline = t.string("spline", "periodic" if closed else "pchip", choices=TABLE_SPLINES)
        if closed and spline != "periodic":
            raise SpecError(t.field("spline"), f"gear \"{name}\": a closed pair needs spline = \"periodic\" "
                                               f"(a {spline} spline does not repeat its slope after a turn)")
        if spline == "periodic" and abs(x[-1] - x[0] - 360.0) > 1e-9:
            raise SpecError(t.field("x_deg"), f"gear \"{name}\": a periodic table spans one turn of gear a "
                                              f"(x_deg from {x[0]:g} to {x[0] + 360.0:g}), got {x[-1] - x[0]:g} deg")
        extra.update(x_deg=tuple(map(float, x)), y_deg=tuple(map(float, y)), spline=spline)
    if closed:
        rng = t.array("working_range_deg", [0.0, 360.0], shape=(2,), min=-MAX_INPUT_DEG, max=MAX_INPUT_DEG)
        if abs(rng[1] - rng[0] - 360.0) > 1e-9:
            raise SpecError(t.field("working_range_deg"), f"gear \"{name}\": a closed pair turns through 360 deg; "
                                                          "leave working_range_deg out or set closed = false")
    else:
        if law == "table" or t.has("working_range_deg"):
            default = [extra["x_deg"][0], extra["x_deg"][-1]] if law == "table" else None
            rng = t.array("working_range_deg", default, shape=(2,), min=-MAX_INPUT_DEG, max=MAX_INPUT_DEG)
        else:
            raise SpecError(t.field("working_range_deg"), f"gear \"{name}\": a sector pair (closed = false) needs "
                                                          "its working range [lo, hi] of gear a, deg")
        if not rng[1] > rng[0]:
            raise SpecError(t.field("working_range_deg"), f"gear \"{name}\": expected [lo, hi] with lo < hi")
        if law == "table" and (rng[0] < extra["x_deg"][0] - 1e-9 or rng[1] > extra["x_deg"][-1] + 1e-9):
            raise SpecError(t.field("working_range_deg"), f"gear \"{name}\": the working range lies outside "
                                                          "the table's x_deg")
    t.finish()
    return LinkageGearSpec(name=name, carrier=carrier, bodies=(pair[0], pair[1]), axes=(axes[0], axes[1]), law=law,
                    closed=closed, working_range_deg=(float(rng[0]), float(rng[1])), **extra)


def _parse_driver(t: Table, joints: dict[str, JointSpec], unit: str, start: float) -> DriverSpec:
    joint = t.string("joint")
    if joint not in joints:
        raise SpecError(t.field("joint"), f"unknown joint \"{joint}\" (joints: {', '.join(joints)})")
    law = t.string("law", "linear", choices=("linear", "table"))
    bound = MAX_INPUT_DEG if unit == "deg" else MAX_LENGTH_MM
    reference = t.number("reference", start, min=-bound, max=bound)
    kind = joints[joint].type
    if law == "linear":
        wanted = "deg" if kind == "revolute" else "mm"
        if unit != wanted:
            raise SpecError(t.field("law"), f"joint \"{joint}\": a linear driver of a {kind} needs input_unit = "
                                            f"\"{wanted}\" (use law = \"table\" to map {unit} to "
                                            f"{'an angle' if kind == 'revolute' else 'a displacement'})")
        t.finish()
        return DriverSpec(joint, law, reference)
    s = t.array("input", shape=(None,), min_rows=2, min=-bound, max=bound)
    vbound = MAX_INPUT_DEG if kind == "revolute" else MAX_LENGTH_MM
    v = t.array("value", shape=(None,), min_rows=2, min=-vbound, max=vbound)
    if len(s) > MAX_LINKAGE_TABLE:
        raise SpecError(t.field("input"), f"{len(s)} samples, over the bound of {MAX_LINKAGE_TABLE}")
    if len(v) != len(s):
        raise SpecError(t.field("value"), f"joint \"{joint}\": {len(v)} values for {len(s)} inputs")
    if np.any(np.diff(s) <= 0):
        raise SpecError(t.field("input"), f"joint \"{joint}\": input must increase strictly")
    spline = t.string("spline", "pchip", choices=("pchip", "cubic"))
    if spline == "cubic" and len(s) < 3:
        raise SpecError(t.field("input"), f"joint \"{joint}\": a cubic spline needs at least 3 samples")
    t.finish()
    return DriverSpec(joint, law, reference, tuple(map(float, s)), tuple(map(float, v)), spline)


def _parse_pad(t: Table, bodies: dict[str, BodySpec]) -> PadSpec:
    body = t.string("body")
    if body not in bodies:
        raise SpecError(t.field("body"), f"unknown body \"{body}\"")
    point = t.string("point")
    if point not in dict(bodies[body].points):
        raise SpecError(t.field("point"), f"body \"{body}\" has no point \"{point}\"")
    radius = t.number("radius_mm", positive=True, max=100.0)
    t.finish()
    return PadSpec(body, point, radius)


@dataclass(frozen=True)
class ExactLinkageSpec:
    """The exact form (``[linkage] exact = true``, what every build writes as ``mechanism.toml``): the
    mechanism as it was, and the parts hints it came with (see :mod:`fabricate.synthesis.linkage.exact`)."""

    mechanism: Any
    hints: dict
    tip_point: str | None = None


def parse_spec(root: Table) -> LinkageSpec | ExactLinkageSpec:
    """Read ``[linkage]`` from the template root (see the module docstring)."""
    t = root.table("linkage")
    if t.has("exact") and t.boolean("exact"):
        from fabricate.synthesis.linkage.exact import parse_exact

        name = str(root.data.get("design", {}).get("name", "linkage"))
        mech, hints, tip = parse_exact(t, name)
        return ExactLinkageSpec(mech, hints, tip)
    unit = t.string("input_unit", choices=("deg", "mm"))
    bound = MAX_INPUT_DEG if unit == "deg" else MAX_LENGTH_MM
    rng = t.array("input_range", shape=(2,), min=-bound, max=bound)
    if not rng[1] != rng[0]:
        raise SpecError(t.field("input_range"), "expected a start and a different end")
    body_tables = t.tables("bodies")
    _count(body_tables, t.field("bodies"), MAX_LINKAGE_BODIES, "bodies")
    if len(body_tables) < 2:
        raise SpecError(t.field("bodies"), "a linkage needs the ground and at least one moving body")
    bodies_list = [_parse_body(b) for b in body_tables]
    _unique([b.name for b in bodies_list], body_tables, "body")
    bodies = {b.name: b for b in bodies_list}
    ground = t.string("ground")
    if ground not in bodies:
        raise SpecError(t.field("ground"), f"unknown body \"{ground}\" (bodies: {', '.join(bodies)})")
    joint_tables = t.tables("joints")
    _count(joint_tables, t.field("joints"), MAX_LINKAGE_JOINTS, "joints")
    joints_list = [_parse_joint(j, bodies) for j in joint_tables]
    _unique([j.name for j in joints_list], joint_tables, "joint")
    joints = {j.name: j for j in joints_list}
    gear_tables = t.tables("gears", [])
    _count(gear_tables, t.field("gears"), MAX_LINKAGE_GEARS, "gear pairs")
    gears = [_parse_gear(g, bodies, joints) for g in gear_tables]
    _unique([g.name for g in gears], gear_tables, "gear")
    driver_tables = t.tables("drivers")
    _count(driver_tables, t.field("drivers"), MAX_LINKAGE_DRIVERS, "drivers")
    if not driver_tables:
        raise SpecError(t.field("drivers"), "a linkage needs at least one driver")
    drivers = [_parse_driver(d, joints, unit, float(rng[0])) for d in driver_tables]
    samples = sum(len(g.x_deg or ()) for g in gears) + sum(len(d.input or ()) for d in drivers)
    if samples > MAX_LINKAGE_TABLE:  # in all: the build's mechanism.toml writes every one of them
        raise SpecError(t.field("drivers" if not any(g.x_deg for g in gears) else "gears"),
                        f"the gear and driver tables have {samples} samples in all, over the bound of "
                        f"{MAX_LINKAGE_TABLE} (each is written into the build's mechanism.toml)")
    seen: set[str] = set()
    for d, dt in zip(drivers, driver_tables, strict=True):
        if d.joint in seen:
            raise SpecError(dt.field("joint"), f"joint \"{d.joint}\" is driven twice")
        seen.add(d.joint)
        if d.reference != drivers[0].reference:
            raise SpecError(dt.field("reference"), f"joint \"{d.joint}\": reference {d.reference:g} differs from "
                                                   f"the first driver's {drivers[0].reference:g}; the reference "
                                                   "pose is at one input value")
    pad_tables = t.tables("pads", [])
    _count(pad_tables, t.field("pads"), MAX_LINKAGE_BODIES, "pads")
    pads = [_parse_pad(p, bodies) for p in pad_tables]
    for p, pt in zip(pads, pad_tables, strict=True):
        if sum(q.body == p.body for q in pads) > 1:
            raise SpecError(pt.field("body"), f"body \"{p.body}\" has more than one pad")
    tip = t.string("tip_point", None)
    if tip is not None and not any(tip in dict(b.points) for b in bodies_list):
        raise SpecError(t.field("tip_point"), f"no body has a point \"{tip}\"")
    t.finish()
    spec = LinkageSpec(ground=ground, input_unit=unit, input_range=(float(rng[0]), float(rng[1])), tip_point=tip,
                       bodies=tuple(bodies_list), joints=tuple(joints_list), gears=tuple(gears),
                       drivers=tuple(drivers), pads=tuple(pads))
    _check_mobility(spec)
    _check_reference_pose(spec)
    return spec


# -- checks of the declared linkage -------------------------------------------------------------

def _check_mobility(spec: LinkageSpec) -> None:
    """Gruebler's count (gears one constraint each) against the number of drivers."""
    dof = 3 * (len(spec.bodies) - 1) - 2 * len(spec.joints) - len(spec.gears)
    n = len(spec.drivers)
    if dof == n:
        return
    driven = ", ".join(f"\"{d.joint}\"" for d in spec.drivers)
    fix = "add a driver or a joint" if dof > n else "remove a driver or a joint"
    raise SpecError("linkage.drivers", f"{dof} degree{'s' if dof != 1 else ''} of freedom but {n} "
                                       f"driver{'s' if n != 1 else ''} (on joint{'s' if n != 1 else ''} {driven}; "
                                       f"{len(spec.bodies)} bodies, {len(spec.joints)} joints, {len(spec.gears)} "
                                       f"gear pairs): {fix}")


def _check_reference_pose(spec: LinkageSpec) -> None:
    """Every joint and gear law holds with all bodies at their reference pose (world frames)."""
    bodies = {b.name: dict(b.points) for b in spec.bodies}
    for k, j in enumerate(spec.joints):
        pa = np.asarray(bodies[j.bodies[0]][j.name])
        pb = np.asarray(bodies[j.bodies[1]][j.name])
        if j.type == "revolute":
            gap = float(np.hypot(*(pb - pa)))
            what = "apart"
        else:  # off the slide line through a's point
            normal = np.array([-j.axis[1], j.axis[0]])
            gap = abs(float(np.dot(pb - pa, normal)))
            what = "off the slide line"
        if gap > ASSEMBLY_GAP_MM:
            raise SpecError(f"linkage.joints[{k}]",
                            f"joint \"{j.name}\" does not assemble at the reference pose: point {j.name} of "
                            f"\"{j.bodies[0]}\" is at {_xy(pa)} and of \"{j.bodies[1]}\" at {_xy(pb)}, "
                            f"{gap:.6g} mm {what} (at most {ASSEMBLY_GAP_MM:g} mm)")
    for k, g in enumerate(spec.gears):
        law, _ = gear_law(g, f"linkage.gears[{k}]")
        y0 = float(law(0.0))
        if not abs(y0) <= LAW_ZERO_TOLERANCE:
            raise SpecError(f"linkage.gears[{k}]", f"gear \"{g.name}\" does not assemble at the reference pose: its "
                                                   f"law gives y = {math.degrees(-y0):.6g} deg at x = 0, where both "
                                                   "gears are at 0 (shift the law so that y(0) = 0)")
    for k, d in enumerate(spec.drivers):
        if d.law == "table":
            if not d.input[0] <= d.reference <= d.input[-1]:
                raise SpecError(f"linkage.drivers[{k}].input", f"joint \"{d.joint}\": the table does not reach the "
                                                               f"reference input {d.reference:g}")
            value = float(sampled_law(d.input, d.value, d.spline)(d.reference))
            if abs(value) > 1e-9:
                raise SpecError(f"linkage.drivers[{k}].value",
                                f"joint \"{d.joint}\": the table gives {value:.6g} at the reference input "
                                f"{d.reference:g}; joint values are measured from the reference pose (0 there)")
            lo, hi = sorted(spec.input_range)
            if d.input[0] > lo + 1e-9 or d.input[-1] < hi - 1e-9:
                raise SpecError(f"linkage.drivers[{k}].input", f"joint \"{d.joint}\": the table covers "
                                                               f"[{d.input[0]:g}, {d.input[-1]:g}], not the input "
                                                               f"range [{lo:g}, {hi:g}]")


def _xy(p: np.ndarray) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _check_gear_ranges(spec: LinkageSpec, mech: Mechanism, motion: Any) -> None:
    """A sector pair's gear a must stay inside its working range over the motion."""
    for k, g in enumerate(spec.gears):
        if g.closed:
            continue
        x = np.degrees(motion.relative_angle(g.bodies[0], g.carrier))
        lo, hi = g.working_range_deg
        if x.min() < lo - 1e-6 or x.max() > hi + 1e-6:
            raise SpecError(f"linkage.gears[{k}].working_range_deg",
                            f"gear \"{g.name}\": the motion turns gear a from {x.min():.3f} to {x.max():.3f} deg, "
                            f"outside its working range [{lo:g}, {hi:g}]")


def synthesise(design: Any) -> SynthesisResult:
    """Build the declared linkage (no synthesis: the template is the design)."""
    spec: LinkageSpec = design.method
    sweep_poses = max(int(getattr(getattr(design, "checks", None), "sweep_poses", 360)), 2)
    if isinstance(spec, ExactLinkageSpec):
        report = {"method": "declared linkage, exact form (a build's mechanism.toml)",
                  "degrees_of_freedom": spec.mechanism.degrees_of_freedom(), "tip_point": spec.tip_point}
        with blas_threads(), contextlib.suppress(LockupError):
            spec.mechanism.sweep(sweep_poses)  # solved here with one BLAS thread; the pipeline's sweep is cached
        return SynthesisResult(mechanism=spec.mechanism, report=report, parts=dict(spec.hints))
    # one BLAS thread: the solver's systems (3 × bodies unknowns) are too small to share, and on busy cores
    # OpenBLAS's threads wait for each other (the worst linkage's 360 poses: 42 s with them, 2 s without)
    with blas_threads():
        mech = build_mechanism(design.name, spec)
        motion = None
        try:  # the pipeline sweeps the same inputs next (cached); a lock-up is its to report (exit 1)
            motion = mech.sweep(sweep_poses)
        except LockupError:
            pass
    if motion is not None:
        _check_gear_ranges(spec, mech, motion)
    laws = {g.name: gear_law(g, f"linkage.gears[{k}]")[1] for k, g in enumerate(spec.gears)}
    report: dict[str, Any] = {
        "method": "declared linkage (no synthesis)",
        "bodies": len(spec.bodies),
        "joints": {j.name: {"type": j.type, "bodies": list(j.bodies)} for j in spec.joints},
        "gears": {g.name: {"carrier": g.carrier, "bodies": list(g.bodies), "axes": list(g.axes), "law": laws[g.name],
                           "closed": g.closed, "working_range_deg": list(g.working_range_deg)} for g in spec.gears},
        "drivers": [{"joint": d.joint, "law": d.law, "reference": d.reference} for d in spec.drivers],
        "degrees_of_freedom": mech.degrees_of_freedom(),
        "input_unit": spec.input_unit,
        "input_range": list(spec.input_range),
        "reference_input": spec.reference,
        "tip_point": spec.tip_point,
    }
    if motion is not None and spec.tip_point is not None:
        tip = motion.point(spec.tip_point)
        report["tip_path_mm"] = {"x": [float(tip[:, 0].min()), float(tip[:, 0].max())],
                                 "y": [float(tip[:, 1].min()), float(tip[:, 1].max())]}

    def figures() -> dict[str, bytes]:
        if not spec.gears:
            return {}
        from fabricate.export.gear_plots import law_png

        out = {}
        for coupling in mech.gears:
            a = float(np.hypot(*(mech.body(coupling.carrier).point(coupling.axis_b)
                                 - mech.body(coupling.carrier).point(coupling.axis_a))))
            out[f"gear_law_{coupling.name}.png"] = law_png(coupling.law, coupling.working_range, a)
        return out

    parts: dict[str, Any] = {"pads": {p.body: {"point": p.point, "radius_mm": p.radius_mm} for p in spec.pads}}
    if spec.tip_point is not None:
        parts["tip_point"] = spec.tip_point
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data={"spec": spec}, parts=parts)
