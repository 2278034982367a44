"""run_checks and CheckReport: what is re-swept, which clearance is required, how the three checks' failures
are gathered, and the report, the per-pair table and its Markdown, each against closed-form box geometry
or hand-made stand-ins.

Written to kill mutants of ``fabricate/checks/__init__.py``. The parts are rectangles (exact polygons at any
chord tolerance) moved by hand-made motions of bodies 'a' (at rest) and 'b', so every clearance is a
difference of known lengths; the gear-mesh and printability checks are replaced by recording stand-ins
(monkeypatched into the ``fabricate.checks`` namespace) where a controlled failure is needed.

Then (formerly tests/test_checks.py) run_checks over whole builds: the four-bar by hand, the seed-000 finger
through the real layers, deliberately broken variants, printability against the process profiles, the gear
mesh in place.
"""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

import fabricate.checks as checks
from fabricate.checks import CheckReport, run_checks, sweep_interference
from fabricate.checks.gear_mesh import check_gear_mesh
from fabricate.checks.printability import check_printability, hole_walls, thin_feature
from fabricate.mechanism import Motion
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.spec import ChecksSpec
from tests.conftest import make_four_bar
from tests.interference_fixtures import four_bar_parts, slot_part

PNG = b"\x89PNG\r\n\x1a\n"
HEADER = ("| a | b | relation | min clearance mm | at input deg | required mm | ok |\n"
          "|---|---|---|---|---|---|---|")


# -- inputs -----------------------------------------------------------------------------------------
def box(name: str, body: str, size: tuple[float, float] = (10.0, 4.0), z: float = 0.0, thickness: float = 2.0,
        holes: tuple[Hole, ...] = ()) -> Part:
    """A ``size`` rectangle centred on its body's origin, extruded from ``z`` by ``thickness``."""
    w, h = size
    outline = BulgePath.polyline(np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]]))
    return Part(name, body, outline, holes, thickness, z, 0, "sla")


def motion_of(poses_b, inputs=None) -> Motion:
    """A Motion of bodies 'a' (at rest) and 'b' (``poses_b``: rows x, y, angle), ground 'g', unit deg."""
    poses_b = np.asarray(poses_b, dtype=np.float64)
    n = len(poses_b)
    inputs = np.arange(n, dtype=np.float64) if inputs is None else np.asarray(inputs, dtype=np.float64)
    return Motion(inputs=inputs, body_names=("g", "a", "b"), ground="g", free=("a", "b"),
                  q=np.stack([np.zeros((n, 3)), poses_b], axis=1), mechanism=SimpleNamespace(input_unit="deg"))


def slide_x(xs, inputs=None) -> Motion:
    """B's origin at (x, 0), unrotated, for each x."""
    xs = np.asarray(xs, dtype=np.float64)
    return motion_of(np.column_stack([xs, np.zeros(len(xs)), np.zeros(len(xs))]), inputs)


class Mech:
    """Mechanism stand-in: ``sweep(n)`` returns ``make(n)`` (a Motion of n poses) and records every n."""

    def __init__(self, make):
        self.make = make
        self.calls: list[int] = []
        self.motions: list[Motion] = []

    def sweep(self, n):
        self.calls.append(n)
        motion = self.make(n)
        self.motions.append(motion)
        return motion


def never_swept(n):
    raise AssertionError(f"mechanism.sweep({n}) called although the motion has enough poses")


def design(process, poses: int, min_clearance: float | None):
    return SimpleNamespace(process=process, checks=SimpleNamespace(sweep_poses=poses, min_clearance_mm=min_clearance))


def two_boxes():
    """A (body a) and B (body b), both 10 x 4 on one layer (z 0..2): B at x = 10 + g stands g mm clear of A."""
    return SimpleNamespace(parts=(box("A", "a"), box("B", "b")), pins=(), spacers=())


class Recorder:
    """Stand-in for check_gear_meshes / check_printability: records its arguments, returns ``result``."""

    def __init__(self, result):
        self.result = result
        self.args: list[tuple] = []
        self.kwargs: list[dict] = []

    def __call__(self, *args, **kwargs):
        self.args.append(args)
        self.kwargs.append(kwargs)
        return self.result


def outcome(failures, report):
    return SimpleNamespace(failures=tuple(failures), report=lambda: report)


