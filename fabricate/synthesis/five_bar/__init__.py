"""Seed 000: one-DOF five-bar finger O-A-B-C-D driven through a non-circular gear pair.

The finger is three phalanges O-D, D-C, C-P (Table 1) with target poses given as absolute phalanx
angles (Table 2). In the frame of the proximal phalanx O-D the five-bar is a four-bar A-B-C-D whose
coupler is the distal phalanx; the dyad A-B is unknown (A fixed in the proximal body, B fixed in the
distal one). The kinematic mapping of the distal poses (eqs 1-2), the matrix ``M`` (eq 11) and the
four smallest eigenvectors of ``M^T M`` (eq 13) give a one-parameter family of dyads traced with
``kappa = cot(omega)`` (eq 14): the hinge curves of A and B (Fig 8). The template's limits cut the
feasible domain out of them (Fig 9), a rule picks one dyad, and the rotation of A-B relative to the
arm O-A, against the ground's rotation relative to the arm, is interpolated by a cubic spline through
the poses: the law of a sun gear fixed at O and a planet fixed to A-B at A (Fig 10). The result is a
:class:`~fabricate.mechanism.Mechanism` whose solved motion gives the fingertip error at every pose.

Departures from the printed formulas (OCR slips, checked by reconstruction in the tests):

- eq 1: the distal pose in the proximal frame is ``(R(-t1) (P - O), t3 - t1)``; the printed ``j1, j2``
  and ``v = phi1 - phi2`` do not reproduce a rigid transformation.
- eq 9: the centre is ``A = -(p4, p5) / p1`` (``a0 = p1 / 2``), see :mod:`.kinematic_mapping`.
- eq 19: rolling without slip, ``r_a dx_a = r_b dx_b`` with ``r_a + r_b = |OA|`` and ratio
  ``i = -f'(x_a)``, gives ``r_a = |OA| i / (1 + i)`` and ``r_b = |OA| / (1 + i)``; the printed
  ``r1 = a / (1 + i12)`` with ``|OA| = 2a`` is neither.
- order defect (section 2.3): the paper asks for phi1 "from small to large"; which sense is right
  depends on the frame's orientation, so we require A-B to turn strictly monotonically relative to
  O-D and let the gear check decide the sense (an external pair needs ``f' < 0``).
- eq 15-16: the pose error is not estimated from the dyad directions but measured on the solved
  mechanism (A-B's angle at each pose is eq 10's direction of A->B_i, which the spline interpolates).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from fabricate.bounds import MAX_KAPPA_SAMPLES, MAX_LENGTH_MM, MIN_CURVE_STEP_MM
from fabricate.errors import FabricateError, LockupError, SpecError, SynthesisError
from fabricate.mechanism import Body, Driver, GearCoupling, Mechanism, Motion, Revolute
from fabricate.planar import rotation, unit, wrap_angle
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.five_bar import kinematic_mapping as km
from fabricate.synthesis.five_bar.law import GearLaw, gear_law
from fabricate.table import Table

#: Rules for picking one dyad of the feasible domain.
SELECTION_RULES = ("x_A", "least_pose_error")
#: Minimum number of poses: with fewer, the four smallest eigenvectors of M^T M span an arbitrary
#: part of a larger null space and the family is not determined by the poses.
MIN_POSES = 4
#: Most target poses (each adds a row to the constraint matrix and a knot to the gear law).
MAX_POSES = 100


# -- spec ------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class FiveBarSpec:
    """``[finger]`` and ``[synthesis]`` of a five_bar_ncg template. Lengths mm, angles deg.

    Attributes
    ----------
    lengths_mm : (float, float, float)
        Phalanx lengths O-D, D-C, C-P (Table 1).
    origin_mm : (float, float)
        Position of the base joint O.
    poses_deg : tuple of (float, float, float)
        Absolute angles of the three phalanges from +x at every target pose, in motion order.
    pad_radius_mm : float
        Fingertip pad radius (a parts hint).
    kappa_samples : int
        Samples of ``omega`` in (0, pi) for tracing the hinge curves.
    curve_step_mm : float
        Largest step of A or B between samples inside the A box (more samples are inserted there).
    a_x_mm, a_y_mm : (float, float)
        Box for hinge A at the first pose.
    ab_length_mm, bc_length_mm : (float, float)
        Allowed lengths of A-B and B-C.
    max_length_error_mm : float
        Largest allowed change of |AB| over the target poses (the dyad's error, eq 16's cause).
    transmission_ratio : (float, float)
        Allowed range of the gear ratio ``i = -dx_b / dx_a`` over the working range.
    min_pitch_curvature_radius_mm : float
        Both pitch curves must be convex with at least this radius of curvature.
    select : str
        ``"x_A"`` (the feasible dyad whose A has x = ``x_A_mm``; least length error among several)
        or ``"least_pose_error"``.
    x_A_mm : float or None
    """

    lengths_mm: tuple[float, float, float]
    origin_mm: tuple[float, float]
    poses_deg: tuple[tuple[float, float, float], ...]
    pad_radius_mm: float
    kappa_samples: int
    curve_step_mm: float
    a_x_mm: tuple[float, float]
    a_y_mm: tuple[float, float]
    ab_length_mm: tuple[float, float]
    bc_length_mm: tuple[float, float]
    max_length_error_mm: float
    transmission_ratio: tuple[float, float]
    min_pitch_curvature_radius_mm: float
    select: str
    x_A_mm: float | None


def _interval(table: Table, key: str, default: Any = None, *, positive: bool = False,
              bound: float = MAX_LENGTH_MM) -> tuple[float, float]:
    arr = table.array(key, default, shape=(2,), positive=positive, min=-bound, max=bound) if default is not None \
        else table.array(key, shape=(2,), positive=positive, min=-bound, max=bound)
    arr = np.asarray(arr, dtype=np.float64)
    if not arr[0] < arr[1]:
        raise SpecError(table.field(key), f"expected [low, high] with low < high, got {arr.tolist()}")
    return float(arr[0]), float(arr[1])


def parse_spec(root: Table) -> FiveBarSpec:
    """Read ``[finger]`` and ``[synthesis]`` from a template root.

    Raises
    ------
    SpecError
        Naming the field: fewer than four poses, a proximal angle that does not change monotonically,
        empty ranges, a selection rule without its target.
    """
    finger = root.table("finger")
    # magnitudes and counts are bounded (fabricate.bounds): a 1e300 mm phalanx overflows the mapping
    lengths = finger.array("lengths_mm", shape=(3,), positive=True, max=MAX_LENGTH_MM)
    origin = finger.array("origin_mm", [0.0, 0.0], shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
    poses = finger.array("poses_deg", shape=(None, 3), min_rows=MIN_POSES, min=-720.0, max=720.0)
    if len(poses) > MAX_POSES:
        raise SpecError(finger.field("poses_deg"), f"{len(poses)} poses, over the bound of {MAX_POSES}")
    pad = finger.number("pad_radius_mm", 5.0, positive=True, max=200.0)
    finger.finish()
    proximal = np.diff(np.unwrap(np.radians(poses[:, 0])))
    if not (np.all(proximal > 0) or np.all(proximal < 0)):
        raise SpecError(finger.field("poses_deg"),
                        "the proximal angle (first column) must change strictly monotonically over the poses")
    syn = root.table("synthesis")
    spec = FiveBarSpec(
        lengths_mm=tuple(float(v) for v in lengths),
        origin_mm=tuple(float(v) for v in origin),
        poses_deg=tuple(tuple(float(v) for v in row) for row in poses),
        pad_radius_mm=pad,
        kappa_samples=syn.integer("kappa_samples", 2001, min=50, max=MAX_KAPPA_SAMPLES),
        curve_step_mm=syn.number("curve_step_mm", 0.25, min=MIN_CURVE_STEP_MM, max=MAX_LENGTH_MM),
        a_x_mm=_interval(syn, "a_x_mm"),
        a_y_mm=_interval(syn, "a_y_mm"),
        ab_length_mm=_interval(syn, "ab_length_mm", positive=True),
        bc_length_mm=_interval(syn, "bc_length_mm", positive=True),
        max_length_error_mm=syn.number("max_length_error_mm", 0.5, positive=True, max=MAX_LENGTH_MM),
        transmission_ratio=_interval(syn, "transmission_ratio", [0.2, 5.0], positive=True, bound=1000.0),
        min_pitch_curvature_radius_mm=syn.number("min_pitch_curvature_radius_mm", 2.0, min=0.0, max=MAX_LENGTH_MM),
        select=syn.string("select", "least_pose_error", choices=SELECTION_RULES),
        x_A_mm=syn.number("x_A_mm", None, min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM),
    )
    if spec.select == "x_A" and spec.x_A_mm is None:
        raise SpecError(syn.field("x_A_mm"), 'missing required field (select = "x_A" needs it)')
    syn.finish()
    return spec


# -- targets -----------------------------------------------------------------------------------------

@dataclass(frozen=True)
class FingerTargets:
    """Target poses in world coordinates (mm, rad).

    Attributes
    ----------
    angles : (n, 3) array
        Absolute phalanx angles, unwrapped over the poses, the first pose's in (-pi, pi].
    origin : (2,) array
    d, c, p : (n, 2) arrays
        Joint D, joint C and fingertip P at every pose.
    displacements : (n, 3) array
        Pose of the distal frame (origin P, x along C->P) in the proximal frame (origin O, x along
        O->D): ``(e, f, v)``, the input of the kinematic mapping.
    """

    angles: np.ndarray
    origin: np.ndarray
    lengths: np.ndarray
    d: np.ndarray
    c: np.ndarray
    p: np.ndarray
    displacements: np.ndarray

    def distal_to_world(self, point: np.ndarray) -> np.ndarray:
        """World positions (n, 2) of a distal-frame point at every pose."""
        return self.p + np.einsum("nij,j->ni", rotation(self.angles[:, 2]), point)

    def proximal_to_world(self, point: np.ndarray) -> np.ndarray:
        """World positions (n, 2) of a proximal-frame point at every pose."""
        return self.origin + np.einsum("nij,j->ni", rotation(self.angles[:, 0]), point)

    def distal_to_proximal(self, point: np.ndarray) -> np.ndarray:
        """Proximal-frame positions (n, 2) of a distal-frame point at every pose."""
        e, f, v = self.displacements.T
        return np.einsum("nij,j->ni", rotation(v), point) + np.stack([e, f], -1)


def finger_targets(spec: FiveBarSpec) -> FingerTargets:
    """Joint positions and the distal-in-proximal displacements of the template's poses."""
    angles = np.unwrap(np.radians(np.asarray(spec.poses_deg, dtype=np.float64)), axis=0)
    # a whole number of turns moves the first pose into (-pi, pi] (Table 2 writes 0 deg as 360)
    angles = angles + (wrap_angle(angles[0]) - angles[0])
    lengths = np.asarray(spec.lengths_mm, dtype=np.float64)
    origin = np.asarray(spec.origin_mm, dtype=np.float64)
    d = origin + lengths[0] * unit(angles[:, 0])
    c = d + lengths[1] * unit(angles[:, 1])
    p = c + lengths[2] * unit(angles[:, 2])
    local = np.einsum("nji,nj->ni", rotation(angles[:, 0]), p - origin)  # R(-t1) (P - O)
    displacements = np.column_stack([local, angles[:, 2] - angles[:, 0]])
    return FingerTargets(angles=angles, origin=origin, lengths=lengths, d=d, c=c, p=p,
                         displacements=displacements)


