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

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fabricate.arguments import path_argument, type_name
from fabricate.errors import SpecError
from fabricate.pipeline import BuildOutcome
from fabricate.spec import DesignSpec, check_design_name

if TYPE_CHECKING:
    from fabricate.mechanism import Mechanism

#: What :func:`build` returns: the pipeline's own result type (:class:`fabricate.pipeline.BuildOutcome`),
#: under the API's name. ``.passed``, ``.failures``, ``.not_checked``, ``.report``, ``.files``, ``.design`` and
#: ``.write(folder)``, the same object ``fabricate build`` writes from.
Build = BuildOutcome


def load(template: str | Path | Mapping[str, Any], process: str | Path | None = None) -> DesignSpec:
    """A validated design from a shipped template's name, a template path, or a dict of its tables.

    Parameters
    ----------
    template : str, Path or Mapping
        ``"finger_five_bar_ncg"``, ``"my_design.toml"``, or ``{"design": {...}, "process": {...}, ...}``
        (the TOML tables as Python values: strings, numbers, booleans, lists, tuples, numpy arrays and
        nested dicts; it is written out as TOML text so the build's report embeds a template that
        ``fabricate check`` can rebuild).
    process : str or Path, optional
        ``"sla"``, ``"laser"`` or a profile file: replaces the template's process (``--process``).

    Raises
    ------
    SpecError
        On the first invalid field, naming it; an argument of the wrong type names the argument
        (``template``, ``process``) or, inside a dict, the value's path.
    """
    from fabricate.design import design_from_text, load_design
    from fabricate.process import process_override

    if process is not None:
        process = str(path_argument(process, "process", '"sla", "laser" or a process profile file'))
    if isinstance(template, Mapping):
        from fabricate.tomlwrite import dumps

        tables = _toml_value(template, "")
        design = tables.get("design")
        name = design.get("name") if isinstance(design, dict) else None
        # the file name only labels the report; the name itself is validated as design.name
        label = f"{name}.toml" if isinstance(name, str) and name and "\0" not in name else "design.toml"
        override = process_override(process) if process is not None else None
        return design_from_text(dumps(tables), Path(label).name or "design.toml", override)
    if not isinstance(template, (str, os.PathLike)):
        raise SpecError("template", "expected a shipped template's name, a template path or a dict of its tables, "
                                    f"got {type_name(template)}")
    return load_design(path_argument(template, "template", "a template name or path"), process)


