"""Cam synthesis from a follower program (mbd2d.cam_profile).

References without the synthesis' own formulas: the engine's cam joint running the
synthesized spline profile (the follower's motion against the program's closed form, the
errors falling at the spline's order), the flat-faced follower's harmonic program whose cam
is exactly a circle, the pressure angle from the cam joint's reaction in inverse dynamics,
and the surface's curvature from periodic differences of its points.
"""
from __future__ import annotations

import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.results import read_csv
from test_derivatives import step_closed_form

EX = Path(__file__).resolve().parents[1] / "examples"

RISE = 0.02
PROGRAM = {"step": [{"t0": 0.0, "t1": math.pi / 2, "h": RISE},
                    {"t0": math.pi, "t1": 1.5 * math.pi, "h": -RISE, "law": "quintic"}]}
FOLLOWERS = [("roller", 0.01, 0.0), ("roller", 0.01, 0.01), ("roller", 0.0, 0.005),
             ("flat", 0.0, 0.0)]


def near_law_ends(theta: np.ndarray, program: dict) -> np.ndarray:
    """The samples within 3.5 sample spacings of a step's t0 or t1 (around the turn)."""
    near = np.zeros(len(theta), dtype=bool)
    for st in program["step"]:
        for tk in (st["t0"], st["t1"]):
            gap = np.abs((theta - tk + math.pi) % (2 * math.pi) - math.pi)
            near |= gap < 3.5 * 2 * math.pi / len(theta)
    return near


