"""Small vibrations about an equilibrium (Model.modes) against closed forms and reduced-
coordinate models written here without mbd2d: a compound pendulum on a torsion spring, a
damped block on a guide (under-, critically and over-damped), a double pendulum (its 2 x 2
mass and stiffness matrices by hand), a spring-mass chain (its closed-form spectrum) on the
dense and band paths, and a four-bar on a spring (the energy method on its closed-form
position analysis: V''/M_eff at the equilibrium, where the constraints' curvature counts)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mbd2d

G = 9.81


def pendulum(k: float = 10.0, c: float = 0.0, mass: float = 1.0, length: float = 1.0,
             inertia: float | None = None, gravity: float = G, q0: str = "0.5, 0.0, 0.0",
             angle0: float = 0.0) -> mbd2d.Model:
    """A bar pinned at its end (-length / 2 in its frame) on a torsion spring-damper."""
    inertia = mass * length**2 / 12 if inertia is None else inertia
    return mbd2d.loads(f"""
[model]
name = "bar-on-a-spring"
gravity = [0.0, {-gravity}]
[[body]]
name = "bar"
q0 = [{q0}]
mass = {mass}
inertia = {inertia}
[[joint]]
type = "revolute"
name = "pivot"
bodies = ["ground", "bar"]
points = [[0.0, 0.0], [{-length / 2}, 0.0]]
[[force]]
type = "rotational-spring"
name = "torsion"
bodies = ["ground", "bar"]
stiffness = {k}
damping = {c}
angle0 = {angle0}
""")


def bisect(f, a: float, b: float) -> float:
    """A root of f in [a, b] (f(a) f(b) < 0) to round-off."""
    fa = f(a)
    for _ in range(200):
        mid = 0.5 * (a + b)
        fm = f(mid)
        if (fm < 0) == (fa < 0):
            a, fa = mid, fm
        else:
            b = mid
        if b - a <= 4e-16 * max(1.0, abs(a)):
            break
    return 0.5 * (a + b)


@pytest.mark.parametrize("k", [10.0, 3.0, 50.0])
def test_pendulum_on_a_spring(k: float) -> None:
    """omega^2 = (k - m g (L/2) sin theta*) / I_O at the equilibrium k theta* + m g (L/2)
    cos theta* = 0, both solved here."""
    m, L = 1.3, 0.8
    res = pendulum(k=k, mass=m, length=L).modes()
    th = bisect(lambda a: k * a + m * G * L / 2 * np.cos(a), -np.pi / 2, 0.0)
    i_o = m * L**2 / 12 + m * (L / 2)**2
    w2 = (k - m * G * L / 2 * np.sin(th)) / i_o
    assert res.n_free == 1 and res.kinds == ["vibration"] and res.stability == "stable"
    assert abs(res.q[2] - th) < 1e-12
    assert abs(res.omega2[0] / w2 - 1) < 1e-13
    assert abs(res.frequency[0] - np.sqrt(w2) / (2 * np.pi)) < 1e-13 * res.frequency[0]
    # mass-normalized: phi^T M phi = 1 with M = diag(m, m, I)
    phi = res.shape(0)
    assert abs(m * (phi[0]**2 + phi[1]**2) + m * L**2 / 12 * phi[2]**2 - 1) < 1e-12
    assert phi[2] > 0 and abs(phi[2] - 1 / np.sqrt(i_o)) < 1e-12
    # the pivot does not move: the centre moves on its circle, d r = (L/2)(-sin, cos) d theta
    assert abs(phi[0] + L / 2 * np.sin(th) * phi[2]) < 1e-12
    assert abs(phi[1] - L / 2 * np.cos(th) * phi[2]) < 1e-12


def block_text(k: float = 36.0, c: float = 1.5, m: float = 2.0) -> str:
    """A block on a vertical guide hanging from a spring-damper-actuator (tension k (L -
    0.5) + c L' - f): the block's y is -L."""
    return f"""
[model]
name = "block"
gravity = [0.0, {-G}]
[[body]]
name = "block"
q0 = [0.0, -1.0, 0.0]
mass = {m}
inertia = 0.01
[[joint]]
type = "translational"
name = "guide"
bodies = ["ground", "block"]
points = [[0, 0], [0, 0]]
axes = [[0, 1], [0, 1]]
[[force]]
type = "spring"
name = "s"
bodies = ["ground", "block"]
points = [[0.0, 0.0], [0.0, 0.0]]
stiffness = {k}
damping = {c}
length0 = 0.5
"""


@pytest.mark.parametrize("c", [0.0, 0.4, 2 * np.sqrt(36.0 * 2.0), 30.0])
def test_damped_block_on_a_guide(c: float) -> None:
    """A 2 kg block on a vertical guide hanging from a spring (k = 36 N/m) and damper c:
    s = (-c +- sqrt(c^2 - 4 m k)) / (2 m), omega^2 = k / m, zeta = c / (2 sqrt(k m))."""
    m, k = 2.0, 36.0
    model = mbd2d.loads(block_text(k, c, m))
    res = model.modes()
    assert abs(res.omega2[0] / (k / m) - 1) < 1e-13
    assert abs(res.q[1] - (-0.5 - m * G / k)) < 1e-12
    disc = complex(c * c - 4 * m * k)
    want = sorted([(-c + np.sqrt(disc)) / (2 * m), (-c - np.sqrt(disc)) / (2 * m)],
                  key=lambda s: (abs(s), -s.imag))
    assert res.eigenvalues.shape == (2,)
    scale = np.sqrt(k / m)
    # K and C are exact (measured 4e-16 here; 8e-12 with the central differences of
    # before); at critical damping the double root splits by the square root of the
    # round-off (measured 4e-10; 6e-6 with the differences)
    if abs(disc) < 1e-9:
        np.testing.assert_allclose(res.eigenvalues, want, rtol=0, atol=3e-8 * scale)
        np.testing.assert_allclose(res.damping_ratio, 1.0, atol=3e-8)
    else:
        np.testing.assert_allclose(res.eigenvalues, want, rtol=0, atol=1e-14 * scale)
        if c < 2 * np.sqrt(k * m):
            np.testing.assert_allclose(res.damping_ratio, c / (2 * np.sqrt(k * m)),
                                       atol=1e-14)
            np.testing.assert_allclose(res.damped_frequency,
                                       np.sqrt(k / m - (c / (2 * m))**2) / (2 * np.pi),
                                       rtol=1e-14)


def double_pendulum(m1: float, m2: float, l1: float, l2: float, i1: float, i2: float
                    ) -> mbd2d.Model:
    """Two bars hanging from a pin, pinned end to end (centres of mass at mid-length)."""
    return mbd2d.loads(f"""
[model]
name = "double-pendulum"
gravity = [0.0, -9.81]
[[body]]
name = "upper"
q0 = [0.1, {-l1 / 2}, -1.5]
mass = {m1}
inertia = {i1}
[[body]]
name = "lower"
q0 = [0.2, {-l1 - l2 / 2}, -1.4]
mass = {m2}
inertia = {i2}
[[joint]]
type = "revolute"
name = "top"
bodies = ["ground", "upper"]
points = [[0, 0], [{-l1 / 2}, 0]]
[[joint]]
type = "revolute"
name = "elbow"
bodies = ["upper", "lower"]
points = [[{l1 / 2}, 0], [{-l2 / 2}, 0]]
""")


def test_double_pendulum_against_its_two_by_two_matrices() -> None:
    """About the hanging equilibrium (absolute angles from the vertical): M = [[I1 + m1 a1^2
    + m2 l1^2, m2 l1 a2], [m2 l1 a2, I2 + m2 a2^2]], K = g diag(m1 a1 + m2 l1, m2 a2);
    frequencies and the shapes' angle ratios from numpy's eigensolver."""
    m1, m2, l1, l2, i1, i2 = 1.5, 0.7, 0.9, 0.6, 0.11, 0.03
    res = double_pendulum(m1, m2, l1, l2, i1, i2).modes()
    a1, a2 = l1 / 2, l2 / 2
    mm = np.array([[i1 + m1 * a1**2 + m2 * l1**2, m2 * l1 * a2], [m2 * l1 * a2, i2 + m2 * a2**2]])
    kk = G * np.diag([m1 * a1 + m2 * l1, m2 * a2])
    w2, vec = np.linalg.eig(np.linalg.solve(mm, kk))
    order = np.argsort(w2)
    np.testing.assert_allclose(res.omega2, w2[order], rtol=1e-13)
    for j, col in enumerate(order):
        ratio = vec[1, col] / vec[0, col]
        phi = res.shape(j)
        assert abs(phi[5] / phi[2] - ratio) < 1e-12 * max(1.0, abs(ratio))
    assert res.stability == "stable" and res.kinds == ["vibration", "vibration"]
    np.testing.assert_allclose(res.damping_ratio, 0.0, atol=1e-12)
    np.testing.assert_allclose(res.eigenvalues.real, 0.0, atol=1e-11 * np.sqrt(w2.max()))


def spring_chain(n: int, m: float = 0.5, k: float = 200.0) -> mbd2d.Model:
    """n blocks on horizontal guides (no gravity), block 1 tied to ground and each block to
    the next by springs k at their natural lengths: a fixed-free chain."""
    parts = ["[model]", 'name = "chain"', "gravity = [0.0, 0.0]"]
    for i in range(1, n + 1):
        parts += ["[[body]]", f'name = "b{i}"', f"q0 = [{i * 0.1}, 0.0, 0.0]",
                  f"mass = {m}", "inertia = 0.001",
                  "[[joint]]", 'type = "translational"', f'name = "g{i}"',
                  f'bodies = ["ground", "b{i}"]', "points = [[0.0, 0.0], [0.0, 0.0]]",
                  "axes = [[1, 0], [1, 0]]",
                  "[[force]]", 'type = "spring"', f'name = "s{i}"',
                  f'bodies = ["{"ground" if i == 1 else f"b{i - 1}"}", "b{i}"]',
                  "points = [[0.0, 0.0], [0.0, 0.0]]",
                  f"stiffness = {k}", "damping = 0.0", "length0 = 0.1"]
    return mbd2d.loads("\n".join(parts))


@pytest.mark.parametrize("n, solver", [(6, "dense"), (40, "banded"), (40, "dense"),
                                       (60, "banded"), (61, "dense")])
def test_spring_chain_spectrum(n: int, solver: str) -> None:
    """A fixed-free chain of n masses: omega_j = 2 sqrt(k/m) sin((2j - 1) pi / (2 (2n + 1))).
    (At 60 and 61 blocks the null basis' pseudo-random vectors were dependent on the free
    coordinates: no basis, a CoreError.)"""
    m, k = 0.5, 200.0
    res = spring_chain(n, m, k).modes(solver=solver)
    j = np.arange(1, n + 1)
    want = 2 * np.sqrt(k / m) * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))
    assert res.stats["solver"] == solver and res.n_free == n
    np.testing.assert_allclose(res.omega, want, rtol=1e-12)
    # the lowest shape: x_i proportional to sin((2 i) pi / (2 (2n + 1))) ... from the block 1
    x = res.shapes[0::3, 0]
    i = np.arange(1, n + 1)
    shape = np.sin(i * np.pi / (2 * n + 1))
    np.testing.assert_allclose(x / x[-1], shape / shape[-1], atol=1e-12)


def fourbar_energy(th2: float, geo: dict) -> tuple[float, float]:
    """V and M_eff of the spring-loaded four-bar at crank angle th2 (open branch), by its
    closed-form position analysis: coupler point by the circle intersection."""
    a, b, c, d = geo["a"], geo["b"], geo["c"], geo["d"]
    A = np.array([a * np.cos(th2), a * np.sin(th2)])
    O4 = np.array([d, 0.0])
    e = O4 - A
    L = np.hypot(*e)
    h = (b * b - c * c + L * L) / (2 * L)
    B = A + h * e / L + np.sqrt(b * b - h * h) * np.array([-e[1], e[0]]) / L
    th3 = np.arctan2(B[1] - A[1], B[0] - A[0])
    th4 = np.arctan2(B[1] - O4[1], B[0] - O4[0])
    cms = [A / 2, (A + B) / 2, (O4 + B) / 2]
    return cms, (th2, th3, th4)


def fourbar_reduced(th2: float, geo: dict) -> tuple[float, float, float]:
    """V(th2), V''(th2) and M_eff(th2) by high-order central differences of the closed form
    (step 1e-3, 8th order: errors ~1e-13 here)."""
    ms, ins = geo["m"], geo["I"]

    def pot(t: float) -> float:
        cms, ths = fourbar_energy(t, geo)
        return sum(m * G * cm[1] for m, cm in zip(ms, cms)) + 0.5 * geo["k"] * (t - geo["t0"])**2

    def state(t: float) -> np.ndarray:
        cms, ths = fourbar_energy(t, geo)
        return np.concatenate([np.concatenate(cms), ths])

    h = 1e-3
    w1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
    w2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315,
                   -1 / 560])
    offs = np.arange(-4, 5) * h
    v2 = sum(w * pot(th2 + o) for w, o in zip(w2, offs)) / h**2
    v1 = sum(w * pot(th2 + o) for w, o in zip(w1, offs)) / h
    ds = sum(w * state(th2 + o) for w, o in zip(w1, offs)) / h
    meff = sum(m * (ds[2 * i]**2 + ds[2 * i + 1]**2) for i, m in enumerate(ms))
    meff += sum(inn * ds[6 + i]**2 for i, inn in enumerate(ins))
    return v1, v2, meff


#: the sprung crank-rocker's dimensions, masses, spring and the spring's free angle
SPRUNG = {"a": 0.2, "b": 0.7, "c": 0.5, "d": 0.6, "m": [0.4, 1.2, 0.9],
          "I": [0.002, 0.05, 0.02], "k": 6.0, "t0": 1.2}


def sprung_fourbar(geo: dict = SPRUNG, damping: float = 0.0) -> mbd2d.Model:
    """A crank-rocker (centres of mass at mid-link) whose crank is held by a torsion spring
    (and damper), under gravity, assembled near crank angle 1."""
    cms, ths = fourbar_energy(1.0, geo)
    bodies = ["crank", "coupler", "rocker"]
    lens = [geo["a"], geo["b"], geo["c"]]
    text = ['[model]', 'name = "sprung-fourbar"', 'gravity = [0.0, -9.81]']
    for nm, cm, th, m, inn in zip(bodies, cms, ths, geo["m"], geo["I"]):
        text += ['[[body]]', f'name = "{nm}"', f'q0 = [{cm[0]}, {cm[1]}, {th}]', f'mass = {m}',
                 f'inertia = {inn}']
    joints = [("O2", "ground", "crank", (0.0, 0.0), (-lens[0] / 2, 0.0)),
              ("A", "crank", "coupler", (lens[0] / 2, 0.0), (-lens[1] / 2, 0.0)),
              ("B", "coupler", "rocker", (lens[1] / 2, 0.0), (lens[2] / 2, 0.0)),
              ("O4", "ground", "rocker", (geo["d"], 0.0), (-lens[2] / 2, 0.0))]
    for nm, b1, b2, p1, p2 in joints:
        text += ['[[joint]]', 'type = "revolute"', f'name = "{nm}"', f'bodies = ["{b1}", "{b2}"]',
                 f'points = [[{p1[0]}, {p1[1]}], [{p2[0]}, {p2[1]}]]']
    text += ['[[force]]', 'type = "rotational-spring"', 'name = "k"',
             'bodies = ["ground", "crank"]', f'stiffness = {geo["k"]}', f'damping = {damping}',
             f'angle0 = {geo["t0"]}']
    return mbd2d.loads("\n".join(text))


def test_fourbar_on_a_spring_by_the_energy_method() -> None:
    """A crank-rocker whose crank is held by a torsion spring, under gravity: omega^2 =
    V''(th2*) / M_eff(th2*) at V'(th2*) = 0 (the equilibrium solved here). Measured 7e-10,
    the reference's own second difference (h = 1e-3: rounding eps V / h^2 ~ 2e-10)."""
    geo = SPRUNG
    res = sprung_fourbar(geo).modes()
    th = bisect(lambda t: fourbar_reduced(t, geo)[0], 0.3, 2.0)
    _, v2, meff = fourbar_reduced(th, geo)
    assert abs(res.q[2] - th) < 1e-9
    assert res.n_free == 1
    assert abs(res.omega2[0] / (v2 / meff) - 1) < 1e-8
    # the crank's angle in the mass-normalized shape: 1 / sqrt(M_eff)
    assert abs(abs(res.shape(0)[2]) - 1 / np.sqrt(meff)) < 1e-8 / np.sqrt(meff)


def test_inverted_pendulum_is_unstable_about_its_top() -> None:
    """Linearized about the upright bar (equilibrium=False, no spring): omega^2 = -m g a /
    I_O, the mode "unstable"; statics started exactly there stays (balanced, "unstable"),
    started beside it, descends to the hanging bar (stable, +m g a / I_O)."""
    m, L = 0.8, 0.6
    model = pendulum(k=0.0, mass=m, length=L, q0=f"0.0, {L / 2}, {np.pi / 2}")
    i_o = m * L**2 / 3
    up = model.modes(equilibrium=False)
    assert up.kinds == ["unstable"] and up.stability.startswith("not examined")
    assert abs(up.omega2[0] / (-m * G * L / 2 / i_o) - 1) < 1e-13
    assert up.omega[0] == 0.0 and up.frequency[0] == 0.0
    # the first-order form's eigenvalues: +- sqrt(m g a / I_O), real
    np.testing.assert_allclose(sorted(up.eigenvalues.real), [-np.sqrt(m * G * L / 2 / i_o),
                               np.sqrt(m * G * L / 2 / i_o)], rtol=1e-13)
    top = model.modes()
    assert top.stability == "unstable" and top.kinds == ["unstable"]
    assert abs(top.omega2[0] / up.omega2[0] - 1) < 1e-12
    down = pendulum(k=0.0, mass=m, length=L, q0=f"0.1, {L / 2}, {np.pi / 2 - 0.2}").modes()
    assert down.stability == "stable" and down.kinds == ["vibration"]
    assert abs(down.q[2] + np.pi / 2) < 1e-12
    assert abs(down.omega2[0] / (m * G * L / 2 / i_o) - 1) < 1e-13


def test_a_free_wheel_has_a_rigid_mode() -> None:
    """A wheel pinned at its centre, no gravity and no spring: one free motion without
    stiffness (omega^2 = 0, "rigid"), next to a pendulum's vibration in the same model."""
    model = mbd2d.loads("""
[model]
name = "wheel-and-pendulum"
gravity = [0.0, -9.81]
[[body]]
name = "wheel"
q0 = [0.0, 0.0, 0.3]
mass = 1.0
inertia = 0.02
[[body]]
name = "bob"
q0 = [2.0, -0.5, 0.0]
mass = 1.0
inertia = 0.001
[[joint]]
type = "revolute"
name = "axle"
bodies = ["ground", "wheel"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "revolute"
name = "hinge"
bodies = ["ground", "bob"]
points = [[2.0, 0.0], [0.0, 0.5]]
""")
    res = model.modes(equilibrium=False)
    assert res.n_free == 2 and res.kinds == ["rigid", "vibration"]
    assert abs(res.omega2[0]) <= 1e-13 * res.omega2[1]
    assert abs(res.omega2[1] / (G * 0.5 / (0.001 + 0.25)) - 1) < 1e-13
    assert abs(res.body_shape(0, "wheel")[2] - 1 / np.sqrt(0.02)) < 1e-12
    np.testing.assert_allclose(res.body_shape(0, "bob"), 0.0, atol=1e-12)


def test_a_fully_constrained_model_has_no_modes() -> None:
    res = mbd2d.load(Path(__file__).parents[1] / "examples" / "fourbar_masses.toml").modes()
    assert res.n_free == 0 and res.omega2.size == 0 and res.shapes.shape[1] == 0
    assert res.stability == "fully constrained" and "0 free motion" in res.summary()
    with pytest.raises(mbd2d.ModelError, match="no modes"):
        res.plot(0)


def test_count_and_the_lowest_modes() -> None:
    full = spring_chain(8).modes()
    few = spring_chain(8).modes(count=3)
    assert few.n_free == 8 and few.omega2.size == 3 and few.eigenvalues.size == 6
    np.testing.assert_array_equal(few.omega2, full.omega2[:3])
    np.testing.assert_array_equal(few.shapes, full.shapes[:, :3])


@pytest.mark.parametrize("kw, needle", [
    ({"count": 0}, "count must be a positive whole number"),
    ({"count": 2.5}, "count must be a positive whole number"),
    ({"count": True}, "count must be a positive whole number"),
    ({"equilibrium": "yes"}, "equilibrium must be True or False"),
    ({"t": float("nan")}, "t"),
    ({"solver": "sparse"}, "solver"),
])
def test_bad_arguments_are_model_errors(kw: dict, needle: str) -> None:
    with pytest.raises(mbd2d.ModelError, match=needle):
        pendulum().modes(**kw)


def test_mode_index_out_of_range_is_a_model_error() -> None:
    res = pendulum().modes()
    for k in (1, -2, 0.5, "0"):
        with pytest.raises(mbd2d.ModelError, match="does not exist"):
            res.shape(k)  # type: ignore[arg-type]
    np.testing.assert_array_equal(res.shape(-1), res.shape(0))


def disc_on_a_spring(inertia: float) -> mbd2d.Model:
    """A disc on a ground axle held by a torsion spring of 2 N m/rad, no gravity."""
    return mbd2d.loads(f"""
[model]
name = "disc"
gravity = [0.0, 0.0]
[[body]]
name = "disc"
q0 = [0.0, 0.0, 0.1]
mass = 1.0
inertia = {inertia}
[[joint]]
type = "revolute"
name = "axle"
bodies = ["ground", "disc"]
points = [[0, 0], [0, 0]]
[[force]]
type = "rotational-spring"
name = "k"
bodies = ["ground", "disc"]
stiffness = 2.0
damping = 0.0
angle0 = 0.0
""")


def test_a_massless_free_motion_is_named() -> None:
    """A disc without inertia turning about its centre on a spring: M_r is singular."""
    with pytest.raises(mbd2d.SingularJacobianError, match="carries no mass"):
        disc_on_a_spring(0.0).modes()


def test_friction_is_refused_as_in_statics() -> None:
    with pytest.raises(mbd2d.ModelError, match="friction"):
        rubbing_pendulum().modes()


def rubbing_pendulum() -> mbd2d.Model:
    """A bar on a pivot with Coulomb friction."""
    return mbd2d.loads("""
[model]
name = "rubbing"
gravity = [0.0, -9.81]
[[body]]
name = "bar"
q0 = [0.5, 0.0, 0.0]
mass = 1.0
inertia = 0.1
[[joint]]
type = "revolute"
name = "pivot"
bodies = ["ground", "bar"]
points = [[0.0, 0.0], [-0.5, 0.0]]
friction = { mu = 0.2, pin_radius = 0.01 }
""")


def test_csv_summary_and_pictures(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    res = double_pendulum(1.5, 0.7, 0.9, 0.6, 0.11, 0.03).modes()
    res.to_csv(tmp_path / "modes.csv")
    res.to_csv(tmp_path / "damped.csv", damped=True)
    table = np.genfromtxt(tmp_path / "modes.csv", delimiter=",", names=True)
    np.testing.assert_allclose(table["frequency_hz"], res.frequency, rtol=1e-12)
    np.testing.assert_allclose(table["lowertheta"], res.shapes[5], rtol=1e-12)
    damped = np.genfromtxt(tmp_path / "damped.csv", delimiter=",", names=True)
    assert damped.size == 4
    text = res.summary()
    assert "2 free motion(s)" in text and "vibration" in text
    mot = res.motion(1, frames=9)
    assert mot.q.shape == (9, 6) and abs(mot.t[-1] - 1 / res.frequency[1]) < 1e-12
    np.testing.assert_allclose(mot.q[0], res.q)
    ax = res.plot(1)
    assert "mode 1" in ax.get_title()
    res.animate(0, tmp_path / "mode.gif", max_frames=8)
    assert (tmp_path / "mode.gif").stat().st_size > 1000


def damped_double_pendulum() -> mbd2d.Model:
    """The double pendulum with a torsion damper at the elbow and a spring at the top."""
    model = double_pendulum(1.5, 0.7, 0.9, 0.6, 0.11, 0.03)
    model.add_rotational_spring(["ground", "upper"], stiffness=4.0, damping=0.0, angle0=-1.6,
                                name="top_spring")
    model.add_rotational_spring(["upper", "lower"], stiffness=0.0, damping=0.3, angle0=0.0,
                                name="elbow_damper")
    return model


def double_pendulum_matrices(res: mbd2d.ModesResult) -> tuple[np.ndarray, ...]:
    """M, K, C of damped_double_pendulum in its absolute angles, by hand at res's rest
    position (K: gravity and the top spring; C: the elbow damper on theta2 - theta1), and the
    first-order form [0, I; -M^-1 K, -M^-1 C]."""
    m1, m2, l1, l2, i1, i2 = 1.5, 0.7, 0.9, 0.6, 0.11, 0.03
    th1 = res.q[2] + np.pi / 2            # the upper bar's angle from the vertical at rest
    th2 = res.q[5] + np.pi / 2
    a1, a2 = l1 / 2, l2 / 2
    c12 = np.cos(th1 - th2)
    mm = np.array([[i1 + m1 * a1**2 + m2 * l1**2, m2 * l1 * a2 * c12],
                   [m2 * l1 * a2 * c12, i2 + m2 * a2**2]])
    # V = -g ((m1 a1 + m2 l1) cos th1 + m2 a2 cos th2) + 2 (th1 - pi/2 + 1.6)^2; its Hessian
    # (the kinetic energy's change does not enter at rest)
    kk = np.array([[G * (m1 * a1 + m2 * l1) * np.cos(th1) + 4.0, 0.0],
                   [0.0, G * m2 * a2 * np.cos(th2)]])
    cc = 0.3 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    # the equilibrium itself: V' = 0 in both angles
    assert abs(G * (m1 * a1 + m2 * l1) * np.sin(th1) + 4.0 * (th1 - np.pi / 2 + 1.6)) < 1e-9
    assert abs(np.sin(th2)) < 1e-12
    a = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(mm, kk), -np.linalg.solve(mm, cc)]])
    return mm, kk, cc, a


