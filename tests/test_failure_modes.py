"""Where the forward-dynamics methods fail, measured (docs/dynamics.md shows the same runs).

Every test runs a model, measures what happened (constraint drift, energy, step counts,
multipliers, the branch of the N-four-bar) and asserts the behaviour documented in
docs/dynamics.md. The oracles are independent of the engine: energy conservation (no damping
or forcing anywhere), the constraint residuals, the classical stability limits of RK4 and
Dormand-Prince, and for the N-four-bar a one-degree-of-freedom reduced model integrated by a
small RK4 written here.

Models (all bars uniform, I = m L^2 / 12, gravity 9.81 m/s^2 down):

* free four-bar: the geometry of examples/fourbar_grashof.toml (crank 1, coupler 3.5,
  rocker 2.5, ground 3), 1 kg per metre of bar, no driver, released at rest;
* stiff cart-pendulum: a 1 kg cart on a horizontal guide held by a spring k to ground, a
  1 kg, 1 m bar hinged on it and released at rest 60 degrees from hanging. The stiff mode has
  omega^2 = k / (m_cart + m_bar - (m_bar L/2)^2 / (m_bar L^2/3)) = k / 1.25;
* free N-four-bar: examples/nfourbar.py's geometry (cranks of length 1 at x = 0..N,
  couplers of length 1), 1 kg bars, cranks upright at t = 0 turning at -1 rad/s;
* examples/pendulum_spring.toml.

docs/failure_modes.py imports the builders from here to draw the charts.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import free_fourbar as free_fourbar_example  # noqa: E402
import nfourbar  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
G = 9.81

# classical stability limits (|R(z)| <= 1) of the explicit tableaus in the engine
RK4_REAL_LIMIT = 2.785    # RK4 on the negative real axis
RK4_IMAG_LIMIT = 2.828    # RK4 on the imaginary axis (2 sqrt 2)
DP5_RADIUS = 4.0          # Dormand-Prince 5: its whole stability region lies in |z| < 3.98
#                           (3.31 on the negative real axis; on the imaginary axis |R| > 1
#                           already for 0.95 < |z| < 3.5, if only slightly at first)


# ----------------------------------------------------------------------------- models
def free_fourbar(density: float = 1.0) -> mbd2d.Model:
    """The free four-bar of examples/free_fourbar.py."""
    return free_fourbar_example.build(density)


def cart_pendulum(k: float, phi0: float = math.radians(60.0)) -> mbd2d.Model:
    """A 1 kg cart on a horizontal guide, held at x = 0 by a spring of stiffness k to ground,
    with a uniform 1 kg, 1 m bar hinged at the cart and released at rest phi0 from hanging."""
    m = mbd2d.Model("stiff-cart-pendulum", gravity=(0.0, -G))
    m.add_body("cart", q0=[0.0, 0.0, 0.0], mass=1.0, inertia=0.1)
    m.add_body("bar", q0=[0.5 * math.sin(phi0), -0.5 * math.cos(phi0), phi0 - math.pi / 2],
               mass=1.0, inertia=1.0 / 12)
    m.add_translational(["ground", "cart"], [[0.0, 0.0], [0.0, 0.0]], [[1.0, 0.0], [1.0, 0.0]],
                        name="guide")
    m.add_revolute(["cart", "bar"], [[0.0, 0.0], [-0.5, 0.0]], name="hinge")
    m.add_spring(["ground", "cart"], [[-1.0, 0.0], [0.0, 0.0]], stiffness=k, length0=1.0,
                 name="spring")
    return m


def stiff_omega(k: float) -> float:
    """Angular frequency of the cart-pendulum's stiff mode (bar hanging)."""
    return math.sqrt(k / 1.25)


def free_nfourbar(n: int, omega0: float = -1.0) -> mbd2d.Model:
    """The N-four-bar of examples/nfourbar.py without its driver: 1 kg, 1 m bars, cranks
    upright, every crank turning at omega0 and the couplers translating (consistent v0)."""
    return nfourbar.build(n, driven=False, omega0=omega0)


