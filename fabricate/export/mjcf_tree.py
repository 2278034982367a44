"""The kinematic tree :mod:`fabricate.export.mjcf` writes a mechanism as, and its gear laws fitted as
MuJoCo's quartic joint equalities.

- :func:`kinematic_tree`: the spanning tree of the mechanism's joints from the ground, sliders first, then the
  drivers', the gear axes' and the springs' joints (so each is a MuJoCo joint with a coordinate), then the
  others in order; the joints it cannot hold are the loops ``mechanism.xml`` closes with ``connect``.
- :func:`joint_coordinates` and :func:`driver_targets`: every tree joint's ``qpos`` over the motion, and what
  each driver sets.
- :func:`fit_gear`: a gear law as quartics ``y - y0 = a0 + a1 (x - x0) + ... + a4 (x - x0)^4``, split into
  segments until each misses the law by at most :data:`GEAR_FIT_TOLERANCE_RAD`.
- :func:`structure_notes`: what the tree cannot hold of the mechanism.

Pure numpy on fabricate's :mod:`fabricate.mechanism` model; nothing here writes XML or needs MuJoCo.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fabricate.export.mass import MM
from fabricate.mechanism import Driver, Mechanism, Motion, Revolute, Slider

#: Largest error (rad) of a gear law's quartic fit before the range is split into segments.
GEAR_FIT_TOLERANCE_RAD = 5e-5
#: Most segments one gear law is split into.
MAX_GEAR_SEGMENTS = 64


@dataclass(frozen=True)
class GearFit:
    """A gear law as MuJoCo joint equalities: ``joint_b - qb0 = poly_k(joint_a - qa0)`` on segment k.

    Attributes
    ----------
    name : str
        The gear coupling.
    joint_a, joint_b : str
        The MuJoCo joints of gear a (x) and gear b (y).
    bounds : (k + 1,) array
        Segment bounds in ``joint_a - qa0`` (rad), increasing.
    coefficients : (k, 5) array
        Each segment's a0..a4.
    max_error_rad : float
        Largest difference between the fitted polynomials and the law over the range (on a dense grid).
    """

    name: str
    joint_a: str
    joint_b: str
    bounds: np.ndarray
    coefficients: np.ndarray
    max_error_rad: float


@dataclass(frozen=True)
class TreeJoint:
    """A mechanism joint held by the kinematic tree: ``child`` hangs from ``parent`` at it; ``sign`` is +1
    when the joint's coordinate (relative angle body_b - body_a, or the slide's coordinate) is MuJoCo's
    ``qpos``, -1 when it is its negative."""

    name: str
    parent: str
    child: str
    sign: float


@dataclass(frozen=True)
class Tree:
    """Which body hangs from which (``joints`` in parent-first order) and the joints left to ``connect``."""

    joints: tuple[TreeJoint, ...]
    loops: tuple[Revolute | Slider, ...]
    unreached: tuple[str, ...]

    def joint(self, name: str) -> TreeJoint | None:
        return next((j for j in self.joints if j.name == name), None)

# -- kinematic tree -----------------------------------------------------------------------------------

def driver_joint(mechanism: Mechanism, driver: Driver) -> Revolute | Slider | None:
    """The joint whose coordinate a driver sets: its slider, or the revolute between its two bodies."""
    for j in mechanism.joints:
        if driver.kind == "slide" and isinstance(j, Slider) and j.name == driver.joint:
            return j
        if driver.kind == "angle" and isinstance(j, Revolute) and {j.body_a, j.body_b} == {driver.body,
                                                                                              driver.reference}:
            return j
    return None


def _gear_joint(mechanism: Mechanism, name: str, gear: str, carrier: str) -> Revolute | None:
    for j in mechanism.joints:
        if isinstance(j, Revolute) and {j.body_a, j.body_b} == {gear, carrier} and (not name or j.name == name):
            return j
    return next((j for j in mechanism.joints if isinstance(j, Revolute) and {j.body_a, j.body_b} == {gear, carrier}),
                None)


def kinematic_tree(mechanism: Mechanism, spring_joints: Sequence[str] = ()) -> Tree:
    """The spanning tree of the mechanism's joints from the ground (see the module docstring)."""
    joints = list(mechanism.joints)
    wanted: list[str] = [j.name for j in joints if isinstance(j, Slider)]
    for d in mechanism.drivers:
        j = driver_joint(mechanism, d)
        if j is not None:
            wanted.append(j.name)
    for g in mechanism.gears:
        for name, gear in ((g.axis_a, g.gear_a), (g.axis_b, g.gear_b)):
            j = _gear_joint(mechanism, name, gear, g.carrier)
            if j is not None:
                wanted.append(j.name)
    wanted += list(spring_joints)
    order = {name: k for k, name in enumerate(dict.fromkeys(wanted))}
    ranked = sorted(joints, key=lambda j: (order.get(j.name, len(order)), joints.index(j)))
    root = {b: b for b in mechanism.body_names}

    def find(b: str) -> str:
        while root[b] != b:
            root[b] = root[root[b]]
            b = root[b]
        return b

    edges: list[Revolute | Slider] = []
    loops: list[Revolute | Slider] = []
    for j in ranked:
        ra, rb = find(j.body_a), find(j.body_b)
        if ra == rb:
            loops.append(j)
        else:
            root[ra] = rb
            edges.append(j)
    # orient from the ground, breadth first
    tree: list[TreeJoint] = []
    reached = {mechanism.ground}
    frontier = [mechanism.ground]
    while frontier:
        nxt: list[str] = []
        for parent in frontier:
            for j in edges:
                if parent in (j.body_a, j.body_b):
                    child = j.body_b if parent == j.body_a else j.body_a
                    if child in reached:
                        continue
                    reached.add(child)
                    nxt.append(child)
                    tree.append(TreeJoint(j.name, parent, child, 1.0 if child == j.body_b else -1.0))
        frontier = nxt
    loops.sort(key=joints.index)
    unreached = tuple(b for b in mechanism.body_names if b not in reached)
    return Tree(tuple(tree), tuple(loops), unreached)


