"""Kinematics speed: microseconds per output step (position + velocity + acceleration).

Three ways of running the same kinematic analysis, on the four-bar
(examples/fourbar_grashof.toml) and the slider-crank (examples/slider_crank.toml):

(a) the Fortran loop: the whole time loop inside the core, one f2py call per analysis
    (``core_us_per_step``: the core entry point of ``Model.kinematics`` called directly);
(b) driven from Python, one f2py call per step: ``mbd2d.KinematicStepper(model).step(t)``
    (``stepper_us_per_step``; recorded as not available when the installed mbd2d lacks it);
(c) plain NumPy: bench/numpy_kinematics.py, the same algorithm written with NumPy alone.

``compare`` times all three at the same step size h (default 1 ms: every step then needs a
Newton correction in each of them) and computes the ratios in the same run. Each figure is
the best-of-N wall time (time.perf_counter) divided by the number of steps.

    python bench/kinematics_speed.py [--steps N] [--repeats R] [--quick]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import mbd2d
from mbd2d import _core
from mbd2d.binding.core import new_ctl
from mbd2d.binding.pack import pack

BENCH = Path(__file__).resolve().parent
EX = BENCH.parent / "examples"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))
import numpy_kinematics  # noqa: E402

CASES = {"four-bar (Grashof)": "fourbar_grashof.toml", "slider-crank": "slider_crank.toml",
         "eccentric cam": "cam_follower.toml"}
#: the two models of the comparison (label: example stem)
COMPARED = {"four-bar (Grashof)": "fourbar_grashof", "slider-crank": "slider_crank"}
H = 1e-3                  # step size of the comparison (s)
LOOP_STEPS = 100_000      # (a)
STEPPER_STEPS = 20_000    # (b)
NUMPY_STEPS = 1000        # (c)


def core_us_per_step(model: mbd2d.Model, t_end: float, steps: int, repeats: int) -> dict:
    """Best-of-repeats wall time of one core call, per output step."""
    p = pack(model)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = _core.core_kinematics(p.nb, p.ctab, p.rpar, p.neq, p.q0, 0.0, t_end, steps,
                                    0.0, 0, 0.0, 1, 0, steps + 1, 0, steps + 1, new_ctl())
        best = min(best, time.perf_counter() - t0)
        status, msg = out[-2], out[-1]
        assert status == 0, msg
    iinfo = out[3]
    return {"us_per_step": 1e6 * best / steps, "steps": steps,
            "newton_corrections_per_step": int(iinfo[5]) / steps,
            "lu_per_step": int(iinfo[6]) / steps}


def loop_us_per_step(model: mbd2d.Model, t_end: float, steps: int, repeats: int) -> dict:
    """(a) The Fortran loop: ``core_us_per_step``, or (when the core's signature differs from
    the one this script knows) one ``model.kinematics`` call keeping only the last row."""
    try:
        return core_us_per_step(model, t_end, steps, repeats)
    except TypeError as e:
        best = float("inf")
        for _ in range(repeats):
            t0 = time.perf_counter()
            res = model.kinematics(t_end=t_end, steps=steps, every=steps)
            best = min(best, time.perf_counter() - t0)
        return {"us_per_step": 1e6 * best / steps, "steps": steps,
                "newton_corrections_per_step": res.stats["newton_corrections"] / steps,
                "lu_per_step": res.stats["factorizations"] / steps,
                "note": f"timed through model.kinematics(every=steps): {e}"}


def stepper_us_per_step(model: mbd2d.Model, h: float, steps: int, repeats: int) -> dict:
    """(b) One ``KinematicStepper.step`` call per step, the loop in Python.

    Returns
    -------
    dict
        {"us_per_step", "steps"}, or {"available": False, "message"} without
        mbd2d.KinematicStepper.
    """
    stepper_cls = getattr(mbd2d, "KinematicStepper", None)
    if stepper_cls is None:
        return {"available": False,
                "message": "mbd2d.KinematicStepper is not in this mbd2d version"}
    times = [h * k for k in range(1, steps + 1)]
    best = float("inf")
    for _ in range(repeats):
        stepper = stepper_cls(model, t0=0.0)
        step = stepper.step
        t0 = time.perf_counter()
        for t in times:
            step(t)
        best = min(best, time.perf_counter() - t0)
    return {"available": True, "us_per_step": 1e6 * best / steps, "steps": steps}


def numpy_us_per_step(stem: str, h: float, steps: int, repeats: int) -> dict:
    """(c) The plain NumPy implementation (bench/numpy_kinematics.py) over steps * h."""
    numpy_kinematics.analyze(stem, 10 * h, 10)          # parse the file once, warm up
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        numpy_kinematics.analyze(stem, steps * h, steps)
        best = min(best, time.perf_counter() - t0)
    return {"us_per_step": 1e6 * best / steps, "steps": steps}


def compare_case(stem: str, h: float, repeats: int, quick: bool) -> dict:
    """(a), (b), (c) and their ratios for one example at step size h."""
    scale = 5 if quick else 1
    model = mbd2d.load(EX / f"{stem}.toml")
    loop = loop_us_per_step(model, LOOP_STEPS // scale * h, LOOP_STEPS // scale, repeats)
    stepper = stepper_us_per_step(model, h, STEPPER_STEPS // scale, repeats)
    npy = numpy_us_per_step(stem, h, NUMPY_STEPS, repeats)
    fine = loop_us_per_step(model, 10.0, LOOP_STEPS // scale, repeats)
    out = {"h": h, "fortran_loop": loop, "python_stepper": stepper, "numpy": npy,
           "fortran_loop_h1e-4": fine,
           "agreement_numpy_vs_mbd2d": numpy_kinematics.check(stem)}
    out["ratio_numpy_over_loop"] = npy["us_per_step"] / loop["us_per_step"]
    if stepper.get("available"):
        out["ratio_numpy_over_stepper"] = npy["us_per_step"] / stepper["us_per_step"]
        out["ratio_stepper_over_loop"] = stepper["us_per_step"] / loop["us_per_step"]
    return out


def compare(h: float = H, repeats: int = 5, quick: bool = False, log: bool = True) -> dict:
    """The three ways on both models at step size h, with the ratios.

    Parameters
    ----------
    h : float
        Step size (s) of every run.
    repeats : int
        Best of this many runs.
    quick : bool
        Five times fewer steps for (a) and (b).
    log : bool
        Print one line per model.

    Returns
    -------
    dict
        {label: compare_case(...)}.
    """
    rows = {}
    for label, stem in COMPARED.items():
        r = rows[label] = compare_case(stem, h, repeats, quick)
        if log:
            st = r["python_stepper"]
            st_txt = f"{st['us_per_step']:7.2f}" if st.get("available") else "    n/a"
            print(f"  {label:20s} Fortran loop {r['fortran_loop']['us_per_step']:6.3f} "
                  f"us/step (h = 1e-4: {r['fortran_loop_h1e-4']['us_per_step']:.3f})   "
                  f"Python stepper {st_txt} us/step   NumPy "
                  f"{r['numpy']['us_per_step']:7.1f} us/step   NumPy / loop "
                  f"{r['ratio_numpy_over_loop']:5.0f}x", flush=True)
    return rows


def main() -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="fewer steps in the comparison")
    args = ap.parse_args()
    rows = {}
    for label, f in CASES.items():
        m = mbd2d.load(EX / f)
        # one crank turn per second; 10 turns
        rows[label] = core_us_per_step(m, 10.0, args.steps, args.repeats)
        r = rows[label]
        print(f"{label:22s} {r['us_per_step']:7.3f} us/step  "
              f"({r['newton_corrections_per_step']:.2f} Newton corrections, "
              f"{r['lu_per_step']:.2f} LU per step)")
    print(f"comparison at h = {H} s:")
    return {"fortran_loop_h1e-4": rows, "comparison": compare(H, args.repeats, args.quick)}


if __name__ == "__main__":
    print(json.dumps(main(), indent=1))
