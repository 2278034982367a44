"""``fabricate check DIR`` verifies what is on disk: one tampering per file type, each named with exit 1."""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from collections.abc import Callable
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import trimesh

from fabricate.cli import main
from fabricate.design import load_design
from fabricate.pipeline import run_build
from fabricate.report_schema import SCHEMA_VERSION
from fabricate.templates import TEMPLATE_DIR

FAST = "gear_pair_elliptic"


@pytest.fixture(scope="module")
def built(built_folder, shipped_build) -> Path:
    """The pair as ``fabricate build`` writes it (cold, once per session); a test copies it before changing it.
    ``shipped_build`` fills the shared stage cache the checks' rebuilds are served from."""
    shipped_build(FAST)
    found = built_folder(FAST, read_only=True)
    assert found.exit_code == 0
    return found.path


_REBUILDS: dict[tuple[str, str, str, bool, bool], object] = {}


@pytest.fixture(autouse=True)
def _one_rebuild_per_template(monkeypatch, shared_stage_cache):
    """Every check rebuilds its embedded template; most tamperings here share one, so build it once
    (the real pipeline, only not repeated: a test-time saving of ~5 s a case). Its stages come from the session's
    shared stage cache (``shared_stage_cache``, byte-identical to a cold build per tests/test_cache.py): the
    folders checked here are cold builds of the command (``built_folder``), so a check still compares two
    builds, while the workers make each design's stages once between them."""
    import fabricate.pipeline as pipeline

    real = pipeline.run_build

    def cached(design, progress=lambda _m: None, *, optional=None, pictures=True):
        from fabricate.export.step import step_available

        if optional is not None and optional.step_files is not None:  # stand-ins: never cached
            return real(design, progress, optional=optional, pictures=pictures)
        step = step_available() if optional is None else optional.step
        key = (Path(design.template).name, design.template_text, repr(design.process_override), step, pictures)
        if key not in _REBUILDS:
            # a check's rebuild names its optional outputs; a build that asks step_available (a test that
            # pretends OCP is missing) runs cold: the cache's keys know the installed OCP, not a patch of it
            with shared_stage_cache(repr(key)) if optional is not None else contextlib.nullcontext():
                _REBUILDS[key] = real(design, progress, optional=optional, pictures=pictures)
        return _REBUILDS[key]

    monkeypatch.setattr(pipeline, "run_build", cached)


@pytest.fixture(autouse=True)
def _one_reading_per_file(monkeypatch, tmp_path_factory):
    """Each file's verdict kept by content (conftest.keep_verdicts; reading STEP back with OCP is ~2.5 s a
    folder), shared by the session's workers: both read the same untouched folder, STEP files and all."""
    from tests.conftest import keep_verdicts, session_folder

    shared = session_folder(tmp_path_factory) / "test-verify-verdicts"
    shared.mkdir(exist_ok=True)
    keep_verdicts(monkeypatch, shared)


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


@pytest.mark.slow
def test_an_untouched_output_passes(copy, capsys):
    code, out = _check(copy, capsys)
    assert code == 0, out
    assert "checks passed" in out


def _edit_first_cut_radius(path: Path, change: Callable[[float], float]) -> None:
    """Change the first CUT circle's radius (group code 40) in place, the file no larger than before: a file
    within its manifest size is read and parsed (a larger one is named by its size alone, never read)."""
    lines = path.read_text().split("\n")
    start = next(k for k in range(len(lines) - 8) if lines[k] == "CIRCLE" and "CUT" in lines[k:k + 10])
    at = next(k for k in range(start, len(lines)) if lines[k].strip() == "40") + 1
    radius = float(lines[at])
    lines[at] = next(text for digits in range(8, 0, -1)
                     if len(text := f"{change(radius):.{digits}g}") <= len(lines[at]))
    path.write_text("\n".join(lines))
    edited = ezdxf.read(io.StringIO(path.read_text())).modelspace().query('CIRCLE[layer=="CUT"]').first
    assert edited.dxf.radius == pytest.approx(change(radius), abs=0.01)


