"""admesh, a real STL client, reads every mesh a build writes as one closed part of the reported volume
with nothing to repair (.ci/run installs it; the test skips only where it is absent)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fabricate.output import write_output

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


@pytest.mark.slow
@pytest.mark.parametrize("template", ["gear_pair_elliptic", "finger_five_bar_ncg"])
def test_admesh_reads_every_part_whole_without_repair(template, tmp_path, shipped_build):
    outcome = shipped_build(template)
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


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("librecad") is None or shutil.which("pdftoppm") is None,
                    reason="LibreCAD or poppler-utils not installed")
def test_librecad_draws_dimension_text_at_least_2_5_mm(tmp_path, shipped_build):
    """LibreCAD sizes dimension text by the drawing's header and dimension style, not by per-entity
    overrides: its PDF, printed at 1:1 and rasterised at 10 px/mm, shows dimension digits >= 2.5 mm."""
    import os

    import numpy as np
    from PIL import Image
    from scipy import ndimage

    from fabricate.export.dxf import MIN_DRAWING_TEXT_MM

    outcome = shipped_build("finger_five_bar_ncg")
    dxf = tmp_path / "kinematic.dxf"
    dxf.write_bytes(outcome.files["drawings/kinematic.dxf"])
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "XDG_RUNTIME_DIR": str(tmp_path)}
    run = subprocess.run(["librecad", "dxf2pdf", "-s", "1", "-c", str(dxf.name)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and (tmp_path / "kinematic.pdf").is_file(), run.stderr
    subprocess.run(["pdftoppm", "-r", "254", "-png", "kinematic.pdf", "page"], cwd=tmp_path, check=True,
                   timeout=120)
    image = np.asarray(Image.open(next(tmp_path.glob("page*.png"))).convert("RGB")).astype(int)
    # layer DIMENSIONS is ACI 2 (yellow): its small connected blobs are the dimension digits
    yellow = (image[:, :, 0] > 180) & (image[:, :, 1] > 180) & (image[:, :, 2] < 120)
    labels, count = ndimage.label(yellow, structure=np.ones((3, 3)))
    sizes = np.array([(s[0].stop - s[0].start, s[1].stop - s[1].start) for s in ndimage.find_objects(labels)])
    px_per_mm = 254 / 25.4
    glyphs = sizes[(sizes[:, 0] < 10 * px_per_mm) & (sizes[:, 1] < 1.2 * sizes[:, 0]) & (sizes[:, 0] > 3)]
    assert len(glyphs) >= 10  # the link lengths' and ordinates' digits
    # digit height is the font's cap height, ~0.9-1.0 of the text height
    assert np.median(glyphs[:, 0]) / px_per_mm >= 0.9 * MIN_DRAWING_TEXT_MM
