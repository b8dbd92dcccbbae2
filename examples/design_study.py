"""Design study of a crank-rocker (examples/fourbar_grashof.toml: crank 1, coupler 3.5,
rocker 2.5, ground 3): a sweep of the coupler length, the exact sensitivities of the rocker
angle to every link length, and a tolerance analysis of a coupler point.

1. ``mbd2d.sweep`` runs 200 coupler lengths from 1.0 to 5.0 in batched core calls, positions
   only (``positions_only=True``: the curves need no velocities, so chord steps). Below
   1.5 the crank can no longer turn fully (the variant stops at a dead centre; its rows up to
   there are kept), above 4.5 the loop cannot close at the start. The coupler curves of the
   whole family are drawn, the variants that hit a dead centre marked where they stopped, and
   each variant's worst transmission angle (``measures=["transmission_angle:B"]``, computed
   by the core for every case at its own dimensions) against the 40 deg rule of thumb and
   the law of cosines at the crank's two dead positions.
2. ``model.kinematics(..., sensitivities=[...])`` gives d(rocker angle)/d(link length) over
   the cycle for the four links, from the differentiated constraint equations, and the
   exact gradient of the design criterion itself: d(worst transmission angle)/d(link
   length) from ``res.transmission_angle_dp`` at the worst row, against the law of cosines
   differentiated.
3. ``mbd2d.tolerance`` propagates a scatter of the link lengths (sigma = 1 mm on metres)
   into a coupler point's position along the cycle, first-order and by Monte Carlo, and
   splits the point's variance among the links (``x_share``, ``y_share``: which tolerance
   to tighten first).

Usage::

    python examples/design_study.py [--out DIR] [--variants N] [--samples N]

Writes ``design_study_curves.png``, ``design_study_sensitivity.png`` and
``design_study_tolerance.png`` to DIR (default ``examples/output/``). Needs the ``sweep``
extra (``pip install 'mbd2d[sweep]'``) and matplotlib. Exit code 0 when the study came out
as expected.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import mbd2d

HERE = Path(__file__).resolve().parent
COUPLER = "joint.B.points.0.0"        # x of B in the coupler frame: coupler length - 1.75
A_ON_COUPLER = 1.75                   # A sits at x = -1.75 in the coupler frame
POINT = (0.0, 1.0)                    # the traced coupler point, in the coupler frame
#: each link's length grows one for one with its parameter
LINKS = {"crank": "joint.A.points.0.0", "coupler": COUPLER, "rocker": "joint.O4.points.0.0",
         "ground": "joint.O4.points.1.0"}
SIGMA = 1e-3
STEPS = 120                           # outputs per crank turn (1 s)
DEAD_CENTRE = 3                       # err.status of SingularConfigurationError


def coupler_point(q: np.ndarray, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The traced point's path from the coordinates (rows: times)."""
    i = names.index("coupler.x")
    th = q[..., i + 2]
    c, s = np.cos(th), np.sin(th)
    return (q[..., i] + c * POINT[0] - s * POINT[1], q[..., i + 1] + s * POINT[0] + c * POINT[1])


