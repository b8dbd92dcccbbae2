"""Steps (motion laws) in functions of time: dwell, rise by h between t0 and t1, dwell.

References computed here without mbd2d: the laws' closed forms (Norton, Cam Design and
Manufacturing Handbook, ch. 3) through the slider-crank's closed-form kinematics, a block
pushed by a stepped force integrated by hand, and central differences of those closed forms
for the design sensitivities.
"""
from __future__ import annotations

import math
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.description import toml_io
from test_derivatives import step_closed_form
from test_standalone import find_solver, solve_file

R, L, E = 0.5, 2.0, 0.3        # crank, rod, offset of the slider's line
LAWS = ["cubic", "quintic", "cycloidal", "harmonic", "modified-sine", "modified-trapezoid"]


def law_step(step: dict) -> str:
    """A step as a TOML inline table."""
    return (f"{{ t0 = {step['t0']}, t1 = {step['t1']}, h = {step['h']}, "
            f"law = \"{step['law']}\" }}")


def slider_crank(step: dict) -> mbd2d.Model:
    """Crank angle theta(t) = 0.2 + a step (the law's rise)."""
    return mbd2d.loads(f"""
[model]
name = "stepped-slider-crank"
[[body]]
name = "crank"
q0 = [0.25, 0.05, 0.2]
[[body]]
name = "rod"
q0 = [1.4, 0.2, -0.1]
[[body]]
name = "slider"
q0 = [2.4, 0.3, 0.0]
[[joint]]
type = "revolute"
name = "O"
bodies = ["ground", "crank"]
points = [[0, 0], [-{R / 2}, 0]]
[[joint]]
type = "revolute"
name = "A"
bodies = ["crank", "rod"]
points = [[{R / 2}, 0], [-{L / 2}, 0]]
[[joint]]
type = "revolute"
name = "B"
bodies = ["rod", "slider"]
points = [[{L / 2}, 0], [0, 0]]
[[joint]]
type = "translational"
name = "guide"
bodies = ["ground", "slider"]
points = [[0, {E}], [0, 0]]
axes = [[1, 0], [1, 0]]
[[driver]]
type = "absolute"
name = "motor"
body = "crank"
coordinate = "theta"
f = {{ poly = [0.2], step = [{law_step(step)}] }}
""")


def slider_chain(th: np.ndarray, th1: np.ndarray, th2: np.ndarray, r: float = R,
                 rod: float = L, e: float = E) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An offset slider-crank's slider x, x_dot, x_ddot from the crank angle and its two
    time derivatives: x = r cos th + sqrt(rod^2 - (r sin th - e)^2) and the chain rule."""
    s = r * np.sin(th) - e
    w = np.sqrt(rod**2 - s**2)
    ds = r * np.cos(th)
    x_th = -r * np.sin(th) - s * ds / w
    # d/dth of -s ds / w: -(ds^2 + s (-r sin th)) / w - s^2 ds^2 / w^3
    x_thth = -r * np.cos(th) - (ds**2 - s * r * np.sin(th)) / w - (s * ds)**2 / w**3
    return r * np.cos(th) + w, x_th * th1, x_thth * th1**2 + x_th * th2


def slider_exact(step: dict, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The slider through th(t) = 0.2 + the step's closed form."""
    th, th1, th2 = (np.array(v) for v in zip(*[step_closed_form(step, float(tk)) for tk in t]))
    return slider_chain(th + 0.2, th1, th2)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("t0, t1", [(0.25, 1.05), (0.253, 1.0471)])
def test_slider_crank_follows_each_law(law: str, t0: float, t1: float) -> None:
    """Positions, velocities and accelerations against the closed form through the rise,
    the dwell before it and the dwell after it, at three Newton tolerances, with the rise's
    ends on output times and between them; positions alone likewise."""
    step = {"t0": t0, "t1": t1, "h": 1.3, "law": law}
    m = slider_crank(step)
    for tol, bound in ((1e-8, 1e-7), (None, 1e-9), (1e-12, 1e-11)):
        res = m.kinematics(1.5, 150, tol=tol)
        x, v, a = slider_exact(step, res.t)
        sl = res.body("slider")
        scale = 1.0 + np.abs(a).max()
        assert np.abs(sl.x - x).max() < bound
        assert np.abs(sl.x_dot - v).max() < bound * scale
        # (the cubic and harmonic laws jump in acceleration at t0 and t1: the functions are
        # right-continuous, the rows there have the value after the instant, as the closed
        # form here)
        assert np.abs(sl.x_ddot - a).max() < bound * scale
        pos = m.kinematics(1.5, 150, tol=tol, positions_only=True)
        assert np.abs(pos.q[:, 6] - x).max() < bound


