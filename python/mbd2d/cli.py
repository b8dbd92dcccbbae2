"""The ``mbd2d`` command line.

    mbd2d kinematics MODEL.toml --t-end T --steps N --out OUT.csv|OUT.npz
    mbd2d export MODEL.toml OUT.mbd --t-end T --steps N
    mbd2d check MODEL.toml

Exit codes: 0 ok, 2 bad input, 3 singular configuration (partial output written),
4 other numerical failure (partial output written when there is any).
"""
from __future__ import annotations

import argparse
import sys
import textwrap
from typing import Sequence

from .errors import AnalysisError, MbdError, ModelError, SingularConfigurationError
from .toml_io import load

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


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        model = load(args.model)
        if args.command == "check":
            print(model.analyze_dof(t=args.t))
            return EXIT_OK
        if args.command == "export":
            model.export(args.out, t_end=args.t_end, steps=args.steps, t0=args.t0, tol=args.tol)
            print(f"wrote {args.out}")
            return EXIT_OK
        if not str(args.out).endswith((".csv", ".npz")):
            raise ModelError(f"--out must end in .csv or .npz, got {args.out!r}", "command line")
        res = model.kinematics(t_end=args.t_end, steps=args.steps, t0=args.t0, tol=args.tol)
        res.save(args.out)
        print(f"wrote {len(res.t)} rows to {args.out}")
        return EXIT_OK
    except ModelError as exc:
        _say(f"mbd2d: error in the model or the command: {exc}")
        return EXIT_INPUT
    except AnalysisError as exc:
        if args.command == "check":
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


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
