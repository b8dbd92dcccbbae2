"""Forward dynamics front door: M q_ddot + J^T lambda = Q, Phi = 0 integrated in one core
call."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import ASSEMBLY_FAILED, INCONSISTENT, INTEGRATOR_FAILED, OK, error_for
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import (MbdError, ModelError, RedundantConstraintWarning, SingularPassageWarning,
                      StiffnessWarning, warn)
from ..results.dynamics import DynamicsResult
from ..validate import number, whole
from .contacts import MAX_EVENTS, check_method, has_events, report_pulls
from .failures import assembly_failed, bad_entry, inconsistent_at, row_names
from .outputs import dynamics_result, finite_part
from .progress import run_core
from .sensitivities import attach, check_sens_method, check_status, requested, table
from .settings import (check_memory, check_span, output_rows, output_steps, solver_code,
                       time_grid)

METHODS = {"generalized-alpha": 1, "dopri5": 2, "baumgarte-rk4": 3, "partitioned": 4}
DEFAULT_METHOD = "dopri5"
MAX_STEPS_DEFAULT = 10_000_000     # the core's default limit on accepted + rejected steps
INT32_MAX = 2**31 - 1


@dataclass(frozen=True)
class DynamicsSettings:
    """Checked settings of a dynamics run, as the core takes them (0 or -1: its default)."""

    method: str
    code: int
    rtol: float
    atol: float
    h: float
    rho_inf: float
    alpha: float
    beta: float
    max_steps: int


def dynamics_settings(method: str | None = None, rtol: Any = None, atol: Any = None,
                      h: Any = None, rho_inf: Any = None, alpha: Any = None, beta: Any = None,
                      max_steps: Any = None) -> DynamicsSettings:
    """Check the settings of :meth:`mbd2d.Model.dynamics` and give them as the core takes
    them (the same numbers for a Python run and an exported file).

    Raises
    ------
    ModelError
        For an unknown method, a setting out of range, or one the method does not use.
    """
    nmax = MAX_STEPS_DEFAULT if max_steps is None else \
        whole(max_steps, "max_steps", "dynamics", 1, INT32_MAX)
    method = DEFAULT_METHOD if method is None else method
    if not isinstance(method, str) or method not in METHODS:
        raise ModelError(f"unknown method {method!r}; use one of {', '.join(METHODS)}",
                         "dynamics")

    def opt(v: Any, name: str, lo: float, hi: float, default: float) -> float:
        if v is None:
            return default
        x = number(v, name, "dynamics")
        if not lo <= x <= hi:
            raise ModelError(f"{name} must be in [{lo:g}, {hi:g}], got {v!r}", "dynamics")
        return x

    rtol_v = opt(rtol, "rtol", 1e-14, 1.0, 0.0)
    atol_v = opt(atol, "atol", 1e-16, 1e6, 0.0)
    h_v = opt(h, "h", 1e-12, math.inf, 0.0)
    if method == "baumgarte-rk4" and h is None:
        raise ModelError("baumgarte-rk4 is a fixed-step method: give h (for example h=1e-3)",
                         "dynamics")
    if h is not None and method in ("dopri5", "partitioned"):
        raise ModelError(f"{method} chooses its own steps from rtol and atol; h is for "
                         "generalized-alpha and baumgarte-rk4", "dynamics")
    rho_v = opt(rho_inf, "rho_inf", 0.0, 1.0, -1.0)
    if method == "generalized-alpha" and h is None and rho_v >= 0.99:
        # undamped, the algorithmic accelerations carry an oscillation the error
        # estimate reads as error; the step then collapses
        raise ModelError(f"error-controlled generalized-alpha needs numerical damping: "
                         f"rho_inf={rho_v:g} is too close to 1; use rho_inf <= 0.9 or give "
                         "a fixed step h", "dynamics")
    alpha_v = opt(alpha, "alpha", 0.0, 1e9, -1.0)
    beta_v = opt(beta, "beta", 0.0, 1e9, -1.0)
    return DynamicsSettings(method, METHODS[method], rtol_v, atol_v, h_v, rho_v, alpha_v,
                            beta_v, nmax)


def run_dynamics(model: ModelDescription, t_end: float, steps: int, method: str | None = None,
                 rtol: float | None = None, atol: float | None = None, h: float | None = None,
                 rho_inf: float | None = None, alpha: float | None = None,
                 beta: float | None = None, t0: float = 0.0, every: Any = 1,
                 max_steps: Any = None, sensitivities: Any = None,
                 progress: bool | None = None, solver: str = "auto") -> DynamicsResult:
    """Forward dynamics in one core call; see :meth:`mbd2d.Model.dynamics`."""
    t0, t_end, steps = check_span(t0, t_end, steps)
    code = solver_code(solver)
    nout = output_rows(steps, every)
    every = int(every)
    st = dynamics_settings(method, rtol, atol, h, rho_inf, alpha, beta, max_steps)
    method, nmax = st.method, st.max_steps
    rtol_v, atol_v, h_v, rho_v, alpha_v, beta_v = (st.rtol, st.atol, st.h, st.rho_inf,
                                                   st.alpha, st.beta)
    check_method(model, method)
    params = requested(model, sensitivities)
    check_sens_method(params, method, "dynamics")
    p = pack(model)
    d = pack_dynamics(model, p)
    npar = len(params) if params else 0
    check_memory(nout, 3 * p.nq * (1 + npar) + p.neq + 4 + 6 * d.ftab.shape[1], "dynamics")
    idx = output_steps(steps, every)
    maxev = MAX_EVENTS if has_events(model) else 1
    if params:
        ptab = table(p, params, d)
        out = core.dynamics_sens(p, d, t0, t_end, steps, rtol_v, atol_v, every, nmax, nout,
                                 ptab, code, METHODS[method], h_v, rho_v)
        check_status(out.status, out.iinfo, out.msg, params)
    else:
        fixed = (t_end - t0) / h_v if h_v > 0 else 0.0
        out = run_core(lambda ctl: core.dynamics(p, d, t0, t_end, steps, METHODS[method],
                                                 rtol_v, atol_v, h_v, rho_v, alpha_v, beta_v,
                                                 every, nout, nmax, maxev, ctl, code),
                       nout, f"dynamics ({method})", progress,
                       max(float(steps), fixed) * float(p.nq + p.neq)**2)
    iinfo, rinfo, status = out.iinfo, out.rinfo, out.status
    n = int(iinfo[0])
    t = time_grid(t0, t_end, steps, idx)
    _, red_rows = row_names(p, model, out.red)
    stats = {"method": method, "steps": int(iinfo[2]), "rejected_steps": int(iinfo[3]),
             "newton_iterations": int(iinfo[4]), "rhs_evaluations": int(iinfo[5]),
             "iteration_matrices": int(iinfo[6]), "factorizations": int(iinfo[9]),
             "partitions": int(iinfo[7]),
             "h_min": float(rinfo[1]) if iinfo[2] else None,
             "h_max": float(rinfo[2]) if iinfo[2] else None, "redundant_rows": red_rows,
             "solver": "banded" if int(rinfo[4]) == 2 else "dense",
             "band": (int(rinfo[5]), int(rinfo[6])),
             "schur": (int(rinfo[7]), int(rinfo[3])),
             "events": int(getattr(out, "nev", 0)),
             "events_not_kept": max(0, int(getattr(out, "nev", 0)) - maxev)}
    if iinfo[10]:
        stats["stiff_from"] = float(rinfo[10])   # dopri5, partitioned: steps set by stability
    if method == "partitioned" and iinfo[2] and rinfo[9] > 0:
        # the worst reciprocal condition of J_u at an accepted step, and when (dense J)
        stats["ju_rcond_min"] = (float(rinfo[8]), float(rinfo[9]))
    res = dynamics_result(model, p, t, n, out, stats, status == OK)
    if params:
        attach(res, out, params, n, ptab)
    res, bad = finite_part(res)
    if status == OK and bad is None:
        report_pulls(model, p, res)
    if red_rows:
        warn(f"redundant constraints: {', '.join(red_rows)} are left out of the equations "
             "of motion; the reported multipliers are the minimum-norm set (the "
             "reactions are statically indeterminate)", RedundantConstraintWarning)
    warn_near_singular(stats)
    warn_stiff(stats)
    exc = dynamics_error(model, p, out, res, t, bad, method, t0)
    if exc is None:
        return res
    raise exc


#: partitioned: a step accepted where J_u's reciprocal condition is below this carries
#: acceleration errors of order eps / rcond**2 above 1e-3 (positions, velocities and
#: accelerations lose accuracy like cond, cond**2, cond**3 next to a singular configuration)
RCOND_WARN = math.sqrt(np.finfo(float).eps / 1e-3)


def warn_near_singular(stats: dict[str, Any]) -> None:
    """SingularPassageWarning when a partitioned run accepted a step next to a singular
    configuration of its dependent coordinates (``stats["ju_rcond_min"]`` below RCOND_WARN)."""
    rc, tc = stats.get("ju_rcond_min", (1.0, 0.0))
    if rc >= RCOND_WARN:
        return
    warn(f"partitioned: a step at t = {tc:.6g} ended next to a singular configuration "
         f"(J_u's reciprocal condition {rc:.1e}; the steps fell to "
         f"h_min = {stats.get('h_min') or 0.0:.1e} s): accelerations there carry errors "
         f"up to eps/rcond**2 = {np.finfo(float).eps / max(rc, 1e-300)**2:.0e}, and the "
         "motion after it may be inaccurate. Check the energy (res.energy), or use "
         "rtol >= 1e-8, whose longer steps pass over such points",
         SingularPassageWarning)


def warn_stiff(stats: dict[str, Any]) -> None:
    """StiffnessWarning when dopri5's (partitioned's) steps became limited by stability
    (``stats["stiff_from"]``, from Hairer's stiffness test in the core)."""
    t = stats.get("stiff_from")
    if t is None:
        return
    warn(f"{stats['method']}: from t = {t:.6g} s the steps were limited by "
         f"stability, not accuracy ({stats['steps']} steps, at most "
         f"{stats.get('h_max') or 0.0:.2e} s): the model is stiff (a stiff spring, "
         "damper or contact). method='generalized-alpha' (implicit) takes steps set "
         "by the motion's accuracy: h of a tenth of its shortest period of interest",
         StiffnessWarning)


def dynamics_error(model: ModelDescription, p: Packed, out: Any, res: DynamicsResult,
                   t: np.ndarray, bad: int | None, method: str, t0: float) -> MbdError | None:
    """The exception a forward dynamics run ends in, or None when it completed (``out`` as
    :func:`mbd2d.binding.core.dynamics` returns it; the other arguments as
    :func:`mbd2d.analysis.kinematics.kinematics_error`; p the tables of the model run)."""
    status, iinfo, rinfo = out.status, out.iinfo, out.rinfo
    if status == OK and bad is None:
        return None
    text = out.msg
    last = f"t = {res.t[-1]:.6g} s" if len(res.t) else "no output rows"
    kept = f"Results up to {last} are kept in the exception's .results."
    if status == OK:
        return error_for("dynamics", INTEGRATOR_FAILED,
                         f"{method}: the solution became non-finite at t = {t[bad]:.6g} s (a "
                         f"blow-up: try a smaller rtol or h, or another method). {kept}",
                         t=t[bad], results=res)
    if status < 0:
        return error_for("dynamics", status, text, entry=bad_entry(model, int(iinfo[1])))
    tf = float(rinfo[0])
    if status == ASSEMBLY_FAILED:
        return assembly_failed("dynamics", model, 0.0, 0, t0, res)
    if status == INCONSISTENT and not len(res.t):
        return inconsistent_at("dynamics", model, p, t0, res, f"{method}: {text}")
    if status == INTEGRATOR_FAILED:
        text = f"{method}: {text}. {kept}"
    else:
        text = f"{method}: {text}"
    return error_for("dynamics", status, text, t=tf, results=res)
