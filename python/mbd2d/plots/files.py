"""Pictures written to files."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

from .geometry import Motion, TracePoint
from .mechanism import plot_mechanism
from .timeseries import plot_timeseries


def save_figures(result: Motion, stem: str | Path,
                 trace: Sequence[TracePoint] | None = None,
                 title: str | None = None) -> list[str]:
    """Write the mechanism picture and the time series as PNG files.

    Parameters
    ----------
    result : KinematicsResult
        The result to draw (see :func:`plot_mechanism`).
    stem : str or pathlib.Path
        Path prefix; its directory is created if needed.
    trace : sequence of (str, (float, float)), optional
        Traced body points, passed to :func:`plot_mechanism`.
    title : str, optional
        Title of the mechanism picture.

    Returns
    -------
    list of str
        ``f"{stem}_mechanism.png"`` and ``f"{stem}_timeseries.png"``.
    """
    stem = str(stem)
    Path(stem).parent.mkdir(parents=True, exist_ok=True)
    paths = [f"{stem}_mechanism.png", f"{stem}_timeseries.png"]
    ax = plot_mechanism(result, trace=trace, title=title)
    ax.figure.savefig(paths[0], dpi=110)
    plot_timeseries(result).savefig(paths[1], dpi=110)
    return paths
