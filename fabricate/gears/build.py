"""Making gear pairs: from a ratio law and a centre distance to two cut, checked gears.

:func:`make_gear_pair` does the work for one law; :func:`build_gear_pairs` makes one pair for each
:class:`~fabricate.mechanism.GearCoupling` of a mechanism (the pipeline's entry point).

Sectors (open working range): teeth are placed at multiples of the circular pitch along the rolled
arc length, with tooth 0 of gear a centred on the pitch point of the working range's start; every
tooth that engages within the range is cut plus ``spare_teeth`` more at each end. Closed gears: the
perimeters must hold whole numbers of teeth, ``z_a / z_b`` equal to the law's turns of b per turn of a;
with the centre distance fixed the module follows (``m = perimeter_a / (pi z_a)``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.spatial import cKDTree

from fabricate.bounds import MAX_MESH_STEP_TEETH, MAX_TEETH, MESH_SECONDS_PER_TOOTH_STEP
from fabricate.errors import SpecError
from fabricate.gears.auto import ModuleLimits, choose_module
from fabricate.gears.checks import (
    check_feasible,
    curvature_summary,
    local_contact_ratio,
    pressure_angle_range_deg,
    undercut_limit_mm,
)
from fabricate.gears.law import check_ratio
from fabricate.gears.mesh import mesh_check
from fabricate.gears.pair import GearPair
from fabricate.gears.pitch import PitchCurves
from fabricate.gears.rack import RackProfile, basic_rack
from fabricate.gears.spec import GearSpec
from fabricate.gears.teeth import GearTeeth, cut_gear

if TYPE_CHECKING:
    from fabricate.mechanism import GearCoupling, Law, Mechanism

#: Default module of a sector when the template leaves it open (SLA-sized), mm.
DEFAULT_SECTOR_MODULE_MM = 0.5
#: Default bore when neither the template nor the caller gives one (the SLA pin), mm.
DEFAULT_BORE_MM = 2.0
TWO_PI = 2.0 * np.pi


def _range(values: np.ndarray | float) -> list[float]:
    return [float(np.min(values)), float(np.max(values))]


def _check_teeth(z_a: int, z_b: int, module: float, spec: GearSpec) -> None:
    """Refuse a pair whose tooth count or mesh check would exceed the resource bounds.

    Cutting and checking cost grows with the teeth (outline vertices) and, for the mesh check, with
    ``mesh_steps`` × teeth; see :mod:`fabricate.bounds`. The message names the field to change.
    """
    if max(z_a, z_b) > MAX_TEETH:
        field = "gears.teeth" if spec.teeth is not None else "gears.module_mm"
        raise SpecError(field, f"the pitch curves need {z_a} and {z_b} teeth at module {module:.3g} mm, over the "
                               f"bound of {MAX_TEETH} teeth per gear; use a module of at least "
                               f"{module * max(z_a, z_b) / MAX_TEETH:.3g} mm")
    work = spec.mesh_steps * (z_a + z_b)
    if work > MAX_MESH_STEP_TEETH:
        raise SpecError("gears.mesh_steps",
                        f"{spec.mesh_steps} steps × {z_a + z_b} teeth = {work} tooth-steps, over the bound of "
                        f"{MAX_MESH_STEP_TEETH} (about {MESH_SECONDS_PER_TOOTH_STEP * work:.0f} s estimated); "
                        f"at most {max(720, MAX_MESH_STEP_TEETH // (z_a + z_b))} steps")


def _closed_teeth(law: Law, x0: float, spec: GearSpec, center_distance: float) -> tuple[int, int]:
    """Tooth counts of a closed pair from the template (teeth or module) and the law's closure."""
    turns = -(float(law(x0 + TWO_PI)) - float(law(x0))) / TWO_PI
    if not np.isfinite(turns) or turns <= 0:
        raise SpecError("gears.closed", f"the law turns gear b {turns:.4g} times per turn of gear a; "
                                        "a closed external pair needs a positive number")
    # gear a's pitch curve closes only if the ratio repeats after a's own turn: whole turns of b per turn
    # of a are not enough (its ratio may still differ at the seam)
    grid = np.linspace(x0, x0 + TWO_PI, 721)
    ratio = law(grid, 1)
    if np.max(np.abs(ratio - law(grid + TWO_PI, 1))) > 1e-7 * np.max(np.abs(ratio)):
        raise SpecError("gears.closed", "the law does not close gear a: its ratio does not repeat after a full "
                                        "turn of a; use a law periodic over 360 deg of a (or closed = false)")
    z_b: float  # whole teeth given; a candidate count of b (z_a / turns) below
    if spec.teeth is not None:
        z_a, z_b = spec.teeth
        if abs(z_a / z_b - turns) > 1e-6 * turns:
            raise SpecError("gears.teeth", f"teeth {z_a}:{z_b} give {z_a / z_b:.6g} turns of b per turn of a "
                                           f"but the law gives {turns:.6g}; use teeth "
                                           f"[{z_a}, {z_a / turns:.6g}] or a law that closes")
        return z_a, z_b
    if spec.module_mm is None:
        raise SpecError("gears.teeth", "a closed pair needs teeth = [z_a, z_b] or module_mm")
    pitch = PitchCurves(law, center_distance, (x0, x0 + TWO_PI), x0)
    ideal = float(pitch.s_of_x(np.array([x0 + TWO_PI]))[0]) / (np.pi * spec.module_mm)
    for dz in sorted(range(-60, 61), key=abs):
        z_a = int(round(ideal)) + dz
        if z_a < 3:
            continue
        z_b = z_a / turns
        if abs(z_b - round(z_b)) < 1e-6 * z_b:
            return z_a, int(round(z_b))
    raise SpecError("gears.teeth", f"no whole tooth counts near {ideal:.1f} close the law "
                                   f"({turns:.6g} turns of b per turn of a); give teeth = [z_a, z_b]")


