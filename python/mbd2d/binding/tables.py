"""The flat tables the Fortran core reads (see ``fortran/mbd_model.f90``), with the names that
go with them."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

NCT = 8  # rows of the constraint table
NFT = 6  # rows of the force table


@dataclass
class Packed:
    """A model as flat tables, with the names that go with them."""

    nb: int
    ctab: np.ndarray            # int32 (NCT, nc), Fortran order
    rpar: np.ndarray            # float64
    q0: np.ndarray              # float64 (nq,), extras zero (the core estimates them)
    nq: int
    neq: int
    body_names: list[str]
    constraint_names: list[str]
    driver_flags: list[bool]
    coordinate_names: list[str]
    row_owner: list[int] = field(default_factory=list)   # constraint index of each row
    row_labels: list[str] = field(default_factory=list)

    @property
    def nc(self) -> int:
        return self.ctab.shape[1]


@dataclass
class DynamicTables:
    """What dynamics adds to :class:`Packed`: masses, gravity, forces and initial velocities."""

    bmass: np.ndarray           # float64 (2, nb): mass, inertia
    grav: np.ndarray            # float64 (2,)
    ftab: np.ndarray            # int32 (NFT, nf), Fortran order
    fpar: np.ndarray            # float64
    v0: np.ndarray              # float64 (nq,)


def decode(raw: bytes | str) -> str:
    """A Fortran message as text."""
    if isinstance(raw, bytes):
        raw = raw.decode("utf-8", "replace")
    return raw.strip()


@dataclass
class BatchTables:
    """Everything one batch call of the core needs besides the case values (see
    ``fortran/mbd_batch.f90``): the model's tables once, the entries each case sets, the
    open phases to set again, and the analysis settings. Picklable: worker processes and
    Dask workers get it whole."""

    analysis: int               # 1 kinematics, 2 inverse dynamics, 3 statics, 4 dynamics
    nb: int
    ctab: np.ndarray            # int32 (NCT, nc)
    rpar: np.ndarray            # float64
    bmass: np.ndarray           # float64 (2, nb); zeros for kinematics
    grav: np.ndarray            # float64 (2,)
    ftab: np.ndarray            # int32 (NFT, nf)
    fpar: np.ndarray            # float64
    q0: np.ndarray              # float64 (nq,)
    v0: np.ndarray              # float64 (nq,)
    vtab: np.ndarray            # int32 (2, nv): (table, 1-based index) of each value row
    opens: np.ndarray           # int32 (2, no): (rpar index, row of Phi) of the open phases
    iset: np.ndarray            # int32 (8,) integer settings
    rset: np.ndarray            # float64 (12,) real settings
    neq: int
    nrow: int                   # output rows per case
    nlam: int                   # neq for the analyses with multipliers, else 0
    ne: int                     # 4 for the analyses with energies, else 0

    @property
    def nq(self) -> int:
        return len(self.q0)

    @property
    def nd(self) -> int:
        """Rows of the velocities and accelerations: 0 for positions-only kinematics."""
        return 0 if self.analysis == 1 and int(self.iset[6]) == 1 else self.nrow
