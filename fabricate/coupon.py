"""Calibration coupons: a small test piece per process that measures the profile's fits on the user's machine.

``fabricate coupon --process P`` makes one plate, the process's stock thickness, holding:

- a row (or two) of pin holes whose NOMINAL diameters are the profile's pin plus a labelled diametral
  clearance, press to loose (:data:`CLEARANCES_MM`, -0.15 ... +0.60 mm); each hole is modelled as the
  profile models a hole (nominal plus ``hole_compensation_mm``; a cut hole's path is shrunk by the kerf), so
  what the made coupon measures tells how the profile's numbers come out on this machine;
- a rack along its lower edge at the process's module (the smallest standard module whose basic-rack tip
  land the process resolves, as ``gears.module_mm = "auto"`` bounds it: :func:`process_module`), cut with
  the basic rack of :func:`fabricate.gears.rack.basic_rack`;
- for a cut process, a kerf comb: closed slots of nominal widths round the sheet thickness
  (:data:`SLOT_OFFSETS_MM`), kerf-compensated like every cut slot.

Every hole and slot is labelled with its clearance: embossed text outlines on the top face of a printed
coupon, engraved outlines (never text entities) in a cut one (:mod:`fabricate.export.labels`). The README
written beside the files says what to measure and which profile field each measurement sets; ``fabricate init
--process P`` writes the profile copy to edit. Everything here is pure: :func:`coupon_files` returns the
files' bytes, the CLI writes them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry.polygon import orient

from fabricate.errors import SpecError
from fabricate.export.labels import Label, text_box
from fabricate.parts.model import BulgePath, Hole
from fabricate.parts.partset import SlottedPart
from fabricate.process import ProcessSpec

#: Diametral clearances (mm) of the pin holes, over the pin: negative is an interference (press fit).
CLEARANCES_MM = tuple(round(-0.15 + 0.05 * k, 2) for k in range(16))
#: Holes per row.
ROW = 8
#: Nominal slot widths of the kerf comb: the sheet thickness plus these (mm).
SLOT_OFFSETS_MM = (-0.2, -0.1, 0.0, 0.1, 0.2)
#: Slot length (mm): a corner of a scrap of the same sheet goes in.
SLOT_LENGTH_MM = 10.0
#: Height of the embossed labels of a printed coupon above its top face (mm: 3 FDM layers of 0.2, 12 SLA layers).
EMBOSS_MM = 0.6
#: Smallest label cap height (mm) used even where the process engraves smaller.
LABEL_MM = 2.0
#: The basic rack of ``[gears]`` by default (fabricate/gears/spec.py): pressure angle (deg), addendum and
#: dedendum (x module).
PRESSURE_ANGLE_DEG, ADDENDUM, DEDENDUM = 20.0, 1.0, 1.25
#: Teeth of the rack strip (at most; fewer where the coupon is shorter).
RACK_TEETH = 12


def clearance_label(clearance_mm: float) -> str:
    """A clearance as engraved: ``"-.15"``, ``"0"``, ``"+.30"`` (diametral, mm)."""
    if abs(clearance_mm) < 1e-9:
        return "0"
    return f"{clearance_mm:+.2f}".replace("0.", ".", 1)


def process_module(process: ProcessSpec) -> float:
    """The smallest standard module (DIN 780-1) whose basic-rack tooth tip land, ``m (pi/2 - 2 h_a tan alpha)``,
    is at least the process's ``min_feature_mm`` (the bound ``gears.module_mm = "auto"`` starts from)."""
    from fabricate.gears.auto import standard_modules

    factor = math.pi / 2.0 - 2.0 * ADDENDUM * math.tan(math.radians(PRESSURE_ANGLE_DEG))
    for module in standard_modules():
        if module * factor >= process.min_feature_mm - 1e-9:
            return float(module)
    raise SpecError("min_feature_mm", f"no standard module makes a tooth tip of {process.min_feature_mm:g} mm")


