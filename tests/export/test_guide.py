"""The assembly guide (``fabricate/parts/assembly.py`` steps, ``fabricate/export/guide.py`` assembly.md and
pictures), read from real builds: every BOM unit is listed once per copy, every step's picture is a PNG of
the stated size, and a step that adds parts shows more of the assembly than the step before."""

from __future__ import annotations

import io
import re
from collections import Counter

import numpy as np
import pytest

from fabricate.templates import shipped_templates

ITEM_LINE = re.compile(r"^- (\d+) × `(.+)` \(([^,)]+)(, shared)?\)$")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def listed(md: str) -> Counter[tuple[str, bool]]:
    """``(item, shared) -> quantity`` over every "Parts and hardware" line of assembly.md."""
    counts: Counter[tuple[str, bool]] = Counter()
    for line in md.splitlines():
        m = ITEM_LINE.match(line)
        if m:
            counts[(m.group(2), bool(m.group(4)))] += int(m.group(1))
    return counts


def expected(bom: list[dict], copies: int) -> Counter[tuple[str, bool]]:
    """The BOM per copy (a row shared by all copies, or not divisible by them: in all)."""
    counts: Counter[tuple[str, bool]] = Counter()
    for row in bom:
        shared = bool(row.get("shared")) or row["qty"] % copies != 0
        counts[(row["item"], shared)] += row["qty"] if shared else row["qty"] // copies
    return counts


def drawn(png: bytes) -> int:
    """Pixels that are not the white background."""
    from PIL import Image

    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int32)
    return int((np.abs(image - 255).sum(axis=2) > 30).sum())


def orange(png: bytes) -> int:
    """Pixels of the highlight (new parts, pins, springs): strongly red-orange."""
    from PIL import Image

    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int32)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((r > 180) & (r - b > 90) & (g < r - 30)).sum())


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(t.removesuffix(".toml") for t in shipped_templates()
                                        if not t.startswith("process_")))
def test_guide_lists_every_bom_unit_once_per_copy_with_its_pictures(shipped_build, name):
    outcome = shipped_build(name)
    md = outcome.files["assembly.md"].decode()
    copies = outcome.partset.copies
    assert listed(md) == expected(outcome.report["bom"], copies)
    assert "[assembly.md](assembly.md)" in outcome.files["report.md"].decode()
    guide = outcome.report["assembly"]["guide"]
    assert [s["step"] for s in guide] == list(range(1, len(guide) + 1))
    assert guide[-1]["title"] == "Check the motion"
    # every pin has its step, every spring its own, and the pictures are there, 360 x 270 PNGs
    assert {p.joint for p in outcome.partset.pins} == {j for s in guide for j in s["new_pins"]}
    assert {s["joint"] for s in outcome.report.get("springs", [])} == {j for s in guide for j in s["new_springs"]}
    from PIL import Image

    previous = None
    for step in guide:
        png = outcome.files[step["picture"]]
        assert png.startswith(PNG_MAGIC) and f"]({step['picture']})" in md
        assert Image.open(io.BytesIO(png)).size == (360, 270)
        if step["new_parts"] or step["new_pins"]:
            # a step that adds something highlights it, and shows more of the assembly than the step before
            assert orange(png) > 0
            if previous is not None and step["new_parts"]:
                assert drawn(png) > drawn(previous)
        previous = png
    assert all(p in outcome.report["files"] for p in (s["picture"] for s in guide))


@pytest.mark.slow
def test_report_md_puts_the_interference_table_last(shipped_build):
    md = shipped_build("gripper_compliant").files["report.md"].decode()
    assert md.index("[assembly.md](assembly.md)") < md.index("## Mechanism")
    assert md.index("## Strength") < md.index("## Files") < md.index("## Interference")
    assert "| a | b | contact |" in md[md.index("## Interference"):]
