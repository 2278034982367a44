"""Exporters: parts to STL / 3MF (printing), DXF and SVG (cutting and CAD), preview pictures, bill of materials.

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
``cut/sheet_N.dxf|.svg``   laser builds: the parts nested on the smallest standard sheet that holds them,
                           labelled with text outlines on ENGRAVE (report.json's ``cut``)
``kinematic.dxf``          joints, link centre lines and dimensions at the first pose
``previews/assembly.png``  the assembly at several poses
``previews/motion.gif``    the motion
``bom.csv``                the bill of materials
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from fabricate.errors import GeometryError
from fabricate.export.layout import Placement, fits

if TYPE_CHECKING:  # ezdxf loads with fabricate.export.dxf: only when a DXF is made
    from fabricate.export.dxf import DxfStyle, Sheet
    from fabricate.export.labels import PartLabel
    from fabricate.export.stl import SolidCache
    from fabricate.mechanism import Mechanism, Motion
    from fabricate.parts.assembly import PinStack
    from fabricate.parts.model import Part
    from fabricate.parts.partset import PartSet
    from fabricate.spec import DesignSpec

#: bom.csv's leading columns; any other key of the report's BOM rows follows, sorted by name.
BOM_COLUMNS = ("item", "designation", "kind", "source", "qty", "process", "material", "thickness_mm", "volume_mm3",
               "mass_g", "diameter_mm", "length_mm", "inner_diameter_mm", "outer_diameter_mm", "rate_Nmm_per_deg",
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


def assembly_csv(stacks: list[PinStack]) -> bytes:
    """assembly.csv: one row per item on a pin, bottom to top (pin, position, item, kind, z in mm, note).

    ``item`` is the BOM's name for it (a part's name, the hardware's item); how it sits where that is not
    through a hole ("in its slot") is the ``note``, so the column can be looked up in bom.csv as it is.
    """
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["pin", "position", "item", "kind", "z_bottom_mm", "z_top_mm", "pin_diameter_mm",
                     "pin_length_mm", "note"])
    for stack in stacks:
        for k, item in enumerate(stack.items, start=1):
            writer.writerow([stack.pin, k, item.item, item.kind, f"{item.z_mm[0]:.3f}", f"{item.z_mm[1]:.3f}",
                             f"{stack.diameter_mm:g}", f"{stack.length_mm:.3f}", item.note])
    return buffer.getvalue().encode("utf-8")


def motion_csv(mechanism: Mechanism, motion: Motion) -> bytes:
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


def export_all(design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion, previews: bool = True,
               step: bool = True, with_step: bool | None = None, sections: dict[str, Any] | None = None,
               keep: Callable[[Callable[[], PartFiles]], PartFiles] | None = None
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
    step : bool
        Include the STEP files when OCP is installed (the pipeline makes them separately, see
        :func:`export_step`); the report names their paths either way.
    with_step : bool, optional
        Whether STEP files are part of this build (default: whether OCP is installed); ``fabricate check``
        rebuilds with the answer the folder's build recorded.
    sections : dict, optional
        The report: a cut process adds its ``cut`` section to it (:func:`cut_section`: sheets and their
        utilisation, every part's number and label, the parts left unlabelled).
    keep : callable, optional
        Given the function that makes :func:`export_part_files`' result, returns that result: the pipeline's
        stage cache (the part files read no layout field, so a layout edit is served them). Default: make it.

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
    from fabricate.export.step import step_available
    from fabricate.export.stl import SolidCache

    if with_step is None:  # optional extra `cad` (OCP); without it no STEP files, "step": None
        with_step = step_available()
    solids = SolidCache(partset.chord_tolerance_mm)  # the parts' meshes, for their files and the plates
    made = (keep or (lambda make: make()))(lambda: export_part_files(design, partset, mechanism, motion, solids))
    files = dict(made.files)
    layout, entries = export_layout(design, partset, made, with_step, sections, solids)
    files.update(layout)
    if with_step and step:
        files.update(export_step(design, partset, motion))
    if previews:
        files.update(export_previews(design, partset, motion))
    return files, entries


@dataclass(frozen=True)
class PartFiles:
    """What :func:`export_part_files` makes: everything but the plate or sheet layout.

    Attributes
    ----------
    files : dict[str, bytes]
        Every part's STL and drawing (and a cut process's cut path), assembly.3mf, the kinematic drawing, bom.csv.
    made : dict[str, tuple[list[str], float]]
        Per part: its STL's problems (always none: a bad STL raises) and the polygonised solid's volume (mm^3).
    labels : dict[str, PartLabel]
        A cut process's label of every part (none for a printer).
    """

    files: dict[str, bytes]
    made: dict[str, tuple[list[str], float]]
    labels: dict[str, PartLabel]


def export_part_files(design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion,
                      solids: SolidCache | None = None) -> PartFiles:
    """The exports that do not depend on the plate or sheet layout (``[parts]``' layout fields are not read: a
    layout edit reuses them, see :func:`export_layout`). ``solids``: the parts' meshes, shared with the layout."""
    from fabricate.export.kinematic import kinematic_dxf
    from fabricate.export.stl import SolidCache, assembly_3mf

    making = _Making.of(design, partset, layout=False)
    cache = solids if solids is not None else SolidCache(partset.chord_tolerance_mm)
    parts = list(partset.parts)
    labels = _labels(parts, making)
    files: dict[str, bytes] = {}
    made: dict[str, tuple[list[str], float]] = {}
    for part in parts:
        part_files, problems, stl_volume = _part_files(part, making, cache, labels.get(part.name))
        files.update(part_files)
        made[part.name] = (problems, stl_volume)
    first = motion.poses_at(0)
    files["assembly.3mf"] = assembly_3mf(parts, cache, first, title=design.name)
    files["drawings/kinematic.dxf"] = kinematic_dxf(mechanism, first)
    files["bom.csv"] = _bom_csv(list(partset.bom))
    return PartFiles(files, made, labels)