# -- gear law ----------------------------------------------------------------------------------------

def dyad_angles(targets: FingerTargets, a_proximal: np.ndarray, b_distal: np.ndarray) -> np.ndarray:
    """Direction of A->B in the proximal frame at every pose (eq 10), unwrapped, rad."""
    b = targets.distal_to_proximal(b_distal) - a_proximal
    return np.unwrap(np.arctan2(b[:, 1], b[:, 0]))


def law_knots(targets: FingerTargets, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pose samples of the gear law from the dyad angles ``phi`` (rad).

    Bodies other than the proximal one use world coordinates of the first pose as body coordinates
    (so their angle is 0 there); the proximal body's angle is the absolute angle t1. Hence
    ``x_a = -t1`` and ``x_b = theta_AB - t1 = phi - phi_0 - t1_0``.
    """
    t1 = targets.angles[:, 0]
    return -t1, phi - phi[0] - t1[0]


# -- feasible domain ---------------------------------------------------------------------------------

#: Reasons a hinge-curve point is rejected, in the order they are tested, with the template field
#: (or rule) responsible. Status 0 is feasible; status k is ``REJECTIONS[k - 1]``.
REJECTIONS = (
    ("a_box", "synthesis.a_x_mm / synthesis.a_y_mm (box for hinge A)"),
    ("ab_length", "synthesis.ab_length_mm"),
    ("bc_length", "synthesis.bc_length_mm"),
    ("length_error", "synthesis.max_length_error_mm"),
    ("order_defect", "order defect (A-B must turn monotonically relative to O-D)"),
    ("transmission_ratio", "synthesis.transmission_ratio (gear ratio positive, finite, in range)"),
    ("pitch_curvature", "synthesis.min_pitch_curvature_radius_mm (convex pitch curves)"),
)


@dataclass(frozen=True)
class HingeDomain:
    """Every traced dyad with its first-pose hinge positions and the limit that rejects it.

    Attributes
    ----------
    family : km.DyadFamily
        Centre = A in the proximal frame, point = B in the distal frame.
    a, b : (m, 2) arrays
        A and B in world coordinates at the first pose, mm.
    ab, bc, length_error : (m,) arrays
        |AB|, |BC| at the first pose and the largest change of |AB| over the poses, mm.
    status : (m,) int array
        0 feasible, else 1 + index into :data:`REJECTIONS`.
    """

    family: km.DyadFamily
    a: np.ndarray
    b: np.ndarray
    ab: np.ndarray
    bc: np.ndarray
    length_error: np.ndarray
    status: np.ndarray

    @property
    def feasible(self) -> np.ndarray:
        return self.status == 0

    def rejected_counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.status == k + 1)) for k, (name, _) in enumerate(REJECTIONS)}


def gear_check(spec: FiveBarSpec, targets: FingerTargets, a_proximal: np.ndarray,
               b_distal: np.ndarray) -> tuple[int, GearLaw | None]:
    """Order-defect and gear limits of one dyad: (status, law); status 0 when feasible."""
    phi = dyad_angles(targets, a_proximal, b_distal)
    step = np.diff(phi)
    if not (np.all(step > 0) or np.all(step < 0)):
        return 5, None
    knots_a, knots_b = law_knots(targets, phi)
    law = gear_law(knots_a, knots_b, float(np.hypot(*a_proximal)))
    lo, hi = spec.transmission_ratio
    if not (np.all(np.isfinite(law.ratio)) and np.all(law.ratio >= lo) and np.all(law.ratio <= hi)):
        return 6, law
    rho = np.concatenate([law.rho_a, law.rho_b])
    if not (np.all(np.isfinite(rho)) and np.all(rho >= spec.min_pitch_curvature_radius_mm)):
        return 7, law
    return 0, law


def hinge_domain(spec: FiveBarSpec, targets: FingerTargets, family: km.DyadFamily) -> HingeDomain:
    """Apply the template limits to every traced dyad (the feasible domain of Fig 9)."""
    a_prox, b_dist = family.centre, family.point
    a = targets.origin + a_prox @ rotation(targets.angles[0, 0]).T
    b = targets.p[0] + b_dist @ rotation(targets.angles[0, 2]).T
    ab = np.hypot(*(b - a).T)
    bc = np.hypot(*(b - targets.c[0]).T)
    # B in the proximal frame at every pose, (m, n, 2): the dyad's length at each pose
    e, f, v = targets.displacements.T
    b_prox = np.einsum("nij,mj->mni", rotation(v), b_dist) + np.stack([e, f], -1)
    radius = np.linalg.norm(b_prox - a_prox[:, None, :], axis=-1)
    length_error = np.max(np.abs(radius - ab[:, None]), axis=1)
    status = np.zeros(len(ab), dtype=int)
    tests = [
        ~((a[:, 0] >= spec.a_x_mm[0]) & (a[:, 0] <= spec.a_x_mm[1])
          & (a[:, 1] >= spec.a_y_mm[0]) & (a[:, 1] <= spec.a_y_mm[1])),
        (ab < spec.ab_length_mm[0]) | (ab > spec.ab_length_mm[1]),
        (bc < spec.bc_length_mm[0]) | (bc > spec.bc_length_mm[1]),
        ~(length_error <= spec.max_length_error_mm),
    ]
    for k, bad in enumerate(tests):
        status[(status == 0) & bad] = k + 1
    for j in np.flatnonzero(status == 0):
        status[j] = gear_check(spec, targets, a_prox[j], b_dist[j])[0]
    return HingeDomain(family=family, a=a, b=b, ab=ab, bc=bc, length_error=length_error, status=status)


def _empty_domain_message(domain: HingeDomain) -> str:
    counts = domain.rejected_counts()
    if len(domain.status) == 0:
        # the kinematic mapping traced no real dyad at all: the poses admit no hinge pair A/B, which
        # no synthesis limit can cure (the finger itself is to blame)
        return ("no feasible hinge A/B: the target poses admit no hinge curve (no real dyad); check "
                "finger.lengths_mm and finger.poses_deg")
    parts = [f"{counts[name]} by {field}" for name, field in REJECTIONS if counts[name]]
    last = next(field for name, field in reversed(REJECTIONS) if counts[name])
    return (f"no feasible hinge A/B: of {len(domain.status)} hinge-curve points, rejected {'; '.join(parts)}; "
            f"the last limit that removed candidates is {last}")


# -- selection -----------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SelectedDyad:
    """The chosen dyad: circle vector, A (proximal frame), B (distal frame), its kappa and law."""

    p: np.ndarray
    kappa: float
    a_proximal: np.ndarray
    b_distal: np.ndarray
    law: GearLaw
    length_error: float


def _single(p: np.ndarray, kappa: float) -> km.DyadFamily:
    centre, point = km.dyad_from_vector(p[None, :])
    return km.DyadFamily(kappa=np.array([kappa]), branch=np.zeros(1, dtype=int), p=p[None, :],
                         centre=centre, point=point)


def _evaluate(spec: FiveBarSpec, targets: FingerTargets, p: np.ndarray, kappa: float
              ) -> tuple[int, SelectedDyad | None]:
    one = hinge_domain(spec, targets, _single(p, kappa))
    status = int(one.status[0])
    if status:
        return status, None
    a_prox, b_dist = one.family.centre[0], one.family.point[0]
    _, law = gear_check(spec, targets, a_prox, b_dist)
    return 0, SelectedDyad(p=p, kappa=kappa, a_proximal=a_prox, b_distal=b_dist, law=law,
                           length_error=float(one.length_error[0]))


def select_dyad(spec: FiveBarSpec, targets: FingerTargets, domain: HingeDomain, basis4: np.ndarray,
                name: str) -> SelectedDyad:
    """Apply the template's selection rule to the feasible domain.

    Raises
    ------
    SynthesisError
        When the domain is empty (naming the limit) or no feasible dyad meets the rule's target.
    """
    feasible = np.flatnonzero(domain.feasible)
    if feasible.size == 0:
        raise SynthesisError(_empty_domain_message(domain))
    fam = domain.family

    def x_a_of(p: np.ndarray) -> float:
        return float(targets.proximal_to_world(km.dyad_from_vector(p)[0])[0, 0])

    if spec.select == "x_A":
        goal = float(spec.x_A_mm)
        found: list[SelectedDyad] = []
        for j in feasible:
            k = j + 1
            if k >= len(fam.kappa) or fam.branch[k] != fam.branch[j]:
                # the next sample of this branch is further on: look it up
                later = np.flatnonzero(fam.branch[j + 1:] == fam.branch[j])
                if later.size == 0:
                    continue
                k = j + 1 + int(later[0])
            if not domain.feasible[k] or (domain.a[j, 0] - goal) * (domain.a[k, 0] - goal) > 0:
                continue
            kappa, p = km.bisect_on_branch(basis4, lambda q: x_a_of(q) - goal, fam.kappa[j], fam.p[j],
                                           fam.kappa[k], fam.p[k])
            status, dyad = _evaluate(spec, targets, p, kappa)
            if dyad is not None:
                found.append(dyad)
        if not found:
            xs = domain.a[feasible, 0]
            raise SynthesisError(f"synthesis.x_A_mm = {goal:g} mm: no feasible hinge A has this x "
                                 f"(feasible A spans x in [{xs.min():.3f}, {xs.max():.3f}] mm)")
        return min(found, key=lambda d: d.length_error)
    # least_pose_error: rank by the dyad's length error, then solve the best few mechanisms
    best = feasible[np.argsort(domain.length_error[feasible])[:5]]
    scored = []
    for j in best:
        _, dyad = _evaluate(spec, targets, fam.p[j], float(fam.kappa[j]))
        if dyad is None:
            continue
        mech = build_mechanism(name, targets, dyad)
        try:
            errors = pose_errors(mech, targets)[0]
        except FabricateError:
            continue
        scored.append((float(np.max(errors)), dyad))
    if not scored:
        raise SynthesisError("no feasible dyad gives a mechanism that reaches every pose")
    return min(scored, key=lambda item: item[0])[1]


# -- mechanism -----------------------------------------------------------------------------------------

#: Body names (the paper's links): the proximal body O-D carries the arm O-A; the distal body B-C-P.
GROUND, PROXIMAL, LINK_AB, MIDDLE, DISTAL = "ground", "proximal", "link_AB", "middle", "distal"
GEAR_NAME = "sun_planet"


def build_mechanism(name: str, targets: FingerTargets, dyad: SelectedDyad) -> Mechanism:
    """The five-bar with its gear pair as a generic :class:`Mechanism`.

    Body coordinates: the proximal body uses its own frame (origin O, x along O->D), so its angle is
    the absolute proximal angle and the driver is the identity (input = t1 in degrees); every other
    body uses world coordinates of the first pose.
    """
    t1 = targets.angles[:, 0]
    a_world = targets.proximal_to_world(dyad.a_proximal)[0]
    b_world = targets.distal_to_world(dyad.b_distal)[0]
    d0, c0, p0 = targets.d[0], targets.c[0], targets.p[0]

    def pt(v: np.ndarray) -> tuple[float, float]:
        return float(v[0]), float(v[1])

    bodies = (
        Body(GROUND, {"O": pt(targets.origin)}),
        Body(PROXIMAL, {"O": (0.0, 0.0), "D": (float(targets.lengths[0]), 0.0), "A": pt(dyad.a_proximal)}),
        Body(LINK_AB, {"A": pt(a_world), "B": pt(b_world)}),
        Body(MIDDLE, {"D": pt(d0), "C": pt(c0)}),
        Body(DISTAL, {"B": pt(b_world), "C": pt(c0), "P": pt(p0)}),
    )
    joints = (Revolute("O", GROUND, PROXIMAL), Revolute("A", PROXIMAL, LINK_AB),
              Revolute("D", PROXIMAL, MIDDLE), Revolute("C", MIDDLE, DISTAL), Revolute("B", LINK_AB, DISTAL))
    gear = GearCoupling(GEAR_NAME, carrier=PROXIMAL, gear_a=GROUND, gear_b=LINK_AB, law=dyad.law.law,
                        axis_a="O", axis_b="A", working_range=dyad.law.working_range)
    assembly = {PROXIMAL: (float(targets.origin[0]), float(targets.origin[1]), float(t1[0]))}
    assembly.update({body: (0.0, 0.0, 0.0) for body in (LINK_AB, MIDDLE, DISTAL)})
    return Mechanism(name=name, bodies=bodies, ground=GROUND, joints=joints, gears=(gear,),
                     drivers=(Driver("angle", PROXIMAL, GROUND),),
                     input_range=(float(np.degrees(t1[0])), float(np.degrees(t1[-1]))),
                     input_unit="deg", assembly=assembly)


def pose_errors(mech: Mechanism, targets: FingerTargets) -> tuple[np.ndarray, np.ndarray, Motion]:
    """Fingertip position error (mm) and distal orientation error (rad) at every target pose.

    The mechanism is swept through the poses' input angles (continuation from the first pose), so the
    errors are those of the generic solver's assembly branch.
    """
    motion = mech.sweep(np.degrees(targets.angles[:, 0]))
    tip = motion.point("P", DISTAL)
    position = np.hypot(*(tip - targets.p).T)
    # the distal body's angle is 0 at the first pose (world coordinates of the first pose)
    orientation = wrap_angle(motion.pose(DISTAL)[:, 2] + targets.angles[0, 2] - targets.angles[:, 2])
    return position, np.asarray(orientation), motion


# -- synthesis -------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class FiveBarData:
    """Everything the plots and tests need (``SynthesisResult.data``)."""

    spec: FiveBarSpec
    targets: FingerTargets
    matrix: np.ndarray
    eigenvalues: np.ndarray
    eigenvectors: np.ndarray
    domain: HingeDomain
    dyad: SelectedDyad
    mechanism: Mechanism
    position_error: np.ndarray
    orientation_error: np.ndarray
    motion: Motion


def _floats(values: np.ndarray) -> list[float]:
    """Plain floats for JSON (adding 0.0 turns -0.0 into 0.0)."""
    return [float(v) + 0.0 for v in np.ravel(values)]


def _xy(v: np.ndarray) -> list[float]:
    return [float(v[0]), float(v[1])]


def _range(v: np.ndarray) -> list[float]:
    return [float(np.min(v)), float(np.max(v))]


def build_report(data: FiveBarData) -> dict[str, Any]:
    """JSON-ready ``synthesis`` section (lengths mm, angles deg)."""
    t, dyad, dom = data.targets, data.dyad, data.domain
    a = t.proximal_to_world(dyad.a_proximal)[0]
    b = t.distal_to_world(dyad.b_distal)[0]
    law = dyad.law
    samples = np.linspace(law.x[0], law.x[-1], 25)
    feasible = dom.feasible
    return {
        "method": "kinematic mapping + eigenvectors of M^T M, cubic-spline non-circular gear law",
        "poses": int(len(t.p)),
        "eigenvalues": _floats(data.eigenvalues),
        "kappa": float(dyad.kappa),
        "selection": {"rule": data.spec.select, "x_A_mm": data.spec.x_A_mm},
        "A_mm": _xy(a),
        "B_mm": _xy(b),
        "link_lengths_mm": {
            "OA": float(np.hypot(*(a - t.origin))), "OD": float(t.lengths[0]), "AD": float(np.hypot(*(a - t.d[0]))),
            "AB": float(np.hypot(*(b - a))), "BC": float(np.hypot(*(b - t.c[0]))), "DC": float(t.lengths[1]),
            "CP": float(t.lengths[2]), "BP": float(np.hypot(*(b - t.p[0]))),
        },
        "dyad_length_error_mm": float(dyad.length_error),
        "pose_error_mm": {"max": float(np.max(data.position_error)), "mean": float(np.mean(data.position_error)),
                          "per_pose": _floats(data.position_error)},
        "orientation_error_deg": {"max": float(np.degrees(np.max(np.abs(data.orientation_error)))),
                                  "mean": float(np.degrees(np.mean(np.abs(data.orientation_error)))),
                                  "per_pose": _floats(np.degrees(data.orientation_error))},
        "target_tip_mm": [_xy(p) for p in t.p],
        "gear_law": {
            "note": "x_a = ground minus arm O-A rotation, x_b = link A-B minus arm rotation; x_b = f(x_a)",
            "poses_x_a_deg": _floats(np.degrees(law.knots_a)),
            "poses_x_b_deg": _floats(np.degrees(law.knots_b)),
            "x_a_deg": _floats(np.degrees(samples)),
            "x_b_deg": _floats(np.degrees(law.law(samples))),
            "working_range_deg": _floats(np.degrees(law.working_range)),
        },
        "center_distance_mm": float(law.centre_distance),
        "transmission_ratio": _range(law.ratio),
        "pitch_radius_mm": {"sun_O": _range(law.r_a), "planet_A": _range(law.r_b)},
        "min_pitch_radius_of_curvature_mm": float(min(np.min(law.rho_a), np.min(law.rho_b))),
        "feasible_domain": {
            "curve_points": int(len(dom.status)),
            "feasible_points": int(np.sum(feasible)),
            "rejected": dom.rejected_counts(),
            "x_A_mm": _range(dom.a[feasible, 0]),
            "y_A_mm": _range(dom.a[feasible, 1]),
            "kappa": _range(dom.family.kappa[feasible]),
        },
    }


def synthesise(design: Any) -> SynthesisResult:
    """Synthesise the five-bar gear finger of a :class:`~fabricate.spec.DesignSpec`.

    Raises
    ------
    SynthesisError
        When the template's limits leave no feasible hinge (the message names the limit), or the
        selection rule's target lies outside the feasible domain.
    """
    spec: FiveBarSpec = design.method
    targets = finger_targets(spec)
    matrix = km.constraint_matrix(km.image_coordinates(targets.displacements))
    eigenvalues, eigenvectors = km.family_basis(matrix)
    basis4 = eigenvectors[:, :4]
    family = km.trace_family(basis4, spec.kappa_samples)

    def hinges(p: np.ndarray) -> np.ndarray:  # A and B at the first pose, (k, 4) mm
        centre, point = km.dyad_from_vector(p)
        return np.hstack([targets.origin + centre @ rotation(targets.angles[0, 0]).T,
                          targets.p[0] + point @ rotation(targets.angles[0, 2]).T])

    first = hinges(family.p)
    in_box = ((first[:, 0] >= spec.a_x_mm[0]) & (first[:, 0] <= spec.a_x_mm[1])
              & (first[:, 1] >= spec.a_y_mm[0]) & (first[:, 1] <= spec.a_y_mm[1]))
    family = km.refine_family(basis4, family, hinges, in_box, spec.curve_step_mm)
    domain = hinge_domain(spec, targets, family)
    dyad = select_dyad(spec, targets, domain, basis4, design.name)
    mech = build_mechanism(design.name, targets, dyad)
    sweep_poses = int(getattr(getattr(design, "checks", None), "sweep_poses", 360))
    try:
        position, orientation, _ = pose_errors(mech, targets)
        motion = mech.sweep(max(sweep_poses, 2))
    except LockupError as exc:
        raise SynthesisError(f"the selected dyad (A = {_xy(mech.body(LINK_AB).point('A'))} mm) gives a "
                             f"mechanism that cannot move through the poses: {exc}") from exc
    data = FiveBarData(spec=spec, targets=targets, matrix=matrix, eigenvalues=eigenvalues,
                       eigenvectors=eigenvectors, domain=domain, dyad=dyad, mechanism=mech,
                       position_error=position, orientation_error=orientation, motion=motion)

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.five_bar.plots import five_bar_figures

        return five_bar_figures(data)

    parts = {"pads": {DISTAL: {"point": "P", "radius_mm": spec.pad_radius_mm}}, "tip_point": "P"}
    return SynthesisResult(mechanism=mech, report=build_report(data), figures=figures, data=data, parts=parts)
