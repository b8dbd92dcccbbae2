"""The band path of dynamics, inverse dynamics and statics (issue 11, item 1).

Every saddle-point solve of these analyses (generalized-alpha's iteration matrix, the
index-1 systems of dopri5 and baumgarte-rk4, the projections, the consistent start, the
multipliers, statics' Newton steps, the partitioned method's J_u) runs in band storage
after an ordering that interleaves each body's coordinates with the rows of its
constraints (mbd_saddle), with no n x n array.

* the band path gives the dense results (solver="banded" against solver="dense") to 1e-10
  at N <= 50 for every method, inverse dynamics and statics; generalized-alpha's own
  velocities and accelerations amplify rounding by g' = gamma/(beta h) and
  b' = 1/(beta' h^2), and there the band path stays within the spread the dense path
  itself shows when v0 changes by one unit in the last place;
* the index-1 systems of dopri5 and baumgarte-rk4 go through the Schur complement
  J M^-1 J^T (mbd_schur) on the band path and on a dense one larger than the sparse LU's
  64 rows (a smaller dense saddle matrix takes the sparse LU; the partitioned method keeps
  the saddle-point LU): every factorization of a chain does, a massless body and the
  neighbourhood of a singular configuration fall back to the saddle-point LU,
  and at N = 3000, where S's condition has grown like N^2, the refined solves keep the
  reduced solution and the energy to dopri5's tolerance;
* independent oracles: the reduced one-degree-of-freedom parallelogram solution (scipy
  DOP853) for dynamics on the band path at N = 300, with generalized-alpha's errors falling
  at its order 2; the driver torque of the driven chain from the energy balance
  (tau = ((N + 1)/2 + N) m g L cos theta); the equilibrium of a sprung chain from a
  bisection on its reduced potential.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from nfourbar import build  # noqa: E402

G = 9.81
METHODS = {"generalized-alpha": {"h": 5e-3}, "dopri5": {"rtol": 1e-8, "atol": 1e-10},
           "baumgarte-rk4": {"h": 5e-3}, "partitioned": {"rtol": 1e-8, "atol": 1e-10}}
T_END, STEPS = 0.05, 10


def loaded(n: int) -> mbd2d.Model:
    """The free N-four-bar with force elements that couple bodies and damp: a rotational
    spring-damper between each crank and its coupler and a translational spring-damper from
    ground to each crank tip (K and C then have off-diagonal blocks of their own)."""
    m = build(n, driven=False, omega0=-1.0)
    for k in range(n):
        m.add_rotational_spring([f"crank{k}", f"coupler{k}"], stiffness=5.0, damping=0.5,
                                angle0=-math.pi / 2)
        m.add_spring(["ground", f"crank{k}"], [[k + 0.5, 2.0], [0.5, 0.0]], stiffness=20.0,
                     damping=0.3, length0=0.8)
    return m


def rel(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| relative to the size of a (at least 1)."""
    return float(np.abs(a - b).max() / max(1.0, np.abs(a).max()))


