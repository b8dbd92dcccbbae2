"""Frequency response front door: the linearized motion about an equilibrium driven by design
parameters varied harmonically, in one core call."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack, pack_dynamics
from ..binding.status import NO_CONVERGENCE, SINGULAR, error_for
from ..description.builder import ModelDescription
from ..description.parameters import Parameter
from ..errors import MbdError, ModelError
from ..results.frf import FrequencyResponseResult
from ..validate import flag, number
from .contacts import check_statics
from .sensitivities import check_status, requested, table
from .settings import solver_code
from .statics import STABILITY, statics_error

WHAT = "frequency response"


def run_frf(model: ModelDescription, inputs: Any, frequencies: Any, t: float = 0.0,
            equilibrium: bool = True, solver: str = "auto") -> FrequencyResponseResult:
    """The frequency response; see :meth:`mbd2d.Model.frequency_response`."""
    t = number(t, "t", WHAT)
    code = solver_code(solver)
    equilibrium = flag(equilibrium, "equilibrium", WHAT)
    freq = frequency_list(frequencies)
    params = frf_inputs(model, inputs)
    p = pack(model)
    d = pack_dynamics(model, p)
    ptab = table(p, params, d)
    out = core.frf(p, d, t, equilibrium, ptab, 2 * np.pi * freq, code)
    check_status(out.status, out.iinfo, out.msg, params)
    h = np.moveaxis(out.hre + 1j * out.him, 2, 0)           # (nw, nq, np)
    exc = frf_error(model, p, out, t, freq, [h, out.lre, out.lim])
    if exc is not None:
        raise exc
    stability = STABILITY.get(int(out.stable), "not examined (equilibrium=False)")
    return FrequencyResponseResult(
        t=t, q=out.q, lam=out.lam, stability=stability, residual=float(out.resid),
        frequencies=freq, inputs=[prm.name for prm in params], response=h,
        n_free=int(out.iinfo[0]), body_names=p.body_names,
        lam_response=np.moveaxis(out.lre + 1j * out.lim, 2, 0), ptab=ptab,
        coordinate_names=p.coordinate_names, model=model, packed=p,
        stats={"solver": "banded" if int(out.iinfo[4]) == 2 else "dense"})


def frf_error(model: ModelDescription, p: Any, out: Any, t: float, freq: np.ndarray,
              arrays: list[np.ndarray], analysis: str = "frf") -> MbdError | None:
    """The exception a frequency response (or a linearized system: analysis "linearize")
    ends in, or None when it is finite.

    ``out`` carries the core's ``status``, ``msg``, ``iinfo``, ``q``, ``lam`` and ``resid``
    (the equilibrium's, as for :func:`statics_error`); freq the frequencies (Hz); arrays the
    response's arrays, which must be finite. An unbounded response names its frequency.
    """
    what = WHAT if analysis == "frf" else "linearized system"
    if out.status == SINGULAR and 0 < int(out.iinfo[7]) <= freq.size:
        f = freq[int(out.iinfo[7]) - 1]
        out.msg = (f"{out.msg}: the response at {f:g} Hz is unbounded; leave that frequency "
                   "out or give the mode damping")
    exc = statics_error(model, p, out, t, analysis=analysis)
    if exc is None and not all(np.isfinite(a).all() for a in arrays):
        exc = error_for(analysis, NO_CONVERGENCE, f"{what}: the response is not finite (the "
                        "linearized equations are singular)", t=t, residual=float(out.resid))
    return exc


def frf_inputs(model: ModelDescription, inputs: Any, what: str = WHAT) -> list[Parameter]:
    """The inputs as design parameters, checked (at least one; no contacts or friction);
    what names the analysis in the messages."""
    check_statics(model)
    try:
        names = [inputs] if isinstance(inputs, str) else list(inputs)
    except TypeError:
        names = []                                # (None, a number: no names)
    if len(names) == 0:
        raise ModelError("inputs must name at least one design parameter (model.parameters() "
                         "lists them), e.g. a force's amplitude or a spring's free length", what)
    if getattr(model, "contacts", None):
        raise ModelError(f"the {what} does not carry contacts "
                         f"({', '.join(c.name for c in model.contacts)}): their exact "
                         "derivatives are not written; use model.modes() for their "
                         "linearized frequencies", what)
    return requested(model, list(names)) or []


def frequency_list(frequencies: Any) -> np.ndarray:
    """The frequencies (Hz) as a 1-D float array: finite, not negative, at least one."""
    try:
        f = np.atleast_1d(np.asarray(frequencies, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"frequencies must be numbers in Hz, not {frequencies!r}",
                         WHAT) from None
    if f.ndim != 1 or f.size == 0 or not np.isfinite(f).all() or (f < 0).any():
        raise ModelError("frequencies must be a non-empty list of finite frequencies >= 0 "
                         f"(Hz), got {frequencies!r}", WHAT)
    return f.copy()
