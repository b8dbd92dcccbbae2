"""Bad input never crashes and never surfaces as an internal error: every case raises
mbd2d.ModelError (a ValueError) whose message names the offending entry."""
from __future__ import annotations

import math

import numpy as np
import pytest

import mbd2d
from conftest import example_path, model_from_toml

BODIES = """
[model]
name = "bad"

[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]

[[body]]
name = "rod"
q0 = [2.5, 0.25, 0.17]

[[body]]
name = "slider"
q0 = [3.96, 0.5, 0.0]
"""

JOINTS = """
[[joint]]
name = "O"
type = "revolute"
bodies = ["ground", "crank"]
points = [[0.0, 0.0], [-0.5, 0.0]]

[[joint]]
name = "A"
type = "revolute"
bodies = ["crank", "rod"]
points = [[0.5, 0.0], [-1.5, 0.0]]

[[joint]]
name = "B"
type = "revolute"
bodies = ["rod", "slider"]
points = [[1.5, 0.0], [0.0, 0.0]]

[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "slider"]
points = [[0.0, 0.5], [0.0, 0.0]]
axes = [[1.0, 0.0], [1.0, 0.0]]
"""

DRIVER = """
[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0.0, 6.283185307179586] }
"""

VALID = BODIES + JOINTS + DRIVER


def cam_joint(profile: str, follower: str = "{ point = [0.0, 0.0] }") -> str:
    return f"""
[[joint]]
name = "contact"
type = "cam"
bodies = ["crank", "slider"]
profile = {profile}
follower = {follower}
"""


def joint(name: str, body: str) -> str:
    return f'\n[[joint]]\nname = "{name}"\n{body}\n'


def driver(name: str, body: str) -> str:
    return f'\n[[driver]]\nname = "{name}"\n{body}\n'


def run_pipeline(text: str) -> None:
    """Parse, build and analyse: the error may come from any stage, but must be a
    ModelError."""
    m = mbd2d.loads(text)
    m.kinematics(t_end=1.0, steps=4)


def test_valid_base_model_runs():
    res = mbd2d.loads(VALID).kinematics(t_end=1.0, steps=4)
    assert res.complete


