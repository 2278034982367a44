"""Template tables of a declared linkage (kind ``linkage``, see the package docstring): ``[linkage]`` -> the
frozen :class:`~.declared.LinkageSpec` (or, for the exact form, an :class:`~.declared.ExactLinkageSpec`), the
checks that it assembles at the reference pose with as many drivers as degrees of freedom, and the estimate
of its cost (:func:`preflight`: poses × bodies, the solver's work, the teeth of its gears)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.bounds import (
    MAX_FRAME_TEETH,
    MAX_LENGTH_MM,
    MAX_LINKAGE_BODIES,
    MAX_LINKAGE_DRIVERS,
    MAX_LINKAGE_EXPRESSION_CHARS,
    MAX_LINKAGE_GEAR_TEETH,
    MAX_LINKAGE_GEARS,
    MAX_LINKAGE_JOINTS,
    MAX_LINKAGE_POINTS,
    MAX_LINKAGE_POSE_BODIES,
    MAX_LINKAGE_POSE_TEETH,
    MAX_LINKAGE_TABLE,
    MAX_SOLVER_S,
    MAX_TEETH,
    SOLVER_DRIVER_S,
    SOLVER_EXPRESSION_CHAR_S,
    SOLVER_GEAR_S,
    SOLVER_JACOBIAN_S,
    SOLVER_JACOBIANS_PER_STEP,
    SOLVER_SLIDER_S,
    check_expression,
)
from fabricate.errors import SpecError
from fabricate.gears.law import FormulaLaw
from fabricate.synthesis.linkage.declared import (
    BodySpec,
    DriverSpec,
    ExactLinkageSpec,
    JointSpec,
    LinkageGearSpec,
    LinkageSpec,
    PadSpec,
)
from fabricate.synthesis.linkage.mechanism import gear_law, sampled_law
from fabricate.table import Table, check_array

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec

#: Largest distance (mm) between the two points of a revolute (or off a slider's line) at the reference
#: pose: the template's coordinates are the assembled linkage, not a guess.
ASSEMBLY_GAP_MM = 1e-6
#: Largest driven-gear angle (rad) a gear law may give at the reference pose (where both gears are at 0).
LAW_ZERO_TOLERANCE = 1e-9
#: Largest input magnitude: degrees (ten turns) or millimetres.
MAX_INPUT_DEG = 3600.0

GEAR_LAWS = ("constant", "elliptic", "table", "expression")
TABLE_SPLINES = ("pchip", "cubic", "periodic")


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


def parse_spec(root: Table) -> LinkageSpec | ExactLinkageSpec:
    """Read ``[linkage]`` from the template root (see the package docstring)."""
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
            assert j.axis is not None  # the parser requires a slider's axis
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
            assert d.input is not None and d.value is not None and d.spline is not None  # the parser read the table
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


# -- the cost estimate ------------------------------------------------------------------------------

def preflight(design: DesignSpec) -> None:
    """Estimate the cost of a validated linkage (declared or exact form) and refuse one over the budget.

    Poses × bodies, the solver's steps × the cost of a step (sliders, gears, drivers, characters of gear
    expressions), and the teeth of its gear pairs, alone and × poses and GIF frames. (The gear mesh check's
    steps × teeth is refused where the tooth counts are known, in :mod:`fabricate.gears.pair`.)

    Raises
    ------
    SpecError
        Naming the field that drives the estimate, the estimate and the largest value that fits.
    """
    _pose_work(design)
    _solver_work(design)
    _gear_work(design)


def _pose_work(design: DesignSpec) -> None:
    """Poses × bodies of a linkage (the interference sweep and the statics visit every pose of every part)."""
    spec = design.method
    bodies = len(spec.mechanism.bodies) if isinstance(spec, ExactLinkageSpec) else len(spec.bodies)
    poses = int(design.checks.sweep_poses)
    if poses * bodies > MAX_LINKAGE_POSE_BODIES:
        raise SpecError("checks.sweep_poses", f"{poses} poses × {bodies} bodies = {poses * bodies}, over the bound of "
                                              f"{MAX_LINKAGE_POSE_BODIES} (the checks go through every pose of every "
                                              f"part); at most {MAX_LINKAGE_POSE_BODIES // bodies} poses with "
                                              f"{bodies} bodies")


def _solver_work(design: DesignSpec) -> None:
    """The sweep's estimated CPU time: continuation steps × Jacobians a step × the cost of one Jacobian."""
    spec = design.method
    if isinstance(spec, ExactLinkageSpec):  # laws by coefficients (cheap), joints as the mechanism has them
        mech = spec.mechanism
        sliders = sum(type(j).__name__ != "Revolute" for j in mech.joints)
        gears, drivers, expressions = len(mech.gears), len(mech.drivers), []
    else:
        sliders = sum(j.type != "revolute" for j in spec.joints)
        gears, drivers = len(spec.gears), len(spec.drivers)
        # an elliptic law is a formula too (at most 60 characters: fabricate.gears.law.elliptic_formula)
        expressions = [(k, len(g.expression) if g.expression is not None else 60) for k, g in enumerate(spec.gears)
                       if g.law in ("expression", "elliptic")]
    chars = sum(n for _, n in expressions)
    if chars > MAX_LINKAGE_EXPRESSION_CHARS:
        raise SpecError(f"linkage.gears[{max(expressions, key=lambda e: e[1])[0]}].expression",
                        f"the gear expressions have {chars} characters in all, over the bound of "
                        f"{MAX_LINKAGE_EXPRESSION_CHARS} (each is evaluated at every step of the motion and "
                        "throughout gear cutting); shorten them")
    jacobian = (SOLVER_JACOBIAN_S + SOLVER_SLIDER_S * sliders + SOLVER_GEAR_S * gears + SOLVER_DRIVER_S * drivers
                + SOLVER_EXPRESSION_CHAR_S * chars)
    step = SOLVER_JACOBIANS_PER_STEP * jacobian
    poses = int(design.checks.sweep_poses)
    seconds = max(poses - 1, 360) * step
    if seconds <= MAX_SOLVER_S:
        return
    what = (f"{sliders} slider{'s' if sliders != 1 else ''}, {gears} gear pair{'s' if gears != 1 else ''}"
            + (f" ({chars} characters of gear expressions)" if chars else "")
            + f", {drivers} driver{'s' if drivers != 1 else ''}")
    most = int(MAX_SOLVER_S / step) + 1
    if most > 361:
        raise SpecError("checks.sweep_poses", f"{poses} poses of a linkage with {what}: about {seconds:.0f} s of "
                                              f"solving estimated, over the budget of {MAX_SOLVER_S:.0f} s; at most "
                                              f"{most} poses")
    field = (f"linkage.gears[{max(expressions, key=lambda e: e[1])[0]}].expression" if chars
             else "linkage.joints")
    raise SpecError(field, f"a linkage with {what}: about {seconds:.0f} s of solving estimated even at 360 steps, "
                           f"over the budget of {MAX_SOLVER_S:.0f} s; "
                           + ("shorten the gear expressions" if chars else "use fewer sliders"))