def export_layout(design: DesignSpec, partset: PartSet, made: PartFiles, with_step: bool,
                  sections: dict[str, Any] | None = None, solids: SolidCache | None = None
                  ) -> tuple[dict[str, bytes], list[dict[str, Any]]]:
    """The plates or sheets of every copy of every part, and the report's ``parts`` entries (where each copy
    went); a cut process's ``cut`` section into ``sections``. ``made``: :func:`export_part_files`' result."""
    from fabricate.export.stl import SolidCache

    making = _Making.of(design, partset)
    cache = solids if solids is not None else SolidCache(partset.chord_tolerance_mm)
    parts = list(partset.parts)
    # every copy of every part is made: a three-finger gripper prints or cuts three finger sets
    copies = [part for part in parts for _ in range(making.copies)]
    placements, sheets = _lay_out(copies, making, cache)
    where: dict[str, list[Placement]] = {}
    for part, placement in zip(copies, placements, strict=True):
        where.setdefault(part.name, []).append(placement)
    entries = [_part_entry(part, *made.made[part.name], where[part.name], making, with_step,
                           getattr(partset, "warnings", ()), sheets) for part in parts]
    files = _layout_files(copies, placements, making, cache, design.name, sheets, made.labels)
    if sections is not None and making.cut:
        sections["cut"] = cut_section(sheets, made.labels)
    return files, entries


@dataclass(frozen=True)
class _NoLayout:
    """``[parts]``' layout fields for :meth:`_Making.of` when the exports at hand lay nothing out."""

    sheet_margin_mm: float = 0.0
    plate_spacing_mm: float = 0.0
    sheet_spacing_mm: float = 0.0


_NO_LAYOUT = _NoLayout()


