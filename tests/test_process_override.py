"""``--process laser|sla|PATH`` overrides a template's process: every shipped template builds for the laser
(or fails naming what the process cannot make), a profile file with ``arcs = "segments"`` gives DXFs that
OpenSCAD reads with the reported areas, and ``check`` rebuilds with the same profile. What a process makes
follows from what it can do (``technique``, ``layout``), never from its name: a new profile needs no code."""

from __future__ import annotations

import dataclasses
import io
import json
import shutil
import subprocess

import ezdxf
import numpy as np
import pytest
import shapely
import shapely.ops

from fabricate.cli import main
from fabricate.design import design_from_text, load_design
from fabricate.errors import SpecError
from fabricate.hints import PartHints
from fabricate.process import ProcessOverride, parse_process, process_override
from fabricate.table import Table
from fabricate.templates import TEMPLATE_DIR, read_toml, shipped_templates

TEMPLATES = [p.stem for p in shipped_templates()]


#: template -> the only kinds of failure its laser build may have (none: it must pass). Clip retention: every pin
#: sticks out of both faces of its stack for its DIN 6799 clip and washers, and the layer order keeps those ends,
#: the spring-lengthened pins and a motor's side clear. The six-bar needs a layer of its own for one body (its
#: MG996R's bare spline reaches one layer into the stack, where the rocker-ground pin's clip end would sit under
#: the case otherwise). The gripper cut from 3 mm acrylic fails only what the laser profile cannot give it: its
#: hinges' strength (the template's 12 mm plates) and its spring's 27 mm arbor (a printed part, thicker than the
#: sheet: nor its shop rules, held to half that thickness). The default five-bar finger keeps its 6 mm plates (a
#: listed stock) and cuts its servo plate from 3 mm. Not listed (open, any named failure accepted): the underactuated
#: finger
#: (ten bodies in five colours of 6 mm sheet: no order of at most seven layers leaves every clip end clear, and its
#: music-wire anchor holes are below the shop's smallest hole).
LASER_PASSES = {
    "finger_watt_six_bar": (),
    "gear_pair_elliptic": (),
    "jansen_leg": (),
    "linkage_quick_return": (),
    "linkage_stephenson": (),
    "gripper_compliant": ("strength:", "printability: spring_arbor_", "shop: part spring_arbor_"),
    "finger_five_bar_ncg": (),
}


@pytest.mark.slow
@pytest.mark.parametrize("template", TEMPLATES)
def test_every_template_builds_for_the_laser_or_names_what_it_cannot_make(template, tmp_path, shipped_build):
    from fabricate.output import write_output

    out = tmp_path / "out"
    outcome = shipped_build(template, "laser")
    write_output(outcome.files, out)
    code = outcome.exit_code
    assert code in (0, 1)
    report = json.loads((out / "report.json").read_text())
    if template in LASER_PASSES:
        assert outcome.design.process.retention == "clip" and outcome.partset is not None
        # every pin is clipped: it sticks out of both faces for its clip
        assert all(min(p.protrusion_mm) > 0.0 and p.end_items[0] and p.end_items[1] for p in outcome.partset.pins)
        assert [f for f in outcome.failures if f.startswith(("interference:", "clearance:"))] == []
        allowed = LASER_PASSES[template]
        assert [f for f in outcome.failures if not f.startswith(allowed or ("\0",))] == []
        assert code == (1 if outcome.failures else 0)
        if not allowed:
            assert code == 0, outcome.failures
    assert report["design"]["process"] == "laser"
    assert report["design"]["process_override"]["source"] == "laser"
    assert any(f.startswith("cut/sheet_") and f.endswith(".svg") for f in report["files"])
    assert not any(f.startswith("plates/") for f in report["files"])
    if code == 1:
        failures = report["checks"]["failures"]
        assert failures and all(isinstance(f, str) and ":" in f for f in failures)
    # the design's own pin survives the override; everything else is the laser's
    laser = load_design(template, "laser").process
    assert laser.kerf_mm == pytest.approx(0.2) and laser.build_volume_mm[:2] == (790.0, 384.0)
    own = read_toml(TEMPLATE_DIR / f"{template}.toml").get("process", {}).get("pin_diameter_mm")
    assert laser.pin_diameter_mm == (own if own is not None else 3.0)  # else the laser profile's 3 mm
    # the files a shop takes as sent: no text, only part contours cut, every part labelled or listed, sheets sized
    from tests.export.test_labels import assert_shop_ready

    assert_shop_ready(out, report, laser)


