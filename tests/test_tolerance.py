"""Tolerance analysis (mbd2d.tolerance): the first-order standard deviations against a
closed-form propagation computed here without mbd2d (the crank-rocker's loop solved by
circle intersection and differentiated by Richardson-extrapolated central differences), and
the Monte Carlo estimate against the first-order one within the Monte Carlo error for small
sigma (the sample standard deviation of N normal draws has a relative standard error of
1/sqrt(2 (N - 1))).
"""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d

from conftest import load_example

pytest.importorskip("xarray")

#: the crank-rocker (examples/fourbar_grashof.toml): crank a, coupler b, rocker c, ground d
#: as the parameters that set them (each length grows one for one with its parameter)
LINKS = {"joint.A.points.0.0": "a", "joint.B.points.0.0": "b", "joint.O4.points.0.0": "c",
         "joint.O4.points.1.0": "d"}
NOMINAL = {"a": 1.0, "b": 3.5, "c": 2.5, "d": 3.0}
SIGMA = {"joint.A.points.0.0": 2e-3, "joint.B.points.0.0": 1e-3, "joint.O4.points.0.0": 3e-3,
         "joint.O4.points.1.0": 1.5e-3}
T_END, STEPS = 1.0, 20
COUPLER_POINT = (0.5, 0.8)       # in the coupler's frame (A at (-1.75, 0), B at (1.75, 0))


def loop(t: np.ndarray, a: float, b: float, c: float, d: float) -> dict[str, np.ndarray]:
    """Closed-form crank-rocker: crank angle 2 pi t about O2 = 0, O4 = (d, 0); B on the
    circles |B - A| = b, |B - O4| = c, on the upper branch (as assembled). Returns the rocker
    angle (its frame's x axis from B to O4) and the coupler point."""
    th = 2 * np.pi * t
    ax, ay = a * np.cos(th), a * np.sin(th)
    ex, ey = d - ax, -ay                            # A -> O4
    e = np.hypot(ex, ey)
    u = (b**2 - c**2 + e**2) / (2 * e)              # along A -> O4 to the chord
    h = np.sqrt(b**2 - u**2)
    bx = ax + (u * ex - h * ey) / e                 # the branch with B above the line
    by = ay + (u * ey + h * ex) / e
    rocker = np.arctan2(-by, d - bx)
    th3 = np.arctan2(by - ay, bx - ax)
    sx, sy = COUPLER_POINT[0] + 1.75, COUPLER_POINT[1]     # from A, in the coupler frame
    px = ax + np.cos(th3) * sx - np.sin(th3) * sy
    py = ay + np.sin(th3) * sx + np.cos(th3) * sy
    return {"rocker": rocker, "px": px, "py": py}


def derivative(f: Callable[[float], np.ndarray], x: float, h: float = 1e-3) -> np.ndarray:
    """df/dx by central differences at h and h/2, Richardson-extrapolated (error h**4)."""
    d1 = (f(x + h) - f(x - h)) / (2 * h)
    d2 = (f(x + h / 2) - f(x - h / 2)) / h
    return (4 * d2 - d1) / 3


def closed_form_std(key: str, t: np.ndarray) -> np.ndarray:
    """First-order standard deviation of a closed-form output under SIGMA."""
    var = np.zeros_like(t)
    for name, link in LINKS.items():
        def f(x: float, link: str = link) -> np.ndarray:
            return loop(t, **{**NOMINAL, link: x})[key]
        var += (derivative(f, NOMINAL[link]) * SIGMA[name]) ** 2
    return np.sqrt(var)


@pytest.fixture(scope="module")
def tol() -> Any:
    m = load_example("fourbar_grashof.toml")
    return mbd2d.tolerance(m, SIGMA, samples=2000, workers=1, t_end=T_END, steps=STEPS)


def test_the_closed_form_is_the_model() -> None:
    """The test's loop solution reproduces the nominal run (so it is the right oracle)."""
    res = load_example("fourbar_grashof.toml").kinematics(T_END, STEPS)
    cf = loop(res.t, **NOMINAL)
    assert_allclose(res.body("rocker").theta, cf["rocker"], atol=1e-11)
    assert_allclose(res.point("coupler", COUPLER_POINT), np.column_stack([cf["px"], cf["py"]]),
                    atol=1e-11)


