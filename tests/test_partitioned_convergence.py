"""Coordinate partitioning converges with rtol (issue 9, item 2).

The partitioned method integrates the independent coordinates v and solves the dependent u
from Phi(u, v) = 0; its error estimate sees only v. A v-error reaches u amplified by
J_u^-1 J_v, which grows as J_u approaches singularity. The method re-partitioned only once
1/cond(J_u) < 1e-3, and on a compound double pendulum the error then stopped falling with
rtol (energy 7.5e-5, 2.2e-7, 8.0e-8 J at rtol 1e-8, 1e-10, 1e-12). It now re-partitions
once J_u is 4x worse conditioned than the best choice at the current state.

Oracle: the double pendulum in its two absolute bar angles, Lagrange's equations
  M(th) th'' + c(th, th') = -dV/dth,
  M = [[m1 L1^2/4 + I1 + m2 L1^2, k cos(th1 - th2)], [k cos(th1 - th2), m2 L2^2/4 + I2]],
  c = [k sin(th1 - th2) th2'^2, -k sin(th1 - th2) th1'^2], k = m2 L1 L2 / 2,
  dV/dth = g [(m1 L1/2 + m2 L1) cos th1, m2 L2/2 cos th2],
integrated here with scipy's DOP853 at rtol 1e-13 (its own energy is checked to 1e-10 J).
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d

G = 9.81
L1 = L2 = 1.0
M1 = M2 = 1.0
I1, I2 = M1 * L1 ** 2 / 12, M2 * L2 ** 2 / 12
T_END, STEPS = 10.0, 1000


def double_pendulum(th1: float, th2: float) -> mbd2d.Model:
    """Two uniform bars, the first on a ground pivot, released at rest at angles th1, th2
    (from the +x axis; gravity along -y)."""
    m = mbd2d.Model("double-pendulum")
    e1 = np.array([math.cos(th1), math.sin(th1)])
    e2 = np.array([math.cos(th2), math.sin(th2)])
    c1, c2 = 0.5 * L1 * e1, L1 * e1 + 0.5 * L2 * e2
    m.add_body("bar1", [c1[0], c1[1], th1], mass=M1, inertia=I1)
    m.add_body("bar2", [c2[0], c2[1], th2], mass=M2, inertia=I2)
    m.add_revolute(["ground", "bar1"], [[0.0, 0.0], [-L1 / 2, 0.0]], name="O")
    m.add_revolute(["bar1", "bar2"], [[L1 / 2, 0.0], [-L2 / 2, 0.0]], name="A")
    return m


@functools.lru_cache(maxsize=None)
def reduced(th0: tuple[float, float]) -> np.ndarray:
    """(th1, th2, th1', th2') at the output times from rest at th0."""
    t = np.linspace(0.0, T_END, STEPS + 1)
    k = M2 * L1 * L2 / 2

    def f(_: float, y: np.ndarray) -> list[float]:
        a, b, wa, wb = y
        s, c = math.sin(a - b), math.cos(a - b)
        mass = np.array([[M1 * L1 ** 2 / 4 + I1 + M2 * L1 ** 2, k * c],
                         [k * c, M2 * L2 ** 2 / 4 + I2]])
        rhs = -np.array([k * s * wb ** 2 + G * math.cos(a) * (M1 * L1 / 2 + M2 * L1),
                         -k * s * wa ** 2 + G * M2 * L2 / 2 * math.cos(b)])
        acc = np.linalg.solve(mass, rhs)
        return [wa, wb, acc[0], acc[1]]

    sol = solve_ivp(f, (0.0, float(t[-1])), [th0[0], th0[1], 0.0, 0.0], method="DOP853",
                    rtol=1e-13, atol=1e-13, t_eval=t)
    return sol.y


def reduced_energy(y: np.ndarray) -> np.ndarray:
    a, b, wa, wb = y
    k = M2 * L1 * L2 / 2
    kin = 0.5 * ((M1 * L1 ** 2 / 4 + I1 + M2 * L1 ** 2) * wa ** 2
                 + 2 * k * np.cos(a - b) * wa * wb + (M2 * L2 ** 2 / 4 + I2) * wb ** 2)
    pot = G * ((M1 * L1 / 2 + M2 * L1) * np.sin(a) + M2 * L2 / 2 * np.sin(b))
    return kin + pot


def errors(th0: tuple[float, float], method: str, rtol: float) -> tuple[float, float, int]:
    """Largest angle error against the reduced solution, largest energy error, partitions."""
    res = double_pendulum(*th0).dynamics(T_END, STEPS, method=method, rtol=rtol,
                                         atol=rtol * 1e-2)
    y = reduced(th0)
    assert res.t.shape == (STEPS + 1,)
    assert np.abs(reduced_energy(y) - reduced_energy(y)[0]).max() < 1e-10   # the oracle
    th = np.unwrap(np.column_stack([res.body("bar1").theta, res.body("bar2").theta]), axis=0)
    e = res.energy
    return (float(np.abs(th - y[:2].T).max()), float(np.abs(e - e[0]).max()),
            res.stats["partitions"])


RTOLS = (1e-8, 1e-10, 1e-12)


def test_partitioned_converges_with_rtol_like_dopri5() -> None:
    """Released at (-0.5, 0.3) rad: the angle and energy errors fall about 100x per 100x of
    rtol, as dopri5's do. Measured, partitioned: angles 4.3e-7, 1.7e-9, 7.8e-12 rad, energy
    1.6e-6, 2.1e-8, 1.8e-10 J (before: 7.8e-6, 8.5e-8, 4.4e-8 rad and 1.0e-5, 1.1e-7,
    2.2e-7 J); dopri5: 1.0e-7, 1.3e-9, 1.5e-11 rad, 5.4e-7, 5.2e-9, 7.9e-11 J."""
    th0 = (-0.5, 0.3)
    part = [errors(th0, "partitioned", r) for r in RTOLS]
    dop = [errors(th0, "dopri5", r) for r in RTOLS]
    assert max(p[2] for p in part) >= 2                      # the partition was changed
    for (ang_c, e_c, _), (ang_f, e_f, _) in zip(part, part[1:]):
        assert ang_f < ang_c / 30 and e_f < e_c / 30, part
    for (ang_p, e_p, _), (ang_d, e_d, _) in zip(part, dop):
        assert ang_p < 10 * ang_d and e_p < 10 * e_d, (part, dop)


def test_partitioned_at_tight_tolerance_on_the_chaotic_release() -> None:
    """Released horizontal, the motion is chaotic over 10 s (dopri5: angle error 4.8e-4 rad at
    rtol 1e-8, 3.6e-8 at 1e-12). partitioned at rtol 1e-12: measured 3.7e-8 to 6.7e-8 rad
    and 4.7e-10 to 9.5e-10 J (before 1.3e-4 rad and 8.0e-8 J, no better than at rtol 1e-10).
    The motion is chaotic: the figures move with the rounding of anything upstream."""
    coarse = errors((0.0, 0.0), "partitioned", 1e-8)
    fine = errors((0.0, 0.0), "partitioned", 1e-12)
    assert fine[0] < 1e-6 and fine[1] < 5e-9, fine
    assert fine[0] < coarse[0] / 1000 and fine[1] < coarse[1] / 300, (coarse, fine)


@pytest.mark.parametrize("rtol", [1e-8, 1e-10])
def test_repartitioning_leaves_a_model_without_a_better_choice_alone(rtol: float) -> None:
    """The free four-bar keeps one partition: no choice becomes 4x better conditioned."""
    import sys

    from conftest import EXAMPLES
    sys.path.insert(0, str(EXAMPLES))
    import free_fourbar
    res = free_fourbar.build().dynamics(2.0, 20, method="partitioned", rtol=rtol,
                                        atol=rtol * 1e-2)
    assert res.stats["partitions"] == 1
