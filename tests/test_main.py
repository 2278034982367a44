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


# entry() after main(): an object whose destructor raises when the interpreter goes down (a library left midway
# by the stop), and a thread, so that entry takes the ordinary exit (as with Dask loaded) rather than os._exit
LOUD_TEARDOWN = """
import sys, threading
import fabricate.cli
from fabricate.__main__ import entry
class Loud:
    def __del__(self):
        raise AssertionError("a library's state, left midway by the stop")
kept = Loud()
fabricate.cli.main = lambda: int(sys.argv[1])
threading.Thread(target=threading.Event().wait, args=(0.2,)).start()
entry()
"""


@pytest.mark.parametrize(("code", "quiet"), [(130, True), (0, False)])
def test_after_a_stop_the_teardown_prints_nothing(code, quiet):
    run = subprocess.run([sys.executable, "-c", LOUD_TEARDOWN, str(code)], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == code
    # a run that was not stopped keeps Python's report: the same script is seen to print it
    assert ("Exception ignored" not in run.stderr) is quiet, run.stderr
    assert ("AssertionError" in run.stderr) is not quiet


# a Ctrl-C that lands while the command line still loads, before main() puts its handlers in place
EARLY_CTRL_C = """
import sys
class CtrlC:
    def find_spec(self, name, path=None, target=None):
        if name == "fabricate.cli":
            raise KeyboardInterrupt
sys.meta_path.insert(0, CtrlC())
from fabricate.__main__ import entry
entry()
"""


def test_a_ctrl_c_while_the_command_loads_is_one_line_and_exit_130():
    run = subprocess.run([sys.executable, "-c", EARLY_CTRL_C], capture_output=True, text=True, timeout=120)
    assert run.returncode == 130
    assert run.stderr.splitlines() == ["fabricate: interrupted; nothing was written (a previous output is "
                                       "unchanged)"]
