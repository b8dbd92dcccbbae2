"""A fast cam whose follower lifts off (examples/cam_liftoff.toml), with its pictures.

Forward dynamics of the follower-profile contact shows where the follower leaves the cam
and lands again (``res.contacts``); the inverse dynamics of the same cam as a bilateral cam
joint reports where that joint would have to pull the follower (``res.lift_off``, a
LiftOffWarning). The two agree: the follower leaves where the pull would begin.

Usage::

    python examples/cam_liftoff.py [--out DIR] [--rpm RPM]

Writes cam_liftoff_mechanism.png (snapshots, the contact bold while it touches) and
cam_liftoff_history.png (lift, contact force, the pull intervals) to DIR (default
examples/output/), and the animation cam_liftoff.gif (``res.animate``).
Exit code 0 when the first lift-off lies within 2 % of the cam's period after the first
pull of the bilateral joint.
"""
from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path

import numpy as np

import mbd2d
from mbd2d.plots import plot_mechanism

HERE = Path(__file__).resolve().parent
TOML = HERE / "cam_liftoff.toml"
BILATERAL = """
[[joint]]
name = "cam-joint"
type = "cam"
bodies = ["cam", "follower"]
profile = { circle = { center = [0.01, 0.0], radius = 0.04 } }
follower = { roller = { center = [0.0, 0.0], radius = 0.01 } }
"""


def models(rpm: float) -> tuple[mbd2d.Model, mbd2d.Model]:
    """The contact model and the bilateral one at a cam speed (rpm)."""
    omega = rpm * 2 * math.pi / 60
    text = TOML.read_text()
    text = text.replace("62.83185307179586", repr(omega))
    text = text.replace("0.6283185307179586", repr(0.01 * omega))
    return mbd2d.loads(text), mbd2d.loads(text.split("[[contact]]")[0] + BILATERAL)


def history_figure(res, inv, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    a1.plot(inv.t, 1e3 * inv.body("follower").y, "k--", lw=1, label="on the profile (cam joint)")
    a1.plot(res.t, 1e3 * res.body("follower").y, lw=1.6, label="follower (contact)")
    a1.set_ylabel("follower height [mm]")
    c = res.contact("roller")
    a2.plot(res.t, c.normal_force, lw=1.2, label="contact force")
    for x in inv.lift_off:
        for a in (a1, a2):
            a.axvspan(x.t_start, x.t_end, color="tab:red", alpha=0.12, lw=0)
    a2.axvspan(0, 0, color="tab:red", alpha=0.12, label="cam joint would pull")
    for e in res.contacts:
        a2.axvline(e.t, color="tab:green" if e.kind == "onset" else "tab:orange", lw=0.6)
    quiet = c.normal_force[res.t < 0.5 * inv.lift_off[0].t_start] if inv.lift_off else []
    if len(quiet):                       # the riding force; impact spikes run off the top
        a2.set_ylim(-0.1 * quiet.max(), 4.0 * quiet.max())
    a2.set_xlabel("t [s]")
    a2.set_ylabel("normal force [N]")
    for a in (a1, a2):
        a.grid(True, lw=0.4, alpha=0.5)
        a.legend(loc="upper right", fontsize=8)
    fig.suptitle("cam follower lifting off (lines: onsets green, separations orange)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "output")
    ap.add_argument("--rpm", type=float, default=600.0)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    contact, bilateral = models(args.rpm)
    period = 60.0 / args.rpm
    res = contact.dynamics(2 * period, 4000, rtol=1e-8, atol=1e-10)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.LiftOffWarning)
        inv = bilateral.inverse_dynamics(2 * period, 4000)
    print(f"cam at {args.rpm:g} rpm: {len(res.contacts)} contact events")
    for e in res.contacts[:8]:
        print(f"  t = {e.t:.6f} s  {e.kind:10s}  speed {e.speed:.4f} m/s")
    for x in inv.lift_off:
        print(f"  the cam joint would pull from t = {x.t_start:.6f} to {x.t_end:.6f} s "
              f"(strongest {x.min_force:.3f} N)")
    files = [args.out / "cam_liftoff_mechanism.png", args.out / "cam_liftoff_history.png"]
    ax = plot_mechanism(res, times=np.linspace(0.0, period, 7)[:-1])
    ax.figure.savefig(files[0], dpi=110)
    history_figure(res, inv, files[1])
    files.append(args.out / "cam_liftoff.gif")
    res.animate(files[-1])
    print("  wrote " + ", ".join(str(f) for f in files))
    seps = [e.t for e in res.contacts if e.kind == "separation"]
    if not inv.lift_off:
        return 0 if not seps else 1
    lag = seps[0] - inv.lift_off[0].t_start if seps else math.inf
    print(f"  first lift-off {lag * 1e3:+.3f} ms after the first pull")
    return 0 if 0.0 <= lag < 0.02 * period else 1


if __name__ == "__main__":
    sys.exit(main())
