"""``fabricate check DIR``: verify what is on disk against what fabricate wrote and would write again.

Three layers, each naming the file and how it differs:

1. **Manifest.** report.json lists every other file with its size and sha256; each is read and compared,
   and a file the manifest does not list is reported.
2. **Contents by type.** Every file is parsed as what it claims to be, against the numbers the report
   gives: a part STL is a closed solid of the reported volume, the print plate holds all of them, the 3MF
   has one closed object per part, a part DXF passes ezdxf's audit and cuts exactly the reported holes,
   images open, CSV and Markdown are UTF-8 text.
3. **Rebuild.** The template text embedded in report.json is built again and every file compared byte
   for byte (builds are deterministic), which also catches an edited report.json.

Nothing here writes files.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
from collections.abc import Callable, Mapping
from pathlib import Path, PurePosixPath
from typing import Any

from fabricate.errors import SpecError
from fabricate.export import copy_name
from fabricate.output import REPORT, foreign_entries

#: Relative tolerance of a mesh volume against the report (the report rounds to 1e-4 mm^3; meshes carry
#: float32 vertices, 1e-7 relative).
VOLUME_REL_TOL = 1e-5
#: Absolute tolerance of a DXF hole diameter against the report (the report rounds to 1e-6 mm).
DIAMETER_TOL_MM = 2e-6


def read_report(directory: Path) -> tuple[dict[str, Any] | None, list[str]]:
    """report.json of an output folder, or the reason it cannot be used.

    Raises
    ------
    SpecError
        ``directory`` is not a folder or has no report.json: it is not a fabricate output at all.
    """
    path = directory / REPORT
    if not directory.is_dir():
        raise SpecError(str(directory), "not a folder")
    if not path.is_file():
        raise SpecError(str(directory), "not a fabricate output folder (it has no report.json)")
    try:
        report = json.loads(path.read_bytes().decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        return None, [f"{REPORT}: not valid JSON ({exc})"]
    if not isinstance(report, dict) or not isinstance(report.get("design"), dict):
        return None, [f"{REPORT}: not a fabricate report (no design section)"]
    return report, []


def _manifest(report: Mapping[str, Any]) -> tuple[dict[str, dict[str, Any]], list[str]]:
    entries: dict[str, dict[str, Any]] = {}
    problems = []
    manifest = report.get("manifest")
    if not isinstance(manifest, list) or not manifest:
        return {}, [f"{REPORT}: no manifest of the files (written by an older fabricate? build it again)"]
    for item in manifest:
        rel = item.get("path") if isinstance(item, dict) else None
        pure = PurePosixPath(rel) if isinstance(rel, str) else None
        if pure is None or pure.is_absolute() or ".." in pure.parts or not isinstance(item.get("sha256"), str) \
                or not isinstance(item.get("bytes"), int):
            problems.append(f"{REPORT}: malformed manifest entry {item!r}")
            continue
        entries[rel] = item
    return entries, problems


def _expected_by_file(report: Mapping[str, Any]) -> dict[str, Any]:
    """What the report says each geometry file holds: volumes, hole diameters, object names and volumes.

    Drawings hold the finished holes, cut files the kerf-compensated ones; a plate or sheet holds every
    copy of every part the report places on it.
    """
    parts = [p for p in report.get("parts", []) if isinstance(p, dict)]
    expected: dict[str, Any] = {}
    plates: dict[int, list[tuple[str, float]]] = {}
    sheets: dict[int, list[float]] = {}
    for part in parts:
        volume = part.get("stl_volume_mm3")
        holes = [h for h in part.get("holes", []) if isinstance(h, dict)]
        finished = sorted(float(h.get("diameter_mm", 0.0)) for h in holes)
        cut = sorted(float(h.get("cut_diameter_mm", h.get("diameter_mm", 0.0))) for h in holes)
        if isinstance(part.get("stl"), str) and isinstance(volume, (int, float)):
            expected[part["stl"]] = float(volume)
        if isinstance(part.get("dxf"), str):
            expected[part["dxf"]] = finished
        if isinstance(part.get("cut_dxf"), str):
            expected[part["cut_dxf"]] = cut
        copies = int(part.get("copies", 1) or 1)
        for key, target in (("plate", plates), ("sheet", sheets)):
            indices = part.get(key, {}).get("index", []) if isinstance(part.get(key), dict) else []
            for k, number in enumerate(indices if isinstance(indices, list) else []):
                name = copy_name(part["name"], k, copies)
                if key == "plate":
                    target.setdefault(number, []).append((name, float(volume or 0.0)))
                else:
                    target.setdefault(number, []).extend(cut)
    for number, items in plates.items():
        expected[f"plates/plate_{number}.stl"] = sum(v for _, v in items)
        expected[f"plates/plate_{number}.3mf"] = dict(items)
    for number, diameters in sheets.items():
        expected[f"cut/sheet_{number}.dxf"] = sorted(diameters)
    if parts:
        expected["assembly.3mf"] = {p.get("name"): p.get("stl_volume_mm3") for p in parts}
        # a STEP solid is exact: the profile's area times the thickness, one cylinder per hole
        solids = {p.get("name"): (float(p.get("volume_mm3") or 0.0), len(p.get("holes", []))) for p in parts}
        for part in parts:
            if isinstance(part.get("step"), str):
                expected[part["step"]] = {part.get("name"): solids[part.get("name")]}
        expected["assembly.step"] = solids
    return expected


def content_problems(rel: str, data: bytes, expected: Any) -> list[str]:
    """What is wrong with one file's bytes, read as the type its name says (empty: nothing found)."""
    suffix = PurePosixPath(rel).suffix.lower()
    if suffix == ".stl":
        from fabricate.export.stl import validate_stl

        return validate_stl(data, expected, rel_tol=VOLUME_REL_TOL)
    if suffix == ".3mf":
        return _threemf_problems(data, expected)
    if suffix == ".dxf":
        from fabricate.export.dxf import read_dxf

        problems, diameters = read_dxf(data)
        if expected is not None and not problems:
            if len(diameters) != len(expected) or any(abs(a - b) > DIAMETER_TOL_MM
                                                       for a, b in zip(diameters, expected, strict=True)):
                problems.append(f"cut holes {_mm(diameters)} differ from the report's {_mm(expected)}")
        return problems
    if suffix in (".png", ".gif"):
        from PIL import Image

        try:
            with Image.open(io.BytesIO(data)) as image:
                image.verify()
            with Image.open(io.BytesIO(data)) as image:
                image.load()
        except Exception as exc:  # noqa: BLE001 - Pillow raises many types for a broken image
            return [f"not a readable image ({type(exc).__name__}: {exc})"]
        return []
    if suffix == ".step":
        from fabricate.export.step import step_available, step_problems

        return step_problems(data, expected) if step_available() else []
    if suffix == ".svg":
        import xml.etree.ElementTree as ET

        try:
            root = ET.fromstring(data)
        except ET.ParseError as exc:
            return [f"not readable SVG ({exc})"]
        if not root.tag.endswith("svg") or not str(root.get("width", "")).endswith("mm"):
            return ["not an SVG sized in millimetres"]
        return []
    if suffix in (".csv", ".md", ".json", ".txt", ".toml"):
        try:
            text = data.decode("utf-8")
            if suffix == ".csv":
                list(csv.reader(io.StringIO(text)))
            elif suffix == ".json":
                json.loads(text)
        except (UnicodeDecodeError, ValueError, csv.Error) as exc:
            return [f"not readable {suffix[1:].upper()} ({exc})"]
    return []


