"""Scaling of kinematics with model size: time per kinematic step of the driven N-four-bar.

The model is bench/models.driven_nfourbar(n): N + 1 cranks and N couplers, 3 (2N + 1)
coordinates, crank 0 driven at theta = pi/2 - t. Every run uses the same step size
h = 1e-3 s (so the Newton work per step is comparable across N) from t = 0; a run has at most
MAX_STEPS steps (t_end <= 1 s keeps the cranks well away from the horizontal change point at
t = pi/2).

Time per step is the marginal cost (T(s) - T(1)) / (s - 1), T(s) being the best-of-N wall time
(time.perf_counter) of one ``model.kinematics`` call with s steps. Subtracting the one-step run
removes the fixed costs of a call (packing the model, assembly), so small models are not
dominated by Python overhead. s comes from calibration runs of growing length (so that one
call takes about half of TARGET_S), and calls are repeated until TARGET_S is spent.

Both linear-solver paths are timed when ``Model.kinematics`` accepts ``solver=``: "dense" for
N <= DENSE_MAX_N, "banded" for every N. Without it, the default path is timed as "dense" and
"banded" is recorded as unavailable.

    python bench/scaling.py [--out DIR] [--quick]

writes DIR/scaling.json and DIR/scaling.png (DIR defaults to bench/results).
"""
from __future__ import annotations

import argparse
import inspect
import json
import math
import sys
import time
import warnings
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import mbd2d

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))
from models import driven_nfourbar  # noqa: E402

N_VALUES = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000)
N_QUICK = (1, 5, 20, 100, 200, 1000)
DENSE_MAX_N = 200
H = 1e-3                     # step size of every run (s)
MAX_STEPS = 1000             # t_end = steps * H <= 1 s < pi/2
TARGET_S = 1.0               # total time of the timed calls of one row
TARGET_QUICK_S = 0.4
TARGET_N = 1000              # the target: N = 1000 at <= TARGET_MS per step
TARGET_MS = 2.0

Row = dict[str, Any]


def has_parameter(name: str) -> bool:
    """Whether ``mbd2d.Model.kinematics`` accepts the keyword `name`."""
    return name in inspect.signature(mbd2d.Model.kinematics).parameters


def run_once(model: mbd2d.Model, steps: int, solver: str | None) -> tuple[float, Any]:
    """Wall time and result of one ``model.kinematics`` call of `steps` steps of size H."""
    kw: dict[str, Any] = {} if solver is None else {"solver": solver}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.errors.MbdWarning)
        t0 = time.perf_counter()
        res = model.kinematics(t_end=steps * H, steps=steps, **kw)
        return time.perf_counter() - t0, res


def best_within(model: mbd2d.Model, steps: int, solver: str | None, budget_s: float,
                max_calls: int = 200) -> tuple[float, Any, int]:
    """Best wall time of calls repeated until budget_s is spent (at least one call).

    Returns
    -------
    tuple
        (best seconds, the result of the best call, number of calls).
    """
    best: tuple[float, Any] | None = None
    spent, calls = 0.0, 0
    while calls < max(1, max_calls) and (calls == 0 or spent < budget_s):
        t, res = run_once(model, steps, solver)
        spent, calls = spent + t, calls + 1
        if best is None or t < best[0]:
            best = (t, res)
    return best[0], best[1], calls


def plan(per_step: float, target_s: float) -> int:
    """Steps per call so that one call takes about half of target_s, in [10, MAX_STEPS].

    Parameters
    ----------
    per_step : float
        Estimated seconds per step.
    target_s : float
        Time budget of the timed calls of one row.

    Returns
    -------
    int
    """
    return int(min(MAX_STEPS, max(10, 0.5 * target_s / max(per_step, 1e-9))))


