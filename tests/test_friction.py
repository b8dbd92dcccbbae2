"""Joint friction (issue 13): a block on an incline, a block pushed by a ramping force, a
pendulum with a rubbing pin, and the efforts of inverse dynamics, against closed forms and a
reduced model integrated with scipy (written here without mbd2d)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d

G = 9.81
M = 2.0


def incline(alpha: float, mu: float, mus: float, model: str = "stick-slip",
            v0: float = 0.0) -> mbd2d.Model:
    m = mbd2d.Model("incline")
    u = [math.cos(alpha), math.sin(alpha)]
    m.add_body("block", q0=[0.0, 0.0, 0.0], mass=M, inertia=0.1,
               v0=[v0 * u[0], v0 * u[1], 0.0])
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [u, u], name="slide",
                        friction={"mu": mu, "mu_static": mus, "model": model})
    return m


def slide_of(res, alpha):
    return res.q[:, 0] * math.cos(alpha) + res.q[:, 1] * math.sin(alpha)


@pytest.mark.parametrize("solver", ["dense", "banded"])
@pytest.mark.parametrize("alpha,mus", [(0.3, 0.35), (0.5, 0.6), (0.1, 0.2)])
def test_block_sticks_when_static_friction_holds(alpha, mus, solver):
    """mu_static > tan(alpha): the block does not move (displacement below 1e-9 m in 1 s);
    the friction force holds the weight's slope component M g sin(alpha)."""
    assert mus > math.tan(alpha)
    for method in ("dopri5", "partitioned"):
        res = incline(alpha, 0.8 * mus, mus).dynamics(1.0, 100, method=method, solver=solver)
        assert np.max(np.abs(slide_of(res, alpha))) < 1e-9
        fr = res.friction("slide")
        assert fr.stuck.all()
        np.testing.assert_allclose(fr.friction_force, M * G * math.sin(alpha), rtol=1e-9)
        np.testing.assert_allclose(fr.normal_load, M * G * math.cos(alpha), rtol=1e-9)


@pytest.mark.parametrize("alpha,mu,mus", [(0.3, 0.2, 0.25), (0.6, 0.3, 0.5), (0.4, 0.0, 0.0)])
@pytest.mark.parametrize("method", ["dopri5", "partitioned"])
def test_block_slides_with_the_coulomb_acceleration(alpha, mu, mus, method):
    """mu_static < tan(alpha): s(t) = -a t**2/2, a = g (sin(alpha) - mu cos(alpha))."""
    a = G * (math.sin(alpha) - mu * math.cos(alpha))
    for rtol in (1e-6, 1e-10):
        res = incline(alpha, mu, mus).dynamics(1.0, 50, method=method, rtol=rtol,
                                               atol=rtol * 1e-2)
        np.testing.assert_allclose(slide_of(res, alpha), -0.5 * a * res.t**2, atol=1e3 * rtol)
    fr = res.friction("slide")
    assert not fr.stuck[1:].any()
    np.testing.assert_allclose(fr.friction_force[1:], mu * M * G * math.cos(alpha), rtol=1e-9)


@pytest.mark.parametrize("method,opts", [("dopri5", {"rtol": 1e-10, "atol": 1e-12}),
                                         ("generalized-alpha", {"h": 1e-4}),
                                         ("baumgarte-rk4", {"h": 1e-4})])
def test_regularized_friction_slides_like_coulomb_above_the_threshold(method, opts):
    """The regularized law is mu beyond twice the threshold velocity: a block launched up
    the incline decelerates at g (sin + mu cos) until it turns, every method."""
    alpha, mu, v0 = 0.3, 0.2, 2.0
    res = incline(alpha, mu, 0.25, model="regularized", v0=v0).dynamics(0.5, 50, method=method,
                                                                          **opts)
    a = G * (math.sin(alpha) + mu * math.cos(alpha))
    t_stop = v0 / a
    keep = res.t < t_stop - 0.01
    np.testing.assert_allclose(slide_of(res, alpha)[keep], v0 * res.t[keep] - 0.5 * a *
                               res.t[keep]**2, atol=1e-6)


