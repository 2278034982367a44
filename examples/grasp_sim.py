"""Grasp an 85 mm can with the compliant gripper's finger in MuJoCo, from fabricate's own mechanism.xml.

    pip install 'fabricate[sim]'
    python examples/grasp_sim.py [--out grasp.gif] [--no-gif]

What it does:

1. builds the shipped ``gripper_compliant`` template (seed 003) in memory and loads its ``mechanism.xml`` (one
   finger of the three; meshes from the build's own STL files);
2. adds the can: a fixed cylinder of the paper's 85 mm diameter whose axis is the gripper's (x = -50 mm in the
   finger's plane, the can's side at x = -7.5 mm), stiff frictionless contact (the paper's force model, eqs 3-4,
   is the normal force alone; friction only enters its F_n2 = mg / (3 mu s));
3. closes the finger with its actuator, the drive rod's motor (the lead screw: held on a stroke by a PD loop
   inside the motor's force limit, one third of the drive's 377 N per finger), the root held at alpha (the
   paper's root drive), the tip hinge guided on its path until it touches the can, then free;
4. prints the pad's normal force at several strokes against the template's own force model (the synthesis'
   ``grasp_force_curve``: F_n1 against the stroke; F_n1 = 4.42 N at the grasp stroke, the paper prints 4.50 N)
   and checks it within :data:`TOLERANCE` (2 %), and F_n1 against F_n2 (the force that holds the can);
5. writes a short GIF of the closing with MuJoCo's offscreen renderer. Headless, it asks for EGL
   (``MUJOCO_GL=egl``, then OSMesa); where no GL context can be made it says so and skips the GIF (the force
   check still runs). ``--no-gif`` skips it on purpose.

Exit code 0 when every stroke's force is within the tolerance, 1 otherwise.
"""

from __future__ import annotations

import argparse
import io
import os
import sys
from typing import Any

import numpy as np

#: Relative tolerance of MuJoCo's pad force against the template's force model (measured: within 0.3 %).
TOLERANCE = 0.02
#: The can-pad contact (both geoms: MuJoCo mixes the two): stiff enough that it sinks < 0.01 mm at the grasp,
#: with an impedance that ramps over 0.5 mm so the contact settles instead of chattering step to step.
CONTACT_SOLREF, CONTACT_SOLIMP = "0.002 1", "0.95 0.9999 0.0005"
#: Simulation time per held stroke (s): the contact settles in a few ms.
SETTLE_S = 0.15


def can_xml(centre_y_m: float, z_m: float) -> str:
    """The can: fixed, its axis along y (the gripper's axis) at x = -50 mm, radius 42.5 mm, 120 mm tall; it
    collides only with the pad (contype / conaffinity 4)."""
    return (f'<body name="can" pos="-0.05 {centre_y_m:.6f} {z_m:.6f}">'
            '<geom name="can" type="cylinder" size="0.0425 0.06" euler="1.5707963267948966 0 0" '
            f'contype="4" conaffinity="4" condim="1" solref="{CONTACT_SOLREF}" solimp="{CONTACT_SOLIMP}" '
            'rgba="0.8 0.8 0.85 0.6"/></body>')


def pad_xml(centre_mm: tuple[float, float], z_m: float, half_thickness_m: float, radius_mm: float) -> str:
    """The fingertip's pad arc as a cylinder about its centre (its exact surface where the can touches it).

    MuJoCo collides a mesh by its convex hull, and the tip part's hull (its hinge boss to the pad arc) would
    touch the can above the pad where the part itself does not; the primitive is the pad the paper's force
    model loads (the force through the arc's centre)."""
    return (f'<geom name="pad" type="cylinder" pos="{centre_mm[0] * 1e-3:.6f} {centre_mm[1] * 1e-3:.6f} {z_m:.6f}" '
            f'size="{radius_mm * 1e-3:.6f} {half_thickness_m:.6f}" contype="4" conaffinity="4" condim="1" '
            f'solref="{CONTACT_SOLREF}" solimp="{CONTACT_SOLIMP}" '
            'rgba="0.9 0.3 0.3 0.4"/>')


