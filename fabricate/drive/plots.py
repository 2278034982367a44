"""The drive's effort over the motion (matplotlib only here, through :mod:`fabricate.plotting`)."""

from __future__ import annotations

from typing import Any

from fabricate.drive.check import DriveResult
from fabricate.plotting import figure, legend, png_bytes


def drive_plot(result: DriveResult) -> bytes:
    """PNG of the input effort against the input, with the actuator's rating and rating / margin.

    Only for a check that ran (``result.reason is None``). Deterministic bytes.
    """
    return png_bytes(drive_figure(result))


def drive_figure(result: DriveResult) -> Any:
    """The figure :func:`drive_plot` renders."""
    assert result.reason is None and result.actuator is not None and result.spec is not None  # a check that ran
    fig = figure((8.0, 4.0), 100)
    ax = fig.add_subplot(1, 1, 1)
    x, y = result.inputs, result.effort
    copies = f" ({result.copies} copies)" if result.copies > 1 else ""
    ax.plot(x, y, lw=1.5, color="tab:blue", label=f"effort the design needs{copies}")
    ax.axhline(result.rating, color="tab:gray", ls=":", lw=1.0,
               label=f"{result.actuator.key} {result.rating_kind}: {result.rating:.4g} {result.unit}")
    ax.axhline(result.allowed, color="red", ls="--", lw=1.0,
               label=f"rating / margin {result.spec.margin:g}: {result.allowed:.4g} {result.unit}")
    k = result.peak
    ax.plot([x[k]], [y[k]], "o", color="tab:blue", ms=4)
    ax.annotate(f"{y[k]:.4g} {result.unit} at {x[k]:.4g} {result.input_unit}", (x[k], y[k]),
                textcoords="offset points", xytext=(4, 6), fontsize=8)
    ax.set_xlabel(f"input ({result.input_unit})")
    ax.set_ylabel(f"{'torque' if result.unit == 'N·mm' else 'force'} ({result.unit})")
    ax.set_title(f"Drive: {result.actuator.name}"[:90], fontsize=9)
    ax.set_ylim(bottom=0.0, top=1.15 * max(result.rating, float(y.max(initial=0.0))))
    ax.grid(True, lw=0.3)
    legend(ax, loc="best", framealpha=0.85)
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.12, top=0.9)
    return fig
