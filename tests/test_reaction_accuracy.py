"""Reactions from forward dynamics against closed forms (issue 9, items 3 and 6).

Every output's multipliers are those of the index-1 equations at the output state.

* Item 3: the index-3 generalized-alpha lambda_{n+1} is a second difference of positions and
  carries the rounding of q amplified by 1 / (beta' h^2): the contact force of a rolling disc
  was off by 2e-10, 2e-8, 4e-6, 3e-4 N at h = 1e-2 ... 1e-5. Oracles: a uniform disc rolling
  without slip down an incline of angle alpha has the normal force m g cos(alpha) and the
  friction force m g sin(alpha) / 3, whatever the step; a bar pendulum's pivot force from the
  reduced equation th'' = -(3 g / 2 L) cos(th) integrated here with scipy's DOP853 at
  rtol 1e-13 must converge at the method's order 2 as h falls to 1e-5.
* Item 6: outputs between dopri5 (and partitioned) steps took lambda from an interpolant of
  the accelerations, 100x less accurate than the state. Oracle: the pivot force at the exact
  state (the same reduced solution), which the reported force must match to within what
  the error of the reported state explains, |dF| <= 30 |d th| + 6 |d th'| (the pivot force's
  sensitivity to the state for this bar; see pivot_force).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d

G = 9.81


# ------------------------------------------------------------------ rolling disc (item 3)
ALPHA, MASS, RADIUS = 0.3, 2.0, 0.5


def rolling_disc() -> mbd2d.Model:
    """A uniform disc (I = m R^2 / 2) on the line through the origin sloping down at ALPHA,
    released at rest touching it."""
    m = mbd2d.Model("disc-on-incline")
    ca, sa = math.cos(ALPHA), math.sin(ALPHA)
    m.add_body("disc", [RADIUS * sa, RADIUS * ca, 0.0], mass=MASS,
               inertia=0.5 * MASS * RADIUS ** 2)
    m.add_rolling_disc(["disc", "ground"], [0.0, 0.0], [0.0, 0.0], [ca, -sa], RADIUS,
                       name="roll")
    return m


def contact_force_errors(res: mbd2d.DynamicsResult) -> tuple[float, float]:
    """Largest errors of the normal and the friction force on the disc against
    N = m g cos(alpha), F = m g sin(alpha) / 3 (friction up the slope)."""
    r = res.reaction("roll")
    ca, sa = math.cos(ALPHA), math.sin(ALPHA)
    down, normal = np.array([ca, -sa]), np.array([sa, ca])
    f = np.column_stack([r.fx, r.fy])
    err_n = np.abs(f @ normal - MASS * G * ca).max()
    err_f = np.abs(-(f @ down) - MASS * G * sa / 3).max()
    return float(err_n), float(err_f)


@pytest.mark.parametrize("h", [1e-2, 1e-3, 1e-4, 1e-5])
def test_generalized_alpha_contact_force_does_not_degrade_as_h_falls(h: float) -> None:
    res = rolling_disc().dynamics(0.1, 10, method="generalized-alpha", h=h)
    assert res.stats["steps"] == round(0.1 / h)
    err_n, err_f = contact_force_errors(res)
    # measured 0 and 2e-15 N at every h (before: normal 1.6e-10, 2.2e-8, 4.1e-6, 3.4e-4 N)
    assert err_n < 1e-12 and err_f < 1e-12, (err_n, err_f)
    # and the motion is the closed form: centre acceleration 2/3 g sin(alpha) down the slope
    d = res.body("disc")
    s = np.hypot(d.x - d.x[0], d.y - d.y[0])
    np.testing.assert_allclose(s, G * math.sin(ALPHA) / 3 * res.t ** 2, rtol=0, atol=1e-12)


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_error_controlled_generalized_alpha_contact_force(rtol: float) -> None:
    res = rolling_disc().dynamics(0.1, 10, method="generalized-alpha", rtol=rtol,
                                  atol=rtol * 1e-2)
    err_n, err_f = contact_force_errors(res)
    # measured 0 and 2e-15 N (before: normal 4.8e-8, 1.7e-6, 1.9e-4 N)
    assert err_n < 1e-12 and err_f < 1e-12, (err_n, err_f)


# ------------------------------------------------------------------ bar pendulum
BAR_L, BAR_M = 1.0, 1.0


def bar_pendulum() -> mbd2d.Model:
    """A uniform bar (1 m, 1 kg) on a pivot at one end, released horizontal."""
    m = mbd2d.Model("bar-pendulum")
    m.add_body("bar", [BAR_L / 2, 0.0, 0.0], mass=BAR_M, inertia=BAR_M * BAR_L ** 2 / 12)
    m.add_revolute(["ground", "bar"], [[0.0, 0.0], [-BAR_L / 2, 0.0]], name="pivot")
    return m


def reduced_bar(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """th'' = -c cos(th), c = m g (L/2) / (m L^2 / 3), from rest at th = 0: th and th'."""
    c = 1.5 * G / BAR_L
    sol = solve_ivp(lambda _, y: [y[1], -c * math.cos(y[0])], (0.0, float(t[-1])), [0.0, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    return sol.y[0], sol.y[1]


def pivot_force(th: np.ndarray, om: np.ndarray) -> np.ndarray:
    """Force of the pivot on the bar, m a_c - m g, with the centre acceleration
    a_c = (L/2) (th'' t_hat - th'^2 r_hat), th'' = -c cos(th). Its sensitivity to the state:
    |dF| <= m (L/2) ((2 c + th'^2) |d th| + 2 |th'| |d th'|) <= 30 |d th| + 6 |d th'| here
    (c = 14.7 s^-2, th'^2 <= 2 c, |th'| <= 5.5 rad/s)."""
    al = -1.5 * G / BAR_L * np.cos(th)
    r = np.column_stack([np.cos(th), np.sin(th)])
    tt = np.column_stack([-np.sin(th), np.cos(th)])
    acc = 0.5 * BAR_L * (al[:, None] * tt - (om ** 2)[:, None] * r)
    return BAR_M * acc + BAR_M * np.array([0.0, G])


def bar_errors(res: mbd2d.DynamicsResult) -> tuple[float, float, float]:
    """Largest errors of the pivot force, th and th' against the reduced solution."""
    th, om = reduced_bar(res.t)
    r = res.reaction("pivot")
    f = np.column_stack([r.fx_j, r.fy_j])
    err_f = np.hypot(*(f - pivot_force(th, om)).T).max()
    return (float(err_f), float(np.abs(res.body("bar").theta - th).max()),
            float(np.abs(res.qd[:, 2] - om).max()))


def test_generalized_alpha_pivot_force_converges_at_order_two_to_small_steps() -> None:
    """The pivot force of the fixed-step run falls 100x per decade of h down to h = 1e-5
    (measured 2.8e-2, 2.8e-4, 2.8e-6, 2.8e-8 N; before: 2.5e-2, 2.5e-4, 3.2e-6, 1.6e-4 N)."""
    errs = [bar_errors(bar_pendulum().dynamics(1.0, 100, method="generalized-alpha", h=h))[0]
            for h in (1e-2, 1e-3, 1e-4, 1e-5)]
    for coarse, fine in zip(errs, errs[1:]):
        assert 1.8 < math.log10(coarse / fine) < 2.2, errs


@pytest.mark.parametrize("method", ["dopri5", "partitioned"])
def test_reactions_between_steps_are_as_accurate_as_the_state(method: str) -> None:
    """2000 outputs in 2 s, most of them between steps: the pivot force is within what the
    state's own error explains, and falls with rtol like the state (dopri5 measured
    1.6e-7, 1.8e-9, 1.7e-11 N at rtol 1e-8, 1e-10, 1e-12; before 1.4e-5, 3.2e-7, 7.8e-9 N)."""
    errs = []
    for rtol in (1e-8, 1e-10, 1e-12):
        res = bar_pendulum().dynamics(2.0, 2000, method=method, rtol=rtol, atol=rtol * 1e-2)
        assert res.stats["steps"] < 1000               # most outputs fall between steps
        err_f, err_th, err_om = bar_errors(res)
        assert err_f <= 30 * err_th + 6 * err_om, (rtol, err_f, err_th, err_om)
        errs.append(err_f)
    assert errs[1] < errs[0] / 30 and errs[2] < errs[1] / 30, errs
