"""The mbd2d command line: outputs, exit codes and one-paragraph messages."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.results import SUFFIXES, read_csv

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mbd2d", *args], capture_output=True,
                          text=True, timeout=120)


def test_kinematics_csv_columns_and_values(tmp_path: Path) -> None:
    out = tmp_path / "crank_rocker.csv"
    r = cli("kinematics", str(EX / "fourbar_grashof.toml"), "--t-end", "1", "--steps", "100",
            "--out", str(out))
    assert r.returncode == 0, r.stderr
    header, rows = read_csv(out)
    expected = ["t"] + [f"{b}.{s}" for b in ("crank", "coupler", "rocker") for s in SUFFIXES]
    assert header == expected
    assert rows.shape == (101, 1 + 27)
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(t_end=1.0, steps=100)
    np.testing.assert_array_equal(rows[:, 0], res.t)
    np.testing.assert_allclose(rows[:, 1:4], res.q[:, 0:3], rtol=0, atol=1e-15)
    np.testing.assert_allclose(rows[:, 1 + 9 + 6:1 + 9 + 9], res.qdd[:, 3:6], rtol=1e-15,
                               atol=1e-13)


def test_kinematics_npz(tmp_path: Path) -> None:
    out = tmp_path / "slider.npz"
    r = cli("kinematics", str(EX / "slider_crank.toml"), "--t-end", "0.5", "--steps", "50",
            "--out", str(out))
    assert r.returncode == 0, r.stderr
    data = np.load(out)
    assert data["q"].shape == (51, 9)
    assert list(data["coordinate_names"])[:3] == ["crank.x", "crank.y", "crank.theta"]


def test_kinematics_every_and_solver(tmp_path: Path) -> None:
    out = tmp_path / "slider.npz"
    r = cli("kinematics", str(EX / "slider_crank.toml"), "--t-end", "0.5", "--steps", "50",
            "--every", "20", "--solver", "dense", "--out", str(out))
    assert r.returncode == 0, r.stderr
    data = np.load(out)
    assert data["q"].shape == (4, 9)          # steps 0, 20, 40 and 50
    np.testing.assert_allclose(data["t"], [0.0, 0.2, 0.4, 0.5], rtol=0, atol=1e-15)


def test_toggle_paragraph_partial_output_and_exit_code(tmp_path: Path) -> None:
    out = tmp_path / "seed.csv"
    r = cli("kinematics", str(EX / "fourbar_seed.toml"), "--t-end", "1", "--steps", "1000",
            "--out", str(out))
    assert r.returncode == 3
    assert "Traceback" not in r.stderr
    text = " ".join(r.stderr.split())
    assert "Singular configuration (dead centre) at t = 0.88591864" in text
    assert "driver 'motor' can no longer be met" in text
    _, rows = read_csv(out)
    t_star = np.arccos((9 + 36 - 7.6**2) / 36) - np.pi / 3
    assert rows.shape[0] == 886
    assert rows[-1, 0] <= t_star


def test_bad_model_message_without_traceback(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text((EX / "fourbar_grashof.toml").read_text().replace(
        'bodies = ["crank", "coupler"]', 'bodies = ["crank", "coupling"]'))
    r = cli("kinematics", str(bad), "--t-end", "1", "--steps", "10", "--out",
            str(tmp_path / "x.csv"))
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "joint 'A'" in r.stderr and "'coupling'" in r.stderr


def test_missing_file_and_bad_suffix(tmp_path: Path) -> None:
    r = cli("kinematics", str(tmp_path / "nope.toml"), "--t-end", "1", "--steps", "10",
            "--out", str(tmp_path / "x.csv"))
    assert r.returncode == 2 and "Traceback" not in r.stderr and "nope.toml" in r.stderr
    r = cli("kinematics", str(EX / "slider_crank.toml"), "--t-end", "1", "--steps", "10",
            "--out", str(tmp_path / "x.txt"))
    assert r.returncode == 2 and ".csv or .npz" in r.stderr


@pytest.mark.parametrize("steps", ["0", "-3"])
def test_bad_steps(tmp_path: Path, steps: str) -> None:
    r = cli("kinematics", str(EX / "slider_crank.toml"), "--t-end", "1", "--steps", steps,
            "--out", str(tmp_path / "x.csv"))
    assert r.returncode == 2 and "steps" in r.stderr and "Traceback" not in r.stderr


def test_inverse_dynamics_and_optional_columns(tmp_path: Path) -> None:
    """inverse-dynamics writes the driver efforts by default; every result command takes the
    optional columns, equal to the API's results."""
    model = EX / "fourbar_masses.toml"
    out = tmp_path / "inv.csv"
    r = cli("inverse-dynamics", str(model), "--t-end", "1", "--steps", "20", "--out", str(out))
    assert r.returncode == 0, r.stderr
    header, rows = read_csv(out)
    res = mbd2d.load(model).inverse_dynamics(1.0, 20)
    assert header[-1] == "motor.effort" and len(header) == 1 + 27 + 1
    np.testing.assert_array_equal(rows[:, -1], res.effort("motor"))
    out = tmp_path / "dyn.csv"
    r = cli("dynamics", str(EX / "pendulum_spring.toml"), "--t-end", "1", "--steps", "10",
            "--out", str(out), "--energy", "--multipliers", "--reactions")
    assert r.returncode == 0, r.stderr
    header, rows = read_csv(out)
    dyn = mbd2d.load(EX / "pendulum_spring.toml").dynamics(1.0, 10)
    assert header[10:] == ["kinetic", "potential", "energy", "drift_position",
                           "drift_velocity", "lambda.pivot.x", "lambda.pivot.y", "pivot.fx",
                           "pivot.fy", "pivot.mz", "pivot.fx_j", "pivot.fy_j", "pivot.mz_j"]
    np.testing.assert_array_equal(rows[:, 12], dyn.energy)
    np.testing.assert_array_equal(rows[:, 15:17], dyn.lam)
    np.testing.assert_array_equal(rows[:, 21], dyn.reaction("pivot").fy_j)
    r = cli("kinematics", str(EX / "fourbar_grashof.toml"), "--t-end", "1", "--steps", "10",
            "--out", str(tmp_path / "k.csv"), "--reactions")
    assert r.returncode == 2 and "need multipliers" in " ".join(r.stderr.split())
    out = tmp_path / "eq.csv"
    r = cli("statics", str(EX / "pendulum_spring.toml"), "--out", str(out), "--reactions")
    assert r.returncode == 0, r.stderr
    header, rows = read_csv(out)
    assert header[:6] == ["t", "bar.x", "bar.y", "bar.theta", "stable", "residual"]
    assert rows[0, 4] == 1.0                                   # stable


def test_export_every_analysis_from_the_command_line(tmp_path: Path) -> None:
    for analysis, extra in (("kinematics", []), ("inverse-dynamics", ["--efforts"]),
                            ("dynamics", ["--method", "baumgarte-rk4", "--h", "1e-3",
                                          "--energy"]),
                            ("statics", ["--t", "0.5", "--multipliers"])):
        mbd = tmp_path / f"{analysis}.mbd"
        span = [] if analysis == "statics" else ["--t-end", "1", "--steps", "10"]
        r = cli("export", str(EX / "fourbar_masses.toml"), str(mbd), "--analysis", analysis,
                *span, *extra)
        assert r.returncode == 0, r.stderr
        text = mbd.read_text()
        assert f"\nanalysis {analysis}\n" in text
    assert "\nmethod baumgarte-rk4\n" in (tmp_path / "dynamics.mbd").read_text()
    r = cli("export", str(EX / "fourbar_masses.toml"), str(tmp_path / "x.mbd"), "--analysis",
            "dynamics")
    assert r.returncode == 2 and "needs t_end and steps" in r.stderr
