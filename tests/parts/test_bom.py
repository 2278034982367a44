"""The bill of materials a maker orders from: every printed or cut part with its mass, springs only where
they exist, bom.csv carrying every column; and the assembly stacks that say what goes where on each pin."""

from __future__ import annotations

import csv
import dataclasses
import io

import numpy as np
import pytest
import shapely

from fabricate.design import load_design
from fabricate.hints import PartHints
from fabricate.parts.bom import Spacer, bill_of_materials


@pytest.fixture(scope="module")
def gripper(shipped_build):
    return shipped_build("gripper_compliant")


@pytest.fixture(scope="module")
def five_bar_laser(shipped_build):
    return shipped_build("finger_five_bar_ncg", "laser")  # the session's, shared with test_mount and test_auto


@pytest.mark.slow
def test_every_part_is_in_the_bom_with_its_mass(gripper, five_bar_laser):
    for outcome, kind in ((gripper, "printed part"), (five_bar_laser, "cut part")):
        process = load_design(outcome.report["design"]["template"].removesuffix(".toml"),
                              "laser" if kind == "cut part" else None).process
        rows = {r["item"]: r for r in outcome.report["bom"] if r["kind"] == kind}
        assert set(rows) == {p.name for p in outcome.partset.parts}
        for part in outcome.partset.parts:
            row = rows[part.name]
            assert row["qty"] == outcome.partset.copies and row["process"] == process.name
            # the profile's material by its name for people (its key selects the strength data)
            assert row["material"] == process.part_material().name and process.material
            # independent of the BOM code: the profile area (shapely, from the polygon) x thickness x density
            rings = part.polygons(1e-6)  # inscribed: loses at most 1e-6 mm x perimeter of area
            area = shapely.Polygon(rings[0], rings[1:]).area
            mass = area * part.thickness_mm * process.density_g_cm3 / 1000
            assert row["mass_g"] == pytest.approx(mass, rel=1e-5, abs=1e-6)
    assert gripper.partset.copies == 3  # three fingers: three of every part


@pytest.mark.slow
def test_springs_only_where_the_rate_is_above_zero(gripper):
    springs = [r for r in gripper.report["bom"] if r["kind"] == "spring"]
    rates = {s.joint: s.rate_Nmm_per_deg for s in gripper.partset.hints.springs}
    assert min(rates.values()) == 0.0 < max(rates.values())  # the optimum's k1 = 0: no spring at that hinge
    assert {s["joints"][0] for s in springs} == {j for j, k in rates.items() if k > 0}
    assert all(s["rate_Nmm_per_deg"] > 0 and s["qty"] == 3 for s in springs)


@pytest.mark.slow
def test_bom_csv_carries_every_column_of_the_report(gripper):
    rows = list(csv.DictReader(io.StringIO(gripper.files["bom.csv"].decode())))
    bom = gripper.report["bom"]
    assert len(rows) == len(bom)
    assert set(rows[0]) == {k for r in bom for k in r}
    for row, entry in zip(rows, bom, strict=True):
        for key, value in entry.items():
            if isinstance(value, list):
                assert row[key] == " ".join(map(str, value))
            elif isinstance(value, float):
                assert float(row[key]) == pytest.approx(value, rel=1e-12)
            else:
                assert row[key] == str(value)


@pytest.mark.slow
def test_printed_spacers_are_parts_not_hardware(gripper):
    bom = gripper.report["bom"]
    spacer_parts = [p.name for p in gripper.partset.parts if p.role == "spacer"]
    assert spacer_parts and all(any(r["item"] == n and r["kind"] == "printed part" for r in bom)
                                for n in spacer_parts)
    assert not any(r["kind"] == "spacer" for r in bom)  # no second count of the same spacers


