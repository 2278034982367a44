"""Sweep specifications: which template, which fields vary over which values, and what to collect.

A sweep spec is a TOML file with a ``[sweep]`` table (see ``templates/sweeps/`` and README.md)::

    [sweep]
    template = "finger_five_bar_ncg"        # a shipped name, or a path relative to this file
    stage = "synth"                          # "synth" or "build"
    sampling = "grid"                        # "grid", "lhs" or "sobol"
    samples = 64                             # lhs / sobol only
    seed = 0
    metrics = ["synthesis.pose_error_mm.max", "min(strength.parts[*].min_safety_factor)"]

    [vary]                                   # template field path -> values
    "finger.lengths_mm[0]" = "36.0:44.0:5"   # start:stop:count (grid); start:stop is a range for lhs/sobol
    "gears.module_mm" = [0.4, 0.5, 0.6]      # a list: these values (lhs/sobol pick among them)

    [set]                                    # fixed changes applied to every point
    "synthesis.select" = "least_pose_error"

Everything here is pure: the points are computed from the spec alone (the samplers are seeded), so the
same spec gives the same points on every machine with the same scipy.
"""

from __future__ import annotations

import contextlib
import copy
import difflib
import functools
import hashlib
import itertools
import json
import math
import re
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fabricate.errors import SpecError
from fabricate.sweep.paths import Metric, get_path, parse_metric, parse_path, set_path

STAGES = ("synth", "build")
SAMPLINGS = ("grid", "lhs", "sobol")

#: Bounds that keep a sweep's bookkeeping small next to its builds (a point costs seconds of CPU).
MAX_POINTS = 100_000
MAX_FIELDS = 16
MAX_METRICS = 64
MAX_BEST = 20
MAX_VALUES_PER_FIELD = 10_000

#: Report sections that only a full build writes: a metric under one of them needs ``stage = "build"``.
BUILD_ONLY_SECTIONS = ("assembly", "bom", "gears", "interference", "parts", "strength", "notes")


@dataclass(frozen=True)
class Field:
    """One varied template field.

    Attributes
    ----------
    path : str
        Template field path, e.g. ``finger.lengths_mm[0]``; also the column name.
    values : tuple or None
        Explicit values (a list, or ``start:stop:count`` expanded); ``None`` for a continuous range.
    low, high : float
        The range of ``start:stop`` (lhs/sobol sample it continuously).
    integer : bool
        The template's value here is an integer: sampled values are rounded.
    """

    path: str
    parts: tuple[str | int, ...]
    values: tuple[Any, ...] | None = None
    low: float = math.nan
    high: float = math.nan
    integer: bool = False

    def at(self, u: float) -> Any:
        """The value at unit coordinate ``u`` in [0, 1) (lhs/sobol)."""
        if self.values is not None:
            return self.values[min(int(u * len(self.values)), len(self.values) - 1)]
        x = self.low + u * (self.high - self.low)
        return int(round(x)) if self.integer else float(x)


def check_finite(value: Any, where: str, depth: int = 0) -> None:
    """Refuse NaN and infinities anywhere in a sweep value (a list, a nested list or table): they cannot be
    a valid template value, and a point's values are written to JSON, which has no NaN."""
    if depth > 32:
        raise SpecError(where, "nested too deeply")
    if isinstance(value, float) and not math.isfinite(value):
        raise SpecError(where, f"expected finite values, got {value}")
    items = value.values() if isinstance(value, Mapping) else value if isinstance(value, (list, tuple)) else ()
    for item in items:
        check_finite(item, where, depth + 1)


_RANGE = re.compile(r"^\s*([^:]+):([^:]+)(?::([^:]+))?\s*$")


