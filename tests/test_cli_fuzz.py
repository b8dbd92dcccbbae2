"""The command line's new doors against seeded random arguments: whatever the flags hold
(--sensitivities, --measure, --param, --sigma, --point, --export-samples, --analysis check,
sweep),
`mbd2d` ends with a documented exit code (0 ok, 2 bad input, 3 singular configuration, 4
other numerical failure) and, for a failure, its own message: never an exception out of
main(), never a traceback. ``MBD2D_CLI_FUZZ`` sets the number of command lines (default 60).
"""
from __future__ import annotations

import os
import random
from pathlib import Path

import pytest

from mbd2d.cli import main

EX = Path(__file__).resolve().parents[1] / "examples"
N = int(os.environ.get("MBD2D_CLI_FUZZ", "60"))
MODELS = ["fourbar_grashof.toml", "fourbar_masses.toml", "pendulum_spring.toml",
          "fourbar_seed.toml", "slider_crank.toml"]
NAMES = ["joint.B.points.0.0", "joint.A.points.1.0", "body.coupler.mass", "model.gravity.1",
         "force.torsion.stiffness", "driver.motor.f.poly.1", "joint.B.point.0.0", "",
         "body.bar.mass", ",", "joint.O4.points.1.0,joint.B.points.0.1"]
MEASURES = ["transmission_angle:B", "transmission_angle:O2", "velocity_ratio:motor:rocker.theta",
            "mechanical_advantage:motor:slider.x", "dead_centre_distance", "speed", ":",
            "velocity_ratio:motor", "transmission_angle:B:coupler", "velocity_ratio:a:b:c:d"]
RANGES = ["joint.B.points.0.0=1.5:2.0:3", "joint.O4.points.1.0=2.0:6.0:3",
          "joint.A.points.0.0=-0.5:0.5:2", "body.bar.mass=0.5:2:2", "body.coupler.mass=1:2:2"]
NUMBERS = ["1", "0", "-1", "1e-3", "nan", "inf", "1e300", "abc", "", "2:3", "1.5:2.0:3",
           "1.5:2.0:0", "1.5:2.0:1000000000", "0,1", "coupler:0,1", "ground:0,0", "x:y"]


