"""The schema of report.json, its version, and the validator ``fabricate check`` runs before it reads any field.

The schema is a JSON Schema document shipped in the package (``fabricate/report_schema.json``, also
:func:`report_schema`) so outside tools can validate reports with any JSON Schema library; ``docs/report.md``
is generated from it (``docs/make_report_docs.py``). It is the contract of report.json: every key it names
is stable, typed, and has a title and a description; it requires the keys ``check`` reads; sections and keys
it does not name may be added freely and are not part of the contract.

Every report carries :data:`SCHEMA_VERSION` as its first key, ``schema_version`` ("MAJOR.MINOR"). MINOR
grows when the schema gains a key or admits a new value that readers may ignore; MAJOR grows when a key is
removed or renamed or its type or meaning changes. A reader of MAJOR.x reads every report of that MAJOR
(:func:`version_problem` says why it cannot read another).

The validator here implements the few keywords the schema uses (``type``, ``enum``, ``pattern``,
``required``, ``properties``, ``additionalProperties``, ``items``, ``minItems``, ``maxItems``,
``minimum``, local ``$ref``) instead of depending on ``jsonschema``: that keeps the core install free of
its dependency tree (``referencing``, the compiled ``rpds-py``), and its messages name a field the way a
reader of report.json writes it (``parts[3].holes is not a list``); a value that misses a pattern is named
by the schema's ``title`` for it (``is not a relative path inside the output folder``). Two deliberate
differences from plain JSON Schema, both stricter: a non-finite float is not a number (fabricate writes null
for one; ``NaN`` is not JSON), and ``true``/``false`` are never numbers.
"""

from __future__ import annotations

import functools
import itertools
import json
import math
import re
from collections.abc import Iterator, Mapping
from importlib import resources
from typing import Any

#: The schema's file name inside the package.
SCHEMA_FILE = "report_schema.json"
#: The version of the schema this fabricate writes and reads: report.json's ``schema_version`` (the schema's
#: ``$id`` ends with it; tests/test_report_schema.py holds the two together).
SCHEMA_VERSION = "1.0"
#: Keywords the validator implements; :func:`unsupported_keywords` finds any other in a schema.
KEYWORDS = frozenset({"type", "enum", "pattern", "required", "properties", "additionalProperties", "items",
                      "minItems", "maxItems", "minimum", "$ref"})
#: Keywords that only annotate (no effect on the verdict).
ANNOTATIONS = frozenset({"$schema", "$id", "$comment", "$defs", "title", "description"})
#: Messages returned at most: a report broken everywhere needs its first few, not thousands of lines.
MAX_MESSAGES = 20

_NAMES = {"object": "an object", "array": "a list", "string": "a string", "integer": "an integer",
          "number": "a number", "boolean": "true or false", "null": "null"}


@functools.lru_cache(maxsize=1)
def report_schema() -> dict[str, Any]:
    """The JSON Schema of report.json (parsed once; do not modify the returned dict)."""
    text = resources.files("fabricate").joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    return json.loads(text)


def _is(value: Any, kind: str) -> bool:
    if kind == "null":
        return value is None
    if kind == "boolean":
        return isinstance(value, bool)
    if kind == "string":
        return isinstance(value, str)
    if kind == "array":
        return isinstance(value, list)
    if kind == "object":
        return isinstance(value, dict)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    if isinstance(value, float) and not math.isfinite(value):
        return False
    # JSON Schema: an integer is a number with no fractional part (1.0 is one)
    return kind == "number" or isinstance(value, int) or value.is_integer()


def _what(value: Any) -> str:
    """The JSON type of a parsed value, in words (for "... (it is a string)")."""
    if isinstance(value, float) and not math.isfinite(value):
        return f"{value}, not a finite number"
    for kind in ("null", "boolean", "string", "array", "object", "integer", "number"):
        if _is(value, kind):
            return _NAMES[kind]
    return type(value).__name__


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def _short(text: str, limit: int = 60) -> str:
    return repr(text if len(text) <= limit else text[:limit] + "...")


def _resolve(root: Mapping[str, Any], ref: str) -> Mapping[str, Any]:
    if not ref.startswith("#/"):
        raise ValueError(f"only local $ref is supported, not {ref!r}")
    node: Any = root
    for key in ref[2:].split("/"):
        node = node[key.replace("~1", "/").replace("~0", "~")]
    return node


