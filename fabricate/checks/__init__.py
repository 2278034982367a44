"""The checks that gate a build: interference over the motion, gear mesh in the assembly, printability.

Findings are data: :func:`run_checks` returns a :class:`CheckReport` whose ``failures`` say in words
what is wrong; the pipeline writes the files anyway and exits 1 when the list is not empty.

Public API
----------
``run_checks(design, partset, mechanism, motion, gear_pairs) -> CheckReport``
``sweep_interference(parts, motion, *, chord_tolerance_mm, min_clearance_mm, pins=None)``
    (:mod:`fabricate.checks.interference`)
``check_gear_mesh(pair, motion)`` (:mod:`fabricate.checks.gear_mesh`)
``check_printability(parts, process, gear_pairs, pins)`` (:mod:`fabricate.checks.printability`)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from fabricate.checks.gear_mesh import GearMeshResult, check_gear_mesh, check_gear_meshes
from fabricate.checks.interference import InterferenceResult, sweep_interference
from fabricate.checks.printability import PrintabilityResult, check_printability
from fabricate.mechanism import Mechanism, Motion

__all__ = ["CheckReport", "run_checks", "sweep_interference", "check_gear_mesh", "check_printability"]


@dataclass(frozen=True)
class CheckReport:
    """Outcome of every check of one build.

    Attributes
    ----------
    interference : dict
        report.json's ``interference`` section: DESIGN.md keys ``poses``, ``pairs_checked``,
        ``collisions`` [{a, b, input_deg, volume_mm3}], ``min_clearance_mm`` plus ``input_unit``, the
        per-pair table ``pairs``, and the ``gear_mesh`` and ``printability`` results.
    failures : list of str
        Human-readable reasons the build fails (empty: it passes).
    passed : bool
    sweep, gear_mesh, printability
        The full results.
    """

    interference: dict[str, Any]
    failures: list[str]
    passed: bool
    sweep: InterferenceResult = field(repr=False)
    gear_mesh: tuple[GearMeshResult, ...] = ()
    printability: PrintabilityResult | None = None

    def report(self) -> dict[str, Any]:
        """``{"interference": ..., "checks": {"passed", "failures"}}`` for report.json."""
        return {"interference": self.interference,
                "checks": {"passed": self.passed, "failures": list(self.failures)}}

    def figures(self) -> dict[str, bytes]:
        """PNG plots: ``clearance.png`` (clearance against input for the closest pairs)."""
        from fabricate.checks.plots import clearance_png

        return {"clearance.png": clearance_png(self.sweep)}

    def pair_table(self) -> list[dict[str, Any]]:
        """One row per checked pair (a, b, relation, min clearance and where, required, ok)."""
        return [self.sweep.pair_row(p) for p in self.sweep.pairs]

    def pair_table_markdown(self) -> str:
        """The per-pair table as Markdown, closest pairs first (for report.md)."""
        unit = self.sweep.input_unit
        lines = [f"| a | b | relation | min clearance mm | at input {unit} | required mm | ok |",
                 "|---|---|---|---|---|---|---|"]
        rows = sorted(self.pair_table(), key=lambda r: (r["min_clearance_mm"] is None,
                                                        r["min_clearance_mm"] or 0.0, r["a"], r["b"]))
        for r in rows:
            value = "—" if r["min_clearance_mm"] is None else f"{r['min_clearance_mm']:.3f}"
            if not r["exact"]:
                value = f"≥ {value}"
            if r["collides"]:
                value = "collides"
            lines.append(f"| {r['a']} | {r['b']} | {r['relation']} | {value} | {r['input_deg']:.2f} | "
                         f"{r['required_mm']:g} | {'yes' if r['ok'] else '**no**'} |")
        return "\n".join(lines)


def run_checks(design: Any, partset: Any, mechanism: Mechanism, motion: Motion,
               gear_pairs: Sequence[Any]) -> CheckReport:
    """Run every check of a build.

    Parameters
    ----------
    design : DesignSpec
        ``design.process`` (clearances, tolerances, build volume) and ``design.checks``
        (``sweep_poses``, ``min_clearance_mm``; None means the process's running clearance).
    partset : PartSet
        ``parts`` and ``pins`` from the parts layer.
    mechanism, motion : Mechanism, Motion
        The motion is re-swept when it has fewer than ``design.checks.sweep_poses`` poses.
    gear_pairs : sequence of GearPair

    Returns
    -------
    CheckReport
    """
    process = design.process
    poses = int(design.checks.sweep_poses)
    if len(motion.inputs) < poses:
        motion = mechanism.sweep(poses)
    required = design.checks.min_clearance_mm
    if required is None:
        required = process.running_clearance_mm
    parts = tuple(partset.parts)
    pins = tuple(getattr(partset, "pins", ()) or ())
    sweep = sweep_interference(parts, motion, chord_tolerance_mm=process.chord_tolerance_mm,
                               min_clearance_mm=float(required), pins=pins or None,
                               spacers=tuple(getattr(partset, "spacers", ()) or ()))
    meshes = tuple(check_gear_meshes(gear_pairs, motion))
    printable = check_printability(parts, process, gear_pairs, pins)
    failures = sweep.failures()
    for mesh in meshes:
        failures += list(mesh.failures)
    failures += list(printable.failures)
    interference = sweep.report()
    interference["gear_mesh"] = [m.report() for m in meshes]
    interference["printability"] = printable.report()
    return CheckReport(interference=interference, failures=failures, passed=not failures, sweep=sweep,
                       gear_mesh=meshes, printability=printable)
