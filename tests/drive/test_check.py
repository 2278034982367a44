"""The drive check: the input effort against an independent virtual-work computation, its verdicts (pass, too
weak, not checked, wrong kind of actuator) and every shipped template driven by its actuator."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fabricate.cli import main
from fabricate.design import design_from_text
from fabricate.drive.check import NO_ACTUATOR, NO_LOAD, drive_markdown, input_statics, run_drive
from fabricate.errors import SpecError
from fabricate.pipeline import synthesise
from fabricate.templates import shipped_templates

# A crank-slider: crank r about O (drawn at 60 deg), rod l from A to the slider point S2 on the x axis.
R, L, START_DEG = 10.0, 30.0, 60.0
AX, AY = R * math.cos(math.radians(START_DEG)), R * math.sin(math.radians(START_DEG))
S0 = AX + math.sqrt(L * L - AY * AY)


def crank_slider(load: str, actuator: str, *, driver: str = "O", unit: str = "deg",
                 input_range: str = "[0.0, 90.0]") -> str:
    """The crank-slider template: driven at the crank (``driver = "O"``, deg) or on the slide (``"S"``, mm)."""
    return f"""
[design]
name = "crank_slider"
kind = "linkage"

[process]
profile = "sla"
pin_diameter_mm = 3.0

{load}

{actuator}

[linkage]
ground = "frame"
input_unit = "{unit}"
input_range = {input_range}
tip_point = "S2"

[[linkage.bodies]]
name = "frame"
points = {{ O = [0.0, 0.0], S = [{S0!r}, 0.0] }}

[[linkage.bodies]]
name = "crank"
points = {{ O = [0.0, 0.0], A = [{AX!r}, {AY!r}] }}

[[linkage.bodies]]
name = "rod"
points = {{ A = [{AX!r}, {AY!r}], S2 = [{S0!r}, 0.0] }}

[[linkage.bodies]]
name = "slider"
points = {{ S = [{S0!r}, 0.0], S2 = [{S0!r}, 0.0] }}

[[linkage.joints]]
name = "O"
type = "revolute"
bodies = ["frame", "crank"]

[[linkage.joints]]
name = "A"
type = "revolute"
bodies = ["crank", "rod"]

[[linkage.joints]]
name = "S2"
type = "revolute"
bodies = ["rod", "slider"]

[[linkage.joints]]
name = "S"
type = "slider"
bodies = ["frame", "slider"]
axis = [1.0, 0.0]

