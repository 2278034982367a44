"""STEP export (issue 11, item 3): every part and the assembly as B-rep solids, read back with OCP.

What is asserted, per shipped template, on the files the pipeline produces:

- every ``parts/NAME.step`` holds one valid solid named NAME whose volume equals the part's exact volume
  (``part.volume_mm3()``, the report's ``volume_mm3``) within 1e-6 relative where its profile is lines and
  arcs. A fused profile (gear teeth, hubs, pads) reaches the part model as a polygon within the chord
  tolerance of its curves; the STEP puts the curves back (true arcs, B-spline flanks: see
  tests/export/test_step_curves.py), so its volume may differ from the polygon's by the chord tolerance
  times its curved side area, and no more;
- full cylinders (a face going once round its axis) = holes, one each; partial cylinders = arc segments
  of the outline and the slots (true circular edges, not facets), and the polygonised arcs recognised;
- ``assembly.step`` holds one solid per part, named as the part, and each solid's bounding box equals
  the posed mesh's in ``assembly.3mf`` within the chord tolerance (the mesh is inscribed in the arcs, so
  a B-rep box may be larger by at most the sagitta) plus 1e-5 mm for the mesh's float32 rounding;
- the bytes are deterministic: two builds in separate processes give identical STEP files.

The whole module skips without OCP (the optional extra ``cad``).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("OCP")

from fabricate.errors import GeometryError  # noqa: E402
from fabricate.export.step import (  # noqa: E402
    HEADER_TIME_STAMP,
    assembly_step,
    part_shape,
    part_step,
    step_available,
)
from fabricate.export.step_curves import SPLINE_FIT_FACTOR  # noqa: E402
from fabricate.export.step_read import read_step, step_problems  # noqa: E402
from fabricate.export.stl import read_3mf  # noqa: E402
from fabricate.parts.model import BulgePath, Hole, Part  # noqa: E402
from fabricate.templates import shipped_templates  # noqa: E402

#: Volume agreement asked by the issue (measured: ~1e-12 on every shipped part).
VOLUME_REL_TOL = 1e-6

#: manifold3d keeps vertices in float32 (~4e-6 mm at 60 mm from the origin) and the 3MF writes 1e-6 mm.
MESH_ROUNDING_MM = 1e-5

TEMPLATES = [path.stem for path in shipped_templates()]


@pytest.fixture(scope="module", params=TEMPLATES)
def build(request: pytest.FixtureRequest, shipped_build):
    """One in-memory build per shipped template (the session's shared one) with its STEP files read back once."""
    outcome = shipped_build(request.param)
    assert outcome.partset is not None, f"{request.param}: build failed before the parts"
    read = {path: read_step(data) for path, data in outcome.files.items() if path.endswith(".step")}
    return request.param, outcome, read


def test_step_available() -> None:
    assert step_available()


@pytest.mark.slow
def test_every_part_step_is_a_valid_solid_with_the_report_volume_and_hole_cylinders(build) -> None:
    name, outcome, read = build
    entries = {entry["name"]: entry for entry in outcome.report["parts"]}
    for part in outcome.partset.parts:
        entry = entries[part.name]
        assert entry["step"] == f"parts/{part.name}.step"
        solids = read[entry["step"]]
        assert len(solids) == 1, f"{name}/{part.name}: {len(solids)} solids"
        solid = solids[0]
        assert solid.valid, f"{name}/{part.name}: invalid solid"
        assert solid.name == part.name
        band = outcome.partset.chord_tolerance_mm * solid.curved_area_mm2 if not part.outline.bulges.any() else 0.0
        assert abs(solid.volume_mm3 - part.volume_mm3()) <= VOLUME_REL_TOL * part.volume_mm3() + band
        assert abs(solid.volume_mm3 - entry["volume_mm3"]) <= VOLUME_REL_TOL * part.volume_mm3() + band + 1e-4
        assert solid.n_cylindrical_faces == len(part.holes), f"{name}/{part.name}"
        arcs = int(np.count_nonzero(part.outline.bulges)) + sum(
            int(np.count_nonzero(slot.bulges)) for slot in getattr(part, "slots", ()))
        assert solid.n_arc_faces >= arcs, f"{name}/{part.name}: arcs not kept as circular edges"
        if not part.outline.bulges.any() and len(part.outline.vertices) > 12:  # a fused profile: few faces
            assert solid.n_faces < len(part.outline.vertices) / 2, f"{name}/{part.name}: {solid.n_faces} faces"
        # lying on z = 0 in its own coordinates, like its STL (a box round curved faces adds their 1e-7 mm)
        assert solid.bounds[0, 2] == pytest.approx(0.0, abs=2e-7)
        assert solid.bounds[1, 2] == pytest.approx(part.thickness_mm, abs=2e-7)


@pytest.mark.slow
def test_assembly_step_has_one_named_solid_per_part_where_the_3mf_puts_it(build) -> None:
    name, outcome, read = build
    parts = outcome.partset.parts
    tolerance = outcome.partset.chord_tolerance_mm
    solids = read["assembly.step"]
    assert [s.name for s in solids] == [p.name for p in parts]
    meshes, problems = read_3mf(outcome.files["assembly.3mf"])
    assert not problems
    for part, solid in zip(parts, solids, strict=True):
        assert solid.valid
        band = tolerance * solid.curved_area_mm2 if not part.outline.bulges.any() else 0.0
        assert abs(solid.volume_mm3 - part.volume_mm3()) <= VOLUME_REL_TOL * part.volume_mm3() + band
        assert solid.n_cylindrical_faces == len(part.holes)
        mesh_bounds = np.asarray(meshes[part.name].bounds)
        # the mesh is inscribed in the exact arcs: the B-rep box contains it, larger by at most a sagitta;
        # MESH_ROUNDING_MM covers the mesh's own rounding, a flank spline may pass inside a vertex by its fit
        slack = MESH_ROUNDING_MM + SPLINE_FIT_FACTOR * tolerance
        assert np.all(solid.bounds[0] <= mesh_bounds[0] + slack), f"{name}/{part.name}"
        assert np.all(solid.bounds[1] >= mesh_bounds[1] - slack), f"{name}/{part.name}"
        assert np.allclose(solid.bounds, mesh_bounds, atol=tolerance + MESH_ROUNDING_MM), f"{name}/{part.name}"
        assert solid.bounds[0, 2] == pytest.approx(part.z_mm, abs=1e-6)


# -------------------------------------------------------------------------------------------- synthetic


def _plate(**changes) -> Part:
    """A 40 x 20 mm rectangle with a half-disc of radius 10 on its right end and two holes, 3 mm thick."""
    outline = BulgePath(np.array([[0.0, 0.0], [40.0, 0.0], [40.0, 20.0], [0.0, 20.0]]),
                        np.array([0.0, 1.0, 0.0, 0.0]))  # a half-circle bulging out at x = 40
    values = dict(name="plate", body="b", outline=outline,
                  holes=(Hole("A", np.array([10.0, 10.0]), 4.0), Hole("B", np.array([40.0, 10.0]), 5.0)),
                  thickness_mm=3.0, z_mm=6.0, layer=2, process="sla")
    values.update(changes)
    return Part(**values)


def test_plate_volume_is_exact_and_the_arc_is_a_circle() -> None:
    part = _plate()
    (solid,) = read_step(part_step(part, 0.005))
    expected = (40.0 * 20.0 + 0.5 * np.pi * 10.0**2 - np.pi * (2.0**2 + 2.5**2)) * 3.0
    assert solid.valid
    assert solid.volume_mm3 == pytest.approx(expected, rel=1e-9)
    assert (solid.n_cylindrical_faces, solid.n_arc_faces) == (2, 1)
    # the arc reaches x = 50 exactly (a polygon would fall short by up to the chord tolerance)
    assert solid.bounds[1, 0] == pytest.approx(50.0, abs=1e-7)


def test_clockwise_outline_gives_the_same_solid() -> None:
    ccw = _plate().outline
    cw = BulgePath(ccw.vertices[::-1], -np.roll(ccw.bulges[::-1], -1))
    assert cw.area() == pytest.approx(-ccw.area())
    (a,) = read_step(part_step(_plate(), 0.005))
    (b,) = read_step(part_step(_plate(outline=cw), 0.005))
    assert b.volume_mm3 == pytest.approx(a.volume_mm3, rel=1e-12)
    assert np.allclose(a.bounds, b.bounds, atol=1e-9)


def test_assembly_pose_rotates_about_the_body_origin_and_lifts_to_the_layer() -> None:
    part = _plate()
    pose = np.array([100.0, -5.0, np.pi / 2.0])
    (solid,) = read_step(assembly_step([part], {"b": pose}, 0.005, title="one"))
    # (x, y) -> (100 - y, -5 + x): the plate spans x in [80, 100], y in [-5, 45], z in [6, 9]
    assert np.allclose(solid.bounds, [[80.0, -5.0, 6.0], [100.0, 45.0, 9.0]], atol=1e-6)


def test_hole_crossing_the_outline_is_a_geometry_error() -> None:
    with pytest.raises(GeometryError, match="plate"):
        part_shape(_plate(holes=(Hole("A", np.array([0.0, 10.0]), 6.0),)), 0.005)


def test_header_is_fixed_and_names_the_part() -> None:
    data = part_step(_plate(), 0.005)
    header = data[:data.index(b"ENDSEC;")].decode("ascii")
    assert f"FILE_NAME('plate','{HEADER_TIME_STAMP}'" in header
    assert data == part_step(_plate(), 0.005)


def test_assembly_bytes_do_not_depend_on_what_was_written_before() -> None:
    # OCCT numbers assembly occurrences from a process-wide counter; the writer renumbers them per file
    poses = {"b": np.array([1.0, 2.0, 0.3])}
    parts = [_plate(), _plate(name="other", z_mm=0.0)]
    first = assembly_step(parts, poses, 0.005, title="two")
    assert b"NEXT_ASSEMBLY_USAGE_OCCURRENCE('1','plate'" in first
    assert assembly_step(parts, poses, 0.005, title="two") == first


def test_step_problems_names_a_wrong_volume_and_hole_count() -> None:
    part = _plate()
    data = part_step(part, 0.005)
    assert step_problems(data, {"plate": (part.volume_mm3(), 2)}) == []
    problems = step_problems(data, {"plate": (part.volume_mm3() * 1.001, 3)})
    assert len(problems) == 2 and "volume" in problems[0] and "3" in problems[1]
    assert "differ" in step_problems(data, {"other": (1.0, 0)})[0]
    assert step_problems(b"ISO-10303-21;\nnot step") != []


# ---------------------------------------------------------------------------------------- determinism

#: The child builds the parts as a build does (``report_only``: no pictures) and writes their STEP files with the
#: function the build's STEP job calls (fabricate/pipeline.py ``step_files``); a whole build's previews and plots
#: would be a third of its time. The parent's side is the session's whole build.
_DIGEST = """
import hashlib, sys
from fabricate.design import load_design
from fabricate.export import export_step
from fabricate.pipeline import run_build
outcome = run_build(load_design(sys.argv[1]), report_only=True)
files = export_step(outcome.design, outcome.partset, outcome.motion)
for path in sorted(p for p in files if p.endswith(".step")):
    print(path, hashlib.sha256(files[path]).hexdigest())
"""


# one template is enough for the bytes: the quickest to build, with arcs, holes and many parts
@pytest.mark.slow
@pytest.mark.parametrize("build", ["finger_watt_six_bar"], indirect=True)
def test_two_builds_in_separate_processes_give_identical_step_bytes(build) -> None:
    name, outcome, _ = build
    here = {path: hashlib.sha256(data).hexdigest() for path, data in outcome.files.items() if path.endswith(".step")}
    env = dict(os.environ, PYTHONHASHSEED="123")
    result = subprocess.run([sys.executable, "-c", _DIGEST, name], capture_output=True, text=True, env=env,
                            check=True, timeout=600)
    there = dict(line.split() for line in result.stdout.splitlines())
    assert there == here


# -------------------------------------------------------------------------------------------- FreeCAD

_FREECAD = """
import Part
shape = Part.read({path!r})
print("FABRICATE", len(shape.Solids), shape.Volume, shape.isValid())
"""


@pytest.mark.skipif(shutil.which("freecadcmd") is None, reason="FreeCAD (freecadcmd) not installed")
def test_freecad_imports_a_part_with_its_volume(tmp_path: Path) -> None:
    part = _plate()
    path = tmp_path / "plate.step"
    path.write_bytes(part_step(part, 0.005))
    script = tmp_path / "read.py"
    script.write_text(_FREECAD.format(path=str(path)))
    result = subprocess.run(["freecadcmd", str(script)], capture_output=True, text=True, timeout=300)
    line = next(l for l in result.stdout.splitlines() if l.startswith("FABRICATE"))
    _, count, volume, valid = line.split()
    assert (int(count), valid) == (1, "True")
    assert float(volume) == pytest.approx(part.volume_mm3(), rel=VOLUME_REL_TOL)


def test_occurrence_ids_and_their_line_wrap_do_not_depend_on_the_process_counter() -> None:
    """OCCT numbers assembly occurrences with a process-wide counter and wraps lines at 72 columns counting
    its digits: the file written after ten others must equal the first (the gripper's laser assembly
    differed in one line break in a full test run)."""
    from fabricate.export.step import _fixed_file_name

    head = b"HEADER;\nFILE_NAME('x','t',(''),(''),'s','s','');\nENDSEC;\nDATA;\n"
    first = head + b"#5544 = NEXT_ASSEMBLY_USAGE_OCCURRENCE('5','two_force_rod','',#5,#5297,$\n  );\nENDSEC;\n"
    later = head + b"#5544 = NEXT_ASSEMBLY_USAGE_OCCURRENCE('15','two_force_rod','',#5,#5297,\n  $);\nENDSEC;\n"
    a, b = _fixed_file_name(first, "assembly"), _fixed_file_name(later, "assembly")
    assert a == b
    assert b"NEXT_ASSEMBLY_USAGE_OCCURRENCE('1','two_force_rod','',#5,#5297,$);" in a
