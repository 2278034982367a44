"""Hole labels of the part drawings (issue 25, item 2): the nominal hole and its fit, and apart from it the CAD
size with the process's compensation; never in a cut file. The cut layout's sheets per stock thickness (issue 26,
item 2: a 3 mm actuator plate beside 6 mm links)."""

from __future__ import annotations

import dataclasses
import io
import json
import re
import xml.etree.ElementTree as ET

import ezdxf
import numpy as np
import pytest

from fabricate.cli import main
from fabricate.drive.records import MOUNT_PART
from fabricate.export.dxf import MIN_DRAWING_TEXT_MM, DxfStyle, part_dxf, sheet_layout, sized_sheets
from fabricate.export.svg import part_svg
from fabricate.parts.build import build_parts
from tests.export.test_labels import PONOKO, bar
from tests.parts.test_build import design_for


@pytest.fixture
def parts(four_bar, sla_process):
    return build_parts(design_for(sla_process), four_bar, four_bar.sweep(31), []).parts


def _msp(data: bytes):
    return ezdxf.read(io.StringIO(data.decode("utf-8"))).modelspace()


def test_drawing_labels_every_hole_with_nominal_and_cad_size(parts):
    for part in parts:
        msp = _msp(part_dxf(part, 0.0, DxfStyle(hole_labels=True)))
        labels = {t.dxf.text.split(": ", 1)[0]: t for t in msp.query('TEXT[layer=="HOLES"]')}
        assert set(labels) == {h.joint for h in part.holes}
        assert len(msp.query('LINE[layer=="HOLES"]')) == len(part.holes)  # a leader to each hole
        for h in part.holes:
            text = labels[h.joint].dxf.text
            assert labels[h.joint].dxf.height >= MIN_DRAWING_TEXT_MM
            # "O: Ø2.5 running (CAD Ø2.7 incl. +0.2 sla compensation)": both sizes read back
            m = re.fullmatch(rf"{re.escape(h.joint)}: Ø([\d.]+) (\w+) \(CAD Ø([\d.]+) incl\. \+([\d.]+) sla "
                             r"compensation\)", text)
            assert m, text
            assert float(m[1]) == pytest.approx(h.nominal_mm, abs=1e-3) and m[2] == h.fit
            assert float(m[3]) == pytest.approx(h.diameter_mm, abs=1e-3) and float(m[4]) == pytest.approx(0.2)
        # the CUT circles stay the modelled holes
        cut = sorted(round(2 * c.dxf.radius, 6) for c in msp.query('CIRCLE[layer=="CUT"]'))
        assert cut == sorted(round(h.diameter_mm, 6) for h in part.holes)


def test_cut_files_carry_no_hole_labels(parts):
    for part in parts:
        msp = _msp(part_dxf(part, 0.2))
        assert not msp.query('*[layer=="HOLES"]')
        svg = ET.fromstring(part_svg(part, 0.2))
        ns = {"s": "http://www.w3.org/2000/svg"}
        circles = svg.findall(".//s:circle", ns)
        assert len(circles) == len(part.holes)
        # the label rides in each circle's title (shown by Inkscape, never cut or engraved)
        titles = [c.find("s:title", ns).text for c in circles]
        assert all("CAD Ø" in t and "cut path Ø" in t for t in titles)
        assert not [t for t in svg.findall(".//s:text", ns) if "Ø" in (t.text or "")]


def test_each_sheet_holds_parts_of_one_thickness():
    """Mixed stock (6 mm links, a 3 mm plate): the 6 mm parts are nested exactly as they are alone, the 3 mm one
    on a sheet of its own that states its thickness; sheet_layout nests the same way."""
    links = [dataclasses.replace(bar(f"l{k}"), thickness_mm=6.0) for k in range(3)]
    plate = bar("plate", length=40.0, width=20.0)  # 3 mm
    mixed = [links[0], plate, *links[1:]]
    placements, sheets = sized_sheets(mixed, 0.2, PONOKO, (790.0, 384.0), 5.0, 3.0)
    assert [(s.thickness_mm, s.parts) for s in sheets] == [(6.0, ("l0", "l1", "l2")), (3.0, ("plate",))]
    assert [s.report()["thickness_mm"] for s in sheets] == [6.0, 3.0]
    assert all(mixed[k].thickness_mm == sheets[pl.sheet].thickness_mm for k, pl in enumerate(placements))
    alone, sheets_alone = sized_sheets(links, 0.2, PONOKO, (790.0, 384.0), 5.0, 3.0)
    assert [s.report() for s in sheets_alone] == [sheets[0].report()]
    for pl, mine in zip(alone, [placements[0], *placements[2:]], strict=True):
        assert pl.sheet == mine.sheet and pl.angle == mine.angle and np.array_equal(pl.offset, mine.offset)
    layout = sheet_layout(mixed, 0.2, (181.0, 181.0), 5.0, 3.0)
    assert [pl.sheet for pl in layout] == [0, 1, 0, 0]
    assert [pl.sheet for pl in sheet_layout(links, 0.2, (181.0, 181.0), 5.0, 3.0)] == [0, 0, 0]


