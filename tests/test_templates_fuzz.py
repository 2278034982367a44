"""Mutated shipped templates: every outcome is an exit code (0, 1, 2), never a traceback.

Values are scaled by random factors (0, negative, 1e9, 1e300), replaced by inf / nan or by values of
another type (string, list, bool, table), keys are deleted and byte noise is inserted into the TOML
text. Each mutation must end in ``main([...])`` returning 0, 1 or 2, with no "Traceback" and no
"internal error" (errors are named where they arise, not by the CLI's catch-all), in bounded time.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fabricate.cli import main
from fabricate.templates import parse_toml, shipped_templates
from tests.toml_writer import toml_text

TEMPLATES = {p.name: p.read_text(encoding="utf-8") for p in shipped_templates()}
#: A build that validates can still take the whole pipeline (a few seconds to ~20 s of CPU). The bound is on
#: this process's CPU time: busy cores stretch the wall time of a build, not its CPU time.
MAX_SECONDS = 120.0


def _leaves(d: dict[str, Any], prefix: tuple = ()) -> list[tuple]:
    """Paths (keys and list indices) of every scalar in a parsed template."""
    out = []
    items = d.items() if isinstance(d, dict) else enumerate(d)
    for k, v in items:
        if isinstance(v, (dict, list)):
            out += _leaves(v, prefix + (k,))
            if isinstance(v, list):
                out.append(prefix + (k,))
        else:
            out.append(prefix + (k,))
    return out


def _set(d: Any, path: tuple, value: Any) -> None:
    for k in path[:-1]:
        d = d[k]
    d[path[-1]] = value


def _delete(d: Any, path: tuple) -> None:
    for k in path[:-1]:
        d = d[k]
    if isinstance(d, dict):
        del d[path[-1]]
    else:
        d.pop(path[-1])


def _get(d: Any, path: tuple) -> Any:
    for k in path:
        d = d[k]
    return d


FACTORS = [0.0, -1.0, 1e9, 1e300, 1e-9, 0.5, 2.0, 10.0]
SPECIALS = [math.inf, -math.inf, math.nan, "x", [1.0, 2.0], True, {"a": 1}, "1e300", -1]


@st.composite
def mutated(draw: st.DrawFn) -> str:
    name = draw(st.sampled_from(sorted(TEMPLATES)))
    text = TEMPLATES[name]
    kind = draw(st.sampled_from(["scale", "special", "delete", "noise", "scale", "special"]))
    if kind == "noise":
        data = text.encode("utf-8")
        pos = draw(st.integers(0, len(data)))
        noise = draw(st.binary(min_size=1, max_size=8))
        return (data[:pos] + noise + data[pos:]).decode("utf-8", errors="replace")
    data = parse_toml(text, name)
    leaves = [p for p in _leaves(data) if p[0] != "design"]
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(leaves))
        try:
            current = _get(data, path)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed or replaced its parent
        if kind == "delete":
            _delete(data, path)
            leaves = [p for p in _leaves(data) if p[0] != "design"]
            if not leaves:
                break
        elif kind == "scale" and isinstance(current, (int, float)) and not isinstance(current, bool):
            factor = draw(st.sampled_from(FACTORS))
            scaled = current * factor
            _set(data, path, int(scaled) if isinstance(current, int) and abs(scaled) < 2**63 else scaled)
        else:
            _set(data, path, draw(st.sampled_from(SPECIALS)))
    return toml_text(data)


@pytest.mark.slow
@settings(max_examples=30, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(text=mutated())
def test_mutated_templates_exit_with_a_code_and_no_traceback(text: str, tmp_path_factory, capsys,
                                                            shared_stage_cache) -> None:
    """The build runs as a user's does, with the stage cache on (the session's shared folder, which
    ``shipped_build`` fills with the unmutated templates): a stage whose inputs a mutation left alone is served
    (byte-identical to running it, per tests/test_cache.py), the stages that read the mutated value run, and the
    cache's keys see the hostile values too."""
    work = tmp_path_factory.mktemp("fuzz")
    template = Path(work) / "mutated.toml"
    template.write_text(text, encoding="utf-8")
    start = time.process_time()
    with shared_stage_cache():
        code = main(["build", str(template), "-o", str(Path(work) / "out"), "-q"])
    elapsed = time.process_time() - start
    captured = capsys.readouterr()
    assert code in (0, 1, 2), captured.err
    assert "Traceback" not in captured.out + captured.err
    assert "internal error" not in captured.err, captured.err
    assert elapsed < MAX_SECONDS


# -- issue 23: every numeric field of one template, and every text field of another, with the values a hostile
# user types: each ends in exit 2 naming the field (or a run, for free text), never exit 3 or a traceback ------

#: Never a valid number: past float's range as TOML integers, NaN and infinities as floats and as text, NUL,
#: control characters and a line separator.
NOT_NUMBERS = [10**400, -(10**400), math.nan, math.inf, -math.inf, "nan", "inf", "-inf", "1e400", "\0", "a\0b",
               "\x01\x1f\x7f", "1\u2028"]
