"""Synthesis tasks: what the mechanism must do, as residuals at target times.

Each task names the body (and the point on it) it watches and its targets; it gives

- its own design variables (a tracer point's coordinates, the target times when the timing
  is free), named ``<kind>.point.0``, ``<kind>.t.0``, ``<kind>.dt.i``, ``<kind>.t_shift``;
- the target times and their derivatives with respect to those variables;
- the residuals at the targets and their exact derivatives, from the configuration q, the
  velocities q_dot and the sensitivities dq/dp at the target times (a point P = r + A(theta) s'
  of a body changes by dP = dr + B(theta) s' dtheta + A ds', and along time by
  dP/dt = r_dot + B s' theta_dot).

Free timing keeps the targets in order by construction: the first time and the positive gaps
between consecutive targets are the unknowns (t_i = t_0 + dt_1 + ... + dt_i).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..errors import ModelError
from ..results.points import PointResult
from ..validate import number

COORDINATE = {"x": 0, "y": 1, "theta": 2}


@dataclass(frozen=True)
class Variable:
    """A design variable of a task: name, starting value and default bounds."""

    name: str
    value: float
    lo: float = -math.inf
    hi: float = math.inf
    automatic: bool = False     #: free without being named in ``free`` (free timing)
    draw: float | None = None   #: upper end of the range the starting points are drawn in


@dataclass
class Rows:
    """The model's state at the target times: q, q_dot (n, nq) and dq/dp (n, nq, np)."""

    q: np.ndarray
    qd: np.ndarray
    dq: np.ndarray | None
    body_names: list[str]


def _array(v: Any, shape_tail: tuple[int, ...], what: str) -> np.ndarray:
    try:
        a = np.array(v, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what} must be numbers, got {v!r}", "task") from None
    if a.ndim != 1 + len(shape_tail) or a.shape[1:] != shape_tail or len(a) == 0:
        raise ModelError(f"{what} must have shape (n{''.join(f', {s}' for s in shape_tail)}), "
                         f"got {a.shape}", "task")
    if not np.isfinite(a).all():
        raise ModelError(f"{what} must be finite numbers", "task")
    return a


def body_point(rows: Rows, body: str, s: Sequence[float]
               ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray, np.ndarray]:
    """A body-fixed point at the rows: P (n, 2), dP/dp (n, 2, np) or None, dP/ds (n, 2, 2),
    dP/dt (n, 2)."""
    if body not in rows.body_names:
        raise ModelError(f"no body {body!r}; bodies: {', '.join(rows.body_names)}", "task")
    i = 3 * rows.body_names.index(body)
    th = rows.q[:, i + 2]
    c, sn = np.cos(th), np.sin(th)
    sx, sy = float(s[0]), float(s[1])
    a_s = np.column_stack([c * sx - sn * sy, sn * sx + c * sy])        # A s
    b_s = np.column_stack([-sn * sx - c * sy, c * sx - sn * sy])       # B s = dA/dtheta s
    p = rows.q[:, i:i + 2] + a_s
    dp = None
    if rows.dq is not None:
        dp = PointResult.derivatives((sx, sy), [rows.q[:, i:i + 3]],
                                     [rows.dq[:, i:i + 3, :]])[0]
    ds = np.empty((len(th), 2, 2))
    ds[:, 0, 0], ds[:, 0, 1], ds[:, 1, 0], ds[:, 1, 1] = c, -sn, sn, c
    dt = rows.qd[:, i:i + 2] + b_s * rows.qd[:, i + 2, None]
    return p, dp, ds, dt


