"""Tolerance analysis: how the scatter of design parameters spreads into every output, by
first-order propagation through the exact sensitivities beside a Monte Carlo estimate.

For independent parameters p_k with standard deviations sigma_k, an output y(p) has to first
order the variance

    var(y) = sum_k (dy/dp_k sigma_k)**2      (the diagonal of S Sigma S^T, Sigma = diag(sigma^2))

with S = dy/dp from the core (docs/sensitivities.md). The Monte Carlo estimate draws N
variants with p_k ~ Normal(p_k0, sigma_k), runs them as one sweep (:func:`mbd2d.sweep`, so in
a process pool or on a Dask cluster) and takes the sample standard deviation of each output
over the variants that completed. For small sigma the two agree within the Monte Carlo error
(a relative standard error of about 1/sqrt(2 (N - 1))); where they differ, the output is
nonlinear in the parameters over the scatter.

A model with contacts or joint friction has no design sensitivities (its events make the
motion non-smooth in the parameters): its report has the Monte Carlo columns alone, and the
dataset's attribute ``first_order`` says why. So have the modes' report (the natural
frequencies', damping ratios' and equilibrium's scatter) and the frequency response's (the
scatter of each response's magnitude and phase over the frequencies): their derivatives need
the model's third derivatives, which mbd2d does not write.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from ..analysis.dynamics import run_dynamics
from ..analysis.frf import run_frf
from ..analysis.sensitivities import SENSITIVITY_METHODS
from ..analysis.inverse import run_inverse
from ..analysis.kinematics import run_kinematics
from ..analysis.modes import run_modes
from ..analysis.statics import run_statics
from ..analysis.settings import check_memory
from ..description.builder import ModelDescription
from ..description.entries import reads_entries
from ..description.parameters import find
from ..errors import ModelError
from ..results.measures import measure, measure_derivatives, measure_list, parse_measure
from ..results.points import PointResult
from ..results.reactions import driver_rows
from ..validate import number, vector, whole
from .dataset import xarray
from .plan import (ANALYSES, _bind, _dynamics_settings, _frf_settings, _inverse_settings,
                   _kinematics_settings, _modes_settings, _statics_settings, nominal_values)
from .sweep import sweep


#: why the modes' report has no first-order column
MODES_FIRST_ORDER = ("none: the natural frequencies' design derivatives need the model's third "
                     "derivatives, which mbd2d does not write; the Monte Carlo columns alone")
#: why the frequency response's report has no first-order column
FRF_FIRST_ORDER = ("none: the frequency response's design derivatives need the model's third "
                   "derivatives, which mbd2d does not write; the Monte Carlo columns alone")
#: the frequency response's outputs: (magnitude, phase in degrees) of the coordinates' and the
#: drivers' efforts' responses, each over ("frequency", "coordinate" | "driver", "input")
FRF_OUTPUTS = {"magnitude": "response", "phase": "response",
               "effort_magnitude": "effort_response", "effort_phase": "effort_response"}


@dataclass
class ToleranceResult:
    """Standard deviations of every output of an analysis under parameter scatter.

    Attributes
    ----------
    dataset : xarray.Dataset
        For each output X (``q``, ``qd``, ``qdd``; ``lam`` and ``effort`` where the analysis
        has multipliers and their sensitivities): ``X`` the nominal values, ``X_std_linear``
        the first-order standard deviation, ``X_std_mc`` and ``X_mean_mc`` the Monte Carlo
        standard deviation and mean, over ("time", "coordinate" | "equation" | "driver").
        Attributes: ``samples``, ``failed`` (samples that did not complete, left out),
        ``seed``, ``sigma``, ``first_order`` ("exact sensitivities", or why there is no
        ``X_std_linear``: a model with contacts or joint friction).
    samples : xarray.Dataset
        The Monte Carlo sweep itself (:func:`mbd2d.sweep`).
    nominal : result
        The nominal analysis with its sensitivities (``dq_dp`` ...; none for a model with
        contacts or joint friction).
    sigma : dict
        Parameter name -> standard deviation.
    """

    dataset: Any
    samples: Any
    nominal: Any
    sigma: dict[str, float] = field(default_factory=dict)

    def point(self, body: str, s: Any) -> Any:
        """Scatter of a point fixed in a body, P = r + A(theta) s': an xarray.Dataset over
        "time" with ``x``, ``y`` (nominal), ``x_std_linear``, ``y_std_linear`` (first order:
        dP/dp = dr/dp + B(theta) s' dtheta/dp), ``x_std_mc``, ``y_std_mc`` (the sample
        standard deviation of P over the completed samples) and ``x_share``, ``y_share``
        over ("time", "parameter"): each parameter's share of the first-order variance (as
        :meth:`contributions`). Without a first-order column (contacts, joint friction):
        ``x``, ``y`` and the Monte Carlo ones alone.

        Raises
        ------
        KeyError
            For an unknown body.
        ModelError
            For a point that is not two finite numbers.
        """
        sx, sy = vector(s, 2, "s", "point")
        names = list(self.nominal.body_names)
        if body not in names:
            raise KeyError(f"no body {body!r}; bodies: {', '.join(names)}")
        i = 3 * names.index(body)
        q = _rows(self.nominal, self.nominal.q)
        th = q[:, i + 2]
        c, sn = np.cos(th), np.sin(th)
        t = ("time",)
        data = {"x": (t, q[:, i] + c * sx - sn * sy), "y": (t, q[:, i + 1] + sn * sx + c * sy)}
        if self.linear:
            data.update(self._point_linear(i, (sx, sy)))
        qs = np.zeros((0,) + q.shape) if self.samples is None else \
            self.samples.q.values[self.samples.status.values == 0]      # (n, time, nq)
        if qs.ndim == 2:                        # (a modes sweep's equilibria: no time axis)
            qs = qs[:, None, :]
        ths = qs[:, :, i + 2]
        data["x_std_mc"] = (t, _std(qs[:, :, i] + np.cos(ths) * sx - np.sin(ths) * sy))
        data["y_std_mc"] = (t, _std(qs[:, :, i + 1] + np.sin(ths) * sx + np.cos(ths) * sy))
        coords = {"time": self.dataset.time.values}
        if self.linear:
            coords["parameter"] = list(self.sigma)
        return xarray().Dataset(data, coords=coords,
                                attrs={"body": body, "point": f"({sx:g}, {sy:g})"})

    @property
    def linear(self) -> bool:
        """Whether the report has the first-order column (the model has design
        sensitivities: no contacts, no joint friction)."""
        return getattr(self.nominal, "dq_dp", None) is not None

    def _point_linear(self, i: int, s: tuple[float, float]) -> dict[str, Any]:
        """The first-order columns of a point of the body whose x is coordinate i:
        dP/dp = dr/dp + B(theta) s' dtheta/dp."""
        q, dq = _rows(self.nominal, self.nominal.q), _rows(self.nominal, self.nominal.dq_dp)
        dr = PointResult.derivatives(s, [q[:, i:i + 3]], [dq[:, i:i + 3, :]])[0]
        dx, dy = dr[:, 0, :], dr[:, 1, :]
        sig = np.array(list(self.sigma.values()))
        t, tp = ("time",), ("time", "parameter")
        return {"x_std_linear": (t, _std_linear(dx, sig)),
                "y_std_linear": (t, _std_linear(dy, sig)),
                "x_share": (tp, _shares(dx, sig)), "y_share": (tp, _shares(dy, sig))}

    def contributions(self, output: str, entry: str) -> Any:
        """Each parameter's share of the first-order variance of one entry of an output,
        over time: (S_k sigma_k)**2 / sum_j (S_j sigma_j)**2, from the nominal run's exact
        sensitivities (0 where the entry does not move with any parameter). The shares say
        which tolerance to tighten first.

        Parameters
        ----------
        output : str
            ``"q"``, ``"qd"``, ``"qdd"``, ``"lam"``, ``"effort"`` or ``"measures"`` (as in
            :attr:`dataset`).
        entry : str
            Its coordinate (``"rocker.theta"``), equation label, driver or measure spec.

        Returns
        -------
        xarray.DataArray
            Over ("time", "parameter"); each row sums to 1 (or 0).

        Raises
        ------
        ModelError
            For an output or entry the analysis does not have, or a report without the
            first-order column (contacts, joint friction: no sensitivities).

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> tol = mbd2d.tolerance(m, {"joint.A.points.0.0": 1e-3, "joint.B.points.0.0": 1e-3},
        ...                       samples=0, t_end=1.0, steps=20)
        >>> tol.contributions("q", "rocker.theta").sum("parameter").values.max()
        1.0
        """
        ds = self.dataset
        if not self.linear:
            raise ModelError(f"variance shares come from the first-order column, which this "
                             f"report does not have ({ds.attrs['first_order']})",
                             "contributions")
        outputs = _outputs(ds)
        if output not in outputs:
            raise ModelError(f"no output {output!r}; outputs: {', '.join(outputs)}",
                             "contributions")
        labels = [str(v) for v in ds[ds[output].dims[1]].values]
        if entry not in labels:
            raise ModelError(f"{output} has no entry {entry!r}; entries: {', '.join(labels)}",
                             "contributions")
        if output == "measures":
            s = measure_derivatives(self.nominal, labels)
        else:
            s = _linear_outputs(self.nominal, ds.attrs["run"])[output][2]
        share = _shares(s[:, labels.index(entry), :], np.array(list(self.sigma.values())))
        return xarray().DataArray(share, dims=("time", "parameter"),
                                  coords={"time": ds.time.values,
                                          "parameter": list(self.sigma)},
                                  name=f"variance share of {entry}")

    def __repr__(self) -> str:
        a = self.dataset.attrs
        return (f"ToleranceResult({len(self.sigma)} parameters, {a.get('samples')} samples, "
                f"{a.get('failed')} failed; outputs {', '.join(_outputs(self.dataset))}"
                f"{'' if self.linear else '; Monte Carlo only'})")


