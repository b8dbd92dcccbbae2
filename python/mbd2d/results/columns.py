"""The columns of the result tables (CSV), built from arrays: the same builders make the
value columns and, fed the sensitivity arrays, their derivatives ``d(COLUMN)/d(PARAM)``.
``mbd2d-solve`` writes the same columns in the same order (fortran/app/mbd2d_solve.f90)."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..errors import ModelError

#: the motion columns of a body, NAME.SUFFIX (positions, velocities, accelerations)
SUFFIXES = ("x", "y", "theta", "x_dot", "y_dot", "theta_dot", "x_ddot", "y_ddot", "theta_ddot")
#: the reaction columns of a constraint, NAME.WORD (the Reaction attributes)
REACTION_WORDS = ("fx", "fy", "mz", "fx_j", "fy_j", "mz_j")


def motion_columns(body_names: Sequence[str], levels: Sequence[np.ndarray]
                   ) -> tuple[list[str], np.ndarray]:
    """NAME.x ... NAME.theta_ddot per body from the levels (q, and q_dot, q_ddot when given),
    each (n, nq): the names and an (n, 3 len(levels) nb) array."""
    suffixes = SUFFIXES[:3 * len(levels)]
    names = [f"{b}.{s}" for b in body_names for s in suffixes]
    blocks = [a[:, 3 * i:3 * i + 3] for i in range(len(body_names)) for a in levels]
    n = levels[0].shape[0]
    return names, np.hstack(blocks) if blocks else np.zeros((n, 0))


def constraint_columns(constraint_names: Sequence[str], driver_flags: Sequence[bool],
                       row_owner: Sequence[int], row_labels: Sequence[str], lam: np.ndarray,
                       reac: np.ndarray | None, multipliers: bool, efforts: bool
                       ) -> tuple[list[str], list[np.ndarray]]:
    """The optional columns that come from the multipliers, in table order:
    ``lambda.LABEL`` per row (multipliers), NAME.fx ... NAME.mz_j per constraint (when
    ``reac``, (n, nc, 6), is given) and ``NAME.effort`` per driver, -lambda of its row
    (efforts). ``lam`` is (n, neq)."""
    names: list[str] = []
    blocks: list[np.ndarray] = []
    if multipliers:
        names += [f"lambda.{r}" for r in row_labels]
        blocks.append(lam)
    if reac is not None:
        for k, name in enumerate(constraint_names):
            names += [f"{name}.{w}" for w in REACTION_WORDS]
            blocks.append(reac[:, k, :])
    if efforts:
        for k, name in enumerate(constraint_names):
            if driver_flags[k]:
                names.append(f"{name}.effort")
                blocks.append(-lam[:, row_owner.index(k), None])
    return names, blocks


def derivative_names(names: Sequence[str], parameter: str) -> list[str]:
    """The names of the sensitivity columns of the columns called names: d(NAME)/d(PARAM)."""
    return [f"d({c})/d({parameter})" for c in names]


def require_sensitivities(present: bool, what: str) -> None:
    """The ModelError of ``sensitivities=True`` on a result computed without them."""
    if not present:
        raise ModelError("this result has no sensitivities: run the analysis with "
                         "sensitivities=[names] (command line: --sensitivities NAMES)", what)
