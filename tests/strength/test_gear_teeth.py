"""The Hertz contact of a cut gear pair (fabricate.strength.features.tooth_stresses on the models of
fabricate/strength/gear_teeth.py) against Shigley's pitch-point formula, written out here: on fixed pitch circles it
depends on the pressure angle and the face width, never on the module."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fabricate.gears import make_gear_pair
from fabricate.gears.spec import parse_gear_spec
from fabricate.process import Material
from fabricate.strength.features import tooth_stresses
from fabricate.table import Table
from tests.gears.test_pair import closed_mechanism

#: A PLA-like material (only E and nu enter the contact).
RESIN = Material("pla", "PLA", 48.0, 48.0, 48.0, 28.0, 2300.0, 0.36, 1.24)


def contact_stress(module: float, degrees: float, torque_b: float, face: float) -> float:
    """The largest Hertz pressure fabricate finds on the closed 2:1 pair of pitch circles r_a 5, r_b 10 mm."""
    (coupling,) = closed_mechanism().gears
    spec = parse_gear_spec(Table({"module_mm": module, "pressure_angle_deg": degrees, "compare_methods": False},
                                 "gears"))
    pair = make_gear_pair(coupling.law, 15.0, coupling.working_range, spec, closed=True, run_mesh_check=False,
                          body_a="gear_a", body_b="gear_b")
    x_a = np.linspace(0.0, 2.0, 9)
    motion = SimpleNamespace(relative_angle=lambda body, carrier: x_a if body == "gear_a" else -0.5 * x_a)
    stresses = tooth_stresses(pair, np.full(len(x_a), torque_b), motion, face, RESIN)
    return float(np.max(stresses.hertz_MPa))


@pytest.mark.parametrize("module", [0.5, 1.0])
@pytest.mark.parametrize("degrees", [20.0, 22.5, 25.0])
def test_pair_contact_is_shigleys_pitch_point_stress_at_any_module(module, degrees):
    """sigma_C = sqrt(W_t / cos(phi) (1/rho_1 + 1/rho_2) / (pi b (2 (1 - nu^2) / E))), rho_i = r_i sin(phi)
    (Shigley Eq. 14-14 with both gears of one material), W_t = T_b / r_b."""
    torque, face = 200.0, 6.0
    phi = math.radians(degrees)
    r_a, r_b = 5.0, 10.0
    normal = torque / r_b / math.cos(phi)
    curvature = 1.0 / (r_a * math.sin(phi)) + 1.0 / (r_b * math.sin(phi))
    compliance = 2.0 * (1.0 - RESIN.poisson ** 2) / RESIN.modulus_MPa
    expected = math.sqrt(normal * curvature / (math.pi * face * compliance))
    assert contact_stress(module, degrees, torque, face) == pytest.approx(expected, rel=1e-6)


def test_contact_falls_with_the_pressure_angle_and_the_face_width_not_the_module():
    """sigma_C^2 ~ 1 / (b sin 2 phi): 25 deg relieves 20 deg's contact by sqrt(sin 40 / sin 50); twice the face by
    sqrt(2); half the module not at all."""
    base = contact_stress(1.0, 20.0, 200.0, 3.0)
    assert contact_stress(0.5, 20.0, 200.0, 3.0) == pytest.approx(base, rel=1e-9)
    assert contact_stress(1.0, 25.0, 200.0, 3.0) / base == pytest.approx(
        math.sqrt(math.sin(math.radians(40.0)) / math.sin(math.radians(50.0))), rel=1e-9)
    assert contact_stress(1.0, 20.0, 200.0, 6.0) / base == pytest.approx(1.0 / math.sqrt(2.0), rel=1e-9)