def from_mechanism(mechanism: Mechanism, *, process: str = "sla", tip_point: str | None = None,
                   pads: Mapping[str, Mapping[str, Any]] | None = None,
                   tables: Mapping[str, Any] | None = None) -> DesignSpec:
    """A design from a :class:`~fabricate.mechanism.Mechanism` built in code.

    The mechanism is written as the exact form of a ``kind = "linkage"`` template (bodies in their own
    frames, every law by its coefficients; see :mod:`fabricate.synthesis.linkage.exact`) and validated like
    one, so the build is of this very mechanism and its report embeds a template ``fabricate check`` can
    rebuild.

    Parameters
    ----------
    mechanism : Mechanism
        It must carry ``assembly``: for every body but the ground, its frame's world pose
        ``(x_mm, y_mm, angle_rad)`` at ``input_range[0]``, e.g.
        ``Mechanism(..., assembly={"crank": (0.0, 0.0, 1.05), "coupler": (7.5, 13.0, 0.2), ...})``.
        The pose solver starts from it, so it picks the assembly branch (elbow up or down); it need only be
        near the true pose. A body drawn in world coordinates at the first pose has ``(0.0, 0.0, 0.0)``.
    process : str
        Process profile, ``"sla"`` or ``"laser"``.
    tip_point : str, optional
        The output point (a point name of a body).
    pads : Mapping, optional
        Fingertip pads, ``{body: {"point": name, "radius_mm": r}}`` (the fields of
        :class:`~fabricate.hints.PadHint`).
    tables : Mapping, optional
        More template tables: ``{"load": {...}, "parts": {...}, "checks": {...}}``.

    Raises
    ------
    SpecError
        ``mechanism`` is not a Mechanism, or its ``assembly`` lacks a body (``mechanism.assembly``), or an
        argument has the wrong type (naming it), or the written template is invalid (naming the field).
    """
    from fabricate.mechanism import Mechanism
    from fabricate.synthesis.linkage.exact import exact_linkage, read_hints
    from fabricate.table import Table

    if not isinstance(mechanism, Mechanism):
        raise SpecError("mechanism", f"expected a fabricate.mechanism.Mechanism, got {type_name(mechanism)}")
    if not isinstance(mechanism.name, str):
        raise SpecError("mechanism.name", f"expected a name (str), got {type_name(mechanism.name)}")
    check_design_name(mechanism.name, "mechanism.name")  # it becomes design.name, the output folder's name
    _check_assembly(mechanism)
    if not isinstance(process, str):
        raise SpecError("process", f'expected "sla" or "laser", got {type_name(process)}')
    if tip_point is not None and not isinstance(tip_point, str):
        raise SpecError("tip_point", f"expected a point name (str), got {type_name(tip_point)}")
    for arg, value in (("pads", pads), ("tables", tables)):
        if value is not None and not (isinstance(value, Mapping)
                                      and all(isinstance(v, Mapping) for v in value.values())):
            raise SpecError(arg, f"expected a dict of tables ({{name: {{...}}}}), got {type_name(value)}")
    pads, tables = (_toml_value(value, arg) if value is not None else None
                    for arg, value in (("pads", pads), ("tables", tables)))
    template: dict[str, Any] = {"design": {"name": mechanism.name, "kind": "linkage"},
                                "process": {"profile": process}}
    for key, value in (tables or {}).items():
        template[key] = dict(value) if key != "process" else {**template["process"], **value}
    raw_hints: dict[str, Any] = {}
    if tip_point:
        raw_hints["tip_point"] = tip_point
    if pads:
        raw_hints["pads"] = pads
    hints = read_hints(Table(raw_hints))  # a bad pad names its argument: "pads.<body>.radius_mm"
    try:
        linkage, exact = exact_linkage(mechanism, hints)
    except SpecError:
        raise
    except (TypeError, ValueError) as exc:  # a point, range or law that holds no numbers
        raise SpecError("mechanism", f"cannot be written as a template: {exc}") from None
    if not exact:
        raise SpecError("mechanism", "a law of this mechanism is neither linear nor a piecewise polynomial "
                                     "(scipy PPoly: CubicSpline, PchipInterpolator, ...): it cannot be written "
                                     "exactly")
    template["linkage"] = linkage
    return load(template)


def _check_assembly(mechanism: Mechanism) -> None:
    """Every moving body has a first-pose guess of three finite numbers, else a :class:`SpecError` saying
    what to pass (the pose solver has no other way to know which assembly branch is meant)."""
    import math

    assembly = mechanism.assembly
    moving = [b.name for b in mechanism.bodies if b.name != mechanism.ground]
    example = f'Mechanism(..., assembly={{"{moving[0] if moving else "body"}": (x_mm, y_mm, angle_rad), ...}})'
    if not isinstance(assembly, Mapping):
        raise SpecError("mechanism.assembly", f"expected a dict of body name -> (x_mm, y_mm, angle_rad), got "
                                              f"{type_name(assembly)}; pass {example}")
    missing = [name for name in moving if name not in assembly]
    if missing:
        more = f" (nor for {', '.join(map(repr, missing[1:]))})" if len(missing) > 1 else ""
        example = example.replace(f'"{moving[0]}"', f'"{missing[0]}"')
        raise SpecError("mechanism.assembly", f"no first pose for body {missing[0]!r}{more}: pass {example}, every "
                                              "moving body's frame position and angle in the world at "
                                              "input_range[0]; it picks the assembly branch and need only be "
                                              "near the true pose ((0.0, 0.0, 0.0) for a body drawn in world "
                                              "coordinates there)")
    for name, pose in assembly.items():
        try:
            values = [float(v) for v in pose]
        except (TypeError, ValueError, OverflowError):
            values = []
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            raise SpecError(f"mechanism.assembly.{name}", f"expected (x_mm, y_mm, angle_rad): three finite "
                                                          f"numbers, got {pose!r:.80}")


