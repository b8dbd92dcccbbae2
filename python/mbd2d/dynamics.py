"""Dynamics front door: inverse dynamics, forward dynamics and statics, one core call each."""
from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _core
from .analysis import (ASSEMBLY_FAILED, INCONSISTENT, NO_CONVERGENCE, OK, SINGULAR,
                       SINGULAR_CONFIG, _assembly_failed, _failure, _names, check_memory,
                       check_solver, check_span, output_steps, require_determined,
                       solver_code, time_grid)
from .errors import (ConvergenceError, CoreError, IntegrationError, ModelError,
                     RedundantConstraintWarning, SingularJacobianError)
from .pack import Packed, decode, pack
from .results import DynamicsResult, StaticsResult
from .validate import number, whole

if TYPE_CHECKING:  # pragma: no cover
    from .model import Model

METHODS = {"generalized-alpha": 1, "dopri5": 2, "baumgarte-rk4": 3, "partitioned": 4}
DEFAULT_METHOD = "dopri5"
INTEGRATOR_FAILED = 8
BAD_FORCE = -1000000
MAX_STEPS_DEFAULT = 10_000_000     # the core's default limit on accepted + rejected steps
INT32_MAX = 2**31 - 1


def pack_dynamics(model: "Model", p: Packed) -> tuple[np.ndarray, ...]:
    """Masses (2, nb), gravity, force table (6, nf), force parameters, and v0 (nq).

    Raises
    ------
    ModelError
        If a body has no mass or inertia.
    """
    bmass = np.zeros((2, len(model.bodies)), order="F")
    for i, b in enumerate(model.bodies):
        if b.mass is None or b.inertia is None:
            raise ModelError("dynamics needs 'mass' and 'inertia' for every body (inertia about "
                             "the centre of mass; 0 for a point mass)", f"body '{b.name}'")
        bmass[:, i] = (b.mass, b.inertia)
    body_idx = {b.name: i + 1 for i, b in enumerate(model.bodies)}
    body_idx["ground"] = 0
    cols: list[list[int]] = []
    fpar: list[float] = []
    for f in model.forces:
        raw = f.raw()
        cols.append([f.kind, body_idx[f.bodies[0]], body_idx[f.bodies[1]], len(fpar) + 1,
                     len(raw), 0])
        fpar.extend(raw)
    ftab = np.asfortranarray(np.array(cols, dtype=np.int32).reshape(-1, 6).T)
    fp = np.array(fpar if fpar else [0.0])
    v0 = np.zeros(p.nq)
    v0[:3 * p.nb] = np.array([b.v0 for b in model.bodies], dtype=float).ravel()
    return bmass, np.asarray(model.gravity, dtype=float), ftab, fp, v0


def _bad_entry(model: "Model", bad: int) -> str:
    if bad <= BAD_FORCE:
        return model.forces[BAD_FORCE - bad - 1].describe()
    if bad < 0:
        return f"body '{model.bodies[-bad - 1].name}'"
    if bad > 0:
        return model.constraints[bad - 1].describe()
    return f"model {model.name!r}"


def _result(model: "Model", p: Packed, t: np.ndarray, n: int, qo: np.ndarray, vo: np.ndarray,
            ao: np.ndarray, lam: np.ndarray, e: np.ndarray, stats: dict[str, Any],
            complete: bool) -> DynamicsResult:
    return DynamicsResult(t=t[:n], q=qo.T[:n].copy(), qd=vo.T[:n].copy(), qdd=ao.T[:n].copy(),
                          body_names=p.body_names, coordinate_names=p.coordinate_names,
                          stats=stats, complete=complete, model=model,
                          lam=lam.T[:n].copy(), kinetic=e[0, :n].copy(),
                          potential=e[1, :n].copy(), drift_position=e[2, :n].copy(),
                          drift_velocity=e[3, :n].copy(), row_labels=p.row_labels, packed=p)


