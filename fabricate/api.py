"""The Python API: the command line's pipeline as three calls.

.. code-block:: python

    import fabricate

    design = fabricate.load("finger_watt_six_bar")        # a shipped name, a path, or a dict of tables
    result = fabricate.build(design)                       # everything in memory, nothing written
    print(result.passed, result.report["strength"]["parts"][0])
    stl = result.files["parts/proximal.stl"]               # bytes, as the build would write them
    result.write("outputs/six_bar")                        # the same folder rules as `fabricate build -o`

``load`` validates like the CLI (a :class:`~fabricate.errors.SpecError` names the field); ``build`` runs
synthesis, gears, parts, exports, interference and strength, and returns a :class:`Build` whose files are
the bytes ``fabricate build`` writes (the same template gives the same bytes).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError
from fabricate.spec import DesignSpec


@dataclass(frozen=True)
class Build:
    """A finished build, in memory.

    Attributes
    ----------
    exit_code : int
        0 when every check passes, 1 when the design fails one (the files are still made): the CLI's code.
    report : dict
        report.json's content.
    files : Mapping[str, bytes]
        Every output file by its path relative to the output folder.
    design : DesignSpec
    """

    exit_code: int
    report: dict[str, Any]
    files: Mapping[str, bytes]
    design: DesignSpec
    outcome: Any = None

    @property
    def passed(self) -> bool:
        """Whether every check (interference, gears, printability, strength) passed."""
        return self.exit_code == 0

    @property
    def failures(self) -> list[str]:
        """Why the design fails, one line per failure (empty when it passes)."""
        return list(self.report.get("checks", {}).get("failures", []))

    def write(self, out: str | Path, *, force: bool = False) -> Path:
        """Write the files to folder ``out`` atomically, with the CLI's rules: ``out`` must be new, empty or
        a previous fabricate output; ``force`` replaces another folder (never a file, a link or the
        current folder). Returns the folder written."""
        from fabricate.output import check_output_dir, write_output

        protect = [Path(self.design.template)]
        check_output_dir(out, force=force, stage="build", protect=protect)
        return write_output(self.files, out, force=force, stage="build", protect=protect)


def load(template: str | Path | Mapping[str, Any], process: str | None = None) -> DesignSpec:
    """A validated design from a shipped template's name, a template path, or a dict of its tables.

    Parameters
    ----------
    template : str, Path or Mapping
        ``"finger_five_bar_ncg"``, ``"my_design.toml"``, or ``{"design": {...}, "process": {...}, ...}``
        (the TOML tables as Python values; it is written out as TOML text so the build's report embeds a
        template that ``fabricate check`` can rebuild).
    process : str, optional
        ``"sla"``, ``"laser"`` or a profile file: replaces the template's process (``--process``).

    Raises
    ------
    SpecError
        On the first invalid field, naming it.
    """
    from fabricate.spec import design_from_text, load_design, process_override

    if isinstance(template, Mapping):
        from fabricate.tomlwrite import dumps

        name = str(template.get("design", {}).get("name", "design"))
        override = process_override(process) if process is not None else None
        return design_from_text(dumps(template), f"{name}.toml", override)
    return load_design(template, process)


def from_mechanism(mechanism: Any, *, process: str = "sla", tip_point: str | None = None,
                   pads: Mapping[str, Mapping[str, Any]] | None = None,
                   tables: Mapping[str, Any] | None = None) -> DesignSpec:
    """A design from a :class:`~fabricate.mechanism.Mechanism` built in code: it is written as the exact
    form of a ``kind = "linkage"`` template (bodies in their own frames, every law by its coefficients;
    see :mod:`fabricate.synthesis.linkage.exact`) and validated like one, so the build is of this very
    mechanism and its report embeds a template ``fabricate check`` can rebuild.

    Parameters
    ----------
    mechanism : Mechanism
    process : str
        Process profile, ``"sla"`` or ``"laser"``.
    tip_point, pads
        The output point and fingertip pads (``{body: {"point": name, "radius_mm": r}}``).
    tables : Mapping, optional
        More template tables: ``{"load": {...}, "parts": {...}, "checks": {...}}``.
    """
    from fabricate.synthesis.linkage.exact import exact_linkage

    template: dict[str, Any] = {"design": {"name": mechanism.name, "kind": "linkage"},
                                "process": {"profile": process}}
    for key, value in (tables or {}).items():
        template[key] = dict(value) if key != "process" else {**template["process"], **value}
    hints: dict[str, Any] = {}
    if tip_point:
        hints["tip_point"] = tip_point
    if pads:
        hints["pads"] = {body: dict(pad) for body, pad in pads.items()}
    linkage, exact = exact_linkage(mechanism, hints)
    if not exact:
        raise SpecError("mechanism", "a law of this mechanism is neither linear nor a piecewise polynomial "
                                     "(scipy PPoly: CubicSpline, PchipInterpolator, ...): it cannot be written "
                                     "exactly")
    template["linkage"] = linkage
    return load(template)


def build(design: DesignSpec | str | Path | Mapping[str, Any]) -> Build:
    """Run the whole pipeline in memory (see :func:`load` for what ``design`` may be; a
    :class:`~fabricate.mechanism.Mechanism` goes through :func:`from_mechanism` with its defaults).

    Raises
    ------
    SpecError, SynthesisError
        Bad input or nothing feasible (the CLI's exit code 2).
    """
    from fabricate.mechanism import Mechanism
    from fabricate.pipeline import run_build

    if isinstance(design, Mechanism):
        design = from_mechanism(design)
    elif not isinstance(design, DesignSpec):
        design = load(design)
    outcome = run_build(design)
    return Build(exit_code=outcome.exit_code, report=outcome.report, files=dict(outcome.files), design=design,
                 outcome=outcome)
