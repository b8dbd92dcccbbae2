"""Charts and numbers of docs/dynamics.md: where the forward-dynamics methods fail.

    python docs/failure_modes.py            (from the repository root; about 30 s)

Writes docs/img/dyn_*.png and prints every number the page quotes. The models and the
reduced N-four-bar solution come from tests/test_failure_modes.py, which asserts the same
behaviour.
"""
from __future__ import annotations

import math
import re
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
import mbd2d  # noqa: E402
import test_failure_modes as fm  # noqa: E402

IMG = ROOT / "docs" / "img"
DPI = 90
COLORS = {"generalized-alpha": "C0", "dopri5": "C1", "baumgarte-rk4": "C2", "partitioned": "C3"}
TINY = 1e-17          # floor for log plots


def save(fig: plt.Figure, name: str) -> None:
    """Write a PNG with a 64-colour palette (a quarter of the size of full colour)."""
    from io import BytesIO

    from PIL import Image
    fig.tight_layout()
    buf = BytesIO()
    fig.savefig(buf, dpi=DPI, format="png", bbox_inches="tight")
    plt.close(fig)
    buf.seek(0)
    Image.open(buf).convert("RGB").quantize(colors=64).save(IMG / name, optimize=True)
    print(f"  -> docs/img/{name} ({(IMG / name).stat().st_size / 1024:.0f} KB)")


def floor(x: np.ndarray) -> np.ndarray:
    return np.maximum(np.asarray(x, dtype=float), TINY)


