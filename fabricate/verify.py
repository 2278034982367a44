"""``fabricate check DIR``: verify what is on disk against what fabricate wrote and would write again.

Three layers, each naming the file and how it differs:

1. **Manifest.** report.json (at most :data:`REPORT_MAX_BYTES`, of a ``schema_version`` this fabricate
   reads, validated against its schema, :mod:`fabricate.report_schema`, before any field is read) lists every
   other file with its size and sha256; each is compared, and a file the manifest does not list is reported.
2. **Contents by type.** Every file is parsed as what it claims to be, against the numbers the report
   gives: a part STL is a closed solid of the reported volume, the print plate holds all of them, the 3MF
   has one closed object per part, a part DXF passes ezdxf's audit and cuts exactly the reported holes,
   images open, CSV and Markdown are UTF-8 text.
3. **Rebuild.** The template text embedded in report.json is built again and every file compared byte
   for byte (builds are deterministic), which also catches an edited report.json.

Each layer runs in full only when the ones before found nothing: once a file differs from its manifest
entry the verdict is given, so only the differing files are parsed (to say how they differ) and nothing is
rebuilt; a folder with a wrong file (a 2 GB sparse file, a zip bomb) is rejected in milliseconds.

Bounded by the manifest: nothing in the folder decides how much ``check`` reads or inflates. Files are
opened without following links and read within their manifest size + 1 byte, 3MF packages and images
judged by their headers before anything is inflated or decoded (:mod:`fabricate.verify_files`, which
reads the folder and parses each file by its type); only the bytes read are parsed, and only up to
:data:`PARSE_MAX_BYTES`.

Optional outputs (STEP, the ``cad`` extra) are recorded in the report as written or skipped; the rebuild
makes the same set, so the verdict is the same on any install. STEP files that this install cannot make
are verified against the manifest and, in the rebuild, "not comparable here" (a note, not a failure).

Nothing here writes files.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path, PurePosixPath
from typing import Any

from fabricate.errors import FabricateError, SpecError
from fabricate.export import copy_name
from fabricate.output_read import REPORT, foreign_entries
from fabricate.report_schema import schema_errors, version_problem
from fabricate.verify_files import OutputFolder, Unreadable, parse_problems, reject_constant, same_bytes

#: Largest report.json read (bytes). The shipped templates write 20-60 kB; the largest a template within
#: the bounds of fabricate/bounds.py can ask for (5000 poses, 40 bodies) stays well under 10 MB.
REPORT_MAX_BYTES = 64 * 2**20
#: Largest file parsed by type (bytes); a larger one (its manifest says so and its hash matches) is
#: verified by hash and rebuild only, with a note. The shipped templates' largest file is a 3.8 MB STEP.
PARSE_MAX_BYTES = 64 * 2**20

_STEP_NOT_COMPARABLE = ("{n} STEP files not comparable here: OCP is not installed (pip install 'fabricate[cad]'), "
                        "so they were checked against the manifest only, not read back or rebuilt")


def _load_report(folder: OutputFolder) -> tuple[dict[str, Any] | None, bytes, list[str]]:
    """report.json, its bytes, and why it cannot be used (a report is returned only when valid)."""
    if not folder.lexists(REPORT):
        raise SpecError(str(folder.directory), "not a fabricate output folder (it has no report.json)")
    try:
        raw, size, _digest = folder.read(REPORT, REPORT_MAX_BYTES)
    except Unreadable as exc:
        return None, b"", [f"{REPORT}: {exc}"]
    if raw is None or size > REPORT_MAX_BYTES:
        return None, b"", [f"{REPORT}: {size} bytes, more than any report fabricate writes "
                           f"({REPORT_MAX_BYTES // 2**20} MB); not read"]
    try:
        report = json.loads(raw.decode("utf-8"), parse_constant=reject_constant)
    except (UnicodeDecodeError, ValueError) as exc:
        return None, raw, [f"{REPORT}: not valid JSON ({exc})"]
    except RecursionError:
        return None, raw, [f"{REPORT}: not valid JSON (nested too deeply)"]
    if not isinstance(report, dict) or not isinstance(report.get("design"), dict):
        return None, raw, [f"{REPORT}: not a fabricate report (no design section)"]
    if report.get("manifest") is None or report.get("manifest") == []:
        return None, raw, [f"{REPORT}: no manifest of the files (written by an older fabricate? build it again)"]
    version = version_problem(report)  # before the schema: a report of another version fails it for that reason
    if version is not None:
        return None, raw, [f"{REPORT}: {version}"]
    errors = schema_errors(report)
    if errors:
        return None, raw, [f"{REPORT}: {text}" for text in errors]
    return report, raw, []


def read_report(directory: str | Path) -> tuple[dict[str, Any] | None, list[str]]:
    """report.json of an output folder (size-bounded, schema-validated), or the reasons it cannot be used.

    Raises
    ------
    SpecError
        ``directory`` is not a folder or has no report.json: it is not a fabricate output at all.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise SpecError(str(directory), "not a folder")
    with OutputFolder(directory) as folder:
        report, _raw, problems = _load_report(folder)
    return report, problems


