"""``mechanism.toml``: every build's mechanism as a ``kind = "linkage"`` template that rebuilds it.

The template is the *exact* form of the linkage kind (``[linkage] exact = true``): bodies with their
points in their own frames, the assembly guess of the first pose, revolute and slider joints as the
mechanism has them, and every law written so that it evaluates to the same floats: the identity, a
:class:`~fabricate.mechanism.LinearLaw`, or a piecewise polynomial (scipy's ``PPoly``: ``CubicSpline``,
``PchipInterpolator``, …) by its breakpoints and coefficients, floats written with ``repr``. The build's
generic tables (process, gears, parts, checks, load) and the synthesis' hints for the parts layer (pads,
springs, purchased items, copies) come along, so the same parts come out byte for byte. A law of another
kind (a method's own piecewise class) is written as dense samples under a PCHIP and the file says that
its rebuild is close, not identical.

Edit it by hand (move a point, change a law) and ``fabricate build mechanism.toml`` builds the edit. The
reader holds it to the declared linkage's bounds (bodies, joints, gears, drivers, points per body) and to
its own: ``hints.copies`` at most :data:`~fabricate.bounds.MAX_COPIES` (the hints are
:class:`~fabricate.hints.PartHints`'s fields, read by :func:`read_hints`), a law's points at most
:data:`~fabricate.bounds.MAX_EXACT_LAW_POINTS` and pieces of at most
:data:`~fabricate.bounds.MAX_EXACT_LAW_ORDER` coefficients.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.bounds import (
    MAX_COPIES,
    MAX_EXACT_LAW_ORDER,
    MAX_EXACT_LAW_POINTS,
    MAX_LINKAGE_BODIES,
    MAX_LINKAGE_DRIVERS,
    MAX_LINKAGE_GEARS,
    MAX_LINKAGE_JOINTS,
    MAX_LINKAGE_POINTS,
)
from fabricate.errors import SpecError
from fabricate.hints import PadHint, PartHints, PurchasedItem, SpringHint
from fabricate.mechanism import Body, Driver, GearCoupling, LinearLaw, Mechanism, Revolute, Slider

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec
    from fabricate.table import Table

#: Samples of a law written approximately (a law of a kind this file cannot write exactly).
SAMPLED_LAW_POINTS = 2001
#: Generic tables of the design copied into the template as they were written.
GENERIC_TABLES = ("process", "gears", "parts", "checks", "load", "actuator")


# -- writing -----------------------------------------------------------------------------------------

def law_table(law: Any, domain: tuple[float, float]) -> tuple[dict[str, Any], bool]:
    """A law as a table, and whether it is exact (else dense samples over ``domain``)."""
    from scipy.interpolate import PPoly

    if law is None:
        return {"type": "identity"}, True
    if isinstance(law, LinearLaw):
        return {"type": "linear", "slope": float(law.slope), "offset": float(law.offset)}, True
    if isinstance(law, PPoly):
        extrapolate = law.extrapolate if isinstance(law.extrapolate, str) else bool(law.extrapolate)
        return {"type": "ppoly", "x": np.asarray(law.x, dtype=np.float64).tolist(),
                "c": np.asarray(law.c, dtype=np.float64).tolist(), "extrapolate": extrapolate}, True
    lo, hi = sorted(domain)
    x = np.linspace(lo, hi, SAMPLED_LAW_POINTS)
    return {"type": "samples", "x": x.tolist(), "y": np.asarray(law(x), dtype=np.float64).tolist()}, False


def _plain(value: Any) -> Any:
    """Hints as TOML values: tuples and arrays as lists, numpy scalars as numbers, None left out."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items() if v is not None}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value if v is not None]
    if hasattr(value, "tolist"):
        return value.tolist()
    return value


