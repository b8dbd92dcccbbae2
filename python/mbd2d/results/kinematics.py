"""Kinematic results: positions, velocities and accelerations by time, per-body views, CSV
and NPZ output."""
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
