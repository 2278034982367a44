"""Design-space sweeps on Dask distributed: many designs from one template, as tables, plots and the best
builds.

.. code-block:: python

    from fabricate.sweep import load_sweep, run_sweep

    spec = load_sweep("finger_hand_sizes")              # a shipped spec, or a path
    outcome = run_sweep(spec, "outputs/finger_hand_sizes-sweep", workers=2)

``fabricate sweep SPEC|TEMPLATE --vary FIELD=VALUES ...`` is the same from the command line.
"""

from __future__ import annotations

from fabricate.sweep.paths import Metric
from fabricate.sweep.spec import Field, SweepSpec, load_sweep, sweep_from_tables

__all__ = ["Field", "Metric", "SweepSpec", "load_sweep", "run_sweep", "sweep_from_tables"]


def __getattr__(name: str):  # Dask is imported only when a sweep runs
    if name == "run_sweep":
        from fabricate.sweep.runner import run_sweep

        return run_sweep
    raise AttributeError(name)
