"""Run every benchmark of mbd2d and write the results (`make bench` runs this).

Sections (each in its own try/except: a failure is recorded and the rest runs):

1. environment: machine, OS and versions (bench/environment.py);
2. work precision of the dynamics methods (bench/work_precision.py): free four-bar 10 s,
   Andrews' squeezer to 0.03 s, IFToMM N-four-bar;
3. peers: Exudyn generalized-alpha on the free four-bar and Exudyn kinematic stepping
   (bench/peers_exudyn.py), with the ratios at equal accuracy;
4. kinematics speed: Fortran loop, Python stepper, plain NumPy (bench/kinematics_speed.py),
   and the four-bar's instructions per step by part under callgrind (bench/callgrind.py);
5. scaling of kinematics with N (bench/scaling.py);
6. memory of 10^6 output steps (bench/memory.py);
7. design sweeps: per-variant cost batched vs a with_params loop, Dask LocalCluster
   throughput with 1 and 2 workers (bench/sweep.py);
8. cost of design sensitivities, 4 parameters against the analysis alone
   (bench/sensitivities.py);
9. contacts (bench/contact.py): the clearance-joint crank-slider against the ideal joint and
   over the restitution, and the cost of far contact pairs;
10. linkage synthesis: the three standard four-bar path-generation cases of the literature,
   mbd2d against the published errors and pylinkage (bench/synthesis.py);
11. dynamics against N: the free N-four-bar with generalized-alpha and dopri5, band and
   dense paths (bench/dynamics_scaling.py);
12. pictures of large models: the N-four-bar's snapshot picture and GIF, batched against one
   artist per part (bench/pictures.py);
13. vibration modes: a double pendulum and a spring chain against their closed forms, side
   by side with Exudyn's ComputeODE2Eigenvalues (bench/peers_modes.py);
14. frequency response: damped spring chains against numpy's solve of their hand-written
   systems, and a sweep of the half car's road response against a loop (bench/frf.py).

Writes bench/results/*.json and *.png, bench/RESULTS.md and bench/README_headline.md
(bench/report.py). With --only, the other sections come from their results files of an
earlier run (the report says which). The whole run is sized to finish in well under 10 minutes on a 2-core
machine; --quick is a smoke test of the same code.

    python bench/run.py [--quick] [--out DIR] [--only SECTION ...]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import traceback
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import contact  # noqa: E402
import dynamics_scaling  # noqa: E402
import environment  # noqa: E402
import frf  # noqa: E402
import callgrind  # noqa: E402
import kinematics_speed  # noqa: E402
import memory  # noqa: E402
import peers_exudyn  # noqa: E402
import peers_exudyn_chain  # noqa: E402
import peers_modes  # noqa: E402
import pictures  # noqa: E402
import report  # noqa: E402
import scaling  # noqa: E402
import sensitivities  # noqa: E402
import sweep as sweeps  # noqa: E402
import synthesis  # noqa: E402
import work_precision  # noqa: E402

SECTIONS = ("environment", "work_precision", "peers", "kinematics", "scaling", "memory",
            "sweep", "sensitivities", "contact", "synthesis", "dynamics_scaling", "peers_chain",
            "pictures", "modes", "frf")


# ===================================================================== JSON
def clean(obj: Any) -> Any:
    """A JSON-safe copy: numpy scalars to Python, non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, Path):
        return str(obj)
    return obj


def write_json(path: Path, data: dict, env: dict | None) -> None:
    """Write one results file, with the environment record alongside the figures."""
    record = dict(data)
    if env is not None:
        record.setdefault("environment", env)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(clean(record), indent=1) + "\n", encoding="utf-8")


