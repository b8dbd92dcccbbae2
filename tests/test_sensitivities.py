"""Design sensitivities against independent references.

* Kinematics: central differences (Richardson-extrapolated) of closed forms written here:
  the four-bar by its loop solution for arbitrary pin coordinates (circle intersection for
  positions, the vector loop for rates), the offset slider-crank and the eccentric-cam lift.
* Inverse dynamics: the torque and pivot force of a driven pendulum in closed form.
* Statics: the torsion-spring pendulum's equilibrium k theta + m g a cos(theta) = 0, by
  implicit differentiation.
* Forward dynamics (dopri5): the pendulum's reduced equation and its variational equations
  integrated with scipy here; a free slider-crank against central differences of tight runs.
* with_params: the original model is unchanged and the new one equals the model built with
  the new value.
"""
from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, load_example, model_from_toml
from numpy.testing import assert_allclose

import mbd2d
from mbd2d.errors import ModelError, SingularConfigurationError

TWO_PI = 2.0 * np.pi
RTOL = 1e-8


def richardson(f, p0: float, h: float):
    """df/dp at p0: central differences with steps h and h/2, extrapolated (error O(h**4))."""
    d1 = (f(p0 + h) - f(p0 - h)) / (2 * h)
    d2 = (f(p0 + h / 2) - f(p0 - h / 2)) / h
    return (4 * d2 - d1) / 3


def rel_close(got: np.ndarray, want: np.ndarray, rtol: float = RTOL, what: str = "",
              floor: float = 0.0) -> None:
    """max |got - want| <= rtol max(max |want|, floor) (floor: the scale of a quantity whose
    derivative is zero)."""
    scale = max(float(np.abs(want).max()), floor)
    assert scale > 0, what
    err = float(np.abs(got - want).max()) / scale
    print(f"\n[sensitivity] {what:50s} relative error {err:.2e}", end="")
    assert err <= rtol, f"{what}: relative error {err:.3e}"


def rot(th: np.ndarray) -> np.ndarray:
    """A(theta) for an array of angles: (n, 2, 2)."""
    c, s = np.cos(th), np.sin(th)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def perp(v: np.ndarray) -> np.ndarray:
    return np.stack([-v[..., 1], v[..., 0]], -1)


# ====================================================================== four-bar

FOURBAR = {  # the example's pins (body frames; ground pivots global)
    "O2g": (0.0, 0.0), "O2c": (-0.5, 0.0), "Ac": (0.5, 0.0), "Ak": (-1.75, 0.0),
    "Bk": (1.75, 0.0), "Br": (-1.25, 0.0), "O4r": (1.25, 0.0), "O4g": (3.0, 0.0)}
#: the parameters and the pin coordinate each one is
FOURBAR_PARAMS = {"joint.A.points.0.0": ("Ac", 0), "joint.B.points.0.0": ("Bk", 0),
                  "joint.B.points.1.1": ("Br", 1), "joint.O4.points.1.0": ("O4g", 0)}


def fourbar_closed_form(t: np.ndarray, pins: dict, w2: float = TWO_PI) -> np.ndarray:
    """q, q_dot, q_ddot (3, n, 9) of the four-bar with the crank angle w2 t, for any pins.

    Positions: A from the crank; B on the circles |B - A| = |Bk - Ak| and
    |B - O4| = |Br - O4r|, on the left of A -> O4; each body's angle from its pin line.
    Rates: the loop u2 + u3 = u4 + (O4 - O2), u_i = A(theta_i) (pin difference), gives
    w2 perp(u2) + w3 perp(u3) = w4 perp(u4) and the same with al_i perp(u_i) - w_i**2 u_i.
    """
    P = {k: np.array(v) for k, v in pins.items()}
    th2 = w2 * t
    A2 = rot(th2)
    r2 = P["O2g"] - A2 @ P["O2c"]
    a_g = r2 + A2 @ P["Ac"]
    L3 = np.linalg.norm(P["Bk"] - P["Ak"])
    L4 = np.linalg.norm(P["Br"] - P["O4r"])
    D = P["O4g"] - a_g
    f = np.linalg.norm(D, axis=1)
    delta = np.arctan2(D[:, 1], D[:, 0])
    phi = delta + np.arccos((L3**2 + f**2 - L4**2) / (2 * L3 * f))
    B = a_g + L3 * np.stack([np.cos(phi), np.sin(phi)], -1)
    def turn(u, v):   # the angle that turns the body vector u onto the global vector v
        return np.arctan2(u[0] * v[..., 1] - u[1] * v[..., 0], u[0] * v[..., 0] + u[1] * v[..., 1])

    th3 = turn(P["Bk"] - P["Ak"], B - a_g)
    th4 = turn(P["Br"] - P["O4r"], B - P["O4g"])
    A3, A4 = rot(th3), rot(th4)
    r3 = a_g - A3 @ P["Ak"]
    r4 = P["O4g"] - A4 @ P["O4r"]
    u2 = A2 @ (P["Ac"] - P["O2c"])
    u3 = A3 @ (P["Bk"] - P["Ak"])
    u4 = A4 @ (P["Br"] - P["O4r"])

    def solve(rhs):   # x3 perp(u3) - x4 perp(u4) = rhs
        M = np.stack([perp(u3), -perp(u4)], -1)
        return np.linalg.solve(M, rhs[..., None])[..., 0]

    w = solve(-w2 * perp(u2))
    w3, w4 = w[:, 0], w[:, 1]
    al = solve(w2**2 * u2 + w3[:, None] ** 2 * u3 - w4[:, None] ** 2 * u4)
    al3, al4 = al[:, 0], al[:, 1]

    # velocities/accelerations of centres: r = pin - A s  ->  r_dot = pin_dot - w perp(A s)
    n = len(t)
    q = np.zeros((3, n, 9))
    s2, s3, s4 = A2 @ P["O2c"], A3 @ P["Ak"], A4 @ P["O4r"]
    a_v = -w2 * perp(s2) + w2 * perp(A2 @ P["Ac"])
    a_a = -w2**2 * (A2 @ P["Ac"]) + w2**2 * s2
    for k, (r, th_, w_, al_, rv, ra) in enumerate([
            (r2, th2, np.full(n, w2), np.zeros(n), w2 * perp(s2) * -1.0, w2**2 * s2),
            (r3, th3, w3, al3, a_v - w3[:, None] * perp(s3),
             a_a - al3[:, None] * perp(s3) + w3[:, None] ** 2 * s3),
            (r4, th4, w4, al4, -w4[:, None] * perp(A4 @ P["O4r"]),
             -al4[:, None] * perp(A4 @ P["O4r"]) + w4[:, None] ** 2 * (A4 @ P["O4r"]))]):
        q[0, :, 3 * k:3 * k + 2] = r
        q[0, :, 3 * k + 2] = th_
        q[1, :, 3 * k:3 * k + 2] = rv
        q[1, :, 3 * k + 2] = w_
        q[2, :, 3 * k:3 * k + 2] = ra
        q[2, :, 3 * k + 2] = al_
    return q


