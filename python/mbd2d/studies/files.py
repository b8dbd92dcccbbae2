"""Study files: a sweep as netCDF (through xarray) or CSV, one row per case and time; a
tolerance analysis as netCDF or CSV, one row per time."""
from __future__ import annotations

import csv
import math
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

from ..errors import ModelError
from ..results.files import write_csv
from .dataset import EXTRA

SUFFIXES = (".nc", ".csv")


def _netcdf_engine() -> str:
    """An installed netCDF writer for xarray: h5netcdf (with h5py), else netCDF4."""
    for engine, modules in (("h5netcdf", ("h5netcdf", "h5py")), ("netcdf4", ("netCDF4",))):
        try:
            for m in modules:
                __import__(m)
        except ImportError:
            continue
        return engine
    raise ImportError(f"writing netCDF needs h5netcdf and h5py (or netCDF4): {EXTRA}")


def write_sweep(ds: Any, path: str | Path) -> None:
    """Write a sweep's Dataset: ``.nc`` as netCDF-4 (every variable, coordinate and
    attribute; read it back with ``xarray.open_dataset``), ``.csv`` as one row per case and
    output time (the rows a case kept; a case without rows gets one row with its status
    and message).

    CSV columns: ``case``, the parameters, ``t``, ``status``, ``message``, then per
    coordinate NAME (q), NAME_dot (qd), NAME_ddot (qdd) (NAME alone for a positions-only
    sweep), with multipliers the efforts ``effort.DRIVER``, then the measures by their specs,
    then for each design parameter P of a sweep with sensitivities ``d(COLUMN)/d(P)`` of
    the motion columns, the efforts and the measures. A modes sweep: one row per case and
    mode, ``case``, the parameters, ``mode``, ``status``, ``message``, ``omega2``,
    ``frequency_hz``, ``kind``, the shape per coordinate. A frequency response sweep: one
    row per case and frequency, ``case``, the parameters, ``frequency_hz``, ``status``,
    ``message``, then for each input ``d(NAME)/d(INPUT).re`` and ``.im`` of each coordinate
    (the columns of :meth:`FrequencyResponseResult.to_csv`) and of each driver's effort
    (``effort.DRIVER``). netCDF keeps the complex ``response``, ``lam_response`` and
    ``effort_response`` as xarray writes complex numbers through h5netcdf.

    Raises
    ------
    ModelError
        For another suffix or a file that cannot be written.
    """
    p = _study_path(path, "a sweep", "write_sweep")
    with _writing(path, "write_sweep"):
        if p.suffix == ".nc":
            ds.to_netcdf(p, engine=_netcdf_engine())
        else:
            _csv(ds, p)


def _study_path(path: Any, what: str, where: str) -> Path:
    """The path of a study's file, .nc or .csv (else a ModelError)."""
    p = Path(path)
    if p.suffix not in SUFFIXES:
        raise ModelError(f"{what} is written as .nc (netCDF) or .csv, got {str(path)!r}",
                         where)
    return p


@contextmanager
def _writing(path: Any, where: str) -> Iterator[None]:
    """An OSError while writing a study's file becomes a ModelError naming it."""
    try:
        yield
    except OSError as exc:
        raise ModelError(f"cannot write {str(path)!r}: {exc.strerror or exc}", where) from None


def _params(ds: Any) -> list[str]:
    text = ds.attrs.get("parameters", "")
    return [n for n in text.split(", ") if n]


def _csv(ds: Any, path: Path) -> None:
    if ds.attrs.get("run") in ("modes", "frf"):
        (_modes_csv if ds.attrs["run"] == "modes" else _frf_csv)(ds, path)
        return
    params = _params(ds)
    coords = [str(c) for c in ds.coordinate.values]
    levels = [ds[k].values for k in ("q", "qd", "qdd") if k in ds]   # (q alone: positions only)
    header = ["case", *params, "t", "status", "message",
              *(f"{c}{s}" for s in ("", "_dot", "_ddot")[:len(levels)] for c in coords)]
    drivers = [str(d) for d in ds.driver.values] if "effort" in ds else []
    header += [f"effort.{d}" for d in drivers]
    specs = [str(m) for m in ds["measure"].values] if "measure" in ds.coords else []
    header += specs
    motion = header[4 + len(params):4 + len(params) + len(levels) * len(coords)]
    sens, sens_names = _sensitivity_columns(ds)
    derived = motion + ([f"effort.{d}" for d in drivers] if "deffort_dp" in ds else []) + \
        (specs if "dmeasures_dp" in ds else [])
    header += [f"d({v})/d({p})" for p in sens_names for v in derived]
    q = levels[0]
    eff = ds.effort.values if drivers else None
    meas = ds["measures"].values if specs else None
    t = ds.time.values
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(header)
        for c in range(q.shape[0]):
            head = [c, *(_g(ds[n].values[c]) for n in params)]
            st, msg = int(ds.status.values[c]), str(ds.message.values[c])
            rows = np.flatnonzero(np.isfinite(q[c]).all(axis=1))
            if not len(rows):
                w.writerow(head + ["", st, msg])
                continue
            for k in rows:
                line = head + [_g(t[k]), st, msg] + [_g(v) for x in levels for v in x[c, k]]
                if eff is not None:
                    line += [_g(v) for v in eff[c, k]]
                if meas is not None:
                    line += [_g(v) for v in meas[c, k]]
                line += [_g(v) for v in sens[c, k]]
                w.writerow(line)


