"""The analysis front door: settings checks, the one call into the core, and the mapping
of the core's status to results, warnings or typed exceptions."""
from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _core
from .errors import (AssemblyError, ConvergenceError, CoreError, InconsistentConstraintsError,
                     InsufficientMemoryError, ModelError, RedundantConstraintWarning,
                     SingularConfigurationError, SingularJacobianError, SingularPassageWarning)
from .pack import Packed, decode, pack
from .results import KinematicsResult
from .validate import is_number, number, whole

if TYPE_CHECKING:  # pragma: no cover
    from .model import Model

# status codes of mbd_status.f90
OK, SINGULAR, NO_CONVERGENCE, SINGULAR_CONFIG, ASSEMBLY_FAILED, LAPACK, INCONSISTENT = range(7)
BAD_COUNT = -4
NO_MEMORY = 10         # an allocation failed or would not fit (mbd_memory.f90)
MAX_STEPS = 10**9      # output rows are held in memory; the core counts in 32-bit integers
MIN_TOL = 1e-15        # below this a residual test cannot pass in double precision


def check_span(t0: Any, t_end: Any, steps: Any) -> tuple[float, float, int]:
    """Validate an output time grid."""
    for name, v in (("t0", t0), ("t_end", t_end)):
        try:
            ok = is_number(v) and math.isfinite(float(v))
        except OverflowError:
            ok = False
        if not ok:
            raise ModelError(f"{name} must be a finite number, got {v!r}", "analysis")
    t0, t_end = float(t0), float(t_end)
    steps = whole(steps, "steps", "analysis", 1, MAX_STEPS)
    if not t_end > t0:
        raise ModelError(f"t_end ({t_end}) must be greater than t0 ({t0})", "analysis")
    if not math.isfinite(t_end - t0):
        raise ModelError("the time span t_end - t0 is too large to represent", "analysis")
    return t0, t_end, steps


def output_steps(steps: int, every: Any) -> np.ndarray:
    """Step indices kept with output decimation: 0, every, 2 every, ... and always ``steps``.

    Parameters
    ----------
    steps : int
        Output intervals of the time grid.
    every : int
        Keep every k-th output (validated here: a whole number >= 1).

    Returns
    -------
    numpy.ndarray
        The kept indices into the grid of ``steps + 1`` times.
    """
    k = whole(every, "every", "analysis", 1, MAX_STEPS)
    idx = np.arange(0, steps + 1, k)
    if idx[-1] != steps:
        idx = np.append(idx, steps)
    return idx


def time_grid(t0: float, t_end: float, steps: int, idx: np.ndarray) -> np.ndarray:
    """Times of the grid indices idx (exact at both ends, as in the core)."""
    t = t0 + (t_end - t0) * (idx / steps)
    t[idx == steps] = t_end
    return t


def check_memory(rows: int, columns: int) -> None:
    """Refuse output arrays that cannot fit in half the physical memory."""
    need = 8.0 * rows * columns
    try:
        phys = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # pragma: no cover
        phys = 8.0 * 2**30
    if need > 0.5 * phys:
        raise ModelError(f"the results would need {need / 2**30:.1f} GiB ({rows} rows x "
                         f"{columns} numbers); use fewer steps", "analysis")


def check_solver(tol: Any, maxit: Any) -> tuple[float, int]:
    """Validate Newton settings; 0 means the core's default."""
    t = 0.0 if tol is None else number(tol, "tol", "analysis")
    if tol is not None and not MIN_TOL <= t < 1.0:
        raise ModelError(f"tol must be from {MIN_TOL:g} to below 1 (it is relative to the "
                         f"model's length scale), got {tol!r}", "analysis")
    it = 0 if maxit is None else whole(maxit, "maxit", "analysis", 1, 10**6)
    return t, it


def _count_detail(p: Packed) -> str:
    ncam = p.nq - 3 * p.nb
    return (f"{p.neq} equations for {p.nq} coordinates ({p.nb} bodies x 3"
            + (f" + {ncam} cam contact (or curve) parameters" if ncam else "") + ")")


def require_determined(p: Packed, model: "Model") -> None:
    """Kinematics needs at least as many equations as coordinates (the core then checks the
    rank at the assembled configuration)."""
    if p.neq >= p.nq:
        return
    raise ModelError(f"the model is not kinematically determined: {_count_detail(p)}; "
                     f"{p.nq - p.neq} degree(s) of freedom are not driven: add a driver for each "
                     "(or a joint you left out)", f"model {model.name!r}")


