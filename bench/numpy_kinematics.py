"""Plain NumPy kinematic analysis: the speed baseline for mbd2d's Fortran time loop.

The same analysis ``mbd2d.Model.kinematics`` does, written the way a competent user would
write it in Python with NumPy alone: Haug's absolute coordinates q = (x, y, theta) per body
(ground implicit), one small class per constraint type (revolute, translational, absolute
driver) that evaluates its rows of Phi, J = Phi_q, nu and gamma, and a time loop that at every
output time

1. predicts q from the previous step, q + h qd + h^2/2 qdd,
2. runs Newton-Raphson on Phi(q, t) = 0 with ``np.linalg.solve`` until
   ||Phi||_inf <= 1e-12 * (the model's length scale),
3. solves J qd = nu and J qdd = gamma.

The models are read from the example TOML files (``fourbar_grashof``, ``slider_crank``).

    python bench/numpy_kinematics.py
"""
from __future__ import annotations

import time
import tomllib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Protocol

import numpy as np

EX = Path(__file__).resolve().parents[1] / "examples"
MODELS = ("fourbar_grashof", "slider_crank")
TOL = 1e-12          # ||Phi||_inf tolerance relative to the model's length scale
MAXIT = 25           # Newton iterations per output time
COORD = {"x": 0, "y": 1, "theta": 2}
GROUND = -1          # body index of the implicit ground


# ----------------------------------------------------------------------------- planar helpers

def rot(theta: float) -> np.ndarray:
    """Rotation matrix A(theta).

    Parameters
    ----------
    theta : float
        Body angle.

    Returns
    -------
    numpy.ndarray
        The 2 x 2 matrix [[cos, -sin], [sin, cos]].
    """
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def perp(v: np.ndarray) -> np.ndarray:
    """The vector v turned by +90 degrees, R v with R = [[0, -1], [1, 0]].

    Note B(theta) v = dA/dtheta v = A(theta) R v = perp(A(theta) v).
    """
    return np.array([-v[1], v[0]])


def pose(q: np.ndarray, k: int) -> tuple[np.ndarray, float]:
    """Position and angle of body k (ground: origin, angle 0).

    Parameters
    ----------
    q : numpy.ndarray
        Coordinates (or velocities) of all bodies, 3 per body.
    k : int
        Body index, or ``GROUND``.

    Returns
    -------
    r : numpy.ndarray
        (x, y) of the body.
    theta : float
        Its angle.
    """
    if k == GROUND:
        return np.zeros(2), 0.0
    return q[3 * k:3 * k + 2], q[3 * k + 2]


def put_block(jac: np.ndarray, k: int, block: np.ndarray) -> None:
    """Write the rows x 3 block of body k into the constraint's rows of J (ground: nothing).

    Parameters
    ----------
    jac : numpy.ndarray
        The constraint's rows of J (a view), rows x 3 nb.
    k : int
        Body index, or ``GROUND``.
    block : numpy.ndarray
        Partial derivatives with respect to (x_k, y_k, theta_k).
    """
    if k != GROUND:
        jac[:, 3 * k:3 * k + 3] = block


# ----------------------------------------------------------------------------- driver function

@dataclass(frozen=True)
class TimeFunction:
    """f(t) = sum c_k t^k + sum A sin(omega t + phi), with its first two derivatives."""

    poly: np.ndarray                                  # c0, c1, ...
    dpoly: np.ndarray                                 # coefficients of f'
    ddpoly: np.ndarray                                # coefficients of f''
    harmonics: tuple[tuple[float, float, float], ...]  # (A, omega, phi)

    def __call__(self, t: float) -> tuple[float, float, float]:
        """f, f' and f'' at t."""
        pv = np.polynomial.polynomial.polyval
        f, fd, fdd = pv(t, self.poly), pv(t, self.dpoly), pv(t, self.ddpoly)
        for a, w, phi in self.harmonics:
            s, co = np.sin(w * t + phi), np.cos(w * t + phi)
            f, fd, fdd = f + a * s, fd + a * w * co, fdd - a * w * w * s
        return float(f), float(fd), float(fdd)


