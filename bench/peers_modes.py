"""Vibration modes side by side with Exudyn (``mbs.ComputeODE2Eigenvalues``), against closed
forms.

* Hanging double pendulum (two bars pinned end to end; tests/test_modes.py's): omega^2 from
  the 2 x 2 mass and stiffness matrices written by hand. Its stiffness comes wholly from the
  constraints' curvature under the multipliers (gravity acts through the pins). Exudyn:
  NodeRigidBody2D + ObjectRigidBody2D, two ObjectJointRevolute2D, LoadMassProportional; its
  eigenvalues of the constrained system (the null-space projection of its ODE2 stiffness at
  the initial state, ``ignoreAlgebraicEquations=False``).
* Fixed-free chain of n masses and springs on a line (n = 40 and 400): omega_j =
  2 sqrt(k/m) sin((2j - 1) pi / (2 (2n + 1))). mbd2d: blocks on translational joints
  (tests/test_modes.py's spring_chain, band path at 400); Exudyn: NodePoint2D +
  ObjectMassPoint2D, ObjectConnectorSpringDamper, the y coordinates constrained
  (``constrainedCoordinates``).

Error: the largest relative error of omega over the modes (pendulum: of omega^2). Time: the
best of a few wall-clock runs of the call alone: ``model.modes()``, which finds the
equilibrium first, and ``model.modes(equilibrium=False)``, about the assembled q0 as Exudyn
takes its initial state; ``mbs.ComputeODE2Eigenvalues()`` on the assembled system (undamped
eigenvalues only).

    python bench/peers_modes.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

import mbd2d

BENCH = Path(__file__).resolve().parent
TESTS = BENCH.parent / "tests"
G = 9.81
PENDULUM = (1.5, 0.7, 0.9, 0.6, 0.11, 0.03)          # m1, m2, l1, l2, I1, I2
CHAIN_M, CHAIN_K, CHAIN_L = 0.5, 200.0, 0.1


def best_time(fn: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    """The best wall time of repeats calls, and the last result."""
    best, out = float("inf"), None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def pendulum_exact() -> np.ndarray:
    """omega^2 of the hanging double pendulum from its 2 x 2 matrices."""
    m1, m2, l1, l2, i1, i2 = PENDULUM
    a1, a2 = l1 / 2, l2 / 2
    mm = np.array([[i1 + m1 * a1**2 + m2 * l1**2, m2 * l1 * a2],
                   [m2 * l1 * a2, i2 + m2 * a2**2]])
    kk = G * np.diag([m1 * a1 + m2 * l1, m2 * a2])
    return np.sort(np.linalg.eigvals(np.linalg.solve(mm, kk)).real)


def chain_exact(n: int) -> np.ndarray:
    """omega of the fixed-free chain."""
    j = np.arange(1, n + 1)
    return 2 * np.sqrt(CHAIN_K / CHAIN_M) * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))


def mbd2d_models() -> tuple[Callable[..., mbd2d.Model], Callable[[int], mbd2d.Model]]:
    """The tests' double pendulum and spring chain builders."""
    if str(TESTS) not in sys.path:
        sys.path.insert(0, str(TESTS))
    import test_modes
    return test_modes.double_pendulum, test_modes.spring_chain


def exudyn_pendulum() -> Any:
    """The double pendulum in Exudyn, assembled at the hanging equilibrium; (container,
    system)."""
    import exudyn as exu
    from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass, MarkerBodyPosition,
                                      NodeRigidBody2D, ObjectGround, ObjectJointRevolute2D,
                                      ObjectRigidBody2D)
    m1, m2, l1, l2, i1, i2 = PENDULUM
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    bodies = []
    for y, m, inertia in ((-l1 / 2, m1, i1), (-l1 - l2 / 2, m2, i2)):
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[0.0, y, -np.pi / 2]))
        body = mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=m, inertia=inertia))
        mk = mbs.AddMarker(MarkerBodyMass(bodyNumber=body))
        mbs.AddLoad(LoadMassProportional(markerNumber=mk, loadVector=[0.0, -G, 0.0]))
        bodies.append(body)

    def at(body: Any, x: float) -> Any:
        return mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[x, 0.0, 0.0]))
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[at(ground, 0.0), at(bodies[0], -l1 / 2)]))
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[at(bodies[0], l1 / 2),
                                                       at(bodies[1], -l2 / 2)]))
    mbs.Assemble()
    return sc, mbs