@dataclass(frozen=True)
class _Making:
    """How the parts are made, as the exporters need it: the process's capabilities and the layout settings.

    Attributes
    ----------
    cut : bool
        The process cuts (``technique = "cut"``): each part also gets its kerf-offset cut path.
    sheets : bool
        Parts are nested on sheets (``layout = "sheet"``: sheet DXF and SVG), else laid out on print plates
        (plate STL and 3MF).
    kerf_mm, min_text_mm : float
    area_mm : (float, float)
        The sheet or the build plate.
    margin_mm : float
        The sheet's edge margin, or the gap between parts on a plate (``[parts]``).
    spacing_mm : float
        The gap between parts on a sheet.
    copies : int
        Identical copies of every part.
    drawing, cutting : DxfStyle
        DXF for CAD (every label, as TEXT), and for the cutter (labels as outlines, only those the process
        can engrave).
    colours : (str, str)
        SVG strokes of cuts and of engraving.
    stock : tuple of (name, width, height)
        The process's standard sheets (``ProcessSpec.sheets``; empty: the sheet is ``area_mm``).
    label_margin_mm : float
        How far a label keeps inside its part (the process's smallest feature).
    """

    cut: bool
    sheets: bool
    kerf_mm: float
    min_text_mm: float
    area_mm: tuple[float, float]
    margin_mm: float
    spacing_mm: float
    copies: int
    drawing: DxfStyle
    cutting: DxfStyle
    colours: tuple[str, str]
    stock: tuple[tuple[str, float, float], ...] = ()
    label_margin_mm: float = 0.5

    @classmethod
    def of(cls, design: DesignSpec, partset: PartSet, layout: bool = True) -> _Making:
        """The making of ``design``'s parts; ``layout=False`` leaves ``[parts]``' layout fields unread (margin
        and spacing 0: for the exports that do not lay parts out)."""
        from fabricate.export.dxf import DxfStyle

        process = design.process
        spec = design.parts if layout else _NO_LAYOUT
        sheets = process.layout == "sheet"
        tol, min_text = partset.chord_tolerance_mm, float(process.min_text_mm)
        return cls(cut=process.technique == "cut", sheets=sheets, kerf_mm=process.kerf_mm, min_text_mm=min_text,
                   area_mm=(float(process.build_volume_mm[0]), float(process.build_volume_mm[1])),
                   margin_mm=spec.sheet_margin_mm if sheets else spec.plate_spacing_mm,
                   spacing_mm=spec.sheet_spacing_mm, copies=max(1, int(getattr(partset, "copies", 1) or 1)),
                   drawing=DxfStyle(process.arcs, tol, hole_labels=True),
                   cutting=DxfStyle(process.arcs, tol, min_text, labels="outlines",
                                    label_margin_mm=float(process.min_feature_mm)),
                   colours=(process.cut_colour, process.engrave_colour),
                   stock=tuple(getattr(process, "sheets", ())), label_margin_mm=float(process.min_feature_mm))


def _lay_out(made: list[Part], making: _Making, cache: SolidCache) -> tuple[list[Placement], list[Sheet]]:
    """Where every made part goes: nested on sheets (by its cut outline, each sheet the smallest standard
    stock that holds its parts), or laid out on print plates (no sheets)."""
    if making.sheets:
        from fabricate.export.dxf import sized_sheets

        return sized_sheets(made, making.kerf_mm, making.stock, making.area_mm, making.margin_mm, making.spacing_mm)
    from fabricate.export.stl import plate_layout

    return plate_layout(made, cache, making.area_mm, making.margin_mm), []


def _labels(parts: list[Part], making: _Making) -> dict[str, PartLabel]:
    """A cut process's label of every part (its name, else its number, else none); none for a printer."""
    if not making.cut:
        return {}
    from fabricate.export.labels import label_parts

    return label_parts(parts, making.min_text_mm, making.label_margin_mm)


def cut_section(sheets: Sequence[Sheet], labels: dict[str, PartLabel]) -> dict[str, Any]:
    """report.json's ``cut``: every sheet with its stock, size and utilisation (part area / sheet area), the
    overall utilisation, every part's number and engraved label (the key from number to name), and the parts
    left unlabelled (no room even for the number)."""
    area = sum(s.size_mm[0] * s.size_mm[1] for s in sheets)
    return {"sheets": [s.report() for s in sheets],
            "utilisation": round(sum(s.part_area_mm2 for s in sheets) / area, 4) if area else None,
            "labels": [label.report() for label in labels.values()],
            "unlabelled": [name for name, label in labels.items() if label.label is None]}