def time_function(spec: dict | float) -> TimeFunction:
    """A TimeFunction from a TOML ``f`` entry (a table with poly/harmonic, or a number)."""
    if not isinstance(spec, dict):
        spec = {"poly": [float(spec)]}
    harm = tuple((h["amplitude"], h["omega"], h.get("phase", 0.0))
                 for h in spec.get("harmonic", ()))
    c = np.asarray(spec.get("poly", [0.0]), dtype=float)
    dc = np.polynomial.polynomial.polyder(c)
    ddc = np.polynomial.polynomial.polyder(dc)
    return TimeFunction(c, dc, ddc, harm)


# ----------------------------------------------------------------------------- constraints

class Constraint(Protocol):
    """Rows of Phi(q, t) = 0 with their Jacobian, nu = -Phi_t and gamma."""

    rows: int

    def phi(self, q: np.ndarray, t: float) -> np.ndarray: ...

    def jac(self, q: np.ndarray, out: np.ndarray) -> None: ...

    def nu(self, t: float) -> np.ndarray: ...

    def gamma(self, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray: ...


@dataclass(frozen=True)
class Revolute:
    """Revolute joint: r_i + A_i s'_i - r_j - A_j s'_j = 0 (2 rows)."""

    i: int
    j: int
    si: np.ndarray
    sj: np.ndarray
    rows: int = 2

    def phi(self, q: np.ndarray, t: float) -> np.ndarray:
        """Position constraint rows."""
        ri, thi = pose(q, self.i)
        rj, thj = pose(q, self.j)
        return ri + rot(thi) @ self.si - rj - rot(thj) @ self.sj

    def jac(self, q: np.ndarray, out: np.ndarray) -> None:
        """Write [I, B_i s'_i, -I, -B_j s'_j] into out (2 x n)."""
        _, thi = pose(q, self.i)
        _, thj = pose(q, self.j)
        bi = perp(rot(thi) @ self.si)
        bj = perp(rot(thj) @ self.sj)
        put_block(out, self.i, np.array([[1.0, 0.0, bi[0]], [0.0, 1.0, bi[1]]]))
        put_block(out, self.j, np.array([[-1.0, 0.0, -bj[0]], [0.0, -1.0, -bj[1]]]))

    def nu(self, t: float) -> np.ndarray:
        """Scleronomic: zero."""
        return np.zeros(2)

    def gamma(self, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray:
        """A_i s'_i thd_i^2 - A_j s'_j thd_j^2."""
        _, thi = pose(q, self.i)
        _, thj = pose(q, self.j)
        _, wi = pose(qd, self.i)
        _, wj = pose(qd, self.j)
        return rot(thi) @ self.si * wi ** 2 - rot(thj) @ self.sj * wj ** 2


@dataclass(frozen=True)
class Translational:
    """Translational joint (Haug 3.3.2), 2 rows.

    With d = r_j + A_j s'_j - r_i - A_i s'_i and h = A_i perp(u'_i):
    Phi_1 = h . d (point of j on the line of i), Phi_2 = theta_j - theta_i - theta0.
    """

    i: int
    j: int
    si: np.ndarray
    sj: np.ndarray
    hi: np.ndarray     # perp of the unit axis of body i, in body i's frame
    theta0: float
    rows: int = 2

    def _d(self, q: np.ndarray) -> np.ndarray:
        """d = P_j - P_i."""
        ri, thi = pose(q, self.i)
        rj, thj = pose(q, self.j)
        return rj + rot(thj) @ self.sj - ri - rot(thi) @ self.si

    def phi(self, q: np.ndarray, t: float) -> np.ndarray:
        """Position constraint rows."""
        _, thi = pose(q, self.i)
        _, thj = pose(q, self.j)
        return np.array([rot(thi) @ self.hi @ self._d(q), thj - thi - self.theta0])

    def jac(self, q: np.ndarray, out: np.ndarray) -> None:
        """Write the two rows of J into out (2 x n)."""
        _, thi = pose(q, self.i)
        _, thj = pose(q, self.j)
        h = rot(thi) @ self.hi
        d = self._d(q)
        dthi = perp(h) @ d - h @ perp(rot(thi) @ self.si)
        dthj = h @ perp(rot(thj) @ self.sj)
        put_block(out, self.i, np.array([[-h[0], -h[1], dthi], [0.0, 0.0, -1.0]]))
        put_block(out, self.j, np.array([[h[0], h[1], dthj], [0.0, 0.0, 1.0]]))

    def nu(self, t: float) -> np.ndarray:
        """Scleronomic: zero."""
        return np.zeros(2)

    def gamma(self, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray:
        """gamma_1 = h . d thd_i^2 - 2 hdot . ddot - h . (A_i s'_i thd_i^2 - A_j s'_j thd_j^2).

        From d2/dt2 (h . d) = h'' . d + 2 h' . d' + h . d'', keeping the terms free of qdd.
        """
        _, thi = pose(q, self.i)
        _, thj = pose(q, self.j)
        vi, wi = pose(qd, self.i)
        vj, wj = pose(qd, self.j)
        ai, aj = rot(thi), rot(thj)
        h = ai @ self.hi
        d = self._d(q)
        hdot = perp(h) * wi
        ddot = vj + perp(aj @ self.sj) * wj - vi - perp(ai @ self.si) * wi
        quad = ai @ self.si * wi ** 2 - aj @ self.sj * wj ** 2
        return np.array([h @ d * wi ** 2 - 2.0 * hdot @ ddot - h @ quad, 0.0])


@dataclass(frozen=True)
class AbsoluteDriver:
    """Absolute driver: q_col - f(t) = 0 (1 row)."""

    col: int
    f: TimeFunction
    rows: int = 1

    def phi(self, q: np.ndarray, t: float) -> np.ndarray:
        """Position constraint row."""
        return np.array([q[self.col] - self.f(t)[0]])

    def jac(self, q: np.ndarray, out: np.ndarray) -> None:
        """A single 1 in the driven coordinate's column."""
        out[0, self.col] = 1.0

    def nu(self, t: float) -> np.ndarray:
        """f'(t)."""
        return np.array([self.f(t)[1]])

    def gamma(self, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray:
        """f''(t)."""
        return np.array([self.f(t)[2]])


# ----------------------------------------------------------------------------- the model

@dataclass(frozen=True)
class Mechanism:
    """Bodies (file order), rough q0, constraints and the length scale for tolerances."""

    bodies: tuple[str, ...]
    q0: np.ndarray
    constraints: tuple[Constraint, ...]
    scale: float

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return 3 * len(self.bodies)


def _body_index(names: list[str], name: str) -> int:
    """Index of a body by name, ``GROUND`` for "ground"."""
    return GROUND if name == "ground" else names.index(name)


def _joint(entry: dict, names: list[str]) -> Constraint:
    """A constraint object from a TOML [[joint]] table."""
    i, j = (_body_index(names, b) for b in entry["bodies"])
    si, sj = (np.asarray(p, dtype=float) for p in entry["points"])
    if entry["type"] == "revolute":
        return Revolute(i, j, si, sj)
    if entry["type"] == "translational":
        ui, uj = (np.asarray(a, dtype=float) for a in entry["axes"])
        ui = ui / np.linalg.norm(ui)
        theta0 = np.arctan2(ui[1], ui[0]) - np.arctan2(uj[1], uj[0])
        return Translational(i, j, si, sj, perp(ui), float(theta0))
    raise ValueError(f"joint type {entry['type']!r} is not in this baseline")


def _driver(entry: dict, names: list[str]) -> Constraint:
    """A constraint object from a TOML [[driver]] table."""
    if entry["type"] != "absolute":
        raise ValueError(f"driver type {entry['type']!r} is not in this baseline")
    col = 3 * _body_index(names, entry["body"]) + COORD[entry["coordinate"]]
    return AbsoluteDriver(col, time_function(entry["f"]))


def model_path(name: str) -> Path:
    """The TOML file of a model: an example's stem (``slider_crank``) or a path."""
    p = Path(name)
    return p if p.suffix == ".toml" else EX / f"{name}.toml"


@lru_cache(maxsize=None)
def load(name: str) -> Mechanism:
    """Read a model (revolute and translational joints, absolute drivers) from its TOML file.

    The length scale is the largest joint point coordinate, at least 1 (as mbd2d takes it).
    """
    data = tomllib.loads(model_path(name).read_text())
    names = [b["name"] for b in data["body"]]
    joints = [_joint(e, names) for e in data.get("joint", [])]
    drivers = [_driver(e, names) for e in data.get("driver", [])]
    q0 = np.concatenate([np.asarray(b["q0"], dtype=float) for b in data["body"]])
    scale = max([1.0] + [float(np.max(np.abs(e["points"]))) for e in data.get("joint", [])])
    return Mechanism(tuple(names), q0, tuple(joints + drivers), scale)


# ----------------------------------------------------------------------------- Phi, J, nu, gamma

def phi(m: Mechanism, q: np.ndarray, t: float) -> np.ndarray:
    """Phi(q, t), all constraint rows stacked."""
    return np.concatenate([c.phi(q, t) for c in m.constraints])


def jacobian(m: Mechanism, q: np.ndarray) -> np.ndarray:
    """J = Phi_q (rows x n)."""
    jac = np.zeros((sum(c.rows for c in m.constraints), m.n))
    row = 0
    for c in m.constraints:
        c.jac(q, jac[row:row + c.rows])
        row += c.rows
    return jac


def nu(m: Mechanism, t: float) -> np.ndarray:
    """Right-hand side of J qd = nu."""
    return np.concatenate([c.nu(t) for c in m.constraints])


def gamma(m: Mechanism, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray:
    """Right-hand side of J qdd = gamma."""
    return np.concatenate([c.gamma(q, qd, t) for c in m.constraints])


# ----------------------------------------------------------------------------- the analysis

def newton(m: Mechanism, q: np.ndarray, t: float, maxit: int = MAXIT) -> np.ndarray:
    """Solve Phi(q, t) = 0 from the estimate q by Newton-Raphson.

    Raises
    ------
    RuntimeError
        If ||Phi||_inf stays above the tolerance after maxit corrections.
    """
    tol = TOL * m.scale
    q = q.copy()
    for _ in range(maxit + 1):
        res = phi(m, q, t)
        if np.max(np.abs(res)) <= tol:
            return q
        q -= np.linalg.solve(jacobian(m, q), res)
    raise RuntimeError(f"Newton did not converge at t = {t}: ||Phi|| = {np.max(np.abs(res))}")


def velocities(m: Mechanism, q: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """qd and qdd at a solved position: J qd = nu, then J qdd = gamma."""
    jac = jacobian(m, q)
    qd = np.linalg.solve(jac, nu(m, t))
    qdd = np.linalg.solve(jac, gamma(m, q, qd, t))
    return qd, qdd


def solve(m: Mechanism, t_end: float, steps: int
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Kinematic analysis at steps + 1 uniform times from 0 to t_end.

    Parameters
    ----------
    m : Mechanism
        The model.
    t_end : float
        Final time.
    steps : int
        Number of intervals.

    Returns
    -------
    t, q, qd, qdd : numpy.ndarray
        Times (steps + 1,) and the histories (steps + 1, n); rows are times.
    """
    t = np.linspace(0.0, t_end, steps + 1)
    q, qd, qdd = (np.empty((steps + 1, m.n)) for _ in range(3))
    q[0] = newton(m, m.q0, 0.0, maxit=50)                  # assembly
    qd[0], qdd[0] = velocities(m, q[0], 0.0)
    for k in range(1, steps + 1):
        h = t[k] - t[k - 1]
        guess = q[k - 1] + h * qd[k - 1] + 0.5 * h * h * qdd[k - 1]
        q[k] = newton(m, guess, t[k])
        qd[k], qdd[k] = velocities(m, q[k], t[k])
    return t, q, qd, qdd


def analyze(name: str, t_end: float, steps: int
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Kinematics of a model (an example's stem or a TOML path), as ``solve``.

    Returns
    -------
    t, q, qd, qdd : numpy.ndarray
        Columns as mbd2d's ``res.q``: bodies in file order, x, y, theta each.
    """
    return solve(load(name), t_end, steps)


def us_per_step(name: str, steps: int, repeats: int) -> float:
    """Best-of-repeats wall time of ``analyze(name, 1.0, steps)`` per output step, in us."""
    analyze(name, 1.0, 10)          # parse the file once and warm up
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        analyze(name, 1.0, steps)
        best = min(best, time.perf_counter() - t0)
    return 1e6 * best / steps


# ----------------------------------------------------------------------------- against mbd2d

def check(name: str, t_end: float = 1.0, steps: int = 1000) -> dict:
    """Largest differences between this baseline and ``mbd2d`` kinematics.

    Returns
    -------
    dict
        Absolute max differences ``q``, ``qd``, ``qdd``, ``t`` and the same relative to the
        length scale (q) and the largest |qd| and |qdd| of the run (``*_rel``).
    """
    import mbd2d
    res = mbd2d.load(model_path(name)).kinematics(t_end=t_end, steps=steps)
    t, q, qd, qdd = analyze(name, t_end, steps)
    out = {"t": float(np.max(np.abs(t - res.t)))}
    for key, mine, ref, scale in (("q", q, res.q, load(name).scale),
                                  ("qd", qd, res.qd, np.max(np.abs(res.qd))),
                                  ("qdd", qdd, res.qdd, np.max(np.abs(res.qdd)))):
        diff = float(np.max(np.abs(mine - ref)))
        out[key], out[f"{key}_rel"] = diff, float(diff / scale)
    return out


def mbd2d_us_per_step(name: str, t_end: float, steps: int, repeats: int) -> float:
    """Best-of-repeats wall time of one ``model.kinematics`` call per output step, in us."""
    import mbd2d
    model = mbd2d.load(model_path(name))
    model.kinematics(t_end=t_end, steps=10)        # warm up
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        model.kinematics(t_end=t_end, steps=steps)
        best = min(best, time.perf_counter() - t0)
    return 1e6 * best / steps


def main(steps: int = 1000, mbd_steps: int = 100_000) -> dict:
    """Print and return us/step of this baseline and of mbd2d, their ratio and agreement.

    The ratio compares equal step sizes, h = 1 s / steps: the baseline over 1 s (best of 3),
    one ``model.kinematics`` call of mbd_steps steps over mbd_steps * h (best of 5). Both
    then do one Newton correction and two Jacobian factorizations per step. mbd2d is also
    timed at bench/kinematics_speed.py's h = 1e-4 (10 s), where its third-order predictor
    already meets the tolerance and it skips Newton on almost every step.
    """
    rows = {}
    for name in MODELS:
        npy = us_per_step(name, steps, 3)
        ref = mbd2d_us_per_step(name, mbd_steps / steps, mbd_steps, 5)
        ref_fine = mbd2d_us_per_step(name, 10.0, mbd_steps, 5)
        rows[name] = {"numpy_us_per_step": npy, "mbd2d_us_per_step": ref,
                      "ratio": npy / ref, "mbd2d_us_per_step_h1e-4": ref_fine,
                      "agreement": check(name)}
        a = rows[name]["agreement"]
        print(f"{name:16s} numpy {npy:7.1f} us/step   mbd2d {ref:5.2f} us/step   "
              f"ratio {npy / ref:4.0f}   (mbd2d at h = 1e-4: {ref_fine:5.2f} us/step)   "
              f"max rel. diff q {a['q_rel']:.1e} qd {a['qd_rel']:.1e} qdd {a['qdd_rel']:.1e}")
    return rows


if __name__ == "__main__":
    main()
