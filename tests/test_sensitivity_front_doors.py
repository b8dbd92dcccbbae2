"""Design sensitivities through every front door: the result tables and files, the command
line and the standalone mbd2d-solve.

The oracle of the columns is independent of the sensitivity code: central differences of
the value columns of runs of ``model.with_params({P: p +- dp})`` (each an ordinary analysis).
The standalone's CSV is compared with the Python path's as text (both write "%.16e").
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

import mbd2d
from mbd2d.cli import main
from mbd2d.results import read_csv

from test_standalone import find_solver

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
ALL = {"multipliers": True, "reactions": True, "efforts": True}


def free_fourbar() -> mbd2d.Model:
    sys.path.insert(0, str(EX))
    import free_fourbar as ff
    return ff.build()


# (model, analysis run, parameters, optional columns): kinematics at the tightest Newton
# tolerance, inverse dynamics and statics with every column that has a derivative, dopri5 at
# rtol 1e-12 with parameters that leave the assembled start alone (the start's sensitivity is
# the minimum-norm one, which the assembly of a perturbed model does not follow exactly),
# and driven (its motion the drive's: a pin and the drive's speed change it), with the
# multipliers', reactions' and efforts' columns as inverse dynamics;
# generalized-alpha at a fixed step (its sensitivities are the derivatives of its discrete
# solution, which the differences of runs at the same step follow)
CASES: dict[str, tuple[Callable[[], mbd2d.Model], Callable[..., Any], list[str], dict]] = {
    "kinematics": (lambda: mbd2d.load(EX / "fourbar_grashof.toml"),
                   lambda m, s: m.kinematics(1.0, 20, tol=1e-15, sensitivities=s),
                   ["joint.B.points.0.0", "joint.A.points.1.0", "driver.motor.f.poly.1"], {}),
    "inverse": (lambda: mbd2d.load(EX / "fourbar_masses.toml"),
                lambda m, s: m.inverse_dynamics(1.0, 20, tol=1e-15, sensitivities=s),
                ["joint.B.points.0.0", "body.coupler.mass", "body.rocker.inertia",
                 "model.gravity.1"], ALL),
    "statics": (lambda: mbd2d.load(EX / "pendulum_spring.toml"),
                lambda m, s: m.statics(sensitivities=s),
                ["joint.pivot.points.1.0", "body.bar.mass", "force.torsion.angle0",
                 "model.gravity.1"], ALL),
    "dynamics": (free_fourbar,
                 lambda m, s: m.dynamics(0.5, 10, method="dopri5", rtol=1e-12, atol=1e-14,
                                         sensitivities=s),
                 ["body.coupler.mass", "body.rocker.inertia", "model.gravity.1"], ALL),
    "driven dynamics": (lambda: mbd2d.load(EX / "fourbar_masses.toml"),
                        lambda m, s: m.dynamics(0.5, 10, method="dopri5", rtol=1e-12,
                                                atol=1e-14, sensitivities=s),
                        ["joint.B.points.0.0", "body.coupler.mass", "driver.motor.f.poly.1"],
                        ALL),
    "generalized-alpha": (free_fourbar,
                          lambda m, s: m.dynamics(0.5, 10, method="generalized-alpha", h=5e-3,
                                                  rtol=1e-12, atol=1e-14, sensitivities=s),
                          ["body.coupler.mass", "body.rocker.inertia", "model.gravity.1"],
                          ALL),
}


@pytest.mark.parametrize("case", list(CASES))
def test_columns_are_central_differences(case: str) -> None:
    """Every d(COLUMN)/d(P) column of the table against the central difference of COLUMN:
    |error| <= 1e-6 of the column's scale + 1e-8 of the parameter's largest derivative
    (central differences with dp = 1e-5 max(1, |p|) carry dp^2 truncation, about 1e-10, and
    the runs' round-off over dp, about 1e-11 relative; a column put under the wrong name or
    parameter is off by its whole size). generalized-alpha's accelerations are converged to
    1e-11 of the dynamic equations' largest term (its Newton's residual test), which the
    differences carry over dp: its differences are taken at dp = 1e-2 and 2e-2,
    Richardson-extrapolated (truncation dp^4, 2e-11 relative in q), and its acceleration
    columns held to 1e-5 of their scale (measured 9.4e-7 at dp = 1e-2, 8.0e-6 at 1e-3 and
    8.3e-5 at 1e-4: the differences' round-off, falling as 1 / dp)."""
    build, run, names, opts = CASES[case]
    model = build()
    res = run(model, names)
    header, rows = res.table(sensitivities=True, **opts)
    base = [c for c in header if not c.startswith("d(")]
    assert header[:len(base)] == base
    derived = header[len(base):]
    checked = 0

    def central(prm: str, v: float, dp: float) -> np.ndarray:
        hp, rp = run(model.with_params({prm: v + dp}), None).table(**opts)
        hm, rm = run(model.with_params({prm: v - dp}), None).table(**opts)
        assert hp == hm == base
        return (rp - rm) / (2 * dp)

    for prm in names:
        v = model.parameters()[prm]
        if case == "generalized-alpha":
            dp = 1e-2 * max(1.0, abs(v))
            fd = (4 * central(prm, v, dp) - central(prm, v, 2 * dp)) / 3
        else:
            fd = central(prm, v, 1e-5 * max(1.0, abs(v)))
        mine = [h for h in derived if h.endswith(f")/d({prm})")]
        block = np.abs(rows[:, [header.index(h) for h in mine]]).max()
        for h in mine:
            col = h[2:-len(f")/d({prm})")]
            j = base.index(col)
            got = rows[:, header.index(h)]
            scale = max(np.abs(got).max(), np.abs(fd[:, j]).max())
            err = np.abs(got - fd[:, j]).max()
            rel = 1e-5 if case == "generalized-alpha" and col.endswith("_ddot") else 1e-6
            assert err <= rel * scale + 1e-8 * block, (h, err, scale)
            checked += 1
    assert checked == len(derived)          # every derived column has its value column
    # the motion's derivatives come first for each parameter, in the value columns' order
    first = [h for h in derived if h.endswith(f")/d({names[0]})")]
    motion = [c for c in base if "." in c and c.split(".")[0] in res.body_names]
    assert [h[2:-len(f")/d({names[0]})")] for h in first][:len(motion)] == motion


@pytest.mark.parametrize("case", list(CASES))
def test_mbd2d_solve_writes_the_python_columns(tmp_path: Path, case: str) -> None:
    """The exported file's sensitivities block: mbd2d-solve writes the Python CSV, text for
    text, sensitivity columns included."""
    build, run, names, opts = CASES[case]
    model = build()
    res = run(model, names)
    settings = {"kinematics": dict(t_end=1.0, steps=20, tol=1e-15),
                "inverse": dict(t_end=1.0, steps=20, tol=1e-15, analysis="inverse-dynamics"),
                "statics": dict(analysis="statics"),
                "dynamics": dict(t_end=0.5, steps=10, analysis="dynamics", method="dopri5",
                                 rtol=1e-12, atol=1e-14),
                "driven dynamics": dict(t_end=0.5, steps=10, analysis="dynamics",
                                        method="dopri5", rtol=1e-12, atol=1e-14),
                "generalized-alpha": dict(t_end=0.5, steps=10, analysis="dynamics",
                                          method="generalized-alpha", h=5e-3, rtol=1e-12,
                                          atol=1e-14)}[case]
    mbd = tmp_path / "m.mbd"
    model.export(mbd, outputs=list(opts), sensitivities=names, **settings)
    assert f"sensitivities {len(names)}" in mbd.read_text()
    out = tmp_path / "solve.csv"
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    py = tmp_path / "python.csv"
    res.to_csv(py, sensitivities=True, **opts)
    assert out.read_text() == py.read_text()
    header, rows = read_csv(out)
    assert sum(h.startswith("d(") for h in header) > 0 and np.isfinite(rows).all()


def test_partial_run_keeps_its_sensitivities(tmp_path: Path) -> None:
    """The seed four-bar reaches its toggle: both paths write the rows up to there with
    their sensitivities (exit code 3 from mbd2d-solve)."""
    model = mbd2d.load(EX / "fourbar_seed.toml")
    names = ["joint.B.points.0.0", "joint.O4.points.0.0"]
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        model.kinematics(1.0, 200, sensitivities=names)
    part = info.value.results
    assert 0 < len(part.t) < 201 and part.dq_dp.shape == (len(part.t), 9, 2)
    mbd = tmp_path / "seed.mbd"
    model.export(mbd, t_end=1.0, steps=200, sensitivities=names)
    out = tmp_path / "seed.csv"
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 3 and "dead centre" in r.stderr
    py = tmp_path / "py.csv"
    part.to_csv(py, sensitivities=True)
    assert out.read_text() == py.read_text()


# ----------------------------------------------------------------------------- command line
def test_cli_writes_the_columns_and_the_arrays(tmp_path: Path, capsys) -> None:
    """--sensitivities (comma-separated and repeated) gives the API's table in the CSV and
    the arrays in an .npz; export --sensitivities gives the same file as Model.export."""
    toml = str(EX / "fourbar_masses.toml")
    names = ["joint.B.points.0.0", "body.coupler.mass", "model.gravity.1"]
    res = mbd2d.load(toml).inverse_dynamics(1.0, 10, sensitivities=names)
    out = tmp_path / "cli.csv"
    assert main(["inverse-dynamics", toml, "--t-end", "1", "--steps", "10", "--out", str(out),
                 "--reactions", "--sensitivities", ",".join(names[:2]),
                 "--sensitivities", names[2]]) == 0
    py = tmp_path / "py.csv"
    res.to_csv(py, reactions=True, efforts=True, sensitivities=True)
    assert out.read_text() == py.read_text()
    npz = tmp_path / "cli.npz"
    assert main(["inverse-dynamics", toml, "--t-end", "1", "--steps", "10", "--out", str(npz),
                 "--sensitivities", ",".join(names)]) == 0
    d = np.load(npz)
    assert list(d["parameter_names"]) == names
    for key in ("dq_dp", "dqd_dp", "dqdd_dp", "dlam_dp"):
        np.testing.assert_array_equal(d[key], getattr(res, key))
    cli_mbd, api_mbd = tmp_path / "cli.mbd", tmp_path / "api.mbd"
    assert main(["export", toml, str(cli_mbd), "--analysis", "inverse-dynamics", "--t-end", "1",
                 "--steps", "10", "--sensitivities", ",".join(names)]) == 0
    mbd2d.load(toml).export(api_mbd, t_end=1.0, steps=10, analysis="inverse-dynamics",
                            sensitivities=names)
    assert cli_mbd.read_text() == api_mbd.read_text()


def test_cli_statics_and_parameters(tmp_path: Path, capsys) -> None:
    """statics --sensitivities prints d(x, y, theta)/dp per body and writes the columns;
    `mbd2d parameters` lists every name with its value (the names --sensitivities takes)."""
    toml = str(EX / "pendulum_spring.toml")
    model = mbd2d.load(toml)
    assert main(["parameters", toml]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert [ln.split(" = ")[0] for ln in listed] == list(model.parameters())
    assert float(listed[0].split(" = ")[1]) == list(model.parameters().values())[0]
    assert main(["parameters", toml, "--match", "body.bar"]) == 0
    inertia = model.parameters()["body.bar.inertia"]
    assert capsys.readouterr().out.split() == ["body.bar.mass", "=", "1", "body.bar.inertia",
                                               "=", f"{inertia:.17g}"]
    out = tmp_path / "eq.csv"
    assert main(["statics", toml, "--out", str(out), "--sensitivities", "body.bar.mass"]) == 0
    text = capsys.readouterr().out
    st = model.statics(sensitivities=["body.bar.mass"])
    dx = st.sensitivity("bar", "body.bar.mass")[0]
    assert "d/d(body.bar.mass) bar" in text and f"{dx: .9g}" in text
    header, rows = read_csv(out)
    assert header[-3:] == [f"d(bar.{c})/d(body.bar.mass)" for c in ("x", "y", "theta")]
    np.testing.assert_array_equal(rows[0, -3:], st.dq_dp[:3, 0])


@pytest.mark.parametrize("argv, needle", [
    (["kinematics", "fourbar_grashof.toml", "--sensitivities", "joint.B.point.0.0"],
     "did you mean joint.B.points.0.0"),
    (["kinematics", "fourbar_grashof.toml", "--sensitivities", " , "], "names no parameter"),
    (["kinematics", "fourbar_grashof.toml", "--positions-only", "--sensitivities",
      "joint.B.points.0.0"], "drop positions_only"),
    (["dynamics", "fourbar_masses.toml", "--method", "partitioned",
      "--sensitivities", "body.crank.mass"], "integrated with dopri5"),
    (["dynamics", "cam_liftoff.toml", "--sensitivities", "body.follower.mass"],
     "do not carry contacts"),
    (["export", "fourbar_masses.toml", "X", "--analysis", "dynamics", "--method",
      "baumgarte-rk4", "--h", "1e-3", "--sensitivities", "body.crank.mass"],
     "integrated with dopri5"),
    (["parameters", "fourbar_grashof.toml", "--match", "zzz"], "no design parameter"),
])
def test_cli_refuses_with_a_reason(tmp_path: Path, capsys, argv: list[str],
                                   needle: str) -> None:
    argv = [a if not a.endswith(".toml") else str(EX / a) for a in argv]
    argv = [str(tmp_path / "x.mbd") if a == "X" else a for a in argv]
    if argv[0] in ("kinematics", "dynamics", "export"):
        argv += ["--t-end", "0.5", "--steps", "5"]
    if argv[0] in ("kinematics", "dynamics"):
        argv += ["--out", str(tmp_path / "o.csv")]
    assert main(argv) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert needle in err, err
    assert not (tmp_path / "o.csv").exists() and not (tmp_path / "x.mbd").exists()


def test_results_without_sensitivities_say_so(tmp_path: Path) -> None:
    m = mbd2d.load(EX / "fourbar_masses.toml")
    for res in (m.kinematics(1.0, 4), m.inverse_dynamics(1.0, 4), m.statics()):
        with pytest.raises(mbd2d.ModelError, match="no sensitivities.*--sensitivities"):
            res.table(sensitivities=True)
    with pytest.raises(mbd2d.ModelError, match="no sensitivities"):
        m.kinematics(1.0, 4).to_npz(tmp_path / "k.npz", sensitivities=True)
    assert not (tmp_path / "k.npz").exists()


# ----------------------------------------------------------------------------- the file
def _exported(tmp_path: Path, **kw: Any) -> list[str]:
    mbd = tmp_path / "m.mbd"
    mbd2d.load(EX / "fourbar_masses.toml").export(mbd, t_end=1.0, steps=10,
                                                   sensitivities=["joint.B.points.0.0",
                                                                  "body.crank.mass"], **kw)
    return mbd.read_text().splitlines()


@pytest.mark.parametrize("edit, needle", [
    (("joint.B.points.0.0 1 ", "joint.B.points.0.0 1 9 9"), "NAME TABLE INDEX expected"),
    (("joint.B.points.0.0 1 ", "joint.B.points.0.0 7 1"), "TABLE is 1 (params)"),
    (("joint.B.points.0.0 1 ", "joint.B.points.0.0 1 0"), "INDEX is a whole number"),
    (("joint.B.points.0.0 1 ", "joint.B.points.0.0 1 x"), "INDEX is a whole number"),
    (("joint.B.points.0.0 1 ", "joint.B.points.0.0 1 99999"),
     'sensitivity "joint.B.points.0.0"'),
    (("body.crank.mass 2 ", "body.crank.mass 2 77"), 'sensitivity "body.crank.mass"'),
    (("sensitivities 2", "sensitivities 0"), "count must be at least 1"),
    (("sensitivities 2", "sensitivities 9"), "more sensitivity lines than the file"),
    (("end", "sensitivities 1\nx 1 1\nend"), '"sensitivities" is given twice'),
    (("analysis kinematics", "analysis kinematics\npositions_only 1"), "positions_only 0"),
])
def test_bad_sensitivity_blocks_name_their_line(tmp_path: Path, edit: tuple[str, str],
                                                needle: str) -> None:
    lines = _exported(tmp_path, analysis="kinematics" if "positions" in edit[1]
                      else "inverse-dynamics")
    i = next(k for k, ln in enumerate(lines) if ln.startswith(edit[0]) or ln == edit[0])
    lines[i] = edit[1]
    bad = tmp_path / "bad.mbd"
    bad.write_text("\n".join(lines) + "\n")
    out = tmp_path / "o.csv"
    r = subprocess.run([find_solver(), str(bad), str(out)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr and r.stderr.startswith(f"mbd2d-solve: {bad}:"), r.stderr


def test_file_sensitivities_refused_where_python_refuses(tmp_path: Path) -> None:
    """A hand-made block on a dynamics file whose method has no sensitivities (neither dopri5
    nor generalized-alpha), and on a model with contacts: exit code 2 with the Python path's
    reason."""
    lines = _exported(tmp_path, analysis="dynamics", method="dopri5")
    i = lines.index("method dopri5")
    lines[i] = "method partitioned"
    f = tmp_path / "partitioned.mbd"
    f.write_text("\n".join(lines) + "\n")
    r = subprocess.run([find_solver(), str(f), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "integrated with dopri5" in r.stderr
    cam = mbd2d.load(EX / "cam_liftoff.toml")
    f = tmp_path / "cam.mbd"
    cam.export(f, t_end=0.1, steps=5, analysis="dynamics")
    text = f.read_text().replace("\nend\n", "\nsensitivities 1\nbody.x 2 1\nend\n")
    f.write_text(text)
    r = subprocess.run([find_solver(), str(f), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "do not carry contacts or joint friction" in r.stderr


def test_lookups_of_the_wrong_name_say_what_there_is() -> None:
    """A row label or a parameter that is not there (or not a name) is a KeyError listing
    what there is (multiplier_dp gave a raw ValueError, a number as a parameter name a raw
    TypeError)."""
    m = mbd2d.load(EX / "fourbar_masses.toml")
    inv = m.inverse_dynamics(1.0, 4, sensitivities=["body.coupler.mass"])
    with pytest.raises(KeyError, match="no row 'coupler'; rows: O2.x"):
        inv.multiplier_dp("coupler", "body.coupler.mass")
    with pytest.raises(KeyError, match="by its name .* got 2.5; computed: body.coupler.mass"):
        inv.sensitivity("crank", 2.5)
    assert inv.multiplier_dp("O2.x", "body.coupler.mass").shape == (5,)
