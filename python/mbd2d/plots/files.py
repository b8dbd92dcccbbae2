"""Pictures written to files, and PNG bytes for notebooks."""
from __future__ import annotations

import io
from pathlib import Path
from typing import Any, Sequence

from ..errors import ModelError
from .canvas import new_figure
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


def save_figure(fig: Any, path: str | Path, dpi: int = 110) -> str:
    """Save a figure (or the figure of an Axes) as an image; a path that cannot be written is
    a ModelError."""
    fig = getattr(fig, "figure", fig)
    try:
        Path(str(path)).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(str(path), dpi=dpi)
    except OSError as exc:
        raise ModelError(f"cannot write {str(path)!r}: {exc.strerror or exc}", "plot") from None
    except ValueError as exc:   # unknown image format
        raise ModelError(f"cannot write {str(path)!r}: {exc}", "plot") from None
    return str(path)


def png_bytes(result: Motion, size: tuple[float, float] = (6.0, 4.8), dpi: int = 72,
              **kwargs: Any) -> bytes:
    """The mechanism picture of a result (or of one configuration) as PNG bytes."""
    ax = new_figure(size).add_subplot()
    plot_mechanism(result, ax=ax, **kwargs)
    buf = io.BytesIO()
    ax.figure.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()