# ===================================================================== sections
def section_work_precision(quick: bool) -> dict:
    """The three work-precision studies (charts are drawn later, with the peers' points)."""
    out: dict[str, Any] = {"quick": quick}
    for name in ("fourbar", "andrews", "nfourbar"):
        print(f" {name} ...", flush=True)
        t0 = time.perf_counter()
        try:
            out[name] = work_precision.study(name, repeats=3, quick=quick)
        except Exception as e:  # noqa: BLE001 - recorded, the others run
            out[name] = failure(e)
        out[name]["runtime_s"] = time.perf_counter() - t0
    return out


def section_peers(quick: bool) -> dict:
    """Exudyn on the free four-bar (generalized-alpha over h) and kinematic stepping."""
    ok, info = peers_exudyn.available()
    print(f" Exudyn: {info}" if ok else f" Exudyn NOT available: {info}", flush=True)
    h_values = [h for h in peers_exudyn.H_VALUES if h >= 1e-3] if quick \
        else list(peers_exudyn.H_VALUES)
    ref_t, ref_theta = peers_exudyn.reference()
    exu_rows: list[dict] = []
    our_rows: list[dict] = []
    for h in h_values:          # interleaved, so that a change of machine load hits both
        if ok:
            exu_rows += peers_exudyn.free_fourbar_genalpha([h], ref_t, ref_theta, 3)
        our_rows += peers_exudyn.mbd2d_genalpha([h], ref_t, ref_theta, 3)
    table = peers_exudyn.side_by_side(exu_rows, our_rows)
    peers_exudyn.print_dynamics(table)
    kin_steps = 1000 if quick else peers_exudyn.KIN_STEPS
    if ok:
        kin = peers_exudyn.kinematic_stepping(kin_steps, 1.0, 3)
    else:
        kin = {"steps": kin_steps, "t_end": 1.0,
               "mbd2d": peers_exudyn.mbd2d_kinematics(kin_steps, 1.0, 3)}
    peers_exudyn.print_kinematics(kin)
    return {"exudyn_available": ok, "exudyn": info if ok else None,
            "exudyn_unavailable_reason": None if ok else info,
            "dynamics": {"model": "bench/models.free_fourbar", "t_end": peers_exudyn.T_END,
                         "rho_inf": peers_exudyn.RHO_INF,
                         "reference": "mbd2d dopri5 rtol 1e-12 atol 1e-14",
                         "exudyn": exu_rows, "mbd2d_genalpha": our_rows,
                         "side_by_side": table},
            "kinematics": kin}


def section_kinematics(quick: bool) -> dict:
    """The three ways of running kinematics, at h = 1 ms, with the ratios, and the four-bar's
    instructions per step (callgrind) at h = 1 ms and 0.1 ms, full and positions only."""
    rows = kinematics_speed.compare(kinematics_speed.H, repeats=5, quick=quick)
    try:
        cg = callgrind.callgrind(callgrind.H_VALUES[:1] if quick else callgrind.H_VALUES)
    except Exception as e:  # noqa: BLE001 - the timings stand without the counts
        cg = {"available": False, "reason": f"{type(e).__name__}: {e}"}
    return {"h": kinematics_speed.H, "quick": quick, "rows": rows, "callgrind": cg}


def section_scaling(quick: bool) -> dict:
    """Time per kinematic step of the driven N-four-bar against N."""
    return scaling.scaling(quick=quick)


def section_memory(quick: bool) -> dict:
    """Peak memory of 10^6 output steps (10^5 with --quick)."""
    return memory.memory(steps=100_000 if quick else memory.STEPS)


def section_sweep(quick: bool) -> dict:
    """Per-variant cost of sweeps and the Dask LocalCluster throughput."""
    return sweeps.measure(quick=quick)


def section_sensitivities(quick: bool) -> dict:
    """Each analysis with 4 parameters' sensitivities against the analysis alone."""
    return sensitivities.measure(500 if quick else 20_000, 2 if quick else 5, quick)


def section_contact(quick: bool) -> dict:
    """Cost of the clearance joint (ratio to the ideal joint, over e) and of far pairs."""
    return contact.study(repeats=1 if quick else 3, quick=quick)


