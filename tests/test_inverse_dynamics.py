"""Inverse dynamics: multipliers, joint reactions and driver efforts against independent
computations (closed-form kinematics and the power balance)."""
from __future__ import annotations


import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES

W = 2.0 * np.pi
G = 9.81


def with_masses(name: str, masses: dict[str, tuple[float, float]], extra: str = "",
                gravity: str = "[0.0, 0.0]") -> mbd2d.Model:
    """An example model with masses (and gravity, extra TOML) added."""
    text = (EXAMPLES / f"{name}.toml").read_text()
    for body, (m, j) in masses.items():
        text = text.replace(f'[[body]]\nname = "{body}"\n',
                            f'[[body]]\nname = "{body}"\nmass = {m!r}\ninertia = {j!r}\n', 1)
    text = text.replace("[model]\n", f"[model]\ngravity = {gravity}\n", 1)
    return mbd2d.loads(text + extra)


def test_slider_crank_torque_closed_form() -> None:
    """Massless crank and rod, slider of mass 2, crank at constant speed omega: the motor
    torque is T = m x_ddot x_dot / omega (the power that accelerates the slider)."""
    m = with_masses("slider_crank", {"crank": (0.0, 0.0), "rod": (0.0, 0.0),
                                     "slider": (2.0, 0.0)})
    res = m.kinematics(t_end=1.0, steps=400)
    assert isinstance(res, mbd2d.DynamicsResult)
    th = W * res.t
    u = np.sin(th) - 0.5
    rt = np.sqrt(9.0 - u**2)
    xd = (-np.sin(th) - u * np.cos(th) / rt) * W
    xdd = W**2 * (-np.cos(th) - (np.cos(th)**2 - u * np.sin(th)) / rt - (u * np.cos(th))**2 / rt**3)
    torque = 2.0 * xdd * xd / W
    assert_allclose(res.effort("motor"), torque, rtol=0, atol=1e-9 * np.abs(torque).max())
    # the slider's guide carries no axial force: the rod pushes it, the guide only presses
    guide = res.reaction("guide")
    assert_allclose(guide.fx_j, 0.0, atol=1e-9)


def test_decimated_inverse_dynamics_keeps_the_closed_form_torque() -> None:
    """every=k: the same closed-form torque at the kept rows (0, k, 2k, ... and the last)."""
    m = with_masses("slider_crank", {"crank": (0.0, 0.0), "rod": (0.0, 0.0),
                                     "slider": (2.0, 0.0)})
    res = m.kinematics(t_end=1.0, steps=400, every=30)
    assert isinstance(res, mbd2d.DynamicsResult)
    assert_allclose(res.t, np.append(np.arange(0, 401, 30), 400) / 400, rtol=0, atol=1e-15)
    th = W * res.t
    u = np.sin(th) - 0.5
    rt = np.sqrt(9.0 - u**2)
    xd = (-np.sin(th) - u * np.cos(th) / rt) * W
    xdd = W**2 * (-np.cos(th) - (np.cos(th)**2 - u * np.sin(th)) / rt - (u * np.cos(th))**2 / rt**3)
    torque = 2.0 * xdd * xd / W
    assert_allclose(res.effort("motor"), torque, rtol=0, atol=1e-9 * np.abs(torque).max())
    banded = m.inverse_dynamics(t_end=1.0, steps=400, every=30, solver="banded")
    assert_allclose(banded.effort("motor"), torque, rtol=0, atol=1e-9 * np.abs(torque).max())


