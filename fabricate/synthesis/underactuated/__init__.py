"""Underactuated finger of stacked four-bars driven by one push rod (seed 001), kind ``underactuated``.

The chapter derives the mobility (n for n phalanges), positions, the velocity recursion
theta_dot_{n+1} = E_n theta_dot_n and the statics, but gives no dimensions. This module

- reads a template (``[finger]``, ``[transmission]``, ``[push_rod]``, ``[springs]``, ``[object]``),
- computes the free closing motion with return springs (quasi-static: least spring energy at each
  stroke, joints on their open stops until the springs let them go) and the closing on a cylinder
  (the same, with the phalanges kept outside it), which yields the contact sequence,
- computes the contact forces at the end for the template's push force (the force chain of
  :func:`fabricate.synthesis.underactuated.model.contact_forces`), the velocity ratios E_i and the
  mobility, and
- returns a 1-input :class:`~fabricate.mechanism.Mechanism`: the push rod is a slider with a "slide"
  driver over the stroke; the n-1 phalanx angles the actuator does not fix are "angle" drivers whose
  laws (cubic splines of stroke -> relative angle, split where a contact or a stop changes the
  motion, :class:`PiecewiseLaw`) come from the closing solution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize

from fabricate.bounds import MAX_FORCE_N, MAX_LENGTH_MM, MAX_SPRING_RATE, MAX_STROKE_SAMPLES
from fabricate.errors import SpecError, SynthesisError
from fabricate.mechanism import Body, Driver, Mechanism, Revolute, Slider
from fabricate.planar import cross2
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.underactuated.model import (
    FingerDesign,
    FingerPose,
    FingerPoses,
    PiecewiseLaw,
    contact_forces,
    crank_rate,
    distal_rate,
    finger_pose,
    finger_poses,
    stroke_gradients,
    transmission_ratios,
)
from fabricate.table import Table


@dataclass(frozen=True)
class UnderactuatedSpec:
    """Validated template tables of the underactuated finger (mm, rad inside; N·mm/rad springs)."""

    design: FingerDesign
    spring_rates: np.ndarray        # N·mm/rad
    spring_preloads: np.ndarray     # rad
    spring_legs: float              # mm
    stroke: float                   # mm
    push_force: float               # N
    cylinder_centre: np.ndarray     # (2,) mm
    cylinder_radius: float          # mm
    samples: int
    source: str


#: Most phalanges of one finger (each adds a four-bar, a body pair and a spring).
MAX_PHALANGES = 8


def parse_spec(root: Table) -> UnderactuatedSpec:
    """Read ``[finger]``, ``[transmission]``, ``[push_rod]``, ``[springs]`` and ``[object]``."""
    finger = root.table("finger")
    lengths = finger.array("phalanx_lengths_mm", shape=(None,), min_rows=2, positive=True, max=MAX_LENGTH_MM)
    if len(lengths) > MAX_PHALANGES:
        raise SpecError(finger.field("phalanx_lengths_mm"),
                        f"{len(lengths)} phalanges, over the bound of {MAX_PHALANGES}")
    thickness = finger.number("thickness_mm", positive=True, max=200.0)
    source = finger.string("source", "")
    finger.finish()
    n = len(lengths)
    tr = root.table("transmission")
    out_arm = tr.array("output_arm_mm", shape=(n - 1,), positive=True, max=MAX_LENGTH_MM)
    out_angle = np.radians(tr.array("output_arm_deg", shape=(n - 1,), min=-180.0, max=180.0))
    in_arm = tr.array("input_arm_mm", shape=(n - 1,), positive=True, max=MAX_LENGTH_MM)
    in_angle = np.radians(tr.array("input_arm_deg", shape=(n - 1,), min=-180.0, max=180.0))
    tr.finish()
    rod = root.table("push_rod")
    crank = rod.number("crank_mm", positive=True, max=MAX_LENGTH_MM)
    crank_angle = np.radians(rod.number("crank_deg", min=-180.0, max=180.0))
    link = rod.number("link_mm", positive=True, max=MAX_LENGTH_MM)
    rod_y = rod.number("axis_y_mm", min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
    stroke = rod.number("stroke_mm", positive=True, max=MAX_LENGTH_MM)
    push_force = rod.number("push_force_N", positive=True, max=MAX_FORCE_N)
    samples = rod.integer("samples", 121, min=11, max=MAX_STROKE_SAMPLES)
    rod.finish()
    springs = root.table("springs")
    rates = springs.array("rate_Nmm_per_deg", shape=(n,), min=0.0, max=MAX_SPRING_RATE) * 180.0 / np.pi
    preloads = np.radians(springs.array("preload_deg", shape=(n,), min=0.0, max=360.0))
    legs = springs.number("legs_mm", 15.0, positive=True, max=MAX_LENGTH_MM)
    springs.finish()
    obj = root.table("object")
    centre = obj.array("cylinder_centre_mm", shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
    radius = 0.5 * obj.number("cylinder_diameter_mm", positive=True, max=MAX_LENGTH_MM)
    obj.finish()
    design = FingerDesign(lengths=lengths, thickness=thickness, out_arm=out_arm, out_angle=out_angle,
                          in_arm=in_arm, in_angle=in_angle, crank=crank, crank_angle=crank_angle, link=link,
                          rod_y=rod_y)
    try:
        design.rod_open_x()
    except ValueError as exc:
        raise SpecError("push_rod.link_mm", str(exc)) from exc
    if centre[1] - radius < 0.5 * thickness:
        raise SpecError("object.cylinder_centre_mm", "the cylinder overlaps the open finger")
    return UnderactuatedSpec(design, rates, preloads, legs, stroke, push_force, centre, radius, samples, source)


# -- closing motion ------------------------------------------------------------------------------

def face_geometry(design: FingerDesign, poses: FingerPoses, centre: np.ndarray, radius: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clearance of every palmar face to the cylinder at m configurations, with its gradient.

    Returns
    -------
    gaps : (m, n) array
        Distance from the cylinder surface to each phalanx's palmar face (mm, negative inside).
    points : (m, n, 2) array
        Nearest face points (mm).
    gradients : (m, n, n) array
        ``d gap_j / d q_i`` (mm/rad), zero for i > j. The nearest point p moves as a point of phalanx
        j, ``dp/dq_i = perp(p - G_i)`` for i <= j (its slide along the face is second order), so with
        w the unit vector p -> centre, ``d gap_j/dq_i = -w . perp(p - G_i) = -cross(p - G_i, w)``.
    """
    n = design.n
    normal = np.stack([-np.sin(poses.theta), np.cos(poses.theta)], -1)       # palmar normals (m, n, 2)
    start = poses.G[:, :-1] + 0.5 * design.thickness * normal
    along = poses.G[:, 1:] - poses.G[:, :-1]
    t = np.clip(np.einsum("mjk,mjk->mj", centre - start, along) / np.einsum("mjk,mjk->mj", along, along),
                0.0, 1.0)
    points = start + t[..., None] * along
    to_centre = centre - points
    dist = np.hypot(to_centre[..., 0], to_centre[..., 1])
    w = to_centre / dist[..., None]
    lever = points[:, :, None, :] - poses.G[:, None, :n, :]                    # (m, j, i, 2)
    grads = -cross2(lever, w[:, :, None, :])
    grads *= np.tril(np.ones((n, n)))
    return dist - radius, points, grads


