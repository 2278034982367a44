"""The one planar mechanism model shared by every seed, with its pose solver and sweep.

A :class:`Mechanism` is a set of rigid bodies (named points in body coordinates), joints between them
(revolute, slider), gear couplings (a law between two bodies' rotations relative to a carrier) and
drivers (a relative angle or a slide as a function of the one scalar input). The solver finds every
body's world pose ``(x, y, theta)`` by Newton's method on the constraint residuals; the sweep follows
the assembly branch of the first pose by continuation, and reports a lock-up or a branch change as a
:class:`~fabricate.errors.LockupError` with the input value where it happened.

Conventions
-----------
- A revolute joint named ``J`` connects two bodies that both have a point named ``J``.
- Angles are radians inside; the input is in ``Mechanism.input_unit`` (``"deg"`` or ``"mm"``).
- Body poses are unwrapped angles: continuous over a sweep, never reduced to (-pi, pi].
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from fabricate.errors import LockupError, SpecError
from fabricate.planar import rotation, transform_points

#: Residual norm (mm or rad) below which a pose is accepted as assembled.
ASSEMBLY_TOLERANCE = 1e-12


class Law(Protocol):
    """A smooth scalar function with derivatives, like :class:`scipy.interpolate.CubicSpline`."""

    def __call__(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray | float: ...


@dataclass(frozen=True)
class LinearLaw:
    """``y = slope * x + offset``; the identity by default. Usable wherever a :class:`Law` is."""

    slope: float = 1.0
    offset: float = 0.0

    def __call__(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray | float:
        if isinstance(x, float):  # one value (the solver's every step): the same product and sum on floats
            return self.slope * x + self.offset if nu == 0 else float(self.slope) if nu == 1 else 0.0
        x = np.asarray(x, dtype=np.float64)
        if nu == 0:
            return self.slope * x + self.offset
        if nu == 1:
            return np.full_like(x, self.slope)
        return np.zeros_like(x)


@dataclass(frozen=True)
class Body:
    """A rigid body.

    Attributes
    ----------
    name : str
    points : Mapping[str, tuple[float, float]]
        Named points (joint centres, markers such as the fingertip) in body coordinates, mm.
    """

    name: str
    points: Mapping[str, tuple[float, float]]

    def point(self, name: str) -> np.ndarray:
        return np.asarray(self.points[name], dtype=np.float64)


@dataclass(frozen=True)
class Revolute:
    """A pin joint: point ``name`` of ``body_a`` coincides with point ``name`` of ``body_b``."""

    name: str
    body_a: str
    body_b: str


@dataclass(frozen=True)
class Slider:
    """A prismatic joint: point ``name`` of ``body_b`` stays on the line through point ``name`` of
    ``body_a`` with direction ``axis`` (body_a coordinates); the relative rotation is locked at
    ``angle`` (rad, theta_b - theta_a)."""

    name: str
    body_a: str
    body_b: str
    axis: tuple[float, float]
    angle: float = 0.0


@dataclass(frozen=True)
class GearCoupling:
    """Two bodies whose rotations relative to ``carrier`` follow ``law``:
    ``theta_b - theta_c = law(theta_a - theta_c)`` (rad).

    ``axis_a`` / ``axis_b`` name the joints about which the gears turn (their distance is the centre
    distance); ``working_range`` is the range of ``theta_a - theta_c`` (rad) the pair must cover.
    """

    name: str
    carrier: str
    gear_a: str
    gear_b: str
    law: Law
    axis_a: str = ""
    axis_b: str = ""
    working_range: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class Driver:
    """What the input drives.

    ``kind="angle"``: ``theta_body - theta_reference = law(s)`` (rad).
    ``kind="slide"``: displacement of point ``joint`` of ``body`` along slider ``joint`` of ``reference``
    measured from point ``joint`` of ``reference``, ``= law(s)`` (mm).
    ``law`` maps the input ``s`` (in the mechanism's input unit) to that coordinate; ``None`` means
    identity (degrees converted to radians for an angle driver).
    """

    kind: str
    body: str
    reference: str
    joint: str = ""
    law: Law | None = None


@dataclass(frozen=True)
class Mechanism:
    """A planar mechanism.

    Attributes
    ----------
    name : str
    bodies : tuple of Body
    ground : str
        Name of the fixed body (its pose is the identity).
    joints : tuple of Revolute or Slider
    gears : tuple of GearCoupling
    drivers : tuple of Driver
    input_range : (float, float)
        Start and end of the motion, in ``input_unit``.
    input_unit : str
        ``"deg"`` or ``"mm"``.
    assembly : Mapping[str, (3,) array]
        World pose guess for every non-ground body at ``input_range[0]``; it selects the assembly branch.
    """

    name: str
    bodies: tuple[Body, ...]
    ground: str
    joints: tuple[Revolute | Slider, ...]
    gears: tuple[GearCoupling, ...]
    drivers: tuple[Driver, ...]
    input_range: tuple[float, float]
    input_unit: str = "deg"
    assembly: Mapping[str, tuple[float, float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        names = [b.name for b in self.bodies]
        if len(set(names)) != len(names):
            raise SpecError("mechanism.bodies", "body names must be unique")
        if self.ground not in names:
            raise SpecError("mechanism.ground", f"unknown body {self.ground!r}")
        by_name = {b.name: b for b in self.bodies}
        for j in self.joints:
            for b in (j.body_a, j.body_b):
                if b not in by_name:
                    raise SpecError(f"mechanism.joints.{j.name}", f"unknown body {b!r}")
                if j.name not in by_name[b].points:
                    raise SpecError(f"mechanism.joints.{j.name}", f"body {b!r} has no point {j.name!r}")
        if self.input_unit not in ("deg", "mm"):
            raise SpecError("mechanism.input_unit", f"expected 'deg' or 'mm', got {self.input_unit!r}")
        n_eq = sum(2 for _ in self.joints) + len(self.gears) + len(self.drivers)
        n_q = 3 * (len(self.bodies) - 1)
        if n_eq < n_q:
            raise SpecError("mechanism", f"under-constrained: {n_q - n_eq} degree(s) of freedom are not driven")

    # -- look-ups ------------------------------------------------------------------------------
    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bodies)

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    def point_owner(self, point: str) -> str:
        """Name of the first body that has a point named ``point``."""
        for b in self.bodies:
            if point in b.points:
                return b.name
        raise KeyError(point)

    def point_names(self) -> tuple[str, ...]:
        """Every named point, in body order, without repeats."""
        seen: dict[str, None] = {}
        for b in self.bodies:
            for p in b.points:
                seen.setdefault(p, None)
        return tuple(seen)

    def degrees_of_freedom(self) -> int:
        """Mobility before drivers (planar Gruebler count with gears as one constraint each)."""
        return 3 * (len(self.bodies) - 1) - 2 * len(self.joints) - len(self.gears)

    # -- solving ---------------------------------------------------------------------------------
    def solve(self, s: float) -> dict[str, np.ndarray]:
        """World pose ``(x, y, theta)`` of every body at input ``s``, on the first pose's branch."""
        motion = self.sweep(np.array([self.input_range[0], s]) if s != self.input_range[0]
                            else np.array([s]))
        return motion.poses_at(len(motion.inputs) - 1)

    def sweep(self, inputs: np.ndarray | int | None = None) -> Motion:
        """Solve every input value by continuation from the assembled first pose.

        Parameters
        ----------
        inputs : (n,) array, int or None
            Input values in order of motion (the first is assembled from ``assembly``), or a count of
            evenly spaced values over ``input_range`` (default 361).

        Raises
        ------
        LockupError
            Where the mechanism cannot be assembled or would have to change branch to go on.
        """
        if inputs is None:
            inputs = 361
        if isinstance(inputs, (int, np.integer)):
            inputs = np.linspace(self.input_range[0], self.input_range[1], int(inputs))
        inputs = np.asarray(inputs, dtype=np.float64)
        # synthesis, parts and checks sweep the same motion: solve it once per mechanism object
        cache: dict[bytes, Motion] = self.__dict__.setdefault("_sweep_cache", {})
        key = inputs.tobytes()
        if key in cache:
            return cache[key]
        motion = self._sweep(inputs)
        if len(cache) >= 8:
            cache.pop(next(iter(cache)))
        cache[key] = motion
        return motion

    def _sweep(self, inputs: np.ndarray) -> Motion:
        system = _System(self)
        q = system.assemble(inputs[0])
        out = np.empty((len(inputs), len(system.free), 3))
        out[0] = q.reshape(-1, 3)
        for i in range(1, len(inputs)):
            q = system.continue_to(q, inputs[i - 1], inputs[i])
            out[i] = q.reshape(-1, 3)
        inputs = inputs.copy()
        # the motion is shared through the sweep cache: make it immutable
        inputs.setflags(write=False)
        out.setflags(write=False)
        return Motion(inputs=inputs, body_names=self.body_names, ground=self.ground,
                      free=tuple(system.free), q=out, mechanism=self)

    def velocity(self, poses: Mapping[str, np.ndarray], s: float) -> dict[str, np.ndarray]:
        """d(pose)/ds of every body at a solved pose (per input unit)."""
        system = _System(self)
        q = np.concatenate([poses[name] for name in system.free])
        _, jac, ds = system.jacobian(q, s)
        dq = np.linalg.lstsq(jac, -ds, rcond=None)[0]
        result = {self.ground: np.zeros(3)}
        for k, name in enumerate(system.free):
            result[name] = dq[3 * k:3 * k + 3]
        return result


@dataclass(frozen=True)
class Motion:
    """World poses of every body over a sweep.

    Attributes
    ----------
    inputs : (n,) array
        Input values (``Mechanism.input_unit``).
    q : (n, m, 3) array
        Poses (x mm, y mm, theta rad) of the ``m`` non-ground bodies named in ``free``.
    """

    inputs: np.ndarray
    body_names: tuple[str, ...]
    ground: str
    free: tuple[str, ...]
    q: np.ndarray
    mechanism: Mechanism

    def pose(self, body: str) -> np.ndarray:
        """Poses of ``body`` over the sweep, shape (n, 3)."""
        if body == self.ground:
            return np.zeros((len(self.inputs), 3))
        return self.q[:, self.free.index(body)]

    def poses_at(self, i: int) -> dict[str, np.ndarray]:
        """Every body's pose at sweep index ``i``."""
        return {name: self.pose(name)[i].copy() for name in self.body_names}

    def point(self, name: str, body: str | None = None) -> np.ndarray:
        """World positions (n, 2) of named point ``name`` (of ``body``, default its first owner)."""
        body = body or self.mechanism.point_owner(name)
        local = self.mechanism.body(body).point(name)
        pose = self.pose(body)
        world: np.ndarray = np.einsum("nij,j->ni", rotation(pose[:, 2]), local) + pose[:, :2]
        return world

    def relative_angle(self, body: str, reference: str) -> np.ndarray:
        """theta_body - theta_reference over the sweep (n,), rad."""
        angle: np.ndarray = self.pose(body)[:, 2] - self.pose(reference)[:, 2]
        return angle


class _System:
    """Residuals and Jacobian of a mechanism's constraints in the free bodies' poses.

    The solver calls :meth:`jacobian` thousands of times per sweep on systems of a dozen or two unknowns, where
    numpy's per-call overhead is most of the cost: the constraint layout is precomputed here, and the
    arithmetic of the small blocks runs on Python floats (the same IEEE operations in the same order as
    elementwise numpy, so the results are bit-identical; sines and cosines stay numpy's).
    """

    def __init__(self, mech: Mechanism) -> None:
        self.mech = mech
        self.free = [b.name for b in mech.bodies if b.name != mech.ground]
        self.index = {name: k for k, name in enumerate(self.free)}
        self.bodies = {b.name: b for b in mech.bodies}
        self.n = 3 * len(self.free)
        self.scale = max(1.0, max((float(np.hypot(*p)) for b in mech.bodies for p in b.points.values()),
                                  default=1.0))
        revolutes = [j for j in mech.joints if isinstance(j, Revolute)]
        self.others = [j for j in mech.joints if not isinstance(j, Revolute)]
        # revolute constraints are most of every mechanism: both ends of all of them at once, with
        # the Jacobian's constant (+-1) entries and the flat positions of its angle entries precomputed
        k = len(revolutes)
        self.rev_body = np.array([[self.index.get(j.body_a, -1) for j in revolutes],
                                  [self.index.get(j.body_b, -1) for j in revolutes]], dtype=np.int64).reshape(2, k)
        self.rev_local = np.array([[self.bodies[j.body_a].point(j.name) for j in revolutes],
                                   [self.bodies[j.body_b].point(j.name) for j in revolutes]]).reshape(2, k, 2)
        sign = np.array([1.0, -1.0])[:, None]
        free = self.rev_body >= 0
        rows = np.broadcast_to(np.arange(k), (2, k))[free]
        cols = 3 * self.rev_body[free]
        rev_sign = np.broadcast_to(sign, (2, k))[free]
        self.rev_const = np.zeros((2 * k, self.n))
        self.rev_const[2 * rows, cols] = rev_sign
        self.rev_const[2 * rows + 1, cols + 1] = rev_sign
        self.rev_flat_x = (2 * rows) * self.n + cols + 2
        self.rev_flat_y = (2 * rows + 1) * self.n + cols + 2
        # the same layout as Python lists for the float loop of _revolute_floats: per joint, both ends'
        # (body index or -1 for the ground, local x, local y); the Jacobian's angle entries in the order of
        # rev_flat_x / rev_flat_y (side a of every joint, then side b), as (end, sign)
        self._rev_ends = [(int(self.rev_body[0, i]), float(self.rev_local[0, i, 0]), float(self.rev_local[0, i, 1]),
                           int(self.rev_body[1, i]), float(self.rev_local[1, i, 0]), float(self.rev_local[1, i, 1]))
                          for i in range(k)]
        self._rev_entries = [(side * k + i, float(sign[side, 0])) for side in (0, 1) for i in range(k)
                             if free[side, i]]
        self._n_rev = 2 * k
        # the angle drivers without a law in a mechanism of degrees: their values are computed on floats
        # (numpy's radians is the product with pi/180 too)
        self._deg = self.mech.input_unit == "deg"
        # where the last assembly or continuation ended: (q, s, Jacobian, d(residual)/ds, orientation) there.
        # A sweep's next continuation starts from that very q and s: it reuses them instead of computing the
        # same Jacobian and determinant again
        self._end: tuple[np.ndarray, float, np.ndarray, np.ndarray, float] | None = None
        # the sliders' and slide drivers' joint points and unit directions (fixed in body_a / the reference)
        self._slider_terms = []
        for j in self.others:
            axis = np.asarray(j.axis, dtype=np.float64)
            normal = np.array([-axis[1], axis[0]])  # the slide axis turned +90 deg
            self._slider_terms.append((self.bodies[j.body_a].point(j.name), self.bodies[j.body_b].point(j.name),
                                       normal / np.hypot(*normal)))
        self._driver_terms: list[tuple[np.ndarray, np.ndarray, np.ndarray] | None] = []
        for d in self.mech.drivers:
            if d.kind == "angle":
                self._driver_terms.append(None)
                continue
            slider = next(j for j in self.mech.joints if j.name == d.joint and isinstance(j, Slider))
            axis = np.asarray(slider.axis, dtype=np.float64)
            self._driver_terms.append((self.bodies[d.reference].point(d.joint), self.bodies[d.body].point(d.joint),
                                       axis / np.hypot(*axis)))

    def _revolute_floats(self, q: np.ndarray) -> tuple[list[float], list[float], list[float]]:
        """Residuals of the revolute joints and the world offsets (x, y) of every joint end from its body's
        origin, ends ordered side a of every joint then side b."""
        # the ground (index -1, last) has pose 0: cos 0 = 1 and sin 0 = 0 exactly, as numpy gives them
        th = q[2::3]
        cos = np.cos(th).tolist() + [1.0]
        sin = np.sin(th).tolist() + [0.0]
        flat = q.tolist()
        px = flat[0::3] + [0.0]
        py = flat[1::3] + [0.0]
        res: list[float] = []
        wxa: list[float] = []
        wya: list[float] = []
        wxb: list[float] = []
        wyb: list[float] = []
        for ba, lxa, lya, bb, lxb, lyb in self._rev_ends:
            ca, sa, cb, sb = cos[ba], sin[ba], cos[bb], sin[bb]
            xa = ca * lxa - sa * lya
            ya = sa * lxa + ca * lya
            xb = cb * lxb - sb * lyb
            yb = sb * lxb + cb * lyb
            res.append((xa + px[ba]) - (xb + px[bb]))
            res.append((ya + py[ba]) - (yb + py[bb]))
            wxa.append(xa)
            wya.append(ya)
            wxb.append(xb)
            wyb.append(yb)
        return res, wxa + wxb, wya + wyb

    def _revolute_entries(self, jac: np.ndarray, wx: list[float], wy: list[float]) -> None:
        """Write the revolute rows' angle entries into ``jac`` (its first 2k rows hold ``rev_const``)."""
        flat = jac.reshape(-1)
        # the two ends of one joint are different bodies: no entry is written twice
        flat[self.rev_flat_x] = [-sign * wy[e] for e, sign in self._rev_entries]
        flat[self.rev_flat_y] = [sign * wx[e] for e, sign in self._rev_entries]

    def _pose(self, q: np.ndarray, name: str) -> np.ndarray:
        k = self.index.get(name)
        return np.zeros(3) if k is None else q[3 * k:3 * k + 3]

    def _driver_value(self, d: Driver, s: float) -> tuple[float, float]:
        if d.law is not None:
            return float(d.law(s)), float(d.law(s, 1))
        if d.kind == "angle" and self._deg:
            return float(s) * (np.pi / 180.0), float(np.pi / 180.0)
        return float(s), 1.0

    def jacobian(self, q: np.ndarray, s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Residual vector (m,), Jacobian (m, n) and d(residual)/ds (m,) at poses ``q``."""
        rev_res, wx, wy = self._revolute_floats(q)
        rows = _Rows(self, q)
        index = self.index
        flat = q.tolist()

        def theta(body: str) -> float:
            k = index.get(body)
            return 0.0 if k is None else flat[3 * k + 2]
        for j, (pa_local, pb_local, normal) in zip(self.others, self._slider_terms, strict=True):
            # sliders: relative rotation locked, point b on a's line
            rows.angle_row(j.body_b, j.body_a)
            rows.res.append(theta(j.body_b) - theta(j.body_a) - j.angle)
            rows.dres_ds.append(0.0)
            # (pb - pa) . n = 0 with n the slide axis turned +90 deg, fixed in body_a
            rows.projection(j.body_a, j.body_b, pa_local, pb_local, normal)
            rows.dres_ds.append(0.0)
        for g in self.mech.gears:
            thc = theta(g.carrier)
            xa = theta(g.gear_a) - thc
            xb = theta(g.gear_b) - thc
            slope = float(g.law(xa, 1))
            r = rows.row()
            for body, coef in ((g.gear_b, 1.0), (g.gear_a, -slope), (g.carrier, slope - 1.0)):
                if body in index:
                    r[3 * index[body] + 2] += coef
            rows.res.append(xb - float(g.law(xa)))
            rows.dres_ds.append(0.0)
        for d, terms in zip(self.mech.drivers, self._driver_terms, strict=True):
            value, dvalue = self._driver_value(d, s)
            if terms is None:
                rows.angle_row(d.body, d.reference)
                rows.res.append(theta(d.body) - theta(d.reference) - value)
            else:
                rows.projection(d.reference, d.body, *terms)
                rows.res[-1] -= value
            rows.dres_ds.append(-dvalue)
        k2 = self._n_rev
        m = k2 + len(rows.res)
        jac = np.empty((m, self.n))
        jac[:k2] = self.rev_const
        if rows.rows:
            jac[k2:] = rows.rows
        self._revolute_entries(jac, wx, wy)
        res = np.array(rev_res + [float(v) for v in rows.res], dtype=np.float64)
        dres_ds = np.zeros(m)
        dres_ds[k2:] = rows.dres_ds
        return res, jac, dres_ds

    def newton(self, q: np.ndarray, s: float, max_iter: int = 30) -> tuple[np.ndarray, bool, np.ndarray, np.ndarray]:
        """Gauss-Newton from ``q``.

        Returns
        -------
        q : (n,) array
        converged : bool
        jac, dres_ds : arrays
            Jacobian and d(residual)/ds at the returned ``q`` (reused by the continuation).
        """
        q = q.copy()
        tol = ASSEMBLY_TOLERANCE * self.scale
        for _ in range(max_iter):
            res, jac, ds = self.jacobian(q, s)
            if res.size == 0 or float(np.abs(res).max()) < tol:
                return q, True, jac, ds
            step = np.linalg.lstsq(jac, -res, rcond=None)[0] if jac.shape[0] != jac.shape[1] \
                else _solve_square(jac, -res)
            if not np.isfinite(step).all():
                return q, False, jac, ds
            q = q + step
        res, jac, ds = self.jacobian(q, s)
        return q, bool(np.max(np.abs(res)) < tol), jac, ds

    def assemble(self, s: float) -> np.ndarray:
        guess: list[float] = []
        for name in self.free:
            if name not in self.mech.assembly:
                raise SpecError(f"mechanism.assembly.{name}", "missing assembly guess for body")
            guess.extend(np.asarray(self.mech.assembly[name], dtype=np.float64))
        q, ok, jac, ds = self.newton(np.asarray(guess), s)
        if not ok:
            raise LockupError(s, f"{self.mech.name}: cannot assemble the first pose")
        self._end = (q, s, jac, ds, self._orientation(jac))
        return q

    def _step_ok(self, q_old: np.ndarray, q_new: np.ndarray) -> bool:
        # a step is suspicious when a body turns more than 0.3 rad or moves more than 30 % of the
        # mechanism's size: the predictor landed near another branch rather than following this one
        d = (q_new - q_old).reshape(-1, 3)
        return bool((np.abs(d[:, 2]) < 0.3).all() and (np.hypot(d[:, 0], d[:, 1]) < 0.3 * self.scale).all())

    @staticmethod
    def _orientation(jac: np.ndarray) -> float:
        if jac.shape[0] != jac.shape[1]:
            return 0.0
        det = float(np.linalg.det(jac))
        # np.sign's values, without its call: +-1, 0, or nan for a nan
        return 1.0 if det > 0.0 else -1.0 if det < 0.0 else det if det != det else 0.0

    def continue_to(self, q: np.ndarray, s0: float, s1: float) -> np.ndarray:
        """Follow the branch from (q at s0) to s1 with an adaptive step; raise at lock-up."""
        s = s0
        end = self._end
        if end is not None and end[0] is q and end[1] == s0:
            jac, ds, sign0 = end[2], end[3], end[4]
        else:
            _, jac, ds = self.jacobian(q, s)
            sign0 = self._orientation(jac)
        sign_end = sign0
        direction = 1.0 if s1 >= s0 else -1.0
        h_mag = abs(s1 - s0)
        min_h = abs(s1 - s0) * 1e-6 + 1e-12
        # near a Grashof change point a step of ~15 deg lands the corrector on the other branch (a false
        # "branch change", or a silent jump where the orientation is not checked); steps of 1/360 of the
        # input range (1 deg of a full turn, the default sweep's own spacing) stayed on the branch
        max_h = abs(self.mech.input_range[1] - self.mech.input_range[0]) / 360.0 or abs(s1 - s0)
        while direction * (s1 - s) > 1e-15:
            h = direction * min(h_mag, max_h, abs(s1 - s))
            # first-order (tangent) predictor keeps the corrector on this branch
            tangent = _solve_square(jac, -ds) if jac.shape[0] == jac.shape[1] \
                else np.linalg.lstsq(jac, -ds, rcond=None)[0]
            q_new, ok, jac_new, ds_new = self.newton(q + tangent * h, s + h)
            if ok and self._step_ok(q, q_new):
                sign = self._orientation(jac_new)
                if sign0 != 0.0 and sign != 0.0 and sign != sign0:
                    raise LockupError(s + h, f"{self.mech.name}: the motion passes a singular pose "
                                             "(branch change)")
                q, s, jac, ds, sign_end = q_new, s + h, jac_new, ds_new, sign
                h_mag *= 1.5
                continue
            h_mag *= 0.5
            if h_mag < min_h:
                raise LockupError(s, f"{self.mech.name}: lock-up, no assembly beyond this input")
        self._end = (q, s, jac, ds, sign_end)
        return q



class _Rows:
    """The constraint rows of :meth:`_System.jacobian` as they are added at poses ``q``: each row's Jacobian
    entries, residual and d(residual)/ds."""

    def __init__(self, system: _System, q: np.ndarray) -> None:
        self.system, self.q, self.n = system, q, system.n
        self.rows: list[np.ndarray] = []
        self.res: list[float] = []
        self.dres_ds: list[float] = []

    def row(self) -> np.ndarray:
        r = np.zeros(self.n)
        self.rows.append(r)
        return r

    def add_point_terms(self, r2: list[np.ndarray], body: str, local: np.ndarray, sign: float) -> None:
        """Add d(world point)/dq of ``local`` on ``body`` (times ``sign``) to the x and y rows ``r2``."""
        k = self.system.index.get(body)
        if k is None:
            return
        th = self.q[3 * k + 2]
        dR = np.array([[-np.sin(th), -np.cos(th)], [np.cos(th), -np.sin(th)]]) @ local
        for axis in (0, 1):
            r2[axis][3 * k + axis] += sign
            r2[axis][3 * k + 2] += sign * dR[axis]

    def world(self, body: str, local: np.ndarray) -> np.ndarray:
        return transform_points(self.system._pose(self.q, body), local)

    def angle_row(self, body: str, reference: str) -> np.ndarray:
        """A row of theta_body - theta_reference (its residual is the caller's)."""
        index = self.system.index
        r = self.row()
        if body in index:
            r[3 * index[body] + 2] += 1.0
        if reference in index:
            r[3 * index[reference] + 2] -= 1.0
        return r

    def projection(self, body_a: str, body_b: str, pa_local: np.ndarray, pb_local: np.ndarray,
                   unit_local: np.ndarray) -> None:
        """Row and value of (p_b - p_a) . u, u the unit direction ``unit_local`` fixed in body_a."""
        index = self.system.index
        u_world = rotation(self.system._pose(self.q, body_a)[2]) @ unit_local
        pa, pb = self.world(body_a, pa_local), self.world(body_b, pb_local)
        r = self.row()
        grad = [np.zeros(self.n), np.zeros(self.n)]
        self.add_point_terms(grad, body_b, pb_local, 1.0)
        self.add_point_terms(grad, body_a, pa_local, -1.0)
        r += grad[0] * u_world[0] + grad[1] * u_world[1]
        if body_a in index:  # u turns with body_a
            r[3 * index[body_a] + 2] += float(np.dot(pb - pa, np.array([-u_world[1], u_world[0]])))
        self.res.append(float(np.dot(pb - pa, u_world)))


def _solve_square(jac: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve a square system; a singular Jacobian gives a non-finite step (treated as failure)."""
    try:
        step: np.ndarray = np.linalg.solve(jac, rhs)
        return step
    except np.linalg.LinAlgError:
        return np.full_like(rhs, np.nan)
