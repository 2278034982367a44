"""The declared linkage as validated: the frozen records :func:`.spec.parse_spec` returns (the template's
``[linkage]`` table, or the exact form a build writes), shared by the parser, the laws and the mechanism."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from fabricate.hints import PartHints
    from fabricate.mechanism import Mechanism


@dataclass(frozen=True)
class BodySpec:
    """One ``[[linkage.bodies]]`` entry: points in world mm at the reference pose."""

    name: str
    points: tuple[tuple[str, tuple[float, float]], ...]


@dataclass(frozen=True)
class JointSpec:
    """One ``[[linkage.joints]]`` entry; ``axis`` (unit, world at the reference pose) for sliders only."""

    name: str
    type: str
    bodies: tuple[str, str]
    axis: tuple[float, float] | None = None


@dataclass(frozen=True)
class LinkageGearSpec:
    """One ``[[linkage.gears]]`` entry (angles in degrees as written)."""

    name: str
    carrier: str
    bodies: tuple[str, str]
    axes: tuple[str, str]
    law: str
    closed: bool
    working_range_deg: tuple[float, float]
    ratio: float | None = None
    eccentricity: float | None = None
    x_deg: tuple[float, ...] | None = None
    y_deg: tuple[float, ...] | None = None
    spline: str | None = None
    expression: str | None = None


@dataclass(frozen=True)
class DriverSpec:
    """One ``[[linkage.drivers]]`` entry."""

    joint: str
    law: str
    reference: float
    input: tuple[float, ...] | None = None
    value: tuple[float, ...] | None = None
    spline: str | None = None


@dataclass(frozen=True)
class PadSpec:
    """One ``[[linkage.pads]]`` entry."""

    body: str
    point: str
    radius_mm: float


@dataclass(frozen=True)
class LinkageSpec:
    """Validated ``[linkage]`` table."""

    ground: str
    input_unit: str
    input_range: tuple[float, float]
    tip_point: str | None
    bodies: tuple[BodySpec, ...]
    joints: tuple[JointSpec, ...]
    gears: tuple[LinkageGearSpec, ...]
    drivers: tuple[DriverSpec, ...]
    pads: tuple[PadSpec, ...]

    @property
    def reference(self) -> float:
        """The input value at the reference pose (every driver's)."""
        return self.drivers[0].reference if self.drivers else self.input_range[0]


@dataclass(frozen=True)
class ExactLinkageSpec:
    """The exact form (``[linkage] exact = true``, what every build writes as ``mechanism.toml``): the
    mechanism as it was, and the parts hints it came with (see :mod:`fabricate.synthesis.linkage.exact`)."""

    mechanism: Mechanism
    hints: PartHints
    tip_point: str | None = None
