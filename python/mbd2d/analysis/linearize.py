"""Linearization front door: the small motion about an equilibrium as a state-space system
whose inputs are design parameters, in one core call."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import BAD_COUNT
from ..description.builder import ModelDescription
from ..errors import ModelError
from ..results.linear import LinearizedSystem
from ..results.reactions import driver_rows
from ..validate import flag, number
from .frf import frf_error, frf_inputs
from .sensitivities import check_status, table
from .settings import solver_code
from .statics import STABILITY

WHAT = "linearized system"


def efforts_rows(p: Any, efforts: bool) -> tuple[list[int], list[str]]:
    """The drivers' rows and names (driver_rows) for the effort outputs.

    Raises
    ------
    ModelError
        When efforts are asked for and the model has no driver.
    """
    rows, drivers = driver_rows(p)
    if efforts and not drivers:
        raise ModelError("efforts=True: the model has no drivers (an effort is what a driver "
                         "holding its motion exerts)", WHAT)
    return rows, drivers


def run_linearize(model: ModelDescription, inputs: Any, t: float = 0.0,
                  equilibrium: bool = True, solver: str = "auto",
                  velocities: bool = False, efforts: bool = False) -> LinearizedSystem:
    """The linearized system; see :meth:`mbd2d.Model.linearize`."""
    t = number(t, "t", WHAT)
    code = solver_code(solver)
    equilibrium = flag(equilibrium, "equilibrium", WHAT)
    velocities = flag(velocities, "velocities", WHAT)
    efforts = flag(efforts, "efforts", WHAT)
    params = frf_inputs(model, inputs, WHAT)
    p = pack(model)
    rows, drivers = efforts_rows(p, efforts)
    d = pack_dynamics(model, p)
    ptab = table(p, params, d)
    out = core.linearize(p, d, t, equilibrium, ptab, 2 * max(p.nq - p.neq, 0), code,
                         velocities, efforts)
    if out.status == BAD_COUNT and 2 * int(out.iinfo[0]) > out.a.shape[0]:
        out = core.linearize(p, d, t, equilibrium, ptab, 2 * int(out.iinfo[0]), code,
                             velocities, efforts)
    check_status(out.status, out.iinfo, out.msg, params)
    f = int(out.iinfo[0])
    exc = frf_error(model, p, out, t, np.zeros(0), [out.a, out.b, out.c, out.d],
                    analysis="linearize")
    if exc is not None:
        raise exc
    stability = STABILITY.get(int(out.stable), "not examined (equilibrium=False)")
    nv = (2 if velocities else 1) * p.nq          # the coordinates' (and velocities') rows
    keep = list(range(nv)) + ([nv + r for r in rows] if efforts else [])
    sign = np.ones(len(keep))
    sign[nv:] = -1.0                              # an effort is -lambda on the driver's row
    return LinearizedSystem(
        t=t, q=out.q, lam=out.lam, stability=stability, residual=float(out.resid),
        a=out.a[:2 * f, :2 * f].copy(), b=out.b[:2 * f].copy(),
        c=sign[:, None] * out.c[keep, :2 * f], d=sign[:, None] * out.d[keep],
        inputs=[prm.name for prm in params],
        outputs=list(p.coordinate_names)
        + ([f"{c}_dot" for c in p.coordinate_names] if velocities else [])
        + ([f"effort.{n}" for n in drivers] if efforts else []), n_free=f, model=model,
        stats={"solver": "banded" if int(out.iinfo[4]) == 2 else "dense"})
