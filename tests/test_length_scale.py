"""The same mechanism in any unit of length (issue 9, item 7).

A model scaled by s (every point, size and position times s) must give the same angles, and
positions times s, whatever s: the core works in units of the model's length scale (a power
of 2, so the conversions are exact). References are closed forms computed here: the four-bar
by circle intersection, a pendulum on a rotational spring (theta0 cos(omega t)), and the root
of a bar's moment balance by bisection. Length scales outside [1e-12, 1e12] are a ModelError.
Before: the Grashof four-bar was off by 4e-11 (s = 1e-3), 6e-9 (1e-6), 1.1e-5 (1e-9); it
failed to assemble at s = 3e5 and 1e6 and reported a false dead centre at s = 1e9.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d

W = 2.0 * math.pi
# the Grashof crank-rocker of examples/fourbar_grashof.toml: ground 3, crank 1, coupler 3.5,
# rocker 2.5 (the largest joint point: 3, so the length scale is 3 s)
A_GROUND, A_CRANK, A_COUPLER, A_ROCKER = 3.0, 1.0, 3.5, 2.5
SCALES = [1e-12 / 3.0 * 1.01, 1e-9, 1e-6, 1e-3, 1.0, 1e3, 3e5, 1e6, 1e9, 1e12 / 3.0 * 0.99]


def fourbar(s: float, masses: bool = False) -> mbd2d.Model:
    """The crank-rocker with every length times s, the crank driven at 1 rev/s; q0 the rough
    estimates of the example, times s. With masses: uniform bars of length/s^2 kg (so that
    m (s L)^2, the moments of inertia and the motor torque do not depend on s), no gravity."""
    m = mbd2d.Model("crank-rocker", gravity=(0.0, 0.0))
    for name, length, q0 in (("crank", A_CRANK, (0.5, 0.0, 0.0)),
                             ("coupler", A_COUPLER, (2.25, 1.2, 0.78)),
                             ("rocker", A_ROCKER, (3.25, 1.2, -1.77))):
        mass = length / s**2 if masses else None
        m.add_body(name, (q0[0] * s, q0[1] * s, q0[2]), mass=mass,
                   inertia=None if mass is None else mass * (s * length)**2 / 12)
    m.add_revolute(["ground", "crank"], [[0.0, 0.0], [-0.5 * s, 0.0]], name="O2")
    m.add_revolute(["crank", "coupler"], [[0.5 * s, 0.0], [-1.75 * s, 0.0]], name="A")
    m.add_revolute(["coupler", "rocker"], [[1.75 * s, 0.0], [-1.25 * s, 0.0]], name="B")
    m.add_revolute(["rocker", "ground"], [[1.25 * s, 0.0], [3.0 * s, 0.0]], name="O4")
    m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [0.0, W]},
                 name="motor")
    return m


def fourbar_angles(th2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coupler and rocker angles by intersecting the circle of radius 3.5 about the crank
    pin A with the circle of radius 2.5 about the ground pivot (3, 0), on the branch of the
    example (the coupler-rocker joint above the line A-O4)."""
    ax, ay = A_CRANK * np.cos(th2), A_CRANK * np.sin(th2)
    dx, dy = A_GROUND - ax, -ay
    d = np.hypot(dx, dy)
    a = (A_COUPLER**2 - A_ROCKER**2 + d**2) / (2 * d)
    h = np.sqrt(A_COUPLER**2 - a**2)
    bx = ax + (a * dx - h * dy) / d
    by = ay + (a * dy + h * dx) / d
    coupler = np.arctan2(by - ay, bx - ax)
    rocker = np.arctan2(by, bx - A_GROUND) + math.pi     # the rocker points from B to O4
    return coupler, rocker


def wrap(a: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * a))


