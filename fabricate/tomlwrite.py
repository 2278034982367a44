"""TOML text from nested Python values (tomllib reads TOML but does not write it).

Enough for templates: strings, booleans, integers, floats (written with ``repr``, so a float reads back as
the same float), lists (a list of tables becomes an array of inline tables) and nested tables. Bare keys
where TOML allows them, quoted otherwise.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from typing import Any

_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE.match(k) else json.dumps(k)


def value(v: Any) -> str:
    """One TOML value."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float) and not math.isfinite(v):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, (int, float)):
        return repr(v)
    if hasattr(v, "item") and not isinstance(v, (list, tuple, Mapping)):  # numpy scalars
        return value(v.item())
    if isinstance(v, str):
        # JSON escapes the C0 controls; TOML also forbids a raw DEL in a basic string
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, (list, tuple)) or hasattr(v, "tolist"):
        items = v.tolist() if hasattr(v, "tolist") else v
        return "[" + ", ".join(value(x) for x in items) + "]"
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{_key(str(k))} = {value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"cannot write {type(v).__name__} as TOML")


def dumps(data: Mapping[str, Any]) -> str:
    """A TOML document: top-level scalars first, then one ``[table]`` per nested table."""
    lines: list[str] = []

    def table(prefix: str, d: Mapping[str, Any]) -> None:
        if prefix:
            if lines:
                lines.append("")
            lines.append(f"[{prefix}]")
        for k, v in d.items():
            if not isinstance(v, Mapping):
                lines.append(f"{_key(str(k))} = {value(v)}")
        for k, v in d.items():
            if isinstance(v, Mapping):
                table(f"{prefix}.{_key(str(k))}" if prefix else _key(str(k)), v)

    table("", data)
    return "\n".join(lines) + "\n"
