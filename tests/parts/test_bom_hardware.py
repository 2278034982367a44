"""Standard hardware and fits in built designs (issue 25, items 2 and 3).

- every pin is a standard pin (its designation reads back to its length, in the ISO 8734 / ISO 2338 series)
  and covers its stack plus what its retention needs; a pressed pin is the shortest one over its stack,
  flush at one end with the rest a bare stub at the other;
- every screw, washer and clip of the BOM is a catalogued standard item, every row says print, cut or buy;
- every hole has its fit's nominal size (press: pin - the profile's interference; running: pin + 2 x the
  running clearance) and is modelled with the process's compensation on top;
- measured on the exported STL (sliced at mid-thickness, a circle fitted to each hole's loop), each running
  hole has the running clearance and each press-fit hole the interference, plus the compensation. The
  loop's vertices lie on the exact circle (the mesh is the polygon inscribed with the chord tolerance), so
  the diameter fitted to them matches to 1e-5 mm (the STL's float32 coordinates); the narrowest width
  across the loop may fall short of it by at most twice the chord tolerance (the sagitta of each chord).
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import trimesh

from fabricate.catalogue.designations import parse_designation
from fabricate.catalogue.pins import PinChoice, pin_lengths
from fabricate.parts.build import build_parts
from fabricate.parts.spec import PartsSpec
from fabricate.templates import shipped_templates

TEMPLATES = [p.stem for p in shipped_templates()]
EPS = 1e-9


def _standard(designation: str) -> str:
    return " ".join(designation.split()[:2])  # "ISO 8734 2 × 20" -> "ISO 8734"


def holes_part(on_pin, body):
    (part,) = [p for p in on_pin if p.body == body]
    return part


def check_pins(partset, process) -> None:
    """The pin properties of the module docstring, for one part set."""
    assert partset.pins
    for pin in partset.pins:
        assert pin.designation, pin.note
        choice = parse_designation(pin.designation)
        assert isinstance(choice, PinChoice) and choice.length_mm == pin.length_mm
        lengths = pin_lengths(pin.diameter_mm, _standard(pin.designation))
        assert pin.length_mm in lengths
        z0, z1 = pin.stack_z_mm
        assert pin.stack_mm == pytest.approx(z1 - z0, abs=1e-9) and pin.stack_mm > 0
        # the pin's own span: the stack and what it has beyond each face
        assert pin.z_mm == pytest.approx(z0 - pin.protrusion_mm[0], abs=1e-9)
        assert pin.z_mm + pin.length_mm == pytest.approx(z1 + pin.protrusion_mm[1], abs=1e-9)
        assert pin.retention == process.retention
        on_pin = [p for p in partset.parts if p.body in pin.bodies and any(h.joint == pin.joint for h in p.holes)
                  and p.role != "spacer"]
        if pin.retention == "press":
            assert pin.allowance_mm == 0.0
            holes = {p.body: next(h for h in p.holes if h.joint == pin.joint) for p in on_pin}
            assert holes[pin.holder].fit == "press"
            assert all(h.fit == "running" for b, h in holes.items() if b != pin.holder)
            # the shortest standard pin over the stack: flush at one end, the rest a stub out of the other
            assert pin.length_mm >= pin.stack_mm - EPS
            assert not [v for v in lengths if pin.stack_mm - EPS <= v < pin.length_mm]
            assert min(pin.protrusion_mm) == pytest.approx(0.0, abs=1e-9)
            assert max(pin.protrusion_mm) == pytest.approx(pin.length_mm - pin.stack_mm, abs=1e-9)
            assert pin.engagement_mm == pytest.approx(holes_part(on_pin, pin.holder).thickness_mm, abs=1e-9)
        else:
            assert pin.length_mm >= pin.stack_mm + pin.allowance_mm - EPS
            assert min(pin.protrusion_mm) >= 0.5 * pin.allowance_mm - EPS
            assert all(h.fit == "running" for p in on_pin for h in p.holes if h.joint == pin.joint)


def check_holes(partset, process) -> None:
    """Every hole has its fit's nominal size and the process's compensation on top."""
    for part in partset.parts:
        for h in part.holes:
            assert h.diameter_mm - h.nominal_mm == pytest.approx(process.hole_compensation_mm, abs=1e-9)
            if h.fit == "press":
                assert h.nominal_mm == pytest.approx(h.pin_diameter_mm - process.press_fit_interference_mm, abs=1e-9)
            elif h.fit == "running" and h.pin_diameter_mm > 0:
                assert h.nominal_mm == pytest.approx(h.pin_diameter_mm + 2 * process.running_clearance_mm, abs=1e-9)


def _fit_circle(xy: np.ndarray) -> tuple[np.ndarray, float]:
    """Algebraic least-squares circle (Kasa): x^2 + y^2 = 2 a x + 2 b y + c; centre (a, b)."""
    a, b, c = np.linalg.lstsq(np.column_stack([2 * xy[:, 0], 2 * xy[:, 1], np.ones(len(xy))]),
                              (xy ** 2).sum(axis=1), rcond=None)[0]
    return np.array([a, b]), math.sqrt(c + a * a + b * b)


def measured_holes(stl: bytes, part, tol: float) -> dict[str, tuple[float, float]]:
    """Each pin hole of ``part`` measured on its STL: (fitted diameter, narrowest width across), mm.

    The mesh is sliced at mid-thickness; every closed loop of the section but the outline is a hole, matched to
    the part's hole by its fitted centre (the STL is in the part's own coordinates).
    """
    mesh = trimesh.load(io.BytesIO(stl), file_type="stl")
    segments = trimesh.intersections.mesh_plane(mesh, [0.0, 0.0, 1.0], [0.0, 0.0, 0.5 * part.thickness_mm])
    out = {}
    for xy in _loops(np.asarray(segments)[:, :, :2]):
        centre, _ = _fit_circle(xy)
        hole = next((h for h in part.holes if np.hypot(*(np.asarray(h.centre) - centre)) < 1e-3), None)
        if hole is None:
            continue
        # the slice crosses each wall quad's diagonal half way, a point on the chord: the circle is fitted to the
        # points on the wall's vertical edges (the outermost, within a tenth of the tolerance), the narrowest
        # width is twice the least distance to any point of the loop
        far = np.hypot(*(xy - centre).T)
        centre, radius = _fit_circle(xy[far >= far.max() - 0.1 * tol])
        out[hole.joint] = (2 * radius, 2 * float(np.min(np.hypot(*(xy - centre).T))))
    return out


def _loops(segments: np.ndarray) -> list[np.ndarray]:
    """Closed loops (vertex arrays) of a section's segments (k, 2, 2), joined end to end."""
    key = lambda p: (round(float(p[0]), 6), round(float(p[1]), 6))  # noqa: E731
    ends: dict[tuple[float, float], list[int]] = {}
    for i, (p, q) in enumerate(segments):
        ends.setdefault(key(p), []).append(i)
        ends.setdefault(key(q), []).append(i)
    used = np.zeros(len(segments), dtype=bool)
    loops = []
    for start in range(len(segments)):
        if used[start]:
            continue
        used[start] = True
        loop = [segments[start][0], segments[start][1]]
        while True:
            nxt = [j for j in ends[key(loop[-1])] if not used[j]]
            if not nxt:
                break
            used[nxt[0]] = True
            p, q = segments[nxt[0]]
            loop.append(q if key(p) == key(loop[-1]) else p)
        loops.append(np.array(loop[:-1]))  # the last point closes on the first
    return loops