def reduced_nfourbar(n: int, t: np.ndarray, th0: float = math.pi / 2, omega0: float = -1.0,
                     substeps: int = 20) -> np.ndarray:
    """The parallelogram branch as one degree of freedom: every crank at th, couplers
    translating. T = 1/2 (N+1) (m L^2/3) th'^2 + 1/2 N m L^2 th'^2 and
    V = (N+1) m g (L/2) sin th + N m g L sin th, so Lagrange's equation is
    ((N+1)/3 + N) th'' = -((N+1)/2 + N) g cos th (m = L = 1). Classical RK4 with `substeps`
    steps per output interval; returns (th, th') at the times t (rows)."""
    inertia = (n + 1) / 3.0 + n
    load = ((n + 1) / 2.0 + n) * G

    def f(y: np.ndarray) -> np.ndarray:
        return np.array([y[1], -load * math.cos(y[0]) / inertia])

    y = np.array([th0, omega0], dtype=float)
    out = [y.copy()]
    for a, b in zip(t[:-1], t[1:]):
        h = (b - a) / substeps
        for _ in range(substeps):
            k1 = f(y)
            k2 = f(y + 0.5 * h * k1)
            k3 = f(y + 0.5 * h * k2)
            k4 = f(y + h * k3)
            y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(y.copy())
    return np.array(out)


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles mapped into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


# ----------------------------------------------------------------------------- measures
def energy_error(res: mbd2d.DynamicsResult) -> np.ndarray:
    """|E(t) - E(0)| (J)."""
    return np.abs(res.energy - res.energy[0])


def window(res: mbd2d.DynamicsResult, values: np.ndarray, t0: float, t1: float) -> float:
    """max |values| over the outputs with t0 <= t <= t1."""
    sel = (res.t >= t0 - 1e-12) & (res.t <= t1 + 1e-12)
    return float(np.abs(values[sel]).max())


def run_or_fail(model: mbd2d.Model, *args, **kw) -> tuple[mbd2d.DynamicsResult,
                                                           mbd2d.IntegrationError | None]:
    """(results, None) or, when the method fails, (the partial results, the error)."""
    try:
        return model.dynamics(*args, **kw), None
    except mbd2d.IntegrationError as e:
        return e.results, e


PASSAGE_METHODS = {          # the settings of each method in the passage runs
    "generalized-alpha": {},
    "dopri5": {},
    "baumgarte-rk4": {"h": 1e-3},
    "partitioned": {},
}
PASSAGE_T_END = 3.5     # four passages through the flat (singular) position: 0.71, 1.22, 2.63,
#                         3.14 s (N = 1; N = 2 within 0.03 s of these)
PASSAGE_TIMES = (0.708, 1.215, 2.632, 3.139)


def nfourbar_passage(n: int, method: str, settings: dict | None = None,
                     t_end: float = PASSAGE_T_END, steps: int = 350) -> dict:
    """Free N-four-bar through its singular positions with one method (settings default to
    PASSAGE_METHODS[method]), against the reduced one-degree-of-freedom solution."""
    settings = PASSAGE_METHODS[method] if settings is None else settings
    res, err = run_or_fail(free_nfourbar(n), t_end, steps, method=method, **settings)
    ref = reduced_nfourbar(n, np.linspace(0.0, t_end, steps + 1))[:len(res.t)]
    th = np.array([res.body(f"crank{k}").theta for k in range(n + 1)])
    dev = np.abs(wrap(th - ref[:, 0])).max(axis=0)            # per output, over cranks
    branch = np.abs(wrap(th - th[0])).max(axis=0)              # cranks parallel to crank0?
    return {"res": res, "error": err, "ref": ref, "deviation": dev, "branch": branch,
            "max_deviation": float(dev.max()), "max_branch": float(branch.max()),
            "energy_error": float(energy_error(res).max()),
            "t_reached": float(res.t[-1])}