def parse_values(raw: Any, where: str, sampling: str, integer: bool) -> tuple[tuple[Any, ...] | None, float, float]:
    """Values of a ``[vary]`` entry: a list, or ``"start:stop:count"`` (grid), ``"start:stop"`` (lhs/sobol).

    Returns ``(values, low, high)``: explicit values, or ``None`` and a continuous range.
    """
    if isinstance(raw, list):
        if not raw:
            raise SpecError(where, "expected at least one value, got an empty list")
        if len(raw) > MAX_VALUES_PER_FIELD:
            raise SpecError(where, f"at most {MAX_VALUES_PER_FIELD} values, got {len(raw)}")
        check_finite(raw, where)
        return tuple(raw), math.nan, math.nan
    if isinstance(raw, str):
        m = _RANGE.match(raw)
        if m:
            try:
                start, stop = float(m.group(1)), float(m.group(2))
            except ValueError:
                raise SpecError(where, f'expected numbers in "start:stop[:count]", got "{raw}"') from None
            if not (math.isfinite(start) and math.isfinite(stop)):
                raise SpecError(where, f'expected finite numbers in "start:stop[:count]", got "{raw}"')
            count_text = m.group(3)
            if sampling == "grid":
                if count_text is None:
                    raise SpecError(where, f'a grid needs a count: "start:stop:count", got "{raw}"')
                try:
                    count = int(count_text)
                except ValueError:
                    raise SpecError(where, f'count must be a whole number, got "{count_text}"') from None
                if not 1 <= count <= MAX_VALUES_PER_FIELD:
                    raise SpecError(where, f"count must be in 1 .. {MAX_VALUES_PER_FIELD}, got {count}")
                with np.errstate(over="ignore", invalid="ignore"):
                    grid = np.linspace(start, stop, count) if count > 1 else np.array([start])
                if not np.all(np.isfinite(grid)):  # stop - start overflows past 1.8e308
                    raise SpecError(where, f'"{raw}" spans more than a float can hold')
                values = tuple(int(round(v)) for v in grid) if integer else tuple(float(v) for v in grid)
                return values, math.nan, math.nan
            if stop < start:
                raise SpecError(where, f'expected start <= stop in "{raw}"')
            if not math.isfinite(stop - start):
                raise SpecError(where, f'"{raw}" spans more than a float can hold')
            return None, start, stop
    raise SpecError(where, f'expected a list of values or "start:stop:count", got {raw!r}')


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep.

    Attributes
    ----------
    name : str
        Names the default output folder ``outputs/<name>-sweep/``.
    template_text : str
        The base template's text; ``template`` is where it came from.
    base : dict
        The base template's tables with ``[set]`` applied (every point starts from a deep copy).
    fields : tuple of Field
    sampling, samples, seed, stage
    metrics : tuple of Metric
    best, best_metric, best_goal
        Build the ``best`` points in full, ranked by ``best_metric`` (``"min"`` or ``"max"``), among the
        points that pass every check.
    map_fields : tuple of str
        The two fields of the feasibility map.
    batch_seconds : float
        Target run time of one Dask task (points are batched to about this).
    """

    name: str
    template: str
    template_text: str
    base: dict[str, Any]
    fields: tuple[Field, ...]
    sampling: str = "grid"
    samples: int = 0
    seed: int = 0
    stage: str = "synth"
    metrics: tuple[Metric, ...] = ()
    best: int = 0
    best_metric: Metric | None = None
    best_goal: str = "min"
    map_fields: tuple[str, ...] = ()
    batch_seconds: float = 1.0
    sets: dict[str, Any] = field(default_factory=dict)

    def points(self) -> list[dict[str, Any]]:
        """Every point as ``{field path: value}``, in a fixed order (the grid's last field varies
        fastest; lhs/sobol in the sampler's order)."""
        if self.sampling == "grid":
            grid = [f.values for f in self.fields if f.values is not None]
            assert len(grid) == len(self.fields)  # a grid's every field has its values (parse_values)
            combos = itertools.product(*grid)
            return [dict(zip((f.path for f in self.fields), combo, strict=True)) for combo in combos]
        unit = unit_samples(self.sampling, len(self.fields), self.samples, self.seed)
        return [{f.path: f.at(float(u[j])) for j, f in enumerate(self.fields)} for u in unit]

    def count(self) -> int:
        """How many points, without making them."""
        if self.sampling == "grid":
            return math.prod(len(f.values or ()) for f in self.fields)
        return self.samples

    def point_template(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """The base template's tables with one point's values set."""
        data = copy.deepcopy(self.base)
        for f in self.fields:
            set_path(data, f.parts, copy.deepcopy(values[f.path]))
        return data

    @functools.cached_property
    def digest(self) -> str:
        """What every point shares: the base tables (with ``[set]``), the stage and the metrics."""
        blob = json.dumps({"base": self.base, "stage": self.stage, "metrics": [m.name for m in self.metrics]},
                          sort_keys=True, default=str)
        return hashlib.sha256(blob.encode()).hexdigest()

    def point_id(self, values: Mapping[str, Any]) -> str:
        """A point's identity (its row's ``id``): the shared digest and its values. A resumed sweep skips the
        points whose id is done."""
        blob = json.dumps([self.digest, [[f.path, values[f.path]] for f in self.fields]], default=str)
        return hashlib.sha256(blob.encode()).hexdigest()[:16]

    def field_parts(self) -> list[tuple[str, tuple[str | int, ...]]]:
        return [(f.path, f.parts) for f in self.fields]

    def describe(self) -> dict[str, Any]:
        """The spec as plain values (sweep.json; two runs resume each other only when these are equal)."""
        out: dict[str, Any] = {
            "name": self.name, "template": self.template, "stage": self.stage, "sampling": self.sampling,
            "seed": self.seed, "samples": self.count(),
            "vary": {f.path: (list(f.values) if f.values is not None else f"{f.low!r}:{f.high!r}")
                     for f in self.fields},
            "set": self.sets, "metrics": [m.name for m in self.metrics],
            "best": {"count": self.best, "metric": self.best_metric.name if self.best_metric else None,
                     "goal": self.best_goal},
            "map": list(self.map_fields),
        }
        return out


def unit_samples(sampling: str, dims: int, n: int, seed: int) -> np.ndarray:
    """``(n, dims)`` points in the unit cube: a Latin hypercube or a scrambled Sobol' sequence (scipy.stats.qmc),
    seeded so the same spec gives the same points."""
    from scipy.stats import qmc

    engine_type = qmc.LatinHypercube if sampling == "lhs" else qmc.Sobol
    try:  # scipy >= 1.15 names the generator `rng`; older releases `seed`
        engine = engine_type(d=dims, rng=np.random.default_rng(seed))
    except TypeError:
        engine = engine_type(d=dims, seed=np.random.default_rng(seed))
    if sampling == "sobol":
        return engine.random_base2(int(round(math.log2(n))))
    return engine.random(n)


def _int(t: Mapping[str, Any], key: str, default: int, lo: int, hi: int) -> int:
    v = t.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int):
        raise SpecError(f"sweep.{key}", f"expected a whole number, got {v!r}")
    if not lo <= v <= hi:
        raise SpecError(f"sweep.{key}", f"must be in {lo} .. {hi}, got {v}")
    return v


def _choice(t: Mapping[str, Any], key: str, default: str, choices: Sequence[str]) -> str:
    v = t.get(key, default)
    if v not in choices:
        raise SpecError(f"sweep.{key}", f"expected one of {', '.join(map(repr, choices))}, got {v!r}")
    return str(v)


_SWEEP_KEYS = {"name", "template", "stage", "sampling", "samples", "seed", "metrics", "best", "best_metric",
               "best_goal", "map", "batch_seconds"}


def default_metrics(stage: str) -> list[str]:
    """Collected when a sweep names none: the verdicts every kind of design reports."""
    if stage == "build":
        return ["interference.min_clearance_mm", "min(strength.parts[*].min_safety_factor)"]
    return []


def sweep_from_tables(tables: Mapping[str, Any], base_dir: Path | None = None, *,
                      origins: Mapping[str, str] | None = None) -> SweepSpec:
    """Validate a sweep spec's tables (``[sweep]``, ``[vary]``, ``[set]``); :class:`SpecError` names the field.

    ``base_dir`` is where a relative ``sweep.template`` path is looked for first. ``origins`` says how the
    user gave the entries that did not come from the file: with ``{"vary.gears.module_mm": "--vary
    gears.module_mm"}`` an error in that entry ends "(given as --vary gears.module_mm)".
    """
    origins = origins or {}
    sweep = _sweep_table(tables)
    template_arg, path, text, base = _base_template(sweep, base_dir)
    stage = _choice(sweep, "stage", "synth", STAGES)
    sampling = _choice(sweep, "sampling", "grid", SAMPLINGS)
    seed = _int(sweep, "seed", 0, 0, 2**32 - 1)
    samples = _samples(sweep, sampling)
    sets = _sets(tables, base, origins)
    fields = _fields(tables, base, sets, sampling, origins, str(path))
    count = math.prod(len(f.values or ()) for f in fields) if sampling == "grid" else samples
    if count > MAX_POINTS:
        raise SpecError("vary", f"the sweep has {count} points; at most {MAX_POINTS}")
    metrics = _metrics(sweep, stage, fields)
    best, best_metric, best_goal = _best(sweep, metrics)
    map_raw = _map_fields(sweep, fields)
    batch = sweep.get("batch_seconds", 1.0)
    if isinstance(batch, bool) or not isinstance(batch, (int, float)) or not 0.01 <= batch <= 600:
        raise SpecError("sweep.batch_seconds", f"expected a number of seconds in 0.01 .. 600, got {batch!r}")
    name = sweep.get("name", Path(str(template_arg)).stem)
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}", name):
        raise SpecError("sweep.name", f"expected a plain name (letters, digits, _ . -), got {name!r}")
    return SweepSpec(name=name, template=str(template_arg), template_text=text, base=base, fields=tuple(fields),
                     sampling=sampling, samples=samples, seed=seed, stage=stage, metrics=metrics, best=best,
                     best_metric=best_metric, best_goal=best_goal, map_fields=tuple(map_raw),
                     batch_seconds=float(batch), sets=sets)


