"""Every way a run ends: a signal (SIGTERM, SIGHUP, SIGINT, SIGKILL of the parent), a closed stdout, an
exception in the picture child. Each leaves no process, a consistent folder and one line on stderr; and the
command line's smaller promises (``-q``, ``check`` of a missing target, plain ``--help``, no exit 3 for an
out-of-memory check)."""

from __future__ import annotations

import json
import multiprocessing
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from fabricate import cli
from fabricate.background import Background
from fabricate.cli import main
from fabricate.output import write_output
from fabricate.pipeline import BuildOutcome, manifest

ROOT = Path(__file__).resolve().parent.parent
FAST = "gear_pair_elliptic"

# The build goes on normally until its picture child runs the first picture job; there the child writes its
# pid into a marker and waits, so the test signals a run whose child is certainly alive (no timing guess).
HOLD_IN_CHILD = """
import os, pathlib, sys, time
import fabricate.pipeline as pipeline
parent = os.getpid()
real = pipeline.synthesis_plots
def held(result):
    if os.getpid() != parent:
        marker = pathlib.Path(sys.argv[1])
        marker.with_suffix('.part').write_text(str(os.getpid()))
        marker.with_suffix('.part').rename(marker)
        time.sleep(600)
    return real(result)
pipeline.synthesis_plots = held
from fabricate.cli import main
sys.exit(main(["build", "gear_pair_elliptic", "-o", sys.argv[2]]))
"""


def _previous_output() -> dict[str, bytes]:
    files = {"parts/a.txt": b"previous\n"}
    report = {"design": {"name": "x", "fabricate_version": "test", "stage": "build"}, "parts": [],
              "files": ["parts/a.txt", "report.json"], "manifest": manifest(files)}
    return {**files, "report.json": json.dumps(report).encode()}


def _tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def _group(pgid: int) -> dict[int, str]:
    """``{pid: state}`` of every process in process group ``pgid`` (from /proc)."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:  # it ended while we looked
            continue
        fields = stat[stat.rindex(")") + 2:].split()  # after "pid (comm) ": state ppid pgrp ...
        if int(fields[2]) == pgid:
            found[int(entry.name)] = fields[0]
    return found


def _alive(pgid: int) -> dict[int, str]:
    # a zombie holds no memory and no file; an orphan's zombie stays until a reaper comes (PID 1 of a container
    # may never reap), which is not fabricate's to fix
    return {pid: state for pid, state in _group(pgid).items() if state not in ("Z", "X")}


def _start_held_build(tmp_path: Path, script: str = HOLD_IN_CHILD, which: str = "picture"
                      ) -> tuple[subprocess.Popen, Path, int]:
    """``script`` run in a session of its own over a previous output in ``tmp_path / "out"``, once the child it
    holds (the ``which`` child) has written its pid: ``(the run, the output folder, the child's pid)``."""
    out = tmp_path / "out"
    write_output(_previous_output(), out)
    marker = tmp_path / "child.pid"
    env = {k: v for k, v in os.environ.items() if k != "FABRICATE_SERIAL"}

    def default_signals() -> None:  # as from a terminal: pytest-xdist ignores SIGINT, nohup ignores SIGHUP
        for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            signal.signal(number, signal.SIG_DFL)

    run = subprocess.Popen([sys.executable, "-c", script, str(marker), str(out)], cwd=tmp_path, env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                           preexec_fn=default_signals)
    deadline = time.monotonic() + 300
    while not marker.exists():
        if run.poll() is not None or time.monotonic() > deadline:
            run.kill()
            pytest.fail(f"the {which} child never started: {run.communicate()}")
        time.sleep(0.05)
    child = int(marker.read_text())
    assert child != run.pid and _group(run.pid).get(child) not in (None, "Z")  # alive, in the run's group
    return run, out, child


def _wait_until_gone(pgid: int) -> dict[int, str]:
    deadline = time.monotonic() + 300
    while _alive(pgid) and time.monotonic() < deadline:
        time.sleep(0.05)
    return _alive(pgid)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize(("name", "to_group", "code", "words"), [
    ("SIGTERM", False, 143, "terminated (SIGTERM)"),  # kill PID: only the parent hears it
    ("SIGHUP", True, 129, "hung up (SIGHUP)"),  # a closed terminal: the whole foreground group hears it
    ("SIGINT", True, 130, "interrupted"),  # Ctrl-C: the whole group
])
def test_a_signal_leaves_no_process_no_temporary_and_the_previous_output(tmp_path, name, to_group, code, words):
    run, out, child = _start_held_build(tmp_path)
    number = getattr(signal, name)
    if to_group:
        os.killpg(run.pid, number)
    else:
        os.kill(run.pid, number)
    stdout, stderr = run.communicate(timeout=600)  # returns: nobody holds the pipes
    assert run.returncode == code, (stdout, stderr)
    assert stderr.strip().splitlines() == [f"fabricate: {words}; nothing was written (a previous output is "
                                           "unchanged)"]
    assert stdout == ""
    assert _wait_until_gone(run.pid) == {}
    assert child not in _group(run.pid)  # not even a zombie: the parent reaped its child
    assert _tree(out) == _previous_output()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".out.")] == []