# ----------------------------------------------------------------------------- Baumgarte
def test_baumgarte_without_stabilization_drifts_and_the_drift_grows() -> None:
    """alpha = beta = 0 integrates J q_ddot = gamma only: the truncation errors of each step
    accumulate, the velocity drift grows like t and the position drift like t^2, while the
    default alpha = beta = 10 keeps both bounded (free four-bar, h = 1e-2, 40 s)."""
    m = free_fourbar()
    off = m.dynamics(40.0, 40, method="baumgarte-rk4", h=1e-2, alpha=0.0, beta=0.0)
    on = m.dynamics(40.0, 40, method="baumgarte-rk4", h=1e-2)
    d_off, d_on = off.drift_position, on.drift_position
    # measured: 8.7e-4 at t = 40 s without stabilization, at most 3.2e-7 with it
    assert d_off[-1] > 1e3 * d_on.max()
    # it grows: steadily from t = 2 s on, by more than 100x between t = 4 s and t = 40 s
    assert np.all(np.diff(d_off[2:]) > 0.0)
    assert d_off[40] > 100 * d_off[4]
    slope = math.log(d_off[40] / d_off[4]) / math.log(10.0)    # measured 2.03
    assert 1.5 < slope < 2.5
    # the stabilized drift does not grow: the last 10 s are no worse than the first 10 s
    assert window(on, d_on, 30, 40) < 3 * window(on, d_on, 0, 10)
    # the velocity drift grows about linearly (4 s: 3.4e-6, 40 s: 4.3e-5), and the energy
    # error follows: 3.6e-2 J at 40 s against 8e-4 J with stabilization
    v_off = off.drift_velocity
    assert 0.7 < math.log(v_off[40] / v_off[4]) / math.log(10.0) < 1.5   # measured 1.1
    assert window(on, on.drift_velocity, 0, 40) < 0.2 * v_off[40]
    assert energy_error(off)[-1] > 10 * energy_error(on)[-1]


def test_baumgarte_coefficients_beyond_the_rk4_limit_blow_up() -> None:
    """The stabilized constraint error obeys e'' + 2 alpha e' + beta^2 e = 0; with
    alpha = beta its double eigenvalue -alpha must lie in RK4's stability interval,
    h alpha < 2.785. alpha = beta = 1e4 at h = 1e-3 (h alpha = 10) blows up within a few
    steps; 2800 (h alpha = 2.8) within 0.15 s; 2000 (h alpha = 2) runs."""
    m = free_fourbar()
    h = 1e-3
    fine = m.dynamics(1.0, 1000, method="baumgarte-rk4", h=h, alpha=2000.0, beta=2000.0)
    assert h * 2000.0 < RK4_REAL_LIMIT
    assert fine.drift_position.max() < 1e-4                     # measured 4.9e-6
    assert energy_error(fine).max() < 1e-2                       # measured 3.8e-4

    for ab, t_fail in ((1e4, 0.02), (2800.0, 0.5)):
        assert h * ab > RK4_REAL_LIMIT
        with pytest.raises(mbd2d.IntegrationError, match="blew up|unstable") as info:
            m.dynamics(1.0, 1000, method="baumgarte-rk4", h=h, alpha=ab, beta=ab)
        part = info.value.results
        assert info.value.t < t_fail                             # measured 0.007 s, 0.136 s
        d = part.drift_position[np.isfinite(part.drift_position)]
        assert d[0] < 1e-13
        # from 6e-15 until the engine stops it (violation > 1e-3 of the model size)
        assert d[-1] > 1e-4
        # exponential growth: every recorded step makes it worse
        assert np.all(np.diff(d[1:]) > 0.0)
    # at 1e4 the drift grows 100-1000x per 1 ms step (|R(-10)| = 291 for RK4, with a double
    # eigenvalue): 9e-12, 8.8e-9, 4.3e-6, then stopped (it went on to 1.7e-3, 0.21, 2.2e7
    # before the engine checked the violation)
    with pytest.raises(mbd2d.IntegrationError) as info:
        m.dynamics(1.0, 1000, method="baumgarte-rk4", h=h, alpha=1e4, beta=1e4)
    d = info.value.results.drift_position
    growth = d[2:] / d[1:-1]                                     # measured 977, 489
    assert len(growth) >= 2 and np.all(growth > 50.0)


