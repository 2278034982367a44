"""Free play of a gear pair (``fabricate.gears.mesh``): the window of rack flanks, the flank tables, the outlines.

Written to kill mutants of ``free_play``, ``flank_reach`` and ``free_play_outlines``. Expected values come from
closed forms written here: the window's half-width from the rack geometry of ``flank_reach``'s docstring, the
involute free play ``j / (2 r_b)`` of spur gears, and angles of hand-made flank tables. The hand-made tables
are read through a duck-typed pair (the fields ``free_play`` documents it reads) whose gear b turns with gear
a on the same axis (centre distance 0, law ``x_b = x_a``): gear b's frame is then gear a's frame bit for bit
and every gap is a difference of angles chosen here.
"""

from __future__ import annotations

import dataclasses
from functools import cache
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
import shapely.affinity

from fabricate.gears import GearSpec, make_gear_pair
from fabricate.gears import mesh as mesh_module
from fabricate.gears.law import FormulaLaw
from fabricate.gears.mesh import flank_reach, free_play, free_play_outlines


def reach_closed_form(module: float, alpha_deg: float, addendum: float, teeth: tuple[int, int] | None) -> float:
    """flank_reach's docstring: max(1.6 p, h_a m / (sin a cos a) + p), capped at (2 z_min - 1.5) p / 4 for
    closed gears (teeth given)."""
    p = np.pi * module
    a = np.radians(alpha_deg)
    reach = max(1.6 * p, addendum * module / (np.sin(a) * np.cos(a)) + p)
    if teeth is not None:
        reach = min(reach, (2 * min(teeth) - 1.5) * p / 4)
    return reach


def duck_pair(flanks_a: dict, flanks_b: dict, *, module: float = 2.0, origin: float = 0.0, closed: bool = False,
              teeth: tuple[int, int] = (0, 0), addendum: float = 1.0, alpha_deg: float = 20.0):
    """A pair as free_play reads it: pitch point at rack abscissa s = x_a (mm), gear b on gear a's axis
    turning with it, so a point of gear a is at the same coordinates in gear b's frame."""
    return SimpleNamespace(
        pitch_model=SimpleNamespace(s_of_x=lambda x: np.asarray(x, dtype=np.float64)),
        law=lambda x: np.asarray(x, dtype=np.float64), module=module, rack_origin=origin, closed=closed,
        teeth=teeth, center_distance_mm=0.0, cut_a=SimpleNamespace(flanks=flanks_a),
        cut_b=SimpleNamespace(flanks=flanks_b),
        spec=SimpleNamespace(addendum=addendum, pressure_angle=np.radians(alpha_deg)))


def radial(angle: float, radii) -> np.ndarray:
    """Points on the ray at ``angle`` from the axis, at ``radii``."""
    r = np.asarray(radii, dtype=np.float64)
    return np.column_stack([r * np.cos(angle), r * np.sin(angle)])


# -- flank_reach -----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("module", "alpha_deg", "addendum", "teeth"), [
    (2.0, 20.0, 1.0, None),     # rack limit + one pitch (module != 1: m and 1/m differ)
    (0.5, 10.0, 1.5, None),     # the docstring's 2.8 p rack limit at 10 deg, addendum 1.5
    (2.0, 35.0, 0.3, None),     # short rack limit: the 1.6 p floor holds (large module)
    (0.2, 35.0, 0.3, None),     # the floor with a small module (1.6 p, not 1.6 / p)
    (1.5, 14.5, 1.0, (4, 8)),   # closed, few teeth: at most 2 z flanks
    (0.8, 25.0, 1.2, (30, 41)),  # closed, many teeth: no cap
])
def test_flank_reach_is_the_rack_limit_plus_a_pitch(module, alpha_deg, addendum, teeth):
    """flank_reach = max(1.6 p, h_a m / (sin a cos a) + p), for closed gears at most (2 z_min - 1.5) p / 4
    (closed form, 1e-12 relative)."""
    pair = SimpleNamespace(module=module, closed=teeth is not None, teeth=teeth or (0, 0),
                           spec=SimpleNamespace(addendum=addendum, pressure_angle=np.radians(alpha_deg)))
    assert flank_reach(pair) == pytest.approx(reach_closed_form(module, alpha_deg, addendum, teeth), rel=1e-12)