def test_a_bad_process_is_named(tmp_path, capsys):
    assert main(["build", "gear_pair_elliptic", "--process", "waterjet", "-o", str(tmp_path / "o")]) == 2
    assert "--process: expected sla, fdm, laser or a process profile file" in capsys.readouterr().err
    profile = tmp_path / "mine.toml"
    profile.write_text((TEMPLATE_DIR / "process_laser.toml").read_text().replace('"#ff0000"', '"red"'))
    assert main(["build", "gear_pair_elliptic", "--process", str(profile), "-o", str(tmp_path / "o")]) == 2
    assert 'cut_colour: expected a colour "#rrggbb", got "red"' in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
def test_check_rebuilds_with_the_process_it_was_built_with(tmp_path, capsys, shared_stage_cache, serve_builds):
    """The build's stages go to the session's shared stage cache and check's rebuild is served from it (as in
    tests/test_verify.py): every stage's key holds the process (fabricate/stage_keys.py), so a rebuild with any
    other process (the template's own 3 mm SLA, say) misses, runs, and its 3 mm parts differ from the folder's."""

    profile = tmp_path / "thick.toml"
    profile.write_text((TEMPLATE_DIR / "process_laser.toml").read_text()
                       .replace("thickness_mm = 3.0", "thickness_mm = 4.0")
                       .replace("build_volume_mm = [790.0, 384.0, 3.0]", "build_volume_mm = [790.0, 384.0, 4.0]"))
    out = tmp_path / "out"
    with shared_stage_cache():
        code = main(["build", "gear_pair_elliptic", "--process", str(profile), "-o", str(out), "-q"])
    assert code in (0, 1)
    report = json.loads((out / "report.json").read_text())
    assert report["design"]["process_override"] == {"source": "thick.toml", "text": profile.read_text()}
    assert {p["thickness_mm"] for p in report["parts"]} == {4.0}
    profile.unlink()  # check needs nothing but the folder
    serve_builds()
    assert main(["check", str(out), "-q"]) == code
    assert "differs" not in capsys.readouterr().out
    assert main(["check", str(out), "--process", "sla"]) == 2


