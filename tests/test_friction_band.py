"""Joint friction on the band path (large models): the parallelogram chain (N-four-bar) with
rubbing pins against its Newton-Euler equations written here without mbd2d, on both paths,
at the sizes where the automatic choice takes the band, and the band results equal to the
dense ones for every method."""
from __future__ import annotations

import dataclasses
import math
import sys
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d
from conftest import EXAMPLES
from mbd2d.description.friction import Friction

sys.path.insert(0, str(EXAMPLES))
import nfourbar  # noqa: E402

G = 9.81
MU, PIN = 0.3, 0.05
FRIC = ("O0", "L1", "R2")


def rubbing_chain(n: int, pins=FRIC, model: str = "stick-slip", driven: bool = False):
    """The N-four-bar of examples/nfourbar.py (1 kg, 1 m bars; driven: crank 0 at
    theta = pi/2 - t, else every crank turning at 1 rad/s from upright) with friction
    mu = 0.3 on pins of radius 0.05 m."""
    m = nfourbar.build(n, driven=driven, omega0=-1.0 if driven else 1.0)
    fr = Friction(MU, 0.35, model, pin_radius=PIN)
    for i, j in enumerate(m.joints):
        if j.name in pins:
            m.joints[i] = dataclasses.replace(j, friction=fr)
    return m


def chain_pins(n: int) -> list:
    """(name, body i, body j, world point(cos, sin)) of each pin; bodies: crank k is k,
    coupler k is n + 1 + k, ground -1; the pin's force acts on j, its opposite on i."""
    out = [(f"O{k}", -1, k, lambda c, s, k=k: (k, 0.0)) for k in range(n + 1)]
    for k in range(n):
        out.append((f"L{k}", k, n + 1 + k, lambda c, s, k=k: (k + c, s)))
        out.append((f"R{k}", k + 1, n + 1 + k, lambda c, s, k=k: (k + 1 + c, s)))
    return out


def newton_euler(n: int, th: float, w: float, pins=FRIC, driven: bool = False):
    """The chain's Newton-Euler equations at crank angle th and rate w: every body's
    m a = sum F + m g and I alpha = sum (r_p - c) x F_p + friction moments, unknowns the pin
    forces and theta'' (driven: theta'' = 0 and the motor torque on crank 0). The friction
    moment on j is -mu r |F_p| sign(w_j - w_i); |F_p| by fixed point.

    Returns
    -------
    float, dict
        theta'' (driven: the motor torque) and the pin force magnitudes by name.
    """
    c, s = math.cos(th), math.sin(th)
    pl = chain_pins(n)
    nb, npin = 2 * n + 1, len(pl)
    # centre (x, y), distance of the centre from the crank pivot's circle, body rate
    cen = {k: (k + 0.5 * c, 0.5 * s, 0.5) for k in range(n + 1)}
    cen.update({n + 1 + k: (k + 0.5 + c, s, 1.0) for k in range(n)})
    rate = {-1: 0.0, **{k: (w if k <= n else 0.0) for k in range(nb)}}
    fmag = np.zeros(npin)
    for _ in range(100):
        a = np.zeros((3 * nb, 2 * npin + 1))
        b = np.zeros(3 * nb)
        for k, (_, _, f) in cen.items():
            b[3 * k] = f * w * w * c                  # minus the centripetal acceleration
            b[3 * k + 1] = f * w * w * s - G
            if not driven:
                a[3 * k:3 * k + 3, -1] = [-f * s, f * c, 1.0 / 12 if k <= n else 0.0]
        if driven:
            a[2, -1] = -1.0
        for p, (name, i, j, point) in enumerate(pl):
            px, py = point(c, s)
            mom = -MU * PIN * fmag[p] * np.sign(rate[j] - rate[i]) if name in pins else 0.0
            for body, sg in ((i, -1.0), (j, 1.0)):
                if body < 0:
                    continue
                cx, cy, _ = cen[body]
                a[3 * body, 2 * p] -= sg
                a[3 * body + 1, 2 * p + 1] -= sg
                a[3 * body + 2, 2 * p:2 * p + 2] -= sg * np.array([cy - py, px - cx])
                b[3 * body + 2] += sg * mom
        x = np.linalg.solve(a, b)
        new = np.hypot(x[0:2 * npin:2], x[1:2 * npin:2])
        done = np.max(np.abs(new - fmag)) <= 1e-14 * max(1.0, np.max(new))
        fmag = new
        if done:
            break
    return x[-1], {name: fmag[p] for p, (name, *_) in enumerate(pl)}


