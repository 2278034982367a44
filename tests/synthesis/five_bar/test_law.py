"""The five-bar's gear law (synthesis/five_bar/law.py): its spline evaluated once per derivative.

gear_law hands the pitch functions a wrapper that evaluates each derivative of the spline at the dense samples
once; the curves must be exactly those of the spline itself.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from fabricate.gears.pitch import pitch_frames, pitch_radii
from fabricate.synthesis.five_bar.law import LAW_SAMPLES, gear_law


def test_gear_law_curves_are_those_of_the_plain_spline():
    """Ratio, pitch radii and radii of curvature of gear_law equal (bitwise, NaN in the same places) the
    pitch functions called on the CubicSpline itself, for laws given in either knot order."""
    rng = np.random.default_rng(5)
    for trial in range(20):
        n = int(rng.integers(3, 8))
        knots_a = np.cumsum(rng.uniform(0.05, 0.5, n))
        knots_b = -np.cumsum(rng.uniform(0.05, 0.8, n))
        if trial % 2:
            knots_a, knots_b = knots_a[::-1].copy(), knots_b[::-1].copy()
        a = float(rng.uniform(5.0, 40.0))
        law = gear_law(knots_a, knots_b, a)
        order = np.argsort(knots_a)
        spline = CubicSpline(knots_a[order], knots_b[order])
        x = np.linspace(knots_a[order[0]], knots_a[order[-1]], LAW_SAMPLES)
        with np.errstate(divide="ignore", invalid="ignore"):
            want = {"ratio": -spline(x, 1), "r_a": pitch_radii(spline, a, x, "a")[0],
                    "r_b": pitch_radii(spline, a, x, "b")[0], "rho_a": 1.0 / pitch_frames(spline, a, x, "a").curvature,
                    "rho_b": 1.0 / pitch_frames(spline, a, x, "b").curvature}
        assert np.array_equal(law.x, x)
        for name, values in want.items():
            assert np.array_equal(getattr(law, name), values, equal_nan=True), name
        # the law kept is the spline itself (not the wrapper): it interpolates the knots at any x
        assert isinstance(law.law, CubicSpline)
        assert np.allclose(law.law(knots_a), knots_b, rtol=0.0, atol=1e-12)
