"""``fabricate check DIR`` verifies what is on disk: one tampering per file type, each named with exit 1."""

from __future__ import annotations

import io
import json
import shutil
import zipfile
from collections.abc import Callable
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import trimesh

from fabricate.cli import main
from fabricate.output import write_output
from fabricate.pipeline import run_build
from fabricate.spec import TEMPLATE_DIR, load_design

FAST = "gear_pair_elliptic"


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("built") / FAST
    outcome = run_build(load_design(FAST))
    assert outcome.exit_code == 0
    write_output(outcome.files, out)
    return out


_REBUILDS: dict[tuple[str, str, bool], object] = {}


@pytest.fixture(autouse=True)
def _one_rebuild_per_template(monkeypatch):
    """Every check rebuilds its embedded template; most tamperings here share one, so build it once
    (the real pipeline, only not repeated: a test-time saving of ~5 s a case)."""
    import fabricate.pipeline as pipeline

    real = pipeline.run_build

    def cached(design, progress=lambda _m: None):
        from fabricate.export.step import step_available

        key = (Path(design.template).name, design.template_text, step_available())
        if key not in _REBUILDS:
            _REBUILDS[key] = real(design, progress)
        return _REBUILDS[key]

    monkeypatch.setattr(pipeline, "run_build", cached)


_STEP_VERDICTS: dict[tuple, list[str]] = {}


@pytest.fixture(autouse=True)
def _one_step_reading_per_file(monkeypatch):
    """Reading STEP back with OCP is most of a check's time (~2.5 s a file); a tampering of another file
    leaves the STEP files as they were, so their verdict (a function of the bytes and the expectation) is
    kept by content hash. A changed STEP file has another hash and is read for real."""
    import hashlib

    import fabricate.export.step as step

    real = step.step_problems

    def cached(data, expected=None, rel_tol=1e-6):
        key = (hashlib.sha256(data).hexdigest(), tuple(sorted((expected or {}).items())), rel_tol)
        if key not in _STEP_VERDICTS:
            _STEP_VERDICTS[key] = real(data, expected, rel_tol)
        return list(_STEP_VERDICTS[key])

    monkeypatch.setattr(step, "step_problems", cached)


@pytest.fixture
def copy(built, tmp_path) -> Path:
    target = tmp_path / FAST
    shutil.copytree(built, target)
    return target


def _check(directory: Path, capsys) -> tuple[int, str]:
    code = main(["check", str(directory), "-q"])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.out + captured.err
    return code, captured.out


def _report(directory: Path) -> dict:
    return json.loads((directory / "report.json").read_text())


def test_an_untouched_output_passes(copy, capsys):
    code, out = _check(copy, capsys)
    assert code == 0, out
    assert "checks passed" in out


def _dxf_hole_radius_x3(d: Path) -> str:
    path = d / "drawings" / "carrier.dxf"
    doc = ezdxf.read(io.StringIO(path.read_text()))
    circle = doc.modelspace().query('CIRCLE[layer=="CUT"]').first
    circle.dxf.radius *= 3.0
    stream = io.StringIO()
    doc.write(stream)
    path.write_text(stream.getvalue())
    return "drawings/carrier.dxf: cut holes"


def _dxf_garbage(d: Path) -> str:
    (d / "drawings" / "kinematic.dxf").write_text("garbage")
    return "drawings/kinematic.dxf: not a readable DXF"


def _stl_scaled(d: Path) -> str:
    path = d / "parts" / "gear_a.stl"
    mesh = trimesh.load(io.BytesIO(path.read_bytes()), file_type="stl")
    mesh.apply_scale(1.5)
    assert mesh.is_watertight  # still a perfectly good solid: only its size betrays it
    path.write_bytes(trimesh.exchange.stl.export_stl(mesh))
    return "parts/gear_a.stl: volume"


def _stl_truncated(d: Path) -> str:
    path = d / "plates" / "plate_1.stl"
    path.write_bytes(path.read_bytes()[:-37])
    return "plates/plate_1.stl: truncated"


