"""What a sweep runs: the case table (names and values) and the analysis with its settings,
checked as the analysis front doors check them, turned into the tables of one batch call.
"""
from __future__ import annotations

import inspect
import itertools
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..analysis.contacts import check_statics
from ..analysis.dynamics import dynamics_settings
from ..analysis.frf import frf_inputs, frequency_list
from ..analysis.modes import mode_count
from ..analysis.sensitivities import check_sens_method, check_positions_only, requested, table
from ..analysis.settings import (check_memory, check_solver, check_span, output_rows,
                                 output_steps, require_determined, solver_code, time_grid)
from ..binding.cases import case_tables
from ..binding.pack import pack, pack_dynamics
from ..binding.params import open_values
from ..binding.tables import NFT, BatchTables, DynamicTables, Packed
from ..description.builder import ModelDescription
from ..description.parameters import Parameter, find
from ..errors import ModelError
from ..results.measures import measure_tables
from ..validate import flag, number

#: the analyses a sweep runs, by the Model method's name, and the core's batch code
#: ("frf": the frequency response, :meth:`mbd2d.Model.frequency_response`)
ANALYSES = {"kinematics": 1, "inverse_dynamics": 2, "statics": 3, "dynamics": 4, "modes": 5,
            "frf": 6}
MAX_CASES = 10**8


# ------------------------------------------------------------------ the case table

def case_values(cases: Any, where: str = "sweep") -> tuple[list[str], np.ndarray]:
    """Names and values (n_params, n_cases) of a case table: a mapping name -> 1-D sequence
    (one case per index, equal lengths) or a pandas DataFrame whose columns are names.

    Raises
    ------
    ModelError
        For anything else, unequal lengths, no case, or a value that is not a finite number.
    """
    if hasattr(cases, "columns") and hasattr(cases, "to_numpy"):      # a DataFrame
        cases = {c: cases[c].to_numpy() for c in cases.columns}
    if not isinstance(cases, Mapping) or not cases:
        raise ModelError("cases must be a dict {parameter name: values} (one case per "
                         "index) or a pandas DataFrame with parameter names as columns; "
                         "mbd2d.grid({...}) builds a full-factorial one", where)
    names, cols = [], []
    for name, v in cases.items():
        if not isinstance(name, str):
            raise ModelError(f"case table column {name!r} is not a parameter name "
                             "(model.parameters() lists them)", where)
        try:
            a = np.asarray(v, dtype=np.float64)
        except (TypeError, ValueError, OverflowError):
            raise ModelError(f"the values of {name!r} must be numbers", where) from None
        if a.ndim != 1 or a.size == 0:
            raise ModelError(f"the values of {name!r} must be a non-empty 1-D list (one "
                             f"value per case), got shape {a.shape}", where)
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise ModelError(f"{name!r} has a value that is not a finite number in case "
                             f"{int(bad[0])}: {v[int(bad[0])]!r}", where)
        names.append(name)
        cols.append(a)
    lengths = {len(a) for a in cols}
    if len(lengths) != 1:
        raise ModelError("every parameter needs one value per case: the lengths are "
                         + ", ".join(f"{n} {len(a)}" for n, a in zip(names, cols)), where)
    if len(cols[0]) > MAX_CASES:
        raise ModelError(f"at most {MAX_CASES} cases in one sweep", where)
    return names, np.array(cols)


def grid(values: Mapping[str, Sequence[float]]) -> dict[str, np.ndarray]:
    """The full-factorial case table of the given values: every combination, the first
    parameter varying slowest.

    Parameters
    ----------
    values : dict
        Parameter name -> 1-D sequence of its values.

    Returns
    -------
    dict
        Parameter name -> values, one case per index (``prod(len(v))`` cases): a case table
        for :func:`mbd2d.sweep`.

    Raises
    ------
    ModelError
        If values is not such a mapping.

    Examples
    --------
    >>> import mbd2d
    >>> g = mbd2d.grid({"a": [1.0, 2.0], "b": [10.0, 20.0, 30.0]})
    >>> g["a"].tolist(), g["b"].tolist()
    ([1.0, 1.0, 1.0, 2.0, 2.0, 2.0], [10.0, 20.0, 30.0, 10.0, 20.0, 30.0])
    """
    names, axes = [], []
    if not isinstance(values, Mapping) or not values:
        raise ModelError("grid takes a dict {parameter name: values}", "grid")
    total = 1
    for name, v in values.items():
        n, a = case_values({name: v}, "grid")
        names += n
        axes.append(a[0])
        total *= len(a[0])
        if total > MAX_CASES:
            raise ModelError(f"the grid has more than {MAX_CASES} cases", "grid")
    combos = np.array(list(itertools.product(*axes)), dtype=np.float64).reshape(-1, len(axes))
    return {name: combos[:, k].copy() for k, name in enumerate(names)}


