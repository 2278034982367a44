"""The design load (the template's ``[load]`` table).

The materials the stresses are held to belong to the process profile (:class:`fabricate.process.Material`,
``[materials.<key>]`` of ``templates/process_<name>.toml``).

``[load]`` (every key optional; the default is no external load, which fails nothing):

``tip_force_N``        float in [0, 10000]. Force at the tip point, opposing the tip's motion at every
                       pose (the object resisting the finger: a grasp or a press); the drivers hold it.
``tip_point``          str. Named point it acts on (default the synthesis' tip point).
``object_centre``      str. A named point of the ground: the object is centred there and pushes the tip
                       point straight away from it (a can on a circular pad: give the pad's arc centre
                       as ``tip_point`` and the force's line passes through the contact). Default: the
                       force opposes the tip's motion.
``input_force_N``      float in [0, 100000]. Known force of the first (slide) driver's actuator (the push
                       rod), acting to advance the motion. The object at the tip point holds it (its force,
                       opposing the tip's motion, is solved) together with the other drivers, which stand
                       for stops and contacts. Not with ``tip_force_N``.
``input_torque_Nmm``   float in [0, 1e7]. The same for an angle driver's actuator.
``torque_Nmm``         float in [0, 1e7]. A couple resisting the motion of ``torque_body`` (its turn
                       against the ground): an output load such as a gear pair's driven shaft.
``torque_body``        str. The body it acts on (required with ``torque_Nmm``).
``springs``            bool, default true. The synthesis' springs load the joints (rate × deflection).
``source``             str. Where the numbers come from (also a comment next to each).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from fabricate.errors import SpecError

if TYPE_CHECKING:
    from fabricate.table import Table


@dataclass(frozen=True)
class LoadSpec:
    """Validated ``[load]``: see the module docstring. Forces in N, torques in N·mm."""

    tip_force_N: float = 0.0
    tip_point: str | None = None
    object_centre: str | None = None
    tip_force_deg: float | None = None
    input_force_N: float = 0.0
    input_torque_Nmm: float = 0.0
    torque_Nmm: float = 0.0
    torque_body: str | None = None
    springs: bool = True
    source: str = ""

    @property
    def stated(self) -> bool:
        """Whether the template states any load at all."""
        return bool(self.tip_force_N or self.input_force_N or self.input_torque_Nmm or self.torque_Nmm
                    or self.springs)


def parse_load(table: Table) -> LoadSpec:
    """Read ``[load]`` (``{}`` when absent)."""
    spec = LoadSpec(
        tip_force_N=table.number("tip_force_N", 0.0, min=0.0, max=10000.0),
        tip_point=table.string("tip_point", None),
        object_centre=table.string("object_centre", None),
        tip_force_deg=table.number("tip_force_deg", None, min=-360.0, max=360.0),
        input_force_N=table.number("input_force_N", 0.0, min=0.0, max=100000.0),
        input_torque_Nmm=table.number("input_torque_Nmm", 0.0, min=0.0, max=1e7),
        torque_Nmm=table.number("torque_Nmm", 0.0, min=0.0, max=1e7),
        torque_body=table.string("torque_body", None),
        springs=table.boolean("springs", True),
        source=table.string("source", ""),
    )
    table.finish()
    if spec.input_force_N and spec.input_torque_Nmm:
        raise SpecError(table.field("input_torque_Nmm"), "give input_force_N (a slide) or input_torque_Nmm "
                                                         "(an angle), not both")
    if spec.torque_Nmm and not spec.torque_body:
        raise SpecError(table.field("torque_body"), "name the body the torque_Nmm acts on")
    if spec.object_centre is not None and spec.tip_force_deg is not None:
        raise SpecError(table.field("tip_force_deg"), "give object_centre or tip_force_deg, not both")
    if spec.tip_force_N and (spec.input_force_N or spec.input_torque_Nmm):
        raise SpecError(table.field("tip_force_N"), "give the tip force or the actuator's effort, not both: with "
                                                    "an actuator effort the tip force is what it produces")
    return spec

