"""Sweeps in the standalone mbd2d-solve: a file written by ``mbd2d.export_sweep`` (or
``mbd2d export ... --param``) runs every case in one batch call and writes the CSV that
``mbd2d.write_sweep`` writes for the Python sweep.

References: the Python sweep's CSV (its numbers are those of ``with_params`` runs, bit for
bit: tests/test_sweep.py), and here again single runs of ``model.with_params(case)``, read
back from mbd2d-solve's file. The failed cases' messages are mbd2d-solve's own words (the
numbers, statuses and rows kept are the Python sweep's).
"""
from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.cli import main

import test_contact_friction_parameters as cfp
from test_standalone import find_solver
from test_sweep import RACK, gear_pair, model_from_toml

pytest.importorskip("xarray")

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"


def _rows(path: Path) -> list[list[str]]:
    with open(path, newline="") as f:
        return list(csv.reader(f))


def solve_sweep(tmp_path: Path, model: mbd2d.Model, cases: dict, analysis: str,
                **kw) -> tuple[list[list[str]], list[list[str]], subprocess.CompletedProcess]:
    """mbd2d-solve's rows and the Python sweep's rows of the same sweep."""
    mbd = tmp_path / "s.mbd"
    mbd2d.export_sweep(model, mbd, cases, analysis, **kw)
    out = tmp_path / "solve.csv"
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=300)
    py = tmp_path / "python.csv"
    mbd2d.write_sweep(mbd2d.sweep(model, cases, analysis, workers=1, **kw), py)
    return _rows(out), _rows(py), r


def same_but_messages(solve: list[list[str]], py: list[list[str]]) -> None:
    """Every field equal (numbers as text), except the message of a failed case, which
    must be there in both."""
    assert len(solve) == len(py) and solve[0] == py[0]
    m = solve[0].index("message")
    for a, b in zip(solve[1:], py[1:]):
        assert a[:m] + a[m + 1:] == b[:m] + b[m + 1:]
        assert bool(a[m]) == bool(b[m])


CASES = {
    "kinematics": (lambda: mbd2d.load(EX / "fourbar_grashof.toml"),
                   mbd2d.grid({"joint.B.points.0.0": [1.6, 1.75, 1.9],
                               "joint.O4.points.1.0": [2.9, 3.1]}), "kinematics",
                   dict(t_end=1.0, steps=30, every=4)),
    "positions": (lambda: mbd2d.load(EX / "cam_follower.toml"),
                  {"joint.pivot.points.0.0": [0.0, 0.01, -0.02]}, "kinematics",
                  dict(t_end=1.0, steps=20, positions_only=True)),
    "rack_open_phase": (lambda: model_from_toml(RACK),
                        {"joint.rp.radius": [0.3, 0.35, 0.25],
                         "joint.rp.point.0": [0.0, 0.05, -0.1]}, "kinematics",
                        dict(t_end=0.5, steps=10)),
    "gear_inverse": (gear_pair, {"joint.mesh.radii.0": [0.5, 0.6, 0.45],
                                 "joint.mesh.radii.1": [1.5, 1.4, 1.55],
                                 "joint.O2.points.0.0": [2.0, 2.0, 2.1],
                                 "body.wheel.mass": [3.0, 2.5, 4.0],
                                 "model.gravity.1": [-9.81, -1.6, 0.0]},
                     "inverse_dynamics", dict(t_end=0.5, steps=10)),
    "statics": (lambda: mbd2d.load(EX / "pendulum_spring.toml"),
                {"body.bar.mass": [0.5, 1.0, 2.0], "force.torsion.angle0": [0.0, 0.1, 0.2]},
                "statics", dict(t=0.0)),
    "dynamics": (lambda: mbd2d.load(EX / "fourbar_masses.toml"),
                 {"body.coupler.mass": [1.0, 2.0], "body.rocker.inertia": [0.05, 0.2]},
                 "dynamics", dict(t_end=0.3, steps=6, method="generalized-alpha", h=1e-3)),
    "joint_friction": (lambda: cfp.incline(),
                       {"joint.slide.friction.mu": [0.0, 0.1, 0.3],
                        "joint.slide.friction.mu_static": [0.0, 0.15, 0.5]},
                       "dynamics", dict(t_end=0.5, steps=5, rtol=1e-9, atol=1e-11)),
    "contact": (lambda: cfp.ball(e=0.5),
                {"contact.floor.law.stiffness": [1e5, 1e6, 1e7],
                 "contact.floor.law.restitution": [0.9, 0.5, 0.3],
                 "contact.floor.circle.radius": [0.1, 0.12, 0.08]},
                "dynamics", dict(t_end=0.2, steps=5, rtol=1e-9, atol=1e-12)),
}


