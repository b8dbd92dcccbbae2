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


def test_profile_layout_and_contact_type() -> None:
    """Fields whose form depends on another: a Fourier profile set to a circle's three
    numbers, and a contact's type the core does not know."""
    from test_derivatives import CASES
    from test_standalone import contact_models
    m = CASES["point-on-curve-fourier"].build()
    slot = next(j for j in m.joints if j.name == "slot")
    slot.profile = (0.0, 0.0, 1.0)
    with pytest.raises(mbd2d.ModelError, match="profile of a Fourier curve must be"):
        m.parameters()
    ball = contact_models()[1][1]
    ball.contacts[0].type = "circle-square"
    with pytest.raises(mbd2d.ModelError, match="contact 'floor'.*type must be one of"):
        ball.dynamics(0.01, 2)


#: values a field may be set to by mistake
JUNK = [None, "x", {"a": 1}, [], [1.0], [1.0, 2.0], [[1.0, 2.0]], [[1, 2], [3, 4]],
        (0.0, 0.0, 0.0), float("nan"), float("inf"), -1.0, 0.0, 1e308, 5, True,
        [[0, 0], [0, 0], [0, 0]], ["nobody", "ground"], "theta", "roller"]


def test_random_fields_through_random_doors(tmp_path: Path) -> None:
    """Seeded random exploration (MBD2D_ENTRY_FUZZ cases, default 80; 2000 passed when
    written): a random field of a random entry of a random model (examples, every joint
    kind, contacts and friction) set to a random wrong value, then a random door; it
    finishes with finite arrays or raises an MbdError, nothing else."""
    import os
    import random
    import warnings
    import dataclasses
    import numpy as np
    from test_derivatives import CASES
    from test_standalone import contact_models
    builds = [lambda p=p: mbd2d.load(p) for p in sorted(EX.glob("*.toml"))]
    builds += [c.build for c in CASES.values()]
    builds += [lambda k=k: contact_models()[k][1] for k in range(5)]
    doors = {
        "kinematics": lambda m: m.kinematics(0.5, 3),
        "dynamics": lambda m: m.dynamics(0.05, 2, max_steps=2000),
        "inverse": lambda m: m.inverse_dynamics(0.5, 3),
        "statics": lambda m: m.statics(),
        "parameters": lambda m: m.parameters(),
        "with_params": lambda m: m.with_params({next(iter(m.parameters())): 0.1}),
        "export": lambda m: m.export(tmp_path / "f.mbd", t_end=0.5, steps=3),
        "dof": lambda m: m.analyze_dof(),
        "sensitivities": lambda m: m.kinematics(0.5, 3,
                                                sensitivities=[next(iter(m.parameters()))]),
        "dump": lambda m: mbd2d.description.toml_io.dumps(m),
        "sweep": lambda m: mbd2d.sweep(m, {next(iter(m.parameters())): [0.1, 0.2]},
                                       t_end=0.5, steps=2, workers=1),
    }
    rng = random.Random(20261127)
    cases = int(os.environ.get("MBD2D_ENTRY_FUZZ", "80"))
    refused = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(cases):
            m = rng.choice(builds)()
            entries = (m.bodies + m.joints + m.drivers + m.forces + list(m.contacts))
            e = rng.choice(entries)
            f = rng.choice(dataclasses.fields(e))
            value = rng.choice(JUNK)
            setattr(e, f.name, value)
            door = rng.choice(list(doors))
            try:
                out = doors[door](m)
            except mbd2d.MbdError:
                refused += 1
                continue
            for a in ("q", "qd", "qdd", "lam", "dq_dp"):
                arr = getattr(out, a, None)
                if isinstance(arr, np.ndarray) and arr.dtype.kind == "f":
                    assert np.isfinite(arr).all(), (e, f.name, value, door)
    print(f"\n[entries] {cases} random fields: {refused} refused with an MbdError, the "
          "others finished finite", end="")
