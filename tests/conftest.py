"""Shared helpers for the mbd2d test suite.

The tests are independent oracles: closed-form solutions and finite differences computed
here, never by calling the engine's own helpers for the quantity being checked.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mbd2d

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


def example_path(name: str) -> Path:
    """Path of an example model file."""
    return EXAMPLES / name


def load_example(name: str) -> mbd2d.Model:
    """Load one of the examples/*.toml models."""
    return mbd2d.load(example_path(name))


def model_from_toml(text: str) -> mbd2d.Model:
    """Build a model from TOML text (through the public loader)."""
    return mbd2d.loads(text)


def global_point(x: np.ndarray, y: np.ndarray, theta: np.ndarray,
                 local: tuple[float, float]) -> np.ndarray:
    """Global position r + A(theta) s' of a body-fixed point, vectorised over rows: (n, 2)."""
    sx, sy = local
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack([x + c * sx - s * sy, y + s * sx + c * sy])


def kinematic_central(model: mbd2d.Model, name: str, value: float, h: float, t_end: float,
                      steps: int) -> np.ndarray:
    """(3, rows, nq) central differences of q, q_dot, q_ddot of the kinematic run itself
    along one parameter."""
    runs = []
    for v in (value + h, value - h):
        res = model.with_params({name: v}).kinematics(t_end, steps)
        runs.append(np.stack([res.q, res.qd, res.qdd]))
    return (runs[0] - runs[1]) / (2 * h)


def check_kinematic_sensitivities(model: mbd2d.Model, names: list[str], t_end: float = 1.0,
                                  steps: int = 24, rtol: float = 1e-7) -> None:
    """dq/dp, dq_dot/dp and dq_ddot/dp of model.kinematics for each name against central
    differences of the run at p +- h and p +- h/2, Richardson-extrapolated (O(h**4); the
    positions, velocities and accelerations are solved to machine accuracy, so the
    differences carry the derivative to about 1e-9): within rtol of the largest entry (at
    least 1)."""
    pars = model.parameters()
    res = model.kinematics(t_end, steps, sensitivities=names)
    for j, name in enumerate(names):
        h = 1e-3 * max(1.0, abs(pars[name]))
        d1 = kinematic_central(model, name, pars[name], h, t_end, steps)
        d2 = kinematic_central(model, name, pars[name], h / 2, t_end, steps)
        want = (4 * d2 - d1) / 3
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            scale = max(1.0, float(np.abs(want[k]).max()))
            err = float(np.abs(got[:, :, j] - want[k]).max())
            assert err <= rtol * scale, f"d{['q', 'qd', 'qdd'][k]}/d {name}: {err:.2e}"


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Angle differences mapped into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


@pytest.fixture
def toml_model():
    """Fixture form of :func:`model_from_toml`."""
    return model_from_toml