def build(design: DesignSpec | str | Path | Mapping[str, Any], process: str | Path | None = None, *,
          cache: bool = False, pictures: bool = True) -> Build:
    """Run the whole pipeline in memory.

    Parameters
    ----------
    design : DesignSpec, str, Path, Mapping or Mechanism
        What :func:`load` takes, a design it returned, or a :class:`~fabricate.mechanism.Mechanism`
        (through :func:`from_mechanism` with its defaults).
    process : str or Path, optional
        ``"sla"``, ``"laser"`` or a profile file: replaces the design's process (``--process``).
    cache : bool
        Reuse (and store) stage results in the stage cache, as ``fabricate build`` does (:mod:`fabricate.cache`:
        an edit of one table reruns only the stages that read it; the files are the same bytes either way).
        Off by default here: a library call writes nothing to the user's cache folder unless asked.
    pictures : bool
        Draw the pictures and plots (PNG, GIF); False leaves them out, as ``fabricate build --no-pictures``
        does (every other file the same bytes but report.json, report.md and assembly.md).

    Raises
    ------
    SpecError, SynthesisError
        Bad input or nothing feasible (the CLI's exit code 2); an argument of the wrong type names it.
    """
    from fabricate.cache import use_cache
    from fabricate.mechanism import Mechanism
    from fabricate.pipeline import run_build

    if isinstance(design, Mechanism):
        design = from_mechanism(design)
    elif not isinstance(design, DesignSpec):
        if not isinstance(design, (str, os.PathLike, Mapping)):
            raise SpecError("design", "expected what fabricate.load takes (a template name, path or dict of tables), "
                                      f"a design it returned, or a Mechanism; got {type_name(design)}")
        design, process = load(design, process), None
    if process is not None:
        from fabricate.design import design_from_text
        from fabricate.process import process_override

        override = process_override(str(path_argument(process, "process", '"sla", "laser" or a process profile file')))
        design = design_from_text(design.template_text, design.template, override)
    for name, flag in (("cache", cache), ("pictures", pictures)):
        if not isinstance(flag, bool):
            raise SpecError(name, f"expected True or False, got {type_name(flag)}")
    with use_cache(cache):
        return run_build(design, pictures=pictures)


#: Deepest nesting of a dict of tables (a template's deepest is a few levels; a cycle would recurse forever).
MAX_TABLE_DEPTH = 32


def _toml_value(value: Any, path: str, depth: int = 0) -> Any:
    """``value`` as plain TOML values (tuples and numpy arrays as lists, numpy scalars as numbers), or a
    :class:`SpecError` at ``path`` for anything TOML cannot hold."""
    if depth > MAX_TABLE_DEPTH:
        raise SpecError(path, f"nested more than {MAX_TABLE_DEPTH} levels deep (a table that holds itself?)")
    import numpy as np

    if isinstance(value, Mapping):
        out = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise SpecError(path or "template", f"expected text keys, got {type_name(key)}")
            where = f"{path}.{key}" if path else key
            out[_text(key, where)] = _toml_value(item, where, depth + 1)
        return out
    if isinstance(value, str):
        return _text(value, path)
    if isinstance(value, bool) or isinstance(value, float):
        return value
    if isinstance(value, int):
        if not -2**63 <= value < 2**63:
            raise SpecError(path, f"expected a number, got an integer beyond 64 bits ({value.bit_length()} bits)")
        return value
    if isinstance(value, (np.ndarray, np.generic)):
        return _toml_value(value.tolist(), path, depth)
    if isinstance(value, (list, tuple)):
        return [_toml_value(item, f"{path}[{i}]", depth + 1) for i, item in enumerate(value)]
    raise SpecError(path or "template", "expected a TOML value (string, number, boolean, list or table), got "
                                        f"{type_name(value)}")


def _text(value: str, path: str) -> str:
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise SpecError(path, f"expected UTF-8 text, got {value!r:.60} (a lone surrogate)") from None
    return value
