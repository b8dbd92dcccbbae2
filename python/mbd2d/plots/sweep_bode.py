"""A frequency response sweep's family: for each coordinate drawn, every variant's Bode
magnitude and phase over frequency coloured by a swept parameter (left), and each variant's
peak |H| and its frequency against that parameter (right). Failed variants have no response
and are marked on the summaries."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..errors import ModelError
from .canvas import STOP_COLOUR, add_legend, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: coordinates drawn by default: those that move most, at most this many
MAX_DEFAULT = 3


def frf_coordinates(ds: Any, coordinates: Sequence[str] | None, j: int) -> list[str]:
    """The coordinates drawn: those named (checked), or by default the ones whose largest
    |H| over cases and frequencies is above 1e-9 of the largest, most moving first (at most
    MAX_DEFAULT).

    Raises
    ------
    ModelError
        For an unknown coordinate, or a response that is zero everywhere.
    """
    names = [str(c) for c in ds.coordinate.values]
    if isinstance(coordinates, str):
        coordinates = [coordinates]
    if coordinates is not None:
        for c in coordinates:
            if c not in names:
                raise ModelError(f"no coordinate {c!r}; coordinates: {', '.join(names)}",
                                 "plot_sweep")
        return list(coordinates)
    mag = np.abs(np.asarray(ds.response.values[..., j]))           # (case, freq, nq)
    peak = np.nanmax(np.where(np.isfinite(mag), mag, np.nan), axis=(0, 1), initial=0.0) \
        if np.isfinite(mag).any() else np.zeros(len(names))
    moving = [k for k in np.argsort(-peak, kind="stable") if peak[k] > 1e-9 * peak.max()]
    if not moving:
        raise ModelError("nothing to draw: no variant's response moves (every response is "
                         "zero, or every variant failed)", "plot_sweep")
    return [names[k] for k in moving[:MAX_DEFAULT]]


def frf_input(ds: Any, input: str | None) -> int:
    """The index of the input drawn (default the first)."""
    inputs = [str(i) for i in ds.input.values]
    if input is None:
        return 0
    if input not in inputs:
        raise ModelError(f"no input {input!r}; the sweep's inputs: {', '.join(inputs)}",
                         "plot_sweep")
    return inputs.index(input)


def plot_sweep_frf(ds: Any, par: str, coordinates: Sequence[str] | None = None,
                   input: str | None = None) -> "Figure":
    """The Bode family of a frequency response sweep (see the module); par the swept
    parameter the colours and the summaries follow (checked by the caller)."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    j = frf_input(ds, input)
    drawn = frf_coordinates(ds, coordinates, j)
    names = [str(c) for c in ds.coordinate.values]
    values = np.asarray(ds[par].values, dtype=float)
    status = np.asarray(ds.status.values)
    norm = Normalize(values.min(), values.max() if values.max() > values.min()
                     else values.min() + 1.0)
    cmap = colormaps["viridis"]
    f = np.asarray(ds.frequency.values, dtype=float)
    fig = new_figure((12.0, 5.6 * len(drawn) + 0.6))
    axes = fig.subplots(2 * len(drawn), 2, squeeze=False, width_ratios=[1.5, 1.0])
    for row, name in enumerate(drawn):
        h = np.asarray(ds.response.values[:, :, names.index(name), j])    # (case, freq)
        mag_ax, ph_ax = axes[2 * row][0], axes[2 * row + 1][0]
        _family(mag_ax, ph_ax, f, h, values, status, norm, cmap)
        mag_ax.set_ylabel(f"|d({name})/d(input)|")
        fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=[mag_ax, ph_ax], label=par)
        _peaks(axes[2 * row][1], axes[2 * row + 1][1], f, h, values, status, par)
    axes[-1][0].set_xlabel("frequency [Hz]")
    failed = int((status != 0).sum())
    fig.suptitle(f"{ds.attrs.get('model', 'model')}: response to "
                 f"{ds.input.values[j]}, {len(values)} variants of {par}"
                 + (f" ({failed} failed)" if failed else ""))
    return fig


def _family(mag_ax: "Axes", ph_ax: "Axes", f: np.ndarray, h: np.ndarray, values: np.ndarray,
            status: np.ndarray, norm: Any, cmap: Any) -> None:
    """Every variant's magnitude (log-log where the frequencies are positive) and phase."""
    pos = f > 0
    for c in np.argsort(values, kind="stable"):
        if status[c] != 0:
            continue
        colour = cmap(norm(values[c]))
        mag = np.abs(h[c, pos])
        mag_ax.plot(f[pos], np.where(mag > 0, mag, np.nan), color=colour, lw=0.9)
        ph_ax.plot(f[pos], np.degrees(np.angle(h[c, pos])), color=colour, lw=0.9)
    if pos.any():
        mag_ax.set_xscale("log")
        ph_ax.set_xscale("log")
        if np.nanmax(np.abs(h[status == 0][:, pos]), initial=0.0) > 0:
            mag_ax.set_yscale("log")
    ph_ax.set_ylabel("phase [deg]")
    ph_ax.set_yticks([-180, -90, 0, 90, 180])
    for ax in (mag_ax, ph_ax):
        ax.grid(True, which="both", lw=0.4, alpha=0.5)


def _peaks(top: "Axes", bottom: "Axes", f: np.ndarray, h: np.ndarray, values: np.ndarray,
           status: np.ndarray, par: str) -> None:
    """Each variant's peak |H| (top) and the frequency of its peak (bottom) against the
    parameter; failed variants marked at the bottom of each."""
    ok = (status == 0) & np.isfinite(h).all(axis=1) & (h.shape[1] > 0)
    mag = np.abs(h[ok])
    k = np.argmax(mag, axis=1) if mag.size else np.zeros(0, dtype=int)
    top.plot(values[ok], mag[np.arange(len(k)), k], ".", color="#1f77b4", ms=4,
             label="peak |H|")
    bottom.plot(values[ok], f[k], ".", color="#ff7f0e", ms=4, label="frequency of the peak")
    bad = ~ok
    for ax in (top, bottom):
        if bad.any():
            lo = ax.get_ylim()[0]
            ax.plot(values[bad], np.full(int(bad.sum()), lo), "x", color=STOP_COLOUR, ms=5,
                    label="failed")
        ax.grid(True, lw=0.4, alpha=0.5)
        add_legend(ax, fontsize=8, loc="best")
    top.set_ylabel("peak |H|")
    bottom.set_ylabel("peak at [Hz]")
    bottom.set_xlabel(par)


__all__ = ["plot_sweep_frf", "frf_coordinates", "frf_input"]
