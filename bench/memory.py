"""Peak memory of long runs: 10^6 output steps, all rows kept (every=1) or every 1000th.

Each case runs in a fresh Python process (``python bench/memory.py --child CASE``): after
``import mbd2d`` and loading the model it reads its resident set size (the baseline), resets
the kernel's high-water mark (``echo 5 > /proc/self/clear_refs``) and runs; the figure is the
peak resident set size of the run (VmHWM, what resource.getrusage reports as ru_maxrss)
minus the baseline: the memory the run itself needed at its peak (output arrays, the core's
work arrays and the copies the Python front end makes). The reset matters: a process started
by fork + exec inherits the parent's high-water mark in ru_maxrss, which would hide the run.
Without /proc (not Linux) the child falls back to ru_maxrss before and after.

Cases:

* kinematics of the four-bar (examples/fourbar_grashof.toml), 10^6 steps over 1000 s
  (h = 1 ms, the crank turning 1 rev/s);
* dynamics of the free four-bar (bench/models.free_fourbar), 10^6 output steps over 1000 s,
  dopri5 at its default tolerances (rtol 1e-6, atol 1e-8; the outputs are dense-output
  interpolants, so the run takes a few seconds).

Each with every=1 and every=1000; ``every`` is a keyword of Model.kinematics and
Model.dynamics in recent mbd2d versions, and a case whose keyword is missing is recorded as
unavailable.

    python bench/memory.py [--out DIR] [--steps N]

writes DIR/memory.json and DIR/memory.png (DIR defaults to bench/results).
"""
from __future__ import annotations

import argparse
import inspect
import json
import resource
import subprocess
import sys
import time
import warnings
from pathlib import Path
from typing import Any, Sequence

BENCH = Path(__file__).resolve().parent
EXAMPLES = BENCH.parent / "examples"
STEPS = 1_000_000
T_END = 1000.0
EVERY = (1, 1000)
ANALYSES = ("kinematics", "dynamics")
CHILD_TIMEOUT_S = 240

Row = dict[str, Any]


# ===================================================================== child process
def maxrss_mib() -> float:
    """Peak resident set size of this process so far (MiB; ru_maxrss is in KiB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def proc_status_mib(field: str) -> float | None:
    """A /proc/self/status field in MiB (VmRSS: now, VmHWM: peak), or None without /proc."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        return None
    return None


def reset_peak() -> bool:
    """Reset the peak RSS (VmHWM) to the current RSS; False where that is not possible."""
    try:
        with open("/proc/self/clear_refs", "w", encoding="ascii") as f:
            f.write("5")
    except OSError:
        return False
    return proc_status_mib("VmHWM") is not None


def accepts(func: Any, name: str) -> bool:
    """Whether `func` has a keyword parameter `name`."""
    return name in inspect.signature(func).parameters


def load_case(analysis: str) -> Any:
    """The model of one analysis (imports mbd2d)."""
    import mbd2d
    if analysis == "kinematics":
        return mbd2d.load(EXAMPLES / "fourbar_grashof.toml")
    sys.path.insert(0, str(BENCH))
    from models import free_fourbar
    return free_fourbar()


def run_case(model: Any, analysis: str, steps: int, every: int) -> Any:
    """One long run; `every` is passed only when it is not 1."""
    kw: dict[str, Any] = {} if every == 1 else {"every": every}
    if analysis == "kinematics":
        return model.kinematics(t_end=T_END * steps / STEPS, steps=steps, **kw)
    return model.dynamics(t_end=T_END * steps / STEPS, steps=steps, method="dopri5", **kw)


def child(analysis: str, every: int, steps: int) -> Row:
    """Run one case in this process and measure it (see the module docstring)."""
    import mbd2d
    model = load_case(analysis)
    method = getattr(mbd2d.Model, analysis)
    if every != 1 and not accepts(method, "every"):
        return {"available": False,
                "message": f"Model.{analysis} has no every= keyword in this mbd2d version"}
    inherited = maxrss_mib()
    reset = reset_peak()
    base = proc_status_mib("VmRSS") if reset else inherited
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.errors.MbdWarning)
        res = run_case(model, analysis, steps, every)
    seconds = time.perf_counter() - t0
    peak = proc_status_mib("VmHWM") if reset else maxrss_mib()
    rows = int(len(res.t))
    return {"available": True, "baseline_mib": base, "peak_mib": peak,
            "run_mib": peak - base, "seconds": seconds, "rows": rows,
            "kept_data_mib": rows * (1 + 3 * res.q.shape[1]) * 8 / 2 ** 20,
            "peak_source": "VmHWM after clear_refs" if reset else "ru_maxrss",
            "ru_maxrss_before_mib": inherited, "ru_maxrss_after_mib": maxrss_mib()}


