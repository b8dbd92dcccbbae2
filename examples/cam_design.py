"""A disc cam synthesized from its follower's program (examples/tasks/cam.toml), then run.

The program rises 20 mm over the first quarter turn by the cycloidal law, dwells, returns by
the 3-4-5 polynomial over the third quarter and dwells; mbd2d.cam_profile gives the cam's
surface for a 10 mm roller on a 50 mm base circle with its axis 5 mm off centre, and the
cam joint of the engine then turns it: the follower's lift must equal the program.

Usage::

    python examples/cam_design.py [--out DIR]

Writes cam_design_mechanism.png (snapshots with the roller's path), cam_design_program.png
(lift, pressure angle and radius of curvature over the turn) and cam_design.gif to DIR
(default examples/output/). Exit code 0 when the follower keeps the program to 1e-9 m.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import mbd2d
from mbd2d.plots import plot_mechanism
from mbd2d.synthesis import CamDesign, cam_report, load_cam

HERE = Path(__file__).resolve().parent
TASK = HERE / "tasks" / "cam.toml"
#: largest accepted |lift - program| [m]
LIFT_TOL = 1e-9


def program_figure(d: CamDesign, res: mbd2d.KinematicsResult, path: Path) -> None:
    """Lift (the program and the engine's follower), pressure angle, radius of curvature."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    deg = np.degrees(d.theta)
    fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    a1.plot(deg, 1e3 * d.s, lw=2.5, color="0.75", label="program s(theta)")
    fol = res.body("follower")
    a1.plot(np.degrees(res.body("cam").theta), 1e3 * (fol.y - fol.y[0]), "k--", lw=1,
            label="follower moved by the cam joint")
    a1.set_ylabel("lift [mm]")
    a1.legend(loc="upper right")
    a2.plot(deg, np.degrees(d.pressure_angle), lw=1.5)
    a2.axhline(30, color="r", lw=0.8, ls=":")
    a2.axhline(-30, color="r", lw=0.8, ls=":", label="30 deg (a usual limit)")
    a2.set_ylabel("pressure angle [deg]")
    a2.legend(loc="upper right")
    a3.plot(deg, 1e3 * d.curvature_radius, lw=1.5)
    a3.set_ylim(-100, 150)
    a3.set_ylabel("radius of curvature [mm]")
    a3.set_xlabel("cam angle [deg]")
    a1.set_title("cam synthesized from its program (mbd2d.cam_profile)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(out: Path) -> tuple[str, mbd2d.KinematicsResult, list[str]]:
    """Synthesize, run one turn, draw; (problem or "", the run, the files written)."""
    design, model = load_cam(TASK)
    print(cam_report(design))
    n = len(design.theta)
    res = model.kinematics(t_end=1.0, steps=n)       # 2 pi rad/s: an output per sample
    lift = res.body("follower").y - res.body("follower").y[0]
    err = float(np.abs(lift[:-1] - design.s).max())
    print(f"the engine's follower against the program at the {n} profile points: largest "
          f"difference {err:.2e} m (between them the spline's error, 6e-11 m here: "
          "docs/synthesis.md)")
    out.mkdir(parents=True, exist_ok=True)
    files = []
    ax = plot_mechanism(res, times=[0.0, 0.125, 0.25, 0.5, 0.625],
                        trace=[("follower", (0.0, 0.0))])
    ax.set_title("cam and follower, snapshots at 0, 45, 90, 180, 225 deg")
    ax.figure.savefig(out / "cam_design_mechanism.png", dpi=110)
    files.append(str(out / "cam_design_mechanism.png"))
    program_figure(design, res, out / "cam_design_program.png")
    files.append(str(out / "cam_design_program.png"))
    files.append(str(model.kinematics(1.0, 90).animate(out / "cam_design.gif", fps=30,
                                                         speed=1.0)))
    problem = "" if err < LIFT_TOL and not design.undercut else \
        f"the follower is {err:.2e} m off its program"
    return problem, res, files


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE / "output")
    args = ap.parse_args(argv)
    problem, _, files = run(args.out)
    print("wrote " + ", ".join(Path(f).name for f in files) + f" in {args.out}")
    if problem:
        print(f"unexpected: {problem}")
    return 1 if problem else 0


if __name__ == "__main__":
    sys.exit(main())
