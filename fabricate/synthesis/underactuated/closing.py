"""The underactuated finger's closing motion: least spring energy at each stroke of the push rod, free or on
the cylinder (which yields the contact sequence), and the contact forces at its end."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.errors import SynthesisError
from fabricate.synthesis.underactuated.model import contact_forces, finger_pose
from fabricate.synthesis.underactuated.settler import Settler, face_clearance
from fabricate.synthesis.underactuated.spec import UnderactuatedSpec


@dataclass(frozen=True)
class ClosingMotion:
    """Quasi-static closing: per stroke sample the relative angles (rad) and which phalanges touch."""

    strokes: np.ndarray          # (m,) mm
    q: np.ndarray                # (m, n) rad
    touching: np.ndarray         # (m, n) bool
    contact_order: list          # phalanx indices in the order they first touch
    contact_strokes: list        # stroke (mm) at each first touch
    with_object: bool
    fallbacks: int = 0           # equilibria the active-set Newton left to SLSQP
    events: tuple = ()           # strokes (mm) where the active set changed: kinks of q(stroke)


def closing_motion(spec: UnderactuatedSpec, with_object: bool = True, samples: int | None = None,
                   stroke: float | None = None, locate_events: bool = True) -> ClosingMotion:
    """Least spring energy at each stroke, joints >= 0 (open stops), phalanges outside the cylinder.

    With the object the motion ends at the template's stroke or where every phalanx touches (the
    finger is then locked: n contacts take its n degrees of freedom).

    Quasi-static, the equilibrium of springs, stops, rod and object at a stroke is a constrained
    minimum of the spring energy on the set of configurations with that stroke; following it from the
    open pose with warm starts keeps the physical branch. As in the chapter (section 2.2, "assumed not
    to turn"), a phalanx that meets the object sticks there: its joint and the proximal ones freeze.

    Where the active set changes between two stroke samples (a face meets the cylinder, a joint
    leaves or reaches a stop) the joint angles have a kink; with ``locate_events`` the stroke of that
    event is found by bisection (to 1e-6 mm) and inserted as a sample, so contact strokes do not snap
    to the stroke grid and the driver laws can be split there (``ClosingMotion.events``). Without it
    (the reference for tests) an event is only seen at the next grid sample.
    """
    d = spec.design
    m = samples or spec.samples
    grid = np.linspace(0.0, spec.stroke if stroke is None else stroke, m)
    settler = Settler(spec, with_object)
    settler.lower = {i for i in range(d.n)}           # the open pose rests on every open stop
    strokes, qs, touching = [0.0], [np.zeros(d.n)], [np.zeros(d.n, dtype=bool)]
    events: list[float] = []
    q = np.zeros(d.n)
    frozen = 0
    resolution = 1e-6                                 # mm, event strokes are located to this
    locked = False

    def signature() -> tuple:
        return tuple(frozenset(i for i in part if i >= frozen)
                     for part in (settler.lower, settler.upper, settler.contacts))

    for target in grid[1:]:
        for _ in range(2 * d.n + 2):                  # at most this many events between two samples
            state, before = settler.state(), signature()
            x, ok = settler.settle(target, q, frozen)
            changed = locate_events and ok and signature() != before
            if ok and not changed:
                s_new, event = float(target), False
            elif not ok and not with_object:
                raise SynthesisError(f"underactuated: closing motion lost at stroke {target:.3f} mm")
            else:
                # the first stroke in (previous sample, target] where the active set changes or the
                # equilibrium is lost (the unfrozen phalanges cannot follow the stroke without entering
                # the object: the finger locked); found as the root of the margin of the active set
                # that held at the previous sample, then the equilibrium just past it is the sample
                lo, x_lo = strokes[-1], q
                settler.restore(state)
                s_new, x, ok, event = settler.locate_event(lo, float(target), x_lo, frozen, resolution)
                if not ok and not with_object:
                    raise SynthesisError(f"underactuated: closing motion lost at stroke {s_new:.3f} mm")
            q = x
            strokes.append(s_new)
            qs.append(q)
            touch = np.zeros(d.n, dtype=bool)
            if event:
                events.append(s_new)
            if with_object:
                touch, frozen = _touching(spec, q, frozen)
            touching.append(touch)
            if with_object and (touch.all() or not ok):
                locked = True                         # every phalanx on the object: the stroke ends
                break
            if s_new >= target - resolution:
                if s_new != target:                   # the event is the grid sample
                    strokes[-1] = float(target)
                    if event:
                        events[-1] = float(target)
                break
        if locked:
            break
    strokes_arr, qs_arr, touching_arr = np.array(strokes), np.array(qs), np.array(touching)
    order, at = _contact_order(strokes_arr, touching_arr)
    return ClosingMotion(strokes_arr, qs_arr, touching_arr, order, at, with_object, settler.fallbacks,
                         tuple(events))


def _touching(spec: UnderactuatedSpec, q: np.ndarray, frozen: int) -> tuple[np.ndarray, int]:
    """Which phalanges touch the object at joint angles ``q`` (n,), rad, and how many joints are frozen then.

    The chapter's assumption: a phalanx stopped by the object no longer turns (it sticks), so it and every
    joint proximal to it hold their angles from then on; the frozen ones count as touching.
    """
    d = spec.design
    pose = finger_pose(d, q)
    assert pose is not None  # the settler only accepts poses that close
    touch = face_clearance(d, pose, spec.cylinder_centre, spec.cylinder_radius)[0] < 1e-4
    touch[:frozen] = True
    hit = np.nonzero(touch)[0]
    if hit.size:
        frozen = max(frozen, int(hit.max()) + 1)
    return touch, frozen


def _contact_order(strokes: np.ndarray, touching: np.ndarray) -> tuple[list[int], list[float]]:
    """The phalanges in the order they first touch, and the strokes (mm) where they do (``strokes`` (m,),
    ``touching`` (m, n) bool)."""
    order, at = [], []
    for i in range(touching.shape[1]):
        hits = np.nonzero(touching[:, i])[0]
        if hits.size:
            order.append(i)
            at.append(float(strokes[hits[0]]))
    ranked = sorted(zip(at, order, strict=True))
    return [i for _, i in ranked], [s for s, _ in ranked]


def final_contact_forces(spec: UnderactuatedSpec, motion: ClosingMotion) -> dict:
    """Contact forces (N) at the end of the closing for the template's push force."""
    d = spec.design
    pose = finger_pose(d, motion.q[-1])
    assert pose is not None  # the closing motion only holds poses that close
    _, points = face_clearance(d, pose, spec.cylinder_centre, spec.cylinder_radius)
    torque = spec.spring_rates * (motion.q[-1] + spec.spring_preloads)
    forces, links = contact_forces(d, pose, spec.push_force, torque, points)
    return {"forces_N": forces, "link_forces_N": links, "points": points, "pose": pose}
