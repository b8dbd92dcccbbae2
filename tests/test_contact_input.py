"""Contact and friction inputs: every malformed entry is a ModelError naming the entry and
the key, in code and in TOML (issue 13)."""
from __future__ import annotations

from pathlib import Path

import pytest

import mbd2d

CIRCLE = {"center": [0.0, 0.0], "radius": 0.1}
LINE = {"point": [0.0, 0.0], "normal": [0.0, 1.0]}
LAW = {"model": "hunt-crossley", "stiffness": 1e7, "restitution": 0.8}


def base() -> mbd2d.Model:
    m = mbd2d.Model("m")
    m.add_body("ball", q0=[0, 1, 0], mass=1.0, inertia=0.01)
    m.add_body("disc", q0=[1, 1, 0], mass=1.0, inertia=0.01)
    return m


@pytest.mark.parametrize("kw,match", [
    ({"type": "circle-box"}, "unknown contact type 'circle-box'"),
    ({"law": {**LAW, "model": "kelvin"}}, "law.model must be one of"),
    ({"law": {**LAW, "restitution": 0.0}}, r"restitution must be in \(0, 1\]"),
    ({"law": {**LAW, "restitution": 1.2}}, r"restitution must be in \(0, 1\]"),
    ({"law": {"model": "hertz", "stiffness": 1e7, "restitution": 0.5}}, "hertz law is elastic"),
    ({"law": {"model": "linear", "stiffness": 1e7, "exponent": 1.5}}, "linear law has exponent 1"),
    ({"law": {**LAW, "exponent": 5.0}}, "exponent must be from 1 to 3"),
    ({"law": {**LAW, "stiffness": -1.0}}, "stiffness must be positive"),
    ({"law": {"model": "flores"}}, "missing key 'stiffness'"),
    ({"law": {**LAW, "damping": 3.0}}, r"unknown key\(s\) \['damping'\]"),
    ({"circle": {"center": [0, 0], "radius": -0.1}}, "radius must be positive"),
    ({"line": {"point": [0, 0], "normal": [0, 0]}}, "line.normal has zero length"),
    ({"line": None}, "missing key 'line'"),
    ({"profile": {"circle": {"center": [0, 0], "radius": 1}}}, "has no 'profile'"),
    ({"friction": {"mu": 0.2, "model": "stick-slip"}}, "contact friction is the regularized"),
    ({"friction": {"mu": 0.2, "pin_radius": 0.1}}, r"unknown key\(s\) \['pin_radius'\]"),
    ({"bodies": ["ball", "ball"]}, "cannot be joined to itself"),
    ({"bodies": ["ball", "nobody"]}, "unknown body 'nobody'"),
    ({"name": "ball"}, "duplicate name 'ball'"),
])
def test_bad_circle_line_contact(kw, match):
    args = {"type": "circle-line", "bodies": ["ball", "ground"], "circle": CIRCLE, "line": LINE,
            "law": LAW, **kw}
    with pytest.raises(mbd2d.ModelError, match=match):
        base().add_contact(**args)


def test_bad_circle_pairs():
    m = base()
    with pytest.raises(mbd2d.ModelError, match="list of two circles"):
        m.add_contact("circle-circle", ["ball", "disc"], circle=CIRCLE, law=LAW)
    with pytest.raises(mbd2d.ModelError, match="hole .* must be larger than the pin"):
        m.add_contact("circle-in-circle", ["ball", "disc"], circle=[CIRCLE, CIRCLE], law=LAW)


def test_bad_profile_is_named_by_the_core():
    """A spline profile that crosses itself passes the front end and is refused by the core,
    which names the contact."""
    m = base()
    m.add_revolute(["ground", "disc"], [[1, 1], [0, 0]], name="pivot")
    pts = [[0, 0], [1, 1], [1, 0], [0, 1]]                     # a figure eight
    m.add_contact("follower-profile", ["disc", "ball"], profile={"spline": {"points": pts}},
                  follower={"point": [0, 0]}, law=LAW, name="cam")
    with pytest.raises(mbd2d.ModelError, match="contact 'cam'.*(crosses|area)"):
        m.dynamics(0.1, 10)


def test_free_bodies_need_a_contact_and_dynamics():
    m = base()
    with pytest.raises(mbd2d.ModelError, match="no joints or drivers"):
        m.dynamics(0.1, 10)
    m.add_contact("circle-circle", ["ball", "disc"], circle=[CIRCLE, CIRCLE], law=LAW)
    with pytest.raises(mbd2d.ModelError, match="not kinematically determined"):
        m.kinematics(1.0, 10)
    res = m.dynamics(0.1, 10)
    assert res.complete


def test_toml_contact_errors_name_the_entry():
    text = """
[[body]]
name = "ball"
q0 = [0.0, 1.0, 0.0]
mass = 1.0
inertia = 0.01
[[contact]]
name = "floor"
type = "circle-line"
bodies = ["ball", "ground"]
circle = { center = [0.0, 0.0], radius = 0.1 }
line = { point = [0.0, 0.0], normal = [0.0, 1.0] }
law = { model = "flores", stiffness = 1e7, restitution = 0.5 }
"""
    with pytest.raises(mbd2d.ModelError, match=r"\[\[contact\]\] #1 'floor'.*unknown key.*'spin'"):
        mbd2d.loads(text + "spin = 1\n")
    with pytest.raises(mbd2d.ModelError, match=r"missing key 'type'"):
        mbd2d.loads(text.replace('type = "circle-line"\n', ""))
    assert mbd2d.loads(text).contacts[0].law.model == "flores"


def test_sensitivities_refuse_contacts():
    m = base()
    m.add_contact("circle-line", ["ball", "ground"], circle=CIRCLE, line=LINE, law=LAW)
    with pytest.raises(mbd2d.ModelError, match="sensitivities do not carry contacts"):
        m.dynamics(0.1, 10, sensitivities=["ball.mass"])


def test_sweeps_carry_contacts():
    """A dynamics sweep of a model with a contact gives each case exactly as the variant run
    alone (the batch passes the contact outputs and events through)."""
    pytest.importorskip("xarray")
    import numpy as np
    ex = Path(__file__).resolve().parents[1] / "examples"
    m = mbd2d.load(ex / "cam_liftoff.toml")
    k0 = m.parameters()["force.spring.stiffness"]
    ks = [0.5 * k0, k0]
    ds = mbd2d.sweep(m, {"force.spring.stiffness": ks}, "dynamics", t_end=0.05, steps=20,
                     workers=1, progress=False)
    assert list(ds.status.values) == [0, 0]
    for i, k in enumerate(ks):
        alone = m.with_params({"force.spring.stiffness": k}).dynamics(0.05, 20)
        assert np.array_equal(np.asarray(ds["q"][i]), alone.q)
