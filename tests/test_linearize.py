"""The linearized system x' = A x + B p, dq = C x + D p (Model.linearize) against references
computed here without mbd2d: transfer functions of closed forms (a mass on a spring-damper
pushed, or moved through its base: a rate input; a pendulum on a cart: an acceleration input)
at points of the complex plane, the poles against the characteristic polynomials, the time
response against mbd2d's nonlinear dynamics (exact for the linear block; errors falling as the
square of the amplitude for the pendulum), and the CSV of every front door."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from test_modes import G
from test_sweep_frf import held_block

M_BLOCK, K, C_D = 2.0, 36.0, 1.5                  # held_block's block, spring, damper
M_BAR, L_BAR, M_CART = 1.3, 0.8, 2.0
S_POINTS = np.array([0.0, 0.7j, 2.5j, 0.3 + 2.0j, -0.2 + 11.0j])


def cart_pendulum(eps: float = 0.0, w: float = 3.0) -> mbd2d.Model:
    """A bar (m 1.3, L 0.8) hanging from a pin on a cart that a driver moves along x:
    x_c = eps (1 - cos w t) (eps = 0: held at 0)."""
    m = mbd2d.Model("cart pendulum", gravity=(0.0, -G))
    m.add_body("cart", (0.0, 0.0, 0.0), mass=M_CART, inertia=0.1)
    m.add_body("bar", (0.0, -L_BAR / 2, -np.pi / 2), mass=M_BAR, inertia=M_BAR * L_BAR**2 / 12)
    m.add_translational(["ground", "cart"], [[0.0, 0.0], [0.0, 0.0]], [[1, 0], [1, 0]],
                        name="rail")
    m.add_revolute(["cart", "bar"], [[0.0, 0.0], [-L_BAR / 2, 0.0]], name="pin")
    f = {"poly": [eps], "harmonic": [{"amplitude": -eps, "omega": w, "phase": np.pi / 2}]} \
        if eps else {"poly": [0.0]}
    m.add_driver("absolute", f, body="cart", coordinate="x", name="shake")
    return m


def transfer(sys_: mbd2d.LinearizedSystem, s: complex) -> np.ndarray:
    """C (s I - A)^-1 B + D (numpy)."""
    n = sys_.a.shape[0]
    return sys_.c @ np.linalg.solve(s * np.eye(n) - sys_.a, sys_.b) + sys_.d


def out(sys_: mbd2d.LinearizedSystem, name: str) -> int:
    return sys_.outputs.index(name)


def test_a_pushed_block_is_a_mass_on_a_spring_damper() -> None:
    """The push on the block: 1 / (m s^2 + c s + k) for block.y at five points s, nothing
    for the held base; the poles are the roots of m s^2 + c s + k; no feedthrough."""
    sys_ = held_block().linearize("force.push.fy.poly.0")
    assert sys_.n_free == 1 and sys_.a.shape == (2, 2) and sys_.states == ["z1", "v1"]
    assert sys_.inputs == ["force.push.fy.poly.0"] and sys_.stability == "stable"
    y, yb = out(sys_, "block.y"), out(sys_, "base.y")
    for s in S_POINTS:
        g = transfer(sys_, s)[:, 0]
        np.testing.assert_allclose(g[y], 1 / (M_BLOCK * s**2 + C_D * s + K), rtol=1e-13)
        assert abs(g[yb]) == 0.0
    poles = np.sort_complex(np.linalg.eigvals(sys_.a))
    np.testing.assert_allclose(poles, np.sort_complex(np.roots([M_BLOCK, C_D, K])), rtol=1e-13)
    assert np.abs(sys_.d).max() == 0.0


def test_a_base_motion_enters_through_its_rate() -> None:
    """The held base moved by its driver's offset u: the block follows through the spring
    and the damper, (k + c s) / (m s^2 + c s + k), and the base moves with u (D = 1); with
    gravity as a second input, g's column is m / (m s^2 + c s + k) per unit g_y."""
    sys_ = held_block().linearize(["driver.hold.f.poly.0", "model.gravity.1"])
    y, yb = out(sys_, "block.y"), out(sys_, "base.y")
    for s in S_POINTS:
        g = transfer(sys_, s)
        den = M_BLOCK * s**2 + C_D * s + K
        np.testing.assert_allclose(g[y, 0], (K + C_D * s) / den, rtol=1e-13)
        np.testing.assert_allclose(g[yb, 0], 1.0, rtol=1e-15)
        np.testing.assert_allclose(g[y, 1], M_BLOCK / den, rtol=1e-13)
    assert sys_.d[yb, 0] == 1.0 and abs(sys_.d[y, 0]) < 1e-15