def envelope(t: np.ndarray, y: np.ndarray, n: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """max of y over consecutive blocks of n outputs (at each block's last time)."""
    k = (len(y) - 1) // n
    yy = np.asarray(y[1:1 + k * n], dtype=float).reshape(k, n).max(axis=1)
    return t[n:1 + k * n:n], floor(yy)


def fail_t(err: Exception) -> float:
    """The failure time the message states ('... at t = 7.53E+00 ...'); NaN if none."""
    found = re.findall(r"at t = +([-+0-9.Ee]+)", str(err))
    return float(found[0]) if found else math.nan


def fail_time(err: Exception) -> str:
    """fail_t formatted."""
    return f"{fail_t(err):.4g} s"


def head(title: str) -> None:
    print(f"\n== {title}")


# ----------------------------------------------------------------------------- 1 Baumgarte
def baumgarte_drift() -> None:
    head("Baumgarte alpha = beta = 0 against the default 10, 10 (free four-bar, h = 1e-2, 40 s)")
    m = fm.free_fourbar()
    runs = {"alpha = beta = 0": m.dynamics(40.0, 400, method="baumgarte-rk4", h=1e-2,
                                           alpha=0.0, beta=0.0),
            "alpha = beta = 10 (default)": m.dynamics(40.0, 400, method="baumgarte-rk4",
                                                      h=1e-2),
            "alpha = beta = 0, h = 5e-3": m.dynamics(40.0, 400, method="baumgarte-rk4",
                                                     h=5e-3, alpha=0.0, beta=0.0)}
    fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
    for (label, r), c, ls in zip(runs.items(), ("C3", "C0", "C3"), ("-", "-", ":")):
        ax[0].loglog(r.t[1:], floor(r.drift_position[1:]), color=c, ls=ls, label=label)
        ax[1].loglog(r.t[1:], floor(r.drift_velocity[1:]), color=c, ls=ls, label=label)
        ax[2].loglog(r.t[1:], floor(fm.energy_error(r)[1:]), color=c, ls=ls, label=label)
        i4, i40 = 40, 400
        print(f"  {label:28s} ||Phi|| at 4 s {r.drift_position[i4]:.2e}, at 40 s "
              f"{r.drift_position[i40]:.2e} (max {r.drift_position.max():.2e}); "
              f"||J qd - nu|| at 4 s {r.drift_velocity[i4]:.2e}, at 40 s "
              f"{r.drift_velocity[i40]:.2e}; |dE| at 40 s {fm.energy_error(r)[-1]:.2e} J")
        if "= 0" in label and "10" not in label:
            sp = math.log(r.drift_position[i40] / r.drift_position[i4]) / math.log(10)
            sv = math.log(r.drift_velocity[i40] / r.drift_velocity[i4]) / math.log(10)
            print(f"  {'':28s} growth exponents 4 s -> 40 s: position {sp:.2f}, velocity {sv:.2f}")
    print(f"  E(0) = {runs['alpha = beta = 0'].energy[0]:.2f} J")
    tt = np.array([2.0, 40.0])
    ax[0].loglog(tt, 1.56e-6 * (tt / 2.0) ** 2, "k--", lw=0.8, label="slope t^2")
    ax[1].loglog(tt, 2.78e-6 * (tt / 2.0), "k--", lw=0.8, label="slope t")
    for a, t in zip(ax, ("position drift ||Phi||_inf", "velocity drift ||J q_dot - nu||_inf",
                         "|E(t) - E(0)| (J)")):
        a.set_title(t, fontsize=10)
        a.set_xlabel("t (s)")
        a.set_xlim(0.1, 40)
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    ax[1].legend(fontsize=8)
    save(fig, "dyn_baumgarte_drift.png")


def baumgarte_instability() -> None:
    head("Baumgarte alpha = beta large against 1/h (free four-bar, h = 1e-3)")
    m = fm.free_fourbar()
    h = 1e-3
    scan = [1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0, 2000.0, 2500.0, 2700.0, 2800.0,
            3000.0, 5000.0, 1e4, 3e4]
    ok_x, ok_d, bad_x, bad_t = [], [], [], []
    for ab in scan:
        r, err = fm.run_or_fail(m, 2.0, 200, method="baumgarte-rk4", h=h, alpha=ab, beta=ab)
        if err is None:
            ok_x.append(h * ab)
            ok_d.append(r.drift_position.max())
            print(f"  alpha = beta = {ab:7g} (h alpha = {h * ab:6.3f}): runs 2 s, max ||Phi|| "
                  f"{r.drift_position.max():.2e}, max |dE| {fm.energy_error(r).max():.2e} J")
        else:
            bad_x.append(h * ab)
            bad_t.append(fail_t(err))
            print(f"  alpha = beta = {ab:7g} (h alpha = {h * ab:6.3f}): IntegrationError at "
                  f"{fail_time(err)}, last output t = {err.t:.3f} s")
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8))
    ax[0].loglog(ok_x, ok_d, "o-", color="C0", label="ran 2 s: max ||Phi||")
    ax[0].loglog(bad_x, [1.0] * len(bad_x), "x", color="C3", ms=9,
                 label="blew up (IntegrationError)")
    ax[0].text(1.2e-3, 1e-3, "blow-up at:\n" + "\n".join(
        f"h alpha = {x:g}: {t:.3g} s" for x, t in zip(bad_x, bad_t)), fontsize=7, va="top")
    ax[0].axvline(fm.RK4_REAL_LIMIT, color="k", ls="--", lw=1)
    ax[0].text(fm.RK4_REAL_LIMIT * 0.8, 1e-9, "RK4 limit\nh alpha = 2.785", ha="right",
               fontsize=8)
    ax[0].set_xlabel("h alpha  (alpha = beta, h = 1e-3)")
    ax[0].set_title("largest position drift over 2 s, or blow-up time", fontsize=10)
    ax[0].set_ylim(1e-12, 1e2)
    ax[0].legend(fontsize=8, loc="upper left")
    for ab, c in ((2000.0, "C0"), (2800.0, "C1"), (1e4, "C3")):
        r, err = fm.run_or_fail(m, 1.0, 1000, method="baumgarte-rk4", h=h, alpha=ab, beta=ab)
        d = r.drift_position
        ok = np.isfinite(d)
        ax[1].semilogy(r.t[ok][1:], floor(d[ok][1:]), ".-" if err else "-", color=c, ms=3,
                       label=f"alpha = beta = {ab:g}" + (f" (fails at {fail_time(err)})" if err
                                                         else ""))
        if ab == 1e4:
            print(f"  alpha = beta = 1e4, step by step: ||Phi|| = "
                  + ", ".join(f"{x:.1e}" for x in d[:8]))
        if ab == 2800.0:
            print(f"  alpha = beta = 2800: ||Phi|| at 0.05 s {d[50]:.1e}, 0.1 s {d[100]:.1e}, "
                  f"last finite {d[ok][-1]:.1e} at {r.t[ok][-1]:.3f} s")
    ax[1].set_xlabel("t (s)")
    ax[1].set_title("position drift ||Phi||_inf, h = 1e-3", fontsize=10)
    ax[1].set_xscale("log")
    ax[1].set_xlim(1e-3, 1.0)
    ax[1].legend(fontsize=8)
    for a in ax:
        a.grid(alpha=0.3)
    save(fig, "dyn_baumgarte_instability.png")