def test_linear_estimate_is_the_closed_form_propagation(tol: Any) -> None:
    t = tol.dataset.time.values
    lin = tol.dataset.q_std_linear.sel(coordinate="rocker.theta").values
    assert_allclose(lin, closed_form_std("rocker", t), rtol=1e-8)
    pt = tol.point("coupler", COUPLER_POINT)
    assert_allclose(pt.x_std_linear.values, closed_form_std("px", t), rtol=1e-8)
    assert_allclose(pt.y_std_linear.values, closed_form_std("py", t), rtol=1e-8)
    assert_allclose(pt.x.values, loop(t, **NOMINAL)["px"], atol=1e-11)


def test_monte_carlo_agrees_within_its_error(tol: Any) -> None:
    ds = tol.dataset
    n = ds.attrs["samples"] - ds.attrs["failed"]
    assert ds.attrs["failed"] == 0 and n == 2000
    se = 1.0 / math.sqrt(2 * (n - 1))          # relative standard error of a sample std
    for out in ("q", "qd", "qdd"):
        lin, mc = ds[f"{out}_std_linear"].values, ds[f"{out}_std_mc"].values
        moving = lin > 1e-9 * np.abs(ds[out].values).max()
        assert moving.sum() > 20
        assert np.abs(mc[moving] / lin[moving] - 1).max() < 5 * se, out
        # the crank does not depend on these parameters: no scatter at all
        assert_allclose(mc[~moving], 0.0, atol=1e-12)
        # the mean is the nominal value within its own error (the bias is second order)
        err = np.abs(ds[f"{out}_mean_mc"].values - ds[out].values)[moving]
        assert (err < 5 * lin[moving] / math.sqrt(n)).all(), out
    pt = tol.point("coupler", COUPLER_POINT)
    for c in ("x", "y"):
        r = pt[f"{c}_std_mc"].values / pt[f"{c}_std_linear"].values
        assert np.abs(r - 1).max() < 5 * se


def test_large_scatter_shows_the_nonlinearity() -> None:
    """With sigma a tenth of the coupler length the first-order estimate no longer holds
    everywhere (where the first-order scatter passes through zero, the second-order one does
    not): the two differ by far more than the Monte Carlo error."""
    m = load_example("fourbar_grashof.toml")
    tol = mbd2d.tolerance(m, {"joint.B.points.0.0": 0.25}, samples=1000, workers=1,
                          t_end=T_END, steps=STEPS)
    ds = tol.dataset
    n = ds.attrs["samples"] - ds.attrs["failed"]
    lin, mc = ds.q_std_linear.values, ds.q_std_mc.values
    moving = lin > 1e-9
    assert np.abs(mc[moving] / lin[moving] - 1).max() > 20 / math.sqrt(2 * (n - 1))


def slider_crank_with_masses() -> mbd2d.Model:
    m = load_example("slider_crank.toml")
    for b, (ms, j) in zip(m.bodies, [(2.0, 0.3), (1.5, 1.1), (0.8, 0.05)]):
        b.mass, b.inertia = ms, j
    return m


def test_inverse_dynamics_effort_linear_in_masses() -> None:
    """The motor torque is linear in the masses and inertias: the first-order standard
    deviation is exact, and Monte Carlo agrees within its error at any sigma."""
    m = slider_crank_with_masses()
    sig = {"body.rod.mass": 0.3, "body.slider.mass": 0.2, "body.rod.inertia": 0.1}
    tol = mbd2d.tolerance(m, sig, "inverse_dynamics", samples=1500, workers=1, t_end=1.0,
                          steps=12)
    ds = tol.dataset
    lin, mc = ds.effort_std_linear.values[:, 0], ds.effort_std_mc.values[:, 0]
    assert np.abs(mc / lin - 1).max() < 5 / math.sqrt(2 * (1500 - 1))
    # the linear estimate by hand: effort = e0 + sum_k (d effort / d m_k) m_k exactly
    base = m.inverse_dynamics(1.0, 12).effort("motor")
    var = np.zeros_like(base)
    for name, s in sig.items():
        value = m.parameters()[name]
        step = m.with_params({name: value + 1.0}).inverse_dynamics(1.0, 12).effort("motor")
        var += ((step - base) * s) ** 2
    assert_allclose(lin, np.sqrt(var), rtol=1e-9, atol=1e-12)
    assert "effort_std_linear" in ds and ds.effort.dims == ("time", "driver")


