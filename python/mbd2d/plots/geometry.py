"""Geometry of the pictures: body poses at output rows, body-local points placed with
r + A(theta) s, cam profile points and load values from the core, and the checks of what to
draw.

The pictures read a result through the small :class:`Motion` protocol (times, coordinates,
per-body histories and the model description), so this layer does not depend on the results
classes. :class:`Configuration` is a Motion of one configuration (a model before any run).
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Protocol

import numpy as np

from ..binding import core
from ..binding.status import error_for
from ..description.joints import PROFILE_KINDS, Cam
from ..errors import ModelError
from ..validate import GROUND

TracePoint = tuple[str, tuple[float, float]]


class Motion(Protocol):
    """What the pictures read from a result (a :class:`~mbd2d.KinematicsResult` is one).

    ``stats`` (a dict, optional) may hold ``singular_passages`` and ``dead_centre`` (times),
    marked on time axes; ``reaction(name)`` and ``effort(name)`` (optional, results with
    multipliers) give the reactions drawn as arrows and plotted against time.
    """

    t: np.ndarray
    q: np.ndarray
    body_names: list[str]
    coordinate_names: list[str]
    complete: bool
    model: Any

    def body(self, name: str) -> Any:
        """Histories x, y, theta (and derivatives) of a body, as attributes."""


class Configuration:
    """One configuration q of a model as a :class:`Motion` with one row (time t); or rows
    of configurations q (m, nq) at times t (m), a motion without velocities (a mode)."""

    def __init__(self, model: Any, q: Any, t: Any = 0.0, note: str = "") -> None:
        self.model = model
        self.t = np.atleast_1d(np.asarray(t, dtype=float)).copy()
        self.q = np.atleast_2d(np.asarray(q, dtype=float))
        self.qd = np.zeros_like(self.q)
        self.qdd = np.zeros_like(self.q)
        self.body_names = [b.name for b in model.bodies]
        self.coordinate_names = list(model.coordinate_names)
        self.complete = True
        self.stats: dict[str, Any] = {}
        self.note = note

    def body(self, name: str) -> Any:
        i = self.body_names.index(name)
        x, y, th = self.q[:, 3 * i], self.q[:, 3 * i + 1], self.q[:, 3 * i + 2]
        z = np.zeros(self.q.shape[0])
        return SimpleNamespace(x=x, y=y, theta=th, x_dot=z, y_dot=z, theta_dot=z, x_ddot=z,
                               y_ddot=z, theta_ddot=z)


class Poses:
    """Body poses at chosen output rows, with ground at the origin."""

    def __init__(self, result: Motion, rows: np.ndarray) -> None:
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


def profile_points(cam: Cam, alphas: np.ndarray) -> np.ndarray:
    """(n, 2) points c(alpha) of a cam profile in its body frame, from the core."""
    raw = np.ascontiguousarray(cam.profile, dtype=np.float64)
    a = np.ascontiguousarray(alphas, dtype=np.float64)
    out = core.profile(PROFILE_KINDS[cam.profile_kind], raw, a)
    if out.status != 0:
        raise error_for("profile", out.status, f"the core could not evaluate its profile: "
                        f"{out.msg}", entry=cam.describe())
    return np.asarray(out.pts).T


def function_values(f: Any, t: np.ndarray, entry: str) -> np.ndarray:
    """f(t) of a :class:`~mbd2d.TimeFunction` at the times t, from the core."""
    out = core.fun_values(np.ascontiguousarray(f.encode(), dtype=np.float64),
                          np.ascontiguousarray(t, dtype=np.float64))
    if out.status != 0:
        raise error_for("eval", out.status, out.msg, entry=entry)
    return np.asarray(out.f, dtype=float).copy()


def convex_hull(pts: np.ndarray) -> np.ndarray:
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


def check_trace(result: Motion, trace: Any) -> list[TracePoint]:
    if trace is None:
        return []
    out: list[TracePoint] = []
    if isinstance(trace, (str, bytes)) or not isinstance(trace, (list, tuple, np.ndarray)):
        raise ModelError(f"must be a list of (body_name, (sx, sy)), got {trace!r}", "trace")
    for item in trace:
        try:
            body, s = item
            sx, sy = float(s[0]), float(s[1])
            if len(s) != 2 or not (np.isfinite(sx) and np.isfinite(sy)):
                raise ValueError
        except (TypeError, ValueError):
            raise ModelError(f"entries must be (body_name, (sx, sy)), got {item!r}", "trace") \
                from None
        if body not in result.body_names:
            raise ModelError(f"no body {body!r}; bodies: {', '.join(result.body_names)}", "trace")
        out.append((str(body), (sx, sy)))
    return out


def snapshot_rows(result: Motion, times: Any, count: int = 6) -> np.ndarray:
    """Output rows to draw: ``count`` evenly spaced ones, or the rows nearest to times."""
    n = len(result.t)
    if times is None:
        k = min(n, count)
        rows = np.unique(np.round(np.linspace(0, n - 1, k)).astype(int))
    else:
        try:
            tt = np.atleast_1d(np.asarray(times, dtype=float))
        except (TypeError, ValueError):
            tt = np.zeros(0)
        if tt.ndim != 1 or tt.size == 0 or not np.all(np.isfinite(tt)):
            raise ModelError("must be a non-empty list of finite times", "times")
        lo, hi = result.t[0], result.t[-1]
        span = max(hi - lo, 1.0)
        bad = tt[(tt < lo - 1e-9 * span) | (tt > hi + 1e-9 * span)]
        if bad.size:
            raise ModelError(f"{bad.tolist()} are outside the result's span "
                             f"t = {lo:g} .. {hi:g} s", "times")
        rows = np.unique(np.abs(result.t[None, :] - tt[:, None]).argmin(axis=1))
    if not result.complete and rows[-1] != n - 1:
        rows = np.append(rows, n - 1)
    return rows


def frame_rows(result: Motion, fps: float, speed: float, max_frames: int) -> np.ndarray:
    """Rows shown by an animation at fps frames per second of the run's time divided by
    speed: the row nearest each frame's time, at most max_frames (evenly spaced), always the
    first and last."""
    n = len(result.t)
    span = float(result.t[-1] - result.t[0]) if n else 0.0
    want = int(round(fps * span / speed)) + 1 if span > 0 else 1
    k = max(2, min(want, max_frames, n)) if n > 1 else 1
    times = np.linspace(result.t[0], result.t[-1], k)
    rows = np.abs(result.t[None, :] - times[:, None]).argmin(axis=1)
    rows[0], rows[-1] = 0, n - 1
    return rows