def exudyn_chain(n: int) -> tuple[Any, Any, list[int]]:
    """The chain in Exudyn, assembled; (container, system, the constrained y coordinates)."""
    import exudyn as exu
    from exudyn.itemInterface import (MarkerBodyPosition, NodePoint2D, ObjectConnectorSpringDamper,
                                      ObjectGround, ObjectMassPoint2D)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    prev = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    for i in range(1, n + 1):
        node = mbs.AddNode(NodePoint2D(referenceCoordinates=[i * CHAIN_L, 0.0]))
        body = mbs.AddObject(ObjectMassPoint2D(mass=CHAIN_M, nodeNumber=node))
        mk = mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
        mbs.AddObject(ObjectConnectorSpringDamper(markerNumbers=[prev, mk], stiffness=CHAIN_K,
                                                  damping=0.0, referenceLength=CHAIN_L))
        prev = mk
    mbs.Assemble()
    return sc, mbs, [2 * i + 1 for i in range(n)]


def exudyn_eigenvalues(mbs: Any, constrained: list[int] | None = None) -> np.ndarray:
    """omega^2 of Exudyn's ComputeODE2Eigenvalues (sorted; its output quieted)."""
    import exudyn as exu
    old = exu.config.printToConsole
    exu.config.printToConsole = False
    try:
        ev = mbs.ComputeODE2Eigenvalues(constrainedCoordinates=constrained or [],
                                        useAbsoluteValues=False)
    finally:
        exu.config.printToConsole = old
    return np.sort(np.asarray(ev[0], dtype=float))


def available() -> tuple[bool, str]:
    """Whether Exudyn can be imported: (True, version) or (False, why not)."""
    try:
        import exudyn
    except Exception as e:  # ImportError, or a broken binary wheel
        return False, f"import exudyn failed: {type(e).__name__}: {e}"
    return True, str(getattr(exudyn, "__version__", "?"))


def study(quick: bool = False) -> dict[str, Any]:
    """Both models in both codes: errors against the closed forms and times."""
    ok, info = available()
    repeats = 2 if quick else 5
    pend, chain = mbd2d_models()
    rows: list[dict[str, Any]] = []
    want = pendulum_exact()
    model = pend(*PENDULUM)
    t, res = best_time(lambda: model.modes(), repeats)
    t0, _ = best_time(lambda: model.modes(equilibrium=False), repeats)
    row: dict[str, Any] = {"model": "double pendulum (omega^2)", "n_free": 2,
                           "exact": want.tolist(), "mbd2d": res.omega2.tolist(),
                           "mbd2d_error": float(np.abs(res.omega2 / want - 1).max()),
                           "mbd2d_s": t, "mbd2d_q0_s": t0}
    if ok:
        sc, mbs = exudyn_pendulum()
        te, ev = best_time(lambda: exudyn_eigenvalues(mbs), repeats)
        free = ev[np.argsort(np.abs(ev))][-2:] if ev.size >= 2 else ev
        row.update(exudyn=np.sort(free).tolist(), exudyn_s=te,
                   exudyn_error=float(np.abs(np.sort(free) / want - 1).max()))
        del sc
    rows.append(row)
    for n in ((40,) if quick else (40, 400)):
        want = chain_exact(n)
        solver = "banded" if n > 100 else "dense"
        model = chain(n, CHAIN_M, CHAIN_K)
        t, res = best_time(lambda: model.modes(solver=solver), repeats)
        t0, _ = best_time(lambda: model.modes(solver=solver, equilibrium=False), repeats)
        row = {"model": f"spring chain n = {n} (omega)", "n_free": n, "solver": solver,
               "mbd2d_error": float(np.abs(res.omega / want - 1).max()), "mbd2d_s": t,
               "mbd2d_q0_s": t0}
        if ok:
            sc, mbs, fixed = exudyn_chain(n)
            te, ev = best_time(lambda: exudyn_eigenvalues(mbs, fixed), repeats)
            w = np.sqrt(np.clip(ev, 0.0, None))
            row.update(exudyn_s=te, exudyn_error=float(np.abs(w / want - 1).max())
                       if w.size == n else None)
            del sc
        rows.append(row)
    for r in rows:
        if r.get("exudyn_s"):
            r["time_ratio"] = r["mbd2d_q0_s"] / r["exudyn_s"]     # > 1: Exudyn faster
    return {"exudyn_available": ok, "exudyn": info if ok else None,
            "exudyn_unavailable_reason": None if ok else info, "rows": rows, "quick": quick}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    print(json.dumps(study(a.quick), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
