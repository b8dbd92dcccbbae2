"""A sweep's family in one figure: one row per quantity (a mechanism measure of the sweep, or
a coordinate), its curves over time for every case coloured by a swept parameter (left), and
each case's summary against that parameter (right): for a transmission angle the worst one,
min(mu, 180 - mu), against the 40 deg rule of thumb; for anything else the least and greatest
value over the case's rows. Cases that failed are drawn up to where they stopped, in red, and
marked on the summary."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..errors import ModelError
from .canvas import STOP_COLOUR, add_legend, new_figure
from .sweep_bode import plot_sweep_frf
from .timeseries import MU_WINDOW

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: a transmission angle's summary: the worst of each case must stay above this [deg]
MU_WORST = MU_WINDOW[0]


def _parameter(ds: Any, parameter: str | None) -> str:
    """The swept parameter the colours and the summary's axis follow (default: the first)."""
    attrs = getattr(ds, "attrs", None)
    names = [n for n in str(attrs.get("parameters", "")).split(", ") if n] \
        if isinstance(attrs, dict) and hasattr(ds, "status") else []
    if not names:
        raise ModelError("plot_sweep takes the Dataset of mbd2d.sweep (its parameters are "
                         "named in ds.attrs['parameters'])", "plot_sweep")
    if parameter is None:
        return names[0]
    if parameter not in names:
        raise ModelError(f"{parameter!r} is not swept; the sweep's parameters: "
                         f"{', '.join(names)}", "plot_sweep")
    return parameter


def sweep_quantities(ds: Any, measures: Sequence[str] | None,
                     coordinates: Sequence[str] | None) -> list[tuple[str, str, np.ndarray]]:
    """(kind, name, values (case, time)) of each quantity drawn: the measures asked for
    (default: every measure of the sweep) and the coordinates asked for (values in their own
    unit; a transmission angle in degrees).

    Raises
    ------
    ModelError
        For a measure the sweep does not have, an unknown coordinate, or nothing to draw.
    """
    have = [str(m) for m in ds["measure"].values] if "measure" in ds.coords else []
    if measures is None:
        measures = have if coordinates is None else []
    if isinstance(measures, str):
        measures = [measures]
    if isinstance(coordinates, str):
        coordinates = [coordinates]
    out = []
    for spec in measures:
        if spec not in have:
            raise ModelError(f"the sweep has no measure {spec!r}"
                             + (f"; it has {', '.join(have)}" if have else
                                "; run mbd2d.sweep(..., measures=[...])"), "plot_sweep")
        v = np.asarray(ds["measures"].values[:, :, have.index(spec)], dtype=float)
        if spec.startswith("transmission_angle"):
            v = np.degrees(v)
        out.append(("measure", spec, v))
    names = [str(c) for c in ds.coordinate.values]
    for c in coordinates or []:
        if c not in names:
            raise ModelError(f"no coordinate {c!r}; coordinates: {', '.join(names)}",
                             "plot_sweep")
        out.append(("coordinate", c, np.asarray(ds.q.values[:, :, names.index(c)], float)))
    if not out:
        raise ModelError("nothing to draw: the sweep has no measures; name coordinates=[...] "
                         "or run mbd2d.sweep(..., measures=[...])", "plot_sweep")
    return out


