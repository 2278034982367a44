"""Underactuated stacked four-bar finger driven by one push rod (kind ``underactuated``).

The chapter derives the mobility (n for n phalanges), positions, the velocity recursion
theta_dot_{n+1} = E_n theta_dot_n and the statics, but gives no dimensions. This package

- reads a template (``[finger]``, ``[transmission]``, ``[push_rod]``, ``[springs]``, ``[object]``),
- computes the free closing motion with return springs (quasi-static: least spring energy at each
  stroke, joints on their open stops until the springs let them go) and the closing on a cylinder
  (the same, with the phalanges kept outside it), which yields the contact sequence,
- computes the contact forces at the end for the template's push force (the force chain of
  :func:`fabricate.synthesis.underactuated.model.contact_forces`), the velocity ratios E_i and the
  mobility, and
- returns a 1-input :class:`~fabricate.mechanism.Mechanism`: the push rod is a slider with a "slide"
  driver over the stroke; the n-1 phalanx angles the actuator does not fix are "angle" drivers whose
  laws (cubic splines of stroke -> relative angle, split where a contact or a stop changes the
  motion, :class:`.model.PiecewiseLaw`) come from the closing solution.

Modules: :mod:`.spec` (template tables), :mod:`.model` (kinematics and statics), :mod:`.settler` (the
equilibrium at one stroke), :mod:`.closing` (the closing motion), :mod:`.mechanism`, :mod:`.method`
(``synthesise`` and the report), :mod:`.plots`.
"""

from __future__ import annotations

from fabricate.synthesis.underactuated.method import synthesise
from fabricate.synthesis.underactuated.spec import parse_spec, preflight

__all__ = ["parse_spec", "preflight", "synthesise"]
