"""Layer assignment: bodies that come near each other anywhere over the motion go to different layers.

The conflict test works in the plan view: for every pair of bodies the outline of one is moved into the
frame of the other at every sampled pose (the relative swept plan view) and the smallest distance between
the two outlines is compared with the clearance. Bodies joined by a pin always conflict (their bosses
share the pin). Bodies carrying meshing gears are merged into one group first (their teeth must lie in
one plane) and the groups are coloured greedily (DSATUR, ties broken by body order so it is
deterministic).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

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


def order_layers(layers: Mapping[str, int], crossings: Sequence[tuple[str, str, str]],
                 max_layers: int = 7) -> dict[str, int]:
    """Renumber the layers (keeping who shares a layer) so no body sits between the layers of a pin it
    passes over.

    Every permutation of up to ``max_layers`` layers is tried; the first with the fewest violations wins
    (the identity first, so a colouring that already works is kept).
    """
    count = 1 + max(layers.values(), default=0)
    if not crossings or count > max_layers:
        return dict(layers)

    def violations(perm: tuple[int, ...]) -> int:
        bad = 0
        for a, b, c in crossings:
            lo, hi = sorted((perm[layers[a]], perm[layers[b]]))
            bad += lo < perm[layers[c]] < hi
        return bad

    best = min(itertools.permutations(range(count)), key=violations)
    return {name: best[layer] for name, layer in layers.items()}


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