def test_a_shaken_pendulum_enters_through_its_acceleration() -> None:
    """A pendulum on a cart moved by x_c: (I + m a^2) phi'' + m g a phi = -m a x_c'', so
    phi / x_c = -m a s^2 / ((I + m a^2) s^2 + m g a), whose value at infinity is the
    feedthrough D = -m a / (I + m a^2); the cart's x follows x_c (D = 1)."""
    sys_ = cart_pendulum().linearize("driver.shake.f.poly.0")
    a, inertia = L_BAR / 2, M_BAR * L_BAR**2 / 12
    th, xc = out(sys_, "bar.theta"), out(sys_, "cart.x")
    for s in S_POINTS:
        g = transfer(sys_, s)[:, 0]
        want = -M_BAR * a * s**2 / ((inertia + M_BAR * a**2) * s**2 + M_BAR * G * a)
        np.testing.assert_allclose(g[th], want, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(g[xc], 1.0, rtol=1e-15)
    np.testing.assert_allclose(sys_.d[th, 0], -M_BAR * a / (inertia + M_BAR * a**2), rtol=1e-14)
    w2 = M_BAR * G * a / (inertia + M_BAR * a**2)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(sys_.a).imag),
                               [-np.sqrt(w2), np.sqrt(w2)], rtol=1e-13)


def _linear_response(sys_: mbd2d.LinearizedSystem, p: callable, t: np.ndarray) -> np.ndarray:
    """dq(t) of the state-space system from rest under p(t) (scipy DOP853 at 1e-13)."""
    from scipy.integrate import solve_ivp
    sol = solve_ivp(lambda tt, x: sys_.a @ x + sys_.b[:, 0] * p(tt), (t[0], t[-1]),
                    np.zeros(sys_.a.shape[0]), method="DOP853", rtol=1e-13, atol=1e-16,
                    t_eval=t)
    return (sys_.c @ sol.y).T + np.outer(p(t), sys_.d[:, 0])


def test_time_response_of_the_linear_block_is_the_dynamics() -> None:
    """The block's motion is linear: its base moved by u = eps (1 - cos w t), the state-space
    system's response equals mbd2d's dopri5 run of the model (rtol 1e-11) to 1e-8 of the
    motion."""
    pytest.importorskip("scipy")
    eps, w = 0.05, 4.0
    sys_ = held_block().linearize("driver.hold.f.poly.0")
    moved = _held_moved(eps, w, rest=sys_.q[4])
    res = moved.dynamics(t_end=3.0, steps=60, method="dopri5", rtol=1e-11, atol=1e-12)
    dq = res.q - sys_.q
    lin = _linear_response(sys_, lambda t: eps - eps * np.cos(w * t), res.t)
    assert np.abs(dq).max() > 0.5 * eps
    assert np.abs(dq - lin).max() <= 1e-8 * np.abs(dq).max()


def _held_moved(eps: float, w: float, rest: float) -> mbd2d.Model:
    """held_block with its base driven to u = eps (1 - cos w t) about its rest place and
    the block starting at its equilibrium height rest."""
    model = held_block()
    model.bodies[1].q0 = (0.0, rest, 0.0)
    head, drivers = mbd2d.description.toml_io.dumps(model).split("[[driver]]")
    old = 'f = { poly = [0.0] }'
    new = (f'f = {{ poly = [{eps!r}], harmonic = [{{ amplitude = {-eps!r}, omega = {w!r}, '
           f'phase = {np.pi / 2!r} }}] }}')
    hold, rest = drivers.split("[[force]]", 1)         # (the forces' functions after it)
    assert hold.count("\n" + old) == 1
    return mbd2d.loads(head + "[[driver]]" + hold.replace("\n" + old, "\n" + new)
                       + "[[force]]" + rest)