def _even_odd_area(faces: list[shapely.Polygon]) -> float:
    """Area enclosed by the faces' outer rings under the even-odd rule (outline less holes).

    A ring's depth is counted at a point of its own face (which leaves its holes out): a point of the whole
    ring may lie in a hole (a mount plate's cut-out fills most of it) and be counted one level too deep."""
    polys = [shapely.Polygon(f.exterior) for f in faces]
    area = 0.0
    for f, p in zip(faces, polys, strict=True):
        inside = f.representative_point()
        depth = sum(1 for q in polys if q is not p and q.contains(inside))
        area += (-1) ** depth * abs(p.area)
    return area


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("openscad") is None, reason="OpenSCAD not installed")
def test_segment_arcs_give_openscad_the_reported_areas(tmp_path, shipped_build, shared_stage_cache):
    """The build runs on the session's shared stage cache, which ``shipped_build`` fills with the finger's laser
    build: the stages whose keys leave out the arcs setting (synthesis, gears) are served, the rest run."""
    profile = tmp_path / "laser_segments.toml"
    profile.write_text((TEMPLATE_DIR / "process_laser.toml").read_text().replace('arcs = "bulge"', 'arcs = "segments"'))
    out = tmp_path / "out"
    shipped_build("finger_five_bar_ncg", "laser")
    with shared_stage_cache():
        assert main(["build", "finger_five_bar_ncg", "--process", str(profile), "-o", str(out), "-q"]) in (0, 1)
    report = json.loads((out / "report.json").read_text())
    tol = load_design("finger_five_bar_ncg", str(profile)).process.chord_tolerance_mm
    for part in report["parts"]:
        data = (out / part["dxf"]).read_bytes()
        doc = ezdxf.read(io.StringIO(data.decode()))
        bulges = [b for e in doc.modelspace().query("LWPOLYLINE") for *_, b in e.get_points("xyb")]
        assert not any(bulges), part["name"]  # no reader has to understand bulges
        scad = tmp_path / f"{part['name']}.scad"
        # holes stay CIRCLEs: 720 facets keep OpenSCAD's own polygon of them within 2e-5 of their area
        scad.write_text(f'$fn = 720; import("{out / part["dxf"]}", layer="CUT");\n')
        result = tmp_path / f"{part['name']}.dxf"
        run = subprocess.run(["openscad", "-o", str(result), str(scad)], capture_output=True, text=True,
                             timeout=120)
        assert run.returncode == 0 and "ERROR" not in run.stderr, run.stderr
        # OpenSCAD writes the 2D result as loose LINEs: join them into contours again
        lines = [((e.dxf.start.x, e.dxf.start.y), (e.dxf.end.x, e.dxf.end.y))
                 for e in ezdxf.readfile(result).modelspace() if e.dxftype() == "LINE"]
        faces = list(shapely.ops.polygonize(shapely.MultiLineString(lines)))
        rings = [np.asarray(f.exterior.coords) for f in faces]
        perimeter = sum(shapely.LinearRing(r).length for r in rings)
        # segments lie on the arcs (inscribed): the area lost is at most sagitta x perimeter; OpenSCAD
        # prints 6 significant digits (1e-4 mm here) and its holes are 720-gons
        bound = (tol + 1e-4) * perimeter + 2e-5 * part["area_mm2"]
        assert abs(_even_odd_area(faces) - part["area_mm2"]) <= bound, part["name"]
    # the files sent to the shop: each part's cut path and each sheet at the area report.json gives (kerf
    # applied), read as sent (every layer: no "Unsupported DXF Entity 'TEXT'", the labels are outlines)
    cut = [(f"cut/{p['name']}.dxf", p["cut_area_mm2"]) for p in report["parts"]]
    cut += [(s["file"], s["cut_area_mm2"]) for s in report["cut"]["sheets"]]
    for rel, area in cut:
        scad = tmp_path / "cut.scad"
        scad.write_text(f'$fn = 720; import("{out / rel}");\n')
        run = subprocess.run(["openscad", "-o", str(tmp_path / "all.dxf"), str(scad)], capture_output=True,
                             text=True, timeout=120)
        assert run.returncode == 0 and "ERROR" not in run.stderr and "Unsupported" not in run.stderr, run.stderr
        scad.write_text(f'$fn = 720; import("{out / rel}", layer="CUT");\n')
        run = subprocess.run(["openscad", "-o", str(tmp_path / "cut.dxf"), str(scad)], capture_output=True,
                             text=True, timeout=120)
        assert run.returncode == 0 and "WARNING" not in run.stderr, run.stderr
        lines = [((e.dxf.start.x, e.dxf.start.y), (e.dxf.end.x, e.dxf.end.y))
                 for e in ezdxf.readfile(tmp_path / "cut.dxf").modelspace() if e.dxftype() == "LINE"]
        faces = list(shapely.ops.polygonize(shapely.MultiLineString(lines)))
        perimeter = sum(f.exterior.length for f in faces)
        assert abs(_even_odd_area(faces) - area) <= (tol + 1e-4) * perimeter + 2e-5 * area, rel


# -- Step 13: a process is what it can do (technique, layout), never its name -----------------------------------

def _without_capabilities(text: str) -> str:
    """A profile as written before ``technique`` and ``layout`` existed."""
    return "\n".join(line for line in text.splitlines() if not line.startswith(("technique", "layout")))


