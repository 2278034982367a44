"""Five-bar NCG finger (kind ``five_bar_ncg``): a one-DOF five-bar finger O-A-B-C-D driven through a
non-circular gear pair.

The finger is three phalanges O-D, D-C, C-P (Table 1) with target poses given as absolute phalanx
angles (Table 2). In the frame of the proximal phalanx O-D the five-bar is a four-bar A-B-C-D whose
coupler is the distal phalanx; the dyad A-B is unknown (A fixed in the proximal body, B fixed in the
distal one). The kinematic mapping of the distal poses (eqs 1-2), the matrix ``M`` (eq 11) and the
four smallest eigenvectors of ``M^T M`` (eq 13) give a one-parameter family of dyads traced with
``kappa = cot(omega)`` (eq 14): the hinge curves of A and B (Fig 8). The template's limits cut the
feasible domain out of them (Fig 9), a rule picks one dyad, and the rotation of A-B relative to the
arm O-A, against the ground's rotation relative to the arm, is interpolated by a cubic spline through
the poses: the law of a sun gear fixed at O and a planet fixed to A-B at A (Fig 10). The result is a
:class:`~fabricate.mechanism.Mechanism` whose solved motion gives the fingertip error at every pose.

Departures from the printed formulas (OCR slips, checked by reconstruction in the tests):

- eq 1: the distal pose in the proximal frame is ``(R(-t1) (P - O), t3 - t1)``; the printed ``j1, j2``
  and ``v = phi1 - phi2`` do not reproduce a rigid transformation.
- eq 9: the centre is ``A = -(p4, p5) / p1`` (``a0 = p1 / 2``), see :mod:`.kinematic_mapping`.
- eq 19: rolling without slip, ``r_a dx_a = r_b dx_b`` with ``r_a + r_b = |OA|`` and ratio
  ``i = -f'(x_a)``, gives ``r_a = |OA| i / (1 + i)`` and ``r_b = |OA| / (1 + i)``; the printed
  ``r1 = a / (1 + i12)`` with ``|OA| = 2a`` is neither.
- order defect (section 2.3): the paper asks for phi1 "from small to large"; which sense is right
  depends on the frame's orientation, so we require A-B to turn strictly monotonically relative to
  O-D and let the gear check decide the sense (an external pair needs ``f' < 0``).
- eq 15-16: the pose error is not estimated from the dyad directions but measured on the solved
  mechanism (A-B's angle at each pose is eq 10's direction of A->B_i, which the spline interpolates).

Modules: :mod:`.spec` (template tables), :mod:`.kinematic_mapping` (eqs 1-14), :mod:`.targets`, :mod:`.law`
(the gear law), :mod:`.domain` (feasible domain and selection), :mod:`.mechanism`, :mod:`.method`
(``synthesise`` and the report), :mod:`.plots`.
"""

from __future__ import annotations

from fabricate.synthesis.five_bar.method import synthesise
from fabricate.synthesis.five_bar.spec import parse_spec, preflight

__all__ = ["parse_spec", "preflight", "synthesise"]
