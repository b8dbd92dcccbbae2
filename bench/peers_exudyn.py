"""Peer comparison with Exudyn (PyPI ``exudyn``): the same models, side by side with mbd2d.

* Free four-bar (bench/models.free_fourbar), 10 s under gravity from rest, generalized-alpha
  at fixed step sizes h in both codes, the same spectral radius (rho_inf = 0.9, which is also
  Exudyn's default). Exudyn model: NodeRigidBody2D + ObjectRigidBody2D per bar (reference
  coordinates = mbd2d's assembled q0), MarkerBodyPosition at the bar ends, four
  ObjectJointRevolute2D (two of them to an ObjectGround), gravity as LoadMassProportional on a
  MarkerBodyMass. Exudyn integrates with its default index-3 generalized-alpha (modified Newton,
  its default Newton tolerances); adaptive step reduction is switched off so that h is really
  fixed. The three angles are recorded by SensorNode(storeInternal=True) at the output times.
  Error: max over the outputs and the three bodies of |theta - theta_ref| (unwrapped angles;
  Exudyn's rotation coordinate is relative to the reference angle, which is added back), the
  reference being a tight mbd2d dopri5 run (rtol 1e-12, atol 1e-14). Time: best-of-N wall time
  (time.perf_counter) of the solve call alone (mbs.SolveDynamic, which includes Exudyn's solver
  initialization, as model.dynamics includes mbd2d's); the model is built and assembled before.
* Kinematic stepping of the driven four-bar (examples/fourbar_grashof.toml, crank theta = 2 pi
  t): Exudyn has no kinematic solver; a static solve per output time with the crank angle
  prescribed by a CoordinateConstraint is the documented way. Three variants are timed (a
  Python loop that sets the constraint offset and calls mbs.SolveStatic per step; one
  mbs.SolveStatic with one load step per output time and a Python offsetUserFunction; the same
  with a symbolic (C++-evaluated) user function), and the fastest is compared with
  model.kinematics (which also computes velocities and accelerations). Error: max abs
  difference of all body coordinates (x, y, theta) from the closed form.

    python bench/peers_exudyn.py [--out PATH] [--repeats R] [--quick] [--exudyn-fast]

The module imports without Exudyn; ``available()`` says whether it can be used and why not.
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np

import mbd2d

BENCH = Path(__file__).resolve().parent
EXAMPLES = BENCH.parent / "examples"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))
from models import FOURBAR_BARS, FOURBAR_GROUND, G, free_fourbar  # noqa: E402

Row = dict[str, Any]
BODIES = tuple(name for name, _, _ in FOURBAR_BARS)      # crank, coupler, rocker
# revolute joints of the four-bar: (body i or None for ground, point on i, body j, point on j)
JOINTS = ((None, (0.0, 0.0), 0, (-0.5, 0.0)),
          (0, (0.5, 0.0), 1, (-1.75, 0.0)),
          (1, (1.75, 0.0), 2, (-1.25, 0.0)),
          (2, (1.25, 0.0), None, (FOURBAR_GROUND, 0.0)))
RHO_INF = 0.9
T_END = 10.0
OUTPUTS = 100                       # 101 uniform output times 0 .. T_END
H_VALUES = (1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)
KIN_FILE = EXAMPLES / "fourbar_grashof.toml"
KIN_STEPS = 10_000
CRANK_OMEGA = 2.0 * math.pi         # rad/s, the motor of fourbar_grashof.toml
TIME_BUDGET_S = 4.0                 # stop repeating a setting once this much time is spent


# ===================================================================== helpers
def available() -> tuple[bool, str]:
    """Whether Exudyn can be imported.

    Returns
    -------
    tuple[bool, str]
        (True, version) or (False, the reason it cannot be used).
    """
    try:
        import exudyn
    except Exception as e:  # ImportError, or a broken binary wheel
        return False, f"import exudyn failed: {type(e).__name__}: {e}"
    return True, str(getattr(exudyn, "__version__", "unknown"))


def _exudyn() -> Any:
    """Import exudyn (lazily), or raise RuntimeError with the reason."""
    ok, info = available()
    if not ok:
        raise RuntimeError(info)
    import exudyn
    return exudyn


def best_of(fn: Callable[[], Any], repeats: int,
            budget_s: float = TIME_BUDGET_S) -> tuple[float, Any]:
    """Best wall time of up to `repeats` calls of fn (fewer once `budget_s` is spent).

    Parameters
    ----------
    fn : callable
        The timed call, without arguments.
    repeats : int
        Maximum number of calls (at least one is made).
    budget_s : float
        No further call is started once the calls so far took this long in total.

    Returns
    -------
    tuple[float, Any]
        The best time in seconds and the return value of the last call.
    """
    best, spent, out = math.inf, 0.0, None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t0
        best, spent = min(best, dt), spent + dt
        if spent >= budget_s:
            break
    return best, out


def angle_error(theta: np.ndarray, ref_theta: np.ndarray) -> float:
    """Max abs difference of two (n, k) arrays of angles, each unwrapped along time."""
    d = np.unwrap(np.asarray(theta, float), axis=0) - np.unwrap(np.asarray(ref_theta, float),
                                                                axis=0)
    return float(np.max(np.abs(d)))


# ===================================================================== reference (mbd2d)
def initial_state() -> np.ndarray:
    """mbd2d's assembled q0 of the free four-bar (x, y, theta of crank, coupler, rocker)."""
    res = free_fourbar().dynamics(t_end=0.01, steps=1)
    return np.asarray(res.q[0], dtype=float)