def case_summary(name: str, v: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """Per case: the worst transmission angle min(mu, 180 - mu) [deg] (and None), or the
    least and greatest value; NaN for a case without rows."""
    finite = np.where(np.isfinite(v), v, np.nan)      # (infinite ratios: gaps)
    rows = np.isfinite(finite).any(axis=1)
    lo, hi = np.full(len(v), np.nan), np.full(len(v), np.nan)
    if name.startswith("transmission_angle"):
        lo[rows] = np.nanmin(np.minimum(finite[rows], 180.0 - finite[rows]), axis=1)
        return lo, None
    lo[rows], hi[rows] = np.nanmin(finite[rows], axis=1), np.nanmax(finite[rows], axis=1)
    return lo, hi


def plot_sweep(ds: Any, measures: Sequence[str] | None = None,
               coordinates: Sequence[str] | None = None,
               parameter: str | None = None, input: str | None = None) -> "Figure":
    """Plot a sweep's family: each quantity over time for every case, and each case's
    summary against a swept parameter; for a frequency response sweep, each coordinate's
    Bode magnitude and phase for every case, and each case's peak and its frequency.

    Parameters
    ----------
    ds : xarray.Dataset
        The result of :func:`mbd2d.sweep` (a run over time, not statics).
    measures : sequence of str, optional
        Measures of the sweep to draw (default: all of them when no coordinate is named).
    coordinates : sequence of str, optional
        Coordinates to draw (``"rocker.theta"`` ...): their values over time, and each
        case's least and greatest value (a frequency response sweep: their responses;
        default the three that move most).
    parameter : str, optional
        The swept parameter the colours and the summary follow (default: the first).
    input : str, optional
        A frequency response sweep's input drawn (default: the first).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ModelError
        For a Dataset that is not a sweep over time, a measure it does not have, an unknown
        coordinate or parameter, or nothing to draw.
    """
    par = _parameter(ds, parameter)
    if ds.attrs.get("run") == "frf":
        if measures is not None:
            raise ModelError("a frequency response sweep has no measures; name its "
                             "coordinates=[...]", "plot_sweep")
        return plot_sweep_frf(ds, par, coordinates, input)
    if input is not None:
        raise ModelError("input= names a frequency response sweep's input", "plot_sweep")
    if ds.sizes.get("time", 0) < 2 or ds.attrs.get("run") == "statics":
        raise ModelError("plot_sweep draws a sweep over time (kinematics, inverse dynamics, "
                         "dynamics), not statics", "plot_sweep")
    items = sweep_quantities(ds, measures, coordinates)
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    values = np.asarray(ds[par].values, dtype=float)
    status = np.asarray(ds.status.values)
    norm = Normalize(values.min(), values.max() if values.max() > values.min()
                     else values.min() + 1.0)
    cmap = colormaps["viridis"]
    fig = new_figure((12.0, 3.4 * len(items) + 0.6))
    axes = fig.subplots(len(items), 2, squeeze=False, width_ratios=[1.5, 1.0])
    t = np.asarray(ds.time.values, dtype=float)
    for row, (kind, name, v) in enumerate(items):
        _curves(axes[row][0], t, v, values, status, norm, cmap, name, row == 0)
        _summary(axes[row][1], name, v, values, status, par, row == 0)
        fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=axes[row][0], label=par)
    axes[-1][0].set_xlabel("t [s]")
    failed = int((status != 0).sum())
    fig.suptitle(f"{ds.attrs.get('model', 'model')}: {len(values)} variants of {par}"
                 + (f" ({failed} failed)" if failed else ""))
    return fig


def _label(name: str) -> str:
    return f"{name} [deg]" if name.startswith("transmission_angle") else name


def _curves(ax: "Axes", t: np.ndarray, v: np.ndarray, values: np.ndarray, status: np.ndarray,
            norm: Any, cmap: Any, name: str, legend: bool) -> None:
    """Every case's curve, coloured by its parameter; failed cases in red up to where they
    stopped (an x there)."""
    marked = False
    for j in np.argsort(values, kind="stable"):
        ok = np.isfinite(v[j])
        if not ok.any():
            continue
        if status[j] == 0:
            ax.plot(t[ok], v[j][ok], color=cmap(norm(values[j])), lw=0.9)
            continue
        ax.plot(t[ok], v[j][ok], color=STOP_COLOUR, lw=0.8, alpha=0.7)
        last = np.flatnonzero(ok)[-1]
        ax.plot(t[last], v[j][last], "x", color=STOP_COLOUR, ms=6,
                label="failed: where the case stopped" if legend and not marked else None)
        marked = True
    if name.startswith("transmission_angle"):
        for b in MU_WINDOW:
            ax.axhline(b, color="0.5", ls="--", lw=0.8)
    ax.set_ylabel(_label(name))
    ax.grid(True, lw=0.4, alpha=0.5)
    if marked and legend:
        add_legend(ax, fontsize=8, loc="best")


def _summary(ax: "Axes", name: str, v: np.ndarray, values: np.ndarray, status: np.ndarray,
             par: str, legend: bool) -> None:
    """Each case's worst transmission angle (or least and greatest value) against the
    parameter; failed cases marked."""
    lo, hi = case_summary(name, v)
    ok, bad = status == 0, status != 0
    if hi is None:
        ax.plot(values[ok], lo[ok], ".", color="#1f77b4", ms=4, label="min(mu, 180 - mu)")
        ax.axhline(MU_WORST, color="0.5", ls="--", lw=0.8, label=f"{MU_WORST:g} deg")
        ax.set_ylabel("worst transmission angle [deg]")
    else:
        ax.plot(values[ok], hi[ok], ".", color="#1f77b4", ms=4, label="greatest")
        ax.plot(values[ok], lo[ok], ".", color="#ff7f0e", ms=4, label="least")
        ax.set_ylabel(_label(name))
    if bad.any():
        ax.plot(values[bad], lo[bad], "x", color=STOP_COLOUR, ms=5,
                label="failed (up to where it stopped)")
    ax.set_xlabel(par)
    ax.grid(True, lw=0.4, alpha=0.5)
    add_legend(ax, fontsize=8, loc="best")


__all__ = ["plot_sweep", "sweep_quantities", "case_summary"]