# -- the clearance verdict and its table ------------------------------------------------------------
def test_boxes_closer_than_the_required_clearance_fail_with_a_row_and_message(sla_process):
    """B stands 0.4, 1.0, 2.0 mm right of A at inputs 12.5, 20, 30 deg; required 0.5 mm: one failure (the
    clearance message, 0.400 mm at 12.5 deg, needs 0.500 mm), passed False, and the table row
    ``| A | B | moving | 0.400 | 12.50 | 0.5 | **no** |``. Three poses asked, three given: no re-sweep.
    The real gear-mesh (no pairs: []) and printability (boxes without holes pass) results are in the report."""
    partset = two_boxes()
    motion = slide_x([10.4, 11.0, 12.0], [12.5, 20.0, 30.0])
    report = run_checks(design(sla_process, 3, 0.5), partset, Mech(never_swept), motion, [])
    msg = "clearance: A and B come within 0.400 mm at input 12.5 deg; the process needs 0.500 mm"
    assert report.failures == [msg]
    assert report.passed is False
    assert report.report() == {"interference": report.interference,
                               "checks": {"passed": False, "failures": [msg], "not_checked": []}}
    inter = report.interference
    assert inter["poses"] == 3 and inter["pairs_checked"] == 1 and inter["collisions"] == []
    assert inter["passed"] is False and "reason" not in inter
    assert inter["min_clearance_mm"] == pytest.approx(0.4, abs=1e-9)
    assert inter["required_clearance_mm"] == 0.5
    assert inter["tolerance_mm"] == sla_process.chord_tolerance_mm
    assert inter["gear_mesh"] == []
    assert inter["printability"] == check_printability(partset.parts, sla_process).report()
    assert inter["printability"]["passed"] is True
    assert report.gear_mesh == () and report.printability.failures == ()
    assert report.printability.process == "sla"
    assert report.sweep.min_clearance_required_mm == 0.5
    (row,) = report.pair_table()
    assert (row["a"], row["b"], row["relation"], row["ok"]) == ("A", "B", "moving", False)
    assert row["input_deg"] == 12.5 and row["min_clearance_mm"] == pytest.approx(0.4, abs=1e-9)
    assert report.pair_table_markdown() == HEADER + "\n| A | B | moving | 0.400 | 12.50 | 0.5 | **no** |"


def test_boxes_farther_than_the_required_clearance_pass(sla_process):
    """The same boxes 0.6 mm apart at best (inputs 0, 1) against 0.5 mm: no failures, passed True, the row says
    ``0.600 | 0.00 | 0.5 | yes``."""
    motion = slide_x([10.6, 11.0])
    report = run_checks(design(sla_process, 2, 0.5), two_boxes(), Mech(never_swept), motion, [])
    assert report.failures == [] and report.passed is True
    assert report.report()["checks"] == {"passed": True, "failures": [], "not_checked": []}
    assert report.interference["passed"] is True and report.not_checked == ()
    assert report.pair_table_markdown() == HEADER + "\n| A | B | moving | 0.600 | 0.00 | 0.5 | yes |"


def test_colliding_boxes_say_collides_and_fail(sla_process):
    """B's centre 8 mm right of A's (overlap 2 x 4 x 2 = 16 mm^3 at input 5 deg), then 11 mm (1 mm clear):
    the interference failure names the pair and volume, the row reads ``collides`` and ``**no**``."""
    motion = slide_x([8.0, 11.0], [5.0, 6.0])
    report = run_checks(design(sla_process, 2, 0.25), two_boxes(), Mech(never_swept), motion, [])
    assert report.failures == ["interference: A collides with B at input 5..5 deg "
                               "(largest overlap 16.000 mm^3 at 5 deg)"]
    assert report.passed is False
    (hit,) = report.interference["collisions"]
    assert (hit["a"], hit["b"], hit["volume_mm3"]) == ("A", "B", pytest.approx(16.0, abs=1e-6))
    assert report.pair_table_markdown() == HEADER + "\n| A | B | moving | collides | 5.00 | 0.25 | **no** |"


def test_lower_bound_clearance_is_prefixed(sla_process):
    """2 x 2 squares 20 mm apart (centre to centre) are beyond the search length (2 mm): the clearance is the
    bounding-circle lower bound 20 - 2 sqrt 2 = 17.172 mm, not exact, printed ``≥ 17.172``."""
    partset = SimpleNamespace(parts=(box("A", "a", (2.0, 2.0)), box("B", "b", (2.0, 2.0))), pins=())
    report = run_checks(design(sla_process, 1, 0.25), partset, Mech(never_swept), slide_x([20.0]), [])
    (row,) = report.pair_table()
    assert row["exact"] is False
    assert row["min_clearance_mm"] == pytest.approx(20.0 - 2.0 * np.sqrt(2.0), abs=1e-6)
    assert report.passed is True
    assert report.pair_table_markdown() == HEADER + "\n| A | B | moving | ≥ 17.172 | 0.00 | 0.25 | yes |"


# -- the required clearance -------------------------------------------------------------------------
@pytest.mark.parametrize("running, passes", [(0.25, True), (0.5, False)])
def test_unset_minimum_is_the_process_running_clearance(sla_process, running, passes):
    """min_clearance_mm None: the process's running clearance is required. Boxes 0.4 mm apart pass with
    0.25 mm and fail with 0.5 mm; the sweep and every row carry that value."""
    process = dataclasses.replace(sla_process, running_clearance_mm=running)
    report = run_checks(design(process, 1, None), two_boxes(), Mech(never_swept), slide_x([10.4]), [])
    assert report.passed is passes
    assert report.interference["required_clearance_mm"] == running
    assert [r["required_mm"] for r in report.pair_table()] == [running]
    if passes:
        assert report.failures == []
    else:
        assert report.failures == ["clearance: A and B come within 0.400 mm at input 0 deg; "
                                   "the process needs 0.500 mm"]
    assert f"| 0.400 | 0.00 | {running:g} |" in report.pair_table_markdown()


