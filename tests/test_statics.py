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


# ---------------------------------------------------------------------------------------------
# Convergence on the equilibrium equations (issue 9, item 1): the angle to 1e-13 from every
# start, at any height of the pivot (a constant added to V), against a root found here.

def bisect(f, a: float, b: float) -> float:
    """A root of f in [a, b] (f(a) f(b) < 0) by bisection until the interval stops shrinking:
    an independent solver whose answer is limited only by the rounding of f."""
    fa = f(a)
    assert fa * f(b) < 0.0
    while True:
        c = 0.5 * (a + b)
        if not a < c < b:
            return c
        fc = f(c)
        if fc == 0.0:
            return c
        if (fc < 0.0) == (fa < 0.0):
            a, fa = c, fc
        else:
            b = c


BAR_M, BAR_L, BAR_K, BAR_A0, G = 2.0, 1.0, 40.0, 1.0, 9.81


def bar_on_spring(theta0: float, y0: float) -> mbd2d.Model:
    """A bar (2 kg, 1 m) pivoted at one end at (0, y0) with a rotational spring to ground
    (40 N m/rad, free at 1 rad), started at theta0."""
    m = mbd2d.Model("bar", gravity=(0.0, -G))
    h = BAR_L / 2
    m.add_body("bar", (h * math.cos(theta0), y0 + h * math.sin(theta0), theta0), mass=BAR_M,
               inertia=BAR_M * BAR_L**2 / 12)
    m.add_revolute(["ground", "bar"], [[0.0, y0], [-h, 0.0]], name="pivot")
    m.add_rotational_spring(["ground", "bar"], stiffness=BAR_K, angle0=BAR_A0)
    return m


def bar_moment(th: float) -> float:
    """Moment about the pivot of the spring and the weight: k (theta - a0) + m g (L/2) cos."""
    return BAR_K * (th - BAR_A0) + BAR_M * G * (BAR_L / 2) * math.cos(th)


@pytest.mark.parametrize("y0", [0.0, 1000.0])
def test_equilibrium_to_round_off_from_every_start(y0: float) -> None:
    """31 starts in [0, 1.5] rad all reach the one equilibrium to 1e-13 rad, with the
    reduced load at round-off; raising the pivot by 1000 m (V + m g 1000) changes nothing.
    Before the fix (a step accepted only when V fell): 6 starts 2e-10 to 6e-9 rad off, and at
    y0 = 1000 six ConvergenceErrors."""
    root = bisect(bar_moment, 0.0, 1.5)
    for th0 in np.linspace(0.0, 1.5, 31):
        st = bar_on_spring(float(th0), y0).statics()
        x, y, th = st.body("bar")
        assert st.stability == "stable"
        assert abs(th - root) <= 1e-13, (th0, th - root)
        assert abs(bar_moment(th)) <= 1e-12                  # N m, independent residual
        assert st.residual <= 1e-14          # the core's ||N^T Q|| relative to the loads
        h = BAR_L / 2
        assert_allclose([x, y], [h * math.cos(root), y0 + h * math.sin(root)], atol=1e-12,
                        rtol=0)
        # the pivot carries the weight
        r = st.reaction("pivot")
        assert_allclose([r.fx_j[0], r.fy_j[0]], [0.0, BAR_M * G], atol=1e-9)


def gravity_slider_crank(theta0: float, y0: float, torque: float = 2.0) -> mbd2d.Model:
    """The offset slider-crank (crank 1, rod 3, guide 0.5 above the pivot) lifted by y0, under
    gravity (1 kg bodies, centres at mid-length), a crank torque and a slider spring
    (k = 50, free length 1.5) to an anchor at (6, y0 + 0.5); started near crank angle theta0."""
    m = mbd2d.Model("slider-crank", gravity=(0.0, -G))
    c, s = math.cos(theta0), math.sin(theta0)
    xb = c + math.sqrt(9.0 - (s - 0.5)**2)
    phi = math.atan2(0.5 - s, xb - c)
    m.add_body("crank", (0.5 * c, y0 + 0.5 * s, theta0), mass=1.0, inertia=0.1)
    m.add_body("rod", (0.5 * (c + xb), y0 + 0.5 * (s + 0.5), phi), mass=1.0, inertia=0.1)
    m.add_body("slider", (xb, y0 + 0.5, 0.0), mass=1.0, inertia=0.1)
    m.add_revolute(["ground", "crank"], [[0.0, y0], [-0.5, 0.0]], name="O")
    m.add_revolute(["crank", "rod"], [[0.5, 0.0], [-1.5, 0.0]], name="A")
    m.add_revolute(["rod", "slider"], [[1.5, 0.0], [0.0, 0.0]], name="B")
    m.add_translational(["ground", "slider"], [[0.0, y0 + 0.5], [0.0, 0.0]],
                        [[1.0, 0.0], [1.0, 0.0]], name="guide")
    m.add_torque("crank", torque)
    m.add_spring(["slider", "ground"], [[0.0, 0.0], [6.0, y0 + 0.5]], stiffness=50.0,
                 length0=1.5)
    return m