def test_statics_tolerance() -> None:
    """Spring pendulum equilibrium k theta + m g a cos(theta) = 0 (a = 0.5): d theta / dk
    by implicit differentiation, -theta / (k - m g a sin theta)."""
    m = load_example("pendulum_spring.toml")
    tol = mbd2d.tolerance(m, {"force.torsion.stiffness": 0.05}, "statics", samples=1000,
                          workers=1)
    eq = m.statics()
    th = eq.body("bar")[2]
    k, g, a = 10.0, 9.81, 0.5
    assert abs(k * th + g * a * math.cos(th)) < 1e-12
    dth = -th / (k - g * a * math.sin(th))
    lin = float(tol.dataset.q_std_linear.sel(coordinate="bar.theta").values[0])
    assert_allclose(lin, abs(dth) * 0.05, rtol=1e-9)
    mc = float(tol.dataset.q_std_mc.sel(coordinate="bar.theta").values[0])
    assert abs(mc / lin - 1) < 5 / math.sqrt(2 * 999)


def test_no_monte_carlo_and_bad_inputs() -> None:
    m = load_example("fourbar_grashof.toml")
    tol = mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, samples=0, t_end=1.0, steps=4)
    assert tol.samples is None and "q_std_mc" not in tol.dataset
    assert np.isnan(tol.point("coupler", (0, 0)).x_std_mc.values).all()
    assert "1 parameters, 0 samples" in repr(tol)
    for sig, kw, match in (({"joint.B.points.0.0": -1.0}, {}, ">= 0"),
                           ({"joint.B.points.0.9": 1.0}, {}, "did you mean"),
                           ({"joint.B.points.0.0": float("nan")}, {}, "finite"),
                           ({}, {}, "dict"),
                           ({"joint.B.points.0.0": 1e-3}, {"samples": 1}, "at least 2"),
                           ({"joint.B.points.0.0": 1e-3}, {"samples": -3}, "samples"),
                           ({"joint.B.points.0.0": 1e-3}, {"rtol": 1.0}, "the settings are"),
                           # (raw ValueError / TypeError from numpy before)
                           ({"joint.B.points.0.0": 1e-3}, {"seed": -1}, "seed"),
                           ({"joint.B.points.0.0": 1e-3}, {"seed": 2.5}, "seed"),
                           ({"joint.B.points.0.0": 1e-3}, {"seed": "x"}, "seed")):
        with pytest.raises(mbd2d.ModelError, match=match):
            mbd2d.tolerance(m, sig, t_end=1.0, steps=4, **kw)
    with pytest.raises(mbd2d.ModelError, match="unknown analysis"):
        mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, "kin", t_end=1.0, steps=4)
    with pytest.raises(mbd2d.ModelError, match="seed"):
        mbd2d.tolerance_samples(m, {"joint.B.points.0.0": 1e-3}, 4, seed=[1, 2])
    with pytest.raises(KeyError, match="no body"):
        tol.point("crank2", (0, 0))
    with pytest.raises(mbd2d.ModelError, match="dopri5 or generalized-alpha"):
        mbd2d.tolerance(load_example("pendulum_spring.toml"), {"body.bar.mass": 0.1},
                        "dynamics", method="baumgarte-rk4", h=1e-3, t_end=1.0, steps=4)


def test_nominal_failure_is_raised() -> None:
    """A nominal design that hits a dead centre has no sensitivities over the cycle: the
    analysis's own exception."""
    m = load_example("fourbar_grashof.toml").with_params({"joint.B.points.0.0": -0.6})
    with pytest.raises(mbd2d.SingularConfigurationError):
        mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, samples=4, t_end=1.0, steps=10)


# ---------------------------------------------------------------------------------------------
# The modes: Monte Carlo alone, against the closed forms evaluated on the same draws