@pytest.mark.parametrize("s", SCALES)
def test_fourbar_kinematics_in_any_unit(s: float) -> None:
    res = fourbar(s).kinematics(1.0, 50)
    th2 = res.body("crank").theta
    coupler, rocker = fourbar_angles(th2)
    assert_allclose(th2, W * res.t, rtol=0, atol=1e-12)
    assert np.abs(wrap(res.body("coupler").theta - coupler)).max() < 1e-11
    assert np.abs(wrap(res.body("rocker").theta - rocker)).max() < 1e-11
    # positions are lengths: times s
    c = res.body("coupler")
    assert_allclose(c.x / s, np.cos(th2) + 1.75 * np.cos(coupler), rtol=0, atol=1e-11)
    assert_allclose(c.y / s, np.sin(th2) + 1.75 * np.sin(coupler), rtol=0, atol=1e-11)
    # and the angular velocities do not depend on s (the crank turns at 2 pi)
    ref = fourbar(1.0).kinematics(1.0, 50)
    assert_allclose(res.body("rocker").theta_dot, ref.body("rocker").theta_dot, rtol=0,
                    atol=1e-9)


@pytest.mark.parametrize("s, what", [(1e-12 / 3.0 * 0.99, "1.0E-12"),
                                     (1e12 / 3.0 * 1.01, "1.0E\\+12")])
def test_length_scale_outside_the_range_is_a_model_error(s: float, what: str) -> None:
    with pytest.raises(mbd2d.ModelError, match=f"length scale.*{what}") as info:
        fourbar(s).kinematics(1.0, 10)
    assert "O4" in info.value.entry          # the joint with the largest length


def spring_pendulum(s: float, theta0: float) -> mbd2d.Model:
    """A uniform bar (1 m times s) on a pivot at one end, with a rotational spring
    (k = 8 N m/rad, free at 0) and no gravity; mass 1/s^2 kg, so its inertia about the pivot,
    m (s L)^2 / 3 = 1/3, and the motion theta0 cos(omega t), omega^2 = 3 k, do not depend on
    s."""
    m = mbd2d.Model("spring-pendulum", gravity=(0.0, 0.0))
    mass = 1.0 / s**2
    half = 0.5 * s
    m.add_body("bar", (half * math.cos(theta0), half * math.sin(theta0), theta0), mass=mass,
               inertia=mass * s**2 / 12)
    m.add_revolute(["ground", "bar"], [[0.0, 0.0], [-half, 0.0]], name="pivot")
    m.add_rotational_spring(["ground", "bar"], stiffness=8.0)
    return m


@pytest.mark.parametrize("s", [2e-12, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1.9e12])
def test_dynamics_in_any_unit(s: float) -> None:
    """Generalized-alpha at a fixed step: the same steps at every scale, so the same angles to
    round-off, within the method's error of the closed form; dopri5 at a tight tolerance: the
    closed form to 1e-9 at every scale (its tolerance is relative to the length scale). The
    pivot force (the centre, s/2 from the pivot, accelerates with the bar; m = 1/s^2) goes
    as 1/s."""
    theta0, omega = 0.7, math.sqrt(24.0)
    ga = spring_pendulum(s, theta0).dynamics(2.0, 40, method="generalized-alpha", h=1e-3)
    ref = spring_pendulum(1.0, theta0).dynamics(2.0, 40, method="generalized-alpha", h=1e-3)
    th = ga.body("bar").theta
    assert np.abs(th - ref.body("bar").theta).max() < 1e-11
    exact = theta0 * np.cos(omega * ga.t)
    assert np.abs(th - exact).max() < 1e-4                            # O(h^2)
    assert_allclose(ga.body("bar").x / s, 0.5 * np.cos(th), rtol=0, atol=1e-11)
    thd = -theta0 * omega * np.sin(omega * ga.t)
    thdd = -omega**2 * exact
    fx = 0.5 * (-thdd * np.sin(exact) - thd**2 * np.cos(exact))      # times s
    fy = 0.5 * (thdd * np.cos(exact) - thd**2 * np.sin(exact))
    piv, pref = ga.reaction("pivot"), ref.reaction("pivot")
    assert_allclose(piv.fx_j * s, fx, rtol=0, atol=5e-3 * np.abs(fx).max())
    assert_allclose(piv.fy_j * s, fy, rtol=0, atol=5e-3 * np.abs(fy).max())
    # (the index-3 multipliers carry errors of order eps cond(iteration matrix) ~ eps / h^2,
    # issue 9 item 3: 1e-7 of the force at h = 1e-3, whatever the scale)
    assert_allclose(piv.fx_j * s, pref.fx_j, rtol=0, atol=1e-6 * np.abs(fx).max())
    dp = spring_pendulum(s, theta0).dynamics(2.0, 40, rtol=1e-11, atol=1e-13)
    th = dp.body("bar").theta
    assert np.abs(th - theta0 * np.cos(omega * dp.t)).max() < 1e-9
    assert_allclose(dp.body("bar").y / s, 0.5 * np.sin(th), rtol=0, atol=1e-11)


