"""Resource bounds of a design: every count or tolerance that drives memory or time has a limit.

A template is checked field by field by the spec parsers (each field's own range uses the constants
here, so the documented limit and the enforced one are the same number). Where a single bound is not
enough, because the cost is a product of several fields, the kind's own ``preflight`` (see
:mod:`fabricate.kinds`) estimates the cost of the validated design before any work starts, with the
constants here, and raises a :class:`~fabricate.errors.SpecError` naming the field and the estimate.

The budget: the worst valid template of each kind (every bounded count at its maximum) builds within
:data:`TIME_BUDGET_S` seconds and :data:`MEMORY_BUDGET_MB` of peak resident memory on two cores
(``tests/benchmarks/bench_bounds.py`` measures it).

Magnitudes: lengths are bounded by :data:`MAX_LENGTH_MM` (no finger or gripper is a metre long, and a
length of 1e300 would overflow the kinematic mapping), forces and spring rates by
:data:`MAX_FORCE_N` / :data:`MAX_SPRING_RATE`.
"""

from __future__ import annotations

import ast
import contextlib
import ctypes
import gc
import os
import sys
from collections.abc import Iterator
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
#: ``checks.sweep_poses``: poses of the swept motion, the interference check and the strength statics. Their memory
#: is flat in the poses (the posed outlines and the gear contact's nearest vertices go a chunk of poses at a time:
#: the default finger's interference proof peaked at 145 MB at 360 poses and 155 MB at 5000, its strength check at
#: 159 and 179 MB; ``bench_bounds.py --poses-memory``), so time bounds them. CPU seconds of each kind's worst
#: template (every other count at its bound, one BLAS thread) at 5000 and 10000 poses: underactuated finger 29.7
#: and 53.8 s (4.8 ms a pose: the worst kind), compliant gripper 20.0 and 39.6, Watt six-bar 28.8 and 32.0, five-bar
#: 23.2 and 28.7 (measured on two cores shared with other work, load 8-13: the wall times were 1.3-2x these).
MAX_SWEEP_POSES = 10000
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
#: the toothed outlines; 5000 poses × 400 teeth spent 70 s in the parts stage alone; the fewest teeth the shipped
#: pair's module cuts, 9 + 9, at 8333 poses: 8.5 s of CPU in all).
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
#: Samples of one sampled law of a declared linkage (gear law or driver table), and of all of them together: a
#: build writes each as piecewise-polynomial coefficients into its ``mechanism.toml`` (~120 bytes a sample:
#: 10000 samples wrote 1.2 MB, over ``fabricate.spec.MAX_TEMPLATE_BYTES``, so the rebuild of a valid build
#: was refused); 4000 in all keeps the exact form of any valid linkage within that size (measured by
#: ``tests/test_bounds.py::test_the_exact_form_of_the_largest_tables_is_a_valid_template``).
MAX_LINKAGE_TABLE = 4000
#: Exact form (``[linkage] exact = true``, a build's ``mechanism.toml``): ``hints.copies``, identical copies of
#: the mechanism made (every copy of every part is laid out on the plates; 2000 copies took 62 s). The compliant
#: gripper, the only kind that writes copies, makes at most 12 fingers.
MAX_COPIES = 12
#: Exact form: breakpoints of a ``ppoly`` law or samples of a ``samples`` law (a build writes at most
#: :data:`MAX_LINKAGE_TABLE` breakpoints of a template's table, 5001 of the compliant gripper's path and 2001
#: samples of a law it cannot write exactly).
MAX_EXACT_LAW_POINTS = 10001
#: Exact form: coefficients of one ``ppoly`` piece (a cubic spline has 4).
MAX_EXACT_LAW_ORDER = 8
#: Characters of a gear law expression: ``linkage.gears[].expression`` and ``gear_pair.law``. A formula is
#: evaluated node by node in Python at every solver step, twice (value and slope) per gear: a 49 kB
#: ``gear_pair.law`` took 108 s, and 8 linkage gears of 1000 characters cost 4.2 ms per Jacobian against
#: 0.55 ms with constant ratios (so their product with the poses is bounded too, by the linkage's preflight).
MAX_EXPRESSION_LENGTH = 1000
#: Nesting depth of a gear law expression's syntax tree. Compiling and evaluating it takes one Python frame a
#: level: 998 unary minus signs overflowed the interpreter's stack (1000 frames); a sum of n terms is n deep.
MAX_EXPRESSION_DEPTH = 100
#: Linkage solver (both forms of kind ``linkage``): CPU seconds of one Jacobian of the worst linkage (40
#: bodies, one BLAS thread), and what each slider, gear pair, driver and character of a gear expression adds
#: (Python rows; a formula is evaluated node by node, value and slope). Measured: 0.55 ms with 6 sliders and
#: 8 constant-ratio gears, 1.4 ms with 18 sliders, 4.2 ms with 8 gear expressions of 1000 characters (whose
#: sweep of 648 poses then took 13.4 s: the character cost is set from that sweep).
SOLVER_JACOBIAN_S = 1.2e-4
SOLVER_SLIDER_S = 7.0e-5
SOLVER_GEAR_S = 2.0e-5
SOLVER_DRIVER_S = 3.0e-5
SOLVER_EXPRESSION_CHAR_S = 6.5e-7
#: Jacobians per continuation step (the tangent, the corrector's one or two iterations and the check; a step
#: per pose above 360 poses, 360 steps below).
SOLVER_JACOBIANS_PER_STEP = 3.5
#: CPU seconds the linkage's sweep may be estimated to take (the rest of the budget is parts and checks).
MAX_SOLVER_S = 10.0
#: Linkage kind: ``checks.sweep_poses`` × bodies. The interference sweep and the statics go through every pose
#: of every part: 40 bodies at 5000 poses took 99 s of CPU (one BLAS thread): checks 54 s (the interference
#: sweep's clearance tests), the sweep 20 s, strength 16 s, exports 5 s, parts 6 s; at 2000 poses (15 sliders,
#: 2 gear pairs of 37 + 37 teeth) 59 s of CPU, 49 s wall; at the bound (1500 poses, 15 sliders, 2 pairs of
#: 13 + 13 teeth) 52 s of CPU with the picture child, 56 s wall on cores shared with other work; its exact form
#: with 12 copies 59 s of CPU, 53 s wall. Few bodies reach :data:`MAX_SWEEP_POSES`: the shipped Stephenson six-bar
#: (6 bodies) at 10000 poses took 14.8 s of CPU.
MAX_LINKAGE_POSE_BODIES = 60_000
#: Linkage kind: characters of all its gear expressions together. Each is evaluated at every solver step and
#: throughout gear cutting: 8 expressions of 1000 characters took 13 s of solving (648 poses) and 10 s of
#: cutting 8 pairs of 12 + 12 teeth.
MAX_LINKAGE_EXPRESSION_CHARS = 2 * MAX_EXPRESSION_LENGTH
#: Linkage kind: teeth of all its gear pairs together (z_a + z_b summed). 8 pairs of 100 + 100 teeth spent 21 s
#: cutting gears and 16 s laying out parts at 360 poses; 8 pairs of 12 + 12 at 781 poses took 69 s of CPU in
#: all, 16 s of it the STEP export of the toothed parts at the finest chord tolerance.
MAX_LINKAGE_GEAR_TEETH = 100
#: Linkage kind: ``checks.sweep_poses`` × the teeth of all its gear pairs (every pose moves every toothed
#: outline through the layer and interference sweeps, among up to 40 bodies): 1408 poses × 192 teeth (8 pairs,
#: 40 bodies) took 62 s wall, 19 s of it in the checks.
MAX_LINKAGE_POSE_TEETH = 80_000
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


