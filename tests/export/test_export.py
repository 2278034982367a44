"""Exporters, read back by independent readers: STL (trimesh), DXF (ezdxf), 3MF (zip + XML), pictures (Pillow).

Every case (fixture mechanisms and every shipped template, each with the SLA and the laser profile) goes
through every exporter. Real tools (OpenSCAD, PrusaSlicer) are run when installed.
"""

from __future__ import annotations

import dataclasses
import io
import math
import os
import pickle
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from types import SimpleNamespace

import ezdxf
import numpy as np
import pytest
import shapely
import trimesh
from ezdxf import path as dxf_path
from ezdxf.math import bulge_to_arc
from PIL import Image

from fabricate.design import load_design
from fabricate.export import export_all, export_step
from fabricate.export.dxf import DxfStyle, audit_problems, part_dxf, sheet_dxf, sheet_layout
from fabricate.export.kinematic import kinematic_dxf
from fabricate.export.step import step_available
from fabricate.export.stl import (
    SolidCache,
    assembly_3mf,
    part_stl,
    placed_flat_mesh,
    plate_layout,
    plate_stl,
    validate_stl,
)
from fabricate.hints import PadHint, PartHints
from fabricate.kinds import KINDS
from fabricate.parts.build import build_parts
from fabricate.parts.spec import PartsSpec
from fabricate.process import ProcessSpec
from fabricate.templates import shipped_templates
from tests.conftest import locked, make_four_bar, session_folder
from tests.parts.test_build import slider_crank, spur_like, sun_planet_four_bar

SLA = ProcessSpec(name="sla", running_clearance_mm=0.25, hole_compensation_mm=0.2, min_wall_mm=0.8,
                  min_pin_mm=1.5, layer_gap_mm=0.3, thickness_mm=3.0, kerf_mm=0.0, min_feature_mm=0.3,
                  build_volume_mm=(130.0, 80.0, 160.0), pin_diameter_mm=2.0, chord_tolerance_mm=0.005)
LASER = ProcessSpec(name="laser", running_clearance_mm=0.1, hole_compensation_mm=0.0, min_wall_mm=3.0,
                    min_pin_mm=2.0, layer_gap_mm=0.5, thickness_mm=3.0, kerf_mm=0.2, min_feature_mm=0.5,
                    build_volume_mm=(600.0, 400.0, 3.0), pin_diameter_mm=3.0, chord_tolerance_mm=0.005,
                    technique="cut", layout="sheet", retention="clip", press_fit_interference_mm=0.0)
PROCESSES = {"sla": SLA, "laser": LASER}
FIXTURES = ("four_bar", "slider_crank", "geared_four_bar")
TEMPLATES = tuple(p.stem for p in shipped_templates())
CASES = [f"{m}-{p}" for m in FIXTURES + TEMPLATES for p in PROCESSES]


def _marked(names: list[str]) -> list:
    """``names`` as parameters; a shipped template's case (its whole part set and every export) is slow."""
    return [pytest.param(n, marks=pytest.mark.slow) if n.rsplit("-", 1)[0] in TEMPLATES else n for n in names]


@cache
def _synthesised(template: str):
    design = load_design(template)
    result = KINDS[design.kind].synthesise(design)
    try:
        from fabricate.gears import build_gear_pairs
    except ImportError:  # the gears layer is not there yet
        gear_pairs = []
    else:
        gear_pairs = build_gear_pairs(result.mechanism, design.gears, design.process.chord_tolerance_mm)
    return design, result, gear_pairs


#: The folder where this test session's workers share their cases (empty: each process makes its own, as a child
#: process of test_bytes_do_not_depend_on_the_hash_seed must).
_SHARED: list[Path] = []


