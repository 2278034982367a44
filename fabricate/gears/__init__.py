"""Non-circular gear pairs: ratio law -> pitch curves -> rack-cut teeth -> checks and mesh check.

Public entry points: :func:`build_gear_pairs` (one pair per gear coupling of a mechanism),
:func:`make_gear_pair` (one law), :func:`mesh_check`, and the :class:`GearPair` they return.
"""

from __future__ import annotations

from fabricate.gears.build import build_gear_pairs, make_gear_pair
from fabricate.gears.mesh import mesh_check
from fabricate.gears.pair import GearPair, MeshResult
from fabricate.gears.spec import GearSpec, parse_gear_spec

__all__ = ["GearPair", "GearSpec", "MeshResult", "build_gear_pairs", "make_gear_pair", "mesh_check",
           "parse_gear_spec"]