def _dxf_hole_radius_x3(d: Path) -> str:
    _edit_first_cut_radius(d / "drawings" / "carrier.dxf", lambda r: 3.0 * r)
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
    # compressed like fabricate's own: smaller than the manifest says, so check reads and parses it (a file
    # larger on disk than its manifest entry is named by its size, never read)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
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


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(TAMPERINGS))
def test_tampering_is_caught_and_named(copy, capsys, name):
    needle = TAMPERINGS[name](copy)
    code, out = _check(copy, capsys)
    assert code == 1
    assert needle in out, out


@pytest.mark.slow
def test_a_broken_report_is_named(copy, capsys):
    (copy / "report.json").write_text("{ not json")
    code, out = _check(copy, capsys)
    assert code == 1 and "report.json: not valid JSON" in out


def test_a_folder_without_a_report_is_a_usage_error(tmp_path, capsys):
    assert main(["check", str(tmp_path)]) == 2
    assert "not a fabricate output folder" in capsys.readouterr().err


@pytest.mark.slow
def test_the_verdict_depends_neither_on_the_folder_nor_on_later_edits(tmp_path, monkeypatch, capsys,
                                                                       shared_stage_cache):
    designs = tmp_path / "designs"
    designs.mkdir()
    (designs / "pair.toml").write_bytes((TEMPLATE_DIR / f"{FAST}.toml").read_bytes())
    monkeypatch.chdir(designs)
    with shared_stage_cache():  # the pair's stages, as any build of it (this is about the template's path)
        assert main(["build", "pair.toml", "-o", str(tmp_path / "out"), "-q"]) == 0  # a relative template path
    report = _report(tmp_path / "out")
    assert report["design"]["template"] == "pair.toml"
    assert report["template_text"] == (designs / "pair.toml").read_text()
    assert {m["path"] for m in report["manifest"]} | {"report.json"} == set(report["files"])
    (designs / "pair.toml").write_text("edited after the build")
    monkeypatch.chdir(tmp_path)
    code, out = _check(tmp_path / "out", capsys)
    assert code == 0, out


@pytest.mark.slow
def test_manifest_sizes_and_hashes_are_those_on_disk(built):
    import hashlib

    report = _report(built)
    for item in report["manifest"]:
        data = (built / item["path"]).read_bytes()
        assert len(data) == item["bytes"]
        assert hashlib.sha256(data).hexdigest() == item["sha256"]
    # the STL volumes the check holds parts to are the meshes' own, and close to area x thickness: the mesh's
    # outline and holes lie within the chord tolerance of the exact ones, so the volumes differ by at most that
    # tolerance x the walls' area (perimeter x thickness); a fixed 0.1 % failed the drive's small standoff tubes
    # (0.12 %), while a missing pin hole (its area x thickness) would still exceed the bound
    tol = load_design(FAST).process.chord_tolerance_mm
    for part in report["parts"]:
        mesh = trimesh.load(built / part["stl"])
        assert mesh.volume == pytest.approx(part["stl_volume_mm3"], rel=1e-6)
        walls = float(mesh.area_faces[np.abs(mesh.face_normals[:, 2]) < 1e-6].sum())
        assert abs(part["stl_volume_mm3"] - part["volume_mm3"]) <= tol * walls, part["name"]


@pytest.fixture(scope="module")
def laser_built(built_folder, shipped_build) -> Path:
    """The same pair made on the laser (``--process laser``): cut/ files (DXF and SVG, kerf-compensated) instead
    of plates. Shared: a test copies it before changing it."""
    shipped_build(FAST, "laser")  # the checks' rebuilds: from the stage cache it fills
    found = built_folder(FAST, "laser", read_only=True)
    assert (found.path / "cut").is_dir() and not (found.path / "plates").exists()
    return found.path


def _laser_copy(laser_built: Path, tmp_path: Path) -> Path:
    target = tmp_path / "laser"
    shutil.copytree(laser_built, target)
    return target


