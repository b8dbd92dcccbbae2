"""Straight-line synthesis: a four-bar whose coupler point traces an approximate straight
line over 60 degrees of crank (the classical Chebyshev / Watt task), found by
``mbd2d.synthesize`` and checked by an ordinary kinematic run.

1. Start from Hoeken's proportions (ground 2, crank 1, rocker 2.5, coupler 2.5 extended to
   a tracer point 5 from the crank pin), whose coupler curve has a long nearly-flat part.
2. Targets: seven equally spaced points on the line through the flattest 60-degree part of
   that curve; free timing (the seven crank angles are unknowns, in order, within 60
   degrees), crank-rocker Grashof type, transmission angle at least 30 degrees.
3. Synthesize (pivots, link lengths, tracer point), then run the designed model over a full
   crank turn: straightness (largest distance from the line) before and after.

Writes ``synthesis_straight_line.png`` (targets, coupler curves, the mechanism at five crank
angles) and, when the results can animate (``res.animate``), ``synthesis_straight_line.gif``
to ``examples/output/``.

    python examples/synthesis_straight_line.py [--out DIR] [--starts K] [--max-nfev N]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import mbd2d
from mbd2d.synthesis import Grashof, PathTask, TransmissionAngle, fourbar

HERE = Path(__file__).resolve().parent
SPAN = math.pi / 3               # 60 degrees of crank
FREE = ["joint.O2.points.0.0", "joint.O2.points.0.1", "joint.O4.points.0.0",
        "joint.O4.points.0.1", "joint.A.points.0.0", "joint.B.points.0.0",
        "joint.B.points.1.0", "path.point.0", "path.point.1"]


def flattest_line(curve: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Seven equally spaced points on the straight line through the flattest 60-degree part
    of a closed coupler curve (sampled at crank angles t over one turn); the part's start
    angle and its straightness (largest distance from its chord line)."""
    n = len(t) - 1
    w = int(round(n * SPAN / (2 * math.pi)))
    best = (math.inf, 0)
    for i in range(n):
        seg = curve[(i + np.arange(w + 1)) % n]
        dev = line_deviation(seg)
        if dev < best[0]:
            best = (dev, i)
    seg = curve[(best[1] + np.arange(w + 1)) % n]
    c, u = fit_line(seg)
    s = (seg - c) @ u
    targets = c + np.linspace(s.min(), s.max(), 7)[:, None] * u
    return targets, float(t[best[1]]), best[0]


