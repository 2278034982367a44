"""Real clients read what a build writes: admesh reads every mesh as one closed part of the reported volume
with nothing to repair; PrusaSlicer arranges and slices every print plate on the bed of the printer it was
packed for (SLA presets via --export-sla, FDM via --export-gcode) without "could not fit"; LibreCAD prints the
kinematic drawing's dimensions legibly. (.ci/run installs them; each test skips only where its client is absent.)
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fabricate.catalogue.printers import PRINTERS, Printer, printer
from fabricate.design import load_design
from fabricate.output import write_output
from fabricate.pipeline import BuildOutcome
from fabricate.templates import shipped_templates

needs_admesh = pytest.mark.skipif(shutil.which("admesh") is None, reason="admesh not installed")
needs_prusaslicer = pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="PrusaSlicer not installed")


def _admesh(path: Path) -> dict[str, float]:
    run = subprocess.run(["admesh", str(path)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    stats = {}
    for key in ("Number of parts", "Volume", "Degenerate facets", "Edges fixed", "Facets removed",
                "Facets added", "Facets reversed", "Backwards edges", "Normals fixed",
                "Total disconnected facets"):
        match = re.search(rf"{key}\s*:\s*(-?[\d.]+)", run.stdout)
        assert match, f"admesh printed no {key!r}"
        stats[key] = float(match.group(1))
    return stats


@needs_admesh
@pytest.mark.slow
@pytest.mark.parametrize("template", ["gear_pair_elliptic", "finger_five_bar_ncg"])
def test_admesh_reads_every_part_whole_without_repair(template, tmp_path, shipped_build):
    outcome = shipped_build(template)
    write_output(outcome.files, tmp_path / "out")
    parts = outcome.report["parts"]
    for part in parts:
        stats = _admesh(tmp_path / "out" / part["stl"])
        assert stats["Number of parts"] == 1, part["name"]
        for key in ("Degenerate facets", "Edges fixed", "Facets removed", "Facets added", "Facets reversed",
                    "Backwards edges", "Normals fixed", "Total disconnected facets"):
            assert stats[key] == 0, (part["name"], key, stats[key])
        # admesh sums float32 facets: 1e-5 relative of the mesh volume the report gives
        assert stats["Volume"] == pytest.approx(part["stl_volume_mm3"], rel=1e-5)
    # every plate: one admesh part per copy on it, together every copy of every part, nothing repaired
    copies = parts[0]["copies"]
    plates = sorted((tmp_path / "out" / "plates").glob("plate_*.stl"))
    stats = [_admesh(plate) for plate in plates]
    assert sum(s["Number of parts"] for s in stats) == copies * len(parts)
    assert all(s["Edges fixed"] == 0 and s["Facets added"] == 0 for s in stats)
    assert sum(s["Volume"] for s in stats) == pytest.approx(copies * sum(p["stl_volume_mm3"] for p in parts),
                                                             rel=1e-5)


@needs_admesh
@pytest.mark.slow
@pytest.mark.skipif(shutil.which("librecad") is None or shutil.which("pdftoppm") is None,
                    reason="LibreCAD or poppler-utils not installed")
def test_librecad_draws_dimension_text_at_least_2_5_mm(tmp_path, shipped_build):
    """LibreCAD sizes dimension text by the drawing's header and dimension style, not by per-entity
    overrides: its PDF, printed at 1:1 and rasterised at 10 px/mm, shows dimension digits >= 2.5 mm."""
    import os

    import numpy as np
    from PIL import Image
    from scipy import ndimage

    from fabricate.export.dxf import MIN_DRAWING_TEXT_MM

    outcome = shipped_build("finger_five_bar_ncg")
    dxf = tmp_path / "kinematic.dxf"
    dxf.write_bytes(outcome.files["drawings/kinematic.dxf"])
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "XDG_RUNTIME_DIR": str(tmp_path)}
    run = subprocess.run(["librecad", "dxf2pdf", "-s", "1", "-c", str(dxf.name)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and (tmp_path / "kinematic.pdf").is_file(), run.stderr
    subprocess.run(["pdftoppm", "-r", "254", "-png", "kinematic.pdf", "page"], cwd=tmp_path, check=True,
                   timeout=120)
    image = np.asarray(Image.open(next(tmp_path.glob("page*.png"))).convert("RGB")).astype(int)
    # the dimension layers are ACI 5 (blue): their small connected blobs are the dimension digits
    blue = (image[:, :, 0] < 120) & (image[:, :, 1] < 120) & (image[:, :, 2] > 180)
    labels, count = ndimage.label(blue, structure=np.ones((3, 3)))
    sizes = np.array([(s[0].stop - s[0].start, s[1].stop - s[1].start) for s in ndimage.find_objects(labels)])
    px_per_mm = 254 / 25.4
    glyphs = sizes[(sizes[:, 0] < 10 * px_per_mm) & (sizes[:, 1] < 1.2 * sizes[:, 0]) & (sizes[:, 0] > 3)]
    assert len(glyphs) >= 10  # the link lengths' and ordinates' digits
    # digit height is the font's cap height, ~0.9-1.0 of the text height
    assert np.median(glyphs[:, 0]) / px_per_mm >= 0.9 * MIN_DRAWING_TEXT_MM


# -- PrusaSlicer: every plate on its printer's bed -------------------------------------------------------------
def _prusaslicer_config(printer: Printer, first_layer_mm: float) -> str:
    """A PrusaSlicer config of the preset's bed and height (SLA: the exposure area at 4 px/mm and 0.1 mm layers,
    enough to tell whether a plate fits, no supports or pad, which would grow the print past the plate; FDM: a
    0.4 mm nozzle, 0.3 mm layers, sparse infill), with the profile's first-layer compensation."""
    x, y, z = printer.build_volume_mm
    lines = [f"bed_shape = 0x0,{x:g}x0,{x:g}x{y:g},0x{y:g}", f"max_print_height = {z:g}",
             f"elefant_foot_compensation = {first_layer_mm:g}"]
    if printer.technique == "sla":
        lines += ["printer_technology = SLA", f"display_width = {x:g}", f"display_height = {y:g}",
                  f"display_pixels_x = {round(4 * x)}", f"display_pixels_y = {round(4 * y)}",
                  "display_orientation = landscape", "supports_enable = 0", "pad_enable = 0", "layer_height = 0.1"]
    else:
        lines += ["printer_technology = FFF", "nozzle_diameter = 0.4", "filament_diameter = 1.75", "layer_height = 0.3",
                  "first_layer_height = 0.3", "perimeters = 2", "fill_density = 15%", "skirts = 0"]
    return "\n".join(lines) + "\n"


