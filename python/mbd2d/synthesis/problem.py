"""One synthesis problem: the design vector (named model parameters and task variables), its
bounds, and the evaluation of a candidate — residuals, their exact Jacobian, and the defect
checks — through the ordinary kinematic analysis.

Evaluating a candidate x:

1. the model with the parameters of x (``with_params``), its q0 estimates those of the last
   good candidate at the reference time t_ref (continuation: the assembly stays on the branch
   the local solve started on);
2. the target times t_i (prescribed, shifted or free);
3. kinematic runs that reach every t_i by continuation from t_ref: one run on a grid that
   holds every t_i when the times are commensurate (equal steps), else one run per target.
   Each run gives q, q_dot and dq/dp at t_i (J dq/dp = -Phi_p, solved by the core);
4. defects: a dead centre (SingularConfigurationError), a passage through a singular
   configuration or a jump between steps (branch / circuit defect), targets out of order or
   beyond the input range (order defect), the Grashof type; a defect rejects the candidate;
5. residuals: the task's, then the penalty terms', with d/dp from the sensitivities and
   d/dt from the velocities.
"""
from __future__ import annotations

import dataclasses
import difflib
import math
import warnings
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from ..analysis.inverse import run_inverse
from ..analysis.kinematics import run_kinematics
from ..errors import (AnalysisError, ModelError, RedundantConstraintWarning,
                      SingularConfigurationError, SingularPassageWarning)
from ..validate import number
from .tasks import Rows, Task, Variable
from .terms import Term

#: largest change of a body angle between two output rows beyond what the velocities
#: explain (trapezoidal rule) before the rows count as a jump to another branch [rad]
JUMP = 0.25


@dataclass
class Evaluation:
    """A candidate's evaluation.

    Attributes
    ----------
    x : numpy.ndarray
        The design vector.
    defects : list of str
        Why the candidate is rejected (empty: defect-free).
    r : numpy.ndarray or None
        Residuals: the task's, then the penalty terms'.
    jac : numpy.ndarray or None
        dr/dx.
    n_task : int
        How many of the residuals are the task's.
    times : numpy.ndarray or None
        Target times.
    q_ref : numpy.ndarray or None
        Configuration at t_ref (the next candidate's q0 estimates).
    model : Model or None
        The candidate model, its q0 estimates the configuration at t_ref.
    """

    x: np.ndarray
    defects: list[str] = field(default_factory=list)
    r: np.ndarray | None = None
    jac: np.ndarray | None = None
    n_task: int = 0
    times: np.ndarray | None = None
    q_ref: np.ndarray | None = None
    model: Any = None
    terms: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not self.defects and self.r is not None

    @property
    def error(self) -> float:
        """The task error: sum of squared task residuals (inf when rejected)."""
        return float(self.r[:self.n_task] @ self.r[:self.n_task]) if self.ok else math.inf

    @property
    def objective(self) -> float:
        """Sum of squares of all residuals (task and penalties; inf when rejected)."""
        return float(self.r @ self.r) if self.ok else math.inf


class _Context:
    """What the terms see of a candidate: the model, the free parameter names, and the
    input-range runs (made on first use)."""

    def __init__(self, problem: "Problem", model: Any, t0: float, t1: float) -> None:
        self.problem, self.model, self.t0, self.t1 = problem, model, t0, t1
        self.pnames = problem.pnames
        self._rows: Rows | None = None
        self._res: Any = None
        self._inv: Any = None

    def range_run(self) -> Any:
        """The kinematic run over the input range, with sensitivities to the free
        parameters (when there are any)."""
        if self._res is None:
            self._res = self.problem.run(self.model, self.t0, self.t1,
                                         self.problem.steps(self.t1 - self.t0), sens=True)
        return self._res

    def range_rows(self) -> Rows:
        if self._rows is None:
            res = self.range_run()
            self._rows = Rows(res.q, res.qd, res.dq_dp if self.pnames else None,
                              res.body_names)
        return self._rows

    def inverse_run(self) -> Any:
        if self._inv is None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", SingularPassageWarning)
                self._inv = run_inverse(self.model, t0=self.t0, t_end=self.t1,
                                        steps=self.problem.steps(self.t1 - self.t0),
                                        sensitivities=self.pnames or None)
        return self._inv


