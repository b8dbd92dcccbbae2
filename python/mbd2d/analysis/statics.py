"""Statics front door: static equilibrium near the q0 estimates, in one core call."""
from __future__ import annotations

from typing import Any

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import ASSEMBLY_FAILED, NO_CONVERGENCE, OK, SINGULAR
from ..description.builder import ModelDescription
from ..errors import ConvergenceError, CoreError, ModelError, SingularJacobianError
from ..results.statics import StaticsResult
from ..validate import number
from .failures import assembly_failed, bad_entry
from .sensitivities import check_status, requested, table

STABILITY = {1: "stable", 0: "unstable", -1: "neutral", 2: "fully constrained"}


def run_statics(model: ModelDescription, t: float = 0.0,
                sensitivities: Any = None) -> StaticsResult:
    """Static equilibrium near the q0 estimates; see :meth:`mbd2d.Model.statics`."""
    t = number(t, "t", "statics")
    params = requested(model, sensitivities)
    p = pack(model)
    d = pack_dynamics(model, p)
    if params:
        ptab = table(p, params, d)
        out = core.statics_sens(p, d, t, ptab)
        check_status(out.status, out.iinfo, out.msg, params)
    else:
        out = core.statics(p, d, t)
    status, text = out.status, out.msg
    if status < 0:
        raise ModelError(text, bad_entry(model, int(out.iinfo[1])))
    if status == ASSEMBLY_FAILED:
        raise assembly_failed(model, float(out.resid), 0, t, None)
    if status == SINGULAR:
        raise SingularJacobianError(text, t=t, status=status)
    if status == NO_CONVERGENCE:
        raise ConvergenceError(text, t=t, status=status, residual=float(out.resid))
    if status != OK:
        raise CoreError(f"internal error in the core (status {status}): {text}")
    res = StaticsResult(t=t, q=out.q, lam=out.lam,
                        stability=STABILITY.get(int(out.stable), "unknown"),
                        residual=float(out.resid), body_names=p.body_names,
                        coordinate_names=p.coordinate_names, row_labels=p.row_labels,
                        model=model, packed=p)
    if params:
        res.parameter_names = [prm.name for prm in params]
        res.dq_dp, res.dlam_dp, res.ptab = out.sq.copy(), out.slam.copy(), ptab
    return res