def test_fourbar_closed_form_matches_the_engine():
    """The oracle itself: its positions, rates match a run of the unperturbed example."""
    res = load_example("fourbar_grashof.toml").kinematics(1.0, 40)
    cf = fourbar_closed_form(res.t, FOURBAR)
    for k, arr in enumerate([res.q, res.qd, res.qdd]):
        assert_allclose(arr, cf[k], atol=1e-9 * max(1.0, np.abs(cf[k]).max()))


def test_fourbar_sensitivities_against_the_closed_form():
    m = load_example("fourbar_grashof.toml")
    names = list(FOURBAR_PARAMS)
    res = m.kinematics(1.0, 40, sensitivities=names)
    assert res.dq_dp.shape == (41, 9, 4) and res.parameter_names == names
    for j, name in enumerate(names):
        pin, c = FOURBAR_PARAMS[name]

        def cf(v):
            pins = dict(FOURBAR)
            xy = list(pins[pin])
            xy[c] = v
            pins[pin] = tuple(xy)
            return fourbar_closed_form(res.t, pins)

        want = richardson(cf, FOURBAR[pin][c], 1e-3)
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            rel_close(got[:, :, j], want[k], what=f"four-bar d{['q', 'qd', 'qdd'][k]}/d {name}")
    # per-body view
    rk = res.sensitivity("rocker", names[1], of="qd")
    assert_allclose(rk, res.dqd_dp[:, 6:9, 1], rtol=0, atol=0)


# ====================================================================== slider-crank

def slider_x(theta: np.ndarray, r: float, L: float, e: float, w: float) -> np.ndarray:
    """x, x_dot, x_ddot of the slider pin: x = r cos th + sqrt(L**2 - (r sin th - e)**2),
    th = w t (w constant), s = r sin th - e, D = sqrt(L**2 - s**2)."""
    s, c = np.sin(theta), np.cos(theta)
    sv = r * s - e
    D = np.sqrt(L**2 - sv**2)
    sd = r * c * w
    sdd = -r * s * w**2
    x = r * c + D
    xd = -r * s * w - sv * sd / D
    xdd = -r * c * w**2 - (sd**2 + sv * sdd) / D - sv**2 * sd**2 / D**3
    return np.stack([x, xd, xdd])


def test_slider_crank_sensitivities_against_the_closed_form():
    m = load_example("slider_crank.toml")
    names = ["joint.A.points.0.0", "joint.B.points.0.0", "joint.guide.points.0.1",
             "driver.motor.f.poly.1"]
    res = m.kinematics(1.0, 40, sensitivities=names)
    th = TWO_PI * res.t
    base = dict(r=1.0, L=3.0, e=0.5, w=TWO_PI)
    keys = ["r", "L", "e", "w"]
    for j, (name, key) in enumerate(zip(names, keys)):
        def cf(v):
            kw = dict(base)
            kw[key] = v
            return slider_x(kw["w"] * res.t, **kw)

        want = richardson(cf, base[key], 1e-3)
        sl = res.body("slider")
        assert_allclose(sl.x, slider_x(th, **base)[0], atol=1e-10)
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            rel_close(got[:, 6, j], want[k], what=f"slider-crank d x_slider^({k}) / d {name}")


