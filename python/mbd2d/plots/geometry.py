"""Geometry of the pictures: body poses at output rows, body-local points placed with
r + A(theta) s, cam profile points from the core, and the checks of what to draw.

The pictures read a result through the small :class:`Motion` protocol (times, coordinates,
per-body histories and the model description), so this layer does not depend on the results
classes.
"""
from __future__ import annotations

from typing import Any, Protocol, Sequence

import numpy as np

from ..binding import core
from ..binding.status import error_for
from ..description.joints import PROFILE_KINDS, Cam, Revolute, Translational
from ..errors import ModelError
from ..validate import GROUND

TracePoint = tuple[str, tuple[float, float]]


class Motion(Protocol):
    """What the pictures read from a result (a :class:`~mbd2d.KinematicsResult` is one)."""

    t: np.ndarray
    q: np.ndarray
    body_names: list[str]
    coordinate_names: list[str]
    complete: bool
    model: Any

    def body(self, name: str) -> Any:
        """Histories x, y, theta (and derivatives) of a body, as attributes."""

    def point(self, name: str, s: Any) -> np.ndarray:
        """Global path (n, 2) of a point fixed in a body."""


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


def body_points(model: Any,
                trace: Sequence[TracePoint]) -> dict[str, list[tuple[float, float]]]:
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


def check_trace(result: Motion, trace: Any) -> list[TracePoint]:
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
            raise ModelError(f"entries must be (body_name, (sx, sy)), got {item!r}", "trace") \
                from None
        if body not in result.body_names:
            raise ModelError(f"no body {body!r}; bodies: {', '.join(result.body_names)}", "trace")
        out.append((str(body), (sx, sy)))
    return out


def snapshot_rows(result: Motion, times: Any) -> np.ndarray:
    """Output rows to draw: a few evenly spaced ones, or the rows nearest to times."""
    n = len(result.t)
    if times is None:
        k = min(n, 6)
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


def slide_axis(model: Any, body: str) -> tuple[float, float] | None:
    """The axis, in the body frame, of the first translational joint of body; None if none."""
    for j in model.joints:
        if isinstance(j, Translational) and body in j.bodies:
            v = j.axes[j.bodies.index(body)]
            return (float(v[0]), float(v[1]))
    return None


def body_axis(model: Any, body: str) -> float:
    """Angle in the body frame of its slide axis (for drawing blocks); 0 if none."""
    v = slide_axis(model, body)
    return 0.0 if v is None else float(np.arctan2(v[1], v[0]))
