"""Printers a maker owns: named presets with the build volume their makers (or the slicer profiles the makers
ship) give.

A process profile, or a template's ``[process]``, names one as ``printer = "prusa_sl1s"``, or the command line
picks one with ``--printer NAME``; its build volume then replaces the profile's ``build_volume_mm`` (plates
are packed to it and every part is checked against it, :mod:`fabricate.process`). A printer serves the
process profiles of its technique (``printer_technique`` of the profile): an SLA printer an SLA profile, an
FDM printer an FDM one.

Each number is the printable area the maker's slicer profile lets a part occupy (x, y of the bed, z the
highest layer), with its source beside it. Presets whose numbers no source was found for are left out and
listed in :data:`NOT_CATALOGUED`.
"""

from __future__ import annotations

from dataclasses import dataclass

from fabricate.errors import SpecError

#: The techniques a printer preset can have: resin (``"sla"``: SLA and masked SLA) or filament (``"fdm"``).
PRINTER_TECHNIQUES = ("sla", "fdm")


@dataclass(frozen=True)
class Printer:
    """One printer preset.

    Attributes
    ----------
    name : str
        Preset key (``"prusa_sl1s"``), what ``--printer`` and ``[process] printer`` take.
    title : str
        The maker's name of the printer, for reports.
    technique : str
        ``"sla"`` or ``"fdm"`` (:data:`PRINTER_TECHNIQUES`).
    build_volume_mm : (float, float, float)
        Printable x, y (the bed or exposure area) and z (the highest layer), mm.
    sources : tuple of str
        Where each number comes from.
    note : str
        What the preset leaves out (excluded bed corners...), or "".
    """

    name: str
    title: str
    technique: str
    build_volume_mm: tuple[float, float, float]
    sources: tuple[str, ...]
    note: str = ""

    def report(self) -> dict[str, object]:
        """JSON-ready summary (report.json's ``design.printer``)."""
        return {"name": self.name, "title": self.title, "technique": self.technique,
                "build_volume_mm": list(self.build_volume_mm), "sources": list(self.sources), "note": self.note}


_PRUSA_INI = ("PrusaSlicer 2.5.0 vendor bundle PrusaResearch.ini (config_version 1.5.1), "
              "https://github.com/prusa3d/PrusaSlicer/blob/version_2.5.0/resources/profiles/PrusaResearch.ini")
_UVTOOLS = "https://github.com/sn4k3/UVtools/blob/master/PrusaSlicer/printer/"
_BAMBU = "https://github.com/bambulab/BambuStudio/blob/master/resources/profiles/BBL/machine/"

