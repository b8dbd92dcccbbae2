"""Markdown from the benchmark results: bench/RESULTS.md, the README headline and the targets.

Every function takes the ``results`` dict that bench/run.py assembles (one entry per section,
a failed section being {"failed": True, "error", ...}) and returns text; nothing here runs a
benchmark.
"""
from __future__ import annotations

import math
import os
import statistics
from pathlib import Path
from typing import Any, Iterable, Sequence

ROOT = Path(__file__).resolve().parents[1]
FOURBAR = "four-bar (Grashof)"
SLIDER = "slider-crank"

Row = dict[str, Any]


# ===================================================================== formatting
def fmt(v: Any, spec: str = ".3g", none: str = "–") -> str:
    """A number formatted with spec, or `none` for None / non-finite."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return none
    return format(v, spec)


def table(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def image(charts: dict[str, str], name: str, out: Path, base: Path, alt: str) -> str:
    """An image link from the directory `base` to the chart `name` in `out` ('' if none)."""
    if name not in charts:
        return f"*(chart {name} not drawn)*\n"
    rel = os.path.relpath(out / charts[name], base).replace(os.sep, "/")
    return f"![{alt}]({rel})\n"


def get(d: Any, *keys: Any, default: Any = None) -> Any:
    """d[k1][k2]... or default when a level is missing."""
    for k in keys:
        if isinstance(d, dict) and k in d:
            d = d[k]
        elif isinstance(d, (list, tuple)) and isinstance(k, int) and -len(d) <= k < len(d):
            d = d[k]
        else:
            return default
    return d


def failed(section: Any) -> str | None:
    """The error message of a failed (or missing) section, else None."""
    if not isinstance(section, dict):
        return "not run"
    return section.get("error") if section.get("failed") else None


def absent(section: Any) -> str | None:
    """The text of a section not run ("Not run.") or failed ("Failed: ..."), else None."""
    if section is None:
        return "Not run.\n"
    return f"Failed: {failed(section)}\n" if failed(section) else None


# ===================================================================== targets
def _target(name: str, figure: str, met: bool | None, detail: str = "") -> Row:
    return {"target": name, "figure": figure, "met": met, "detail": detail}


def kinematics_targets(results: dict) -> list[Row]:
    """<= 1 us/step four-bar (Fortran loop) and >= 100x faster than NumPy."""
    rows = get(results, "kinematics", "rows") or {}
    fb = rows.get(FOURBAR, {})
    us = get(fb, "fortran_loop", "us_per_step")
    fine = get(fb, "fortran_loop_h1e-4", "us_per_step")
    fig = (f"{fmt(us, '.2f')} us/step at h = 1 ms ({fmt(fine, '.2f')} at h = 0.1 ms)"
           if us is not None else "not measured")
    ins = {r.get("h"): r.get("instructions_per_step")
           for r in get(results, "kinematics", "callgrind", "rows", default=[]) or []
           if not r.get("positions_only")}
    if ins:
        fig += "; " + ", ".join(f"{v / 1000:.1f}k instructions at h = {h * 1000:g} ms"
                                for h, v in ins.items() if v is not None)
    out = [_target("kinematics, four-bar, Fortran loop: <= 1 us/step (h = 1 ms and 0.1 ms)",
                   fig, None if us is None else us <= 1.0 and (fine is None or fine <= 1.0),
                   "position + velocity + acceleration per step")]
    ratios = {k: v.get("ratio_numpy_over_loop") for k, v in rows.items()}
    if ratios and all(r is not None for r in ratios.values()):
        fig = ", ".join(f"{k} {v:.0f}x" for k, v in ratios.items())
        out.append(_target("kinematics: Fortran loop >= 100x faster than plain NumPy", fig,
                           min(ratios.values()) >= 100.0, "same h = 1 ms, same algorithm"))
    else:
        out.append(_target("kinematics: Fortran loop >= 100x faster than plain NumPy",
                           "not measured", None, failed(results.get("kinematics")) or ""))
    return out


def peer_targets(results: dict) -> list[Row]:
    """>= 5x Exudyn on the free four-bar at equal accuracy, >= 50x on kinematic stepping."""
    peers = results.get("peers")
    why = failed(peers)
    if why is None and not peers.get("exudyn_available"):
        why = f"Exudyn unavailable: {peers.get('exudyn_unavailable_reason')}"
    if why is not None:
        return [_target("free four-bar: >= 5x faster than Exudyn at equal accuracy",
                        f"not measured ({why})", None),
                _target("kinematic stepping: >= 50x faster than Exudyn",
                        f"not measured ({why})", None)]
    eq = [r["ratio"] for r in get(peers, "dynamics", "equal_accuracy", default=[]) or []
          if r.get("ratio")]
    same = [r["time_ratio_exudyn_over_mbd2d"]
            for r in get(peers, "dynamics", "side_by_side", default=[]) or []
            if r.get("time_ratio_exudyn_over_mbd2d")]
    if eq:
        fig = (f"min {min(eq):.1f}x, median {statistics.median(eq):.1f}x over {len(eq)} "
               f"Exudyn step sizes")
        if same:
            fig += (f" (same method, generalized-alpha at equal h: {min(same):.1f}x – "
                    f"{max(same):.1f}x)")
        dyn = _target("free four-bar: >= 5x faster than Exudyn at equal accuracy", fig,
                      min(eq) >= 5.0, "met when every Exudyn point is matched >= 5x faster")
    else:
        dyn = _target("free four-bar: >= 5x faster than Exudyn at equal accuracy",
                      "not measured", None)
    ratio = get(peers, "kinematics", "ratio")
    rpos = get(peers, "kinematics", "ratio_positions")
    best = get(peers, "kinematics", "exudyn_best")
    if rpos:       # like for like: positions alone, as Exudyn's static solves give them
        fig = (f"{fmt(rpos, '.0f')}x positions only (like for like), {fmt(ratio, '.0f')}x "
               f"with q_dot and q_ddot (Exudyn's fastest variant: {best})")
    else:
        fig = (f"{fmt(ratio, '.0f')}x (Exudyn's fastest variant: {best})" if ratio
               else "not measured")
    crit = rpos if rpos else ratio
    kin = _target("kinematic stepping: >= 50x faster than Exudyn", fig,
                  None if crit is None else crit >= 50.0,
                  "Exudyn's static solves give q only: compared with mbd2d's positions-only "
                  "kinematics; the full step also computes q_dot and q_ddot")
    return [dyn, kin]


def chain_targets(results: dict) -> list[Row]:
    """>= 3x Exudyn's generalized-alpha on the N-four-bar at N = 100 and 1000, equal h."""
    pc = results.get("peers_chain")
    name = "free N-four-bar, generalized-alpha: >= 3x faster than Exudyn at N = 100 and 1000"
    why = failed(pc) or (f"Exudyn unavailable: {pc.get('unavailable')}"
                         if pc and pc.get("unavailable") else None)
    if pc is None or why:
        return [_target(name, f"not measured ({why or 'not run'})", None)]
    rows = [r for r in pc.get("rows", []) if r["n"] in (100, 1000)]
    if not rows:
        return [_target(name, "not measured", None)]
    fig = ", ".join(f"N = {r['n']} h = {r['h']:g}: {fmt(r.get('ratio'), '.1f')}x (errors "
                    f"{fmt(r['mbd2d'].get('error'), '.1e')} / "
                    f"{fmt(r['exudyn'].get('error'), '.1e')})" for r in rows)
    return [_target(name, fig, bool(pc.get("meets_target")),
                    "equal h, errors against the reduced one-dof equation")]


