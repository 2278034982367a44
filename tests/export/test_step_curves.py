"""STEP solids a CAD user can work with (issue 26, item 5): polygonised circles come back as true arcs and
gear flanks as a few smooth B-spline faces within the chord tolerance of the exact flank.

The exact flank is the gear's dense outline (:class:`fabricate.gears.teeth.GearTeeth`: exact envelope points,
its own chord error below 1 um) and its involute flank samples; the part only carries the decimated polygon
(chord tolerance 5 um), as a fused profile does. Measured (tol 5 um, 24 teeth): faces per tooth 5.0 (spur
module 0.5) to 8.6 (elliptic, approximate method); flank samples at most 4.7 um from the solid's edges (the
polygon's: 4.0 um); the whole dense outline at most 5.7 um (where two fillets meet at the root in a corner
the polygon hides); the volume's error against the dense outline's area is 1.6 to 4.3 times smaller than the
polygon's (which is 6.8e-5 to 6.2e-4: no solid built from the polygon's vertices can be within 1e-6).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import shapely

pytest.importorskip("OCP")

from fabricate.export.step import part_shape, part_step  # noqa: E402
from fabricate.export.step_curves import SPLINE_FIT_FACTOR, profile_pieces  # noqa: E402
from fabricate.export.step_read import read_step, step_problems
from fabricate.parts.model import BulgePath, Hole, Part  # noqa: E402
from fabricate.parts.profiles import circle_hull  # noqa: E402
from fabricate.planar import polygon_area  # noqa: E402
from tests.gears.test_teeth import elliptic, spur  # noqa: E402

TOL = 0.005
#: Stated bound on the faces of a gear part per tooth (two planes, the bore and the teeth's side faces).
FACES_PER_TOOTH = 10


def plate(outline: np.ndarray, holes=(), thickness: float = 2.0, name: str = "p") -> Part:
    return Part(name, "b", BulgePath.polyline(outline), tuple(holes), thickness, 0.0, 0, "sla", role="gear")


def stadium_polygon() -> tuple[np.ndarray, float]:
    """A stadium (two circles of radius 4 and 2, 20 mm apart) polygonised at the chord tolerance, as a fused
    profile carries it; and its exact area."""
    path = circle_hull(np.array([[0.0, 0.0], [20.0, 0.0]]), np.array([4.0, 2.0]))
    return path.polygon(TOL), path.area()


def test_polygonised_circles_become_true_arcs_with_the_exact_volume():
    polygon, exact = stadium_polygon()
    assert [p.kind for p in profile_pieces(polygon, np.zeros(len(polygon)))].count("arc") == 2
    part = plate(polygon, (Hole("A", np.zeros(2), 2.0),))
    (solid,) = read_step(part_step(part, TOL))
    assert solid.valid and (solid.n_cylindrical_faces, solid.n_arc_faces) == (1, 2)
    assert solid.n_faces == 2 + 1 + 2 + 2  # top, bottom, the hole, two arcs, two tangent lines
    # the arcs' circular segments are back: the polygon's area is short of the exact one by ~2e-4 relative
    assert solid.volume_mm3 == pytest.approx((exact - np.pi) * 2.0, rel=1e-9)
    assert abs(part.volume_mm3() - solid.volume_mm3) > 1e-4 * solid.volume_mm3
    assert solid.bounds[0, 0] == pytest.approx(-4.0, abs=1e-9) and solid.bounds[1, 0] == pytest.approx(22.0, abs=1e-9)
    assert step_problems(part_step(part, TOL), {"p": (part.volume_mm3(), 1)}) == []  # within the stated band


def test_corners_on_a_circle_stay_lines():
    """A rectangle's corners lie on one circle: its sides stay lines (an arc needs three or more equal steps
    under a quarter turn; a square's are a quarter turn, a rectangle's unequal)."""
    rectangle = np.array([[0.0, 0.0], [30.0, 0.0], [30.0, 10.0], [0.0, 10.0]])
    assert {p.kind for p in profile_pieces(rectangle, np.zeros(4))} == {"line"}
    square = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
    assert {p.kind for p in profile_pieces(square, np.zeros(4))} == {"line"}
    (solid,) = read_step(part_step(plate(rectangle), TOL))
    assert solid.n_faces == 6 and solid.volume_mm3 == pytest.approx(600.0, rel=1e-12)


def gear_cases():
    return {"spur_m1": spur(24, 1.0), "spur_m05": spur(24, 0.5), "elliptic_exact": elliptic("exact")[2],
            "elliptic_approx": elliptic("approx")[2]}


def edge_samples(shape) -> shapely.STRtree:
    """The solid's bottom edges (z = 0), each sampled at 100 points (a flank spline's chord there is under
    0.05 mm, its sagitta under 1e-4 um), as a tree of segments."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer

    from fabricate.export.occt import downcast

    lines = []
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(downcast("Edge", explorer.Current()))
        ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), 100)
        points = np.array([[curve.Value(t).X(), curve.Value(t).Y(), curve.Value(t).Z()] for t in ts])
        if np.all(np.abs(points[:, 2]) < 1e-9):
            lines += [shapely.LineString(points[j:j + 2, :2]) for j in range(len(points) - 1)]
        explorer.Next()
    return shapely.STRtree(lines)


