"""Standard hardware from standard series: washers (ISO 7089 = DIN 125-A, ISO 8738) and shim rings
(DIN 988), screws (ISO 4762, ISO 7380-1) and nuts (ISO 4032).

Every number below is a value of a standard's table, taken from a public reproduction named in the
comment beside it (the standards themselves are sold, not published). Where no source was found for a
size or a series, the size is left out and the function that would need it raises :class:`SpecError`
naming the field: the catalogue never guesses a dimension. Pins are in :mod:`.pins`, E-clips in
:mod:`.clips`, and :mod:`.designations` reads every designation back.

The functions are pure: they pick a size from the tables, they place nothing.

Sources
-------
FASTENERS_WB
    :data:`fabricate.catalogue.tables.FASTENERS_WB`: the FreeCAD Fasteners workbench's ``FsData`` tables.
KB3D_SHIMS
    KB-3D retail listings of DIN 988 shim rings (named in the comment of each size).
DIN988_TEXT
    DIN 988:1990-03, page 1 (English edition, reproduced at http://m.mydoc123.com/p-662206.html and
    https://de.scribd.com/document/440217046/DIN-988): the designation "Shim ring DIN 988 - 40 x 50 x 0,5"
    (inside diameter d1 × outside diameter d2 × thickness h). Its size table (page 2) was not legible in any
    public reproduction found, so the shim sizes are only those a retail listing names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fabricate.catalogue.tables import EPS, FASTENERS_WB, diameter_key, finite_nonnegative, finite_positive
from fabricate.errors import SpecError

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
    d = finite_positive("diameter_mm", diameter_mm)
    for size, (d1, _, _) in sorted(ISO7089.items(), key=lambda kv: kv[1][0]):
        if d1 >= d - EPS:
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
    d = finite_positive("shaft_mm", shaft_mm)
    t = finite_positive("thickness_mm", thickness_mm)
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
    d = finite_positive("diameter_mm", diameter_mm)
    if diameter_key(d) not in ISO8738:
        raise SpecError("diameter_mm", f"no ISO 8738 washer for a Ø{d:g} mm pin in the catalogue; pins "
                        f"{', '.join(f'{k:g}' for k in ISO8738)}")
    d1, d2, h = ISO8738[diameter_key(d)]
    return Washer(f"ISO 8738 {d:g}", d1, d2, h, ISO8738_SOURCE, "ISO 8738")


def washers_for_shaft(shaft_mm: float) -> tuple[Washer, ...]:
    """Every catalogued washer or shim that sits on a pin of ``shaft_mm``: the smallest ISO 7089 washer
    that clears it, the ISO 8738 pin washer and each DIN 988 shim ring of that bore (thinnest first)."""
    d = finite_positive("shaft_mm", shaft_mm)
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
    d = finite_positive("shaft_mm", shaft_mm)
    gap = finite_nonnegative("gap_mm", gap_mm)
    tol = finite_nonnegative("tol_mm", tol_mm)
    if gap <= tol + EPS:
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
    clamp = finite_positive("clamp_mm", clamp_mm)
    engage = finite_positive("engagement_mm", engagement_mm)
    need = clamp + engage
    for length in lengths:
        if length < row.min_length_mm - EPS or length > row.max_length_mm + EPS or length < need - EPS:
            continue
        thread = min(length, row.thread_b_mm)
        if thread < engage - EPS:
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
