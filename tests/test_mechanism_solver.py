"""The pose solver's core (Newton, first-pose assembly, continuation, step guard) against closed forms.

Every expected value here is written independently of fabricate.mechanism: circle intersections by hand,
slider/crank geometry, angle laws. Tolerances are stated per test.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from fabricate.errors import LockupError, SpecError
from fabricate.mechanism import Body, Driver, GearCoupling, LinearLaw, Mechanism, Revolute, Slider
from tests.conftest import make_four_bar


def _meet(c1, r1, c2, r2, left=True):
    """Intersection of circle (c1, r1) and circle (c2, r2) on the left (or right) of c1 -> c2."""
    c1, c2 = np.asarray(c1, dtype=float), np.asarray(c2, dtype=float)
    dx, dy = c2 - c1
    d = math.hypot(dx, dy)
    a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    h = math.sqrt(r1 * r1 - a * a)
    ex, ey = dx / d, dy / d
    sign = 1.0 if left else -1.0
    return np.array([c1[0] + a * ex - sign * h * ey, c1[1] + a * ey + sign * h * ex])


def _four_bar_b(crank, coupler, rocker, ground, theta_deg, left=True):
    """Coupler-rocker joint B of the four-bar O-A-B-D (ground O-D on +x) at crank angle theta_deg."""
    th = math.radians(theta_deg)
    a = (crank * math.cos(th), crank * math.sin(th))
    return _meet(a, coupler, (ground, 0.0), rocker, left)


def _scaled_four_bar(k: float) -> Mechanism:
    """conftest's crank-rocker (15, 40, 30, 40) with every length multiplied by ``k``."""
    return make_four_bar(crank=15.0 * k, coupler=40.0 * k, rocker=30.0 * k, ground=40.0 * k)


# -- redundant (over-constrained) mechanisms: the non-square Jacobian path -------------------------------------