# ====================================================================== cam

def cam_lift(theta: np.ndarray, e: float, R: float, r: float, w: float) -> np.ndarray:
    """y, y_dot, y_ddot of the roller follower: y = e sin th + D, D = sqrt(K - e**2 c**2),
    K = (R + r)**2; dy/dth = e c + e**2 c s / D,
    d2y/dth2 = -e s + e**2 (c**2 - s**2) / D - e**4 c**2 s**2 / D**3."""
    s, c = np.sin(theta), np.cos(theta)
    D = np.sqrt((R + r) ** 2 - e**2 * c**2)
    y1 = e * c + e**2 * c * s / D
    y2 = -e * s + e**2 * (c**2 - s**2) / D - e**4 * c**2 * s**2 / D**3
    return np.stack([e * s + D, w * y1, w**2 * y2])


def test_cam_lift_sensitivities_against_the_closed_form():
    m = load_example("cam_follower.toml")
    names = ["joint.contact.profile.circle.center.0", "joint.contact.profile.circle.radius",
             "joint.contact.follower.roller.radius"]
    res = m.kinematics(1.0, 40, sensitivities=names)
    base = dict(e=0.4, R=1.0, r=0.25, w=TWO_PI)
    for j, (name, key) in enumerate(zip(names, ["e", "R", "r"])):
        def cf(v):
            kw = dict(base)
            kw[key] = v
            return cam_lift(TWO_PI * res.t, **kw)

        want = richardson(cf, base[key], 1e-3)
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            rel_close(got[:, 4, j], want[k], what=f"cam d y^({k}) / d {name}")


def test_cam_with_hundreds_of_harmonics_against_differences():
    """A Fourier cam with 230 harmonics (the last one 1e-9, its fourth derivative k**4 a_k
    about 2.8): the roller's contact curve needs the profile's fourth derivative in the
    design sensitivities, whose k**4 overflowed a default integer past k = 215 (found by
    UBSan on a fuzz case) and flipped the term's sign; the sensitivities to the roller
    radius and to the profile's centre match Richardson-extrapolated central differences of
    with_params runs."""
    K = 230
    a = [1.0, 0.1] + [0.0] * (K - 2) + [1e-9]
    b = [0.05] + [0.0] * (K - 1)
    text = (ROOT / "examples" / "cam_follower.toml").read_text().replace(
        "profile = { circle = { center = [0.4, 0.0], radius = 1.0 } }",
        f"profile = {{ fourier = {{ center = [0.1, 0.0], a = {a}, b = {b} }} }}")
    m = mbd2d.loads(text)
    names = ["joint.contact.follower.roller.radius", "joint.contact.profile.fourier.center.0"]
    res = m.kinematics(1.0, 40, sensitivities=names, tol=1e-14)
    for j, name in enumerate(names):
        v = m.parameters()[name]

        def run(x):
            r = m.with_params({name: x}).kinematics(1.0, 40, tol=1e-14)
            return np.stack([r.q, r.qd, r.qdd])

        want = richardson(run, v, 1e-4)
        for k, got in enumerate([res.dq_dp, res.dqd_dp, res.dqdd_dp]):
            rel_close(got[:, :, j], want[k], rtol=1e-7,
                      what=f"230-harmonic cam d q^({k}) / d {name}")


# ====================================================================== pendulum

PENDULUM = """
[model]
name = "driven-pendulum"
gravity = [0.0, {gy}]
[[body]]
name = "bar"
q0 = [{a}, 0.0, 0.0]
mass = {m}
inertia = {J}
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "bar"]
points = [[0.0, 0.0], [{sx}, 0.0]]
[[driver]]
name = "motor"
type = "absolute"
body = "bar"
coordinate = "theta"
f = {{ poly = [0.3, {w}], harmonic = [{{ amplitude = {A}, omega = 3.0 }}] }}
"""
PEND = dict(m=1.3, J=0.07, a=0.45, gy=-9.81, w=2.0, A=0.4)


def pendulum_torque(t: np.ndarray, m: float, J: float, a: float, gy: float, w: float,
                    A: float) -> np.ndarray:
    """Driver torque and the pivot force on the bar, rows (tau, fx, fy).

    theta = 0.3 + w t + A sin 3t about the pivot (origin), centre at a (cos, sin)(theta):
    tau = (J + m a**2) theta_dd - m gy a cos(theta);  F = m (a_centre - g)."""
    th = 0.3 + w * t + A * np.sin(3 * t)
    thd = w + 3 * A * np.cos(3 * t)
    thdd = -9 * A * np.sin(3 * t)
    tau = (J + m * a**2) * thdd - m * gy * a * np.cos(th)
    ax = a * (-np.sin(th) * thdd - np.cos(th) * thd**2)
    ay = a * (np.cos(th) * thdd - np.sin(th) * thd**2)
    return np.stack([tau, m * ax, m * (ay - gy)])


