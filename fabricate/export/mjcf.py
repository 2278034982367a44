"""``mechanism.xml``: the built mechanism as an MJCF model for MuJoCo, with its closed loops, gear laws,
springs, actuator and the mass properties of the parts as made.

Model
-----
- Units are SI (m, kg, s, N, N·m, rad): fabricate's mm and N·mm are converted here. Every body's frame is
  fabricate's body frame, placed at the motion's first pose, so MuJoCo's initial configuration (``qpos0``)
  is that pose and a body's named points are at their fabricate coordinates (x 0.001).
- The bodies form a kinematic tree rooted at the ground (a fixed body). Its edges are the mechanism's
  joints, chosen sliders first, then the drivers', the gear axes' and the springs' joints (so each of
  those is a MuJoCo joint with a coordinate), then the others in order; every joint the tree cannot hold
  closes its loop with an equality ``connect`` at the pin. Hinges turn about +z (the plane's normal);
  a hinge's ``ref`` is the relative angle theta_child - theta_parent at the first pose, so its ``qpos``
  is that relative angle (rad); a slide's is the driver's coordinate (m). The tree, the joints'
  coordinates and the gear-law fits are computed in :mod:`fabricate.export.mjcf_tree`; this module writes
  the document.
- Part geoms are the build's own STL files (``parts/NAME.stl``, mm, scaled by 0.001), placed at the part's
  height ``z_mm``. Mass and inertia are written explicitly (``<inertial>`` with ``fullinertia``): the
  parts' exported meshes integrated exactly (divergence theorem on their triangles) at the process profile's
  density, so nothing depends on MuJoCo's mesh-inertia settings. Pins, washers, springs and the actuator's
  body are not in the masses (bom.csv lists them).
- Gear pairs couple their joints by a joint equality ``y - y0 = a0 + a1 (x - x0) + ... + a4 (x - x0)^4``
  (MuJoCo's quartic) fitted to the gear law over the pair's working range. Where one quartic misses the law
  by more than :data:`~fabricate.export.mjcf_tree.GEAR_FIT_TOLERANCE_RAD` (a full-turn non-circular pair),
  the range is split into segments, one equality each; the one holding the first pose is active, the
  others are written ``active="false"`` and :func:`activate_gear_segments` switches them as the joint turns
  (call it before each ``mj_step``; ``<custom>`` numerics ``gear_<pair>_segments`` hold the segment
  bounds). MuJoCo has no arbitrary-function equality without a compiled plugin; this keeps the file
  loadable by the stock package.
- Torsion springs are joint ``stiffness`` with ``springref`` at the spring's free angle (the preload
  back from the first pose): linear, as fabricate's statics count them while the spring is wound.
- The design's actuator is a ``<motor>`` on the driven joint, its control the effort along the driver's
  coordinate (N·m or N), limited to the catalogue rating fabricate's drive check holds it to (divided among
  the copies it drives: a three-finger gripper's one finger gets a third).
- Every driver also gets a joint equality ``drive_K`` (inactive): activate it and set ``eq_data[0]`` to
  (coordinate - qpos0) to prescribe that coordinate kinematically, as fabricate's drivers do. Drivers
  beyond the first stand for stops and the object (the underactuated finger, the gripper): they are free
  joints in the file.
- Every named point is a site ``BODY.POINT``; the tip point is also the site ``tip``.
- Part-part collisions are off (``contype=2 conaffinity=1``: parts collide with anything of contype 1,
  such as an object, but not with each other; MuJoCo collides convex hulls of meshes, and a plate's hull
  covers the pins of its neighbours).

Solver settings that keep the loops closed (written in ``<option>`` and the equalities' defaults):
timestep 1e-4 s, implicitfast integrator, Newton solver with tolerance 1e-10, equality ``solref`` with a
time constant of two timesteps (the least MuJoCo accepts) and ``solimp`` 0.9999 (the greatest impedance).
Driven through the motion by the ``drive_K`` equalities, every shipped template's pins stay within 2e-5 mm of
closed and its points within 0.003 mm of motion.csv (tests/export/test_mjcf.py).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any
from xml.sax.saxutils import quoteattr

import numpy as np

from fabricate.errors import FabricateError, SpecError
from fabricate.export.mass import MM, MassProperties, body_mass_properties
from fabricate.export.mjcf_tree import (
    GearFit,
    Tree,
    TreeJoint,
    active_segment,
    driver_joint,
    driver_targets,
    fit_gear,
    joint_coordinates,
    kinematic_tree,
    structure_notes,
)
from fabricate.mechanism import Driver, Mechanism, Motion, Revolute, Slider

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.hints import SpringHint
    from fabricate.parts.partset import PartSet
    from fabricate.spec import DesignSpec

#: Simulation timestep (s) written in ``<option>``.
TIMESTEP_S = 1e-4


def activate_gear_segments(model: Any, data: Any) -> None:
    """Switch each segmented gear equality of a ``mechanism.xml`` model to the segment holding its joint's
    current angle (``data.eq_active``); call before each ``mujoco.mj_step``. Does nothing for a model whose
    gear laws fit in one quartic."""
    import mujoco

    for k in range(model.nnumeric):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_NUMERIC, k)
        if not name or not name.startswith("gear_") or not name.endswith("_segments"):
            continue
        start, size = int(model.numeric_adr[k]), int(model.numeric_size[k])
        bounds = np.asarray(model.numeric_data[start:start + size])
        pair = name[len("gear_"):-len("_segments")]
        first = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, f"gear_{pair}_0")
        joint_a = int(model.eq_obj2id[first])
        u = float(data.qpos[model.jnt_qposadr[joint_a]] - model.qpos0[model.jnt_qposadr[joint_a]])
        chosen = int(np.clip(np.searchsorted(bounds, u, side="right") - 1, 0, size - 2))
        for s in range(size - 1):
            data.eq_active[first + s] = 1 if s == chosen else 0


# -- the document ---------------------------------------------------------------------------------------

def _num(x: float, digits: int = 12) -> str:
    value = float(x) + 0.0  # no "-0"
    if abs(value) < 1e-300:
        value = 0.0
    return f"{value:.{digits}g}"


def _vec(values: Sequence[float] | np.ndarray, digits: int = 12) -> str:
    return " ".join(_num(v, digits) for v in values)


def _quat(angle: float) -> str:
    return _vec([math.cos(angle / 2.0), 0.0, 0.0, math.sin(angle / 2.0)], 15)


_COLOURS = {"ground": "0.55 0.57 0.6 1", "gear": "0.85 0.55 0.2 1", "link": "0.25 0.5 0.8 1",
            "spacer": "0.7 0.7 0.7 1", "mount": "0.4 0.4 0.45 1"}


def actuator_limit(design: DesignSpec, driver: Driver, copies: int = 1) -> tuple[float, str, str] | None:
    """The design actuator's rating in SI (N·m or N) shared by the ``copies`` of the mechanism it drives
    together (one finger's share of a three-finger gripper's drive), its kind and model name; None without
    ``[actuator]`` or without a rating of the driver's kind."""
    from fabricate.drive.check import rating

    spec = design.actuator
    if spec is None:
        return None
    entry = spec.entry()
    unit = "N·mm" if driver.kind == "angle" else "N"
    try:
        value, kind, _ = rating(entry, unit)
    except SpecError:  # an entry without this rating: no actuator in the file (the drive check says why)
        return None
    value /= max(1, int(copies))
    return (value * MM if driver.kind == "angle" else value), kind, entry.name


