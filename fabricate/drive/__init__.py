"""The actuator that drives a design: the template's ``[actuator]`` (:mod:`.spec`), the drive check of its
rating against the input effort the statics compute (:mod:`.check`) and the effort-over-motion plot
(:mod:`.plots`); the interface on the driven part and the mount on the ground are built by
:mod:`.geometry` and :mod:`.parts`.
"""

from __future__ import annotations

from fabricate.drive.spec import ActuatorSpec, parse_actuator

__all__ = ["ActuatorSpec", "parse_actuator"]