def run(model: mbd2d.Model, method: str, solver: str) -> mbd2d.DynamicsResult:
    return model.dynamics(T_END, STEPS, method=method, solver=solver, **METHODS[method])


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("case", ["chain-3", "chain-8", "chain-40", "loaded-12"])
def test_band_path_gives_the_dense_results(case: str, method: str) -> None:
    kind, n = case.split("-")
    model = (build(int(n), driven=False, omega0=-1.0) if kind == "chain" else loaded(int(n)))
    dense, band = run(model, method, "dense"), run(model, method, "banded")
    assert dense.stats["solver"] == "dense" and band.stats["solver"] == "banded"
    assert band.stats["steps"] == dense.stats["steps"]
    assert band.stats["partitions"] == dense.stats["partitions"]
    for name in ("q", "lam", "energy"):
        assert rel(getattr(dense, name), getattr(band, name)) < 1e-10, name
    if method in ("dopri5", "baumgarte-rk4"):        # every index-1 system through S
        assert band.stats["schur"][0] == band.stats["schur"][1] > 0
        nt = dense.q.shape[1] + dense.lam.shape[1]    # the saddle matrix's order
        if nt > 64:
            assert dense.stats["schur"][0] == dense.stats["schur"][1] > 0
        else:                                         # chain-3 (41): the sparse LU
            assert dense.stats["schur"][0] == 0 < dense.stats["schur"][1]
    if method == "partitioned":                      # the saddle-point LU throughout
        assert dense.stats["schur"][0] == band.stats["schur"][0] == 0
    if method == "generalized-alpha" and kind == "chain":
        # pins under gravity, K diagonal: on the band path every iteration matrix through
        # S (the dense path keeps its sparse LU; the results above agree to 1e-10)
        assert band.stats["schur"][0] == band.stats["schur"][1] >= band.stats["factorizations"]
    if method != "generalized-alpha":
        assert rel(dense.qd, band.qd) < 1e-10 and rel(dense.qdd, band.qdd) < 1e-10
        return
    # generalized-alpha: q_dot and q_ddot carry the rounding of q times g' and b'; the
    # band path agrees with the dense one as closely as the dense path agrees with itself
    # when v0 changes by one unit in the last place
    nudged = build(int(n), driven=False, omega0=-1.0 * (1 + 2.3e-16)) if kind == "chain" \
        else None
    if nudged is None:
        nudged = loaded(int(n))
        for b in nudged.bodies:
            if b.v0 is not None:
                b.v0 = [v * (1 + 2.3e-16) for v in b.v0]
    spread = run(nudged, method, "dense")
    for name in ("qd", "qdd"):
        d, b, s = getattr(dense, name), getattr(band, name), getattr(spread, name)
        assert rel(d, b) <= max(10 * rel(d, s), 1e-10), (name, rel(d, b), rel(d, s))


def test_auto_picks_the_band_for_a_large_chain_and_dense_for_a_small_one() -> None:
    small = build(3, driven=False, omega0=-1.0).dynamics(0.01, 1)
    large = build(12, driven=False, omega0=-1.0).dynamics(0.01, 1)
    assert small.stats["solver"] == "dense"
    assert large.stats["solver"] == "banded"
    kl, ku = large.stats["band"]
    assert 0 < kl <= 12 and 0 < ku <= 12            # interleaved order: measured 6, 6


