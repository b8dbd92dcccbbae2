"""The integrator's step limit (issue 9, item 4): ``max_steps=`` on Model.dynamics and
``--max-steps`` on the command line. When the limit is reached the run stops with an
IntegrationError that names the limit and how to raise it, keeping the results up to then;
a larger limit lets the same run finish with the same results. Oracle for "the same run":
the simple pendulum's angle against a reduced-coordinate solution integrated here with
scipy's DOP853 (rtol 1e-13), not against another mbd2d run."""
from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbd2d

G = 9.81
PENDULUM = '''
[model]
name = "pendulum"
gravity = [0.0, -9.81]
[[body]]
name = "mass"
q0 = [1.0, 0.0, 0.0]
mass = 1.0
inertia = 0.0
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "mass"]
points = [[0.0, 0.0], [-1.0, 0.0]]
'''
T_END, STEPS = 2.0, 20


def reference_angle(t: np.ndarray) -> np.ndarray:
    """Point mass on a massless 1 m rod released horizontal: th'' = -g cos(th)."""
    sol = solve_ivp(lambda _, y: [y[1], -G * math.cos(y[0])], (0.0, float(t[-1])), [0.0, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    return sol.y[0]


def test_error_controlled_run_stops_at_the_limit_and_says_how_to_raise_it() -> None:
    m = mbd2d.loads(PENDULUM)
    with pytest.raises(mbd2d.IntegrationError, match=r"max_steps = 40 .*raise max_steps "
                       r"\(command line: --max-steps\)") as info:
        m.dynamics(T_END, STEPS, method="generalized-alpha", rtol=1e-8, max_steps=40)
    assert 0.0 < info.value.t < T_END
    part = info.value.results
    assert 0 < len(part.t) < STEPS + 1 and part.t[-1] <= info.value.t
    # raised, the same run finishes and follows the reference
    res = m.dynamics(T_END, STEPS, method="generalized-alpha", rtol=1e-8, max_steps=100_000)
    assert res.stats["steps"] + res.stats["rejected_steps"] > 40
    th = np.arctan2(res.body("mass").y, res.body("mass").x)
    np.testing.assert_allclose(th, reference_angle(res.t), rtol=0, atol=1e-4)
    # the rows kept before the stop are those of the full run
    np.testing.assert_allclose(part.q, res.q[:len(part.t)], rtol=0, atol=1e-14)


@pytest.mark.parametrize("method", ["dopri5", "partitioned"])
def test_explicit_methods_obey_the_limit(method: str) -> None:
    m = mbd2d.loads(PENDULUM)
    with pytest.raises(mbd2d.IntegrationError, match="max_steps = 10 "):
        m.dynamics(T_END, STEPS, method=method, rtol=1e-10, atol=1e-12, max_steps=10)
    res = m.dynamics(T_END, STEPS, method=method, rtol=1e-10, atol=1e-12, max_steps=10**6)
    th = np.arctan2(res.body("mass").y, res.body("mass").x)
    np.testing.assert_allclose(th, reference_angle(res.t), rtol=0, atol=1e-7)


@pytest.mark.parametrize("method", ["generalized-alpha", "baumgarte-rk4"])
def test_fixed_step_run_that_needs_more_steps_stops_before_it_starts(method: str) -> None:
    m = mbd2d.loads(PENDULUM)
    with pytest.raises(mbd2d.IntegrationError, match=r"needs 2000 steps, more than the step "
                       r"limit max_steps = 1999: raise max_steps .* or take a larger h"):
        m.dynamics(T_END, STEPS, method=method, h=1e-3, max_steps=1999)
    res = m.dynamics(T_END, STEPS, method=method, h=1e-3, max_steps=2000)
    assert res.stats["steps"] == 2000


@pytest.mark.parametrize("bad", [0, -5, 2.5, "100", True, 2**31])
def test_bad_limit_is_a_model_error(bad: object) -> None:
    with pytest.raises(mbd2d.ModelError, match="max_steps must be a whole number >= 1"):
        mbd2d.loads(PENDULUM).dynamics(T_END, STEPS, max_steps=bad)


def test_command_line_max_steps(tmp_path: Path) -> None:
    model = tmp_path / "pendulum.toml"
    model.write_text(PENDULUM)
    out = tmp_path / "out.csv"
    base = [sys.executable, "-m", "mbd2d", "dynamics", str(model), "--t-end", str(T_END),
            "--steps", str(STEPS), "--out", str(out), "--method", "generalized-alpha",
            "--rtol", "1e-8"]
    r = subprocess.run(base + ["--max-steps", "40"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 4, r.stderr
    assert "--max-steps" in r.stderr and "max_steps = 40" in r.stderr
    r = subprocess.run(base + ["--max-steps", "100000"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert f"wrote {STEPS + 1} rows" in r.stdout
