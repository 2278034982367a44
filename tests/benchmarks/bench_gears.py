"""Benchmark: the same closed 30:30 non-circular pair by fabricate and by ncgears, side by side.

Law (driven angle against driving angle): psi = phi + 0.03 sin(phi); module 0.5 mm; 20 deg pressure
angle; addendum 1 m, dedendum 1.25 m, root fillet 0.38 m for both; each gear face offset inwards by
0.02 m (ncgears ``clearance=0.02``; fabricate ``backlash_mm = 4 * 0.01 / cos 20``).

Both pairs are measured the same way here (:func:`fabricate.gears.mesh.free_play_outlines`: bisection
on 2D booleans of the placed outlines, 360 poses over a turn): transmission error = driven angle at
contact minus the law minus the lag the designed face offset alone allows, on either flank.

Run: ``pip install ncgears`` (the ``bench`` extra), then ``python tests/benchmarks/bench_gears.py``.
Goal: fabricate 10x faster at equal or better transmission error. Not part of the default test run.
"""

from __future__ import annotations

import sys
import tempfile
import time

import numpy as np

from fabricate.gears import GearSpec, make_gear_pair
from fabricate.gears.law import FormulaLaw
from fabricate.gears.mesh import designed_lag, free_play_outlines
from fabricate.gears.pitch import PitchCurves

TEETH = 30
MODULE = 0.5
FACE_OFFSET = 0.02  # x module, per gear face
STEPS = 360


def fabricate_pair(mesh: bool):
    law = FormulaLaw("x + 0.03*sin(x)")
    unit = PitchCurves(law, 1.0, (0.0, 2 * np.pi), 0.0)
    centre = TEETH * np.pi * MODULE / float(unit.s_of_x(np.array([2 * np.pi]))[0])
    spec = GearSpec(teeth=(TEETH, TEETH), backlash_mm=4 * FACE_OFFSET * MODULE / np.cos(np.radians(20)),
                    compare_methods=False)
    return make_gear_pair(law, centre, (0.0, 2 * np.pi), spec, closed=True, name="bench",
                          chord_tolerance_mm=0.005, run_mesh_check=mesh)


def transmission_error_deg(outline_a, outline_b, centre, pair, x):
    plus, minus = free_play_outlines(outline_a, outline_b, pair.law, centre, x, MODULE)
    lag_plus, lag_minus = designed_lag(pair, x)
    te = np.maximum(np.abs(plus - lag_plus), np.abs(minus - lag_minus))
    backlash = (plus + minus) * pair.pitch_model.radii(x, "b")[0]
    return float(np.degrees(np.nanmax(te))), int(np.count_nonzero(np.isnan(te))), backlash


def main() -> int:
    try:
        import ncgears
    except ImportError:
        print("ncgears is not installed: pip install ncgears (or the 'bench' extra)")
        return 1
    fabricate_pair(False)  # warm-up (imports, caches)
    t0 = time.perf_counter()
    ours = fabricate_pair(False)
    t_ours = time.perf_counter() - t0
    t0 = time.perf_counter()
    ours_checked = fabricate_pair(True)
    t_ours_checked = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        theirs = ncgears.generate("phi + 0.03*sin(phi)", teeth=TEETH, module=MODULE, pressure_angle_deg=20.0,
                                  addendum_factor=1.0, dedendum_factor=1.25, fillet_factor=0.38,
                                  clearance=FACE_OFFSET, output_directory=out, name="bench")
        t_theirs = time.perf_counter() - t0
    x = np.linspace(0.0, 2 * np.pi, STEPS, endpoint=False)
    te_ours, bad_ours, bl_ours = transmission_error_deg(ours.cut_a.dense, ours.cut_b.dense,
                                                        ours.center_distance_mm, ours, x)
    te_theirs, bad_theirs, bl_theirs = transmission_error_deg(theirs.drive_outline, theirs.driven_outline,
                                                              theirs.center_distance, ours, x)
    rows = [
        ("generator", "fabricate (exact)", f"ncgears {ncgears.__version__}"),
        ("teeth", f"{ours.teeth[0]}:{ours.teeth[1]}", f"{theirs.drive_teeth}:{theirs.driven_teeth}"),
        ("centre distance (mm)", f"{ours.center_distance_mm:.6f}", f"{theirs.center_distance:.6f}"),
        ("generation time (s)", f"{t_ours:.3f}", f"{t_theirs:.3f}"),
        ("with own checks (s)", f"{t_ours_checked:.3f} (720-step mesh check)", "(included above)"),
        ("outline vertices", f"{len(ours.cut_a.dense)} dense / {len(ours.outline_a)} DXF",
         f"{len(theirs.drive_outline)}"),
        ("TE measured here (deg)", f"{te_ours:.2e}", f"{te_theirs:.2e}"),
        ("poses overlapping", f"{bad_ours}", f"{bad_theirs}"),
        ("backlash here (mm)", f"{np.nanmin(bl_ours):.4f}..{np.nanmax(bl_ours):.4f}",
         f"{np.nanmin(bl_theirs):.4f}..{np.nanmax(bl_theirs):.4f}"),
        ("TE self-reported (deg)", f"{ours_checked.report()['transmission_error_deg']:.2e}",
         f"{np.degrees(theirs.maximum_transmission_error):.2e}"),
    ]
    width = max(len(r[0]) for r in rows)
    col = max(len(r[1]) for r in rows)
    for name, a, b in rows:
        print(f"{name:<{width}}  {a:<{col}}  {b}")
    print(f"\nspeed-up: {t_theirs / t_ours:.1f}x (goal 10x); TE ratio ncgears/fabricate: "
          f"{te_theirs / max(te_ours, 1e-12):.2f} (goal >= 1)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
