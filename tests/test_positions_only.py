"""Kinematics of the positions alone (``positions_only=True``): chord steps, the same answers.

Where J is well conditioned the core predicts the positions by their Newton polynomial and
corrects them with chord steps (simplified Newton on a kept factorization of J), each step
ending, as a full step does, when a correction is below resolution; anywhere else it takes the
full steps with velocities and accelerations. The references are independent of the engine:
the hand-derived closed forms of tests/test_closed_forms.py (four-bar, slider-crank, cam lift),
the toggle time of the seed four-bar from the law of cosines (tests/test_toggle.py), and the
parallelogram branch of the N-four-bar (tests/test_bifurcation.py). Each position must be
within 32 units in the last place of the quantity's largest magnitude of its closed form (the
rounding floor), at every step size: tighter than the full run, which stops Newton at the
tolerance when a step needs more than one correction (3e-13 at h = 10 ms).
"""
from __future__ import annotations

import math
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
import test_closed_forms as cf
import test_toggle as tg
from conftest import EXAMPLES, example_path, load_example, model_from_toml, wrap_angle
from mbd2d.binding import core
from mbd2d.binding.pack import pack
from mbd2d.binding.status import USER_ABORT

sys.path.insert(0, str(EXAMPLES))
import nfourbar  # noqa: E402

FLOOR_ULPS = 32.0


def worst(actual: np.ndarray, ref: np.ndarray, angle: bool = False) -> float:
    d = np.asarray(actual) - np.asarray(ref)
    return float(np.max(np.abs(wrap_angle(d) if angle else d)))


def at_least_as_close(label: str, pos: np.ndarray, full: np.ndarray, ref: np.ndarray,
                      angle: bool = False) -> None:
    """The positions-only error is within the rounding floor (32 units in the last place of
    the quantity's largest magnitude), whatever the full run's (printed beside it)."""
    e_pos, e_full = worst(pos, ref, angle), worst(full, ref, angle)
    limit = FLOOR_ULPS * np.finfo(float).eps * float(np.max(np.abs(ref)))
    print(f"\n[positions only] {label}: {e_pos:.2e} (full run {e_full:.2e}, bound {limit:.1e})",
          end="")
    assert e_pos <= limit, f"{label}: {e_pos:.3e} > {limit:.3e}"


def both(model: mbd2d.Model, t_end: float, steps: int, **kw):
    return (model.kinematics(t_end=t_end, steps=steps, positions_only=True, **kw),
            model.kinematics(t_end=t_end, steps=steps, **kw))


# ------------------------------------------------------------------ closed forms
@pytest.mark.parametrize("h", [1e-2, 1e-3, 1e-4])
def test_fourbar_against_its_closed_form(h: float) -> None:
    steps = int(round(1.0 / h))
    pos, full = both(load_example("fourbar_grashof.toml"), 1.0, steps)
    assert pos.complete and pos.qd is None and pos.qdd is None
    ref = cf.fourbar_closed_form(pos.t)
    for body, th in (("coupler", "th3"), ("rocker", "th4")):
        at_least_as_close(f"four-bar h={h:g} {body} theta", pos.body(body).theta,
                          full.body(body).theta, ref[th], angle=True)
        b, bf = pos.body(body), full.body(body)
        at_least_as_close(f"four-bar h={h:g} {body} centre",
                          np.column_stack([b.x, b.y]), np.column_stack([bf.x, bf.y]), ref[body])
    if h <= 1e-3:     # chord steps: a factorization every few steps, not one per step
        assert pos.stats["factorizations"] <= 0.25 * steps
        assert full.stats["factorizations"] >= steps


@pytest.mark.parametrize("tol", [1e-8, 1e-10, 1e-14])
def test_fourbar_at_other_tolerances(tol: float) -> None:
    """The tolerance on ||Phi|| does not loosen the chord steps' test (a correction below
    resolution), nor does a tight one keep them from ending."""
    m = load_example("fourbar_grashof.toml")
    pos = m.kinematics(1.0, 1000, tol=tol, positions_only=True)
    full = m.kinematics(1.0, 1000, tol=tol)
    ref = cf.fourbar_closed_form(pos.t)
    for body, th in (("coupler", "th3"), ("rocker", "th4")):
        at_least_as_close(f"four-bar tol={tol:g} {body} theta", pos.body(body).theta,
                          full.body(body).theta, ref[th], angle=True)
    assert pos.stats["factorizations"] <= 0.25 * 1000


