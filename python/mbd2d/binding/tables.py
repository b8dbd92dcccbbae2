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
class MeasureTables:
    """A list of mechanism measures as the core takes them (``api_measures`` in
    ``fortran/mbd_measures.f90``): per measure its kind (1 transmission angle, 2 velocity
    ratio, 3 mechanical advantage, 4 distance to a dead centre), its integers (an angle: its
    kind and three bodies; a ratio: the driver's row, X's kind and index, Y's kind and index;
    1-based), an angle's points and the raw-parameter entries they come from (1-based; 0
    the number given)."""

    specs: list[str]
    kind: np.ndarray            # int32 (nm,)
    mint: np.ndarray            # int32 (5, nm)
    mpts: np.ndarray            # float64 (2, 3, nm)
    mref: np.ndarray            # int32 (2, 3, nm)

    @classmethod
    def empty(cls) -> "MeasureTables":
        """No measure."""
        return cls([], np.zeros(0, dtype=np.int32), np.zeros((5, 0), dtype=np.int32, order="F"),
                   np.zeros((2, 3, 0), order="F"),
                   np.zeros((2, 3, 0), dtype=np.int32, order="F"))


@dataclass
class BatchTables:
    """Everything one batch call of the core needs besides the case values (see
    ``fortran/mbd_batch.f90``): the model's tables once, the entries each case sets, the
    open phases to set again, and the analysis settings. Picklable: worker processes and
    Dask workers get it whole."""

    analysis: int               # 1 kinematics, 2 inverse dynamics, 3 statics, 4 dynamics,
    #                             5 modes (rows: the modes), 6 frequency response (rows: the
    #                             frequencies, given as times in rad/s; ptab: the inputs)
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
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))   # (nrow,) output times
    measures: MeasureTables = field(default_factory=MeasureTables.empty)
    #: design parameters of the sensitivities (int32 (2, npar)) and their names (the
    #: frequency response: its inputs)
    ptab: np.ndarray = field(default_factory=lambda: np.zeros((2, 0), dtype=np.int32))
    sensitivities: list[str] = field(default_factory=list)

    @property
    def nq(self) -> int:
        return len(self.q0)

    @property
    def nd(self) -> int:
        """Rows of the velocities and accelerations: 0 for positions-only kinematics and for
        modes and the frequency response."""
        return 0 if (self.analysis == 1 and int(self.iset[6]) == 1) or self.analysis in (5, 6) \
            else self.nrow

    @property
    def npar(self) -> int:
        """Design parameters of the sensitivities."""
        return self.ptab.shape[1]

    @property
    def nsl(self) -> int:
        """Rows of the multipliers' sensitivities: every analysis but kinematics has them;
        the frequency response's, the multipliers' response (real parts, then imaginary)."""
        if not self.npar:
            return 0
        return 2 * self.neq if self.analysis == 6 else self.neq if self.analysis in (2, 3, 4) \
            else 0