def _modes_csv(ds: Any, path: Path) -> None:
    """A modes sweep: one row per case and mode (``case``, the parameters, ``mode``,
    ``status``, ``message``, ``omega2``, ``frequency_hz``, ``kind``, then the shape per
    coordinate); a case without modes gets one row with its status and message."""
    params = _params(ds)
    coords = [str(c) for c in ds.coordinate.values]
    header = ["case", *params, "mode", "status", "message", "omega2", "frequency_hz", "kind",
              *coords]
    w2, f, kind, shape = (ds[k].values for k in ("omega2", "frequency", "kind", "shape"))
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for c in range(ds.sizes["case"]):
            head, st, msg = _case_head(ds, params, c)
            modes = np.flatnonzero(np.isfinite(w2[c]))
            if not len(modes):
                w.writerow(head + ["", st, msg])
                continue
            for k in modes:
                w.writerow(head + [k, st, msg, _g(w2[c, k]), _g(f[c, k]), _g(kind[c, k])]
                           + [_g(v) for v in shape[c, k]])


def _case_head(ds: Any, params: Sequence[str], c: int) -> tuple[list[Any], int, str]:
    """A case's leading columns (case, the parameters), its status and its message."""
    head = [c, *(_g(ds[n].values[c]) for n in params)]
    return head, int(ds.status.values[c]), str(ds.message.values[c])


def _frf_csv(ds: Any, path: Path) -> None:
    """A frequency response sweep: one row per case and frequency (see write_sweep); a case
    without a response gets one row with its status and message."""
    params = _params(ds)
    drivers = [str(d) for d in ds.driver.values] if "effort_response" in ds else []
    cols = [str(c) for c in ds.coordinate.values] + [f"effort.{d}" for d in drivers]
    header = ["case", *params, "frequency_hz", "status", "message",
              *(f"d({c})/d({i}).{part}" for i in ds.input.values for c in cols
                for part in ("re", "im"))]
    h = ds.response.values                                   # (case, frequency, nq, input)
    if drivers:
        h = np.concatenate([h, ds.effort_response.values], axis=2)
    h = np.moveaxis(h, 3, 2)                                 # (case, frequency, input, cols)
    parts = np.stack([h.real, h.imag], axis=4).reshape(h.shape[0], h.shape[1], -1) + 0.0
    f = ds.frequency.values
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for c in range(ds.sizes["case"]):
            head, st, msg = _case_head(ds, params, c)
            if st != 0:
                w.writerow(head + ["", st, msg])
                continue
            for k in range(len(f)):
                w.writerow(head + [_g(f[k]), st, msg] + [_g(v) for v in parts[c, k]])


def _sensitivity_columns(ds: Any) -> tuple[np.ndarray, list[str]]:
    """The sensitivities as (case, time, columns), parameter by parameter: for each, the
    derivatives of the motion columns (q, qd, qdd), with multipliers' sensitivities of the
    efforts, and of the measures; and the parameters' names. (case, time, 0) without
    sensitivities."""
    if "dq_dp" not in ds:
        return np.zeros(ds.q.shape[:2] + (0,)), []
    parts = [ds[k].values for k in ("dq_dp", "dqd_dp", "dqdd_dp", "deffort_dp", "dmeasures_dp")
             if k in ds]
    block = np.concatenate(parts, axis=2)          # (case, time, columns, parameter)
    return (np.ascontiguousarray(np.moveaxis(block, 3, 2)).reshape(
        block.shape[0], block.shape[1], -1), [str(p) for p in ds.parameter.values])


def _g(v: Any) -> str:
    """A number with 17 significant digits (round trip), NaN as empty."""
    x = float(v)
    return "" if math.isnan(x) else format(x, ".17g")


#: the column names of a tolerance output's entries, from its coordinate's labels
_ENTRY = {"q": "{}", "qd": "{}_dot", "qdd": "{}_ddot", "lam": "lambda.{}", "effort": "{}.effort",
          "measures": "{}", "frequency": "mode{}.frequency",
          "damping_ratio": "eigenvalue{}.damping_ratio",
          "damped_frequency": "eigenvalue{}.damped_frequency"}
#: the statistics of a tolerance output, as column suffixes
_STATS = (("", ""), ("_std_linear", ".std_linear"), ("_std_mc", ".std_mc"),
          ("_mean_mc", ".mean_mc"))