def _rows(res: Any, a: np.ndarray) -> np.ndarray:
    """An array of the result with a time axis (a statics result has none: one row)."""
    return a[None] if np.ndim(res.t) == 0 else a


def _std_linear(s: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """sqrt of the diagonal of S diag(sigma**2) S^T: sqrt(sum_k (S_k sigma_k)**2), scaled by
    the largest term so that the squares do not overflow.

    Raises
    ------
    ModelError
        When a standard deviation itself exceeds the floating-point range.
    """
    m, v = _scaled_terms(s, sigma)
    with np.errstate(over="ignore", invalid="ignore"):
        out = (m * np.sqrt(np.sum(v, axis=-1, keepdims=True)))[..., 0]
    if not np.isfinite(out).all():
        raise ModelError("the first-order standard deviation exceeds the floating-point range: "
                         "give smaller sigma", "tolerance")
    return out


def _shares(s: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """Each parameter's share of the first-order variance, (S_k sigma_k)**2 / sum_j (S_j
    sigma_j)**2 along the last axis (scaled by the largest term: no overflow; 0 where no
    parameter moves the entry)."""
    v = _scaled_terms(s, sigma)[1]
    with np.errstate(invalid="ignore"):
        tot = v.sum(axis=-1, keepdims=True)
        return np.where(tot > 0, v / np.where(tot > 0, tot, 1.0), 0.0)


def _scaled_terms(s: np.ndarray, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The largest |S_k sigma_k| along the last axis, m (keepdims), and the terms
    (|S_k sigma_k| / m)**2 (m taken as 1 where it is 0): the variance is m**2 sum(terms)
    without the squares' overflow."""
    with np.errstate(over="ignore", invalid="ignore"):
        a = np.abs(s * sigma)
        m = a.max(axis=-1, keepdims=True) if a.shape[-1] else np.zeros(a.shape[:-1] + (1,))
        return m, (a / np.where(m > 0, m, 1.0)) ** 2


def _std(x: np.ndarray) -> np.ndarray:
    """Sample standard deviation over the first axis (NaN with fewer than 2 samples)."""
    if x.shape[0] < 2:
        return np.full(x.shape[1:], np.nan)
    return np.std(x, axis=0, ddof=1)


def _outputs(ds: Any) -> list[str]:
    """The outputs of a tolerance dataset (those with a first-order or a Monte Carlo
    standard deviation)."""
    return [v for v in ds.data_vars
            if f"{v}_std_linear" in ds.data_vars or f"{v}_std_mc" in ds.data_vars]


def _nominal(model: ModelDescription, names: list[str] | None, analysis: str,
             kw: Mapping[str, Any]) -> tuple[Any, str]:
    """The analysis with sensitivities to names (None: without; the exception it raises
    when it fails); and which analysis ran."""
    if analysis == "modes":
        return run_modes(model, **_bind(_modes_settings, kw, analysis)), "modes"
    if analysis == "frf":
        return run_frf(model, **_bind(_frf_settings, kw, analysis)), "frf"
    if analysis == "kinematics":
        a = _bind(_kinematics_settings, kw, analysis)
        if model.has_masses() and a["maxit"] is None and not a["positions_only"]:
            a.pop("maxit")                      # as the sweep (plan) and Model.kinematics
            a.pop("positions_only")
            return run_inverse(model, sensitivities=names, **a), "inverse"
        return run_kinematics(model, sensitivities=names, **a), "kinematics"
    if analysis == "inverse_dynamics":
        a = _bind(_inverse_settings, kw, analysis)
        return run_inverse(model, sensitivities=names, **a), "inverse"
    if analysis == "statics":
        return run_statics(model, sensitivities=names, **_bind(_statics_settings, kw,
                                                                 analysis)), "statics"
    a = _bind(_dynamics_settings, kw, analysis)
    if names is not None and a["method"] not in (None,) + SENSITIVITY_METHODS:
        raise ModelError(f"tolerance analysis of dynamics needs the sensitivities of dopri5 "
                         f"or generalized-alpha (method={a['method']!r} has none)", "tolerance")
    return run_dynamics(model, sensitivities=names, **a), "dynamics"


def _linear_outputs(res: Any, ran: str) -> dict[str, tuple[tuple[str, ...], np.ndarray,
                                                           np.ndarray | None]]:
    """Output name -> (dims, nominal (time, k), sensitivities (time, k, n_params)); the
    sensitivities None for a run without them (then lam and effort where the run has
    multipliers)."""
    def rows(a: np.ndarray | None) -> np.ndarray | None:
        return None if a is None else _rows(res, a)

    out = {"q": (("time", "coordinate"), rows(res.q), rows(getattr(res, "dq_dp", None)))}
    if ran == "frf":                            # (the equilibrium; no sensitivities)
        return {**out, **{k: (("frequency", "driver" if "effort" in k else "coordinate",
                               "input"), v, None) for k, v in _frf_values(res).items()}}
    if ran == "modes":                          # (the equilibrium; no sensitivities)
        return {**out, "frequency": (("mode",), res.frequency, None),
                "damping_ratio": (("eigenvalue",), res.damping_ratio, None),
                "damped_frequency": (("eigenvalue",), res.damped_frequency, None)}
    if ran != "statics":
        out["qd"] = (("time", "coordinate"), res.qd, getattr(res, "dqd_dp", None))
        out["qdd"] = (("time", "coordinate"), res.qdd, getattr(res, "dqdd_dp", None))
    dlam = getattr(res, "dlam_dp", None)
    lam = getattr(res, "lam", None)
    if dlam is not None or (out["q"][2] is None and lam is not None):
        lam, dlam = rows(lam), rows(dlam)
        out["lam"] = (("time", "equation"), lam, dlam)
        drows = driver_rows(res.packed)[0]
        if drows:
            out["effort"] = (("time", "driver"), -lam[:, drows],
                             None if dlam is None else -dlam[:, drows, :])
    return out


def _frf_complex(res: Any) -> dict[str, np.ndarray]:
    """The nominal frequency response's complex outputs: "response" and "effort_response"
    (the drivers' efforts, -lambda of their rows), (frequency, entry, input)."""
    rows = driver_rows(res.packed)[0]
    return {"response": res.response, "effort_response": -res.lam_response[:, rows, :]}


def _frf_values(res: Any) -> dict[str, np.ndarray]:
    """The nominal frequency response's outputs (FRF_OUTPUTS): magnitudes and phases
    (degrees) of the coordinates' and, with drivers, the efforts' responses."""
    h = _frf_complex(res)
    return {k: (np.abs(h[src]) if "magnitude" in k else np.degrees(np.angle(h[src])))
            for k, src in FRF_OUTPUTS.items() if h[src].shape[1]}


def _frf_samples(mc: Any, ok: np.ndarray, name: str, nom_h: np.ndarray) -> np.ndarray:
    """The completed samples' values of a frequency response output: magnitudes, or phases
    as the nominal's phase plus each sample's phase relative to it (in (-180, 180] degrees:
    no jumps of 360 between samples near +-180)."""
    h = mc[FRF_OUTPUTS[name]].values[ok]
    if "magnitude" in name:
        return np.abs(h)
    return np.degrees(np.angle(nom_h)) + np.degrees(np.angle(h * np.conj(nom_h)))


def _measure_specs(measures: Any, analysis: str) -> list[str]:
    """The measures asked for (each has exact design derivatives).

    Raises
    ------
    ModelError
        For a malformed spec, or measures of statics.
    """
    specs = measure_list(measures)
    for spec in specs:
        parse_measure(spec)
    if specs and analysis in ("statics", "modes", "frf"):
        raise ModelError(f"measures are columns of a run over time, not of {analysis}",
                         "tolerance")
    return list(specs)


def _measure_outputs(res: Any, specs: list[str], linear: bool
                     ) -> tuple[tuple[str, ...], np.ndarray, np.ndarray | None]:
    """The measures' nominal values (time, k) and derivatives (time, k, n_params; None
    when not linear), as _linear_outputs gives the other outputs."""
    return (("time", "measure"), np.column_stack([measure(res, s) for s in specs]),
            measure_derivatives(res, specs) if linear else None)


def _as_nominal(vals: np.ndarray, nom: np.ndarray) -> np.ndarray:
    """A sweep's values of the completed samples (sample, ...) shaped as the nominal output:
    a modes sweep's equilibria (sample, coordinate) get the nominal's time axis of one row,
    its frequencies (sample, mode) the nominal's number of modes (the sweep has as many as
    its case with the most)."""
    if vals.ndim == 2 and nom.ndim == 2:
        return vals[:, None, :]
    if vals.ndim == 2 and nom.ndim == 1:
        return vals[:, :nom.shape[0]]
    return vals


def _seed(seed: Any) -> int | None:
    """None, or the seed as a whole number >= 0 (else a ModelError)."""
    return None if seed is None else whole(seed, "seed", "tolerance", 0, 2**63 - 1)


def draws(model: ModelDescription, params: Any, sig: np.ndarray, n: int,
          seed: int | None) -> dict[str, np.ndarray]:
    """The Monte Carlo case table: n variants with p ~ Normal(p0, sigma), drawn by numpy's
    default generator from seed (the parameters in turn, one row of n each)."""
    check_memory(n, len(params), "tolerance")      # the draws (the sweep checks its outputs)
    p0 = nominal_values(model, params)
    rng = np.random.default_rng(_seed(seed))
    values = p0[:, None] + sig[:, None] * rng.standard_normal((len(params), n))
    return dict(zip([prm.name for prm in params], values))


def tolerance_samples(model: ModelDescription, sigma: Mapping[str, Any], samples: int = 200,
                      seed: int | None = 0) -> dict[str, np.ndarray]:
    """The case table of :func:`tolerance`'s Monte Carlo estimate (the same draws for the
    same sigma, samples and seed): for :func:`mbd2d.sweep` or :func:`mbd2d.export_sweep`
    (mbd2d-solve then runs them without Python).

    Raises
    ------
    ModelError
        As :func:`tolerance` for sigma and samples.
    """
    params, sig = _sigma(model, sigma)
    n = whole(samples, "samples", "tolerance", 1, 10**8)
    return draws(model, params, sig, n, seed)


def _not_smooth(model: ModelDescription) -> str:
    """Why a model has no first-order column ("" when it has one): its motion is not smooth
    in its parameters (contacts, joint friction), and the column needs design
    sensitivities."""
    names = [c.name for c in model.contacts] + \
        [j.name for j in model.joints if getattr(j, "friction", None) is not None]
    if not names:
        return ""
    return (f"none: the first-order estimate needs design sensitivities, which models with "
            f"contacts or joint friction ({', '.join(names)}) do not have (their events make "
            "the motion non-smooth in the parameters)")


def _sigma(model: ModelDescription, sigma: Any) -> tuple[list[Any], np.ndarray]:
    """The parameters and standard deviations of sigma, checked."""
    if not isinstance(sigma, Mapping) or not sigma:
        raise ModelError("sigma must be a dict {parameter name: standard deviation}",
                         "tolerance")
    params = find(model, list(sigma), "tolerance")
    sig = np.array([number(sigma[n], f"sigma of {n}", "tolerance") for n in sigma])
    if (sig < 0).any():
        raise ModelError("a standard deviation must be >= 0", "tolerance")
    return params, sig


@reads_entries
def tolerance(model: ModelDescription, sigma: Mapping[str, Any], analysis: str = "kinematics",
              samples: int = 200, client: Any = None, *, seed: int | None = 0,
              workers: int | None = None, progress: bool | None = None,
              measures: Any = None, **analysis_kwargs: Any) -> ToleranceResult:
    """Standard deviation of every output of an analysis under independent parameter scatter,
    by first-order propagation of the exact sensitivities (S Sigma S^T) beside a Monte Carlo
    estimate.

    Parameters
    ----------
    model : Model
        The nominal model.
    sigma : dict
        Parameter name -> standard deviation (>= 0), in the parameter's units.
    analysis : {"kinematics", "inverse_dynamics", "statics", "dynamics", "modes", "frf"}
        As :func:`mbd2d.sweep`; dynamics with method dopri5 or generalized-alpha (the ones
        with sensitivities); modes and frf by Monte Carlo alone (frf: ``magnitude`` and
        ``phase``, degrees, of every response over ("frequency", "coordinate", "input"),
        with drivers ``effort_magnitude`` and ``effort_phase`` over ("frequency", "driver",
        "input"); a sample's phase is taken relative to the nominal's, so samples near
        +-180 degrees do not jump by 360).
    samples : int
        Monte Carlo variants, drawn with p ~ Normal(p0, sigma) (default 200; 0 skips the
        Monte Carlo estimate; a model with contacts or joint friction needs them: its report
        has the Monte Carlo columns alone).
    client : distributed.Client, optional
        Run the Monte Carlo sweep on a Dask cluster.
    seed : int or None
        Seed of the random draws (default 0: reproducible; None: fresh entropy).
    workers, progress
        As :func:`mbd2d.sweep`.
    measures : str or list of str, optional
        Mechanism measures (``transmission_angle:JOINT[:OUTPUT]``,
        ``velocity_ratio:INPUT:OUTPUT[:VIA]``, ``mechanical_advantage:INPUT:OUTPUT[:VIA]``,
        ``dead_centre_distance``) to spread the scatter into too: ``measures`` over
        ("time", "measure") with its statistics, first order from the measures' exact
        design derivatives (:func:`mbd2d.results.measures.measure_derivatives`), Monte Carlo
        from the samples' own measures (not for statics).
    **analysis_kwargs
        The analysis's settings (``t_end``, ``steps``, ...).

    Returns
    -------
    ToleranceResult
        ``.dataset`` with ``X``, ``X_std_linear``, ``X_std_mc``, ``X_mean_mc`` per output X;
        ``.point(body, s)`` for a point of a body; ``.samples``, ``.nominal``.

    Raises
    ------
    ModelError
        For an unknown parameter or setting, a negative or non-finite sigma, samples out of
        range, or samples=0 for a model with contacts or joint friction (it has no
        first-order column); the nominal analysis's own exception when it fails.

    Examples
    --------
    >>> import mbd2d
    >>> m = mbd2d.load("examples/fourbar_grashof.toml")
    >>> tol = mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, samples=50, t_end=1.0,
    ...                       steps=20)
    >>> tol.dataset.q_std_linear.shape
    (21, 9)
    """
    xr = xarray()
    params, sig = _sigma(model, sigma)
    if not isinstance(analysis, str) or analysis not in ANALYSES:
        raise ModelError(f"unknown analysis {analysis!r}; use one of {', '.join(ANALYSES)}",
                         "tolerance")
    rough = {"modes": MODES_FIRST_ORDER, "frf": FRF_FIRST_ORDER}.get(analysis) or \
        _not_smooth(model)
    names = [str(n) for n in sigma]
    n = whole(samples, "samples", "tolerance", 0, 10**8)
    seed = _seed(seed)
    if n == 1:
        raise ModelError("samples must be 0 (no Monte Carlo estimate) or at least 2",
                         "tolerance")
    if rough and not n:
        raise ModelError(f"samples=0 leaves nothing to report: first-order column {rough}; "
                         "give samples >= 2 for the Monte Carlo estimate", "tolerance")
    specs = _measure_specs(measures, analysis)
    res, ran = _nominal(model, None if rough else names, analysis, analysis_kwargs)
    outs = _linear_outputs(res, ran)
    if specs:
        outs["measures"] = _measure_outputs(res, specs, not rough)
    mc = None
    if n:
        mc = sweep(model, draws(model, params, sig, n, seed), analysis, client,
                   workers=workers, progress=progress, measures=specs or None,
                   **analysis_kwargs)
    ok = mc.status.values == 0 if mc is not None else np.zeros(0, dtype=bool)
    times = np.array([res.t]) if ran in ("statics", "modes", "frf") else np.asarray(res.t)
    data: dict[str, Any] = {}
    for name, (dims, nom, s) in list(outs.items()):
        own = name in FRF_OUTPUTS and ran == "frf"       # (the sweep's complex response)
        if s is None and (mc is None or (name not in mc and not own)):
            del outs[name]                      # no statistic of it
            continue
        vals = None if mc is None else \
            _frf_samples(mc, ok, name, _frf_complex(res)[FRF_OUTPUTS[name]]) if own else \
            _as_nominal(mc[name].values[ok], nom)
        if vals is not None and vals.ndim == 2 and nom.ndim == 1:
            nom = nom[:vals.shape[1]]           # (a modes sweep with fewer modes)
        data[name] = (dims, nom)
        if s is not None:
            data[f"{name}_std_linear"] = (dims, _std_linear(s, sig))
        if vals is not None:
            data[f"{name}_std_mc"] = (dims, _std(vals))
            data[f"{name}_mean_mc"] = (dims, vals.mean(axis=0) if len(vals) else
                                       np.full(nom.shape, np.nan))
    coords: dict[str, Any] = {"time": times, "coordinate": list(res.coordinate_names)}
    if ran == "modes":
        coords["mode"] = np.arange(data["frequency"][1].shape[0])
        coords["eigenvalue"] = np.arange(data["damping_ratio"][1].shape[0])
    if ran == "frf":
        coords.update(frequency=res.frequencies, input=list(res.inputs))
        if "effort_magnitude" in outs:
            coords["driver"] = driver_rows(res.packed)[1]
    if specs:
        coords["measure"] = specs
    if "lam" in outs:
        coords["equation"] = list(res.row_labels)
    if "effort" in outs:
        coords["driver"] = driver_rows(res.packed)[1]
    attrs = {"analysis": analysis, "run": ran, "model": model.name, "samples": n,
             "failed": int((~ok).sum()), "seed": "none" if seed is None else int(seed),
             "sigma": ", ".join(f"{k}={v:g}" for k, v in zip(names, sig)),
             "first_order": rough or "exact sensitivities"}
    ds = xr.Dataset(data, coords=coords, attrs=attrs)
    return ToleranceResult(ds, mc, res, dict(zip(names, sig.tolist())))


__all__ = ["tolerance", "tolerance_samples", "ToleranceResult"]
