"""report.json's ``design`` and ``mechanism`` sections, the same for ``synth`` and ``build`` (the pipeline's
first, :mod:`fabricate.pipeline`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fabricate import __version__
from fabricate.mechanism import Mechanism, Motion
from fabricate.spec import DesignSpec


def design_section(design: DesignSpec, stage: str) -> dict[str, Any]:
    """report.json's ``design`` section (fabricate/report_schema.json): the template's name, kind and process,
    fabricate's version and ``stage`` (``synth`` or ``build``), the printer and the ``--process`` override if any."""
    # the template's file name only: a folder in the report would make its bytes depend on where the
    # build ran (the template itself is embedded as template_text)
    section: dict[str, Any] = {"name": design.name, "kind": design.kind, "template": Path(design.template).name,
                               "fabricate_version": __version__, "description": design.description,
                               "process": design.process.name, "stage": stage}
    if design.process.printer:  # the printer the plates are packed for (fabricate.catalogue.printers)
        from fabricate.catalogue.printers import printer

        section["printer"] = {**printer(design.process.printer).report(),
                              "first_layer_compensation_mm": design.process.first_layer_compensation_mm}
    if design.process_override is not None:  # --process: check rebuilds with the same profile
        section["process_override"] = {"source": design.process_override.source,
                                       "text": design.process_override.text}
        if design.process_override.printer:  # --printer
            section["process_override"]["printer"] = design.process_override.printer
    return section


def mechanism_section(mechanism: Mechanism, motion: Motion) -> dict[str, Any]:
    """report.json's ``mechanism`` section (fabricate/report_schema.json): every named point at the first
    pose, bodies with their points."""
    joints = {}
    for body in mechanism.bodies:
        for name in body.points:
            if name not in joints:
                joints[name] = motion.point(name, body.name)[0]
    return {
        "joints": {k: [float(v[0]), float(v[1])] for k, v in joints.items()},
        "bodies": {b.name: list(b.points) for b in mechanism.bodies},
        "input_range_deg": [float(mechanism.input_range[0]), float(mechanism.input_range[1])],
        "input_unit": mechanism.input_unit,
        "ground": mechanism.ground,
        "degrees_of_freedom": mechanism.degrees_of_freedom(),
        "drivers": len(mechanism.drivers),
    }