def program_exact(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """s and ds/dtheta of PROGRAM from the laws' closed forms."""
    vals = np.array([[sum(step_closed_form(st, float(t))[k] for st in PROGRAM["step"])
                      for k in (0, 1)] for t in theta])
    return vals[:, 0], vals[:, 1]


@pytest.mark.parametrize("follower, rr, e", FOLLOWERS)
def test_the_engine_moves_the_follower_by_the_program(follower: str, rr: float,
                                                      e: float) -> None:
    """The synthesized cam in the engine's cam joint (turning at 2 pi rad/s): the follower's
    lift and speed against the program, errors falling at the spline's order (lift: 13-18x
    per doubling of the points, 1.1e-12 to 5e-12 m at 1440 points for a 20 mm rise; speed:
    about 8x, 7e-9 to 4.3e-8 m/s of a 0.16 m/s peak; docs/synthesis.md)."""
    errs, verrs = [], []
    for n in (360, 720, 1440):
        d = mbd2d.cam_profile(PROGRAM, 0.05, follower=follower, roller_radius=rr, offset=e,
                              points=n)
        assert not d.undercut
        res = d.model(speed=2 * math.pi).kinematics(1.0, 400)
        s, ds = program_exact(2 * math.pi * res.t)
        fol = res.body("follower")
        errs.append(np.abs(fol.y - fol.y[0] - s).max())
        verrs.append(np.abs(fol.y_dot - 2 * math.pi * ds).max())
        assert np.abs(fol.x - fol.x[0]).max() < 1e-14       # on its guide
    assert errs[2] < 1e-11 and verrs[2] < 1e-7
    assert errs[0] / errs[1] > 10 and errs[1] / errs[2] > 10
    assert verrs[0] / verrs[1] > 5 and verrs[1] / verrs[2] > 5


def test_flat_follower_harmonic_program_is_a_circle() -> None:
    """s = eps (1 - cos theta) under a flat face is the eccentric circle: centre (0, -eps),
    radius base + eps, curvature radius base + eps everywhere."""
    eps, rb = 0.012, 0.04
    prog = {"poly": [eps], "harmonic": {"amplitude": -eps, "omega": 1.0, "phase": math.pi / 2}}
    d = mbd2d.cam_profile(prog, rb, follower="flat", points=64)
    r = np.hypot(d.points[:, 0], d.points[:, 1] + eps)
    np.testing.assert_allclose(r, rb + eps, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d.curvature_radius, rb + eps, rtol=1e-14)
    assert d.face == pytest.approx((-eps, eps), abs=1e-15) and not d.undercut
    assert d.max_pressure_angle == 0.0


@pytest.mark.parametrize("follower, rr, e", FOLLOWERS)
def test_curvature_against_differences_of_the_points(follower: str, rr: float,
                                                     e: float) -> None:
    """The surface's radius of curvature against periodic central differences of its
    points over theta (fourth-order stencils), 1e-6 relative."""
    n = 2880
    d = mbd2d.cam_profile(PROGRAM, 0.05, follower=follower, roller_radius=rr, offset=e,
                          points=n)
    h = 2 * math.pi / n

    def diff(a: np.ndarray, k: int) -> np.ndarray:
        r = [np.roll(a, -j, axis=0) for j in (-2, -1, 1, 2)]
        if k == 1:
            return (r[0] - 8 * r[1] + 8 * r[2] - r[3]) / (12 * h)
        return (-r[0] + 16 * r[1] - 30 * a + 16 * r[2] - r[3]) / (12 * h * h)

    p1, p2 = diff(d.points, 1), diff(d.points, 2)
    cross = p1[:, 0] * p2[:, 1] - p1[:, 1] * p2[:, 0]
    rho = -np.hypot(p1[:, 0], p1[:, 1])**3 / cross           # clockwise: convex > 0
    # away from the laws' acceleration jumps (the quintic's ends are smooth to s'')
    smooth = np.ones(n, dtype=bool)
    for st in PROGRAM["step"]:
        for tk in (st["t0"], st["t1"]):
            smooth &= np.abs((d.theta - tk + math.pi) % (2 * math.pi) - math.pi) > 4 * h
    np.testing.assert_allclose(rho[smooth], d.curvature_radius[smooth], rtol=1e-6)


def test_pressure_angle_from_the_cam_joints_reaction() -> None:
    """The angle between the cam joint's force on the follower and the follower's axis
    (inverse dynamics, frictionless) is the synthesis' pressure angle, at each sample."""
    n = 360
    d = mbd2d.cam_profile(PROGRAM, 0.05, roller_radius=0.01, offset=0.01, points=n)
    m = d.model(speed=2 * math.pi, masses={"cam": (0.5, 1e-3), "follower": (0.3, 1e-4)})
    m.add_spring(["ground", "follower"], [[0.01, 0.3], [0.0, 0.0]], stiffness=200.0,
                 length0=0.35, name="return")            # keeps the roller pressed
    res = m.inverse_dynamics(1.0, n)
    f = res.reaction("contact")
    assert np.all(f.fy_j[:-1] > 0)                       # the cam pushes the follower up
    angle = np.arctan2(-f.fx_j[:-1], f.fy_j[:-1])
    # the spline's normal is exact to O(h^3) where the program is smooth and to O(h^2) next
    # to the laws' ends (a jump of the third or second derivative of s): measured 1e-7 and
    # 2.2e-6 rad at 360 points
    near = near_law_ends(d.theta, PROGRAM)
    np.testing.assert_allclose(angle[~near], d.pressure_angle[~near], rtol=0, atol=2e-7)
    np.testing.assert_allclose(angle, d.pressure_angle, rtol=0, atol=5e-6)
    assert math.degrees(d.max_pressure_angle) > 20


def test_an_undercut_cam_is_flagged_and_refused() -> None:
    """A 30 mm rise over 45 degrees on a 10 mm base circle with a 20 mm roller: the pitch
    curve is sharper than the roller; the design says so and model() refuses it."""
    fast = {"step": [{"t0": 0.0, "t1": math.pi / 4, "h": 0.03, "law": "cubic"},
                     {"t0": math.pi, "t1": 1.25 * math.pi, "h": -0.03, "law": "cubic"}]}
    for kw in ({"roller_radius": 0.02}, {"follower": "flat"}):
        d = mbd2d.cam_profile(fast, 0.01, points=720, **kw)
        assert d.undercut and d.min_curvature_radius < 0
        with pytest.raises(mbd2d.ModelError, match="undercut"):
            d.model()


@pytest.mark.parametrize("kw, needle", [
    ({"program": {"step": {"t0": 0.0, "t1": 1.0, "h": 0.01}}}, "does not close"),
    ({"program": {"poly": [0.0, 0.01]}}, "does not close"),
    ({"program": {"step": {"t0": 0.0, "t1": 1.0, "h": 0.01, "law": "jerky"}}}, "law"),
    ({"base_radius": -0.05}, "base_radius must be positive"),
    ({"base_radius": 0.0}, "base_radius must be positive"),
    ({"roller_radius": -0.01}, "roller_radius must be >= 0"),
    ({"offset": 0.07}, "must be below base_radius"),
    ({"follower": "oscillating"}, "follower must be"),
    ({"follower": "flat", "roller_radius": 0.01}, "flat-faced follower has no"),
    ({"points": 8}, "points must be a whole number >= 16"),
    ({"points": 100.5}, "points must be a whole number"),
    ({"program": {"poly": [-0.2]}}, "reaches the cam's centre"),
    ({"base_radius": float("nan")}, "base_radius"),
])
def test_bad_cam_inputs_are_model_errors(kw: dict, needle: str) -> None:
    args = {"program": PROGRAM, "base_radius": 0.05, "roller_radius": 0.01, **kw}
    with pytest.raises(mbd2d.ModelError, match=needle):
        mbd2d.cam_profile(args.pop("program"), args.pop("base_radius"), **args)


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mbd2d", *args], capture_output=True,
                          text=True, timeout=120)