@pytest.mark.parametrize("solver", ["dense", "banded"])
@pytest.mark.parametrize("c", [10.0, 40.0])
def test_pushed_block_slips_when_the_force_reaches_the_static_limit(c, solver):
    """F = c t on a block on flat ground: stuck until c t* = mu_s M g, then
    M x'' = c t - mu M g. The slip is an event located to 1e-9 s."""
    mu, mus = 0.3, 0.5
    m = mbd2d.Model("push")
    m.add_body("block", q0=[0.0, 0.0, 0.0], mass=M, inertia=0.1)
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="slide",
                        friction={"mu": mu, "mu_static": mus, "model": "stick-slip"})
    m.add_point_force("block", [0.0, 0.0], fx={"poly": [0.0, c]}, name="push")
    ts = mus * M * G / c
    res = m.dynamics(2 * ts, 200, rtol=1e-10, atol=1e-12, solver=solver)
    [slip] = res.friction_events
    assert slip.kind == "slip" and slip.joint == "slide"
    assert slip.t == pytest.approx(ts, abs=1e-9)
    assert slip.force == pytest.approx(-mus * M * G, rel=1e-8)
    tt = np.maximum(res.t - ts, 0.0)
    ref = (c * tt**3 / 6 + (c * ts - mu * M * G) * tt**2 / 2) / M
    np.testing.assert_allclose(res.q[:, 0], ref, atol=1e-9)


@pytest.mark.parametrize("solver", ["dense", "banded"])
def test_pendulum_with_a_rubbing_pin_matches_the_reduced_model(solver):
    """A point mass on a rod, pin friction torque mu r |F| against the rotation, |F| the pin
    force (friction circle). Reference: l**2 m theta'' = -m g l sin(theta) - mu r |F|
    sign(theta'), |F| = |m a - m g| solved by fixed point in scipy's right-hand side; up to
    the first stop, which is a reversal since gravity beats static friction there."""
    mass, ell, r, mu, mus, th0 = 1.0, 0.5, 0.05, 0.3, 0.35, 1.0
    m = mbd2d.Model("pendulum")
    m.add_body("bob", q0=[ell * math.sin(th0), -ell * math.cos(th0), th0], mass=mass,
               inertia=0.0)
    m.add_revolute(["ground", "bob"], [[0, 0], [0, ell]], name="pin",
                   friction={"mu": mu, "mu_static": mus, "pin_radius": r,
                             "model": "stick-slip"})
    res = m.dynamics(1.2, 120, rtol=1e-11, atol=1e-13, solver=solver)
    first = res.friction_events[0]
    assert first.kind == "reversal"

    def rhs(t, y, sgn):
        th, w = y
        acc = -G / ell * math.sin(th)
        for _ in range(60):
            ax = ell * acc * math.cos(th) - ell * w * w * math.sin(th)   # P = l (sin, -cos)
            ay = ell * acc * math.sin(th) + ell * w * w * math.cos(th)
            f = math.hypot(mass * ax, mass * ay + mass * G)
            acc = (-mass * G * ell * math.sin(th) - mu * r * f * sgn) / (mass * ell**2)
        return [w, acc]

    stop = lambda t, y, sgn: y[1]                  # noqa: E731
    stop.terminal, stop.direction = True, 1
    sol = solve_ivp(rhs, [0, 2], [th0, 0.0], args=(-1.0,), method="DOP853", events=stop,
                    rtol=1e-12, atol=1e-14, dense_output=True)
    t_stop = sol.t_events[0][0]
    assert first.t == pytest.approx(t_stop, abs=1e-8)
    keep = res.t < t_stop
    np.testing.assert_allclose(res.body("bob").theta[keep], sol.sol(res.t[keep])[0], atol=1e-8)
    # and the energy falls by the friction work only
    e = res.kinetic + res.potential
    assert np.all(np.diff(e[keep]) <= 1e-9)


