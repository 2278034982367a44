"""mechanism.xml (fabricate/export/mjcf.py) loaded and run in MuJoCo, held against fabricate's own numbers:

- kinematics: the drivers moved through the motion by their joint equalities, the loops held by the file's
  ``connect`` equalities and gear polynomials at the file's solver settings: the tip site on motion.csv's
  path within 0.05 mm, every pin closed within 0.01 mm;
- statics: ``mj_inverse`` at rest with the template's [load] at the tip (the springs are the file's joint
  stiffness) gives the driver efforts of fabricate's statics within 1 % of their largest value;
- mass properties: the file's inertials against trimesh's mass properties of the exported STL files.
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fabricate.export.mass import mesh_mass_properties, stl_triangles
from fabricate.export.mjcf import activate_gear_segments
from fabricate.export.mjcf_tree import driver_targets, joint_coordinates, kinematic_tree
from fabricate.mechanism import Body, Driver, GearCoupling, Mechanism, Revolute
from fabricate.pipeline import BuildOutcome

# headless offscreen rendering (the grasp example's GIF): MuJoCo picks its GL backend when first imported
os.environ.setdefault("MUJOCO_GL", "egl")
mujoco = pytest.importorskip("mujoco")

TEMPLATES = ("finger_five_bar_ncg", "finger_watt_six_bar", "finger_underactuated", "gripper_compliant",
             "gear_pair_elliptic", "jansen_leg", "linkage_quick_return", "linkage_stephenson")


def load_model(build: BuildOutcome) -> Any:
    """The build's mechanism.xml with its STL files as MuJoCo assets (nothing on disk)."""
    return build.mujoco_model()


def _spring_joints(build: BuildOutcome) -> list[str]:
    assert build.partset is not None
    return [s.joint for s in build.partset.hints.springs if s.rate_Nmm_per_deg > 0.0]


def _world(model: Any, data: Any, body: str, local_mm: np.ndarray) -> np.ndarray:
    """World position (mm, xy) of a point of ``body`` given in its frame (mm)."""
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    point = data.xpos[b] + data.xmat[b].reshape(3, 3) @ np.array([local_mm[0], local_mm[1], 0.0]) * 1e-3
    return np.asarray(point[:2] * 1e3)


def drive_through(build: BuildOutcome, rows: np.ndarray, steps_per_row: int = 10, hold: int = 60
                  ) -> dict[str, np.ndarray]:
    """Move every driver through the motion by its ``drive_K`` equality (all rows, ``steps_per_row`` steps
    each), holding ``hold`` steps at each of ``rows``. Returns, at those rows: ``points`` (k, p, 2) mm, the
    sites of every body's named points in the order of :func:`named_points`; ``angles`` (k, b) rad, every
    body's rotation; ``gap`` (k,) mm, the widest pin (both bodies' points of every revolute joint)."""
    assert build.motion is not None and build.partset is not None
    mech, motion = build.motion.mechanism, build.motion
    model = load_model(build)
    data = mujoco.MjData(model)
    tree = kinematic_tree(mech, _spring_joints(build))
    targets = driver_targets(mech, motion, tree)
    eq = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, f"drive_{k}") for k in range(len(targets))]
    q0 = [float(model.qpos0[model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)]])
          for j, _, _ in targets]
    for e in eq:
        data.eq_active[e] = 1
    sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{body}.{point}")
             for body, point in named_points(build)]
    bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for name in mech.body_names]
    revolutes = [j for j in mech.joints if isinstance(j, Revolute)]
    points, angles, gaps = [], [], []
    wanted = set(int(r) for r in rows)
    previous = [float(t[0]) for _, _, t in targets]
    for i in range(int(max(rows)) + 1):
        goal = [float(t[i]) for _, _, t in targets]
        for s in range(steps_per_row):
            f = (s + 1) / steps_per_row
            for e, q, a, b in zip(eq, q0, previous, goal, strict=True):
                model.eq_data[e, 0] = a + f * (b - a) - q
            activate_gear_segments(model, data)
            mujoco.mj_step(model, data)
        previous = goal
        if i in wanted:
            for _ in range(hold):
                activate_gear_segments(model, data)
                mujoco.mj_step(model, data)
            mujoco.mj_forward(model, data)
            points.append(data.site_xpos[sites][:, :2] * 1e3)
            angles.append([np.arctan2(data.xmat[b][3], data.xmat[b][0]) for b in bodies])
            gaps.append(max(float(np.hypot(*(_world(model, data, j.body_a, mech.body(j.body_a).point(j.name))
                                              - _world(model, data, j.body_b, mech.body(j.body_b).point(j.name)))))
                            for j in revolutes))
    return {"points": np.array(points), "angles": np.array(angles), "gap": np.array(gaps)}