def _stl_bounds(data: bytes) -> np.ndarray:
    """(2, 3) min and max corner of a binary STL's vertices."""
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
    records = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                            count=count, offset=84)
    vertices = records["v"].reshape(-1, 3)
    return np.array([vertices.min(axis=0), vertices.max(axis=0)])


def _slice_plates(plates: dict[str, bytes], printer: Printer, first_layer_mm: float, margin_mm: float,
                  folder: Path) -> None:
    """Each plate lies inside the bed less the margin as placed, and PrusaSlicer arranges it on the preset's bed
    (the default: the plate is one object, which must fit) and slices it: exit 0, a non-empty print file and
    no "could not fit"."""
    assert plates
    folder.mkdir(parents=True, exist_ok=True)
    config = folder / f"{printer.name}.ini"
    config.write_text(_prusaslicer_config(printer, first_layer_mm))
    x, y, z = printer.build_volume_mm
    sla = printer.technique == "sla"
    for rel, data in sorted(plates.items()):
        lo, hi = _stl_bounds(data)
        # float32 vertices: 1e-4 mm
        assert lo[0] >= margin_mm - 1e-4 and lo[1] >= margin_mm - 1e-4, (printer.name, rel, lo)
        assert hi[0] <= x - margin_mm + 1e-4 and hi[1] <= y - margin_mm + 1e-4 and hi[2] <= z + 1e-4, \
            (printer.name, rel, hi)
        stl = folder / rel.replace("/", "_")
        stl.write_bytes(data)
        out = stl.with_suffix(".sl1" if sla else ".gcode")
        run = subprocess.run(["prusa-slicer", "--loglevel", "1", "--load", str(config),
                              "--export-sla" if sla else "--export-gcode", "-o", str(out), str(stl)],
                             capture_output=True, text=True, timeout=300)
        said = run.stdout + run.stderr
        assert "could not fit" not in said, (printer.name, rel, said[-400:])
        assert run.returncode == 0 and out.is_file() and out.stat().st_size > 0, (printer.name, rel, said[-400:])


