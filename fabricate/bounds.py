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

#: ``process.chord_tolerance_mm``: the polygonisation sagitta; vertex counts grow as 1/sqrt(tol), and the
#: STEP export's shape fixing works to a tenth of it (100-tooth gears at 0.001 mm: 65 s of STEP alone).
MIN_CHORD_TOLERANCE_MM = 0.002
#: ``checks.sweep_poses``: poses of the swept motion and the interference check.
MAX_SWEEP_POSES = 5000
#: ``gears.mesh_steps``: poses of the gear mesh check.
MAX_MESH_STEPS = 7200
#: ``gears.teeth`` / ``gear_pair.teeth`` and the teeth a module gives: teeth of one gear (cost grows
#: faster than linearly: 200 + 200 teeth built in 15 s, 400 + 400 in 98 s; the STEP export of a
#: 200 + 200 pair at the finest chord tolerance took minutes).
MAX_TEETH = 100
#: ``gears.mesh_steps`` × (z_a + z_b): the mesh check's work (7200 steps of a 30 + 30 pair took ~15 s;
#: 100 + 100 teeth at 1500 steps, 30 + 30 at 5000).
MAX_MESH_STEP_TEETH = 300_000
#: Gear pair kind: ``checks.sweep_poses`` × (z_a + z_b) (posing, layering and the interference sweep of
#: the toothed outlines; 5000 poses × 400 teeth spent 70 s in the parts stage alone).
MAX_POSE_TEETH = 150_000
#: Gear pair kind: ``parts.gif_frames`` × (z_a + z_b) (each frame draws both toothed outlines).
MAX_FRAME_TEETH = 12_000
#: Measured seconds per step and tooth of the mesh check (for the estimate in messages).
MESH_SECONDS_PER_TOOTH_STEP = 3.5e-5
#: ``synthesis.kappa_samples`` (five-bar): samples of the hinge curves (a Python loop per sample).
MAX_KAPPA_SAMPLES = 5000
#: ``synthesis.curve_step_mm`` (five-bar): smallest refinement step of the hinge curves.
MIN_CURVE_STEP_MM = 0.01
#: ``region.step_mm`` (Watt six-bar): the x sampling of the Burmester curves, per box.
MAX_REGION_SAMPLES = 20000
#: Watt six-bar region work: d samples × d0 samples × statics samples (the shipped template is 8.3e5;
#: 4.1e6 took 8 s and 0.4 GB of synthesis, 4.1e7 over 100 s and 2 GB).
MAX_REGION_WORK = 8.0e6
#: Measured MB of peak memory per unit of region work (0.4 GB at 4.1e6).
REGION_MB_PER_WORK = 1.0e-4
#: ``region.statics_samples`` (Watt six-bar).
MAX_STATICS_SAMPLES = 2001
#: ``selection.refine_seeds`` (Watt six-bar): least-squares refinements started (100000 took 17 s
#: of synthesis; the worst Watt template at 100000 used 45 s of CPU in all).
MAX_REFINE_SEEDS = 10000
#: Declared linkage (``kind = "linkage"``): bodies, joints, gear pairs, drivers and points of one body. The
#: solver's Newton step is a dense solve in 3 × bodies unknowns per pose (40 bodies: 117 unknowns, well
#: under a millisecond), and the layer conflict test compares every pair of bodies over the motion.
MAX_LINKAGE_BODIES = 40
MAX_LINKAGE_JOINTS = 80
MAX_LINKAGE_GEARS = 8
MAX_LINKAGE_DRIVERS = 8
MAX_LINKAGE_POINTS = 32
#: Samples of one sampled law of a declared linkage (gear law or driver table).
MAX_LINKAGE_TABLE = 10000
#: ``push_rod.samples`` (underactuated): stroke samples of the closing motion.
MAX_STROKE_SAMPLES = 2001
#: ``optimisation.path_samples`` (compliant gripper).
MAX_PATH_SAMPLES = 5001
#: ``optimisation`` grid of the compliant gripper: points of one axis, and of the whole grid.
MAX_GRID_AXIS = 2001
MAX_GRID_POINTS = 1.0e12
#: k1 × k2 × phi01 values × path samples tabulated by the certified search (1.6e8 took 4.5 s and
#: 0.36 GB in all).
MAX_SPRING_TABLE = 2.0e8


def preflight(design: Any) -> None:
    """Estimate the cost of a validated design and refuse one that would exceed the budget.

    Products of counts that the field bounds alone do not cap:

    - compliant gripper: the optimisation grid (points per axis and in all);
    - Watt six-bar: the solution region's d samples × d0 samples × statics samples;
    - gear pair: sweep poses and GIF frames × teeth.

    (The gear mesh check's steps × teeth is refused where the tooth counts are known, in
    :mod:`fabricate.gears.pair`.)

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
    if design.kind == "gear_pair":
        _gear_pair_work(design)
    if design.kind == "watt_six_bar":
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


def _gear_pair_work(design: Any) -> None:
    """Poses and picture frames × teeth of a standalone gear pair (its outlines dominate every stage)."""
    teeth = design.gears.teeth or getattr(design.method, "teeth", None)
    # without tooth counts the module decides them after synthesis: assume the most teeth allowed
    total = sum(teeth) if teeth else 2 * MAX_TEETH
    for field, count, bound, what in (
            ("checks.sweep_poses", design.checks.sweep_poses, MAX_POSE_TEETH, "poses"),
            ("parts.gif_frames", design.parts.gif_frames, MAX_FRAME_TEETH, "GIF frames")):
        if count * total > bound:
            raise SpecError(field, f"{count} {what} × {total} teeth = {count * total}, over the bound of {bound} "
                                   f"(every pose moves both toothed outlines); at most {max(1, bound // total)} "
                                   f"{what} with {total} teeth")


_GRID_FIELDS = {"alpha": "alpha_deg", "c": "c_mm", "k1": "k1_Nmm_per_deg", "k2": "k2_Nmm_per_deg",
                "phi01": "phi01_deg", "phi02": "phi02_deg"}