#: Text with NUL, C0 and C1 controls, DEL, a line separator and non-characters, all valid TOML escapes.
HOSTILE_TEXT = "a\0b\x01\x1f\x7f\x85\u2028\ud7ff\ufffe c"


def _dotted(path: tuple) -> str:
    return "".join(f"[{k}]" if isinstance(k, int) else (f".{k}" if i else k) for i, k in enumerate(path))


def _run(main_args: list[str], capsys) -> tuple[int, str]:
    code = main(main_args)
    captured = capsys.readouterr()
    text = captured.out + captured.err
    assert "Traceback" not in text and "internal error" not in text, text
    return code, captured.err


@pytest.mark.slow
def test_every_numeric_field_refuses_what_is_not_a_finite_number(tmp_path, capsys):
    """finger_five_bar_ncg (41 numbers, lists included) x 13 values: 533 runs, all exit 2 naming the field."""
    data = parse_toml(TEMPLATES["finger_five_bar_ncg.toml"], "t")
    numeric = [p for p in _leaves(data) if isinstance(_get(data, p), (int, float))
               and not isinstance(_get(data, p), bool)]
    assert len(numeric) >= 40
    template, out = tmp_path / "t.toml", tmp_path / "out"
    for path in numeric:
        for value in NOT_NUMBERS:
            mutated = parse_toml(TEMPLATES["finger_five_bar_ncg.toml"], "t")
            _set(mutated, path, value)
            template.write_text(toml_text(mutated), encoding="utf-8")
            code, err = _run(["synth", str(template), "-o", str(out), "-q"], capsys)
            assert code == 2 and f"error: {_dotted(path)}: expected a" in err, (path, value, err)
            assert not out.exists()


def test_an_integer_too_long_to_read_is_invalid_toml(tmp_path, capsys):
    text = TEMPLATES["gear_pair_elliptic.toml"]
    assert "\nmodule_mm = 1.0\n" in text
    template = tmp_path / "t.toml"
    template.write_text(text.replace("\nmodule_mm = 1.0\n", f"\nmodule_mm = {'7' * 5000}\n"), encoding="utf-8")
    code, err = _run(["synth", str(template), "-o", str(tmp_path / "out"), "-q"], capsys)
    assert code == 2 and "invalid TOML: a number too long to read" in err, err


def test_every_text_field_takes_hostile_text_without_a_bug(tmp_path, capsys):
    """gear_pair_elliptic's 8 text fields hold NUL, controls and a line separator: a name or choice is refused
    naming its field (exit 2, nothing written, the NUL shown escaped); free text runs to its end."""
    data = parse_toml(TEMPLATES["gear_pair_elliptic.toml"], "t")
    text_fields = [p for p in _leaves(data) if isinstance(_get(data, p), str)]
    assert len(text_fields) >= 8
    ran = []
    for n, path in enumerate(text_fields):
        mutated = parse_toml(TEMPLATES["gear_pair_elliptic.toml"], "t")
        _set(mutated, path, HOSTILE_TEXT)
        template, out = tmp_path / f"t{n}.toml", tmp_path / f"out{n}"
        template.write_text(toml_text(mutated), encoding="utf-8")
        code, err = _run(["synth", str(template), "-o", str(out), "-q"], capsys)
        assert code in (0, 1, 2), err
        if code == 2:
            assert f"error: {_dotted(path)}:" in err and not out.exists(), (path, err)
            assert "\0" not in err  # a NUL is shown escaped, never written to the terminal by a name check
        else:
            ran.append(_dotted(path))
    # load.torque_body names a body: a build checks it against the mechanism's (synth has no load)
    assert ran == ["design.description", "load.torque_body", "load.source", "actuator.source"]


@pytest.mark.parametrize(("template", "path", "value", "needle"), [
    # a spring grid of k2 = 0 only holds nothing: the optimiser's "no point" was a bare ValueError (exit 3)
    ("gripper_compliant.toml", ("optimisation", "k2_Nmm_per_deg"), [0.0, 0.0, 1.0],
     "no point of the [optimisation] grid holds the object"),
    # a 0.14 mm crank locks at once: a zero-length stroke made the driver law's spline raise (exit 3)
    ("finger_underactuated.toml", ("push_rod", "crank_mm"), 0.14, "the finger does not close"),
])
def test_valid_but_hopeless_values_are_synthesis_errors(template, path, value, needle, tmp_path, capsys):
    """Found by scaling every numeric field of each kind's template by 0, -1, 1e6 and 1e-6 (synth stage):
    values inside every bound that leave synthesis nothing to find exit 2 saying what to change."""
    data = parse_toml(TEMPLATES[template], "t")
    _set(data, path, value)
    source, out = tmp_path / "t.toml", tmp_path / "out"
    source.write_text(toml_text(data), encoding="utf-8")
    code, err = _run(["synth", str(source), "-o", str(out), "-q"], capsys)
    assert code == 2 and needle in err, err
    assert not out.exists()
