"""Kinematics front door: settings checks, the one call into the core, and the result,
warnings or typed exception."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack
from ..binding.status import NO_CONVERGENCE, OK, SINGULAR_CONFIG, error_for
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import MbdError, RedundantConstraintWarning, SingularPassageWarning, warn
from ..results.kinematics import KinematicsResult
from ..validate import flag
from .failures import kinematic_failure, row_names
from .outputs import finite_part, rows
from .progress import run_core
from .sensitivities import attach, check_positions_only, check_status, requested, table
from .settings import (check_memory, check_solver, check_span, output_rows, output_steps,
                       require_determined, solver_code, time_grid)


def run_kinematics(model: ModelDescription, t_end: float, steps: int, t0: float = 0.0,
                   tol: float | None = None, maxit: int | None = None,
                   tmin: float | None = None, every: Any = 1, solver: str = "auto",
                   sensitivities: Any = None, progress: bool | None = None,
                   positions_only: bool = False) -> KinematicsResult:
    """Run a kinematic analysis in one core call; see :meth:`mbd2d.Model.kinematics`."""
    t0, t_end, steps = check_span(t0, t_end, steps)
    tol_v, maxit_v = check_solver(tol, maxit)
    nout = output_rows(steps, every)
    code = solver_code(solver)
    params = requested(model, sensitivities)
    pos = flag(positions_only, "positions_only", "analysis")
    check_positions_only(params, pos)
    p = pack(model)
    require_determined(p, model)
    npar = len(params) if params else 0
    check_memory(nout, (1 if pos else 3) * p.nq * (1 + npar), "kinematics")
    idx = output_steps(steps, every)
    if params:
        ptab = table(p, params)
        out = core.kinematics_sens(p, t0, t_end, steps, tol_v, maxit_v, float(tmin or 0.0),
                                   int(every), code, nout, ptab)
        check_status(out.status, out.iinfo, out.msg, params)
    else:
        out = run_core(lambda ctl: core.kinematics(p, t0, t_end, steps, tol_v, maxit_v,
                                                   float(tmin or 0.0), int(every), code, nout,
                                                   ctl, pos),
                       nout, "kinematics", progress, float(steps) * (p.nq + p.neq))
    iinfo, rinfo, tpass, status = out.iinfo, out.rinfo, out.tpass, out.status
    n = int(iinfo[0])
    t = time_grid(t0, t_end, steps, idx)
    npass = int(iinfo[9])
    red_cons, red_rows = row_names(p, model, out.red)
    res = KinematicsResult(t=t[:n], q=rows(out.q, n), qd=None if pos else rows(out.qd, n),
                           qdd=None if pos else rows(out.qdd, n), body_names=p.body_names,
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
    if params:
        attach(res, out, params, n, ptab)
        res, bad = finite_part(res, out.ssum[:n], ("dq_dp", "dqd_dp", "dqdd_dp"))
    else:
        res, bad = finite_part(res)
    if red_rows and status in (OK, SINGULAR_CONFIG, NO_CONVERGENCE):
        warn(f"redundant constraints: {', '.join(red_rows)} repeat what the other "
             "constraints impose (rank of J is "
             f"{int(iinfo[8])} for {p.neq} equations); kinematics solves them in least "
             "squares, exactly while they agree", RedundantConstraintWarning)
    if npass:
        times = ", ".join(f"{x:.6g}" for x in tpass[:min(npass, 5)])
        warn(f"passed through {npass} singular configuration(s) (bifurcation points, "
             f"J lost rank) at t = {times}{' ...' if npass > 5 else ''} s and stayed on "
             "the branch the run started on", SingularPassageWarning)
    exc = kinematics_error(model, p, out, res, t, bad)
    if exc is None:
        return res
    raise exc


def kinematics_error(model: ModelDescription, p: Packed, out: Any, res: KinematicsResult,
                     t: np.ndarray, bad: int | None) -> MbdError | None:
    """The exception a kinematic run ends in, or None when it completed.

    Parameters
    ----------
    model, p : the model and its tables
    out : the core's outputs (``status``, ``msg``, ``iinfo``, ``rinfo``, ``qsing``, ``dep``,
        ``red``), as :func:`mbd2d.binding.core.kinematics` returns them
    res : the result up to the failure
    t : the output times
    bad : its first row with a non-finite number (None: all finite)
    """
    if out.status == OK and bad is None:
        return None
    if out.status == OK:
        return error_for("kinematics", NO_CONVERGENCE,
                         f"the run gave non-finite values at t = {t[bad]:.6g} s; results up to "
                         f"there ({bad} rows) are kept in the exception's .results", t=t[bad],
                         results=res)
    return kinematic_failure("kinematics", model, p, out.status, out.msg, out.iinfo, out.rinfo,
                             out.qsing, out.dep, out.red, res)