def test_a_new_shipped_profile_needs_no_code_change(tmp_path, monkeypatch):
    """A profile file dropped into templates/ (here an FDM printer) is a template's ``profile`` and a
    ``--process`` name, named in the errors that list the choices, and keeps the capabilities it states."""
    import fabricate.process as process_module

    shipped = tmp_path / "templates"
    shipped.mkdir()
    for path in TEMPLATE_DIR.glob("process_*.toml"):
        shutil.copy(path, shipped)
    sla = (TEMPLATE_DIR / "process_sla.toml").read_text(encoding="utf-8")
    assert sla.count('method = "sla"') == 1
    (shipped / "process_fdm.toml").write_text(sla.replace('method = "sla"', 'method = "fdm"')
                                              .replace("min_feature_mm = 0.3", "min_feature_mm = 0.4"))
    monkeypatch.setattr(process_module, "TEMPLATE_DIR", shipped)
    assert process_module.shipped_profiles() == ("sla", "fdm", "laser")  # the default first

    text = (TEMPLATE_DIR / "gear_pair_elliptic.toml").read_text(encoding="utf-8")
    assert text.count('profile = "sla"') == 1
    fdm = design_from_text(text.replace('profile = "sla"', 'profile = "fdm"'), "g.toml").process
    assert (fdm.name, fdm.technique, fdm.layout, fdm.min_feature_mm) == ("fdm", "additive", "plate", 0.4)
    assert process_override("fdm").text == (shipped / "process_fdm.toml").read_text(encoding="utf-8")
    with pytest.raises(SpecError, match="expected sla, fdm, laser or a process profile file"):
        process_override("waterjet")
    with pytest.raises(SpecError, match="expected one of 'sla', 'fdm', 'laser'") as info:
        design_from_text(text.replace('profile = "sla"', 'profile = "waterjet"'), "g.toml")
    assert info.value.path == "process.profile"


def test_a_profile_without_capabilities_takes_those_of_its_method_or_states_them():
    """A ``--process`` file older than the capability fields (embedded in an old build's report.json, which
    ``check`` rebuilds from) takes them from the shipped profile of its ``method``; a method of its own must
    state them, and a method is a plain name."""
    old = _without_capabilities((TEMPLATE_DIR / "process_laser.toml").read_text(encoding="utf-8"))
    assert old.count('method = "laser"') == 1
    laser = parse_process(Table({}, "process"), ProcessOverride("old.toml", old))
    assert (laser.name, laser.technique, laser.layout) == ("laser", "cut", "sheet")
    router = old.replace('method = "laser"', 'method = "router"')
    with pytest.raises(SpecError) as info:
        parse_process(Table({}, "process"), ProcessOverride("router.toml", router))
    assert info.value.path == "--process router.toml.technique" and info.value.message == "missing required field"
    spec = parse_process(Table({}, "process"),
                         ProcessOverride("router.toml", 'technique = "cut"\nlayout = "sheet"\n' + router))
    assert (spec.name, spec.technique, spec.layout) == ("router", "cut", "sheet")
    with pytest.raises(SpecError, match="expected one of 'additive', 'cut'") as info:
        parse_process(Table({"technique": "milled"}, "process"))
    assert info.value.path == "process.technique"
    with pytest.raises(SpecError, match="expected a process name") as info:
        parse_process(Table({}, "process"), ProcessOverride("x.toml", old.replace('method = "laser"',
                                                                                  'method = "../laser"')))
    assert info.value.path == "--process x.toml.method"


