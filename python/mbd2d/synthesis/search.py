"""Multi-start synthesis: Latin-hypercube starts in the bounds, screened by one evaluation
each, then a local least-squares solve (``scipy.optimize.least_squares``, trust-region
reflective, with the exact Jacobian) from each of the best defect-free ones; every solve goes
through :func:`run_all`, the executor seam (serial, a local process pool, or a Dask
client's ``map``/``gather``).
"""
from __future__ import annotations

import math
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..errors import ModelError
from ..studies.runner import _context, cores
from ..validate import whole
from .problem import Evaluation, Problem
from .tasks import Task
from .terms import Term


# ===================================================================== the executor seam
def run_all(fn: Callable[[Any], Any], items: Sequence[Any], client: Any = None,
            workers: int | None = 1) -> list[Any]:
    """fn over items, results in order: THE one place where synthesis spreads work.

    ``client``: a Dask distributed client (anything with ``map`` and ``gather``: the client
    :func:`mbd2d.sweep` takes, or :func:`mbd2d.studies.connect`'s) or a
    ``concurrent.futures`` executor (``submit``); without one, ``workers`` local processes
    (1: in this process; None: every core, as a sweep), started as the sweeps start theirs.
    """
    items = list(items)
    if client is not None:
        if hasattr(client, "map") and hasattr(client, "gather"):
            return list(client.gather(client.map(fn, items, pure=False)))
        if hasattr(client, "submit"):
            return [f.result() for f in [client.submit(fn, it) for it in items]]
        raise ModelError("client must be a Dask client (map, gather) or a concurrent.futures "
                         "executor (submit)", "synthesize")
    n = cores() if workers is None else int(workers)
    if n <= 1 or len(items) <= 1:
        return [fn(it) for it in items]
    with ProcessPoolExecutor(max_workers=min(n, len(items)), mp_context=_context()) as pool:
        return list(pool.map(fn, items))


# ===================================================================== results
@dataclass
class StartRecord:
    """One local solve: where it started and ended, and how."""

    start: np.ndarray
    x: np.ndarray
    error: float
    objective: float
    nfev: int
    njev: int
    status: str
    defects: list[str]
    seconds: float
    trace: list[float] = field(default_factory=list)


@dataclass
class SynthesisResult:
    """The outcome of :func:`synthesize`.

    Attributes
    ----------
    model : Model
        The best defect-free design (an ordinary model: every analysis and picture applies;
        its q0 estimates are the designed branch's configuration at t_ref).
    objective : float
        Sum of squares of all residuals (task and penalties) of the best design.
    error : float
        The task error: sum of squared distances to the targets (the synthesis literature's
        measure for path generation).
    residuals : numpy.ndarray
        The error per target (a distance for points and poses, |difference| for functions).
    values : dict
        The free design variables of the best design by name.
    times : numpy.ndarray
        The target times (driver inputs) of the best design.
    history : list of StartRecord
        Every local solve, best first.
    rejected : list of (numpy.ndarray, list of str)
        Candidates rejected in the screening and at the end of solves, with the reasons.
    terms : dict
        What the constraints watch, at the best design (transmission angle, peak effort...).
    seconds : float
        Wall-clock time of the whole synthesis.
    names : list of str
        The design vector's names.
    """

    model: Any
    objective: float
    error: float
    residuals: np.ndarray
    values: dict[str, float]
    times: np.ndarray
    history: list[StartRecord]
    rejected: list[tuple[np.ndarray, list[str]]]
    terms: dict[str, float]
    seconds: float
    names: list[str]
    task: Any = None

    @property
    def defect_reasons(self) -> dict[str, int]:
        """How often each kind of defect rejected a candidate (the reason's text up to its
        first colon)."""
        out: dict[str, int] = {}
        for _, reasons in self.rejected:
            for r in reasons:
                key = r.split(":")[0]
                out[key] = out.get(key, 0) + 1
        return out

    def __repr__(self) -> str:
        return (f"SynthesisResult(error {self.error:.6g}, {len(self.history)} local solves, "
                f"{len(self.rejected)} rejected, {self.seconds:.2f} s)")


# ===================================================================== the search
def latin_hypercube(n: int, lo: np.ndarray, hi: np.ndarray, seed: int | None
                    ) -> np.ndarray:
    """n points of a Latin hypercube in the box [lo, hi] (each coordinate's range cut into
    n strata, one point in each, strata paired at random)."""
    rng = np.random.default_rng(seed)
    d = len(lo)
    u = (rng.permuted(np.tile(np.arange(n), (d, 1)), axis=1).T + rng.random((n, d))) / n
    return lo + u * (hi - lo)


def _screen(job: tuple[Problem, np.ndarray]) -> list[Evaluation]:
    """Strict evaluations of starting points, their free times first moved to where the
    candidate passes the targets best."""
    problem, xs = job
    return [problem.evaluate(problem.seed_timing(x), jac=False) for x in xs]


