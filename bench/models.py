"""The models every benchmark shares, built with the mbd2d API.

* free_fourbar: the Grashof crank-rocker of examples/fourbar_grashof.toml without its motor,
  uniform bars (m = density * L, I = m L^2 / 12, centre of mass at mid-length) under gravity
  g = 9.81 m/s^2, released at rest with the crank horizontal. Crank 1 m, coupler 3.5 m,
  rocker 2.5 m, ground 3 m.
* free_nfourbar: the IFToMM N-four-bar (A02) without a driver: 1 kg, 1 m bars, cranks upright,
  every crank turning at omega0 and the couplers translating.
* driven_nfourbar: examples/nfourbar.py (kinematics).
"""
from __future__ import annotations

import sys
from pathlib import Path

import mbd2d

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import free_fourbar as free_fourbar_example  # noqa: E402
import nfourbar  # noqa: E402

G = 9.81

FOURBAR_BARS, FOURBAR_GROUND = free_fourbar_example.BARS, free_fourbar_example.GROUND


def free_fourbar(density: float = 1.0) -> mbd2d.Model:
    """The free four-bar under gravity (examples/free_fourbar.py)."""
    return free_fourbar_example.build(density)


def free_nfourbar(n: int, omega0: float = -1.0) -> mbd2d.Model:
    """The IFToMM N-four-bar without its driver (A02)."""
    return nfourbar.build(n, driven=False, omega0=omega0)


def driven_nfourbar(n: int) -> mbd2d.Model:
    """The kinematic N-four-bar: crank 0 driven, theta = pi/2 - t (cranks upright at t = 0)."""
    return nfourbar.build(n)