@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_slider_crank_against_its_closed_form(h: float) -> None:
    steps = int(round(1.0 / h))
    pos, full = both(load_example("slider_crank.toml"), 1.0, steps)
    ref = cf.slider_crank_closed_form(pos.t)
    at_least_as_close(f"slider-crank h={h:g} slider x", pos.body("slider").x,
                      full.body("slider").x, ref["x"])
    assert pos.stats["factorizations"] <= 0.25 * steps


@pytest.mark.parametrize("kind", ["roller", "flat", "point"])
def test_cam_lift_against_its_closed_form(kind: str) -> None:
    """Cams add extra coordinates (the contact parameters) and are evaluated whole."""
    pos, full = both(cf.cam_model(kind), 1.0, cf.STEPS)
    y, _, _ = cf.cam_lift(pos.t, kind)
    at_least_as_close(f"cam ({kind}) follower y", pos.body("follower").y,
                      full.body("follower").y, y)
    assert_allclose(pos.q, full.q, rtol=0, atol=1e-12)


# ------------------------------------------------------------------ one correction per step
FLAG = 0.8          # distance from a flag's pin (the coupler's centre) to its centre


def flagged_fourbar(flags: int) -> mbd2d.Model:
    """The Grashof four-bar with flags: bodies pinned at the coupler's centre, each at its
    point (-0.8, 0), their angles driven (0.3 k + (1 + k) t). Closed form: a flag's centre is
    the coupler's plus 0.8 (cos, sin) of its angle."""
    text = example_path("fourbar_grashof.toml").read_text()
    for k in range(flags):
        text += f"""
[[body]]
name = "flag{k}"
q0 = [2.25, 1.2, {0.3 * k}]

[[joint]]
name = "F{k}"
type = "revolute"
bodies = ["coupler", "flag{k}"]
points = [[0.0, 0.0], [{-FLAG}, 0.0]]

[[driver]]
name = "swing{k}"
type = "absolute"
body = "flag{k}"
coordinate = "theta"
f = {{ poly = [{0.3 * k}, {1.0 + k}] }}
"""
    return model_from_toml(text)


@pytest.mark.parametrize("flags", [0, 1, 2])
@pytest.mark.parametrize("h", [1e-2, 1e-3, 1e-4])
def test_the_rest_of_the_newton_step_in_closed_form(flags: int, h: float) -> None:
    """Revolutes and absolute drivers alone (only J's angle columns change, at most 4 bodies):
    after one chord correction the rest of the Newton step is computed from J(q) - J(qf) in
    closed form and ends the step when its error bound is below half the resolution, so at
    h = 0.1 ms each step takes one correction (at 1 ms most do). With 5 bodies (2 flags) the chord steps go on
    as before (about two corrections). Every position within the rounding floor of the
    closed form at every step size."""
    steps = int(round(1.0 / h))
    pos, full = both(flagged_fourbar(flags), 1.0, steps)
    ref = cf.fourbar_closed_form(pos.t)
    for body, th in (("coupler", "th3"), ("rocker", "th4")):
        at_least_as_close(f"{flags} flags h={h:g} {body} theta", pos.body(body).theta,
                          full.body(body).theta, ref[th], angle=True)
    for k in range(flags):
        ang = 0.3 * k + (1.0 + k) * pos.t
        centre = ref["coupler"] + FLAG * np.column_stack([np.cos(ang), np.sin(ang)])
        b, bf = pos.body(f"flag{k}"), full.body(f"flag{k}")
        at_least_as_close(f"{flags} flags h={h:g} flag{k} centre", np.column_stack([b.x, b.y]),
                          np.column_stack([bf.x, bf.y]), centre)
    per_step = pos.stats["newton_corrections"] / steps
    if h == 1e-4:     # (the predictor's order drops while its last term is below its error)
        assert per_step < 1.05 if flags < 2 else per_step > 1.5
    if h == 1e-3 and flags < 2:       # (and rises again when the rest cannot be taken)
        assert per_step < 1.5
    if h == 1e-2:
        assert per_step > 1.5       # corrections too large for the bound: the chord goes on