@pytest.mark.slow
def test_a_laser_output_passes_and_its_cut_files_are_verified(laser_built, tmp_path, capsys):
    copy = _laser_copy(laser_built, tmp_path)
    assert (copy / "cut" / "sheet_1.svg").is_file() and not (copy / "plates").exists()
    code, out = _check(copy, capsys)
    assert "cut/" not in out, out  # whatever the design's own verdict, no cut file is flagged
    (copy / "cut" / "sheet_1.svg").write_text("<svg")
    # gear_b's pin hole (gear_a has no round hole since Step 14: the motor's D-bore is a contour)
    _edit_first_cut_radius(copy / "cut" / "gear_b.dxf", lambda r: r + 0.1)  # a kerf applied twice
    code, out = _check(copy, capsys)
    assert code == 1
    assert "cut/sheet_1.svg: not readable SVG" in out and "cut/gear_b.dxf: cut holes" in out


@pytest.mark.slow
def test_a_tampered_step_solid_is_named(copy, capsys):
    pytest.importorskip("OCP")
    path = copy / "parts" / "gear_a.step"
    text = path.read_text()
    # move one Cartesian point of the solid by 50 mm in x (its leading digit, so the size stays): still a
    # STEP file, no longer the reported solid
    marker = "CARTESIAN_POINT('',("
    start = text.index(marker, len(text) // 2) + len(marker)
    start += text[start] == "-"
    path.write_text(text[:start] + str((int(text[start]) + 5) % 10) + text[start + 1:])
    code, out = _check(copy, capsys)
    assert code == 1
    assert "parts/gear_a.step: contents differ from the manifest" in out
    assert "parts/gear_a.step: solid" in out  # read back: the solid is not the reported one
    assert "not compared with a rebuild" in out and "differs from a rebuild" not in out


@pytest.mark.slow
def test_without_ocp_a_build_says_step_was_skipped(built_without_cad):
    # the command's own build with step_available False (built_folder(step=False)), and what it printed
    out = built_without_cad.output
    assert built_without_cad.exit_code == 0, out
    assert out.count("STEP skipped") == 1 and "fabricate[cad]" in out
    report = _report(built_without_cad.path)
    assert not any(f.endswith(".step") for f in report["files"])
    assert all(p["step"] is None for p in report["parts"])
    assert "STEP skipped" in (built_without_cad.path / "report.md").read_text()


# --- check is bounded by the manifest (issue 23, item 3) ---------------------------------------------------

#: Peak resident memory (MB) a `check` that rejects a wrong file may reach: the interpreter, numpy, trimesh,
#: ezdxf and Pillow imported and the small files parsed measure 65-125 MB; reading the 2 GB file or inflating
#: the bomb would take 2 GB or more (a plain `check` of the intact folder peaks at ~560 MB: it rebuilds).
REJECT_PEAK_MB = 200


def _fabricate_peak_mb(*args: str) -> tuple[int, str, float]:
    """Run ``fabricate ARGS`` in a fresh interpreter that reports the peak resident memory of that child
    alone (RUSAGE_CHILDREN of this process would include every earlier child): (exit code, output, MB)."""
    probe = ("import resource, subprocess, sys\n"
             "done = subprocess.run([sys.executable, '-m', 'fabricate', *sys.argv[1:]], capture_output=True,\n"
             "                      text=True)\n"
             "peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss\n"
             "print(done.returncode, peak / (2**20 if sys.platform == 'darwin' else 2**10))\n"
             "print(done.stdout + done.stderr)\n")
    env = {**os.environ, "FABRICATE_SERIAL": "1"}
    run = subprocess.run([sys.executable, "-c", probe, *args], capture_output=True, text=True, timeout=600, env=env)
    assert run.returncode == 0, run.stderr
    head, _, output = run.stdout.partition("\n")
    code, peak = head.split()
    return int(code), output, float(peak)


@pytest.mark.slow
def test_a_2gb_sparse_file_is_named_by_its_size_and_never_read(copy):
    listed = {m["path"]: m["bytes"] for m in _report(copy)["manifest"]}
    with open(copy / "motion.csv", "r+b") as fh:
        fh.truncate(2**31)  # sparse: no disk space, 2 GB to whoever reads it
    code, out, peak = _fabricate_peak_mb("check", str(copy), "-q")
    assert code == 1, out
    assert f"motion.csv: 2147483648 bytes on disk, {listed['motion.csv']} bytes in the manifest" in out
    assert "Traceback" not in out
    assert peak < REJECT_PEAK_MB, f"{peak:.0f} MB"


def _zip_bomb(inflated_mb: int) -> bytes:
    """A zip named like a 3MF whose model member is ``inflated_mb`` MB of zeros (~1000-fold deflate)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as archive:
        archive.writestr("[Content_Types].xml", "<Types/>")
        with archive.open("3D/3dmodel.model", "w", force_zip64=True) as member:
            for _ in range(inflated_mb):
                member.write(b"\0" * 2**20)
    return buffer.getvalue()


def _forge_manifest(folder: Path, rel: str, data: bytes, drop_step: bool = False) -> None:
    """Write ``data`` to ``rel`` and make report.json's manifest agree with it (a forged folder)."""
    import hashlib

    (folder / rel).write_bytes(data)
    report = _report(folder)
    for item in report["manifest"]:
        if item["path"] == rel:
            item["bytes"], item["sha256"] = len(data), hashlib.sha256(data).hexdigest()
    if drop_step:  # so the child's peak is the bomb's, not OCP reading the STEP files back
        steps = {m["path"] for m in report["manifest"] if m["path"].endswith(".step")}
        report["manifest"] = [m for m in report["manifest"] if m["path"] not in steps]
        report["files"] = [f for f in report["files"] if f not in steps]
        for rel_step in steps:
            (folder / rel_step).unlink()
    (folder / "report.json").write_text(json.dumps(report, indent=2))


@pytest.mark.slow
def test_a_zip_bomb_3mf_is_rejected_without_inflating(copy, tmp_path):
    bomb = _zip_bomb(256)
    assert len(bomb) < 300_000  # the 262 kB bomb: 256 MB of model
    # as found: larger than the manifest's 3MF, so it is named by its size and never opened
    (copy / "assembly.3mf").write_bytes(bomb)
    code, out, peak = _fabricate_peak_mb("check", str(copy), "-q")
    assert code == 1 and f"assembly.3mf: {len(bomb)} bytes on disk" in out, out
    assert peak < REJECT_PEAK_MB, f"{peak:.0f} MB"
    # with a manifest forged to match it, it is opened as a zip and judged by its members' declared sizes
    _forge_manifest(copy, "assembly.3mf", bomb, drop_step=True)
    code, out, peak = _fabricate_peak_mb("check", str(copy), "-q")
    assert code == 1, out
    assert "assembly.3mf: member '3D/3dmodel.model' declares 268435456 bytes" in out and "not inflated" in out
    assert "Traceback" not in out
    assert peak < REJECT_PEAK_MB, f"{peak:.0f} MB"


@pytest.mark.slow
def test_a_zip_bomb_within_the_manifest_size_is_never_inflated(copy, capsys, monkeypatch):
    import zipfile

    import fabricate.export.stl as stl

    manifest_bytes = {m["path"]: m["bytes"] for m in _report(copy)["manifest"]}["assembly.3mf"]
    bomb = _zip_bomb(64)
    assert len(bomb) <= manifest_bytes  # so it is read (its hash differs) and parsed to say how it differs
    # every zip member opened (to be inflated) from here on, by its declared size
    opened: list[int] = []
    real_open = zipfile.ZipFile.open

    def spying(self, name, *args, **kwargs):
        opened.append((name if isinstance(name, zipfile.ZipInfo) else self.getinfo(name)).file_size)
        return real_open(self, name, *args, **kwargs)

    monkeypatch.setattr(zipfile.ZipFile, "open", spying)
    stl.read_3mf((copy / "assembly.3mf").read_bytes())  # the spy sees a real 3MF's model being read
    assert opened
    (copy / "assembly.3mf").write_bytes(bomb)
    opened.clear()
    code, out = _check(copy, capsys)
    assert code == 1
    assert f"assembly.3mf: {len(bomb)} bytes on disk, {manifest_bytes} bytes in the manifest" in out
    assert "assembly.3mf: member '3D/3dmodel.model' declares 67108864 bytes" in out
    assert 64 * 2**20 not in opened  # the bomb's member was never opened: judged by its declared size


@pytest.mark.slow
def test_a_3mf_with_another_compression_method_is_not_inflated(copy, capsys):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_BZIP2) as archive:  # bzip2 chunks inflate whole
        archive.writestr("3D/3dmodel.model", "<model/>")
    _forge_manifest(copy, "plates/plate_1.3mf", buffer.getvalue())
    code, out = _check(copy, capsys)
    assert code == 1 and "plates/plate_1.3mf: member '3D/3dmodel.model' is compressed with method 12" in out


