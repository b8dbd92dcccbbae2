"""Kinematics against closed-form solutions over a full crank (cam) turn.

The oracles are derived here by hand: loop closure in closed form for positions, the
differentiated loop equations solved analytically (Cramer) for velocities and
accelerations, and analytic derivatives of the lift laws for the cams. Each oracle is
itself checked against finite differences of its own positions (loosely, just to catch a
slip in the algebra), then the engine is held to a worst error of 1e-9.

The worst error of every comparison is printed (run pytest with -s to see them).
"""
from __future__ import annotations

import numpy as np
import pytest

from conftest import load_example, model_from_toml, wrap_angle

TWO_PI = 2.0 * np.pi
TOL = 1e-9
STEPS = 360


def report(label: str, err: float) -> None:
    print(f"\n[closed-form] {label:48s} worst error {err:.3e}", end="")


def worst(actual: np.ndarray, expected: np.ndarray, angle: bool = False) -> float:
    d = np.asarray(actual) - np.asarray(expected)
    if angle:
        d = wrap_angle(d)
    return float(np.max(np.abs(d)))


def check(label: str, actual: np.ndarray, expected: np.ndarray, angle: bool = False) -> float:
    err = worst(actual, expected, angle)
    report(label, err)
    assert err <= TOL, f"{label}: worst error {err:.3e} > {TOL:g}"
    return err


def oracle_self_check(t: np.ndarray, pos: np.ndarray, vel: np.ndarray, acc: np.ndarray,
                      what: str) -> None:
    """The oracle's velocity and acceleration agree with differences of its own positions
    and velocities (catches algebra slips in the oracle, not in the engine)."""
    dt = t[1] - t[0]
    v_fd = (pos[2:] - pos[:-2]) / (2 * dt)
    a_fd = (vel[2:] - vel[:-2]) / (2 * dt)
    # central-difference truncation with dt = 1/360 is ~ dt^2/6 |x'''| ~ 1e-3 relative
    assert np.max(np.abs(v_fd - vel[1:-1])) <= 2e-3 * max(1.0, np.abs(vel).max()), what
    assert np.max(np.abs(a_fd - acc[1:-1])) <= 2e-3 * max(1.0, np.abs(acc).max()), what


def e(a: np.ndarray) -> np.ndarray:
    """Unit vectors (cos a, sin a), shape (n, 2)."""
    return np.column_stack([np.cos(a), np.sin(a)])


def p(a: np.ndarray) -> np.ndarray:
    """Unit vectors turned +90 degrees, (-sin a, cos a)."""
    return np.column_stack([-np.sin(a), np.cos(a)])


# ====================================================================== four-bar

