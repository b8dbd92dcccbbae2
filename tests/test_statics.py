"""Statics: equilibria against closed forms and hand calculations, with reactions and
stability."""
from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES


def newton(f, x0: float, tol: float = 1e-15) -> float:
    """A scalar root by Newton with central differences (an independent solver)."""
    x = x0
    for _ in range(100):
        h = 1e-7
        dx = f(x) / ((f(x + h) - f(x - h)) / (2 * h))
        x -= dx
        if abs(dx) < tol:
            break
    return x


def test_pendulum_with_torsion_spring_closed_form() -> None:
    """Uniform bar (1 m, 1 kg) on a pivot with a torsion spring k = 10 N m/rad, free at
    horizontal: k theta + m g (L/2) cos(theta) = 0."""
    st = mbd2d.load(EXAMPLES / "pendulum_spring.toml").statics()
    th = newton(lambda a: 10.0 * a + 9.81 * 0.5 * math.cos(a), 0.0)
    x, y, theta = st.body("bar")
    assert st.stability == "stable"
    assert_allclose(theta, th, atol=1e-10)
    assert_allclose([x, y], [0.5 * math.cos(th), 0.5 * math.sin(th)], atol=1e-10)
    r = st.reaction("pivot")
    assert_allclose([r.fx_j[0], r.fy_j[0]], [0.0, 9.81], atol=1e-9)   # carries the weight


def test_pendulum_without_spring_hangs_down() -> None:
    """Started horizontal, where the tangent stiffness vanishes: the search still goes down
    to the stable equilibrium."""
    text = (EXAMPLES / "pendulum_spring.toml").read_text().split("[[force]]")[0]
    st = mbd2d.loads(text).statics()
    assert st.stability == "stable"
    assert_allclose(st.body("bar")[2], -math.pi / 2, atol=1e-9)


def spring_slider_crank(torque: float) -> mbd2d.Model:
    """The offset slider-crank (crank 1, rod 3, guide 0.5 above the pivot) with a torque on
    the crank and a spring from the slider to a ground anchor at (6, 0.5)."""
    text = (EXAMPLES / "slider_crank.toml").read_text()
    text = text.split("[[driver]]")[0]                    # no driver: the crank is free
    for body in ("crank", "rod", "slider"):
        text = text.replace(f'[[body]]\nname = "{body}"\n',
                            f'[[body]]\nname = "{body}"\nmass = 1.0\ninertia = 0.1\n')
    text = text.replace("[model]\n", "[model]\ngravity = [0.0, 0.0]\n")
    text += (f'\n[[force]]\nname = "motor"\ntype = "torque"\nbody = "crank"\nf = {torque!r}\n'
             '\n[[force]]\nname = "spring"\ntype = "spring"\nbodies = ["slider", "ground"]\n'
             'points = [[0.0, 0.0], [6.0, 0.5]]\nstiffness = 50.0\nlength0 = 1.5\n')
    return mbd2d.loads(text)


def test_spring_loaded_slider_crank_by_virtual_work() -> None:
    """Hand calculation: with x(theta) = cos th + sqrt(9 - (sin th - 0.5)^2) the spring
    (k = 50, free length 1.5, anchor at x = 6) pulls the slider with k (6 - x - 1.5); virtual
    work with the crank torque T gives T + k (6 - x - 1.5) dx/dth = 0."""
    T = 2.0
    st = spring_slider_crank(T).statics()

    def x(th: float) -> float:
        return math.cos(th) + math.sqrt(9.0 - (math.sin(th) - 0.5)**2)

    def work(th: float) -> float:
        h = 1e-6
        return T + 50.0 * (6.0 - x(th) - 1.5) * (x(th + h) - x(th - h)) / (2 * h)

    theta = st.body("crank")[2]
    assert abs(work(theta)) < 1e-6
    th_hand = newton(work, theta)
    assert_allclose(theta, th_hand, atol=1e-9)
    assert_allclose(st.body("slider")[0], x(th_hand), atol=1e-9)
    assert st.stability == "stable"
    # the guide takes no axial load: the spring force goes through the rod
    guide = st.reaction("guide")
    assert_allclose(guide.fx_j[0], 0.0, atol=1e-8)


def test_neutral_equilibrium_is_reported() -> None:
    """A slider on a frictionless horizontal guide with no loads: any position balances."""
    m = mbd2d.loads('''
[model]
gravity = [0.0, 0.0]
[[body]]
name = "block"
q0 = [0.3, 0.0, 0.0]
mass = 1.0
inertia = 0.1
[[joint]]
name = "rail"
type = "translational"
bodies = ["ground", "block"]
points = [[0, 0], [0, 0]]
axes = [[1, 0], [1, 0]]
''')
    st = m.statics()
    assert st.stability == "neutral"
    assert_allclose(st.body("block")[0], 0.3, atol=1e-12)


def test_statics_needs_masses() -> None:
    with pytest.raises(mbd2d.ModelError, match="mass"):
        mbd2d.load(EXAMPLES / "slider_crank.toml").statics()


def test_statics_cli(tmp_path) -> None:
    import subprocess
    import sys
    r = subprocess.run([sys.executable, "-m", "mbd2d", "statics",
                        str(EXAMPLES / "pendulum_spring.toml")], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert "stable" in r.stdout and "pivot" in r.stdout
    assert np.isclose(float(r.stdout.split("theta =")[1].split()[0]), -0.443125528, atol=1e-8)