def loop_closure(th1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coupler and rocker angles of the seed four-bar (crank 3, coupler 5, rocker 2.6,
    ground 6) on the branch the example assembles (B above the line A-O4)."""
    a = 3.0 * np.column_stack([np.cos(th1), np.sin(th1)])
    d = np.array([6.0, 0.0]) - a
    L = np.hypot(*d.T)
    along = (L**2 + 25.0 - 2.6**2) / (2 * L)
    h = np.sqrt(25.0 - along**2)
    u = d / L[:, None]
    b = a + along[:, None] * u + h[:, None] * np.column_stack([-u[:, 1], u[:, 0]])
    th2 = np.arctan2(b[:, 1] - a[:, 1], b[:, 0] - a[:, 0])
    th3 = np.arctan2(-b[:, 1], 6.0 - b[:, 0])
    return th2, th3


def seed_motion(t: np.ndarray, k: int) -> dict[str, np.ndarray]:
    """k-th time derivative of every body's centre-of-mass position and angle, from the
    closed-form loop closure differentiated by a 9-point central stencil (step 1e-3)."""
    def state(tt: np.ndarray) -> np.ndarray:
        th1 = tt + np.pi / 3
        th2, th3 = loop_closure(th1)
        a = 3.0 * np.column_stack([np.cos(th1), np.sin(th1)])
        c1 = 0.5 * a
        c2 = a + 2.5 * np.column_stack([np.cos(th2), np.sin(th2)])
        c3 = np.array([6.0, 0.0]) - 1.3 * np.column_stack([np.cos(th3), np.sin(th3)])
        return np.column_stack([c1, th1, c2, th2, c3, th3])
    if k == 0:
        return state(t)
    hs = 1e-3
    w1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
    w2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315,
                   -1 / 560])
    w = w1 if k == 1 else w2
    return sum(wj * state(t + (j - 4) * hs) for j, wj in enumerate(w)) / hs**k


SEED_MASSES = {"crank": (3.0, 3.0 * 9.0 / 12), "coupler": (5.0, 5.0 * 25.0 / 12),
               "rocker": (2.6, 2.6 * 2.6**2 / 12)}


def test_seed_four_bar_with_gravity_against_newton_euler() -> None:
    """The seed four-bar with uniform bars (m = L, J = m L^2 / 12) under gravity, driven
    to t = 0.8 s: the motor torque from the power balance T th1_dot = sum(m a.v + J alpha
    omega) + sum(m g v_y) with closed-form kinematics, and every body's reactions
    satisfying Newton-Euler with those accelerations."""
    m = with_masses("fourbar_seed", SEED_MASSES, gravity="[0.0, -9.81]")
    res = m.inverse_dynamics(t_end=0.8, steps=80)
    t = res.t
    v, a = seed_motion(t, 1), seed_motion(t, 2)
    mass = np.array([SEED_MASSES[b][0] for b in ("crank", "coupler", "rocker")])
    inertia = np.array([SEED_MASSES[b][1] for b in ("crank", "coupler", "rocker")])
    power = np.zeros_like(t)
    for i in range(3):
        vi, ai = v[:, 3 * i:3 * i + 3], a[:, 3 * i:3 * i + 3]
        power += mass[i] * (ai[:, 0] * vi[:, 0] + ai[:, 1] * vi[:, 1] + G * vi[:, 1])
        power += inertia[i] * ai[:, 2] * vi[:, 2]
    torque = power / 1.0                          # th1_dot = 1
    assert_allclose(res.effort("motor"), torque, rtol=0, atol=1e-8 * np.abs(torque).max())
    # Newton-Euler per body with the engine's reactions: forces and moments about the CoM
    joints = {"crank": [("O2", "j"), ("A", "i")], "coupler": [("A", "j"), ("B", "i")],
              "rocker": [("B", "j"), ("O4", "i")]}
    for i, body in enumerate(("crank", "coupler", "rocker")):
        fx = np.zeros_like(t)
        fy = np.zeros_like(t)
        mz = np.zeros_like(t)
        for name, side in joints[body]:
            r = res.reaction(name)
            fx += r.fx if side == "i" else r.fx_j
            fy += r.fy if side == "i" else r.fy_j
            mz += r.mz if side == "i" else r.mz_j
        if body == "crank":
            mz += res.effort("motor")
        ai = a[:, 3 * i:3 * i + 3]
        assert_allclose(fx, mass[i] * ai[:, 0], atol=1e-7 * torque.__abs__().max())
        assert_allclose(fy - mass[i] * G, mass[i] * ai[:, 1], atol=1e-7 * torque.__abs__().max())
        assert_allclose(mz, inertia[i] * ai[:, 2], atol=1e-7 * torque.__abs__().max())


def test_kinematics_with_masses_gives_inverse_dynamics() -> None:
    m = with_masses("fourbar_seed", SEED_MASSES, gravity="[0.0, -9.81]")
    a = m.kinematics(t_end=0.5, steps=10)
    b = m.inverse_dynamics(t_end=0.5, steps=10)
    assert isinstance(a, mbd2d.DynamicsResult)
    assert_allclose(a.lam, b.lam, rtol=0, atol=0)
    plain = mbd2d.load(EXAMPLES / "fourbar_seed.toml").kinematics(t_end=0.5, steps=10)
    assert_allclose(a.q, plain.q, atol=0)


def test_driver_power_balance_with_springs_and_loads() -> None:
    """Along the whole run: driver power = d(kinetic + potential)/dt - power of the applied
    loads, for a crank-rocker with masses, gravity, a spring and a point force."""
    extra = ('\n[[force]]\nname = "spring"\ntype = "spring"\nbodies = ["ground", "rocker"]\n'
             'points = [[4.0, 2.0], [-1.25, 0.0]]\nstiffness = 40.0\nlength0 = 0.5\n'
             '\n[[force]]\nname = "load"\ntype = "point"\nbody = "coupler"\n'
             'point = [0.0, 1.0]\nfx = 3.0\nfy = { poly = [-5.0], harmonic = [{ amplitude = 2.0, '
             'omega = 6.0 }] }\n')
    masses = {"crank": (1.0, 1.0 / 12), "coupler": (3.5, 3.5 * 3.5**2 / 12),
              "rocker": (2.5, 2.5 * 2.5**2 / 12)}
    m = with_masses("fourbar_grashof", masses, extra, gravity="[0.0, -9.81]")
    n = 4000
    res = m.inverse_dynamics(t_end=1.0, steps=n)
    h = 1.0 / n
    e = res.energy
    de = (e[2:] - e[:-2]) / (2 * h)                      # d(T + V)/dt, central differences
    c = res.body("coupler")
    # velocity of the loaded point (0, 1) in the coupler frame: r_dot + B s' theta_dot
    vx = c.x_dot - np.cos(c.theta) * c.theta_dot
    vy = c.y_dot - np.sin(c.theta) * c.theta_dot
    load = 3.0 * vx + (-5.0 + 2.0 * np.sin(6.0 * res.t)) * vy
    p_driver = res.effort("motor") * W
    assert_allclose(p_driver[1:-1], de - load[1:-1], rtol=0,
                    atol=1e-5 * np.abs(p_driver).max())


def test_redundant_multipliers_are_minimum_norm() -> None:
    """A door on two identical hinges with mass: the pin load splits evenly between them
    (the minimum-norm multipliers), and the reactions are reported as indeterminate."""
    m = with_masses("door_two_hinges", {"door": (4.0, 0.3)}, gravity="[0.0, -9.81]")
    with pytest.warns(mbd2d.RedundantConstraintWarning, match="indeterminate"):
        res = m.inverse_dynamics(t_end=0.5, steps=20)
    lo, up = res.reaction("lower"), res.reaction("upper")
    assert_allclose(lo.fx_j, up.fx_j, atol=1e-9)
    assert_allclose(lo.fy_j, up.fy_j, atol=1e-9)
    total = lo.fy_j + up.fy_j
    d = res.body("door")
    assert_allclose(total - 4.0 * G, 4.0 * d.y_ddot, atol=1e-8)


def test_dynamics_needs_masses() -> None:
    with pytest.raises(mbd2d.ModelError, match="body 'crank'.*mass"):
        mbd2d.load(EXAMPLES / "fourbar_grashof.toml").inverse_dynamics(t_end=1.0, steps=4)
