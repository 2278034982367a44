"""Every shipped template's pins, built (issue 25 item 3): each is a catalogued standard pin at or above its
stack plus its retention's allowance, its ends as the plan states them, and the build's interference proof,
which sweeps each pin over its own length, still passes."""

from __future__ import annotations

import pytest

from fabricate.catalogue.designations import parse_designation
from fabricate.catalogue.pins import PinChoice, pin_lengths
from fabricate.checks.items import pin_items, pins_from_parts_layer
from fabricate.templates import shipped_templates

TEMPLATES = [p.stem for p in shipped_templates()]


@pytest.mark.slow
@pytest.mark.parametrize("template", TEMPLATES)
def test_every_pin_covers_its_stack_and_its_retention(template, shipped_build):
    outcome = shipped_build(template)
    partset = outcome.partset
    assert partset is not None and partset.pins
    for pin in partset.pins:
        assert not pin.note, pin.note  # no pin cut from rod: every stack has a standard pin
        choice = parse_designation(pin.designation)
        assert isinstance(choice, PinChoice) and choice.length_mm == pin.length_mm
        standard = " ".join(pin.designation.split()[:2])
        assert pin.length_mm in pin_lengths(pin.diameter_mm, standard)
        assert pin.length_mm >= pin.stack_mm + pin.allowance_mm - 1e-9, (pin.joint, pin.length_mm, pin.stack_mm)
        # the pin's own span is its stack and what sticks out of each face, never less than the stack
        assert min(pin.protrusion_mm) >= -1e-9
        assert sum(pin.protrusion_mm) + pin.stack_mm == pytest.approx(pin.length_mm, abs=1e-9)
    # the proof sweeps each pin from its own bottom over its whole catalogued length...
    items = {it.name: it for it in pin_items(pins_from_parts_layer(partset.pins, partset.parts), 0.005)}
    for pin in partset.pins:
        item = items[f"pin_{pin.joint}"]
        assert (item.z0, item.z1) == pytest.approx((pin.z_mm, pin.z_mm + pin.length_mm), abs=1e-9)
    # ...and finds no collision in the build
    assert not [f for f in outcome.failures if f.startswith("interference")], outcome.failures
    assert outcome.report["interference"]["collisions"] == [] and outcome.report["interference"]["passed"]