CASES = {
    # ---- names
    "unknown body in a joint": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "crankk"]\n'
                       'points = [[0, 0], [0, 0]]'),
        r"joint 'pin'.*unknown body 'crankk'"),
    "unknown body in a driver": (
        BODIES + driver("motor", 'type = "absolute"\nbody = "wheel"\ncoordinate = "x"\nf = 1.0'),
        r"driver 'motor'.*unknown body 'wheel'"),
    "duplicate body names": (
        BODIES + '\n[[body]]\nname = "rod"\nq0 = [0.0, 0.0, 0.0]\n',
        r"body 'rod'.*duplicate name 'rod'"),
    "body and joint share a name": (
        BODIES + joint("slider", 'type = "revolute"\nbodies = ["ground", "crank"]\n'
                       'points = [[0, 0], [0, 0]]'),
        r"joint 'slider'.*duplicate name 'slider'"),
    "joint and driver share a name": (
        BODIES + JOINTS + DRIVER.replace('name = "motor"', 'name = "guide"'),
        r"driver 'guide'.*duplicate name 'guide'"),
    "a body called ground": (
        BODIES.replace('name = "rod"', 'name = "ground"'),
        r"body 'ground'.*'ground' is reserved"),
    # ---- array lengths
    "q0 of 2 numbers": (
        BODIES.replace("q0 = [2.5, 0.25, 0.17]", "q0 = [2.5, 0.25]"),
        r"body 'rod'.*q0 must be a list of 3 numbers"),
    "points with 3 pairs": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "crank"]\n'
                       'points = [[0, 0], [0, 0], [1, 1]]'),
        r"joint 'pin'.*points must be a list of 2"),
    "a point of 3 numbers": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "crank"]\n'
                       'points = [[0, 0], [0, 0, 0]]'),
        r"joint 'pin'.*points\[1\]"),
    "spline with 3 points": (
        BODIES + cam_joint("{ spline = { points = [[1, 0], [0, 1], [-1, 0]] } }"),
        r"joint 'contact'.*at least 4"),
    # ---- non-finite numbers
    "nan in q0": (
        BODIES.replace("q0 = [2.5, 0.25, 0.17]", "q0 = [nan, 0.25, 0.17]"),
        r"body 'rod'.*q0\[0\] must be finite"),
    "inf in q0": (
        BODIES.replace("q0 = [2.5, 0.25, 0.17]", "q0 = [2.5, -inf, 0.17]"),
        r"body 'rod'.*q0\[1\] must be finite"),
    "inf in points": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "crank"]\n'
                       'points = [[0, inf], [0, 0]]'),
        r"joint 'pin'.*points\[0\]\[1\] must be finite"),
    "nan in spline points": (
        BODIES + cam_joint("{ spline = { points = [[1, 0], [0, 1], [-1, 0], [0, nan]] } }"),
        r"joint 'contact'.*must be finite"),
    "inf in f.poly": (
        BODIES + JOINTS + DRIVER.replace("poly = [0.0, 6.283185307179586]", "poly = [0.0, inf]"),
        r"driver 'motor'.*f\.poly\[1\] must be finite"),
    "nan in f.harmonic": (
        BODIES + JOINTS + DRIVER.replace(
            "poly = [0.0, 6.283185307179586]",
            "harmonic = [{ amplitude = 1.0, omega = nan }]"),
        r"driver 'motor'.*f\.harmonic\[0\]\.omega must be finite"),
    "nan constant f": (
        BODIES + JOINTS + DRIVER.replace("f = { poly = [0.0, 6.283185307179586] }", "f = nan"),
        r"driver 'motor'.*f must be finite"),
    # ---- degenerate geometry
    "zero translational axis": (
        BODIES + joint("guide", 'type = "translational"\nbodies = ["ground", "slider"]\n'
                       'points = [[0, 0], [0, 0]]\naxes = [[1.0, 0.0], [0.0, 0.0]]'),
        r"joint 'guide'.*axes\[1\] has zero length"),
    "zero flat-follower normal": (
        BODIES + cam_joint("{ circle = { center = [0, 0], radius = 1.0 } }",
                           "{ flat = { point = [0, 0], normal = [0.0, 0.0] } }"),
        r"joint 'contact'.*normal has zero length"),
    "negative circle radius": (
        BODIES + cam_joint("{ circle = { center = [0, 0], radius = -1.0 } }"),
        r"joint 'contact'.*radius must be positive"),
    "zero circle radius": (
        BODIES + cam_joint("{ circle = { center = [0, 0], radius = 0.0 } }"),
        r"joint 'contact'.*radius must be positive"),
    "zero roller radius": (
        BODIES + cam_joint("{ circle = { center = [0, 0], radius = 1.0 } }",
                           "{ roller = { center = [0, 0], radius = 0.0 } }"),
        r"joint 'contact'.*roller\.radius must be positive"),
    "negative roller radius": (
        BODIES + cam_joint("{ circle = { center = [0, 0], radius = 1.0 } }",
                           "{ roller = { center = [0, 0], radius = -0.2 } }"),
        r"joint 'contact'.*roller\.radius must be positive"),
    "fourier radius not positive": (
        BODIES + cam_joint("{ fourier = { a = [1.0, 1.5] } }"),
        r"'contact'.*r\(alpha\) must stay positive"),
    "spline with repeated points": (
        BODIES + cam_joint("{ spline = { points = [[1, 0], [1, 0], [0, 1], [-1, 0], "
                           "[0, -1]] } }"),
        r"'contact'.*equal points"),
    "self-crossing spline": (
        BODIES + cam_joint("{ spline = { points = [[1, 0], [0.5, 0.5], [0, 0], [-0.5, -0.5], "
                           "[-1, 0], [-0.5, 0.5], [0, 0.0001], [0.5, -0.5]] } }"),
        r"'contact'.*crosses itself"),
    "self-joint": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["crank", "crank"]\n'
                       'points = [[0, 0], [0, 0]]'),
        r"joint 'pin'.*joined to itself"),
    "ground jointed to ground": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "ground"]\n'
                       'points = [[0, 0], [0, 0]]'),
        r"joint 'pin'.*joined to itself"),
    # ---- determinacy
    "not determined: driver missing": (
        BODIES + JOINTS,
        r"model 'bad'.*not kinematically determined: 8 equations for 9 coordinates"),
    # ---- types and keys
    "unknown joint type": (
        BODIES + joint("scissor", 'type = "scissor"\nbodies = ["crank", "rod"]'),
        r"joint 'scissor'.*unknown joint type 'scissor'"),
    "unknown driver type": (
        BODIES + driver("motor", 'type = "torque"\nbody = "crank"\nf = 1.0'),
        r"driver 'motor'.*unknown driver type 'torque'"),
    "unknown key in a joint": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "crank"]\n'
                       'points = [[0, 0], [0, 0]]\ncolour = "red"'),
        r"joint 'pin'.*unknown key.*colour"),
    "unknown key in a body": (
        BODIES.replace('name = "rod"', 'name = "rod"\nlength = 3.0'),
        r"'rod'.*unknown key.*length"),
    "unknown key in a driver": (
        BODIES + JOINTS + DRIVER.replace('name = "motor"', 'name = "motor"\nspeed = 1.0'),
        r"'motor'.*unknown key.*speed"),
    "unknown key in [model]": (
        VALID.replace('name = "bad"', 'name = "bad"\nunits = "SI"'),
        r"\[model\].*unknown key.*units"),
    "unknown section": (
        VALID + '\n[[spring]]\nname = "k"\n',
        r"unknown section.*spring"),
    "missing points": (
        BODIES + joint("pin", 'type = "revolute"\nbodies = ["ground", "crank"]'),
        r"joint 'pin'.*missing key 'points'"),
    "missing joint type": (
        BODIES + joint("pin", 'bodies = ["ground", "crank"]\npoints = [[0, 0], [0, 0]]'),
        r"'pin'.*missing key 'type'"),
    "missing q0": (
        BODIES + '\n[[body]]\nname = "wheel"\n',
        r"'wheel'.*missing key 'q0'"),
    "missing driver f": (
        BODIES + JOINTS + driver("motor", 'type = "absolute"\nbody = "crank"\n'
                                 'coordinate = "theta"'),
        r"'motor'.*missing key 'f'"),
    "missing absolute coordinate": (
        BODIES + JOINTS + driver("motor", 'type = "absolute"\nbody = "crank"\nf = 1.0'),
        r"driver 'motor'.*'coordinate'"),
    "unknown coordinate": (
        BODIES + JOINTS + driver("motor", 'type = "absolute"\nbody = "crank"\n'
                                 'coordinate = "z"\nf = 1.0'),
        r"driver 'motor'.*coordinate must be"),
    "malformed TOML": (
        BODIES + '\n[[joint]\nname = "pin"\n',
        r"not valid TOML"),
    "TOML value of the wrong kind": (
        BODIES.replace("q0 = [2.5, 0.25, 0.17]", 'q0 = "2.5, 0.25, 0.17"'),
        r"body 'rod'.*q0 must be a list of 3 numbers"),
    "empty model": ("", r"model.*no moving bodies"),
    "model without bodies": ('[model]\nname = "nothing"\n', r"model.*no moving bodies"),
    "bodies but no constraints": (BODIES, r"model.*no joints or drivers"),
    "relative-distance driver on a revolute joint": (
        VALID + driver("push", 'type = "relative-distance"\njoint = "A"\nf = 1.0'),
        r"driver 'push'.*joint 'A' is a revolute joint.*translational"),
    "relative-distance driver on an unknown joint": (
        VALID + driver("push", 'type = "relative-distance"\njoint = "slot"\nf = 1.0'),
        r"driver 'push'.*unknown joint 'slot'"),
}