def test_damped_double_pendulum_against_its_matrices() -> None:
    """The damped first-order form [0, I; -M^-1 K, -M^-1 C] with M, K, C written here."""
    res = damped_double_pendulum().modes()
    mm, kk, cc, a = double_pendulum_matrices(res)
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(mm, kk)).real)
    np.testing.assert_allclose(res.omega2, w2, rtol=1e-13)
    s = np.linalg.eigvals(a)
    s = np.array(sorted(s, key=lambda z: (abs(z), -z.imag)))
    np.testing.assert_allclose(res.eigenvalues, s, rtol=0, atol=1e-14 * abs(s).max())
    assert np.all(res.damping_ratio > 0) and np.all(res.damping_ratio < 1)


def by_modulus(s: np.ndarray, vec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and eigenvector columns in mbd2d's order: by |s|, then Im s descending."""
    order = sorted(range(s.size), key=lambda j: (abs(s[j]), -s[j].imag))
    return s[order], vec[:, order]


def test_damped_shapes_of_the_double_pendulum_against_its_matrices() -> None:
    """Each damped shape's angle ratio theta_upper / theta_lower is that of the eigenvector
    of the first-order form written by hand (complex: the damper puts the bars out of phase);
    the bars' centres follow their angles (the null space of J: dx = -a sin(theta) dtheta);
    the largest entry is 1."""
    res = damped_double_pendulum().modes()
    a = double_pendulum_matrices(res)[3]
    s, vec = by_modulus(*np.linalg.eig(a))
    np.testing.assert_allclose(res.eigenvalues, s, rtol=0, atol=1e-14 * abs(s).max())
    psi = res.damped_shapes
    assert psi.shape == (6, 4)
    for j in range(4):
        want = vec[0, j] / vec[1, j]
        assert abs(psi[2, j] / psi[5, j] - want) < 1e-13 * abs(want), j
        assert abs(np.angle(want)) > 0.02 and abs(abs(np.angle(want)) - np.pi) > 0.02
        np.testing.assert_array_equal(psi[np.argmax(abs(psi[:, j])), j], 1.0)
        th1, a1 = res.q[2], 0.45
        assert abs(psi[0, j] + a1 * np.sin(th1) * psi[2, j]) < 1e-12
        assert abs(psi[1, j] - a1 * np.cos(th1) * psi[2, j]) < 1e-12
        np.testing.assert_array_equal(res.damped_shape(j), psi[:, j])
    np.testing.assert_allclose(psi[:, 1::2], psi[:, 0::2].conj(), rtol=0, atol=1e-14)


def test_undamped_shapes_are_the_modes_scaled() -> None:
    """Without damping both eigenvalues +-i omega of a mode have its (real) shape, scaled to
    its largest entry."""
    res = double_pendulum(1.5, 0.7, 0.9, 0.6, 0.11, 0.03).modes()
    for k in range(2):
        phi = res.shapes[:, k]
        want = phi / phi[np.argmax(abs(phi))]
        for j in (2 * k, 2 * k + 1):
            np.testing.assert_array_equal(res.damped_shapes[:, j].imag, 0.0)
            np.testing.assert_allclose(res.damped_shapes[:, j].real, want, rtol=0, atol=1e-14)


def damped_chain(c: float, n: int = 2, m: float = 0.5, k: float = 200.0) -> mbd2d.Model:
    """spring_chain with a damper c from the ground to its last block only (non-proportional
    damping: the shapes are complex)."""
    model = spring_chain(n, m, k)
    model.add_spring(["ground", f"b{n}"], [[0.0, 0.0], [0.0, 0.0]], stiffness=0.0,
                     damping=c, length0=0.1 * n, name="damper")
    return model


@pytest.mark.parametrize("c", [3.0, 40.0])
def test_a_chain_damped_at_its_end(c: float) -> None:
    """Two blocks (M = m I, K = [[2k, -k], [-k, k]], C = diag(0, c)): the eigenvalues and the
    shapes' ratios x1 / x2 from numpy's eigenvectors of the first-order form; at c = 40 the
    second block is overdamped: its real eigenvalues have real shapes."""
    m, k = 0.5, 200.0
    res = damped_chain(c).modes()
    mm, kk, cc = m * np.eye(2), k * np.array([[2.0, -1.0], [-1.0, 1.0]]), np.diag([0.0, c])
    a = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(mm, kk), -np.linalg.solve(mm, cc)]])
    s, vec = by_modulus(*np.linalg.eig(a))
    scale = abs(s).max()
    np.testing.assert_allclose(res.eigenvalues, s, rtol=0, atol=1e-14 * scale)
    psi = res.damped_shapes
    for j in range(4):
        want = vec[0, j] / vec[1, j]
        assert abs(psi[0, j] / psi[3, j] - want) < 1e-13 * max(1.0, abs(want)), (j, want)
        if s[j].imag == 0.0:
            np.testing.assert_array_equal(psi[:, j].imag, 0.0)
    assert (np.count_nonzero(s.imag == 0.0) == 2) == (c == 40.0)