def scaling_targets(results: dict) -> list[Row]:
    """About linear in N (banded path) and N = 1000 at <= 2 ms per step."""
    sc = results.get("scaling")
    if failed(sc):
        return [_target("scaling: about linear in N", "not measured", None, failed(sc))]
    slope = sc.get("banded_slope")
    path = "banded"
    if slope is None:
        slope, path = sc.get("dense_slope"), "dense (no banded path)"
    t = sc.get("target") or {}
    return [_target("kinematics scaling with N: about linear (log-log slope ~ 1)",
                    f"slope {fmt(slope, '.2f')} ({path} path, N >= 10)",
                    None if slope is None else slope <= 1.25,
                    "met for a fitted slope <= 1.25"),
            _target("kinematics, N-four-bar N = 1000: <= 2 ms per step",
                    f"{fmt(t.get('ms_per_step'), '.3f')} ms/step ({t.get('path')} path)"
                    if t.get("ms_per_step") is not None else "not measured",
                    t.get("met") if t.get("ms_per_step") is not None else None)]


def short_steps_text(results: dict) -> str:
    """'; at h = 10 ms: R x' from the sweep's second setting, or ''."""
    sp = get(results, "sweep", "per_variant_short_steps") or {}
    r = sp.get("ratio_loop_over_batched")
    return f"; 10 steps of 10 ms: {fmt(r, '.1f')}x" if r else ""


def study_targets(results: dict) -> list[Row]:
    """Sweeps >= 10x cheaper per variant than a with_params loop; sensitivities of 4
    parameters <= 2x the analysis alone."""
    pv = get(results, "sweep", "per_variant") or {}
    ratio = pv.get("ratio_loop_over_batched")
    us = pv.get("us_per_variant") or {}
    out = [_target("sweep, 10-step kinematics: per-variant cost >= 10x below a with_params "
                   "loop", f"{fmt(ratio, '.1f')}x ({fmt(us.get('loop'), '.0f')} us -> "
                   f"{fmt(us.get('batched'), '.0f')} us; core alone "
                   f"{fmt(us.get('core'), '.0f')} us)" if ratio else "not measured",
                   None if ratio is None else ratio >= 10.0,
                   failed(results.get("sweep")) or "one crank turn in 10 steps; same run, "
                   "interleaved" + short_steps_text(results))]
    rows = get(results, "sensitivities", "rows") or []
    ratios = [r.get("ratio") for r in rows if r.get("ratio")]
    out.append(_target("sensitivities of 4 parameters: <= 2x the analysis alone",
                       ", ".join(f"{r['case'].split(',')[0]} {r['ratio']:.2f}x"
                                 + (f" ({r['instruction_ratio']:.2f}x instructions)"
                                    if r.get("instruction_ratio") else "")
                                 for r in rows if r.get("ratio")) or "not measured",
                       None if not ratios else max(ratios) <= 2.0,
                       failed(results.get("sensitivities")) or "wall time, same run; "
                       "instructions: callgrind of the core call"))
    return out


def runtime_target(results: dict) -> list[Row]:
    """`make bench` in under 10 minutes (the run itself, without the install)."""
    total = get(results, "meta", "total_runtime_s")
    if get(results, "meta", "earlier"):
        return [_target("make bench: under 10 minutes on this 2-core machine",
                        "not measured (this run measured only some sections)", None)]
    return [_target("make bench: under 10 minutes on this 2-core machine",
                    f"{fmt(total, '.0f')} s for bench/run.py (installs not counted)",
                    None if total is None else total < 600.0)]


def targets(results: dict) -> list[Row]:
    """Every target with its measured figure and whether it is met (None: not measured)."""
    return (kinematics_targets(results) + peer_targets(results) + chain_targets(results)
            + scaling_targets(results)
            + dynamics_scaling_targets(results) + study_targets(results)
            + runtime_target(results))


def dynamics_scaling_targets(results: dict) -> list[Row]:
    """Issue 11: generalized-alpha at N = 1000 <= 5 ms/step, setup < 1 s, slope <= 1.15
    from N = 100 to 10,000 (each method)."""
    ds = results.get("dynamics_scaling")
    if failed(ds):
        return [_target("dynamics scaling with N", "not measured", None, failed(ds))]
    at = (ds.get("n1000") or {}).get("generalized-alpha") or {}
    out = [_target("free N-four-bar, generalized-alpha h = 1 ms, N = 1000: <= 5 ms/step",
                   f"{fmt(at.get('ms_per_step'), '.2f')} ms/step (whole call "
                   f"{fmt(at.get('call_ms_per_step'), '.2f')})",
                   None if at.get("ms_per_step") is None else at["ms_per_step"] <= 5.0),
           _target("the same: setup at N = 1000 under 1 s",
                   f"{fmt(at.get('setup_s'), '.3f')} s",
                   None if at.get("setup_s") is None else at["setup_s"] < 1.0)]
    calls = ds.get("call_slopes") or {}
    for method, sl in (ds.get("slopes") or {}).items():
        out.append(_target(f"dynamics ({method}): log-log slope <= 1.15, N = 100 to 10,000",
                           f"slope {fmt(sl, '.2f')} per step (whole call "
                           f"{fmt(calls.get(method), '.2f')})",
                           None if sl is None else sl <= 1.15))
    return out


