"""Parts: every body of a solved mechanism becomes a plate you can print or cut.

Modules
-------
``model``     exact profiles (:class:`~fabricate.parts.model.BulgePath`), holes, :class:`~fabricate.parts.model.Part`
``solids``    the manifold3d adapter (parts to solids)
``spec``      the generic ``[parts]`` template table
``profiles``  circle hulls, gear fusion, kerf offsets
``layers``    plan-view conflict graph over the motion and its colouring into layers
``bom``       pins, spacers, washers and the bill of materials
``build``     :func:`~fabricate.parts.build.build_parts`, the entry point

The synthesis' hints (``SynthesisResult.parts``: pads, springs, purchased items, copies, link width, tip
point) are a frozen :class:`~fabricate.hints.PartHints`, documented there.
"""