def test_inverse_dynamics_effort_and_reaction_sensitivities():
    kw = dict(PEND)
    m = model_from_toml(PENDULUM.format(sx=-kw["a"], **kw))
    names = ["body.bar.mass", "body.bar.inertia", "joint.pivot.points.1.0", "model.gravity.1",
             "driver.motor.f.poly.1", "driver.motor.f.harmonic.0.amplitude"]
    keys = ["m", "J", "a", "gy", "w", "A"]
    res = m.inverse_dynamics(2.0, 40, sensitivities=names)
    assert_allclose(res.effort("motor"), pendulum_torque(res.t, **PEND)[0], rtol=0, atol=1e-10)
    tau_p = res.effort_dp("motor")
    reac = res.reaction_dp("pivot")
    assert tau_p.shape == (41, 6)
    for j, (name, key) in enumerate(zip(names, keys)):
        sign = -1.0 if key == "a" else 1.0       # the parameter is the pin x = -a

        def cf(v):
            p = dict(PEND)
            p[key] = v
            return pendulum_torque(res.t, **p)

        want = sign * richardson(cf, PEND[key], 1e-3)
        rel_close(tau_p[:, j], want[0], what=f"pendulum d tau / d {name}")
        rel_close(np.column_stack([reac.fx_j[:, j], reac.fy_j[:, j]]), want[1:].T,
                  what=f"pendulum d F_pivot / d {name}", floor=PEND["m"] * 9.81)


def test_statics_sensitivities_against_implicit_differentiation():
    """k theta + m g a cos(theta) = 0 (g = 9.81 down): dtheta/dp = -F_p / F_theta."""
    m = load_example("pendulum_spring.toml")
    names = ["force.torsion.stiffness", "body.bar.mass", "model.gravity.1",
             "joint.pivot.points.1.0", "force.torsion.angle0"]
    eq = m.statics(sensitivities=names)
    th = eq.q[2]
    k, mass, g, a = 10.0, 1.0, 9.81, 0.5
    Ft = k - mass * g * a * np.sin(th)
    # F = k (theta - theta0) - m gy a cos(theta), gy = -g; pin x = -a
    dth = {"force.torsion.stiffness": -th / Ft,
           "body.bar.mass": -(g * a * np.cos(th)) / Ft,
           "model.gravity.1": (mass * a * np.cos(th)) / Ft,
           "joint.pivot.points.1.0": (mass * g * np.cos(th)) / Ft,
           "force.torsion.angle0": k / Ft}
    assert abs(k * th + mass * g * a * np.cos(th)) < 1e-10
    for name in names:
        got = eq.sensitivity("bar", name)
        # centre (a cos th, a sin th): its derivative through theta and (for the pin) a
        da = -1.0 if name == "joint.pivot.points.1.0" else 0.0
        want = np.array([-a * np.sin(th) * dth[name] + np.cos(th) * da,
                         a * np.cos(th) * dth[name] + np.sin(th) * da, dth[name]])
        assert_allclose(got, want, rtol=1e-10, atol=1e-12, err_msg=name)


# ====================================================================== forward dynamics

SWING = """
[model]
name = "swing"
gravity = [0.0, -9.81]
[[body]]
name = "bar"
q0 = [0.4, 0.0, 0.0]
mass = 1.3
inertia = 0.07
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "bar"]
points = [[0.0, 0.0], [-0.4, 0.0]]
[[force]]
name = "torsion"
type = "rotational-spring"
bodies = ["ground", "bar"]
stiffness = 6.0
damping = 0.3
angle0 = 0.2
"""


def swing_reference(t: np.ndarray, names: list[str]) -> np.ndarray:
    """theta and dtheta/dp of the swing by scipy: I theta'' = -k (theta - th0) - c theta' -
    m g a cos(theta), I = J + m a**2, with the variational equations
    S'' = f_theta S + f_thd S' + f_p (theta(0) = 0, theta'(0) = 0 for every parameter)."""
    from scipy.integrate import solve_ivp
    m, J, a, g, k, c, th0 = 1.3, 0.07, 0.4, 9.81, 6.0, 0.3, 0.2

    def rhs(_t, y):
        th, thd = y[0], y[1]
        inertia = J + m * a**2
        acc = (-k * (th - th0) - c * thd - m * g * a * np.cos(th)) / inertia
        f_th = (-k + m * g * a * np.sin(th)) / inertia
        f_thd = -c / inertia
        fp = {"force.torsion.stiffness": -(th - th0) / inertia,
              "force.torsion.damping": -thd / inertia,
              "body.bar.mass": (-g * a * np.cos(th) - acc * a**2) / inertia,
              "body.bar.inertia": -acc / inertia,
              "model.gravity.1": m * a * np.cos(th) / inertia}
        out = [thd, acc]
        for i, name in enumerate(names):
            s, sd = y[2 + 2 * i], y[3 + 2 * i]
            out += [sd, f_th * s + f_thd * sd + fp[name]]
        return out

    sol = solve_ivp(rhs, (t[0], t[-1]), np.zeros(2 + 2 * len(names)), method="DOP853",
                    t_eval=t, rtol=1e-13, atol=1e-13)
    return sol.y