def load_with_can(build: Any) -> Any:
    """The build's model with the can in its world (at the pad's height and the grasp's depth) and the pad's
    collision cylinder on the tip."""
    from fabricate.export.mjcf import load_model

    motion, mech = build.motion, build.motion.mechanism
    pad = motion.point("pad", "tip")
    tip_part = next(p for p in build.partset.parts if p.body == "tip" and p.role != "spacer")
    z = (tip_part.z_mm + 0.5 * tip_part.thickness_mm) * 1e-3
    # the arc's radius: from its centre to its tangent point (the template's pad_radius_mm)
    radius = float(np.hypot(*(mech.body("tip").point("pad") - mech.body("tip").point("pad_start"))))
    xml = build.files["mechanism.xml"].decode("utf-8")
    xml = xml.replace("  </worldbody>", f"    {can_xml(float(pad[-1, 1]) * 1e-3, z)}\n  </worldbody>", 1)
    opening = next(line for line in xml.splitlines() if line.strip().startswith('<body name="tip"'))
    centre = tuple(float(v) for v in mech.body("tip").point("pad"))
    xml = xml.replace(opening, opening + "\n" + pad_xml((centre[0], centre[1]), z,
                                                        0.5 * tip_part.thickness_mm * 1e-3, radius), 1)
    files = dict(build.files)
    files["mechanism.xml"] = xml.encode("utf-8")
    model = load_model(files)
    model.dof_damping[:] = 0.005  # settles the free hinges (N·m·s/rad, N·s/m at the slide); 0 at rest
    return model


class Finger:
    """The loaded model with what the grasp drives: the stroke joint, the root and tip equalities."""

    def __init__(self, build: Any) -> None:
        import mujoco

        from fabricate.export.mjcf import spring_joints
        from fabricate.export.mjcf_tree import driver_targets, kinematic_tree

        self.build = build
        self.model = load_with_can(build)
        self.data = mujoco.MjData(self.model)
        mech, motion = build.motion.mechanism, build.motion
        self.tree = kinematic_tree(mech, spring_joints(build.partset, mech))
        self.targets = driver_targets(mech, motion, self.tree)
        self.stroke_mm = np.asarray(motion.inputs, dtype=np.float64)
        self.eq = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_EQUALITY, f"drive_{k}")
                   for k in range(len(self.targets))]
        self.adr = [int(self.model.jnt_qposadr[mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, j)])
                    for j, _, _ in self.targets]
        self.dof = int(self.model.jnt_dofadr[mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT,
                                                                self.targets[0][0])])
        self.can = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "can")
        self.limit = float(self.model.actuator_ctrlrange[0, 1])
        self.integral = 0.0
        self.touched = False

    def stroke(self) -> float:
        """The drive rod's stroke (mm), fabricate's input: the slide driver's coordinate (its qpos times the
        driver's sign, in mm)."""
        _, sign, _ = self.targets[0]
        return float(sign * self.data.qpos[self.adr[0]] * 1e3)

    def set_pose(self, row: int, touching: bool) -> None:
        """Every joint at fabricate's pose ``row`` of the motion, at rest; ``touching``: the pad is on the can
        there (the tip is left free)."""
        import mujoco

        from fabricate.export.mjcf_tree import joint_coordinates

        coordinates = joint_coordinates(self.build.motion.mechanism, self.build.motion, self.tree)
        for name, values in coordinates.items():
            jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
            self.data.qpos[self.model.jnt_qposadr[jid]] = values[row]
        self.data.qvel[:] = 0.0
        self.integral = 0.0
        self.touched = touching
        mujoco.mj_forward(self.model, self.data)

    def step(self, stroke_target_mm: float, first_touch_mm: float) -> None:
        """One step: the motor's PD on the stroke (inside its limit), the root held, the tip guided on its
        path before the can is touched and free after."""
        import mujoco

        _, sign, _ = self.targets[0]
        error = (stroke_target_mm - self.stroke()) * 1e-3
        speed = sign * float(self.data.qvel[self.dof])
        # PI on the stroke (the lead screw holds a position), D on its speed; inside the motor's limit
        self.integral = float(np.clip(self.integral + error * self.model.opt.timestep, -1e-3, 1e-3))
        push = 2e5 * error + 2e7 * self.integral - 20.0 * speed
        self.data.ctrl[0] = float(np.clip(push, -self.limit, self.limit))
        root = 1
        self.data.eq_active[self.eq[root]] = 1
        self.model.eq_data[self.eq[root], 0] = float(self.targets[root][2][0]) - float(self.model.qpos0[self.adr[root]])
        tip = 2
        # guided on its path (the paper's stop) until the pad first touches the can, then free for good
        self.touched = self.touched or self.pad_force() > 0.0 or self.stroke() >= first_touch_mm
        guided = not self.touched
        self.data.eq_active[self.eq[tip]] = 1 if guided else 0
        if guided:
            along = float(np.interp(self.stroke(), self.stroke_mm, self.targets[tip][2]))
            self.model.eq_data[self.eq[tip], 0] = along - float(self.model.qpos0[self.adr[tip]])
        mujoco.mj_step(self.model, self.data)

    def pad_force(self) -> float:
        """The can's normal force on the finger (N), summed over its contacts."""
        import mujoco

        total = 0.0
        force = np.zeros(6)
        for k in range(self.data.ncon):
            c = self.data.contact[k]
            if self.can in (c.geom1, c.geom2):
                mujoco.mj_contactForce(self.model, self.data, k, force)
                total += float(force[0])
        return total


