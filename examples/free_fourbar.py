"""The free four-bar: the Grashof crank-rocker of fourbar_grashof.toml without its motor,
uniform bars (m = density L, I = m L^2 / 12, centre of mass at mid-length) under gravity,
released at rest with the crank horizontal. Crank 1 m, coupler 3.5 m, rocker 2.5 m, ground 3 m.
The model of the dynamics benchmarks and tests.

    python examples/free_fourbar.py [t_end]
"""
from __future__ import annotations

import sys

import mbd2d

# (name, length, rough q0) of the moving bars; the joint points are the bar ends (+-L/2 along
# the local x axis)
BARS = (("crank", 1.0, (0.5, 0.0, 0.0)),
        ("coupler", 3.5, (2.25, 1.2, 0.78)),
        ("rocker", 2.5, (3.25, 1.2, -1.77)))
GROUND = 3.0     # distance of the two ground pivots


def build(density: float = 1.0) -> mbd2d.Model:
    """The free four-bar with bars of `density` kg/m (gravity 9.81 m/s^2 downwards)."""
    m = mbd2d.Model("free-four-bar")
    for name, length, q0 in BARS:
        mass = density * length
        m.add_body(name, q0=list(q0), mass=mass, inertia=mass * length ** 2 / 12)
    m.add_revolute(["ground", "crank"], [[0.0, 0.0], [-0.5, 0.0]], name="O2")
    m.add_revolute(["crank", "coupler"], [[0.5, 0.0], [-1.75, 0.0]], name="A")
    m.add_revolute(["coupler", "rocker"], [[1.75, 0.0], [-1.25, 0.0]], name="B")
    m.add_revolute(["rocker", "ground"], [[1.25, 0.0], [GROUND, 0.0]], name="O4")
    return m


if __name__ == "__main__":
    t_end = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    print(build().dynamics(t_end=t_end, steps=100))
