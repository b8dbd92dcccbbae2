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


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Angle differences mapped into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


@pytest.fixture
def toml_model():
    """Fixture form of :func:`model_from_toml`."""
    return model_from_toml
