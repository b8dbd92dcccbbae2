"""The matplotlib canvas: the one place matplotlib is imported (inside the functions, so that
``import mbd2d`` does not need it), colours shared by every picture."""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Colour of the configuration where an incomplete run stopped.
STOP_COLOUR = "#d62728"
GROUND_COLOUR = "0.35"
#: Applied loads (point forces, torques) and joint reactions drawn as arrows.
LOAD_COLOUR = "#e6550d"
REACTION_COLOUR = "#7b3294"
#: Singular passages marked on time axes.
PASSAGE_COLOUR = "#8c564b"
PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
           "#bcbd22", "#7f7f7f"]


def import_matplotlib() -> Any:
    """Import matplotlib, selecting Agg unless pyplot already runs another backend."""
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("mbd2d.plots needs matplotlib: pip install 'mbd2d[plot]'") from exc
    if "matplotlib.pyplot" not in sys.modules:
        # switching the backend under a running pyplot would close the user's figures
        matplotlib.use("Agg")
    return matplotlib


def new_figure(figsize: tuple[float, float]) -> "Figure":
    """A Figure on its own Agg canvas (not managed by pyplot)."""
    import_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


#: legends with more entries than this are left out: a chain of a hundred bodies is read from
#: its colours and its title, not from a list running off the figure
LEGEND_MAX = 16


def add_legend(ax: "Axes", **kw: Any) -> None:
    """ax.legend(**kw) when the axes have from 1 to LEGEND_MAX labelled artists."""
    _, labels = ax.get_legend_handles_labels()
    if 0 < len(labels) <= LEGEND_MAX:
        ax.legend(**kw)


def shade(colour: str, f: float) -> tuple[float, float, float]:
    """colour mixed with white: f = 1 the colour itself, f -> 0 white."""
    from matplotlib.colors import to_rgb

    c = np.array(to_rgb(colour))
    return tuple(1.0 - f * (1.0 - c))  # type: ignore[return-value]
