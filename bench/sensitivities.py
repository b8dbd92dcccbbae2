"""Cost of design sensitivities: each analysis with 4 parameters against the same analysis
without, measured in the same run (best-of-R wall time of the public API call, runs
interleaved so both see the same machine load).

Cases:
  kinematics  four-bar (examples/fourbar_grashof.toml) and offset slider-crank, h = 1 ms,
              every output kept: 4 pin coordinates / the crank speed;
  inverse     the slider-crank with masses: 2 pin coordinates, a mass and an inertia;
  dopri5      a free slider-crank under gravity with a spring (rtol = atol = 1e-8): the
              spring stiffness, two masses and gravity. With sensitivities the error control
              also covers them, so the step count may differ: it is reported.
  generalized-alpha  the same free slider-crank and parameters at the fixed step h = 1 ms
              (its discrete equations differentiated; default rtol, atol), 10 s.

Target (issue 10): sensitivities for 4 parameters cost at most 2x the analysis alone.
Beside them (no target): the mechanism measures' design derivatives of the four-bar's run
with 4 parameters, per output row, against each measure alone (the same run's rows).
Beside the wall time, each case's core call (the api_* routine, setup and output included)
runs once more under callgrind with and without sensitivities (shorter runs: 3000 steps, the
dopri5 case as it is): the instruction ratio, stable on a shared machine (skipped without
valgrind or with --quick).

    python bench/sensitivities.py [--steps N] [--repeats R] [--quick]
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import mbd2d

BENCH = Path(__file__).resolve().parent
EX = BENCH.parent / "examples"
TARGET = 2.0
#: per case: the model, the call (``{S}`` takes the sensitivities) and the core routine
#: whose instructions are counted
CALLGRIND_CASES = {
    "kinematics four-bar, 4 parameters": (
        "m = mbd2d.load(EX / 'fourbar_grashof.toml')",
        "m.kinematics(3.0, 3000{S})", "__mbd_api_MOD_api_kinematics"),
    "kinematics slider-crank, 4 parameters": (
        "m = mbd2d.load(EX / 'slider_crank.toml')",
        "m.kinematics(3.0, 3000{S})", "__mbd_api_MOD_api_kinematics"),
    "inverse dynamics slider-crank, 4 parameters": (
        "m = S.masses(mbd2d.load(EX / 'slider_crank.toml'))",
        "m.inverse_dynamics(3.0, 3000{S})", "__mbd_api_MOD_api_inverse"),
    "dopri5 free slider-crank, 4 parameters": (
        "m = S.free_slider_crank()",
        "m.dynamics(10.0, 200, rtol=1e-8, atol=1e-8{S})", "__mbd_api_MOD_api_dynamics"),
    "generalized-alpha free slider-crank, 4 parameters": (
        "m = S.free_slider_crank()",
        "m.dynamics(3.0, 200, method='generalized-alpha', h=1e-3{S})",
        "__mbd_api_MOD_api_dynamics"),
}


def masses(m: mbd2d.Model) -> mbd2d.Model:
    for b, (ms, j) in zip(m.bodies, [(2.0, 0.3), (1.5, 1.1), (0.8, 0.05)]):
        b.mass, b.inertia = ms, j
    return m


def free_slider_crank() -> mbd2d.Model:
    m = masses(mbd2d.load(EX / "slider_crank.toml"))
    m.drivers.clear()
    m.add_spring(["ground", "slider"], [[0.0, 0.5], [0.0, 0.0]], stiffness=40.0, damping=3.0,
                 length0=2.0, name="s1")
    return m


def instructions(case: str, names: list[str]) -> list[int] | None:
    """Callgrind instructions of a case's core call without and with sensitivities of
    names (None without valgrind)."""
    sys.path.insert(0, str(BENCH))
    import callgrind as cg                         # bench/callgrind.py: the dump reader
    exe = shutil.which("valgrind")
    if exe is None:
        return None
    build, call, fn = CALLGRIND_CASES[case]
    counts = []
    for sens in ("", f", sensitivities={names!r}"):
        code = (f"import sys; sys.path.insert(0, {str(BENCH)!r})\nimport mbd2d\n"
                f"import sensitivities as S\nEX = S.EX\n{build}\n{call.format(S=sens)}\n")
        # dynamics with sensitivities runs its own routine (api_dynamics_sens)
        f = fn + ("_sens" if sens and fn.endswith("api_dynamics") else "")
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "cg.out"
            subprocess.run([exe, "--tool=callgrind", f"--callgrind-out-file={out}",
                            f"--toggle-collect={f}", sys.executable, "-c", code],
                           capture_output=True, text=True, timeout=900, check=True)
            counts.append(cg._totals(out))
    return counts


def timed(fn: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    best, out = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def compare(label: str, base: Callable[[], Any], sens: Callable[[], Any], repeats: int,
            steps: int) -> dict[str, Any]:
    """Interleaved best-of-repeats of both calls; the ratio and us per output step."""
    tb, ts = float("inf"), float("inf")
    out_b = out_s = None
    for _ in range(repeats):
        t, out_b = timed(base, 1)
        tb = min(tb, t)
        t, out_s = timed(sens, 1)
        ts = min(ts, t)
    row = {"case": label, "base_s": tb, "sens_s": ts, "ratio": ts / tb,
           "base_us_per_step": 1e6 * tb / steps, "sens_us_per_step": 1e6 * ts / steps,
           "meets_target": ts / tb <= TARGET}
    stats_b, stats_s = getattr(out_b, "stats", {}), getattr(out_s, "stats", {})
    if "steps" in stats_b:
        row["integrator_steps"] = [stats_b["steps"], stats_s["steps"]]
    return row


def measure(steps: int, reps: int, quick: bool = False) -> dict[str, Any]:
    """Every case, interleaved best-of-reps; the rows and the settings."""
    t_end = steps * 1e-3                          # h = 1 ms
    rows = []

    fourbar = mbd2d.load(EX / "fourbar_grashof.toml")
    p4 = ["joint.A.points.0.0", "joint.B.points.0.0", "joint.B.points.1.1",
          "joint.O4.points.1.0"]
    rows.append(compare("kinematics four-bar, 4 parameters",
                        lambda: fourbar.kinematics(t_end, steps),
                        lambda: fourbar.kinematics(t_end, steps, sensitivities=p4), reps, steps))
    slider = mbd2d.load(EX / "slider_crank.toml")
    ps = ["joint.A.points.0.0", "joint.B.points.0.0", "joint.guide.points.0.1",
          "driver.motor.f.poly.1"]
    rows.append(compare("kinematics slider-crank, 4 parameters",
                        lambda: slider.kinematics(t_end, steps),
                        lambda: slider.kinematics(t_end, steps, sensitivities=ps), reps, steps))
    heavy = masses(mbd2d.load(EX / "slider_crank.toml"))
    pi = ["joint.A.points.0.0", "joint.B.points.0.0", "body.rod.mass", "body.rod.inertia"]
    rows.append(compare("inverse dynamics slider-crank, 4 parameters",
                        lambda: heavy.inverse_dynamics(t_end, steps),
                        lambda: heavy.inverse_dynamics(t_end, steps, sensitivities=pi), reps,
                        steps))
    free = free_slider_crank()
    pd = ["force.s1.stiffness", "body.rod.mass", "body.crank.inertia", "model.gravity.1"]
    t_dyn = 2.0 if quick else 10.0
    rows.append(compare("dopri5 free slider-crank, 4 parameters",
                        lambda: free.dynamics(t_dyn, 200, rtol=1e-8, atol=1e-8),
                        lambda: free.dynamics(t_dyn, 200, rtol=1e-8, atol=1e-8,
                                              sensitivities=pd), reps, 200))
    ga_kw = {"method": "generalized-alpha", "h": 1e-3}
    rows.append(compare("generalized-alpha free slider-crank, 4 parameters",
                        lambda: free.dynamics(t_dyn, 200, **ga_kw),
                        lambda: free.dynamics(t_dyn, 200, sensitivities=pd, **ga_kw), reps,
                        200))
    names = {rows[0]["case"]: p4, rows[1]["case"]: ps, rows[2]["case"]: pi, rows[3]["case"]: pd,
             rows[4]["case"]: pd}
    for r in rows if not quick else []:
        counts = instructions(r["case"], names[r["case"]])
        if counts and counts[0] > 0:
            r["instructions"] = counts
            r["instruction_ratio"] = counts[1] / counts[0]
    meas = measure_costs(fourbar, p4, 2000 if not quick else 200, reps)
    for r in rows:
        extra = f"  steps {r['integrator_steps']}" if "integrator_steps" in r else ""
        if "instruction_ratio" in r:
            extra += f"  callgrind {r['instruction_ratio']:.2f}"
        print(f"{r['case']:46s} {r['base_us_per_step']:9.2f} us  {r['sens_us_per_step']:9.2f} us"
              f"  ratio {r['ratio']:5.2f}{'' if r['meets_target'] else '  (above 2x)'}{extra}")
    return {"target_ratio": TARGET, "steps": steps, "repeats": reps, "quick": quick,
            "rows": rows, "measures": meas}


#: the measures whose derivatives are timed (the four-bar's)
MEASURES = ["transmission_angle:B", "velocity_ratio:motor:rocker.theta",
            "mechanical_advantage:motor:rocker.theta", "dead_centre_distance"]


def measure_costs(model: mbd2d.Model, names: list[str], rows: int, reps: int
                  ) -> dict[str, Any]:
    """us per output row of each measure alone and with its derivatives along names (one
    core call each, interleaved best of reps), beside the run with sensitivities itself."""
    from mbd2d.results.measures import measure, measure_derivatives
    t_run, res = timed(lambda: model.kinematics(1.0, rows - 1, sensitivities=names), reps)
    out = []
    for spec in MEASURES:
        tv = td = float("inf")
        for _ in range(reps):
            tv = min(tv, timed(lambda: measure(res, spec), 1)[0])
            td = min(td, timed(lambda: measure_derivatives(res, [spec]), 1)[0])
        out.append({"measure": spec, "value_us_per_row": 1e6 * tv / rows,
                    "with_derivatives_us_per_row": 1e6 * td / rows, "ratio": td / tv})
        print(f"{spec:46s} {out[-1]['value_us_per_row']:9.2f} us  "
              f"{out[-1]['with_derivatives_us_per_row']:9.2f} us per row with "
              f"{len(names)} derivatives")
    return {"rows": rows, "parameters": len(names), "run_us_per_row": 1e6 * t_run / rows,
            "measures": out}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="small smoke run")
    ap.add_argument("--out", type=Path, default=BENCH / "results" / "sensitivities.json")
    a = ap.parse_args(argv)
    steps, reps = (500, 2) if a.quick else (a.steps, a.repeats)
    data = measure(steps, reps, a.quick)
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
