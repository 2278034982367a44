"""The compliant gripper finger's closing motion: free (eqs 1-2, the hinges on their stops until the rod
overcomes the preloads) up to the first touch, then on the can up to the grasp stroke."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, fsolve

from fabricate.errors import SynthesisError
from fabricate.synthesis.compliant.model import (
    ContactPath,
    Grasp,
    GripperGeometry,
    Springs,
    finger_state,
    phi1_on_can,
    spring_torques,
)
from fabricate.synthesis.compliant.spec import CompliantSpec


@dataclass(frozen=True)
class GripperMotion:
    """Hinge angles (rad) against stroke (mm) from the open finger to the end of the sweep."""

    strokes: np.ndarray
    phi1: np.ndarray
    phi2: np.ndarray
    on_can: np.ndarray


def _no_load_residual(geom: GripperGeometry, springs: Springs, x: np.ndarray, s: float) -> np.ndarray:
    st = finger_state(geom, x[0], x[1])
    s1, s2 = spring_torques(springs, x[0], x[1])
    # eqs 1-2 with Fd eliminated: s1 h2 - s2 h1 = 0; scaled so both rows are about mm
    return np.array([float(st.stroke) - s, float(s1 * st.h2 - s2 * st.h1) / 1e3])


def no_load_closing(geom: GripperGeometry, springs: Springs, strokes: np.ndarray) -> np.ndarray:
    """Eqs 1-2 over increasing strokes with the hinge stops (phi >= 0) as an active set.

    A hinge stays on its stop while the rod's moment about it is below the spring preload (the stop
    still pushes back); then both hinges are free and eqs 1-2 hold (Fd eliminated). On a stop the
    other hinge follows the stroke alone (a 1-D root). Returns (m, 2) angles (phi1, phi2), rad.
    """
    out = np.zeros((len(strokes), 2))
    x = np.zeros(2)
    mode = None
    for i, s in enumerate(strokes):
        if s <= 0.0:
            continue
        for _ in range(3):
            if mode is None or mode in ("B", "C"):
                candidates = [mode] if mode else ["B", "C"]
                solved = None
                for m in candidates:
                    j = 0 if m == "B" else 1           # the hinge that moves
                    def one(v, j=j, s=s):
                        y = np.zeros(2)
                        y[j] = v
                        return float(finger_state(geom, y[0], y[1]).stroke) - s
                    grid = np.linspace(x[j], np.pi, 721)
                    vals = finger_state(geom, *(np.where(np.arange(2)[:, None] == j, grid, 0.0))).stroke - s
                    sign = np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
                    if sign.size == 0:
                        continue
                    v = brentq(one, grid[sign[0]], grid[sign[0] + 1], xtol=1e-14)
                    y = np.zeros(2)
                    y[j] = v
                    st = finger_state(geom, y[0], y[1])
                    s1, s2 = spring_torques(springs, y[0], y[1])
                    h_move, h_stop = (st.h1, st.h2) if m == "B" else (st.h2, st.h1)
                    t_move, t_stop = (s1, s2) if m == "B" else (s2, s1)
                    fd = t_move / h_move if h_move != 0 else 0.0
                    if t_stop - fd * h_stop >= -1e-9:      # the stop still holds
                        solved = (m, y)
                        break
                if solved is not None:
                    mode, x = solved
                    break
                mode = "free"
            if mode == "free":
                y, info, ok, _ = fsolve(lambda v, s=s: _no_load_residual(geom, springs, v, s), x,
                                        full_output=True, xtol=1e-13)
                if ok == 1 and y[0] >= -1e-9 and y[1] >= -1e-9:
                    x = np.maximum(y, 0.0)
                    break
                mode = "B" if y[1] < 0 else "C"
        else:
            raise SynthesisError(f"compliant_gripper: no-load closing lost at stroke {s:.3f} mm")
        if abs(float(finger_state(geom, x[0], x[1]).stroke) - s) > 1e-6:
            raise SynthesisError(f"compliant_gripper: no-load closing lost at stroke {s:.3f} mm")
        out[i] = x
    return out


def closing_motion(spec: CompliantSpec, path: ContactPath, grasp: Grasp, samples: int = 81) -> GripperMotion:
    """Free closing up to the first touch, then on the can up to the grasp stroke plus overtravel."""
    geom = spec.geometry
    end = grasp.stroke + spec.overtravel
    strokes = np.linspace(0.0, end, samples)
    free = strokes <= grasp.contact_stroke
    phi = np.zeros((samples, 2))
    phi[free] = no_load_closing(geom, spec.springs, strokes[free])
    st = path.state
    for i in np.nonzero(~free)[0]:
        s = strokes[i]
        j = int(np.searchsorted(st.stroke, s))
        if j <= 0 or j >= len(st.stroke):
            raise SynthesisError(f"compliant_gripper: stroke {s:.2f} mm leaves the contact path")
        p2 = brentq(lambda v, s=s: float(finger_state(geom, phi1_on_can(geom, v, path.can_radius), v).stroke) - s,
                    path.phi2[j - 1], path.phi2[j], xtol=1e-14)
        phi[i] = (float(phi1_on_can(geom, p2, path.can_radius)), p2)
    return GripperMotion(strokes, phi[:, 0], phi[:, 1], ~free)