def reference(t_end: float = T_END, outputs: int = OUTPUTS) -> tuple[np.ndarray, np.ndarray]:
    """The reference angles of the free four-bar: mbd2d dopri5 at rtol 1e-12, atol 1e-14.

    Returns
    -------
    tuple[np.ndarray, np.ndarray]
        ref_t (outputs + 1,) and ref_theta (outputs + 1, 3).
    """
    res = free_fourbar().dynamics(t_end=t_end, steps=outputs, method="dopri5",
                                  rtol=1e-12, atol=1e-14)
    theta = np.column_stack([res.body(name).theta for name in BODIES])
    return np.asarray(res.t, dtype=float), theta


# ===================================================================== Exudyn: free four-bar
def _add_bar(mbs: Any, q: np.ndarray, length: float, density: float,
             gravity: bool) -> tuple[Any, Any]:
    """A uniform bar as NodeRigidBody2D + ObjectRigidBody2D with reference coordinates q.

    Returns
    -------
    tuple
        (node index, body index).
    """
    from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass,
                                      NodeRigidBody2D, ObjectRigidBody2D)
    mass = density * length
    node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[float(v) for v in q]))
    body = mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=mass,
                                           inertia=mass * length ** 2 / 12))
    if gravity:
        marker = mbs.AddMarker(MarkerBodyMass(bodyNumber=body))
        mbs.AddLoad(LoadMassProportional(markerNumber=marker, loadVector=[0.0, -G, 0.0]))
    return node, body


def _add_revolutes(mbs: Any, ground: Any, bodies: list[Any]) -> None:
    """The four ObjectJointRevolute2D of the four-bar, markers at the bar ends."""
    from exudyn.itemInterface import MarkerBodyPosition, ObjectJointRevolute2D

    def marker(body: Any, point: tuple[float, float]) -> Any:
        return mbs.AddMarker(MarkerBodyPosition(bodyNumber=body,
                                                localPosition=[point[0], point[1], 0.0]))

    for i, pi, j, pj in JOINTS:
        bi = ground if i is None else bodies[i]
        bj = ground if j is None else bodies[j]
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[marker(bi, pi), marker(bj, pj)]))


def build_fourbar(q0: np.ndarray, gravity: bool = True) -> tuple[Any, Any, list[Any]]:
    """The four-bar in Exudyn (not yet assembled).

    Parameters
    ----------
    q0 : np.ndarray
        (9,) consistent coordinates (x, y, theta of crank, coupler, rocker): the nodes'
        reference coordinates; the initial displacements are zero.
    gravity : bool
        Add g = 9.81 m/s^2 in -y (LoadMassProportional).

    Returns
    -------
    tuple
        (SystemContainer, MainSystem, node indices); the container must be kept alive.
    """
    exu = _exudyn()
    from exudyn.itemInterface import ObjectGround
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
    nodes, bodies = [], []
    for k, (_, length, _) in enumerate(FOURBAR_BARS):
        node, body = _add_bar(mbs, q0[3 * k:3 * k + 3], length, 1.0, gravity)
        nodes.append(node)
        bodies.append(body)
    _add_revolutes(mbs, ground, bodies)
    return sc, mbs, nodes


