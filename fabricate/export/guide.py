"""The assembly guide: assembly.md and a picture per step (``assembly/step_NN.png``).

Encoders only: :func:`guide_markdown` returns the text, :func:`guide_pictures` PNG bytes (the pipeline
writes them). The steps come from :func:`fabricate.parts.assembly.assembly_guide`.

Each picture shows the assembly after its step at the first pose in an oblique view from above: every
plate a prism (its top face true to the plan, the height drawn up and to the right), the parts placed
before in grey and the step's new parts, pins and springs in orange, drawn bottom to top (painter's order).
All pictures of a guide share one frame, so they line up when paged through.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.parts.assembly import GuideStep

if TYPE_CHECKING:
    from fabricate.mechanism import Motion
    from fabricate.parts.partset import PartSet

#: Picture size (inches at :data:`DPI`): 360 × 270 px.
SIZE_IN = (3.6, 2.7)
DPI = 100
#: Oblique projection: a point at height z is drawn shifted by z × this in plan (x, y).
OBLIQUE = np.array([0.35, 0.5])
#: Colours: placed before (top face, sides), new in this step (top, sides), edges, pins, springs.
OLD = ("#d3d7db", "#a0a6ad")
NEW = ("#f5a04a", "#c4701f")
EDGE = "#3a3a3a"
PIN, NEW_PIN = "#555555", "#d9480f"
SPRING, NEW_SPRING = "#5f6b76", "#d9480f"


def guide_markdown(steps: Sequence[GuideStep], name: str, copies: int = 1, pictures: bool = True) -> str:
    """assembly.md: the numbered steps, each with its picture, the parts and hardware it fits, what to do
    and the tool.

    The "Parts and hardware" lines read ``- N × `item` (kind)``, N per copy (``shared`` items: in all); over
    the whole guide they add up to the bill of materials. ``pictures=False`` (a build without its pictures)
    links no step picture and says so.
    """
    tools = list(dict.fromkeys(s.tool for s in steps if s.tool and s.tool not in ("none", "as above",
                                                                                 "as the parts need")))
    per = (f"Quantities are for one copy: the design has {copies} identical copies (the BOM's quantities are "
           "for all of them); items marked shared are bought once for all copies." if copies > 1 else
           "Quantities are for the whole design.")
    seen = ("Each picture shows the assembly after its step at the first pose, seen from above; the step's new "
            "parts are orange." if pictures else "This build was made without its pictures (--no-pictures): build "
            "again without that option for a picture of each step.")
    out = [f"# Assembly: {name}", "",
           f"Follow the steps in order. {seen} Every part and every piece of hardware of the bill of "
           "materials (`bom.csv`) is fitted in exactly one step.", "", per, "",
           "Tools: " + "; ".join(tools) + ".", ""]
    for step in steps:
        out += [f"## Step {step.number}. {step.title}", ""]
        out += [f"![step {step.number}]({step.picture})", ""] if pictures else []
        if step.items:
            out += ["Parts and hardware:", ""]
            out += [f"- {i.qty} × `{i.item}` ({i.kind}{', shared' if i.shared else ''})" for i in step.items]
            out.append("")
        out += [f"{k}. {line}" for k, line in enumerate(step.text, start=1)]
        out += ["", f"Tool: {step.tool}.", ""]
    return "\n".join(out)


def _world(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return np.column_stack([pose[0] + c * points[:, 0] - s * points[:, 1],
                            pose[1] + s * points[:, 0] + c * points[:, 1]])


def _prism(rings: list[np.ndarray], z0: float, z1: float) -> tuple[np.ndarray, list[np.ndarray], list[np.ndarray]]:
    """Projected side quads (k, 4, 2) of the outer ring and the top face's rings of a prism."""
    outer = rings[0]
    lo, hi = outer + z0 * OBLIQUE, outer + z1 * OBLIQUE
    nxt = np.roll(np.arange(len(outer)), -1)
    quads = np.stack([lo, lo[nxt], hi[nxt], hi], axis=1)
    return quads, [r + z1 * OBLIQUE for r in rings], [outer + z0 * OBLIQUE]


