"""What each stage of a build reads, as the key of its :mod:`fabricate.cache` entry.

Each function returns the values the stage reads, section by section; a stage that takes another's result takes
its key (the result is a function of it). Whole sections where a stage reads most of one, single fields where one
field is all a stage reads and the others are edited often. ``tests/test_cache.py`` traces the attributes each stage
reads from the design on every shipped template and fails when a stage reads a field its key leaves out.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from fabricate.cache import cached, enabled

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec


def synthesis_key(design: DesignSpec) -> tuple[Any, ...]:
    """Synthesis and the swept motion (``pipeline._synthesis_stage``).

    Reads: ``name`` (the mechanism's name), ``kind`` and ``method`` (the kind's own tables), ``checks.sweep_poses``
    (the motion's poses), ``gears`` (a gear pair's teeth and module give its mechanism) and ``actuator`` (the
    underactuated finger's push rod is drawn only when no actuator is placed). Not ``[process]``, ``[parts]``,
    ``[load]`` or the rest of ``[checks]``: synthesis is geometry of the kind's tables alone.
    """
    return ("synthesis", design.name, design.kind, design.method, design.checks.sweep_poses, design.gears,
            design.actuator)


def module_is_chosen(design: DesignSpec) -> bool:
    """Whether the gear stage chooses the module (``gears.module_mm`` left out or ``"auto"``): then it reads the
    process, the load and the checks too (:func:`fabricate.gears.auto.module_limits`)."""
    return getattr(design.gears, "module_mm", None) is None


def gears_key(design: DesignSpec) -> tuple[Any, ...]:
    """The gear pairs (``pipeline._make_gears``).

    Reads: the synthesis' result, ``gears``, ``process.chord_tolerance_mm`` (the flanks' polygonisation); with a
    chosen module also ``process`` (minimum feature, thickness, materials), ``load``, ``checks`` (the safety
    factor the teeth must keep), ``parts`` and ``actuator`` (the loads' statics).
    """
    key: tuple[Any, ...] = (synthesis_key(design), design.gears, design.process.chord_tolerance_mm)
    if module_is_chosen(design):
        key += (design.process, design.load, design.checks, design.parts, design.actuator)
    return key


#: ``[parts]`` fields only the plate or sheet layout reads: the exports' plates and sheets, and the checks' test that
#: each part fits on one. A part set, its pictures and its strength are the same whatever they are.
LAYOUT_FIELDS = ("plate_spacing_mm", "sheet_margin_mm", "sheet_spacing_mm")
#: ``[parts]`` fields only the previews read.
PREVIEW_FIELDS = ("preview_poses", "gif_frames")


def _parts_fields(design: DesignSpec, names: tuple[str, ...] | None) -> Any:
    """``[parts]``' ``(field, value)`` pairs named in ``names``, or (None) every other but the layout's and the
    previews'; None for a design without a ``[parts]`` table (a test's stand-in)."""
    parts = getattr(design, "parts", None)
    if parts is None:
        return None
    left_out = LAYOUT_FIELDS + PREVIEW_FIELDS
    return tuple((f.name, getattr(parts, f.name)) for f in dataclasses.fields(parts)
                 if (f.name in names if names is not None else f.name not in left_out))


def parts_key(design: DesignSpec) -> tuple[Any, ...]:
    """The part set (``pipeline._make_parts``), of the design after link sizing.

    Reads: the gear pairs (and through them the synthesis), ``parts`` but its layout and preview fields
    (:data:`LAYOUT_FIELDS`, :data:`PREVIEW_FIELDS`), ``process`` (thickness, clearances, compensation, retention,
    materials), ``gears`` (hub diameter), ``actuator`` (its mount and interface parts) and ``name``/``kind``. Not
    ``[load]`` or ``[checks]`` (only the link sizing reads them, and its width is in ``parts``).
    """
    return (gears_key(design), _parts_fields(design, None), design.process, design.gears, design.actuator,
            design.name, design.kind)


def exports_key(design: DesignSpec, with_step: bool) -> tuple[Any, ...]:
    """The part files, drawings and plates (``export_all`` in ``pipeline._export``): the part set's inputs, the
    layout's fields and whether STEP files are listed; the report's ``cut`` section is part of the result."""
    return (parts_key(design), _parts_fields(design, LAYOUT_FIELDS), bool(with_step))


def checks_key(design: DesignSpec) -> tuple[Any, ...]:
    """Interference, gear mesh and printability (``pipeline._check``): the part set and gear pairs,
    ``checks.min_clearance_mm`` (``sweep_poses`` is the motion's, in the synthesis key), ``process`` (in the part
    set's key) and the layout's fields (each part must fit on a plate or sheet). Not ``checks.min_safety_factor``
    (strength's) or ``[load]``."""
    return (clearance_key(design), _parts_fields(design, LAYOUT_FIELDS))


def clearance_key(design: DesignSpec) -> tuple[Any, ...]:
    """The clearance plot (``pipeline._plots``): the interference sweep's inputs, the part set's and
    ``checks.min_clearance_mm``; not the layout (which only the printability check reads)."""
    return (parts_key(design), design.checks.min_clearance_mm)


def pictures_key(design: DesignSpec, job: str, extra: Any = None) -> tuple[Any, ...]:
    """A picture job of the forked children (``pipeline._picture_jobs``): the synthesis figures read the synthesis
    only, the gear pictures the gear pairs, the guide pictures and STEP files the part set, the previews the part
    set and :data:`PREVIEW_FIELDS`."""
    if job == "synthesis_plots":
        return (synthesis_key(design),)
    if job == "gear_pictures":
        return (gears_key(design),)
    if job == "previews":
        return (parts_key(design), _parts_fields(design, PREVIEW_FIELDS), extra)
    return (parts_key(design), extra)


def strength_key(design: DesignSpec) -> tuple[Any, ...]:
    """The strength check (``pipeline._check_strength``) and its plot: the part set (with its gear pairs and the
    synthesis' hints), ``load`` and ``checks.min_safety_factor``; ``process`` (materials) is in the part set's
    key already."""
    return (parts_key(design), design.load, design.checks.min_safety_factor)


class SynthesisFigures:
    """A synthesis result's ``figures`` that can be pickled: the method's own drawing function where this process
    has it, else the figures stored under the synthesis' key, else (evicted) the synthesis run again for them.

    A method's figures are a closure over its intermediate results (not picklable); a cached result carries this
    in its place, and the figures themselves are the ``synthesis_plots`` entry.
    """

    def __init__(self, design: DesignSpec, draw: Callable[[], dict[str, bytes]] | None = None) -> None:
        self.design = design
        self._draw = draw

    def __getstate__(self) -> dict[str, Any]:
        return {"design": self.design}  # the closure stays in the process that made it

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.design = state["design"]
        self._draw = None

    def __call__(self) -> dict[str, bytes]:
        return cached("synthesis_plots", synthesis_key(self.design), self._figures)

    def _figures(self) -> dict[str, bytes]:
        if self._draw is not None:
            return self._draw()
        from fabricate.kinds import KINDS

        figures: dict[str, bytes] = KINDS[self.design.kind].synthesise(self.design).figures()
        return figures


def storable_synthesis(result: Any, design: DesignSpec) -> Any:
    """``result`` (a :class:`~fabricate.synthesis.base.SynthesisResult`) with :class:`SynthesisFigures` in place
    of its figures closure when the cache is on, so it can be stored; unchanged when it is off."""
    if not enabled():
        return result
    return dataclasses.replace(result, figures=SynthesisFigures(design, result.figures))


def sizing_key(design: DesignSpec) -> tuple[Any, ...]:
    """``parts.link_width_mm = "auto"`` (``pipeline._size_links``): the gear pairs, and every section the parts
    and the strength check read (it builds parts at each width tried and checks their strength)."""
    return (gears_key(design), design.parts, design.process, design.load, design.checks, design.actuator,
            design.name, design.kind)


def drive_key(design: DesignSpec) -> tuple[Any, ...]:
    """The drive check's plot (``pipeline._plots``): the strength check's inputs (its statics) and ``actuator``
    (the rating and margin drawn)."""
    return (strength_key(design), design.actuator)