@pytest.mark.parametrize("law", LAWS)
def test_sensitivities_to_the_step_against_the_closed_form(law: str) -> None:
    """d(x, x_dot, x_ddot of the slider)/d(t0, t1, h) against central differences of the
    closed form, 1e-8 relative."""
    step = {"t0": 0.25, "t1": 1.05, "h": 1.3, "law": law}
    names = [f"driver.motor.f.step.0.{k}" for k in ("t0", "t1", "h")]
    res = slider_crank(step).kinematics(1.5, 150, tol=1e-13, sensitivities=names)
    inside = (res.t > 0.25 + 1e-3) & (res.t < 1.05 - 1e-3)   # away from the kinks
    if law.startswith("modified"):     # and from the jerk's jumps inside (the eighths)
        for e in (1, 3, 5, 7):
            inside &= np.abs(res.t - (0.25 + 0.8 * e / 8)) > 1e-3
    k = 3 * 2                                                  # the slider's x
    for j, key in enumerate(("t0", "t1", "h")):
        d = 1e-6
        hi, lo = dict(step), dict(step)
        hi[key] += d
        lo[key] -= d
        ref = [(a - b) / (2 * d) for a, b in zip(slider_exact(hi, res.t), slider_exact(lo, res.t))]
        for got, want in zip((res.dq_dp, res.dqd_dp, res.dqdd_dp), ref):
            scale = np.abs(want).max()
            assert scale > 0.1
            err = np.abs(got[inside, k, j] - want[inside]).max() / scale
            assert err < 1e-8, (law, key, err)
        # before the rise nothing depends on the step; after it only h moves the slider
        before = res.t < 0.25
        assert np.all(res.dq_dp[before, k, j] == 0.0)
        after = res.t > 1.05
        if key != "h":
            assert np.all(res.dq_dp[after, k, j] == 0.0)


def block(law: str = "cubic") -> mbd2d.Model:
    """A 2 kg block on a horizontal guide pushed by fx = 3 N x the step's law (0.2 .. 0.9 s)."""
    return mbd2d.loads(f"""
[model]
name = "pushed-block"
gravity = [0.0, -9.81]
[[body]]
name = "block"
q0 = [0.0, 0.0, 0.0]
mass = 2.0
inertia = 0.1
[[joint]]
type = "translational"
name = "guide"
bodies = ["ground", "block"]
points = [[0, 0], [0, 0]]
axes = [[1, 0], [1, 0]]
[[force]]
type = "point"
name = "push"
body = "block"
point = [0.0, 0.0]
fx = {{ poly = [0.0], step = {{ t0 = 0.2, t1 = 0.9, h = 3.0, law = "{law}" }} }}
fy = 0.0
""")


def block_exact(t: np.ndarray, t0: float = 0.2, t1: float = 0.9, f0: float = 3.0,
                m: float = 2.0) -> np.ndarray:
    """x(t) of the cubic law's push: the double integral of (f0/m)(3u^2 - 2u^3)."""
    T = t1 - t0
    u = np.clip((t - t0) / T, 0.0, 1.0)
    x = f0 / m * T**2 * (u**4 / 4 - u**5 / 10)
    late = t > t1
    x1, v1 = f0 / m * T**2 * 0.15, f0 / m * T * 0.5
    x[late] = x1 + v1 * (t[late] - t1) + f0 / m * (t[late] - t1)**2 / 2
    return x