def test_explicit_zero_minimum_is_kept(sla_process):
    """min_clearance_mm 0.0 is a value, not 'unset': with a 0.5 mm running clearance, boxes 0.1 mm apart
    pass, and 0 mm is reported as required (``| 0 |`` in the table)."""
    process = dataclasses.replace(sla_process, running_clearance_mm=0.5)
    report = run_checks(design(process, 1, 0.0), two_boxes(), Mech(never_swept), slide_x([10.1]), [])
    assert report.failures == [] and report.passed is True
    assert report.interference["required_clearance_mm"] == 0.0
    assert report.pair_table_markdown() == HEADER + "\n| A | B | moving | 0.100 | 0.00 | 0 | yes |"


# -- re-sweep ---------------------------------------------------------------------------------------
def test_motion_with_fewer_poses_is_reswept_with_exactly_the_poses_asked(sla_process, monkeypatch):
    """A 4-pose motion (B 5 mm clear) and 5 poses asked: mechanism.sweep is called once, with 5, and its motion
    (B 0.4 mm from A at every pose) is the one checked and handed to the gear-mesh check: 5 poses, 0.4 mm."""
    mech = Mech(lambda n: slide_x(np.full(n, 10.4)))
    meshes = Recorder([])
    monkeypatch.setattr(checks, "check_gear_meshes", meshes)
    report = run_checks(design(sla_process, 5, 0.25), two_boxes(), mech, slide_x(np.full(4, 15.0)), [])
    assert mech.calls == [5]
    assert report.interference["poses"] == 5
    assert report.interference["min_clearance_mm"] == pytest.approx(0.4, abs=1e-9)
    assert len(meshes.args) == 1 and meshes.args[0][1] is mech.motions[0]


@pytest.mark.parametrize("given", [4, 6])
def test_motion_with_enough_poses_is_not_reswept(sla_process, monkeypatch, given):
    """4 poses asked of a motion that has 4 (or 6): no call of mechanism.sweep; the given motion is checked
    (``given`` poses, B 1.5 mm clear) and handed to the gear-mesh check."""
    mech = Mech(lambda n: slide_x(np.full(n, 10.4)))
    motion = slide_x(np.full(given, 11.5))
    meshes = Recorder([])
    monkeypatch.setattr(checks, "check_gear_meshes", meshes)
    report = run_checks(design(sla_process, 4, 0.25), two_boxes(), mech, motion, [])
    assert mech.calls == []
    assert report.interference["poses"] == given
    assert report.interference["min_clearance_mm"] == pytest.approx(1.5, abs=1e-9)
    assert meshes.args[0][1] is motion


# -- gathering the failures -------------------------------------------------------------------------
def test_failures_of_all_three_checks_are_gathered_in_order(sla_process, monkeypatch):
    """Sweep failure (0.4 mm against 0.5), two gear meshes (one and two failures) and printability (one):
    all five failures in that order, passed False; the report carries the meshes' and printability's
    reports under ``gear_mesh`` and ``printability``; the stand-ins get the gear pairs, the checked motion,
    the parts, the process and the pins as given."""
    m1, m2 = outcome(["mesh: g1 binds"], {"name": "g1"}), outcome(["mesh: g2 a", "mesh: g2 b"], {"name": "g2"})
    meshes = Recorder([m1, m2])
    printable = outcome(["printability: too thin"], {"process": "stand-in"})
    printing = Recorder(printable)
    monkeypatch.setattr(checks, "check_gear_meshes", meshes)
    monkeypatch.setattr(checks, "check_printability", printing)
    pin = SimpleNamespace(joint="J", bodies=("a", "b"), diameter_mm=2.0, length_mm=2.0, z_mm=0.0)
    partset = SimpleNamespace(parts=[box("A", "a"), box("B", "b")], pins=[pin])  # no hole J: pin not swept
    gear_pairs = [SimpleNamespace(name="g1"), SimpleNamespace(name="g2")]
    motion = slide_x([10.4])
    report = run_checks(design(sla_process, 1, 0.5), partset, Mech(never_swept), motion, gear_pairs)
    assert report.failures == ["clearance: A and B come within 0.400 mm at input 0 deg; the process needs 0.500 mm",
                               "mesh: g1 binds", "mesh: g2 a", "mesh: g2 b", "printability: too thin"]
    assert report.passed is False
    assert report.report()["checks"]["failures"] == report.failures
    assert report.interference["gear_mesh"] == [{"name": "g1"}, {"name": "g2"}]
    assert report.interference["printability"] == {"process": "stand-in"}
    assert report.gear_mesh == (m1, m2) and isinstance(report.gear_mesh, tuple)
    assert report.printability is printable
    assert meshes.args == [(gear_pairs, motion)]
    ((parts, process, pairs, pins),) = printing.args
    assert parts == tuple(partset.parts) and process is sla_process and pairs is gear_pairs
    assert pins == (pin,)
    assert printing.kwargs == [{"margin_mm": 0.0}]  # a design without [parts]: no plate margin


