"""Gear reactions against Newton-Euler written by hand on each gear (issue 9, item 5).

The gear joint's reaction is the tooth force at the pitch point along the line of action
(pressure angle phi): a tangential part F_t and a radial part |F_t| tan(phi) that pushes the
gears apart. Each test gets the motion in closed form (or the equilibrium from a reduced
coordinate solved here), then writes m a = sum F and I alpha = sum M for every gear and
compares the pivot forces the engine reports. Before the fix the gear row was angle-only:
its multiplier was a pure moment and the pivots carried no tooth force.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d

G = 9.81
R1, R2 = 0.5, 1.5            # pinion and wheel pitch radii
M1, I1, M2, I2 = 1.0, 0.02, 3.0, 0.5


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z-component of a x b, row-wise."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def gear_pair(alpha: float, phi: float) -> mbd2d.Model:
    """Pinion (centre at the origin) driven at theta = alpha t^2 / 2 meshing with a wheel on
    a ground pivot at (2, 0), both under gravity."""
    m = mbd2d.Model("pair", gravity=(0.0, -G))
    m.add_body("pinion", (0.0, 0.0, 0.0), mass=M1, inertia=I1)
    m.add_body("wheel", (R1 + R2, 0.0, 0.3), mass=M2, inertia=I2)
    m.add_revolute(["ground", "pinion"], [[0.0, 0.0], [0.0, 0.0]], name="O1")
    m.add_revolute(["ground", "wheel"], [[R1 + R2, 0.0], [0.0, 0.0]], name="O2")
    m.add_gear(["pinion", "wheel"], [R1, R2], pressure_angle=phi, name="mesh")
    m.add_driver("absolute", body="pinion", coordinate="theta", f={"poly": [0.0, 0.0, alpha / 2]},
                 name="motor")
    return m


@pytest.mark.parametrize("alpha, phi", [(3.0, math.radians(20.0)), (3.0, 0.0),
                                        (-2.0, -math.radians(20.0)),
                                        (4.0, math.radians(14.5))])
def test_external_pair_pivot_forces(alpha: float, phi: float) -> None:
    """Constant angular acceleration alpha of the pinion. On the wheel (centre fixed):
    I2 th2'' = -R2 F_y (the tooth force F acts at the pitch point (R1, 0), left of the wheel
    centre), th2'' = -(R1/R2) alpha; F_x = |F_y| tan(phi) pushes the wheel away from the
    pinion (the physical flank: phi > 0 while the pinion drives, phi < 0 while it brakes).
    Pivot forces: O2 = -F - M2 g, O1 = +F - M1 g; motor torque I1 alpha + R1 F_y."""
    res = gear_pair(alpha, phi).inverse_dynamics(t_end=1.0, steps=8)
    fy = I2 * R1 * alpha / R2**2                     # on the wheel, from its moment balance
    fx = abs(fy) * math.tan(abs(phi))                # separating
    w = np.array([fx, fy])
    o2, o1, mesh = res.reaction("O2"), res.reaction("O1"), res.reaction("mesh")
    n = len(res.t)
    tol = dict(rtol=0, atol=1e-9)
    assert_allclose(np.column_stack([o2.fx_j, o2.fy_j]), np.tile(-w + [0, M2 * G], (n, 1)), **tol)
    assert_allclose(np.column_stack([o1.fx_j, o1.fy_j]), np.tile(w + [0, M1 * G], (n, 1)), **tol)
    # the mesh reaction itself: -F on the pinion, F on the wheel, moments about the centres
    assert_allclose(np.column_stack([mesh.fx, mesh.fy, mesh.fx_j, mesh.fy_j]),
                    np.tile([-fx, -fy, fx, fy], (n, 1)), **tol)
    assert_allclose(mesh.mz, -R1 * fy, **tol)
    assert_allclose(mesh.mz_j, -R2 * fy, **tol)
    assert_allclose(res.effort("motor"), I1 * alpha + R1 * fy, **tol)
    # the multiplier is the tangential force: positive while the mesh turns the pinion
    # clockwise
    lam = res.multiplier("mesh.mesh")
    assert_allclose(lam, fy, **tol)


def test_pressure_angle_from_toml_and_default() -> None:
    """The TOML key and the builder agree; the default is 20 degrees."""
    text = """
