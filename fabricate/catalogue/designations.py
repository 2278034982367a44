"""Shop designations read back: the catalogue record each standard's name for a part stands for.

Every record of the catalogue carries the ``designation`` a shop names it by (the form each standard's own
designation example uses, with "×" between dimensions and a decimal point): ``ISO 8734 2 × 20``, ``ISO 7089 3``
(also ``DIN 125-A 3.2``), ``DIN 988 3 × 6 × 0.5``, ``ISO 4762 M3 × 12``, ``ISO 4032 M3``, ``DIN 6799 1.9``,
``ISO 2341-B 3 × 16``, ``ISO 1234 0.8 × 5``, ``ISO 8738 3``. :func:`parse_designation` reads each back.
"""

from __future__ import annotations

import re

from fabricate.catalogue.clips import RetainingRing, e_clip_row
from fabricate.catalogue.hardware import ISO7089, SCREW_SERIES, Nut, Screw, Washer, nut, pin_washer, shim_ring, washer
from fabricate.catalogue.pins import ISO2341, ClevisPin, PinChoice, SplitPin, clevis_pin, dowel_pin, split_pin
from fabricate.catalogue.tables import diameter_key
from fabricate.errors import SpecError

Designated = PinChoice | Washer | Screw | Nut | RetainingRing | ClevisPin | SplitPin

_NUM = r"(\d+(?:\.\d+)?)"
_X = r"\s*[×x]\s*"


def parse_designation(text: str) -> Designated:
    """The catalogue record a shop designation names (the inverse of every record's ``designation``).

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
            return e_clip_row(diameter_key(float(m[1])))
        elif m := re.fullmatch(rf"ISO 2341-B {_NUM}{_X}{_NUM}", t):
            cp = clevis_pin(float(m[1]), float(m[2]) - ISO2341[diameter_key(float(m[1]))][5]
                            - ISO2341[diameter_key(float(m[1]))][1] / 2.0)
            if abs(cp.length_mm - float(m[2])) < 1e-6:
                return cp
        elif m := re.fullmatch(rf"ISO 1234 {_NUM}{_X}{_NUM}", t):
            sp = split_pin(float(m[1]), float(m[2]))
            if abs(sp.length_mm - float(m[2])) < 1e-6:
                return sp
    except (SpecError, KeyError):
        pass
    raise SpecError("designation", f"{text!r} names no part in the catalogue")