def _actuator_lines(design: DesignSpec, mechanism: Mechanism, tree: Tree,
                    targets: list[tuple[str, float, np.ndarray]], copies: int) -> list[str]:
    """``<actuator>``: a motor on the driven joint, its control the effort along the driver's coordinate,
    limited to the catalogue rating (none without ``[actuator]`` or a rating)."""
    spec = design.actuator
    if spec is None or spec.driver >= len(mechanism.drivers):
        return []
    driver = mechanism.drivers[spec.driver]
    limit = actuator_limit(design, driver, copies)
    joint = driver_joint(mechanism, driver)
    held = tree.joint(joint.name) if joint is not None else None
    if limit is None or held is None:
        return []
    sign = next(sg for name, sg, _ in targets if name == held.name)
    value, kind, label = limit
    unit = "N·m" if driver.kind == "angle" else "N"
    share = f" (its share: one actuator drives the {copies} copies)" if copies > 1 else ""
    return ['  <actuator>',
            f'    <!-- {label}: {kind} {_num(value, 6)} {unit}{share}; the control is the effort along the driver -->',
            f'    <motor name="actuator" joint={quoteattr(held.name)} gear="{_num(sign)}" '
            f'ctrlrange="{_num(-value)} {_num(value)}" forcerange="{_num(-value)} {_num(value)}"/>',
            '  </actuator>']