def _part_files(part: Part, making: _Making, cache: SolidCache,
                label: PartLabel | None = None) -> tuple[dict[str, bytes], list[str], float]:
    """A part's own files: its STL, its DXF at finished size (for CAD) and, for a cut process, its cut path.

    Returns
    -------
    files : dict[str, bytes]
    stl_problems : list of str
        Always empty: a written STL that does not read back as a closed solid raises.
    stl_volume_mm3 : float
        The polygonised solid's volume.
    """
    from fabricate.export.dxf import part_dxf
    from fabricate.export.stl import mesh_volume, part_stl, validate_stl
    from fabricate.export.svg import part_svg

    stl = part_stl(part, cache)
    problems = validate_stl(stl)
    vertices, faces = cache.flat_mesh(part)
    if problems:
        raise GeometryError(f"part {part.name}: STL {', '.join(problems)}")
    files = {f"parts/{part.name}.stl": stl, f"drawings/{part.name}.dxf": part_dxf(part, 0.0, making.drawing)}
    if making.cut:
        engraved = _engraved(label)
        files[f"cut/{part.name}.dxf"] = part_dxf(part, making.kerf_mm, making.cutting, label=engraved)
        files[f"cut/{part.name}.svg"] = part_svg(part, making.kerf_mm, min_text_mm=making.min_text_mm,
                                                 colours=making.colours, label=engraved)
    return files, problems, mesh_volume(vertices, faces)


def _part_entry(part: Part, problems: list[str], stl_volume: float, placed: list[Placement], making: _Making,
                with_step: bool, warnings: Sequence[str], sheets: Sequence[Sheet] = ()) -> dict[str, Any]:
    """A part's entry in the report's ``parts`` (see :func:`export_all`); ``placed``: where its copies went,
    ``sheets``: the laser layout's sheets (each copy fits its own sheet's size)."""
    from fabricate.export.dxf import cut_area

    kerf = making.kerf_mm
    cut_dxf, cut_svg = (f"cut/{part.name}.dxf", f"cut/{part.name}.svg") if making.cut else (None, None)
    entry: dict[str, Any] = {
        "name": part.name, "process": part.process, "stl": f"parts/{part.name}.stl",
        "dxf": f"drawings/{part.name}.dxf", "cut_dxf": cut_dxf, "cut_svg": cut_svg,
        "step": f"parts/{part.name}.step" if with_step else None,
        "copies": making.copies,
        "volume_mm3": round(part.volume_mm3(), 4), "stl_volume_mm3": round(stl_volume, 4),
        "layer": part.layer,
        "holes": [{"joint": h.joint, "diameter_mm": round(h.diameter_mm, 6),
                   "cut_diameter_mm": round(h.diameter_mm - kerf, 6), "fit": h.fit,
                   "nominal_diameter_mm": round(h.nominal_mm, 6)} for h in part.holes],
        "role": part.role, "body": part.body, "thickness_mm": part.thickness_mm,
        "z_mm": round(part.z_mm, 6), "area_mm2": round(part.area_mm2(), 4), "gear": part.gear,
        "slots": len(getattr(part, "slots", ())), "stl_problems": problems,
        ("sheet" if making.sheets else "plate"): {
            "index": [pl.sheet + 1 for pl in placed],
            "fits": all(fits(pl, sheets[pl.sheet].size_mm if sheets else making.area_mm, making.margin_mm)
                        for pl in placed)},
        "warnings": [w for w in warnings if w.startswith(f"part {part.name}:")],
    }
    if making.cut:  # what a reader of the cut DXF's layer CUT measures (kerf applied)
        entry["cut_area_mm2"] = round(cut_area(part, kerf), 4)
    return entry


