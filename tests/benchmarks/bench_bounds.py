"""Worst valid template of each kind against the resource budget of :mod:`fabricate.bounds`.

Each shipped template is turned into its most expensive valid form (every bounded count at its
maximum, products of counts at the preflight bound); the declared linkage and its exact form (the
``mechanism.toml`` every build writes) are generated (:func:`worst_linkage`, :func:`worst_exact`). Each is
built by ``python -m fabricate build T -o DIR -q`` in a subprocess of its own wrapper process, so the
wrapper's ``RUSAGE_CHILDREN`` peak is that build's alone. Prints: kind, BLAS threads, wall time, CPU time
(user + sys of the build and its forked picture child, from ``resource.getrusage``: on a shared machine the
wall time also counts waiting for a core, so CPU time is the figure to hold against the budget there), peak
RSS, exit code and the ratios to the 60 s / 4 GB budget.

``--blas 1`` runs with the BLAS libraries' environment set to one thread (``OPENBLAS_NUM_THREADS=1``), ``--blas 2``
with two (fabricate pins OpenBLAS to one thread where it solves, :func:`fabricate.bounds.blas_threads`, so this
shows what is left unpinned), ``--blas both`` (default) each kind both ways.

``--poses N`` sets ``checks.sweep_poses`` of the kinds that take the generic bound (default
:data:`fabricate.bounds.MAX_SWEEP_POSES`): two runs at two counts give each kind's cost per pose. ``gear_pair_poses``
and ``linkage_poses_few`` are the most poses the products with the teeth and the bodies allow (the fewest teeth, the
shipped six-bar's six bodies).

``--poses-memory [template ...]`` (Linux) is the memory figure of the chunked sweeps instead: each stage that goes
through every pose, run at 360 and at the most poses in its own process, its peak resident memory and the ratio
(:func:`poses_memory`).

Run: ``python tests/benchmarks/bench_bounds.py [--blas 1|2|both] [--poses N] [kind ...]`` (not part of the test
suite; about ten minutes on an idle machine).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository: tests/ helpers

from fabricate import bounds  # noqa: E402
from fabricate.templates import TEMPLATE_DIR, parse_toml  # noqa: E402
from tests.toml_writer import toml_text  # noqa: E402

#: Environment variables that set the thread count of the BLAS libraries numpy and scipy may load.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
                         "OMP_NUM_THREADS")

#: Wrapper run in its own process: times one build and reads its peak RSS (kB on Linux).
WRAPPER = """
import json, resource, subprocess, sys, time
start = time.perf_counter()
rc = subprocess.run([sys.executable, "-m", "fabricate", "build", sys.argv[1], "-o", sys.argv[2], "-q"],
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
elapsed = time.perf_counter() - start
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"rc": rc.returncode, "stderr": rc.stderr.decode(errors="replace"), "seconds": elapsed,
                  "cpu_seconds": usage.ru_utime + usage.ru_stime,
                  "peak_mb": usage.ru_maxrss / 1024.0}))
