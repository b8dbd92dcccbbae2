"""Mechanism quantities against closed forms written here (no mbd2d in the references):
a body point's position, velocity and acceleration, the transmission angle (law of
cosines), the velocity ratio and mechanical advantage (loop-closure velocity ratio) and the
distance to a dead centre (zero at the closed-form toggle times) for the Grashof four-bar,
the offset slider-crank and a five-bar with one driver held."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d import ModelError

EX = Path(__file__).resolve().parents[1] / "examples"
W = 2 * np.pi                       # crank speed of the examples [rad/s]


@pytest.fixture(scope="module")
def fourbar() -> mbd2d.KinematicsResult:
    return mbd2d.load(EX / "fourbar_grashof.toml").kinematics(t_end=1.0, steps=720)


@pytest.fixture(scope="module")
def slider() -> mbd2d.KinematicsResult:
    return mbd2d.load(EX / "slider_crank.toml").kinematics(t_end=1.0, steps=720)


# --------------------------------------------------------------- closed forms (no mbd2d)
def fourbar_angles(th2: np.ndarray, a: float, b: float, c: float, d: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Coupler and rocker link angles of the open four-bar (B above the line A-O4), ground
    pivots (0, 0) and (d, 0): the two-circle intersection."""
    ax, ay = a * np.cos(th2), a * np.sin(th2)
    vx, vy = d - ax, -ay
    L = np.hypot(vx, vy)
    x = (b**2 - c**2 + L**2) / (2 * L)
    h = np.sqrt(b**2 - x**2)
    bx, by = ax + (x * vx - h * vy) / L, ay + (x * vy + h * vx) / L
    return np.arctan2(by - ay, bx - ax), np.arctan2(by, bx - d)


def slider_x(th: np.ndarray, r: float, l: float, e: float) -> tuple[np.ndarray, ...]:
    """Offset slider-crank: x, dx/dtheta, d2x/dtheta2 with g = r sin(theta) - e."""
    g, gp, gpp = r * np.sin(th) - e, r * np.cos(th), -r * np.sin(th)
    D = np.sqrt(l * l - g * g)
    x = r * np.cos(th) + D
    dx = -r * np.sin(th) - g * gp / D
    ddx = -r * np.cos(th) - (gp**2 + g * gpp) / D - g**2 * gp**2 / D**3
    return x, dx, ddx


# --------------------------------------------------------------- body points
def test_point_position_velocity_acceleration(slider):
    """The rod's end B is the slider's pin: x, x_dot, x_ddot from the closed form, y fixed;
    the crank pin turns on a circle at constant speed."""
    th = W * slider.t
    x, dx, ddx = slider_x(th, 1.0, 3.0, 0.5)
    b = slider.point("rod", [1.5, 0.0])
    assert_allclose(b.x, x, atol=1e-12)
    assert_allclose(b.x_dot, W * dx, atol=1e-11)
    assert_allclose(b.x_ddot, W**2 * ddx, atol=1e-10)
    assert_allclose(b.y, 0.5, atol=1e-12)
    assert_allclose(b.v[:, 1], 0.0, atol=1e-11)
    assert_allclose(b.a[:, 1], 0.0, atol=1e-10)
    a = slider.point("crank", (0.5, 0.0))
    assert_allclose(a.r, np.column_stack([np.cos(th), np.sin(th)]), atol=1e-12)
    assert_allclose(a.v, W * np.column_stack([-np.sin(th), np.cos(th)]), atol=1e-11)
    assert_allclose(a.a, -W**2 * a.r, atol=1e-9)
    assert_allclose(a.speed, W, rtol=1e-12)
    assert_allclose(b[:, 0], b.r[:, 0], rtol=0, atol=0)     # indexing gives positions
    assert np.asarray(b).shape == (len(slider.t), 2)


