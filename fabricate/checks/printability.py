"""Can the parts be made with the chosen process?

Checks against the process profile (:class:`fabricate.process.ProcessSpec`), by what the process can do:

- *wall around holes*: the web between every hole and the outline or the next hole is at least
  ``min_wall_mm`` (for a cut process the minimum web, at least the sheet thickness);
- *smallest feature*: a morphological opening of the plate by a disc of diameter ``min_feature_mm``
  (erode, then dilate) removes every feature thinner than that disc. A corner of angle θ is only cut
  back by ``r (1/sin(θ/2) - 1)``, at most ``r`` for θ ≥ 60°, so any point of the outline left more than
  ``r`` outside the opened plate marks a feature thinner than the process resolves (or a spike
  sharper than 60°);
- *tooth tip land*: the narrowest tooth tip of every gear pair (from the gears package) is at least
  ``min_feature_mm``;
- *pins*: at least ``min_pin_mm`` in diameter;
- *build volume / sheet*: on a plate layout parts lie flat within the printer's build area less the layout's
  margin (the gap kept at the plate's edge), at some rotation on the plate (the smallest box either way
  round, or across the diagonal: :func:`fabricate.export.layout.fitting_angle`, the turn the plates use) and
  are no taller than the build height; on a sheet layout they fit the sheet less its margin the same way and
  are as thick as it or as another stock the process lists (``stock_thickness_mm``; the layout nests each
  thickness on sheets of its own), spacers aside (tubes, not cut from the sheet).

Webs around holes are exact (circle to circle, hole to the outline's true lines and arcs); the files
are polygonised at the chord tolerance (chords inside the outline's arcs, holes' polygons inside their
circles), so the verdict allows that tolerance as its slack. Thin features are taken on the polygonised
plate.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.parts.model import Part
from fabricate.process import ProcessSpec

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.parts.bom import Pin


@dataclass(frozen=True)
class PartPrintability:
    """Numbers of one part (mm)."""

    name: str
    min_wall_mm: float | None       # None: no hole
    min_wall_hole: str
    thin_feature_mm: float          # largest departure of the outline from its opening (0: none)
    footprint_mm: tuple[float, float]
    thickness_mm: float
    fits: bool

    def report(self) -> dict[str, Any]:
        return {"name": self.name,
                "min_wall_mm": None if self.min_wall_mm is None else round(self.min_wall_mm, 6),
                "min_wall_hole": self.min_wall_hole,
                "thin_feature_mm": round(self.thin_feature_mm, 6),
                "footprint_mm": [round(v, 4) for v in self.footprint_mm],
                "thickness_mm": self.thickness_mm, "fits": self.fits}


@dataclass(frozen=True)
class PrintabilityResult:
    """Per-part numbers, gear tip lands and the failures (human-readable)."""

    process: str
    parts: tuple[PartPrintability, ...]
    tip_lands_mm: dict[str, float]
    failures: tuple[str, ...]

    @property
    def passed(self) -> bool:
        return not self.failures

    def report(self) -> dict[str, Any]:
        return {"process": self.process, "parts": [p.report() for p in self.parts],
                "tip_land_mm": {k: round(v, 6) for k, v in self.tip_lands_mm.items()},
                "passed": self.passed}


def hole_walls(part: Part, chord_tolerance_mm: float) -> list[tuple[str, float]]:
    """Web (mm) around every hole of ``part``, as (joint, web) pairs: the distance from the hole to the
    nearest other boundary (the outline, another hole), negative where they overlap.

    Exact up to rounding: the web to another hole is ``|c_k - c_j| - r_j - r_k`` and the web to the outline
    is measured to its true lines and arcs (:meth:`BulgePath.distance`). Polygons would overstate both —
    the other hole's inscribed polygon and a concave arc's chords lie in the void, up to the chord sagitta
    away — so a web under the limit could pass. ``chord_tolerance_mm`` only polygonises the outline to tell
    whether a hole's centre is inside the plate at all.
    """
    outer = part.polygons(chord_tolerance_mm)[0]
    plate = shapely.Polygon(outer)
    out = []
    for k, hole in enumerate(part.holes):
        centre = np.asarray(hole.centre, dtype=np.float64)
        to_outline = part.outline.distance(centre)
        if not plate.covers(shapely.Point(centre)):
            to_outline = -to_outline  # a hole centred outside the plate: no web at all
        webs = [to_outline - 0.5 * hole.diameter_mm]
        webs += [float(np.hypot(*(centre - np.asarray(other.centre, dtype=np.float64))))
                 - 0.5 * other.diameter_mm - 0.5 * hole.diameter_mm
                 for j, other in enumerate(part.holes) if j != k]
        out.append((hole.joint, min(webs)))
    return out


def thin_feature(part: Part, min_feature_mm: float, chord_tolerance_mm: float) -> float:
    """Largest distance (mm) of an outline vertex from the plate opened by a disc of diameter
    ``min_feature_mm`` beyond the corner allowance ``min_feature_mm / 2``; 0 when nothing is thinner."""
    rings = part.polygons(chord_tolerance_mm)
    plate = shapely.Polygon(rings[0], rings[1:])
    r = 0.5 * min_feature_mm
    opened = plate.buffer(-r, quad_segs=8).buffer(r, quad_segs=8)
    points = np.concatenate(rings)
    if opened.is_empty:
        return float(np.max(np.hypot(*(points - points.mean(axis=0)).T)))
    shapely.prepare(opened)
    pts = shapely.points(points)
    # only vertices farther than r + tolerance can give a non-zero result: find them with the prepared
    # distance-within test (edge index) and measure just those (a polygon distance compares every edge
    # with the point: for a 200-tooth gear's outline that was seconds per part)
    far = ~shapely.dwithin(opened, pts, r + chord_tolerance_mm)
    if not np.any(far):
        return 0.0
    depart = shapely.distance(opened, pts[far])
    excess = float(np.max(depart)) - r
    return excess if excess > chord_tolerance_mm else 0.0


def footprint(part: Part, chord_tolerance_mm: float) -> tuple[float, float]:
    """Sides (long, short) of the smallest rotated rectangle around the plate, mm."""
    outer = part.polygons(chord_tolerance_mm)[0]
    rect = shapely.minimum_rotated_rectangle(shapely.MultiPoint(outer))
    xy = np.asarray(rect.exterior.coords)[:4]
    sides = np.hypot(*(np.roll(xy, -1, axis=0) - xy).T)
    return float(max(sides[0], sides[1])), float(min(sides[0], sides[1]))


def check_printability(parts: Sequence[Part], process: ProcessSpec, gear_pairs: Sequence[GearPair] = (),
                       pins: Sequence[Pin] = (), margin_mm: float = 0.0) -> PrintabilityResult:
    """Judge every part, gear pair and pin against the process profile.

    Parameters
    ----------
    parts : sequence of Part
    process : ProcessSpec
    gear_pairs : sequence of GearPair
        Their ``checks["tip_land_min_mm"]`` is compared with ``min_feature_mm``.
    pins : sequence
        Objects with ``joint`` and ``diameter_mm``.
    margin_mm : float
        Free border the layout keeps at the plate's or sheet's edge (``[parts] plate_spacing_mm`` /
        ``sheet_margin_mm``): a part must fit inside it.
    """
    from fabricate.export.layout import fitting_angle

    tol = float(process.chord_tolerance_mm)
    failures: list[str] = []
    rows = []
    usable = (float(process.build_volume_mm[0]) - 2 * margin_mm, float(process.build_volume_mm[1]) - 2 * margin_mm)
    for part in parts:
        walls = hole_walls(part, tol)
        weakest = min(walls, key=lambda w: w[1]) if walls else None
        if weakest is not None and weakest[1] < process.min_wall_mm - tol:
            failures.append(f"printability: {part.name} has a {weakest[1]:.3f} mm wall at hole "
                            f"{weakest[0]}; the process needs {process.min_wall_mm:.3f} mm")
        thin = thin_feature(part, process.min_feature_mm, tol)
        if thin > 0.0:
            failures.append(f"printability: {part.name} has a feature thinner than "
                            f"{process.min_feature_mm:.3f} mm (reaching {thin:.3f} mm beyond the opened outline)")
        long_side, short_side = footprint(part, tol)
        in_area = min(usable) > 0 and fitting_angle(part.polygons(tol)[0], *usable) is not None
        height = float(process.build_volume_mm[2])
        sheet = process.layout == "sheet"
        if sheet:
            # a part as thick as a stock the process lists is cut from that stock (the layout nests each
            # thickness on its own sheets: fabricate.export.dxf.sized_sheets)
            stock = [height, *(float(s) for s in getattr(process, "stock_thickness_mm", ()) or ())]
            thick_ok = part.role == "spacer" or any(abs(part.thickness_mm - s) <= 1e-6 for s in stock)
            if not thick_ok:
                listed = sorted(set(stock) - {height})
                also = f" (stock: {', '.join(f'{s:g}' for s in listed)} mm)" if listed else ""
                failures.append(f"printability: {part.name} is {part.thickness_mm:g} mm thick, the sheet "
                                f"{height:g} mm{also}")
        else:
            thick_ok = part.thickness_mm <= height + 1e-9
        if not in_area or (not sheet and not thick_ok):
            where = "sheet" if sheet else (f"{process.printer} build volume" if process.printer else "build volume")
            inside = ""
            if not in_area and margin_mm > 0:
                inside = (f" inside its {margin_mm:g} mm margin ({usable[0]:g} × {usable[1]:g} mm usable, at any "
                          f"rotation on the {'sheet' if sheet else 'plate'})")
            failures.append(f"printability: {part.name} ({long_side:.1f} × {short_side:.1f} × "
                            f"{part.thickness_mm:g} mm) does not fit the {where} "
                            f"{' × '.join(f'{v:g}' for v in process.build_volume_mm)} mm{inside}")
        fits = in_area and thick_ok
        rows.append(PartPrintability(part.name, None if weakest is None else float(weakest[1]),
                                     "" if weakest is None else weakest[0], thin, (long_side, short_side),
                                     float(part.thickness_mm), bool(fits)))
    tips = {}
    for pair in gear_pairs:
        land = float(pair.checks.get("tip_land_min_mm", np.inf))
        tips[pair.name] = land
        if land < process.min_feature_mm - 1e-9:
            failures.append(f"printability: gear {pair.name} has a {land:.3f} mm tooth tip land; the process "
                            f"resolves {process.min_feature_mm:.3f} mm (use a larger module or a smaller addendum)")
    for pin in pins:
        if float(pin.diameter_mm) < process.min_pin_mm - 1e-9:
            failures.append(f"printability: pin {pin.joint} is {pin.diameter_mm:g} mm, the process needs "
                            f"{process.min_pin_mm:g} mm")
    return PrintabilityResult(process.name, tuple(rows), tips, tuple(failures))