[[linkage.drivers]]
joint = "{driver}"
law = "linear"
"""


#: 2 N on the slider point, pushing it towards -x (against the crank at every pose of [0, 90] deg).
PUSH = '[load]\ntip_force_N = 2.0\ntip_point = "S2"\ntip_force_deg = 180.0'


def _drive(text: str, poses: int = 91, copies: int = 1):
    design = design_from_text(text, "crank_slider.toml")
    result = synthesise(design)
    motion = result.mechanism.sweep(np.linspace(*result.mechanism.input_range, poses))
    return design, result, motion, run_drive(design, result.mechanism, motion, result.parts, copies=copies)


def _slider_x(phi: np.ndarray) -> np.ndarray:
    """The slider's x for an absolute crank angle ``phi`` (rad): the crank-slider's closed form."""
    return R * np.cos(phi) + np.sqrt(L * L - (R * np.sin(phi)) ** 2)


def test_the_effort_equals_virtual_work_on_an_independent_position_analysis() -> None:
    # virtual work: the crank torque τ and the force F on the slider do no net work, τ dφ + F·dx = 0, so
    # τ = -F_x dx/dφ with F_x = -2 N; dx/dφ by central differences of the closed form (step 1e-6 rad: the
    # truncation error ~1e-12 relative, the rounding ~1e-10), against the statics' multiplier to 1e-6 relative
    design, result, motion, drive = _drive(crank_slider(PUSH, '[actuator]\nmodel = "mg90s"'))
    phi = np.radians(START_DEG + motion.inputs)
    h = 1e-6
    dx = (_slider_x(phi + h) - _slider_x(phi - h)) / (2.0 * h)
    force_x = -2.0
    expected = -force_x * dx
    statics = input_statics(design, result.mechanism, motion, result.parts)
    assert statics is not None
    np.testing.assert_allclose(statics.driver_efforts[:, 0], expected, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(drive.effort, np.abs(expected), rtol=1e-6, atol=1e-9)
    assert drive.unit == "N·mm" and drive.travel == pytest.approx(90.0)
    k = drive.peak
    assert drive.effort[k] == pytest.approx(np.abs(expected).max(), rel=1e-6)


def test_a_strong_enough_servo_passes_and_reports_its_numbers() -> None:
    *_, drive = _drive(crank_slider(PUSH, '[actuator]\nmodel = "mg90s"\nmargin = 2.0'))
    assert drive.passed is True and drive.failures() == []
    section = drive.report()
    assert section["actuator"]["key"] == "mg90s" and section["rating_kind"] == "stall"
    assert section["allowed"] == pytest.approx(section["rating"] / 2.0, rel=1e-5)
    assert section["least_margin"] == pytest.approx(section["rating"] / section["peak_effort"], rel=1e-5)
    # 90 deg at the MG90S's 600 deg/s (0.1 s/60 deg)
    assert section["speed"]["full_travel_s"] == pytest.approx(0.15, rel=1e-6)
    text = "\n".join(drive_markdown(section))
    assert "passed" in text and "mg90s" in text and "plots/drive.png" in text


def test_copies_driven_together_add_up() -> None:
    *_, one = _drive(crank_slider(PUSH, '[actuator]\nmodel = "mg90s"'), poses=11)
    *_, three = _drive(crank_slider(PUSH, '[actuator]\nmodel = "mg90s"'), poses=11, copies=3)
    np.testing.assert_allclose(three.effort, 3.0 * one.effort, rtol=1e-12)


def test_no_actuator_and_no_load_are_not_checked_never_passed() -> None:
    *_, none = _drive(crank_slider(PUSH, ""), poses=11)
    assert none.passed is None and none.reason == NO_ACTUATOR and none.failures() == []
    *_, unloaded = _drive(crank_slider("", '[actuator]\nmodel = "sg90"'), poses=11)
    assert unloaded.passed is None and unloaded.reason == NO_LOAD and unloaded.failures() == []
    assert "not checked" in "\n".join(drive_markdown(unloaded.report()))


def test_an_actuator_of_the_wrong_kind_or_driver_is_a_spec_error() -> None:
    with pytest.raises(SpecError) as err:
        _drive(crank_slider(PUSH, '[actuator]\nmodel = "tendon"\nforce_N = 50.0'), poses=5)
    assert err.value.path == "actuator.model" and "angle" in str(err.value) and "sg90" in str(err.value)
    with pytest.raises(SpecError) as err:
        _drive(crank_slider(PUSH, '[actuator]\nmodel = "sg90"\ndriver = 1'), poses=5)
    assert err.value.path == "actuator.driver"


def test_a_push_rod_on_the_slide_is_held_to_its_force_and_its_stroke() -> None:
    # driven on the slide (mm) from the drawn pose 10 mm towards the crank; 2 N at S2 along +x
    load = '[load]\ntip_force_N = 2.0\ntip_point = "S2"\ntip_force_deg = 0.0'
    text = crank_slider(load, '[actuator]\nmodel = "tendon"\nforce_N = 2.5\nstroke_mm = 8.0', driver="S",
                        unit="mm", input_range="[0.0, -10.0]")
    *_, drive = _drive(text, poses=21)
    assert drive.unit == "N"
    # the slider's own force balance: the push along the slide holds the 2 N on the same point
    np.testing.assert_allclose(drive.effort, 2.0, rtol=1e-9)
    assert drive.travel == pytest.approx(10.0)
    failures = drive.failures()
    assert len(failures) == 2 and drive.passed is False
    assert "2.5 N (stated) / margin 1.5" in failures[0] and "strokes 8 mm" in failures[1]


FOUR_BAR = """
[design]
name = "four_bar"
kind = "linkage"

[process]
profile = "sla"
pin_diameter_mm = 3.0

[checks]
sweep_poses = 90

[load]
tip_force_N = 8.0
tip_point = "B"

[actuator]
model = "sg90"

[linkage]
ground = "frame"
input_unit = "deg"
input_range = [0.0, 90.0]
tip_point = "B"

[[linkage.bodies]]
name = "frame"
points = { O = [0.0, 0.0], D = [40.0, 0.0] }

[[linkage.bodies]]
name = "crank"
points = { O = [0.0, 0.0], A = [15.0, 0.0] }

[[linkage.bodies]]
name = "coupler"
points = { A = [15.0, 0.0], B = [40.0, 30.0] }

[[linkage.bodies]]
name = "rocker"
points = { D = [40.0, 0.0], B = [40.0, 30.0] }

[[linkage.joints]]
name = "O"
type = "revolute"
bodies = ["frame", "crank"]

[[linkage.joints]]
name = "A"
type = "revolute"
bodies = ["crank", "coupler"]