def _add_sensors(exu: Any, mbs: Any, nodes: list[Any]) -> list[Any]:
    """One in-memory SensorNode per node recording its coordinates (displacements)."""
    from exudyn.itemInterface import SensorNode
    return [mbs.AddSensor(SensorNode(nodeNumber=n, storeInternal=True, writeToFile=False,
                                     outputVariableType=exu.OutputVariableType.Coordinates))
            for n in nodes]


def _quiet_settings(exu: Any, write_period: float) -> Any:
    """SimulationSettings without files or console output; sensors every `write_period`."""
    s = exu.SimulationSettings()
    s.solution.file.write = False
    s.solution.sensors.active = True
    s.solution.sensors.writePeriod = write_period
    s.timeIntegration.verboseMode = 0
    s.staticSolver.verboseMode = 0
    s.show.computationTime = False
    s.show.statistics = False
    return s


def genalpha_settings(exu: Any, h: float, t_end: float, write_period: float,
                      rho_inf: float = RHO_INF) -> Any:
    """Exudyn's generalized-alpha (index 3, defaults otherwise) at the fixed step h."""
    s = _quiet_settings(exu, write_period)
    ti = s.timeIntegration
    ti.solverType = exu.DynamicSolverType.GeneralizedAlpha
    ti.endTime = t_end
    ti.numberOfSteps = int(round(t_end / h))
    ti.adaptiveStep = False                 # a fixed step: fail rather than reduce h
    ti.generalizedAlpha.spectralRadius = rho_inf
    ti.generalizedAlpha.useIndex2Constraints = False
    ti.generalizedAlpha.useNewmark = False
    return s


def _sensor_angles(mbs: Any, sensors: list[Any], theta0: np.ndarray,
                   ref_t: np.ndarray) -> tuple[np.ndarray, float]:
    """The absolute body angles at ref_t from the sensors' stored coordinates.

    Returns
    -------
    tuple[np.ndarray, float]
        (len(ref_t), 3) angles and the largest |recorded time - ref_t|.
    """
    data = [np.asarray(mbs.GetSensorStoredData(s)) for s in sensors]
    t = data[0][:, 0]
    idx = np.clip(np.searchsorted(t, ref_t - 1e-9), 0, len(t) - 1)
    mismatch = float(np.max(np.abs(t[idx] - ref_t)))
    theta = np.column_stack([d[idx, 3] for d in data]) + theta0
    return theta, mismatch


def _exudyn_genalpha_row(exu: Any, mbs: Any, sensors: list[Any], q0: np.ndarray, h: float,
                         ref_t: np.ndarray, ref_theta: np.ndarray, repeats: int,
                         rho_inf: float) -> Row:
    """Run and time one step size; the error row."""
    s = genalpha_settings(exu, h, float(ref_t[-1]), float(ref_t[1] - ref_t[0]), rho_inf)
    row: Row = {"h": h, "error": None, "cpu_s": None, "steps": None}
    try:
        seconds, _ = best_of(lambda: mbs.SolveDynamic(s), repeats)
    except Exception as e:   # exudyn.SolverError (Newton failure at a large h)
        row["message"] = f"{type(e).__name__}: {e}"
        return row
    theta, mismatch = _sensor_angles(mbs, sensors, q0[2::3], ref_t)
    it = mbs.sys["dynamicSolver"].it
    row.update(error=angle_error(theta, ref_theta), cpu_s=seconds,
               steps=int(it.currentStepIndex) - 1, newton_iterations=int(it.newtonStepsCount),
               jacobians=int(it.newtonJacobiCount), output_time_mismatch=mismatch)
    if mismatch > 1e-9:
        row["message"] = f"sensor times differ from ref_t by up to {mismatch:.3g} s"
    return row