def _sweep_table(tables: Mapping[str, Any]) -> Mapping[str, Any]:
    """The ``[sweep]`` table, once the spec has no unknown table and it no unknown field."""
    if not isinstance(tables, Mapping):
        raise SpecError("", f"expected the tables of a sweep spec, got {type(tables).__name__}")
    unknown = sorted(str(k) for k in set(tables) - {"sweep", "vary", "set"})
    if unknown:
        raise SpecError(unknown[0], "unknown table (a sweep spec has [sweep], [vary] and [set])")
    sweep = tables.get("sweep")
    if not isinstance(sweep, Mapping):
        raise SpecError("sweep", "missing table [sweep]")
    bad = sorted(str(k) for k in set(sweep) - _SWEEP_KEYS)
    if bad:
        close = difflib.get_close_matches(bad[0], sorted(_SWEEP_KEYS), n=1)
        raise SpecError(f"sweep.{bad[0]}", "unknown field" + (f' (did you mean "{close[0]}"?)' if close else ""))
    return sweep


def _base_template(sweep: Mapping[str, Any], base_dir: Path | None) -> tuple[str, Path, str, dict[str, Any]]:
    """``sweep.template`` as given, the file it names (looked for in ``base_dir`` first), its text and its
    tables; the template must be valid by itself."""
    from fabricate.design import design_from_text
    from fabricate.templates import find_template, parse_toml, path_kind, read_text

    template_arg = sweep.get("template")
    if not isinstance(template_arg, str) or not template_arg:
        raise SpecError("sweep.template", "expected the base template's name or path")
    candidate = (base_dir / template_arg) if base_dir is not None else None
    path = candidate if candidate is not None and path_kind(candidate, "sweep.template") == "file" \
        else find_template(template_arg)
    text = read_text(path)
    design_from_text(text, path)  # the base template must be valid by itself
    return template_arg, path, text, parse_toml(text, str(path))