def slider_crank_load(th: float, torque: float = 2.0) -> float:
    """-dV/dtheta in the crank angle alone (reduced coordinate): with
    x = cos th + sqrt(9 - (sin th - 0.5)^2), V = k (4.5 - x)^2 / 2 - T th + g (sin th + const)
    (crank centre at height sin(th)/2, rod centre at (sin th + 0.5)/2)."""
    s, c = math.sin(th), math.cos(th)
    r = math.sqrt(9.0 - (s - 0.5)**2)
    x = c + r
    dx = -s - (s - 0.5) * c / r
    return torque + 50.0 * (4.5 - x) * dx - G * c


@pytest.mark.parametrize("y0, tol", [(0.0, 1e-13), (1000.0, 4e-13)])
def test_slider_crank_equilibrium_against_reduced_coordinates(y0: float, tol: float) -> None:
    """Three bodies, five joint equations: every start reaches an equilibrium of the reduced
    equation dV/dtheta = 0 (solved here by bisection) to 1e-13 rad. Lifted to y0 = 1000 m
    the positions round to 1.1e-13 m, and the crank angle (1 m crank) follows them: 4e-13."""
    grid = np.linspace(-math.pi, math.pi, 721)
    vals = [slider_crank_load(float(a)) for a in grid]
    roots = [bisect(slider_crank_load, float(grid[i]), float(grid[i + 1]))
             for i in range(len(grid) - 1) if vals[i] * vals[i + 1] < 0]
    # stable ones: -dV/dtheta falls through zero
    stable = [r for r in roots if slider_crank_load(r - 1e-6) > 0 > slider_crank_load(r + 1e-6)]
    assert stable
    for th0 in np.linspace(-1.0, 1.0, 9):
        st = gravity_slider_crank(float(th0), y0).statics()
        th = st.body("crank")[2]
        wrapped = math.remainder(th, 2 * math.pi)
        err = min(abs(wrapped - r) for r in stable)
        assert err <= tol, (th0, err)
        assert st.stability == "stable"
        assert abs(slider_crank_load(wrapped)) <= 1e-11
        s, c = math.sin(th), math.cos(th)
        assert_allclose(st.body("slider")[0], c + math.sqrt(9.0 - (s - 0.5)**2), atol=1e-12)
        assert st.residual <= 1e-14


def test_springs_at_their_natural_lengths_are_an_equilibrium() -> None:
    """A chain of blocks on guides tied by springs at their natural lengths: q0 is the
    equilibrium, though the loads there are of round-off size (i * 0.1 is not exact); the
    residual is measured against the stiffness times the model's size, not those loads (it
    was "no equilibrium found, the unbalanced load is 1.0 times the loads")."""
    from test_modes import spring_chain
    for n, solver in ((6, "dense"), (40, "banded")):
        model = spring_chain(n)
        res = model.statics(solver=solver)
        q0 = np.concatenate([b.q0 for b in model.bodies])
        np.testing.assert_allclose(res.q, q0, rtol=0, atol=1e-15)
        assert res.stability == "stable" and res.residual < 1e-12


@pytest.mark.parametrize("solver", ["dense", "banded"])
def test_a_bob_on_a_distance_joint_settles_below_its_pivot(solver: str) -> None:
    """A bob on a massless rod (distance joint) hangs straight down (x = 0, y = -L, its spin
    free and kept). On the band path the basis of the free motions weighted each coordinate
    by its column of J, and the x column, 1e-17 there, made the matrix singular: an internal
    error ("MBD_LAPACK ... a bug")."""
    from test_modes import distance_bob
    model = distance_bob()
    res = model.statics(solver=solver)
    assert_allclose(res.q, [0.0, -0.8, 0.3], atol=1e-12)
    assert res.stats["solver"] == solver


