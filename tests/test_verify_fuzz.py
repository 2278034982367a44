"""Fuzz of ``fabricate check DIR`` (issue 23, item 6): random edits of report.json and of every file type in
a built folder. Whatever the folder holds, check ends with its documented exit codes (1: the folder is not
what fabricate wrote; 2: not a fabricate output at all), never exit 3 ("a bug in fabricate") and never a
traceback; every edit that changes a byte is caught.

Seeded loops (each case names its seed): one small build per session (``built_folder``), copied per case.
"""

from __future__ import annotations

import json
import math
import os
import random
import re
import shutil
import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from fabricate.cli import main
from fabricate.pipeline import run_build
from tests.conftest import keep_verdicts

FAST = "gear_pair_elliptic"
#: Cases of each kind: ~0.1-0.3 s each once the module's build and first parse are done.
REPORT_CASES = 48
FILE_KINDS = ("truncate", "flip", "append", "empty", "directory", "symlink_same_bytes", "symlink_dangling",
              "symlink_folder", "fifo", "sparse_huge", "other_file", "parent_symlink")


@pytest.fixture(scope="module")
def built(built_folder) -> Path:
    """The pair built once by the command, as without the `cad` extra: STEP export is OCP's own, fuzzed
    elsewhere, and reading STEP back costs seconds a file. Shared: each case copies it."""
    return built_folder(FAST, step=False, read_only=True).path


_REBUILDS: dict[tuple, Any] = {}


@pytest.fixture(autouse=True)
def _fast_and_bounded(monkeypatch, shared_stage_cache):
    """No OCP (as the folder was built); one real rebuild per embedded template (a report edit changes the
    verdict, not the rebuild's work), its stages from the session's shared stage cache (the workers make them
    once between them); a file's parse verdict kept by its bytes and expectation (an edit of report.json
    leaves the files as they were); and a hang (a FIFO opened) fails the case instead of blocking the suite."""
    import fabricate.export.step as step
    import fabricate.pipeline as pipeline

    monkeypatch.setattr(step, "step_available", lambda: False)

    def cached_build(design, progress=lambda _m: None, *, optional=None, pictures=True):
        override = design.process_override
        key = (design.template_text, None if override is None else (override.source, override.text),
               optional, pictures)
        if key not in _REBUILDS:
            # the hang bound is for reading the folder: a rebuild, and the wait for the other worker's under the
            # lock, take tens of seconds on busy cores (and no FIFO), so the bound pauses for it
            left = signal.alarm(0) if hasattr(signal, "SIGALRM") else 0
            try:
                with shared_stage_cache(repr(key)):
                    _REBUILDS[key] = run_build(design, progress, optional=optional, pictures=pictures)
            finally:
                if left:
                    signal.alarm(left)
        return _REBUILDS[key]

    monkeypatch.setattr(pipeline, "run_build", cached_build)
    keep_verdicts(monkeypatch)

    def hung(_signum, _frame):
        raise TimeoutError("check blocked for 120 s (a FIFO or device opened?)")

    if hasattr(signal, "SIGALRM"):
        previous = signal.signal(signal.SIGALRM, hung)
        signal.alarm(120)
        yield
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    else:  # pragma: no cover - Windows
        yield


def _check(folder: Path, capsys) -> tuple[int, str]:
    code = main(["check", str(folder), "-q"])
    captured = capsys.readouterr()
    text = captured.out + captured.err
    assert "Traceback" not in text, text
    assert "internal error" not in text, text
    assert code in (0, 1, 2), (code, text)
    return code, text


# --- report.json --------------------------------------------------------------------------------------------

def _nested(depth: int) -> Any:
    value: Any = 1
    for _ in range(depth):
        value = [value]
    return value