# --------------------------------------------------------------- transmission angle
def test_transmission_angle_fourbar_law_of_cosines(fourbar):
    a, b, c, d = 1.0, 3.5, 2.5, 3.0
    th2 = W * fourbar.t
    mu = np.arccos((b * b + c * c - a * a - d * d + 2 * a * d * np.cos(th2)) / (2 * b * c))
    assert_allclose(fourbar.transmission_angle("B"), mu, atol=1e-12)
    assert_allclose(fourbar.transmission_angle("B", output="rocker"), mu, atol=1e-12)
    # extremes at theta2 = 0 and pi, as the formula says
    got = np.degrees(fourbar.transmission_angle("B"))
    assert got.min() == pytest.approx(np.degrees(np.arccos((b*b + c*c - (d - a)**2)
                                                           / (2*b*c))), abs=1e-9)


def test_transmission_angle_slider_crank(slider):
    """mu = pi/2 - |phi|, phi the rod's angle to the slide: sin phi = (r sin th - e) / l."""
    th = W * slider.t
    mu = np.pi / 2 - np.arcsin(np.abs(np.sin(th) - 0.5) / 3.0)
    assert_allclose(slider.transmission_angle("B"), mu, atol=1e-12)


# --------------------------------------------------------------- velocity ratio and MA
def test_fourbar_velocity_ratio_and_mechanical_advantage(fourbar):
    """omega4 / omega2 = a sin(th2 - th3) / (c sin(th4 - th3)) (Norton, eq. 6.18); the
    mechanical advantage (rocker torque per crank torque) is its inverse."""
    a, c = 1.0, 2.5
    th2 = W * fourbar.t
    th3, th4 = fourbar_angles(th2, a, 3.5, c, 3.0)
    ratio = a * np.sin(th2 - th3) / (c * np.sin(th4 - th3))
    assert_allclose(fourbar.velocity_ratio("motor", "rocker.theta"), ratio, atol=1e-12)
    assert_allclose(fourbar.mechanical_advantage("motor", "rocker.theta"), 1 / ratio,
                    rtol=1e-10)
    # the same between two coordinates: the crank's angle is the driver's quantity
    assert_allclose(fourbar.mechanical_advantage("crank.theta", "rocker.theta"), 1 / ratio,
                    rtol=1e-10)
    # coupler: omega3 / omega2 = a sin(th4 - th2) / (b sin(th3 - th4))
    assert_allclose(fourbar.velocity_ratio("motor", "coupler.theta"),
                    a * np.sin(th4 - th2) / (3.5 * np.sin(th3 - th4)), atol=1e-12)


def test_slider_crank_mechanical_advantage(slider):
    """Output force per input torque F / T = 1 / (dx/dtheta) (power in = power out)."""
    th = W * slider.t
    _, dx, _ = slider_x(th, 1.0, 3.0, 0.5)
    assert_allclose(slider.velocity_ratio("motor", "slider.x"), dx, atol=1e-12)
    assert_allclose(slider.mechanical_advantage("motor", "slider.x"), 1 / dx, rtol=1e-10)


def test_ratio_is_defined_where_the_driver_stands_still():
    """A crank that rocks (theta = 0.3 sin(2 pi t)) stands still at t = 0.25: the velocity
    ratio (a property of the configuration) is still the closed form there."""
    text = (EX / "slider_crank.toml").read_text().replace(
        "f = { poly = [0.0, 6.283185307179586] }",
        "f = { harmonic = [{ amplitude = 0.3, omega = 6.283185307179586, phase = 0.0 }] }")
    res = mbd2d.loads(text).kinematics(t_end=0.5, steps=8)
    th = 0.3 * np.sin(W * res.t)
    _, dx, _ = slider_x(th, 1.0, 3.0, 0.5)
    assert res.body("crank").theta_dot[4] == pytest.approx(0.0, abs=1e-12)
    assert_allclose(res.velocity_ratio("motor", "slider.x"), dx, atol=1e-12)