# ------------------------------------------------------------------ the analysis

@dataclass
class Plan:
    """One sweep's analysis: the batch tables (values aside), the tables it was built from,
    the output times and what the analysis reports."""

    analysis: str                     # the front door's name ("kinematics", "inverse", ...)
    tables: BatchTables
    packed: Packed
    params: list[Parameter]
    times: np.ndarray
    settings: dict[str, Any] = field(default_factory=dict)
    method: str = ""                  # dynamics: the integrator
    t0: float = 0.0

    @property
    def has_lam(self) -> bool:
        return self.tables.nlam > 0


def _bind(fn: Callable[..., Any], kw: Mapping[str, Any], analysis: str) -> dict[str, Any]:
    """The settings kw checked against the front door's signature (a ModelError naming the
    settings it takes otherwise)."""
    if "sensitivities" in kw:
        raise ModelError("sensitivities= is a keyword of mbd2d.sweep and mbd2d.export_sweep "
                         "(mbd2d.tolerance computes its own)", "sweep")
    sig = inspect.signature(fn)
    try:
        bound = sig.bind(**kw)
    except TypeError as exc:
        allowed = ", ".join(p for p in sig.parameters if p != "sensitivities")
        raise ModelError(f"{analysis}: {exc}; the settings are {allowed}", "sweep") from None
    bound.apply_defaults()
    return dict(bound.arguments)


def _kinematics_settings(t_end: Any, steps: Any, t0: Any = 0.0, tol: Any = None,
                         maxit: Any = None, every: Any = 1, solver: Any = "auto",
                         positions_only: Any = False) -> None:
    """Settings of a kinematic sweep (as :meth:`mbd2d.Model.kinematics`)."""


def _inverse_settings(t_end: Any, steps: Any, t0: Any = 0.0, tol: Any = None,
                      every: Any = 1, solver: Any = "auto") -> None:
    """Settings of an inverse dynamics sweep (as :meth:`mbd2d.Model.inverse_dynamics`)."""


def _statics_settings(t: Any = 0.0) -> None:
    """Settings of a statics sweep (as :meth:`mbd2d.Model.statics`)."""


def _modes_settings(t: Any = 0.0, count: Any = None, equilibrium: Any = True,
                    solver: Any = "auto") -> None:
    """Settings of a modes sweep (as :meth:`mbd2d.Model.modes`)."""


def _frf_settings(inputs: Any, frequencies: Any, t: Any = 0.0, equilibrium: Any = True,
                  solver: Any = "auto") -> None:
    """Settings of a frequency response sweep (as :meth:`mbd2d.Model.frequency_response`)."""


def _dynamics_settings(t_end: Any, steps: Any, method: Any = None, rtol: Any = None,
                       atol: Any = None, h: Any = None, rho_inf: Any = None, alpha: Any = None,
                       beta: Any = None, t0: Any = 0.0, every: Any = 1,
                       max_steps: Any = None) -> None:
    """Settings of a forward dynamics sweep (as :meth:`mbd2d.Model.dynamics`)."""


def _tables(code: int, p: Packed, d: DynamicTables | None, iset: list[int], rset: list[float],
            nrow: int, nlam: int, ne: int) -> BatchTables:
    if d is None:
        d = DynamicTables(np.zeros((2, p.nb), order="F"), np.zeros(2),
                          np.zeros((NFT, 0), dtype=np.int32, order="F"), np.zeros(1),
                          np.zeros(p.nq))
    rs = np.zeros(12)
    rs[:len(rset)] = rset
    iv = np.zeros(8, dtype=np.int32)
    iv[:len(iset)] = iset
    empty = np.zeros((2, 0), dtype=np.int32, order="F")
    return BatchTables(code, p.nb, p.ctab, p.rpar, np.asfortranarray(d.bmass),
                       np.asarray(d.grav, dtype=np.float64), d.ftab, d.fpar, p.q0, d.v0, empty,
                       empty, iv, rs, p.neq, nrow, nlam, ne)


