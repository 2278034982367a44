"""A laser shop's rules as checks: what a shop's preflight rejects, found before the files are sent.

Shops (SendCutSend, Ponoko...) reject a cut file whose paths are open, whose lines overlap or repeat (two
passes of the beam), and parts whose holes, bridges or hole-to-edge distances are below the stock's minimum.
The numbers are the process profile's ``[shop]`` (``min_hole_mm``, ``min_web_mm``, ``min_hole_edge_mm``),
each defaulting to half the stock's thickness (SendCutSend's rule of thumb; see templates/process_laser.toml);
a part cut from another of the shop's stocks (an actuator's mount plate, :mod:`fabricate.drive.mount`) is held
to half its own stock's thickness.
Only a cut process (``technique = "cut"``) is checked.

Every part is checked on what the shop gets, its cut path (the kerf-offset outline, holes and slots of
:func:`fabricate.export.dxf.cut_geometry`): each contour closed, simple and of positive size, no two contours
touching, crossing or repeating; and on what is left after cutting, the finished part: every hole and slot at
least ``min_hole_mm`` across, ``min_web_mm`` of material between any two of them, ``min_hole_edge_mm`` between
each and the outline. A tooth or a neck of the outline itself is the gear and strength checks' business.
The written files are held to the same (no TEXT, only contours on CUT, nothing repeated) by
:func:`fabricate.export.dxf.cut_file_problems`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.parts.profiles import touching_pairs

if TYPE_CHECKING:
    from fabricate.parts.model import Part
    from fabricate.process import ProcessSpec

#: Polygonisation of the checked contours (mm): far below any shop's resolution.
CHECK_TOLERANCE_MM = 0.005


@dataclass(frozen=True)
class ShopRules:
    """The shop's minimums (mm) a cut part must meet.

    Attributes
    ----------
    min_hole_mm : float
        Smallest finished hole diameter, or slot width.
    min_web_mm : float
        Smallest material between two holes or slots.
    min_hole_edge_mm : float
        Smallest material between a hole or slot and the outline.
    """

    min_hole_mm: float
    min_web_mm: float
    min_hole_edge_mm: float

    @classmethod
    def of(cls, process: ProcessSpec, thickness_mm: float | None = None) -> ShopRules:
        """The profile's ``[shop]`` for a part cut from its stock; a rule it does not give, or any rule for a part
        cut from another of the shop's stocks (``thickness_mm``: the profile's numbers are its own stock's), is
        half that stock's thickness."""
        t = float(process.thickness_mm) if thickness_mm is None else float(thickness_mm)
        own = abs(t - float(process.thickness_mm)) <= 1e-9
        given = dict(getattr(process, "shop", ()) or ()) if own else {}
        half = 0.5 * t
        return cls(min_hole_mm=float(given.get("min_hole_mm", half)), min_web_mm=float(given.get("min_web_mm", half)),
                   min_hole_edge_mm=float(given.get("min_hole_edge_mm", half)))

    def report(self) -> dict[str, float]:
        return {"min_hole_mm": self.min_hole_mm, "min_web_mm": self.min_web_mm,
                "min_hole_edge_mm": self.min_hole_edge_mm}


@dataclass(frozen=True)
class ShopResult:
    """Outcome of the shop rules over every part.

    Attributes
    ----------
    rules : ShopRules
    parts_checked : int
    failures : tuple of str
        One sentence per breach, naming the part, the feature, the rule and its number.
    """

    rules: ShopRules
    parts_checked: int
    failures: tuple[str, ...]

    @property
    def passed(self) -> bool:
        return not self.failures

    def report(self) -> dict[str, Any]:
        """report.json's ``interference.shop``: the rules, parts checked, passed and the failures."""
        return {"rules": self.rules.report(), "parts_checked": self.parts_checked, "passed": self.passed,
                "failures": list(self.failures)}


@dataclass(frozen=True)
class _Feature:
    """A hole or slot of the finished part: its name and shape."""

    name: str
    geometry: Any  # shapely Polygon (a slot) or None for a circle
    centre: np.ndarray
    radius: float  # circles only


def _features(part: Part) -> list[_Feature]:
    out = [_Feature(f"hole {h.joint} Ø{h.diameter_mm:.3f}", None, np.asarray(h.centre, dtype=np.float64),
                    0.5 * float(h.diameter_mm)) for h in part.holes]
    for k, slot in enumerate(getattr(part, "slots", ()), start=1):
        poly = shapely.Polygon(slot.polygon(CHECK_TOLERANCE_MM))
        out.append(_Feature(f"slot {k}", poly, np.zeros(2), 0.0))
    return out