def calibrate(model: mbd2d.Model, solver: str | None, t_one: float,
              target_s: float) -> tuple[int, tuple[float, Any]]:
    """Steps per call, from runs of 10, 40, 160, ... steps until one takes a tenth of the
    budget beyond the one-step call; also returns the last calibration run (time, result)."""
    steps = 10
    while True:
        run = run_once(model, steps, solver)
        if run[0] - t_one >= 0.1 * target_s or steps >= MAX_STEPS:
            break
        steps = min(MAX_STEPS, 4 * steps)
    per_step = max(run[0] - t_one, 1e-9) / (steps - 1)
    return plan(per_step, target_s), (steps, run)


def time_row(n: int, solver: str | None, target_s: float) -> Row:
    """Time per step of the N-four-bar on one solver path (see the module docstring)."""
    model = driven_nfourbar(n)
    run_once(model, 1, solver)                                   # warm-up
    t_one = best_within(model, 1, solver, 0.1 * target_s, 50)[0]
    steps, (cal_steps, cal_run) = calibrate(model, solver, t_one, target_s)
    if cal_steps == steps and cal_run[0] >= target_s:    # costly: calibration is the run
        (t_all, res), calls = cal_run, 1
    else:
        t_all, res, calls = best_within(model, steps, solver, target_s)
    marginal = max(t_all - t_one, 0.0) / (steps - 1)
    stats = getattr(res, "stats", {}) or {}
    return {"n": n, "coordinates": int(np.shape(res.q)[1]), "solver": solver or "default",
            "solver_ran": stats.get("solver", "dense" if solver is None else solver),
            "band": stats.get("band"), "steps": steps, "calls": calls, "h": H,
            "call_s": t_all, "one_step_call_s": t_one,
            "us_per_step": 1e6 * marginal, "us_per_step_whole_call": 1e6 * t_all / steps,
            "newton_corrections_per_step": stats.get("newton_corrections", 0) / steps,
            "factorizations_per_step": stats.get("factorizations", 0) / steps}


def fit_slope(rows: Sequence[Row], n_min: int = 10) -> float | None:
    """Least-squares slope of log(us_per_step) against log(N) over the rows with N >= n_min."""
    pts = [(math.log(r["n"]), math.log(r["us_per_step"])) for r in rows
           if r.get("us_per_step") and r["us_per_step"] > 0 and r["n"] >= n_min]
    if len(pts) < 2:
        return None
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def sweep(solver: str | None, n_values: Sequence[int], target_s: float,
          log: bool = True) -> list[Row]:
    """One row per N; a failure is recorded with its message and the sweep goes on."""
    rows = []
    for n in n_values:
        try:
            row = time_row(n, solver, target_s)
        except Exception as e:  # noqa: BLE001 - recorded, the sweep goes on
            row = {"n": n, "solver": solver or "default", "us_per_step": None,
                   "message": f"{type(e).__name__}: {e}"}
        rows.append(row)
        if log:
            print("  " + format_row(row), flush=True)
    return rows


def format_row(row: Row) -> str:
    """One printed line."""
    if row.get("us_per_step") is None:
        return f"{row['solver']:8s} N = {row['n']:5d}  FAILED: {row.get('message', '')[:100]}"
    return (f"{row['solver']:8s} N = {row['n']:5d} ({row['coordinates']:5d} coordinates) "
            f"{row['us_per_step']:11.2f} us/step  ({row['steps']} steps x {row['calls']} calls, "
            f"ran {row['solver_ran']})")


