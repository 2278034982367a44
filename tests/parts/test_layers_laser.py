"""Shipped templates made with ``--process laser`` (clip retention: every pin sticks out of both faces of its
stack for its DIN 6799 clip and washers): the layer order keeps those ends, the spring-lengthened pins and a
motor's side clear, so no part collides with a pin, a washer, a clip or the actuator.

The six-bar needs a layer of its own for one body (its MG996R's bare spline reaches one layer into the stack,
where the rocker-ground pin's clip end would sit under the case otherwise). The gripper cut from 3 mm acrylic
fails only what the laser profile cannot give it: its hinges' strength (the template's 12 mm plates) and its
spring's 27 mm arbor (a printed part, thicker than the sheet). The default five-bar finger's laser gears and
the underactuated finger (ten bodies in five colours of 6 mm sheet: no order of at most seven layers leaves
every clip end clear, and its music-wire anchor holes are below the shop's smallest hole) are open: not here.
"""

from __future__ import annotations

import pytest

from fabricate.design import load_design
from fabricate.pipeline import run_build

#: template -> the only kinds of failure its laser build may have (none: it must pass)
LASER = {
    "finger_watt_six_bar": (),
    "gear_pair_elliptic": (),
    "jansen_leg": (),
    "linkage_quick_return": (),
    "linkage_stephenson": (),
    "gripper_compliant": ("strength:", "printability: spring_arbor_"),
}


@pytest.mark.slow
@pytest.mark.parametrize("template", sorted(LASER))
def test_laser_builds_have_no_collision(template):
    outcome = run_build(load_design(template, "laser"))
    assert outcome.design.process.retention == "clip" and outcome.partset is not None
    # every pin is clipped: it sticks out of both faces for its clip
    assert all(min(p.protrusion_mm) > 0.0 and p.end_items[0] and p.end_items[1] for p in outcome.partset.pins)
    collisions = [f for f in outcome.failures if f.startswith(("interference:", "clearance:"))]
    assert collisions == []
    allowed = LASER[template]
    assert [f for f in outcome.failures if not f.startswith(allowed or ("\0",))] == []
    assert outcome.exit_code == (1 if outcome.failures else 0)
    if not allowed:
        assert outcome.exit_code == 0, outcome.failures