def _gear_work(design: DesignSpec) -> None:
    """Teeth of a linkage's gear pairs (estimated before any is cut), alone and × poses and GIF frames."""
    spec = design.method
    gear = design.gears
    pairs = []  # (centre distance, fraction of a turn, closed)
    if isinstance(spec, ExactLinkageSpec):
        mech = spec.mechanism
        for g in mech.gears:
            carrier = mech.body(g.carrier)
            a = math.dist(carrier.points[g.axis_a], carrier.points[g.axis_b])
            span = abs(g.working_range[1] - g.working_range[0]) / (2 * math.pi)
            pairs.append((a, span, span >= 1.0 - 1e-9))
    else:
        points = {b.name: dict(b.points) for b in spec.bodies}
        for g in spec.gears:
            a = math.dist(points[g.carrier][g.axes[0]], points[g.carrier][g.axes[1]])
            pairs.append((a, (g.working_range_deg[1] - g.working_range_deg[0]) / 360.0, g.closed))
    if not pairs:
        return
    total = 0
    for a, span, closed in pairs:
        if closed and gear.teeth is not None:
            total += sum(gear.teeth)
        elif closed and gear.module_mm is None:
            continue  # the gear layer asks for teeth or a module (exit 2) before cutting any
        else:  # whole pitch curves of 2a / m teeth (r_a + r_b = a), a sector's share and its spare teeth
            module = gear.module_or(0.5)
            share = 1.0 if closed else min(1.0, span)
            total += min(2 * MAX_TEETH, int(2 * a / module * share) + (0 if closed else 4 * gear.spare_teeth + 6))
    field = "gears.teeth" if gear.teeth is not None else "gears.module_mm"
    if total > MAX_LINKAGE_GEAR_TEETH:
        raise SpecError(field, f"{len(pairs)} gear pair{'s' if len(pairs) != 1 else ''} with about {total} teeth in "
                               f"all, over the bound of {MAX_LINKAGE_GEAR_TEETH}; fewer teeth (a larger module)")
    for field, count, bound, what in (
            ("checks.sweep_poses", design.checks.sweep_poses, MAX_LINKAGE_POSE_TEETH, "poses"),
            ("parts.gif_frames", design.parts.gif_frames, MAX_FRAME_TEETH, "GIF frames")):
        if count * total > bound:
            raise SpecError(field, f"{count} {what} × about {total} teeth of the linkage's gears = {count * total}, "
                                   f"over the bound of {bound} (every pose moves every toothed outline); at most "
                                   f"{max(1, bound // total)} {what} with {total} teeth")
