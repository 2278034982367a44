"""The kinematic drawing (``drawings/kinematic.dxf``): joints, link centre lines and their dimensions at one pose.

Its documents come from :mod:`fabricate.export.dxf` (R2010 in mm, fixed metadata, the layer colours).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import ezdxf
import numpy as np

from fabricate.export.dxf import DIMSTYLE, MIN_DRAWING_TEXT_MM, document_bytes, new_document
from fabricate.planar import transform_points

if TYPE_CHECKING:
    from fabricate.mechanism import Mechanism


def kinematic_dxf(mechanism: Mechanism, poses: Mapping[str, np.ndarray]) -> bytes:
    """Kinematic drawing at one pose: joints, link centre lines, link-length and joint-coordinate dimensions.

    Parameters
    ----------
    mechanism : Mechanism
    poses : Mapping[str, (3,) array]
        World pose of every body (the first pose of the motion).
    """
    doc = new_document(("LINKS", "JOINTS", "DIMENSIONS", "LABELS"), dimensions=True)
    msp = doc.modelspace()
    joint_names = {j.name for j in mechanism.joints}
    world: dict[str, np.ndarray] = {}
    for body in mechanism.bodies:
        for name in body.points:
            world.setdefault(name, transform_points(poses[body.name], body.point(name)))
    span = max(1.0, float(np.ptp(np.array(list(world.values())), axis=0).max())) if world else 1.0
    text_h = round(max(MIN_DRAWING_TEXT_MM, span / 60.0), 3)
    # the sizes go in a dimension style of their own (readers ignore per-entity overrides) and in the
    # drawing's header variables, which LibreCAD sizes every dimension by
    sizes = {"dimtxt": text_h, "dimasz": text_h, "dimdec": 3, "dimlfac": 1.0, "dimexo": 0.5 * text_h,
             "dimexe": 0.5 * text_h, "dimgap": 0.3 * text_h, "dimtad": 1}
    doc.dimstyles.new(DIMSTYLE, dxfattribs=dict(sizes))  # ezdxf adds its name to the dict it is given
    for variable, value in sizes.items():
        doc.header[f"${variable.upper()}"] = value
    drawn: set[tuple[str, ...]] = set()
    for body in mechanism.bodies:
        names = [n for n in body.points if n in joint_names] or list(body.points)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                key = tuple(sorted((a, b)))
                pa = transform_points(poses[body.name], body.point(a))
                pb = transform_points(poses[body.name], body.point(b))
                length = float(np.hypot(*(pb - pa)))
                if key in drawn or length < 1e-6:
                    continue
                drawn.add(key)
                msp.add_line(tuple(pa), tuple(pb), dxfattribs={"layer": "LINKS"})
                dim = msp.add_aligned_dim(p1=tuple(pa), p2=tuple(pb), distance=3.0 * text_h, dimstyle=DIMSTYLE,
                                          dxfattribs={"layer": "DIMENSIONS"})
                dim.render()
    # points at one spot (a compound hinge) get one label and one pair of ordinate dimensions
    spots: dict[tuple[float, float], list[str]] = {}
    for name in sorted(world):
        spots.setdefault((round(float(world[name][0]), 6), round(float(world[name][1]), 6)), []).append(name)
    for names in spots.values():
        p = world[names[0]]
        is_joint = any(n in joint_names for n in names)
        msp.add_circle(tuple(p), 0.6 * text_h if is_joint else 0.3 * text_h,
                       dxfattribs={"layer": "JOINTS" if is_joint else "LABELS"})
        label = f"{', '.join(names)} ({p[0]:.3f}, {p[1]:.3f})"
        text = msp.add_text(label, height=text_h, dxfattribs={"layer": "LABELS"})
        text.set_placement((float(p[0] + text_h), float(p[1] + text_h)),
                           align=ezdxf.enums.TextEntityAlignment.BOTTOM_LEFT)
        if is_joint:
            for add, offset in ((msp.add_ordinate_x_dim, (0.0, -4.0 * text_h)),
                                (msp.add_ordinate_y_dim, (-4.0 * text_h, 0.0))):
                dim = add(feature_location=tuple(p), offset=offset, dimstyle=DIMSTYLE,
                          dxfattribs={"layer": "DIMENSIONS"})
                dim.render()
    return document_bytes(doc)