@pytest.mark.parametrize("s", [2e-12, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1.9e12])
def test_statics_in_any_unit(s: float) -> None:
    """A bar (2 / s^2 kg, s m) on a rotational spring (40 N m/rad, free at 1 rad) under gravity
    9.81 s: the weight's moment about the pivot, m g (s/2) cos(theta), does not depend on s, so
    neither does the equilibrium k (theta - 1) + 9.81 cos(theta) = 0 (bisection here)."""
    m = mbd2d.Model("bar", gravity=(0.0, -9.81 * s))
    mass = 2.0 / s**2
    m.add_body("bar", (0.5 * s, 0.0, 0.0), mass=mass, inertia=mass * s**2 / 12)
    m.add_revolute(["ground", "bar"], [[0.0, 0.0], [-0.5 * s, 0.0]], name="pivot")
    m.add_rotational_spring(["ground", "bar"], stiffness=40.0, angle0=1.0)

    def moment(th: float) -> float:
        return 40.0 * (th - 1.0) + 9.81 * math.cos(th)

    lo, hi = 0.0, 1.5
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if moment(mid) < 0 else (lo, mid)
    st = m.statics()
    x, y, th = st.body("bar")
    assert abs(th - lo) < 1e-13
    assert_allclose([x / s, y / s], [0.5 * math.cos(lo), 0.5 * math.sin(lo)], rtol=0,
                    atol=1e-13)
    r = st.reaction("pivot")                      # carries the weight, 2 * 9.81 / s
    assert_allclose([r.fx_j[0] * s, r.fy_j[0] * s], [0.0, 2.0 * 9.81], rtol=0, atol=1e-11)
    assert st.stability == "stable"


def test_inverse_dynamics_in_any_unit() -> None:
    """The driven four-bar with bars of length/s^2 kg: the motor torque and the moments of
    the joint reactions do not depend on s, the joint forces go as 1/s."""
    ref = fourbar(1.0, masses=True).inverse_dynamics(1.0, 20)
    tau = ref.effort("motor")
    for s in (1e-9, 1e-3, 1e3, 1e9):
        res = fourbar(s, masses=True).inverse_dynamics(1.0, 20)
        assert_allclose(res.effort("motor"), tau, rtol=0, atol=1e-9 * np.abs(tau).max())
        fb, fr = res.reaction("B"), ref.reaction("B")
        assert_allclose(fb.fx_j * s, fr.fx_j, rtol=0, atol=1e-9 * np.abs(fr.fx_j).max())
        assert_allclose(fb.mz_j, fr.mz_j, rtol=0, atol=1e-9 * np.abs(fr.mz_j).max())


@pytest.mark.parametrize("s", [1e-9, 1e6])
def test_stepper_and_dof_report_in_any_unit(s: float) -> None:
    """The step-by-step front door and the degrees-of-freedom report convert too."""
    m = fourbar(s)
    stepper = mbd2d.KinematicStepper(m)
    for t in np.linspace(0.02, 0.2, 10):
        q, qd, qdd = stepper.step(float(t))
    names = m.coordinate_names
    th2 = q[names.index("crank.theta")]
    coupler, rocker = fourbar_angles(np.array([th2]))
    assert abs(th2 - W * 0.2) < 1e-12
    assert abs(wrap(q[names.index("rocker.theta")] - rocker[0])) < 1e-11
    assert abs(q[names.index("coupler.x")] / s - (math.cos(th2) + 1.75 * math.cos(coupler[0]))) \
        < 1e-11
    rep = m.analyze_dof()
    assert rep.dof == 0 and rep.rank == 9


def test_mass_that_overflows_in_the_core_units_is_a_model_error() -> None:
    """Masses are multiplied by L^2 in the core: 1e290 kg on a 1e10 m bar would overflow, and is
    refused with a ModelError rather than ending in inf or NaN."""
    s = 1e10
    m = spring_pendulum(s, 0.3)
    m.bodies[0].mass = 1e290
    with pytest.raises(mbd2d.ModelError, match="too large for the model's length scale"):
        m.dynamics(1.0, 10)