def test_gear_mesh_failures_alone_fail_the_build(sla_process, monkeypatch):
    """Sweep clear (1 mm against 0.25) and printability (real) passing: one gear mesh failure is the only
    failure and the build fails; a mesh with none leaves it passing."""
    monkeypatch.setattr(checks, "check_gear_meshes", Recorder([outcome([], {}), outcome(["mesh: g skips"], {})]))
    report = run_checks(design(sla_process, 1, 0.25), two_boxes(), Mech(never_swept), slide_x([11.0]), [])
    assert report.failures == ["mesh: g skips"] and report.passed is False
    monkeypatch.setattr(checks, "check_gear_meshes", Recorder([outcome([], {"ok": 1})]))
    report = run_checks(design(sla_process, 1, 0.25), two_boxes(), Mech(never_swept), slide_x([11.0]), [])
    assert report.failures == [] and report.passed is True
    assert report.interference["gear_mesh"] == [{"ok": 1}]


def test_real_printability_failures_use_gear_pairs_and_pins(sla_process, monkeypatch):
    """Real printability with a gear pair (tip land 0.1 mm < 0.3 mm minimum feature) and a parts-layer pin of
    1 mm (< 1.5 mm): both failures, in that order, after nothing else (sweep clear, mesh stand-in clean)."""
    monkeypatch.setattr(checks, "check_gear_meshes", Recorder([outcome([], {})]))
    pin = SimpleNamespace(joint="K", bodies=("a", "b"), diameter_mm=1.0, length_mm=2.0, z_mm=0.0)
    partset = SimpleNamespace(parts=(box("A", "a"), box("B", "b")), pins=(pin,))
    pairs = [SimpleNamespace(name="gp", checks={"tip_land_min_mm": 0.1})]
    report = run_checks(design(sla_process, 1, 0.25), partset, Mech(never_swept), slide_x([11.0]), pairs)
    assert report.failures == [
        "printability: gear gp has a 0.100 mm tooth tip land; the process resolves 0.300 mm "
        "(use a larger module or a smaller addendum)",
        "printability: pin K is 1 mm, the process needs 1.5 mm"]
    assert report.passed is False
    assert report.interference["printability"]["passed"] is False
    assert report.interference["printability"]["tip_land_mm"] == {"gp": 0.1}


# -- pins and spacers -------------------------------------------------------------------------------
def pinned_plates(pin_diameter_in_holes: float = 2.0):
    """A (z 0..2) and B (z 2.5..4.5), 10 x 6, each with a 2.5 mm hole for joint J at its origin; B turns
    about it (0, 90, 180 deg). The holes take a ``pin_diameter_in_holes`` pin."""
    hole = Hole("J", np.zeros(2), 2.5, pin_diameter_in_holes)
    parts = (box("A", "a", (10.0, 6.0), holes=(hole,)), box("B", "b", (10.0, 6.0), z=2.5, holes=(hole,)))
    turn = np.column_stack([np.zeros(3), np.zeros(3), np.radians([0.0, 90.0, 180.0])])
    return parts, motion_of(turn)


def pin_rows(report):
    return {(r["a"], r["b"]): r for r in report.pair_table() if "pin_J" in (r["a"], r["b"])}


def test_parts_layer_pins_are_swept_as_given(sla_process):
    """A parts-layer pin of 1.6 mm (holes made for 2 mm) fixed in A: B's hole clears it by (2.5 - 1.6) / 2 =
    0.45 mm (less at most the chord tolerance), not the holes' 0.25 mm."""
    parts, motion = pinned_plates()
    pin = SimpleNamespace(joint="J", bodies=("a", "b"), diameter_mm=1.6, length_mm=4.5, z_mm=0.0)
    report = run_checks(design(sla_process, 3, 0.25), SimpleNamespace(parts=parts, pins=(pin,)),
                        Mech(never_swept), motion, [])
    row = pin_rows(report)[("B", "pin_J")]
    assert row["relation"] == "pin"
    assert 0.45 - sla_process.chord_tolerance_mm <= row["min_clearance_mm"] <= 0.45 + 1e-9
    assert report.passed is True, report.failures


