"""Pictures and animations: every element kind has its drawer, the drawn configuration is the
computed one (closed form of the slider-crank), animations are written as GIF (and MP4
through ffmpeg's pipe), notebooks get PNG and HTML, time axes mark dead centres and singular
passages, and the command line draws every analysis. Images are small and runs short."""
from __future__ import annotations

import base64
import io
import math
import os
import stat
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d import ModelError
from mbd2d.description import joints as J
from mbd2d.description.forces import FORCE_KEYS, PointForce, RotationalSpring, Spring, Torque
from mbd2d.plots import elements, plot_mechanism, plot_paths, plot_timeseries
from mbd2d.plots.animation import render_frames
from mbd2d.plots.canvas import PASSAGE_COLOUR, STOP_COLOUR, new_figure
from mbd2d.plots.elements import Look
from mbd2d.plots.scene import Scene

PIL = pytest.importorskip("PIL.Image")
ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
W = 2 * np.pi
SMALL = {"size": (2.0, 1.6), "dpi": 40}
PNG = b"\x89PNG\r\n\x1a\n"


def image(src: Path | bytes) -> tuple[int, tuple[int, int], dict]:
    """(frames, size, info) of an image file or bytes, the file closed again."""
    with PIL.open(io.BytesIO(src) if isinstance(src, bytes) else src) as im:
        return getattr(im, "n_frames", 1), im.size, dict(im.info)


@pytest.fixture(scope="module")
def slider() -> mbd2d.KinematicsResult:
    return mbd2d.load(EX / "slider_crank.toml").kinematics(t_end=1.0, steps=40)


@pytest.fixture(scope="module")
def masses() -> mbd2d.DynamicsResult:
    return mbd2d.load(EX / "fourbar_masses.toml").kinematics(t_end=1.0, steps=40)


# ----------------------------------------------------------------------------- drawers
JOINT_CLASSES = [J.Revolute, J.Translational, J.Cam, J.PointOnCurve, J.Distance,
                 J.PointOnLine, J.PinInSlot, J.Weld, J.Gear, J.RackPinion, J.RollingDisc,
                 J.Absolute]


def test_every_joint_and_force_kind_has_a_drawer():
    """Each TOML joint type and force type maps to a class with its own drawer."""
    types = {c.type for c in JOINT_CLASSES}
    assert types == set(J.joint_keys())
    for cls in JOINT_CLASSES + [Spring, RotationalSpring, Torque, PointForce]:
        assert elements.drawer_for(cls.__new__(cls)) is not None, cls
    assert {c.type for c in (Spring, RotationalSpring, Torque, PointForce)} == set(FORCE_KEYS)
    # the most specific drawer wins for subclasses
    assert elements.drawer_for(J.PinInSlot.__new__(J.PinInSlot)) is elements.SlotDrawer
    assert elements.drawer_for(J.RollingDisc.__new__(J.RollingDisc)) is elements.RackDrawer


def test_drawn_configuration_is_the_closed_form(slider):
    """The artists moved to a row sit where the closed form puts the bodies: the slider
    block's centre at x = cos th + sqrt(9 - (sin th - 0.5)^2), y = 0.5, the crank pin
    A on the unit circle."""
    scene = Scene(slider)
    ax = new_figure((2, 2)).add_subplot()
    update = scene.make(ax, Look(scene.colour, label=True))
    block = next(p for p in ax.patches if p.get_label() == "slider")
    pin = ax.lines[[ln.get_marker() for ln in ax.lines].index("o")]
    for k in (0, 7, 23, 40):
        update(k)
        th = W * slider.t[k]
        xy = np.asarray(block.get_xy())[:-1].mean(axis=0)
        assert_allclose(xy, [np.cos(th) + np.sqrt(9 - (np.sin(th) - 0.5)**2), 0.5],
                        atol=1e-12)
        assert_allclose([pin.get_xdata()[0], pin.get_ydata()[0]], [0.0, 0.0], atol=1e-13)
    a = scene.full.place("crank", (0.5, 0.0))
    assert_allclose(np.hypot(a[:, 0], a[:, 1]), 1.0, atol=1e-12)


