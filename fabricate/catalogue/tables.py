"""What the tables of standard hardware share (:mod:`.hardware`, :mod:`.pins`, :mod:`.clips`): their common
source, the tolerance and the key rounding they are looked up with, and the checks of the numbers a picker
is given.

Sources
-------
FASTENERS_WB
    shaise/FreeCAD_FastenersWB, folder ``FsData`` (https://github.com/shaise/FreeCAD_FastenersWB): the
    FreeCAD Fasteners workbench's transcriptions of the ISO/DIN tables, file named per value.
"""

from __future__ import annotations

import math

from fabricate.errors import SpecError

FASTENERS_WB = "shaise/FreeCAD_FastenersWB FsData (https://github.com/shaise/FreeCAD_FastenersWB)"

#: Tolerance (mm) of the comparisons against table values: a numerical tolerance, not catalogue data.
EPS = 1e-9


def finite_positive(path: str, value: float) -> float:
    """``value`` as a float if it is a positive finite number; else :class:`SpecError` naming ``path``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpecError(path, f"expected a number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise SpecError(path, f"expected a positive finite number, got {value!r}")
    return v


def finite_nonnegative(path: str, value: float) -> float:
    """``value`` as a float if it is a finite number >= 0; else :class:`SpecError` naming ``path``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpecError(path, f"expected a number, got {value!r}") from None
    if not math.isfinite(v) or v < 0.0:
        raise SpecError(path, f"expected a finite number >= 0, got {value!r}")
    return v


def diameter_key(d: float) -> float:
    """Diameters as table keys (1.5 and 1.50000001 are the same pin)."""
    return round(float(d), 3)
