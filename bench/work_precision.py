"""Work-precision data and charts of the four dynamics methods.

Three models, each with a reference solution that is checked independently:

* free four-bar (bench/models.free_fourbar), 10 s under gravity, 101 uniform outputs. Error:
  max over the outputs of the max abs error of the three body angles. Reference: a very tight
  mbd2d dopri5 run, checked (a) against a tighter one and (b) against an independent
  one-degree-of-freedom integration written here (Lagrange's equation in the crank angle,
  scipy DOP853 at rtol = atol = 1e-13).
* Andrews' squeezer (examples/andrews.py) to t = 0.03 s against the published IVP test set
  reference; the error measure of bench/andrews.py (max abs error of the 7 relative angles).
* the IFToMM N-four-bar (bench/models.free_nfourbar), N = 5 and N = 1, 10 s, error in the crank
  angles against the reduced one-degree-of-freedom solution (parallelogram branch, scipy
  DOP853 at rtol 1e-13); each row also records whether the run kept the branch.

Each method is swept over its parameter: the tolerance (dopri5, partitioned, adaptive
generalized-alpha; atol = rtol * 1e-2) or the fixed step h (generalized-alpha, baumgarte-rk4;
default rho_inf and Baumgarte alpha, beta). The time of a run ("cpu_s") is the best-of-N wall
time (time.perf_counter) of model.dynamics on this 2-core machine: N = `repeats` for runs under
0.5 s, one run otherwise. A setting that fails is recorded with its message, not plotted.

    python bench/work_precision.py [--out DIR] [--quick] [--repeats R]

writes DIR/work_precision.json and DIR/wp_fourbar.png, wp_andrews.png, wp_nfourbar.png
(DIR defaults to bench/results).
"""
from __future__ import annotations

import argparse
import cmath
import importlib.util
import json
import math
import sys
import time
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any, Callable, Sequence

import numpy as np
from scipy.integrate import solve_ivp

import mbd2d

BENCH = Path(__file__).resolve().parent
EXAMPLES = BENCH.parent / "examples"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))
from models import FOURBAR_BARS, FOURBAR_GROUND, G, free_fourbar, free_nfourbar  # noqa: E402

Row = dict[str, Any]
#: (method, sweep, parameter values); sweep "rtol" (atol = rtol * ATOL_RATIO) or "h"
Sweep = tuple[str, str, Sequence[float]]
ATOL_RATIO = 1e-2
SLOW_RUN_S = 0.5          # runs slower than this are timed once
SKIP_AFTER_S = 5.0        # a sweep stops once one of its runs takes longer (time budget)
T_END = 10.0              # four-bar and N-four-bar
STEPS = 100               # outputs at 101 uniform times 0 .. T_END


def _decades(hi: float, lo: float) -> list[float]:
    """1eK values from hi down to lo."""
    k_hi, k_lo = round(math.log10(hi)), round(math.log10(lo))
    return [10.0 ** k for k in range(k_hi, k_lo - 1, -1)]


def _steps_125(hi: float, lo: float) -> list[float]:
    """1, 5, 2 x 10^k values from hi down to lo (step sizes)."""
    out = []
    for k in range(round(math.log10(hi)), round(math.log10(lo)) - 1, -1):
        out += [m * 10.0 ** k for m in (1.0, 0.5, 0.2)]
    return [v for v in out if lo * (1 - 1e-9) <= v <= hi * (1 + 1e-9)]


# ===================================================================== running one setting
def settings_of(sweep: str, param: float) -> dict[str, float]:
    """The keyword arguments of model.dynamics for one point of a sweep."""
    if sweep == "rtol":
        return {"rtol": param, "atol": param * ATOL_RATIO}
    return {"h": param}


def setting_label(kw: dict[str, float]) -> str:
    """'rtol=1e-06, atol=1e-08' or 'h=0.001'."""
    return ", ".join(f"{k}={v:.3g}" for k, v in kw.items())


def timed_run(model: mbd2d.Model, t_end: float, steps: int, method: str,
              kw: dict[str, float], repeats: int
              ) -> tuple[mbd2d.DynamicsResult | None, float, str]:
    """Best-of-`repeats` wall time of model.dynamics (one run if it takes over SLOW_RUN_S).

    Returns
    -------
    result, seconds, message
        The result (the partial one, or None, when the method failed), the best time and
        the failure message ('' when it ran).
    """
    best, res, msg = math.inf, None, ""
    for i in range(max(1, repeats)):
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", mbd2d.errors.MbdWarning)
                res = model.dynamics(t_end=t_end, steps=steps, method=method, **kw)
        except mbd2d.MbdError as e:
            best = min(best, time.perf_counter() - t0)
            return getattr(e, "results", None), best, f"{type(e).__name__}: {e}"
        best = min(best, time.perf_counter() - t0)
        if best > SLOW_RUN_S:
            break
    if res is not None and not res.complete:
        msg = f"incomplete: results end at t = {res.t[-1]:.6g}"
    return res, best, msg