def test_cam_command_writes_a_model_that_keeps_the_program(tmp_path: Path) -> None:
    """mbd2d cam on the example task: the report, the written model (run again from its
    file: the follower's lift against the program's closed form) and the profile CSV."""
    out, prof = tmp_path / "cam.toml", tmp_path / "cam.csv"
    r = cli("cam", str(EX / "tasks" / "cam.toml"), "--out", str(out), "--profile", str(prof))
    assert r.returncode == 0, r.stderr
    assert "largest pressure angle" in r.stdout and "UNDERCUT" not in r.stdout
    # the follower's largest acceleration at the task's speed: the cycloidal rise's
    # 2 pi h / T^2 with T the rise's time (a quarter turn at 2 pi rad/s: 0.25 s)
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("at "))
    acc = float(line.rsplit("acceleration ", 1)[1])
    assert acc == pytest.approx(2 * math.pi * 0.02 / 0.25**2, rel=1e-5)
    res = mbd2d.load(out).kinematics(1.0, 200)
    task = tomllib.loads((EX / "tasks" / "cam.toml").read_text())["cam"]
    theta = task["speed"] * res.t
    lift = np.array([sum(step_closed_form(st, float(t))[0] for st in task["program"]["step"])
                     for t in theta])
    fol = res.body("follower")
    assert np.abs(fol.y - fol.y[0] - lift).max() < 1e-10
    head, rows = read_csv(prof)
    assert head[:2] == ["theta", "s"] and rows.shape == (task["points"], 8)
    np.testing.assert_allclose(rows[:, 1], [sum(step_closed_form(st, float(t))[0]
                                                for st in task["program"]["step"])
                                            for t in rows[:, 0]], rtol=0, atol=1e-15)


@pytest.mark.parametrize("text, needle", [
    ("[cam]\nbase_radius = 0.05\n", "missing key 'program'"),
    ("[cam]\nbase_radius = 0.05\nprogram = 0.0\ncolour = 'red'\n", "unknown key"),
    ("[cams]\n", "unknown key"),
    ("[cam\n", "not a valid TOML"),
    ("[cam]\nbase_radius = 0.01\nroller_radius = 0.02\nprogram = { step = [{ t0 = 0.0, "
     "t1 = 0.5, h = 0.03, law = 'cubic' }, { t0 = 3.0, t1 = 3.5, h = -0.03 }] }\n",
     "undercut"),
])
def test_cam_command_names_bad_task_files(tmp_path: Path, text: str, needle: str) -> None:
    task = tmp_path / "t.toml"
    task.write_text(text)
    r = cli("cam", str(task), "--out", str(tmp_path / "o.toml"))
    assert r.returncode == 2 and needle in r.stderr, r.stderr
    assert not (tmp_path / "o.toml").exists()


SWING = {"step": [{"t0": 0.0, "t1": math.pi / 2, "h": 0.3},
                  {"t0": math.pi, "t1": 1.5 * math.pi, "h": -0.3, "law": "quintic"}]}
ARMS = [({"pivot": [0.12, 0.0], "length": 0.1}, 0.01),
        ({"pivot": [0.0, 0.11], "length": 0.09}, 0.0),
        ({"pivot": [-0.1, -0.08], "length": 0.12}, 0.015)]