@dataclass
class Timing:
    """Target times: prescribed (``times``), prescribed up to a free common shift
    (``shift=True``), or free (``times=None``: the first time and the gaps are unknowns).

    ``span`` = (lo, hi) bounds the times (and the first time when they are free);
    ``max_span`` bounds t_last - t_first for free timing (default hi - lo): a design that
    needs more than that to pass the targets in order has an order defect.
    """

    n: int
    times: np.ndarray | None = None
    shift: bool = False
    span: tuple[float, float] = (0.0, 2.0 * math.pi)
    max_span: float | None = None
    min_gap: float | None = None

    def variables(self, prefix: str) -> list[Variable]:
        lo, hi = self.span
        if self.times is None:
            gap = (hi - lo) / (2 * self.n)
            lo_gap = self.min_gap if self.min_gap is not None else 1e-3 * (hi - lo) / self.n
            out = [Variable(f"{prefix}.t.0", lo + gap, lo, hi, True)]
            out += [Variable(f"{prefix}.dt.{i}", gap, lo_gap, self.limit(), True,
                             self.limit() / (self.n - 1))
                    for i in range(1, self.n)]
            return out
        if self.shift:
            return [Variable(f"{prefix}.t_shift", 0.0, lo - float(self.times[0]),
                             hi - float(self.times[-1]), True)]
        return []

    def limit(self) -> float:
        return self.max_span if self.max_span is not None else self.span[1] - self.span[0]

    def times_of(self, z: dict[str, float], prefix: str) -> tuple[np.ndarray, dict[str,
                                                                               np.ndarray]]:
        """Times (n,) and d times / d variable for each timing variable."""
        if self.times is None:
            gaps = [z[f"{prefix}.t.0"]] + [z[f"{prefix}.dt.{i}"] for i in range(1, self.n)]
            t = np.cumsum(gaps)
            d = {f"{prefix}.t.0": np.ones(self.n)}
            for i in range(1, self.n):
                col = np.zeros(self.n)
                col[i:] = 1.0
                d[f"{prefix}.dt.{i}"] = col
            return t, d
        if self.shift:
            return self.times + z[f"{prefix}.t_shift"], {f"{prefix}.t_shift": np.ones(self.n)}
        return self.times.copy(), {}

    def order_penalty(self, z: dict[str, float], prefix: str, names: Sequence[str],
                      weight: float = 100.0, margin: float = 1e-3
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Free timing while solving: weight * (t_last - t_first - max_span + margin *
        max_span) when positive, with its derivative (the gaps' sum)."""
        if self.times is None and self.n > 1:
            total = sum(z[f"{prefix}.dt.{i}"] for i in range(1, self.n))
            excess = total - self.limit() * (1.0 - margin)
            row = np.array([f"{prefix}.dt." in n for n in names], float)
            if excess > 0:
                return np.array([weight * excess]), weight * row[None, :]
            return np.zeros(1), np.zeros((1, len(names)))
        return np.zeros(0), np.zeros((0, len(names)))

    def order_defect(self, t: np.ndarray) -> str | None:
        """The order defect of free timing: the targets need more than max_span."""
        if self.times is None and t[-1] - t[0] > self.limit() * (1 + 1e-12):
            return (f"order defect: passing the targets in order needs an input range of "
                    f"{t[-1] - t[0]:.6g} > {self.limit():.6g}")
        return None


def _timing(n: int, times: Any, shift: bool, span: Any, max_span: Any,
            min_gap: Any = None) -> Timing:
    t = None if times is None else _array(times, (), "times")
    if t is not None and len(t) != n:
        raise ModelError(f"{len(t)} times for {n} targets", "task")
    if t is not None and np.any(np.diff(t) < 0):
        raise ModelError("times must be in increasing order (the order the targets are met)",
                         "task")
    if span is None:
        span = (0.0, 2.0 * math.pi) if t is None or shift else (float(t[0]), float(t[-1]))
    lo, hi = (number(v, "span", "task") for v in span)
    if not hi > lo:
        raise ModelError(f"span must be (lo, hi) with hi > lo, got {span!r}", "task")
    if t is not None and not shift and (t[0] < lo or t[-1] > hi):
        raise ModelError(f"the times must lie in the span {lo:g} .. {hi:g}", "task")
    ms = None if max_span is None else number(max_span, "max_span", "task")
    mg = None if min_gap is None else number(min_gap, "min_gap", "task")
    return Timing(n, t, bool(shift) and t is not None, (lo, hi), ms, mg)


class Task:
    """Base of the tasks: timing, the point-on-body residual machinery, its variables."""

    kind = "task"
    timing: Timing
    per_target = 1

    def variables(self) -> list[Variable]:
        return self.timing.variables(self.kind)

    def target_times(self, z: dict[str, float]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        return self.timing.times_of(z, self.kind)

    def residuals(self, rows: Rows, z: dict[str, float]
                  ) -> tuple[np.ndarray, np.ndarray | None, dict[str, np.ndarray]]:
        """Residuals (m,), d/dp (m, np) and d/dz for each task variable (with the time
        derivative folded in through the timing)."""
        raise NotImplementedError

    def errors(self, r: np.ndarray) -> np.ndarray:
        """Error per target from the residuals (a distance for points)."""
        return np.linalg.norm(r.reshape(-1, self.per_target), axis=1)

    def _with_time(self, dz: dict[str, np.ndarray], rt: np.ndarray,
                   z: dict[str, float]) -> dict[str, np.ndarray]:
        """Fold dr/dt_i (n, per_target) into the timing variables."""
        _, dtdz = self.target_times(z)
        for name, col in dtdz.items():
            dz[name] = (rt * col[:, None]).ravel()
        return dz


@dataclass
class PathTask(Task):
    """Path generation: a point of a body passes through (or near) target points.

    Parameters
    ----------
    body : str
        The body that carries the tracer point (the coupler).
    point : (x, y)
        The tracer point in the body's frame (its starting value when ``path.point.0`` and
        ``path.point.1`` are in ``free``).
    targets : (n, 2) array
        Target points, in the order they are to be met.
    times : (n,) array, optional
        Prescribed timing: the model times (driver inputs) of the targets. Without them the
        timing is free (the first time and the gaps are unknowns, in order by
        construction).
    shift : bool
        The times are prescribed up to a common shift (a free unknown ``path.t_shift``).
    span : (lo, hi), optional
        The input range the times may take (default 0 .. 2 pi for free timing).
    max_span : float, optional
        Free timing: the largest t_last - t_first (default hi - lo; more is an order defect).
    cycle : float, optional
        The mechanism must also run defect-free over [t_first, t_first + cycle] (2 pi: the
        crank turns fully).
    """

    body: str
    point: Sequence[float]
    targets: Any
    times: Any = None
    shift: bool = False
    span: Any = None
    max_span: Any = None
    cycle: Any = None
    min_gap: Any = None
    kind = "path"
    per_target = 2

    def __post_init__(self) -> None:
        self.targets = _array(self.targets, (2,), "targets")
        self.point = tuple(float(v) for v in _array([self.point], (2,), "point")[0])
        self.timing = _timing(len(self.targets), self.times, self.shift, self.span,
                              self.max_span, self.min_gap)
        self.cycle = None if self.cycle is None else number(self.cycle, "cycle", "task")

    def variables(self) -> list[Variable]:
        return [Variable(f"path.point.{c}", self.point[c]) for c in range(2)] \
            + super().variables()

    def _point(self, z: dict[str, float]) -> tuple[float, float]:
        return (z.get("path.point.0", self.point[0]), z.get("path.point.1", self.point[1]))

    def residuals(self, rows: Rows, z: dict[str, float]
                  ) -> tuple[np.ndarray, np.ndarray | None, dict[str, np.ndarray]]:
        p, dp, ds, dt = body_point(rows, self.body, self._point(z))
        r = (p - self.targets).ravel()
        drdp = None if dp is None else dp.reshape(-1, dp.shape[2])
        dz = {f"path.point.{c}": ds[:, :, c].ravel() for c in range(2)}
        return r, drdp, self._with_time(dz, dt, z)

    def sample_cost(self, rows: Rows, z: dict[str, float]) -> np.ndarray:
        """Squared distance of every target (columns) to the tracer point at every row."""
        p, _, _, _ = body_point(rows, self.body, self._point(z))
        return ((p[:, None, :] - self.targets[None, :, :])**2).sum(axis=2)

    def curve(self, res: Any, z: dict[str, float]) -> np.ndarray:
        """The tracer point's path in a kinematics result (n, 2)."""
        return res.point(self.body, self._point(z))


@dataclass
class MotionTask(Task):
    """Motion generation: a body passes through target poses (x, y, theta) of one of its
    points. ``angle_weight`` (a length, default the targets' extent) converts the angle
    error into a length. Timing as in :class:`PathTask` (variables ``motion.*``)."""

    body: str
    point: Sequence[float]
    poses: Any
    times: Any = None
    shift: bool = False
    span: Any = None
    max_span: Any = None
    cycle: Any = None
    angle_weight: Any = None
    min_gap: Any = None
    kind = "motion"
    per_target = 3

    def __post_init__(self) -> None:
        self.poses = _array(self.poses, (3,), "poses")
        self.point = tuple(float(v) for v in _array([self.point], (2,), "point")[0])
        self.timing = _timing(len(self.poses), self.times, self.shift, self.span,
                              self.max_span, self.min_gap)
        self.cycle = None if self.cycle is None else number(self.cycle, "cycle", "task")
        if self.angle_weight is None:
            ext = np.ptp(self.poses[:, :2], axis=0).max() if len(self.poses) > 1 else 1.0
            self.angle_weight = float(ext) if ext > 0 else 1.0
        self.angle_weight = number(self.angle_weight, "angle_weight", "task")

    def variables(self) -> list[Variable]:
        return [Variable(f"motion.point.{c}", self.point[c]) for c in range(2)] \
            + super().variables()

    def sample_cost(self, rows: Rows, z: dict[str, float]) -> np.ndarray:
        """Squared pose error of every target (columns) at every row."""
        s = (z.get("motion.point.0", self.point[0]), z.get("motion.point.1", self.point[1]))
        p, _, _, _ = body_point(rows, self.body, s)
        th = rows.q[:, 3 * rows.body_names.index(self.body) + 2]
        dth = np.angle(np.exp(1j * (th[:, None] - self.poses[None, :, 2])))
        return ((p[:, None, :] - self.poses[None, :, :2])**2).sum(axis=2) \
            + (self.angle_weight * dth)**2

    def residuals(self, rows: Rows, z: dict[str, float]
                  ) -> tuple[np.ndarray, np.ndarray | None, dict[str, np.ndarray]]:
        s = (z.get("motion.point.0", self.point[0]), z.get("motion.point.1", self.point[1]))
        p, dp, ds, dt = body_point(rows, self.body, s)
        i = 3 * rows.body_names.index(self.body)
        th = rows.q[:, i + 2]
        dth = np.angle(np.exp(1j * (th - self.poses[:, 2])))
        w = self.angle_weight
        n = len(th)
        r = np.column_stack([p - self.poses[:, :2], w * dth]).ravel()
        drdp = None
        if dp is not None and rows.dq is not None:
            drdp = np.concatenate([dp, w * rows.dq[:, i + 2, None, :]], axis=1).reshape(
                3 * n, -1)
        dz = {}
        for c in range(2):
            col = np.zeros((n, 3))
            col[:, :2] = ds[:, :, c]
            dz[f"motion.point.{c}"] = col.ravel()
        rt = np.column_stack([dt, w * rows.qd[:, i + 2]])
        return r, drdp, self._with_time(dz, rt, z)


@dataclass
class FunctionTask(Task):
    """Function generation: a coordinate (x, y or theta) of a body follows target values at
    prescribed input times; with ``relative`` (default) its change from the first time
    follows the change of the targets (an output angle measured from where it starts)."""

    body: str
    coordinate: str
    times: Any
    values: Any
    relative: bool = True
    span: Any = None
    cycle: Any = None
    kind = "function"
    per_target = 1

    def __post_init__(self) -> None:
        if self.coordinate not in COORDINATE:
            raise ModelError(f"coordinate must be x, y or theta, got {self.coordinate!r}",
                             "task")
        self.values = _array(self.values, (), "values")
        self.timing = _timing(len(self.values), self.times, False, self.span, None)
        self.cycle = None if self.cycle is None else number(self.cycle, "cycle", "task")

    def residuals(self, rows: Rows, z: dict[str, float]
                  ) -> tuple[np.ndarray, np.ndarray | None, dict[str, np.ndarray]]:
        if self.body not in rows.body_names:
            raise ModelError(f"no body {self.body!r}", "task")
        j = 3 * rows.body_names.index(self.body) + COORDINATE[self.coordinate]
        out = rows.q[:, j]
        drdp = None if rows.dq is None else rows.dq[:, j, :].copy()
        if self.relative:
            r = (out - out[0]) - (self.values - self.values[0])
            if drdp is not None:
                drdp = drdp - drdp[0]
        else:
            r = out - self.values
        return r, drdp, {}

    def errors(self, r: np.ndarray) -> np.ndarray:
        return np.abs(r)


@dataclass
class TaskSpec:
    """A task as written in a task file (kind and keys), turned into a Task by
    :func:`make_task`."""

    kind: str
    keys: dict[str, Any] = field(default_factory=dict)


KINDS = {"path": PathTask, "motion": MotionTask, "function": FunctionTask}


def make_task(kind: str, /, **keys: Any) -> Task:
    """A task by its kind name ('path', 'motion', 'function') and keys.

    Raises
    ------
    ModelError
        For an unknown kind or key, or a malformed value.
    """
    if kind not in KINDS:
        raise ModelError(f"unknown task kind {kind!r}; kinds: {', '.join(KINDS)}", "task")
    cls = KINDS[kind]
    fields = set(cls.__dataclass_fields__)
    bad = set(keys) - fields
    if bad:
        raise ModelError(f"unknown key(s) {sorted(bad)} of a {kind} task; keys: "
                         f"{', '.join(sorted(fields))}", "task")
    try:
        return cls(**keys)
    except TypeError as exc:
        raise ModelError(f"{kind} task: {exc}", "task") from None


__all__ = ["Task", "PathTask", "MotionTask", "FunctionTask", "Timing", "Variable", "Rows",
           "body_point", "make_task", "KINDS"]
