"""The seed four-bar reaches a toggle (dead centre): the run must stop there, say where,
and keep the results up to it.

Crank 3 about O2 = (0, 0), coupler 5, rocker 2.6 about O4 = (6, 0), crank angle
theta2 = t + pi/3. The toggle is where coupler and rocker become collinear (stretched
out): |A - O4| = 5 + 2.6, i.e. by the law of cosines in triangle O2 A O4
    cos theta2* = (3^2 + 6^2 - 7.6^2) / (2 * 3 * 6),   t* = theta2* - pi/3.
"""
from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import global_point, load_example, wrap_angle

L2, L3, L4, L1 = 3.0, 5.0, 2.6, 6.0
O4 = np.array([L1, 0.0])
T_STAR = float(np.arccos((L2**2 + L1**2 - (L3 + L4) ** 2) / (2 * L2 * L1)) - np.pi / 3)


def closed_form_config(t: float) -> np.ndarray:
    """q = (crank, coupler, rocker) x (x, y, theta) on the branch the example starts on
    (B to the left of the line A -> O4). At and beyond t* the arccos argument is clipped,
    which gives the toggle configuration itself."""
    th2 = t + np.pi / 3
    A = L2 * np.array([np.cos(th2), np.sin(th2)])
    D = O4 - A
    f = np.hypot(*D)
    cb = np.clip((L3**2 + f**2 - L4**2) / (2 * L3 * f), -1.0, 1.0)
    th3 = np.arctan2(D[1], D[0]) + np.arccos(cb)
    B = A + L3 * np.array([np.cos(th3), np.sin(th3)])
    th4 = np.arctan2(*(O4 - B)[::-1])
    crank = A / 2
    coupler = A + L3 / 2 * np.array([np.cos(th3), np.sin(th3)])
    rocker = O4 - L4 / 2 * np.array([np.cos(th4), np.sin(th4)])
    return np.array([*crank, th2, *coupler, th3, *rocker, th4])


def loop_residuals(t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Residuals of the four pins and the driver, from the body coordinates (independent of
    the engine's Phi): shape (n, 9)."""
    q = np.atleast_2d(q)
    crank, coupler, rocker = (q[:, 0:3].T, q[:, 3:6].T, q[:, 6:9].T)
    O2 = global_point(*crank, (-1.5, 0.0))
    A = global_point(*crank, (1.5, 0.0)) - global_point(*coupler, (-2.5, 0.0))
    B = global_point(*coupler, (2.5, 0.0)) - global_point(*rocker, (-1.3, 0.0))
    O4r = global_point(*rocker, (1.3, 0.0)) - O4
    drive = wrap_angle(q[:, 2] - (np.atleast_1d(t) + np.pi / 3))
    return np.column_stack([O2, A, B, O4r, drive])


@pytest.fixture(scope="module")
def toggle_error():
    m = load_example("fourbar_seed.toml")
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        m.kinematics(t_end=1.0, steps=1000)
    return info.value


def test_closed_form_toggle_time():
    assert T_STAR == pytest.approx(0.8859186478, abs=1e-10)
    # the clipped closed form really is collinear at t*
    q = closed_form_config(T_STAR)
    assert abs(wrap_angle(q[5] - q[8])) < 1e-6


def test_toggle_is_reported(toggle_error):
    err = toggle_error
    assert isinstance(err, mbd2d.AnalysisError)
    assert isinstance(err, mbd2d.ToggleError)
    assert abs(err.t - T_STAR) <= 1e-8, (err.t, T_STAR)
    assert err.driver == "motor"
    assert isinstance(err.dependent, list) and len(err.dependent) > 0
    assert set(err.dependent) <= {"O2", "A", "B", "O4", "motor"}
    assert "motor" in str(err) and "Singular configuration" in str(err)
    assert 0.0 < err.sigma_min < 1e-3 * err.sigma_max


def test_partial_results_stop_at_the_toggle(toggle_error):
    res = toggle_error.results
    assert isinstance(res, mbd2d.KinematicsResult)
    assert not res.complete
    n_expected = int(np.floor(T_STAR * 1000)) + 1
    assert n_expected == 886
    assert len(res.t) == n_expected
    assert res.q.shape == res.qd.shape == res.qdd.shape == (n_expected, 9)
    assert np.all(res.t <= T_STAR)
    assert_allclose(res.t, np.arange(n_expected) / 1000.0, rtol=0, atol=1e-15)
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.qd)) \
        and np.all(np.isfinite(res.qdd))


def test_partial_results_satisfy_loop_closure(toggle_error):
    res = toggle_error.results
    r = loop_residuals(res.t, res.q)
    assert np.max(np.abs(r)) <= 1e-9
    # and they are the closed-form configuration of the starting branch (away from the
    # last rows, where the sqrt-type sensitivity at the toggle amplifies the tolerance)
    cf = np.array([closed_form_config(t) for t in res.t])
    d = res.q - cf
    d[:, 2::3] = wrap_angle(d[:, 2::3])
    assert np.max(np.abs(d[res.t <= 0.85])) <= 1e-9


def test_singular_configuration_is_the_toggle(toggle_error):
    err = toggle_error
    q = np.asarray(err.q)
    assert q.shape == (9,)
    # it satisfies the constraints at err.t
    assert np.max(np.abs(loop_residuals(err.t, q))) <= 1e-9
    # Near a toggle the configuration depends on t like sqrt(t* - t): the angle psi
    # between coupler and rocker obeys 13 psi^2 ~ 36 sin(theta2*) (t* - t), so
    # psi ~ 1.6 sqrt(t* - t). With |t - t*| <= 1e-8 that allows psi up to ~1.6e-4;
    # 5e-4 is the honest bound (1e-12 Newton residuals add only ~1e-6 at
    # sigma_min/sigma_max ~ 1e-6).
    psi = wrap_angle(q[5] - q[8])
    assert abs(psi) <= 5e-4
    d = q - closed_form_config(T_STAR)
    d[2::3] = wrap_angle(d[2::3])
    assert np.max(np.abs(d)) <= 5e-4 * 5.0  # angle error times the longest lever (5)
    # and tightly: it is the closed-form configuration of its own time err.t
    d = q - closed_form_config(err.t)
    d[2::3] = wrap_angle(d[2::3])
    assert np.max(np.abs(d)) <= 1e-5


def test_run_ending_before_the_toggle_completes():
    m = load_example("fourbar_seed.toml")
    res = m.kinematics(t_end=0.85, steps=170)
    assert res.complete
    assert len(res.t) == 171
    assert res.t[-1] == 0.85
    assert np.max(np.abs(loop_residuals(res.t, res.q))) <= 1e-9


def test_coarse_step_past_the_toggle_still_locates_it():
    m = load_example("fourbar_seed.toml")
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        m.kinematics(t_end=1.0, steps=1)
    err = info.value
    assert abs(err.t - T_STAR) <= 1e-8, (err.t, T_STAR)
    assert err.driver == "motor"
    assert len(err.dependent) > 0
    assert len(err.results.t) == 1 and err.results.t[0] == 0.0
    assert np.max(np.abs(loop_residuals(err.t, err.q))) <= 1e-9


@pytest.mark.parametrize("steps", [7, 50, 333])
def test_toggle_time_does_not_depend_on_the_step(steps):
    m = load_example("fourbar_seed.toml")
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        m.kinematics(t_end=1.0, steps=steps)
    err = info.value
    assert abs(err.t - T_STAR) <= 1e-8
    assert len(err.results.t) == int(np.floor(T_STAR * steps)) + 1
