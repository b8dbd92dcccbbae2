"""Results built from the core's output arrays (one column per output time), and the check
that no result leaves a front door with a non-finite number in it."""
from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

import numpy as np

from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..results.contacts import element_arrays, events_from
from ..results.dynamics import DynamicsResult
from ..results.kinematics import KinematicsResult

R = TypeVar("R", bound=KinematicsResult)

#: arrays of a result with one row per output time
ROW_FIELDS = ("t", "q", "qd", "qdd", "lam", "kinetic", "potential", "drift_position",
              "drift_velocity", "elements", "dq_dp", "dqd_dp", "dqdd_dp", "dlam_dp")


def rows(a: np.ndarray, n: int) -> np.ndarray:
    """The first n output rows of a core array whose columns are the outputs.

    A view when every column is kept (the transpose of f2py's Fortran-order array is
    C-contiguous: no copy of a long run), a copy of the part otherwise (the unused tail is
    not kept alive).
    """
    return a.T if n == a.shape[-1] else a.T[:n].copy()


def dynamics_result(model: ModelDescription, p: Packed, t: np.ndarray, n: int, out: Any,
                    stats: dict[str, Any], complete: bool) -> DynamicsResult:
    """The first n output rows of an inverse or forward dynamics run (``out`` from
    :mod:`mbd2d.binding.core`)."""
    e = out.e
    names = [(name, what) for name, what, _ in model.force_elements()]
    eo = getattr(out, "eo", None)
    if eo is None:                      # a sensitivity run: no element outputs
        eo = np.zeros((6, len(names), max(n, 0)))
    contacts, friction = (events_from(out.evo, int(out.nev), names) if hasattr(out, "evo")
                          else ([], []))
    return DynamicsResult(t=t[:n], q=rows(out.q, n), qd=rows(out.qd, n),
                          qdd=rows(out.qdd, n), body_names=p.body_names,
                          coordinate_names=p.coordinate_names, stats=stats, complete=complete,
                          model=model, lam=rows(out.lam, n), kinetic=e[0, :n].copy(),
                          potential=e[1, :n].copy(), drift_position=e[2, :n].copy(),
                          drift_velocity=e[3, :n].copy(), row_labels=p.row_labels, packed=p,
                          elements=element_arrays(eo, n), element_names=names,
                          contacts=contacts, friction_events=friction)


def first_nonfinite_row(*arrays: np.ndarray) -> int | None:
    """Index of the first row (axis 0) where any of the arrays holds a non-finite value, or
    None when all are finite."""
    bad = None
    for a in arrays:
        a = np.asarray(a)
        if a.size == 0:
            continue
        with np.errstate(over="ignore", invalid="ignore"):
            if np.isfinite(a.sum()):    # a finite sum: every entry is finite (a fast test)
                continue
        rows = ~np.isfinite(a.reshape(a.shape[0], -1)).all(axis=1)
        if rows.any():
            k = int(np.argmax(rows))
            bad = k if bad is None else min(bad, k)
    return bad


def finite_part(res: R, sums: np.ndarray | None = None,
                covered: tuple[str, ...] = ()) -> tuple[R, int | None]:
    """The result cut before its first row with a non-finite number (marked incomplete),
    and that row's index; the result itself and None when every number is finite.

    Parameters
    ----------
    res : the result
    sums : per row, the core's sum of the fields in ``covered`` (finite exactly when they
        all are, unless the sum overflowed): when every one is finite, those fields need not
        be read again; otherwise they are checked entry by entry like the others
    covered : the fields ``sums`` vouches for
    """
    names = [f for f in ROW_FIELDS if getattr(res, f, None) is not None]
    if sums is not None:
        with np.errstate(over="ignore", invalid="ignore"):
            if np.isfinite(sums).all():
                names = [f for f in names if f not in covered]
    k = first_nonfinite_row(*(getattr(res, f) for f in names))
    if k is None:
        return res, None
    cut = {f: getattr(res, f)[:k].copy() for f in names}
    return dataclasses.replace(res, complete=False, **cut), k
