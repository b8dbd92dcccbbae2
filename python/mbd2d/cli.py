"""The ``mbd2d`` command line.

    mbd2d kinematics MODEL.toml --t-end T --steps N --out OUT.csv|OUT.npz [--every K --solver S
                     --positions-only --sensitivities NAME,...]
    mbd2d inverse-dynamics MODEL.toml --t-end T --steps N --out OUT.csv [--every K --solver S]
    mbd2d dynamics MODEL.toml --t-end T --steps N --out OUT.csv [--method M --rtol R --atol A --h H
                   --max-steps S --solver S]
    mbd2d statics MODEL.toml [--t T --solver S] [--out OUT.csv]
    mbd2d modes MODEL.toml [--t T --count K --at-q0 --solver S] [--out MODES.csv
                --damped-out EIGEN.csv --picture MODE.png|MODE.gif --mode K | --damped-mode J]
    mbd2d frf MODEL.toml --input NAME ... --f START:STOP:NUM [--log --t T --at-q0 --solver S]
              [--out FRF.csv --picture BODE.png|ODS.gif --at HZ --body B
              --coordinate x|y|theta]
    mbd2d linearize MODEL.toml --input NAME ... [--t T --at-q0 --solver S --velocities
                    --efforts]
                    [--out SYS.csv]
    mbd2d sweep MODEL.toml --param NAME=START:STOP:NUM ... [--grid] --t-end T --steps N
                --out sweep.nc|sweep.csv [--analysis A --t0 T0 --every K --workers W
                --scheduler ADDRESS --positions-only --method M --rtol R --atol A --h H
                --input NAME --f START:STOP:NUM --log (--analysis frf)]
    mbd2d tolerance MODEL.toml --sigma NAME=STD ... --t-end T --steps N --out tol.csv|tol.nc
                    [--samples N --seed S --analysis A --point BODY:X,Y --workers W
                    --scheduler ADDRESS --method M --rtol R --atol A --h H
                    --input NAME --f START:STOP:NUM --log (--analysis frf)]
    mbd2d synthesize TASK.toml --out BEST.toml [--starts K --seed S --workers N]
    mbd2d cam TASK.toml --out MODEL.toml [--profile PROFILE.csv]
    mbd2d check MODEL.toml [--t T --tol TOL --out REPORT.csv]
    mbd2d parameters MODEL.toml [--match TEXT]
    mbd2d export MODEL.toml OUT.mbd [--analysis A] --t-end T --steps N [settings of A]
                 [--param NAME=START:STOP:NUM ... --grid]   (a sweep for mbd2d-solve)
    mbd2d plot MODEL.toml --t-end T --steps N --out FIG.png
               [--what mechanism|paths|time-series|forces|energy] [--analysis A] [--trace B:X,Y]
    mbd2d animate MODEL.toml --t-end T --steps N --out MOTION.gif|MOTION.mp4 [--fps F --speed S]

The result commands take optional columns: ``--energy`` (kinetic, potential, total energy,
drift), ``--multipliers``, ``--reactions`` and ``--efforts`` (need multipliers: inverse
dynamics, dynamics, statics, or kinematics of a model with masses; inverse-dynamics writes
the efforts unless ``--no-efforts``). ``export`` writes them into the file for mbd2d-solve.

``--measure SPEC`` (repeatable; kinematics, inverse-dynamics, dynamics, sweep, export) adds a
column per measure: ``transmission_angle:JOINT[:OUTPUT]``,
``velocity_ratio:INPUT:OUTPUT[:VIA]``, ``mechanical_advantage:INPUT:OUTPUT[:VIA]`` or
``dead_centre_distance`` (a sweep: each case's, from its own dimensions).

``--sensitivities NAME,...`` (kinematics, inverse-dynamics, statics, dynamics by dopri5 or
generalized-alpha, sweep, export) computes the design sensitivities with respect to the
named parameters (``mbd2d parameters MODEL`` lists them) and adds the columns
``d(COLUMN)/d(NAME)`` to the CSV (``dq_dp``, ``dqd_dp``, ``dqdd_dp`` arrays to an .npz).

``plot`` and ``animate`` run the analysis ``--analysis`` (default ``auto``: kinematics of a
driven model, with the inverse dynamics when every body has a mass; dynamics otherwise) and
draw it; a run that stops at a dead centre is drawn up to there (exit code 3).

Exit codes: 0 ok, 2 bad input, 3 singular configuration (partial output written),
4 other numerical failure (partial output written when there is any).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import textwrap
import warnings
from typing import Any, Sequence

import numpy as np

from . import plots
from .errors import (AnalysisError, InsufficientMemoryError, MbdError, MbdWarning, ModelError,
                     SingularConfigurationError)
from .model import Model, load
from .description import toml_io
from .results import StaticsResult
from .results.files import OUTPUTS, write_csv
from .synthesis import SynthesisResult, cam_report, load_cam, load_task, synthesize
from .studies.plan import MAX_CASES

EXIT_OK, EXIT_INPUT, EXIT_SINGULAR, EXIT_NUMERICAL = 0, 2, 3, 4
ANALYSES = ("auto", "kinematics", "inverse-dynamics", "dynamics")
PICTURES = ("mechanism", "paths", "time-series", "forces", "energy", "measures")
#: the endings of picture files and of animation files
PICTURE_ENDS = (".png", ".svg", ".pdf")
MOTION_ENDS = (".gif", ".mp4")


def _span(p: argparse.ArgumentParser) -> None:
    p.add_argument("model", help="model file (.toml)")
    p.add_argument("--t-end", type=float, required=True, help="final time")
    p.add_argument("--steps", type=int, required=True, help="output intervals (rows = steps + 1)")
    p.add_argument("--t0", type=float, default=0.0, help="start time (default 0)")


def _dynamics_settings(p: argparse.ArgumentParser) -> None:
    p.add_argument("--method", default=None,
                   help="dopri5 (default), generalized-alpha, baumgarte-rk4 or partitioned")
    p.add_argument("--rtol", type=float, default=None, help="relative tolerance (adaptive)")
    p.add_argument("--atol", type=float, default=None, help="absolute tolerance (adaptive)")
    p.add_argument("--h", type=float, default=None, help="fixed step (generalized-alpha, "
                   "baumgarte-rk4)")
    p.add_argument("--rho-inf", type=float, default=None, help="generalized-alpha rho_inf")
    p.add_argument("--alpha", type=float, default=None, help="Baumgarte alpha")
    p.add_argument("--beta", type=float, default=None, help="Baumgarte beta")
    p.add_argument("--max-steps", type=int, default=None, help="limit on the integrator's "
                   "steps, accepted and rejected (default 10000000)")


def _columns(p: argparse.ArgumentParser, energy: bool = True, efforts: bool = False) -> None:
    """The optional output columns."""
    if energy:
        p.add_argument("--energy", action="store_true",
                       help="columns kinetic, potential, energy, drift_position, drift_velocity")
    p.add_argument("--multipliers", action="store_true",
                   help="a column lambda.LABEL per row of Phi")
    p.add_argument("--reactions", action="store_true", help="columns NAME.fx, NAME.fy, "
                   "NAME.mz (on the first body) and NAME.fx_j, NAME.fy_j, NAME.mz_j per joint "
                   "and driver")
    p.add_argument("--efforts", action=argparse.BooleanOptionalAction, default=efforts,
                   help="a column NAME.effort per driver" + (" (default)" if efforts else ""))


def _outputs(args: argparse.Namespace) -> dict[str, bool]:
    return {k: bool(getattr(args, k, False)) for k in OUTPUTS if getattr(args, k, False)}


def _measures(p: argparse.ArgumentParser) -> None:
    p.add_argument("--measure", action="append", default=None, metavar="SPEC",
                   help="a measure column (repeatable): transmission_angle:JOINT[:OUTPUT], "
                   "velocity_ratio:INPUT:OUTPUT[:VIA], mechanical_advantage:INPUT:OUTPUT[:VIA] "
                   "or dead_centre_distance")


def _sensitivities(p: argparse.ArgumentParser) -> None:
    p.add_argument("--sensitivities", action="append", default=None, metavar="NAME,...",
                   help="design parameters (`mbd2d parameters MODEL` lists them): adds the "
                   "columns d(COLUMN)/d(NAME) for each (comma-separated, repeatable)")


def _sens_names(args: argparse.Namespace) -> list[str] | None:
    """The parameter names of --sensitivities (None without it)."""
    items = getattr(args, "sensitivities", None)
    if not items:
        return None
    names = [n.strip() for item in items for n in item.split(",") if n.strip()]
    if not names:
        raise ModelError("--sensitivities names no parameter; give NAME,NAME,... (`mbd2d "
                         "parameters MODEL` lists them)", "command line")
    return names


def _file_outputs(args: argparse.Namespace) -> dict[str, Any]:
    """The optional columns of a result file: --energy ... and the sensitivities'."""
    out: dict[str, Any] = dict(_outputs(args))
    if _sens_names(args):
        out["sensitivities"] = True
    if getattr(args, "measure", None):
        out["measures"] = list(args.measure)
    return out