@pytest.mark.parametrize("partset_kw", [{"pins": ()}, {"pins": None}, {}])
def test_without_parts_layer_pins_the_holes_make_them(sla_process, partset_kw):
    """No pins from the parts layer (empty, None, or no attribute): the pin comes from the holes (2 mm), so B's
    hole clears it by (2.5 - 2) / 2 = 0.25 mm (less at most the chord tolerance)."""
    parts, motion = pinned_plates()
    report = run_checks(design(sla_process, 3, 0.2), SimpleNamespace(parts=parts, **partset_kw),
                        Mech(never_swept), motion, [])
    row = pin_rows(report)[("B", "pin_J")]
    assert 0.25 - sla_process.chord_tolerance_mm <= row["min_clearance_mm"] <= 0.25 + 1e-9


def test_spacers_are_passed_to_the_sweep(sla_process):
    """A washer (joint J, on B, 2.5/4 mm, z 4.5..5.5) from the parts layer is swept ('washer_J' rows appear);
    without it (or with no attribute) there are none."""
    parts, motion = pinned_plates()
    washer = SimpleNamespace(joint="J", body="b", centre=(0.0, 0.0), inner_diameter_mm=2.5, outer_diameter_mm=4.0,
                             z_mm=4.5, length_mm=1.0, washer=True)

    def names(partset):
        report = run_checks(design(sla_process, 3, 0.25), partset, Mech(never_swept), motion, [])
        return {n for r in report.pair_table() for n in (r["a"], r["b"])}

    assert "washer_J" in names(SimpleNamespace(parts=parts, pins=(), spacers=(washer,)))
    assert names(SimpleNamespace(parts=parts, pins=(), spacers=())) == {"A", "B", "pin_J"}
    assert names(SimpleNamespace(parts=parts, pins=())) == {"A", "B", "pin_J"}


# -- CheckReport on its own -------------------------------------------------------------------------
def row(a, b, value, *, exact=True, collides=False, ok=True, input_deg=1.0, required=0.25, relation="moving"):
    return {"a": a, "b": b, "relation": relation, "min_clearance_mm": value, "exact": exact,
            "input_deg": input_deg, "required_mm": required, "collides": collides, "ok": ok}


def fake_report(rows, unit="mm", failures=(), passed=True):
    sweep = SimpleNamespace(input_unit=unit, pairs=tuple(rows), pair_row=dict)
    return CheckReport(interference={"k": 1}, failures=list(failures), passed=passed, sweep=sweep)


def test_markdown_sorts_closest_first_none_last_ties_by_names():
    """Rows sort by clearance (a collision's 0 first), then a, then b (D-Z before E-A, M-N before M-Q);
    unknown (None) clearances last, by a then b. Values: 3 decimals; lower bounds '≥ '; None '—'; collisions
    'collides'; input 2 decimals; required with :g; ok yes / **no**; the input unit in the header."""
    rows = [
        row("Z", "X", 0.5, input_deg=12.3456),
        row("Y", "X", 0.5, required=1.0),
        row("M", "Q", 2.0, exact=False, required=0.375),
        row("M", "N", 2.0, exact=False),
        row("P", "Q", None, exact=False),
        row("C", "Q", None),
        row("A", "C", 0.0, collides=True, ok=False, input_deg=-7.005, required=0.1234567),
        row("K", "L", 0.1, ok=False),
        row("E", "A", 0.7),
        row("D", "Z", 0.7),
    ]
    report = fake_report(rows, unit="mm")
    assert report.pair_table() == rows  # in pair order, unsorted
    assert report.pair_table_markdown() == "\n".join([
        "| a | b | relation | min clearance mm | at input mm | required mm | ok |",
        "|---|---|---|---|---|---|---|",
        "| A | C | moving | collides | -7.00 | 0.123457 | **no** |",
        "| K | L | moving | 0.100 | 1.00 | 0.25 | **no** |",
        "| Y | X | moving | 0.500 | 1.00 | 1 | yes |",
        "| Z | X | moving | 0.500 | 12.35 | 0.25 | yes |",
        "| D | Z | moving | 0.700 | 1.00 | 0.25 | yes |",
        "| E | A | moving | 0.700 | 1.00 | 0.25 | yes |",
        "| M | N | moving | ≥ 2.000 | 1.00 | 0.25 | yes |",
        "| M | Q | moving | ≥ 2.000 | 1.00 | 0.375 | yes |",
        "| C | Q | moving | — | 1.00 | 0.25 | yes |",
        "| P | Q | moving | ≥ — | 1.00 | 0.25 | yes |",
    ])


def test_markdown_of_no_pairs_is_the_header():
    """No pairs: just the two header lines (unit 'deg')."""
    assert fake_report([], unit="deg").pair_table_markdown() == HEADER


def test_collides_overrides_lower_bound_prefix():
    """A colliding row reads 'collides' whether or not its value is exact."""
    md = fake_report([row("A", "B", 0.0, exact=False, collides=True, ok=False)]).pair_table_markdown()
    assert md.splitlines()[-1] == "| A | B | moving | collides | 1.00 | 0.25 | **no** |"