def _short(rel: Any) -> str:
    text = str(rel)
    return repr(text if len(text) <= 80 else text[:80] + "...")


def _manifest(report: Mapping[str, Any]) -> tuple[dict[str, dict[str, Any]], list[str]]:
    entries: dict[str, dict[str, Any]] = {}
    problems = []
    for item in report.get("manifest", []):
        rel = item.get("path") if isinstance(item, dict) else None
        pure = PurePosixPath(rel) if isinstance(rel, str) else None
        # the schema admits only relative paths, sizes and hashes; this guard keeps it so for any caller
        if not isinstance(rel, str) or pure is None or pure.is_absolute() or ".." in pure.parts \
                or not isinstance(item.get("sha256"), str) or not isinstance(item.get("bytes"), int) \
                or isinstance(item.get("bytes"), bool):
            problems.append(f"{REPORT}: malformed manifest entry for {_short(rel)}")
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
        holes: list[dict[str, Any]] = [h for h in part.get("holes", []) if isinstance(h, dict)]
        finished = sorted(float(h.get("diameter_mm", 0.0)) for h in holes)
        cut = sorted(float(h.get("cut_diameter_mm", h.get("diameter_mm", 0.0))) for h in holes)
        if isinstance(part.get("stl"), str) and isinstance(volume, (int, float)):
            expected[part["stl"]] = float(volume)
        if isinstance(part.get("dxf"), str):
            expected[part["dxf"]] = finished
        if isinstance(part.get("cut_dxf"), str):
            expected[part["cut_dxf"]] = cut
        copies = int(part.get("copies", 1) or 1)
        for key in ("plate", "sheet"):
            indices = part.get(key, {}).get("index", []) if isinstance(part.get(key), dict) else []
            for k, number in enumerate(indices if isinstance(indices, list) else []):
                name = copy_name(part["name"], k, copies)
                if key == "plate":
                    plates.setdefault(number, []).append((name, float(volume or 0.0)))
                else:
                    sheets.setdefault(number, []).extend(cut)
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


