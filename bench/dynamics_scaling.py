"""Dynamics against model size: the free N-four-bar (examples/nfourbar.py, 1 kg bars under
gravity, every crank turning) with generalized-alpha at h = 1 ms and dopri5 at rtol 1e-6,
on the band path and, up to N = 200, the dense path (the baseline, measured in the same run).

CPU time (time.process_time) per integrator step of a run of 20 to 50 steps (its start
and first iteration matrix spread over them), and the setup: the first call (assembly,
rank analysis, the saddle-point plan, the tangent's column groups) with one step. The log-log slope is fitted between N = 100 and the largest N of the band path.

    python bench/dynamics_scaling.py [--quick]
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any, Sequence

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

from nfourbar import build  # noqa: E402

METHODS = {"generalized-alpha": {"h": 1e-3}, "dopri5": {"rtol": 1e-6}}
N_BAND = (10, 30, 100, 300, 1000, 3000, 10000)
#: the dense baseline (dopri5's dense projections grow like N^3 per step: fewer N)
N_DENSE = {"generalized-alpha": (10, 30, 100, 200), "dopri5": (10, 30, 100)}


def time_run(n: int, method: str, solver: str, steps: int) -> dict[str, Any]:
    """Setup (the first call, one step) and CPU ms per integrator step of a steps-ms run
    after it (its start and first iteration matrix spread over the steps)."""
    m = build(n, driven=False, omega0=1.0)
    kw = METHODS[method]
    t0 = time.process_time()
    m.dynamics(t_end=1e-3, steps=1, method=method, solver=solver, **kw)
    t1 = time.process_time()
    res = m.dynamics(t_end=steps * 1e-3, steps=steps, method=method, solver=solver,
                     every=steps, **kw)
    t2 = time.process_time()
    nst = max(int(res.stats["steps"]), 1)
    return {"n": n, "coordinates": 3 * (2 * n + 1), "solver": res.stats.get("solver", solver),
            "setup_s": t1 - t0, "ms_per_step": 1e3 * (t2 - t1) / nst, "steps": nst,
            "band": list(res.stats.get("band", (0, 0)))}


def slope(rows: Sequence[dict], lo: int = 100) -> float | None:
    """Log-log slope of ms/step against N from N = lo to the largest N."""
    pts = [r for r in rows if r["n"] >= lo]
    if len(pts) < 2:
        return None
    a, b = pts[0], pts[-1]
    if not (a["ms_per_step"] > 0 and b["ms_per_step"] > 0):
        return None
    return math.log(b["ms_per_step"] / a["ms_per_step"]) / math.log(b["n"] / a["n"])


def study(quick: bool = False, log: bool = True) -> dict[str, Any]:
    """Every method on both paths over N; slopes and the N = 1000 figures."""
    n_band = (10, 100, 1000) if quick else N_BAND
    n_dense = {k: (10, 30) for k in METHODS} if quick else N_DENSE
    out: dict[str, Any] = {"model": "free N-four-bar (examples/nfourbar.py, omega0 = 1)",
                           "settings": {k: dict(v) for k, v in METHODS.items()}, "rows": {}}
    for method in METHODS:
        for solver, ns in (("banded", n_band), ("dense", n_dense[method])):
            rows = []
            for n in ns:
                if solver == "dense":
                    steps = 20 if n <= 30 else 5
                else:
                    steps = 50 if n <= 1000 else 20
                r = time_run(n, method, solver, steps)
                rows.append(r)
                if log:
                    print(f"  {method:18s} {solver:6s} N = {n:5d}: {r['ms_per_step']:9.3f} "
                          f"ms/step, setup {r['setup_s']:.3f} s", flush=True)
            out["rows"][f"{method}/{solver}"] = rows
        band = out["rows"][f"{method}/banded"]
        out.setdefault("slopes", {})[method] = slope(band)
        at = {r["n"]: r for r in band}
        if 1000 in at:
            out.setdefault("n1000", {})[method] = {"ms_per_step": at[1000]["ms_per_step"],
                                                   "setup_s": at[1000]["setup_s"]}
    return out


def chart(data: dict, path: str | Path) -> Path:
    """ms/step against N on log-log axes, each method and path."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    for key, rows in data["rows"].items():
        if not rows:
            continue
        ax.loglog([r["n"] for r in rows], [r["ms_per_step"] for r in rows], "o-" if
                  key.endswith("banded") else "s--", label=key)
    ax.set_xlabel("N (loops of the N-four-bar)")
    ax.set_ylabel("CPU ms per integrator step")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    ax.set_title("dynamics of the free N-four-bar")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def main(argv: Sequence[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    return study(a.quick)


if __name__ == "__main__":
    main()
