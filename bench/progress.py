"""Cost of the progress bar: each long analysis with ``progress=True`` (the core on a worker
thread publishing its output count, the bar polled 10 times a second) against the same call
with ``progress=False``, measured in the same run (best-of-R wall time, interleaved), and the
check that both give the same numbers bit for bit.

Cases: kinematics of the Grashof four-bar (10^6 steps, every output kept or every 1000th),
inverse dynamics of the four-bar with masses (2 x 10^5 steps), dopri5 and generalized-alpha
dynamics of the spring pendulum (500 s).

Target (issue 12): no measurable slowdown (ratio within the run-to-run scatter, about 1 +- 0.05).

    python bench/progress.py [--quick] [--repeats R]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

import mbd2d

BENCH = Path(__file__).resolve().parent
EX = BENCH.parent / "examples"


def best(fn: Callable[[], Any]) -> tuple[float, Any]:
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def compare(label: str, run: Callable[[bool], Any], repeats: int) -> dict[str, Any]:
    tp, tb = float("inf"), float("inf")
    plain = barred = None
    for _ in range(repeats):
        t, plain = best(lambda: run(False))
        tp = min(tp, t)
        t, barred = best(lambda: run(True))
        tb = min(tb, t)
    same = all(np.array_equal(getattr(plain, f), getattr(barred, f))
               for f in ("t", "q", "qd", "qdd", "lam") if hasattr(plain, f))
    return {"case": label, "plain_s": tp, "bar_s": tb, "ratio": tb / tp, "identical": same}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small smoke run")
    ap.add_argument("--out", type=Path, default=BENCH / "results" / "progress.json")
    a = ap.parse_args(argv)
    scale = 0.02 if a.quick else 1.0
    reps = 2 if a.quick else a.repeats
    n = int(10**6 * scale)
    four = mbd2d.load(EX / "fourbar_grashof.toml")
    heavy = mbd2d.load(EX / "fourbar_masses.toml")
    swing = mbd2d.load(EX / "pendulum_spring.toml")
    rows = [
        compare(f"kinematics four-bar, {n} steps, every output",
                lambda p: four.kinematics(n * 1e-3, n, progress=p), reps),
        compare(f"kinematics four-bar, {n} steps, every 1000th",
                lambda p: four.kinematics(n * 1e-3, n, every=1000, progress=p), reps),
        compare(f"inverse dynamics four-bar, {n // 5} steps",
                lambda p: heavy.inverse_dynamics(n * 2e-4, n // 5, progress=p), reps),
        compare("dopri5 spring pendulum, 500 s",
                lambda p: swing.dynamics(500 * scale, 5000, rtol=1e-9, atol=1e-9,
                                         progress=p), reps),
        compare("generalized-alpha spring pendulum, 500 s, h = 1 ms",
                lambda p: swing.dynamics(500 * scale, 5000, method="generalized-alpha",
                                         h=1e-3, progress=p), reps),
    ]
    for r in rows:
        print(f"{r['case']:52s} {r['plain_s']:8.3f} s {r['bar_s']:8.3f} s  ratio "
              f"{r['ratio']:5.3f}  {'identical' if r['identical'] else 'DIFFERENT'}")
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps({"repeats": reps, "quick": a.quick, "rows": rows}, indent=1)
                     + "\n", encoding="utf-8")
    return 0 if all(r["identical"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
