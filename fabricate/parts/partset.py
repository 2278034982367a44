"""The parts of one mechanism as the parts stage hands them on (:class:`PartSet`), the slotted part, and the
small geometric helpers every editor of a part set uses (part names, cuts that run into each other, the region
the moving bodies sweep). :mod:`fabricate.parts.build` makes a part set; :mod:`fabricate.drive` edits it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.hints import PartHints
from fabricate.mechanism import Motion
from fabricate.parts.bom import Pin, Spacer
from fabricate.parts.model import BulgePath, Part
from fabricate.parts.springs import PlacedSpring
from fabricate.planar import rotation

if TYPE_CHECKING:
    from fabricate.drive.records import PlacedActuator

#: Chord tolerance (mm) of the coarse outlines used only for the layer conflict test and the swept region.
CONFLICT_CHORD_MM = 0.05


@dataclass(frozen=True)
class SlottedPart(Part):
    """A part with slots (stadium-shaped through cuts, e.g. the guide slot of a push rod) besides holes.

    Attributes
    ----------
    slots : tuple of BulgePath
        Counter-clockwise slot contours in body coordinates; cut through the plate.
    """

    slots: tuple[BulgePath, ...] = ()

    def polygons(self, chord_tolerance_mm: float) -> list[np.ndarray]:
        rings = super().polygons(chord_tolerance_mm)
        for slot in self.slots:
            ring = slot.polygon(chord_tolerance_mm)
            rings.append(ring[::-1] if slot.area() > 0 else ring)
        return rings

    def area_mm2(self) -> float:
        return super().area_mm2() - sum(abs(s.area()) for s in self.slots)


@dataclass(frozen=True)
class PartSet:
    """All parts of one mechanism and how they go together.

    Attributes
    ----------
    parts : tuple of Part
        Body parts (one per body) then printed spacers.
    bom : list of dict
        Bill of materials rows (JSON-ready): pins, spacers, washers, springs, purchased items.
    pins : tuple of Pin
    spacers : tuple of Spacer
    layers : dict[str, int]
        Body name -> layer index.
    process : str
        The process's name (a label: :class:`~fabricate.process.ProcessSpec` says what it can do).
    chord_tolerance_mm : float
        Polygonisation tolerance for meshes.
    copies : int
        Identical copies of the mechanism (BOM quantities already multiplied).
    hints : PartHints
        The synthesis hints used.
    warnings : tuple of str
        Geometry the mechanism forces but nobody can make: holes that run into each other (their
        centres closer than their radii). Parts are still built; the report should carry these.
    actuator : PlacedActuator or None
        What drives the design, as placed (:mod:`fabricate.drive.parts`); None without ``[actuator]``.
    springs : tuple of PlacedSpring
        The torsion springs, sized and placed on their pins (:mod:`fabricate.parts.springs`).
    """

    parts: tuple[Part, ...]
    bom: list[dict[str, Any]]
    pins: tuple[Pin, ...]
    spacers: tuple[Spacer, ...]
    layers: dict[str, int]
    process: str
    chord_tolerance_mm: float
    thickness_mm: float
    layer_gap_mm: float
    kerf_mm: float
    copies: int = 1
    hints: PartHints = field(default_factory=PartHints)
    warnings: tuple[str, ...] = ()
    actuator: PlacedActuator | None = None
    springs: tuple[PlacedSpring, ...] = ()

    def part(self, name: str) -> Part:
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(name)

    def body_parts(self) -> tuple[Part, ...]:
        """Parts that move with a body (spacers excluded)."""
        return tuple(p for p in self.parts if p.role != "spacer")


def safe_name(name: str) -> str:
    """A file-name-safe part name."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "part"


def overlapping_cuts(parts: Sequence[Part]) -> list[str]:
    """Holes of one part that run into each other or into a slot (the plate would fall apart there)."""
    found = []
    for part in parts:
        holes = list(part.holes)
        for i, a in enumerate(holes):
            for b in holes[i + 1:]:
                gap = float(np.hypot(*(np.asarray(a.centre) - b.centre))) - 0.5 * (a.diameter_mm + b.diameter_mm)
                if gap < 0:
                    found.append(f"part {part.name}: holes {a.joint} and {b.joint} overlap by {-gap:.3f} mm; "
                                 "move the joints apart or use a smaller pin")
            for slot in getattr(part, "slots", ()):
                ring = shapely.Polygon(slot.polygon(0.01))
                if ring.distance(shapely.Point(a.centre)) < 0.5 * a.diameter_mm:
                    found.append(f"part {part.name}: hole {a.joint} runs into a guide slot")
    return found


def swept_region(outlines: Mapping[str, BulgePath], motion: Motion, poses: int = 90) -> Any:
    """Plan-view region (shapely geometry, ground coordinates) swept by the given bodies over the motion."""
    pick = np.unique(np.linspace(0, len(motion.inputs) - 1, min(poses, len(motion.inputs))).round().astype(int))
    shapes = []
    for body, path in outlines.items():
        outline = path.polygon(CONFLICT_CHORD_MM)
        # each pose's ring as before; the polygons made in one shapely call (was a Polygon object a pose)
        rings = [outline @ rotation(pose[2]).T + pose[:2] for pose in motion.pose(body)[pick]]
        if rings:
            shapes.extend(shapely.polygons(np.stack(rings)).tolist())
    return shapely.union_all(shapes) if shapes else shapely.Polygon()