def _check_files(folder: OutputFolder, report: Mapping[str, Any], notes: list[str]) -> list[str]:
    """Layer 1 for every file, then layer 2: every file when layer 1 found nothing, else only the files
    whose bytes differ from their manifest entry (to say how), so a wrong folder is judged in milliseconds."""
    entries, problems = _manifest(report)
    listed = {str(p) for p in report.get("files", []) if isinstance(p, str)}
    if entries and listed != set(entries) | {REPORT}:
        missing = sorted(set(entries) - listed)
        extra = sorted(listed - set(entries) - {REPORT})
        problems.append(f"{REPORT}: its file list and its manifest disagree (not listed: {missing[:5]}, "
                        f"not in the manifest: {extra[:5]})")
    matching, differing = [], []
    for rel, item in sorted(entries.items()):
        manifest_bytes = int(item["bytes"])
        try:  # hashed in chunks, nothing held; +1 byte: a file that grew while being read shows it
            _data, size, digest = folder.read(rel, manifest_bytes + 1, keep=False)
        except Unreadable as exc:
            problems.append(f"{rel}: {exc}")
            continue
        if size != manifest_bytes:
            problems.append(f"{rel}: {size} bytes on disk, {manifest_bytes} bytes in the manifest")
        elif digest != item["sha256"]:
            problems.append(f"{rel}: contents differ from the manifest (sha256 {digest[:12]}... against "
                            f"{item['sha256'][:12]}...)")
        else:
            matching.append(rel)
            continue
        if size <= manifest_bytes:  # within the manifest's size: its contents may say how it differs
            differing.append(rel)
    if entries:
        problems += [f"{rel}: not written by fabricate (not in the manifest)"
                     for rel in foreign_entries(folder.directory, report)]
    expected = _expected_by_file(report)
    for rel in differing if problems else matching:
        manifest_bytes = int(entries[rel]["bytes"])
        if manifest_bytes > PARSE_MAX_BYTES:
            notes.append(f"{rel}: {manifest_bytes} bytes, more than check parses ({PARSE_MAX_BYTES // 2**20} MB); "
                         "verified by its hash" + ("" if problems else " and the rebuild") + " only")
            continue
        try:
            data, _size, _digest = folder.read(rel, manifest_bytes)
        except Unreadable as exc:  # changed since it was hashed
            problems.append(f"{rel}: {exc}")
            continue
        if data is not None:  # None: it grew past its manifest size since it was hashed (named above)
            problems += parse_problems(rel, data, expected.get(rel), notes)
    return problems


def file_problems(directory: str | Path, report: Mapping[str, Any]) -> list[str]:
    """Layers 1 and 2: the manifest's sizes and hashes, files it does not list, and every file's contents.

    ``report`` must have passed the schema (:func:`read_report` returns only such a report).
    """
    with OutputFolder(directory) as folder:
        return _check_files(folder, report, [])


def _recorded_step(report: Mapping[str, Any]) -> bool | None:
    """Whether the folder's build wrote STEP files (None: a synth output, no such question)."""
    outputs = report.get("outputs")
    if isinstance(outputs, dict) and isinstance(outputs.get("step"), str):
        return outputs["step"].startswith("written")
    if report.get("design", {}).get("stage") == "synth":
        return None
    # written before the report recorded its optional outputs: the manifest tells
    return any(str(m.get("path")).endswith(".step") for m in report.get("manifest", []) if isinstance(m, dict))


def _recorded_pictures(report: Mapping[str, Any]) -> bool:
    """Whether the folder's build drew its pictures (``outputs.pictures``; a report written before it was recorded
    came from a build that always drew them)."""
    outputs = report.get("outputs")
    pictures = outputs.get("pictures") if isinstance(outputs, dict) else None
    return not isinstance(pictures, str) or pictures.startswith("written")


def _folder_step_files(folder: OutputFolder, report: Mapping[str, Any]) -> dict[str, bytes]:
    """The folder's STEP files that match their manifest entries (stand-ins for a rebuild without OCP)."""
    entries, _problems = _manifest(report)
    found = {}
    for rel, item in entries.items():
        if not rel.endswith(".step"):
            continue
        try:
            data, size, digest = folder.read(rel, int(item["bytes"]))
        except Unreadable:
            continue
        if data is not None and size == item["bytes"] and digest == item["sha256"]:
            found[rel] = data
    return found