def exact_linkage(mechanism: Mechanism, hints: PartHints) -> tuple[dict[str, Any], bool]:
    """The ``[linkage]`` table of the exact form, and whether every law in it is exact."""
    exact = True
    lo, hi = (float(v) for v in mechanism.input_range)
    bodies = [{"name": b.name, "points": {p: [float(v) for v in b.point(p)] for p in b.points}}
              for b in mechanism.bodies]
    joints = []
    for j in mechanism.joints:
        entry: dict[str, Any] = {"name": j.name, "type": "revolute" if isinstance(j, Revolute) else "slider",
                                 "bodies": [j.body_a, j.body_b]}
        if isinstance(j, Slider):
            entry["axis"] = [float(v) for v in j.axis]
            entry["angle_rad"] = float(j.angle)
        joints.append(entry)
    gears = []
    for g in mechanism.gears:
        law, ok = law_table(g.law, g.working_range if g.working_range[1] != g.working_range[0]
                            else (-math.pi, math.pi))
        exact &= ok
        gears.append({"name": g.name, "carrier": g.carrier, "bodies": [g.gear_a, g.gear_b],
                      "axes": [g.axis_a, g.axis_b], "working_range_rad": [float(v) for v in g.working_range],
                      "law": law})
    drivers = []
    for d in mechanism.drivers:
        law, ok = law_table(d.law, (lo, hi))
        exact &= ok
        entry = {"kind": d.kind, "body": d.body, "reference": d.reference, "law": law}
        if d.joint:
            entry["joint"] = d.joint
        drivers.append(entry)
    table: dict[str, Any] = {
        "exact": True, "ground": mechanism.ground, "input_unit": mechanism.input_unit, "input_range": [lo, hi],
        "assembly": {name: [float(v) for v in pose] for name, pose in mechanism.assembly.items()},
        "hints": _plain(hints.as_table()),
        "bodies": bodies, "joints": joints, "drivers": drivers,
    }
    if gears:
        table["gears"] = gears
    return table, exact


def mechanism_toml(design: DesignSpec, mechanism: Mechanism, hints: PartHints) -> bytes:
    """``mechanism.toml`` of a build: see the module docstring."""
    from fabricate.templates import parse_toml
    from fabricate.tomlwrite import dumps

    linkage, exact = exact_linkage(mechanism, hints)
    source = parse_toml(design.template_text, str(design.template)) if design.template_text else {}
    tables: dict[str, Any] = {"design": {"name": design.name, "kind": "linkage",
                                         "description": f"the mechanism of {design.name} ({design.kind}), exact"}}
    for key in GENERIC_TABLES:
        if key in source:
            tables[key] = source[key]
    tables["linkage"] = linkage
    note = ("every law is written exactly: this template rebuilds the same mechanism and the same parts"
            if exact else "a law is written as samples under a PCHIP: the rebuild is close, not identical")
    head = (f"# The mechanism of {design.name} (kind {design.kind}), written by fabricate as a linkage template:\n"
            f"# {note}. Edit it and `fabricate build` it like any template.\n\n")
    return (head + dumps(tables)).encode("utf-8")


# -- reading (the exact form of kind "linkage") ---------------------------------------------------------

def _law(table: Any, field: str) -> Any:
    from scipy.interpolate import PchipInterpolator, PPoly

    kind = table.string("type", choices=("identity", "linear", "ppoly", "samples"))
    if kind == "identity":
        table.finish()
        return None
    if kind == "linear":
        law = LinearLaw(table.number("slope", min=-1e6, max=1e6), table.number("offset", 0.0, min=-1e6, max=1e6))
        table.finish()
        return law
    if kind == "ppoly":
        x = _law_points(table, "x")
        c = table.array("c", shape=(None, len(x) - 1), min_rows=1, min=-1e12, max=1e12)
        if len(c) > MAX_EXACT_LAW_ORDER:
            raise SpecError(table.field("c"), f"{len(c)} coefficients a piece, over the bound of {MAX_EXACT_LAW_ORDER}")
        extrapolate = table.raw("extrapolate", True)
        if extrapolate not in (True, False, "periodic"):
            raise SpecError(table.field("extrapolate"), "expected true, false or \"periodic\"")
        table.finish()
        if np.any(np.diff(x) <= 0):
            raise SpecError(table.field("x"), "breakpoints must increase strictly")
        return PPoly(c, x, extrapolate=extrapolate)
    x = _law_points(table, "x")
    y = table.array("y", shape=(len(x),), min=-1e6, max=1e6)
    table.finish()
    if np.any(np.diff(x) <= 0):
        raise SpecError(table.field("x"), "samples must increase strictly")
    return PchipInterpolator(x, y)