def face_clearance(design: FingerDesign, pose: FingerPose, centre: np.ndarray, radius: float):
    """Distance from the cylinder surface to each phalanx's palmar face (n,), mm, and the nearest
    face points (n, 2)."""
    poses = FingerPoses(q=pose.q[None], theta=pose.theta[None], G=pose.G[None], Q=pose.Q[None],
                        P=pose.P[None], psi=pose.psi[None], K=pose.K[None], S=pose.S[None],
                        stroke=np.array([pose.stroke]), valid=np.array([True]))
    gaps, points, _ = face_geometry(design, poses, np.asarray(centre, dtype=np.float64), radius)
    return gaps[0], points[0]


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


_UPPER_STOP = 0.6 * np.pi          # rad, the joints' closed stop (far beyond any grasp)


class _Settler:
    """Constrained minimum of the spring energy at a given stroke (the quasi-static equilibrium).

    ``min 1/2 sum k_i (q_i + q0_i)^2`` subject to ``stroke(q) = s``, open stops ``0 <= q_i <= 0.6 pi``,
    frozen joints held and (with the object) every face outside the cylinder. Solved by an active
    set: for a guess of the joints on their stops and the faces on the cylinder, Newton on the KKT
    conditions ``k (q + q0) = lambda ds/dq + sum mu_j d gap_j/dq`` (free joints), ``stroke = s``,
    ``gap_j = 0``, with the closed-form gradients and their central differences as Hessians (one
    vectorised pose evaluation per iteration); then constraints violated are added and negative
    multipliers dropped until the KKT conditions hold. The active set is carried from one stroke to
    the next (continuation). Should the active set not settle, SLSQP on the same problem decides.
    """

    def __init__(self, spec: UnderactuatedSpec, with_object: bool):
        self.spec = spec
        self.design = spec.design
        self.with_object = with_object
        self.rates = spec.spring_rates
        self.preloads = spec.spring_preloads
        self.lower: set[int] = set()             # joints on their open stop
        self.upper: set[int] = set()             # joints on their closed stop
        self.contacts: set[int] = set()          # faces on the cylinder
        self.fallbacks = 0

    def state(self) -> tuple[set, set, set]:
        """The active set (settle replaces these sets, never edits them, so references suffice)."""
        return self.lower, self.upper, self.contacts

    def restore(self, state: tuple[set, set, set]) -> None:
        self.lower, self.upper, self.contacts = state

    # derivatives at m configurations ------------------------------------------------------------
    def evaluate(self, q: np.ndarray) -> dict:
        poses = finger_poses(self.design, q)
        out = {"valid": poses.valid, "stroke": poses.stroke, "ds": stroke_gradients(self.design, poses)}
        if self.with_object:
            gaps, _, grads = face_geometry(self.design, poses, self.spec.cylinder_centre,
                                           self.spec.cylinder_radius)
            out["gaps"], out["dgaps"] = gaps, grads
        return out

    def _newton(self, x: np.ndarray, free: np.ndarray, contacts: list[int], target: float,
                step: float = 1e-5, tol: float = 1e-11) -> tuple[np.ndarray, np.ndarray, dict] | None:
        """KKT point for a fixed active set; x holds the fixed joints. None if Newton fails."""
        nf, nc = len(free), len(contacts)
        k, q0 = self.rates[free], self.preloads[free]
        scale = float(np.max(self.rates) + 1.0)
        mult = None
        x = x.copy()
        for _ in range(40):
            stencil = np.repeat(x[None], 1 + 2 * nf, axis=0)
            stencil[1 + np.arange(nf), free] += step
            stencil[1 + nf + np.arange(nf), free] -= step
            ev = self.evaluate(stencil)
            if not ev["valid"][0] or not np.isfinite(ev["ds"]).all():
                return None              # a loop opened or the push link reached its dead point
            grads = [ev["ds"]] + [ev["dgaps"][:, j] for j in contacts]   # each (1+2nf, n)
            normals = np.stack([g[0, free] for g in grads], -1)           # (nf, 1+nc)
            values = np.array([ev["stroke"][0] - target] + [ev["gaps"][0, j] for j in contacts])
            if mult is None:
                mult = np.linalg.lstsq(normals, k * (x[free] + q0), rcond=None)[0]
            stationarity = k * (x[free] + q0) - normals @ mult
            if np.all(np.abs(values) < tol) and np.all(np.abs(stationarity) < tol * scale):
                return x, mult, ev
            if not ev["valid"].all():
                return None
            hess = np.diag(k)
            for g, mu in zip(grads, mult, strict=True):
                hess = hess - mu * (g[1:1 + nf, free] - g[1 + nf:, free]).T / (2 * step)
            kkt = np.zeros((nf + 1 + nc, nf + 1 + nc))
            kkt[:nf, :nf] = hess
            kkt[:nf, nf:] = -normals
            kkt[nf:, :nf] = normals.T
            try:
                delta = np.linalg.solve(kkt, -np.concatenate([stationarity, values]))
            except np.linalg.LinAlgError:
                return None
            x[free] += delta[:nf]
            mult = mult + delta[nf:]
        return None

    def settle(self, target: float, start: np.ndarray, frozen: int) -> tuple[np.ndarray, bool]:
        """Equilibrium at stroke ``target`` from ``start`` with joints ``< frozen`` held; (q, ok)."""
        n = self.design.n
        movable = [i for i in range(n) if i >= frozen]
        lower = {i for i in self.lower if i >= frozen}
        upper = {i for i in self.upper if i >= frozen}
        contacts = {j for j in self.contacts if j >= frozen} if self.with_object else set()
        x = np.asarray(start, dtype=np.float64).copy()
        seen = set()
        for _ in range(12):
            key = (frozenset(lower), frozenset(upper), frozenset(contacts))
            free = np.array([i for i in movable if i not in lower and i not in upper], dtype=int)
            if len(movable) < 1 + len(contacts):
                return x, False              # more contacts and stroke than joints left: locked
            if key in seen:
                break
            seen.add(key)
            if len(free) < 1 + len(contacts):
                # too many joints on stops: release the one that yields first, the least spring
                # torque per stroke (with the stroke's multiplier lambda, its stop force is
                # k (q + q0) - lambda ds/dq, the first to turn negative as lambda grows)
                ds = self.evaluate(x[None])["ds"][0]
                held = [i for i in lower | upper if ds[i] > 0.0]
                if not held:
                    break
                release = min(held, key=lambda i: self.rates[i] * (x[i] + self.preloads[i]) / ds[i])
                lower.discard(release)
                upper.discard(release)
                continue
            x[list(lower)] = 0.0
            x[list(upper)] = _UPPER_STOP
            solved = self._newton(x, free, sorted(contacts), target)
            if solved is None:
                break
            x_new, mult, ev = solved
            # primal: stops and faces the step went through join the active set
            entered = False
            for i in free:
                if x_new[i] < -1e-10:
                    lower.add(int(i))
                    entered = True
                elif x_new[i] > _UPPER_STOP + 1e-10:
                    upper.add(int(i))
                    entered = True
            if self.with_object:
                for j in movable:
                    if j not in contacts and ev["gaps"][0, j] < -1e-9:
                        contacts.add(j)
                        entered = True
            if entered:
                x = np.clip(x_new, 0.0, _UPPER_STOP)
                continue
            # dual: a stop or a face pulling instead of pushing is released (the most negative first)
            residual = self.rates * (x_new + self.preloads) - mult[0] * ev["ds"][0]
            cs = sorted(contacts)
            for mu, j in zip(mult[1:], cs, strict=True):
                residual = residual - mu * ev["dgaps"][0, j]
            scale = 1e-9 * float(np.max(self.rates) + 1.0)
            worst, release = -scale, None
            for i in lower:
                if residual[i] < worst:
                    worst, release = residual[i], ("lower", i)
            for i in upper:
                if -residual[i] < worst:
                    worst, release = -residual[i], ("upper", i)
            for mu, j in zip(mult[1:], cs, strict=True):
                if mu < worst:
                    worst, release = mu, ("contact", j)
            if release is None:
                ok = self._acceptable(x_new, target)
                if ok:
                    self.lower, self.upper, self.contacts = lower, upper, contacts
                return x_new, ok
            {"lower": lower, "upper": upper, "contact": contacts}[release[0]].discard(release[1])
            x = x_new
        self.fallbacks += 1
        return self._slsqp(target, start, frozen)

    def margin(self, target: float, start: np.ndarray, frozen: int, state: tuple | None = None) -> float:
        """How far the active set ``state`` (default: the current one) still holds at stroke ``target``.

        The equilibrium with that set fixed (Newton from ``start``) is measured by its smallest slack:
        free joint angles off their stops (rad), faces off the cylinder (mm), stop torques (N·mm) and
        contact multipliers. Positive: the set still holds; negative (or -inf if no equilibrium with
        that set exists): an event happened before ``target``. Only the sign and the zero matter.
        """
        lower, upper, contacts = self.state() if state is None else state
        n = self.design.n
        movable = [i for i in range(n) if i >= frozen]
        lower = sorted(i for i in lower if i >= frozen)
        upper = sorted(i for i in upper if i >= frozen)
        contacts = sorted(j for j in contacts if j >= frozen) if self.with_object else []
        free = np.array([i for i in movable if i not in lower and i not in upper], dtype=int)
        if len(free) < 1 + len(contacts):
            return -np.inf
        x = np.asarray(start, dtype=np.float64).copy()
        x[lower] = 0.0
        x[upper] = _UPPER_STOP
        solved = self._newton(x, free, contacts, target)
        if solved is None:
            return -np.inf
        x_new, mult, ev = solved
        slack = [x_new[free], _UPPER_STOP - x_new[free], mult[1:]]
        residual = self.rates * (x_new + self.preloads) - mult[0] * ev["ds"][0]
        for mu, j in zip(mult[1:], contacts, strict=True):
            residual = residual - mu * ev["dgaps"][0, j]
        slack += [residual[lower], -residual[upper]]
        if self.with_object:
            slack.append(ev["gaps"][0, [j for j in movable if j not in contacts]])
        return float(np.min(np.concatenate(slack)))

    def locate_event(self, lo: float, hi: float, x_lo: np.ndarray, frozen: int, resolution: float
                     ) -> tuple[float, np.ndarray, bool, bool]:
        """The first change of the current active set in strokes (lo, hi] and the equilibrium there.

        The change is the root of :meth:`margin` (positive at ``lo``), found by Brent's method to
        ``resolution`` (mm); -inf past a lost equilibrium keeps the bracket. Returns (stroke, q, ok,
        event): the equilibrium just past the change (ok, event) or, if none settles there (the finger
        locked), the last one before it (not ok).
        """
        state = self.state()

        def margin(s: float) -> float:
            return max(self.margin(s, x_lo, frozen, state), -1e6)

        if margin(lo) <= 0.0:             # the set at lo was no equilibrium set (the open pose on all
            x, ok = self.settle(hi, x_lo, frozen)          # its stops): nothing to locate
            return (hi, x, True, False) if ok else (lo, np.asarray(x_lo, dtype=np.float64), False, False)
        if margin(hi) > 0.0:            # no change of this set: the settle took another branch
            root = hi
        else:
            root = brentq(margin, lo, hi, xtol=0.25 * resolution)
        past = min(root + 0.5 * resolution, hi)
        x, ok = self.settle(past, x_lo, frozen)
        if ok:
            return past, x, True, True
        self.restore(state)
        before = max(root - 0.5 * resolution, lo)
        x, ok = self.settle(before, x_lo, frozen)
        return before, x, False, False

    def _acceptable(self, x: np.ndarray, target: float) -> bool:
        """The reference test of an equilibrium: stroke met and no face inside the cylinder."""
        ev = self.evaluate(x[None])
        ok = bool(ev["valid"][0]) and abs(ev["stroke"][0] - target) <= 1e-5
        if ok and self.with_object:
            ok = bool(ev["gaps"][0].min() > -1e-5)
        return ok

    def _slsqp(self, target: float, start: np.ndarray, frozen: int, max_iter: int = 200
               ) -> tuple[np.ndarray, bool]:
        """The generic route (scipy SLSQP) for the rare active sets the Newton loop cannot settle."""
        k, q0 = self.rates, self.preloads
        scale = float(np.max(k * (q0 + 1.0)) + 1.0)
        n = self.design.n
        cons = [{"type": "eq", "fun": lambda x: self.evaluate(x[None])["stroke"][0] - target,
                 "jac": lambda x: self.evaluate(x[None])["ds"][0]}]
        if self.with_object:
            cons.append({"type": "ineq", "fun": lambda x: self.evaluate(x[None])["gaps"][0],
                         "jac": lambda x: self.evaluate(x[None])["dgaps"][0]})
        bounds = [(start[i], start[i]) if i < frozen else (0.0, _UPPER_STOP) for i in range(n)]
        res = minimize(lambda x: 0.5 * float(np.sum(k * (x + q0) ** 2)) / scale, start,
                       jac=lambda x: k * (x + q0) / scale, method="SLSQP", constraints=cons,
                       bounds=bounds, options={"ftol": 1e-13, "maxiter": max_iter})
        x = np.clip(res.x, [b[0] for b in bounds], [b[1] for b in bounds])
        ok = self._acceptable(x, target)
        if ok:                       # a failed attempt must not leave its guesses for the next stroke
            self.lower = {i for i in range(frozen, n) if x[i] <= 1e-12}
            self.upper = {i for i in range(frozen, n) if x[i] >= _UPPER_STOP - 1e-12}
            if self.with_object:
                gaps = self.evaluate(x[None])["gaps"][0]
                self.contacts = {j for j in range(frozen, n) if gaps[j] < 1e-9}
        return x, ok


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
    settler = _Settler(spec, with_object)
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
                pose = finger_pose(d, q)
                touch = face_clearance(d, pose, spec.cylinder_centre, spec.cylinder_radius)[0] < 1e-4
                touch[:frozen] = True
                hit = np.nonzero(touch)[0]
                if hit.size:
                    # the chapter's assumption: a phalanx stopped by the object no longer turns (it
                    # sticks), so it and every joint proximal to it hold their angles from here on
                    frozen = max(frozen, int(hit.max()) + 1)
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
    order, at = [], []
    for i in range(d.n):
        hits = np.nonzero(touching_arr[:, i])[0]
        if hits.size:
            order.append(i)
            at.append(float(strokes_arr[hits[0]]))
    ranked = sorted(zip(at, order, strict=True))
    return ClosingMotion(strokes_arr, qs_arr, touching_arr, [i for _, i in ranked], [s for s, _ in ranked],
                         with_object, settler.fallbacks, tuple(events))