def _3mf_corrupt(d: Path) -> str:
    path = d / "assembly.3mf"
    data = bytearray(path.read_bytes())
    data[len(data) // 2: len(data) // 2 + 64] = b"\0" * 64
    path.write_bytes(bytes(data))
    return "assembly.3mf: not a readable 3MF"


def _3mf_object_dropped(d: Path) -> str:
    path = d / "assembly.3mf"
    with zipfile.ZipFile(path) as archive:
        entries = {name: archive.read(name) for name in archive.namelist()}
    model = entries["3D/3dmodel.model"].decode()
    start = model.index('<object id="3"')
    model = model[:start] + model[model.index("</object>", start) + len("</object>"):]
    entries["3D/3dmodel.model"] = model.replace('<item objectid="3"/>', "").encode()
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in entries.items():
            archive.writestr(name, data)
    return "assembly.3mf: objects"


def _png_corrupt(d: Path) -> str:
    path = d / "previews" / "assembly.png"
    path.write_bytes(path.read_bytes()[:200])
    return "previews/assembly.png: not a readable image"


def _file_list_emptied(d: Path) -> str:
    report = _report(d)
    report["files"] = []
    (d / "report.json").write_text(json.dumps(report, indent=2))
    return "report.json: its file list and its manifest disagree"


def _template_edited_in_report(d: Path) -> str:
    report = _report(d)
    report["template_text"] = report["template_text"].replace("teeth = [30, 30]", "teeth = [32, 32]")
    assert "teeth = [32, 32]" in report["template_text"]
    (d / "report.json").write_text(json.dumps(report, indent=2))
    return "parts/gear_a.stl: differs from a rebuild of the embedded template"


def _template_swapped(d: Path) -> str:
    report = _report(d)
    report["template_text"] = (TEMPLATE_DIR / "finger_five_bar_ncg.toml").read_text()
    (d / "report.json").write_text(json.dumps(report, indent=2))
    return "a rebuild of the embedded template does not write it"


def _file_deleted(d: Path) -> str:
    (d / "bom.csv").unlink()
    return "bom.csv: missing"


def _file_added(d: Path) -> str:
    (d / "parts" / "extra.stl").write_bytes((d / "parts" / "gear_a.stl").read_bytes())
    return "parts/extra.stl: not written by fabricate"


def _bom_edited(d: Path) -> str:
    path = d / "bom.csv"
    path.write_text(path.read_text().replace("pin", "pun", 1))  # same size: only the hash tells
    return "bom.csv: contents differ from the manifest"


TAMPERINGS: dict[str, Callable[[Path], str]] = {
    "dxf_hole_radius_x3": _dxf_hole_radius_x3, "dxf_garbage": _dxf_garbage, "stl_scaled_1.5": _stl_scaled,
    "stl_truncated": _stl_truncated, "3mf_corrupt": _3mf_corrupt, "3mf_object_dropped": _3mf_object_dropped,
    "png_corrupt": _png_corrupt, "report_file_list_emptied": _file_list_emptied,
    "template_edited": _template_edited_in_report, "template_swapped": _template_swapped,
    "file_deleted": _file_deleted, "file_added": _file_added, "csv_edited": _bom_edited,
}


@pytest.mark.parametrize("name", sorted(TAMPERINGS))
def test_tampering_is_caught_and_named(copy, capsys, name):
    needle = TAMPERINGS[name](copy)
    code, out = _check(copy, capsys)
    assert code == 1
    assert needle in out, out


def test_a_broken_report_is_named(copy, capsys):
    (copy / "report.json").write_text("{ not json")
    code, out = _check(copy, capsys)
    assert code == 1 and "report.json: not valid JSON" in out


def test_a_folder_without_a_report_is_a_usage_error(tmp_path, capsys):
    assert main(["check", str(tmp_path)]) == 2
    assert "not a fabricate output folder" in capsys.readouterr().err


def test_the_verdict_depends_neither_on_the_folder_nor_on_later_edits(tmp_path, monkeypatch, capsys):
    designs = tmp_path / "designs"
    designs.mkdir()
    (designs / "pair.toml").write_bytes((TEMPLATE_DIR / f"{FAST}.toml").read_bytes())
    monkeypatch.chdir(designs)
    assert main(["build", "pair.toml", "-o", str(tmp_path / "out"), "-q"]) == 0  # a relative template path
    report = _report(tmp_path / "out")
    assert report["design"]["template"] == "pair.toml"
    assert report["template_text"] == (designs / "pair.toml").read_text()
    assert {m["path"] for m in report["manifest"]} | {"report.json"} == set(report["files"])
    (designs / "pair.toml").write_text("edited after the build")
    monkeypatch.chdir(tmp_path)
    code, out = _check(tmp_path / "out", capsys)
    assert code == 0, out


def test_manifest_sizes_and_hashes_are_those_on_disk(built):
    import hashlib

    report = _report(built)
    for item in report["manifest"]:
        data = (built / item["path"]).read_bytes()
        assert len(data) == item["bytes"]
        assert hashlib.sha256(data).hexdigest() == item["sha256"]
    # the STL volumes the check holds parts to are the meshes' own, and close to area x thickness
    for part in report["parts"]:
        mesh = trimesh.load(built / part["stl"])
        assert mesh.volume == pytest.approx(part["stl_volume_mm3"], rel=1e-6)
        assert np.isclose(part["stl_volume_mm3"], part["volume_mm3"], rtol=1e-3)


@pytest.fixture(scope="module")
def laser_built(tmp_path_factory) -> Path:
    """The same pair made on the laser: cut/ files (DXF and SVG, kerf-compensated) instead of plates."""
    src = tmp_path_factory.mktemp("laser_src") / "pair_laser.toml"
    text = (TEMPLATE_DIR / f"{FAST}.toml").read_text().replace('profile = "sla"', 'profile = "laser"', 1)
    assert 'profile = "laser"' in text
    src.write_text(text)
    out = tmp_path_factory.mktemp("laser") / "out"
    outcome = run_build(load_design(src))
    write_output(outcome.files, out)
    return out


def _laser_copy(laser_built: Path, tmp_path: Path) -> Path:
    target = tmp_path / "laser"
    shutil.copytree(laser_built, target)
    return target


def test_a_laser_output_passes_and_its_cut_files_are_verified(laser_built, tmp_path, capsys):
    copy = _laser_copy(laser_built, tmp_path)
    assert (copy / "cut" / "sheet_1.svg").is_file() and not (copy / "plates").exists()
    code, out = _check(copy, capsys)
    assert "cut/" not in out, out  # whatever the design's own verdict, no cut file is flagged
    (copy / "cut" / "sheet_1.svg").write_text("<svg")
    path = copy / "cut" / "gear_a.dxf"
    doc = ezdxf.read(io.StringIO(path.read_text()))
    doc.modelspace().query('CIRCLE[layer=="CUT"]').first.dxf.radius += 0.1  # a kerf applied twice
    stream = io.StringIO()
    doc.write(stream)
    path.write_text(stream.getvalue())
    code, out = _check(copy, capsys)
    assert code == 1
    assert "cut/sheet_1.svg: not readable SVG" in out and "cut/gear_a.dxf: cut holes" in out


def test_a_tampered_step_solid_is_named(copy, capsys):
    pytest.importorskip("OCP")
    path = copy / "parts" / "gear_a.step"
    text = path.read_text()
    # move one Cartesian point of the solid: still a STEP file, no longer the reported solid
    marker = "CARTESIAN_POINT('',("
    start = text.index(marker, len(text) // 2) + len(marker)
    end = text.index(",", start)
    path.write_text(text[:start] + str(float(text[start:end]) + 5.0) + text[end:])
    code, out = _check(copy, capsys)
    assert code == 1
    assert "parts/gear_a.step: contents differ from the manifest" in out
    assert "parts/gear_a.step: differs from a rebuild" in out


def test_without_ocp_a_build_says_step_was_skipped(tmp_path, monkeypatch, capsys):
    import fabricate.export.step as step

    monkeypatch.setattr(step, "step_available", lambda: False)
    assert main(["build", FAST, "-o", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert out.count("STEP skipped") == 1 and "fabricate[cad]" in out
    report = _report(tmp_path / "out")
    assert not any(f.endswith(".step") for f in report["files"])
    assert all(p["step"] is None for p in report["parts"])
    assert "STEP skipped" in (tmp_path / "out" / "report.md").read_text()
