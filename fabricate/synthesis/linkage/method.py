"""The declared linkage's "synthesis": nothing is synthesised; the template's linkage (or a build's exact
form) becomes the :class:`~fabricate.mechanism.Mechanism`, solved once over the range, with the report's
``synthesis`` section and the parts hints."""

from __future__ import annotations

import contextlib
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.bounds import blas_threads
from fabricate.errors import LockupError, SpecError
from fabricate.hints import PadHint, PartHints
from fabricate.mechanism import Mechanism, Motion
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.linkage.declared import ExactLinkageSpec, LinkageSpec
from fabricate.synthesis.linkage.mechanism import build_mechanism, gear_law

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


def _check_gear_ranges(spec: LinkageSpec, mech: Mechanism, motion: Motion) -> None:
    """A sector pair's gear a must stay inside its working range over the motion."""
    for k, g in enumerate(spec.gears):
        if g.closed:
            continue
        x = np.degrees(motion.relative_angle(g.bodies[0], g.carrier))
        lo, hi = g.working_range_deg
        if x.min() < lo - 1e-6 or x.max() > hi + 1e-6:
            raise SpecError(f"linkage.gears[{k}].working_range_deg",
                            f"gear \"{g.name}\": the motion turns gear a from {x.min():.3f} to {x.max():.3f} deg, "
                            f"outside its working range [{lo:g}, {hi:g}]")


def synthesise(design: DesignSpec) -> SynthesisResult:
    """Build the declared linkage (no synthesis: the template is the design)."""
    spec: LinkageSpec = design.method
    sweep_poses = max(int(getattr(getattr(design, "checks", None), "sweep_poses", 360)), 2)
    if isinstance(spec, ExactLinkageSpec):
        return _exact_form(spec, sweep_poses)
    # one BLAS thread: the solver's systems (3 × bodies unknowns) are too small to share, and on busy cores
    # OpenBLAS's threads wait for each other (the worst linkage's 360 poses: 42 s with them, 2 s without)
    with blas_threads():
        mech = build_mechanism(design.name, spec)
        motion = None
        try:  # the pipeline sweeps the same inputs next (cached); a lock-up is its to report (exit 1)
            motion = mech.sweep(sweep_poses)
        except LockupError:
            pass
    if motion is not None:
        _check_gear_ranges(spec, mech, motion)
    report = _report(spec, mech, motion)

    def figures() -> dict[str, bytes]:
        if not spec.gears:
            return {}
        from fabricate.synthesis.linkage.plots import gear_law_figures

        return gear_law_figures(mech)

    parts = PartHints(tip_point=spec.tip_point, pads={p.body: PadHint(p.point, p.radius_mm) for p in spec.pads})
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data={"spec": spec}, parts=parts)


def _exact_form(spec: ExactLinkageSpec, sweep_poses: int) -> SynthesisResult:
    """The exact form: the mechanism as written, solved once, with the parts hints it came with."""
    report = {"method": "declared linkage, exact form (a build's mechanism.toml)",
              "degrees_of_freedom": spec.mechanism.degrees_of_freedom(), "tip_point": spec.tip_point}
    with blas_threads(), contextlib.suppress(LockupError):
        spec.mechanism.sweep(sweep_poses)  # solved here with one BLAS thread; the pipeline's sweep is cached
    return SynthesisResult(mechanism=spec.mechanism, report=report, parts=spec.hints)


def _report(spec: LinkageSpec, mech: Mechanism, motion: Motion | None) -> dict[str, Any]:
    """The ``synthesis`` section: the linkage as declared, its mobility and (when it moved) the tip's path."""
    laws = {g.name: gear_law(g, f"linkage.gears[{k}]")[1] for k, g in enumerate(spec.gears)}
    report: dict[str, Any] = {
        "method": "declared linkage (no synthesis)",
        "bodies": len(spec.bodies),
        "joints": {j.name: {"type": j.type, "bodies": list(j.bodies)} for j in spec.joints},
        "gears": {g.name: {"carrier": g.carrier, "bodies": list(g.bodies), "axes": list(g.axes), "law": laws[g.name],
                           "closed": g.closed, "working_range_deg": list(g.working_range_deg)} for g in spec.gears},
        "drivers": [{"joint": d.joint, "law": d.law, "reference": d.reference} for d in spec.drivers],
        "degrees_of_freedom": mech.degrees_of_freedom(),
        "input_unit": spec.input_unit,
        "input_range": list(spec.input_range),
        "reference_input": spec.reference,
        "tip_point": spec.tip_point,
    }
    if motion is not None and spec.tip_point is not None:
        tip = motion.point(spec.tip_point)
        report["tip_path_mm"] = {"x": [float(tip[:, 0].min()), float(tip[:, 0].max())],
                                 "y": [float(tip[:, 1].min()), float(tip[:, 1].max())]}
    return report