def test_damped_shapes_on_the_band_path() -> None:
    """A damped chain of 12 on the band path: the dense path's eigenvalues and shapes."""
    dense = damped_chain(5.0, n=12).modes(solver="dense")
    band = damped_chain(5.0, n=12).modes(solver="banded")
    assert band.stats["solver"] == "banded"
    np.testing.assert_allclose(band.eigenvalues, dense.eigenvalues, rtol=1e-14)
    np.testing.assert_allclose(band.damped_shapes, dense.damped_shapes, rtol=0, atol=1e-13)


def test_damped_shape_tables_and_pictures(tmp_path: Path) -> None:
    """The damped table's shape columns, a damped mode's motion (Re(psi e^(i w t)): a quarter
    period later -Im(psi)), its picture and animation, and a bad index."""
    pytest.importorskip("matplotlib")
    res = damped_double_pendulum().modes()
    header, rows = res.table(damped=True)
    assert header[5:8] == ["upper.x.re", "upper.x.im", "upper.y.re"]
    np.testing.assert_array_equal(rows[:, 5::2], res.damped_shapes.real.T)
    np.testing.assert_array_equal(rows[:, 6::2], res.damped_shapes.imag.T)
    mot = res.motion(0, amplitude=0.01, frames=5, damped=True)
    np.testing.assert_allclose(mot.q[0], res.q + 0.01 * res.damped_shapes[:, 0].real,
                               atol=1e-15)
    np.testing.assert_allclose(mot.q[1], res.q - 0.01 * res.damped_shapes[:, 0].imag,
                               atol=1e-12)
    assert abs(mot.t[-1] - 1 / res.damped_frequency[0]) < 1e-12
    assert "damped mode 2" in res.plot(2, damped=True).get_title()
    res.animate(1, tmp_path / "d.gif", damped=True, max_frames=6)
    assert (tmp_path / "d.gif").stat().st_size > 1000
    with pytest.raises(mbd2d.ModelError, match="damped eigenvalue 4 does not exist"):
        res.damped_shape(4)


