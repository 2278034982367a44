"""Installs anywhere: the wheel carries every template and process profile and builds from a foreign folder;
``fabricate init`` writes an editable copy and never overwrites."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from fabricate.cli import main
from fabricate.design import load_design
from fabricate.templates import TEMPLATE_DIR

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, Path]:
    """The project built as a wheel and installed (without dependencies: those of this environment serve)
    into a folder of its own; returns (wheel, site folder)."""
    work = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                    "-w", str(work / "dist"), str(ROOT)], check=True, cwd=work)
    (wheel,) = (work / "dist").glob("fabricate-*.whl")
    site = work / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
                   check=True, cwd=work)
    return wheel, site


def _with_cache(cache: Path) -> dict[str, str]:
    """The environment of a user's run: the stage cache on (the command's default; the suite turns it off), in
    folder ``cache`` of the test's own, so a run repeated in one test is served by the cache as a user's would be
    (byte-identical to a cold build: tests/test_cache.py)."""
    env = {k: v for k, v in os.environ.items() if k != "FABRICATE_NO_CACHE"}
    env["FABRICATE_CACHE_DIR"] = str(cache)
    return env


def _run(site: Path, cwd: Path, *args: str, cache: Path | None = None) -> subprocess.CompletedProcess:
    env = {k: v for k, v in (os.environ if cache is None else _with_cache(cache)).items()
           if k not in ("PYTHONPATH", "PYTHONSAFEPATH")}
    env["PYTHONPATH"] = str(site)
    return subprocess.run([sys.executable, "-m", "fabricate", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)


@pytest.mark.slow
def test_the_wheel_carries_every_template(installed):
    wheel, _ = installed
    names = set(zipfile.ZipFile(wheel).namelist())
    shipped = sorted(p.relative_to(ROOT / "templates").as_posix() for p in (ROOT / "templates").rglob("*.toml"))
    assert len(shipped) >= 7 and any(n.startswith("process_") for n in shipped)
    assert any(n.startswith("sweeps/") for n in shipped)  # the shipped sweep specs too
    for name in shipped:
        assert f"fabricate/templates/{name}" in names, name
        data = zipfile.ZipFile(wheel).read(f"fabricate/templates/{name}")
        assert data == (ROOT / "templates" / name).read_bytes()  # the one source, packaged as it is


@pytest.mark.slow
def test_installed_it_lists_and_builds_from_a_foreign_folder(installed, tmp_path):
    _, site = installed
    foreign = tmp_path / "elsewhere"
    foreign.mkdir()
    where = subprocess.run([sys.executable, "-c", "import fabricate; print(fabricate.__file__)"], cwd=foreign,
                           env={**os.environ, "PYTHONPATH": str(site)}, capture_output=True, text=True)
    assert Path(where.stdout.strip()).is_relative_to(site)  # the installed copy, not this checkout
    listed = _run(site, foreign, "list")
    assert listed.returncode == 0
    for path in sorted((ROOT / "templates").glob("*.toml")):
        assert (path.stem in listed.stdout) == (not path.name.startswith("process_"))
    for path in sorted((ROOT / "templates" / "sweeps").glob("*.toml")):
        assert f"fabricate sweep {path.stem}" in listed.stdout
    cache = tmp_path / "cache"  # empty: the first build is the installed copy's own, cold
    built = _run(site, foreign, "build", "gear_pair_elliptic", "-q", cache=cache)
    assert built.returncode == 0, built.stderr
    report = json.loads((foreign / "outputs" / "gear_pair_elliptic" / "report.json").read_text())
    assert report["design"]["process"] == "sla" and report["checks"]["passed"]
    # an explicit path to a template outside any checkout, with a process profile found in the wheel (the
    # template and profile are read as ever; the stages are the first build's, from the cache)
    (foreign / "mine.toml").write_bytes((ROOT / "templates" / "gear_pair_elliptic.toml").read_bytes())
    explicit = _run(site, tmp_path, "build", str(foreign / "mine.toml"), "-o", str(tmp_path / "o2"), "-q",
                    cache=cache)
    assert explicit.returncode == 0, explicit.stderr
    assert (tmp_path / "o2" / "assembly.3mf").is_file()


def test_init_writes_an_editable_copy_and_never_overwrites(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["init", "my_finger"]) == 0
    copy = tmp_path / "my_finger.toml"
    design = load_design(copy)
    assert design.name == "my_finger" and design.kind == "five_bar_ncg"
    shipped = (TEMPLATE_DIR / "finger_five_bar_ncg.toml").read_text()
    assert copy.read_text() == shipped.replace('name = "finger_five_bar_ncg"', 'name = "my_finger"', 1)
    copy.write_text(copy.read_text() + "\n# my edit\n")
    assert main(["init", "my_finger"]) == 2
    assert "never overwrites" in capsys.readouterr().err
    assert copy.read_text().endswith("# my edit\n")
    assert main(["init", "pair", "--from", "gear_pair_elliptic"]) == 0
    assert load_design(tmp_path / "pair.toml").kind == "gear_pair"
    assert main(["init", "../escape"]) == 2
    assert main(["init", "x", "--from", "no_such_template"]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["my_finger.toml", "pair.toml"]


@pytest.fixture(scope="module")
def built_linkage(built_folder) -> Path:
    """A small build (the shipped Stephenson linkage, whose mechanism.toml is exact) to copy from: the
    session's, as ``fabricate build`` writes it (shared: only copied here)."""
    found = built_folder("linkage_stephenson", read_only=True)
    assert found.exit_code == 0
    return found.path