def run_inverse(model: "Model", t_end: float, steps: int, t0: float = 0.0,
                tol: float | None = None, every: int = 1, solver: str = "auto") -> DynamicsResult:
    """Kinematics plus the multipliers, energies and (on demand) reactions at every output.

    See :meth:`Model.inverse_dynamics`.
    """
    t0, t_end, steps = check_span(t0, t_end, steps)
    tol_v, _ = check_solver(tol, None)
    idx = output_steps(steps, every)
    code = solver_code(solver)
    p = pack(model)
    require_determined(p, model)
    bmass, grav, ftab, fpar, _ = pack_dynamics(model, p)
    check_memory(len(idx), 3 * p.nq + p.neq + 4)
    out = _core.core_inverse(ctab=p.ctab, rpar=p.rpar, bmass=bmass, grav=grav, ftab=ftab,
                             fpar=fpar, neq=p.neq, q0=p.q0, t0=t0, t1=t_end, nsteps=steps,
                             tol=tol_v, every=int(every), solver=code,
                             nout=len(idx))
    qo, vo, ao, lam, e, iinfo, rinfo, qsing, dep, red, tpass, status, msg = out
    n = int(iinfo[0])
    t = time_grid(t0, t_end, steps, idx)
    _, red_rows = _names(p, model, red)
    stats = {"newton_corrections": int(iinfo[5]), "factorizations": int(iinfo[6]),
             "rejected_steps": int(iinfo[7]), "rank": int(iinfo[8]),
             "redundant_rows": red_rows,
             "singular_passages": [float(x) for x in tpass[:min(int(iinfo[9]), 64)]]}
    res = _result(model, p, t, n, qo, vo, ao, lam, e, stats, status == OK)
    if red_rows:
        warnings.warn(f"redundant constraints: {', '.join(red_rows)}; the multipliers are the "
                      "minimum-norm set (the reactions are statically indeterminate)",
                      RedundantConstraintWarning, stacklevel=3)
    if status == OK:
        return res
    if status < 0 and iinfo[1] <= BAD_FORCE:
        raise ModelError(decode(msg), _bad_entry(model, int(iinfo[1])))
    raise _failure(model, p, int(status), decode(msg), iinfo, rinfo, qsing, dep, red, res)


