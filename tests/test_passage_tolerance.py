"""A failure mode found by the benchmarks: dopri5 at tight tolerances across the N-four-bar's
singular passage. Near the passage J loses rank, the projected index-1 solution carries
errors of order cond(J) * eps (through the Schur complement cond(J)^2 eps), and dopri5's
error estimate reads them as truncation error: its steps and its accuracy then depend
erratically on the last digit of atol, and a step can underflow at a passage. That is what
the band path (Schur complement, band LU) still does. The dense path's sparse LU of the
saddle matrix, replayed in one pivot order, has rounding errors that vary smoothly with q:
the error estimate does not see them and every run is accurate. The partitioned method
(independent coordinate away from the singular direction) stays accurate for the same
settings. Oracle: the reduced one-degree-of-freedom solution of the parallelogram branch."""
from __future__ import annotations

import math
import subprocess
import warnings

import numpy as np
import pytest

import mbd2d
from test_failure_modes import free_nfourbar, reduced_nfourbar

T_END, STEPS = 10.0, 100
ATOLS = (1.0e-14, 0.9e-14, 1.1e-14)     # the same tolerance up to its last digit


@pytest.fixture(scope="module")
def reference() -> np.ndarray:
    return reduced_nfourbar(1, np.linspace(0.0, T_END, STEPS + 1), substeps=200)


def crank_error(res: mbd2d.DynamicsResult, ref: np.ndarray) -> float:
    th = np.array([res.body(f"crank{k}").theta for k in range(2)])
    return float(np.abs(th - ref[: th.shape[1], 0]).max())


ATOL_SWEEP = np.linspace(0.6e-14, 1.6e-14, 11)


def test_dopri5_at_rtol_1e12_underflows_at_a_singular_passage_for_some_atol(reference):
    """Band path, rtol 1e-12 and eleven atol from 0.6e-14 to 1.6e-14: some runs end in a
    step-size underflow at a passage (5 of 11 measured; 3 of 11 on the dense path when it
    went through the Schur complement, 7 of 11 with the saddle-point LU before), the others
    are accurate."""
    model = free_nfourbar(1)
    failures = []
    for atol in ATOL_SWEEP:
        try:
            res = model.dynamics(t_end=T_END, steps=STEPS, method="dopri5", rtol=1e-12,
                                 atol=atol, solver="banded")
            assert crank_error(res, reference) < 1e-6
        except mbd2d.IntegrationError as exc:
            assert "step size underflow" in str(exc)
            failures.append(exc.t)
    assert failures, "expected at least one of these settings to fail (documented behaviour)"
    for tf in failures:
        # at a passage: the cranks horizontal on the reduced solution, sin(theta) ~ 0
        th = reduced_nfourbar(1, np.array([0.0, tf]), substeps=4000)[-1, 0]
        assert abs(math.sin(th)) < 0.05, f"underflow at t = {tf}, theta = {th}"


def test_dopri5_on_the_dense_path_passes_for_every_atol(reference):
    """The same eleven settings on the dense path (the sparse LU of the saddle matrix): every
    run passes, accurate to 1e-9 (measured 5.6e-11 to 6.4e-11), with 4 to 39 rejected steps
    of about 2900 and no step below 3.7e-8 s (the band path: up to 351 rejected, steps down
    to 3e-14 s)."""
    model = free_nfourbar(1)
    for atol in ATOL_SWEEP:
        res = model.dynamics(t_end=T_END, steps=STEPS, method="dopri5", rtol=1e-12, atol=atol)
        assert res.stats["solver"] == "dense" and res.stats["schur"][0] == 0
        assert crank_error(res, reference) < 1e-9
        assert res.stats["rejected_steps"] <= 50 and res.stats["h_min"] > 1e-8


def test_partitioned_stays_accurate_for_the_same_tolerances(reference):
    model = free_nfourbar(1)
    for atol in ATOLS:
        res = model.dynamics(t_end=T_END, steps=STEPS, method="partitioned", rtol=1e-11,
                             atol=10 * atol)
        assert crank_error(res, reference) < 2e-7


def perturbed(model: mbd2d.Model, k: int) -> mbd2d.Model:
    """The same mechanism with its pivots' x moved by k + 1 units in the last place."""
    pars = model.parameters()
    names = [n for n in pars if n.startswith("joint.") and n.endswith(".0")][:4]
    return model.with_params({n: pars[n] * (1 + (k + 1) * 2.2e-16) if pars[n]
                              else (k + 1) * 1e-16 for n in names})


