"""Phi, J, nu, gamma and the row labels, as exposed for teaching and custom integrators."""
from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES


def test_rows_are_labelled_by_constraint_and_equation() -> None:
    m = mbd2d.load(EXAMPLES / "slider_crank.toml")
    assert m.constraint_rows() == ["O.x", "O.y", "A.x", "A.y", "B.x", "B.y", "guide.normal",
                                   "guide.angle", "motor.theta"]
    assert m.coordinate_names[:3] == ["crank.x", "crank.y", "crank.theta"]


def test_pieces_at_a_solved_state_satisfy_the_kinematic_equations() -> None:
    """At states the engine solved: Phi = 0, J q_dot = nu and J q_ddot = gamma."""
    m = mbd2d.load(EXAMPLES / "cam_follower.toml")
    res = m.kinematics(t_end=0.5, steps=5)
    scale = 1.25   # the documented tolerance: ||Phi|| <= 1e-12 x the model's length scale
    for k, t in enumerate(res.t):
        q, qd, qdd = res.q[k], res.qd[k], res.qdd[k]
        assert_allclose(m.phi(q, t), 0.0, atol=1e-12 * scale)
        j = m.jacobian(q, t)
        assert_allclose(j @ qd, m.nu(q, t), atol=1e-12)
        assert_allclose(j @ qdd, m.gamma(q, qd, t), atol=1e-10)


def test_seed_four_bar_by_hand() -> None:
    """The seed lesson's R1 at theta1 = 0: Phi = r1 + A(0)(-1.5, 0) with J block
    [1 0 -sin*xi - cos*eta; 0 1 cos*xi - sin*eta] = [1 0 0; 0 1 -1.5] and
    gamma = A s' thd^2. The example lists the joint as [ground, crank], i.e. Phi_O2 =
    (0, 0) - (r1 + A s'), so its rows are the seed's with the opposite sign."""
    m = mbd2d.load(EXAMPLES / "fourbar_seed.toml")
    q = np.zeros(9)
    q[0:3] = [1.3, 0.2, 0.0]
    assert_allclose(m.phi(q)[:2], -np.array([1.3 - 1.5, 0.2]), atol=1e-15)
    assert_allclose(m.jacobian(q)[:2, :3], -np.array([[1, 0, 0], [0, 1, -1.5]]), atol=1e-15)
    qd = np.zeros(9)
    qd[2] = 2.0
    assert_allclose(m.gamma(q, qd)[:2], -np.array([-1.5 * 4.0, 0.0]), atol=1e-14)
