"""Design sensitivities of forward dynamics' multipliers: the joints' reactions and the
drivers' efforts (``dlam_dp``, ``reaction_dp``, ``effort_dp``), by dopri5 and
generalized-alpha, on the dense and the band path, against references computed without the
sensitivity code.

The multipliers of an output are those of the index-1 equations at the output's state, a
function of (q, q_dot, t; p): their sensitivity is its derivative along the state's
sensitivities (S, S_dot), the multiplier part of the saddle-point solve that gives S_ddot.

* The swing (a bar on a pin with a torsion spring and damper under gravity): the pin force
  on the bar is m r_ddot - m g with r = a (cos theta, sin theta); its derivative along six
  parameters (spring, damper, mass, inertia, gravity, the pin's place on the bar) from the
  reduced equation and its variational equations, integrated by scipy at 1e-13.
* A driven crank (theta(t) = w t + A sin(W t) under gravity): the motor torque
  tau = I_O theta_ddot - m a (g_y cos theta - g_x sin theta) and its derivatives in closed
  form for eight parameters (mass, inertia, both gravity components, the pin, the drive's
  speed, amplitude and frequency).
* Generalized-alpha at a fixed step: the derivatives of its own outputs, so central
  differences of plain runs at the same step (Richardson) for eleven parameters of every kind.
* dopri5 on the same model: central differences of runs at rtol 1e-12.
* Redundant constraints (a parallelogram with an extra link): the minimum-norm multipliers'
  derivatives against differences of runs.
* The band path gives the dense path's; sweeps and tolerance studies carry them.
"""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from conftest import model_from_toml
from test_genalpha_sensitivity import consistent_start, ga
from test_sensitivities import SWING, add_force_kinds, free_slider_crank, rel_close

EX = Path(__file__).resolve().parents[1] / "examples"


# ------------------------------------------------------------------ the swing's pin force

#: the swing of test_sensitivities.SWING: mass, inertia, pin distance, gravity, spring
SW = dict(m=1.3, J=0.07, a=0.4, gy=-9.81, k=6.0, c=0.3, th0=0.2)
SWING_P = ["force.torsion.stiffness", "force.torsion.damping", "body.bar.mass",
           "body.bar.inertia", "model.gravity.1", "joint.pivot.points.1.0"]


def swing_accel(th: np.ndarray, thd: np.ndarray) -> tuple:
    """theta_ddot = f = (-k (theta - th0) - c theta_dot + m g_y a cos theta) / (J + m a^2)
    and its partial derivatives: f_theta, f_theta_dot and f_p per parameter (the pin's x
    on the bar is p = -a)."""
    m, J, a, gy, k, c, th0 = (SW[x] for x in ("m", "J", "a", "gy", "k", "c", "th0"))
    inertia = J + m * a**2
    f = (-k * (th - th0) - c * thd + m * gy * a * np.cos(th)) / inertia
    f_th = (-k - m * gy * a * np.sin(th)) / inertia
    fp = {"force.torsion.stiffness": -(th - th0) / inertia,
          "force.torsion.damping": -thd / inertia,
          "body.bar.mass": (gy * a * np.cos(th) - f * a**2) / inertia,
          "body.bar.inertia": -f / inertia,
          "model.gravity.1": m * a * np.cos(th) / inertia,
          "joint.pivot.points.1.0": -(m * gy * np.cos(th) - 2 * f * m * a) / inertia}
    return f, f_th, -c / inertia, fp


