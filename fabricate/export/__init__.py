"""Exporters: parts to STL / 3MF (SLA), DXF (laser and CAD), preview pictures, bill of materials.

:func:`export_all` is what the pipeline calls: it returns every file as bytes keyed by its path relative
to the output directory, and the ``parts`` section of report.json. Nothing here writes files.

Files
-----
``parts/<name>.stl``       binary STL of each part lying on z = 0 in its own coordinates
``parts/<name>.dxf``       DXF of each part's cut path in its own coordinates
``print_plate.stl``        every part laid out on the SLA build plate
``assembly.3mf``           the assembly at the first pose (one object per part)
``parts/<name>.step``      B-rep solid of each part on z = 0 (only with the extra ``cad``: OCP)
``assembly.step``          the assembly at the first pose, one named solid per part (extra ``cad``)
``sheet.dxf``              every part nested on the process sheet, labelled on ENGRAVE
``kinematic.dxf``          joints, link centre lines and dimensions at the first pose
``previews/assembly.png``  the assembly at several poses
``previews/motion.gif``    the motion
``bom.csv``                the bill of materials
"""

from __future__ import annotations

import csv
import io
from typing import Any

from fabricate.errors import GeometryError
from fabricate.export.layout import fits


def _bom_csv(rows: list[dict[str, Any]]) -> bytes:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["item", "kind", "qty", "joints", "description"])
    for row in rows:
        writer.writerow([row.get("item", ""), row.get("kind", ""), row.get("qty", 0),
                         " ".join(row.get("joints", [])), row.get("description", "")])
    return buffer.getvalue().encode("utf-8")


def export_all(design: Any, partset: Any, mechanism: Any, motion: Any, previews: bool = True
               ) -> tuple[dict[str, bytes], list[dict[str, Any]]]:
    """Every export of a part set.

    Parameters
    ----------
    design : DesignSpec
        Uses ``process`` (build volume / sheet size, kerf) and ``parts`` (spacing, preview settings).
    partset : PartSet
        From :func:`fabricate.parts.build.build_parts`.
    mechanism : Mechanism
    motion : Motion
        The sweep; its first pose is the assembly pose.
    previews : bool
        Include the preview pictures (the pipeline draws them separately, see :func:`export_previews`).

    Returns
    -------
    files : dict[str, bytes]
        Relative path -> content.
    parts_report : list of dict
        One entry per part: name, process, stl, dxf, volume_mm3, layer, holes [{joint, diameter_mm,
        cut_diameter_mm}], plus role, body, thickness_mm, z_mm, area_mm2, stl_problems, plate and sheet
        placement, and the part's geometry warnings (e.g. holes running into each other). ``volume_mm3`` is
        the exact profile area times the thickness, ``stl_volume_mm3`` the polygonised solid's (what
        ``fabricate check`` holds the STL and 3MF to).

    Raises
    ------
    GeometryError
        When a written STL does not read back as a closed solid (a bug, never a design finding).
    """
    from fabricate.export.dxf import kinematic_dxf, part_dxf, sheet_dxf, sheet_layout
    from fabricate.export.stl import (
        SolidCache,
        assembly_3mf,
        mesh_volume,
        part_stl,
        plate_layout,
        print_plate_stl,
        validate_stl,
    )
    from fabricate.export.step import step_available, step_files

    process = design.process
    spec = design.parts
    parts = list(partset.parts)
    kerf = process.kerf_mm
    cache = SolidCache(partset.chord_tolerance_mm)
    files: dict[str, bytes] = {}
    entries: list[dict[str, Any]] = []
    plate_area = (float(process.build_volume_mm[0]), float(process.build_volume_mm[1]))
    plate = plate_layout(parts, cache, plate_area, spec.plate_spacing_mm)
    sheet = sheet_layout(parts, kerf, plate_area, spec.sheet_margin_mm, spec.sheet_spacing_mm)
    with_step = step_available()  # optional extra `cad` (OCP); without it no STEP files, "step": None
    for part, on_plate, on_sheet in zip(parts, plate, sheet, strict=True):
        stl_path, dxf_path = f"parts/{part.name}.stl", f"parts/{part.name}.dxf"
        stl = part_stl(part, cache)
        problems = validate_stl(stl)
        vertices, faces = cache.flat_mesh(part)
        if problems:
            raise GeometryError(f"part {part.name}: STL {', '.join(problems)}")
        files[stl_path] = stl
        files[dxf_path] = part_dxf(part, kerf)
        entries.append({
            "name": part.name, "process": part.process, "stl": stl_path, "dxf": dxf_path,
            "step": f"parts/{part.name}.step" if with_step else None,
            "volume_mm3": round(part.volume_mm3(), 4), "stl_volume_mm3": round(mesh_volume(vertices, faces), 4),
            "layer": part.layer,
            "holes": [{"joint": h.joint, "diameter_mm": round(h.diameter_mm, 6),
                       "cut_diameter_mm": round(h.diameter_mm - kerf, 6)} for h in part.holes],
            "role": part.role, "body": part.body, "thickness_mm": part.thickness_mm,
            "z_mm": round(part.z_mm, 6), "area_mm2": round(part.area_mm2(), 4), "gear": part.gear,
            "slots": len(getattr(part, "slots", ())), "stl_problems": problems,
            "plate": {"index": on_plate.sheet, "fits": fits(on_plate, plate_area, spec.plate_spacing_mm)},
            "sheet": {"index": on_sheet.sheet, "fits": fits(on_sheet, plate_area, spec.sheet_margin_mm)},
            "warnings": [w for w in getattr(partset, "warnings", ()) if w.startswith(f"part {part.name}:")],
        })
    files["print_plate.stl"] = print_plate_stl(parts, cache, plate, plate_area)
    first = motion.poses_at(0)
    files["assembly.3mf"] = assembly_3mf(parts, cache, first, title=design.name)
    if with_step:
        files.update(step_files(parts, first, partset.chord_tolerance_mm, title=design.name))
    files["sheet.dxf"] = sheet_dxf(parts, kerf, sheet, plate_area)
    files["kinematic.dxf"] = kinematic_dxf(mechanism, first)
    if previews:
        files.update(export_previews(design, partset, motion))
    files["bom.csv"] = _bom_csv(list(partset.bom))
    return files, entries


def export_previews(design: Any, partset: Any, motion: Any) -> dict[str, bytes]:
    """The assembly at several poses (PNG) and its motion (GIF), keyed by relative path."""
    from fabricate.export.previews import assembly_png, motion_gif

    parts = list(partset.parts)
    spec = design.parts
    tip = partset.hints.get("tip_point") if hasattr(partset, "hints") else None
    return {"previews/assembly.png": assembly_png(parts, motion, spec.preview_poses, tip, title=design.name),
            "previews/motion.gif": motion_gif(parts, motion, spec.gif_frames)}