def fourbar_closed_form(t: np.ndarray) -> dict[str, np.ndarray]:
    """Crank a = 1 about O2 = (0, 0), coupler b = 3.5, rocker c = 2.5, O4 = (d, 0), d = 3.

    Loop: a e2 + b e3 + c e4 = (d, 0), where e4 points from B to O4 (the rocker's local
    x axis in the example: its point [-1.25, 0] is at B and [1.25, 0] at O4).
    Positions: B on the circle of radius b about A and radius c about O4; the example
    starts with B on the left of the line A -> O4 (coupler angle 0.78 at t = 0), so
    theta3 = angle(O4 - A) + arccos((b^2 + f^2 - c^2) / (2 b f)), f = |O4 - A|.
    Grashof crank-rocker: 2 <= f <= 4 stays inside (b - c, b + c) = (1, 6), so this one
    branch is valid for the whole turn.
    """
    a, b, c, d = 1.0, 3.5, 2.5, 3.0
    w2 = TWO_PI
    th2 = w2 * t
    A = a * e(th2)
    D = np.array([d, 0.0]) - A
    f = np.hypot(D[:, 0], D[:, 1])
    delta = np.arctan2(D[:, 1], D[:, 0])
    th3 = delta + np.arccos((b * b + f * f - c * c) / (2 * b * f))
    B = A + b * e(th3)
    E4 = np.array([d, 0.0]) - B
    th4 = np.arctan2(E4[:, 1], E4[:, 0])
    # velocities: a w2 p2 + b w3 p3 + c w4 p4 = 0; dot with e4 and e3 (p_i . e_j = sin(j - i))
    w3 = -a * w2 * np.sin(th4 - th2) / (b * np.sin(th4 - th3))
    w4 = -a * w2 * np.sin(th3 - th2) / (c * np.sin(th3 - th4))
    # accelerations (w2 constant): sum L_i (al_i p_i - w_i^2 e_i) = 0, dotted likewise
    al3 = (a * w2**2 * np.cos(th2 - th4) + b * w3**2 * np.cos(th3 - th4) + c * w4**2) \
        / (b * np.sin(th4 - th3))
    al4 = (a * w2**2 * np.cos(th2 - th3) + b * w3**2 + c * w4**2 * np.cos(th4 - th3)) \
        / (c * np.sin(th3 - th4))
    W = lambda x: x[:, None]  # noqa: E731  (column broadcast)
    # body centres (mid-links) and their derivatives
    crank = a / 2 * e(th2)
    crank_v = a / 2 * w2 * p(th2)
    crank_a = -a / 2 * w2**2 * e(th2)
    A_v = a * w2 * p(th2)
    A_a = -a * w2**2 * e(th2)
    coupler = A + b / 2 * e(th3)
    coupler_v = A_v + b / 2 * W(w3) * p(th3)
    coupler_a = A_a + b / 2 * (W(al3) * p(th3) - W(w3**2) * e(th3))
    rocker = np.array([d, 0.0]) - c / 2 * e(th4)
    rocker_v = -c / 2 * W(w4) * p(th4)
    rocker_a = -c / 2 * (W(al4) * p(th4) - W(w4**2) * e(th4))
    return {"th2": th2, "th3": th3, "th4": th4, "w2": np.full_like(t, w2), "w3": w3, "w4": w4,
            "al2": np.zeros_like(t), "al3": al3, "al4": al4,
            "crank": crank, "crank_v": crank_v, "crank_a": crank_a,
            "coupler": coupler, "coupler_v": coupler_v, "coupler_a": coupler_a,
            "rocker": rocker, "rocker_v": rocker_v, "rocker_a": rocker_a}


@pytest.fixture(scope="module")
def fourbar():
    res = load_example("fourbar_grashof.toml").kinematics(t_end=1.0, steps=STEPS)
    assert res.complete and len(res.t) == STEPS + 1
    return res, fourbar_closed_form(res.t)


def test_fourbar_oracle_is_consistent(fourbar):
    res, cf = fourbar
    t = res.t
    for th, w, al in (("th3", "w3", "al3"), ("th4", "w4", "al4")):
        oracle_self_check(t, np.unwrap(cf[th]), cf[w], cf[al], th)
    for name in ("crank", "coupler", "rocker"):
        oracle_self_check(t, cf[name], cf[name + "_v"], cf[name + "_a"], name)


@pytest.mark.parametrize("body,th,w,al", [("crank", "th2", "w2", "al2"),
                                          ("coupler", "th3", "w3", "al3"),
                                          ("rocker", "th4", "w4", "al4")])
def test_fourbar_angles(fourbar, body, th, w, al):
    res, cf = fourbar
    b = res.body(body)
    check(f"four-bar {body} theta", b.theta, cf[th], angle=True)
    check(f"four-bar {body} theta_dot", b.theta_dot, cf[w])
    check(f"four-bar {body} theta_ddot", b.theta_ddot, cf[al])


@pytest.mark.parametrize("body", ["crank", "coupler", "rocker"])
def test_fourbar_centres(fourbar, body):
    res, cf = fourbar
    b = res.body(body)
    check(f"four-bar {body} centre x, y", np.column_stack([b.x, b.y]), cf[body])
    check(f"four-bar {body} centre velocity", np.column_stack([b.x_dot, b.y_dot]),
          cf[body + "_v"])
    check(f"four-bar {body} centre acceleration", np.column_stack([b.x_ddot, b.y_ddot]),
          cf[body + "_a"])


def test_fourbar_angles_are_continuous(fourbar):
    """Angles are not wrapped between steps: no jump larger than the motion of one step."""
    res, _ = fourbar
    for body in ("crank", "coupler", "rocker"):
        jumps = np.abs(np.diff(res.body(body).theta))
        assert jumps.max() < 0.2, body


