"""Kind ``linkage``: a planar linkage declared in the template, taken through the whole pipeline.

Nothing is synthesised: the template names the bodies with their points, the joints, the gear pairs and
the drivers, and this package validates them (:mod:`.spec`, into the records of :mod:`.declared`) and
builds the :class:`~fabricate.mechanism.Mechanism` (:mod:`.mechanism`, :mod:`.method`) the rest of the
pipeline (gears, parts, exports, interference, strength) works on unchanged. :mod:`.exact` reads and writes
the exact form, :mod:`.plots` draws the gear laws.

Template tables
---------------
``[linkage]``
    ``ground`` (name of the fixed body), ``input_unit`` (``"deg"``: angle driver, ``"mm"``: slide driver),
    ``input_range = [start, end]`` (in ``input_unit``), optional ``tip_point`` (the point whose path is
    the output: previews, the strength tip load).
``[[linkage.bodies]]``
    ``name``, ``points = { NAME = [x, y], ... }``: **world** coordinates (mm) at the reference pose.
``[[linkage.joints]]``
    ``name``, ``type`` (``"revolute"`` or ``"slider"``), ``bodies = [a, b]``. A revolute joint ``J`` makes
    point ``J`` of both bodies coincide (they must be the same world point at the reference pose, within
    :data:`ASSEMBLY_GAP_MM`). A slider takes ``axis = [ux, uy]`` (world direction at the reference pose,
    fixed in ``a``): point ``J`` of ``b`` moves on the line through point ``J`` of ``a`` and the two bodies
    keep their relative angle.
``[[linkage.gears]]`` (optional)
    ``name``, ``carrier``, ``bodies = [gear_a, gear_b]``, ``axes = [JA, JB]`` (revolute joints joining the
    carrier to gear a and to gear b: their distance is the centre distance), ``law`` and its parameters,
    ``closed`` (default true), ``working_range_deg`` (range of gear a's angle against the carrier; default
    ``[0, 360]`` for a closed pair and the table's span for a table sector). The law gives the driven angle
    ``y`` (deg, counted in gear b's own sense, i.e. opposite to gear a's: an external pair) as a function
    of the driving angle ``x`` (deg), both measured from the reference pose, so ``y(0) = 0``:

    - ``"constant"``: ``ratio`` = driven turn / driving turn;
    - ``"elliptic"``: ``eccentricity`` in [0, 0.95]: two equal ellipses about their foci, 1:1 over a turn,
      the major axes on the line of centres at the reference pose (gear a's nearer vertex towards b);
    - ``"table"``: ``x_deg``, ``y_deg`` samples and ``spline`` (``"pchip"``, ``"cubic"`` or
      ``"periodic"``; a closed pair needs ``"periodic"``: the law then repeats after 360° of x with
      ``y(x + 360) = y(x) + y_end - y_start``);
    - ``"expression"``: ``expression``, a formula in ``x`` (radians) giving ``y`` (radians), e.g.
      ``"x + 0.2*sin(x)"`` (the functions of :data:`fabricate.gears.law.FUNCTIONS`; at most
      :data:`~fabricate.bounds.MAX_EXPRESSION_LENGTH` characters and
      :data:`~fabricate.bounds.MAX_EXPRESSION_DEPTH` levels of nesting, all of a linkage's together at most
      :data:`~fabricate.bounds.MAX_LINKAGE_EXPRESSION_CHARS` characters).
``[[linkage.drivers]]`` (one per degree of freedom)
    ``joint`` (a revolute: the angle of ``bodies[1]`` against ``bodies[0]``; a slider: the displacement of
    its point along the axis), ``law`` (``"linear"``: value = input - reference; degrees become radians
    for an angle; ``"table"``: ``input = [...]``, ``value = [...]`` in deg or mm, ``spline = "pchip" |
    "cubic"``), ``reference`` (the input at the reference pose; default ``input_range[0]``; one value
    for all drivers). Joint values are measured from the reference pose: a table must give 0 at it.
``[[linkage.pads]]`` (optional)
    ``body``, ``point``, ``radius_mm``: a pad disc fused to the body at the point (parts layer).

``exact = true`` (in ``[linkage]``)
    The exact form every build writes as ``mechanism.toml``: bodies with points in their own frames, the
    first pose's ``assembly``, joints and drivers as the mechanism has them, laws by their coefficients,
    and the parts ``hints``; see :mod:`fabricate.synthesis.linkage.exact`.

Reference pose and start
------------------------
Because points are world coordinates at the reference pose, every body's frame is the world frame there:
its pose is ``(0, 0, 0)`` when the input equals ``reference``. When ``reference`` is not the start of
the range the linkage is first moved by continuation from the reference pose to the start (so the start
pose is on the branch the template draws); a lock-up on that way is reported by the sweep (exit 1).

Validation
----------
Every error is a :class:`~fabricate.errors.SpecError` naming the field (``linkage.joints[3].bodies``) and,
for joints, the joint: unknown bodies or points, duplicate names, counts beyond :mod:`fabricate.bounds`
(and, by the kind's preflight estimate, poses × bodies, the solver's work and the gears' teeth × poses),
a linkage that does not assemble at the reference pose, degrees of freedom (Gruebler, gears one
constraint each) that differ from the number of drivers. A lock-up inside the range is found by the
pipeline's sweep: a :class:`~fabricate.errors.LockupError` naming the input value, the driven joint and
the joint nearest a dead point (exit 1).
"""

from __future__ import annotations

from fabricate.synthesis.linkage.method import synthesise
from fabricate.synthesis.linkage.spec import parse_spec, preflight

__all__ = ["parse_spec", "preflight", "synthesise"]
