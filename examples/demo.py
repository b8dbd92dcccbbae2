"""Run the four example mechanisms and write their pictures.

Usage::

    python examples/demo.py [--out DIR]

Writes ``NAME_mechanism.png`` and ``NAME_timeseries.png`` for each example to DIR (default
``examples/output/`` next to this script), animations ``fourbar_grashof.gif`` (with its
coupler curve) and ``slider_crank.gif``, the cam lift-off pictures, the design study's
three pictures (examples/design_study.py: a sweep of the crank-rocker's coupler length, the
sensitivities of the rocker angle, the tolerance of a coupler point), and the same sweep
and a sensitivity run in the standalone mbd2d-solve (examples/standalone_sweep.py), a cam
synthesized from its follower's program and run (examples/cam_design.py), a half car's
vibration modes and road response (examples/vibration_modes.py). The seed four-bar is
non-Grashof: driven past its
toggle it raises :class:`mbd2d.SingularConfigurationError`, which is the expected outcome;
its partial results are drawn with the toggle configuration marked.

Exit code 0 when every example behaved as expected, 1 otherwise.
"""
from __future__ import annotations

import argparse
import math
import sys
import textwrap
import traceback
from pathlib import Path
from typing import Any, Callable

import mbd2d
from mbd2d.plots import save_figures

HERE = Path(__file__).resolve().parent

#: largest accepted |located - closed-form| toggle time of the seed four-bar [s]
TOGGLE_TOL = 1e-8


def seed_toggle_time() -> float:
    """Closed-form toggle time of the seed four-bar (crank 3, coupler 5, rocker 2.6,
    ground 6, theta = t + pi/3): the crank angle where coupler and rocker line up."""
    return math.acos((3.0**2 + 6.0**2 - 7.6**2) / (2 * 3.0 * 6.0)) - math.pi / 3


def run_seed(path: Path, out: Path) -> tuple[str, Any, list[str]]:
    """The seed four-bar: expect a toggle error; draw the partial results."""
    model = mbd2d.load(path)
    try:
        res = model.kinematics(t_end=1.0, steps=1000)
    except mbd2d.SingularConfigurationError as err:
        print(f"{path.stem}: SingularConfigurationError (expected):")
        print(textwrap.fill(str(err), width=92, initial_indent="  ", subsequent_indent="  "))
        exact = seed_toggle_time()
        diff = err.t - exact
        print(f"  located toggle time     t = {err.t:.12f} s")
        print(f"  closed-form toggle time t = {exact:.12f} s"
              "  (arccos((9 + 36 - 7.6**2)/36) - pi/3)")
        print(f"  difference                = {diff:+.2e} s")
        if err.results is None or len(err.results.t) == 0:
            raise RuntimeError("the toggle error carries no partial results") from err
        files = save_figures(err.results, out / path.stem,
                             title=f"{model.name}: stopped at the toggle "
                                   f"(t = {err.t:.6f} s)")
        if abs(diff) > TOGGLE_TOL:
            return (f"toggle located at t = {err.t:.10f} s, {diff:+.1e} s from the closed "
                    "form", err.results, files)
        return "", err.results, files
    return ("expected a SingularConfigurationError (toggle near t = 0.886 s) but the run "
            "completed", res, save_figures(res, out / path.stem))


def run_full(path: Path, out: Path, trace: list[tuple[str, tuple[float, float]]] | None = None,
             gif: bool = False) -> tuple[str, Any, list[str]]:
    """A full crank turn; expect a complete result (and animate it when gif)."""
    res = mbd2d.load(path).kinematics(t_end=1.0, steps=360)
    files = save_figures(res, out / path.stem, trace=trace)
    if gif:
        files.append(res.animate(out / f"{path.stem}.gif", fps=30, speed=0.5, trace=trace))
    return ("" if res.complete else "the run did not complete"), res, files