def mechanism_mjcf(design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion,
                   gear_pairs: Sequence[GearPair], stl: Mapping[str, bytes]) -> bytes:
    """``mechanism.xml``: the mechanism as an MJCF document (see the module docstring); deterministic.

    Parameters
    ----------
    design : DesignSpec
        Its process density, ``[actuator]`` and name.
    partset : PartSet
        The parts (geoms, masses), the synthesis' hints (tip point, springs).
    mechanism, motion : Mechanism, Motion
        The first pose of ``motion`` is the model's initial configuration.
    gear_pairs : sequence of GearPair
        Unused beyond the mechanism's gear couplings (the laws are the couplings'); kept for the caller's
        symmetry with the other exporters.
    stl : mapping of str to bytes
        ``{part name: STL bytes}``, the files at ``parts/NAME.stl``.
    """
    del gear_pairs  # the couplings carry the laws
    bodies = _Bodies.of(design, partset, mechanism, motion, stl)
    lines = _header_lines(design, partset)
    lines += bodies.worldbody()
    equalities, fits, targets = _equality_lines(mechanism, motion, bodies.tree, bodies.coordinates)
    lines += equalities
    lines += _actuator_lines(design, mechanism, bodies.tree, targets, max(1, int(partset.copies)))
    lines += _gear_fit_lines(fits)
    for note in structure_notes(mechanism, bodies.tree) + bodies.notes:
        lines.append(f"  <!-- {note} -->")
    lines.append('</mujoco>')
    return ("\n".join(lines) + "\n").encode("utf-8")


def _header_lines(design: DesignSpec, partset: PartSet) -> list[str]:
    """The document's head: compiler, solver options, defaults, and a mesh asset per part."""
    lines = ['<mujoco model=' + quoteattr(design.name) + '>',
             f'  <!-- made by fabricate from {design.name}: SI units (m, kg, N); see fabricate/export/mjcf.py -->',
             '  <compiler angle="radian" autolimits="true" inertiafromgeom="false"/>',
             f'  <option timestep="{_num(TIMESTEP_S)}" integrator="implicitfast" solver="Newton" iterations="200" '
             'tolerance="1e-10" gravity="0 0 -9.81"/>',
             '  <default>',
             f'    <equality solref="{_num(2 * TIMESTEP_S)} 1" solimp="0.9999 0.9999 0.001 0.5 2"/>',
             '    <geom contype="2" conaffinity="1"/>',
             '  </default>',
             '  <asset>']
    for part in partset.parts:
        lines.append(f'    <mesh name={quoteattr(part.name)} file={quoteattr(f"parts/{part.name}.stl")} '
                     'scale="0.001 0.001 0.001"/>')
    lines.append('  </asset>')
    return lines