def tolerance_table(ds: Any, points: Sequence[tuple[str, Any]] = ()
                    ) -> tuple[list[str], np.ndarray]:
    """A tolerance analysis (:attr:`ToleranceResult.dataset`) and point scatters
    (``(label, ToleranceResult.point(...))``) as one row per output time: ``t``, then for
    each output (q, qd, qdd, lam, effort, the measures by their specs) and entry its nominal
    value ``NAME``, first-order
    standard deviation ``NAME.std_linear`` and, with Monte Carlo samples, ``NAME.std_mc``
    and ``NAME.mean_mc`` (NAME: ``crank.x``, ``crank.x_dot``, ``crank.x_ddot``,
    ``lambda.LABEL``, ``DRIVER.effort``; the modes' one row also ``modeK.frequency``,
    ``eigenvalueK.damping_ratio``, ``eigenvalueK.damped_frequency``, K from 1); then per
    point ``LABEL.x``, ``LABEL.y`` with their ``.std_linear`` and ``.std_mc``
    (``.std_linear`` only where the analysis has the first-order column: not with contacts
    or joint friction, nor for the modes)."""
    if "magnitude" in ds:                       # a frequency response's: per frequency
        return _frf_tolerance_table(ds)
    header = ["t"]
    blocks = [np.atleast_1d(ds.time.values)[:, None]]
    for out, fmt in _ENTRY.items():
        if out not in ds:
            continue
        per_time = len(ds[out].dims) == 2       # (the modes' outputs: one row, K from 1)
        labels = [str(v) for v in ds[ds[out].dims[1]].values] if per_time else \
            [str(k + 1) for k in range(ds[out].shape[0])]
        for suffix, word in _STATS:
            if f"{out}{suffix}" in ds:
                header += [fmt.format(lb) + word for lb in labels]
                v = np.asarray(ds[f"{out}{suffix}"].values)
                blocks.append(v if per_time else v[None, :])
    for label, pt in points:
        for v in ("x", "y", "x_std_linear", "y_std_linear", "x_std_mc", "y_std_mc"):
            if v not in pt:
                continue                        # no first-order column (contacts, friction)
            header.append(f"{label}.{v.replace('_std', '.std')}")
            blocks.append(np.asarray(pt[v].values)[:, None])
    return header, np.hstack(blocks)


def _frf_tolerance_table(ds: Any) -> tuple[list[str], np.ndarray]:
    """A frequency response's tolerance analysis as one row per frequency: ``frequency_hz``,
    then for each input, coordinate (then driver's effort, ``effort.DRIVER``) the magnitude
    ``d(NAME)/d(INPUT).abs`` and the phase ``d(NAME)/d(INPUT).deg`` (degrees), each nominal
    and with ``.std_mc`` and ``.mean_mc`` (the equilibrium's scatter is in the dataset)."""
    header = ["frequency_hz"]
    blocks = [np.asarray(ds.frequency.values)[:, None]]
    outputs = [("magnitude", "phase", "coordinate", "{}")]
    if "effort_magnitude" in ds:
        outputs.append(("effort_magnitude", "effort_phase", "driver", "effort.{}"))
    for j, inp in enumerate(str(v) for v in ds.input.values):
        for mag, ph, dim, fmt in outputs:
            for k, entry in enumerate(str(v) for v in ds[dim].values):
                for out, part in ((mag, "abs"), (ph, "deg")):
                    for suffix, word in _STATS:
                        if f"{out}{suffix}" in ds:
                            header.append(f"d({fmt.format(entry)})/d({inp}).{part}{word}")
                            blocks.append(np.asarray(ds[f"{out}{suffix}"].values)[:, k, j,
                                                                                   None])
    return header, np.hstack(blocks)


def write_tolerance(ds: Any, path: str | Path, points: Sequence[tuple[str, Any]] = ()
                    ) -> None:
    """Write a tolerance analysis: ``.csv`` as :func:`tolerance_table` (numbers as every
    mbd2d CSV, ``%.16e``), ``.nc`` as netCDF-4 with the point scatters as variables
    ``point1_x``, ``point1_x_std_linear``, ... (attributes ``point1`` ... name them).

    Raises
    ------
    ModelError
        For another suffix or a file that cannot be written.
    """
    p = _study_path(path, "a tolerance analysis", "write_tolerance")
    if p.suffix == ".csv":
        header, rows = tolerance_table(ds, points)
        write_csv(p, header, rows, "write_tolerance")
        return
    out = ds.copy()
    for k, (label, pt) in enumerate(points, start=1):
        for v in pt.data_vars:
            out[f"point{k}_{v}"] = pt[v]
        out.attrs[f"point{k}"] = label
    with _writing(path, "write_tolerance"):
        out.to_netcdf(p, engine=_netcdf_engine())


__all__ = ["write_sweep", "write_tolerance", "tolerance_table"]