def _relaid(outcome: BuildOutcome, printer_name: str, process: str | None = None) -> tuple[dict[str, bytes], float]:
    """The build's plates packed for another printer as the exporter packs plates (``plate_layout`` of the
    printed meshes, one STL per plate), in the build volume the template gets with ``--printer`` (only the build
    volume differs, so the parts are the build's): plate files and the plate margin."""
    from fabricate.export.stl import SolidCache, placed_flat_mesh, plate_layout, plate_stl

    design = load_design(outcome.design.template, process, printer_name)
    assert design.process.printer == printer_name
    partset = outcome.partset
    margin = outcome.design.parts.plate_spacing_mm
    cache = SolidCache(partset.chord_tolerance_mm)
    copies = max(1, int(getattr(partset, "copies", 1) or 1))
    made = [part for part in partset.parts for _ in range(copies)]
    placements = plate_layout(made, cache, design.process.build_volume_mm[:2], margin)
    files = {}
    for number in sorted({pl.sheet for pl in placements}):
        meshes = [placed_flat_mesh(part, cache, pl) for part, pl in zip(made, placements, strict=True)
                  if pl.sheet == number]
        files[f"plates/plate_{number + 1}.stl"] = plate_stl(meshes)
    return files, margin


#: Every template's own build (its profile's printer: the SL1S, the Saturn 3 for the gripper's palm).
@needs_prusaslicer
@pytest.mark.slow
@pytest.mark.parametrize("template", [p.stem for p in shipped_templates()])
def test_prusaslicer_slices_every_plate_of_every_template(template, tmp_path, shipped_build):
    outcome = shipped_build(template)
    info = outcome.report["design"]["printer"]
    plates = {k: v for k, v in outcome.files.items() if k.startswith("plates/") and k.endswith(".stl")}
    assert len(plates) == len({i for p in outcome.report["parts"] for i in p["plate"]["index"]})
    assert all(p["plate"]["fits"] for p in outcome.report["parts"])
    _slice_plates(plates, printer(info["name"]), info["first_layer_compensation_mm"],
                  outcome.design.parts.plate_spacing_mm, tmp_path)


@needs_prusaslicer
@pytest.mark.slow
@pytest.mark.parametrize("preset", sorted(PRINTERS))
def test_prusaslicer_slices_plates_on_every_printer_preset(preset, tmp_path, shipped_build):
    """Jansen's leg (8 parts, 3 SL1S plates) or the Watt six-bar packed for each preset's bed: SLA presets with
    the SLA build's parts, FDM presets with the template built with --process fdm. One template per preset, in
    turn by the presets' technique, so each technique slices both (the SL1S, the smallest bed, slices every
    template's own plates in the test above)."""
    spec = printer(preset)
    same_technique = sorted(name for name in PRINTERS if printer(name).technique == spec.technique)
    template = ("jansen_leg", "finger_watt_six_bar")[same_technique.index(preset) % 2]
    process = None if spec.technique == "sla" else "fdm"
    outcome = shipped_build(template, process)  # the FDM builds too: once per session
    plates, margin = _relaid(outcome, preset, process)
    _slice_plates(plates, spec, outcome.design.process.first_layer_compensation_mm, margin, tmp_path / template)