def _rebuild(folder: OutputFolder, report: Mapping[str, Any], raw: bytes, progress: Callable[[str], None],
             notes: list[str]) -> tuple[list[str], dict[str, Any] | None]:
    from fabricate.design import design_from_text
    from fabricate.export.step import step_available
    from fabricate.pipeline import OptionalOutputs, run_build, run_synth
    from fabricate.process import ProcessOverride

    text = report.get("template_text")
    design_info = report.get("design", {})
    if not isinstance(text, str) or not text:
        return [f"{REPORT}: no embedded template (template_text) to rebuild from"], None
    override = design_info.get("process_override")
    try:
        process = None
        if isinstance(override, dict):
            process = ProcessOverride(str(override.get("source")), str(override.get("text")),
                                      str(override.get("printer") or ""))
        design = design_from_text(text, str(design_info.get("template") or "template.toml"), process)
    except SpecError as exc:
        return [f"{REPORT}: the embedded template is not valid: {exc}"], None
    runner = run_synth if design_info.get("stage") == "synth" else run_build
    step_written = _recorded_step(report)
    not_comparable: set[str] = set()
    stand_ins = None
    if step_written and not step_available():
        stand_ins = _folder_step_files(folder, report)
        not_comparable = {str(m["path"]) for m in report.get("manifest", []) if str(m["path"]).endswith(".step")}
        notes.append(_STEP_NOT_COMPARABLE.format(n=len(not_comparable)))
    try:
        if runner is run_build and step_written is not None:
            # the optional outputs the folder's build made, whatever this install can make
            outcome = run_build(design, progress, optional=OptionalOutputs(step_written, stand_ins),
                                pictures=_recorded_pictures(report))
        else:
            outcome = runner(design, progress)
    except FabricateError as exc:  # the embedded template no longer builds (nothing feasible, a bound)
        return [f"{REPORT}: the embedded template cannot be built again: {exc}"], None
    on_disk = {str(m.get("path")) for m in report.get("manifest", [])} | {REPORT}
    problems = []
    for rel in sorted((set(outcome.files) | on_disk) - not_comparable):
        if rel not in outcome.files:
            problems.append(f"{rel}: a rebuild of the embedded template does not write it")
            continue
        same: bool | None
        if rel == REPORT:
            same, why = raw == outcome.files[REPORT], ""
        else:
            same, why = same_bytes(folder, rel, outcome.files[rel])
        if same is None:
            if rel not in on_disk:  # a manifest entry that cannot be read is named by the manifest layer
                problems.append(f"{rel}: {why} (a rebuild writes it)" if why != "missing"
                                else f"{rel}: missing (a rebuild writes it)")
        elif not same:
            problems.append(f"{rel}: differs from a rebuild of the embedded template" + (f" ({why})" if why else ""))
    return problems, outcome.report


def rebuild_problems(directory: str | Path, report: Mapping[str, Any],
                     progress: Callable[[str], None] = lambda _m: None) -> tuple[list[str], dict[str, Any] | None]:
    """Layer 3: build the embedded template again and compare every file byte for byte.

    Returns
    -------
    problems : list of str
    rebuilt_report : dict or None
        The fresh report (its check failures are the design's own), None when nothing could be rebuilt.
    """
    with OutputFolder(directory) as folder:
        loaded, raw, _problems = _load_report(folder)
        return _rebuild(folder, report, raw if loaded == report else b"", progress, [])


def verify_output(directory: str | Path, progress: Callable[[str], None] = lambda _m: None
                  ) -> tuple[list[str], dict[str, Any] | None]:
    """Every problem of an output folder: manifest, contents, rebuild (see the module docstring).

    Returns
    -------
    problems : list of str
        Each names the file and how it differs; empty when the folder is exactly what the template builds.
    report : dict or None
        The rebuilt report when a rebuild ran (its ``checks`` are the design's), else the one on disk; its
        ``notes`` end with what this check could not verify here (e.g. STEP files without OCP).

    Raises
    ------
    SpecError
        ``directory`` is not a fabricate output folder at all.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise SpecError(str(directory), "not a folder")
    notes: list[str] = []
    with OutputFolder(directory) as folder:
        report, raw, problems = _load_report(folder)
        if report is None:
            return problems, None
        progress("files")
        problems += _check_files(folder, report, notes)
        rebuilt: list[str] = []
        fresh: dict[str, Any] | None = None
        if problems:  # the verdict is given: a rebuild (seconds to a minute) would only repeat it per file
            notes.append("not compared with a rebuild: the files already differ from what fabricate wrote")
        else:
            progress("rebuild")
            rebuilt, fresh = _rebuild(folder, report, raw, progress, notes)
    final = fresh if fresh is not None else report
    if notes:  # a copy: the rebuilt report may be shared (cached) by the caller
        final = {**final, "notes": [*final.get("notes", []), *notes]}
    return problems + rebuilt, final
