"""The shipped examples run through the API, the plots draw them, and examples/demo.py works."""
from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
COMPLETE = ["fourbar_grashof", "slider_crank", "cam_follower"]
#: closed-form toggle time of the seed four-bar: crank 3, coupler 5, rocker 2.6, ground 6
SEED_TOGGLE = math.acos((9 + 36 - 7.6**2) / 36) - math.pi / 3


def _load(name: str) -> mbd2d.Model:
    return mbd2d.load(EXAMPLES / f"{name}.toml")


@pytest.mark.parametrize("name", COMPLETE)
def test_example_runs_a_full_turn(name: str) -> None:
    res = _load(name).kinematics(t_end=1.0, steps=100)
    assert res.complete
    assert res.q.shape[0] == 101
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.qd))
    assert np.all(np.isfinite(res.qdd))
    # one turn of the driven first body at 1 rev/s brings every body back to its start
    nb = len(res.body_names)
    expected = np.zeros(3 * nb)
    expected[2] = 2 * np.pi
    np.testing.assert_allclose(res.q[-1, :3 * nb] - res.q[0, :3 * nb], expected, atol=1e-9)


def test_seed_fourbar_raises_at_its_toggle() -> None:
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        _load("fourbar_seed").kinematics(t_end=1.0, steps=100)
    err = info.value
    assert err.t == pytest.approx(SEED_TOGGLE, abs=1e-8)
    assert err.driver == "motor"
    res = err.results
    assert res is not None and not res.complete
    assert len(res.t) == 89  # rows t = 0, 0.01, ..., 0.88 precede the toggle
    assert res.t[-1] < err.t


def test_seed_toggle_alias() -> None:
    with pytest.raises(mbd2d.ToggleError):
        _load("fourbar_seed").kinematics(t_end=1.0, steps=20)


# ------------------------------------------------------------------------------ plots
@pytest.mark.parametrize("name", COMPLETE)
def test_plot_mechanism_draws_each_example(name: str) -> None:
    pytest.importorskip("matplotlib")
    from mbd2d.plots import plot_mechanism

    res = _load(name).kinematics(t_end=1.0, steps=36)
    trace = [("coupler", (0.0, 1.0))] if name == "fourbar_grashof" else None
    ax = plot_mechanism(res, trace=trace)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert set(res.body_names) <= set(labels)
    if trace:
        assert any(lab.startswith("path of coupler") for lab in labels)
    assert ax.get_aspect() == 1.0


def test_plot_mechanism_marks_where_an_incomplete_run_stopped() -> None:
    pytest.importorskip("matplotlib")
    from mbd2d.plots import STOP_COLOUR, plot_mechanism

    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        _load("fourbar_seed").kinematics(t_end=1.0, steps=100)
    ax = plot_mechanism(info.value.results, times=[0.0, 0.5])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("last configuration" in lab for lab in labels)
    red = [ln for ln in ax.lines if ln.get_color() == STOP_COLOUR and len(ln.get_xdata())]
    assert red, "the last configuration is drawn in the stop colour"


def test_plot_mechanism_rejects_bad_arguments() -> None:
    pytest.importorskip("matplotlib")
    from mbd2d.plots import plot_mechanism

    res = _load("slider_crank").kinematics(t_end=1.0, steps=10)
    with pytest.raises(ValueError, match="outside"):
        plot_mechanism(res, times=[2.0])
    with pytest.raises(ValueError, match="no body"):
        plot_mechanism(res, trace=[("coupler", (0.0, 1.0))])


def test_plot_timeseries_and_save_figures(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    from mbd2d.plots import plot_timeseries, save_figures

    res = _load("cam_follower").kinematics(t_end=1.0, steps=36)
    fig = plot_timeseries(res, bodies=["follower"])
    assert len(fig.axes) == 9
    with pytest.raises(KeyError):
        plot_timeseries(res, bodies=["nobody"])
    paths = save_figures(res, tmp_path / "sub" / "cam")
    assert [Path(p).name for p in paths] == ["cam_mechanism.png", "cam_timeseries.png"]
    for p in paths:
        assert Path(p).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_import_does_not_need_matplotlib() -> None:
    code = "import sys, mbd2d, mbd2d.plots; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, check=True)
    assert out.stdout.strip() == "False"


# ------------------------------------------------------------------------------ demo
def test_demo_script(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "pngs"
    proc = subprocess.run([sys.executable, str(EXAMPLES / "demo.py"), "--out", str(out),
                           "--no-synthesis"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    pngs = sorted(out.glob("*.png"))
    assert len(pngs) == 20, [p.name for p in pngs]
    for name in ["fourbar_seed", "fourbar_grashof", "slider_crank", "cam_follower"]:
        for kind in ["mechanism", "timeseries"]:
            p = out / f"{name}_{kind}.png"
            assert p.is_file() and p.stat().st_size > 0
    gifs = sorted(p.name for p in out.glob("*.gif"))
    for kind in ["mechanism", "history"]:                      # the lifting cam follower
        assert (out / f"cam_liftoff_{kind}.png").stat().st_size > 0
    assert "Singular configuration" in proc.stdout
    for kind in ["curves", "sensitivity", "tolerance"]:
        assert (out / f"design_study_{kind}.png").stat().st_size > 0
    assert "hit a dead centre" in proc.stdout
    assert "summary: 9/9" in proc.stdout and "GIF animations" in proc.stdout
    for kind in ["mechanism", "program", "base_radius"]:       # the synthesized cam
        assert (out / f"cam_design_{kind}.png").stat().st_size > 0
    # the design study's sweep and a sensitivity run through mbd2d-solve, as Python writes them
    assert "the same file byte for byte (rows, numbers, statuses and messages): True" in \
        proc.stdout
    assert "the same CSV: True" in proc.stdout
    assert gifs == ["cam_design.gif", "cam_liftoff.gif", "fourbar_grashof.gif",
                    "slider_crank.gif", "vibration_modes.gif", "vibration_modes_road.gif"]
    for kind in ["shapes", "damping", "road", "road_damping"]:   # the half car's modes, response
        assert (out / f"vibration_modes_{kind}.png").stat().st_size > 0
    assert "ratio 2.00, second order" in proc.stdout
    assert proc.stdout.count("the driven dynamics settles within") == 3
