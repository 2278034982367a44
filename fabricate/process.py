"""The manufacturing process: a profile's numbers, its materials, and what the process can do.

A process profile is ``templates/process_<name>.toml`` (every such file is a profile a template may name as
``[process] profile``, or ``--process`` may pick), or any file given to ``--process``. A template's
``[process]`` table names the profile and overrides any of its fields.

Capabilities
------------
Modules downstream never test a process by its name; they read what it can do:

``technique``  ``"additive"``: parts are built up layer by layer, so a spacer at least a plate thick prints
               with the parts and the BOM lists "printed part"s. ``"cut"``: parts are cut through sheet
               stock, so the web round a hole is at least the stock thickness, spacers are bought (tubes,
               not cut from the sheet), each part gets a cut path offset by the kerf (``cut/NAME.dxf``,
               ``.svg``) and the BOM lists "cut part"s.
``layout``     ``"plate"``: parts lie on print plates of ``build_volume_mm[:2]``, none taller than
               ``build_volume_mm[2]`` (``plates/plate_N.stl``, ``.3mf``). ``"sheet"``: parts are nested on
               sheets of ``build_volume_mm[:2]``, each as thick as the sheet, ``build_volume_mm[2]``
               (``cut/sheet_N.dxf``, ``.svg``).
plus the numbers every process has: ``min_feature_mm``, ``min_wall_mm``, ``min_pin_mm``, the fits
(``running_clearance_mm``, ``hole_compensation_mm``, ``kerf_mm``) and ``min_text_mm``.

Printers
--------
A plate layout prints on a printer: ``printer = "prusa_sl1s"`` (a preset of :mod:`fabricate.catalogue.printers`)
in the profile or the template's ``[process]``, or ``--printer NAME`` on the command line (which wins over
both and survives ``--process``). The printer's build volume replaces ``build_volume_mm``; a template that
gives its own ``build_volume_mm`` and names no printer prints on that area (a printer of its own). A profile
says which printers it serves by ``printer_technique`` (``"sla"``, ``"fdm"``); a printer of another technique,
or any printer with a sheet layout, is a SpecError.

First layer
-----------
``first_layer_compensation_mm`` is how far the first layer of an additive process spreads beyond its contour
(FDM "elephant foot", resin bottom-layer bloom). The exported meshes keep the nominal contour; the value is
the slicer's compensation to set (PrusaSlicer ``elefant_foot_compensation``: the first layer's contour is
inset by it), recorded in the report, and the real-client test slices with it.

Fits and retention
------------------
Every pin runs in the holes of all but (at most) one of the parts it joins. How it is kept in is the
profile's ``retention`` (:data:`RETENTIONS`):

``"press"``  pressed into the hole of the part that holds it (its first body), whose NOMINAL hole is the pin
             less ``press_fit_interference_mm`` (diametral); it runs in the others.
``"clip"``   runs in every part; it sticks out at both ends far enough for a DIN 6799 retaining washer in a
             groove (an ISO 2338 pin, which can be grooved).
``"cap"``    runs in every part; a collar of the process's own stock (printed, or cut from the sheet) is
             bonded onto each end.

``press_fit_interference_mm`` is the profile's value, else the part material's (``[materials.X]``): a
material that does not take a press fit (cast acrylic crazes under a lasting hoop stress) has none, and
``retention = "press"`` with it is a SpecError. Fit sizes are NOMINAL (what to measure on the finished part);
``hole_compensation_mm`` is added to the modelled (CAD) hole separately (:mod:`fabricate.parts.retention`).

A profile that leaves a capability out (a ``--process`` file written before the field existed) takes it from
the shipped profile of its ``method``; a profile with a method of its own must state both.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from fabricate.errors import SpecError
from fabricate.table import Table, _quote
from fabricate.templates import TEMPLATE_DIR, parse_toml, path_kind, read_text, read_toml

#: The profile of a template that names none.
DEFAULT_PROFILE = "sla"
#: How a process shapes a part, and how it lays the parts out (see the module docstring).
TECHNIQUES = ("additive", "cut")
LAYOUTS = ("plate", "sheet")
#: How a joint's pin is kept in (see the module docstring).
RETENTIONS = ("press", "clip", "cap")
#: Largest diametral press-fit interference (mm): beyond ~0.5 mm a pin of any catalogued size splits a
#: printed or cut boss (hoop strain interference / pin of 10 % and more).
MAX_INTERFERENCE_MM = 0.5
#: What a profile's printers are (``printer_technique``): "" for a process that prints on none.
PRINTER_TECHNIQUES = ("", "sla", "fdm")
#: A process name (``method``; a shipped profile's file is ``process_<name>.toml``).
_PROCESS_NAME = re.compile(r"[a-z][a-z0-9_-]{0,39}")


def shipped_profiles() -> tuple[str, ...]:
    """Names of the shipped process profiles (``templates/process_<name>.toml``), the default first."""
    names = sorted(p.stem[len("process_"):] for p in TEMPLATE_DIR.glob("process_*.toml"))
    return tuple(sorted((n for n in names if _PROCESS_NAME.fullmatch(n)), key=lambda n: n != DEFAULT_PROFILE))


@dataclass(frozen=True)
class Material:
    """Strength data of one material (MPa = N/mm²).

    Attributes
    ----------
    key, name : str
        Profile key and a description for people (the BOM's material).
    tensile_MPa, flexural_MPa, compressive_MPa, shear_MPa : float
        Ultimate strengths: tension governs net sections, flexure in-plane bending and tooth roots,
        compression bearing and contact, shear pins and tear-out.
    modulus_MPa, poisson : float
        Elastic constants (Hertz contact).
    density_g_cm3 : float
    press_fit_interference_mm : float or None
        Diametral interference (mm) a pin pressed into a hole of this material takes; None when the
        material does not take a press fit (the profile says why beside the material).
    """

    key: str
    name: str
    tensile_MPa: float
    flexural_MPa: float
    compressive_MPa: float
    shear_MPa: float
    modulus_MPa: float
    poisson: float
    density_g_cm3: float
    press_fit_interference_mm: float | None = None


def parse_materials(table: Table) -> dict[str, Material]:
    """Read a profile's ``[materials]`` table (``{}`` when absent) into ``{key: Material}``.

    Every number's source is a comment in the profile.
    """
    out = {}
    for key in sorted(table.data):
        t = table.table(key)
        out[key] = Material(
            key=key, name=t.string("name", key.replace("_", " ")),
            tensile_MPa=t.number("tensile_MPa", positive=True, max=1e5),
            flexural_MPa=t.number("flexural_MPa", positive=True, max=1e5),
            compressive_MPa=t.number("compressive_MPa", positive=True, max=1e5),
            shear_MPa=t.number("shear_MPa", positive=True, max=1e5),
            modulus_MPa=t.number("modulus_MPa", positive=True, max=1e7),
            poisson=t.number("poisson", min=0.0, max=0.5),
            density_g_cm3=t.number("density_g_cm3", positive=True, max=25.0),
            press_fit_interference_mm=(t.number("press_fit_interference_mm", positive=True,
                                                max=MAX_INTERFERENCE_MM)
                                       if t.has("press_fit_interference_mm") else None),
        )
        t.finish()
    return out


def pick_material(materials: Mapping[str, Material], key: str, field: str) -> Material:
    """The profile's material ``key``; a SpecError naming ``field`` if the profile has none such."""
    if key not in materials:
        known = ", ".join(sorted(materials)) or "none"
        raise SpecError(field, f"unknown material \"{key}\" (this process profile has: {known})")
    return materials[key]


@dataclass(frozen=True)
class ProcessSpec:
    """Manufacturing process profile. Lengths in mm.

    Attributes
    ----------
    name : str
        The profile's ``method`` (``"sla"``, ``"laser"``...): a label for reports, never a switch.
    running_clearance_mm : float
        Radial clearance between a pin and its hole, and between moving faces.
    hole_compensation_mm : float
        Added to a hole's diameter in the model (SLA holes print undersize); a cut process uses kerf instead.
    min_wall_mm, min_pin_mm, layer_gap_mm : float
        Smallest wall around a hole, smallest pin diameter, axial gap between stacked layers.
    thickness_mm : float
        Plate thickness of a link layer, or the sheet thickness.
    kerf_mm : float
        Cut width (0 for an additive process); cut outlines are offset out and holes in by kerf / 2.
    min_feature_mm : float
        Smallest feature the process resolves (tooth tip land, web).
    build_volume_mm : tuple of float
        Build volume (x, y, z) of a plate layout, or the sheet (x, y, thickness) of a sheet layout.
    pin_diameter_mm : float
        Nominal pin diameter used at joints.
    chord_tolerance_mm : float
        Polygonisation sagitta for meshes.
    technique : str
        ``"additive"`` or ``"cut"`` (see the module docstring).
    layout : str
        ``"plate"`` or ``"sheet"`` (see the module docstring).
    material : str
        What parts are made of (BOM); ``density_g_cm3`` its density (part masses).
    min_text_mm : float
        Smallest label the process engraves or embosses legibly; smaller labels are left out.
    arcs : str
        ``"bulge"`` (exact LWPOLYLINE arcs) or ``"segments"`` (arcs as lines within the chord tolerance,
        for OpenSCAD and older laser software that ignore bulges).
    cut_colour, engrave_colour : str
        SVG stroke colours ("#rrggbb") of the two operations.
    materials : Mapping
        The profile's ``[materials]``: key -> :class:`Material`.
    pin_material : str
        Key of the dowel pins' material.
    retention : str
        How every pin is kept in: ``"press"``, ``"clip"`` or ``"cap"`` (see the module docstring).
    press_fit_interference_mm : float
        Diametral interference of a press-fit hole (nominal hole = pin - interference); 0 when the process
        does not press-fit (``retention`` is then not ``"press"``).
    printer : str
        The printer preset whose build volume ``build_volume_mm`` is ("" when the area is the profile's or
        the template's own).
    printer_technique : str
        The technique of the printers the profile serves (``"sla"``, ``"fdm"``, "" for none).
    stock_thickness_mm : tuple of float
        The sheet thicknesses a cut process's shop stocks, ascending (``stock_thickness_mm``; () when not given):
        a template's own ``thickness_mm`` among them survives ``--process`` (see :func:`_keeps_thickness`).
    first_layer_compensation_mm : float
        How far the first layer spreads (see the module docstring); 0 when the process has no such effect.
    """

    name: str
    running_clearance_mm: float
    hole_compensation_mm: float
    min_wall_mm: float
    min_pin_mm: float
    layer_gap_mm: float
    thickness_mm: float
    kerf_mm: float
    min_feature_mm: float
    build_volume_mm: tuple[float, float, float]
    pin_diameter_mm: float
    chord_tolerance_mm: float
    technique: str = "additive"  # the default profile's (process_sla.toml)
    layout: str = "plate"
    material: str = ""
    density_g_cm3: float = 1.2
    min_text_mm: float = 1.0
    arcs: str = "bulge"
    cut_colour: str = "#ff0000"
    engrave_colour: str = "#0000ff"
    materials: Mapping[str, Material] = field(default_factory=dict, compare=False)
    pin_material: str = ""
    retention: str = "press"  # the default profile's (process_sla.toml)
    press_fit_interference_mm: float = 0.05
    printer: str = ""
    printer_technique: str = ""
    first_layer_compensation_mm: float = 0.0
    sheets: tuple[tuple[str, float, float], ...] = ()  # [sheets]: standard stock (name, w, h), smallest first
    stock_thickness_mm: tuple[float, ...] = ()  # the sheet thicknesses a cut process stocks (--process keeps these)
    shop: tuple[tuple[str, float], ...] = ()  # [shop]: the cut shop's rules (fabricate.checks.shop)

    def part_material(self) -> Material | None:
        """The :class:`Material` of the parts (None if the profile has none)."""
        return self.materials.get(self.material)

    def pin_material_spec(self) -> Material | None:
        """The :class:`Material` of the dowel pins (None if not given)."""
        return self.materials.get(self.pin_material)


@dataclass(frozen=True)
class ProcessOverride:
    """A process chosen on the command line (``--process NAME|PATH``) instead of the template's.

    Attributes
    ----------
    source : str
        A shipped profile's name (``"sla"``, ``"laser"``...) or the profile file's name; "" when only the
        printer is chosen.
    text : str
        The profile's TOML text (embedded in report.json so ``check`` rebuilds with it); "" when only the
        printer is chosen (the template's own profile is used).
    printer : str
        ``--printer``: the printer preset that replaces the profile's and the template's ("" for none).
    """

    source: str
    text: str
    printer: str = ""


def process_override(name_or_path: str | Path | None, printer: str | None = None) -> ProcessOverride:
    """Resolve ``--process`` (a shipped profile name or a profile file; None: the template's) and
    ``--printer`` (a preset name)."""
    if printer is not None:
        from fabricate.catalogue.printers import printer as find_printer

        find_printer(printer, "--printer")
        base = process_override(name_or_path) if name_or_path is not None else ProcessOverride("", "")
        return ProcessOverride(base.source, base.text, printer)
    profiles = shipped_profiles()
    if not isinstance(name_or_path, (str, Path)):
        named = ", ".join(f'"{p}"' for p in profiles)
        raise SpecError("process", f"expected {named} or a process profile file (str or pathlib.Path), "
                                   f"got {type(name_or_path).__name__}")
    if name_or_path in profiles:
        return ProcessOverride(name_or_path, read_text(TEMPLATE_DIR / f"process_{name_or_path}.toml"))
    path = Path(name_or_path)
    if path_kind(path, "--process") != "file":
        raise SpecError("--process", f"expected {', '.join(profiles)} or a process profile file, "
                                     f"got {_quote(str(name_or_path))}")
    return ProcessOverride(path.name, read_text(path))


#: Fields a template keeps when --process replaces its profile: which dowel pins the design uses is a
#: choice of the design, everything else (clearances, kerf, sheet) belongs to the process; the plate thickness is
#: kept where the new process makes it (:func:`_keeps_thickness`).
DESIGN_PROCESS_FIELDS = ("pin_diameter_mm",)


def _keeps_thickness(base: Mapping[str, object], value: object) -> bool:
    """Whether a template's own ``thickness_mm`` stays when ``--process`` replaces its profile with ``base``.

    A template sets its plate thickness for strength (its gear contact, its hinges), a choice of the design as
    long as the new process can make it: an additive process prints any plate thickness (its printer's height is
    checked with the parts), a cut process only the stock it lists (``stock_thickness_mm``; a profile without the
    list cuts its own thickness only). A sheet kept at another stock is that thick (``build_volume_mm[2]``), and the
    profile's ``[shop]`` numbers, which are its own stock's, give way to the shop check's half the stock.
    """
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        return False  # validated (and refused) as the profile's field would be
    technique = base.get("technique")
    method = base.get("method")
    if technique is None and isinstance(method, str) and method in shipped_profiles():
        technique = read_toml(TEMPLATE_DIR / f"process_{method}.toml").get("technique")
    if technique == "additive":
        return True
    stock = base.get("stock_thickness_mm")
    return isinstance(stock, list) and any(isinstance(t, (int, float)) and abs(float(t) - float(value)) <= 1e-9
                                           for t in stock)


def parse_process(table: Table, override: ProcessOverride | None = None) -> ProcessSpec:
    """Read ``[process]``: a profile name plus overrides of the profile's fields.

    With ``override`` (``--process``) the profile is the override's and of the template's own fields only
    :data:`DESIGN_PROCESS_FIELDS` are kept; its ``printer`` (``--printer``) replaces any other.
    """
    from fabricate.bounds import MIN_CHORD_TOLERANCE_MM

    cli_printer = override.printer if override is not None else ""
    if override is not None and not override.text:
        override = None  # only --printer: the template's own profile
    profile = table.string("profile", DEFAULT_PROFILE, choices=shipped_profiles())
    t = _merged(table, profile, override)
    name = t.string("method", profile) if override is None else t.string("method")
    if not _PROCESS_NAME.fullmatch(name):
        raise SpecError(t.field("method"), "expected a process name of lower-case letters, digits, _ and - "
                                           f"(\"sla\", \"laser\"...), got {_quote(name)}")
    materials = parse_materials(t.table("materials", {}))
    material = t.string("material", "")
    pin_material = t.string("pin_material", "")
    density = 1.2
    if materials:
        density = pick_material(materials, material, t.field("material")).density_g_cm3
        pick_material(materials, pin_material, t.field("pin_material"))
    # every length is bounded (bounds.MAX_LENGTH_MM and tighter where the process makes sense): a
    # huge pin or wall turns into geometry no kernel can build; the chord tolerance's lower bound
    # caps the vertex count of every polygonised arc (memory and time grow as 1/sqrt(tolerance))
    spec = ProcessSpec(
        name=name,
        running_clearance_mm=t.number("running_clearance_mm", min=0.0, max=5.0),
        hole_compensation_mm=t.number("hole_compensation_mm", 0.0, min=-2.0, max=2.0),
        min_wall_mm=t.number("min_wall_mm", positive=True, max=50.0),
        min_pin_mm=t.number("min_pin_mm", positive=True, max=50.0),
        layer_gap_mm=t.number("layer_gap_mm", min=0.0, max=50.0),
        thickness_mm=t.number("thickness_mm", positive=True, max=100.0),
        kerf_mm=t.number("kerf_mm", 0.0, min=0.0, max=2.0),
        min_feature_mm=t.number("min_feature_mm", positive=True, max=10.0),
        build_volume_mm=_build_volume(t, table, cli_printer, override is None),
        pin_diameter_mm=t.number("pin_diameter_mm", positive=True, max=50.0),
        chord_tolerance_mm=t.number("chord_tolerance_mm", 0.005, min=MIN_CHORD_TOLERANCE_MM, max=1.0),
        technique=_capability(t, "technique", name, TECHNIQUES),
        layout=_capability(t, "layout", name, LAYOUTS),
        material=material,
        density_g_cm3=t.number("density_g_cm3", density, positive=True, max=25.0),
        min_text_mm=t.number("min_text_mm", 1.0, min=0.0, max=20.0),
        arcs=t.string("arcs", "bulge", choices=("bulge", "segments")),
        cut_colour=_colour(t, "cut_colour", "#ff0000"),
        engrave_colour=_colour(t, "engrave_colour", "#0000ff"),
        materials=materials,
        pin_material=pin_material,
        retention=_capability(t, "retention", name, RETENTIONS, fallback="clip"),
        press_fit_interference_mm=_interference(t, materials.get(material), name, material),
        printer=_printer_name(t, table, cli_printer, override is None),
        printer_technique=_capability(t, "printer_technique", name, PRINTER_TECHNIQUES, fallback=""),
        first_layer_compensation_mm=t.number("first_layer_compensation_mm", 0.0, min=0.0, max=2.0),
        sheets=_sheets(t.table("sheets", {})),
        stock_thickness_mm=_stock(t),
        shop=_shop(t.table("shop", {})),
    )
    t.finish()
    _check_spec(spec, t, cli_printer, materials, material)
    return spec


def _merged(table: Table, profile: str, override: ProcessOverride | None) -> Table:
    """The profile's fields (the shipped ``profile``'s, or ``--process``'s) with the template's over them: all of
    them, or with an override only :data:`DESIGN_PROCESS_FIELDS` and a thickness the new process makes."""
    if override is None:
        base_path = TEMPLATE_DIR / f"process_{profile}.toml"
        base = read_toml(base_path) if base_path.is_file() else {}
        path = table.path or "process"
    else:
        base = parse_toml(override.text, override.source)
        path = f"--process {override.source}"
    merged = dict(base)
    for key in table.data:
        if key != "profile":
            table._used.add(key)
            if override is None or key in DESIGN_PROCESS_FIELDS:
                merged[key] = table.data[key]
    if override is not None and "thickness_mm" in table.data and _keeps_thickness(base, table.data["thickness_mm"]):
        merged["thickness_mm"] = table.data["thickness_mm"]
        volume = base.get("build_volume_mm")
        if base.get("layout") == "sheet" and isinstance(volume, list) and len(volume) == 3:
            merged["build_volume_mm"] = [*volume[:2], table.data["thickness_mm"]]  # a sheet is the stock it is cut from
        if base.get("thickness_mm") != table.data["thickness_mm"]:
            # the profile's [shop] numbers are its own stock's: at another stock the shop check takes its rule of
            # half the stock thickness (fabricate.checks.shop)
            merged.pop("shop", None)
    return Table(merged, path)


def _check_spec(spec: ProcessSpec, t: Table, cli_printer: str, materials: Mapping[str, Material],
                material: str) -> None:
    """What no single field shows: the printer holds the process, a press fit has an interference, the pin
    is not below the process's minimum."""
    _check_printer(spec, "--printer" if cli_printer else t.field("printer"))
    if spec.retention == "press" and spec.press_fit_interference_mm <= 0.0:
        why = (f"{materials[material].name} takes no press fit (the profile gives it no press_fit_interference_mm)"
               if material in materials else "the profile gives no press_fit_interference_mm")
        raise SpecError(t.field("retention"), f'"press" needs a press-fit interference: {why}; use "clip" or "cap", '
                                              "or set press_fit_interference_mm")
    if spec.pin_diameter_mm < spec.min_pin_mm:
        raise SpecError(t.field("pin_diameter_mm"),
                        f"pin {spec.pin_diameter_mm:g} mm is below the process minimum {spec.min_pin_mm:g} mm")


def _printer_name(t: Table, template: Table, cli_printer: str, template_fields: bool) -> str:
    """The printer preset in use: ``--printer``; else the merged table's ``printer``, unless the template gives
    its own ``build_volume_mm`` without naming a printer (its own area); "" for none."""
    if cli_printer:
        if t.has("printer"):
            t.string("printer")
        return cli_printer
    own_area = template_fields and "build_volume_mm" in template.data and "printer" not in template.data
    name = t.string("printer", "")
    return "" if own_area else name


def _build_volume(t: Table, template: Table, cli_printer: str, template_fields: bool) -> tuple[float, float, float]:
    """``build_volume_mm``: the printer's (see :func:`_printer_name`), else the table's."""
    from fabricate.catalogue.printers import printer

    name = _printer_name(t, template, cli_printer, template_fields)
    if not name:
        x, y, z = (float(v) for v in t.array("build_volume_mm", shape=(3,), positive=True, max=10000.0))
        return x, y, z
    if t.has("build_volume_mm"):  # validated, then replaced by the printer's
        t.array("build_volume_mm", shape=(3,), positive=True, max=10000.0)
    field = "--printer" if cli_printer else t.field("printer")
    x, y, z = (float(v) for v in printer(name, field).build_volume_mm)
    return x, y, z


def _check_printer(spec: ProcessSpec, field: str) -> None:
    """A printer must print what the profile makes: a plate layout of its own technique."""
    if not spec.printer:
        return
    from fabricate.catalogue.printers import printer, printers_for

    preset = printer(spec.printer, field)
    if spec.layout != "plate":
        raise SpecError(field, f"the {spec.name} process nests parts on sheets; a printer ({spec.printer}) is for "
                               "a plate layout")
    if preset.technique != spec.printer_technique:
        fitting = ", ".join(printers_for(spec.printer_technique)) or "none"
        raise SpecError(field, f"{spec.printer} is an {preset.technique.upper()} printer; the {spec.name} profile "
                               f"prints on {spec.printer_technique.upper() or 'no'} printers ({fitting})")


def _capability(t: Table, key: str, name: str, choices: tuple[str, ...], fallback: str | None = None) -> str:
    """A capability field: the profile's value; if it has none, the shipped profile's of the same ``method``
    (``process_<name>.toml``: a ``--process`` file older than the field); else ``fallback``, or it is
    required when there is none."""
    if not t.has(key) and name in shipped_profiles():
        default = read_toml(TEMPLATE_DIR / f"process_{name}.toml").get(key)
        if isinstance(default, str) and default in choices:
            return t.string(key, default, choices=choices)
    if fallback is not None:
        return t.string(key, fallback, choices=choices)
    return t.string(key, choices=choices)


def _interference(t: Table, material: Material | None, name: str, key: str) -> float:
    """``press_fit_interference_mm``: the profile's (0 allowed: no press fits), else the part material's, else
    (a ``--process`` file older than the field) the shipped profile's of the same ``method`` for that material,
    else 0."""
    default = material.press_fit_interference_mm if material is not None else None
    if default is None and name in shipped_profiles():
        # the shipped profile's value for the same material: the profile has no such material (no
        # [materials] at all), or has it under the same name without the field
        shipped = read_toml(TEMPLATE_DIR / f"process_{name}.toml")
        row = shipped.get("materials", {}).get(key or shipped.get("material", ""), {})
        value = row.get("press_fit_interference_mm") if isinstance(row, dict) else None
        if isinstance(value, (int, float)) and (material is None or material.name == row.get("name")):
            default = float(value)
    return t.number("press_fit_interference_mm", default if default is not None else 0.0, min=0.0,
                    max=MAX_INTERFERENCE_MM)


def _sheets(t: Table) -> tuple[tuple[str, float, float], ...]:
    """``[sheets]``: ``NAME = [width, height]`` (mm) of each standard stock sheet, smallest area first."""
    sizes: list[tuple[str, float, float]] = []
    for key in t.data:
        width, height = (float(v) for v in t.array(key, shape=(2,), positive=True, max=10000.0))
        sizes.append((key, width, height))
    return tuple(sorted(sizes, key=lambda s: (s[1] * s[2], s[1], s[0])))


def _stock(t: Table) -> tuple[float, ...]:
    """``stock_thickness_mm``: the sheet thicknesses (mm) the cut shop stocks, ascending; () when not given."""
    if not t.has("stock_thickness_mm"):
        return ()
    values = t.array("stock_thickness_mm", shape=(None,), positive=True, max=100.0)
    if len(values) == 0:
        raise SpecError(t.field("stock_thickness_mm"), "expected at least one thickness (or leave the field out)")
    return tuple(sorted({float(v) for v in values}))


#: ``[shop]`` rules (mm) a cut part is checked against (fabricate.checks.shop).
SHOP_RULES = ("min_hole_mm", "min_web_mm", "min_hole_edge_mm")


def _shop(t: Table) -> tuple[tuple[str, float], ...]:
    """``[shop]``: the shop's minimum hole, web between cuts and hole-to-edge distance (mm); absent rules are
    not given (the check takes its defaults)."""
    rules = tuple((key, t.number(key, min=0.0, max=100.0)) for key in SHOP_RULES if t.has(key))
    t.finish()
    return rules


def _colour(t: Table, key: str, default: str) -> str:
    value = t.string(key, default)
    if not (len(value) == 7 and value[0] == "#" and all(c in "0123456789abcdefABCDEF" for c in value[1:])):
        raise SpecError(t.field(key), f'expected a colour "#rrggbb", got {_quote(value)}')
    return value.lower()
