"""Frequency response pictures: a Bode plot (magnitude on log-log axes, phase in degrees)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numpy as np

from .canvas import PALETTE, add_legend, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure


def plot_bode(frequencies: np.ndarray, responses: Sequence[np.ndarray], labels: Sequence[str],
              title: str = "", unit: str = "") -> "Figure":
    """Magnitude |H| (log-log) over phase arg H (degrees) against frequency (Hz).

    Parameters
    ----------
    frequencies : ndarray
        Frequencies in Hz (n).
    responses : sequence of ndarray
        Complex responses H (n each), one line per response.
    labels : sequence of str
        A label per response.
    title, unit : str
        The figure's title, and the magnitude's unit (shown on its axis).
    """
    fig = new_figure((7.0, 5.6))
    mag_ax, ph_ax = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    f = np.asarray(frequencies, dtype=float)
    positive = f > 0
    for k, (h, label) in enumerate(zip(responses, labels)):
        colour = PALETTE[k % len(PALETTE)]
        h = np.asarray(h)
        mag = np.abs(h[positive])
        mag_ax.plot(f[positive], np.where(mag > 0, mag, np.nan), color=colour, label=label)
        ph_ax.plot(f[positive], np.degrees(np.angle(h[positive])), color=colour)
    if positive.any():
        mag_ax.set_xscale("log")
        if np.nanmax(np.abs(np.concatenate([np.ravel(r) for r in responses])),
                     initial=0.0) > 0:
            mag_ax.set_yscale("log")
    mag_ax.set_ylabel(f"|H| {unit}".strip())
    mag_ax.grid(True, which="both", alpha=0.3)
    ph_ax.set_ylabel("phase (deg)")
    ph_ax.set_yticks([-180, -90, 0, 90, 180])
    ph_ax.set_xlabel("frequency (Hz)")
    ph_ax.grid(True, which="both", alpha=0.3)
    if title:
        mag_ax.set_title(title)
    add_legend(mag_ax, fontsize=8)
    return fig