def swing_pin_force(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pin's force on the bar, F = m r_ddot - m g (n, 2), and dF/dp (n, 2, 6) along
    SWING_P: theta and its sensitivities S (S(0) = S_dot(0) = 0: the start is consistent
    and the pin's change moves x alone) by scipy DOP853 at 1e-13, then
    dF = F_theta S + F_theta_dot S_dot + F_theta_ddot S_ddot + F_p."""
    from scipy.integrate import solve_ivp

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        f, f_th, f_thd, fp = swing_accel(y[0], y[1])
        out = [y[1], f]
        for i, name in enumerate(SWING_P):
            out += [y[3 + 2 * i], f_th * y[2 + 2 * i] + f_thd * y[3 + 2 * i] + fp[name]]
        return out

    y = solve_ivp(rhs, (t[0], t[-1]), np.zeros(2 + 2 * len(SWING_P)), method="DOP853",
                  t_eval=t, rtol=1e-13, atol=1e-13).y
    th, thd = y[0], y[1]
    f, f_th, f_thd, fp = swing_accel(th, thd)
    m, a, gy = SW["m"], SW["a"], SW["gy"]
    s, c = np.sin(th), np.cos(th)
    ux, uy = -s * f - c * thd**2, c * f - s * thd**2        # r_ddot / a
    F = np.stack([m * a * ux, m * a * uy - m * gy], -1)
    dF = np.zeros((len(t), 2, len(SWING_P)))
    for i, name in enumerate(SWING_P):
        S, Sd = y[2 + 2 * i], y[3 + 2 * i]
        Sdd = f_th * S + f_thd * Sd + fp[name]
        dF[:, 0, i] = m * a * ((-c * f + s * thd**2) * S - 2 * c * thd * Sd - s * Sdd)
        dF[:, 1, i] = m * a * ((-s * f - c * thd**2) * S - 2 * s * thd * Sd + c * Sdd)
        if name == "body.bar.mass":
            dF[:, 0, i] += a * ux
            dF[:, 1, i] += a * uy - gy
        elif name == "model.gravity.1":
            dF[:, 1, i] -= m
        elif name == "joint.pivot.points.1.0":            # d/dp = -d/da
            dF[:, 0, i] -= m * ux
            dF[:, 1, i] -= m * uy
    return F, dF


def pin_errors(res: mbd2d.DynamicsResult) -> tuple[float, float]:
    """The worst relative error of the pin force and of its sensitivities (each parameter's
    against its own largest entry) against swing_pin_force."""
    F, dF = swing_pin_force(res.t)
    r, rd = res.reaction("pivot"), res.reaction_dp("pivot")
    got = np.stack([r.fx_j, r.fy_j], -1)
    gd = np.stack([rd.fx_j, rd.fy_j], 1)
    err = float(np.abs(got - F).max() / np.abs(F).max())
    derr = max(float(np.abs(gd[:, :, i] - dF[:, :, i]).max() / np.abs(dF[:, :, i]).max())
               for i in range(len(SWING_P)))
    return err, derr


def test_dopri5_pin_force_sensitivities_against_the_reduced_equation() -> None:
    """dopri5 at rtol = atol = 1e-6, 1e-8, 1e-10: the pin force's sensitivities fall with the
    tolerance like the force itself. Measured 3.0e-6, 2.5e-8, 2.3e-10 (the force 3.2e-7,
    2.6e-9, 2.3e-11)."""
    m = model_from_toml(SWING)
    errs = []
    for tol in (1e-6, 1e-8, 1e-10):
        res = m.dynamics(2.0, 20, rtol=tol, atol=tol, sensitivities=SWING_P)
        err, derr = pin_errors(res)
        print(f"\n[sensitivity] dopri5 swing pin force tol {tol:.0e}: force {err:.2e}, "
              f"sensitivities {derr:.2e}", end="")
        assert derr <= 10 * tol and err <= tol
        errs.append(derr)
    assert errs[0] > 30 * errs[1] > 30 * 30 * errs[2]


def test_generalized_alpha_pin_force_sensitivities_converge_at_order_two() -> None:
    """Generalized-alpha at h = 2e-2, 1e-2, 5e-3: the worst relative error of the pin force's
    sensitivities falls by 4 per halving. Measured 1.737e-2, 4.353e-3, 1.089e-3 (ratios
    3.99, 4.00)."""
    m = model_from_toml(SWING)
    errs = []
    for h in (2e-2, 1e-2, 5e-3):
        errs.append(pin_errors(m.dynamics(2.0, 20, sensitivities=SWING_P, **ga(h)))[1])
        print(f"\n[sensitivity] generalized-alpha swing pin force h {h:.0e}: {errs[-1]:.3e}",
              end="")
    for a, b in zip(errs, errs[1:]):
        assert 3.6 < a / b < 4.4, errs


# -------------------------------------------------------------- a driven crank's torque

CRANK = """
[model]
name = "driven crank"
gravity = [0.7, -9.81]
[[body]]
name = "crank"
q0 = [0.35, 0.0, 0.0]
mass = 2.2
inertia = 0.09
[[joint]]
name = "O"
type = "revolute"
bodies = ["ground", "crank"]
points = [[0.0, 0.0], [-0.35, 0.0]]
[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0.0, 3.0], harmonic = [{ amplitude = 0.4, omega = 5.0 }] }
"""
CRANK_P = ["body.crank.mass", "body.crank.inertia", "model.gravity.0", "model.gravity.1",
           "joint.O.points.1.0", "driver.motor.f.poly.1",
           "driver.motor.f.harmonic.0.amplitude", "driver.motor.f.harmonic.0.omega"]


def crank_torque(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The motor's torque tau = I_O theta_ddot - m a (g_y cos theta - g_x sin theta),
    I_O = J + m a^2, theta = w t + A sin(W t), and d tau / dp (n, 8) along CRANK_P (the pin's
    x on the crank is p = -a)."""
    M, J, a, gx, gy, w, A, W = 2.2, 0.09, 0.35, 0.7, -9.81, 3.0, 0.4, 5.0
    th = w * t + A * np.sin(W * t)
    thdd = -A * W**2 * np.sin(W * t)
    s, c = np.sin(th), np.cos(th)
    io, grav = J + M * a**2, gy * c - gx * s
    tau = io * thdd - M * a * grav
    dth = {"driver.motor.f.poly.1": t, "driver.motor.f.harmonic.0.amplitude": np.sin(W * t),
           "driver.motor.f.harmonic.0.omega": A * t * np.cos(W * t)}
    dthdd = {"driver.motor.f.harmonic.0.amplitude": -W**2 * np.sin(W * t),
             "driver.motor.f.harmonic.0.omega": (-2 * A * W * np.sin(W * t)
                                                 - A * W**2 * t * np.cos(W * t))}
    explicit = {"body.crank.mass": a**2 * thdd - a * grav, "body.crank.inertia": thdd,
                "model.gravity.0": M * a * s, "model.gravity.1": -M * a * c,
                "joint.O.points.1.0": -(2 * M * a * thdd - M * grav)}
    dtau_dth = M * a * (gy * s + gx * c)
    cols = [dtau_dth * dth.get(n, 0.0) + io * dthdd.get(n, 0.0) + explicit.get(n, 0.0)
            for n in CRANK_P]
    return tau, np.stack(cols, -1)


def torque_errors(res: mbd2d.DynamicsResult) -> tuple[float, float]:
    tau, dtau = crank_torque(res.t)
    got = res.effort_dp("motor")
    err = float(np.abs(res.effort("motor") - tau).max() / np.abs(tau).max())
    derr = max(float(np.abs(got[:, i] - dtau[:, i]).max() / np.abs(dtau[:, i]).max())
               for i in range(len(CRANK_P)))
    return err, derr


def test_driven_crank_torque_sensitivities_in_closed_form() -> None:
    """Forward dynamics of a fully driven crank (the motion is the drive's): the motor
    torque's sensitivities against the closed form, with the constraints' projections at
    the tolerance's level (dopri5: measured 2.0e-8 at 1e-6, 3.5e-13 at 1e-10) and
    generalized-alpha at h = 1e-3 (measured 6.6e-16: its positions are the constraints'
    and its velocities exact on this motion)."""
    m = model_from_toml(CRANK)
    loose = torque_errors(m.dynamics(2.0, 40, rtol=1e-6, atol=1e-6, sensitivities=CRANK_P))
    tight = torque_errors(m.dynamics(2.0, 40, rtol=1e-10, atol=1e-10, sensitivities=CRANK_P))
    alpha = torque_errors(m.dynamics(2.0, 40, sensitivities=CRANK_P, **ga(1e-3)))
    print(f"\n[sensitivity] driven crank torque: dopri5 1e-6 {loose[1]:.2e}, 1e-10 "
          f"{tight[1]:.2e}, generalized-alpha {alpha[1]:.2e}", end="")
    assert loose[1] <= 1e-7 and tight[1] <= 5e-12 and alpha[1] <= 1e-12
    assert loose[0] <= 1e-7 and tight[0] <= 5e-12 and alpha[0] <= 1e-12


# ------------------------------------------------------- differences of runs, every kind

NAMES11 = ["joint.O.points.0.0", "joint.A.points.0.1", "joint.B.points.1.0",
           "force.s1.stiffness", "body.rod.mass", "body.crank.inertia", "model.gravity.1",
           "force.s2.points.0.0", "force.s2.damping", "force.s2.f.poly.1", "force.p1.point.0"]


def richardson_lam(m: mbd2d.Model, name: str, run, d: float = 1e-3) -> np.ndarray:
    """d lambda / dp from plain runs: central differences at d and 2d (relative to
    max(1, |p|)), Richardson-extrapolated."""
    v = m.parameters()[name]
    step = d * max(1.0, abs(v))

    def central(hh: float) -> np.ndarray:
        return (run(m.with_params({name: v + hh})).lam -
                run(m.with_params({name: v - hh})).lam) / (2 * hh)

    return (4 * central(step) - central(2 * step)) / 3


#: parameters whose multiplier sensitivities are small against the multipliers
SMALL = ("force.s2.f.poly.1", "force.s2.damping", "force.p1.point.0")


@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_generalized_alpha_multipliers_are_derivatives_of_its_outputs(h: float) -> None:
    """The free slider-crank with a spring, a spring-damper-actuator, a torque and a point
    force, from a consistent start, at a fixed step: the multipliers' sensitivities are the
    derivatives of the run's own multipliers (Richardson differences of plain runs at
    d = 1e-3; at d = 1e-2 for the two whose sensitivities are small against the
    multipliers, the actuator's slope (0.8 against 100) and damping, where the runs'
    round-off over d dominates: 9e-9, 2.2e-8, 1.1e-7, 7.7e-7 at d = 1e-2, 3e-3, 1e-3, 3e-4
    for the slope at h = 1e-3; a pin's truncation is 1.2e-7 at d = 3e-3). Measured 2.1e-11
    to 2.6e-9 (h = 1e-2) and 8.3e-11 to 9.9e-9 (h = 1e-3) of each parameter's largest
    entry."""
    m = consistent_start(add_force_kinds(free_slider_crank()))
    res = m.dynamics(1.0, 10, sensitivities=NAMES11, **ga(h))
    assert res.dlam_dp.shape == (11, len(res.row_labels), len(NAMES11))
    for j, name in enumerate(NAMES11):
        d = 1e-2 if name in SMALL else 1e-3
        ref = richardson_lam(m, name, lambda mm: mm.dynamics(1.0, 10, **ga(h)), d=d)
        assert np.abs(ref).max() > 1e-3, name
        rel_close(res.dlam_dp[:, :, j], ref, rtol=1e-7, what=f"GA h={h:g} dlam / d {name}")


def test_dopri5_multipliers_against_central_differences() -> None:
    """The same model and parameters by dopri5: against central differences of runs at
    rtol = atol = 1e-12 (d = 1e-5; the sensitivities' run at 1e-11, as the motion's test).
    Measured 5.9e-10 to 7.7e-7 of each parameter's largest entry (the largest where the
    sensitivity is small against the multipliers: the point force's place, the actuator's
    slope)."""
    m = consistent_start(add_force_kinds(free_slider_crank()))
    res = m.dynamics(1.0, 10, rtol=1e-11, atol=1e-11, sensitivities=NAMES11)
    for j, name in enumerate(NAMES11):
        v = m.parameters()[name]
        d = 1e-5 * max(1.0, abs(v))
        up = m.with_params({name: v + d}).dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
        dn = m.with_params({name: v - d}).dynamics(1.0, 10, rtol=1e-12, atol=1e-12)
        rel_close(res.dlam_dp[:, :, j], (up.lam - dn.lam) / (2 * d), rtol=2e-6,
                  what=f"dopri5 dlam / d {name}")


# ----------------------------------------------------------------- redundant constraints

def parallelogram() -> mbd2d.Model:
    """examples/parallelogram_extra_link.toml free under gravity: masses on every body, the
    cranks started at 1.2 rad (one redundant equation, A3.y)."""
    text = (EX / "parallelogram_extra_link.toml").read_text().split("[[driver]]")[0]
    text = text.replace("1.5708]", "1.2]\nmass = 1.0\ninertia = 0.1")
    text = text.replace("q0 = [1.0, 1.0, 0.0]", "q0 = [1.0, 1.0, 0.0]\nmass = 3.0\n"
                        "inertia = 0.5")
    text = text.replace('name = "parallelogram-extra-link"',
                        'name = "p"\ngravity = [0.0, -9.81]')
    return model_from_toml(text)


@pytest.mark.parametrize("method", ["dopri5", "generalized-alpha"])
def test_redundant_constraints_minimum_norm_multipliers(method: str) -> None:
    """With a redundant equation the outputs' multipliers are the minimum-norm set; their
    sensitivities are its derivatives (the minimum-norm solution of J^T dlambda = b, as
    inverse dynamics): Richardson differences of plain runs at d = 1e-3, dopri5 at
    rtol 1e-12 and generalized-alpha at a fixed step. Measured 1.0e-11 to 6.5e-11
    (dopri5) and 5.4e-10 to 1.5e-9 (generalized-alpha)."""
    m = parallelogram()
    names = ["body.crank1.mass", "body.crank3.mass", "body.coupler.mass", "model.gravity.1"]
    kw = ga(1e-3) if method == "generalized-alpha" else dict(method=method, rtol=1e-12,
                                                              atol=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.RedundantConstraintWarning)
        res = m.dynamics(0.5, 10, sensitivities=names, **kw)
        assert res.stats["redundant_rows"] == ["A3.y"]
        for j, name in enumerate(names):
            ref = richardson_lam(m, name, lambda mm: mm.dynamics(0.5, 10, **kw))
            rel_close(res.dlam_dp[:, :, j], ref, rtol=1e-8,
                      what=f"{method} redundant dlam / d {name}")


# ------------------------------------------------------------------------------ paths

@pytest.mark.parametrize("method", ["dopri5", "generalized-alpha"])
def test_band_path_gives_the_dense_multiplier_sensitivities(method: str) -> None:
    """The free N-four-bar (N = 20) on the band path and the dense path: the same
    multipliers' sensitivities to 1e-10 of their scale."""
    sys.path.insert(0, str(EX))
    from nfourbar import build
    m = build(20, driven=False, omega0=1.0)
    m.bodies[3].mass *= 1.7
    names = ["model.gravity.1", "body.crank3.mass"]
    kw = ga(2e-3) if method == "generalized-alpha" else dict(method=method, rtol=1e-9,
                                                              atol=1e-9)
    band = m.dynamics(0.2, 4, solver="banded", sensitivities=names, **kw)
    dense = m.dynamics(0.2, 4, solver="dense", sensitivities=names, **kw)
    assert band.stats["solver"] == "banded" and dense.stats["solver"] == "dense"
    assert np.abs(dense.dlam_dp).max() > 0
    assert np.abs(band.dlam_dp - dense.dlam_dp).max() <= 1e-10 * np.abs(dense.dlam_dp).max()


# ---------------------------------------------------------------------- studies

def test_sweep_cases_carry_the_efforts_sensitivities() -> None:
    """A dynamics sweep with sensitivities: dlam_dp and deffort_dp of every case are its
    single run's, bit for bit (dopri5 and generalized-alpha)."""
    m = model_from_toml(CRANK)
    values = [2.0, 2.2, 2.5]
    for kw in (dict(method="dopri5"), dict(method="generalized-alpha", h=2e-3)):
        ds = mbd2d.sweep(m, {"body.crank.mass": values}, "dynamics", t_end=0.2, steps=4,
                         sensitivities=CRANK_P[:3], workers=1, **kw)
        for c, v in enumerate(values):
            one = m.with_params({"body.crank.mass": v}).dynamics(
                0.2, 4, sensitivities=CRANK_P[:3], **kw)
            assert np.array_equal(ds.dlam_dp.values[c], one.dlam_dp)
            assert np.array_equal(ds.deffort_dp.values[c][:, 0], one.effort_dp("motor"))


def test_tolerance_study_of_the_motor_torque() -> None:
    """The first-order scatter of the driven crank's motor torque from sigmas on the mass and
    the pin: sqrt(sum (d tau / dp sigma)^2) from the closed form, to 1e-9 (dopri5 at
    1e-10), and the Monte Carlo estimate within its sampling error."""
    m = model_from_toml(CRANK)
    sig = {"body.crank.mass": 0.05, "joint.O.points.1.0": 0.002}
    tol = mbd2d.tolerance(m, sig, "dynamics", samples=200, workers=1, t_end=1.0, steps=10,
                          rtol=1e-10, atol=1e-10)
    _, dtau = crank_torque(np.linspace(0.0, 1.0, 11))
    want = np.sqrt((dtau[:, 0] * 0.05)**2 + (dtau[:, 4] * 0.002)**2)
    std = tol.dataset.effort_std_linear.sel(driver="motor").values
    assert np.abs(std - want).max() <= 1e-9 * want.max()
    mc = tol.dataset.effort_std_mc.sel(driver="motor").values
    assert np.abs(mc - std).max() <= 0.2 * std.max()
