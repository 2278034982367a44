"""A :class:`~fabricate.mechanism.Mechanism` written as the tables of a ``kind = "linkage"`` template.

The API hands a mechanism built in code to the pipeline through this: the template it makes is embedded
in the build's report like any other, so ``fabricate check`` rebuilds it. Every body's points are written
in world coordinates at the pose of ``input_range[0]`` (the linkage's reference pose); revolute and
slider joints keep their names; drivers become linear drivers of the joint between the driven body and
its reference. Gear couplings and driver laws other than the identity are not written yet (a clear
:class:`~fabricate.errors.SpecError` says so).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from fabricate.errors import SpecError
from fabricate.mechanism import LinearLaw, Mechanism, Revolute, Slider
from fabricate.planar import rotation, transform_points


def _world(poses: Mapping[str, np.ndarray], body: str, local: np.ndarray) -> list[float]:
    return [float(v) for v in transform_points(np.asarray(poses[body], dtype=np.float64), local)]


def _identity(driver: Any, unit: str) -> bool:
    law = driver.law
    if law is None:
        return True
    if isinstance(law, LinearLaw):
        slope = math.pi / 180.0 if (driver.kind == "angle" and unit == "deg") else 1.0
        return math.isclose(law.slope, slope, rel_tol=1e-12)
    return False


def linkage_tables(mechanism: Mechanism, *, tip_point: str | None = None,
                   pads: Mapping[str, Mapping[str, Any]] | None = None) -> dict[str, Any]:
    """The ``[linkage]`` table (with its bodies, joints, drivers and pads) of ``mechanism``.

    Parameters
    ----------
    mechanism : Mechanism
        Revolute and slider joints, drivers with the identity law (an angle in degrees, a slide in mm).
    tip_point : str, optional
        Named point whose path is the output.
    pads : Mapping, optional
        ``{body: {"point": name, "radius_mm": r}}`` fingertip pads.

    Raises
    ------
    SpecError
        ``mechanism.gears`` or a driver law this writer cannot express; the mechanism not assembling at
        its first input.
    """
    if mechanism.gears:
        raise SpecError("mechanism.gears", "gear couplings cannot be handed over as a linkage yet: "
                                           "declare the pair in a linkage template ([[linkage.gears]])")
    unit = mechanism.input_unit
    start = float(mechanism.input_range[0])
    poses = mechanism.solve(start)
    bodies = [{"name": b.name, "points": {p: _world(poses, b.name, b.point(p)) for p in b.points}}
              for b in mechanism.bodies]
    driven: dict[str, tuple[str, str]] = {}
    drivers = []
    for k, d in enumerate(mechanism.drivers):
        if not _identity(d, unit):
            raise SpecError(f"mechanism.drivers[{k}]", "only identity driver laws (the input itself, degrees "
                                                       "or mm) can be handed over as a linkage yet")
        if d.kind == "angle":
            joint = next((j for j in mechanism.joints if isinstance(j, Revolute)
                          and {j.body_a, j.body_b} == {d.body, d.reference}), None)
            if joint is None:
                raise SpecError(f"mechanism.drivers[{k}]", f"no revolute joint between {d.body!r} and "
                                                           f"{d.reference!r} to drive")
            driven[joint.name] = (d.reference, d.body)
        else:
            joint = next(j for j in mechanism.joints if j.name == d.joint)
        drivers.append({"joint": joint.name, "law": "linear", "reference": start})
    joints = []
    for j in mechanism.joints:
        entry: dict[str, Any] = {"name": j.name, "type": "revolute" if isinstance(j, Revolute) else "slider",
                                 "bodies": list(driven.get(j.name, (j.body_a, j.body_b)))}
        if isinstance(j, Slider):
            theta = float(poses[j.body_a][2])
            axis = rotation(theta) @ (np.asarray(j.axis, dtype=np.float64) / math.hypot(*j.axis))
            entry["axis"] = [float(axis[0]), float(axis[1])]
        joints.append(entry)
    table: dict[str, Any] = {"ground": mechanism.ground, "input_unit": unit,
                             "input_range": [start, float(mechanism.input_range[1])]}
    if tip_point:
        table["tip_point"] = tip_point
    table["bodies"] = bodies
    table["joints"] = joints
    table["drivers"] = drivers
    if pads:
        table["pads"] = [{"body": body, "point": str(p["point"]), "radius_mm": float(p["radius_mm"])}
                         for body, p in pads.items()]
    return table
