"""The sweep's result tables as bytes: ``sweep.csv`` (any spreadsheet) and ``sweep.parquet`` (pandas, polars,
DuckDB, Arrow). Encoders only; the runner writes.

One row per point, sorted by point index: ``point``, ``id``, the varied fields (columns named by their
template path), ``exit_code``, ``reason``, then the metrics (columns named by their report key path). A
metric the point's report does not have is empty in the CSV and null in Parquet. Floats are written with
``repr`` (the shortest text that reads back as the same float), so the CSV holds the metrics bit for bit.
Run times are not in the tables (they would make two runs of one sweep differ); they are in the journal.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Mapping, Sequence
from typing import Any

FIXED_BEFORE = ("point", "id")
FIXED_AFTER = ("exit_code", "reason")


def columns(field_paths: Sequence[str], metric_names: Sequence[str]) -> list[str]:
    """Column order of both tables."""
    return [*FIXED_BEFORE, *field_paths, *FIXED_AFTER, *metric_names]


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return ""
        return repr(v)
    if isinstance(v, (list, dict)):
        return json.dumps(v, separators=(", ", ": "))
    return str(v)


def csv_bytes(rows: Sequence[Mapping[str, Any]], cols: Sequence[str]) -> bytes:
    """UTF-8 CSV, comma-separated, ``\\n`` line ends, a header of the column names."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(cols)
    for row in sorted(rows, key=lambda r: r["point"]):
        writer.writerow([_cell(row.get(c)) for c in cols])
    return buffer.getvalue().encode("utf-8")


def arrow_table(rows: Sequence[Mapping[str, Any]], field_paths: Sequence[str], metric_names: Sequence[str]) -> Any:
    """A ``pyarrow.Table`` of the rows: int64 ``point`` and ``exit_code``, float64 metrics, and each varied
    field as int64, float64, bool or (for lists and tables) its JSON text."""
    import pyarrow as pa

    ordered = sorted(rows, key=lambda r: r["point"])
    arrays: dict[str, Any] = {
        "point": pa.array([int(r["point"]) for r in ordered], type=pa.int64()),
        "id": pa.array([str(r["id"]) for r in ordered], type=pa.string()),
    }
    for path in field_paths:
        values = [r.get(path) for r in ordered]
        if values and all(isinstance(v, bool) for v in values):
            arrays[path] = pa.array(values, type=pa.bool_())
        elif values and all(isinstance(v, int) and not isinstance(v, bool) for v in values):
            arrays[path] = pa.array(values, type=pa.int64())
        elif all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
            # every value is a number here (the test above): the filter only tells the type checker
            arrays[path] = pa.array([float(v) for v in values if v is not None], type=pa.float64())
        else:
            arrays[path] = pa.array([v if isinstance(v, str) else json.dumps(v) for v in values], type=pa.string())
    arrays["exit_code"] = pa.array([int(r["exit_code"]) for r in ordered], type=pa.int64())
    arrays["reason"] = pa.array([str(r.get("reason", "")) for r in ordered], type=pa.string())
    for name in metric_names:
        values = [r.get(name) for r in ordered]
        arrays[name] = pa.array([None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)
                                 for v in values], type=pa.float64())
    return pa.table(arrays)


def parquet_bytes(rows: Sequence[Mapping[str, Any]], field_paths: Sequence[str],
                  metric_names: Sequence[str]) -> bytes:
    """Parquet bytes (pyarrow, zstd) of :func:`arrow_table`."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    sink = pa.BufferOutputStream()
    pq.write_table(arrow_table(rows, field_paths, metric_names), sink, compression="zstd")
    return sink.getvalue().to_pybytes()