@dataclass(frozen=True)
class _Bodies:
    """What the ``<worldbody>`` is written from: the kinematic tree, the joints' coordinates, the bodies' mass
    properties, the springs the joints carry and the tip site; ``notes`` collects what the writing finds."""

    partset: PartSet
    mechanism: Mechanism
    motion: Motion
    springs: list[SpringHint]
    tree: Tree
    masses: dict[str, MassProperties]
    coordinates: dict[str, np.ndarray]
    by_joint: dict[str, Revolute | Slider]
    tip: str | None
    tip_body: str | None
    children: dict[str, list[TreeJoint]]
    notes: list[str]

    @classmethod
    def of(cls, design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion,
           stl: Mapping[str, bytes]) -> _Bodies:
        hints = partset.hints
        springs = [s for s in hints.springs if s.joint in spring_joints(partset, mechanism)]
        tree = kinematic_tree(mechanism, [s.joint for s in springs])
        masses = body_mass_properties(partset, stl, design.process.density_g_cm3)
        coordinates = joint_coordinates(mechanism, motion, tree)
        # sites: every named point of a body, and the tip
        tip = hints.tip_point if hints.tip_point in mechanism.point_names() else None
        tip_body = None
        if tip is not None:
            owners = [b for b, pad in (hints.pads or {}).items() if pad.point == tip]
            tip_body = owners[0] if owners else mechanism.point_owner(tip)
        children: dict[str, list[TreeJoint]] = {}
        for tj in tree.joints:
            children.setdefault(tj.parent, []).append(tj)
        return cls(partset, mechanism, motion, springs, tree, masses, coordinates,
                   {j.name: j for j in mechanism.joints}, tip, tip_body, children, [])

    def worldbody(self) -> list[str]:
        """``<worldbody>``: the ground body and, nested in it, the tree's bodies at the first pose."""
        first = self.motion.poses_at(0)
        ground = self.mechanism.ground
        lines = ['  <worldbody>', f'    <body name={quoteattr(ground)}>']
        lines += self.body_xml(ground, "      ")
        for tj in self.children.get(ground, []):
            lines += self.subtree(tj, "      ", first)
        lines += ['    </body>', '  </worldbody>']
        return lines

    def body_xml(self, name: str, indent: str) -> list[str]:
        """A body's inertial, its parts' mesh geoms and its sites."""
        out: list[str] = []
        m = self.masses.get(name)
        if m is None or m.mass <= 0.0:
            self.notes.append(f"body {name} has no printed part: a nominal 1 g point mass")
            m = MassProperties(1e-3, np.zeros(3), np.eye(3) * 1e-9)
        i = m.inertia
        out.append(f'{indent}<inertial pos="{_vec(m.com)}" mass="{_num(m.mass)}" '
                   f'fullinertia="{_vec([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])}"/>')
        for part in self.partset.parts:
            if part.body == name:
                out.append(f'{indent}<geom name={quoteattr(part.name)} type="mesh" mesh={quoteattr(part.name)} '
                           f'pos="0 0 {_num(part.z_mm * MM)}" rgba="{_COLOURS.get(part.role, "0.6 0.6 0.6 1")}"/>')
        body = self.mechanism.body(name)
        for point, xy in body.points.items():
            out.append(f'{indent}<site name={quoteattr(f"{name}.{point}")} pos="{_vec([xy[0] * MM, xy[1] * MM, 0])}" '
                       'size="0.0008"/>')
            if point == self.tip and name == self.tip_body:
                out.append(f'{indent}<site name="tip" pos="{_vec([xy[0] * MM, xy[1] * MM, 0])}" size="0.0015" '
                           'rgba="1 0.2 0.2 1"/>')
        return out

    def joint_xml(self, tj: TreeJoint, indent: str) -> str:
        """The joint a tree edge's child body turns or slides on."""
        j = self.by_joint[tj.name]
        ref = float(self.coordinates[tj.name][0])
        child = self.mechanism.body(tj.child)
        anchor = child.point(j.name)
        if isinstance(j, Slider):
            axis = np.asarray(j.axis, dtype=np.float64) / math.hypot(*j.axis)
            if tj.child == j.body_b:  # the axis is fixed in body_a; body_b's frame is turned by `angle` from it
                c, s = math.cos(j.angle), math.sin(j.angle)
                axis = np.array([c * axis[0] + s * axis[1], -s * axis[0] + c * axis[1]])
            # body_a the child: moving it along +u lowers the coordinate, and its qpos is minus the coordinate
            return (f'{indent}<joint name={quoteattr(j.name)} type="slide" pos="{_vec([*(anchor * MM), 0])}" '
                    f'axis="{_vec([*axis, 0])}" ref="{_num(ref, 15)}"{self.spring_attr(tj)}/>')
        return (f'{indent}<joint name={quoteattr(j.name)} type="hinge" pos="{_vec([*(anchor * MM), 0])}" '
                f'axis="0 0 1" ref="{_num(ref, 15)}"{self.spring_attr(tj)}/>')

    def spring_attr(self, tj: TreeJoint) -> str:
        """A torsion spring's stiffness and free angle on its joint ('' for a joint without one)."""
        for s in self.springs:
            if s.joint != tj.name:
                continue
            j = self.by_joint[tj.name]
            rel = np.degrees(self.motion.relative_angle(j.body_b, j.body_a))
            sense = 1.0 if rel[-1] >= rel[0] else -1.0
            free = math.radians(float(rel[0]) - sense * s.preload_deg)  # the relative angle where it is unwound
            stiffness = s.rate_Nmm_per_deg * 180.0 / math.pi * MM  # N·m/rad
            return f' stiffness="{_num(stiffness)}" springref="{_num(tj.sign * free, 15)}"'
        return ""

    def subtree(self, tj: TreeJoint, indent: str, first: Mapping[str, np.ndarray]) -> list[str]:
        """A tree edge's child body in its parent's frame, with its joint and its own subtrees."""
        parent, child = first[tj.parent], first[tj.child]
        c, s = math.cos(parent[2]), math.sin(parent[2])
        d = child[:2] - parent[:2]
        local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
        out = [f'{indent}<body name={quoteattr(tj.child)} pos="{_vec([*(local * MM), 0])}" '
               f'quat="{_quat(float(child[2] - parent[2]))}">', self.joint_xml(tj, indent + "  ")]
        out += self.body_xml(tj.child, indent + "  ")
        for grandchild in self.children.get(tj.child, []):
            out += self.subtree(grandchild, indent + "  ", first)
        out.append(f"{indent}</body>")
        return out


