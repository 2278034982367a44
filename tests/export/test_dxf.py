"""Hole labels of the part drawings (issue 25, item 2): the nominal hole and its fit, and apart from it the CAD
size with the process's compensation; never in a cut file."""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET

import ezdxf
import pytest

from fabricate.export.dxf import MIN_DRAWING_TEXT_MM, DxfStyle, part_dxf
from fabricate.export.svg import part_svg
from fabricate.parts.build import build_parts
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