def _samples(sweep: Mapping[str, Any], sampling: str) -> int:
    """``sweep.samples``: 0 for a grid (its values set its size); a power of two for Sobol'."""
    if sampling == "grid":
        if "samples" in sweep:
            raise SpecError("sweep.samples", "a grid's size is set by its values; samples is for lhs/sobol")
        return 0
    samples = _int(sweep, "samples", 64, 1, MAX_POINTS)
    if sampling == "sobol" and samples & (samples - 1):
        raise SpecError("sweep.samples", f"a Sobol' sequence keeps its balance only with a power of two "
                                         f"points (e.g. {1 << max(0, samples.bit_length() - 1)} or "
                                         f"{1 << samples.bit_length()}), got {samples}")
    return samples


def _sets(tables: Mapping[str, Any], base: dict[str, Any], origins: Mapping[str, str]) -> dict[str, Any]:
    """``[set]``: each a field of the template, applied to ``base`` (in place)."""
    sets_raw = tables.get("set", {})
    if not isinstance(sets_raw, Mapping):
        raise SpecError("set", "expected a table of field path = value")
    sets: dict[str, Any] = {}
    for key, value in sets_raw.items():
        where = f"set.{key}"
        with _given_as(origins.get(where), where):
            check_finite(value, where)
            try:
                parts = parse_path(key)
                set_path(base, parts, copy.deepcopy(value))
            except (ValueError, KeyError) as exc:
                raise SpecError(where, f"not a field of the template ({exc})") from None
        sets[key] = value
    return sets


