"""IFToMM multibody benchmarks A01 (simple pendulum) and A02 (N-four-bar), against
independent one-degree-of-freedom solutions integrated here with a small RK4."""
from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES

sys.path.insert(0, str(EXAMPLES))
import nfourbar  # noqa: E402

G = 9.81


def rk4(f, y0: list[float], t_end: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Classical RK4 on floats (the oracle): times and states."""
    n = int(round(t_end / h))
    ys = np.empty((n + 1, len(y0)))
    y = list(y0)
    ys[0] = y
    for i in range(n):
        k1 = f(y)
        k2 = f([a + 0.5 * h * b for a, b in zip(y, k1)])
        k3 = f([a + 0.5 * h * b for a, b in zip(y, k2)])
        k4 = f([a + h * b for a, b in zip(y, k3)])
        y = [a + h / 6 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(y, k1, k2, k3, k4)]
        ys[i + 1] = y
    return np.linspace(0.0, n * h, n + 1), ys


# ------------------------------------------------------------------ A01 simple pendulum
A01 = '''
[model]
name = "A01"
gravity = [0.0, -9.81]
[[body]]
name = "mass"
q0 = [1.0, 0.0, 0.0]
mass = 1.0
inertia = 0.0
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "mass"]
points = [[0.0, 0.0], [-1.0, 0.0]]
'''


@pytest.fixture(scope="module")
def a01_reference() -> tuple[np.ndarray, np.ndarray]:
    """Point mass on a massless 1 m rod, released horizontal: th'' = -g cos(th)."""
    t, y = rk4(lambda s: [s[1], -G * math.cos(s[0])], [0.0, 0.0], 10.0, 2e-4)
    return t, y[:, 0]


@pytest.mark.parametrize("method, settings, bound", [
    ("dopri5", dict(rtol=1e-10, atol=1e-12), 1e-7),
    ("partitioned", dict(rtol=1e-10, atol=1e-12), 1e-7),
    ("baumgarte-rk4", dict(h=1e-3), 1e-7),
    ("generalized-alpha", dict(h=2e-4), 1e-3),
])
def test_a01_simple_pendulum(a01_reference, method: str, settings: dict, bound: float) -> None:
    res = mbd2d.loads(A01).dynamics(t_end=10.0, steps=500, method=method, **settings)
    t_ref, th_ref = a01_reference
    th = np.interp(res.t, t_ref, th_ref)
    b = res.body("mass")
    err = np.max(np.hypot(b.x - np.cos(th), b.y - np.sin(th)))
    assert err < bound, f"{method}: position error {err:.2e}"
    # no damping, no forcing: energy to within the method's accuracy
    assert np.max(np.abs(res.energy - res.energy[0])) < 10 * bound * G


# ------------------------------------------------------------------ A02 N-four-bar
def free_chain(n: int) -> mbd2d.Model:
    """The N-four-bar with uniform bars (1 kg, 1 m, J = 1/12), cranks upright and turning at
    -1 rad/s, under gravity: it passes the horizontal singular position twice a turn."""
    return nfourbar.build(n, driven=False, omega0=-1.0)


def reduced(n: int, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """One degree of freedom: every crank at th, couplers translating.
    T = (N+1) m L^2 th'^2 / 6 + N m L^2 th'^2 / 2, V = ((N+1)/2 + N) m g L sin(th)."""
    inertia = (n + 1) / 3 + n
    moment = ((n + 1) * 0.5 + n) * G
    t, y = rk4(lambda s: [s[1], -moment * math.cos(s[0]) / inertia], [math.pi / 2, -1.0],
               t_end, 1e-4)
    return t, y[:, 0]


@pytest.mark.parametrize("n", [1, 2, 5])
@pytest.mark.parametrize("method, settings, bound", [
    ("dopri5", dict(rtol=1e-8, atol=1e-10), 1e-5),
    ("partitioned", dict(rtol=1e-8, atol=1e-10), 1e-4),
])
def test_a02_n_four_bar_stays_on_the_parallelogram_branch(n: int, method: str, settings: dict,
                                                         bound: float) -> None:
    t_end = 10.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.RedundantConstraintWarning)
        res = free_chain(n).dynamics(t_end=t_end, steps=500, method=method, **settings)
    t_ref, th_ref = reduced(n, t_end)
    th0 = res.body("crank0").theta
    crossings = np.sum(np.diff(np.sign(np.cos(th0))) != 0)
    assert crossings >= 4                                 # the horizontal was passed
    for k in range(n + 1):                                # every crank parallel to the first
        assert_allclose(res.body(f"crank{k}").theta, th0, atol=1e-8)
    for k in range(n):
        assert_allclose(res.body(f"coupler{k}").theta, 0.0, atol=1e-8)
    err = np.max(np.abs(th0 - np.interp(res.t, t_ref, th_ref)))
    assert err < bound, f"{method}, N = {n}: error {err:.2e} against the reduced solution"


@pytest.mark.parametrize("method, settings, bound", [
    ("generalized-alpha", dict(h=1e-3), 1e-3),
    ("baumgarte-rk4", dict(h=1e-3), 1e-6),
])
def test_a02_fixed_step_methods(method: str, settings: dict, bound: float) -> None:
    res = free_chain(1).dynamics(t_end=10.0, steps=500, method=method, **settings)
    t_ref, th_ref = reduced(1, 10.0)
    th0 = res.body("crank0").theta
    assert_allclose(res.body("crank1").theta, th0, atol=1e-8)
    assert np.max(np.abs(th0 - np.interp(res.t, t_ref, th_ref))) < bound
