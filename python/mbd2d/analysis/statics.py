"""Statics front door: static equilibrium near the q0 estimates, in one core call."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import (ASSEMBLY_FAILED, INCONSISTENT, NO_CONVERGENCE, OK, SINGULAR,
                              error_for)
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import MbdError
from ..results.statics import StaticsResult
from ..validate import number
from .contacts import check_statics
from .failures import assembly_failed, bad_entry, inconsistent_at
from .sensitivities import check_status, requested, table
from .settings import solver_code

STABILITY = {1: "stable", 0: "unstable", -1: "neutral", 2: "fully constrained"}


def run_statics(model: ModelDescription, t: float = 0.0, sensitivities: Any = None,
                solver: str = "auto") -> StaticsResult:
    """Static equilibrium near the q0 estimates; see :meth:`mbd2d.Model.statics`."""
    t = number(t, "t", "statics")
    code = solver_code(solver)
    check_statics(model)
    params = requested(model, sensitivities)
    p = pack(model)
    d = pack_dynamics(model, p)
    if params:
        ptab = table(p, params, d)
        out = core.statics_sens(p, d, t, ptab, code)
        check_status(out.status, out.iinfo, out.msg, params)
    else:
        out = core.statics(p, d, t, code)
    exc = statics_error(model, p, out, t)
    if exc is not None:
        raise exc
    res = StaticsResult(t=t, q=out.q, lam=out.lam,
                        stability=STABILITY.get(int(out.stable), "unknown"),
                        residual=float(out.resid), body_names=p.body_names,
                        coordinate_names=p.coordinate_names, row_labels=p.row_labels,
                        model=model, packed=p,
                        stats={"solver": "banded" if int(out.iinfo[4]) == 2 else "dense",
                               "band": (int(out.iinfo[5]), int(out.iinfo[6]))})
    if params:
        if not (np.isfinite(out.sq).all() and np.isfinite(out.slam).all()):
            raise error_for("statics", NO_CONVERGENCE, "the sensitivities of the equilibrium "
                            "are not finite (the equilibrium is not isolated)", t=t,
                            residual=float(out.resid))
        res.parameter_names = [prm.name for prm in params]
        res.dq_dp, res.dlam_dp, res.ptab = out.sq.copy(), out.slam.copy(), ptab
    return res


def statics_error(model: ModelDescription, p: Packed, out: Any, t: float,
                  analysis: str = "statics") -> MbdError | None:
    """The exception a statics call ends in, or None when it found a finite equilibrium.

    ``out`` carries the core's ``status``, ``msg``, ``iinfo``, ``q``, ``lam`` and ``resid``
    (as :func:`mbd2d.binding.core.statics` returns them); p the tables of the model solved
    (a rank analysis of them names contradicting constraints); analysis: the key of
    :data:`~mbd2d.binding.status.ERRORS` and the name in the messages ("statics", "modes").
    """
    status, text = out.status, out.msg
    if status < 0:
        return error_for(analysis, status, text, entry=bad_entry(model, int(out.iinfo[1])))
    if status == ASSEMBLY_FAILED:
        return assembly_failed(analysis, model, float(out.resid), 0, t, None)
    if status == INCONSISTENT:
        return inconsistent_at(analysis, model, p, t, None, text)
    own = text.startswith(("modes:", "frequency response:", "linearized system:"))
    if status == NO_CONVERGENCE and not own:
        text = f"{text} (no equilibrium found near the q0 estimates; give q0 closer to one)"
    elif status == SINGULAR and not own:   # (modes: a massless motion)
        text = (f"{text} (the equilibrium is not unique: a motion without stiffness, such as "
                "a free rotation, is left; add a spring or a driver)")
    if status != OK:
        return error_for(analysis, status, text, t=t, residual=float(out.resid))
    if not (np.isfinite(out.q).all() and np.isfinite(out.lam).all()
            and np.isfinite(out.resid)):
        return error_for(analysis, NO_CONVERGENCE, "the equilibrium iteration gave non-finite "
                         "values; give q0 closer to an equilibrium", t=t,
                         residual=float(out.resid))
    return None
