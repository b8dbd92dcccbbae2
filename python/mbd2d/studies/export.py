"""A sweep as a model file for the standalone ``mbd2d-solve``: the model and its analysis as
:meth:`mbd2d.Model.export` writes them, plus a ``cases`` block (the swept parameters, the
core's entries each case sets and their values per case) and an ``opens`` block (the phases
the core sets again from the q0 estimates). ``mbd2d-solve`` makes the batch call the Python
sweep makes and writes the CSV ``write_sweep`` writes (docs/mbd-format.md)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from ..analysis.mbdfile import file_lines
from ..results.files import write_text
from .plan import case_values, plan, with_cases, with_measures, with_sensitivities

#: the file's analysis for the sweep's plan (kinematics of a model with masses runs as
#: inverse dynamics, as in the sweep)
FILE_ANALYSIS = {"kinematics": "kinematics", "inverse": "inverse-dynamics",
                 "statics": "statics", "dynamics": "dynamics", "modes": "modes", "frf": "frf"}


def export_sweep(model: Any, path: str | Path, cases: Any, analysis: str = "kinematics",
                 measures: Any = None, sensitivities: Any = None,
                 **analysis_kwargs: Any) -> None:
    """Write a sweep for ``mbd2d-solve``: the cases of :func:`mbd2d.sweep` with the same
    analysis and settings, run there in one batch call without Python.

    Parameters
    ----------
    model : Model
        The base model.
    path : str or pathlib.Path
        The file to write (.mbd).
    cases : dict or pandas.DataFrame
        As :func:`mbd2d.sweep` (:func:`mbd2d.grid` builds a full-factorial table).
    analysis : {"kinematics", "inverse_dynamics", "statics", "dynamics", "modes", "frf"}
        As :func:`mbd2d.sweep`.
    measures : str or list of str, optional
        As :func:`mbd2d.sweep`: columns of every case (an angle's points given with the
        params entries a case may set).
    sensitivities : list of str, optional
        As :func:`mbd2d.sweep`: every case's design sensitivities to these parameters.
    **analysis_kwargs
        The analysis's settings, as :func:`mbd2d.sweep` takes them.

    Raises
    ------
    ModelError
        For an unknown parameter, analysis or setting, or a model the analysis cannot run
        (checked as the sweep checks them).

    Examples
    --------
    >>> import mbd2d
    >>> m = mbd2d.load("examples/fourbar_grashof.toml")
    >>> mbd2d.export_sweep(m, "/tmp/sweep.mbd", {"joint.B.points.0.0": [1.6, 1.75, 1.9]},
    ...                    t_end=1.0, steps=60)
    """
    names, values = case_values(cases, "export_sweep")
    pl = plan(model, names, analysis, analysis_kwargs)
    with_measures(pl, model, measures)
    with_sensitivities(pl, model, sensitivities)
    vals = with_cases(pl, model, values)
    lines = file_lines(model, analysis=FILE_ANALYSIS[pl.analysis], measures=measures,
                       measure_refs=True, sensitivities=sensitivities, **pl.settings)
    b = pl.tables
    lines.append(f"cases {len(names)} {b.vtab.shape[1]} {values.shape[1]}")
    lines += list(names)
    lines += [f"{int(b.vtab[0, k])} {int(b.vtab[1, k])}" for k in range(b.vtab.shape[1])]
    for j in range(values.shape[1]):           # a case per line, six numbers at most
        row = [_r(v) for v in [*values[:, j], *vals[:, j]]]
        lines += [" ".join(row[i:i + 6]) for i in range(0, len(row), 6)]
    lines.append(f"opens {b.opens.shape[1]}")
    lines += [f"{int(b.opens[0, k])} {int(b.opens[1, k])}" for k in range(b.opens.shape[1])]
    write_text(path, "\n".join(lines + ["end"]) + "\n", "export_sweep")


def _r(x: float) -> str:
    return f"{float(x):.17e}"


__all__ = ["export_sweep", "FILE_ANALYSIS"]