@pytest.mark.parametrize("solver", ["dense", "banded"])
def test_inverse_dynamics_efforts_include_friction(solver):
    """A block dragged at constant speed needs mu M g; with acceleration a, M a + mu M g; a
    rotor turning in a rubbing pin needs mu r M g."""
    mu = 0.3
    m = mbd2d.Model("drag")
    m.add_body("block", q0=[0.0, 0.0, 0.0], mass=M, inertia=0.1)
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="slide",
                        friction={"mu": mu, "mu_static": 0.4})
    m.add_driver("relative-distance", joint="slide", f={"poly": [0.0, 0.5, 0.5]}, name="pull")
    res = m.inverse_dynamics(1.0, 10, solver=solver)
    np.testing.assert_allclose(res.effort("pull"), M * 1.0 + mu * M * G, rtol=1e-9)
    r = mbd2d.Model("rotor")
    r.add_body("rotor", q0=[0.0, 0.0, 0.0], mass=3.0, inertia=0.2)
    r.add_revolute(["ground", "rotor"], [[0, 0], [0, 0]], name="pin",
                   friction={"mu": 0.2, "pin_radius": 0.01})
    r.add_driver("absolute", body="rotor", coordinate="theta", f={"poly": [0.0, 2.0]},
                 name="motor")
    res = r.inverse_dynamics(1.0, 10, solver=solver)
    np.testing.assert_allclose(res.effort("motor"), 0.2 * 0.01 * 3.0 * G, rtol=1e-9)
    np.testing.assert_allclose(res.friction("pin").moment, -0.2 * 0.01 * 3.0 * G, rtol=1e-9)


def test_methods_without_stick_slip_say_which_can():
    model = incline(0.3, 0.2, 0.25)
    for method, opts in (("generalized-alpha", {}), ("baumgarte-rk4", {"h": 1e-3})):
        with pytest.raises(mbd2d.ModelError, match="dopri5 and partitioned"):
            model.dynamics(1.0, 10, method=method, **opts)
    with pytest.raises(mbd2d.ModelError, match="statics does not carry friction.*slide"):
        model.statics()


@pytest.mark.parametrize("kw,match", [
    ({"friction": {"mu": 0.2}}, "needs pin_radius"),
    ({"friction": {"mu": -0.2, "pin_radius": 0.1}}, "must be >= 0"),
    ({"friction": {"mu": 0.2, "pin_radius": 0.1, "model": "sticky"}}, "friction.model"),
    ({"friction": {"mu": 0.3, "mu_static": 0.2, "pin_radius": 0.1, "model": "stick-slip"}},
     "mu_static >= mu"),
    ({"pin_radius": 0.1}, "give it with friction"),
    ({"friction": {"mu": 0.2, "pin_radius": 0.1}, "pin_radius": 0.1}, "pin_radius once"),
    ({"friction": {"mu": 0.2, "pin_radius": 0.0}}, "pin_radius must be positive"),
])
def test_bad_friction_is_a_model_error(kw, match):
    m = mbd2d.Model("bad")
    m.add_body("b", q0=[0, 0, 0], mass=1.0, inertia=1.0)
    with pytest.raises(mbd2d.ModelError, match=match):
        m.add_revolute(["ground", "b"], [[0, 0], [0, 0]], name="pin", **kw)


def test_friction_in_toml():
    text = """
[model]
name = "toml-slide"
gravity = [0.0, -9.81]
[[body]]
name = "block"
q0 = [0.0, 0.0, 0.0]
mass = 2.0
inertia = 0.1
[[joint]]
name = "slide"
type = "translational"
bodies = ["ground", "block"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[0.9553364891256060, 0.2955202066613396], [0.9553364891256060, 0.2955202066613396]]
friction = { mu = 0.2, mu_static = 0.25, model = "stick-slip" }
[[joint]]
name = "hinge"
type = "revolute"
bodies = ["ground", "wheel"]
points = [[1.0, 0.0], [0.0, 0.0]]
pin_radius = 0.02
friction = { mu = 0.1 }
[[body]]
name = "wheel"
q0 = [1.0, 0.0, 0.0]
mass = 1.0
inertia = 0.05
"""
    res = mbd2d.loads(text).dynamics(0.5, 10)
    a = G * (math.sin(0.3) - 0.2 * math.cos(0.3))
    np.testing.assert_allclose(slide_of(res, 0.3)[-1], -0.5 * a * 0.25, rtol=1e-6)
