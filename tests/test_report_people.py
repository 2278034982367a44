"""report.md and the pictures for people: interference worst first and by kind of contact, labelled GIF frames,
distinct part colours, kinematic drawing text of at least 2.5 mm in its dimension style."""

from __future__ import annotations

import io
import re

import ezdxf
import numpy as np
import pytest
from PIL import Image

from fabricate.export.dxf import DIMSTYLE, MIN_DRAWING_TEXT_MM
from fabricate.export.previews import part_colours


@pytest.fixture(scope="module")
def five_bar(shipped_build):
    return shipped_build("finger_five_bar_ncg")


def _rows(markdown: str, header_start: str) -> list[list[str]]:
    lines = markdown.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header_start))
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


@pytest.mark.slow
def test_interference_table_is_worst_first(five_bar):
    md = five_bar.files["report.md"].decode()
    rows = _rows(md, "| a | b | contact | smallest gap mm | required mm | margin mm")
    pairs = five_bar.report["interference"]["pairs"]
    assert len(rows) == len(pairs)
    margins = [float(r[5]) for r in rows]
    assert margins == sorted(margins)
    # the margin printed is the gap less the requirement of that pair, recomputed from the report
    expected = sorted(p["min_clearance_mm"] - p["required_mm"] for p in pairs)
    assert np.allclose(margins, expected, atol=5e-4 * max(1.0, max(map(abs, expected))))


@pytest.mark.slow
def test_summary_separates_moving_clearance_from_gear_mesh_and_bearing(five_bar):
    md = five_bar.files["report.md"].decode()
    rows = {r[0]: r for r in _rows(md, "| contact | pairs |")}
    pairs = five_bar.report["interference"]["pairs"]
    mesh = [p for p in pairs if p["relation"] == "meshing"]
    bearing = [p for p in pairs if p["relation"] == "bearing"]
    assert mesh and bearing
    # the gear mesh gap (well under the running clearance) is reported with what it is held to
    assert float(rows["gear teeth in mesh"][2]) == pytest.approx(min(p["min_clearance_mm"] for p in mesh), rel=1e-3)
    assert min(p["min_clearance_mm"] for p in mesh) < five_bar.report["interference"]["required_clearance_mm"]
    assert "backlash" in rows["gear teeth in mesh"][4]
    assert int(rows["a spacer or washer on its parts"][1]) == len(bearing)
    assert "passes" in rows["a spacer or washer on its parts"][5]
    moving = [p for p in pairs if p["relation"] == "moving"]
    assert float(rows["parts moving past each other"][2]) == pytest.approx(
        min(p["min_clearance_mm"] for p in moving), rel=1e-3)
    backlash = five_bar.report["interference"]["gear_mesh"][0]["backlash_mm"]
    assert re.search(r"Gear mesh \w+: backlash \[", md) and f"{backlash[0]:.4g}" in md


def _label_box(frame: Image.Image) -> np.ndarray:
    return np.asarray(frame.convert("L"))[2:14, 2:110]


@pytest.mark.slow
@pytest.mark.parametrize("path", ["previews/motion.gif", "gears/sun_planet_turning.gif"])
def test_gif_frames_carry_their_input(five_bar, path):
    gif = Image.open(io.BytesIO(five_bar.files[path]))
    first = gif.copy()
    gif.seek(gif.n_frames // 3)
    later = gif.copy()
    for frame in (first, later):
        box = _label_box(frame)
        assert (box < 128).sum() > 40  # dark text pixels on the white corner
    assert not np.array_equal(_label_box(first), _label_box(later))  # a different value is written


@pytest.mark.slow
def test_parts_of_a_gear_pair_get_distinct_colours(shipped_build):
    outcome = shipped_build("gear_pair_elliptic")
    parts = outcome.partset.parts
    colours = part_colours(parts)
    gears = [p.name for p in parts if p.gear]
    assert len(gears) == 2 and colours[gears[0]] != colours[gears[1]]
    assert {p.layer for p in parts if p.gear} and len({p.layer for p in parts if p.gear}) == 1  # one layer
    gif = Image.open(io.BytesIO(outcome.files["previews/motion.gif"])).convert("RGB")
    used = {tuple(c) for c in np.asarray(gif).reshape(-1, 3)}
    assert len(used) >= 2 + len(parts)  # background, outline and one fill per part


@pytest.mark.slow
def test_kinematic_drawing_text_is_at_least_2_5_mm_in_its_dimension_style(five_bar):
    doc = ezdxf.read(io.StringIO(five_bar.files["drawings/kinematic.dxf"].decode()))
    style = doc.dimstyles.get(DIMSTYLE)
    assert style.dxf.dimtxt >= MIN_DRAWING_TEXT_MM
    dims = list(doc.modelspace().query("DIMENSION"))
    assert dims and all(d.dxf.dimstyle == DIMSTYLE for d in dims)
    # LibreCAD sizes every dimension by the header variables, so they carry the same sizes
    assert doc.header["$DIMTXT"] == style.dxf.dimtxt and doc.header["$DIMASZ"] == style.dxf.dimasz
    texts = list(doc.modelspace().query("TEXT"))
    assert texts and min(t.dxf.height for t in texts) >= MIN_DRAWING_TEXT_MM


# -- "not checked" in report.md (issue 23) ------------------------------------------------------------

def _md(**sections) -> str:
    from fabricate.report import report_markdown

    report = {"design": {"name": "d", "kind": "linkage", "stage": "build"},
              "checks": {"passed": True, "failures": [], "not_checked": []}}
    report.update(sections)
    return report_markdown(report)


def test_strength_not_checked_says_why_and_rates_no_part():
    md = _md(strength={"passed": None, "reason": "no materials in the profile", "required_safety_factor": 2.0,
                       "loads": [], "parts": [], "notes": []},
             checks={"passed": True, "failures": [],
                     "not_checked": [{"check": "strength", "reason": "no materials in the profile"}]})
    section = md[md.index("## Strength"):]
    assert "Strength: not checked: no materials in the profile." in section
    assert "passed" not in section and "| part |" not in section
    checks = md[md.index("## Checks"):md.index("## Strength")]
    assert checks.startswith("## Checks: PASSED") and "- strength not checked: no materials in the profile" in checks


def test_interference_not_checked_says_why():
    md = _md(interference={"poses": 0, "pairs_checked": 0, "collisions": [], "passed": None,
                           "reason": "no poses in the motion", "pairs": []})
    section = md[md.index("## Interference"):]
    assert section.startswith("## Interference\n\nInterference: not checked: no poses in the motion")
    assert "| contact |" not in section


def test_unloaded_parts_read_unloaded_and_come_after_the_weakest():
    md = _md(strength={"passed": True, "required_safety_factor": 2.0, "loads": ["torque 50 N·mm on rocker"],
                       "parts": [{"name": "idle", "min_safety_factor": None},
                                 {"name": "weak", "min_safety_factor": 2.5},
                                 {"name": "strong", "min_safety_factor": 9.0}], "notes": []})
    rows = _rows(md, "| part | safety factor")
    assert [(r[0], r[1]) for r in rows] == [("weak", "2.5"), ("strong", "9"), ("idle", "unloaded")]
    assert not re.search(r"\binf\b", md)


def test_synth_report_says_no_check_ran():
    md = _md(design={"name": "d", "kind": "linkage", "stage": "synth"},
             checks={"passed": True, "failures": [], "not_checked": [{"check": "strength", "reason": "synth only"}]})
    assert "## Checks: none run (synth only" in md and "PASSED" not in md
