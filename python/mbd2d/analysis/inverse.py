"""Inverse dynamics front door: kinematics of the driven model plus the multipliers, energies
and (on demand) reactions at every output, in one core call."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import NO_CONVERGENCE, OK, error_for
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import MbdError, RedundantConstraintWarning, warn
from ..results.dynamics import DynamicsResult
from .contacts import MAX_EVENTS, report_pulls
from .failures import bad_entry, kinematic_failure, row_names
from .outputs import dynamics_result, finite_part
from .progress import run_core
from .sensitivities import attach, check_status, requested, table
from .settings import (check_memory, check_solver, check_span, output_rows, output_steps,
                       require_determined, solver_code, time_grid)


def run_inverse(model: ModelDescription, t_end: float, steps: int, t0: float = 0.0,
                tol: float | None = None, every: Any = 1, solver: str = "auto",
                sensitivities: Any = None, progress: bool | None = None) -> DynamicsResult:
    """Kinematics plus the multipliers, energies and (on demand) reactions at every output.

    See :meth:`mbd2d.Model.inverse_dynamics`.
    """
    t0, t_end, steps = check_span(t0, t_end, steps)
    tol_v, _ = check_solver(tol, None)
    nout = output_rows(steps, every)
    code = solver_code(solver)
    params = requested(model, sensitivities)
    p = pack(model)
    require_determined(p, model)
    d = pack_dynamics(model, p)
    npar = len(params) if params else 0
    check_memory(nout, (3 * p.nq + p.neq) * (1 + npar) + 4 + 6 * d.ftab.shape[1],
                 "inverse dynamics")
    idx = output_steps(steps, every)
    if params:
        ptab = table(p, params, d)
        out = core.inverse_sens(p, d, t0, t_end, steps, tol_v, int(every), code, nout, ptab)
        check_status(out.status, out.iinfo, out.msg, params)
    else:
        maxev = MAX_EVENTS if model.contacts else 1
        out = run_core(lambda ctl: core.inverse(p, d, t0, t_end, steps, tol_v, int(every),
                                                code, nout, maxev, ctl),
                       2 * nout, "inverse dynamics", progress,
                       float(steps) * (p.nq + p.neq) + nout * float(p.nq + p.neq)**2)
    iinfo, status = out.iinfo, out.status
    n = int(iinfo[0])
    t = time_grid(t0, t_end, steps, idx)
    _, red_rows = row_names(p, model, out.red)
    stats = {"newton_corrections": int(iinfo[5]), "factorizations": int(iinfo[6]),
             "rejected_steps": int(iinfo[7]), "rank": int(iinfo[8]),
             "redundant_rows": red_rows,
             "singular_passages": [float(x) for x in out.tpass[:min(int(iinfo[9]), 64)]],
             "solver": "banded" if int(out.rinfo[4]) == 2 else "dense",
             "band": (int(out.rinfo[5]), int(out.rinfo[6])),
             "multiplier_solver": "banded" if int(out.rinfo[7]) == 2 else "dense",
             "events": int(getattr(out, "nev", 0))}
    res = dynamics_result(model, p, t, n, out, stats, status == OK)
    if params:
        attach(res, out, params, n, ptab)
    res, bad = finite_part(res)
    if status == OK and bad is None:
        report_pulls(model, p, res)
    if red_rows:
        warn(f"redundant constraints: {', '.join(red_rows)}; the multipliers are the "
             "minimum-norm set (the reactions are statically indeterminate)",
             RedundantConstraintWarning)
    exc = inverse_error(model, p, out, res, t, bad)
    if exc is None:
        return res
    raise exc


def inverse_error(model: ModelDescription, p: Packed, out: Any, res: DynamicsResult,
                  t: np.ndarray, bad: int | None) -> MbdError | None:
    """The exception an inverse dynamics run ends in, or None when it completed (arguments
    as :func:`mbd2d.analysis.kinematics.kinematics_error`)."""
    status, iinfo = out.status, out.iinfo
    if status == OK and bad is None:
        return None
    if status == OK:
        return error_for("inverse", NO_CONVERGENCE,
                         f"the run gave non-finite values at t = {t[bad]:.6g} s; results up to "
                         f"there ({bad} rows) are kept in the exception's .results", t=t[bad],
                         results=res)
    if status < 0 and iinfo[1] < 0:          # a force or a body (masses)
        return error_for("inverse", status, out.msg, entry=bad_entry(model, int(iinfo[1])))
    return kinematic_failure("inverse", model, p, status, out.msg, iinfo, out.rinfo, out.qsing,
                             out.dep, out.red, res)