def test_mbd2d_solve_writes_the_modes_python_writes(tmp_path: Path) -> None:
    """The standalone program: the modes table, the damped table, a count and a
    linearization about q0, to the last digit of Python's CSV."""
    from test_standalone import solve_file
    damped = damped_double_pendulum()
    up = pendulum(k=0.0, q0=f"0.0, 0.5, {np.pi / 2}")
    runs = [(damped, {}, damped.modes(), {}),
            (damped, {"outputs": ["damped"]}, damped.modes(), {"damped": True}),
            (spring_chain(7), {"count": 3, "solver": "banded"},
             spring_chain(7).modes(count=3, solver="banded"), {}),
            (up, {"equilibrium": False}, up.modes(equilibrium=False), {})]
    for k, (model, kw, res, csv_kw) in enumerate(runs):
        mbd = tmp_path / f"m{k}.mbd"
        model.export(mbd, analysis="modes", **kw)
        py = tmp_path / f"p{k}.csv"
        res.to_csv(py, **csv_kw)
        assert solve_file(mbd, tmp_path / f"f{k}.csv") == py.read_text()


@pytest.mark.parametrize("line, needle", [
    ("outputs energy", "modes takes no outputs"),
    ("count -1", "count must be"),
    ("at_q0 2", "at_q0 must be"),
    ("count 1.5", "count"),
])
def test_mbd2d_solve_refuses_bad_modes_settings(tmp_path: Path, line: str, needle: str) -> None:
    import subprocess

    from test_standalone import find_solver
    mbd = tmp_path / "m.mbd"
    pendulum().export(mbd, analysis="modes")
    mbd.write_text(mbd.read_text().replace("\nend\n", f"\n{line}\nend\n"))
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and needle in r.stderr and "Traceback" not in r.stderr


