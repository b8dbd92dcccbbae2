"""Mechanism measures in sweeps: every case's transmission angle, velocity ratio, mechanical
advantage and distance to a dead centre, from its own dimensions, in the Python sweep, its CSV,
the CLI and mbd2d-solve.

References (no mbd2d numerics): the four-bar's law of cosines for the transmission angle and
Norton's velocity ratio omega4 / omega2 = a sin(th2 - th3) / (c sin(th4 - th3)) at each case's
own link lengths, with the link angles from the two-circle intersection
(tests/test_mechanism_measures.py); swept pivots that move the angle's own points (the
coupler's point of A, the rocker's point of B) so that a recipe taken from the base model
would be wrong. The dead-centre distance falls to zero where the closed-form transmission
angle reaches 0 or pi. mbd2d-solve's CSV is the Python sweep's, byte for byte.
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
SPECS = ["transmission_angle:B", "velocity_ratio:motor:rocker.theta",
         "mechanical_advantage:motor:rocker.theta", "dead_centre_distance"]


@pytest.fixture(scope="module")
def fourbar() -> mbd2d.Model:
    return mbd2d.load(EX / "fourbar_grashof.toml")


def closed_forms(t: np.ndarray, a: float, b: float, c: float, d: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Transmission angle (law of cosines) and omega4 / omega2 (Norton, eq. 6.18)."""
    th2 = W * t
    mu = np.arccos((b * b + c * c - a * a - d * d + 2 * a * d * np.cos(th2)) / (2 * b * c))
    th3, th4 = fourbar_angles(th2, a, b, c, d)
    return mu, a * np.sin(th2 - th3) / (c * np.sin(th4 - th3))


# the example's links: crank O2-A 1.0 (points -0.5, 0.5), coupler A-B 3.5 (-1.75, 1.75),
# rocker B-O4 2.5 (B at -1.25, O4 at 1.25), ground 3.0
@pytest.mark.parametrize("name, values, links", [
    ("joint.A.points.1.0", [-2.0, -1.85, -1.6], lambda v: (1.0, 1.75 - v, 2.5, 3.0)),
    ("joint.B.points.1.0", [-1.4, -1.25, -1.1], lambda v: (1.0, 3.5, 1.25 - v, 3.0)),
    ("joint.O4.points.1.0", [2.8, 3.0, 3.2], lambda v: (1.0, 3.5, 2.5, v)),
])
def test_each_case_against_its_closed_forms(fourbar, name, values, links):
    """The coupler's point of A and the rocker's point of B are points of the angle's own
    recipe: each case's angle is taken at its own points."""
    ds = mbd2d.sweep(fourbar, {name: values}, t_end=1.0, steps=90, measures=SPECS)
    assert ds.measures.dims == ("case", "time", "measure")
    assert list(ds.measure.values) == SPECS and (ds.status.values == 0).all()
    t = ds.time.values
    for c, v in enumerate(values):
        mu, ratio = closed_forms(t, *links(v))
        got = ds.measures.values[c]
        assert_allclose(got[:, 0], mu, atol=1e-10)
        assert_allclose(got[:, 1], ratio, atol=1e-10)
        assert_allclose(got[:, 2], 1 / ratio, rtol=1e-9)
        assert (got[:, 3] > 0).all() and (got[:, 3] <= 1).all()


def test_the_angle_moves_with_the_case_not_the_base(fourbar):
    """A wrong recipe (the base model's point of A on the coupler) would give the base
    model's angle: the swept cases differ from it by the closed form's change."""
    ds = mbd2d.sweep(fourbar, {"joint.A.points.1.0": [-1.75, -2.25]}, t_end=0.5, steps=10,
                     measures="transmission_angle:B")
    t = ds.time.values
    base, _ = closed_forms(t, 1.0, 3.5, 2.5, 3.0)
    long_, _ = closed_forms(t, 1.0, 4.0, 2.5, 3.0)
    assert np.abs(base - long_).max() > 0.05
    assert_allclose(ds.measures.values[0, :, 0], base, atol=1e-10)
    assert_allclose(ds.measures.values[1, :, 0], long_, atol=1e-10)


