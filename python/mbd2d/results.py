"""Results of an analysis: arrays by time, per-body views, CSV and NPZ output."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

SUFFIXES = ("x", "y", "theta", "x_dot", "y_dot", "theta_dot", "x_ddot", "y_ddot", "theta_ddot")


@dataclass
class BodyResult:
    """Time histories of one body (arrays over the output times)."""

    name: str
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    x_dot: np.ndarray
    y_dot: np.ndarray
    theta_dot: np.ndarray
    x_ddot: np.ndarray
    y_ddot: np.ndarray
    theta_ddot: np.ndarray


@dataclass
class KinematicsResult:
    """Positions, velocities and accelerations at the output times.

    Attributes
    ----------
    t : numpy.ndarray
        Output times (n,).
    q, qd, qdd : numpy.ndarray
        Coordinates, velocities, accelerations (n, nq); rows are times. Columns are
        ``coordinate_names``: x, y, theta of each body, then extra coordinates (cam alpha).
    body_names, coordinate_names : list of str
    stats : dict
        Newton corrections, LU factorizations, rejected steps, tolerance used.
    complete : bool
        False when the run stopped early (see the exception that carried this result).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    body_names: list[str]
    coordinate_names: list[str]
    stats: dict[str, Any] = field(default_factory=dict)
    complete: bool = True
    model: Any = None

    def body(self, name: str) -> BodyResult:
        """Histories of the body called name.

        Raises
        ------
        KeyError
            If there is no such body.
        """
        try:
            i = self.body_names.index(name)
        except ValueError:
            raise KeyError(f"no body {name!r}; bodies: {', '.join(self.body_names)}") from None
        c = slice(3 * i, 3 * i + 3)
        q, qd, qdd = self.q[:, c], self.qd[:, c], self.qdd[:, c]
        return BodyResult(name, q[:, 0], q[:, 1], q[:, 2], qd[:, 0], qd[:, 1], qd[:, 2],
                          qdd[:, 0], qdd[:, 1], qdd[:, 2])

    def point(self, name: str, s: Any) -> np.ndarray:
        """Global path r + A(theta) s' of a point s' fixed in a body, shape (n, 2)."""
        b = self.body(name)
        sx, sy = float(s[0]), float(s[1])
        c, sn = np.cos(b.theta), np.sin(b.theta)
        return np.column_stack([b.x + c * sx - sn * sy, b.y + sn * sx + c * sy])

    def table(self) -> tuple[list[str], np.ndarray]:
        """Header and rows of the CSV: t, then NAME.x ... NAME.theta_ddot per body."""
        header = ["t"] + [f"{b}.{s}" for b in self.body_names for s in SUFFIXES]
        nb = len(self.body_names)
        blocks = [self.t[:, None]]
        for i in range(nb):
            c = slice(3 * i, 3 * i + 3)
            blocks += [self.q[:, c], self.qd[:, c], self.qdd[:, c]]
        return header, np.hstack(blocks)

    def to_csv(self, path: str | Path) -> None:
        """Write the CSV (17 significant digits)."""
        header, rows = self.table()
        np.savetxt(path, rows, delimiter=",", header=",".join(header), comments="", fmt="%.17g")

    def to_npz(self, path: str | Path) -> None:
        """Write t, q, qd, qdd and the names to a NumPy .npz archive."""
        np.savez(path, t=self.t, q=self.q, qd=self.qd, qdd=self.qdd,
                 coordinate_names=np.array(self.coordinate_names),
                 body_names=np.array(self.body_names))

    def save(self, path: str | Path) -> None:
        """Write .csv or .npz by the file suffix."""
        if str(path).endswith(".npz"):
            self.to_npz(path)
        else:
            self.to_csv(path)

    def __repr__(self) -> str:
        span = f"t = {self.t[0]:g} .. {self.t[-1]:g}" if len(self.t) else "no rows"
        return (f"{type(self).__name__}({len(self.t)} rows, {span}, {len(self.coordinate_names)} "
                f"coordinates{'' if self.complete else ', incomplete'})")


@dataclass
class Reaction:
    """Reaction of a joint or driver on its two bodies over time (arrays over outputs).

    fx, fy are the force on body i (global components) and mz the moment about its centre
    of mass; fx_j, fy_j, mz_j the same on body j. The ``_local`` arrays are the forces in
    each body's own frame. Forces on ground are zero (ground has no coordinates).
    """

    name: str
    bodies: tuple[str, str]
    fx: np.ndarray
    fy: np.ndarray
    mz: np.ndarray
    fx_j: np.ndarray
    fy_j: np.ndarray
    mz_j: np.ndarray
    fx_local: np.ndarray
    fy_local: np.ndarray
    fx_j_local: np.ndarray
    fy_j_local: np.ndarray