def test_report_is_the_interference_and_the_verdict():
    """report(): ``{"interference": <section>, "checks": {"passed", "failures", "not_checked"}}``, failures
    and the not-checked entries as new lists."""
    report = fake_report([], failures=["x", "y"], passed=False)
    out = report.report()
    assert out == {"interference": {"k": 1}, "checks": {"passed": False, "failures": ["x", "y"], "not_checked": []}}
    assert out["checks"]["failures"] is not report.failures
    assert fake_report([]).report() == {"interference": {"k": 1},
                                        "checks": {"passed": True, "failures": [], "not_checked": []}}
    entry = {"check": "interference", "reason": "r"}
    skipped = dataclasses.replace(fake_report([]), not_checked=(entry,)).report()["checks"]
    assert skipped["not_checked"] == [entry] and skipped["not_checked"][0] is not entry


def test_report_is_frozen_and_defaults():
    """CheckReport is frozen, leaves the sweep out of its repr, and defaults to no meshes, no printability."""
    report = fake_report([])
    assert report.gear_mesh == () and report.printability is None
    assert "sweep=" not in repr(report) and "failures=[]" in repr(report)
    with pytest.raises(dataclasses.FrozenInstanceError):
        report.passed = False  # type: ignore[misc]


def test_figures_is_the_clearance_png(sla_process):
    """figures(): exactly ``clearance.png``, a PNG, the same bytes twice."""
    report = run_checks(design(sla_process, 2, 0.25), two_boxes(), Mech(never_swept), slide_x([10.4, 11.0]), [])
    figs = report.figures()
    assert set(figs) == {"clearance.png"}
    assert figs["clearance.png"].startswith(PNG) and figs["clearance.png"] == report.figures()["clearance.png"]


# -- checks that cannot run are "not checked", never passed ----------------------------------------
def test_one_part_alone_has_no_pair_and_the_sweep_is_not_checked(sla_process):
    """A single box: nothing moves against it, so no pair is swept; the interference verdict is null with
    the reason, listed in not_checked, and no failure (the build is not failed for it)."""
    partset = SimpleNamespace(parts=(box("A", "a"),), pins=(), spacers=())
    report = run_checks(design(sla_process, 2, 0.25), partset, Mech(never_swept), slide_x([10.0, 11.0]), [])
    assert report.interference["pairs_checked"] == 0
    assert report.interference["passed"] is None and report.interference["reason"] == checks.NO_PAIRS
    assert report.not_checked == ({"check": "interference", "reason": checks.NO_PAIRS},)
    assert report.failures == [] and report.passed is True  # over the checks that ran (printability)
    assert report.report()["checks"]["not_checked"] == [{"check": "interference", "reason": checks.NO_PAIRS}]


def test_a_motion_of_no_poses_is_not_swept_and_not_checked(sla_process, monkeypatch):
    """No pose to sweep (``sweep_poses`` 0, which only the API can ask for): neither the interference sweep
    nor the gear mesh runs; both are listed as not checked with the reason, and the section says null."""
    monkeypatch.setattr(checks, "sweep_interference", Recorder(None))
    meshes = Recorder([])
    monkeypatch.setattr(checks, "check_gear_meshes", meshes)
    pair = SimpleNamespace(name="g")
    monkeypatch.setattr(checks, "check_printability", Recorder(outcome([], {"passed": True})))
    report = run_checks(design(sla_process, 0, 0.25), two_boxes(), Mech(never_swept), slide_x([]), [pair])
    assert checks.sweep_interference.args == [] and meshes.args == []
    assert report.not_checked == ({"check": "interference", "reason": checks.NO_POSES},
                                  {"check": "gear mesh", "reason": checks.NO_POSES})
    inter = report.interference
    assert inter["poses"] == 0 and inter["pairs_checked"] == 0 and inter["passed"] is None
    assert inter["reason"] == checks.NO_POSES and inter["gear_mesh"] == []
    assert report.passed is True and report.failures == []


# == run_checks on whole builds (formerly tests/test_checks.py) ==================================================
def bare_design(process, poses: int = 360):
    return SimpleNamespace(process=process, checks=ChecksSpec(sweep_poses=poses, min_clearance_mm=None))


# -- four-bar by hand -------------------------------------------------------------------------------
def test_four_bar_build_passes_and_reports(sla_process):
    mech = make_four_bar()
    motion = mech.sweep(360)
    partset = SimpleNamespace(parts=tuple(four_bar_parts(mech)), pins=())
    report = run_checks(bare_design(sla_process), partset, mech, motion, [])
    assert report.passed, report.failures
    inter = report.interference
    assert {"poses", "pairs_checked", "collisions", "min_clearance_mm"} <= set(inter)
    assert inter["poses"] == 360 and inter["collisions"] == []
    # the smallest clearance is a pin in its hole: 0.25 mm radial, less at most the chord tolerance
    assert 0.25 - sla_process.chord_tolerance_mm <= inter["min_clearance_mm"] <= 0.25
    assert report.report()["checks"] == {"passed": True, "failures": [], "not_checked": []}
    png = report.figures()["clearance.png"]
    assert png.startswith(PNG) and png == report.figures()["clearance.png"]
    assert "| crank | coupler | joined | 0.300 |" in report.pair_table_markdown()


