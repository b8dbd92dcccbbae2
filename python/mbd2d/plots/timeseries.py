"""Time series: x, y, theta of bodies and their derivatives; driver efforts and joint
reactions; energies and constraint drift; mechanism measures (transmission angle, velocity
ratio, mechanical advantage, dead-centre distance). Dead centres and singular passages are
marked on every time axis."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..errors import ModelError
from ..validate import GROUND
from .canvas import PALETTE, PASSAGE_COLOUR, STOP_COLOUR, add_legend, new_figure
from .geometry import Motion

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

KINDS = ("motion", "forces", "energy", "measures")
#: the transmission angle designers keep: pi/2 +- 50 deg (Norton, ch. 4) [deg]
MU_WINDOW = (40.0, 140.0)


def mark_times(ax: "Axes", result: Motion, labels: bool = True) -> None:
    """Vertical lines at the singular passages (dotted) and where the run stopped (dashed
    red, with the dead centre's time when the run ended at one)."""
    stats = getattr(result, "stats", {}) or {}
    for i, tp in enumerate(stats.get("singular_passages", []) or []):
        ax.axvline(tp, color=PASSAGE_COLOUR, ls=":", lw=1.2,
                   label="singular passage" if labels and i == 0 else None)
    dead = stats.get("dead_centre")
    if dead is not None:
        ax.axvline(dead, color=STOP_COLOUR, ls="--", lw=1.0,
                   label=f"dead centre, t = {dead:.6g} s" if labels else None)
    elif not result.complete and len(result.t):
        ax.axvline(result.t[-1], color=STOP_COLOUR, ls="--", lw=1.0,
                   label="run stopped" if labels else None)


def plot_timeseries(result: Motion, bodies: Sequence[str] | None = None,
                    kind: str = "motion", length_unit: str = "m",
                    force_unit: str = "N", measures: Sequence[str] | None = None) -> "Figure":
    """Plot a result against time.

    Parameters
    ----------
    result : KinematicsResult or DynamicsResult
        The result to plot. Singular passages are marked by dotted lines, a dead centre (or
        where an incomplete run stopped) by a dashed red line.
    bodies : sequence of str, optional
        Bodies to plot (default: all); kind "motion" only.
    kind : {"motion", "forces", "energy"}
        "motion": x, y, theta and their first and second derivatives (three rows by three
        columns, one line per body). "forces": what each driver supplies (torque or force)
        and the magnitude of each joint's reaction on its moving body; needs multipliers
        (inverse dynamics or dynamics). "energy": kinetic, potential and total energy and
        the constraint drift ||Phi||, ||J q_dot - nu||; needs a DynamicsResult. "measures":
        one axis per measure of ``measures`` (specs as ``res.table(measures=...)``: the
        transmission angle in degrees with the 40-140 deg window designers keep, ratios,
        the dead-centre distance).
    length_unit, force_unit : str
        Units for the axis labels (default "m" and "N"; any consistent set).
    measures : sequence of str, optional
        The measures of kind "measures".

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    KeyError
        If a body name is unknown.
    ModelError
        If ``kind`` is unknown or needs multipliers the result does not have.

    Examples
    --------
    >>> import mbd2d
    >>> from mbd2d.plots import plot_timeseries
    >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=90)
    >>> fig = plot_timeseries(res, bodies=["rocker"])
    """
    if kind not in KINDS:
        raise ModelError(f"unknown kind {kind!r}; use one of {', '.join(KINDS)}",
                         "plot_timeseries")
    if kind == "measures":
        return _measures(result, measures)
    if kind != "motion" and not hasattr(result, "lam"):
        raise ModelError(f"kind={kind!r} needs a result with multipliers and energies "
                         "(inverse dynamics, dynamics, or kinematics of a model with masses)",
                         "plot_timeseries")
    if kind == "forces":
        return _forces(result, force_unit, length_unit)
    if kind == "energy":
        return _energy(result, force_unit, length_unit)
    return _motion(result, bodies, length_unit)


def _name(result: Motion) -> str:
    model = getattr(result, "model", None)
    return model.name if model is not None else "result"


def _motion(result: Motion, bodies: Sequence[str] | None, lu: str) -> "Figure":
    if isinstance(bodies, str):                 # (one body by its name)
        bodies = [bodies]
    if bodies is not None and not isinstance(bodies, (list, tuple)):
        raise ModelError(f"bodies must be a list of body names, got {bodies!r}",
                         "plot_timeseries")
    names = list(result.body_names if bodies is None else bodies)
    hist = [result.body(b) for b in names]  # KeyError on an unknown name
    levels = 1 if getattr(result, "qd", None) is None else 3    # (positions only: 1)
    fig = new_figure((11.0, 8.0 if levels == 3 else 3.6))
    axes = fig.subplots(levels, 3, sharex=True, squeeze=False)
    marks = ["", "\u0307", "\u0308"]  # combining dot / two dots
    per = ["", "/s", "/s²"]
    suffixes = ["", "_dot", "_ddot"][:levels]
    for i, suffix in enumerate(suffixes):
        row_data = [np.asarray(getattr(h, c + suffix)) for h in hist for c in ("x", "y", "theta")]
        ref = max([1.0] + [float(np.abs(d).max()) for d in row_data if d.size])
        for c, coord in enumerate(("x", "y", "theta")):
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
            unit = "rad" if coord == "theta" else lu
            a.set_ylabel(f"{sym}{marks[i]} [{unit}{per[i]}]" if unit else f"{sym}{marks[i]}")
            a.grid(True, lw=0.4, alpha=0.5)
            mark_times(a, result, labels=(i, c) == (0, 0))
            if i == levels - 1:
                a.set_xlabel("t [s]")
    for c, sym in enumerate(("x", "y", "θ")):
        axes[0][c].set_title(sym)
    add_legend(axes[0][0], fontsize=8, loc="best")
    fig.suptitle(f"{_name(result)}: positions"
                 + (", velocities, accelerations" if levels == 3 else "")
                 + ("" if result.complete else " (incomplete run)"))
    return fig


def _measures(result: Any, specs: Sequence[str] | None) -> "Figure":
    if not specs or isinstance(specs, str):
        specs = [specs] if isinstance(specs, str) else []
    if not specs:
        raise ModelError('kind="measures" needs measures=[specs] (for example '
                         '"transmission_angle:B")', "plot_timeseries")
    header, rows = result.table(measures=list(specs))      # the measures are its last columns
    values = rows[:, len(header) - len(specs):]
    fig = new_figure((10.0, 1.2 + 2.3 * len(specs)))
    axes = fig.subplots(len(specs), 1, sharex=True, squeeze=False)
    for i, spec in enumerate(specs):
        a = axes[i][0]
        y = np.asarray(values[:, i], dtype=float)
        angle = spec.startswith("transmission_angle")
        if angle:
            y = np.degrees(y)
            for bound in MU_WINDOW:
                a.axhline(bound, color="0.6", ls=":", lw=1.0)
        # infinite ratios (a limit position of the input or output) leave a gap
        a.plot(result.t, np.where(np.isfinite(y), y, np.nan), lw=1.5,
               color=PALETTE[i % len(PALETTE)])
        a.set_ylabel("deg" if angle else "")
        a.set_title(spec, fontsize=9)
        a.grid(True, lw=0.4, alpha=0.5)
        mark_times(a, result, labels=i == 0)
    axes[-1][0].set_xlabel("t [s]")
    if result.stats.get("singular_passages") or not result.complete:
        add_legend(axes[0][0], fontsize=8, loc="best")
    fig.suptitle(f"{_name(result)}: mechanism measures"
                 + ("" if result.complete else " (incomplete run)"))
    return fig


def _effort_unit(driver: Any, fu: str, lu: str) -> str:
    angle = getattr(driver, "coordinate", "theta") == "theta" and driver.type != \
        "relative-distance"
    return f"{fu} {lu}" if angle else fu


def _forces(result: Any, fu: str, lu: str) -> "Figure":
    model = result.model
    drivers = [c for c in model.constraints if c.is_driver]
    joints = list(model.joints)
    fig = new_figure((10.0, 7.0))
    axes = fig.subplots(2, 1, sharex=True, squeeze=False)
    a = axes[0][0]
    units = set()
    for k, d in enumerate(drivers):
        u = _effort_unit(d, fu, lu)
        units.add(u)
        a.plot(result.t, result.effort(d.name), lw=1.5, color=PALETTE[k % len(PALETTE)],
               label=f"{d.name} [{u}]")
    a.set_ylabel("driver effort [" + ", ".join(sorted(units)) + "]" if units
                 else "driver effort")
    a.set_title("what each driver supplies (torque for angles, force for slides)")
    a.grid(True, lw=0.4, alpha=0.5)
    mark_times(a, result)
    if drivers:
        add_legend(a, fontsize=8, loc="best")
    b = axes[1][0]
    for k, j in enumerate(joints):
        r = result.reaction(j.name)
        on_j = j.bodies[1] != GROUND
        fx, fy = (r.fx_j, r.fy_j) if on_j else (r.fx, r.fy)
        body = j.bodies[1] if on_j else j.bodies[0]
        b.plot(result.t, np.hypot(fx, fy), lw=1.4, color=PALETTE[k % len(PALETTE)],
               label=f"{j.name} on {body}")
    b.set_ylabel(f"|reaction force| [{fu}]")
    b.set_xlabel("t [s]")
    b.set_title("joint reactions (force on the body named)")
    b.grid(True, lw=0.4, alpha=0.5)
    mark_times(b, result, labels=False)
    if joints:
        add_legend(b, fontsize=8, loc="best", ncol=2)
    fig.suptitle(f"{_name(result)}: driver efforts and joint reactions"
                 + ("" if result.complete else " (incomplete run)"))
    return fig


def _energy(result: Any, fu: str, lu: str) -> "Figure":
    fig = new_figure((10.0, 7.0))
    axes = fig.subplots(2, 1, sharex=True, squeeze=False)
    a = axes[0][0]
    eu = "J" if (fu, lu) == ("N", "m") else f"{fu} {lu}"
    a.plot(result.t, result.kinetic, lw=1.4, label="kinetic")
    a.plot(result.t, result.potential, lw=1.4, label="potential")
    a.plot(result.t, result.kinetic + result.potential, lw=1.8, color="k", label="total")
    a.set_ylabel(f"energy [{eu}]")
    a.grid(True, lw=0.4, alpha=0.5)
    mark_times(a, result)
    add_legend(a, fontsize=8, loc="best")
    b = axes[1][0]
    floor = 1e-300
    b.semilogy(result.t, np.maximum(result.drift_position, floor), lw=1.2,
               label=f"||Φ||∞ [{lu}]")
    b.semilogy(result.t, np.maximum(result.drift_velocity, floor), lw=1.2,
               label=f"||J q̇ − ν||∞ [{lu}/s]")
    b.set_ylabel("constraint drift")
    b.set_xlabel("t [s]")
    b.grid(True, lw=0.4, alpha=0.5)
    mark_times(b, result, labels=False)
    add_legend(b, fontsize=8, loc="best")
    fig.suptitle(f"{_name(result)}: energy and constraint drift"
                 + ("" if result.complete else " (incomplete run)"))
    return fig