# ----------------------------------------------------------------------------- stiff spring
def test_stiff_spring_limits_explicit_steps_not_generalized_alpha() -> None:
    """k = 1e7 on the cart-pendulum: omega = 2828 rad/s. The explicit methods are held at
    h omega of order 1-3 whatever the tolerance (dopri5 needs thousands of steps a second;
    baumgarte-rk4 blows up above h omega = 2.83; partitioned at a loose tolerance lets the
    stiff mode grow); generalized-alpha takes steps of h omega = 28 to 100 with bounded
    energy."""
    k = 1e7
    om = stiff_omega(k)
    stiff, soft = cart_pendulum(k), cart_pendulum(1e3)
    loose = {"rtol": 1e-3, "atol": 1e-6}
    t_end = 1.0

    # dopri5: the steps stay below the stability radius, even at a loose tolerance
    d_tight = stiff.dynamics(t_end, 100, method="dopri5")
    d_loose = stiff.dynamics(t_end, 100, method="dopri5", **loose)
    d_soft = soft.dynamics(t_end, 100, method="dopri5", **loose)
    for r in (d_tight, d_loose):
        assert r.stats["h_max"] * om < DP5_RADIUS                # measured 0.86 and 1.94
        assert r.stats["steps"] > t_end * om / DP5_RADIUS        # > 707; measured 4655, 1933
    # relaxing the tolerance 1000x saves less than 3x: stability, not accuracy, sets h
    assert d_loose.stats["steps"] > d_tight.stats["steps"] / 3
    # the same model with k = 1e3 needs far fewer steps at the same tolerance (25: 77x)
    assert d_loose.stats["steps"] > 20 * d_soft.stats["steps"]

    # baumgarte-rk4: stable below the RK4 limit h omega = 2.83, blows up above it
    ok = stiff.dynamics(t_end, 100, method="baumgarte-rk4", h=5e-4)
    assert 5e-4 * om < RK4_IMAG_LIMIT
    assert energy_error(ok).max() < 1e-5                         # measured 5e-7 J
    assert 2e-3 * om > RK4_IMAG_LIMIT
    with pytest.raises(mbd2d.IntegrationError, match="blew up|unstable") as info:
        stiff.dynamics(t_end, 100, method="baumgarte-rk4", h=2e-3)
    assert info.value.t < 0.1                                    # measured 0.01 s

    # just above the limit at the bottom of the swing (h omega = 2.97 there, 2.47 at 60
    # degrees) the stiff mode grows from the first passage of the bar through the bottom
    # (0.42 s); before anything becomes non-finite, the growing constraint violation stops
    # the run as unstable (without that check it ended with a 3.6e4 J energy error)
    with pytest.raises(mbd2d.IntegrationError, match="unstable") as info:
        stiff.dynamics(t_end, 100, method="baumgarte-rk4", h=1.05e-3)
    assert 0.4 < info.value.t < t_end                             # measured 0.46 s
    ee = energy_error(info.value.results)
    assert ee[info.value.results.t < 0.4].max() < 1e-5            # measured 5e-7 J

    # at the loose tolerance partitioned lets the stiff mode grow (its error norm sees only
    # the independent coordinates, and DP5 amplifies |R(iy)| > 1 for 0.95 < y < 3.5): the
    # energy rises by about 1 J of 2.45 J in 1 s; dopri5 at the same tolerance: 2e-5 J
    p_loose = stiff.dynamics(t_end, 100, method="partitioned", **loose)
    assert energy_error(p_loose).max() > 0.1                       # measured 1.1 J
    assert energy_error(d_loose).max() < 1e-3                      # measured 1.9e-5 J

    # generalized-alpha's error control at a tolerance that does not ask to resolve the
    # micrometre stiff vibration: large steps (measured 147; dopri5 above: 1900-4700)
    gl = stiff.dynamics(t_end, 100, method="generalized-alpha", rtol=1e-4, atol=1e-6)
    assert gl.stats["h_max"] * om > 10 * DP5_RADIUS                # measured 66
    assert d_loose.stats["steps"] > 10 * gl.stats["steps"]

    # generalized-alpha with a fixed step 20x above the explicit limits: stable, 10 s
    ga = stiff.dynamics(10.0, 1000, method="generalized-alpha", h=1e-2)
    assert 1e-2 * om > 10 * RK4_IMAG_LIMIT
    assert energy_error(ga).max() < 3e-3                          # measured 1.2e-3 J of 2.45
    assert np.abs(ga.body("cart").x).max() < 1e-5                # static deflection ~F/k
    # and no growth: the last 2 s no worse than the first 2 s (x 2)
    ee = energy_error(ga)
    assert window(ga, ee, 8, 10) < 2 * window(ga, ee, 0, 2) + 1e-4