def _face_path(rings: list[np.ndarray]) -> Any:
    from matplotlib.path import Path

    # each ring closed by its first point again (the CLOSEPOLY vertex), as arrays: the same vertices and codes
    verts = np.concatenate([np.concatenate([ring, ring[:1]]) for ring in rings])
    codes = np.full(len(verts), Path.LINETO, dtype=Path.code_type)
    starts = np.cumsum([0] + [len(ring) + 1 for ring in rings[:-1]])
    codes[starts] = Path.MOVETO
    codes[starts + np.array([len(ring) for ring in rings])] = Path.CLOSEPOLY
    return Path(verts, codes)


#: One drawn solid: (the z its top ends at, its side quads (k, 4, 2), its top face's rings), in the picture's plane.
_Solid = tuple[float, np.ndarray, list[np.ndarray]]


def guide_pictures(partset: PartSet, motion: Motion, steps: Sequence[GuideStep]) -> dict[str, bytes]:
    """One PNG per step (``assembly/step_NN.png``): the parts, pins and springs in place after it."""
    from fabricate.plotting import png_bytes

    poses = {name: motion.pose(name)[0] for name in motion.body_names}
    corners: list[np.ndarray] = []  # every drawn point, for the common view of all the steps
    solids = _part_solids(partset, poses, corners)
    pins = _pin_segments(partset, poses, corners)
    springs = _spring_drawings(partset, poses, corners)
    actuator = _actuator_solids(partset, poses, corners)
    allpts = np.concatenate(corners) if corners else np.zeros((1, 2))
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    pad = 0.04 * float(max(hi - lo)) + 1.0
    # one figure for every step (the same frame), and each part's, pin's and spring's artists made once per look
    # (new or placed before): each step adds its artists in painter's order, draws, and removes them again, the
    # same pixels as a new figure of new artists per step without building them all again. add_artist: the view
    # is fixed (_frame), so the data-limit passes of add_collection, add_patch (every segment of a face's
    # outline) and plot only cost time
    scene = _Scene(solids, pins, springs, actuator)
    fig, ax = _frame((lo - pad, hi + pad))
    pictures = {}
    for step in steps:
        drawn = [ax.add_artist(artist) for layer in scene.layers(step) for artist in scene.artists(*layer)]
        drawn.append(fig.text(0.02, 0.97, f"step {step.number}", fontsize=8, va="top", color=EDGE))
        pictures[step.picture] = png_bytes(fig)
        for artist in drawn:
            artist.remove()
    return pictures


def _part_solids(partset: PartSet, poses: dict[str, np.ndarray], corners: list[np.ndarray]) -> dict[str, _Solid]:
    """Each part as placed at the first pose, by name (its side quads added to ``corners``)."""
    # coarse outlines: a picture of 360 px needs no finer than a few hundredths of the assembly's size
    span = max((float(np.ptp(p.outline.vertices, axis=0).max()) for p in partset.parts), default=10.0)
    tol = max(0.02, span / 300.0)
    solids: dict[str, _Solid] = {}
    for part in partset.parts:
        pose = poses.get(part.body, np.zeros(3))
        rings = [_world(r, pose) for r in part.polygons(tol)]
        quads, top, _ = _prism(rings, part.z_mm, part.z_mm + part.thickness_mm)
        solids[part.name] = (part.z_mm + part.thickness_mm, quads, top)
        corners.append(quads.reshape(-1, 2))
    return solids


def _pin_segments(partset: PartSet, poses: dict[str, np.ndarray],
                  corners: list[np.ndarray]) -> dict[str, tuple[float, np.ndarray]]:
    """Each pin as a segment along its axis, by joint: (the z its top ends at, its two end points (2, 2))."""
    pins = {}
    for pin in partset.pins:
        hole = next((h for p in partset.parts if p.body == pin.bodies[0] for h in p.holes if h.joint == pin.joint),
                    None)
        if hole is None:
            continue
        centre = _world(np.asarray([hole.centre], dtype=np.float64), poses.get(pin.bodies[0], np.zeros(3)))[0]
        seg = np.array([centre + pin.z_mm * OBLIQUE, centre + (pin.z_mm + pin.length_mm) * OBLIQUE])
        pins[pin.joint] = (pin.z_mm + pin.length_mm, seg)
        corners.append(seg)
    return pins