# ====================================================================== slider-crank

def slider_crank_closed_form(t: np.ndarray) -> dict[str, np.ndarray]:
    """Crank 1, rod 3, slider guide y = 0.5: sin(phi) = (0.5 - sin th) / 3 (rod angle,
    cos(phi) > 0), x_slider = cos th + 3 cos(phi) = cos th + sqrt(9 - (sin th - 0.5)^2)."""
    w = TWO_PI
    th = w * t
    s = (0.5 - np.sin(th)) / 3.0
    s1 = -np.cos(th) * w / 3.0
    s2 = np.sin(th) * w**2 / 3.0
    root = np.sqrt(1.0 - s * s)
    phi = np.arcsin(s)
    phi1 = s1 / root
    phi2 = s2 / root + s * s1**2 / root**3
    x = np.cos(th) + 3.0 * np.cos(phi)
    x1 = -np.sin(th) * w - 3.0 * np.sin(phi) * phi1
    x2 = -np.cos(th) * w**2 - 3.0 * (np.cos(phi) * phi1**2 + np.sin(phi) * phi2)
    # rod centre = A + 1.5 e(phi)
    rx = np.cos(th) + 1.5 * np.cos(phi)
    ry = np.sin(th) + 1.5 * np.sin(phi)
    rx1 = -np.sin(th) * w - 1.5 * np.sin(phi) * phi1
    ry1 = np.cos(th) * w + 1.5 * np.cos(phi) * phi1
    rx2 = -np.cos(th) * w**2 - 1.5 * (np.cos(phi) * phi1**2 + np.sin(phi) * phi2)
    ry2 = -np.sin(th) * w**2 + 1.5 * (-np.sin(phi) * phi1**2 + np.cos(phi) * phi2)
    return {"x": x, "x1": x1, "x2": x2, "phi": phi, "phi1": phi1, "phi2": phi2,
            "rod": np.column_stack([rx, ry]), "rod1": np.column_stack([rx1, ry1]),
            "rod2": np.column_stack([rx2, ry2])}


@pytest.fixture(scope="module")
def slider_crank():
    res = load_example("slider_crank.toml").kinematics(t_end=1.0, steps=STEPS)
    assert res.complete and len(res.t) == STEPS + 1
    return res, slider_crank_closed_form(res.t)


def test_slider_crank_oracle_is_consistent(slider_crank):
    res, cf = slider_crank
    oracle_self_check(res.t, cf["x"], cf["x1"], cf["x2"], "slider x")
    oracle_self_check(res.t, cf["phi"], cf["phi1"], cf["phi2"], "rod angle")
    oracle_self_check(res.t, cf["rod"], cf["rod1"], cf["rod2"], "rod centre")
    th = TWO_PI * res.t
    assert np.allclose(cf["x"], np.cos(th) + np.sqrt(9.0 - (np.sin(th) - 0.5) ** 2),
                       rtol=0, atol=1e-14)


def test_slider_crank_slider(slider_crank):
    res, cf = slider_crank
    s = res.body("slider")
    check("slider-crank slider x", s.x, cf["x"])
    check("slider-crank slider x_dot", s.x_dot, cf["x1"])
    check("slider-crank slider x_ddot", s.x_ddot, cf["x2"])
    # the guide holds y = 0.5 and theta = 0 exactly up to the solver tolerance
    check("slider-crank slider y, theta and rates",
          np.column_stack([s.y - 0.5, s.theta, s.y_dot, s.theta_dot, s.y_ddot, s.theta_ddot]),
          np.zeros((len(res.t), 6)))


def test_slider_crank_rod(slider_crank):
    res, cf = slider_crank
    r = res.body("rod")
    check("slider-crank rod theta", r.theta, cf["phi"], angle=True)
    check("slider-crank rod theta_dot", r.theta_dot, cf["phi1"])
    check("slider-crank rod theta_ddot", r.theta_ddot, cf["phi2"])
    check("slider-crank rod centre", np.column_stack([r.x, r.y]), cf["rod"])
    check("slider-crank rod centre velocity", np.column_stack([r.x_dot, r.y_dot]), cf["rod1"])
    check("slider-crank rod centre acceleration", np.column_stack([r.x_ddot, r.y_ddot]),
          cf["rod2"])