def plan(model: ModelDescription, names: Sequence[str], analysis: Any,
         kw: Mapping[str, Any]) -> Plan:
    """The analysis of a sweep with its settings checked, and the base model packed.

    Raises
    ------
    ModelError
        For an unknown analysis, parameter or setting, or a model the analysis cannot run.
    """
    if not isinstance(analysis, str) or analysis not in ANALYSES:
        raise ModelError(f"unknown analysis {analysis!r}; use one of {', '.join(ANALYSES)}",
                         "sweep")
    params = find(model, list(names), "sweep")
    if analysis == "kinematics":
        a = _bind(_kinematics_settings, kw, analysis)
        a["positions_only"] = flag(a["positions_only"], "positions_only", "sweep")
        if model.has_masses() and a["maxit"] is None and not a["positions_only"]:
            a.pop("maxit")                                 # as Model.kinematics
            a.pop("positions_only")
            return _inverse(model, params, a)
        return _kinematics(model, params, a)
    if analysis == "inverse_dynamics":
        return _inverse(model, params, _bind(_inverse_settings, kw, analysis))
    if analysis == "statics":
        return _statics(model, params, _bind(_statics_settings, kw, analysis))
    if analysis == "modes":
        return _modes(model, params, _bind(_modes_settings, kw, analysis))
    if analysis == "frf":
        return _frf(model, params, _bind(_frf_settings, kw, analysis))
    return _dynamics(model, params, _bind(_dynamics_settings, kw, analysis))


def _span(a: dict[str, Any]) -> tuple[float, float, int, int, np.ndarray]:
    t0, t_end, steps = check_span(a["t0"], a["t_end"], a["steps"])
    nrow = output_rows(steps, a["every"])
    return t0, t_end, steps, nrow, time_grid(t0, t_end, steps, output_steps(steps, a["every"]))


def _kinematics(model: ModelDescription, params: list[Parameter], a: dict[str, Any]) -> Plan:
    t0, t_end, steps, nrow, times = _span(a)
    tol, maxit = check_solver(a["tol"], a["maxit"])
    code = solver_code(a["solver"])
    pos = a["positions_only"]
    p = pack(model)
    require_determined(p, model)
    b = _tables(1, p, None, [steps, maxit, int(a["every"]), code, 0, 0, int(pos)],
                [t0, t_end, tol, 0.0], nrow, 0, 0)
    return Plan("kinematics", b, p, params, times, a, t0=t0)


def _inverse(model: ModelDescription, params: list[Parameter], a: dict[str, Any]) -> Plan:
    t0, t_end, steps, nrow, times = _span(a)
    tol, _ = check_solver(a["tol"], None)
    code = solver_code(a["solver"])
    p = pack(model)
    require_determined(p, model)
    d = pack_dynamics(model, p)
    b = _tables(2, p, d, [steps, 0, int(a["every"]), code], [t0, t_end, tol, 0.0], nrow,
                p.neq, 4)
    return Plan("inverse", b, p, params, times, a, t0=t0)


def _statics(model: ModelDescription, params: list[Parameter], a: dict[str, Any]) -> Plan:
    t = number(a["t"], "t", "statics")
    p = pack(model)
    d = pack_dynamics(model, p)
    rset = [0.0] * 10 + [t]
    b = _tables(3, p, d, [], rset, 1, p.neq, 4)
    return Plan("statics", b, p, params, np.array([t]), a, t0=t)


def _modes(model: ModelDescription, params: list[Parameter], a: dict[str, Any]) -> Plan:
    t = number(a["t"], "t", "modes")
    about_q0 = not flag(a["equilibrium"], "equilibrium", "modes")
    code = solver_code(a["solver"])
    check_statics(model)
    p = pack(model)
    d = pack_dynamics(model, p)
    rset = [0.0] * 10 + [t]
    b = _tables(5, p, d, [0, 0, 1, code, 0, 0, 0, int(about_q0)], rset,
                mode_count(a["count"], p.nq), 0, 6)
    return Plan("modes", b, p, params, np.array([t]), a, t0=t)


def _frf(model: ModelDescription, params: list[Parameter], a: dict[str, Any]) -> Plan:
    """The frequency response's plan: its inputs as the batch's parameters (ptab), the
    angular frequencies as its times; the plan's times are the frequencies in Hz."""
    t = number(a["t"], "t", "frequency response")
    about_q0 = not flag(a["equilibrium"], "equilibrium", "frequency response")
    code = solver_code(a["solver"])
    freq = frequency_list(a["frequencies"])
    inputs = frf_inputs(model, a["inputs"])
    p = pack(model)
    d = pack_dynamics(model, p)
    b = _tables(6, p, d, [0, 0, 1, code, 0, 0, 0, int(about_q0)], [0.0] * 10 + [t],
                freq.size, 0, 0)
    b.times = 2 * np.pi * freq
    b.ptab = table(p, inputs, d)
    b.sensitivities = [prm.name for prm in inputs]
    return Plan("frf", b, p, params, freq, a, t0=t)


