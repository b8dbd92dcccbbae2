"""KinematicStepper: one core call per step, against the slider-crank's closed form."""
from __future__ import annotations

import math

import numpy as np
import pytest

import mbd2d
from conftest import load_example
from test_closed_forms import slider_crank_closed_form


def test_stepper_follows_the_slider_crank_closed_form():
    model = load_example("slider_crank.toml")
    s = mbd2d.KinematicStepper(model)
    ts = np.linspace(0.0, 1.0, 201)
    xs, x1s, x2s = [], [], []
    i = 3 * [b.name for b in model.bodies].index("slider")
    for t in ts[1:]:
        q, qd, qdd = s.step(t)
        xs.append(q[i]); x1s.append(qd[i]); x2s.append(qdd[i])
    cf = slider_crank_closed_form(ts[1:])
    assert np.abs(np.array(xs) - cf["x"]).max() < 1e-11
    assert np.abs(np.array(x1s) - cf["x1"]).max() < 1e-10
    assert np.abs(np.array(x2s) - cf["x2"]).max() < 1e-8
    assert s.t == 1.0


def test_stepper_agrees_with_the_core_loop():
    model = load_example("fourbar_grashof.toml")
    res = model.kinematics(t_end=0.5, steps=50, maxit=25)
    s = mbd2d.KinematicStepper(model)
    assert np.abs(s.q - res.q[0]).max() < 1e-12
    for k in range(1, 51):
        q, qd, qdd = s.step(res.t[k])
    assert np.abs(q - res.q[-1]).max() < 1e-11
    assert np.abs(qd - res.qd[-1]).max() < 1e-10
    assert np.abs(qdd - res.qdd[-1]).max() < 1e-9


def test_stepper_stops_at_the_toggle_with_a_convergence_error():
    s = mbd2d.KinematicStepper(load_example("fourbar_seed.toml"))
    with pytest.raises(mbd2d.ConvergenceError, match="state stays at t"):
        for k in range(1, 301):
            s.step(0.01 * k)
    toggle = math.acos((9 + 36 - 7.6**2) / 36) - math.pi / 3      # closed form
    assert 0.85 < s.t < toggle          # the last good state is before the toggle


def test_stepper_needs_a_square_jacobian():
    with pytest.raises(mbd2d.ModelError, match="as many equations as coordinates"):
        mbd2d.KinematicStepper(load_example("fourbar_redundant.toml"))
