"""The quasi-static equilibrium of the underactuated finger at one stroke (:class:`Settler`), and the
clearance of its palmar faces to the cylinder it closes on."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq, minimize

from fabricate.planar import cross2
from fabricate.synthesis.underactuated.model import (
    FingerDesign,
    FingerPose,
    FingerPoses,
    finger_poses,
    stroke_gradients,
)
from fabricate.synthesis.underactuated.spec import UnderactuatedSpec


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


_UPPER_STOP = 0.6 * np.pi          # rad, the joints' closed stop (far beyond any grasp)


class Settler:
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
                yielding = min(held, key=lambda i: self.rates[i] * (x[i] + self.preloads[i]) / ds[i])
                lower.discard(yielding)
                upper.discard(yielding)
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
            worst = -scale
            release: tuple[str, int] | None = None
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
