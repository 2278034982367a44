"""PartHints (fabricate/hints.py): the exact form's [linkage.hints] written and read back, and bad hints refused
with the field named."""

from __future__ import annotations

import pytest

import fabricate
from fabricate.errors import SpecError
from fabricate.hints import PadHint, PartHints, PurchasedItem, SpringHint
from fabricate.synthesis.linkage.exact import read_hints
from fabricate.table import Table
from fabricate.templates import parse_toml
from fabricate.tomlwrite import dumps
from tests.conftest import make_four_bar

EVERY_FIELD = PartHints(
    springs=(SpringHint("A", 0.25, 12.5, 15.0, "return spring"), SpringHint("B", 0.0)),
    purchased=(PurchasedItem("rod", 2, "pushes"),),
    purchased_shared=(PurchasedItem("motor", 1, "one for all"),),
    copies=3, copy_angle_deg=120.0, tip_point="tip", link_width_mm=7.5,
    pads={"distal": PadHint("tip", 4.0), "palm": PadHint("pad", None, ("p0", "p1"))},
)


def _read(table: dict) -> PartHints:
    return read_hints(Table(table, "linkage.hints"))


def test_every_field_survives_the_toml_round_trip() -> None:
    text = dumps({"hints": EVERY_FIELD.as_table()})
    assert _read(parse_toml(text, "m.toml")["hints"]) == EVERY_FIELD


def test_defaults_are_not_written_and_an_empty_pads_table_is_kept() -> None:
    assert PartHints().as_table() == {}
    # the linkage kind hands an empty pads table; mechanism.toml keeps it, so a rebuild writes the same file
    assert PartHints(pads={}).as_table() == {"pads": {}}
    assert _read({"pads": {}}) == PartHints(pads={})
    # the field order is the file's: lists and scalars first, pads last; within an item, None left out
    table = EVERY_FIELD.as_table()
    assert list(table) == ["springs", "purchased", "purchased_shared", "copies", "copy_angle_deg", "tip_point",
                           "link_width_mm", "pads"]
    assert table["springs"][1] == {"joint": "B", "rate_Nmm_per_deg": 0.0, "preload_deg": 0.0, "note": ""}
    assert table["pads"]["palm"] == {"point": "pad", "arc": ["p0", "p1"]}


@pytest.mark.parametrize(("table", "path"), [
    ({"tip": "P"}, "linkage.hints.tip"),
    ({"pads": {"distal": {"point": "P", "radius": 3.0}}}, "linkage.hints.pads.distal.radius"),
    ({"pads": {"distal": {"radius_mm": 3.0}}}, "linkage.hints.pads.distal.point"),
    ({"pads": {"distal": {"point": "P", "arc": ["a", "b", "c"]}}}, "linkage.hints.pads.distal.arc"),
    ({"springs": [{"joint": "A"}]}, "linkage.hints.springs[0].rate_Nmm_per_deg"),
    ({"springs": [{"joint": "A", "rate_Nmm_per_deg": -1.0}]}, "linkage.hints.springs[0].rate_Nmm_per_deg"),
    ({"purchased": [{"item": "rod", "qty": 0}]}, "linkage.hints.purchased[0].qty"),
    ({"copies": 0}, "linkage.hints.copies"),
    ({"link_width_mm": "wide"}, "linkage.hints.link_width_mm"),
])
def test_a_bad_hint_is_refused_naming_its_field(table: dict, path: str) -> None:
    with pytest.raises(SpecError) as info:
        _read(table)
    assert info.value.path == path, info.value


def test_from_mechanism_names_the_bad_pad_by_its_argument() -> None:
    with pytest.raises(SpecError) as info:
        fabricate.from_mechanism(make_four_bar(), pads={"rocker": {"point": "B", "radius_mm": -3.0}})
    assert info.value.path == "pads.rocker.radius_mm", info.value
    design = fabricate.from_mechanism(make_four_bar(), tip_point="B", pads={"rocker": {"point": "B", "radius_mm": 3.0}})
    assert design.method.hints == PartHints(tip_point="B", pads={"rocker": PadHint("B", 3.0)})
