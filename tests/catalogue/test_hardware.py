"""Standard hardware: the tables are standard series, the pickers choose from them, and every designation a
shop reads names the record it came from."""

from __future__ import annotations

import itertools
import math

import pytest

from fabricate.catalogue import clips, pins
from fabricate.catalogue import hardware as hw
from fabricate.catalogue.designations import parse_designation
from fabricate.errors import SpecError

# --- ISO 7089 / DIN 125-A washers -------------------------------------------------------------------------


def test_iso7089_covers_m16_to_m8_as_a_monotone_series():
    sizes = list(hw.ISO7089)
    assert sizes[0] == "M1.6" and sizes[-1] == "M8" and {"M2", "M2.5", "M3", "M4", "M5", "M6"} <= set(sizes)
    nominal = [float(s[1:]) for s in sizes]
    assert nominal == sorted(nominal)
    rows = [hw.ISO7089[s] for s in sizes]
    for (d1, d2, h), n in zip(rows, nominal, strict=True):
        assert n < d1 < n + 0.5 and d1 < d2 and 0 < h < d1       # a clearance bore, a ring, thin
    for a, b in itertools.pairwise(rows):
        assert a[0] < b[0] and a[1] < b[1] and a[2] <= b[2]
    for size in sizes:
        w = hw.washer(size)
        assert parse_designation(w.designation) == w == parse_designation(w.alt_designation)


# --- fill_gap ----------------------------------------------------------------------------------------------


def _brute_force(items, gap, tol):
    """Every multiset of the items (each thickness at most gap/h times) whose total lies in [gap-tol, gap],
    as (count, total) pairs: the independent check on fill_gap's choice."""
    hs = sorted({w.h_mm for w in items})
    ranges = [range(int(gap / h + 1e-9) + 1) for h in hs]
    found = []
    for counts in itertools.product(*ranges):
        total = sum(c * h for c, h in zip(counts, hs, strict=True))
        if gap - tol - 1e-9 <= total <= gap + 1e-9 and sum(counts) > 0:
            found.append((sum(counts), total))
    return found


@pytest.mark.parametrize("shaft", [2.0, 3.0, 5.0, 8.0])
@pytest.mark.parametrize("tol", [0.05, 0.2, 0.5])
def test_fill_gap_stays_within_the_gap_uses_table_pieces_and_the_fewest(shaft, tol):
    items = hw.washers_for_shaft(shaft)
    assert items and all(w.d1_mm >= shaft for w in items)       # every piece slides over the pin
    assert {w.standard for w in items} <= {"ISO 7089", "ISO 8738", "DIN 988"}
    for gap in (0.3, 0.6, 1.0, 1.35, 2.0, 2.9, 4.0):
        options = _brute_force(items, gap, tol)
        if gap <= tol:
            assert hw.fill_gap(shaft, gap, tol) == ()
            continue
        if not options:
            with pytest.raises(SpecError) as err:
                hw.fill_gap(shaft, gap, tol)
            assert err.value.path == "gap_mm"
            continue
        stack = hw.fill_gap(shaft, gap, tol)
        total = sum(w.h_mm for w in stack)
        assert gap - tol - 1e-9 <= total <= gap + 1e-9
        assert all(w in items for w in stack)                    # only catalogued washers and shims
        fewest = min(c for c, _ in options)
        assert len(stack) == fewest
        assert math.isclose(total, max(t for c, t in options if c == fewest), abs_tol=1e-9)
        assert [w.h_mm for w in stack] == sorted((w.h_mm for w in stack), reverse=True)


def test_fill_gap_refusals_name_the_field():
    for args, path in (((2.0, -0.1, 0.1), "gap_mm"), ((2.0, 1.0, -0.1), "tol_mm"), ((0.0, 1.0, 0.1), "shaft_mm"),
                       ((9.5, 1.0, 0.1), "shaft_mm"), ((2.0, float("nan"), 0.1), "gap_mm")):
        with pytest.raises(SpecError) as err:
            hw.fill_gap(*args)
        assert err.value.path == path


def test_din988_shims_are_named_d1_x_d2_x_h_and_read_back():
    for (d1, d2), (thicknesses, _) in hw.DIN988.items():
        for h in thicknesses:
            ring = hw.shim_ring(d1, h)
            assert ring.designation == f"DIN 988 {d1:g} × {d2:g} × {h:g}"
            assert parse_designation(ring.designation) == ring
            assert parse_designation(f"DIN 988 {d1:g} x {d2:g} x {h:g}".replace(".", ",")) == ring
    with pytest.raises(SpecError):
        parse_designation("DIN 988 3 × 7 × 0.5")                 # the 3 mm ring is 6 mm outside


# --- nuts and screws ---------------------------------------------------------------------------------------


def test_iso4032_nuts_are_hexagons_growing_with_the_thread():
    sizes = list(hw.ISO4032)
    assert {"M2", "M2.5", "M3", "M4", "M5"} <= set(sizes)
    prev = None
    for size in sizes:
        n = hw.nut(size)
        assert n.designation == f"ISO 4032 {size}" and parse_designation(n.designation) == n
        # across corners of a regular hexagon is s / cos 30°; the standard's e min sits just under it
        assert n.s_mm < n.e_mm <= n.s_mm / math.cos(math.radians(30)) + 1e-9
        assert float(size[1:]) < n.s_mm and 0 < n.m_mm < n.s_mm
        if prev is not None:
            assert prev.s_mm < n.s_mm and prev.m_mm < n.m_mm and prev.pitch_mm < n.pitch_mm
        prev = n
    with pytest.raises(SpecError) as err:
        hw.nut("M7")
    assert err.value.path == "size"


