"""The frequency response (Model.frequency_response) against closed forms and matrices written
here without mbd2d: a block on a spring-damper driven by its actuator, its spring's free length
and gravity (1 / (k - m w^2 + i c w) and its multiples), two blocks damped at one end and a
chain of twelve on the band path ((K - w^2 M + i w C)^-1 b by numpy), a pendulum on a torsion
spring driven by a torque (the constraints' curvature under the equilibrium's multipliers) and
a pendulum whose pivot is shaken (a base motion: the parameter moves the constraint)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mbd2d
from test_modes import (SPRUNG, G, ball_on_floor, bead_in_slot, bisect, block_text,
                        damped_chain, distance_bob, fourbar_energy, fourbar_reduced, gear_pair,
                        pendulum, rack_pinion, rolling_disc, rubbing_pendulum, spring_chain,
                        sprung_fourbar)

FREQS = np.array([0.0, 0.2, 0.5, 0.6755, 0.7, 1.3, 4.0, 25.0])


def block(k: float = 36.0, c: float = 1.5, m: float = 2.0) -> mbd2d.Model:
    """test_modes' block on a spring-damper-actuator (its y is minus the spring's length)."""
    return mbd2d.loads(block_text(k, c, m))


@pytest.mark.parametrize("c", [1.5, 0.0, 30.0])
def test_a_block_on_a_spring_damper(c: float) -> None:
    """dy per unit input: free length -k/D, actuator f -1/D, gravity's y m/D (a base
    acceleration), D = k - m w^2 + i c w; at 0 Hz the statics sensitivity."""
    k, m = 36.0, 2.0
    model = block(k, c, m)
    inputs = ["force.s.length0", "force.s.f.poly.0", "model.gravity.1"]
    res = model.frequency_response(inputs, FREQS)
    w = 2 * np.pi * FREQS
    d = k - m * w**2 + 1j * c * w
    for name, want in zip(inputs, (-k / d, -1 / d, m / d)):
        got = res.response_of("block", "y", name)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
        np.testing.assert_array_equal(res.response_of("block", "x", name), 0.0)
    assert res.response.shape == (FREQS.size, 3, 3) and res.n_free == 1
    eq = model.statics(sensitivities=inputs)
    np.testing.assert_allclose(res.response[0].real, eq.dq_dp, rtol=1e-12, atol=1e-15)
    assert res.stability == "stable" and abs(res.q[1] - (-0.5 - m * G / k)) < 1e-12


def road_block(rot: float | None = None) -> mbd2d.Model:
    """A 2 kg block on a vertical guide on a damped tyre (k 36, c 1.5) whose lower end is a
    point of the ground (rot None) or of an arm welded to the ground at the angle rot."""
    m = mbd2d.Model("road", gravity=(0.0, 0.0))
    m.add_body("block", (0.0, 1.0, 0.0), mass=2.0, inertia=0.1)
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [[0, 1], [0, 1]], name="guide")
    base = "ground"
    if rot is not None:
        m.add_body("arm", (0.0, 0.0, rot), mass=1.0, inertia=0.1)
        m.add_weld(["ground", "arm"], [[0.0, 0.0], [0.0, 0.0]], angle=rot, name="fix")
        base = "arm"
    m.add_spring([base, "block"], [[0.0, 0.0], [0.0, 0.0]], stiffness=36.0, damping=1.5,
                 length0=1.0, name="tyre")
    return m


@pytest.mark.parametrize("rot", [None, np.pi / 6])
def test_a_road_under_a_damped_tyre(rot: float | None) -> None:
    """The tyre's lower point moved (a road): the damper sees the point's velocity, so the
    block follows by (k + i c w) / (k - m w^2 + i c w) per unit of the point's travel along
    the tyre (on the arm at 30 degrees its local x is sin 30 of that, its local y cos 30);
    the free length moved is no road: k / (k - m w^2 + i c w) (the damper does not see it).
    The linearized system's transfer function is the same (the rate enters B); before, the
    road's rate was left out (k / D for the point as for the free length)."""
    k, c, m = 36.0, 1.5, 2.0
    model = road_block(rot)
    inputs = ["force.tyre.points.0.0", "force.tyre.points.0.1", "force.tyre.length0"]
    res = model.frequency_response(inputs, FREQS)
    w = 2 * np.pi * FREQS
    d = k - m * w**2 + 1j * c * w
    along = (0.0, 1.0) if rot is None else (np.sin(rot), np.cos(rot))
    wants = [a * (k + 1j * c * w) / d for a in along] + [k / d]    # (the tyre is below)
    lin = model.linearize(inputs)
    y = lin.outputs.index("block.y")
    for j, (name, want) in enumerate(zip(inputs, wants)):
        np.testing.assert_allclose(res.response_of("block", "y", name), want, rtol=1e-12,
                                   atol=1e-15)
        tf = [(lin.c @ np.linalg.solve(1j * wk * np.eye(2) - lin.a, lin.b) + lin.d)[y, j]
              for wk in w]
        np.testing.assert_allclose(tf, want, rtol=1e-12, atol=1e-15)


