"""The mechanism picture: bodies at a few snapshots (earlier ones lighter), with traced
paths, loads and, optionally, reactions; and the paths picture."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..description.joints import Revolute
from ..errors import ModelError
from ..validate import GROUND
from .canvas import STOP_COLOUR, add_legend, import_matplotlib, new_figure, shade
from .elements import Look
from .geometry import Motion, TracePoint, check_trace, snapshot_rows
from .scene import Scene

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes


def plot_mechanism(result: Motion, times: Sequence[float] | None = None,
                   trace: Sequence[TracePoint] | None = None, ax: "Axes | None" = None,
                   title: str | None = None, forces: bool = False, length_unit: str = "m",
                   snapshots: int = 6) -> "Axes":
    """Draw the mechanism at a few times, with the paths of traced points.

    Every element is drawn as an engineer draws it (:mod:`mbd2d.plots.elements`): bodies as
    bars or plates between their joints (a slider as a block), pins as circles and ground
    pivots hatched, slides as hatched rails, slots, gears as pitch circles with teeth and a
    mark, racks, rolling discs on their line, cam profiles with their followers, springs as
    zigzags, applied forces and torques as arrows. Earlier snapshots are lighter.

    Parameters
    ----------
    result : KinematicsResult
        The result to draw; it must carry its model (``result.model``). An incomplete result
        (``result.complete`` false, e.g. the ``.results`` of a
        :class:`~mbd2d.SingularConfigurationError`) has its last configuration drawn in red
        and labelled.
    times : sequence of float, optional
        Snapshot times; the nearest output rows are drawn. Default: ``snapshots`` rows
        evenly spaced over the run.
    trace : sequence of (str, (float, float)), optional
        Points ``(body_name, (sx, sy))`` fixed in bodies whose global paths over the whole
        run are drawn (e.g. a coupler point).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new figure is made.
    title : str, optional
        Axes title; by default the model name and the time span.
    forces : bool
        Also draw each joint's reaction force on its second body (on its first when the
        second is ground) as arrows; the result needs multipliers (a DynamicsResult).
    length_unit : str
        Unit of length for the axis labels (default "m"; "" for none).
    snapshots : int
        Number of snapshots when ``times`` is not given (default 6).

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ModelError
        (a ValueError) If the result has no rows or no model, a time is outside the run, a
        trace entry names no body, or reactions are asked of a result without multipliers.

    Examples
    --------
    >>> import mbd2d
    >>> from mbd2d.plots import plot_mechanism
    >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=90)
    >>> ax = plot_mechanism(res, trace=[("coupler", (0.0, 1.0))])
    >>> ax.figure.savefig("/tmp/fourbar.png")
    """
    scene = Scene(result, trace, forces)
    if ax is None:
        ax = new_figure((8.0, 6.5)).add_subplot()
    else:
        import_matplotlib()
    rows = snapshot_rows(result, times, _count(snapshots))
    m = len(rows)
    stopped = not result.complete
    last_normal = m - 2 if stopped and m > 1 else m - 1   # the snapshot with the labels

    def look(k: int) -> Look:
        if stopped and k == m - 1:
            return Look(lambda b: STOP_COLOUR, 0.15, 2.0 + k / m, m == 1)
        f = 1.0 if m == 1 else 0.25 + 0.75 * k / (m - 1)
        return Look(lambda b: shade(scene.colour(b), f), 0.3 if k >= last_normal else 0.1,
                    2.0 + k / max(m, 1), k == last_normal)

    scene.draw_fixed(ax)
    for k, r in enumerate(rows):
        scene.make(ax, look(k))(int(r))
    scene.fit(ax)

    if stopped:
        t_last = result.t[-1]
        ax.plot([], [], color=STOP_COLOUR, lw=3,
                label=f"last configuration, t = {t_last:.6g} s (run stopped)")
        pts = [scene.full.place(b, s)[-1] for b, ss in scene.attach.items() for s in ss]
        top = max(pts, key=lambda p: p[1])
        ax.annotate(f"last configuration:\nrun stopped after t = {t_last:.6g} s",
                    xy=top, xytext=(0, 28), textcoords="offset points", ha="center",
                    va="bottom", color=STOP_COLOUR, fontsize=9,
                    arrowprops={"arrowstyle": "->", "color": STOP_COLOUR}, zorder=10)
    if title is None:
        span = f"t = {result.t[0]:.4g} .. {result.t[-1]:.4g} s"
        title = f"{scene.model.name}: {m} snapshot{'s' if m > 1 else ''}, {span}"
    scene.dress(ax, length_unit, title)
    add_legend(ax, loc="best", fontsize=8, framealpha=0.85)
    return ax


def _count(n: Any) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= 1000:
        raise ModelError(f"must be a whole number from 1 to 1000, got {n!r}", "snapshots")
    return int(n)


def default_points(model: Any) -> list[TracePoint]:
    """The points whose paths tell a mechanism's motion: every pin of a revolute joint on a
    moving body (once per joint, on its first moving body) that does not stay on ground."""
    out: list[TracePoint] = []
    for j in model.joints:
        if isinstance(j, Revolute) and GROUND not in j.bodies:
            out.append((j.bodies[0], (float(j.points[0][0]), float(j.points[0][1]))))
    if not out:
        out = [(b.name, (0.0, 0.0)) for b in model.bodies]
    return out


def plot_paths(result: Motion, points: Sequence[TracePoint] | None = None,
               ax: "Axes | None" = None, title: str | None = None,
               length_unit: str = "m", at: float | None = None) -> "Axes":
    """The paths of body points over the run (coupler curves), drawn over the mechanism
    at one time, with arrowheads in the direction of motion and a dot where each starts.

    Parameters
    ----------
    result : KinematicsResult
        The run (with its model).
    points : sequence of (str, (float, float)), optional
        ``(body, (sx, sy))`` points to trace; default: every pin that does not stay on
        ground (the moving revolute joints).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new figure is made.
    title : str, optional
        Axes title.
    length_unit : str
        Unit of length for the axis labels (default "m").
    at : float, optional
        Time of the mechanism drawn under the paths (default: the first output).

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ModelError
        If a point names no body or ``at`` is outside the run.

    Examples
    --------
    >>> import mbd2d
    >>> from mbd2d.plots import plot_paths
    >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=90)
    >>> ax = plot_paths(res, [("coupler", (0.0, 1.0)), ("coupler", (1.75, 0.0))])
    """
    model = getattr(result, "model", None)
    pts = check_trace(result, points) if points is not None else \
        (default_points(model) if model else [])
    scene = Scene(result, pts, what="plot_paths")
    if ax is None:
        ax = new_figure((8.0, 6.5)).add_subplot()
    else:
        import_matplotlib()
    row = int(snapshot_rows(result, [result.t[0] if at is None else at])[0])
    scene.draw_fixed(ax)
    scene.make(ax, Look(lambda b: shade(scene.colour(b), 0.45), 0.12, 2.0, True))(row)
    n = len(result.t)
    for i, tr in enumerate(scene.traces):
        path = tr.path
        ax.plot(*path[0], marker="o", ms=5, color="k", zorder=3.5)
        for k in np.unique(np.linspace(0, n - 2, 5).astype(int))[1:] if n > 2 else []:
            d = path[k + 1] - path[k]
            if np.hypot(*d) > 0:
                ax.annotate("", xy=path[k + 1], xytext=path[k], zorder=3.5,
                            arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.0})
    if title is None:
        title = (f"{scene.model.name}: paths, t = {result.t[0]:.4g} .. {result.t[-1]:.4g} s"
                 f" (mechanism at t = {result.t[row]:.4g} s)")
    scene.fit(ax)
    scene.dress(ax, length_unit, title)
    add_legend(ax, loc="best", fontsize=8, framealpha=0.85)
    return ax
