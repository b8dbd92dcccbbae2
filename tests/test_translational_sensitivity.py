"""The translational joint's second derivatives and parameter parts in closed form
(translational_second, translational_param) against finite differences: every point and axis
parameter of a translational joint between two moving bodies (the block of an inverted
slider-crank sliding in a swinging slotted lever) and of one whose first body is the ground
(the offset slider-crank's guide) gives dq/dp, dq_dot/dp and dq_ddot/dp equal to central
differences of the kinematic run itself at p +- h (positions, velocities and accelerations
solved to machine accuracy), with Richardson extrapolation of two step sizes."""
from __future__ import annotations

import numpy as np
import pytest

import mbd2d
from conftest import load_example

STEPS, T_END = 24, 1.0

INVERTED = """
[model]
name = "inverted slider-crank"

[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]

[[body]]
name = "lever"
q0 = [0.0, -2.0, 1.107]

[[body]]
name = "block"
q0 = [1.0, 0.0, 1.107]

[[joint]]
name = "O2"
type = "revolute"
bodies = ["ground", "crank"]
points = [[0.0, 0.0], [-0.5, 0.0]]

[[joint]]
name = "O4"
type = "revolute"
bodies = ["ground", "lever"]
points = [[0.0, -2.0], [0.0, 0.0]]

[[joint]]
name = "A"
type = "revolute"
bodies = ["crank", "block"]
points = [[0.5, 0.0], [0.0, 0.0]]

[[joint]]
name = "slot"
type = "translational"
bodies = ["lever", "block"]
points = [[0.1, 0.05], [0.2, -0.1]]
axes = [[1.0, 0.0], [1.0, 0.1]]

[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0.0, 6.283185307179586] }
"""


def central(model, name: str, value: float, h: float) -> np.ndarray:
    """(3, rows, nq) central differences of q, q_dot, q_ddot along the parameter."""
    runs = []
    for v in (value + h, value - h):
        res = model.with_params({name: v}).kinematics(T_END, STEPS)
        runs.append(np.stack([res.q, res.qd, res.qdd]))
    return (runs[0] - runs[1]) / (2 * h)


def check(model, joint: str) -> None:
    pars = model.parameters()
    names = [f"joint.{joint}.{what}.{side}.{c}" for what in ("points", "axes")
             for side in (0, 1) for c in (0, 1)]
    res = model.kinematics(T_END, STEPS, sensitivities=names)
    assert np.abs(res.dq_dp).max() > 0.1                    # the parameters do move things
    for j, name in enumerate(names):
        h = 1e-3 * max(1.0, abs(pars[name]))
        d1, d2 = central(model, name, pars[name], h), central(model, name, pars[name], h / 2)
        want = (4 * d2 - d1) / 3                            # Richardson: O(h**4)
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            scale = max(1.0, float(np.abs(want[k]).max()))
            err = float(np.abs(got[:, :, j] - want[k]).max())
            assert err <= 1e-7 * scale, f"d{['q', 'qd', 'qdd'][k]}/d {name}: {err:.2e}"


def test_translational_between_two_moving_bodies_against_central_differences():
    check(mbd2d.loads(INVERTED), "slot")


@pytest.mark.parametrize("joint", ["guide"])
def test_translational_on_the_ground_against_central_differences(joint):
    check(load_example("slider_crank.toml"), joint)
