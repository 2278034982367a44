"""Template loading and validation.

A template is a TOML file. This module reads it and offers :class:`Table`, a strict reader that every
spec parser (the generic sections here, the kind-specific ones in :mod:`fabricate.synthesis`) uses so
that every error names the field path and what was expected. Nothing here writes files.

Generic sections
----------------
``[design]``   name, kind (selects the synthesis method), description.
``[process]``  profile (``"sla"`` or ``"laser"``, read from ``templates/process_<profile>.toml``) and any
               field of that profile to override.
``[checks]``   sweep_poses, min_clearance_mm.
Every other top-level table belongs to the kind's parser.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def _template_dir() -> Path:
    # A wheel carries the repository's templates/ as fabricate/templates (setup.py maps it there); a
    # source checkout or an editable install reads the one copy at the repository's top level.
    package = Path(__file__).resolve().parent
    inside = package / "templates"
    return inside if inside.is_dir() else package.parent / "templates"


#: Folder of the shipped templates and process profiles.
TEMPLATE_DIR = _template_dir()

#: Largest template file read (a design template is a few kB; this keeps a stray binary out of memory).
MAX_TEMPLATE_BYTES = 1_000_000

from fabricate.table import _MISSING, Table, _describe, _quote, check_array, check_number  # noqa: E402,F401 (re-exported)


def path_kind(path: str | Path, what: str = "") -> str:
    """``"file"`` (a regular file, after links), ``"other"`` (a folder, FIFO, device...) or ``"missing"``.

    A path the system refuses to look at (a name too long, a NUL, no permission) is a :class:`SpecError`
    naming ``what`` (the argument) rather than an ``OSError``: it is the user's input, not fabricate's fault.
    """
    try:
        path = Path(path)
        if path.is_file():
            return "file"
        return "other" if path.exists() else "missing"
    except (TypeError, ValueError) as exc:  # a NUL in the name; a value that is no path at all
        raise SpecError(what, f"not a usable path: {exc}") from None
    except OSError as exc:
        raise SpecError(what, f"cannot look at {str(path)[:80]!r}: {exc.strerror}") from None


def find_template(name_or_path: str | Path) -> Path:
    """Resolve a template argument: an existing path, or a shipped template's name (with or without .toml)."""
    if not isinstance(name_or_path, (str, Path)):
        raise SpecError("template", "expected a template name or path (str or pathlib.Path), got "
                                    f"{type(name_or_path).__name__}")
    candidate = Path(name_or_path)
    kind = path_kind(candidate, "template")
    if kind == "file":
        return candidate
    if kind == "other":
        raise SpecError("", f"template {name_or_path} is not a file")
    stem = candidate.name[:-5] if candidate.name.endswith(".toml") else candidate.name
    shipped = TEMPLATE_DIR / f"{stem}.toml"
    if candidate.parent == Path(".") and not stem.startswith("process_") and path_kind(shipped) == "file":
        return shipped
    raise SpecError("", f"template not found: {name_or_path} (see 'fabricate list')")


def shipped_templates() -> list[Path]:
    """Design templates shipped in ``templates/`` (process profiles excluded)."""
    return sorted(p for p in TEMPLATE_DIR.glob("*.toml") if not p.name.startswith("process_"))


