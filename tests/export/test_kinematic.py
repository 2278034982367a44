"""The kinematic drawing as CAD programs read it (issue 26, item 5): labels that never overlap, dimensions
that LibreCAD draws and FreeCAD reads at their true value, and text that prints on white paper."""

from __future__ import annotations

import functools
import io
import itertools
import math
from types import SimpleNamespace

import ezdxf
import numpy as np
import pytest
import shapely

from fabricate.export.kinematic import dimension_text_boxes, kinematic_dxf, text_box
from fabricate.mechanism import Body
from tests.conftest import make_four_bar


def crowded() -> tuple[SimpleNamespace, dict[str, np.ndarray]]:
    """Joints a text height apart (where labels at a fixed offset would print over each other), a compound
    hinge, a free point and links crossing each other."""
    bodies = (Body("base", {"O": (0.0, 0.0), "A": (1.0, 0.5), "C": (2.0, -0.5), "P": (2.5, 0.4)}),
              Body("arm", {"B": (0.0, 0.0), "D": (30.0, 0.0), "D2": (30.0, 0.0), "T": (31.0, 1.0)}),
              Body("cross", {"E": (0.0, 0.0), "F": (30.0, 0.0)}))
    joints = [SimpleNamespace(name=n) for n in ("O", "A", "C", "P", "B", "D", "D2", "E", "F")]
    poses = {"base": np.zeros(3), "arm": np.array([0.0, 10.0, -0.3]), "cross": np.array([0.0, -5.0, 0.5])}
    return SimpleNamespace(bodies=bodies, joints=joints), poses


DRAWINGS = ("four_bar", "crowded")


@functools.cache
def drawing(name: str) -> bytes:
    """Drawing ``name`` of :data:`DRAWINGS`, made when a test first asks (at collection, every worker made each
    twice, ~0.6 s of CPU, whether or not it ran these tests)."""
    if name == "four_bar":
        mech = make_four_bar()
        return kinematic_dxf(mech, mech.sweep(5).poses_at(2))
    return kinematic_dxf(*crowded())


@pytest.mark.parametrize("name", DRAWINGS)
def test_no_two_labels_or_a_label_and_dimension_text_overlap(name):
    """Each label's box (ezdxf's font metrics, read back from the file) meets no other label's box and no
    dimension's text; a label standing off its point has a leader line from the point to it."""
    data = drawing(name)
    msp = ezdxf.read(io.StringIO(data.decode())).modelspace()
    labels = {t.dxf.text: text_box(t) for t in msp.query('TEXT[layer=="LABELS"]')}
    dims = [box for d in msp.query("DIMENSION") for box in dimension_text_boxes(d)]
    assert len(dims) == len(msp.query("DIMENSION"))
    for (a, box_a), (b, box_b) in itertools.combinations(labels.items(), 2):
        assert not box_a.intersects(box_b), (name, a, b)
    for label, box in labels.items():
        assert not any(box.intersects(d) for d in dims), (name, label)
    if name == "crowded":  # O, A, C, P lie within 2.5 mm: most labels need a leader
        leaders = msp.query('LINE[layer=="LABELS"]')
        assert len(leaders) >= 2
        for line in leaders:  # a leader runs from a point's circle to its label's box
            start = (line.dxf.start.x, line.dxf.start.y)
            end = shapely.Point(line.dxf.end.x, line.dxf.end.y)
            assert any(box.distance(end) < 1e-6 for box in labels.values())
            centres = [(c.dxf.center.x, c.dxf.center.y) for c in msp.query("CIRCLE")]
            assert min(math.dist(start, c) for c in centres) < 2.0 * 2.5
            assert end.distance(shapely.Point(start)) > 0


def freecad_distance(dim) -> float:
    """What FreeCAD 0.20's DXF importer (Mod/Draft/importDXF.py, processdxf, 'Draw dimensions') makes of a
    linear DIMENSION: Start = group 13, End = group 14, moved onto the measuring direction when the rotation
    (group 50) is 0/180 (End keeps Start's y) or 90/270 (End keeps Start's x); Distance = |End - Start|.
    (An ordinate dimension, type 6, would read as its leader's length.)"""
    p1, p2 = np.array(dim.dxf.defpoint2)[:2], np.array(dim.dxf.defpoint3)[:2]
    assert dim.dimtype in (0, 1)
    angle = dim.dxf.get("angle", 0.0)
    if dim.dimtype == 0 and angle in (0, 180):
        p2 = np.array([p2[0], p1[1]])
    elif dim.dimtype == 0 and angle in (90, 270):
        p2 = np.array([p1[0], p2[1]])
    return float(np.hypot(*(p2 - p1)))


