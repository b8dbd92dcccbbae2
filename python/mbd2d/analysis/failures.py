"""Typed exceptions for the core's failure statuses, with messages that name the time, the
entries and what to do."""
from __future__ import annotations

import numpy as np

from ..binding.status import (ASSEMBLY_FAILED, BAD_COUNT, INCONSISTENT, NO_CONVERGENCE,
                              SINGULAR, SINGULAR_CONFIG)
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import (AssemblyError, ConvergenceError, CoreError, InconsistentConstraintsError,
                      ModelError, SingularConfigurationError, SingularJacobianError)
from ..results.kinematics import KinematicsResult
from .settings import count_detail

BAD_FORCE = -1000000   # the core's "bad entry" code of force k is BAD_FORCE - k


def row_names(p: Packed, model: ModelDescription, flags: np.ndarray
              ) -> tuple[list[str], list[str]]:
    """(constraint names, row labels) of the flagged rows."""
    rows = [int(r) for r in np.flatnonzero(flags)]
    cons = sorted({p.row_owner[r] for r in rows})
    return [model.constraints[k].name for k in cons], [p.row_labels[r] for r in rows]


def bad_entry(model: ModelDescription, bad: int) -> str:
    """How messages name the entry the core's ``bad`` code points at: a force (<= BAD_FORCE),
    a body (< 0), a joint or driver (> 0), or the model (0)."""
    if bad <= BAD_FORCE:
        return model.forces[BAD_FORCE - bad - 1].describe()
    if bad < 0:
        return f"body '{model.bodies[-bad - 1].name}'"
    if bad > 0:
        return model.constraints[bad - 1].describe()
    return f"model {model.name!r}"


def inconsistent(model: ModelDescription, p: Packed, resid: float, dep: np.ndarray,
                 red: np.ndarray, rank: int, t: float, res: KinematicsResult | None,
                 level: int = 0) -> InconsistentConstraintsError:
    """Redundant constraints that contradict each other, named."""
    cons, rows = row_names(p, model, dep)
    red_cons, red_rows = row_names(p, model, red)
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


def assembly_failed(model: ModelDescription, resid: float, worst: int, t: float,
                    res: KinematicsResult | None) -> AssemblyError:
    """No configuration near the q0 estimates, with the worst constraint named."""
    cons = model.constraints
    name = cons[worst - 1].describe() if worst > 0 else "?"
    return AssemblyError(
        f"Assembly failed at t = {t:.6g} s: no configuration satisfies the constraints near "
        f"the q0 estimates (smallest residual {resid:.3g}, largest in {name}). Check the "
        "link lengths and joint points, and give q0 closer to the intended configuration.",
        t=t, results=res, status=ASSEMBLY_FAILED, residual=resid,
        constraint=cons[worst - 1].name if worst > 0 else None)


def kinematic_failure(model: ModelDescription, p: Packed, status: int, msg: str,
                      iinfo: np.ndarray, rinfo: np.ndarray, qsing: np.ndarray, dep: np.ndarray,
                      red: np.ndarray, res: KinematicsResult) -> Exception:
    """The typed exception for a status of a kinematic run (kinematics, inverse dynamics),
    with names in the message."""
    cons = model.constraints
    if status == BAD_COUNT and int(iinfo[8]) > 0:
        rank = int(iinfo[8])
        return ModelError(f"the model is not kinematically determined at the assembled "
                          f"configuration: J has rank {rank} for {p.nq} coordinates "
                          f"({count_detail(p)}), so {p.nq - rank} degree(s) of freedom are "
                          "not driven; run model.analyze_dof() to see which equations are "
                          "redundant, and add a driver for each free degree of freedom",
                          f"model {model.name!r}")
    if status < 0:
        bad = int(iinfo[1])
        return ModelError(msg, cons[bad - 1].describe() if bad else f"model {model.name!r}")
    t = float(rinfo[0])
    last = f"t = {res.t[-1]:.6g} s" if len(res.t) else "no output rows"
    if status in (SINGULAR_CONFIG, SINGULAR):
        dep_names, _ = row_names(p, model, dep)
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
        return inconsistent(model, p, float(rinfo[3]), dep, red, int(iinfo[8]), t, res,
                            level=int(iinfo[4]))
    if status == ASSEMBLY_FAILED:
        return assembly_failed(model, float(rinfo[3]), int(iinfo[3]), t, res)
    if status == NO_CONVERGENCE:
        return ConvergenceError(f"Newton-Raphson failed after t = {t:.6g} s: {msg}. Results up "
                                f"to {last} are kept in the exception's .results.", t=t,
                                results=res, status=status)
    return CoreError(f"internal error in the core (status {status}): {msg}")