def test_stepped_force_drives_the_block_as_integrated_by_hand() -> None:
    """dopri5 against the closed form at three tolerances: its steps end on the law's t0 and
    t1, where the force's second derivative jumps, and between them the motion is a
    polynomial of degree 5 in t, which the fifth-order method integrates exactly: round-off
    at every tolerance (measured 5.6e-16 to 8.9e-16 of a 0.9 m travel, 2 or 3 rejected
    steps; before the steps ended on the breakpoints 6.6e-7, 9.8e-8, 1.0e-9, the error of
    the steps across them, with 6 to 13 rejected), and generalized-alpha at two steps
    (second order)."""
    m = block()
    for rtol in (1e-6, 1e-8, 1e-10):
        res = m.dynamics(1.5, 150, rtol=rtol, atol=rtol * 1e-2)
        assert np.abs(res.body("block").x - block_exact(res.t)).max() < 1e-14
        assert res.stats["rejected_steps"] <= 3
    ga = [np.abs(r.body("block").x - block_exact(r.t)).max()
          for r in (m.dynamics(1.5, 150, method="generalized-alpha", h=h) for h in (1e-2, 5e-3))]
    assert 3.0 < ga[0] / ga[1] < 5.0          # O(h^2)


def test_dynamics_sensitivity_to_the_push_duration() -> None:
    """dx/dt1 by dopri5's variational equations against a central difference of the closed
    form (measured 1.3e-10 and 3.4e-10 relative), the steps ending on the law's t0 and t1
    with the state's run (3 rejected steps; 25 before, and dx/dt1 5.7e-10)."""
    res = block().dynamics(1.5, 150, rtol=1e-11, atol=1e-13,
                           sensitivities=["force.push.fx.step.0.t1", "force.push.fx.step.0.h"])
    assert res.stats["rejected_steps"] <= 5
    d = 1e-6
    for j, kw in enumerate(({"t1": 0.9}, {"f0": 3.0})):
        key, v = next(iter(kw.items()))
        want = (block_exact(res.t, **{key: v + d}) - block_exact(res.t, **{key: v - d})) / (2 * d)
        got = res.dq_dp[:, 0, j]
        assert np.abs(got - want).max() < 1e-8 * np.abs(want).max()


@pytest.mark.parametrize("step, needle", [
    ({"t0": 1.0, "t1": 1.0, "h": 1.0}, "t1 > t0"),
    ({"t0": 1.0, "t1": 0.5, "h": 1.0}, "t1 > t0"),
    ({"t0": 0.0, "t1": 1.0, "h": 1.0, "law": "bang-bang"}, "law must be one of"),
    ({"t0": 0.0, "t1": 1.0}, "needs 't0', 't1' and 'h'"),
    ({"t0": 0.0, "t1": 1.0, "h": 1.0, "speed": 2}, "needs 't0', 't1' and 'h'"),
    ({"t0": 0.0, "t1": float("nan"), "h": 1.0}, "t1"),
    ("fast", "must be a list of tables"),
    ({"t0": 0.0, "t1": 1.0, "h": 1.0, "law": ["cubic"]}, "law must be one of"),
])
def test_bad_steps_are_model_errors(step: object, needle: str) -> None:
    m = mbd2d.Model("m")
    m.add_body("b", q0=[0.0, 0.0, 0.0])
    with pytest.raises(mbd2d.ModelError, match=needle.replace("(", r"\(")):
        m.add_driver("absolute", body="b", coordinate="x", f={"poly": [0.0], "step": step})


def test_a_variant_without_a_rise_is_refused_by_the_core() -> None:
    """with_params can set t1 below t0 (each number alone is fine): the core's check says
    which step; a sweep keeps the other cases."""
    m = slider_crank({"t0": 0.25, "t1": 1.05, "h": 1.3, "law": "quintic"})
    bad = m.with_params({"driver.motor.f.step.0.t1": 0.1})
    with pytest.raises(mbd2d.ModelError, match="step 0 needs t1 > t0"):
        bad.kinematics(1.0, 10)
    ds = mbd2d.sweep(m, {"driver.motor.f.step.0.t1": np.array([0.8, 0.1, 1.2])}, t_end=1.0,
                     steps=10, workers=1)
    assert list(ds["status"].values[[0, 2]]) == [0, 0] and ds["status"].values[1] < 0
    assert "t1 > t0" in str(ds["message"].values[1])


