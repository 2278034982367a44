"""Gear properties a user depends on, with expected values from closed forms written here.

Written to kill mutants of ``fabricate/gears`` (see ``tests/benchmarks/mutation_report.md``): the sector's
hub is the hub that was asked for, and the transmission error is the larger of the two flank errors.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, Polygon

from fabricate.gears import GearSpec, make_gear_pair
from fabricate.gears.law import FormulaLaw

MODULE = 0.5
HUB_MM = 4.0  # hub diameter asked for


@cache
def sector_pair():
    spec = GearSpec(module_mm=MODULE, backlash_mm=0.05, compare_methods=False, hub_diameter_mm=HUB_MM)
    return make_gear_pair(FormulaLaw("0.8*x + 0.05*sin(2*x)"), 18.0, (0.1, 0.9), spec, closed=False,
                          chord_tolerance_mm=0.005, run_mesh_check=False)


@cache
def spur_pair(z: int = 24, module: float = 1.0, backlash: float = 0.1):
    """Two equal circular gears (law x_b = -x_a): exact involute spur gears."""
    spec = GearSpec(teeth=(z, z), module_mm=module, backlash_mm=backlash, compare_methods=False, mesh_steps=720)
    return make_gear_pair(FormulaLaw("x"), z * module, (0.0, 2 * np.pi), spec, closed=True)


def ray_extent(outline: np.ndarray, direction: np.ndarray) -> float:
    """Distance from the axis (origin) to the outline along ``direction`` (nearest crossing)."""
    ray = LineString([(0.0, 0.0), tuple(200.0 * direction)])
    hit = Polygon(outline).exterior.intersection(ray)
    return float(min(Point(0.0, 0.0).distance(g) for g in getattr(hit, "geoms", [hit])))


@pytest.mark.parametrize("gear", ["a", "b"])
def test_sector_hub_is_the_hub_asked_for(gear):
    """Away from the teeth the sector is its hub: the outline's extent there is the hub radius, and the
    area is at most the toothed fan (pitch curve pushed out by the addendum, closed at the axis) plus
    the hub disc."""
    pair = sector_pair()
    cut, pitch = (pair.cut_a, pair.pitch_a) if gear == "a" else (pair.cut_b, pair.pitch_b)
    outline = np.asarray(cut.outline)
    assert Polygon(outline).is_valid
    # opposite the teeth: the direction away from the mean direction of the pitch curve
    mean = np.mean(pitch / np.hypot(*pitch.T)[:, None], axis=0)
    away = -mean / np.hypot(*mean)
    for turn in (-0.5, 0.0, 0.5):  # three rays over the back of the hub
        c, s = np.cos(turn), np.sin(turn)
        d = np.array([c * away[0] - s * away[1], s * away[0] + c * away[1]])
        assert ray_extent(outline, d) == pytest.approx(HUB_MM / 2, abs=0.005)
    # area bound: the fan up to the tip curve plus the hub disc (generous: the fan uses 1.1 addendum)
    r = np.hypot(*pitch.T)[:, None]
    tip = pitch * (r + 1.1 * MODULE) / r
    fan = Polygon(np.vstack([[0.0, 0.0], tip]))
    if not fan.is_valid:
        fan = shapely.make_valid(fan)
    bound = fan.area + np.pi * (HUB_MM / 2) ** 2
    assert Polygon(outline).area <= bound
    # and the teeth are there: more than the fan up to the root curve
    root = pitch * (r - 1.25 * MODULE - 0.1) / r
    assert Polygon(outline).area > Polygon(np.vstack([[0.0, 0.0], root])).area


def test_spur_transmission_error_is_the_larger_flank_error():
    """For equal involute spur gears each flank's designed free play is backlash / (2 r) (the flank
    thinning j cos(alpha) / 4 over the base radius r cos(alpha), twice): the transmission error at a
    step is the larger of |play - designed| over the two flanks, and the report gives its maximum."""
    z, module, backlash = 24, 1.0, 0.1
    pair = spur_pair(z, module, backlash)
    mesh = pair.mesh
    r = z * module / 2
    lag = backlash / (2 * r)
    ok = np.isfinite(mesh.free_plus) & np.isfinite(mesh.free_minus)
    assert ok.mean() > 0.99
    err = np.maximum(np.abs(mesh.free_plus[ok] - lag), np.abs(mesh.free_minus[ok] - lag))
    np.testing.assert_allclose(np.abs(mesh.transmission_error[ok]), err, rtol=1e-9, atol=1e-15)
    assert pair.report()["transmission_error_deg"] == pytest.approx(np.degrees(err.max()), rel=1e-9)
    # total free rotation is the backlash over the pitch radius (closed form, 1 um)
    np.testing.assert_allclose((mesh.free_plus[ok] + mesh.free_minus[ok]) * r, backlash, atol=1e-3)
    # the errors of the two flanks differ: the max/min choice matters for this pair
    assert np.mean(np.abs(np.abs(mesh.free_plus[ok] - lag) - np.abs(mesh.free_minus[ok] - lag)) > 0) > 0.5


# -- outline helpers, each against its definition -------------------------------------------------
def test_flank_index_counts_half_pitches_from_the_origin():
    from fabricate.gears.teeth import flank_index

    p, origin = 2.0, 0.3
    # flank k sits at origin - p/4 + k p/2 on the pitch line (left flank of tooth 0 is 0)
    k = np.arange(-5, 6)
    u = origin - p / 4 + k * p / 2
    np.testing.assert_array_equal(flank_index(u, p, origin), k)
    np.testing.assert_array_equal(flank_index(u + 0.2 * p, p, origin), k)  # rounds to the nearest
    np.testing.assert_array_equal(flank_index(u - 0.2 * p, p, origin), k)
    out = flank_index(np.array([np.nan, np.inf]), p, origin)
    assert out.dtype == np.int64 and np.all(out < -(2**61))


def test_largest_polygon_of_collections():
    from fabricate.gears.teeth import _largest_polygon

    small, big = shapely.box(0, 0, 1, 1), shapely.box(5, 5, 8, 8)
    assert _largest_polygon(big) is big
    assert _largest_polygon(shapely.MultiPolygon([small, big])).equals(big)
    mixed = shapely.GeometryCollection([LineString([(0, 0), (9, 9)]), small, shapely.MultiPolygon([big])])
    assert _largest_polygon(mixed).equals(big)
    with pytest.raises(ValueError):
        _largest_polygon(shapely.GeometryCollection([LineString([(0, 0), (1, 1)])]))


def test_clean_ring_drops_closing_and_repeated_vertices():
    from fabricate.gears.teeth import _clean_ring

    square = np.array([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1], [0, 0]], dtype=float)
    np.testing.assert_array_equal(_clean_ring(square), [[0, 0], [1, 0], [1, 1], [0, 1]])
    np.testing.assert_array_equal(_clean_ring(square[:-1]), [[0, 0], [1, 0], [1, 1], [0, 1]])
    near = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 1e-12]], dtype=float)  # last repeats the first
    assert len(_clean_ring(near)) == 4


@pytest.mark.parametrize("tol", [1e-3, 0.02, 0.2])
def test_simplify_ring_keeps_every_dropped_vertex_within_the_tolerance(tol):
    from fabricate.gears.teeth import simplify_ring

    t = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    r = 10 + 0.8 * np.sin(7 * t) + 0.05 * np.sin(53 * t)
    ring = np.column_stack([r * np.cos(t), r * np.sin(t)])
    out = simplify_ring(ring, tol)
    assert 3 < len(out) < len(ring)
    # a subset of the input, in order
    idx = [int(np.flatnonzero(np.all(ring == v, axis=1))[0]) for v in out]
    assert idx == sorted(idx) and idx[0] == 0
    dist = shapely.distance(shapely.points(ring), shapely.LinearRing(out))
    assert dist.max() <= tol * (1 + 1e-9)
    assert dist.max() > 0.3 * tol  # not needlessly dense
    if tol < 0.01:
        assert len(out) > 100


@pytest.mark.parametrize(("radius", "tol"), [(2.0, 0.005), (0.5, 0.2), (20.0, 1e-4)])
def test_circle_points_chord_error(radius, tol):
    from fabricate.gears.teeth import circle_points

    pts = circle_points(radius, tol, start=0.3)
    n = len(pts)
    assert n >= 16
    np.testing.assert_allclose(np.hypot(*pts.T), radius, rtol=1e-12)
    sagitta = radius * (1 - np.cos(np.pi / n))
    assert sagitta <= tol * (1 + 1e-9)
    assert n == 16 or radius * (1 - np.cos(np.pi / (n - 1))) > tol  # the fewest points that do it
    assert Polygon(pts).exterior.is_ccw
    assert np.arctan2(pts[0, 1], pts[0, 0]) == pytest.approx(0.3)


# -- the gear-mesh check of an assembled motion ---------------------------------------------------
def fake_motion(x_a: np.ndarray, x_b: np.ndarray):
    """The three things check_gear_mesh reads from a Motion: relative angles, inputs, the input unit."""
    from types import SimpleNamespace

    angles = {"gear_a": x_a, "gear_b": x_b, "carrier": np.zeros_like(x_a)}
    return SimpleNamespace(relative_angle=lambda body, ref: angles[body] - angles[ref],
                           inputs=np.degrees(x_a), mechanism=SimpleNamespace(input_unit="deg"))


def test_gear_mesh_check_of_a_motion_on_the_law():
    """Spur pair driven exactly by its law: no failure, backlash = the designed 0.1 mm (closed form), the TE
    the larger flank error against the closed-form designed play at the motion's own angles."""
    from dataclasses import replace

    from fabricate.checks.gear_mesh import check_gear_mesh

    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.2, 1.4, 61)
    result = check_gear_mesh(pair, fake_motion(x, np.asarray(pair.law(x))))
    assert result.failures == ()
    assert result.law_error_rad < 1e-12
    assert result.steps == 61 and result.steps_without_contact == 0
    assert result.backlash_mm == pytest.approx((0.1, 0.1), abs=1e-3)
    lo, hi = result.backlash_allowed_mm
    assert lo < 0.1 < hi
    assert result.x_a_range_deg == pytest.approx((np.degrees(0.2), np.degrees(1.4)))
    assert result.interference_area_mm2 == 0.0
    lag = 0.1 / (2 * 12.0)  # backlash / (2 r), r = 12 mm
    from fabricate.gears.mesh import mesh_check

    own = mesh_check(pair, x_a_values=x)
    err = np.maximum(np.abs(own.free_plus - lag), np.abs(own.free_minus - lag))
    assert result.transmission_error_deg == pytest.approx(np.degrees(np.nanmax(err)), rel=1e-9)


def test_gear_mesh_check_catches_a_motion_off_the_law_and_out_of_range():
    from dataclasses import replace

    from fabricate.checks.gear_mesh import check_gear_mesh

    pair = replace(spur_pair(), carrier="carrier")
    x = np.linspace(0.2, 1.4, 31)
    off = check_gear_mesh(pair, fake_motion(x, np.asarray(pair.law(x)) + np.radians(0.5)))
    assert off.law_error_rad == pytest.approx(np.radians(0.5), rel=1e-9)
    assert any("departs from the gear law" in f for f in off.failures)
    sector = replace(sector_pair(), carrier="carrier")
    lo, hi = sector.working_range
    x = np.linspace(lo, hi + 0.2, 31)  # 11 deg past the cut range
    out = check_gear_mesh(sector, fake_motion(x, np.asarray(sector.law(x))))
    assert any("outside the cut range" in f for f in out.failures)
    inside = check_gear_mesh(sector, fake_motion(x[x <= hi], np.asarray(sector.law(x[x <= hi]))))
    assert not any("outside the cut range" in f for f in inside.failures)
