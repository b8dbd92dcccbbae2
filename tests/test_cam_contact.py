"""A cam follower that lifts off (issue 13): the inverse dynamics of a bilateral cam joint
report where the joint would have to pull, and a follower-profile contact in forward
dynamics leaves the profile there; both against the closed form of an eccentric circular
cam (y = e sin(theta) + sqrt((R + r)**2 - e**2 cos(theta)**2))."""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import mbd2d

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cam_liftoff.toml"
E, RC, RR, M, K, G = 0.01, 0.04, 0.01, 0.5, 200.0, 9.81
ANCHOR, L0 = 0.2, 0.18


def needed_force(t: np.ndarray | float, omega: float) -> np.ndarray | float:
    """Vertical force the cam must give the follower: M (y'' + g) - spring force."""
    th = omega * t
    a2 = (RC + RR)**2
    s = np.sqrt(a2 - E * E * np.cos(th)**2)
    y = E * np.sin(th) + s
    ypp = (-E * np.sin(th) + E * E * (np.cos(th)**2 - np.sin(th)**2) / s
           - E**4 * np.cos(th)**2 * np.sin(th)**2 / s**3)
    return M * (omega**2 * ypp + G) - K * (ANCHOR - y - L0)


def pull_starts(omega: float, t_end: float) -> list[float]:
    tt = np.linspace(0.0, t_end, 20001)
    v = needed_force(tt, omega)
    idx = np.flatnonzero((v[:-1] > 0) & (v[1:] <= 0))
    return [brentq(needed_force, tt[j], tt[j + 1], args=(omega,), xtol=1e-14) for j in idx]


def text_at(omega: float, law: str | None = None) -> str:
    text = EXAMPLE.read_text().replace("62.83185307179586", repr(omega))
    text = text.replace("0.6283185307179586", repr(omega * E))
    if law:
        text = text.split("law = {")[0] + f"law = {law}\n"
    return text


def bilateral(omega: float) -> mbd2d.Model:
    text = text_at(omega).split("[[contact]]")[0] + """
[[joint]]
name = "cam-joint"
type = "cam"
bodies = ["cam", "follower"]
profile = { circle = { center = [0.01, 0.0], radius = 0.04 } }
follower = { roller = { center = [0.0, 0.0], radius = 0.01 } }
"""
    return mbd2d.loads(text)


@pytest.mark.parametrize("rpm", [600.0, 800.0])
def test_inverse_dynamics_reports_where_the_cam_would_pull(rpm):
    omega = rpm * 2 * math.pi / 60
    with pytest.warns(mbd2d.LiftOffWarning, match="cam joint 'cam-joint'.*pulling force"):
        res = bilateral(omega).inverse_dynamics(0.2, 4000)
    starts = pull_starts(omega, 0.2)
    assert [x.joint for x in res.lift_off] == ["cam-joint"] * len(starts)
    np.testing.assert_allclose([x.t_start for x in res.lift_off], starts, atol=1e-7)
    assert all(x.min_force < 0 for x in res.lift_off)


def test_slow_cam_needs_no_pull():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = bilateral(300 * 2 * math.pi / 60).inverse_dynamics(0.2, 400)
    assert res.lift_off == []


def test_follower_leaves_the_profile_where_the_joint_would_pull():
    """The first separation of the follower-profile contact tends to the first pull of the
    bilateral joint as the contact stiffens (a compliant contact lags by its own dynamics)."""
    omega = 600 * 2 * math.pi / 60
    first = pull_starts(omega, 0.05)[0]
    errors = []
    for k in (1e7, 1e8):
        res = mbd2d.loads(text_at(omega, f'{{ model = "linear", stiffness = {k}, '
                                         'restitution = 0.3 }')).dynamics(0.05, 50)
        sep = [x for x in res.contacts if x.kind == "separation"][0]
        errors.append(sep.t - first)
    assert 0 < errors[1] < errors[0]
    assert errors[1] < 1e-4                         # 0.1 % of the cam's period
    res = mbd2d.load(EXAMPLE).dynamics(0.2, 400)   # the example (Hunt-Crossley) lifts off too
    assert any(x.kind == "separation" for x in res.contacts)


@pytest.mark.parametrize("follower", ["roller", "flat"])
def test_follower_profile_penetration_against_the_closed_form(follower):
    """With the cam and the follower driven, the contact's penetration is R + r - |F - C|
    (roller) or e sin(theta) + R - y (flat face at height y, normal down)."""
    fol = ('{ roller = { center = [0.0, 0.0], radius = 0.01 } }' if follower == "roller"
           else '{ flat = { point = [0.0, 0.0], normal = [0.0, -1.0] } }')
    m = mbd2d.Model("driven-cam")
    m.add_body("cam", q0=[0, 0, 0], mass=1.0, inertia=1e-3)
    m.add_body("follower", q0=[0, 0.048, 0], mass=0.5, inertia=1e-4)
    m.add_revolute(["ground", "cam"], [[0, 0], [0, 0]], name="pivot")
    m.add_translational(["ground", "follower"], [[0, 0], [0, 0]], [[0, 1], [0, 1]], name="guide")
    m.add_driver("absolute", body="cam", coordinate="theta", f={"poly": [0.0, 3.0]},
                 name="motor")
    m.add_driver("relative-distance", joint="guide", f={"poly": [0.048, 0.0, 0.0, 0.0]},
                 name="lift")
    import tomllib
    m.add_contact("follower-profile", ["cam", "follower"],
                  profile={"circle": {"center": [E, 0.0], "radius": RC}},
                  follower=tomllib.loads(f"f = {fol}")["f"],
                  law={"model": "hertz", "stiffness": 1e9}, name="touch")
    res = m.inverse_dynamics(2.0, 200)
    th = 3.0 * res.t
    y = 0.048
    if follower == "roller":
        ref = RC + RR - np.hypot(E * np.cos(th), y - E * np.sin(th))
    else:
        ref = E * np.sin(th) + RC - y
    np.testing.assert_allclose(res.contact("touch").penetration, ref, atol=1e-12)
    fn = res.contact("touch").normal_force
    np.testing.assert_allclose(fn, 1e9 * np.maximum(ref, 0.0)**1.5, rtol=1e-9, atol=1e-9)
    on = [x for x in res.contacts if x.kind == "onset"]
    assert on and all(abs(r) < 0.02 for r in np.interp([x.t for x in on], res.t, ref))


def test_the_example_runs_and_draws(tmp_path):
    import importlib.util
    spec = importlib.util.spec_from_file_location("cam_liftoff", EXAMPLE.with_suffix(".py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--out", str(tmp_path)]) == 0
    assert (tmp_path / "cam_liftoff_mechanism.png").stat().st_size > 10_000
    assert (tmp_path / "cam_liftoff_history.png").stat().st_size > 10_000
