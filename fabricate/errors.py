"""Exception hierarchy.

Findings of checks are data (see :mod:`fabricate.report`); exceptions are for input that cannot be
used (:class:`SpecError`), synthesis that finds nothing (:class:`SynthesisError`), motion that cannot
be assembled (:class:`LockupError`) and kernel failures (:class:`GeometryError`).
"""

from __future__ import annotations


class FabricateError(Exception):
    """Base class of every error fabricate raises on purpose."""


class SpecError(FabricateError, ValueError):
    """A template or argument is invalid.

    Parameters
    ----------
    path : str
        Dotted field path, e.g. ``finger.poses_deg[3][1]``.
    message : str
        What was expected and what was found.
    """

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        self.message = message
        super().__init__(f"{path}: {message}" if path else message)

    def __reduce__(self) -> tuple[type[SpecError], tuple[str, str]]:
        # a sweep's worker sends errors across processes: rebuild from both arguments
        return (type(self), (self.path, self.message))


class SynthesisError(FabricateError):
    """Synthesis found no design that satisfies the template's limits."""


class LockupError(FabricateError):
    """The mechanism cannot be assembled at an input value (lock-up or branch change).

    Parameters
    ----------
    input_value : float
        The input (in the driver's unit: degrees or mm) where assembly failed.
    message : str
        Why.
    """

    def __init__(self, input_value: float, message: str) -> None:
        self.input_value = float(input_value)
        self.message = message
        super().__init__(f"{message} (at input {input_value:.6g})")

    def __reduce__(self) -> tuple[type[LockupError], tuple[float, str]]:
        return (type(self), (self.input_value, self.message))


class GeometryError(FabricateError):
    """A geometry kernel (manifold3d, shapely) failed or returned an invalid solid."""
