"""Sweeps: one analysis of many variants of a model in batched core calls."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..description.builder import ModelDescription
from ..description.entries import reads_entries
from ..errors import ModelError, StiffnessWarning, warn
from .dataset import to_dataset, xarray
from .plan import case_values, plan, with_cases, with_measures, with_sensitivities
from .runner import run


@reads_entries
def sweep(model: ModelDescription, cases: Any, analysis: str = "kinematics", client: Any = None,
          *, workers: int | None = None, progress: bool | None = None,
          measures: Any = None, sensitivities: Any = None, **analysis_kwargs: Any) -> Any:
    """Run one analysis for many variants of a model: one case per set of parameter values.

    The model is packed once; the core takes the cases in batches (one call per chunk of
    cases), sets each case's numbers in the model's tables, rebuilds what depends on them
    (length scale, unit axes, spline coefficients, gear geometry, open phases) and runs the
    analysis. Every case gives the numbers ``model.with_params(case).<analysis>(...)`` gives,
    bit for bit, at a fraction of the cost per variant (see bench/sweep.py).

    Parameters
    ----------
    model : Model
        The base model.
    cases : dict or pandas.DataFrame
        Parameter name (see ``model.parameters()``) -> 1-D values, one case per index, all
        of one length; or a DataFrame whose columns are parameter names.
        :func:`mbd2d.grid` builds a full-factorial table.
    analysis : {"kinematics", "inverse_dynamics", "statics", "dynamics", "modes", "frf"}
        The analysis, by the name of the Model method ("modes": per case and mode
        ``omega2``, ``frequency``, ``kind``, ``shape``, per case and damped eigenvalue
        ``s_real``, ``s_imag``, ``damping_ratio``, ``damped_frequency``, per case the
        equilibrium ``q``, ``n_free``, ``stability``, ``residual``; every case's as its own
        ``modes()`` gives them, bit for bit; "frf", the frequency response
        (:meth:`mbd2d.Model.frequency_response`, settings ``inputs``, ``frequencies``, ``t``,
        ``equilibrium``, ``solver``): the complex ``response`` over ("case", "frequency",
        "coordinate", "input"), the multipliers' ``lam_response`` over ("case",
        "frequency", "equation", "input") and the drivers' ``effort_response`` (-lambda of
        their rows) over ("case", "frequency", "driver", "input"), the frequencies in Hz, and
        per case the equilibrium ``q``,
        ``n_free``, ``stability``, ``residual``; a case whose response fails (an undamped
        resonance among the frequencies, no equilibrium) is NaN with its status and
        message); "kinematics" of a model with masses
        is inverse dynamics, as :meth:`mbd2d.Model.kinematics`.
    client : distributed.Client, optional
        Run the batches on a Dask cluster (as futures, gathered into the same Dataset,
        identical bit for bit to a local run).
    workers : int, optional
        Without a client: worker processes (default every core; 1 runs in this process).
        A pool is started only when the cases would take more than about a second.
    progress : bool, optional
        A tqdm progress bar of cases done: by default one appears when the sweep takes more
        than 2 s; True always, False never.
    measures : str or list of str, optional
        Mechanism measures of every case at its rows, as a table's ``measures=``:
        ``transmission_angle:JOINT[:OUTPUT]``, ``velocity_ratio:IN:OUT[:VIA]``,
        ``mechanical_advantage:IN:OUT[:VIA]``, ``dead_centre_distance`` (not for statics).
        Each case's come from its own dimensions (a swept pivot moves its angle's points).
    sensitivities : list of str, optional
        Design parameters (``model.parameters()`` names): every case's exact sensitivities
        to them at its own values, as ``sensitivities=`` of the Model method computes them
        (not for positions-only kinematics; dynamics by dopri5 or generalized-alpha).
    **analysis_kwargs
        The analysis's settings, as for the Model method (``t_end``, ``steps``, ``t0``,
        ``every``, ``tol``, ``solver``; ``method``, ``rtol``, ``atol``, ``h`` ... for
        dynamics; ``t`` for statics; ``inputs``, ``frequencies`` for frf).

    Returns
    -------
    xarray.Dataset
        ``q``, ``qd``, ``qdd`` over ("case", "time", "coordinate"); with multipliers
        (inverse dynamics, dynamics, statics) also ``lam`` over ("case", "time",
        "equation"), ``effort`` over ("case", "time", "driver"), and the energies
        ``kinetic``, ``potential`` (statics: ``stability`` and ``residual`` per case;
        dynamics: ``stiff_from`` per case, the time from which dopri5's or partitioned's
        steps were limited by stability, NaN where they were not, with one
        StiffnessWarning for them all); with
        measures ``measures`` over ("case", "time", "measure"), the "measure" coordinate
        naming them by their specs; with sensitivities ``dq_dp``, ``dqd_dp``, ``dqdd_dp``
        over ("case", "time", "coordinate", "parameter") and, with multipliers (inverse
        dynamics, dynamics, statics), ``dlam_dp`` and ``deffort_dp``; with both measures and
        sensitivities ``dmeasures_dp`` over ("case", "time", "measure", "parameter"), each
        case's exact measure derivatives as a single run's ``measure_derivatives``. The
        parameters are coordinates of "case"; ``status`` (0 ok, else the status of the
        exception the variant raises alone, ``err.status``, or the core's status for bad
        input) and ``message`` (that exception's text) per case. A failing case keeps its
        rows up to the failure; the rows after it are NaN. A case whose measure fails (a
        quantity that does not move with the driver) keeps its rows, its measures are NaN
        and its status and message are those of the measure's error. ``ds.attrs["failed"]`` counts
        the failed cases.

    Raises
    ------
    ModelError
        For a malformed case table, an unknown parameter or setting, or a base model the
        analysis cannot run (a single variant's failure is reported in its row instead).
    ImportError
        When xarray (the ``sweep`` extra) is missing.

    Examples
    --------
    >>> import numpy as np, mbd2d
    >>> m = mbd2d.load("examples/fourbar_grashof.toml")
    >>> ds = mbd2d.sweep(m, {"joint.B.points.0.0": np.linspace(1.7, 1.8, 5)},
    ...                  t_end=1.0, steps=10)
    >>> ds.q.shape, int(ds.status.max())
    ((5, 11, 9), 0)
    """
    xarray()                                  # the extra first: fail before any work
    if not isinstance(model, ModelDescription):
        raise ModelError(f"sweep needs a model (mbd2d.load or mbd2d.Model), got "
                         f"{type(model).__name__}", "sweep")
    names, values = case_values(cases)
    pl = plan(model, names, analysis, analysis_kwargs)
    with_measures(pl, model, measures)
    with_sensitivities(pl, model, sensitivities)
    vals = with_cases(pl, model, values)
    out = run(pl.tables, vals, client=client, workers=workers, progress=progress)
    ds = to_dataset(pl, analysis, model, out, names, values)
    _warn_stiff(ds)
    return ds


def _warn_stiff(ds: Any) -> None:
    """One StiffnessWarning for the cases whose dopri5 (partitioned) steps were limited by
    stability (``ds.stiff_from`` finite)."""
    if "stiff_from" not in ds:
        return
    stiff = np.flatnonzero(np.isfinite(ds["stiff_from"].values))
    if len(stiff):
        shown = ", ".join(str(int(c)) for c in stiff[:8]) + (", ..." if len(stiff) > 8 else "")
        warn(f"{len(stiff)} of {ds.sizes['case']} cases (case {shown}) ran with steps limited "
             "by stability, not accuracy (ds.stiff_from: from when): stiff variants; "
             "method='generalized-alpha' takes steps set by the motion's accuracy",
             StiffnessWarning)


__all__ = ["sweep"]
