"""Design sensitivities in sweeps: every case's dq/dp (and dlambda/dp, deffort/dp) at its own
parameter values, in the Python sweep, its CSV, the CLI and mbd2d-solve.

References (no sensitivity code): the four-bar's closed-form link angles (two-circle
intersection, tests/test_mechanism_measures.py) and angular velocities (Norton's velocity
ratio), differentiated by central differences at each case's own link lengths; the spring
pendulum's equilibrium k theta + m g (l/2) cos theta = 0 differentiated implicitly; central
differences of ordinary runs of ``with_params`` models for inverse dynamics and dopri5.
mbd2d-solve's CSV is the Python sweep's, byte for byte.
"""
from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d.cli import main

from test_mechanism_measures import fourbar_angles
from test_standalone import find_solver
from test_standalone_sweep import same_but_messages

pytest.importorskip("xarray")

EX = Path(__file__).resolve().parents[1] / "examples"
W = 2 * np.pi                      # the four-bar's crank speed (rad/s)
# the example's links: crank 1.0, coupler 3.5 (A at -1.75 on it), rocker 2.5 (B at -1.25 on
# it, O4 at 1.25), ground 3.0; the rocker's body angle is the link angle O4 -> B minus pi
GROUND, ROCKER = "joint.O4.points.1.0", "joint.B.points.1.0"


