"""Names and row labels: one scheme for every joint, driver and force.

* An entry without a name is called joint<k>, driver<k> or force<k>, k counting the entries
  of its section in the order they were added (the k-th [[joint]] of a file), whatever its
  type; messages name it so.
* Every row of Phi (and of the multipliers) is labelled NAME.WORD, one word per equation from
  one vocabulary (ROW_WORDS), the same word for the same kind of equation in every joint and
  driver; the README's tables list the same words (checked here, so they cannot drift).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.description.joints import ROW_WORDS

ROOT = Path(__file__).resolve().parent.parent

BODIES = """
[[body]]
name = "a"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "b"
q0 = [1.0, 0.0, 0.0]
"""

#: one TOML joint per type (and per follower and coordinate where the rows differ), with the
#: labels the scheme gives it; the models need not be determined (labels need no analysis)
JOINTS = {
    "revolute": ('bodies = ["a", "b"]\npoints = [[0, 0], [0, 0]]', ["x", "y"]),
    "translational": ('bodies = ["a", "b"]\npoints = [[0, 0], [0, 0]]\naxes = [[1, 0], [1, 0]]',
                      ["normal", "angle"]),
    "cam/point": ('type = "cam"\nbodies = ["a", "b"]\n'
                  'profile = { circle = { center = [0, 0], radius = 1.0 } }\n'
                  'follower = { point = [0, 0] }', ["x", "y"]),
    "cam/roller": ('type = "cam"\nbodies = ["a", "b"]\n'
                   'profile = { circle = { center = [0, 0], radius = 1.0 } }\n'
                   'follower = { roller = { center = [0, 0], radius = 0.2 } }', ["x", "y"]),
    "cam/flat": ('type = "cam"\nbodies = ["a", "b"]\n'
                 'profile = { circle = { center = [0, 0], radius = 1.0 } }\n'
                 'follower = { flat = { point = [0, 0], normal = [0, -1] } }',
                 ["normal", "tangent"]),
    "point-on-curve": ('bodies = ["a", "b"]\ncurve = { circle = { center = [0, 0], radius = 1 } }'
                       '\npoint = [0, 0]', ["x", "y"]),
    "distance": ('bodies = ["a", "b"]\npoints = [[0, 0], [0, 0]]\ndistance = 1.0', ["distance"]),
    "point-on-line": ('bodies = ["a", "b"]\npoints = [[0, 0], [0, 0]]\naxis = [1, 0]',
                      ["normal"]),
    "revolute-translational": ('bodies = ["a", "b"]\npoints = [[0, 0], [0, 0]]\naxis = [1, 0]',
                               ["normal"]),
    "weld": ('bodies = ["a", "b"]\npoints = [[0, 0], [0, 0]]', ["x", "y", "angle"]),
    "gear": ('bodies = ["a", "b"]\nradii = [1.0, 2.0]', ["mesh"]),
    "rack-pinion": ('bodies = ["a", "b"]\ncenter = [0, 0]\npoint = [0, 0]\naxis = [1, 0]\n'
                    'radius = 1.0', ["no_slip"]),
    "rolling-disc": ('bodies = ["a", "b"]\ncenter = [0, 0]\npoint = [0, 0]\naxis = [1, 0]\n'
                     'radius = 1.0', ["no_slip", "normal"]),
    "absolute/x": ('body = "a"\ncoordinate = "x"', ["x"]),
    "absolute/y": ('body = "a"\ncoordinate = "y"', ["y"]),
    "absolute/theta": ('body = "a"\ncoordinate = "theta"', ["theta"]),
}

DRIVERS = {
    "absolute/x": ('body = "a"\ncoordinate = "x"', ["x"]),
    "absolute/y": ('body = "a"\ncoordinate = "y"', ["y"]),
    "absolute/theta": ('body = "a"\ncoordinate = "theta"', ["theta"]),
    "relative-angle": ('bodies = ["a", "b"]', ["angle"]),
    "relative-distance": ('joint = "slide"', ["slide"]),
}


def _joint_toml(key: str, name: str | None) -> str:
    body, _ = JOINTS[key]
    jtype = key.split("/")[0]
    head = "[[joint]]\n" + (f'name = "{name}"\n' if name else "")
    return head + ("" if body.startswith("type") else f'type = "{jtype}"\n') + body + "\n"


@pytest.mark.parametrize("key", sorted(JOINTS))
def test_joint_rows_are_name_dot_word(key):
    model = mbd2d.loads(BODIES + _joint_toml(key, "J"))
    words = JOINTS[key][1]
    assert model.constraint_rows() == [f"J.{w}" for w in words]
    assert all(w in ROW_WORDS for w in words)


@pytest.mark.parametrize("key", sorted(DRIVERS))
def test_driver_rows_are_name_dot_word(key):
    slide = ('[[joint]]\nname = "slide"\ntype = "translational"\nbodies = ["a", "b"]\n'
             'points = [[0, 0], [0, 0]]\naxes = [[1, 0], [1, 0]]\n')
    body, words = DRIVERS[key]
    text = (BODIES + slide + f'[[driver]]\nname = "D"\ntype = "{key.split("/")[0]}"\n{body}\n'
            "f = 0.0\n")
    model = mbd2d.loads(text)
    assert model.constraint_rows()[-1:] == [f"D.{w}" for w in words]
    assert all(w in ROW_WORDS for w in words)


def _readme_table(first_header: str) -> dict[str, set[str]]:
    """type -> the backticked words of the 'row labels' column of a README table."""
    lines = (ROOT / "README.md").read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith(first_header))
    header = [c.strip() for c in lines[start].strip("|").split("|")]
    col = header.index("row labels")
    out = {}
    for ln in lines[start + 2:]:
        if not ln.startswith("|"):
            break
        cells = [c.strip() for c in ln.strip("|").split("|")]
        out[cells[0].strip("`")] = set(re.findall(r"`([a-z_]+)`", cells[col]))
    return out


def test_readme_lists_the_same_row_labels():
    for header, table in (("| joint `type` |", JOINTS), ("| driver `type` |", DRIVERS)):
        documented = _readme_table(header)
        actual: dict[str, set[str]] = {}
        for key, (_, words) in table.items():
            actual.setdefault(key.split("/")[0], set()).update(words)
        assert documented == actual


def test_automatic_names_count_per_section():
    """Before: revolute1, translational2, ..., a first driver after five joints 'driver6',
    forces named after their type. After: joint1..joint5, driver1, force1, force2."""
    m = mbd2d.Model("auto")
    m.add_body("a", q0=[0, 0, 0], mass=1.0, inertia=0.1)
    m.add_body("b", q0=[1, 0, 0], mass=1.0, inertia=0.1)
    m.add_revolute(["ground", "a"], [[0, 0], [0, 0]])
    m.add_translational(["a", "b"], [[0, 0], [0, 0]], [[1, 0], [1, 0]])
    m.add_distance(["ground", "b"], [[0, 0], [0, 0]], 1.0)
    m.add_weld(["a", "b"], [[0, 0], [0, 0]])
    m.add_absolute("a", "x")
    m.add_driver("absolute", body="a", coordinate="theta", f=0.0)
    m.add_spring(["ground", "a"], [[0, 0], [0, 0]], stiffness=1.0)
    m.add_torque("b", f=1.0)
    assert [j.name for j in m.joints] == ["joint1", "joint2", "joint3", "joint4", "joint5"]
    assert [d.name for d in m.drivers] == ["driver1"]
    assert [f.name for f in m.forces] == ["force1", "force2"]


def test_automatic_names_in_toml_follow_the_file_order():
    text = BODIES + _joint_toml("revolute", "pin") + _joint_toml("weld", None) + \
        _joint_toml("distance", None) + \
        '[[driver]]\ntype = "relative-angle"\nbodies = ["a", "b"]\nf = 0.0\n'
    m = mbd2d.loads(text)
    assert [c.name for c in m.constraints] == ["pin", "joint2", "joint3", "driver1"]
    assert m.constraint_rows()[-1] == "driver1.angle"


def test_a_taken_automatic_name_is_an_error_naming_the_entry():
    m = mbd2d.Model()
    m.add_body("joint2", q0=[0, 0, 0])
    m.add_revolute(["ground", "joint2"], [[0, 0], [0, 0]])
    with pytest.raises(mbd2d.ModelError, match=r"joint #2 \(weld\).*'joint2'.*give this joint "
                                               r"a name"):
        m.add_weld(["ground", "joint2"], [[0, 0], [0, 0]])


def test_dead_centre_names_the_driver_the_user_has():
    """The seed four-bar's driver, unnamed, reaches its toggle: the error names 'driver1'
    (before: 'driver5', an entry the file does not have)."""
    text = (ROOT / "examples" / "fourbar_seed.toml").read_text().replace('name = "motor"\n', "")
    with pytest.raises(mbd2d.SingularConfigurationError, match="driver 'driver1'") as err:
        mbd2d.loads(text).kinematics(t_end=1.0, steps=100)
    assert err.value.driver == "driver1"


def test_multipliers_and_efforts_by_the_labels():
    """The labels index the multipliers of a run: the driver's row is its effort (-lambda)
    and the pin's rows are the reaction's components on the crank."""
    text = (ROOT / "examples" / "fourbar_seed.toml").read_text()
    text = text.replace('q0 = [0.75, 1.3, 1.047]', 'q0 = [0.75, 1.3, 1.047]\nmass = 1.0\n'
                        'inertia = 0.2')
    for body in ("coupler", "rocker"):
        text = re.sub(rf'(name = "{body}"\nq0 = \[[^\]]*\])', r"\1\nmass = 2.0\ninertia = 0.5",
                      text)
    res = mbd2d.loads(text).inverse_dynamics(t_end=0.5, steps=10)
    assert res.row_labels[-1] == "motor.theta"
    np.testing.assert_array_equal(res.effort("motor"), -res.multiplier("motor.theta"))
    assert res.row_labels[:2] == ["O2.x", "O2.y"]
