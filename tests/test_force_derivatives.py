"""Finite-difference oracle for the applied forces' derivatives the design sensitivities use.

Inverse dynamics, statics and the dopri5 sensitivities need the change of the generalized
forces Q(q, q_dot, t; p) along a state direction (dq, dq_dot) and a design parameter p:
dQ = Q_q dq + Q_q_dot dq_dot + Q_p. The core computes it by two paths: direction by
direction through dual numbers (``dcol``: inverse dynamics, statics) and, for the dopri5
sensitivities, all parameters at once with a spring's derivative in closed form
(``drow``, mbd_forces spring_rows). Both are compared here with central differences of Q
itself (``qf``, the core's force evaluation) at (q +- h dq, q_dot +- h dq_dot, p +- h), for
every kind of force and every one of its non-count parameters, the masses and gravity, at
random states: springs to ground and between two moving bodies (with damping, a free
length and an actuator), a torque, a point force and a rotational spring.
"""
from __future__ import annotations

import numpy as np
import pytest

import mbd2d
from mbd2d.analysis.sensitivities import requested
from mbd2d.binding import core
from mbd2d.binding.pack import pack, pack_dynamics
from mbd2d.binding.params import parameter_table

H = 1e-6


def loaded_model() -> mbd2d.Model:
    """The free slider-crank of test_sensitivities (masses, a spring s1 to ground) with every
    other kind of force."""
    from test_sensitivities import add_force_kinds, free_slider_crank
    m = add_force_kinds(free_slider_crank())
    m.add_rotational_spring(["crank", "rod"], stiffness=7.0, damping=0.4, angle0=0.3,
                            f={"poly": [0.2, 0.1]}, name="r1")
    return m


def force_params(m: mbd2d.Model) -> list[str]:
    """Every force parameter, mass, inertia and gravity component by name."""
    return [n for n in m.parameters()
            if n.startswith(("force.", "body.", "model.gravity"))]


class Tables:
    """The packed tables of a model and a copy of its parameter arrays to change."""

    def __init__(self, m: mbd2d.Model):
        self.p = pack(m)
        self.d = pack_dynamics(m, self.p)
        self.arrays = {1: self.p.rpar.copy(), 2: np.asfortranarray(self.d.bmass.copy()),
                       3: self.d.grav.copy(), 4: self.d.fpar.copy()}

    def call(self, q, qd, t, dq, dqd, ptab, arrays=None):
        a = self.arrays if arrays is None else arrays
        out = core.forces_d(self.p, self.d, a[1], a[2], a[3], a[4], q, qd, t, dq, dqd, ptab)
        assert out.status == 0, out.msg
        return out

    def shifted(self, table: int, index: int, h: float) -> dict:
        """The parameter arrays with entry index (1-based) of table changed by h."""
        a = {k: v.copy(order="F") for k, v in self.arrays.items()}
        flat = a[table].reshape(-1, order="F")
        flat[index - 1] += h
        a[table] = flat.reshape(self.arrays[table].shape, order="F")
        return a


@pytest.fixture(scope="module")
def setup():
    m = loaded_model()
    tabs = Tables(m)
    names = force_params(m)
    ptab = parameter_table(tabs.p, requested(m, names), tabs.d)
    return m, tabs, names, ptab


def test_every_force_parameter_is_covered(setup):
    m, _, names, _ = setup
    for f in ("s1", "s2", "t1", "p1", "r1"):
        assert any(n.startswith(f"force.{f}.") for n in names), f
    assert "model.gravity.1" in names and "body.rod.mass" in names


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_force_changes_against_central_differences(setup, seed):
    """dcol and drow against (Q(x + h d) - Q(x - h d)) / 2h, x = (q, q_dot, p), each column
    a random state direction together with one parameter."""
    m, tabs, names, ptab = setup
    rng = np.random.default_rng(seed)
    nq, nk = tabs.p.nq, ptab.shape[1]
    q = tabs.p.q0 + rng.normal(0.0, 0.2, nq)
    qd = rng.normal(0.0, 1.5, nq)
    t = float(rng.uniform(0.0, 2.0))
    dq = rng.normal(0.0, 1.0, (nq, nk))
    dqd = rng.normal(0.0, 1.0, (nq, nk))
    out = tabs.call(q, qd, t, dq, dqd, ptab)
    for k in range(nk):
        table, index = int(ptab[0, k]), int(ptab[1, k])
        up = tabs.call(q + H * dq[:, k], qd + H * dqd[:, k], t, dq[:, :1], dqd[:, :1],
                       ptab[:, :1], tabs.shifted(table, index, H)).qf
        dn = tabs.call(q - H * dq[:, k], qd - H * dqd[:, k], t, dq[:, :1], dqd[:, :1],
                       ptab[:, :1], tabs.shifted(table, index, -H)).qf
        fd = (up - dn) / (2 * H)
        scale = max(1.0, float(np.abs(fd).max()))
        for path in ("dcol", "drow"):
            got = getattr(out, path)[:, k]
            err = float(np.abs(got - fd).max()) / scale
            assert err < 1e-7, f"{path} along {names[k]}: {err:.2e}"


def test_state_directions_alone(setup):
    """Without a parameter change (a parameter no force holds: a constraint's), the rows'
    closed form is the state derivative alone: both paths agree with the differences."""
    m, tabs, _, _ = setup
    ptab = parameter_table(tabs.p, requested(m, ["joint.A.points.0.0"] * 1), tabs.d)
    rng = np.random.default_rng(7)
    nq = tabs.p.nq
    q = tabs.p.q0 + rng.normal(0.0, 0.2, nq)
    qd = rng.normal(0.0, 1.5, nq)
    dq = rng.normal(0.0, 1.0, (nq, 1))
    dqd = rng.normal(0.0, 1.0, (nq, 1))
    out = tabs.call(q, qd, 0.7, dq, dqd, ptab)
    up = tabs.call(q + H * dq[:, 0], qd + H * dqd[:, 0], 0.7, dq, dqd, ptab).qf
    dn = tabs.call(q - H * dq[:, 0], qd - H * dqd[:, 0], 0.7, dq, dqd, ptab).qf
    fd = (up - dn) / (2 * H)
    scale = max(1.0, float(np.abs(fd).max()))
    assert np.abs(out.dcol[:, 0] - fd).max() / scale < 1e-7
    assert np.abs(out.drow[:, 0] - fd).max() / scale < 1e-7