def check_expression(text: str, path: str) -> None:
    """Refuse a gear law expression longer or deeper than the bounds, before it is compiled.

    Parameters
    ----------
    text : str
        The formula as written.
    path : str
        The field (``gear_pair.law``, ``linkage.gears[2].expression``) named in the error.

    Raises
    ------
    SpecError
        Over :data:`MAX_EXPRESSION_LENGTH` characters or :data:`MAX_EXPRESSION_DEPTH` levels of nesting. A
        syntax error is left to the formula compiler, which names it.
    """
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise SpecError(path, f"the expression has {len(text)} characters, over the bound of "
                              f"{MAX_EXPRESSION_LENGTH} (it is evaluated at every step of the motion)")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        return
    except (RecursionError, MemoryError):  # the parser's own stack: deeper than any bound below
        raise SpecError(path, f"the expression is nested too deeply (at most {MAX_EXPRESSION_DEPTH} levels)") from None
    # the depth by an explicit stack: a recursive walk would overflow on the input it is meant to refuse
    deepest = 0
    stack: list[tuple[ast.AST, int]] = [(tree.body, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        if deepest > MAX_EXPRESSION_DEPTH:
            raise SpecError(path, f"the expression is nested more than {MAX_EXPRESSION_DEPTH} levels deep "
                                  "(each unary sign, operator and call is a level; a sum of n terms is n deep)")
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


# -- processes and threads -------------------------------------------------------------------------

#: Peak resident memory (MB) of one local Dask worker process of ``fabricate sweep``: its imports, the builds it
#: runs and the stage results it keeps for its later points (idle, a worker holds about 75 MB; building the
#: shipped Stephenson six-bar at 90 to 720 poses each of two workers peaked at 474 MB; the kept results are bounded
#: by the in-process cache layer's 256 MB, ``fabricate.cache.MEMORY_MAX_BYTES``; the shipped hand-size sweep's
#: largest process peaked at 577 MB). ``--workers`` is bounded by the available memory divided by it.
WORKER_MB = 750.0
def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the platform has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # macOS, Windows
        return max(1, os.cpu_count() or 1)


def available_memory_mb() -> float | None:
    """``MemAvailable`` of ``/proc/meminfo`` in MB (memory that can be had without swapping), or None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) / 1024.0
    except (OSError, ValueError, IndexError):
        pass
    return None


def max_workers() -> int:
    """Most local sweep worker processes: one per core, and no more than the available memory holds.

    Each worker is a single-threaded process (a point is CPU-bound Python), so more workers than cores only
    wait for each other; each costs :data:`WORKER_MB` of memory.
    """
    cores = available_cores()
    memory = available_memory_mb()
    if memory is None:
        return cores
    return max(1, min(cores, int(memory // WORKER_MB)))


def check_workers(workers: int, field: str = "--workers") -> None:
    """Refuse a local worker count outside ``1 .. max_workers()``, naming the limit that binds.

    Raises
    ------
    SpecError
        Naming ``field``, the cores and the memory available.
    """
    if isinstance(workers, bool) or not isinstance(workers, int):
        raise SpecError(field, f"expected a whole number of processes, got {workers!r}")
    limit = max_workers()
    if 1 <= workers <= limit:
        return
    cores, memory = available_cores(), available_memory_mb()
    held = "" if memory is None else f", {memory / 1024:.1f} GB available at {WORKER_MB:.0f} MB a worker holds " \
                                      f"{max(1, int(memory // WORKER_MB))}"
    raise SpecError(field, f"expected 1 .. {limit} processes, got {workers} (this machine: {cores} "
                           f"core{'s' if cores != 1 else ''}{held})")


@contextlib.contextmanager
def blas_threads(count: int = 1) -> Iterator[None]:
    """Run the block (or, as a decorator, the function) with at most ``count`` threads in every OpenBLAS
    loaded (numpy's, scipy's), then restore the counts.

    fabricate's matrices are small (the solver's are at most 117 × 117, the statics' as large): a second
    BLAS thread saves nothing, and on busy cores OpenBLAS's threads wait for each other. A 117 × 117 solve
    took 8.5 ms instead of 0.1 ms, so the worst linkage's sweep of 360 poses took 42 s instead of 2 s, and a
    whole build with two threads 159 s of CPU instead of 54. The pin holds whatever the environment asks
    (``OPENBLAS_NUM_THREADS``): nothing fabricate runs is faster with more.

    Does nothing where no OpenBLAS is loaded or the platform does not list the libraries (only Linux's
    ``/proc/self/maps`` is read). A process forked inside the block inherits the pin.
    """
    restore = []
    for get, put in _openblas_controls():
        try:
            before = int(get())
            if before > count:
                put(count)
                restore.append((put, before))
        except (OSError, ValueError):  # a library that does not answer is left as it is
            continue
    try:
        yield
    finally:
        for put, before in restore:
            put(before)


#: The cyclic garbage collector's thresholds during a build (:func:`rare_collections`): a young collection
#: every 10 000 allocations instead of Python's 700, an older one every 20 of those.
BUILD_GC_THRESHOLDS = (10_000, 20, 20)


@contextlib.contextmanager
def rare_collections(thresholds: tuple[int, int, int] = BUILD_GC_THRESHOLDS) -> Iterator[None]:
    """Run the block (or, as a decorator, the function) with the cyclic garbage collector's ``thresholds``,
    then restore the caller's.

    A build allocates millions of short-lived small objects (numpy scalars, shapely geometries, dict rows)
    while matplotlib, ezdxf and scipy hold hundreds of thousands of long-lived ones: with Python's default
    thresholds the default finger's serial build ran 464 collections, the full ones walking every live
    object, 0.285 s of CPU; with these, 29 collections and 0.083 s, for ~12 MB more peak memory. Reference
    counting still frees everything that is not in a cycle at once; the collector only runs less often.
    Results never depend on it (builds are byte-identical either way).
    """
    before = gc.get_threshold()
    gc.set_threshold(*thresholds)
    try:
        yield
    finally:
        gc.set_threshold(*before)


#: glibc malloc thresholds for a build's own process (``mallopt``; the codes from glibc's ``<malloc.h>``): freed
#: memory is handed back to the system only past 64 MB at the heap's top, and blocks up to 32 MB (glibc's largest
#: allowed) come from the heap instead of their own mmap. glibc's defaults (128 kB, adjusted upwards as large
#: blocks are freed) gave the default finger's build ~86k page faults, the gear mesh check's chunked arrays
#: mapped, unmapped and faulted in again chunk after chunk: with these, ~37k, the gears stage 0.24 -> 0.17 s and
#: the checks 0.27 -> 0.23 s of CPU, the same peak memory (helper measurement, 5 paired builds).
#: Each as glibc's environment variable (for a process about to start) -> (its ``mallopt`` code, bytes).
ROOMY_HEAP = {"MALLOC_TRIM_THRESHOLD_": (-1, 64 << 20), "MALLOC_MMAP_THRESHOLD_": (-3, 32 << 20)}


def roomy_heap_environ() -> dict[str, str]:
    """:data:`ROOMY_HEAP` as environment variables, for processes fabricate starts (the sweep's local workers)."""
    return {name: str(size) for name, (_, size) in ROOMY_HEAP.items()}


def roomy_heap() -> bool:
    """Set :data:`ROOMY_HEAP` in this process (glibc only; elsewhere nothing happens); whether every one was taken.

    Process-wide and not restorable (glibc has no getter), so only a process fabricate owns calls it: the command
    line's ``build`` and ``synth``, never the API in a caller's process. Results never depend on it.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # no mallopt in this C library
        return False
    return all(mallopt(code, size) == 1 for code, size in ROOMY_HEAP.values())


def _openblas_controls() -> list[tuple[Any, Any]]:
    """``(get_num_threads, set_num_threads)`` of every OpenBLAS mapped into this process (Linux)."""
    if "numpy" not in sys.modules or not sys.platform.startswith("linux"):
        return []
    cache = _OPENBLAS.get("controls")
    if cache is not None:
        return cache
    paths: list[str] = []
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as f:
            for line in f:
                fields = line.split(maxsplit=5)  # address, perms, offset, device, inode, path
                path = fields[5].strip() if len(fields) == 6 else ""
                if "openblas" in path.lower() and path.startswith("/") and path not in paths:
                    paths.append(path)
    except OSError:
        return []
    controls = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for prefix, suffix in (("scipy_openblas", "64_"), ("scipy_openblas", ""), ("openblas", "64_"),
                               ("openblas", "")):
            get = getattr(lib, f"{prefix}_get_num_threads{suffix}", None)
            put = getattr(lib, f"{prefix}_set_num_threads{suffix}", None)
            if get is not None and put is not None:
                put.argtypes = [ctypes.c_int]
                controls.append((get, put))
                break
    _OPENBLAS["controls"] = controls
    return controls


_OPENBLAS: dict[str, list[tuple[Any, Any]]] = {}