def test_export_refuses_what_modes_does_not_write(tmp_path: Path) -> None:
    with pytest.raises(mbd2d.ModelError, match="unknown output 'energy'"):
        pendulum().export(tmp_path / "m.mbd", analysis="modes", outputs=["energy"])
    with pytest.raises(mbd2d.ModelError, match="sensitivities"):
        pendulum().export(tmp_path / "m.mbd", analysis="modes",
                          sensitivities=["force.torsion.stiffness"])
    with pytest.raises(mbd2d.ModelError, match="unknown output 'damped'"):
        pendulum().export(tmp_path / "m.mbd", analysis="statics", outputs=["damped"])


def test_the_command_line(tmp_path: Path) -> None:
    """``mbd2d modes``: the summary, the CSVs Python writes, a picture; bad files are exit 2."""
    import subprocess
    import sys
    pytest.importorskip("matplotlib")
    toml = Path(__file__).parents[1] / "examples" / "pendulum_spring.toml"

    def cli(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "mbd2d", "modes", str(toml), *args],
                              capture_output=True, text=True, timeout=120)
    r = cli("--out", str(tmp_path / "m.csv"), "--damped-out", str(tmp_path / "d.csv"),
            "--picture", str(tmp_path / "m.png"))
    assert r.returncode == 0, r.stderr
    assert "1 free motion(s)" in r.stdout and "vibration" in r.stdout
    res = mbd2d.load(toml).modes()
    res.to_csv(tmp_path / "p.csv")
    res.to_csv(tmp_path / "pd.csv", damped=True)
    assert (tmp_path / "m.csv").read_text() == (tmp_path / "p.csv").read_text()
    assert (tmp_path / "d.csv").read_text() == (tmp_path / "pd.csv").read_text()
    assert (tmp_path / "m.png").stat().st_size > 1000
    r = cli("--damped-mode", "1", "--picture", str(tmp_path / "d.png"))
    assert r.returncode == 0 and "drew damped mode 1" in r.stdout, r.stderr
    assert (tmp_path / "d.png").stat().st_size > 1000
    for bad in (["--out", str(tmp_path / "m.txt")], ["--picture", str(tmp_path / "m.bmp")],
                ["--count", "0"], ["--mode", "3", "--picture", str(tmp_path / "x.png")],
                ["--damped-mode", "2", "--picture", str(tmp_path / "x.png")]):
        r = cli(*bad)
        assert r.returncode == 2 and "Traceback" not in r.stderr, (bad, r.stderr)