def local_solve(job: tuple[Problem, np.ndarray, np.ndarray | None, int]) -> tuple[
        StartRecord, Evaluation]:
    """One local least-squares solve from x0 (its q0 continuation starts at q_ref)."""
    from scipy.optimize import least_squares

    problem, x0, q_ref, max_nfev = job
    t0 = time.perf_counter()
    state: dict[str, Any] = {"q": q_ref, "last": None}
    trace: list[float] = []

    def ev_at(x: np.ndarray) -> Evaluation:
        last = state["last"]
        if last is not None and np.array_equal(last.x, x):
            return last
        ev = problem.evaluate(x, state["q"], jac=True, strict=False)
        if ev.ok:
            state["q"] = ev.q_ref
            trace.append(ev.objective)
        state["last"] = ev
        return ev

    def fun(x: np.ndarray) -> np.ndarray:
        ev = ev_at(x)
        if not ev.ok:       # a rejected candidate: least_squares shrinks its step
            return np.full(problem.m, np.nan)
        return ev.r

    def jac(x: np.ndarray) -> np.ndarray:
        ev = ev_at(x)
        return ev.jac if ev.ok else np.zeros((problem.m, len(x)))

    first = ev_at(x0)
    if not first.ok:
        return (StartRecord(x0, x0, math.inf, math.inf, 1, 0, "rejected start", first.defects,
                            time.perf_counter() - t0), first)
    problem.m = len(first.r)
    lo, hi = problem.lo, problem.hi
    x_start = np.clip(x0, lo, hi)
    nfev = njev = 0
    for cycle in range(3):      # free timing: re-seed the times from the design, solve again
        sol = least_squares(fun, x_start, jac=jac, bounds=(lo, hi), method="trf",
                            x_scale="jac", max_nfev=max_nfev, xtol=1e-12, ftol=1e-12,
                            gtol=1e-10)
        nfev, njev = nfev + int(sol.nfev), njev + int(sol.njev or 0)
        if problem.task.timing.times is not None or cycle == 2:
            break
        seeded = problem.seed_timing(sol.x)
        if np.array_equal(seeded, sol.x):
            break
        trial = problem.evaluate(seeded, state["q"], jac=False, strict=False)
        if not trial.ok or trial.objective >= 2.0 * sol.cost:
            break
        x_start = seeded
    final = problem.evaluate(sol.x, state["q"], jac=False)
    status = {0: "max evaluations", 1: "gtol", 2: "ftol", 3: "xtol", 4: "ftol and xtol"}.get(
        sol.status, str(sol.status))
    return (StartRecord(x0, sol.x, final.error, final.objective, nfev, njev, status,
                        final.defects, time.perf_counter() - t0, trace), final)