def named_points(build: BuildOutcome) -> list[tuple[str, str]]:
    """(body, point) of every named point of every body."""
    assert build.motion is not None
    return [(b.name, p) for b in build.motion.mechanism.bodies for p in b.points]


def kinematic_errors(build: BuildOutcome, count: int = 13) -> dict[str, float]:
    """Largest errors over ``count`` poses of the motion: ``tip`` (mm, the tip site against motion.csv's
    tip point; 0 without one), ``points`` (mm, every named point's site), ``angle`` (rad, every body's
    rotation) and ``gap`` (mm, the widest pin)."""
    assert build.motion is not None and build.partset is not None
    motion = build.motion
    rows = np.unique(np.linspace(0, len(motion.inputs) - 1, count).round().astype(int))
    got = drive_through(build, rows)
    expected = np.stack([motion.point(point, body)[rows] for body, point in named_points(build)], axis=1)
    miss = np.hypot(*(got["points"] - expected).transpose(2, 0, 1))
    names = named_points(build)
    tip_point = build.partset.hints.tip_point
    tip_columns = [k for k, (_, point) in enumerate(names) if point == tip_point]
    theta = np.stack([motion.pose(name)[rows, 2] for name in motion.mechanism.body_names], axis=1)
    turn = np.angle(np.exp(1j * (got["angles"] - theta)))
    return {"tip": float(miss[:, tip_columns].max()) if tip_columns else 0.0, "points": float(miss.max()),
            "angle": float(np.abs(turn).max()), "gap": float(got["gap"].max())}