def check_measured(files, partset, process) -> int:
    """Every pin hole's size on the exported mesh (see the module docstring); returns how many were measured."""
    tol = process.chord_tolerance_mm
    count = 0
    for part in partset.parts:
        pin_holes = [h for h in part.holes if h.pin_diameter_mm > 0 and h.fit in ("press", "running")]
        if not pin_holes or f"parts/{part.name}.stl" not in files:
            continue
        measured = measured_holes(files[f"parts/{part.name}.stl"], part, tol)
        for h in pin_holes:
            diameter, narrowest = measured[h.joint]
            assert diameter == pytest.approx(h.diameter_mm, abs=1e-5)  # float32 STL vertices
            assert h.diameter_mm - 2 * tol - 1e-9 <= narrowest <= h.diameter_mm + 1e-9
            finished = diameter - process.hole_compensation_mm  # what the print measures once it shrinks
            if h.fit == "press":
                assert h.pin_diameter_mm - finished == pytest.approx(process.press_fit_interference_mm, abs=1e-5)
            else:
                assert 0.5 * (finished - h.pin_diameter_mm) == pytest.approx(process.running_clearance_mm, abs=1e-5)
            count += 1
    return count


def check_bom(bom) -> None:
    for row in bom:
        assert row["source"] in ("print", "cut", "buy")
        if row["kind"] in ("printed part", "cut part"):
            assert row["source"] == ("print" if row["kind"] == "printed part" else "cut")
        if row["kind"] in ("pin", "washer", "screw", "clip"):
            assert row["source"] == "buy"
            parse_designation(row.get("designation") or row["item"])  # a SpecError if not a standard item