def ball_on_floor(law: str = "linear", k: float = 1e5, n: float = 1.0,
                  m: float = 2.0) -> mbd2d.Model:
    """A ball (radius 0.1) on a vertical guide above the floor, a contact law F = k d^n."""
    return mbd2d.loads(f"""
[model]
name = "ball"
gravity = [0.0, -9.81]
[[body]]
name = "ball"
q0 = [0.0, 0.1, 0.0]
mass = {m}
inertia = 0.01
[[joint]]
type = "translational"
name = "guide"
bodies = ["ground", "ball"]
points = [[0, 0], [0, 0]]
axes = [[0, 1], [0, 1]]
[[contact]]
name = "floor"
type = "circle-line"
bodies = ["ball", "ground"]
circle = {{ center = [0.0, 0.0], radius = 0.1 }}
line = {{ point = [0.0, 0.0], normal = [0.0, 1.0] }}
law = {{ model = "{law}", stiffness = {k}, exponent = {n}, restitution = 1.0 }}
""")


@pytest.mark.parametrize("law, n", [("linear", 1.0), ("hertz", 1.5)])
def test_a_ball_resting_on_a_contact(law: str, n: float) -> None:
    """A ball on a vertical guide resting on the floor through a contact law F = k d^n: at
    rest d = (m g / k)^(1/n), and omega^2 = n k d^(n - 1) / m (measured 1e-12 and 1.2e-9)."""
    m, k = 2.0, 1e5
    model = ball_on_floor(law, k, n, m)
    res = model.modes()
    d = (m * G / k)**(1 / n)
    assert abs(res.q[1] - (0.1 - d)) < 1e-12
    assert abs(res.omega2[0] / (n * k * d**(n - 1) / m) - 1) < 1e-8


# ------------------------------------------------------------------ sweeps of the modes

def half_car() -> mbd2d.Model:
    return mbd2d.load(Path(__file__).parents[1] / "examples" / "half_car.toml")


DAMPING = ("force.front_suspension.damping", "force.rear_suspension.damping")


def test_a_modes_sweep_is_every_variants_modes() -> None:
    """mbd2d.sweep(..., "modes"): every case's numbers are its own modes() bit for bit."""
    pytest.importorskip("xarray")
    model = half_car()
    cs = np.linspace(0.0, 3000.0, 5)
    cases = {DAMPING[0]: cs, DAMPING[1]: cs[::-1].copy(), "body.body.mass": cs / 10 + 400}
    ds = mbd2d.sweep(model, cases, "modes", workers=1, count=3)
    assert ds.sizes["mode"] == 3 and ds.sizes["eigenvalue"] == 6
    for j in range(len(cs)):
        res = model.with_params({k: float(v[j]) for k, v in cases.items()}).modes(count=3)
        np.testing.assert_array_equal(ds.omega2.values[j], res.omega2)
        np.testing.assert_array_equal(ds.frequency.values[j], res.frequency)
        np.testing.assert_array_equal(ds.kind.values[j], res.kind_codes)
        np.testing.assert_array_equal(ds.shape.values[j], res.shapes.T)
        np.testing.assert_array_equal(ds.s_real.values[j] + 1j * ds.s_imag.values[j],
                                      res.eigenvalues)
        np.testing.assert_array_equal(ds.damping_ratio.values[j], res.damping_ratio)
        np.testing.assert_array_equal(ds.damped_frequency.values[j], res.damped_frequency)
        np.testing.assert_array_equal(ds.q.values[j], res.q)
        assert ds.n_free.values[j] == 4 and ds.stability.values[j] == res.stability
        assert ds.residual.values[j] == res.residual and ds.status.values[j] == 0


def test_a_failing_variant_keeps_its_place() -> None:
    """A disc without inertia (a free motion without mass) in the middle of a sweep: its
    status and message are those modes() raises, the others run."""
    pytest.importorskip("xarray")
    model = disc_on_a_spring(0.5)
    ds = mbd2d.sweep(model, {"body.disc.inertia": [0.5, 0.0, 2.0]}, "modes", workers=1)
    with pytest.raises(mbd2d.MbdError) as err:
        model.with_params({"body.disc.inertia": 0.0}).modes()
    assert list(ds.status.values) == [0, err.value.status, 0]
    assert ds.message.values[1] == str(err.value) and "mass" in str(err.value)
    np.testing.assert_allclose(ds.omega2.values[[0, 2], 0], [2.0 / 0.5, 2.0 / 2.0], rtol=1e-14)
    assert np.isnan(ds.omega2.values[1]).all() and ds.n_free.values[1] == -1


