"""Pictures a build draws stay readable (``fabricate/export/previews.py`` and every plot module through
``fabricate.plotting``), the exploded view draws every pin, and assembly.csv names what the BOM names.

Read from the shipped templates' builds (the session's shared builds): slow, like every full build."""

from __future__ import annotations

import csv
import io
from typing import Any

import pytest

import fabricate.plotting as plotting
from fabricate.templates import shipped_templates

TEMPLATES = [p.stem for p in shipped_templates()]


def _rows(data: bytes) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(data.decode("utf-8"))))


@pytest.fixture
def drawn(monkeypatch) -> list[Any]:
    """Every matplotlib figure rendered through :func:`fabricate.plotting.png_bytes` while the test runs."""
    figures: list[Any] = []
    render = plotting._savefig

    def keep(fig: Any, buffer: io.BytesIO, dpi: float) -> None:
        figures.append(fig)
        render(fig, buffer, dpi)

    monkeypatch.setattr(plotting, "_savefig", keep)
    return figures


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_assembly_csv_names_only_bom_items(shipped_build, name):
    outcome = shipped_build(name)
    bom_items = {row["item"] for row in _rows(outcome.files["bom.csv"])}
    rows = _rows(outcome.files["assembly.csv"])
    assert rows
    assert {row["item"] for row in rows} <= bom_items
    # every part on a pin is the part itself: through its hole, or (a slider) noted as riding in its slot
    by_name = {p.name: p for p in outcome.partset.parts}
    for row in rows:
        if row["kind"] == "part":
            joints = set(row["pin"].split("+")) | {row["pin"], f"arbor_{row['pin']}"}  # a spring's arbor too
            on_hole = any(h.joint in joints for h in by_name[row["item"]].holes)
            assert on_hole == (row["note"] == ""), row
            assert row["note"] in ("", "in its slot")


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_every_stack_item_is_on_its_pin(shipped_build, name):
    """What a pin's stack lists, the pin passes through (it may end inside an end part: a pressed pin). The
    drive's mount plate and standoffs, on the ground's screws, were listed on a ground pin past its end."""
    outcome = shipped_build(name)
    arbors = {p.name for p in outcome.partset.parts if p.role == "arbor"}  # a spring's, beside its pin
    for stack in outcome.report["assembly"]["pins"]:
        bottom, top = stack["z_mm"], stack["z_mm"] + stack["length_mm"]
        for item in stack["stack"]:
            if item["kind"] != "spring" and item["item"] not in arbors:
                assert item["z_mm"][0] < top and item["z_mm"][1] > bottom, (stack["pin"], item)


@pytest.mark.slow
def test_exploded_view_draws_every_pin_compound_ones_too(shipped_build):
    from fabricate.export.previews import exploded_figure
    from fabricate.parts.assembly import pin_stacks

    outcome = shipped_build("jansen_leg")
    stacks = pin_stacks(outcome.partset)
    assert any("+" in s.pin for s in stacks)  # the compound pins the view used to leave out
    fig = exploded_figure(list(outcome.partset.parts), outcome.motion.poses_at(0), stacks, title="jansen_leg")
    drawn_pins = sorted(line.get_gid() for line in fig.axes[0].get_lines() if (line.get_gid() or "").startswith("pin "))
    assert drawn_pins == sorted(f"pin {s.pin}" for s in stacks)


@pytest.mark.slow
def test_assembly_preview_gives_every_part_its_own_colour_and_a_legend(shipped_build):
    from fabricate.export.previews import assembly_figure

    outcome = shipped_build("jansen_leg")
    parts = list(outcome.partset.parts)
    assert len(parts) > 10  # past the ten colours that used to cycle
    fig = assembly_figure(parts, outcome.motion, 4, outcome.partset.hints.tip_point, title="jansen_leg")
    faces = fig.axes[0].collections[0].get_facecolors()
    assert len(faces) == len(parts)
    assert len({tuple(round(float(c), 4) for c in rgba[:3]) for rgba in faces}) == len(parts)
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert set(texts) >= {p.name for p in parts}
    assert plotting.figure_problems(fig) == []


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_every_picture_of_a_build_is_readable(shipped_build, drawn, name):
    """The method's plots, the gear pictures, the previews and the clearance plot of each shipped template:
    no legend under the stated size, every labelled series in a legend, no two legend entries alike, no
    unexplained multi-colour curves."""
    from fabricate.export.previews import assembly_figure, exploded_figure
    from fabricate.parts.assembly import pin_stacks
    from fabricate.pipeline import gear_pictures

    outcome = shipped_build(name)
    parts, motion = list(outcome.partset.parts), outcome.motion
    outcome.synthesis.figures()
    gear_pictures(outcome.gear_pairs)
    outcome.checks.figures()
    drawn.append(assembly_figure(parts, motion, 4, outcome.partset.hints.tip_point, title=name))
    drawn.append(exploded_figure(parts, motion.poses_at(0), pin_stacks(outcome.partset), title=name))
    assert len(drawn) >= 3
    problems = {k: plotting.figure_problems(fig) for k, fig in enumerate(drawn)}
    assert not {k: p for k, p in problems.items() if p}


@pytest.mark.slow
def test_strength_and_drive_plots_of_a_build_are_readable(shipped_build, drawn):
    """The strength plot with its 12 most loaded parts and the drive plot of jansen_leg, from the checks as
    the build runs them."""
    from fabricate.drive.check import run_drive
    from fabricate.drive.plots import drive_plot
    from fabricate.strength.check import run_strength
    from fabricate.strength.plots import strength_plot

    outcome = shipped_build("jansen_leg")
    design, partset, motion, synthesis = outcome.design, outcome.partset, outcome.motion, outcome.synthesis
    strength = run_strength(design, partset, synthesis.mechanism, motion, outcome.gear_pairs, synthesis.parts)
    assert strength_plot(strength, synthesis.mechanism.input_unit) == outcome.files["plots/strength.png"]
    drive = run_drive(design, synthesis.mechanism, motion, synthesis.parts, strength, copies=partset.copies)
    assert drive_plot(drive) == outcome.files["plots/drive.png"]
    strength_fig, drive_fig = drawn
    colours = plotting.series_colours(strength_fig.axes[0])
    assert len(colours) == 13 and len(set(colours)) == 13  # 12 parts and the limit, no two alike
    assert plotting.figure_problems(strength_fig) == [] and plotting.figure_problems(drive_fig) == []