@pytest.fixture(autouse=True, scope="module")
def _share_cases(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Cases are shared by the session's pytest-xdist workers: each test function is parametrised by case and its
    parameters are dealt out to both workers, so without this each worker made every case (pytest-xdist gives a
    worker its own basetemp inside the session's folder; without xdist the basetemp is the session's)."""
    folder = session_folder(tmp_path_factory) / "export-cases"
    folder.mkdir(exist_ok=True)
    _SHARED[:] = [folder]
    yield
    _SHARED.clear()


#: A case's fields that hold the mechanism (the elliptic pair's compiled law does not pickle).
_MECHANISM_FIELDS = ("mechanism", "motion", "gear_pairs")


@cache
def case(name: str) -> SimpleNamespace:
    """Design, mechanism, motion, part set and exported files of one case, made once per test session: the first
    worker to ask makes it (an exclusive lock per case, so the other waits instead of making it too) and leaves it
    pickled for the other. A template case whose mechanism does not pickle (the elliptic pair's holds its compiled
    law) is left without it, and the other worker synthesises it again (``_synthesised``, as make_case does: 0.6 s
    of the pair's 3 s for its two cases); its part set and files are the first worker's."""
    if not _SHARED:
        return make_case(name)
    with locked(_SHARED[0] / f"{name}.lock"):
        path = _SHARED[0] / f"{name}.pickle"
        if path.is_file():
            made = pickle.loads(path.read_bytes())
            if not hasattr(made, "mechanism"):
                _, result, made.gear_pairs = _synthesised(name.rsplit("-", 1)[0])
                made.mechanism = result.mechanism
                made.motion = made.mechanism.sweep(made.design.checks.sweep_poses + 1)
            return made
        made = make_case(name)
        try:
            blob = pickle.dumps(made, protocol=pickle.HIGHEST_PROTOCOL)
        except (pickle.PicklingError, AttributeError, TypeError):
            if name.rsplit("-", 1)[0] not in TEMPLATES:
                return made
            lean = SimpleNamespace(**{k: v for k, v in vars(made).items() if k not in _MECHANISM_FIELDS})
            blob = pickle.dumps(lean, protocol=pickle.HIGHEST_PROTOCOL)
        path.with_suffix(".part").write_bytes(blob)
        path.with_suffix(".part").replace(path)
        return made


def make_case(name: str) -> SimpleNamespace:
    """One case, made in this process. Its files are every export but STEP (no test here reads a STEP file; they
    are tests/export/test_step.py's, and the STEP exporter starts a process of its own: 60-90 % of a case's time)."""
    mech_name, process_name = name.rsplit("-", 1)
    process = PROCESSES[process_name]
    hints = PartHints()
    gear_pairs: list = []
    if mech_name in TEMPLATES:
        base, result, gear_pairs = _synthesised(mech_name)
        design = dataclasses.replace(base, process=dataclasses.replace(
            process, chord_tolerance_mm=base.process.chord_tolerance_mm))
        mechanism, hints = result.mechanism, result.parts
        motion = mechanism.sweep(design.checks.sweep_poses + 1)
    else:
        design = SimpleNamespace(name=mech_name, process=process, parts=PartsSpec(gif_frames=8),
                                 gears=SimpleNamespace(hub_diameter_mm=None))
        if mech_name == "slider_crank":
            mechanism = slider_crank()
        else:
            mechanism = make_four_bar()
        motion = mechanism.sweep(121)
        if mech_name == "geared_four_bar":
            mechanism = sun_planet_four_bar(mechanism)
            gear_pairs = [SimpleNamespace(name="sun_planet", body_a="ground", body_b="coupler", axis_a="O",
                                          axis_b="A", outline_a=spur_like(9.0, 12, 0.4),
                                          outline_b=spur_like(6.0, 8, 0.4))]
            hints = PartHints(pads={"rocker": PadHint("B", 4.0)})
    partset = build_parts(design, mechanism, motion, gear_pairs, hints)
    files, entries = export_all(design, partset, mechanism, motion, step=False)
    return SimpleNamespace(design=design, process=process, mechanism=mechanism, motion=motion,
                           partset=partset, files=files, entries=entries, gear_pairs=gear_pairs, hints=hints)


def perimeter_mm(part) -> float:
    """Outline, hole and slot perimeters (mm): with the chord tolerance it bounds the area error."""
    rings = part.polygons(1e-3)
    return float(sum(shapely.LinearRing(r).length for r in rings))


def expected_cut_diameter(hole, c) -> float:
    """Modelled hole minus the kerf. A pin's hole and a ``[parts]`` mounting hole from the process and the
    design alone (never from the part model's sizes, only its fit): a running or clearance hole is the pin (or
    the mounting screw) + 2 x radial clearance, a press-fit hole the pin - the profile's interference. Step 14's
    other holes (the actuator's screw, shaft and clearance holes, the springs' leg anchors and arbors) are sized
    from the catalogue item they take, so their nominal is the model's stated one (it must be stated). Every
    hole then gets the process's compensation (SLA) and loses the kerf."""
    process = c.process
    pin_joints = {j for p in c.partset.pins for j in (p.joint, *p.joint.split("+"))}
    if hole.joint.startswith("mount_"):
        nominal = c.design.parts.mounting_hole_mm + 2 * process.running_clearance_mm
    elif hole.joint in pin_joints and hole.fit == "press":
        nominal = process.pin_diameter_mm - process.press_fit_interference_mm
    elif hole.joint in pin_joints:
        nominal = process.pin_diameter_mm + 2 * process.running_clearance_mm
    else:
        assert hole.nominal_diameter_mm > 0.0, (hole.joint, "no nominal size stated")
        nominal = hole.nominal_diameter_mm
    return nominal + process.hole_compensation_mm - process.kerf_mm


def bulge_path_polygon(vertices, bulges, chord_mm: float = 1e-4) -> shapely.Polygon:
    """A closed line/arc path as a fine polygon, built here from the raw vertices and bulges with ezdxf's
    bulge-to-arc conversion (not the part model's own polygonisation)."""
    pts = []
    n = len(vertices)
    for i in range(n):
        p0, p1, b = np.asarray(vertices[i], float), np.asarray(vertices[(i + 1) % n], float), float(bulges[i])
        pts.append(p0)
        if b == 0.0:
            continue
        centre, start, end, radius = bulge_to_arc(p0, p1, b)
        sweep = (end - start) % (2 * math.pi)
        k = max(8, math.ceil(sweep / (2 * math.acos(1 - chord_mm / radius))))
        t = start + sweep * np.arange(1, k) / k
        arc = np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])
        pts.extend(arc if b > 0 else arc[::-1])
    return shapely.Polygon(np.array(pts))


