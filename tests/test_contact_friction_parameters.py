"""Contacts' and joint frictions' numbers as design parameters (issue 10, section 1: every
numeric entry a designer may vary has a name): names, with_params, and sweeps over them,
each case against a closed form written here without mbd2d: a block sliding down an incline
(s = -g (sin a - mu cos a) t^2 / 2, or at rest when mu_static > tan a) and a ball on the
linear contact law (an undamped clamped spring, contact time pi sqrt(m / k); with damping it
rebounds with the restitution e exactly)."""
from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.description.toml_io import dumps

pytest.importorskip("xarray")

G = 9.81
M = 2.0
R = 0.1


def incline(alpha: float = 0.3) -> mbd2d.Model:
    m = mbd2d.Model("incline")
    u = [math.cos(alpha), math.sin(alpha)]
    m.add_body("block", q0=[0.0, 0.0, 0.0], mass=M, inertia=0.1)
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [u, u], name="slide",
                        friction={"mu": 0.1, "mu_static": 0.12, "model": "stick-slip"})
    return m


def ball(law: str = "linear", e: float = 1.0, k: float = 1e6, v0: float = 3.0,
         h0: float = 0.2) -> mbd2d.Model:
    """A 1 kg ball falling at v0 without gravity onto a floor at y = 0."""
    m = mbd2d.Model("ball", gravity=[0.0, 0.0])
    m.add_body("ball", q0=[0.0, h0, 0.0], mass=1.0, inertia=0.4 * R * R, v0=[0.0, -v0, 0.0])
    m.add_contact("circle-line", ["ball", "ground"], circle={"center": [0, 0], "radius": R},
                  line={"point": [0.0, 0.0], "normal": [0.0, 1.0]},
                  law={"model": law, "stiffness": k, "restitution": e}, name="floor")
    return m


def test_names_values_and_with_params():
    """The friction of a translational joint (no pin radius), a revolute's (with it), and a
    contact's law, friction and geometry are named by their TOML keys with the model's
    values; the linear law's exponent (fixed at 1) is not a parameter; with_params sets them
    in a copy, which its TOML keeps."""
    p = incline().parameters()
    assert {k: v for k, v in p.items() if ".friction." in k} == {
        "joint.slide.friction.mu": 0.1, "joint.slide.friction.mu_static": 0.12,
        "joint.slide.friction.threshold": 0.0}
    pend = mbd2d.Model("pendulum")
    pend.add_body("bob", q0=[0.5, 0.0, 0.0], mass=1.0, inertia=0.1)
    pend.add_revolute(["ground", "bob"], [[0, 0], [-0.5, 0]], name="pin",
                      friction={"mu": 0.2, "pin_radius": 0.01})
    assert pend.parameters()["joint.pin.friction.pin_radius"] == 0.01
    b = ball()
    q = {k: v for k, v in b.parameters().items() if k.startswith("contact.")}
    assert q == {"contact.floor.law.stiffness": 1e6, "contact.floor.law.restitution": 1.0,
                 "contact.floor.friction.mu": 0.0, "contact.floor.friction.mu_static": 0.0,
                 "contact.floor.friction.threshold": 0.0,
                 "contact.floor.circle.center.0": 0.0, "contact.floor.circle.center.1": 0.0,
                 "contact.floor.circle.radius": R, "contact.floor.line.point.0": 0.0,
                 "contact.floor.line.point.1": 0.0, "contact.floor.line.normal.0": 0.0,
                 "contact.floor.line.normal.1": 1.0}
    hertz = ball("hertz").parameters()
    assert "contact.floor.law.exponent" in hertz
    assert "contact.floor.law.restitution" not in hertz        # elastic by definition
    new = b.with_params({"contact.floor.law.stiffness": 2e6, "contact.floor.circle.radius": 0.2})
    assert b.parameters()["contact.floor.law.stiffness"] == 1e6
    back = mbd2d.loads(dumps(new)).parameters()
    assert back["contact.floor.law.stiffness"] == 2e6
    assert back["contact.floor.circle.radius"] == 0.2
    with pytest.raises(mbd2d.ModelError, match="did you mean.*friction.mu"):
        incline().with_params({"joint.slide.friction.muu": 0.2})