def test_dead_centre_cases_keep_their_measures_up_to_the_failure(fourbar):
    """Ground lengths past the Grashof range stop at a toggle: the angle there is 0 or pi by
    the law of cosines and the dead-centre distance falls towards zero; the measures of the
    kept rows equal the closed forms and the rows after the failure are NaN."""
    d = np.array([5.8, 3.0, 5.5])
    ds = mbd2d.sweep(fourbar, {"joint.O4.points.1.0": d}, t_end=1.0, steps=400,
                     measures=["transmission_angle:B", "dead_centre_distance"])
    assert ds.status.values[1] == 0 and (ds.status.values[[0, 2]] == 3).all()
    t = ds.time.values
    for c in (0, 2):
        keep = np.isfinite(ds.q.values[c, :, 0])
        n = int(keep.sum())
        assert 1 < n < len(t) and np.isnan(ds.measures.values[c, n:]).all()
        mu, _ = closed_forms(t[:n], 1.0, 3.5, 2.5, d[c])
        assert_allclose(ds.measures.values[c, :n, 0], mu, atol=1e-9)
        edge = np.minimum(mu, np.pi - mu)              # to 0 or pi at the toggle
        assert edge[-1] < 0.1 * edge[0]
        cond = ds.measures.values[c, :n, 1]
        assert cond[-1] < 0.1 * cond[0]


def test_a_quantity_that_stops_moving_fails_its_case_not_the_sweep(fourbar):
    """With no crank (A on the crank at its pivot) the rocker stands still: the ratio to it
    has no value. That case keeps its rows with NaN measures, and its status and message are
    those of the same measure of a run of its own model."""
    name = "joint.A.points.0.0"
    ds = mbd2d.sweep(fourbar, {name: [0.5, -0.5]}, t_end=0.5, steps=10,
                     measures=["transmission_angle:B", "velocity_ratio:motor:rocker.theta"])
    assert ds.status.values[0] == 0 and ds.message.values[0] == ""
    assert ds.status.values[1] < 0
    assert np.isfinite(ds.q.values[1]).all() and np.isnan(ds.measures.values[1]).all()
    res = fourbar.with_params({name: -0.5}).kinematics(t_end=0.5, steps=10)
    with pytest.raises(mbd2d.ModelError) as exc:
        res.velocity_ratio("motor", "rocker.theta")
    assert ds.message.values[1] == str(exc.value)


@pytest.mark.parametrize("kw, match", [
    (dict(measures=["transmission_angle:nowhere"]), "no joint 'nowhere'"),
    (dict(measures=["speed:B"]), "unknown measure"),
    (dict(measures=5), "measures must be a list"),
])
def test_bad_measures_are_model_errors(fourbar, kw, match):
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.sweep(fourbar, {"joint.O4.points.1.0": [3.0]}, t_end=0.1, steps=2, **kw)


def test_no_measures_in_a_statics_sweep():
    m = mbd2d.load(EX / "pendulum_spring.toml")
    with pytest.raises(mbd2d.ModelError, match="not of statics"):
        mbd2d.sweep(m, {"body.bar.mass": [1.0]}, "statics", measures="dead_centre_distance")


def _rows(path: Path) -> list[list[str]]:
    with open(path, newline="") as f:
        return list(csv.reader(f))


def test_csv_columns_and_the_cli(fourbar, tmp_path, capsys):
    """The CSV takes a column per measure after the motion (NaN as empty); the CLI writes the
    same file and prints each measure's range over the cases."""
    cases = {"joint.O4.points.1.0": np.linspace(2.8, 3.2, 3)}
    ds = mbd2d.sweep(fourbar, cases, t_end=1.0, steps=20, measures=SPECS[:2])
    mbd2d.write_sweep(ds, tmp_path / "api.csv")
    rows = _rows(tmp_path / "api.csv")
    assert rows[0][-2:] == SPECS[:2]
    mu = [float(r[-2]) for r in rows[1:] if r[0] == "2"]
    assert_allclose(mu, closed_forms(ds.time.values, 1.0, 3.5, 2.5, 3.2)[0], atol=1e-10)
    code = main(["sweep", str(EX / "fourbar_grashof.toml"), "--param",
                 "joint.O4.points.1.0=2.8:3.2:3", "--t-end", "1", "--steps", "20",
                 "--measure", SPECS[0], "--measure", SPECS[1], "--out",
                 str(tmp_path / "cli.csv")])
    assert code == 0
    assert (tmp_path / "cli.csv").read_bytes() == (tmp_path / "api.csv").read_bytes()
    out = capsys.readouterr().out
    lo = np.nanmin(ds.measures.values[:, :, 0])
    assert f"transmission_angle:B: from {lo:.6g}" in out


