"""Exact design derivatives of every mechanism measure: the velocity ratio, the mechanical
advantage and the distance to a dead centre (beside the transmission angle,
tests/test_angle_sensitivity.py), through results, tables, files, the tolerance and
mbd2d-solve.

References (no mbd2d):

* the four-bar's velocity ratio from its loop closure, a w2 sin(th2 - th3) = c w4 sin(th4 -
  th3), with th3, th4 from the two-circle intersection at the link lengths (a, b, c, d);
* the offset slider-crank's dx/dth = -r sin th - (r sin th - e) r cos th / sqrt(l^2 - (r sin th
  - e)^2);
* both differentiated by central differences at two step sizes (the gap falls as h^2: it is
  the reference's truncation); the mechanical advantage's as -r'/r^2 of the same;
* the dead-centre distance (sigma_min / sigma_max of the column-scaled J): central differences
  of ordinary ``with_params`` runs' values (no derivative code), the gap falling as h^2;
* the redundant four-bar (least squares in the core) against the same closed form.
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from mbd2d.cli import main
from mbd2d.results import read_csv
from mbd2d.results.measures import measure_derivatives, measure_dp

EX = Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_angle_sensitivity import FOURBAR, W, central  # noqa: E402

RATIO = "velocity_ratio:motor:rocker.theta"
ADVANTAGE = "mechanical_advantage:motor:rocker.theta"


def loop(t: np.ndarray, a: float, b: float, c: float, d: float
         ) -> tuple[np.ndarray, np.ndarray]:
    """Joints A and B (2, n) of the crank-rocker (crank pivot at the origin, rocker pivot at
    (d, 0)) by the two-circle intersection, on the branch of examples/fourbar_grashof.toml
    (B to the left of A -> O4)."""
    th2 = W * t
    pa = np.stack([a * np.cos(th2), a * np.sin(th2)])
    e = np.array([d, 0.0])[:, None] - pa
    dist = np.hypot(*e)
    x = (b * b - c * c + dist * dist) / (2 * dist)
    e = e / dist
    return pa, pa + x * e + np.sqrt(b * b - x * x) * np.stack([-e[1], e[0]])


def ratio_fourbar(t: np.ndarray, a: float, b: float, c: float, d: float) -> np.ndarray:
    """w4 / w2 of the crank-rocker from the loop closure."""
    pa, pb = loop(t, a, b, c, d)
    th3 = np.arctan2(pb[1] - pa[1], pb[0] - pa[0])
    th4 = np.arctan2(pb[1], pb[0] - d)
    return a * np.sin(W * t - th3) / (c * np.sin(th4 - th3))


def rate_slider(t: np.ndarray, r: float, l: float, e: float) -> np.ndarray:
    """dx/dth of the offset slider-crank."""
    s = r * np.sin(W * t) - e
    return -r * np.sin(W * t) - s * r * np.cos(W * t) / np.sqrt(l * l - s * s)


SLIDER = {"joint.guide.points.0.1": lambda s: (1.0, 3.0, 0.5 + s),
          "joint.A.points.1.0": lambda s: (1.0, 3.0 - s, 0.5),
          "joint.A.points.0.0": lambda s: (1.0 + s, 3.0, 0.5)}


def _h2(d: np.ndarray, f, links, t: np.ndarray, scale=None) -> tuple[float, float]:
    """The largest gap of d to the reference's central differences at h = 1e-3, 1e-4 (scaled
    by scale where given)."""
    w = 1.0 if scale is None else scale
    return tuple(float(np.abs((d - central(f, links, t, h)) / w).max()) for h in (1e-3, 1e-4))


def test_velocity_ratio_against_the_loop_closure():
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    res = m.kinematics(1.0, 90, sensitivities=list(FOURBAR), tol=1e-14)
    assert_allclose(res.velocity_ratio("motor", "rocker.theta"),
                    ratio_fourbar(res.t, 1.0, 3.5, 2.5, 3.0), atol=1e-12)
    d = res.velocity_ratio_dp("motor", "rocker.theta")
    assert d.shape == (91, len(FOURBAR))
    for k, name in enumerate(FOURBAR):
        e3, e4 = _h2(d[:, k], ratio_fourbar, FOURBAR[name], res.t)
        assert e4 < 1e-8 and e4 < e3 / 50, (name, e3, e4)


def test_mechanical_advantage_is_the_inverse_ratios_derivative():
    """d(1/r)/dp = -r'/r^2 with r and r' from the closed form (the advantage reaches 170 near
    the rocker's dead positions: compared relative to max(1, |reference|))."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    res = m.kinematics(1.0, 90, sensitivities=list(FOURBAR), tol=1e-14)
    d = res.mechanical_advantage_dp("motor", "rocker.theta")
    r = ratio_fourbar(res.t, 1.0, 3.5, 2.5, 3.0)
    for k, name in enumerate(FOURBAR):
        ref = -central(ratio_fourbar, FOURBAR[name], res.t, 1e-4) / r**2
        assert np.abs((d[:, k] - ref) / np.maximum(1, np.abs(ref))).max() < 1e-6, name


def test_slider_crank_ratio_and_advantage():
    """The slider's travel per crank radian and its inverse (the force a unit torque
    balances), for the crank, the rod and the guide's offset."""
    m = mbd2d.load(EX / "slider_crank.toml")
    res = m.kinematics(1.0, 72, sensitivities=list(SLIDER), tol=1e-14)
    assert_allclose(res.velocity_ratio("motor", "slider.x"),
                    rate_slider(res.t, 1.0, 3.0, 0.5), atol=1e-12)
    d = res.velocity_ratio_dp("motor", "slider.x")
    ma = res.mechanical_advantage_dp("motor", "slider.x")
    r = rate_slider(res.t, 1.0, 3.0, 0.5)
    for k, name in enumerate(SLIDER):
        e3, e4 = _h2(d[:, k], rate_slider, SLIDER[name], res.t)
        assert e4 < 1e-8 and e4 < e3 / 50, (name, e3, e4)
        ref = -central(rate_slider, SLIDER[name], res.t, 1e-4) / r**2
        assert np.abs((ma[:, k] - ref) / np.maximum(1, np.abs(ref))).max() < 1e-6, name


def test_redundant_fourbar_least_squares():
    """A distance tie doubling the coupler (consistent): the core solves the influence
    coefficients and their derivatives by least squares; the ground pivot keeps the tie
    consistent."""
    m = mbd2d.load(EX / "fourbar_redundant.toml")
    name = "joint.O4.points.1.0"
    with pytest.warns(mbd2d.errors.RedundantConstraintWarning):
        res = m.kinematics(1.0, 45, sensitivities=[name], tol=1e-14)
    e3, e4 = _h2(res.velocity_ratio_dp("motor", "rocker.theta")[:, 0], ratio_fourbar,
                 FOURBAR[name], res.t)
    assert e4 < 1e-8 and e4 < e3 / 50, (e3, e4)


@pytest.mark.parametrize("model, names", [
    ("fourbar_grashof.toml", list(FOURBAR)),
    ("slider_crank.toml", list(SLIDER) + ["joint.guide.axes.1.1"]),
])
def test_dead_centre_distance_against_ordinary_runs(model, names):
    m = mbd2d.load(EX / model)
    res = m.kinematics(1.0, 40, sensitivities=names, tol=1e-14)
    d = res.dead_centre_distance_dp()
    p0 = m.parameters()

    def fd(name, h):
        hi, lo = (m.with_params({name: p0[name] + s * h}).kinematics(1.0, 40, tol=1e-14)
                  .dead_centre_distance() for s in (1, -1))
        return (hi - lo) / (2 * h)

    for k, name in enumerate(names):
        e3 = np.abs(d[:, k] - fd(name, 1e-3)).max()
        e4 = np.abs(d[:, k] - fd(name, 1e-4)).max()
        assert e4 < 1e-8 and (e4 < e3 / 30 or e3 < 1e-11), (name, e3, e4)


def test_dynamics_by_dopri5_against_ordinary_runs():
    """The free four-bar's dead-centre distance along its motion (dopri5 with the
    variational equations) against central differences of ordinary runs, from a start given
    exactly consistent (the perturbed runs' own assembly then takes the sensitivities'
    minimum-norm change to first order: docs/sensitivities.md)."""
    sys.path.insert(0, str(EX))
    import free_fourbar
    m = free_fourbar.build()
    kw = dict(method="dopri5", rtol=1e-12, atol=1e-12)
    start = m.dynamics(0.5, 10, **kw)
    for k, b in enumerate(m.bodies):
        b.q0 = [float(x) for x in start.q[0, 3 * k:3 * k + 3]]
        b.v0 = [float(x) for x in start.qd[0, 3 * k:3 * k + 3]]
    names = ["joint.B.points.0.0", "joint.O4.points.1.0", "body.coupler.mass"]
    res = m.dynamics(0.5, 10, sensitivities=names, **kw)
    d = res.dead_centre_distance_dp()
    p0 = m.parameters()

    def fd(name, h):
        hi, lo = (m.with_params({name: p0[name] + s * h}).dynamics(0.5, 10, **kw)
                  .dead_centre_distance() for s in (1, -1))
        return (hi - lo) / (2 * h)

    for k, name in enumerate(names):
        assert np.abs(fd(name, 1e-4)).max() > 1e-3, name     # each moves the measure
        assert_allclose(d[:, k], (4 * fd(name, 1e-4) - fd(name, 2e-4)) / 3, atol=1e-8)


def test_inverse_dynamics_and_one_call_for_all():
    """measure_derivatives gives every measure in one core call, as each alone."""
    m = mbd2d.load(EX / "fourbar_masses.toml")
    names = ["joint.O4.points.1.0", "body.coupler.mass"]
    res = m.inverse_dynamics(0.5, 12, sensitivities=names, tol=1e-14)
    specs = ["transmission_angle:B", RATIO, ADVANTAGE, "dead_centre_distance"]
    both = measure_derivatives(res, specs)
    assert both.shape == (13, 4, 2)
    for j, spec in enumerate(specs):
        assert_allclose(both[:, j, :], measure_dp(res, spec), rtol=0, atol=0)
    assert np.all(both[:, :, 1] == 0)          # a mass moves no kinematic measure
    e3, e4 = _h2(both[:, 1, 0], ratio_fourbar, FOURBAR["joint.O4.points.1.0"], res.t)
    assert e4 < 1e-8, (e3, e4)


def test_no_sensitivities_and_bad_quantities():
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(1.0, 4)
    for call in (lambda: res.velocity_ratio_dp("motor", "rocker.theta"),
                 res.dead_centre_distance_dp,
                 lambda: measure_derivatives(res, ["dead_centre_distance"])):
        with pytest.raises(mbd2d.ModelError, match="no sensitivities"):
            call()
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(
        1.0, 4, sensitivities=["joint.O4.points.1.0"])
    with pytest.raises(mbd2d.ModelError, match="no driver or coordinate"):
        res.velocity_ratio_dp("motor", "nothing.x")
    with pytest.raises(mbd2d.ModelError, match="unknown measure"):
        measure_derivatives(res, ["velocity_ratio"])
    assert measure_derivatives(res, []).shape == (5, 0, 1)


def test_near_the_slider_dead_centres_never_nan():
    """The slider's advantage dth/dx passes its poles (the crank's dead centres): the
    derivatives are finite or infinite there, never NaN."""
    m = mbd2d.load(EX / "slider_crank.toml")
    res = m.kinematics(1.0, 360, sensitivities=list(SLIDER), tol=1e-14)
    d = measure_derivatives(res, ["mechanical_advantage:motor:slider.x",
                                  "velocity_ratio:motor:slider.x", "dead_centre_distance"])
    assert not np.isnan(d).any()


def test_tolerance_of_the_velocity_ratio(tmp_path, capsys):
    """First order |dr/dp| sigma from the loop closure; Monte Carlo within its error; the
    command line's columns and report."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    name, sigma, n = "joint.O4.points.1.0", 2e-3, 400
    tol = mbd2d.tolerance(m, {name: sigma}, samples=n, t_end=1.0, steps=36, workers=1,
                          measures=[RATIO, "dead_centre_distance"])
    ds = tol.dataset
    t = ds.time.values
    lin = np.abs(central(ratio_fourbar, FOURBAR[name], t, 1e-4)) * sigma
    assert_allclose(ds.measures_std_linear.values[:, 0], lin, rtol=1e-6)
    ratio = ds.measures_std_mc.values[:, :] / ds.measures_std_linear.values[:, :]
    assert np.abs(ratio - 1).max() < 5 / np.sqrt(2 * (n - 1))
    out = tmp_path / "tol.csv"
    assert main(["tolerance", str(EX / "fourbar_grashof.toml"), "--sigma", f"{name}={sigma}",
                 "--samples", "0", "--t-end", "1", "--steps", "12", "--measure", RATIO,
                 "--out", str(out)]) == 0
    assert f"  {RATIO}" in capsys.readouterr().out
    header, rows = read_csv(out)
    lin = np.abs(central(ratio_fourbar, FOURBAR[name], rows[:, 0], 1e-4)) * sigma
    assert_allclose(rows[:, header.index(f"{RATIO}.std_linear")], lin, rtol=1e-6)


def test_sweep_cases_carry_their_measures_derivatives(tmp_path):
    """Each swept coupler length's ratio derivative against the loop closure at its own
    lengths; every measure's equal to a single run of its own model; the CSV's columns."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    values = np.array([-2.0, -1.75, -1.6])              # A on the coupler: b = 1.75 - x
    names = ["joint.O4.points.1.0", "joint.B.points.1.0"]
    specs = [RATIO, "transmission_angle:B", "dead_centre_distance", ADVANTAGE]
    ds = mbd2d.sweep(m, {"joint.A.points.1.0": values}, t_end=1.0, steps=36, tol=1e-14,
                     workers=1, sensitivities=names, measures=specs)
    assert ds.dmeasures_dp.dims == ("case", "time", "measure", "parameter")
    t = ds.time.values
    for k, x in enumerate(values):
        b = 1.75 - x
        links = {names[0]: lambda e: (1.0, b, 2.5, 3.0 + e),
                 names[1]: lambda e: (1.0, b, 2.5 - e, 3.0)}
        for j, name in enumerate(names):
            e3, e4 = _h2(ds.dmeasures_dp.values[k, :, 0, j], ratio_fourbar, links[name], t)
            assert e4 < 1e-8 and e4 < e3 / 50, (k, name, e3, e4)
        one = m.with_params({"joint.A.points.1.0": float(x)}).kinematics(
            1.0, 36, tol=1e-14, sensitivities=names)
        assert np.array_equal(ds.dmeasures_dp.values[k], measure_derivatives(one, specs))
    mbd2d.write_sweep(ds, tmp_path / "s.csv")
    with open(tmp_path / "s.csv", newline="") as f:
        header, *rows = list(csv.reader(f))
    col = [float(r[header.index(f"d({ADVANTAGE})/d({names[1]})")]) for r in rows]
    assert np.array_equal(col, ds.dmeasures_dp.values[:, :, 3, 1].ravel())


def test_random_sweeps_equal_single_runs_bit_for_bit():
    """Random sweeps (tests/test_standalone_random_sweep.py's draws with measures and
    sensitivities; dynamics by dopri5): every completed case's dmeasures_dp equals its own
    single run's measure_derivatives bit for bit, and a failed case fails alone too."""
    import random
    import warnings
    pytest.importorskip("xarray")
    from test_standalone_random_sweep import _draw
    drawn = 0
    for seed in range(400):
        name, cases, analysis, kw = _draw(random.Random(seed))
        if "sensitivities" not in kw or "measures" not in kw or \
                (analysis != "kinematics" and name != "fourbar_masses.toml"):   # (no masses)
            continue
        kw["method"] = "dopri5" if analysis == "dynamics" else kw.get("method")
        kw = {k: v for k, v in kw.items() if v is not None}
        m = mbd2d.load(EX / name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = mbd2d.sweep(m, cases, analysis, workers=1, progress=False, **kw)
            for k in range(ds.sizes["case"]):
                one = m.with_params({n: float(ds[n].values[k]) for n in cases})
                single = {a: v for a, v in kw.items() if a != "measures"}
                try:
                    d = measure_derivatives(getattr(one, analysis)(**single), kw["measures"])
                except mbd2d.MbdError:
                    assert ds.status.values[k] != 0
                    continue
                assert ds.status.values[k] == 0
                assert np.array_equal(ds.dmeasures_dp.values[k], d), (seed, k)
        drawn += 1
        if drawn == 12:
            break
    assert drawn == 12


@pytest.mark.parametrize("model", ["cam_follower.toml", "door_two_hinges.toml",
                                   "fourbar_seed.toml", "fourbar_redundant.toml",
                                   "slider_crank.toml"])
def test_every_joint_type_against_ordinary_runs(model):
    """The velocity ratio to the last coordinate (a cam's contact angle, a hinge's door, a
    slider's travel) and the dead-centre distance, for every geometric and driver parameter
    of each example (revolute, translational, cam with roller, distance, harmonic and
    polynomial drivers), against central differences of ordinary runs (relative 1e-8).
    Left out: the dead-centre distance along the cam's radius, which sits at a power of 2,
    the model's length scale L: the distance, measured in L, jumps there (L <= size < 2 L;
    the derivative is the one at fixed L)."""
    import warnings
    from mbd2d.results.measures import measure
    m = mbd2d.load(EX / model)
    driver = next(c.name for c in m.constraints if c.is_driver)
    p0 = m.parameters()
    names = [n for n, v in p0.items() if v is not None
             and not n.startswith(("body.", "force.", "model."))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = m.kinematics(0.5, 10, tol=1e-13, sensitivities=names)
        out = base.coordinate_names[-1] if model != "slider_crank.toml" else "slider.x"
        specs = [f"velocity_ratio:{driver}:{out}", "dead_centre_distance"]
        d = measure_derivatives(base, specs)
        checked = 0
        for k, name in enumerate(names):
            h = 1e-6 * max(1.0, abs(p0[name]))
            try:
                hi, lo = (m.with_params({name: p0[name] + s * h}).kinematics(0.5, 10, tol=1e-13)
                          for s in (1, -1))
            except mbd2d.MbdError:        # a redundant tie made inconsistent: no neighbours
                continue
            for j, spec in enumerate(specs):
                if spec == "dead_centre_distance" and name.endswith("circle.radius"):
                    continue
                fd = (measure(hi, spec) - measure(lo, spec)) / (2 * h)
                err = np.abs(d[:, j, k] - fd) / np.maximum(1.0, np.abs(fd))
                assert err.max() < 1e-8, (name, spec, err.max())
            checked += 1
    assert checked >= 4          # (the two hinges: only the driver moves them consistently)


def test_cli_sweep_prints_the_derivatives_ranges(tmp_path, capsys):
    """`mbd2d sweep --measure --sensitivities`: each measure's derivative range over the
    cases, as the written file's column has it."""
    out = tmp_path / "w.csv"
    assert main(["sweep", str(EX / "fourbar_grashof.toml"), "--param",
                 "joint.B.points.0.0=1.5:2.0:3", "--t-end", "1", "--steps", "20", "--measure",
                 RATIO, "--sensitivities", "joint.O4.points.1.0", "--workers", "1", "--out",
                 str(out)]) == 0
    text = capsys.readouterr().out
    label = f"d({RATIO})/d(joint.O4.points.1.0)"
    line = next(ln for ln in text.splitlines() if ln.strip().startswith(label + ":"))
    with open(out, newline="") as f:
        header, *rows = list(csv.reader(f))
    col = np.array([float(r[header.index(label)]) for r in rows])
    assert f"from {col.min():.6g}" in line and f"to {col.max():.6g}" in line


def coupler_point(t: np.ndarray, a: float, xa: float, xb: float, c: float, d: float
                  ) -> np.ndarray:
    """The crank-rocker's coupler point (0, 1) (coupler frame: A at (xa, 0), B at (xb, 0)):
    P = A + R(th3) (-xa, 1), (n, 2)."""
    pa, pb = loop(t, a, xb - xa, c, d)
    th3 = np.arctan2(pb[1] - pa[1], pb[0] - pa[0])
    return (pa + np.stack([np.cos(th3) * -xa - np.sin(th3), np.sin(th3) * -xa + np.cos(th3)])).T


POINT_LINKS = {"joint.O4.points.1.0": lambda e: (1.0, -1.75, 1.75, 2.5, 3.0 + e),
               "joint.A.points.1.0": lambda e: (1.0, -1.75 + e, 1.75, 2.5, 3.0),
               "joint.B.points.1.0": lambda e: (1.0, -1.75, 1.75, 2.5 - e, 3.0),
               "joint.A.points.0.0": lambda e: (1.0 + e, -1.75, 1.75, 2.5, 3.0),
               "joint.B.points.0.0": lambda e: (1.0, -1.75, 1.75 + e, 2.5, 3.0)}


def test_point_dp_against_the_closed_form_and_ordinary_runs():
    """res.point_dp: the coupler point's position derivatives against the closed form
    differentiated (the gap falls as h^2), its velocity's and acceleration's against central
    differences of ordinary runs."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    names = list(POINT_LINKS)
    res = m.kinematics(1.0, 48, sensitivities=names, tol=1e-14)
    assert_allclose(res.point("coupler", (0.0, 1.0)).r,
                    coupler_point(res.t, 1.0, -1.75, 1.75, 2.5, 3.0), atol=1e-12)
    dr = res.point_dp("coupler", (0.0, 1.0))
    assert dr.shape == (49, 2, len(names))
    p0 = m.parameters()
    for k, name in enumerate(names):
        e3, e4 = (np.abs(dr[:, :, k] - central(coupler_point, POINT_LINKS[name], res.t, h)).max()
                  for h in (1e-3, 1e-4))
        assert e4 < 1e-8 and e4 < e3 / 50, (name, e3, e4)
        h = 1e-5
        hi, lo = (m.with_params({name: p0[name] + s * h}).kinematics(1.0, 48, tol=1e-14)
                  .point("coupler", (0.0, 1.0)) for s in (1, -1))
        for of in ("v", "a"):
            fd = (getattr(hi, of) - getattr(lo, of)) / (2 * h)
            got = res.point_dp("coupler", (0.0, 1.0), of=of)[:, :, k]
            assert np.abs(got - fd).max() < 1e-7 * max(1.0, np.abs(fd).max()), (name, of)


def test_point_dp_refusals():
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(1.0, 4)
    with pytest.raises(mbd2d.ModelError, match="no sensitivities"):
        res.point_dp("coupler", (0, 1))
    res = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(
        1.0, 4, sensitivities=["joint.O4.points.1.0"])
    with pytest.raises(KeyError):
        res.point_dp("nobody", (0, 1))
    with pytest.raises(KeyError):
        res.point_dp("coupler", (0, 1), of="jerk")
    with pytest.raises(mbd2d.ModelError):
        res.point_dp("coupler", (0, "x"))


def test_tolerance_contributions_against_the_law_of_cosines(tmp_path, capsys):
    """Each parameter's share of the transmission angle's first-order variance: (dmu/dp_k
    sigma_k)**2 / sum over the parameters, with dmu/dp from the law of cosines; a point's
    shares add to 1; the command line names the largest."""
    from test_angle_sensitivity import mu_fourbar
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    sigma = {"joint.O4.points.1.0": 2e-3, "joint.A.points.0.0": 1e-3,
             "joint.B.points.1.0": 1.5e-3}
    tol = mbd2d.tolerance(m, sigma, samples=0, t_end=1.0, steps=36,
                          measures=["transmission_angle:B"])
    share = tol.contributions("measures", "transmission_angle:B")
    assert share.dims == ("time", "parameter") and list(share.parameter.values) == list(sigma)
    t = share.time.values
    v = np.column_stack([(central(mu_fourbar, FOURBAR[n], t, 1e-4) * s) ** 2
                         for n, s in sigma.items()])
    assert_allclose(share.values, v / v.sum(axis=1, keepdims=True), atol=1e-7)
    pt = tol.point("coupler", (0.0, 1.0))
    assert_allclose(pt.x_share.sum("parameter").values, 1.0, rtol=1e-12)
    with pytest.raises(mbd2d.ModelError, match="no output"):
        tol.contributions("lam", "x")
    with pytest.raises(mbd2d.ModelError, match="no entry"):
        tol.contributions("q", "nobody.x")
    assert main(["tolerance", str(EX / "fourbar_grashof.toml"), "--samples", "0",
                 "--t-end", "1", "--steps", "36", "--measure", "transmission_angle:B",
                 "--out", str(tmp_path / "t.csv")]
                + [a for n, s in sigma.items() for a in ("--sigma", f"{n}={s}")]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines()
                if ln.strip().startswith("transmission_angle:B"))
    k = int(np.argmax(np.sqrt(v.sum(axis=1))))
    j = int(np.argmax(v[k]))
    assert f"mostly {list(sigma)[j]} ({100 * v[k, j] / v[k].sum():.0f}%)" in line