def _command(rng: random.Random, tmp: Path) -> list[str]:
    model = str(EX / rng.choice(MODELS))
    cmd = rng.choice(["kinematics", "inverse-dynamics", "dynamics", "statics", "export",
                      "tolerance", "parameters", "check", "plot", "sweep", "modes", "frf",
                      "linearize"])
    argv = [cmd, model]
    if cmd == "export":
        argv.append(str(tmp / "f.mbd"))
    if cmd in ("kinematics", "inverse-dynamics", "dynamics", "export", "tolerance", "plot",
               "sweep"):
        argv += ["--t-end", rng.choice(["0.2", "1", "1", "0.5", "-1", "nan"]),
                 "--steps", rng.choice(["4", "4", "3", "0"])]
    if cmd in ("kinematics", "inverse-dynamics", "dynamics", "plot"):
        good = "o.png" if cmd == "plot" else rng.choice(["o.csv", "o.npz"])
        argv += ["--out", str(tmp / rng.choice([good, good, good, "o.txt"]))]
    if cmd in ("statics", "check", "modes") and rng.random() < 0.5:
        argv += ["--out", str(tmp / rng.choice(["s.csv", "s.txt"]))]
    if cmd == "modes" and rng.random() < 0.5:
        argv += rng.choice([["--count", rng.choice(["1", "0", "-2", "x"])], ["--at-q0"],
                            ["--picture", str(tmp / rng.choice(["m.png", "m.gif", "m.txt"]))],
                            ["--mode", rng.choice(["0", "5", "-1"])],
                            ["--damped-out", str(tmp / rng.choice(["d.csv", "d.nc"]))]])
    if cmd == "frf":
        argv += ["--input", rng.choice(NAMES + ["model.gravity.1"]),
                 "--f", rng.choice(["0.1:10:5", "0:3:4", "1:2", "-1:2:3"] + NUMBERS)]
        if rng.random() < 0.5:
            argv += rng.choice([["--log"], ["--at-q0"],
                                ["--out", str(tmp / rng.choice(["f.csv", "f.nc"]))],
                                ["--picture", str(tmp / rng.choice(["b.png", "b.gif"]))],
                                ["--picture", str(tmp / "o.gif"), "--at",
                                 rng.choice(NUMBERS + ["1.5"])], ["--at", "2"],
                                ["--body", rng.choice(["coupler", "zzz"])]])
    if cmd == "linearize":
        argv += ["--input", rng.choice(NAMES + ["model.gravity.1", "driver.motor.f.poly.0"])]
        if rng.random() < 0.5:
            argv += rng.choice([["--at-q0"], ["--t", rng.choice(NUMBERS)],
                                ["--out", str(tmp / rng.choice(["s.csv", "s.nc"]))],
                                ["--input", rng.choice(NAMES)], ["--velocities"],
                                ["--efforts"]])
    if cmd == "tolerance":
        argv += ["--samples", rng.choice(["0", "3", "3", "1"]), "--workers", "1",
                 "--out", str(tmp / rng.choice(["t.csv", "t.csv", "t.nc", "t.txt"]))]
        for _ in range(rng.randint(1, 2)):
            value = rng.choice(["1e-3", "1e-3", "1e-4"] + NUMBERS)
            argv += ["--sigma", f"{rng.choice(NAMES)}={value}"]
        if rng.random() < 0.3:
            argv += ["--point", rng.choice(NUMBERS)]
        if rng.random() < 0.2:
            argv += ["--export-samples", str(tmp / "mc.mbd")]
        if rng.random() < 0.3:
            argv += ["--analysis", rng.choice(["statics", "inverse_dynamics", "dynamics"])]
    if cmd in ("kinematics", "inverse-dynamics", "dynamics", "statics", "export", "sweep") and \
            rng.random() < 0.5:
        argv += ["--sensitivities", rng.choice(NAMES)]
    if cmd == "sweep":
        argv += ["--workers", "1", "--out", str(tmp / rng.choice(["w.csv", "w.csv", "w.nc", "w.txt"]))]
        if rng.random() < 0.3:
            argv += ["--analysis", rng.choice(["statics", "inverse_dynamics", "dynamics",
                                               "modes", "frf"])]
    if cmd in ("sweep", "export") and rng.random() < 0.25:   # a frequency response's inputs
        argv += ["--input", rng.choice(NAMES + ["model.gravity.1"]),
                 "--f", rng.choice(["0.1:10:5", "0:3:4"] + NUMBERS)]
    if cmd in ("kinematics", "inverse-dynamics", "dynamics", "export", "plot", "sweep",
               "tolerance") and rng.random() < 0.5:
        for _ in range(rng.randint(1, 2)):
            argv += ["--measure", rng.choice(MEASURES)]
    if cmd == "plot" and rng.random() < 0.5:
        argv += ["--what", "measures"]
    if cmd == "sweep" and rng.random() < 0.7:          # mostly a sweep that runs
        argv += ["--param", rng.choice(RANGES)]
    elif cmd == "sweep" or (cmd == "export" and rng.random() < 0.4):
        argv += ["--param", f"{rng.choice(NAMES)}={rng.choice(NUMBERS)}"]
        if rng.random() < 0.5:
            argv.append("--grid")
    if cmd == "export" and rng.random() < 0.3:
        argv += ["--analysis", rng.choice(["check", "statics", "dynamics", "inverse-dynamics",
                                           "modes", "frf", "linearize"])]
    if cmd == "parameters" and rng.random() < 0.5:
        argv += ["--match", rng.choice(["B", "zzz", ""])]
    if rng.random() < 0.15:
        argv.append("--positions-only")
    return argv


@pytest.mark.parametrize("seed", range(N))
def test_random_command_lines_end_with_a_documented_code(tmp_path: Path, capsys,
                                                         seed: int) -> None:
    rng = random.Random(seed)
    argv = _command(rng, tmp_path)
    try:
        code = main(argv)
    except SystemExit as exc:                 # argparse: a malformed command line
        code = exc.code
    out = capsys.readouterr()
    assert code in (0, 2, 3, 4), (argv, code, out.err[-1000:])
    assert "Traceback" not in out.err, (argv, out.err[-2000:])
    if code not in (0,):
        assert out.err.strip(), argv
