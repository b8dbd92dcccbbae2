"""Seeded random sweeps through mbd2d-solve: a model, one or two swept parameters, an
analysis, measures and design sensitivities drawn at random; the file ``export_sweep``
writes gives, in mbd2d-solve, the CSV of the Python sweep byte for byte, failed cases'
messages included.
A combination the export refuses (a ModelError) must be refused by the sweep alike.
``MBD2D_SWEEP_FUZZ`` sets the number of combinations (default 40).

Reference: the Python sweep, itself checked case by case against single runs of
``with_params`` models (tests/test_sweep.py) and closed forms (tests/test_sweep_measures.py,
tests/test_sweep_sensitivities.py).
"""
from __future__ import annotations

import os
import random
import subprocess
from pathlib import Path

import numpy as np
import pytest

import mbd2d

from test_standalone import find_solver

pytest.importorskip("xarray")

EX = Path(__file__).resolve().parents[1] / "examples"
N = int(os.environ.get("MBD2D_SWEEP_FUZZ", "40"))
#: per model: parameters to sweep or differentiate, and measures it has
MODELS = {
    "fourbar_grashof.toml": (
        ["joint.B.points.0.0", "joint.A.points.1.0", "joint.B.points.1.0",
         "joint.O4.points.1.0", "joint.A.points.0.0"],
        ["transmission_angle:B", "transmission_angle:A:coupler",
         "velocity_ratio:motor:rocker.theta", "mechanical_advantage:motor:coupler.theta",
         "dead_centre_distance", "velocity_ratio:crank.theta:rocker.theta"]),
    "fourbar_masses.toml": (
        ["joint.B.points.0.0", "body.coupler.mass", "joint.O4.points.1.0",
         "body.rocker.inertia"],
        ["transmission_angle:B", "velocity_ratio:motor:rocker.theta", "dead_centre_distance"]),
    "slider_crank.toml": (
        ["joint.guide.points.0.1", "joint.guide.axes.1.1", "joint.guide.axes.0.0",
         "joint.A.points.1.0", "joint.B.points.1.1"],
        ["transmission_angle:B", "mechanical_advantage:motor:slider.x",
         "velocity_ratio:motor:rod.theta", "dead_centre_distance"]),
}


def _draw(rng: random.Random) -> tuple[str, dict, str, dict]:
    name = rng.choice(sorted(MODELS))
    params, measures = MODELS[name]
    base = mbd2d.load(EX / name).parameters()
    n = rng.randint(1, 4)
    cases = {p: base[p] + rng.uniform(-0.3, 0.3) * np.linspace(-1.0, 1.0, n)
             for p in rng.sample(params, rng.randint(1, 2))}
    analysis = rng.choice(["kinematics", "kinematics", "inverse_dynamics", "dynamics"])
    kw: dict = dict(t_end=rng.choice([0.3, 1.0]), steps=rng.choice([5, 12]))
    if rng.random() < 0.7:
        kw["measures"] = rng.sample(measures, rng.randint(1, 2))
    if analysis == "dynamics":
        kw["method"] = rng.choice(["dopri5", "generalized-alpha"])
    if rng.random() < 0.5:
        kw["sensitivities"] = rng.sample(params, 1)
    elif analysis == "kinematics" and rng.random() < 0.3:
        kw["positions_only"] = True
    return name, cases, analysis, kw


@pytest.mark.parametrize("seed", range(N))
def test_random_sweep_files_give_the_python_csv(tmp_path: Path, seed: int) -> None:
    name, cases, analysis, kw = _draw(random.Random(seed))
    model = mbd2d.load(EX / name)
    try:
        mbd2d.export_sweep(model, tmp_path / "s.mbd", cases, analysis, **kw)
    except mbd2d.ModelError:                  # refused (no masses, no dopri5 ...): the sweep
        with pytest.raises(mbd2d.ModelError):  # refuses it alike
            mbd2d.sweep(model, cases, analysis, workers=1, **kw)
        return
    ds = mbd2d.sweep(model, cases, analysis, workers=1, **kw)
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    r = subprocess.run([find_solver(), str(tmp_path / "s.mbd"), str(tmp_path / "solve.csv")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, (name, cases, analysis, kw, r.stderr)
    # (failed cases too: dead centres, contradictions, failed assemblies and the integrators'
    # failures are written in the Python words)
    assert (tmp_path / "solve.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