def rocker_motion(t: np.ndarray, a: float, b: float, c: float, d: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The rocker's link angle and angular velocity (closed forms)."""
    th2 = W * t
    th3, th4 = fourbar_angles(th2, a, b, c, d)
    return th4, W * a * np.sin(th2 - th3) / (c * np.sin(th4 - th3))


@pytest.fixture(scope="module")
def fourbar() -> mbd2d.Model:
    return mbd2d.load(EX / "fourbar_grashof.toml")


def test_each_case_against_closed_form_derivatives(fourbar):
    """d(rocker angle)/dp and d(rocker speed)/dp for p the ground length d and the rocker's
    point of B (the rocker length c = 1.25 - x), at each swept coupler length."""
    values = np.array([-2.0, -1.75, -1.6])       # A on the coupler: b = 1.75 - x
    ds = mbd2d.sweep(fourbar, {"joint.A.points.1.0": values}, t_end=1.0, steps=72,
                     tol=1e-14, sensitivities=[GROUND, ROCKER])
    assert ds.dq_dp.dims == ("case", "time", "coordinate", "parameter")
    assert list(ds.parameter.values) == [GROUND, ROCKER] and (ds.status.values == 0).all()
    t, h = ds.time.values, 1e-6
    for k, x in enumerate(values):
        b = 1.75 - x
        links = {GROUND: lambda e: (1.0, b, 2.5, 3.0 + e),
                 ROCKER: lambda e: (1.0, b, 2.5 - e, 3.0)}
        for name, lk in links.items():
            (p4, p4d), (m4, m4d) = rocker_motion(t, *lk(h)), rocker_motion(t, *lk(-h))
            sel = dict(case=k, coordinate="rocker.theta", parameter=name)
            assert_allclose(ds.dq_dp.sel(**sel), (p4 - m4) / (2 * h), atol=2e-8)
            assert_allclose(ds.dqd_dp.sel(**sel), (p4d - m4d) / (2 * h), atol=2e-7)


def test_statics_against_the_implicit_derivative():
    """Spring pendulum: k theta + m g (l/2) cos theta = 0, so dtheta/dm = -(g l/2 cos th) /
    (k - m g l/2 sin th) and dtheta/dk = -theta / (k - m g l/2 sin th)."""
    m = mbd2d.load(EX / "pendulum_spring.toml")
    masses = np.array([0.5, 1.0, 2.0])
    names = ["body.bar.mass", "force.torsion.stiffness"]
    ds = mbd2d.sweep(m, {"body.bar.mass": masses}, "statics", sensitivities=names)
    k, g, r = 10.0, 9.81, 0.5
    for c, mass in enumerate(masses):
        th = 0.0
        for _ in range(60):                          # Newton on the closed form
            th -= (k * th + mass * g * r * np.cos(th)) / (k - mass * g * r * np.sin(th))
        den = k - mass * g * r * np.sin(th)
        got = ds.dq_dp.sel(case=c, coordinate="bar.theta").values[0]
        assert_allclose(got, [-g * r * np.cos(th) / den, -th / den], rtol=1e-9)
        gx = ds.dq_dp.sel(case=c, coordinate="bar.x").values[0]
        assert_allclose(gx, -r * np.sin(th) * got, rtol=1e-9, atol=1e-14)


def _central(model: mbd2d.Model, case: dict, name: str, h: float, run,
             driver: str | None = None) -> tuple:
    """Central differences of an ordinary run's q, qd, qdd (and a driver's effort) along
    name."""
    base = model.with_params(case).parameters()[name]
    hi, lo = (run(model.with_params({**case, name: base + s * h})) for s in (1, -1))
    diff = [(getattr(hi, k) - getattr(lo, k)) / (2 * h) for k in ("q", "qd", "qdd")]
    eff = (hi.effort(driver) - lo.effort(driver)) / (2 * h) if driver else None
    return diff, eff


def test_inverse_dynamics_against_central_differences():
    """The efforts are affine in the masses: their central differences are exact to
    rounding; the joint point's to O(h^2)."""
    m = mbd2d.load(EX / "fourbar_masses.toml")
    names = ["body.rocker.mass", "body.coupler.inertia", "joint.B.points.0.0"]
    cases = {"body.coupler.mass": [1.0, 2.5]}
    ds = mbd2d.sweep(m, cases, "inverse_dynamics", t_end=0.5, steps=20, sensitivities=names)
    assert ds.deffort_dp.dims == ("case", "time", "driver", "parameter")
    run = lambda mm: mm.inverse_dynamics(t_end=0.5, steps=20, tol=1e-14)   # noqa: E731
    for c, mass in enumerate(cases["body.coupler.mass"]):
        for j, name in enumerate(names):
            (dq, dqd, dqdd), deff = _central(m, {"body.coupler.mass": mass}, name, 1e-5, run,
                                             "motor")
            assert_allclose(ds.dq_dp.values[c, :, :, j], dq, atol=1e-8)
            assert_allclose(ds.dqdd_dp.values[c, :, :, j], dqdd, atol=1e-6)
            scale = np.abs(deff).max() + 1.0
            assert_allclose(ds.deffort_dp.values[c, :, 0, j], deff, atol=1e-7 * scale)


def test_dopri5_against_central_differences():
    m = mbd2d.load(EX / "fourbar_masses.toml")
    m.drivers.clear()
    cases = {"body.coupler.mass": [1.0, 2.0]}
    kw = dict(t_end=0.4, steps=8, method="dopri5", rtol=1e-12, atol=1e-12)
    ds = mbd2d.sweep(m, cases, "dynamics", sensitivities=["body.rocker.mass"], **kw)
    run = lambda mm: mm.dynamics(**kw)                                       # noqa: E731
    for c, mass in enumerate(cases["body.coupler.mass"]):
        (dq, dqd, _), _ = _central(m, {"body.coupler.mass": mass}, "body.rocker.mass", 1e-4,
                                   run)
        assert_allclose(ds.dq_dp.values[c, :, :, 0], dq, atol=1e-7)
        assert_allclose(ds.dqd_dp.values[c, :, :, 0], dqd, atol=1e-6)


def test_a_dead_centre_case_keeps_its_sensitivities_up_to_there(fourbar):
    """As the case's own run raises: its results (with their sensitivities) up to the
    dead centre; NaN after."""
    ds = mbd2d.sweep(fourbar, {GROUND: [5.8, 3.0]}, t_end=1.0, steps=100,
                     sensitivities=[ROCKER])
    assert list(ds.status.values) == [3, 0]
    with pytest.raises(mbd2d.SingularConfigurationError) as exc:
        fourbar.with_params({GROUND: 5.8}).kinematics(t_end=1.0, steps=100,
                                                      sensitivities=[ROCKER])
    kept = exc.value.results
    n = len(kept.t)
    assert 1 < n < 101
    assert_allclose(ds.dq_dp.values[0, :n], kept.dq_dp, rtol=0, atol=0)
    assert np.isnan(ds.dq_dp.values[0, n:]).all()
    assert ds.message.values[0] == str(exc.value)


@pytest.mark.parametrize("analysis, kw, match", [
    ("kinematics", dict(positions_only=True), "velocities and accelerations"),
    ("dynamics", dict(method="baumgarte-rk4", h=1e-3), "dopri5.*or generalized-alpha"),
])
def test_analyses_without_sensitivities_are_model_errors(analysis, kw, match):
    m = mbd2d.load(EX / ("fourbar_grashof.toml" if analysis == "kinematics"
                         else "fourbar_masses.toml"))
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.sweep(m, {GROUND: [3.0]}, analysis, t_end=0.1, steps=2,
                    sensitivities=[ROCKER], **kw)


@pytest.mark.parametrize("names, match", [(["joint.Z.x"], "unknown parameter"),
                                          (5, "list of names"), ([ROCKER, ROCKER], "twice")])
def test_bad_parameter_lists_are_model_errors(fourbar, names, match):
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.sweep(fourbar, {GROUND: [3.0]}, t_end=0.1, steps=2, sensitivities=names)


def _rows(path: Path) -> list[list[str]]:
    with open(path, newline="") as f:
        return list(csv.reader(f))


def test_csv_columns_and_the_cli(fourbar, tmp_path):
    cases = {GROUND: np.linspace(2.9, 3.1, 3)}
    ds = mbd2d.sweep(fourbar, cases, t_end=1.0, steps=10, sensitivities=[ROCKER])
    mbd2d.write_sweep(ds, tmp_path / "api.csv")
    rows = _rows(tmp_path / "api.csv")
    col = rows[0].index(f"d(rocker.theta_dot)/d({ROCKER})")
    got = [float(r[col]) for r in rows[1:] if r[0] == "1"]
    assert_allclose(got, ds.dqd_dp.sel(case=1, coordinate="rocker.theta",
                                       parameter=ROCKER).values, rtol=1e-16)
    assert main(["sweep", str(EX / "fourbar_grashof.toml"), "--param", f"{GROUND}=2.9:3.1:3",
                 "--t-end", "1", "--steps", "10", "--sensitivities", ROCKER, "--out",
                 str(tmp_path / "cli.csv")]) == 0
    assert (tmp_path / "cli.csv").read_bytes() == (tmp_path / "api.csv").read_bytes()


@pytest.mark.parametrize("model, cases, analysis, kw", [
    ("fourbar_grashof.toml", {"joint.A.points.1.0": [-1.9, -1.75]}, "kinematics",
     dict(t_end=1.0, steps=20, sensitivities=[GROUND, ROCKER],
          measures=["transmission_angle:B", "velocity_ratio:motor:rocker.theta",
                    "dead_centre_distance"])),
    ("fourbar_masses.toml", {"body.coupler.mass": [1.0, 2.0]}, "inverse_dynamics",
     dict(t_end=0.5, steps=10, sensitivities=["body.rocker.mass", "joint.B.points.0.0"],
          measures=["mechanical_advantage:motor:rocker.theta"])),
    ("pendulum_spring.toml", {"body.bar.mass": [0.5, 1.0]}, "statics",
     dict(sensitivities=["body.bar.mass", "force.torsion.stiffness"])),
    ("fourbar_masses.toml", {"body.coupler.mass": [1.0, 2.0]}, "dynamics",
     dict(t_end=0.3, steps=6, method="dopri5", sensitivities=["body.rocker.mass"])),
    ("fourbar_grashof.toml", {GROUND: [5.8, 3.0]}, "kinematics",
     dict(t_end=1.0, steps=50, sensitivities=[ROCKER])),
])
def test_mbd2d_solve_writes_the_python_sweep_with_sensitivities(tmp_path, model, cases,
                                                              analysis, kw):
    m = mbd2d.load(EX / model)
    mbd2d.export_sweep(m, tmp_path / "s.mbd", cases, analysis, **kw)
    r = subprocess.run([find_solver(), str(tmp_path / "s.mbd"), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=300)
    mbd2d.write_sweep(mbd2d.sweep(m, cases, analysis, workers=1, **kw), tmp_path / "py.csv")
    assert r.returncode == 0, r.stderr
    solve, py = _rows(tmp_path / "solve.csv"), _rows(tmp_path / "py.csv")
    if r.stderr:                                       # a failed case: its own words
        same_but_messages(solve, py)
    else:
        assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
