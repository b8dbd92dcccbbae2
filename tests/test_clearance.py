"""A crank-slider with a revolute clearance joint between the connecting rod and the slider
(issue 13), in the setup of Flores' studies (Flores & Ambrosio 2004, Computers & Structures
82: 1359-1369; Flores 2010, Nonlinear Dynamics 61: 633-653): crank 0.05 m, 0.30 kg,
1e-4 kg m^2; rod 0.12 m, 0.21 kg, 2.5e-4 kg m^2; slider 0.14 kg; journal radius 9.5 mm in a
10 mm bearing (radial clearance 0.5 mm); Lankarani-Nikravesh law, restitution 0.9, Hertz
stiffness of steel cylinders (E = 207 GPa, nu = 0.3); crank at 5000 rpm.

The reference is the ideal joint's slider motion in closed form, x = L1 cos(theta) +
sqrt(L2**2 - L1**2 sin(theta)**2) (a driven crank: kinematics alone), not mbd2d. The checks
are the ones the papers report qualitatively: the three motion modes of the journal (free
flight, impacts, following), and a slider acceleration whose spikes reach many times the
ideal one while it oscillates about it (here: its 1 ms moving average follows the ideal
curve). Limits of the comparison: the papers' plots are not digitized here, so peak values
and impact times are not compared with them (docs/contact.md)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import mbd2d

L1, L2 = 0.05, 0.12
RJ, RB = 0.0095, 0.0100
E_YOUNG, NU = 207e9, 0.3
OMEGA = 5000 * 2 * math.pi / 60
#: Hertz stiffness of a journal in a bearing (Flores: K = 4/(3 (s_i + s_j)) sqrt(R_i R_j /
#: (R_j - R_i)), s = (1 - nu**2)/E)
K_HERTZ = 4 / (3 * 2 * (1 - NU**2) / E_YOUNG) * math.sqrt(RJ * RB / (RB - RJ))


def crank_slider(clearance: bool = True, e: float = 0.9, mu: float = 0.0) -> mbd2d.Model:
    m = mbd2d.Model("crank-slider")
    m.add_body("crank", q0=[L1 / 2, 0, 0], mass=0.30, inertia=1e-4)
    m.add_body("rod", q0=[L1 + L2 / 2, 0, 0], mass=0.21, inertia=2.5e-4)
    m.add_body("slider", q0=[L1 + L2, 0, 0], mass=0.14, inertia=1e-4)
    m.add_revolute(["ground", "crank"], [[0, 0], [-L1 / 2, 0]], name="O")
    m.add_revolute(["crank", "rod"], [[L1 / 2, 0], [-L2 / 2, 0]], name="A")
    m.add_translational(["ground", "slider"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="guide")
    if clearance:
        m.add_contact("circle-in-circle", ["rod", "slider"],
                      circle=[{"center": [L2 / 2, 0], "radius": RJ},
                              {"center": [0, 0], "radius": RB}],
                      law={"model": "lankarani-nikravesh", "stiffness": K_HERTZ,
                           "exponent": 1.5, "restitution": e},
                      friction={"mu": mu} if mu else None, name="B")
    else:
        m.add_revolute(["rod", "slider"], [[L2 / 2, 0], [0, 0]], name="B")
    m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [0.0, OMEGA]},
                 name="motor")
    return m


def ideal_x(t: np.ndarray) -> np.ndarray:
    th = OMEGA * t
    return L1 * np.cos(th) + np.sqrt(L2**2 - (L1 * np.sin(th))**2)


def ideal_acc(t: np.ndarray) -> np.ndarray:
    h = 1e-7
    return (ideal_x(t + h) - 2 * ideal_x(t) + ideal_x(t - h)) / h**2


def moving_average(a: np.ndarray, k: int) -> np.ndarray:
    return np.convolve(a, np.ones(k) / k, mode="same")


@pytest.fixture(scope="module")
def runs():
    t_end, steps = 0.024, 2400                 # two crank turns, outputs every 10 us
    return (crank_slider(False).dynamics(t_end, steps, rtol=1e-8, atol=1e-10),
            crank_slider(True).dynamics(t_end, steps, rtol=1e-8, atol=1e-10))


def test_ideal_joint_slider_follows_the_closed_form(runs):
    ideal, _ = runs
    acc = ideal_acc(ideal.t)
    np.testing.assert_allclose(ideal.body("slider").x, ideal_x(ideal.t), atol=1e-9)
    np.testing.assert_allclose(ideal.body("slider").x_ddot, acc, atol=1e-5 * np.abs(acc).max())


def test_journal_shows_free_flight_impacts_and_following(runs):
    _, cl = runs
    ev = cl.contacts
    assert ev[0].kind == "onset"                         # starts centred: flies first
    kinds = [x.kind for x in ev]
    assert all(a != b for a, b in zip(kinds, kinds[1:]))  # onsets and separations alternate
    onsets = [x for x in ev if x.kind == "onset"]
    closed = [(a.t, b.t) for a, b in zip(ev, ev[1:]) if a.kind == "onset"]
    flights = [(a.t, b.t) for a, b in zip(ev, ev[1:]) if a.kind == "separation"]
    assert sum(1 for x in onsets if x.speed > 0.1) >= 10            # impacts
    assert max(b - a for a, b in closed) > 0.1 * 2 * math.pi / OMEGA  # following
    assert max(b - a for a, b in flights) > 1e-4                     # free flight
    c = cl.contact("B")
    assert c.normal_force.max() > 10 * cl.reaction("motor").fx.std()
    # the journal's penetration into the bearing (the contact law's compliance) stays a
    # fraction of the clearance, as Hertz's law gives it at the peak force
    assert np.all(c.penetration < 0.5 * (RB - RJ))
    assert c.penetration.max() == pytest.approx((c.normal_force.max() / K_HERTZ)**(2 / 3),
                                                rel=0.1)


def test_slider_acceleration_oscillates_about_the_ideal_curve(runs):
    _, cl = runs
    t = cl.t
    acc = ideal_acc(t)
    a = cl.body("slider").x_ddot
    assert np.abs(a).max() > 5 * np.abs(acc).max()          # the impact spikes
    k = int(round(1e-3 / (t[1] - t[0])))                    # 1 ms moving average
    keep = slice(k, -k)
    fa, fi = moving_average(a, k)[keep], moving_average(acc, k)[keep]
    assert np.corrcoef(fa, fi)[0, 1] > 0.97
    assert np.sqrt(np.mean((fa - fi)**2)) < 0.15 * np.abs(acc).max()
    # and its position stays within the clearance (amplified by the rod's tilt) of the ideal
    dev = np.abs(cl.body("slider").x - ideal_x(t))
    assert dev.max() <= (RB - RJ) * (1 + L1 / L2)


def test_lower_restitution_dissipates_more(runs):
    """Restitution 0.9 against 0.5: with more dissipation per impact the impacts are slower
    on average after the first ones (the journal settles into following sooner)."""
    _, cl = runs
    low = crank_slider(True, e=0.5).dynamics(0.024, 240, rtol=1e-8, atol=1e-10)

    def mean_later_impact(res):
        on = [x.speed for x in res.contacts if x.kind == "onset"]
        return np.mean(on[3:])
    assert mean_later_impact(low) < mean_later_impact(cl)