def test_flank_reach_docstring_example_and_which_bound_holds():
    """The docstring's numbers: the rack limit is 2.8 p at 10 deg with addendum 1.5 (2.79 p, 0.01 p); at 20 deg
    and addendum 1 the rack limit plus a pitch (1.99 p) beats the 1.6 p floor; at 35 deg and addendum 0.3 the
    floor holds; for 4 teeth the cap (6.5 / 4 p) holds."""
    def reach(module, alpha, addendum, closed=False, teeth=(0, 0)):
        return flank_reach(SimpleNamespace(module=module, closed=closed, teeth=teeth,
                                           spec=SimpleNamespace(addendum=addendum, pressure_angle=np.radians(alpha))))

    p = np.pi * 3.0
    assert reach(3.0, 10.0, 1.5) / p - 1 == pytest.approx(2.79, abs=0.01)
    assert reach(3.0, 20.0, 1.0) / p == pytest.approx(1 / (np.pi * np.sin(np.radians(20)) * np.cos(np.radians(20))) + 1,
                                                      rel=1e-12)
    assert reach(3.0, 20.0, 1.0) / p > 1.6
    assert reach(3.0, 35.0, 0.3) / p == pytest.approx(1.6, rel=1e-12)
    assert reach(3.0, 20.0, 1.0, True, (4, 8)) / p == pytest.approx(6.5 / 4, rel=1e-12)


# -- free_play: the window of flanks ---------------------------------------------------------------------------
def test_free_play_window_holds_the_flanks_within_reach_of_the_pitch_point():
    """Open pair, module 2, rack origin 3.7 mm: rack flank j crosses the pitch line at u_j = origin - p/4 + j p/2.
    Gear a's flank j is a ray at angle 0.04 j, gear b's every flank a ray at angle 0: flank j's gap is 0.04 j
    (even j, free_plus) or -0.04 j (odd j, free_minus), so free_plus is the gap of the lowest even flank held
    and free_minus tells the highest odd flank held. With R the closed-form reach: the window starts at the
    first flank with u_j >= s - R (exactly: a closed gear's cap relies on holding no more), holds every flank up
    to s + R, and none a pitch or more beyond it. 1e-12 rad."""
    module, origin = 2.0, 3.7
    p = np.pi * module
    R = reach_closed_form(module, 20.0, 1.0, None)
    keys = np.arange(-20, 21)
    u = origin - p / 4 + keys * p / 2
    angle = 0.04 * keys
    flanks_a = {int(j): radial(angle[i], [1.5, 1.75, 2.0]) for i, j in enumerate(keys)}
    flanks_b = {int(j): radial(0.0, [1.0, 2.0, 3.0]) for j in keys}
    pair = duck_pair(flanks_a, flanks_b, module=module, origin=origin)
    s = np.linspace(origin - 3 * p, origin + 3 * p, 601)
    # keep clear of steps where s - R falls on a flank (rounding could go either way there)
    frac = (s - R - u[0]) / (p / 2) % 1.0
    s = s[(frac > 1e-9) & (frac < 1 - 1e-9)]
    plus, minus = free_play(pair, s)
    for k, sk in enumerate(s):
        first = keys[u >= sk - R].min()
        lowest_even = first if first % 2 == 0 else first + 1
        assert plus[k] == pytest.approx(0.04 * lowest_even, abs=1e-12), sk
        within = keys[(u <= sk + R) & (keys % 2 == 1)].max()
        beyond = keys[(u < sk + R + p) & (keys % 2 == 1)].max()
        assert -0.04 * beyond - 1e-12 <= minus[k] <= -0.04 * within + 1e-12, sk


def test_free_play_does_not_depend_on_where_the_flank_numbering_starts():
    """Flank tables like the window test's, renumbered from a rack origin n whole pitches further on (every key
    - 2 n, origin n p, for n = 5, -3, 8): the same flanks, so the same free play at every step (bit for bit)."""
    module = 2.0
    p = np.pi * module
    keys = np.arange(-30, 31)
    flanks_a = {int(j): radial(0.03 * j, [1.5, 2.0]) for j in keys}
    flanks_b = {int(j): radial(0.0, [1.0, 3.0]) for j in keys}
    s = np.linspace(-2 * p, 2 * p, 97)
    base = free_play(duck_pair(flanks_a, flanks_b, module=module, origin=0.0), s)
    assert np.all(np.isfinite(base))
    for turns in (5, -3, 8):
        shifted_a = {k - 2 * turns: v for k, v in flanks_a.items()}
        shifted_b = {k - 2 * turns: v for k, v in flanks_b.items()}
        got = free_play(duck_pair(shifted_a, shifted_b, module=module, origin=turns * p), s)
        np.testing.assert_array_equal(got, base)


