"""Seeded random combinations of analysis, settings, output columns, design sensitivities and
measures (and drivers with a motion law and a table) through both paths: whatever `Model.export` accepts, mbd2d-solve writes the CSV the
Python result writes (text for text) and ends with the exit code of the Python run (0, or 3
at a dead centre with the rows up to there). ``MBD2D_RANDOM_FILES`` sets the number of
combinations (default 200; an export the model refuses is not counted as a failure).
"""
from __future__ import annotations

import os
import random
import subprocess
import warnings
from pathlib import Path

import pytest

import mbd2d

from test_standalone import find_solver

EX = Path(__file__).resolve().parents[1] / "examples"
N = int(os.environ.get("MBD2D_RANDOM_FILES", "200"))
MODELS = ["fourbar_grashof", "fourbar_masses", "pendulum_spring", "slider_crank", "cam_follower",
          "fourbar_seed"]
NAMES = ["joint.B.points.0.0", "body.coupler.mass", "model.gravity.1", "force.torsion.stiffness",
         "body.bar.mass", "joint.pivot.points.0.0", "driver.motor.f.poly.1",
         "joint.guide.points.0.0"]
MEASURES = ["transmission_angle:B", "dead_centre_distance", "velocity_ratio:motor:rocker.theta",
            "mechanical_advantage:motor:slider.x"]
OUTPUTS = ["energy", "multipliers", "reactions", "efforts"]


#: a driver's function dressed with a step and a table (drawn after the case, so the cases
#: of the seeds stay as they were), and the design parameters that then exist
STEP = {"t0": 0.1, "t1": 0.25, "h": 0.2, "law": "modified-sine"}
TABLE = {"t": [0.0, 0.2, 0.35, 0.5, 0.8, 1.0], "y": [0.0, 0.05, -0.02, 0.04, 0.0, 0.01]}
DRESSED = ["driver.motor.f.step.0.t1", "driver.motor.f.step.0.h", "driver.motor.f.table.y.2"]


def _dress(model: mbd2d.Model, rng: random.Random, kw: dict) -> None:
    """Add a step and a table to the model's motor driver (when it has one) at random,
    sometimes with their parameters among the sensitivities."""
    motor = next((d for d in model.drivers if d.name == "motor"), None)
    if motor is None or rng.random() < 0.6:
        return
    f = motor.f
    motor.f = mbd2d.TimeFunction(poly=f.poly, harmonic=f.harmonic,
                                 step=(mbd2d.Step(**STEP),),
                                 table=mbd2d.Table(tuple(TABLE["t"]), tuple(TABLE["y"])))
    if "sensitivities" in kw and rng.random() < 0.5:
        kw["sensitivities"] = kw["sensitivities"][:1] + [rng.choice(DRESSED)]


def _case(rng: random.Random) -> tuple[str, dict]:
    kw: dict = {"analysis": rng.choice(["kinematics", "inverse-dynamics", "dynamics",
                                        "statics"])}
    if kw["analysis"] != "statics":
        kw.update(t_end=rng.choice([0.3, 1.0]), steps=rng.choice([3, 4]))
        if rng.random() < 0.3:
            kw["every"] = rng.choice([2, 5])
    if rng.random() < 0.4:
        kw["sensitivities"] = rng.sample(NAMES, rng.randint(1, 2))
    if rng.random() < 0.4:
        kw["measures"] = rng.sample(MEASURES, rng.randint(1, 2))
    if rng.random() < 0.3:
        kw["outputs"] = rng.sample(OUTPUTS, rng.randint(1, 2))
    if kw["analysis"] == "dynamics" and rng.random() < 0.5:
        kw.update(method="generalized-alpha", h=1e-3)
    return rng.choice(MODELS), kw


@pytest.mark.parametrize("seed", range(N))
def test_random_files_give_the_python_csv(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    name, kw = _case(rng)
    model = mbd2d.load(EX / f"{name}.toml")
    _dress(model, rng, kw)
    mbd = tmp_path / "f.mbd"
    try:
        model.export(mbd, **kw)
    except mbd2d.ModelError:
        return                                   # refused for the model, as the run would be
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "s.csv")], capture_output=True,
                       text=True, timeout=120)
    run = {"kinematics": model.kinematics, "inverse-dynamics": model.inverse_dynamics,
           "dynamics": model.dynamics, "statics": model.statics}[kw["analysis"]]
    args = {k: v for k, v in kw.items() if k in ("t_end", "steps", "every", "sensitivities",
                                                 "method", "h")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res, code = run(**args), 0
        except mbd2d.SingularConfigurationError as err:
            res, code = err.results, 3
    assert r.returncode == code, (name, kw, r.stderr)
    opts: dict = {k: True for k in kw.get("outputs", [])}
    if kw.get("sensitivities"):
        opts["sensitivities"] = True
    if kw.get("measures"):
        opts["measures"] = kw["measures"]
    res.to_csv(tmp_path / "p.csv", **opts)
    assert (tmp_path / "s.csv").read_text() == (tmp_path / "p.csv").read_text(), (name, kw)