# ----------------------------------------------------------------------------- 2 stiff spring
def stiff_spring() -> None:
    head("Stiff spring: cart-pendulum, omega = sqrt(k / 1.25)")
    ks = [1e2, 1e3, 1e4, 1e5, 1e6, 1e7]
    t_end = 1.0
    loose = {"rtol": 1e-3, "atol": 1e-6}
    series = {"dopri5 (rtol 1e-6)": ("dopri5", {}), "dopri5 (rtol 1e-3)": ("dopri5", loose),
              "partitioned (rtol 1e-6)": ("partitioned", {}),
              "generalized-alpha (rtol 1e-6)": ("generalized-alpha", {}),
              "generalized-alpha (rtol 1e-4, atol 1e-6)": ("generalized-alpha",
                                                           {"rtol": 1e-4, "atol": 1e-6}),
              "generalized-alpha, h = 1e-2": ("generalized-alpha", {"h": 1e-2})}
    steps = {s: [] for s in series}
    for k in ks:
        m = fm.cart_pendulum(k)
        om = fm.stiff_omega(k)
        for label, (meth, kw) in series.items():
            r = m.dynamics(t_end, 100, method=meth, **kw)
            steps[label].append(r.stats["steps"])
            if k in (1e3, 1e7):
                print(f"  k = {k:5.0e} (omega {om:7.1f}) {label:30s} steps {r.stats['steps']:5d}, "
                      f"rejected {r.stats['rejected_steps']:4d}, h_max {r.stats['h_max']:.2e} "
                      f"(h_max omega {r.stats['h_max'] * om:5.2f}), max |dE| "
                      f"{fm.energy_error(r).max():.1e} J")
    fig, ax = plt.subplots(1, 2, figsize=(12.5, 3.8), gridspec_kw={"width_ratios": [1, 1.1]})
    for (label, n), mk in zip(steps.items(), "osv^<D"):
        ax[0].loglog(ks, n, marker=mk, label=label)
    om = np.array([fm.stiff_omega(k) for k in ks])
    ax[0].loglog(ks, t_end * om / fm.DP5_RADIUS, "k--", lw=1,
                 label=f"t omega / {fm.DP5_RADIUS:g} (DP5 stability)")
    ax[0].set_xlabel("spring stiffness k (N/m)")
    ax[0].set_title("steps for 1 s", fontsize=10)
    ax[0].legend(fontsize=7)

    k = 1e7
    m = fm.cart_pendulum(k)
    om = fm.stiff_omega(k)
    print(f"  k = 1e7: omega = {om:.1f} rad/s; RK4 limit h = {fm.RK4_IMAG_LIMIT / om:.3e} s")
    runs = [("generalized-alpha, h = 1e-2 (h omega = 28)", "generalized-alpha", {"h": 1e-2}, "C0"),
            ("baumgarte-rk4, h = 5e-4 (h omega = 1.4)", "baumgarte-rk4", {"h": 5e-4}, "C2"),
            ("baumgarte-rk4, h = 1e-3 (h omega = 2.83)", "baumgarte-rk4", {"h": 1e-3}, "C9"),
            ("baumgarte-rk4, h = 1.05e-3 (h omega = 2.97)", "baumgarte-rk4", {"h": 1.05e-3},
             "C1"),
            ("baumgarte-rk4, h = 2e-3 (h omega = 5.7)", "baumgarte-rk4", {"h": 2e-3}, "C3"),
            ("partitioned, rtol 1e-3", "partitioned", loose, "C4"),
            ("dopri5, rtol 1e-3", "dopri5", loose, "C5")]
    for label, meth, kw, c in runs:
        r, err = fm.run_or_fail(m, 2.0, 200, method=meth, **kw)
        ee = fm.energy_error(r)
        fin = np.isfinite(ee)
        ax[1].semilogy(r.t[fin], floor(ee[fin]), color=c,
                       label=label + (f": fails at {fail_time(err)}" if err else ""))
        xm = np.abs(r.body("cart").x[fin]).max()
        if err is not None:
            print(f"    {err}")
        print(f"  {label:44s} {'IntegrationError at ' + fail_time(err) if err else 'runs 2 s':26s} "
              f"max |dE| {ee[fin].max():.2e} J, max |x_cart| {xm:.1e} m, steps "
              f"{r.stats['steps']}")
    for rtol in (1e-3, 1e-4, 1e-5):
        for meth in ("partitioned", "dopri5"):
            r = m.dynamics(1.0, 100, method=meth, rtol=rtol, atol=1e-6)
            print(f"  1 s, {meth:12s} rtol {rtol:g}, atol 1e-6: max |dE| "
                  f"{fm.energy_error(r).max():.2e} J, max |x_cart| "
                  f"{np.abs(r.body('cart').x).max():.1e} m, steps {r.stats['steps']}")
    r = m.dynamics(10.0, 1000, method="generalized-alpha", h=1e-2)
    print(f"  generalized-alpha h = 1e-2 over 10 s: max |dE| {fm.energy_error(r).max():.2e} J "
          f"(E(0) - V_min = {r.energy[0] - r.potential.min():.2f} J), max |x_cart| "
          f"{np.abs(r.body('cart').x).max():.1e} m")
    ax[1].set_xlabel("t (s)")
    ax[1].set_title("k = 1e7: |E(t) - E(0)| (J)", fontsize=10)
    ax[1].set_ylim(1e-10, 1e6)
    ax[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    for a in ax:
        a.grid(alpha=0.3)
    save(fig, "dyn_stiff_spring.png")


# ----------------------------------------------------------------------------- 3 rho_inf = 1
def rho_inf() -> None:
    head("generalized-alpha rho_inf = 1 against 0.8 (free four-bar, fixed h)")
    m = fm.free_fourbar()
    fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
    for h, ls in ((1e-3, "-"), (1e-2, ":")):
        for rho, c in ((0.8, "C0"), (1.0, "C3")):
            r, err = fm.run_or_fail(m, 10.0, 1000, method="generalized-alpha", h=h, rho_inf=rho)
            acc = np.abs(r.qdd).max(axis=1)
            lab = f"rho_inf = {rho:g}, h = {h:g}" + (f" (fails {fail_time(err)})" if err else "")
            ax[0].semilogy(r.t, acc, color=c, ls=ls, label=lab)
            ax[1].semilogy(r.t, floor(r.drift_velocity), color=c, ls=ls, label=lab)
            ax[2].semilogy(r.t, floor(fm.energy_error(r)), color=c, ls=ls, label=lab)
            end = float(r.t[-1])
            print(f"  {lab:42s} max |q_ddot| 0-2 s {fm.window(r, r.qdd, 0, 2):.3g}, last s "
                  f"{fm.window(r, r.qdd, end - 1, end):.3g}; max |lambda| (of the state) "
                  f"0-2 s {fm.window(r, r.lam, 0, 2):.3g}, last s "
                  f"{fm.window(r, r.lam, end - 1, end):.3g}; max ||J qd - nu|| 0-2 s "
                  f"{fm.window(r, r.drift_velocity, 0, 2):.2e}, last s "
                  f"{fm.window(r, r.drift_velocity, end - 1, end):.2e}; |dE| end "
                  f"{fm.energy_error(r)[-1]:.2e} J; max ||Phi|| {r.drift_position.max():.1e}")
            if err is not None and h == 1e-2:
                i = np.searchsorted(r.t, 7.0)
                col = int(np.argmax(np.abs(r.qdd[-1])))
                print(f"    sawtooth at 7.00 .. 7.05 s, q_ddot of '{r.coordinate_names[col]}': "
                      + ", ".join(f"{x:.0f}" for x in r.qdd[i:i + 6, col]))
    p = mbd2d.load(ROOT / "examples" / "pendulum_spring.toml")
    c = fm.cart_pendulum(1e7)
    for label, mod, t_end in (("pendulum_spring.toml", p, 20.0), ("cart-pendulum k = 1e7", c,
                                                                   10.0)):
        for h in (1e-2, 1e-3):
            r, err = fm.run_or_fail(mod, t_end, int(t_end * 100), method="generalized-alpha",
                                    h=h, rho_inf=1.0)
            print(f"  {label:24s} rho_inf = 1, h = {h:g}: "
                  + (f"Newton fails at {fail_time(err)} (last output {err.t:.4g} s)" if err
                     else f"runs {t_end:g} s, max |dE| {fm.energy_error(r).max():.2e}"))
    for h in (1e-2, 3e-3, 1e-3):
        r, err = fm.run_or_fail(m, 10.0, 1000, method="generalized-alpha", h=h, rho_inf=0.95)
        print(f"  free four-bar rho_inf = 0.95, h = {h:g}: "
              + (f"fails at {fail_time(err)}" if err else "runs 10 s")
              + f", max |q_ddot| {np.abs(r.qdd).max():.3g}, max ||J qd - nu|| "
              f"{r.drift_velocity.max():.2e}, max |dE| {fm.energy_error(r).max():.2e} J")
    for a, t in zip(ax, ("max |q_ddot| of the scheme", "velocity drift ||J q_dot - nu||_inf",
                         "|E(t) - E(0)| (J)")):
        a.set_title(t, fontsize=10)
        a.set_xlabel("t (s)")
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=7)
    save(fig, "dyn_rho_inf.png")


