"""Andrews' squeezing mechanism: accuracy and wall time of each dynamics method.

For each method at a loose and a tight setting (tolerances for the adaptive methods, two step
sizes for the fixed-step ones): the max error of the 7 relative angles at t = 0.03 against the
IVP test set reference, and the best-of-3 wall time of m.dynamics (time.perf_counter).

    python bench/andrews.py [--repeats R]
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import time
from pathlib import Path

import numpy as np

import mbd2d

EX = Path(__file__).resolve().parents[1] / "examples"

# (method, setting label, keyword arguments); generalized-alpha is shown both ways.
CASES = [
    ("generalized-alpha", "loose", dict(rtol=1e-6, atol=1e-8)),
    ("generalized-alpha", "tight", dict(rtol=1e-8, atol=1e-10)),
    ("generalized-alpha", "h=1e-5", dict(h=1e-5)),
    ("generalized-alpha", "h=5e-6", dict(h=5e-6)),
    ("dopri5", "loose", dict(rtol=1e-6, atol=1e-8)),
    ("dopri5", "tight", dict(rtol=1e-10, atol=1e-12)),
    ("partitioned", "loose", dict(rtol=1e-6, atol=1e-8)),
    ("partitioned", "tight", dict(rtol=1e-10, atol=1e-12)),
    ("baumgarte-rk4", "h=2e-5", dict(h=2e-5)),
    ("baumgarte-rk4", "h=1e-5", dict(h=1e-5)),
]


def _example():
    spec = importlib.util.spec_from_file_location("andrews_example", EX / "andrews.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def run_case(model: mbd2d.Model, ex, method: str, kw: dict, repeats: int) -> dict:
    """Best-of-repeats wall time and the angle error of one setting."""
    best, res = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = model.dynamics(t_end=ex.T_END, steps=1, method=method, **kw)
        best = min(best, time.perf_counter() - t0)
    err = np.abs(ex.angle_errors(res))
    return {"settings": kw, "max_error": float(err.max()), "wall_s": best,
            "steps": res.stats["steps"], "rejected": res.stats["rejected_steps"]}


def main(repeats: int = 3) -> dict:
    ex = _example()
    model = ex.build()
    rows: dict = {}
    print(f"{'method':18s} {'setting':8s} {'settings':30s} {'max error':>10s} {'wall s':>8s} "
          f"{'steps':>7s} {'rej':>6s}")
    for method, label, kw in CASES:
        r = run_case(model, ex, method, kw, repeats)
        rows.setdefault(method, {})[label] = r
        s = ", ".join(f"{k}={v:g}" for k, v in kw.items())
        print(f"{method:18s} {label:8s} {s:30s} {r['max_error']:10.2e} {r['wall_s']:8.3f} "
              f"{r['steps']:7d} {r['rejected']:6d}", flush=True)
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", action="store_true", help="also print the dict as JSON")
    a = ap.parse_args()
    out = main(a.repeats)
    if a.json:
        print(json.dumps(out, indent=1))
