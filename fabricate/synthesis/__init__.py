"""Synthesis methods: one package per kind of design (the registry of kinds is :mod:`fabricate.kinds`).

Every kind package has one shape:

``__init__.py``
    What the kind is (its paper, its template tables) and its entry points only: ``parse_spec``,
    ``preflight`` and ``synthesise`` (see :mod:`fabricate.kinds` for their contracts).
``spec.py``
    The kind's template tables -> its frozen spec (``parse_spec``) and the cost estimate of a validated
    design (``preflight``, with the constants of :mod:`fabricate.bounds`).
``method.py``
    ``synthesise``: the method from the spec to a :class:`~fabricate.synthesis.base.SynthesisResult` (its
    report section, figures and parts hints), with the method's own modules beside it (the five-bar's
    kinematic mapping, the six-bar's Burmester curves and solution region, ...).
``mechanism.py``
    The :class:`~fabricate.mechanism.Mechanism` the method builds.
``plots.py``
    Its figures (PNG bytes; matplotlib is imported only there, lazily).
"""