def swing_exact(theta: np.ndarray, k: int = 0) -> np.ndarray:
    return np.array([sum(step_closed_form(st, float(t))[k] for st in SWING["step"])
                     for t in theta])


@pytest.mark.parametrize("arm, rr", ARMS)
def test_oscillating_arm_keeps_its_program(arm: dict, rr: float) -> None:
    """A roller (or knife edge) on an arm swinging 0.3 rad: the engine's arm angle against
    the program, falling at the spline's order (measured 14-17x per doubling, 1.7e-11 to
    4.1e-11 rad at 1440 points; the angular speed about 8x)."""
    errs, verrs = [], []
    for n in (360, 720, 1440):
        d = mbd2d.cam_profile(SWING, 0.05, roller_radius=rr, arm=arm, points=n)
        assert not d.undercut
        res = d.model().kinematics(1.0, 400)
        th = res.body("follower").theta
        errs.append(np.abs(th - th[0] - swing_exact(2 * math.pi * res.t)).max())
        verrs.append(np.abs(res.body("follower").theta_dot
                            - 2 * math.pi * swing_exact(2 * math.pi * res.t, 1)).max())
        # the roller sits on the prime circle at rest
        r0 = np.hypot(*(np.array(arm["pivot"]) + arm["length"] * np.array(
            [math.cos(d.arm_angle0), math.sin(d.arm_angle0)])))
        assert r0 == pytest.approx(0.05 + rr, abs=1e-15)
    assert errs[2] < 1e-10 and verrs[2] < 1e-6
    assert errs[0] / errs[1] > 10 and errs[1] / errs[2] > 10
    assert verrs[0] / verrs[1] > 5 and verrs[1] / verrs[2] > 5


def test_arm_pressure_angle_from_the_reaction() -> None:
    """The angle between the cam joint's force on the arm and the roller's direction of
    motion (perpendicular to the arm) is the synthesis' pressure angle."""
    n = 360
    arm, rr = ARMS[0]
    d = mbd2d.cam_profile(SWING, 0.05, roller_radius=rr, arm=arm, points=n)
    m = d.model(masses={"cam": (0.5, 1e-3), "follower": (0.3, 1e-3)})
    m.add_rotational_spring(["ground", "follower"], stiffness=20.0,
                            angle0=d.arm_angle0 - 1.0, name="return")   # presses the roller
    res = m.inverse_dynamics(1.0, n)
    f = res.reaction("contact")
    th = res.body("follower").theta[:-1]
    jn = np.column_stack([-np.sin(th), np.cos(th)])      # the roller's direction of motion
    fv = np.column_stack([f.fx_j[:-1], f.fy_j[:-1]])
    assert np.all(np.einsum("ij,ij->i", fv, jn) > 0)    # the cam pushes the roller out
    angle = np.arctan2(jn[:, 0] * fv[:, 1] - jn[:, 1] * fv[:, 0], np.einsum("ij,ij->i", jn, fv))
    near = near_law_ends(d.theta, SWING)
    np.testing.assert_allclose(angle[~near], d.pressure_angle[~near], rtol=0, atol=2e-7)
    np.testing.assert_allclose(angle, d.pressure_angle, rtol=0, atol=5e-6)


@pytest.mark.parametrize("kw, needle", [
    ({"arm": {"pivot": [0.12, 0.0], "length": 0.01}}, "cannot put its roller"),
    ({"arm": {"pivot": [0.12, 0.0], "length": 0.3}}, "cannot put its roller"),
    ({"arm": {"pivot": [0.12, 0.0]}}, "missing key 'length'"),
    ({"arm": {"pivot": [0.12], "length": 0.1}}, "arm.pivot must be a list of 2"),
    ({"arm": {"pivot": [0.12, 0.0], "length": -0.1}}, "arm.length must be positive"),
    ({"arm": {"pivot": [0.12, 0.0], "length": 0.1, "stroke": 1}}, "unknown key"),
    ({"arm": [0.12, 0.0]}, "arm must be a table"),
    ({"arm": {"pivot": [0.12, 0.0], "length": 0.1}, "offset": 0.01}, "has no offset"),
    ({"arm": {"pivot": [0.12, 0.0], "length": 0.1}, "follower": "flat",
      "roller_radius": 0.0}, "unknown key"),
])
def test_bad_arms_are_model_errors(kw: dict, needle: str) -> None:
    args = {"roller_radius": 0.01, **kw}
    with pytest.raises(mbd2d.ModelError, match=needle):
        mbd2d.cam_profile(SWING, 0.05, **args)


