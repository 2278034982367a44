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


def figure(size: tuple[float, float], dpi: float) -> Any:
    """A standalone figure (not registered with pyplot) on an Agg canvas."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def gif_bytes(images: list[Any], frame_ms: int, **options: Any) -> bytes:
    """Animated GIF (looping) of Pillow images."""
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=frame_ms, loop=0,
                   **options)
    return buffer.getvalue()


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