def test_a_swinging_crank_raises_the_predictor_order_again() -> None:
    """The crank swings, theta2 = 3 sin(6 pi t): at rest at the ends of each swing, where the
    predictor's order drops, at 56 rad/s in between, where it must rise again for one
    correction to end most steps (1.08 corrections per step at h = 0.1 ms; 1.53 with the
    order left where it dropped to). The positions depend on theta2 alone: the closed form
    at t' = theta2 / (2 pi). Within the rounding floor throughout."""
    w = 6.0 * math.pi
    text = example_path("fourbar_grashof.toml").read_text().replace(
        "f = { poly = [0.0, 6.283185307179586] }",
        f"f = {{ harmonic = [{{ amplitude = 3.0, omega = {w!r} }}] }}")
    pos, full = both(model_from_toml(text), 1.0, 10000)
    ref = cf.fourbar_closed_form(3.0 * np.sin(w * pos.t) / (2.0 * math.pi))
    for body, th in (("coupler", "th3"), ("rocker", "th4")):
        at_least_as_close(f"swinging crank {body} theta", pos.body(body).theta,
                          full.body(body).theta, ref[th], angle=True)
        b, bf = pos.body(body), full.body(body)
        at_least_as_close(f"swinging crank {body} centre", np.column_stack([b.x, b.y]),
                          np.column_stack([bf.x, bf.y]), ref[body])
    assert pos.stats["newton_corrections"] / 10000 < 1.2


def test_twenty_turns_stay_at_the_rounding_floor() -> None:
    """200,000 steps of 0.1 ms (twenty crank turns) with one correction a step: nothing
    accumulates (each step ends within resolution of its own closed form)."""
    pos = load_example("fourbar_grashof.toml").kinematics(20.0, 200000, positions_only=True)
    ref = cf.fourbar_closed_form(pos.t)
    limit = FLOOR_ULPS * np.finfo(float).eps
    for body, th in (("coupler", "th3"), ("rocker", "th4")):
        assert worst(pos.body(body).theta, ref[th], angle=True) <= limit * np.pi
        b = pos.body(body)
        assert worst(np.column_stack([b.x, b.y]), ref[body]) <= limit * np.max(np.abs(ref[body]))
    assert pos.stats["newton_corrections"] / 200000 < 1.05


# ------------------------------------------------------------------ where a method breaks
def test_the_toggle_stops_the_run_where_the_full_run_stops() -> None:
    """The seed four-bar's dead centre at t* (law of cosines): the same exception, at the same
    time, with the rows up to it; those rows close the loop."""
    m = load_example("fourbar_seed.toml")
    errs = []
    for flag in (True, False):
        with pytest.raises(mbd2d.SingularConfigurationError, match="dead centre") as info:
            m.kinematics(t_end=1.0, steps=1000, positions_only=flag)
        errs.append(info.value)
    pos, full = errs
    assert pos.t == pytest.approx(tg.T_STAR, abs=1e-6)
    assert pos.t == pytest.approx(full.t, abs=1e-9)
    assert len(pos.results.t) == len(full.results.t)
    assert pos.results.qd is None
    assert np.max(np.abs(tg.loop_residuals(pos.results.t, pos.results.q))) < 1e-9
    assert_allclose(pos.results.q, full.results.q, rtol=0, atol=1e-9)