PRINTERS: dict[str, Printer] = {p.name: p for p in (
    Printer(
        "prusa_sl1s", "Original Prusa SL1S SPEED", "sla", (127.0, 80.0, 150.0),
        # bed_shape = 0.5x0.5,127.5x0.5,127.5x80.5,0.5x80.5 -> 127 x 80; max_print_height = 150
        (f"{_PRUSA_INI}, [printer:Original Prusa SL1S SPEED]: bed_shape 0.5x0.5 .. 127.5x80.5 (127 x 80 mm), "
         "max_print_height = 150 (display 128 x 81 mm)",)),
    Printer(
        "elegoo_mars_4", "Elegoo Mars 4", "sla", (132.8, 74.7, 150.0),
        # bed_shape = 0x0,132.8x0,132.8x74.7,0x74.7; max_print_height = 150
        (f"{_UVTOOLS}Elegoo%20Mars%204.ini (UVtools' PrusaSlicer printer profile, its Elegoo LCD size): "
         "bed_shape 0x0 .. 132.8x74.7, max_print_height = 150",)),
    Printer(
        "elegoo_saturn_3", "Elegoo Saturn 3", "sla", (218.88, 122.88, 249.7),
        # bed_shape = 0x0,218.88x0,218.88x122.88,0x122.88; max_print_height = 249.7
        (f"{_UVTOOLS}Elegoo%20Saturn%203.ini (UVtools' PrusaSlicer printer profile, its Elegoo LCD size): "
         "bed_shape 0x0 .. 218.88x122.88, max_print_height = 249.7 (Elegoo: 250)",)),
    Printer(
        "formlabs_form_3", "Formlabs Form 3/3+", "sla", (145.0, 145.0, 185.0),
        # Formlabs' Form 3+ tech specs: build volume 14.5 x 14.5 x 18.5 cm
        ("Formlabs Form 3+ specifications, build volume 145 x 145 x 185 mm (https://formlabs.com/3d-printers/form-3/, "
         "as reproduced by Fab Academy and makerspace equipment pages)",)),
    Printer(
        "formlabs_form_4", "Formlabs Form 4", "sla", (200.0, 125.0, 210.0),
        # Formlabs' Form 4 tech specs: build volume 20.0 x 12.5 x 21.0 cm
        ("Formlabs Form 4 specifications, build volume 200 x 125 x 210 mm (as reproduced in the VT DISCO lab "
         "wiki, https://github.com/VT-DISCO-LAB/Getting-Started-in-the-Discovery-Lab/wiki/Formlabs-Form-4)",)),
    Printer(
        "prusa_mk4", "Original Prusa MK4", "fdm", (250.0, 210.0, 220.0),
        # printable_area 0x0,250x0,250x210,0x210; printable_height 220 (Prusa: 250 x 210 x 220 mm)
        ("OrcaSlicer resources/profiles/Prusa/machine/Prusa MK4 0.4 nozzle.json: printable_area 0x0 .. 250x210, "
         "printable_height 220 (https://github.com/SoftFever/OrcaSlicer; Prusa's MK4 spec: 250 x 210 x 220 mm)",)),
    Printer(
        "bambu_x1", "Bambu Lab X1 / X1 Carbon", "fdm", (256.0, 256.0, 250.0),
        # fdm_bbl_machine_common.json: printable_area 0x0,256x0,256x256,0x256; printable_height 250
        (f"{_BAMBU}fdm_bbl_machine_common.json (inherited by 'Bambu Lab X1 Carbon 0.4 nozzle.json'): "
         "printable_area 0x0 .. 256x256, printable_height 250 (Bambu's spec sheet: 256 x 256 x 256 mm)",),
        note="Bambu Studio keeps the corner x < 18, y < 28 mm (and a strip x < 8) off the plate (bed_exclude_area): "
             "a full-width plate may need the slicer to shift it"),
    Printer(
        "bambu_p1", "Bambu Lab P1P / P1S", "fdm", (256.0, 256.0, 250.0),
        # fdm_bbl_3dp_001_common.json: printable_area 0x0,256x0,256x256,0x256; printable_height 250
        (f"{_BAMBU}fdm_bbl_3dp_001_common.json (inherited by 'Bambu Lab P1P 0.4 nozzle.json'): "
         "printable_area 0x0 .. 256x256, printable_height 250",),
        note="Bambu Studio keeps the corner x < 18, y < 28 mm off the plate (bed_exclude_area)"),
)}

#: Presets asked for but left out, and why.
NOT_CATALOGUED: dict[str, str] = {}


def printer(name: str, field: str = "printer") -> Printer:
    """The preset ``name``; a SpecError naming ``field`` and the presets when there is none such."""
    if not isinstance(name, str) or name not in PRINTERS:
        known = ", ".join(sorted(PRINTERS))
        raise SpecError(field, f"unknown printer {name!r} (presets: {known})")
    return PRINTERS[name]


def printers_for(technique: str) -> tuple[str, ...]:
    """Names of the presets of one technique (``"sla"`` or ``"fdm"``), sorted."""
    return tuple(sorted(p.name for p in PRINTERS.values() if p.technique == technique))