@dataclass(repr=False)
class DynamicsResult(KinematicsResult):
    """A kinematic or dynamic run with multipliers, energies and constraint drift.

    Attributes
    ----------
    lam : numpy.ndarray
        Lagrange multipliers (n, neq), rows labelled by ``row_labels``; with redundant
        constraints the minimum-norm set.
    kinetic, potential : numpy.ndarray
        Kinetic energy q_dot^T M q_dot / 2 and potential energy (gravity and springs).
    drift_position, drift_velocity : numpy.ndarray
        ||Phi||_inf and ||J q_dot - nu||_inf at each output.
    """

    lam: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    kinetic: np.ndarray = field(default_factory=lambda: np.zeros(0))
    potential: np.ndarray = field(default_factory=lambda: np.zeros(0))
    drift_position: np.ndarray = field(default_factory=lambda: np.zeros(0))
    drift_velocity: np.ndarray = field(default_factory=lambda: np.zeros(0))
    row_labels: list[str] = field(default_factory=list)
    packed: Any = None
    _reac: Any = None

    @property
    def energy(self) -> np.ndarray:
        """Kinetic plus potential energy."""
        return self.kinetic + self.potential

    def _reactions(self) -> tuple[np.ndarray, np.ndarray]:
        if self._reac is None:
            from .dynamics import reactions
            self._reac = reactions(self.packed, self.q, self.t, self.lam)
        return self._reac

    def reaction(self, name: str) -> Reaction:
        """Reaction of the joint or driver called name on its two bodies.

        Raises
        ------
        KeyError
            If there is no such joint or driver.
        """
        names = self.packed.constraint_names
        if name not in names:
            raise KeyError(f"no joint or driver {name!r}; known: {', '.join(names)}")
        k = names.index(name)
        g, loc = self._reactions()
        c = self.model.constraints[k]
        r, rl = g[:, k, :], loc[:, k, :]
        return Reaction(name, c.bodies, r[:, 0], r[:, 1], r[:, 2], r[:, 3], r[:, 4], r[:, 5],
                        rl[:, 0], rl[:, 1], rl[:, 3], rl[:, 4])

    def effort(self, name: str) -> np.ndarray:
        """What the driver called name supplies: the torque (angle drivers) or force
        (x, y or slide drivers) in the driven direction, -lambda of its row."""
        names = self.packed.constraint_names
        if name not in names or not self.packed.driver_flags[names.index(name)]:
            raise KeyError(f"no driver {name!r}")
        row = self.packed.row_owner.index(names.index(name))
        return -self.lam[:, row]

    def multiplier(self, row: str) -> np.ndarray:
        """The multiplier of a row by its label (see ``model.constraint_rows()``)."""
        return self.lam[:, self.row_labels.index(row)]

    def to_npz(self, path: str | Path) -> None:
        """t, q, qd, qdd, the multipliers and energies, and the names."""
        np.savez(path, t=self.t, q=self.q, qd=self.qd, qdd=self.qdd, lam=self.lam,
                 kinetic=self.kinetic, potential=self.potential,
                 drift_position=self.drift_position, drift_velocity=self.drift_velocity,
                 coordinate_names=np.array(self.coordinate_names),
                 body_names=np.array(self.body_names), row_labels=np.array(self.row_labels))


@dataclass
class StaticsResult:
    """A static equilibrium: configuration, multipliers, reactions and stability;
    ``residual`` is the unbalanced load ||N^T Q||_inf relative to the largest load."""

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
        from .dynamics import reactions
        names = self.packed.constraint_names
        if name not in names:
            raise KeyError(f"no joint or driver {name!r}; known: {', '.join(names)}")
        k = names.index(name)
        g, loc = reactions(self.packed, self.q[None, :], np.array([self.t]), self.lam[None, :])
        r, rl = g[:, k, :], loc[:, k, :]
        c = self.model.constraints[k]
        return Reaction(name, c.bodies, r[:, 0], r[:, 1], r[:, 2], r[:, 3], r[:, 4], r[:, 5],
                        rl[:, 0], rl[:, 1], rl[:, 3], rl[:, 4])

    def multiplier(self, row: str) -> float:
        """The multiplier of a row by its label."""
        return float(self.lam[self.row_labels.index(row)])


def read_csv(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a result CSV back: (header, rows)."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return header, rows
