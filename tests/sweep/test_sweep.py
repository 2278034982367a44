"""Design-space sweeps (fabricate.sweep): the spec, the samplers, one point, a local Dask cluster, a real
``dask scheduler`` with two ``dask worker`` processes (one killed mid-sweep), and an interrupted sweep that
resumes.

The sweeps here vary the elliptic gear pair (``gear_pair_elliptic``, synthesis stage: ~0.2 s a point): its
pitch curves have closed forms, so every row can be checked against the values in its own columns (a row
mixed up with another point's metrics fails), and an eccentricity >= 1 is an invalid point.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fabricate.errors import SpecError
from fabricate.sweep.paths import get_path, parse_metric, parse_path, set_path
from fabricate.sweep.spec import sweep_from_tables, unit_samples
from fabricate.sweep.task import run_point

pytest.importorskip("distributed")
pytest.importorskip("pyarrow")

GEAR_METRICS = ["synthesis.center_distance_mm", "min(synthesis.transmission_ratio[*])",
                "max(synthesis.transmission_ratio[*])", "synthesis.pitch_radius_a_mm[0]",
                "synthesis.pitch_radius_a_mm[1]"]


def _values(v):
    return v if isinstance(v, str) else [float(x) for x in v]


def gear_tables(eccentricities=(0.1, 0.2, 0.3, 1.5), modules=(0.8, 1.0), **sweep) -> dict:
    return {"sweep": {"template": "gear_pair_elliptic", "stage": "synth", "metrics": list(GEAR_METRICS),
                      "name": "gears", **sweep},
            "vary": {"gear_pair.eccentricity": _values(eccentricities), "gears.module_mm": _values(modules)},
            "set": {"checks.sweep_poses": 30}}


def reference_rows(spec) -> list[dict]:
    """Every point run one by one in this process, without Dask."""
    return [run_point(i, values, spec.point_id(values), spec.base, spec.field_parts(), spec.stage,
                      list(spec.metrics)) for i, values in enumerate(spec.points())]


def same_row(a: dict, b: dict) -> bool:
    """Equal in every column but the run time, floats bit for bit (NaN equals NaN)."""
    keys = (set(a) | set(b)) - {"seconds"}
    for k in keys:
        x, y = a.get(k), b.get(k)
        if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
            continue
        if type(x) is not type(y) or x != y:
            return False
    return True


def check_gear_row(row: dict) -> None:
    """Closed forms of a 1:1 elliptic pair turning about the foci: the pitch radius runs from a(1 - e) to
    a(1 + e), the centre distance is 2a, and the ratio spans (1 - e)/(1 + e) .. (1 + e)/(1 - e)."""
    e = row["gear_pair.eccentricity"]
    r_min, r_max = row["synthesis.pitch_radius_a_mm[0]"], row["synthesis.pitch_radius_a_mm[1]"]
    assert r_max / r_min == pytest.approx((1 + e) / (1 - e), rel=1e-6)
    assert row["synthesis.center_distance_mm"] == pytest.approx(r_min + r_max, rel=1e-6)
    assert row["max(synthesis.transmission_ratio[*])"] == pytest.approx((1 + e) / (1 - e), rel=1e-6)
    assert row["min(synthesis.transmission_ratio[*])"] == pytest.approx((1 - e) / (1 + e), rel=1e-6)


# -- spec, paths, samplers (pure) ------------------------------------------------------------------------------

def test_field_paths_get_and_set():
    assert parse_path("finger.lengths_mm[0]") == ("finger", "lengths_mm", 0)
    assert parse_path("a[1][2].b-c") == ("a", 1, 2, "b-c")
    assert parse_path("strength.parts[*].x", wildcard=True) == ("strength", "parts", "*", "x")
    for bad in ("", "a..b", "a[x]", "a[-1]", "[0]", "a.[0]", "a[*]"):
        with pytest.raises(ValueError):
            parse_path(bad)
    data = {"finger": {"lengths_mm": [40.0, 28.0, 20.0]}}
    set_path(data, ("finger", "lengths_mm", 1), 30.0)
    set_path(data, ("synthesis", "select"), "x_A")  # a missing table is created
    assert data == {"finger": {"lengths_mm": [40.0, 30.0, 20.0]}, "synthesis": {"select": "x_A"}}
    assert get_path(data, ("finger", "lengths_mm", 2)) == 20.0
    with pytest.raises(KeyError):
        set_path(data, ("finger", "lengths_mm", 3), 1.0)  # a sweep never grows a list


def test_metrics_read_paths_and_aggregates():
    report = {"strength": {"parts": [{"sf": 3.0}, {"sf": 2.5}, {"sf": 7.0}]}, "a": {"b": [1, 2], "ok": True}}
    assert parse_metric("min(strength.parts[*].sf)", "m").read(report) == 2.5
    assert parse_metric("max(strength.parts[*].sf)", "m").read(report) == 7.0
    assert parse_metric("mean(strength.parts[*].sf)", "m").read(report) == pytest.approx(12.5 / 3, rel=1e-15)
    assert parse_metric("count(strength.parts[*])", "m").read(report) == 3.0
    assert parse_metric("a.b[1]", "m").read(report) == 2.0
    assert parse_metric("a.ok", "m").read(report) == 1.0
    assert math.isnan(parse_metric("a.missing", "m").read(report))
    assert math.isnan(parse_metric("a.b", "m").read(report))  # a list is not a number
    with pytest.raises(SpecError, match="selects several values"):
        parse_metric("strength.parts[*].sf", "sweep.metrics[0]")


def test_grid_points_are_the_product_in_order():
    spec = sweep_from_tables(gear_tables(eccentricities=(0.1, 0.2), modules="0.5:1.0:3"))
    points = spec.points()
    assert spec.count() == len(points) == 6
    assert [p["gear_pair.eccentricity"] for p in points] == [0.1, 0.1, 0.1, 0.2, 0.2, 0.2]
    assert [p["gears.module_mm"] for p in points] == [0.5, 0.75, 1.0] * 2
    assert len({spec.point_id(p) for p in points}) == 6


@pytest.mark.parametrize("n, dims, seed", [(7, 1, 0), (50, 3, 1), (64, 5, 123)])
def test_latin_hypercube_has_one_point_per_stratum(n, dims, seed):
    u = unit_samples("lhs", dims, n, seed)
    assert u.shape == (n, dims) and np.all((u >= 0) & (u < 1))
    for j in range(dims):  # the defining property: each of the n equal slices of every axis holds one point
        assert sorted(np.floor(u[:, j] * n).astype(int)) == list(range(n))
    assert np.array_equal(u, unit_samples("lhs", dims, n, seed))  # seeded


@pytest.mark.parametrize("m, dims", [(3, 2), (6, 4)])
def test_sobol_points_are_balanced(m, dims):
    n = 2 ** m
    u = unit_samples("sobol", dims, n, 7)
    for j in range(dims):  # a (0, m, s)-net in base 2: every dyadic slice of 1/2 .. 1/2^m holds n/2^k points
        for k in range(1, m + 1):
            counts = np.bincount(np.floor(u[:, j] * 2 ** k).astype(int), minlength=2 ** k)
            assert np.all(counts == n // 2 ** k)


def test_lhs_sweep_samples_ranges_and_choices():
    tables = gear_tables(sampling="lhs", samples=40, seed=3)
    tables["vary"] = {"gear_pair.eccentricity": "0.05:0.35", "gears.teeth[0]": "20:40",
                      "gears.module_mm": [0.8, 1.0, 1.25]}
    spec = sweep_from_tables(tables)
    points = spec.points()
    assert len(points) == 40
    e = np.array([p["gear_pair.eccentricity"] for p in points])
    assert np.all((e >= 0.05) & (e <= 0.35))
    assert sorted(np.floor((e - 0.05) / 0.3 * 40).astype(int)) == list(range(40))  # still one per stratum
    teeth = [p["gears.teeth[0]"] for p in points]
    assert all(isinstance(t, int) and 20 <= t <= 40 for t in teeth)  # the template's integer stays integer
    modules = [p["gears.module_mm"] for p in points]
    assert {modules.count(v) for v in (0.8, 1.0, 1.25)} <= {13, 14}  # a list is split evenly


@pytest.mark.parametrize("change, field", [
    (lambda t: t["vary"].update({"gear_pair.eccentrcity": [0.1]}), "vary.gear_pair.eccentrcity"),
    (lambda t: t["vary"].update({"gears.teeth[2]": [30]}), "vary.gears.teeth[2]"),
    (lambda t: t["vary"].update({"gears.module_mm": "0.5:1.0"}), "vary.gears.module_mm"),
    (lambda t: t["vary"].update({"gears.module_mm": []}), "vary.gears.module_mm"),
    (lambda t: t["sweep"].update({"metrics": ["strength.passed"]}), "sweep.metrics[0]"),
    (lambda t: t["sweep"].update({"metrics": ["a.b[*]"]}), "sweep.metrics[0]"),
    (lambda t: t["sweep"].update({"sampling": "sobol", "samples": 48}), "sweep.samples"),
    (lambda t: t["sweep"].update({"sampling": "random"}), "sweep.sampling"),
    (lambda t: t["sweep"].update({"samples": 8}), "sweep.samples"),
    (lambda t: t["sweep"].update({"best": 2, "metrics": []}), "sweep.best"),
    (lambda t: t["sweep"].update({"map": ["gears.module_mm", "gears.module_mm"]}), "sweep.map"),
    (lambda t: t["sweep"].update({"map": ["gears.teeth[0]", "gears.module_mm"]}), "sweep.map[0]"),
    (lambda t: t["sweep"].update({"stage": "all"}), "sweep.stage"),
    (lambda t: t["sweep"].update({"template": "no_such_template"}), ""),
    (lambda t: t["sweep"].update({"colour": "red"}), "sweep.colour"),
    (lambda t: t["vary"].update({"gears.module_mm": "0.1:2.0:10000", "gear_pair.eccentricity": "0:0.5:11"}),
     "vary"),
    (lambda t: t["set"].update({"gears.module_mm": 1.0}), "vary.gears.module_mm"),
])
def test_bad_sweep_specs_name_the_field(change, field):
    tables = gear_tables()
    change(tables)
    with pytest.raises(SpecError) as info:
        sweep_from_tables(tables)
    assert info.value.path == field, str(info.value)


def test_tasks_are_batched_to_about_the_target_time():
    from fabricate.sweep.runner import MAX_BATCH, next_batch_size

    assert next_batch_size([], 1.0) == 1  # nothing measured yet: one point per task
    assert next_batch_size([0.25] * 10, 1.0) == 4
    assert next_batch_size([3.0, 0.2, 0.2, 0.2], 1.0) == 5  # a worker's slow first point does not set it
    assert next_batch_size([5.0] * 3, 1.0) == 1  # a point longer than the target: one per task
    assert next_batch_size([1e-5] * 3, 1.0) == MAX_BATCH
    assert next_batch_size([0.5] * 100 + [0.01] * 64, 1.0) == 100  # the recent points count


def test_the_last_points_are_spread_over_every_task_in_flight():
    from fabricate.sweep.runner import batch_share

    assert batch_share(8, 100, 4) == 8  # plenty left: the timed batch
    assert batch_share(8, 12, 4) == 3  # 12 left, 4 tasks in flight (2 workers): 3 each, not 8 + 4
    assert batch_share(8, 13, 4) == 4
    assert batch_share(8, 3, 4) == 1 and batch_share(1, 0, 4) == 1  # never an empty task
    assert batch_share(5, 100, 0) == 5


def test_a_bad_point_is_a_row_with_its_reason():
    spec = sweep_from_tables(gear_tables(eccentricities=(1.5,), modules=(1.0,)))
    (values,) = spec.points()
    row = run_point(0, values, spec.point_id(values), spec.base, spec.field_parts(), spec.stage,
                    list(spec.metrics))
    assert row["exit_code"] == 2 and "gear_pair.eccentricity" in row["reason"]
    assert all(math.isnan(row[m]) for m in GEAR_METRICS)


# -- Dask: local cluster, real scheduler and workers, resume ----------------------------------------------------

@pytest.mark.slow
def test_local_cluster_sweep_equals_the_points_one_by_one(tmp_path):
    import pyarrow.parquet as pq

    from fabricate.sweep.runner import run_sweep
    from fabricate.sweep.tables import columns, csv_bytes

    spec = sweep_from_tables(gear_tables(best=1, best_metric="synthesis.center_distance_mm", best_goal="min"))
    expected = reference_rows(spec)
    out = tmp_path / "sweep"
    from fabricate.bounds import max_workers

    workers = min(2, max_workers())  # two where the machine allows (the bound follows its cores and memory)
    outcome = run_sweep(spec, out, workers=workers, quiet=True)
    assert outcome.exit_code == 0 and outcome.done == outcome.total == 8 and outcome.workers == workers
    assert outcome.counts == {"0": 6, "2": 2}
    assert 1 <= outcome.tasks <= outcome.total

    journal = [json.loads(line) for line in (out / "rows.jsonl").read_text().splitlines()]
    assert sorted(r["point"] for r in journal) == list(range(8))  # every point once
    cols = columns([f.path for f in spec.fields], GEAR_METRICS)
    assert (out / "sweep.csv").read_bytes() == csv_bytes(expected, cols)  # every metric bit for bit
    from fabricate.sweep.tables import parquet_bytes

    assert (out / "sweep.parquet").read_bytes() == parquet_bytes(expected, [f.path for f in spec.fields],
                                                                 GEAR_METRICS)  # the same rows, the same bytes
    table = pq.read_table(out / "sweep.parquet").to_pylist()
    assert len(table) == 8
    for got, want in zip(table, expected, strict=True):
        want = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in want.items()}
        assert {k: got[k] for k in cols} == {k: want[k] for k in cols}
    for row in expected:
        if row["exit_code"] == 0:
            check_gear_row(row)
    by_e = {(r["gear_pair.eccentricity"], r["gears.module_mm"]): r for r in expected}
    assert by_e[(0.2, 0.8)]["synthesis.center_distance_mm"] == pytest.approx(
        0.8 * by_e[(0.2, 1.0)]["synthesis.center_distance_mm"], rel=1e-9)  # the pair scales with the module

    plots = sorted(p.name for p in (out / "plots").iterdir())
    assert "feasibility.png" in plots and len(plots) == 1 + 2 * len(GEAR_METRICS)
    assert all((out / "plots" / p).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in plots)

    record = json.loads((out / "sweep.json").read_text())
    assert record["complete"] and record["counts"] == {"0": 6, "2": 2}
    (best,) = record["best"]  # 4 a E(e) = pi m z: the least eccentric, finest pair is the smallest
    assert best["values"] == {"gear_pair.eccentricity": 0.1, "gears.module_mm": 0.8}
    report = json.loads((out / best["folder"] / "report.json").read_text())
    assert report["design"]["kind"] == "gear_pair"
    # built in full, never report-only (as a build sweep's points are): its pictures are there
    assert {"previews/assembly.png", "plots/strength.png"} <= set(report["files"])
    assert (out / best["folder"] / "previews" / "assembly.png").is_file()
    assert report["outputs"]["step"] in ("written", "skipped: OCP is not installed (extra 'cad')")
    # the full build is judged like any build (its checks may fail where synthesis passed); the sweep says so
    assert best["build_exit_code"] == (0 if report["checks"]["passed"] else 1)
    assert report["synthesis"]["center_distance_mm"] == pytest.approx(  # a build's report rounds to 1e-9 mm
        by_e[(0.1, 0.8)]["synthesis.center_distance_mm"], abs=1e-9)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dask(*args: str) -> subprocess.Popen:
    exe = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    assert exe, "the dask command (dask distributed) is not installed"
    return subprocess.Popen([exe, *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


def _journal_points(path: Path) -> list[int]:
    if not path.is_file():
        return []
    return [json.loads(line)["point"] for line in path.read_text().splitlines() if line.endswith("}")]


def _cli(*args: str, **kw) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "fabricate", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


@pytest.mark.slow
def test_sweep_through_a_real_scheduler_survives_a_killed_worker(tmp_path):
    """``dask scheduler`` and two ``dask worker`` processes on localhost; one worker is killed (SIGKILL) once
    rows arrive: the sweep still ends with every point exactly once, equal to the points run one by one. Twelve
    points: the sweep keeps about two tasks per worker in flight, so when two rows are in, ten points are left and
    the killed worker holds some (24 points took twice the time: the points one by one dominate the test)."""
    spec_tables = gear_tables(eccentricities=tuple(np.round(np.linspace(0.05, 0.4, 6), 6)), modules=(0.8, 1.0))
    spec_tables["sweep"]["batch_seconds"] = 0.01  # one point per task: the killed worker surely holds some
    spec_file = tmp_path / "gears.toml"
    from fabricate.tomlwrite import dumps

    spec_file.write_text(dumps(spec_tables))
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = [_dask("scheduler", "--host", "127.0.0.1", "--port", str(port), "--dashboard-address", ":0")]
    try:
        for _ in range(2):
            procs.append(_dask("worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                               "--memory-limit", "0", "--death-timeout", "60"))
        out = tmp_path / "out"
        child = _cli("sweep", str(spec_file), "--scheduler", address, "-o", str(out))
        deadline = time.monotonic() + 600
        while len(_journal_points(out / "rows.jsonl")) < 2:
            assert child.poll() is None and time.monotonic() < deadline, child.communicate()
            time.sleep(0.02)
        os.killpg(procs[1].pid, signal.SIGKILL)  # a worker dies mid-sweep
        stdout, stderr = child.communicate(timeout=600)
        assert child.returncode == 0, (stdout, stderr)
        assert "2 Dask workers at " + address in stderr
    finally:
        for p in procs:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()
    points = _journal_points(out / "rows.jsonl")
    assert len(_journal_points(out / "rows.jsonl")) > 2 and sorted(set(points)) == list(range(12))
    assert len(points) == 12, "a point was recorded twice"
    spec = sweep_from_tables(spec_tables)
    from fabricate.sweep.tables import columns, csv_bytes

    expected = reference_rows(spec)
    assert (out / "sweep.csv").read_bytes() == csv_bytes(expected, columns([f.path for f in spec.fields],
                                                                           GEAR_METRICS))
    for row in expected:
        check_gear_row(row)


@pytest.mark.slow
def test_an_interrupted_sweep_resumes_where_it_stopped(tmp_path):
    from fabricate.sweep.tables import columns, csv_bytes

    tables = gear_tables(eccentricities=tuple(np.round(np.linspace(0.05, 0.4, 6), 6)), modules=(1.0,))
    tables["sweep"]["batch_seconds"] = 0.01
    from fabricate.tomlwrite import dumps

    spec_file = tmp_path / "gears.toml"
    spec_file.write_text(dumps(tables))
    out = tmp_path / "out"
    # a terminal's Ctrl-C (SIGINT at its default disposition: pytest-xdist workers ignore it)
    child = _cli("sweep", str(spec_file), "--workers", "1", "-o", str(out),
                 preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 600
    while len(_journal_points(out / "rows.jsonl")) < 2:
        assert child.poll() is None and time.monotonic() < deadline, child.communicate()
        time.sleep(0.02)
    child.send_signal(signal.SIGINT)
    stdout, stderr = child.communicate(timeout=600)
    assert child.returncode == 130, (stdout, stderr)
    assert "Traceback" not in stderr and "run the same command again to resume" in stderr
    first = _journal_points(out / "rows.jsonl")
    assert 2 <= len(first) < 6
    record = json.loads((out / "sweep.json").read_text())
    assert not record["complete"] and record["done"] == len(set(first))
    with (out / "rows.jsonl").open("a") as fh:  # a run killed while appending leaves a torn line
        fh.write('{"point": 5, "id": "tor')

    again = _cli("sweep", str(spec_file), "--workers", "1", "-o", str(out))
    stdout, stderr = again.communicate(timeout=600)
    assert again.returncode == 0, (stdout, stderr)
    assert f"({len(set(first))} done earlier)" in stdout
    points = _journal_points(out / "rows.jsonl")
    assert sorted(points) == list(range(6)), "every point exactly once (none lost, none run twice)"
    spec = sweep_from_tables(tables)
    assert (out / "sweep.csv").read_bytes() == csv_bytes(reference_rows(spec),
                                                         columns([f.path for f in spec.fields], GEAR_METRICS))


# -- command line ---------------------------------------------------------------------------------------------

def test_cli_vary_values_parse_like_toml():
    from fabricate.sweep.spec import assignments as _assignments

    got = _assignments(["a.b=0.1:0.3:3", "c=1,2.5,x", "d=[[1.0, 2.0], [3.0, 4.0]]", "e=7", 'f="s"'], "--vary",
                       True)
    assert got == {"a.b": "0.1:0.3:3", "c": [1, 2.5, "x"], "d": [[1.0, 2.0], [3.0, 4.0]], "e": [7], "f": ["s"]}
    assert _assignments(["g=least_pose_error", "h=0.5"], "--set", False) == {"g": "least_pose_error", "h": 0.5}
    with pytest.raises(SpecError, match="FIELD=VALUES"):
        _assignments(["nothing"], "--vary", True)


@pytest.mark.parametrize("args, field", [
    (["--vary", "gear_pair.eccentrcity=0.1,0.2"], "vary.gear_pair.eccentrcity"),
    (["--vary", "gears.module_mm=1:2"], "vary.gears.module_mm"),
    (["--vary", "gears.module_mm=1,2", "--metric", "strength.passed"], "sweep.metrics[0]"),
    (["--vary", "gears.module_mm=1,2", "--workers", "0"], "--workers"),
])
def test_cli_bad_sweep_exits_2_and_writes_nothing(tmp_path, capsys, args, field):
    from fabricate.cli import main

    out = tmp_path / "out"
    assert main(["sweep", "gear_pair_elliptic", *args, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"error: {field}:" in err and "Traceback" not in err
    assert not out.exists()


def test_cli_sweep_never_writes_into_a_foreign_folder(tmp_path, capsys):
    from fabricate.cli import main

    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep")
    assert main(["sweep", "gear_pair_elliptic", "--vary", "gears.module_mm=1,2", "-o", str(out)]) == 2
    assert "did not write" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


# -- a sweep folder is never written through a link ---------------------------------------------------------------

def _earlier_sweep(tmp_path: Path) -> tuple[Path, Path, object]:
    """A spec file and the folder of an earlier run of it (its sweep.json, no rows yet)."""
    from fabricate.sweep.folder import SWEEP_JSON, sweep_record
    from fabricate.sweep.runner import _json
    from fabricate.tomlwrite import dumps

    tables = gear_tables(eccentricities=(0.1, 0.2), modules=(1.0,))
    spec_file = tmp_path / "gears.toml"
    spec_file.write_text(dumps(tables))
    spec = sweep_from_tables(tables, tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / SWEEP_JSON).write_bytes(_json(sweep_record(spec, {"points": 2, "done": 0, "complete": False})))
    return spec_file, out, spec


def test_a_symlinked_journal_is_refused_and_never_written_through(tmp_path, capsys):
    from fabricate.cli import main
    from fabricate.sweep.folder import Journal, read_journal

    spec_file, out, spec = _earlier_sweep(tmp_path)
    target = tmp_path / "thesis.txt"
    target.write_text("line one\nno newline at the end")  # what a torn journal line looks like
    (out / "rows.jsonl").symlink_to(target)
    assert main(["sweep", str(spec_file), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert "rows.jsonl: is a symbolic link" in err and "Traceback" not in err
    # and below the folder check, the journal itself is never opened through the link
    with pytest.raises(SpecError, match="symbolic link"):
        read_journal(out, spec)
    with pytest.raises(SpecError, match="symbolic link"):
        Journal(out / "rows.jsonl")
    assert target.read_text() == "line one\nno newline at the end"
    assert (out / "rows.jsonl").is_symlink()


@pytest.mark.parametrize("name, make", [("rows.jsonl", "fifo"), ("rows.jsonl", "folder"), ("plots", "link"),
                                        ("best", "link"), ("sweep.json", "link")])
def test_a_sweep_folder_entry_of_the_wrong_kind_is_refused(tmp_path, name, make):
    spec_file, out, _ = _earlier_sweep(tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    path = out / name
    if name == "sweep.json":
        os.replace(path, elsewhere / "sweep.json")
        path.symlink_to(elsewhere / "sweep.json")
    elif make == "fifo":
        os.mkfifo(path)
    elif make == "folder":
        path.mkdir()
    else:
        path.symlink_to(elsewhere)
    before = sorted(p.name for p in out.iterdir())
    # a child, so that a FIFO opened by mistake fails the test instead of hanging it
    child = _cli("sweep", str(spec_file), "-o", str(out), "-q")
    stdout, stderr = child.communicate(timeout=120)
    assert child.returncode == 2, (stdout, stderr)
    assert f"{path}: is " in stderr and "Traceback" not in stderr
    assert sorted(p.name for p in out.iterdir()) == before and list(elsewhere.iterdir()) == (
        [elsewhere / "sweep.json"] if name == "sweep.json" else [])


def test_a_sweep_never_writes_into_a_folder_holding_its_spec(tmp_path, capsys):
    from fabricate.cli import main
    from fabricate.tomlwrite import dumps

    folder = tmp_path / "work"
    folder.mkdir()
    spec_file = folder / "gears.toml"
    spec_file.write_text(dumps(gear_tables(eccentricities=(0.1, 0.2), modules=(1.0,))))
    assert main(["sweep", str(spec_file), "-o", str(folder), "-q"]) == 2
    assert "holds gears.toml, an input of this sweep" in capsys.readouterr().err
    assert sorted(p.name for p in folder.iterdir()) == ["gears.toml"]


# -- issue 23: every sweep value is finite, checked where the spec is validated ---------------------------------

@pytest.mark.parametrize(("change", "field", "needle"), [
    (lambda t: t["vary"].update({"gears.module_mm": [0.8, math.nan]}), "vary.gears.module_mm", "got nan"),
    (lambda t: t["vary"].update({"gears.module_mm": [math.inf]}), "vary.gears.module_mm", "got inf"),
    (lambda t: t["vary"].update({"gears.teeth": [[30, 30], [30, -math.inf]]}), "vary.gears.teeth", "got -inf"),
    (lambda t: t["vary"].update({"gears.module_mm": "-1e308:1e308:3"}), "vary.gears.module_mm",
     "spans more than a float can hold"),
    (lambda t: t.update({"sweep": {**t["sweep"], "sampling": "lhs", "samples": 4},
                         "vary": {"gears.module_mm": "-1e308:1e308"}}), "vary.gears.module_mm",
     "spans more than a float can hold"),
    (lambda t: t["set"].update({"gears.backlash_mm": math.nan}), "set.gears.backlash_mm", "got nan"),
    (lambda t: t["sweep"].update({"metrcs": []}), "sweep.metrcs", 'did you mean "metrics"?'),
])
def test_non_finite_sweep_values_are_refused_naming_the_entry(change, field, needle):
    tables = gear_tables()
    change(tables)
    with pytest.raises(SpecError) as info:
        sweep_from_tables(tables)
    assert info.value.path == field and needle in info.value.message, str(info.value)


def test_an_entry_given_on_the_command_line_says_so():
    tables = gear_tables(modules=[math.nan])
    with pytest.raises(SpecError) as info:
        sweep_from_tables(tables, origins={"vary.gears.module_mm": "--vary gears.module_mm"})
    assert str(info.value) == "vary.gears.module_mm: expected finite values, got nan (given as --vary gears.module_mm)"


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "0.8,nan", "[nan]", "1e400"])
def test_cli_vary_nan_exits_2_naming_the_flag(tmp_path, capsys, value):
    """The issue's case: `--vary field=nan` was an internal error (exit 3) when the row went to JSON."""
    from fabricate.cli import main

    out = tmp_path / "out"
    assert main(["sweep", "gear_pair_elliptic", "--vary", f"gears.module_mm={value}", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "expected finite values" in err and "--vary gears.module_mm" in err, err
    assert "Traceback" not in err and "internal error" not in err
    assert not out.exists()


@pytest.mark.slow
def test_a_second_sweep_into_a_folder_waits_then_resumes_what_the_first_recorded(tmp_path):
    """Two sweeps into one folder appended to one journal (every point ran twice, and a resume could cut the
    other's line in half). A sweep holds the folder's lock: the second waits, saying so, then resumes from the
    journal the first left. Here the test holds the lock as the first run and records two points meanwhile."""
    from fabricate.output import folder_lock
    from fabricate.sweep.folder import JOURNAL, SWEEP_JSON, sweep_record
    from fabricate.sweep.task import row_json
    from fabricate.tomlwrite import dumps

    tables = gear_tables(eccentricities=(0.1, 0.2, 0.3), modules=(1.0,))
    spec_file = tmp_path / "gears.toml"
    spec_file.write_text(dumps(tables))
    spec = sweep_from_tables(tables)
    out = tmp_path / "out"
    with folder_lock(out):
        second = _cli("sweep", str(spec_file), "--workers", "1", "-o", str(out))
        heard = second.stderr.readline()
        assert "waiting for another run writing" in heard and str(out) in heard, (heard, second.communicate())
        out.mkdir()  # what the first run records while the second waits: two points of the three
        first = [run_point(i, values, spec.point_id(values), spec.base, spec.field_parts(), spec.stage,
                           list(spec.metrics)) for i, values in enumerate(spec.points()[:2])]
        (out / JOURNAL).write_text("".join(row_json(row) + "\n" for row in first))
        (out / SWEEP_JSON).write_text(json.dumps(sweep_record(spec, {"points": 3, "done": 2, "complete": False})))
    stdout, stderr = second.communicate(timeout=600)
    assert second.returncode == 0, (stdout, stderr)
    assert "(2 done earlier)" in stdout
    assert sorted(_journal_points(out / JOURNAL)) == [0, 1, 2], "every point once: the two recorded are not rerun"