@pytest.mark.slow
def test_an_image_declaring_too_many_pixels_is_not_decoded(copy, capsys):
    from PIL import Image

    from fabricate.verify_files import IMAGE_MAX_PIXELS

    side = int(IMAGE_MAX_PIXELS**0.5) + 1
    buffer = io.BytesIO()
    Image.new("1", (side, side)).save(buffer, format="PNG")  # a few kB on disk, 2 GB as RGBA
    _forge_manifest(copy, "previews/assembly.png", buffer.getvalue())
    code, out = _check(copy, capsys)
    assert code == 1 and f"previews/assembly.png: an image of {side} x {side} pixels" in out


def _outside_copy(copy: Path, rel: str) -> Path:
    outside = copy.parent / "elsewhere"
    outside.mkdir(exist_ok=True)
    target = outside / Path(rel).name
    shutil.copyfile(copy / rel, target)
    return target


@pytest.mark.slow
def test_a_symlink_is_never_followed_even_to_identical_bytes(copy, capsys):
    target = _outside_copy(copy, "bom.csv")
    (copy / "bom.csv").unlink()
    (copy / "bom.csv").symlink_to(target)  # the same bytes: only the link betrays it
    code, out = _check(copy, capsys)
    assert code == 1
    assert f"bom.csv: is a symbolic link to '{target}', not a regular file (check follows no links)" in out


