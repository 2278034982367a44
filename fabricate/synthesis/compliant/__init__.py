"""Compliant spring-hinge gripper: three fingers of two spring hinges each (kind ``compliant_gripper``).

Reads ``[finger]``, ``[springs]``, ``[object]``, ``[optimisation]`` and ``[drive]``; computes

- the grasp of the paper's procedure (:func:`fabricate.synthesis.compliant.model.solve_grasp`): the
  stroke where the hover force reaches F_n2 = mg/(3 mu s), and F_n1 at that stroke, on the physical
  branch (tip turned in on the can, two-force rod pushing);
- the grasp force against stroke (paper Fig 3);
- the certified optimum of Delta N over the Table 1 grid (:mod:`fabricate.synthesis.compliant.grid_search`);
- the no-load closing (eqs 1-2: least spring energy at each stroke with the hinges on their stops
  until the rod overcomes the preloads), continued on the can up to the grasp stroke;

and returns one finger's planar :class:`~fabricate.mechanism.Mechanism` driven by the drive rod: a
slider with a "slide" driver over the stroke, the root phalanx held at alpha by an "angle" driver
(in the gripper the root push rod sets it), and the one hinge angle the drive does not fix as an
"angle" driver whose law (monotone cubic, stroke -> angle) comes from the closing solution.

Modules: :mod:`.spec` (template tables), :mod:`.model` (the static force model), :mod:`.grid_search` (the
certified optimum), :mod:`.closing` (the closing motion), :mod:`.mechanism`, :mod:`.method` (``synthesise``
and the report), :mod:`.plots`.
"""

from __future__ import annotations

from fabricate.synthesis.compliant.method import synthesise
from fabricate.synthesis.compliant.spec import parse_spec, preflight

__all__ = ["parse_spec", "preflight", "synthesise"]
