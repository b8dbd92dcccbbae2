"""Stiffness: dopri5 and partitioned say when their steps are limited by stability, not
accuracy (Hairer's stiffness test of DOPRI5), from every front door; generalized-alpha takes
steps set by the motion.

Oracle, written here: a block on a slide pulled back by a spring-damper, m x'' + c x' + k x = 0
with x(0) = x0, x'(0) = 0. Overdamped, x = A exp(l1 t) + B exp(l2 t) with
l1,2 = (-c +- sqrt(c^2 - 4 m k)) / (2 m), A = -l2 x0 / (l1 - l2), B = l1 x0 / (l1 - l2). With
c = 1e4, k = 100, m = 1 the fast rate l2 ~ -1e4 dies within a millisecond and the slow one
l1 ~ -0.01 sets the motion; an explicit method's steps stay near its stability boundary
(3.3 / |l2| for dopri5) however loose the tolerance. An undamped oscillator (k = 1e4) has
steps set by accuracy: no warning, even past the thousand steps where the test starts.
"""
from __future__ import annotations

import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest
from test_standalone import ROOT, find_solver

import mbd2d
from mbd2d.cli import main

M, C, K, X0 = 1.0, 1e4, 100.0, 0.1

BLOCK = """
[model]
name = "damped"
gravity = [0.0, 0.0]
[[body]]
name = "block"
q0 = [{x0}, 0.0, 0.0]
mass = {m}
inertia = 0.1
[[joint]]
name = "slide"
type = "translational"
bodies = ["ground", "block"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[1.0, 0.0], [1.0, 0.0]]
[[force]]
name = "damper"
type = "spring"
bodies = ["ground", "block"]
points = [[-1.0, 0.0], [0.0, 0.0]]
stiffness = {k}
damping = {c}
length0 = 1.0
"""


def block(c: float = C, k: float = K) -> str:
    return BLOCK.format(x0=X0, m=M, k=k, c=c)


def rates(c: float = C, k: float = K, m: float = M) -> tuple[float, float]:
    d = np.sqrt(c * c - 4.0 * m * k)
    return (-c + d) / (2.0 * m), (-c - d) / (2.0 * m)


def x_exact(t: np.ndarray) -> np.ndarray:
    l1, l2 = rates()
    return (-l2 * np.exp(l1 * t) + l1 * np.exp(l2 * t)) * X0 / (l1 - l2)


@pytest.mark.parametrize("method", ["dopri5", "partitioned"])
def test_explicit_steps_on_the_stability_boundary_are_reported(method):
    """Three tolerances: each run warns, its steps stay at h |l2| of 2.5 to 5 (the stability
    boundary, 3.3, with the step control hovering around it: measured 3.9 to 4.3), their
    number hardly changes with the tolerance (3038 to 3124 from rtol 1e-6 to 1e-10: stability
    sets them), and the motion is the closed form's to 1e-11 (measured 9e-13 to 9e-15)."""
    m = mbd2d.loads(block())
    steps = []
    for rtol in (1e-6, 1e-8, 1e-10):
        with pytest.warns(mbd2d.StiffnessWarning, match="generalized-alpha"):
            r = m.dynamics(1.0, 10, method=method, rtol=rtol, atol=rtol * 1e-3)
        assert 0.0 < r.stats["stiff_from"] < 1.0
        assert 2.5 < r.stats["h_max"] * abs(rates()[1]) < 5.0
        np.testing.assert_allclose(r.q[:, 0], x_exact(r.t), rtol=0, atol=1e-11)
        steps.append(r.stats["steps"])
    assert steps[0] > 0.9 * steps[-1]


def test_generalized_alpha_steps_with_the_slow_motion():
    """The implicit method at h = 1e-2 and 1e-3 (100 and 1000 steps against dopri5's 3000):
    no warning, the error falls as h**2 (measured 3.1e-6, 3.1e-8)."""
    m = mbd2d.loads(block())
    errs = []
    for h in (1e-2, 1e-3):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            r = m.dynamics(1.0, 10, method="generalized-alpha", h=h)
        assert "stiff_from" not in r.stats
        errs.append(np.abs(r.q[:, 0] - x_exact(r.t)).max())
    assert errs[0] < 1e-5 and 50 < errs[0] / errs[1] < 200


def test_steps_set_by_accuracy_are_not_reported():
    """The undamped oscillator x = x0 cos(100 t): 440 to 2850 steps, growing with the
    accuracy asked, without a warning (the test starts at the thousandth step, so the two
    tight runs are tested); a damper of c = 100 (a fast rate of 99/s) over 51 steps is not
    worth a warning either, whatever limits them."""
    osc = mbd2d.loads(block(c=0.0, k=1e4))
    steps = []
    for rtol in (1e-6, 1e-8, 1e-10):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            r = osc.dynamics(1.0, 10, rtol=rtol, atol=rtol * 1e-3)
        np.testing.assert_allclose(r.q[:, 0], X0 * np.cos(100.0 * r.t), rtol=0,
                                   atol=1e4 * rtol * X0)
        steps.append(r.stats["steps"])
    assert steps[-1] > 2000 and steps[1] > 1000 and steps[0] < steps[1] < steps[-1]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = mbd2d.loads(block(c=100.0)).dynamics(1.0, 10, rtol=1e-6, atol=1e-9)
    assert r.stats["steps"] < 1000 and "stiff_from" not in r.stats