def test_oracle_without_friction_is_the_closed_form():
    """The oracle itself: without friction, J theta'' = -c g cos(theta) with J = (N+1)/3 + N
    and c = (N+1)/2 + N, and the driven chain's torque c g cos(theta)."""
    n, th = 3, 2.0
    acc, _ = newton_euler(n, th, 1.3, pins=())
    c = (n + 1) / 2 + n
    assert acc == pytest.approx(-c * G * math.cos(th) / ((n + 1) / 3 + n), rel=1e-13)
    torque, _ = newton_euler(n, th, -1.0, pins=(), driven=True)
    assert torque == pytest.approx(c * G * math.cos(th), rel=1e-13)


def check_outputs(res, n: int, pins=FRIC, every: int = 5, rel: float = 1e-11) -> None:
    """At the result's own outputs: theta'', the pin loads and the friction moments equal
    the Newton-Euler ones to rounding (rel)."""
    crank = res.body("crank0")
    th, w = crank.theta, crank.theta_dot
    for k in range(0, len(res.t), every):
        acc, loads = newton_euler(n, th[k], w[k], pins)
        assert crank.theta_ddot[k] == pytest.approx(acc, abs=1e-11 * (1 + abs(acc)))
        for name in pins:
            fr = res.friction(name)
            assert fr.normal_load[k] == pytest.approx(loads[name], rel=rel)
            sgn = 1.0 if name.startswith("O") else -1.0       # crank vs ground or coupler
            ref = -MU * PIN * loads[name] * sgn * np.sign(w[k])
            assert fr.moment[k] == pytest.approx(ref, rel=rel)


@pytest.mark.parametrize("solver", ["dense", "banded"])
def test_rubbing_chain_follows_newton_euler(solver):
    """Three pins with Coulomb friction on the 3-loop chain falling from upright (dopri5,
    0.5 s, before the parallelogram's collinear position): crank angle against the
    Newton-Euler equation integrated by scipy (DOP853 1e-13), the error falling with the
    tolerance, and each output's acceleration and pin loads to rounding."""
    n = 3
    m = rubbing_chain(n)
    sol = solve_ivp(lambda t, y: [y[1], newton_euler(n, y[0], y[1])[0]], [0, 0.5],
                    [math.pi / 2, 1.0], method="DOP853", rtol=1e-13, atol=1e-14,
                    dense_output=True)
    errs = []
    for tol in (1e-6, 1e-8, 1e-10):
        res = m.dynamics(0.5, 20, rtol=tol, atol=tol * 1e-2, solver=solver)
        assert res.stats["solver"] == solver
        errs.append(np.max(np.abs(res.body("crank0").theta - sol.sol(res.t)[0])))
        assert errs[-1] < 10 * tol
        check_outputs(res, n)
    assert errs[0] > 50 * errs[1] > 2500 * errs[2]


def test_large_rubbing_chain_takes_the_band():
    """N = 100 (603 coordinates) with friction on three pins: the automatic choice is the
    band (it was the dense path for any model with joint friction), and the outputs satisfy
    the chain's Newton-Euler equations."""
    n = 100
    pins = ("O0", "L50", "R99")
    res = rubbing_chain(n, pins).dynamics(0.3, 6, rtol=1e-8, atol=1e-10)
    assert res.stats["solver"] == "banded"
    check_outputs(res, n, pins, every=2)