def test_modes_sweep_files_and_command_line(tmp_path: Path) -> None:
    """write_sweep: .csv one row per case and mode, .nc the whole Dataset; mbd2d sweep
    --analysis modes writes the same CSV."""
    import subprocess
    import sys
    pytest.importorskip("xarray")
    model = half_car()
    cs = np.linspace(500.0, 2500.0, 3)
    ds = mbd2d.sweep(model, {DAMPING[0]: cs}, "modes", workers=1)
    mbd2d.write_sweep(ds, tmp_path / "s.csv")
    rows = np.genfromtxt(tmp_path / "s.csv", delimiter=",", names=True)
    assert rows.size == 3 * 4
    np.testing.assert_array_equal(rows["frequency_hz"].reshape(3, 4), ds.frequency.values)
    try:
        mbd2d.write_sweep(ds, tmp_path / "s.nc")
    except ImportError:
        pass
    else:
        import xarray as xr
        back = xr.open_dataset(tmp_path / "s.nc")
        np.testing.assert_array_equal(back.omega2.values, ds.omega2.values)
        back.close()
    toml = Path(__file__).parents[1] / "examples" / "half_car.toml"
    r = subprocess.run([sys.executable, "-m", "mbd2d", "sweep", str(toml), "--analysis", "modes",
                        "--param", f"{DAMPING[0]}=500:2500:3", "--workers", "1", "--out",
                        str(tmp_path / "c.csv")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "c.csv").read_text() == (tmp_path / "s.csv").read_text()


def test_what_a_modes_sweep_does_not_take(tmp_path: Path) -> None:
    pytest.importorskip("xarray")
    model = half_car()
    cases = {DAMPING[0]: [1000.0, 2000.0]}
    for kw, needle in (({"sensitivities": [DAMPING[1]]}, "no design sensitivities"),
                       ({"measures": ["dead_centre_distance"]}, "not of modes"),
                       ({"t_end": 1.0}, "settings are")):
        with pytest.raises(mbd2d.ModelError, match=needle):
            mbd2d.sweep(model, cases, "modes", workers=1, **kw)
    # (mbd2d.tolerance takes the modes, by Monte Carlo alone: tests/test_tolerance.py)


def test_mbd2d_solve_runs_a_modes_sweep_as_python(tmp_path: Path) -> None:
    """export_sweep(..., "modes") and mbd2d-solve: the CSV of write_sweep byte for byte (a
    count and a failing case among them; the failing case's status, with the program's own
    message, as for every sweep file)."""
    import csv

    from test_standalone import solve_file
    pytest.importorskip("xarray")
    model = half_car()
    cases = {DAMPING[0]: np.linspace(0.0, 3000.0, 4),
             "body.front_wheel.mass": [40.0, 30.0, 0.0, 50.0]}
    ds = mbd2d.sweep(model, cases, "modes", workers=1, count=3)
    assert list(ds.status.values != 0) == [False, False, True, False]
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    mbd2d.export_sweep(model, tmp_path / "s.mbd", cases, "modes", count=3)
    py = list(csv.reader((tmp_path / "py.csv").read_text().splitlines()))
    fo = list(csv.reader(solve_file(tmp_path / "s.mbd", tmp_path / "f.csv").splitlines()))
    assert len(py) == len(fo) == 1 + 3 * 3 + 1
    msg = py[0].index("message")
    for a, b in zip(py, fo):
        assert a[:msg] + a[msg + 1:] == b[:msg] + b[msg + 1:]
    failed = [row for row in fo if row[msg - 1] not in ("0", "status")]
    assert len(failed) == 1 and "mass" in failed[0][msg]
    good = tmp_path / "good.mbd"
    keep = {k: np.delete(np.asarray(v, dtype=float), 2) for k, v in cases.items()}
    mbd2d.export_sweep(model, good, keep, "modes", count=3)
    mbd2d.write_sweep(mbd2d.sweep(model, keep, "modes", workers=1, count=3),
                      tmp_path / "good_py.csv")
    assert solve_file(good, tmp_path / "good.csv") == (tmp_path / "good_py.csv").read_text()


# ------------------------------------------------------------------ more joints' stiffness

def joint_model(body_text: str, joint_text: str, force_text: str,
                gravity: float = -G) -> mbd2d.Model:
    return mbd2d.loads(f"""
[model]
name = "joint-mode"
gravity = [0.0, {gravity}]
{body_text}
{joint_text}
{force_text}
""")


def rolling_disc(m: float, inertia: float, r: float, k: float, c: float = 0.0) -> mbd2d.Model:
    """A disc (m, I, r) rolling without slip on the floor, tied by a horizontal spring-damper
    (k, c; free length 0.3) at its centre; gravity holds it on the floor."""
    return joint_model(f"""
[[body]]
name = "disc"
q0 = [0.4, {r + 0.01}, 0.0]
mass = {m}
inertia = {inertia}""", f"""
[[joint]]
type = "rolling-disc"
name = "floor"
bodies = ["disc", "ground"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = {r}""", f"""
[[force]]
type = "spring"
name = "s"
bodies = ["ground", "disc"]
points = [[0.0, {r}], [0.0, 0.0]]
stiffness = {k}
damping = {c}
length0 = 0.3""")


def test_a_disc_rolling_on_a_spring() -> None:
    """A disc (m, I, r) rolling without slip on the floor, tied by a horizontal spring k at
    its centre: omega^2 = k / (m + I / r^2); gravity holds it on the floor."""
    m, inertia, r, k = 2.0, 0.03, 0.15, 50.0
    res = rolling_disc(m, inertia, r, k).modes()
    assert res.n_free == 1 and abs(res.q[0] - 0.3) < 1e-12 and abs(res.q[1] - r) < 1e-12
    assert abs(res.omega2[0] / (k / (m + inertia / r**2)) - 1) < 1e-13
    phi = res.shape(0)
    assert abs(phi[2] + phi[0] / r) < 1e-12 * abs(phi[2])        # rolls: d theta = -dx / r


def gear_pair(r1: float, r2: float, i1: float, i2: float, k: float,
              c: float = 0.0) -> mbd2d.Model:
    """Gears R1, R2 (a pinion and a wheel) on ground pivots, the pinion held by a torsion
    spring-damper (k, c) at angle 0."""
    return joint_model(f"""
[[body]]
name = "pinion"
q0 = [0, 0, 0.1]
mass = 1.0
inertia = {i1}
[[body]]
name = "wheel"
q0 = [{r1 + r2}, 0, 0.4]
mass = 3.0
inertia = {i2}""", f"""
[[joint]]
type = "revolute"
name = "p1"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "revolute"
name = "p2"
bodies = ["ground", "wheel"]
points = [[{r1 + r2}, 0], [0, 0]]
[[joint]]
type = "gear"
name = "mesh"
bodies = ["pinion", "wheel"]
radii = [{r1}, {r2}]""", f"""
[[force]]
type = "rotational-spring"
name = "k"
bodies = ["ground", "pinion"]
stiffness = {k}
damping = {c}
angle0 = 0.0""")


def test_a_gear_pair_on_a_torsion_spring() -> None:
    """Gears R1, R2 on ground pivots, the first held by a torsion spring k:
    omega^2 = k / (I1 + I2 (R1 / R2)^2)."""
    r1, r2, i1, i2, k = 0.5, 1.5, 0.02, 0.3, 8.0
    res = gear_pair(r1, r2, i1, i2, k).modes()
    assert res.n_free == 1
    assert abs(res.omega2[0] / (k / (i1 + i2 * (r1 / r2)**2)) - 1) < 1e-13
    phi = res.shape(0)
    assert abs(phi[5] / phi[2] + r1 / r2) < 1e-12                   # the mesh: -R1/R2


def rack_pinion(m: float, inertia: float, r: float, k: float, c: float = 0.0) -> mbd2d.Model:
    """A rack (m) on a guide under a pinion (I, r) on a ground pivot, the rack on a
    spring-damper (k, c; free length 0.5)."""
    return joint_model(f"""
[[body]]
name = "pinion"
q0 = [0, 0, 0]
mass = 0.5
inertia = {inertia}
[[body]]
name = "rack"
q0 = [0, {-r}, 0]
mass = {m}
inertia = 0.1""", f"""
[[joint]]
type = "revolute"
name = "pivot"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "translational"
name = "guide"
bodies = ["ground", "rack"]
points = [[0, {-r}], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
type = "rack-pinion"
name = "teeth"
bodies = ["pinion", "rack"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = {r}""", f"""
[[force]]
type = "spring"
name = "s"
bodies = ["ground", "rack"]
points = [[-0.5, {-r}], [0.0, 0.0]]
stiffness = {k}
damping = {c}
length0 = 0.5""")


def test_a_rack_on_a_spring_turning_a_pinion() -> None:
    """A rack (m) on a guide under a pinion (I, r) on a ground pivot, the rack on a spring k:
    omega^2 = k / (m + I / r^2)."""
    m, inertia, r, k = 1.5, 0.01, 0.3, 40.0
    res = rack_pinion(m, inertia, r, k).modes()
    assert res.n_free == 1
    assert abs(res.omega2[0] / (k / (m + inertia / r**2)) - 1) < 1e-13


def distance_bob(q0: str = "0.2, -0.75, 0.3", length: float = 0.8) -> mbd2d.Model:
    """A bob (2 kg) hung from the origin by a massless rod: a distance joint to its centre."""
    return joint_model(f"""
[[body]]
name = "bob"
q0 = [{q0}]
mass = 2.0
inertia = 0.05""", f"""
[[joint]]
type = "distance"
name = "rod"
bodies = ["ground", "bob"]
points = [[0, 0], [0, 0]]
distance = {length}""", "")


def test_a_pendulum_on_a_distance_joint() -> None:
    """A bob hung by a massless rod (a distance joint L from a ground point to its centre):
    its swing omega^2 = g / L, and its spin about its own centre a motion without stiffness
    ("rigid")."""
    length = 0.8
    model = distance_bob(length=length)
    res = model.modes()
    assert res.n_free == 2 and res.kinds == ["rigid", "vibration"]
    assert abs(res.q[0]) < 1e-12 and abs(res.q[1] + length) < 1e-12
    assert abs(res.omega2[1] / (G / length) - 1) < 1e-13
    assert abs(res.omega2[0]) <= 1e-13 * res.omega2[1]


def bead_in_slot(radius: float) -> mbd2d.Model:
    """A bead (0.4 kg, its spin locked) in a circular slot of radius R whose lowest point is
    the origin."""
    return joint_model("""
[[body]]
name = "bead"
q0 = [0.3, 0.05, 0.0]
mass = 0.4
inertia = 0.001""", f"""
[[joint]]
type = "point-on-curve"
name = "slot"
bodies = ["ground", "bead"]
curve = {{ circle = {{ center = [0, {radius}], radius = {radius} }} }}
point = [0, 0]
[[joint]]
type = "absolute"
name = "no_spin"
body = "bead"
coordinate = "theta"
""", "")


def test_a_bead_in_a_circular_slot() -> None:
    """A bead (its spin locked) in a circular slot of radius R, the slot's lowest point at
    the origin: omega^2 = g / R; the joint's extra coordinate (the point's place on the
    curve, massless) moves with it."""
    radius = 1.2
    res = bead_in_slot(radius).modes()
    assert res.n_free == 1 and abs(res.q[0]) < 1e-12 and abs(res.q[1]) < 1e-12
    assert abs(res.omega2[0] / (G / radius) - 1) < 1e-13
    phi = res.shape(0)
    assert abs(phi[3] - phi[0] / radius) < 1e-13 * abs(phi[3])     # d alpha = dx / R


def test_the_null_basis_for_every_chain_size() -> None:
    """Every fixed-free chain of 1 to 80 blocks has its closed-form spectrum (dense path up to
    19 blocks, band path from 20). The null basis' pseudo-random vectors were linear
    congruential, seeded k apart: affine in k modulo 2^31, exactly dependent on the free
    coordinates of 22 of the first 150 sizes (5, 13-16, 48-64): no basis, so no modes, no
    frequency response, no band-path statics and no partitioned step there."""
    worst = 0.0
    for n in range(1, 81):
        res = spring_chain(n).modes()
        j = np.arange(1, n + 1)
        want = 2 * np.sqrt(200.0 / 0.5) * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))
        worst = max(worst, float(np.max(np.abs(res.omega - want) / want)))
    assert worst < 1e-11


