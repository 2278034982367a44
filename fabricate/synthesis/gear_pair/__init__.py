"""Kind ``gear_pair``: a standalone non-circular gear pair on a fixed carrier.

Template tables
---------------
``[gear_pair]``
    One of
      ``family = "elliptic"`` with ``eccentricity`` (0 <= e < 1): two equal ellipses about their foci, 1:1;
      ``law = "x + 0.03*sin(x)"``: the driven gear's angle as a formula in the driving angle ``x``
      (rad; the numpy functions of :data:`fabricate.gears.law.FUNCTIONS`, evaluated safely; at most
      :data:`~fabricate.bounds.MAX_EXPRESSION_LENGTH` characters and
      :data:`~fabricate.bounds.MAX_EXPRESSION_DEPTH` levels of nesting);
      ``law_samples_deg = [[x_a, x_b], ...]``: driven against driving angle (deg), a cubic spline.
    The driven angle is counted positive in its own sense of turning (external gears turn opposite
    ways): the coupling law is its negative.
    ``closed`` (default true): full gears; false: sectors over ``working_range_deg = [lo, hi]``.
    ``center_distance_mm``: the axis distance. For a closed pair it may be left out when
    ``[gears] module_mm`` and ``teeth`` are given (the centre distance then follows from whole teeth);
    given together with ``module_mm``, the module is adjusted to fit whole teeth.
    ``teeth = [z_a, z_b]`` (closed pairs; the same as ``[gears] teeth``).

The mechanism: body ``carrier`` (ground) holding the axes ``OA`` at the origin and ``OB`` at
``(center_distance, 0)``; ``gear_a`` turned by an angle driver over the working range (0..360 deg for a
closed pair), ``gear_b`` coupled by the law.

Modules: :mod:`.spec` (the ``[gear_pair]`` table), :mod:`.mechanism` (the law and the carrier with its two
gears), :mod:`.method` (``synthesise`` and the report), :mod:`.plots`.
"""

from __future__ import annotations

from fabricate.synthesis.gear_pair.method import synthesise
from fabricate.synthesis.gear_pair.spec import parse_spec, preflight

__all__ = ["parse_spec", "preflight", "synthesise"]
