"""Static results: an equilibrium with its multipliers, reactions and stability."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .reactions import Reaction, reaction_arrays, reaction_of


@dataclass
class StaticsResult:
    """A static equilibrium: configuration, multipliers, reactions and stability."""

    t: float
    q: np.ndarray
    lam: np.ndarray
    stability: str
    residual: float
    body_names: list[str]
    coordinate_names: list[str]
    row_labels: list[str]
    model: Any = None
    packed: Any = None

    def body(self, name: str) -> tuple[float, float, float]:
        """(x, y, theta) of a body at the equilibrium."""
        i = self.body_names.index(name)
        return tuple(float(v) for v in self.q[3 * i:3 * i + 3])  # type: ignore[return-value]

    def reaction(self, name: str) -> Reaction:
        """The reaction of a joint or driver at the equilibrium (arrays of length 1)."""
        return reaction_of(self.packed, self.model, name, lambda: reaction_arrays(
            self.packed, self.q[None, :], np.array([self.t]), self.lam[None, :]))

    def multiplier(self, row: str) -> float:
        """The multiplier of a row by its label."""
        return float(self.lam[self.row_labels.index(row)])