def test_toml_round_trip_and_names() -> None:
    m = slider_crank({"t0": 0.25, "t1": 1.05, "h": 1.3, "law": "harmonic"})
    p = m.parameters()
    assert [k for k in p if ".step." in k] == [f"driver.motor.f.step.0.{k}"
                                               for k in ("t0", "t1", "h")]
    again = mbd2d.loads(toml_io.dumps(m))
    assert again.parameters() == p
    assert again.drivers[0].f.step[0].law == "harmonic"


def test_mbd2d_solve_runs_steps_as_python(tmp_path: Path) -> None:
    """The standalone program on a stepped driver (kinematics with sensitivities) and a
    stepped force (dynamics): the CSV Python writes, to the last digit."""
    m = slider_crank({"t0": 0.25, "t1": 1.05, "h": 1.3, "law": "cycloidal"})
    names = ["driver.motor.f.step.0.t1"]
    runs = [(m, dict(t_end=1.5, steps=30, sensitivities=names),
             m.kinematics(1.5, 30, sensitivities=names), dict(sensitivities=True)),
            (block(), dict(analysis="dynamics", t_end=1.5, steps=30),
             block().dynamics(1.5, 30), {})]
    for k, (model, kw, res, csv_kw) in enumerate(runs):
        mbd = tmp_path / f"m{k}.mbd"
        model.export(mbd, **kw)
        py = tmp_path / f"p{k}.csv"
        res.to_csv(py, **csv_kw)
        assert solve_file(mbd, tmp_path / f"f{k}.csv") == py.read_text()


# ------------------------------------------------------------ files of formats 1 and 2

def downgrade(text: str, version: int) -> str:
    """A format-3 file as formats 1 and 2 wrote it: every function of time without its
    counts of steps and table points (which must be 0), and every index into params and
    fparams moved."""
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    assert lines[0] == "mbd2d 3"
    out, i = [f"mbd2d {version}"], 1
    cons, forces, sens, vtab, opens = [], [], [], [], []
    blocks: dict[str, list[float]] = {}
    while i < len(lines):
        key, *rest = lines[i].split()
        if key in ("constraints", "forces", "sensitivities", "opens"):
            n = int(rest[0])
            rows = [ln.split() for ln in lines[i + 1:i + 1 + n]]
            {"constraints": cons, "forces": forces, "sensitivities": sens,
             "opens": opens}[key].extend(rows)
            out.append((key, rows))
            i += 1 + n
        elif key in ("params", "fparams"):
            n, vals, i = int(rest[0]), [], i + 1
            while len(vals) < n:
                vals += [float(w) for w in lines[i].split()]
                i += 1
            blocks[key] = vals
            out.append((key, vals))
        elif key == "cases":
            npar, nv, nc = map(int, rest)
            names = lines[i + 1:i + 1 + npar]
            vt = [ln.split() for ln in lines[i + 1 + npar:i + 1 + npar + nv]]
            vtab.extend(vt)
            j, vals = i + 1 + npar + nv, []
            while len(vals) < nc * (npar + nv):
                vals += lines[j].split()
                j += 1
            out.append(("cases", (lines[i], names, vt, vals)))
            i = j
        else:
            out.append(lines[i])
            i += 1

    def drop(vals: list[float], at: list[int]) -> tuple[list[float], dict[int, int]]:
        for a in at:
            assert vals[a - 1] == 0.0            # (ns = nt = 0: no steps, no table)
        keep = [k for k in range(1, len(vals) + 1) if k not in set(at)]
        return [vals[k - 1] for k in keep], {k: n + 1 for n, k in enumerate(keep)}

    def fun_len(v: list[float], a: int) -> int:   # [np, c, nh, 3 nh, ns, 4 ns, nt, 2 nt]
        n_p = int(v[a - 1])
        nh = int(v[a + n_p])
        ns = int(v[a + n_p + 1 + 3 * nh])
        return n_p + 4 + 3 * nh + 4 * ns + 2 * int(v[a + n_p + 2 + 3 * nh + 4 * ns])

    pat = [k for c in cons if 101 <= int(c[1]) <= 103
           for k in (int(c[6]) + int(c[7]) - 2, int(c[6]) + int(c[7]) - 1)]
    fat = []
    fp = blocks.get("fparams", [])
    for f in forces:
        kind, off, n = int(f[1]), int(f[4]), int(f[5])
        if kind == 3:
            end_fx = off + 2 + fun_len(fp, off + 2) - 1
            fat += [end_fx - 1, end_fx]
        if kind in (1, 2, 3, 4):
            fat += [off + n - 2, off + n - 1]
    rp, rmap = drop(blocks["params"], pat)
    fpn, fmap = drop(fp, fat)
    for c in cons:
        first, last = int(c[6]), int(c[6]) + int(c[7]) - 1
        last -= 2 * (last in pat)
        c[6], c[7] = str(rmap[first]), str(rmap[last] - rmap[first] + 1)
    for f in forces:
        first, last = int(f[4]), int(f[4]) + int(f[5]) - 1
        last -= 2 * (last in fat)
        f[4], f[5] = str(fmap[first]), str(fmap[last] - fmap[first] + 1)
    for row in sens + vtab:
        idx = -1
        if row[idx - 1] in ("1", "4"):
            row[idx] = str((rmap if row[idx - 1] == "1" else fmap)[int(row[idx])])
    for row in opens:
        row[0] = str(rmap[int(row[0])])
    text_out = []
    for item in out:
        if isinstance(item, str):
            text_out.append(item)
        elif item[0] in ("params", "fparams"):
            vals = rp if item[0] == "params" else fpn
            text_out += [f"{item[0]} {len(vals)}", " ".join(repr(v) for v in vals)]
        elif item[0] == "cases":
            head, names, vt, vals = item[1]
            text_out += [head, *names, *(" ".join(r) for r in vt), " ".join(vals)]
        else:
            text_out += [f"{item[0]} {len(item[1])}", *(" ".join(r) for r in item[1])]
    return "\n".join(text_out) + "\n"


