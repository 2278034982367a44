"""Gear pairs: the record of two cut, checked gears (:class:`GearPair`) and of their mesh check
(:class:`MeshResult`).

:mod:`fabricate.gears.build` makes them (:func:`~fabricate.gears.build.make_gear_pair` for one law,
:func:`~fabricate.gears.build.build_gear_pairs` for every gear coupling of a mechanism) and
:mod:`fabricate.gears.mesh` measures the mesh; both read this record, which imports neither.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.gears.pitch import PitchCurves
from fabricate.gears.spec import GearSpec
from fabricate.gears.teeth import GearTeeth

if TYPE_CHECKING:
    from fabricate.mechanism import Law

#: Shortest acceptable tip land, multiples of the module.
MIN_TIP_LAND = 0.2

@dataclass(frozen=True)
class MeshResult:
    """Mesh check over ``n`` steps. Angles rad, lengths mm, areas mm^2.

    Attributes
    ----------
    x_a : (n,) array
        Driving angles.
    free_plus, free_minus : (n,) array
        Free rotation of gear b towards / away from gear a's driving flanks (negative: interference).
    backlash_mm : (n,) array
        Circumferential backlash at the pitch curve.
    transmission_error : (n,) array
        Driven angle at contact minus the law minus the designed backlash lag, on whichever flank
        deviates more (signed).
    contact_lag : (n,) array
        Driven angle at contact (a driving forward) minus the law, ``= free_plus``.
    interference_area_mm2 : (n,) array
        Overlap area of the two outlines.
    teeth_in_contact : (n,) int array
        Driving flank pairs touching at once (conjugate flanks touch together; the mean over a
        cycle is the measured contact ratio); 0 at steps where no driving flank pair is in mesh.
    """

    x_a: np.ndarray
    free_plus: np.ndarray
    free_minus: np.ndarray
    backlash_mm: np.ndarray
    transmission_error: np.ndarray
    contact_lag: np.ndarray
    interference_area_mm2: np.ndarray
    teeth_in_contact: np.ndarray | None = None

    @property
    def steps(self) -> int:
        return len(self.x_a)

    def summary(self) -> dict[str, Any]:
        """JSON-ready numbers (degrees where the key says so)."""
        ok = np.isfinite(self.backlash_mm)
        return {
            "steps": int(self.steps),
            "interference_area_mm2": float(np.max(self.interference_area_mm2)),
            "backlash_mm": [float(np.min(self.backlash_mm[ok])), float(np.max(self.backlash_mm[ok]))]
            if np.any(ok) else [None, None],
            "transmission_error_deg": float(np.degrees(np.max(np.abs(self.transmission_error[ok]))))
            if np.any(ok) else None,
            "contact_lag_deg": [float(np.degrees(np.min(self.contact_lag[ok]))),
                                float(np.degrees(np.max(self.contact_lag[ok])))] if np.any(ok) else [None, None],
            "steps_without_contact_pair": int(np.count_nonzero(~ok)),
            "teeth_in_contact": [int(self.teeth_in_contact.min()), int(self.teeth_in_contact.max())]
            if self.teeth_in_contact is not None else None,
            "contact_ratio_measured": float(np.mean(self.teeth_in_contact))
            if self.teeth_in_contact is not None else None,
        }


@dataclass(frozen=True, eq=False)
class GearPair:
    """Two cut gears and everything measured about them.

    Outlines and pitch curves are in each gear's frame (origin at its axis, x along the line of
    centres at relative angle 0, see :mod:`fabricate.gears.pitch`), mm, CCW, (n, 2).

    Attributes
    ----------
    name : str
        The coupling's name (the pair is named after it).
    coupling, carrier, body_a, body_b, axis_a, axis_b : str
        Where the pair sits in the mechanism.
    center_distance_mm, module : float
    teeth : (int, int)
        Teeth cut on gear a and gear b (for sectors, the count on the sector).
    method : str
        ``"exact"`` or ``"approx"``.
    closed : bool
    working_range : (float, float)
        Range of ``x_a`` (rad).
    law : callable
        ``x_b = law(x_a)``.
    outline_a, outline_b : (n, 2) arrays
    pitch_a, pitch_b : (n, 2) arrays
    bore_a_mm, bore_b_mm, hub_diameter_mm : float
    checks : dict
        Numbers of the boolean-free checks.
    mesh : MeshResult or None
    module_choice : dict or None
        How ``module_mm = "auto"`` chose the module (:func:`fabricate.gears.auto.choose_module`); None when the
        template fixed it (a module, or a closed pair's teeth).
    """

    name: str
    coupling: str
    carrier: str
    body_a: str
    body_b: str
    axis_a: str
    axis_b: str
    center_distance_mm: float
    teeth: tuple[int, int]
    module: float
    method: str
    closed: bool
    working_range: tuple[float, float]
    law: Law
    outline_a: np.ndarray
    outline_b: np.ndarray
    pitch_a: np.ndarray
    pitch_b: np.ndarray
    bore_a_mm: float
    bore_b_mm: float
    hub_diameter_mm: float
    spec: GearSpec
    pitch_model: PitchCurves = field(repr=False)
    cut_a: GearTeeth = field(repr=False)
    cut_b: GearTeeth = field(repr=False)
    rack_origin: float = 0.0
    checks: dict[str, Any] = field(default_factory=dict)
    mesh: MeshResult | None = None
    module_choice: dict[str, Any] | None = None

    @property
    def module_mm(self) -> float:
        return self.module

    def report(self) -> dict[str, Any]:
        """JSON-ready entry of report.json's ``gears`` list (fabricate/report_schema.json: its stable keys
        first, ``gears[]`` in docs/report.md)."""
        c = self.checks
        mesh = self.mesh.summary() if self.mesh is not None else {}
        out: dict[str, Any] = {
            "name": self.name,
            "teeth": [int(self.teeth[0]), int(self.teeth[1])],
            "module_mm": float(self.module),
            "method": self.method,
            "center_distance_mm": float(self.center_distance_mm),
            "transmission_error_deg": mesh.get("transmission_error_deg"),
            "backlash_mm": mesh.get("backlash_mm", [None, None]),
            "interference_area_mm2": mesh.get("interference_area_mm2"),
            "undercut": bool(c["undercut"]),
            "min_pitch_radius_of_curvature_mm": _finite(c["min_pitch_radius_of_curvature_mm"]),
        }
        out.update({
            "closed": self.closed,
            "coupling": self.coupling,
            "bodies": [self.body_a, self.body_b],
            "working_range_deg": [float(np.degrees(v)) for v in self.working_range],
            "pressure_angle_deg": float(self.spec.pressure_angle_deg),
            "backlash_design_mm": float(self.spec.backlash_mm),
            "transmission_ratio": c["transmission_ratio"],
            "pitch_radius_a_mm": c["pitch_radius_a_mm"],
            "pitch_radius_b_mm": c["pitch_radius_b_mm"],
            "convex": bool(c["convex"]),
            "undercut_limit_radius_mm": c["undercut_limit_radius_mm"],
            "contact_ratio": c["contact_ratio"],
            "working_pressure_angle_deg": c["working_pressure_angle_deg"],
            "tip_land_min_mm": c["tip_land_min_mm"],
            "exact_vs_approx_max_deviation_um": c.get("exact_vs_approx_max_deviation_um"),
            "contact_lag_deg": mesh.get("contact_lag_deg"),
            "teeth_in_contact": mesh.get("teeth_in_contact"),
            "contact_ratio_measured": mesh.get("contact_ratio_measured"),
            "mesh_steps": mesh.get("steps"),
            "bore_mm": [float(self.bore_a_mm), float(self.bore_b_mm)],
            "outline_vertices": [int(len(self.outline_a)), int(len(self.outline_b))],
        })
        if self.module_choice is not None:  # only an automatic module: a fixed one's report is unchanged
            out["module_choice"] = self.module_choice
        return out

    def failures(self) -> list[str]:
        """Human-readable failed checks (empty when the pair is fine)."""
        c, out = self.checks, []
        m = self.module
        if self.module_choice is not None and not self.module_choice["found"]:
            out.append(f"module auto: {self.module_choice['unsatisfied']}")
        if c["undercut"]:
            out.append(f"undercut: min pitch radius of curvature {c['min_pitch_radius_of_curvature_mm']:.3g} mm "
                       f"< {c['undercut_limit_radius_mm']:.3g} mm; use module <= "
                       f"{m * c['min_pitch_radius_of_curvature_mm'] / c['undercut_limit_radius_mm']:.3g} mm")
        if c["tip_land_min_mm"] < MIN_TIP_LAND * m:
            out.append(f"pointed teeth: tip land {c['tip_land_min_mm']:.3g} mm < {MIN_TIP_LAND * m:.3g} mm; "
                       "use a smaller addendum or a larger module")
        if c["contact_ratio"]["min"] < 1.0:
            out.append(f"contact ratio {c['contact_ratio']['min']:.3f} < 1: the teeth lose contact; "
                       "use a smaller module or a larger addendum")
        if self.mesh is not None:
            s = self.mesh.summary()
            if s["interference_area_mm2"] > 1e-6:
                out.append(f"interference: {s['interference_area_mm2']:.3g} mm^2 of tooth overlap in mesh")
            lo = s["backlash_mm"][0]
            if lo is None or s["steps_without_contact_pair"]:
                out.append(f"mesh: {s['steps_without_contact_pair']} step(s) without a flank pair in mesh "
                           "(add spare teeth)")
            elif lo <= 0:
                out.append(f"backlash {lo:.3g} mm <= 0: the teeth jam; increase backlash_mm")
        return out


def _finite(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None
