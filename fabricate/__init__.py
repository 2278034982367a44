"""fabricate: CAD and fabrication pipeline for synthesised finger mechanisms."""

from __future__ import annotations

__version__ = "0.1.0"

from fabricate.errors import FabricateError, GeometryError, LockupError, SpecError, SynthesisError

__all__ = ["FabricateError", "GeometryError", "LockupError", "SpecError", "SynthesisError", "__version__"]