@pytest.mark.parametrize("label", sorted(CASES))
def test_bad_model_raises_model_error(label):
    text, match = CASES[label]
    with pytest.raises(mbd2d.ModelError, match=match) as info:
        run_pipeline(text)
    assert isinstance(info.value, ValueError)
    assert not isinstance(info.value, mbd2d.AnalysisError)


def test_not_determined_cam_model_counts_contact_parameters():
    text = example_path("cam_follower.toml").read_text().split("[[driver]]")[0]
    with pytest.raises(mbd2d.ModelError,
                       match=r"6 equations for 7 coordinates \(2 bodies x 3 \+ 1 cam contact"):
        run_pipeline(text)


# ------------------------------------------------------------------ the builder API

def test_builder_reports_the_same_errors():
    m = mbd2d.Model("builder")
    m.add_body("a", q0=[0, 0, 0])
    with pytest.raises(mbd2d.ModelError, match=r"body 'a'.*duplicate name"):
        m.add_body("a", q0=[1, 1, 1])
    with pytest.raises(mbd2d.ModelError, match=r"body 'b'.*q0 must be a list of 3"):
        m.add_body("b", q0=[1, 1])
    with pytest.raises(mbd2d.ModelError, match=r"body 'b'.*must be finite"):
        m.add_body("b", q0=[1, math.inf, 1])
    with pytest.raises(mbd2d.ModelError, match=r"joint 'pin'.*unknown body 'b'"):
        m.add_revolute(["ground", "b"], [[0, 0], [0, 0]], name="pin")
    with pytest.raises(mbd2d.ModelError, match=r"joint 'pin'.*joined to itself"):
        m.add_revolute(["a", "a"], [[0, 0], [0, 0]], name="pin")
    with pytest.raises(mbd2d.ModelError, match=r"joint 'g'.*axes\[0\] has zero length"):
        m.add_translational(["ground", "a"], [[0, 0], [0, 0]], [[0, 0], [1, 0]], name="g")
    with pytest.raises(mbd2d.ModelError, match=r"joint 'c'.*radius must be positive"):
        m.add_cam(["ground", "a"], {"circle": {"center": [0, 0], "radius": 0}},
                  {"point": [0, 0]}, name="c")
    with pytest.raises(mbd2d.ModelError, match=r"joint 'c'.*normal has zero length"):
        m.add_cam(["ground", "a"], {"circle": {"center": [0, 0], "radius": 1}},
                  {"flat": {"point": [0, 0], "normal": [0, 0]}}, name="c")
    with pytest.raises(mbd2d.ModelError, match=r"'j'.*unknown joint type 'hinge'"):
        m.add_joint("hinge", name="j", bodies=["ground", "a"])
    with pytest.raises(mbd2d.ModelError, match=r"driver 'd'.*unknown driver type 'speed'"):
        m.add_driver("speed", f=1.0, name="d", body="a")
    with pytest.raises(mbd2d.ModelError, match=r"driver 'd'.*unknown driver type array"):
        m.add_driver(np.array([math.nan, 0.0]), f=0.0, name="d")   # (was a raw ValueError)
    with pytest.raises(mbd2d.ModelError, match=r"driver 'd'.*f\.poly\[0\] must be finite"):
        m.add_driver("absolute", f={"poly": [math.nan]}, name="d", body="a", coordinate="x")
    m.add_revolute(["ground", "a"], [[0, 0], [0, 0]], name="pin")
    with pytest.raises(mbd2d.ModelError, match=r"driver 'd'.*'pin' is a revolute joint"):
        m.add_driver("relative-distance", f=1.0, name="d", joint="pin")
    # nothing half-added by the failed calls
    assert [b.name for b in m.bodies] == ["a"]
    assert [j.name for j in m.joints] == ["pin"]
    assert m.drivers == []
    with pytest.raises(mbd2d.ModelError, match=r"2 equations for 3 coordinates"):
        m.kinematics(t_end=1.0, steps=2)