def test_a_damper_without_a_spring_and_no_zero_frequency() -> None:
    """A block on a horizontal guide with a damper only: 1 / (-m w^2 + i c w) for a force;
    at 0 Hz the response is unbounded (a motion without stiffness): a SingularJacobianError
    that names the frequency."""
    m, c = 2.0, 3.0
    model = mbd2d.Model("slider", gravity=(0.0, 0.0))
    model.add_body("slider", [0.3, 0.0, 0.0], mass=m, inertia=0.01)
    model.add_translational(["ground", "slider"], [[0, 0], [0, 0]], axes=[[1, 0], [1, 0]],
                            name="guide")
    model.add_spring(["ground", "slider"], [[0.0, 0.0], [0.0, 0.0]], damping=c, length0=0.3,
                     name="damper")
    model.add_point_force("slider", [0.0, 0.0], fx=0.0, name="push")
    name = [p for p in model.parameters() if p.startswith("force.push.fx")][0]
    f = np.array([0.1, 1.0, 10.0])
    w = 2 * np.pi * f
    res = model.frequency_response(name, f)
    np.testing.assert_allclose(res.response_of("slider", "x"), 1 / (-m * w**2 + 1j * c * w),
                               rtol=1e-12)
    with pytest.raises(mbd2d.SingularJacobianError, match="at 0 Hz is unbounded"):
        model.frequency_response(name, [1.0, 0.0])


def damped_pair(c: float = 3.0, m: float = 0.5, k: float = 200.0) -> mbd2d.Model:
    """spring_chain(2) with a damper on its last block and a force on its first."""
    model = spring_chain(2, m, k)
    model.add_spring(["ground", "b2"], [[0.0, 0.0], [0.0, 0.0]], damping=c, length0=0.2,
                     name="damper")
    model.add_point_force("b1", [0.0, 0.0], fx=0.0, name="shaker")
    return model


def test_two_blocks_damped_at_one_end() -> None:
    """(K - w^2 M + i w C) x = e_1 with M = m I, K = [[2k, -k], [-k, k]], C = diag(0, c)."""
    m, k, c = 0.5, 200.0, 3.0
    model = damped_pair(c, m, k)
    name = [p for p in model.parameters() if p.startswith("force.shaker.fx")][0]
    res = model.frequency_response(name, FREQS * 10)
    kk = k * np.array([[2.0, -1.0], [-1.0, 1.0]])
    for j, f in enumerate(FREQS * 10):
        w = 2 * np.pi * f
        want = np.linalg.solve(kk - w**2 * m * np.eye(2) + 1j * w * np.diag([0.0, c]),
                               [1.0, 0.0])
        got = res.response[j, [0, 3], 0]
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-13 * abs(want).max())


def shaken_chain(c: float, n: int, m: float, k: float) -> tuple[mbd2d.Model, str]:
    """test_modes' chain damped at its end, with a force on its first block; the force's
    amplitude parameter."""
    model = damped_chain(c, n, m, k)
    model.add_point_force("b1", [0.0, 0.0], fx=0.0, name="shaker")
    return model, "force.shaker.fx.poly.0"


def test_a_chain_on_the_band_path() -> None:
    """Twelve blocks on springs, a damper on the last, a force on the first: the band path
    equals the tridiagonal system solved here (and the dense path)."""
    n, m, k, c = 12, 0.5, 200.0, 5.0
    model, name = shaken_chain(c, n, m, k)
    f = np.linspace(0.0, 8.0, 17)
    band = model.frequency_response(name, f, solver="banded")
    dense = model.frequency_response(name, f, solver="dense")
    assert band.stats["solver"] == "banded" and dense.stats["solver"] == "dense"
    kk = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kk[-1, -1] = k
    cc = np.zeros((n, n))
    cc[-1, -1] = c
    b = np.zeros(n)
    b[0] = 1.0
    for j, fj in enumerate(f):
        w = 2 * np.pi * fj
        want = np.linalg.solve(kk - w**2 * m * np.eye(n) + 1j * w * cc, b)
        np.testing.assert_allclose(band.response[j, 0::3, 0], want, rtol=1e-9,
                                   atol=1e-12 * abs(want).max())
    np.testing.assert_allclose(band.response, dense.response, rtol=0,
                               atol=1e-10 * abs(dense.response).max())