# A library on the build's path swallows the stop: the exports stage sends SIGTERM to its own process while it
# sleeps inside a try that catches BaseException (trimesh catches BaseException in its own code), so the Stopped
# the handler raises never reaches the command line's handler.
SWALLOWED = """
import os, signal, sys, time
import fabricate.pipeline as pipeline
real = pipeline._export
def swallowing(run, with_step, **kw):
    try:
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(60)  # the handler raises Stopped out of the sleep at once
    except BaseException:
        pass
    return real(run, with_step, **kw)
pipeline._export = swallowing
from fabricate.cli import main
sys.exit(main(["build", "gear_pair_elliptic", "-o", sys.argv[1], "-q"]))
"""


@pytest.mark.slow
def test_a_stop_a_library_swallowed_still_stops_the_run_before_anything_is_written(tmp_path):
    out = tmp_path / "out"
    write_output(_previous_output(), out)
    env = {k: v for k, v in os.environ.items() if k != "FABRICATE_SERIAL"}
    run = subprocess.run([sys.executable, "-c", SWALLOWED, str(out)], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=600, start_new_session=True,
                         preexec_fn=lambda: signal.signal(signal.SIGTERM, signal.SIG_DFL))
    assert run.returncode == 143, (run.stdout, run.stderr)
    # the next stage's start raised it again: not "as the run ended (its result is complete)"
    assert run.stderr.strip().splitlines() == ["fabricate: terminated (SIGTERM); nothing was written (a previous "
                                               "output is unchanged)"]
    assert _tree(out) == _previous_output()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".out.")] == []


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_the_picture_child_dies_with_a_killed_parent_and_frees_its_output(tmp_path):
    run, out, child = _start_held_build(tmp_path)
    os.kill(run.pid, signal.SIGKILL)  # no handler, no finally: only the kernel can stop the child now
    stdout, stderr = run.communicate(timeout=600)  # the child's stdout/stderr are not the caller's pipes
    assert run.returncode == -signal.SIGKILL
    assert "Traceback" not in stderr
    assert _wait_until_gone(run.pid) == {}  # the child, asleep for 600 s, was killed with its parent
    assert _tree(out) == _previous_output()


def test_the_background_child_does_not_write_to_the_callers_stdout(capfd):
    parent = os.getpid()

    def job() -> dict[str, bytes]:
        if os.getpid() != parent:
            os.write(1, b"child-stdout\n")
            os.write(2, b"child-stderr\n")
            return {"where": b"child"}
        return {"where": b"parent"}

    assert Background([job]).result() == {"where": b"child"}
    captured = capfd.readouterr()
    assert "child-" not in captured.out + captured.err
    assert multiprocessing.active_children() == []


@pytest.mark.parametrize("failure", ["raise", "exit", "unpicklable"])
def test_a_failing_background_child_falls_back_to_the_caller_and_leaves_no_process(failure):
    parent = os.getpid()

    def job() -> dict[str, bytes]:
        if os.getpid() != parent:
            if failure == "raise":
                raise RuntimeError("only in the child")
            if failure == "exit":
                os._exit(7)
            return {"where": lambda: None}  # type: ignore[dict-item]  # cannot be sent back
        return {"where": b"parent"}

    assert Background([job]).result() == {"where": b"parent"}
    assert multiprocessing.active_children() == []


def test_cancel_kills_a_child_still_at_work():
    parent = os.getpid()

    def job() -> dict[str, bytes]:
        if os.getpid() != parent:
            time.sleep(600)
        return {}

    background = Background([job])
    process = background._process
    assert process is not None and process.is_alive()
    background.cancel()
    assert process.exitcode == -signal.SIGKILL
    assert multiprocessing.active_children() == []