def test_missing_model_file_is_a_model_error(tmp_path):
    with pytest.raises(mbd2d.ModelError, match=r"nope\.toml.*cannot read"):
        mbd2d.load(tmp_path / "nope.toml")


# ------------------------------------------------------------------ analysis settings

@pytest.fixture(scope="module")
def good_model():
    return model_from_toml(VALID)


@pytest.mark.parametrize("kwargs,match", [
    ({"t_end": 1.0, "steps": 0}, r"analysis.*steps must be a whole number >= 1"),
    ({"t_end": 1.0, "steps": -5}, r"analysis.*steps"),
    ({"t_end": 1.0, "steps": 2.5}, r"analysis.*steps"),
    ({"t_end": 1.0, "steps": True}, r"analysis.*steps"),
    ({"t_end": 0.0, "steps": 10}, r"analysis.*t_end \(0.0\) must be greater than t0 \(0.0\)"),
    ({"t_end": -1.0, "steps": 10}, r"analysis.*t_end.*must be greater than t0"),
    ({"t_end": 1.0, "steps": 10, "t0": 2.0}, r"analysis.*t_end.*must be greater than t0"),
    ({"t_end": math.nan, "steps": 10}, r"analysis.*t_end must be a finite number"),
    ({"t_end": math.inf, "steps": 10}, r"analysis.*t_end must be a finite number"),
    ({"t_end": 1.0, "steps": 10, "t0": math.nan}, r"analysis.*t0 must be a finite number"),
    ({"t_end": "1.0", "steps": 10}, r"analysis.*t_end must be a finite number"),
    ({"t_end": 1.0, "steps": 10, "tol": 0.0}, r"analysis.*tol"),
    ({"t_end": 1.0, "steps": 10, "tol": math.nan}, r"analysis.*tol"),
    ({"t_end": 1.0, "steps": 10, "maxit": 0}, r"analysis.*maxit"),
])
def test_bad_analysis_settings(good_model, kwargs, match):
    with pytest.raises(mbd2d.ModelError, match=match):
        good_model.kinematics(**kwargs)