# ----------------------------------------------------------------------------- 4 N-four-bar
def nfourbar() -> None:
    head("Free N-four-bar through the flat position (3.5 s, four passages)")
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8))
    for n in (1, 2):
        for meth in fm.PASSAGE_METHODS:
            t0 = time.perf_counter()
            o = fm.nfourbar_passage(n, meth)
            dt = time.perf_counter() - t0
            st = o["res"].stats
            e = fm.energy_error(o["res"])
            print(f"  N = {n} {meth:18s} largest |dE| at t = {o['res'].t[e.argmax()]:.2f} s")
            print(f"  N = {n} {meth:18s} {'error' if o['error'] else 'ok':5s} max deviation "
                  f"{o['max_deviation']:.1e} rad, max |th_k - th_0| {o['max_branch']:.1e}, "
                  f"max |dE| {o['energy_error']:.1e} J (E0 {o['res'].energy[0]:.2f}), "
                  f"steps {st['steps']}, rejected {st['rejected_steps']}, {dt:.2f} s")
            if n == 2:
                ax[0].semilogy(o["res"].t, floor(o["deviation"]), color=COLORS[meth],
                               label=meth + ("" if meth != "baumgarte-rk4" else ", h = 1e-3"))
    for n in (1, 2, 5):
        for ab in (0.0, 10.0):
            o = fm.nfourbar_passage(n, "baumgarte-rk4", {"h": 1e-2, "alpha": ab, "beta": ab})
            t, br = o["res"].t, o["branch"]
            lab = f"N = {n}, alpha = beta = {ab:g}" + (f" (blows up {o['t_reached']:.3g} s)"
                                                       if o["error"] else "")
            print(f"  baumgarte-rk4 h = 1e-2 {lab:40s} max |th_k - th_0| "
                  f"{o['max_branch']:.1e}, max deviation {o['max_deviation']:.1e}")
            if n in (2, 5):
                fin = np.isfinite(br)
                ax[1].semilogy(t[fin], floor(br[fin]), color="C3" if ab == 0 else "C2",
                               ls="-" if n == 5 else ":", label=lab)
            if n == 5 and ab == 0.0:
                spread = [br[(t > a + 0.05) & (t < b - 0.05)].max() for a, b in
                          zip(fm.PASSAGE_TIMES, fm.PASSAGE_TIMES[1:] + (o["t_reached"] + .05,))]
                print("    spread after passages 1, 2, 3, 4: "
                      + ", ".join(f"{x:.1e}" for x in spread))
    for a in ax:
        for tp in fm.PASSAGE_TIMES:
            a.axvline(tp, color="k", lw=0.6, ls=":")
        a.set_xlabel("t (s)")
        a.grid(alpha=0.3)
    ax[0].set_title("N = 2: max |th_k - th_reduced| (rad)", fontsize=10)
    ax[1].set_title("baumgarte-rk4 h = 1e-2: spread max |th_k - th_0|", fontsize=10)
    ax[0].legend(fontsize=7, loc="lower right")
    ax[1].legend(fontsize=7, loc="upper left")
    ax[1].set_ylim(1e-17, 1e2)
    save(fig, "dyn_nfourbar.png")


