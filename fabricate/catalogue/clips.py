"""Retaining washers (E-clips, DIN 6799) and the grooved pin they hold at both faces of a stack.

Every number below is a value of DIN 6799's table as a maker reproduces it, named in the comment beside it.

Sources
-------
BENERI_6799
    Beneri S.p.A., product page "DIN 6799 Retaining rings for shafts", size table
    (http://beneri.com/en/prodotto/din-6799): groove width m and edge margin n, besides d2, d3, s.
"""

from __future__ import annotations

from dataclasses import dataclass

from fabricate.catalogue.pins import PinChoice, dowel_pin
from fabricate.catalogue.tables import EPS, FASTENERS_WB, finite_positive
from fabricate.errors import SpecError

BENERI_6799 = "Beneri DIN 6799 size table (http://beneri.com/en/prodotto/din-6799)"


# ---------------------------------------------------------------------------------------------------------
# Retaining washers (E-clips) DIN 6799
# ---------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RetainingRing:
    """A DIN 6799 retaining washer and the groove it needs (mm).

    ``protrusion_mm`` is the pin length needed beyond the face the ring holds: the groove width ``m``
    plus the least edge margin ``n`` between the groove and the pin's end.
    """

    designation: str
    shaft_min_mm: float
    shaft_max_mm: float
    groove_d_mm: float
    groove_w_mm: float
    ring_s_mm: float
    ring_od_mm: float
    edge_margin_mm: float
    source: str

    @property
    def protrusion_mm(self) -> float:
        return self.groove_w_mm + self.edge_margin_mm


#: DIN 6799 rows: groove d2 -> (shaft d1 over, d1 up to, ring d3 max, ring s, groove width m, edge margin n).
#: Beneri size table (d2, d3, s, d1 min, d1 max, m, n); d2, d3, s, d1 range also FsData/din6799def.csv.
DIN6799: dict[float, tuple[float, float, float, float, float, float]] = {
    1.2: (1.4, 2.0, 3.25, 0.30, 0.34, 0.6),  # Beneri row 1,2: d3 3,25 s 0,30 d1 1,4-2,0 m 0,34 n 0,6
    1.5: (2.0, 2.5, 4.25, 0.40, 0.44, 0.8),  # Beneri row 1,5: d3 4,25 s 0,40 d1 2,0-2,5 m 0,44 n 0,8
    1.9: (2.5, 3.0, 4.80, 0.50, 0.54, 1.0),  # Beneri row 1,9: d3 4,80 s 0,50 d1 2,5-3,0 m 0,54 n 1,0
    2.3: (3.0, 4.0, 6.30, 0.60, 0.64, 1.0),  # Beneri row 2,3: d3 6,30 s 0,60 d1 3,0-4,0 m 0,64 n 1,0
    3.2: (4.0, 5.0, 7.30, 0.60, 0.64, 1.0),  # Beneri row 3,2: d3 7,30 s 0,60 d1 4,0-5,0 m 0,64 n 1,0
    4.0: (5.0, 7.0, 9.30, 0.70, 0.74, 1.2),  # Beneri row 4: d3 9,30 s 0,70 d1 5,0-7,0 m 0,74 n 1,2
    5.0: (6.0, 8.0, 11.30, 0.70, 0.74, 1.2),  # Beneri row 5: d3 11,30 s 0,70 d1 6,0-8,0 m 0,74 n 1,2
    6.0: (7.0, 9.0, 12.30, 0.70, 0.74, 1.2),  # Beneri row 6: d3 12,30 s 0,70 d1 7,0-9,0 m 0,74 n 1,2
}
DIN6799_SOURCE = f"DIN 6799: {BENERI_6799}; cross-checked against {FASTENERS_WB}, din6799def.csv"


def e_clip_row(groove: float) -> RetainingRing:
    """The DIN 6799 ring of groove diameter ``groove`` (a key of :data:`DIN6799`)."""
    lo, hi, od, s, m, n = DIN6799[groove]
    return RetainingRing(f"DIN 6799 {groove:g}", lo, hi, groove, m, s, od, n, DIN6799_SOURCE)


def e_clip(shaft_mm: float) -> RetainingRing:
    """The DIN 6799 retaining washer for a pin of ``shaft_mm``.

    The table gives each ring a shaft range d1 whose ends touch the next ring's; a shaft on a boundary
    takes the ring whose range it closes (read "over d1 min up to d1 max", as the table's ranges join),
    so a Ø2 pin takes the 1.2 groove. A groove cannot be cut into a hardened ISO 8734 pin by hand:
    grooved pins are ISO 2338 (unhardened) or bought grooved.

    Raises
    ------
    SpecError
        No DIN 6799 ring covers ``shaft_mm``.
    """
    d = finite_positive("shaft_mm", shaft_mm)
    for groove, (lo, hi, *_) in sorted(DIN6799.items()):
        if lo + EPS < d <= hi + EPS:
            return e_clip_row(groove)
    raise SpecError("shaft_mm", f"no DIN 6799 retaining washer in the catalogue for a Ø{d:g} mm shaft "
                    f"(shafts over {min(v[0] for v in DIN6799.values()):g} up to "
                    f"{max(v[1] for v in DIN6799.values()):g} mm)")


@dataclass(frozen=True)
class GroovedPin:
    """A pin held by DIN 6799 E-clips at both faces of its stack: an unhardened ISO 2338 pin (a groove can
    be cut into it) of the standard length, the clip, and where the grooves go.

    The stack sits centred on the pin; each groove's near edge is at a face of the stack (the clip bears on
    it), so the groove centres are ``groove_from_end_mm`` from each end, and each end keeps at least the
    clip's edge margin ``n`` beyond its groove.
    """

    pin: PinChoice
    clip: RetainingRing
    stack_mm: float

    @property
    def designation(self) -> str:
        return self.pin.designation

    @property
    def groove_from_end_mm(self) -> float:
        return (self.pin.length_mm - self.stack_mm) / 2.0 - self.clip.groove_w_mm / 2.0


def grooved_pin(diameter_mm: float, stack_mm: float) -> GroovedPin:
    """The shortest ISO 2338 pin of ``diameter_mm`` that takes a DIN 6799 clip at each face of a
    ``stack_mm`` stack (length >= stack + 2 × the clip's protrusion)."""
    d = finite_positive("diameter_mm", diameter_mm)
    stack = finite_positive("stack_mm", stack_mm)
    clip = e_clip(d)
    pin = dowel_pin(d, stack + 2.0 * clip.protrusion_mm, "ISO 2338")
    return GroovedPin(pin, clip, stack)
