"""kind = "linkage": a declared planar linkage through the pipeline (issue 13).

The shipped linkages against position analyses written here from their published or stated numbers
(circle intersections and closed forms, no fabricate code), and every bad linkage against its exit code
and a message that names the joint. The shipped templates' full builds (interference, strength, exports)
are the parametrised tests of tests/test_cli.py and tests/export/test_export.py.
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from fabricate.cli import main
from fabricate.design import design_from_text, load_design
from fabricate.errors import LockupError, SpecError
from fabricate.hints import PartHints
from fabricate.pipeline import synthesise
from fabricate.templates import TEMPLATE_DIR

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


# -- an independent position analysis -------------------------------------------------------------

def _circles(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float, side: float) -> np.ndarray:
    """The intersection of two circles left (side +1) or right (-1) of the line c1 -> c2."""
    d = c2 - c1
    dist = math.hypot(d[0], d[1])
    along = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist)
    height = math.sqrt(r1 * r1 - along * along)
    u = d / dist
    return c1 + along * u + side * height * np.array([-u[1], u[0]])


#: Jansen's holy numbers (strandbeest.com; Jansen, The Great Pretender, 2007).
HOLY = dict(a=38.0, b=41.5, c=39.3, d=40.1, e=55.8, f=39.4, g=36.7, h=65.7, i=49.0, j=50.0, k=61.9, l=7.8, m=15.0)


def jansen_foot(crank_deg: float) -> np.ndarray:
    """Foot of Jansen's leg for a crank angle (deg from +x, counter-clockwise), crank axle at the origin.

    Standard labelling: fixed pivot B = (-a, -l); crank m to A; C = (j from A) ∩ (b from B) above A-B;
    D = (d from B) ∩ (e from C), left of B->C; E = (k from A) ∩ (c from B), below A-B; knee F = (f from D)
    ∩ (g from E); foot = (h from F) ∩ (i from E), below.
    """
    t = math.radians(crank_deg)
    n = HOLY
    b = np.array([-n["a"], -n["l"]])
    a = n["m"] * np.array([math.cos(t), math.sin(t)])
    c = _circles(a, n["j"], b, n["b"], -1.0)
    d = _circles(b, n["d"], c, n["e"], +1.0)
    e = _circles(a, n["k"], b, n["c"], +1.0)
    f = _circles(d, n["f"], e, n["g"], -1.0)
    return _circles(f, n["h"], e, n["i"], -1.0)


def test_jansen_foot_path_equals_an_independent_position_analysis():
    design = load_design("jansen_leg")
    assert design.kind == "linkage" and design.method.tip_point == "foot"
    mech = synthesise(design).mechanism
    inputs = np.linspace(0.0, 360.0, 145)  # every 2.5 deg: 144 crank angles
    foot = mech.sweep(inputs).point("foot")
    expected = np.array([jansen_foot(s) for s in inputs])
    error = np.hypot(*(foot - expected).T)
    assert error.max() < 1e-6, error.max()
    # the walking leg: a stride of about 50 mm, the foot flat along the bottom of its path
    assert 45.0 < np.ptp(expected[:, 0]) < 75.0
    # every bar keeps its holy length over the motion (the template's points are the assembled leg)
    motion = mech.sweep(inputs)
    for (p, q), length in {("O", "A"): "m", ("A", "C"): "j", ("B", "C"): "b", ("A_k", "E_k"): "k",
                           ("B_c", "E"): "c", ("D", "F"): "f", ("F", "foot"): "h", ("E", "foot"): "i"}.items():
        owner = next(b.name for b in mech.bodies if p in b.points and q in b.points)
        span = np.hypot(*(motion.point(p, owner) - motion.point(q, owner)).T)
        assert np.allclose(span, HOLY[length], atol=1e-9), (p, q)


def test_start_away_from_the_reference_pose_is_reached_on_the_drawn_branch():
    """input_range starting at 90 deg with the points drawn at crank 0: the leg moves there first."""
    text = (TEMPLATE_DIR / "jansen_leg.toml").read_text(encoding="utf-8")
    text = text.replace("input_range = [0.0, 360.0]", "input_range = [90.0, 450.0]")
    design = design_from_text(text, "jansen_90.toml")
    assert design.method.reference == 0.0 and design.method.input_range == (90.0, 450.0)
    mech = synthesise(design).mechanism
    inputs = np.linspace(90.0, 450.0, 73)
    foot = mech.sweep(inputs).point("foot")
    expected = np.array([jansen_foot(s) for s in inputs])
    assert np.max(np.hypot(*(foot - expected).T)) < 1e-6


# -- the quick return ------------------------------------------------------------------------------

def _quick_return_numbers() -> dict[str, float]:
    """Lengths, eccentricity and reference crank angle read from the template (TOML, not fabricate)."""
    data = tomllib.loads((TEMPLATE_DIR / "linkage_quick_return.toml").read_text(encoding="utf-8"))
    pts = {b["name"]: {k: np.array(v) for k, v in b["points"].items()} for b in data["linkage"]["bodies"]}
    frame = pts["frame"]
    ob, d, p, q = frame["OB"], frame["D"], pts["crank"]["P"], pts["coupler"]["Q"]
    (gear,) = data["linkage"]["gears"]
    return {"crank": float(np.hypot(*(p - ob))), "coupler": float(np.hypot(*(q - p))),
            "rocker": float(np.hypot(*(q - d))), "ground": float(np.hypot(*(d - ob))),
            "e": float(gear["eccentricity"]), "phi_ref": math.atan2(p[1] - ob[1], p[0] - ob[0]),
            "d_x": float(d[0]), "ob_x": float(ob[0])}


def test_quick_return_time_ratio_equals_the_closed_form():
    n = _quick_return_numbers()
    r, l3, l4, g, e = n["crank"], n["coupler"], n["rocker"], n["ground"], n["e"]
    # dead centres: crank and coupler in line, the rocker pin Q at l3 + r (extended) or l3 - r (folded)
    # from the crank axle; Q above the ground line (the template's branch); ground along +x
    dead = []
    for reach, extended in ((l3 + r, True), (l3 - r, False)):
        cos_q = (reach * reach + g * g - l4 * l4) / (2.0 * reach * g)
        angle_q = math.acos(cos_q)  # angle of OB->Q above the ground line
        dead.append(angle_q if extended else angle_q + math.pi)
    # gear b (the crank) turns clockwise, y counted in its own sense from the reference pose;
    # x(y) = y + 2 atan(e sin y / (1 - e cos y)) inverts the elliptic law y = x - 2 atan(e sin x / (1 + e cos x))
    ys = [(n["phi_ref"] - phi) % (2 * math.pi) for phi in dead]
    xs = [math.degrees(y + 2.0 * math.atan(e * math.sin(y) / (1.0 - e * math.cos(y)))) for y in ys]
    one = (xs[1] - xs[0]) % 360.0
    closed_form = max(one, 360.0 - one) / min(one, 360.0 - one)

    mech = synthesise(load_design("linkage_quick_return")).mechanism
    inputs = np.linspace(0.0, 360.0, 3601)
    motion = mech.sweep(inputs)
    rocker = np.unwrap(motion.pose("rocker")[:, 2])
    extremes = []
    for k in (int(np.argmax(rocker)), int(np.argmin(rocker))):
        k = min(max(k, 1), len(inputs) - 2)
        y0, y1, y2 = rocker[k - 1:k + 2]
        shift = 0.5 * (y0 - y2) / (y0 - 2.0 * y1 + y2)  # vertex of the parabola through three samples
        extremes.append(inputs[k] + shift * (inputs[1] - inputs[0]))
    assert sorted(extremes) == pytest.approx(sorted(xs), abs=1e-3)
    measured = (extremes[1] - extremes[0]) % 360.0
    ratio = max(measured, 360.0 - measured) / min(measured, 360.0 - measured)
    assert ratio == pytest.approx(closed_form, rel=1e-5)
    # the gears make the return quick: 2.61 against the four-bar's own 1.20 at constant crank speed
    four_bar = (dead[1] - dead[0]) % (2 * math.pi)
    assert closed_form > 2.5 and max(four_bar, 2 * math.pi - four_bar) / min(four_bar, 2 * math.pi - four_bar) < 1.25


def test_stephenson_is_a_one_dof_stephenson_chain():
    design = load_design("linkage_stephenson")
    mech = synthesise(design).mechanism
    assert mech.degrees_of_freedom() == 1 and len(mech.bodies) == 6 and len(mech.joints) == 7
    joints_of = {b.name: {j.name for j in mech.joints if b.name in (j.body_a, j.body_b)} for b in mech.bodies}
    ternary = [name for name, js in joints_of.items() if len(js) == 3]
    assert sorted(ternary) == ["coupler", "frame"]
    assert not joints_of["coupler"] & joints_of["frame"]  # the ternaries share no joint: Stephenson, not Watt
    # the coupler point C against the four-bar's own circle intersections
    inputs = np.linspace(0.0, 360.0, 73)
    c = mech.sweep(inputs).point("C", "coupler")
    for s, got in zip(inputs, c, strict=True):
        a = 15.0 * np.array([math.cos(math.radians(s)), math.sin(math.radians(s))])
        b = _circles(a, 45.0, np.array([50.0, 0.0]), 35.0, +1.0)
        u = (b - a) / 45.0
        assert np.allclose(got, a + 25.0 * u + 18.0 * np.array([-u[1], u[0]]), atol=1e-6)


# -- bad linkages ----------------------------------------------------------------------------------

def four_bar(*, b_coupler: str = "[40.0, 30.0]", second_body: str = "rocker", extra: str = "", crank: float = 15.0,
             coupler: float = 0.0, rocker: float = 0.0, ground: float = 40.0, drivers: str | None = None) -> str:
    """A four-bar template: ground O-D on +x, crank O-A along +x at the reference pose, B above.

    The coupler and rocker lengths follow from B = (40, 30) unless B is given through the lengths.
    """
    b = np.array([40.0, 30.0])
    if coupler and rocker:
        b = _circles(np.array([crank, 0.0]), coupler, np.array([ground, 0.0]), rocker, +1.0)
    b_text = f"[{float(b[0])!r}, {float(b[1])!r}]"
    if b_coupler == "[40.0, 30.0]":
        b_coupler = b_text
    drivers = drivers if drivers is not None else '[[linkage.drivers]]\njoint = "O"\nlaw = "linear"\n'
    return f"""