[model]
gravity = [0.0, -9.81]
[[body]]
name = "pinion"
q0 = [0, 0, 0]
mass = 1.0
inertia = 0.02
[[body]]
name = "wheel"
q0 = [2, 0, 0.3]
mass = 3.0
inertia = 0.5
[[joint]]
name = "O1"
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
name = "O2"
type = "revolute"
bodies = ["ground", "wheel"]
points = [[2, 0], [0, 0]]
[[joint]]
name = "mesh"
type = "gear"
bodies = ["pinion", "wheel"]
radii = [0.5, 1.5]
PA
[[driver]]
name = "motor"
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { poly = [0.0, 0.0, 1.5] }
"""
    ref = gear_pair(3.0, math.radians(20.0)).inverse_dynamics(t_end=1.0, steps=4)
    for pa in ("", "pressure_angle = 0.3490658503988659"):
        res = mbd2d.loads(text.replace("PA", pa)).inverse_dynamics(t_end=1.0, steps=4)
        assert_allclose(res.reaction("O2").fx_j, ref.reaction("O2").fx_j, rtol=0, atol=1e-12)
    res = mbd2d.loads(text.replace("PA", "pressure_angle = 0.0")).inverse_dynamics(1.0, 4)
    assert_allclose(res.reaction("O2").fx_j, 0.0, atol=1e-12)
    with pytest.raises(mbd2d.ModelError, match="pressure_angle"):
        mbd2d.loads(text.replace("PA", "pressure_angle = 20.0"))
    with pytest.raises(mbd2d.ModelError, match="pressure_angle"):
        mbd2d.loads(text.replace("PA", 'pressure_angle = "20deg"'))


def test_geared_pendulum_in_equilibrium() -> None:
    """A wheel whose centre of mass sits ELL off its pivot (its gear centre given by the
    pivot, not the body origin) hangs from a pinion held by a rotational spring (k, free at 0).
    Reduced coordinate psi (pinion angle), wheel angle th2 = th20 - (R1/R2) psi:
    k psi - m2 g ELL cos(th2) R1/R2 = 0, solved here by bisection. Newton-Euler on the wheel:
    -m2 g ELL cos(th2) - R2 F_y = 0; on the pinion the spring balances R1 F_y."""
    k, ell, th20 = 30.0, 0.4, 2.5
    flank = None
    for phi_sign in (1.0, -1.0):
        m = mbd2d.Model("geared-pendulum", gravity=(0.0, -G))
        c2 = np.array([R1 + R2, 0.0])
        m.add_body("pinion", (0.0, 0.0, 0.0), mass=M1, inertia=I1)
        m.add_body("wheel", (c2[0] + ell * math.cos(th20), ell * math.sin(th20), th20),
                   mass=M2, inertia=I2)
        m.add_revolute(["ground", "pinion"], [[0.0, 0.0], [0.0, 0.0]], name="O1")
        m.add_revolute(["ground", "wheel"], [list(c2), [-ell, 0.0]], name="O2")
        m.add_gear(["pinion", "wheel"], [R1, R2], pressure_angle=phi_sign * math.radians(20),
                   name="mesh")
        m.add_rotational_spring(["ground", "pinion"], stiffness=k)

        def load(psi: float) -> float:
            return k * psi - M2 * G * ell * math.cos(th20 - R1 / R2 * psi) * R1 / R2

        lo, hi = -2.0, 2.0
        assert load(lo) < 0 < load(hi)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if load(mid) < 0 else (lo, mid)
        psi = 0.5 * (lo + hi)
        th2 = th20 - R1 / R2 * psi
        st = m.statics()
        assert_allclose(st.body("pinion")[2], psi, atol=1e-12)
        fy = -M2 * G * ell * math.cos(th2) / R2           # tooth force on the wheel, y
        # the mesh turns the pinion clockwise when R1 * (-fy) < 0: the positive flank
        flank = 1.0 if fy > 0 else -1.0
        fx = abs(fy) * math.tan(math.radians(20)) * (1.0 if phi_sign == flank else -1.0)
        o2 = st.reaction("O2")
        assert_allclose([o2.fx_j[0], o2.fy_j[0]], [-fx, -fy + M2 * G], atol=1e-9)
        o1 = st.reaction("O1")
        assert_allclose([o1.fx_j[0], o1.fy_j[0]], [fx, fy + M1 * G], atol=1e-9)
    assert flank is not None


def test_planet_carrier_pivot_force() -> None:
    """A planet (R 0.5, mass 2, inertia 0.03) on a carrier driven at psi = alpha t^2 / 2
    rolls inside a ring (R 1.5) welded to ground; the ring's centre comes from q0 (it is not
    pinned to the carrier). Planet centre on the circle of radius 1: a = psi'' t - psi'^2 e;
    planet angle -2 psi. Moment about its centre: I th'' = R F_t; the radial part pushes the
    planet toward the ring centre (-e). Carrier pin: m a - F - m g; ring weld: F - m_r g."""
    alpha, mp, ip, mr = 2.0, 2.0, 0.03, 5.0
    m = mbd2d.Model("planetary", gravity=(0.0, -G))
    m.add_body("carrier", (0.5, 0.0, 0.0), mass=1.0, inertia=0.1)
    m.add_body("planet", (1.0, 0.0, 0.0), mass=mp, inertia=ip)
    m.add_body("ring", (0.0, 0.0, 0.0), mass=mr, inertia=3.0)
    m.add_revolute(["ground", "carrier"], [[0.0, 0.0], [-0.5, 0.0]], name="C")
    m.add_revolute(["carrier", "planet"], [[0.5, 0.0], [0.0, 0.0]], name="P")
    m.add_weld(["ground", "ring"], [[0.0, 0.0], [0.0, 0.0]], name="R")
    m.add_gear(["planet", "ring"], [0.5, 1.5], internal=True, carrier="carrier", name="mesh")
    m.add_driver("absolute", body="carrier", coordinate="theta",
                 f={"poly": [0.0, 0.0, alpha / 2]}, name="motor")
    res = m.inverse_dynamics(t_end=1.5, steps=6)
    t = res.t
    psi, psid = alpha * t**2 / 2, alpha * t
    e = np.column_stack([np.cos(psi), np.sin(psi)])
    tt = np.column_stack([-np.sin(psi), np.cos(psi)])
    acc = alpha * tt - psid[:, None]**2 * e
    ft = ip * (-2.0 * alpha) / 0.5                   # tangential (along t) on the planet
    assert ft < 0                                    # clockwise mesh moment: positive flank
    f = ft * tt - abs(ft) * math.tan(math.radians(20)) * e
    p = res.reaction("P")
    assert_allclose(np.column_stack([p.fx_j, p.fy_j]), mp * acc - f - [0.0, -mp * G],
                    rtol=0, atol=1e-9)
    r = res.reaction("R")
    assert_allclose(np.column_stack([r.fx_j, r.fy_j]), f + [0.0, mr * G], rtol=0, atol=1e-9)
    # the weld's moment balances the tooth force's moment about the ring centre
    contact = 1.5 * e
    assert_allclose(r.mz_j, cross(contact, f), rtol=0, atol=1e-9)
    assert_allclose(res.body("planet").theta, -2.0 * psi, atol=1e-12)


def test_explicit_centers_and_coincident_centres() -> None:
    """`centers` given by hand (here the wheel's pivot off its body origin, and no pivot to
    read it from: a point-on-line pair instead of a revolute) gives the same tooth force as the
    pivots would; centres that coincide are a ModelError naming the gear."""
    def pair(centers: list | None, pin: bool) -> mbd2d.Model:
        m = mbd2d.Model("pair", gravity=(0.0, 0.0))
        m.add_body("pinion", (0.0, 0.0, 0.0), mass=M1, inertia=I1)
        m.add_body("wheel", (R1 + R2 + 0.3, 0.0, 0.0), mass=M2, inertia=I2)
        m.add_revolute(["ground", "pinion"], [[0.0, 0.0], [0.0, 0.0]], name="O1")
        if pin:
            m.add_revolute(["ground", "wheel"], [[R1 + R2, 0.0], [-0.3, 0.0]], name="O2")
        else:       # the same pin as two point-on-line equations
            m.add_point_on_line(["ground", "wheel"], [[R1 + R2, 0.0], [-0.3, 0.0]], [1.0, 0.0],
                                name="O2x")
            m.add_point_on_line(["ground", "wheel"], [[R1 + R2, 0.0], [-0.3, 0.0]], [0.0, 1.0],
                                name="O2y")
        m.add_gear(["pinion", "wheel"], [R1, R2], centers=centers, name="mesh")
        m.add_driver("absolute", body="pinion", coordinate="theta", f={"poly": [0.0, 0.0, 1.0]},
                     name="motor")
        return m
    ref = pair(None, True).inverse_dynamics(1.0, 4).reaction("mesh")
    res = pair([[0.0, 0.0], [-0.3, 0.0]], False).inverse_dynamics(1.0, 4).reaction("mesh")
    fy = (I2 + M2 * 0.3**2) * R1 * 2.0 / R2**2        # the wheel turns about its pivot
    assert_allclose(ref.fy_j, fy, atol=1e-10)
    assert_allclose(res.fx_j, ref.fx_j, atol=1e-10)
    assert_allclose(res.fy_j, ref.fy_j, atol=1e-10)
    with pytest.raises(mbd2d.ModelError, match="centres coincide") as info:
        pair([[0.0, 0.0], [-(R1 + R2 + 0.3), 0.0]], False).inverse_dynamics(1.0, 4)
    assert "mesh" in info.value.entry