def test_the_command_line_and_the_standalone_program_say_it(tmp_path: Path, capsys):
    """`mbd2d dynamics` writes the warning as one of its own lines; mbd2d-solve writes the
    same CSV and says it on standard error."""
    toml = tmp_path / "block.toml"
    toml.write_text(block())
    assert main(["dynamics", str(toml), "--t-end", "1", "--steps", "10",
                 "--out", str(tmp_path / "py.csv")]) == 0
    err = capsys.readouterr().err
    assert err.startswith("mbd2d: warning: dopri5: from t = ") and "stiff" in err
    exe = find_solver()
    assert main(["export", str(toml), str(tmp_path / "b.mbd"), "--analysis", "dynamics",
                 "--t-end", "1", "--steps", "10"]) == 0
    run = subprocess.run([exe, str(tmp_path / "b.mbd"), str(tmp_path / "solve.csv")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "mbd2d-solve: warning: from t = " in run.stderr and "stiff" in run.stderr
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()


def test_warnings_point_at_the_callers_line():
    """The stiffness warning and a redundant-constraint warning name this file and the line
    of the call, not a line inside mbd2d."""
    m = mbd2d.loads(block())
    with pytest.warns(mbd2d.StiffnessWarning) as rec:
        m.dynamics(1.0, 10); line = _line()  # noqa: E702
    assert (rec[0].filename, rec[0].lineno) == (__file__, line)
    par = mbd2d.load(ROOT / "examples" / "parallelogram_extra_link.toml")
    with pytest.warns(mbd2d.RedundantConstraintWarning) as rec:
        par.kinematics(1.0, 4); line = _line()  # noqa: E702
    assert (rec[0].filename, rec[0].lineno) == (__file__, line)


def _line() -> int:
    """The caller's line number."""
    import inspect
    return inspect.currentframe().f_back.f_lineno


def test_a_sweep_marks_its_stiff_cases():
    """Dampers of 100, 1e4 and 1e5 (fast rates 99, 1e4 and 1e5 per second; the first one's 51
    steps are too few to be worth a warning): the two stiff cases carry the time of their
    own runs' stiff_from, the other NaN, and one warning names them; each case's motion is
    the closed form's."""
    pytest.importorskip("xarray")
    m = mbd2d.loads(block())
    cs = np.array([100.0, 1e4, 1e5])
    with pytest.warns(mbd2d.StiffnessWarning, match="2 of 3 cases .case 1, 2"):
        ds = mbd2d.sweep(m, {"force.damper.damping": cs}, analysis="dynamics", t_end=1.0,
                         steps=10, rtol=1e-8, atol=1e-11, workers=1)
    assert np.isnan(ds["stiff_from"].values[0])
    for k, c in enumerate(cs):
        l1, l2 = rates(c=c)
        t = ds["time"].values
        x = (-l2 * np.exp(l1 * t) + l1 * np.exp(l2 * t)) * X0 / (l1 - l2)
        np.testing.assert_allclose(ds["q"].values[k, :, 0], x, rtol=0, atol=1e-9)
        if k:
            with pytest.warns(mbd2d.StiffnessWarning):
                one = m.with_params({"force.damper.damping": c}).dynamics(
                    1.0, 10, rtol=1e-8, atol=1e-11)
            assert ds["stiff_from"].values[k] == one.stats["stiff_from"]


def test_the_standalone_sweep_names_its_stiff_cases(tmp_path: Path):
    """mbd2d-solve on the same three cases says which two were stiff, on standard error."""
    m = mbd2d.loads(block())
    mbd = tmp_path / "sweep.mbd"
    mbd2d.export_sweep(m, mbd, {"force.damper.damping": np.array([100.0, 1e4, 1e5])},
                       "dynamics", t_end=1.0, steps=10, rtol=1e-8, atol=1e-11)
    run = subprocess.run([find_solver(), str(mbd), str(tmp_path / "sweep.csv")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "warning: 2 of 3 cases (case 1, 2) ran with steps limited by stability" in run.stderr


def test_dopri5_with_sensitivities_reports_it_too():
    """The sensitivities' dopri5 (its own loop over the state and the variational equations)
    runs the same test: it warns on the damped block, and dx/dk is the closed form's,
    differentiated here by central differences."""
    m = mbd2d.loads(block())
    with pytest.warns(mbd2d.StiffnessWarning):
        r = m.dynamics(1.0, 10, rtol=1e-8, atol=1e-11, sensitivities=["force.damper.stiffness"])
    assert 0.0 < r.stats["stiff_from"] < 1.0

    def x(k: float) -> np.ndarray:
        l1, l2 = rates(k=k)
        return (-l2 * np.exp(l1 * r.t) + l1 * np.exp(l2 * r.t)) * X0 / (l1 - l2)
    np.testing.assert_allclose(r.q[:, 0], x(K), rtol=0, atol=1e-10)
    dk = 1e-3
    np.testing.assert_allclose(r.dq_dp[:, 0, 0], (x(K + dk) - x(K - dk)) / (2 * dk), rtol=0,
                               atol=1e-9)
