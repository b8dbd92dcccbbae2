"""Modes front door: small vibrations about an equilibrium, in one core call."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import NO_CONVERGENCE, error_for
from ..description.builder import ModelDescription
from ..errors import ModelError
from ..results.modes import ModesResult
from ..validate import flag, number
from .contacts import check_statics
from .settings import solver_code
from .statics import STABILITY, statics_error

#: without a count, every free motion's mode; past this many coordinates, the lowest few
ALL_MODES_MAX_NQ = 3000
FEW_MODES = 20


def run_modes(model: ModelDescription, t: float = 0.0, count: int | None = None,
              equilibrium: bool = True, solver: str = "auto") -> ModesResult:
    """Natural frequencies, damping and mode shapes; see :meth:`mbd2d.Model.modes`."""
    t = number(t, "t", "modes")
    code = solver_code(solver)
    equilibrium = flag(equilibrium, "equilibrium", "modes")
    check_statics(model)
    p = pack(model)
    d = pack_dynamics(model, p)
    kmax = mode_count(count, p.nq)
    out = core.modes(p, d, t, equilibrium, kmax, code)
    exc = statics_error(model, p, out, t, analysis="modes")
    if exc is not None:
        raise exc
    nk = min(kmax, int(out.iinfo[0]))
    s = out.sre[:2 * nk] + 1j * out.sim[:2 * nk]
    psi = out.zre[:, :2 * nk] + 1j * out.zim[:, :2 * nk]
    if not (np.isfinite(out.omega2[:nk]).all() and np.isfinite(s).all()
            and np.isfinite(out.shapes[:, :nk]).all() and np.isfinite(psi).all()):
        raise error_for("modes", NO_CONVERGENCE, "modes: the eigenvalues are not finite "
                        "(the linearized equations are singular)", t=t,
                        residual=float(out.resid))
    stability = STABILITY.get(int(out.stable), "not examined (equilibrium=False)")
    return ModesResult(t=t, q=out.q, lam=out.lam, stability=stability,
                       residual=float(out.resid), omega2=out.omega2[:nk].copy(),
                       eigenvalues=s, shapes=out.shapes[:, :nk].copy(), damped_shapes=psi,
                       kind_codes=out.kinds[:nk].astype(int),
                       n_free=int(out.iinfo[0]), body_names=p.body_names,
                       coordinate_names=p.coordinate_names, model=model, packed=p,
                       stats={"solver": "banded" if int(out.iinfo[4]) == 2 else "dense"})


def mode_count(count: Any, nq: int) -> int:
    """The number of modes to ask the core for: count, or every free motion (at most nq; the
    lowest FEW_MODES past ALL_MODES_MAX_NQ coordinates)."""
    if count is None:
        return nq if nq <= ALL_MODES_MAX_NQ else FEW_MODES
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ModelError(f"count must be a positive whole number of modes, not {count!r}",
                         "modes")
    return int(min(count, nq))