def free_fourbar_genalpha(h_values: Any, ref_t: np.ndarray, ref_theta: np.ndarray,
                          repeats: int = 3, rho_inf: float = RHO_INF) -> list[Row]:
    """Exudyn generalized-alpha on the free four-bar at each fixed step size.

    Parameters
    ----------
    h_values : sequence of float
        Step sizes; each should divide the output interval.
    ref_t : np.ndarray
        Uniform output times 0 .. t_end.
    ref_theta : np.ndarray
        (len(ref_t), 3) reference angles of crank, coupler, rocker.
    repeats : int
        Best of this many solves (fewer for slow runs, see `best_of`).
    rho_inf : float
        Spectral radius at infinite frequency.

    Returns
    -------
    list[dict]
        Rows {"h", "error", "cpu_s", "steps"} plus Exudyn's Newton statistics; a failed run
        has error None and a "message".
    """
    exu = _exudyn()
    ref_t = np.asarray(ref_t, dtype=float)
    q0 = initial_state()
    sc, mbs, nodes = build_fourbar(q0)
    sensors = _add_sensors(exu, mbs, nodes)
    mbs.Assemble()
    rows = [_exudyn_genalpha_row(exu, mbs, sensors, q0, float(h), ref_t, ref_theta, repeats,
                                 rho_inf) for h in h_values]
    del sc
    return rows


# ===================================================================== mbd2d: free four-bar
def mbd2d_genalpha(h_values: Any, ref_t: np.ndarray, ref_theta: np.ndarray,
                   repeats: int = 3, rho_inf: float = RHO_INF) -> list[Row]:
    """mbd2d's generalized-alpha on the same model and step sizes (rows as Exudyn's)."""
    model = free_fourbar()
    t_end, outputs = float(ref_t[-1]), len(ref_t) - 1
    rows = []
    for h in h_values:
        def run() -> Any:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", mbd2d.errors.MbdWarning)
                return model.dynamics(t_end=t_end, steps=outputs, method="generalized-alpha",
                                      h=float(h), rho_inf=rho_inf)
        row: Row = {"h": float(h), "error": None, "cpu_s": None, "steps": None}
        try:
            seconds, res = best_of(run, repeats)
        except mbd2d.MbdError as e:
            row["message"] = f"{type(e).__name__}: {e}"
            rows.append(row)
            continue
        theta = np.column_stack([res.body(name).theta for name in BODIES])
        row.update(error=angle_error(theta, ref_theta), cpu_s=seconds,
                   steps=int(res.stats["steps"]),
                   newton_iterations=int(res.stats["newton_iterations"]),
                   jacobians=int(res.stats["iteration_matrices"]))
        rows.append(row)
    return rows


# ===================================================================== kinematics
def closed_form_fourbar(t: np.ndarray) -> np.ndarray:
    """Body coordinates of the Grashof four-bar (open branch) with crank angle 2 pi t.

    Returns
    -------
    np.ndarray
        (len(t), 9): x, y, theta of crank, coupler, rocker (angles unwrapped, continuous
        from their values at t = 0 in (-pi, pi]).
    """
    (_, l2, _), (_, l3, _), (_, l4, _) = FOURBAR_BARS
    th2 = CRANK_OMEGA * np.asarray(t, dtype=float)
    a = np.column_stack([l2 * np.cos(th2), l2 * np.sin(th2)])
    o4 = np.array([FOURBAR_GROUND, 0.0])
    e = o4 - a
    d = np.linalg.norm(e, axis=1)[:, None]
    along = (l3 ** 2 - l4 ** 2 + d ** 2) / (2 * d)
    across = np.sqrt(l3 ** 2 - along ** 2)
    perp = np.column_stack([-e[:, 1], e[:, 0]])
    b = a + (along * e + across * perp) / d          # the branch with B above A-O4
    th3 = np.unwrap(np.arctan2(b[:, 1] - a[:, 1], b[:, 0] - a[:, 0]))
    th4 = np.unwrap(np.arctan2(o4[1] - b[:, 1], o4[0] - b[:, 0]))
    return np.column_stack([a / 2, th2, (a + b) / 2, th3, (b + o4) / 2, th4])


