"""The vibration modes of a half car (examples/half_car.toml): bounce, pitch, two wheel hops.

model.modes() linearizes the equations of motion about the static equilibrium and gives the
natural frequencies, the mass-normalized shapes and the damped eigenvalues. Two checks that
do not use the modes' own numbers: released from the equilibrium displaced along an undamped
mode, the forward dynamics of the nonlinear model moves as a cos(omega t) phi, its departure
from that falling with the amplitude as the linearization's error must (halved with the
amplitude: second order); and the damping chart's undamped end (c = 0) has zero damping
ratios. Then the car driven by the road: model.frequency_response() gives the body's bounce
and pitch per unit rise of the road under the front wheel (the front tyre's ground point
moved: a base motion) from 0.1 to 30 Hz, and the nonlinear forward dynamics driven by a
1 mm sinusoidal road (the tyre's actuator force k_t u(t), the same load) settles on the same
amplitude and phase at three frequencies; the car as a state-space system with the road as
its input (model.linearize) has the modes' damped eigenvalues as its poles and the road
response as its transfer function. Last, the designer's question: how the road
response changes with the suspension damping (one mbd2d.sweep of the frequency response over
40 dampings: every variant's Bode curves and its peak bounce).

Usage::

    python examples/vibration_modes.py [--out DIR]

Writes vibration_modes_shapes.png (the four modes, each drawn at both extremes),
vibration_modes_damping.png (each mode's damping ratio and damped frequency against the
suspension damping, one mbd2d.sweep of the modes: the designer's chart) and
vibration_modes.gif (the pitch mode), vibration_modes_road.gif (the car's steady motion on
the road at the body's bounce peak: the operating deflection shape), vibration_modes_road.png
(the Bode plot of the road
response, with the dynamics' steady amplitudes marked) and vibration_modes_road_damping.png
(the road response's family over the suspension damping) to DIR (default examples/output/).
Exit code 0 when the released modes depart from their linear motion by less than 2e-3 of a
1 mm amplitude, and by half as much at half the amplitude, and the driven dynamics settles
within 1e-2 of the frequency response.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import mbd2d

HERE = Path(__file__).resolve().parent
MODEL = HERE / "half_car.toml"
#: the released mode's largest departure from a cos(omega t) phi, relative to a
RELEASE_TOL = 2e-3
#: the amplitude of the release: the largest point moves this far [m]
AMPLITUDE = 1e-3
DAMPING = ("force.front_suspension.damping", "force.rear_suspension.damping")
#: the road under the front wheel: the front tyre's ground point's height
ROAD = "force.front_tyre.points.0.1"
#: the driven dynamics' steady response within this fraction of the frequency response's
ROAD_TOL = 1e-2
#: the frequencies at which the driven dynamics checks the response [Hz]
ROAD_CHECKS = (1.0, 1.5, 8.0)


def released(model: mbd2d.Model, res: mbd2d.ModesResult, k: int,
             amplitude: float = AMPLITUDE) -> float:
    """Release the undamped model from q* + a phi_k at rest; the largest |q(t) - q* - a
    cos(omega t) phi_k| over two periods, relative to a |phi_k|_inf."""
    undamped = model.with_params({name: 0.0 for name in DAMPING})
    phi = res.shape(k)
    a = amplitude / np.abs(phi[:9]).max()
    start = res.q + a * phi
    for i, body in enumerate(undamped.bodies):
        body.q0 = [float(v) for v in start[3 * i:3 * i + 3]]
    period = 1.0 / res.frequency[k]
    run = undamped.dynamics(2 * period, 200, rtol=1e-10, atol=1e-12)
    want = res.q[None, :] + a * np.cos(2 * np.pi * run.t / period)[:, None] * phi[None, :]
    return float(np.abs(run.q - want).max() / (a * np.abs(phi).max()))


def damping_chart(model: mbd2d.Model, path: Path) -> float:
    """Damping ratio and damped frequency of each mode against the suspension damping (both
    struts); returns the largest damping ratio at c = 0."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cs = np.linspace(0.0, 3500.0, 36)            # (past about 3800 N s/m pitch is overdamped)
    ds = mbd2d.sweep(model, {name: cs for name in DAMPING}, "modes", progress=False)
    zeta, fd = np.full((cs.size, 4), np.nan), np.full((cs.size, 4), np.nan)
    for i in range(cs.size):
        up = ds.s_imag.values[i] > 0                 # one of each underdamped pair
        n = min(4, int(up.sum()))
        zeta[i, :n] = ds.damping_ratio.values[i][up][:n]
        fd[i, :n] = ds.damped_frequency.values[i][up][:n]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    names = ["1st (bounce)", "2nd (pitch)", "3rd (a wheel hop)", "4th (a wheel hop)"]
    for j in range(zeta.shape[1]):
        a1.plot(cs, zeta[:, j], lw=1.8, label=names[j] if j < len(names) else f"mode {j}")
        a2.plot(cs, fd[:, j], lw=1.8)
    a1.axvline(1500.0, color="0.5", lw=0.8, ls=":", label="this design (1500 N s/m)")
    a1.set_ylabel("damping ratio zeta")
    a1.legend(loc="upper left", fontsize=8)
    a2.set_yscale("log")
    a2.set_ylabel("damped frequency [Hz]")
    a2.set_xlabel("suspension damping c (both struts) [N s/m]")
    a1.set_title("half car: modes against the suspension damping (a modes sweep)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return float(np.nanmax(np.abs(zeta[0])))


def driven(f_hz: float, amplitude: float = AMPLITUDE) -> np.ndarray:
    """The nonlinear car on a road u = a sin(2 pi f t) under the front wheel (the tyre's
    actuator force k_t u: its tension k_t (L - L0 - u)), run until the start has died out;
    the complex amplitudes (Y with y = Re(Y e^(i w t))) of the body's y and theta over the
    last two periods, per unit of the road's complex amplitude -i a."""
    text = MODEL.read_text()
    tyre = text.index('name = "front_tyre"')
    at = text.index("length0 = 0.32", tyre) + len("length0 = 0.32")
    k_t = 200000.0
    w = 2 * np.pi * f_hz
    text = (text[:at] + f"\nf = {{ harmonic = [{{ amplitude = {k_t * amplitude!r}, "
            f"omega = {w!r}, phase = 0.0 }}] }}" + text[at:])
    model = mbd2d.loads(text)
    rest = model.statics()
    for i, body in enumerate(model.bodies):
        body.q0 = [float(v) for v in rest.q[3 * i:3 * i + 3]]
    period = 1.0 / f_hz
    t_end = 8.0 + 2 * period                      # (the slowest start decays as e^(-2 t))
    run = model.dynamics(t_end, int(t_end * f_hz * 40), rtol=1e-10, atol=1e-12)
    last = run.t >= t_end - 2 * period
    basis = np.column_stack([np.cos(w * run.t[last]), np.sin(w * run.t[last])])
    out = []
    for j in (1, 2):                              # the body's y and theta
        (a, b), *_ = np.linalg.lstsq(basis, run.q[last, j] - rest.q[j], rcond=None)
        out.append(complex(a, -b) / (-1j * amplitude))
    return np.array(out)


def road_figure(frf: mbd2d.FrequencyResponseResult, checks: dict, path: Path) -> None:
    """The Bode plot of the body's bounce and pitch per unit road rise, with the driven
    dynamics' steady responses marked."""
    fig = frf.plot("body", ["y", "theta"])
    mag_ax, ph_ax = fig.axes[:2]
    for f, h in checks.items():
        mag_ax.plot([f, f], np.abs(h), "ko", ms=4)
        ph_ax.plot([f, f], np.degrees(np.angle(h)), "ko", ms=4)
    mag_ax.plot([], [], "ko", ms=4, label="nonlinear dynamics, settled")
    mag_ax.legend(fontsize=8)
    mag_ax.set_title("half car: body per unit road rise under the front wheel "
                     "(m/m and rad/m)")
    mbd2d.plots.save_figure(fig, path)


def road_damping(model: mbd2d.Model, frf: mbd2d.FrequencyResponseResult,
                 path: Path) -> list[str]:
    """The road response over 40 suspension dampings (both struts; one frequency response
    sweep) drawn as a Bode family with each variant's peak; the variant at this design's
    damping must be the response computed alone (bit for bit)."""
    cs = np.linspace(300.0, 4200.0, 40)
    cs[np.argmin(np.abs(cs - 1500.0))] = 1500.0                  # this design among them
    ds = mbd2d.sweep(model, {name: cs for name in DAMPING}, "frf", inputs=[ROAD],
                     frequencies=frf.frequencies, progress=False)
    design = int(np.flatnonzero(cs == 1500.0)[0])
    y = np.abs(ds.response.sel(coordinate="body.y").values[:, :, 0])
    bounce = y.max(axis=1)
    k10 = int(np.argmin(np.abs(frf.frequencies - 10.0)))        # harshness: near 10 Hz
    print(f"road response over {cs.size} suspension dampings (one sweep): the peak bounce "
          f"per unit road rise falls from {bounce[0]:.3g} at {cs[0]:g} N s/m to "
          f"{bounce[-1]:.3g} at {cs[-1]:g} while the bounce at "
          f"{frf.frequencies[k10]:.3g} Hz rises from {y[0, k10]:.3g} to {y[-1, k10]:.3g} "
          f"(this design, {cs[design]:g} N s/m: {bounce[design]:.3g} and {y[design, k10]:.3g})")
    fig = mbd2d.plots.plot_sweep(ds, coordinates=["body.y", "body.theta"],
                                 parameter=DAMPING[0])
    mbd2d.plots.save_figure(fig, path)
    if not np.array_equal(ds.response.values[design], frf.response):
        return ["the damping sweep's design variant is not the response computed alone"]
    return []


def shapes_figure(res: mbd2d.ModesResult, path: Path) -> None:
    """The four modes, each at both extremes around the equilibrium."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for k, ax in enumerate(axes.flat[:res.omega2.size]):
        res.plot(k, ax=ax)
        ax.set_title(f"mode {k}: {res.frequency[k]:.3f} Hz, zeta = "
                     f"{res.damping_ratio[2 * k]:.3f} (damped)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def state_space(model: mbd2d.Model, res: mbd2d.ModesResult,
                frf: mbd2d.FrequencyResponseResult) -> list[str]:
    """The car as a state-space system with the road as its input (model.linearize: the
    matrices a controller is designed on): its poles are the damped eigenvalues of the
    modes, its transfer function C (i w I - A)^-1 B + D the road response; the problems."""
    lin = model.linearize(ROAD)
    poles, eig = np.linalg.eigvals(lin.a), np.asarray(res.eigenvalues)
    gap = max(float(np.abs(eig - s).min()) for s in poles) / float(np.abs(eig).max())
    i = len(frf.frequencies) // 2
    w = 2 * np.pi * frf.frequencies[i]
    tf = lin.c @ np.linalg.solve(1j * w * np.eye(lin.a.shape[0]) - lin.a, lin.b) + lin.d
    dev = float(np.abs(tf[:, 0] - frf.response[i, :, 0]).max()
                / np.abs(frf.response[i, :, 0]).max())
    print(f"state space (model.linearize, road input): {lin.a.shape[0]} states; its poles are "
          f"the damped eigenvalues to {gap:.1e}, its transfer function at "
          f"{frf.frequencies[i]:.3g} Hz the road response to {dev:.1e}")
    return [] if gap < 1e-9 and dev < 1e-9 else [f"the state-space system departs {gap:.1e} "
                                                 f"and {dev:.1e} from the modes and the response"]


def run(out: Path) -> tuple[str, list[str]]:
    """Modes, the release checks, the pictures; (problem or "", the files written)."""
    model = mbd2d.load(MODEL)
    res = model.modes()
    print(res.summary())
    problems = []
    for k in range(2):
        dev, half = released(model, res, k), released(model, res, k, AMPLITUDE / 2)
        print(f"mode {k} released ({AMPLITUDE * 1e3:g} mm) in the nonlinear dynamics: largest "
              f"departure from a cos(omega t) phi over two periods {dev:.1e} of the amplitude "
              f"({half:.1e} at half the amplitude: ratio {dev / half:.2f}, second order)")
        if not (dev < RELEASE_TOL and 1.8 < dev / half < 2.2):
            problems.append(f"mode {k} released departs {dev:.1e} from its shape")
    out.mkdir(parents=True, exist_ok=True)
    files = [str(out / "vibration_modes_shapes.png"), str(out / "vibration_modes_damping.png")]
    shapes_figure(res, Path(files[0]))
    zeta0 = damping_chart(model, Path(files[1]))
    print(f"without suspension damping the largest damping ratio is {zeta0:.1e}")
    if not zeta0 < 1e-9:
        problems.append(f"the undamped car has a damping ratio {zeta0:.1e}")
    files.append(str(res.animate(1, out / "vibration_modes.gif", max_frames=40)))
    frf = model.frequency_response(ROAD, np.geomspace(0.1, 30.0, 400))
    checks = {}
    for f in ROAD_CHECKS:
        h = model.frequency_response(ROAD, [f]).response[0, [1, 2], 0]
        checks[f] = driven(f)
        err = float(np.abs(checks[f] - h).max() / np.abs(h).max())
        print(f"road at {f:g} Hz: bounce {abs(h[0]):.4g} m/m at {np.degrees(np.angle(h[0])):.1f}"
              f" deg, pitch {abs(h[1]):.4g} rad/m; the driven dynamics settles within "
              f"{err:.1e} of it")
        if not err < ROAD_TOL:
            problems.append(f"the driven dynamics at {f:g} Hz departs {err:.1e}")
    peak_f, peak = frf.peak("body", "y")
    print(f"largest bounce per unit road rise {peak:.3g} at {peak_f:.3g} Hz")
    files.append(str(frf.animate(peak_f, out / "vibration_modes_road.gif", max_frames=40)))
    problems += state_space(model, res, frf)
    files.append(str(out / "vibration_modes_road.png"))
    road_figure(frf, checks, Path(files[-1]))
    files.append(str(out / "vibration_modes_road_damping.png"))
    problems += road_damping(model, frf, Path(files[-1]))
    return "; ".join(problems), files


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE / "output")
    args = ap.parse_args(argv)
    problem, files = run(args.out)
    print("wrote " + ", ".join(Path(f).name for f in files) + f" in {args.out}")
    if problem:
        print(f"unexpected: {problem}")
    return 1 if problem else 0


if __name__ == "__main__":
    sys.exit(main())
