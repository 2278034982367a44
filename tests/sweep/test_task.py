"""A sweep point's row says what its build did not check (issue 23 item 5), so a sweep's best point is
never one that passed only because nothing was checked."""

from __future__ import annotations

from fabricate.sweep.task import EXIT_OK, evaluate
from fabricate.tomlwrite import dumps
from tests.test_not_checked import _tables


def test_a_point_built_without_a_load_says_strength_was_not_checked() -> None:
    code, reason, report, _ = evaluate(dumps(_tables(load=False)), "build")
    assert code == EXIT_OK
    assert report is not None and report["strength"]["passed"] is None
    assert "strength not checked: no [load] in the template" in reason


def test_a_checked_point_has_no_reason_and_a_synth_point_no_not_checked_note() -> None:
    code, reason, report, _ = evaluate(dumps(_tables(load=True)), "build")
    assert (code, reason) == (EXIT_OK, "")
    assert report is not None and report["strength"]["passed"] is True
    code, reason, _, _ = evaluate(dumps(_tables(load=True)), "synth")
    assert (code, reason) == (EXIT_OK, "")
