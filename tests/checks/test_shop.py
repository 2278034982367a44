"""A laser shop's rules as checks (fabricate.checks.shop): the profile's numbers, each breach named by part and
rule; a clean part passes; only a cut process is checked; the profile's [shop] and [sheets] are read and
checked like every other field."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fabricate.checks.shop import ShopRules, check_part, check_shop, cut_path_problems
from fabricate.errors import SpecError
from fabricate.process import parse_process
from fabricate.table import Table
from fabricate.templates import TEMPLATE_DIR, read_toml
from tests.export.test_labels import bar

RULES = ShopRules(min_hole_mm=1.5, min_web_mm=1.5, min_hole_edge_mm=1.5)


def with_holes(*holes: tuple[str, tuple[float, float], float]):
    part = bar(length=40.0, width=12.0)
    return dataclasses.replace(part, holes=tuple(dataclasses.replace(part.holes[0], joint=j, centre=np.array(c),
                                                                     diameter_mm=d) for j, c, d in holes))


def test_a_part_within_the_rules_passes():
    assert check_part(bar(length=40.0, width=12.0), RULES, 0.2) == []


def test_each_rule_names_the_part_the_feature_and_its_number():
    small = check_part(with_holes(("A", (0.0, 0.0), 1.2)), RULES, 0.2)
    assert small == ["shop: part link_long: hole A Ø1.200 is 1.200 mm across, below the shop's minimum hole "
                     "1.5 mm (min_hole_mm)"]
    # web: two 3.2 holes 4.4 apart leave 1.2 mm between them
    web = check_part(with_holes(("A", (10.0, 0.0), 3.2), ("B", (14.4, 0.0), 3.2)), RULES, 0.2)
    assert len(web) == 1 and "hole A Ø3.200 and hole B Ø3.200 leave a 1.200 mm web" in web[0]
    assert "min_web_mm" in web[0]
    # edge: a 3.2 hole 1 mm from the 6 mm half-width edge
    edge = check_part(with_holes(("A", (20.0, 3.4), 3.2)), RULES, 0.2)
    assert len(edge) == 1 and "leaves 1.000 mm to the edge" in edge[0] and "min_hole_edge_mm" in edge[0]
    # exactly at the rule passes; the numbers are the rules'
    assert check_part(with_holes(("A", (20.0, 2.9), 3.2)), RULES, 0.2) == []
    assert check_part(with_holes(("A", (20.0, 2.9), 3.2)), dataclasses.replace(RULES, min_hole_edge_mm=1.6), 0.2)


def test_overlapping_or_repeated_cut_contours_are_found():
    twice = with_holes(("A", (10.0, 0.0), 3.2), ("B", (10.0, 0.0), 3.2))
    assert cut_path_problems(twice, 0.2) == ["the cut hole A and hole B touch or overlap (a line cut twice)"]
    assert any("overlap" in f and "min_web_mm" in f for f in check_part(twice, RULES, 0.2))
    outside = with_holes(("A", (0.0, 6.0), 3.2))  # on the edge: its circle crosses the outline
    problems = check_part(outside, RULES, 0.2)
    assert any("the cut outline and hole A touch or overlap" in p for p in problems)
    assert any("hole A Ø3.200 reaches the outline" in p for p in problems)
    assert cut_path_problems(with_holes(("A", (0.0, 0.0), 0.1)), 0.2)[0].startswith("hole A: the cut circle")


def test_only_a_cut_process_is_checked_and_defaults_are_half_the_thickness(laser_process, sla_process):
    parts = [with_holes(("A", (0.0, 0.0), 1.2))]
    assert check_shop(parts, sla_process) is None
    result = check_shop(parts, laser_process)  # no [shop]: half of the 3 mm stock
    assert result.rules == ShopRules(1.5, 1.5, 1.5) and not result.passed and result.parts_checked == 1
    assert result.report()["failures"] == list(result.failures)
    lenient = dataclasses.replace(laser_process, shop=(("min_hole_mm", 1.0),))
    assert check_shop(parts, lenient).passed and ShopRules.of(lenient).min_web_mm == 1.5


def test_the_laser_profile_reads_its_sheets_and_shop_rules():
    spec = parse_process(Table({"profile": "laser"}, "process"))
    assert [name for name, *_ in spec.sheets] == ["P1", "P2", "P3"]  # smallest first
    assert dict(spec.shop) == {"min_hole_mm": 1.5, "min_web_mm": 1.5, "min_hole_edge_mm": 1.5}
    assert max(w for _, w, _ in spec.sheets) <= spec.build_volume_mm[0]  # every sheet fits the bed
    shipped = read_toml(TEMPLATE_DIR / "process_laser.toml")
    with pytest.raises(SpecError, match="unknown field") as info:
        parse_process(Table({"profile": "laser", "shop": {**shipped["shop"], "min_hoel_mm": 1.0}}, "process"))
    assert info.value.path == "process.shop.min_hoel_mm"
    with pytest.raises(SpecError) as info:
        parse_process(Table({"profile": "laser", "sheets": {"A4": [297.0]}}, "process"))
    assert info.value.path == "process.sheets.A4"


def test_a_part_cut_from_another_stock_is_held_to_half_that_stock(laser_process):
    six = dataclasses.replace(laser_process, thickness_mm=6.0)  # a template's 6 mm: [shop] dropped, half of 6
    assert ShopRules.of(six) == ShopRules(3.0, 3.0, 3.0)
    assert ShopRules.of(six, 3.0) == ShopRules(1.5, 1.5, 1.5)
    given = dataclasses.replace(laser_process, shop=(("min_hole_mm", 1.0),))  # the profile's numbers: its own stock's
    assert ShopRules.of(given, 3.0).min_hole_mm == 1.0 and ShopRules.of(given, 6.0).min_hole_mm == 3.0
    # a 2.4 mm hole: below a 6 mm sheet's minimum, within a 3 mm sheet's
    thick = dataclasses.replace(with_holes(("A", (0.0, 0.0), 2.4)), thickness_mm=6.0)
    thin = dataclasses.replace(thick, thickness_mm=3.0)
    assert [f for f in check_shop([thick], six).failures if "minimum hole 3 mm" in f]
    assert check_shop([thin], six).passed
