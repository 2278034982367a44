"""Worst valid template of each kind against the resource budget of :mod:`fabricate.bounds`.

Each shipped template is turned into its most expensive valid form (every bounded count at its
maximum, products of counts at the preflight bound) and built by ``python -m fabricate build T -o DIR
-q`` in a subprocess of its own wrapper process, so the wrapper's ``RUSAGE_CHILDREN`` peak is that
build's alone. Prints: kind, wall time, CPU time (user + sys of the build and its forked picture
child: on a shared machine the wall time also counts waiting for a core), peak RSS, exit code and the
ratios to the 60 s / 4 GB budget.

Run: ``python tests/benchmarks/bench_bounds.py [kind ...]`` (not part of the test suite; a few minutes).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository: tests/ helpers

from fabricate import bounds  # noqa: E402
from fabricate.spec import TEMPLATE_DIR, parse_toml  # noqa: E402
from tests.toml_writer import toml_text  # noqa: E402

#: Wrapper run in its own process: times one build and reads its peak RSS (kB on Linux).
WRAPPER = """
import json, resource, subprocess, sys, time
start = time.perf_counter()
rc = subprocess.run([sys.executable, "-m", "fabricate", "build", sys.argv[1], "-o", sys.argv[2], "-q"],
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE).returncode
elapsed = time.perf_counter() - start
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"rc": rc, "seconds": elapsed, "cpu_seconds": usage.ru_utime + usage.ru_stime,
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
    "compliant_gripper": ("gripper_compliant.toml", {
        # the shipped 31 x 31 x 91 spring triples: path samples up to the spring-table bound
        ("optimisation", "path_samples"): min(bounds.MAX_PATH_SAMPLES,
                                              int(bounds.MAX_SPRING_TABLE // (31 * 31 * 91))),
        ("drive", "fingers"): 12,
    }),
}


def worst_template(kind: str) -> str:
    """The worst valid template text of ``kind``."""
    name, overrides = WORST[kind]
    data = parse_toml((TEMPLATE_DIR / name).read_text(encoding="utf-8"), name)
    data["design"]["name"] = f"worst_{kind}"
    for (section, key), value in {**_GENERIC, **overrides}.items():
        data.setdefault(section, {})[key] = value
    return toml_text(data)


def run(kind: str, work: Path) -> dict[str, Any]:
    template = work / f"worst_{kind}.toml"
    template.write_text(worst_template(kind), encoding="utf-8")
    out = subprocess.run([sys.executable, "-c", WRAPPER, str(template), str(work / f"out_{kind}")],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(kinds: list[str]) -> None:
    print(f"{'kind':18s} {'time s':>8s} {'CPU s':>7s} {'peak MB':>9s} {'exit':>5s} {'time/60s':>9s} {'RSS/4GB':>8s}")
    with tempfile.TemporaryDirectory(prefix="bench_bounds_") as tmp:
        for kind in kinds:
            r = run(kind, Path(tmp))
            print(f"{kind:18s} {r['seconds']:8.1f} {r['cpu_seconds']:7.1f} {r['peak_mb']:9.0f} {r['rc']:5d} "
                  f"{r['seconds'] / bounds.TIME_BUDGET_S:9.2f} {r['peak_mb'] / bounds.MEMORY_BUDGET_MB:8.2f}",
                  flush=True)


if __name__ == "__main__":
    main(sys.argv[1:] or list(WORST))
