"""Template tables of the Watt-I six-bar finger (kind ``watt_six_bar``): ``[finger]``, ``[boxes]``, ``[region]``,
``[selection]`` and the optional ``[reference]`` -> a frozen :class:`WattSixBarSpec`, and the estimate of the
solution region's work (:func:`preflight`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fabricate.bounds import (
    MAX_FORCE_N,
    MAX_LENGTH_MM,
    MAX_REFINE_SEEDS,
    MAX_REGION_SAMPLES,
    MAX_REGION_WORK,
    MAX_STATICS_SAMPLES,
    MEMORY_BUDGET_MB,
    REGION_MB_PER_WORK,
)
from fabricate.errors import SpecError
from fabricate.synthesis.watt_six_bar.region import RegionInputs
from fabricate.table import Table

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec

BOX_NAMES = ("d0", "d", "e", "f")


@dataclass(frozen=True)
class WattSixBarSpec:
    """Validated inputs of the Watt-I six-bar synthesis (mm, degrees as in the template)."""

    phalanx_lengths_mm: tuple[float, float, float]
    angles_deg: tuple[tuple[float, ...], ...]  # (3, 4): theta1, theta2, theta3 at positions 1..4
    boxes: tuple[tuple[str, tuple[float, float, float, float]], ...]
    tip_pad_radius_mm: float = 5.0
    step_mm: float = 0.2
    k_max: float = 20.0
    force_N: float = 1.0
    statics_samples: int = 41
    tip_tolerance_mm: float = 0.5
    min_pin_to_middle_mm: float = 0.0
    rule: str = "nearest"
    target: tuple[float, float] | None = None
    branches: tuple[int, int] | None = None
    refine: bool = True
    refine_seeds: int = 600
    reference: tuple[tuple[str, tuple[float, float]], ...] = ()

    def box(self, name: str) -> np.ndarray:
        return np.asarray(dict(self.boxes)[name], dtype=np.float64)

    def region_inputs(self) -> RegionInputs:
        return RegionInputs(lengths=np.asarray(self.phalanx_lengths_mm, dtype=np.float64),
                            angles=np.radians(np.asarray(self.angles_deg, dtype=np.float64)),
                            box_d=self.box("d"), box_e=self.box("e"), box_f=self.box("f"),
                            box_d0=self.box("d0"), step=self.step_mm, force=self.force_N,
                            statics_samples=self.statics_samples, tip_tolerance=self.tip_tolerance_mm,
                            min_clearance=self.min_pin_to_middle_mm)


def parse_spec(root: Table) -> WattSixBarSpec:
    """Read ``[finger]``, ``[boxes]``, ``[region]``, ``[selection]`` and the optional ``[reference]``."""
    finger = root.table("finger")
    lengths = finger.array("phalanx_lengths_mm", shape=(3,), positive=True, max=MAX_LENGTH_MM)
    angles = [finger.array(f"theta{k}_deg", shape=(4,), min=-360.0, max=360.0) for k in (1, 2, 3)]
    pad = finger.number("tip_pad_radius_mm", 5.0, positive=True, max=50.0)
    finger.finish()
    steps = np.diff(angles[0])
    if not (np.all(steps > 0) or np.all(steps < 0)):
        raise SpecError(finger.field("theta1_deg"), "the input angle must change monotonically over the "
                                                    "positions (it drives the finger)")
    if np.max(np.abs(angles[0][-1] - angles[0][0])) >= 180.0:
        raise SpecError(finger.field("theta1_deg"), "the input must turn less than 180 degrees")
    # the distal phalanx must move relative to the proximal one between every two positions, or the
    # dyad condition is empty (every point would be a "solution")
    distal_rel = np.diff(angles[2] - angles[0])
    if np.any(np.abs(distal_rel) < 0.1):
        raise SpecError(finger.field("theta3_deg"), "the distal phalanx must turn relative to the proximal "
                                                    "one between consecutive positions")

    boxes_t = root.table("boxes")
    boxes = []
    for name in BOX_NAMES:
        box = boxes_t.array(name, shape=(4,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
        if not (box[0] < box[1] and box[2] < box[3]):
            raise SpecError(boxes_t.field(name), "expected [x_min, x_max, y_min, y_max] with min < max")
        boxes.append((name, (float(box[0]), float(box[1]), float(box[2]), float(box[3]))))
    boxes_t.finish()

    region = root.table("region", {})
    step = region.number("step_mm", 0.2, positive=True, max=10.0)
    k_max = region.number("k_max", 20.0, positive=True, max=1e6)
    force = region.number("force_N", 1.0, positive=True, max=MAX_FORCE_N)
    samples = region.integer("statics_samples", 41, min=3, max=MAX_STATICS_SAMPLES)
    tol = region.number("tip_tolerance_mm", 0.5, positive=True, max=50.0)
    clearance = region.number("min_pin_to_middle_mm", 0.0, min=0.0, max=100.0)
    region.finish()
    box_d = dict(boxes)["d"]
    box_d0 = dict(boxes)["d0"]
    for name, extent in (("d", box_d), ("d0", box_d0)):
        if (extent[1] - extent[0]) / step > MAX_REGION_SAMPLES:
            raise SpecError(region.field("step_mm"),
                            f"step too fine for the {name} box (over {MAX_REGION_SAMPLES} samples)")

    sel = root.table("selection", {})
    rule = sel.string("rule", "nearest", choices=("nearest", "least_k"))
    target = None
    if rule == "nearest":
        t = sel.array("target", shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
        target = (float(t[0]), float(t[1]))
    elif sel.has("target"):
        sel.array("target", shape=(2,))
    branches = None
    if sel.has("branches"):
        b = sel.array("branches", shape=(2,), min=1, max=3)
        if np.any(b != np.round(b)):
            raise SpecError(sel.field("branches"), "expected two whole numbers 1..3")
        branches = (int(b[0]), int(b[1]))
    refine = sel.boolean("refine", True)
    seeds = sel.integer("refine_seeds", 600, min=1, max=MAX_REFINE_SEEDS)
    sel.finish()

    reference: list[tuple[str, tuple[float, float]]] = []
    if root.has("reference"):
        ref = root.table("reference")
        for name in ("d", "e", "f", "d0"):
            p = ref.array(name, shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
            reference.append((name, (float(p[0]), float(p[1]))))
        ref.string("note", "")
        ref.finish()

    return WattSixBarSpec(
        phalanx_lengths_mm=(float(lengths[0]), float(lengths[1]), float(lengths[2])),
        angles_deg=tuple(tuple(float(v) for v in row) for row in angles),
        boxes=tuple(boxes), tip_pad_radius_mm=pad, step_mm=step, k_max=k_max, force_N=force,
        statics_samples=samples, tip_tolerance_mm=tol, min_pin_to_middle_mm=clearance, rule=rule, target=target,
        branches=branches,
        refine=refine, refine_seeds=seeds, reference=tuple(reference))


def preflight(design: DesignSpec) -> None:
    """Refuse a solution region whose d samples × d0 samples × statics samples is over
    :data:`~fabricate.bounds.MAX_REGION_WORK` (its memory grows with that product).

    Raises
    ------
    SpecError
        Naming ``region.statics_samples`` (or ``region.step_mm`` when even 3 statics samples do not fit), the
        estimate and the largest value that fits.
    """
    method = design.method
    counts = [int((box[1] - box[0]) / method.step_mm + 1e-9) + 1 for box in (method.box("d"), method.box("d0"))]
    work = float(counts[0] * counts[1] * method.statics_samples)
    if work > MAX_REGION_WORK:
        most = int(MAX_REGION_WORK / (counts[0] * counts[1]))
        fix = (f"at most {most} statics samples at this step" if most >= 3
               else "use a larger region.step_mm")
        raise SpecError("region.statics_samples" if most >= 3 else "region.step_mm",
                        f"{counts[0]} × {counts[1]} region samples × {method.statics_samples} statics samples "
                        f"= {work:.3g}, over the bound of {MAX_REGION_WORK:.0e} (about "
                        f"{REGION_MB_PER_WORK * work / 1024:.1f} GB estimated against "
                        f"{MEMORY_BUDGET_MB / 1024:.0f} GB); {fix}")
