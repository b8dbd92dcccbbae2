"""Dynamics against model size: the free N-four-bar (examples/nfourbar.py, 1 kg bars under
gravity, every crank turning) with generalized-alpha at h = 1 ms and dopri5 at rtol 1e-6,
on the band path and, up to N = 200, the dense path (the baseline, measured in the same run).

Three CPU times (time.process_time) per N, method and path:
  setup         the first call (assembly, rank analysis, the saddle-point plan, the tangent's
                column groups) with one step;
  ms_per_step   the cost of a step: two calls of different lengths (generalized-alpha 10 and
                50 steps of 1 ms; dopri5 0.1 s and 0.8 s of motion, before the collinear
                passage), the difference of their times over the difference of their
                accepted steps (rejected steps and right-hand sides included), best of two;
  call_ms_per_step  the longer call's whole time over its steps (its start, the Python
                packing of the model and the result spread over them), the earlier measure.
The log-log slope is taken between N = 100 and the largest N of the band path, of both.

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


#: the two run lengths per method (t_end of the short and the long call)
SPANS = {"generalized-alpha": (0.01, 0.05), "dopri5": (0.1, 0.8)}


def _timed(m: Any, t_end: float, method: str, solver: str, repeats: int) -> tuple[float, Any]:
    """Best CPU time of `repeats` calls (one output row) and the last result."""
    best, res = math.inf, None
    for _ in range(max(1, repeats)):
        t0 = time.process_time()
        res = m.dynamics(t_end=t_end, steps=1, method=method, solver=solver, **METHODS[method])
        best = min(best, time.process_time() - t0)
    return best, res


def time_run(n: int, method: str, solver: str, repeats: int = 2) -> dict[str, Any]:
    """Setup (the first call, one step), the marginal CPU ms per step (the difference of a
    short and a long call; SPANS, lengthened by 300 / N below N = 300) and the long call's
    whole time per step."""
    m = build(n, driven=False, omega0=1.0)
    t0 = time.process_time()
    m.dynamics(t_end=1e-3, steps=1, method=method, solver=solver, **METHODS[method])
    setup = time.process_time() - t0
    # small models: longer runs, so that the difference of the two is not lost in timer noise
    scale = max(1.0, 300.0 / n)
    ta, tb = (scale * x for x in SPANS[method])
    da, ra = _timed(m, ta, method, solver, repeats)
    db, rb = _timed(m, tb, method, solver, repeats)
    na, nb = int(ra.stats["steps"]), max(int(rb.stats["steps"]), 1)
    marginal = 1e3 * (db - da) / (nb - na) if nb > na and db > da else None
    return {"n": n, "coordinates": 3 * (2 * n + 1), "solver": rb.stats.get("solver", solver),
            "setup_s": setup, "ms_per_step": marginal, "call_ms_per_step": 1e3 * db / nb,
            "steps": nb, "steps_short": na, "rejected": int(rb.stats["rejected_steps"]),
            "band": list(rb.stats.get("band", (0, 0)))}


def slope(rows: Sequence[dict], lo: int = 100, key: str = "ms_per_step") -> float | None:
    """Log-log slope of rows[key] against N from N = lo to the largest N."""
    pts = [r for r in rows if r["n"] >= lo]
    if len(pts) < 2:
        return None
    a, b = pts[0].get(key), pts[-1].get(key)
    if not (a and b and a > 0 and b > 0):
        return None
    return math.log(b / a) / math.log(pts[-1]["n"] / pts[0]["n"])


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
                # best of 3 on the band path at every N (N = 10,000 is memory-bound and its
                # time varies by 20% between runs on a shared machine); the dense baseline once
                r = time_run(n, method, solver, 1 if solver == "dense" else 3)
                rows.append(r)
                if log:
                    ms = r["ms_per_step"]
                    print(f"  {method:18s} {solver:6s} N = {n:5d}: "
                          f"{'-' if ms is None else f'{ms:9.3f}'} ms/step "
                          f"(whole call {r['call_ms_per_step']:.3f}), "
                          f"setup {r['setup_s']:.3f} s", flush=True)
            out["rows"][f"{method}/{solver}"] = rows
        band = out["rows"][f"{method}/banded"]
        out.setdefault("slopes", {})[method] = slope(band)
        out.setdefault("call_slopes", {})[method] = slope(band, key="call_ms_per_step")
        at = {r["n"]: r for r in band}
        if 1000 in at:
            out.setdefault("n1000", {})[method] = {
                "ms_per_step": at[1000]["ms_per_step"],
                "call_ms_per_step": at[1000]["call_ms_per_step"], "setup_s": at[1000]["setup_s"]}
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
        pts = [(r["n"], r["ms_per_step"]) for r in rows if r.get("ms_per_step")]
        if not pts:
            continue
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if
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