def section_dynamics_scaling(quick: bool) -> dict:
    """Dynamics of the free N-four-bar against N (band and dense paths)."""
    return dynamics_scaling.study(quick=quick)


def section_peers_chain(quick: bool) -> dict:
    """Exudyn and mbd2d, generalized-alpha on the free N-four-bar (N = 10, 100, 1000)."""
    ok, info = peers_exudyn.available()
    print(f" Exudyn: {info}" if ok else f" Exudyn NOT available: {info}", flush=True)
    return peers_exudyn_chain.study((10, 100) if quick else peers_exudyn_chain.N_VALUES,
                                    (1e-3,) if quick else (1e-3, 5e-4), 1 if quick else 2)


def section_synthesis(quick: bool) -> dict:
    """Four-bar path generation: published errors, mbd2d, pylinkage."""
    return synthesis.study(quick=quick)


def section_pictures(quick: bool) -> dict:
    """Pictures of the N-four-bar: batched artists against one per part."""
    return pictures.study(quick=quick)


def section_modes(quick: bool) -> dict:
    """Vibration modes against closed forms, side by side with Exudyn."""
    return peers_modes.study(quick=quick)


def section_frf(quick: bool) -> dict:
    """The frequency response against numpy, and a sweep of it against a loop."""
    return frf.study(quick=quick)


def failure(e: BaseException) -> dict:
    """The record of a failed section."""
    return {"failed": True, "error": f"{type(e).__name__}: {e}",
            "traceback": traceback.format_exc(limit=8)}


def run_section(name: str, fn: Callable[[bool], dict], quick: bool) -> dict:
    """Run one section, timed; a failure becomes {"failed": True, "error", "traceback"}."""
    print(f"\n=== {name}", flush=True)
    t0 = time.perf_counter()
    try:
        data = fn(quick)
    except Exception as e:  # noqa: BLE001 - one failed section must not stop the others
        data = failure(e)
        print(f" FAILED: {data['error']}", flush=True)
    data["runtime_s"] = time.perf_counter() - t0
    print(f" ({name}: {data['runtime_s']:.1f} s)", flush=True)
    return data


# ===================================================================== charts
def earlier_sections(out: Path, names: Sequence[str]) -> dict[str, dict]:
    """The results of sections not run now (``--only``), from their files of an earlier run,
    so that the report stays whole."""
    found: dict[str, dict] = {}
    for name in names:
        path = out / f"{name}.json"
        if not path.is_file():
            continue
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if name == "environment":
            data = data.get("environment") or {}
        found[name] = data
    return found


def draw_charts(results: dict, out: Path) -> dict[str, str]:
    """Every PNG; returns {chart name: file name} of the charts that were drawn."""
    charts: dict[str, str] = {}
    wp = results.get("work_precision", {})
    peers = results.get("peers", {})
    exu_rows = peers.get("dynamics", {}).get("exudyn") or []
    for name in ("fourbar", "andrews", "nfourbar"):
        data = wp.get(name)
        if not data or data.get("failed"):
            continue
        extra = None
        if name == "fourbar" and exu_rows:
            extra = [{"label": f"Exudyn {peers.get('exudyn')} generalized-alpha "
                               f"(fixed h, rho_inf {peers_exudyn.RHO_INF})",
                      "rows": exu_rows}]
        charts[f"wp_{name}"] = try_chart(lambda d=data, e=extra, n=name: work_precision.chart(
            d, out / f"wp_{n}.png", extra_points=e))
    if "rows" in results.get("scaling", {}):
        charts["scaling"] = try_chart(lambda: scaling.chart(results["scaling"],
                                                            out / "scaling.png"))
    if "rows" in results.get("memory", {}):
        charts["memory"] = try_chart(lambda: memory.chart(results["memory"],
                                                          out / "memory.png"))
    if "rows" in (results.get("dynamics_scaling") or {}):
        charts["dynamics_scaling"] = try_chart(lambda: dynamics_scaling.chart(
            results["dynamics_scaling"], out / "dynamics_scaling.png"))
    if "clearance" in results.get("contact", {}):
        charts["contact"] = try_chart(lambda: contact.chart(results["contact"],
                                                            out / "contact.png"))
    return {k: v for k, v in charts.items() if v}