def test_four_bar_resweeps_when_given_fewer_poses(sla_process):
    mech = make_four_bar()
    partset = SimpleNamespace(parts=tuple(four_bar_parts(mech)), pins=())
    report = run_checks(bare_design(sla_process, poses=400), partset, mech, mech.sweep(20), [])
    assert report.interference["poses"] == 400


def test_four_bar_forced_onto_one_layer_fails_with_reason(sla_process):
    mech = make_four_bar()
    parts = four_bar_parts(mech, layers={"ground": 0, "crank": 1, "rocker": 2, "coupler": 0})
    report = run_checks(bare_design(sla_process), SimpleNamespace(parts=tuple(parts), pins=()), mech,
                        mech.sweep(360), [])
    assert not report.passed
    pairs = {(c["a"], c["b"]) for c in report.interference["collisions"]}
    assert ("ground", "coupler") in pairs
    hit = next(c for c in report.interference["collisions"] if (c["a"], c["b"]) == ("ground", "coupler"))
    lo, hi = hit["input_ranges"][0]
    assert 60.0 < lo <= hit["input_deg"] <= hi < 420.0 and hit["volume_mm3"] > 1.0
    assert any("ground collides with coupler" in f for f in report.failures)


# -- printability -----------------------------------------------------------------------------------
def test_hole_wall_is_the_analytic_web(sla_process, laser_process):
    """A 6 mm slot with 2.5 mm holes: web (6 - 2.5) / 2 = 1.75 mm (within the chord tolerance);
    enough for SLA (0.8 mm), not for 3 mm laser sheet (web ≥ 3 mm)."""
    part = slot_part("link", "link", ("A", "B"), 30.0, width=6.0)
    walls = dict(hole_walls(part, 0.005))
    assert walls["A"] == pytest.approx(1.75, abs=0.005) and walls["B"] == pytest.approx(1.75, abs=0.005)
    assert check_printability([part], sla_process).passed
    laser_part = dataclasses.replace(part, process="laser")
    result = check_printability([laser_part], laser_process)
    assert any(f.startswith("printability: link has a 1.7") and "wall at hole" in f for f in result.failures)


def test_thin_tab_and_oversize_part_fail(sla_process):
    """A 0.2 mm wide tab on a plate is thinner than the SLA feature size (0.3 mm); a 200 mm plate
    does not fit the 130 × 80 mm build area; a 0.5 mm wall around a hole is under 0.8 mm."""
    tab = np.array([[0, 0], [10, 0], [10, 5], [5.1, 5], [5.1, 9], [4.9, 9], [4.9, 5], [0, 5]], dtype=float)
    part = Part("tab", "b", BulgePath.polyline(tab), (), 3.0, 0.0, 0, "sla")
    assert thin_feature(part, 0.3, 0.005) > 3.0  # the whole 4 mm tab goes
    assert thin_feature(dataclasses.replace(part, outline=BulgePath.polyline(tab[[0, 1, 2, 7]])), 0.3,
                        0.005) == 0.0
    big = slot_part("long", "b", ("A", "B"), 200.0)
    thin_wall = Part("web", "b", BulgePath.polyline(np.array([[0, 0], [10, 0], [10, 4], [0, 4]], float)),
                     (Hole("A", np.array([5.0, 2.0]), 3.0, 2.0),), 3.0, 0.0, 0, "sla")
    failures = check_printability([part, big, thin_wall], sla_process).failures
    assert any("tab has a feature thinner" in f for f in failures)
    assert any("long (" in f and "does not fit the build volume" in f for f in failures)
    assert any("web has a 0.500 mm wall at hole A" in f for f in failures)


def test_laser_parts_must_be_sheet_thick(laser_process):
    part = slot_part("link", "b", ("A", "B"), 30.0, width=12.0, thickness=4.0, process="laser")
    failures = check_printability([part], laser_process).failures
    assert list(failures) == ["printability: link is 4 mm thick, the sheet 3 mm"]


# -- seed-000 through the real layers ----------------------------------------------------------------
@pytest.fixture(scope="module")
def seed000():
    from fabricate.design import load_design
    from fabricate.gears import build_gear_pairs
    from fabricate.parts.build import build_parts
    from fabricate.pipeline import synthesise
    from fabricate.templates import TEMPLATE_DIR

    design = load_design(TEMPLATE_DIR / "finger_five_bar_ncg.toml")
    result = synthesise(design)
    mech = result.mechanism
    motion = mech.sweep(design.checks.sweep_poses + 1)
    pairs = build_gear_pairs(mech, design.gears, design.process.chord_tolerance_mm)
    partset = build_parts(design, mech, motion, pairs, result.parts)
    return design, mech, motion, pairs, partset


