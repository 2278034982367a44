"""Template tables of the compliant spring-hinge gripper (kind ``compliant_gripper``): ``[finger]``,
``[springs]``, ``[object]``, ``[optimisation]`` and ``[drive]`` -> a frozen :class:`CompliantSpec`, and the
estimate of its optimisation grid's work (:func:`preflight`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fabricate.bounds import (
    MAX_GRID_AXIS,
    MAX_GRID_POINTS,
    MAX_LENGTH_MM,
    MAX_PATH_SAMPLES,
    MAX_SPRING_RATE,
    MAX_SPRING_TABLE,
)
from fabricate.errors import SpecError
from fabricate.synthesis.compliant.grid_search import ParameterGrid
from fabricate.synthesis.compliant.model import GripperGeometry, Load, Springs
from fabricate.table import Table

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


@dataclass(frozen=True)
class CompliantSpec:
    """Validated template of the compliant gripper (mm, rad, N·mm/deg springs)."""

    geometry: GripperGeometry
    springs: Springs
    load: Load
    pad_arc: float
    grid: ParameterGrid | None
    min_hinge: float
    path_samples: int
    spring_legs: float
    overtravel: float
    fingers: int


def _grid_axis(table: Table, key: str, scale: float, lo: float, hi: float) -> np.ndarray:
    start, stop, step = table.array(key, shape=(3,), min=lo, max=hi)
    if step <= 0 or stop < start:
        raise SpecError(table.field(key), "expected [start, stop, step] with step > 0 and stop >= start")
    count = int(np.floor((stop - start) / step + 1e-9)) + 1
    if count > MAX_GRID_AXIS:  # checked before the axis is made (a step of 1e-300 would not fit memory)
        raise SpecError(table.field(key), f"{count} grid values, over the bound of {MAX_GRID_AXIS}; use a larger step")
    axis: np.ndarray = (start + step * np.arange(count)) * scale
    return axis


def parse_spec(root: Table) -> CompliantSpec:
    """Read ``[finger]``, ``[springs]``, ``[object]``, ``[optimisation]``, ``[drive]``."""
    f = root.table("finger")
    geom = GripperGeometry(
        a1=f.number("a1_mm", positive=True, max=MAX_LENGTH_MM), a2=f.number("a2_mm", positive=True, max=MAX_LENGTH_MM),
        a3=f.number("a3_mm", positive=True, max=MAX_LENGTH_MM), b=f.number("b_mm", min=0.0, max=MAX_LENGTH_MM),
        c=f.number("c_mm", min=0.0, max=MAX_LENGTH_MM),
        d=f.number("d_mm", positive=True, max=MAX_LENGTH_MM),
        l1=f.number("l1_mm", positive=True, max=MAX_LENGTH_MM),
        l2=f.number("l2_mm", positive=True, max=MAX_LENGTH_MM),
        r=f.number("pad_radius_mm", positive=True, max=MAX_LENGTH_MM),
        alpha=np.radians(f.number("alpha_deg", min=0.0, max=90.0)))
    pad_arc = np.radians(f.number("pad_arc_deg", 90.0, positive=True, max=180.0))
    f.finish()
    s = root.table("springs")
    springs = Springs(k1=s.number("k1_Nmm_per_deg", min=0.0, max=MAX_SPRING_RATE),
                      k2=s.number("k2_Nmm_per_deg", min=0.0, max=MAX_SPRING_RATE),
                      phi01=s.number("phi01_rad", min=0.0, max=2 * np.pi),
                      phi02=s.number("phi02_rad", min=0.0, max=2 * np.pi))
    legs = s.number("legs_mm", 20.0, positive=True, max=MAX_LENGTH_MM)
    s.finish()
    o = root.table("object")
    load = Load(diameter=o.number("diameter_mm", positive=True, max=MAX_LENGTH_MM),
                mass=o.number("mass_kg", positive=True, max=1000.0),
                mu=o.number("friction", positive=True, max=2.0), safety=o.number("safety", positive=True, max=100.0),
                g=o.number("gravity", 9.8, positive=True, max=100.0))
    o.finish()
    opt = root.table("optimisation", {})
    enabled = opt.boolean("enabled", True)
    grid = None
    if opt.has("alpha_deg") or enabled:
        grid = ParameterGrid(
            alpha=_grid_axis(opt, "alpha_deg", np.pi / 180.0, 0.0, 90.0),
            c=_grid_axis(opt, "c_mm", 1.0, 0.0, 500.0),
            k1=_grid_axis(opt, "k1_Nmm_per_deg", 1.0, 0.0, 1e4),
            k2=_grid_axis(opt, "k2_Nmm_per_deg", 1.0, 0.0, 1e4),
            phi01=_grid_axis(opt, "phi01_deg", np.pi / 180.0, 0.0, 360.0),
            phi02=_grid_axis(opt, "phi02_deg", np.pi / 180.0, 0.0, 360.0))
    if not enabled:
        grid = None
    min_hinge = np.radians(opt.number("min_hinge_deg", 5.0, min=0.0, max=45.0))
    samples = opt.integer("path_samples", 181, min=31, max=MAX_PATH_SAMPLES)
    opt.finish()
    dr = root.table("drive", {})
    overtravel = dr.number("overtravel_mm", 1.0, min=0.0, max=MAX_LENGTH_MM)
    fingers = dr.integer("fingers", 3, min=1, max=12)
    dr.finish()
    return CompliantSpec(geom, springs, load, pad_arc, grid, min_hinge, samples, legs, overtravel, fingers)


#: The grid's axes (:class:`~fabricate.synthesis.compliant.grid_search.ParameterGrid` fields) and their
#: ``[optimisation]`` keys.
_GRID_FIELDS = {"alpha": "alpha_deg", "c": "c_mm", "k1": "k1_Nmm_per_deg", "k2": "k2_Nmm_per_deg",
                "phi01": "phi01_deg", "phi02": "phi02_deg"}


def preflight(design: DesignSpec) -> None:
    """Refuse an optimisation grid over :data:`~fabricate.bounds.MAX_GRID_POINTS` points, or whose spring
    table (k1 × k2 × phi01 values × path samples, what the certified search tabulates) is over
    :data:`~fabricate.bounds.MAX_SPRING_TABLE`.

    Raises
    ------
    SpecError
        Naming the ``optimisation`` field that drives the estimate, the estimate and what fits.
    """
    method = design.method
    grid = method.grid
    if grid is None:
        return
    axes = [(name, len(getattr(grid, name))) for name in _GRID_FIELDS]
    total = 1.0
    for _, count in axes:
        total *= count
    if total > MAX_GRID_POINTS:
        largest = max(axes, key=lambda item: item[1])[0]
        raise SpecError(f"optimisation.{_GRID_FIELDS[largest]}",
                        f"the grid has {total:.3g} points, over the bound of {MAX_GRID_POINTS:.0e}; "
                        "use a larger step on this axis")
    # the certified search tabulates every (k1, k2, phi01) triple along each contact path
    triples = len(grid.k1) * len(grid.k2) * len(grid.phi01)
    work = float(triples) * method.path_samples
    if work > MAX_SPRING_TABLE:
        raise SpecError("optimisation.path_samples" if triples * 31 <= MAX_SPRING_TABLE
                        else "optimisation.k1_Nmm_per_deg",
                        f"{len(grid.k1)} × {len(grid.k2)} × {len(grid.phi01)} spring triples × "
                        f"{method.path_samples} path samples = {work:.3g}, over the bound of "
                        f"{MAX_SPRING_TABLE:.0e}; at most {int(MAX_SPRING_TABLE // triples)} path samples "
                        "with these axes, or larger steps on k1, k2, phi01")
