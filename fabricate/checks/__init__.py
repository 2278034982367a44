"""The checks that gate a build: interference over the motion, gear mesh in the assembly, printability.

Findings are data: :func:`run_checks` returns a :class:`CheckReport` whose ``failures`` say in words
what is wrong; the pipeline writes the files anyway and exits 1 when the list is not empty. A check that
could not run (a motion of no poses, no pair of parts that move against each other) is "not checked":
its ``passed`` is None and ``not_checked`` names it with the reason, never a pass.

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
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.checks.gear_mesh import GearMeshResult, check_gear_mesh, check_gear_meshes
from fabricate.checks.interference import DEFAULT_SEARCH_MM, InterferenceResult, sweep_interference
from fabricate.checks.printability import PrintabilityResult, check_printability
from fabricate.mechanism import Mechanism, Motion

if TYPE_CHECKING:
    from fabricate.gears.pair import GearPair
    from fabricate.parts.partset import PartSet
    from fabricate.spec import DesignSpec

__all__ = ["CheckReport", "run_checks", "sweep_interference", "check_gear_mesh", "check_printability"]

#: Why the interference (and gear mesh) check did not run, in the words the CLI prints.
NO_POSES = "no poses in the motion"
NO_PAIRS = "no two parts move against each other"


@dataclass(frozen=True)
class CheckReport:
    """Outcome of every check of one build.

    Attributes
    ----------
    interference : dict
        report.json's ``interference`` section (fabricate/report_schema.json, docs/report.md): ``poses``,
        ``pairs_checked``, ``collisions`` [{a, b, input_deg, volume_mm3}], ``min_clearance_mm``, ``input_unit``, the
        per-pair table ``pairs``, ``passed`` (the sweep's verdict; None when it could not run, with a
        ``reason``), and the ``gear_mesh`` and ``printability`` results.
    failures : list of str
        Human-readable reasons the build fails (empty: it passes).
    passed : bool
        No failure among the checks that ran.
    sweep, gear_mesh, printability
        The full results.
    not_checked : tuple of dict
        ``{"check": name, "reason": why}`` for each check that could not run.
    """

    interference: dict[str, Any]
    failures: list[str]
    passed: bool
    sweep: InterferenceResult = field(repr=False)
    gear_mesh: tuple[GearMeshResult, ...] = ()
    printability: PrintabilityResult | None = None
    not_checked: tuple[dict[str, str], ...] = ()

    def report(self) -> dict[str, Any]:
        """``{"interference": ..., "checks": {"passed", "failures", "not_checked"}}`` for report.json."""
        return {"interference": self.interference,
                "checks": {"passed": self.passed, "failures": list(self.failures),
                           "not_checked": [dict(entry) for entry in self.not_checked]}}

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


def run_checks(design: DesignSpec, partset: PartSet, mechanism: Mechanism, motion: Motion,
               gear_pairs: Sequence[GearPair]) -> CheckReport:
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
        With no poses to sweep (only a motion of none and ``sweep_poses`` 0, which a template cannot ask
        for) the interference and gear mesh checks are not run; with no pair of parts that move against
        each other the sweep has nothing to check. Either is listed in ``not_checked``, never passed.
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
    not_checked: list[dict[str, str]] = []
    if len(motion.inputs) == 0:
        # nothing to sweep: an empty result (the sweep itself needs at least one pose)
        sweep = InterferenceResult(np.empty(0), motion.mechanism.input_unit, (), 0, float(required),
                                   float(process.chord_tolerance_mm),
                                   max(DEFAULT_SEARCH_MM, 4.0 * float(required)))
        meshes: tuple[GearMeshResult, ...] = ()
        not_checked.append({"check": "interference", "reason": NO_POSES})
        if gear_pairs:
            not_checked.append({"check": "gear mesh", "reason": NO_POSES})
    else:
        from fabricate.drive.parts import sweep_items as actuator_items
        from fabricate.parts.spring_rows import spring_sweep_items

        sweep = sweep_interference(parts, motion, chord_tolerance_mm=process.chord_tolerance_mm,
                                   min_clearance_mm=float(required), pins=pins or None,
                                   spacers=tuple(getattr(partset, "spacers", ()) or ()),
                                   extra=actuator_items(partset)
                                   + spring_sweep_items(getattr(partset, "springs", ()), process.chord_tolerance_mm))
        meshes = tuple(check_gear_meshes(gear_pairs, motion))
        if not sweep.pairs:
            not_checked.append({"check": "interference", "reason": NO_PAIRS})
    # the free border the plate / sheet layout keeps (export._Making): a part must fit inside it (a design
    # without a [parts] spec, as unit tests build, keeps none)
    layout = getattr(design, "parts", None)
    margin = 0.0 if layout is None else (layout.sheet_margin_mm if process.layout == "sheet"
                                         else layout.plate_spacing_mm)
    printable = check_printability(parts, process, gear_pairs, pins, margin_mm=float(margin))
    from fabricate.checks.shop import check_shop

    shop = check_shop(parts, process)  # a cut process: the shop's rules (None for a printer)
    failures = sweep.failures()
    for mesh in meshes:
        failures += list(mesh.failures)
    failures += list(printable.failures)
    if shop is not None:
        failures += list(shop.failures)
    interference = sweep.report()
    skipped = next((e["reason"] for e in not_checked if e["check"] == "interference"), None)
    interference["passed"] = None if skipped is not None else sweep.passed
    if skipped is not None:
        interference["reason"] = skipped
    interference["gear_mesh"] = [m.report() for m in meshes]
    interference["printability"] = printable.report()
    if shop is not None:
        interference["shop"] = shop.report()
    return CheckReport(interference=interference, failures=failures, passed=not failures, sweep=sweep,
                       gear_mesh=meshes, printability=printable, not_checked=tuple(not_checked))