def _solve(tmp_path: Path, model: mbd2d.Model, cases: dict, analysis: str, **kw):
    mbd = tmp_path / "s.mbd"
    mbd2d.export_sweep(model, mbd, cases, analysis, **kw)
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=300)
    mbd2d.write_sweep(mbd2d.sweep(model, cases, analysis, workers=1, **kw),
                      tmp_path / "python.csv")
    return r


@pytest.mark.parametrize("build, cases, analysis, kw", [
    (lambda: mbd2d.load(EX / "fourbar_grashof.toml"),
     mbd2d.grid({"joint.A.points.1.0": [-2.0, -1.75], "joint.B.points.1.0": [-1.3, -1.2]}),
     "kinematics", dict(t_end=1.0, steps=30, every=3, measures=SPECS)),
    (lambda: mbd2d.load(EX / "slider_crank.toml"),
     {"joint.guide.points.0.1": [0.3, 0.5], "joint.guide.axes.1.1": [0.0, 0.1]},
     "kinematics", dict(t_end=1.0, steps=20,
                        measures=["transmission_angle:B", "mechanical_advantage:motor:slider.x"])),
    (lambda: mbd2d.load(EX / "fourbar_masses.toml"),
     {"body.coupler.mass": [1.0, 2.0], "joint.B.points.1.0": [-1.25, -1.2]},
     "inverse_dynamics", dict(t_end=0.3, steps=6, measures=SPECS[:2])),
])
def test_mbd2d_solve_writes_the_python_sweep_with_measures(tmp_path, build, cases, analysis,
                                                         kw):
    """The .mbd angle lines name the params entries of their points (the cases set them):
    mbd2d-solve's CSV is the Python sweep's byte for byte."""
    r = _solve(tmp_path, build(), cases, analysis, **kw)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "python.csv").read_bytes()


def test_mbd2d_solve_failed_cases_with_measures(fourbar, tmp_path):
    """Dead centres and a ratio without a value: the same rows, numbers and statuses."""
    cases = {"joint.O4.points.1.0": [2.2, 3.0, 5.5], "joint.A.points.0.0": [0.5, -0.5, 0.5]}
    r = _solve(tmp_path, fourbar, cases, "kinematics", t_end=1.0, steps=50,
               measures=["transmission_angle:B", "velocity_ratio:motor:rocker.theta"])
    assert r.returncode == 0 and "case 1: measure" in r.stderr
    same_but_messages(_rows(tmp_path / "solve.csv"), _rows(tmp_path / "python.csv"))


def test_mbd2d_solve_refuses_a_point_entry_outside_the_params(fourbar, tmp_path):
    mbd = tmp_path / "s.mbd"
    mbd2d.export_sweep(fourbar, mbd, {"joint.O4.points.1.0": [3.0]}, t_end=0.1, steps=2,
                       measures="transmission_angle:B")
    text = mbd.read_text().splitlines()
    k = next(i for i, ln in enumerate(text) if ln.startswith("transmission_angle:B angle"))
    fields = text[k].split()
    for bad, match in ((fields[:-1], "bad measure line"),
                       (fields[:-1] + ["99"], "a point's entry beyond the"),
                       (fields[:-1] + ["-1"], "a point's entry is a whole number")):
        text[k] = " ".join(bad)
        mbd.write_text("\n".join(text) + "\n")
        r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 2 and match in r.stderr, r.stderr