@pytest.mark.parametrize("n", [1, 2])
def test_bifurcation_passages_as_in_the_full_run(n: int) -> None:
    """N-four-bar through its collinear positions (odd N: det J changes sign; even N: it only
    touches zero): the positions-only run takes full steps there, records the same passages
    and stays on the parallelogram branch."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.SingularPassageWarning)
        pos, full = both(nfourbar.build(n), 4 * math.pi, 1000)
    assert_allclose(pos.stats["singular_passages"], np.pi / 2 + np.pi * np.arange(4), atol=1e-6)
    assert pos.stats["singular_passage_count"] == full.stats["singular_passage_count"] == 4
    th = np.pi / 2 - pos.t
    for k in range(n + 1):
        assert_allclose(pos.body(f"crank{k}").theta, th, rtol=0, atol=1e-10)
    for k in range(n):
        c = pos.body(f"coupler{k}")
        assert_allclose(c.x, k + 0.5 + np.cos(th), rtol=0, atol=1e-10)
        assert_allclose(c.y, np.sin(th), rtol=0, atol=1e-10)


def test_even_n_passage_without_a_rejected_step() -> None:
    with pytest.warns(mbd2d.SingularPassageWarning, match="passed through 1 singular"):
        res = nfourbar.build(2).kinematics(t_end=3.0, steps=2000, positions_only=True)
    assert_allclose(res.stats["singular_passages"], [np.pi / 2], atol=1e-6)
    th = math.pi / 2 - res.t
    assert_allclose(res.body("crank2").theta, th, rtol=0, atol=1e-10)


@pytest.mark.parametrize("n", [2, 20])
def test_banded_chain(n: int) -> None:
    """N-four-bars on the band LU. N = 2 (J well conditioned): chord steps on the band
    factors, a quarter of the full run's factorizations. N = 20 (pivot ratios about the
    threshold FAST_PIV): mostly full steps, the chord steps tried ever more rarely after each
    failed attempt, at most a few percent more factorizations than the full run."""
    pos, full = both(nfourbar.build(n), 1.0, 200, solver="banded")
    assert pos.stats["solver"] == "banded"
    ratio = pos.stats["factorizations"] / full.stats["factorizations"]
    assert ratio < 0.3 if n == 2 else ratio < 1.05
    th = np.pi / 2 - pos.t
    assert_allclose(pos.body(f"crank{n}").theta, th, rtol=0, atol=1e-10)
    assert_allclose(pos.q, full.q, rtol=0, atol=1e-11)


def test_redundant_constraints_take_the_full_steps() -> None:
    """Least squares (more equations than coordinates) has no chord steps; the positions are
    the plain four-bar's."""
    with pytest.warns(mbd2d.RedundantConstraintWarning):
        red = load_example("fourbar_redundant.toml").kinematics(1.0, 200, positions_only=True)
    plain = load_example("fourbar_grashof.toml").kinematics(1.0, 200, positions_only=True)
    assert red.qd is None
    assert_allclose(red.q, plain.q, rtol=0, atol=1e-12)


def test_every_keeps_the_same_rows() -> None:
    m = load_example("fourbar_grashof.toml")
    all_rows = m.kinematics(1.0, 1000, positions_only=True)
    some = m.kinematics(1.0, 1000, every=7, positions_only=True)
    idx = np.r_[np.arange(0, 1001, 7), 1000]
    assert np.array_equal(some.q, all_rows.q[idx])


def test_stop_request_is_honoured() -> None:
    p = pack(load_example("fourbar_grashof.toml"))
    ctl = core.new_ctl()
    ctl[1] = 1
    out = core.kinematics(p, 0.0, 1.0, 100, 0.0, 0, 0.0, 1, 0, 101, ctl, True)
    assert out.status == USER_ABORT and out.iinfo[0] == 2 and out.qd.shape == (p.nq, 0)


# ------------------------------------------------------------------ the result and its inputs
def test_result_holds_positions_only(tmp_path: Path) -> None:
    res = load_example("fourbar_grashof.toml").kinematics(1.0, 20, positions_only=True)
    b = res.body("rocker")
    assert b.theta.shape == (21,) and b.theta_dot is None and b.x_ddot is None
    pt = res.point("coupler", [0.0, 1.0])
    assert pt.r.shape == (21, 2) and pt.v is None and pt.a is None
    with pytest.raises(mbd2d.ModelError, match="positions only"):
        pt.x_dot
    with pytest.raises(mbd2d.ModelError, match="positions only"):
        pt.speed
    header, rows = res.table()
    assert header == ["t"] + [f"{n}.{c}" for n in ("crank", "coupler", "rocker")
                              for c in ("x", "y", "theta")]
    assert rows.shape == (21, 10)
    res.to_npz(tmp_path / "r.npz")
    with np.load(tmp_path / "r.npz") as z:
        assert "q" in z.files and "qd" not in z.files
    # the measures need the positions only
    assert res.transmission_angle("B").shape == (21,)
    assert np.all(np.isfinite(res.velocity_ratio("motor", "rocker.theta")))


def test_timeseries_picture_has_one_row() -> None:
    pytest.importorskip("matplotlib")
    res = load_example("fourbar_grashof.toml").kinematics(1.0, 20, positions_only=True)
    fig = res.plot_timeseries()
    assert len(fig.axes) == 3


def test_bad_inputs_are_model_errors() -> None:
    m = load_example("fourbar_grashof.toml")
    with pytest.raises(mbd2d.ModelError, match="True or False"):
        m.kinematics(1.0, 10, positions_only="yes")
    with pytest.raises(mbd2d.ModelError, match="drop positions_only"):
        m.kinematics(1.0, 10, positions_only=True, sensitivities=["joint.A.points.0.0"])
    with pytest.raises(mbd2d.ModelError, match="setting of kinematics"):
        load_example("fourbar_masses.toml").export("/tmp/x.mbd", t_end=1.0, steps=10,
                                                   analysis="dynamics", positions_only=True)