def test_snapshots_paths_and_labels(slider, masses):
    ax = plot_mechanism(slider, times=[0.0, 0.5], length_unit="mm")
    assert ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "y [mm]"
    labels = {t.get_text() for t in ax.get_legend().get_texts()}
    assert {"crank", "rod", "slider"} <= labels
    ax = plot_paths(masses)
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("path of coupler") for t in texts)      # the moving pins A, B
    ax = plot_mechanism(masses, forces=True, snapshots=2)
    arrows = [p for p in ax.patches if type(p).__name__ == "FancyArrowPatch"]
    assert len(arrows) == 2 * 4                                      # 4 joints x 2 snapshots
    with pytest.raises(ModelError, match="multipliers"):
        plot_mechanism(slider, forces=True)
    with pytest.raises(ModelError, match="snapshots"):
        plot_mechanism(slider, snapshots=0)


def test_a_long_chain_is_drawn_at_its_links_proportions(tmp_path):
    """The 60-loop parallelogram chain (121 bodies, 60 m long, 1 m links): its details
    (pins, hatching) are sized from ten typical bodies, not from the whole picture (a pin
    was a fifth of the chain's height), and no legend of 121 names runs off the figure (it
    collapsed the layout: matplotlib warned); the four-bar's pictures are as before (its
    bodies are larger than a tenth of the picture) and keep their legend."""
    sys.path.insert(0, str(EX))
    import nfourbar
    res = nfourbar.build(60).kinematics(0.5, 5)
    assert Scene(res, None, False).scale == pytest.approx(10.0)      # ten 1 m links
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ax = plot_mechanism(res, snapshots=2)
        assert ax.get_legend() is None
        res.animate(tmp_path / "chain.gif", fps=4, **SMALL)
    grashof = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(1.0, 10)
    sc = Scene(grashof, None, False)
    pts = np.vstack([sc.full.place(b, s) for b, ss in sc.attach.items() for s in ss]
                    + [np.array([s]) for j in grashof.model.joints
                       for b, s in zip(j.bodies, j.points) if b == "ground"])
    assert sc.scale == pytest.approx(max(np.ptp(pts[:, 0]), np.ptp(pts[:, 1])))
    assert plot_mechanism(grashof).get_legend() is not None


def _pins(ax) -> np.ndarray:
    """The centres of the white pin marks on the Axes (every Line2D of them), sorted."""
    pts = [np.column_stack(ln.get_data()) for ln in ax.get_lines()
           if ln.get_marker() == "o" and ln.get_markerfacecolor() == "white"]
    pts = np.vstack(pts)
    pts = pts[np.isfinite(pts).all(axis=1)]
    return pts[np.lexsort((pts[:, 1], pts[:, 0]))]


