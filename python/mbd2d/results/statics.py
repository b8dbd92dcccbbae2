"""Static results: an equilibrium with its multipliers, reactions and stability."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .reactions import Reaction, reaction_arrays, reaction_of
from .sensitivities import body_columns, parameter_index, reaction_dp_arrays, reaction_dp_of


@dataclass
class StaticsResult:
    """A static equilibrium: configuration, multipliers, reactions and stability;
    ``residual`` is the unbalanced load ||N^T Q||_inf relative to the largest load. With
    ``sensitivities=[...]`` also ``dq_dp`` (nq, n_params) and ``dlam_dp`` (neq, n_params),
    the derivatives of the equilibrium and its multipliers."""

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
    parameter_names: list[str] = field(default_factory=list)
    dq_dp: np.ndarray | None = None
    dlam_dp: np.ndarray | None = None
    ptab: Any = None

    def body(self, name: str) -> tuple[float, float, float]:
        """(x, y, theta) of a body at the equilibrium (KeyError if there is none)."""
        if name not in self.body_names:
            raise KeyError(f"no body {name!r}; bodies: {', '.join(self.body_names)}")
        i = self.body_names.index(name)
        return tuple(float(v) for v in self.q[3 * i:3 * i + 3])  # type: ignore[return-value]

    def reaction(self, name: str) -> Reaction:
        """The reaction of a joint or driver at the equilibrium (arrays of length 1)."""
        return reaction_of(self.packed, self.model, name, lambda: reaction_arrays(
            self.packed, self.q[None, :], np.array([self.t]), self.lam[None, :]))

    def sensitivity(self, body: str, name: str) -> np.ndarray:
        """d(x, y, theta)/dp of a body at the equilibrium for the parameter called name."""
        k = parameter_index(self.parameter_names, name)
        assert self.dq_dp is not None
        return self.dq_dp[body_columns(self.body_names, body), k]

    def reaction_dp(self, name: str) -> Reaction:
        """Sensitivities of a joint's or driver's reaction (arrays (1, n_params))."""
        if self.dq_dp is None or self.dlam_dp is None:
            raise KeyError("this result has no sensitivities: run statics with "
                           "sensitivities=[names]")
        g, loc = reaction_dp_arrays(self.packed, self.ptab, self.q[None, :],
                                    np.array([self.t]), self.lam[None, :], self.dq_dp[None],
                                    self.dlam_dp[None])
        return reaction_dp_of(self.packed, self.model, name, g, loc)

    def multiplier(self, row: str) -> float:
        """The multiplier of a row by its label (KeyError if no row has it)."""
        if row not in self.row_labels:
            raise KeyError(f"no row {row!r}; rows: {', '.join(self.row_labels)}")
        return float(self.lam[self.row_labels.index(row)])
