"""Each joint of the wider library in a small mechanism with a closed-form answer.

The models are written in TOML, as a user would, so they also document the keys.
"""
from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose

import mbd2d

W = 2.0 * np.pi          # one turn per second
TURN = dict(t_end=1.0, steps=200)


def run(text: str, **kw: float) -> mbd2d.KinematicsResult:
    return mbd2d.loads(text).kinematics(**{**TURN, **kw})


def test_distance_replaces_the_coupler() -> None:
    """Crank-rocker (crank 1, coupler 3.5, rocker 2.5, ground 3) with the coupler as a
    distance constraint: the rocker angle follows the loop-closure closed form."""
    res = run("""
[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]
[[body]]
name = "rocker"
q0 = [3.25, 1.2, -1.77]
[[joint]]
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
type = "revolute"
bodies = ["rocker", "ground"]
points = [[1.25, 0], [3, 0]]
[[joint]]
name = "coupler"
type = "distance"
bodies = ["crank", "rocker"]
points = [[0.5, 0], [-1.25, 0]]
distance = 3.5
[[driver]]
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    th = W * res.t
    a = np.column_stack([np.cos(th), np.sin(th)])            # crank tip
    o4 = np.array([3.0, 0.0])
    d = o4 - a
    L = np.hypot(*d.T)
    # rocker tip B on the open branch: |B - A| = 3.5, |B - O4| = 2.5
    along = (L**2 + 3.5**2 - 2.5**2) / (2 * L)
    h = np.sqrt(3.5**2 - along**2)
    u = d / L[:, None]
    b = a + along[:, None] * u + h[:, None] * np.column_stack([-u[:, 1], u[:, 0]])
    r = res.body("rocker")
    tip = np.column_stack([r.x - 1.25 * np.cos(r.theta), r.y - 1.25 * np.sin(r.theta)])
    assert_allclose(tip, b, atol=1e-10)


def test_pin_in_slot_scotch_yoke() -> None:
    """Scotch yoke: the crank pin runs in a vertical slot of a horizontal slider:
    x_slider = r cos(theta), exactly."""
    res = run("""
[[body]]
name = "crank"
q0 = [0.4, 0.0, 0.0]
[[body]]
name = "yoke"
q0 = [0.8, 0.0, 0.0]
[[joint]]
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.4, 0]]
[[joint]]
type = "translational"
bodies = ["ground", "yoke"]
points = [[0, 0], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
name = "slot"
type = "revolute-translational"
bodies = ["yoke", "crank"]
points = [[0, 0], [0.4, 0]]
axis = [0, 1]
[[driver]]
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    th = W * res.t
    y = res.body("yoke")
    assert_allclose(y.x, 0.8 * np.cos(th), atol=1e-12)
    assert_allclose(y.x_dot, -0.8 * W * np.sin(th), atol=1e-10)
    assert_allclose(y.x_ddot, -0.8 * W**2 * np.cos(th), atol=1e-9)


def test_point_on_line_slider_crank_without_slider() -> None:
    """The rod end of the offset slider-crank (crank 1, rod 3, offset 0.5) kept on the line
    y = 0.5 by a point-on-line joint: x_B = cos th + sqrt(9 - (sin th - 0.5)^2)."""
    res = run("""
[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]
[[body]]
name = "rod"
q0 = [2.5, 0.25, 0.17]
[[joint]]
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
type = "revolute"
bodies = ["crank", "rod"]
points = [[0.5, 0], [-1.5, 0]]
[[joint]]
name = "rail"
type = "point-on-line"
bodies = ["ground", "rod"]
points = [[0, 0.5], [1.5, 0]]
axis = [1, 0]
[[driver]]
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    th = W * res.t
    tip = res.point("rod", (1.5, 0.0))
    assert_allclose(tip[:, 0], np.cos(th) + np.sqrt(9 - (np.sin(th) - 0.5)**2), atol=1e-12)
    assert_allclose(tip[:, 1], 0.5, atol=1e-12)


def test_weld_carries_a_body_along() -> None:
    """A plate welded to a driven crank at 0.3 rad turns with it rigidly."""
    res = run("""
[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]
[[body]]
name = "plate"
q0 = [1.0, 0.2, 0.3]
[[joint]]
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
type = "weld"
bodies = ["crank", "plate"]
points = [[0.5, 0], [0, -0.2]]
angle = 0.3
[[driver]]
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    th = W * res.t
    p = res.body("plate")
    assert_allclose(p.theta, th + 0.3, atol=1e-12)
    # plate origin = crank tip + A(th + 0.3) (0, 0.2)
    assert_allclose(p.x, np.cos(th) - 0.2 * np.sin(th + 0.3), atol=1e-12)
    assert_allclose(p.y, np.sin(th) + 0.2 * np.cos(th + 0.3), atol=1e-12)


def test_pin_in_a_circular_slot() -> None:
    """A pin driven along x runs in a circular slot of radius 2 fixed to ground:
    y = sqrt(4 - x^2)."""
    res = run("""
[[body]]
name = "pin"
q0 = [0.0, 2.0, 0.0]
[[joint]]
type = "point-on-curve"
bodies = ["ground", "pin"]
curve = { circle = { center = [0, 0], radius = 2.0 } }
point = [0, 0]
[[joint]]
type = "absolute"
body = "pin"
coordinate = "theta"
[[driver]]
type = "absolute"
body = "pin"
coordinate = "x"
f = { harmonic = [{ amplitude = 1.5, omega = 6.283185307179586 }] }
""")
    x = 1.5 * np.sin(W * res.t)
    p = res.body("pin")
    assert_allclose(p.y, np.sqrt(4 - x**2), atol=1e-12)
    assert_allclose(p.theta, 0.0, atol=1e-14)


def test_gear_pair_ratio() -> None:
    """Two gears on ground pivots, radii 0.5 and 1.5: the driven gear turns at -1/3 the speed."""
    res = run("""
[[body]]
name = "pinion"
q0 = [0, 0, 0]
[[body]]
name = "wheel"
q0 = [2, 0, 0.4]
[[joint]]
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "revolute"
bodies = ["ground", "wheel"]
points = [[2, 0], [0, 0]]
[[joint]]
type = "gear"
bodies = ["pinion", "wheel"]
radii = [0.5, 1.5]
[[driver]]
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    w = res.body("wheel")
    assert_allclose(w.theta, 0.4 - W * res.t / 3, atol=1e-12)   # phase taken from q0
    assert_allclose(w.theta_dot, -W / 3, atol=1e-12)


def test_planet_in_a_ring_gear() -> None:
    """A planet (radius 0.5) on a driven carrier rolls inside a fixed ring (radius 1.5):
    its absolute speed is omega_c (1 - 1.5/0.5) = -2 omega_c."""
    res = run("""
[[body]]
name = "carrier"
q0 = [0.5, 0, 0]
[[body]]
name = "planet"
q0 = [1.0, 0, 0]
[[body]]
name = "ring"
q0 = [0, 0, 0]
[[joint]]
type = "revolute"
bodies = ["ground", "carrier"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
type = "revolute"
bodies = ["carrier", "planet"]
points = [[0.5, 0], [0, 0]]
[[joint]]
type = "weld"
bodies = ["ground", "ring"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "gear"
bodies = ["planet", "ring"]
radii = [0.5, 1.5]
internal = true
carrier = "carrier"
[[driver]]
type = "absolute"
body = "carrier"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    p = res.body("planet")
    assert_allclose(p.theta_dot, -2 * W, atol=1e-12)
    assert_allclose(p.theta, -2 * W * res.t, atol=1e-12)
    assert_allclose(np.hypot(p.x, p.y), 1.0, atol=1e-12)


def test_rack_and_pinion() -> None:
    """A pinion (radius 0.3) on a ground pivot above a rack sliding along x:
    x_rack = 0.3 theta + const."""
    res = run("""
[[body]]
name = "pinion"
q0 = [0, 0, 0]
[[body]]
name = "rack"
q0 = [0, -0.3, 0]
[[joint]]
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "translational"
bodies = ["ground", "rack"]
points = [[0, -0.3], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
type = "rack-pinion"
bodies = ["pinion", "rack"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = 0.3
[[driver]]
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""")
    assert_allclose(res.body("rack").x, 0.3 * W * res.t, atol=1e-12)


def test_rolling_disc() -> None:
    """A disc of radius 0.25 rolling on the ground line y = 0, driven along x:
    y = 0.25 and theta = -x / 0.25."""
    res = run("""
[[body]]
name = "disc"
q0 = [0, 0.3, 0]
[[joint]]
type = "rolling-disc"
bodies = ["disc", "ground"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = 0.25
[[driver]]
type = "absolute"
body = "disc"
coordinate = "x"
f = { poly = [0, 0.5, 0.2] }
""")
    d = res.body("disc")
    x = 0.5 * res.t + 0.2 * res.t**2
    assert_allclose(d.y, 0.25, atol=1e-12)
    assert_allclose(d.theta, -x / 0.25, atol=1e-12)
    assert_allclose(d.theta_ddot, -0.4 / 0.25, atol=1e-10)


def test_absolute_constraints_pin_a_body() -> None:
    """x and y fixed at their q0 values, theta driven: a pure rotation in place."""
    res = run("""
[[body]]
name = "wheel"
q0 = [1.5, -0.5, 0.0]
[[joint]]
type = "absolute"
body = "wheel"
coordinate = "x"
[[joint]]
type = "absolute"
body = "wheel"
coordinate = "y"
value = -0.5
[[driver]]
type = "absolute"
body = "wheel"
coordinate = "theta"
f = { poly = [0, 1] }
""")
    w = res.body("wheel")
    assert_allclose(w.x, 1.5, atol=1e-14)
    assert_allclose(w.y, -0.5, atol=1e-14)
    assert_allclose(w.theta, res.t, atol=1e-14)
