"""Kinematics speed: microseconds per output step (position + velocity + acceleration) with
the whole time loop inside the Fortran core, one f2py call per analysis.

    python bench/kinematics_speed.py [--steps N] [--repeats R]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import mbd2d
from mbd2d import _core
from mbd2d.pack import pack

EX = Path(__file__).resolve().parents[1] / "examples"
CASES = {"four-bar (Grashof)": "fourbar_grashof.toml", "slider-crank": "slider_crank.toml",
         "eccentric cam": "cam_follower.toml"}


def core_us_per_step(model: mbd2d.Model, t_end: float, steps: int, repeats: int) -> dict:
    """Best-of-repeats wall time of one core call, per output step."""
    p = pack(model)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = _core.core_kinematics(p.nb, p.ctab, p.rpar, p.neq, p.q0, 0.0, t_end, steps,
                                    0.0, 0, 0.0, 1, 0, steps + 1)
        best = min(best, time.perf_counter() - t0)
        status, msg = out[-2], out[-1]
        assert status == 0, msg
    iinfo = out[3]
    return {"us_per_step": 1e6 * best / steps, "steps": steps,
            "newton_corrections_per_step": int(iinfo[5]) / steps,
            "lu_per_step": int(iinfo[6]) / steps}


def main() -> dict:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    rows = {}
    for label, f in CASES.items():
        m = mbd2d.load(EX / f)
        # one crank turn per second; 10 turns
        rows[label] = core_us_per_step(m, 10.0, args.steps, args.repeats)
        r = rows[label]
        print(f"{label:22s} {r['us_per_step']:7.3f} us/step  "
              f"({r['newton_corrections_per_step']:.2f} Newton corrections, "
              f"{r['lu_per_step']:.2f} LU per step)")
    return rows


if __name__ == "__main__":
    print(json.dumps(main(), indent=1))