def test_many_free_motions_take_the_hessenberg_form() -> None:
    """Forty blocks damped at the end, twenty frequencies: the response from the Hessenberg
    form of the first-order system (Laub's method, taken from 16 free motions and 8
    frequencies on) equals the system solved here by numpy, and the dense LU of each
    frequency alone (one frequency a call), to 1e-12 of the largest (measured 6.8e-14 and
    3.7e-14 with the step of refinement on the second-order system; 2.7e-11 without it);
    twenty free blocks (no stiffness) are singular at 0 Hz on this path too, and move as
    -1 / (m w^2) elsewhere."""
    n, m, k, c = 40, 0.5, 200.0, 5.0
    model, name = shaken_chain(c, n, m, k)
    f = np.linspace(0.0, 12.0, 20)
    res = model.frequency_response(name, f)
    kk = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kk[-1, -1] = k
    cc = np.zeros((n, n))
    cc[-1, -1] = c
    for j, fj in enumerate(f):
        w = 2 * np.pi * fj
        want = np.linalg.solve(kk - w**2 * m * np.eye(n) + 1j * w * cc, np.eye(n)[0])
        np.testing.assert_allclose(res.response[j, 0::3, 0], want, rtol=0,
                                   atol=1e-12 * abs(want).max())
        alone = model.frequency_response(name, [fj])
        np.testing.assert_allclose(res.response[j], alone.response[0], rtol=0,
                                   atol=1e-12 * abs(want).max())
        np.testing.assert_allclose(res.lam_response[j], alone.lam_response[0], rtol=0,
                                   atol=1e-9 * abs(alone.lam_response[0]).max())
    free = spring_chain(20, k=0.0)
    free.add_point_force("b1", [0.0, 0.0], fx=0.0, name="shaker")
    with pytest.raises(mbd2d.SingularJacobianError, match="at 0 Hz is unbounded"):
        free.frequency_response("force.shaker.fx.poly.0", np.arange(10.0))
    f = np.arange(1.0, 11.0)
    got = free.frequency_response("force.shaker.fx.poly.0", f)
    np.testing.assert_allclose(got.response[:, 0, 0], -1 / (0.5 * (2 * np.pi * f)**2),
                               rtol=1e-13)
    np.testing.assert_allclose(got.response[:, 3:, 0], 0.0, atol=1e-12)


def test_a_pendulum_on_a_torsion_spring_driven_by_a_torque() -> None:
    """dtheta per unit torque 1 / (k - m g a sin th* - I_O w^2 + i c w) at the equilibrium
    k th* + m g a cos th* = 0: the pendulum's stiffness m g a comes from the constraints'
    curvature under the equilibrium's multipliers."""
    m, L, k, c = 1.3, 0.8, 10.0, 0.4
    model = pendulum(k=k, c=c, mass=m, length=L)
    model.add_torque("bar", 0.0, name="drive")
    th = bisect(lambda a: k * a + m * G * L / 2 * np.cos(a), -np.pi / 2, 0.0)
    i_o = m * L**2 / 12 + m * (L / 2)**2
    res = model.frequency_response("force.drive.f.poly.0", FREQS)
    w = 2 * np.pi * FREQS
    want = 1 / (k - m * G * L / 2 * np.sin(th) - i_o * w**2 + 1j * c * w)
    np.testing.assert_allclose(res.response_of("bar", "theta"), want, rtol=1e-10)
    # the pivot stays: the centre moves on its circle, dx = -(L/2) sin(th) dtheta
    np.testing.assert_allclose(res.response_of("bar", "x"),
                               -L / 2 * np.sin(th) * want, rtol=1e-10)