# ----------------------------------------------------------------------------- 5 per method
def per_method() -> None:
    head("Energy and drift per method (free four-bar, 10 s, outputs every 0.01 s)")
    m = fm.free_fourbar()
    cases = [("generalized-alpha", {}), ("generalized-alpha", {"h": 1e-2}),
             ("generalized-alpha", {"h": 1e-3}), ("dopri5", {}), ("partitioned", {}),
             ("baumgarte-rk4", {"h": 1e-2}), ("baumgarte-rk4", {"h": 1e-3})]
    fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
    print(f"  {'method':34s} {'max|dE| J':>10s} {'max Phi':>9s} {'Phi end':>9s} "
          f"{'max Jqd-nu':>10s} {'Jqd-nu end':>10s} {'steps':>6s} {'rej':>5s} {'f/Newton':>8s} "
          f"{'time s':>6s}")
    for meth, kw in cases:
        t0 = time.perf_counter()
        r = m.dynamics(10.0, 1000, method=meth, **kw)
        dt = time.perf_counter() - t0
        st = r.stats
        work = st["rhs_evaluations"] if meth != "generalized-alpha" else st["newton_iterations"]
        label = meth + (f", h = {kw['h']:g}" if "h" in kw else "")
        print(f"  {label:34s} {fm.energy_error(r).max():10.2e} {r.drift_position.max():9.1e} "
              f"{r.drift_position[-1]:9.1e} {r.drift_velocity.max():10.1e} "
              f"{r.drift_velocity[-1]:10.1e} {st['steps']:6d} {st['rejected_steps']:5d} "
              f"{work:8d} {dt:6.2f}")
        if kw.get("h") == 1e-3:
            continue
        c = COLORS[meth]
        ls = ":" if kw.get("h") == 1e-2 else "-"
        for a, y in zip(ax, (fm.energy_error(r), r.drift_position, r.drift_velocity)):
            a.semilogy(*envelope(r.t, y), color=c, ls=ls, label=label)
    print(f"  E(0) = {m.dynamics(1.0, 1).energy[0]:.3f} J")
    for meth, kws in (("generalized-alpha", ({"h": 1e-2}, {"h": 2e-3})),
                      ("baumgarte-rk4", ({"h": 1e-2}, {"h": 2e-3})),
                      ("dopri5", ({}, {"rtol": 1e-9, "atol": 1e-11})),
                      ("partitioned", ({}, {"rtol": 1e-9, "atol": 1e-11}))):
        e = [fm.energy_error(m.dynamics(5.0, 500, method=meth, **kw)).max() for kw in kws]
        extra = (f", observed order {fm.observed_order(e[0], e[1], 5.0):.2f}"
                 if "h" in kws[0] else f", ratio {e[0] / e[1]:.0f}")
        print(f"  5 s: {meth:18s} {kws[0]} -> {kws[1]}: max |dE| {e[0]:.2e} -> {e[1]:.2e}{extra}")
    p = mbd2d.load(ROOT / "examples" / "pendulum_spring.toml")
    for meth, kw in (("generalized-alpha", {}), ("dopri5", {}), ("partitioned", {}),
                     ("baumgarte-rk4", {"h": 1e-3})):
        r = p.dynamics(10.0, 1000, method=meth, **kw)
        print(f"  pendulum_spring.toml {meth:18s} max |dE| {fm.energy_error(r).max():.2e} J, "
              f"max Phi {r.drift_position.max():.1e}, max |J qd - nu| "
              f"{r.drift_velocity.max():.1e}, steps {r.stats['steps']}")
    for a, t in zip(ax, ("|E(t) - E(0)| (J), max per 0.1 s", "||Phi||_inf, max per 0.1 s",
                         "||J q_dot - nu||_inf, max per 0.1 s")):
        a.set_title(t, fontsize=10)
        a.set_xlabel("t (s)")
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=7, loc="lower right")
    save(fig, "dyn_energy_drift.png")


def fixed_step_count() -> None:
    head("Fixed-step bookkeeping (engine bug: a sliver step at the end)")
    m = fm.free_fourbar()
    for meth in ("generalized-alpha", "baumgarte-rk4"):
        for t_end in (1.0, 3.0, 5.0, 10.0):
            st = m.dynamics(t_end, 10, method=meth, h=1e-3).stats
            print(f"  {meth:18s} t_end {t_end:4g}, h 1e-3: steps {st['steps']} (expected "
                  f"{round(t_end / 1e-3)}), h_min {st['h_min']:.3e}")


def main() -> None:
    IMG.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    for part in (baumgarte_drift, baumgarte_instability, stiff_spring, rho_inf, nfourbar,
                 per_method, fixed_step_count):
        t1 = time.perf_counter()
        part()
        print(f"  ({time.perf_counter() - t1:.1f} s)")
    print(f"\ntotal {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
