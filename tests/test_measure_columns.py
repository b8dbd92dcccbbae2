"""Mechanism measures as result columns in every front door: ``res.to_csv(measures=[...])``,
``mbd2d kinematics ... --measure SPEC`` and mbd2d-solve's ``measures`` block.

Independent references: the four-bar's transmission angle in closed form, cos mu =
(b^2 + c^2 - a^2 - d^2 + 2 a d cos theta2) / (2 b c) (Norton, ch. 4), from the crank angle
column; the velocity ratio and mechanical advantage against the ratio of the run's own
angular velocities (the velocity solution J q_dot = nu, not the influence coefficients). The standalone's CSV
is compared with the Python one as text.
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.cli import main
from mbd2d.results import read_csv

from test_standalone import find_solver

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
FOURBAR = ["transmission_angle:B", "velocity_ratio:motor:rocker.theta",
           "mechanical_advantage:motor:rocker.theta", "dead_centre_distance",
           "velocity_ratio:crank.theta:coupler.theta"]


def _solve(tmp_path: Path, mbd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([find_solver(), str(mbd), str(tmp_path / "solve.csv")],
                          capture_output=True, text=True, timeout=120)


def test_fourbar_columns_against_closed_forms(tmp_path: Path, capsys) -> None:
    toml = EX / "fourbar_grashof.toml"
    out = tmp_path / "cli.csv"
    argv = ["kinematics", str(toml), "--t-end", "1", "--steps", "72", "--out", str(out)]
    for m in FOURBAR:
        argv += ["--measure", m]
    assert main(argv) == 0
    header, rows = read_csv(out)
    col = {h: rows[:, k] for k, h in enumerate(header)}
    model = mbd2d.load(toml)
    prm = model.parameters()
    pt = lambda j, k: np.array([prm[f"joint.{j}.points.{k}.0"],  # noqa: E731
                                prm[f"joint.{j}.points.{k}.1"]])
    a = np.linalg.norm(pt("A", 0) - pt("O2", 1))      # crank: O2 -> A on the crank
    b = np.linalg.norm(pt("B", 0) - pt("A", 1))       # coupler: A -> B on the coupler
    c = np.linalg.norm(pt("B", 1) - pt("O4", 0))      # rocker: B -> O4 on the rocker
    d = np.linalg.norm(pt("O4", 1) - pt("O2", 0))     # ground
    th2 = col["crank.theta"]
    cos_mu = (b**2 + c**2 - a**2 - d**2 + 2 * a * d * np.cos(th2)) / (2 * b * c)
    np.testing.assert_allclose(col["transmission_angle:B"], np.arccos(cos_mu), rtol=0,
                               atol=1e-11)
    np.testing.assert_allclose(col["velocity_ratio:motor:rocker.theta"],
                               col["rocker.theta_dot"] / col["crank.theta_dot"], rtol=1e-10)
    np.testing.assert_allclose(col["mechanical_advantage:motor:rocker.theta"],
                               col["crank.theta_dot"] / col["rocker.theta_dot"], rtol=1e-10)
    np.testing.assert_allclose(col["velocity_ratio:crank.theta:coupler.theta"],
                               col["coupler.theta_dot"] / col["crank.theta_dot"], rtol=1e-10)
    assert ((col["dead_centre_distance"] > 0) & (col["dead_centre_distance"] <= 1)).all()
    # the API's file is the command's, and the .npz holds the same numbers
    res = model.kinematics(1.0, 72)
    py = tmp_path / "py.csv"
    res.to_csv(py, measures=FOURBAR)
    assert py.read_text() == out.read_text()
    npz = tmp_path / "m.npz"
    res.to_npz(npz, measures=FOURBAR)
    z = np.load(npz)
    assert list(z["measure_names"]) == FOURBAR
    np.testing.assert_array_equal(z["measures"], rows[:, -len(FOURBAR):])


@pytest.mark.parametrize("name, run, specs, export", [
    ("fourbar_grashof", lambda m: m.kinematics(1.0, 40), FOURBAR,
     dict(t_end=1.0, steps=40)),
    ("slider_crank", lambda m: m.kinematics(0.5, 40, every=3),
     ["transmission_angle:B", "mechanical_advantage:motor:slider.x", "dead_centre_distance"],
     dict(t_end=0.5, steps=40, every=3)),
    ("fourbar_masses", lambda m: m.inverse_dynamics(1.0, 20), FOURBAR[:4],
     dict(t_end=1.0, steps=20, analysis="inverse-dynamics", outputs=["efforts"])),
    ("fourbar_masses", lambda m: m.dynamics(0.3, 6, method="generalized-alpha", h=1e-3),
     FOURBAR[:4], dict(t_end=0.3, steps=6, analysis="dynamics", method="generalized-alpha",
                       h=1e-3)),
])
def test_mbd2d_solve_writes_the_python_columns(tmp_path: Path, name: str, run, specs,
                                              export: dict) -> None:
    model = mbd2d.load(EX / f"{name}.toml")
    mbd = tmp_path / "m.mbd"
    model.export(mbd, measures=specs, **export)
    r = _solve(tmp_path, mbd)
    assert r.returncode == 0, r.stderr
    py = tmp_path / "py.csv"
    run(model).to_csv(py, measures=specs, **{k: True for k in export.get("outputs", [])})
    assert (tmp_path / "solve.csv").read_text() == py.read_text()


def test_partial_run_to_the_dead_centre(tmp_path: Path) -> None:
    """The seed four-bar's rows up to its toggle: the ratios grow without bound there and
    the dead-centre distance falls; both paths write the same file (exit code 3)."""
    model = mbd2d.load(EX / "fourbar_seed.toml")
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        model.kinematics(1.0, 200)
    mbd = tmp_path / "seed.mbd"
    model.export(mbd, t_end=1.0, steps=200, measures=FOURBAR[:4])
    r = _solve(tmp_path, mbd)
    assert r.returncode == 3
    py = tmp_path / "py.csv"
    info.value.results.to_csv(py, measures=FOURBAR[:4])
    assert (tmp_path / "solve.csv").read_text() == py.read_text()
    header, rows = read_csv(py)
    dc = rows[:, header.index("dead_centre_distance")]
    assert dc[-1] < 0.05 * dc[0]


def _wheel() -> mbd2d.Model:
    """A wheel turning about its centre: its x and y do not move with the motor."""
    m = mbd2d.Model("wheel")
    m.add_body("wheel", (0.0, 0.0, 0.0))
    m.add_revolute(["ground", "wheel"], [[0.0, 0.0], [0.0, 0.0]], name="axle")
    m.add_driver("absolute", body="wheel", coordinate="theta", f={"poly": [0.0, 1.0]},
                 name="motor")
    return m


def test_a_quantity_that_does_not_move_is_refused_alike(tmp_path: Path) -> None:
    m = _wheel()
    res = m.kinematics(1.0, 4)
    with pytest.raises(mbd2d.ModelError, match="does not move with the driver"):
        res.table(measures=["velocity_ratio:motor:wheel.x"])
    mbd = tmp_path / "w.mbd"
    m.export(mbd, t_end=1.0, steps=4, measures=["velocity_ratio:motor:wheel.x"])
    r = _solve(tmp_path, mbd)
    assert r.returncode == 2 and "does not move with the driver" in r.stderr
    assert not (tmp_path / "solve.csv").exists()


@pytest.mark.parametrize("spec, needle", [
    ("transmission_angle", "unknown measure"),
    ("transmission_angle:B:crank:x", "unknown measure"),
    ("velocity_ratio:motor", "unknown measure"),
    ("speed:motor:rocker.theta", "unknown measure"),
    ("transmission_angle:Q", "no joint 'Q'"),
    ("transmission_angle:O2", "joins 'crank' to ground"),
    ("velocity_ratio:motor:rocker.phi", "no driver or coordinate 'rocker.phi'"),
])
def test_bad_specs_are_model_errors(tmp_path: Path, capsys, spec: str, needle: str) -> None:
    model = mbd2d.load(EX / "fourbar_grashof.toml")
    res = model.kinematics(1.0, 4)
    with pytest.raises(mbd2d.ModelError) as err:
        res.table(measures=[spec])
    assert needle in str(err.value)
    with pytest.raises(mbd2d.ModelError):
        model.export(tmp_path / "m.mbd", t_end=1.0, steps=4, measures=[spec])
    out = tmp_path / "o.csv"
    assert main(["kinematics", str(EX / "fourbar_grashof.toml"), "--t-end", "1", "--steps",
                 "4", "--out", str(out), "--measure", spec]) == 2
    assert needle in " ".join(capsys.readouterr().err.split())
    assert not out.exists()


def test_statics_files_take_no_measures(tmp_path: Path) -> None:
    with pytest.raises(mbd2d.ModelError, match="not of statics"):
        mbd2d.load(EX / "pendulum_spring.toml").export(tmp_path / "s.mbd", analysis="statics",
                                                       measures=["dead_centre_distance"])


@pytest.mark.parametrize("edit, needle", [
    (("transmission_angle:B angle 1 3", "transmission_angle:B angle 7 3"), "KIND is 1"),
    (("transmission_angle:B angle 1 3", "transmission_angle:B angle 1 9"),
     "a body number beyond the 3 bodies"),
    (("transmission_angle:B angle 1 3", "transmission_angle:B angle 1 -3"), "from 0 (ground)"),
    (("velocity_ratio:motor:rocker.theta ratio 9", "velocity_ratio:motor:rocker.theta ratio 99"),
     "a row or coordinate beyond the model"),
    (("velocity_ratio:motor:rocker.theta ratio 9", "velocity_ratio:motor:rocker.theta ratio 9 3"),
     "REF XKIND XINDEX YKIND YINDEX expected"),
    (("dead_centre_distance conditioning", "dead_centre_distance conditioning 1"),
     "SPEC conditioning expected"),
    (("dead_centre_distance conditioning", "dead_centre_distance speed"), "unknown measure"),
    (("measures 3", "measures 0"), "count must be at least 1"),
])
def test_bad_measure_lines_name_their_line(tmp_path: Path, edit: tuple[str, str],
                                           needle: str) -> None:
    mbd = tmp_path / "m.mbd"
    mbd2d.load(EX / "fourbar_grashof.toml").export(mbd, t_end=1.0, steps=4,
                                                   measures=FOURBAR[:2] + FOURBAR[3:4])
    lines = mbd.read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith(edit[0]))
    lines[i] = lines[i].replace(edit[0], edit[1], 1)
    mbd.write_text("\n".join(lines) + "\n")
    r = _solve(tmp_path, mbd)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr and r.stderr.startswith(f"mbd2d-solve: {mbd}:"), r.stderr


@pytest.mark.parametrize("analysis", ["inverse-dynamics", "dynamics"])
def test_every_column_group_together(tmp_path: Path, analysis: str) -> None:
    """Energy, multipliers, reactions, efforts, measures and sensitivities in one file, in
    the Python table's order: mbd2d-solve writes the same text."""
    outputs = ["energy", "multipliers", "reactions", "efforts"]
    specs = ["transmission_angle:B", "velocity_ratio:motor:rocker.theta", "dead_centre_distance"]
    if analysis == "inverse-dynamics":
        model, names = mbd2d.load(EX / "fourbar_masses.toml"), ["joint.B.points.0.0",
                                                                "body.coupler.mass"]
        res = model.inverse_dynamics(1.0, 20, every=3, sensitivities=names)
        kw = dict(t_end=1.0, steps=20, every=3)
    else:
        import sys
        sys.path.insert(0, str(EX))
        import free_fourbar
        model, names, specs = free_fourbar.build(), ["body.coupler.mass"], [specs[0], specs[2]]
        res = model.dynamics(0.5, 10, method="dopri5", sensitivities=names)
        kw = dict(t_end=0.5, steps=10, method="dopri5")
    mbd = tmp_path / "all.mbd"
    model.export(mbd, analysis=analysis, outputs=outputs, measures=specs, sensitivities=names,
                 **kw)
    r = _solve(tmp_path, mbd)
    assert r.returncode == 0, r.stderr
    py = tmp_path / "py.csv"
    res.to_csv(py, sensitivities=True, measures=specs, **{k: True for k in outputs})
    assert (tmp_path / "solve.csv").read_text() == py.read_text()


@pytest.mark.parametrize("bad", [5, 3.0, object()])
def test_measures_that_are_not_a_list_are_model_errors(tmp_path: Path, bad) -> None:
    model = mbd2d.load(EX / "fourbar_grashof.toml")
    res = model.kinematics(1.0, 4)
    for call in (lambda: res.to_csv(tmp_path / "m.csv", measures=bad),
                 lambda: res.to_npz(tmp_path / "m.npz", measures=bad),
                 lambda: model.export(tmp_path / "m.mbd", t_end=1.0, steps=4, measures=bad)):
        with pytest.raises(mbd2d.ModelError, match="measures must be a list of specs"):
            call()
    assert not list(tmp_path.iterdir())
