"""Layer 7, design studies: sweeps of many variants of a model in batched core calls (locally
in a process pool, or on a Dask cluster), and tolerance analysis (first-order propagation
through the exact sensitivities beside a Monte Carlo estimate).

xarray, dask, distributed, pandas and tqdm are optional (``pip install 'mbd2d[sweep]'``):
they are imported here only, when a study runs.
"""
from __future__ import annotations

from .export import export_sweep
from .files import tolerance_table, write_sweep, write_tolerance
from .plan import ANALYSES, grid
from .runner import connect
from .sweep import sweep
from .tolerance import ToleranceResult, tolerance, tolerance_samples

__all__ = ["sweep", "grid", "tolerance", "tolerance_samples", "ToleranceResult", "write_sweep", "write_tolerance",
           "tolerance_table", "export_sweep", "connect", "ANALYSES"]
