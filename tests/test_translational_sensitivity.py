"""The translational joint's second derivatives and parameter parts in closed form
(translational_second, translational_param) against finite differences: every point and axis
parameter of a translational joint between two moving bodies (the block of an inverted
slider-crank sliding in a swinging slotted lever) and of one whose first body is the ground
(the offset slider-crank's guide) gives dq/dp, dq_dot/dp and dq_ddot/dp equal to central
differences of the kinematic run itself at p +- h (positions, velocities and accelerations
solved to machine accuracy), with Richardson extrapolation of two step sizes."""
from __future__ import annotations

import numpy as np

from conftest import check_kinematic_sensitivities, load_example, model_from_toml

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


def names_of(joint: str) -> list[str]:
    """Every point and axis parameter of a translational joint."""
    return [f"joint.{joint}.{what}.{side}.{c}" for what in ("points", "axes")
            for side in (0, 1) for c in (0, 1)]


def test_translational_between_two_moving_bodies_against_central_differences():
    model = model_from_toml(INVERTED)
    assert np.abs(model.kinematics(1.0, 24, sensitivities=names_of("slot")).dq_dp).max() > 0.1
    check_kinematic_sensitivities(model, names_of("slot"))


def test_translational_on_the_ground_against_central_differences():
    check_kinematic_sensitivities(load_example("slider_crank.toml"), names_of("guide"))