@pytest.mark.parametrize("kind", ["rolling disc", "gear pair", "rack and pinion"])
def test_joints_that_couple_by_rolling(kind: str) -> None:
    """The rolling disc, gear and rack-and-pinion joints' curvature and coupling: each system
    has one free motion of effective inertia M (m + I/r^2, I1 + I2 (R1/R2)^2, m + I/r^2),
    driven through its spring's free length or free angle p: dx/dp = k / (k - M w^2 + i c w);
    the coupled body follows by the joint's ratio."""
    c = 0.7
    w = 2 * np.pi * FREQS
    if kind == "rolling disc":
        m, inertia, r, k = 2.0, 0.03, 0.15, 50.0
        model, name, body, coord = rolling_disc(m, inertia, r, k, c), "force.s.length0", \
            "disc", "x"
        mass, follower, ratio = m + inertia / r**2, ("disc", "theta"), -1 / r
    elif kind == "gear pair":
        r1, r2, i1, i2, k = 0.5, 1.5, 0.02, 0.3, 8.0
        model, name, body, coord = gear_pair(r1, r2, i1, i2, k, c), "force.k.angle0", \
            "pinion", "theta"
        mass, follower, ratio = i1 + i2 * (r1 / r2)**2, ("wheel", "theta"), -r1 / r2
    else:
        m, inertia, r, k = 1.5, 0.01, 0.3, 40.0
        model, name, body, coord = rack_pinion(m, inertia, r, k, c), "force.s.length0", \
            "rack", "x"
        mass, follower, ratio = m + inertia / r**2, ("pinion", "theta"), None
    res = model.frequency_response(name, FREQS)
    want = k / (k - mass * w**2 + 1j * c * w)
    np.testing.assert_allclose(res.response_of(body, coord), want, rtol=1e-12)
    got = res.response_of(*follower)
    if ratio is not None:
        np.testing.assert_allclose(got, ratio * want, rtol=1e-12)
    else:                          # the pinion turns by the rack's travel over its radius
        np.testing.assert_allclose(abs(got), abs(want) / r, rtol=1e-12)


@pytest.mark.parametrize("kind", ["distance", "point-on-curve"])
def test_a_bob_on_a_rod_and_a_bead_in_a_slot(kind: str) -> None:
    """A horizontal force on a bob hung by a distance joint L, or on a bead in a circular
    slot R: dx = 1 / (m g / L - m w^2) (the joints' curvature under the weight); the bob's
    free spin does not answer (and makes 0 Hz unbounded, so it is left out)."""
    length, m = (0.8, 2.0) if kind == "distance" else (1.2, 0.4)
    model = distance_bob(length=length) if kind == "distance" else bead_in_slot(length)
    body = "bob" if kind == "distance" else "bead"
    model.add_point_force(body, [0.0, 0.0], fx=0.0, name="push")
    f = FREQS[1:]
    res = model.frequency_response("force.push.fx.poly.0", f)
    want = 1 / (m * G / length - m * (2 * np.pi * f)**2)
    np.testing.assert_allclose(res.response_of(body, "x"), want, rtol=1e-12)
    np.testing.assert_allclose(res.response_of(body, "theta"), 0.0, atol=1e-14)


