"""Design sensitivities of generalized-alpha: its discrete equations differentiated
(fortran/mbd_sens_genalpha.f90), against references computed without them.

* Fixed step: the sensitivities are the exact derivatives of generalized-alpha's own
  numerical solution, so central differences of plain runs at the same step
  (Richardson-extrapolated) agree with them to the runs' round-off, for every kind of
  parameter: pins (through Phi_p and the start's assembly), masses, forces, gravity.
* As h -> 0 they converge to the sensitivity of the motion at the method's order, 2: the
  swing's reduced equation and its variational equations integrated by scipy at 1e-13.
* Error control: the sensitivities' local error joins the state's; their error falls with
  the tolerance.
* The band path gives the dense path's sensitivities; sweeps, tolerance analysis and the
  command line carry them.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from conftest import model_from_toml
from test_sensitivities import SWING, add_force_kinds, free_slider_crank, rel_close, \
    swing_reference

EX = Path(__file__).resolve().parents[1] / "examples"
SWING_NAMES = ["force.torsion.stiffness", "force.torsion.damping", "body.bar.mass",
               "body.bar.inertia", "model.gravity.1"]


def ga(h: float | None = None, **kw) -> dict:
    """generalized-alpha's settings: a fixed step h (or error control) with Newton converged
    to its rounding."""
    out = {"method": "generalized-alpha", "rtol": 1e-12, "atol": 1e-12}
    if h is not None:
        out["h"] = h
    out.update(kw)
    return out


def consistent_start(m: mbd2d.Model) -> mbd2d.Model:
    """m with q0 and v0 the assembled and projected ones of a first run: the perturbed runs'
    own assembly then takes the start's minimum-norm change to first order (see
    test_sensitivities.test_dopri5_sensitivities_of_pin_coordinates)."""
    start = m.dynamics(0.1, 1, method="dopri5", rtol=1e-12, atol=1e-12)
    for k, b in enumerate(m.bodies):
        b.q0 = [float(x) for x in start.q[0, 3 * k:3 * k + 3]]
        b.v0 = [float(x) for x in start.qd[0, 3 * k:3 * k + 3]]
    return m


def richardson(m: mbd2d.Model, name: str, run, d: float = 1e-3) -> list[np.ndarray]:
    """d(q, q_dot, q_ddot)/dp from plain runs: central differences at d and 2d (relative to
    max(1, |p|)), Richardson-extrapolated (4 D(d) - D(2d)) / 3."""
    v = m.parameters()[name]
    step = d * max(1.0, abs(v))

    def central(hh: float) -> list[np.ndarray]:
        up, dn = run(m.with_params({name: v + hh})), run(m.with_params({name: v - hh}))
        return [(a - b) / (2 * hh) for a, b in ((up.q, dn.q), (up.qd, dn.qd), (up.qdd, dn.qdd))]

    c1, c2 = central(step), central(2 * step)
    return [(4 * a - b) / 3 for a, b in zip(c1, c2)]


# --------------------------------------------------------------- the discrete solution's own

@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_fixed_step_gives_the_derivatives_of_the_discrete_solution(h: float) -> None:
    """The free slider-crank with a spring, a spring-damper-actuator, a torque and a point
    force, from an exactly consistent start: eleven parameters of every kind (pins, spring,
    mass, inertia, gravity, force points, damping, an actuator's slope). Reference:
    Richardson central differences of plain runs at the same h. Measured dq/dp 1.7e-11 to
    6.9e-10 (h = 1e-2) and 8.0e-11 to 2.7e-9 (h = 1e-3) of each sensitivity's largest
    entry; dq_dot/dp up to 3.2e-8 and 3.0e-7 (where a sensitivity is small, ~3e-3: the
    differences' round-off)."""
    m = consistent_start(add_force_kinds(free_slider_crank()))
    names = ["joint.O.points.0.0", "joint.A.points.0.1", "joint.B.points.1.0",
             "force.s1.stiffness", "body.rod.mass", "body.crank.inertia", "model.gravity.1",
             "force.s2.points.0.0", "force.s2.damping", "force.s2.f.poly.1", "force.p1.point.0"]
    res = m.dynamics(1.0, 10, sensitivities=names, **ga(h))
    assert res.dq_dp.shape == (11, 9, len(names))
    for j, name in enumerate(names):
        ref = richardson(m, name, lambda mm: mm.dynamics(1.0, 10, **ga(h)))
        assert np.abs(ref[0]).max() > 1e-3, name          # each parameter moves the motion
        rel_close(res.dq_dp[:, :, j], ref[0], rtol=1e-7, what=f"GA h={h:g} dq / d {name}")
        rel_close(res.dqd_dp[:, :, j], ref[1], rtol=1e-6, what=f"GA h={h:g} dqd / d {name}")


def test_accelerations_are_those_of_the_discrete_solution() -> None:
    """dq_ddot/dp is the derivative of generalized-alpha's own q_ddot (a second difference
    of positions over beta' h^2): Richardson central differences of the swing's runs at
    d = 1e-3, whose accelerations carry Newton's residual test (1e-11 of the largest term)
    over d. Measured 3.2e-9 to 1.9e-8 over the five parameters."""
    m = model_from_toml(SWING)
    res = m.dynamics(1.0, 10, sensitivities=SWING_NAMES, **ga(1e-2))
    for j, name in enumerate(SWING_NAMES):
        ref = richardson(m, name, lambda mm: mm.dynamics(1.0, 10, **ga(1e-2)), d=1e-3)
        rel_close(res.dqdd_dp[:, :, j], ref[2], rtol=2e-7, what=f"GA swing dqdd / d {name}")


# ------------------------------------------------------------------- the motion's, order 2

def test_fixed_step_converges_at_order_two_to_the_motion() -> None:
    """The swing (rotational spring and damper under gravity): the worst relative error of
    dtheta/dp against the reduced equation's variational solution (scipy DOP853 at 1e-13)
    falls by 4 per halving of h. Measured 1.457e-2, 3.643e-3, 9.107e-4 (ratios 4.00)."""
    m = model_from_toml(SWING)
    errs = []
    for h in (2e-2, 1e-2, 5e-3):
        res = m.dynamics(2.0, 20, sensitivities=SWING_NAMES, **ga(h))
        ref = swing_reference(res.t, SWING_NAMES)
        errs.append(max(float(np.abs(res.dq_dp[:, 2, i] - ref[2 + 2 * i]).max()) /
                        float(np.abs(ref[2 + 2 * i]).max()) for i in range(len(SWING_NAMES))))
        print(f"\n[sensitivity] generalized-alpha swing h {h:.0e}: worst relative error "
              f"{errs[-1]:.3e}", end="")
    for a, b in zip(errs, errs[1:]):
        assert 3.6 < a / b < 4.4, errs


def test_error_control_covers_the_sensitivities() -> None:
    """Error-controlled: the sensitivities' error falls with the tolerance (measured 2.4e-4,
    1.1e-5, 5.1e-7 at rtol = atol = 1e-6, 1e-8, 1e-10: by tol^(2/3), the order-2 method's
    local error control), and the run takes more steps than without them (their error
    joins the state's: 859 against 434 at 1e-6), its angle no less accurate."""
    m = model_from_toml(SWING)
    errs = []
    for tol in (1e-6, 1e-8, 1e-10):
        kw = {"method": "generalized-alpha", "rtol": tol, "atol": tol}
        res = m.dynamics(2.0, 20, sensitivities=SWING_NAMES, **kw)
        plain = m.dynamics(2.0, 20, **kw)
        assert res.stats["steps"] > plain.stats["steps"]
        ref = swing_reference(res.t, SWING_NAMES)
        assert np.abs(res.q[:, 2] - ref[0]).max() <= np.abs(plain.q[:, 2] - ref[0]).max()
        errs.append(max(float(np.abs(res.dq_dp[:, 2, i] - ref[2 + 2 * i]).max()) /
                        float(np.abs(ref[2 + 2 * i]).max()) for i in range(len(SWING_NAMES))))
    assert errs[0] > 10 * errs[1] > 100 * errs[2], errs
    assert errs[2] < 2e-6


# ------------------------------------------------------------------------------ paths

def test_band_path_gives_the_dense_sensitivities() -> None:
    """The free N-four-bar (N = 20, 123 coordinates) on the band path (generalized-alpha's
    iteration matrix through the Schur complement) and the dense path: the same
    sensitivities to 1e-10, and both the derivatives of the discrete solution (Richardson
    differences of dense runs)."""
    sys.path.insert(0, str(EX))
    from nfourbar import build
    m = build(20, driven=False, omega0=1.0)
    m.bodies[3].mass *= 1.7                          # break the chain's uniformity
    names = ["model.gravity.1", "body.crank3.mass"]
    kw = ga(2e-3)
    band = m.dynamics(0.2, 4, solver="banded", sensitivities=names, **kw)
    dense = m.dynamics(0.2, 4, solver="dense", sensitivities=names, **kw)
    assert band.stats["solver"] == "banded" and dense.stats["solver"] == "dense"
    for a, b in ((band.dq_dp, dense.dq_dp), (band.dqd_dp, dense.dqd_dp)):
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max()
    for j, name in enumerate(names):
        ref = richardson(m, name, lambda mm: mm.dynamics(0.2, 4, solver="dense", **kw))
        rel_close(band.dq_dp[:, :, j], ref[0], rtol=1e-7, what=f"GA N=20 dq / d {name}")


def test_stiff_spring_with_a_long_step() -> None:
    """A stiff spring (k = 1e6 on a 1 kg bar, h = 5e-3: K is 1000x the mass term M b'): the
    iteration matrix's K and C, differences some steps old, are far from the exact
    tangent's share; where the refined solve stops contracting the step asks for fresh
    ones (one more iteration matrix than the plain run here), and lands on the discrete
    solution's derivatives (Richardson differences of runs at d = 1e-4 of k and m: the
    motion is strongly nonlinear in k, d = 1e-3 leaves 1e-7 of truncation; at 1e-2 of g,
    whose sensitivity is small and whose differences' round-off falls as 1 / d).
    Measured 8.2e-12 (stiffness), 1.1e-11 (mass), 1.5e-9 (gravity)."""
    m = model_from_toml(SWING.replace("stiffness = 6.0", "stiffness = 1.0e6"))
    names = ["force.torsion.stiffness", "body.bar.mass", "model.gravity.1"]
    kw = ga(5e-3)
    res = m.dynamics(0.5, 10, sensitivities=names, **kw)
    plain = m.dynamics(0.5, 10, **kw)
    assert res.stats["iteration_matrices"] > plain.stats["iteration_matrices"]
    assert np.abs(res.q - plain.q).max() < 1e-12         # (Newton converged either way)
    for j, name in enumerate(names):
        ref = richardson(m, name, lambda mm: mm.dynamics(0.5, 10, **kw),
                         d=1e-2 if name == "model.gravity.1" else 1e-4)
        rel_close(res.dq_dp[:, :, j], ref[0], rtol=1e-7, what=f"GA stiff dq / d {name}")


# ---------------------------------------------------------------------------- front doors

def test_sweep_cases_are_their_single_runs() -> None:
    """A sweep with generalized-alpha and sensitivities: every case is its own single run,
    bit for bit."""
    m = free_slider_crank()
    names = ["body.rod.mass", "joint.A.points.0.1"]
    values = [30.0, 40.0, 50.0]
    kw = dict(method="generalized-alpha", h=2e-3)
    ds = mbd2d.sweep(m, {"force.s1.stiffness": values}, "dynamics", t_end=0.2, steps=4,
                     sensitivities=names, workers=1, **kw)
    for c, v in enumerate(values):
        one = m.with_params({"force.s1.stiffness": v}).dynamics(0.2, 4, sensitivities=names,
                                                                 **kw)
        assert np.array_equal(ds.dq_dp.values[c], one.dq_dp)
        assert np.array_equal(ds.dqdd_dp.values[c], one.dqdd_dp)


def test_tolerance_of_dynamics_by_generalized_alpha() -> None:
    """First-order scatter of the swing's angle from the stiffness's sigma: |dtheta/dk|
    sigma from the reduced equation's variational solution (scipy), to the method's error
    at h = 1e-3 (order 2: ~1e-5 relative), and the Monte Carlo estimate within its own
    error."""
    m = model_from_toml(SWING)
    sigma = 0.05
    tol = mbd2d.tolerance(m, {"force.torsion.stiffness": sigma}, "dynamics", samples=200,
                          workers=1, t_end=1.0, steps=10, method="generalized-alpha", h=1e-3)
    ref = swing_reference(np.linspace(0.0, 1.0, 11), ["force.torsion.stiffness"])
    std = tol.dataset.q_std_linear.sel(coordinate="bar.theta").values
    want = np.abs(ref[2]) * sigma
    assert np.abs(std - want).max() <= 1e-4 * want.max()
    mc = tol.dataset.q_std_mc.sel(coordinate="bar.theta").values
    assert np.abs(mc - std).max() <= 0.2 * std.max()


def test_command_line_writes_the_columns(tmp_path: Path) -> None:
    """`mbd2d dynamics --method generalized-alpha --h H --sensitivities ...` writes the API's
    table."""
    from mbd2d.cli import main
    toml = EX / "pendulum_spring.toml"
    names = ["body.bar.mass", "force.torsion.stiffness"]
    res = mbd2d.load(toml).dynamics(0.5, 10, method="generalized-alpha", h=1e-3,
                                    sensitivities=names)
    out = tmp_path / "cli.csv"
    assert main(["dynamics", str(toml), "--t-end", "0.5", "--steps", "10", "--method",
                 "generalized-alpha", "--h", "1e-3", "--out", str(out), "--sensitivities",
                 ",".join(names)]) == 0
    py = tmp_path / "py.csv"
    res.to_csv(py, sensitivities=True)
    assert out.read_text() == py.read_text()


def test_a_failed_run_keeps_the_rows_and_their_sensitivities() -> None:
    """The step limit reached: the IntegrationError carries the rows up to there with their
    sensitivities (finite)."""
    m = model_from_toml(SWING)
    with pytest.raises(mbd2d.IntegrationError) as info:
        m.dynamics(1.0, 100, method="generalized-alpha", rtol=1e-8, atol=1e-8, max_steps=300,
                   sensitivities=["body.bar.mass"])
    part = info.value.results
    assert 1 < len(part.t) < 101 and part.dq_dp.shape == (len(part.t), 3, 1)
    assert np.isfinite(part.dq_dp).all() and math.isfinite(float(part.dqdd_dp[-1, 2, 0]))


def test_kept_rows_are_those_of_the_full_run() -> None:
    """every = 3 keeps every third output row (and the last) of the same run: the state and
    its sensitivities equal the full run's rows bit for bit, at a fixed step and under error
    control (the rows between steps interpolated alike)."""
    m = free_slider_crank()
    names = ["body.rod.mass", "force.s1.stiffness"]
    for kw in (ga(2e-3), {"method": "generalized-alpha", "rtol": 1e-7, "atol": 1e-9}):
        full = m.dynamics(0.3, 9, sensitivities=names, **kw)
        kept = m.dynamics(0.3, 9, every=3, sensitivities=names, **kw)
        rows = [0, 3, 6, 9]
        assert np.array_equal(kept.q, full.q[rows])
        for a, b in ((kept.dq_dp, full.dq_dp), (kept.dqd_dp, full.dqd_dp),
                     (kept.dqdd_dp, full.dqdd_dp)):
            assert np.array_equal(a, b[rows])