def met_text(met: bool | None) -> str:
    return {True: "met", False: "**not met**", None: "not measured"}[met]


# ===================================================================== sections
def machine_section(env: dict) -> str:
    """The machine and versions table."""
    git = env.get("git") or {}
    dirty = git.get("uncommitted_changes_outside_bench") or []
    rows = [("CPU", f"{env.get('cpu_model')}, {env.get('cores')} cores, "
                    f"{fmt(env.get('memory_gib'), '.0f')} GiB"),
            ("OS", env.get("os")), ("Python", env.get("python")),
            ("numpy", f"{env.get('numpy')} ({env.get('numpy_blas')})"),
            ("scipy / matplotlib", f"{env.get('scipy')} / {env.get('matplotlib')}"),
            ("gfortran", env.get("gfortran")),
            ("BLAS / LAPACK of the mbd2d core", "<br>".join(env.get("blas_lapack") or [])
             or "unknown"),
            ("mbd2d", f"{env.get('mbd2d')}, commit `{str(git.get('commit'))[:12]}` "
                      f"({git.get('subject')})"
                      + (f"; uncommitted changes in {', '.join(dirty)}" if dirty else "")),
            ("Exudyn", env.get("exudyn") or f"unavailable: {env.get('exudyn_unavailable_reason')}"),
            ("load average (1 min) at start / end",
             f"{fmt(get(env, 'load_average_start', 0), '.2f')} / "
             f"{fmt(get(env, 'load_average_end', 0), '.2f')}"),
            ("date (UTC)", env.get("date_utc"))]
    return table(("", ""), rows)


def wp_table(data: dict) -> str:
    """Every row of one work-precision study."""
    rows = []
    for r in data.get("rows", []):
        note = "" if r.get("ok") else r.get("message", "")[:80]
        if "branch_kept" in r and r.get("ok"):
            note = "branch kept" if r["branch_kept"] else "left the branch"
        rows.append((r.get("variant", ""), r["method"], r["setting"], fmt(r.get("error"), ".2e"),
                     fmt(r.get("cpu_s"), ".4f"), fmt(r.get("steps"), "d"), note))
    return table(("model", "method", "setting", "error (rad)", "CPU s", "steps", "note"), rows)


def work_precision_section(results: dict, charts: dict, out: Path, base: Path) -> str:
    """Charts, settings and tables of the three studies."""
    wp = results.get("work_precision")
    if failed(wp):
        return f"Failed: {failed(wp)}\n"
    parts = ["Error against CPU time (best-of-3 wall time of one `model.dynamics` call for "
             "runs under 0.5 s, one run otherwise), one line per method and sweep: the "
             "adaptive methods over rtol (atol = rtol/100), the fixed-step ones over h. "
             "A sweep stops once one of its runs takes over its time budget (the remaining "
             "settings are listed as skipped).\n"]
    titles = {"fourbar": "Free four-bar, 10 s", "andrews": "Andrews' squeezer, to 0.03 s",
              "nfourbar": "IFToMM N-four-bar, 10 s"}
    for name, title in titles.items():
        data = wp.get(name) or {}
        parts.append(f"### {title}\n")
        if failed(data):
            parts.append(f"Failed: {failed(data)}\n")
            continue
        parts.append(f"{data.get('model', '')}.\n\nReference: "
                     f"{get(data, 'reference', 'description')}; check "
                     f"{fmt(get(data, 'reference', 'check'), '.1e')} rad.\n")
        parts.append(image(charts, f"wp_{name}", out, base, f"work-precision {name}"))
        parts.append("Sweeps: " + "; ".join(data.get("sweeps", [])) + ".\n")
        parts.append(f"<details><summary>All {len(data.get('rows', []))} runs "
                     f"({fmt(data.get('runtime_s'), '.0f')} s)</summary>\n\n{wp_table(data)}"
                     "\n</details>\n")
    return "\n".join(parts)


def chain_section(results: dict) -> str:
    """Exudyn and mbd2d on the free N-four-bar (bench/peers_exudyn_chain.py)."""
    pc = results.get("peers_chain")
    if (text := absent(pc)) is not None:
        return text
    if pc.get("unavailable"):
        return f"Exudyn unavailable: {pc['unavailable']}.\n"
    rows = []
    for r in pc.get("rows", []):
        a, b = r["mbd2d"], r["exudyn"]
        rows.append((r["n"], f"{r['h']:g}", fmt(a.get("ms_per_step"), ".3f"),
                     fmt(b.get("ms_per_step"), ".3f"), fmt(r.get("ratio"), ".1f"),
                     fmt(a.get("error"), ".2e"), fmt(b.get("error"), ".2e"),
                     f"{a.get('newton_iterations')} / {b.get('newton_iterations')}"
                     + (f" ({b.get('message')})" if b.get("message") else "")))
    return "\n".join([
        f"{pc.get('model')}, {pc.get('t_end')} s from the upright start, generalized-alpha "
        f"(rho_inf = {pc.get('rho_inf')}) at fixed h in both codes, Exudyn "
        f"{pc.get('exudyn_version')} with its sparse solver (EigenSparse). Error: the first "
        "crank's angle against the reduced one-degree-of-freedom equation (DOP853, 1e-13), "
        "largest over the outputs. Time: best wall time of the solve call (see "
        "bench/peers_exudyn_chain.py).\n",
        table(("N", "h", "mbd2d ms/step", "Exudyn ms/step", "Exudyn / mbd2d", "mbd2d error",
               "Exudyn error", "Newton iterations mbd2d / Exudyn"), rows)])