def figure(size: tuple[float, float]):
    """A matplotlib Figure on the Agg canvas (no window)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def draw_family(ds, out: Path) -> str:
    """Coupler curves of every variant, coloured by coupler length; dead centres marked."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    lengths = ds[COUPLER].values + A_ON_COUPLER
    names = [str(c) for c in ds.coordinate.values]
    x, y = coupler_point(ds.q.values, names)
    status = ds.status.values
    norm = Normalize(lengths.min(), lengths.max())
    cmap = colormaps["viridis"]
    fig = figure((16.0, 4.8))
    fig.get_layout_engine().set(wspace=0.12)
    ax, ax2, ax3 = fig.subplots(1, 3, width_ratios=[1.6, 1.0, 1.0])
    for j in np.flatnonzero(status == 0)[::2]:
        ax.plot(x[j], y[j], color=cmap(norm(lengths[j])), lw=0.8)
    dead = np.flatnonzero(status == DEAD_CENTRE)
    for k, j in enumerate(dead):
        ok = np.isfinite(x[j])
        ax.plot(x[j][ok], y[j][ok], color="#d62728", lw=0.6, alpha=0.6)
        ax.plot(x[j][ok][-1], y[j][ok][-1], "x", color="#d62728", ms=5,
                label="dead centre: where the variant stopped" if k == 0 else None)
    ax.plot([0.0, 3.0], [0.0, 0.0], "^", color="0.3", ms=9, label="ground pivots")
    ax.set_aspect("equal")
    ax.set_xlim(np.nanmin(x) - 0.2, 3.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"coupler point {POINT} of {len(lengths)} coupler lengths")
    ax.legend(loc="lower right", fontsize=8)
    fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="coupler length [m]")
    rocker = ds.q.sel(coordinate="rocker.theta").values
    rows = np.isfinite(rocker).any(axis=1)
    swing = np.zeros(len(lengths))
    swing[rows] = np.degrees(np.nanmax(rocker[rows], axis=1) - np.nanmin(rocker[rows], axis=1))
    full = status == 0
    ax2.plot(lengths[full], swing[full], ".", color="#1f77b4", ms=3, label="full crank turn")
    ax2.plot(lengths[status == DEAD_CENTRE], swing[status == DEAD_CENTRE], "x",
             color="#d62728", ms=4, label="dead centre (swing until there)")
    nofit = (status != 0) & (status != DEAD_CENTRE)
    ax2.plot(lengths[nofit], np.zeros(nofit.sum()), "|", color="0.4", ms=8,
             label="does not assemble")
    ax2.set_xlabel("coupler length [m]")
    ax2.set_ylabel("rocker swing [deg]")
    ax2.set_title("rocker swing per variant")
    ax2.legend(fontsize=8)
    worst = worst_transmission(ds)
    ax3.plot(lengths[full], worst[full], ".", color="#1f77b4", ms=3, label="full crank turn")
    ax3.plot(lengths[status == DEAD_CENTRE], worst[status == DEAD_CENTRE], "x",
             color="#d62728", ms=4, label="dead centre")
    ax3.axhline(40.0, color="0.5", ls="--", lw=0.8, label="40 deg")
    ax3.set_xlabel("coupler length [m]")
    ax3.set_ylabel("worst transmission angle [deg]")
    ax3.set_title("min(mu, 180 - mu) over the cycle")
    ax3.legend(fontsize=8)
    path = out / "design_study_curves.png"
    fig.savefig(path, dpi=110)
    return str(path)


def worst_transmission(ds) -> np.ndarray:
    """Each variant's smallest min(mu, 180 - mu) over its rows [deg] (NaN without rows)."""
    mu = np.degrees(ds.measures.sel(measure="transmission_angle:B").values)
    rows = np.isfinite(mu).any(axis=1)
    worst = np.full(len(mu), np.nan)
    worst[rows] = np.nanmin(np.minimum(mu[rows], 180.0 - mu[rows]), axis=1)
    return worst


def closed_form_worst(b: np.ndarray, a: float = 1.0, c: float = 2.5, d: float = 3.0
                      ) -> np.ndarray:
    """The crank-rocker's worst transmission angle [deg]: the extremes of mu are at the
    crank's positions along the ground line, cos mu = (b^2 + c^2 - (d -+ a)^2) / (2 b c)
    (law of cosines; Norton, Design of Machinery, ch. 4)."""
    lo = np.degrees(np.arccos((b * b + c * c - (d - a) ** 2) / (2 * b * c)))
    hi = np.degrees(np.arccos((b * b + c * c - (d + a) ** 2) / (2 * b * c)))
    return np.minimum(lo, 180.0 - hi)


def worst_gradient(res) -> tuple[float, np.ndarray]:
    """The worst min(mu, 180 - mu) of a run [deg] and its exact gradient over the links
    [deg/m] (the angle's derivatives at the worst row: the crank angle there is fixed)."""
    mu = res.transmission_angle("B")
    dev = np.minimum(mu, np.pi - mu)
    k = int(np.argmin(dev))
    sign = 1.0 if mu[k] <= np.pi / 2 else -1.0
    return float(np.degrees(dev[k])), np.degrees(sign * res.transmission_angle_dp("B")[k])