# ====================================================================== cams

CAM_R, CAM_E, ROLLER_R = 1.0, 0.4, 0.25
OMEGA = TWO_PI

CAM_TOML = """
[model]
name = "eccentric-cam-{kind}"

[[body]]
name = "cam"
q0 = [0.0, 0.0, 0.0]

[[body]]
name = "follower"
q0 = [0.0, 1.2, 0.0]

[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "cam"]
points = [[0.0, 0.0], [0.0, 0.0]]

[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "follower"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[0.0, 1.0], [0.0, 1.0]]

[[joint]]
name = "contact"
type = "cam"
bodies = ["cam", "follower"]
profile = {{ circle = {{ center = [{e}, 0.0], radius = {R} }} }}
follower = {follower}

[[driver]]
name = "motor"
type = "absolute"
body = "cam"
coordinate = "theta"
f = {{ poly = [0.0, {omega!r}] }}
"""

FOLLOWER_SPECS = {
    "flat": "{ flat = { point = [0.0, 0.0], normal = [0.0, -1.0] } }",
    "point": "{ point = [0.0, 0.0] }",
}


def cam_lift(t: np.ndarray, kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Follower lift y(t) and its derivatives for the eccentric circle cam, th = omega t.

    flat:   y = e sin th + R
    roller: y = e sin th + sqrt((R + r)^2 - e^2 cos^2 th)
    point:  the roller formula with r = 0.
    """
    th = OMEGA * t
    w = OMEGA
    base = CAM_E * np.sin(th)
    base1 = CAM_E * w * np.cos(th)
    base2 = -CAM_E * w**2 * np.sin(th)
    if kind == "flat":
        return base + CAM_R, base1, base2
    rr = ROLLER_R if kind == "roller" else 0.0
    g = (CAM_R + rr) ** 2 - CAM_E**2 * np.cos(th) ** 2
    g1 = CAM_E**2 * w * np.sin(2 * th)
    g2 = 2 * CAM_E**2 * w**2 * np.cos(2 * th)
    sq = np.sqrt(g)
    return (base + sq, base1 + g1 / (2 * sq), base2 + g2 / (2 * sq) - g1**2 / (4 * sq**3))


def cam_model(kind: str):
    if kind == "roller":
        return load_example("cam_follower.toml")
    return model_from_toml(CAM_TOML.format(kind=kind, e=CAM_E, R=CAM_R, omega=OMEGA,
                                           follower=FOLLOWER_SPECS[kind]))


@pytest.mark.parametrize("kind", ["roller", "flat", "point"])
def test_cam_follower_lift(kind):
    res = cam_model(kind).kinematics(t_end=1.0, steps=STEPS)
    assert res.complete and len(res.t) == STEPS + 1
    y, y1, y2 = cam_lift(res.t, kind)
    oracle_self_check(res.t, y, y1, y2, f"{kind} lift")
    f = res.body("follower")
    check(f"cam ({kind}) follower y", f.y, y)
    check(f"cam ({kind}) follower y_dot", f.y_dot, y1)
    check(f"cam ({kind}) follower y_ddot", f.y_ddot, y2)
    check(f"cam ({kind}) follower x, theta and rates",
          np.column_stack([f.x, f.theta, f.x_dot, f.theta_dot, f.x_ddot, f.theta_ddot]),
          np.zeros((len(res.t), 6)))
    c = res.body("cam")
    check(f"cam ({kind}) cam theta", c.theta, OMEGA * res.t, angle=True)


def test_cam_roller_example_matches_its_header_formula():
    """The example's documented parameters are the ones the oracle uses."""
    m = load_example("cam_follower.toml")
    contact = next(j for j in m.joints if j.name == "contact")
    assert contact.profile_kind == "circle" and contact.follower_kind == "roller"
    assert contact.profile == (CAM_E, 0.0, CAM_R)
    assert contact.follower[2] == ROLLER_R