def test_modes_tolerance_against_the_closed_form_on_the_same_draws(tmp_path) -> None:
    """A block (m) on a vertical guide hanging from a spring-damper (k, c): f = sqrt(k/m) /
    (2 pi), zeta = c / (2 sqrt(k m)), equilibrium y = -0.5 - m g / k. With k and m scattered
    the Monte Carlo standard deviations and means of f, zeta and y are those of the closed
    forms over the same draws (mbd2d.tolerance_samples), to 1e-12 relative; there is no
    first-order column (the frequencies' derivatives need third derivatives), and the report
    says so."""
    from test_modes import G, block_text
    m0, k0, c0 = 2.0, 36.0, 1.5
    model = mbd2d.loads(block_text(k0, c0, m0))
    sigma = {"force.s.stiffness": 2.0, "body.block.mass": 0.05}
    tol = mbd2d.tolerance(model, sigma, "modes", samples=300, workers=1)
    ds = tol.dataset
    d = mbd2d.tolerance_samples(model, sigma, 300)
    k, m = d["force.s.stiffness"], d["body.block.mass"]
    for name, values, nominal in (
            ("frequency", np.sqrt(k / m) / (2 * np.pi), np.sqrt(k0 / m0) / (2 * np.pi)),
            ("damping_ratio", c0 / (2 * np.sqrt(k * m)), c0 / (2 * np.sqrt(k0 * m0)))):
        assert_allclose(ds[name].values, nominal, rtol=1e-13)
        assert_allclose(ds[f"{name}_std_mc"].values, np.std(values, ddof=1), rtol=1e-12)
        assert_allclose(ds[f"{name}_mean_mc"].values, values.mean(), rtol=1e-12)
    y = -0.5 - m * G / k
    assert_allclose(ds.q.sel(coordinate="block.y").values, -0.5 - m0 * G / k0, rtol=1e-13)
    assert_allclose(ds.q_std_mc.sel(coordinate="block.y").values, np.std(y, ddof=1),
                    rtol=1e-12)
    assert_allclose(tol.point("block", (0.0, 0.0)).y_std_mc.values, np.std(y, ddof=1),
                    rtol=1e-12)
    assert not tol.linear and ds.attrs["first_order"].startswith("none")
    assert not [v for v in ds.data_vars if v.endswith("_std_linear")]
    assert "Monte Carlo only" in repr(tol)
    with pytest.raises(mbd2d.ModelError, match="first-order column"):
        tol.contributions("frequency", "0")
    out = tmp_path / "tol.csv"
    mbd2d.studies.write_tolerance(ds, out)
    header = out.read_text().splitlines()[0].split(",")
    row = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    assert row.shape[0] == 1
    got = dict(zip(header, row[0]))
    assert_allclose(got["mode1.frequency.std_mc"], np.std(np.sqrt(k / m) / (2 * np.pi),
                                                          ddof=1), rtol=1e-12)
    assert "eigenvalue2.damping_ratio.mean_mc" in got


def test_modes_tolerance_needs_samples_and_takes_no_measures() -> None:
    from test_modes import block_text
    model = mbd2d.loads(block_text())
    with pytest.raises(mbd2d.ModelError, match="samples=0 leaves nothing"):
        mbd2d.tolerance(model, {"force.s.stiffness": 1.0}, "modes", samples=0)
    with pytest.raises(mbd2d.ModelError, match="not of modes"):
        mbd2d.tolerance(model, {"force.s.stiffness": 1.0}, "modes", samples=4,
                        measures="dead_centre_distance")
    with pytest.raises(mbd2d.ModelError, match="the settings are"):
        mbd2d.tolerance(model, {"force.s.stiffness": 1.0}, "modes", samples=4, t_end=1.0)
    # the frequency response: Monte Carlo alone too, and its own settings
    with pytest.raises(mbd2d.ModelError, match="samples=0 leaves nothing"):
        mbd2d.tolerance(model, {"force.s.stiffness": 1.0}, "frf", samples=0,
                        inputs=["force.s.length0"], frequencies=[1.0])
    with pytest.raises(mbd2d.ModelError, match="not of frf"):
        mbd2d.tolerance(model, {"force.s.stiffness": 1.0}, "frf", samples=4,
                        inputs=["force.s.length0"], frequencies=[1.0],
                        measures="dead_centre_distance")
    with pytest.raises(mbd2d.ModelError, match="the settings are"):
        mbd2d.tolerance(model, {"force.s.stiffness": 1.0}, "frf", samples=4,
                        inputs=["force.s.length0"], frequencies=[1.0], t_end=1.0)


