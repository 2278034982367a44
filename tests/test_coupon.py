"""Calibration coupons (fabricate/coupon.py) and ``fabricate coupon`` / ``fabricate init --process``: the coupon
of every shipped process is made, its holes and slots measure their labelled clearances on the exported files
themselves, the profile copy reads back as the shipped profile, and bad input exits 2 writing nothing."""

from __future__ import annotations

import io
import math

import ezdxf
import numpy as np
import pytest
import trimesh

from fabricate.checks.shop import check_shop
from fabricate.cli import main
from fabricate.coupon import (
    ADDENDUM,
    CLEARANCES_MM,
    EMBOSS_MM,
    PRESSURE_ANGLE_DEG,
    SLOT_OFFSETS_MM,
    coupon_files,
    coupon_process,
    make_coupon,
)
from fabricate.export.dxf import cut_file_problems
from fabricate.export.stl import validate_stl
from fabricate.process import parse_process, process_override, shipped_profiles
from fabricate.table import Table


def _fit_circle(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares circle (Kasa) through (n, 2) points: centre and diameter."""
    a = np.column_stack([2.0 * points, np.ones(len(points))])
    b = (points ** 2).sum(axis=1)
    (cx, cy, c), *_ = np.linalg.lstsq(a, b, rcond=None)
    return np.array([cx, cy]), 2.0 * math.sqrt(c + cx * cx + cy * cy)


@pytest.mark.parametrize("name", shipped_profiles())
def test_coupon_builds_for_every_shipped_process(name):
    process = coupon_process(name)
    files = coupon_files(process, name)
    cut = process.technique == "cut"
    assert set(files) == ({"coupon.dxf", "coupon.svg", "README.md"} if cut
                          else {"coupon.stl", "coupon.3mf", "README.md"})
    if cut:
        assert cut_file_problems(files["coupon.dxf"]) == []
        assert b"<text" not in files["coupon.svg"]
    else:
        assert validate_stl(files["coupon.stl"]) == []
    readme = files["README.md"].decode()
    fields = ["running_clearance_mm", "press_fit_interference_mm", "min_feature_mm", f"--process my_{name}.toml"]
    fields.append("kerf_mm" if cut else "hole_compensation_mm")
    for field in fields:
        assert f"{field}" in readme, field
    coupon = make_coupon(process)
    labels = [f.label for f in coupon.features if f.kind == "hole"]
    assert sorted(float(t) for t in labels) == sorted(CLEARANCES_MM)  # every clearance labelled once
    assert len(coupon.labels) == len(coupon.features)
    assert coupon.labels[0].height_mm >= process.min_text_mm


@pytest.mark.parametrize("name", [n for n in shipped_profiles() if coupon_process(n).technique == "additive"])
def test_printed_coupon_holes_measure_their_labelled_clearances(name):
    """Slice the exported STL at mid-thickness, fit a circle to every hole: it is the pin plus the hole's
    labelled clearance plus the profile's hole compensation, within the chord tolerance."""
    process = coupon_process(name)
    coupon = make_coupon(process)
    mesh = trimesh.load(io.BytesIO(coupon_files(process)["coupon.stl"]), file_type="stl")
    t = process.thickness_mm
    assert mesh.is_watertight  # the plate and its raised labels are one closed shell
    assert mesh.bounds[1][2] == pytest.approx(t + EMBOSS_MM)  # the labels stand on the top face
    # the cut's segments (trimesh's own, without its path graph); each hole's are those near its centre
    lines = trimesh.intersections.mesh_plane(mesh, plane_normal=[0.0, 0.0, 1.0], plane_origin=[0.0, 0.0, 0.5 * t])
    points = lines.reshape(-1, 3)[:, :2]
    holes = [f for f in coupon.features if f.kind == "hole"]
    near = [np.hypot(*(points - f.centre).T) < 0.5 * f.modelled_mm + process.min_wall_mm / 2 for f in holes]
    assert np.count_nonzero(np.any(near, axis=0)) < len(points)  # the rest is the plate's outline
    for feature, mine in zip(holes, near, strict=True):
        centre, diameter = _fit_circle(points[mine])
        assert np.hypot(*(centre - feature.centre)) < 0.01
        # an inscribed polygon reads at most 2 x the chord tolerance small
        measured = diameter - process.hole_compensation_mm - process.pin_diameter_mm
        assert measured == pytest.approx(float(feature.label), abs=2.0 * process.chord_tolerance_mm + 1e-4)


def test_cut_coupon_holes_and_slots_measure_their_labels():
    """On the laser DXF: each hole CIRCLE plus the kerf is the pin plus its labelled clearance; each comb slot's
    path plus the kerf is the sheet plus its label; the labels are engraved outlines, no TEXT."""
    process = coupon_process("laser")
    coupon = make_coupon(process)
    doc = ezdxf.read(io.StringIO(coupon_files(process)["coupon.dxf"].decode()))
    msp = doc.modelspace()
    assert check_shop([coupon.part], process).failures == ()  # the shop's rules (hole, web, hole to edge)
    assert not list(msp.query("TEXT MTEXT"))
    assert len(msp.query('LWPOLYLINE[layer=="ENGRAVE"]')) > 0
    circles = list(msp.query('CIRCLE[layer=="CUT"]'))
    holes = [f for f in coupon.features if f.kind == "hole"]
    assert len(circles) == len(holes)
    for feature in holes:
        circle = min(circles, key=lambda c: float(np.hypot(c.dxf.center.x - feature.centre[0],
                                                           c.dxf.center.y - feature.centre[1])))
        finished = 2.0 * circle.dxf.radius + process.kerf_mm
        assert finished - process.pin_diameter_mm == pytest.approx(float(feature.label), abs=1e-9)
    polylines = [np.asarray(p.get_points("xy")) for p in msp.query('LWPOLYLINE[layer=="CUT"]')]
    slots = [p for p in polylines if len(p) == 4]
    assert len(slots) == len(SLOT_OFFSETS_MM)
    for feature in (f for f in coupon.features if f.kind == "slot"):
        slot = min(slots, key=lambda s: float(np.hypot(*(s.mean(axis=0) - feature.centre))))
        width = float(np.ptp(slot[:, 0])) + process.kerf_mm
        assert width - process.thickness_mm == pytest.approx(float(feature.label), abs=1e-9)


@pytest.mark.parametrize("name", shipped_profiles())
def test_rack_has_the_process_module_and_a_tip_land_it_makes(name):
    process = coupon_process(name)
    coupon = make_coupon(process)
    m = coupon.module_mm
    land = m * (math.pi / 2.0 - 2.0 * ADDENDUM * math.tan(math.radians(PRESSURE_ANGLE_DEG)))
    assert land >= process.min_feature_mm
    v = coupon.part.outline.vertices
    tips = v[np.isclose(v[:, 1], -ADDENDUM * m)]
    assert len(tips) >= 4 and len(tips) % 2 == 0
    widths = tips[1::2, 0] - tips[0::2, 0]
    assert np.allclose(widths, land, atol=1e-9)
    assert np.allclose(np.diff(tips[0::2, 0]), math.pi * m, atol=1e-9)


@pytest.mark.parametrize("name", shipped_profiles())
def test_init_process_copy_round_trips(name, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["init", "--process", name, "-o", "mine.toml"]) == 0
    copy = parse_process(Table({}, "process"), process_override(str(tmp_path / "mine.toml")))
    shipped = parse_process(Table({}, "process"), process_override(name))
    assert copy == shipped
    assert copy.materials == shipped.materials
    assert main(["init", "--process", name, "-o", "mine.toml"]) == 2  # never overwritten
    assert "exists already" in capsys.readouterr().err


def test_coupon_cli_writes_the_files_from_a_profile_copy(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["init", "--process", "sla"]) == 0
    assert main(["coupon", "--process", "my_sla.toml", "-o", "c"]) == 0
    assert sorted(p.name for p in (tmp_path / "c").iterdir()) == ["README.md", "coupon.3mf", "coupon.stl"]
    # the loop: a measured compensation edited into the copy is what the next coupon (and build) uses
    copy = tmp_path / "my_sla.toml"
    text = copy.read_text()
    assert "hole_compensation_mm = 0.2 " in text
    copy.write_text(text.replace("hole_compensation_mm = 0.2 ", "hole_compensation_mm = 0.35"))
    edited = make_coupon(coupon_process(str(copy)))
    assert edited.process.hole_compensation_mm == 0.35
    assert all(abs(f.modelled_mm - f.nominal_mm - 0.35) < 1e-12 for f in edited.features)


@pytest.mark.parametrize("argv", [["coupon", "--process", "nope", "-o", "out"],
                                  ["coupon", "--process", "sla", "--printer", "prusa_mk4", "-o", "out"],
                                  ["init", "--process", "nope", "-o", "out"]])
def test_bad_process_exits_2_naming_it_and_writes_nothing(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert ("--printer" if "--printer" in argv else "--process") in err
    assert not (tmp_path / "out").exists()