def test_cam_command_with_an_arm(tmp_path: Path) -> None:
    task = tmp_path / "arm.toml"
    task.write_text("[cam]\nbase_radius = 0.05\nroller_radius = 0.01\npoints = 1440\n"
                    "arm = { pivot = [0.12, 0.0], length = 0.1 }\n"
                    "program = { step = [{ t0 = 0.0, t1 = 1.5707963267948966, h = 0.3 }, "
                    "{ t0 = 3.141592653589793, t1 = 4.71238898038469, h = -0.3, "
                    "law = 'quintic' }] }\n")
    out = tmp_path / "arm_model.toml"
    r = cli("cam", str(task), "--out", str(out))
    assert r.returncode == 0, r.stderr
    res = mbd2d.load(out).kinematics(1.0, 100)
    th = res.body("follower").theta
    assert np.abs(th - th[0] - swing_exact(2 * math.pi * res.t)).max() < 1e-10
    assert "arm_pivot" in out.read_text()


@pytest.mark.parametrize("speed", [0.0, -1.0, float("nan")])
def test_the_model_turns_counterclockwise(speed: float) -> None:
    with pytest.raises(mbd2d.ModelError, match="speed"):
        mbd2d.cam_profile(PROGRAM, 0.05, roller_radius=0.01).model(speed=speed)


TILT = {"step": [{"t0": 0.0, "t1": math.pi / 2, "h": 0.08},
                 {"t0": math.pi, "t1": 1.5 * math.pi, "h": -0.08, "law": "quintic"}]}
FLAT_ARMS = [{"pivot": [0.1, 0.12]}, {"pivot": [-0.12, 0.1], "offset": 0.01},
             {"pivot": [0.0, -0.15], "offset": -0.02}]


def tilt_exact(theta: np.ndarray, k: int = 0) -> np.ndarray:
    return np.array([sum(step_closed_form(st, float(t))[k] for st in TILT["step"])
                     for t in theta])


@pytest.mark.parametrize("arm", FLAT_ARMS)
def test_flat_face_on_an_arm_keeps_its_program(arm: dict) -> None:
    """A flat face on an arm tilting 0.08 rad (through the pivot or offset from it): the
    engine's arm angle against the program at the spline's order (measured 13x per doubling,
    1.3e-11 to 1.4e-11 rad at 1440 points), and the surface's curvature against differences
    of its points."""
    errs = []
    for n in (360, 720, 1440):
        d = mbd2d.cam_profile(TILT, 0.05, follower="flat", arm=arm, points=n)
        assert not d.undercut
        res = d.model().kinematics(1.0, 400)
        th = res.body("follower").theta
        errs.append(np.abs(th - th[0] - tilt_exact(2 * math.pi * res.t)).max())
    assert errs[2] < 5e-11 and errs[0] / errs[1] > 10 and errs[1] / errs[2] > 10
    d = mbd2d.cam_profile(TILT, 0.05, follower="flat", arm=arm, points=2880)
    h = 2 * math.pi / 2880
    r = [np.roll(d.points, -j, axis=0) for j in (-2, -1, 1, 2)]
    p1 = (r[0] - 8 * r[1] + 8 * r[2] - r[3]) / (12 * h)
    p2 = (-r[0] + 16 * r[1] - 30 * d.points + 16 * r[2] - r[3]) / (12 * h * h)
    rho = -np.hypot(p1[:, 0], p1[:, 1])**3 / (p1[:, 0] * p2[:, 1] - p1[:, 1] * p2[:, 0])
    smooth = ~near_law_ends(d.theta, TILT)
    np.testing.assert_allclose(rho[smooth], d.curvature_radius[smooth], rtol=1e-6)