def read_text(path: Path) -> str:
    """A template's text: UTF-8 with or without a byte-order mark; anything else is a :class:`SpecError`."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_TEMPLATE_BYTES + 1)
    except OSError as exc:
        raise SpecError(str(path), f"cannot read: {exc.strerror}") from exc
    except ValueError as exc:  # a NUL in the path
        raise SpecError(repr(str(path)), f"cannot read: {exc}") from exc
    if len(data) > MAX_TEMPLATE_BYTES:
        raise SpecError(str(path), f"larger than {MAX_TEMPLATE_BYTES} bytes: not a design template")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SpecError(str(path), f"not UTF-8 text (byte {exc.start}: {data[exc.start:exc.start + 1]!r}); "
                                   "save the template as UTF-8") from exc


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML text; syntax errors become :class:`SpecError` naming ``source`` and the line."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(source, f"invalid TOML: {exc}") from exc
    except ValueError as exc:  # int() refuses an integer literal of more than sys.get_int_max_str_digits()
        raise SpecError(source, f"invalid TOML: a number too long to read ({str(exc).split(';')[0]})") from exc
    except RecursionError as exc:  # tomllib recurses per nesting level of arrays and inline tables
        raise SpecError(source, "invalid TOML: nested too deeply") from exc


def read_toml(path: Path) -> dict[str, Any]:
    """Read and parse a TOML file (see :func:`read_text`, :func:`parse_toml`)."""
    return parse_toml(read_text(path), str(path))


@dataclass(frozen=True)
class ProcessSpec:
    """Manufacturing process profile. Lengths in mm.

    Attributes
    ----------
    name : str
        ``"sla"`` or ``"laser"``.
    running_clearance_mm : float
        Radial clearance between a pin and its hole, and between moving faces.
    hole_compensation_mm : float
        Added to a hole's diameter in the model (SLA holes print undersize); laser uses kerf instead.
    min_wall_mm, min_pin_mm, layer_gap_mm : float
        Smallest wall around a hole, smallest pin diameter, axial gap between stacked layers.
    thickness_mm : float
        Plate thickness of a link layer (SLA) or the sheet thickness (laser).
    kerf_mm : float
        Laser kerf width (0 for SLA); outlines are offset out and holes in by kerf / 2.
    min_feature_mm : float
        Smallest feature the process resolves (tooth tip land, web).
    build_volume_mm : tuple of float
        SLA build volume (x, y, z) or laser sheet (x, y, thickness).
    pin_diameter_mm : float
        Nominal pin diameter used at joints.
    chord_tolerance_mm : float
        Polygonisation sagitta for meshes.
    material : str
        What parts are made of (BOM); ``density_g_cm3`` its density (part masses).
    min_text_mm : float
        Smallest label the process engraves or embosses legibly; smaller labels are left out.
    arcs : str
        ``"bulge"`` (exact LWPOLYLINE arcs) or ``"segments"`` (arcs as lines within the chord tolerance,
        for OpenSCAD and older laser software that ignore bulges).
    cut_colour, engrave_colour : str
        SVG stroke colours ("#rrggbb") of the two operations.
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
    material: str = ""
    density_g_cm3: float = 1.2
    min_text_mm: float = 1.0
    arcs: str = "bulge"
    cut_colour: str = "#ff0000"
    engrave_colour: str = "#0000ff"
    materials: Mapping[str, Any] = field(default_factory=dict, compare=False)
    pin_material: str = ""

    def part_material(self) -> Any:
        """The :class:`~fabricate.strength.spec.Material` of the parts (None if the profile has none)."""
        return self.materials.get(self.material)

    def pin_material_spec(self) -> Any:
        """The :class:`~fabricate.strength.spec.Material` of the dowel pins (None if not given)."""
        return self.materials.get(self.pin_material)


@dataclass(frozen=True)
class ProcessOverride:
    """A process chosen on the command line (``--process laser|sla|PATH``) instead of the template's.

    Attributes
    ----------
    source : str
        ``"sla"``, ``"laser"`` or the profile file's name.
    text : str
        The profile's TOML text (embedded in report.json so ``check`` rebuilds with it).
    """

    source: str
    text: str


def process_override(name_or_path: str | Path) -> ProcessOverride:
    """Resolve ``--process``: a shipped profile name or a profile file."""
    if not isinstance(name_or_path, (str, Path)):
        raise SpecError("process", "expected \"sla\", \"laser\" or a process profile file (str or pathlib.Path), "
                                   f"got {type(name_or_path).__name__}")
    if name_or_path in ("sla", "laser"):
        return ProcessOverride(name_or_path, read_text(TEMPLATE_DIR / f"process_{name_or_path}.toml"))
    path = Path(name_or_path)
    if path_kind(path, "--process") != "file":
        raise SpecError("--process", f"expected sla, laser or a process profile file, got {_quote(str(name_or_path))}")
    return ProcessOverride(path.name, read_text(path))


#: Fields a template keeps when --process replaces its profile: which dowel pins the design uses is a
#: choice of the design, everything else (clearances, kerf, sheet, thickness) belongs to the process.
DESIGN_PROCESS_FIELDS = ("pin_diameter_mm",)