@pytest.mark.parametrize("name", DRAWINGS)
def test_every_dimension_measures_its_true_value(name):
    """Every DIMENSION is linear or aligned (no ordinate: LibreCAD 2.2 does not draw them); its measurement
    read back with ezdxf and as FreeCAD's importer computes it equals the geometric distance: a link's length
    between its joints, or a joint's |x| or |y| from the origin."""
    data = drawing(name)
    msp = ezdxf.read(io.StringIO(data.decode())).modelspace()
    joints = [np.array(c.dxf.center)[:2] for c in msp.query('CIRCLE[layer=="JOINTS"]')]
    links = {tuple(sorted(tuple(np.round(np.array(end)[:2], 9)) for end in (line.dxf.start, line.dxf.end)))
             for line in msp.query('LINE[layer=="LINKS"]')}
    dims = msp.query("DIMENSION")
    assert {d.dimtype for d in dims} <= {0, 1}
    for d in dims:
        p1, p2 = np.array(d.dxf.defpoint2)[:2], np.array(d.dxf.defpoint3)[:2]
        if d.dxf.layer == "DIMENSIONS":  # along a link, from joint to joint
            assert tuple(sorted((tuple(np.round(p1, 9)), tuple(np.round(p2, 9))))) in links
            true = float(np.hypot(*(p2 - p1)))
        else:  # from the origin to a joint, along x (0 deg) or y (90 deg)
            assert d.dxf.layer == "COORDINATES" and tuple(p1) == (0.0, 0.0)
            assert any(np.allclose(p2, j, atol=1e-9) for j in joints)
            true = abs(float(p2[0] if d.dxf.angle == 0.0 else p2[1]))
        assert d.get_measurement() == pytest.approx(true, abs=1e-9)
        assert freecad_distance(d) == pytest.approx(true, abs=1e-9)


def test_text_prints_on_white_paper():
    """Text is by layer (colour 256) on layers of ACI 7 (black on white) or 5 (blue); no yellow (2) or cyan (4)
    anywhere; dimension text takes its layer's colour."""
    doc = ezdxf.read(io.StringIO(kinematic_dxf(*crowded()).decode()))
    colours = {layer.dxf.name: layer.color for layer in doc.layers if layer.dxf.name != "0"}
    assert not {2, 4} & set(colours.values()), colours
    assert colours["LABELS"] == 7 and colours["DIMENSIONS"] in (5, 7) and colours["COORDINATES"] in (5, 7)
    msp = doc.modelspace()
    assert all(e.dxf.color == 256 for e in msp)
    style = doc.dimstyles.get("FABRICATE")
    assert style.dxf.get("dimclrt", 0) in (0, 256) and style.dxf.get("dimclrd", 0) in (0, 256)


def test_label_candidates_tested_a_chunk_at_a_time_are_those_tested_one_at_a_time():
    """``_free_boxes`` (shapely's array functions over a chunk of candidates) yields exactly the candidates,
    centres and boxes the one-at-a-time test finds free: the same floats, the same predicates. Obstacles are
    set so that some candidates of the first ring are blocked and some free, and ``others`` blocks more."""
    from fabricate.export import kinematic as kin

    p, radius, text_h, half = np.array([3.0, -2.0]), 0.9, 1.5, np.array([6.2, 0.75])
    obstacles = [shapely.box(4.0, -1.0, 12.0, 3.0), shapely.LineString([(-20.0, -6.0), (20.0, -4.5)]),
                 shapely.Point(-4.0, 1.0).buffer(2.0, quad_segs=4)]
    others = shapely.Point(3.0, 9.0).buffer(3.0, quad_segs=4)
    tree = shapely.STRtree(obstacles)
    expected = []
    for index, (ring, direction) in enumerate(zip(kin._CANDIDATE_RINGS, kin._CANDIDATE_DIRECTIONS, strict=True)):
        u = np.array(direction)
        reach = radius + ring * text_h + min(half[0] / max(abs(u[0]), 1e-9), half[1] / max(abs(u[1]), 1e-9))
        centre = p + u * reach
        box = shapely.box(*(centre - half), *(centre + half))
        if not (len(tree.query(box.buffer(0.25 * text_h, join_style="mitre"), predicate="intersects"))
                or box.intersects(others)):
            expected.append((index, centre, box))
    found = list(kin._free_boxes(p, radius, half, text_h, tree, others))
    assert 0 < len(found) < len(kin._CANDIDATE_RINGS)
    assert expected[0][0] > 0  # the first candidate is blocked
    assert [k for k, _, _ in found] == [k for k, _, _ in expected]
    for (_, centre, box), (_, want_centre, want_box) in zip(found, expected, strict=True):
        assert np.array_equal(centre, want_centre)
        assert shapely.equals_exact(box, want_box, tolerance=0.0)