def modes_section(results: dict) -> str:
    """Vibration modes: closed forms, mbd2d and Exudyn (bench/peers_modes.py)."""
    md = results.get("modes")
    if (text := absent(md)) is not None:
        return text
    rows = []
    for r in md.get("rows", []):
        rows.append((r["model"], r.get("n_free"), fmt(r.get("mbd2d_error"), ".1e"),
                     fmt(r.get("exudyn_error"), ".1e"), fmt(1e3 * r["mbd2d_s"], ".3g"),
                     fmt(1e3 * r["mbd2d_q0_s"], ".3g"),
                     fmt(1e3 * r["exudyn_s"] if r.get("exudyn_s") else None, ".3g"),
                     fmt(r.get("time_ratio"), ".2g")))
    exu = (f"Exudyn {md.get('exudyn')}" if md.get("exudyn_available")
           else f"Exudyn unavailable ({md.get('exudyn_unavailable_reason')})")
    return "\n".join([
        "Natural frequencies against closed forms (docs/modes.md): the hanging double pendulum "
        "(its 2 x 2 matrices by hand; all its stiffness is the pins' curvature under the "
        "multipliers) and a fixed-free spring chain; mbd2d's `model.modes()` (which finds the "
        "equilibrium first) and `modes(equilibrium=False)` (about q0, as Exudyn takes its "
        f"initial state) beside {exu}'s `ComputeODE2Eigenvalues` (undamped only; the chain "
        "as mass points with their y coordinates removed, no constraint equations). Error: "
        "largest relative error over the modes. Time: best wall time of the call.\n",
        table(("model", "free motions", "mbd2d error", "Exudyn error", "mbd2d ms",
               "mbd2d about q0 ms", "Exudyn ms", "mbd2d about q0 / Exudyn"), rows),
        "\nExudyn's eigenvalues of the pendulum are 0: its projected stiffness leaves out the "
        "multipliers' term (Jᵀλ)_q, which is all of a pendulum's stiffness; mbd2d has it, "
        "exactly (its stiffness and damping from the design sensitivities' second "
        "derivatives). On the unconstrained chain Exudyn is faster (a dense symmetric "
        "eigensolver on the free coordinates directly; mbd2d builds the null space of a "
        "constrained model of blocks on guides, 3 coordinates a block).\n"])


def frf_section(results: dict) -> str:
    """The frequency response: chains against numpy, a sweep against a loop (bench/frf.py)."""
    md = results.get("frf")
    if (text := absent(md)) is not None:
        return text
    chains = [(r["n"], r["frequencies"], r["solver"], fmt(r["error"], ".1e"),
               fmt(r.get("cond_eps"), ".1e"),
               fmt(1e3 * r["mbd2d_s"], ".3g"), fmt(1e3 * r["numpy_s"], ".3g"),
               fmt(r["ratio"], ".2g"), fmt(1e3 * r["mbd2d_per_frequency_s"], ".2g"),
               fmt(1e3 * r["numpy_per_frequency_s"], ".2g")) for r in md.get("chains", [])]
    sweeps = [(r["cases"], r["frequencies"], fmt(1e3 * r["batched_per_case_s"], ".3g"),
               fmt(1e3 * r["loop_per_case_s"], ".3g"), fmt(r["ratio"], ".2g"),
               "yes" if r["identical"] else "NO") for r in md.get("sweeps", [])]
    return "\n".join([
        "A spring chain of n blocks damped at its end, driven by a force on its first block "
        "(docs/frf.md): `model.frequency_response` against numpy's `linalg.solve` of "
        "(K − ω²M + iωC)x = e₁ per frequency with the matrices written by hand. Error: largest "
        "|H − x| over blocks and frequencies relative to max |x|, beside cond(K − ω²M + iωC)·eps "
        "(its largest over the frequencies: the lightly damped chain's resonances bound what "
        "either solution is good to). Time: best wall time of "
        "mbd2d's whole call (statics, null space, exact K, C and the input's derivatives from "
        "the model, the multipliers' response) and of numpy's solves alone; per frequency: "
        "the difference of the calls at 2 nw and nw frequencies over nw (mbd2d: Laub's "
        "Hessenberg form from 16 free motions and 8 frequencies).\n",
        table(("n", "frequencies", "mbd2d solver", "error", "cond·eps", "mbd2d ms", "numpy ms",
               "mbd2d / numpy", "mbd2d ms per frequency", "numpy ms per frequency"), chains),
        "\nThe half car's road response over its suspension damping: one "
        "`mbd2d.sweep(..., \"frf\")` against a Python loop of `with_params` and "
        "`frequency_response` (the same numbers, bit for bit).\n",
        table(("cases", "frequencies", "batched ms per case", "loop ms per case",
               "loop / batched", "identical"), sweeps)])


def peers_section(results: dict) -> str:
    """Exudyn side by side, at equal accuracy, and kinematic stepping."""
    peers = results.get("peers")
    if failed(peers):
        return f"Failed: {failed(peers)}\n"
    parts = []
    if not peers.get("exudyn_available"):
        parts.append(f"**Exudyn is unavailable** ({peers.get('exudyn_unavailable_reason')}); "
                     "only mbd2d's side was run.\n")
    parts.append(f"Free four-bar, 10 s, generalized-alpha at fixed h in both codes "
                 f"(rho_inf = {get(peers, 'dynamics', 'rho_inf')}); error: max abs angle "
                 "error against mbd2d dopri5 at rtol 1e-12. Time: best-of-3 wall time of the "
                 "solve call (Exudyn: `mbs.SolveDynamic`, model assembled before). The "
                 "Exudyn points are also on the four-bar work-precision chart.\n")
    rows = [(fmt(r["h"], ".0e"), fmt(r["exudyn_error"], ".2e"), fmt(r["exudyn_cpu_s"], ".4f"),
             fmt(r["mbd2d_error"], ".2e"), fmt(r["mbd2d_cpu_s"], ".4f"),
             fmt(r["time_ratio_exudyn_over_mbd2d"], ".1f"))
            for r in get(peers, "dynamics", "side_by_side", default=[]) or []]
    parts.append("#### Same method, equal h\n\n" + table(
        ("h", "Exudyn error", "Exudyn s", "mbd2d error", "mbd2d s", "Exudyn / mbd2d"), rows))
    eq = get(peers, "dynamics", "equal_accuracy", default=[]) or []
    if eq:
        rows = [(fmt(r["h"], ".0e"), fmt(r["exudyn_error"], ".2e"), fmt(r["exudyn_cpu_s"], ".4f"),
                 r["mbd2d_method"] or "–", fmt(r["mbd2d_cpu_s"], ".4f"), fmt(r["ratio"], ".1f"))
                for r in eq]
        parts.append("#### At equal accuracy\n\nFor each Exudyn point, mbd2d's time at the same "
                     "error: each mbd2d work-precision line of the four-bar study interpolated "
                     "log-log at that error (no extrapolation), the fastest line taken.\n\n"
                     + table(("Exudyn h", "error", "Exudyn s", "fastest mbd2d line",
                              "mbd2d s", "Exudyn / mbd2d"), rows))
    kin = peers.get("kinematics") or {}
    rows = [(f"Exudyn: {name}", fmt(v.get("us_per_step"), ".2f"), fmt(v.get("max_error"), ".1e"),
             v.get("message", "")[:80]) for name, v in (kin.get("exudyn_variants") or {}).items()]
    for key, label in (("mbd2d", "mbd2d: `model.kinematics` (q, qd, qdd)"),
                       ("mbd2d_positions", "mbd2d: `model.kinematics(positions_only=True)` "
                                           "(q)")):
        m = kin.get(key) or {}
        if m:
            rows.append((label, fmt(m.get("us_per_step"), ".2f"), fmt(m.get("max_error"), ".1e"),
                         ""))
    parts.append(f"#### Kinematic stepping\n\nDriven four-bar (examples/fourbar_grashof.toml), "
                 f"{kin.get('steps')} steps over {kin.get('t_end')} s; Exudyn has no kinematic "
                 "solver, so a static solve per time with the crank angle prescribed. Error: "
                 "max abs coordinate error against the closed form. Ratio (fastest Exudyn "
                 f"variant / mbd2d): **{fmt(kin.get('ratio_positions'), '.0f')}x** like for "
                 "like (mbd2d's positions only), "
                 f"**{fmt(kin.get('ratio'), '.0f')}x** with velocities and accelerations.\n\n"
                 + table(("code", "us/step", "max error", "note"), rows))
    return "\n".join(parts)