def distance(points: np.ndarray, edges: shapely.STRtree) -> float:
    """Largest distance (mm) from the points to the edges."""
    _, gaps = edges.query_nearest(shapely.points(points), return_distance=True)
    return float(gaps.max())


@pytest.mark.parametrize("name", ["spur_m1", "elliptic_exact", pytest.param("spur_m05", marks=pytest.mark.slow),
                                  pytest.param("elliptic_approx", marks=pytest.mark.slow)])
def test_gear_flanks_are_a_few_smooth_faces_within_the_chord_tolerance(name):
    cut = gear_cases()[name]
    teeth = len(cut.tooth_centres)
    part = plate(cut.outline, (Hole("A", np.zeros(2), 2.0),))
    shape = part_shape(part, TOL)
    (solid,) = read_step(part_step(part, TOL, shape))
    assert solid.valid
    assert solid.n_faces <= FACES_PER_TOOTH * teeth + 3, (solid.n_faces, teeth)
    assert solid.n_faces < len(cut.outline) / 3  # the polygon gave one face per line
    assert solid.curved_area_mm2 > 0.5 * shapely.LinearRing(cut.outline).length * 2.0  # most of the side is curved
    edges = edge_samples(shape)
    flanks = np.vstack(list(cut.flanks.values()))
    assert distance(flanks, edges) <= TOL
    assert distance(cut.dense, edges) <= 1.2 * TOL
    # closer to the exact solid than the polygon is, and within the band the file states
    exact = (abs(polygon_area(cut.dense)) - np.pi) * 2.0
    assert abs(solid.volume_mm3 - exact) < abs(part.volume_mm3() - exact)
    assert abs(solid.volume_mm3 - part.volume_mm3()) <= TOL * solid.curved_area_mm2
    assert step_problems(part_step(part, TOL, shape), {"p": (part.volume_mm3(), 1)}) == []
    assert step_problems(part_step(part, TOL, shape), {"p": (1.01 * part.volume_mm3(), 1)})  # a wrong one


def test_volume_read_back_is_the_solids_own():
    """OCCT integrates a face over its whole parameter range with one Gauss rule: the flanks are single-span
    B-splines so that the volume it reads back (FreeCAD's too) is the solid's: its top face's area times the
    thickness, to rounding (a many-span spline read 0.2 % off)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    from fabricate.export.step import _path_wire

    cut = gear_cases()["elliptic_exact"]
    part = plate(cut.outline, thickness=3.0)
    face = BRepBuilderAPI_MakeFace(_path_wire(part.outline, True, "gear", TOL), True).Face()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    (solid,) = read_step(part_step(part, TOL))
    assert solid.volume_mm3 == pytest.approx(3.0 * props.Mass(), rel=1e-9)
    assert SPLINE_FIT_FACTOR * TOL < 1e-3


_FREECAD = """
import Part
shape = Part.read({path!r})
kinds = sorted(set(type(f.Surface).__name__ for f in shape.Faces))
print("FABRICATE", len(shape.Solids), repr(shape.Volume), shape.isValid(), len(shape.Faces), ",".join(kinds))
"""


@pytest.mark.skipif(shutil.which("freecadcmd") is None, reason="FreeCAD (freecadcmd) not installed")
def test_freecad_reads_a_gear_part_valid_with_its_volume(tmp_path: Path):
    cut = gear_cases()["spur_m05"]
    part = plate(cut.outline, (Hole("A", np.zeros(2), 2.0),))
    data = part_step(part, TOL)
    (solid,) = read_step(data)
    path = tmp_path / "gear.step"
    path.write_bytes(data)
    script = tmp_path / "read.py"
    script.write_text(_FREECAD.format(path=str(path)))
    result = subprocess.run(["freecadcmd", str(script)], capture_output=True, text=True, timeout=300)
    line = next(line for line in result.stdout.splitlines() if line.startswith("FABRICATE"))
    _, count, volume, valid, faces, kinds = line.split()
    assert (int(count), valid, int(faces)) == (1, "True", solid.n_faces)
    assert float(volume) == pytest.approx(solid.volume_mm3, rel=1e-9)
    assert "SurfaceOfExtrusion" in kinds and "Cylinder" in kinds