def test_dopri5_sensitivities_against_scipy_reference():
    names = ["force.torsion.stiffness", "force.torsion.damping", "body.bar.mass",
             "body.bar.inertia", "model.gravity.1"]
    m = model_from_toml(SWING)
    errs = []
    for tol in (1e-6, 1e-8, 1e-10):
        res = m.dynamics(2.0, 20, rtol=tol, atol=tol, sensitivities=names)
        ref = swing_reference(res.t, names)
        assert_allclose(res.q[:, 2], ref[0], atol=100 * tol)
        err = max(float(np.abs(res.dq_dp[:, 2, i] - ref[2 + 2 * i]).max()) /
                  float(np.abs(ref[2 + 2 * i]).max()) for i in range(len(names)))
        errs.append(err)
        print(f"\n[sensitivity] dopri5 swing tol {tol:.0e}: worst relative error {err:.2e}",
              end="")
    assert errs[-1] <= 1e-8
    assert errs[0] > 30 * errs[1] > 30 * 30 * errs[2] or errs[2] < 1e-10


def test_dopri5_sensitivity_outputs_take_the_accelerations_at_the_state():
    """The accelerations and their sensitivities at the outputs (q_ddot, dq_ddot/dp) come
    from the index-1 equations at the interpolated output state, as a plain run's q_ddot
    (not from an interpolant of the accelerations, about 100x less accurate). Reference: the
    swing's scipy solution at 1e-13, its theta'' = f(theta, theta') and
    S'' = f_theta S + f_theta' S' + f_p there. The errors fall with the tolerance and stay
    within 10x the worst error of (theta, theta') and of (dtheta/dp, dtheta'/dp): measured
    5.9-6.4x at rtol = atol = 1e-7 and 1e-9, against 26-170x when the outputs took the
    interpolant of the accelerations (which fails here); q_ddot as accurate as a plain
    run's (0.54-0.56 of its error)."""
    from scipy.integrate import solve_ivp  # noqa: F401  (swing_reference needs scipy)
    names = ["force.torsion.stiffness", "body.bar.mass", "model.gravity.1"]
    m = model_from_toml(SWING)
    mass, J, a, g, k, c, th0 = 1.3, 0.07, 0.4, 9.81, 6.0, 0.3, 0.2
    inertia = J + mass * a**2
    last = None
    for tol in (1e-7, 1e-9):
        res = m.dynamics(2.0, 20, rtol=tol, atol=tol, sensitivities=names)
        ref = swing_reference(res.t, names)
        th, thd = ref[0], ref[1]
        acc = (-k * (th - th0) - c * thd - mass * g * a * np.cos(th)) / inertia
        f_th = (-k + mass * g * a * np.sin(th)) / inertia
        fp = {"force.torsion.stiffness": -(th - th0) / inertia,
              "body.bar.mass": (-g * a * np.cos(th) - acc * a**2) / inertia,
              "model.gravity.1": mass * a * np.cos(th) / inertia}
        e_q = float(np.abs(res.q[:, 2] - th).max())
        e_a = float(np.abs(res.qdd[:, 2] - acc).max())
        assert e_a <= 10 * max(e_q, float(np.abs(res.qd[:, 2] - thd).max())), (tol, e_a, e_q)
        errs = []
        for i, name in enumerate(names):
            s, sd = ref[2 + 2 * i], ref[3 + 2 * i]
            sdd = f_th * s - c / inertia * sd + fp[name]
            e_s = float(np.abs(res.dq_dp[:, 2, i] - s).max())
            e_sd = float(np.abs(res.dqd_dp[:, 2, i] - sd).max())
            e_sdd = float(np.abs(res.dqdd_dp[:, 2, i] - sdd).max())
            assert e_sdd <= 10 * max(e_s, e_sd) + 1e-12, (tol, name, e_sdd, e_s, e_sd)
            errs.append(e_sdd)
        print(f"\n[sensitivity] swing outputs tol {tol:.0e}: q_ddot error {e_a:.1e} (theta "
              f"{e_q:.1e}), worst dq_ddot/dp error {max(errs):.1e}", end="")
        if last is not None:
            assert e_a < last[0] / 10 and max(errs) < last[1] / 10
        last = (e_a, max(errs))


def free_slider_crank() -> mbd2d.Model:
    """The slider-crank example without its driver, with masses and a spring from ground to
    the slider (stiffness 40, damping 3, free length 2), under gravity."""
    m = load_example("slider_crank.toml")
    m.drivers.clear()
    for b, (ms, J) in zip(m.bodies, [(2.0, 0.3), (1.5, 1.1), (0.8, 0.05)]):
        b.mass, b.inertia = ms, J
    m.add_spring(["ground", "slider"], [[0.0, 0.5], [0.0, 0.0]], stiffness=40.0, damping=3.0,
                 length0=2.0, name="s1")
    return m


def add_force_kinds(m: mbd2d.Model) -> mbd2d.Model:
    """m with a spring-damper-actuator between the crank and the rod (s2), a torque on the
    crank (t1) and a point force on the rod (p1)."""
    m.add_spring(["crank", "rod"], [[0.3, 0.1], [-0.2, 0.15]], stiffness=25.0, damping=1.5,
                 length0=0.5, f={"poly": [1.0, 0.5]}, name="s2")
    m.add_torque("crank", {"poly": [0.3, -0.2]}, name="t1")
    m.add_point_force("rod", [0.4, 0.05], fx={"poly": [0.5]}, fy={"poly": [0.0, 1.0]},
                      name="p1")
    return m