def test_a_pendulum_whose_pivot_is_shaken() -> None:
    """The ground pivot's x moved as X e^(i w t) (a base motion through Phi_p): the hanging
    bar's angle I_O phi'' + c phi' + m g a phi = m a w^2 X, so dphi/dX = m a w^2 / (m g a -
    I_O w^2 + i c w), and its centre follows the pivot (1 at 0 Hz)."""
    m, L, c = 1.3, 0.8, 0.4
    a = L / 2
    model = pendulum(k=0.0, c=c, mass=m, length=L, q0=f"0.0, {-a}, {-np.pi / 2}")
    res = model.frequency_response("joint.pivot.points.0.0", FREQS)
    w = 2 * np.pi * FREQS
    i_o = m * L**2 / 12 + m * a**2
    phi = m * a * w**2 / (m * G * a - i_o * w**2 + 1j * c * w)
    np.testing.assert_allclose(res.response_of("bar", "theta"), phi, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(res.response_of("bar", "x"), 1 + a * phi, rtol=1e-10)
    np.testing.assert_allclose(res.response_of("bar", "y"), 0.0, atol=1e-12)


def test_a_sprung_four_bar_driven_at_its_crank() -> None:
    """A crank-rocker on a torsion spring-damper under gravity, a torque on the crank: by the
    energy method on its closed-form position analysis, dth2 = 1 / (V'' - M_eff w^2 + i c w)
    at V' = 0, and the rocker follows by its closed-form dth4/dth2 (the reference's own
    differences: about 1e-9)."""
    c = 0.05
    model = sprung_fourbar(SPRUNG, damping=c)
    model.add_torque("crank", 0.0, name="drive")
    th = bisect(lambda t: fourbar_reduced(t, SPRUNG)[0], 0.3, 2.0)
    _, v2, meff = fourbar_reduced(th, SPRUNG)
    res = model.frequency_response("force.drive.f.poly.0", FREQS)
    w = 2 * np.pi * FREQS
    want = 1 / (v2 - meff * w**2 + 1j * c * w)
    np.testing.assert_allclose(res.response_of("crank", "theta"), want, rtol=1e-8)
    h = 1e-6
    ratio = (fourbar_energy(th + h, SPRUNG)[1][2] - fourbar_energy(th - h, SPRUNG)[1][2]) / (2 * h)
    np.testing.assert_allclose(res.response_of("rocker", "theta"), ratio * want, rtol=1e-8)


def test_the_pivot_force_of_a_pendulum() -> None:
    """The force the pivot puts on the hanging bar is m times its centre's acceleration (to
    first order, horizontal): -m a w^2 H per unit torque, H = 1 / (m g a - I_O w^2 + i c w);
    per unit shake of the pivot -m w^2 (1 + a dphi/dX), the pivot's own move counted once.
    The bar's far end moves L H across. The multipliers' response of all the frequencies
    (solved by parts once: P(K N), ...) equals that of each frequency alone (two solves per
    input) to 1e-12."""
    m, L, c = 1.3, 0.8, 0.4
    a = L / 2
    model = shaken_pendulum()
    model.add_torque("bar", 0.0, name="drive")
    inputs = ["force.drive.f.poly.0", "joint.pivot.points.0.0"]
    res = model.frequency_response(inputs, FREQS)
    w = 2 * np.pi * FREQS
    h = 1 / (m * G * a - (m * L**2 / 12 + m * a**2) * w**2 + 1j * c * w)
    for k, fk in enumerate(FREQS):
        one = model.frequency_response(inputs, [fk]).lam_response[0]
        np.testing.assert_allclose(one, res.lam_response[k], rtol=1e-12,
                                   atol=1e-14 * np.abs(res.lam_response).max())
    torque = res.reaction_response("pivot", inputs[0])
    assert torque.bodies == ("ground", "bar")
    np.testing.assert_allclose(torque.fx_j, -m * a * w**2 * h, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(torque.fy_j, 0.0, atol=1e-13)
    np.testing.assert_array_equal(torque.fx, 0.0)                 # (ground carries none)
    shake = res.reaction_response("pivot", inputs[1])
    want = -m * w**2 * (1 + a * m * a * w**2 * h)
    np.testing.assert_allclose(shake.fx_j, want, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(shake.fy_j, 0.0, atol=1e-11 * abs(want).max())
    with pytest.raises(KeyError, match="no joint or driver 'hinge'"):
        res.reaction_response("hinge", inputs[0])
    header, rows = res.table(reactions=True)            # the CSV's columns: the same numbers
    col = header.index("d(pivot.fx_j)/d(joint.pivot.points.0.0).im")
    np.testing.assert_array_equal(rows[:, col], shake.fx_j.imag + 0.0)
    assert len(header) == 1 + 2 * (2 * 3 + 2 * 6)
    # the bar's far end, L from the pivot: L dphi across, nothing up (first order)
    tip = res.point_response("bar", [a, 0.0], inputs[0])
    np.testing.assert_allclose(tip[:, 0], L * h, rtol=1e-12)
    np.testing.assert_allclose(tip[:, 1], 0.0, atol=1e-14)
    with pytest.raises(mbd2d.ModelError, match="no body 'arm'"):
        res.point_response("arm", [a, 0.0], inputs[0])


def test_tables_summary_and_picture(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    res = block().frequency_response(["force.s.f.poly.0", "model.gravity.1"], FREQS)
    header, rows = res.table()
    assert header[:3] == ["frequency_hz", "d(block.x)/d(force.s.f.poly.0).re",
                          "d(block.x)/d(force.s.f.poly.0).im"]
    assert len(header) == 1 + 2 * 6 and rows.shape == (FREQS.size, 13)
    np.testing.assert_array_equal(rows[:, 3], res.response[:, 1, 0].real)
    np.testing.assert_array_equal(rows[:, 10], res.response[:, 1, 1].imag)
    res.to_csv(tmp_path / "frf.csv")
    back = np.genfromtxt(tmp_path / "frf.csv", delimiter=",", skip_header=1)
    np.testing.assert_allclose(back, rows, rtol=1e-15)
    f, mag = res.peak("block", "y", "model.gravity.1")
    assert f == 0.6755 and mag == pytest.approx(abs(res.response[3, 1, 1]))
    text = res.summary()
    assert "input model.gravity.1" in text and "block.y" in text and "block.x" not in text
    assert f"{FREQS.size} frequencies from 0 to 25 Hz" in text
    assert "from 0.2 to 0.5 Hz" in block().frequency_response("model.gravity.1",
                                                              [0.5, 0.2]).summary()
    for kw, needle in [({}, "name one of"), ({"input": "model.gravity.0"}, "no input"),
                       ({"coordinate": "z", "input": "model.gravity.1"}, "coordinate must"),
                       ({"body": "wheel", "input": "model.gravity.1"}, "no body 'wheel'")]:
        with pytest.raises(mbd2d.ModelError, match=needle):
            res.response_of(**{"body": "block", **kw})
    fig = res.plot("block", "y", input="model.gravity.1")
    mbd2d.plots.save_figure(fig, tmp_path / "bode.png")
    assert (tmp_path / "bode.png").stat().st_size > 1000


@pytest.mark.parametrize("kw, error, needle", [
    ({"inputs": []}, mbd2d.ModelError, "at least one design parameter"),
    ({"inputs": None}, mbd2d.ModelError, "at least one design parameter"),
    ({"inputs": "force.s.stifness"}, mbd2d.ModelError, "force.s.stiffness"),
    ({"frequencies": [1.0, -2.0]}, mbd2d.ModelError, "frequencies must be"),
    ({"frequencies": [np.nan]}, mbd2d.ModelError, "frequencies must be"),
    ({"frequencies": []}, mbd2d.ModelError, "frequencies must be"),
    ({"frequencies": "fast"}, mbd2d.ModelError, "frequencies must be"),
    ({"t": "now"}, mbd2d.ModelError, "t"),
    ({"solver": "sparse"}, mbd2d.ModelError, "solver"),
])
def test_bad_arguments_are_model_errors(kw: dict, error: type, needle: str) -> None:
    args = {"inputs": "force.s.length0", "frequencies": [1.0], **kw}
    with pytest.raises(error, match=needle):
        block().frequency_response(**args)


def test_what_it_does_not_carry() -> None:
    """Contacts and joint friction are refused (their exact derivatives are not written)."""
    with pytest.raises(mbd2d.ModelError, match="does not carry contacts"):
        ball_on_floor().frequency_response("model.gravity.1", [1.0])
    with pytest.raises(mbd2d.ModelError, match="friction"):
        rubbing_pendulum().frequency_response("model.gravity.1", [1.0])


# ------------------------------------------------------------------ the other front doors

def shaken_pendulum() -> mbd2d.Model:
    return pendulum(k=0.0, c=0.4, mass=1.3, length=0.8, q0=f"0.0, -0.4, {-np.pi / 2}")


def test_mbd2d_solve_writes_the_response_python_writes(tmp_path: Path) -> None:
    """The standalone program: two inputs of the block, the shaken pivot about q0, a chain on
    the band path, to the last digit of Python's CSV."""
    from test_standalone import solve_file
    chain = spring_chain(8)
    chain.add_spring(["ground", "b8"], [[0.0, 0.0], [0.0, 0.0]], damping=2.0, length0=0.8,
                     name="damper")
    pend = shaken_pendulum()
    pend.add_torque("bar", 0.0, name="drive")
    runs = [(block(), ["force.s.length0", "model.gravity.1"], {}, False),
            (shaken_pendulum(), ["joint.pivot.points.0.0"], {"equilibrium": False}, False),
            (chain, ["force.s1.length0"], {"solver": "banded"}, False),
            (pend, ["force.drive.f.poly.0", "joint.pivot.points.0.0"], {}, True),
            (sprung_fourbar(SPRUNG, 0.05), ["joint.O4.points.0.0"], {}, True)]
    for k, (model, inputs, kw, reactions) in enumerate(runs):
        mbd = tmp_path / f"m{k}.mbd"
        model.export(mbd, analysis="frf", inputs=inputs, frequencies=FREQS,
                     outputs=["reactions"] if reactions else None, **kw)
        py = tmp_path / f"p{k}.csv"
        model.frequency_response(inputs, FREQS, **kw).to_csv(py, reactions=reactions)
        assert solve_file(mbd, tmp_path / f"f{k}.csv") == py.read_text()


@pytest.mark.parametrize("edit, needle", [
    (("frequencies 8", "frequencies 9"), "\"gravity\" is not a number"),
    (("frequencies 8\n", "frequencies 8\n-1 "), "more numbers than the count"),
    (("\nsensitivities 1\n", "\n# sensitivities 1\n# "), "frf needs its inputs"),
    (("\nfrequencies 8\n", "\n# frequencies 8\n# "), None),
    (("analysis frf", "analysis frf\noutputs energy"), "frf takes no outputs but"),
])
def test_mbd2d_solve_refuses_bad_frf_files(tmp_path: Path, edit: tuple,
                                            needle: str | None) -> None:
    import subprocess

    from test_standalone import find_solver
    mbd = tmp_path / "m.mbd"
    block().export(mbd, analysis="frf", inputs=["force.s.length0"], frequencies=FREQS)
    text = mbd.read_text()
    assert edit[0] in text
    text = text.replace(edit[0], edit[1], 1)
    if needle is None:                  # the block gone: its second line commented out too
        needle = 'needs a "frequencies" block'
        lines = text.splitlines()
        i = lines.index("# frequencies 8")
        lines[i + 2] = "# " + lines[i + 2]
        text = "\n".join(lines) + "\n"
    mbd.write_text(text)
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and needle in r.stderr, r.stderr


def test_mbd2d_solve_names_an_unbounded_frequency(tmp_path: Path) -> None:
    """A damper without a spring at 0 Hz: exit code 4 and the frequency named."""
    import subprocess

    from test_standalone import find_solver
    model = mbd2d.Model("slider", gravity=(0.0, 0.0))
    model.add_body("slider", [0.3, 0.0, 0.0], mass=2.0, inertia=0.01)
    model.add_translational(["ground", "slider"], [[0, 0], [0, 0]], axes=[[1, 0], [1, 0]])
    model.add_spring(["ground", "slider"], [[0.0, 0.0], [0.0, 0.0]], damping=3.0,
                     length0=0.3, name="damper")
    mbd = tmp_path / "m.mbd"
    model.export(mbd, analysis="frf", inputs=["force.damper.length0"], frequencies=[2.0, 0.0])
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 4 and "at 0.0000000000000000e+00 Hz is unbounded" in r.stderr


def test_export_refuses_what_frf_does_not_take(tmp_path: Path) -> None:
    m = block()
    for kw, needle in [({"analysis": "statics", "inputs": ["force.s.length0"]}, "settings of frf"),
                       ({"analysis": "frf", "frequencies": [1.0]}, "at least one design"),
                       ({"analysis": "frf", "inputs": ["force.s.length0"]}, "frequencies"),
                       ({"analysis": "frf", "inputs": ["force.s.length0"], "frequencies": [1.0],
                         "outputs": ["energy"]}, "unknown output 'energy'"),
                       ({"analysis": "frf", "inputs": ["force.s.length0"], "frequencies": [1.0],
                         "sensitivities": ["force.s.stiffness"]}, "inputs=")]:
        with pytest.raises(mbd2d.ModelError, match=needle):
            m.export(tmp_path / "m.mbd", **kw)


def test_the_command_line(tmp_path: Path) -> None:
    """``mbd2d frf``: the peaks, the CSV Python writes, a Bode plot; ``export --analysis frf``;
    bad arguments are exit 2."""
    import subprocess
    import sys
    pytest.importorskip("matplotlib")
    toml = tmp_path / "block.toml"
    toml.write_text(block_text())

    def cli(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "mbd2d", *args], capture_output=True,
                              text=True, timeout=120)
    r = cli("frf", str(toml), "--input", "force.s.f.poly.0", "--f", "0.1:10:25", "--log",
            "--out", str(tmp_path / "f.csv"), "--picture", str(tmp_path / "b.png"))
    assert r.returncode == 0, r.stderr
    assert "block.y" in r.stdout and "peak" in r.stdout
    res = mbd2d.load(toml).frequency_response("force.s.f.poly.0", np.geomspace(0.1, 10, 25))
    res.to_csv(tmp_path / "p.csv")
    assert (tmp_path / "f.csv").read_text() == (tmp_path / "p.csv").read_text()
    assert (tmp_path / "b.png").stat().st_size > 1000
    r = cli("export", str(toml), str(tmp_path / "m.mbd"), "--analysis", "frf", "--input",
            "force.s.f.poly.0", "--f", "0.1:10:25", "--log")
    assert r.returncode == 0, r.stderr
    from test_standalone import solve_file
    assert solve_file(tmp_path / "m.mbd", tmp_path / "s.csv") == (tmp_path / "p.csv").read_text()
    r = cli("frf", str(toml), "--input", "force.s.f.poly.0", "--f", "0.1:10:25", "--log",
            "--out", str(tmp_path / "fr.csv"), "--reactions")
    assert r.returncode == 0, r.stderr
    res.to_csv(tmp_path / "pr.csv", reactions=True)
    assert (tmp_path / "fr.csv").read_text() == (tmp_path / "pr.csv").read_text()
    assert "d(guide.fx_j)/d(force.s.f.poly.0).re" in (tmp_path / "fr.csv").read_text()
    for bad in (["--f", "1:2"], ["--f", "0:2:5", "--log"], ["--out", str(tmp_path / "x.txt")],
                ["--f", "1:2:3", "--input", "force.s.nope"], ["--f", "1:2:0"],
                ["--f", "1:2:3", "--body", "wheel", "--picture", str(tmp_path / "x.png")]):
        args = ["frf", str(toml)] + (["--input", "force.s.f.poly.0"] if "--input" not in bad
                                     else []) + bad
        r = cli(*args)
        assert r.returncode == 2 and "Traceback" not in r.stderr, (bad, r.stderr)
    # a sweep file of the response (tests/test_sweep_frf.py: the sweep's own checks)
    r = cli("export", str(toml), str(tmp_path / "w.mbd"), "--analysis", "frf", "--input",
            "force.s.f.poly.0", "--f", "1:2:3", "--param", "force.s.stiffness=30:40:3")
    assert r.returncode == 0, r.stderr
    ds = mbd2d.sweep(mbd2d.load(toml), {"force.s.stiffness": np.linspace(30.0, 40.0, 3)},
                     "frf", inputs=["force.s.f.poly.0"], frequencies=np.linspace(1, 2, 3),
                     workers=1)
    mbd2d.write_sweep(ds, tmp_path / "w.csv")
    assert solve_file(tmp_path / "w.mbd", tmp_path / "ws.csv") == \
        (tmp_path / "w.csv").read_text()


def test_the_operating_deflection_shape_of_the_pushed_block(tmp_path: Path) -> None:
    """The steady motion at a frequency (res.deflection): the block's y moves by
    a Re(H e^(i 2 pi f t)) over one period, H = -1/(k - m w^2 + i c w) per unit of the
    actuator's force (closed form), at the computed frequency nearest to the one asked for;
    at 0 Hz the static deflection a sin(2 pi t) H over 1 s; by default the block moves by 15%
    of the mechanism's size. GIFs from Python and from ``mbd2d frf --picture x.gif`` (at
    --at, and at the peak by default); a frequency that is no number, an --at without an
    animation, an amplitude or a frame count that is not one (here and in a mode's
    motion): ModelErrors."""
    k, c, m = 36.0, 1.5, 2.0
    res = block(k, c, m).frequency_response("force.s.f.poly.0", FREQS)
    for asked, f in ((0.68, 0.6755), (1.3, 1.3), (24.0, 25.0), (0.0, 0.0)):
        mot = res.deflection(asked, amplitude=0.2, frames=21)
        w = 2 * np.pi * f
        h = -1 / (k - m * w**2 + 1j * c * w)
        period = 1 / f if f > 0 else 1.0
        assert mot.t[-1] == pytest.approx(period) and mot.q.shape == (21, 3)
        wave = np.exp(1j * w * mot.t) if f > 0 else np.sin(2 * np.pi * mot.t)
        np.testing.assert_allclose(mot.q[:, 1] - res.q[1], 0.2 * (h * wave).real, rtol=0,
                                   atol=1e-14)
        np.testing.assert_array_equal(mot.q[:, [0, 2]], np.tile(res.q[[0, 2]], (21, 1)))
    default = res.deflection(0.7)
    move = np.abs(default.q[:, 1] - res.q[1]).max()
    assert move == pytest.approx(0.15 * abs(res.q[1]), rel=1e-3)    # (frames: the peak)
    for bad in ("fast", float("nan"), None):
        with pytest.raises(mbd2d.ModelError, match="frequency must be a finite number"):
            res.deflection(bad)
    modes = block(k, c, m).modes()
    for kw, needle in [({"frames": "x"}, "frames must be a whole number"),
                       ({"frames": 10**9}, "frames must be a whole number"),
                       ({"frames": 2}, "frames must be a whole number"),
                       ({"amplitude": "x"}, "amplitude must be a number"),
                       ({"amplitude": float("nan")}, "amplitude must be finite")]:
        for call in (lambda: res.deflection(1.3, **kw), lambda: modes.motion(0, **kw)):
            with pytest.raises(mbd2d.ModelError, match=needle):   # (before: a ValueError,
                call()                                  # NaN frames, or 1e9 frames' memory)
    pytest.importorskip("matplotlib")
    res.animate(1.3, tmp_path / "ods.gif", fps=10)
    assert (tmp_path / "ods.gif").stat().st_size > 1000
    toml = tmp_path / "block.toml"
    toml.write_text(block_text(k, c, m))
    import subprocess
    import sys
    grid = np.linspace(0.0, 5.0, 21)
    peak = grid[np.argmax(np.abs(1 / (k - m * (2 * np.pi * grid)**2 + 2j * np.pi * c * grid)))]
    for extra, hz in (([], f"{peak:g}"), (["--at", "4.1"], "4")):     # (the nearest: 4)
        r = subprocess.run([sys.executable, "-m", "mbd2d", "frf", str(toml), "--input",
                            "force.s.f.poly.0", "--f", "0:5:21", "--body", "block",
                            "--picture", str(tmp_path / "c.gif"), *extra],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        assert f"at {hz} Hz" in r.stdout and (tmp_path / "c.gif").stat().st_size > 1000
    r = subprocess.run([sys.executable, "-m", "mbd2d", "frf", str(toml), "--input",
                        "force.s.f.poly.0", "--f", "0:5:21", "--at", "2"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--at is the frequency of an animation" in r.stderr