def test_friction_sweep_against_the_incline():
    """Five (mu, mu_static) cases in one sweep: sliding ones follow s = -a t^2/2 with
    a = g (sin a - mu cos a) (stick-slip, dopri5 at rtol 1e-10, to 1e-8 m), those with
    mu_static > tan(0.3) = 0.309 stay at rest; each case equals its with_params run bit for
    bit."""
    alpha = 0.3
    m = incline(alpha)
    mu = np.array([0.0, 0.1, 0.2, 0.3, 0.3])
    mus = np.array([0.0, 0.15, 0.25, 0.32, 0.5])
    cases = {"joint.slide.friction.mu": mu, "joint.slide.friction.mu_static": mus}
    ds = mbd2d.sweep(m, cases, analysis="dynamics", t_end=1.0, steps=20, rtol=1e-10,
                     atol=1e-12)
    t = ds["time"].values
    for k in range(len(mu)):
        assert int(ds["status"].values[k]) == 0
        q = ds["q"].values[k]
        s = q[:, 0] * math.cos(alpha) + q[:, 1] * math.sin(alpha)
        a = G * (math.sin(alpha) - mu[k] * math.cos(alpha)) if mus[k] < math.tan(alpha) \
            else 0.0
        np.testing.assert_allclose(s, -0.5 * a * t**2, atol=1e-8)
        one = m.with_params({n: v[k] for n, v in cases.items()}).dynamics(
            1.0, 20, rtol=1e-10, atol=1e-12)
        np.testing.assert_array_equal(one.q, q)


def test_contact_sweeps_against_the_linear_law():
    """Stiffness (undamped): the ball leaves the floor after pi sqrt(m / k) at its impact
    speed, so y(t_end) = R + v0 (t_end - t_on - pi sqrt(m / k)); restitution: it rebounds at
    e v0 exactly (the linear law's damping is chosen for that). A case with restitution 1.5
    fails alone, its message naming the restitution."""
    v0, h0, t_end = 3.0, 0.2, 0.2
    ks = np.array([1e4, 1e5, 1e6])
    ds = mbd2d.sweep(ball(), {"contact.floor.law.stiffness": ks}, analysis="dynamics",
                     t_end=t_end, steps=10, rtol=1e-10, atol=1e-13)
    t_on = (h0 - R) / v0
    y_end = R + v0 * (t_end - t_on - math.pi * np.sqrt(1.0 / ks))
    np.testing.assert_allclose(ds["q"].values[:, -1, 1], y_end, atol=1e-8)
    np.testing.assert_allclose(ds["qd"].values[:, -1, 1], v0, atol=1e-8)
    es = np.array([0.9, 0.5, 1.5, 0.2])
    ds = mbd2d.sweep(ball(e=0.5), {"contact.floor.law.restitution": es}, analysis="dynamics",
                     t_end=t_end, steps=10, rtol=1e-10, atol=1e-13)
    status = ds["status"].values
    assert list(status == 0) == [True, True, False, True]
    assert "restitution" in str(ds["message"].values[2])
    ok = status == 0
    np.testing.assert_allclose(ds["qd"].values[ok, -1, 1], es[ok] * v0, rtol=1e-7)


def test_sensitivities_to_them_are_refused_with_the_reason():
    with pytest.raises(mbd2d.ModelError, match="contacts or joint friction"):
        incline().dynamics(0.5, 5, sensitivities=["joint.slide.friction.mu"])