def test_a_large_scene_draws_one_artist_per_look(monkeypatch):
    """The 40-loop chain's 201 elements draw as a few dozen artists (about 4,500 before: a
    picture of a 1000-loop chain took 38 s, now 3 s); the pins are where the closed form
    puts them (ground pivots at (k, 0), crank tips at (k + cos th, sin th), th = pi/2 - t)
    and the picture differs from the one drawn artist by artist in under 1 % of its pixels
    (the stacking of overlapping pins); the reactions' arrows start at the same places and
    point along the reactions; torques and traces still draw."""
    sys.path.insert(0, str(EX))
    import nfourbar
    import mbd2d.plots.scene as scene_module
    n = 40
    res = nfourbar.build(n).kinematics(0.5, 5)
    ax = plot_mechanism(res, times=[0.3], snapshots=1)
    assert len(ax.get_children()) < 60
    th = np.pi / 2 - 0.3
    ref = np.vstack([[(k, 0.0) for k in range(n + 1)],
                     [(k + np.cos(th), np.sin(th)) for k in range(n)],
                     [(k + 1 + np.cos(th), np.sin(th)) for k in range(n)]])
    ref = ref[np.lexsort((ref[:, 1], ref[:, 0]))]
    np.testing.assert_allclose(_pins(ax), ref, atol=1e-9)

    def pixels(ax) -> np.ndarray:
        ax.figure.canvas.draw()
        return np.asarray(ax.figure.canvas.buffer_rgba())[:, :, :3].copy()
    batched = [pixels(plot_mechanism(res, snapshots=3)), *render_frames(res, fps=4)]
    monkeypatch.setattr(scene_module, "BATCH_MIN", 10**9)
    alone = plot_mechanism(res, times=[0.3], snapshots=1)
    assert len(alone.get_children()) > 10 * n
    np.testing.assert_allclose(_pins(alone), ref, atol=1e-9)
    singly = [pixels(plot_mechanism(res, snapshots=3)), *render_frames(res, fps=4)]
    for a, b in zip(batched, singly):
        assert a.shape == b.shape and np.any(a != b, axis=2).mean() < 0.01
    monkeypatch.undo()
    m = nfourbar.build(n, True, 0.0)                                 # with masses
    m.add_torque("crank3", f={"poly": [1.0]}, name="push")
    inv = m.inverse_dynamics(0.5, 5)
    ax = plot_mechanism(inv, forces=True, times=[0.3], trace=[("coupler0", (0.0, 0.0))])
    quivers = [c for c in ax.collections if type(c).__name__ == "Quiver"]
    tails = np.vstack([q.get_offsets() for q in quivers])          # the reactions' arrows
    np.testing.assert_allclose(tails[np.lexsort((tails[:, 1], tails[:, 0]))], ref, atol=1e-9)
    row = int(np.argmin(np.abs(inv.t - 0.3)))
    force = inv.reaction("O3")
    u, v = quivers[0].U, quivers[0].V
    k = int(np.argmin(np.hypot(*(quivers[0].get_offsets() - [3.0, 0.0]).T)))
    assert u[k] * force.fy[row] == pytest.approx(v[k] * force.fx[row], rel=1e-9, abs=1e-12)


def test_a_mechanism_far_from_the_origin_fills_its_picture():
    """A crank turning about (100, 100): the picture holds the crank, not the origin (the
    bodies' outlines were put on the Axes in their own frames first, and the data limits
    took them in)."""
    m = mbd2d.Model("far")
    m.add_body("bar", q0=[100.5, 100.0, 0.0])
    m.add_revolute(["ground", "bar"], [[100.0, 100.0], [-0.5, 0.0]], name="O")
    m.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0.0, 1.0]},
                 name="motor")
    res = m.kinematics(1.0, 10)
    for ax in (plot_mechanism(res), plot_paths(res, [("bar", (0.5, 0.0))])):
        ax.figure.canvas.draw()
        for lo, hi in (ax.get_xlim(), ax.get_ylim()):
            assert 97.0 < lo < 100.0 < hi < 103.0


# ----------------------------------------------------------------------------- animation
def test_gif_frames_size_and_timing(slider, tmp_path):
    out = slider.animate(tmp_path / "a" / "slider.gif", fps=5, trace=[("rod", (0.0, 0.5))],
                         **SMALL)
    assert out == str(tmp_path / "a" / "slider.gif")
    n, size, info = image(Path(out))
    assert n == 6                            # 1 s at 5 fps: t = 0, 0.2, ..., 1
    assert size == (80, 64)
    assert info["duration"] == 200
    frames = render_frames(slider, fps=5, **SMALL)
    assert len(frames) == 6 and frames[0].shape == (64, 80, 3)
    assert np.any(frames[1] != frames[2])    # it moves
    # slow motion: four times the frames, capped by max_frames
    assert len(render_frames(slider, fps=5, speed=0.25, **SMALL)) == 21
    assert len(render_frames(slider, fps=5, speed=0.25, max_frames=10, **SMALL)) == 10


