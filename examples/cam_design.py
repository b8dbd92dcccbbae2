"""A disc cam synthesized from its follower's program (examples/tasks/cam.toml), then run.

The program rises 20 mm over the first quarter turn by the cycloidal law, dwells, returns by
the 3-4-5 polynomial over the third quarter and dwells; mbd2d.cam_profile gives the cam's
surface for a 10 mm roller on a 50 mm base circle with its axis 5 mm off centre, and the
cam joint of the engine then turns it: the follower's lift must equal the program.

Usage::

    python examples/cam_design.py [--out DIR]

Writes cam_design_mechanism.png (snapshots with the roller's path), cam_design_program.png
(lift, pressure angle and radius of curvature over the turn), cam_design_base_radius.png (the
largest pressure angle and the smallest radius of curvature against the base radius: the
design chart) and cam_design.gif to DIR (default examples/output/). Exit code 0 when the
follower keeps the program to 1e-9 m.
"""
from __future__ import annotations

import argparse
import math
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


def base_radius_figure(design: CamDesign, path: Path) -> float:
    """The classic design chart: the largest pressure angle and the smallest radius of
    curvature against the base radius (the same program, follower and offset); returns the
    smallest base radius that keeps the pressure angle within 30 degrees."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    radii = np.linspace(0.02, 0.1, 33)
    designs = [mbd2d.cam_profile(design.program, rb, roller_radius=design.roller_radius,
                                 offset=design.offset, points=360) for rb in radii]
    phi = np.degrees([d.max_pressure_angle for d in designs])
    rho = np.array([d.min_curvature_radius for d in designs])
    ok = radii[phi <= 30.0]
    smallest = float(ok.min()) if ok.size else math.nan
    fig, a1 = plt.subplots(figsize=(8, 4.5))
    a1.plot(1e3 * radii, phi, "o-", ms=3, label="largest pressure angle")
    a1.axhline(30, color="r", lw=0.8, ls=":")
    a1.axvline(1e3 * design.base_radius, color="k", lw=0.8, ls="--",
               label=f"this design ({1e3 * design.base_radius:g} mm)")
    a1.set_xlabel("base radius [mm]")
    a1.set_ylabel("largest pressure angle [deg]")
    a2 = a1.twinx()
    a2.plot(1e3 * radii, 1e3 * rho, "s-", ms=3, color="tab:green",
            label="smallest radius of curvature")
    a2.set_ylabel("smallest radius of curvature [mm]", color="tab:green")
    a1.legend(loc="upper center")
    a1.set_title(f"pressure angle within 30 deg from a {1e3 * smallest:.1f} mm base radius")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return smallest


def run(out: Path) -> tuple[str, mbd2d.KinematicsResult, list[str]]:
    """Synthesize, run one turn, draw; (problem or "", the run, the files written)."""
    design, model, speed = load_cam(TASK)
    print(cam_report(design, speed))
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
    smallest = base_radius_figure(design, out / "cam_design_base_radius.png")
    files.append(str(out / "cam_design_base_radius.png"))
    print(f"the pressure angle stays within 30 deg from a base radius of {1e3 * smallest:.1f} "
          f"mm (this design: {1e3 * design.base_radius:g} mm)")
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