def statics_efforts(build: BuildOutcome, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Driver efforts (k, d) from MuJoCo's inverse dynamics at rest at ``rows`` of the motion (N·mm or N), and
    fabricate's (its strength statics)."""
    from fabricate.strength.check import design_loads, solved_loads

    assert build.motion is not None and build.partset is not None and build.design is not None
    motion, mech = build.motion, build.motion.mechanism
    loads = design_loads(build.design, mech, motion, build.partset.hints)
    from fabricate.strength.statics import solve_statics

    statics = solve_statics(mech, motion, loads.forces, loads.torques, loads.efforts, loads.reaction)
    if loads.reaction is not None:
        assert statics.reaction_N is not None
        loads = solved_loads(loads, statics.reaction_N)
    model = load_model(build)
    data = mujoco.MjData(model)
    tree = kinematic_tree(mech, _spring_joints(build))
    coordinates = {tj.name: tj for tj in tree.joints}
    targets = driver_targets(mech, motion, tree)
    qpos = joint_coordinates(mech, motion, tree)
    out = np.zeros((len(rows), len(targets)))
    for r, i in enumerate(rows):
        data.qpos[:] = model.qpos0
        for name in coordinates:
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
            data.qpos[model.jnt_qposadr[jid]] = qpos[name][i]
        data.qvel[:] = 0.0
        data.qacc[:] = 0.0
        activate_gear_segments(model, data)
        mujoco.mj_inverse(model, data)
        external = np.zeros(model.nv)
        for f in loads.forces:
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f.body)
            point = np.array([*_world(model, data, f.body, np.asarray(f.local)), 0.0]) * 1e-3
            force = np.broadcast_to(np.asarray(f.force, dtype=np.float64), (len(motion.inputs), 2))[i]
            mujoco.mj_applyFT(model, data, np.array([force[0], force[1], 0.0]), np.zeros(3), point, b, external)
        for t in loads.torques:
            if t.joint:  # a spring: the file's joint stiffness carries it
                continue
            value = np.broadcast_to(np.asarray(t.torque, dtype=np.float64), (len(motion.inputs),))[i] * 1e-3
            for body, sign in ((t.body, 1.0), (t.reaction, -1.0)):
                b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
                mujoco.mj_applyFT(model, data, np.zeros(3), np.array([0.0, 0.0, sign * value]),
                                  data.xpos[b].copy(), b, external)
        # the drivers' efforts (unit columns at their joints, along the driver's coordinate) and the loop,
        # gear and pin multipliers (the active equality rows MuJoCo built) balance what inverse dynamics asks
        columns = []
        for joint, sign, _ in targets:
            col = np.zeros(model.nv)
            col[model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)]] = sign
            columns.append(col)
        eq_rows = [k for k in range(data.nefc) if data.efc_type[k] == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
        jac = np.zeros((data.nefc, model.nv))
        if data.nefc:
            mujoco.mju_sparse2dense(jac, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind) \
                if mujoco.mj_isSparse(model) else jac.__setitem__(slice(None), data.efc_J.reshape(data.nefc, model.nv))
        system = np.column_stack(columns + [jac[k] for k in eq_rows])
        sol, *_ = np.linalg.lstsq(system, data.qfrc_inverse - external, rcond=None)
        for k, (_, _, _) in enumerate(targets):
            out[r, k] = sol[k] * (1e3 if mech.drivers[k].kind == "angle" else 1.0)
    return out, np.asarray(statics.driver_efforts)[rows]


def mass_errors(build: BuildOutcome) -> float:
    """Largest relative difference between the file's inertials and trimesh's mass properties of the STL files."""
    import trimesh

    assert build.partset is not None and build.design is not None
    model = load_model(build)
    density = build.design.process.density_g_cm3 * 1e-3  # g/mm³
    worst = 0.0
    for body in {p.body for p in build.partset.parts}:
        pieces = []
        for part in (p for p in build.partset.parts if p.body == body):
            mesh = trimesh.Trimesh(**trimesh.exchange.stl.load_stl(io.BytesIO(build.files[f"parts/{part.name}.stl"])))
            mesh.density = density
            com = np.asarray(mesh.center_mass) + np.array([0.0, 0.0, part.z_mm])
            pieces.append((float(mesh.mass), com, np.asarray(mesh.moment_inertia)))
        mass = sum(m for m, _, _ in pieces)
        com = sum(m * c for m, c, _ in pieces) / mass
        inertia = sum(i + m * (float((c - com) @ (c - com)) * np.eye(3) - np.outer(c - com, c - com))
                      for m, c, i in pieces)
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        file_mass = float(model.body_mass[b]) * 1e3  # g
        flat = np.zeros(9)
        mujoco.mju_quat2Mat(flat, model.body_iquat[b])
        rot = flat.reshape(3, 3)
        file_inertia = rot @ np.diag(model.body_inertia[b]) @ rot.T * 1e9  # g·mm²
        file_com = np.asarray(model.body_ipos[b]) * 1e3
        worst = max(worst, abs(file_mass - mass) / mass, float(np.max(np.abs(file_com - com))) / 100.0,
                    float(np.max(np.abs(file_inertia - inertia))) / float(np.max(np.abs(inertia))))
    return worst


# -- fast: the mass integrals against trimesh on a box, no build ------------------------------------------

def test_mesh_mass_properties_of_a_box_match_trimesh() -> None:
    import trimesh

    mesh = trimesh.creation.box(extents=(30.0, 8.0, 3.0))
    mesh.apply_translation((12.0, -4.0, 1.5))
    data = trimesh.exchange.stl.export_stl(mesh)
    props = mesh_mass_properties(stl_triangles(data), 1.15e-3)
    assert props.mass == pytest.approx(30 * 8 * 3 * 1.15e-3, rel=1e-9)
    np.testing.assert_allclose(props.com, [12.0, -4.0, 1.5], atol=1e-9)
    m = props.mass
    np.testing.assert_allclose(np.diag(props.inertia), [m * (8 ** 2 + 3 ** 2) / 12, m * (30 ** 2 + 3 ** 2) / 12,
                                                        m * (30 ** 2 + 8 ** 2) / 12], rtol=1e-9)
    assert np.max(np.abs(props.inertia - np.diag(np.diag(props.inertia)))) < 1e-9


def _gear_train(law: Any, turn_deg: float) -> Mechanism:
    """Two gears on a fixed carrier (centres 30 mm apart), gear a driven through ``turn_deg``."""
    return Mechanism(
        name="gears",
        bodies=(Body("carrier", {"OA": (0.0, 0.0), "OB": (30.0, 0.0)}), Body("gear_a", {"OA": (0.0, 0.0)}),
                Body("gear_b", {"OB": (0.0, 0.0), "mark": (10.0, 0.0)})),
        ground="carrier", joints=(Revolute("OA", "carrier", "gear_a"), Revolute("OB", "carrier", "gear_b")),
        gears=(GearCoupling("pair", "carrier", "gear_a", "gear_b", law, "OA", "OB", (0.0, math.radians(turn_deg))),),
        drivers=(Driver("angle", "gear_a", "carrier"),), input_range=(0.0, turn_deg),
        assembly={"gear_a": (0.0, 0.0, 0.0), "gear_b": (30.0, 0.0, float(law(0.0)))})


def test_kinematic_tree_of_a_four_bar_closes_one_pin_and_holds_the_driver(four_bar: Mechanism) -> None:
    tree = kinematic_tree(four_bar)
    # the driver's O first, then A and B in order; D, the last, would close the loop: a connect
    assert [j.name for j in tree.loops] == ["D"]
    assert len(tree.joints) == 3 and not tree.unreached
    held = {j.name for j in tree.joints}
    assert "O" in held and tree.loops[0].name not in held  # the driven joint is a MuJoCo joint
    motion = four_bar.sweep(13)
    (joint, sign, qpos), = driver_targets(four_bar, motion, tree)
    np.testing.assert_allclose(sign * qpos, np.radians(motion.inputs), atol=1e-12)
    # every tree joint's qpos is its relative angle: the parent's angle plus it gives the child's
    for tj in tree.joints:
        q = joint_coordinates(four_bar, motion, tree)[tj.name]
        np.testing.assert_allclose(motion.pose(tj.parent)[:, 2] + q, motion.pose(tj.child)[:, 2], atol=1e-12)


def test_gear_fit_is_one_exact_quartic_for_a_quartic_law_and_segments_a_full_turn_law() -> None:
    from fabricate.export.mjcf_tree import GEAR_FIT_TOLERANCE_RAD, fit_gear
    from fabricate.mechanism import LinearLaw

    linear = _gear_train(LinearLaw(-1.5, 0.2), 60.0)
    motion = linear.sweep(61)
    (fit,) = [fit_gear(linear, motion, kinematic_tree(linear), 0)]
    assert fit is not None and len(fit.coefficients) == 1 and fit.max_error_rad < 1e-12
    assert fit.coefficients[0][1] == pytest.approx(-1.5, abs=1e-9)  # the slope, relative to the first pose

    def wavy(x: Any, nu: int = 0) -> Any:  # an elliptic pair's kind of law: x plus a periodic part
        x = np.asarray(x, dtype=np.float64)
        return -(x + 0.3 * np.sin(x)) if nu == 0 else -(1.0 + 0.3 * np.cos(x)) if nu == 1 else 0.3 * np.sin(x)

    full = _gear_train(wavy, 360.0)
    motion = full.sweep(361)
    fit = fit_gear(full, motion, kinematic_tree(full), 0)
    assert fit is not None and len(fit.coefficients) > 1 and fit.max_error_rad <= GEAR_FIT_TOLERANCE_RAD
    # the segments cover the turn and each polynomial meets the law inside its own segment
    assert fit.bounds[0] == pytest.approx(0.0, abs=1e-12) and fit.bounds[-1] == pytest.approx(2 * math.pi)
    u = np.linspace(0.0, 2 * math.pi, 1001)
    k = np.clip(np.searchsorted(fit.bounds, u, side="right") - 1, 0, len(fit.coefficients) - 1)
    values = np.array([np.polynomial.polynomial.polyval(x, fit.coefficients[i]) for x, i in zip(u, k, strict=True)])
    assert np.max(np.abs(values - wavy(u))) <= GEAR_FIT_TOLERANCE_RAD


# -- every shipped template (full builds: slow) -----------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_mjcf_kinematics_follow_motion_csv(shipped_build: Callable[[str], BuildOutcome], name: str) -> None:
    errors = kinematic_errors(shipped_build(name))
    assert errors["tip"] < 0.05 and errors["points"] < 0.05
    assert errors["angle"] < 1e-3  # a gear pair's output: 1e-3 rad is 0.05 mm at 50 mm
    assert errors["gap"] < 0.01


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_mjcf_statics_match_fabricate(shipped_build: Callable[[str], BuildOutcome], name: str) -> None:
    build = shipped_build(name)
    assert build.motion is not None
    rows = np.unique(np.linspace(0, len(build.motion.inputs) - 1, 9).round().astype(int))
    simulated, fabricated = statics_efforts(build, rows)
    scale = np.max(np.abs(fabricated), axis=0)
    assert np.all(np.abs(simulated - fabricated) <= 0.01 * scale + 1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_mjcf_mass_properties_match_trimesh(shipped_build: Callable[[str], BuildOutcome], name: str) -> None:
    assert mass_errors(shipped_build(name)) < 1e-6


# -- contacts: MuJoCo's collisions of the part meshes against fabricate's interference proof ---------------

def deepest_contacts(build: BuildOutcome, rows: np.ndarray) -> dict[frozenset[str], float]:
    """With every part colliding with every other (parents and children too), the deepest penetration (mm,
    > 0) MuJoCo reports per pair of part geoms over the motion's ``rows`` (pairs without contact left out)."""
    assert build.motion is not None
    mech, motion = build.motion.mechanism, build.motion
    model = load_model(build)
    # the bodies' own flags too: MuJoCo's broad phase filters by them, compiled from the file's geoms
    for flags in (model.geom_contype, model.geom_conaffinity, model.body_contype, model.body_conaffinity):
        flags[:] = 1
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
    data = mujoco.MjData(model)
    tree = kinematic_tree(mech, _spring_joints(build))
    qpos = joint_coordinates(mech, motion, tree)
    address = {name: int(model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)])
               for name in qpos}
    deepest: dict[frozenset[str], float] = {}
    for i in rows:
        for name, values in qpos.items():
            data.qpos[address[name]] = values[i]
        mujoco.mj_fwdPosition(model, data)
        for c in data.contact[:data.ncon]:
            pair = frozenset((mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, c.geom1),
                              mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, c.geom2)))
            deepest[pair] = max(deepest.get(pair, 0.0), -float(c.dist) * 1e3)
    return deepest