def _mm(values: list[float]) -> str:
    return "[" + ", ".join(f"{v:.4f}" for v in values) + "] mm"


def _threemf_problems(data: bytes, expected: Mapping[str, Any] | None) -> list[str]:
    from fabricate.export.stl import mesh_problems, read_3mf

    objects, problems = read_3mf(data)
    if problems or expected is None:
        return problems
    if list(objects) != list(expected):
        problems.append(f"objects {sorted(objects)} differ from the report's parts {sorted(expected)}")
    for name, mesh in objects.items():
        volume = expected.get(name)
        problems += [f"object {name}: {p}" for p in mesh_problems(
            mesh, float(volume) if isinstance(volume, (int, float)) else None, VOLUME_REL_TOL)]
    return problems


def file_problems(directory: Path, report: Mapping[str, Any]) -> list[str]:
    """Layers 1 and 2: the manifest's sizes and hashes, files it does not list, and every file's contents."""
    entries, problems = _manifest(report)
    listed = {str(p) for p in report.get("files", []) if isinstance(p, str)}
    if entries and listed != set(entries) | {REPORT}:
        missing = sorted(set(entries) - listed)
        extra = sorted(listed - set(entries) - {REPORT})
        problems.append(f"{REPORT}: its file list and its manifest disagree (not listed: {missing[:5]}, "
                        f"not in the manifest: {extra[:5]})")
    expected = _expected_by_file(report)
    for rel, item in sorted(entries.items()):
        path = directory / rel
        if not path.is_file():
            problems.append(f"{rel}: missing")
            continue
        data = path.read_bytes()
        if len(data) != item["bytes"]:
            problems.append(f"{rel}: {len(data)} bytes, the manifest says {item['bytes']}")
        elif hashlib.sha256(data).hexdigest() != item["sha256"]:
            problems.append(f"{rel}: contents differ from the manifest (sha256 {hashlib.sha256(data).hexdigest()[:12]}"
                            f"... against {item['sha256'][:12]}...)")
        problems += [f"{rel}: {p}" for p in content_problems(rel, data, expected.get(rel))]
    if entries:
        problems += [f"{rel}: not written by fabricate (not in the manifest)"
                     for rel in foreign_entries(directory, report)]
    return problems


