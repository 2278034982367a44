"""The underactuated finger as a :class:`~fabricate.mechanism.Mechanism`: the push rod a slider with a "slide"
driver over the stroke, the n-1 phalanx angles the actuator does not fix "angle" drivers whose laws come from
the closing motion; and the chapter's mobility count."""

from __future__ import annotations

import numpy as np

from fabricate.mechanism import Body, Driver, Mechanism, Revolute, Slider
from fabricate.synthesis.underactuated.closing import ClosingMotion
from fabricate.synthesis.underactuated.model import PiecewiseLaw, finger_pose
from fabricate.synthesis.underactuated.spec import UnderactuatedSpec


def build_mechanism(spec: UnderactuatedSpec, motion: ClosingMotion, name: str) -> Mechanism:
    """Bodies palm, rod, push_link, rocker_i, coupler_i, phalanx_i with a slide driver and n-1 angle
    drivers (stroke -> relative phalanx angle from the closing motion)."""
    d = spec.design
    n = d.n
    open_pose = finger_pose(d, np.zeros(n))
    assert open_pose is not None  # assembled by construction: FingerDesign takes the couplers from it
    g = open_pose.G
    bodies = []
    palm = {"G1": (0.0, 0.0), "G1r": (0.0, 0.0), "rod": (float(open_pose.S[0]) - 10.0, d.rod_y)}
    bodies.append(Body("palm", palm))
    bodies.append(Body("rod", {"rod": (-10.0, 0.0), "S": (0.0, 0.0)}))
    kvec = open_pose.K - open_pose.S
    bodies.append(Body("push_link", {"S": (0.0, 0.0), "K": (float(np.hypot(*kvec)), 0.0)}))
    assembly = {"rod": (float(open_pose.S[0]), d.rod_y, 0.0),
                "push_link": (float(open_pose.S[0]), d.rod_y, float(np.arctan2(kvec[1], kvec[0])))}
    joints: list[Revolute | Slider] = [Slider("rod", "palm", "rod", (1.0, 0.0)), Revolute("S", "rod", "push_link"),
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


def mobility(n: int) -> dict[str, int]:
    """The chapter's count (eq 2.1): m = 3(n-1)+3 moving links, P_L = 4(n-1)+4 lower pairs."""
    m = 3 * (n - 1) + 3
    pl = 4 * (n - 1) + 4
    return {"moving_links": m, "lower_pairs": pl, "dof": 3 * m - 2 * pl, "underactuation": 3 * m - 2 * pl - 1}