def closed_form_gradient(h: float = 1e-6) -> np.ndarray:
    """d(worst transmission angle)/d(crank, coupler, rocker, ground) [deg/m] by central
    differences of the law of cosines (closed_form_worst)."""
    base = np.array([1.0, 3.5, 2.5, 3.0])
    grad = []
    for k in range(4):
        e = np.zeros(4)
        e[k] = h
        hi, lo = base + e, base - e
        grad.append((closed_form_worst(np.array([hi[1]]), hi[0], hi[2], hi[3])[0]
                     - closed_form_worst(np.array([lo[1]]), lo[0], lo[2], lo[3])[0]) / (2 * h))
    return np.array(grad)


def draw_sensitivity(res, out: Path) -> str:
    """d(rocker angle)/d(link length) over the cycle."""
    fig = figure((7.5, 4.2))
    ax = fig.subplots()
    crank = np.degrees(2 * np.pi * res.t)
    for link, name in LINKS.items():
        ax.plot(crank, res.sensitivity("rocker", name)[:, 2], label=link)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("d(rocker angle) / d(link length) [rad/m]")
    ax.set_title("exact sensitivities of the rocker angle")
    ax.set_xlim(0, 360)
    ax.legend()
    path = out / "design_study_sensitivity.png"
    fig.savefig(path, dpi=110)
    return str(path)


def draw_tolerance(pt, tol, out: Path) -> str:
    """The coupler point's scatter along the cycle: first order against Monte Carlo."""
    fig = figure((15.0, 4.2))
    ax, ax2, ax3 = fig.subplots(1, 3, width_ratios=[1.4, 1.0, 1.2])
    crank = np.degrees(2 * np.pi * pt.time.values)
    for c, colour in (("x", "#1f77b4"), ("y", "#ff7f0e")):
        ax.plot(crank, 1e3 * pt[f"{c}_std_linear"].values, color=colour,
                label=f"{c}: first order (S Sigma S^T)")
        ax.plot(crank[::3], 1e3 * pt[f"{c}_std_mc"].values[::3], "o", ms=3.5, mfc="none",
                color=colour, label=f"{c}: Monte Carlo ({tol.dataset.attrs['samples']} variants)")
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("standard deviation [mm]")
    ax.set_xlim(0, 360)
    ax.set_title(f"coupler point {POINT}: link lengths sigma = {SIGMA * 1e3:g} mm each")
    ax.legend(fontsize=8)
    # the curve with the 3-sigma scatter drawn to scale (magnified 50x)
    x, y = pt.x.values, pt.y.values
    ax2.plot(x, y, color="0.3", lw=1)
    names = [str(c) for c in tol.samples.coordinate.values]
    ok = tol.samples.status.values == 0
    xs, ys = coupler_point(tol.samples.q.values[ok], names)
    k = np.arange(0, len(x) - 1, 10)
    mag = 50.0
    ax2.plot((x[k] + mag * (xs[:, k] - x[k])).ravel(), (y[k] + mag * (ys[:, k] - y[k])).ravel(),
             ".", ms=0.8, color="#2ca02c", alpha=0.4)
    ax2.set_aspect("equal")
    ax2.set_title(f"Monte Carlo scatter, magnified {mag:g}x")
    ax2.set_xlabel("x [m]")
    ax2.set_ylabel("y [m]")
    # which tolerance to tighten: each link's share of the point's position variance
    vx, vy = pt.x_std_linear.values ** 2, pt.y_std_linear.values ** 2
    share = (pt.x_share.values * vx[:, None] + pt.y_share.values * vy[:, None]) \
        / (vx + vy)[:, None]
    ax3.stackplot(crank, 100 * share.T, labels=list(LINKS), alpha=0.85)
    ax3.set_xlim(0, 360)
    ax3.set_ylim(0, 100)
    ax3.set_xlabel("crank angle [deg]")
    ax3.set_ylabel("share of the variance [%]")
    ax3.set_title("which link's tolerance the scatter comes from")
    ax3.legend(fontsize=8, loc="upper right")
    path = out / "design_study_tolerance.png"
    fig.savefig(path, dpi=110)
    return str(path)


