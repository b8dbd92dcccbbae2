"""The frequency response: accuracy and cost against numpy's solve of the system written by
hand, and the cost per variant of a sweep of it.

* A spring chain of n blocks on guides (tests/test_frf.py's shaken chain: springs k between
  neighbours and to the ground, a damper c on the last block, a harmonic force on the first),
  n = 12, 40 and 200. Reference: (K - w^2 M + i w C) x = e_1 with the tridiagonal K,
  M = m I and C = c e_n e_n^T written here, solved by ``np.linalg.solve`` per frequency (what
  a user with the matrices in hand writes). Error: the largest |H - x| over the blocks and
  frequencies, relative to the largest |x|, beside cond(K - w^2 M + i w C) eps (its
  largest over the frequencies: what either solution can be trusted to). Time: the best
  wall time of mbd2d's whole call (statics, the null space, K, C and the input's derivatives
  from the model, the solves) and of numpy's solves alone (its matrices built outside the timing); the cost per frequency is
  the difference of the calls at 2 nw and nw frequencies over nw (mbd2d takes Laub's
  Hessenberg form from 16 free motions and 8 frequencies, docs/frf.md).
* The half car's road response (examples/half_car.toml, the front tyre's ground point) over
  its suspension damping: the cost per variant of one ``mbd2d.sweep(..., "frf")`` against a
  Python loop of ``with_params`` and ``frequency_response``, identical bit for bit (checked).

    python bench/frf.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

import mbd2d
from peers_modes import best_time

BENCH = Path(__file__).resolve().parent
EXAMPLES = BENCH.parent / "examples"
CHAIN_M, CHAIN_K, CHAIN_C = 0.5, 200.0, 5.0
ROAD = "force.front_tyre.points.0.1"
DAMPING = ("force.front_suspension.damping", "force.rear_suspension.damping")


def shaken_chain(n: int) -> tuple[mbd2d.Model, str]:
    """n blocks on horizontal guides, springs to the previous one (the first to the ground),
    a damper from the ground to the last, a force on the first; the force's input name."""
    model = mbd2d.Model(f"chain{n}", gravity=(0.0, 0.0))
    for i in range(1, n + 1):
        prev = "ground" if i == 1 else f"b{i - 1}"
        model.add_body(f"b{i}", [0.1 * i, 0.0, 0.0], mass=CHAIN_M, inertia=0.01)
        model.add_translational(["ground", f"b{i}"], [[0.0, 0.0], [0.0, 0.0]],
                                axes=[[1, 0], [1, 0]], name=f"g{i}")
        model.add_spring([prev, f"b{i}"], [[0.0, 0.0], [0.0, 0.0]], stiffness=CHAIN_K,
                         length0=0.1, name=f"s{i}")
    model.add_spring(["ground", f"b{n}"], [[0.0, 0.0], [0.0, 0.0]], damping=CHAIN_C,
                     length0=0.1 * n, name="damper")
    model.add_point_force("b1", [0.0, 0.0], fx=0.0, name="shaker")
    return model, [p for p in model.parameters() if p.startswith("force.shaker.fx")][0]


def chain_matrices(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, K, C of the chain's block displacements, written by hand."""
    kk = CHAIN_K * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kk[-1, -1] = CHAIN_K
    cc = np.zeros((n, n))
    cc[-1, -1] = CHAIN_C
    return CHAIN_M * np.eye(n), kk, cc


def numpy_response(mm: np.ndarray, kk: np.ndarray, cc: np.ndarray, f: np.ndarray) -> np.ndarray:
    """x (nw, n) of (K - w^2 M + i w C) x = e_1 at each frequency f (Hz)."""
    b = np.zeros(kk.shape[0])
    b[0] = 1.0
    return np.array([np.linalg.solve(kk - w**2 * mm + 1j * w * cc, b)
                     for w in 2 * np.pi * f])


def chain_row(n: int, nw: int, repeats: int) -> dict[str, Any]:
    """Error and times of one chain at nw and 2 nw frequencies."""
    model, name = shaken_chain(n)
    mm, kk, cc = chain_matrices(n)
    f1, f2 = np.linspace(0.05, 8.0, nw), np.linspace(0.05, 8.0, 2 * nw)
    t1, res = best_time(lambda: model.frequency_response(name, f1), repeats)
    t2, _ = best_time(lambda: model.frequency_response(name, f2), repeats)
    n1, want = best_time(lambda: numpy_response(mm, kk, cc, f1), repeats)
    n2, _ = best_time(lambda: numpy_response(mm, kk, cc, f2), repeats)
    got = res.response[:, 0::3, 0]
    cond = max(np.linalg.cond(kk - w**2 * mm + 1j * w * cc) for w in 2 * np.pi * f1)
    return {"n": n, "frequencies": nw, "solver": res.stats["solver"],
            "error": float(np.abs(got - want).max() / np.abs(want).max()),
            "cond_eps": float(cond * np.finfo(float).eps),
            "mbd2d_s": t1, "numpy_s": n1, "ratio": t1 / n1,
            "mbd2d_per_frequency_s": max(t2 - t1, 0.0) / nw,
            "numpy_per_frequency_s": max(n2 - n1, 0.0) / nw}


def sweep_row(ncase: int, nw: int, repeats: int) -> dict[str, Any]:
    """The half car's road response over ncase dampings: batched against a loop."""
    car = mbd2d.load(EXAMPLES / "half_car.toml")
    cases = {name: np.linspace(500.0, 3000.0, ncase) for name in DAMPING}
    f = np.geomspace(0.1, 30.0, nw)

    def batched() -> Any:
        return mbd2d.sweep(car, cases, "frf", inputs=[ROAD], frequencies=f, workers=1,
                           progress=False)

    def loop() -> list[np.ndarray]:
        return [car.with_params({k: v[c] for k, v in cases.items()})
                .frequency_response(ROAD, f).response for c in range(ncase)]

    tb, ds = best_time(batched, repeats)
    tl, each = best_time(loop, repeats)
    same = all(np.array_equal(each[c], ds.response.values[c]) for c in range(ncase))
    return {"cases": ncase, "frequencies": nw, "batched_per_case_s": tb / ncase,
            "loop_per_case_s": tl / ncase, "ratio": tl / tb, "identical": same}


def study(quick: bool = False) -> dict[str, Any]:
    """The chains and the sweep (quick: the small chain and a short sweep)."""
    repeats = 2 if quick else 5
    chains = [chain_row(n, 50, repeats) for n in ((12,) if quick else (12, 40, 200))]
    sweeps = [sweep_row(8 if quick else 200, nw, 1 if quick else 2)
              for nw in ((10,) if quick else (10, 100))]
    return {"chains": chains, "sweeps": sweeps, "quick": quick}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    print(json.dumps(study(a.quick), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
