"""run_checks over whole builds: the four-bar by hand, the seed-000 finger through the real layers,
deliberately broken variants, printability against the process profiles, the gear mesh in place."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from fabricate.checks import run_checks, sweep_interference
from fabricate.checks.gear_mesh import check_gear_mesh
from fabricate.checks.printability import check_printability, hole_walls, thin_feature
from fabricate.mechanism import Motion
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.spec import ChecksSpec
from tests.conftest import make_four_bar
from tests.interference_fixtures import four_bar_parts, slot_part

PNG = b"\x89PNG\r\n\x1a\n"


def bare_design(process, poses: int = 360):
    return SimpleNamespace(process=process, checks=ChecksSpec(sweep_poses=poses, min_clearance_mm=None))


# -- four-bar by hand -------------------------------------------------------------------------------
def test_four_bar_build_passes_and_reports(sla_process):
    mech = make_four_bar()
    motion = mech.sweep(360)
    partset = SimpleNamespace(parts=tuple(four_bar_parts(mech)), pins=())
    report = run_checks(bare_design(sla_process), partset, mech, motion, [])
    assert report.passed, report.failures
    inter = report.interference
    assert {"poses", "pairs_checked", "collisions", "min_clearance_mm"} <= set(inter)
    assert inter["poses"] == 360 and inter["collisions"] == []
    # the smallest clearance is a pin in its hole: 0.25 mm radial, less at most the chord tolerance
    assert 0.25 - sla_process.chord_tolerance_mm <= inter["min_clearance_mm"] <= 0.25
    assert report.report()["checks"] == {"passed": True, "failures": [], "not_checked": []}
    png = report.figures()["clearance.png"]
    assert png.startswith(PNG) and png == report.figures()["clearance.png"]
    assert "| crank | coupler | joined | 0.300 |" in report.pair_table_markdown()


def test_four_bar_resweeps_when_given_fewer_poses(sla_process):
    mech = make_four_bar()
    partset = SimpleNamespace(parts=tuple(four_bar_parts(mech)), pins=())
    report = run_checks(bare_design(sla_process, poses=400), partset, mech, mech.sweep(20), [])
    assert report.interference["poses"] == 400


def test_four_bar_forced_onto_one_layer_fails_with_reason(sla_process):
    mech = make_four_bar()
    parts = four_bar_parts(mech, layers={"ground": 0, "crank": 1, "rocker": 2, "coupler": 0})
    report = run_checks(bare_design(sla_process), SimpleNamespace(parts=tuple(parts), pins=()), mech,
                        mech.sweep(360), [])
    assert not report.passed
    pairs = {(c["a"], c["b"]) for c in report.interference["collisions"]}
    assert ("ground", "coupler") in pairs
    hit = next(c for c in report.interference["collisions"] if (c["a"], c["b"]) == ("ground", "coupler"))
    lo, hi = hit["input_ranges"][0]
    assert 60.0 < lo <= hit["input_deg"] <= hi < 420.0 and hit["volume_mm3"] > 1.0
    assert any("ground collides with coupler" in f for f in report.failures)


# -- printability -----------------------------------------------------------------------------------
def test_hole_wall_is_the_analytic_web(sla_process, laser_process):
    """A 6 mm slot with 2.5 mm holes: web (6 - 2.5) / 2 = 1.75 mm (within the chord tolerance);
    enough for SLA (0.8 mm), not for 3 mm laser sheet (web ≥ 3 mm)."""
    part = slot_part("link", "link", ("A", "B"), 30.0, width=6.0)
    walls = dict(hole_walls(part, 0.005))
    assert walls["A"] == pytest.approx(1.75, abs=0.005) and walls["B"] == pytest.approx(1.75, abs=0.005)
    assert check_printability([part], sla_process).passed
    laser_part = dataclasses.replace(part, process="laser")
    result = check_printability([laser_part], laser_process)
    assert any(f.startswith("printability: link has a 1.7") and "wall at hole" in f for f in result.failures)


def test_thin_tab_and_oversize_part_fail(sla_process):
    """A 0.2 mm wide tab on a plate is thinner than the SLA feature size (0.3 mm); a 200 mm plate
    does not fit the 130 × 80 mm build area; a 0.5 mm wall around a hole is under 0.8 mm."""
    tab = np.array([[0, 0], [10, 0], [10, 5], [5.1, 5], [5.1, 9], [4.9, 9], [4.9, 5], [0, 5]], dtype=float)
    part = Part("tab", "b", BulgePath.polyline(tab), (), 3.0, 0.0, 0, "sla")
    assert thin_feature(part, 0.3, 0.005) > 3.0  # the whole 4 mm tab goes
    assert thin_feature(dataclasses.replace(part, outline=BulgePath.polyline(tab[[0, 1, 2, 7]])), 0.3,
                        0.005) == 0.0
    big = slot_part("long", "b", ("A", "B"), 200.0)
    thin_wall = Part("web", "b", BulgePath.polyline(np.array([[0, 0], [10, 0], [10, 4], [0, 4]], float)),
                     (Hole("A", np.array([5.0, 2.0]), 3.0, 2.0),), 3.0, 0.0, 0, "sla")
    failures = check_printability([part, big, thin_wall], sla_process).failures
    assert any("tab has a feature thinner" in f for f in failures)
    assert any("long (" in f and "does not fit the build volume" in f for f in failures)
    assert any("web has a 0.500 mm wall at hole A" in f for f in failures)


def test_laser_parts_must_be_sheet_thick(laser_process):
    part = slot_part("link", "b", ("A", "B"), 30.0, width=12.0, thickness=4.0, process="laser")
    failures = check_printability([part], laser_process).failures
    assert list(failures) == ["printability: link is 4 mm thick, the sheet 3 mm"]


# -- seed-000 through the real layers ----------------------------------------------------------------
@pytest.fixture(scope="module")
def seed000():
    from fabricate.gears import build_gear_pairs
    from fabricate.parts.build import build_parts
    from fabricate.pipeline import synthesise
    from fabricate.spec import load_design
    from fabricate.templates import TEMPLATE_DIR

    design = load_design(TEMPLATE_DIR / "finger_five_bar_ncg.toml")
    result = synthesise(design)
    mech = result.mechanism
    motion = mech.sweep(design.checks.sweep_poses + 1)
    pairs = build_gear_pairs(mech, design.gears, design.process.chord_tolerance_mm)
    partset = build_parts(design, mech, motion, pairs, result.parts)
    return design, mech, motion, pairs, partset


def test_seed000_interference_and_mesh_pass(seed000):
    """No collision over 361 poses, every moving pair at least the running clearance, pins at their
    radial hole clearance, the gears in mesh with the design backlash in the assembly."""
    design, mech, motion, pairs, partset = seed000
    report = run_checks(design, partset, mech, motion, pairs)
    inter = report.interference
    assert inter["poses"] == 361 and inter["collisions"] == []
    assert inter["min_clearance_mm"] >= design.process.running_clearance_mm - design.process.chord_tolerance_mm
    assert not [f for f in report.failures if f.startswith(("interference", "clearance", "gear mesh"))]
    for row in inter["pairs"]:
        if row["relation"] == "pin":
            # modelled hole: pin + 2 x running clearance + SLA compensation, radially
            expected = design.process.running_clearance_mm + design.process.hole_compensation_mm / 2
            assert expected - design.process.chord_tolerance_mm <= row["min_clearance_mm"] <= expected + 1e-9
    (mesh,) = inter["gear_mesh"]
    assert mesh["passed"] and mesh["interference_area_mm2"] == 0.0
    assert mesh["law_error_rad"] < 1e-9
    assert mesh["backlash_mm"][0] > 0.0
    meshing = [r for r in inter["pairs"] if r["relation"] == "meshing"]
    assert len(meshing) == 1 and 0.0 < meshing[0]["min_clearance_mm"] < 0.1


def test_seed000_two_bodies_on_one_layer_caught(seed000):
    """The middle phalanx forced onto the gear layer of link_AB: the pair collides and the report
    names it with the inputs and the volume."""
    design, mech, motion, pairs, partset = seed000
    link = partset.part("link_AB")
    parts = tuple(dataclasses.replace(p, z_mm=link.z_mm, layer=link.layer) if p.name == "middle" else p
                  for p in partset.parts)
    broken = dataclasses.replace(partset, parts=parts)
    report = run_checks(design, broken, mech, motion, pairs)
    assert not report.passed
    hit = [c for c in report.interference["collisions"] if {c["a"], c["b"]} == {"link_AB", "middle"}]
    assert len(hit) == 1 and hit[0]["volume_mm3"] > 0.0
    assert motion.inputs.min() <= hit[0]["input_deg"] <= motion.inputs.max()
    assert any("collides with" in f and "middle" in f and "link_AB" in f for f in report.failures)


def test_gear_mesh_check_fails_when_the_assembly_leaves_the_law(seed000):
    """Turn gear b by an extra 3° in the motion: the gear check reports the law error, and the
    interference sweep finds the teeth of the two gear parts overlapping."""
    design, mech, motion, pairs, partset = seed000
    pair = pairs[0]
    q = motion.q.copy()
    q[:, motion.free.index(pair.body_b), 2] += math.radians(3.0)
    moved = Motion(motion.inputs, motion.body_names, motion.ground, motion.free, q, motion.mechanism)
    result = check_gear_mesh(pair, moved)
    assert not result.passed
    assert result.law_error_rad == pytest.approx(math.radians(3.0), rel=1e-9)
    assert any("departs from the gear law" in f for f in result.failures)
    sweep = sweep_interference(partset.parts, moved, chord_tolerance_mm=design.process.chord_tolerance_mm,
                               min_clearance_mm=0.25, pins=partset.pins)
    (gears,) = [p for p in sweep.pairs if p.relation == "meshing"]
    assert gears.collides and len(gears.collision_indices) > len(motion.inputs) // 2


@pytest.mark.slow
def test_colliding_build_exits_1_with_files_and_reason(tmp_path, monkeypatch):
    """``fabricate build`` of the default finger with the middle phalanx forced onto the gear layer
    (the parts layer patched): exit code 1, every file written, report.json names the pair, the
    inputs and the volume, and the checks section says why."""
    import json

    import fabricate.parts.build as parts_build
    from fabricate.cli import main

    original = parts_build.build_parts

    def forced(*args, **kwargs):
        partset = original(*args, **kwargs)
        link = partset.part("link_AB")
        parts = tuple(dataclasses.replace(p, z_mm=link.z_mm, layer=link.layer) if p.name == "middle" else p
                      for p in partset.parts)
        return dataclasses.replace(partset, parts=parts)

    monkeypatch.setattr(parts_build, "build_parts", forced)
    out = tmp_path / "broken"
    assert main(["build", "-o", str(out), "--quiet"]) == 1
    report = json.loads((out / "report.json").read_text())
    assert report["checks"]["passed"] is False
    hit = [c for c in report["interference"]["collisions"] if {c["a"], c["b"]} == {"link_AB", "middle"}]
    assert len(hit) == 1 and hit[0]["volume_mm3"] > 0.0 and "input_deg" in hit[0]
    assert any("collides with" in f and "middle" in f for f in report["checks"]["failures"])
    assert all((out / f).is_file() for f in report["files"])
    assert (out / "plots" / "clearance.png").is_file()