def _slide_coordinates(motion: Motion, j: Slider) -> np.ndarray:
    """(p_b - p_a) . u at every pose of the motion (mm), u the slider's unit axis fixed in body_a.

    The points and body_a's angle are taken over the motion once (a pose's row of them is the same), the axis
    turned and the dot product made per pose as before (math.cos and a 2-vector product: the same floats)."""
    axis = np.asarray(j.axis, dtype=np.float64) / math.hypot(*j.axis)
    pa, pb = motion.point(j.name, j.body_a), motion.point(j.name, j.body_b)
    out = np.empty(len(pa))
    for i, theta_a in enumerate(motion.pose(j.body_a)[:, 2].tolist()):
        u = np.array([math.cos(theta_a) * axis[0] - math.sin(theta_a) * axis[1],
                      math.sin(theta_a) * axis[0] + math.cos(theta_a) * axis[1]])
        out[i] = (pb[i] - pa[i]) @ u
    return out


def joint_coordinates(mechanism: Mechanism, motion: Motion, tree: Tree) -> dict[str, np.ndarray]:
    """Every tree joint's MuJoCo ``qpos`` over the motion (rad, or m for a slide), shape (n,)."""
    out: dict[str, np.ndarray] = {}
    by_name = {j.name: j for j in mechanism.joints}
    for tj in tree.joints:
        j = by_name[tj.name]
        if isinstance(j, Slider):
            values = _slide_coordinates(motion, j) * MM
        else:
            values = motion.relative_angle(j.body_b, j.body_a)
        out[tj.name] = tj.sign * np.asarray(values, dtype=np.float64)
    return out


def driver_targets(mechanism: Mechanism, motion: Motion, tree: Tree,
                   coordinates: dict[str, np.ndarray] | None = None) -> list[tuple[str, float, np.ndarray]]:
    """Per driver: its MuJoCo joint, the sign from the driver's coordinate to that joint's ``qpos``, and the
    ``qpos`` the driver sets at each input of the motion. ``coordinates``: :func:`joint_coordinates`' answer
    where the caller has it already."""
    if coordinates is None:
        coordinates = joint_coordinates(mechanism, motion, tree)
    out = []
    for d in mechanism.drivers:
        j = driver_joint(mechanism, d)
        tj = tree.joint(j.name) if j is not None else None
        if tj is None or j is None:
            continue
        # the driver's coordinate is theta_body - theta_reference (or the slide's from the reference); the
        # joint's is theta_b - theta_a (or the slide's of body_b along body_a)
        sign = tj.sign if j.body_b == d.body else -tj.sign
        out.append((tj.name, sign, coordinates[tj.name]))
    return out


# -- gear laws ------------------------------------------------------------------------------------------