def test_closed_pair_pairs_flank_j_mod_2z_also_without_gear_b_flank_0():
    """Closed 9/9 pair whose gear b lost flank 0 (trimmed away: its table starts at flank 1). Rack line j pairs
    a's flank j mod 18 with b's flank j mod 18. Gear a: even flanks rays at 0.5 rad, flank 6 at 0.8; odd at -0.5.
    Gear b: rays at 0, flank 6 at 0.3. Every line's gap is 0.5 (flank 6 against flank 6: 0.8 - 0.3), so both
    plays are 0.5 rad at every step over more than a turn either way (1e-12 rad); pairing a's flank 4 with b's
    flank 6 would give 0.2."""
    z = 9
    flanks_a = {k: radial(0.8 if k == 6 else (0.5 if k % 2 == 0 else -0.5), [1.5, 2.0]) for k in range(2 * z)}
    flanks_b = {k: radial(0.3 if k == 6 else 0.0, [1.0, 3.0]) for k in range(1, 2 * z)}
    pair = duck_pair(flanks_a, flanks_b, closed=True, teeth=(z, z))
    p = np.pi * pair.module
    s = np.linspace(-1.3 * z * p, 1.3 * z * p, 469)
    plus, minus = free_play(pair, s)
    np.testing.assert_allclose(plus, 0.5, rtol=0, atol=1e-12)
    np.testing.assert_allclose(minus, 0.5, rtol=0, atol=1e-12)


# -- free_play: the radius tables ------------------------------------------------------------------------------
def test_a_point_at_the_top_radius_of_gear_b_flank_is_compared():
    """Gear b's flank 0 covers radii 1 .. 2.5 along the ray at 0; gear a's flank 0 reaches it only with its point
    (1.5, 2) at radius exactly 2.5 (the others lie beyond). The radius range is closed: the gap there,
    atan2(2, 1.5), is free_plus (1e-12 rad); a point just outside (radius 2.5 + 1e-9) has nothing to compare."""
    flanks_b = {0: radial(0.0, [1.0, 1.75, 2.5])}
    s = np.array([-np.pi / 2])  # u_0 = -p/4 with module 2, origin 0: the pitch point at flank 0
    plus, minus = free_play(duck_pair({0: np.array([[1.5, 2.0], [2.1, 2.8], [2.4, 3.2]])}, flanks_b), s)
    assert plus[0] == pytest.approx(np.arctan2(2.0, 1.5), abs=1e-12)
    assert np.isnan(minus[0])
    outside = np.array([[1.5, 2.0], [2.1, 2.8]]) * (1 + 4e-10)
    plus, _ = free_play(duck_pair({0: outside}, flanks_b), s)
    assert np.isnan(plus[0])


def test_a_point_at_the_bottom_radius_of_gear_b_first_flank_uses_the_angle_there():
    """Gear b has one flank (its table's first and only row), curved: radii 1.25, 2, 3 at angles 0, 0.1, 0.2.
    Gear a's flank 0 has a point at radius exactly 1.25, (0.75, 1), and points at radii 2 and 3 on the ray at
    1.2. The gaps are atan2(1, 0.75) - 0 = 0.927 (compared with b's angle at radius 1.25, not at its other
    end, which would give 0.727), 1.1 and 1.0: free_plus is 0.927 (1e-12 rad)."""
    flanks_b = {0: np.vstack([radial(0.0, [1.25]), radial(0.1, [2.0]), radial(0.2, [3.0])])}
    flanks_a = {0: np.vstack([[[0.75, 1.0]], radial(1.2, [2.0, 3.0])])}
    plus, minus = free_play(duck_pair(flanks_a, flanks_b), np.array([-np.pi / 2]))
    assert plus[0] == pytest.approx(np.arctan2(1.0, 0.75), abs=1e-12)
    assert np.isnan(minus[0])


def test_a_point_at_the_bottom_radius_of_a_later_flank_row_is_compared():
    """The same flanks as flank 2 of both gears, gear b also holding a flank 0 (so flank 2 is a later row of its
    table): the point at radius exactly 1.25 is compared as on the first row, free_plus 0.927 (1e-12 rad). It
    was once dropped (its search key's left neighbour was the previous row), giving NaN."""
    flank_b = np.vstack([radial(0.0, [1.25]), radial(0.1, [2.0]), radial(0.2, [3.0])])
    flanks_a = {2: np.vstack([[[0.75, 1.0]], radial(1.2, [2.0, 3.0])])}
    s = np.array([-np.pi / 2 + np.pi])  # the pitch point moved by one pitch, p = pi * module = 2 pi
    short = flank_b[:2]  # rows of two points: the last row's lowest key is the table's second to last
    for flanks_b in ({2: flank_b}, {0: flank_b, 2: flank_b}, {0: short, 2: short}):
        plus, minus = free_play(duck_pair(flanks_a, flanks_b), s)
        assert plus[0] == pytest.approx(np.arctan2(1.0, 0.75), abs=1e-12), sorted(flanks_b)
        assert np.isnan(minus[0])


