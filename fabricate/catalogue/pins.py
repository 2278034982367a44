"""Standard pins: dowel pins (ISO 8734 hardened, ISO 2338 unhardened), clevis pins (ISO 2341 type B) and
the split pins (ISO 1234) that hold them.

Every number below is a value of a standard's table, taken from a public reproduction named in the comment
beside it (:data:`fabricate.catalogue.tables.FASTENERS_WB`). A size no source gave is left out, and the
picker that would need it raises :class:`SpecError` naming the field. The pins held by E-clips are in
:mod:`.clips`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from fabricate.catalogue.tables import EPS, FASTENERS_WB, diameter_key, finite_positive
from fabricate.errors import SpecError

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
    d = finite_positive("diameter_mm", diameter_mm)
    if diameter_key(d) not in ranges:
        raise SpecError("diameter_mm", f"no {standard} pin of Ø{d:g} mm; the series has "
                        f"{', '.join(f'{k:g}' for k in sorted(ranges))} mm")
    lo, hi = ranges[diameter_key(d)]
    return tuple(float(v) for v in lengths if lo - EPS <= v <= hi + EPS)


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
    need = finite_positive("min_length_mm", min_length_mm)
    lengths = pin_lengths(diameter_mm, standard)
    for length in lengths:
        if length >= need - EPS:
            return PinChoice(f"{standard} {float(diameter_mm):g} × {length:g}", length)
    raise SpecError("min_length_mm", f"{need:g} mm is longer than the longest {standard} Ø{float(diameter_mm):g} "
                    f"pin ({lengths[-1]:g} mm)")


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
    size = finite_positive("size_mm", size_mm)
    need = finite_positive("min_length_mm", min_length_mm)
    if diameter_key(size) not in ISO1234:
        raise SpecError("size_mm", f"no ISO 1234 split pin of size {size:g} in the catalogue; sizes "
                        f"{', '.join(f'{k:g}' for k in ISO1234)}")
    a, _, c, d = ISO1234[diameter_key(size)]
    lo, hi = ISO1234_RANGE_MM[diameter_key(size)]
    for length in ISO1234_LENGTHS_MM:
        if lo - EPS <= length <= hi + EPS and length >= need - EPS:
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
    d = finite_positive("diameter_mm", diameter_mm)
    grip = finite_positive("min_grip_mm", min_grip_mm)
    if diameter_key(d) not in ISO2341:
        raise SpecError("diameter_mm", f"no ISO 2341 clevis pin of Ø{d:g} mm in the catalogue; diameters "
                        f"{', '.join(f'{k:g}' for k in ISO2341)}")
    dk, dl, _, _, k, le = ISO2341[diameter_key(d)]
    lo, hi = ISO2341_RANGE_MM[diameter_key(d)]
    for length in ISO2341_LENGTHS_MM:
        if not lo - EPS <= length <= hi + EPS:
            continue
        if length - le - dl / 2.0 >= grip - EPS:
            sp = split_pin(dl, d)
            return ClevisPin(f"ISO 2341-B {d:g} × {length:g}", d, float(length), dk, k, dl, le, sp,
                             ISO2341_SOURCE)
    raise SpecError("min_grip_mm", f"a {grip:g} mm grip is more than the longest ISO 2341 Ø{d:g} pin holds "
                    f"({hi - le - dl / 2.0:g} mm)")
