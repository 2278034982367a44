"""Properties of the planar solver a user depends on, against closed forms written here.

These tests were written to kill mutants of ``fabricate/mechanism.py`` (see
``tests/benchmarks/mutation_report.md``): a sweep through a change point must be reported, not
followed silently onto the other assembly branch.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fabricate.errors import LockupError
from fabricate.mechanism import Body, Driver, Mechanism, Revolute


def parallelogram(start_deg: float, end_deg: float, crank: float = 20.0, ground: float = 40.0) -> Mechanism:
    """A parallelogram four-bar O-A-B-D (crank = rocker, coupler = ground), assembled as a parallelogram.

    Closed form: on the parallelogram branch the rocker stays parallel to the crank (phi = theta) and the
    coupler keeps angle 0. At theta = 0 and pi every link is collinear: a change point, where the
    anti-parallelogram branch crosses this one and the constraint Jacobian is singular
    (d/dphi |B - A|^2 = -2 * ground * crank * sin(theta) changes sign).
    """
    th = math.radians(start_deg)
    return Mechanism(
        name="parallelogram",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (ground, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (crank, 0.0)}),
                Body("coupler", {"A": (0.0, 0.0), "B": (ground, 0.0)}),
                Body("rocker", {"D": (0.0, 0.0), "B": (crank, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker")),
        gears=(),
        drivers=(Driver("angle", "crank", "ground"),),
        input_range=(start_deg, end_deg),
        assembly={"crank": (0.0, 0.0, th),
                  "coupler": (crank * math.cos(th), crank * math.sin(th), 0.0),
                  "rocker": (ground, 0.0, th)},
    )


def test_parallelogram_away_from_change_points_follows_closed_form():
    """Control: between the change points the sweep is fine and phi = theta exactly."""
    motion = parallelogram(20.0, 160.0).sweep(57)
    theta = np.radians(motion.inputs)
    np.testing.assert_allclose(motion.pose("rocker")[:, 2], theta, atol=1e-9)
    np.testing.assert_allclose(motion.pose("coupler")[:, 2], 0.0, atol=1e-9)


@pytest.mark.parametrize(("start", "end"), [(60.0, 300.0), (-120.0, 120.0), (300.0, 60.0)])
def test_sweep_through_change_point_is_reported(start, end):
    """A linkage driven through a change point (all links collinear) must raise a branch-change error
    at that input, not flip to the anti-parallelogram silently or stop with a plain lock-up."""
    mech = parallelogram(start, end)
    with pytest.raises(LockupError, match="branch change") as info:
        mech.sweep(25)
    change_points = np.array([-180.0, 0.0, 180.0, 360.0])
    # the error names an input near the first change point on the way (within one sweep step)
    first = change_points[(change_points - start) * np.sign(end - start) > 0]
    first = first[np.argmin(np.abs(first - start))]
    assert abs(info.value.input_value - first) <= abs(end - start) / 24 + 1e-6  # input in degrees
