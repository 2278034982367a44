"""Edits of a :class:`~fabricate.parts.partset.PartSet` the actuator makes: a part's copy with changes, a pad
fused on, the part of a body, the BOM without a replaced pin's hardware.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import shapely
import shapely.ops

from fabricate.errors import SpecError
from fabricate.parts.model import BulgePath, Part
from fabricate.parts.partset import PartSet, SlottedPart
from fabricate.parts.profiles import fuse_polygons

if TYPE_CHECKING:
    from fabricate.process import ProcessSpec


def with_changes(part: Part, **changes: Any) -> Part:
    """A copy of ``part`` with ``changes``; ``slots`` turns a plain part into a slotted one."""
    if "slots" in changes and not isinstance(part, SlottedPart):
        base = {f.name: getattr(part, f.name) for f in dataclasses.fields(Part)}
        base.update(changes)
        return SlottedPart(**base)
    return dataclasses.replace(part, **changes)


#: The fused outline's chords lie inside its arcs by at most the chord tolerance / this: walls measured on it
#: (the printability check) lose next to nothing against the exact outline.
FUSE_REFINE = 10.0


def fuse_pad(outline: BulgePath, pad: BulgePath, tol: float) -> BulgePath:
    """The outline with a pad fused on (kept exact when the pad lies inside already)."""
    fine = tol / FUSE_REFINE
    inside = shapely.Polygon(outline.polygon(tol)).buffer(1e-9).contains(shapely.Polygon(pad.polygon(tol)))
    return outline if inside else fuse_polygons(outline, [pad.polygon(fine)], fine)


def body_part(partset: PartSet, body: str) -> Part:
    for p in partset.parts:
        if p.body == body and p.role not in ("spacer", "mount", "standoff"):
            return p
    raise SpecError("actuator.driver", f"body {body!r} has no part")


def bom_without(bom: Sequence[dict[str, Any]], pin: Any, spacers: Sequence[Any], removed_parts: set[str],
                 changed: Sequence[Part], process: ProcessSpec, copies: int) -> list[dict[str, Any]]:
    """The BOM without one pin's hardware (the rows the parts layer makes for it and its ``spacers``, taken
    out of the grouped rows by item) and the removed parts, with the changed parts' rows renewed."""
    from fabricate.hints import PartHints
    from fabricate.parts.bom import bill_of_materials, part_rows

    fresh = {row["item"]: row for row in part_rows(list(changed), process, copies)}
    gone: dict[tuple[str, str], int] = {}
    if pin is not None:
        for row in bill_of_materials([pin], list(spacers), PartHints(), process, copies):
            key = (str(row["item"]), str(row["kind"]))
            gone[key] = gone.get(key, 0) + int(row["qty"])
    out = []
    for row in bom:
        item = str(row.get("item", ""))
        if item in removed_parts:
            continue
        if item in fresh:
            out.append(dict(fresh[item], **{k: v for k, v in row.items() if k not in fresh[item]}))
            continue
        key = (item, str(row.get("kind", "")))
        if key in gone:
            take = min(gone.pop(key), int(row.get("qty", 0)))
            joints = [j for j in row.get("joints", []) or [] if j != pin.joint]
            row = dict(row, qty=int(row["qty"]) - take, joints=joints)
            if row["qty"] <= 0:
                continue
        out.append(row)
    return out