def _double_parallelogram(start_deg: float = 20.0, end_deg: float = 160.0) -> Mechanism:
    """Parallelogram four-bar O-A-B-D (crank = rocker = 15, coupler = ground = 40) with a third parallel
    link E-C (E at x = 20 on the ground, C at x = 20 on the coupler): 6 revolutes + 1 driver = 13 equations
    in 12 unknowns, consistent (Gruebler mobility 0 before the driver, yet it moves)."""
    r, g = 15.0, 40.0
    th = math.radians(start_deg)
    ax, ay = r * math.cos(th), r * math.sin(th)
    return Mechanism(
        name="double_parallelogram",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (g, 0.0), "E": (20.0, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (r, 0.0)}),
                Body("coupler", {"A": (0.0, 0.0), "B": (g, 0.0), "C": (20.0, 0.0)}),
                Body("rocker", {"D": (0.0, 0.0), "B": (r, 0.0)}),
                Body("link", {"E": (0.0, 0.0), "C": (r, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker"),
                Revolute("E", "ground", "link"), Revolute("C", "coupler", "link")),
        gears=(), drivers=(Driver("angle", "crank", "ground"),),
        input_range=(start_deg, end_deg),
        # a rough guess: Newton (least squares here) must pull it onto the parallelogram
        assembly={"crank": (0.0, 0.0, th + 0.05), "coupler": (ax + 0.3, ay - 0.2, 0.04),
                  "rocker": (g, 0.0, th - 0.05), "link": (20.0, 0.0, th + 0.03)},
    )


def test_redundant_parallelogram_follows_closed_form():
    """An over-constrained (13 x 12) but consistent double parallelogram assembles from a rough guess and
    sweeps 20 -> 160 deg (short of the folded, singular pose at 180): the coupler stays parallel to the ground
    and A = 15 (cos s, sin s), within 1e-9."""
    mech = _double_parallelogram()
    motion = mech.sweep(np.linspace(20.0, 160.0, 15))  # 10 degree input steps
    th = np.radians(motion.inputs)
    a = np.column_stack([15.0 * np.cos(th), 15.0 * np.sin(th)])
    assert np.max(np.abs(motion.pose("coupler")[:, 2])) < 1e-9
    assert np.max(np.hypot(*(motion.point("A", "coupler") - a).T)) < 1e-9
    assert np.max(np.hypot(*(motion.point("C", "coupler") - a - [20.0, 0.0]).T)) < 1e-9
    assert np.max(np.abs(motion.pose("link")[:, 2] - th)) < 1e-9
    assert np.max(np.abs(motion.pose("rocker")[:, 2] - th)) < 1e-9


def test_redundant_parallelogram_sweeps_backwards():
    """The least-squares continuation also runs with a decreasing input (160 -> 20 deg, 20 deg steps)."""
    mech = _double_parallelogram(start_deg=160.0, end_deg=20.0)
    motion = mech.sweep(np.linspace(160.0, 20.0, 8))
    th = np.radians(motion.inputs)
    assert np.max(np.abs(motion.pose("rocker")[:, 2] - th)) < 1e-9
    assert np.max(np.abs(motion.pose("coupler")[:, 2])) < 1e-9


def _parallel_links_with_roller(start_deg: float, end_deg: float) -> Mechanism:
    """The parallelogram four-bar of :func:`_double_parallelogram` with two parallel links (E0-C0 at x = 10, E1-C1
    at x = 25) and an idle roller pinned at its centre to the ground's R = (20, -10), which no equation turns:
    9 revolutes (18 rows) + 1 driver = 19 equations in 18 unknowns (6 bodies). The count passes (the two
    redundant links make up for the roller's free turn) but the Jacobian has rank 17 (15 for the linkage, 2 for
    the roller's pin): over-determined and rank-deficient at once."""
    r, g = 15.0, 40.0
    th = math.radians(start_deg)
    ax, ay = r * math.cos(th), r * math.sin(th)
    ground = {"O": (0.0, 0.0), "D": (g, 0.0), "R": (20.0, -10.0)}
    coupler = {"A": (0.0, 0.0), "B": (g, 0.0)}
    links, joints = [], [Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                         Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker"),
                         Revolute("R", "ground", "roller")]
    assembly = {"crank": (0.0, 0.0, th + 0.05), "coupler": (ax + 0.3, ay - 0.2, 0.04), "rocker": (g, 0.0, th - 0.05),
                "roller": (20.0, -10.0, 0.7)}
    for k, x in enumerate((10.0, 25.0)):
        ground[f"E{k}"], coupler[f"C{k}"] = (x, 0.0), (x, 0.0)
        links.append(Body(f"link{k}", {f"E{k}": (0.0, 0.0), f"C{k}": (r, 0.0)}))
        joints += [Revolute(f"E{k}", "ground", f"link{k}"), Revolute(f"C{k}", "coupler", f"link{k}")]
        assembly[f"link{k}"] = (x, 0.0, th + 0.03)
    return Mechanism(
        name="parallel_links_with_roller",
        bodies=(Body("ground", ground), Body("crank", {"O": (0.0, 0.0), "A": (r, 0.0)}), Body("coupler", coupler),
                Body("rocker", {"D": (0.0, 0.0), "B": (r, 0.0)}), *links, Body("roller", {"R": (0.0, 0.0)})),
        ground="ground", joints=tuple(joints), gears=(), drivers=(Driver("angle", "crank", "ground"),),
        input_range=(start_deg, end_deg), assembly=assembly)


def test_redundant_and_rank_deficient_system_sweeps():
    """A parallelogram with two extra parallel links and an idle roller (19 x 18 Jacobian of rank 17) assembles
    and sweeps 20 -> 160 deg in 20 degree steps: the linkage follows the closed form (coupler parallel to the
    ground, rocker and links at the crank angle, within 1e-9) and the roller stays on its pin at (20, -10)
    (1e-12). No equation sees the roller's angle and the least-squares steps are minimum-norm, so it keeps its
    assembly angle 0.7 rad (1e-12)."""
    mech = _parallel_links_with_roller(20.0, 160.0)
    motion = mech.sweep(np.linspace(20.0, 160.0, 8))
    th = np.radians(motion.inputs)
    assert np.max(np.abs(motion.pose("coupler")[:, 2])) < 1e-9
    for body in ("rocker", "link0", "link1"):
        assert np.max(np.abs(motion.pose(body)[:, 2] - th)) < 1e-9, body
    a = np.column_stack([15.0 * np.cos(th), 15.0 * np.sin(th)])
    assert np.max(np.hypot(*(motion.point("A", "coupler") - a).T)) < 1e-9
    assert np.max(np.abs(motion.pose("roller") - [20.0, -10.0, 0.7])) < 1e-12


class _Cubic:
    """law(x) = x**3 - 3 x with its derivatives: increasing for |x| > 1, a fold (law' = 0) at x = +-1."""

    def __call__(self, x, nu: int = 0):
        x = np.asarray(x, dtype=np.float64)
        if nu == 0:
            return x ** 3 - 3.0 * x
        return 3.0 * x * x - 3.0 if nu == 1 else 6.0 * x


def _twin_cubic_train(x0: float) -> Mechanism:
    """A wheel pinned at O coupled to a driven disc at P by two identical couplings (twin gear trains side by
    side), theta_disc = law(theta_wheel) with law(x) = x**3 - 3 x; the disc's angle is the input (rad,
    input unit mm). 2 revolutes + 2 couplings + 1 driver = 7 equations in 6 unknowns (one redundant): the
    least-squares path. Assembled with the wheel at x0 on the branch x > 1."""
    law = _Cubic()
    return Mechanism(
        name="twin_cubic",
        bodies=(Body("ground", {"O": (0.0, 0.0), "P": (10.0, 0.0)}), Body("wheel", {"O": (0.0, 0.0)}),
                Body("disc", {"P": (0.0, 0.0)})),
        ground="ground", joints=(Revolute("O", "ground", "wheel"), Revolute("P", "ground", "disc")),
        gears=(GearCoupling("left", "ground", "wheel", "disc", law),
               GearCoupling("right", "ground", "wheel", "disc", law)),
        drivers=(Driver("angle", "disc", "ground"),), input_range=(float(law(x0)), 1.0), input_unit="mm",
        assembly={"wheel": (0.0, 0.0, x0), "disc": (10.0, 0.0, float(law(x0)))})


@pytest.mark.parametrize("x0", [1.04, 1.05, 1.06, 1.07, 1.08])
def test_redundant_continuation_moves_away_from_a_fold(x0):
    """Twin cubic couplings, the wheel assembled just past the fold (x0 = 1.04 .. 1.08), the input raised in one
    step to s1 = law(1.5) = -1.125. On the branch x > 1 the law increases, so the wheel turns on to the largest
    root of x**3 - 3 x - s1 = (x - 1.5) (x**2 + 1.5 x - 0.75), x = 1.5 (1e-9 rad), not to the middle one,
    (sqrt(5.25) - 1.5) / 2 = 0.396. At the start the middle branch is only 0.08 .. 0.16 rad away, across the
    fold, inside the 0.3 rad step guard: the predictor must lead away from the fold, along the tangent
    d x / d s = 1 / law'(x) > 0, or the continuation slips onto that branch (the least-squares path has no
    orientation check to notice)."""
    law = _Cubic()
    s1 = float(law(1.5))
    assert s1 == -1.125
    motion = _twin_cubic_train(x0).sweep(np.array([float(law(x0)), s1]))
    assert motion.pose("wheel")[1, 2] == pytest.approx(1.5, abs=1e-9)
    assert motion.pose("disc")[1, 2] == pytest.approx(s1, abs=1e-12)


def pinned_twice(offset: float, input_range: tuple[float, float]) -> Mechanism:
    """A crank pinned to the ground at O and at P (0.8 mm apart): locked; its angle is driven by
    theta = s + offset over ``input_range``."""
    return Mechanism(
        name="pinned_twice",
        bodies=(Body("ground", {"O": (0.0, 0.0), "P": (0.8, 0.0)}), Body("crank", {"O": (0.0, 0.0), "P": (0.8, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("P", "ground", "crank")),
        gears=(), drivers=(Driver("angle", "crank", "ground", law=LinearLaw(1.0, offset)),),
        input_range=input_range, input_unit="mm", assembly={"crank": (0.0, 0.0, 0.0)})


def test_inconsistent_redundant_constraints_lock_up_at_the_start():
    """A crank pinned to the ground at two points cannot turn: driving it gives a LockupError carrying
    the first input (least squares leaves a residual of the order of the step, far above tolerance)."""
    mech = pinned_twice(-5.0, (5.0, 6.0))
    with pytest.raises(LockupError) as info:
        mech.sweep(np.array([5.0, 6.0]))
    assert info.value.input_value == 5.0


def test_locked_input_span_below_a_micro_unit_still_reports_lockup():
    """The smallest step is relative to the span plus an absolute 1e-12: a span of 1e-6 input units on a
    locked mechanism still ends in a LockupError at its start (not an endless crawl)."""
    mech = pinned_twice(-2.0, (2.0, 2.000001))
    with pytest.raises(LockupError) as info:
        mech.sweep(np.array([2.0, 2.000001]))
    assert info.value.input_value == 2.0


# -- scale ------------------------------------------------------------------------------------------------------

def test_metre_scale_four_bar_solves_to_scaled_tolerance():
    """A four-bar 1000 x larger (links of 15-40 m, in mm) sweeps and closes its loop: B matches the circle
    intersection to 1e-8 relative to the size (the residual tolerance grows with the mechanism)."""
    k = 1000.0
    mech = _scaled_four_bar(k)
    motion = mech.sweep(np.linspace(60.0, 420.0, 37))
    b = motion.point("B", "rocker")
    expected = np.array([_four_bar_b(15 * k, 40 * k, 30 * k, 40 * k, s) for s in motion.inputs])
    assert np.max(np.hypot(*(b - expected).T)) < 1e-8 * 40.0 * k
    assert np.max(np.abs(np.hypot(*(motion.point("B", "coupler") - motion.point("A")).T) - 40.0 * k)) < 1e-8 * k


# -- direction and repeated inputs --------------------------------------------------------------------------------

def test_four_bar_swept_downwards_matches_closed_form():
    """Continuation with a decreasing input (420 -> 60 deg in 30 deg steps) stays on the upper branch."""
    mech = make_four_bar(start_deg=420.0, end_deg=60.0)
    motion = mech.sweep(np.linspace(420.0, 60.0, 13))
    expected = np.array([_four_bar_b(15, 40, 30, 40, s) for s in motion.inputs])
    assert np.max(np.hypot(*(motion.point("B", "rocker") - expected).T)) < 1e-9
    assert np.allclose(motion.pose("crank")[:, 2], np.radians(motion.inputs), atol=1e-12)


def test_sweep_through_zero_input_both_ways():
    """Inputs symmetric about zero (-40 -> 40 -> -40 deg) are followed like any other."""
    mech = make_four_bar(start_deg=-40.0, end_deg=40.0)
    inputs = np.array([-40.0, 40.0, -40.0])
    motion = mech.sweep(inputs)
    expected = np.array([_four_bar_b(15, 40, 30, 40, s) for s in inputs])
    assert np.max(np.hypot(*(motion.point("B", "rocker") - expected).T)) < 1e-9


def test_repeated_input_keeps_the_pose():
    """Equal consecutive inputs give the same pose (a zero-length continuation)."""
    mech = make_four_bar()
    motion = mech.sweep(np.array([60.0, 100.0, 100.0, 100.0, 90.0]))
    q = motion.q
    assert np.array_equal(q[1], q[2]) and np.array_equal(q[2], q[3])
    expected = _four_bar_b(15, 40, 30, 40, 90.0)
    assert np.hypot(*(motion.point("B", "rocker")[4] - expected)) < 1e-9


def test_steep_law_far_from_zero_input():
    """The smallest allowed step depends on the span of the inputs, not on their magnitude: a crank turned
    by 20 rad per input unit around s = 10000 follows theta = 20 (s - 10000) over s in [10000, 10000.1]
    (2 rad, so about ten guarded steps of 0.01 input units)."""
    law = LinearLaw(20.0, -200000.0)
    mech = Mechanism(
        name="steep", bodies=(Body("ground", {"O": (0.0, 0.0)}), Body("crank", {"O": (0.0, 0.0), "A": (10.0, 0.0)})),
        ground="ground", joints=(Revolute("O", "ground", "crank"),), gears=(),
        drivers=(Driver("angle", "crank", "ground", law=law),), input_range=(10000.0, 10000.1), input_unit="mm",
        assembly={"crank": (0.0, 0.0, 0.0)})
    motion = mech.sweep(np.array([10000.0, 10000.1]))
    assert motion.pose("crank")[1, 2] == pytest.approx(20.0 * (10000.1 - 10000.0), abs=1e-9)


# -- assembly errors ------------------------------------------------------------------------------------------------

def test_missing_assembly_guess_is_named():
    """A free body without an assembly guess is a SpecError at mechanism.assembly.<body>."""
    base = make_four_bar()
    assembly = dict(base.assembly)
    del assembly["rocker"]
    mech = Mechanism(name="no_guess", bodies=base.bodies, ground=base.ground, joints=base.joints, gears=(),
                     drivers=base.drivers, input_range=base.input_range, assembly=assembly)
    with pytest.raises(SpecError) as err:
        mech.sweep(3)
    assert err.value.path == "mechanism.assembly.rocker"
    assert err.value.message == "missing assembly guess for body"


def test_unassemblable_first_pose_reports_its_input():
    """A non-Grashof four-bar whose crank starts beyond its limit (|A - D| > coupler + rocker at 150 deg)
    cannot assemble: LockupError with the first input (150) as input_value."""
    base = make_four_bar(crank=25.0, coupler=30.0, rocker=20.0, ground=40.0, start_deg=0.0, end_deg=180.0)
    assert math.hypot(25 * math.cos(math.radians(150)) - 40, 25 * math.sin(math.radians(150))) > 50.0
    mech = Mechanism(name="stuck", bodies=base.bodies, ground=base.ground, joints=base.joints, gears=(),
                     drivers=base.drivers, input_range=(150.0, 180.0), assembly=base.assembly)
    with pytest.raises(LockupError) as info:
        mech.sweep(np.array([150.0, 180.0]))
    assert info.value.input_value == 150.0
    assert "stuck: cannot assemble the first pose" in info.value.message


def test_exact_rationals_are_accepted_as_guesses_and_axes():
    """Assembly guesses and slider axes given as fractions.Fraction are read as floats: a slide-driven
    block on the axis (3/5, 4/5) sits at s * (0.6, 0.8), within 1e-12."""
    axis = (Fraction(3, 5), Fraction(4, 5))
    mech = Mechanism(
        name="rational",
        bodies=(Body("ground", {"S": (0.0, 0.0)}), Body("block", {"S": (0.0, 0.0)})),
        ground="ground", joints=(Slider("S", "ground", "block", axis=axis),), gears=(),
        drivers=(Driver("slide", "block", "ground", joint="S"),), input_range=(0.0, 10.0), input_unit="mm",
        assembly={"block": (Fraction(1, 10), Fraction(-1, 10), Fraction(1, 50))})
    motion = mech.sweep(np.array([0.0, 4.0, 10.0]))
    expected = np.outer(motion.inputs, [0.6, 0.8])
    assert np.max(np.abs(motion.point("S", "block") - expected)) < 1e-12
    assert np.max(np.abs(motion.pose("block")[:, 2])) < 1e-12


# -- drivers measured from a moving body ----------------------------------------------------------------------------

def _four_bar_driven_at_a(psi0_deg: float, psi1_deg: float) -> Mechanism:
    """Crank-rocker (15, 40, 30, 40) driven by the coupler's angle relative to the crank, psi (deg)."""
    psi = math.radians(psi0_deg)
    th, b = _driven_at_a_closed_form(psi)
    a = np.array([15.0 * math.cos(th), 15.0 * math.sin(th)])
    return Mechanism(
        name="driven_at_a",
        bodies=(Body("ground", {"O": (0.0, 0.0), "D": (40.0, 0.0)}),
                Body("crank", {"O": (0.0, 0.0), "A": (15.0, 0.0)}),
                Body("coupler", {"A": (0.0, 0.0), "B": (40.0, 0.0)}),
                Body("rocker", {"D": (0.0, 0.0), "B": (30.0, 0.0)})),
        ground="ground",
        joints=(Revolute("O", "ground", "crank"), Revolute("A", "crank", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker")),
        gears=(), drivers=(Driver("angle", "coupler", "crank"),), input_range=(psi0_deg, psi1_deg),
        assembly={"crank": (0.0, 0.0, th + 0.02), "coupler": (a[0], a[1], th + psi - 0.02),
                  "rocker": (40.0, 0.0, math.atan2(b[1], b[0] - 40.0) + 0.02)})


def _driven_at_a_closed_form(psi: float) -> tuple[float, np.ndarray]:
    """Crank angle and B for relative angle psi: B = R(theta) (15 + 40 cos psi, 40 sin psi), so |OB| is
    fixed by psi and B is where the circle |OB| meets the rocker circle about D (upper intersection)."""
    local = np.array([15.0 + 40.0 * math.cos(psi), 40.0 * math.sin(psi)])
    b = _meet((0.0, 0.0), float(np.hypot(*local)), (40.0, 0.0), 30.0, left=True)
    theta = math.atan2(b[1], b[0]) - math.atan2(local[1], local[0])
    return theta, b


def test_angle_driver_relative_to_a_moving_body():
    """A driver measured from a moving reference (coupler relative to crank) follows the closed form:
    theta_coupler - theta_crank = psi exactly (1e-12) and B, the crank angle as derived by hand (1e-9)."""
    mech = _four_bar_driven_at_a(-60.0, -120.0)
    motion = mech.sweep(np.linspace(-60.0, -120.0, 7))
    psi = np.radians(motion.inputs)
    assert np.max(np.abs(motion.relative_angle("coupler", "crank") - psi)) < 1e-12
    for i, p in enumerate(psi):
        theta, b = _driven_at_a_closed_form(float(p))
        assert math.remainder(motion.pose("crank")[i, 2] - theta, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
        assert np.hypot(*(motion.point("B", "rocker")[i] - b)) < 1e-9


# -- degenerate sizes -------------------------------------------------------------------------------------------

def test_ground_only_mechanism_has_an_empty_motion():
    """A mechanism of its ground alone (no unknowns, no equations) sweeps to zero free bodies."""
    mech = Mechanism(name="frame", bodies=(Body("ground", {"O": (0.0, 0.0)}),), ground="ground", joints=(),
                     gears=(), drivers=(), input_range=(0.0, 1.0))
    motion = mech.sweep(4)
    assert motion.q.shape == (4, 0, 3)
    assert np.array_equal(motion.pose("ground"), np.zeros((4, 3)))


# -- Newton's acceptance test and iteration budget, on a constraint with a double root ------------------------------
#
# A disc pinned to the ground whose "gear" law to the ground is a * x**2: the constraint 0 = a * theta**2 has a
# double root at 0, so Newton halves theta each iteration (exactly, in floating point, for powers of two) and the
# residual a * theta_k**2 = a * theta_0**2 / 4**k falls by four per iteration: the iteration where it first drops
# below the tolerance is known in advance.

class _Parabola:
    """law(x) = a * x**2 - c with its derivatives (the Law protocol)."""

    def __init__(self, a: float, c: float = 0.0) -> None:
        self.a, self.c = a, c

    def __call__(self, x, nu: int = 0):
        x = np.asarray(x, dtype=np.float64)
        if nu == 0:
            return self.a * x * x - self.c
        return 2.0 * self.a * x if nu == 1 else np.full_like(x, 2.0 * self.a)


def _disc(law, guess, disc_point=(0.0, 0.0), marker=1.0) -> Mechanism:
    """Disc pinned at O, coupled to the ground by 0 = law(theta_disc); ``marker`` sets the size (scale)."""
    return Mechanism(
        name="disc", bodies=(Body("ground", {"O": (0.0, 0.0), "M": (marker, 0.0)}), Body("disc", {"O": disc_point})),
        ground="ground", joints=(Revolute("O", "ground", "disc"),),
        gears=(GearCoupling("square", "ground", "disc", "ground", law),), drivers=(), input_range=(0.0, 1.0),
        input_unit="mm", assembly={"disc": guess})


def test_linear_convergence_accepted_on_the_last_iteration():
    """a = 2e6, theta_0 = 0.5: residual after k halvings is 5e5 / 4**k, first below 1e-12 at k = 30, the last
    allowed iteration; the pose is accepted (theta = 0.5 / 2**30 within 1e-15)."""
    motion = _disc(_Parabola(2e6), (0.0, 0.0, 0.5)).sweep(np.array([0.0]))
    assert motion.pose("disc")[0, 2] == pytest.approx(0.5 / 2**30, abs=1e-15)


def test_newton_gives_up_after_thirty_iterations():
    """a = 8e6, theta_0 = 0.5: the residual 2e6 / 4**k is still 1.7e-12 > 1e-12 after 30 iterations, so the
    first pose is a LockupError (the budget is 30 Newton iterations)."""
    with pytest.raises(LockupError) as info:
        _disc(_Parabola(8e6), (0.0, 0.0, 0.5)).sweep(np.array([0.0]))
    assert "cannot assemble" in info.value.message


def _exact_tolerance_marker() -> float:
    """A size that makes the residual tolerance exactly 2**-39 (1e-12 per unit of size)."""
    scale = 2.0**-39 / 1e-12
    assert 1e-12 * scale == 2.0**-39 and scale > 1.0
    return scale


def test_residual_equal_to_tolerance_is_not_accepted_inside_the_loop():
    """a = 2**21, theta_0 = 1/2, tolerance 2**-39: the residual 2**(19 - 2k) equals the tolerance at k = 29,
    which is not *below* it, so one more iteration runs: theta = 2**-31 exactly."""
    motion = _disc(_Parabola(2.0**21), (0.0, 0.0, 0.5), marker=_exact_tolerance_marker()).sweep(np.array([0.0]))
    assert motion.pose("disc")[0, 2] == 2.0**-31


def test_residual_equal_to_tolerance_after_the_budget_is_a_failure():
    """a = 2**23, theta_0 = 1/2, tolerance 2**-39: the residual 2**(21 - 2k) reaches the tolerance exactly
    after the 30th iteration; not below it, so the first pose is a LockupError."""
    with pytest.raises(LockupError):
        _disc(_Parabola(2.0**23), (0.0, 0.0, 0.5), marker=_exact_tolerance_marker()).sweep(np.array([0.0]))


def test_exactly_singular_jacobian_at_the_guess_is_a_failure():
    """A singular Jacobian gives no Newton step and counts as failure (not success, not a least-squares
    step): a disc pinned by its point (1, 0), with 0 = theta**2 - 0.01, guessed at theta = 0 where the
    coupling row is exactly zero, is a LockupError although roots theta = +-0.1 exist nearby."""
    mech = _disc(_Parabola(1.0, 0.01), (-1.0, 0.1, 0.0), disc_point=(1.0, 0.0))
    with pytest.raises(LockupError) as info:
        mech.sweep(np.array([0.0]))
    assert info.value.input_value == 0.0
    # the same mechanism from a regular guess finds the root: theta = 0.1, disc point (1, 0) at the origin
    ok = _disc(_Parabola(1.0, 0.01), (-1.0, 0.1, 0.2), disc_point=(1.0, 0.0)).sweep(np.array([0.0]))
    assert ok.pose("disc")[0, 2] == pytest.approx(0.1, abs=1e-12)
    assert np.max(np.abs(ok.point("O", "disc")[0])) < 1e-12


def test_coupling_of_a_body_with_itself():
    """The coupling residual and its derivative hold when one body plays two roles: gear_a = gear_b = disc
    with law(x) = 0.6 - x gives theta = 0.6 - theta, i.e. theta = 0.3 (1e-12), from a guess of 0."""
    mech = Mechanism(
        name="self", bodies=(Body("ground", {"O": (0.0, 0.0)}), Body("disc", {"O": (0.0, 0.0)})), ground="ground",
        joints=(Revolute("O", "ground", "disc"),),
        gears=(GearCoupling("self", "ground", "disc", "disc", LinearLaw(-1.0, 0.6)),), drivers=(),
        input_range=(0.0, 1.0), input_unit="mm", assembly={"disc": (0.0, 0.0, 0.0)})
    assert mech.sweep(np.array([0.0])).pose("disc")[0, 2] == pytest.approx(0.3, abs=1e-12)


# -- step guard and tangent predictor -------------------------------------------------------------------------------

def test_large_input_step_near_change_point_stays_on_branch():
    """A crank-rocker close to Grashof's change point (8.6 + 28.75 = 37.35 against 17.8 + 19.75 = 37.55), whose
    two assembly branches pass close to each other, asked for one 120 deg input step on its lower branch:
    the step must be subdivided (no body turning 0.3 rad or more per accepted step) and predicted along the
    tangent, landing on the lower-branch closed form within 1e-9, like a 1-degree sweep does."""
    lengths = (8.6, 17.8, 19.75, 28.75)
    mech = make_four_bar(*lengths, start_deg=80.0, end_deg=200.0, upper=False)
    coarse = mech.sweep(np.array([80.0, 200.0]))
    fine = mech.sweep(121)
    expected = _four_bar_b(*lengths, 200.0, left=False)
    assert np.hypot(*(coarse.point("B", "rocker")[1] - expected)) < 1e-9
    assert np.max(np.abs(coarse.q[1] - fine.q[-1])) < 1e-9


def test_half_turn_in_one_step_a_tenth_of_a_millimetre_from_the_change_point():
    """A crank-rocker 0.1 mm short of Grashof's change point (crank 10.1, coupler 38.6, rocker 49.2, ground 20.8:
    10.1 + 49.2 = 59.3 against 38.6 + 20.8 = 59.4), whose branches pass within a fraction of a degree of each
    other, asked for one 180 degree input step (110 -> -70 deg) on its lower branch. A crank-rocker has no
    singular pose, so no LockupError may come, and B must be on the lower-branch circle intersection within
    1e-9 mm, where a 1 degree sweep ends too: the accepted steps may grow only so fast that each one's
    predictor still lands on this branch."""
    lengths = (10.1, 38.6, 49.2, 20.8)
    assert 10.1 + 49.2 == pytest.approx(38.6 + 20.8 - 0.1, abs=1e-12)
    mech = make_four_bar(*lengths, start_deg=110.0, end_deg=-70.0, upper=False)
    coarse = mech.sweep(np.array([110.0, -70.0]))
    fine = mech.sweep(181)
    expected = _four_bar_b(*lengths, -70.0, left=False)
    assert np.hypot(*(coarse.point("B", "rocker")[1] - expected)) < 1e-9
    assert np.hypot(*(fine.point("B", "rocker")[-1] - expected)) < 1e-9


def _slider_rocker(axis, d_point, s0: float, s1: float) -> Mechanism:
    """A block slid along ``axis`` through the origin (slide driver) carries pin P; coupler P-B (19.4) and
    rocker D-B (18.9) close the loop. Links have their frames at mid-length (local points +-L/2), so the
    size scale is 9.7 and the per-step translation guard 0.3 * 9.7 = 2.91 mm binds before the 0.3 rad one."""
    big_l, big_r = 19.4, 18.9
    axis_v, d = np.asarray(axis, dtype=float), np.asarray(d_point, dtype=float)
    p = s0 * axis_v
    b = _meet(p, big_l, d, big_r, left=True)

    def frame(p0, p1, length):
        ang = math.atan2(p1[1] - p0[1], p1[0] - p0[0])
        return (p0[0] + length / 2 * math.cos(ang), p0[1] + length / 2 * math.sin(ang), ang)

    return Mechanism(
        name="slider_rocker",
        bodies=(Body("ground", {"S": (0.0, 0.0), "D": tuple(d_point)}),
                Body("block", {"S": (0.0, 0.0), "P": (0.0, 0.0)}),
                Body("coupler", {"P": (-big_l / 2, 0.0), "B": (big_l / 2, 0.0)}),
                Body("rocker", {"D": (-big_r / 2, 0.0), "B": (big_r / 2, 0.0)})),
        ground="ground",
        joints=(Slider("S", "ground", "block", axis), Revolute("P", "block", "coupler"),
                Revolute("B", "coupler", "rocker"), Revolute("D", "ground", "rocker")),
        gears=(), drivers=(Driver("slide", "block", "ground", joint="S"),), input_range=(s0, s1), input_unit="mm",
        assembly={"block": (p[0], p[1], 0.0), "coupler": frame(p, b, big_l), "rocker": frame(d, b, big_r)})


@pytest.mark.parametrize(("axis", "d_point"), [((1.0, 0.0), (4.9, -0.6)), ((0.0, 1.0), (0.6, 4.9))])
def test_large_slide_step_is_subdivided_by_translation(axis, d_point):
    """One 18.75 mm slide step (6.4 x the 2.91 mm translation guard, along x or, the same mechanism turned
    90 deg, along y) is subdivided and stays on the branch it was assembled on: B matches the circle
    intersection within 1e-9, as a 0.25 mm sweep does."""
    s0, s1 = 5.65, -13.1
    mech = _slider_rocker(axis, d_point, s0, s1)
    coarse = mech.sweep(np.array([s0, s1]))
    fine = mech.sweep(np.linspace(s0, s1, 76))
    expected = _meet(s1 * np.asarray(axis), 19.4, d_point, 18.9, left=True)
    assert np.hypot(*(coarse.point("B", "rocker")[1] - expected)) < 1e-9
    assert np.max(np.abs(coarse.q[1] - fine.q[-1])) < 1e-9


@pytest.mark.parametrize("upper", [False, True])
def test_a_coarse_sweep_near_a_change_point_stays_on_its_branch(upper):
    """Regression (found by helper-29): a crank-rocker 0.02 mm from its Grashof change point (10.3 + 26.68 <
    21.3 + 15.7) swept in 15 deg poses (sweep(25) over a turn) raised a false 'branch change': one adaptive
    step of 15 deg put the corrector on the other branch. Steps are now at most 1/360 of the input range, so
    every pose equals the 1 deg sweep's pose at the same input (1e-9 mm), on either branch. (Over 60 random
    crank-rockers 0.001-1 mm from their change point, 4 failed so before, none after.)"""
    mech = make_four_bar(10.3, 26.68, 21.3, 15.7, start_deg=0.0, end_deg=360.0, upper=upper)
    coarse, fine = mech.sweep(25), mech.sweep(361)
    np.testing.assert_allclose(coarse.q, fine.q[::15], rtol=0, atol=1e-9)
