"""Watt-I six-bar finger by solution-region synthesis (kind ``watt_six_bar``).

Template tables read here (see ``templates/finger_watt_six_bar.toml``):

``[finger]``     phalanx_lengths_mm (L1, L2, L3), theta1_deg / theta2_deg / theta3_deg (absolute angles
                 of a0-a, a-b, b-c from +x at the four positions), tip_pad_radius_mm.
``[boxes]``      d0, d, e, f: ``[x_min, x_max, y_min, y_max]`` at position 1, a0 at the origin (Table 3).
``[region]``     step_mm (x sampling of both curves), k_max, force_N, statics_samples, tip_tolerance_mm,
                 min_pin_to_middle_mm (pins d and e cross the middle link's layer: smallest distance
                 from its centreline a-b over the motion; 0 switches the check off).
``[selection]``  rule ("nearest" to ``target = [d_x, d0_x]`` or "least_k"), optional branches = [m, n],
                 refine (when no exact region point qualifies, look for approximate defect-free
                 mechanisms from the region points, see :mod:`.refine`), refine_seeds.
``[reference]``  optional published design (d, e, f, d0) to compare with; report only.

The pipeline: curves and region (:mod:`.region`), force index K (:mod:`.statics`),
selection, the six-bar :class:`~fabricate.mechanism.Mechanism` (bodies ground, proximal, middle, distal,
coupler, rocker; one angle driver proximal vs ground in degrees), and the checks reported in
``report["synthesis"]``: fingertip error at the positions through the generic solver, and K against
an independent virtual-work computation on that same mechanism.

Modules: :mod:`.spec` (template tables), :mod:`.burmester`, :mod:`.region`, :mod:`.statics`, :mod:`.refine`,
:mod:`.selection`, :mod:`.mechanism`, :mod:`.method` (``synthesise`` and the report), :mod:`.plots`.
"""

from __future__ import annotations

from fabricate.synthesis.watt_six_bar.method import synthesise
from fabricate.synthesis.watt_six_bar.spec import parse_spec, preflight

__all__ = ["parse_spec", "preflight", "synthesise"]