def run_solver(path: Path, text: str) -> str:
    path.write_text(text)
    return solve_file(path, path.with_suffix(".csv"))


def forced_fourbar() -> mbd2d.Model:
    """The four-bar with masses, every force kind with a function (the point force's two),
    for dynamics."""
    m = mbd2d.load(Path(__file__).resolve().parents[1] / "examples" / "fourbar_masses.toml")
    m.drivers.clear()
    m.add_spring(["ground", "coupler"], [[0.0, 2.0], [0.0, 0.0]], stiffness=20.0, damping=1.0,
                 length0=1.0, f={"poly": [0.5, 0.1]}, name="s1")
    m.add_torque("crank", f={"poly": [1.0], "harmonic": {"amplitude": 0.5, "omega": 3.0}},
                 name="tq")
    m.add_point_force("coupler", [0.2, 0.0], fx={"poly": [0.3, 0.2, 0.1]}, fy=-2.0,
                      name="push")
    m.add_rotational_spring(["crank", "rocker"], stiffness=2.0, damping=0.1, angle0=0.5,
                            f=0.2, name="rs")
    return m


def test_format_2_files_read_as_before(tmp_path: Path) -> None:
    """Files of format 2 (functions without steps) give the format-3 file's CSV: dynamics
    with every force kind and design sensitivities of function coefficients after them,
    and a kinematic sweep of a driver coefficient."""
    m = forced_fourbar()
    f3 = tmp_path / "f3.mbd"
    names = ["force.push.fy.poly.0", "force.rs.angle0", "force.tq.f.harmonic.0.omega",
             "body.coupler.mass"]
    m.export(f3, analysis="dynamics", t_end=0.5, steps=20, rtol=1e-9, atol=1e-11,
             sensitivities=names)
    new = run_solver(tmp_path / "a3.mbd", f3.read_text())
    old = run_solver(tmp_path / "a2.mbd", downgrade(f3.read_text(), 2))
    assert old == new and "force.tq.f.harmonic.0.omega" in new.splitlines()[0]
    sw = tmp_path / "sweep.mbd"
    driven = mbd2d.load(Path(__file__).resolve().parents[1] / "examples" / "fourbar_grashof.toml")
    mbd2d.export_sweep(driven, sw, {"driver.motor.f.poly.1": [0.5, 1.0],
                                    "joint.B.points.0.0": [1.7, 1.8]}, t_end=1.0, steps=5)
    assert run_solver(tmp_path / "s2.mbd", downgrade(sw.read_text(), 2)) == \
        run_solver(tmp_path / "s3.mbd", sw.read_text())