def test_dopri5_sensitivities_against_central_differences():
    """A free slider-crank under gravity with a spring: parameters that leave the assembled
    start alone, central differences of runs at rtol = atol = 1e-12."""
    m = free_slider_crank()
    names = ["force.s1.stiffness", "body.rod.mass", "body.crank.inertia", "model.gravity.1"]
    res = m.dynamics(1.0, 10, rtol=1e-11, atol=1e-11, sensitivities=names)
    h = 1e-5
    for j, name in enumerate(names):
        v = m.parameters()[name]
        up = m.with_params({name: v + h}).dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
        dn = m.with_params({name: v - h}).dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
        fd = (up.q - dn.q) / (2 * h)
        rel_close(res.dq_dp[:, :, j], fd, rtol=2e-6, what=f"free slider-crank dq / d {name}")


def richardson_dq_dp(m: mbd2d.Model, name: str, h: float = 1e-4) -> np.ndarray:
    """dq/dp of a 1 s dopri5 run (10 outputs) from plain runs at rtol = atol = 1e-12: central
    differences at h and 2h, Richardson-extrapolated (4 D(h) - D(2h)) / 3."""
    v = m.parameters()[name]

    def central(hh: float) -> np.ndarray:
        up = m.with_params({name: v + hh}).dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
        dn = m.with_params({name: v - hh}).dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
        return (up.q - dn.q) / (2 * hh)

    return (4 * central(h) - central(2 * h)) / 3


def test_dopri5_sensitivities_of_pin_coordinates():
    """Geometric parameters enter Phi: their forward-dynamics sensitivities start from the
    minimum-norm change of the assembled q (J S = -Phi_p) and the kinetic-energy-nearest one
    of q_dot, and every step projects S onto J S = -Phi_p. A start given exactly consistent
    (the assembled q0 and projected v0 of a first run) makes the perturbed runs' own
    assembly and projection take those same changes to first order, so central differences
    of plain runs (Richardson, h and h/2) are an independent reference. Measured 1.8e-10 to
    1.3e-9; the projection's Phi_p term with its sign flipped fails it (relative error 2)."""
    m = free_slider_crank()
    start = m.dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
    for k, b in enumerate(m.bodies):
        b.q0 = [float(x) for x in start.q[0, 3 * k:3 * k + 3]]
        b.v0 = [float(x) for x in start.qd[0, 3 * k:3 * k + 3]]
    names = ["joint.O.points.0.0", "joint.A.points.0.1", "joint.B.points.1.0"]
    res = m.dynamics(1.0, 10, rtol=1e-11, atol=1e-11, sensitivities=names)
    for j, name in enumerate(names):
        ref = richardson_dq_dp(m, name)
        rel_close(res.dq_dp[:, :, j], ref, rtol=1e-8, what=f"free slider-crank dq / d {name}")


def test_dopri5_sensitivities_of_force_parameters():
    """Every kind of applied force's parameters through the dual-number force derivatives:
    a spring-damper-actuator between two moving bodies (its points on both, damping, free
    length, the actuator's slope), a torque's constant and a point force's point and slope,
    on the free slider-crank. They leave the assembled start alone; reference: Richardson
    central differences of plain runs at rtol 1e-12 (h = 1e-4, 2e-4). Measured 4.3e-11 to
    3.8e-8 relative to each sensitivity's largest entry (the larger ones where the
    sensitivity is small, about 3e-3: the differences' own noise)."""
    m = add_force_kinds(free_slider_crank())
    names = ["force.s2.points.0.0", "force.s2.points.1.1", "force.s2.damping",
             "force.s2.length0", "force.s2.f.poly.1", "force.t1.f.poly.0", "force.p1.point.0",
             "force.p1.fy.poly.1"]
    res = m.dynamics(1.0, 10, rtol=1e-11, atol=1e-11, sensitivities=names)
    for j, name in enumerate(names):
        ref = richardson_dq_dp(m, name)
        assert np.abs(ref).max() > 1e-3, name          # each parameter moves the motion
        rel_close(res.dq_dp[:, :, j], ref, rtol=2e-7, what=f"free slider-crank dq / d {name}")


# ====================================================================== parameters by name

def test_parameter_names_and_values():
    m = load_example("fourbar_grashof.toml")
    p = m.parameters()
    assert p["joint.A.points.1.0"] == -1.75 and p["joint.O4.points.1.0"] == 3.0
    assert p["driver.motor.f.poly.1"] == TWO_PI and p["model.gravity.1"] == -9.81
    cam = load_example("cam_follower.toml").parameters()
    assert cam["joint.contact.profile.circle.radius"] == 1.0
    assert cam["joint.guide.axes.0.1"] == 1.0
    spring = load_example("pendulum_spring.toml").parameters()
    assert spring["force.torsion.stiffness"] == 10.0 and spring["body.bar.mass"] == 1.0


