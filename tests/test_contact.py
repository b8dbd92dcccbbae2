"""Contacts (issue 13): a ball dropped on a floor and two discs in a central impact, checked
against references computed here without mbd2d: closed forms (free fall, momentum and
restitution of a two-particle impact), and the one-degree-of-freedom contact laws integrated
with scipy's DOP853 (the laws written out again below from their papers)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d

G = 9.81
R = 0.1                     # ball radius
K = 1.0e7                   # contact stiffness (N/m**1.5)
N_EXP = 1.5


# ------------------------------------------------------------------ the laws, independently
def damping_factor(law: str, e: float) -> float:
    """chi of Fn = k d**n (1 + chi d_dot / v0) (Hunt & Crossley 1975, Lankarani & Nikravesh
    1990, Flores et al. 2011)."""
    return {"hertz": 0.0, "hunt-crossley": 1.5 * (1 - e),
            "lankarani-nikravesh": 0.75 * (1 - e * e), "flores": 1.6 * (1 - e) / e}[law]


def bounce_reference(law: str, e: float, v0: float, m: float, k: float = K,
                     g: float = G) -> tuple[float, float]:
    """One impact of a particle of mass m falling at v0 onto a rigid floor through the
    penalty law, with gravity: (rebound speed, contact duration), by DOP853."""
    chi = damping_factor(law, e)

    def rhs(t, y):
        d, dd = y
        f = k * d**N_EXP * (1.0 + chi * dd / v0) if d > 0 else 0.0
        return [dd, g - max(f, 0.0) / m]

    out = lambda t, y: y[0]                               # noqa: E731
    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, [0, 1.0], [0.0, v0], method="DOP853", events=out, rtol=1e-12,
                    atol=1e-16, first_step=1e-9, max_step=1e-5)
    return -sol.y_events[0][0][1], sol.t_events[0][0]


def ball(law: str = "hunt-crossley", e: float = 0.8, h0: float = 1.0, k: float = K,
         mass: float = 1.0, g: float = G, v0: float = 0.0) -> mbd2d.Model:
    m = mbd2d.Model("ball", gravity=[0.0, -g])
    m.add_body("ball", q0=[0.0, h0, 0.0], mass=mass, inertia=0.4 * mass * R * R,
               v0=[0.0, -v0, 0.0])
    law_spec = {"model": law, "stiffness": k, "restitution": e}
    if law != "linear":
        law_spec["exponent"] = N_EXP
    m.add_contact("circle-line", ["ball", "ground"], circle={"center": [0, 0], "radius": R},
                  line={"point": [0.0, 0.0], "normal": [0.0, 1.0]}, law=law_spec,
                  name="floor")
    return m


METHODS = [("dopri5", {}), ("partitioned", {}), ("generalized-alpha", {"rho_inf": 0.8})]


@pytest.mark.parametrize("method,opts", METHODS, ids=[m for m, _ in METHODS])
@pytest.mark.parametrize("h0", [1.0, 0.3])
def test_onset_located_at_the_free_fall_time(method, opts, h0):
    """The first onset is t = sqrt(2 (h0 - R) / g) and its speed sqrt(2 g (h0 - R)), to the
    precision of the dead-centre search (1e-10 s) and beyond."""
    res = ball(h0=h0).dynamics(0.6, 60, method=method, rtol=1e-9, atol=1e-12, **opts)
    onset = res.contacts[0]
    assert onset.kind == "onset" and onset.contact == "floor"
    assert onset.t == pytest.approx(math.sqrt(2 * (h0 - R) / G), abs=1e-9)
    assert onset.speed == pytest.approx(math.sqrt(2 * G * (h0 - R)), rel=1e-8)


@pytest.mark.parametrize("law,e", [("hunt-crossley", 0.8), ("hunt-crossley", 0.5),
                                   ("lankarani-nikravesh", 0.9), ("flores", 0.5),
                                   ("flores", 0.9), ("hertz", 1.0)])
def test_rebound_ratio_matches_the_law(law, e):
    """The rebound speed of each bounce equals the one-degree-of-freedom reference of the law
    (DOP853 here), and the requested restitution within the law's documented accuracy
    (docs/contact.md, measured by the same reference)."""
    res = ball(law, e).dynamics(1.8, 180, rtol=1e-9, atol=1e-12)
    ev = res.contacts
    onsets = [x for x in ev if x.kind == "onset"]
    seps = [x for x in ev if x.kind == "separation"]
    assert len(onsets) >= 2 and len(seps) >= 2
    for on, off in zip(onsets[:2], seps[:2]):
        ref, dur = bounce_reference(law, e, on.speed, 1.0)
        assert off.speed == pytest.approx(ref, rel=2e-6), (on, off)
        assert off.t - on.t == pytest.approx(dur, rel=1e-5)


#: the laws' effective restitution of a particle impact (n = 1.5), as docs/contact.md
#: tabulates it (measured with the one-degree-of-freedom reference above)
DOC_EFFECTIVE = {("hunt-crossley", 0.5): 0.6630, ("hunt-crossley", 0.8): 0.8329,
                 ("lankarani-nikravesh", 0.5): 0.7252, ("lankarani-nikravesh", 0.9): 0.9132,
                 ("flores", 0.1): 0.0694, ("flores", 0.5): 0.4704, ("flores", 0.9): 0.8939}


@pytest.mark.parametrize("law,e", sorted(DOC_EFFECTIVE))
def test_restitution_within_the_documented_accuracy(law, e):
    """Without gravity the rebound ratio is the law's own: the documented table's value."""
    res = ball(law, e, g=0.0, v0=3.0, h0=0.2).dynamics(0.2, 20, rtol=1e-10, atol=1e-13)
    on, off = res.contacts[0], res.contacts[1]
    assert off.speed / on.speed == pytest.approx(DOC_EFFECTIVE[law, e], abs=1e-4)
    ref, _ = bounce_reference(law, e, 3.0, 1.0, g=0.0)
    assert off.speed == pytest.approx(ref, rel=1e-7)


def test_linear_law_rebounds_with_e_exactly():
    """The linear law's damping is chosen so that the clamped spring-dashpot rebounds with e
    (a particle without gravity)."""
    for e in (0.9, 0.6, 0.2, 0.02):
        res = ball("linear", e, k=1e6, g=0.0, v0=3.0, h0=0.2).dynamics(0.2, 20, rtol=1e-10,
                                                                         atol=1e-13)
        on, off = res.contacts[0], res.contacts[1]
        assert off.speed / on.speed == pytest.approx(e, abs=1e-7)


@pytest.mark.parametrize("law,e", [("hunt-crossley", 0.8), ("flores", 0.7)])
def test_apex_heights_fall_as_e_to_the_2k(law, e):
    """Apex k above the touching height is h0 e_eff**(2k), e_eff the law's effective
    restitution (from the reference), and the energy never grows."""
    h0 = 1.0
    res = ball(law, e, h0=h0).dynamics(2.5, 50000, rtol=1e-10, atol=1e-12)
    y = res.body("ball").y - R
    vy = res.body("ball").y_dot
    apex = [k for k in range(1, len(y) - 1) if vy[k - 1] > 0 >= vy[k]]
    assert len(apex) >= 3
    on = [x for x in res.contacts if x.kind == "onset"]
    for k, i in enumerate(apex[:3], start=1):
        eff = np.prod([bounce_reference(law, e, on[j].speed, 1.0)[0] / on[j].speed
                       for j in range(k)])
        assert y[i] == pytest.approx((h0 - R) * eff**2, rel=2e-4, abs=2e-6)
    energy = res.kinetic + res.potential
    assert np.max(np.diff(energy)) <= 1e-7 * energy[0]          # no energy gained
    assert energy[-1] < energy[0]


def test_elastic_bounce_conserves_energy_and_height():
    """hertz (e = 1): T + V (with the contact's elastic energy) is conserved through the
    impacts, and the ball comes back to its height."""
    res = ball("hertz", 1.0).dynamics(1.8, 3600, rtol=1e-10, atol=1e-12)
    energy = res.kinetic + res.potential
    assert np.ptp(energy) <= 1e-6 * energy[0]
    assert res.body("ball").y.max() == pytest.approx(1.0, abs=1e-6)


# ------------------------------------------------------------------ two discs
def discs(law: str, e: float, v: float = 2.0, k: float = 1e6, mass: float = 1.0,
          y_offset: float = 0.0) -> mbd2d.Model:
    m = mbd2d.Model("discs", gravity=[0.0, 0.0])
    m.add_body("a", q0=[0.0, 0.0, 0.0], mass=mass, inertia=0.01, v0=[v, 0.0, 0.0])
    m.add_body("b", q0=[0.5, y_offset, 0.0], mass=mass, inertia=0.01)
    spec = {"model": law, "stiffness": k, "restitution": e}
    if law != "linear":
        spec["exponent"] = N_EXP
    m.add_contact("circle-circle", ["a", "b"],
                  circle=[{"center": [0, 0], "radius": 0.1}, {"center": [0, 0], "radius": 0.1}],
                  law=spec, name="hit")
    return m


@pytest.mark.parametrize("law", ["hertz", "linear"])
@pytest.mark.parametrize("v", [2.0, 0.5])
def test_equal_discs_exchange_velocities_when_elastic(law, v):
    res = discs(law, 1.0, v=v).dynamics(1.0, 10, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(res.qd[-1, [0, 3]], [0.0, v], atol=1e-7 * v)
    np.testing.assert_allclose(res.qd[-1, [1, 4]], [0.0, 0.0], atol=1e-12)
    assert [x.kind for x in res.contacts] == ["onset", "separation"]
    assert res.contacts[0].t == pytest.approx(0.3 / v, abs=1e-9)


@pytest.mark.parametrize("e", [0.3, 0.05, 0.001])
def test_equal_discs_share_velocity_as_e_goes_to_zero(e):
    """Momentum and the restitution law of a central impact: v_a = v (1 - e)/2,
    v_b = v (1 + e)/2 (the linear law reaches e exactly), tending to the shared v/2."""
    v = 2.0
    res = discs("linear", e, v=v).dynamics(1.0, 10, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(res.qd[-1, [0, 3]], [v * (1 - e) / 2, v * (1 + e) / 2],
                               atol=1e-6)


def test_flores_discs_match_the_one_degree_reference():
    """Two equal discs are one particle of the effective mass m/2 on the relative motion."""
    v, e = 2.0, 0.4
    res = discs("flores", e, v=v, k=1e6).dynamics(1.0, 10, rtol=1e-10, atol=1e-12)
    rebound, _ = bounce_reference("flores", e, v, 0.5, k=1e6, g=0.0)
    assert res.qd[-1, 3] - res.qd[-1, 0] == pytest.approx(rebound, rel=1e-6)
    assert res.qd[-1, 0] + res.qd[-1, 3] == pytest.approx(v, rel=1e-12)       # momentum


def test_oblique_elastic_impact_conserves_energy_and_momentum():
    """An off-centre impact of hertz discs with friction-free contact: the normal force
    acts through the centres (no spin), momentum and energy are kept."""
    res = discs("hertz", 1.0, y_offset=0.08).dynamics(1.0, 100, rtol=1e-10, atol=1e-12)
    p = res.qd[:, 0] + res.qd[:, 3], res.qd[:, 1] + res.qd[:, 4]
    np.testing.assert_allclose(p[0], 2.0, rtol=1e-9)
    np.testing.assert_allclose(p[1], 0.0, atol=1e-9)
    energy = res.kinetic + res.potential
    assert np.ptp(energy) <= 1e-7 * energy[0]
    np.testing.assert_allclose(res.qd[:, [2, 5]], 0.0, atol=1e-9)


def test_contact_outputs_and_csv_columns():
    res = ball().dynamics(0.6, 600, rtol=1e-9, atol=1e-12)
    c = res.contact("floor")
    y = res.body("ball").y
    np.testing.assert_allclose(c.penetration, R - y, atol=1e-12)
    assert np.all(c.normal_force[c.penetration <= 0] == 0)
    assert np.all(c.normal_force[c.penetration > 1e-9] > 0)
    header, rows = res.table()
    assert "floor.normal_force" in header and rows.shape[1] == len(header)
    with pytest.raises(KeyError, match="no contact 'nope'"):
        res.contact("nope")


def test_fixed_step_methods_record_events_to_their_step():
    """baumgarte-rk4 and fixed-step generalized-alpha carry contacts; they change modes at
    the end of the step that crossed and record the located time."""
    exact = math.sqrt(2 * (1.0 - R) / G)
    for method, opts in (("baumgarte-rk4", {"h": 1e-5}), ("generalized-alpha", {"h": 1e-5})):
        res = ball().dynamics(0.5, 50, method=method, **opts)
        assert res.contacts[0].kind == "onset"
        assert res.contacts[0].t == pytest.approx(exact, abs=2e-5)


def test_contact_in_toml():
    text = """
[model]
name = "toml-ball"
[[body]]
name = "ball"
q0 = [0.0, 0.5, 0.0]
mass = 1.0
inertia = 0.004
[[contact]]
name = "ball-floor"
type = "circle-line"
bodies = ["ball", "ground"]
circle = { center = [0.0, 0.0], radius = 0.1 }
line = { point = [0.0, 0.0], normal = [0.0, 1.0] }
law = { model = "hunt-crossley", stiffness = 1e7, exponent = 1.5, restitution = 0.8 }
friction = { mu = 0.3 }
"""
    res = mbd2d.loads(text).dynamics(0.4, 40)
    assert res.contacts[0].t == pytest.approx(math.sqrt(2 * 0.4 / G), abs=1e-8)


@pytest.mark.parametrize("law,k", [("hertz", 1e7), ("linear", 1e6)])
def test_statics_rests_the_ball_on_its_contact(law, k):
    """Statics carries contacts as elastic elements: the ball sinks to k delta**n = m g."""
    m = ball(law, 1.0, h0=R - 1e-4, k=k)
    res = m.statics()
    n = 1.0 if law == "linear" else N_EXP
    assert R - res.q[1] == pytest.approx((G / k)**(1 / n), rel=1e-8)
