"""[actuator]: read into ActuatorSpec; every bad value is a SpecError naming its field (exit 2 through the CLI)."""

from __future__ import annotations

import pytest

from fabricate.catalogue.actuators import CATALOGUE
from fabricate.cli import main
from fabricate.design import design_from_text, load_design
from fabricate.drive.spec import ActuatorSpec, catalogue_keys, parse_actuator
from fabricate.errors import SpecError
from fabricate.table import Table
from fabricate.templates import TEMPLATE_DIR, parse_toml, shipped_templates
from fabricate.tomlwrite import dumps


def _parse(data: dict) -> ActuatorSpec | None:
    return parse_actuator(Table(data, "actuator"))


def test_a_servo_reads_with_its_defaults() -> None:
    spec = _parse({"model": "sg90"})
    assert spec == ActuatorSpec(model="sg90", margin=1.5, force_N=None, driver=0)
    assert spec.entry() is CATALOGUE["sg90"]


def test_no_table_is_no_actuator() -> None:
    assert _parse({}) is None


def test_a_tendon_is_rated_at_its_stated_force() -> None:
    spec = _parse({"model": "tendon", "force_N": 42.0, "stroke_mm": 12.0, "margin": 2.0})
    assert spec is not None
    entry = spec.entry()
    assert entry.rated_force_n == 42.0 and entry.stroke_mm == 12.0 and spec.margin == 2.0


def test_only_complete_catalogue_entries_are_offered() -> None:
    keys = catalogue_keys()
    assert "tendon" in keys and "sg90" in keys
    assert all(CATALOGUE[k].complete for k in keys if k != "tendon")


@pytest.mark.parametrize(("data", "field", "needle"), [
    ({"model": "sg9O"}, "actuator.model", "sg90"),  # the message lists the valid keys
    ({"model": 90}, "actuator.model", "string"),
    ({"margin": 2.0}, "actuator.model", "missing required field"),
    ({"model": "sg90", "margin": 0.9}, "actuator.margin", ">= 1"),
    ({"model": "sg90", "margin": 11.0}, "actuator.margin", "<= 10"),
    ({"model": "sg90", "force_N": 5.0}, "actuator.force_N", "only a 'tendon'"),
    ({"model": "tendon"}, "actuator.force_N", "needs the force"),
    ({"model": "tendon", "force_N": 0.0}, "actuator.force_N", "positive"),
    ({"model": "sg90", "driver": -1}, "actuator.driver", ">= 0"),
    ({"model": "sg90", "driver": 1.5}, "actuator.driver", "whole"),
    ({"model": "sg90", "torque": 3}, "actuator.torque", "unknown field"),
])
def test_bad_values_name_the_field(data: dict, field: str, needle: str) -> None:
    with pytest.raises(SpecError) as err:
        _parse(data)
    assert err.value.path == field
    assert needle in str(err.value)


def test_an_incomplete_catalogue_entry_is_refused_with_its_gaps() -> None:
    incomplete = [k for k, a in CATALOGUE.items() if not a.complete and k != "tendon"]
    if not incomplete:
        pytest.skip("every catalogue entry is complete")
    with pytest.raises(SpecError) as err:
        _parse({"model": incomplete[0]})
    assert err.value.path == "actuator.model" and "incomplete" in str(err.value)


def _with_actuator(actuator: dict) -> str:
    """The six-bar finger's template with ``[actuator]`` replaced."""
    data = parse_toml((TEMPLATE_DIR / "finger_watt_six_bar.toml").read_text(encoding="utf-8"), "t")
    data["actuator"] = actuator
    return dumps(data)


def test_the_design_carries_its_actuator() -> None:
    design = design_from_text(_with_actuator({"model": "mg90s", "margin": 2.5}), "x.toml")
    assert design.actuator == ActuatorSpec(model="mg90s", margin=2.5)


def test_a_bad_actuator_exits_2_naming_the_field_and_writes_nothing(tmp_path, capsys) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(_with_actuator({"model": "sg90", "margin": 0.5}), encoding="utf-8")
    out = tmp_path / "out"
    code = main(["build", str(path), "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 2
    assert "actuator.margin" in captured.err
    assert not out.exists()


@pytest.mark.parametrize("template", [p.stem for p in shipped_templates()])
def test_every_shipped_template_names_a_catalogue_actuator(template: str) -> None:
    spec = load_design(template).actuator
    assert spec is not None and spec.model in catalogue_keys() and spec.margin >= 1.5
    assert spec.source  # why this actuator, for people