def rebuild_problems(directory: Path, report: Mapping[str, Any],
                     progress: Callable[[str], None]) -> tuple[list[str], dict[str, Any] | None]:
    """Layer 3: build the embedded template again and compare every file byte for byte.

    Returns
    -------
    problems : list of str
    rebuilt_report : dict or None
        The fresh report (its check failures are the design's own), None when nothing could be rebuilt.
    """
    from fabricate.pipeline import run_build, run_synth
    from fabricate.spec import ProcessOverride, design_from_text

    text = report.get("template_text")
    design_info = report.get("design", {})
    if not isinstance(text, str) or not text:
        return [f"{REPORT}: no embedded template (template_text) to rebuild from"], None
    override = design_info.get("process_override")
    try:
        process = None
        if isinstance(override, dict):
            process = ProcessOverride(str(override.get("source")), str(override.get("text")))
        design = design_from_text(text, str(design_info.get("template") or "template.toml"), process)
    except SpecError as exc:
        return [f"{REPORT}: the embedded template is not valid: {exc}"], None
    runner = run_synth if design_info.get("stage") == "synth" else run_build
    outcome = runner(design, progress)
    on_disk = {str(m.get("path")) for m in report.get("manifest", []) if isinstance(m, dict)} | {REPORT}
    problems = []
    skipped: set[str] = set()
    from fabricate.export.step import step_available

    if not step_available() and any(rel.endswith(".step") for rel in on_disk):
        # without OCP a rebuild makes no STEP files and its report says so: compare everything else
        skipped = {rel for rel in on_disk if rel.endswith(".step")} | {REPORT}
        outcome.report.setdefault("notes", []).append(
            f"{len(skipped) - 1} STEP files and report.json not compared with a rebuild: OCP is not installed "
            "(pip install 'fabricate[cad]'); their hashes were checked")
    for rel in sorted((set(outcome.files) | on_disk) - skipped):
        path = directory / rel
        if rel not in outcome.files:
            problems.append(f"{rel}: a rebuild of the embedded template does not write it")
        elif not path.is_file():
            problems.append(f"{rel}: missing (a rebuild writes it)")
        elif path.read_bytes() != outcome.files[rel]:
            problems.append(f"{rel}: differs from a rebuild of the embedded template")
    return problems, outcome.report


def verify_output(directory: str | Path, progress: Callable[[str], None] = lambda _m: None
                  ) -> tuple[list[str], dict[str, Any] | None]:
    """Every problem of an output folder: manifest, contents, rebuild (see the module docstring).

    Returns
    -------
    problems : list of str
        Each names the file and how it differs; empty when the folder is exactly what the template builds.
    report : dict or None
        The rebuilt report when a rebuild ran (its ``checks`` are the design's), else the one on disk.

    Raises
    ------
    SpecError
        ``directory`` is not a fabricate output folder at all.
    """
    directory = Path(directory)
    report, problems = read_report(directory)
    if report is None:
        return problems, None
    progress("files")
    problems += file_problems(directory, report)
    progress("rebuild")
    rebuilt, fresh = rebuild_problems(directory, report, progress)
    return problems + rebuilt, fresh if fresh is not None else report