@pytest.mark.parametrize("case", list(CASES))
def test_mbd2d_solve_writes_the_python_sweep(tmp_path: Path, case: str) -> None:
    """Byte for byte when every case completes."""
    build, cases, analysis, kw = CASES[case]
    model = build()
    solve, py, r = solve_sweep(tmp_path, model, cases, analysis, **kw)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "python.csv").read_bytes()
    # one case against a run of its own model (no batch code)
    names = list(cases)
    j = len(next(iter(cases.values()))) - 1
    own = model.with_params({n: float(cases[n][j]) for n in names})
    t0 = {"kinematics": lambda: own.kinematics(**kw),
          "inverse_dynamics": lambda: own.inverse_dynamics(**kw),
          "statics": lambda: own.statics(**kw),
          "dynamics": lambda: own.dynamics(**kw)}[analysis]()
    head = solve[0]
    mine = [row for row in solve[1:] if row[0] == str(j)]
    q = np.atleast_2d(t0.q)
    assert len(mine) == q.shape[0]
    coords = [str(c) for c in (t0.coordinate_names)]
    got = np.array([[float(row[head.index(c)]) for c in coords] for row in mine])
    np.testing.assert_array_equal(got, q)


def test_failed_cases_keep_their_rows_and_say_why(tmp_path: Path) -> None:
    """The seed four-bar's coupler lengths reach the dead centre at different times, and a
    far-off pivot does not assemble: rows, statuses, numbers and messages as the Python
    sweep, exit code 0 with the first failures on standard error."""
    model = mbd2d.load(EX / "fourbar_seed.toml")
    cases = {"joint.B.points.0.0": [1.0, 2.0, 3.0, 40.0]}
    solve, py, r = solve_sweep(tmp_path, model, cases, "kinematics", t_end=1.0, steps=50)
    assert r.returncode == 0
    same_but_messages(solve, py)
    m, s = solve[0].index("message"), solve[0].index("status")
    status = {row[0]: row[s] for row in solve[1:]}
    assert status == {"0": "3", "1": "3", "2": "0", "3": "6"}
    last = {row[0]: row[m] for row in solve[1:]}
    assert "dead centre" in last["0"] and "'motor'" in last["0"] and last["2"] == ""
    pm = {row[0]: row[m] for row in py[1:]}
    assert last == pm                  # dead centres and contradictions: the Python words
    assert "contradict" in last["3"] and "O2, A, B, O4, motor cannot all hold" in last["3"]
    assert r.stderr.count("mbd2d-solve: case ") == 3
    assert [row for row in solve[1:] if row[0] == "3"][0][solve[0].index("t")] == ""


def test_cli_export_param_gives_the_sweep_file(tmp_path: Path, capsys) -> None:
    """`mbd2d export --param ... --grid` writes export_sweep's file; mbd2d-solve then writes
    `mbd2d sweep --out .csv`'s file."""
    toml = str(EX / "fourbar_grashof.toml")
    args = ["--param", "joint.B.points.0.0=1.5:2.0:3", "--param", "joint.O4.points.1.0=2.9:3.1:2",
            "--grid", "--t-end", "1", "--steps", "20"]
    cli = tmp_path / "cli.mbd"
    assert main(["export", toml, str(cli), *args]) == 0
    assert "of 6 cases" in capsys.readouterr().out
    api = tmp_path / "api.mbd"
    mbd2d.export_sweep(mbd2d.load(toml), api, mbd2d.grid(
        {"joint.B.points.0.0": np.linspace(1.5, 2.0, 3),
         "joint.O4.points.1.0": np.linspace(2.9, 3.1, 2)}), t_end=1.0, steps=20)
    assert cli.read_text() == api.read_text()
    out = tmp_path / "solve.csv"
    assert subprocess.run([find_solver(), str(cli), str(out)], timeout=120).returncode == 0
    py = tmp_path / "sweep.csv"
    assert main(["sweep", toml, *args, "--workers", "1", "--out", str(py)]) == 0
    assert out.read_bytes() == py.read_bytes()
    assert main(["export", toml, str(cli), *args, "--energy"]) == 2
    assert "writes the sweep's columns" in " ".join(capsys.readouterr().err.split())


def _sweep_lines(tmp_path: Path) -> list[str]:
    mbd = tmp_path / "m.mbd"
    mbd2d.export_sweep(mbd2d.load(EX / "fourbar_grashof.toml"), mbd,
                       {"joint.B.points.0.0": [1.7, 1.8]}, t_end=1.0, steps=5)
    return mbd.read_text().splitlines()