def synthesis_example(out: Path) -> int:
    """examples/synthesis_straight_line.py (its exit code)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("synthesis_straight_line",
                                                  HERE / "synthesis_straight_line.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return int(mod.main(["--out", str(out)]))


def run_liftoff(path: Path, out: Path) -> tuple[str, Any, list[str]]:
    """The fast cam whose follower lifts off (examples/cam_liftoff.py): forward dynamics
    with a follower-profile contact; expect the first lift-off where the bilateral cam
    joint would start to pull."""
    sys.path.insert(0, str(HERE))
    import cam_liftoff
    code = cam_liftoff.main(["--out", str(out)])
    res = mbd2d.load(path).dynamics(0.2, 400)
    files = [str(out / f"cam_liftoff{kind}") for kind in ("_mechanism.png", "_history.png",
                                                         ".gif")]
    return ("" if code == 0 else "the follower did not lift off where the cam joint would "
            "pull"), res, files


def main(argv: list[str] | None = None) -> int:
    """Run the examples; return the exit code."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "output",
                    help="directory for the pictures (default: examples/output/)")
    ap.add_argument("--no-synthesis", action="store_true",
                    help="skip the linkage-synthesis example (it takes tens of seconds)")
    args = ap.parse_args(argv)
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)

    runs: list[tuple[str, Callable[[Path, Path], tuple[str, Any, list[str]]]]] = [
        ("fourbar_seed", run_seed),
        ("fourbar_grashof", lambda p, o: run_full(p, o, trace=[("coupler", (0.0, 1.0))],
                                                  gif=True)),
        ("slider_crank", lambda p, o: run_full(p, o, gif=True)),
        ("cam_follower", run_full),
        ("cam_liftoff", run_liftoff),
    ]
    problems: list[str] = []
    written: list[str] = []
    for name, run in runs:
        path = HERE / f"{name}.toml"
        try:
            problem, res, files = run(path, out)
        except Exception as exc:  # report every example, then fail
            traceback.print_exc()
            problems.append(f"{name}: {type(exc).__name__}: {exc}")
            print(f"{name}: FAILED ({type(exc).__name__})")
            continue
        written += files
        state = "complete" if res.complete else f"stopped after t = {res.t[-1]:g} s"
        print(f"{name}: {len(res.t)} rows ({state}) -> "
              + ", ".join(str(Path(f).name) for f in files) + f" in {out}")
        if problem:
            problems.append(f"{name}: {problem}")

    total = len(runs) + 1
    try:                         # the design study: sweeps, sensitivities, tolerances
        import design_study
        problem, files = design_study.run(out)
        written += files
        print("design_study: " + ", ".join(Path(f).name for f in files) + f" in {out}")
        if problem:
            problems.append(f"design_study: {problem}")
    except Exception as exc:  # report every example, then fail
        traceback.print_exc()
        problems.append(f"design_study: {type(exc).__name__}: {exc}")
        print(f"design_study: FAILED ({type(exc).__name__})")

    total += 1
    print("\ncam_design (a cam synthesized from its follower's program, then run):")
    try:
        sys.path.insert(0, str(HERE))
        import cam_design
        problem, res, files = cam_design.run(out)
        written += files
        print("cam_design: " + ", ".join(Path(f).name for f in files) + f" in {out}")
        if problem:
            problems.append(f"cam_design: {problem}")
    except Exception as exc:  # report every example, then fail
        traceback.print_exc()
        problems.append(f"cam_design: {type(exc).__name__}: {exc}")

    total += 1
    print("\nvibration_modes (a half car's modes about its equilibrium, model.modes, and its "
          "response to the road, model.frequency_response):")
    try:
        sys.path.insert(0, str(HERE))
        import vibration_modes
        problem, files = vibration_modes.run(out)
        written += files
        print("vibration_modes: " + ", ".join(Path(f).name for f in files) + f" in {out}")
        if problem:
            problems.append(f"vibration_modes: {problem}")
    except Exception as exc:  # report every example, then fail
        traceback.print_exc()
        problems.append(f"vibration_modes: {type(exc).__name__}: {exc}")

    total += 1
    print("\nstandalone_sweep (the design study's sweep and a sensitivity run in mbd2d-solve):")
    try:
        sys.path.insert(0, str(HERE))
        import standalone_sweep
        if standalone_sweep.main(["--out", str(out)]) != 0:
            problems.append("standalone_sweep: mbd2d-solve's files differ from the Python "
                            "path's")
    except Exception as exc:  # report every example, then fail
        traceback.print_exc()
        problems.append(f"standalone_sweep: {type(exc).__name__}: {exc}")

    if not args.no_synthesis:
        print("\nsynthesis_straight_line (linkage synthesis, issue 14):")
        try:
            if synthesis_example(out) != 0:
                problems.append("synthesis_straight_line: the design is not straighter than "
                                "the start")
        except Exception as exc:  # report every example, then fail
            traceback.print_exc()
            problems.append(f"synthesis_straight_line: {type(exc).__name__}: {exc}")
        total += 1

    print()
    pngs = sum(f.endswith(".png") for f in written)
    gifs = sum(f.endswith(".gif") for f in written)
    print(f"summary: {total - len(problems)}/{total} examples as expected, "
          f"{pngs} PNG files and {gifs} GIF animations in {out}")
    for p in problems:
        print(f"  unexpected: {p}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