[design]
name = "bad_four_bar"
kind = "linkage"

[checks]
sweep_poses = 360

[linkage]
ground = "frame"
input_unit = "deg"
input_range = [0.0, 360.0]

[[linkage.bodies]]
name = "frame"
points = {{ O = [0.0, 0.0], D = [{ground!r}, 0.0] }}

[[linkage.bodies]]
name = "crank"
points = {{ O = [0.0, 0.0], A = [{crank!r}, 0.0] }}

[[linkage.bodies]]
name = "coupler"
points = {{ A = [{crank!r}, 0.0], B = {b_coupler} }}

[[linkage.bodies]]
name = "rocker"
points = {{ D = [{ground!r}, 0.0], B = {b_text} }}
{extra}
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
bodies = ["coupler", "{second_body}"]

[[linkage.joints]]
name = "D"
type = "revolute"
bodies = ["frame", "rocker"]

{drivers}
"""


def _build(tmp_path: Path, text: str, capsys) -> tuple[int, str, Path]:
    path = tmp_path / "bad_four_bar.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    code = main(["build", str(path), "-o", str(out)])
    captured = capsys.readouterr()
    return code, captured.out + captured.err, out


def test_a_good_four_bar_passes_validation():
    design = design_from_text(four_bar(), "four_bar.toml")
    mech = synthesise(design).mechanism
    assert mech.degrees_of_freedom() == 1
    a = mech.sweep(np.array([0.0, 90.0])).point("A")
    assert np.allclose(a, [[15.0, 0.0], [0.0, 15.0]], atol=1e-9)


def test_does_not_assemble_exits_2_naming_the_joint(tmp_path, capsys):
    code, text, out = _build(tmp_path, four_bar(b_coupler="[40.0, 30.5]"), capsys)
    assert code == 2 and not out.exists()
    assert "linkage.joints[2]" in text and 'joint "B" does not assemble at the reference pose' in text
    assert "0.5 mm apart" in text


def test_two_degrees_of_freedom_with_one_driver_exits_2_naming_the_joint(tmp_path, capsys):
    # a fifth body between coupler and rocker: a five-bar, two degrees of freedom, one driver
    extra = ('\n[[linkage.bodies]]\nname = "link"\npoints = { B = [40.0, 30.0], B2 = [40.0, 30.0] }\n'
             '\n[[linkage.joints]]\nname = "B2"\ntype = "revolute"\nbodies = ["link", "rocker"]\n')
    text5 = four_bar(second_body="link", extra=extra).replace(
        'points = { D = [40.0, 0.0], B = [40.0, 30.0] }', 'points = { D = [40.0, 0.0], B2 = [40.0, 30.0] }')
    code, text, out = _build(tmp_path, text5, capsys)
    assert code == 2 and not out.exists()
    assert "linkage.drivers" in text and "2 degrees of freedom but 1 driver" in text
    assert 'joint "O"' in text and "add a driver or a joint" in text


def test_a_joint_naming_an_unknown_body_exits_2_naming_the_joint(tmp_path, capsys):
    code, text, out = _build(tmp_path, four_bar(second_body="rockr"), capsys)
    assert code == 2 and not out.exists()
    assert "linkage.joints[2].bodies" in text and 'joint "B": unknown body "rockr"' in text


def test_lockup_inside_the_range_exits_1_with_where(tmp_path, capsys):
    # crank 25, coupler 30, rocker 20, ground 40: not a crank; A is 50 mm from D (coupler and rocker in
    # line at B) at cos(theta) = (25^2 + 40^2 - 50^2) / (2 * 25 * 40)
    code, text, out = _build(tmp_path, four_bar(crank=25.0, coupler=30.0, rocker=20.0), capsys)
    dead = math.degrees(math.acos((25.0**2 + 40.0**2 - 50.0**2) / (2 * 25.0 * 40.0)))
    assert code == 1 and (out / "report.json").is_file()
    assert 'driven joint "O"' in text and 'dead point at joint "B"' in text
    where = float(re.search(r"at input ([-0-9.e+]+)", text).group(1))
    assert where == pytest.approx(dead, abs=0.01)
    assert 97.0 < dead < 98.0


def test_lockup_between_the_reference_and_the_start_is_reported_by_the_sweep():
    # drawn at crank 0 (the reference), swept over 120..130 deg: beyond the dead point at 97.9 deg
    text = four_bar(crank=25.0, coupler=30.0, rocker=20.0).replace("input_range = [0.0, 360.0]",
                                                                    "input_range = [120.0, 130.0]")
    text = text.replace('law = "linear"\n', 'law = "linear"\nreference = 0.0\n')
    mech = synthesise(design_from_text(text, "x.toml")).mechanism
    with pytest.raises(LockupError, match="cannot move from the reference pose"):
        mech.sweep(11)


@pytest.mark.parametrize(("edit", "field", "needle"), [
    (lambda t: t.replace('name = "rocker"', 'name = "coupler"'), "linkage.bodies[3].name",
     'duplicate body name "coupler"'),
    (lambda t: t.replace('name = "D"\ntype', 'name = "X"\ntype'), "linkage.joints[3].name",
     'joint "X": body "frame" has no point "X"'),
    (lambda t: t.replace('ground = "frame"', 'ground = "base"'), "linkage.ground", 'unknown body "base"'),
    (lambda t: t.replace("A = [15.0, 0.0] }", "A = [1500.0, 0.0] }", 1), "linkage.bodies[1].points.A[0]",
     "expected a number <= 1000"),
    (lambda t: t.replace('joint = "O"', 'joint = "Z"'), "linkage.drivers[0].joint", 'unknown joint "Z"'),
    (lambda t: t.replace('input_unit = "deg"', 'input_unit = "mm"'), "linkage.drivers[0].law",
     'a linear driver of a revolute needs input_unit = "deg"'),
    (lambda t: t.replace('type = "revolute"\nbodies = ["frame", "crank"]',
                         'type = "hinge"\nbodies = ["frame", "crank"]'), "linkage.joints[0].type", "expected one of"),
])
def test_invalid_fields_name_the_field(edit, field, needle):
    with pytest.raises(SpecError) as info:
        design_from_text(edit(four_bar()), "x.toml")
    assert info.value.path == field and needle in info.value.message, str(info.value)


# -- gears, sliders, tables ------------------------------------------------------------------------

GEARED = """
[design]
name = "geared"
kind = "linkage"

