"""Output folders never destroy anything: what ``-o`` may be, locking, leftovers of killed runs, Ctrl-C."""

from __future__ import annotations

import hashlib
import json
import multiprocessing
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fabricate.cli import main
from fabricate.errors import SpecError
from fabricate.output import (
    LeftAloneWarning,
    check_output_dir,
    parse_sibling,
    remove_leftovers,
    sibling_name,
    write_atomically,
    write_output,
)
from fabricate.output_read import previous_output
from fabricate.pipeline import manifest

FAST = "gear_pair_elliptic"  # the quickest shipped template to build


def fake_output(tag: str, n_files: int = 5) -> dict[str, bytes]:
    """A small but complete fabricate output: files plus a report.json listing them with a manifest."""
    files = {f"parts/p{i}.txt": f"{tag} {i}\n".encode() * 200 for i in range(n_files)}
    report = {"design": {"name": "x", "fabricate_version": "test", "stage": "build"}, "parts": [],
              "files": sorted([*files, "report.json"]), "manifest": manifest(files), "tag": tag}
    files["report.json"] = json.dumps(report).encode()
    return files


def _tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def _siblings(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir())


# -- what -o may be -----------------------------------------------------------------------------------

def test_a_folder_with_user_files_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    import fabricate.pipeline as pipeline

    out = tmp_path / "x"
    out.mkdir()
    (out / "notes.txt").write_text("keep")
    started = []
    monkeypatch.setattr(pipeline, "run_build", lambda *args, **kwargs: started.append(args))
    assert main(["build", FAST, "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert "notes.txt" in err and str(out) in err and "--force" in err
    assert _tree(out) == {"notes.txt": b"keep"}
    assert _siblings(tmp_path) == ["x"]
    assert started == []  # refused before the build began (not timed: a busy machine is slow at anything)


def test_force_replaces_a_foreign_folder(tmp_path):
    out = tmp_path / "x"
    out.mkdir()
    (out / "notes.txt").write_text("keep")
    write_output(fake_output("a"), out, force=True)
    assert _tree(out) == fake_output("a")


def test_the_templates_own_folder_is_refused_even_with_force(tmp_path, capsys):
    src = tmp_path / "designs"
    src.mkdir()
    from fabricate.templates import TEMPLATE_DIR

    template = src / "mine.toml"
    template.write_bytes((TEMPLATE_DIR / f"{FAST}.toml").read_bytes())
    for extra in ([], ["--force"]):
        assert main(["build", str(template), "-o", str(src), "-q", *extra]) == 2
        assert "mine.toml, the template being built" in capsys.readouterr().err
        assert _siblings(src) == ["mine.toml"]


@pytest.mark.parametrize("kind", ["file", "symlink_to_dir", "symlink_to_file", "dangling_symlink"])
def test_a_file_or_link_is_refused(tmp_path, capsys, kind):
    target = tmp_path / "real"
    out = tmp_path / "out"
    if kind == "file":
        out.write_text("data")
    elif kind == "symlink_to_dir":
        target.mkdir()
        out.symlink_to(target)
    elif kind == "symlink_to_file":
        target.write_text("data")
        out.symlink_to(target)
    else:
        out.symlink_to(tmp_path / "nowhere")
    before = _siblings(tmp_path)
    for extra in ([], ["--force"]):
        assert main(["build", FAST, "-o", str(out), "-q", *extra]) == 2
        err = capsys.readouterr().err
        assert str(out) in err and ("symbolic link" in err or "is a file" in err)
    assert _siblings(tmp_path) == before
    assert out.is_symlink() == (kind != "file")


def test_the_current_folder_and_its_parents_are_refused(tmp_path, monkeypatch, capsys):
    inner = tmp_path / "work"
    inner.mkdir()
    monkeypatch.chdir(inner)
    for out in (".", str(inner), str(tmp_path)):
        assert main(["build", FAST, "-o", out, "-q", "--force"]) == 2
        assert "current folder" in capsys.readouterr().err
    assert _siblings(inner) == []


def test_unusable_locations_are_named_before_any_work(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    cases = {str(blocker / "sub" / "out"): "is a file, not a folder",
             str(tmp_path / ("n" * 300)): "bytes long"}
    for out, needle in cases.items():
        assert main(["build", FAST, "-o", out, "-q"]) == 2
        err = capsys.readouterr().err
        assert needle in err and "Traceback" not in err
    assert _siblings(tmp_path) == ["file"]


def test_a_folder_that_cannot_be_written_is_named(tmp_path, capsys, monkeypatch):
    # root writes into read-only folders, so the system's refusal is simulated where it is asked for
    import fabricate.output as output

    def refuse(*_args, **_kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(output.tempfile, "mkdtemp", refuse)
    out = tmp_path / "ro" / "out"
    assert main(["build", FAST, "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert "cannot be written" in err and "Permission denied" in err
    assert _siblings(tmp_path) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write into a read-only folder")
def test_a_read_only_folder_is_refused(tmp_path, capsys):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        assert main(["build", FAST, "-o", str(ro / "out"), "-q"]) == 2
        assert "cannot be written" in capsys.readouterr().err
    finally:
        ro.chmod(0o755)


def test_a_previous_output_is_replaced_but_not_with_a_user_file_in_it(tmp_path):
    out = tmp_path / "out"
    write_output(fake_output("a"), out)
    write_output(fake_output("b"), out)  # a previous fabricate output: replaced without --force
    assert _tree(out) == fake_output("b")
    (out / "parts" / "mine.txt").write_text("keep")
    with pytest.raises(SpecError, match=r"parts/mine.txt, which fabricate did not write"):
        write_output(fake_output("c"), out)
    assert (out / "parts" / "mine.txt").read_text() == "keep"
    assert previous_output(out)["tag"] == "b"


@pytest.mark.slow
def test_synth_never_replaces_a_build(tmp_path, monkeypatch, capsys, built_folder):
    monkeypatch.chdir(tmp_path)
    from fabricate.cli import _default_output
    from fabricate.templates import find_template

    # where `fabricate build NAME` puts it (its design is named as its template): a copy of the session's build
    build = tmp_path / _default_output(FAST, find_template(FAST), "build")
    build.parent.mkdir()
    shutil.copytree(built_folder(FAST, read_only=True).path, build, symlinks=True)
    before = _tree(build)
    assert json.loads(before["report.json"])["design"]["stage"] == "build"
    assert main(["synth", FAST, "-q"]) == 0  # its own default folder
    assert _tree(build) == before
    assert (tmp_path / "outputs" / f"{FAST}-synth" / "report.json").is_file()
    assert main(["synth", FAST, "-o", str(build), "-q"]) == 2
    assert "holds a full build" in capsys.readouterr().err
    assert _tree(build) == before


# -- leftovers, concurrency, interruption ---------------------------------------------------------------

def test_leftovers_of_killed_runs_are_removed_by_the_next_run(tmp_path):
    out = tmp_path / "out"
    write_output(fake_output("a"), out)
    script = (
        "import os, sys, time\n"
        "import fabricate.output as o\n"
        "real = o._write_tree\n"
        "def slow(files, root):\n"  # half the files written, then held until killed
        "    real(dict(sorted(files.items())[:20]), root); open(sys.argv[2], 'w').close(); time.sleep(600)\n"
        "o._write_tree = slow\n"
        "from tests.test_output import fake_output\n"
        "o.write_output(fake_output('b', 40), sys.argv[1])\n"
    )
    marker = tmp_path / "writing"
    child = subprocess.Popen([sys.executable, "-c", script, str(out), str(marker)],
                             cwd=Path(__file__).resolve().parent.parent)
    try:
        deadline = time.monotonic() + 600
        while not marker.exists():
            assert child.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
        child.send_signal(signal.SIGKILL)
    finally:
        child.wait()
    leftovers = [n for n in _siblings(tmp_path) if n.startswith(".out.")]
    assert any(n.endswith(".tmp") for n in leftovers)  # the killed run left its half-written folder
    assert _tree(out) == fake_output("a")  # and the previous output untouched
    write_output(fake_output("c"), out)
    assert _siblings(tmp_path) == ["out", "writing"]
    assert _tree(out) == fake_output("c")


def _hammer(out: str, tag: str, rounds: int, errors: multiprocessing.Queue) -> None:
    try:
        for k in range(rounds):
            write_output(fake_output(f"{tag}{k}"), out)
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        errors.put(f"{tag}: {type(exc).__name__}: {exc}")


def _run_writers(jobs: list[tuple]) -> None:
    """Run ``(target, out, tag, rounds)`` writers in forked processes at once; none may report an error."""
    ctx = multiprocessing.get_context("fork")
    errors = ctx.Queue()
    workers = [ctx.Process(target=target, args=(out, tag, rounds, errors)) for target, out, tag, rounds in jobs]
    for w in workers:
        w.start()
    for w in workers:
        w.join(600)
    found = []
    while not errors.empty():
        found.append(errors.get())
    assert found == [] and all(w.exitcode == 0 for w in workers)


def test_concurrent_writers_are_serialised(tmp_path):
    out = tmp_path / "out"
    _run_writers([(_hammer, str(out), tag, 40) for tag in "abcd"])
    tree = _tree(out)
    tag = json.loads(tree["report.json"])["tag"]
    assert tree == fake_output(tag)  # one writer's complete output, nothing mixed
    assert _siblings(tmp_path) == ["out"]  # no temporary, old or lock file left


CTRL_C_CHILD = """
import pathlib, sys, time
import fabricate.pipeline as pipeline
real = pipeline._build_stages
def held(*args, **kwargs):  # the build is inside its stages (parts, exports) when Ctrl-C comes
    pathlib.Path(sys.argv[1]).touch()
    time.sleep(120)
    return real(*args, **kwargs)
pipeline._build_stages = held
from fabricate.cli import main
sys.exit(main(["build", "gear_pair_elliptic", "-o", sys.argv[2]]))
"""


@pytest.mark.slow
def test_ctrl_c_exits_130_with_one_line_and_the_previous_output_intact(tmp_path):
    out = tmp_path / "out"
    write_output(fake_output("a"), out)
    marker = tmp_path / "inside"
    # a terminal's Ctrl-C: SIGINT at its default disposition (pytest-xdist workers ignore SIGINT, an ignored
    # signal stays ignored across exec, and Python then installs no KeyboardInterrupt handler)
    child = subprocess.Popen([sys.executable, "-c", CTRL_C_CHILD, str(marker), str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 600
    while not marker.exists():  # wait until the build is under way: no race with a fast machine
        assert child.poll() is None and time.monotonic() < deadline, child.communicate()
        time.sleep(0.05)
    child.send_signal(signal.SIGINT)
    stdout, stderr = child.communicate(timeout=600)
    assert child.returncode == 130, (stdout, stderr)
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1
    assert "interrupted" in stderr
    assert _tree(out) == fake_output("a")
    assert sorted(_siblings(tmp_path)) == ["inside", "out"]


def test_ctrl_c_during_the_ocp_import_stays_a_ctrl_c(monkeypatch):
    """pybind11 turns an exception in a module's init into ImportError; a KeyboardInterrupt behind one must
    not read as "OCP is not installed"."""
    import builtins

    import fabricate.export.step as step

    real_import = builtins.__import__

    def interrupted(name, *args, **kwargs):
        if name.startswith("OCP"):
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt as exc:
                raise ImportError("initialization failed") from exc
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", interrupted)
    try:
        with pytest.raises(KeyboardInterrupt):
            step._import_ocp()  # where OCP is imported (step_available only looks for it)
    finally:
        monkeypatch.undo()


def test_check_output_dir_accepts_new_and_empty_folders(tmp_path):
    assert check_output_dir(tmp_path / "new" / "deeper") == tmp_path / "new" / "deeper"
    (tmp_path / "empty").mkdir()
    assert check_output_dir(tmp_path / "empty") == tmp_path / "empty"
    assert _siblings(tmp_path) == ["empty"]  # checking writes nothing


# -- fabricate deletes only what it can prove it made -------------------------------------------------------

def _foreign_siblings(parent: Path) -> dict[str, dict[str, bytes] | str]:
    """Siblings of output ``out`` named like fabricate's temporary folders that fabricate did not make."""
    outside = parent / "elsewhere"
    outside.mkdir()
    (outside / "data.txt").write_text("keep")
    made = {".out.backup.old": "thesis.txt", ".out.k3j9x0q2.tmp": "draft.txt",  # the earlier naming scheme
            f".out.{'fabricate-' + '0' * 16}.tmp": "mine.txt"}  # the current scheme, but not recorded
    for name, file in made.items():
        (parent / name).mkdir()
        (parent / name / file).write_text(name)
    (parent / ".out.notes.old").write_text("a file")
    (parent / f".out.fabricate-{'1' * 16}.old").symlink_to(outside)
    return {name: _tree(parent / name) for name in made} | {".out.notes.old": "a file"}


def test_foreign_folders_named_like_leftovers_survive_and_are_named(tmp_path):
    before = _foreign_siblings(tmp_path)
    said: list[str] = []
    write_output(fake_output("a"), tmp_path / "out", warn=said.append)
    write_output(fake_output("b"), tmp_path / "out", warn=said.append)  # and again, with an output there
    assert _tree(tmp_path / "out") == fake_output("b")
    for name, content in before.items():
        now = (tmp_path / name).read_text() if content == "a file" else _tree(tmp_path / name)
        assert now == content, name
    link = tmp_path / f".out.fabricate-{'1' * 16}.old"
    assert link.is_symlink() and _tree(tmp_path / "elsewhere") == {"data.txt": b"keep"}
    names = [*before, link.name]
    assert sorted(said) == sorted(f"left {n} alone: fabricate did not make it" for n in names * 2)
    with pytest.warns(LeftAloneWarning) as caught:  # the API's default
        write_output(fake_output("c"), tmp_path / "out")
    assert sorted(str(w.message) for w in caught) == sorted(f"left {n} alone: fabricate did not make it" for n in names)


def test_the_cli_leaves_a_foreign_backup_folder_and_warns(tmp_path, capsys):
    backup = tmp_path / ".results.backup.old"
    backup.mkdir()
    (backup / "thesis.txt").write_text("x\n")
    assert main(["synth", FAST, "-o", str(tmp_path / "results"), "-q"]) == 0  # writes as a build does, faster
    assert (backup / "thesis.txt").read_text() == "x\n"
    assert "fabricate: warning: left .results.backup.old alone: fabricate did not make it" in capsys.readouterr().err
    assert _siblings(tmp_path) == [".results.backup.old", "results"]


def test_only_recorded_folders_of_this_output_are_removed(tmp_path):
    token = "0123456789abcdef"
    ours, other = tmp_path / sibling_name("a", token, "tmp"), tmp_path / sibling_name("a.b", token, "tmp")
    for path in (ours, other):
        path.mkdir()
        (path / "f.txt").write_text("x")
    ident = (ours.lstat().st_dev, ours.lstat().st_ino)
    other_ident = (other.lstat().st_dev, other.lstat().st_ino)
    # a record naming the token with the wrong inode proves nothing
    assert remove_leftovers(tmp_path, "a", {token: {other_ident}}).removed == []
    # even a record of a.b's folder's inode under a's lock does not reach a.b's name
    found = remove_leftovers(tmp_path, "a", {token: {ident, other_ident}})
    assert found.removed == [ours] and found.left_alone == []
    assert _tree(other) == {"f.txt": b"x"}
    # recorded before its folder was made (no inode): removed only while empty
    empty, full = tmp_path / sibling_name("c", token, "tmp"), tmp_path / sibling_name("c", token, "old")
    empty.mkdir()
    full.mkdir()
    (full / "f.txt").write_text("x")
    found = remove_leftovers(tmp_path, "c", {token: {None}})
    assert found.removed == [empty] and found.left_alone == [full] and full.is_dir()


@pytest.mark.parametrize("name", ["a", "a.b", "a.b.c", ".a", "a.fabricate-0123456789abcdef", "x\ny", "a.tmp"])
def test_a_siblings_name_gives_back_its_output_name(name):
    for kind in ("tmp", "old"):
        entry = sibling_name(name, "0123456789abcdef", kind)
        assert parse_sibling(entry) == (name, "0123456789abcdef", kind)
    assert parse_sibling(f".{name}.fabricate-0123456789abcde.tmp") is None  # 15 digits: not fabricate's
    assert parse_sibling(f".{name}.fabricate-0123456789ABCDEF.tmp") is None


def _hammer_verified(out: str, tag: str, rounds: int, errors: multiprocessing.Queue) -> None:
    try:
        for k in range(rounds):
            write_output(fake_output(f"{tag}{k}", 45), out)
            tree = _tree(Path(out))  # no other writer of this folder: it must be exactly what was written
            if tree != fake_output(f"{tag}{k}", 45):
                errors.put(f"{tag}{k}: {len(tree)} files of {len(fake_output(tag, 45))}")
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        errors.put(f"{tag}: {type(exc).__name__}: {exc}")


def test_writers_of_a_and_a_b_both_end_complete(tmp_path):
    outs = {"a": str(tmp_path / "a"), "b": str(tmp_path / "a.b")}
    _run_writers([(_hammer_verified, out, tag, 25) for tag, out in outs.items()])
    for tag, out in outs.items():
        tree = _tree(Path(out))
        report = json.loads(tree["report.json"])
        assert tree == fake_output(f"{tag}24", 45)
        assert len(report["manifest"]) == 45
        for entry in report["manifest"]:  # every file present, of the size and digest its manifest says
            data = tree[entry["path"]]
            assert len(data) == entry["bytes"] and hashlib.sha256(data).hexdigest() == entry["sha256"]
    assert _siblings(tmp_path) == ["a", "a.b"]


def test_force_never_removes_the_process_profile(tmp_path, capsys):
    from fabricate.templates import TEMPLATE_DIR

    folder = tmp_path / "pforce"
    folder.mkdir()
    profile = folder / "my_profile.toml"
    profile.write_bytes((TEMPLATE_DIR / "process_sla.toml").read_bytes())
    elsewhere = tmp_path / "profiles" / "shared.toml"  # a link to a profile kept elsewhere is protected too
    elsewhere.parent.mkdir()
    elsewhere.write_bytes(profile.read_bytes())
    (folder / "link.toml").symlink_to(elsewhere)
    for given in (profile, folder / "link.toml"):
        for extra in ([], ["--force"]):
            assert main(["build", FAST, "--process", str(given), "-o", str(folder), "-q", *extra]) == 2
            assert f"holds {given.name}, the process profile in use" in capsys.readouterr().err
    assert sorted(p.name for p in folder.iterdir()) == ["link.toml", "my_profile.toml"]
    assert profile.read_bytes() == (TEMPLATE_DIR / "process_sla.toml").read_bytes()


def test_a_swap_puts_back_what_it_did_not_write(tmp_path, monkeypatch):
    """Someone replaces the temporary folder between fabricate's last look and the exchange: the exchange is
    undone, the previous output stays, and neither folder is deleted."""
    import fabricate.output as output

    out = tmp_path / "out"
    write_output(fake_output("a"), out)
    real = output._exchange

    def raced(a: Path, b: Path) -> bool:
        if a.name.endswith(".tmp") and not (tmp_path / "moved").exists():
            os.rename(a, tmp_path / "moved")  # fabricate's folder moved away, another put in its place
            a.mkdir()
            (a / "theirs.txt").write_text("keep")
        return real(a, b)

    monkeypatch.setattr(output, "_exchange", raced)
    with pytest.raises(SpecError, match="nothing was replaced or deleted"):
        write_output(fake_output("b"), out)
    assert _tree(out) == fake_output("a")
    intruder = [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    assert len(intruder) == 1 and _tree(intruder[0]) == {"theirs.txt": b"keep"}
    assert _tree(tmp_path / "moved") == fake_output("b")  # what fabricate wrote, moved away by the intruder
    monkeypatch.undo()
    write_output(fake_output("c"), out, warn=lambda _msg: None)
    assert _tree(intruder[0]) == {"theirs.txt": b"keep"}  # the next run does not take it for a leftover


def test_an_output_replaced_while_writing_is_not_deleted(tmp_path, monkeypatch):
    import fabricate.output as output

    out = tmp_path / "out"
    write_output(fake_output("a"), out)
    real = output._write_tree

    def meanwhile(files, root):
        real(files, root)
        os.rename(out, tmp_path / "was_out")
        out.mkdir()
        (out / "thesis.txt").write_text("keep")

    monkeypatch.setattr(output, "_write_tree", meanwhile)
    with pytest.raises(SpecError, match="replaced by another folder"):
        write_output(fake_output("b"), out)
    assert _tree(out) == {"thesis.txt": b"keep"}
    assert _siblings(tmp_path) == ["out", "was_out"]  # fabricate's own temporary folder removed


def test_without_an_atomic_exchange_two_renames_do_it(tmp_path, monkeypatch):
    import fabricate.output as output

    monkeypatch.setattr(output, "_exchange", lambda a, b: False)
    out = tmp_path / "out"
    write_atomically(fake_output("a"), out)
    write_atomically(fake_output("b"), out)
    assert _tree(out) == fake_output("b") and _siblings(tmp_path) == ["out"]


FIFO_CHILD = """
import json, sys
from pathlib import Path
from fabricate.errors import SpecError
from fabricate.output import check_output_dir, write_output
from fabricate.output_read import previous_output
from tests.test_output import fake_output
out = Path(sys.argv[1])
print(json.dumps(previous_output(out)))
try:
    check_output_dir(out)
except SpecError as exc:
    print("refused:", exc)
write_output(fake_output("a"), out, force=True)
print("written")
"""


@pytest.mark.parametrize("kind", ["fifo", "link_to_fifo", "link_to_device", "link_to_report"])
def test_a_report_json_that_is_not_a_regular_file_is_never_opened(tmp_path, kind):
    out = tmp_path / "out"
    out.mkdir()
    report = out / "report.json"
    if kind == "fifo":
        os.mkfifo(report)
    elif kind == "link_to_fifo":
        os.mkfifo(tmp_path / "pipe")
        report.symlink_to(tmp_path / "pipe")
    elif kind == "link_to_device":
        report.symlink_to("/dev/zero")
    else:  # a real fabricate report elsewhere: the folder itself is still not an output
        write_output(fake_output("x"), tmp_path / "real")
        report.symlink_to(tmp_path / "real" / "report.json")
    # a child, so that a hang fails the test instead of hanging it
    run = subprocess.run([sys.executable, "-c", FIFO_CHILD, str(out)], capture_output=True, text=True, timeout=120,
                         cwd=Path(__file__).resolve().parent.parent)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0] == "null"  # not a fabricate output
    assert lines[1].startswith("refused:") and "report.json" in lines[1] and "--force" in lines[1]
    assert lines[2] == "written" and _tree(out) == fake_output("a")


def test_the_cli_refuses_a_fifo_report_with_exit_2(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    os.mkfifo(out / "report.json")
    run = subprocess.run([sys.executable, "-m", "fabricate", "build", FAST, "-o", str(out), "-q"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2, run.stderr
    assert "report.json that is a FIFO" in run.stderr and "Traceback" not in run.stderr
    assert _siblings(out) == ["report.json"]


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_stop_signals_wait_until_the_swap_is_done(signum: int) -> None:
    """A stop signal sent between the swap's renames is delivered only after them (issue 23 item 2)."""
    from fabricate.stops import signals_deferred

    seen: list[int] = []
    old = signal.signal(signum, lambda s, _f: seen.append(s))
    try:
        with signals_deferred():
            os.kill(os.getpid(), signum)
            assert seen == []  # held off while the folder is being swapped
        assert seen == [signum]  # and delivered right after
    finally:
        signal.signal(signum, old)
