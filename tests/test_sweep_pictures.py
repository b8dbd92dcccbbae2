"""The picture of a sweep's family (``mbd2d.plot_sweep``, ``mbd2d sweep --plot``): what is drawn
is the sweep's own values, and each crank-rocker's worst transmission angle on the summary is
the law of cosines at the crank's two positions along the ground line (Norton, ch. 4),
computed here without mbd2d. Failed cases are drawn up to where they stopped and marked."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d.cli import main
from mbd2d.plots.canvas import STOP_COLOUR

pytest.importorskip("xarray")
pytest.importorskip("matplotlib")

EX = Path(__file__).resolve().parents[1] / "examples"
GROUND = "joint.O4.points.1.0"
SPECS = ["transmission_angle:B", "velocity_ratio:motor:rocker.theta"]


def worst_angle(d: np.ndarray, a: float = 1.0, b: float = 3.5, c: float = 2.5) -> np.ndarray:
    """The crank-rocker's worst transmission angle [deg]: mu is extreme with the crank along
    the ground line, cos mu = (b^2 + c^2 - (d -+ a)^2) / (2 b c)."""
    lo = np.degrees(np.arccos((b * b + c * c - (d - a) ** 2) / (2 * b * c)))
    hi = np.degrees(np.arccos((b * b + c * c - (d + a) ** 2) / (2 * b * c)))
    return np.minimum(lo, 180.0 - hi)


@pytest.fixture(scope="module")
def family():
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    d = np.linspace(2.2, 5.8, 13)
    ds = mbd2d.sweep(m, {GROUND: d}, t_end=1.0, steps=120, measures=SPECS)
    return d, ds


def test_drawn_values_and_the_law_of_cosines(family):
    d, ds = family
    fig = mbd2d.plot_sweep(ds)
    axes = fig.axes
    curves, summary = axes[0], axes[1]            # the first row: the transmission angle
    ok = ds.status.values == 0
    assert ok.sum() >= 5 and (~ok).sum() >= 2     # Grashof and non-Grashof variants
    drawn = [ln for ln in curves.get_lines() if len(ln.get_xdata()) > 2]
    mu = np.degrees(ds.measures.sel(measure=SPECS[0]).values)
    order = np.argsort(d, kind="stable")
    for ln, j in zip(drawn, order):               # one curve per case, in parameter order
        keep = np.isfinite(mu[j])
        assert_allclose(ln.get_ydata(), mu[j][keep], rtol=0, atol=0)
    pts = summary.get_lines()[0]                  # each completed case's worst angle
    assert_allclose(pts.get_xdata(), d[ok])
    assert_allclose(pts.get_ydata(), worst_angle(d[ok]), atol=1e-8)
    # failed cases: red, an x where each stopped
    marks = [ln for ln in curves.get_lines() if ln.get_marker() == "x"]
    assert len(marks) == (~ok).sum() and all(ln.get_color() == STOP_COLOUR for ln in marks)
    for ln, j in zip(marks, [j for j in order if not ok[j]]):
        last = np.flatnonzero(np.isfinite(mu[j]))[-1]
        assert ln.get_xdata()[0] == ds.time.values[last] and ln.get_ydata()[0] == mu[j][last]
    # the ratio's row: least and greatest over each completed case's rows
    ratio = ds.measures.sel(measure=SPECS[1]).values
    greatest, least = axes[3].get_lines()[:2]       # (the second row's summary)
    assert_allclose(greatest.get_ydata(), np.nanmax(ratio[ok], axis=1))
    assert_allclose(least.get_ydata(), np.nanmin(ratio[ok], axis=1))


def test_coordinates_and_the_parameter_axis(family):
    d, ds = family
    fig = mbd2d.plot_sweep(ds, measures=[], coordinates=["rocker.theta"])
    q = ds.q.sel(coordinate="rocker.theta").values
    ok = ds.status.values == 0
    greatest = fig.axes[1].get_lines()[0]
    assert_allclose(greatest.get_ydata(), np.nanmax(q[ok], axis=1))
    assert fig.axes[1].get_xlabel() == GROUND


@pytest.mark.parametrize("kw, match", [
    (dict(measures=["dead_centre_distance"]), "no measure 'dead_centre_distance'"),
    (dict(coordinates=["rocker.phi"]), "no coordinate"),
    (dict(parameter="joint.B.points.0.0"), "is not swept"),
    (dict(measures=[]), "nothing to draw"),
])
def test_bad_requests_are_model_errors(family, kw, match):
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.plot_sweep(family[1], **kw)


def test_not_a_sweep_over_time():
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    with pytest.raises(mbd2d.ModelError, match="Dataset of mbd2d.sweep"):
        mbd2d.plot_sweep(m.kinematics(t_end=0.1, steps=2))
    st = mbd2d.sweep(mbd2d.load(EX / "pendulum_spring.toml"), {"body.bar.mass": [1.0, 2.0]},
                     "statics")
    with pytest.raises(mbd2d.ModelError, match="not statics"):
        mbd2d.plot_sweep(st, coordinates=["bar.theta"])


def test_cli_plot(tmp_path, capsys):
    out = tmp_path / "fam.png"
    args = ["sweep", str(EX / "fourbar_grashof.toml"), "--param", f"{GROUND}=2.5:3.5:5",
            "--t-end", "1", "--steps", "30", "--out", str(tmp_path / "s.csv")]
    assert main(args + ["--measure", SPECS[0], "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(args + ["--plot", str(out)]) == 2
    assert "--plot draws the sweep's measures" in capsys.readouterr().err