FIVEBAR = """
[model]
name = "five-bar"
[[body]]
name = "c1"
q0 = [0.0, 0.5, 1.5708]
[[body]]
name = "l1"
q0 = [0.8, 1.5, 0.2]
[[body]]
name = "l2"
q0 = [2.2, 1.5, -0.2]
[[body]]
name = "c2"
q0 = [3.0, 0.5, 1.5708]
[[joint]]
name = "O1"
type = "revolute"
bodies = ["ground", "c1"]
points = [[0.0, 0.0], [-0.5, 0.0]]
[[joint]]
name = "A"
type = "revolute"
bodies = ["c1", "l1"]
points = [[0.5, 0.0], [-1.0, 0.0]]
[[joint]]
name = "P"
type = "revolute"
bodies = ["l1", "l2"]
points = [[1.0, 0.0], [-1.0, 0.0]]
[[joint]]
name = "C"
type = "revolute"
bodies = ["l2", "c2"]
points = [[1.0, 0.0], [0.5, 0.0]]
[[joint]]
name = "O2"
type = "revolute"
bodies = ["ground", "c2"]
points = [[3.0, 0.0], [-0.5, 0.0]]
[[driver]]
name = "left"
type = "absolute"
body = "c1"
coordinate = "theta"
f = { poly = [1.5708, 0.5] }
[[driver]]
name = "right"
type = "absolute"
body = "c2"
coordinate = "theta"
f = { poly = [1.5708, -0.3] }
"""


def test_two_drivers_the_other_is_held():
    """A five-bar with two motors: with 'right' held, 'left' drives the four-bar O1-A-P-C
    whose ground link runs from O1 to the fixed crank tip C, so d(l2.theta)/d(left) is that
    four-bar's omega4 / omega2 (rotation invariant: angle differences only); the two motors
    do not move each other (ratio 0, mechanical advantage infinite)."""
    res = mbd2d.loads(FIVEBAR).kinematics(t_end=1.0, steps=20)
    t2 = np.array([res.point("c1", (0.5, 0.0)).r, res.point("l1", (1.0, 0.0)).r,
                   res.point("c2", (0.5, 0.0)).r])
    a_pt, p_pt, c_pt = t2
    th2 = np.arctan2(a_pt[:, 1], a_pt[:, 0])
    th3 = np.arctan2(p_pt[:, 1] - a_pt[:, 1], p_pt[:, 0] - a_pt[:, 0])
    th4 = np.arctan2(p_pt[:, 1] - c_pt[:, 1], p_pt[:, 0] - c_pt[:, 0])
    ratio = 1.0 * np.sin(th2 - th3) / (2.0 * np.sin(th4 - th3))
    assert_allclose(res.velocity_ratio("left", "l2.theta"), ratio, atol=1e-12)
    assert_allclose(res.velocity_ratio("left", "right"), 0.0, atol=0)
    assert np.all(np.isinf(res.mechanical_advantage("left", "right")))
    assert_allclose(res.velocity_ratio("left", "c1.theta"), 1.0, atol=1e-12)
    with pytest.raises(ModelError, match="via"):
        res.velocity_ratio("l1.theta", "l2.theta")
    assert_allclose(res.velocity_ratio("l1.theta", "l2.theta", via="right"),
                    res.velocity_ratio("right", "l2.theta")
                    / res.velocity_ratio("right", "l1.theta"), rtol=1e-12)


# --------------------------------------------------------------- dead centres
def _toggle_root(t: np.ndarray, c: np.ndarray, t_star: float) -> float:
    """Where c**2 (linear in t* - t near a fold) extrapolates to zero, from the last rows."""
    cf = np.polyfit(t[-4:] - t_star, c[-4:] ** 2, 2)
    roots = np.roots(cf).real
    return float(t_star + roots[np.argmin(np.abs(roots))])


