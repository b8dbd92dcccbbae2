"""Layer 4, the pictures: mechanism snapshots, time series, PNG output.

matplotlib is imported only when a function here is called, so ``import mbd2d`` does not
need it. Figures are drawn on the non-interactive Agg canvas and are not registered with
``pyplot`` (nothing to close, no figure leak in loops).

Everything drawn is post-processing of the result: body poses come from
:class:`~mbd2d.results.KinematicsResult`, cam profile points from the Fortran core
(through :mod:`mbd2d.binding.core`); body-local points are placed with r + A(theta) s.

Examples
--------
>>> import mbd2d
>>> from mbd2d.plots import save_figures
>>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=90)
>>> paths = save_figures(res, "/tmp/crank_rocker", trace=[("coupler", (0.0, 1.0))])
>>> [p.rsplit("_", 1)[-1] for p in paths]
['mechanism.png', 'timeseries.png']
"""
from __future__ import annotations

from .canvas import STOP_COLOUR
from .files import save_figures
from .geometry import Motion, TracePoint
from .mechanism import plot_mechanism
from .timeseries import plot_timeseries

__all__ = ["plot_mechanism", "plot_timeseries", "save_figures", "STOP_COLOUR", Motion,
           "TracePoint"]