def _deviation_um(main: GearTeeth, other: GearTeeth) -> float:
    """Largest distance (um) from the other method's dense outline to this one's (point to segment)."""
    ring = main.dense
    seg_a, seg_b = ring, np.roll(ring, -1, axis=0)
    tree = cKDTree(ring)
    _, idx = tree.query(other.dense, k=2)
    best = np.full(len(other.dense), np.inf)
    for column in range(idx.shape[1]):
        for start in (idx[:, column], (idx[:, column] - 1) % len(ring)):
            a, b = seg_a[start], seg_b[start]
            d = b - a
            t = np.clip(np.einsum("ij,ij->i", other.dense - a, d) / np.maximum(np.einsum("ij,ij->i", d, d),
                                                                           1e-30), 0.0, 1.0)
            dist = np.hypot(*(a + t[:, None] * d - other.dense).T)
            best = np.minimum(best, dist)
    return float(np.max(best) * 1000.0)


@dataclass(frozen=True)
class _Layout:
    """Where the teeth go: the pitch curves, the module, the tooth centres along the rolled arc length of
    each gear and the range of ``x_a`` the outlines cover (``periods``: the closed gears' turns, else None)."""

    pitch: PitchCurves
    module: float
    centres_a: np.ndarray
    centres_b: np.ndarray
    x_cover: np.ndarray
    periods: tuple[float, float] | None = None

    @property
    def teeth(self) -> tuple[int, int]:
        return len(self.centres_a), len(self.centres_b)


@dataclass(frozen=True)
class _Cut:
    """Both gears cut from one rack, and what they were cut with."""

    rack: RackProfile
    bore: float
    hub: float
    common: dict[str, Any]
    a: GearTeeth
    b: GearTeeth


