"""Cost of design sweeps: per-variant cost of a batched sweep against a Python loop, and the
throughput of a Dask LocalCluster with 1 and 2 worker processes.

Per-variant cost: the crank-rocker (examples/fourbar_grashof.toml) with its coupler length
varied over N values, each variant a 10-step kinematic run over one crank turn (h = 0.1 s, the
target's setting) and, beside it, over 0.1 s (h = 10 ms), measured side by side in the same
run (interleaved, best of R):

  loop      ``for v in values: model.with_params({name: v}).kinematics(1.0, 10)``
  batched   ``mbd2d.sweep(model, {name: values}, t_end=1.0, steps=10, workers=1)``: one
            process, the Dataset included (a process pool would only divide it further)
  core      one ``core_kinematics`` call per variant on the packed tables of the base model
            (the analysis itself plus one f2py call: about the floor of any batching)

Target (issue 10): the batched per-variant cost at least 10x below the loop's.

Dask: a LocalCluster (processes, 1 thread each) with 1 and with 2 workers runs a sweep of
1000 variants of a 1000-step run (every 50th row kept: the time goes to computing, not to
moving the outputs); variants per second, cluster start excluded, the first sweep on a fresh
cluster discarded (the workers import mbd2d). For reference the same sweep in this process
(workers=1) and in the local process pool (every core).

Without Python: the same sweeps exported once (``mbd2d.export_sweep``) and run from the file
to a CSV by the standalone ``mbd2d-solve`` (process start, reading the file, the batch call,
writing the CSV), against ``mbd2d.sweep(..., workers=1)`` + ``mbd2d.write_sweep`` in this
process, interleaved best of R; the two CSV files are compared byte for byte.

    python bench/sweep.py [--quick] [--out FILE]
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np

import mbd2d

BENCH = Path(__file__).resolve().parent
EX = BENCH.parent / "examples"
TARGET = 10.0
NAME = "joint.B.points.0.0"          # x of B on the coupler: the coupler length - 1.75


def best(fn: Callable[[], Any], repeats: int) -> float:
    t = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


def per_variant(n: int, repeats: int, steps: int = 10, t_end: float = 1.0) -> dict[str, Any]:
    """Loop, batched and core-alone cost per variant (us), interleaved best-of-repeats."""
    from mbd2d.binding import core
    from mbd2d.binding.pack import pack

    m = mbd2d.load(EX / "fourbar_grashof.toml")
    values = np.linspace(1.6, 1.9, n)           # every variant turns fully

    def loop() -> None:
        for v in values:
            m.with_params({NAME: float(v)}).kinematics(t_end, steps)

    def batched() -> None:
        ds = mbd2d.sweep(m, {NAME: values}, t_end=t_end, steps=steps, workers=1, progress=False)
        assert int(ds.attrs["failed"]) == 0

    p = pack(m)

    def core_alone() -> None:
        for _ in values:
            core.kinematics(p, 0.0, t_end, steps, 0.0, 0, 0.0, 1, 0, steps + 1)

    batched()                                   # imports (xarray) and caches out of the way
    t = {"loop": float("inf"), "batched": float("inf"), "core": float("inf")}
    for _ in range(repeats):                    # interleaved: the same machine load for all
        t["loop"] = min(t["loop"], best(loop, 1))
        t["batched"] = min(t["batched"], best(batched, 1))
        t["core"] = min(t["core"], best(core_alone, 1))
    us = {k: 1e6 * v / n for k, v in t.items()}
    ratio = us["loop"] / us["batched"]
    return {"model": "examples/fourbar_grashof.toml", "parameter": NAME, "variants": n,
            "steps": steps, "t_end": t_end, "repeats": repeats, "us_per_variant": us,
            "ratio_loop_over_batched": ratio,
            "batched_over_core": us["batched"] / us["core"],
            "target": TARGET, "meets_target": ratio >= TARGET}


def throughput(m_cases: int, steps: int, every: int, repeats: int) -> dict[str, Any]:
    """Variants per second: this process, the local pool, Dask LocalCluster 1 and 2."""
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    cases = {NAME: np.linspace(1.6, 1.9, m_cases)}
    kw = {"t_end": 1.0, "steps": steps, "every": every, "progress": False}
    ref = mbd2d.sweep(m, cases, workers=1, **kw)
    rows: list[dict[str, Any]] = []

    def record(label: str, run: Callable[[], Any]) -> None:
        out = run()                              # warm-up (imports, worker start)
        same = bool(out.identical(ref))
        t = best(run, repeats)
        rows.append({"runner": label, "seconds": t, "variants_per_s": m_cases / t,
                     "identical_to_serial": same})
        print(f" {label:34s} {m_cases / t:10.0f} variants/s  identical: {same}", flush=True)

    record("this process (workers=1)", lambda: mbd2d.sweep(m, cases, workers=1, **kw))
    record("local process pool (every core)", lambda: mbd2d.sweep(m, cases, **kw))
    try:
        import distributed
    except ImportError as exc:
        return {"cases": m_cases, "steps": steps, "every": every, "rows": rows,
                "dask_unavailable": f"{type(exc).__name__}: {exc}"}
    for nw in (1, 2):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with distributed.LocalCluster(n_workers=nw, threads_per_worker=1, processes=True,
                                          dashboard_address=":0") as cluster, \
                    distributed.Client(cluster) as client:
                record(f"Dask LocalCluster, {nw} worker(s)",
                       lambda c=client: mbd2d.sweep(m, cases, client=c, **kw))
    return {"cases": m_cases, "steps": steps, "every": every, "repeats": repeats,
            "rows": rows}


def standalone(m_cases: int, steps: int, every: int, repeats: int) -> dict[str, Any]:
    """Seconds from one exported file to a CSV: mbd2d-solve against the Python sweep and
    write_sweep, interleaved best-of-repeats, and whether the files are the same bytes."""
    here = Path(sys.executable).parent / "mbd2d-solve"
    solver = str(here) if here.exists() else shutil.which("mbd2d-solve")
    if not solver:
        return {"unavailable": "mbd2d-solve not found next to this Python or on PATH"}
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    cases = {NAME: np.linspace(1.6, 1.9, m_cases)}
    kw = {"t_end": 1.0, "steps": steps, "every": every}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        mbd2d.export_sweep(m, d / "s.mbd", cases, **kw)

        def solve() -> None:
            subprocess.run([solver, str(d / "s.mbd"), str(d / "solve.csv")], check=True,
                           timeout=600)

        def python() -> None:
            mbd2d.write_sweep(mbd2d.sweep(m, cases, workers=1, progress=False, **kw),
                              d / "python.csv")

        ts, tp = float("inf"), float("inf")
        for _ in range(repeats):
            ts, tp = min(ts, best(solve, 1)), min(tp, best(python, 1))
        same = (d / "solve.csv").read_bytes() == (d / "python.csv").read_bytes()
        size = (d / "solve.csv").stat().st_size
    print(f" file to CSV, {m_cases} variants x {steps} steps (every {every}): mbd2d-solve "
          f"{ts:.3f} s, Python sweep + write_sweep {tp:.3f} s ({tp / ts:.1f}x); same bytes: "
          f"{same}", flush=True)
    return {"cases": m_cases, "steps": steps, "every": every, "repeats": repeats,
            "solve_s": ts, "python_s": tp, "ratio": tp / ts, "same_csv": same,
            "csv_bytes": size}


def measure(quick: bool = False) -> dict[str, Any]:
    """The whole section: per-variant cost and throughput."""
    pv = per_variant(n=100 if quick else 400, repeats=2 if quick else 5)
    short = per_variant(n=100 if quick else 400, repeats=2 if quick else 5, t_end=0.1)
    for label, r in (("one turn, h = 0.1 s", pv), ("0.1 s, h = 10 ms", short)):
        us = r["us_per_variant"]
        print(f" per variant (10 steps, {label}): loop {us['loop']:.0f} us, batched "
              f"{us['batched']:.1f} us, core alone {us['core']:.1f} us; loop / batched = "
              f"{r['ratio_loop_over_batched']:.1f}x (target {TARGET:.0f}x)", flush=True)
    # before the Dask clusters: their worker processes may linger a moment after closing
    alone = [standalone(100 if quick else 400, 10, 1, 2 if quick else 5),
             standalone(200 if quick else 1000, 1000, 50, 1 if quick else 3)]
    tp = throughput(m_cases=200 if quick else 1000, steps=1000, every=50,
                    repeats=1 if quick else 3)
    return {"per_variant": pv, "per_variant_short_steps": short, "throughput": tp,
            "standalone": alone, "quick": quick}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small smoke run")
    ap.add_argument("--out", type=Path, default=BENCH / "results" / "sweep.json")
    a = ap.parse_args(argv)
    data = measure(a.quick)
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