def test_builder_models_get_the_same_names():
    m = mbd2d.Model("built")
    m.add_body("bar", q0=[0.5, 0.0, 0.0], mass=1.0, inertia=0.1)
    m.add_revolute(["ground", "bar"], [[0.0, 0.0], [-0.5, 0.0]])
    m.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0.0, 1.0]})
    names = set(m.parameters())
    assert {"joint.joint1.points.1.0", "driver.driver1.f.poly.1", "body.bar.mass",
            "body.bar.inertia", "model.gravity.0"} <= names


def test_with_params_leaves_the_model_and_equals_a_rebuilt_one():
    m = load_example("fourbar_grashof.toml")
    before = m.parameters()
    m2 = m.with_params({"joint.B.points.0.0": 1.8, "joint.B.points.1.0": -1.2})
    assert m.parameters() == before
    text = (load_example.__globals__["example_path"]("fourbar_grashof.toml")
            .read_text().replace("[1.75, 0.0], [-1.25, 0.0]", "[1.8, 0.0], [-1.2, 0.0]"))
    rebuilt = model_from_toml(text)
    a, b = m2.kinematics(1.0, 20), rebuilt.kinematics(1.0, 20)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.qdd, b.qdd)
    assert not np.array_equal(a.q, m.kinematics(1.0, 20).q)


def test_unknown_names_are_model_errors_with_suggestions():
    m = load_example("fourbar_grashof.toml")
    with pytest.raises(ModelError, match=r"'joint\.B\.point\.0\.0'.*did you mean "
                                         r"joint\.B\.points\.0\.0"):
        m.kinematics(1.0, 4, sensitivities=["joint.B.point.0.0"])
    with pytest.raises(ModelError, match="unknown parameter 'body.crank.mas'"):
        m.with_params({"body.crank.mas": 1.0})
    with pytest.raises(ModelError, match="finite"):
        m.with_params({"joint.B.points.0.0": float("nan")})
    with pytest.raises(ModelError, match="names no parameter"):
        m.kinematics(1.0, 4, sensitivities=[])
    with pytest.raises(ModelError, match="list of names"):
        m.kinematics(1.0, 4, sensitivities="joint.B.points.0.0")
    for bad in (5, 2.5):                       # (a raw TypeError before)
        with pytest.raises(ModelError, match="list of names, got"):
            m.kinematics(1.0, 4, sensitivities=bad)
    res = m.kinematics(1.0, 4, sensitivities=["joint.B.points.0.0"])
    with pytest.raises(KeyError, match="no sensitivity with respect to 'joint.A.points.0.0'"):
        res.sensitivity("coupler", "joint.A.points.0.0")


def test_sensitivities_need_dopri5_or_generalized_alpha():
    m = model_from_toml(SWING)
    for method in ("baumgarte-rk4", "partitioned"):
        with pytest.raises(ModelError, match="dopri5.*or generalized-alpha.*has none"):
            m.dynamics(1.0, 10, method=method, h=1e-3 if method == "baumgarte-rk4" else None,
                       sensitivities=["body.bar.mass"])


def test_dead_centre_keeps_the_sensitivities_up_to_it():
    """A non-Grashof four-bar driven into its dead centre: the error carries the results
    with their (growing, finite) sensitivities."""
    m = load_example("fourbar_grashof.toml").with_params({"joint.O4.points.1.0": 5.5})
    with pytest.raises(SingularConfigurationError) as err:
        m.kinematics(1.0, 100, sensitivities=["joint.B.points.0.0"])
    res = err.value.results
    assert res.dq_dp is not None and res.dq_dp.shape[0] == len(res.t) > 2
    assert np.all(np.isfinite(res.dq_dp))
    growth = np.abs(res.dq_dp[:, 8, 0])
    assert growth[-1] > 10 * growth[0]


def test_sensitivities_do_not_depend_on_the_length_unit():
    """The same four-bar in metres and in millimetres (the core works in units of the model's
    length scale): d(x, y)/d(length) is unit-free, d(theta)/d(length) scales as 1/unit, and
    d/d(mass) of an effort scales like the effort."""
    def build(s: float) -> mbd2d.Model:
        m = mbd2d.Model("four-bar", gravity=(0.0, -9.81 * s))
        for name, q0 in (("crank", [0.5, 0.0, 0.0]), ("coupler", [2.25, 1.2, 0.78]),
                         ("rocker", [3.25, 1.2, -1.77])):
            m.add_body(name, q0=[q0[0] * s, q0[1] * s, q0[2]], mass=2.0, inertia=0.1 * s * s)
        for name, bodies, pts in (("O2", ["ground", "crank"], [[0, 0], [-0.5, 0]]),
                                  ("A", ["crank", "coupler"], [[0.5, 0], [-1.75, 0]]),
                                  ("B", ["coupler", "rocker"], [[1.75, 0], [-1.25, 0]]),
                                  ("O4", ["rocker", "ground"], [[1.25, 0], [3.0, 0]])):
            m.add_revolute(bodies, [[p[0] * s, p[1] * s] for p in pts], name=name)
        m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [0.0, TWO_PI]},
                     name="motor")
        return m

    names = ["joint.B.points.0.0", "body.coupler.mass"]
    a = build(1.0).inverse_dynamics(1.0, 20, sensitivities=names)
    b = build(1000.0).inverse_dynamics(1.0, 20, sensitivities=names)
    xy = [c for c in range(9) if c % 3 != 2]
    th = [2, 5, 8]
    assert_allclose(b.dq_dp[:, xy, 0], a.dq_dp[:, xy, 0], rtol=1e-9, atol=1e-12)
    assert_allclose(b.dq_dp[:, th, 0] * 1000.0, a.dq_dp[:, th, 0], rtol=1e-9, atol=1e-12)
    # torque ~ m g L and m L^2 w^2: scales by 1000**2 with lengths, gravity and inertia
    assert_allclose(b.effort_dp("motor")[:, 1], 1e6 * a.effort_dp("motor")[:, 1], rtol=1e-9)
    assert_allclose(b.effort_dp("motor")[:, 0], 1e3 * a.effort_dp("motor")[:, 0], rtol=1e-9)


