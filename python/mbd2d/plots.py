"""Pictures of a kinematic result: mechanism snapshots, time series, PNG output.

matplotlib is imported only when a function here is called, so ``import mbd2d`` does not
need it. Figures are drawn on the non-interactive Agg canvas and are not registered with
``pyplot`` (nothing to close, no figure leak in loops).

Everything drawn is post-processing of the result: body poses come from
:class:`~mbd2d.results.KinematicsResult`, cam profile points from the Fortran core
(``_core.core_profile``); body-local points are placed with r + A(theta) s.

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

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from .joints import PROFILE_KINDS, Cam, Revolute, Translational
from .validate import GROUND

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .results import KinematicsResult

TracePoint = tuple[str, tuple[float, float]]

#: Colour of the configuration where an incomplete run stopped.
STOP_COLOUR = "#d62728"
_GROUND_COLOUR = "0.35"
_PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
            "#bcbd22", "#7f7f7f"]
_NPROFILE = 361  # points along a drawn cam profile


# ---------------------------------------------------------------------------- matplotlib
def _matplotlib() -> Any:
    """Import matplotlib, selecting Agg unless pyplot already runs another backend."""
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("mbd2d.plots needs matplotlib: pip install 'mbd2d[plot]'") from exc
    if "matplotlib.pyplot" not in sys.modules:
        # switching the backend under a running pyplot would close the user's figures
        matplotlib.use("Agg")
    return matplotlib


def _new_figure(figsize: tuple[float, float]) -> "Figure":
    """A Figure on its own Agg canvas (not managed by pyplot)."""
    _matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _shade(colour: str, f: float) -> tuple[float, float, float]:
    """colour mixed with white: f = 1 the colour itself, f -> 0 white."""
    from matplotlib.colors import to_rgb

    c = np.array(to_rgb(colour))
    return tuple(1.0 - f * (1.0 - c))  # type: ignore[return-value]


# ---------------------------------------------------------------------------- geometry
class _Poses:
    """Body poses at chosen output rows, with ground at the origin."""

    def __init__(self, result: "KinematicsResult", rows: np.ndarray) -> None:
        self.rows = rows
        self._q: dict[str, np.ndarray] = {}
        for name in result.body_names:
            b = result.body(name)
            self._q[name] = np.column_stack([b.x[rows], b.y[rows], b.theta[rows]])
        self._ground = np.zeros((len(rows), 3))

    def pose(self, body: str) -> np.ndarray:
        """(m, 3) x, y, theta of body at the rows."""
        return self._ground if body == GROUND else self._q[body]

    def place(self, body: str, s: Any) -> np.ndarray:
        """(m, 2) global position of local point s = (sx, sy) of body at the rows."""
        p = self.pose(body)
        sx, sy = float(s[0]), float(s[1])
        c, sn = np.cos(p[:, 2]), np.sin(p[:, 2])
        return np.column_stack([p[:, 0] + c * sx - sn * sy, p[:, 1] + sn * sx + c * sy])

    def turn(self, body: str, v: Any) -> np.ndarray:
        """(m, 2) global direction of local vector v of body at the rows."""
        th = self.pose(body)[:, 2]
        c, sn = np.cos(th), np.sin(th)
        return np.column_stack([c * v[0] - sn * v[1], sn * v[0] + c * v[1]])

    def place_many(self, body: str, pts: np.ndarray, k: int) -> np.ndarray:
        """(n, 2) global positions of local points pts (n, 2) at the k-th row."""
        x, y, th = self.pose(body)[k]
        c, sn = np.cos(th), np.sin(th)
        return np.column_stack([x + c * pts[:, 0] - sn * pts[:, 1],
                                y + sn * pts[:, 0] + c * pts[:, 1]])


def _profile_points(cam: Cam, alphas: np.ndarray) -> np.ndarray:
    """(n, 2) points c(alpha) of a cam profile in its body frame, from the core."""
    from . import _core
    from .pack import decode

    raw = np.ascontiguousarray(cam.profile, dtype=np.float64)
    a = np.ascontiguousarray(alphas, dtype=np.float64)
    pts, status, msg = _core.core_profile(PROFILE_KINDS[cam.profile_kind], raw, a)
    if status != 0:
        raise ValueError(f"cam '{cam.name}': the core could not evaluate its profile: "
                         f"{decode(msg)}")
    return np.asarray(pts).T


def _hull(pts: np.ndarray) -> np.ndarray:
    """Convex hull (counterclockwise) of a few 2-D points; collinear points give the two
    extremes."""
    p = sorted({(round(float(x), 12), round(float(y), 12)) for x, y in pts})
    if len(p) <= 2:
        return np.array(p, dtype=float)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for q in p:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 0:
            lower.pop()
        lower.append(q)
    upper: list[tuple[float, float]] = []
    for q in reversed(p):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 0:
            upper.pop()
        upper.append(q)
    h = lower[:-1] + upper[:-1]
    return np.array(h, dtype=float)


def _body_points(model: Any, trace: Sequence[TracePoint]) -> dict[str, list[tuple[float, float]]]:
    """Local points of each moving body: its origin, its joint points, traced points."""
    pts: dict[str, list[tuple[float, float]]] = {b.name: [(0.0, 0.0)] for b in model.bodies}
    for j in model.joints:
        if isinstance(j, (Revolute, Translational)):
            for body, s in zip(j.bodies, j.points):
                if body != GROUND:
                    pts[body].append((float(s[0]), float(s[1])))
        elif isinstance(j, Cam) and j.bodies[1] != GROUND:
            pts[j.bodies[1]].append((float(j.follower[0]), float(j.follower[1])))
    for body, s in trace:
        if body != GROUND:
            pts[body].append((float(s[0]), float(s[1])))
    return pts


def _check_trace(result: "KinematicsResult", trace: Any) -> list[TracePoint]:
    if trace is None:
        return []
    out: list[TracePoint] = []
    for item in trace:
        try:
            body, s = item
            sx, sy = float(s[0]), float(s[1])
            if len(s) != 2:
                raise ValueError
        except (TypeError, ValueError):
            raise ValueError(f"trace entries must be (body_name, (sx, sy)), got {item!r}") \
                from None
        if body not in result.body_names:
            raise ValueError(f"trace: no body {body!r}; bodies: {', '.join(result.body_names)}")
        out.append((str(body), (sx, sy)))
    return out


def _snapshot_rows(result: "KinematicsResult", times: Any) -> np.ndarray:
    """Output rows to draw: a few evenly spaced ones, or the rows nearest to times."""
    n = len(result.t)
    if times is None:
        k = min(n, 6)
        rows = np.unique(np.round(np.linspace(0, n - 1, k)).astype(int))
    else:
        tt = np.atleast_1d(np.asarray(times, dtype=float))
        if tt.size == 0 or not np.all(np.isfinite(tt)):
            raise ValueError("times must be a non-empty list of finite times")
        lo, hi = result.t[0], result.t[-1]
        span = max(hi - lo, 1.0)
        bad = tt[(tt < lo - 1e-9 * span) | (tt > hi + 1e-9 * span)]
        if bad.size:
            raise ValueError(f"times {bad.tolist()} are outside the result's span "
                             f"t = {lo:g} .. {hi:g} s")
        rows = np.unique(np.abs(result.t[None, :] - tt[:, None]).argmin(axis=1))
    if not result.complete and rows[-1] != n - 1:
        rows = np.append(rows, n - 1)
    return rows


# ---------------------------------------------------------------------------- mechanism
def plot_mechanism(result: "KinematicsResult", times: Sequence[float] | None = None,
                   trace: Sequence[TracePoint] | None = None, ax: "Axes | None" = None,
                   title: str | None = None) -> "Axes":
    """Draw the mechanism at a few times, with the paths of traced points.

    Each body is drawn as the polygon (or line) through its attachment points in its own
    frame (origin, joint points, traced points), placed at each snapshot; earlier snapshots
    are lighter. Ground pivots are hatched triangles, translational guides a line along the
    axis, cam profiles the core's profile curve, roller followers circles, flat followers a
    face segment.

    Parameters
    ----------
    result : KinematicsResult
        The result to draw; it must carry its model (``result.model``). An incomplete result
        (``result.complete`` false, e.g. the ``.results`` of a
        :class:`~mbd2d.SingularConfigurationError`) has its last configuration drawn in red
        and labelled.
    times : sequence of float, optional
        Snapshot times; the nearest output rows are drawn. Default: six rows evenly spaced
        over the run.
    trace : sequence of (str, (float, float)), optional
        Points ``(body_name, (sx, sy))`` fixed in bodies whose global paths over the whole
        run are drawn (e.g. a coupler point).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new figure is made.
    title : str, optional
        Axes title; by default the model name and the time span.

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ValueError
        If the result has no rows or no model, a time is outside the run, or a trace entry
        names no body.
    """
    model = getattr(result, "model", None)
    if model is None:
        raise ValueError("the result carries no model (result.model is None); plot_mechanism "
                         "needs the joints to draw the bodies")
    if len(result.t) == 0:
        raise ValueError("the result has no rows to draw")
    tr = _check_trace(result, trace)
    if ax is None:
        ax = _new_figure((8.0, 6.5)).add_subplot()
    else:
        _matplotlib()

    n = len(result.t)
    rows = _snapshot_rows(result, times)
    snap = _Poses(result, rows)
    full = _Poses(result, np.arange(n))
    m = len(rows)
    stopped = not result.complete
    colours = {b.name: _PALETTE[i % len(_PALETTE)] for i, b in enumerate(model.bodies)}
    local = _body_points(model, tr)
    cams = [j for j in model.joints if isinstance(j, Cam)]
    profiles = {c.name: _profile_points(c, np.linspace(0.0, 2 * np.pi, _NPROFILE))
                for c in cams}

    # length scale: extent of everything that moves or is fixed, over the run
    extent = [full.place(b, s) for b, ss in local.items() for s in ss]
    for c in cams:
        pr = profiles[c.name]
        for k in np.unique(np.linspace(0, n - 1, 24).astype(int)):
            extent.append(full.place_many(c.bodies[0], pr, k))
    for j in model.joints:
        for body, s in zip(j.bodies, getattr(j, "points", ())):
            if body == GROUND:
                extent.append(np.array([s], dtype=float))
    allp = np.vstack(extent)
    scale = float(max(np.ptp(allp[:, 0]), np.ptp(allp[:, 1]), 1e-9))

    # a cam follower with no shape of its own (all its points coincide) gets a stem along
    # its slide axis, pointing away from the cam
    for c in cams:
        bc, bf = c.bodies
        if bf == GROUND or len(_hull(np.array(local[bf]))) != 1:
            continue
        v = np.array(_slide_axis(model, bf) or (0.0, 0.0))
        if not v.any():
            continue
        v = v / np.hypot(*v)
        gv = full.turn(bf, v)[0]
        away = full.place(bf, c.follower[:2])[0] - full.place(bc, (0.0, 0.0))[0]
        if float(gv @ away) < 0.0:
            v = -v
        f = np.array(c.follower[:2], dtype=float)
        stem = 0.35 * scale + (c.follower[2] if c.follower_kind == "roller" else 0.0)
        local[bf].append(tuple(f + stem * v))

    def shade_of(body: str, k: int) -> Any:
        if stopped and k == m - 1:
            return STOP_COLOUR
        f = 1.0 if m == 1 else 0.25 + 0.75 * k / (m - 1)
        return _shade(colours[body], f)

    last_normal = m - 2 if stopped else m - 1  # the snapshot that carries the labels

    def z(k: int) -> float:
        return 2.0 + k / max(m, 1)

    # ---- translational guides (a line along the axis of body i covering the slide)
    for j in model.joints:
        if not isinstance(j, Translational):
            continue
        bi, bj = j.bodies
        pi_, pj = full.place(bi, j.points[0]), full.place(bj, j.points[1])
        u = full.turn(bi, j.axes[0])
        u /= np.linalg.norm(u, axis=1)[:, None]
        s = np.einsum("ij,ij->i", pj - pi_, u)
        lo, hi = s.min() - 0.15 * scale, s.max() + 0.15 * scale
        if bi == GROUND:
            nrm = np.array([-u[0, 1], u[0, 0]])
            for side in (1.0, -1.0):
                off = side * 0.045 * scale * nrm
                a, b = pi_[0] + lo * u[0] + off, pi_[0] + hi * u[0] + off
                ax.plot([a[0], b[0]], [a[1], b[1]], color=_GROUND_COLOUR, lw=1.8,
                        solid_capstyle="butt", zorder=1.0)
                _hatch_line(ax, a, b, scale, side * nrm)
        else:
            ps, us = snap.place(bi, j.points[0]), snap.turn(bi, j.axes[0])
            us /= np.linalg.norm(us, axis=1)[:, None]
            for k in range(m):
                a, b = ps[k] + lo * us[k], ps[k] + hi * us[k]
                ax.plot([a[0], b[0]], [a[1], b[1]], color=shade_of(bi, k), lw=1.2, ls="--",
                        zorder=z(k) - 0.5)

    # ---- traced paths over the whole run
    for i, (body, s) in enumerate(tr):
        path = result.point(body, s)
        ax.plot(path[:, 0], path[:, 1], color="k", lw=1.0, ls=(0, (4, 2)) if i else "-",
                alpha=0.8, zorder=1.5, label=f"path of {body} ({s[0]:g}, {s[1]:g})")

    # ---- bodies at the snapshots
    cam_bodies = {c.bodies[0] for c in cams}
    for body in [b.name for b in model.bodies]:
        hull = _hull(np.array(local[body]))
        axis = _body_axis(model, body)
        for k in range(m):
            col = shade_of(body, k)
            label = body if k == last_normal else None
            if len(hull) >= 3:
                g = snap.place_many(body, hull, k)
                ax.fill(g[:, 0], g[:, 1], color=col, alpha=0.3 if k >= last_normal else 0.1,
                        lw=0, zorder=z(k))
                g = np.vstack([g, g[:1]])
                ax.plot(g[:, 0], g[:, 1], color=col, lw=2.0, zorder=z(k), label=label)
            elif len(hull) == 2:
                g = snap.place_many(body, hull, k)
                ax.plot(g[:, 0], g[:, 1], color=col, lw=3.5, solid_capstyle="round",
                        zorder=z(k), label=label)
            elif body not in cam_bodies:
                # a body with a single attachment point (a slider): a small block
                w, h = 0.10 * scale, 0.06 * scale
                blk = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2
                c, sn = np.cos(axis), np.sin(axis)
                blk = blk @ np.array([[c, sn], [-sn, c]]) + hull[0]
                g = snap.place_many(body, blk, k)
                ax.fill(g[:, 0], g[:, 1], facecolor=_shade(col, 0.45), edgecolor=col, lw=1.5,
                        zorder=z(k), label=label)
            o = snap.place(body, (0.0, 0.0))[k]
            ax.plot(*o, marker="+", ms=5, color=col, zorder=z(k) + 0.01)

    # ---- cams and followers
    shaped = {b for b in local if len(_hull(np.array(local[b]))) > 1}  # labelled above
    for c in cams:
        bc, bf = c.bodies
        pr = profiles[c.name]
        fpt = snap.place(bf, c.follower[:2])
        for k in range(m):
            col = shade_of(bc, k) if bc != GROUND else _GROUND_COLOUR
            g = snap.place_many(bc, pr, k)
            ax.fill(g[:, 0], g[:, 1], color=col, alpha=0.25 if k >= last_normal else 0.07,
                    lw=0, zorder=z(k) - 0.2)
            lab = bc if (bc != GROUND and k == last_normal and bc not in shaped) else None
            ax.plot(g[:, 0], g[:, 1], color=col, lw=1.8, zorder=z(k) - 0.1, label=lab)
            fcol = shade_of(bf, k) if bf != GROUND else _GROUND_COLOUR
            if c.follower_kind == "roller":
                r = c.follower[2]
                a = np.linspace(0.0, 2 * np.pi, 73)
                ax.plot(fpt[k, 0] + r * np.cos(a), fpt[k, 1] + r * np.sin(a), color=fcol,
                        lw=1.8, zorder=z(k) + 0.1)
            elif c.follower_kind == "flat":
                nrm = snap.turn(bf, c.follower[2:])[k]
                nrm /= np.linalg.norm(nrm)
                tan = np.array([-nrm[1], nrm[0]])
                half = 0.35 * scale
                a, b = fpt[k] - half * tan, fpt[k] + half * tan
                ax.plot([a[0], b[0]], [a[1], b[1]], color=fcol, lw=3.0,
                        solid_capstyle="butt", zorder=z(k) + 0.1)
            else:
                ax.plot(*fpt[k], marker="o", ms=4, color=fcol, zorder=z(k) + 0.1)
        ai = _alpha_column(result, c)
        if ai is not None:
            cp = np.vstack([snap.place_many(bc, _profile_points(c, result.q[[r], ai]), k)
                            for k, r in enumerate(rows)])
            ax.plot(cp[:, 0], cp[:, 1], ls="none", marker="o", ms=3.5, mfc="k", mec="k",
                    zorder=z(m) + 0.2)

    # ---- joints: pins, ground pivots
    for j in model.joints:
        if not isinstance(j, Revolute):
            continue
        on_ground = GROUND in j.bodies
        for k in range(m):
            body = j.bodies[1] if j.bodies[0] == GROUND else j.bodies[0]
            s = j.points[j.bodies.index(body)]
            p = snap.place(body, s)[k]
            ax.plot(*p, marker="o", ms=5.5, mfc="white", mec=shade_of(body, k), mew=1.4,
                    zorder=z(k) + 0.3)
        if on_ground:
            g = np.asarray(j.points[j.bodies.index(GROUND)], dtype=float)
            _ground_pivot(ax, g, scale)

    # ---- traced points at the snapshots
    for body, s in tr:
        p = snap.place(body, s)
        for k in range(m):
            ax.plot(*p[k], marker="o", ms=4, color=shade_of(body, k), zorder=z(k) + 0.3)

    # ---- where an incomplete run stopped
    if stopped:
        t_last = result.t[-1]
        ax.plot([], [], color=STOP_COLOUR, lw=3,
                label=f"last configuration, t = {t_last:.6g} s (run stopped)")
        pts = [snap.place(b, s)[m - 1] for b, ss in local.items() for s in ss]
        top = max(pts, key=lambda p: p[1])
        ax.annotate(f"last configuration:\nrun stopped after t = {t_last:.6g} s",
                    xy=top, xytext=(0, 28), textcoords="offset points", ha="center",
                    va="bottom", color=STOP_COLOUR, fontsize=9,
                    arrowprops={"arrowstyle": "->", "color": STOP_COLOUR}, zorder=10)

    if title is None:
        span = f"t = {result.t[0]:.4g} .. {result.t[-1]:.4g} s"
        title = f"{model.name}: {m} snapshot{'s' if m > 1 else ''}, {span}"
    ax.set_title(title)
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.08)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.grid(True, lw=0.4, alpha=0.4)
    ax.legend(loc="best", fontsize=8, framealpha=0.85)
    return ax


def _alpha_column(result: "KinematicsResult", cam: Cam) -> int | None:
    name = f"{cam.name}.alpha"
    names = list(getattr(result, "coordinate_names", []))
    return names.index(name) if name in names else None


def _slide_axis(model: Any, body: str) -> tuple[float, float] | None:
    """The axis, in the body frame, of the first translational joint of body; None if none."""
    for j in model.joints:
        if isinstance(j, Translational) and body in j.bodies:
            v = j.axes[j.bodies.index(body)]
            return (float(v[0]), float(v[1]))
    return None


def _body_axis(model: Any, body: str) -> float:
    """Angle in the body frame of its slide axis (for drawing blocks); 0 if none."""
    v = _slide_axis(model, body)
    return 0.0 if v is None else float(np.arctan2(v[1], v[0]))


def _hatch_line(ax: "Axes", a: np.ndarray, b: np.ndarray, scale: float,
                nrm: np.ndarray) -> None:
    """Short hatch ticks on the nrm side of a fixed guide from a to b."""
    d = b - a
    length = float(np.hypot(*d))
    if length == 0.0:
        return
    u = d / length
    h = 0.025 * scale
    for s in np.arange(h, length + 1e-12, 2 * h):
        p = a + s * u
        q = p + h * nrm - h * u
        ax.plot([p[0], q[0]], [p[1], q[1]], color=_GROUND_COLOUR, lw=0.8, zorder=0.9)


def _ground_pivot(ax: "Axes", g: np.ndarray, scale: float) -> None:
    """A hatched triangle under a ground pivot at g."""
    d = 0.035 * scale
    tri = np.array([g, g + [-d, -1.6 * d], g + [d, -1.6 * d]])
    ax.fill(tri[:, 0], tri[:, 1], facecolor="0.85", edgecolor=_GROUND_COLOUR, lw=1.2,
            zorder=1.2)
    y0 = g[1] - 1.6 * d
    ax.plot([g[0] - 1.5 * d, g[0] + 1.5 * d], [y0, y0], color=_GROUND_COLOUR, lw=1.5,
            zorder=1.2)
    for x in np.linspace(g[0] - 1.3 * d, g[0] + 1.5 * d, 5):
        ax.plot([x, x - 0.6 * d], [y0, y0 - 0.6 * d], color=_GROUND_COLOUR, lw=0.8,
                zorder=1.2)


# ---------------------------------------------------------------------------- time series
def plot_timeseries(result: "KinematicsResult",
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
    fig = _new_figure((11.0, 8.0))
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
                       color=_PALETTE[result.body_names.index(names[k]) % len(_PALETTE)],
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


# ---------------------------------------------------------------------------- files
def save_figures(result: "KinematicsResult", stem: str | Path,
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


__all__ = ["plot_mechanism", "plot_timeseries", "save_figures"]
