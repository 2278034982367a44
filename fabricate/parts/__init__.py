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

Synthesis hints (``SynthesisResult.parts``; all optional)
---------------------------------------------------------
``pads``           ``{body: {"point": name, "radius_mm": r}}``: a fingertip pad disc fused at that point
``springs``        ``[{"joint", "rate_Nmm_per_deg", "preload_deg", "legs_mm", "note"}]``: torsion springs (BOM)
``purchased``      ``[{"item", "qty", "note"}]``: motors, actuators, screws (BOM)
``purchased_shared``  like ``purchased`` but once for all copies (not multiplied)
``copies``         identical mechanism copies; BOM quantities are multiplied (``copy_angle_deg`` informs)
``link_width_mm``  preferred plate width of links (``[parts] link_width_mm`` overrides it)
``tip_point``      the fingertip point whose path the previews draw
"""
