"""admesh, a real STL client, reads every mesh a build writes as one closed part of the reported volume
with nothing to repair (.ci/run installs it; the test skips only where it is absent)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fabricate.output import write_output
from fabricate.pipeline import run_build
from fabricate.spec import load_design

pytestmark = pytest.mark.skipif(shutil.which("admesh") is None, reason="admesh not installed")


def _admesh(path: Path) -> dict[str, float]:
    run = subprocess.run(["admesh", str(path)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    stats = {}
    for key in ("Number of parts", "Volume", "Degenerate facets", "Edges fixed", "Facets removed",
                "Facets added", "Facets reversed", "Backwards edges", "Normals fixed",
                "Total disconnected facets"):
        match = re.search(rf"{key}\s*:\s*(-?[\d.]+)", run.stdout)
        assert match, f"admesh printed no {key!r}"
        stats[key] = float(match.group(1))
    return stats


@pytest.mark.parametrize("template", ["gear_pair_elliptic", "finger_five_bar_ncg"])
def test_admesh_reads_every_part_whole_without_repair(template, tmp_path):
    outcome = run_build(load_design(template))
    write_output(outcome.files, tmp_path / "out")
    parts = outcome.report["parts"]
    for part in parts:
        stats = _admesh(tmp_path / "out" / part["stl"])
        assert stats["Number of parts"] == 1, part["name"]
        for key in ("Degenerate facets", "Edges fixed", "Facets removed", "Facets added", "Facets reversed",
                    "Backwards edges", "Normals fixed", "Total disconnected facets"):
            assert stats[key] == 0, (part["name"], key, stats[key])
        # admesh sums float32 facets: 1e-5 relative of the mesh volume the report gives
        assert stats["Volume"] == pytest.approx(part["stl_volume_mm3"], rel=1e-5)
    # every plate: one admesh part per copy on it, together every copy of every part, nothing repaired
    copies = parts[0]["copies"]
    plates = sorted((tmp_path / "out" / "plates").glob("plate_*.stl"))
    stats = [_admesh(plate) for plate in plates]
    assert sum(s["Number of parts"] for s in stats) == copies * len(parts)
    assert all(s["Edges fixed"] == 0 and s["Facets added"] == 0 for s in stats)
    assert sum(s["Volume"] for s in stats) == pytest.approx(copies * sum(p["stl_volume_mm3"] for p in parts),
                                                             rel=1e-5)