def make_gear_pair(law: Law, center_distance_mm: float, working_range: tuple[float, float],
                   spec: GearSpec, *, closed: bool, name: str = "pair", chord_tolerance_mm: float = 0.005,
                   coupling: str = "", carrier: str = "", body_a: str = "gear_a", body_b: str = "gear_b",
                   axis_a: str = "", axis_b: str = "", run_mesh_check: bool = True) -> GearPair:
    """Cut and check one gear pair.

    Parameters
    ----------
    law : callable
        ``x_b = law(x_a)`` (rad, relative to the carrier), ``law(x, nu)`` for derivatives, ``law' < 0``.
    center_distance_mm : float
    working_range : (float, float)
        Range of ``x_a`` (rad); a full turn for closed gears.
    spec : GearSpec
    closed : bool
    name : str
    chord_tolerance_mm : float
        Chord error allowed in the outlines.
    run_mesh_check : bool
        Run :func:`~fabricate.gears.mesh.mesh_check` over the working range (``spec.mesh_steps``).

    Raises
    ------
    SpecError
        Infeasible request, naming the quantity and the fix (nothing is built).
    """
    lo, hi = (float(v) for v in working_range)
    a = float(center_distance_mm)
    _check_request(law, lo, hi, a, working_range, spec, name)
    layout = _closed_layout(law, lo, a, spec, name) if closed else _sector_layout(law, lo, hi, a, spec, name)
    z_a, z_b = layout.teeth
    module, pitch, x_cover = layout.module, layout.pitch, layout.x_cover
    _check_teeth(z_a, z_b, module, spec)
    curv = curvature_summary(pitch, x_cover)
    check_feasible(curv, module, spec)
    cut = _cut_teeth(layout, spec, closed, chord_tolerance_mm)
    checks = _pair_checks(law, lo, hi, layout, spec, curv, cut, _method_deviation_um(layout, spec, cut))
    pitch_a, pitch_b = _pitch_outlines(layout, lo, closed)
    pair = GearPair(name=name, coupling=coupling or name, carrier=carrier, body_a=body_a, body_b=body_b,
                    axis_a=axis_a, axis_b=axis_b, center_distance_mm=a, teeth=(int(z_a), int(z_b)),
                    module=float(module), method=spec.method, closed=closed, working_range=(lo, hi), law=law,
                    outline_a=cut.a.outline, outline_b=cut.b.outline, pitch_a=pitch_a, pitch_b=pitch_b,
                    bore_a_mm=float(cut.bore), bore_b_mm=float(cut.bore), hub_diameter_mm=float(cut.hub), spec=spec,
                    pitch_model=pitch, cut_a=cut.a, cut_b=cut.b, rack_origin=0.0, checks=checks)
    if run_mesh_check:
        pair = replace(pair, mesh=mesh_check(pair))
    return pair


def _check_request(law: Law, lo: float, hi: float, a: float, working_range: tuple[float, float],
                   spec: GearSpec, name: str) -> None:
    """Refuse a range, centre distance, law or module no pair can be cut for, naming the field."""
    if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        raise SpecError(f"gears.{name}.working_range", f"expected a finite range lo < hi, got {working_range}")
    if not (np.isfinite(a) and a > 0):
        raise SpecError(f"gears.{name}.center_distance_mm", f"expected a positive distance, got {a}")
    check_ratio(law, np.linspace(lo, hi, 1025), f"gears.{name}.law")
    if spec.module_mm is not None:
        # the module against the curvature of the working range first: the clearest message
        check_feasible(curvature_summary(_Bare(law, a), np.linspace(lo, hi, 721)), spec.module_mm, spec)


def _closed_layout(law: Law, lo: float, a: float, spec: GearSpec, name: str) -> _Layout:
    """Closed gears: whole numbers of teeth on both perimeters, the module following from gear a's."""
    z_a, z_b = _closed_teeth(law, lo, spec, a)
    periods = (TWO_PI, TWO_PI * z_b / z_a)
    span = max(periods)
    ratio_grid = np.linspace(lo, lo + TWO_PI, 721)
    i0, i1 = -law(ratio_grid, 1), -law(ratio_grid + periods[1], 1)
    if np.max(np.abs(i0 - i1)) > 1e-7 * np.max(np.abs(i0)):
        raise SpecError(f"gears.{name}.law", f"the law does not close gear b: its ratio does not repeat "
                                             f"after gear b's turn ({np.degrees(periods[1]):.2f} deg of a); "
                                             "use a law periodic over that angle")
    pitch = PitchCurves(law, a, (lo, lo + span), lo, periods)
    module = pitch.perimeter_a / (np.pi * z_a)
    if min(z_a, z_b) < spec.min_teeth:
        largest = pitch.perimeter_a / (np.pi * spec.min_teeth * max(1.0, z_a / min(z_a, z_b)))
        raise SpecError("gears.teeth", f"{min(z_a, z_b)} teeth is below min_teeth = {spec.min_teeth}: "
                                       f"use at least {spec.min_teeth} teeth (module <= {largest:.3g} mm)")
    p = np.pi * module
    centres_a = np.arange(z_a) * p
    centres_b = np.arange(z_b) * p + 0.5 * p
    x_cover = np.linspace(lo, lo + span, 2049)
    return _Layout(pitch, module, centres_a, centres_b, x_cover, periods)