@pytest.mark.parametrize("n", [5, 14, 48, 56, 64])
def test_partitioned_steps_of_chains_the_old_basis_could_not_take(n: int) -> None:
    """The last block of the chain pulled by 1 cm and let go: the partitioned method (band
    path: its coordinates chosen from the null basis) against the linear chain's exact
    motion x(t) = V cos(Omega t) V^T M x0 (numpy's eigendecomposition of M^-1 K)."""
    m, k = 0.5, 200.0
    model = spring_chain(n, m, k)
    x0 = np.zeros(n)
    x0[-1] = 0.01
    model.bodies[-1].q0 = (model.bodies[-1].q0[0] + x0[-1], 0.0, 0.0)
    res = model.dynamics(t_end=0.05, steps=5, method="partitioned", solver="banded",
                         rtol=1e-10, atol=1e-12)
    kk = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kk[-1, -1] = k
    w2, v = np.linalg.eigh(kk / m)                  # M = m I: V orthonormal
    exact = np.array([v @ (np.cos(np.sqrt(w2) * t) * (v.T @ x0)) for t in res.t])
    x = res.q[:, 0::3] - 0.1 * np.arange(1, n + 1)
    np.testing.assert_allclose(x, exact, rtol=0, atol=1e-9)


@pytest.mark.parametrize("n", [3, 5, 13, 30, 48, 60])
def test_a_massless_block_in_a_chain_is_refused_at_every_size(n: int) -> None:
    """One block of the chain without mass: its free motion has none, so M_r is singular in
    exact arithmetic; the modes and the linearized system refuse it (SingularJacobianError
    naming the mass), whatever the basis. Found with the new null basis: the half car's
    massless wheel then gave a Cholesky factor with a pivot of 4e-18 of M_r's largest entry
    instead of an exact zero, and a mode at 9.6e9 rad/s; the pivots are now judged against
    1e-12 of that entry. The frequency response has no inverse of M_r and answers: the
    tridiagonal (K - Omega^2 M) x = k e1 with that block's mass zero, solved here."""
    model = spring_chain(n)
    model.bodies[n // 2].mass = 0.0
    with pytest.raises(mbd2d.SingularJacobianError, match="carries no mass"):
        model.modes()
    with pytest.raises(mbd2d.SingularJacobianError, match="carries no mass"):
        model.linearize("force.s1.length0")
    f = np.linspace(0.0, 4.0, 9)                  # (from 16 free motions: M_r^-1 is refused
    res = model.frequency_response("force.s1.length0", f)     # by the Hessenberg path too)
    m, k = 0.5, 200.0
    kk = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kk[-1, -1] = k
    mm = m * np.eye(n)
    mm[n // 2, n // 2] = 0.0
    for j, fj in enumerate(f):                    # the spring s1 pushes b1 by k per unit
        want = np.linalg.solve(kk - (2 * np.pi * fj)**2 * mm, k * np.eye(n)[0])
        np.testing.assert_allclose(res.response[j, 0::3, 0], want, rtol=1e-9,
                                   atol=1e-12 * np.abs(want).max())