def test_time_response_of_the_pendulum_errs_at_second_order() -> None:
    """The cart shaken by x_c = eps (1 - cos w t): the linear system's response against the
    nonlinear dynamics (dopri5, rtol 1e-12) differs by O(eps^2): the error divided by the
    motion halves with eps (ratios 4 of the error within 3%), and is below 1e-3 of it at the
    smallest."""
    pytest.importorskip("scipy")
    w, errs, sizes = 3.0, [], []
    sys_ = cart_pendulum().linearize("driver.shake.f.poly.0")
    for eps in (1e-3, 5e-4, 2.5e-4):
        res = cart_pendulum(eps, w).dynamics(t_end=4.0, steps=40, method="dopri5", rtol=1e-12,
                                             atol=1e-13)
        dq = res.q - sys_.q
        lin = _linear_response(sys_, lambda t: eps - eps * np.cos(w * t), res.t)
        errs.append(np.abs(dq - lin).max())
        sizes.append(np.abs(dq).max())
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    np.testing.assert_allclose(ratios, 4.0, rtol=0.03)
    assert errs[-1] < 1e-3 * sizes[-1]


def test_redundant_and_fully_driven_models() -> None:
    """A block on two parallel guides (two redundant rows: more free motions than
    coordinates minus rows, the core called again with room for them) on a spring: poles
    +-i sqrt(k/m); a base alone held by its driver: no free motion, A empty, D its own
    motion."""
    m = mbd2d.Model("two guides", gravity=(0.0, 0.0))
    m.add_body("block", (0.0, 0.0, 0.0), mass=0.5, inertia=0.01)
    for k, y in enumerate((0.0, 0.1)):
        m.add_translational(["ground", "block"], [[0.0, y], [0.0, y]], [[1, 0], [1, 0]],
                            name=f"g{k}")
    m.add_spring(["ground", "block"], [[-0.1, 0.0], [0.0, 0.0]], stiffness=200.0,
                 length0=0.1, name="s")
    sys_ = m.linearize("force.s.length0")
    assert sys_.n_free == 1
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(sys_.a).imag),
                               [-20.0, 20.0], rtol=1e-13)
    base = mbd2d.Model("base", gravity=(0.0, -G))
    base.add_body("base", (0.0, 0.0, 0.0), mass=1.0, inertia=0.1)
    base.add_translational(["ground", "base"], [[0.0, 0.0], [0.0, 0.0]], [[0, 1], [0, 1]],
                           name="guide")
    base.add_driver("absolute", {"poly": [0.0]}, body="base", coordinate="y", name="hold")
    sys_ = base.linearize("driver.hold.f.poly.0")
    assert sys_.n_free == 0 and sys_.a.shape == (0, 0) and sys_.b.shape == (0, 1)
    np.testing.assert_array_equal(sys_.d[:, 0] + 0.0, [0.0, 1.0, 0.0])


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mbd2d", *args], capture_output=True,
                          text=True, timeout=120)


