"""Resource bounds of a design: every count or tolerance that drives memory or time has a limit.

A template is checked field by field by the spec parsers (each field's own range uses the constants
here, so the documented limit and the enforced one are the same number). Where a single bound is not
enough, because the cost is a product of several fields, :func:`preflight` estimates the cost of the
validated design before any work starts and raises a :class:`~fabricate.errors.SpecError` naming the
field and the estimate.

The budget: the worst valid template of each kind (every bounded count at its maximum) builds within
:data:`TIME_BUDGET_S` seconds and :data:`MEMORY_BUDGET_MB` of peak resident memory on two cores
(``tests/benchmarks/bench_bounds.py`` measures it).

Magnitudes: lengths are bounded by :data:`MAX_LENGTH_MM` (no finger or gripper is a metre long, and a
length of 1e300 would overflow the kinematic mapping), forces and spring rates by
:data:`MAX_FORCE_N` / :data:`MAX_SPRING_RATE`.
"""

from __future__ import annotations

from typing import Any

from fabricate.errors import SpecError

#: Seconds the worst valid template of a kind may take (two cores).
TIME_BUDGET_S = 60.0
#: Peak resident memory (MB) the worst valid template of a kind may use.
MEMORY_BUDGET_MB = 4096.0

#: Largest length of any template dimension, mm (also coordinates and box limits).
MAX_LENGTH_MM = 1000.0
#: Largest force, N.
MAX_FORCE_N = 1.0e5
#: Largest spring rate, N·mm/deg.
MAX_SPRING_RATE = 1.0e4

#: ``process.chord_tolerance_mm``: the polygonisation sagitta; vertex counts grow as 1/sqrt(tol).
MIN_CHORD_TOLERANCE_MM = 0.001
#: ``checks.sweep_poses``: poses of the swept motion and the interference check.
MAX_SWEEP_POSES = 10000
#: ``gears.mesh_steps``: poses of the gear mesh check.
MAX_MESH_STEPS = 7200
#: ``gears.teeth`` / ``gear_pair.teeth``: teeth of one closed gear.
MAX_TEETH = 200
#: ``synthesis.kappa_samples`` (five-bar): samples of the hinge curves (a Python loop per sample).
MAX_KAPPA_SAMPLES = 10000
#: ``synthesis.curve_step_mm`` (five-bar): smallest refinement step of the hinge curves.
MIN_CURVE_STEP_MM = 0.01
#: ``region.step_mm`` (Watt six-bar): the x sampling of the Burmester curves, per box.
MAX_REGION_SAMPLES = 20000
#: ``region.statics_samples`` (Watt six-bar).
MAX_STATICS_SAMPLES = 2001
#: ``selection.refine_seeds`` (Watt six-bar): least-squares refinements started.
MAX_REFINE_SEEDS = 100000
#: ``push_rod.samples`` (underactuated): stroke samples of the closing motion.
MAX_STROKE_SAMPLES = 2001
#: ``optimisation.path_samples`` (compliant gripper).
MAX_PATH_SAMPLES = 5001
#: ``optimisation`` grid of the compliant gripper: points of one axis, and of the whole grid.
MAX_GRID_AXIS = 2001
MAX_GRID_POINTS = 1.0e12


def _estimate_sweep_mb(poses: int, samples: int) -> float:
    """Peak memory (MB) the pose-dependent arrays of a sweep need beyond the fixed part."""
    # 0.2 MB per pose was measured for the five-bar finger's interference sweep; the constant is the
    # slope of peak RSS against sweep_poses (360 -> 3600 poses: +660 MB)
    return 0.2 * poses + 0.0 * samples


def preflight(design: Any) -> None:
    """Estimate the cost of a validated design and refuse one that would exceed the budget.

    Parameters
    ----------
    design : fabricate.spec.DesignSpec

    Raises
    ------
    SpecError
        Naming the field that drives the estimate, the estimate and the largest value that fits.
    """
    method = design.method
    grid = getattr(method, "grid", None)
    if grid is not None:
        axes = [(name, len(getattr(grid, name))) for name in ("alpha", "c", "k1", "k2", "phi01", "phi02")]
        for name, count in axes:
            if count > MAX_GRID_AXIS:
                raise SpecError(f"optimisation.{_GRID_FIELDS[name]}",
                                f"{count} grid values, over the bound of {MAX_GRID_AXIS}; use a larger step")
        total = 1.0
        for _, count in axes:
            total *= count
        if total > MAX_GRID_POINTS:
            largest = max(axes, key=lambda item: item[1])[0]
            raise SpecError(f"optimisation.{_GRID_FIELDS[largest]}",
                            f"the grid has {total:.3g} points, over the bound of {MAX_GRID_POINTS:.0e}; "
                            "use a larger step on this axis")


_GRID_FIELDS = {"alpha": "alpha_deg", "c": "c_mm", "k1": "k1_Nmm_per_deg", "k2": "k2_Nmm_per_deg",
                "phi01": "phi01_deg", "phi02": "phi02_deg"}
