"""Entries changed after the builder checked them (``m.bodies[0].q0 = ...``): every door
that reads the entries (the analyses, the parameter list, with_params, the model and .mbd
files) answers a field of the wrong form with a ModelError naming the entry, the field and
the form, not a raw TypeError or ValueError from deep inside; well-formed models of every
kind pass the check untouched, and an error that no field explains passes through."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Callable

import pytest

import mbd2d
from mbd2d.description.entries import check_entries, reading

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
sys.path.insert(0, str(ROOT / "docs"))


def every_model() -> list[tuple[str, Any]]:
    """The examples, the gallery, every joint and driver kind of test_derivatives and the
    contact and friction models of test_standalone."""
    from test_derivatives import CASES
    from test_standalone import contact_models
    import gallery
    out = [(p.name, mbd2d.load(p)) for p in sorted(EX.glob("*.toml"))]
    out += [(f"gallery {k}", mbd2d.loads(v[2], source=k) if not v[2].startswith("@")
             else mbd2d.load(EX / v[2][1:])) for k, v in gallery.MODELS.items()]
    out += [(k, c.build()) for k, c in CASES.items()]
    out += contact_models()
    return out


def test_well_formed_models_pass() -> None:
    models = every_model()
    assert len(models) > 40
    for name, m in models:
        check_entries(m)                                     # (raises on a false alarm)


def test_an_error_no_field_explains_passes_through() -> None:
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    with pytest.raises(TypeError, match="not from a field"):
        with reading(m):
            raise TypeError("not from a field")


#: (change, entry named, text of the message)
CHANGES: list[tuple[Callable[[Any], None], str, str]] = [
    (lambda m: setattr(m.bodies[1], "q0", [0.0]), "body 'coupler'",
     "q0 must have 3 entries"),
    (lambda m: setattr(m.bodies[1], "q0", None), "body 'coupler'", "q0 must be a sequence"),
    (lambda m: setattr(m.joints[1], "points", 5), "joint 'A' (revolute)",
     "points must be a sequence"),
    (lambda m: setattr(m.joints[1], "points", [["a", 0.0], [0.0, 0.0]]),
     "joint 'A' (revolute)", "points[0][0] must be a number"),
    (lambda m: setattr(m.joints[1], "points", [[float("nan"), 0.0], [0.0, 0.0]]),
     "joint 'A' (revolute)", "finite"),
    (lambda m: setattr(m.joints[2], "bodies", ["coupler", "nobody"]), "joint 'B' (revolute)",
     "bodies names no body 'nobody'"),
    (lambda m: setattr(m.drivers[0], "f", {"poly": [0.0, 1.0]}), "driver 'motor'",
     "f must be a TimeFunction"),
    (lambda m: setattr(m.drivers[0], "coordinate", "z"), "driver 'motor'",
     "coordinate must be one of x, y, theta"),
    (lambda m: setattr(m.bodies[0], "mass", "heavy"), "body 'crank'",
     "mass must be a number >= 0 or None"),
]


@pytest.mark.parametrize("k", range(len(CHANGES)))
def test_every_door_names_the_field(tmp_path: Path, k: int) -> None:
    """Each door either does not read the field (and finishes) or raises a ModelError;
    dynamics, which reads every field, names the entry and the field's form."""
    change, entry, text = CHANGES[k]
    doors = {
        "dynamics": lambda m: m.dynamics(0.1, 4),
        "kinematics": lambda m: m.kinematics(1.0, 4),
        "inverse dynamics": lambda m: m.inverse_dynamics(1.0, 4),
        "parameters": lambda m: m.parameters(),
        "with_params": lambda m: m.with_params({"model.gravity.1": -9.0}),
        "export": lambda m: m.export(tmp_path / "m.mbd", t_end=1.0, steps=4),
        "dump": lambda m: mbd2d.description.toml_io.dump(m, tmp_path / "m.toml"),
        "analyze_dof": lambda m: m.analyze_dof(),
    }
    raised = {}
    for door, call in doors.items():
        m = mbd2d.load(EX / "fourbar_masses.toml")
        change(m)
        try:
            call(m)
        except mbd2d.ModelError as err:
            raised[door] = str(err)
    assert entry in raised["dynamics"] and text in raised["dynamics"], raised["dynamics"]
    assert all(entry in msg for msg in raised.values()), raised


def test_cam_fields(tmp_path: Path) -> None:
    """A cam's follower set as the model file writes it (a table) and a profile kind the
    core does not know."""
    for field, value, text in (("follower", {"roller": {"radius": 0.25}},
                                "follower must be a sequence"),
                               ("profile_kind", "ellipse",
                                "profile_kind must be one of circle, spline, fourier")):
        m = mbd2d.load(EX / "cam_follower.toml")
        setattr(m.joints[2], field, value)
        with pytest.raises(mbd2d.ModelError, match=text):
            m.kinematics(1.0, 4)