def test_seed000_interference_and_mesh_pass(seed000):
    """No collision over 361 poses, every moving pair at least the running clearance, pins at their
    radial hole clearance, the gears in mesh with the design backlash in the assembly."""
    design, mech, motion, pairs, partset = seed000
    report = run_checks(design, partset, mech, motion, pairs)
    inter = report.interference
    assert inter["poses"] == 361 and inter["collisions"] == []
    assert inter["min_clearance_mm"] >= design.process.running_clearance_mm - design.process.chord_tolerance_mm
    assert not [f for f in report.failures if f.startswith(("interference", "clearance", "gear mesh"))]
    for row in inter["pairs"]:
        if row["relation"] == "pin":
            # modelled hole: pin + 2 x running clearance + SLA compensation, radially
            expected = design.process.running_clearance_mm + design.process.hole_compensation_mm / 2
            assert expected - design.process.chord_tolerance_mm <= row["min_clearance_mm"] <= expected + 1e-9
    (mesh,) = inter["gear_mesh"]
    assert mesh["passed"] and mesh["interference_area_mm2"] == 0.0
    assert mesh["law_error_rad"] < 1e-9
    assert mesh["backlash_mm"][0] > 0.0
    meshing = [r for r in inter["pairs"] if r["relation"] == "meshing"]
    assert len(meshing) == 1 and 0.0 < meshing[0]["min_clearance_mm"] < 0.1


def test_seed000_two_bodies_on_one_layer_caught(seed000):
    """The middle phalanx forced onto the gear layer of link_AB: the pair collides and the report
    names it with the inputs and the volume."""
    design, mech, motion, pairs, partset = seed000
    link = partset.part("link_AB")
    parts = tuple(dataclasses.replace(p, z_mm=link.z_mm, layer=link.layer) if p.name == "middle" else p
                  for p in partset.parts)
    broken = dataclasses.replace(partset, parts=parts)
    report = run_checks(design, broken, mech, motion, pairs)
    assert not report.passed
    hit = [c for c in report.interference["collisions"] if {c["a"], c["b"]} == {"link_AB", "middle"}]
    assert len(hit) == 1 and hit[0]["volume_mm3"] > 0.0
    assert motion.inputs.min() <= hit[0]["input_deg"] <= motion.inputs.max()
    assert any("collides with" in f and "middle" in f and "link_AB" in f for f in report.failures)


def test_gear_mesh_check_fails_when_the_assembly_leaves_the_law(seed000):
    """Turn gear b by an extra 3° in the motion: the gear check reports the law error, and the
    interference sweep finds the teeth of the two gear parts overlapping."""
    design, mech, motion, pairs, partset = seed000
    pair = pairs[0]
    q = motion.q.copy()
    q[:, motion.free.index(pair.body_b), 2] += math.radians(3.0)
    moved = Motion(motion.inputs, motion.body_names, motion.ground, motion.free, q, motion.mechanism)
    result = check_gear_mesh(pair, moved)
    assert not result.passed
    assert result.law_error_rad == pytest.approx(math.radians(3.0), rel=1e-9)
    assert any("departs from the gear law" in f for f in result.failures)
    sweep = sweep_interference(partset.parts, moved, chord_tolerance_mm=design.process.chord_tolerance_mm,
                               min_clearance_mm=0.25, pins=partset.pins)
    (gears,) = [p for p in sweep.pairs if p.relation == "meshing"]
    assert gears.collides and len(gears.collision_indices) > len(motion.inputs) // 2


@pytest.mark.slow
def test_colliding_build_exits_1_with_files_and_reason(tmp_path, monkeypatch):
    """``fabricate build`` of the default finger with the middle phalanx forced onto the gear layer
    (the parts layer patched): exit code 1, every file written, report.json names the pair, the
    inputs and the volume, and the checks section says why."""
    import json

    import fabricate.parts.build as parts_build
    from fabricate.cli import main

    original = parts_build.build_parts

    def forced(*args, **kwargs):
        partset = original(*args, **kwargs)
        link = partset.part("link_AB")
        parts = tuple(dataclasses.replace(p, z_mm=link.z_mm, layer=link.layer) if p.name == "middle" else p
                      for p in partset.parts)
        return dataclasses.replace(partset, parts=parts)

    monkeypatch.setattr(parts_build, "build_parts", forced)
    out = tmp_path / "broken"
    assert main(["build", "-o", str(out), "--quiet"]) == 1
    report = json.loads((out / "report.json").read_text())
    assert report["checks"]["passed"] is False
    hit = [c for c in report["interference"]["collisions"] if {c["a"], c["b"]} == {"link_AB", "middle"}]
    assert len(hit) == 1 and hit[0]["volume_mm3"] > 0.0 and "input_deg" in hit[0]
    assert any("collides with" in f and "middle" in f for f in report["checks"]["failures"])
    assert all((out / f).is_file() for f in report["files"])
    assert (out / "plots" / "clearance.png").is_file()