def try_chart(draw: Callable[[], Path]) -> str | None:
    """Draw one chart; its file name, or None (with the error printed) when it failed."""
    try:
        return draw().name
    except Exception as e:  # noqa: BLE001 - a chart failure must not lose the figures
        print(f" chart FAILED: {type(e).__name__}: {e}", flush=True)
        return None


def derive(results: dict) -> None:
    """Figures computed from two sections: mbd2d vs Exudyn at equal accuracy."""
    exu = results.get("peers", {}).get("dynamics", {}).get("exudyn") or []
    wp_rows = results.get("work_precision", {}).get("fourbar", {}).get("rows") or []
    if exu and wp_rows:
        results["peers"]["dynamics"]["equal_accuracy"] = peers_exudyn.equal_accuracy(exu,
                                                                                     wp_rows)


# ===================================================================== main
def main(argv: Sequence[str] | None = None) -> dict:
    """Run the sections, write the JSON files, the charts, RESULTS.md and the headline."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smoke test: reduced sweeps")
    ap.add_argument("--out", default=str(BENCH / "results"), help="results directory")
    ap.add_argument("--markdown", default=str(BENCH / "RESULTS.md"), help="report file")
    ap.add_argument("--headline", default=str(BENCH / "README_headline.md"),
                    help="README section with the key figures")
    ap.add_argument("--only", nargs="*", choices=SECTIONS, help="run only these sections")
    a = ap.parse_args(argv)
    out = Path(a.out)
    wanted = a.only or SECTIONS
    t_start = time.perf_counter()
    fns: dict[str, Callable[[bool], dict]] = {
        "environment": environment.collect, "work_precision": section_work_precision,
        "peers": section_peers, "kinematics": section_kinematics,
        "scaling": section_scaling, "memory": section_memory, "sweep": section_sweep,
        "sensitivities": section_sensitivities, "contact": section_contact,
        "synthesis": section_synthesis, "dynamics_scaling": section_dynamics_scaling,
        "peers_chain": section_peers_chain, "pictures": section_pictures,
        "modes": section_modes, "frf": section_frf}
    ran = {name: run_section(name, fns[name], a.quick) for name in SECTIONS if name in wanted}
    earlier = earlier_sections(out, [n for n in SECTIONS if n not in wanted])
    results = {name: ran.get(name, earlier.get(name)) for name in SECTIONS
               if name in ran or name in earlier}
    derive(results)
    env = results.get("environment")
    if env is not None:
        env["load_average_end"] = os.getloadavg()
    total = time.perf_counter() - t_start
    results["meta"] = {"quick": a.quick, "sections": list(wanted), "total_runtime_s": total,
                       "earlier": sorted(earlier),
                       "command": "python bench/run.py" + (" --quick" if a.quick else "")
                       + (" --only " + " ".join(wanted) if a.only else "")}
    print("\n=== charts and report", flush=True)
    charts = draw_charts(results, out)
    for name, data in results.items():
        if name not in ("environment", "meta") and name in wanted:
            write_json(out / f"{name}.json", data, env)
    write_json(out / "environment.json", {"environment": env or {}, "meta": results["meta"]},
               None)
    md = Path(a.markdown)
    md.write_text(report.results_markdown(results, charts, md, out), encoding="utf-8")
    headline = Path(a.headline)
    headline.write_text(report.headline_markdown(results, charts, out), encoding="utf-8")
    for t in report.targets(results):
        print(f" target: {t['target']:60s} {t['figure']:40s} {t['met']}")
    print(f"\nwrote {out}/*.json, {len(charts)} charts, {md} and {headline}; "
          f"total {total:.0f} s", flush=True)
    return results


if __name__ == "__main__":
    main()
