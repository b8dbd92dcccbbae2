"""Typed exceptions for the core's failure statuses, with messages that name the time, the
entries and what to do."""
from __future__ import annotations

import numpy as np

from ..binding import core
from ..binding.status import (ASSEMBLY_FAILED, BAD_COUNT, INCONSISTENT, NO_CONVERGENCE,
                              SINGULAR, SINGULAR_CONFIG, error_for)
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import MbdError
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
        name, what, e = model.force_elements()[BAD_FORCE - bad - 1]
        return f"joint '{name}' friction" if what == "friction" else e.describe()
    if bad < 0:
        return f"body '{model.bodies[-bad - 1].name}'"
    if bad > 0:
        return model.constraints[bad - 1].describe()
    return f"model {model.name!r}"


def inconsistent(analysis: str, model: ModelDescription, p: Packed, resid: float,
                 dep: np.ndarray, red: np.ndarray, rank: int, t: float,
                 res: KinematicsResult | None, level: int = 0) -> MbdError:
    """Redundant constraints that contradict each other, named."""
    cons, rows = row_names(p, model, dep)
    red_cons, red_rows = row_names(p, model, red)
    lead = (f"{', '.join(red_rows)} ({len(red_rows)} redundant equation(s): {p.neq} equations, "
            f"rank {rank}) contradict(s) the other constraints; " if red_rows and rank else "")
    what = ("||Phi||", "||J q_dot - nu||", "||J q_ddot - gamma||")[level]
    kind = ("", " at velocity level", " at acceleration level")[level]
    return error_for(
        analysis, INCONSISTENT,
        f"Redundant constraints contradict each other{kind} at t = {t:.6g} s: {lead}"
        f"{', '.join(cons)} cannot all hold (smallest residual {what} = {resid:.3g}). "
        "Check their points and dimensions, or remove the one that repeats another.",
        t=t, results=res, constraints=cons, redundant=red_cons, residual=resid)


def inconsistent_at(analysis: str, model: ModelDescription, p: Packed, t: float,
                    res: KinematicsResult | None, text: str) -> MbdError:
    """Redundant constraints that contradict each other at assembly, reported by a call that
    does not name them (statics, dynamics): one rank analysis at t names them; ``text`` (the
    core's message) when it cannot."""
    out = core.analyze(p, t, 0.0)
    if out.status == INCONSISTENT:
        return inconsistent(analysis, model, p, float(out.resid), out.dep, out.red,
                            int(out.rank), t, res)
    return error_for(analysis, INCONSISTENT, f"{text}; run model.analyze_dof({t:g}) to see "
                     "which constraints disagree, and check their points and dimensions", t=t,
                     results=res)


def assembly_failed(analysis: str, model: ModelDescription, resid: float, worst: int, t: float,
                    res: KinematicsResult | None) -> MbdError:
    """No configuration near the q0 estimates, with the worst constraint named."""
    cons = model.constraints
    name = cons[worst - 1].describe() if worst > 0 else "?"
    return error_for(
        analysis, ASSEMBLY_FAILED,
        f"Assembly failed at t = {t:.6g} s: no configuration satisfies the constraints near "
        f"the q0 estimates (smallest residual {resid:.3g}, largest in {name}). Check the "
        "link lengths and joint points, and give q0 closer to the intended configuration.",
        t=t, results=res, residual=resid, constraint=cons[worst - 1].name if worst > 0 else None)


def kinematic_failure(analysis: str, model: ModelDescription, p: Packed, status: int, msg: str,
                      iinfo: np.ndarray, rinfo: np.ndarray, qsing: np.ndarray, dep: np.ndarray,
                      red: np.ndarray, res: KinematicsResult) -> MbdError:
    """The typed exception for a status of a kinematic run (``analysis`` "kinematics" or
    "inverse"), with names in the message."""
    cons = model.constraints
    if status == BAD_COUNT and int(iinfo[8]) > 0:
        rank = int(iinfo[8])
        return error_for(analysis, status,
                         f"the model is not kinematically determined at the assembled "
                         f"configuration: J has rank {rank} for {p.nq} coordinates "
                         f"({count_detail(p)}), so {p.nq - rank} degree(s) of freedom are "
                         "not driven; run model.analyze_dof() to see which equations are "
                         "redundant, and add a driver for each free degree of freedom",
                         entry=f"model {model.name!r}")
    if status < 0:
        bad = int(iinfo[1])
        return error_for(analysis, status, msg,
                         entry=cons[bad - 1].describe() if bad else f"model {model.name!r}")
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
            res.stats["dead_centre"] = t     # marked on the time axes of the pictures
            text = (f"Singular configuration (dead centre) at t = {t:.10f} s: {where} "
                    f"(J lost rank; sigma_min/sigma_max = {ratio:.1e}). The mechanism cannot "
                    "move further as driven: end the run before this time, or change the "
                    "driver or the link lengths. Results up to "
                    f"{last} ({len(res.t)} rows) are kept in the exception's .results.")
        else:
            text = (f"The assembled configuration at t = {t:.6g} s is singular: {where} "
                    f"(sigma_min/sigma_max = {ratio:.1e}). Start the run away from the dead "
                    "centre (another t0 or driver offset).")
        return error_for(analysis, status, text, t=t, results=res, driver=driver,
                         dependent=dep_names, q=np.array(qsing), sigma_min=float(rinfo[1]),
                         sigma_max=float(rinfo[2]))
    if status == INCONSISTENT:
        return inconsistent(analysis, model, p, float(rinfo[3]), dep, red, int(iinfo[8]), t,
                            res, level=int(iinfo[4]))
    if status == ASSEMBLY_FAILED:
        return assembly_failed(analysis, model, float(rinfo[3]), int(iinfo[3]), t, res)
    if status == NO_CONVERGENCE:
        return error_for(analysis, status,
                         f"Newton-Raphson failed after t = {t:.6g} s: {msg}. Results up to "
                         f"{last} are kept in the exception's .results.", t=t, results=res)
    return error_for(analysis, status, msg, t=t, results=res)

