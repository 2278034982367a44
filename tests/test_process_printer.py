"""Printers in the process: the profile's preset, [process] printer, a template's own area, --printer over both
(and over --process), refusals for a printer of the wrong technique or a sheet layout; the FDM profile's
numbers, each with its source; the report records the printer and check rebuilds with it."""

from __future__ import annotations

import re

import pytest

from fabricate.catalogue.printers import PRINTERS
from fabricate.design import design_from_text, load_design
from fabricate.errors import SpecError
from fabricate.process import process_override
from fabricate.templates import TEMPLATE_DIR, find_template, read_text

TEMPLATE = "jansen_leg"  # [process] profile = "sla" and the pin diameter only


def _with_process_lines(*lines: str):
    """Jansen's leg with extra lines in its [process] table."""
    path = find_template(TEMPLATE)
    text = read_text(path)
    assert 'profile = "sla"\n' in text
    return design_from_text(text.replace('profile = "sla"\n', 'profile = "sla"\n' + "".join(f"{x}\n" for x in lines)),
                            path)


def test_the_sla_profile_prints_on_the_sl1s():
    process = load_design(TEMPLATE).process
    assert process.printer == "prusa_sl1s" and process.printer_technique == "sla"
    assert process.build_volume_mm == PRINTERS["prusa_sl1s"].build_volume_mm == (127.0, 80.0, 150.0)


def test_a_template_printer_sets_the_area():
    process = _with_process_lines('printer = "formlabs_form_3"').process
    assert process.printer == "formlabs_form_3" and process.build_volume_mm == (145.0, 145.0, 185.0)


def test_a_template_area_without_a_printer_is_its_own():
    process = _with_process_lines("build_volume_mm = [100.0, 90.0, 50.0]").process
    assert process.printer == "" and process.build_volume_mm == (100.0, 90.0, 50.0)


@pytest.mark.parametrize("name", sorted(PRINTERS))
def test_printer_on_the_command_line_wins_and_survives_process(name):
    """--printer over the profile's and the template's own (a template naming the Saturn 3); an FDM preset
    with --process fdm."""
    path = find_template(TEMPLATE)
    text = read_text(path).replace('profile = "sla"\n', 'profile = "sla"\nprinter = "elegoo_saturn_3"\n')
    assert design_from_text(text, path).process.printer == "elegoo_saturn_3"
    fdm = PRINTERS[name].technique == "fdm"
    process = design_from_text(text, path, process_override("fdm" if fdm else None, name)).process
    assert process.printer == name and process.build_volume_mm == PRINTERS[name].build_volume_mm
    assert process.name == ("fdm" if fdm else "sla")


def test_a_printer_of_the_other_technique_is_refused():
    with pytest.raises(SpecError) as err:
        load_design(TEMPLATE, None, "prusa_mk4")
    assert err.value.path == "--printer" and "FDM printer" in str(err.value) and "prusa_sl1s" in str(err.value)
    with pytest.raises(SpecError) as err:
        load_design(TEMPLATE, "fdm", "prusa_sl1s")
    assert err.value.path == "--printer" and "SLA printer" in str(err.value) and "prusa_mk4" in str(err.value)
    with pytest.raises(SpecError) as err:
        _with_process_lines('printer = "bambu_x1"')
    assert err.value.path.endswith("printer") and "FDM printer" in str(err.value)


def test_a_sheet_layout_takes_no_printer():
    with pytest.raises(SpecError) as err:
        load_design(TEMPLATE, "laser", "prusa_sl1s")
    assert "sheets" in str(err.value)


def test_unknown_printer_is_a_spec_error_naming_the_presets():
    with pytest.raises(SpecError) as err:
        process_override(None, "ender_3")
    assert err.value.path == "--printer" and "prusa_mk4" in str(err.value)


def test_fdm_profile_numbers():
    """The FDM profile: a plate layout on the MK4, press-fit dowels, line-width features (0.45 mm lines: one line
    the smallest feature, two the smallest wall), first-layer compensation, PLA and PETG."""
    process = load_design(TEMPLATE, "fdm").process
    assert (process.technique, process.layout, process.printer, process.retention) == (
        "additive", "plate", "prusa_mk4", "press")
    assert process.min_feature_mm == pytest.approx(0.45) and process.min_wall_mm == pytest.approx(0.9)
    assert process.first_layer_compensation_mm == pytest.approx(0.2)
    assert process.press_fit_interference_mm == pytest.approx(0.1)
    assert {"pla", "petg", "steel_dowel"} <= set(process.materials) and process.material == "pla"
    pla, petg = process.materials["pla"], process.materials["petg"]
    assert (pla.tensile_MPa, pla.modulus_MPa, pla.density_g_cm3) == (48.0, 2300.0, 1.24)
    assert (petg.tensile_MPa, petg.modulus_MPa, petg.density_g_cm3) == (45.0, 1500.0, 1.27)
    # the template's own pin diameter is kept, everything else is the profile's
    assert process.pin_diameter_mm == 3.0 and process.thickness_mm == 3.0


def test_every_fdm_number_has_its_source_beside_it():
    """Each numeric line of process_fdm.toml (a field = number) carries a comment, or is one of the few with no
    claim to source (kerf 0, the design's pin and the shared chord tolerance) — and every material strength,
    modulus and density line names its datasheet or says it is an estimate."""
    no_claim = {"kerf_mm", "pin_diameter_mm", "poisson"}
    steel = False
    for line in (TEMPLATE_DIR / "process_fdm.toml").read_text().splitlines():
        if line.startswith("[materials.steel_dowel]"):
            steel = True  # the SLA and laser profiles' steel block, sourced there
        match = re.match(r"^(\w+) = [-\d.]+", line)
        if not match or steel or match.group(1) in no_claim:
            continue
        assert "#" in line, line


def test_report_records_the_printer_and_check_rebuilds_with_it(tmp_path):
    """A --printer build's report names the printer (area, sources, first-layer compensation) and the
    command-line choice; fabricate check's rebuild reads it back (design_from_text with the override)."""
    from fabricate.pipeline import design_section
    from fabricate.process import ProcessOverride

    design = load_design(TEMPLATE, None, "elegoo_mars_4")
    section = design_section(design, "build")
    assert section["printer"]["name"] == "elegoo_mars_4"
    assert section["printer"]["build_volume_mm"] == [132.8, 74.7, 150.0]
    assert section["printer"]["sources"] and section["printer"]["first_layer_compensation_mm"] == 0.2
    assert section["process_override"] == {"source": "", "text": "", "printer": "elegoo_mars_4"}
    again = design_from_text(design.template_text, design.template,
                             ProcessOverride(section["process_override"]["source"],
                                             section["process_override"]["text"],
                                             section["process_override"]["printer"]))
    assert again.process == design.process