# -- a small four-bar, built directly (fast) --------------------------------------------------------------
@pytest.mark.parametrize("process_name", ["sla_process", "laser_process"])
def test_four_bar_pins_holes_and_mesh(four_bar, process_name, request):
    from fabricate.export.stl import SolidCache, part_stl
    from tests.parts.test_build import design_for

    process = request.getfixturevalue(process_name)
    partset = build_parts(design_for(process, PartsSpec()), four_bar, four_bar.sweep(61), [])
    check_pins(partset, process)
    check_holes(partset, process)
    check_bom(partset.bom)
    cache = SolidCache(partset.chord_tolerance_mm)
    files = {f"parts/{p.name}.stl": part_stl(p, cache) for p in partset.parts}
    assert check_measured(files, partset, process) == 2 * len(four_bar.joints)
    if process.retention == "clip":  # a DIN 6799 clip on both ends of every pin, in the BOM once per clip
        clips = [r for r in partset.bom if r["kind"] == "clip"]
        assert [r["item"] for r in clips] == ["DIN 6799 1.9"] and clips[0]["qty"] == 2 * len(partset.pins)


# -- every shipped template (slow: full builds, shared) ---------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("template", TEMPLATES)
def test_shipped_pins_hardware_and_holes(template, shipped_build):
    outcome = shipped_build(template)
    assert outcome.partset is not None and outcome.design is not None
    process = outcome.design.process
    check_pins(outcome.partset, process)
    check_holes(outcome.partset, process)
    check_bom(outcome.report["bom"])
    assert check_measured(outcome.files, outcome.partset, process) > 0
    # the report states what to measure: every hole once, its nominal size apart from the model's
    measure = outcome.report["hardware"]["measure"]
    holes = [(p.name, h) for p in outcome.partset.parts for h in p.holes]
    assert len(measure) == len(holes)
    for entry, (name, h) in zip(measure, holes, strict=True):
        assert (entry["part"], entry["hole"], entry["fit"]) == (name, h.joint, h.fit)
        assert entry["nominal_mm"] == pytest.approx(h.nominal_mm) and entry["modelled_mm"] == pytest.approx(
            h.diameter_mm)
    assert "## Pins, fits and what to measure" in outcome.files["report.md"].decode("utf-8")


def test_interference_proof_sees_the_standard_pins_and_their_end_pieces(four_bar, laser_process):
    """The proof sweeps each pin over its own length (stack and clip ends), and each clip and washer on its end
    as a ring where it stands; a pin shortened to its stack would leave the clips floating."""
    from fabricate.checks.items import pin_items, pins_from_parts_layer, spacer_items
    from tests.parts.test_build import design_for

    partset = build_parts(design_for(laser_process, PartsSpec()), four_bar, four_bar.sweep(61), [])
    items = {it.name: it for it in pin_items(pins_from_parts_layer(partset.pins, partset.parts), 0.005)}
    rings = spacer_items(partset.spacers, partset.parts, 0.005)
    for pin in partset.pins:
        item = items[f"pin_{pin.joint}"]
        assert (item.z0, item.z1) == pytest.approx((pin.z_mm, pin.z_mm + pin.length_mm))
        assert item.z0 < pin.stack_z_mm[0] and item.z1 > pin.stack_z_mm[1]  # clips stand beyond both faces
        ends = sorted((r for r in rings if pin.joint in r.joints and (r.z1 <= pin.stack_z_mm[0] + 1e-9
                                                                     or r.z0 >= pin.stack_z_mm[1] - 1e-9)),
                      key=lambda r: r.z0)
        clips = [r for r in ends if r.source.kind == "clip"]
        assert len(clips) == 2 and all(item.z0 - 1e-9 <= r.z0 and r.z1 <= item.z1 + 1e-9 for r in ends)
        # each clip's groove: where the report tells the maker to cut it, from the pin's bottom end
        assert sorted(round(r.z0 - pin.z_mm, 6) for r in clips) == pytest.approx(list(pin.grooves_mm))