def test_partitioned_near_the_passage_is_accurate_or_says_so(reference):
    """The same tight settings on the parallelogram moved by a few units in the last place:
    some runs crawl up to the singular configuration (h_min ~ 1e-12), accept a step there
    (J_u's reciprocal condition ~ 1e-7, accelerations off by eps cond**2 ~ 1e-2) and lose
    energy (a conservative system; the error against the reduced solution reaches 0.1 rad).
    Every such run warns (SingularPassageWarning); the accurate ones do not; at rtol 1e-8 the
    steps pass over the point, every run is accurate and none warns."""
    model = free_nfourbar(1)
    inaccurate = 0
    for k in range(6):
        mk = perturbed(model, k)
        for atol in (1.0e-13, 1.1e-13):
            with warnings.catch_warnings(record=True) as got:
                warnings.simplefilter("always")
                res = mk.dynamics(t_end=T_END, steps=STEPS, method="partitioned", rtol=1e-11,
                                  atol=atol)
            warned = any(issubclass(w.category, mbd2d.SingularPassageWarning) for w in got)
            e = res.kinetic + res.potential
            err = crank_error(res, reference)
            bad = err > 1e-5 or float(np.ptp(e)) > 1e-6
            inaccurate += bad
            assert warned == bad, f"k = {k}, atol = {atol}: error {err:.1e}, warned {warned}"
        with warnings.catch_warnings():
            warnings.simplefilter("error", mbd2d.SingularPassageWarning)
            res = mk.dynamics(t_end=T_END, steps=STEPS, method="partitioned", rtol=1e-8,
                              atol=1e-10)
        assert crank_error(res, reference) < 1e-4
    assert inaccurate > 0, "expected some of these runs to land next to the passage"


@pytest.mark.parametrize("n", [3, 4, 6])
@pytest.mark.parametrize("solver", ["dense", "banded"])
def test_dopri5_passes_the_longer_chains_at_every_tight_tolerance(n, solver):
    """N = 3, 4, 6 over 1 s through the first passage, rtol 1e-9 to 1e-12: the crank angle
    against the reduced equation J th'' = -c g cos(th) (J = (N+1)/3 + N, c = (N+1)/2 + N;
    scipy DOP853 at 1e-13), error within 10 rtol and falling with it (measured 0.9 to 5.0
    rtol), the cranks parallel to 1e-10, at most 200 rejected steps. Before, the dense
    path's nearly singular index-1 solves took dgelsy, whose dropped directions jump where
    the condition estimate crosses its threshold: N = 3 at rtol 1e-10 took 17,974 rejected
    steps (15 s), N = 4 at 1e-11 10,243, and N = 6 at 1e-12 ran out of 200,000 steps; now
    they are regularized and refined (mbd_saddle), at most 87 rejected steps."""
    from scipy.integrate import solve_ivp
    g = 9.81
    c, inertia = (n + 1) / 2 + n, (n + 1) / 3 + n
    ref = solve_ivp(lambda t, y: [y[1], -c * g * math.cos(y[0]) / inertia], [0.0, 1.0],
                    [math.pi / 2, 1.0], method="DOP853", rtol=1e-13, atol=1e-14,
                    dense_output=True)
    model = free_nfourbar(n, omega0=1.0)       # over upright, flat at t = 0.72 s
    errs = []
    for rtol in (1e-9, 1e-10, 1e-11, 1e-12):
        res = model.dynamics(1.0, 20, method="dopri5", rtol=rtol, atol=rtol * 1e-2,
                             solver=solver)
        th = np.array([res.body(f"crank{k}").theta for k in range(n + 1)])
        errs.append(np.abs(th[0] - ref.sol(res.t)[0]).max())
        assert errs[-1] < 10 * rtol
        assert np.abs(th - th[0]).max() < 1e-10
        assert res.stats["rejected_steps"] <= 200
    assert errs[0] > 30 * errs[-1]


def test_mbd2d_solve_says_it_for_the_same_runs(tmp_path):
    """mbd2d-solve on the same perturbed runs says the partitioned warning exactly when the
    Python path gives it (one run of each kind compared; the CSVs are equal)."""
    from test_standalone import find_solver
    solver = find_solver()
    model = free_nfourbar(1)
    seen = set()
    for k in range(6):
        mk = perturbed(model, k)
        for atol in (1.0e-13, 1.1e-13):
            with warnings.catch_warnings(record=True) as got:
                warnings.simplefilter("always")
                mk.dynamics(t_end=T_END, steps=STEPS, method="partitioned", rtol=1e-11,
                            atol=atol)
            warned = any(issubclass(w.category, mbd2d.SingularPassageWarning) for w in got)
            if warned in seen:
                continue
            seen.add(warned)
            mbd = tmp_path / f"run{k}.mbd"
            mk.export(mbd, analysis="dynamics", t_end=T_END, steps=STEPS, method="partitioned",
                      rtol=1e-11, atol=atol)
            run = subprocess.run([solver, str(mbd), str(tmp_path / "out.csv")],
                                 capture_output=True, text=True, timeout=300)
            assert run.returncode == 0, run.stderr
            assert ("partitioned: a step at t =" in run.stderr) == warned, run.stderr
        if len(seen) == 2:
            break
    assert seen == {True, False}