def test_contact_count_includes_the_closest_pair_whatever_the_tolerance(monkeypatch):
    """Driving (even) flanks 0 and 2 of gear a at 0.3 rad, flank 4 at 0.3 + 1e-3, gear b's at 0: two pairs touch
    together. The count is of pairs within the tolerance of the closest, bound included: with the tolerance 0
    still 2 (the closest pair always counts), with the default 2e-6 rad still 2, with 2e-3 all 3."""
    flanks_a = {0: radial(0.3, [1.5, 2.0]), 2: radial(0.3, [1.5, 2.0]), 4: radial(0.301, [1.5, 2.0])}
    flanks_b = {k: radial(0.0, [1.0, 3.0]) for k in (0, 2, 4)}
    pair = duck_pair(flanks_a, flanks_b, module=4.0)  # reach 2.0 p: flanks 0..4 all held at s = u_2 = 3 p / 4
    s = np.array([0.75 * np.pi * 4.0])
    for tolerance, expected in ((0.0, 2), (mesh_module.CONTACT_TOLERANCE_RAD, 2), (2e-3, 3)):
        monkeypatch.setattr(mesh_module, "CONTACT_TOLERANCE_RAD", tolerance)
        plus, minus, count = free_play(pair, s, return_contacts=True)
        assert plus[0] == pytest.approx(0.3, abs=1e-12)
        assert count.tolist() == [expected], tolerance


# -- free_play_outlines ----------------------------------------------------------------------------------------
@cache
def spur_48_12():
    """Spur gears 48/12 (ratio 4: gear b small), module 1, backlash 0.1 mm, outlines to 1 um."""
    spec = GearSpec(teeth=(48, 12), module_mm=1.0, backlash_mm=0.1, compare_methods=False, min_teeth=8)
    return make_gear_pair(FormulaLaw("4.0*x"), 30.0, (0.0, 2 * np.pi), spec, closed=True, run_mesh_check=False,
                          chord_tolerance_mm=0.001)


def test_free_play_from_outlines_of_a_small_driven_gear():
    """48/12 spur gears: both ways the free play is the involute j / (2 r_b) = 0.1 / 12 rad at every step over a
    tooth of gear a (the window on gear b must reach the whole path of contact: it spans 3 pitches either way
    at gear b's pitch radius). Measured from the outlines (decimated to 1 um) within 2.5 %, measured 1.4 %;
    from the dense flanks within 5e-6 rad."""
    pair = spur_48_12()
    x = np.linspace(0.0, 2 * np.pi / 48, 24, endpoint=False)
    expected = 0.1 / 12
    plus, minus = free_play_outlines(pair.outline_a, pair.outline_b, pair.law, pair.center_distance_mm, x,
                                     pair.module)
    np.testing.assert_allclose(plus, expected, rtol=0.025)
    np.testing.assert_allclose(minus, expected, rtol=0.025)
    dense_plus, dense_minus = free_play(pair, x)
    np.testing.assert_allclose(dense_plus, expected, rtol=0, atol=5e-6)
    np.testing.assert_allclose(dense_minus, expected, rtol=0, atol=5e-6)


# -- interference_areas ----------------------------------------------------------------------------------------
def test_interference_areas_are_the_overlap_where_teeth_meet_and_zero_elsewhere():
    """48/12 spur gears with gear b turned towards gear a by up to twice the backlash's angle, by an amount that
    varies with x: some steps overlap and some keep clear. Where they overlap the area is that of the posed
    outlines' intersection within the window (to rounding); elsewhere exactly 0. Fails if the overlay is skipped
    at a step where the teeth meet (interference_areas runs it only where the windows intersect)."""
    pair = spur_48_12()
    x = np.linspace(0.0, 2 * np.pi / 48, 40, endpoint=False)
    turn = 2.0 * 0.1 / 12 * np.sin(np.linspace(0.0, 3 * np.pi, len(x)))

    def turned(v, *order):
        return pair.law(v, *order) if order else np.asarray(pair.law(v)) + np.interp(v, x, turn)

    shifted = dataclasses.replace(pair, law=turned)
    areas = mesh_module.interference_areas(shifted, x)
    m, half = pair.module, 3.5 * np.pi * pair.module
    window = shapely.box(-3.0 * m, -half, 3.0 * m, half)
    reference = []
    for xa in x:
        r_a = float(pair.pitch_model.radii(np.array([xa]), "a")[0][0])
        a = shapely.affinity.translate(shapely.affinity.rotate(shapely.Polygon(pair.outline_a), xa, (0, 0), True),
                                       -r_a)
        b = shapely.affinity.translate(shapely.affinity.rotate(shapely.Polygon(pair.outline_b),
                                                               float(turned(np.array([xa]))[0]), (0, 0), True),
                                       pair.center_distance_mm - r_a)
        reference.append(a.intersection(b).intersection(window).area)
    reference = np.array(reference)
    assert np.count_nonzero(reference > 1e-9) >= 5 and np.count_nonzero(reference == 0.0) >= 5
    np.testing.assert_allclose(areas, reference, rtol=1e-9, atol=1e-12)
    assert np.all(areas[reference == 0.0] == 0.0)
