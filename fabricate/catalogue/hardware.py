"""Standard hardware from standard series: dowel pins, washers, shim rings, screws, E-clips.

Every number below is a value of a standard's table, taken from a public reproduction named in the
comment beside it (the standards themselves are sold, not published). Where no source was found for a
size or a series, the size is left out and the function that would need it raises :class:`SpecError`
naming the field: the catalogue never guesses a dimension.

The functions are pure: they pick a size from the tables, they place nothing.

Sources
-------
FASTENERS_WB
    shaise/FreeCAD_FastenersWB, folder ``FsData`` (https://github.com/shaise/FreeCAD_FastenersWB): the
    FreeCAD Fasteners workbench's transcriptions of the ISO/DIN tables, file named per value.
BENERI_6799
    Beneri S.p.A., product page "DIN 6799 Retaining rings for shafts", size table
    (http://beneri.com/en/prodotto/din-6799): groove width m and edge margin n, besides d2, d3, s.
KB3D_SHIMS
    KB-3D retail listings of DIN 988 shim rings (named in the comment of each size).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from fabricate.errors import SpecError

FASTENERS_WB = "shaise/FreeCAD_FastenersWB FsData (https://github.com/shaise/FreeCAD_FastenersWB)"
BENERI_6799 = "Beneri DIN 6799 size table (http://beneri.com/en/prodotto/din-6799)"

_EPS = 1e-9


def _finite_positive(path: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpecError(path, f"expected a number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise SpecError(path, f"expected a positive finite number, got {value!r}")
    return v


def _key(d: float) -> float:
    """Diameters as table keys (1.5 and 1.50000001 are the same pin)."""
    return round(float(d), 3)


# ---------------------------------------------------------------------------------------------------------
# Dowel pins: ISO 8734 (hardened) and ISO 2338 (unhardened, m6/h8)
# ---------------------------------------------------------------------------------------------------------

#: ISO 8734 nominal lengths l (mm). FsData/iso8734length.csv ("ISO8734length", column "nominal").
ISO8734_LENGTHS_MM: tuple[float, ...] = (
    3, 4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 32, 35, 40, 45, 50,  # iso8734length.csv
    55, 60, 65, 70, 75, 80, 85, 90, 95, 100)  # iso8734length.csv
#: ISO 8734 commercial length range (min, max) per nominal diameter d. FsData/iso8734range.csv.
ISO8734_RANGE_MM: dict[float, tuple[float, float]] = {
    1.0: (3, 10),  # iso8734range.csv "1 mm",3,10
    1.5: (4, 16),  # iso8734range.csv "1.5 mm",4,16
    2.0: (5, 20),  # iso8734range.csv "2 mm",5,20
    2.5: (6, 24),  # iso8734range.csv "2.5 mm",6,24
    3.0: (8, 30),  # iso8734range.csv "3 mm",8,30
    4.0: (10, 40),  # iso8734range.csv "4 mm",10,40
    5.0: (12, 50),  # iso8734range.csv "5 mm",12,50
    6.0: (14, 60),  # iso8734range.csv "6 mm",14,60
    8.0: (18, 80),  # iso8734range.csv "8 mm",18,80
    10.0: (22, 100),  # iso8734range.csv "10 mm",22,100
}
#: ISO 2338 nominal lengths l (mm). FsData/iso2338length.csv ("ISO2338length", column "nom").
ISO2338_LENGTHS_MM: tuple[float, ...] = (
    2, 3, 4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 32, 35, 40, 45, 50,  # iso2338length.csv
    55, 60, 65, 70, 75, 80, 85, 90, 95, 100, 120, 140, 160, 180, 200)  # iso2338length.csv
#: ISO 2338 commercial length range (min, max) per nominal diameter d. FsData/iso2338range.csv.
ISO2338_RANGE_MM: dict[float, tuple[float, float]] = {
    1.0: (4, 10),  # iso2338range.csv "1 mm",4,10
    1.5: (4, 16),  # iso2338range.csv "1.5 mm",4,16
    2.0: (6, 20),  # iso2338range.csv "2 mm",6,20
    2.5: (6, 24),  # iso2338range.csv "2.5 mm",6,24
    3.0: (8, 30),  # iso2338range.csv "3 mm",8,30
    4.0: (8, 40),  # iso2338range.csv "4 mm",8,40
    5.0: (10, 50),  # iso2338range.csv "5 mm",10,50
    6.0: (12, 60),  # iso2338range.csv "6 mm",12,60
    8.0: (14, 80),  # iso2338range.csv "8 mm",14,80
    10.0: (18, 95),  # iso2338range.csv "10 mm",18,95
}

PIN_SERIES: dict[str, tuple[tuple[float, ...], dict[float, tuple[float, float]], str]] = {
    "ISO 8734": (ISO8734_LENGTHS_MM, ISO8734_RANGE_MM,
                 f"ISO 8734 length series and ranges: {FASTENERS_WB}, iso8734length.csv, iso8734range.csv"),
    "ISO 2338": (ISO2338_LENGTHS_MM, ISO2338_RANGE_MM,
                 f"ISO 2338 length series and ranges: {FASTENERS_WB}, iso2338length.csv, iso2338range.csv"),
}


class PinChoice(NamedTuple):
    """A dowel pin as a shop names it (``"ISO 8734 2 × 20"``) and its length (mm)."""

    designation: str
    length_mm: float


def pin_lengths(diameter_mm: float, standard: str = "ISO 8734") -> tuple[float, ...]:
    """The standard lengths (mm) of a ``standard`` pin of ``diameter_mm``, shortest first."""
    if standard not in PIN_SERIES:
        raise SpecError("standard", f"expected one of {sorted(PIN_SERIES)}, got {standard!r}")
    lengths, ranges, _ = PIN_SERIES[standard]
    d = _finite_positive("diameter_mm", diameter_mm)
    if _key(d) not in ranges:
        raise SpecError("diameter_mm", f"no {standard} pin of Ø{d:g} mm; the series has "
                        f"{', '.join(f'{k:g}' for k in sorted(ranges))} mm")
    lo, hi = ranges[_key(d)]
    return tuple(float(v) for v in lengths if lo - _EPS <= v <= hi + _EPS)


def dowel_pin(diameter_mm: float, min_length_mm: float, standard: str = "ISO 8734") -> PinChoice:
    """The shortest standard pin of ``diameter_mm`` at least ``min_length_mm`` long.

    Parameters
    ----------
    diameter_mm : float
        Nominal pin diameter; must be a diameter of the series.
    min_length_mm : float
        The length the stack and its retention need.
    standard : {"ISO 8734", "ISO 2338"}
        ISO 8734 is the hardened pin a shop stocks as "dowel pin"; ISO 2338 the unhardened one (the one
        a groove for an E-clip can be cut into).

    Returns
    -------
    PinChoice
        ``("ISO 8734 2 × 20", 20.0)``.

    Raises
    ------
    SpecError
        ``diameter_mm`` not in the series, or ``min_length_mm`` above the longest length of the diameter.
    """
    need = _finite_positive("min_length_mm", min_length_mm)
    lengths = pin_lengths(diameter_mm, standard)
    for length in lengths:
        if length >= need - _EPS:
            return PinChoice(f"{standard} {float(diameter_mm):g} × {length:g}", length)
    raise SpecError("min_length_mm", f"{need:g} mm is longer than the longest {standard} Ø{float(diameter_mm):g} "
                    f"pin ({lengths[-1]:g} mm)")


# ---------------------------------------------------------------------------------------------------------
# Washers: ISO 7089 (= DIN 125-A), and DIN 988 shim rings
# ---------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Washer:
    """A flat washer or shim ring: bore ``d1``, outside ``d2``, thickness ``h`` (mm)."""

    designation: str
    d1_mm: float
    d2_mm: float
    h_mm: float
    source: str


#: ISO 7089 normal series (d1 min, d2 max, h nominal), mm. FsData/iso7089def.csv columns d1_min, d2_max, h.
ISO7089: dict[str, tuple[float, float, float]] = {
    "M1.6": (1.7, 4.0, 0.3),  # iso7089def.csv "M1.6",1.7,4.0,0.3
    "M2": (2.2, 5.0, 0.3),  # iso7089def.csv "M2",2.2,5.0,0.3
    "M2.5": (2.7, 6.0, 0.5),  # iso7089def.csv "M2.5",2.7,6.0,0.5
    "M3": (3.2, 7.0, 0.5),  # iso7089def.csv "M3",3.2,7.0,0.5
    "M4": (4.3, 9.0, 0.8),  # iso7089def.csv "M4",4.3,9.0,0.8
    "M5": (5.3, 10.0, 1.0),  # iso7089def.csv "M5",5.3,10.0,1.0
    "M6": (6.4, 12.0, 1.6),  # iso7089def.csv "M6",6.4,12.0,1.6
}
ISO7089_SOURCE = (f"ISO 7089 / DIN 125-A: {FASTENERS_WB}, iso7089def.csv (M3..M6 also engineeringhardware.com "
                  "ISO 7089 size table, https://engineeringhardware.com/guide/standard/iso-7089-cad-svg-086-washer/)")


def washer(size: str) -> Washer:
    """The ISO 7089 (DIN 125-A) washer of thread ``size`` (``"M3"``)."""
    if size not in ISO7089:
        raise SpecError("size", f"no ISO 7089 washer for {size!r}; sizes {', '.join(ISO7089)}")
    d1, d2, h = ISO7089[size]
    return Washer(f"ISO 7089 {size} (DIN 125-A {d1:g})", d1, d2, h, ISO7089_SOURCE)


def washer_for_shaft(diameter_mm: float) -> Washer:
    """The smallest ISO 7089 washer whose bore clears a pin or shaft of ``diameter_mm``."""
    d = _finite_positive("diameter_mm", diameter_mm)
    for size, (d1, _, _) in sorted(ISO7089.items(), key=lambda kv: kv[1][0]):
        if d1 >= d - _EPS:
            return washer(size)
    raise SpecError("diameter_mm", f"no ISO 7089 washer in the catalogue clears Ø{d:g} mm")


#: DIN 988 shim rings (d1, d2) -> thicknesses h, mm. Only the sizes a retail listing was found for: the
#: standard's full table (and its thickness series) was not found in a public reproduction.
DIN988: dict[tuple[float, float], tuple[tuple[float, ...], str]] = {
    (3.0, 6.0): ((0.5,),  # KB-3D "3x6x0.5mm Shim Ring Washer (DIN988)", pack of 50
                 "KB-3D listing https://kb-3d.com/store/inserts-fasteners-adhesives/"
                 "287-3x6x05mm-shim-ring-washer-pack-of-50-din988-1634423217623.html"),
    (5.0, 10.0): ((1.0,),  # KB-3D "5x10x1mm Shim Ring Washer (DIN988)", pack of 50
                  "KB-3D listing https://kb-3d.com/store/inserts-fasteners-adhesives/"
                  "288-5x10x1mm-shim-ring-washer-pack-of-50-din988-1634423113147.html"),
}


def shim_ring(shaft_mm: float, thickness_mm: float) -> Washer:
    """The DIN 988 shim ring of bore ``shaft_mm`` and thickness ``thickness_mm``.

    Raises
    ------
    SpecError
        No catalogued DIN 988 ring of that bore (``shaft_mm``) or thickness (``thickness_mm``).
    """
    d = _finite_positive("shaft_mm", shaft_mm)
    t = _finite_positive("thickness_mm", thickness_mm)
    rows = [(dd, row) for dd, row in DIN988.items() if abs(dd[0] - d) < 1e-6]
    if not rows:
        raise SpecError("shaft_mm", f"no DIN 988 shim ring of bore {d:g} mm in the catalogue "
                        f"(bores {', '.join(f'{k[0]:g}' for k in DIN988)})")
    (d1, d2), (thicknesses, source) = rows[0]
    if not any(abs(h - t) < 1e-6 for h in thicknesses):
        raise SpecError("thickness_mm", f"no {d1:g} × {d2:g} DIN 988 ring {t:g} mm thick in the catalogue "
                        f"(thicknesses {', '.join(f'{h:g}' for h in thicknesses)})")
    return Washer(f"DIN 988 {d1:g} × {d2:g} × {t:g}", d1, d2, t, source)


# ---------------------------------------------------------------------------------------------------------
# Screws: ISO 4762 socket head cap screws, ISO 7380-1 button head screws
# ---------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ScrewSize:
    """One row of a screw standard (mm): head diameter ``dk`` and height ``k``, reference thread length
    ``b`` and the commercial length range."""

    standard: str
    size: str
    head_d_mm: float
    head_h_mm: float
    thread_b_mm: float
    min_length_mm: float
    max_length_mm: float


#: ISO 4762 (dk, k, b) and length range (min, max). FsData/iso4762def.csv: columns dk_max, k, b of
#: "ISO4762def", and "ISO4762range" (the same file).
ISO4762: dict[str, ScrewSize] = {
    "M2": ScrewSize("ISO 4762", "M2", 3.8, 2.0, 16.0, 3, 20),  # iso4762def.csv M2: dk 3.8 k 2.0 b 16; range 3-20
    "M2.5": ScrewSize("ISO 4762", "M2.5", 4.5, 2.5, 17.0, 4, 25),  # M2.5: dk 4.5 k 2.5 b 17; range 4-25
    "M3": ScrewSize("ISO 4762", "M3", 5.5, 3.0, 18.0, 5, 30),  # M3: dk 5.5 k 3.0 b 18; range 5-30
    "M4": ScrewSize("ISO 4762", "M4", 7.0, 4.0, 20.0, 6, 40),  # M4: dk 7.0 k 4.0 b 20; range 6-40
    "M5": ScrewSize("ISO 4762", "M5", 8.5, 5.0, 22.0, 8, 50),  # M5: dk 8.5 k 5.0 b 22; range 8-50
    "M6": ScrewSize("ISO 4762", "M6", 10.0, 6.0, 24.0, 8, 60),  # M6: dk 10.0 k 6.0 b 24; range 8-60
}
#: ISO 4762 nominal lengths (mm). FsData/iso4762def.csv "ISO4762length", column "Nominal" (to 80 mm).
ISO4762_LENGTHS_MM: tuple[float, ...] = (
    2.5, 3, 4, 5, 6, 8, 10, 12, 14, 16, 20, 25, 30, 35, 40,  # iso4762def.csv ISO4762length "Nominal"
    45, 50, 55, 60, 65, 70, 75, 80)  # iso4762def.csv ISO4762length "Nominal"
#: ISO 7380-1 (dk, k, b) and range. FsData/iso7380def.csv: "ISO7380-1def" dk, k, b and "ISO7380-1range".
#: ISO 7380-1 covers M3..M16 only (westfieldfasteners.co.uk ISO 7380-1 guide: "M2.5 ... not covered").
ISO7380: dict[str, ScrewSize] = {
    "M3": ScrewSize("ISO 7380-1", "M3", 5.7, 1.65, 18.0, 6, 30),  # iso7380def.csv M3: dk 5.7 k 1.65 b 18; 6-30
    "M4": ScrewSize("ISO 7380-1", "M4", 7.6, 2.2, 20.0, 6, 40),  # M4: dk 7.6 k 2.2 b 20; range 6-40
    "M5": ScrewSize("ISO 7380-1", "M5", 9.5, 2.75, 22.0, 8, 50),  # M5: dk 9.5 k 2.75 b 22; range 8-50
    "M6": ScrewSize("ISO 7380-1", "M6", 10.5, 3.3, 24.0, 10, 60),  # M6: dk 10.5 k 3.3 b 24; range 10-60
}
#: ISO 7380 nominal lengths (mm). FsData/iso7380def.csv "ISO7380-1length", column "Nominal".
ISO7380_LENGTHS_MM: tuple[float, ...] = (
    4, 5, 6, 8, 10, 12, 14, 16, 20, 25, 30, 35, 40,  # iso7380def.csv ISO7380-1length "Nominal"
    45, 50, 55, 60, 65, 70, 80, 90)  # iso7380def.csv ISO7380-1length "Nominal"

SCREW_SERIES: dict[str, tuple[dict[str, ScrewSize], tuple[float, ...], str]] = {
    "ISO 4762": (ISO4762, ISO4762_LENGTHS_MM, f"ISO 4762: {FASTENERS_WB}, iso4762def.csv"),
    "ISO 7380": (ISO7380, ISO7380_LENGTHS_MM, f"ISO 7380-1: {FASTENERS_WB}, iso7380def.csv"),
}


@dataclass(frozen=True)
class Screw:
    """A screw chosen for a clamped stack: its designation, length and the thread it engages."""

    designation: str
    standard: str
    size: str
    length_mm: float
    clamp_mm: float
    engagement_mm: float
    head_d_mm: float
    head_h_mm: float
    thread_length_mm: float
    source: str


def screw(size: str, clamp_mm: float, engagement_mm: float, standard: str = "ISO 4762") -> Screw:
    """The shortest standard screw that passes ``clamp_mm`` of parts and engages ``engagement_mm`` of thread.

    The length (under the head) is at least ``clamp_mm + engagement_mm``; the thread must reach over the
    engaged length. A screw is taken as threaded over ``min(length, b)`` from its tip (``b`` the
    standard's reference thread length; shorter screws are threaded to the head), so the engagement is
    checked against that.

    Parameters
    ----------
    size : str
        ``"M3"``.
    clamp_mm : float
        Thickness of everything between the head and the threaded part.
    engagement_mm : float
        Thread engagement wanted in the threaded part (nut, insert or tapped hole).
    standard : {"ISO 4762", "ISO 7380"}

    Raises
    ------
    SpecError
        Unknown ``standard`` or ``size``; no standard length reaches (``clamp_mm``); the thread is too
        short for the engagement (``engagement_mm``).
    """
    if standard not in SCREW_SERIES:
        raise SpecError("standard", f"expected one of {sorted(SCREW_SERIES)}, got {standard!r}")
    table, lengths, source = SCREW_SERIES[standard]
    if size not in table:
        raise SpecError("size", f"no {standard} screw {size!r} in the catalogue; sizes {', '.join(table)}")
    row = table[size]
    clamp = _finite_positive("clamp_mm", clamp_mm)
    engage = _finite_positive("engagement_mm", engagement_mm)
    need = clamp + engage
    for length in lengths:
        if length < row.min_length_mm - _EPS or length > row.max_length_mm + _EPS or length < need - _EPS:
            continue
        thread = min(length, row.thread_b_mm)
        if thread < engage - _EPS:
            raise SpecError("engagement_mm", f"{standard} {size} × {length:g} has {thread:g} mm of thread, "
                            f"short of the {engage:g} mm engagement")
        return Screw(f"{standard} {size} × {length:g}", standard, size, float(length), clamp,
                     float(length) - clamp, row.head_d_mm, row.head_h_mm, float(thread), source)
    raise SpecError("clamp_mm", f"{clamp:g} mm clamped + {engage:g} mm engaged = {need:g} mm is longer than "
                    f"the longest {standard} {size} ({row.max_length_mm:g} mm)")


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
    d = _finite_positive("shaft_mm", shaft_mm)
    for groove, (lo, hi, od, s, m, n) in sorted(DIN6799.items()):
        if lo + _EPS < d <= hi + _EPS:
            return RetainingRing(f"DIN 6799 – {groove:g}", lo, hi, groove, m, s, od, n, DIN6799_SOURCE)
    raise SpecError("shaft_mm", f"no DIN 6799 retaining washer in the catalogue for a Ø{d:g} mm shaft "
                    f"(shafts over {min(v[0] for v in DIN6799.values()):g} up to "
                    f"{max(v[1] for v in DIN6799.values()):g} mm)")