def coordinate_error(q: np.ndarray, q_ref: np.ndarray) -> float:
    """Max abs difference of body coordinates; the angle columns compared unwrapped."""
    q, q_ref = np.array(q, dtype=float), np.array(q_ref, dtype=float)
    for c in (2, 5, 8):
        q[:, c] = np.unwrap(q[:, c])
        q_ref[:, c] = np.unwrap(q_ref[:, c])
        q[:, c] -= 2 * math.pi * np.round((q[0, c] - q_ref[0, c]) / (2 * math.pi))
    return float(np.max(np.abs(q - q_ref)))


def _build_driven(q0: np.ndarray) -> tuple[Any, Any, list[Any], Any]:
    """The four-bar with a CoordinateConstraint on the crank's rotation coordinate.

    The constraint equation is u_crank = offset (u: the rotation relative to the reference
    angle q0[2]); no gravity (positions only).

    Returns
    -------
    tuple
        (SystemContainer, MainSystem, node indices, constraint index).
    """
    from exudyn.itemInterface import CoordinateConstraint, MarkerNodeCoordinate, NodePointGround
    sc, mbs, nodes = build_fourbar(q0, gravity=False)
    ground_node = mbs.AddNode(NodePointGround())
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    m_crank = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=2))
    cc = mbs.AddObject(CoordinateConstraint(markerNumbers=[m_ground, m_crank], offset=0.0))
    return sc, mbs, nodes, cc


def _static_settings(exu: Any, t_end: float, steps: int) -> Any:
    """Static solver settings: `steps` load steps over the quasi-time t_end, no adaptation."""
    s = _quiet_settings(exu, t_end / steps)
    s.staticSolver.numberOfLoadSteps = steps
    s.staticSolver.loadStepDuration = t_end
    s.staticSolver.adaptiveStep = False
    return s


def _kin_loop(exu: Any, q0: np.ndarray, steps: int, t_end: float,
              repeats: int) -> tuple[float, np.ndarray]:
    """Variant 'loop': set the offset, mbs.SolveStatic, read the coordinates; per step."""
    sc, mbs, nodes, cc = _build_driven(q0)
    mbs.Assemble()
    s = _static_settings(exu, 1.0, 1)
    s.solution.sensors.active = False
    zeros = np.zeros(9)
    offsets = CRANK_OMEGA * t_end * np.arange(1, steps + 1) / steps - q0[2]

    def run() -> np.ndarray:
        mbs.systemData.SetODE2Coordinates(zeros, configuration=exu.ConfigurationType.Initial)
        out = np.empty((steps + 1, 9))
        out[0] = 0.0
        for i, off in enumerate(offsets, start=1):
            mbs.SetObjectParameter(cc, "offset", float(off))
            mbs.SolveStatic(s, updateInitialValues=True)
            out[i] = mbs.systemData.GetODE2Coordinates()
        return out

    seconds, u = best_of(run, repeats)
    del sc
    return seconds, u + q0


def _offset_function(mbs: Any, cc: Any, theta0: float, symbolic: bool) -> Any:
    """The offset user function 2 pi t - theta0, as a Python or a symbolic function."""
    def offset(mbs: Any, t: float, item_number: int, l_offset: float) -> float:
        return CRANK_OMEGA * t - theta0
    if not symbolic:
        return offset
    from exudyn.advancedUtilities import CreateSymbolicUserFunction
    return CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", cc)


def _kin_loadsteps(exu: Any, q0: np.ndarray, steps: int, t_end: float, repeats: int,
                   symbolic: bool) -> tuple[float, np.ndarray]:
    """Variant 'load steps': one mbs.SolveStatic, a load step per output time."""
    sc, mbs, nodes, cc = _build_driven(q0)
    uf = _offset_function(mbs, cc, float(q0[2]), symbolic)
    mbs.SetObjectParameter(cc, "offsetUserFunction", uf)
    sensors = _add_sensors(exu, mbs, nodes)
    mbs.Assemble()
    s = _static_settings(exu, t_end, steps)
    seconds, _ = best_of(lambda: mbs.SolveStatic(s), repeats)
    data = [np.asarray(mbs.GetSensorStoredData(x)) for x in sensors]
    t = data[0][:, 0]
    if len(t) != steps + 1 or np.max(np.abs(t - np.linspace(0, t_end, steps + 1))) > 1e-9:
        raise RuntimeError(f"sensor rows ({len(t)}) do not match the {steps + 1} output times")
    u = np.column_stack([d[:, 1:4] for d in data])
    del sc, uf
    return seconds, u + q0


