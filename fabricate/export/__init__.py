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

#: bom.csv's leading columns; any other key of the report's BOM rows follows, sorted by name.
BOM_COLUMNS = ("item", "kind", "qty", "process", "material", "thickness_mm", "volume_mm3", "mass_g",
               "diameter_mm", "length_mm", "inner_diameter_mm", "outer_diameter_mm", "rate_Nmm_per_deg",
               "preload_deg", "legs_mm", "shared", "joints", "description")


def _bom_csv(rows: list[dict[str, Any]]) -> bytes:
    """bom.csv: every column of the report's BOM (empty where a row has no such value)."""
    present = {k for row in rows for k in row}
    columns = [c for c in BOM_COLUMNS if c in present] + sorted(present - set(BOM_COLUMNS))
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([" ".join(map(str, row[c])) if isinstance(row.get(c), list)
                         else ("" if row.get(c) is None else row[c]) for c in columns])
    return buffer.getvalue().encode("utf-8")


def assembly_csv(stacks: list[Any]) -> bytes:
    """assembly.csv: one row per item on a pin, bottom to top (pin, position, item, kind, z in mm)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["pin", "position", "item", "kind", "z_bottom_mm", "z_top_mm", "pin_diameter_mm",
                     "pin_length_mm"])
    for stack in stacks:
        for k, item in enumerate(stack.items, start=1):
            writer.writerow([stack.pin, k, item.item, item.kind, f"{item.z_mm[0]:.3f}", f"{item.z_mm[1]:.3f}",
                             f"{stack.diameter_mm:g}", f"{stack.length_mm:.3f}"])
    return buffer.getvalue().encode("utf-8")


def motion_csv(mechanism: Any, motion: Any) -> bytes:
    """motion.csv: column ``input`` (the mechanism's input unit), then ``NAME_x``, ``NAME_y`` (mm, world) of
    every named point in body order, one row per swept pose. A point shared by several bodies (a joint) is
    taken from its first body; the solver holds the others on it to 1e-12 mm."""
    names = mechanism.point_names()
    columns = [motion.inputs] + [c for name in names for c in motion.point(name).T]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["input"] + [f"{name}_{axis}" for name in names for axis in ("x", "y")])
    for row in zip(*columns, strict=True):
        # 1 nm in mm (and 1e-6 of the input unit): far below any machine's resolution, and stable bytes
        writer.writerow([f"{float(v):.6f}" for v in row])
    return buffer.getvalue().encode("utf-8")


def export_all(design: Any, partset: Any, mechanism: Any, motion: Any, previews: bool = True,
               step: bool = True, with_step: bool | None = None) -> tuple[dict[str, bytes], list[dict[str, Any]]]:
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
    step : bool
        Include the STEP files when OCP is installed (the pipeline makes them separately, see
        :func:`export_step`); the report names their paths either way.
    with_step : bool, optional
        Whether STEP files are part of this build (default: whether OCP is installed); ``fabricate check``
        rebuilds with the answer the folder's build recorded.

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
    from fabricate.export.dxf import DxfStyle, kinematic_dxf, part_dxf, sheet_dxf, sheet_layout
    from fabricate.export.step import step_available
    from fabricate.export.stl import (
        SolidCache,
        assembly_3mf,
        mesh_volume,
        model_3mf,
        part_stl,
        placed_flat_mesh,
        plate_layout,
        plate_stl,
        validate_stl,
    )
    from fabricate.export.svg import part_svg, sheet_svg

    process = design.process
    spec = design.parts
    parts = list(partset.parts)
    copies = max(1, int(getattr(partset, "copies", 1) or 1))
    laser = process.name == "laser"  # cut sheets, else print plates
    kerf = process.kerf_mm
    min_text = float(getattr(process, "min_text_mm", 0.0))
    arcs = getattr(process, "arcs", "bulge")
    drawing = DxfStyle(arcs, partset.chord_tolerance_mm)  # for CAD: every label
    cutting = DxfStyle(arcs, partset.chord_tolerance_mm, min_text)  # only labels the process can engrave
    colours = (getattr(process, "cut_colour", "#ff0000"), getattr(process, "engrave_colour", "#0000ff"))
    cache = SolidCache(partset.chord_tolerance_mm)
    files: dict[str, bytes] = {}
    entries: list[dict[str, Any]] = []
    area = (float(process.build_volume_mm[0]), float(process.build_volume_mm[1]))
    # every copy of every part is made: a three-finger gripper prints or cuts three finger sets
    made = [part for part in parts for _ in range(copies)]
    if laser:
        margin = spec.sheet_margin_mm
        placements = sheet_layout(made, kerf, area, margin, spec.sheet_spacing_mm)
    else:
        margin = spec.plate_spacing_mm
        placements = plate_layout(made, cache, area, margin)
    where: dict[str, list[Any]] = {}
    for part, placement in zip(made, placements, strict=True):
        where.setdefault(part.name, []).append(placement)
    if with_step is None:  # optional extra `cad` (OCP); without it no STEP files, "step": None
        with_step = step_available()
    for part in parts:
        stl_path, dxf_path = f"parts/{part.name}.stl", f"drawings/{part.name}.dxf"
        stl = part_stl(part, cache)
        problems = validate_stl(stl)
        vertices, faces = cache.flat_mesh(part)
        if problems:
            raise GeometryError(f"part {part.name}: STL {', '.join(problems)}")
        files[stl_path] = stl
        files[dxf_path] = part_dxf(part, 0.0, drawing)  # finished size, for CAD
        cut_dxf = cut_svg = None
        if laser:
            cut_dxf, cut_svg = f"cut/{part.name}.dxf", f"cut/{part.name}.svg"
            files[cut_dxf] = part_dxf(part, kerf, cutting)
            files[cut_svg] = part_svg(part, kerf, min_text_mm=min_text, colours=colours)
        placed = where[part.name]
        entries.append({
            "name": part.name, "process": part.process, "stl": stl_path, "dxf": dxf_path,
            "cut_dxf": cut_dxf, "cut_svg": cut_svg,
            "step": f"parts/{part.name}.step" if with_step else None,
            "copies": copies,
            "volume_mm3": round(part.volume_mm3(), 4), "stl_volume_mm3": round(mesh_volume(vertices, faces), 4),
            "layer": part.layer,
            "holes": [{"joint": h.joint, "diameter_mm": round(h.diameter_mm, 6),
                       "cut_diameter_mm": round(h.diameter_mm - kerf, 6)} for h in part.holes],
            "role": part.role, "body": part.body, "thickness_mm": part.thickness_mm,
            "z_mm": round(part.z_mm, 6), "area_mm2": round(part.area_mm2(), 4), "gear": part.gear,
            "slots": len(getattr(part, "slots", ())), "stl_problems": problems,
            ("sheet" if laser else "plate"): {"index": [pl.sheet + 1 for pl in placed],
                                              "fits": all(fits(pl, area, margin) for pl in placed)},
            "warnings": [w for w in getattr(partset, "warnings", ()) if w.startswith(f"part {part.name}:")],
        })
    for number in sorted({pl.sheet for pl in placements}):
        on_it = [(part, pl, k) for k, (part, pl) in enumerate(zip(made, placements, strict=True))
                 if pl.sheet == number]
        if laser:
            sheet_parts, sheet_places = [part for part, _, _ in on_it], [pl for _, pl, _ in on_it]
            files[f"cut/sheet_{number + 1}.dxf"] = sheet_dxf(sheet_parts, kerf, sheet_places, area, number, cutting)
            files[f"cut/sheet_{number + 1}.svg"] = sheet_svg(sheet_parts, kerf, sheet_places, area, number,
                                                             title=f"{design.name} sheet", min_text_mm=min_text,
                                                             colours=colours)
        else:
            meshes = [placed_flat_mesh(part, cache, pl) for part, pl, _ in on_it]
            names = [copy_name(part.name, k % copies, copies) for part, _, k in on_it]
            files[f"plates/plate_{number + 1}.stl"] = plate_stl(meshes)
            files[f"plates/plate_{number + 1}.3mf"] = model_3mf(
                [(name, *mesh) for name, mesh in zip(names, meshes, strict=True)], f"{design.name} plate {number + 1}")
    first = motion.poses_at(0)
    files["assembly.3mf"] = assembly_3mf(parts, cache, first, title=design.name)
    if with_step and step:
        files.update(export_step(design, partset, motion))
    files["drawings/kinematic.dxf"] = kinematic_dxf(mechanism, first)
    if previews:
        files.update(export_previews(design, partset, motion))
    files["bom.csv"] = _bom_csv(list(partset.bom))
    return files, entries


def copy_name(name: str, index: int, copies: int) -> str:
    """How a plate's 3MF names copy ``index`` (from 0) of a part made ``copies`` times."""
    return name if copies == 1 else f"{name} ({index + 1} of {copies})"


def export_step(design: Any, partset: Any, motion: Any) -> dict[str, bytes]:
    """``parts/NAME.step`` and ``assembly.step`` (B-rep solids, first pose); empty without OCP."""
    from fabricate.export.step import step_available, step_files

    if not step_available():
        return {}
    return step_files(list(partset.parts), motion.poses_at(0), partset.chord_tolerance_mm, title=design.name)


#: What a build says when the optional ``cad`` extra is missing.
STEP_SKIPPED = "STEP skipped: OCP is not installed (pip install 'fabricate[cad]' for parts/*.step and assembly.step)"


def export_previews(design: Any, partset: Any, motion: Any) -> dict[str, bytes]:
    """The assembly at several poses (PNG) and its motion (GIF), keyed by relative path."""
    from fabricate.export.previews import assembly_png, exploded_png, motion_gif
    from fabricate.parts.assembly import pin_stacks

    parts = list(partset.parts)
    spec = design.parts
    tip = partset.hints.get("tip_point") if hasattr(partset, "hints") else None
    return {"previews/assembly.png": assembly_png(parts, motion, spec.preview_poses, tip, title=design.name),
            "previews/exploded.png": exploded_png(parts, motion.poses_at(0), pin_stacks(partset), title=design.name),
            "previews/motion.gif": motion_gif(parts, motion, spec.gif_frames)}
