"""The ``fabricate`` command's entry (fabricate/__main__.py): it leaves without the interpreter's teardown once
everything is written, flushed and reaped, and the ordinary way where something else may still need it."""

from __future__ import annotations

import subprocess
import sys

import pytest

ENTRY = """
import atexit, pathlib, sys, threading, time
marker = pathlib.Path(sys.argv[1])
atexit.register(lambda: marker.write_text("torn down"))
if sys.argv[2] == "thread":
    threading.Thread(target=time.sleep, args=(60,), daemon=True).start()  # another thread: the ordinary exit
sys.argv = ["fabricate", *sys.argv[3:]]
from fabricate.__main__ import entry
entry()
"""


def _entry(tmp_path, mode: str, *args: str) -> tuple[subprocess.CompletedProcess, bool]:
    marker = tmp_path / f"torn-{mode}"
    run = subprocess.run([sys.executable, "-c", ENTRY, str(marker), mode, *args], capture_output=True, text=True,
                         timeout=300)
    return run, marker.exists()


@pytest.mark.slow
def test_a_build_leaves_without_teardown_with_its_files_output_and_exit_code(tmp_path):
    out = tmp_path / "out"
    run, torn = _entry(tmp_path, "plain", "build", "gear_pair_elliptic", "-o", str(out))
    assert run.returncode == 0, run.stderr
    assert not torn  # no exit hook ran: the interpreter was not torn down
    assert run.stdout.endswith(f"gear_pair_elliptic: checks passed -> {out}\n")  # flushed before leaving
    assert (out / "report.json").is_file() and (out / "report.md").is_file()


def test_an_error_keeps_its_exit_code_and_message_and_another_thread_the_ordinary_exit(tmp_path):
    missing = str(tmp_path / "missing")
    run, torn = _entry(tmp_path, "plain", "check", missing)
    assert (run.returncode, torn) == (2, False)
    assert run.stderr.startswith("fabricate: error:") and missing in run.stderr
    run, torn = _entry(tmp_path, "thread", "check", missing)
    assert (run.returncode, torn) == (2, True)