[gears]
teeth = [30, 30]

[linkage]
ground = "frame"
input_unit = "deg"
input_range = [0.0, 360.0]

[[linkage.bodies]]
name = "frame"
points = { OA = [0.0, 0.0], OB = [40.0, 0.0] }

[[linkage.bodies]]
name = "gear_a"
points = { OA = [0.0, 0.0] }

[[linkage.bodies]]
name = "gear_b"
points = { OB = [40.0, 0.0] }

[[linkage.joints]]
name = "OA"
type = "revolute"
bodies = ["frame", "gear_a"]

[[linkage.joints]]
name = "OB"
type = "revolute"
bodies = ["frame", "gear_b"]

[[linkage.gears]]
name = "g"
carrier = "frame"
bodies = ["gear_a", "gear_b"]
axes = ["OA", "OB"]
LAW

[[linkage.drivers]]
joint = "OA"
"""


def test_periodic_table_gear_law_closes_and_follows_the_samples():
    # samples of the elliptic law (e = 0.2) over one turn: a closed pair through a periodic spline
    x = np.linspace(0.0, 2 * np.pi, 73)
    y = x - 2 * np.arctan(0.2 * np.sin(x) / (1 + 0.2 * np.cos(x)))
    law = (f'law = "table"\nx_deg = {np.degrees(x).tolist()!r}\ny_deg = {np.degrees(y).tolist()!r}\n'
           'spline = "periodic"\nclosed = true')
    mech = synthesise(design_from_text(GEARED.replace("LAW", law), "g.toml")).mechanism
    inputs = np.linspace(0.0, 720.0, 145)  # two turns of gear a: the law repeats
    turned = -mech.sweep(np.linspace(0.0, 720.0, 145)).relative_angle("gear_b", "frame")
    s = np.radians(inputs)
    exact = s - 2 * np.arctan2(0.2 * np.sin(s), 1 + 0.2 * np.cos(s))
    assert np.max(np.abs(turned - exact)) < 1e-4  # a spline through 73 samples of the law
    assert abs(turned[-1] - 4 * np.pi) < 1e-12 and abs(turned[72] - 2 * np.pi) < 1e-12


@pytest.mark.parametrize(("law", "field", "needle"), [
    ('law = "table"\nx_deg = [0.0, 180.0, 360.0]\ny_deg = [0.0, 180.0, 360.0]\nspline = "pchip"',
     "linkage.gears[0].spline", 'a closed pair needs spline = "periodic"'),
    ('law = "expression"\nexpression = "x + 0.1"', "linkage.gears[0]",
     'gear "g" does not assemble at the reference pose'),
    ('law = "expression"\nexpression = "x + 0.1*x*x"', "linkage.gears[0].law", "must repeat its ratio"),
])
def test_bad_gear_laws_name_the_field(law, field, needle):
    text = GEARED.replace("LAW", law)
    with pytest.raises(SpecError) as info:
        synthesise(design_from_text(text, "g.toml"))
    assert info.value.path == field and needle in info.value.message, str(info.value)


def test_gear_axis_must_join_the_carrier_and_its_gear():
    text = GEARED.replace("LAW", 'law = "constant"\nratio = 1.0').replace('axes = ["OA", "OB"]', 'axes = ["OA", "OA"]')
    with pytest.raises(SpecError) as info:
        design_from_text(text, "g.toml")
    assert info.value.path == "linkage.gears[0].axes"
    assert 'joint "OA" joins [\'frame\', \'gear_a\'], not the carrier "frame" and gear "gear_b"' in info.value.message


@pytest.mark.parametrize("guide_x", [None, 20.0])
def test_slider_crank_driven_on_the_slide(guide_x):
    """The slide is measured from the reference pose, wherever the guide's point lies on the slide line."""
    # crank 10 about O, rod 30 to the slider point S on the x axis; the slide is the input (mm)
    # drawn with the crank at 60 deg: A = (5, 8.66), S on the x axis 30 from A
    ax, ay = 5.0, 10.0 * math.sin(math.radians(60.0))
    s0 = ax + math.sqrt(900.0 - ay * ay)
    text = f"""
[design]
name = "slider_crank"
kind = "linkage"

[linkage]
ground = "frame"
input_unit = "mm"
input_range = [0.0, -10.0]

[[linkage.bodies]]
name = "frame"
points = {{ O = [0.0, 0.0], S = [{s0 if guide_x is None else guide_x!r}, 0.0] }}

[[linkage.bodies]]
name = "crank"
points = {{ O = [0.0, 0.0], A = [{ax!r}, {ay!r}] }}

[[linkage.bodies]]
name = "rod"
points = {{ A = [{ax!r}, {ay!r}], S2 = [{s0!r}, 0.0] }}

[[linkage.bodies]]
name = "slider"
points = {{ S = [{s0!r}, 0.0], S2 = [{s0!r}, 0.0] }}

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
joint = "S"
law = "linear"
"""
    mech = synthesise(design_from_text(text, "sc.toml")).mechanism
    inputs = np.linspace(0.0, -10.0, 21)
    motion = mech.sweep(inputs)
    slide = motion.point("S", "slider")[:, 0]
    assert np.allclose(slide, s0 + inputs, atol=1e-9)
    crank = math.radians(60.0) + motion.pose("crank")[:, 2]  # the body turns from its drawn 60 deg
    x = s0 + inputs  # law of cosines in triangle O-A-S
    assert np.allclose(crank, np.arccos((100.0 + x * x - 900.0) / (20.0 * x)), atol=1e-9)