# ---------------------------------------------------------------------------------------------
# Many free motions: a hanging chain of rigid links between two supports against the discrete
# catenary, solved here without mbd2d, from a V-shaped start. The statics' Newton steps take
# the exact stiffness (the design sensitivities' second derivatives), on K's sparse pattern when
# there are more free motions than its colour groups (the band cases here).

CHAIN_LENGTH, CHAIN_SPAN, LINK_MASS = 1.5, (1.0, 0.2), 0.1


def hanging_chain(n: int, start: np.ndarray | None = None) -> mbd2d.Model:
    """n uniform links (total length 1.5 m, 0.1 kg each) pinned end to end, the first to
    ground at (0, 0), the last at (1, 0.2); started at the link angles start, by default
    as a V (the assembly closes it)."""
    link = CHAIN_LENGTH / n
    m = mbd2d.Model("chain", gravity=(0.0, -G))
    a = math.acos(CHAIN_SPAN[0] / CHAIN_LENGTH)
    x = y = 0.0
    for i in range(n):
        th = (-a if i < n // 2 else a) if start is None else float(start[i])
        c, s = math.cos(th), math.sin(th)
        m.add_body(f"l{i}", (x + 0.5 * link * c, y + 0.5 * link * s, th), mass=LINK_MASS,
                   inertia=LINK_MASS * link**2 / 12)
        x, y = x + link * c, y + link * s
    m.add_revolute(["ground", "l0"], [[0.0, 0.0], [-link / 2, 0.0]], name="A")
    for i in range(n - 1):
        m.add_revolute([f"l{i}", f"l{i + 1}"], [[link / 2, 0.0], [-link / 2, 0.0]])
    m.add_revolute([f"l{n - 1}", "ground"], [[link / 2, 0.0], list(CHAIN_SPAN)], name="B")
    return m


def discrete_catenary(n: int) -> tuple[np.ndarray, float]:
    """The links' angles and the horizontal tension H. Each link's end forces differ by its
    weight w and their sum lies along it (moments about its centre), so with H constant
    tan(theta_i) = c0 + c1 (i - 1/2), c1 = w / H; (c0, c1) from the span by Newton with the
    exact 2 x 2 Jacobian, to round-off."""
    link = CHAIN_LENGTH / n
    i = np.arange(1, n + 1) - 0.5
    c = np.array([-1.0, 2.0 / n])
    for _ in range(100):
        tan = c[0] + c[1] * i
        th = np.arctan(tan)
        f = link * np.array([np.cos(th).sum() - CHAIN_SPAN[0] / link,
                             np.sin(th).sum() - CHAIN_SPAN[1] / link])
        d = 1.0 / (1.0 + tan**2)                   # d theta / d tan
        jac = link * np.array([[-(np.sin(th) * d).sum(), -(np.sin(th) * d * i).sum()],
                               [(np.cos(th) * d).sum(), (np.cos(th) * d * i).sum()]])
        step = np.linalg.solve(jac, f)
        c -= step
        if np.abs(step).max() <= 1e-16 * max(1.0, np.abs(c).max()):
            break
    return np.arctan(c[0] + c[1] * i), LINK_MASS * G / c[1]


@pytest.mark.parametrize("n, solver", [(10, "dense"), (40, "dense"), (40, "banded"),
                                       (120, "banded")])
def test_hanging_chain_against_the_discrete_catenary(n: int, solver: str) -> None:
    """Every link's angle to 1e-13 rad (measured 8.9e-16 to 3.3e-14), its centre to 1e-13 m,
    the supports' reactions to the tension H and the chain's weight to 1e-13 relative
    (measured 5.4e-15 at most), stable; n - 2 free motions."""
    theta, tension = discrete_catenary(n)
    st = hanging_chain(n).statics(solver=solver)
    assert st.stability == "stable" and st.residual <= 1e-13
    got = np.array([st.body(f"l{i}")[2] for i in range(n)])
    assert np.abs(np.remainder(got - theta + math.pi, 2 * math.pi) - math.pi).max() <= 1e-13
    link = CHAIN_LENGTH / n
    ends = np.concatenate([[0.0], np.cumsum(np.cos(theta))]) * link
    heights = np.concatenate([[0.0], np.cumsum(np.sin(theta))]) * link
    centres = np.array([st.body(f"l{i}")[:2] for i in range(n)])
    assert_allclose(centres[:, 0], 0.5 * (ends[:-1] + ends[1:]), rtol=0, atol=1e-13)
    assert_allclose(centres[:, 1], 0.5 * (heights[:-1] + heights[1:]), rtol=0, atol=1e-13)
    a, b = st.reaction("A"), st.reaction("B")      # on the first link, on the last
    weight = n * LINK_MASS * G
    assert_allclose([a.fx_j[0], b.fx[0]], [-tension, tension], rtol=1e-13)
    assert_allclose(a.fy_j[0] + b.fy[0], weight, rtol=1e-13)


@pytest.mark.parametrize("n, solver", [(10, "dense"), (40, "banded")])
def test_hanging_chain_comes_down_from_an_arch(n: int, solver: str) -> None:
    """Started far away, as an arch over the chord (the catenary's angles mirrored about it,
    slightly disturbed: links up to 2.6 rad off), the saddle-free steps come down through
    n - 2 free motions to the hanging catenary, to the same 1e-13 rad."""
    theta, _ = discrete_catenary(n)
    chord = math.atan2(CHAIN_SPAN[1], CHAIN_SPAN[0])
    arch = 2 * chord - theta + 0.1 * np.random.default_rng(1).normal(size=n)
    st = hanging_chain(n, arch).statics(solver=solver)
    got = np.array([st.body(f"l{i}")[2] for i in range(n)])
    assert st.stability == "stable"
    assert np.abs(np.remainder(got - theta + math.pi, 2 * math.pi) - math.pi).max() <= 1e-13


def vertical_chain(n: int, m: float = 0.5, k: float = 200.0) -> mbd2d.Model:
    """n blocks on vertical guides, each hanging from the one above by a spring (k, free
    length 0.1), the first from the ground at y = 0; started 1 cm above the equilibrium."""
    parts = ["[model]", 'name = "vertical chain"', f"gravity = [0.0, {-G}]"]
    y = 0.0
    for i in range(1, n + 1):
        y -= 0.1 + (n - i + 1) * m * G / k
        above = "ground" if i == 1 else f"b{i - 1}"
        parts += ["[[body]]", f'name = "b{i}"', f"q0 = [0.0, {y + 0.01}, 0.0]", f"mass = {m}",
                  "inertia = 0.001", "[[joint]]", 'type = "translational"', f'name = "g{i}"',
                  f'bodies = ["ground", "b{i}"]', "points = [[0.0, 0.0], [0.0, 0.0]]",
                  "axes = [[0, 1], [0, 1]]", "[[force]]", 'type = "spring"', f'name = "s{i}"',
                  f'bodies = ["{above}", "b{i}"]', "points = [[0.0, 0.0], [0.0, 0.0]]",
                  f"stiffness = {k}", "damping = 0.0", "length0 = 0.1"]
    return mbd2d.loads("\n".join(parts))


def test_statics_sensitivities_of_a_hanging_chain_at_every_size() -> None:
    """Spring j carries the blocks j..n, T_j = (n - j + 1) m g, so y_i = -sum_{j <= i}
    (0.1 + T_j / k_j) and dy_i/dk_j = T_j / k_j^2 for j <= i: every size from 1 to 60 blocks,
    dense and band paths, positions to 1e-12 m and the sensitivities to 1e-10 relative
    (measured 5.7e-14 and 9.0e-13 to 80 blocks). With the null basis' old pseudo-random
    vectors the band path failed at 5 of these sizes (4, 6, ...: an internal error)."""
    m, k = 0.5, 200.0
    for n in range(1, 61):
        js = sorted({1, (n + 1) // 2, n})
        tension = (n - np.arange(1, n + 1) + 1) * m * G
        y = -np.cumsum(0.1 + tension / k)
        want = np.zeros((n, len(js)))
        for c, j in enumerate(js):
            want[j - 1:, c] = tension[j - 1] / k**2
        for solver in ("dense", "banded"):
            st = vertical_chain(n, m, k).statics(
                sensitivities=[f"force.s{j}.stiffness" for j in js], solver=solver)
            assert np.abs(st.q[1::3] - y).max() <= 1e-12, (n, solver)
            assert np.abs(st.dq_dp[1::3] - want).max() <= 1e-10 * np.abs(want).max(), \
                (n, solver)
