"""Sweep files: netCDF (through xarray) or CSV, one row per case and time."""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelError
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
    sweep), and with multipliers the efforts ``effort.DRIVER``.

    Raises
    ------
    ModelError
        For another suffix or a file that cannot be written.
    """
    p = Path(path)
    if p.suffix not in SUFFIXES:
        raise ModelError(f"a sweep is written as .nc (netCDF) or .csv, got {str(path)!r}",
                         "write_sweep")
    try:
        if p.suffix == ".nc":
            ds.to_netcdf(p, engine=_netcdf_engine())
        else:
            _csv(ds, p)
    except OSError as exc:
        raise ModelError(f"cannot write {str(path)!r}: {exc.strerror or exc}",
                         "write_sweep") from None


def _params(ds: Any) -> list[str]:
    text = ds.attrs.get("parameters", "")
    return [n for n in text.split(", ") if n]


def _csv(ds: Any, path: Path) -> None:
    params = _params(ds)
    coords = [str(c) for c in ds.coordinate.values]
    levels = [ds[k].values for k in ("q", "qd", "qdd") if k in ds]   # (q alone: positions only)
    header = ["case", *params, "t", "status", "message",
              *(f"{c}{s}" for s in ("", "_dot", "_ddot")[:len(levels)] for c in coords)]
    drivers = [str(d) for d in ds.driver.values] if "effort" in ds else []
    header += [f"effort.{d}" for d in drivers]
    q = levels[0]
    eff = ds.effort.values if drivers else None
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
                w.writerow(line)


def _g(v: Any) -> str:
    """A number with 17 significant digits (round trip), NaN as empty."""
    x = float(v)
    return "" if math.isnan(x) else format(x, ".17g")


__all__ = ["write_sweep"]