def _sector_layout(law: Law, lo: float, hi: float, a: float, spec: GearSpec, name: str) -> _Layout:
    """Sectors: every tooth that engages within the working range plus ``spare_teeth`` at each end, on pitch
    curves extended beyond the range far enough to hold them."""
    if spec.teeth is not None:
        raise SpecError("gears.teeth", "tooth counts apply to closed pairs; a sector's teeth follow from "
                                       "its working range and module (leave teeth out or set closed = true)")
    module = spec.module_or(DEFAULT_SECTOR_MODULE_MM)
    p = np.pi * module
    margin = (1.25 + spec.spare_teeth + 2.5) * p + 5 * module
    r_min = float(np.min(_Bare(law, a).radii(np.linspace(lo, hi, 257), "a")[0]))
    grow = 1.3 * margin / max(r_min, 1e-6)
    for _ in range(8):
        try:
            pitch = PitchCurves(law, a, (lo - grow, hi + grow), lo)
        except SpecError as exc:
            raise SpecError(f"gears.{name}.law", f"{exc.message} (the law is extended "
                            f"{np.degrees(grow):.1f} deg beyond the working range for the spare teeth; "
                            "widen the law's range or use fewer spare_teeth)") from exc
        s_lo, s_hi = 0.0, float(pitch.s_of_x(np.array([hi]))[0])
        if pitch.s_nodes[0] < s_lo - margin and pitch.s_nodes[-1] > s_hi + margin:
            break
        grow *= 1.5
    reach = (1.25 + spec.spare_teeth) * p
    _check_teeth(int((s_hi - s_lo + 2 * reach) / p), int((s_hi - s_lo + 2 * reach) / p), module, spec)
    k_a = np.arange(np.ceil((s_lo - reach) / p), np.floor((s_hi + reach) / p) + 1)
    k_b = np.arange(np.ceil((s_lo - reach) / p - 0.5), np.floor((s_hi + reach) / p - 0.5) + 1)
    centres_a, centres_b = k_a * p, (k_b + 0.5) * p
    s_ends = np.array([min(centres_a[0], centres_b[0]) - p, max(centres_a[-1], centres_b[-1]) + p])
    x_ends = pitch.x_of_s(s_ends)
    x_cover = np.linspace(x_ends[0], x_ends[1], 2049)
    sweep_b = abs(float(law(x_ends[1]) - law(x_ends[0])))
    if x_ends[1] - x_ends[0] >= TWO_PI or sweep_b >= TWO_PI:
        raise SpecError(f"gears.{name}.closed", "the sector with its spare teeth spans a full turn; "
                                                "use closed = true")
    return _Layout(pitch, module, centres_a, centres_b, x_cover)


