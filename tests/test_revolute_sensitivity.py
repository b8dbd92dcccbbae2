"""The revolute's second derivatives and parameter parts in closed form (revolute_second,
revolute_param) against finite differences: every point parameter of every revolute of the
four-bar, ground as the first body (O2) and as the second (O4), body to body (A, B), gives
dq/dp, dq_dot/dp and dq_ddot/dp equal to central differences of the kinematic run itself at
p +- h (positions, velocities and accelerations solved to machine accuracy, so the differences
carry the derivative to about 1e-9), with Richardson extrapolation of two step sizes."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import load_example

STEPS, T_END = 24, 1.0


def central(model, name: str, value: float, h: float) -> np.ndarray:
    """(3, rows, nq) central differences of q, q_dot, q_ddot along the parameter."""
    runs = []
    for v in (value + h, value - h):
        res = model.with_params({name: v}).kinematics(T_END, STEPS)
        runs.append(np.stack([res.q, res.qd, res.qdd]))
    return (runs[0] - runs[1]) / (2 * h)


@pytest.mark.parametrize("joint", ["O2", "A", "B", "O4"])
def test_every_revolute_point_parameter_against_central_differences(joint):
    model = load_example("fourbar_grashof.toml")
    pars = model.parameters()
    names = [f"joint.{joint}.points.{side}.{c}" for side in (0, 1) for c in (0, 1)]
    res = model.kinematics(T_END, STEPS, sensitivities=names)
    for j, name in enumerate(names):
        h = 1e-3 * max(1.0, abs(pars[name]))
        d1, d2 = central(model, name, pars[name], h), central(model, name, pars[name], h / 2)
        want = (4 * d2 - d1) / 3                            # Richardson: O(h**4)
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            scale = max(1.0, float(np.abs(want[k]).max()))
            err = float(np.abs(got[:, :, j] - want[k]).max())
            assert err <= 1e-7 * scale, f"d{['q', 'qd', 'qdd'][k]}/d {name}: {err:.2e}"
