"""Degrees of freedom and redundancy at an assembled configuration."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .files import write_csv


@dataclass
class DofReport:
    """Degrees of freedom and redundancy at an assembled configuration.

    Attributes
    ----------
    coordinates : int
        Number of coordinates (3 per body plus curve parameters).
    equations : int
        Number of constraint equations (joints and drivers).
    rank : int
        Rank of the constraint Jacobian J (rank-revealing QR, LAPACK dgeqp3).
    dof : int
        coordinates - rank: the motion left free (0 for a driven mechanism).
    mobility : int
        Degrees of freedom of the joints alone (without drivers).
    redundant_rows : list of str
        Row labels of the redundant equations (NAME.equation).
    redundant_constraints : list of str
        The joints or drivers those rows belong to.
    q : numpy.ndarray
        The assembled configuration.
    coordinate_names, row_labels : list of str
        The names of the entries of q and of the rows of Phi.
    """

    model_name: str
    t: float
    coordinates: int
    equations: int
    rank: int
    dof: int
    mobility: int
    redundant_rows: list[str] = field(default_factory=list)
    redundant_constraints: list[str] = field(default_factory=list)
    q: np.ndarray = field(default_factory=lambda: np.zeros(0))
    coordinate_names: list[str] = field(default_factory=list)
    row_labels: list[str] = field(default_factory=list)

    def table(self) -> tuple[list[str], np.ndarray]:
        """Header and the one row of the CSV: ``t``, the assembled configuration (a column
        per coordinate), ``coordinates``, ``equations``, ``rank``, ``dof``, ``mobility``, then
        ``redundant.LABEL`` per row of Phi (1 redundant, 0 not); ``mbd2d-solve`` writes the
        same for an exported ``check``."""
        header = ["t", *self.coordinate_names, "coordinates", "equations", "rank", "dof",
                  "mobility", *(f"redundant.{r}" for r in self.row_labels)]
        red = set(self.redundant_rows)
        row = [self.t, *self.q, self.coordinates, self.equations, self.rank, self.dof,
               self.mobility, *(1.0 if r in red else 0.0 for r in self.row_labels)]
        return header, np.array([row], dtype=float)

    def to_csv(self, path: Any) -> None:
        """Write :meth:`table` as CSV (numbers as every mbd2d CSV, ``%.16e``)."""
        header, rows = self.table()
        write_csv(path, header, rows, "to_csv")

    def __str__(self) -> str:
        lines = [f"model '{self.model_name}' at t = {self.t:g}",
                 f"  coordinates        {self.coordinates}",
                 f"  equations          {self.equations}",
                 f"  rank of J          {self.rank}",
                 f"  degrees of freedom {self.dof}   (coordinates - rank)",
                 f"  mobility           {self.mobility}   (joints alone, without drivers)",
                 f"  redundant          {len(self.redundant_rows)} equation(s)"]
        for r in self.redundant_rows:
            lines.append(f"    {r}")
        if self.redundant_rows:
            lines.append("  redundant equations repeat what the others impose: kinematics solves "
                         "them in least squares; reactions are statically indeterminate")
        return "\n".join(lines)
