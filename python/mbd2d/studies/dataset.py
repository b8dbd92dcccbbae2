"""A sweep's outputs as an ``xarray.Dataset``: per case its status and message (the text the
analysis would raise for that variant alone), its rows up to a failure, NaN after them."""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Sequence

import numpy as np

from ..analysis.dynamics import dynamics_error
from ..analysis.frf import frf_error
from ..analysis.inverse import inverse_error
from ..analysis.kinematics import kinematics_error
from ..analysis.outputs import dynamics_result, finite_part
from ..analysis.sensitivities import attach, check_status
from ..analysis.statics import STABILITY, statics_error
from ..binding.pack import pack
from ..binding.status import INCONSISTENT, OK
from ..description.builder import ModelDescription
from ..description.parameters import find
from ..errors import MbdError
from ..results.kinematics import KinematicsResult
from ..results.measures import measure_failure
from ..results.reactions import driver_rows
from .plan import Plan
from .runner import Outputs

#: the extra that holds xarray, for messages
EXTRA = "pip install 'mbd2d[sweep]' (xarray, dask[distributed], h5netcdf, pandas, tqdm)"


def xarray() -> Any:
    """The xarray module.

    Raises
    ------
    ImportError
        Naming the extra to install when it is missing.
    """
    try:
        import xarray as xr
    except ImportError:
        raise ImportError(f"sweeps and tolerance analyses return an xarray.Dataset: {EXTRA}") \
            from None
    return xr


def _case(out: Outputs, j: int) -> SimpleNamespace:
    """Case j of the batch outputs, shaped as the front doors' core outputs."""
    a = out.arrays
    return SimpleNamespace(status=int(out.status[j]), msg=out.msg[j],
                           **{k: a[k][..., j] for k in a},
                           resid=float(a["rinfo"][0, j]))


def _finite_rows(pl: Plan, out: Outputs) -> np.ndarray:
    """(nrow, ncase): every output of the row is finite."""
    a = out.arrays
    fin = np.ones(a["q"].shape[1:], dtype=bool)
    for k in ("q", "qd", "qdd", "lam", "e"):
        if a[k].shape[0] and a[k].shape[1]:       # (none: no multipliers, positions only)
            fin &= np.isfinite(a[k]).all(axis=0)
    for k in ("sq", "sqd", "sqdd", "slam"):      # (nq or nsl, npar, nrow, ncase)
        if a[k].shape[0] and a[k].shape[1]:
            fin &= np.isfinite(a[k]).all(axis=(0, 1))
    return fin


def _with_sensitivities(pl: Plan, model: ModelDescription, res: Any, c: SimpleNamespace,
                        n: int) -> Any:
    """The case's result with its sensitivities (the first n rows), as a run with them."""
    if not pl.tables.npar:
        return res
    names = pl.tables.sensitivities
    arrays = {k: getattr(c, k) for k in ("sq", "sqd", "sqdd")}
    if pl.tables.nsl:
        arrays["slam"] = c.slam
    attach(res, SimpleNamespace(**arrays), find(model, names, "sweep"), n, pl.tables.ptab)
    return res