def test_flat_face_on_an_arm_pressure_angle_from_the_reaction() -> None:
    """The engine's reaction alone gives the pressure angle of a flat face on an arm: the
    contact point's distance along the face from the cam joint's moment about the pivot (the
    arm's origin), lambda = M / (u x F); then the angle between the force and the contact
    point's motion J (Y - P) about the pivot (0 for a face through the pivot)."""
    n = 360
    for arm in FLAT_ARMS[:2]:
        d = mbd2d.cam_profile(TILT, 0.05, follower="flat", arm=arm, points=n)
        m = d.model(masses={"cam": (0.5, 1e-3), "follower": (0.3, 1e-3)})
        m.add_rotational_spring(["ground", "follower"], stiffness=20.0,
                                angle0=d.arm_angle0 - 1.0, name="return")
        res = m.inverse_dynamics(1.0, n)
        f = res.reaction("contact")
        fv = np.column_stack([f.fx_j[:-1], f.fy_j[:-1]])
        th = res.body("follower").theta[:-1]
        u = np.column_stack([np.cos(th), np.sin(th)])
        lam = f.mz_j[:-1] / (u[:, 0] * fv[:, 1] - u[:, 1] * fv[:, 0])
        rel = lam[:, None] * u + arm.get("offset", 0.0) * np.column_stack([-u[:, 1], u[:, 0]])
        vel = np.column_stack([-rel[:, 1], rel[:, 0]])
        angle = np.arctan2(vel[:, 0] * fv[:, 1] - vel[:, 1] * fv[:, 0],
                           np.einsum("ij,ij->i", vel, fv))
        np.testing.assert_allclose(angle, d.pressure_angle, rtol=0, atol=1e-6)
        # the contact stays on the face's extent (which the design takes at its 360 samples;
        # between them the contact runs past the sampled ends by 2e-9 m here)
        assert d.face[0] - 1e-7 <= lam.min() and lam.max() <= d.face[1] + 1e-7


@pytest.mark.parametrize("arm, needle", [
    ({"pivot": [0.01, 0.0]}, "cannot touch the base circle"),
    ({"pivot": [0.1, 0.12], "length": 0.1}, "unknown key"),
    ({"pivot": [0.1, 0.12], "offset": "x"}, "arm.offset"),
])
def test_bad_flat_arms_are_model_errors(arm: dict, needle: str) -> None:
    with pytest.raises(mbd2d.ModelError, match=needle):
        mbd2d.cam_profile(TILT, 0.05, follower="flat", arm=arm)


def test_an_arm_that_would_turn_with_the_cam_is_refused() -> None:
    fast = {"step": [{"t0": 0.0, "t1": 0.5, "h": 0.9},
                     {"t0": math.pi, "t1": math.pi + 0.5, "h": -0.9}]}
    with pytest.raises(mbd2d.ModelError, match="turn with the cam"):
        mbd2d.cam_profile(fast, 0.05, follower="flat", arm={"pivot": [0.1, 0.12]})


def test_a_measured_program_as_a_table() -> None:
    """A program given as samples (a table over a little more than one turn, so that the
    seam's slopes are estimated inside it): the engine's follower against the closed form
    the samples were taken from, falling as the samples are refined (measured 3.4e-8,
    1.5e-9, 2.5e-11 m at 180, 360, 720 samples); the same table over exactly one turn does
    not close (its end slopes are one-sided estimates) and is refused."""
    errs = []
    for n in (180, 360, 720):
        h = 2 * math.pi / n
        th = np.arange(-4, n + 5) * h
        s, _ = program_exact(np.mod(th, 2 * math.pi))
        d = mbd2d.cam_profile({"table": {"t": list(th), "y": list(s)}}, 0.05,
                              roller_radius=0.01, points=720)
        res = d.model().kinematics(1.0, 400)
        fol = res.body("follower")
        errs.append(np.abs(fol.y - fol.y[0] - program_exact(2 * math.pi * res.t)[0]).max())
    assert errs[2] < 1e-10 and errs[0] / errs[1] > 10 and errs[1] / errs[2] > 10
    th = np.linspace(0.0, 2 * math.pi, 361)
    with pytest.raises(mbd2d.ModelError, match="does not close"):
        mbd2d.cam_profile({"table": {"t": list(th), "y": list(program_exact(th)[0])}}, 0.05,
                          roller_radius=0.01)
