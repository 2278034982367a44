"""Printer presets: every number sourced, the makers the issue names present, the SL1S as the installed
PrusaSlicer's vendor bundle gives it, and unknown names refused with the list."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from fabricate.catalogue.printers import PRINTER_TECHNIQUES, PRINTERS, printer, printers_for
from fabricate.errors import SpecError


@pytest.mark.parametrize("name", sorted(PRINTERS))
def test_every_preset_number_is_in_its_source(name):
    """Each preset has a source with an address or a file, and every build-volume number (as written, %g) is
    quoted in its sources: a number changed without its source fails here."""
    preset = PRINTERS[name]
    assert preset.name == name and preset.technique in PRINTER_TECHNIQUES and preset.title
    assert preset.sources and all(("http" in s or ".ini" in s or ".json" in s) for s in preset.sources)
    text = " ".join(preset.sources)
    for value in preset.build_volume_mm:
        assert value > 0
        assert re.search(rf"(?<![\d.]){re.escape(f'{value:g}')}(?![\d])", text), (name, value)


def test_the_issues_printers_are_catalogued():
    """Prusa SL1S, an Elegoo Mars/Saturn, a Formlabs Form 3/4, Prusa MK4 and a Bambu X1/P1 (issue 26)."""
    names = set(PRINTERS)
    assert {"prusa_sl1s", "prusa_mk4"} <= names
    assert any(n.startswith("elegoo_") for n in names)
    assert any(n.startswith("formlabs_form_") for n in names)
    assert {"bambu_x1", "bambu_p1"} <= names
    assert set(printers_for("sla")) | set(printers_for("fdm")) == names
    assert "prusa_mk4" in printers_for("fdm") and "prusa_sl1s" in printers_for("sla")


VENDOR_INI = Path("/usr/share/PrusaSlicer/profiles/PrusaResearch.ini")


@pytest.mark.skipif(not VENDOR_INI.is_file(), reason="PrusaSlicer's vendor profiles not installed")
def test_sl1s_matches_the_installed_prusaslicer_vendor_bundle():
    """The SL1S section's bed_shape spans 127 x 80 mm and max_print_height is 150: the preset's numbers."""
    text = VENDOR_INI.read_text(encoding="utf-8", errors="replace")
    section = text.split("[printer:Original Prusa SL1S SPEED]", 1)[1].split("\n[", 1)[0]
    corners = re.search(r"^bed_shape = (.+)$", section, re.M).group(1).split(",")
    xs = [float(c.split("x")[0]) for c in corners]
    ys = [float(c.split("x")[1]) for c in corners]
    height = float(re.search(r"^max_print_height = (.+)$", section, re.M).group(1))
    assert (max(xs) - min(xs), max(ys) - min(ys), height) == PRINTERS["prusa_sl1s"].build_volume_mm


def test_unknown_printer_names_the_presets():
    with pytest.raises(SpecError) as err:
        printer("prusa_xl", "--printer")
    assert err.value.path == "--printer" and "prusa_sl1s" in str(err.value) and "bambu_x1" in str(err.value)