def test_inline_animation_for_notebooks(slider):
    anim = slider.animate(fps=4, **SMALL)
    html = anim._repr_html_()
    assert html.startswith('<img src="data:image/gif;base64,')
    gif = base64.b64decode(html.split(",", 1)[1].split('"')[0])
    assert image(gif)[0] == anim.frames == 5


def test_mp4_through_ffmpeg_or_a_clear_error(slider, tmp_path, monkeypatch):
    """Without ffmpeg an .mp4 is a ModelError naming it; with one (here a stand-in that
    copies its standard input) the raw RGB frames reach it, one per frame."""
    empty = tmp_path / "empty"
    empty.mkdir()
    monkeypatch.setenv("PATH", str(empty))
    with pytest.raises(ModelError, match="ffmpeg"):
        slider.animate(tmp_path / "x.mp4", fps=4, **SMALL)
    fake = empty / "ffmpeg"
    fake.write_text(f"#!{sys.executable}\nimport sys\n"
                    "open(sys.argv[-1], 'wb').write(sys.stdin.buffer.read())\n")
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    out = slider.animate(tmp_path / "x.mp4", fps=4, **SMALL)
    assert Path(out).stat().st_size == 5 * 80 * 64 * 3


@pytest.mark.parametrize("kwargs, match", [
    ({"path": "x.avi"}, ".gif or .mp4"),
    ({"path": 3}, "path must be"),
    ({"fps": 0}, "fps"),
    ({"speed": -1.0}, "speed"),
    ({"max_frames": 1}, "max_frames"),
    ({"dpi": 2.5}, "dpi"),
    ({"size": (1.0,)}, "size"),
    ({"trace": [("nobody", (0, 0))]}, "no body"),
    ({"trace": "rod"}, "list of"),
    ({"forces": True}, "multipliers"),
])
def test_animation_arguments_are_checked(slider, tmp_path, kwargs, match):
    kw = dict(SMALL)
    kw.update(kwargs)
    path = kw.pop("path", None)
    with pytest.raises(ModelError, match=match):
        slider.animate(path if path is None or not isinstance(path, str)
                       else tmp_path / path, **kw)


# ----------------------------------------------------------------------------- notebooks
def test_results_and_models_show_themselves(slider, masses):
    for obj in (slider, masses, mbd2d.load(EX / "pendulum_spring.toml").statics(),
                mbd2d.load(EX / "cam_follower.toml")):
        png = obj._repr_png_()
        assert png[:8] == PNG, obj
    # a model that cannot assemble is drawn at its q0 estimates, and says so
    bad = mbd2d.loads((EX / "fourbar_grashof.toml").read_text().replace(
        "points = [[1.25, 0.0], [3.0, 0.0]]", "points = [[1.25, 0.0], [9.0, 0.0]]"))
    conf = bad.configuration()
    assert "assembly failed" in conf.note
    assert bad._repr_png_()[:8] == PNG
    orphan = mbd2d.KinematicsResult(slider.t, slider.q, slider.qd, slider.qdd,
                                    slider.body_names, slider.coordinate_names)
    assert orphan._repr_png_() is None


# ----------------------------------------------------------------------------- time axes
def _vlines(fig, colour):
    from matplotlib.colors import same_color

    out = set()
    for ax in fig.axes:
        for ln in ax.lines:
            x = np.asarray(ln.get_xdata(), dtype=float)
            if len(x) == 2 and x[0] == x[1] and same_color(ln.get_color(), colour):
                out.add(round(float(x[0]), 9))
    return out


