"""Generate docs/report.md, the page of report.json's keys, from its schema (fabricate/report_schema.json).

    python docs/make_report_docs.py           # writes docs/report.md
    python docs/make_report_docs.py --check   # exit 1 when docs/report.md is not what the schema renders

The schema is the contract; the page only lays it out for people (one table per section, every key with its
type and its title and description), so the two cannot disagree: tests/test_report_schema.py fails when the
page is stale.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
SCHEMA_PATH = ROOT / "fabricate" / "report_schema.json"
PAGE_PATH = ROOT / "docs" / "report.md"

#: How a shared definition is named in the type column (the others are expanded in place).
_NAMED_DEFS = {"number": "number or null", "pair": "[a, b]: two numbers (or null)", "path": "relative path",
               "path_or_null": "relative path or null"}
_PLURALS = {"string": "strings", "integer": "integers", "number": "numbers", "number or null": "numbers (or null)",
            "relative path": "relative paths", "[a, b]: two numbers (or null)": "[a, b] pairs of numbers (or null)"}
_TYPE_WORDS = {"object": "object", "array": "list", "string": "string", "integer": "integer", "number": "number",
               "boolean": "true/false", "null": "null"}


def load_schema(path: Path = SCHEMA_PATH) -> dict[str, Any]:
    return json.loads(path.read_text(encoding="utf-8"))


def _resolve(schema: Mapping[str, Any], node: Mapping[str, Any]) -> Mapping[str, Any]:
    """``node`` with a local ``$ref`` merged in (the node's own title and description win)."""
    if "$ref" not in node:
        return node
    target = schema
    for key in node["$ref"][2:].split("/"):
        target = target[key]
    return {**_resolve(schema, target), **{k: v for k, v in node.items() if k != "$ref"}}


def _ref_name(node: Mapping[str, Any]) -> str | None:
    ref = node.get("$ref", "")
    name = ref.rsplit("/", 1)[-1] if ref.startswith("#/$defs/") else None
    return name if name in _NAMED_DEFS else None


def type_text(schema: Mapping[str, Any], node: Mapping[str, Any]) -> str:
    """The type column of one key, in words."""
    named = _ref_name(node)
    if named:
        return _NAMED_DEFS[named]
    node = _resolve(schema, node)
    if "enum" in node:
        return "one of " + ", ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    kinds = node.get("type", [])
    kinds = [kinds] if isinstance(kinds, str) else list(kinds)
    words = []
    for kind in kinds:
        if kind == "array" and "items" in node:
            item = node["items"]
            inner = "objects" if _resolve(schema, item).get("properties") else type_text(schema, item)
            inner = _PLURALS.get(inner, inner)
            size = ""
            if node.get("minItems") is not None and node.get("minItems") == node.get("maxItems"):
                size = f" of {node['minItems']}"
            words.append(f"list{size} of {inner}")
        elif kind == "object" and isinstance(node.get("additionalProperties"), Mapping) and not node.get("properties"):
            words.append(f"object: name → {type_text(schema, node['additionalProperties'])}")
        elif kind == "integer" and "minimum" in node:
            words.append(f"integer ≥ {node['minimum']}")
        else:
            words.append(_TYPE_WORDS.get(kind, kind))
    text = " or ".join(words) or "any"
    if "pattern" in node:
        text += " (pattern)"
    return text


def _children(schema: Mapping[str, Any], node: Mapping[str, Any]) -> tuple[Mapping[str, Any], list[str], str]:
    """The keyed children of a node (an object's properties, or a list's objects'), their required keys and
    the path suffix (``""`` for an object, ``"[]"`` for a list)."""
    if _ref_name(node):
        return {}, [], ""
    node = _resolve(schema, node)
    if "array" in ([node.get("type")] if isinstance(node.get("type"), str) else node.get("type", [])) \
            and "items" in node:
        item = _resolve(schema, node["items"])
        return item.get("properties", {}), list(item.get("required", [])), "[]"
    return node.get("properties", {}), list(node.get("required", [])), ""


def rows(schema: Mapping[str, Any], node: Mapping[str, Any], path: str) -> Iterator[tuple[str, str, bool, str]]:
    """``(key path, type, required, meaning)`` of every key below ``node``, depth first."""
    properties, required, suffix = _children(schema, node)
    for key, child in properties.items():
        full = f"{path}{suffix}.{key}" if path else key
        resolved = _resolve(schema, child)
        meaning = f"{resolved.get('title', '')}: {resolved.get('description', '')}".strip(": ")
        yield full, type_text(schema, child), key in required, meaning
        yield from rows(schema, child, full)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def render(schema: Mapping[str, Any]) -> str:
    """docs/report.md as the schema gives it."""
    version = schema["$id"].rsplit(":", 1)[-1]
    top = schema["properties"]
    out = [f"# report.json, schema version {version}", "",
           "<!-- generated from fabricate/report_schema.json by docs/make_report_docs.py: edit the schema, then "
           "run the script -->", "",
           schema["description"], "",
           f"Schema: `fabricate/report_schema.json` (`$id` `{schema['$id']}`, JSON Schema "
           f"{schema['$schema'].split('/')[-2]}), also `fabricate.report_schema.report_schema()`.", "",
           "## Sections", "", "| key | type | required | what |", "|---|---|---|---|"]
    required = set(schema.get("required", []))
    for key, node in top.items():
        resolved = _resolve(schema, node)
        out.append(f"| [`{key}`](#{key.replace('_', '-')}) | {_cell(type_text(schema, node))} | "
                   f"{'yes' if key in required else ''} | {_cell(resolved.get('title', ''))} |")
    out.append("")
    for key, node in top.items():
        resolved = _resolve(schema, node)
        out += [f"## {key}", "", resolved.get("description", ""), "", f"Type: {type_text(schema, node)}."
                + (" Required." if key in required else ""), ""]
        table = list(rows(schema, node, key))
        if table:
            out += ["| key | type | required | meaning |", "|---|---|---|---|"]
            out += [f"| `{path}` | {_cell(kind)} | {'yes' if needed else ''} | {_cell(meaning)} |"
                    for path, kind, needed, meaning in table]
            out.append("")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 when docs/report.md is stale")
    args = parser.parse_args(argv)
    text = render(load_schema())
    if args.check:
        current = PAGE_PATH.read_text(encoding="utf-8") if PAGE_PATH.exists() else ""
        if current != text:
            print(f"{PAGE_PATH.relative_to(ROOT)} is stale: run python docs/make_report_docs.py", file=sys.stderr)
            return 1
        return 0
    PAGE_PATH.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
