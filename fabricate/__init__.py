"""fabricate: CAD and fabrication pipeline for synthesised finger mechanisms."""

from __future__ import annotations

__version__ = "0.1.0"

from fabricate.errors import FabricateError, GeometryError, LockupError, SpecError, SynthesisError

__all__ = ["Build", "FabricateError", "GeometryError", "LockupError", "SpecError", "SynthesisError", "__version__",
           "build", "from_mechanism", "load"]


def __getattr__(name: str):
    # the API pulls in numpy and the pipeline: load it on first use, so `import fabricate` stays light
    if name in ("Build", "build", "from_mechanism", "load"):
        from fabricate import api

        return getattr(api, name)
    raise AttributeError(f"module 'fabricate' has no attribute {name!r}")