def convex_parts(build: BuildOutcome) -> set[str]:
    """Parts whose outline is convex (MuJoCo collides a mesh by its convex hull, so only these are exact)."""
    from shapely.geometry import Polygon

    assert build.partset is not None
    out = set()
    for part in build.partset.parts:
        outline = Polygon(part.outline.polygon(build.partset.chord_tolerance_mm))
        if outline.convex_hull.area - outline.area <= 1e-6 * outline.area:
            out.add(part.name)
    return out


def clearance_disagreements(build: BuildOutcome, step: int = 10) -> tuple[list[str], int]:
    """Pairs of convex parts fabricate proves clear (clearance > 0 at every pose) that MuJoCo finds
    penetrating by more than 1 µm, and the number of pairs compared."""
    assert build.motion is not None
    deepest = deepest_contacts(build, np.arange(0, len(build.motion.inputs), step))
    convex = convex_parts(build)
    wrong, compared = [], 0
    for pair in build.report["interference"]["pairs"]:
        if pair["a"] not in convex or pair["b"] not in convex or not pair["min_clearance_mm"] > 0.0:
            continue
        compared += 1
        depth = deepest.get(frozenset((pair["a"], pair["b"])), 0.0)
        if depth > 1e-3:
            wrong.append(f"{pair['a']}-{pair['b']}: clearance {pair['min_clearance_mm']} mm, MuJoCo {depth:.4f} mm")
    return wrong, compared


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_mjcf_contacts_agree_with_the_interference_proof(shipped_build: Callable[[str], BuildOutcome],
                                                         name: str) -> None:
    wrong, compared = clearance_disagreements(shipped_build(name))
    if compared == 0:  # the gear pair: its gears and carrier are not convex, MuJoCo collides their hulls
        pytest.skip("no pair of convex parts to compare")
    assert not wrong