def _dynamics(model: ModelDescription, params: list[Parameter], a: dict[str, Any]) -> Plan:
    t0, t_end, steps, nrow, times = _span(a)
    st = dynamics_settings(a["method"], a["rtol"], a["atol"], a["h"], a["rho_inf"], a["alpha"],
                           a["beta"], a["max_steps"])
    p = pack(model)
    d = pack_dynamics(model, p)
    b = _tables(4, p, d, [steps, 0, int(a["every"]), 0, st.code, st.max_steps],
                [t0, t_end, 0.0, 0.0, st.rtol, st.atol, st.h, st.rho_inf, st.alpha, st.beta],
                nrow, p.neq, 4)
    return Plan("dynamics", b, p, params, times, a, method=st.method, t0=t0)


def with_cases(pl: Plan, model: ModelDescription, values: np.ndarray) -> np.ndarray:
    """Fill the plan's value table and open phases for these cases (n_params, ncase); the
    values of every case, as the core takes them (nv, ncase), and checks the memory."""
    ct = case_tables(model, pl.packed, _dynamic(pl.tables), pl.params, values)
    pl.tables.vtab, pl.tables.opens = ct.vtab, ct.opens
    b = pl.tables
    check_memory(b.nrow * values.shape[1],
                 b.nq * (3 if b.nd else 1) + b.nlam + b.ne + len(b.measures.specs)
                 + b.npar * (3 * b.nq + b.nsl), "sweep")
    return ct.vals


def _dynamic(b: BatchTables) -> DynamicTables | None:
    """The batch's dynamic tables (None for kinematics, which takes none)."""
    return None if b.analysis == 1 else DynamicTables(b.bmass, b.grav, b.ftab, b.fpar, b.v0)


def with_measures(pl: Plan, model: ModelDescription, specs: Any) -> None:
    """Add the measures asked for (specs as ``measures=`` of a table) to the plan's batch:
    each case gets them at its rows from its own tables.

    Raises
    ------
    ModelError
        For a spec the model does not have, or measures of a statics sweep.
    """
    t = measure_tables(model, pl.packed, specs, moved=True)
    if t.specs and pl.analysis in ("statics", "modes", "frf"):
        raise ModelError(f"measures are columns of a run over time, not of {pl.analysis}",
                         "sweep")
    pl.tables.measures = t
    if pl.analysis != "frf":                      # (its times: the angular frequencies)
        pl.tables.times = np.ascontiguousarray(pl.times, dtype=np.float64)


def with_sensitivities(pl: Plan, model: ModelDescription, names: Any) -> None:
    """Add design sensitivities (names as ``sensitivities=`` of a run) to the plan's batch:
    each case gets them at its rows, as a run of its own model with them.

    Raises
    ------
    ModelError
        For an unknown or repeated name, or an analysis that has none (positions-only
        kinematics, dynamics other than dopri5 and generalized-alpha, a model with contacts
        or joint friction).
    """
    params = requested(model, names)
    if not params:
        return
    if pl.analysis == "modes":
        raise ModelError("a modes sweep computes no design sensitivities (the frequencies' "
                         "change: sweep the parameter)", "sweep")
    if pl.analysis == "frf":
        raise ModelError("a frequency response sweep computes no design sensitivities (its "
                         "inputs= are the parameters varied harmonically; the response's "
                         "change with a design parameter: sweep that parameter)", "sweep")
    b = pl.tables
    check_positions_only(params, b.nd == 0 and pl.analysis == "kinematics")
    check_sens_method(params, pl.method or "dopri5", "sweep")
    b.ptab = table(pl.packed, params, _dynamic(b))
    b.sensitivities = [prm.name for prm in params]


def nominal_values(model: ModelDescription, params: Sequence[Parameter]) -> np.ndarray:
    """The parameters' values in the model (an open phase: the value taken from q0)."""
    opened = open_values(pack(model), params) if any(p.value is None for p in params) else {}
    return np.array([opened[p.name] if p.value is None else p.value for p in params],
                    dtype=np.float64)


__all__ = ["ANALYSES", "Plan", "case_values", "grid", "plan", "with_cases", "with_measures",
           "with_sensitivities", "nominal_values"]