"""

_GENERIC = {
    ("process", "chord_tolerance_mm"): bounds.MIN_CHORD_TOLERANCE_MM,
    ("checks", "sweep_poses"): bounds.MAX_SWEEP_POSES,
    ("parts", "gif_frames"): 360,
    ("parts", "preview_poses"): 24,
}

#: Template and the kind's own counts at their maxima (products at the preflight bound).
WORST: dict[str, tuple[str, dict[tuple[str, str], Any]]] = {
    "five_bar_ncg": ("finger_five_bar_ncg.toml", {
        ("synthesis", "kappa_samples"): bounds.MAX_KAPPA_SAMPLES,
        ("synthesis", "curve_step_mm"): bounds.MIN_CURVE_STEP_MM,
        # spare_teeth 16 and 20 make the sectors span a full turn (refused, naming gears.<pair>.closed);
        # 10 gives 52-53 teeth in all: mesh steps at the steps × teeth bound (with a little margin)
        ("gears", "spare_teeth"): 10,
        ("gears", "mesh_steps"): bounds.MAX_MESH_STEP_TEETH // 54,
    }),
    "gear_pair": ("gear_pair_elliptic.toml", {
        ("gears", "teeth"): [bounds.MAX_TEETH, bounds.MAX_TEETH],
        ("gears", "mesh_steps"): max(720, bounds.MAX_MESH_STEP_TEETH // (2 * bounds.MAX_TEETH)),
        # poses and GIF frames at their products with the teeth (preflight)
        ("checks", "sweep_poses"): bounds.MAX_POSE_TEETH // (2 * bounds.MAX_TEETH),
        ("parts", "gif_frames"): bounds.MAX_FRAME_TEETH // (2 * bounds.MAX_TEETH),
    }),
    "watt_six_bar": ("finger_watt_six_bar.toml", {
        # 201 x 101 region samples at the shipped 0.2 mm step: statics samples up to the region bound
        ("region", "statics_samples"): int(bounds.MAX_REGION_WORK // (201 * 101)),
        ("selection", "refine_seeds"): bounds.MAX_REFINE_SEEDS,
    }),
    "underactuated": ("finger_underactuated.toml", {
        ("push_rod", "samples"): bounds.MAX_STROKE_SAMPLES,
    }),
    # the most poses the products with the teeth and the bodies allow: the fewest teeth of a gear pair that still
    # make a closed elliptic pair of whole teeth, and the shipped Stephenson six-bar (6 bodies)
    "gear_pair_poses": ("gear_pair_elliptic.toml", {
        # 8 + 8 (gears.min_teeth) is refused at the template's module: the ellipse's flattest curvature holds 7.8
        ("gears", "teeth"): [9, 9],
        ("checks", "sweep_poses"): min(bounds.MAX_SWEEP_POSES, bounds.MAX_POSE_TEETH // 18),
    }),
    "linkage_poses_few": ("linkage_stephenson.toml", {
        ("checks", "sweep_poses"): min(bounds.MAX_SWEEP_POSES, bounds.MAX_LINKAGE_POSE_BODIES // 6),
    }),
    "compliant_gripper": ("gripper_compliant.toml", {
        # the shipped 31 x 31 x 91 spring triples: path samples up to the spring-table bound
        ("optimisation", "path_samples"): min(bounds.MAX_PATH_SAMPLES,
                                              int(bounds.MAX_SPRING_TABLE // (31 * 31 * 91))),
        ("drive", "fingers"): 12,
    }),
}


def _expression(length: int) -> str:
    """A closed gear law of ``length`` characters: the 1:1 law plus tiny harmonics (so the pitch curves stay
    round and the teeth cut), y(0) = 0 and repeating after a turn."""
    text, k = "x", 1
    while True:
        term = f" + 1e-09*sin({k}*x)"
        if len(text) + len(term) > length:
            break
        text, k = text + term, k + 1
    return text + " " * (length - len(text))


def worst_linkage(poses: int = bounds.MAX_SWEEP_POSES, points: int = bounds.MAX_LINKAGE_POINTS,
                  gears: int = bounds.MAX_LINKAGE_GEARS, teeth: int = 12,
                  expression: int = bounds.MAX_EXPRESSION_LENGTH, sliders: int = 6,
                  table: int = bounds.MAX_LINKAGE_TABLE) -> dict[str, Any]:
    """A worst-case declared linkage, as a parsed template (the two worst: :func:`linkage_poses`,
    :func:`linkage_gears`).

    A crank-rocker four-bar drives a chain of stages that all assemble and move without a dead point:
    ``gears`` gear stages (the rotating body drives a gear on the frame through a closed pair of
    ``teeth`` + ``teeth`` teeth whose law is an expression of ``expression`` characters), each followed by a
    parallelogram stage (coupler and rocker: the rocker turns as the gear does), more parallelogram stages,
    then ``sliders`` slider stages (a rod to a block on a slide, block to block), up to
    :data:`~fabricate.bounds.MAX_LINKAGE_BODIES` bodies; one driver (a table law of ``table`` samples), a pad
    on every moving body, every body with ``points`` points (the joints', the rest on a small circle: a hull
    of that many circles), ``poses`` sweep poses and a torque load. Gruebler: 3 × 39 - 2 × joints - gears = 1.
    """
    bodies: list[dict[str, Any]] = []
    joints: list[dict[str, Any]] = []
    gear_pairs: list[dict[str, Any]] = []
    frame: dict[str, list[float]] = {"O": [0.0, 0.0]}
    bodies.append({"name": "frame", "points": frame})
    h, arm, d, cd = 30.0, 5.0, 40.0, 30.0

    def body(name: str, pts: dict[str, list[float]]) -> None:
        bodies.append({"name": name, "points": pts})

    def joint(name: str, a: str, b: str, axis: list[float] | None = None) -> None:
        entry: dict[str, Any] = {"name": name, "type": "slider" if axis else "revolute", "bodies": [a, b]}
        if axis:
            entry["axis"] = axis
        joints.append(entry)

    def parallelogram(k: int, rot: tuple[str, str, float, str, list[float]]) -> tuple[str, str, float, str,
                                                                                          list[float]]:
        """A coupler and a rocker whose input arm equals the driving body's output arm (arms alternate
        between two vectors), so the rocker turns as the driving body does."""
        name, _, px, out, out_xy = rot
        x = px + d
        va = [out_xy[0] - px, out_xy[1]] if k > 1 else [0.0, h]
        vb = [arm, h] if va[0] == 0.0 else [0.0, h]
        inp = [x + va[0], va[1]]
        coupler, rocker = f"coupler{k}", f"rocker{k}"
        body(coupler, {out: out_xy, f"I{k}": inp})
        joint(out, name, coupler)
        frame[f"G{k}"] = [x, 0.0]
        body(rocker, {f"G{k}": [x, 0.0], f"I{k}": inp, f"U{k}": [x + vb[0], vb[1]]})
        joint(f"I{k}", coupler, rocker)
        joint(f"G{k}", "frame", rocker)
        return rocker, f"G{k}", x, f"U{k}", [x + vb[0], vb[1]]

    body("crank", {"O": [0.0, 0.0], "A": [8.0, 0.0]})
    joint("O", "frame", "crank")
    rot = parallelogram(1, ("crank", "O", 0.0, "A", [8.0, 0.0]))  # with the crank: a crank-rocker
    k = 1
    for g in range(1, gears + 1):
        name, pivot, px, _, _ = rot
        x = px + cd
        gear = f"gear{g}"
        frame[f"Q{g}"] = [x, 0.0]
        body(gear, {f"Q{g}": [x, 0.0], f"V{g}": [x + arm, h]})
        joint(f"Q{g}", "frame", gear)
        gear_pairs.append({"name": f"pair{g}", "carrier": "frame", "bodies": [name, gear], "axes": [pivot, f"Q{g}"],
                           "law": "expression", "expression": _expression(expression)})
        k += 1
        rot = parallelogram(k, (gear, f"Q{g}", x, f"V{g}", [x + arm, h]))
    while len(bodies) + 2 * (sliders + 1) <= bounds.MAX_LINKAGE_BODIES:
        k += 1
        rot = parallelogram(k, rot)
    # slider stages: a rod from the last rocker to a block on the x axis, then block to block (the blocks'
    # pin holes off the slide line, clear of the guide slot cut along it)
    name, _, _, out, out_xy = rot
    loaded = name
    k, length = 1, 40.0
    while len(bodies) + 2 <= bounds.MAX_LINKAGE_BODIES:
        x = out_xy[0] + math.sqrt(length ** 2 - (out_xy[1] - 8.0) ** 2) + 2.0
        rod, block = f"rod{k}", f"block{k}"
        body(rod, {out: out_xy, f"B{k}": [x - 2.0, 8.0]})
        joint(out, name, rod)
        frame[f"S{k}"] = [x, 0.0]
        body(block, {f"B{k}": [x - 2.0, 8.0], f"S{k}": [x, 0.0], f"C{k}": [x + 2.0, -8.0]})
        joint(f"B{k}", rod, block)
        joint(f"S{k}", "frame", block, axis=[1.0, 0.0])
        name, out, out_xy = block, f"C{k}", [x + 2.0, -8.0]
        k, length = k + 1, 30.0
    for b in bodies:  # every body at the point bound: the rest on a circle about its first point
        pts = b["points"]
        cx, cy = next(iter(pts.values()))
        n = points - len(pts)
        for i in range(n):
            t = 2 * math.pi * i / max(n, 1)
            pts[f"m{i}"] = [round(cx + 4.0 * math.cos(t), 9), round(cy + 4.0 * math.sin(t), 9)]
    inputs = [360.0 * i / (table - 1) for i in range(table)]
    return {
        "design": {"name": "worst_linkage", "kind": "linkage", "description": "a worst-case declared linkage"},
        "process": {"profile": "sla", "pin_diameter_mm": 3.0, "chord_tolerance_mm": bounds.MIN_CHORD_TOLERANCE_MM},
        "checks": {"sweep_poses": poses},
        "gears": {"teeth": [teeth, teeth]},
        # the most GIF frames the frames × teeth bound allows
        "parts": {"gif_frames": min(_GENERIC[("parts", "gif_frames")],
                                    bounds.MAX_FRAME_TEETH // max(1, 2 * teeth * gears)), "preview_poses": 24},
        "load": {"torque_Nmm": 50.0, "torque_body": loaded, "source": "benchmark"},
        "linkage": {"ground": "frame", "input_unit": "deg", "input_range": [0.0, 360.0], "tip_point": "A",
                    "bodies": bodies, "joints": joints, "gears": gear_pairs,
                    "drivers": [{"joint": "O", "law": "table", "input": inputs, "value": inputs}],
                    "pads": [{"body": b["name"], "point": "m0", "radius_mm": 3.0} for b in bodies[1:]]},
    }


def _largest(make: Any, lo: int, hi: int) -> int:
    """The largest ``n`` in ``lo .. hi`` whose template ``make(n)`` validates (the preflight included)."""
    from fabricate.design import design_from_text
    from fabricate.errors import SpecError

    def valid(n: int) -> bool:
        try:
            design_from_text(toml_text(make(n)), "worst.toml")
        except SpecError:
            return False
        return True

    if not valid(lo):
        raise SystemExit(f"no valid template at {lo}")
    while lo < hi:
        mid = (lo + hi + 1) // 2
        lo, hi = (mid, hi) if valid(mid) else (lo, mid - 1)
    return lo


def linkage_poses(table: int = bounds.MAX_LINKAGE_TABLE) -> dict[str, Any]:
    """The worst linkage for the poses: the most bodies and the most poses they allow (the poses × bodies
    bound), two gear pairs with the most teeth those poses allow (poses × teeth), and the most sliders the
    solver's estimate then allows."""
    poses = min(bounds.MAX_SWEEP_POSES, bounds.MAX_LINKAGE_POSE_BODIES // bounds.MAX_LINKAGE_BODIES)
    teeth = min(bounds.MAX_LINKAGE_POSE_TEETH // poses, bounds.MAX_LINKAGE_GEAR_TEETH) // 4
    kw = dict(poses=poses, gears=2, teeth=teeth, expression=60, table=table)
    sliders = _largest(lambda n: worst_linkage(sliders=n, **kw), 0, 18)
    return worst_linkage(sliders=sliders, **kw)


def linkage_gears() -> dict[str, Any]:
    """The worst linkage for the gears: the most pairs of at least 9 + 9 teeth that the teeth in all allow
    (and the most teeth), gear expressions of the most characters in all, and the most poses the solver's
    estimate and the poses × teeth bound then allow."""
    # 9 + 9 teeth at least: 8 + 8 round gears of 30 mm centre distance hold exactly min_teeth = 8 and are refused
    gears = min(bounds.MAX_LINKAGE_GEARS, bounds.MAX_LINKAGE_GEAR_TEETH // 18)
    gears -= gears % 2  # a gear stage adds three bodies, the others two: an even count reaches 40 bodies
    teeth = bounds.MAX_LINKAGE_GEAR_TEETH // (2 * gears)
    expression = min(bounds.MAX_EXPRESSION_LENGTH, bounds.MAX_LINKAGE_EXPRESSION_CHARS // gears)
    kw = dict(gears=gears, teeth=teeth, expression=expression, sliders=6)
    poses = _largest(lambda n: worst_linkage(poses=n, **kw), 2, bounds.MAX_SWEEP_POSES)
    return worst_linkage(poses=poses, **kw)


def worst_exact(copies: int = bounds.MAX_COPIES) -> str:
    """The worst exact form: the poses-worst linkage's ``mechanism.toml`` (every body at the point bound, laws
    by their coefficients or samples) with ``hints.copies`` at its bound, as the build writes it.

    The driver's table is halved until the file fits :data:`fabricate.templates.MAX_TEMPLATE_BYTES` (a guard: at
    the bound of 4000 samples in all the table writes 0.44 MB of PCHIP coefficients and fits as it is).
    """
    from fabricate.design import design_from_text
    from fabricate.hints import PadHint, PartHints
    from fabricate.synthesis.linkage.exact import mechanism_toml
    from fabricate.synthesis.linkage.mechanism import build_mechanism
    from fabricate.templates import MAX_TEMPLATE_BYTES

    table = bounds.MAX_LINKAGE_TABLE
    while True:
        design = design_from_text(toml_text(linkage_poses(table)), "worst_linkage.toml")
        mechanism = build_mechanism(design.name, design.method)
        hints = PartHints(copies=copies, tip_point="A",
                          pads={p.body: PadHint(p.point, p.radius_mm) for p in design.method.pads})
        text = mechanism_toml(design, mechanism, hints)
        if len(text) <= MAX_TEMPLATE_BYTES:
            return text.decode("utf-8")
        table //= 2


#: Generated kinds: the declared linkage and its exact form.
GENERATED = {"linkage": lambda: toml_text(linkage_poses()), "linkage_gears": lambda: toml_text(linkage_gears()),
             "linkage_exact": worst_exact}


def worst_template(kind: str) -> str:
    """The worst valid template text of ``kind``."""
    if kind in GENERATED:
        return GENERATED[kind]()
    name, overrides = WORST[kind]
    data = parse_toml((TEMPLATE_DIR / name).read_text(encoding="utf-8"), name)
    data["design"]["name"] = f"worst_{kind}"
    for (section, key), value in {**_GENERIC, **overrides}.items():
        data.setdefault(section, {})[key] = value
    return toml_text(data)


def run(kind: str, work: Path, blas: int) -> dict[str, Any]:
    """Build the worst template of ``kind`` with ``blas`` BLAS threads; its wall, CPU, peak and exit."""
    template = work / f"worst_{kind}.toml"
    template.write_text(worst_template(kind), encoding="utf-8")
    env = {**os.environ, **{name: str(blas) for name in BLAS_THREAD_VARIABLES}}
    out = subprocess.run([sys.executable, "-c", WRAPPER, str(template), str(work / f"out_{kind}_{blas}")],
                         capture_output=True, text=True, check=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


#: Run in its own process by ``--poses-memory``: builds a template's inputs up to the parts, then runs each stage
#: that goes through every pose (the motion sweep again, the exports with motion.csv and the MJCF model, the
#: interference proof, the gear mesh check, the strength statics and findings, the pictures a build's child draws
#: and the strength and clearance plots) with the peak resident memory reset before it (Linux
#: ``/proc/self/clear_refs``, after glibc's ``malloc_trim``); prints each stage's peak (VmHWM) and the resident
#: memory it started from (MB). The interference proof and the gear mesh check are measured
#: inside ``run_checks`` by wrapping them.
STAGE_PEAKS = """
import ctypes, json, sys
import fabricate.checks as checks
from fabricate.design import design_from_text
from fabricate.pipeline import (BuildRun, _synthesis_stage, _make_gears, _make_parts, _check, _check_strength,
                                _export, _record_optional_outputs, OptionalOutputs, _picture_jobs)
from fabricate.bounds import blas_threads

def status(key):
    with open("/proc/self/status") as f:
        return next(float(line.split()[1]) / 1024.0 for line in f if line.startswith(key + ":"))

out = {}

def measured(name, fn):
    def run(*args, **kwargs):
        ctypes.CDLL("libc.so.6").malloc_trim(0)  # what earlier stages freed goes back: the start is what lives
        start = status("VmRSS")
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")  # VmHWM := VmRSS
        try:
            return fn(*args, **kwargs)
        finally:
            out[name] = {"start_mb": start, "peak_mb": status("VmHWM")}
    return run

checks.sweep_interference = measured("interference", checks.sweep_interference)
checks.check_gear_meshes = measured("gear mesh", checks.check_gear_meshes)
with blas_threads():
    design = design_from_text(open(sys.argv[1]).read(), "t.toml")
    result, report, motion, failures = _synthesis_stage(design, lambda s: None, "build")
    measured("motion sweep", result.mechanism.sweep)(design.checks.sweep_poses)
    run = BuildRun(design, result, motion, report, lambda s: None, OptionalOutputs(step=False))
    _make_gears(run)
    _make_parts(run)
    measured("exports", _export)(run, _record_optional_outputs(run))
    _check(run)
    measured("strength", _check_strength)(run)
    measured("pictures", lambda: [job() for job in _picture_jobs(run)])()
    from fabricate.strength.plots import strength_plot
    measured("plots", lambda: (strength_plot(run.strength, run.mechanism.input_unit), run.checks.figures()))()
print(json.dumps(out))
"""

#: ``--poses-memory``: the templates and pose counts whose stage peaks are compared.
POSES_MEMORY_TEMPLATES = ("finger_five_bar_ncg", "linkage_stephenson")
POSES_MEMORY_COUNTS = (360, bounds.MAX_SWEEP_POSES)
POSES_MEMORY_STAGES = ("motion sweep", "exports", "interference", "gear mesh", "strength", "pictures", "plots")


def poses_memory(templates: tuple[str, ...] = POSES_MEMORY_TEMPLATES,
                 counts: tuple[int, ...] = POSES_MEMORY_COUNTS) -> None:
    """Peak memory of the stages that go through every pose against the number of poses: each template at each
    count in a fresh process (:data:`STAGE_PEAKS`); prints each stage's peak and its ratio to the first count's
    (the interference proof and the strength sweep stream their poses in chunks: within 1.3x from 360 to 5000)."""
    print(f"{'template':22s} {'stage':13s} " + " ".join(f"{f'{n} poses MB':>15s}" for n in counts)
          + f" {'ratio':>6s}   (peak RSS in the stage; in brackets its growth over the RSS it started from)")
    with tempfile.TemporaryDirectory(prefix="bench_poses_") as tmp:
        for name in templates:
            peaks: dict[int, dict[str, Any]] = {}
            for n in counts:
                data = parse_toml((TEMPLATE_DIR / f"{name}.toml").read_text(encoding="utf-8"), name)
                data.setdefault("checks", {})["sweep_poses"] = n
                path = Path(tmp) / f"{name}_{n}.toml"
                path.write_text(toml_text(data), encoding="utf-8")
                env = {**os.environ, "FABRICATE_SERIAL": "1", "OPENBLAS_NUM_THREADS": "1"}
                out = subprocess.run([sys.executable, "-c", STAGE_PEAKS, str(path)], capture_output=True, text=True,
                                     check=True, env=env)
                peaks[n] = json.loads(out.stdout.strip().splitlines()[-1])
            for stage in POSES_MEMORY_STAGES:
                if any(stage not in peaks[n] for n in counts):
                    continue  # no gear pair: no gear mesh check
                cells = [f"{p['peak_mb']:6.0f} ({p['peak_mb'] - p['start_mb']:+6.0f})"
                         for p in (peaks[n][stage] for n in counts)]
                ratio = peaks[counts[-1]][stage]["peak_mb"] / peaks[counts[0]][stage]["peak_mb"]
                print(f"{name:22s} {stage:13s} " + " ".join(f"{c:>15s}" for c in cells) + f" {ratio:6.2f}",
                      flush=True)


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blas", choices=("1", "2", "both"), default="both")
    parser.add_argument("--poses-memory", action="store_true",
                        help="peak memory of the interference and strength sweeps at 360 and the most poses")
    parser.add_argument("--poses", type=int, help="checks.sweep_poses of the shipped kinds' worst templates (default "
                        f"the bound, {bounds.MAX_SWEEP_POSES}; the gear pair and linkages keep their products)")
    parser.add_argument("kinds", nargs="*", metavar="kind", help=f"of {', '.join([*WORST, *GENERATED])}")
    args = parser.parse_args(argv)
    if args.poses_memory:
        poses_memory(tuple(args.kinds) or POSES_MEMORY_TEMPLATES)
        return
    if args.poses:
        _GENERIC[("checks", "sweep_poses")] = args.poses
    kinds = args.kinds or [*WORST, *GENERATED]
    unknown = [k for k in kinds if k not in WORST and k not in GENERATED]
    if unknown:
        parser.error(f"unknown kind {', '.join(unknown)}")
    threads = (1, 2) if args.blas == "both" else (int(args.blas),)
    print(f"{'kind':18s} {'BLAS':>4s} {'wall s':>8s} {'CPU s':>7s} {'peak MB':>9s} {'exit':>5s} "
          f"{'CPU/60s':>8s} {'wall/60s':>9s} {'RSS/4GB':>8s}")
    with tempfile.TemporaryDirectory(prefix="bench_bounds_") as tmp:
        for kind in kinds:
            for blas in threads:
                r = run(kind, Path(tmp), blas)
                print(f"{kind:18s} {blas:4d} {r['seconds']:8.1f} {r['cpu_seconds']:7.1f} {r['peak_mb']:9.0f} "
                      f"{r['rc']:5d} {r['cpu_seconds'] / bounds.TIME_BUDGET_S:8.2f} "
                      f"{r['seconds'] / bounds.TIME_BUDGET_S:9.2f} {r['peak_mb'] / bounds.MEMORY_BUDGET_MB:8.2f}",
                      flush=True)
                if r["rc"] not in (0, 1):
                    print(f"  exit {r['rc']}: {r['stderr'].strip()[-300:]}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