def scaling(quick: bool = False, log: bool = True) -> dict:
    """Time per kinematic step against N for the dense and banded paths.

    Parameters
    ----------
    quick : bool
        Fewer N values and a smaller time budget per row.
    log : bool
        Print each row.

    Returns
    -------
    dict
        {"model", "method", "rows": {"dense": [...], "banded": [...]}, "banded_available",
        "banded_slope", "dense_slope", "target": {...}}.
    """
    n_values = N_QUICK if quick else N_VALUES
    target_s = TARGET_QUICK_S if quick else TARGET_S
    banded = has_parameter("solver")
    out: dict[str, Any] = {
        "model": "bench/models.driven_nfourbar(N): 3 (2N + 1) coordinates, crank 0 driven",
        "method": f"Marginal time per step (T(s) - T(1)) / (s - 1) of model.kinematics at "
                  f"h = {H} s, best of N calls; about {target_s} s of timed calls per row",
        "quick": quick, "banded_available": banded, "rows": {}}
    if log:
        print("dense path" + ("" if banded else " (no solver= keyword: the default path)"))
    out["rows"]["dense"] = sweep("dense" if banded else None,
                                 [n for n in n_values if n <= DENSE_MAX_N], target_s, log)
    if banded:
        if log:
            print("banded path")
        out["rows"]["banded"] = sweep("banded", n_values, target_s, log)
    else:
        out["rows"]["banded"] = []
        out["banded_unavailable_reason"] = ("Model.kinematics has no solver= keyword in this "
                                            "mbd2d version")
    out["dense_slope"] = fit_slope(out["rows"]["dense"])
    out["banded_slope"] = fit_slope(out["rows"]["banded"])
    out["target"] = target_figure(out)
    return out


def target_figure(data: dict) -> dict:
    """The N = TARGET_N figure of the banded path (or the best available path)."""
    for path in ("banded", "dense"):
        row = next((r for r in data["rows"].get(path, [])
                    if r["n"] == TARGET_N and r.get("us_per_step")), None)
        if row is not None:
            ms = row["us_per_step"] / 1e3
            return {"path": path, "n": TARGET_N, "ms_per_step": ms, "limit_ms": TARGET_MS,
                    "met": ms <= TARGET_MS}
    return {"path": None, "n": TARGET_N, "ms_per_step": None, "limit_ms": TARGET_MS,
            "met": False}


def chart(data: dict, path: str | Path) -> Path:
    """Log-log chart of time per step against N, both paths and a slope-1 reference line.

    Parameters
    ----------
    data : dict
        The output of scaling().
    path : str or Path
        The PNG to write.

    Returns
    -------
    Path
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    styles = {"dense": ("tab:red", "s"), "banded": ("tab:blue", "o")}
    anchor = None
    for name, rows in data["rows"].items():
        ok = [r for r in rows if r.get("us_per_step")]
        if not ok:
            continue
        slope = data.get(f"{name}_slope")
        label = f"{name} (as run: {ok[-1]['solver_ran']})" if name == "default" else name
        if slope is not None:
            label += f", fitted slope {slope:.2f} (N >= 10)"
        colour, marker = styles.get(name, ("grey", "^"))
        ax.loglog([r["n"] for r in ok], [r["us_per_step"] for r in ok], marker=marker,
                  color=colour, label=label)
        if name == "banded" or anchor is None:
            anchor = ok[-1]
    if anchor is not None:
        n = np.array([1.0, 1000.0])
        ax.loglog(n, anchor["us_per_step"] * n / anchor["n"], "k:", label="slope 1 (linear)")
    ax.axhline(TARGET_MS * 1e3, color="grey", linestyle="--", linewidth=0.8)
    ax.annotate(f"target: N = {TARGET_N} at <= {TARGET_MS:g} ms/step", (1.0, TARGET_MS * 1e3),
                fontsize=7, textcoords="offset points", xytext=(2, 3))
    ax.set_xlabel("N (four-bar loops); 3 (2N + 1) coordinates")
    ax.set_ylabel("time per kinematic step (us), q + qd + qdd")
    ax.set_title("Kinematics of the driven N-four-bar: time per step", fontsize=10)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.1)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def main(argv: Sequence[str] | None = None) -> dict:
    """Run the sweep, write DIR/scaling.json and DIR/scaling.png."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(BENCH / "results"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="fewer N, shorter timing")
    a = ap.parse_args(argv)
    out = Path(a.out)
    data = scaling(quick=a.quick)
    out.mkdir(parents=True, exist_ok=True)
    (out / "scaling.json").write_text(json.dumps(data, indent=1), encoding="utf-8")
    chart(data, out / "scaling.png")
    print(f"banded slope {data['banded_slope']}, dense slope {data['dense_slope']}; "
          f"target {data['target']}")
    print(f"wrote {out / 'scaling.json'} and scaling.png")
    return data


if __name__ == "__main__":
    main()
