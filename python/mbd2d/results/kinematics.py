"""Kinematic results: positions, velocities and accelerations by time, per-body views, CSV
and NPZ output."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..validate import vector
from .files import writing
from .sensitivities import LEVELS, body_columns, parameter_index

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
    parameter_names : list of str
        The design parameters of ``sensitivities=[...]`` (empty without them).
    dq_dp, dqd_dp, dqdd_dp : numpy.ndarray or None
        Their sensitivities d q / d p, d q_dot / d p, d q_ddot / d p, each
        (n, n_coordinates, n_params), computed in the core (None without them).
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
    parameter_names: list[str] = field(default_factory=list)
    dq_dp: np.ndarray | None = None
    dqd_dp: np.ndarray | None = None
    dqdd_dp: np.ndarray | None = None

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

    def sensitivity(self, body: str, name: str, of: str = "q") -> np.ndarray:
        """d(x, y, theta)/dp of a body over time, shape (n, 3), for the design parameter
        called name; ``of`` = "qd" or "qdd" for the velocities' or accelerations'.

        Raises
        ------
        KeyError
            For an unknown body, a parameter the run was not asked for, or a bad ``of``.

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> res = m.kinematics(1.0, 10, sensitivities=["joint.B.points.0.0"])
        >>> res.sensitivity("rocker", "joint.B.points.0.0").shape
        (11, 3)
        """
        if of not in LEVELS:
            raise KeyError(f"of must be one of {', '.join(LEVELS)}, got {of!r}")
        k = parameter_index(self.parameter_names, name)
        arr = {"q": self.dq_dp, "qd": self.dqd_dp, "qdd": self.dqdd_dp}[of]
        assert arr is not None
        return arr[:, body_columns(self.body_names, body), k]

    def point(self, name: str, s: Any) -> np.ndarray:
        """Global path r + A(theta) s' of a point s' fixed in a body, shape (n, 2)."""
        sx, sy = vector(s, 2, "s", "point")
        b = self.body(name)
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
        with writing(path, "to_csv") as p:
            np.savetxt(p, rows, delimiter=",", header=",".join(header), comments="",
                       fmt="%.17g")

    def to_npz(self, path: str | Path) -> None:
        """Write t, q, qd, qdd and the names to a NumPy .npz archive."""
        with writing(path, "to_npz") as p:
            np.savez(p, t=self.t, q=self.q, qd=self.qd, qdd=self.qdd,
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