def test_dead_centre_and_singular_passages_are_marked():
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        mbd2d.load(EX / "fourbar_seed.toml").kinematics(t_end=1.0, steps=200)
    err = info.value
    assert err.results.stats["dead_centre"] == err.t
    fig = plot_timeseries(err.results)
    t_star = math.acos((9 + 36 - 7.6**2) / 36) - math.pi / 3
    assert _vlines(fig, STOP_COLOUR) == {round(err.t, 9)}
    assert abs(err.t - t_star) < 1e-8
    sys.path.insert(0, str(EX))
    import nfourbar

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.SingularPassageWarning)
        res = nfourbar.build(1).kinematics(t_end=2 * np.pi, steps=300)
    marked = sorted(_vlines(plot_timeseries(res), PASSAGE_COLOUR))
    assert_allclose(marked, [np.pi / 2, 3 * np.pi / 2], atol=1e-6)   # the collinear times


def test_force_and_energy_series(masses):
    fig = plot_timeseries(masses, kind="forces")
    top, bottom = fig.axes
    assert_allclose(top.lines[0].get_ydata(), masses.effort("motor"))
    assert "N m" in top.get_ylabel()
    r = masses.reaction("B")
    line = next(ln for ln in bottom.lines if ln.get_label() == "B on rocker")
    assert_allclose(line.get_ydata(), np.hypot(r.fx_j, r.fy_j))
    fig = plot_timeseries(masses, kind="energy")
    assert_allclose(fig.axes[0].lines[2].get_ydata(), masses.energy)
    assert "[J]" in fig.axes[0].get_ylabel()
    with pytest.raises(ModelError, match="kind"):
        plot_timeseries(masses, kind="nope")


# ----------------------------------------------------------------------------- command line
def cli(*args: str, cwd: Path, capsys) -> tuple[int, str]:
    """The command line in this process (exit code, stderr as one line)."""
    from mbd2d.cli import main

    old = os.getcwd()
    os.chdir(cwd)
    try:
        code = main(list(args))
    finally:
        os.chdir(old)
    return code, " ".join(capsys.readouterr().err.split())