def _distance(a: _Feature, b: _Feature) -> float:
    """Material between two features (negative: they overlap)."""
    if a.geometry is None and b.geometry is None:
        return float(np.hypot(*(a.centre - b.centre))) - a.radius - b.radius
    if a.geometry is None:
        a, b = b, a
    if b.geometry is None:  # a slot and a circle
        point = shapely.Point(b.centre)
        gap = float(a.geometry.exterior.distance(point))
        return (-gap if a.geometry.contains(point) else gap) - b.radius
    return -1.0 if a.geometry.intersects(b.geometry) else float(a.geometry.distance(b.geometry))


def _to_edge(feature: _Feature, outline: Any) -> float:
    """Material between a feature and the outline (negative: it reaches or passes the outline)."""
    if feature.geometry is None:
        point = shapely.Point(feature.centre)
        if not outline.contains(point):
            return -1.0
        return float(outline.exterior.distance(point)) - feature.radius
    if not outline.contains(feature.geometry):
        return -1.0
    return float(outline.exterior.distance(feature.geometry))


def _width(feature: _Feature) -> float:
    """A hole's diameter, a slot's width (twice its largest inscribed radius)."""
    if feature.geometry is None:
        return 2.0 * feature.radius
    from shapely.ops import polylabel

    centre = polylabel(feature.geometry, tolerance=CHECK_TOLERANCE_MM / 10.0)
    return 2.0 * float(feature.geometry.exterior.distance(centre))


def cut_path_problems(part: Part, kerf_mm: float) -> list[str]:
    """What is wrong with a part's cut path as a shop's software reads it (empty: nothing).

    Each contour (outline, slots, holes) must be closed, simple (no self-crossing) and of positive size, and
    no two contours may touch, cross or coincide (a repeated or overlapping line is cut twice)."""
    from fabricate.export.dxf import cut_geometry

    outline, holes, slots = cut_geometry(part, kerf_mm)
    contours: list[tuple[str, Any]] = []
    for name, path in [("outline", outline)] + [(f"slot {k}", s) for k, s in enumerate(slots, start=1)]:
        ring = path.polygon(CHECK_TOLERANCE_MM)
        if len(ring) < 3 or abs(float(path.area())) <= 0.0:
            return [f"the cut {name} is not a closed contour of positive area"]
        poly = shapely.Polygon(ring)
        if not poly.is_valid:
            return [f"the cut {name} crosses itself ({shapely.is_valid_reason(poly)})"]
        contours.append((name, poly.exterior))
    for hole, (centre, diameter) in zip(part.holes, holes, strict=True):
        if diameter <= 0.0:
            return [f"hole {hole.joint}: the cut circle has no size (Ø{diameter:.3f} mm after the kerf)"]
        contours.append((f"hole {hole.joint}", shapely.Point(centre).buffer(diameter / 2.0, 64).exterior))
    return [f"the cut {contours[i][0]} and {contours[j][0]} touch or overlap (a line cut twice)"
            for i, j in touching_pairs([c for _, c in contours])]


def check_part(part: Part, rules: ShopRules, kerf_mm: float) -> list[str]:
    """Every shop rule on one part: failures, each naming the part, the feature and the rule."""
    where = f"shop: part {part.name}"
    problems = [f"{where}: {p}" for p in cut_path_problems(part, kerf_mm)]
    outline = shapely.Polygon(part.outline.polygon(CHECK_TOLERANCE_MM))
    features = _features(part)
    for f in features:
        width = _width(f)
        if width < rules.min_hole_mm - 1e-9:
            problems.append(f"{where}: {f.name} is {width:.3f} mm across, below the shop's minimum hole "
                            f"{rules.min_hole_mm:g} mm (min_hole_mm)")
        edge = _to_edge(f, outline)
        if edge < rules.min_hole_edge_mm - 1e-9:
            what = "reaches the outline" if edge < 0 else f"leaves {edge:.3f} mm to the edge"
            problems.append(f"{where}: {f.name} {what}, below the shop's hole-to-edge {rules.min_hole_edge_mm:g} mm "
                            "(min_hole_edge_mm)")
    for i, a in enumerate(features):
        for b in features[i + 1:]:
            web = _distance(a, b)
            if web < rules.min_web_mm - 1e-9:
                what = "overlap" if web < 0 else f"leave a {web:.3f} mm web"
                problems.append(f"{where}: {a.name} and {b.name} {what}, below the shop's minimum web "
                                f"{rules.min_web_mm:g} mm (min_web_mm)")
    return problems


def check_shop(parts: Sequence[Part], process: ProcessSpec) -> ShopResult | None:
    """The shop rules over every part of a cut process (None for any other process)."""
    if process.technique != "cut":
        return None
    rules = ShopRules.of(process)
    failures: list[str] = []
    for part in parts:  # a part cut from another stock (an actuator's mount plate) is held to that stock's rules
        own = rules if abs(float(part.thickness_mm) - float(process.thickness_mm)) <= 1e-9 else \
            ShopRules.of(process, float(part.thickness_mm))
        failures += check_part(part, own, float(process.kerf_mm))
    return ShopResult(rules=rules, parts_checked=len(parts), failures=tuple(failures))