def synthesize(model: Any, free: Sequence[str], task: Task,
               bounds: Mapping[str, Any] | None = None,
               constraints: Sequence[Term] | None = None, starts: int = 8,
               client: Any = None, workers: int | None = 1, screen: int = 8, rounds: int = 8,
               seed: int | None = 0, max_nfev: int = 200, resolution: int = 72,
               t_ref: float | None = None, verify: int = 4) -> SynthesisResult:
    """Fit a mechanism to a task: the best defect-free values of the free parameters.

    Parameters
    ----------
    model : Model
        The starting model: its topology, a first guess, and q0 estimates at t_ref on the
        wanted assembly branch.
    free : list of str
        Names of the model parameters to vary (``model.parameters()``) and of task variables
        (``path.point.0``, ``path.point.1``: the tracer point); free timing variables
        (``path.t.0``, ``path.dt.i``, ``path.t_shift``) join by themselves.
    task : PathTask, MotionTask or FunctionTask
        What the mechanism must do.
    bounds : mapping name -> (lo, hi)
        Bounds of the free variables; every model parameter needs them when starts > 1 (the
        Latin hypercube is drawn in them).
    constraints : list of Term
        :class:`Grashof` (rejects), :class:`LinkRatio`, :class:`TransmissionAngle`,
        :class:`PeakEffort` (penalties).
    starts : int
        Number of local solves K: the starting model, then the K - 1 best defect-free points
        of a Latin hypercube of (K - 1) * screen points.
    client : Dask client or concurrent.futures executor, optional
        Spreads the screening and the local solves (see :func:`run_all`).
    workers : int, optional
        Local processes when no client is given (default 1: in this process).
    screen : int
        Latin-hypercube points per start in a round of screening.
    rounds : int
        Rounds of screening at most, until K - 1 defect-free points are found.
    seed : int, optional
        Seed of the Latin hypercube.
    max_nfev : int
        Evaluations per local solve.
    resolution : int
        Continuation steps per task span in every kinematic run.
    t_ref : float, optional
        Time at which the q0 estimates hold (default the task span's start).
    verify : int
        The best design is re-checked with ``verify`` times finer runs; one that fails is
        dropped for the next best.

    Returns
    -------
    SynthesisResult

    Raises
    ------
    ModelError
        For unknown names, missing bounds, or when no defect-free design is found (the
        message counts the defects met).

    Examples
    --------
    >>> import mbd2d
    >>> from mbd2d.synthesis import PathTask, fourbar
    >>> m = fourbar([[0, 0], [3, 0]], crank=1, coupler=3, rocker=2.5)   # doctest: +SKIP
    >>> task = PathTask("coupler", (1.5, 1.0), targets=[[1, 2], [2, 2.5], [3, 2.3]])
    >>> res = mbd2d.synthesize(m, free=["joint.B.points.0.0"], task=task,
    ...                        bounds={"joint.B.points.0.0": (2, 4)}, starts=1)  # doctest: +SKIP
    """
    t_start = time.perf_counter()
    try:
        import scipy.optimize  # noqa: F401  (the local solver)
    except ImportError:
        raise ModelError("mbd2d.synthesize needs scipy (pip install 'mbd2d[synthesis]')",
                         "synthesize") from None
    k = whole(starts, "starts", "synthesize", 1, 100000)
    problem = Problem(model, free, task, bounds, constraints, resolution, t_ref)
    rejected: list[tuple[np.ndarray, list[str]]] = []
    xs = [problem.x0]
    if k > 1:
        if not (np.isfinite(problem.lo).all() and np.isfinite(problem.hi).all()):
            missing = [n for n, a, b in zip(problem.names, problem.lo, problem.hi)
                       if not (math.isfinite(a) and math.isfinite(b))]
            raise ModelError(f"starts > 1 draws starting points in the bounds: give bounds "
                             f"for {', '.join(missing)}", "synthesize")
        good: list[Evaluation] = []
        for round_ in range(max(1, int(rounds))):      # until K - 1 defect-free points
            cand = latin_hypercube((k - 1) * max(1, int(screen)), problem.lo,
                                   problem.draw_hi, None if seed is None else seed + round_)
            chunks = np.array_split(cand, max(1, min(len(cand), 4 * (workers or 1))))
            evs = [e for part in run_all(_screen, [(problem, c) for c in chunks if len(c)],
                                         client, workers) for e in part]
            good += [e for e in evs if e.ok]
            rejected += [(e.x, e.defects) for e in evs if not e.ok]
            if len(good) >= k - 1:
                break
        good.sort(key=lambda e: e.objective)
        xs += [e.x for e in good[:k - 1]]
    jobs = [(problem, x, None, max_nfev) for x in xs]
    outs = run_all(local_solve, jobs, client, workers)
    history = sorted((rec for rec, _ in outs), key=lambda r: r.objective)
    for rec, ev in outs:
        if not ev.ok:
            rejected.append((rec.x, ev.defects))
    finals = sorted((ev for _, ev in outs if ev.ok), key=lambda e: e.objective)
    best = _verified(problem, finals, verify, rejected)
    if best is None:
        reasons = {}
        for _, rs in rejected:
            for r in rs:
                reasons[r.split(":")[0]] = reasons.get(r.split(":")[0], 0) + 1
        raise ModelError(f"no defect-free design found in {len(xs)} start(s); defects met: "
                         + (", ".join(f"{n} x{c}" for n, c in reasons.items()) or "none")
                         + ". Widen the bounds, add starts, or check the task.", "synthesize")
    _, z = problem.split(best.x)
    assert best.r is not None and best.times is not None
    return SynthesisResult(model=best.model, objective=best.objective, error=best.error,
                           residuals=task.errors(best.r[:best.n_task]),
                           values=dict(zip(problem.names, map(float, best.x))),
                           times=best.times, history=history, rejected=rejected,
                           terms=best.terms, seconds=time.perf_counter() - t_start,
                           names=problem.names, task=task)


def _verified(problem: Problem, finals: list[Evaluation], verify: int,
              rejected: list[tuple[np.ndarray, list[str]]]) -> Evaluation | None:
    """The best design that stays defect-free with ``verify`` times finer runs."""
    if verify <= 1:
        return finals[0] if finals else None
    fine = Problem.__new__(Problem)
    fine.__dict__.update(problem.__dict__)
    fine.resolution = problem.resolution * int(verify)
    for ev in finals:
        check = fine.evaluate(ev.x, ev.q_ref, jac=False)
        if check.ok:
            return ev
        rejected.append((ev.x, ["verification: " + d for d in check.defects]))
    return None


__all__ = ["synthesize", "SynthesisResult", "StartRecord", "run_all", "latin_hypercube",
           "local_solve"]