def test_cli_sweep_over_a_friction_coefficient(tmp_path: Path):
    """``mbd2d sweep --param joint.slide.friction.mu=...`` writes the cases' rows."""
    path = tmp_path / "incline.toml"
    path.write_text(dumps(incline()))
    out = tmp_path / "sweep.csv"
    r = subprocess.run([sys.executable, "-m", "mbd2d", "sweep", str(path), "--param",
                        "joint.slide.friction.mu=0:0.2:3", "--analysis", "dynamics",
                        "--t-end", "0.5", "--steps", "5", "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    text = out.read_text().splitlines()
    assert "joint.slide.friction.mu" in text[0]
    assert len(text) == 1 + 3 * 6


def every_contact() -> mbd2d.Model:
    """One model with every contact type and follower and profile kind, and friction on a
    revolute and a translational joint (not meant to move: for its file and its names)."""
    m = mbd2d.Model("contacts")
    for k, name in enumerate(("a", "b", "c", "d")):
        m.add_body(name, q0=[float(k), 1.0, 0.0], mass=1.0, inertia=0.1)
    m.add_revolute(["ground", "a"], [[0, 0], [0, -1]], name="pin",
                   friction={"mu": 0.2, "mu_static": 0.3, "model": "stick-slip",
                             "pin_radius": 0.01, "threshold": 1e-3})
    m.add_translational(["ground", "b"], [[1, 0], [0, -1]], [[0, 1], [0, 1]], name="slot",
                        friction={"mu": 0.1})
    law = {"model": "hunt-crossley", "stiffness": 1e6, "exponent": 1.4, "restitution": 0.7}
    m.add_contact("circle-line", ["c", "ground"], circle={"center": [0.1, 0], "radius": 0.2},
                  line={"point": [0, -1], "normal": [0, 1]}, law=law,
                  friction={"mu": 0.3, "threshold": 2e-3}, name="floor")
    m.add_contact("circle-circle", ["c", "d"], circle=[{"center": [0, 0], "radius": 0.1},
                                                       {"center": [0, 0.1], "radius": 0.2}],
                  law={"model": "linear", "stiffness": 1e5, "restitution": 0.5}, name="discs")
    m.add_contact("circle-in-circle", ["a", "b"], circle=[{"center": [0, 0], "radius": 0.1},
                                                          {"center": [0, 0], "radius": 0.12}],
                  law={"model": "hertz", "stiffness": 1e8}, name="clearance")
    kinds = [({"circle": {"center": [0.01, 0.0], "radius": 0.04}},
              {"roller": {"center": [0.0, 0.0], "radius": 0.01}}),
             ({"spline": {"points": [[0.05, 0.0], [0.0, 0.04], [-0.05, 0.0], [0.0, -0.05]]}},
              {"flat": {"point": [0.0, 0.0], "normal": [0.0, -1.0]}}),
             ({"fourier": {"center": [0.0, 0.0], "a": [0.05, 0.01], "b": [0.005]}},
              {"point": [0.0, 0.001]})]
    for k, (profile, follower) in enumerate(kinds):
        m.add_contact("follower-profile", ["a", "d"], profile=profile, follower=follower,
                      law={"model": "flores", "stiffness": 1e9, "restitution": 0.9},
                      name=f"cam{k}")
    return m


def test_every_contact_and_friction_survives_the_model_file():
    """dumps writes the contacts and the joints' frictions (it dropped both, so a model
    written by ``mbd2d synthesize`` or ``toml_io.dump`` lost them): the file read back has
    the same parameters, and writing it again gives the same text."""
    m = every_contact()
    text = dumps(m)
    back = mbd2d.loads(text)
    assert back.parameters() == m.parameters()
    assert dumps(back) == text
    names = m.parameters()
    for name in ("joint.pin.friction.pin_radius", "joint.slot.friction.mu",
                 "contact.discs.circle.1.radius", "contact.clearance.law.exponent",
                 "contact.cam0.profile.circle.center.0", "contact.cam0.follower.roller.radius",
                 "contact.cam1.profile.spline.points.3.1", "contact.cam1.follower.flat.normal.1",
                 "contact.cam2.profile.fourier.b.0", "contact.cam2.follower.point.1"):
        assert name in names, name
    assert "contact.discs.law.exponent" not in names               # linear: 1
    assert names["contact.cam2.profile.fourier.a.1"] == 0.01
    new = m.with_params({"contact.cam1.profile.spline.points.3.1": -0.06,
                         "contact.floor.friction.threshold": 5e-3})
    back = mbd2d.loads(dumps(new)).parameters()
    assert back["contact.cam1.profile.spline.points.3.1"] == -0.06
    assert back["contact.floor.friction.threshold"] == 5e-3


def test_follower_profile_geometry_as_a_parameter():
    """A driven cam (eccentric circle, eccentricity e) on a follower-profile contact with a
    roller: with the eccentricity set by its name, the penetration R + r - |F - C| equals
    the closed form for each e."""
    ecc, rc, rr, y = 0.01, 0.04, 0.01, 0.048
    m = mbd2d.Model("driven-cam")
    m.add_body("cam", q0=[0, 0, 0], mass=1.0, inertia=1e-3)
    m.add_body("follower", q0=[0, y, 0], mass=0.5, inertia=1e-4)
    m.add_revolute(["ground", "cam"], [[0, 0], [0, 0]], name="pivot")
    m.add_translational(["ground", "follower"], [[0, 0], [0, 0]], [[0, 1], [0, 1]],
                        name="guide")
    m.add_driver("absolute", body="cam", coordinate="theta", f={"poly": [0.0, 3.0]},
                 name="motor")
    m.add_driver("relative-distance", joint="guide", f=y, name="lift")
    m.add_contact("follower-profile", ["cam", "follower"],
                  profile={"circle": {"center": [ecc, 0.0], "radius": rc}},
                  follower={"roller": {"center": [0.0, 0.0], "radius": rr}},
                  law={"model": "hertz", "stiffness": 1e9}, name="touch")
    es = [0.005, 0.01, 0.015]
    for e in es:
        res = m.with_params({"contact.touch.profile.circle.center.0": e}).inverse_dynamics(
            2.0, 50)
        th = 3.0 * res.t
        ref = rc + rr - np.hypot(e * np.cos(th), y - e * np.sin(th))
        np.testing.assert_allclose(res.contact("touch").penetration, ref, atol=1e-12)


def test_tolerance_of_friction_by_monte_carlo_against_the_incline():
    """A model with joint friction has no design sensitivities, so its tolerance report has
    the Monte Carlo columns alone (the attribute first_order says why): the slide's scatter
    over the drawn mu (tolerance_samples: the same draws) is that of the closed form
    s = -g (sin a - mu cos a) t^2 / 2 over them, at two tolerances (measured 2e-14 at both:
    dopri5 integrates the quadratic exactly between the stick-slip events); a point of the block has
    the same; variance shares and samples=0 are refused with the reason."""
    m = incline()
    alpha, sig = 0.3, {"joint.slide.friction.mu": 0.004}
    mu = mbd2d.tolerance_samples(m, sig, samples=30)["joint.slide.friction.mu"]
    for rtol in (1e-6, 1e-10):                  # constant acceleration: dopri5 is exact
        tol = 1e-9
        rep = mbd2d.tolerance(m, sig, analysis="dynamics", samples=30, t_end=0.5, steps=5,
                              rtol=rtol, atol=rtol * 1e-2, workers=1)
        ds = rep.dataset
        assert "q_std_linear" not in ds and "slide" in ds.attrs["first_order"]
        assert ds.attrs["failed"] == 0
        t = ds["time"].values
        s = -0.5 * G * (math.sin(alpha) - np.outer(mu, np.ones_like(t)) * math.cos(alpha)) * t**2
        for j, u in enumerate((math.cos(alpha), math.sin(alpha))):
            ref = np.std(s * u, axis=0, ddof=1)
            np.testing.assert_allclose(ds["q_std_mc"].values[:, j], ref, rtol=tol, atol=1e-12)
            np.testing.assert_allclose(ds["q_mean_mc"].values[:, j], np.mean(s * u, axis=0),
                                       rtol=tol, atol=1e-12)
        pt = rep.point("block", (0.1, 0.0))
        assert "x_std_linear" not in pt
        np.testing.assert_allclose(pt["x_std_mc"].values, ds["q_std_mc"].values[:, 0],
                                   rtol=1e-12, atol=1e-15)
    assert "Monte Carlo only" in repr(rep)
    with pytest.raises(mbd2d.ModelError, match="first-order column"):
        rep.contributions("q", "block.x")
    with pytest.raises(mbd2d.ModelError, match="samples >= 2"):
        mbd2d.tolerance(m, sig, analysis="dynamics", samples=0, t_end=0.5, steps=5)


def test_tolerance_of_a_contact_stiffness_against_the_linear_law():
    """The ball leaves the floor after pi sqrt(m / k): over the drawn stiffnesses
    y(t_end) = R + v0 (t_end - t_on - pi sqrt(1 / k)), whose sample spread the report's Monte
    Carlo column has; the rebound speed is v0 whatever k (spread below 1e-8)."""
    v0, h0, t_end = 3.0, 0.2, 0.2
    sig = {"contact.floor.law.stiffness": 5e4}
    ks = mbd2d.tolerance_samples(ball(), sig, samples=20)["contact.floor.law.stiffness"]
    ds = mbd2d.tolerance(ball(), sig, analysis="dynamics", samples=20, t_end=t_end, steps=10,
                         rtol=1e-10, atol=1e-13, workers=1).dataset
    y_end = R + v0 * (t_end - (h0 - R) / v0 - math.pi * np.sqrt(1.0 / ks))
    np.testing.assert_allclose(ds["q_std_mc"].values[-1, 1], np.std(y_end, ddof=1), rtol=1e-6)
    assert ds["qd_std_mc"].values[-1, 1] < 1e-8
    assert "floor" in ds.attrs["first_order"]


def test_cli_tolerance_of_a_friction_model(tmp_path: Path, capsys):
    """`mbd2d tolerance` on the incline: the summary names the Monte Carlo standard
    deviation and why there is no first-order one; the CSV has the Monte Carlo columns, whose
    last row is the closed form's spread over the same draws."""
    from mbd2d.cli import main
    toml = tmp_path / "incline.toml"
    toml.write_text(dumps(incline()))
    out = tmp_path / "tol.csv"
    sig = {"joint.slide.friction.mu": 0.004}
    assert main(["tolerance", str(toml), "--sigma", "joint.slide.friction.mu=0.004",
                 "--samples", "20", "--analysis", "dynamics", "--t-end", "0.5", "--steps", "5",
                 "--rtol", "1e-10", "--atol", "1e-12", "--workers", "1",
                 "--point", "block:0.1,0", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "largest Monte Carlo standard deviation" in text and "joint friction" in text
    header = out.read_text().splitlines()[0].split(",")
    assert not [h for h in header if "std_linear" in h]
    rows = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    mu = mbd2d.tolerance_samples(incline(), sig, samples=20)["joint.slide.friction.mu"]
    s = -0.5 * G * (math.sin(0.3) - mu * math.cos(0.3)) * 0.5**2
    ref = np.std(s * math.cos(0.3), ddof=1)
    assert rows[-1, header.index("block.x.std_mc")] == pytest.approx(ref, rel=1e-6)
    assert rows[-1, header.index("block(0.1;0).x.std_mc")] == pytest.approx(ref, rel=1e-6)
