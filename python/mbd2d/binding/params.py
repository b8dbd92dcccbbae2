"""Design parameters as the core addresses them: a column (table, 1-based index) of the
parameter table per parameter (see ``fortran/mbd_sensitivity.f90``): 1 the constraints' raw
parameters, 2 the masses (flattened (2, nb)), 3 gravity, 4 the forces' raw parameters."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..description.parameters import Parameter
from .tables import DynamicTables, Packed

TABLE_IDS = {"constraint": 1, "mass": 2, "gravity": 3, "force": 4}


def parameter_table(p: Packed, params: Sequence[Parameter],
                    d: DynamicTables | None = None) -> np.ndarray:
    """The parameter table, int32 (2, np) in Fortran order.

    Force parameters need the force table (``d``); without it (a kinematic run, where no
    force enters) they are passed as pointing at no force, and their sensitivities are zero.
    """
    cols = []
    for prm in params:
        if prm.table == "constraint":
            index = int(p.ctab[5, prm.element]) + prm.raw
        elif prm.table == "mass":
            index = 2 * prm.element + 1 + prm.raw
        elif prm.table == "gravity":
            index = 1 + prm.raw
        else:
            index = 1 + prm.raw if d is None else int(d.ftab[3, prm.element]) + prm.raw
        cols.append([TABLE_IDS[prm.table], index])
    return np.asfortranarray(np.array(cols, dtype=np.int32).reshape(-1, 2).T)


def open_values(p: Packed, params: Sequence[Parameter]) -> dict[str, float]:
    """Values of the parameters left open in the description (a gear or rolling phase taken
    from the q0 estimates), as packed."""
    return {prm.name: float(p.rpar[int(p.ctab[5, prm.element]) - 1 + prm.raw])
            for prm in params if prm.value is None and prm.table == "constraint"}
