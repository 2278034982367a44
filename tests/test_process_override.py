"""``--process laser|sla|PATH`` overrides a template's process: every shipped template builds for the laser
(or fails naming what the process cannot make), a profile file with ``arcs = "segments"`` gives DXFs that
OpenSCAD reads with the reported areas, and ``check`` rebuilds with the same profile."""

from __future__ import annotations

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
from fabricate.spec import TEMPLATE_DIR, load_design, read_toml, shipped_templates

TEMPLATES = [p.stem for p in shipped_templates()]


@pytest.mark.parametrize("template", TEMPLATES)
def test_every_template_builds_for_the_laser_or_names_what_it_cannot_make(template, tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["build", template, "--process", "laser", "-o", str(out), "-q"])
    assert code in (0, 1)
    report = json.loads((out / "report.json").read_text())
    assert report["design"]["process"] == "laser"
    assert report["design"]["process_override"]["source"] == "laser"
    assert any(f.startswith("cut/sheet_") and f.endswith(".svg") for f in report["files"])
    assert not any(f.startswith("plates/") for f in report["files"])
    if code == 1:
        failures = report["checks"]["failures"]
        assert failures and all(isinstance(f, str) and ":" in f for f in failures)
    # the design's own pin survives the override; everything else is the laser's
    laser = load_design(template, "laser").process
    assert laser.kerf_mm == pytest.approx(0.2) and laser.build_volume_mm[:2] == (600.0, 400.0)
    own = read_toml(TEMPLATE_DIR / f"{template}.toml").get("process", {}).get("pin_diameter_mm")
    assert laser.pin_diameter_mm == (own if own is not None else 3.0)  # else the laser profile's 3 mm


def test_a_bad_process_is_named(tmp_path, capsys):
    assert main(["build", "gear_pair_elliptic", "--process", "waterjet", "-o", str(tmp_path / "o")]) == 2
    assert "--process: expected sla, laser or a process profile file" in capsys.readouterr().err
    profile = tmp_path / "mine.toml"
    profile.write_text((TEMPLATE_DIR / "process_laser.toml").read_text().replace('"#ff0000"', '"red"'))
    assert main(["build", "gear_pair_elliptic", "--process", str(profile), "-o", str(tmp_path / "o")]) == 2
    assert 'cut_colour: expected a colour "#rrggbb", got "red"' in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_check_rebuilds_with_the_process_it_was_built_with(tmp_path, capsys):
    profile = tmp_path / "thick.toml"
    profile.write_text((TEMPLATE_DIR / "process_laser.toml").read_text()
                       .replace("thickness_mm = 3.0", "thickness_mm = 4.0")
                       .replace("build_volume_mm = [600.0, 400.0, 3.0]", "build_volume_mm = [600.0, 400.0, 4.0]"))
    out = tmp_path / "out"
    code = main(["build", "gear_pair_elliptic", "--process", str(profile), "-o", str(out), "-q"])
    assert code in (0, 1)
    report = json.loads((out / "report.json").read_text())
    assert report["design"]["process_override"] == {"source": "thick.toml", "text": profile.read_text()}
    assert {p["thickness_mm"] for p in report["parts"]} == {4.0}
    profile.unlink()  # check needs nothing but the folder
    assert main(["check", str(out), "-q"]) == code
    assert "differs" not in capsys.readouterr().out
    assert main(["check", str(out), "--process", "sla"]) == 2


def _even_odd_area(rings: list[np.ndarray]) -> float:
    """Area enclosed by closed rings under the even-odd rule (outline less holes)."""
    polys = [shapely.Polygon(r) for r in rings if len(r) >= 3]
    area = 0.0
    for p in polys:
        depth = sum(1 for q in polys if q is not p and q.contains(p.representative_point()))
        area += (-1) ** depth * abs(p.area)
    return area


@pytest.mark.skipif(shutil.which("openscad") is None, reason="OpenSCAD not installed")
def test_segment_arcs_give_openscad_the_reported_areas(tmp_path):
    profile = tmp_path / "laser_segments.toml"
    profile.write_text((TEMPLATE_DIR / "process_laser.toml").read_text().replace('arcs = "bulge"', 'arcs = "segments"'))
    out = tmp_path / "out"
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
        assert abs(_even_odd_area(rings) - part["area_mm2"]) <= bound, part["name"]
