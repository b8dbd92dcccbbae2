"""Four-bar path generation: the three standard cases of the synthesis literature, solved by
mbd2d (multi-start least squares with exact gradients, defect-free by construction) and by
pylinkage (its differential-evolution optimizer over its own dyad solver), with the
published designs' errors recomputed.

The cases (targets, bounds, error measure: sum of squared distances between the coupler point
and the targets):

1. six points on a vertical line, (20, 20) ... (20, 45), without prescribed timing (the six
   crank angles are unknowns); Grashof crank-rocker (the crank shortest); 15 unknowns
   (Kunjur & Krishnamurty 1997; Cabrera, Simon & Prado 2002, case 1);
2. five points with prescribed timing, crank angles pi/6 ... pi/2 in steps of pi/12, crank
   pivot at the origin and the ground link along x; Grashof; 6 unknowns (Cabrera et al.
   2002, case 2);
3. eighteen points on a closed curve with prescribed timing, crank angles theta_1 + (i - 1)
   20 degrees (theta_1 free); Grashof; 10 unknowns (Kunjur & Krishnamurty 1997; Cabrera et
   al. 2002, case 3).

Targets, bounds and the published design vectors are those collected with the public code of
Nguyen-Van et al., "A new study on optimization of four-bar mechanisms based on a hybrid-
combined differential evolution and Jaya algorithm", Symmetry 14 (2022) 381 (repository
sy-nguyen-van/DE_Jaya_Synthesis_Four_Bar_Mechanisms): the published errors are recomputed
here from those vectors with the literature's closed form (:func:`literature_error`), so
they are on the same measure as mbd2d's.

    python bench/synthesis.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from typing import Any

import numpy as np

TWO_PI = 2.0 * math.pi

CASES: dict[str, dict[str, Any]] = {
    "six points on a line, free timing": {
        "key": "line6",
        "targets": [[20, 20], [20, 25], [20, 30], [20, 35], [20, 40], [20, 45]],
        "timing": "free",
        "length_bounds": (0.0, 60.0), "position_bounds": (-60.0, 60.0),
        "grashof": "crank-rocker",
        # x = [r1 r2 r3 r4 rcx rcy x0 y0 theta0 theta2_1..6]
        "published": {
            "GA (Cabrera et al. 2002)": [35.02074, 6.404196, 31.60722, 50.59949, 20.80324,
                                         41.54364, 60, 18.07791, 0, 6.283185, 0.264935,
                                         0.500377, 0.735321, 0.996529, 1.333549],
            "DE (Lin & Hsiao, combined mutation)": [
                45.9540268793200, 10.1413352283990, 36.1198616002200, 49.7905570636800,
                51.4935231082160, 16.4957302836340, 59.9251894962240, -0.267255177889410,
                0.862384954187540, 4.49683139849550, 3.94685292206840, 3.51208539098020,
                3.11078124880880, 2.71010931195190, 2.26549866257340],
            "HCDJ (Nguyen-Van et al. 2022)": [
                14.201369, 8.0143127, 16.309922, 12.253871, 27.797721, 11.305412, -2.309531,
                45.695083, 4.5172417, 6.2532447, 2.4038981, 2.9362397, 3.4905751, 4.0650776,
                5.2095019],
        },
    },
    "five points, prescribed timing": {
        "key": "timed5",
        "targets": [[3, 3], [2.759, 3.363], [2.372, 3.663], [1.890, 3.862], [1.355, 3.943]],
        "timing": [math.pi / 6, math.pi / 4, math.pi / 3, 5 * math.pi / 12, math.pi / 2],
        "length_bounds": (0.0, 50.0), "position_bounds": (-50.0, 50.0),
        "grashof": "grashof",
        # x = [r1 r2 r3 r4 rcx rcy]; O2 at the origin, ground link along x
        "published": {
            "GA (Kunjur & Krishnamurty 1997)": [3.509643, 1.857606, 4.725835, 3.518721,
                                                1.959538, 1.558898],
            "GA (Cabrera et al. 2002)": [3.0630424, 1.9959624, 3.305823, 2.524706, 1.645158,
                                         1.708959],
            "MUMSA": [3.77326856, 2.00000403, 4.11697104, 2.74615671, 1.67848787,
                      1.67098007],
            "IOA": [2.803607, 1.99226, 3.030461, 2.474117, 1.64413, 1.714536],
            "HCDJ (Nguyen-Van et al. 2022)": [4.2930812, 1.9978324, 4.7374099, 2.9417301,
                                              1.7074051, 1.6441696],
        },
    },
    "eighteen points on a closed curve, prescribed timing": {
        "key": "closed18",
        "targets": [[0.5, 1.1], [0.4, 1.1], [0.3, 1.1], [0.2, 1.0], [0.1, 0.9], [0.05, 0.75],
                    [0.02, 0.6], [0.0, 0.5], [0.0, 0.4], [0.03, 0.3], [0.1, 0.25],
                    [0.15, 0.2], [0.2, 0.3], [0.3, 0.4], [0.4, 0.5], [0.5, 0.7], [0.6, 0.9],
                    [0.6, 1.0]],
        "timing": "shift",          # theta2_i = theta2_1 + (i - 1) pi / 9
        "length_bounds": (0.0, 50.0), "position_bounds": (-50.0, 50.0),
        "grashof": "grashof",
        # x = [r1 r2 r3 r4 rcx rcy x0 y0 theta0 theta2_1]
        "published": {
            "GA (Kunjur & Krishnamurty 1997)": [1.879660, 0.274853, 1.180253, 2.138209,
                                                -0.833592, -0.378770, 1.132062, 0.663433,
                                                4.354224, 2.558625],
            "GA (Cabrera et al. 2002)": [3.057878, 0.237803, 4.828954, 2.056456, 0.767038,
                                         1.850828, 1.776808, -0.641991, 1.002168, 0.226186],
            "MUMSA": [4.453772, 0.297057, 3.913095, 0.849372, -2.067338, 1.6610626,
                      -1.309243, 2.806964, 2.7387359, 4.853543],
            "IOA": [4.040435, 0.245216, 6.38294, 2.620532, 1.139106, 1.866109, 1.891805,
                    -0.761339, 1.187751, 0.0],
            "HCDJ (Nguyen-Van et al. 2022)": [49.800886, 0.28817159, 48.476138, 1.633642,
                                              -23.41281, 7.6644886, -14.836153, 20.140223,
                                              2.5286091, 5.0644224],
        },
    },
}


# ===================================================================== the literature's form
def literature_points(x: Any, theta2: Any, ground: bool = True) -> np.ndarray:
    """Coupler points of the literature's closed form: x = [r1 r2 r3 r4 rcx rcy (x0 y0
    theta0)], theta2 measured from the ground link; the coupler angle theta3 from the
    tangent-half-angle root with the minus sign (one assembly branch)."""
    r1, r2, r3, r4, rcx, rcy = x[:6]
    out = []
    for t2 in theta2:
        k1, k4 = r1 / r2, r1 / r3
        k5 = (r4**2 - r1**2 - r2**2 - r3**2) / (2 * r3 * r2)
        d = math.cos(t2) - k1 + k4 * math.cos(t2) + k5
        e = -2 * math.sin(t2)
        f = k1 + (k4 - 1) * math.cos(t2) + k5
        root = (-e - np.sqrt(complex(e * e - 4 * d * f))) / (2 * d)
        t3 = float((2 * np.arctan(root)).real)
        cx = r2 * math.cos(t2) + rcx * math.cos(t3) - rcy * math.sin(t3)
        cy = r2 * math.sin(t2) + rcx * math.sin(t3) + rcy * math.cos(t3)
        if ground:
            x0, y0, t0 = x[6], x[7], x[8]
            cx, cy = (math.cos(t0) * cx - math.sin(t0) * cy + x0,
                      math.sin(t0) * cx + math.cos(t0) * cy + y0)
        out.append((cx, cy))
    return np.array(out)


def case_angles(case: dict, x: Any) -> list[float]:
    """The crank angles (from the ground link) of a literature design vector."""
    n = len(case["targets"])
    if case["timing"] == "free":
        return list(x[9:9 + n])
    if case["timing"] == "shift":
        return [x[9] + i * math.pi / 9 for i in range(n)]
    return list(case["timing"])


def literature_error(case: dict, x: Any) -> float:
    """Sum of squared distances of a literature design vector (the published measure)."""
    pts = literature_points(x, case_angles(case, x), ground=isinstance(case["timing"], str))
    return float(((pts - np.array(case["targets"], float))**2).sum())


# ===================================================================== mbd2d
def mbd2d_problem(case: dict, branch: int) -> tuple[Any, list[str], Any, dict, list]:
    """The case as an mbd2d synthesis: model, free names, task, bounds, constraints."""
    from mbd2d.synthesis import Grashof, PathTask, fourbar

    targets = np.array(case["targets"], float)
    lo_l, hi_l = case["length_bounds"]
    lo_l = max(lo_l, 1e-3 * hi_l)
    lo_p, hi_p = case["position_bounds"]
    c = targets.mean(axis=0)
    ext = float(np.ptp(targets, axis=0).max())
    if case["timing"] == "free" or case["timing"] == "shift":
        model = fourbar([[c[0] - ext, c[1] - ext], [c[0] + ext, c[1] - ext]], crank=0.4 * ext,
                        coupler=1.6 * ext, rocker=1.4 * ext, branch=branch)
        free = ["joint.O2.points.0.0", "joint.O2.points.0.1", "joint.O4.points.0.0",
                "joint.O4.points.0.1", "joint.A.points.0.0", "joint.B.points.0.0",
                "joint.B.points.1.0", "path.point.0", "path.point.1"]
        # O2 in the position box; O4 = O2 + r1 (cos theta0, sin theta0) in the box widened
        # by the longest ground link (the literature's domain for x0, y0, r1, theta0)
        bounds = {n: (lo_p, hi_p) for n in free[:2]}
        bounds.update({n: (lo_p - hi_l, hi_p + hi_l) for n in free[2:4]})
        if case["timing"] == "free":
            task = PathTask("coupler", (0.8 * ext, 0.5 * ext), targets, span=(0.0, TWO_PI),
                            cycle=TWO_PI)
        else:
            task = PathTask("coupler", (0.8 * ext, 0.5 * ext), targets,
                            times=[i * math.pi / 9 for i in range(len(targets))], shift=True,
                            span=(0.0, 2 * TWO_PI))
            bounds["path.t_shift"] = (0.0, TWO_PI)
    else:
        model = fourbar([[0.0, 0.0], [1.2 * ext + c[0], 0.0]], crank=0.5 * ext + 0.5,
                        coupler=1.5 * ext + 1.0, rocker=1.2 * ext + 0.8, branch=branch)
        free = ["joint.O4.points.0.0", "joint.A.points.0.0", "joint.B.points.0.0",
                "joint.B.points.1.0", "path.point.0", "path.point.1"]
        bounds = {"joint.O4.points.0.0": (lo_l, hi_l)}
        task = PathTask("coupler", (0.5, 0.5), targets, times=case["timing"],
                        span=(0.0, case["timing"][-1]))
    for n in ("joint.A.points.0.0", "joint.B.points.0.0", "joint.B.points.1.0"):
        bounds[n] = (lo_l, hi_l)
    bounds["path.point.0"] = bounds["path.point.1"] = (lo_p, hi_p)
    return model, free, task, bounds, [Grashof(case["grashof"])]


def run_mbd2d(case: dict, starts: int, seed: int = 0, workers: int = 1) -> dict:
    """Best design of both assembly branches (starts local solves each), timed."""
    import mbd2d

    t0 = time.perf_counter()
    cpu0 = time.process_time()
    best, runs = None, []
    for branch in (1, -1):
        model, free, task, bounds, cons = mbd2d_problem(case, branch)
        try:
            res = mbd2d.synthesize(model, free, task, bounds=bounds, constraints=cons,
                                   starts=starts, seed=seed, workers=workers)
        except mbd2d.ModelError as exc:
            runs.append({"branch": branch, "error": None, "failed": str(exc)})
            continue
        runs.append({"branch": branch, "error": res.error, "seconds": res.seconds,
                     "local_solves": len(res.history), "rejected": len(res.rejected),
                     "defects": res.defect_reasons,
                     "nfev": int(sum(h.nfev for h in res.history))})
        if best is None or res.error < best.error:
            best = res
    out = {"starts_per_branch": starts, "wall_s": time.perf_counter() - t0,
           "cpu_s": time.process_time() - cpu0, "runs": runs}
    if best is not None:
        out.update(error=best.error, values=best.values, times=best.times.tolist(),
                   residuals=best.residuals.tolist(), terms=best.terms)
    return out


def run_polish(case: dict, name: str) -> dict:
    """mbd2d's local solve (exact Jacobian) started from a published design vector, on the
    literature's assembly branch (+1 here): what exact gradients add to a metaheuristic's
    answer."""
    from mbd2d.synthesis import Problem, fourbar
    from mbd2d.synthesis.search import local_solve

    x = np.asarray(case["published"][name], float)
    r1, r2, r3, r4, rcx, rcy = x[:6]
    if isinstance(case["timing"], str):
        x0, y0, t0 = x[6], x[7], x[8]
    else:
        x0, y0, t0 = 0.0, 0.0, 0.0
    o2, o4 = (x0, y0), (x0 + r1 * math.cos(t0), y0 + r1 * math.sin(t0))
    base, free, task, bounds, cons = mbd2d_problem(case, 1)
    model = fourbar([o2, o4], r2, r3, r4, branch=1)
    problem = Problem(model, free, task, bounds, cons)
    vals = {"joint.O2.points.0.0": o2[0], "joint.O2.points.0.1": o2[1],
            "joint.O4.points.0.0": o4[0], "joint.O4.points.0.1": o4[1],
            "joint.A.points.0.0": r2, "joint.B.points.0.0": r3, "joint.B.points.1.0": r4,
            "path.point.0": rcx, "path.point.1": rcy}
    ang = np.array(case_angles(case, x)) + t0
    if case["timing"] == "free" and np.diff(np.unwrap(ang)).min() < 0:
        return {"from": name, "skipped": "its crank turns clockwise through the targets "
                "(the task here drives it counter-clockwise)"}
    if case["timing"] == "free":
        ang = np.unwrap(ang)
        ang -= TWO_PI * math.floor(ang[0] / TWO_PI)
        vals["path.t.0"] = ang[0]
        vals.update({f"path.dt.{i}": ang[i] - ang[i - 1] for i in range(1, len(ang))})
    elif case["timing"] == "shift":
        vals["path.t_shift"] = (ang[0] % TWO_PI)
    xs = np.array([vals[n] for n in problem.names])
    t_0, cpu0 = time.perf_counter(), time.process_time()
    start = problem.evaluate(xs)
    rec, final = local_solve((problem, np.clip(xs, problem.lo, problem.hi), None, 300))
    return {"from": name, "start_error": start.error if start.ok else None,
            "start_defects": start.defects, "error": rec.error if final.ok else None,
            "defects": rec.defects, "nfev": rec.nfev, "wall_s": time.perf_counter() - t_0,
            "cpu_s": time.process_time() - cpu0}


# ===================================================================== pylinkage
def pylinkage_available() -> tuple[bool, str]:
    try:
        import pylinkage
    except ImportError as exc:
        return False, f"not installed ({exc})"
    return True, f"pylinkage {pylinkage.__version__}"


def _pl_points(x: np.ndarray, angles: list[float], case: dict) -> np.ndarray | None:
    """Coupler points of a literature design vector computed by pylinkage's kinematics (its
    Crank, RRRDyad and FixedDyad solved step by step), or None when it does not build."""
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.simulation import Linkage

    r1, r2, r3, r4, rcx, rcy = x[:6]
    if isinstance(case["timing"], str):
        x0, y0, t0 = x[6], x[7], x[8]
    else:
        x0, y0, t0 = 0.0, 0.0, 0.0
    o2 = Ground(x0, y0, name="O2")
    o4 = Ground(x0 + r1 * math.cos(t0), y0 + r1 * math.sin(t0), name="O4")
    steps = np.diff(angles)
    if len(steps) and np.allclose(steps, steps[0]):
        crank = Crank(anchor=o2, radius=r2, angular_velocity=float(steps[0]),
                      initial_angle=t0 + angles[0] - float(steps[0]))
        rocker = RRRDyad(crank.output, o4, distance1=r3, distance2=r4)
        point = FixedDyad(crank.output, rocker, distance=math.hypot(rcx, rcy),
                          angle=math.atan2(rcy, rcx))
        linkage = Linkage([o2, o4, crank, rocker, point])
        try:
            pos = [p[-1] for p in linkage.step(iterations=len(angles))]
        except Exception:  # noqa: BLE001 - pylinkage's unbuildable configurations
            return None
        arr = np.array(pos, dtype=float)
        return arr if np.isfinite(arr).all() else None
    out = []
    for a in angles:     # free timing: one placement per crank angle
        crank = Crank(anchor=o2, radius=r2, angular_velocity=0.0, initial_angle=t0 + a)
        rocker = RRRDyad(crank.output, o4, distance1=r3, distance2=r4)
        point = FixedDyad(crank.output, rocker, distance=math.hypot(rcx, rcy),
                          angle=math.atan2(rcy, rcx))
        linkage = Linkage([o2, o4, crank, rocker, point])
        try:
            out.append(next(iter(linkage.step(iterations=1)))[-1])
        except Exception:  # noqa: BLE001
            return None
    arr = np.array(out, dtype=float)
    return arr if np.isfinite(arr).all() else None


def run_pylinkage(case: dict, maxiter: int, popsize: int, seed: int = 0) -> dict:
    """pylinkage's differential evolution on the literature's design vector (same bounds,
    same error measure, Grashof and angle order as penalties), timed."""
    from pylinkage.optimization import differential_evolution_optimization

    targets = np.array(case["targets"], float)
    n = len(targets)
    lo_l, hi_l = case["length_bounds"]
    lo_p, hi_p = case["position_bounds"]
    lo = [max(lo_l, 1e-3 * hi_l)] * 4 + [lo_p, lo_p]
    hi = [hi_l] * 4 + [hi_p, hi_p]
    if isinstance(case["timing"], str):
        lo += [lo_p, lo_p, 0.0]
        hi += [hi_p, hi_p, TWO_PI]
        extra = n if case["timing"] == "free" else 1
        lo += [0.0] * extra
        hi += [TWO_PI] * extra

    def fitness(_linkage: Any, dims: Any, _pos: Any) -> float:
        x = np.asarray(dims, float)
        pen = 0.0
        s = np.sort(x[:4])
        if s[0] + s[3] > s[1] + s[2]:
            pen += 1e3 * (s[0] + s[3] - s[1] - s[2])
        if case["grashof"] == "crank-rocker" and x[1] > s[0]:
            pen += 1e3 * (x[1] - s[0])
        if case["timing"] == "free":
            gaps = np.diff(np.unwrap(x[9:9 + n]))
            pen += 1e3 * float(np.clip(-gaps, 0, None).sum())
        pts = _pl_points(x, case_angles(case, x), case)
        if pts is None:
            return 1e12
        return float(((pts - targets)**2).sum()) + pen

    class _Holder:                  # the optimizer asks its linkage for the dimension count
        def __init__(self, k: int) -> None:
            self.k = k

        def get_constraints(self) -> list[float]:
            return [1.0] * self.k

        def get_coords(self) -> list[tuple[float, float]]:
            return []

    t0 = time.perf_counter()
    cpu0 = time.process_time()
    ens = differential_evolution_optimization(fitness, _Holder(len(lo)), bounds=(lo, hi),
                                              order_relation=min, maxiter=maxiter,
                                              popsize=popsize, seed=seed, verbose=False,
                                              polish=False)
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    x = np.asarray(ens.dimensions[0], float)
    pts = _pl_points(x, case_angles(case, x), case)
    err = None if pts is None else float(((pts - targets)**2).sum())
    return {"error": err, "score": float(ens.scores["score"][0]), "x": x.tolist(),
            "wall_s": wall, "cpu_s": cpu, "maxiter": maxiter, "popsize": popsize}


# ===================================================================== the study
def study(quick: bool = False, starts: int | None = None) -> dict:
    """Every case: published errors (recomputed), mbd2d, pylinkage."""
    ok, info = pylinkage_available()
    out: dict[str, Any] = {"pylinkage": info if ok else None,
                           "pylinkage_unavailable_reason": None if ok else info,
                           "cases": {}}
    k = starts or (3 if quick else 8)
    for name, case in CASES.items():
        print(f" {name} ...", flush=True)
        row: dict[str, Any] = {"key": case["key"], "targets": case["targets"],
                               "published": {a: literature_error(case, x)
                                             for a, x in case["published"].items()}}
        row["mbd2d"] = run_mbd2d(case, k)
        for pub in sorted(row["published"], key=row["published"].get):
            try:
                row["polish"] = run_polish(case, pub)
            except Exception as exc:  # noqa: BLE001 - recorded, the bench goes on
                row["polish"] = {"failed": True, "error": f"{type(exc).__name__}: {exc}"}
            if "skipped" not in row["polish"]:
                break
        print(f"  mbd2d: error {row['mbd2d'].get('error')}, "
              f"{row['mbd2d']['cpu_s']:.1f} s CPU", flush=True)
        if ok:
            try:
                row["pylinkage"] = run_pylinkage(case, maxiter=30 if quick else 200,
                                                 popsize=10 if quick else 15)
                print(f"  pylinkage: error {row['pylinkage']['error']}, "
                      f"{row['pylinkage']['cpu_s']:.1f} s CPU", flush=True)
            except Exception as exc:  # noqa: BLE001 - recorded, the bench goes on
                row["pylinkage"] = {"failed": True, "error": f"{type(exc).__name__}: {exc}"}
        out["cases"][name] = row
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--starts", type=int, default=None)
    a = ap.parse_args()
    print(json.dumps(study(a.quick, a.starts), indent=1, default=float))


if __name__ == "__main__":
    main()