def parse_process(table: Table, override: ProcessOverride | None = None) -> ProcessSpec:
    """Read ``[process]``: a profile name plus overrides of the profile's fields.

    With ``override`` (``--process``) the profile is the override's and of the template's own fields only
    :data:`DESIGN_PROCESS_FIELDS` are kept.
    """
    from fabricate.bounds import MIN_CHORD_TOLERANCE_MM

    profile = table.string("profile", "sla", choices=("sla", "laser"))
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
    t = Table(merged, path)
    method = t.string("method", profile if override is None else _MISSING, choices=("sla", "laser"))
    from fabricate.strength.spec import parse_materials, pick_material

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
        name=method,
        running_clearance_mm=t.number("running_clearance_mm", min=0.0, max=5.0),
        hole_compensation_mm=t.number("hole_compensation_mm", 0.0, min=-2.0, max=2.0),
        min_wall_mm=t.number("min_wall_mm", positive=True, max=50.0),
        min_pin_mm=t.number("min_pin_mm", positive=True, max=50.0),
        layer_gap_mm=t.number("layer_gap_mm", min=0.0, max=50.0),
        thickness_mm=t.number("thickness_mm", positive=True, max=100.0),
        kerf_mm=t.number("kerf_mm", 0.0, min=0.0, max=2.0),
        min_feature_mm=t.number("min_feature_mm", positive=True, max=10.0),
        build_volume_mm=tuple(t.array("build_volume_mm", shape=(3,), positive=True, max=10000.0).tolist()),
        pin_diameter_mm=t.number("pin_diameter_mm", positive=True, max=50.0),
        chord_tolerance_mm=t.number("chord_tolerance_mm", 0.005, min=MIN_CHORD_TOLERANCE_MM, max=1.0),
        material=material,
        density_g_cm3=t.number("density_g_cm3", density, positive=True, max=25.0),
        min_text_mm=t.number("min_text_mm", 1.0, min=0.0, max=20.0),
        arcs=t.string("arcs", "bulge", choices=("bulge", "segments")),
        cut_colour=_colour(t, "cut_colour", "#ff0000"),
        engrave_colour=_colour(t, "engrave_colour", "#0000ff"),
        materials=materials,
        pin_material=pin_material,
    )
    t.finish()
    if spec.pin_diameter_mm < spec.min_pin_mm:
        raise SpecError(t.field("pin_diameter_mm"),
                        f"pin {spec.pin_diameter_mm:g} mm is below the process minimum {spec.min_pin_mm:g} mm")
    return spec


def _colour(t: Table, key: str, default: str) -> str:
    value = t.string(key, default)
    if not (len(value) == 7 and value[0] == "#" and all(c in "0123456789abcdefABCDEF" for c in value[1:])):
        raise SpecError(t.field(key), f'expected a colour "#rrggbb", got {_quote(value)}')
    return value.lower()


@dataclass(frozen=True)
class ChecksSpec:
    """``[checks]``: sweep resolution and pass thresholds."""

    sweep_poses: int = 360
    min_clearance_mm: float | None = None  # None: the process's running clearance
    min_safety_factor: float = 2.0  # every part's strength: allowable stress / stress at the design load


def parse_checks(table: Table) -> ChecksSpec:
    """Read ``[checks]``; ``sweep_poses`` is bounded by :data:`fabricate.bounds.MAX_SWEEP_POSES`."""
    from fabricate.bounds import MAX_SWEEP_POSES

    spec = ChecksSpec(
        sweep_poses=table.integer("sweep_poses", 360, min=2, max=MAX_SWEEP_POSES),
        min_clearance_mm=table.number("min_clearance_mm", None, min=0.0, max=50.0),
        min_safety_factor=table.number("min_safety_factor", 2.0, min=1.0, max=20.0),
    )
    table.finish()
    return spec


#: Longest design name: it names the output folder (plus "-synth" or "-sweep" and fabricate's temporary
#: siblings' suffix), which must stay within a file system's 255 bytes per name.
MAX_NAME_CHARS = 100
MAX_NAME_BYTES = 200
#: Characters no design name may hold: path separators, and those Windows refuses in a folder name.
_NAME_FORBIDDEN = '/\\:*?"<>|'


def check_design_name(name: str, path: str = "design.name") -> str:
    """A design name that is safe as a folder name on every platform, else a :class:`SpecError` at ``path``.

    Refused: an empty name, ``.``/``..`` or any name starting with ``.`` (a hidden folder), leading or trailing
    spaces and a trailing ``.`` (Windows drops them), control characters (NUL included), line separators, lone
    surrogates, the characters ``/ \\ : * ? " < > |``, and more than :data:`MAX_NAME_CHARS` characters or
    :data:`MAX_NAME_BYTES` bytes of UTF-8.
    """
    import unicodedata

    # as the user would type it in TOML, without writing a NUL or a control character to the terminal
    shown = '"' + "".join(c if c.isprintable() else f"\\u{ord(c):04X}" for c in name[:60]) \
        + ('..."' if len(name) > 60 else '"')
    if not name:
        raise SpecError(path, "expected a plain file name (it names the output folder), got an empty name")
    kinds = {"Cc": "control character", "Cs": "lone surrogate", "Zl": "line separator", "Zp": "paragraph separator"}
    bad = next((c for c in name if c in _NAME_FORBIDDEN or unicodedata.category(c) in kinds), None)
    why = ""
    if bad is not None:
        why = f'it holds "{bad}"' if bad in _NAME_FORBIDDEN else \
            f"it holds the {kinds[unicodedata.category(bad)]} U+{ord(bad):04X}"
    elif name.startswith("."):
        why = 'it starts with "." (a hidden folder, or the folder itself or its parent)'
    elif name.endswith(".") or name != name.strip():
        why = 'it ends with "." or has spaces at an end (Windows drops them from folder names)'
    if why:
        raise SpecError(path, f"expected a plain file name (it names the output folder), got {shown}: {why}")
    size = len(name.encode("utf-8"))
    if len(name) > MAX_NAME_CHARS or size > MAX_NAME_BYTES:
        raise SpecError(path, f"expected at most {MAX_NAME_CHARS} characters ({MAX_NAME_BYTES} bytes of UTF-8): it "
                              f"names the output folder; got {len(name)} characters ({size} bytes)")
    return name


