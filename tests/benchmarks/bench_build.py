"""Budget of a build, per stage and whole: every shipped template's ``fabricate build`` against the import floor.

    python tests/benchmarks/bench_build.py                       # every template, both installs
    python tests/benchmarks/bench_build.py --vs /tmp/old_checkout  # and the same, paired, on another checkout's code
    python tests/benchmarks/bench_build.py --templates finger_five_bar_ncg --runs 5 --no-stages

What it measures, in one run:

- **whole-process builds**: ``python -m fabricate build T -o TMP --force -q`` as a user runs it (its
  picture child and STEP worker included; ``FABRICATE_NO_CACHE=1``: every run a cold build), medians of
  ``--runs`` runs for the default template (``finger_five_bar_ncg``) and of ``--other-runs`` for the others,
  after one warm-up run of the default template. Wall time, CPU time (user + sys of the build and its
  children, from ``os.wait4``) and peak memory (``ru_maxrss``: the largest single process of the build);
- **the import floor** in the same rounds: a process that only imports what a build cannot do without
  (:data:`FLOOR_MODULES`; with the ``cad`` extra also :data:`STEP_MODULES`), and each build's ratio to it
  (the median of the per-round ratios, so the machine's drift cancels);
- **two installs**: ``cad`` (OCP importable: STEP files written) and ``core``, emulated by a
  ``sitecustomize`` that makes every ``import OCP...`` fail as if the extra were not installed (the build then
  skips STEP and says so; the floor leaves OCP out). ``cad`` rows are skipped where OCP is not installed;
- **per stage**, in a separate process per template and install: the pipeline's progress marks
  (synthesis, sweep, gears, parts, exports, checks, strength, drive, plots) timestamped with wall and CPU
  clocks, the STEP probe and each picture job wrapped, with ``FABRICATE_SERIAL=1`` so the pictures run in
  that process and every stage's CPU is counted once (the stages add up to a serial build; the whole-process
  rows are the real, parallel one). CPU includes the processes a stage waited for (the STEP worker, which
  a build starts early: all its CPU is in the STEP row). Peak memory per stage is the process's resident
  high-water mark over that stage (``/proc/self/clear_refs`` resets it at each mark; Linux only), or the
  STEP worker's where that is larger;
- ``--rebuilds``: edit, rebuild, see. The default template's rebuild after an edit of one table, with the stage
  cache on (a private cache folder, warmed by one build of the unedited template): each round runs the floor, then
  one rebuild per edit of :data:`REBUILD_EDITS` (``[load]``, ``[checks]``, ``[parts]`` (the plate layout: the exports
  and checks run again; a boss wall: everything from the parts on), ``[process]``) and of the
  unedited template. Each round writes a value no earlier round used, so every rebuild misses exactly the stages
  its table reaches and is served the others (what a user who edits one value sees); ratio to the floor per round;
- ``--vs PATH``: the same builds on another checkout's code (``PYTHONPATH=PATH``), run alternately with this
  checkout's (A B A B ...), and the ratio A/B (median of the pairs).

Nothing is asserted: the numbers are printed as markdown tables (the README's). Timings on a shared machine
drift: quote medians and ratios. Byte-identity of builds is ``tests/benchmarks/output_hashes.py``'s job.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_TEMPLATE = "finger_five_bar_ncg"

#: What every build imports and cannot do without: the floor a build's time is compared with. matplotlib
#: through its object-oriented Agg API (what the plots use), scipy with the subpackages the kernels use.
FLOOR_MODULES = ("numpy", "scipy", "scipy.interpolate", "scipy.optimize", "scipy.spatial", "shapely", "trimesh",
                 "manifold3d", "ezdxf", "PIL.Image", "matplotlib", "matplotlib.figure",
                 "matplotlib.backends.backend_agg")
#: The STEP writer's modules (the ``cad`` extra): part of the floor of a build that writes STEP.
STEP_MODULES = ("OCP.STEPCAFControl",)

#: ``sitecustomize`` of the emulated core install: every import of OCP fails as if it were not installed.
_NO_OCP = '''"""bench_build: emulate the core install (no OCP) for this process and its children."""
import sys


class _NoOCP:
    def find_spec(self, name, path=None, target=None):
        if name == "OCP" or name.startswith("OCP."):
            raise ModuleNotFoundError(f"No module named {name!r} (core install emulated)", name=name)
        return None


sys.meta_path.insert(0, _NoOCP())
'''

INSTALLS = ("core", "cad")

#: ``--rebuilds``: one edit of the default template per table, ``(text in the template, its replacement)``; ``{k}``
#: is the round's number, so each round's value is new to the cache (tests/test_cache.py's edits of the same tables,
#: whose byte-identity to a cold build it proves; a screw size of its own cannot vary by round).
REBUILD_EDITS = {
    "[load]": ("tip_force_N = 1.5", "tip_force_N = 1.2{k:03d}"),
    "[checks]": ("sweep_poses = 360 ", "min_safety_factor = 2.5{k:03d}\nsweep_poses = 360 "),
    "[parts] layout": ("[checks]\n", "[parts]\nplate_spacing_mm = 4.0{k:03d}\n\n[checks]\n"),
    "[parts] geometry": ("[checks]\n", "[parts]\nboss_wall_mm = 2.0{k:03d}\n\n[checks]\n"),
    "[process]": ("thickness_mm = 6.0 ", "hole_compensation_mm = 0.15{k:03d}\nthickness_mm = 6.0 "),
    "none (unchanged)": ("", ""),
}


@dataclass
class Sample:
    """One finished process: wall (s), CPU (user + sys of it and its reaped children, s), peak RSS (MB)."""

    wall: float
    cpu: float
    rss_mb: float
    code: int


@dataclass
class Series:
    """The samples of one command, in the order they ran."""

    samples: list[Sample] = field(default_factory=list)

    def median(self, what: str) -> float:
        return statistics.median(getattr(s, what) for s in self.samples)


def _env(code: Path, install: str, blocker: Path, extra: dict[str, str] | None = None) -> dict[str, str]:
    """The environment of a process running ``code``'s fabricate on ``install``."""
    env = dict(os.environ)
    paths = [str(code)] if install == "cad" else [str(blocker), str(code)]
    env["PYTHONPATH"] = os.pathsep.join(paths + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    env["MPLBACKEND"] = "Agg"
    env["FABRICATE_NO_CACHE"] = "1"  # every run a cold build: a stage cache (fabricate/cache.py) must not serve it
    env.pop("FABRICATE_SERIAL", None)
    # an installed package has its compiled modules: let the warm-up run write them (a shell that sets
    # PYTHONDONTWRITEBYTECODE would otherwise make every counted run recompile fabricate's ~120 modules)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.update(extra or {})
    return env


def _run(argv: Sequence[str], env: dict[str, str], cwd: Path) -> Sample:
    """Run ``argv`` to its end: its wall time and, from ``os.wait4``, CPU time and peak memory."""
    start = time.perf_counter()
    proc = subprocess.Popen(list(argv), env=env, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here: Popen must not wait for it again
    return Sample(wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, proc.returncode)


def _floor_argv(install: str) -> list[str]:
    modules = FLOOR_MODULES + (STEP_MODULES if install == "cad" else ())
    return [sys.executable, "-c", "import matplotlib; matplotlib.use('Agg')\n"
            + "".join(f"import {m}\n" for m in modules)]


def _build_argv(template: str, out: Path, extra: Sequence[str] = ()) -> list[str]:
    return [sys.executable, "-m", "fabricate", "build", template, "-o", str(out), "--force", "-q", *extra]


def ocp_installed() -> bool:
    import importlib.util

    return importlib.util.find_spec("OCP") is not None


# -- per stage, in a process of its own ------------------------------------------------------------------------

def stage_profile(template: str) -> dict[str, dict[str, float]]:
    """``{stage: {"wall": s, "cpu": s, "peak_mb": MB}}`` of one serial in-process build (run with
    ``FABRICATE_SERIAL=1``), in the order the stages ran; ``import`` and ``load`` first."""
    wall0, cpu0 = time.perf_counter(), _cpu()
    import fabricate.pipeline as pipeline
    from fabricate.design import load_design

    clock = _Clock(wall0, cpu0)
    clock.mark("load")
    design = load_design(template)
    picture_names = ("synthesis plots", "gear pictures", "previews", "STEP", "assembly pictures")
    jobs_of = pipeline._picture_jobs

    def timed_jobs(run):  # noqa: ANN001, ANN202 - the pipeline's own types
        jobs = jobs_of(run)
        names = list(picture_names) + [f"picture job {k}" for k in range(len(picture_names), len(jobs))]
        return [clock.nested(f"  {name}", job) for name, job in zip(names, jobs, strict=False)]

    probe = pipeline._record_optional_outputs
    pipeline._picture_jobs = timed_jobs
    pipeline._record_optional_outputs = clock.nested("  STEP probe", probe)
    try:
        outcome = pipeline.run_build(design, lambda text: clock.mark(text.split(" (")[0]))
    finally:
        pipeline._picture_jobs, pipeline._record_optional_outputs = jobs_of, probe
    clock.mark("end")
    out = clock.table()
    out["exit code"] = {"wall": float(outcome.exit_code), "cpu": 0.0, "peak_mb": 0.0}
    return out


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w", encoding="ascii") as fh:
            fh.write("5")  # resets the resident high-water mark (VmHWM), Linux 4.0+
        return True
    except OSError:
        return False


def _peak_mb() -> float:
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _cpu() -> float:
    """CPU seconds of this process and its reaped children (the STEP worker a build may start)."""
    import resource

    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def _children_peak_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0


class _Clock:
    """Stage marks with wall and CPU clocks; nested (wrapped) calls are taken out of their stage's time."""

    def __init__(self, wall0: float, cpu0: float) -> None:
        self.stage, self.wall, self.cpu = "import", wall0, cpu0
        self.rows: dict[str, list[float]] = {}
        self.inner = [0.0, 0.0]
        self.stage_peak = 0.0  # the stage's high-water mark before its nested calls reset it
        _reset_peak()

    def _add(self, name: str, wall: float, cpu: float, peak: float) -> None:
        row = self.rows.setdefault(name, [0.0, 0.0, 0.0])
        row[0] += wall
        row[1] += cpu
        row[2] = max(row[2], peak)

    def mark(self, stage: str) -> None:
        wall, cpu = time.perf_counter(), _cpu()
        self._add(self.stage, wall - self.wall - self.inner[0], cpu - self.cpu - self.inner[1],
                  max(self.stage_peak, _peak_mb()))
        _reset_peak()
        self.stage, self.wall, self.cpu, self.inner, self.stage_peak = stage, wall, cpu, [0.0, 0.0], 0.0

    def nested(self, name: str, func):  # noqa: ANN001, ANN201 - any callable
        def timed(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            self.stage_peak = max(self.stage_peak, _peak_mb())
            _reset_peak()
            wall, cpu, children = time.perf_counter(), _cpu(), _children_peak_mb()
            result = func(*args, **kwargs)
            dw, dc = time.perf_counter() - wall, _cpu() - cpu
            peak = _peak_mb()
            if _children_peak_mb() > children:  # a process it ran (the STEP worker) was the larger
                peak = max(peak, _children_peak_mb())
            self.stage_peak = max(self.stage_peak, peak)
            _reset_peak()
            self.inner[0] += dw
            self.inner[1] += dc
            self._add(name, dw, dc, peak)
            return result

        return timed

    def table(self) -> dict[str, dict[str, float]]:
        return {name: {"wall": w, "cpu": c, "peak_mb": m} for name, (w, c, m) in self.rows.items()}


def _stages_in_child(template: str, code: Path, install: str, blocker: Path, cwd: Path) -> dict | None:
    env = _env(code, install, blocker, {"FABRICATE_SERIAL": "1"})
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--stage-profile", template], env=env,
                          cwd=cwd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        print(f"(stage profile of {template} on {install} failed: {proc.stderr.strip().splitlines()[-1:]})",
              file=sys.stderr)
        return None
    return json.loads(proc.stdout)


# -- the whole run -------------------------------------------------------------------------------------------

@dataclass
class Row:
    template: str
    install: str
    a: Series = field(default_factory=Series)
    b: Series = field(default_factory=Series)
    floor: Series = field(default_factory=Series)  # the floor runs of the same rounds


def _ratio(num: Series, den: Series, what: str = "wall") -> float:
    """Median of the per-round ratios (as many rounds as both have)."""
    pairs = [getattr(x, what) / getattr(y, what) for x, y in zip(num.samples, den.samples, strict=False)
             if getattr(y, what) > 0]
    return statistics.median(pairs) if pairs else float("nan")


def measure(templates: Sequence[str], installs: Sequence[str], runs: int, other_runs: int, vs: Path | None,
            stages: bool, work: Path, log=print, extra: Sequence[str] = ()  # noqa: ANN001
            ) -> tuple[list[Row], dict[str, Series], dict]:
    """Every build and floor run; the stage profiles. Rounds alternate this code (A), the other (B) and the
    floor, so that each ratio compares runs made side by side. ``extra``: more arguments of every build."""
    blocker = work / "no_ocp"
    blocker.mkdir(exist_ok=True)
    (blocker / "sitecustomize.py").write_text(_NO_OCP, encoding="utf-8")
    codes = {"A": ROOT} | ({"B": vs} if vs is not None else {})
    floors = {install: Series() for install in installs}
    rows: list[Row] = []
    for template in templates:
        for install in installs:
            row = Row(template, install)
            count = runs if template == DEFAULT_TEMPLATE else other_runs
            warm = template == DEFAULT_TEMPLATE
            for k in range(count + (1 if warm else 0)):
                counted = k >= (1 if warm else 0)
                floor = _run(_floor_argv(install), _env(ROOT, install, blocker), work)
                if counted:
                    row.floor.samples.append(floor)
                    floors[install].samples.append(floor)
                for key, code in codes.items():
                    sample = _run(_build_argv(template, work / f"out_{key}", extra), _env(code, install, blocker),
                                  work)
                    if counted:
                        (row.a if key == "A" else row.b).samples.append(sample)
            log(f"  {template} {install}: A {row.a.median('wall'):.2f} s"
                + (f", B {row.b.median('wall'):.2f} s" if row.b.samples else "")
                + f", floor {row.floor.median('wall'):.2f} s")
            rows.append(row)
    profiles: dict = {}
    if stages:
        for template in templates:
            for install in installs:
                for key, code in codes.items():
                    profile = _stages_in_child(template, code, install, blocker, work)
                    if profile is not None:
                        profiles[(template, install, key)] = profile
    return rows, floors, profiles


def measure_rebuilds(install: str, runs: int, work: Path, log=print,  # noqa: ANN001
                     extra: Sequence[str] = ()) -> tuple[dict[str, Series], Series]:
    """Rebuilds of the default template after each edit of :data:`REBUILD_EDITS`, cache on; and the floor runs of
    the same rounds (``extra``: more arguments of every build). Returns ``({edit: series}, floor)``."""
    from fabricate.templates import find_template

    blocker = work / "no_ocp"
    blocker.mkdir(exist_ok=True)
    (blocker / "sitecustomize.py").write_text(_NO_OCP, encoding="utf-8")
    original = find_template(DEFAULT_TEMPLATE).read_text(encoding="utf-8")
    folder = work / "rebuilds"
    folder.mkdir(exist_ok=True)
    env = _env(ROOT, install, blocker)
    env.pop("FABRICATE_NO_CACHE")
    env["FABRICATE_CACHE_DIR"] = str(work / f"cache_{install}")
    template = folder / f"{DEFAULT_TEMPLATE}.toml"
    template.write_text(original, encoding="utf-8")
    warm = _run(_build_argv(str(template), folder / "out", extra), env, work)  # fills the cache with every stage
    if warm.code not in (0, 1):
        raise RuntimeError(f"the warm-up build exited {warm.code}")
    series = {edit: Series() for edit in REBUILD_EDITS}
    floor = Series()
    for k in range(runs):
        floor.samples.append(_run(_floor_argv(install), _env(ROOT, install, blocker), work))
        for edit, (old, new) in REBUILD_EDITS.items():
            if old and old not in original:
                raise RuntimeError(f"{DEFAULT_TEMPLATE}: {old!r} is not in the template ({edit} edit)")
            template.write_text(original.replace(old, new.format(k=k), 1) if old else original, encoding="utf-8")
            series[edit].samples.append(_run(_build_argv(str(template), folder / "out", extra), env, work))
    log(f"  rebuilds {install}: " + ", ".join(f"{e} {v.median('wall'):.2f} s" for e, v in series.items())
        + f", floor {floor.median('wall'):.2f} s")
    return series, floor


def print_rebuilds(results: dict[str, tuple[dict[str, Series], Series]], out=sys.stdout,  # noqa: ANN001
                   extra: Sequence[str] = ()) -> None:
    given = f", `{shlex.join(extra)}`" if extra else ""
    print(f"### Rebuild after an edit (stage cache on, default template{given})", file=out)
    print(file=out)
    print("| install | edit | runs | wall s | CPU s | peak MB | x floor | x floor CPU |", file=out)
    print("|---|---|---|---|---|---|---|---|", file=out)
    for install, (series, floor) in results.items():
        print(f"| {install} | floor (imports only) | {len(floor.samples)} | {_fmt(floor.median('wall'))} | "
              f"{_fmt(floor.median('cpu'))} | {_fmt(floor.median('rss_mb'), 0)} | 1.00 | 1.00 |", file=out)
        for edit, row in series.items():
            codes = "" if all(s.code in (0, 1) for s in row.samples) else \
                " (exit codes: " + ",".join(str(s.code) for s in row.samples) + ")"
            print(f"| {install} | {edit}{codes} | {len(row.samples)} | {_fmt(row.median('wall'))} | "
                  f"{_fmt(row.median('cpu'))} | {_fmt(row.median('rss_mb'), 0)} | {_fmt(_ratio(row, floor))} | "
                  f"{_fmt(_ratio(row, floor, 'cpu'))} |", file=out)
    print(file=out)
    print("Each round: the floor, then one rebuild per edit, each edit with a value no earlier round used (so the "
          "stages its table reaches run, the others are served by the cache); x floor: median of the per-round "
          "ratios.", file=out)


def _fmt(x: float, digits: int = 2) -> str:
    return "n/a" if x != x else f"{x:.{digits}f}"


def print_tables(rows: list[Row], floors: dict[str, Series], profiles: dict, vs: Path | None,
                 out=sys.stdout, extra: Sequence[str] = ()) -> None:  # noqa: ANN001
    def p(text: str = "") -> None:
        print(text, file=out)

    p("### Import floor")
    p()
    p("| install | imports | runs | wall s | CPU s | peak MB |")
    p("|---|---|---|---|---|---|")
    for install, series in floors.items():
        what = "core set" + (" + OCP.STEPCAFControl" if install == "cad" else "")
        p(f"| {install} | {what} | {len(series.samples)} | {_fmt(series.median('wall'))} | "
          f"{_fmt(series.median('cpu'))} | {_fmt(series.median('rss_mb'), 0)} |")
    p()
    p(f"core set: {', '.join(FLOOR_MODULES)}")
    p()
    p(f"### Whole-process builds (`fabricate build T -o DIR --force -q{''.join(' ' + a for a in extra)}`)")
    p()
    head = "| template | install | runs | wall s | CPU s | peak MB | x floor | x floor CPU |"
    rule = "|---|---|---|---|---|---|---|---|"
    if vs is not None:
        head += " before: wall s | CPU s | peak MB | x floor | now / before |"
        rule += "---|---|---|---|---|"
    p(head)
    p(rule)
    for row in rows:
        if not row.a.samples:
            continue
        fail = "" if all(s.code in (0, 1) for s in row.a.samples + row.b.samples) else " (exit codes: " + \
            ",".join(str(s.code) for s in row.a.samples + row.b.samples) + ")"
        line = (f"| {row.template}{fail} | {row.install} | {len(row.a.samples)} | {_fmt(row.a.median('wall'))} | "
                f"{_fmt(row.a.median('cpu'))} | {_fmt(row.a.median('rss_mb'), 0)} | "
                f"{_fmt(_ratio(row.a, row.floor))} | {_fmt(_ratio(row.a, row.floor, 'cpu'))} |")
        if vs is not None and row.b.samples:
            line += (f" {_fmt(row.b.median('wall'))} | {_fmt(row.b.median('cpu'))} | "
                     f"{_fmt(row.b.median('rss_mb'), 0)} | {_fmt(_ratio(row.b, row.floor))} | "
                     f"{_fmt(_ratio(row.a, row.b))} |")
        p(line)
    p()
    p("x floor: median over the rounds of build wall / floor wall (the floor of the same install, run in the "
      "same round); x floor CPU: the same of CPU time (steadier on a loaded machine); now / before: median of "
      "the paired wall ratios.")
    if not profiles:
        return
    for install in INSTALLS:
        keys = [k for k in profiles if k[1] == install]
        if not keys:
            continue
        templates = list(dict.fromkeys(k[0] for k in keys))
        for code in ("A", "B"):
            cols = [t for t in templates if (t, install, code) in profiles]
            if not cols:
                continue
            stages = list(dict.fromkeys(s for t in cols for s in profiles[(t, install, code)] if s != "exit code"))
            label = "this code" if code == "A" else "before (--vs)"
            p()
            p(f"### Per stage, {install} install, {label}: wall s / CPU s / peak MB (serial, in-process)")
            p()
            p("| stage | " + " | ".join(cols) + " |")
            p("|---|" + "---|" * len(cols))
            for stage in stages:
                cells = []
                for t in cols:
                    v = profiles[(t, install, code)].get(stage)
                    cells.append("" if v is None else f"{v['wall']:.2f} / {v['cpu']:.2f} / {v['peak_mb']:.0f}")
                p(f"| {stage} | " + " | ".join(cells) + " |")
            totals = [sum(v["cpu"] for s, v in profiles[(t, install, code)].items() if s != "exit code")
                      for t in cols]
            p("| total CPU (stages) | " + " | ".join(f"{x:.2f}" for x in totals) + " |")
    p()
    p("Indented rows (STEP probe, picture jobs) are inside their stage and taken out of its time and CPU; the "
      "total adds every row. Peak MB: the process's resident high-water mark within that row.")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="counted runs of the default template (default 5)")
    parser.add_argument("--other-runs", type=int, default=1, help="counted runs of each other template (default 1)")
    parser.add_argument("--templates", help="comma-separated template names (default: every shipped one)")
    parser.add_argument("--installs", default=",".join(INSTALLS), help="core, cad or both (default both)")
    parser.add_argument("--vs", type=Path, metavar="PATH", help="another checkout to compare with (paired runs)")
    parser.add_argument("--no-stages", action="store_true", help="skip the per-stage profiles")
    parser.add_argument("--json", type=Path, help="also write every sample here")
    parser.add_argument("--rebuilds", action="store_true",
                        help="only the default template's cached rebuilds after an edit of each table (--runs rounds)")
    parser.add_argument("--build-args", default="", metavar="ARGS",
                        help="more arguments of every build, e.g. --build-args=--no-pictures (split like a shell)")
    parser.add_argument("--stage-profile", metavar="TEMPLATE", help=argparse.SUPPRESS)  # the per-stage child
    args = parser.parse_args(argv)
    if args.stage_profile:
        json.dump(stage_profile(args.stage_profile), sys.stdout)
        return 0
    sys.path.insert(0, str(ROOT))
    from fabricate.templates import shipped_templates

    templates = args.templates.split(",") if args.templates else [p.stem for p in shipped_templates()]
    installs = [i for i in args.installs.split(",") if i in INSTALLS]
    if "cad" in installs and not ocp_installed():
        print("OCP is not installed here: the cad rows are skipped", file=sys.stderr)
        installs.remove("cad")
    vs = args.vs.resolve() if args.vs else None
    extra = shlex.split(args.build_args)
    if vs is not None and not (vs / "fabricate" / "__init__.py").is_file():
        parser.error(f"--vs {vs}: not a fabricate checkout (no fabricate/__init__.py)")
    if args.rebuilds:
        with tempfile.TemporaryDirectory(prefix="bench_build_") as tmp:
            results = {install: measure_rebuilds(install, args.runs, Path(tmp),
                                                 log=lambda text: print(text, file=sys.stderr, flush=True),
                                                 extra=extra)
                       for install in installs}
        print_rebuilds(results, extra=extra)
        return 0
    with tempfile.TemporaryDirectory(prefix="bench_build_") as tmp:
        rows, floors, profiles = measure(templates, installs, args.runs, args.other_runs, vs, not args.no_stages,
                                         Path(tmp), log=lambda text: print(text, file=sys.stderr, flush=True),
                                         extra=extra)
    print_tables(rows, floors, profiles, vs, extra=extra)
    if args.json:
        data = {"rows": [{"template": r.template, "install": r.install, "a": [vars(s) for s in r.a.samples],
                          "b": [vars(s) for s in r.b.samples], "floor": [vars(s) for s in r.floor.samples]}
                         for r in rows],
                "profiles": {"|".join(k): v for k, v in profiles.items()}}
        args.json.write_text(json.dumps(data, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