def make_row(method: str, sweep: str, param: float, kw: dict[str, float],
             res: mbd2d.DynamicsResult | None, seconds: float, msg: str,
             error: float | None) -> Row:
    """One row of the work-precision table."""
    stats = res.stats if res is not None else {}
    ok = not msg and error is not None and math.isfinite(error)
    return {"method": method, "sweep": sweep, "setting": setting_label(kw), "param": param,
            "error": error if ok else None, "cpu_s": seconds,
            "steps": stats.get("steps"), "rejected": stats.get("rejected_steps"),
            "ok": ok, "message": msg or ("" if ok else "non-finite error")}


def skipped_row(method: str, sweep: str, param: float, reason: str) -> Row:
    """The row of a setting that was not run."""
    return {"method": method, "sweep": sweep, "setting": setting_label(settings_of(sweep, param)),
            "param": param, "error": None, "cpu_s": None, "steps": None, "rejected": None,
            "ok": False, "skipped": True, "message": reason}


def run_sweeps(model: mbd2d.Model, t_end: float, steps: int, sweeps: Sequence[Sweep],
               error_of: Callable[[mbd2d.DynamicsResult], dict[str, float]],
               repeats: int, log: bool = True,
               skip_after_s: float | None = None) -> list[Row]:
    """Every point of every sweep; `error_of(res)` gives {"error": ..., other fields}.

    Each sweep runs from its loosest to its tightest setting; once one run of a sweep takes
    longer than `skip_after_s`, its remaining (costlier) settings are recorded as skipped.
    """
    rows = []
    for method, sweep, params in sweeps:
        slow: float | None = None
        for p in params:
            kw = settings_of(sweep, p)
            if slow is not None:
                rows.append(skipped_row(method, sweep, p, f"skipped: a looser setting took "
                                                          f"{slow:.1f} s (time budget)"))
                continue
            res, sec, msg = timed_run(model, t_end, steps, method, kw, repeats)
            extra = error_of(res) if (res is not None and not msg) else {"error": None}
            row = make_row(method, sweep, p, kw, res, sec, msg, extra.pop("error"))
            row.update(extra)
            rows.append(row)
            if log:
                print("  " + format_row(row), flush=True)
            if skip_after_s is not None and sec > skip_after_s:
                slow = sec
    return rows


def format_row(row: Row) -> str:
    """One line of the printed table."""
    err = f"{row['error']:9.2e}" if row["error"] is not None else f"{'-':>9s}"
    steps = row["steps"] if row["steps"] is not None else "-"
    cpu = f"{row['cpu_s']:9.4f}" if row["cpu_s"] is not None else f"{'-':>9s}"
    tail = "" if row["ok"] else ("  " if row.get("skipped") else "  FAILED: ") \
        + row["message"][:110]
    return f"{row['method']:18s} {row['setting']:24s} {err} {cpu} s {steps!s:>7s}{tail}"


# ===================================================================== free four-bar
FOURBAR_SWEEPS: list[Sweep] = [
    ("dopri5", "rtol", _decades(1e-3, 1e-11)),
    ("partitioned", "rtol", _decades(1e-3, 1e-11)),
    ("generalized-alpha", "h", _steps_125(1e-2, 1e-4)),
    ("generalized-alpha", "rtol", _decades(1e-3, 1e-8)),
    ("baumgarte-rk4", "h", _steps_125(1e-2, 1e-4)),
]
FOURBAR_QUICK: list[Sweep] = [
    ("dopri5", "rtol", [1e-3, 1e-5, 1e-7, 1e-9, 1e-11]),
    ("partitioned", "rtol", [1e-3, 1e-5, 1e-7, 1e-9, 1e-11]),
    ("generalized-alpha", "h", [1e-2, 1e-3]),
    ("generalized-alpha", "rtol", [1e-3, 1e-5, 1e-7]),
    ("baumgarte-rk4", "h", [1e-2, 1e-3, 2e-4]),
]
FOURBAR_ANGLES = (2, 5, 8)        # theta of crank, coupler, rocker in q