def test_sector_gears_follow_a_table_and_keep_to_their_working_range():
    law = ('law = "table"\nx_deg = [0.0, 30.0, 60.0, 90.0]\ny_deg = [0.0, 40.0, 70.0, 90.0]\nspline = "pchip"\n'
           "closed = false")
    text = GEARED.replace("LAW", law).replace("[gears]\nteeth = [30, 30]\n", "")
    short = text.replace("input_range = [0.0, 360.0]", "input_range = [0.0, 90.0]")
    design = design_from_text(short, "g.toml")
    assert design.method.gears[0].working_range_deg == (0.0, 90.0)  # the table's span
    mech = synthesise(design).mechanism
    turned = -np.degrees(mech.sweep(np.array([0.0, 30.0, 60.0, 90.0])).relative_angle("gear_b", "frame"))
    assert np.allclose(turned, [0.0, 40.0, 70.0, 90.0], atol=1e-9)
    with pytest.raises(SpecError) as info:
        synthesise(design_from_text(text.replace("input_range = [0.0, 360.0]", "input_range = [0.0, 89.0]")
                                    .replace('law = "table"', 'working_range_deg = [0.0, 45.0]\nlaw = "table"'),
                                    "g.toml"))
    assert info.value.path == "linkage.gears[0].working_range_deg"
    assert 'gear "g": the motion turns gear a from 0.000 to 89.000 deg' in info.value.message


