"""Catalogue of real hardware: actuators (:mod:`.actuators`), standard pins, washers, screws and
retaining rings (:mod:`.hardware`) and torsion springs sized by the standard formulas (:mod:`.springs`).

Every number comes from a named public source (datasheet, a standard's table as a maker or a CAD
library reproduces it, a spring maker's formula), given beside it; a value no source gave is left out
and its absence stated. The functions pick and size; they build no geometry.
"""

from __future__ import annotations

from fabricate.catalogue.actuators import CATALOGUE, Actuator, actuator, tendon
from fabricate.catalogue.hardware import (
    PinChoice,
    RetainingRing,
    Screw,
    Washer,
    dowel_pin,
    e_clip,
    screw,
    shim_ring,
    washer,
    washer_for_shaft,
)
from fabricate.catalogue.springs import TorsionSpring, torsion_spring

__all__ = [
    "CATALOGUE",
    "Actuator",
    "PinChoice",
    "RetainingRing",
    "Screw",
    "TorsionSpring",
    "Washer",
    "actuator",
    "dowel_pin",
    "e_clip",
    "screw",
    "shim_ring",
    "tendon",
    "torsion_spring",
    "washer",
    "washer_for_shaft",
]