class FourBar:
    """The free four-bar as one degree of freedom in the crank angle phi.

    The crank turns about the ground pivot O2 = (0, 0), its tip is A = l1 (cos phi, sin phi);
    the rocker turns about O4 = (l0, 0) and the coupler joins A to the rocker's tip
    B = O4 - l3 (cos th3, sin th3) = A + l2 (cos th2, sin th2) (th2, th3 are the body angles
    of coupler and rocker; each bar's local x axis points from its first joint to its second,
    as in bench/models.py). B is the intersection of the circles about A (radius l2) and O4
    (radius l3) on the side `sign` of the line A -> O4.

    Lagrange's equation: M(phi) phi'' + 1/2 M'(phi) phi'^2 + V'(phi) = 0, with
    M = sum_i m_i |dr_i/dphi|^2 + I_i (dth_i/dphi)^2 and V = g sum_i m_i y_i; dth/dphi and
    d2th/dphi2 from differentiating the loop closure A + l2 u2 + l3 u3 = O4 once and twice.
    Every function also accepts complex phi (lib = cmath), for complex-step checks of M', V'.
    """

    def __init__(self, density: float = 1.0, sign: float = 1.0) -> None:
        lengths = {name: length for name, length, _ in FOURBAR_BARS}
        self.l1, self.l2, self.l3 = lengths["crank"], lengths["coupler"], lengths["rocker"]
        self.l0 = FOURBAR_GROUND
        self.m = [density * self.l1, density * self.l2, density * self.l3]
        self.inertia = [m * length ** 2 / 12 for m, length in
                        zip(self.m, (self.l1, self.l2, self.l3))]
        self.sign = sign

    # --------------------------------------------------------------- position level
    def closure(self, phi: complex, lib: ModuleType = math) -> tuple[complex, ...]:
        """(cos phi, sin phi, cos th2, sin th2, cos th3, sin th3) on the chosen branch."""
        c1, s1 = lib.cos(phi), lib.sin(phi)
        ax, ay = self.l1 * c1, self.l1 * s1
        dx, dy = self.l0 - ax, -ay                               # A -> O4
        dist = lib.sqrt(dx * dx + dy * dy)
        a = (self.l2 ** 2 - self.l3 ** 2 + dist * dist) / (2 * dist)
        hh = self.sign * lib.sqrt(self.l2 ** 2 - a * a)
        bx = ax + (a * dx - hh * dy) / dist
        by = ay + (a * dy + hh * dx) / dist
        return (c1, s1, (bx - ax) / self.l2, (by - ay) / self.l2,
                (self.l0 - bx) / self.l3, -by / self.l3)

    def angles(self, phi: float) -> tuple[float, float]:
        """Coupler and rocker angles th2, th3 (principal values)."""
        _, _, c2, s2, c3, s3 = self.closure(phi)
        return math.atan2(s2, c2), math.atan2(s3, c3)

    def rates(self, cs: tuple[complex, ...]) -> tuple[complex, ...]:
        """(a2, a3, b2, b3): dth/dphi and d2th/dphi2 of coupler and rocker."""
        c1, s1, c2, s2, c3, s3 = cs
        l1, l2, l3 = self.l1, self.l2, self.l3
        # [-l2 s2, -l3 s3; l2 c2, l3 c3] x = rhs, det = l2 l3 sin(th3 - th2)
        det = l2 * l3 * (s3 * c2 - c3 * s2)

        def solve(r1: complex, r2: complex) -> tuple[complex, complex]:
            return ((l3 * c3 * r1 + l3 * s3 * r2) / det, (-l2 * c2 * r1 - l2 * s2 * r2) / det)

        a2, a3 = solve(l1 * s1, -l1 * c1)
        b2, b3 = solve(l1 * c1 + l2 * a2 * a2 * c2 + l3 * a3 * a3 * c3,
                       l1 * s1 + l2 * a2 * a2 * s2 + l3 * a3 * a3 * s3)
        return a2, a3, b2, b3

    def terms(self, phi: complex, lib: ModuleType = math) -> tuple[complex, complex, complex,
                                                                     complex]:
        """M, M', V, V' at phi."""
        cs = self.closure(phi, lib)
        c1, s1, c2, s2, c3, s3 = cs
        a2, a3, b2, b3 = self.rates(cs)
        l1, h2, h3 = self.l1, self.l2 / 2, self.l3 / 2
        # centre-of-mass velocities per unit phi' (J) and their phi-derivatives (K)
        j = [(-0.5 * l1 * s1, 0.5 * l1 * c1),
             (-l1 * s1 - h2 * a2 * s2, l1 * c1 + h2 * a2 * c2),
             (h3 * a3 * s3, -h3 * a3 * c3)]
        k = [(-0.5 * l1 * c1, -0.5 * l1 * s1),
             (-l1 * c1 - h2 * (b2 * s2 + a2 * a2 * c2), -l1 * s1 + h2 * (b2 * c2 - a2 * a2 * s2)),
             (h3 * (b3 * s3 + a3 * a3 * c3), -h3 * (b3 * c3 - a3 * a3 * s3))]
        y = (0.5 * l1 * s1, l1 * s1 + h2 * s2, -h3 * s3)
        rate, drate = (1.0, a2, a3), (0.0, b2, b3)
        mm = sum(m * (jx * jx + jy * jy) + i * w * w
                 for m, i, (jx, jy), w in zip(self.m, self.inertia, j, rate))
        dmm = sum(2 * m * (jx * kx + jy * ky) + 2 * i * w * dw
                  for m, i, (jx, jy), (kx, ky), w, dw in zip(self.m, self.inertia, j, k,
                                                              rate, drate))
        v = G * sum(m * yy for m, yy in zip(self.m, y))
        dv = G * sum(m * jy for m, (_, jy) in zip(self.m, j))
        return mm, dmm, v, dv

    def rhs(self, t: float, y: np.ndarray) -> list[float]:
        """(phi', phi'') from Lagrange's equation."""
        mm, dmm, _, dv = self.terms(y[0])
        return [y[1], -(0.5 * dmm * y[1] ** 2 + dv) / mm]

    def energy(self, y: np.ndarray) -> float:
        """T + V of the state (phi, phi')."""
        mm, _, v, _ = self.terms(y[0])
        return 0.5 * mm * y[1] ** 2 + v

    # --------------------------------------------------------------- checks and solution
    def derivative_check(self, phis: Sequence[float]) -> dict[str, float]:
        """Largest relative difference of M' and V' from their complex-step values
        Im f(phi + i h)/h (h = 1e-30, exact to round-off), and from central differences."""
        hc, hf = 1e-30, 1e-6
        cstep = fdiff = 0.0
        for phi in phis:
            mm, dmm, _, dv = self.terms(phi)
            mc, _, vc, _ = self.terms(complex(phi, hc), cmath)
            mp, _, vp, _ = self.terms(phi + hf)
            mn, _, vn, _ = self.terms(phi - hf)
            scale_m, scale_v = abs(dmm) + mm, abs(dv) + G * sum(self.m)
            cstep = max(cstep, abs(mc.imag / hc - dmm) / scale_m, abs(vc.imag / hc - dv) / scale_v)
            fdiff = max(fdiff, abs((mp - mn) / (2 * hf) - dmm) / scale_m,
                        abs((vp - vn) / (2 * hf) - dv) / scale_v)
        return {"complex_step": cstep, "central_difference": fdiff}

    def solve(self, phi0: float, t: np.ndarray, rtol: float = 1e-13,
              atol: float = 1e-13) -> np.ndarray:
        """(phi, phi') at the times t, released at rest (DOP853)."""
        sol = solve_ivp(self.rhs, (t[0], t[-1]), [phi0, 0.0], method="DOP853", t_eval=t,
                        rtol=rtol, atol=atol)
        if not sol.success:
            raise RuntimeError(f"reference integration failed: {sol.message}")
        return sol.y.T


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles mapped into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def fourbar_angles(res: mbd2d.DynamicsResult) -> np.ndarray:
    """Crank, coupler and rocker angles (rows: outputs)."""
    return res.q[:, FOURBAR_ANGLES]