# ----------------------------------------------------------------------------- rho_inf = 1
@pytest.mark.parametrize("model, t_end, t_fail", [
    ("free-four-bar", 10.0, (5.0, 10.0)),          # measured: Newton fails at 7.41 s
    ("pendulum_spring", 20.0, (5.0, 20.0)),        # measured: Newton fails at 9.88 s
    # (IntegrationError.t is the last output kept: 7.40 s and 9.87 s)
])
def test_generalized_alpha_without_damping_grows_a_sawtooth(model: str, t_end: float,
                                                            t_fail: tuple) -> None:
    """Index-3 generalized-alpha at rho_inf = 1 leaves the recursion of the accelerations
    with a root at -1: a step-to-step sawtooth in the scheme's q_ddot (and its lambda) that
    nothing damps. It grows until Newton fails (fixed h = 1e-2); at rho_inf = 0.8 it is
    damped. The reported multipliers are those of the index-1 equations at each output
    state, so they do not carry the sawtooth; the velocity drift and the energy show the
    state going wrong."""
    m = free_fourbar() if model == "free-four-bar" else \
        mbd2d.load(ROOT / "examples" / "pendulum_spring.toml")
    damped = m.dynamics(t_end, int(round(t_end / 1e-2)), method="generalized-alpha", h=1e-2,
                        rho_inf=0.8)
    with pytest.raises(mbd2d.IntegrationError, match="Newton did not converge") as info:
        m.dynamics(t_end, int(round(t_end / 1e-2)), method="generalized-alpha", h=1e-2,
                   rho_inf=1.0)
    und = info.value.results
    assert t_fail[0] < info.value.t < t_fail[1]
    qdd_ok = np.abs(damped.qdd).max()
    dv_ok = damped.drift_velocity.max()
    # early on the two agree (same step, same accuracy) ...
    assert window(und, und.qdd, 0, 2) < 1.05 * window(damped, damped.qdd, 0, 2)
    assert window(und, und.drift_velocity, 0, 2) < 1.5 * window(damped, damped.drift_velocity,
                                                                0, 2)
    # ... in the last second before the failure the accelerations are 300x their damped
    # size (measured 550x, 650x) and the velocity constraints are violated 100x more
    t_end_und = float(und.t[-1])
    assert window(und, und.qdd, t_end_und - 1, t_end_und) > 300 * qdd_ok
    assert window(und, und.drift_velocity, t_end_und - 1, t_end_und) > 100 * dv_ok
    # the position constraints stay satisfied (index 3 enforces them)
    assert und.drift_position.max() < 1e-10
    # the growth is a sawtooth: the largest acceleration alternates in sign step by step
    row = int(np.argmax(np.abs(und.qdd[-1])))
    tail = und.qdd[-8:, row]
    assert np.all(tail[1:] * tail[:-1] < 0.0)
    # the multipliers of the states stay of their physical size (measured 253 N of 190 N,
    # 19 N of 15 N): the reactions of a wrong state, not the sawtooth
    assert window(und, und.lam, t_end_und - 1, t_end_und) < 2 * np.abs(damped.lam).max()
    # the damped run is stable: energy within 0.2 % and no growth
    assert energy_error(damped).max() < 2e-3 * np.abs(damped.energy).max() + 1e-3
    assert window(damped, damped.lam, t_end - 2, t_end) < 1.1 * window(damped, damped.lam,
                                                                       0, t_end - 2)
    assert window(damped, damped.qdd, t_end - 2, t_end) < 1.1 * window(damped, damped.qdd,
                                                                       0, t_end - 2)


def test_generalized_alpha_without_damping_small_step_grows_without_an_error() -> None:
    """At h = 1e-3 the rho_inf = 1 run of the free four-bar reaches 10 s without an error,
    but the scheme's accelerations end near 2e5 rad/s^2 (physical: below 30) and J q_dot - nu
    near 0.02."""
    m = free_fourbar()
    und = m.dynamics(10.0, 1000, method="generalized-alpha", h=1e-3, rho_inf=1.0)
    assert window(und, und.qdd, 0, 4) < 30.0                      # measured 29.3
    assert window(und, und.qdd, 9, 10) > 1e5                      # measured 1.8e5
    assert window(und, und.drift_velocity, 9, 10) > 1e-2          # measured 2.3e-2
    assert energy_error(und)[-1] > 0.1                            # measured 0.33 J
    assert und.drift_position.max() < 1e-10