def test_dead_centre_distance_seed_fourbar_toggle():
    """Zero at the seed four-bar's toggle t* = arccos((3^2 + 6^2 - 7.6^2)/36) - pi/3, falling
    like sqrt(t* - t); bounded away from zero over a Grashof crank's whole turn."""
    t_star = np.arccos((9 + 36 - 7.6**2) / 36) - np.pi / 3
    assert t_star == pytest.approx(0.88591864783, abs=1e-11)
    res = mbd2d.load(EX / "fourbar_seed.toml").kinematics(t_end=0.8859, steps=8859)
    c = res.dead_centre_distance()
    assert c[-1] < 2e-3 < 0.1 < c[0]
    assert np.all(np.diff(c[-2000:]) < 0)
    assert abs(_toggle_root(res.t, c, t_star) - t_star) < 1e-7
    # sqrt law: c / sqrt(t* - t) tends to a constant
    k = c[-50:] / np.sqrt(t_star - res.t[-50:])
    assert np.ptp(k) < 1e-2 * k.mean()
    grashof = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(t_end=1.0, steps=100)
    assert grashof.dead_centre_distance().min() > 0.1


SLIDER_DRIVEN = (EX / "slider_crank.toml").read_text().replace(
    """[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0.0, 6.283185307179586] }""",
    """[[driver]]
name = "cylinder"
type = "relative-distance"
joint = "guide"
f = { poly = [3.5, 1.0] }""").replace("q0 = [0.5, 0.0, 0.0]", "q0 = [0.45, 0.2, 0.45]")


def test_dead_centre_distance_slider_driven_slider_crank():
    """Driven at the slider, the offset slider-crank reaches its dead centre where crank and
    rod line up: x = sqrt((r + l)^2 - e^2), at t* = that - 3.5."""
    t_star = np.sqrt(16.0 - 0.25) - 3.5
    model = mbd2d.loads(SLIDER_DRIVEN)
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        model.kinematics(t_end=0.6, steps=600)
    assert info.value.t == pytest.approx(t_star, abs=1e-9)
    res = model.kinematics(t_end=0.4686, steps=4686)
    assert res.t[-1] < t_star
    c = res.dead_centre_distance()
    assert abs(_toggle_root(res.t, c, t_star) - t_star) < 1e-7
    # towards the dead centre the crank turns ever faster per unit slide (dtheta/dx =
    # 1 / (dx/dtheta)), and a torque on the crank balances an ever larger slider force: the
    # toggle press (mechanical advantage dtheta/dx -> infinity)
    th = res.body("crank").theta
    _, dx, _ = slider_x(th, 1.0, 3.0, 0.5)
    assert_allclose(res.velocity_ratio("cylinder", "crank.theta"), 1 / dx, rtol=1e-9)
    ma = res.mechanical_advantage("crank.theta", "cylinder")
    assert_allclose(ma, 1 / dx, rtol=1e-9)
    assert abs(ma[-1]) > 100 * abs(ma[0])


# --------------------------------------------------------------- what users get wrong
@pytest.mark.parametrize("call, match", [
    (lambda r: r.transmission_angle("guide"), "translational joint"),
    (lambda r: r.transmission_angle("nope"), "no joint 'nope'"),
    (lambda r: r.transmission_angle("O"), "no coupler"),
    (lambda r: r.transmission_angle("B", output="crank"), "output must be one of"),
    (lambda r: r.velocity_ratio("motor", "slider.z"), "no driver or coordinate"),
    (lambda r: r.velocity_ratio("motor", 3), "driver name or a coordinate name"),
    (lambda r: r.mechanical_advantage("motor", "slider.y"), "does not move"),
    (lambda r: r.velocity_ratio("crank.theta", "slider.x", via="rod.x"), "via must name"),
    (lambda r: r.point("rod", [0.0]), "s"),
])
def test_bad_requests_are_model_errors(slider, call, match):
    with pytest.raises(ModelError, match=match):
        call(slider)
