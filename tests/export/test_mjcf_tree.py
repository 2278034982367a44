"""The MJCF export's kinematic tree helpers (fabricate/export/mjcf_tree.py) without MuJoCo."""

from __future__ import annotations

import math

import numpy as np

from fabricate.export.mjcf_tree import _slide_coordinates
from fabricate.mechanism import Body, Driver, Mechanism, Revolute, Slider


def test_slide_coordinates_are_each_poses_product_along_the_turning_axis():
    """A slide's coordinate over the motion, taken from the points over the whole motion at once, is at every
    pose the product (p_b - p_a) . u, u the axis turned with body_a at that pose: the same floats as pose by
    pose. body_a (a slider-crank's crank) turns and the block slides, so the products differ."""
    r, length, th0 = 10.0, 35.0, math.radians(30.0)
    a = np.array([r * math.cos(th0), r * math.sin(th0)])
    x_b = a[0] + math.sqrt(length**2 - a[1] ** 2)
    mech = Mechanism(
        name="slider_crank",
        bodies=(Body("ground", {"O": (0.0, 0.0), "S": (0.0, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (r, 0.0), "S": (3.0, 1.0)}),
                Body("rod", {"A": (0.0, 0.0), "B": (length, 0.0)}),
                Body("slider", {"B": (0.0, 0.0), "S": (0.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "rod"), Revolute("B", "rod", "slider"),
                Slider("S", "ground", "slider", axis=(1.0, 0.0))),
        gears=(), drivers=(Driver("angle", "crank", "ground"),), input_range=(30.0, 330.0),
        assembly={"crank": (0, 0, th0), "rod": (a[0], a[1], math.atan2(-a[1], x_b - a[0])),
                  "slider": (x_b, 0.0, 0.0)})
    motion = mech.sweep(41)
    probe = Slider("S", "crank", "slider", axis=(0.6, 0.8))  # the block seen along an axis fixed in the crank
    got = _slide_coordinates(motion, probe)
    expected = []
    for i in range(len(motion.inputs)):
        theta = float(motion.pose("crank")[i, 2])
        ax, ay = 0.6 / math.hypot(0.6, 0.8), 0.8 / math.hypot(0.6, 0.8)
        u = np.array([math.cos(theta) * ax - math.sin(theta) * ay, math.sin(theta) * ax + math.cos(theta) * ay])
        expected.append(float((motion.point("S", "slider")[i] - motion.point("S", "crank")[i]) @ u))
    assert np.array_equal(got, np.array(expected))
    assert np.ptp(got) > 1.0  # the slide moves: a wrong pose row would not match