# -- a closed stdout, a closed stderr ---------------------------------------------------------------------------

def _with_closed_stdout(*args: str) -> subprocess.CompletedProcess:
    reader, writer = os.pipe()
    os.close(reader)  # the reader has gone before anything is written: every write is EPIPE
    try:
        return subprocess.run([sys.executable, "-m", "fabricate", *args], stdout=writer, stderr=subprocess.PIPE,
                              text=True, timeout=120)
    finally:
        os.close(writer)


@pytest.mark.parametrize("args", [["list"], ["--help"], ["build", "--help"]])
def test_a_reader_that_closed_stdout_is_not_an_error(args):
    done = _with_closed_stdout(*args)
    assert (done.returncode, done.stderr) == (0, "")


def test_a_broken_stdout_keeps_the_commands_own_exit_code(monkeypatch, capsys):
    class Gone:
        def write(self, _text: str) -> int:
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self) -> None:
            raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(sys, "stdout", Gone())
    assert main(["list"]) == 0
    assert capsys.readouterr().err == ""
    assert isinstance(sys.stdout, Gone)  # given back as it was


def test_text_the_output_cannot_encode_is_escaped_not_fatal(monkeypatch):
    import io

    buffer = io.BytesIO()
    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(buffer, encoding="ascii", errors="strict"))
    monkeypatch.setattr(cli, "_list", lambda: print("folder caf\u00e9-\udcff") or 0)  # a name with a raw 0xff byte
    assert main(["list"]) == 0
    assert buffer.getvalue() == b"folder caf\\xe9-\\udcff\n"


@pytest.mark.slow
def test_a_closed_stderr_does_not_turn_an_error_into_a_crash(tmp_path):
    missing = str(tmp_path / "missing")
    reader, writer = os.pipe()
    os.close(reader)
    try:  # a reader of stderr that has gone: writing the error line fails with EPIPE
        done = subprocess.run([sys.executable, "-m", "fabricate", "check", missing], stdout=subprocess.PIPE,
                              stderr=writer, text=True, timeout=120)
    finally:
        os.close(writer)
    assert (done.returncode, done.stdout) == (2, "")
    # stderr not open at all (fd 2 closed): Python has no sys.stderr, and nothing goes to stdout instead
    done = subprocess.run([sys.executable, "-m", "fabricate", "check", missing], stdout=subprocess.PIPE,
                          text=True, timeout=120, preexec_fn=lambda: os.close(2))
    assert (done.returncode, done.stdout) == (2, "")


def test_a_full_stdout_is_named_and_exits_2():
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "fabricate", "list"], stdout=full, stderr=subprocess.PIPE,
                              text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == ["fabricate: error: cannot write to standard output: No space left "
                                                "on device"]


# -- signal handlers are the command's only -------------------------------------------------------------------