def _errors(value: Any, schema: Mapping[str, Any], path: str, root: Mapping[str, Any]) -> Iterator[str]:
    if "$ref" in schema:
        yield from _errors(value, _resolve(root, schema["$ref"]), path, root)
    where = path or "the report"
    if "type" in schema:
        kinds = [schema["type"]] if isinstance(schema["type"], str) else list(schema["type"])
        if not any(_is(value, kind) for kind in kinds):
            yield f"{where} is not {' or '.join(_NAMES[k] for k in kinds)} (it is {_what(value)})"
            return  # nothing below applies to a value of the wrong type
    if "enum" in schema and not any(type(value) is type(v) and value == v for v in schema["enum"]):
        yield f"{where} is not one of {', '.join(json.dumps(v) for v in schema['enum'])}"
    if isinstance(value, str) and "pattern" in schema and not re.search(schema["pattern"], value):
        yield f"{where} {_short(value)} is not " + (
            schema["title"] if "title" in schema else f"of the form {schema['pattern']}")
    if "minimum" in schema and _is(value, "number") and value < schema["minimum"]:
        yield f"{where} is {value}, less than {schema['minimum']}"
    if isinstance(value, list):
        low, high = schema.get("minItems"), schema.get("maxItems")
        if (low is not None and len(value) < low) or (high is not None and len(value) > high):
            wanted = f"{low}" if low == high else f"{low if low is not None else 0} to {high if high else 'any'}"
            yield f"{where} has {len(value)} item{'' if len(value) == 1 else 's'}, not {wanted}"
        if "items" in schema:
            for k, item in enumerate(value):
                yield from _errors(item, schema["items"], f"{path}[{k}]", root)
    if isinstance(value, dict):
        for key in schema.get("required", []):
            if key not in value:
                yield f"{_join(path, key)} is missing"
        properties = schema.get("properties", {})
        extra = schema.get("additionalProperties", True)
        for key, item in value.items():
            if key in properties:
                yield from _errors(item, properties[key], _join(path, key), root)
            elif extra is False:
                yield f"{_join(path, key)} is not a key of this section"
            elif isinstance(extra, Mapping):
                yield from _errors(item, extra, _join(path, key), root)


def schema_errors(report: Any, schema: Mapping[str, Any] | None = None, limit: int = MAX_MESSAGES) -> list[str]:
    """What makes ``report`` (parsed report.json) not match the schema, at most ``limit`` messages.

    Parameters
    ----------
    report : Any
        The parsed JSON document.
    schema : Mapping, optional
        A schema using only :data:`KEYWORDS` (default: :func:`report_schema`).
    limit : int
        Stop after this many messages (the last one then says more were left out).

    Returns
    -------
    list of str
        Each names the field by its path, e.g. ``"parts[3].holes is not a list (it is a string)"``;
        empty when the report matches.
    """
    root = report_schema() if schema is None else schema
    found = list(itertools.islice(_errors(report, root, "", root), limit + 1))
    if len(found) > limit:
        found = found[:limit] + [f"(more problems after the first {limit} not listed)"]
    return found


def version_problem(report: Mapping[str, Any]) -> str | None:
    """Why this fabricate cannot read ``report`` by its ``schema_version`` (None: it can).

    A report without one was written before report.json had a version (fabricate 0.1 before Step 13); one of
    another MAJOR follows a contract this fabricate does not know. A value that is not a version at all is
    left to :func:`schema_errors`, which names it.
    """
    version = report.get("schema_version")
    if "schema_version" not in report:
        return "no schema_version: written by an older fabricate, before report.json had a version; build it again"
    if not isinstance(version, str) or not re.fullmatch(r"[0-9]+\.[0-9]+", version):
        return None
    major = SCHEMA_VERSION.split(".")[0]
    if version.split(".")[0] != major:
        return (f"schema_version {version}: a report format this fabricate does not read (it reads {major}.x); "
                "use the fabricate that wrote it (design.fabricate_version)")
    return None


def unsupported_keywords(schema: Any) -> set[str]:
    """Keywords in ``schema`` that :func:`schema_errors` does not implement (empty: it implements all).

    ``properties`` and ``$defs`` map names to subschemas, so their keys are names, not keywords.
    """
    found: set[str] = set()
    if isinstance(schema, Mapping):
        for key, value in schema.items():
            if key in ("properties", "$defs"):
                for sub in value.values():
                    found |= unsupported_keywords(sub)
                continue
            if key not in KEYWORDS and key not in ANNOTATIONS:
                found.add(key)
            if key in ("items", "additionalProperties"):
                found |= unsupported_keywords(value)
    return found