def test_error_controlled_generalized_alpha_refuses_rho_inf_one() -> None:
    """Without damping the sawtooth in q_ddot reads as local error and the step collapses
    (measured: about 2e6 steps for 0.03 s of Andrews' squeezer), so the engine refuses the
    combination and names the way out; with a fixed step rho_inf = 1 is allowed (above)."""
    m = free_fourbar()
    with pytest.raises(mbd2d.ModelError, match="rho_inf <= 0.9 or give a fixed step h"):
        m.dynamics(1.0, 10, method="generalized-alpha", rho_inf=1.0)
    ok = m.dynamics(1.0, 10, method="generalized-alpha", rho_inf=0.9, rtol=1e-6)
    assert ok.stats["steps"] < 2000


# ----------------------------------------------------------------------------- N-four-bar
PASSAGE_DEVIATION = {   # largest crank-angle error against the reduced solution over 3.5 s
    "generalized-alpha": 1e-2,      # measured 2.5e-3 (N = 1), 2.6e-3 (N = 2) rad
    "dopri5": 5e-4,                 # 3.2e-5, 3.0e-5
    "baumgarte-rk4": 1e-6,          # 4.3e-9, 4.4e-9 (h = 1e-3)
    "partitioned": 1e-3,            # 5.1e-5, 5.1e-5
}


@pytest.mark.parametrize("method", list(PASSAGE_METHODS))
@pytest.mark.parametrize("n", [1, 2])
def test_nfourbar_singular_passage_keeps_the_parallelogram_branch(n: int, method: str) -> None:
    """The free N-four-bar falls through its flat (singular) position four times in 3.5 s.
    Every method, at its default settings, stays on the parallelogram branch (all cranks
    parallel to round-off) and follows the reduced one-degree-of-freedom solution to its own
    accuracy; no error is raised."""
    out = nfourbar_passage(n, method)
    assert out["error"] is None
    assert out["t_reached"] == PASSAGE_T_END
    assert out["max_branch"] < 1e-8                               # measured <= 2e-9 rad
    assert out["max_deviation"] < PASSAGE_DEVIATION[method]
    assert out["energy_error"] < 1e-3 * out["res"].energy[0]       # of 20.5 J (N=1), 35.8 J
    # the passages are where the work is: the deviation is still small before the first one
    before = out["res"].t < PASSAGE_TIMES[0] - 0.05
    assert out["deviation"][before].max() <= out["max_deviation"]


def test_nfourbar_unstabilized_baumgarte_leaves_the_branch_at_the_passages() -> None:
    """Without Baumgarte stabilization (alpha = beta = 0) the constraint drift is not
    corrected, and at every flat passage, where J loses rank, part of it turns into a
    spread of the crank angles: for N = 5 the spread grows about 100x per passage until the
    engine stops the run as unstable after the fourth (h = 1e-2: the constraint violation
    passed 1e-3 of the model size). With the default alpha = beta = 10 the cranks stay
    parallel to 1e-7. (The growth starts from round-off, so how far past the fourth
    passage the run gets depends on its last digits: the run is given until 5 s.)"""
    on = nfourbar_passage(5, "baumgarte-rk4", {"h": 1e-2})
    assert on["error"] is None and on["max_branch"] < 1e-7         # measured 1.2e-9
    off = nfourbar_passage(5, "baumgarte-rk4", {"h": 1e-2, "alpha": 0.0, "beta": 0.0},
                           t_end=5.0, steps=500)
    assert isinstance(off["error"], mbd2d.IntegrationError)
    assert PASSAGE_TIMES[3] < off["t_reached"] < 5.0                # measured 3.22 s
    t, br = off["res"].t, off["branch"]
    spread = [br[(t > a + 0.05) & (t < b - 0.05)].max()
              for a, b in zip(PASSAGE_TIMES, PASSAGE_TIMES[1:] + (off["t_reached"] + 0.05,))]
    # after passages 1, 2, 3: measured 7e-13, 6e-11, 6e-5 (in units of the model's length
    # scale since issue 9: 1.6e-13, 1.2e-11, 1.3e-5); then stopped as unstable
    assert "unstable" in str(off["error"])
    assert br[t < PASSAGE_TIMES[0] - 0.05].max() < 1e-14
    assert all(b > 10 * a for a, b in zip(spread[:3], spread[1:3]))
    assert spread[2] > 1e-6


