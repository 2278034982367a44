"""Strength of the fabricated parts: closed-form models (:mod:`.models`) and cross-sections cut from
the real part geometry (:mod:`.section`)."""