@pytest.mark.slow
@pytest.mark.parametrize("which", ["gripper", "five_bar_laser"])
def test_each_pin_stack_fills_its_pin_exactly(which, request):
    """Each stack's items cover its pin's span where the pin is: from face to face of the stack (report.json's
    hardware: the pin's ends less its stated protrusions), without an overlap, a gap only where no standard
    washer is that thin (axial play). Beyond a face only the retention's end items (the hardware's ``ends``,
    on the pin's protrusion) and a spring (on the pin's extension, or on its printed arbor where it reaches
    past the pin's end). A pressed pin short of a face ends inside the part there."""
    from fabricate.parts.retention import fill_layer_gap

    outcome = request.getfixturevalue(which)
    stacks = outcome.report["assembly"]["pins"]
    hardware = {p["pin"]: p for p in outcome.report["hardware"]["pins"]}
    assert {s["pin"] for s in stacks} == {p.joint for p in outcome.partset.pins} == set(hardware)
    by_name = {p.name: p for p in outcome.partset.parts}
    for stack in stacks:
        pin = hardware[stack["pin"]]
        assert stack["length_mm"] == pytest.approx(pin["length_mm"], abs=1e-9)
        ends = (stack["z_mm"], stack["z_mm"] + stack["length_mm"])  # the pin's own ends
        faces = (ends[0] + pin["protrusion_mm"][0], ends[0] + pin["protrusion_mm"][0] + pin["stack_mm"])
        assert faces[1] + pin["protrusion_mm"][1] == pytest.approx(ends[1], abs=1e-9)
        items = stack["stack"]
        inside = [i for i in items if faces[0] - 1e-9 <= i["z_mm"][0] and i["z_mm"][1] <= faces[1] + 1e-9]
        # the stack: bottom face to top face, no overlap, a gap only where no standard washer fits
        assert inside[0]["z_mm"][0] == pytest.approx(faces[0], abs=1e-9)
        assert inside[-1]["z_mm"][1] == pytest.approx(faces[1], abs=1e-9)
        for below, above in zip(inside, inside[1:], strict=False):
            gap = above["z_mm"][0] - below["z_mm"][1]
            assert gap >= -1e-9, (stack["pin"], below, above)
            assert gap <= 1e-9 or fill_layer_gap(pin["diameter_mm"], gap) == (), (stack["pin"], below, above)
        for side, sign in ((0, -1.0), (1, 1.0)):
            face = faces[side]
            if pin["protrusion_mm"][side] < 0.0:  # a pressed pin short of this face: it ends inside the part there
                (at_face,) = [i for i in inside if abs(i["z_mm"][side] - face) < 1e-9]
                assert at_face["kind"] == "part"
                assert at_face["z_mm"][1] - at_face["z_mm"][0] > -pin["protrusion_mm"][side]
            beyond = sorted((i for i in items if sign * (i["z_mm"][1 - side] - face) >= -1e-9 and i not in inside),
                            key=lambda i: sign * i["z_mm"][0])
            # the retention's end items, face outwards, each on the pin's protrusion
            retained = [i for i in beyond if i["kind"] in ("clip", "washer")]
            assert [i["item"] for i in retained] == pin["ends"][side], stack["pin"]
            for i in retained:
                assert min(ends) - 1e-9 <= i["z_mm"][0] and i["z_mm"][1] <= max(ends) + 1e-9
            for spring in (i for i in beyond if i["kind"] == "spring"):
                assert min(abs(spring["z_mm"][0] - face), abs(spring["z_mm"][1] - face)) < 1e-9  # on the face
                past_pin = spring["z_mm"][0] < ends[0] - 1e-9 or spring["z_mm"][1] > ends[1] + 1e-9
                arbors = [i for i in beyond if i["kind"] == "part" and i["z_mm"] == spring["z_mm"]
                          and any(h.joint == f"arbor_{stack['pin']}" for h in by_name[i["item"]].holes)]
                assert arbors or not past_pin, (stack["pin"], spring)  # past the pin's end: on its arbor
            assert {i["kind"] for i in beyond} <= {"clip", "washer", "spring", "part"}
        for item in items:
            if item["kind"] == "part":
                part = by_name[item["item"].removesuffix(" (in its slot)")]  # a real part, at its own height
                # report.json rounds heights to 1e-6 mm (an arbor stands at a computed, not a round, height)
                assert item["z_mm"] == pytest.approx([part.z_mm, part.z_mm + part.thickness_mm], abs=1e-6)
                holes = {h.joint for h in part.holes}
                if f"arbor_{stack['pin']}" in holes:
                    assert item not in inside  # a spring's arbor stands beyond the stack's face
                    continue
                on_hole = bool(holes & set(stack["pin"].split("+")))
                assert on_hole != item["item"].endswith("(in its slot)")  # a hole, or else its slot
                assert on_hole or part.slots
    csv_rows = list(csv.DictReader(io.StringIO(outcome.files["assembly.csv"].decode())))
    assert len(csv_rows) == sum(len(s["stack"]) for s in stacks)
    steps = outcome.report["assembly"]["steps"]
    assert len(steps) == len(stacks) + (outcome.partset.copies > 1)
    assert "## Assembly" in outcome.files["report.md"].decode()


@pytest.mark.slow
def test_exploded_picture_shows_every_part(gripper):
    import numpy as np
    from PIL import Image

    from fabricate.export.previews import PALETTE, part_colours

    image = np.asarray(Image.open(io.BytesIO(gripper.files["previews/exploded.png"])).convert("RGB")).astype(float)
    colours = part_colours(gripper.partset.parts)
    for part in gripper.partset.parts:
        # each part's face is drawn in its own colour at alpha 0.75 over white
        rgb = 0.75 * np.array(PALETTE[colours[part.name]], dtype=float) + 0.25 * 255.0
        close = np.all(np.abs(image - rgb) <= 3.0, axis=2)
        assert close.sum() > 20, part.name


def test_spacers_are_printed_by_an_additive_process_and_bought_for_a_cut_one(sla_process, laser_process):
    """A tube over a skipped layer is a part an additive process prints (no hardware row); a cut process
    buys it. Washers are bought either way. The technique decides, not the name."""
    tube = Spacer(joint="A", body="b", centre=np.zeros(2), inner_diameter_mm=2.5, outer_diameter_mm=6.0,
                  length_mm=3.6, z_mm=3.3, lower_layer=0, washer=False)
    washer = dataclasses.replace(tube, length_mm=0.3, washer=True)
    for process, kinds in ((sla_process, {"washer"}), (laser_process, {"spacer", "washer"}),
                           (dataclasses.replace(sla_process, name="laser"), {"washer"}),
                           (dataclasses.replace(laser_process, name="sla"), {"spacer", "washer"})):
        rows = bill_of_materials([], [tube, washer], PartHints(), process, copies=2)
        assert {r["kind"] for r in rows} == kinds, process.name
        assert all(r["qty"] == 2 for r in rows)