#: Values put in place of a field: other types, extremes, shapes.
REPLACEMENTS: tuple[Callable[[random.Random], Any], ...] = (
    lambda r: None, lambda r: True, lambda r: 0, lambda r: -1, lambda r: 10**30, lambda r: 1e308,
    lambda r: -1e308, lambda r: 0.5, lambda r: "", lambda r: "x", lambda r: "A" * r.randint(1000, 100_000),
    lambda r: "../../etc/passwd", lambda r: "/dev/zero", lambda r: [], lambda r: {},
    lambda r: _nested(r.randint(2, 60)),
    lambda r: {"a": {"b": [None, {}]}}, lambda r: [r.randint(-5, 5) for _ in range(1000)],
    lambda r: ["plates/plate_1.stl"] * 3, lambda r: {"path": "x", "bytes": -5, "sha256": "z"},
)


def _paths(value: Any, path: tuple = ()) -> list[tuple]:
    """Every place in a JSON document, as a tuple of keys and indices."""
    found = [path]
    if isinstance(value, dict):
        for key, item in value.items():
            found += _paths(item, (*path, key))
    elif isinstance(value, list):
        for k, item in enumerate(value[:6]):  # the first few of a long list: the shape is the same
            found += _paths(item, (*path, k))
    return found


def _edit_tree(report: dict, rng: random.Random) -> None:
    # bias towards what check reads: the manifest, parts, design and files
    places = [p for p in _paths(report) if p]
    hot = [p for p in places if p[0] in ("manifest", "parts", "design", "files", "checks", "outputs")]
    for _ in range(rng.randint(1, 3)):
        where = rng.choice(hot if rng.random() < 0.7 else places)
        parent = report
        for key in where[:-1]:
            parent = parent[key]
        if rng.random() < 0.3:
            del parent[where[-1]]
            return  # the other places may be gone with it
        parent[where[-1]] = rng.choice(REPLACEMENTS)(rng)


def _edit_text(text: str, rng: random.Random) -> str:
    """Edits only the JSON text can carry: non-JSON constants, giant literals, nesting, broken bytes."""
    numbers = [m.span() for m in re.finditer(r"(?<=: )-?\d+(\.\d+)?(e-?\d+)?(?=,?\n)", text)]
    kind = rng.randrange(7)
    if kind == 0 and numbers:
        start, end = rng.choice(numbers)
        return text[:start] + rng.choice(["NaN", "Infinity", "-Infinity", "1e999", "9" * 5000]) + text[end:]
    if kind == 1:
        at = rng.randrange(len(text))
        return text[:at] + "[" * 50_000 + text[at:]
    if kind == 2:
        return text[:rng.randrange(len(text))]
    if kind == 3:
        data = bytearray(text.encode())
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(len(data))] ^= rng.randint(1, 255)
        return data.decode("utf-8", errors="surrogateescape")
    if kind == 4:
        return "\ufeff" + text
    if kind == 5:
        return text.replace('"manifest": [', '"manifest": "gone", "manifest2": [', 1)
    return '{"design": {"name": "x"}, "manifest": [{"path": "report.md", "bytes": 1, "sha256": "' + "0" * 64 + '"}]}'


def _write_text(path: Path, text: str) -> None:
    path.write_bytes(text.encode("utf-8", errors="surrogateescape"))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(REPORT_CASES))
def test_random_edits_of_report_json_end_in_a_documented_exit(built, tmp_path, capsys, seed):
    rng = random.Random(seed)
    folder = tmp_path / FAST
    shutil.copytree(built, folder)
    path = folder / "report.json"
    before = path.read_bytes()
    if seed % 3 == 2:
        _write_text(path, _edit_text(before.decode(), rng))
    else:
        report = json.loads(before)
        _edit_tree(report, rng)
        path.write_text(json.dumps(report, indent=2))
    code, text = _check(folder, capsys)
    if path.read_bytes() != before:
        assert code == 1, text  # any changed byte of the report: its folder is not what fabricate wrote


# --- every file type ---------------------------------------------------------------------------------------

def _by_type(folder: Path) -> dict[str, list[str]]:
    report = json.loads((folder / "report.json").read_text())
    groups: dict[str, list[str]] = {}
    for item in report["manifest"]:
        groups.setdefault(Path(item["path"]).suffix, []).append(item["path"])
    return groups


