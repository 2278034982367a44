"""Catalogue of real hardware: actuators (:mod:`.actuators`), printers (:mod:`.printers`), standard
washers, shims, screws and nuts (:mod:`.hardware`), dowel, clevis and split pins (:mod:`.pins`), retaining
rings and the grooved pins they hold (:mod:`.clips`), shop designations read back (:mod:`.designations`)
and torsion springs sized by the standard formulas (:mod:`.springs`); :mod:`.tables` holds what the
standard tables share.

Every number comes from a named public source (datasheet, a standard's table as a maker or a CAD
library reproduces it, a spring maker's formula), given beside it; a value no source gave is left out
and its absence stated. The functions pick and size; they build no geometry.
"""

from __future__ import annotations

from fabricate.catalogue.actuators import CATALOGUE, Actuator, actuator, tendon
from fabricate.catalogue.clips import GroovedPin, RetainingRing, e_clip, grooved_pin
from fabricate.catalogue.designations import parse_designation
from fabricate.catalogue.hardware import (
    Nut,
    Screw,
    Washer,
    fill_gap,
    nut,
    pin_washer,
    screw,
    screw_and_nut,
    shim_ring,
    washer,
    washer_for_shaft,
    washers_for_shaft,
)
from fabricate.catalogue.pins import ClevisPin, PinChoice, SplitPin, clevis_pin, dowel_pin, split_pin
from fabricate.catalogue.springs import TorsionSpring, torsion_spring

__all__ = [
    "CATALOGUE",
    "Actuator",
    "ClevisPin",
    "GroovedPin",
    "Nut",
    "PinChoice",
    "RetainingRing",
    "Screw",
    "SplitPin",
    "TorsionSpring",
    "Washer",
    "actuator",
    "clevis_pin",
    "dowel_pin",
    "e_clip",
    "fill_gap",
    "grooved_pin",
    "nut",
    "parse_designation",
    "pin_washer",
    "screw",
    "screw_and_nut",
    "shim_ring",
    "split_pin",
    "tendon",
    "torsion_spring",
    "washer",
    "washer_for_shaft",
    "washers_for_shaft",
]