@pytest.mark.slow
def test_the_laser_default_finger_cuts_its_3mm_plate_on_a_3mm_sheet(tmp_path, capsys, shipped_build, serve_builds):
    """``--process laser`` of the default finger (the session's build, shared with test_mount, test_auto and
    test_bom): its links are 6 mm, its actuator plate is cut from the 3 mm stock. The build exits 0, the plate is on
    a sheet of thickness 3 with no 6 mm part, every sheet's parts are as thick as it, and ``fabricate check`` passes
    on the written folder (check rebuilds it from the report's embedded template and profile).

    Check's rebuild is served by the session's shared stage cache, which ``shipped_build`` filled with this very
    design (as in tests/test_verify.py and test_process_override's check test): the rebuild goes through check's
    own path (the embedded template and profile read back into a design, whose stage keys must be the build's to be
    served; a key that missed would build cold and still be compared), without building the finger a third time."""

    outcome = shipped_build("finger_five_bar_ncg", "laser")
    serve_builds()
    assert outcome.exit_code == 0, outcome.failures
    out = outcome.write(tmp_path / "out")
    report = json.loads((out / "report.json").read_text())
    thickness = {p["name"]: p["thickness_mm"] for p in report["parts"]}
    assert thickness[MOUNT_PART] == 3.0 and 6.0 in thickness.values()
    sheets = report["cut"]["sheets"]
    for sheet in sheets:
        assert {thickness[name] for name in sheet["parts"]} == {sheet["thickness_mm"]}, sheet
        assert (out / sheet["file"]).is_file() and (out / sheet["file"]).with_suffix(".svg").is_file()
    (plate_sheet,) = [s for s in sheets if MOUNT_PART in s["parts"]]
    assert plate_sheet["thickness_mm"] == 3.0
    assert not [name for name in plate_sheet["parts"] if thickness[name] == 6.0]
    code = main(["check", str(out), "-q"])
    captured = capsys.readouterr()
    assert code == 0, captured.out + captured.err
    assert "Traceback" not in captured.out + captured.err


@pytest.mark.parametrize("bulged", [True, False])
def test_add_closed_polyline_writes_what_add_lwpolyline_writes(bulged):
    """The polyline whose vertices go to ezdxf's vertex array at once is byte for byte the one ezdxf's
    ``add_lwpolyline`` makes point by point: the same document bytes (bulges of either sign and none)."""
    from fabricate.export.dxf import add_closed_polyline, document_bytes, new_document

    angle = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    xy = np.column_stack([10.0 * np.cos(angle) + 0.1, 4.0 * np.sin(3.0 * angle) - 1.0 / 3.0])
    bulges = np.where(np.arange(40) % 3 == 0, 0.0, np.sin(angle) * 0.4) if bulged else None
    ours, theirs = new_document(), new_document()
    add_closed_polyline(ours.modelspace(), xy, "CUT", bulges)
    points = [(float(x), float(y), float(b)) for (x, y), b in zip(xy, bulges if bulged else np.zeros(40),
                                                                   strict=True)]
    theirs.modelspace().add_lwpolyline(points, format="xyb", close=True, dxfattribs={"layer": "CUT"})
    data = document_bytes(ours)
    assert data == document_bytes(theirs)
    (polyline,) = _msp(data).query("LWPOLYLINE")
    assert polyline.closed and len(polyline) == 40
    assert np.allclose([b for *_, b in polyline.get_points("xyseb")], bulges if bulged else 0.0)


def test_cut_geometry_is_worked_out_once_per_part_and_kerf(parts, monkeypatch):
    """A part's cut path is offset once per kerf, and every call gets it in lists of its own (a caller that
    appends to one changes no other's); the hole centres shared between calls cannot be written."""
    from fabricate.export import dxf
    from fabricate.parts.profiles import offset_path

    calls = []
    monkeypatch.setattr(dxf, "offset_path", lambda path, d: calls.append(d) or offset_path(path, d))
    part = next(p for p in parts if p.holes)
    first = dxf.cut_geometry(part, 0.2)
    made = len(calls)
    second = dxf.cut_geometry(part, 0.2)
    assert len(calls) == made > 0  # nothing offset again
    assert second[0] is first[0] and second[1] == first[1] and second[1] is not first[1]
    assert np.array_equal(first[0].vertices, offset_path(part.outline, 0.1).vertices)
    assert [d for _, d in first[1]] == pytest.approx([h.diameter_mm - 0.2 for h in part.holes])
    first[1].clear()
    assert len(dxf.cut_geometry(part, 0.2)[1]) == len(part.holes)
    with pytest.raises(ValueError):
        second[1][0][0][0] = 1.0
    other = dxf.cut_geometry(part, 0.3)  # another kerf: worked out for itself
    assert len(calls) > made and not np.array_equal(other[0].vertices, first[0].vertices)
