"""Hand-made parts for the interference and checks tests (no parts layer, no synthesis).

Binary links are rounded slots (two semicircle ends, bulge 1) with a pin hole at each joint, in the
link's body frame (first joint at the origin, second on +x), as in ``tests/conftest.make_four_bar``.
"""

from __future__ import annotations

import numpy as np

from fabricate.mechanism import Mechanism
from fabricate.parts.model import BulgePath, Hole, Part


def slot_outline(length: float, width: float) -> BulgePath:
    """A rounded slot from (0, 0) to (length, 0), semicircle ends of radius width / 2; CCW."""
    h = width / 2.0
    vertices = np.array([[0.0, -h], [length, -h], [length, h], [0.0, h]])
    return BulgePath(vertices, np.array([0.0, 1.0, 0.0, 1.0]))


def slot_part(name: str, body: str, joints: tuple[str, str], length: float, *, width: float = 6.0,
              pin: float = 2.0, clearance: float = 0.25, thickness: float = 3.0, z: float = 0.0,
              layer: int = 0, process: str = "sla") -> Part:
    """A binary link part with a hole of ``pin + 2 * clearance`` at each end."""
    holes = (Hole(joints[0], np.array([0.0, 0.0]), pin + 2.0 * clearance, pin),
             Hole(joints[1], np.array([length, 0.0]), pin + 2.0 * clearance, pin))
    return Part(name, body, slot_outline(length, width), holes, thickness, z, layer, process)


def four_bar_parts(mech: Mechanism, *, layers: dict[str, int] | None = None, thickness: float = 3.0,
                   gap: float = 0.3, width: float = 6.0, clearance: float = 0.25) -> list[Part]:
    """One slot part per body of :func:`tests.conftest.make_four_bar`, stacked on ``layers``
    (default ground 0, crank 1, rocker 1, coupler 2: the crank and the rocker never meet)."""
    layers = layers or {"ground": 0, "crank": 1, "rocker": 1, "coupler": 2}
    parts = []
    for body in mech.bodies:
        names = list(body.points)
        length = float(np.hypot(*body.point(names[1])))
        layer = layers[body.name]
        parts.append(slot_part(body.name, body.name, (names[0], names[1]), length, width=width,
                               clearance=clearance, thickness=thickness, z=layer * (thickness + gap),
                               layer=layer))
    return parts
