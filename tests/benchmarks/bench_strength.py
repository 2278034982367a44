"""What the strength check costs per shipped template, side by side with the stages it follows.

    python tests/benchmarks/bench_strength.py

For each template: the sweep's poses, the time of the statics alone, of the whole strength check
(statics + every closed-form model on every part, hole, section, pin and gear), of the parts stage it
follows and of the interference check, and the ratio strength / interference. Each figure is the least of
three runs (one core, nothing written).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from fabricate.checks import run_checks  # noqa: E402
from fabricate.design import load_design  # noqa: E402
from fabricate.gears import build_gear_pairs  # noqa: E402
from fabricate.parts.build import build_parts  # noqa: E402
from fabricate.pipeline import synthesise  # noqa: E402
from fabricate.strength.check import design_loads, run_strength  # noqa: E402
from fabricate.strength.statics import solve_statics  # noqa: E402
from fabricate.templates import shipped_templates  # noqa: E402


def best(fn, runs: int = 3) -> tuple[float, object]:
    out, times = None, []
    for _ in range(runs):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


def main() -> None:
    rows = []
    for path in shipped_templates():
        design = load_design(path.stem)
        result = synthesise(design)
        mech = result.mechanism
        motion = mech.sweep(design.checks.sweep_poses)
        gears = build_gear_pairs(mech, design.gears, design.process.chord_tolerance_mm)
        t_parts, partset = best(lambda d=design, m=mech, mo=motion, g=gears, h=result.parts:
                                build_parts(d, m, mo, g, h))
        loads = design_loads(design, mech, motion, result.parts)
        t_statics, _ = best(lambda m=mech, mo=motion, lo=loads: solve_statics(m, mo, lo.forces, lo.torques, lo.efforts,
                                                                                 lo.reaction))
        t_strength, strength = best(lambda d=design, p=partset, m=mech, mo=motion, g=gears, h=result.parts:
                                    run_strength(d, p, m, mo, g, h))
        t_checks, _ = best(lambda d=design, p=partset, m=mech, mo=motion, g=gears: run_checks(d, p, m, mo, g), runs=1)
        least = min((f.safety_factor for f in strength.findings), default=float("inf"))
        rows.append((path.stem, len(motion.inputs), len(strength.findings), t_statics, t_strength, t_parts, t_checks,
                     t_strength / t_checks, least))
    head = ("template", "poses", "findings", "statics s", "strength s", "parts s", "interference s",
            "strength/interference", "least SF")
    print(" | ".join(head))
    print(" | ".join("---" for _ in head))
    for r in rows:
        print(f"{r[0]} | {r[1]} | {r[2]} | {r[3]:.3f} | {r[4]:.3f} | {r[5]:.3f} | {r[6]:.3f} | {r[7]:.2f} | {r[8]:.2f}")


if __name__ == "__main__":
    main()
