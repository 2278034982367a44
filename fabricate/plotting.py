"""Shared matplotlib plumbing for every plot module (kernel isolation: matplotlib is imported only here
and in the plot modules, lazily).

PNG bytes are deterministic: the Agg backend, a fixed dpi, and no ``Software`` tag in the metadata.
"""

from __future__ import annotations

import io
from typing import Any


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def png_bytes(fig: Any, dpi: float | None = None) -> bytes:
    """Render a figure to PNG bytes and release it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A pyplot-managed or standalone figure.
    dpi : float, optional
        Resolution; the figure's own when omitted.
    """
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi if dpi is not None else fig.dpi, metadata={"Software": None})
    pyplot().close(fig)
    return buffer.getvalue()
