"""Static results: an equilibrium with its multipliers, reactions and stability."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import plots
from .columns import constraint_columns, derivative_names, require_sensitivities
from .files import check_outputs, write_csv
from .kinematics import repr_png
from .reactions import Reaction, reaction_arrays, reaction_of
from .sensitivities import body_columns, parameter_index, reaction_dp_arrays, reaction_dp_of


#: the core's stability codes (the ``stable`` column of a table)
STABILITY_CODES = {"stable": 1, "unstable": 0, "neutral": -1, "fully constrained": 2}


@dataclass
class StaticsResult:
    """A static equilibrium: configuration, multipliers, reactions and stability;
    ``residual`` is the unbalanced load ||N^T Q||_inf relative to the largest load (or to the
    reduced stiffness times the model's size, when larger). With
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
    #: the linear-algebra path: {"solver": "dense" | "banded", "band": (kl, ku)}
    stats: dict = field(default_factory=dict)
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

    def configuration(self) -> Any:
        """The equilibrium as a one-row motion for the pictures."""
        return plots.Configuration(self.model, self.q, self.t)

    def plot(self, **kwargs: Any) -> Any:
        """The mechanism at the equilibrium: :func:`mbd2d.plot_mechanism` (returns the
        Axes)."""
        kwargs.setdefault("title", f"{getattr(self.model, 'name', 'model')}: equilibrium "
                          f"({self.stability})")
        return plots.plot_mechanism(self.configuration(), **kwargs)

    def _repr_png_(self) -> bytes | None:
        """The equilibrium's picture, for Jupyter."""
        return repr_png(self.configuration())
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
        return reaction_dp_of(self.packed, self.model, name, *self._reaction_dp_arrays())

    def _reaction_dp_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The reactions' sensitivities (1, nc, 6, n_params), global and local."""
        assert self.dq_dp is not None and self.dlam_dp is not None
        return reaction_dp_arrays(self.packed, self.ptab, self.q[None, :], np.array([self.t]),
                                  self.lam[None, :], self.dq_dp[None], self.dlam_dp[None])

    def table(self, multipliers: bool = False, reactions: bool = False, efforts: bool = False,
              sensitivities: bool = False, **unknown: bool) -> tuple[list[str], np.ndarray]:
        """Header and the one row of the CSV: t, NAME.x, NAME.y, NAME.theta per body,
        ``stable`` (1 stable, 0 unstable, -1 neutral, 2 fully constrained), ``residual``,
        then optional columns as :meth:`DynamicsResult.table` (``multipliers``,
        ``reactions``, ``efforts``; ``mbd2d-solve`` writes the same); with
        ``sensitivities=True`` (statics with ``sensitivities=[names]``) then, for each
        parameter P in turn, ``d(COLUMN)/d(P)`` of the body columns and of the optional
        columns asked for."""
        check_outputs(unknown, (), "table")
        nb = len(self.body_names)
        header = ["t"] + self._body_columns()
        header += ["stable", "residual"]
        row = [np.array([self.t, *self.q[:3 * nb], STABILITY_CODES.get(self.stability, 0),
                         self.residual])]
        reac = None
        if reactions:
            reac, _ = reaction_arrays(self.packed, self.q[None, :], np.array([self.t]),
                                      self.lam[None, :])
        names, blocks = self._constraint_columns(self.lam, reac, multipliers, efforts)
        header += names
        row += [b[0] for b in blocks]
        if sensitivities:
            names, values = self._derivative_columns(multipliers, reactions, efforts)
            header += names
            row += values
        return header, np.concatenate(row)[None, :].astype(float)

    def _body_columns(self) -> list[str]:
        return [f"{b}.{s}" for b in self.body_names for s in ("x", "y", "theta")]

    def _constraint_columns(self, lam: np.ndarray, reac: np.ndarray | None, multipliers: bool,
                            efforts: bool) -> tuple[list[str], list[np.ndarray]]:
        p = self.packed
        return constraint_columns(p.constraint_names, p.driver_flags, p.row_owner,
                                  self.row_labels, lam[None, :], reac, multipliers, efforts)

    def _derivative_columns(self, multipliers: bool, reactions: bool, efforts: bool
                            ) -> tuple[list[str], list[np.ndarray]]:
        """d(COLUMN)/d(P) of the body columns and the optional columns, parameter after
        parameter (names, and one row of values per parameter)."""
        require_sensitivities(self.dq_dp is not None and self.dlam_dp is not None, "table")
        assert self.dq_dp is not None and self.dlam_dp is not None
        dreac = self._reaction_dp_arrays()[0] if reactions else None
        nb = len(self.body_names)
        names: list[str] = []
        values: list[np.ndarray] = []
        for k, prm in enumerate(self.parameter_names):
            cn, cb = self._constraint_columns(self.dlam_dp[:, k],
                                              None if dreac is None else dreac[..., k],
                                              multipliers, efforts)
            names += derivative_names(self._body_columns() + cn, prm)
            values += [self.dq_dp[:3 * nb, k]] + [b[0] for b in cb]
        return names, values

    def to_csv(self, path: Any, **outputs: bool) -> None:
        """Write the table (:meth:`table`) as CSV, numbers as every mbd2d CSV."""
        header, rows = self.table(**outputs)
        write_csv(path, header, rows, "to_csv")

    def multiplier(self, row: str) -> float:
        """The multiplier of a row by its label (KeyError if no row has it)."""
        if row not in self.row_labels:
            raise KeyError(f"no row {row!r}; rows: {', '.join(self.row_labels)}")
        return float(self.lam[self.row_labels.index(row)])
