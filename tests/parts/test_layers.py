"""Layer order with pins that stick out of their stacks (clip or cap retention) and a motor's short shaft."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fabricate.checks.interference import sweep_interference
from fabricate.parts.build import build_parts
from fabricate.parts.layers import order_layers, pin_neighbours
from fabricate.parts.retention import end_radius_mm, end_reach_mm, plan_pin
from fabricate.parts.spec import PartsSpec
from tests.parts.test_build import design_for

T, GAP = 3.0, 0.5  # sheet and layer gap of the laser fixture
PITCH = T + GAP


def _end_hits(layers, pin, body, reach):
    """Whether ``body``'s layer meets the room a pin on ``pin``'s bodies takes beyond its end faces."""
    lo, hi = min(layers[b] for b in pin), max(layers[b] for b in pin)
    z0, z1, zc = lo * PITCH, hi * PITCH + T, layers[body] * PITCH
    return (zc < z0 and zc + T > z0 - reach) or (zc >= z1 and zc < z1 + reach)


def test_a_body_over_a_pin_end_gets_a_layer_clear_of_it():
    """c passes over the pin of a and b (both its spacer and its clips): it may lie neither between a and b
    nor on the layer next to either end; three layers cannot do that, four (one empty) can."""
    layers = {"a": 0, "b": 1, "c": 2}
    reach = 1.75  # a DIN 6799 clip and its groove margin: past the 0.5 mm gap into the next sheet
    kwargs = dict(pins=[("a", "b")], end_crossings=[(0, "c")], end_reach=lambda stack: reach, thickness_mm=T,
                  gap_mm=GAP)
    # without a spare layer the fewest violations is one (the identity's, kept)
    assert order_layers(layers, [("a", "b", "c")], **kwargs) == layers
    assert _end_hits(layers, ("a", "b"), "c", reach)
    ordered = order_layers(layers, [("a", "b", "c")], spare_layers=2, **kwargs)
    lo, hi = sorted((ordered["a"], ordered["b"]))
    assert not lo < ordered["c"] < hi
    assert not _end_hits(ordered, ("a", "b"), "c", reach)
    assert max(ordered.values()) == 3 and len(set(ordered.values())) == 3  # one empty layer, no more
    # a pin that ends inside its stack (a press fit: no reach) keeps the plain order
    assert order_layers(layers, [("a", "b", "c")], spare_layers=2,
                        **{**kwargs, "end_reach": lambda stack: 0.0}) == order_layers(layers, [("a", "b", "c")])


def test_pin_ends_keep_off_a_neighbouring_pin():
    """Two pins that pass near each other: one's clip end may not reach into the other's stack."""
    layers = {"a": 0, "b": 1, "c": 2, "d": 3}
    pins = [("a", "b"), ("b", "c"), ("c", "d")]
    kwargs = dict(pins=pins, pin_pairs=[(0, 2)], end_reach=lambda stack: 1.75, thickness_mm=T, gap_mm=GAP)
    ordered = order_layers(layers, [], spare_layers=2, **kwargs)
    spans = [(min(ordered[x] for x in p) * PITCH - 1.75, max(ordered[x] for x in p) * PITCH + T + 1.75)
             for p in (pins[0], pins[2])]
    assert spans[0][1] <= spans[1][0] + 1e-9 or spans[1][1] <= spans[0][0] + 1e-9
    assert ordered != layers  # the identity has pin 0's top clip in the gap pin 2's bottom clip takes


def test_a_short_shaft_keeps_its_driven_part_outside():
    """A motor shaft reaching 1 mm into the stack: the driven body takes the bottom or the top layer."""
    layers = {"ground": 0, "driven": 1, "other": 2}
    ordered = order_layers(layers, [], outer=[("driven", 1.0)], thickness_mm=T, gap_mm=GAP)
    assert ordered["driven"] in (0, 2)
    assert sorted(ordered.values()) == [0, 1, 2]
    # deep enough for one layer: the colouring stays
    assert order_layers(layers, [], outer=[("driven", PITCH)], thickness_mm=T, gap_mm=GAP) == layers


def test_pin_neighbours_over_the_motion():
    k = 20
    still = np.zeros((k, 3))
    turning = np.column_stack([np.zeros(k), np.zeros(k), np.linspace(0.0, np.pi, k)])
    poses = {"g": still, "r": turning}
    pins = [(np.array([10.0, 0.0]), "g"), (np.array([10.0, 0.0]), "r"), (np.array([0.0, 30.0]), "g")]
    # the pin on r starts on the first and swings half a turn away; the third stays 30 mm off
    assert pin_neighbours(pins, poses, 5.0) == [(0, 1)]
    assert pin_neighbours(pins, poses, 40.0) == [(0, 1), (0, 2), (1, 2)]


def test_end_reach_is_the_planned_pins(laser_process):
    for stack in (6.5, 10.0, 13.5):
        plan = plan_pin("j", laser_process, (0.0, stack))
        assert end_reach_mm(laser_process, stack) == pytest.approx(max(e.protrusion_mm for e in plan.ends))
        assert end_reach_mm(laser_process, stack) > laser_process.layer_gap_mm  # into the next sheet
    assert end_radius_mm(laser_process) >= 0.5 * plan.ends[0].retainer.ring_od_mm
    # a press fit: the bare stub of the shortest standard pin over the stack (Ø3: 8 mm on 6.5, 14 on 13.5)
    press = dataclasses.replace(laser_process, retention="press", press_fit_interference_mm=0.05)
    assert end_reach_mm(press, 6.5) == pytest.approx(1.5) and end_reach_mm(press, 13.5) == pytest.approx(0.5)
    assert end_radius_mm(press) == 1.5


def test_a_pressed_pin_stub_takes_room_at_one_end_only():
    """A pressed pin's stub sticks out of the top of its stack unless only its bottom is the outermost layer
    (retention.press_stub_at_bottom): c over the pin of a and b must keep off that end only."""
    layers = {"a": 1, "b": 2, "c": 0, "d": 3}
    kwargs = dict(pins=[("a", "b")], end_crossings=[(0, "c")], end_reach=lambda stack: 1.7, thickness_mm=T,
                  gap_mm=GAP)
    # both ends inside: the stub is at the top, c at the bottom is clear of it (both-end room would not be)
    assert order_layers(layers, [], one_end=True, **kwargs) == layers
    assert _end_hits(layers, ("a", "b"), "c", 1.7)
    # c above the pin: the stub's end, so c moves off it
    above = {"a": 1, "b": 2, "c": 3, "d": 0}
    ordered = order_layers(above, [], one_end=True, **kwargs)
    lo, hi = sorted((ordered["a"], ordered["b"]))
    stub_at_bottom = lo == 0 and hi != max(ordered.values())
    assert ordered != above and not (ordered["c"] == (lo - 1 if stub_at_bottom else hi + 1))


def test_a_stack_no_standard_pin_covers_is_a_violation():
    """Three bodies c, a, b on one pin (c in the middle): a stack over the longest standard pin (infinite reach)
    is avoided where an order keeps it within the series."""
    layers = {"a": 0, "b": 2, "c": 1, "d": 3}
    reach = {1: 0.0, 2: 0.0, 3: np.inf, 4: np.inf}  # by the number of layers the stack spans
    kwargs = dict(pins=[("a", "b"), ("c", "d")], pin_pairs=[(0, 1)], thickness_mm=T, gap_mm=GAP,
                  end_reach=lambda stack: reach[round((stack - T) / PITCH) + 1])
    ordered = order_layers(layers, [], **kwargs)
    for pin in (("a", "b"), ("c", "d")):
        assert abs(ordered[pin[0]] - ordered[pin[1]]) <= 1  # two layers each, within the series
    assert ordered != layers


def test_clip_pins_of_a_crank_rocker_hit_no_part(four_bar, laser_process):
    """The four-bar's coupler passes over the crank's ground pin and the ground under the others: with clips
    sticking out of every stack, the layers leave their ends room and the proof finds no collision."""
    motion = four_bar.sweep(61)
    partset = build_parts(design_for(laser_process, PartsSpec()), four_bar, motion, [])
    assert all(p.protrusion_mm[0] > GAP and p.protrusion_mm[1] > GAP for p in partset.pins)
    sweep = sweep_interference(list(partset.parts), motion, chord_tolerance_mm=laser_process.chord_tolerance_mm,
                               min_clearance_mm=laser_process.running_clearance_mm, pins=partset.pins,
                               spacers=partset.spacers)
    assert not sweep.collisions, [(p.a, p.b) for p in sweep.collisions]


def test_the_motor_meets_only_the_pin_ends_within_its_reach():
    """A motor's short shaft reaches one layer deep (depth = one pitch) to its driven part in the middle layer. A
    pin with clip ends over the whole stack sticks out of both faces: where it is within the motor's reach
    (near_motor) the driven part must move to a face (the motor then clears it from outside); a pin out of its
    reach leaves the colouring as it is. Without near_motor every pin end counts (the largest reach)."""
    layers = {"g": 0, "driven": 1, "x": 2}
    kwargs = dict(pins=[("g", "x")], end_reach=lambda stack: 1.75, thickness_mm=T, gap_mm=GAP,
                  outer=[("driven", PITCH)])
    assert order_layers(layers, [], near_motor=[], **kwargs) == layers
    for near in ([0], None):
        ordered = order_layers(layers, [], near_motor=near, **kwargs)
        assert ordered["driven"] in (min(ordered.values()), max(ordered.values())), near
    # one layer too deep even without a pin end: out of the shaft's reach, always moved
    assert order_layers(layers, [], near_motor=[], **{**kwargs, "outer": [("driven", 1.0)]})["driven"] != 1


def test_a_shared_layer_is_split_where_no_order_of_the_layers_works():
    """a and d share a layer; c may not lie between a and b, b not between d and c, a not between b and c: each
    of the three orders of the three layers breaks one. Giving d a layer of its own (a, b, c, d) breaks none."""
    layers = {"a": 0, "d": 0, "b": 1, "c": 2}
    crossings = [("a", "b", "c"), ("d", "c", "b"), ("b", "c", "a")]

    def broken(order):
        return [(p, q, r) for p, q, r in crossings
                if min(order[p], order[q]) < order[r] < max(order[p], order[q])]

    plain = order_layers(layers, crossings)
    assert plain["a"] == plain["d"] and len(broken(plain)) == 1
    split = order_layers(layers, crossings, split=True)
    assert split["a"] != split["d"] and broken(split) == []
    assert sorted(split.values()) == [0, 1, 2, 3]