def kinematics_section(results: dict) -> str:
    """The three ways of running kinematics."""
    kin = results.get("kinematics")
    if failed(kin):
        return f"Failed: {failed(kin)}\n"
    rows = []
    for label, r in (kin.get("rows") or {}).items():
        st = r.get("python_stepper") or {}
        st_txt = fmt(st.get("us_per_step"), ".2f") if st.get("available") else \
            f"not available ({st.get('message', '')})"
        rows.append((label, fmt(get(r, "fortran_loop", "us_per_step"), ".3f"),
                     fmt(get(r, "fortran_loop_h1e-4", "us_per_step"), ".3f"), st_txt,
                     fmt(get(r, "numpy", "us_per_step"), ".1f"),
                     fmt(r.get("ratio_numpy_over_loop"), ".0f"),
                     fmt(r.get("ratio_numpy_over_stepper"), ".0f"),
                     fmt(get(r, "agreement_numpy_vs_mbd2d", "q_rel"), ".0e")))
    intro = ("Microseconds per output step (position + velocity + acceleration), best-of-5 "
             "wall time over the run, at h = 1 ms (100 s, 100 crank turns) and, for (a), "
             "also at h = 0.1 ms (10 s): "
             "(a) the time loop in the Fortran core, one call per analysis; (b) one "
             "`mbd2d.KinematicStepper.step(t)` call (one core call) per step from a Python "
             "loop; (c) bench/numpy_kinematics.py, the same algorithm in plain NumPy. "
             "The last column is the largest difference of the NumPy q from mbd2d's, "
             "relative to the model size.\n\n")
    return intro + table(("model", "(a) Fortran loop", "(a) at h = 0.1 ms",
                          "(b) Python stepper", "(c) NumPy", "NumPy / (a)", "NumPy / (b)",
                          "NumPy vs mbd2d q"), rows) + "\n" + callgrind_section(kin)


def callgrind_section(kin: dict) -> str:
    """Instructions per kinematic step of the four-bar, by part (bench/callgrind.py)."""
    cg = kin.get("callgrind") or {}
    if not cg.get("available"):
        return f"Instructions per step: not measured ({cg.get('reason', 'not run')}).\n"
    rows = []
    for r in cg.get("rows") or []:
        tot = r.get("instructions_per_step") or 0.0
        parts = r.get("parts") or {}
        rows.append((f"{r.get('h', 0) * 1000:g} ms"
                     + (", positions only" if r.get("positions_only") else ""), f"{tot:,.0f}",
                     *(f"{parts.get(k, 0.0):,.0f} ({100 * parts.get(k, 0.0) / tot:.0f}%)"
                       if tot else "–" for k in ("assembly", "LU", "solves", "loop")),
                     fmt(r.get("newton_corrections_per_step"), ".3f"),
                     fmt(r.get("lu_per_step"), ".3f")))
    intro = ("#### Instructions per step (callgrind)\n\nThe four-bar "
             "(examples/fourbar_grashof.toml) in the core's time loop under "
             "`valgrind --tool=callgrind`, collection on inside `kin_run` only; per step = "
             "(I(3000 steps) - I(1000 steps)) / 2000 (crank turns 1 to 3 at h = 1 ms), so "
             "the setup cancels. Parts: each "
             "function's own instructions by name (assembly of Phi, J, nu, gamma with sin/cos; "
             "the sparse LU; the triangular solves; the rest of the loop: predictor, step "
             "acceptance, checks, output; with positions only also the chord corrections' "
             "bookkeeping). Stable on a shared machine, unlike wall time. "
             f"{cg.get('valgrind', '')}.\n\n")
    return intro + table(("h", "instructions/step", "assembly", "LU", "solves", "loop",
                          "Newton corrections/step", "LU/step"), rows)


def scaling_section(results: dict, charts: dict, out: Path, base: Path) -> str:
    """Chart and table of time per step against N."""
    sc = results.get("scaling")
    if failed(sc):
        return f"Failed: {failed(sc)}\n"
    parts = [f"{sc.get('model')}. {sc.get('method')}.\n"]
    if not sc.get("banded_available"):
        parts.append(f"Banded path: unavailable ({sc.get('banded_unavailable_reason')}).\n")
    parts.append(image(charts, "scaling", out, base, "time per step against N"))
    parts.append(f"Fitted log-log slope (N >= 10): banded {fmt(sc.get('banded_slope'), '.2f')}, "
                 f"dense {fmt(sc.get('dense_slope'), '.2f')}.\n")
    by_n: dict[int, dict[str, Row]] = {}
    for path, rows in (sc.get("rows") or {}).items():
        for r in rows:
            by_n.setdefault(r["n"], {})[path] = r
    rows = []
    for n in sorted(by_n):
        d, b = by_n[n].get("dense", {}), by_n[n].get("banded", {})
        coords = d.get("coordinates") or b.get("coordinates") or 3 * (2 * n + 1)
        rows.append((n, coords, fmt(d.get("us_per_step"), ".2f"), fmt(b.get("us_per_step"), ".2f"),
                     fmt(b.get("factorizations_per_step") or d.get("factorizations_per_step"),
                         ".2f"),
                     d.get("message") or b.get("message") or ""))
    parts.append(table(("N", "coordinates", "dense us/step", "banded us/step",
                        "LU per step", "note"), rows))
    return "\n".join(parts)


