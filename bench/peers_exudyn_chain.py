"""Peer comparison on a large model: the free N-four-bar in Exudyn and mbd2d, generalized-alpha.

Model: examples/nfourbar.py ``build(n, driven=False, omega0=1.0)``: N + 1 cranks and N couplers,
uniform 1 kg, 1 m bars (inertia 1/12 kg m^2), gravity -9.81 m/s^2 in y, ground pivots at
x = 0 .. N, every crank upright and turning at 1 rad/s, the couplers translating (a
consistent start). 6N + 3 coordinates, 6N + 2 constraint rows (none redundant), one degree of
freedom. In Exudyn: NodeRigidBody2D + ObjectRigidBody2D per bar (reference coordinates = the
start, initial velocities = the start's), MarkerBodyPosition at the bar ends, 3N + 1
ObjectJointRevolute2D, gravity as LoadMassProportional; its sparse solver
(LinearSolverType.EigenSparse), index-3 generalized-alpha at a fixed h (adaptive step off,
rho_inf = 0.9 in both codes, Exudyn's default Newton settings). mbd2d: ``model.dynamics(...,
method="generalized-alpha", h=h, rho_inf=0.9)`` on its band path (auto).

Reference, computed here without either code: every crank stays parallel to the first and the
couplers translate, so the chain is a one-degree-of-freedom system in the crank angle theta
(from the x axis): T = 1/2 theta_dot^2 ((N + 1) m L^2 / 3 + N m L^2),
V = m g sin(theta) ((N + 1) L / 2 + N L), hence
theta_ddot = -g cos(theta) ((N + 1)/2 + N) / ((N + 1)/3 + N)   (m = L = 1),
integrated by scipy's DOP853 at rtol = atol = 1e-13. Error: the largest |theta_0 - theta_ref|
of the first crank over the outputs. The run (T_END = 0.5 s) ends before the cranks reach the
horizontal (the collinear, singular position, near t = 0.7 s).

Time: best-of-R wall time (time.perf_counter) of the solve call alone (Exudyn's
mbs.SolveDynamic, which includes its solver initialization, as mbd2d's model.dynamics includes
its start); both models are built (and Exudyn's assembled) before.

    python bench/peers_exudyn_chain.py [--n 100 1000] [--h 1e-3] [--repeats R] [--quick]

The module imports without Exudyn; ``peers_exudyn.available()`` says whether it can be used.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import mbd2d

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
for _p in (BENCH, ROOT / "examples"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))
from nfourbar import build  # noqa: E402
from peers_exudyn import RHO_INF, _exudyn, _quiet_settings, available, best_of  # noqa: E402

Row = dict[str, Any]
G = 9.81
OMEGA0 = 1.0
T_END = 0.5
OUTPUTS = 50
N_VALUES = (10, 100, 1000)
H_VALUES = (1e-3,)
TARGET = 3.0


# ===================================================================== reference
def reference(n: int, t: np.ndarray) -> np.ndarray:
    """The first crank's angle at times t from the reduced one-dof equation (DOP853)."""
    from scipy.integrate import solve_ivp
    c = ((n + 1) / 2 + n) / ((n + 1) / 3 + n)

    def f(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -G * c * math.cos(y[0])]

    sol = solve_ivp(f, (0.0, float(t[-1])), [math.pi / 2, OMEGA0], method="DOP853",
                    rtol=1e-13, atol=1e-13, t_eval=t)
    return np.asarray(sol.y[0], dtype=float)


# ===================================================================== Exudyn
def build_exudyn(n: int) -> tuple[Any, Any, Any]:
    """The chain in Exudyn, assembled. Returns (SystemContainer, MainSystem, sensor of crank 0)."""
    exu = _exudyn()
    from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass, MarkerBodyPosition,
                                      NodeRigidBody2D, ObjectGround, ObjectJointRevolute2D,
                                      ObjectRigidBody2D, SensorNode)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
    w = OMEGA0

    def bar(q: list[float], v: list[float]) -> tuple[Any, Any]:
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=q, initialVelocities=v))
        body = mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=1.0, inertia=1.0 / 12))
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(
            bodyNumber=body)), loadVector=[0.0, -G, 0.0]))
        return node, body

    def pin(bi: Any, pi: tuple[float, float], bj: Any, pj: tuple[float, float]) -> None:
        mi = mbs.AddMarker(MarkerBodyPosition(bodyNumber=bi, localPosition=[*pi, 0.0]))
        mj = mbs.AddMarker(MarkerBodyPosition(bodyNumber=bj, localPosition=[*pj, 0.0]))
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[mi, mj]))

    cranks = [bar([float(k), 0.5, math.pi / 2], [-0.5 * w, 0.0, w]) for k in range(n + 1)]
    couplers = [bar([k + 0.5, 1.0, 0.0], [-w, 0.0, 0.0]) for k in range(n)]
    for k in range(n + 1):
        pin(ground, (float(k), 0.0), cranks[k][1], (-0.5, 0.0))
    for k in range(n):
        pin(cranks[k][1], (0.5, 0.0), couplers[k][1], (-0.5, 0.0))
        pin(cranks[k + 1][1], (0.5, 0.0), couplers[k][1], (0.5, 0.0))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=cranks[0][0], storeInternal=True,
                                      writeToFile=False,
                                      outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    return sc, mbs, sensor