def test_main_gives_the_signal_handlers_back():
    before = {n: signal.getsignal(n) for n in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    hook = sys.unraisablehook
    assert main(["list"]) == 0
    assert {n: signal.getsignal(n) for n in before} == before
    assert sys.unraisablehook is hook


def test_a_stop_signal_inside_a_command_exits_128_plus_its_number(monkeypatch, capsys):
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL or threading.current_thread() is not \
            threading.main_thread():
        pytest.skip("the test runner handles SIGTERM itself, or runs tests outside the main thread")

    def stopped() -> int:
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(60)  # the handler raises in here
        return 0

    monkeypatch.setattr(cli, "_list", stopped)
    assert main(["list"]) == 143
    assert capsys.readouterr().err.strip().splitlines() == [
        "fabricate: terminated (SIGTERM); nothing was written (a previous output is unchanged)"]
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_a_stop_raised_in_a_destructor_prints_no_traceback(monkeypatch, capsys):
    """The handler can raise where Python cannot pass the exception on: a destructor or a garbage-collector
    callback (distributed's, in a sweep). Python hands it to ``sys.unraisablehook``, whose default prints
    "Exception ignored in ..." and a traceback. The run still ends as a stopped one."""
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL or threading.current_thread() is not \
            threading.main_thread():
        pytest.skip("the test runner handles SIGTERM itself, or runs tests outside the main thread")
    unraised: list = []
    monkeypatch.setattr(sys, "unraisablehook", unraised.append)  # what would be printed (pytest has its own)

    class Held:
        def __del__(self) -> None:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(60)  # the handler raises Stopped in here, and out of this destructor

    def listed() -> int:
        Held()
        return 0

    monkeypatch.setattr(cli, "_list", listed)
    assert main(["list"]) == 143
    assert unraised == []
    assert capsys.readouterr().err.strip().splitlines() == [
        "fabricate: terminated (SIGTERM) as the run ended (its result is complete)"]
    assert sys.unraisablehook == unraised.append  # given back


def test_a_stop_during_an_import_stops_the_command_once_the_import_is_done(monkeypatch, capsys, tmp_path):
    """Raised inside an import, the stop can fail a C extension's initialisation midway, which some abort on
    (CI: a held build's parent ended by SIGSEGV, and by SIGABRT with the stop raised from enum.py inside an
    extension's exec_module). The handler sends the signal again until the import is done."""
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL or threading.current_thread() is not \
            threading.main_thread():
        pytest.skip("the test runner handles SIGTERM itself, or runs tests outside the main thread")
    (tmp_path / "fabricate_test_slow_import.py").write_text(
        "import os, signal, time\nos.kill(os.getpid(), signal.SIGTERM)\ntime.sleep(0.2)\ndone = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    imported = []

    def listed() -> int:
        import fabricate_test_slow_import

        imported.append(fabricate_test_slow_import.done)
        time.sleep(60)  # the signal, sent again, stops the command in here
        return 0

    monkeypatch.setattr(cli, "_list", listed)
    try:
        assert main(["list"]) == 143
    finally:
        sys.modules.pop("fabricate_test_slow_import", None)
    assert imported == [True]  # the module's code ran to its end
    assert capsys.readouterr().err.strip().splitlines() == [
        "fabricate: terminated (SIGTERM); nothing was written (a previous output is unchanged)"]


def test_an_ignored_signal_stays_ignored(monkeypatch):
    if signal.getsignal(signal.SIGHUP) is not signal.SIG_DFL:
        pytest.skip("the test runner handles SIGHUP itself")
    seen = []
    monkeypatch.setattr(cli, "_list", lambda: seen.append(signal.getsignal(signal.SIGHUP)) or 0)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # nohup fabricate ...
    try:
        assert main(["list"]) == 0
    finally:
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
    assert seen == [signal.SIG_IGN]


# -- -q, check of a missing target, --help, out of memory ---------------------------------------------------------

def _fake_build(passed: bool):
    def run_build(design, progress=None, *, pictures=True):
        failures = [] if passed else ["strength: link too thin"]
        report = {"design": {"name": design.name, "fabricate_version": "test", "stage": "build"},
                  "checks": {"passed": passed, "failures": failures}, "files": ["report.json"]}
        return BuildOutcome(exit_code=0 if passed else 1, report=report,
                            files={"report.json": json.dumps(report).encode()})
    return run_build


@pytest.mark.parametrize("passed", [True, False])
def test_quiet_hides_progress_but_not_the_result(tmp_path, monkeypatch, capsys, passed):
    import fabricate.pipeline

    monkeypatch.setattr(fabricate.pipeline, "run_build", _fake_build(passed))
    code = main(["build", FAST, "-o", str(tmp_path / "out"), "-q"])
    out = capsys.readouterr().out.splitlines()
    assert code == (0 if passed else 1)
    assert out[0].startswith(f"{FAST}: ") and out[0].endswith(f" -> {tmp_path / 'out'}")
    assert ("FAILED" in out[0]) is not passed
    if not passed:
        assert "  - strength: link too thin" in out


def test_check_of_a_missing_folder_names_both_readings(tmp_path, capsys):
    missing = tmp_path / "results"
    assert main(["check", str(missing)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "template not found" not in err[0]
    assert str(missing) in err[0] and "no such folder or template" in err[0]


def test_check_accepts_a_shipped_name_that_is_no_path(monkeypatch, tmp_path, capsys):
    import fabricate.pipeline

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(fabricate.pipeline, "run_build", _fake_build(True))
    assert main(["check", FAST]) == 0
    assert capsys.readouterr().out.startswith(f"{FAST}: ")


@pytest.mark.parametrize("argv", [["--help"], ["build", "--help"], ["check", "--help"], ["sweep", "--help"]])
def test_help_is_plain_text_and_states_the_exit_codes(capsys, argv):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 0
    text = capsys.readouterr().out
    assert "``" not in text and ":class:" not in text and ":func:" not in text
    if argv == ["--help"]:
        assert "143" in " ".join(text.split()) and "-q hides progress only" in " ".join(text.split())
    if argv[0] in ("build", "check", "sweep"):
        assert "the result line and any failures are still printed" in " ".join(text.split())


def test_out_of_memory_while_checking_a_folder_does_not_blame_a_template(tmp_path, monkeypatch, capsys):
    import fabricate.verify

    def exhausted(*_args, **_kwargs):
        raise MemoryError

    monkeypatch.setattr(fabricate.verify, "verify_output", exhausted)
    assert main(["check", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"fabricate: error: out of memory while checking {tmp_path} (the folder was not verified)"]


def test_every_error_is_one_line(tmp_path, monkeypatch, capsys):
    from fabricate.errors import SpecError

    def bad(*_args, **_kwargs):
        raise SpecError("design.name", "a\nmulti-line\rmessage")

    monkeypatch.setattr(cli, "_list", bad)
    assert main(["list"]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1

    def bug(*_args, **_kwargs):
        raise RuntimeError("two\nlines")

    monkeypatch.setattr(cli, "_list", bug)
    assert main(["list"]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("fabricate: internal error: RuntimeError: two\\nlines")


# The exports fail with a geometry kernel's error wherever they run: in the export child the build forks after the
# parts, then again here where the parent redoes the child's jobs. Each call leaves its process id in a folder.
EXPORTS_FAIL = """
import os, pathlib, sys
import fabricate.export
from fabricate.errors import GeometryError
def failing(*args, **kwargs):
    (pathlib.Path(sys.argv[1]) / str(os.getpid())).touch()
    raise GeometryError("the plate outline self-intersects")
fabricate.export.export_part_files = failing
from fabricate.cli import main
sys.exit(main(["build", "gear_pair_elliptic", "-o", sys.argv[2], "-q"]))
"""


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_kernel_failure_in_the_export_child_is_a_design_failure_with_no_traceback_or_process_left(tmp_path):
    calls, out = tmp_path / "calls", tmp_path / "out"
    calls.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "FABRICATE_SERIAL"}
    run = subprocess.Popen([sys.executable, "-c", EXPORTS_FAIL, str(calls), str(out)], cwd=tmp_path, env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    stdout, stderr = run.communicate(timeout=600)
    assert run.returncode == 1, (stdout, stderr)
    assert "Traceback" not in stderr and "Traceback" not in stdout
    failure = "exports: this design cannot be made (the plate outline self-intersects)"
    assert failure in stdout + stderr
    # the child failed (its pid), then this process redid its jobs and failed the same way
    assert len(list(calls.iterdir())) == 2 and str(run.pid) in {p.name for p in calls.iterdir()}
    report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    assert report["checks"]["failures"] == [failure] and not report["checks"]["passed"]
    # as a serial build's: it fails in the exports, before any check ran
    assert not {"interference", "strength", "drive", "parts"} & set(report)
    assert sorted(p.name for p in out.iterdir()) == ["report.json", "report.md"]
    assert _wait_until_gone(run.pid) == {}  # the children and the STEP workers went with the build


# As HOLD_IN_CHILD, but in the child that makes the exports after the parts (it also takes the prestarted STEP
# worker): this process runs the checks meanwhile, then waits for that child.
HOLD_IN_EXPORT_CHILD = """
import os, pathlib, sys, time
import fabricate.export
parent = os.getpid()
real = fabricate.export.export_part_files
def held(*args, **kwargs):
    if os.getpid() != parent:
        marker = pathlib.Path(sys.argv[1])
        marker.with_suffix('.part').write_text(str(os.getpid()))
        marker.with_suffix('.part').rename(marker)
        time.sleep(600)
    return real(*args, **kwargs)
fabricate.export.export_part_files = held
from fabricate.cli import main
sys.exit(main(["build", "gear_pair_elliptic", "-o", sys.argv[2]]))
"""


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_signal_while_the_export_child_works_leaves_no_process_and_the_previous_output(tmp_path):
    run, out, child = _start_held_build(tmp_path, HOLD_IN_EXPORT_CHILD, "export")
    os.kill(run.pid, signal.SIGTERM)  # only the parent hears it: it must kill the child (and the STEP worker)
    stdout, stderr = run.communicate(timeout=600)
    assert run.returncode == 143, (stdout, stderr)
    assert stderr.strip().splitlines() == ["fabricate: terminated (SIGTERM); nothing was written (a previous output "
                                           "is unchanged)"]
    assert _wait_until_gone(run.pid) == {}
    assert child not in _group(run.pid)  # reaped, not even a zombie
    assert _tree(out) == _previous_output()