def _spring_drawings(partset: PartSet, poses: dict[str, np.ndarray],
                     corners: list[np.ndarray]) -> dict[str, tuple[float, list[np.ndarray], list[np.ndarray]]]:
    """Each torsion spring, by joint: (the z its top ends at, its coils as circles, its two legs as polylines)."""
    springs = {}
    angles = np.linspace(0.0, 2.0 * np.pi, 40)
    circle = np.column_stack([np.cos(angles), np.sin(angles)])
    for sp in getattr(partset, "springs", ()) or ():
        centre = _world(sp.centre[None, :], poses.get(sp.pin_body, np.zeros(3)))[0]
        r = 0.5 * sp.spring.outer_d_mm
        turns = max(2, min(8, int(round(sp.spring.active_turns))))
        coils = [centre + r * circle + z * OBLIQUE for z in np.linspace(sp.z_mm[0], sp.z_mm[1], turns)]
        near = _world(sp.near_anchor[None, :], poses.get(sp.near_body, np.zeros(3)))[0]
        far = _world(sp.far_anchor[None, :], poses.get(sp.far_body, np.zeros(3)))[0]
        z_near = sp.z_mm[0] if sp.side == "top" else sp.z_mm[1]
        z_far = sp.z_mm[1] if sp.side == "top" else sp.z_mm[0]
        far_down = z_far - sp.leg_axial_mm[1] if sp.side == "top" else z_far + sp.leg_axial_mm[1]
        legs = [np.array([centre + z_near * OBLIQUE, near + z_near * OBLIQUE]),
                np.array([centre + z_far * OBLIQUE, far + z_far * OBLIQUE, far + far_down * OBLIQUE])]
        springs[sp.joint] = (sp.z_mm[1], coils, legs)
        corners += coils
    return springs


def _actuator_solids(partset: PartSet, poses: dict[str, np.ndarray], corners: list[np.ndarray]) -> list[_Solid]:
    """The actuator's body, output and screws (its catalogue solids as placed): drawn from its step on."""
    actuator: list[_Solid] = []
    placed = partset.actuator
    if placed is not None:
        for solid in placed.solids:
            pose = poses.get(placed.body_of(solid), np.zeros(3))
            quads, top, _ = _prism([_world(np.asarray(r, dtype=np.float64), pose) for r in solid.rings],
                                   float(solid.z0), float(solid.z1))
            actuator.append((float(solid.z1), quads, top))
            corners.append(quads.reshape(-1, 2))
    return actuator


def _frame(view: tuple[np.ndarray, np.ndarray]) -> tuple[Any, Any]:
    """The guide's figure and its one axes (no frame or ticks), showing ``view`` (lower left, upper right)."""
    from fabricate.plotting import figure

    fig = figure(SIZE_IN, DPI)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    ax.set_aspect("equal")
    ax.set_xlim(view[0][0], view[1][0])
    ax.set_ylim(view[0][1], view[1][1])
    return fig, ax


