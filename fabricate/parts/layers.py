"""Layer assignment: bodies that come near each other anywhere over the motion go to different layers.

The conflict test works in the plan view: for every pair of bodies the outline of one is moved into the
frame of the other at every sampled pose (the relative swept plan view) and the smallest distance between
the two outlines is compared with the clearance. Bodies joined by a pin always conflict (their bosses
share the pin). Bodies carrying meshing gears are merged into one group first (their teeth must lie in
one plane) and the groups are coloured greedily (DSATUR, ties broken by body order so it is
deterministic). The colours are then put in order (:func:`order_layers`): no body between the two layers of a
pin it passes over; where a pin's retention sticks out of its stack (a clip and its washers, a cap, or a pressed
pin's bare stub at one end), no body that passes over the pin's end and no pin near it in the room beyond the end
face, with empty layers put in where no order of the colours gives that room; no stack longer than a standard pin;
a motor's short shaft's driven part near a face of the stack, clear of the pin ends within the motor's reach.
Where no order of the colours does all that, one body of a shared layer may take a layer of its own.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import shapely

from fabricate.planar import relative_poses, wrap_angle

#: At most this many poses of the motion are used for the plan-view conflict test.
MAX_CONFLICT_POSES = 180


def min_distance_over_motion(outline_ref: np.ndarray, outline_body: np.ndarray, rel: np.ndarray,
                             within: float | None = None) -> float:
    """Smallest distance (mm) between a fixed outline and a moving one over relative poses.

    Parameters
    ----------
    outline_ref, outline_body : (n, 2), (m, 2) arrays
        Outlines in their own body coordinates, mm.
    rel : (k, 3) array
        Poses of the moving body in the reference body's frame.
    within : float, optional
        Only decide whether the result is below this: return 0 if it is and ``within`` if not. GEOS
        computes a polygon distance by comparing every edge pair (two 200-tooth gears: seconds per
        pose), while a distance-within test on the prepared fixed outline uses its edge index.

    Returns
    -------
    float
        0 where they overlap; otherwise the gap, less a margin for the motion between samples.
    """
    c, s = np.cos(rel[:, 2]), np.sin(rel[:, 2])
    x = outline_body[None, :, 0] * c[:, None] - outline_body[None, :, 1] * s[:, None] + rel[:, None, 0]
    y = outline_body[None, :, 0] * s[:, None] + outline_body[None, :, 1] * c[:, None] + rel[:, None, 1]
    rings = np.stack([x, y], -1)
    rings = np.concatenate([rings, rings[:, :1]], axis=1)
    moving = shapely.polygons(rings)
    fixed = shapely.Polygon(outline_ref)
    # a point of the moving outline travels at most this far between consecutive samples
    if len(rel) > 1:
        reach = float(np.max(np.hypot(outline_body[:, 0], outline_body[:, 1])))
        # relative angles come wrapped to (-pi, pi]: the turn between samples is the wrapped difference
        turn = np.abs(wrap_angle(np.diff(rel[:, 2])))
        step = np.hypot(np.diff(rel[:, 0]), np.diff(rel[:, 1])) + turn * reach
        margin = 0.5 * float(np.max(step))
    else:
        margin = 0.0
    if within is not None:
        shapely.prepare(fixed)
        return 0.0 if bool(np.any(shapely.dwithin(fixed, moving, within + margin))) else float(within)
    gaps = shapely.distance(moving, fixed)
    return max(0.0, float(np.min(gaps)) - margin)


def conflict_graph(outlines: Mapping[str, np.ndarray], world_poses: Mapping[str, np.ndarray],
                   clearance_mm: float, always: Sequence[tuple[str, str]] = ()) -> dict[str, set[str]]:
    """Which bodies must not share a layer.

    Parameters
    ----------
    outlines : Mapping[str, (n, 2) array]
        Each body's outline polygon in body coordinates (mm).
    world_poses : Mapping[str, (k, 3) array]
        Each body's world poses over the motion.
    clearance_mm : float
        Outlines closer than this anywhere over the motion conflict.
    always : sequence of (str, str)
        Pairs that conflict regardless (bodies sharing a pin).

    Returns
    -------
    dict[str, set[str]]
        Symmetric adjacency.
    """
    names = list(outlines)
    graph: dict[str, set[str]] = {n: set() for n in names}
    for a, b in always:
        if a in graph and b in graph and a != b:
            graph[a].add(b)
            graph[b].add(a)
    k = len(next(iter(world_poses.values()))) if world_poses else 0
    pick = np.unique(np.linspace(0, max(k - 1, 0), min(k, MAX_CONFLICT_POSES)).round().astype(int))
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if b in graph[a]:
                continue
            rel = relative_poses(world_poses[a][pick], world_poses[b][pick])
            if min_distance_over_motion(outlines[a], outlines[b], rel, within=clearance_mm) < clearance_mm:
                graph[a].add(b)
                graph[b].add(a)
    return graph


def assign_layers(graph: Mapping[str, set[str]], order: Sequence[str],
                  same_layer: Sequence[tuple[str, str]] = ()) -> dict[str, int]:
    """Colour the conflict graph: bodies -> layer index (0 at the bottom).

    Parameters
    ----------
    graph : Mapping[str, set[str]]
        Conflicts from :func:`conflict_graph`.
    order : sequence of str
        Body order for tie-breaks (the mechanism's order; the first body's group gets layer 0 when
        it is among the most constrained).
    same_layer : sequence of (str, str)
        Pairs forced into one layer (meshing gears); their mutual conflict is ignored.

    Returns
    -------
    dict[str, int]
    """
    parent = {n: n for n in order}

    def find(n: str) -> str:
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for a, b in same_layer:
        ra, rb = find(a), find(b)
        if ra != rb:
            # the earlier body in the order names the group
            if order.index(rb) < order.index(ra):
                ra, rb = rb, ra
            parent[rb] = ra
    groups: dict[str, list[str]] = {}
    for n in order:
        groups.setdefault(find(n), []).append(n)
    group_graph: dict[str, set[str]] = {g: set() for g in groups}
    for a in order:
        for b in graph.get(a, ()):
            ga, gb = find(a), find(b)
            if ga != gb:
                group_graph[ga].add(gb)
                group_graph[gb].add(ga)
    colour: dict[str, int] = {}
    rank = {g: order.index(g) for g in groups}
    while len(colour) < len(groups):
        def key(g: str) -> tuple[int, int, int]:
            saturation = len({colour[h] for h in group_graph[g] if h in colour})
            return (-saturation, -len(group_graph[g]), rank[g])
        g = min((g for g in groups if g not in colour), key=key)
        used = {colour[h] for h in group_graph[g] if h in colour}
        colour[g] = next(c for c in range(len(groups) + 1) if c not in used)
    return {n: colour[find(n)] for n in order}


def pin_crossings(outlines: Mapping[str, np.ndarray], world_poses: Mapping[str, np.ndarray],
                  pins: Sequence[tuple[np.ndarray, str, str]], spacer_radius_mm: float, clearance_mm: float
                  ) -> list[tuple[str, str, str]]:
    """Bodies that pass over a pin's spacer and so must not sit between the pin's two layers.

    Parameters
    ----------
    outlines, world_poses
        As for :func:`conflict_graph`.
    pins : sequence of ((2,) centre in body a, body a, body b)
        Every pin, its position in the coordinates of ``body a``.
    spacer_radius_mm : float
        Radius of the spacer tube that fills the skipped layers.
    clearance_mm : float

    Returns
    -------
    list of (body a, body b, body c)
        ``c`` comes within the clearance of the spacer at the pin of ``a`` and ``b`` somewhere in the motion.
    """
    k = len(next(iter(world_poses.values()))) if world_poses else 0
    pick = np.unique(np.linspace(0, max(k - 1, 0), min(k, MAX_CONFLICT_POSES)).round().astype(int))
    angles = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
    out = []
    for centre, a, b in pins:
        # a polygon around the spacer circle (circumscribed, so never smaller than the spacer)
        disc = centre + spacer_radius_mm / np.cos(np.pi / 48) * np.column_stack([np.cos(angles), np.sin(angles)])
        for c in outlines:
            if c in (a, b):
                continue
            rel = relative_poses(world_poses[a][pick], world_poses[c][pick])
            if min_distance_over_motion(disc, outlines[c], rel, within=clearance_mm) < clearance_mm:
                out.append((a, b, c))
    return out


def pin_neighbours(pins: Sequence[tuple[np.ndarray, str]], world_poses: Mapping[str, np.ndarray],
                   within_mm: float) -> list[tuple[int, int]]:
    """Pairs of pins that come within ``within_mm`` of each other (centre to centre) anywhere over the motion.

    Parameters
    ----------
    pins : sequence of ((2,) centre in the body's coordinates, body)
    world_poses : Mapping[str, (k, 3) array]
        Each body's world poses over the motion.
    within_mm : float

    Returns
    -------
    list of (int, int)
        Indices into ``pins``, the lower first.
    """
    k = len(next(iter(world_poses.values()))) if world_poses else 0
    pick = np.unique(np.linspace(0, max(k - 1, 0), min(k, MAX_CONFLICT_POSES)).round().astype(int))
    paths = []
    for centre, body in pins:
        pose = np.asarray(world_poses[body], dtype=np.float64)[pick]
        c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
        paths.append(np.column_stack([centre[0] * c - centre[1] * s + pose[:, 0],
                                      centre[0] * s + centre[1] * c + pose[:, 1]]))
    out = []
    for i, j in itertools.combinations(range(len(pins)), 2):
        rel = paths[i] - paths[j]
        # the pins move at most this far apart between samples
        margin = 0.5 * float(np.max(np.hypot(*np.diff(rel, axis=0).T))) if len(rel) > 1 else 0.0
        if float(np.min(np.hypot(rel[:, 0], rel[:, 1]))) - margin < within_mm:
            out.append((i, j))
    return out


#: The layer order tries at most this many arrangements for one number of layers.
MAX_ARRANGEMENTS = 400_000
#: What a collision counts in the layer order (as much as a stack no standard pin covers, whose pin is then cut
#: from rod: weighing collisions more makes the plain order trade them for taller stacks, e.g. the laser five-bar's
#: 28.7 mm mount standoffs, longer than a standard screw clamps).
COLLISION = 1
#: What a driven part out of its motor shaft's reach counts in the layer order (it cannot be built at all).
OUT_OF_REACH = 1000 * COLLISION


def order_layers(layers: Mapping[str, int], crossings: Sequence[tuple[str, str, str]],
                 max_layers: int = 7, *, pins: Sequence[tuple[str, ...]] = (),
                 end_crossings: Sequence[tuple[int, str]] = (), pin_pairs: Sequence[tuple[int, int]] = (),
                 end_reach: Callable[[float], float] | None = None, thickness_mm: float = 1.0,
                 gap_mm: float = 0.0, spare_layers: int = 0, outer: Sequence[tuple[str, float]] = (),
                 one_end: bool = False, near_motor: Sequence[int] | None = None, split: bool = False
                 ) -> dict[str, int]:
    """Renumber the layers (keeping who shares a layer) so no body sits between the layers of a pin it
    passes over, nor where a pin's end sticks out of its stack.

    Every arrangement of the layers is tried, the identity first (so a colouring that already works is
    kept): first with no empty layer, then with up to ``spare_layers`` empty layers among them, while some
    arrangement still has a violation. The first with the fewest violations wins (fewest layers on a tie).

    A pin whose retention sticks out of its stack (a clip and its washers, or a bonded cap: ``end_reach``)
    takes the room beyond each end face at its position: a body that passes over the pin (``end_crossings``)
    may not lie there, nor may another pin near it (``pin_pairs``) reach there with its stack or its own
    ends. An empty layer gives such an end its room.

    Parameters
    ----------
    layers : Mapping[str, int]
        The colouring (:func:`assign_layers`).
    crossings : sequence of (body a, body b, body c)
        ``c`` passes over the spacer of the pin of ``a`` and ``b`` (:func:`pin_crossings`).
    max_layers : int
        No arrangement is searched beyond this many layers (nor is one of more colours reordered).
    pins : sequence of tuple of str
        Each pin's bodies (the stack runs from the lowest of their layers to the highest).
    end_crossings : sequence of (int, str)
        (pin index, body) the body passes over the pin's end (its retention hardware).
    pin_pairs : sequence of (int, int)
        Pins whose stacks or ends come near each other (:func:`pin_neighbours`).
    end_reach : callable, optional
        Stack length (mm) -> how far (mm) the pin and its retention reach beyond each end face; none: 0.
        Infinite: no standard pin covers that stack (one violation per such pin).
    thickness_mm, gap_mm : float
        Layer thickness and the gap between layers (:func:`layer_z`).
    spare_layers : int
        At most this many empty layers may be put among the bodies' layers.
    outer : sequence of (str, float)
        (body, depth mm): the body's part lies at most this deep under the stack's bottom or top face (a motor's
        short shaft reaches it from outside the stack; :data:`OUT_OF_REACH` violations if not), and at most that
        less how far the pins' ends stick out there (one violation if not: the motor meets a pin's end).
    one_end : bool
        The reach sticks out of one end of each stack only (a pressed pin's stub): the bottom where the
        stack's bottom layer is the lowest and its top layer not the highest, else the top
        (:func:`~fabricate.parts.retention.press_stub_at_bottom`, the same rule).
    near_motor : sequence of int, optional
        The pins (indices into ``pins``) within reach of the motor of ``outer``: only their ends (where they
        stick out) count against the motor's side; the motor may go under or over the stack, a violation only
        where it meets such an end on both. None: any pin's end at the stack's faces counts (the largest
        reach).
    split : bool
        Where no arrangement is free of violations, try giving one body of a shared layer a layer of its own:
        the split with the fewest violations, then the fewest layers, where it has fewer violations in no more
        layers than the best arrangement without a split (empty layers included) or one more than the colours.

    Returns
    -------
    dict[str, int]
    """
    args = (crossings, max_layers, pins, end_crossings, pin_pairs, end_reach, thickness_mm, gap_mm, spare_layers,
            outer, one_end, near_motor)
    bad, best = _best_order(layers, *args)
    if bad == 0 or not split:
        return best
    return _best_split(layers, args, bad, best)


def _best_split(layers: Mapping[str, int], args: tuple[Any, ...], bad: int, best: dict[str, int]) -> dict[str, int]:
    """No order of the colours works (``bad`` violations in ``best``): give one body of a shared layer a layer of
    its own (a legal colouring still: the conflict graph only asks for different layers), the split with the
    fewest violations, then layers, in body order; ``best`` where none does better. ``args``:
    :func:`_best_order`'s after ``layers`` (``max_layers`` second)."""
    max_layers = args[1]
    count = 1 + max(layers.values(), default=0)
    height = 1 + max(best.values(), default=0)
    key = (bad, height)
    for body in layers:
        if sum(v == layers[body] for v in layers.values()) < 2 or count + 1 > max_layers:
            continue
        bad_split, ordered = _best_order({**layers, body: count}, *args)
        # fewer violations in no more layers than the plain order takes, or the split's own one more (a taller
        # stack takes longer pins and standoff screws than the standard series has); then the fewest layers
        split_height = 1 + max(ordered.values())
        if split_height <= max(height, count + 1) and (bad_split, split_height) < key:
            key, best = (bad_split, split_height), ordered
    return best


def _best_order(layers: Mapping[str, int], crossings: Sequence[tuple[str, str, str]], max_layers: int,
                pins: Sequence[tuple[str, ...]], end_crossings: Sequence[tuple[int, str]],
                pin_pairs: Sequence[tuple[int, int]], end_reach: Callable[[float], float] | None,
                thickness_mm: float, gap_mm: float, spare_layers: int, outer: Sequence[tuple[str, float]],
                one_end: bool, near_motor: Sequence[int] | None) -> tuple[int, dict[str, int]]:
    """(violations, layers) of the best arrangement of the colours of ``layers`` (see :func:`order_layers`)."""
    count = 1 + max(layers.values(), default=0)
    ends = end_reach is not None and bool(pins) and (bool(end_crossings or pin_pairs) or near_motor is not None)
    if (not crossings and not ends and not outer) or count > max_layers:
        return 0, dict(layers)
    pitch = thickness_mm + gap_mm
    eps = 1e-6
    best: tuple[int, np.ndarray] | None = None
    for extra in range(0, spare_layers + 1 if ends else 1):
        slots = count + extra
        if slots > max_layers or math.perm(slots, count) > MAX_ARRANGEMENTS:
            break
        perms = np.array(list(itertools.permutations(range(slots), count)), dtype=np.int64).reshape(-1, count)
        if extra:  # an empty layer at the bottom or top is no arrangement of its own (one fewer layers, moved)
            perms = perms[(perms.min(axis=1) == 0) & (perms.max(axis=1) == slots - 1)]
        bad = np.zeros(len(perms), dtype=np.int64)
        reach_of = np.array([end_reach(s * pitch + thickness_mm) if end_reach is not None else 0.0
                             for s in range(slots)])
        # a stack no standard pin covers (infinite reach) is a violation of its own: its pin would be cut from rod
        unbuyable = ~np.isfinite(reach_of)
        reach_of = np.where(unbuyable, 0.0, reach_of)
        for a, b, c in crossings:
            pa, pb, pc = perms[:, layers[a]], perms[:, layers[b]], perms[:, layers[c]]
            bad += COLLISION * ((np.minimum(pa, pb) < pc) & (pc < np.maximum(pa, pb)))
        if ends:
            lo = np.stack([perms[:, [layers[b] for b in bodies]].min(axis=1) for bodies in pins], axis=1)
            hi = np.stack([perms[:, [layers[b] for b in bodies]].max(axis=1) for bodies in pins], axis=1)
            z0, z1 = lo * pitch, hi * pitch + thickness_mm
            reach = reach_of[hi - lo]
            bad += unbuyable[hi - lo].sum(axis=1)
            if one_end:  # the stub's end: the bottom where only the bottom is the outermost layer
                bottom = (lo == perms.min(axis=1)[:, None]) & (hi != perms.max(axis=1)[:, None])
                r0, r1 = np.where(bottom, reach, 0.0), np.where(bottom, 0.0, reach)
            else:
                r0 = r1 = reach
            for i, body in end_crossings:
                zc = perms[:, layers[body]] * pitch
                below = (r0[:, i] > eps) & (zc < z0[:, i]) & (zc + thickness_mm > z0[:, i] - r0[:, i] + eps)
                above = (r1[:, i] > eps) & (zc >= z1[:, i] - eps) & (zc < z1[:, i] + r1[:, i] - eps)
                bad += COLLISION * (below | above)
            for i, j in pin_pairs:
                for p, q in ((i, j), (j, i)):
                    # the ends of p against all of q (its stack and its ends)
                    q0, q1 = z0[:, q] - r0[:, q], z1[:, q] + r1[:, q]
                    hit_bottom = (r0[:, p] > eps) & (z0[:, p] - r0[:, p] < q1 - eps) & (q0 < z0[:, p] - eps)
                    hit_top = (r1[:, p] > eps) & (z1[:, p] < q1 - eps) & (q0 < z1[:, p] + r1[:, p] - eps)
                    bad += COLLISION * (hit_bottom | hit_top)
        for body, depth in outer:
            zc = perms[:, layers[body]] * pitch
            z_top = perms.max(axis=1) * pitch + thickness_mm
            top = z_top - zc - thickness_mm
            # out of the shaft's reach the design cannot be built: that outweighs any collision
            bad += OUT_OF_REACH * ((zc > depth + eps) & (top > depth + eps))
            if ends and near_motor is not None:
                # the motor (under the stack: its face depth below the driven part's near face; over it: above
                # its far face) meets the ends of the pins within its reach that stick out that far
                idx = list(near_motor)
                low = np.min(z0[:, idx] - r0[:, idx], axis=1, initial=np.inf) if idx else np.full(len(perms), np.inf)
                high = np.max(z1[:, idx] + r1[:, idx], axis=1, initial=-np.inf) if idx else np.full(len(perms),
                                                                                                    -np.inf)
                bad += COLLISION * ((low < zc - depth - eps) & (high > zc + thickness_mm + depth + eps))
            else:
                stuck_out = float(np.max(reach_of))
                bad += COLLISION * ((zc > depth - stuck_out + eps) & (top > depth - stuck_out + eps))
        k = int(np.argmin(bad))
        if best is None or int(bad[k]) < best[0]:
            best = (int(bad[k]), perms[k])
        if best[0] == 0:
            break
    assert best is not None
    return best[0], {name: int(best[1][layer]) for name, layer in layers.items()}


def layer_z(layer: int, thickness_mm: float, gap_mm: float) -> float:
    """Height (mm) of the bottom face of ``layer``."""
    return layer * (thickness_mm + gap_mm)


def stack_span(layers: Sequence[int], thickness_mm: float, gap_mm: float) -> tuple[float, float]:
    """Bottom and top z (mm) of the stack from the lowest to the highest of ``layers``."""
    lo, hi = min(layers), max(layers)
    return layer_z(lo, thickness_mm, gap_mm), layer_z(hi, thickness_mm, gap_mm) + thickness_mm


def skipped_gap(lower: int, upper: int, thickness_mm: float, gap_mm: float) -> float:
    """Axial length (mm) between the top of ``lower`` and the bottom of ``upper`` (a spacer's length)."""
    return max(0.0, layer_z(upper, thickness_mm, gap_mm) - layer_z(lower, thickness_mm, gap_mm) - thickness_mm)