def test_bad_states_for_evaluation(good_model):
    with pytest.raises(mbd2d.ModelError, match=r"state.*q must have 9 entries"):
        good_model.phi([0.0, 1.0])
    with pytest.raises(mbd2d.ModelError, match=r"state.*q has non-finite"):
        good_model.jacobian([math.nan] * 9)
    with pytest.raises(mbd2d.ModelError, match=r"state.*qd must have 9 entries"):
        good_model.gamma([0.0] * 9, [0.0] * 8)


# ------------------------------------------------------------------ found while probing
# Each of these inputs currently escapes as a raw Python/f2py exception (or is silently
# accepted) instead of a ModelError naming the entry; see the report.

def test_joint_type_that_is_not_a_string():
    text = BODIES + joint("pin", 'type = ["revolute"]\nbodies = ["ground", "crank"]\n'
                          'points = [[0, 0], [0, 0]]')
    with pytest.raises(mbd2d.ModelError, match=r"'pin'.*type"):
        run_pipeline(text)


def test_driver_coordinate_that_is_not_a_string():
    text = BODIES + JOINTS + driver("motor", 'type = "absolute"\nbody = "crank"\n'
                                    'coordinate = ["theta"]\nf = 1.0')
    with pytest.raises(mbd2d.ModelError, match=r"driver 'motor'.*coordinate"):
        run_pipeline(text)


def test_model_file_that_is_not_utf8(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(VALID.replace('name = "bad"', 'name = "bad" # caf\xe9').encode("latin-1"))
    with pytest.raises(mbd2d.ModelError, match=r"latin1\.toml"):
        mbd2d.load(path)


@pytest.mark.parametrize("kwargs,match", [
    ({"t_end": 1.0, "steps": 2**31}, r"analysis.*steps"),
    ({"t_end": 1.0, "steps": 4, "maxit": 2**40}, r"analysis.*maxit"),
])
def test_settings_beyond_the_core_integer_range(good_model, kwargs, match):
    with pytest.raises(mbd2d.ModelError, match=match):
        good_model.kinematics(**kwargs)


def test_spline_profile_of_collinear_points_is_rejected():
    """Four collinear points give a zero-area 'closed curve' traced back and forth along a
    segment: not a simple closed profile, and its outward normal flips."""
    text = BODIES + cam_joint("{ spline = { points = [[0, 0], [1, 0], [2, 0], [3, 0]] } }")
    with pytest.raises(mbd2d.ModelError, match=r"'contact'"):
        mbd2d.loads(text).counts()


@pytest.mark.parametrize("value", [1e300, -1e300, 1e15, -2.5e99, 1e100])
def test_the_length_scale_message_writes_its_number_whole(value: float) -> None:
    """A length scale out of range is named with its number as Python writes it in E
    notation: a three-digit exponent came out as "1.00+300" (Fortran's es9.2 drops the E)."""
    m = mbd2d.load(example_path("fourbar_grashof.toml"))
    with pytest.raises(mbd2d.ModelError) as info:
        m.with_params({"joint.O4.points.1.0": value, "joint.O4.points.0.0": value}).kinematics(
            0.1, 2)
    want = f"{abs(value):.2E}"
    assert f"length scale (its largest joint point, size or position) is {want};" in \
        str(info.value), str(info.value)
