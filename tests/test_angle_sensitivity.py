"""The transmission angle's exact design derivatives (``res.transmission_angle_dp``) and the
tolerance of transmission angles (``mbd2d.tolerance(..., measures=[...])``,
``mbd2d tolerance --measure``).

References (no mbd2d): the four-bar's law of cosines and the offset slider-crank's
mu = pi/2 - asin(|r sin th - e| / l), differentiated by central differences at two step
sizes (the gap falls as h^2: it is the reference's truncation); and central differences of
ordinary ``with_params`` runs' angles (no sensitivity code). The parameters include the
angle's own points (the output's ground pivot, the coupler's joints), which move the angle
both through the motion and directly.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d.cli import main
from mbd2d.results import read_csv

EX = Path(__file__).resolve().parents[1] / "examples"
W = 2 * np.pi
# crank 1 (O2, A on it at -0.5, 0.5), coupler 3.5 (A at -1.75, B at 1.75), rocker 2.5 (B at
# -1.25, O4 at 1.25), ground 3 (O4 at (3, 0))
FOURBAR = {"joint.O4.points.1.0": lambda e: (1.0, 3.5, 2.5, 3.0 + e),    # the pivot P
           "joint.A.points.1.0": lambda e: (1.0, 3.5 - e, 2.5, 3.0),     # A on the coupler
           "joint.B.points.1.0": lambda e: (1.0, 3.5, 2.5 - e, 3.0),     # B on the rocker
           "joint.A.points.0.0": lambda e: (1.0 + e, 3.5, 2.5, 3.0),     # the crank
           "joint.B.points.0.0": lambda e: (1.0, 3.5 + e, 2.5, 3.0)}     # B on the coupler


def mu_fourbar(t: np.ndarray, a: float, b: float, c: float, d: float) -> np.ndarray:
    """Law of cosines: cos mu = (b^2 + c^2 - a^2 - d^2 + 2 a d cos th2) / (2 b c)."""
    return np.arccos((b * b + c * c - a * a - d * d + 2 * a * d * np.cos(W * t)) / (2 * b * c))


def mu_slider(t: np.ndarray, r: float, l: float, e: float) -> np.ndarray:
    return np.pi / 2 - np.arcsin(np.abs(r * np.sin(W * t) - e) / l)


def central(f, links, t, h):
    return (f(t, *links(h)) - f(t, *links(-h))) / (2 * h)


def test_fourbar_against_the_law_of_cosines():
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    names = list(FOURBAR)
    res = m.kinematics(1.0, 90, sensitivities=names, tol=1e-14)
    d = res.transmission_angle_dp("B")
    assert d.shape == (91, len(names))
    for k, name in enumerate(names):
        e3 = np.abs(d[:, k] - central(mu_fourbar, FOURBAR[name], res.t, 1e-3)).max()
        e4 = np.abs(d[:, k] - central(mu_fourbar, FOURBAR[name], res.t, 1e-4)).max()
        assert e4 < 1e-8 and e4 < e3 / 50, (name, e3, e4)      # the reference's h^2


def test_slider_crank_sliding_angle():
    """r = 1 (A on the crank), l = 3 (A on the rod), e = 0.5 (the guide's point on ground);
    the slider's own axis turns the slider with it: the angle does not change."""
    m = mbd2d.load(EX / "slider_crank.toml")
    links = {"joint.guide.points.0.1": lambda s: (1.0, 3.0, 0.5 + s),
             "joint.A.points.1.0": lambda s: (1.0, 3.0 - s, 0.5),
             "joint.A.points.0.0": lambda s: (1.0 + s, 3.0, 0.5)}
    names = list(links) + ["joint.guide.axes.1.1"]
    res = m.kinematics(1.0, 90, sensitivities=names, tol=1e-14)
    d = res.transmission_angle_dp("B")
    for k, name in enumerate(links):
        assert_allclose(d[:, k], central(mu_slider, links[name], res.t, 1e-5), atol=1e-9)
    assert np.abs(d[:, 3]).max() < 1e-12


def test_against_ordinary_runs():
    """Central differences of the angles of with_params runs (no sensitivity code)."""
    m = mbd2d.load(EX / "fourbar_masses.toml")
    name, h = "joint.O4.points.1.0", 1e-5
    res = m.inverse_dynamics(0.5, 20, sensitivities=[name], tol=1e-14)
    p0 = m.parameters()[name]
    hi, lo = (m.with_params({name: p0 + s * h}).inverse_dynamics(0.5, 20, tol=1e-14)
              for s in (1, -1))
    fd = (hi.transmission_angle("B") - lo.transmission_angle("B")) / (2 * h)
    assert_allclose(res.transmission_angle_dp("B")[:, 0], fd, atol=1e-8)


def test_tolerance_of_the_transmission_angle():
    """First order: |dmu/dp| sigma from the law of cosines; Monte Carlo within its error."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    name, sigma, n = "joint.O4.points.1.0", 2e-3, 400
    tol = mbd2d.tolerance(m, {name: sigma}, samples=n, t_end=1.0, steps=36, workers=1,
                          measures=["transmission_angle:B"])
    ds = tol.dataset
    assert ds.measures.dims == ("time", "measure")
    t = ds.time.values
    assert_allclose(ds.measures.values[:, 0], mu_fourbar(t, 1.0, 3.5, 2.5, 3.0), atol=1e-11)
    lin = np.abs(central(mu_fourbar, FOURBAR[name], t, 1e-4)) * sigma
    assert_allclose(ds.measures_std_linear.values[:, 0], lin, rtol=1e-6)
    ratio = ds.measures_std_mc.values[:, 0] / ds.measures_std_linear.values[:, 0]
    assert np.abs(ratio - 1).max() < 5 / np.sqrt(2 * (n - 1))


@pytest.mark.parametrize("kw, match", [
    (dict(measures=["velocity_ratio:motor"]), "unknown measure"),
    (dict(measures=["velocity_ratio:motor:nothing"]), "no driver or coordinate"),
    (dict(measures=["transmission_angle:nowhere"]), "no joint"),
    (dict(measures=5), "measures must be a list"),
])
def test_tolerance_refuses_bad_measures(kw, match):
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.tolerance(m, {"joint.O4.points.1.0": 1e-3}, samples=0, t_end=1.0, steps=4, **kw)


def test_no_sensitivities_no_derivative():
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(1.0, 4)
    with pytest.raises(mbd2d.ModelError, match="no sensitivities"):
        res.transmission_angle_dp("B")


def test_cli_columns(tmp_path, capsys):
    out = tmp_path / "tol.csv"
    code = main(["tolerance", str(EX / "fourbar_grashof.toml"), "--sigma",
                 "joint.O4.points.1.0=1e-3", "--samples", "0", "--t-end", "1", "--steps", "12",
                 "--measure", "transmission_angle:B", "--out", str(out)])
    assert code == 0
    assert "measures, largest first-order standard deviation (angles in deg)" in \
        capsys.readouterr().out
    header, rows = read_csv(out)
    k = header.index("transmission_angle:B.std_linear")
    t = rows[:, header.index("t")]
    lin = np.abs(central(mu_fourbar, FOURBAR["joint.O4.points.1.0"], t, 1e-4)) * 1e-3
    assert_allclose(rows[:, k], lin, rtol=1e-6)


@pytest.mark.parametrize("model, cmd, extra", [
    ("fourbar_grashof.toml", "kinematics", []),
    ("fourbar_masses.toml", "inverse-dynamics", ["--efforts", "--reactions"]),
])
def test_table_columns_and_mbd2d_solve(tmp_path, model, cmd, extra):
    """The tables take d(transmission_angle:B)/d(P) after each parameter's other columns
    (the closed form's derivative); mbd2d-solve writes the same file byte for byte."""
    from test_standalone import find_solver
    import subprocess
    names = ["joint.O4.points.1.0", "joint.A.points.1.0"]
    args = [str(EX / model), "--t-end", "1", "--steps", "24", "--sensitivities",
            ",".join(names), "--measure", "transmission_angle:B", "--measure",
            "velocity_ratio:motor:rocker.theta"] + extra
    assert main([cmd] + args + ["--out", str(tmp_path / "py.csv")]) == 0
    exp = [str(EX / model), str(tmp_path / "m.mbd")] + args[1:]
    assert main(["export", "--analysis", cmd] + exp) == 0
    r = subprocess.run([find_solver(), str(tmp_path / "m.mbd"), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
    header, rows = read_csv(tmp_path / "py.csv")
    t = rows[:, header.index("t")]
    from test_measure_sensitivity import ratio_fourbar
    for name in names:
        got = rows[:, header.index(f"d(transmission_angle:B)/d({name})")]
        assert_allclose(got, central(mu_fourbar, FOURBAR[name], t, 1e-4), atol=1e-8)
        got = rows[:, header.index(f"d(velocity_ratio:motor:rocker.theta)/d({name})")]
        assert_allclose(got, central(ratio_fourbar, FOURBAR[name], t, 1e-4), atol=1e-8)


def test_npz_carries_the_derivatives(tmp_path):
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    names = ["joint.O4.points.1.0", "joint.B.points.1.0"]
    res = m.kinematics(1.0, 24, sensitivities=names, tol=1e-14)
    res.to_npz(tmp_path / "r.npz", measures=["transmission_angle:B", "dead_centre_distance"])
    with np.load(tmp_path / "r.npz") as z:
        assert list(z["dmeasure_names"]) == ["transmission_angle:B", "dead_centre_distance"]
        assert z["dmeasures_dp"].shape == (25, 2, 2)
        assert_allclose(z["dmeasures_dp"][:, 1, :], res.dead_centre_distance_dp())
        for k, name in enumerate(names):
            assert_allclose(z["dmeasures_dp"][:, 0, k],
                            central(mu_fourbar, FOURBAR[name], res.t, 1e-4), atol=1e-8)
