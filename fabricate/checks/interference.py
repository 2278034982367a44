"""Interference of every pair of parts (and pins) over the whole motion.

Every part is a prism (a planar outline extruded from ``z_mm`` by ``thickness_mm``) moving with its
body; pins are cylinders fixed in one body. For two prisms the 3D problem is exactly planar:

- z ranges overlap by ``t > 0``: the solids collide iff the posed outlines overlap, the overlap volume
  is the planar overlap area × ``t``, and the clearance is the planar distance of the outlines;
- z ranges are disjoint with gap ``g``: no collision; the clearance is ``hypot(g, planar distance)``
  (``g`` itself wherever the outlines overlap in plan view, e.g. two links stacked on one pin).

The sweep is therefore (1) a broad phase per pair over all poses at once: z ranges (layers) and the
distance of bounding circles; (2) pairs that one pose settles (a pin on its hole's axis keeps one
clearance; parts on other layers whose gap alone is enough are at exactly that gap wherever they
overlap in plan, so one such pose gives the minimum); (3) the exact planar clearance of the poses
left (:mod:`fabricate.checks.distance`: vectorised posing and overlap test, GEOS distance on
clipped windows); (4) manifold3d on the few poses that decide the verdict: ``min_gap`` at each
pair's closest pose (searching just beyond the planar value) and the boolean intersection volume at
each colliding pair's worst pose. The kernel's numbers are the ones reported (the smaller of the two
for a clearance); the planar engine chooses where to ask.

Pairs of one body are rigid (no relative motion) and are not swept, but for an actuator's body (and its
mount's standoffs) against the parts of the body it is fixed to: those are "fixed" (may touch, must not
overlap; one pose settles them). An actuator's output and horn screws are fastened to the part they
drive (rigid with it); the output on the actuator's own body is "bearing". Joined pairs (two parts on one
pin, a pin in the hole of a part of another body) are swept like any other: their clearances are the
layer gap and the radial pin clearance, and they must meet the minimum like every moving pair. Gear
parts meshing with each other (same ``gear`` name, different bodies) run with the backlash, far below
the process clearance: for them only an overlap fails here, the backlash is judged by the gear mesh
check. Spacers (tubes, washers) bear on the parts of their joint and on whatever is flush with their
end faces: touching is allowed there, an overlap is not. A clearance passes when it is at least the
minimum less the chord tolerance (polygons inscribed in the exact curves can read that much short).

The solids (:class:`~fabricate.checks.items.SweepItem`) and their relations are :mod:`fabricate.checks.items`'s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.checks.distance import Outline, RelativePoses, overlap_areas, planar_clearance
from fabricate.checks.items import (
    PinSolid,
    SweepItem,
    item_relation,
    part_items,
    pin_items,
    pins_from_holes,
    pins_from_parts_layer,
    require_positive,
    spacer_items,
)
from fabricate.errors import GeometryError, SpecError
from fabricate.mechanism import Motion
from fabricate.parts.model import Part
from fabricate.planar import polygon_area

if TYPE_CHECKING:
    from fabricate.parts.bom import Pin, Spacer

#: Planar clearances beyond this (mm) are not resolved exactly (curves show a lower bound there).
DEFAULT_SEARCH_MM = 2.0
#: Planar penetration (mm) below which two outlines touch rather than overlap.
TOUCH_MM = 1e-9
#: Colliding poses at which the overlap volume is computed before refining around the worst.
OVERLAP_SAMPLES = 24
#: Relations whose solids may touch (only an overlap fails): gears in mesh (the backlash is the gear mesh
#: check's), spacers on their faces, an actuator's output in its own bearing, an actuator or standoff fixed
#: to a body's parts.
TOUCHING = ("meshing", "bearing", "fixed")
#: The first pose alone (pairs one pose settles).
_FIRST = np.zeros(1, dtype=np.intp)


@dataclass(frozen=True)
class PairResult:
    """Clearance and collisions of one pair over the motion.

    Attributes
    ----------
    a, b : str
        Item names.
    relation : str
        ``"moving"``, ``"joined"`` (share a pin), ``"pin"`` (a pin in another body's hole),
        ``"bearing"`` (a spacer against a part of its joint, or anything flush with a spacer's end
        face, or an actuator's output on its body: may touch, must not overlap),
        ``"fixed"`` (an actuator's body or a mount standoff against a part of the body it is fixed to:
        may touch, must not overlap) or
        ``"meshing"`` (gear parts in mesh).
    z_gap_mm : float
        Gap between the z ranges (negative: the overlap thickness).
    required_mm : float
        Clearance the pair must keep (0 for meshing gears: only an overlap fails).
    clearance : (n,) array
        Clearance per pose, mm: exact up to the search length, a lower bound beyond it
        (``exact`` says which); 0 where the solids overlap.
    exact : (n,) bool array
    min_clearance_mm : float
        Smallest clearance over the motion (manifold ``min_gap`` at that pose when it resolves it).
    min_index : int
        Pose index of the smallest clearance.
    kernel_gap_mm : float or None
        manifold3d ``min_gap`` at ``min_index`` (None when not asked).
    collision_indices : (k,) int array
        Poses where the solids overlap.
    overlap_indices : (j,) int array
        Colliding poses whose overlap volume was computed (all of them, or a spread sample refined
        around the worst).
    overlap_mm3 : (j,) array
        Planar overlap area × z overlap at those poses.
    max_overlap_mm3 : float
        Largest overlap volume, from manifold3d's boolean intersection at the worst pose.
    max_overlap_index : int
    """

    a: str
    b: str
    relation: str
    z_gap_mm: float
    required_mm: float
    clearance: np.ndarray
    exact: np.ndarray
    min_clearance_mm: float
    min_index: int
    kernel_gap_mm: float | None
    collision_indices: np.ndarray
    overlap_indices: np.ndarray
    overlap_mm3: np.ndarray
    max_overlap_mm3: float
    max_overlap_index: int

    @property
    def collides(self) -> bool:
        return len(self.collision_indices) > 0


@dataclass(frozen=True)
class InterferenceResult:
    """Outcome of :func:`sweep_interference`.

    Attributes
    ----------
    inputs : (n,) array
        Input values of the poses (``input_unit``).
    input_unit : str
    pairs : tuple of PairResult
        Every non-rigid pair, in item order.
    rigid_pairs : int
        Pairs on one body (no relative motion), not swept.
    min_clearance_required_mm : float
    tolerance_mm : float
        Slack of the clearance verdict: the chord tolerance of the polygonised solids.
    search_length_mm : float
    """

    inputs: np.ndarray
    input_unit: str
    pairs: tuple[PairResult, ...]
    rigid_pairs: int
    min_clearance_required_mm: float
    tolerance_mm: float
    search_length_mm: float

    @property
    def collisions(self) -> list[PairResult]:
        return [p for p in self.pairs if p.collides]

    def too_close(self) -> list[PairResult]:
        """Pairs that do not collide but come closer than they must."""
        return [p for p in self.pairs if not p.collides
                and p.min_clearance_mm < p.required_mm - self.tolerance_mm]

    @property
    def min_clearance_mm(self) -> float:
        """Smallest clearance over all pairs that must keep the process clearance (mm)."""
        values = [p.min_clearance_mm for p in self.pairs if p.relation not in TOUCHING]
        return float(min(values)) if values else math.inf

    def failures(self) -> list[str]:
        """Human-readable reasons the sweep fails (empty when it passes)."""
        out = []
        unit = self.input_unit
        for p in self.collisions:
            ranges = ", ".join(f"{lo:g}..{hi:g}" for lo, hi in self.input_ranges(p.collision_indices))
            out.append(f"interference: {p.a} collides with {p.b} at input {ranges} {unit} "
                       f"(largest overlap {p.max_overlap_mm3:.3f} mm^3 at "
                       f"{self.inputs[p.max_overlap_index]:g} {unit})")
        for p in self.too_close():
            out.append(f"clearance: {p.a} and {p.b} come within {p.min_clearance_mm:.3f} mm at input "
                       f"{self.inputs[p.min_index]:g} {unit}; the process needs {p.required_mm:.3f} mm")
        return out

    @property
    def passed(self) -> bool:
        return not self.failures()

    def input_ranges(self, indices: np.ndarray) -> list[tuple[float, float]]:
        """Contiguous runs of pose indices as (first, last) input values."""
        if len(indices) == 0:
            return []
        idx = np.asarray(indices)
        breaks = np.nonzero(np.diff(idx) > 1)[0]
        starts = np.concatenate([[idx[0]], idx[breaks + 1]])
        ends = np.concatenate([idx[breaks], [idx[-1]]])
        return [(float(self.inputs[s]), float(self.inputs[e])) for s, e in zip(starts, ends, strict=True)]

    def report(self) -> dict[str, Any]:
        """The ``interference`` section of report.json (its keys: fabricate/report_schema.json, docs/report.md)."""
        collisions = []
        for p in self.collisions:
            collisions.append({
                "a": p.a, "b": p.b,
                "input_deg": float(self.inputs[p.max_overlap_index]),
                "volume_mm3": round(float(p.max_overlap_mm3), 6),
                "input_ranges": [[lo, hi] for lo, hi in self.input_ranges(p.collision_indices)],
                "poses_colliding": int(len(p.collision_indices)),
            })
        return {
            "poses": int(len(self.inputs)),
            "pairs_checked": len(self.pairs),
            "collisions": collisions,
            "min_clearance_mm": _finite(self.min_clearance_mm),
            "input_unit": self.input_unit,
            "required_clearance_mm": self.min_clearance_required_mm,
            "tolerance_mm": self.tolerance_mm,
            "rigid_pairs_skipped": self.rigid_pairs,
            "pairs": [self.pair_row(p) for p in self.pairs],
        }

    def pair_row(self, p: PairResult) -> dict[str, Any]:
        """One row of the per-pair table."""
        return {
            "a": p.a, "b": p.b, "relation": p.relation,
            "min_clearance_mm": _finite(p.min_clearance_mm),
            # False: the parts never came within the search length, the value is a lower bound
            "exact": bool(p.exact[p.min_index]),
            "input_deg": float(self.inputs[p.min_index]),
            "required_mm": p.required_mm,
            "z_gap_mm": round(p.z_gap_mm, 6),
            "kernel_gap_mm": None if p.kernel_gap_mm is None else round(p.kernel_gap_mm, 6),
            "collides": p.collides,
            "ok": not p.collides and p.min_clearance_mm >= p.required_mm - self.tolerance_mm,
            # the names report.md's table reads
            "at_input": float(self.inputs[p.min_index]),
            "kind": p.relation,
        }


def _finite(value: float) -> float | None:
    return round(float(value), 6) if math.isfinite(value) else None


def _outline(item: SweepItem) -> Outline:
    # the same words as the boolean reference's extrusion (parts/solids.py), not shapely's ring error
    outer = item.rings[0]  # every item has its outer ring (float64, from the parts layer's polygons)
    if len(outer) < 3 or not polygon_area(outer) > 0.0:
        raise GeometryError(f"{item.name}: empty cross-section")
    return Outline(list(item.rings))


class _PlanarMemo:
    """The planar engine's answers within one sweep, shared by the pairs that ask the same question.

    A planar value is a pure function of the two outlines, the two bodies' poses and the poses asked: a
    stack of identical washers on one pin of one body, against another such stack, asks the same question
    for every washer pair (the laser underactuated finger: 1098 distance runs of which 90 differ, 377 000
    posed distances of which 24 000 differ). Identical outlines are therefore made one :class:`Outline`,
    and each answer is computed once, by the same call with the same arguments as before, so the values
    are the same bits.
    """

    def __init__(self, poses: dict[str, np.ndarray], search: float) -> None:
        self.poses = poses
        self.search = search
        self._outlines: dict[tuple[Any, ...], Outline] = {}
        self._rel: dict[tuple[str, str], RelativePoses] = {}
        self._values: dict[tuple[Any, ...], np.ndarray] = {}

    def outline(self, item: SweepItem) -> Outline:
        """The item's outline, one object for every item of the same rings."""
        key = tuple((r.shape, r.dtype.str, np.ascontiguousarray(r).tobytes()) for r in item.rings)
        found = self._outlines.get(key)
        if found is None:
            found = self._outlines[key] = _outline(item)
        return found

    def relative(self, body_a: str, body_b: str) -> RelativePoses:
        """Poses of ``body_b``'s frame in ``body_a``'s."""
        rel = self._rel.get((body_a, body_b))
        if rel is None:
            rel = self._rel[(body_a, body_b)] = RelativePoses.between(self.poses[body_a], self.poses[body_b])
        return rel

    def lower_bound(self, oa: Outline, ob: Outline, bodies: tuple[str, str]) -> np.ndarray:
        """The broad phase: per pose, the distance of the outlines' bounding circles (read-only)."""
        key = ("lower", id(oa), id(ob), bodies)
        found = self._values.get(key)
        if found is None:
            centre_b = self.relative(*bodies).apply(ob.centre[None, :])[:, 0]
            found = np.hypot(*(centre_b - oa.centre).T) - oa.radius - ob.radius
            found.flags.writeable = False
            self._values[key] = found
        return found

    def clearance(self, oa: Outline, ob: Outline, bodies: tuple[str, str], index: np.ndarray) -> np.ndarray:
        """:func:`planar_clearance` of ``ob`` posed at the poses ``index`` of ``bodies`` (read-only)."""
        return self._ask("clearance", oa, ob, bodies, index)

    def overlap(self, oa: Outline, ob: Outline, bodies: tuple[str, str], index: np.ndarray) -> np.ndarray:
        """:func:`overlap_areas` of ``ob`` posed at the poses ``index`` of ``bodies`` (read-only)."""
        return self._ask("overlap", oa, ob, bodies, index)

    def _ask(self, what: str, oa: Outline, ob: Outline, bodies: tuple[str, str], index: np.ndarray) -> np.ndarray:
        index = np.asarray(index, dtype=np.intp)
        key = (what, id(oa), id(ob), bodies, index.tobytes())
        found = self._values.get(key)
        if found is None:
            rel = RelativePoses(self.relative(*bodies).q[index])
            # the module's names, looked up at call time (tests count the poses the engine is handed)
            found = (planar_clearance(oa, ob, rel, self.search) if what == "clearance"
                     else overlap_areas(oa, ob, rel))
            found.flags.writeable = False
            self._values[key] = found
        return found



# -- the sweep -------------------------------------------------------------------------------------
def sweep_interference(parts: Sequence[Part], motion: Motion, *, chord_tolerance_mm: float,
                       min_clearance_mm: float, pins: Sequence[PinSolid | Pin] | None = None,
                       spacers: Sequence[Spacer] = (), search_length_mm: float | None = None,
                       use_kernel: bool = True, extra: Sequence[SweepItem] = ()) -> InterferenceResult:
    """Check every pair of parts and pins for collision and clearance at every pose of ``motion``.

    Parameters
    ----------
    parts : sequence of Part
    motion : Motion
        Poses of every body; each of its inputs is one pose of the check.
    chord_tolerance_mm : float
        Polygonisation of the solids (also the slack of the clearance verdict).
    min_clearance_mm : float
        Clearance every moving pair must keep (mm).
    pins : sequence of PinSolid or parts-layer pins, optional
        Default: :func:`pins_from_holes`.
    spacers : sequence of parts-layer spacers
        Tubes and washers on the pins (see :func:`spacer_items`).
    search_length_mm : float, optional
        Planar distances up to this are resolved exactly (default max(2 mm, 4 × the minimum)).
    use_kernel : bool
        Confirm with manifold3d (``min_gap`` / intersection volume) at the deciding poses.
    extra : sequence of SweepItem
        Further solids (an actuator's, :func:`fabricate.drive.parts.sweep_items`), swept like the rest.

    Returns
    -------
    InterferenceResult
    """
    require_positive("chord_tolerance_mm", float(chord_tolerance_mm))
    if not (math.isfinite(float(min_clearance_mm)) and float(min_clearance_mm) >= 0.0):
        raise SpecError("min_clearance_mm", f"must be a finite number >= 0, got {min_clearance_mm!r}")
    if search_length_mm is not None:
        require_positive("search_length_mm", float(search_length_mm))
    pins = pins_from_holes(parts) if pins is None else pins_from_parts_layer(pins, parts)
    search = float(search_length_mm or max(DEFAULT_SEARCH_MM, 4.0 * min_clearance_mm))
    items = (part_items(parts, chord_tolerance_mm) + pin_items(pins, chord_tolerance_mm)
             + spacer_items(spacers, parts, chord_tolerance_mm) + list(extra))
    outlines: dict[str, Outline] = {}
    solids: dict[str, object] = {}
    poses = {name: motion.pose(name) for name in motion.body_names}
    memo = _PlanarMemo(poses, search)
    results = []
    rigid = 0
    for i in range(len(items)):
        for j in range(i + 1, len(items)):
            a, b = items[i], items[j]
            relation = item_relation(a, b)
            if relation == "rigid":
                rigid += 1
                continue
            for it in (a, b):
                if it.name not in outlines:
                    outlines[it.name] = memo.outline(it)
            required = 0.0 if relation in TOUCHING else float(min_clearance_mm)
            results.append(_sweep_pair(a, b, outlines[a.name], outlines[b.name], poses[a.body], poses[b.body],
                                       relation, required, search, solids if use_kernel else None,
                                       chord_tolerance_mm, memo))
    return InterferenceResult(np.asarray(motion.inputs, dtype=np.float64), motion.mechanism.input_unit,
                              tuple(results), rigid, float(min_clearance_mm), float(chord_tolerance_mm), search)


def _sweep_pair(a: SweepItem, b: SweepItem, oa: Outline, ob: Outline, pose_a: np.ndarray, pose_b: np.ndarray,
                relation: str, required: float, search: float, solids: dict[str, Any] | None,
                tol: float, planar_memo: _PlanarMemo) -> PairResult:
    n = len(pose_a)
    bodies = (a.body, b.body)
    z_gap = max(a.z0, b.z0) - min(a.z1, b.z1)
    if abs(z_gap) < 1e-9:
        # flush faces (layer heights are sums of thicknesses and gaps: 12.6 may come out 12.600000000000001)
        z_gap = 0.0
    stacked = z_gap >= 0.0
    rel = planar_memo.relative(*bodies)
    # broad phase: bounding circles; a pose whose circles are farther apart than the search length
    # keeps that distance as a lower bound of its clearance
    lower = planar_memo.lower_bound(oa, ob, bodies)
    planar = np.maximum(lower, search)
    exact = np.zeros(n, dtype=bool)
    near = np.nonzero(lower < search)[0]
    shortcut = None if a.body == b.body else _shortcut(a, b, oa, ob, rel, lower, z_gap, required, tol,
                                                       planar_memo)
    if a.body == b.body:  # fixed to one body: one pose is every pose
        value = float(planar_memo.clearance(oa, ob, bodies, _FIRST)[0])
        resolved = math.isfinite(value) or value < 0
        planar[:] = value if resolved else search
        exact[:] = resolved
        near = near[:0]
    elif shortcut is not None:
        k, value = shortcut
        if value > 0.0:  # a pin in its hole: the same clearance at every pose
            planar[:] = value
            exact[:] = True
        else:  # stacked, overlapping in plan at pose k: elsewhere 0 is a safe lower bound
            planar = np.maximum(lower, 0.0)
            planar[k], exact[k] = value, True
        near = near[:0]
    if len(near):
        d = planar_memo.clearance(oa, ob, bodies, near)
        resolved = np.isfinite(d) | (d < 0)
        planar[near] = np.where(resolved, d, search)
        exact[near] = resolved
    if stacked:
        clearance = np.hypot(z_gap, np.maximum(planar, 0.0))
        collide_idx = np.zeros(0, dtype=int)
    else:
        clearance = np.maximum(planar, 0.0)
        # a negative value within rounding is touching (clearance 0), not an overlap
        collide_idx = np.nonzero(planar < -TOUCH_MM)[0]
    sampled = np.zeros(0, dtype=int)
    overlap = np.zeros(0)
    max_overlap = 0.0
    max_idx = 0
    if len(collide_idx):
        sampled, overlap = _overlap_volumes(oa, ob, bodies, collide_idx, -z_gap, planar_memo)
        k = int(np.argmax(overlap))
        max_idx = int(sampled[k])
        max_overlap = float(overlap[k])
        if solids is not None:
            sa, sb = _posed_pair(a, b, pose_a[max_idx], pose_b[max_idx], solids, tol)
            max_overlap = float((sa ^ sb).volume())
    # smallest clearance, an exactly known pose first among equal values (stacked parts show the
    # z gap as a lower bound everywhere and exactly where they overlap in plan)
    min_idx = int(np.lexsort((~exact, clearance))[0])
    min_clear = float(clearance[min_idx])
    kernel_gap = None
    if solids is not None and not len(collide_idx) and exact[min_idx] and min_clear < search:
        sa, sb = _posed_pair(a, b, pose_a[min_idx], pose_b[min_idx], solids, tol)
        # search just beyond the planar value: manifold's min_gap is fast when the search is short
        reach = min_clear + 4.0 * tol + 1e-3
        kernel_gap = float(sa.min_gap(sb, reach))
        if kernel_gap < reach:
            min_clear = min(min_clear, kernel_gap)
    return PairResult(a.name, b.name, relation, float(z_gap), required, clearance, exact, min_clear, min_idx,
                      kernel_gap, collide_idx, sampled, overlap, max_overlap, max_idx)


def _overlap_volumes(oa: Outline, ob: Outline, bodies: tuple[str, str], colliding: np.ndarray,
                     thickness: float, planar_memo: _PlanarMemo) -> tuple[np.ndarray, np.ndarray]:
    """Overlap volumes (planar overlap area × z overlap) at up to :data:`OVERLAP_SAMPLES` colliding
    poses spread over the run, then at every colliding pose next to the worst sample (the volume is
    continuous in the pose, so its maximum lies there); returns (pose indices, volumes)."""
    if len(colliding) <= OVERLAP_SAMPLES:
        picks = colliding
    else:
        picks = colliding[np.unique(np.linspace(0, len(colliding) - 1, OVERLAP_SAMPLES).round().astype(int))]
    volumes = planar_memo.overlap(oa, ob, bodies, picks) * thickness
    if len(picks) < len(colliding):
        k = int(np.argmax(volumes))
        lo = picks[k - 1] if k > 0 else picks[0]
        hi = picks[k + 1] if k + 1 < len(picks) else picks[-1]
        extra = np.setdiff1d(colliding[(colliding > lo) & (colliding < hi)], picks)
        if len(extra):
            picks = np.concatenate([picks, extra])
            volumes = np.concatenate([volumes, planar_memo.overlap(oa, ob, bodies, extra) * thickness])
            order = np.argsort(picks)
            picks, volumes = picks[order], volumes[order]
    return picks, volumes


def _shortcut(a: SweepItem, b: SweepItem, oa: Outline, ob: Outline, rel: RelativePoses, lower: np.ndarray,
              z_gap: float, required: float, tol: float, planar_memo: _PlanarMemo) -> tuple[int, float] | None:
    """Pairs whose sweep one pose settles: (pose index, planar value) or None.

    - A pin in another body's hole whose axis stays on the hole's centre (a revolute joint): the pin
      lies inside the hole's disc at every pose, so the nearest material of the part is that hole's
      wall and the clearance is the same at every pose; one pose gives it exactly.
    - Parts on disjoint z ranges whose gap alone meets the requirement: the clearance is at least the
      gap at every pose and equals it wherever the outlines overlap in plan view (parts on one pin
      always do); one pose that shows the overlap gives the exact minimum.
    """
    if a.kind == "pin" or b.kind == "pin":
        pin, part, flip = (a, b, False) if a.kind == "pin" else (b, a, True)
        if part.kind == "spacer":
            hole_centre = np.asarray(part.source.centre, dtype=np.float64)
        elif part.kind == "part":
            hole = next((h for h in part.source.holes if h.joint in pin.joints), None)
            if hole is None:
                return None
            hole_centre = np.asarray(hole.centre, dtype=np.float64)
        else:
            return None
        # pin axis in the part's frame at every pose
        q = rel.inverse() if not flip else rel
        axis = q.apply(np.asarray(pin.source.centre, dtype=np.float64)[None, :])[:, 0]
        if np.max(np.hypot(*(axis - hole_centre).T)) > 1e-6:
            return None
        value = float(planar_memo.clearance(oa, ob, (a.body, b.body), _FIRST)[0])
        return (0, value) if value > 0.0 else None
    if z_gap >= 0.0 and z_gap >= required - tol:
        k = int(np.argmin(lower))
        value = float(planar_memo.overlap(oa, ob, (a.body, b.body), np.array([k]))[0])
        if value > 0.0:
            return k, -math.inf
    return None


def _posed_pair(a: SweepItem, b: SweepItem, pose_a: np.ndarray, pose_b: np.ndarray, cache: dict[str, Any],
                tol: float) -> list[Any]:
    # manifold3d is imported here and in the parts adapter only (kernel isolation)
    from fabricate.parts.solids import extrude_polygons, posed

    out = []
    for it, pose in ((a, pose_a), (b, pose_b)):
        if it.name not in cache:
            cache[it.name] = extrude_polygons(list(it.rings), it.z1 - it.z0, it.z0, what=it.name)
        out.append(posed(cache[it.name], pose))
    return out


def naive_interference(parts: Sequence[Part], motion: Motion, *, chord_tolerance_mm: float,
                       pins: Sequence[PinSolid | Pin] | None = None, spacers: Sequence[Spacer] = (),
                       extra: Sequence[SweepItem] = ()) -> dict[tuple[str, str], np.ndarray]:
    """Reference: the boolean intersection of every non-rigid pair at every pose (manifold3d only).

    Returns
    -------
    dict
        ``(a, b) -> (n,) overlap volumes (mm^3)`` for the same pairs :func:`sweep_interference` checks.
        For benchmarks and tests; far slower than the sweep.
    """
    pins = pins_from_holes(parts) if pins is None else pins_from_parts_layer(pins, parts)
    items = (part_items(parts, chord_tolerance_mm) + pin_items(pins, chord_tolerance_mm)
             + spacer_items(spacers, parts, chord_tolerance_mm) + list(extra))
    cache: dict[str, object] = {}
    poses = {name: motion.pose(name) for name in motion.body_names}
    out = {}
    for i in range(len(items)):
        for j in range(i + 1, len(items)):
            a, b = items[i], items[j]
            if item_relation(a, b) == "rigid":
                continue
            volumes = np.zeros(len(motion.inputs))
            for k in range(len(motion.inputs)):
                sa, sb = _posed_pair(a, b, poses[a.body][k], poses[b.body][k], cache, chord_tolerance_mm)
                volumes[k] = (sa ^ sb).volume()
            out[(a.name, b.name)] = volumes
    return out