# ===================================================================== parent
def measure(analysis: str, every: int, steps: int = STEPS) -> Row:
    """Run one case in a fresh subprocess; its row (or the failure)."""
    row: Row = {"analysis": analysis, "every": every, "steps": steps}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", analysis,
           "--every", str(every), "--steps", str(steps)]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=CHILD_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        row.update(available=True, message=f"timed out after {CHILD_TIMEOUT_S} s")
        return row
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if p.returncode != 0 or not lines:
        tail = (p.stderr.strip().splitlines() or ["(no output)"])[-1]
        row.update(available=True, message=f"exit {p.returncode}: {tail[:200]}")
        return row
    row.update(json.loads(lines[-1]))
    return row


def memory(steps: int = STEPS, log: bool = True) -> dict:
    """Every case (analysis x every) in its own subprocess.

    Parameters
    ----------
    steps : int
        Output steps of each run (10^6 by default; t_end scales with it, h stays 1 ms).
    log : bool
        Print each row.

    Returns
    -------
    dict
        {"method", "rows"}; a row has analysis, every, steps, available and, when it ran,
        baseline_mib, peak_mib, run_mib, seconds, rows, kept_data_mib (or a message).
    """
    rows = []
    for analysis in ANALYSES:
        for every in EVERY:
            row = measure(analysis, every, steps)
            rows.append(row)
            if log:
                print("  " + format_row(row), flush=True)
    return {"method": "Peak RSS of the run in a fresh process (VmHWM, reset after import "
                      "mbd2d and model load) minus the RSS after import and load",
            "kinematics_case": f"examples/fourbar_grashof.toml, {steps} steps over "
                               f"{T_END * steps / STEPS:g} s",
            "dynamics_case": f"bench/models.free_fourbar, dopri5 (rtol 1e-6, atol 1e-8), {steps} "
                             f"output steps over {T_END * steps / STEPS:g} s",
            "rows": rows}


def format_row(row: Row) -> str:
    """One printed line."""
    head = f"{row['analysis']:10s} every={row['every']:<5d}"
    if row.get("run_mib") is None:
        return f"{head} {'unavailable' if not row.get('available') else 'FAILED'}: " \
               f"{row.get('message', '')}"
    return (f"{head} run {row['run_mib']:8.1f} MiB (peak {row['peak_mib']:.1f}, baseline "
            f"{row['baseline_mib']:.1f}), {row['rows']} rows kept, {row['seconds']:.2f} s")


def chart(data: dict, path: str | Path) -> Path:
    """Bar chart of the run's peak memory per case (log scale).

    Parameters
    ----------
    data : dict
        The output of memory().
    path : str or Path
        The PNG to write.

    Returns
    -------
    Path
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 3.6))
    labels, values, colours = [], [], []
    for r in data["rows"]:
        labels.append(f"{r['analysis']}\nevery={r['every']}")
        values.append(max(r.get("run_mib") or 0.0, 0.05))
        colours.append("lightgrey" if r.get("run_mib") is None
                       else "tab:blue" if r["every"] == 1 else "tab:green")
    bars = ax.bar(range(len(values)), values, color=colours)
    for b, r in zip(bars, data["rows"]):
        text = f"{r['run_mib']:.1f} MiB" if r.get("run_mib") is not None else \
            ("not available" if not r.get("available", True) else "failed")
        ax.annotate(text, (b.get_x() + b.get_width() / 2, b.get_height()), ha="center",
                    fontsize=8, textcoords="offset points", xytext=(0, 2))
    ax.set_xticks(range(len(values)), labels, fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("peak memory of the run (MiB)")
    ax.set_title(f"Memory of {data['rows'][0]['steps']:,} output steps", fontsize=10)
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def main(argv: Sequence[str] | None = None) -> dict | None:
    """Parent: run every case, write DIR/memory.json and memory.png. Child: one case."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(BENCH / "results"), help="output directory")
    ap.add_argument("--steps", type=int, default=STEPS)
    ap.add_argument("--child", choices=ANALYSES, help=argparse.SUPPRESS)
    ap.add_argument("--every", type=int, default=1, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        print(json.dumps(child(a.child, a.every, a.steps)))
        return None
    data = memory(a.steps)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "memory.json").write_text(json.dumps(data, indent=1), encoding="utf-8")
    chart(data, out / "memory.png")
    print(f"wrote {out / 'memory.json'} and memory.png")
    return data


if __name__ == "__main__":
    main()
