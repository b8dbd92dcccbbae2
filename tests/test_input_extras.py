"""Input handling beyond the model file: NumPy inputs, settings limits, states, and the
difference between a dead centre and a driver the solver cannot follow."""
from __future__ import annotations

import numpy as np
import pytest

import mbd2d
from conftest import EXAMPLES


def test_numpy_scalars_and_arrays_are_numbers() -> None:
    m = mbd2d.Model("np")
    m.add_body("a", q0=[np.int64(1), np.float32(0.0), 0])
    m.add_revolute(["ground", "a"], np.zeros((2, 2)))
    m.add_driver("absolute", body="a", coordinate="theta", f={"poly": np.array([0.0, 1.0])})
    res = m.kinematics(t_end=np.float32(1.0), steps=np.int64(4))
    assert res.q.shape == (5, 3)


@pytest.mark.parametrize("t", [float("nan"), float("inf"), "a"])
def test_state_time_must_be_a_number(t: object) -> None:
    m = mbd2d.load(EXAMPLES / "slider_crank.toml")
    with pytest.raises(mbd2d.ModelError, match="t must be"):
        m.phi(np.zeros(9), t)  # type: ignore[arg-type]


def test_state_of_wrong_type() -> None:
    m = mbd2d.load(EXAMPLES / "slider_crank.toml")
    with pytest.raises(mbd2d.ModelError, match="q must be an array of 9 numbers"):
        m.jacobian([{"x": 1}] * 9)


@pytest.mark.parametrize("tol", [1e-300, 0.0, 2.0])
def test_unreachable_tolerance_is_rejected(tol: float) -> None:
    m = mbd2d.load(EXAMPLES / "slider_crank.toml")
    with pytest.raises(mbd2d.ModelError, match="tol must be from 1e-15"):
        m.kinematics(t_end=1.0, steps=10, tol=tol)


def test_steps_beyond_the_core_integer_range() -> None:
    m = mbd2d.load(EXAMPLES / "slider_crank.toml")
    with pytest.raises(mbd2d.ModelError, match="steps must be a whole number"):
        m.kinematics(t_end=1.0, steps=2**31)


def seed_with_driver(f: str) -> mbd2d.Model:
    return mbd2d.loads((EXAMPLES / "fourbar_seed.toml").read_text().replace(
        "f = { poly = [1.0471975511965976, 1.0] }", f"f = {f}"))


def test_runaway_driver_is_not_called_a_dead_centre() -> None:
    """A driver far too fast for the output steps, at a regular configuration, is a
    convergence failure (with advice), not a singular configuration."""
    with pytest.raises(mbd2d.ConvergenceError, match="too fast") as err:
        seed_with_driver("{ poly = [1.0471975511965976, 1e9] }").kinematics(t_end=1.0, steps=2)
    assert not isinstance(err.value, mbd2d.SingularConfigurationError)
    assert len(err.value.results.t) == 1   # the assembled state at t0


def test_jumping_driver_is_not_called_a_dead_centre() -> None:
    """A driver whose value jumps (a huge frequency sampled coarsely) fails at a regular J."""
    with pytest.raises(mbd2d.ConvergenceError, match="J is regular"):
        seed_with_driver("{ poly = [1.0471975511965976], harmonic = [{ amplitude = 0.3, "
                         "omega = 1e11 }] }").kinematics(t_end=1.0, steps=100)


@pytest.mark.parametrize("f, match", [
    ("{ poly = [0, 1e308] }", "within"),
    ("{ harmonic = [{ amplitude = 1, omega = 1, phase = 1e16 }] }", "phase"),
    ("{ harmonic = [{ amplitude = 1, omega = 1e13 }] }", "omega"),
    ("{ harmonic = [{ amplitude = 1, omega = 1e300 }] }", "within"),
])
def test_function_coefficients_out_of_range(f: str, match: str) -> None:
    with pytest.raises(mbd2d.ModelError, match=match):
        seed_with_driver(f).counts()


def test_non_utf8_file(tmp_path) -> None:
    p = tmp_path / "latin1.toml"
    p.write_bytes(b'[model]\nname = "caf\xe9"\n')
    with pytest.raises(mbd2d.ModelError, match="not UTF-8"):
        mbd2d.load(p)