KIN_VARIANTS = {
    "loop: offset + mbs.SolveStatic per step":
        lambda exu, q0, n, te, r: _kin_loop(exu, q0, n, te, r),
    "load steps, Python offsetUserFunction":
        lambda exu, q0, n, te, r: _kin_loadsteps(exu, q0, n, te, r, symbolic=False),
    "load steps, symbolic offsetUserFunction":
        lambda exu, q0, n, te, r: _kin_loadsteps(exu, q0, n, te, r, symbolic=True),
}


def mbd2d_kinematics(steps: int, t_end: float = 1.0, repeats: int = 3,
                     positions_only: bool = False) -> dict[str, float]:
    """Best-of-N time of model.kinematics on fourbar_grashof.toml and its error (positions
    alone, as Exudyn's static solves give them, with positions_only)."""
    model = mbd2d.load(KIN_FILE)
    seconds, res = best_of(lambda: model.kinematics(t_end=t_end, steps=steps,
                                                    positions_only=positions_only), repeats)
    q_ref = closed_form_fourbar(np.asarray(res.t))
    return {"us_per_step": 1e6 * seconds / steps, "cpu_s": seconds,
            "max_error": coordinate_error(np.asarray(res.q), q_ref)}


def kinematic_stepping(steps: int, t_end: float = 1.0, repeats: int = 3) -> dict[str, Any]:
    """Exudyn kinematic stepping (static solves, positions only) against mbd2d kinematics.

    Parameters
    ----------
    steps : int
        Output steps (steps + 1 times 0 .. t_end, crank theta = 2 pi t).
    t_end : float
        End time.
    repeats : int
        Best of this many runs.

    Returns
    -------
    dict
        "exudyn_variants" (per variant us_per_step, max_error, or message),
        "exudyn_best" (the fastest variant that ran), "exudyn_us_per_step",
        "exudyn_max_error", "mbd2d" (us_per_step, max_error; q, q_dot and q_ddot),
        "mbd2d_positions" (the same for positions alone, like for like with Exudyn's static
        solves), "ratio" and "ratio_positions" (Exudyn / mbd2d time per step).
    """
    exu = _exudyn()
    q0 = np.asarray(mbd2d.load(KIN_FILE).kinematics(t_end=t_end, steps=1).q[0], dtype=float)
    t = np.linspace(0.0, t_end, steps + 1)
    q_ref = closed_form_fourbar(t)
    variants: dict[str, dict[str, Any]] = {}
    for name, run in KIN_VARIANTS.items():
        try:
            seconds, q = run(exu, q0, steps, t_end, repeats)
        except Exception as e:
            variants[name] = {"message": f"{type(e).__name__}: {e}"}
            continue
        variants[name] = {"us_per_step": 1e6 * seconds / steps, "cpu_s": seconds,
                          "max_error": coordinate_error(q, q_ref)}
    ran = {k: v for k, v in variants.items() if "us_per_step" in v}
    best = min(ran, key=lambda k: ran[k]["us_per_step"]) if ran else None
    ours = mbd2d_kinematics(steps, t_end, repeats)
    pos = mbd2d_kinematics(steps, t_end, repeats, positions_only=True)
    out: dict[str, Any] = {"steps": steps, "t_end": t_end, "exudyn_variants": variants,
                           "exudyn_best": best, "mbd2d": ours, "mbd2d_positions": pos}
    if best is not None:
        out.update(exudyn_us_per_step=ran[best]["us_per_step"],
                   exudyn_max_error=ran[best]["max_error"],
                   ratio=ran[best]["us_per_step"] / ours["us_per_step"],
                   ratio_positions=ran[best]["us_per_step"] / pos["us_per_step"])
    return out


# ===================================================================== equal accuracy
def _curves(rows: list[Row]) -> dict[str, list[tuple[float, float]]]:
    """(log10 error, log10 time) points of each work-precision line, sorted by error."""
    curves: dict[str, list[tuple[float, float]]] = {}
    for r in rows:
        if r.get("ok", True) and r.get("error") and r.get("cpu_s") and r["error"] > 0:
            key = f"{r['method']} ({'fixed h' if r.get('sweep') == 'h' else 'rtol'})"
            curves.setdefault(key, []).append((math.log10(r["error"]), math.log10(r["cpu_s"])))
    return {k: sorted(v) for k, v in curves.items()}