def fit_gear(mechanism: Mechanism, motion: Motion, tree: Tree, coupling_index: int) -> GearFit | None:
    """The gear law of coupling ``coupling_index`` as quartic joint equalities (None where the tree does not
    hold both gears' axes)."""
    g = mechanism.gears[coupling_index]
    ja = _gear_joint(mechanism, g.axis_a, g.gear_a, g.carrier)
    jb = _gear_joint(mechanism, g.axis_b, g.gear_b, g.carrier)
    ta = tree.joint(ja.name) if ja is not None else None
    tb = tree.joint(jb.name) if jb is not None else None
    if ja is None or jb is None or ta is None or tb is None:
        return None
    # x = theta_a - theta_c = sa * qpos_a, y = theta_b - theta_c = sb * qpos_b
    sa = ta.sign * (1.0 if ja.body_b == g.gear_a else -1.0)
    sb = tb.sign * (1.0 if jb.body_b == g.gear_b else -1.0)
    x_motion = motion.relative_angle(g.gear_a, g.carrier)
    y_motion = motion.relative_angle(g.gear_b, g.carrier)
    qa0, qb0 = sa * float(x_motion[0]), sb * float(y_motion[0])
    lo, hi = sorted(float(v) for v in g.working_range)
    if hi - lo <= 0.0:
        lo, hi = float(np.min(x_motion)), float(np.max(x_motion))
    lo, hi = min(lo, float(np.min(x_motion))), max(hi, float(np.max(x_motion)))
    # the working range in u = qpos_a - qa0
    u_lo, u_hi = sorted((sa * lo - qa0, sa * hi - qa0))

    def target(u: np.ndarray) -> np.ndarray:
        return sb * np.asarray(g.law(sa * (qa0 + u)), dtype=np.float64) - qb0

    segments = 1
    while True:
        bounds = np.linspace(u_lo, u_hi, segments + 1)
        coefficients = np.zeros((segments, 5))
        worst = 0.0
        for k in range(segments):
            # Chebyshev nodes for the fit, a dense even grid (ends included) to measure it
            nodes = 0.5 * (bounds[k] + bounds[k + 1]) + 0.5 * (bounds[k + 1] - bounds[k]) * np.cos(
                np.pi * (np.arange(40) + 0.5) / 40)
            fit = np.polynomial.Polynomial.fit(nodes, target(nodes), 4).convert()
            coefficients[k, :len(fit.coef)] = fit.coef
            grid = np.linspace(bounds[k], bounds[k + 1], 201)
            worst = max(worst, float(np.max(np.abs(np.polynomial.polynomial.polyval(grid, coefficients[k])
                                                   - target(grid)))))
        if worst <= GEAR_FIT_TOLERANCE_RAD or segments >= MAX_GEAR_SEGMENTS:
            return GearFit(g.name, ja.name, jb.name, bounds, coefficients, worst)
        segments *= 2


def active_segment(fit: GearFit, u: float) -> int:
    """The segment of ``fit`` whose range holds ``u`` (= qpos_a - qa0); the nearest one outside the range."""
    return int(np.clip(np.searchsorted(fit.bounds, u, side="right") - 1, 0, len(fit.coefficients) - 1))


def structure_notes(mechanism: Mechanism, tree: Tree) -> list[str]:
    """What the model cannot hold of the mechanism (empty for every shipped template)."""
    notes = [f"body {name} is joined to nothing the ground reaches: left out" for name in tree.unreached]
    notes += [f"slider {j.name} closes a loop: MuJoCo has no equality for it, the loop is open"
              for j in tree.loops if isinstance(j, Slider)]
    for g in mechanism.gears:
        ja = _gear_joint(mechanism, g.axis_a, g.gear_a, g.carrier)
        jb = _gear_joint(mechanism, g.axis_b, g.gear_b, g.carrier)
        if ja is None or jb is None or tree.joint(ja.name) is None or tree.joint(jb.name) is None:
            notes.append(f"gear {g.name}: its axes are not both joints of the tree, the law is not coupled")
    return notes


def gear_fits(mechanism: Mechanism, motion: Motion, spring_joints: Sequence[str] = ()) -> list[GearFit]:
    """The gear fits :func:`mechanism_mjcf` writes (for reports and tests)."""
    tree = kinematic_tree(mechanism, spring_joints)
    fits = [fit_gear(mechanism, motion, tree, k) for k in range(len(mechanism.gears))]
    return [f for f in fits if f is not None]