def _fields(tables: Mapping[str, Any], base: dict[str, Any], sets: Mapping[str, Any], sampling: str,
            origins: Mapping[str, str], source: str) -> list[Field]:
    """``[vary]``: the varied fields, each a field of the template (or one its kind knows) not also set."""
    vary = tables.get("vary")
    if not isinstance(vary, Mapping) or not vary:
        raise SpecError("vary", "expected a table of field path = values, with at least one field")
    if len(vary) > MAX_FIELDS:
        raise SpecError("vary", f"at most {MAX_FIELDS} fields, got {len(vary)}")
    fields: list[Field] = []
    for key, raw in vary.items():
        where = f"vary.{key}"
        with _given_as(origins.get(where), where):
            try:
                parts = parse_path(key)
            except ValueError as exc:
                raise SpecError(where, str(exc)) from None
            if key in sets:
                raise SpecError(where, "is also in [set]: a field is either varied or set")
            try:
                current = get_path(base, parts)
            except KeyError:
                current = None
                try:  # a field the template leaves at its default: the table (or list) above it must exist
                    get_path(base, parts[:-1]) if len(parts) > 1 else None
                except KeyError:
                    raise SpecError(where, "not a field of the template (its table or list is not there)") from None
                if isinstance(parts[-1], int):
                    raise SpecError(where, "the list has no such element (a sweep never grows a list)") from None
            integer = isinstance(current, int) and not isinstance(current, bool)
            values, low, high = parse_values(raw, where, sampling, integer)
            fields.append(Field(path=key, parts=parts, values=values, low=low, high=high, integer=integer))
            if current is None:
                _check_known(base, fields[-1], where, source)
    return fields


def _metrics(sweep: Mapping[str, Any], stage: str, fields: Sequence[Field]) -> tuple[Metric, ...]:
    """``sweep.metrics``: report key paths, each once, none a column's name, none a full build's in a synth."""
    metrics_raw = sweep.get("metrics", default_metrics(stage))
    if not isinstance(metrics_raw, list) or len(metrics_raw) > MAX_METRICS:
        raise SpecError("sweep.metrics", f"expected a list of at most {MAX_METRICS} report key paths")
    metrics = tuple(parse_metric(m, f"sweep.metrics[{i}]") for i, m in enumerate(metrics_raw))
    names = [m.name for m in metrics]
    if len(set(names)) != len(names):
        raise SpecError("sweep.metrics", "a metric is listed twice")
    for i, m in enumerate(metrics):
        if m.name in {f.path for f in fields} or m.name in ("point", "id", "exit_code", "reason"):
            raise SpecError(f"sweep.metrics[{i}]", f'"{m.name}" is also the name of another column')
        if stage == "synth" and m.section in BUILD_ONLY_SECTIONS:
            raise SpecError(f"sweep.metrics[{i}]", f'"{m.name}" is written by a full build only: set '
                                                   'sweep.stage = "build" (or --stage build)')
    return metrics


def _best(sweep: Mapping[str, Any], metrics: Sequence[Metric]) -> tuple[int, Metric | None, str]:
    """How many best points to rank (``sweep.best``), by which metric, and its goal (``min`` or ``max``)."""
    best = _int(sweep, "best", 0, 0, MAX_BEST)
    best_metric = None
    best_goal = _choice(sweep, "best_goal", "min", ("min", "max"))
    if best:
        if "best_metric" in sweep:
            best_metric = parse_metric(sweep["best_metric"], "sweep.best_metric")
            if best_metric.name not in [m.name for m in metrics]:
                raise SpecError("sweep.best_metric", f'"{best_metric.name}" is not one of sweep.metrics')
        elif metrics:
            best_metric = metrics[0]
        else:
            raise SpecError("sweep.best", "ranking the best points needs a metric (sweep.metrics)")
    return best, best_metric, best_goal