def offset_area(vertices, bulges, distance_mm: float) -> tuple[float, float]:
    """Area of a closed path offset by ``distance_mm`` (Minkowski sum with a disc, or erosion when
    negative), by shapely from the raw path, and a bound on its polygonisation error (mm^2)."""
    poly = bulge_path_polygon(vertices, bulges)
    if distance_mm != 0.0:
        poly = poly.buffer(distance_mm, quad_segs=512)
    return float(poly.area), 2e-4 * float(poly.length) + 1e-9


# -- STL ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", _marked(CASES))
def test_stl_round_trip(name):
    c = case(name)
    tol = c.partset.chord_tolerance_mm
    flawed = {w.split(":")[0].removeprefix("part ") for w in c.partset.warnings}
    for part in c.partset.parts:
        data = c.files[f"parts/{part.name}.stl"]
        assert validate_stl(data) == []
        if part.name in flawed:  # holes run into each other: the count and exact area do not apply
            assert (2 - trimesh.load(io.BytesIO(data), file_type="stl").euler_number) // 2 < len(part.holes)
            continue
        mesh = trimesh.load(io.BytesIO(data), file_type="stl")
        assert mesh.is_watertight and mesh.is_winding_consistent
        # volume = exact plate area x thickness, within the chord bound (inscribed polygons lose at most
        # tolerance x perimeter of area) plus float32 rounding of the STL
        bound = tol * perimeter_mm(part) * part.thickness_mm + 1e-5 * part.volume_mm3()
        assert abs(mesh.volume - part.volume_mm3()) <= bound, (part.name, mesh.volume, part.volume_mm3(), bound)
        genus = (2 - mesh.euler_number) // 2
        assert genus == len(part.holes) + len(getattr(part, "slots", ())), part.name
        assert mesh.bounds[0][2] == pytest.approx(0.0, abs=1e-6)
        assert mesh.bounds[1][2] == pytest.approx(part.thickness_mm, abs=1e-5)


@pytest.mark.parametrize("name", _marked(CASES))
def test_plates_hold_every_copy_inside_the_build_area(name):
    c = case(name)
    plates = sorted(k for k in c.files if k.startswith("plates/") and k.endswith(".stl"))
    if c.process.name == "laser":  # a laser build cuts sheets instead
        assert not any(k.startswith("plates/") for k in c.files)
        return
    parts = list(c.partset.parts)
    copies = c.partset.copies
    width, depth = c.process.build_volume_mm[:2]
    margin = c.design.parts.plate_spacing_mm
    all_fit = all(e["plate"]["fits"] for e in c.entries)
    shells, volume = 0, 0.0
    for rel in plates:
        data = c.files[rel]
        assert validate_stl(data) == []
        mesh = trimesh.load(io.BytesIO(data), file_type="stl")
        bodies = mesh.split(only_watertight=True)
        shells += len(bodies)
        volume += mesh.volume
        assert mesh.bounds[0][2] == pytest.approx(0.0, abs=1e-6)  # laid flat
        if all_fit:
            assert mesh.bounds[0][0] >= margin - 1e-6 and mesh.bounds[0][1] >= margin - 1e-6
            assert mesh.bounds[1][0] <= width - margin + 1e-6 and mesh.bounds[1][1] <= depth - margin + 1e-6
        # no two parts overlap on the plate
        footprints = [shapely.MultiPoint(b.vertices[:, :2]).convex_hull for b in bodies]
        assert sum(f.area for f in footprints) == pytest.approx(shapely.union_all(footprints).area, rel=1e-9)
        # its 3MF twin: unit millimetre, one named object per part on the plate
        with zipfile.ZipFile(io.BytesIO(c.files[rel[:-4] + ".3mf"])) as archive:
            root = ET.fromstring(archive.read("3D/3dmodel.model"))
        ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
        assert root.get("unit") == "millimeter"
        names = [o.get("name") for o in root.findall(".//m:object", ns)]
        assert len(names) == len(bodies) == len(set(names))
    assert shells == copies * len(parts)  # every copy of every part is printed
    total = copies * sum(p.volume_mm3() for p in parts)
    bound = copies * sum(c.partset.chord_tolerance_mm * perimeter_mm(p) * p.thickness_mm for p in parts)
    assert abs(volume - total) <= bound + 1e-5 * total


