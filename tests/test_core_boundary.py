"""The f2py boundary: the core takes float64 reals and default (32-bit) integer tables, and
the Python API converts whatever numbers the user gives (integer lists included)."""
from __future__ import annotations

import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d import _core
from conftest import load_example, model_from_toml


def _arg_line(doc: str, name: str) -> str:
    m = re.search(rf"^{name} : (.*)$", doc, flags=re.MULTILINE)
    assert m, f"{name} not documented in:\n{doc}"
    return m.group(1)


def test_core_kinematics_signature_is_float64_and_int32():
    doc = _core.core_kinematics.__doc__
    assert "array('d')" in _arg_line(doc, "rpar")
    assert "array('d')" in _arg_line(doc, "q0")
    assert "array('i')" in _arg_line(doc, "ctab")


@pytest.mark.parametrize("fn", ["core_eval", "core_sizes"])
def test_other_entry_points_take_the_same_tables(fn):
    doc = getattr(_core, fn).__doc__
    assert "array('d')" in _arg_line(doc, "rpar")
    assert "array('i')" in _arg_line(doc, "ctab")


INT_PENDULUM = """
[[body]]
name = "bar"
q0 = [1, 0, 0]

[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "bar"]
points = [[0, 0], [-1, 0]]

[[driver]]
name = "spin"
type = "absolute"
body = "bar"
coordinate = "theta"
f = { poly = [0, 2] }
"""


def pendulum_closed_form(t):
    th = 2.0 * t
    return np.column_stack([np.cos(th), np.sin(th), th])


def test_integer_q0_lists_through_the_builder():
    m = mbd2d.Model("int-pendulum")
    m.add_body("bar", q0=[1, 0, 0])
    m.add_revolute(["ground", "bar"], [[0, 0], [-1, 0]], name="pivot")
    m.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0, 2]}, name="spin")
    assert m.bodies[0].q0 == (1.0, 0.0, 0.0)
    res = m.kinematics(t_end=1, steps=10)
    assert res.q.dtype == np.float64
    assert_allclose(res.q, pendulum_closed_form(res.t), rtol=0, atol=1e-12)


def test_integer_numbers_in_toml(toml_model):
    res = toml_model(INT_PENDULUM).kinematics(t_end=1, steps=10, t0=0)
    assert_allclose(res.q, pendulum_closed_form(res.t), rtol=0, atol=1e-12)


def test_numpy_integer_array_q0():
    m = model_from_toml(INT_PENDULUM)
    m2 = mbd2d.Model("np-int")
    m2.add_body("bar", q0=np.array([1, 0, 0], dtype=np.int32))
    m2.add_revolute(["ground", "bar"], [[0, 0], [-1, 0]], name="pivot")
    m2.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0, 2]}, name="spin")
    a = m.kinematics(t_end=1.0, steps=5)
    b = m2.kinematics(t_end=1.0, steps=5)
    assert np.array_equal(a.q, b.q)


def test_integer_states_for_evaluation():
    m = load_example("fourbar_grashof.toml")
    qi = [0, 0, 1, 2, 1, 0, 3, 1, -2]
    qf = np.array(qi, dtype=float)
    assert np.array_equal(m.phi(qi, 0), m.phi(qf, 0.0))
    assert np.array_equal(m.jacobian(np.array(qi, dtype=np.int64), 1), m.jacobian(qf, 1.0))
    assert np.array_equal(m.gamma(qi, [1] * 9, 0), m.gamma(qf, np.ones(9), 0.0))
    assert np.array_equal(m.nu(qi, 0), m.nu(qf, 0.0))
    for out in (m.phi(qi, 0), m.jacobian(qi, 0), m.nu(qi, 0), m.gamma(qi, [1] * 9, 0)):
        assert out.dtype == np.float64


def test_integer_time_span():
    m = load_example("fourbar_grashof.toml")
    a = m.kinematics(t_end=1, steps=4, t0=0)
    b = m.kinematics(t_end=1.0, steps=4, t0=0.0)
    assert a.t.dtype == np.float64
    assert np.array_equal(a.q, b.q)
    assert np.array_equal(a.t, [0.0, 0.25, 0.5, 0.75, 1.0])