def final_contact_forces(spec: UnderactuatedSpec, motion: ClosingMotion) -> dict:
    """Contact forces (N) at the end of the closing for the template's push force."""
    d = spec.design
    pose = finger_pose(d, motion.q[-1])
    _, points = face_clearance(d, pose, spec.cylinder_centre, spec.cylinder_radius)
    torque = spec.spring_rates * (motion.q[-1] + spec.spring_preloads)
    forces, links = contact_forces(d, pose, spec.push_force, torque, points)
    return {"forces_N": forces, "link_forces_N": links, "points": points, "pose": pose}


# -- mechanism -----------------------------------------------------------------------------------

def build_mechanism(spec: UnderactuatedSpec, motion: ClosingMotion, name: str) -> Mechanism:
    """Bodies palm, rod, push_link, rocker_i, coupler_i, phalanx_i with a slide driver and n-1 angle
    drivers (stroke -> relative phalanx angle from the closing motion)."""
    d = spec.design
    n = d.n
    open_pose = finger_pose(d, np.zeros(n))
    g = open_pose.G
    bodies = []
    palm = {"G1": (0.0, 0.0), "G1r": (0.0, 0.0), "rod": (float(open_pose.S[0]) - 10.0, d.rod_y)}
    bodies.append(Body("palm", palm))
    bodies.append(Body("rod", {"rod": (-10.0, 0.0), "S": (0.0, 0.0)}))
    kvec = open_pose.K - open_pose.S
    bodies.append(Body("push_link", {"S": (0.0, 0.0), "K": (float(np.hypot(*kvec)), 0.0)}))
    assembly = {"rod": (float(open_pose.S[0]), d.rod_y, 0.0),
                "push_link": (float(open_pose.S[0]), d.rod_y, float(np.arctan2(kvec[1], kvec[0])))}
    joints: list = [Slider("rod", "palm", "rod", (1.0, 0.0)), Revolute("S", "rod", "push_link"),
                    Revolute("K", "push_link", "rocker1")]
    for i in range(n):
        pts = {f"G{i + 1}": (0.0, 0.0)}
        if i + 1 < n:
            pts[f"G{i + 2}"] = (float(d.lengths[i]), 0.0)
            pts[f"G{i + 2}r"] = (float(d.lengths[i]), 0.0)
        else:
            pts["tip"] = (float(d.lengths[i]), 0.0)
            pts[f"P{n}"] = tuple((open_pose.P[n - 2] - g[n - 1]).tolist())
        bodies.append(Body(f"phalanx{i + 1}", pts))
        assembly[f"phalanx{i + 1}"] = (float(g[i][0]), 0.0, 0.0)
        parent = "palm" if i == 0 else f"phalanx{i}"
        joints.append(Revolute(f"G{i + 1}", parent, f"phalanx{i + 1}"))
    for i in range(n - 1):
        pts = {f"G{i + 1}r": (0.0, 0.0), f"Q{i + 1}": tuple((open_pose.Q[i] - g[i]).tolist())}
        if i == 0:
            pts["K"] = tuple((open_pose.K - g[0]).tolist())
        else:
            pts[f"P{i + 1}"] = tuple((open_pose.P[i - 1] - g[i]).tolist())
        bodies.append(Body(f"rocker{i + 1}", pts))
        assembly[f"rocker{i + 1}"] = (float(g[i][0]), 0.0, 0.0)
        parent = "palm" if i == 0 else f"phalanx{i}"
        joints.append(Revolute(f"G{i + 1}r", parent, f"rocker{i + 1}"))
        cvec = open_pose.P[i] - open_pose.Q[i]
        bodies.append(Body(f"coupler{i + 1}", {f"Q{i + 1}": (0.0, 0.0),
                                               f"P{i + 2}": (float(np.hypot(*cvec)), 0.0)}))
        assembly[f"coupler{i + 1}"] = (float(open_pose.Q[i][0]), float(open_pose.Q[i][1]),
                                       float(np.arctan2(cvec[1], cvec[0])))
        joints.append(Revolute(f"Q{i + 1}", f"rocker{i + 1}", f"coupler{i + 1}"))
        target = f"rocker{i + 2}" if i + 2 < n else f"phalanx{n}"
        joints.append(Revolute(f"P{i + 2}", f"coupler{i + 1}", target))
    drivers = [Driver("slide", "rod", "palm", joint="rod")]
    for i in range(n - 1):
        law = PiecewiseLaw(motion.strokes, motion.q[:, i], motion.events)
        parent = "palm" if i == 0 else f"phalanx{i}"
        drivers.append(Driver("angle", f"phalanx{i + 1}", parent, law=law))
    return Mechanism(name=name, bodies=tuple(bodies), ground="palm", joints=tuple(joints), gears=(),
                     drivers=tuple(drivers), input_range=(0.0, float(motion.strokes[-1])), input_unit="mm",
                     assembly=assembly)