def _cut_teeth(layout: _Layout, spec: GearSpec, closed: bool, chord_tolerance_mm: float) -> _Cut:
    """Both gears cut by one rack with the backlash split between them, and their bores checked."""
    module, pitch = layout.module, layout.pitch
    p = np.pi * module
    alpha = spec.pressure_angle
    delta = spec.backlash_mm * np.cos(alpha) / 4.0
    if spec.backlash_mm > 0.25 * p:
        raise SpecError("gears.backlash_mm", f"backlash {spec.backlash_mm:g} mm is too large for module "
                                             f"{module:.3g} mm; use backlash_mm <= {0.25 * p:.3g}")
    rack = basic_rack(module, alpha, spec.dedendum, spec.root_fillet, spec.addendum)
    bore = spec.bore_mm if spec.bore_mm is not None else DEFAULT_BORE_MM
    hub = spec.hub_diameter_mm if spec.hub_diameter_mm is not None else max(bore + 2.0, bore + 4 * module)
    common = dict(delta=delta, addendum_mm=spec.addendum * module, closed=closed, rack_origin=0.0,
                  hub_radius_mm=0.5 * hub, chord_tolerance_mm=chord_tolerance_mm)
    cut_a = cut_gear(pitch, "a", rack, layout.centres_a, method=spec.method, **common)
    cut_b = cut_gear(pitch, "b", rack, layout.centres_b, method=spec.method, **common)
    for gear, cut in (("a", cut_a), ("b", cut_b)):
        if cut.root_radius_min_mm <= 0.5 * bore:
            raise SpecError("gears.bore_mm", f"bore {bore:g} mm cuts into the root of gear {gear} (root radius "
                                             f"{cut.root_radius_min_mm:.3g} mm); use a smaller bore or module")
    return _Cut(rack, bore, hub, common, cut_a, cut_b)


def _method_deviation_um(layout: _Layout, spec: GearSpec, cut: _Cut) -> float | None:
    """With ``compare_methods``: the largest distance (µm) of the other tooth method's outlines from these."""
    if not spec.compare_methods:
        return None
    pitch, rack, common = layout.pitch, cut.rack, cut.common
    centres_a, centres_b, cut_a, cut_b = layout.centres_a, layout.centres_b, cut.a, cut.b
    other = "approx" if spec.method == "exact" else "exact"
    dev = [_deviation_um(main, cut_gear(pitch, g, rack, c, method=other, decimate=False, **common))
           for g, main, c in (("a", cut_a, centres_a), ("b", cut_b, centres_b))]
    return float(max(dev))


def _pair_checks(law: Law, lo: float, hi: float, layout: _Layout, spec: GearSpec, curv: dict[str, Any],
                 cut: _Cut, deviation: float | None) -> dict[str, Any]:
    """The boolean-free checks over the working range (:attr:`GearPair.checks`)."""
    module, pitch, cut_a, cut_b = layout.module, layout.pitch, cut.a, cut.b
    x_work = np.linspace(lo, hi, 721)
    ratio = -law(x_work, 1)
    limit = undercut_limit_mm(module, spec)
    rho_min = min(curv["min_radius_of_curvature_a_mm"], curv["min_radius_of_curvature_b_mm"])
    eps = local_contact_ratio(pitch, x_work, module, spec)
    return {
        "transmission_ratio": _range(ratio),
        "pitch_radius_a_mm": _range(pitch.radii(x_work, "a")[0]),
        "pitch_radius_b_mm": _range(pitch.radii(x_work, "b")[0]),
        "min_pitch_radius_of_curvature_mm": rho_min,
        "convex": bool(min(curv["min_curvature_a_per_mm"], curv["min_curvature_b_per_mm"]) > 0),
        "undercut_limit_radius_mm": limit,
        "undercut": bool(rho_min < limit),
        "self_intersecting_envelope": bool(cut_a.self_intersecting or cut_b.self_intersecting),
        "contact_ratio": {"min": float(eps.min()), "mean": float(eps.mean())},
        "working_pressure_angle_deg": pressure_angle_range_deg(pitch, x_work, spec),
        "tip_land_min_mm": float(min(cut_a.tip_land_min_mm, cut_b.tip_land_min_mm)),
        "exact_vs_approx_max_deviation_um": deviation,
    }


