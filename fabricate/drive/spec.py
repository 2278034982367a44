"""The template's ``[actuator]`` table: which catalogue actuator drives the design, and with what margin.

``[actuator]`` (optional; without it nothing drives the design and the drive check is "not checked"):

``model``      str, required. A key of :data:`fabricate.catalogue.actuators.CATALOGUE` (``"sg90"``,
               ``"mg90s"``, ``"n20"``, ``"nema17"``, ``"28byj48"``, ``"l16"``, ``"tendon"``...) whose entry
               is complete (a body, a mount, an output interface and a rating).
``margin``     float in [1, 10], default 1.5. The drive check holds the input effort at every pose to the
               actuator's rating divided by it.
``force_N``    float in (0, 100000]. The force a ``"tendon"`` (a tendon or push rod driven from off-board)
               delivers: required for it, refused for any other model (their rating is the datasheet's).
``stroke_mm``  float in (0, 10000]. The tendon's travel, if known (for the report; refused otherwise).
``driver``     int >= 0, default 0. Which driver of the mechanism the actuator drives (checked against
               the mechanism at the drive check: its kind, angle or slide, must suit the actuator's).
``source``     str. Where the choice comes from (a paper, a datasheet), for people.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from fabricate.errors import SpecError

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.table import Table

#: Largest margin accepted: more is no longer a margin but a wrong rating.
MAX_MARGIN = 10.0
MAX_FORCE_N = 100000.0
MAX_STROKE_MM = 10000.0
#: Largest driver index (a planar mechanism of fabricate's has a handful of drivers at most).
MAX_DRIVER = 16


@dataclass(frozen=True)
class ActuatorSpec:
    """Validated ``[actuator]`` (see the module docstring).

    Attributes
    ----------
    model : str
        The catalogue key.
    margin : float
        The rating is divided by it before the input effort is compared with it.
    force_N : float or None
        A tendon's force (N); None for every other model.
    stroke_mm : float or None
        A tendon's travel (mm), if given.
    driver : int
        Index of the mechanism's driver the actuator drives.
    source : str
        Where the choice comes from.
    """

    model: str
    margin: float = 1.5
    force_N: float | None = None
    driver: int = 0
    stroke_mm: float | None = None
    source: str = ""

    def entry(self) -> Actuator:
        """The catalogue entry (a tendon rated at :attr:`force_N`)."""
        from fabricate.catalogue.actuators import actuator, tendon

        if self.model == "tendon":
            assert self.force_N is not None  # parse_actuator requires it
            return tendon(self.force_N, self.stroke_mm)
        return actuator(self.model)


def catalogue_keys() -> list[str]:
    """The catalogue keys a template may name (complete entries; the tendon is completed by ``force_N``)."""
    from fabricate.catalogue.actuators import CATALOGUE

    return [k for k, a in CATALOGUE.items() if a.complete or k == "tendon"]


def parse_actuator(table: Table) -> ActuatorSpec | None:
    """Read ``[actuator]``; None when the template has none (an empty table reads as none too)."""
    from fabricate.catalogue.actuators import CATALOGUE

    if not table.data:
        return None
    keys = catalogue_keys()
    model = table.string("model")
    if model not in CATALOGUE:
        raise SpecError(table.field("model"), f"no actuator {model!r} in the catalogue; expected one of "
                                              f"{', '.join(keys)}")
    if model not in keys:
        missing = "; ".join(f"{k}: {why}" for k, why in CATALOGUE[model].gaps) or "no rating"
        raise SpecError(table.field("model"), f"{model!r} is incomplete in the catalogue ({missing}); "
                                              f"expected one of {', '.join(keys)}")
    margin = table.number("margin", 1.5, min=1.0, max=MAX_MARGIN)
    force = table.number("force_N", None, min=0.0, max=MAX_FORCE_N, positive=True)
    stroke = table.number("stroke_mm", None, min=0.0, max=MAX_STROKE_MM, positive=True)
    driver = table.integer("driver", 0, min=0, max=MAX_DRIVER)
    source = table.string("source", "")
    table.finish()
    if model == "tendon" and force is None:
        raise SpecError(table.field("force_N"), "a tendon or push rod driven from off-board needs the force it "
                                                "delivers (N)")
    if model != "tendon":
        for key, value in (("force_N", force), ("stroke_mm", stroke)):
            if value is not None:
                raise SpecError(table.field(key), f"only a 'tendon' takes {key}; {model!r} is rated by its "
                                                  "datasheet (catalogue)")
    return ActuatorSpec(model=model, margin=float(margin), force_N=None if force is None else float(force),
                        driver=driver, stroke_mm=None if stroke is None else float(stroke), source=source)
