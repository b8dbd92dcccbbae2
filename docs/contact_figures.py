"""The figures and numbers of docs/contact.md: the laws' effective restitution (one-degree-of-
freedom reference and mbd2d), the clearance-joint crank-slider against the ideal joint, the
cam follower lifting off. Writes docs/img/contact_*.png and prints the numbers (about 20 s).

    python docs/contact_figures.py
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE.parent / "examples"))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import mbd2d  # noqa: E402
from test_clearance import (L1, L2, OMEGA, RB, RJ, crank_slider, ideal_acc,  # noqa: E402
                            moving_average)
from test_contact import ball, bounce_reference  # noqa: E402

IMG = HERE / "img"


def restitution_table() -> None:
    print("| law | e requested | e of the law (1-DOF reference) | mbd2d ball drop |")
    for law in ("hunt-crossley", "lankarani-nikravesh", "flores"):
        for e in (0.1, 0.3, 0.5, 0.7, 0.9, 0.99):
            ref, _ = bounce_reference(law, e, 3.0, 1.0, g=0.0)
            res = ball(law, e, g=0.0, v0=3.0, h0=0.2).dynamics(0.2, 20, rtol=1e-10, atol=1e-13)
            on, off = res.contacts[0], res.contacts[1]
            print(f"| {law} | {e} | {ref / 3.0:.4f} | {off.speed / on.speed:.4f} |")


def clearance_figure() -> None:
    t_end = 0.024
    ideal = crank_slider(False).dynamics(t_end, 4800, rtol=1e-8, atol=1e-10)
    cl = crank_slider(True).dynamics(t_end, 4800, rtol=1e-8, atol=1e-10)
    t = cl.t
    acc = ideal_acc(t)
    a = cl.body("slider").x_ddot
    k = int(round(1e-3 / (t[1] - t[0])))
    c = cl.contact("B")
    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    ax[0].plot(t, a, lw=0.6, color="tab:blue", label="clearance joint")
    ax[0].plot(t, moving_average(a, k), lw=1.6, color="tab:orange",
               label="clearance joint, 1 ms moving average")
    ax[0].plot(t, acc, "k--", lw=1.2, label="ideal joint (closed form)")
    ax[0].set_ylim(-8 * np.abs(acc).max(), 8 * np.abs(acc).max())
    ax[0].set_ylabel("slider acceleration [m/s²]")
    ax[1].plot(t, c.normal_force, lw=0.8)
    ax[1].plot(t, np.hypot(ideal.reaction("B").fx, ideal.reaction("B").fy), "k--", lw=1.0,
               label="ideal joint's pin force")
    ax[1].set_yscale("symlog", linthresh=100)
    ax[1].set_ylabel("contact force [N]")
    pen = c.penetration
    ax[2].plot(t, 1e3 * (pen + (RB - RJ)), lw=0.8)
    ax[2].axhline(1e3 * (RB - RJ), color="k", lw=0.8, ls=":")
    ax[2].set_ylabel("eccentricity [mm]")
    ax[2].set_xlabel("t [s]")
    for e in cl.contacts:
        if e.kind == "onset" and e.speed > 0.1:
            ax[2].axvline(e.t, color="tab:red", lw=0.4, alpha=0.6)
    for x in ax:
        x.grid(True, lw=0.4, alpha=0.5)
    ax[0].legend(fontsize=8, loc="lower right")
    ax[1].legend(fontsize=8, loc="upper right")
    fig.suptitle("crank-slider with a clearance joint (Flores' setup), 5000 rpm: "
                 "red lines = impacts > 0.1 m/s")
    fig.tight_layout()
    fig.savefig(IMG / "contact_clearance.png", dpi=100)
    plt.close(fig)
    fa, fi = moving_average(a, k)[k:-k], moving_average(acc, k)[k:-k]
    on = [e for e in cl.contacts if e.kind == "onset"]
    closed = [(p.t, q.t) for p, q in zip(cl.contacts, cl.contacts[1:]) if p.kind == "onset"]
    print(f"clearance: {len(on)} onsets, {sum(1 for e in on if e.speed > 0.1)} impacts above "
          f"0.1 m/s, longest following {max(q - p for p, q in closed) * 1e3:.2f} ms, peak "
          f"|a| {np.abs(a).max():.3g} vs ideal {np.abs(acc).max():.3g} m/s², 1 ms average: "
          f"correlation {np.corrcoef(fa, fi)[0, 1]:.4f}, rms difference "
          f"{np.sqrt(np.mean((fa - fi) ** 2)) / np.abs(acc).max():.3f} of the ideal peak; "
          f"peak contact force {c.normal_force.max():.4g} N, ideal pin force max "
          f"{np.hypot(ideal.reaction('B').fx, ideal.reaction('B').fy).max():.4g} N; "
          f"steps {cl.stats['steps']} vs {ideal.stats['steps']}")


def liftoff_figure() -> None:
    import cam_liftoff
    cam_liftoff.main(["--out", str(IMG)])
    for kind in ("mechanism", "history"):
        (IMG / f"cam_liftoff_{kind}.png").rename(IMG / f"contact_liftoff_{kind}.png")


if __name__ == "__main__":
    IMG.mkdir(exist_ok=True)
    restitution_table()
    clearance_figure()
    liftoff_figure()
    print(f"mbd2d {mbd2d.__version__}; omega {OMEGA:.2f} rad/s, L1 {L1}, L2 {L2}; "
          f"pi {math.pi:.3f}")
