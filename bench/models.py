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

import math
import sys
from pathlib import Path

import mbd2d

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import nfourbar  # noqa: E402

G = 9.81

# (name, length, rough q0) of the free four-bar's moving bars; the joint points are the bar
# ends (+-L/2 along the local x axis)
FOURBAR_BARS = (("crank", 1.0, (0.5, 0.0, 0.0)),
                ("coupler", 3.5, (2.25, 1.2, 0.78)),
                ("rocker", 2.5, (3.25, 1.2, -1.77)))
FOURBAR_GROUND = 3.0


def free_fourbar(density: float = 1.0) -> mbd2d.Model:
    """The free four-bar under gravity (see the module docstring)."""
    m = mbd2d.Model("free-four-bar", gravity=(0.0, -G))
    for name, length, q0 in FOURBAR_BARS:
        mass = density * length
        m.add_body(name, q0=list(q0), mass=mass, inertia=mass * length ** 2 / 12)
    m.add_revolute(["ground", "crank"], [[0.0, 0.0], [-0.5, 0.0]], name="O2")
    m.add_revolute(["crank", "coupler"], [[0.5, 0.0], [-1.75, 0.0]], name="A")
    m.add_revolute(["coupler", "rocker"], [[1.75, 0.0], [-1.25, 0.0]], name="B")
    m.add_revolute(["rocker", "ground"], [[1.25, 0.0], [FOURBAR_GROUND, 0.0]], name="O4")
    return m


def free_nfourbar(n: int, omega0: float = -1.0) -> mbd2d.Model:
    """The IFToMM N-four-bar without its driver (A02)."""
    return nfourbar.build(n, driven=False, omega0=omega0)


def driven_nfourbar(n: int) -> mbd2d.Model:
    """The kinematic N-four-bar: crank 0 driven, theta = pi/2 - t (cranks upright at t = 0)."""
    return nfourbar.build(n)
