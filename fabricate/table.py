"""The strict template reader every spec parser uses: :class:`Table` and the number / array checks.

Its own module so that the parsers of the generic tables (``fabricate.gears.spec``, ``fabricate.parts.spec``)
and of each synthesis method read templates without importing :mod:`fabricate.spec`, which imports them
(the loop spec -> gears.spec -> spec is gone). Import these names from here.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from fabricate.errors import SpecError

_MISSING = object()

#: Least :class:`difflib.SequenceMatcher` ratio of a misspelt key to the missing one it is offered for (one
#: slip in a 10-letter name scores about 0.9). No required field of a shipped template scores this against a
#: valid field beside it that :func:`_different_field` lets through (tests/test_spec.py checks it).
MISSPELLING_CUTOFF = 0.8
_NO_DIGITS = str.maketrans("", "", "0123456789")


def _different_field(key: str, other: str) -> bool:
    """Whether ``other`` reads as another field of a family rather than a slip of ``key``.

    Exactly one ``_`` word differs and those words are not a slip of each other: both short (``x``/``y``,
    ``deg``/``mm``), equal but for digits (``k1``/``k2``, ``theta1``/``theta3``) or unlike (``input``/
    ``output``); or one name's words are a run of the other's (``teeth`` in ``min_teeth``).
    """
    a, b = key.lower().split("_"), other.lower().split("_")
    if len(a) == len(b):
        diff = [(x, y) for x, y in zip(a, b, strict=True) if x != y]
        if len(diff) != 1:
            return False
        x, y = diff[0]
        return (len(x) <= 3 and len(y) <= 3) or x.translate(_NO_DIGITS) == y.translate(_NO_DIGITS) \
            or difflib.SequenceMatcher(None, x, y).ratio() < MISSPELLING_CUTOFF
    short, long_ = (a, b) if len(a) < len(b) else (b, a)
    return any(long_[i:i + len(short)] == short for i in range(len(long_) - len(short) + 1))


def _quote(text: str, limit: int = 80) -> str:
    """``text`` in double quotes for a message: control characters, separators and the like as ``\\uXXXX``
    (a NUL or an escape sequence in a template never reaches the terminal raw), cut after ``limit``."""
    shown = "".join(c if c.isprintable() else f"\\u{ord(c):04X}" for c in text[:limit])
    return f'"{shown}{"..." if len(text) > limit else ""}"'


def _describe(value: Any) -> str:
    if isinstance(value, str):
        return _quote(value)
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)}"
    return repr(value)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class Table:
    """Strict, path-aware reader over one TOML table.

    Parameters
    ----------
    data : Mapping
        The table.
    path : str
        Its dotted path in the template ('' for the root).

    Notes
    -----
    Every getter records the key as used; :meth:`finish` raises on keys never read, so a typo in a
    template is an error and not a silently ignored field.
    """

    def __init__(self, data: Mapping[str, Any], path: str = "") -> None:
        if not isinstance(data, Mapping):
            raise SpecError(path, f"expected a table, got {_describe(data)}")
        self.data = data
        self.path = path
        self._used: set[str] = set()

    # -- helpers -----------------------------------------------------------------------------
    def field(self, key: str) -> str:
        """Dotted path of ``key`` in this table."""
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        return key in self.data

    def _get(self, key: str, default: Any) -> Any:
        self._used.add(key)
        if key in self.data:
            return self.data[key]
        if default is _MISSING:
            raise SpecError(self.field(key), "missing required field" + self._misspelt(key))
        return default

    def _misspelt(self, key: str) -> str:
        """`` (found unknown "lenghts_mm": did you mean "lengths_mm"?)`` when a key of this table that no
        getter has read looks like a misspelling of the missing ``key``; else ``""``.

        Keys read later are not known yet, so a close key may be a valid field still to come: siblings of a
        series (``theta1_deg`` / ``theta2_deg``, ``a_x_mm`` / ``a_y_mm``, ``input_arm_deg`` / ``input_arm_mm``)
        and qualified names (``teeth`` / ``min_teeth``) are never offered, and the likeness must be high.
        """
        unread = [k for k in self.data if isinstance(k, str) and k not in self._used and k != key]
        same_case = [k for k in unread if k.lower() == key.lower()]
        plausible = same_case or [k for k in unread if not _different_field(key, k)]
        lowered = {k.lower(): k for k in plausible}
        match = difflib.get_close_matches(key.lower(), list(lowered), n=1, cutoff=MISSPELLING_CUTOFF)
        return f' (found unknown "{lowered[match[0]]}": did you mean "{key}"?)' if match else ""

    # -- getters -----------------------------------------------------------------------------
    def number(
        self,
        key: str,
        default: Any = _MISSING,
        *,
        min: float | None = None,
        max: float | None = None,
        positive: bool = False,
        integer: bool = False,
    ) -> float:
        """A finite number, optionally bounded. ``positive`` means strictly greater than zero."""
        value = self._get(key, default)
        if value is default and default is not _MISSING:
            return value
        return check_number(value, self.field(key), min=min, max=max, positive=positive, integer=integer)

    def integer(self, key: str, default: Any = _MISSING, *, min: int | None = None,
                max: int | None = None) -> int:
        """A whole number, optionally bounded."""
        return int(self.number(key, default, min=min, max=max, integer=True))

    def string(self, key: str, default: Any = _MISSING, *, choices: Sequence[str] | None = None) -> str:
        """A string, optionally one of ``choices``."""
        value = self._get(key, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, str):
            raise SpecError(self.field(key), f"expected a string, got {_describe(value)}")
        if choices is not None and value not in choices:
            raise SpecError(self.field(key), f"expected one of {', '.join(map(repr, choices))}, got {_quote(value)}")
        return value

    def boolean(self, key: str, default: Any = _MISSING) -> bool:
        value = self._get(key, default)
        if not isinstance(value, bool):
            raise SpecError(self.field(key), f"expected true or false, got {_describe(value)}")
        return value

    def array(
        self,
        key: str,
        default: Any = _MISSING,
        *,
        shape: tuple[int | None, ...] | None = None,
        min_rows: int = 0,
        min: float | None = None,
        max: float | None = None,
        positive: bool = False,
    ) -> np.ndarray:
        """A list (or nested list) of finite numbers as a float64 array.

        ``shape`` may use ``None`` for a free dimension, e.g. ``(None, 3)``.
        """
        value = self._get(key, default)
        if value is default and default is not _MISSING:
            return value
        return check_array(value, self.field(key), shape=shape, min_rows=min_rows, min=min, max=max,
                           positive=positive)

    def strings(self, key: str, default: Any = _MISSING) -> tuple[str, ...]:
        value = self._get(key, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, list):
            raise SpecError(self.field(key), f"expected a list of strings, got {_describe(value)}")
        for i, item in enumerate(value):
            if not isinstance(item, str):
                raise SpecError(f"{self.field(key)}[{i}]", f"expected a string, got {_describe(item)}")
        return tuple(value)

    def table(self, key: str, default: Any = _MISSING) -> Table:
        """A sub-table; with a default of ``{}`` a missing table reads as empty."""
        value = self._get(key, default)
        return Table(value, self.field(key))

    def tables(self, key: str, default: Any = _MISSING) -> list[Table]:
        """An array of tables (``[[key]]``)."""
        value = self._get(key, default)
        if not isinstance(value, list):
            raise SpecError(self.field(key), f"expected an array of tables, got {_describe(value)}")
        return [Table(item, f"{self.field(key)}[{i}]") for i, item in enumerate(value)]

    def raw(self, key: str, default: Any = _MISSING) -> Any:
        return self._get(key, default)

    def finish(self) -> None:
        """Raise on the first key that no getter read (a typo or a field this kind does not know)."""
        for key in self.data:
            if key not in self._used:
                raise SpecError(self.field(key), "unknown field")


def check_number(value: Any, path: str, *, min: float | None = None, max: float | None = None,
                 positive: bool = False, integer: bool = False) -> float:
    """Validate one number; see :meth:`Table.number`."""
    if not _is_number(value):
        raise SpecError(path, f"expected a number, got {_describe(value)}")
    try:
        value = float(value)
    except OverflowError:  # an integer past float's range (TOML integers have no size limit in tomllib)
        try:
            digits = f"{len(str(abs(value)))}"
        except ValueError:  # str() of an int refuses past sys.get_int_max_str_digits() (4300 by default)
            digits = "thousands of"
        raise SpecError(path, f"expected a finite number, got an integer of {digits} digits") from None
    if not math.isfinite(value):
        raise SpecError(path, f"expected a finite number, got {value}")
    if integer and value != round(value):
        raise SpecError(path, f"expected a whole number, got {value:g}")
    if positive and value <= 0:
        raise SpecError(path, f"expected a positive number, got {value:g}")
    if min is not None and value < min:
        raise SpecError(path, f"expected a number >= {min:g}, got {value:g}")
    if max is not None and value > max:
        raise SpecError(path, f"expected a number <= {max:g}, got {value:g}")
    return value


def check_array(value: Any, path: str, *, shape: tuple[int | None, ...] | None = None, min_rows: int = 0,
                min: float | None = None, max: float | None = None, positive: bool = False) -> np.ndarray:
    """Validate a (nested) list of numbers element by element so the error names the bad index."""

    def walk(item: Any, where: str, depth: int) -> Any:
        if isinstance(item, list):
            if shape is not None and depth < len(shape) and shape[depth] is not None \
                    and len(item) != shape[depth]:
                raise SpecError(where, f"expected {shape[depth]} values, got {len(item)}")
            return [walk(x, f"{where}[{i}]", depth + 1) for i, x in enumerate(item)]
        if shape is not None and depth < len(shape):
            raise SpecError(where, f"expected a list, got {_describe(item)}")
        return check_number(item, where, min=min, max=max, positive=positive)

    if not isinstance(value, list):
        raise SpecError(path, f"expected a list, got {_describe(value)}")
    nested = walk(value, path, 0)
    if len(nested) < min_rows:
        raise SpecError(path, f"expected at least {min_rows} entries, got {len(nested)}")
    try:
        arr = np.asarray(nested, dtype=np.float64)
    except ValueError as exc:  # ragged lists
        raise SpecError(path, "expected rows of equal length") from exc
    if shape is not None and arr.ndim != len(shape):
        raise SpecError(path, f"expected a {len(shape)}-dimensional list, got {arr.ndim} dimensions")
    return arr


# -- templates -------------------------------------------------------------------------------