def renderer(model: Any) -> Any | None:
    """An offscreen renderer, or None (and why, on stderr) where no GL context can be made."""
    import mujoco

    try:
        return mujoco.Renderer(model, 240, 320)
    except Exception as exc:  # no EGL/OSMesa/GLFW context: the GIF is skipped, the check still runs
        print(f"no GIF: MuJoCo cannot open an offscreen GL context here ({type(exc).__name__}: {exc})",
              file=sys.stderr)
        return None


def frame(render: Any, model: Any, data: Any) -> np.ndarray:
    import mujoco

    camera = mujoco.MjvCamera()
    camera.lookat[:] = (0.0, -0.09, 0.02)
    camera.distance = 0.32
    camera.elevation = -90.0
    camera.azimuth = 90.0
    render.update_scene(data, camera)
    image: np.ndarray = render.render()
    return image


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="grasp.gif", help="the GIF to write (default grasp.gif)")
    parser.add_argument("--no-gif", action="store_true", help="skip the GIF")
    args = parser.parse_args(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")

    import fabricate

    print("building gripper_compliant ...", flush=True)
    build = fabricate.build(fabricate.load("gripper_compliant"))
    curve = build.report["synthesis"]["grasp_force_curve"]
    grasp = build.report["synthesis"]["grasp"]
    first_touch = float(grasp["first_touch_stroke_mm"])
    strokes = np.asarray(curve["stroke_mm"], dtype=np.float64)
    forces = np.asarray(curve["F_static_N"], dtype=np.float64)
    finger = Finger(build)
    dt = float(finger.model.opt.timestep)

    # the closing, from open to the grasp stroke, with the GIF's frames
    render = None if args.no_gif else renderer(finger.model)
    finger.set_pose(0, touching=False)
    frames: list[np.ndarray] = []
    target = float(grasp["stroke_mm"])
    steps = int(0.6 / dt)
    for k in range(steps):
        ramp = min(1.0, k / (0.4 / dt))
        finger.step(finger.stroke_mm[0] + ramp * (target - finger.stroke_mm[0]), first_touch)
        if render is not None and k % int(0.02 / dt) == 0:
            frames.append(frame(render, finger.model, finger.data))
    closed, model_force = finger.pad_force(), float(np.interp(finger.stroke(), strokes, forces))
    worst = abs(closed - model_force) / model_force
    print(f"closed by the motor to stroke {finger.stroke():.3f} mm (target {target:.3f}): pad force {closed:.3f} N, "
          f"the template's force model {model_force:.3f} N ({100 * (closed - model_force) / model_force:+.2f} %)")

    # the force curve: held strokes against the template's grasp_force_curve
    print("held strokes:\nstroke_mm  mujoco_N  model_N  difference")
    inside = [s for s in strokes if s <= finger.stroke_mm[-1] and s > first_touch + 0.5]
    for stroke in inside:
        row = int(np.argmin(np.abs(finger.stroke_mm - stroke)))
        finger.set_pose(row, touching=True)
        for _ in range(int(SETTLE_S / dt)):
            finger.step(float(finger.stroke_mm[row]), first_touch)
        got, want = finger.pad_force(), float(np.interp(finger.stroke(), strokes, forces))
        worst = max(worst, abs(got - want) / want)
        print(f"{finger.stroke():9.3f}  {got:8.3f}  {want:7.3f}  {100 * (got - want) / want:+6.2f} %")
    f_n2 = float(build.report["synthesis"]["F_n2_N"])
    print(f"F_n2 = mg/(3 mu s) = {f_n2:.3f} N: the can is held where F_n1 >= F_n2 "
          f"(grasp stroke {target:.3f} mm, F_n1 {np.interp(target, strokes, forces):.3f} N)")
    print(f"largest difference {100 * worst:.2f} % (tolerance {100 * TOLERANCE:g} %)")

    if frames:
        from PIL import Image

        images = [Image.fromarray(f) for f in frames]
        buffer = io.BytesIO()
        images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=60, loop=0)
        with open(args.out, "wb") as handle:
            handle.write(buffer.getvalue())
        print(f"wrote {args.out} ({len(frames)} frames)")
    return 0 if worst <= TOLERANCE else 1


if __name__ == "__main__":
    sys.exit(main())