# ----------------------------------------------------------------------------- energy, drift
def observed_order(e_coarse: float, e_fine: float, ratio: float) -> float:
    """log(e_coarse / e_fine) / log(ratio)."""
    return math.log(e_coarse / e_fine) / math.log(ratio)


def test_energy_is_conserved_to_each_methods_order() -> None:
    """No damping or forcing: E(t) - E(0) is the integration error. It falls at the order of
    each fixed-step method (2 for generalized-alpha, 4 for RK4) and with the tolerance for
    the adaptive ones."""
    m = free_fourbar()
    t_end = 5.0
    ga = [energy_error(m.dynamics(t_end, 500, method="generalized-alpha", h=h)).max()
          for h in (1e-2, 2e-3)]
    assert 1.8 < observed_order(ga[0], ga[1], 5.0) < 2.2          # measured 2.00
    rk = [energy_error(m.dynamics(t_end, 500, method="baumgarte-rk4", h=h)).max()
          for h in (1e-2, 2e-3)]
    assert 3.5 < observed_order(rk[0], rk[1], 5.0) < 4.7          # measured 4.1
    for method in ("dopri5", "partitioned"):
        coarse = energy_error(m.dynamics(t_end, 500, method=method)).max()
        fine = energy_error(m.dynamics(t_end, 500, method=method, rtol=1e-9,
                                       atol=1e-11)).max()
        assert coarse < 2e-3 * abs(m.dynamics(t_end, 5, method=method).energy[0])
        assert fine < coarse / 100                                # measured 1219x, 2324x
    # generalized-alpha's own error control at the default tolerance
    gad = energy_error(m.dynamics(t_end, 500, method="generalized-alpha")).max()
    assert gad < 0.02                                             # measured 1.0e-2 J of 72 J


def test_constraint_drift_per_method() -> None:
    """What each method enforces, measured on the free four-bar over 10 s with outputs every
    0.01 s:

    * generalized-alpha (index 3) solves Phi = 0 at every step: position drift at the step
      times is round-off, but J q_dot = nu is not imposed; the velocity drift falls like h^2;
    * dopri5 projects q and q_dot after every step: both residuals are round-off at a step
      (the last output is one); in between, the quintic dense output leaves ~1e-7;
    * partitioned solves the dependent coordinates at every stage: the same;
    * baumgarte-rk4 imposes neither exactly; both residuals are small and nonzero."""
    m = free_fourbar()
    t_end, steps = 10.0, 1000
    ga = {h: m.dynamics(t_end, steps, method="generalized-alpha", h=h) for h in (1e-2, 1e-3)}
    for r in ga.values():
        assert r.drift_position.max() < 1e-12                    # outputs on step times
    dv = [ga[h].drift_velocity.max() for h in (1e-2, 1e-3)]
    assert dv[0] > 1e-4                                           # measured 1.7e-3
    assert 1.8 < observed_order(dv[0], dv[1], 10.0) < 2.2          # measured 2.0

    for method in ("dopri5", "partitioned"):
        r = m.dynamics(t_end, steps, method=method)
        assert r.drift_position[-1] < 1e-12 and r.drift_velocity[-1] < 1e-12
        assert r.drift_position.max() < 1e-5                      # measured 7e-8, 6e-7
        assert r.drift_velocity.max() < 1e-3                      # measured 8e-6, 4e-5

    rk = m.dynamics(t_end, steps, method="baumgarte-rk4", h=1e-3)
    assert 1e-14 < rk.drift_position.max() < 1e-9                 # measured 3.1e-11
    assert 1e-13 < rk.drift_velocity.max() < 1e-8                 # measured 2.4e-10


# ----------------------------------------------------------------------------- step count
@pytest.mark.parametrize("method", ["generalized-alpha", "baumgarte-rk4"])
def test_fixed_step_runs_take_exactly_the_steps_asked_for(method: str) -> None:
    """A fixed step h over t_end takes t_end / h steps of size h (when that is a whole
    number). Engine bug (reported): the loop adds h to t, the sum falls short of t_end by a
    few 1e-13 and a sliver step of ~2e-13 s follows, so stats report 3001 steps and
    h_min = 2.2e-13 for t_end = 3, h = 1e-3."""
    res = free_fourbar().dynamics(3.0, 30, method=method, h=1e-3)
    assert res.stats["steps"] == 3000
    assert res.stats["h_min"] == pytest.approx(1e-3, rel=1e-9)