def test_every_front_door_writes_the_same_system(tmp_path: Path) -> None:
    """The CSV (matrix,row,column,value; A, B, C, D row by row) from Python, from
    ``mbd2d linearize --out`` and from mbd2d-solve, byte for byte; select(), to_scipy()."""
    from test_standalone import solve_file
    model, inputs = cart_pendulum(), ["driver.shake.f.poly.0", "model.gravity.0"]
    sys_ = model.linearize(inputs)
    header, rows = sys_.table()
    assert header == ["matrix", "row", "column", "value"]
    f, ni, nq = sys_.n_free, len(inputs), len(sys_.outputs)
    assert len(rows) == (2 * f)**2 + 2 * f * ni + nq * 2 * f + nq * ni
    assert rows[0][:3] == ("A", "z1", "z1") and rows[-1][:3] == ("D", "bar.theta",
                                                                  "model.gravity.0")
    py = tmp_path / "py.csv"
    sys_.to_csv(py)
    model.export(tmp_path / "m.mbd", analysis="linearize", inputs=inputs)
    assert solve_file(tmp_path / "m.mbd", tmp_path / "s.csv") == py.read_text()
    toml = tmp_path / "cart.toml"
    toml.write_text(mbd2d.description.toml_io.dumps(model))
    r = _cli("linearize", str(toml), "--input", inputs[0], "--input", inputs[1], "--out",
             str(tmp_path / "c.csv"))
    assert r.returncode == 0, r.stderr
    assert "1 free motion(s): 2 states, 2 input(s)" in r.stdout
    assert (tmp_path / "c.csv").read_text() == py.read_text()
    r = _cli("export", str(toml), str(tmp_path / "e.mbd"), "--analysis", "linearize",
             "--input", inputs[0], "--input", inputs[1])
    assert r.returncode == 0, r.stderr
    assert solve_file(tmp_path / "e.mbd", tmp_path / "e.csv") == py.read_text()
    one = sys_.select(outputs=["bar.theta"], inputs=[inputs[0]])
    assert one.c.shape == (1, 2) and one.d.shape == (1, 1) and one.b.shape == (2, 1)
    np.testing.assert_allclose(transfer(one, 2.5j)[0, 0],
                               transfer(sys_, 2.5j)[out(sys_, "bar.theta"), 0], rtol=1e-15)
    pytest.importorskip("scipy")
    ss = one.to_scipy()
    _, h = ss.freqresp([2.5])
    np.testing.assert_allclose(h[0], transfer(one, 2.5j)[0, 0], rtol=1e-12)


@pytest.mark.parametrize("call, err, needle", [
    (lambda m: m.linearize([]), mbd2d.ModelError, "inputs must name at least one"),
    (lambda m: m.linearize("force.push.nope"), mbd2d.ModelError, "force.push.nope"),
    (lambda m: m.linearize("force.push.fy.poly.0").select(outputs=["block.z"]),
     mbd2d.ModelError, "no output 'block.z'"),
    (lambda m: m.linearize("force.push.fy.poly.0").select(inputs=["model.gravity.1"]),
     mbd2d.ModelError, "no input 'model.gravity.1'"),
    (lambda m: m.linearize("force.push.fy.poly.0").select(outputs=3), mbd2d.ModelError,
     "outputs must be a name or a list of names"),             # (before: a TypeError)
    (lambda m: m.linearize(3), mbd2d.ModelError, "inputs must name at least one"),   # (idem)
    (lambda m: m.frequency_response(3, [1.0]), mbd2d.ModelError,
     "inputs must name at least one"),
    (lambda m: m.linearize("force.push.fy.poly.0", t=float("nan")), mbd2d.ModelError, "t"),
    (lambda m: m.export("x.mbd", analysis="linearize", inputs=["force.push.fy.poly.0"],
                        frequencies=[1.0]), mbd2d.ModelError, "frequencies of frf"),
    (lambda m: m.export("x.mbd", analysis="linearize"), mbd2d.ModelError,
     "inputs must name at least one"),
])
def test_bad_input_is_a_typed_error(call: callable, err: type, needle: str) -> None:
    with pytest.raises(err, match=needle):
        call(held_block())