@pytest.mark.parametrize("n,solver", [(3, "dense"), (3, "banded"), (100, "auto")])
def test_driven_rubbing_chain_motor_torque(n, solver):
    """Inverse dynamics: the motor torque of the driven chain with three rubbing pins against
    the Newton-Euler equations with theta'' = 0 (the auto choice at N = 100 the band); up to
    theta = 0.37, away from the collinear position where the pin forces lose their
    digits to conditioning in both (2e-7 at theta = 0.07, N = 30)."""
    pins = ("O0", f"L{n // 2}", f"R{n - 1}")
    res = rubbing_chain(n, pins, model="regularized", driven=True).inverse_dynamics(
        1.2, 8, solver=solver)
    assert res.stats["solver"] == ("banded" if solver == "auto" else solver)
    for k, t in enumerate(res.t):
        torque, loads = newton_euler(n, math.pi / 2 - t, -1.0, pins, driven=True)
        assert res.effort("motor")[k] == pytest.approx(torque, rel=1e-10, abs=1e-10)
        for name in pins:
            assert res.friction(name).normal_load[k] == pytest.approx(loads[name], rel=1e-10)


@pytest.mark.parametrize("method,opts,model", [
    ("dopri5", {"rtol": 1e-9, "atol": 1e-11}, "stick-slip"),
    ("partitioned", {"rtol": 1e-9, "atol": 1e-11}, "stick-slip"),
    ("generalized-alpha", {"h": 2e-3}, "regularized"),
    ("baumgarte-rk4", {"h": 2e-3}, "regularized")])
def test_band_equals_dense_with_friction(method, opts, model):
    """Every method with joint friction: the band path gives the dense results (positions,
    multipliers, loads and friction forces) to 1e-10 at N = 20."""
    m = rubbing_chain(20, ("O0", "L10", "R19", "O20"), model=model)
    dense = m.dynamics(0.3, 10, method=method, solver="dense", **opts)
    band = m.dynamics(0.3, 10, method=method, solver="banded", **opts)
    np.testing.assert_allclose(band.q, dense.q, atol=1e-10)
    scale = np.max(np.abs(dense.lam))
    np.testing.assert_allclose(band.lam, dense.lam, atol=1e-10 * scale)
    for name in ("O0", "L10", "R19", "O20"):
        a, b = dense.friction(name), band.friction(name)
        np.testing.assert_allclose(b.normal_load, a.normal_load, atol=1e-10 * scale)
        np.testing.assert_allclose(b.friction_force, a.friction_force, atol=1e-10 * scale)


def test_friction_at_the_collinear_position_stops_and_says_why():
    """Next to the parallelogram's collinear position J loses a rank: the pin loads grow like
    1 / distance and the friction on them can have several solutions or none (the oracle's
    fixed point for |F| stops converging within 0.01 rad of theta = pi: a rigid linkage
    with Coulomb friction jams there). Without friction the chain passes theta = pi; with
    one rubbing pin dopri5 stops just before it with an IntegrationError that names joint
    friction and the jam, the rows before kept and still Newton-Euler's; the partitioned
    method at a tight tolerance stops or warns (SingularPassageWarning), never silently."""
    free = rubbing_chain(3, ()).dynamics(1.0, 20, rtol=1e-8, atol=1e-10)
    assert free.body("crank0").theta[-1] > math.pi + 1.0
    for pin in ("O0", "L1"):
        with pytest.raises(mbd2d.IntegrationError, match="joint friction.*jams") as err:
            rubbing_chain(3, (pin,)).dynamics(1.0, 20, rtol=1e-8, atol=1e-10)
        kept = err.value.results
        assert math.pi - 0.2 < kept.body("crank0").theta[-1] < math.pi
        # (the loads lose digits like 1 / distance: 6e-11 at 0.09 rad from the position)
        check_outputs(kept, 3, (pin,), every=1, rel=1e-9)
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        try:
            rubbing_chain(3, ("O0",)).dynamics(1.0, 20, method="partitioned", rtol=1e-10,
                                               atol=1e-12)
            said = any(issubclass(w.category, mbd2d.SingularPassageWarning) for w in got)
        except mbd2d.IntegrationError as exc:
            said = "joint friction" in str(exc)
    assert said
