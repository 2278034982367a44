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
@pytest.mark.parametrize("name", [p.stem for p in shipped_templates()])
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
        if step["new_parts"] or step["new_pins"] or step["new_springs"]:
            # a step that adds something highlights it, and its picture is not the step before's (a part
            # added under others may add no pixel of its own: the highlight shows where it went)
            assert orange(png) > 0 and png != previous
        previous = png
    # the whole assembly covers more of the picture than the ground part alone
    assert drawn(outcome.files[guide[-1]["picture"]]) > drawn(outcome.files[guide[0]["picture"]])
    assert all(p in outcome.report["files"] for p in (s["picture"] for s in guide))


@pytest.mark.slow
def test_report_md_puts_the_interference_table_last(shipped_build):
    md = shipped_build("gripper_compliant").files["report.md"].decode()
    assert md.index("[assembly.md](assembly.md)") < md.index("## Mechanism")
    assert md.index("## Strength") < md.index("## Files") < md.index("## Interference")
    assert "| a | b | contact |" in md[md.index("## Interference"):]


@pytest.mark.parametrize("process", ["sla_process", "laser_process"])
def test_guide_of_a_four_bar_fits_every_unit_once_and_draws_each_step(process, request):
    """Fast: a four-bar in two copies with a spring and a shared motor, built by the parts layer alone (printed
    and cut: spacers printed or bought, each process's retention)."""
    chosen = request.getfixturevalue(process)
    from types import SimpleNamespace

    from fabricate.export.guide import guide_markdown, guide_pictures, guide_steps
    from fabricate.hints import PartHints, PurchasedItem, SpringHint
    from fabricate.parts.build import build_parts
    from fabricate.parts.spec import PartsSpec
    from tests.conftest import make_four_bar

    mech = make_four_bar()
    motion = mech.sweep(41)
    design = SimpleNamespace(name="t", process=chosen, parts=PartsSpec(),
                             gears=SimpleNamespace(hub_diameter_mm=None))
    hints = PartHints(copies=2, springs=(SpringHint("B", 0.2, 30.0, 12.0),),
                      purchased_shared=(PurchasedItem("drive motor", 1, "turns the crank"),))
    partset = build_parts(design, mech, motion, [], hints)
    steps = guide_steps(partset, motion)
    md = guide_markdown(steps, "t", partset.copies)
    assert listed(md) == expected(partset.bom, 2)
    assert ("drive motor", True) in listed(md)
    titles = [s.title for s in steps]
    assert titles[0] == "The ground part" and titles[-1] == "Check the motion"
    # the spring's step comes right after its pin's
    assert titles.index("Torsion spring at B") == titles.index("Pin B") + 1
    assert "Repeat steps 1–" in md
    pictures = guide_pictures(partset, motion, steps)
    assert sorted(pictures) == [s.picture for s in steps]
    spring_step = steps[titles.index("Torsion spring at B")]
    assert orange(pictures[spring_step.picture]) > 0  # the new spring is highlighted
    for before, after in zip(steps, steps[1:], strict=False):
        if after.new:
            assert drawn(pictures[after.picture]) > drawn(pictures[before.picture])
