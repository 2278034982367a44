"""Geometric checks of a gear pair that need no booleans: curvature, undercut, contact ratio,
working pressure angle, and the feasibility limits that make a request an error.

Limits used
-----------
- Undercut (a flag): the rack's straight flank reaches ``h_l = h_f - rho_f (1 - sin alpha)`` below the
  pitch line (1.0 m for the standard 1.25 m / 0.38 m rack); a pitch curve whose radius of curvature
  ``rho`` is below ``h_l / sin^2 alpha`` is undercut locally (the classical ``z_min = 2 h_l / (m sin^2
  alpha)`` = 17 applied to the osculating circle).
- Infeasible (an error): an osculating circle holding fewer than ``min_teeth`` teeth
  (``2 rho / m < min_teeth``), or a concave stretch whose radius is within ``2 h_f`` (the tip or root
  curve would fold).
"""

from __future__ import annotations

import numpy as np

from fabricate.errors import SpecError
from fabricate.gears.pitch import PitchCurves
from fabricate.gears.spec import GearSpec


def curvature_summary(pitch: PitchCurves, x: np.ndarray) -> dict[str, float]:
    """Smallest radius of curvature of the convex parts and smallest curvature of each pitch curve."""
    out: dict[str, float] = {}
    for gear in ("a", "b"):
        k = pitch.frames_at_x(x, gear).curvature
        kmax = float(np.max(k))
        out[f"min_radius_of_curvature_{gear}_mm"] = float(1.0 / kmax) if kmax > 0 else float("inf")
        out[f"min_curvature_{gear}_per_mm"] = float(np.min(k))
        concave = k < 0
        out[f"min_concave_radius_{gear}_mm"] = float(1.0 / np.max(-k[concave])) if np.any(concave) \
            else float("inf")
    return out


def undercut_limit_mm(module: float, spec: GearSpec) -> float:
    """Smallest pitch radius of curvature free of undercut, mm."""
    straight = spec.dedendum - spec.root_fillet * (1.0 - np.sin(spec.pressure_angle))
    return float(straight * module / np.sin(spec.pressure_angle) ** 2)


def check_feasible(curv: dict[str, float], module: float, spec: GearSpec, path: str = "gears.module_mm") -> None:
    """Raise :class:`SpecError` naming the quantity and the fix when the module cannot be cut."""
    rho = min(curv["min_radius_of_curvature_a_mm"], curv["min_radius_of_curvature_b_mm"])
    needed = 2.0 * rho / spec.min_teeth
    # a closed pair of exactly min_teeth teeth has module == needed up to the rounding of the sampled
    # curvature (2e-16 relative): it is allowed, as the message's own bound says
    if module > needed * (1.0 + 1e-9):
        raise SpecError(path, f"module {module:g} mm too large: min pitch radius of curvature {rho:.3g} mm "
                              f"holds {2 * rho / module:.1f} teeth (min_teeth = {spec.min_teeth}); "
                              f"needs module <= {needed:.3g} mm (or a gentler ratio law)")
    concave = min(curv["min_concave_radius_a_mm"], curv["min_concave_radius_b_mm"])
    limit = 2.0 * spec.dedendum * module
    if concave < limit:
        raise SpecError(path, f"module {module:g} mm too large: the pitch curve is concave with radius "
                              f"{concave:.3g} mm; needs module <= {concave / (2 * spec.dedendum):.3g} mm")


def local_contact_ratio(pitch: PitchCurves, x: np.ndarray, module: float, spec: GearSpec) -> np.ndarray:
    """Contact ratio of the osculating spur pair at each ``x`` (rack limit where a curve is flat or
    concave): ``(L_a + L_b) / (p cos alpha)`` with ``L = sqrt((rho + h_a)^2 - (rho cos alpha)^2) -
    rho sin alpha``."""
    alpha = spec.pressure_angle
    ha = spec.addendum * module
    total = np.zeros_like(x)
    for gear in ("a", "b"):
        k = pitch.frames_at_x(x, gear).curvature
        rack = ha / np.sin(alpha)
        rho = np.where(k > 1e-9, 1.0 / np.maximum(k, 1e-9), np.inf)
        finite = np.isfinite(rho)
        part = np.full_like(x, rack)
        r = rho[finite]
        part[finite] = np.sqrt((r + ha) ** 2 - (r * np.cos(alpha)) ** 2) - r * np.sin(alpha)
        total += part
    ratio: np.ndarray = total / (np.pi * module * np.cos(alpha))
    return ratio


def pressure_angle_range_deg(pitch: PitchCurves, x: np.ndarray, spec: GearSpec) -> dict[str, list[float]]:
    """Working pressure angle of each flank over ``x`` (deg, [min, max]): the angle between its line
    of action and the perpendicular to the line of centres.

    The rack flank makes ``alpha`` with the pitch normal; the pitch tangent of a non-circular gear is
    tilted by ``mu = atan(dr / (r dtheta))`` from that perpendicular, so the flanks work at about
    ``alpha + mu`` and ``alpha - mu``. The driving flank is the one in contact when gear a drives with
    ``x_a`` increasing (gear b lagging).
    """
    alpha = spec.pressure_angle
    frames = pitch.frames_at_x(x, "a")
    c, s = np.cos(x), np.sin(x)
    # world y-components (along the perpendicular to the line of centres) of tangent and normal
    t_y = s * frames.tangent[:, 0] + c * frames.tangent[:, 1]
    n_y = s * frames.normal[:, 0] + c * frames.normal[:, 1]
    drive = np.degrees(np.arccos(np.clip(np.abs(-np.cos(alpha) * t_y + np.sin(alpha) * n_y), 0.0, 1.0)))
    coast = np.degrees(np.arccos(np.clip(np.abs(np.cos(alpha) * t_y + np.sin(alpha) * n_y), 0.0, 1.0)))
    return {"drive_flank_deg": [float(drive.min()), float(drive.max())],
            "coast_flank_deg": [float(coast.min()), float(coast.max())]}