def time_at_error(points: list[tuple[float, float]], log_err: float) -> float | None:
    """Time (s) of a work-precision line at an error, interpolated linearly in log-log
    between the two nearest points on either side; None outside the line's error range."""
    for (e0, t0), (e1, t1) in zip(points, points[1:]):
        if e0 <= log_err <= e1:
            w = 0.0 if e1 == e0 else (log_err - e0) / (e1 - e0)
            return 10.0 ** (t0 + w * (t1 - t0))
    if points and abs(points[0][0] - log_err) < 1e-12:
        return 10.0 ** points[0][1]
    return None


def equal_accuracy(exu_rows: list[Row], wp_rows: list[Row]) -> list[Row]:
    """For each Exudyn point, mbd2d's time at the same error.

    Every mbd2d work-precision line (method and sweep, rows as bench/work_precision.py
    writes them) is interpolated in log-log at Exudyn's error; the fastest line there is
    mbd2d's figure. Lines are not extrapolated.

    Parameters
    ----------
    exu_rows : list of dict
        Exudyn rows {"h", "error", "cpu_s"} (free_fourbar_genalpha).
    wp_rows : list of dict
        mbd2d's work-precision rows of the same model and error measure.

    Returns
    -------
    list of dict
        {"h", "exudyn_error", "exudyn_cpu_s", "mbd2d_method", "mbd2d_cpu_s", "ratio"}
        (ratio = Exudyn time / mbd2d time; None where no mbd2d line covers the error).
    """
    curves = _curves(wp_rows)
    out = []
    for e in exu_rows:
        row: Row = {"h": e.get("h"), "exudyn_error": e.get("error"),
                    "exudyn_cpu_s": e.get("cpu_s"), "mbd2d_method": None,
                    "mbd2d_cpu_s": None, "ratio": None}
        if e.get("error") and e.get("cpu_s"):
            log_err = math.log10(e["error"])
            at = {k: time_at_error(v, log_err) for k, v in curves.items()}
            at = {k: v for k, v in at.items() if v is not None}
            if at:
                best = min(at, key=at.get)
                row.update(mbd2d_method=best, mbd2d_cpu_s=at[best],
                           ratio=e["cpu_s"] / at[best])
        out.append(row)
    return out


# ===================================================================== output
def _fmt(v: Any, spec: str) -> str:
    """Format a number, or a right-aligned '-' for None (spec like '11.3e')."""
    return format("-", ">" + spec.split(".")[0]) if v is None else format(v, spec)


def side_by_side(exu_rows: list[Row], our_rows: list[Row]) -> list[Row]:
    """Merge the two row lists by h; ratio = Exudyn time / mbd2d time."""
    ours = {r["h"]: r for r in our_rows}
    table = []
    for h in sorted({r["h"] for r in exu_rows} | set(ours), reverse=True):
        e = next((r for r in exu_rows if r["h"] == h), {})
        m = ours.get(h, {})
        ratio = (e["cpu_s"] / m["cpu_s"]) if e.get("cpu_s") and m.get("cpu_s") else None
        table.append({"h": h, "exudyn_error": e.get("error"), "exudyn_cpu_s": e.get("cpu_s"),
                      "mbd2d_error": m.get("error"), "mbd2d_cpu_s": m.get("cpu_s"),
                      "time_ratio_exudyn_over_mbd2d": ratio})
    return table


def print_dynamics(table: list[Row]) -> None:
    """The side-by-side generalized-alpha table."""
    print(f"free four-bar, 10 s, generalized-alpha rho_inf = {RHO_INF}, max angle error [rad]")
    print(f"{'h':>8} {'Exudyn err':>11} {'Exudyn s':>9} {'mbd2d err':>11} {'mbd2d s':>9} "
          f"{'Exu/mbd2d':>9}")
    for r in table:
        print(f"{r['h']:8.0e} {_fmt(r['exudyn_error'], '11.3e')} "
              f"{_fmt(r['exudyn_cpu_s'], '9.4f')} {_fmt(r['mbd2d_error'], '11.3e')} "
              f"{_fmt(r['mbd2d_cpu_s'], '9.4f')} "
              f"{_fmt(r['time_ratio_exudyn_over_mbd2d'], '9.2f')}")