def test_what_linearize_refuses_or_cannot_do(tmp_path: Path) -> None:
    """Contacts are refused (no exact derivatives); a free motion without mass is a
    SingularJacobianError naming it; mbd2d-solve refuses a linearize file with frequencies
    or without inputs (exit 2)."""
    from test_standalone import solve_file
    m = held_block()
    m.add_body("ball", [1.0, 1.0, 0.0], mass=0.1, inertia=1e-3)
    m.add_contact("circle-line", ["ball", "ground"], circle={"center": [0, 0], "radius": 0.05},
                  line={"point": [0.0, 0.0], "normal": [0.0, 1.0]},
                  law={"model": "linear", "stiffness": 1e5, "restitution": 0.8}, name="floor")
    with pytest.raises(mbd2d.ModelError, match="linearized system does not carry contacts"):
        m.linearize("force.push.fy.poly.0")
    light = held_block()
    light.bodies[1].mass = 0.0
    light.bodies[1].inertia = 0.0
    with pytest.raises(mbd2d.SingularJacobianError, match="carries no mass"):
        light.linearize("force.push.fy.poly.0")
    held_block().export(tmp_path / "m.mbd", analysis="linearize",
                        inputs=["force.push.fy.poly.0"])
    text = (tmp_path / "m.mbd").read_text()
    for edit, needle in [(("at_q0 0\n", "at_q0 0\nfrequencies 1\n1.0\n"), "frequencies"),
                         (("\nsensitivities 1\n", "\n# sensitivities 1\n# "),
                          "linearize needs its inputs")]:
        bad = tmp_path / "bad.mbd"
        bad.write_text(text.replace(*edit, 1))
        r = subprocess.run([_solver(), str(bad), str(tmp_path / "o.csv")], capture_output=True,
                           text=True, timeout=60)
        assert r.returncode == 2 and needle in r.stderr, r.stderr
    assert solve_file(tmp_path / "m.mbd", tmp_path / "ok.csv").startswith("matrix,row,")
    # "velocities" is linearize's output alone
    with pytest.raises(mbd2d.ModelError, match="unknown output 'velocities'"):
        held_block().export(tmp_path / "k.mbd", analysis="statics", outputs=["velocities"])
    held_block().export(tmp_path / "s.mbd", analysis="statics")
    bad = tmp_path / "bad.mbd"
    bad.write_text((tmp_path / "s.mbd").read_text().replace("\ngravity ",
                                                            "\noutputs velocities\ngravity ", 1))
    r = subprocess.run([_solver(), str(bad), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "is linearize's" in r.stderr, r.stderr


def _solver() -> str:
    from test_standalone import find_solver
    return find_solver()


def test_velocity_outputs(tmp_path: Path) -> None:
    """velocities=True: the coordinates' velocities after them (NAME.y_dot ...): the pushed
    block's s / (m s^2 + c s + k) at five points s, C A and C B of the positions' system, no
    feedthrough; the CSV from Python, the command line and mbd2d-solve the same bytes. An
    input that moves the mechanism directly (the base's driver: D = 1) is refused, named."""
    from test_standalone import solve_file
    model, inp = held_block(), "force.push.fy.poly.0"
    sys_ = model.linearize(inp, velocities=True)
    pos = model.linearize(inp)
    nq = len(pos.outputs)
    assert sys_.outputs == pos.outputs + [f"{c}_dot" for c in pos.outputs]
    yd = sys_.outputs.index("block.y_dot")
    for s in S_POINTS:
        np.testing.assert_allclose(transfer(sys_, s)[yd, 0],
                                   s / (M_BLOCK * s**2 + C_D * s + K), rtol=1e-13, atol=1e-16)
    np.testing.assert_array_equal(sys_.c[:nq], pos.c)
    np.testing.assert_allclose(sys_.c[nq:], pos.c @ pos.a, rtol=0, atol=1e-15)
    np.testing.assert_allclose(sys_.d[nq:], pos.c @ pos.b, rtol=0, atol=1e-15)
    py = tmp_path / "py.csv"
    sys_.to_csv(py)
    assert "C,block.y_dot,v1," in py.read_text()
    model.export(tmp_path / "m.mbd", analysis="linearize", inputs=[inp], outputs=["velocities"])
    assert solve_file(tmp_path / "m.mbd", tmp_path / "s.csv") == py.read_text()
    toml = tmp_path / "held.toml"
    toml.write_text(mbd2d.description.toml_io.dumps(model))
    r = _cli("linearize", str(toml), "--input", inp, "--velocities", "--out",
             str(tmp_path / "c.csv"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "c.csv").read_text() == py.read_text()
    with pytest.raises(mbd2d.ModelError, match="driver.hold.f.poly.0.*moves the mechanism"):
        model.linearize(["force.push.fy.poly.0", "driver.hold.f.poly.0"], velocities=True)
    with pytest.raises(mbd2d.ModelError, match="velocities"):
        model.linearize(inp, velocities="yes")


# -- the drivers' efforts as outputs ---------------------------------------------------------

def _pushed_cart_pendulum() -> mbd2d.Model:
    """cart_pendulum (the cart held by its driver) with a horizontal push on the bar's centre
    of mass (the input: its amplitude)."""
    m = cart_pendulum()
    m.add_force("point", body="bar", point=[0.0, 0.0], fx={"poly": [0.0]}, fy=0.0, name="push")
    return m


def _tyred_block(slant: float = 0.0) -> mbd2d.Model:
    """held_block with a damped tyre (k2 20, c2 0.8) from a ground point below the block
    (slant: the point moved sideways by this much, so that the tyre leans)."""
    m = held_block()
    m.add_spring(["ground", "block"], [[slant, -2.0], [0.0, 0.0]], stiffness=K2, damping=C2,
                 length0=float(np.hypot(slant, 1.0)), name="tyre")
    return m


K2, C2 = 20.0, 0.8


def test_efforts_of_force_inputs_against_closed_forms() -> None:
    """The held base's effort per unit push on the block, -(k + c s) / (m s^2 + c s + k) (the
    spring-damper's pull, held against); the held cart's per unit push on the pendulum's
    centre, -(I s^2 + m g a) / ((I + m a^2) s^2 + m g a) (-1 at rest; the feedthrough
    D = -I / (I + m a^2): a push is felt at once), at five points s; with the velocities the
    effort rows come after them and are the same."""
    block = held_block().linearize("force.push.fy.poly.0", efforts=True)
    assert block.outputs[-1] == "effort.hold" and len(block.outputs) == 7
    e = out(block, "effort.hold")
    a, inertia = L_BAR / 2, M_BAR * L_BAR**2 / 12
    j = inertia + M_BAR * a**2
    cart = _pushed_cart_pendulum().linearize("force.push.fx.poly.0", efforts=True)
    both = _pushed_cart_pendulum().linearize("force.push.fx.poly.0", efforts=True,
                                             velocities=True)
    assert both.outputs[-1] == "effort.shake" and both.outputs[-2] == "bar.theta_dot"
    for s in S_POINTS:
        np.testing.assert_allclose(transfer(block, s)[e, 0],
                                   -(K + C_D * s) / (M_BLOCK * s**2 + C_D * s + K), rtol=1e-13)
        want = -(inertia * s**2 + M_BAR * G * a) / (j * s**2 + M_BAR * G * a)
        for sys_ in (cart, both):
            np.testing.assert_allclose(transfer(sys_, s)[out(sys_, "effort.shake"), 0], want,
                                       rtol=1e-13)
    np.testing.assert_allclose(cart.d[out(cart, "effort.shake"), 0], -inertia / j, rtol=1e-14)
    assert block.d[e, 0] == 0.0


def test_a_road_input_reaches_the_driver_through_the_block() -> None:
    """A road under the block (the tyre's ground point moved up by p): the block follows by
    (k2 + c2 s) / D, D = m s^2 + (c + c2) s + k + k2, and the held base's effort is
    -(k + c s) times that: the road's rate acts on the free block alone, so the effort is
    proper. With the tyre leaning, the rate's sideways part goes into the block's guide, not
    into the driver: still proper, and equal to the frequency response's effort."""
    sys_ = _tyred_block().linearize("force.tyre.points.0.1", efforts=True)
    e, y = out(sys_, "effort.hold"), out(sys_, "block.y")
    for s in S_POINTS:
        den = M_BLOCK * s**2 + (C_D + C2) * s + K + K2
        g = transfer(sys_, s)[:, 0]
        np.testing.assert_allclose(g[y], (K2 + C2 * s) / den, rtol=1e-13)
        np.testing.assert_allclose(g[e], -(K + C_D * s) * (K2 + C2 * s) / den, rtol=1e-13)
    lean = _tyred_block(0.3)
    freqs = np.array([0.0, 0.4, 1.1, 2.5])
    sys_ = lean.linearize("force.tyre.points.0.1", efforts=True)
    res = lean.frequency_response("force.tyre.points.0.1", freqs)
    tf = [transfer(sys_, 2j * np.pi * f)[out(sys_, "effort.hold"), 0] for f in freqs]
    np.testing.assert_allclose(tf, res.effort_response("hold", "force.tyre.points.0.1"),
                               rtol=1e-12)


def test_time_response_of_the_effort_is_the_dynamics() -> None:
    """The block pushed by 0.3 sin(2.2 t) from rest: the held base's effort of the state-space
    system (scipy DOP853 at 1e-13) against mbd2d's dopri5 run of the model (rtol 1e-11),
    whose efforts come from its own index-1 solves: within 1e-9 of the effort's swing."""
    pytest.importorskip("scipy")
    amp, w = 0.3, 2.2
    sys_ = held_block().linearize("force.push.fy.poly.0", efforts=True)
    model = held_block()
    model.bodies[1].q0 = (0.0, float(sys_.q[4]), 0.0)
    text = mbd2d.description.toml_io.dumps(model)
    old = 'name = "push"\ntype = "point"\nbody = "block"\npoint = [0.0, 0.0]\n' \
          'fx = { poly = [0.0] }\nfy = { poly = [0.0] }'
    assert text.count(old) == 1
    new = old.replace('fy = { poly = [0.0] }',
                      f'fy = {{ harmonic = [{{ amplitude = {amp!r}, omega = {w!r} }}] }}')
    res = mbd2d.loads(text.replace(old, new)).dynamics(t_end=4.0, steps=80, method="dopri5",
                                                       rtol=1e-11, atol=1e-12)
    lin = _linear_response(sys_, lambda t: amp * np.sin(w * t), res.t)
    effort = res.effort("hold") - res.effort("hold")[0]
    swing = np.abs(effort).max()
    assert swing > 0.1
    assert np.abs(effort - lin[:, out(sys_, "effort.hold")]).max() <= 1e-9 * swing


def test_efforts_refuse_inputs_that_move_the_constraints() -> None:
    """The base moved by its driver's offset (its acceleration is held by the driver at
    once), the spring's point on the held base (its damper's rate pulls the base, held
    against), and a model without drivers: ModelErrors naming the input, or saying why."""
    for inputs, name in ((["force.push.fy.poly.0", "driver.hold.f.poly.0"],
                          "driver.hold.f.poly.0"),
                         ("force.s.points.0.1", "force.s.points.0.1")):
        with pytest.raises(mbd2d.ModelError, match="effort outputs") as err:
            held_block().linearize(inputs, efforts=True)
        assert name in str(err.value)
    held_block().linearize("driver.hold.f.poly.0")           # (the positions alone: fine)
    with pytest.raises(mbd2d.ModelError, match="no drivers"):
        _no_driver().linearize("force.push.fy.poly.0", efforts=True)
    with pytest.raises(mbd2d.ModelError, match="no drivers"):     # (the file: refused at once)
        _no_driver().export("never.mbd", analysis="linearize", inputs=["force.push.fy.poly.0"],
                            outputs=["efforts"])


def _no_driver() -> mbd2d.Model:
    """A block on a vertical guide on a spring, pushed; no driver."""
    m = mbd2d.Model("free block", gravity=(0.0, -G))
    m.add_body("block", (0.0, -1.0, 0.0), mass=2.0, inertia=0.01)
    m.add_translational(["ground", "block"], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 1.0], [0.0, 1.0]],
                        name="guide")
    m.add_spring(["ground", "block"], [[0.0, 0.0], [0.0, 0.0]], stiffness=K, length0=0.5,
                 name="s")
    m.add_force("point", body="block", point=[0.0, 0.0], fx=0.0, fy={"poly": [0.0]},
                name="push")
    return m


def test_effort_outputs_from_every_front_door(tmp_path: Path) -> None:
    """efforts=True with velocities: the CSV's effort rows (``C,effort.shake,...``) from
    Python, ``mbd2d linearize --velocities --efforts``, and mbd2d-solve (``outputs
    velocities efforts``, from Model.export and from ``mbd2d export``) byte for byte; the
    file's and the command line's refusals: a model without drivers, an input that moves the
    constraints (exit 2, named)."""
    from test_standalone import solve_file
    model, inp = _pushed_cart_pendulum(), "force.push.fx.poly.0"
    sys_ = model.linearize(inp, velocities=True, efforts=True)
    py = tmp_path / "py.csv"
    sys_.to_csv(py)
    text = py.read_text()
    assert "C,effort.shake,z1," in text and "D,effort.shake,force.push.fx.poly.0," in text
    model.export(tmp_path / "m.mbd", analysis="linearize", inputs=[inp],
                 outputs=["efforts", "velocities"])
    assert "\noutputs velocities efforts\n" in (tmp_path / "m.mbd").read_text()
    assert solve_file(tmp_path / "m.mbd", tmp_path / "s.csv") == text
    toml = tmp_path / "cart.toml"
    toml.write_text(mbd2d.description.toml_io.dumps(model))
    r = _cli("linearize", str(toml), "--input", inp, "--velocities", "--efforts", "--out",
             str(tmp_path / "c.csv"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "c.csv").read_text() == text
    r = _cli("export", str(toml), str(tmp_path / "e.mbd"), "--analysis", "linearize",
             "--input", inp, "--velocities", "--efforts")
    assert r.returncode == 0, r.stderr
    assert solve_file(tmp_path / "e.mbd", tmp_path / "e.csv") == text
    r = _cli("linearize", str(toml), "--input", "driver.shake.f.poly.0", "--efforts")
    assert r.returncode == 2 and "driver.shake.f.poly.0" in r.stderr, r.stderr
    model.export(tmp_path / "d.mbd", analysis="linearize", inputs=["driver.shake.f.poly.0"],
                 outputs=["efforts"])
    r = subprocess.run([_solver(), str(tmp_path / "d.mbd"), str(tmp_path / "o.csv")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "driver.shake.f.poly.0" in r.stderr, r.stderr
    assert "effort outputs" in r.stderr
    _no_driver().export(tmp_path / "n.mbd", analysis="linearize",
                        inputs=["force.push.fy.poly.0"], outputs=["velocities"])
    text = (tmp_path / "n.mbd").read_text()           # (export refuses efforts without drivers)
    (tmp_path / "n.mbd").write_text(text.replace("outputs velocities", "outputs efforts", 1))
    r = subprocess.run([_solver(), str(tmp_path / "n.mbd"), str(tmp_path / "o.csv")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "no drivers" in r.stderr, r.stderr


def _anchored_chain(n: int, m: float, k: float, c: float) -> mbd2d.Model:
    """test_modes' chain damped at its end (c), its first spring tied to an anchor block that
    a driver holds at x = 0 instead of to the ground, pushed along x at its first block."""
    from test_modes import damped_chain
    text = mbd2d.description.toml_io.dumps(damped_chain(c, n, m, k))
    old = 'bodies = ["ground", "b1"]'
    assert text.count(old) == 2                       # (the guide, then the spring s1)
    head, tail = text.rsplit(old, 1)
    text = head + 'bodies = ["anchor", "b1"]' + tail
    anchor = '[[body]]\nname = "anchor"\nq0 = [0.0, 0.0, 0.0]\nmass = 1.0\ninertia = 0.01\n\n'
    model = mbd2d.loads(text.replace("[[body]]", anchor + "[[body]]", 1))
    model.add_translational(["ground", "anchor"], [[0.0, 0.0], [0.0, 0.0]], [[1, 0], [1, 0]],
                            name="rail")
    model.add_driver("absolute", {"poly": [0.0]}, body="anchor", coordinate="x", name="hold")
    model.add_point_force("b1", [0.0, 0.0], fx=0.0, name="shaker")
    return model


def test_efforts_of_a_long_chain_on_the_band_path() -> None:
    """Sixty blocks on springs (k 200, m 0.5), a damper (c 5) on the last, the first spring
    held by a driven anchor, a push on the first block: the anchor's effort is -k X1(s), X the
    tridiagonal system (K + s C + s^2 M) X = e1 solved here, at five points s, on the band path
    and the dense one."""
    n, m, k, c = 60, 0.5, 200.0, 5.0
    model = _anchored_chain(n, m, k, c)
    kk = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kk[-1, -1] = k
    cc = np.zeros((n, n))
    cc[-1, -1] = c
    e1 = np.eye(n)[0]
    for solver in ("banded", "dense"):
        sys_ = model.linearize("force.shaker.fx.poly.0", solver=solver, efforts=True)
        assert sys_.stats["solver"] == solver and sys_.n_free == n
        for s in S_POINTS[1:]:
            x1 = np.linalg.solve(kk + s * cc + s**2 * m * np.eye(n), e1)[0]
            np.testing.assert_allclose(transfer(sys_, s)[out(sys_, "effort.hold"), 0], -k * x1,
                                       rtol=1e-10)
