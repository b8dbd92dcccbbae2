"""The revolute's second derivatives and parameter parts in closed form
(revolute_second_sides, revolute_param_sides) against finite differences: every point
parameter of every revolute of the four-bar, ground as the first body (O2) and as the second
(O4), body to body (A, B), gives dq/dp, dq_dot/dp and dq_ddot/dp equal to central
differences of the kinematic run itself at p +- h (positions, velocities and accelerations
solved to machine accuracy, so the differences carry the derivative to about 1e-9), with
Richardson extrapolation of two step sizes (conftest.check_kinematic_sensitivities)."""
from __future__ import annotations

import pytest

from conftest import check_kinematic_sensitivities, load_example


@pytest.mark.parametrize("joint", ["O2", "A", "B", "O4"])
def test_every_revolute_point_parameter_against_central_differences(joint):
    names = [f"joint.{joint}.points.{side}.{c}" for side in (0, 1) for c in (0, 1)]
    check_kinematic_sensitivities(load_example("fourbar_grashof.toml"), names)
