"""Phi, J, nu and gamma at a given state, from the core."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack
from ..binding.status import OK, error_for
from ..description.builder import ModelDescription
from ..errors import ModelError
from ..validate import number


def evaluate(model: ModelDescription, q: Any, qd: Any, t: float) -> tuple[np.ndarray, ...]:
    """Phi, J, nu and gamma at a state, from the core."""
    p = pack(model)
    t = number(t, "t", "state")
    qv = _state(q, p.nq, "q")
    qdv = np.zeros(p.nq) if qd is None else _state(qd, p.nq, "qd")
    out = core.evaluate(p.nb, p.ctab, p.rpar, p.neq, qv, qdv, float(t))
    if out.status != OK:
        bad = int(out.bad)
        raise error_for("eval", out.status, out.msg,
                        entry=model.constraints[bad - 1].describe() if bad else "model")
    values = (out.phi, out.jac, out.nu, out.gam)
    if not all(np.isfinite(v).all() for v in values):
        raise ModelError("Phi, J, nu or gamma overflow at this state (non-finite values): "
                         "q and qd are too large for the model's dimensions", "state")
    return values


def _state(x: Any, n: int, what: str) -> np.ndarray:
    try:
        if np.iscomplexobj(x):
            raise ModelError(f"{what} must be real numbers, got complex ones", "state")
        v = np.asarray(x, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{what} must be an array of {n} numbers", "state") from None
    if v.shape != (n,):
        raise ModelError(f"{what} must have {n} entries (the model's coordinates), "
                         f"got shape {v.shape}", "state")
    if not np.all(np.isfinite(v)):
        raise ModelError(f"{what} has non-finite entries", "state")
    return np.ascontiguousarray(v)
