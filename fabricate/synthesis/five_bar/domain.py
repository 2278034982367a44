"""The feasible domain of the five-bar's hinge curves (paper Fig 9) and the choice of one dyad from it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.errors import FabricateError, SynthesisError
from fabricate.planar import rotation
from fabricate.synthesis.five_bar import kinematic_mapping as km
from fabricate.synthesis.five_bar.law import GearLaw, gear_law
from fabricate.synthesis.five_bar.mechanism import SelectedDyad, build_mechanism, pose_errors
from fabricate.synthesis.five_bar.spec import FiveBarSpec
from fabricate.synthesis.five_bar.targets import FingerTargets, dyad_angles, law_knots

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
        ok: np.ndarray = self.status == 0
        return ok

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
    assert law is not None  # hinge_domain's status 0 includes the gear check
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
        assert spec.x_A_mm is not None  # the parser requires it for this rule
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