[[linkage.joints]]
name = "B"
type = "revolute"
bodies = ["coupler", "rocker"]

[[linkage.joints]]
name = "D"
type = "revolute"
bodies = ["frame", "rocker"]

[[linkage.drivers]]
joint = "O"
law = "linear"
"""


@pytest.mark.slow
def test_a_servo_too_weak_exits_1_naming_the_actuator_and_the_pose(tmp_path: Path, capsys) -> None:
    # a four-bar crank (15 mm) with 8 N against the motion of B: the crank needs up to 144 N·mm, more than the
    # SG90's 176.5 / 1.5 = 118 N·mm; the parts are strong enough, so the drive is the one failure
    path = tmp_path / "weak.toml"
    path.write_text(FOUR_BAR, encoding="utf-8")
    out = tmp_path / "out"
    code = main(["build", str(path), "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 1
    line = next(x for x in (captured.out + captured.err).splitlines() if x.strip().startswith("- drive:"))
    report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    drive = report["drive"]
    assert drive["passed"] is False and drive["peak_effort"] > drive["allowed"]
    assert [f for f in report["checks"]["failures"] if not f.startswith("drive:")] == []
    assert "SG90" in line and "(sg90)" in line
    assert f"{drive['peak_effort']:.4g} N·mm at input {drive['peak_input']:.4g} deg" in line
    assert (out / "plots" / "drive.png").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("template", [p.stem for p in shipped_templates()])
def test_every_shipped_template_is_driven_by_its_actuator(template: str, shipped_build) -> None:
    outcome = shipped_build(template)
    assert outcome.design is not None and outcome.design.actuator is not None, "no [actuator]"
    drive = outcome.report["drive"]
    assert drive["passed"] is True, drive
    assert drive["peak_effort"] <= drive["allowed"] and drive["least_margin"] >= drive["margin"]
    assert not any(f.startswith("drive:") for f in outcome.failures)
    assert "plots/drive.png" in outcome.files
    assert "## Drive" in outcome.files["report.md"].decode("utf-8")


def test_a_stepper_held_to_its_holding_torque_says_it_assumes_a_slow_motion() -> None:
    """The catalogue has no pull-out curve for its steppers: the check holds a NEMA 17 to its holding torque
    (its stall value) and the report says what that assumes; a servo's stall value carries no such note."""
    *_, stepper = _drive(crank_slider(PUSH, '[actuator]\nmodel = "nema17"'), poses=11)
    assert stepper.rating_kind == "stall" and stepper.rating == pytest.approx(400.0)
    assert [n for n in stepper.notes if "pull-out" in n and "holding torque" in n]
    *_, servo = _drive(crank_slider(PUSH, '[actuator]\nmodel = "mg90s"'), poses=11)
    assert servo.rating_kind == "stall" and not [n for n in servo.notes if "pull-out" in n]


@pytest.mark.slow
def test_the_mount_plate_bears_the_reaction_torque(shipped_build) -> None:
    """The gear pair's NEMA 17 on its mount plate: its peak torque T comes back through the two standoff screws
    at radii r_i about the axis as F = T max(r) / sum(r**2) each, bearing F / (d t) on the plate, recomputed here
    from the placed standoffs; the same plate under 1e4 times the torque fails naming the plate."""
    from fabricate.drive.check import DriveResult, rate_mount

    outcome = shipped_build("gear_pair_elliptic")
    placed, partset = outcome.partset.actuator, outcome.partset
    torque = outcome.report["drive"]["peak_effort"]
    r = np.array([np.hypot(*(np.asarray(s.centre) - placed.axis)) for s in placed.standoffs])
    t = partset.part(placed.mount_part).thickness_mm
    stress = torque * r.max() / np.sum(r ** 2) / (3.0 * t)  # M3 standoff screws
    (note,) = [n for n in outcome.report["drive"]["notes"] if "standoff screws" in n]
    assert f"bearing {stress:.3g} MPa" in note and f"{len(r)} at up to {r.max():.3g} mm" in note
    material = outcome.design.process.part_material()
    assert f"safety factor {material.compressive_MPa / stress:.3g}" in note
    assert not any(f.startswith("drive: mount plate") for f in outcome.failures)
    entry = outcome.design.actuator.entry()
    heavy = DriveResult(outcome.design.actuator, entry, np.zeros(1), "deg", effort=np.array([torque * 1e4]))
    rate_mount(heavy, partset, outcome.design)
    assert [f for f in heavy.failures() if f.startswith(f"drive: mount plate {placed.mount_part}, standoff screws")]
