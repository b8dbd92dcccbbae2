"""The design study's sweep without Python: the crank-rocker's coupler length over 200
values (examples/design_study.py), exported once (``mbd2d.export_sweep``) and run by the
standalone ``mbd2d-solve``, which writes the CSV the Python sweep writes
(``mbd2d.write_sweep``) byte for byte, the failed variants' messages (dead centres, no
assembly) in the Python words; then a run with design sensitivities and measure columns, byte
for byte.

Usage::

    python examples/standalone_sweep.py [--out DIR]

Exit code 0 when both files agree with the Python path's, 1 otherwise.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import mbd2d

HERE = Path(__file__).resolve().parent


def solver() -> str:
    """mbd2d-solve next to this Python, or on PATH."""
    here = Path(sys.executable).parent / "mbd2d-solve"
    found = str(here) if here.exists() else shutil.which("mbd2d-solve")
    if not found:
        raise FileNotFoundError("mbd2d-solve not found: `pip install .` installs it next to "
                                "`mbd2d`")
    return found


def run_solve(mbd: Path, csv: Path) -> tuple[float, subprocess.CompletedProcess]:
    t = time.perf_counter()
    r = subprocess.run([solver(), str(mbd), str(csv)], capture_output=True, text=True,
                       timeout=300)
    return time.perf_counter() - t, r


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "output")
    out: Path = ap.parse_args(argv).out
    out.mkdir(parents=True, exist_ok=True)
    model = mbd2d.load(HERE / "fourbar_grashof.toml")
    # coupler lengths 1 .. 5 (B at x = length - 1.75 in the coupler frame), positions only
    cases = {"joint.B.points.0.0": np.linspace(1.0, 5.0, 200) - 1.75}
    kw = dict(t_end=1.0, steps=120, positions_only=True)
    mbd2d.export_sweep(model, out / "sweep.mbd", cases, **kw)
    dt, r = run_solve(out / "sweep.mbd", out / "sweep_solve.csv")
    t = time.perf_counter()
    ds = mbd2d.sweep(model, cases, workers=1, **kw)
    mbd2d.write_sweep(ds, out / "sweep_python.csv")
    dp = time.perf_counter() - t
    same_sweep = r.returncode == 0 and \
        (out / "sweep_solve.csv").read_bytes() == (out / "sweep_python.csv").read_bytes()
    print(f"  sweep of 200 coupler lengths ({int(ds.attrs['failed'])} fail: dead centre or "
          f"no assembly): mbd2d-solve {dt:.2f} s, Python sweep + write_sweep {dp:.2f} s; "
          f"the same file byte for byte (rows, numbers, statuses and messages): {same_sweep}")

    names = ["joint.B.points.0.0", "joint.O4.points.1.0"]
    measures = ["transmission_angle:B", "velocity_ratio:motor:rocker.theta"]
    model.export(out / "sens.mbd", t_end=1.0, steps=360, sensitivities=names,
                 measures=measures)
    _, r2 = run_solve(out / "sens.mbd", out / "sens_solve.csv")
    res = model.kinematics(1.0, 360, sensitivities=names)
    res.to_csv(out / "sens_python.csv", sensitivities=True, measures=measures)
    same_sens = r2.returncode == 0 and \
        (out / "sens_solve.csv").read_text() == (out / "sens_python.csv").read_text()
    header = (out / "sens_solve.csv").read_text().split("\n", 1)[0].split(",")
    print(f"  one crank turn with {len(names)} sensitivities and {len(measures)} measures: "
          f"{len(header)} columns, the same CSV: {same_sens}")
    return 0 if same_sweep and same_sens else 1


if __name__ == "__main__":
    sys.exit(main())
