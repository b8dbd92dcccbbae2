"""The figure and numbers of docs/motion.md: the six motion laws' displacement, velocity and
acceleration over a rise (a slider driven through each, one core run per law). Writes
docs/img/motion_laws.png and prints each law's largest velocity and acceleration in units
of h/T and h/T^2 (a few seconds).

    python docs/motion_figures.py
"""
from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

import mbd2d
from mbd2d.description.functions import LAWS

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).resolve().parent


def rise(law: str, steps: int = 2000) -> mbd2d.KinematicsResult:
    """A unit rise over one second: x(t) = L(t) of the law."""
    m = mbd2d.Model(f"rise-{law}")
    m.add_body("s", q0=[0.0, 0.0, 0.0])
    m.add_translational(["ground", "s"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="g")
    m.add_driver("absolute", body="s", coordinate="x",
                 f={"step": {"t0": 0.0, "t1": 1.0, "h": 1.0, "law": law}})
    return m.kinematics(1.0, steps)


def main() -> None:
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    print("| law | largest velocity (h/T) | largest acceleration (h/T^2) |")
    print("|---|---|---|")
    for law in LAWS:
        res = rise(law)
        x, v, a = res.q[:, 0], res.qd[:, 0], res.qdd[:, 0]
        for ax, y in zip(axes, (x, v, a)):
            ax.plot(res.t[:-1], y[:-1], label=law)
        print(f"| {law} | {np.abs(v).max():.4f} | {np.abs(a[:-1]).max():.4f} |")
    for ax, name in zip(axes, ("L (displacement / h)", "L' (velocity, h/T)",
                               "L'' (acceleration, h/T^2)")):
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("u = (t - t0)/(t1 - t0)")
    axes[0].set_title("motion laws of a step (a rise of h over T)")
    fig.tight_layout()
    out = HERE / "img" / "motion_laws.png"
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