def _project(built: Path, root: Path) -> Path:
    """``root/outputs/<name>/``: a copy of ``built`` where a user's ``fabricate build`` would have put it."""
    folder = root / "outputs" / built.name
    shutil.copytree(built, folder)
    return folder


def _fabricate(cwd: Path, *args: str, cache: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fabricate", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=300, env=None if cache is None else _with_cache(cache))


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_the_outputs_readme_rebuild_recipe_works_as_written(built_linkage, tmp_path):
    """Issue 23: outputs/README.md's recipe, run as written from the folder holding outputs/, exits 0 and
    writes where the README says; the build it came from is left as it was (nothing nested in it), a plain
    re-run replaces the rebuild, and run from inside the build folder it lands in the same place."""
    text = (ROOT / "outputs" / "README.md").read_text(encoding="utf-8")
    recipe = re.search(r"^fabricate build (outputs/NAME/mechanism\.toml)\s+# writes (outputs/NAME-rebuild)/$", text,
                       re.MULTILINE)
    assert recipe, "outputs/README.md no longer states the rebuild recipe this test runs"
    source = _project(built_linkage, tmp_path)
    before = _files(source)
    name = source.name
    template, target = (recipe.group(k).replace("NAME", name) for k in (1, 2))
    cache = tmp_path / "cache"  # as a user runs it: the first build cold, its re-runs served by the cache
    done = _fabricate(tmp_path, "build", template, "-q", cache=cache)
    assert done.returncode == 0, done.stderr
    rebuilt = tmp_path / target
    assert f"building into {rebuilt}" in done.stderr  # said, with -q too
    assert (rebuilt / "report.json").is_file()
    assert _files(source) == before  # the source build: not replaced, nothing written into it
    parts = {k: v for k, v in before.items() if k.startswith("parts/") and k.endswith(".stl")}
    assert parts and all(_files(rebuilt)[k] == v for k, v in parts.items())  # the same parts, byte for byte
    assert sorted(p.name for p in (tmp_path / "outputs").iterdir()) == [name, f"{name}-rebuild"]
    again = _fabricate(tmp_path, "build", template, "-q", cache=cache)  # a plain re-run replaces the rebuild
    assert again.returncode == 0, again.stderr
    inside = _fabricate(source, "build", "mechanism.toml", "-q", cache=cache)  # the other reading: from inside
    assert inside.returncode == 0, inside.stderr
    assert _files(source) == before
    assert sorted(p.name for p in (tmp_path / "outputs").iterdir()) == [name, f"{name}-rebuild"]
    assert not (source / "outputs").exists()


@pytest.mark.slow
def test_a_default_output_is_never_written_into_a_fabricate_output_folder(built_linkage, tmp_path, monkeypatch,
                                                                           capsys):
    """Issue 23: run from inside a build folder (or a folder in it), the default output (outputs/<name>/
    under the current folder) would nest a build inside a build: refused with exit 2, naming the folder and
    -o, before any work; nothing is written into the build. An explicit -o elsewhere still works."""
    source = _project(built_linkage, tmp_path)
    before = _files(source)
    for cwd in (source, source / "parts"):
        monkeypatch.chdir(cwd)
        for command in (["build", "linkage_stephenson"], ["synth", "linkage_stephenson"], ["build"]):
            assert main([*command, "-q"]) == 2, (cwd, command)
            err = capsys.readouterr().err
            assert f"inside {source}, a fabricate output folder" in err and "-o" in err, err
            assert "Traceback" not in err
    assert _files(source) == before and not (source / "outputs").exists()
    # a template copied out of the build builds by default as any template does, beside nothing
    elsewhere = tmp_path / "work"
    elsewhere.mkdir()
    shutil.copy(source / "mechanism.toml", elsewhere / "edited.toml")
    monkeypatch.chdir(elsewhere)
    assert main(["synth", "edited.toml", "-q"]) in (0, 1)
    assert (elsewhere / "outputs" / f"{source.name}-synth" / "report.json").is_file()
    assert _files(source) == before
