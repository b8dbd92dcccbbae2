"""A point fixed in a body: its global position, velocity and acceleration over a run.

For a point with local coordinates s' in body i (r_i, theta_i), A(theta) the rotation matrix
and B = dA/dtheta (Haug, ch. 2; Nikravesh, ch. 2)::

    r_P     = r_i + A s'
    r_P_dot = r_i_dot + theta_dot B s'                       (B s' = A s' turned by +90 deg)
    r_P_ddot = r_i_ddot + theta_ddot B s' - theta_dot**2 A s'

and along a design parameter p, from the body's sensitivities (dB/dtheta = -A)::

    d r_P     = d r_i + B s' d theta
    d r_P_dot = d r_i_dot + d theta_dot B s' - theta_dot A s' d theta
    d r_P_ddot = d r_i_ddot + d theta_ddot B s' - theta_ddot A s' d theta
                 - 2 theta_dot d theta_dot A s' - theta_dot**2 B s' d theta
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ModelError


@dataclass
class PointResult:
    """Position, velocity and acceleration of a body point at the output times.

    Attributes
    ----------
    body : str
        The body the point is fixed in.
    s : tuple of float
        The point in the body's frame.
    r, v, a : numpy.ndarray
        Global position, velocity and acceleration, each (n, 2): columns x and y (``v`` and
        ``a`` None after a ``positions_only`` run; their components raise ModelError).

    Indexing the result indexes the positions, so ``res.point("rod", s)[:, 0]`` is the
    x path, as before the velocities were added.
    """

    body: str
    s: tuple[float, float]
    r: np.ndarray
    v: np.ndarray | None
    a: np.ndarray | None

    @classmethod
    def of(cls, body: str, s: tuple[float, float], q: np.ndarray, qd: np.ndarray | None,
           qdd: np.ndarray | None) -> "PointResult":
        """The point s of a body from its (n, 3) coordinates, velocities, accelerations
        (None: positions only)."""
        th = q[:, 2]
        c, sn = np.cos(th), np.sin(th)
        as_ = np.column_stack([c * s[0] - sn * s[1], sn * s[0] + c * s[1]])   # A s'
        r = q[:, :2] + as_
        if qd is None or qdd is None:
            return cls(body, s, r, None, None)
        w, al = qd[:, 2], qdd[:, 2]
        bs = np.column_stack([-as_[:, 1], as_[:, 0]])                       # B s'
        v = qd[:, :2] + w[:, None] * bs
        a = qdd[:, :2] + al[:, None] * bs - (w**2)[:, None] * as_
        return cls(body, s, r, v, a)

    @staticmethod
    def derivatives(s: tuple[float, float], levels: list[np.ndarray],
                    dlevels: list[np.ndarray]) -> list[np.ndarray]:
        """d r_P, d r_P_dot, d r_P_ddot (each (n, 2, n_params), as many as levels are given)
        of the point s from the body's levels q, q_dot, q_ddot (each (n, 3)) and their
        sensitivities (each (n, 3, n_params))."""
        th = levels[0][:, 2]
        c, sn = np.cos(th), np.sin(th)
        a_s = np.column_stack([c * s[0] - sn * s[1], sn * s[0] + c * s[1]])[:, :, None]
        b_s = np.concatenate([-a_s[:, 1:], a_s[:, :1]], axis=1)           # B s' = A s' + 90
        dth = dlevels[0][:, None, 2, :]
        out = [dlevels[0][:, :2, :] + b_s * dth]
        if len(levels) > 1:
            w, dw = levels[1][:, None, 2, None], dlevels[1][:, None, 2, :]
            out.append(dlevels[1][:, :2, :] + b_s * dw - w * a_s * dth)
        if len(levels) > 2:
            al, dal = levels[2][:, None, 2, None], dlevels[2][:, None, 2, :]
            out.append(dlevels[2][:, :2, :] + b_s * dal - al * a_s * dth
                       - 2 * w * dw * a_s - w**2 * b_s * dth)
        return out

    def _rates(self, which: str) -> np.ndarray:
        """v or a, or a ModelError after a positions-only run."""
        x = self.v if which == "v" else self.a
        if x is None:
            raise ModelError("the run computed positions only (positions_only=True): run "
                             "the kinematics without it for velocities and accelerations",
                             "positions_only")
        return x

    @property
    def x(self) -> np.ndarray:
        """Global x of the point."""
        return self.r[:, 0]

    @property
    def y(self) -> np.ndarray:
        """Global y of the point."""
        return self.r[:, 1]

    @property
    def x_dot(self) -> np.ndarray:
        """Velocity, x component."""
        return self._rates("v")[:, 0]

    @property
    def y_dot(self) -> np.ndarray:
        """Velocity, y component."""
        return self._rates("v")[:, 1]

    @property
    def x_ddot(self) -> np.ndarray:
        """Acceleration, x component."""
        return self._rates("a")[:, 0]

    @property
    def y_ddot(self) -> np.ndarray:
        """Acceleration, y component."""
        return self._rates("a")[:, 1]

    @property
    def speed(self) -> np.ndarray:
        """|v|."""
        v = self._rates("v")
        return np.hypot(v[:, 0], v[:, 1])

    # the positions as an (n, 2) array
    @property
    def shape(self) -> tuple[int, ...]:
        return self.r.shape

    def __len__(self) -> int:
        return len(self.r)

    def __getitem__(self, key: Any) -> Any:
        return self.r[key]

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self.r if dtype is None else self.r.astype(dtype)

    def __repr__(self) -> str:
        return (f"PointResult({self.body!r}, s=({self.s[0]:g}, {self.s[1]:g}), "
                f"{len(self.r)} rows: r, v, a)")