def reduced(n: int, t: np.ndarray, th0: float = math.pi / 2, w0: float = -1.0) -> np.ndarray:
    """Crank angle of the parallelogram branch: ((N+1)/3 + N) th'' = -((N+1)/2 + N) g cos th
    (m = L = 1), scipy DOP853 at rtol = atol = 1e-12."""
    inertia, load = (n + 1) / 3.0 + n, ((n + 1) / 2.0 + n) * G
    sol = solve_ivp(lambda _, y: [y[1], -load * math.cos(y[0]) / inertia], (t[0], t[-1]),
                    [th0, w0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t)
    return sol.y[0]


def test_band_path_follows_the_reduced_solution_at_n_300() -> None:
    """N = 300 (1803 coordinates, auto: the band path) against the reduced solution, 0.4 s:
    generalized-alpha's crank error falls 4x when h halves (order 2), dopri5 within 1e-8."""
    n, t_end = 300, 0.4
    model = build(n, driven=False, omega0=-1.0)
    t = np.linspace(0.0, t_end, 21)
    ref = reduced(n, t)
    errs = []
    for h in (4e-3, 2e-3):
        res = model.dynamics(t_end, 20, method="generalized-alpha", h=h)
        assert res.stats["solver"] == "banded"
        assert res.stats["schur"][0] == res.stats["schur"][1] >= res.stats["factorizations"]
        th = res.q[:, 2::3][:, :n + 1]
        assert np.abs(th - th[:, :1]).max() < 1e-10          # the parallelogram branch
        errs.append(np.abs(th[:, 0] - ref).max())
    assert errs[1] < 1e-5                                   # measured 1.9e-6 at h = 2 ms
    assert 3.0 < errs[0] / errs[1] < 5.0                    # order 2: measured 4.00
    res = model.dynamics(t_end, 20, method="dopri5", rtol=1e-9, atol=1e-11)
    assert res.stats["solver"] == "banded"
    assert np.abs(res.q[:, 2] - ref).max() < 1e-8           # measured 1.0e-9


@pytest.mark.parametrize("n", [3, 20])
def test_inverse_dynamics_band_path_against_dense_and_the_energy_balance(n: int) -> None:
    """Driven chain (crank 0 at theta = pi/2 - t, 1 kg bars): every speed is constant, so the
    driver's power is the rate of the potential: tau = ((N + 1)/2 + N) g cos theta."""
    model = build(n, omega0=-1.0)
    dense = model.inverse_dynamics(t_end=1.0, steps=10, solver="dense")
    band = model.inverse_dynamics(t_end=1.0, steps=10, solver="banded")
    assert dense.stats["multiplier_solver"] == "dense"
    assert band.stats["multiplier_solver"] == "banded"
    assert rel(dense.lam, band.lam) < 1e-10
    tau = ((n + 1) / 2 + n) * G * np.cos(band.body("crank0").theta)
    assert np.abs(band.effort("motor") - tau).max() < 1e-9 * np.abs(tau).max()


@pytest.mark.parametrize("n", [20, 300, 1500])
def test_inverse_dynamics_sensitivities_on_the_band_path(n: int) -> None:
    """The driven chain's motor torque tau = (sum of crank masses / 2 + coupler masses) g cos
    theta (every speed constant): its sensitivities to gravity, a crank's and a coupler's
    mass and an inertia (zero: no body accelerates its rotation) in closed form, on the
    band path (the saddle-point factors of each output's multipliers; the sensitivities took
    the dense path before, 398 s at N = 1000 against 0.13 s now) and equal to the dense
    path's at N = 20. Measured 3.3e-15 (N = 20) and 9.9e-13 (N = 300) of the largest;
    band against dense 1.7e-15. The torque itself too: from N = 1100 on (6603 coordinates)
    the multipliers' band solve took the index-1 check's regularized least squares, 98% off
    (now an exact factorization of the regular matrix: 2.5e-13 at N = 1500, its
    sensitivities 2.8e-13)."""
    model = build(n, omega0=-1.0)
    names = ["model.gravity.1", "body.crank3.mass", "body.coupler2.mass",
             "body.coupler1.inertia"]
    band = model.inverse_dynamics(t_end=1.0, steps=10, solver="banded", sensitivities=names)
    assert band.stats["multiplier_solver"] == "banded"
    cos = np.cos(band.body("crank0").theta)
    c = (n + 1) / 2 + n
    want = np.stack([-c * cos, 0.5 * G * cos, G * cos, 0.0 * cos], -1)
    got = band.effort_dp("motor")
    assert np.abs(got - want).max() < 1e-9 * np.abs(want).max()
    tau = c * G * cos
    assert np.abs(band.effort("motor") - tau).max() < 1e-9 * np.abs(tau).max()
    if n <= 50:
        dense = model.inverse_dynamics(t_end=1.0, steps=10, solver="dense", sensitivities=names)
        assert dense.stats["multiplier_solver"] == "dense"
        assert rel(dense.dlam_dp, band.dlam_dp) < 1e-10


def sprung(n: int, k: float, a0: float) -> mbd2d.Model:
    """The N-four-bar (1 kg bars) with a torsion spring k from ground on crank 0 (rest angle
    a0), no driver: one free motion, potential V = c g sin th + k (th - a0)^2 / 2."""
    m = build(n, driven=False, omega0=0.0)
    m.add_rotational_spring(["ground", "crank0"], stiffness=k, angle0=a0)
    return m


def equilibrium(n: int, k: float, a0: float) -> float:
    """The root of V'(th) = c g cos th + k (th - a0) in (0, pi/2) by bisection."""
    c = (n + 1) / 2 + n
    lo, hi = 0.0, math.pi / 2
    f = lambda th: c * G * math.cos(th) + k * (th - a0)    # noqa: E731
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(lo) * f(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("n", [3, 30])
def test_statics_band_path_against_dense_and_the_reduced_potential(n: int) -> None:
    k, a0 = 40.0 * (n + 1), 1.2
    model = sprung(n, k, a0)
    dense, band = model.statics(solver="dense"), model.statics(solver="banded")
    assert dense.stats["solver"] == "dense" and band.stats["solver"] == "banded"
    assert dense.stability == band.stability == "stable"
    th = equilibrium(n, k, a0)
    for res in (dense, band):
        cranks = res.q[2::3][:n + 1]
        assert np.abs(cranks - th).max() < 1e-10
    assert rel(dense.q, band.q) < 1e-10
    assert rel(dense.lam, band.lam) < 1e-10


@pytest.mark.parametrize("n", [3, 30, 300])
def test_statics_sensitivities_on_the_band_path(n: int) -> None:
    """The sprung chain's equilibrium F(th; p) = c g cos th + k (th - a0) = 0 (c = sum of crank
    masses / 2 + coupler masses): d th / dp = -F_p / F_th for the spring's stiffness and rest
    angle, gravity, a crank's and a coupler's mass, by the null-space form on the band path
    (the sensitivities forced a dense path before: 33.8 s at N = 200 against 0.04 s now), and
    equal to the dense path's. Measured 7.6e-18, 8.2e-17, 8.4e-15 (N = 3, 30, 300) of the
    largest against the closed form; band against dense 1.5e-14 (N = 30)."""
    k, a0 = 40.0 * (n + 1), 1.2
    model = sprung(n, k, a0)
    spring = [p for p in model.parameters() if p.startswith("force.")]
    names = [f"{spring[0].rsplit('.', 1)[0]}.stiffness", f"{spring[0].rsplit('.', 1)[0]}.angle0",
             "model.gravity.1", "body.crank2.mass", "body.coupler1.mass"]
    band = model.statics(solver="banded", sensitivities=names)
    assert band.stats["solver"] == "banded"
    th = equilibrium(n, k, a0)
    c = (n + 1) / 2 + n
    f_th = -c * G * math.sin(th) + k
    f_p = [th - a0, -k, -c * math.cos(th), 0.5 * G * math.cos(th), G * math.cos(th)]
    want = np.array([-fp / f_th for fp in f_p])
    got = band.dq_dp[2]                                # crank0's theta
    assert np.abs(got - want).max() < 1e-12 * np.abs(want).max(), (got, want)
    if n <= 50:
        dense = model.statics(solver="dense", sensitivities=names)
        assert dense.stats["solver"] == "dense"
        assert rel(dense.dq_dp, band.dq_dp) < 1e-11
        assert rel(dense.dlam_dp, band.dlam_dp) < 1e-11


def test_unknown_solver_is_a_model_error() -> None:
    model = build(2, driven=False, omega0=-1.0)
    with pytest.raises(mbd2d.ModelError, match="unknown solver 'sparse'"):
        model.dynamics(0.1, 2, solver="sparse")
    with pytest.raises(mbd2d.ModelError, match="unknown solver"):
        model.statics(solver=2)


def test_schur_path_falls_back_for_a_massless_body() -> None:
    """A massless coupler: M has zero entries and S = J M^-1 J^T does not exist; those
    index-1 systems take the saddle-point LU (the velocity projection, metric 1, still takes
    S) and the run gives the dense results."""
    m = build(12, driven=False, omega0=-1.0)
    for b in m.bodies:
        if b.name == "coupler5":
            b.mass, b.inertia = 0.0, 0.0
    for method, kw in (("dopri5", {"rtol": 1e-8, "atol": 1e-10}), ("baumgarte-rk4", {"h": 5e-3})):
        dense = m.dynamics(0.3, 10, method=method, solver="dense", **kw)
        band = m.dynamics(0.3, 10, method=method, solver="banded", **kw)
        schur, total = band.stats["schur"]
        assert 0 < schur < total                     # measured 23 of 147 (dopri5)
        for name in ("q", "qd", "qdd", "lam"):
            assert rel(getattr(dense, name), getattr(band, name)) < 1e-10, name


def test_schur_path_at_n_3000_keeps_the_reduced_solution_and_the_energy() -> None:
    """N = 3000 (18,003 coordinates): cond(S) grows like N^2 along the chain, and the solves
    refined once against the constraint equations keep dopri5 at rtol 1e-10 on the reduced
    solution and the conservative chain's energy."""
    n, t_end = 3000, 0.3
    t = np.linspace(0.0, t_end, 11)
    res = build(n, driven=False, omega0=-1.0).dynamics(t_end, 10, method="dopri5", rtol=1e-10,
                                                         atol=1e-12)
    assert res.stats["solver"] == "banded"
    assert res.stats["schur"][0] == res.stats["schur"][1] > 0
    th = res.q[:, 2::3][:, :n + 1]
    assert np.abs(th - th[:, :1]).max() < 1e-10
    assert np.abs(th[:, 0] - reduced(n, t)).max() < 1e-9
    e = res.energy                                   # kinetic + potential
    assert np.abs(e - e[0]).max() < 1e-9 * max(1.0, abs(e[0]))


def test_schur_path_falls_back_next_to_the_singular_passage() -> None:
    """dopri5 at rtol 1e-10 through the N = 2 chain's flat position: the steps next to it
    take the saddle-point LU (S's pivot ratio below 1e-8 there) and the run follows the
    reduced solution as the dense path does (1.4e-10 both)."""
    n, t_end = 2, 1.5
    t = np.linspace(0.0, t_end, 151)
    ref = reduced(n, t)
    res = build(n, driven=False, omega0=-1.0).dynamics(t_end, 150, method="dopri5",
                                                       solver="banded", rtol=1e-10, atol=1e-12)
    schur, total = res.stats["schur"]
    assert 0 < schur < total
    assert np.abs(res.q[:, 2] - ref).max() < 1e-9


def test_band_path_through_the_singular_passages() -> None:
    """The free N-four-bar (N = 2) falls through its flat, singular position; on the band
    path the nearly singular index-1 systems are solved with the constraint block
    regularized and refined (the dense path: dgelsy). Both stay on the parallelogram branch
    and follow the reduced solution to the method's accuracy over the first two passages."""
    n, t_end = 2, 1.5
    model = build(n, driven=False, omega0=-1.0)
    t = np.linspace(0.0, t_end, 151)
    ref = reduced(n, t)
    for method, settings, bound in (("dopri5", {}, 5e-4), ("generalized-alpha", {}, 1e-2)):
        res = model.dynamics(t_end, 150, method=method, solver="banded", **settings)
        th = res.q[:, 2::3][:, :n + 1]
        assert np.abs(th - th[:, :1]).max() < 1e-8
        assert np.abs(th[:, 0] - ref).max() < bound


@pytest.mark.parametrize("method, kw", [("dopri5", {"rtol": 1e-8, "atol": 1e-10}),
                                        ("generalized-alpha", {"h": 1e-3})])
def test_band_path_carries_contacts(method, kw):
    """A free N-four-bar (75 coordinates: the band path by default) whose coupler hits a floor:
    the band run gives the dense run's motion, contact events and contact force."""
    m = build(12, driven=False, omega0=2.0)
    m.add_contact("circle-line", ["coupler5", "ground"],
                  circle={"center": [0.0, 0.0], "radius": 0.1},
                  line={"point": [0.0, 0.3], "normal": [0.0, 1.0]},
                  law={"model": "hunt-crossley", "stiffness": 1e6, "exponent": 1.5,
                       "restitution": 0.8}, name="floor")
    runs = {s: m.dynamics(1.0, 100, method=method, solver=s, **kw)
            for s in ("dense", "banded", "auto")}
    assert runs["auto"].stats["solver"] == "banded"
    d, b = runs["dense"], runs["banded"]
    assert len(d.contacts) == len(b.contacts) >= 1
    assert [e.kind for e in d.contacts] == [e.kind for e in b.contacts]
    np.testing.assert_allclose(b.q, d.q, rtol=0, atol=1e-9)
    fd, fb = d.contact("floor").normal_force, b.contact("floor").normal_force
    np.testing.assert_allclose(fb, fd, rtol=0, atol=1e-9 * max(1.0, float(np.abs(fd).max())))


def reduced_masses(n: int, t: np.ndarray, mk: float) -> np.ndarray:
    """The parallelogram branch with 1 kg cranks and couplers of mass mk (translating):
    ((N + 1)/3 + N mk) th'' = -((N + 1)/2 + N mk) g cos th, scipy DOP853 at 1e-12."""
    inertia, load = (n + 1) / 3.0 + n * mk, ((n + 1) / 2.0 + n * mk) * G
    sol = solve_ivp(lambda _, y: [y[1], -load * math.cos(y[0]) / inertia], (t[0], t[-1]),
                    [math.pi / 2, -1.0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t)
    return sol.y[0]


@pytest.mark.parametrize("n", [3, 12])
@pytest.mark.parametrize("mk", [1e-6, 1e6])
def test_schur_path_with_extreme_mass_ratios(n: int, mk: float) -> None:
    """Couplers 1e-6 and 1e6 times as heavy as the cranks: M^-1 spans twelve decades and
    S = J M^-1 J^T with it. dopri5 (through S on the band path at N = 12, the sparse LU of
    the saddle matrix on the dense path at N = 3) and the partitioned method (saddle-point LU)
    all follow the reduced solution to 1e-9 (measured 3.9e-11 to 9.1e-11 over 0.5 s)."""
    m = build(n, driven=False, omega0=-1.0)
    for b in m.bodies:
        if b.name.startswith("coupler"):
            b.mass, b.inertia = mk, mk / 12
    t = np.linspace(0.0, 0.5, 11)
    ref = reduced_masses(n, t, mk)
    for method in ("dopri5", "partitioned"):
        res = m.dynamics(0.5, 10, method=method, rtol=1e-10, atol=1e-12)
        assert res.stats["solver"] == ("dense" if n == 3 else "banded")
        schur, total = res.stats["schur"]
        assert (schur == total > 0) if method == "dopri5" and n == 12 else schur == 0
        assert np.abs(res.q[:, 2] - ref).max() < 1e-9


def test_dopri5_sensitivities_on_the_band_path():
    """Sensitivities of a 123-coordinate chain (N = 20) by dopri5 on the band path (the
    Schur complement for the variational solves and the projections, no dense J): equal to
    the dense path's own, and against Richardson-extrapolated central differences of dense
    analysis runs at rtol 1e-13 (no sensitivity code; steps h and h/2, h = 2e-3 of the
    value). Measured 1.1e-8 (the mass: dq/dp ~ 4e-4, where the differences' own noise,
    ~1e-13 / h, sets the floor) and 1.5e-10 (gravity)."""
    m = build(20, driven=False, omega0=1.0)
    m.bodies[3].mass *= 1.7                          # break the chain's uniformity
    names = ["model.gravity.1", "body.crank3.mass"]
    kw = {"method": "dopri5", "rtol": 1e-11, "atol": 1e-12}
    band = m.dynamics(0.3, 6, solver="banded", sensitivities=names, **kw)
    dense = m.dynamics(0.3, 6, solver="dense", sensitivities=names, **kw)
    assert band.stats["solver"] == "banded" and dense.stats["solver"] == "dense"
    assert rel(dense.dq_dp, band.dq_dp) < 1e-9
    assert rel(dense.dqd_dp, band.dqd_dp) < 1e-9
    base = m.parameters()

    def central(name: str, h: float) -> np.ndarray:
        runs = [m.with_params({name: base[name] + sign * h}).dynamics(
            0.3, 6, solver="dense", method="dopri5", rtol=1e-13, atol=1e-14) for sign in (1, -1)]
        return (runs[0].q - runs[1].q) / (2 * h)

    for j, name in enumerate(names):
        h = 2e-3 * abs(base[name])
        fd = (4 * central(name, h / 2) - central(name, h)) / 3
        err = float(np.abs(band.dq_dp[:, :, j] - fd).max()) / float(np.abs(fd).max())
        print(f"\n[band sensitivities] N = 20 dq/d {name}: relative error {err:.1e}", end="")
        assert err < 5e-8, name


@pytest.mark.parametrize("n", [300, 1500])
def test_fixed_step_generalized_alpha_at_tight_tolerances_on_long_chains(n: int) -> None:
    """rtol = atol = 1e-12 at a fixed step on long chains (band path): the Newton
    corrections stall at the rounding the chain's conditioning allows, above the floor of
    100 eps |q| (1.6x at N = 300, 2.9x at N = 1000, 17x at N = 3000), and the step failed
    ("Newton did not converge ... take a smaller h", which no h helps); now a stall with
    fresh K and C below the step's error tolerance is convergence. The runs equal the
    1e-10 run's result (the same discrete solution; measured 4.9e-14 and 4.6e-13 apart) and keep the
    parallelogram branch (cranks parallel, couplers level)."""
    m = build(n, driven=False, omega0=1.0)
    kw = dict(method="generalized-alpha", h=2e-3)
    tight = m.dynamics(0.02, 2, rtol=1e-12, atol=1e-12, **kw)
    loose = m.dynamics(0.02, 2, rtol=1e-10, atol=1e-10, **kw)
    assert tight.stats["solver"] == "banded"
    diff = float(np.abs(tight.q - loose.q).max())
    print(f"\n[band] generalized-alpha N = {n} rtol 1e-12 against 1e-10: {diff:.1e}", end="")
    assert diff < 1e-10
    th = tight.q[:, 2:3 * (n + 1):3]
    assert np.abs(th - th[:, :1]).max() < 1e-10
    assert np.abs(tight.q[:, 3 * (n + 1) + 1::3] - np.sin(th[:, :1])).max() < 1e-10


@pytest.mark.parametrize("solver", ["dense", "banded"])
def test_fixed_step_generalized_alpha_at_the_tightest_tolerances(solver: str) -> None:
    """rtol = atol = 1e-12 and the tightest accepted (rtol 1e-14, atol 1e-16) at a fixed
    step: Newton's correction test is not below the rounding of q (100 eps |q|). It was, and
    the free N = 20 chain failed at its first step ("Newton did not converge"; found by the
    sensitivity tests). Each run converges to the 1e-10 run's result (measured 1.4e-14
    apart), and against dopri5 at 1e-12 its error falls as h^2 (measured ratios 4.000)."""
    m = build(20, driven=False, omega0=1.0)
    ref = m.dynamics(0.2, 4, method="dopri5", rtol=1e-12, atol=1e-12)
    errs = []
    for h in (4e-3, 2e-3, 1e-3):
        runs = [m.dynamics(0.2, 4, method="generalized-alpha", h=h, rtol=rt, atol=at,
                           solver=solver) for rt, at in ((1e-14, 1e-16), (1e-12, 1e-12),
                                                         (1e-10, 1e-10))]
        for r in runs[:2]:
            assert np.abs(r.q - runs[2].q).max() < 1e-12
        errs.append(float(np.abs(runs[0].q - ref.q).max()))
    for a, b in zip(errs, errs[1:]):
        assert 3.8 < a / b < 4.2, errs