def memory_section(results: dict, charts: dict, out: Path, base: Path) -> str:
    """Table and chart of the memory cases."""
    mem = results.get("memory")
    if failed(mem):
        return f"Failed: {failed(mem)}\n"
    rows = []
    for r in mem.get("rows", []):
        note = r.get("message", "") if r.get("run_mib") is None else ""
        rows.append((r["analysis"], r["every"], f"{r['steps']:,}", fmt(r.get("rows"), ","),
                     fmt(r.get("run_mib"), ".1f"), fmt(r.get("kept_data_mib"), ".1f"),
                     fmt(r.get("seconds"), ".2f"), note or ("" if r.get("available", True)
                                                           else "unavailable")))
    return (f"{mem.get('method')}. Kinematics: {mem.get('kinematics_case')}; dynamics: "
            f"{mem.get('dynamics_case')}. 'kept data' is t, q, qd, qdd of the rows returned.\n\n"
            + table(("analysis", "every", "steps", "rows kept", "run peak MiB",
                     "kept data MiB", "s", "note"), rows) + "\n"
            + image(charts, "memory", out, base, "memory"))


def synthesis_section(results: dict) -> str:
    """The literature cases: published errors, mbd2d and pylinkage, with times."""
    syn = results.get("synthesis")
    if failed(syn):
        return f"Failed: {failed(syn)}\n"
    parts = ["Four-bar path generation, the three standard cases of the synthesis literature "
             "(bench/synthesis.py has the targets, bounds and the published design vectors). "
             "Error: sum of squared distances between the coupler point and the targets. The "
             "published errors are recomputed from the published design vectors with the "
             "literature's closed form. mbd2d: `mbd2d.synthesize` (Latin-hypercube starts "
             "screened for defects, least squares with the exact Jacobian from the "
             "sensitivities), both assembly branches; every design defect-free (no dead "
             "centre or branch change over the input range, targets in order, Grashof type). "
             "pylinkage: its differential-evolution optimizer over its own dyad solver, same "
             "bounds, Grashof and order as penalties. Times are CPU seconds of this process "
             "(pylinkage single-threaded; mbd2d with one worker).\n"]
    if syn.get("pylinkage_unavailable_reason"):
        parts.append(f"**pylinkage unavailable**: {syn['pylinkage_unavailable_reason']}.\n")
    rows = []
    for name, c in (syn.get("cases") or {}).items():
        pub = c.get("published") or {}
        best_pub = min(pub.items(), key=lambda kv: kv[1]) if pub else (None, None)
        mb, pl, po = c.get("mbd2d") or {}, c.get("pylinkage") or {}, c.get("polish") or {}
        rows.append((name, f"{fmt(best_pub[1], '.3g')} ({best_pub[0]})",
                     fmt(mb.get("error"), ".3g"), fmt(mb.get("cpu_s"), ".1f"),
                     fmt(pl.get("error"), ".3g"), fmt(pl.get("cpu_s"), ".1f"),
                     fmt(po.get("error"), ".3g")))
    parts.append(table(("case", "best published (recomputed)", "mbd2d error", "mbd2d CPU s",
                        "pylinkage error", "pylinkage CPU s",
                        "mbd2d from the best published design"), rows))
    for name, c in (syn.get("cases") or {}).items():
        pub = c.get("published") or {}
        parts.append(f"<details><summary>{name}: every published design</summary>\n\n"
                     + table(("source", "error (recomputed)"),
                             [(a, fmt(e, ".4g")) for a, e in pub.items()])
                     + "\n</details>\n")
    return "\n".join(parts)


def sweep_section(results: dict) -> str:
    """Per-variant cost of sweeps and the Dask throughput."""
    sw = results.get("sweep")
    if failed(sw):
        return f"Failed: {failed(sw)}\n"
    pv = sw.get("per_variant") or {}
    us = pv.get("us_per_variant") or {}
    parts = [f"Per-variant cost of a {pv.get('steps')}-step kinematic run of the crank-rocker "
             f"({pv.get('model')}, `{pv.get('parameter')}` over {pv.get('variants')} values), "
             "best-of-{0} wall time, interleaved: a Python loop of `model.with_params(...)"
             ".kinematics(...)`, one `mbd2d.sweep(..., workers=1)` (one process, the Dataset "
             "included), and one core call per variant on the packed base model (the floor "
             "of any batching).\n".format(pv.get("repeats")),
             table(("", "us per variant"),
                   [("loop: with_params + kinematics", fmt(us.get("loop"), ".0f")),
                    ("batched: mbd2d.sweep", fmt(us.get("batched"), ".1f")),
                    ("one core_kinematics call per variant (packed once)",
                     fmt(us.get("core"), ".1f"))]),
             f"Loop / batched: **{fmt(pv.get('ratio_loop_over_batched'), '.1f')}x**; batched "
             f"/ core alone: {fmt(pv.get('batched_over_core'), '.2f')} (one crank turn in "
             f"{pv.get('steps')} steps).\n"]
    sp = sw.get("per_variant_short_steps") or {}
    if sp:
        su = sp.get("us_per_variant") or {}
        parts.append(f"The same over {fmt(sp.get('t_end'), 'g')} s (h = "
                     f"{fmt(1e3 * sp['t_end'] / sp['steps'], 'g')} ms): loop "
                     f"{fmt(su.get('loop'), '.0f')} us, batched {fmt(su.get('batched'), '.1f')} "
                     f"us, core alone {fmt(su.get('core'), '.1f')} us; loop / batched "
                     f"**{fmt(sp.get('ratio_loop_over_batched'), '.1f')}x**.\n")
    tp = sw.get("throughput") or {}
    rows = [(r["runner"], fmt(r.get("variants_per_s"), ".0f"), fmt(r.get("seconds"), ".3f"),
             "yes" if r.get("identical_to_serial") else "**no**") for r in tp.get("rows", [])]
    parts.append(f"Throughput: {tp.get('cases')} variants of a {tp.get('steps')}-step run, "
                 f"every {tp.get('every')}th row kept (best of the repeats after a warm-up "
                 "sweep; Dask LocalCluster with process workers of 1 thread, started before "
                 "the timing).\n")
    if tp.get("dask_unavailable"):
        parts.append(f"Dask unavailable: {tp['dask_unavailable']}.\n")
    parts.append(table(("runner", "variants / s", "s", "identical to the serial Dataset"),
                       rows))
    alone = [r for r in sw.get("standalone") or [] if "solve_s" in r]
    if alone:
        parts.append("Without Python: the same sweeps exported once (`mbd2d.export_sweep`) and "
                     "run from the file to a CSV by `mbd2d-solve` (process start, reading, the "
                     "batch call, writing), against `mbd2d.sweep(..., workers=1)` + "
                     "`mbd2d.write_sweep` (interleaved, best of the repeats).\n")
        parts.append(table(("variants x steps (rows kept)", "mbd2d-solve s", "Python s",
                            "Python / mbd2d-solve", "the same CSV bytes"),
                           [(f"{r['cases']} x {r['steps']} (every {r['every']})",
                             fmt(r.get("solve_s"), ".3f"), fmt(r.get("python_s"), ".3f"),
                             fmt(r.get("ratio"), ".1f") + "x",
                             "yes" if r.get("same_csv") else "**no**") for r in alone]))
    return "\n".join(parts)


