"""Layer 4, the pictures: the mechanism at snapshots, paths, time series, animations, and a
sweep's family of variants.

matplotlib is imported only when a function here is called, so ``import mbd2d`` does not
need it. Figures are drawn on the non-interactive Agg canvas and are not registered with
``pyplot`` (nothing to close, no figure leak in loops).

Everything drawn is post-processing of the result: body poses come from the result, cam
profile points and load values from the Fortran core (through :mod:`mbd2d.binding.core`);
body-local points are placed with r + A(theta) s. How each element is drawn lives in
:mod:`.elements` (one class per kind, in one table).

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

from .animation import InlineAnimation, animate, ffmpeg_available
from .bode import plot_bode
from .canvas import STOP_COLOUR
from .files import png_bytes, save_figure, save_figures
from .geometry import Configuration, Motion, TracePoint
from .mechanism import default_points, plot_mechanism, plot_paths
from .sweep import plot_sweep
from .timeseries import plot_timeseries

__all__ = ["plot_mechanism", "plot_paths", "plot_timeseries", "plot_sweep", "plot_bode",
           "animate",
           "save_figures",
           "save_figure", "png_bytes", "InlineAnimation", "ffmpeg_available", "Configuration",
           "default_points", "STOP_COLOUR", "Motion", "TracePoint"]