@pytest.mark.parametrize("size", ["M2", "M2.5", "M3", "M4", "M5"])
def test_screw_and_nut_engages_the_whole_nut(size):
    for clamp in (2.0, 6.0, 10.5):
        s, n = hw.screw_and_nut(size, clamp)
        assert s.length_mm >= clamp + n.m_mm and s.engagement_mm >= n.m_mm
        assert s.length_mm in hw.ISO4762_LENGTHS_MM
        assert parse_designation(s.designation).length_mm == s.length_mm


# --- clevis pins and split pins ------------------------------------------------------------------------------


@pytest.mark.parametrize("d", sorted(pins.ISO2341))
def test_clevis_pin_grip_covers_the_stack_and_takes_its_split_pin(d):
    dk, dl, _, _, k, le = pins.ISO2341[d]
    lo, hi = pins.ISO2341_RANGE_MM[d]
    series = [v for v in pins.ISO2341_LENGTHS_MM if lo <= v <= hi]
    for grip in (1.0, 4.5, 9.2, series[-1] - le - dl / 2):
        pin = pins.clevis_pin(d, grip)
        assert pin.length_mm in series
        assert pin.grip_mm == pytest.approx(pin.length_mm - le - dl / 2) and pin.grip_mm >= grip - 1e-9
        shorter = [v for v in series if v < pin.length_mm]
        assert not shorter or shorter[-1] - le - dl / 2 < grip     # the shortest that holds the stack
        assert pin.protrusion_mm == pytest.approx(le + dl / 2) and pin.head_d_mm == dk > d
        sp = pin.split_pin
        assert sp.size_mm == dl and sp.length_mm >= d and sp.wire_d_mm < dl   # fits its hole, spans the pin
        assert sp.length_mm in pins.ISO1234_LENGTHS_MM
        assert pin.designation == f"ISO 2341-B {d:g} × {pin.length_mm:g}"
        assert parse_designation(pin.designation) == pin
        assert parse_designation(sp.designation) == sp
    with pytest.raises(SpecError) as err:
        pins.clevis_pin(d, series[-1])
    assert err.value.path == "min_grip_mm"


def test_clevis_pin_refuses_a_diameter_iso_2341_lacks():
    with pytest.raises(SpecError) as err:
        pins.clevis_pin(2.0, 10.0)                                    # ISO 2341 starts at 3 mm
    assert err.value.path == "diameter_mm"
    assert pins.clevis_pin(3, 9.2).designation == "ISO 2341-B 3 × 12"   # 12 - 1.6 - 0.4 = 10 >= 9.2


@pytest.mark.parametrize("d", [2.0, 2.5, 3.0, 4.0, 5.0])
def test_grooved_pin_leaves_room_for_a_clip_at_each_face(d):
    for stack in (3.0, 7.4, 12.0):
        g = clips.grooved_pin(d, stack)
        series = pins.pin_lengths(d, "ISO 2338")
        need = stack + 2 * (g.clip.groove_w_mm + g.clip.edge_margin_mm)
        assert g.pin.length_mm in series and g.pin.length_mm >= need
        assert all(v < need for v in series if v < g.pin.length_mm)        # the shortest that does
        # groove centre to the end: half the overhang less half a groove; the margin beyond stays >= n
        over = (g.pin.length_mm - stack) / 2
        assert g.groove_from_end_mm == pytest.approx(over - g.clip.groove_w_mm / 2)
        assert g.groove_from_end_mm - g.clip.groove_w_mm / 2 >= g.clip.edge_margin_mm - 1e-9
        assert g.designation.startswith("ISO 2338 ") and g.clip.groove_d_mm < d


# --- designations --------------------------------------------------------------------------------------------


def test_every_designation_names_its_record():
    records = [pins.dowel_pin(d, n) for d in (1.5, 2, 3) for n in (8.0, 12.3, 15.6)]
    records += [hw.screw(size, clamp, 3.0, std) for std in ("ISO 4762", "ISO 7380") for size in ("M3", "M4")
                for clamp in (2.0, 7.0)]
    records += [clips.e_clip(d) for d in (2.0, 2.5, 3.0, 4.0)]
    records += [pins.split_pin(s, 10) for s in pins.ISO1234]
    records += [hw.pin_washer(d) for d in hw.ISO8738]
    for r in records:
        back = parse_designation(r.designation)
        assert back.designation == r.designation
        if isinstance(r, hw.Screw):
            assert (back.length_mm, back.head_d_mm) == (r.length_mm, r.head_d_mm)
        else:
            assert back == r
    assert clips.e_clip(3.0).designation == "DIN 6799 1.9"
    assert parse_designation("ISO 8734 2 × 20") == ("ISO 8734 2 × 20", 20.0)
    for bad in ("ISO 8734 2 × 21", "ISO 4762 M3 × 13", "ISO 7089 7", "DIN 6799 1.3", "ISO 2341-B 3 × 7",
                "ISO 1234 0.8 × 7", "M3 washer", "ISO 4032 M7"):
        with pytest.raises(SpecError) as err:
            parse_designation(bad)
        assert err.value.path == "designation"