def run_dynamics(model: "Model", t_end: float, steps: int, method: str | None = None,
                 rtol: float | None = None, atol: float | None = None, h: float | None = None,
                 rho_inf: float | None = None, alpha: float | None = None,
                 beta: float | None = None, t0: float = 0.0, every: int = 1,
                 max_steps: int | None = None) -> DynamicsResult:
    """Forward dynamics in one core call; see :meth:`Model.dynamics`."""
    t0, t_end, steps = check_span(t0, t_end, steps)
    idx = output_steps(steps, every)
    every = int(every)
    nmax = MAX_STEPS_DEFAULT if max_steps is None else \
        whole(max_steps, "max_steps", "dynamics", 1, INT32_MAX)
    method = DEFAULT_METHOD if method is None else method
    if method not in METHODS:
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
    p = pack(model)
    bmass, grav, ftab, fpar, v0 = pack_dynamics(model, p)
    check_memory(len(idx), 3 * p.nq + p.neq + 4)
    out = _core.core_dynamics(ctab=p.ctab, rpar=p.rpar, bmass=bmass, grav=grav, ftab=ftab,
                              fpar=fpar, neq=p.neq, q0=p.q0, v0=v0, t0=t0, t1=t_end,
                              nsteps=steps, method=METHODS[method], rtol=rtol_v, atol=atol_v,
                              h=h_v, rho_inf=rho_v, balpha=alpha_v, bbeta=beta_v,
                              every=every, nrow=len(idx), max_steps=nmax)
    qo, vo, ao, lam, e, iinfo, rinfo, red, status, msg = out
    n = int(iinfo[0])
    t = time_grid(t0, t_end, steps, idx)
    _, red_rows = _names(p, model, red)
    stats = {"method": method, "steps": int(iinfo[2]), "rejected_steps": int(iinfo[3]),
             "newton_iterations": int(iinfo[4]), "rhs_evaluations": int(iinfo[5]),
             "iteration_matrices": int(iinfo[6]), "factorizations": int(iinfo[9]),
             "partitions": int(iinfo[7]),
             "h_min": float(rinfo[1]) if iinfo[2] else None,
             "h_max": float(rinfo[2]) if iinfo[2] else None, "redundant_rows": red_rows}
    res = _result(model, p, t, n, qo, vo, ao, lam, e, stats, status == OK)
    if red_rows:
        warnings.warn(f"redundant constraints: {', '.join(red_rows)} are left out of the equations "
                      "of motion; the reported multipliers are the minimum-norm set (the "
                      "reactions are statically indeterminate)", RedundantConstraintWarning,
                      stacklevel=3)
    if status == OK:
        return res
    text = decode(msg)
    if status < 0:
        raise ModelError(text, _bad_entry(model, int(iinfo[1])))
    tf = float(rinfo[0])
    last = f"t = {res.t[-1]:.6g} s" if len(res.t) else "no output rows"
    if status == ASSEMBLY_FAILED:
        raise _assembly_failed(model, 0.0, 0, t0, res)
    if status == INTEGRATOR_FAILED:
        raise IntegrationError(f"{method}: {text}. Results up to {last} are kept in the "
                               "exception's .results.", t=tf, results=res, status=status)
    if status in (SINGULAR, SINGULAR_CONFIG):
        raise SingularJacobianError(f"{method}: {text}", t=tf, results=res, status=status)
    if status in (NO_CONVERGENCE, INCONSISTENT):
        raise ConvergenceError(f"{method}: {text}", t=tf, results=res, status=status)
    raise CoreError(f"internal error in the core (status {status}): {text}")


STABILITY = {1: "stable", 0: "unstable", -1: "neutral", 2: "fully constrained"}


def run_statics(model: "Model", t: float = 0.0) -> StaticsResult:
    """Static equilibrium near the q0 estimates; see :meth:`Model.statics`."""
    t = number(t, "t", "statics")
    p = pack(model)
    bmass, grav, ftab, fpar, _ = pack_dynamics(model, p)
    q, lam, stable, resid, iinfo, status, msg = _core.core_statics(
        ctab=p.ctab, rpar=p.rpar, bmass=bmass, grav=grav, ftab=ftab, fpar=fpar, neq=p.neq,
        q0=p.q0, t=t)
    text = decode(msg)
    if status < 0:
        raise ModelError(text, _bad_entry(model, int(iinfo[1])))
    if status == ASSEMBLY_FAILED:
        raise _assembly_failed(model, float(resid), 0, t, None)
    if status == SINGULAR:
        raise SingularJacobianError(text, t=t, status=status)
    if status == NO_CONVERGENCE:
        raise ConvergenceError(text, t=t, status=status, residual=float(resid))
    if status != OK:
        raise CoreError(f"internal error in the core (status {status}): {text}")
    return StaticsResult(t=t, q=q, lam=lam, stability=STABILITY.get(int(stable), "unknown"),
                         residual=float(resid), body_names=p.body_names,
                         coordinate_names=p.coordinate_names, row_labels=p.row_labels,
                         model=model, packed=p)


def reactions(p: Packed, q: np.ndarray, t: np.ndarray, lam: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """Joint reactions at many states (global and in the body frames): (nt, nc, 6) each."""
    qq = np.asfortranarray(np.atleast_2d(q).T)
    ll = np.asfortranarray(np.atleast_2d(lam).T)
    reac, rloc, status, msg = _core.core_reactions(p.nb, p.ctab, p.rpar, qq,
                                                   np.atleast_1d(t).astype(float), ll)
    if status != OK:
        raise CoreError(decode(msg))
    return np.transpose(reac, (2, 1, 0)), np.transpose(rloc, (2, 1, 0))