def test_what_is_made_follows_the_capabilities_not_the_name(four_bar, laser_process):
    """The laser's numbers under another name make the same cut files and sheets; under the laser's name
    but additive on plates they make print plates and no cut file. The web round a hole is at least the
    stock only for a cut process."""
    from fabricate.export import export_all
    from fabricate.parts.build import build_parts, derive_sizes
    from fabricate.parts.spec import PartsSpec

    motion = four_bar.sweep(37)
    base = load_design("gear_pair_elliptic")

    def made(process):
        design = dataclasses.replace(base, process=process, parts=PartsSpec(gif_frames=4))
        partset = build_parts(design, four_bar, motion, [])
        files, entries = export_all(design, partset, four_bar, motion, previews=False, step=False,
                                    with_step=False)
        return partset, files, entries

    laser, files, entries = made(laser_process)
    router, router_files, router_entries = made(dataclasses.replace(laser_process, name="router"))
    assert set(router_files) == set(files) and any(f.startswith("cut/sheet_") for f in files)
    assert router_files["cut/sheet_1.svg"] == files["cut/sheet_1.svg"]
    assert [e["sheet"] for e in router_entries] == [e["sheet"] for e in entries]
    assert {r["kind"] for r in router.bom if r["kind"].endswith(" part")} == {"cut part"}
    assert {r["process"] for r in router.bom if r["kind"].endswith(" part")} == {"router"}  # the label

    printed, printed_files, printed_entries = made(dataclasses.replace(laser_process, technique="additive",
                                                                       layout="plate"))
    assert not any(f.startswith("cut/") for f in printed_files)
    assert any(f.startswith("plates/plate_") for f in printed_files)
    assert all("plate" in e and "sheet" not in e and e["cut_dxf"] is None for e in printed_entries)
    assert {r["kind"] for r in printed.bom if r["kind"].endswith(" part")} == {"printed part"}

    thick_cut = dataclasses.replace(laser_process, name="router", thickness_mm=5.0)
    thick_printed = dataclasses.replace(thick_cut, technique="additive", layout="plate")
    hole = derive_sizes(thick_cut, PartsSpec(), PartHints()).hole_mm
    assert derive_sizes(thick_cut, PartsSpec(), PartHints()).boss_radius_mm == pytest.approx(hole / 2 + 5.0)
    assert derive_sizes(thick_printed, PartsSpec(), PartHints()).boss_radius_mm == pytest.approx(hole / 2 + 3.0)


@pytest.mark.parametrize(("template", "process", "thickness"), [
    ("finger_five_bar_ncg", "laser", 6.0),  # 6 mm acrylic is a stock the laser profile names
    ("gripper_compliant", "laser", 3.0),  # 12 mm is not: the laser's own 3 mm sheet
    ("finger_five_bar_ncg", "fdm", 6.0),  # a printer prints any plate thickness
    ("gripper_compliant", "fdm", 12.0),
    ("jansen_leg", "laser", 3.0),  # the template gives none: the profile's
])
def test_process_keeps_the_templates_thickness_where_the_process_makes_it(template, process, thickness):
    spec = load_design(template, process).process
    assert spec.thickness_mm == thickness
    shipped = read_toml(TEMPLATE_DIR / f"process_{process}.toml")
    if spec.layout == "sheet":
        # the sheet is the stock it is cut from; the profile's shop numbers are its own 3 mm stock's
        assert spec.build_volume_mm == (790.0, 384.0, thickness)
        assert spec.stock_thickness_mm == (3.0, 6.0) and thickness in spec.stock_thickness_mm
        from fabricate.checks.shop import ShopRules

        rules = ShopRules.of(spec)
        expected = (shipped["shop"]["min_hole_mm"] if thickness == shipped["thickness_mm"] else 0.5 * thickness)
        assert (rules.min_hole_mm, rules.min_web_mm, rules.min_hole_edge_mm) == (expected,) * 3
    else:
        assert spec.build_volume_mm[2] >= thickness


def test_a_cut_profile_without_stock_keeps_only_its_own_thickness():
    text = (TEMPLATE_DIR / "process_laser.toml").read_text()
    text = text.replace("stock_thickness_mm = [3.0, 6.0]", "")
    spec = parse_process(Table({"profile": "sla", "thickness_mm": 6.0}, "process"), ProcessOverride("mine.toml", text))
    assert spec.thickness_mm == 3.0 and spec.stock_thickness_mm == ()
    bad = text.replace("thickness_mm = 3.0 ", "stock_thickness_mm = []\nthickness_mm = 3.0 ")
    with pytest.raises(SpecError, match="at least one thickness"):
        parse_process(Table({}, "process"), ProcessOverride("bad.toml", bad))