# ---------------------------------------------------------------------------------------------
# The frequency response: Monte Carlo alone, against the closed forms on the same draws


def test_frf_tolerance_against_the_closed_form_on_the_same_draws(tmp_path) -> None:
    """The held block pushed (test_sweep_frf.held_block): H = 1 / (k - m w^2 + i c w) for the
    block and -(k + i c w) / (k - m w^2 + i c w) for the holding driver's effort. With k, c
    and m scattered, the Monte Carlo standard deviations and means of the magnitudes and of
    the phases (degrees; each sample's phase relative to the nominal's, so the effort's
    phase near 180 degrees does not jump by 360) are those of the closed forms over the same
    draws, to 1e-12; no first-order column; the CSV has one row per frequency."""
    from test_sweep_frf import held_block
    model, k0, c0, m0 = held_block(), 36.0, 1.5, 2.0
    sigma = {"force.s.stiffness": 2.0, "force.s.damping": 0.3, "body.block.mass": 0.1}
    freq = np.array([0.1, 0.5, 0.675, 0.8, 2.0])
    kw = {"inputs": ["force.push.fy.poly.0"], "frequencies": freq}
    tol = mbd2d.tolerance(model, sigma, "frf", samples=200, workers=1, **kw)
    ds = tol.dataset
    d = mbd2d.tolerance_samples(model, sigma, 200)
    k, c, m = (d[n][:, None] for n in sigma)
    w = 2 * np.pi * freq

    def block(k, c, m):
        return 1 / (k - m * w**2 + 1j * c * w)

    def effort(k, c, m):
        return -(k + 1j * c * w) * block(k, c, m)
    for name, fn, sel in (("magnitude", block, {"coordinate": "block.y"}),
                          ("effort_magnitude", effort, {"driver": "hold"})):
        h, h0 = fn(k, c, m), fn(k0, c0, m0)
        ph = np.degrees(np.angle(h0)) + np.degrees(np.angle(h * np.conj(h0)))
        phase = name.replace("magnitude", "phase")
        one = {**sel, "input": "force.push.fy.poly.0"}
        assert_allclose(ds[name].sel(**one).values, np.abs(h0), rtol=1e-13)
        assert_allclose(ds[f"{name}_std_mc"].sel(**one).values, np.std(np.abs(h), axis=0,
                                                                        ddof=1), rtol=1e-12)
        assert_allclose(ds[f"{name}_mean_mc"].sel(**one).values, np.abs(h).mean(axis=0),
                        rtol=1e-12)
        assert_allclose(ds[phase].sel(**one).values, np.degrees(np.angle(h0)), rtol=1e-13)
        assert_allclose(ds[f"{phase}_std_mc"].sel(**one).values, np.std(ph, axis=0, ddof=1),
                        rtol=1e-11)
        assert_allclose(ds[f"{phase}_mean_mc"].sel(**one).values, ph.mean(axis=0),
                        rtol=1e-12)
    # the effort's phase within 0.04 degrees of 180 at 0.1 Hz: its samples' spread is small
    assert 179.9 < ds.effort_phase_mean_mc.values[0, 0, 0] < 180.0
    assert ds.effort_phase_std_mc.values[0, 0, 0] < 0.1
    assert ds.attrs["first_order"].startswith("none") and not tol.linear
    out = tmp_path / "tol.csv"
    mbd2d.studies.write_tolerance(ds, out)
    header = out.read_text().splitlines()[0].split(",")
    rows = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    assert rows.shape == (freq.size, len(header)) and header[0] == "frequency_hz"
    col = header.index("d(block.y)/d(force.push.fy.poly.0).abs.std_mc")
    assert_allclose(rows[:, col], np.std(np.abs(block(k, c, m)), axis=0, ddof=1), rtol=1e-12)
    assert "d(effort.hold)/d(force.push.fy.poly.0).deg.mean_mc" in header