class Problem:
    """The design vector of a synthesis and the evaluation of its candidates.

    Parameters
    ----------
    model : Model
        The starting model (topology, first guess, q0 estimates at t_ref).
    free : list of str
        Model parameter names (``model.parameters()``) and task variable names
        (``path.point.0`` ...) to vary; free timing variables join by themselves.
    task : Task
    bounds : mapping name -> (lo, hi)
    constraints : list of Term
    resolution : int
        Continuation steps per task span (default 72: 5 degrees of a crank turn).
    t_ref : float, optional
        Time at which the q0 estimates hold (default the task span's start).
    """

    def __init__(self, model: Any, free: Sequence[str], task: Task,
                 bounds: Mapping[str, Any] | None = None,
                 constraints: Sequence[Term] | None = None, resolution: int = 72,
                 t_ref: float | None = None) -> None:
        if not isinstance(task, Task):
            raise ModelError(f"task must be a PathTask, MotionTask or FunctionTask, got "
                             f"{type(task).__name__}", "synthesize")
        if isinstance(free, str) or not isinstance(free, Sequence):
            raise ModelError("free must be a list of parameter names", "synthesize")
        self.model, self.task = model, task
        self.constraints = list(constraints or [])
        for c in self.constraints:
            if not isinstance(c, Term):
                raise ModelError(f"constraints must be Grashof, LinkRatio, TransmissionAngle, "
                                 f"PeakEffort or MeasureBound terms, got {c!r}", "synthesize")
            c.check(model)
        params = model.parameters()
        tvars = {v.name: v for v in task.variables()}
        self.pnames = [n for n in free if n in params]
        named_t = [n for n in free if n in tvars]
        unknown = [n for n in free if n not in params and n not in tvars]
        if unknown:
            close = difflib.get_close_matches(str(unknown[0]), list(params) + list(tvars), n=3,
                                              cutoff=0.5)
            hint = f"; did you mean {', '.join(close)}?" if close else ""
            raise ModelError(f"unknown design variable {unknown[0]!r}{hint} (model parameters "
                             "are listed by model.parameters(); task variables: "
                             f"{', '.join(tvars)})", "synthesize")
        if len(set(free)) != len(free):
            raise ModelError("a design variable is named twice in free", "synthesize")
        self.tvars: list[Variable] = [tvars[n] for n in named_t] + [
            v for v in tvars.values() if v.automatic and v.name not in named_t]
        self.names = self.pnames + [v.name for v in self.tvars]
        if not self.names:
            raise ModelError("nothing to vary: free names no parameter and the task has no "
                             "free timing", "synthesize")
        self.x0 = np.array([float(params[n]) if params[n] is not None else 0.0
                            for n in self.pnames] + [v.value for v in self.tvars])
        self.lo, self.hi = self._bounds(bounds or {})
        # the box the starting points are drawn in (free gaps: so that they fit the span)
        self.draw_hi = self.hi.copy()
        for k, v in enumerate(self.tvars):
            if v.draw is not None:
                i = len(self.pnames) + k
                self.draw_hi[i] = min(self.hi[i], max(self.lo[i], v.draw))
        self.x0 = np.clip(self.x0, self.lo, self.hi)
        self.span = task.timing.span
        self.t_ref = float(self.span[0]) if t_ref is None else number(t_ref, "t_ref",
                                                                      "synthesize")
        self.resolution = int(resolution)
        self.q_start = np.array([b.q0 for b in model.bodies], float)
        self.m = 0      # number of residuals (set by the first good evaluation)

    # ------------------------------------------------------------------ setup
    def _bounds(self, bounds: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        if not isinstance(bounds, Mapping):
            raise ModelError("bounds must be a mapping {name: (lo, hi)}", "synthesize")
        extra = set(bounds) - set(self.names)
        if extra:
            raise ModelError(f"bounds for {sorted(extra)}, which are not free", "synthesize")
        lo = np.full(len(self.names), -math.inf)
        hi = np.full(len(self.names), math.inf)
        for k, v in enumerate(self.tvars):
            lo[len(self.pnames) + k], hi[len(self.pnames) + k] = v.lo, v.hi
        for name, b in bounds.items():
            if isinstance(b, (str, bytes)) or not isinstance(b, Sequence) or len(b) != 2:
                raise ModelError(f"bounds[{name!r}] must be (lo, hi)", "synthesize")
            a, c = (number(x, f"bounds[{name!r}]", "synthesize") for x in b)
            if not c > a:
                raise ModelError(f"bounds[{name!r}] = {b!r} needs lo < hi", "synthesize")
            k = self.names.index(name)
            lo[k], hi[k] = a, c
        return lo, hi

    def split(self, x: np.ndarray) -> tuple[dict[str, float], dict[str, float]]:
        """(model parameter values, task variable values) of a design vector."""
        n = len(self.pnames)
        return (dict(zip(self.pnames, map(float, x[:n]))),
                dict(zip(self.names[n:], map(float, x[n:]))))

    def steps(self, length: float) -> int:
        """Continuation steps over a time length."""
        h = (self.span[1] - self.span[0]) / self.resolution
        return max(1, int(math.ceil(length / h - 1e-9)))

    # ------------------------------------------------------------------ runs
    def run(self, model: Any, t0: float, t1: float, steps: int, sens: bool) -> Any:
        """One kinematic run (passage warnings silenced: passages are read from the
        result)."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SingularPassageWarning)
            warnings.simplefilter("ignore", RedundantConstraintWarning)
            return run_kinematics(model, t_end=t1, steps=steps, t0=t0,
                                  sensitivities=self.pnames if sens and self.pnames else None)

    def candidate(self, x: np.ndarray, q_ref: np.ndarray | None) -> Any:
        """The model of x with its q0 estimates q_ref (or the starting model's)."""
        pvals, _ = self.split(x)
        m = self.model.with_params(pvals) if pvals else _copy(self.model)
        return with_q0(m, self.q_start if q_ref is None else q_ref)

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, x: Any, q_ref: np.ndarray | None = None, jac: bool = True,
                 strict: bool = True) -> Evaluation:
        """Residuals, Jacobian (with ``jac``) and defects of the candidate x.

        With ``strict`` (screening, final checks) the order and Grashof conditions reject;
        without (inside a local solve) they act only through their penalties, so that the
        solver can slide along their boundary; the kinematic defects (dead centre, branch)
        always reject."""
        x = np.asarray(x, float)
        ev = Evaluation(x=x.copy())
        try:
            model = self.candidate(x, q_ref)
        except ModelError as exc:
            ev.defects.append(f"invalid design: {exc}")
            return ev
        _, z = self.split(x)
        t, _ = self.task.target_times(z)
        ev.times = t
        order = self.task.timing.order_defect(t)
        if order and strict:
            ev.defects.append(order)
        if t[0] < self.t_ref - 1e-12:
            ev.defects.append(f"the first target time {t[0]:.6g} is before t_ref = "
                              f"{self.t_ref:.6g}")
        if strict:
            for term in self.constraints:
                ev.defects += term.defects(_Context(self, model, t[0], t[-1]))
        if ev.defects:
            return ev
        try:
            rows, model, q_ref_new = self._rows(model, t, jac)
            ev.q_ref = q_ref_new
            ev.model = with_q0(model, q_ref_new)
            cycle = getattr(self.task, "cycle", None)
            t1 = t[0] + cycle if cycle else t[-1]
            if cycle:
                self._check(self.run(model, t[0], t1, self.steps(cycle), False), ev)
            r, drdp, dz = self.task.residuals(rows, z)
            ev.n_task = len(r)
            blocks_r, blocks_j = [r], [self._jac(drdp, dz, len(r))] if jac else []
            op, oj = self.task.timing.order_penalty(z, self.task.kind, self.names)
            if len(op):
                blocks_r.append(op)
                if jac:
                    blocks_j.append(oj)
            ctx = _Context(self, model, t[0], t1 if t1 > t[0] else t[0] + 1e-9)
            for term in self.constraints:
                tr, tj = term.residuals(ctx)
                if len(tr):
                    blocks_r.append(tr)
                    if jac:
                        full = np.zeros((len(tr), len(self.names)))
                        full[:, :len(self.pnames)] = tj
                        blocks_j.append(full)
                v = term.value(ctx)
                if v is not None:
                    ev.terms[term.label] = v
        except _Defect as d:
            ev.defects.append(str(d))
            return ev
        except SingularConfigurationError as exc:
            ev.defects.append(f"dead centre: at t = {exc.t:.6g} (a singular configuration in "
                              "the input range; the mechanism cannot be driven through it)")
            return ev
        except AnalysisError as exc:
            ev.defects.append(f"does not assemble or run: {type(exc).__name__}: "
                              f"{str(exc).split('. ')[0]}")
            return ev
        except ModelError as exc:
            ev.defects.append(f"invalid design: {exc}")
            return ev
        ev.r = np.concatenate(blocks_r)
        if not np.isfinite(ev.r).all():
            ev.defects.append("non-finite residuals")
            ev.r = None
            return ev
        if jac:
            ev.jac = np.vstack(blocks_j)
        return ev

    # ------------------------------------------------------------------ starting times
    def seed_timing(self, x: np.ndarray) -> np.ndarray:
        """x with its free (or shifted) target times moved to where the candidate's watched
        point passes the targets best: one run over the input range from t_ref, then the
        ordered assignment of targets to sampled times (free timing, by dynamic
        programming) or the best common shift. x unchanged when the timing is prescribed or
        the run fails."""
        timing = self.task.timing
        if timing.times is not None and not timing.shift:
            return x
        try:
            model = self.candidate(x, None)
            length = timing.limit() * 2 if timing.times is None else \
                self.span[1] - self.span[0]
            steps = 4 * self.steps(length)
            try:
                res = self.run(model, self.t_ref, self.t_ref + length, steps, False)
            except AnalysisError as exc:
                res = exc.results
            if res is None or len(res.t) < 3:
                return x
            _, z = self.split(x)
            rows = Rows(res.q, res.qd, None, res.body_names)
            zz = dict(z)
            for v in self.tvars:
                if ".t" in v.name or ".dt" in v.name:
                    zz.pop(v.name, None)
            # the residual per target at every sampled time
            cost = self.task.sample_cost(rows, zz)
        except (ModelError, AnalysisError):
            return x
        y = x.copy()
        n0 = len(self.pnames)
        idx = {n: n0 + k for k, n in enumerate(self.names[n0:])}
        kind = self.task.kind
        if timing.times is None:
            pick = ordered_assignment(cost, int(round(len(res.t) * timing.limit() / length)))
            if pick is None:
                return x
            t = res.t[pick]
            y[idx[f"{kind}.t.0"]] = t[0]
            for i in range(1, len(t)):
                y[idx[f"{kind}.dt.{i}"]] = max(t[i] - t[i - 1], self.lo[idx[f"{kind}.dt.{i}"]])
        else:
            h = res.t[1] - res.t[0]
            offs = np.round((timing.times - timing.times[0]) / h).astype(int)
            lo_s, hi_s = self.lo[idx[f"{kind}.t_shift"]], self.hi[idx[f"{kind}.t_shift"]]
            best, arg = math.inf, None
            for j in range(len(res.t) - offs[-1]):
                s = res.t[j] - timing.times[0]
                if lo_s <= s <= hi_s:
                    c = float(cost[j + offs, np.arange(len(offs))].sum())
                    if c < best:
                        best, arg = c, s
            if arg is None:
                return x
            y[idx[f"{kind}.t_shift"]] = arg
        return np.clip(y, self.lo, self.hi)

    def _jac(self, drdp: np.ndarray | None, dz: dict[str, np.ndarray], m: int) -> np.ndarray:
        j = np.zeros((m, len(self.names)))
        if self.pnames and drdp is not None:
            j[:, :len(self.pnames)] = drdp
        for k, name in enumerate(self.names[len(self.pnames):]):
            if name in dz:
                j[:, len(self.pnames) + k] = dz[name]
        return j

    def _check(self, res: Any, ev: Evaluation) -> None:
        """Branch defects of a completed run: singular passages, jumps between rows."""
        passages = res.stats.get("singular_passages", [])
        if passages:
            raise _Defect(f"branch (circuit) defect: passes a singular configuration at t = "
                          f"{passages[0]:.6g} (J lost rank; the branch is not certain)")
        if len(res.t) > 1:
            h = np.diff(res.t)
            k = np.arange(2, res.q.shape[1], 3)[:len(res.body_names)]
            th, w = res.q[:, k], res.qd[:, k]
            gap = np.abs(np.diff(th, axis=0) - 0.5 * h[:, None] * (w[1:] + w[:-1]))
            if gap.max() > JUMP:
                i = int(np.argmax(gap.max(axis=1)))
                raise _Defect(f"branch (circuit) defect: the configuration jumps between "
                              f"t = {res.t[i]:.6g} and {res.t[i + 1]:.6g}")

    def _rows(self, model: Any, t: np.ndarray, sens: bool) -> tuple[Rows, Any, np.ndarray]:
        """The state at the target times by continuation from t_ref; the model whose q0
        estimates hold at t[0]; the configuration at t_ref."""
        ev = Evaluation(x=np.zeros(0))
        grid = commensurate(t - t[0], self.steps(t[-1] - t[0]))
        if grid is not None and len(t) > 1:
            q_ref = None
            if t[0] > self.t_ref + 1e-12:
                pos = self.run(model, self.t_ref, t[0], self.steps(t[0] - self.t_ref), False)
                self._check(pos, ev)
                q_ref = pos.q[0]
                model = with_q0(model, pos.q[-1])
            steps, idx = grid
            res = self.run(model, t[0], t[-1], steps, sens)
            self._check(res, ev)
            if q_ref is None:
                q_ref = res.q[0]
            dq = res.dq_dp[idx] if sens and self.pnames else None
            return Rows(res.q[idx], res.qd[idx], dq, res.body_names), model, q_ref
        q, qd, dq = [], [], []
        q_ref, q_first, names = None, None, []
        for ti in t:
            if ti <= self.t_ref + 1e-12:
                res = self.run(model, self.t_ref, self.t_ref + 1e-9 * max(1.0, abs(ti)), 1,
                               sens)
                k = 0
            else:
                res = self.run(model, self.t_ref, ti, self.steps(ti - self.t_ref), sens)
                self._check(res, ev)
                k = -1
            q.append(res.q[k])
            qd.append(res.qd[k])
            if sens and self.pnames:
                dq.append(res.dq_dp[k])
            if q_ref is None:
                q_ref, q_first, names = res.q[0], res.q[k], res.body_names
        assert q_first is not None
        rows = Rows(np.array(q), np.array(qd), np.array(dq) if dq else None, names)
        return rows, with_q0(model, q[0]), q_ref


class _Defect(Exception):
    """A defect found in a run (raised inside the evaluation only)."""


def commensurate(offsets: np.ndarray, min_steps: int, max_steps: int = 4000
                 ) -> tuple[int, np.ndarray] | None:
    """A uniform grid over [0, offsets[-1]] holding every offset as a row: (steps, row
    indices), steps >= min_steps, or None when no grid up to max_steps does."""
    total = float(offsets[-1])
    if total <= 0.0:
        return None
    frac = offsets / total
    for m in range(1, max_steps + 1):
        k = frac * m
        if np.all(np.abs(k - np.round(k)) < 1e-9 * m):
            mult = max(1, int(math.ceil(min_steps / m)))
            if m * mult > max_steps:
                return None
            return m * mult, np.round(k).astype(int) * mult
        if m > 720:
            break
    return None


def ordered_assignment(cost: np.ndarray, window: int) -> np.ndarray | None:
    """Rows k_0 < k_1 < ... (one per column of cost (samples, targets)) with k_last - k_0 <=
    window that minimise the summed cost (dynamic programming for each first row f:
    acc_i[k] = cost[k, i] + min_{j < k} acc_{i-1}[j])."""
    m, n = cost.shape
    best, pick = math.inf, None
    for f in range(max(1, m - window)):
        c = cost[f:min(m, f + window + 1)]
        idx = np.arange(len(c))
        acc = c[:, 0].copy()
        back = []
        for i in range(1, n):
            run = np.minimum.accumulate(acc)
            arg = np.maximum.accumulate(np.where(acc <= run, idx, 0))
            prev = np.concatenate([[math.inf], run[:-1]])      # min over j < k
            back.append(np.concatenate([[0], arg[:-1]]))
            acc = prev + c[:, i]
        k = int(np.argmin(acc))
        if acc[k] < best:
            rows = [k]
            for arg in reversed(back):
                rows.append(int(arg[rows[-1]]))
            best, pick = float(acc[k]), f + np.array(rows[::-1])
    return pick


def with_q0(model: Any, q: Any) -> Any:
    """A shallow copy of the model whose bodies have the q0 estimates q (nb, 3)."""
    nb = len(model.bodies)
    q = np.asarray(q, float).ravel()[:3 * nb].reshape(nb, 3)
    new = _copy(model)
    new.bodies = [dataclasses.replace(b, q0=tuple(float(v) for v in qi))
                  for b, qi in zip(model.bodies, q)]
    return new


def _copy(model: Any) -> Any:
    new = model.__class__.__new__(model.__class__)
    new.__dict__.update(model.__dict__)
    new.bodies = list(model.bodies)
    return new


__all__ = ["Problem", "Evaluation", "commensurate", "with_q0"]