def outcomes(pl: Plan, model: ModelDescription, out: Outputs, names: Sequence[str],
             values: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Rows kept, status and message of every case.

    A case that completed has status 0 and an empty message. Any other case has the status
    of the exception its analysis raises for that variant alone (``err.status``; the core's
    status for bad input) and that exception's text, and keeps the rows that exception
    carries.
    """
    ncase = len(out.status)
    a = out.arrays
    if pl.analysis in ("statics", "frf"):      # (the frequency response: all or nothing)
        n = np.where(out.status == OK, 1 if pl.analysis == "statics" else pl.tables.nrow, 0)
    else:               # (modes: the free motions, at most the modes asked for)
        n = a["iinfo"][0].astype(np.int64).clip(0, pl.tables.nrow)
    fin = _finite_rows(pl, out)
    inside = np.arange(fin.shape[0])[:, None] < n[None, :]
    clean = (out.status == OK) & ~((~fin) & inside).any(axis=0)
    if pl.analysis in ("statics", "modes", "frf"):
        clean &= np.isfinite(a["rinfo"][0])
    rows = np.where(clean, n, 0)
    status = np.zeros(ncase, dtype=np.int32)
    messages = [""] * ncase
    for j in np.flatnonzero(clean & (a["mbad"][0] != OK)):    # its rows, not its measures
        bad = a["mbad"][:, j]
        exc = measure_failure(model, pl.packed, pl.tables.measures.specs[int(bad[1]) - 1],
                              int(bad[0]), out.msg[j], int(bad[2]))
        status[j] = int(getattr(exc, "status", 0) or bad[0])
        messages[j] = str(exc)
    for j in np.flatnonzero(~clean):
        exc = _failure(pl, model, _case(out, int(j)), int(n[j]), names, values[:, j])
        if exc is None:          # pragma: no cover - the same test as the front door's
            rows[j] = n[j]
            continue
        kept = getattr(exc, "results", None)
        rows[j] = len(kept.t) if kept is not None and hasattr(kept, "t") else 0
        status[j] = int(getattr(exc, "status", 0) or out.status[j])
        messages[j] = str(exc)
    return rows, status, messages


def _failure(pl: Plan, model: ModelDescription, c: SimpleNamespace, n: int,
             names: Sequence[str], values: np.ndarray) -> MbdError | None:
    """The exception the analysis raises for case c alone."""
    p, t = pl.packed, pl.times

    def own() -> Any:             # the case's own tables (a rank analysis runs on them)
        return pack(model.with_params(dict(zip(names, values.tolist()))))

    try:
        if pl.tables.npar:            # a design parameter the core refused
            check_status(c.status, c.iinfo, c.msg, find(model, pl.tables.sensitivities))
        if pl.analysis == "frf":
            eq = SimpleNamespace(status=c.status, msg=c.msg, iinfo=c.iinfo, q=c.qsing,
                                 lam=np.zeros(0), resid=c.resid)
            return frf_error(model, own() if c.status == INCONSISTENT else p, eq, pl.t0, t,
                             [c.sq, c.sqd])
        if pl.analysis in ("statics", "modes"):
            return statics_error(model, own() if c.status == INCONSISTENT else p, c, pl.t0,
                                 analysis=pl.analysis)
        if pl.analysis == "kinematics":
            pos = pl.tables.nd == 0
            res: Any = KinematicsResult(t=t[:n], q=c.q.T[:n].copy(),
                                        qd=None if pos else c.qd.T[:n].copy(),
                                        qdd=None if pos else c.qdd.T[:n].copy(),
                                        body_names=p.body_names,
                                        coordinate_names=p.coordinate_names, complete=False,
                                        model=model)
            res, bad = finite_part(_with_sensitivities(pl, model, res, c, n))
            return kinematics_error(model, p, c, res, t, bad)
        res = dynamics_result(model, p, t, n, c, {}, False)
        res, bad = finite_part(_with_sensitivities(pl, model, res, c, n))
        if pl.analysis == "inverse":
            return inverse_error(model, p, c, res, t, bad)
        if c.status == INCONSISTENT and not len(res.t):
            p = own()
        return dynamics_error(model, p, c, res, t, bad, pl.method, pl.t0)
    except MbdError as exc:       # the variant's own tables are bad
        return exc


def _per_case(x: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """A core array with rows and cases last, (k, [npar,] nrow, ncase), as (ncase, nrow, k
    [, npar]), NaN outside each case's kept rows (keep: (ncase, nrow))."""
    v = np.ascontiguousarray(np.moveaxis(x, (-1, -2), (0, 1)))
    v[~keep] = np.nan
    return v


def _sensitivity_data(pl: Plan, a: dict[str, np.ndarray], keep: np.ndarray
                      ) -> dict[str, Any]:
    """The sensitivities as Dataset variables (case, time, entry, parameter), NaN after each
    case's kept rows; with multipliers the efforts' too (-dlambda/dp of the driver rows)."""
    def per_case(x: np.ndarray) -> np.ndarray:
        return _per_case(x, keep)

    cube = ("case", "time", "coordinate", "parameter")
    data: dict[str, Any] = {"dq_dp": (cube, per_case(a["sq"])),
                            "dqd_dp": (cube, per_case(a["sqd"])),
                            "dqdd_dp": (cube, per_case(a["sqdd"]))}
    if pl.tables.nsl:
        p = pl.packed
        dlam = per_case(a["slam"])
        data["dlam_dp"] = (("case", "time", "equation", "parameter"), dlam)
        rows_d, drivers = driver_rows(p)
        if drivers:
            data["deffort_dp"] = (("case", "time", "driver", "parameter"), -dlam[:, :, rows_d])
    return data


def to_dataset(pl: Plan, analysis: str, model: ModelDescription, out: Outputs,
               names: Sequence[str], values: np.ndarray) -> Any:
    """The Dataset of a sweep (see :func:`mbd2d.sweep`)."""
    xr = xarray()
    rows, status, messages = outcomes(pl, model, out, names, values)
    p, b = pl.packed, pl.tables
    keep = np.arange(b.nrow)[None, :] < rows[:, None]          # (ncase, nrow)

    def per_case(x: np.ndarray) -> np.ndarray:
        return _per_case(x, keep)

    a = out.arrays
    if pl.analysis in ("modes", "frf"):
        data, coords = (_modes_data(pl, a, status == 0, keep) if pl.analysis == "modes" else
                        _frf_data(pl, a, status == 0))
        return xr.Dataset(_case_columns(data, coords, status, messages, names, values),
                          coords=coords, attrs=_attrs(pl, analysis, model, names, status))
    cube = ("case", "time", "coordinate")
    data: dict[str, Any] = {"q": (cube, per_case(a["q"]))}
    if b.nd:                                                   # (not positions only)
        data.update(qd=(cube, per_case(a["qd"])), qdd=(cube, per_case(a["qdd"])))
    coords: dict[str, Any] = {"case": np.arange(len(status)), "time": pl.times,
                              "coordinate": list(p.coordinate_names)}
    if b.npar:
        data.update(_sensitivity_data(pl, a, keep))
        coords["parameter"] = list(b.sensitivities)
    if b.measures.specs:
        m = per_case(a["m"])
        m[a["mbad"][0] != OK] = np.nan
        data["measures"] = (("case", "time", "measure"), m)
        coords["measure"] = list(b.measures.specs)
        if b.npar:
            dm = per_case(a["dm"])
            dm[a["mbad"][0] != OK] = np.nan
            data["dmeasures_dp"] = (("case", "time", "measure", "parameter"), dm)
    if b.nlam:
        lam = per_case(a["lam"])
        data["lam"] = (("case", "time", "equation"), lam)
        coords["equation"] = list(p.row_labels)
        rows_d, drivers = driver_rows(p)
        if drivers:
            data["effort"] = (("case", "time", "driver"), -lam[:, :, rows_d])
            coords["driver"] = drivers
        e = per_case(a["e"])
        if pl.analysis != "statics":
            data["kinetic"] = (("case", "time"), e[:, :, 0])
            data["potential"] = (("case", "time"), e[:, :, 1])
    if pl.analysis == "statics":
        ok = rows > 0
        data["stability"] = ("case", np.array(
            [STABILITY.get(int(s), "unknown") if k else "" for s, k in zip(a["rinfo"][1], ok)],
            dtype=object))
        data["residual"] = ("case", np.where(ok, a["rinfo"][0], np.nan))
    if pl.analysis == "dynamics":                 # dopri5, partitioned: steps set by stability
        data["stiff_from"] = ("case", np.where(a["iinfo"][10] == 1, a["rinfo"][10], np.nan))
    return xr.Dataset(_case_columns(data, coords, status, messages, names, values),
                      coords=coords, attrs=_attrs(pl, analysis, model, names, status))


def _case_columns(data: dict[str, Any], coords: dict[str, Any], status: np.ndarray,
                  messages: list[str], names: Sequence[str], values: np.ndarray
                  ) -> dict[str, Any]:
    """data with each case's status and message; the parameters added to coords."""
    data["status"] = ("case", status)
    data["message"] = ("case", np.array(messages, dtype=object))
    for k, name in enumerate(names):
        coords[name] = ("case", values[k].copy())
    return data


def _attrs(pl: Plan, analysis: str, model: ModelDescription, names: Sequence[str],
           status: np.ndarray) -> dict[str, Any]:
    """The Dataset's attributes: the analysis, its settings and the count of failures."""
    attrs = {"analysis": analysis, "run": pl.analysis, "model": model.name,
             "parameters": ", ".join(names),
             "settings": ", ".join(f"{k}={v!r}" for k, v in pl.settings.items()
                                   if k != "frequencies"),     # (a frf's: a coordinate)
             "failed": int((status != 0).sum())}
    if pl.method:
        attrs["method"] = pl.method
    return attrs


def _modes_data(pl: Plan, a: dict[str, np.ndarray], ran: np.ndarray, keep: np.ndarray
                ) -> tuple[dict[str, Any], dict[str, Any]]:
    """A modes sweep's variables (as many modes as the case with the most; NaN past each
    case's modes, and for a failed case): per
    case and mode ``omega2``, ``frequency`` (Hz), ``kind`` (1 vibration, 0 rigid, -1
    unstable) and ``shape`` (coordinate), per case and damped eigenvalue ``s_real``,
    ``s_imag``, ``damping_ratio``, ``damped_frequency``, per case the equilibrium ``q``,
    ``n_free``, ``stability`` and ``residual``; and the coordinates. ran: (case) the cases
    that completed."""
    p = pl.packed
    nm = int(keep.sum(axis=1).max(initial=0))                  # the most modes of a case
    e = _per_case(a["e"], keep)[:, :nm]                        # (case, mode, 6)
    w2 = e[:, :, 0]
    re = e[:, :, [2, 4]].reshape(len(ran), -1)                 # (case, eigenvalue)
    im = e[:, :, [3, 5]].reshape(len(ran), -1)
    mod = np.hypot(re, im)
    zeta = np.divide(-re, mod, out=np.where(np.isnan(mod), np.nan, 0.0), where=mod > 0) + 0.0
    data: dict[str, Any] = {
        "omega2": (("case", "mode"), w2),
        "frequency": (("case", "mode"), np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)),
        "kind": (("case", "mode"), e[:, :, 1]),
        "shape": (("case", "mode", "coordinate"), _per_case(a["q"], keep)[:, :nm]),
        "s_real": (("case", "eigenvalue"), re), "s_imag": (("case", "eigenvalue"), im),
        "damping_ratio": (("case", "eigenvalue"), zeta),
        "damped_frequency": (("case", "eigenvalue"), np.abs(im) / (2 * np.pi)),
        "q": (("case", "coordinate"), np.where(ran[:, None], a["qsing"].T, np.nan)),
        "n_free": ("case", np.where(ran, a["iinfo"][0], -1).astype(np.int64)),
        "stability": ("case", np.array([STABILITY.get(int(s), "not examined") if k else ""
                                        for s, k in zip(a["rinfo"][1], ran)], dtype=object)),
        "residual": ("case", np.where(ran, a["rinfo"][0], np.nan))}
    coords: dict[str, Any] = {"case": np.arange(len(ran)), "mode": np.arange(nm),
                              "eigenvalue": np.arange(2 * nm),
                              "coordinate": list(p.coordinate_names)}
    return data, coords