def print_kinematics(kin: dict[str, Any]) -> None:
    """The kinematic-stepping comparison."""
    print(f"\ndriven four-bar kinematics, {kin['steps']} steps over {kin['t_end']} s "
          "(error: max |q - closed form|)")
    for name, v in kin.get("exudyn_variants", {}).items():
        if "us_per_step" in v:
            print(f"  Exudyn {name:42s} {v['us_per_step']:8.2f} us/step  "
                  f"err {v['max_error']:.2e}")
        else:
            print(f"  Exudyn {name:42s} failed: {v['message']}")
    for key, label in (("mbd2d", "model.kinematics (q, qd, qdd)"),
                       ("mbd2d_positions", "model.kinematics(positions_only=True)")):
        m = kin.get(key)
        if m:
            print(f"  mbd2d  {label:42s} {m['us_per_step']:8.2f} us/step  "
                  f"err {m['max_error']:.2e}")
    if kin.get("ratio") is not None:
        print(f"  ratio Exudyn (fastest variant) / mbd2d: {kin['ratio']:.1f} (q, qd, qdd), "
              f"{kin.get('ratio_positions', float('nan')):.1f} (positions only)")


def environment(exu_ok: bool, exu_info: str) -> dict[str, Any]:
    """Versions and platform for the JSON record."""
    env: dict[str, Any] = {"python": platform.python_version(), "platform": platform.platform(),
                           "machine": platform.machine(), "numpy": np.__version__,
                           "exudyn_available": exu_ok}
    if exu_ok:
        import exudyn
        env["exudyn"] = exu_info
        env["exudyn_module"] = getattr(exudyn, "_compiledModuleName", "unknown")
    else:
        env["exudyn_unavailable_reason"] = exu_info
    return env


def main() -> dict[str, Any]:
    """Run both comparisons, print the tables, write the JSON."""
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=BENCH / "results" / "peers_exudyn.json")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="h >= 1e-3, 1000 kinematic steps")
    ap.add_argument("--exudyn-fast", action="store_true",
                    help="load exudynCPPfast (no range checks, AVX2) instead of exudynCPP")
    args = ap.parse_args()
    if args.exudyn_fast:
        sys.exudynFast = True       # read by exudyn at its (first) import
    h_values = [h for h in H_VALUES if h >= 1e-3] if args.quick else list(H_VALUES)
    kin_steps = 1000 if args.quick else KIN_STEPS

    exu_ok, exu_info = available()
    print(f"Exudyn: {exu_info}" if exu_ok else f"Exudyn NOT available: {exu_info}")
    ref_t, ref_theta = reference()
    exu_rows: list[Row] = []
    our_rows: list[Row] = []
    for h in h_values:      # interleaved, so that a change of machine load hits both alike
        if exu_ok:
            exu_rows += free_fourbar_genalpha([h], ref_t, ref_theta, args.repeats)
        our_rows += mbd2d_genalpha([h], ref_t, ref_theta, args.repeats)
    table = side_by_side(exu_rows, our_rows)
    print_dynamics(table)
    if exu_ok:
        kin = kinematic_stepping(kin_steps, 1.0, args.repeats)
    else:
        kin = {"steps": kin_steps, "t_end": 1.0, "mbd2d": mbd2d_kinematics(kin_steps, 1.0,
                                                                          args.repeats)}
    print_kinematics(kin)

    record = {"environment": environment(exu_ok, exu_info),
              "dynamics": {"model": "bench/models.free_fourbar", "t_end": T_END,
                           "outputs": len(ref_t), "rho_inf": RHO_INF,
                           "reference": "mbd2d dopri5 rtol 1e-12 atol 1e-14",
                           "exudyn": exu_rows, "mbd2d": our_rows, "side_by_side": table},
              "kinematics": kin}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1))
    print(f"\nwrote {args.out}")
    return record


if __name__ == "__main__":
    main()