def sensitivities_section(results: dict) -> str:
    """Cost ratio of each analysis with 4 parameters' sensitivities to the analysis alone."""
    se = results.get("sensitivities")
    if failed(se):
        return f"Failed: {failed(se)}\n"
    rows = [(r["case"], fmt(r.get("base_us_per_step"), ".2f"),
             fmt(r.get("sens_us_per_step"), ".2f"), fmt(r.get("ratio"), ".2f"),
             fmt(r.get("instruction_ratio"), ".2f"),
             " / ".join(str(x) for x in r.get("integrator_steps", [])) or "–")
            for r in se.get("rows", [])]
    text = (f"Wall time per output step of the public call with and without "
            f"`sensitivities=[4 names]` ({se.get('steps')} steps at h = 1 ms, best of "
            f"{se.get('repeats')}, interleaved; bench/sensitivities.py), and the ratio of "
            "callgrind instructions of the core call (3000 steps; the dopri5 case as timed), "
            "stable on a shared machine.\n\n"
            + table(("case", "us/step", "with sensitivities", "ratio", "instruction ratio",
                     "integrator steps"), rows))
    ms = se.get("measures")
    if ms:
        text += (f"\nThe mechanism measures' exact derivatives (no target): the four-bar's run "
                 f"with {ms.get('parameters')} parameters ({ms.get('rows')} rows, "
                 f"{fmt(ms.get('run_us_per_row'), '.2f')} us per row with its sensitivities); "
                 "per row, each measure alone and with its derivatives (one core call).\n\n"
                 + table(("measure", "us/row", "with derivatives", "ratio"),
                         [(r["measure"], fmt(r["value_us_per_row"], ".2f"),
                           fmt(r["with_derivatives_us_per_row"], ".2f"),
                           fmt(r["ratio"], ".1f") + "x") for r in ms.get("measures", [])]))
    return text


def dynamics_scaling_section(results: dict, charts: dict, out: Path, base: Path) -> str:
    """Table and chart of the dynamics cost against N (bench/dynamics_scaling.py)."""
    ds = results.get("dynamics_scaling")
    if failed(ds):
        return f"Failed: {failed(ds)}\n"
    parts = [f"{ds.get('model')}; settings {ds.get('settings')}. CPU time per integrator step "
             "(the difference of a short and a long call over the difference of their steps; "
             "below N = 300 both calls run 300 / N times longer; band path best of 3 at every "
             "N), the long call's whole time per step (start, packing and result included) and "
             "the setup (the first call, one step); the dense path is the baseline of the same "
             "run.\n",
             image(charts, "dynamics_scaling", out, base, "dynamics cost against N")]
    rows = []
    for key, rs in (ds.get("rows") or {}).items():
        for r in rs:
            rows.append((key, r["n"], r["coordinates"], fmt(r["ms_per_step"], ".3f"),
                         fmt(r.get("call_ms_per_step"), ".3f"), fmt(r["setup_s"], ".3f"),
                         r["steps"]))
    parts.append(table(("method / path", "N", "coordinates", "ms / step", "whole call ms / step",
                        "setup s", "steps"), rows))
    calls = ds.get("call_slopes") or {}
    parts.append("Log-log slopes (band path, N = 100 to the largest), per step (whole call): "
                 + ", ".join(f"{k} {fmt(v, '.2f')} ({fmt(calls.get(k), '.2f')})"
                             for k, v in (ds.get("slopes") or {}).items()) + ".\n")
    return "\n".join(parts)


def contact_section(results: dict, charts: dict, out: Path, base: Path) -> str:
    """Tables of the contact costs (bench/contact.py)."""
    con = results.get("contact")
    if (text := absent(con)) is not None:
        return text
    cl = con.get("clearance", {})
    rows = [(r["case"], fmt(1e3 * r["seconds"], ".1f"), fmt(r["ratio"], ".1f"), r["steps"],
             r["rejected"], r["events"], fmt(r["us_per_rhs"], ".1f")) for r in cl.get("rows", [])]
    far = con.get("far_pairs", {})
    frows = [(r["case"], fmt(r["us_per_rhs"], ".1f"), fmt(r.get("per_rhs_ratio"), ".2f"),
              fmt(r.get("us_per_pair_per_rhs"), ".2f")) for r in far.get("rows", [])]
    return (f"{cl.get('model')}, two crank turns, {cl.get('method')} rtol {cl.get('rtol')}; "
            "best of the repeats, ratio to the ideal joint in the same run.\n\n"
            + table(("case", "ms", "x ideal", "steps", "rejected", "events", "us / rhs"), rows)
            + "\n" + image(charts, "contact", out, base, "clearance joint cost")
            + f"\n{far.get('model')}: cost per right-hand side (the bounding test per pair).\n\n"
            + table(("case", "us / rhs", "x none", "us per pair"), frows) + "\n")