@pytest.mark.slow
def test_a_symlinked_folder_on_the_path_is_never_followed(copy, capsys):
    outside = copy.parent / "elsewhere_parts"
    shutil.copytree(copy / "parts", outside)
    shutil.rmtree(copy / "parts")
    (copy / "parts").symlink_to(outside, target_is_directory=True)
    code, out = _check(copy, capsys)
    assert code == 1
    assert "parts/gear_a.stl: its folder parts is a symbolic link" in out
    assert "parts: not written by fabricate" in out


@pytest.mark.slow
def test_a_folder_in_place_of_a_file_is_named(copy, capsys):
    (copy / "assembly.csv").unlink()
    (copy / "assembly.csv").mkdir()
    code, out = _check(copy, capsys)
    assert code == 1 and "assembly.csv: is a folder, not a regular file" in out


@pytest.mark.slow
def test_a_socket_in_place_of_a_file_is_never_opened(copy, capsys, monkeypatch):
    import socket

    if not hasattr(socket, "AF_UNIX"):
        pytest.skip("no Unix sockets here")
    (copy / "assembly.csv").unlink()
    monkeypatch.chdir(copy)  # a relative name: socket paths are limited to ~100 bytes
    with socket.socket(socket.AF_UNIX) as server:
        server.bind("assembly.csv")
        code, out = _check(copy, capsys)
    assert code == 1 and "assembly.csv: is a socket, not a regular file" in out