@dataclass(frozen=True)
class DesignSpec:
    """A whole validated template.

    Attributes
    ----------
    name, kind, description : str
    template : Path
        Where it was read from.
    template_text : str
        The template exactly as validated (embedded in report.json so a build can be re-made from it).
    process_override : ProcessOverride or None
        The ``--process`` profile that replaced the template's, if any.
    process : ProcessSpec
    checks : ChecksSpec
    gears : fabricate.gears.spec.GearSpec
        ``[gears]``: module, pressure angle, method, backlash (defaults when the table is absent).
    parts : fabricate.parts.spec.PartsSpec
        ``[parts]``: pad, hub and mounting options (defaults when the table is absent).
    method : object
        The kind's own frozen spec (see :mod:`fabricate.synthesis`).
    """

    name: str
    kind: str
    description: str
    template: Path
    process: ProcessSpec
    checks: ChecksSpec
    gears: Any
    parts: Any
    method: Any
    template_text: str = ""
    process_override: ProcessOverride | None = None
    load: Any = None


def load_design(path: str | Path, process: str | ProcessOverride | None = None) -> DesignSpec:
    """Load and validate a template file (a path, or a shipped template's name) into a :class:`DesignSpec`.

    ``process`` (``--process``: ``"sla"``, ``"laser"``, a profile file or a :class:`ProcessOverride`)
    replaces the template's process profile.

    Raises
    ------
    SpecError
        On the first invalid field, naming its path.
    """
    path = find_template(path)
    if isinstance(process, str):
        process = process_override(process)
    return design_from_text(read_text(path), path, process)


def design_from_text(text: str, path: str | Path, process: ProcessOverride | None = None) -> DesignSpec:
    """Validate a template given as text; ``path`` is where it came from (its file name goes in reports).

    ``fabricate check DIR`` rebuilds from the text embedded in a report with this, so the verdict depends
    neither on the working folder nor on later edits of the file.
    """
    from fabricate.gears.spec import parse_gear_spec
    from fabricate.parts.spec import parse_parts_spec
    from fabricate.synthesis import KINDS

    path = Path(path)
    if text.startswith("\ufeff"):
        text = text[1:]
    root = Table(parse_toml(text, str(path)))
    design = root.table("design")
    name = check_design_name(design.string("name"), design.field("name"))
    kind = design.string("kind", choices=tuple(sorted(KINDS)))
    description = design.string("description", "")
    design.finish()
    process_spec = parse_process(root.table("process", {}), process)
    checks = parse_checks(root.table("checks", {}))
    gears = parse_gear_spec(root.table("gears", {}))
    parts = parse_parts_spec(root.table("parts", {}))
    from fabricate.strength.spec import parse_load

    load = parse_load(root.table("load", {}))
    method = KINDS[kind].parse_spec(root)
    root.finish()
    bore = getattr(gears, "bore_mm", None)
    if bore is not None and abs(bore - process_spec.pin_diameter_mm) > 1e-9:
        # every joint, gear axes included, turns on a pin of the process diameter
        pin = process_spec.pin_diameter_mm
        raise SpecError("gears.bore_mm", f"{bore:g} mm differs from the pin diameter {pin:g} mm "
                                         "the gears turn on; set process.pin_diameter_mm to it or leave bore_mm out")
    spec = DesignSpec(name=name, kind=kind, description=description, template=path, process=process_spec,
                      checks=checks, gears=gears, parts=parts, method=method, template_text=text,
                      process_override=process, load=load)
    from fabricate.bounds import preflight

    preflight(spec)  # counts whose product drives memory or time (each field alone is already bounded)
    return spec