@pytest.mark.slow
def test_mjcf_contacts_find_the_collision_of_the_24_mm_link_six_bar(shared_stage_cache) -> None:
    """The Watt six-bar with 24 mm links: fabricate's interference check rejects it (the rocker runs into the
    spacer at d); MuJoCo's collision of the same meshes finds the same two parts in contact, and no penetration
    between convex parts fabricate proves clear. (At 14 mm the proximal link hit spacer_d0 until pressed pins
    covered their stacks; since then 10-20 mm links fail only on pin_d's stub in spacer_f, a pin MuJoCo models as
    a joint, not a geom.)"""
    import re

    from fabricate.design import design_from_text
    from fabricate.pipeline import run_build
    from fabricate.templates import find_template

    text = find_template("finger_watt_six_bar").read_text(encoding="utf-8")
    text = re.sub(r"^link_width_mm\s*=.*$", "link_width_mm = 24.0", text, count=1, flags=re.M)
    # the six-bar's synthesis (~1.8 s; its key leaves [parts] out) from the session's build of the template
    with shared_stage_cache():
        build = run_build(design_from_text(text, "finger_watt_six_bar.toml"))
    assert build.motion is not None
    collisions = build.report["interference"]["collisions"]
    assert collisions
    deepest = deepest_contacts(build, np.arange(0, len(build.motion.inputs), 10))
    # the model's geoms are the parts (its pins are joints): a pressed pin's stub in a spacer (spacer_f / pin_d
    # since pins cover their stacks) is fabricate's alone
    parts = {p.name for p in build.partset.parts}
    between_parts = [hit for hit in collisions if {hit["a"], hit["b"]} <= parts]
    assert between_parts  # else this test compares nothing
    for hit in between_parts:
        assert deepest.get(frozenset((hit["a"], hit["b"])), 0.0) > 1e-3, hit
    wrong, _ = clearance_disagreements(build)
    assert not wrong


@pytest.mark.slow
def test_grasp_sim_example_matches_the_gripper_force_model(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          shipped_build: Callable[..., BuildOutcome],
                                                          serve_builds: Callable[[], None]) -> None:
    """examples/grasp_sim.py: the finger closed on the 85 mm can by its motor gives the pad force of the
    template's force model within 2 % (exit 0), and writes its GIF where MuJoCo can open an offscreen GL
    context (EGL, else OSMesa); where it cannot, it says so and skips the GIF.

    The example's own build (``fabricate.build`` of the shipped gripper) runs on the session's shared stage cache,
    which ``shipped_build`` fills with that design (byte-identical to a cold build, tests/test_cache.py): what is
    tested is the simulation of the build, not the build, which the session makes once."""
    import importlib.util


    shipped_build("gripper_compliant")
    serve_builds()

    path = Path(__file__).resolve().parents[2] / "examples" / "grasp_sim.py"
    spec = importlib.util.spec_from_file_location("grasp_sim", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    out = tmp_path / "grasp.gif"
    assert module.main(["--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert "largest difference" in printed.out
    if "no GIF" not in printed.err:
        assert out.read_bytes()[:6] in (b"GIF87a", b"GIF89a")