@dataclass(frozen=True)
class Feature:
    """One measured feature of a coupon.

    Attributes
    ----------
    kind : str
        ``"hole"`` or ``"slot"``.
    label : str
        What is engraved beside it.
    nominal_mm : float
        The finished size it should measure (hole diameter, slot width).
    modelled_mm : float
        The size in the STL/3MF (nominal plus the hole compensation) or, for a cut, the finished size the
        kerf-offset path leaves.
    offset_mm : float
        Its clearance over the pin (hole) or over the sheet thickness (slot), diametral.
    centre : (2,) array
    """

    kind: str
    label: str
    nominal_mm: float
    modelled_mm: float
    offset_mm: float
    centre: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class Coupon:
    """A coupon: the part, its measured features, its labels and its rack module."""

    part: SlottedPart
    features: tuple[Feature, ...]
    labels: tuple[Label, ...]
    module_mm: float
    process: ProcessSpec


@dataclass(frozen=True)
class _Labels(Label):
    """Several placed labels drawn as one (the exporters engrave one :class:`Label` per part)."""

    members: tuple[Label, ...] = ()

    def polygons(self) -> list[np.ndarray]:
        return [ring for label in self.members for ring in label.polygons()]


def _rack_edge(module: float, x0: float, x1: float) -> np.ndarray:
    """The lower edge of the coupon from x0 to x1 (left to right): rack teeth pointing down (-y), pitch line
    y = 0, tips at -addendum, roots at +dedendum; flat at y = +dedendum beyond the teeth."""
    from fabricate.gears.rack import basic_rack

    # the cutter's period has a cutter tooth (depth h_f) round u = +-p/2 and the gear's tooth space (up to
    # h_a, its flank drawn to h_a + 0.02 m) round u = 0; flipped (v -> -v) the space is the coupon's tooth:
    # tip land at -h_a, root flat at +h_f (ISO 53's basic rack, sharp tip corners)
    profile = basic_rack(module, math.radians(PRESSURE_ANGLE_DEG), DEDENDUM, 0.0, ADDENDUM - 0.02,
                         flank_points=2, flat_points=2)
    period = profile.points * [1.0, -1.0]
    pitch = profile.pitch
    teeth = max(2, min(RACK_TEETH, int((x1 - x0) // pitch) - 1))
    start = 0.5 * (x0 + x1) - 0.5 * teeth * pitch  # whole teeth centred on the edge
    # a period runs over [-p/2, p/2) round its tooth: periods joined end to end, then the last space's end
    rows = [np.array([[x0, DEDENDUM * module]])]
    for k in range(teeth):
        rows.append(period + [start + (k + 0.5) * pitch, 0.0])
    rows.append(np.array([[start + teeth * pitch, DEDENDUM * module], [x1, DEDENDUM * module]]))
    edge = np.concatenate(rows)
    # points repeated where a run meets the flat ends
    keep = np.concatenate([[True], np.any(np.diff(edge, axis=0) != 0.0, axis=1)])
    kept: np.ndarray = edge[keep]
    return kept


def _label(text: str, height: float, centre: tuple[float, float]) -> Label:
    return Label(text, "name", height, np.asarray(centre, dtype=np.float64), 0.0)


def make_coupon(process: ProcessSpec) -> Coupon:
    """The coupon of ``process`` (see the module docstring), in its own coordinates, lower left near 0."""
    cut = process.technique == "cut"
    pin = float(process.pin_diameter_mm)
    comp = 0.0 if cut else float(process.hole_compensation_mm)
    height = max(LABEL_MM, float(process.min_text_mm))
    wall = max(float(process.min_wall_mm), 1.0)
    widest = max(text_box(clearance_label(c))[0] for c in CLEARANCES_MM) * height
    largest = pin + max(CLEARANCES_MM) + comp
    pitch = max(largest + 2.0 * wall, widest + 1.0)
    module = process_module(process)
    rack_top = DEDENDUM * module
    margin = max(wall, 2.0)
    rows = [CLEARANCES_MM[k:k + ROW] for k in range(0, len(CLEARANCES_MM), ROW)]
    row_h = largest + height + 2.0 * wall  # a hole, its label below it, walls
    width = 2.0 * margin + ROW * pitch
    features: list[Feature] = []
    labels: list[Label] = []
    y = rack_top + margin
    slots: list[BulgePath] = []
    if cut:
        t = float(process.thickness_mm)
        slot_pitch = max(t + max(SLOT_OFFSETS_MM) + max(float(process.min_wall_mm), 3.0),
                         max(text_box(clearance_label(o))[0] for o in SLOT_OFFSETS_MM) * height + 1.0)
        width = max(width, 2.0 * margin + len(SLOT_OFFSETS_MM) * slot_pitch)
        x_start = 0.5 * width - 0.5 * (len(SLOT_OFFSETS_MM) - 1) * slot_pitch
        for k, offset in enumerate(SLOT_OFFSETS_MM):
            w = t + offset
            cx, cy = x_start + k * slot_pitch, y + height + wall + 0.5 * SLOT_LENGTH_MM
            corners = np.array([[cx - w / 2, cy - SLOT_LENGTH_MM / 2], [cx + w / 2, cy - SLOT_LENGTH_MM / 2],
                                [cx + w / 2, cy + SLOT_LENGTH_MM / 2], [cx - w / 2, cy + SLOT_LENGTH_MM / 2]])
            slots.append(BulgePath.polyline(corners))
            text = clearance_label(offset)
            features.append(Feature("slot", text, w, w, offset, np.array([cx, cy])))
            labels.append(_label(text, height, (cx, y + 0.5 * height)))
        y += height + 2.0 * wall + SLOT_LENGTH_MM
    holes: list[Hole] = []
    for row in reversed(rows):  # the loosest row lowest, nearest the rack
        x_start = 0.5 * width - 0.5 * (ROW - 1) * pitch
        for k, clearance in enumerate(row):
            nominal = pin + clearance
            cx, cy = x_start + k * pitch, y + height + wall + 0.5 * largest
            text = clearance_label(clearance)
            fit = "press" if clearance < 0 else "running"
            holes.append(Hole(f"c{text}", np.array([cx, cy]), nominal + comp, pin, fit, nominal))
            features.append(Feature("hole", text, nominal, nominal + comp, clearance, np.array([cx, cy])))
            labels.append(_label(text, height, (cx, y + 0.5 * height + 0.5 * wall)))
        y += row_h
    top = y + margin - wall
    edge = _rack_edge(module, 0.0, width)
    outline = np.concatenate([edge, [[width, top], [0.0, top]]])
    part = SlottedPart(name=f"coupon_{process.name}", body="coupon", outline=BulgePath.polyline(outline),
                       holes=tuple(holes), thickness_mm=float(process.thickness_mm), z_mm=0.0, layer=0,
                       process=process.name, role="coupon", slots=tuple(slots))
    return Coupon(part, tuple(features), tuple(labels), module, process)


def _embossed(labels: Sequence[Label], z0: float) -> list[Any]:
    """Solids of the labels' glyphs raised :data:`EMBOSS_MM` from ``z0``: glyph rings (even-odd: a letter's
    counters are rings inside it) become oriented polygons with holes for the solid kernel."""
    from fabricate.parts.solids import extrude_polygons

    solids = []
    for label in labels:
        shape = shapely.Polygon()
        for ring in label.polygons():
            shape = shape.symmetric_difference(shapely.Polygon(ring))
        polys = list(getattr(shape, "geoms", [shape]))
        for poly in polys:
            if poly.is_empty or poly.geom_type != "Polygon":
                continue
            poly = orient(poly, 1.0)  # exterior counter-clockwise, holes clockwise
            rings = [np.asarray(poly.exterior.coords)[:-1]] + [np.asarray(r.coords)[:-1] for r in poly.interiors]
            solids.append(extrude_polygons(rings, EMBOSS_MM, z0, what=f"label {label.text}"))
    return solids


def coupon_files(process: ProcessSpec, source: str = "") -> dict[str, bytes]:
    """The coupon's files: ``coupon.stl`` and ``coupon.3mf`` (additive) or ``coupon.dxf`` and ``coupon.svg``
    (cut), and ``README.md``. ``source`` is what ``--process`` named (for the README's commands).

    Raises
    ------
    SpecError
        The coupon does not fit the process's build area or sheet.
    """
    coupon = make_coupon(process)
    part = coupon.part
    outline = part.outline.vertices
    size = np.ptp(outline, axis=0)
    area = process.build_volume_mm[:2]
    if not ((size[0] <= area[0] and size[1] <= area[1]) or (size[1] <= area[0] and size[0] <= area[1])):
        where = f"the printer {process.printer}" if process.printer else "the process's build_volume_mm"
        raise SpecError("--printer" if process.printer else "build_volume_mm",
                        f"the coupon ({size[0]:.1f} x {size[1]:.1f} mm) does not fit {where} "
                        f"({area[0]:g} x {area[1]:g} mm)")
    engraved = _Labels("clearances", "name", coupon.labels[0].height_mm, np.zeros(2), 0.0, coupon.labels)
    files: dict[str, bytes] = {}
    if process.technique == "cut":
        from fabricate.export.dxf import DxfStyle, part_dxf
        from fabricate.export.svg import part_svg

        style = DxfStyle(arcs=process.arcs, chord_tolerance_mm=process.chord_tolerance_mm,
                         min_text_mm=process.min_text_mm, labels="outlines")
        files["coupon.dxf"] = part_dxf(part, process.kerf_mm, style, label=engraved)
        files["coupon.svg"] = part_svg(part, process.kerf_mm, min_text_mm=process.min_text_mm,
                                       colours=(process.cut_colour, process.engrave_colour), label=engraved)
    else:
        from fabricate.export.stl import model_3mf, stl_bytes
        from fabricate.parts.solids import mesh_arrays, part_solid

        solid = part_solid(part, process.chord_tolerance_mm)
        for glyphs in _embossed(coupon.labels, part.thickness_mm):
            solid = solid + glyphs  # one closed shell: the plate and its raised labels
        vertices, faces = mesh_arrays(solid)
        files["coupon.stl"] = stl_bytes(vertices, faces)
        files["coupon.3mf"] = model_3mf([(part.name, vertices, faces)],
                                        f"fabricate calibration coupon ({process.name})")
    files["README.md"] = coupon_readme(coupon, source or process.name).encode("utf-8")
    return files


def coupon_readme(coupon: Coupon, source: str) -> str:
    """What to measure on the made coupon and which profile field each measurement sets."""
    p = coupon.process
    cut = p.technique == "cut"
    files = "coupon.dxf / coupon.svg (cut red, engrave blue)" if cut else "coupon.stl / coupon.3mf"
    make = "Cut" if cut else "Print"
    lines = [f"# Calibration coupon: process {p.name}" + (f", printer {p.printer}" if p.printer else ""), "",
             f"{make} {files} as it is, in the {p.material.replace('_', ' ') or 'stock'} you will use "
             f"({p.thickness_mm:g} mm thick), with the {'laser' if cut else 'slicer'} settings you will build "
             "with. "
             "Then measure it as below, edit your copy of the profile and build with it:", "",
             "```",
             f"fabricate init --process {p.name} -o my_{p.name}.toml   # once: an editable copy of the profile",
             f"fabricate coupon --process {source} -o coupon/           # this coupon",
             f"# measure, edit my_{p.name}.toml, then (and print a new coupon with it to confirm)",
             f"fabricate build TEMPLATE --process my_{p.name}.toml",
             "```", "",
             f"Profile values this coupon was made with: pin_diameter_mm = {p.pin_diameter_mm:g}, "
             f"running_clearance_mm = {p.running_clearance_mm:g}, press_fit_interference_mm = "
             f"{p.press_fit_interference_mm:g}, hole_compensation_mm = {p.hole_compensation_mm:g}, kerf_mm = "
             f"{p.kerf_mm:g}, min_feature_mm = {p.min_feature_mm:g}.", "",
             "## 1. Pin holes (labelled with their diametral clearance over the pin, mm)", "",
             f"Each hole's label is its clearance c: the finished hole should measure {p.pin_diameter_mm:g} + c mm. ",
             "",
             "| label | finished (nominal) Ø mm | in the file Ø mm |", "|---|---|---|"]
    for f in sorted(coupon.features, key=lambda f: f.offset_mm):
        if f.kind == "hole":
            lines.append(f"| {f.label} | {f.nominal_mm:.2f} | {f.modelled_mm:.2f} |")
    comp = ("**kerf_mm** = kerf_mm + the mean of (measured - nominal) over the holes (each hole's path is cut "
            "kerf/2 inside its size)") if cut else \
        ("**hole_compensation_mm** = hole_compensation_mm + the mean of (nominal - measured) over the holes "
         "(holes print undersize; the file's holes are nominal + hole_compensation_mm)")
    lines += ["", "Measure, with a pin gauge or the dowel pins you will use:", "",
              f"- the holes' diameters (calipers or gauge pins) -> {comp};",
              f"- the tightest hole a {p.pin_diameter_mm:g} mm dowel can be pressed into without cracking the "
              "coupon and stays put: its label is -interference -> **press_fit_interference_mm** = minus that "
              "label (e.g. -.05 -> 0.05; a material that takes no press fit: leave it out and keep retention "
              "\"clip\");",
              "- the tightest hole the dowel turns in freely, with no wobble you mind: its label is twice the "
              "radial clearance -> **running_clearance_mm** = label / 2 (e.g. +.50 -> 0.25).", ""]
    n = 2
    if cut:
        lines += [f"## {n}. Kerf comb (slots labelled with their width over the sheet thickness, mm)", "",
                  f"Each slot's finished width should be {p.thickness_mm:g} + label mm; its path in the file is "
                  f"kerf_mm = {p.kerf_mm:g} narrower (offset kerf/2 each side).", "",
                  "| label | finished width mm | path in the file mm |", "|---|---|---|"]
        lines += [f"| {f.label} | {f.nominal_mm:.2f} | {f.nominal_mm - p.kerf_mm:.2f} |" for f in coupon.features
                  if f.kind == "slot"]
        lines += ["", "- measure each slot's width w (calipers): **kerf_mm** = kerf_mm + (w - nominal) "
                      "(averaged over the slots);",
                  "- push a scrap of the same sheet into the slots: the slot it fits snugly tells the real sheet "
                  "thickness -> **thickness_mm** = the sheet's measured thickness.", ""]
        n += 1
    land = coupon.module_mm * (math.pi / 2.0 - 2.0 * ADDENDUM * math.tan(math.radians(PRESSURE_ANGLE_DEG)))
    lines += [f"## {n}. Rack (lower edge), module {coupon.module_mm:g} mm", "",
              f"The rack's teeth are cut with the basic rack (20° pressure angle, addendum 1 m, dedendum 1.25 m) at "
              f"the smallest standard module whose tip land (flat tooth top, {land:.2f} mm) "
              f"is at least min_feature_mm = {p.min_feature_mm:g}: the smallest module `gears.module_mm = \"auto\"` "
              "considers on this process.", "",
              "- look at the tooth tips under a loupe: a flat, sharp-cornered land means the process makes it; "
              "pointed, rounded or missing tips -> raise **min_feature_mm** (auto modules then grow);",
              f"- two coupons' racks should slide into each other's teeth (pitch {math.pi * coupon.module_mm:.3f} mm) "
              "without force; if they do not, the flanks grew: raise **running_clearance_mm** or, for a cut, "
              "check kerf_mm first.", ""]
    return "\n".join(lines)


def coupon_process(name_or_path: str, printer: str | None = None) -> ProcessSpec:
    """The process of ``--process NAME|FILE`` (and ``--printer``) alone, with no design template."""
    from fabricate.process import parse_process, process_override
    from fabricate.table import Table

    return parse_process(Table({}, "process"), process_override(name_or_path, printer))


def profile_copy(name: str, target: str | Path) -> str:
    """The text ``fabricate init --process NAME`` writes: the shipped profile under a header saying how to
    calibrate and use it. It is checked to read back as the same profile before it is returned.

    Raises
    ------
    SpecError
        ``--process`` is no shipped profile.
    """
    from fabricate.process import shipped_profiles
    from fabricate.templates import TEMPLATE_DIR, read_text

    profiles = shipped_profiles()
    if name not in profiles:
        raise SpecError("--process", f"expected a shipped process profile ({', '.join(profiles)}) to copy, got "
                                     f"\"{name}\"")
    header = (f"# An editable copy of fabricate's shipped \"{name}\" process profile (fabricate init --process "
              f"{name}).\n# Calibrate it: fabricate coupon --process {target} -o coupon/ ; make the coupon, measure "
              "it as coupon/README.md says,\n# edit the fields it names here, then: fabricate build TEMPLATE "
              f"--process {target}\n\n")
    return header + read_text(TEMPLATE_DIR / f"process_{name}.toml")