def _map_fields(sweep: Mapping[str, Any], fields: Sequence[Field]) -> list[Any]:
    """``sweep.map``: the feasibility map's two axes, different varied numeric fields (the first two by
    default), or none."""
    numeric = [f.path for f in fields if _is_numeric(f)]
    map_raw = sweep.get("map", numeric[:2] if len(numeric) >= 2 else [])
    if not isinstance(map_raw, list) or len(map_raw) not in (0, 2):
        raise SpecError("sweep.map", "expected two varied field paths (the feasibility map's axes)")
    for i, path in enumerate(map_raw):
        if path not in numeric:
            raise SpecError(f"sweep.map[{i}]", f'"{path}" is not a varied numeric field')
    if len(map_raw) == 2 and map_raw[0] == map_raw[1]:
        raise SpecError("sweep.map", "the two axes must be different fields")
    return map_raw


@contextlib.contextmanager
def _given_as(origin: str | None, where: str) -> Iterator[None]:
    """An error in entry ``where`` also says how the user gave it (``--vary gears.module_mm``) when that was
    not in the spec file."""
    try:
        yield
    except SpecError as exc:
        if origin is None or exc.path != where:
            raise
        raise SpecError(where, f"{exc.message} (given as {origin})") from None


def _check_known(base: dict[str, Any], f: Field, where: str, source: str) -> None:
    """A field the base template leaves at its default must be one the template's kind knows: set its first
    value and validate (a misspelt path would otherwise make every point an "unknown field" row)."""
    from fabricate.design import design_from_text
    from fabricate.tomlwrite import dumps

    data = copy.deepcopy(base)
    set_path(data, f.parts, f.values[0] if f.values is not None else f.at(0.0))
    try:
        design_from_text(dumps(data), source)
    except SpecError as exc:
        if exc.path == f.path and exc.message == "unknown field":
            raise SpecError(where, "not a field of the template (unknown field)") from None


def _is_numeric(f: Field) -> bool:
    if f.values is None:
        return True
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in f.values)


def find_sweep(path: str | Path) -> Path | None:
    """The sweep spec file ``path`` names (a path, or a shipped spec's name from ``templates/sweeps/``), or
    None when ``path`` is not a sweep spec (a design template, say)."""
    from fabricate.templates import TEMPLATE_DIR, parse_toml, path_kind, read_text

    if not isinstance(path, (str, Path)):
        raise SpecError("spec", "expected a sweep spec's name or path (str or pathlib.Path), got "
                                f"{type(path).__name__}")
    candidate = Path(path)
    if path_kind(candidate, "spec") != "file":
        stem = candidate.name[:-5] if candidate.name.endswith(".toml") else candidate.name
        shipped = TEMPLATE_DIR / "sweeps" / f"{stem}.toml"
        return shipped if candidate.parent == Path(".") and path_kind(shipped) == "file" else None
    try:
        return candidate if "sweep" in parse_toml(read_text(candidate), str(candidate)) else None
    except SpecError:
        return None


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and validate a sweep spec file (a path, or a shipped spec's name from ``templates/sweeps/``)."""
    from fabricate.templates import parse_toml, read_text

    source = find_sweep(path)
    if source is None:
        raise SpecError("", f"sweep spec not found: {path} (a TOML file with a [sweep] table)")
    return sweep_from_tables(parse_toml(read_text(source), str(source)), source.parent)


def _value(text: str, where: str, many: bool) -> Any:
    """A command-line value: TOML (``[1, 2]``, ``0.5``, ``"x"``), else ``a,b,c`` or a bare word."""
    from fabricate.templates import parse_toml

    try:
        return parse_toml(f"v = {text}", where)["v"]
    except SpecError:
        pass
    if many and ":" not in text and "," in text:
        return [_value(part.strip(), where, False) for part in text.split(",")]
    return text


def assignments(items: list[str], flag: str, many: bool) -> dict[str, Any]:
    """``--vary``/``--set`` items (``FIELD=VALUE``; ``many``: ``FIELD=VALUES``, a list or ``lo:hi:n``) as a table."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip() or not text.strip():
            raise SpecError(flag, f'expected FIELD=VALUE{"S" if many else ""}, got "{item}"')
        value = _value(text.strip(), f"{flag} {key.strip()}", many)
        if many and not isinstance(value, list) and not (isinstance(value, str) and ":" in value):
            value = [value]
        out[key.strip()] = value
    return out
