"""Degrees of freedom and redundancy at an assembled configuration."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


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