def _equality_lines(mechanism: Mechanism, motion: Motion, tree: Tree, coordinates: dict[str, np.ndarray]
                    ) -> tuple[list[str], list[GearFit], list[tuple[str, float, np.ndarray]]]:
    """``<equality>``: the loops' connects, the gear laws' segments and the drivers' (inactive) equalities;
    with the gear fits and the drivers' targets the rest of the document reads. ``coordinates``: every tree
    joint's ``qpos`` over the motion (:func:`joint_coordinates`)."""
    lines = ['  <equality>']
    for j in tree.loops:
        if isinstance(j, Slider):
            continue
        anchor = mechanism.body(j.body_a).point(j.name) * MM
        lines.append(f'    <connect name={quoteattr(f"pin_{j.name}")} body1={quoteattr(j.body_a)} '
                     f'body2={quoteattr(j.body_b)} anchor="{_vec([*anchor, 0])}"/>')
    fits: list[GearFit] = []
    for k, g in enumerate(mechanism.gears):
        fit = fit_gear(mechanism, motion, tree, k)
        if fit is None:
            continue
        fits.append(fit)
        start = active_segment(fit, 0.0)
        for s, coef in enumerate(fit.coefficients):
            active = "" if s == start else ' active="false"'
            lines.append(f'    <joint name={quoteattr(f"gear_{g.name}_{s}")} joint1={quoteattr(fit.joint_b)} '
                         f'joint2={quoteattr(fit.joint_a)} polycoef="{_vec(coef, 17)}"{active}/>')
    targets = driver_targets(mechanism, motion, tree, coordinates)
    for k, (joint, _, _) in enumerate(targets):
        lines.append(f'    <joint name="drive_{k}" joint1={quoteattr(joint)} polycoef="0 0 0 0 0" active="false"/>')
    lines.append('  </equality>')
    return lines, fits, targets