def _richardson_runs(m: mbd2d.Model, name: str, run, d: float = 1e-3) -> list[np.ndarray]:
    """d(q, q_dot)/dp from plain runs: central differences at d and 2d (relative to
    max(1, |p|)), Richardson-extrapolated."""
    v = m.parameters()[name]
    step = d * max(1.0, abs(v))

    def central(hh: float) -> list[np.ndarray]:
        up, dn = run(m.with_params({name: v + hh})), run(m.with_params({name: v - hh}))
        return [(up.q - dn.q) / (2 * hh), (up.qd - dn.qd) / (2 * hh)]

    c1, c2 = central(step), central(2 * step)
    return [(4 * a - b) / 3 for a, b in zip(c1, c2)]


def free_cam() -> mbd2d.Model:
    """The eccentric cam example without its motor: the cam (2 kg, on its pivot) spun to
    6 rad/s, the follower (0.5 kg) on it under gravity; the cam joint's contact coordinate
    has no mass (the projection's metric takes the mean mass there)."""
    m = load_example("cam_follower.toml")
    m.drivers.clear()
    m.bodies[0].mass, m.bodies[0].inertia = 2.0, 0.5
    m.bodies[1].mass, m.bodies[1].inertia = 0.5, 0.01
    m.gravity = (0.0, -9.81)
    m.bodies[0].v0 = [0.0, 0.0, 6.0]
    return m


def crank_spun_fourbar() -> mbd2d.Model:
    """The four-bar with masses, motor removed, assembled q0, and only the crank's speed
    given (5 rad/s, the coupler and rocker at rest: an inconsistent v0)."""
    m = load_example("fourbar_masses.toml")
    m.drivers.clear()
    start = m.dynamics(0.05, 1, method="dopri5", rtol=1e-12, atol=1e-12)
    for k, b in enumerate(m.bodies):
        b.q0 = [float(x) for x in start.q[0, 3 * k:3 * k + 3]]
        b.v0 = [0.0, 0.0, 5.0 if k == 0 else 0.0]
    return m


@pytest.mark.parametrize("method", ["dopri5", "generalized-alpha"])
@pytest.mark.parametrize("case", ["four-bar", "cam"])
def test_sensitivities_from_an_inconsistent_v0(method: str, case: str) -> None:
    """The start's velocity is the estimate v0 projected onto J q_dot = nu, nearest in the
    kinetic metric W (the masses): it depends on the masses, and on the constraints'
    parameters through mu of that projection (J^T mu = W (v0 - q_dot)). The start's
    sensitivity took neither (33-65% off for a coupler mass and a rocker inertia, 1.3% for
    a pin, when only the crank's speed was given; found by this test). The cam's mass moves
    nothing but the metric of the massless contact coordinate (the mean mass). Reference:
    Richardson central differences of plain runs, the start's own rows included. Measured
    2.8e-12 to 3.2e-10 (q), up to 3.3e-12 (the start's q_dot)."""
    m = crank_spun_fourbar() if case == "four-bar" else free_cam()
    names = (["body.coupler.mass", "body.rocker.inertia", "joint.B.points.0.0"]
             if case == "four-bar" else ["body.cam.mass", "body.cam.inertia",
                                         "body.follower.mass"])
    if method == "dopri5":
        kw = {"method": "dopri5", "rtol": 1e-11, "atol": 1e-11}
        ref_kw = {"method": "dopri5", "rtol": 1e-12, "atol": 1e-12}
    else:
        kw = ref_kw = {"method": "generalized-alpha", "h": 1e-3, "rtol": 1e-12, "atol": 1e-12}
    res = m.dynamics(0.2, 4, sensitivities=names, **kw)
    v0 = np.array([b.v0 for b in m.bodies]).ravel()
    assert np.abs(res.qd[0, :len(v0)] - v0).max() > 0.1      # the projection moved v0
    for j, name in enumerate(names):
        ref = _richardson_runs(m, name, lambda mm: mm.dynamics(0.2, 4, **ref_kw))
        rel_close(res.dq_dp[:, :, j], ref[0], rtol=1e-8, what=f"{case} {method} dq / d {name}")
        rel_close(res.dqd_dp[0, :, j], ref[1][0], rtol=1e-8,
                  what=f"{case} {method} start's dqd / d {name}")