def _picture_settings(p: argparse.ArgumentParser) -> None:
    p.add_argument("--analysis", default="auto", choices=ANALYSES,
                   help="auto (default): kinematics of a driven model (with the inverse "
                   "dynamics when it has masses), else dynamics")
    p.add_argument("--trace", action="append", default=None, metavar="BODY:X,Y",
                   help="draw the path of the point (X, Y) of BODY (repeatable)")
    p.add_argument("--forces", action="store_true",
                   help="draw the joints' reaction forces as arrows (needs masses)")
    p.add_argument("--length-unit", default="m", help="unit of length on the axes (default m)")
    p.add_argument("--dpi", type=int, default=None, help="dots per inch")
    _dynamics_settings(p)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mbd2d", description="Planar multibody analysis.")
    sub = ap.add_subparsers(dest="command", required=True)
    k = sub.add_parser("kinematics", help="kinematic analysis of a driven model")
    _span(k)
    k.add_argument("--out", required=True, help="output file, .csv or .npz")
    k.add_argument("--tol", type=float, default=None, help="Newton tolerance (default 1e-12)")
    k.add_argument("--every", type=int, default=1, help="write every k-th row (and the last)")
    k.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear solver (default auto: banded LU for large chains)")
    _sensitivities(k)
    _measures(k)
    k.add_argument("--positions-only", action="store_true",
                   help="positions alone, no velocities or accelerations (faster: chord steps)")
    _columns(k)
    i = sub.add_parser("inverse-dynamics", help="kinematics of a driven model with masses, "
                       "with driver efforts, multipliers and reactions")
    _span(i)
    i.add_argument("--out", required=True, help="output file, .csv or .npz")
    i.add_argument("--tol", type=float, default=None, help="Newton tolerance (default 1e-12)")
    i.add_argument("--every", type=int, default=1, help="write every k-th row (and the last)")
    _sensitivities(i)
    _measures(i)
    i.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear solver (default auto: banded LU for large chains)")
    _columns(i, efforts=True)
    d = sub.add_parser("dynamics", help="forward dynamics")
    _span(d)
    d.add_argument("--out", required=True, help="output file, .csv or .npz")
    _dynamics_settings(d)
    d.add_argument("--every", type=int, default=1, help="write every k-th row (and the last)")
    _sensitivities(d)
    _measures(d)
    d.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear algebra (default auto: band LU for large chains)")
    _columns(d)
    s = sub.add_parser("statics", help="static equilibrium and reactions")
    s.add_argument("model", help="model file (.toml) with masses")
    s.add_argument("--t", type=float, default=0.0, help="time at which loads and drivers are "
                   "taken (default 0)")
    s.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear algebra (default auto: band LU for large chains)")
    s.add_argument("--out", default=None, help="also write the equilibrium as CSV")
    _sensitivities(s)
    _columns(s, energy=False)
    o = sub.add_parser("modes", help="natural frequencies, damping and mode shapes about the "
                       "static equilibrium")
    o.add_argument("model", help="model file (.toml) with masses")
    _linear_point(o)
    o.add_argument("--count", type=int, default=None, help="only the lowest K modes")
    o.add_argument("--out", default=None, help="write the modes (frequencies, shapes) as CSV")
    o.add_argument("--damped-out", default=None, help="write the damped eigenvalues as CSV")
    o.add_argument("--picture", default=None, help="draw a mode: .png/.svg/.pdf (the "
                   "extremes) or .gif/.mp4 (one period)")
    o.add_argument("--mode", type=int, default=0, help="the mode drawn (default 0, the lowest)")
    o.add_argument("--damped-mode", type=int, default=None, metavar="J",
                   help="draw damped eigenvalue J's complex shape instead (each coordinate at "
                   "its own phase)")
    fr = sub.add_parser("frf", help="frequency response about the static equilibrium to "
                       "design parameters varied harmonically (Bode plot)")
    fr.add_argument("model", help="model file (.toml) with masses")
    _frf_settings(fr)
    _linear_point(fr)
    fr.add_argument("--out", default=None, help="write the response as CSV")
    fr.add_argument("--reactions", action="store_true", help="with --out: the joints' "
                   "reaction responses too")
    fr.add_argument("--picture", default=None, help="draw a Bode plot (.png, .svg or .pdf), "
                    "or animate the operating deflection shape (.gif or .mp4) at --at")
    fr.add_argument("--at", type=float, default=None, metavar="HZ", help="with an animation: "
                    "the frequency (default: the peak of --body's --coordinate)")
    fr.add_argument("--body", default=None, help="the body drawn (default the first)")
    fr.add_argument("--coordinate", default="y", choices=["x", "y", "theta"],
                   help="the coordinate drawn (default y)")
    li = sub.add_parser("linearize", help="the small motion about the static equilibrium as "
                        "a state-space system x' = A x + B p, dq = C x + D p (inputs: design "
                        "parameters)")
    li.add_argument("model", help="model file (.toml) with masses")
    li.add_argument("--input", action="append", required=True, metavar="NAME",
                    help="a design parameter as an input (repeatable; `mbd2d parameters "
                    "MODEL` lists them)")
    _linear_point(li)
    li.add_argument("--velocities", action="store_true", help="the coordinates' velocities as "
                    "outputs too (inputs that act through forces)")
    li.add_argument("--efforts", action="store_true", help="every driver's effort as an "
                    "output too (inputs that act through forces)")
    li.add_argument("--out", default=None, help="write A, B, C, D as CSV (matrix,row,column,"
                    "value)")
    w = sub.add_parser("sweep", help="one analysis of many variants (design parameters "
                       "swept): netCDF or CSV")
    w.add_argument("model", help="model file (.toml)")
    w.add_argument("--param", action="append", required=True, metavar="NAME=START:STOP:NUM",
                   help="a design parameter (see model.parameters()) and NUM values from "
                   "START to STOP; repeat for more parameters")
    w.add_argument("--grid", action="store_true", help="every combination of the values "
                   "(default: the i-th value of every parameter together; equal NUM)")
    _study_settings(w, "the analysis (default kinematics; modes: the frequencies, damping "
                    "and shapes of every case; frf: every case's frequency response to "
                    "--input at --f)", frf=True)
    _frf_settings(w, required=False)
    _study_integrator(w)
    w.add_argument("--positions-only", action="store_true",
                   help="kinematics: positions alone (no velocities or accelerations)")
    w.add_argument("--out", required=True, help="output file, .nc (netCDF) or .csv")
    w.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: every core)")
    w.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on the Dask cluster of this scheduler (tcp://host:8786)")
    _measures(w)
    _sensitivities(w)
    w.add_argument("--plot", default=None, metavar="FIG.png",
                   help="also draw the measures of every case (needs --measure): over time "
                   "coloured by the first parameter, and each case's worst transmission "
                   "angle or range against it (frf: every case's Bode plot of the "
                   "coordinates that move most, and its peak against the parameter)")
    r = sub.add_parser("parameters", help="the design parameters of a model: name = value")
    r.add_argument("model", help="model file (.toml)")
    r.add_argument("--match", default=None, metavar="TEXT",
                   help="only the names that contain TEXT")
    _tolerance_parser(sub)
    c = sub.add_parser("check", help="degrees of freedom and redundant constraints")
    c.add_argument("model", help="model file (.toml)")
    c.add_argument("--t", type=float, default=0.0, help="time of the check (default 0)")
    c.add_argument("--tol", type=float, default=None, help="assembly tolerance (default 1e-12)")
    c.add_argument("--out", default=None, help="also write the report as CSV (the assembled "
                   "configuration, the counts, a 0/1 column per row of Phi: redundant)")
    e = sub.add_parser("export", help="write a model file with its analysis for the standalone "
                       "mbd2d-solve")
    e.add_argument("model", help="model file (.toml)")
    e.add_argument("out", help="output model file (.mbd)")
    e.add_argument("--analysis", default="kinematics",
                   choices=ANALYSES[1:] + ("statics", "modes", "frf", "linearize", "check"),
                   help="the analysis mbd2d-solve runs (default kinematics)")
    e.add_argument("--t-end", type=float, default=None, help="final time (not for statics)")
    e.add_argument("--steps", type=int, default=None, help="output intervals")
    e.add_argument("--t0", type=float, default=0.0, help="start time (default 0)")
    e.add_argument("--every", type=int, default=1, help="keep every k-th row (and the last)")
    e.add_argument("--tol", type=float, default=None, help="Newton tolerance (default 1e-12)")
    e.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear solver of kinematic runs (default auto)")
    e.add_argument("--t", type=float, default=0.0, help="statics, modes: time of loads and "
                   "drivers")
    e.add_argument("--count", type=int, default=None, help="modes: only the lowest K")
    e.add_argument("--at-q0", action="store_true", help="modes: about q0 as given")
    e.add_argument("--damped", action="store_true", help="modes: write the damped "
                   "eigenvalues' table")
    e.add_argument("--velocities", action="store_true", help="linearize: the velocities' "
                   "outputs too")
    _frf_settings(e, required=False)
    _sensitivities(e)
    _measures(e)
    e.add_argument("--positions-only", action="store_true",
                   help="kinematics: positions alone (no velocities or accelerations)")
    e.add_argument("--param", action="append", default=None, metavar="NAME=START:STOP:NUM",
                   help="a sweep: mbd2d-solve runs every case and writes the sweep's CSV "
                   "(as `mbd2d sweep`; repeatable)")
    e.add_argument("--grid", action="store_true", help="with --param: every combination")
    _dynamics_settings(e)
    _columns(e)
    p = sub.add_parser("plot", help="run an analysis and draw it (PNG, SVG or PDF)")
    _span(p)
    p.add_argument("--out", required=True, help="picture file (.png, .svg or .pdf)")
    p.add_argument("--what", default="mechanism", choices=PICTURES,
                   help="mechanism (default): snapshots; paths: point paths; time-series: "
                   "positions, velocities, accelerations; forces: driver efforts and joint "
                   "reactions; energy: energies and constraint drift; measures: the --measure "
                   "columns against time")
    _measures(p)
    _picture_settings(p)
    a = sub.add_parser("animate", help="run an analysis and animate it (GIF or MP4)")
    _span(a)
    a.add_argument("--out", required=True, help="animation file (.gif, or .mp4 with ffmpeg)")
    a.add_argument("--fps", type=float, default=30.0, help="frames per second (default 30)")
    a.add_argument("--speed", type=float, default=1.0,
                   help="seconds of the run per second of animation (default 1: real time)")
    a.add_argument("--max-frames", type=int, default=300, help="at most this many frames")
    _picture_settings(a)
    y = sub.add_parser("synthesize", help="fit a mechanism to a task (linkage synthesis)")
    y.add_argument("task", help="task file (.toml): model, free parameters, bounds, targets")
    y.add_argument("--out", required=True, help="best model, written as a model file (.toml)")
    y.add_argument("--starts", type=int, default=None, help="local solves (default: the task "
                   "file's, else 8)")
    y.add_argument("--seed", type=int, default=None, help="Latin-hypercube seed")
    y.add_argument("--workers", type=int, default=1, help="local processes (default 1)")
    cm = sub.add_parser("cam", help="a disc cam from a follower program (cam synthesis)")
    cm.add_argument("task", help="cam task file (.toml): [cam] program, base_radius, follower")
    cm.add_argument("--out", required=True, help="the cam and its follower, written as a "
                    "model file (.toml)")
    cm.add_argument("--profile", default=None, help="also write the profile as CSV: theta, "
                    "s, ds, dds, x, y, pressure_angle, curvature_radius")
    return ap


def _synthesis_report(res: SynthesisResult) -> str:
    """The best design, its error per target and the defects met, as text."""
    lines = [f"best design: error {res.error:.6g} (sum of squared target errors), objective "
             f"{res.objective:.6g}, {len(res.history)} local solve(s), {res.seconds:.2f} s"]
    lines += [f"  {n:28s} = {v:.12g}" for n, v in res.values.items()]
    lines.append("error per target: " + ", ".join(f"{e:.3g}" for e in res.residuals))
    lines.append("target times: " + ", ".join(f"{t:.6g}" for t in res.times))
    for name, v in res.terms.items():
        lines.append(f"  {name}: {v:.6g}")
    if res.rejected:
        lines.append(f"rejected candidates: {len(res.rejected)} ("
                     + ", ".join(f"{k} x{n}" for k, n in res.defect_reasons.items()) + ")")
    return "\n".join(lines)


def _synthesize(args: argparse.Namespace) -> int:
    tf = load_task(args.task)
    opts = dict(tf.options)
    if args.starts is not None:
        opts["starts"] = args.starts
    if args.seed is not None:
        opts["seed"] = args.seed
    res = synthesize(tf.model, tf.free, tf.task, bounds=tf.bounds, constraints=tf.constraints,
                     workers=args.workers, **opts)
    print(_synthesis_report(res))
    header = (f"mbd2d synthesize {args.task}: error {res.error:.9g}\n"
              + "\n".join(f"{n} = {v:.15g}" for n, v in res.values.items()))
    toml_io.dump(res.model, args.out, header=header)
    print(f"wrote {args.out}")
    return EXIT_OK


def _cam(args: argparse.Namespace) -> int:
    """mbd2d cam: synthesize, report, write the model (and the profile)."""
    if args.profile is not None and not str(args.profile).endswith(".csv"):
        raise ModelError(f"--profile must end in .csv, got {args.profile!r}", "command line")
    design, model, speed = load_cam(args.task)
    print(cam_report(design, speed))
    toml_io.dump(model, args.out, header=f"mbd2d cam {args.task}: the cam and its follower")
    print(f"wrote {args.out}")
    if args.profile is not None:
        cols = np.column_stack([design.theta, design.s, design.ds, design.dds, design.points,
                                design.pressure_angle, design.curvature_radius])
        write_csv(args.profile, ["theta", "s", "ds", "dds", "x", "y", "pressure_angle",
                                 "curvature_radius"], cols, "the cam profile")
        print(f"wrote {args.profile}")
    return EXIT_OK


def _say(text: str) -> None:
    print(textwrap.fill(text, width=100), file=sys.stderr)


def _statics_report(model: Model, st: StaticsResult) -> str:
    """The equilibrium, its stability and the reactions, as text."""
    lines = [f"equilibrium of '{model.name}' at t = {st.t:g}: {st.stability}"]
    for name in st.body_names:
        x, y, th = st.body(name)
        lines.append(f"  {name:16s} x = {x: .9g}  y = {y: .9g}  theta = {th: .9g}")
    lines.append("reactions (force on each body, global; moment about its centre of mass):")
    for c in model.constraints:
        r = st.reaction(c.name)
        for b, fx, fy, mz in ((c.bodies[0], r.fx, r.fy, r.mz), (c.bodies[1], r.fx_j, r.fy_j,
                                                                  r.mz_j)):
            if b != "ground":
                lines.append(f"  {c.name:12s} on {b:12s} Fx = {fx[0]: .6g}  Fy = {fy[0]: .6g}  "
                             f"Mz = {mz[0]: .6g}")
    if st.parameter_names:
        lines.append("sensitivities of the equilibrium (change per unit of each parameter):")
    for prm in st.parameter_names:
        for name in st.body_names:
            dx, dy, dth = st.sensitivity(name, prm)
            lines.append(f"  d/d({prm}) {name:16s} x: {dx: .9g}  y: {dy: .9g}  "
                         f"theta: {dth: .9g}")
    return "\n".join(lines)


def _linear_point(p: argparse.ArgumentParser) -> None:
    """--t, --at-q0 and --solver: where modes, frf and linearize linearize the motion."""
    p.add_argument("--t", type=float, default=0.0, help="time at which loads and drivers are "
                   "held (default 0)")
    p.add_argument("--at-q0", action="store_true", help="about the assembled q0 as given "
                   "(an equilibrium you know), not the equilibrium statics finds")
    p.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear algebra (default auto: band LU for large chains)")


def _frf_settings(p: argparse.ArgumentParser, required: bool = True) -> None:
    """--input (repeatable), --f START:STOP:NUM and --log: a frequency response's inputs and
    frequencies."""
    p.add_argument("--input", action="append", required=required, default=None,
                   metavar="NAME", help="frf: a design parameter varied harmonically "
                   "(repeatable; `mbd2d parameters MODEL` lists them)")
    p.add_argument("--f", required=required, default=None, metavar="START:STOP:NUM",
                   help="frf: NUM frequencies in Hz from START to STOP")
    p.add_argument("--log", action="store_true", help="frf: the frequencies evenly spaced "
                   "on a log scale (START > 0)")


def _frequencies(args: argparse.Namespace) -> np.ndarray | None:
    """The frequencies of --f START:STOP:NUM (--log: geometric), None without --f."""
    if args.f is None:
        return None
    start, stop, num = _range(str(args.f), "--f", "START:STOP:NUM in Hz",
                              (str(args.f), "0.1:100:200"))
    if args.log:
        if start <= 0 or stop <= 0:
            raise ModelError(f"--f {args.f!r} with --log: START and STOP must be > 0",
                             "command line")
        return np.geomspace(start, stop, num)
    return np.linspace(start, stop, num)


def _linearize(model: Model, args: argparse.Namespace) -> int:
    """``mbd2d linearize``: the system's summary printed, then its CSV."""
    if args.out is not None and not str(args.out).lower().endswith(".csv"):
        raise ModelError(f"--out must end in .csv, got {args.out!r}", "command line")
    res = model.linearize(args.input, t=args.t, equilibrium=not args.at_q0, solver=args.solver,
                          velocities=args.velocities, efforts=args.efforts)
    print(res.summary())
    if args.out is not None:
        res.to_csv(args.out)
        print(f"wrote A, B, C, D ({2 * res.n_free} states) to {args.out}")
    return EXIT_OK


def _frf(model: Model, args: argparse.Namespace) -> int:
    """``mbd2d frf``: the peaks printed, then the files asked for."""
    for opt, path, ends in (("--out", args.out, (".csv",)),
                            ("--picture", args.picture, PICTURE_ENDS + MOTION_ENDS)):
        if path is not None and not str(path).lower().endswith(ends):
            raise ModelError(f"{opt} must end in {' or '.join(ends)}, got {path!r}",
                             "command line")
    if args.at is not None and not str(args.picture or "").lower().endswith(MOTION_ENDS):
        raise ModelError("--at is the frequency of an animation: give --picture NAME.gif or "
                         ".mp4", "command line")
    res = model.frequency_response(args.input, _frequencies(args), t=args.t,
                                   equilibrium=not args.at_q0, solver=args.solver)
    print(res.summary())
    if args.out is not None:
        res.to_csv(args.out, reactions=args.reactions)
        print(f"wrote {res.frequencies.size} frequencies to {args.out}")
    if args.picture is not None:
        body = args.body if args.body is not None else res.body_names[0]
        if str(args.picture).lower().endswith(MOTION_ENDS):
            at = args.at if args.at is not None else \
                res.peak(body, args.coordinate, args.input[0])[0]
            res.animate(at, args.picture, input=args.input[0])
            print(f"animated the response to {args.input[0]} at "
                  f"{res.frequencies[res.frequency_index(at)]:g} Hz in {args.picture}")
            return EXIT_OK
        fig = res.plot(body, args.coordinate, input=args.input[0])
        plots.save_figure(fig, args.picture)
        print(f"drew {body}.{args.coordinate} per unit {args.input[0]} in {args.picture}")
    return EXIT_OK


def _modes(model: Model, args: argparse.Namespace) -> int:
    """``mbd2d modes``: the table of modes printed, then the files asked for."""
    for opt, path, ends in (("--out", args.out, (".csv",)),
                            ("--damped-out", args.damped_out, (".csv",)),
                            ("--picture", args.picture, PICTURE_ENDS + MOTION_ENDS)):
        if path is not None and not str(path).lower().endswith(ends):
            raise ModelError(f"{opt} must end in {' or '.join(ends)}, got {path!r}",
                             "command line")
    res = model.modes(t=args.t, count=args.count, equilibrium=not args.at_q0,
                      solver=args.solver)
    print(res.summary())
    if args.out is not None:
        res.to_csv(args.out)
        print(f"wrote {res.omega2.size} modes to {args.out}")
    if args.damped_out is not None:
        res.to_csv(args.damped_out, damped=True)
        print(f"wrote {res.eigenvalues.size} eigenvalues to {args.damped_out}")
    if args.picture is not None:
        damped = args.damped_mode is not None
        k = args.damped_mode if damped else args.mode
        if str(args.picture).lower().endswith(MOTION_ENDS):
            res.animate(k, args.picture, damped=damped)
        else:
            ax = res.plot(k, damped=damped)
            plots.save_figure(ax.figure, args.picture)
        print(f"drew {'damped mode' if damped else 'mode'} {k} in {args.picture}")
    return EXIT_OK


def _study_settings(p: argparse.ArgumentParser, analysis_help: str,
                    frf: bool = False) -> None:
    """The analysis and output times of a study (sweep; tolerance with the modes but without
    the frequency response)."""
    p.add_argument("--analysis", default="kinematics",
                   choices=["kinematics", "inverse_dynamics", "statics", "dynamics", "modes"]
                   + (["frf"] if frf else []), help=analysis_help)
    p.add_argument("--t-end", type=float, default=None, help="final time")
    p.add_argument("--steps", type=int, default=None, help="output intervals")
    p.add_argument("--t0", type=float, default=0.0, help="start time (statics, modes, frf: "
                   "its time)")
    p.add_argument("--every", type=int, default=1, help="keep every k-th row (and the last)")


def _study_integrator(p: argparse.ArgumentParser) -> None:
    """A study's dynamics settings (sweep, tolerance): the integrator and its tolerances."""
    p.add_argument("--method", default=None,
                   help="dynamics: the integrator (dopri5 default; with --sensitivities or in "
                   "a tolerance study dopri5 or generalized-alpha)")
    p.add_argument("--rtol", type=float, default=None, help="dynamics: relative tolerance")
    p.add_argument("--atol", type=float, default=None, help="dynamics: absolute tolerance")
    p.add_argument("--h", type=float, default=None,
                   help="dynamics: fixed step (generalized-alpha, baumgarte-rk4)")


def _study_dynamics(args: argparse.Namespace) -> dict[str, Any]:
    """The settings given by _study_integrator's options (those not given are left out)."""
    given = {"method": args.method, "rtol": args.rtol, "atol": args.atol, "h": args.h}
    return {k: v for k, v in given.items() if v is not None}


def _study_span(args: argparse.Namespace) -> dict[str, Any]:
    """The settings of a study's analysis from --t0, --t-end, --steps, --every (statics and
    modes: t; frf: t, and its inputs and frequencies)."""
    frf = getattr(args, "input", None) is not None or getattr(args, "f", None) is not None
    if frf != (args.analysis == "frf"):
        raise ModelError("--analysis frf needs --input NAME and --f START:STOP:NUM; they are "
                         "its settings alone", "command line")
    if args.analysis == "frf":
        if args.input is None or args.f is None:
            raise ModelError("--analysis frf needs --input NAME and --f START:STOP:NUM",
                             "command line")
        return {"t": args.t0, "inputs": args.input, "frequencies": _frequencies(args)}
    if args.analysis in ("statics", "modes"):
        return {"t": args.t0}
    if args.t_end is None or args.steps is None:
        raise ModelError(f"{args.analysis} needs --t-end and --steps", "command line")
    return {"t_end": args.t_end, "steps": args.steps, "t0": args.t0, "every": args.every}


def _tolerance_parser(sub: Any) -> None:
    t = sub.add_parser("tolerance", help="scatter of every output under parameter "
                       "tolerances: first order (exact sensitivities) beside Monte Carlo")
    t.add_argument("model", help="model file (.toml)")
    t.add_argument("--sigma", action="append", required=True, metavar="NAME=STD",
                   help="a design parameter and its standard deviation (repeatable)")
    t.add_argument("--samples", type=int, default=200,
                   help="Monte Carlo variants (default 200; 0: first order alone)")
    t.add_argument("--seed", type=int, default=0, help="seed of the draws (default 0)")
    _study_settings(t, "the analysis (default kinematics; dynamics by dopri5 or "
                       "generalized-alpha; modes and frf: Monte Carlo alone)", frf=True)
    _frf_settings(t, required=False)
    _study_integrator(t)
    t.add_argument("--point", action="append", default=None, metavar="BODY:X,Y",
                   help="also the scatter of the point (X, Y) of BODY (repeatable)")
    t.add_argument("--out", default=None, help="output file, .csv (one row per time) or "
                   ".nc (netCDF)")
    t.add_argument("--export-samples", default=None, metavar="FILE.mbd",
                   help="instead of running: write the Monte Carlo draws (--samples, --seed) "
                   "as a sweep file for mbd2d-solve")
    t.add_argument("--workers", type=int, default=None,
                   help="local processes for the Monte Carlo sweep (default: all cores)")
    t.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the Monte Carlo sweep on the Dask scheduler at ADDRESS")
    _measures(t)


def _sigma(spec: str) -> tuple[str, float]:
    """NAME=STD as the name and the standard deviation."""
    name, eq, value = spec.partition("=")
    try:
        if not eq or not name.strip():
            raise ValueError
        std = float(value)
    except ValueError:
        raise ModelError(f"--sigma {spec!r}: write NAME=STD, for example "
                         "joint.B.points.0.0=1e-4", "command line") from None
    return name.strip(), std


def _tolerance(model: Model, args: argparse.Namespace) -> int:
    """The tolerance command: run, write, summarize."""
    from .studies import connect, export_sweep, tolerance, tolerance_samples, write_tolerance
    sigma = dict(_sigma(s) for s in args.sigma)
    kw = _study_span(args)
    if args.analysis not in ("statics", "modes", "frf"):
        kw.update(_study_dynamics(args))
    if args.export_samples is not None:
        cases = tolerance_samples(model, sigma, args.samples, args.seed)
        export_sweep(model, args.export_samples, cases, args.analysis, measures=args.measure,
                     **kw)
        print(f"wrote {args.export_samples} ({args.samples} Monte Carlo variants, seed "
              f"{args.seed}; run it with mbd2d-solve {args.export_samples} OUT.csv)")
        return EXIT_OK
    if args.out is None or not str(args.out).endswith((".nc", ".csv")):
        raise ModelError(f"--out must end in .nc or .csv, got {args.out!r}", "command line")
    points = _trace(args.point) or []
    if points and args.analysis == "frf":
        raise ModelError("--point is a scatter over time, not of a frequency response",
                         "command line")
    bodies = [b.name for b in model.bodies]
    for body, _ in points:
        if body not in bodies:
            raise ModelError(f"--point {body}:...: no moving body {body!r}; bodies: "
                             f"{', '.join(bodies)}", "command line")
    client = connect(args.scheduler) if args.scheduler else None
    try:
        tol = tolerance(model, sigma, args.analysis, samples=args.samples, client=client,
                        seed=args.seed, workers=args.workers, measures=args.measure, **kw)
    finally:
        if client is not None:
            client.close()
    pts = [(f"{b}({x:g};{y:g})", tol.point(b, (x, y))) for b, (x, y) in points]
    write_tolerance(tol.dataset, args.out, pts)
    print(_tolerance_report(tol, pts))
    print(f"wrote {args.out}")
    return EXIT_OK


def _tolerance_report(tol: Any, points: list[tuple[str, Any]]) -> str:
    """The largest first-order standard deviations of the positions (and points), with the
    Monte Carlo estimate beside them; the Monte Carlo ones alone for a report without the
    first-order column (contacts, joint friction)."""
    ds = tol.dataset
    a = ds.attrs
    key, word = ("_std_linear", "first-order") if tol.linear else ("_std_mc", "Monte Carlo")
    lines = [f"tolerance of '{a['model']}' ({a['run']}; {a['samples']} samples, {a['failed']} "
             f"failed): {a['sigma']}",
             f"largest {word} standard deviation over the run"
             + (" (Monte Carlo at the same time):" if tol.linear else
                f" (first order: {a['first_order']}):")]
    rows = []
    for j, name in enumerate(str(c) for c in ds.coordinate.values):
        rows.append((name, ds[f"q{key}"].values[:, j],
                     ds.q_std_mc.values[:, j] if tol.linear and "q_std_mc" in ds else None,
                     "q" if tol.linear else None))
    for label, pt in points:
        for v in ("x", "y"):
            rows.append((f"{label}.{v}", pt[f"{v}{key}"].values,
                         pt[f"{v}_std_mc"].values if tol.linear else None,
                         pt[f"{v}_share"].values if tol.linear else None))
    rows.sort(key=lambda r: -_nanmax(r[1]))
    t = np.atleast_1d(ds.time.values)
    for name, lin, mc, output in rows[:8]:
        if not np.isfinite(lin).any():
            lines.append(f"  {name:24s} no value: fewer than 2 samples completed")
            continue
        k = int(np.nanargmax(lin))
        beside = "" if mc is None else f"  (Monte Carlo {mc[k]:.3g})" if np.isfinite(mc[k]) \
            else "  (Monte Carlo: fewer than 2 samples completed)"
        lines.append(f"  {name:24s} {lin[k]:.3g} at t = {t[k]:.6g}{beside}"
                     + _main_share(tol, output, name, k))
    if "measures" in ds:
        lines += _measures_report(tol, key, word, t)
    if "frequency_std_mc" in ds:
        lines += _modes_report(ds)
    if "magnitude" in ds:
        lines += _frf_report(ds)
    return "\n".join(lines)


def _frf_report(ds: Any) -> list[str]:
    """The frequency response's lines of a tolerance report: for each input and response
    that moves, its peak magnitude and frequency with the Monte Carlo standard deviation
    there."""
    lines = ["frequency response peaks, Monte Carlo standard deviation at the peak:"]
    freq = np.asarray(ds.frequency.values)
    for j, inp in enumerate(str(v) for v in ds.input.values):
        for mag, dim, fmt in (("magnitude", "coordinate", "{}"),
                              ("effort_magnitude", "driver", "effort.{}")):
            if mag not in ds:
                continue
            m = np.asarray(ds[mag].values)[:, :, j]
            sd = np.asarray(ds[f"{mag}_std_mc"].values)[:, :, j]
            for k, entry in enumerate(str(v) for v in ds[dim].values):
                if not m[:, k].max(initial=0.0) > 1e-12 * np.abs(m).max(initial=0.0):
                    continue
                i = int(np.argmax(m[:, k]))
                spread = f"std {sd[i, k]:.3g}" if np.isfinite(sd[i, k]) else \
                    "fewer than 2 samples completed"
                lines.append(f"  d({fmt.format(entry)})/d({inp}): |H| {m[i, k]:.4g} at "
                             f"{freq[i]:.4g} Hz, {spread}")
    return lines


def _modes_report(ds: Any) -> list[str]:
    """The modes' lines of a tolerance report: each natural frequency with its Monte Carlo
    standard deviation and mean."""
    lines = ["natural frequencies (Hz), Monte Carlo standard deviation and mean:"]
    for k, f in enumerate(ds.frequency.values, start=1):
        sd, mean = ds.frequency_std_mc.values[k - 1], ds.frequency_mean_mc.values[k - 1]
        lines.append(f"  mode {k:<3d} {f:.6g}  std {sd:.3g}  mean {mean:.6g}"
                     if np.isfinite(sd) else f"  mode {k:<3d} {f:.6g}  fewer than 2 samples "
                     "completed")
    return lines


def _nanmax(x: np.ndarray) -> float:
    """The largest finite value (-inf when there is none)."""
    x = np.asarray(x, dtype=float)
    return float(np.max(x[np.isfinite(x)])) if np.isfinite(x).any() else -math.inf


def _measures_report(tol: Any, key: str, word: str, t: np.ndarray) -> list[str]:
    """The report's lines of the measures: each one's largest standard deviation (key:
    first order or Monte Carlo) with the Monte Carlo one beside the first order."""
    ds = tol.dataset
    lines = [f"measures, largest {word} standard deviation (angles in deg):"]
    for j, spec in enumerate(str(m) for m in ds["measure"].values):
        unit = np.degrees if spec.startswith("transmission_angle") else np.asarray
        lin = unit(ds[f"measures{key}"].values[:, j])
        if not np.any(np.isfinite(lin)):
            lines.append(f"  {spec:24s} no finite value (a dead centre throughout)")
            continue
        k = int(np.nanargmax(np.where(np.isfinite(lin), lin, np.nan)))
        mc = (f"  (Monte Carlo {unit(ds.measures_std_mc.values[k, j]):.3g})"
              if tol.linear and "measures_std_mc" in ds else "")
        lines.append(f"  {spec:24s} {lin[k]:.3g} at t = {t[k]:.6g}{mc}"
                     + (_main_share(tol, "measures", spec, k) if tol.linear else ""))
    return lines


def _main_share(tol: Any, output: Any, entry: str, k: int) -> str:
    """", mostly P (NN %)": the parameter with the largest share of the entry's first-order
    variance at row k (ToleranceResult.contributions; a point's shares given as output, an
    array (time, parameter)); "" for a lone parameter or without shares (output None)."""
    if len(tol.sigma) < 2 or output is None:
        return ""
    share = (tol.contributions(output, entry).values if isinstance(output, str)
             else output)[k]
    if not share.any():
        return ""
    j = int(np.argmax(share))
    return f", mostly {list(tol.sigma)[j]} ({100 * share[j]:.0f}%)"


def _parameters_report(model: Model, match: str | None) -> str:
    """The design parameters, one "name = value" line each (those containing match)."""
    params = model.parameters()
    lines = [f"{n} = {'(from the q0 estimates)' if v is None else f'{v:.17g}'}"
             for n, v in params.items() if match is None or match in n]
    if not lines:
        raise ModelError(f"no design parameter name contains {match!r}; "
                         f"{len(params)} parameters in all", "command line")
    return "\n".join(lines)


def _trace(items: list[str] | None) -> list[tuple[str, tuple[float, float]]] | None:
    """--trace BODY:X,Y entries."""
    if not items:
        return None
    out = []
    for item in items:
        body, sep, xy = item.rpartition(":")
        try:
            x, y = (float(v) for v in xy.split(","))
        except ValueError:
            sep = ""
        if not sep or not body:
            raise ModelError(f"--trace takes BODY:X,Y (for example coupler:0,1), got {item!r}",
                             "command line")
        out.append((body, (x, y)))
    return out


def _dynamics_kwargs(args: argparse.Namespace) -> dict[str, Any]:
    return {"method": args.method, "rtol": args.rtol, "atol": args.atol, "h": args.h,
            "rho_inf": args.rho_inf, "alpha": args.alpha, "beta": args.beta,
            "max_steps": args.max_steps}


def _run(model: Model, args: argparse.Namespace, analysis: str) -> Any:
    """The result of the analysis a command asks for."""
    span = {"t_end": args.t_end, "steps": args.steps, "t0": args.t0}
    if analysis == "auto":
        neq, nq = model.counts()
        analysis = "kinematics" if neq >= nq else "dynamics"
    sens = _sens_names(args)
    if analysis == "dynamics":
        return model.dynamics(**span, every=getattr(args, "every", 1), **_dynamics_kwargs(args),
                              solver=getattr(args, "solver", "auto"), sensitivities=sens)
    if analysis == "inverse-dynamics":
        return model.inverse_dynamics(**span, tol=getattr(args, "tol", None),
                                      every=getattr(args, "every", 1),
                                      solver=getattr(args, "solver", "auto"),
                                      sensitivities=sens)
    return model.kinematics(**span, tol=getattr(args, "tol", None),
                            every=getattr(args, "every", 1),
                            solver=getattr(args, "solver", "auto"),
                            positions_only=getattr(args, "positions_only", False),
                            sensitivities=sens)


def _picture(res: Any, args: argparse.Namespace) -> str:
    """Draw a result as the plot or animate command asks; returns the file written."""
    trace = _trace(args.trace)
    extra = {} if args.dpi is None else {"dpi": args.dpi}
    if args.command == "animate":
        return plots.animate(res, args.out, fps=args.fps, speed=args.speed, trace=trace,
                             forces=args.forces, max_frames=args.max_frames,
                             length_unit=args.length_unit, **extra)
    if args.what == "mechanism":
        fig = plots.plot_mechanism(res, trace=trace, forces=args.forces,
                                   length_unit=args.length_unit)
    elif args.what == "paths":
        fig = plots.plot_paths(res, trace, length_unit=args.length_unit)
    else:
        kind = {"time-series": "motion"}.get(args.what, args.what)
        fig = plots.plot_timeseries(res, kind=kind, length_unit=args.length_unit,
                                    measures=getattr(args, "measure", None))
    return plots.save_figure(fig, args.out, **extra)


def _check_out(args: argparse.Namespace) -> None:
    if args.command in ("kinematics", "dynamics", "inverse-dynamics"):
        ok = (".csv", ".npz")
    elif args.command == "plot":
        ok = PICTURE_ENDS
    else:
        ok = MOTION_ENDS
    if not str(args.out).lower().endswith(ok):
        raise ModelError(f"--out must end in {' or '.join(ok)}, got {args.out!r}",
                         "command line")


def _write(res: Any, args: argparse.Namespace) -> str:
    """Write a (possibly partial) result where the command puts it."""
    if args.command in ("plot", "animate"):
        return _picture(res, args)
    res.save(args.out, **_file_outputs(args))
    return args.out
def _range(text: str, option: str, form: str, example: str,
           ok: bool = True) -> tuple[float, float, int]:
    """START:STOP:NUM of an option's value: finite START and STOP, NUM from 1 to MAX_CASES
    (ok False: the value is malformed around it)."""
    parts = text.split(":")
    try:
        if not ok or len(parts) != 3:
            raise ValueError
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise ModelError(f"{option} {example[0]!r}: write {form}, for example {example[1]}",
                         "command line") from None
    if not 1 <= num <= MAX_CASES or not (np.isfinite(start) and np.isfinite(stop)):
        raise ModelError(f"{option} {example[0]!r}: NUM must be from 1 to {MAX_CASES} and "
                         "START, STOP finite", "command line")
    return start, stop, num


def _param_values(spec: str) -> tuple[str, np.ndarray]:
    """NAME=START:STOP:NUM as the name and NUM values from START to STOP."""
    name, eq, rng = spec.partition("=")
    start, stop, num = _range(rng, "--param", "NAME=START:STOP:NUM",
                              (spec, "joint.B.points.0.0=1.5:2.0:11"), ok=bool(eq))
    return name.strip(), np.linspace(start, stop, num)


def _cases(args: argparse.Namespace) -> dict[str, np.ndarray]:
    """The case table of --param (and --grid)."""
    from .studies import grid
    values = dict(_param_values(p) for p in args.param)
    if args.grid:
        return grid(values)
    counts = {len(v) for v in values.values()}
    if len(counts) != 1:
        raise ModelError("without --grid every --param needs the same NUM (the i-th "
                         "values form case i); use --grid for every combination",
                         "command line")
    return values


def _export_sweep(model: Model, args: argparse.Namespace) -> int:
    """export --param: a sweep file for mbd2d-solve (the settings of the analysis alone)."""
    from .studies import export_sweep
    if _outputs(args):
        raise ModelError("a sweep file writes the sweep's columns (and --measure, "
                         "--sensitivities): no --energy, --multipliers, --reactions or "
                         "--efforts with --param", "command line")
    if args.analysis in ("check", "linearize"):
        raise ModelError("a sweep runs kinematics, inverse-dynamics, dynamics, statics, "
                         f"modes or frf, not {args.analysis}", "command line")
    span = {"t_end": args.t_end, "steps": args.steps, "t0": args.t0, "every": args.every}
    kw: dict[str, Any] = {
        "kinematics": dict(span, tol=args.tol, solver=args.solver,
                           positions_only=args.positions_only),
        "inverse-dynamics": dict(span, tol=args.tol, solver=args.solver),
        "statics": {"t": args.t},
        "modes": {"t": args.t, "count": args.count, "equilibrium": not args.at_q0,
                  "solver": args.solver},
        "frf": {"t": args.t, "inputs": args.input, "frequencies": _frequencies(args),
                "equilibrium": not args.at_q0, "solver": args.solver},
        "dynamics": dict(span, **_dynamics_kwargs(args))}[args.analysis]
    timed = args.analysis not in ("statics", "modes", "frf")
    if timed and (args.t_end is None or args.steps is None):
        raise ModelError(f"{args.analysis} needs --t-end and --steps", "command line")
    cases = _cases(args)
    export_sweep(model, args.out, cases, args.analysis.replace("-", "_"),
                 measures=args.measure, sensitivities=_sens_names(args), **kw)
    n = len(next(iter(cases.values())))
    print(f"wrote {args.out} ({args.analysis} of {n} cases; run it with mbd2d-solve "
          f"{args.out} OUT.csv)")
    return EXIT_OK


def _sweep(model: Model, args: argparse.Namespace) -> int:
    """The sweep command: run, write, summarize."""
    from .studies import connect, sweep, write_sweep
    if not str(args.out).endswith((".nc", ".csv")):
        raise ModelError(f"--out must end in .nc or .csv, got {args.out!r}", "command line")
    if args.plot is not None and not args.measure and args.analysis != "frf":
        raise ModelError("--plot draws the sweep's measures: give --measure SPEC",
                         "command line")
    cases = _cases(args)
    kw = _study_span(args)
    if args.analysis not in ("statics", "modes", "frf"):
        kw.update(_study_dynamics(args))
        if args.positions_only:
            kw["positions_only"] = True
    client = connect(args.scheduler) if args.scheduler else None
    try:
        ds = sweep(model, cases, args.analysis, client, workers=args.workers,
                   measures=args.measure, sensitivities=_sens_names(args), **kw)
    finally:
        if client is not None:
            client.close()
    write_sweep(ds, args.out)
    failed = int(ds.attrs["failed"])
    print(f"wrote {ds.sizes['case']} cases ({failed} failed) to {args.out}")
    for j in np.flatnonzero(ds.status.values != 0)[:5]:
        _say(f"  case {int(j)}: {ds.message.values[j]}")
    for line in _measure_ranges(ds):
        print(line)
    if args.plot is not None:
        from .plots import plot_sweep, save_figure
        save_figure(plot_sweep(ds), args.plot)
        print(f"wrote {args.plot}")
    return EXIT_OK


def _measure_ranges(ds: Any) -> list[str]:
    """Each measure's least and greatest value over the cases' rows, and where; with
    sensitivities, those of its derivatives along each parameter too."""
    if "measure" not in ds.coords:
        return []
    out = []
    for k, spec in enumerate(ds["measure"].values):
        out.append(_range_line(str(spec), ds["measures"].values[:, :, k]))
        if "dmeasures_dp" in ds:
            for j, name in enumerate(ds["parameter"].values):
                out.append(_range_line(f"d({spec})/d({name})",
                                       ds["dmeasures_dp"].values[:, :, k, j]))
    return out


def _range_line(label: str, values: Any) -> str:
    """"  LABEL: from LEAST (case i) to GREATEST (case j)" over (case, time) values."""
    v = np.asarray(values, dtype=float)
    if not np.isfinite(v).any():
        return f"  {label}: no value"
    lo, hi = np.nanargmin(v), np.nanargmax(v)
    cl, ch = np.unravel_index(lo, v.shape)[0], np.unravel_index(hi, v.shape)[0]
    return (f"  {label}: from {v.flat[lo]:.6g} (case {int(cl)}) to {v.flat[hi]:.6g} "
            f"(case {int(ch)})")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code. The analyses' warnings are lines
    ``mbd2d: warning: ...`` on standard error."""
    args = _parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("always", MbdWarning)      # each one said, whatever the filters
        warnings.showwarning = _show_warning
        return _main(args)


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: Any = None, line: str | None = None) -> None:
    """A warning as the command line says it (no source location: it is the command's)."""
    _say(f"mbd2d: warning: {message}")


def _main(args: argparse.Namespace) -> int:
    """The command of the parsed arguments; returns the exit code."""
    try:
        if args.command == "synthesize":
            return _synthesize(args)
        if args.command == "cam":
            return _cam(args)
        model = load(args.model)
        if args.command == "check":
            if args.out is not None and not str(args.out).endswith(".csv"):
                raise ModelError(f"--out must end in .csv, got {args.out!r}", "command line")
            report = model.analyze_dof(t=args.t, tol=args.tol)
            print(report)
            if args.out is not None:
                report.to_csv(args.out)
            return EXIT_OK
        if args.command == "parameters":
            print(_parameters_report(model, args.match))
            return EXIT_OK
        if args.command == "statics":
            if args.out is not None and not str(args.out).endswith(".csv"):
                raise ModelError(f"--out must end in .csv, got {args.out!r}", "command line")
            st = model.statics(t=args.t, solver=args.solver, sensitivities=_sens_names(args))
            print(_statics_report(model, st))
            if args.out is not None:
                st.to_csv(args.out, **_file_outputs(args))
                print(f"wrote the equilibrium to {args.out}")
            return EXIT_OK
        if args.command == "modes":
            return _modes(model, args)
        if args.command == "frf":
            return _frf(model, args)
        if args.command == "linearize":
            return _linearize(model, args)
        if args.command == "export" and args.param:
            return _export_sweep(model, args)
        if args.command == "export":
            extra = _dynamics_kwargs(args) if args.analysis == "dynamics" else {}
            model.export(args.out, t_end=args.t_end, steps=args.steps, t0=args.t0, tol=args.tol,
                         analysis=args.analysis, every=args.every, solver=args.solver, t=args.t,
                         outputs=list(_outputs(args)) + (["damped"] if args.damped else [])
                         + (["velocities"] if args.velocities else []),
                         positions_only=args.positions_only, count=args.count,
                         equilibrium=not args.at_q0, inputs=args.input,
                         frequencies=_frequencies(args),
                         sensitivities=_sens_names(args), measures=args.measure, **extra)
            print(f"wrote {args.out} ({args.analysis}; run it with mbd2d-solve "
                  f"{args.out} OUT.csv)")
            return EXIT_OK
        if args.command == "sweep":
            return _sweep(model, args)
        if args.command == "tolerance":
            return _tolerance(model, args)
        _check_out(args)
        _trace(getattr(args, "trace", None))       # a malformed --trace fails before the run
        res = _run(model, args, getattr(args, "analysis", args.command))
        _write(res, args)
        what = "rows, drawn," if args.command in ("plot", "animate") else "rows"
        print(f"wrote {len(res.t)} {what} to {args.out}")
        return EXIT_OK
    except ModelError as exc:
        _say(f"mbd2d: error in the model or the command: {exc}")
        return EXIT_INPUT
    except InsufficientMemoryError as exc:      # too large for this machine: change the input
        _say(f"mbd2d: {exc}")
        return EXIT_INPUT
    except AnalysisError as exc:
        if args.command in ("check", "statics", "modes", "frf", "linearize", "synthesize",
                            "cam"):
            _say(f"mbd2d: {exc}")
            return EXIT_NUMERICAL
        _say(f"mbd2d: {exc}")
        if exc.results is not None and len(exc.results.t):
            try:
                _write(exc.results, args)
            except MbdError as err:
                _say(f"mbd2d: the partial results could not be written: {err}")
                return EXIT_INPUT
            print(f"wrote {len(exc.results.t)} rows (up to t = {exc.results.t[-1]:.6g}) to "
                  f"{args.out}", file=sys.stderr)
        return EXIT_SINGULAR if isinstance(exc, SingularConfigurationError) else EXIT_NUMERICAL
    except MbdError as exc:
        _say(f"mbd2d: {exc}")
        return EXIT_NUMERICAL
    except ImportError as exc:                  # an optional package (the sweep extra)
        _say(f"mbd2d: {exc}")
        return EXIT_INPUT
    except BrokenPipeError:                     # the reader left (mbd2d ... | head): stop
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())   # (Python's own flush at exit would fail)
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