@pytest.mark.parametrize("name", _marked(CASES))
def test_assembly_3mf(name):
    c = case(name)
    with zipfile.ZipFile(io.BytesIO(c.files["assembly.3mf"])) as archive:
        assert {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"} <= set(archive.namelist())
        root = ET.fromstring(archive.read("3D/3dmodel.model"))
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    assert root.get("unit") == "millimeter"
    objects = root.findall("m:resources/m:object", ns)
    assert [o.get("name") for o in objects] == [p.name for p in c.partset.parts]
    first = c.motion.poses_at(0)
    for obj, part in zip(objects, c.partset.parts, strict=True):
        verts = np.array([[float(v.get(k)) for k in "xyz"] for v in obj.findall("m:mesh/m:vertices/m:vertex", ns)])
        tris = np.array([[int(t.get(k)) for k in ("v1", "v2", "v3")]
                         for t in obj.findall("m:mesh/m:triangles/m:triangle", ns)])
        mesh = trimesh.Trimesh(verts, tris)
        assert mesh.is_watertight
        bound = c.partset.chord_tolerance_mm * perimeter_mm(part) * part.thickness_mm + 1e-4 * part.volume_mm3()
        assert abs(mesh.volume - part.volume_mm3()) <= bound
        # posed at the first pose: the first hole's centre is where the body puts it
        if part.holes:
            pose = first[part.body]
            centre = part.holes[0].centre @ np.array([[math.cos(pose[2]), math.sin(pose[2])],
                                                      [-math.sin(pose[2]), math.cos(pose[2])]]) + pose[:2]
            ring = verts[np.abs(np.hypot(*(verts[:, :2] - centre).T) - part.holes[0].diameter_mm / 2) < 1e-3]
            assert len(ring) >= 8
            assert verts[:, 2].min() == pytest.approx(part.z_mm, abs=1e-5)


# -- DXF ----------------------------------------------------------------------------------------

def read_dxf(data: bytes):
    doc = ezdxf.read(io.StringIO(data.decode("utf-8")))
    assert doc.dxfversion == "AC1024"  # R2010
    assert doc.header["$INSUNITS"] == 4 and doc.header["$MEASUREMENT"] == 1  # mm, metric
    return doc


def contour_polygons(msp, layer: str = "CUT", flatten_mm: float = 1e-4) -> list[shapely.Polygon]:
    """Closed contours on ``layer`` as polygons, read through ezdxf's own path flattening."""
    polys = []
    for e in msp.query(f'LWPOLYLINE[layer=="{layer}"]'):
        assert e.closed, "open contour"
        pts = [(v.x, v.y) for v in dxf_path.make_path(e).flattening(flatten_mm)]
        polys.append(shapely.Polygon(pts))
    for e in msp.query(f'CIRCLE[layer=="{layer}"]'):
        polys.append(shapely.Point(e.dxf.center.x, e.dxf.center.y).buffer(e.dxf.radius, 4096))
    return polys


def lwpolyline_area(entity) -> float:
    """Exact area of a closed LWPOLYLINE: its vertex polygon plus the circular segments of its arcs,
    the arcs taken from ezdxf's own bulge conversion."""
    pts = np.array(entity.get_points("xyb"))
    xy = pts[:, :2]
    area = 0.5 * float(np.dot(xy[:, 0], np.roll(xy[:, 1], -1)) - np.dot(np.roll(xy[:, 0], -1), xy[:, 1]))
    for i, bulge in enumerate(pts[:, 2]):
        if bulge == 0:
            continue
        _, start, end, radius = bulge_to_arc(xy[i], xy[(i + 1) % len(xy)], bulge)
        sweep = (end - start) % (2 * math.pi)
        area += math.copysign(0.5 * radius * radius * (sweep - math.sin(sweep)), bulge)
    return area


@pytest.mark.parametrize("name", _marked(CASES))
def test_part_dxf_round_trip(name):
    c = case(name)
    kerf = c.process.kerf_mm
    for part in c.partset.parts:
        data = c.files[f"cut/{part.name}.dxf" if c.process.name == "laser" else f"drawings/{part.name}.dxf"]
        doc = read_dxf(data)
        assert doc.layers.get("CUT").color == 1
        assert audit_problems(data) == []
        msp = doc.modelspace()
        outlines = msp.query('LWPOLYLINE[layer=="CUT"]')
        assert len(outlines) == 1 + len(getattr(part, "slots", ()))
        assert all(e.closed for e in outlines)
        circles = msp.query('CIRCLE[layer=="CUT"]')
        assert len(circles) == len(part.holes)
        for circle, hole in zip(circles, part.holes, strict=True):
            assert 2 * circle.dxf.radius == pytest.approx(expected_cut_diameter(hole, c), abs=1e-6)
            np.testing.assert_allclose([circle.dxf.center.x, circle.dxf.center.y], hole.centre, atol=1e-6)
        # every contour is a simple closed curve (the kerf offset made no loops)
        assert all(poly.is_valid for poly in contour_polygons(msp, flatten_mm=1e-3))
        # the outline read back through ezdxf's bulge-to-arc conversion has the area of the part's outline
        # grown by kerf / 2, and each slot the area of the slot shrunk by kerf / 2 (shapely, from raw paths)
        expected, slack = offset_area(part.outline.vertices, part.outline.bulges, kerf / 2)
        assert abs(lwpolyline_area(outlines[0]) - expected) <= slack
        for entity, slot in zip(list(outlines)[1:], getattr(part, "slots", ()), strict=True):
            expected, slack = offset_area(slot.vertices, slot.bulges, -kerf / 2)
            assert abs(abs(lwpolyline_area(entity)) - expected) <= slack
        # no duplicate contours
        keys = [tuple(np.round(np.array(e.get_points("xyb")).ravel(), 6)) for e in outlines]
        keys += [(round(e.dxf.center.x, 6), round(e.dxf.center.y, 6), round(e.dxf.radius, 6)) for e in circles]
        assert len(set(keys)) == len(keys)
        # the drawing keeps its label as TEXT; a cut file has no text, its label is outlines on ENGRAVE (the
        # name, else the part number, where the process can engrave it legibly)
        drawn = read_dxf(c.files[f"drawings/{part.name}.dxf"]).modelspace().query('TEXT[layer=="ENGRAVE"]')
        assert len(drawn) == 1
        if c.process.name == "laser":
            from fabricate.export.labels import label_parts

            label = label_parts(c.partset.parts, c.process.min_text_mm, c.process.min_feature_mm)[part.name].label
            assert not msp.query("TEXT MTEXT")
            assert bool(msp.query('LWPOLYLINE[layer=="ENGRAVE"]')) == (label is not None)
        else:
            assert len(msp.query('TEXT[layer=="ENGRAVE"]')) == 1


def test_binary_link_dxf_is_exact_rounded_slot():
    """Closed form: a 15 mm crank cut on the laser is a stadium of radius boss + kerf / 2."""
    c = case("four_bar-laser")
    crank = c.partset.part("crank")
    doc = read_dxf(c.files["cut/crank.dxf"])
    (outline,) = doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')
    r = 0.5 * (3.0 + 0.2) + 3.0 + 0.1  # hole/2 + web (= sheet thickness) + kerf/2
    bulges = sorted(b for *_, b in outline.get_points("xyb"))
    np.testing.assert_allclose(bulges, [0.0, 0.0, 1.0, 1.0], atol=1e-12)
    pts = np.array(outline.get_points("xy"))
    assert np.ptp(pts[:, 1]) == pytest.approx(2 * r, abs=1e-9)
    assert lwpolyline_area(outline) == pytest.approx(2 * r * 15.0 + math.pi * r * r, rel=1e-12)
    assert crank.outline.area() == pytest.approx(2 * (r - 0.1) * 15.0 + math.pi * (r - 0.1) ** 2, rel=1e-12)


@pytest.mark.parametrize("name", _marked(CASES))
def test_cut_sheets_nest_every_copy_without_overlap(name):
    c = case(name)
    sheets = sorted(k for k in c.files if k.startswith("cut/sheet_") and k.endswith(".dxf"))
    if c.process.name != "laser":  # nothing is cut for a printed build
        assert not any(k.startswith("cut/") for k in c.files)
        return
    parts = list(c.partset.parts)
    outers_total, names = 0, []
    for rel in sheets:
        data = c.files[rel]
        assert audit_problems(data) == []
        assert c.files[rel[:-4] + ".svg"].startswith(b"<?xml")
        msp = read_dxf(data).modelspace()
        contours = contour_polygons(msp, flatten_mm=1e-3)
        # outer contours are those not inside another one
        outers = [p for p in contours if not any(q is not p and q.contains(p) for q in contours)]
        outers_total += len(outers)
        for i, a in enumerate(outers):
            for b in outers[i + 1:]:
                assert not a.intersects(b)
        # no border to cut: the sheet is the drawing's limits (here the process's sheet: no standard sizes)
        assert not msp.query('*[layer!="CUT" & layer!="ENGRAVE"]') and not msp.query("TEXT MTEXT")
        border = shapely.box(*read_dxf(data).header["$LIMMIN"][:2], *read_dxf(data).header["$LIMMAX"][:2])
        assert border.bounds == (0.0, 0.0, *c.process.build_volume_mm[:2])
        for outer in outers:
            assert border.contains(outer)
        # each part's engraving lies inside its own outline
        engraved = contour_polygons(msp, layer="ENGRAVE")
        names += [k for k, outer in enumerate(outers) if any(outer.contains(g) for g in engraved)]
    assert outers_total == c.partset.copies * len(parts)  # every copy of every part is cut
    # every copy is labelled where the process can engrave its name or number legibly
    from fabricate.export.labels import label_parts

    labels = label_parts(parts, c.process.min_text_mm, c.process.min_feature_mm)
    assert len(names) == c.partset.copies * sum(labels[p.name].label is not None for p in parts)


@pytest.mark.parametrize("name", _marked([n for n in CASES if n.endswith("-laser")]))
def test_drawings_are_at_the_finished_size(name):
    """drawings/ is for CAD: the part as it is once cut (no kerf), unlike cut/."""
    c = case(name)
    kerf = c.process.kerf_mm
    assert kerf > 0
    for part in c.partset.parts:
        msp = read_dxf(c.files[f"drawings/{part.name}.dxf"]).modelspace()
        circles = msp.query('CIRCLE[layer=="CUT"]')
        for circle, hole in zip(circles, part.holes, strict=True):
            assert 2 * circle.dxf.radius == pytest.approx(expected_cut_diameter(hole, c) + kerf, abs=1e-6)
        outline = msp.query('LWPOLYLINE[layer=="CUT"]')[0]
        expected, slack = offset_area(part.outline.vertices, part.outline.bulges, 0.0)
        assert abs(lwpolyline_area(outline) - expected) <= slack


@pytest.mark.parametrize("name", _marked(CASES))
def test_kinematic_dxf(name):
    c = case(name)
    data = c.files["drawings/kinematic.dxf"]
    assert audit_problems(data) == []
    msp = read_dxf(data).modelspace()
    first = c.motion.poses_at(0)
    lengths = []
    for dim in msp.query('DIMENSION[layer=="DIMENSIONS"]'):
        if dim.dimtype == 0:  # linear along the link (ezdxf writes aligned as rotated linear)
            lengths.append(dim.get_measurement())
    joint_names = {j.name for j in c.mechanism.joints}
    expected = set()
    for body in c.mechanism.bodies:
        names = [n for n in body.points if n in joint_names] or list(body.points)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                length = float(np.hypot(*(body.point(a) - body.point(b))))
                if length > 1e-6:
                    expected.add(round(length, 6))
    assert {round(v, 6) for v in lengths} == expected
    labels = " ".join(t.dxf.text for t in msp.query('TEXT[layer=="LABELS"]'))
    for body in c.mechanism.bodies:
        for n in body.points:
            assert re.search(rf"\b{re.escape(n)}[ ,]", labels)
    # the coordinate dimensions (linear, from the origin) locate every joint at the first pose
    located = {0.0: set(), 90.0: set()}
    for d in msp.query('DIMENSION[layer=="COORDINATES"]'):
        target = d.dxf.defpoint3
        assert tuple(d.dxf.defpoint2)[:2] == (0.0, 0.0)
        assert d.get_measurement() == pytest.approx(abs(target.x if d.dxf.angle == 0.0 else target.y), abs=1e-9)
        located[d.dxf.angle].add(round(target.x if d.dxf.angle == 0.0 else target.y, 6))
    for joint in joint_names:
        owner = c.mechanism.point_owner(joint)
        pose = first[owner]
        rot = np.array([[math.cos(pose[2]), -math.sin(pose[2])], [math.sin(pose[2]), math.cos(pose[2])]])
        xy = pose[:2] + rot @ c.mechanism.body(owner).point(joint)
        for angle, value in ((0.0, xy[0]), (90.0, xy[1])):
            assert round(value, 6) in located[angle] or abs(value) < 5e-7, (joint, angle)


# -- pictures, report, determinism ------------------------------------------------------------------

@pytest.mark.parametrize("name", _marked(CASES))
def test_previews_and_report_entries(name):
    c = case(name)
    png = Image.open(io.BytesIO(c.files["previews/assembly.png"]))
    assert png.format == "PNG" and png.size[0] > png.size[1]
    gif = Image.open(io.BytesIO(c.files["previews/motion.gif"]))
    assert gif.format == "GIF" and gif.n_frames == 2 * c.design.parts.gif_frames - 2
    assert [e["name"] for e in c.entries] == [p.name for p in c.partset.parts]
    for entry, part in zip(c.entries, c.partset.parts, strict=True):
        assert entry["stl"] in c.files and entry["dxf"] in c.files
        assert entry["volume_mm3"] == pytest.approx(part.volume_mm3(), abs=1e-4)
        assert entry["layer"] == part.layer and entry["process"] == c.process.name
        assert [h["joint"] for h in entry["holes"]] == [h.joint for h in part.holes]
    assert c.files["bom.csv"].startswith(b"item,designation,kind,source,qty")


@pytest.mark.parametrize("name", _marked([CASES[0], CASES[-1]]))
def test_same_input_gives_identical_bytes(name):
    c = case(name)
    again = build_parts(c.design, c.mechanism, c.motion, c.gear_pairs, c.hints)
    files, entries = export_all(c.design, again, c.mechanism, c.motion, step=False)
    assert sorted(files) == sorted(c.files)
    assert [k for k in files if files[k] != c.files[k]] == []
    assert entries == c.entries


def test_encoders_are_pure_functions_of_their_input():
    c = case("geared_four_bar-laser")
    parts = list(c.partset.parts)
    cache = SolidCache(c.partset.chord_tolerance_mm)
    kerf = c.process.kerf_mm
    assert part_stl(parts[0], cache) == c.files[f"parts/{parts[0].name}.stl"]
    cutting = DxfStyle(min_text_mm=c.process.min_text_mm, labels="outlines", label_margin_mm=c.process.min_feature_mm)
    assert part_dxf(parts[0], kerf, cutting) == c.files[f"cut/{parts[0].name}.dxf"]
    assert part_dxf(parts[0], 0.0, DxfStyle(hole_labels=True)) == c.files[f"drawings/{parts[0].name}.dxf"]
    area = c.process.build_volume_mm[:2]
    layout = sheet_layout(parts, kerf, area, c.design.parts.sheet_margin_mm, c.design.parts.sheet_spacing_mm)
    assert sheet_dxf(parts, kerf, layout, area, 0, cutting) == c.files["cut/sheet_1.dxf"]
    assert assembly_3mf(parts, cache, c.motion.poses_at(0), c.design.name) == c.files["assembly.3mf"]
    assert kinematic_dxf(c.mechanism, c.motion.poses_at(0)) == c.files["drawings/kinematic.dxf"]
    sla = case("geared_four_bar-sla")
    sla_parts = [p for p in sla.partset.parts for _ in range(sla.partset.copies)]
    cache = SolidCache(sla.partset.chord_tolerance_mm)
    plate = plate_layout(sla_parts, cache, sla.process.build_volume_mm[:2], sla.design.parts.plate_spacing_mm)
    assert {pl.sheet for pl in plate} == {0}
    meshes = [placed_flat_mesh(p, cache, pl) for p, pl in zip(sla_parts, plate, strict=True)]
    assert plate_stl(meshes) == sla.files["plates/plate_1.stl"]


def test_validate_stl_finds_problems():
    c = case("four_bar-sla")
    good = c.files["parts/crank.stl"]
    assert validate_stl(good) == []
    # drop the last triangle: the surface is open
    count = int.from_bytes(good[80:84], "little")
    broken = good[:80] + (count - 1).to_bytes(4, "little") + good[84:-50]
    assert "not watertight" in validate_stl(broken)
    assert validate_stl(b"garbage")


# -- real tools ---------------------------------------------------------------------------------------

TOOL_CASES = ["four_bar-laser", "slider_crank-sla", "geared_four_bar-sla"] + [
    f"{t}-sla" for t in TEMPLATES]


@pytest.mark.skipif(shutil.which("openscad") is None, reason="OpenSCAD not installed")
@pytest.mark.parametrize("name", _marked(TOOL_CASES))
def test_openscad_imports_every_dxf(name, tmp_path):
    """OpenSCAD imports each DXF's CUT layer (and the kinematic drawing's joints) without an error.

    OpenSCAD 2021.01 reads LWPOLYLINE vertices but ignores bulges (it draws arcs as chords), so only
    the import itself and the outline's extent along straight edges are checked here; the exact arcs
    are checked through ezdxf above.
    """
    c = case(name)
    dxfs = sorted((k, v) for k, v in c.files.items() if k.endswith(".dxf"))
    imports, names = [], {}
    for k, (rel, data) in enumerate(dxfs):
        target = tmp_path / f"f{k}.dxf"
        target.write_bytes(data)
        names[target.name] = rel
        layer = "JOINTS" if rel.endswith("kinematic.dxf") else "CUT"
        imports.append(f'translate([{1000 * k}, 0]) import("{target}", layer="{layer}");')
    # one OpenSCAD run per case (its start-up dominates); messages name the file they concern
    scad = tmp_path / "all.scad"
    scad.write_text("\n".join(imports) + "\n")
    out = tmp_path / "all.dxf"  # 2D output: no 3D union of OpenSCAD's arc-less outlines
    run = subprocess.run(["openscad", "-o", str(out), str(scad)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "ERROR" not in run.stderr, run.stderr
    for line in run.stderr.splitlines():
        if "WARNING" not in line:
            continue
        rel = next((names[n] for n in names if n in line), "?")
        # OpenSCAD cannot draw dimensions and texts: it says so and skips them (kinematic drawing only)
        assert rel.endswith("kinematic.dxf") and "Unsupported DXF Entity" in line, line
    # every file produced geometry: something in each 1000 mm slot along x
    xs = [v[0] for e in ezdxf.readfile(out).modelspace() if e.dxftype() in ("LWPOLYLINE", "POLYLINE", "LINE")
          for v in (e.get_points("xy") if e.dxftype() == "LWPOLYLINE" else
                    ([e.dxf.start, e.dxf.end] if e.dxftype() == "LINE" else [p.dxf.location for p in e.vertices]))]
    assert {int(math.floor(x / 1000 + 0.5)) for x in xs} == set(range(len(dxfs)))


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="PrusaSlicer not installed")
@pytest.mark.parametrize("name", _marked(TOOL_CASES))
def test_prusaslicer_reports_manifold_without_repair(name, tmp_path):
    c = case(name)
    stls = {k: v for k, v in c.files.items() if k.endswith(".stl")}
    paths = []
    for k, (rel, data) in enumerate(sorted(stls.items())):
        target = tmp_path / f"s{k}.stl"
        target.write_bytes(data)
        paths.append((rel, target))
    run = subprocess.run(["prusa-slicer", "--info"] + [str(p) for _, p in paths], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    blocks = re.split(r"^\[(.+?)\]\s*$", run.stdout, flags=re.M)
    info = {blocks[i]: blocks[i + 1] for i in range(1, len(blocks) - 1, 2)}
    assert len(info) == len(paths)
    repairs = ("open_edges", "edges_fixed", "degenerate_facets", "facets_removed", "facets_added",
               "facets_reversed", "backwards_edges")
    for rel, target in paths:
        text = info[target.name]
        assert "manifold = yes" in text, (rel, text)
        for key in repairs:
            m = re.search(rf"{key}\s*=\s*(\d+)", text)
            assert m is None or int(m.group(1)) == 0, (rel, key, text)
    # the 3MF assembly: one manifold object per part
    model = tmp_path / "assembly.3mf"
    model.write_bytes(c.files["assembly.3mf"])
    run = subprocess.run(["prusa-slicer", "--info", str(model)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.count("[assembly.3mf]") == len(c.partset.parts)
    assert run.stdout.count("manifold = yes") == len(c.partset.parts)
    # every plate's 3MF: one manifold object per copy of a part on it, together every copy of every part
    plates = sorted(k for k in c.files if k.startswith("plates/") and k.endswith(".3mf"))
    targets = []
    for k, rel in enumerate(plates):
        targets.append(tmp_path / f"plate{k}.3mf")
        targets[-1].write_bytes(c.files[rel])
    if targets:
        run = subprocess.run(["prusa-slicer", "--info", *map(str, targets)], capture_output=True, text=True,
                             timeout=300)
        assert run.returncode == 0, run.stderr
        objects = sum(run.stdout.count(f"[{t.name}]") for t in targets)
        assert objects == run.stdout.count("manifold = yes") == c.partset.copies * len(c.partset.parts)


def with_step(c: SimpleNamespace) -> dict[str, bytes]:
    """A case's files and its STEP files (none without OCP), as a build writes them."""
    return {**c.files, **export_step(c.design, c.partset, c.motion)}


ENCODE_IN_CHILD = """
import hashlib, sys
sys.path.insert(0, {root!r})
from tests.export.test_export import case, with_step
files = with_step(case({name!r}))
for key in sorted(files):
    print(key, hashlib.sha256(files[key]).hexdigest())
"""


@pytest.mark.slow
def test_bytes_do_not_depend_on_the_hash_seed():
    """Two processes with different string-hash seeds write identical files (ezdxf keeps some records
    in sets; the encoders fix their order)."""
    import hashlib
    import sys

    name = "slider_crank-laser"
    here = with_step(case(name))
    assert any(k.endswith(".step") for k in here) == step_available()
    expected = "".join(f"{k} {hashlib.sha256(here[k]).hexdigest()}\n" for k in sorted(here))
    script = ENCODE_IN_CHILD.format(root=str(Path(__file__).resolve().parents[2]), name=name)
    for seed in ("1", "12345"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env,
                             timeout=300, cwd=Path(__file__).resolve().parents[2])
        assert run.returncode == 0, run.stderr
        assert run.stdout == expected