def _mutate(folder: Path, rel: str, kind: str, rng: random.Random) -> None:
    path = folder / rel
    data = path.read_bytes()
    outside = folder.parent / "outside"
    outside.mkdir(exist_ok=True)
    if kind == "truncate":
        path.write_bytes(data[:rng.randrange(len(data))])
    elif kind == "flip":
        buffer = bytearray(data)
        for _ in range(rng.randint(1, 16)):
            buffer[rng.randrange(len(buffer))] ^= rng.randint(1, 255)
        path.write_bytes(bytes(buffer))
    elif kind == "append":
        path.write_bytes(data + rng.randbytes(rng.randint(1, 4096)))
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "directory":
        path.unlink()
        path.mkdir()
        (path / "inside.txt").write_text("x")
    elif kind == "symlink_same_bytes":
        (outside / path.name).write_bytes(data)
        path.unlink()
        path.symlink_to(outside / path.name)
    elif kind == "symlink_dangling":
        path.unlink()
        path.symlink_to(outside / "nothing_here")
    elif kind == "symlink_folder":
        path.unlink()
        path.symlink_to(outside, target_is_directory=True)
    elif kind == "fifo":
        path.unlink()
        os.mkfifo(path)
    elif kind == "sparse_huge":
        with open(path, "r+b") as fh:
            fh.truncate(rng.choice([2**31, 2**33, len(data) * 1000 + 1]))
    elif kind == "other_file":
        donor = rng.choice([p for p in folder.rglob("*") if p.is_file() and p.stat().st_size != len(data)])
        path.write_bytes(donor.read_bytes())
    elif kind == "parent_symlink":
        if "/" not in rel:  # a top-level file: its folder is the output itself; link the file instead
            (outside / path.name).write_bytes(data)
            path.unlink()
            path.symlink_to(outside / path.name)
            return
        parent = folder / rel.split("/")[0]
        shutil.copytree(parent, outside / parent.name)
        shutil.rmtree(parent)
        parent.symlink_to(outside / parent.name, target_is_directory=True)
    else:  # pragma: no cover - a kind without a mutation
        raise AssertionError(kind)


def _file_cases() -> list[tuple[str, str, int]]:
    suffixes = (".stl", ".3mf", ".dxf", ".png", ".gif", ".csv", ".md", ".toml")
    return [(suffix, kind, 1000 + k) for k, (suffix, kind) in
            enumerate((s, f) for s in suffixes for f in FILE_KINDS)]


@pytest.mark.parametrize(("suffix", "kind", "seed"), _file_cases())
def test_random_edits_of_each_file_type_are_named(built, tmp_path, capsys, suffix, kind, seed):
    if kind == "fifo" and not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    rng = random.Random(seed)
    folder = tmp_path / FAST
    shutil.copytree(built, folder)
    candidates = _by_type(folder).get(suffix)
    assert candidates, f"the build writes no {suffix} file"
    rel = rng.choice(sorted(candidates))
    _mutate(folder, rel, kind, rng)
    code, text = _check(folder, capsys)
    assert code == 1, text
    named = rel if kind != "parent_symlink" or "/" not in rel else rel.split("/")[0]
    assert named in text, text


def test_the_fuzz_reaches_every_layer(built, tmp_path, capsys):
    """The fuzz is only as good as where it lands: a value edit the schema admits reaches the rebuild,
    one it refuses stops there (so both paths of the report cases are exercised)."""
    folder = tmp_path / FAST
    shutil.copytree(built, folder)
    report = json.loads((folder / "report.json").read_text())
    report["gears"][0]["module_mm"] = 1e308
    (folder / "report.json").write_text(json.dumps(report, indent=2))
    code, text = _check(folder, capsys)
    assert code == 1 and "report.json: differs from a rebuild" in text
    report["parts"][0]["holes"] = math.pi
    (folder / "report.json").write_text(json.dumps(report, indent=2))
    code, text = _check(folder, capsys)
    assert code == 1 and "report.json: parts[0].holes is not a list" in text