def test_format_1_files_still_run(tmp_path: Path) -> None:
    """A kinematics file of format 1 (no every, solver or labels; drivers without steps)."""
    model = mbd2d.load(Path(__file__).resolve().parents[1] / "examples" / "slider_crank.toml")
    mbd = tmp_path / "v3.mbd"
    model.export(mbd, t_end=1.0, steps=20)
    lines = downgrade(mbd.read_text(), 1).splitlines()
    lines = lines[:next(i for i, ln in enumerate(lines) if ln.startswith("labels"))]
    keep = [ln for ln in lines if not ln.startswith(("every", "solver"))]
    rows = read_csv_text(run_solver(tmp_path / "v1.mbd", "\n".join(keep + ["end"]) + "\n"))
    np.testing.assert_allclose(rows[:, 1:], model.kinematics(1.0, 20).table()[1][:, 1:],
                               rtol=0, atol=1e-12)


def read_csv_text(text: str) -> np.ndarray:
    return np.array([[float(w) for w in ln.split(",")] for ln in text.splitlines()[1:]])


def test_steps_keep_the_length_scale() -> None:
    """A stepped stroke in micrometres and in kilometres: the same motion scaled (the rise h
    is a length, t0 and t1 are times)."""
    out = []
    for scale in (1e-6, 1.0, 1e3):
        m = mbd2d.Model("stroke")
        m.add_body("s", q0=[0.0, 0.0, 0.0])
        m.add_translational(["ground", "s"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="g")
        m.add_driver("absolute", body="s", coordinate="x",
                     f={"poly": [0.0], "step": {"t0": 0.1, "t1": 0.6, "h": 2.0 * scale}})
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            res = m.kinematics(1.0, 20)
        out.append(res.qdd[:, 0] / scale)
    np.testing.assert_allclose(out[0], out[1], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(out[2], out[1], rtol=1e-12, atol=1e-12)
    assert math.isclose(out[1][10], 2.0 * 2 * math.pi * math.sin(2 * math.pi * 0.8) / 0.25,
                        rel_tol=1e-12)


@pytest.mark.parametrize("law, t0, t1, needle", [
    (2.5, 0.1, 0.5, "unknown law"),
    (99.0, 0.1, 0.5, "unknown law"),
    (-1.0, 0.1, 0.5, "unknown law"),
    (3.0, 0.5, 0.5, "needs t1 > t0"),
    (3.0, 0.5, 0.5 + 1e-12, "needs t1 > t0"),
    (3.0, -1e13, 0.5, "needs |t0| and |t1|"),
])
def test_hostile_steps_in_a_file(tmp_path: Path, law: float, t0: float, t1: float,
                                 needle: str) -> None:
    """A hand-edited .mbd file with a bad step: mbd2d-solve names it (exit code 2)."""
    m = slider_crank({"t0": 0.25, "t1": 1.05, "h": 1.3, "law": "cubic"})
    mbd = tmp_path / "m.mbd"
    m.export(mbd, t_end=1.0, steps=10)
    lines = [ln for ln in mbd.read_text().splitlines() if not ln.startswith("#")]
    at = next(k for k, ln in enumerate(lines) if ln.startswith("params "))
    n, vals, end = int(lines[at].split()[1]), [], at + 1
    while len(vals) < n:
        vals += [float(w) for w in lines[end].split()]
        end += 1
    i = next(k for k in range(n - 2) if vals[k:k + 3] == [1.0, 0.25, 1.05])   # law t0 t1
    vals[i:i + 3] = [law, t0, t1]
    bad = tmp_path / "bad.mbd"
    bad.write_text("\n".join(lines[:at + 1] + [" ".join(map(repr, vals))] + lines[end:]) + "\n")
    r = subprocess.run([find_solver(), str(bad), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and needle in r.stderr, r.stderr


@pytest.mark.parametrize("value", [float("nan"), float("inf"), 1e300])
def test_hostile_step_values_from_python(value: float) -> None:
    """with_params with a non-finite or huge step time or rise: a ModelError, no NaN."""
    m = slider_crank({"t0": 0.25, "t1": 1.05, "h": 1.3, "law": "cubic"})
    for name in ("driver.motor.f.step.0.t1", "driver.motor.f.step.0.h"):
        with pytest.raises(mbd2d.ModelError):
            m.with_params({name: value}).kinematics(1.0, 10)


@pytest.mark.parametrize("law, coefficient", [
    ("cubic", 6.0), ("quintic", 10 / math.sqrt(3)), ("cycloidal", 2 * math.pi),
    ("harmonic", math.pi**2 / 2), ("modified-sine", 4 * math.pi**2 / (math.pi + 4)),
    ("modified-trapezoid", 8 * math.pi / (2 + math.pi))])
def test_peak_accelerations_are_the_published_coefficients(law: str, coefficient: float
                                                            ) -> None:
    """The largest acceleration of a rise h over T is C h / T^2 with the textbook
    coefficients (Norton, Cam Design and Manufacturing Handbook, ch. 3: 6, 5.77, 6.28, 4.93,
    5.53, 4.89), here in their exact forms, found on a fine grid of a driven slider."""
    m = mbd2d.Model("stroke")
    m.add_body("s", q0=[0.0, 0.0, 0.0])
    m.add_translational(["ground", "s"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="g")
    m.add_driver("absolute", body="s", coordinate="x",
                 f={"poly": [0.0], "step": {"t0": 0.0, "t1": 0.5, "h": 0.03, "law": law}})
    res = m.kinematics(0.5, 20000)
    peak = np.abs(res.qdd[:-1, 0]).max() * 0.5**2 / 0.03
    assert peak == pytest.approx(coefficient, rel=1e-6)
    assert res.q[-1, 0] == pytest.approx(0.03, abs=1e-15)


@pytest.mark.parametrize("f, needle", [
    (mbd2d.TimeFunction(step=(mbd2d.Step(0.0, 1.0, 1.0, "bogus"),)), "law must be one of"),
    (mbd2d.TimeFunction(step=(mbd2d.Step(1.0, 0.5, 1.0),)), "t1 > t0"),
    (mbd2d.TimeFunction(step=(mbd2d.Step(0.0, 1.0, float("nan")),)), "must be finite"),
    (mbd2d.TimeFunction(step=((0.0, 1.0, 1.0),)), "must be a Step"),
    (mbd2d.TimeFunction(table=mbd2d.Table((0.0, 1.0), (1.0,))), "one length"),
    (mbd2d.TimeFunction(table=mbd2d.Table((0.0, 0.0), (1.0, 2.0))), "must increase"),
])
def test_functions_built_in_code_are_checked(f: mbd2d.TimeFunction, needle: str) -> None:
    """A TimeFunction made in code gets the checks its TOML table would."""
    m = mbd2d.Model("m")
    m.add_body("b", q0=[0.0, 0.0, 0.0])
    with pytest.raises(mbd2d.ModelError, match=needle):
        m.add_driver("absolute", body="b", coordinate="x", f=f)


@pytest.mark.parametrize("law", LAWS)
def test_inverse_dynamics_effort_is_mass_times_the_laws_acceleration(law: str) -> None:
    """A 2 kg block driven along its guide by a step: the driver's effort is m x'' from the
    law's closed form at every output, the instants t0 and t1 included (the value after
    them: right-continuous)."""
    m = mbd2d.Model("driven-block")
    m.add_body("block", q0=[0.0, 0.0, 0.0], mass=2.0, inertia=0.1)
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="g")
    step = {"t0": 0.2, "t1": 0.7, "h": 0.05, "law": law}
    m.add_driver("absolute", body="block", coordinate="x",
                 f={"poly": [0.0], "step": step}, name="push")
    res = m.inverse_dynamics(1.0, 100)
    want = np.array([2.0 * step_closed_form(step, float(t))[2] for t in res.t])
    np.testing.assert_allclose(res.effort("push"), want, rtol=0, atol=1e-11)
