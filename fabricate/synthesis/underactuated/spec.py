"""Template tables of the underactuated stacked four-bar finger (kind ``underactuated``): ``[finger]``,
``[transmission]``, ``[push_rod]``, ``[springs]`` and ``[object]`` -> a frozen :class:`UnderactuatedSpec`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fabricate.bounds import MAX_FORCE_N, MAX_LENGTH_MM, MAX_SPRING_RATE, MAX_STROKE_SAMPLES
from fabricate.errors import SpecError
from fabricate.synthesis.underactuated.model import FingerDesign
from fabricate.table import Table

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


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


def preflight(design: DesignSpec) -> None:
    """Nothing to estimate: no product of this kind's counts is bounded beyond its fields.

    The closing motion's work grows with the phalanges (at most :data:`MAX_PHALANGES`) and the stroke samples
    (``push_rod.samples``, at most :data:`~fabricate.bounds.MAX_STROKE_SAMPLES`), each bounded by its parser.
    """