class _Scene:
    """What the guide draws, as placed at the first pose, and the artists made of it.

    Parameters
    ----------
    solids : dict
        Each part's :data:`_Solid`, by name.
    pins : dict
        Each pin's (top z, end points (2, 2)), by joint.
    springs : dict
        Each spring's (top z, coils, legs), by joint.
    actuator : list
        The actuator's solids.
    """

    def __init__(self, solids: dict[str, _Solid], pins: dict[str, tuple[float, np.ndarray]],
                 springs: dict[str, tuple[float, list[np.ndarray], list[np.ndarray]]], actuator: list[_Solid]) -> None:
        self.solids, self.pins, self.springs, self.actuator = solids, pins, springs, actuator
        self._made: dict[tuple[str, str, bool], list[Any]] = {}

    def layers(self, step: GuideStep) -> list[tuple[str, str, bool]]:
        """``(kind, name, new)`` of everything in place after ``step``, in painter's order (whatever ends lower
        first); ``new``: fitted in this step (drawn highlighted)."""
        solids, pins, springs = self.solids, self.pins, self.springs
        layers: list[tuple[float, int, str, str]] = [(solids[n][0], 0, "part", n) for n in step.placed if n in solids]
        layers += [(pins[j][0], 1, "pin", j) for j in step.pins if j in pins]
        layers += [(springs[j][0], 2, "spring", j) for j in step.springs if j in springs]
        if step.actuator:
            layers += [(z1, 3, "actuator", str(k)) for k, (z1, _, _) in enumerate(self.actuator)]
        new = {"part": set(step.new), "pin": set(step.new_pins), "spring": set(step.new_springs)}
        return [(kind, name, step.new_actuator if kind == "actuator" else name in new[kind])
                for _, _, kind, name in sorted(layers)]

    def artists(self, kind: str, name: str, new: bool) -> list[Any]:
        """The artists of one layer (made on first use; not yet on any axes)."""
        key = (kind, name, new)
        if key not in self._made:
            self._made[key] = self._make(kind, name, new)
        return self._made[key]

    def _make(self, kind: str, name: str, new: bool) -> list[Any]:
        from matplotlib.collections import PolyCollection
        from matplotlib.lines import Line2D
        from matplotlib.patches import PathPatch

        if kind in ("part", "actuator"):
            _, quads, top = self.solids[name] if kind == "part" else self.actuator[int(name)]
            face, side = NEW if new else OLD
            # the quads as one (k, 4, 2) array take PolyCollection's one-template-path route (the same paths;
            # matplotlib's stubs name only a sequence of polygons, its code takes the array first)
            return [PolyCollection(quads, facecolors=side, edgecolors=side, linewidths=0.3),  # type: ignore[arg-type]
                    PathPatch(_face_path(top), facecolor=face, edgecolor=EDGE, linewidth=0.4)]
        # the lines Axes.plot made of the same points and style
        if kind == "pin":
            seg = self.pins[name][1]
            return [Line2D(seg[:, 0], seg[:, 1], color=NEW_PIN if new else PIN, linewidth=1.6, solid_capstyle="round")]
        _, coils, legs = self.springs[name]
        colour = NEW_SPRING if new else SPRING
        return [Line2D(line[:, 0], line[:, 1], color=colour, linewidth=0.8) for line in [*coils, *legs]]


def motion_check(partset: PartSet, motion: Motion, min_clearance_mm: float | None = None) -> Any:
    """The final step's :class:`~fabricate.parts.assembly.MotionCheck` from a part set and its motion: the
    input range and the tip point's first and last positions (the hints' tip point, where given)."""
    from fabricate.parts.assembly import MotionCheck

    mechanism = motion.mechanism
    hints = partset.hints
    tip = (hints.get("tip_point") if isinstance(hints, dict) else getattr(hints, "tip_point", None)) or ""
    start = end = None
    if tip and tip in mechanism.point_names():
        path = motion.point(tip)
        start, end = (float(path[0, 0]), float(path[0, 1])), (float(path[-1, 0]), float(path[-1, 1]))
    a, b = mechanism.input_range
    return MotionCheck((float(a), float(b)), mechanism.input_unit, tip if start else "", start, end,
                       min_clearance_mm)


def guide_steps(partset: PartSet, motion: Motion, min_clearance_mm: float | None = None) -> tuple[GuideStep, ...]:
    """The guide of a part set: its pin stacks, then :func:`~fabricate.parts.assembly.assembly_guide`."""
    from fabricate.parts.assembly import assembly_guide, pin_stacks

    return assembly_guide(partset, pin_stacks(partset), motion_check(partset, motion, min_clearance_mm))


def guide_picture_files(partset: PartSet, motion: Motion) -> dict[str, bytes]:
    """Every step's picture (the pipeline's background job: the steps are the same as assembly.md's)."""
    return guide_pictures(partset, motion, guide_steps(partset, motion))
