"""fabricate/report.py: report.json's one-pass writer gives json.dumps(indent=2)'s exact text."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fabricate.report import jsonable, report_json

_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),  # escapes, controls and non-ASCII included
    st.integers(-1000, 1000).map(np.int64), st.floats(-1e6, 1e6).map(np.float64), st.booleans().map(np.bool_),
    st.lists(st.floats(-1e3, 1e3), max_size=4).map(np.array),
)
_values = st.recursive(
    _scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.lists(inner, max_size=3).map(tuple),
        # non-str keys: jsonable turns them into text, where equal texts collapse (1 and "1")
        st.dictionaries(st.one_of(st.text(max_size=4), st.integers(-3, 3)), inner, max_size=4)),
    max_leaves=25)


@settings(max_examples=300)
@given(report=st.dictionaries(st.text(max_size=6), _values, max_size=5))
def test_report_json_is_the_text_json_dumps_writes(report: dict) -> None:
    expected = (json.dumps(jsonable(report), indent=2, ensure_ascii=False) + "\n").encode("utf-8")
    assert report_json(report) == expected