@pytest.mark.slow
@pytest.mark.parametrize("rel", ["motion.csv", "report.json"])
def test_a_fifo_is_never_opened(copy, rel):
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    (copy / rel).unlink()
    os.mkfifo(copy / rel)  # opening it for reading would block until a writer came: forever
    done = subprocess.run([sys.executable, "-m", "fabricate", "check", str(copy), "-q"], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 1, done.stdout + done.stderr
    assert f"{rel}: is a FIFO (named pipe), not a regular file" in done.stdout
    assert "Traceback" not in done.stdout + done.stderr


@pytest.mark.slow
def test_a_symlinked_report_is_never_followed(copy, capsys):
    target = _outside_copy(copy, "report.json")
    (copy / "report.json").unlink()
    (copy / "report.json").symlink_to(target)
    code, out = _check(copy, capsys)
    assert code == 1 and "report.json: is a symbolic link to" in out


# --- report.json: bounded, then validated against its schema (issue 23, items 3 and 6) ---------------------


@pytest.mark.slow
def test_a_huge_report_is_not_read(copy, capsys):
    from fabricate.verify import REPORT_MAX_BYTES

    with open(copy / "report.json", "r+b") as fh:
        fh.truncate(REPORT_MAX_BYTES + 1)
    code, out = _check(copy, capsys)
    assert code == 1 and f"report.json: {REPORT_MAX_BYTES + 1} bytes, more than any report fabricate writes" in out


def _edit_report(folder: Path, edit: Callable[[dict], None]) -> None:
    report = _report(folder)
    edit(report)
    (folder / "report.json").write_text(json.dumps(report, indent=2))


@pytest.mark.slow
@pytest.mark.parametrize(("edit", "message"), [
    (lambda r: r["parts"][1].update(holes="4 holes"), "report.json: parts[1].holes is not a list (it is a string)"),
    (lambda r: r["parts"][0]["holes"][0].update(diameter_mm=None), "parts[0].holes[0].diameter_mm is not a number"),
    (lambda r: r["manifest"][2].update(bytes="512"), "report.json: manifest[2].bytes is not an integer"),
    (lambda r: r["manifest"][0].update(sha256="0" * 63), "manifest[0].sha256 '000"),
    (lambda r: r["manifest"][0].update(path="../../etc/passwd"), "manifest[0].path '../../etc/passwd' is not a"),
    (lambda r: r["files"].append("/etc/passwd"), "is not a relative path inside the output folder"),
    (lambda r: r["design"].update(name=["x"]), "report.json: design.name is not a string (it is a list)"),
    (lambda r: r["checks"].pop("failures"), "report.json: checks.failures is missing"),
    (lambda r: r["checks"].update(not_checked=[{"check": "strength"}]), "checks.not_checked[0].reason is missing"),
    (lambda r: r["parts"][0].update(plate={"index": "1"}), "parts[0].plate.index is not a list"),
    (lambda r: r["parts"][0].update(copies=0), "parts[0].copies is 0, less than 1"),
    (lambda r: r["mechanism"].update(input_range_deg=[0]), "mechanism.input_range_deg has 1 item, not 2"),
    (lambda r: r.update(template_text=7), "template_text is not a string"),
    (lambda r: r["design"].update(process_override={"source": "x"}), "design.process_override.text is missing"),
    (lambda r: r.update(schema_version="2.0"), "report.json: schema_version 2.0: a report format this fabricate "
                                               "does not read (it reads 1.x)"),
    (lambda r: r.pop("schema_version"), "report.json: no schema_version: written by an older fabricate"),
])
def test_a_report_of_the_wrong_shape_is_named_before_it_is_read(copy, capsys, edit, message):
    _edit_report(copy, edit)
    code, out = _check(copy, capsys)
    assert code == 1
    assert message in out, out


@pytest.mark.slow
@pytest.mark.parametrize(("text", "message"), [
    ('{"design": {"name": NaN}}', "not valid JSON (NaN is not JSON)"),
    ("[" * 100_000 + "]" * 100_000, "not valid JSON (nested too deeply)"),
    ('{"design": {}, "manifest": [], "n": ' + "9" * 5000 + "}", "not valid JSON"),
    ("[]", "not a fabricate report (no design section)"),
])
def test_a_report_that_is_not_json_is_named(copy, capsys, text, message):
    (copy / "report.json").write_text(text)
    code, out = _check(copy, capsys)
    assert code == 1 and f"report.json: {message}" in out


def test_the_schema_uses_only_what_its_validator_implements():
    import re

    from fabricate.report_schema import report_schema, unsupported_keywords

    schema = report_schema()
    assert unsupported_keywords(schema) == set()
    assert unsupported_keywords({"properties": {"a": {"oneOf": []}}, "items": {"format": "x"}}) == {"oneOf", "format"}

    def patterns(node):
        if isinstance(node, dict):
            yield from ([node["pattern"]] if isinstance(node.get("pattern"), str) else [])
            for value in node.values():
                yield from patterns(value)

    found = list(patterns(schema))
    assert len(found) >= 3
    for pattern in found:
        re.compile(pattern)


def test_the_path_pattern_admits_only_relative_paths_inside_the_folder():
    import re

    from fabricate.report_schema import report_schema

    pattern = report_schema()["$defs"]["path"]["pattern"]
    good = ["report.md", "parts/gear_a.stl", "gears/pair_mesh.png", ".hidden/x", "a..b/c", "..."]
    bad = ["", "/etc/passwd", "../x", "a/../b", "..", ".", "a/.", "./a", "a//b", "a/", "a\0b", "a\n", "x/..\n"]
    assert all(re.search(pattern, p) for p in good)
    assert not any(re.search(pattern, p) for p in bad)


@pytest.mark.slow
def test_every_shipped_template_writes_a_report_that_matches_its_schema(shipped_build):
    import fabricate.pipeline as pipeline
    from fabricate.report_schema import schema_errors
    from fabricate.templates import shipped_templates

    templates = shipped_templates()
    assert len(templates) >= 8
    metrics = _sweep_metrics()
    for path in templates:
        outcome = shipped_build(path.stem)  # the shipped report itself: full poses, pictures and STEP files
        report = json.loads(outcome.files["report.json"])
        assert report["parts"] and report["strength"] and report["outputs"]["step"]
        assert next(iter(report)) == "schema_version" and report["schema_version"] == SCHEMA_VERSION
        assert schema_errors(report) == [], path.stem
        _reads_only_schema_keys(report, metrics)
    synth = pipeline.run_synth(load_design("linkage_stephenson"))
    assert schema_errors(json.loads(synth.files["report.json"])) == []
    # the shipped sweep's own metrics came out as numbers from a report cut down to the schema's keys
    assert all(not np.isnan(value) for value in metrics["finger_five_bar_ncg"].values())


def _schema_only(value, node=None):
    """``value`` (a parsed report) with only the keys the schema names: what is left is the contract."""
    from fabricate.report_schema import report_schema

    root = report_schema()
    node = root if node is None else node
    while "$ref" in node:
        target = root
        for part in node["$ref"][2:].split("/"):
            target = target[part]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    if isinstance(value, dict):
        properties, extra = node.get("properties", {}), node.get("additionalProperties")
        return {key: _schema_only(item, properties.get(key, extra)) for key, item in value.items()
                if key in properties or isinstance(extra, dict)}
    if isinstance(value, list) and isinstance(node.get("items"), dict):
        return [_schema_only(item, node["items"]) for item in value]
    return value


def _sweep_metrics():
    """Every metric a shipped sweep or the README reads, and the default ones, by name (``{template: {}}``
    collects the values read)."""
    from fabricate.sweep.paths import parse_metric
    from fabricate.sweep.spec import default_metrics, load_sweep

    names = set(default_metrics("build"))
    for spec in (TEMPLATE_DIR / "sweeps").glob("*.toml"):
        names |= {m.name for m in load_sweep(spec).metrics}
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    line = next(text for text in readme.splitlines() if text.startswith("| `--metric"))
    names |= {token for token in re.findall(r"`([^`]+)`", line) if "." in token and not token.startswith("--")}
    assert {"synthesis.pose_error_mm.max", "interference.min_clearance_mm"} <= names
    return {"metrics": [parse_metric(n, "metric") for n in sorted(names)], "finger_five_bar_ncg": {}}


def _reads_only_schema_keys(report, metrics) -> None:
    """What check and sweeps read from a report is the same from the report cut down to the schema's keys:
    every key they read is in the schema."""
    from fabricate.report import not_checked, verdict
    from fabricate.verify import _expected_by_file, _manifest, _recorded_step

    contract = _schema_only(report)
    assert contract != report  # extras exist (synthesis' method results), so the cut is a real one
    for read in (_expected_by_file, _manifest, _recorded_step, not_checked, verdict):
        assert read(contract) == read(report), read.__name__
    for metric in metrics["metrics"]:
        full, cut = metric.read(report), metric.read(contract)
        assert full == cut or (np.isnan(full) and np.isnan(cut)), metric.name
        if report["design"]["kind"] == "five_bar_ncg":
            metrics["finger_five_bar_ncg"][metric.name] = cut


@pytest.mark.slow
def test_check_reads_only_what_the_schema_names(copy, laser_built, tmp_path, capsys):
    """A folder whose report.json holds only the schema's keys passes every check but the rebuild's byte
    comparison of report.json itself: the manifest, every file's contents and the rebuild read nothing else."""
    laser = _laser_copy(laser_built, tmp_path)
    for folder in (copy, laser):
        report = _report(folder)
        (folder / "report.json").write_text(json.dumps(_schema_only(report), indent=2))
        code, out = _check(folder, capsys)
        assert code == 1
        assert [line for line in out.splitlines() if line.startswith("  - ")] == [
            "  - report.json: differs from a rebuild of the embedded template"], out


@pytest.mark.slow
def test_the_full_builds_match_the_schema_too(built, laser_built):
    from fabricate.report_schema import schema_errors

    for folder in (built, laser_built):
        assert schema_errors(_report(folder)) == []


# --- the same verdict on any install (issue 23, item 7) ---------------------------------------------------


@pytest.fixture(scope="module")
def built_without_cad(built_folder):
    """The same pair built by the command as on an install without the `cad` extra (no OCP: STEP skipped):
    a ``BuiltFolder`` (path, exit code, output), shared: a test copies it before changing it."""
    found = built_folder(FAST, step=False, read_only=True)
    assert found.exit_code == 0, found.output
    return found


@pytest.mark.slow
@pytest.mark.parametrize("built_with", ["cad", "no_cad"], ids=["built_with_cad", "built_without"])
@pytest.mark.parametrize("checked_with", ["cad", "no_cad"], ids=["checked_with_cad", "checked_without"])
def test_check_gives_the_same_verdict_on_any_install(built, built_without_cad, tmp_path, monkeypatch, capsys,
                                                     built_with, checked_with):
    import fabricate.export.step as step

    if "cad" in (built_with, checked_with) and not step.step_available():
        pytest.skip("OCP (the cad extra) is not installed here")
    source = built if built_with == "cad" else built_without_cad.path
    folder = tmp_path / FAST
    shutil.copytree(source, folder)
    report = _report(folder)
    has_step = any(f.endswith(".step") for f in report["files"])
    assert has_step == (built_with == "cad")
    assert report["outputs"]["step"] == "written" if has_step else report["outputs"]["step"].startswith("skipped")
    if checked_with == "no_cad":  # as without OCP: asked, it is not there; STEP export would fail
        monkeypatch.setattr(step, "step_available", lambda: False)

        def no_ocp(*_args, **_kwargs):
            raise ImportError("No module named 'OCP'")

        monkeypatch.setattr(step, "step_files", no_ocp)
        if built_with == "cad":  # the real rebuild, not one cached with OCP: STEP bytes must come from the folder
            import fabricate.pipeline as pipeline

            monkeypatch.setattr(pipeline, "run_build", run_build)
    code, out = _check(folder, capsys)
    assert code == 0, out
    assert ("not comparable here" in out) == (built_with == "cad" and checked_with == "no_cad")
    assert step.step_available() == (checked_with == "cad")  # the rebuild's answer was the folder's, then restored
