"""Checks of analysis settings shared by the front doors: time grid, output decimation,
memory, Newton settings and the linear solver."""
from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from ..binding.status import MEMORY_ADVICE
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..errors import InsufficientMemoryError, ModelError
from ..validate import is_number, number, whole

MAX_STEPS = 10**9      # output rows are held in memory; the core counts in 32-bit integers
MIN_TOL = 1e-15        # below this a residual test cannot pass in double precision

#: linear solvers of the kinematic loop (codes of mbd_kinematics.f90)
SOLVERS = {"auto": 0, "dense": 1, "banded": 2}


def check_span(t0: Any, t_end: Any, steps: Any) -> tuple[float, float, int]:
    """Validate an output time grid."""
    for name, v in (("t0", t0), ("t_end", t_end)):
        try:
            ok = is_number(v) and math.isfinite(float(v))
        except OverflowError:
            ok = False
        if not ok:
            raise ModelError(f"{name} must be a finite number, got {v!r}", "analysis")
    t0, t_end = float(t0), float(t_end)
    steps = whole(steps, "steps", "analysis", 1, MAX_STEPS)
    if not t_end > t0:
        raise ModelError(f"t_end ({t_end}) must be greater than t0 ({t0})", "analysis")
    if not math.isfinite(t_end - t0):
        raise ModelError("the time span t_end - t0 is too large to represent", "analysis")
    return t0, t_end, steps


def output_rows(steps: int, every: Any) -> int:
    """Number of output rows kept with decimation ``every`` (validated here: a whole number
    >= 1): steps 0, every, 2 every, ... and always ``steps``. Nothing is allocated."""
    k = whole(every, "every", "analysis", 1, MAX_STEPS)
    return steps // k + 1 + (1 if steps % k else 0)


def output_steps(steps: int, every: Any) -> np.ndarray:
    """Step indices kept with output decimation: 0, every, 2 every, ... and always ``steps``.

    Call :func:`check_memory` with :func:`output_rows` first: this array has one entry per
    kept row.

    Parameters
    ----------
    steps : int
        Output intervals of the time grid.
    every : int
        Keep every k-th output (validated here: a whole number >= 1).

    Returns
    -------
    numpy.ndarray
        The kept indices into the grid of ``steps + 1`` times.
    """
    k = whole(every, "every", "analysis", 1, MAX_STEPS)
    idx = np.arange(0, steps + 1, k)
    if idx[-1] != steps:
        idx = np.append(idx, steps)
    return idx


def time_grid(t0: float, t_end: float, steps: int, idx: np.ndarray) -> np.ndarray:
    """Times of the grid indices idx (exact at both ends, as in the core)."""
    t = t0 + (t_end - t0) * (idx / steps)
    t[idx == steps] = t_end
    return t


def physical_memory() -> float:
    """Bytes of physical memory (8 GiB when the system does not say)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover
        return 8.0 * 2**30


def check_memory(rows: int, columns: int, analysis: str = "analysis") -> None:
    """Refuse a run whose output arrays (rows x columns numbers, held twice: the core's and
    the result's) cannot fit in half the physical memory, before anything is allocated. The
    core checks its own work arrays (the dense matrices) before it allocates them and
    returns NO_MEMORY with their size (mbd_memory.f90).

    Raises
    ------
    InsufficientMemoryError
        With the size asked and what to change.
    """
    need = 2.0 * 8.0 * rows * columns
    if need > 0.5 * physical_memory():
        parts = f"{rows} output rows x {columns} numbers, twice"
        raise InsufficientMemoryError(
            f"{analysis}: the run would need {need / 2**30:.3g} GiB ({parts}), more than half "
            f"of this machine's {physical_memory() / 2**30:.3g} GiB; {MEMORY_ADVICE}", need)


def check_solver(tol: Any, maxit: Any) -> tuple[float, int]:
    """Validate Newton settings; 0 means the core's default."""
    t = 0.0 if tol is None else number(tol, "tol", "analysis")
    if tol is not None and not MIN_TOL <= t < 1.0:
        raise ModelError(f"tol must be from {MIN_TOL:g} to below 1 (it is relative to the "
                         f"model's length scale), got {tol!r}", "analysis")
    it = 0 if maxit is None else whole(maxit, "maxit", "analysis", 1, 10**6)
    return t, it


def solver_code(solver: Any) -> int:
    """The core's code of a linear-solver name ("auto", "dense" or "banded")."""
    if not isinstance(solver, str) or solver not in SOLVERS:
        raise ModelError(f"unknown solver {solver!r}; use one of {', '.join(SOLVERS)}",
                         "analysis")
    return SOLVERS[solver]


def count_detail(p: Packed) -> str:
    """'N equations for M coordinates (...)', for messages."""
    ncam = p.nq - 3 * p.nb
    return (f"{p.neq} equations for {p.nq} coordinates ({p.nb} bodies x 3"
            + (f" + {ncam} cam contact (or curve) parameters" if ncam else "") + ")")


def require_determined(p: Packed, model: ModelDescription) -> None:
    """Kinematics needs at least as many equations as coordinates (the core then checks the
    rank at the assembled configuration)."""
    if p.neq >= p.nq:
        return
    raise ModelError(f"the model is not kinematically determined: {count_detail(p)}; "
                     f"{p.nq - p.neq} degree(s) of freedom are not driven: add a driver for each "
                     "(or a joint you left out)", f"model {model.name!r}")