def _frf_data(pl: Plan, a: dict[str, np.ndarray], ran: np.ndarray
              ) -> tuple[dict[str, Any], dict[str, Any]]:
    """A frequency response sweep's variables: ``response`` (complex amplitudes over case,
    frequency, coordinate, input; NaN for a failed case), per case the equilibrium ``q``,
    ``n_free``, ``stability`` and ``residual``; and the coordinates (frequency in Hz). ran:
    (case) the cases that completed."""
    p, b = pl.packed, pl.tables
    h = np.transpose(a["sq"] + 1j * a["sqd"], (3, 2, 0, 1))    # (case, frequency, nq, input)
    h[~ran] = np.nan
    neq = b.neq
    hl = np.transpose(a["slam"][:neq] + 1j * a["slam"][neq:], (3, 2, 0, 1))
    hl[~ran] = np.nan                                          # (case, frequency, neq, input)
    data: dict[str, Any] = {
        "response": (("case", "frequency", "coordinate", "input"), h),
        "lam_response": (("case", "frequency", "equation", "input"), hl),
        "q": (("case", "coordinate"), np.where(ran[:, None], a["qsing"].T, np.nan)),
        "n_free": ("case", np.where(ran, a["iinfo"][0], -1).astype(np.int64)),
        "stability": ("case", np.array([STABILITY.get(int(s), "not examined") if k else ""
                                        for s, k in zip(a["rinfo"][1], ran)], dtype=object)),
        "residual": ("case", np.where(ran, a["rinfo"][0], np.nan))}
    coords: dict[str, Any] = {"case": np.arange(len(ran)), "frequency": pl.times.copy(),
                              "coordinate": list(p.coordinate_names),
                              "equation": list(p.row_labels), "input": list(b.sensitivities)}
    rows_d, drivers = driver_rows(p)
    if drivers:                                      # (an effort is -lambda on its row)
        data["effort_response"] = (("case", "frequency", "driver", "input"), -hl[:, :, rows_d])
        coords["driver"] = drivers
    return data, coords


__all__ = ["to_dataset", "outcomes", "xarray", "EXTRA"]