def _gear_fit_lines(fits: Sequence[GearFit]) -> list[str]:
    """The segmented gear fits' bounds (``<custom>``) and a comment per fit with its largest error."""
    lines = []
    if fits and any(len(f.coefficients) > 1 for f in fits):
        lines.append('  <custom>')
        for f in fits:
            if len(f.coefficients) > 1:
                lines.append(f'    <numeric name={quoteattr(f"gear_{f.name}_segments")} size="{len(f.bounds)}" '
                             f'data="{_vec(f.bounds, 17)}"/>')
        lines.append('  </custom>')
    for f in fits:
        lines.append(f'  <!-- gear {f.name}: {len(f.coefficients)} quartic segment(s), largest error of the fit '
                     f'{_num(f.max_error_rad, 3)} rad -->')
    return lines

def spring_joints(partset: PartSet, mechanism: Mechanism) -> list[str]:
    """The revolute joints whose torsion spring (a rate above 0) the model carries as joint stiffness."""
    return [s.joint for s in partset.hints.springs if s.rate_Nmm_per_deg > 0.0
            and any(isinstance(j, Revolute) and j.name == s.joint for j in mechanism.joints)]


def simulation_section(design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion) -> dict[str, Any]:
    """report.json's ``simulation``: what mechanism.xml holds and how (fabricate/report_schema.json)."""
    tree = kinematic_tree(mechanism, spring_joints(partset, mechanism))
    fits = [fit for fit in (fit_gear(mechanism, motion, tree, k) for k in range(len(mechanism.gears)))
            if fit is not None]
    actuator = None
    spec = design.actuator
    if spec is not None and spec.driver < len(mechanism.drivers):
        driver = mechanism.drivers[spec.driver]
        limit = actuator_limit(design, driver, partset.copies)
        joint = driver_joint(mechanism, driver)
        if limit is not None and joint is not None and tree.joint(joint.name) is not None:
            actuator = {"joint": joint.name, "model": limit[2], "limit": limit[0],
                        "unit": "N·m" if driver.kind == "angle" else "N", "rating": limit[1]}
    return {
        "mjcf": "mechanism.xml",
        "joints": [tj.name for tj in tree.joints],
        "connect": [j.name for j in tree.loops if isinstance(j, Revolute)],
        "gear_fits": [{"pair": f.name, "joints": [f.joint_a, f.joint_b], "segments": len(f.coefficients),
                       "max_error_rad": float(f"{f.max_error_rad:.4g}")} for f in fits],
        "springs": spring_joints(partset, mechanism),
        "actuator": actuator,
        "solver": {"timestep_s": TIMESTEP_S, "integrator": "implicitfast", "solver": "Newton",
                   "equality_solref": [2 * TIMESTEP_S, 1.0], "equality_solimp": [0.9999, 0.9999, 0.001, 0.5, 2.0]},
        "notes": structure_notes(mechanism, tree),
    }

def load_model(files: Mapping[str, bytes]) -> Any:
    """A build's ``mechanism.xml`` as a ``mujoco.MjModel``, its meshes from the build's own STL files in
    ``files`` (``{relative path: bytes}``, as :attr:`fabricate.Build.files`); nothing is read from disk.

    Raises
    ------
    FabricateError
        When ``files`` holds no ``mechanism.xml`` (a synthesis-only run, or a build that stopped before its
        exports), or the ``mujoco`` package is not installed (the ``sim`` extra).
    """
    if "mechanism.xml" not in files:
        raise FabricateError("no mechanism.xml in this result: only a build that got to its exports makes one")
    try:
        import mujoco
    except ImportError:
        raise FabricateError("MuJoCo is not installed: pip install 'fabricate[sim]'") from None
    assets = {path: data for path, data in files.items() if path.startswith("parts/") and path.endswith(".stl")}
    return mujoco.MjModel.from_xml_string(files["mechanism.xml"].decode("utf-8"), assets)