def oracle_angles(bar: FourBar, phi: np.ndarray) -> np.ndarray:
    """Crank, coupler and rocker angles of the one-DOF solution phi (rows: outputs)."""
    th = np.array([bar.angles(p) for p in phi])
    return np.column_stack([phi, th])


def angle_difference(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| over outputs and angles, the coupler and rocker columns taken modulo 2 pi
    (the closed form returns principal values; the crank angle is continuous in both)."""
    d = np.asarray(a) - np.asarray(b)
    d[:, 1:] = wrap(d[:, 1:])
    return float(np.abs(d).max())


def fourbar_reference(model: mbd2d.Model, t: np.ndarray) -> tuple[np.ndarray, dict]:
    """The tight mbd2d reference (crank, coupler, rocker angles at t) and its checks."""
    q0 = model.dynamics(t_end=0.01, steps=1).q[0]
    phi0 = float(q0[2])
    kw = dict(method="dopri5", rtol=1e-12, atol=1e-14)
    tighter = dict(method="dopri5", rtol=1e-13, atol=1e-15)
    ref = fourbar_angles(model.dynamics(t_end=t[-1], steps=len(t) - 1, **kw))
    ref2 = fourbar_angles(model.dynamics(t_end=t[-1], steps=len(t) - 1, **tighter))
    # the branch of the closed form: the one that reproduces the assembled q0
    bar = min((FourBar(sign=s) for s in (1.0, -1.0)),
              key=lambda b: float(np.abs(wrap(np.array(b.angles(phi0)) - q0[[5, 8]])).max()))
    start = float(np.abs(wrap(np.array(bar.angles(phi0)) - q0[[5, 8]])).max())
    y = bar.solve(phi0, t)
    y_loose = bar.solve(phi0, t, rtol=1e-11, atol=1e-11)
    indep = oracle_angles(bar, y[:, 0])
    e = np.array([bar.energy(s) for s in y])
    check = {
        "mbd2d_vs_independent": angle_difference(ref, indep),
        "mbd2d_tighter_change": angle_difference(ref2, ref),
        "independent_vs_rtol_1e-11": float(np.abs(y_loose[:, 0] - y[:, 0]).max()),
        "independent_energy_drift_J": float(np.abs(e - e[0]).max()),
        "start_closure_vs_assembled_q0": start,
        "derivatives": bar.derivative_check(np.linspace(-math.pi, math.pi, 13)),
    }
    desc = (f"mbd2d dopri5 {setting_label({'rtol': 1e-12, 'atol': 1e-14})}, checked against "
            f"dopri5 rtol=1e-13, atol=1e-15 and against an independent one-DOF Lagrange "
            f"integration in the crank angle (scipy DOP853, rtol = atol = 1e-13) from the "
            f"assembled q0 (crank angle {phi0:.12f} rad, at rest)")
    return ref, {"description": desc, "check": check["mbd2d_vs_independent"],
                 "checks": check, "phi0": phi0}


def fourbar(repeats: int = 3, quick: bool = False) -> dict:
    """Work-precision data of the free four-bar (10 s, 101 outputs).

    Parameters
    ----------
    repeats : int
        Timing repeats of runs under SLOW_RUN_S.
    quick : bool
        A reduced sweep.

    Returns
    -------
    dict
        {"model", "reference", "rows"}.
    """
    model = free_fourbar()
    t = np.linspace(0.0, T_END, STEPS + 1)
    ref, reference = fourbar_reference(model, t)

    def error_of(res: mbd2d.DynamicsResult) -> dict[str, float]:
        return {"error": angle_difference(fourbar_angles(res), ref)}

    rows = run_sweeps(model, T_END, STEPS, FOURBAR_QUICK if quick else FOURBAR_SWEEPS,
                      error_of, repeats, skip_after_s=SKIP_AFTER_S)
    return {"model": "free four-bar (bench/models.free_fourbar), 10 s, 101 outputs; error: max "
                     "abs error of the crank, coupler and rocker angles (rad)",
            "reference": reference, "rows": rows}


# ===================================================================== Andrews' squeezer
ANDREWS_SWEEPS: list[Sweep] = [
    ("dopri5", "rtol", _decades(1e-3, 1e-11)),
    ("partitioned", "rtol", _decades(1e-3, 1e-11)),
    ("generalized-alpha", "h", [4e-5, 2e-5, 1e-5, 5e-6]),
    ("generalized-alpha", "rtol", _decades(1e-3, 1e-8)),
    ("baumgarte-rk4", "h", [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6]),
]
ANDREWS_QUICK: list[Sweep] = [
    ("dopri5", "rtol", [1e-4, 1e-7, 1e-10]),
    ("partitioned", "rtol", [1e-4, 1e-7, 1e-10]),
    ("generalized-alpha", "h", [2e-5]),
    ("generalized-alpha", "rtol", [1e-4, 1e-6]),
    ("baumgarte-rk4", "h", [5e-5, 1e-5]),
]


def andrews_example() -> ModuleType:
    """examples/andrews.py as a module."""
    spec = importlib.util.spec_from_file_location("andrews_example", EXAMPLES / "andrews.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def andrews(repeats: int = 3, quick: bool = False) -> dict:
    """Work-precision data of Andrews' squeezer (t = 0.03 s, error as in bench/andrews.py).

    Parameters
    ----------
    repeats : int
        Timing repeats of runs under SLOW_RUN_S.
    quick : bool
        A reduced sweep.

    Returns
    -------
    dict
        {"model", "reference", "rows"}.
    """
    ex = andrews_example()
    model = ex.build()

    def error_of(res: mbd2d.DynamicsResult) -> dict[str, float]:
        return {"error": float(np.abs(ex.angle_errors(res)).max())}

    tight = model.dynamics(t_end=ex.T_END, steps=1, method="dopri5", rtol=1e-12, atol=1e-14)
    check = error_of(tight)["error"]
    reference = {"description": "IVP test set (Mazzia & Magherini) reference at t = 0.03 s "
                                "(RADAU5, 16 digits); check: mbd2d dopri5 rtol=1e-12, "
                                "atol=1e-14 against it",
                 "check": check}
    rows = run_sweeps(model, ex.T_END, 1, ANDREWS_QUICK if quick else ANDREWS_SWEEPS,
                      error_of, repeats, skip_after_s=SKIP_AFTER_S)
    return {"model": "Andrews' squeezer (examples/andrews.py) to t = 0.03 s; error: max abs "
                     "error of the 7 relative angles at t = 0.03 (rad)",
            "reference": reference, "rows": rows}


# ===================================================================== N-four-bar
#: N = 5 is costly: the cranks pass the singular (all-horizontal) configuration twice a
#: swing, where the adaptive methods cut the step to ~1e-8 s and the index-1 solve takes its
#: rank-revealing fallback; on this 2-core machine dopri5 or partitioned at rtol <= 1e-9 take
#: minutes (or end in a step-size underflow) and a fixed step of 1 ms takes ~6 s. The sweeps
#: stop at the settings that fit the benchmark's time budget.
NFOURBAR_SWEEPS: list[Sweep] = [
    ("dopri5", "rtol", [1e-3, 1e-4, 1e-5, 1e-6]),
    ("partitioned", "rtol", [1e-3, 1e-4, 1e-5, 1e-6]),
    ("generalized-alpha", "h", [1e-2, 5e-3, 2e-3]),
    ("generalized-alpha", "rtol", [1e-3, 1e-4, 1e-5]),
    ("baumgarte-rk4", "h", [1e-2, 5e-3, 2e-3]),
]
NFOURBAR_QUICK: list[Sweep] = [
    ("dopri5", "rtol", [1e-3, 1e-5]),
    ("partitioned", "rtol", [1e-3, 1e-5]),
    ("generalized-alpha", "h", [1e-2]),
    ("generalized-alpha", "rtol", [1e-3]),
    ("baumgarte-rk4", "h", [1e-2]),
]
NFOURBAR_SKIP_AFTER_S = 3.0
#: N = 1 is cheap: the same sweeps, fewer points
NFOURBAR1_SWEEPS: list[Sweep] = [
    ("dopri5", "rtol", _decades(1e-3, 1e-11)[::2]),
    ("partitioned", "rtol", _decades(1e-3, 1e-11)[::2]),
    ("generalized-alpha", "h", [1e-2, 1e-3, 1e-4]),
    ("generalized-alpha", "rtol", [1e-3, 1e-5, 1e-7]),
    ("baumgarte-rk4", "h", [1e-2, 1e-3, 1e-4]),
]
BRANCH_SPREAD = 1e-3      # rad: the cranks are parallel (parallelogram branch kept)


def reduced_nfourbar(n: int, t: np.ndarray, th0: float = math.pi / 2, omega0: float = -1.0,
                     rtol: float = 1e-13, atol: float = 1e-13) -> np.ndarray:
    """The parallelogram branch as one degree of freedom (tests/test_failure_modes): every
    crank at th, couplers translating, ((N+1)/3 + N) th'' = -((N+1)/2 + N) g cos th
    (m = L = 1), integrated with scipy DOP853; (th, th') at the times t (rows)."""
    inertia = (n + 1) / 3.0 + n
    load = ((n + 1) / 2.0 + n) * G

    def f(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -load * math.cos(y[0]) / inertia]

    sol = solve_ivp(f, (t[0], t[-1]), [th0, omega0], method="DOP853", t_eval=t, rtol=rtol,
                    atol=atol)
    if not sol.success:
        raise RuntimeError(f"reduced N-four-bar integration failed: {sol.message}")
    return sol.y.T


def nfourbar_measures(res: mbd2d.DynamicsResult, n: int, ref: np.ndarray) -> dict[str, Any]:
    """Crank-angle error against the reduced solution (max over outputs and cranks), the final
    error, the spread max |th_k - th_0| and whether the parallelogram branch was kept."""
    th = np.array([res.body(f"crank{k}").theta for k in range(n + 1)])
    dev = np.abs(th - ref[: th.shape[1], 0])
    spread = float(np.abs(wrap(th - th[0])).max())
    final = float(dev[:, -1].max())
    return {"error": float(dev.max()), "final_error": final, "spread": spread,
            "branch_kept": bool(spread < BRANCH_SPREAD)}


def nfourbar_reference(n: int, t: np.ndarray, mbd2d_check: bool = True
                       ) -> tuple[np.ndarray, dict]:
    """The reduced solution at t and its checks: against DOP853 at rtol 1e-11, the first
    integral th'^2/2 + (load/inertia) sin th, and (with `mbd2d_check`; minutes for N >= 2)
    a tight mbd2d dopri5 run of the full model."""
    ref = reduced_nfourbar(n, t)
    loose = reduced_nfourbar(n, t, rtol=1e-11, atol=1e-11)
    k = ((n + 1) / 2.0 + n) * G / ((n + 1) / 3.0 + n)
    first = 0.5 * ref[:, 1] ** 2 + k * np.sin(ref[:, 0])
    checks: dict[str, Any] = {
        "reduced_vs_rtol_1e-11": float(np.abs(loose[:, 0] - ref[:, 0]).max()),
        "reduced_first_integral_drift": float(np.abs(first - first[0]).max())}
    check = checks["reduced_vs_rtol_1e-11"]
    desc = (f"reduced one-DOF parallelogram solution, N = {n} (Lagrange equation of "
            "tests/test_failure_modes.reduced_nfourbar), scipy DOP853 rtol = atol = 1e-13; ")
    if mbd2d_check:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", mbd2d.errors.MbdWarning)
            tight = free_nfourbar(n).dynamics(t_end=t[-1], steps=len(t) - 1, method="dopri5",
                                              rtol=1e-12, atol=1e-14)
        mbd = nfourbar_measures(tight, n, ref)
        checks.update({"mbd2d_dopri5_1e-12_vs_reduced": mbd["error"],
                       "mbd2d_dopri5_1e-12_spread": mbd["spread"]})
        check = mbd["error"]
        desc += "check: mbd2d dopri5 rtol=1e-12, atol=1e-14 of the full model against it"
    else:
        desc += ("check: the reduced solution at rtol = atol = 1e-11 against it (a tight "
                 "mbd2d run of the full model does not fit the time budget at this N)")
    return ref, {"description": desc, "check": check, "checks": checks}


def nfourbar_rows(n: int, sweeps: Sequence[Sweep], repeats: int, mbd2d_check: bool = True,
                  skip_after_s: float | None = None) -> tuple[list[Row], dict]:
    """Rows (each with "n" and "variant") and the reference of the N-four-bar."""
    t = np.linspace(0.0, T_END, STEPS + 1)
    ref, reference = nfourbar_reference(n, t, mbd2d_check)
    print(f"  N = {n}: reference check {reference['check']:.2e}", flush=True)
    rows = run_sweeps(free_nfourbar(n), T_END, STEPS, sweeps,
                      lambda res: nfourbar_measures(res, n, ref), repeats,
                      skip_after_s=skip_after_s)
    for r in rows:
        r["n"], r["variant"] = n, f"N={n}"
    return rows, reference


def nfourbar(repeats: int = 3, quick: bool = False, with_n1: bool = True) -> dict:
    """Work-precision data of the free IFToMM N-four-bar, N = 5 (and N = 1), 10 s.

    Parameters
    ----------
    repeats : int
        Timing repeats of runs under SLOW_RUN_S.
    quick : bool
        A reduced sweep (and no N = 1).
    with_n1 : bool
        Also sweep N = 1 (fewer points).

    Returns
    -------
    dict
        {"model", "reference", "rows"}; every row also has "n", "final_error", "spread"
        (max |th_k - th_0|) and "branch_kept" (spread < BRANCH_SPREAD).

    Notes
    -----
    N = 5 is swept at loose settings only and without a tight mbd2d check run (see
    NFOURBAR_SWEEPS); a sweep stops once a run takes over NFOURBAR_SKIP_AFTER_S.
    """
    rows, ref5 = nfourbar_rows(5, NFOURBAR_QUICK if quick else NFOURBAR_SWEEPS, repeats,
                               mbd2d_check=False, skip_after_s=NFOURBAR_SKIP_AFTER_S)
    reference = {"description": ref5["description"], "check": ref5["check"],
                 "checks": {"N=5": ref5["checks"]}}
    if with_n1 and not quick:
        rows1, ref1 = nfourbar_rows(1, NFOURBAR1_SWEEPS, repeats,
                                    skip_after_s=SKIP_AFTER_S)
        rows += rows1
        reference["checks"]["N=1"] = ref1["checks"]
        reference["check_n1"] = ref1["check"]
    return {"model": "free IFToMM N-four-bar (bench/models.free_nfourbar), 10 s, 101 outputs; "
                     "error: max abs crank-angle error against the reduced solution (rad)",
            "reference": reference, "rows": rows}


# ===================================================================== entry point
STUDIES: dict[str, Callable[..., dict]] = {"fourbar": fourbar, "andrews": andrews,
                                           "nfourbar": nfourbar}


def study(name: str, repeats: int = 3, quick: bool = False) -> dict:
    """One study ("fourbar", "andrews" or "nfourbar") with its sweep settings recorded.

    Returns
    -------
    dict
        The study's {"model", "reference", "rows"} plus "sweeps" (the settings that were
        asked for) and "quick".
    """
    data = STUDIES[name](repeats, quick=quick)
    data["sweeps"] = describe_sweeps(name, quick)
    data["quick"] = quick
    return data


def describe_sweeps(name: str, quick: bool) -> list[str]:
    """The sweeps of a study as text, one line per method and sweep."""
    table = {"fourbar": (FOURBAR_QUICK, FOURBAR_SWEEPS), "andrews": (ANDREWS_QUICK,
                                                                     ANDREWS_SWEEPS),
             "nfourbar": (NFOURBAR_QUICK, NFOURBAR_SWEEPS)}[name][0 if quick else 1]
    lines = [f"{'N = 5: ' if name == 'nfourbar' else ''}{m} {sw}: "
             + ", ".join(f"{v:.0e}" for v in vals) for m, sw, vals in table]
    if name == "nfourbar" and not quick:
        lines += [f"N = 1: {m} {sw}: " + ", ".join(f"{v:.0e}" for v in vals)
                  for m, sw, vals in NFOURBAR1_SWEEPS]
    return lines


# ===================================================================== chart
COLOURS = {("dopri5", "rtol"): "tab:blue", ("partitioned", "rtol"): "tab:orange",
           ("generalized-alpha", "h"): "tab:green", ("generalized-alpha", "rtol"): "tab:olive",
           ("baumgarte-rk4", "h"): "tab:red"}
MARKERS = {"rtol": "o", "h": "s"}
STYLES = ("-", "--", ":", "-.")


def _line_key(row: Row) -> tuple[str, str, str]:
    return row["method"], row.get("sweep", "rtol" if "rtol" in row["setting"] else "h"), \
        row.get("variant", "")


def _label(method: str, sweep: str, variant: str) -> str:
    fam = "fixed h" if sweep == "h" else "rtol"
    return f"{method} ({fam})" + (f", {variant}" if variant else "")


def chart(data: dict, path: str | Path, extra_points: list[dict] | None = None) -> Path:
    """Log-log work-precision chart: error against CPU time, one line per method and sweep
    (and per variant, e.g. N); failed settings are left out.

    Parameters
    ----------
    data : dict
        The output of fourbar(), andrews() or nfourbar().
    path : str or Path
        The PNG to write.
    extra_points : list of dict, optional
        Peers, each {"label": str, "rows": [{"error", "cpu_s", ...}]}, drawn as black-edged
        marker lines.

    Returns
    -------
    Path
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.0, 6.0))
    lines: dict[tuple[str, str, str], list[Row]] = {}
    for r in data["rows"]:
        if r.get("ok") and r.get("error") is not None:
            lines.setdefault(_line_key(r), []).append(r)
    variants = sorted({k[2] for k in lines}, key=lambda v: (v != "N=5", v))
    for (method, sweep, variant), rows in lines.items():
        rows = sorted(rows, key=lambda r: r["cpu_s"])
        ax.loglog([r["cpu_s"] for r in rows], [max(r["error"], 1e-16) for r in rows],
                  color=COLOURS.get((method, sweep), "grey"), marker=MARKERS[sweep],
                  linestyle=STYLES[variants.index(variant) % len(STYLES)], markersize=4,
                  label=_label(method, sweep, variant))
        for r in (rows[0], rows[-1]):
            ax.annotate(f"{r['param']:.0e}", (r["cpu_s"], max(r["error"], 1e-16)),
                        fontsize=6, textcoords="offset points", xytext=(3, 3))
    for i, peer in enumerate(extra_points or []):
        rows = sorted((r for r in peer["rows"] if r.get("error") is not None),
                      key=lambda r: r["cpu_s"])
        ax.loglog([r["cpu_s"] for r in rows], [max(r["error"], 1e-16) for r in rows],
                  marker="DPv^"[i % 4], color="k", markerfacecolor="none", linestyle=":",
                  label=peer["label"])
    ax.set_xlabel("CPU time (s): best-of-N wall time of one run")
    ax.set_ylabel("error (rad)")
    ax.set_title(f"Work-precision: {data['model'].split(';')[0]}", fontsize=10)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.1)
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


# ===================================================================== main
def print_table(name: str, data: dict) -> None:
    """The reference check and the rows of one model."""
    print(f"\n== {name}: reference check {data['reference']['check']:.2e}")
    for r in data["rows"]:
        extra = ""
        if "branch_kept" in r:
            extra = f"  N={r['n']} final {r['final_error']:.1e} spread {r['spread']:.1e}" \
                    f" {'branch kept' if r['branch_kept'] else 'LEFT THE BRANCH'}"
        print("  " + format_row(r) + extra)


def _clean(obj: Any) -> Any:
    """JSON-safe copy (non-finite floats become None)."""
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def main(argv: Sequence[str] | None = None) -> dict:
    """Run the three sweeps, write DIR/work_precision.json and the three charts."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(BENCH / "results"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="a reduced sweep")
    ap.add_argument("--repeats", type=int, default=3, help="timing repeats of fast runs")
    a = ap.parse_args(argv)
    out = Path(a.out)
    t0 = time.perf_counter()
    results = {}
    for name, fn in (("fourbar", fourbar), ("andrews", andrews), ("nfourbar", nfourbar)):
        print(f"{name} ...", flush=True)
        t1 = time.perf_counter()
        results[name] = fn(a.repeats, quick=a.quick)
        results[name]["runtime_s"] = time.perf_counter() - t1
    total = time.perf_counter() - t0
    results["meta"] = {"quick": a.quick, "repeats": a.repeats, "total_runtime_s": total,
                       "timing": "best-of-N wall time (time.perf_counter) of model.dynamics"}
    out.mkdir(parents=True, exist_ok=True)
    (out / "work_precision.json").write_text(json.dumps(_clean(results), indent=1),
                                             encoding="utf-8")
    for name in ("fourbar", "andrews", "nfourbar"):
        chart(results[name], out / f"wp_{name}.png")
        print_table(name, results[name])
    print(f"\nwrote {out / 'work_precision.json'} and wp_*.png; total {total:.1f} s")
    return results


if __name__ == "__main__":
    main()
