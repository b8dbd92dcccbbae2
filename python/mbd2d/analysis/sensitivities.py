"""Design sensitivities in the analysis front doors: the requested parameters checked by name,
their table for the core, and the core's arrays put into the result."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..binding.params import parameter_table
from ..binding.tables import DynamicTables, Packed
from ..description.parameters import Parameter, find
from ..errors import ModelError

#: iinfo(2) of the core below this names a bad design parameter (-2000000 - its column)
BAD_PARAMETER = -2000000


def requested(model: Any, names: Sequence[str] | None) -> list[Parameter] | None:
    """The design parameters called names (None: no sensitivities).

    Raises
    ------
    ModelError
        For an unknown name (with the closest names) or a repeated one.
    """
    if names is None:
        return None
    fric = [j.name for j in model.joints if getattr(j, "friction", None) is not None]
    if getattr(model, "contacts", None) or fric:
        raise ModelError("design sensitivities do not carry contacts or joint friction "
                         f"({', '.join([c.name for c in model.contacts] + fric)}): their "
                         "events make the motion non-smooth in the parameters; run without "
                         "sensitivities=", "sensitivities")
    params = find(model, names, "sensitivities")
    if not params:
        raise ModelError("sensitivities=[] names no parameter; give parameter names "
                         "(model.parameters() lists them) or leave it out", "sensitivities")
    return params


def check_positions_only(params: list[Parameter] | None, positions_only: bool) -> None:
    """Kinematic sensitivities need every step's velocities and accelerations."""
    if positions_only and params:
        raise ModelError("sensitivities need the velocities and accelerations of every "
                         "step: drop positions_only=True to ask for them", "analysis")


#: the dynamics methods with sensitivities: dopri5 integrates the variational equations with
#: the state, generalized-alpha differentiates its discrete equations
SENSITIVITY_METHODS = ("dopri5", "generalized-alpha")


def check_sens_method(params: list[Parameter] | None, method: str, what: str) -> None:
    """Forward dynamics has sensitivities by dopri5 and generalized-alpha."""
    if params and method not in SENSITIVITY_METHODS:
        raise ModelError(f"sensitivities are integrated with dopri5 (the variational "
                         f"equations with the state) or generalized-alpha (its discrete "
                         f"equations differentiated); method {method!r} has none", what)


def table(p: Packed, params: list[Parameter], d: DynamicTables | None = None) -> np.ndarray:
    """The core's parameter table."""
    return parameter_table(p, params, d)


def check_status(status: int, iinfo: Any, msg: str, params: list[Parameter]) -> None:
    """Raise the ModelError for a design parameter the core refused."""
    bad = int(iinfo[1])
    if status < 0 and bad <= BAD_PARAMETER:
        k = BAD_PARAMETER - bad
        name = params[k - 1].name if 0 < k <= len(params) else "sensitivities"
        raise ModelError(msg, name)


def attach(res: Any, out: Any, params: list[Parameter], n: int, ptab: np.ndarray) -> None:
    """Put the first n rows of the core's sensitivity arrays (nq, np, rows) into res as
    (rows, nq, np)."""
    res.parameter_names = [prm.name for prm in params]
    res.dq_dp, res.dqd_dp, res.dqdd_dp = rows(out.sq, n), rows(out.sqd, n), rows(out.sqdd, n)
    if hasattr(out, "slam"):
        res.dlam_dp = rows(out.slam, n)
    res.ptab = ptab


def rows(a: np.ndarray, n: int) -> np.ndarray:
    """The core's (nq, np, rows) array as (rows, nq, np), its first n rows: a view of the
    core's own array when all rows are kept (no copy), else a copy."""
    v = np.transpose(a, (2, 0, 1))
    return v if n == v.shape[0] else v[:n].copy()
