"""report.json's schema as a documented, versioned contract (issue 24, item 3): every stable key titled and
described, one version in the package, the schema and the report, and docs/report.md generated from it.

The builds against the schema (every shipped template, and the keys `check` and sweeps read) are in
tests/test_verify.py, beside the built folders they use.
"""

from __future__ import annotations

import importlib.util
import re
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import pytest

from fabricate.report_schema import SCHEMA_VERSION, report_schema, schema_errors, version_problem

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def docs():
    """docs/make_report_docs.py as a module (docs/ is not a package)."""
    spec = importlib.util.spec_from_file_location("make_report_docs", ROOT / "docs" / "make_report_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _keys(node: Mapping[str, Any], path: str = "") -> Iterator[tuple[str, Mapping[str, Any]]]:
    """Every named key of the schema (properties, through lists and $defs), with its own node."""
    root = report_schema()

    def resolve(n: Mapping[str, Any]) -> Mapping[str, Any]:
        while "$ref" in n:
            target = root
            for part in n["$ref"][2:].split("/"):
                target = target[part]
            n = {**target, **{k: v for k, v in n.items() if k != "$ref"}}
        return n

    node = resolve(node)
    for key, child in node.get("properties", {}).items():
        yield f"{path}.{key}" if path else key, resolve(child)
        yield from _keys(child, f"{path}.{key}" if path else key)
    if isinstance(node.get("items"), Mapping):
        yield from _keys(node["items"], f"{path}[]")


def test_every_stable_key_has_a_title_and_a_description():
    keys = list(_keys(report_schema()))
    assert len(keys) > 150  # the walk reaches through lists and $refs (parts[].holes[].diameter_mm)
    assert "parts[].holes[].diameter_mm" in dict(keys) and "interference.pairs[].min_clearance_mm" in dict(keys)
    untitled = [path for path, node in keys if not (isinstance(node.get("title"), str) and node["title"].strip())]
    undescribed = [path for path, node in keys
                   if not (isinstance(node.get("description"), str) and len(node["description"]) > 2)]
    assert untitled == [] and undescribed == []
    root = report_schema()
    assert root["$id"] and root["title"] and root["description"]


def test_the_version_is_one_number_in_the_package_the_schema_and_every_report():
    root = report_schema()
    assert re.fullmatch(r"[0-9]+\.[0-9]+", SCHEMA_VERSION)
    assert root["$id"].endswith(f":{SCHEMA_VERSION}")
    assert "schema_version" in root["required"]
    major = SCHEMA_VERSION.split(".")[0]
    pattern = root["properties"]["schema_version"]["pattern"]
    assert re.search(pattern, SCHEMA_VERSION) and re.search(pattern, f"{major}.99")
    for other in (f"{int(major) + 1}.0", major, f"{SCHEMA_VERSION}\n", f"v{SCHEMA_VERSION}", ""):
        assert not re.search(pattern, other), other


def test_a_report_of_another_version_is_named_by_its_version():
    major = int(SCHEMA_VERSION.split(".")[0])
    assert version_problem({"schema_version": SCHEMA_VERSION}) is None
    assert version_problem({"schema_version": f"{major}.99"}) is None  # a newer minor only adds keys
    assert "older fabricate" in version_problem({"design": {}})
    newer = version_problem({"schema_version": f"{major + 1}.0"})
    assert f"schema_version {major + 1}.0" in newer and f"reads {major}.x" in newer
    # not a version at all: the schema names it (by the key's title), not the version check
    assert version_problem({"schema_version": 7}) is None
    assert "schema_version is not a string" in " ".join(schema_errors({"schema_version": 7}))
    assert "schema_version '1' is not a report schema version" in " ".join(schema_errors({"schema_version": "1"}))


def test_a_value_missing_its_pattern_is_named_by_the_keys_title():
    root = report_schema()
    titled = [(path, node) for path, node in _keys(root) if "pattern" in node]
    assert {path for path, _ in titled} >= {"schema_version", "outputs.step", "manifest[].path", "manifest[].sha256",
                                            "parts[].stl"}
    report = {"schema_version": SCHEMA_VERSION, "outputs": {"step": "maybe"},
              "manifest": [{"path": "a", "bytes": 1, "sha256": "x"}]}
    found = schema_errors(report)
    assert "outputs.step 'maybe' is not 'written' or 'skipped: <why>'" in found
    assert "manifest[0].sha256 'x' is not the SHA-256 of the file's bytes in 64 lowercase hex digits" in found


def test_docs_report_md_is_generated_from_the_schema(docs):
    """The page is the schema laid out: stale after any schema change until the script is run again."""
    page = (ROOT / "docs" / "report.md").read_text(encoding="utf-8")
    assert page == docs.render(docs.load_schema()), "docs/report.md is stale: run python docs/make_report_docs.py"
    assert docs.main(["--check"]) == 0
    assert page.startswith(f"# report.json, schema version {SCHEMA_VERSION}\n")
    for path, node in _keys(report_schema()):
        assert f"`{path}`" in page or path in report_schema()["properties"], path
        assert node["title"] in page


def test_a_changed_schema_renders_another_page(docs):
    schema = docs.load_schema()
    schema["properties"]["design"]["properties"]["name"]["description"] = "something else"
    assert docs.render(schema) != docs.render(docs.load_schema())
    assert "something else" in docs.render(schema)