@pytest.mark.parametrize("edit, needle", [
    (("cases 1 1 2", "cases 1 1"), "three whole numbers"),
    (("cases 1 1 2", "cases 0 1 2"), "NP and NCASE must be at least 1"),
    (("cases 1 1 2", "cases 1 1 999999"), "more cases than the rest of the file"),
    (("cases 1 1 2", "cases 1 1 x"), "is not a whole number"),
    (("1 9", "7 9"), "TABLE is 1 (params)"),
    (("1 9", "1 0"), "INDEX is a whole number"),
    (("1 9", "1 9 3"), "TABLE INDEX expected"),
    (("1 9", "1 999"), "lies outside its table (22 entries)"),
    (("1 9", "2 1"), "lies outside its table (0 entries in kinematics)"),
    (("opens 0", "opens 1\n3 99"), "open phase 1 lies outside"),
    (("1.80000000000000004e+00 1.80000000000000004e+00", "1.8 nan"), "is not a number"),
    (("opens 0", "opens 1\n0 3"), "from 1"),
    (("opens 0", "opens 0\ncases 1 0 1\nx\n1"), '"cases" is given twice'),
    (("opens 0", "opens 0\noutputs energy"), "outputs"),
    (("opens 0", "opens 0\nsensitivities 1\njoint.B.points.0.0 1 99"),
     'sensitivity "joint.B.points.0.0"'),
])
def test_bad_cases_blocks_name_their_line(tmp_path: Path, edit: tuple[str, str],
                                          needle: str) -> None:
    lines = _sweep_lines(tmp_path)
    i = lines.index(edit[0])
    lines[i] = edit[1]
    bad = tmp_path / "bad.mbd"
    bad.write_text("\n".join(lines) + "\n")
    r = subprocess.run([find_solver(), str(bad), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr and r.stderr.startswith("mbd2d-solve: "), r.stderr


def test_a_sweep_file_takes_no_output_columns(tmp_path: Path) -> None:
    """An inverse-dynamics sweep with an "outputs" line: refused (the sweep's CSV has its
    own columns), as the command line refuses --energy with --param."""
    mbd = tmp_path / "g.mbd"
    mbd2d.export_sweep(gear_pair(), mbd, {"body.wheel.mass": [3.0, 4.0]}, "inverse_dynamics",
                       t_end=0.2, steps=4)
    text = mbd.read_text().replace("\nend\n", "\noutputs efforts\nend\n")
    mbd.write_text(text)
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "a sweep writes its own columns" in r.stderr, r.stderr
    assert not (tmp_path / "o.csv").exists()


def test_the_threads_do_not_change_a_byte(tmp_path: Path) -> None:
    """mbd2d-solve runs the cases in parallel chunks (OpenMP): 1 and 2 threads write the
    same file, failed cases included (the seed four-bar's dead centres, a contradiction)."""
    import os
    mbd = tmp_path / "s.mbd"
    mbd2d.export_sweep(mbd2d.load(EX / "fourbar_seed.toml"), mbd,
                       {"joint.B.points.0.0": np.linspace(0.5, 4.0, 150).tolist() + [40.0]},
                       t_end=1.0, steps=40)
    outs = []
    for threads in ("1", "2"):
        out = tmp_path / f"t{threads}.csv"
        r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True,
                           text=True, timeout=120, env={**os.environ, "OMP_NUM_THREADS": threads})
        assert r.returncode == 0, r.stderr
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]
    statuses = {row[3] for row in _rows(tmp_path / "t1.csv")[1:]}
    assert {"0", "3", "6"} <= statuses