def _law_points(table: Any, key: str) -> np.ndarray:
    """A law's breakpoints or sample abscissae, at most :data:`~fabricate.bounds.MAX_EXACT_LAW_POINTS`."""
    raw = table.raw(key, None)
    if isinstance(raw, list) and len(raw) > MAX_EXACT_LAW_POINTS:  # before converting a long list
        raise SpecError(table.field(key), f"{len(raw)} points, over the bound of {MAX_EXACT_LAW_POINTS}")
    return table.array(key, shape=(None,), min_rows=2, min=-1e6, max=1e6)


def read_hints(h: Table) -> PartHints:
    """The parts hints of a ``[linkage.hints]`` table (:class:`~fabricate.hints.PartHints`'s fields, every one
    optional), with the counts that drive the parts' cost checked: ``copies`` at most
    :data:`~fabricate.bounds.MAX_COPIES`, a pad per body and a spring per joint at most."""
    copies = h.raw("copies", None)
    if copies is not None and (isinstance(copies, bool) or not isinstance(copies, int)
                               or not 1 <= copies <= MAX_COPIES):
        raise SpecError(h.field("copies"), f"expected a whole number of copies from 1 to {MAX_COPIES} "
                                           f"(every copy of every part is laid out), got {copies!r}")
    spring_tables = h.tables("springs", [])
    if len(spring_tables) > MAX_LINKAGE_JOINTS:
        raise SpecError(h.field("springs"), f"at most {MAX_LINKAGE_JOINTS} springs (one a joint)")
    springs = tuple(_spring(s) for s in spring_tables)
    purchased = tuple(_purchased(p) for p in h.tables("purchased", []))
    shared = tuple(_purchased(p) for p in h.tables("purchased_shared", []))
    angle = h.number("copy_angle_deg", None, min=-360.0, max=360.0)
    tip = h.string("tip_point", None)
    width = h.number("link_width_mm", None, positive=True, max=500.0)
    pads = None
    if h.has("pads"):
        pad_table = h.table("pads")
        if len(pad_table.data) > MAX_LINKAGE_BODIES:
            raise SpecError(h.field("pads"), f"at most {MAX_LINKAGE_BODIES} pads (one a body)")
        pads = {str(body): _pad(pad_table.table(body)) for body in list(pad_table.data)}
        pad_table.finish()
    h.finish()
    return PartHints(springs=springs, purchased=purchased, purchased_shared=shared, copies=copies,
                     copy_angle_deg=angle, tip_point=tip, link_width_mm=width, pads=pads)


def _spring(s: Table) -> SpringHint:
    spring = SpringHint(s.string("joint"), s.number("rate_Nmm_per_deg", min=0.0, max=1e6),
                        s.number("preload_deg", 0.0, min=-3600.0, max=3600.0),
                        s.number("legs_mm", None, positive=True, max=1e4), s.string("note", ""))
    s.finish()
    return spring


def _purchased(p: Table) -> PurchasedItem:
    item = PurchasedItem(p.string("item"), p.integer("qty", 1, min=1, max=1_000_000), p.string("note", ""))
    p.finish()
    return item


def _pad(p: Table) -> PadHint:
    arc = p.strings("arc", None)
    if arc is not None and len(arc) != 2:
        raise SpecError(p.field("arc"), f"expected the two points the pad's arc runs between, got {len(arc)}")
    pad = PadHint(p.string("point"), p.number("radius_mm", None, positive=True, max=1e4),
                  (arc[0], arc[1]) if arc is not None else None)
    p.finish()
    return pad