def test_command_line_plot_and_animate(tmp_path, capsys):
    span = ["--t-end", "1", "--steps", "30", "--dpi", "30"]
    r = subprocess.run([sys.executable, "-m", "mbd2d", "animate", str(EX / "fourbar_grashof.toml"),
                        *span, "--fps", "4", "--out", "m.gif", "--trace", "coupler:0,1"],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert image(tmp_path / "m.gif")[0] == 5
    for what in ("mechanism", "paths", "time-series", "forces", "energy"):
        code, err = cli("plot", str(EX / "fourbar_masses.toml"), *span, "--what", what,
                        "--analysis", "inverse-dynamics", "--out", f"{what}.png", cwd=tmp_path,
                        capsys=capsys)
        assert code == 0, err
        assert (tmp_path / f"{what}.png").read_bytes()[:8] == PNG
    code, err = cli("plot", str(EX / "pendulum_spring.toml"), *span, "--forces", "--out",
                    "d.png", "--method", "generalized-alpha", "--h", "0.01", cwd=tmp_path,
                    capsys=capsys)
    assert code == 0, err                                  # no driver: dynamics
    # a run that stops at a dead centre is drawn up to there
    code, err = cli("plot", str(EX / "fourbar_seed.toml"), "--t-end", "1", "--steps", "100",
                    "--dpi", "30", "--out", "seed.png", cwd=tmp_path, capsys=capsys)
    assert code == 3 and "dead centre" in err
    assert (tmp_path / "seed.png").read_bytes()[:8] == PNG
    for bad, match in ((["--trace", "coupler"], "BODY:X,Y"), (["--what", "forces"], "multipl"),
                       (["--out", "x.jpg"], ".png")):
        args = ["plot", str(EX / "fourbar_grashof.toml"), *span, "--out", "y.png", *bad]
        code, err = cli(*args, cwd=tmp_path, capsys=capsys)
        assert code == 2, err
        assert match in err and "Traceback" not in err


# ----------------------------------------------------------------------------- gallery
def test_gallery_is_regenerated_for_every_joint_type(tmp_path):
    """docs/gallery.py draws one picture per joint type (and the force elements); the
    committed docs/img/gallery holds exactly those files and docs/gallery.md shows each."""
    sys.path.insert(0, str(ROOT / "docs"))
    import gallery

    assert {v[0] for v in gallery.MODELS.values()} == set(J.joint_keys()) | {"forces"}
    assert gallery.main(["--out", str(tmp_path)]) == 0
    made = sorted(p.name for p in tmp_path.iterdir())
    readme = {"plot_mechanism.png", "plot_paths.png", "plot_timeseries.png", "animate.gif",
              "plot_sweep.png"}
    assert set(made) == {f"{n}.png" for n in gallery.MODELS} | readme
    for n in gallery.MODELS:
        assert image(tmp_path / f"{n}.png")[1] == (300, 240)
    assert image(tmp_path / "animate.gif")[0] == 13
    committed = sorted(p.name for p in (ROOT / "docs" / "img" / "gallery").iterdir())
    assert committed == made
    text = (ROOT / "README.md").read_text()
    for name in readme:
        assert f"(docs/img/gallery/{name})" in text, name
    assert (ROOT / "docs" / "gallery.md").read_text() == gallery.markdown(list(gallery.MODELS))


def test_measures_against_time(tmp_path: Path, capsys) -> None:
    """kind="measures": one axis per measure; the transmission angle in degrees (the
    seed four-bar's reaches 180 deg at its toggle, where coupler and rocker line up), a
    ratio's infinite values left as gaps, the dead centre marked; the command line draws it."""
    from mbd2d.cli import main
    toml = Path(__file__).resolve().parents[1] / "examples" / "fourbar_seed.toml"
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        mbd2d.load(toml).kinematics(1.0, 200)
    res = info.value.results
    specs = ["transmission_angle:B", "mechanical_advantage:motor:rocker.theta"]
    fig = plot_timeseries(res, kind="measures", measures=specs)
    axes = fig.axes
    assert len(axes) == 2 and [a.get_title() for a in axes] == specs
    def data(a):
        return [ln for ln in a.lines if len(ln.get_ydata()) == len(res.t)][0].get_ydata()
    mu = data(axes[0])
    assert_allclose(mu, np.degrees(res.transmission_angle("B")), rtol=0, atol=1e-12)
    assert 170.0 < mu[-1] <= 180.0            # the toggle: coupler and rocker in line
    ma = res.mechanical_advantage("motor", "rocker.theta")
    drawn = data(axes[1])
    assert np.array_equal(np.isnan(drawn), ~np.isfinite(ma))
    assert any(ln.get_color() == STOP_COLOUR for ln in axes[0].lines)
    with pytest.raises(ModelError, match="needs measures"):
        plot_timeseries(res, kind="measures")
    out = tmp_path / "m.png"
    assert main(["plot", str(toml), "--t-end", "1", "--steps", "100", "--what", "measures",
                 "--measure", specs[0], "--out", str(out)]) == 3      # drawn up to the toggle
    assert out.stat().st_size > 0


def test_picture_arguments_of_the_wrong_form_are_refused() -> None:
    """A number where a list of traced points or bodies goes is a ModelError (was a raw
    TypeError); one body's name alone is taken as that body."""
    import matplotlib.pyplot as plt
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(1.0, 4)
    for call in (lambda: res.plot(trace=-1), lambda: plot_paths(res, 2.5),
                 lambda: plot_paths(res, "coupler"), lambda: plot_timeseries(res, -1)):
        with pytest.raises(ModelError, match="must be a list"):
            call()
    fig = plot_timeseries(res, "rocker")
    assert len(fig.axes[0].lines) == 1
    plt.close("all")
