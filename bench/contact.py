"""Cost of contacts (issue 13): the crank-slider of Flores' studies with a revolute clearance
joint between rod and slider, against the same crank-slider with an ideal joint, and
against the restitution coefficient; and the cost of contact pairs that are far apart (the
bounding test: they should cost little per step).

Every figure is a ratio to a baseline measured in the same run (the ideal joint; the model
without the far pairs), with the run time (best of ``repeats``) and the integrator's steps,
right-hand sides and events, so that the cost can be split into more steps and more work
per step.

    python bench/contact.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from typing import Any

import mbd2d

L1, L2 = 0.05, 0.12
RJ, RB = 0.0095, 0.0100
OMEGA = 5000 * 2 * math.pi / 60
K_HERTZ = 4 / (3 * 2 * (1 - 0.3**2) / 207e9) * math.sqrt(RJ * RB / (RB - RJ))
T_END = 2 * 2 * math.pi / OMEGA            # two crank turns
RESTITUTIONS = (0.99, 0.9, 0.7, 0.5, 0.3)
RTOL, ATOL = 1e-8, 1e-10


def crank_slider(e: float | None) -> mbd2d.Model:
    """Flores' crank-slider; e None: the ideal joint, else a clearance joint (Lankarani-
    Nikravesh law of restitution e)."""
    m = mbd2d.Model("crank-slider")
    m.add_body("crank", q0=[L1 / 2, 0, 0], mass=0.30, inertia=1e-4)
    m.add_body("rod", q0=[L1 + L2 / 2, 0, 0], mass=0.21, inertia=2.5e-4)
    m.add_body("slider", q0=[L1 + L2, 0, 0], mass=0.14, inertia=1e-4)
    m.add_revolute(["ground", "crank"], [[0, 0], [-L1 / 2, 0]], name="O")
    m.add_revolute(["crank", "rod"], [[L1 / 2, 0], [-L2 / 2, 0]], name="A")
    m.add_translational(["ground", "slider"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="guide")
    if e is None:
        m.add_revolute(["rod", "slider"], [[L2 / 2, 0], [0, 0]], name="B")
    else:
        m.add_contact("circle-in-circle", ["rod", "slider"],
                      circle=[{"center": [L2 / 2, 0], "radius": RJ},
                              {"center": [0, 0], "radius": RB}],
                      law={"model": "lankarani-nikravesh", "stiffness": K_HERTZ,
                           "exponent": 1.5, "restitution": e}, name="B")
    m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [0.0, OMEGA]},
                 name="motor")
    return m


def timed(model: mbd2d.Model, repeats: int, t_end: float = T_END,
          steps: int = 240) -> tuple[float, Any]:
    """Best wall time of repeats runs of dopri5, and the last result."""
    best, res = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = model.dynamics(t_end, steps, rtol=RTOL, atol=ATOL)
        best = min(best, time.perf_counter() - t0)
    return best, res


def row(label: str, seconds: float, res: Any, base: float | None) -> dict:
    s = res.stats
    return {"case": label, "seconds": seconds, "ratio": seconds / base if base else 1.0,
            "steps": s["steps"], "rejected": s["rejected_steps"],
            "rhs": s["rhs_evaluations"], "events": s.get("events", 0),
            "us_per_rhs": 1e6 * seconds / max(s["rhs_evaluations"], 1)}


def clearance(repeats: int = 3, quick: bool = False) -> dict:
    """The clearance joint against the ideal one, over the restitution."""
    base, res = timed(crank_slider(None), repeats)
    rows = [row("ideal joint", base, res, None)]
    for e in (RESTITUTIONS[1:3] if quick else RESTITUTIONS):
        sec, res = timed(crank_slider(e), repeats)
        rows.append(row(f"clearance, e = {e:g}", sec, res, base))
        print(f"  e = {e:4.2f}: {sec * 1e3:8.1f} ms ({sec / base:6.1f} x ideal), "
              f"{res.stats['steps']} steps, {res.stats.get('events', 0)} events", flush=True)
    return {"model": "Flores' crank-slider, clearance 0.5 mm, Lankarani-Nikravesh, 5000 rpm",
            "t_end": T_END, "rtol": RTOL, "atol": ATOL, "method": "dopri5",
            "repeats": repeats, "rows": rows}


def far_pairs(repeats: int = 3, quick: bool = False) -> dict:
    """A ball bouncing on a floor, with n extra contacts between fixed-far discs (never
    touching): the cost per right-hand side against n."""
    rows = []
    base = None
    for n in ((0, 20) if quick else (0, 10, 50, 200)):
        m = mbd2d.Model("far")
        m.add_body("ball", q0=[0, 1, 0], mass=1.0, inertia=0.004)
        law = {"model": "hunt-crossley", "stiffness": 1e7, "restitution": 0.8}
        m.add_contact("circle-line", ["ball", "ground"],
                      circle={"center": [0, 0], "radius": 0.1},
                      line={"point": [0, 0], "normal": [0, 1]}, law=law, name="floor")
        for k in range(n):
            m.add_contact("circle-circle", ["ball", "ground"],
                          circle=[{"center": [0, 0], "radius": 0.1},
                                  {"center": [10.0 + k, 5.0], "radius": 0.1}],
                          law=law, name=f"far{k}")
        sec, res = timed(m, repeats, t_end=1.0, steps=100)
        r = row(f"{n} far pairs", sec, res, base)
        if base is None:
            base = r["us_per_rhs"]
        r["per_rhs_ratio"] = r["us_per_rhs"] / base
        r["us_per_pair_per_rhs"] = (r["us_per_rhs"] - base) / n if n else None
        rows.append(r)
        print(f"  {n:4d} far pairs: {r['us_per_rhs']:7.2f} us per right-hand side "
              f"({r['per_rhs_ratio']:.2f} x)", flush=True)
    return {"model": "ball on a floor + n circle-circle contacts 10 m away", "rows": rows}


def study(repeats: int = 3, quick: bool = False) -> dict:
    """Both measurements (bench/run.py's contact section)."""
    return {"clearance": clearance(repeats, quick), "far_pairs": far_pairs(repeats, quick),
            "quick": quick}


def chart(data: dict, path: Any) -> Any:
    """Run time ratio to the ideal joint against restitution."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [r for r in data["clearance"]["rows"] if r["case"].startswith("clearance")]
    e = [float(r["case"].split("=")[1]) for r in rows]
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(e, [r["ratio"] for r in rows], "o-", label="run time / ideal joint")
    ax.plot(e, [r["steps"] / data["clearance"]["rows"][0]["steps"] for r in rows], "s--",
            label="steps / ideal joint")
    ax.set_xlabel("restitution e")
    ax.set_ylabel("ratio to the ideal joint")
    ax.set_yscale("log")
    ax.grid(True, which="both", lw=0.4, alpha=0.5)
    ax.legend()
    ax.set_title("clearance-joint crank-slider (dopri5, rtol 1e-8): cost")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    print(json.dumps(study(quick=a.quick), indent=1, default=float))