def fit_line(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares line through points: centre and unit direction."""
    c = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - c)
    return c, vt[0]


def line_deviation(points: np.ndarray) -> float:
    """Largest distance of points from their least-squares line."""
    c, u = fit_line(points)
    d = points - c
    return float(np.abs(d[:, 0] * u[1] - d[:, 1] * u[0]).max())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "output")
    ap.add_argument("--starts", type=int, default=4)
    ap.add_argument("--max-nfev", type=int, default=200, help="evaluations per local solve")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    # 1. Hoeken's linkage and its coupler curve (an ordinary kinematic run)
    start = fourbar([[0.0, 0.0], [2.0, 0.0]], crank=1.0, coupler=2.5, rocker=2.5)
    point = (5.0, 0.0)
    t = np.linspace(0.0, 2 * math.pi, 721)
    kin0 = start.kinematics(t_end=t[-1], steps=len(t) - 1)
    curve0 = kin0.point("coupler", point)

    # 2. the task: seven points on the line through its flattest 60 degrees
    targets, t_flat, dev0 = flattest_line(curve0, t)
    task = PathTask("coupler", point, targets, span=(0.0, 2 * math.pi), max_span=SPAN,
                    cycle=2 * math.pi)
    ext = 6.0
    bounds = {n: (-ext, ext) for n in FREE[:4]}
    bounds.update({n: (0.2, 8.0) for n in FREE[4:7]})
    bounds.update({"path.point.0": (-8.0, 8.0), "path.point.1": (-8.0, 8.0)})

    # 3. synthesis
    res = mbd2d.synthesize(start, FREE, task, bounds=bounds, starts=args.starts,
                           max_nfev=args.max_nfev,
                           constraints=[Grashof("crank-rocker"),
                                        TransmissionAngle(min_deg=30.0)])
    best = res.model
    tracer = (res.values["path.point.0"], res.values["path.point.1"])
    t1 = np.linspace(0.0, 2 * math.pi, 721)
    kin1 = best.kinematics(t_end=t1[-1], steps=len(t1) - 1)
    curve1 = kin1.point("coupler", tracer)
    on = (t1 >= res.times[0] - 1e-12) & (t1 <= res.times[-1] + 1e-12)
    dev1 = line_deviation(curve1[on])
    length = float(np.hypot(*(targets[-1] - targets[0])))
    print(f"straight line over {math.degrees(res.times[-1] - res.times[0]):.1f} degrees of "
          f"crank, length {length:.4g}:")
    print(f"  Hoeken start: flattest 60 degrees deviate {dev0:.3e} from a line "
          f"({dev0 / length:.2e} of its length)")
    print(f"  synthesized:  error {res.error:.3e} (sum of squared target distances), largest "
          f"distance from the line {dev1:.3e} ({dev1 / length:.2e} of its length)")
    print(f"  transmission angle >= {res.terms.get('TransmissionAngle', float('nan')):.1f} deg;"
          f" {len(res.history)} local solves, {len(res.rejected)} candidates rejected "
          f"({', '.join(f'{k} x{n}' for k, n in res.defect_reasons.items()) or 'none'}), "
          f"{res.seconds:.1f} s")
    for n, v in res.values.items():
        print(f"  {n:22s} {v: .6f}")

    files = [picture(args.out / "synthesis_straight_line.png", targets, curve0, curve1, on,
                     kin1, tracer, res)]
    if hasattr(kin1, "animate"):     # the animation of issue 12, when the results have it
        gif = args.out / "synthesis_straight_line.gif"
        kin1.animate(str(gif), trace=[("coupler", tracer)])
        files.append(gif)
    print("wrote " + ", ".join(str(f) for f in files))
    return 0 if dev1 < dev0 and res.error < 1e-2 * length**2 else 1


def picture(path: Path, targets: np.ndarray, curve0: np.ndarray, curve1: np.ndarray,
            on: np.ndarray, kin: mbd2d.KinematicsResult, tracer: tuple[float, float],
            res: mbd2d.SynthesisResult) -> Path:
    """Targets, coupler curves (start and design) and the designed mechanism at five crank
    angles."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 6), dpi=110)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(curve0[:, 0], curve0[:, 1], color="0.7", lw=1, label="Hoeken start: coupler curve")
    ax.plot(curve1[:, 0], curve1[:, 1], color="C0", lw=1, label="synthesized: coupler curve")
    ax.plot(curve1[on, 0], curve1[on, 1], color="C2", lw=4, zorder=4,
            label="the 60-degree stroke")
    ax.plot(targets[:, 0], targets[:, 1], "o", color="C3", ms=4, zorder=5, label="targets")
    j = {c.name: c for c in res.model.joints}
    o2, o4 = np.array(j["O2"].points[0]), np.array(j["O4"].points[0])
    idx = np.linspace(0, len(kin.t) - 1, 6).astype(int)[:-1]
    for k, i in enumerate(idx):
        a = kin.point("crank", j["A"].points[0])[i]
        b = kin.point("coupler", j["B"].points[0])[i]
        p = kin.point("coupler", tracer)[i]
        alpha = 1.0 if k == 0 else 0.35
        ax.plot(*np.array([o2, a]).T, "-o", color="k", alpha=alpha, ms=4)
        ax.fill(*np.array([a, b, p]).T, color="C1", alpha=0.25 * alpha)
        ax.plot(*np.array([a, b, p, a]).T, "-", color="C1", alpha=alpha)
        ax.plot(*np.array([b, o4]).T, "-o", color="k", alpha=alpha, ms=4)
    ax.plot(*np.array([o2, o4]).T, "^", color="k", ms=10, label="ground pivots")
    ax.set_aspect("equal")
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"Straight-line four-bar by mbd2d.synthesize: error {res.error:.2e}")
    fig.savefig(path)
    return path


if __name__ == "__main__":
    sys.exit(main())