def mobility(n: int) -> dict:
    """The chapter's count (eq 2.1): m = 3(n-1)+3 moving links, P_L = 4(n-1)+4 lower pairs."""
    m = 3 * (n - 1) + 3
    pl = 4 * (n - 1) + 4
    return {"moving_links": m, "lower_pairs": pl, "dof": 3 * m - 2 * pl, "underactuation": 3 * m - 2 * pl - 1}


def synthesise(design) -> SynthesisResult:
    """Closing motion, contact sequence, final forces, velocity ratios and the mechanism."""
    spec: UnderactuatedSpec = design.method
    d = spec.design
    motion = closing_motion(spec, with_object=True)
    if motion.strokes[-1] < 1e-3:  # the driver law needs a stroke to span (a 0.14 mm crank stopped at 0)
        raise SynthesisError(f"underactuated: the finger does not close: the push rod stops at stroke "
                             f"{motion.strokes[-1]:.3g} mm (the linkage locks or meets the object at once); "
                             "check the [push_rod] and [transmission] dimensions")
    free = closing_motion(spec, with_object=False, stroke=float(motion.strokes[-1]))
    final = final_contact_forces(spec, motion)
    mech = build_mechanism(spec, motion, design.name)
    pose_end = final["pose"]
    open_pose = finger_pose(d, np.zeros(d.n))
    report = {
        "mobility": {**mobility(d.n), "mechanism_dof": mech.degrees_of_freedom()},
        "phalanx_lengths_mm": d.lengths.tolist(),
        "dimensions_source": spec.source,
        "stroke_mm": spec.stroke,
        "push_force_N": spec.push_force,
        "contact_sequence": [f"phalanx{i + 1}" for i in motion.contact_order],
        "contact_strokes_mm": motion.contact_strokes,
        "contact_forces_N": {f"phalanx{i + 1}": float(f) for i, f in enumerate(final["forces_N"])},
        "link_forces_N": [float(v) for v in final["link_forces_N"]],
        "final_joint_angles_deg": np.degrees(motion.q[-1]).tolist(),
        "free_closing_joint_angles_deg": np.degrees(free.q[-1]).tolist(),
        "velocity_ratios": {
            "E_open": transmission_ratios(open_pose).tolist(),
            "E_final": transmission_ratios(pose_end).tolist(),
            "crank_rate_rad_per_mm_open": crank_rate(d, open_pose),
            "distal_rate_rad_per_mm_final": distal_rate(d, pose_end),
        },
    }
    springs = [{"joint": f"G{i + 1}", "rate_Nmm_per_deg": float(spec.spring_rates[i] * np.pi / 180.0),
                "preload_deg": float(np.degrees(spec.spring_preloads[i])), "legs_mm": spec.spring_legs,
                "note": "return spring, opens the joint against its stop"} for i in range(d.n)]
    parts = {
        "springs": springs,
        "purchased": [{"item": f"linear actuator, stroke >= {spec.stroke:.0f} mm, force >= "
                               f"{spec.push_force:.0f} N", "qty": 1, "note": "drives the push rod"}],
        "tip_point": "tip",
        "pads": {f"phalanx{d.n}": {"point": "tip", "radius_mm": 0.5 * d.thickness}},
    }

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.underactuated.plots import closing_figures
        return closing_figures(spec, motion, free, final)

    data = {"motion": motion, "free": free, "final": final, "spec": spec}
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data=data, parts=parts)