def evaluate(model: "Model", q: Any, qd: Any, t: float) -> tuple[np.ndarray, ...]:
    """Phi, J, nu and gamma at a state, from the core."""
    p = pack(model)
    t = number(t, "t", "state")
    qv = _state(q, p.nq, "q")
    qdv = np.zeros(p.nq) if qd is None else _state(qd, p.nq, "qd")
    phi, jac, nu, gam, status, msg, bad = _core.core_eval(p.nb, p.ctab, p.rpar, p.neq, qv, qdv,
                                                          float(t))
    if status != OK:
        raise ModelError(decode(msg), model.constraints[bad - 1].describe() if bad else "model")
    return phi, jac, nu, gam


def _state(x: Any, n: int, what: str) -> np.ndarray:
    try:
        if np.iscomplexobj(x):
            raise ModelError(f"{what} must be real numbers, got complex ones", "state")
        v = np.asarray(x, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{what} must be an array of {n} numbers", "state") from None
    if v.shape != (n,):
        raise ModelError(f"{what} must have {n} entries (the model's coordinates), "
                         f"got shape {v.shape}", "state")
    if not np.all(np.isfinite(v)):
        raise ModelError(f"{what} has non-finite entries", "state")
    return np.ascontiguousarray(v)


def _names(p: Packed, model: "Model", flags: np.ndarray) -> tuple[list[str], list[str]]:
    """(constraint names, row labels) of the flagged rows."""
    rows = [int(r) for r in np.flatnonzero(flags)]
    cons = sorted({p.row_owner[r] for r in rows})
    return [model.constraints[k].name for k in cons], [p.row_labels[r] for r in rows]


@dataclass
class DofReport:
    """Degrees of freedom and redundancy at an assembled configuration.

    Attributes
    ----------
    coordinates : int
        Number of coordinates (3 per body plus curve parameters).
    equations : int
        Number of constraint equations (joints and drivers).
    rank : int
        Rank of the constraint Jacobian J (rank-revealing QR, LAPACK dgeqp3).
    dof : int
        coordinates - rank: the motion left free (0 for a driven mechanism).
    mobility : int
        Degrees of freedom of the joints alone (without drivers).
    redundant_rows : list of str
        Row labels of the redundant equations (NAME.equation).
    redundant_constraints : list of str
        The joints or drivers those rows belong to.
    q : numpy.ndarray
        The assembled configuration.
    """

    model_name: str
    t: float
    coordinates: int
    equations: int
    rank: int
    dof: int
    mobility: int
    redundant_rows: list[str] = field(default_factory=list)
    redundant_constraints: list[str] = field(default_factory=list)
    q: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __str__(self) -> str:
        lines = [f"model '{self.model_name}' at t = {self.t:g}",
                 f"  coordinates        {self.coordinates}",
                 f"  equations          {self.equations}",
                 f"  rank of J          {self.rank}",
                 f"  degrees of freedom {self.dof}   (coordinates - rank)",
                 f"  mobility           {self.mobility}   (joints alone, without drivers)",
                 f"  redundant          {len(self.redundant_rows)} equation(s)"]
        for r in self.redundant_rows:
            lines.append(f"    {r}")
        if self.redundant_rows:
            lines.append("  redundant equations repeat what the others impose: kinematics solves "
                         "them in least squares; reactions are statically indeterminate")
        return "\n".join(lines)


def analyze_dof(model: "Model", t: float = 0.0, tol: float | None = None) -> DofReport:
    """Degrees of freedom and redundant constraints at the configuration assembled from q0.

    Raises
    ------
    InconsistentConstraintsError
        If redundant constraints contradict each other (names them and gives the residual).
    AssemblyError
        If no configuration satisfies the constraints near q0.
    """
    t = number(t, "t", "analysis")
    tol_v, _ = check_solver(tol, None)
    p = pack(model)
    q, rank, mobility, red, dep, resid, worst, status, msg = _core.core_analyze(
        p.nb, p.ctab, p.rpar, p.neq, p.q0, t, tol_v)
    if status < 0:
        raise ModelError(decode(msg), model.constraints[worst - 1].describe() if worst else
                         f"model {model.name!r}")
    if status == INCONSISTENT:
        raise _inconsistent(model, p, float(resid), dep, red, int(rank), t, None)
    if status == ASSEMBLY_FAILED:
        raise _assembly_failed(model, float(resid), worst, t, None)
    if status == NO_MEMORY:
        raise InsufficientMemoryError(decode(msg))
    if status != OK:
        raise CoreError(f"internal error in the core (status {status}): {decode(msg)}")
    cons, rows = _names(p, model, red)
    return DofReport(model.name, t, p.nq, p.neq, int(rank), p.nq - int(rank), int(mobility),
                     rows, cons, q)


def _inconsistent(model: "Model", p: Packed, resid: float, dep: np.ndarray, red: np.ndarray,
                  rank: int, t: float, res: KinematicsResult | None, level: int = 0
                  ) -> InconsistentConstraintsError:
    cons, rows = _names(p, model, dep)
    red_cons, red_rows = _names(p, model, red)
    lead = (f"{', '.join(red_rows)} ({len(red_rows)} redundant equation(s): {p.neq} equations, "
            f"rank {rank}) contradict(s) the other constraints; " if red_rows and rank else "")
    what = ("||Phi||", "||J q_dot - nu||", "||J q_ddot - gamma||")[level]
    kind = ("", " at velocity level", " at acceleration level")[level]
    return InconsistentConstraintsError(
        f"Redundant constraints contradict each other{kind} at t = {t:.6g} s: {lead}"
        f"{', '.join(cons)} cannot all hold (smallest residual {what} = {resid:.3g}). "
        "Check their points and dimensions, or remove the one that repeats another.",
        t=t, results=res, status=INCONSISTENT, constraints=cons, redundant=red_cons,
        residual=resid)


def _assembly_failed(model: "Model", resid: float, worst: int, t: float,
                     res: KinematicsResult | None) -> AssemblyError:
    cons = model.constraints
    name = cons[worst - 1].describe() if worst > 0 else "?"
    return AssemblyError(
        f"Assembly failed at t = {t:.6g} s: no configuration satisfies the constraints near "
        f"the q0 estimates (smallest residual {resid:.3g}, largest in {name}). Check the "
        "link lengths and joint points, and give q0 closer to the intended configuration.",
        t=t, results=res, status=ASSEMBLY_FAILED, residual=resid,
        constraint=cons[worst - 1].name if worst > 0 else None)


#: linear solvers of the kinematic loop (codes of mbd_kinematics.f90)
SOLVERS = {"auto": 0, "dense": 1, "banded": 2}


def solver_code(solver: Any) -> int:
    """The core's code of a linear-solver name ("auto", "dense" or "banded")."""
    if not isinstance(solver, str) or solver not in SOLVERS:
        raise ModelError(f"unknown solver {solver!r}; use one of {', '.join(SOLVERS)}",
                         "analysis")
    return SOLVERS[solver]


def run_kinematics(model: "Model", t_end: float, steps: int, t0: float = 0.0,
                   tol: float | None = None, maxit: int | None = None,
                   tmin: float | None = None, every: int = 1,
                   solver: str = "auto") -> KinematicsResult:
    """Run a kinematic analysis in one core call; see :meth:`Model.kinematics`."""
    t0, t_end, steps = check_span(t0, t_end, steps)
    tol_v, maxit_v = check_solver(tol, maxit)
    idx = output_steps(steps, every)
    code = solver_code(solver)
    p = pack(model)
    require_determined(p, model)
    check_memory(len(idx), 3 * p.nq)
    out = _core.core_kinematics(p.nb, p.ctab, p.rpar, p.neq, p.q0, t0, t_end, steps,
                                tol_v, maxit_v, float(tmin or 0.0), int(every),
                                code, len(idx))
    qout, qdout, qddout, iinfo, rinfo, qsing, dep, red, tpass, status, msg = out
    n = int(iinfo[0])
    t = time_grid(t0, t_end, steps, idx)
    npass = int(iinfo[9])
    red_cons, red_rows = _names(p, model, red)
    res = KinematicsResult(t=t[:n], q=qout.T[:n].copy(), qd=qdout.T[:n].copy(),
                           qdd=qddout.T[:n].copy(), body_names=p.body_names,
                           coordinate_names=p.coordinate_names,
                           stats={"newton_corrections": int(iinfo[5]),
                                  "factorizations": int(iinfo[6]),
                                  "rejected_steps": int(iinfo[7]),
                                  "rank": int(iinfo[8]),
                                  "redundant_rows": red_rows,
                                  "singular_passages": [float(x) for x in tpass[:min(npass, 64)]],
                                  "singular_passage_count": npass,
                                  "solver": "banded" if int(rinfo[4]) == 2 else "dense",
                                  "band": (int(rinfo[5]), int(rinfo[6]))},
                           complete=status == OK, model=model)
    if red_rows and status in (OK, SINGULAR_CONFIG, NO_CONVERGENCE):
        warnings.warn(f"redundant constraints: {', '.join(red_rows)} repeat what the other "
                      "constraints impose (rank of J is "
                      f"{int(iinfo[8])} for {p.neq} equations); kinematics solves them in least "
                      "squares, exactly while they agree", RedundantConstraintWarning,
                      stacklevel=3)
    if npass:
        times = ", ".join(f"{x:.6g}" for x in tpass[:min(npass, 5)])
        warnings.warn(f"passed through {npass} singular configuration(s) (bifurcation points, "
                      f"J lost rank) at t = {times}{' ...' if npass > 5 else ''} s and stayed on "
                      "the branch the run started on", SingularPassageWarning, stacklevel=3)
    if status == OK:
        return res
    raise _failure(model, p, int(status), decode(msg), iinfo, rinfo, qsing, dep, red, res)


def _failure(model: "Model", p: Packed, status: int, msg: str, iinfo: np.ndarray,
             rinfo: np.ndarray, qsing: np.ndarray, dep: np.ndarray, red: np.ndarray,
             res: KinematicsResult) -> Exception:
    """The typed exception for a core status, with names in the message."""
    cons = model.constraints
    if status == BAD_COUNT and int(iinfo[8]) > 0:
        rank = int(iinfo[8])
        return ModelError(f"the model is not kinematically determined at the assembled "
                          f"configuration: J has rank {rank} for {p.nq} coordinates "
                          f"({_count_detail(p)}), so {p.nq - rank} degree(s) of freedom are "
                          "not driven; run model.analyze_dof() to see which equations are "
                          "redundant, and add a driver for each free degree of freedom",
                          f"model {model.name!r}")
    if status < 0:
        bad = int(iinfo[1])
        return ModelError(msg, cons[bad - 1].describe() if bad else f"model {model.name!r}")
    t = float(rinfo[0])
    last = f"t = {res.t[-1]:.6g} s" if len(res.t) else "no output rows"
    if status in (SINGULAR_CONFIG, SINGULAR):
        dep_names, _ = _names(p, model, dep)
        drv = int(iinfo[2])
        driver = cons[drv - 1].name if drv > 0 else None
        ratio = rinfo[1] / rinfo[2] if rinfo[2] > 0 else 0.0
        where = (f"driver '{driver}' can no longer be met, because the constraints "
                 f"{', '.join(dep_names)} became dependent"
                 if driver else f"the constraints {', '.join(dep_names)} became dependent")
        if status == SINGULAR_CONFIG:
            text = (f"Singular configuration (dead centre) at t = {t:.10f} s: {where} "
                    f"(J lost rank; sigma_min/sigma_max = {ratio:.1e}). The mechanism cannot "
                    "move further as driven: end the run before this time, or change the "
                    "driver or the link lengths. Results up to "
                    f"{last} ({len(res.t)} rows) are kept in the exception's .results.")
            cls: type = SingularConfigurationError
        else:
            text = (f"The assembled configuration at t = {t:.6g} s is singular: {where} "
                    f"(sigma_min/sigma_max = {ratio:.1e}). Start the run away from the dead "
                    "centre (another t0 or driver offset).")
            cls = SingularJacobianError
        return cls(text, t=t, results=res, status=status, driver=driver,
                   dependent=dep_names, q=np.array(qsing), sigma_min=float(rinfo[1]),
                   sigma_max=float(rinfo[2]))
    if status == INCONSISTENT:
        return _inconsistent(model, p, float(rinfo[3]), dep, red, int(iinfo[8]), t, res,
                             level=int(iinfo[4]))
    if status == ASSEMBLY_FAILED:
        return _assembly_failed(model, float(rinfo[3]), int(iinfo[3]), t, res)
    if status == NO_CONVERGENCE:
        return ConvergenceError(f"Newton-Raphson failed after t = {t:.6g} s: {msg}. Results up "
                                f"to {last} are kept in the exception's .results.", t=t,
                                results=res, status=status)
    if status == NO_MEMORY:
        return InsufficientMemoryError(msg)
    return CoreError(f"internal error in the core (status {status}): {msg}")
