"""The analysis front door: settings checks, the one call into the core, and the mapping
of the core's status to results or typed exceptions."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _core
from .errors import (AssemblyError, ConvergenceError, CoreError, ModelError,
                     SingularConfigurationError, SingularJacobianError)
from .pack import Packed, decode, pack
from .results import KinematicsResult
from .validate import is_number, number, whole

if TYPE_CHECKING:  # pragma: no cover
    from .model import Model

# status codes of mbd_status.f90
OK, SINGULAR, NO_CONVERGENCE, SINGULAR_CONFIG, ASSEMBLY_FAILED, LAPACK = 0, 1, 2, 3, 4, 5


MAX_STEPS = 10**9      # output rows are held in memory; the core counts in 32-bit integers
MIN_TOL = 1e-15        # below this a residual test cannot pass in double precision


def check_span(t0: Any, t_end: Any, steps: Any) -> tuple[float, float, int]:
    """Validate an output time grid."""
    for name, v in (("t0", t0), ("t_end", t_end)):
        if not is_number(v) or not math.isfinite(v):
            raise ModelError(f"{name} must be a finite number, got {v!r}", "analysis")
    t0, t_end = float(t0), float(t_end)
    steps = whole(steps, "steps", "analysis", 1, MAX_STEPS)
    if not t_end > t0:
        raise ModelError(f"t_end ({t_end}) must be greater than t0 ({t0})", "analysis")
    return t0, t_end, steps


def check_solver(tol: Any, maxit: Any) -> tuple[float, int]:
    """Validate Newton settings; 0 means the core's default."""
    t = 0.0 if tol is None else number(tol, "tol", "analysis")
    if tol is not None and not MIN_TOL <= t < 1.0:
        raise ModelError(f"tol must be from {MIN_TOL:g} to below 1 (it is relative to the "
                         f"model's length scale), got {tol!r}", "analysis")
    it = 0 if maxit is None else whole(maxit, "maxit", "analysis", 1, 10**6)
    return t, it


def require_determined(p: Packed, model: "Model") -> None:
    """Kinematics needs as many independent equations as coordinates."""
    if p.neq == p.nq:
        return
    ncam = p.nq - 3 * p.nb
    detail = (f"{p.neq} equations for {p.nq} coordinates ({p.nb} bodies x 3"
              + (f" + {ncam} cam contact parameters" if ncam else "") + ")")
    if p.neq < p.nq:
        hint = (f"{p.nq - p.neq} degree(s) of freedom are not driven: add a driver for each "
                "(or a joint you left out)")
    else:
        hint = (f"{p.neq - p.nq} equation(s) too many: remove a driver or a joint that repeats "
                "another")
    raise ModelError(f"the model is not kinematically determined: {detail}; {hint}",
                     f"model {model.name!r}")


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
        v = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what} must be an array of {n} numbers", "state") from None
    if v.shape != (n,):
        raise ModelError(f"{what} must have {n} entries (the model's coordinates), "
                         f"got shape {v.shape}", "state")
    if not np.all(np.isfinite(v)):
        raise ModelError(f"{what} has non-finite entries", "state")
    return np.ascontiguousarray(v)


def run_kinematics(model: "Model", t_end: float, steps: int, t0: float = 0.0,
                   tol: float | None = None, maxit: int | None = None,
                   tmin: float | None = None) -> KinematicsResult:
    """Run a kinematic analysis in one core call; see :meth:`Model.kinematics`."""
    t0, t_end, steps = check_span(t0, t_end, steps)
    tol_v, maxit_v = check_solver(tol, maxit)
    p = pack(model)
    require_determined(p, model)
    out = _core.core_kinematics(p.nb, p.ctab, p.rpar, p.neq, p.q0, t0, t_end, steps,
                                tol_v, maxit_v, float(tmin or 0.0))
    qout, qdout, qddout, iinfo, rinfo, qsing, dep, status, msg = out
    n = int(iinfo[0])
    t = t0 + (t_end - t0) * (np.arange(steps + 1) / steps)
    t[-1] = t_end
    res = KinematicsResult(t=t[:n], q=qout.T[:n].copy(), qd=qdout.T[:n].copy(),
                           qdd=qddout.T[:n].copy(), body_names=p.body_names,
                           coordinate_names=p.coordinate_names,
                           stats={"newton_corrections": int(iinfo[5]),
                                  "lu_factorizations": int(iinfo[6]),
                                  "rejected_steps": int(iinfo[7])},
                           complete=status == OK, model=model)
    if status == OK:
        return res
    raise _failure(model, p, int(status), decode(msg), iinfo, rinfo, qsing, dep, res)


def _failure(model: "Model", p: Packed, status: int, msg: str, iinfo: np.ndarray,
             rinfo: np.ndarray, qsing: np.ndarray, dep: np.ndarray,
             res: KinematicsResult) -> Exception:
    """The typed exception for a core status, with names in the message."""
    cons = model.constraints
    if status < 0:
        bad = int(iinfo[1])
        return ModelError(msg, cons[bad - 1].describe() if bad else f"model {model.name!r}")
    t = float(rinfo[0])
    last = f"t = {res.t[-1]:.6g} s" if len(res.t) else "no output rows"
    if status in (SINGULAR_CONFIG, SINGULAR):
        dependent = sorted({p.row_owner[r] for r in np.flatnonzero(dep)})
        dep_names = [cons[k].name for k in dependent]
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
    if status == ASSEMBLY_FAILED:
        worst = int(iinfo[3])
        name = cons[worst - 1].describe() if worst > 0 else "?"
        return AssemblyError(
            f"Assembly failed at t = {t:.6g} s: no configuration satisfies the constraints near "
            f"the q0 estimates (smallest residual {rinfo[3]:.3g}, largest in {name}). Check the "
            "link lengths and joint points, and give q0 closer to the intended configuration.",
            t=t, results=res, status=status, residual=float(rinfo[3]),
            constraint=cons[worst - 1].name if worst > 0 else None)
    if status == NO_CONVERGENCE:
        return ConvergenceError(f"Newton-Raphson failed after t = {t:.6g} s: {msg}. Results up "
                                f"to {last} are kept in the exception's .results.", t=t,
                                results=res, status=status)
    return CoreError(f"internal error in the core (status {status}): {msg}")