def _pitch_outlines(layout: _Layout, lo: float, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """Both pitch curves as polylines, counter-clockwise like the outlines (a closed gear's whole turn)."""
    pitch, x_cover, periods = layout.pitch, layout.x_cover, layout.periods
    pitch_a = pitch.curve(x_cover if not closed else np.linspace(lo, lo + TWO_PI, 721)[:-1], "a")
    x_b = x_cover
    if closed:
        assert periods is not None  # a closed layout has the gears' turns
        x_b = np.linspace(lo, lo + periods[1], 721)[:-1]
    pitch_b = pitch.curve(x_b, "b")
    if not closed:
        pitch_a, pitch_b = pitch_a[::-1].copy(), pitch_b  # CCW like the outlines
    return pitch_a, pitch_b


class _Bare(PitchCurves):
    """Radii only (no arc-length table), for sizing the extended domain."""

    def __init__(self, law: Law, center_distance: float) -> None:  # noqa: D107
        self.law = law
        self.a = float(center_distance)


def build_gear_pairs(mechanism: Mechanism, spec: GearSpec, chord_tolerance_mm: float,
                     limits: Callable[[], ModuleLimits] | None = None) -> list[GearPair]:
    """One checked :class:`GearPair` per gear coupling of ``mechanism``.

    The centre distance is the distance between the coupling's axis points in the carrier; a
    coupling whose working range covers a full turn makes closed gears unless ``spec.closed`` says
    otherwise.

    With ``limits`` (called once when needed: the process's and the load's limits,
    :func:`fabricate.gears.auto.module_limits`) a module the
    template leaves open (``module_mm`` absent or ``"auto"``, and no ``teeth`` of a closed pair) is chosen by
    :func:`fabricate.gears.auto.choose_module`: the pair records how (``module_choice``). Without ``limits`` an
    open module is the old default (a sector 0.5 mm; a closed pair needs teeth or a module).
    """
    pairs = []
    known: list[ModuleLimits] = []  # the limits, once asked for
    for g in mechanism.gears:
        carrier = mechanism.body(g.carrier)
        if g.axis_a in carrier.points and g.axis_b in carrier.points:
            d = carrier.point(g.axis_b) - carrier.point(g.axis_a)
        else:
            body = mechanism.body(g.gear_a)
            d = body.point(g.axis_b) - body.point(g.axis_a)
        lo, hi = g.working_range
        closed = spec.closed if spec.closed is not None else bool(hi - lo >= TWO_PI - 1e-9)

        def make(s: GearSpec, mesh: bool, g: GearCoupling = g, d: np.ndarray = d, closed: bool = closed
                 ) -> GearPair:
            return make_gear_pair(g.law, float(np.hypot(*d)), g.working_range, s, closed=closed, name=g.name,
                                  chord_tolerance_mm=chord_tolerance_mm, coupling=g.name, carrier=g.carrier,
                                  body_a=g.gear_a, body_b=g.gear_b, axis_a=g.axis_a, axis_b=g.axis_b,
                                  run_mesh_check=mesh)

        if limits is None or spec.module_mm is not None or (closed and spec.teeth is not None):
            pairs.append(make(spec, True))
            continue
        # the scan cuts each candidate without the method comparison or the mesh check; the chosen module is
        # then cut and checked in full, exactly as a template fixing it would be
        known = known or [limits()]
        convex = _convex(g.law, float(np.hypot(*d)), g.working_range)
        scanned, choice = choose_module(lambda s: make(replace(s, compare_methods=False), False), spec, known[0],
                                        convex=convex)
        assert scanned.spec.module_mm is not None  # every candidate is cut with its module (and angle) fixed
        full = make(replace(scanned.spec, compare_methods=spec.compare_methods), True)
        pairs.append(replace(full, module_choice=choice))
    return pairs


def _convex(law: Law, center_distance: float, working_range: tuple[float, float]) -> bool:
    """Both pitch curves convex, with a margin, over the working range and a quarter turn beyond each end (the
    spare teeth of a sector lie beyond the range; a closed pair's range is its whole turn)."""
    lo, hi = working_range
    x = np.linspace(lo - 0.5 * np.pi, hi + 0.5 * np.pi, 721) if hi - lo < TWO_PI - 1e-9 else \
        np.linspace(lo, lo + TWO_PI, 721)
    try:
        curv = curvature_summary(_Bare(law, center_distance), x)
    except (SpecError, ValueError, FloatingPointError, ZeroDivisionError):
        return False  # a law that cannot be followed that far: no shortcut, every candidate is cut
    return bool(min(curv["min_curvature_a_per_mm"], curv["min_curvature_b_per_mm"]) > 0.0)