def test_a_sweep_too_large_or_unwritable_is_refused(tmp_path: Path) -> None:
    """Outputs beyond the memory are refused before anything is allocated, and an output
    path that cannot be written is named: exit code 2 both."""
    lines = _sweep_lines(tmp_path)
    i = next(k for k, ln in enumerate(lines) if ln.startswith("steps "))
    lines[i] = "steps 900000000"
    big = tmp_path / "big.mbd"
    big.write_text("\n".join(lines) + "\n")
    r = subprocess.run([find_solver(), str(big), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "give fewer cases or steps" in r.stderr, r.stderr
    ok = tmp_path / "ok.mbd"
    ok.write_text("\n".join(_sweep_lines(tmp_path)) + "\n")
    r = subprocess.run([find_solver(), str(ok), str(tmp_path / "no" / "dir" / "o.csv")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "cannot write" in r.stderr, r.stderr


@pytest.mark.parametrize("command", ["sweep", "export"])
def test_param_counts_beyond_a_sweep_are_refused(tmp_path: Path, capsys, command: str) -> None:
    """NUM beyond the largest sweep (10^8 cases) is refused before any array is made."""
    toml = str(EX / "fourbar_grashof.toml")
    argv = [command, toml] + ([str(tmp_path / "s.mbd")] if command == "export" else []) + [
        "--param", "joint.B.points.0.0=1.5:2.0:1000000000", "--t-end", "1", "--steps", "4"]
    if command == "sweep":
        argv += ["--out", str(tmp_path / "s.csv")]
    assert main(argv) == 2
    assert "NUM must be from 1 to 100000000" in " ".join(capsys.readouterr().err.split())


@pytest.mark.parametrize("analysis", ["check", "linearize"])
def test_a_check_is_no_sweep(tmp_path: Path, capsys, analysis: str) -> None:
    """export --analysis check (or linearize) --param: a ModelError (exit 2), not a KeyError
    (both found by tests/test_cli_fuzz.py)."""
    assert main(["export", str(EX / "fourbar_grashof.toml"), str(tmp_path / "c.mbd"),
                 "--analysis", analysis, "--param", "joint.B.points.0.0=1.5:2.0:3"]) == 2
    assert f"not {analysis}" in capsys.readouterr().err


def test_a_parameter_a_kinematic_run_does_not_take(tmp_path: Path) -> None:
    """Gravity swept in kinematics enters no table of the run (it raised a ValueError when no
    entry was left to set; found by a random sweep export): every case is the base model's
    run, in the Python sweep and in mbd2d-solve alike."""
    model = mbd2d.load(EX / "fourbar_grashof.toml")
    cases = {"model.gravity.1": [-9.81, -1.0, 0.0]}
    solve, py, r = solve_sweep(tmp_path, model, cases, "kinematics", t_end=1.0, steps=6)
    assert r.returncode == 0 and solve == py
    base = model.kinematics(1.0, 6).q
    head = solve[0]
    cols = [head.index(c) for c in model.kinematics(1.0, 1).coordinate_names]
    for c in range(3):
        got = np.array([[float(row[k]) for k in cols] for row in solve[1:] if row[0] == str(c)])
        np.testing.assert_array_equal(got, base)


@pytest.mark.parametrize("model, analysis", [("fourbar_grashof.toml", "kinematics"),
                                             ("fourbar_masses.toml", "inverse_dynamics")])
def test_dead_centre_cases_in_the_python_words(tmp_path: Path, model: str,
                                               analysis: str) -> None:
    """Coupler lengths below 1.5 stop at a dead centre: mbd2d-solve writes their messages as
    the Python sweep records them (time, driver, dependent constraints, sigma ratio, rows
    kept), so the whole file is the Python one byte for byte."""
    m = mbd2d.load(EX / model)
    cases = {"joint.B.points.0.0": [-0.5, -0.4, 1.75, -0.3]}        # coupler 1.25 .. 3.5
    kw = dict(t_end=1.0, steps=24)
    mbd2d.export_sweep(m, tmp_path / "s.mbd", cases, analysis, **kw)
    r = subprocess.run([find_solver(), str(tmp_path / "s.mbd"), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    ds = mbd2d.sweep(m, cases, analysis, workers=1, **kw)
    assert (ds.status.values == 3).sum() >= 2          # dead centres
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
    assert "Singular configuration (dead centre)" in r.stderr


def test_assembly_failures_in_the_python_words(tmp_path: Path) -> None:
    """Coupler lengths the loop cannot close at the start (no assembly near the estimates,
    or the driver contradicting the loop) and a far-off rocker pivot: mbd2d-solve's file is
    the Python sweep's byte for byte, messages included."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    cases = {"joint.B.points.0.0": [3.0, 1.75, 3.2], "joint.O4.points.1.0": [3.0, 9.0, 3.0]}
    mbd2d.export_sweep(m, tmp_path / "s.mbd", cases, "kinematics", t_end=1.0, steps=12)
    r = subprocess.run([find_solver(), str(tmp_path / "s.mbd"), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    ds = mbd2d.sweep(m, cases, "kinematics", workers=1, t_end=1.0, steps=12)
    assert set(ds.status.values) == {4, 6}, ds.status.values   # no assembly, contradiction
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()


@pytest.mark.parametrize("method", ["dopri5", "generalized-alpha"])
def test_dynamics_failures_in_the_python_words(tmp_path: Path, method: str) -> None:
    """The driven four-bar with masses, coupler lengths below 1.5 run into the dead centre in
    forward dynamics: mbd2d-solve's file is the Python sweep's byte for byte ("METHOD: what",
    the rows kept)."""
    m = mbd2d.load(EX / "fourbar_masses.toml")
    cases = {"joint.B.points.0.0": [-0.5, -0.4, 1.75]}
    kw = dict(t_end=1.0, steps=24, method=method)
    mbd2d.export_sweep(m, tmp_path / "s.mbd", cases, "dynamics", **kw)
    r = subprocess.run([find_solver(), str(tmp_path / "s.mbd"), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    ds = mbd2d.sweep(m, cases, "dynamics", workers=1, **kw)
    assert (ds.status.values != 0).sum() >= 2, ds.status.values
    assert all(str(msg).startswith(f"{method}: ") for msg, st in
               zip(ds.message.values, ds.status.values) if st != 0)
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