def test_a_model_with_masses_gives_its_kinematics() -> None:
    m = load_example("fourbar_masses.toml")
    assert isinstance(m.kinematics(1.0, 10), mbd2d.DynamicsResult)
    res = m.kinematics(1.0, 10, positions_only=True)
    assert isinstance(res, mbd2d.KinematicsResult) and res.qd is None


# ------------------------------------------------------------------ every front door
def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mbd2d", *args], capture_output=True,
                          text=True, timeout=120)


def test_command_line_and_standalone_write_the_same_csv(tmp_path: Path) -> None:
    from test_standalone import find_solver
    model = EXAMPLES / "fourbar_grashof.toml"
    out_cli, out_py = tmp_path / "cli.csv", tmp_path / "py.csv"
    r = cli("kinematics", str(model), "--t-end", "1", "--steps", "100", "--positions-only",
            "--out", str(out_cli))
    assert r.returncode == 0, r.stderr
    mbd2d.load(model).kinematics(1.0, 100, positions_only=True).to_csv(out_py)
    assert out_cli.read_text() == out_py.read_text()
    mbd = tmp_path / "m.mbd"
    r = cli("export", str(model), str(mbd), "--t-end", "1", "--steps", "100",
            "--positions-only")
    assert r.returncode == 0, r.stderr
    assert "positions_only 1" in mbd.read_text()
    out_exe = tmp_path / "exe.csv"
    s = subprocess.run([find_solver(), str(mbd), str(out_exe)], capture_output=True, text=True,
                       timeout=120)
    assert s.returncode == 0, s.stderr
    assert out_exe.read_text() == out_py.read_text()


def test_standalone_refuses_a_bad_positions_line(tmp_path: Path) -> None:
    from test_standalone import find_solver
    mbd = tmp_path / "m.mbd"
    load_example("fourbar_grashof.toml").export(mbd, t_end=1.0, steps=10, positions_only=True)
    mbd.write_text(mbd.read_text().replace("positions_only 1", "positions_only 2"))
    s = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=120)
    assert s.returncode == 2 and "positions_only must be 0 or 1" in s.stderr


def test_sweep_of_positions() -> None:
    pytest.importorskip("xarray")
    m = load_example("fourbar_grashof.toml")
    values = np.linspace(-1.9, -1.6, 4)
    ds = mbd2d.sweep(m, {"joint.A.points.1.0": values}, t_end=1.0, steps=50,
                     positions_only=True, workers=1)
    assert "qd" not in ds and "qdd" not in ds and ds.q.shape == (4, 51, 9)
    for c, v in enumerate(values):
        one = m.with_params({"joint.A.points.1.0": float(v)}).kinematics(1.0, 50,
                                                                          positions_only=True)
        assert np.array_equal(ds.q.values[c], one.q)


def test_sweep_of_positions_keeps_failures_as_the_variants_alone() -> None:
    """Coupler lengths from dead centres through Grashof to no assembly: each case's status,
    message and rows are those of the variant run alone with positions_only."""
    pytest.importorskip("xarray")
    m = load_example("fourbar_grashof.toml")
    cases = {"joint.B.points.0.0": np.array([-0.6, 1.2, 1.75, 4.05])}
    ds = mbd2d.sweep(m, cases, t_end=1.0, steps=40, positions_only=True, workers=1)
    assert set(ds.status.values) >= {0, 3}
    for j, v in enumerate(cases["joint.B.points.0.0"]):
        variant = m.with_params({"joint.B.points.0.0": float(v)})
        st, msg = int(ds.status.values[j]), str(ds.message.values[j])
        try:
            res = variant.kinematics(1.0, 40, positions_only=True)
        except mbd2d.AnalysisError as exc:
            assert (st, msg) == (exc.status, str(exc))
            n = len(exc.results.t) if exc.results is not None else 0
            assert exc.results is None or exc.results.qd is None
            assert np.array_equal(ds.q.values[j, :n], exc.results.q if n else ds.q.values[j, :0])
            assert np.isnan(ds.q.values[j, n:]).all()
            continue
        assert (st, msg) == (0, "") and np.array_equal(ds.q.values[j], res.q)
