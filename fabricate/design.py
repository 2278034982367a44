"""Reading a design: a template (a file, a shipped name or text) into a validated
:class:`~fabricate.spec.DesignSpec`.

This is the glue above every section's parser (:mod:`fabricate.process`, :mod:`fabricate.gears.spec`,
:mod:`fabricate.parts.spec`, :mod:`fabricate.strength.spec`, :mod:`fabricate.drive.spec`) and the kinds'
(:mod:`fabricate.kinds`); :mod:`fabricate.spec` holds the record they fill, which every stage imports, so it
imports none of them.
"""

from __future__ import annotations

from pathlib import Path

from fabricate.drive.spec import parse_actuator
from fabricate.errors import SpecError
from fabricate.gears.spec import parse_gear_spec
from fabricate.kinds import KINDS
from fabricate.parts.spec import parse_parts_spec
from fabricate.process import ProcessOverride, parse_process, process_override
from fabricate.spec import DesignSpec, check_design_name, parse_checks
from fabricate.strength.spec import parse_load
from fabricate.table import Table
from fabricate.templates import find_template, parse_toml, read_text

#: The template tables every kind shares (read here); every other top-level table is the kind's own.
GENERIC_SECTIONS = ("design", "process", "checks", "gears", "parts", "load", "actuator")


def load_design(path: str | Path, process: str | ProcessOverride | None = None,
                printer: str | None = None) -> DesignSpec:
    """Load and validate a template file (a path, or a shipped template's name) into a :class:`DesignSpec`.

    ``process`` (``--process``: ``"sla"``, ``"laser"``, a profile file or a :class:`ProcessOverride`)
    replaces the template's process profile; ``printer`` (``--printer``: a preset of
    :mod:`fabricate.catalogue.printers`) the printer of the profile and the template.

    Raises
    ------
    SpecError
        On the first invalid field, naming its path.
    """
    path = find_template(path)
    if printer is not None:
        source = process.source if isinstance(process, ProcessOverride) else process
        process = (ProcessOverride(process.source, process.text, printer) if isinstance(process, ProcessOverride)
                   else process_override(source, printer))
    elif isinstance(process, str):
        process = process_override(process)
    return design_from_text(read_text(path), path, process)


def design_from_text(text: str, path: str | Path, process: ProcessOverride | None = None) -> DesignSpec:
    """Validate a template given as text; ``path`` is where it came from (its file name goes in reports).

    ``fabricate check DIR`` rebuilds from the text embedded in a report with this, so the verdict depends
    neither on the working folder nor on later edits of the file.
    """

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
    # --process builds the design for another process: the teeth are sized for it again (gears.spec)
    gears = parse_gear_spec(root.table("gears", {}), retarget=process is not None and bool(process.text))
    parts = parse_parts_spec(root.table("parts", {}))
    load = parse_load(root.table("load", {}))
    actuator = parse_actuator(root.table("actuator", {}))
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
                      process_override=process, load=load, actuator=actuator)
    KINDS[kind].preflight(spec)  # counts whose product drives memory or time (each field alone is already bounded)
    return spec