def parse_exact(t: Table, name: str) -> tuple[Mechanism, PartHints, str | None]:
    """The mechanism and the parts hints of an exact ``[linkage]`` table (``t`` after ``exact``)."""

    unit = t.string("input_unit", choices=("deg", "mm"))
    rng = t.array("input_range", shape=(2,), min=-1e5, max=1e5)
    ground = t.string("ground")
    tables = t.tables("bodies")
    if not 2 <= len(tables) <= MAX_LINKAGE_BODIES:
        raise SpecError(t.field("bodies"), f"expected 2 to {MAX_LINKAGE_BODIES} bodies, got {len(tables)}")
    bodies = []
    for b in tables:
        points = b.table("points")
        if len(points.data) > MAX_LINKAGE_POINTS:
            raise SpecError(b.field("points"), f"{len(points.data)} points, over the bound of {MAX_LINKAGE_POINTS}")
        pts = {k: tuple(points.array(k, shape=(2,), min=-1e4, max=1e4).tolist()) for k in list(points.data)}
        points.finish()
        bodies.append(Body(b.string("name"), pts))
        b.finish()
    joints: list[Any] = []
    tables = t.tables("joints")
    if len(tables) > MAX_LINKAGE_JOINTS:
        raise SpecError(t.field("joints"), f"at most {MAX_LINKAGE_JOINTS} joints")
    for j in tables:
        kind = j.string("type", choices=("revolute", "slider"))
        pair = j.strings("bodies")
        if len(pair) != 2:
            raise SpecError(j.field("bodies"), "expected two bodies")
        if kind == "revolute":
            joints.append(Revolute(j.string("name"), pair[0], pair[1]))
        else:
            axis = j.array("axis", shape=(2,), min=-1e6, max=1e6)
            if not np.hypot(*axis) > 0:
                raise SpecError(j.field("axis"), "expected a non-zero direction")
            joints.append(Slider(j.string("name"), pair[0], pair[1], tuple(axis.tolist()),
                                 j.number("angle_rad", 0.0, min=-1e3, max=1e3)))
        j.finish()
    gears = []
    tables = t.tables("gears", [])
    if len(tables) > MAX_LINKAGE_GEARS:
        raise SpecError(t.field("gears"), f"at most {MAX_LINKAGE_GEARS} gear pairs")
    for g in tables:
        pair, axes = g.strings("bodies"), g.strings("axes")
        if len(pair) != 2 or len(axes) != 2:
            raise SpecError(g.field("bodies"), "expected two bodies and two axes")
        working = g.array("working_range_rad", shape=(2,), min=-1e3, max=1e3)
        gears.append(GearCoupling(g.string("name"), g.string("carrier"), pair[0], pair[1],
                                  _law(g.table("law"), g.field("law")), axes[0], axes[1],
                                  (float(working[0]), float(working[1]))))
        g.finish()
    drivers = []
    tables = t.tables("drivers")
    if not 1 <= len(tables) <= MAX_LINKAGE_DRIVERS:
        raise SpecError(t.field("drivers"), f"expected 1 to {MAX_LINKAGE_DRIVERS} drivers")
    for d in tables:
        drivers.append(Driver(d.string("kind", choices=("angle", "slide")), d.string("body"), d.string("reference"),
                              d.string("joint", ""), _law(d.table("law"), d.field("law"))))
        d.finish()
    assembly_t = t.table("assembly", {})
    assembly = {k: tuple(assembly_t.array(k, shape=(3,), min=-1e5, max=1e5).tolist()) for k in list(assembly_t.data)}
    assembly_t.finish()
    hints = read_hints(t.table("hints", {}))
    t.finish()
    mech = Mechanism(name=name, bodies=tuple(bodies), ground=ground, joints=tuple(joints), gears=tuple(gears),
                     drivers=tuple(drivers), input_range=(float(rng[0]), float(rng[1])), input_unit=unit,
                     assembly=assembly)
    return mech, hints, hints.tip_point
