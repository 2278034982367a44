"""What a synthesis method tells the parts layer beyond the mechanism: :class:`PartHints`.

A method knows things the mechanism does not: which body carries the fingertip pad, which joints hold a
return spring, what must be bought (an actuator, rods, a shared drive), how many identical copies make the
device. It hands them over as one frozen :class:`PartHints` (``SynthesisResult.parts``); the parts stage
(pads, BOM rows, copies, link width), the strength check (tip point, springs as loads) and the previews
(tip path) read its fields. ``mechanism.toml`` writes it as ``[linkage.hints]`` (:meth:`PartHints.as_table`)
and the exact form of kind ``linkage`` reads it back (:func:`fabricate.synthesis.linkage.exact.read_hints`).

Every field is optional. The defaults mean "not given": a field left at its default is not written to
``mechanism.toml``, so a rebuilt mechanism writes the same file byte for byte.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any


@dataclass(frozen=True)
class PadHint:
    """A fingertip pad fused to a body.

    Attributes
    ----------
    point : str
        The body's point the pad is centred on.
    radius_mm : float or None
        Pad radius; None: the boss radius (``[parts] pad_radius_mm`` overrides both).
    arc : (str, str) or None
        On a curved face: the two named points on the pad's circle between which the circular segment is
        fused (the fingertip arc of the compliant gripper); None: a whole disc.
    """

    point: str
    radius_mm: float | None = None
    arc: tuple[str, str] | None = None


@dataclass(frozen=True)
class SpringHint:
    """A torsion spring at a revolute joint: a BOM row, and a load of the strength check.

    Attributes
    ----------
    joint : str
        The joint it acts at.
    rate_Nmm_per_deg : float
        Rate; 0 means no spring there (the compliant optimum may set k1 = 0): no BOM row, no load.
    preload_deg : float
        Deflection at the first pose.
    legs_mm : float or None
        Leg length, for the BOM.
    note : str
        What it is for, for people (the BOM description).
    """

    joint: str
    rate_Nmm_per_deg: float
    preload_deg: float = 0.0
    legs_mm: float | None = None
    note: str = ""


@dataclass(frozen=True)
class PurchasedItem:
    """A bought item the method needs (motor, actuator, rod, knob): a BOM row.

    Attributes
    ----------
    item : str
        What to buy.
    qty : int
        How many (per copy, or in all for :attr:`PartHints.purchased_shared`).
    note : str
        What it is for (the BOM description).
    """

    item: str
    qty: int = 1
    note: str = ""


@dataclass(frozen=True)
class PartHints:
    """The synthesis' hints for the parts layer (``SynthesisResult.parts``).

    The field order is the order ``mechanism.toml`` writes them in.

    Attributes
    ----------
    springs : tuple of SpringHint
        Torsion springs (BOM rows; loads of the strength check when ``[load] springs`` is on).
    purchased : tuple of PurchasedItem
        Bought items of one copy; the BOM multiplies them by the copies.
    purchased_shared : tuple of PurchasedItem
        Bought items shared by all copies (one drive for a three-finger gripper): not multiplied.
    copies : int or None
        Identical copies of the mechanism; BOM quantities are multiplied (None: one).
    copy_angle_deg : float or None
        Angle between neighbouring copies (informs; nothing is placed by it).
    tip_point : str or None
        The fingertip point: the path the previews draw and the strength check's default load point.
    link_width_mm : float or None
        Preferred plate width of links (``[parts] link_width_mm`` overrides it).
    pads : Mapping[str, PadHint] or None
        Fingertip pads by body name. None: the method has no pads table; an empty mapping is a table with
        no pad (the linkage kind's), which ``mechanism.toml`` writes as an empty ``[linkage.hints.pads]``.
    """

    springs: tuple[SpringHint, ...] = ()
    purchased: tuple[PurchasedItem, ...] = ()
    purchased_shared: tuple[PurchasedItem, ...] = ()
    copies: int | None = None
    copy_angle_deg: float | None = None
    tip_point: str | None = None
    link_width_mm: float | None = None
    pads: Mapping[str, PadHint] | None = None

    def as_table(self) -> dict[str, Any]:
        """The hints as a TOML table (``[linkage.hints]`` of ``mechanism.toml``): fields at their default
        (None, no items) left out, tuples as lists, in field order."""
        table: dict[str, Any] = {}
        for key in ("springs", "purchased", "purchased_shared"):
            items = getattr(self, key)
            if items:
                table[key] = [_plain(item) for item in items]
        for key in ("copies", "copy_angle_deg", "tip_point", "link_width_mm"):
            if getattr(self, key) is not None:
                table[key] = getattr(self, key)
        if self.pads is not None:
            table["pads"] = {body: _plain(pad) for body, pad in self.pads.items()}
        return table


def _plain(item: PadHint | SpringHint | PurchasedItem) -> dict[str, Any]:
    """One item's fields as a TOML table, in field order: None left out, tuples as lists."""
    values = ((f.name, getattr(item, f.name)) for f in fields(item))
    return {k: list(v) if isinstance(v, tuple) else v for k, v in values if v is not None}
