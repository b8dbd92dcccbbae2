"""The time-series picture: x, y, theta of bodies and their derivatives against t."""
from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numpy as np

from .canvas import PALETTE, STOP_COLOUR, new_figure
from .geometry import Motion

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure


def plot_timeseries(result: Motion,
                    bodies: Sequence[str] | None = None) -> "Figure":
    """Plot x, y, theta of bodies and their first and second time derivatives against t.

    Parameters
    ----------
    result : KinematicsResult
        The result to plot. For an incomplete result a dashed red line marks where the run
        stopped.
    bodies : sequence of str, optional
        Bodies to plot (default: all).

    Returns
    -------
    matplotlib.figure.Figure
        Three rows (positions, velocities, accelerations) by three columns (x, y, theta),
        one line per body.

    Raises
    ------
    KeyError
        If a body name is unknown.
    """
    names = list(result.body_names if bodies is None else bodies)
    hist = [result.body(b) for b in names]  # KeyError on an unknown name
    fig = new_figure((11.0, 8.0))
    axes = fig.subplots(3, 3, sharex=True, squeeze=False)
    rows = [("", ""), ("_dot", "velocity"), ("_ddot", "acceleration")]
    cols = [("x", "x"), ("y", "y"), ("theta", "θ [rad]")]
    marks = ["", "\u0307", "\u0308"]  # combining dot / two dots
    for i, (suffix, _) in enumerate(rows):
        row_data = [np.asarray(getattr(h, coord + suffix)) for h in hist for coord, _ in cols]
        ref = max([1.0] + [float(np.abs(d).max()) for d in row_data if d.size])
        for c, (coord, label) in enumerate(cols):
            a = axes[i][c]
            data = [np.asarray(getattr(h, coord + suffix)) for h in hist]
            flat = np.concatenate(data) if data else np.zeros(0)
            if flat.size and np.ptp(flat) <= 1e-9 * ref:
                # constant up to round-off: do not blow 1e-16 noise up to the full height
                mid = float(flat.mean())
                a.set_ylim(mid - 0.1 * ref, mid + 0.1 * ref)
            for k, h in enumerate(hist):
                a.plot(result.t, getattr(h, coord + suffix), lw=1.4,
                       color=PALETTE[result.body_names.index(names[k]) % len(PALETTE)],
                       label=names[k])
            sym = "θ" if coord == "theta" else coord
            unit = " [rad" + ("/s" if i == 1 else "/s²" if i == 2 else "") + "]" \
                if coord == "theta" else ""
            a.set_ylabel(f"{sym}{marks[i]}{unit}")
            a.grid(True, lw=0.4, alpha=0.5)
            if not result.complete and len(result.t):
                a.axvline(result.t[-1], color=STOP_COLOUR, ls="--", lw=1.0,
                          label="run stopped" if (i, c) == (0, 0) else None)
            if i == 2:
                a.set_xlabel("t [s]")
    for c, (_, label) in enumerate(cols):
        axes[0][c].set_title({"x": "x", "y": "y", "θ [rad]": "θ"}[label])
    axes[0][0].legend(fontsize=8, loc="best")
    model = getattr(result, "model", None)
    name = model.name if model is not None else "result"
    fig.suptitle(f"{name}: positions, velocities, accelerations"
                 + ("" if result.complete else " (incomplete run)"))
    return fig
