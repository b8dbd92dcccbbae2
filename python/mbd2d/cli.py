"""The ``mbd2d`` command line.

    mbd2d kinematics MODEL.toml --t-end T --steps N --out OUT.csv|OUT.npz [--every K --solver S]
    mbd2d export MODEL.toml OUT.mbd --t-end T --steps N
    mbd2d check MODEL.toml
    mbd2d dynamics MODEL.toml --t-end T --steps N --out OUT.csv [--method M --rtol R --atol A --h H
                   --max-steps S]
    mbd2d statics MODEL.toml [--t T]
    mbd2d sweep MODEL.toml --param NAME=START:STOP:NUM ... [--grid] --t-end T --steps N
                --out sweep.nc|sweep.csv [--analysis A --t0 T0 --every K --workers W
                --scheduler ADDRESS]

Exit codes: 0 ok, 2 bad input, 3 singular configuration (partial output written),
4 other numerical failure (partial output written when there is any).
"""
from __future__ import annotations

import argparse
import sys
import textwrap
from typing import Sequence

import numpy as np

from .errors import (AnalysisError, InsufficientMemoryError, MbdError, ModelError,
                     SingularConfigurationError)
from .model import Model, load
from .results import StaticsResult

EXIT_OK, EXIT_INPUT, EXIT_SINGULAR, EXIT_NUMERICAL = 0, 2, 3, 4


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mbd2d", description="Planar multibody analysis.")
    sub = ap.add_subparsers(dest="command", required=True)
    k = sub.add_parser("kinematics", help="kinematic analysis of a driven model")
    k.add_argument("model", help="model file (.toml)")
    k.add_argument("--t-end", type=float, required=True, help="final time")
    k.add_argument("--steps", type=int, required=True, help="output intervals (rows = steps + 1)")
    k.add_argument("--t0", type=float, default=0.0, help="start time (default 0)")
    k.add_argument("--out", required=True, help="output file, .csv or .npz")
    k.add_argument("--tol", type=float, default=None, help="Newton tolerance (default 1e-12)")
    k.add_argument("--every", type=int, default=1, help="write every k-th row (and the last)")
    k.add_argument("--solver", default="auto", choices=["auto", "dense", "banded"],
                   help="linear solver (default auto: banded LU for large chains)")
    d = sub.add_parser("dynamics", help="forward dynamics")
    d.add_argument("model", help="model file (.toml) with masses")
    d.add_argument("--t-end", type=float, required=True, help="final time")
    d.add_argument("--steps", type=int, required=True, help="output intervals (rows = steps + 1)")
    d.add_argument("--t0", type=float, default=0.0, help="start time (default 0)")
    d.add_argument("--out", required=True, help="output file, .csv or .npz")
    d.add_argument("--method", default=None,
                   help="dopri5 (default), generalized-alpha, baumgarte-rk4 or partitioned")
    d.add_argument("--rtol", type=float, default=None, help="relative tolerance (adaptive)")
    d.add_argument("--atol", type=float, default=None, help="absolute tolerance (adaptive)")
    d.add_argument("--h", type=float, default=None, help="fixed step (generalized-alpha, "
                   "baumgarte-rk4)")
    d.add_argument("--rho-inf", type=float, default=None, help="generalized-alpha rho_inf")
    d.add_argument("--alpha", type=float, default=None, help="Baumgarte alpha")
    d.add_argument("--beta", type=float, default=None, help="Baumgarte beta")
    d.add_argument("--every", type=int, default=1, help="write every k-th row (and the last)")
    d.add_argument("--max-steps", type=int, default=None, help="limit on the integrator's "
                   "steps, accepted and rejected (default 10000000)")
    s = sub.add_parser("statics", help="static equilibrium and reactions")
    s.add_argument("model", help="model file (.toml) with masses")
    s.add_argument("--t", type=float, default=0.0, help="time at which loads and drivers are "
                   "taken (default 0)")
    w = sub.add_parser("sweep", help="one analysis of many variants (design parameters "
                       "swept): netCDF or CSV")
    w.add_argument("model", help="model file (.toml)")
    w.add_argument("--param", action="append", required=True, metavar="NAME=START:STOP:NUM",
                   help="a design parameter (see model.parameters()) and NUM values from "
                   "START to STOP; repeat for more parameters")
    w.add_argument("--grid", action="store_true", help="every combination of the values "
                   "(default: the i-th value of every parameter together; equal NUM)")
    w.add_argument("--analysis", default="kinematics",
                   choices=["kinematics", "inverse_dynamics", "statics", "dynamics"],
                   help="the analysis (default kinematics)")
    w.add_argument("--t-end", type=float, default=None, help="final time")
    w.add_argument("--steps", type=int, default=None, help="output intervals")
    w.add_argument("--t0", type=float, default=0.0, help="start time (statics: its time)")
    w.add_argument("--every", type=int, default=1, help="keep every k-th row (and the last)")
    w.add_argument("--method", default=None, help="dynamics: the integrator")
    w.add_argument("--out", required=True, help="output file, .nc (netCDF) or .csv")
    w.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: every core)")
    w.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on the Dask cluster of this scheduler (tcp://host:8786)")
    c = sub.add_parser("check", help="degrees of freedom and redundant constraints")
    c.add_argument("model", help="model file (.toml)")
    c.add_argument("--t", type=float, default=0.0, help="time of the check (default 0)")
    e = sub.add_parser("export", help="write a model file for the standalone mbd2d-solve")
    e.add_argument("model", help="model file (.toml)")
    e.add_argument("out", help="output model file (.mbd)")
    e.add_argument("--t-end", type=float, required=True, help="final time")
    e.add_argument("--steps", type=int, required=True, help="output intervals")
    e.add_argument("--t0", type=float, default=0.0, help="start time (default 0)")
    e.add_argument("--tol", type=float, default=None, help="Newton tolerance (default 1e-12)")
    return ap


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
    return "\n".join(lines)


def _param_values(spec: str) -> tuple[str, np.ndarray]:
    """NAME=START:STOP:NUM as the name and NUM values from START to STOP."""
    name, eq, rng = spec.partition("=")
    parts = rng.split(":")
    try:
        if not eq or len(parts) != 3:
            raise ValueError
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise ModelError(f"--param {spec!r}: write NAME=START:STOP:NUM, for example "
                         "joint.B.points.0.0=1.5:2.0:11", "command line") from None
    if num < 1 or not (np.isfinite(start) and np.isfinite(stop)):
        raise ModelError(f"--param {spec!r}: NUM must be >= 1 and START, STOP finite",
                         "command line")
    return name.strip(), np.linspace(start, stop, num)


def _sweep(model: Model, args: argparse.Namespace) -> int:
    """The sweep command: run, write, summarize."""
    from .studies import connect, grid, sweep, write_sweep
    if not str(args.out).endswith((".nc", ".csv")):
        raise ModelError(f"--out must end in .nc or .csv, got {args.out!r}", "command line")
    values = dict(_param_values(p) for p in args.param)
    if args.grid:
        cases = grid(values)
    else:
        counts = {len(v) for v in values.values()}
        if len(counts) != 1:
            raise ModelError("without --grid every --param needs the same NUM (the i-th "
                             "values form case i); use --grid for every combination",
                             "command line")
        cases = values
    if args.analysis == "statics":
        kw: dict = {"t": args.t0}
    else:
        if args.t_end is None or args.steps is None:
            raise ModelError(f"{args.analysis} needs --t-end and --steps", "command line")
        kw = {"t_end": args.t_end, "steps": args.steps, "t0": args.t0, "every": args.every}
        if args.method is not None:
            kw["method"] = args.method
    client = connect(args.scheduler) if args.scheduler else None
    try:
        ds = sweep(model, cases, args.analysis, client, workers=args.workers, **kw)
    finally:
        if client is not None:
            client.close()
    write_sweep(ds, args.out)
    failed = int(ds.attrs["failed"])
    print(f"wrote {ds.sizes['case']} cases ({failed} failed) to {args.out}")
    for j in np.flatnonzero(ds.status.values != 0)[:5]:
        _say(f"  case {int(j)}: {ds.message.values[j]}")
    return EXIT_OK


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        model = load(args.model)
        if args.command == "check":
            print(model.analyze_dof(t=args.t))
            return EXIT_OK
        if args.command == "statics":
            print(_statics_report(model, model.statics(t=args.t)))
            return EXIT_OK
        if args.command == "export":
            model.export(args.out, t_end=args.t_end, steps=args.steps, t0=args.t0, tol=args.tol)
            print(f"wrote {args.out}")
            return EXIT_OK
        if args.command == "sweep":
            return _sweep(model, args)
        if not str(args.out).endswith((".csv", ".npz")):
            raise ModelError(f"--out must end in .csv or .npz, got {args.out!r}", "command line")
        if args.command == "dynamics":
            res = model.dynamics(t_end=args.t_end, steps=args.steps, t0=args.t0,
                                 method=args.method, rtol=args.rtol, atol=args.atol, h=args.h,
                                 rho_inf=args.rho_inf, alpha=args.alpha, beta=args.beta,
                                 every=args.every, max_steps=args.max_steps)
        else:
            res = model.kinematics(t_end=args.t_end, steps=args.steps, t0=args.t0, tol=args.tol,
                                   every=args.every, solver=args.solver)
        res.save(args.out)
        print(f"wrote {len(res.t)} rows to {args.out}")
        return EXIT_OK
    except ModelError as exc:
        _say(f"mbd2d: error in the model or the command: {exc}")
        return EXIT_INPUT
    except InsufficientMemoryError as exc:      # too large for this machine: change the input
        _say(f"mbd2d: {exc}")
        return EXIT_INPUT
    except AnalysisError as exc:
        if args.command in ("check", "statics"):
            _say(f"mbd2d: {exc}")
            return EXIT_NUMERICAL
        if exc.results is not None and len(exc.results.t):
            exc.results.save(args.out)
        _say(f"mbd2d: {exc}")
        if exc.results is not None and len(exc.results.t):
            print(f"wrote {len(exc.results.t)} rows (up to t = {exc.results.t[-1]:.6g}) to "
                  f"{args.out}", file=sys.stderr)
        return EXIT_SINGULAR if isinstance(exc, SingularConfigurationError) else EXIT_NUMERICAL
    except MbdError as exc:
        _say(f"mbd2d: {exc}")
        return EXIT_NUMERICAL
    except ImportError as exc:                  # an optional package (the sweep extra)
        _say(f"mbd2d: {exc}")
        return EXIT_INPUT


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
