"""Gears seated on the bodies that carry them: a gear's outline in its body's coordinates, and how close the
mating gear comes to each gear axis over the motion (the room a boss or hub round that axis has)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import shapely

from fabricate.mechanism import Mechanism, Motion
from fabricate.planar import rotation

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair


def gear_outline_in_body(mechanism: Mechanism, pair: GearPair, side: str) -> tuple[str, str, np.ndarray]:
    """A gear outline mapped into the coordinates of the body that carries it.

    Parameters
    ----------
    pair : GearPair
        Needs ``name``, ``body_a``, ``body_b``, ``axis_a``, ``axis_b``, ``outline_a``, ``outline_b``.
    side : str
        ``"a"`` or ``"b"``.

    Returns
    -------
    (body, axis joint, (n, 2) array)
        u = u_axis + R(beta) g, beta = direction of JB - JA in the carrier (gear-frame convention).
    """
    coupling = next((g for g in mechanism.gears if g.name == pair.name), None)
    carrier = mechanism.body(coupling.carrier) if coupling is not None else None
    ja, jb = pair.axis_a, pair.axis_b
    if carrier is not None and ja in carrier.points and jb in carrier.points:
        d = carrier.point(jb) - carrier.point(ja)
    else:  # no carrier record: the line of centres as seen in body a
        d = mechanism.body(pair.body_a).point(jb) - mechanism.body(pair.body_a).point(ja)
    beta = math.atan2(d[1], d[0])
    body = pair.body_a if side == "a" else pair.body_b
    axis = ja if side == "a" else jb
    outline = np.asarray(pair.outline_a if side == "a" else pair.outline_b, dtype=np.float64)
    u_axis = mechanism.body(body).point(axis)
    return body, axis, outline @ rotation(beta).T + u_axis


def mesh_limits(mechanism: Mechanism, motion: Motion, gear_pairs: Sequence[GearPair],
                 clearance: float) -> dict[tuple[str, str], float]:
    """The largest radius a boss or hub round each gear's axis may have: ``clearance`` short of the nearest
    the mating gear comes to the axis over the motion (its tips, reaching down to this gear's root).

    Returns
    -------
    dict
        (body, axis joint) -> radius, mm.
    """
    out: dict[tuple[str, str], float] = {}
    for pair in gear_pairs:
        for side, other in (("a", "b"), ("b", "a")):
            body, axis, _ = gear_outline_in_body(mechanism, pair, side)
            mate, _, ring = gear_outline_in_body(mechanism, pair, other)
            centre = mechanism.body(body).point(axis)
            own, theirs = motion.pose(body), motion.pose(mate)
            world = np.einsum("nij,vj->nvi", rotation(theirs[:, 2]), ring) + theirs[:, None, :2]
            local = np.einsum("nji,nvj->nvi", rotation(own[:, 2]), world - own[:, None, :2])
            reach = float(np.min(shapely.distance(shapely.polygons(local), shapely.Point(*centre))))
            key = (body, axis)
            out[key] = min(out.get(key, math.inf), reach - clearance)
    return out
