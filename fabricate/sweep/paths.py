"""Paths into templates and reports (``finger.lengths_mm[0]``) and the metrics a sweep collects over them
(``min(strength.parts[*].min_safety_factor)``): parse, read and write, pure.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from fabricate.errors import SpecError

_NAME = r"[A-Za-z_][A-Za-z0-9_-]*"
_PATH = re.compile(rf"^{_NAME}(?:\.{_NAME}|\[\d+\])*$")
_METRIC_PATH = re.compile(rf"^{_NAME}(?:\.{_NAME}|\[(?:\d+|\*)\])*$")
_AGGREGATES = ("min", "max", "mean", "sum", "count")
_AGGREGATE = re.compile(rf"^({'|'.join(_AGGREGATES)})\((.+)\)$")
_TOKEN = re.compile(rf"\.?({_NAME})|\[(\d+|\*)\]")

def parse_path(path: str, *, wildcard: bool = False) -> tuple[str | int, ...]:
    """Split a field path such as ``finger.lengths_mm[0]`` into ``("finger", "lengths_mm", 0)``.

    ``wildcard`` allows ``[*]`` (every element; metrics only), returned as the string ``"*"``.
    """
    pattern = _METRIC_PATH if wildcard else _PATH
    if not isinstance(path, str) or not pattern.match(path):
        raise ValueError(f'"{path}" is not a field path (names joined by ".", list indices in [ ])')
    parts: list[str | int] = []
    for name, index in _TOKEN.findall(path):
        parts.append(name if name else ("*" if index == "*" else int(index)))
    return tuple(parts)


def get_path(data: Any, parts: Sequence[str | int]) -> Any:
    """The value at ``parts`` in nested dicts/lists; ``KeyError`` when it is not there."""
    node = data
    for part in parts:
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise KeyError(part)
            node = node[part]
        else:
            if not isinstance(node, Mapping) or part not in node:
                raise KeyError(part)
            node = node[part]
    return node


def set_path(data: dict[str, Any], parts: Sequence[str | int], value: Any) -> None:
    """Set ``value`` at ``parts`` in place. Missing tables and the last key are created; a list index
    must exist (a sweep changes an element, it never grows a list)."""
    node: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise KeyError(part)
            if last:
                node[part] = value
            else:
                node = node[part]
        else:
            if not isinstance(node, dict):
                raise KeyError(part)
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})


@dataclass(frozen=True)
class Metric:
    """A number read from each point's report.json: a key path, optionally aggregated over ``[*]``.

    Attributes
    ----------
    name : str
        As written, e.g. ``synthesis.pose_error_mm.max`` or ``min(strength.parts[*].min_safety_factor)``;
        also the column name.
    aggregate : str or None
        ``min``, ``max``, ``mean``, ``sum`` or ``count`` over the values a ``[*]`` path selects.
    parts : tuple
        The key path.
    """

    name: str
    aggregate: str | None
    parts: tuple[str | int, ...]

    @property
    def section(self) -> str:
        return str(self.parts[0])

    def read(self, report: Mapping[str, Any]) -> float:
        """This metric's value in ``report`` as a float; NaN where the report does not have it (an
        invalid point, or a key the design's kind does not write). Booleans read as 0/1."""
        values = _select(report, self.parts)
        numbers = [float(v) for v in values if isinstance(v, (int, float)) and not isinstance(v, str)]
        if self.aggregate is None:
            return numbers[0] if len(values) == 1 and len(numbers) == 1 else math.nan
        if self.aggregate == "count":
            return float(len(values))
        if not numbers:
            return math.nan
        if self.aggregate == "min":
            return min(numbers)
        if self.aggregate == "max":
            return max(numbers)
        if self.aggregate == "sum":
            return math.fsum(numbers)
        return math.fsum(numbers) / len(numbers)


def _select(node: Any, parts: Sequence[str | int]) -> list[Any]:
    if not parts:
        return [node]
    head, rest = parts[0], parts[1:]
    if head == "*":
        return [v for item in node for v in _select(item, rest)] if isinstance(node, list) else []
    if isinstance(head, int):
        return _select(node[head], rest) if isinstance(node, list) and head < len(node) else []
    return _select(node[head], rest) if isinstance(node, Mapping) and head in node else []


def parse_metric(text: str, where: str) -> Metric:
    """A :class:`Metric` from ``path`` or ``min(path)`` (``[*]`` needs an aggregate)."""
    if not isinstance(text, str):
        raise SpecError(where, f"expected a report key path (string), got {text!r}")
    name = text.strip()
    m = _AGGREGATE.match(name)
    aggregate, path = (m.group(1), m.group(2).strip()) if m else (None, name)
    try:
        parts = parse_path(path, wildcard=True)
    except ValueError as exc:
        raise SpecError(where, f"{exc}; an aggregate is one of {', '.join(_AGGREGATES)}, e.g. "
                               "min(strength.parts[*].min_safety_factor)") from None
    if "*" in parts and aggregate is None:
        raise SpecError(where, f'"{name}" selects several values ([*]): wrap it in one of '
                               f"{', '.join(_AGGREGATES)}, e.g. min({name})")
    return Metric(name=name, aggregate=aggregate, parts=parts)