def run(out: Path, variants: int = 200, samples: int = 500) -> tuple[str, list[str]]:
    """The whole study; (problem, files): problem is '' when it came out as expected."""
    out.mkdir(parents=True, exist_ok=True)
    model = mbd2d.load(HERE / "fourbar_grashof.toml")
    lengths = np.linspace(1.0, 5.0, variants)
    t0 = time.perf_counter()
    ds = mbd2d.sweep(model, {COUPLER: lengths - A_ON_COUPLER}, t_end=1.0, steps=STEPS,
                     positions_only=True, measures=["transmission_angle:B"])
    t_sweep = time.perf_counter() - t0
    status = ds.status.values
    dead = lengths[status == DEAD_CENTRE]
    print(f"design study: {variants} coupler lengths in {t_sweep:.2f} s: "
          f"{int((status == 0).sum())} turn fully, {len(dead)} hit a dead centre "
          f"(lengths {dead.min():.3f} .. {dead.max():.3f}), "
          f"{int(((status != 0) & (status != DEAD_CENTRE)).sum())} do not assemble"
          if len(dead) else f"design study: {variants} lengths, no dead centre")
    res = model.kinematics(1.0, STEPS, sensitivities=list(LINKS.values()))
    mu_worst, grad = worst_gradient(res)
    gerr = np.abs(grad - closed_form_gradient()).max()
    print(f"  worst transmission angle {mu_worst:.2f} deg; its exact gradient [deg/m]: "
          + ", ".join(f"{link} {g:+.2f}" for link, g in zip(LINKS, grad))
          + f" (law of cosines matched to {gerr:.1e})")
    tol = mbd2d.tolerance(model, {name: SIGMA for name in LINKS.values()}, samples=samples,
                          t_end=1.0, steps=STEPS)
    pt = tol.point("coupler", POINT)
    ratio = np.concatenate([pt.x_std_mc.values / pt.x_std_linear.values,
                            pt.y_std_mc.values / pt.y_std_linear.values])
    print(f"  tolerance of the coupler point (sigma {SIGMA * 1e3:g} mm per link): largest "
          f"std {1e3 * max(pt.x_std_linear.max(), pt.y_std_linear.max()):.2f} mm; Monte Carlo"
          f" / first order = {ratio.min():.3f} .. {ratio.max():.3f} over the cycle")
    files = [draw_family(ds, out), draw_sensitivity(res, out), draw_tolerance(pt, tol, out)]
    problems = []
    if not len(dead) or dead.max() > 1.5 + 1e-9:
        problems.append("expected dead centres for coupler lengths below 1.5 only")
    full = status == 0
    worst = worst_transmission(ds)
    err = np.abs(worst[full] - closed_form_worst(lengths[full])).max()
    good = lengths[full][worst[full] > 40.0]
    print(f"  worst transmission angle per variant: law of cosines matched to {err:.1e} deg; "
          f"40 deg or better for coupler lengths {good.min():.3f} .. {good.max():.3f}"
          if len(good) else "  no variant keeps the transmission angle above 40 deg")
    if err > 1e-8:
        problems.append("the worst transmission angles differ from the law of cosines")
    if gerr > 1e-6:
        problems.append("the worst angle's gradient differs from the law of cosines")
    if np.abs(ratio - 1).max() > 5 / np.sqrt(2 * (samples - 1)):
        problems.append("Monte Carlo and first order differ by more than the Monte Carlo error")
    return "; ".join(problems), files


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "output", help="directory for the PNGs")
    ap.add_argument("--variants", type=int, default=200, help="coupler lengths (default 200)")
    ap.add_argument("--samples", type=int, default=500, help="Monte Carlo variants")
    a = ap.parse_args(argv)
    problem, files = run(a.out, a.variants, a.samples)
    print("  wrote " + ", ".join(Path(f).name for f in files) + f" in {a.out}")
    if problem:
        print(f"  unexpected: {problem}")
    return 1 if problem else 0


if __name__ == "__main__":
    sys.exit(main())