def exudyn_row(n: int, h: float, t_out: np.ndarray, ref: np.ndarray, repeats: int) -> Row:
    """Exudyn's generalized-alpha on the chain: time, error, Newton statistics."""
    exu = _exudyn()
    row: Row = {"code": "Exudyn", "n": n, "h": h, "error": None, "seconds": None}
    t0 = time.perf_counter()
    sc, mbs, sensor = build_exudyn(n)
    row["build_s"] = time.perf_counter() - t0
    s = _quiet_settings(exu, float(t_out[1] - t_out[0]))
    if hasattr(s, "linearSolver"):             # Exudyn >= 1.10
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    else:
        s.linearSolverType = exu.LinearSolverType.EigenSparse
    ti = s.timeIntegration
    ti.solverType = exu.DynamicSolverType.GeneralizedAlpha
    ti.endTime = float(t_out[-1])
    ti.numberOfSteps = int(round(t_out[-1] / h))
    ti.adaptiveStep = False
    ti.generalizedAlpha.spectralRadius = RHO_INF
    ti.generalizedAlpha.useIndex2Constraints = False
    ti.generalizedAlpha.useNewmark = False
    try:
        seconds, _ = best_of(lambda: mbs.SolveDynamic(s), repeats, budget_s=30.0)
    except Exception as e:  # exudyn's solver errors
        row["message"] = f"{type(e).__name__}: {e}"
        return row
    data = np.asarray(mbs.GetSensorStoredData(sensor))
    idx = np.clip(np.searchsorted(data[:, 0], t_out - 1e-9), 0, len(data) - 1)
    theta = data[idx, 3] + math.pi / 2
    it = mbs.sys["dynamicSolver"].it
    steps = int(it.currentStepIndex) - 1
    row.update(error=float(np.max(np.abs(theta - ref))), seconds=seconds, steps=steps,
               ms_per_step=1e3 * seconds / max(steps, 1),
               newton_iterations=int(it.newtonStepsCount),
               jacobians=int(it.newtonJacobiCount),
               time_mismatch=float(np.max(np.abs(data[idx, 0] - t_out))))
    del sc
    return row


# ===================================================================== mbd2d
def mbd2d_row(n: int, h: float, t_out: np.ndarray, ref: np.ndarray, repeats: int) -> Row:
    """mbd2d's generalized-alpha on the chain (band path): time and error."""
    m = build(n, driven=False, omega0=OMEGA0)
    row: Row = {"code": "mbd2d", "n": n, "h": h, "error": None, "seconds": None}

    def run() -> Any:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", mbd2d.errors.MbdWarning)
            return m.dynamics(t_end=float(t_out[-1]), steps=len(t_out) - 1,
                              method="generalized-alpha", h=h, rho_inf=RHO_INF)
    try:
        seconds, res = best_of(run, repeats, budget_s=30.0)
    except mbd2d.MbdError as e:
        row["message"] = f"{type(e).__name__}: {e}"
        return row
    theta = np.asarray(res.body("crank0").theta, dtype=float)
    steps = int(res.stats["steps"])
    row.update(error=float(np.max(np.abs(theta - ref))), seconds=seconds, steps=steps,
               ms_per_step=1e3 * seconds / max(steps, 1),
               newton_iterations=int(res.stats["newton_iterations"]),
               jacobians=int(res.stats["iteration_matrices"]), solver=res.stats.get("solver"))
    return row


# ===================================================================== study
def study(n_values: Sequence[int] = N_VALUES, h_values: Sequence[float] = H_VALUES,
          repeats: int = 3, t_end: float = T_END, log: bool = True) -> dict[str, Any]:
    """Both codes at each N and h; the ratios Exudyn / mbd2d and the target check."""
    ok, info = available()
    out: dict[str, Any] = {"model": "free N-four-bar (examples/nfourbar.py, omega0 = 1)",
                           "t_end": t_end, "outputs": OUTPUTS, "rho_inf": RHO_INF,
                           "target": TARGET, "rows": []}
    if not ok:
        out["unavailable"] = info
        return out
    out["exudyn_version"] = info
    t_out = np.linspace(0.0, t_end, OUTPUTS + 1)
    for n in n_values:
        ref = reference(n, t_out)
        for h in h_values:
            ours = mbd2d_row(n, h, t_out, ref, repeats)
            theirs = exudyn_row(n, h, t_out, ref, repeats)
            ratio = (theirs["seconds"] / ours["seconds"]
                     if theirs.get("seconds") and ours.get("seconds") else None)
            out["rows"].append({"n": n, "h": h, "mbd2d": ours, "exudyn": theirs,
                                "ratio": ratio})
            if log:
                def txt(r: Row) -> str:
                    if r.get("seconds") is None:
                        return f"failed ({r.get('message')})"
                    return (f"{r['ms_per_step']:8.3f} ms/step, error {r['error']:.2e}, "
                            f"{r['newton_iterations']} Newton its")
                print(f"  N = {n:5d} h = {h:g}: mbd2d {txt(ours)} | Exudyn {txt(theirs)}"
                      + (f" | Exudyn / mbd2d {ratio:.1f}x" if ratio else ""), flush=True)
    need = [r for r in out["rows"] if r["n"] in (100, 1000)]
    out["meets_target"] = (bool(need) and all(r["ratio"] is not None and r["ratio"] >= TARGET
                                               for r in need))
    return out


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="*", default=list(N_VALUES))
    ap.add_argument("--h", type=float, nargs="*", default=list(H_VALUES))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="N = 10 and 100, one repeat")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    data = study((10, 100) if a.quick else a.n, a.h, 1 if a.quick else a.repeats)
    if a.out:
        a.out.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return data


if __name__ == "__main__":
    main()
