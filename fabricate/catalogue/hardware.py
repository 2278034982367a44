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
DIN988_TEXT
    DIN 988:1990-03, page 1 (English edition, reproduced at http://m.mydoc123.com/p-662206.html and
    https://de.scribd.com/document/440217046/DIN-988): the designation "Shim ring DIN 988 - 40 x 50 x 0,5"
    (inside diameter d1 × outside diameter d2 × thickness h). Its size table (page 2) was not legible in any
    public reproduction found, so the shim sizes are only those a retail listing names.

Designations
------------
Every record carries the ``designation`` a shop names it by (the form each standard's own designation
example uses, with "×" between dimensions and a decimal point): ``ISO 8734 2 × 20``, ``ISO 7089 3``
(also ``DIN 125-A 3.2``), ``DIN 988 3 × 6 × 0.5``, ``ISO 4762 M3 × 12``, ``ISO 4032 M3``, ``DIN 6799 1.9``,
``ISO 2341-B 3 × 16``, ``ISO 1234 0.8 × 5``, ``ISO 8738 3``. :func:`parse_designation` reads each back.
"""

from __future__ import annotations

import math
import re
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


def _finite_nonnegative(path: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpecError(path, f"expected a number, got {value!r}") from None
    if not math.isfinite(v) or v < 0.0:
        raise SpecError(path, f"expected a finite number >= 0, got {value!r}")
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
    """A flat washer or shim ring: bore ``d1``, outside ``d2``, thickness ``h`` (mm).

    ``designation`` is the name a shop orders it by; ``alt_designation`` an equivalent name under another
    standard (an ISO 7089 washer is also a DIN 125-A one), or None.
    """

    designation: str
    d1_mm: float
    d2_mm: float
    h_mm: float
    source: str
    standard: str = ""
    alt_designation: str | None = None


#: ISO 7089 normal series (d1 min, d2 max, h nominal), mm. FsData/iso7089def.csv columns d1_min, d2_max, h.
ISO7089: dict[str, tuple[float, float, float]] = {
    "M1.6": (1.7, 4.0, 0.3),  # iso7089def.csv "M1.6",1.7,4.0,0.3
    "M2": (2.2, 5.0, 0.3),  # iso7089def.csv "M2",2.2,5.0,0.3
    "M2.5": (2.7, 6.0, 0.5),  # iso7089def.csv "M2.5",2.7,6.0,0.5
    "M3": (3.2, 7.0, 0.5),  # iso7089def.csv "M3",3.2,7.0,0.5
    "M4": (4.3, 9.0, 0.8),  # iso7089def.csv "M4",4.3,9.0,0.8
    "M5": (5.3, 10.0, 1.0),  # iso7089def.csv "M5",5.3,10.0,1.0
    "M6": (6.4, 12.0, 1.6),  # iso7089def.csv "M6",6.4,12.0,1.6
    "M8": (8.4, 16.0, 1.6),  # iso7089def.csv "M8",8.4,16.0,1.6
}
ISO7089_SOURCE = (f"ISO 7089 / DIN 125-A: {FASTENERS_WB}, iso7089def.csv (M3..M6 also engineeringhardware.com "
                  "ISO 7089 size table, https://engineeringhardware.com/guide/standard/iso-7089-cad-svg-086-washer/)")


def washer(size: str) -> Washer:
    """The ISO 7089 (DIN 125-A) washer of thread ``size`` (``"M3"``).

    Its designation is ISO 7089's, by the nominal thread size (``"ISO 7089 3"``); ``alt_designation`` is
    DIN 125-A's, by the bore d1 (``"DIN 125-A 3.2"``).
    """
    if size not in ISO7089:
        raise SpecError("size", f"no ISO 7089 washer for {size!r}; sizes {', '.join(ISO7089)}")
    d1, d2, h = ISO7089[size]
    return Washer(f"ISO 7089 {size[1:]}", d1, d2, h, ISO7089_SOURCE, "ISO 7089", f"DIN 125-A {d1:g}")


def washer_for_shaft(diameter_mm: float) -> Washer:
    """The smallest ISO 7089 washer whose bore clears a pin or shaft of ``diameter_mm``."""
    d = _finite_positive("diameter_mm", diameter_mm)
    for size, (d1, _, _) in sorted(ISO7089.items(), key=lambda kv: kv[1][0]):
        if d1 >= d - _EPS:
            return washer(size)
    raise SpecError("diameter_mm", f"no ISO 7089 washer in the catalogue clears Ø{d:g} mm")


DIN988_NAMING = ("DIN 988:1990-03 p. 1, 'Shim ring DIN 988 - 40 x 50 x 0,5' (d1 x d2 x h), http://m.mydoc123.com/"
                 "p-662206.html")
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
    return Washer(f"DIN 988 {d1:g} × {d2:g} × {t:g}", d1, d2, t, f"{source}; naming: {DIN988_NAMING}", "DIN 988")


#: ISO 8738 plain washers for clevis pins, pin d -> (d1 min, d2 max, h nominal), mm.
#: FsData/iso8738def.csv columns d1_min, d2_max, h (rows "M3".."M8" are the pin diameters 3..8).
ISO8738: dict[float, tuple[float, float, float]] = {
    3.0: (3.0, 6.0, 0.8),  # iso8738def.csv "M3",3,6,0.8
    4.0: (4.0, 8.0, 0.8),  # iso8738def.csv "M4",4,8,0.8
    5.0: (5.0, 10.0, 0.8),  # iso8738def.csv "M5",5,10,0.8
    6.0: (6.0, 12.0, 1.6),  # iso8738def.csv "M6",6,12,1.6
    8.0: (8.0, 16.0, 2.0),  # iso8738def.csv "M8",8,16,2
}
ISO8738_SOURCE = f"ISO 8738: {FASTENERS_WB}, iso8738def.csv (columns d1_min, d2_max, h)"


def pin_washer(diameter_mm: float) -> Washer:
    """The ISO 8738 plain washer for a clevis pin (or any pin) of ``diameter_mm`` (bore = the pin)."""
    d = _finite_positive("diameter_mm", diameter_mm)
    if _key(d) not in ISO8738:
        raise SpecError("diameter_mm", f"no ISO 8738 washer for a Ø{d:g} mm pin in the catalogue; pins "
                        f"{', '.join(f'{k:g}' for k in ISO8738)}")
    d1, d2, h = ISO8738[_key(d)]
    return Washer(f"ISO 8738 {d:g}", d1, d2, h, ISO8738_SOURCE, "ISO 8738")


def washers_for_shaft(shaft_mm: float) -> tuple[Washer, ...]:
    """Every catalogued washer or shim that sits on a pin of ``shaft_mm``: the smallest ISO 7089 washer
    that clears it, the ISO 8738 pin washer and each DIN 988 shim ring of that bore (thinnest first)."""
    d = _finite_positive("shaft_mm", shaft_mm)
    out: list[Washer] = []
    for pick in (washer_for_shaft, pin_washer):
        try:
            out.append(pick(d))
        except SpecError:
            pass
    for (d1, _), (thicknesses, _) in DIN988.items():
        if abs(d1 - d) < 1e-6:
            out.extend(shim_ring(d1, h) for h in thicknesses)
    return tuple(sorted(out, key=lambda w: (w.h_mm, w.designation)))


#: fill_gap works in these steps (mm): every catalogued thickness is a whole number of them.
_GAP_STEP = 0.01  # fill_gap's resolution, not a table value (every thickness above is a multiple of it)


def fill_gap(shaft_mm: float, gap_mm: float, tol_mm: float) -> tuple[Washer, ...]:
    """The fewest standard washers and shims on a pin of ``shaft_mm`` that fill an axial gap.

    The stack's thickness ``t`` satisfies ``gap_mm - tol_mm <= t <= gap_mm`` (it never over-fills the
    gap, so the stack and the pin length stay consistent). Among the stacks with the fewest pieces the
    thickest is taken. Only the washers :func:`washers_for_shaft` lists are used, each as often as needed.

    Parameters
    ----------
    shaft_mm : float
        Pin diameter.
    gap_mm : float
        The axial play to take up (>= 0).
    tol_mm : float
        How much of the gap may stay open (>= 0).

    Returns
    -------
    tuple of Washer
        Thickest first; empty when ``gap_mm <= tol_mm``.

    Raises
    ------
    SpecError
        Bad numbers (the parameter's name); no washer for the shaft (``shaft_mm``); no stack within the
        tolerance (``gap_mm``).
    """
    d = _finite_positive("shaft_mm", shaft_mm)
    gap = _finite_nonnegative("gap_mm", gap_mm)
    tol = _finite_nonnegative("tol_mm", tol_mm)
    if gap <= tol + _EPS:
        return ()
    items = washers_for_shaft(d)
    if not items:
        raise SpecError("shaft_mm", f"no washer or shim in the catalogue fits a Ø{d:g} mm pin")
    steps = [round(w.h_mm / _GAP_STEP) for w in items]
    hi = math.floor(gap / _GAP_STEP + 1e-6)
    lo = max(0, math.ceil((gap - tol) / _GAP_STEP - 1e-6))
    # fewest pieces to reach each total (unbounded change-making), the last piece remembered
    inf = hi + 1
    count = [0] + [inf] * hi
    last = [-1] * (hi + 1)
    for total in range(1, hi + 1):
        for i, st in enumerate(steps):
            if st <= total and count[total - st] + 1 < count[total]:
                count[total] = count[total - st] + 1
                last[total] = i
    reachable = [t for t in range(lo, hi + 1) if count[t] < inf]
    if not reachable:
        raise SpecError("gap_mm", f"no stack of {', '.join(w.designation for w in items)} fills {gap:g} mm "
                        f"within {tol:g} mm")
    best = min(reachable, key=lambda t: (count[t], -t))
    stack: list[Washer] = []
    while best > 0:
        stack.append(items[last[best]])
        best -= steps[last[best]]
    return tuple(sorted(stack, key=lambda w: -w.h_mm))


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


@dataclass(frozen=True)
class Nut:
    """An ISO 4032 hexagon nut (style 1): pitch ``P``, width across flats ``s``, across corners ``e`` (min)
    and height ``m`` (max), mm."""

    designation: str
    size: str
    pitch_mm: float
    s_mm: float
    e_mm: float
    m_mm: float
    source: str


#: ISO 4032 (P, s nominal, e min, m max), mm. FsData/iso4032def.csv columns P, s_nom, e, m.
ISO4032: dict[str, tuple[float, float, float, float]] = {
    "M1.6": (0.35, 3.2, 3.4, 1.3),  # iso4032def.csv "M1.6",0.35,..,e 3.4,m 1.3,..,s 3.2
    "M2": (0.4, 4.0, 4.4, 1.6),  # iso4032def.csv "M2",0.4,..,e 4.4,m 1.6,..,s 4.0
    "M2.5": (0.45, 5.0, 5.5, 2.0),  # iso4032def.csv "M2.5",0.45,..,e 5.5,m 2.0,..,s 5.0
    "M3": (0.5, 5.5, 6.1, 2.4),  # iso4032def.csv "M3",0.5,..,e 6.1,m 2.4,..,s 5.5
    "M4": (0.7, 7.0, 7.7, 3.2),  # iso4032def.csv "M4",0.7,..,e 7.7,m 3.2,..,s 7.0
    "M5": (0.8, 8.0, 8.9, 4.7),  # iso4032def.csv "M5",0.8,..,e 8.9,m 4.7,..,s 8.0
    "M6": (1.0, 10.0, 11.05, 5.2),  # iso4032def.csv "M6",1.0,..,e 11.05,m 5.2,..,s 10.0
}
ISO4032_SOURCE = f"ISO 4032: {FASTENERS_WB}, iso4032def.csv (columns P, s_nom, e, m)"


def nut(size: str) -> Nut:
    """The ISO 4032 hexagon nut of thread ``size`` (``"M3"``)."""
    if size not in ISO4032:
        raise SpecError("size", f"no ISO 4032 nut {size!r} in the catalogue; sizes {', '.join(ISO4032)}")
    p, s, e, m = ISO4032[size]
    return Nut(f"ISO 4032 {size}", size, p, s, e, m, ISO4032_SOURCE)


def screw_and_nut(size: str, clamp_mm: float, standard: str = "ISO 4762") -> tuple[Screw, Nut]:
    """A screw through ``clamp_mm`` of parts into an ISO 4032 nut: the thread engages the nut's full
    height ``m`` (the shortest standard screw that reaches through the nut)."""
    n = nut(size)
    return screw(size, clamp_mm, n.m_mm, standard), n


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


def _e_clip_row(groove: float) -> RetainingRing:
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
    d = _finite_positive("shaft_mm", shaft_mm)
    for groove, (lo, hi, *_) in sorted(DIN6799.items()):
        if lo + _EPS < d <= hi + _EPS:
            return _e_clip_row(groove)
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
    d = _finite_positive("diameter_mm", diameter_mm)
    stack = _finite_positive("stack_mm", stack_mm)
    clip = e_clip(d)
    pin = dowel_pin(d, stack + 2.0 * clip.protrusion_mm, "ISO 2338")
    return GroovedPin(pin, clip, stack)


# ---------------------------------------------------------------------------------------------------------
# Clevis pins ISO 2341 type B and split pins ISO 1234
# ---------------------------------------------------------------------------------------------------------

#: ISO 2341 rows d -> (head d_k, split-pin hole d_l, chamfer c, head edge e, head height k, hole centre from
#: the end l_e), mm. FsData/iso2341def.csv columns d, d_k, d_l, c, e, k, l_e (its r, the under-head radius,
#: is left out); the geometry (head above, the hole l_e from the tip): FsFunctions/FSmakeClevisPin.py.
ISO2341: dict[float, tuple[float, float, float, float, float, float]] = {
    3.0: (5.0, 0.8, 1.0, 0.5, 1.0, 1.6),  # iso2341def.csv "3 mm",3,5,0.8,1,0.5,1,1.6
    4.0: (6.0, 1.0, 1.0, 0.5, 1.0, 2.2),  # iso2341def.csv "4 mm",4,6,1,1,0.5,1,2.2
    5.0: (8.0, 1.2, 2.0, 1.0, 1.6, 2.9),  # iso2341def.csv "5 mm",5,8,1.2,2,1,1.6,2.9
    6.0: (10.0, 1.6, 2.0, 1.0, 2.0, 3.2),  # iso2341def.csv "6 mm",6,10,1.6,2,1,2,3.2
    8.0: (14.0, 2.0, 2.0, 1.0, 3.0, 3.5),  # iso2341def.csv "8 mm",8,14,2,2,1,3,3.5
    10.0: (18.0, 3.2, 2.0, 1.0, 4.0, 4.5),  # iso2341def.csv "10 mm",10,18,3.2,2,1,4,4.5
}
#: ISO 2341 nominal lengths (mm). FsData/iso2341length.csv column "nominal" (to 100 mm).
ISO2341_LENGTHS_MM: tuple[float, ...] = (
    6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 32, 35, 40, 45, 50,  # iso2341length.csv "nominal"
    55, 60, 65, 70, 75, 80, 85, 90, 95, 100)  # iso2341length.csv "nominal"
#: ISO 2341 length range (min, max) per d. FsData/iso2341range.csv.
ISO2341_RANGE_MM: dict[float, tuple[float, float]] = {
    3.0: (6, 30),  # iso2341range.csv "3 mm","6","30"
    4.0: (8, 40),  # iso2341range.csv "4 mm","8","40"
    5.0: (10, 50),  # iso2341range.csv "5 mm","10","50"
    6.0: (12, 60),  # iso2341range.csv "6 mm","12","60"
    8.0: (16, 80),  # iso2341range.csv "8 mm","16","80"
    10.0: (20, 100),  # iso2341range.csv "10 mm","20","100"
}
ISO2341_SOURCE = (f"ISO 2341: {FASTENERS_WB}, iso2341def.csv, iso2341length.csv, iso2341range.csv; geometry "
                  "FsFunctions/FSmakeClevisPin.py")

#: ISO 1234 rows nominal size (= the hole it fits) -> (leg extension a, length b, eye c, wire width d), mm.
#: FsData/iso1234def.csv columns a, b, c, d; the shape FsFunctions/FSmakeSplitPin.py.
ISO1234: dict[float, tuple[float, float, float, float]] = {
    0.6: (1.2, 2.0, 0.95, 0.45),  # iso1234def.csv "0.6 mm",1.2,2,0.95,0.45
    0.8: (1.2, 2.4, 1.3, 0.65),  # iso1234def.csv "0.8 mm",1.2,2.4,1.3,0.65
    1.0: (1.2, 3.0, 1.7, 0.85),  # iso1234def.csv "1 mm",1.2,3,1.7,0.85
    1.2: (1.875, 3.2, 2.6, 0.95),  # iso1234def.csv "1.2 mm",1.875,3.2,2.6,0.95
    1.6: (1.875, 4.0, 3.4, 1.35),  # iso1234def.csv "1.6 mm",1.875,4,3.4,1.35
    2.0: (1.875, 5.0, 4.3, 1.75),  # iso1234def.csv "2 mm",1.875,5,4.3,1.75
    2.5: (1.875, 5.0, 4.3, 2.2),  # iso1234def.csv "2.5 mm",1.875,5,4.3,2.2
    3.2: (2.4, 6.4, 5.45, 2.8),  # iso1234def.csv "3.2 mm",2.4,6.4,5.45,2.8
}
#: ISO 1234 nominal lengths (mm). FsData/iso1234length.csv column "nominal" (to 50 mm).
ISO1234_LENGTHS_MM: tuple[float, ...] = (
    4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 25, 28, 32, 36, 40, 45, 50)  # iso1234length.csv "nominal"
#: ISO 1234 length range (min, max) per nominal size. FsData/iso1234range.csv.
ISO1234_RANGE_MM: dict[float, tuple[float, float]] = {
    0.6: (4, 12),  # iso1234range.csv "0.6 mm","4","12"
    0.8: (5, 16),  # iso1234range.csv "0.8 mm","5","16"
    1.0: (6, 20),  # iso1234range.csv "1 mm","6","20"
    1.2: (8, 25),  # iso1234range.csv "1.2 mm","8","25"
    1.6: (8, 32),  # iso1234range.csv "1.6 mm","8","32"
    2.0: (10, 40),  # iso1234range.csv "2 mm","10","40"
    2.5: (12, 50),  # iso1234range.csv "2.5 mm","12","50"
    3.2: (14, 63),  # iso1234range.csv "3.2 mm","14","63"
}
ISO1234_SOURCE = (f"ISO 1234: {FASTENERS_WB}, iso1234def.csv, iso1234length.csv, iso1234range.csv; shape "
                  "FsFunctions/FSmakeSplitPin.py")


@dataclass(frozen=True)
class SplitPin:
    """An ISO 1234 split pin (cotter pin): ``size`` is the nominal size, the diameter of the hole it goes
    through; ``length_mm`` the shank under the eye; ``wire_d_mm`` the pin's width (d), ``eye_d_mm`` (c)."""

    designation: str
    size_mm: float
    length_mm: float
    wire_d_mm: float
    eye_d_mm: float
    leg_extension_mm: float
    source: str


@dataclass(frozen=True)
class ClevisPin:
    """An ISO 2341 type B clevis pin (head, and a cross hole for a split pin) with its split pin.

    The head sits on one face of the stack; the cross hole's centre is ``hole_from_end_mm`` from the
    pin's tip. ``grip_mm = length - hole_from_end - hole_d / 2`` is the longest stack the pin holds with
    its cross hole entirely outside the stack (the split pin then bears on the far face).
    ``protrusion_mm`` is what passes the far face of a stack of ``grip_mm`` (the pin's end and the split
    pin's hole), and ``head_h_mm`` what stands proud of the near face.
    """

    designation: str
    d_mm: float
    length_mm: float
    head_d_mm: float
    head_h_mm: float
    hole_d_mm: float
    hole_from_end_mm: float
    split_pin: SplitPin
    source: str

    @property
    def grip_mm(self) -> float:
        return self.length_mm - self.hole_from_end_mm - self.hole_d_mm / 2.0

    @property
    def protrusion_mm(self) -> float:
        return self.length_mm - self.grip_mm


def split_pin(size_mm: float, min_length_mm: float) -> SplitPin:
    """The shortest ISO 1234 split pin of nominal ``size_mm`` (its hole) at least ``min_length_mm`` long."""
    size = _finite_positive("size_mm", size_mm)
    need = _finite_positive("min_length_mm", min_length_mm)
    if _key(size) not in ISO1234:
        raise SpecError("size_mm", f"no ISO 1234 split pin of size {size:g} in the catalogue; sizes "
                        f"{', '.join(f'{k:g}' for k in ISO1234)}")
    a, _, c, d = ISO1234[_key(size)]
    lo, hi = ISO1234_RANGE_MM[_key(size)]
    for length in ISO1234_LENGTHS_MM:
        if lo - _EPS <= length <= hi + _EPS and length >= need - _EPS:
            return SplitPin(f"ISO 1234 {size:g} × {length:g}", size, float(length), d, c, a, ISO1234_SOURCE)
    raise SpecError("min_length_mm", f"{need:g} mm is longer than the longest ISO 1234 {size:g} split pin "
                    f"({min(hi, ISO1234_LENGTHS_MM[-1]):g} mm)")


def clevis_pin(diameter_mm: float, min_grip_mm: float) -> ClevisPin:
    """The shortest ISO 2341-B clevis pin of ``diameter_mm`` whose grip covers ``min_grip_mm``, with the
    ISO 1234 split pin its cross hole takes.

    The split pin is the shortest of its size whose shank spans the pin (length >= d: its legs must
    pass the far side to be bent back); a longer one is the fitter's choice.

    Parameters
    ----------
    diameter_mm : float
        Pin diameter; ISO 2341 starts at 3 mm.
    min_grip_mm : float
        The stack the pin passes, with any washer under the split pin (:func:`pin_washer`, ISO 8738, is
        the one made for it).

    Raises
    ------
    SpecError
        ``diameter_mm`` not in the catalogue; ``min_grip_mm`` beyond the longest pin of the diameter.
    """
    d = _finite_positive("diameter_mm", diameter_mm)
    grip = _finite_positive("min_grip_mm", min_grip_mm)
    if _key(d) not in ISO2341:
        raise SpecError("diameter_mm", f"no ISO 2341 clevis pin of Ø{d:g} mm in the catalogue; diameters "
                        f"{', '.join(f'{k:g}' for k in ISO2341)}")
    dk, dl, _, _, k, le = ISO2341[_key(d)]
    lo, hi = ISO2341_RANGE_MM[_key(d)]
    for length in ISO2341_LENGTHS_MM:
        if not lo - _EPS <= length <= hi + _EPS:
            continue
        if length - le - dl / 2.0 >= grip - _EPS:
            sp = split_pin(dl, d)
            return ClevisPin(f"ISO 2341-B {d:g} × {length:g}", d, float(length), dk, k, dl, le, sp,
                             ISO2341_SOURCE)
    raise SpecError("min_grip_mm", f"a {grip:g} mm grip is more than the longest ISO 2341 Ø{d:g} pin holds "
                    f"({hi - le - dl / 2.0:g} mm)")


# ---------------------------------------------------------------------------------------------------------
# Designations read back
# ---------------------------------------------------------------------------------------------------------

Designated = PinChoice | Washer | Screw | Nut | RetainingRing | ClevisPin | SplitPin

_NUM = r"(\d+(?:\.\d+)?)"
_X = r"\s*[×x]\s*"


def parse_designation(text: str) -> Designated:
    """The catalogue record a shop designation names (the inverse of every ``designation`` above).

    A screw is named without its joint: it comes back with ``clamp_mm = 0`` and its whole length as
    ``engagement_mm``. Raises :class:`SpecError` (path ``designation``) for a name the catalogue does
    not hold.
    """
    t = " ".join(str(text).replace(",", ".").split())
    try:
        if m := re.fullmatch(rf"(ISO 8734|ISO 2338) {_NUM}{_X}{_NUM}", t):
            pin = dowel_pin(float(m[2]), float(m[3]), m[1])
            if abs(pin.length_mm - float(m[3])) < 1e-6:
                return pin
        elif m := re.fullmatch(rf"ISO 7089 {_NUM}", t):
            return washer(f"M{m[1]}")
        elif m := re.fullmatch(rf"DIN 125-A {_NUM}", t):
            for size, (d1, _, _) in ISO7089.items():
                if abs(d1 - float(m[1])) < 1e-6:
                    return washer(size)
        elif m := re.fullmatch(rf"ISO 8738 {_NUM}", t):
            return pin_washer(float(m[1]))
        elif m := re.fullmatch(rf"DIN 988 {_NUM}{_X}{_NUM}{_X}{_NUM}", t):
            ring = shim_ring(float(m[1]), float(m[3]))
            if abs(ring.d2_mm - float(m[2])) < 1e-6:
                return ring
        elif m := re.fullmatch(rf"(ISO 4762|ISO 7380) (M{_NUM}){_X}{_NUM}", t):
            table, lengths, source = SCREW_SERIES[m[1]]
            row = table.get(m[2])
            length = float(m[4])
            if row and length in lengths and row.min_length_mm <= length <= row.max_length_mm:
                return Screw(t, m[1], m[2], length, 0.0, length, row.head_d_mm, row.head_h_mm,
                             min(length, row.thread_b_mm), source)
        elif m := re.fullmatch(r"ISO 4032 (M\d+(?:\.\d+)?)", t):
            return nut(m[1])
        elif m := re.fullmatch(rf"DIN 6799 {_NUM}", t):
            return _e_clip_row(_key(float(m[1])))
        elif m := re.fullmatch(rf"ISO 2341-B {_NUM}{_X}{_NUM}", t):
            cp = clevis_pin(float(m[1]), float(m[2]) - ISO2341[_key(float(m[1]))][5]
                            - ISO2341[_key(float(m[1]))][1] / 2.0)
            if abs(cp.length_mm - float(m[2])) < 1e-6:
                return cp
        elif m := re.fullmatch(rf"ISO 1234 {_NUM}{_X}{_NUM}", t):
            sp = split_pin(float(m[1]), float(m[2]))
            if abs(sp.length_mm - float(m[2])) < 1e-6:
                return sp
    except (SpecError, KeyError):
        pass
    raise SpecError("designation", f"{text!r} names no part in the catalogue")
