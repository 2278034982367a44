"""Arguments of the API face (:mod:`fabricate.api` and :meth:`fabricate.pipeline.BuildOutcome.write`): a
wrong one is a :class:`~fabricate.errors.SpecError` naming it, never a bare exception from deep inside."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from fabricate.errors import SpecError


def type_name(value: Any) -> str:
    """A value's type and the start of its repr, for an error naming a wrong argument."""
    text = repr(value)
    return f"{type(value).__name__} {text[:60]}{'...' if len(text) > 60 else ''}"


def path_argument(value: Any, argument: str, what: str) -> Path:
    """``value`` as a Path, or a :class:`SpecError` naming ``argument`` (bytes, numbers, None, a NUL...)."""
    if isinstance(value, (str, os.PathLike)):
        try:
            path = Path(value)
        except TypeError:  # a PathLike that returns bytes
            path = None
        if path is not None and "\0" in str(path):
            raise SpecError(argument, f"a path cannot hold a NUL character, got {str(path)!r:.80}")
        try:
            os.fsencode(path) if path is not None else None
        except UnicodeError:  # a lone surrogate the file system's encoding cannot write
            raise SpecError(argument, f"not a name the file system can hold: {str(path)!r:.80}") from None
        if path is not None and str(value):
            return path
    raise SpecError(argument, f"expected {what} (str or pathlib.Path), got {type_name(value)}")