def test_table_driver_maps_the_input_to_the_joint_and_is_zero_at_the_reference():
    table = ('[[linkage.drivers]]\njoint = "O"\nlaw = "table"\ninput = [0.0, 5.0, 10.0]\nvalue = [0.0, 45.0, 90.0]\n'
             'spline = "pchip"\n')
    text = four_bar(drivers=table).replace('input_unit = "deg"', 'input_unit = "mm"').replace(
        "input_range = [0.0, 360.0]", "input_range = [0.0, 10.0]")
    mech = synthesise(design_from_text(text, "t.toml")).mechanism
    a = mech.sweep(np.array([0.0, 5.0, 10.0])).point("A")
    assert np.allclose(a, [[15.0, 0.0], [15.0 * math.sqrt(0.5), 15.0 * math.sqrt(0.5)], [0.0, 15.0]], atol=1e-9)
    with pytest.raises(SpecError) as info:
        design_from_text(text.replace("value = [0.0, 45.0, 90.0]", "value = [10.0, 45.0, 90.0]"), "t.toml")
    assert info.value.path == "linkage.drivers[0].value" and "0 there" in info.value.message


def test_synthesis_solves_with_one_blas_thread_and_restores_the_count(monkeypatch: pytest.MonkeyPatch) -> None:
    # OpenBLAS's threads on a 117-unknown solve wait for each other on busy cores (42 s against 2 s)
    from fabricate import bounds
    from fabricate.mechanism import Mechanism

    def counts() -> list[int]:
        return [int(get()) for get, _ in bounds._openblas_controls()]

    design = load_design(TEMPLATE_DIR / "linkage_stephenson.toml")
    before, seen = counts(), []
    original = Mechanism.sweep

    def spy(self: Mechanism, inputs: object = None) -> object:
        seen.append(counts())
        return original(self, inputs)

    monkeypatch.setattr(Mechanism, "sweep", spy)
    synthesise(design)
    assert seen and counts() == before
    assert all(n == 1 for during in seen for n in during)


def test_exact_form_synthesis_solves_the_sweep_the_pipeline_asks_for() -> None:
    from fabricate.synthesis.linkage.exact import mechanism_toml
    from fabricate.synthesis.linkage.mechanism import build_mechanism

    design = load_design(TEMPLATE_DIR / "linkage_stephenson.toml")
    text = mechanism_toml(design, build_mechanism(design.name, design.method), PartHints()).decode("utf-8")
    exact = design_from_text(text, "mechanism.toml")
    mech = synthesise(exact).mechanism
    inputs = np.linspace(*mech.input_range, exact.checks.sweep_poses)
    assert inputs.tobytes() in mech.__dict__.get("_sweep_cache", {})  # the pipeline's sweep is this one