def pictures_section(results: dict) -> str:
    """The pictures' cost, batched against one artist per part (bench/pictures.py)."""
    pic = results.get("pictures")
    if (text := absent(pic)) is not None:
        return text
    rows = [(r["n"], "one per look" if r["batched"] else "one per part", r["artists"],
             fmt(r["picture_s"], ".2f"), fmt(r.get("picture_ratio"), ".1f"),
             fmt(r["gif_s"], ".2f"), fmt(r.get("gif_ratio"), ".1f"))
            for r in pic.get("rows", [])]
    return (f"{pic.get('model')}: the snapshot picture ({pic.get('picture')}) and the GIF "
            f"({pic.get('gif')}), CPU seconds; the ratio is one artist per part over one per "
            "look, in the same run.\n\n"
            + table(("N", "drawn as", "artists on the Axes", "picture s", "x", "GIF s", "x"), rows)
            + "\n")


def notes_section(results: dict) -> str:
    """Quick mode, failures and section run times."""
    meta = results.get("meta") or {}
    lines = []
    if meta.get("quick"):
        lines.append("- This run used `--quick` (reduced sweeps, fewer steps): a smoke test, "
                     "not the reference figures.")
    else:
        lines.append("- Time budget: the N-four-bar work-precision sweep at N = 5 stops at "
                     "loose settings (tight ones take minutes per run), and every sweep stops "
                     "once one of its runs exceeds its budget; the Exudyn kinematic "
                     "comparison uses 10,000 steps.")
    if meta.get("earlier"):
        lines.append(f"- This run measured {', '.join(meta.get('sections') or [])}; the other "
                     f"sections ({', '.join(meta['earlier'])}) are from an earlier run's "
                     "results files.")
    for name, sec in results.items():
        if isinstance(sec, dict) and sec.get("failed"):
            lines.append(f"- Section **{name} failed**: {sec.get('error')}")
    times = ", ".join(f"{k} {v['runtime_s']:.0f} s" for k, v in results.items()
                      if isinstance(v, dict) and v.get("runtime_s") is not None)
    total = fmt(meta.get("total_runtime_s"), ".0f")
    lines.append(f"- Section run times: {times}; total {total} s.")
    load = get(results, "environment", "load_average_start", 0)
    if load is not None and load > 1.5:
        lines.append(f"- The machine was busy at the start (load average {load:.1f} on 2 "
                     "cores): the timings may be pessimistic.")
    blas = " ".join(get(results, "environment", "blas_lapack", default=[]) or [])
    if "libblas3" in blas or "liblapack3" in blas:
        lines.append("- The mbd2d core links Debian's reference BLAS/LAPACK (libblas3, "
                     "liblapack3), not an optimized BLAS: the dense path's figures for large N "
                     "reflect that.")
    lines.append("- Timings are wall times (time.perf_counter) on a shared 2-core virtual "
                 "machine; expect a few tens of percent run-to-run variation.")
    return "\n".join(lines) + "\n"


# ===================================================================== documents
def results_markdown(results: dict, charts: dict[str, str], md_path: Path, out: Path) -> str:
    """bench/RESULTS.md."""
    base = md_path.resolve().parent
    env = results.get("environment") or {}
    tg = targets(results)
    parts = ["# mbd2d benchmarks\n",
             f"> Generated by `{get(results, 'meta', 'command')}` (`make bench` runs it) on "
             f"{env.get('date_utc')}. Do not edit: regenerate with `make bench` or "
             "`python bench/run.py` in the project's venv. Raw figures: "
             f"[{os.path.relpath(out, base)}/]({os.path.relpath(out, base)}/) (JSON, with "
             "the machine and versions in every file).\n",
             "## Targets\n",
             table(("target", "measured", "met"),
                   [(t["target"], t["figure"], met_text(t["met"])) for t in tg]),
             "## Machine\n", machine_section(env),
             "## Work precision of the dynamics methods\n",
             work_precision_section(results, charts, out, base),
             "## Peers: Exudyn\n", peers_section(results),
             "### The free N-four-bar (large model)\n", chain_section(results),
             "## Kinematics speed\n", kinematics_section(results),
             "## Scaling with model size\n", scaling_section(results, charts, out, base),
             "## Memory of long runs\n", memory_section(results, charts, out, base),
             "## Design sweeps\n", sweep_section(results),
             "## Sensitivity cost\n", sensitivities_section(results),
             "## Dynamics against model size\n",
             dynamics_scaling_section(results, charts, out, base),
             "## Contacts\n", contact_section(results, charts, out, base),
             "## Pictures of large models\n", pictures_section(results),
             "## Vibration modes: closed forms and Exudyn\n", modes_section(results),
             "## Frequency response: numpy and sweeps\n", frf_section(results),
             "## Linkage synthesis: literature cases and pylinkage\n",
             synthesis_section(results),
             "## Notes\n", notes_section(results)]
    return "\n".join(parts)


def headline_markdown(results: dict, charts: dict[str, str], out: Path) -> str:
    """A short README section: the four-bar work-precision chart and the key figures."""
    tg = targets(results)
    rows = [(t["target"], t["figure"], met_text(t["met"])) for t in tg
            if not t["target"].startswith("make bench")]
    mem = get(results, "memory", "rows", default=[]) or []
    for r in mem:
        if r.get("run_mib") is not None:
            rows.append((f"memory, {r['analysis']} of {r['steps']:,} steps, every={r['every']}",
                         f"{r['run_mib']:.1f} MiB", "–"))
    env = results.get("environment") or {}
    return "\n".join([
        "## Performance\n",
        f"Measured by `make bench` on {env.get('cpu_model')} ({env.get('cores')} cores), "
        f"{env.get('os', '').split(' (')[0]}, mbd2d commit "
        f"`{str(get(env, 'git', 'commit'))[:12]}`; all figures, charts and the method in "
        "[bench/RESULTS.md](bench/RESULTS.md).\n",
        image(charts, "wp_fourbar", out, ROOT, "work-precision of the free four-bar"),
        "Error against CPU time of mbd2d's dynamics methods on a free four-bar (10 s), with "
        "Exudyn's generalized-alpha for comparison.\n",
        table(("target", "measured", "met"), rows)])