def _layout_files(made: list[Part], placements: list[Placement], making: _Making, cache: SolidCache,
                  title: str, sheets: Sequence[Sheet] = (),
                  labels: dict[str, PartLabel] | None = None) -> dict[str, bytes]:
    """One file pair per sheet (cut DXF and SVG, each the size of its sheet) or per print plate (STL and 3MF,
    each copy named)."""
    from fabricate.export.dxf import sheet_dxf
    from fabricate.export.stl import model_3mf, placed_flat_mesh, plate_stl
    from fabricate.export.svg import sheet_svg

    files: dict[str, bytes] = {}
    kerf, area, copies = making.kerf_mm, making.area_mm, making.copies
    for number in sorted({pl.sheet for pl in placements}):
        on_it = [(part, pl, k) for k, (part, pl) in enumerate(zip(made, placements, strict=True))
                 if pl.sheet == number]
        if making.sheets:
            sheet_parts, sheet_places = [part for part, _, _ in on_it], [pl for _, pl, _ in on_it]
            size = sheets[number].size_mm if sheets else area
            engraved = [_engraved((labels or {}).get(part.name)) for part in sheet_parts]
            files[f"cut/sheet_{number + 1}.dxf"] = sheet_dxf(sheet_parts, kerf, sheet_places, size, number,
                                                             making.cutting, labels=engraved)
            files[f"cut/sheet_{number + 1}.svg"] = sheet_svg(sheet_parts, kerf, sheet_places, size, number,
                                                             title=f"{title} sheet", min_text_mm=making.min_text_mm,
                                                             colours=making.colours, labels=engraved)
        else:
            meshes = [placed_flat_mesh(part, cache, pl) for part, pl, _ in on_it]
            names = [copy_name(part.name, k % copies, copies) for part, _, k in on_it]
            files[f"plates/plate_{number + 1}.stl"] = plate_stl(meshes)
            files[f"plates/plate_{number + 1}.3mf"] = model_3mf(
                [(name, *mesh) for name, mesh in zip(names, meshes, strict=True)], f"{title} plate {number + 1}")
    return files


def _engraved(label: PartLabel | None) -> Any:
    """What a cut file engraves on a part: its placed label, "" (none) when it has no room for one, None (the
    writer's default) when no label was worked out."""
    if label is None:
        return None
    return label.label if label.label is not None else ""


def copy_name(name: str, index: int, copies: int) -> str:
    """How a plate's 3MF names copy ``index`` (from 0) of a part made ``copies`` times."""
    return name if copies == 1 else f"{name} ({index + 1} of {copies})"


def prestart_step() -> None:
    """Start the STEP worker now, where OCP is installed: it imports OCP (about 1 s) on a core the build
    leaves idle, and :func:`export_step` finds it ready (:func:`fabricate.background.prestart`)."""
    from fabricate.background import prestart
    from fabricate.export.step import step_available

    if step_available():
        prestart("fabricate.export.step", "_import_ocp")


def export_step(design: DesignSpec, partset: PartSet, motion: Motion) -> dict[str, bytes]:
    """``parts/NAME.step`` and ``assembly.step`` (B-rep solids, first pose); empty without OCP."""
    from fabricate.background import run_isolated
    from fabricate.export.step import step_available

    if not step_available():
        return {}
    # in a fresh process: OCP's 220 MB stay out of the processes holding the rest of the build
    files: dict[str, bytes] = run_isolated("fabricate.export.step", "step_files", list(partset.parts),
                                           motion.poses_at(0), partset.chord_tolerance_mm, design.name)
    return files


#: What a build says when the optional ``cad`` extra is missing.
STEP_SKIPPED = "STEP skipped: OCP is not installed (pip install 'fabricate[cad]' for parts/*.step and assembly.step)"


def export_previews(design: DesignSpec, partset: PartSet, motion: Motion) -> dict[str, bytes]:
    """The assembly at several poses (PNG) and its motion (GIF), keyed by relative path."""
    from fabricate.export.previews import assembly_png, exploded_png, motion_gif
    from fabricate.parts.assembly import pin_stacks

    parts = list(partset.parts)
    spec = design.parts
    tip = partset.hints.tip_point
    return {"previews/assembly.png": assembly_png(parts, motion, spec.preview_poses, tip, title=design.name),
            "previews/exploded.png": exploded_png(parts, motion.poses_at(0), pin_stacks(partset), title=design.name),
            "previews/motion.gif": motion_gif(parts, motion, spec.gif_frames)}
