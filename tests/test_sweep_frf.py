"""Frequency response sweeps (mbd2d.sweep(..., "frf")): every case against the closed form of
its own block on a spring-damper (1 / (k - m w^2 + i c w) and its multiples) and against
numpy's solve of its own two-block matrices, every case bit for bit as its own
frequency_response(), failing cases reported in their rows, the files, the command line and
mbd2d-solve."""
from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from test_frf import block, damped_pair
from test_modes import G

pytest.importorskip("xarray")

FREQS = np.array([0.0, 0.3, 0.6755, 1.1, 4.0])
INPUTS = ["force.s.length0", "force.s.f.poly.0", "model.gravity.1"]


def block_cases() -> dict[str, np.ndarray]:
    """Stiffness, damping and mass of the block, every combination (undamped cases too)."""
    return mbd2d.grid({"force.s.stiffness": [20.0, 36.0, 90.0],
                       "force.s.damping": [0.0, 1.5, 30.0], "body.block.mass": [0.5, 2.0]})


def test_each_case_against_its_closed_form() -> None:
    """dy per unit input of each case (k, c, m): free length -k/D, actuator force -1/D,
    gravity's y m/D with D = k - m w^2 + i c w; the case's equilibrium y = -0.5 - m g / k."""
    cases = block_cases()
    ds = mbd2d.sweep(block(), cases, "frf", inputs=INPUTS, frequencies=FREQS, workers=1)
    assert ds.response.dims == ("case", "frequency", "coordinate", "input")
    assert ds.response.shape == (18, FREQS.size, 3, 3) and (ds.status.values == 0).all()
    np.testing.assert_array_equal(ds.frequency.values, FREQS)
    assert list(ds.input.values) == INPUTS and ds.attrs["run"] == "frf"
    w = 2 * np.pi * FREQS
    worst = 0.0
    for c in range(18):
        k, damp, m = (cases[n][c] for n in ("force.s.stiffness", "force.s.damping",
                                             "body.block.mass"))
        d = k - m * w**2 + 1j * damp * w
        for j, want in enumerate((-k / d, -1 / d, m / d)):
            got = ds.response.values[c, :, 1, j]
            worst = max(worst, float(np.max(np.abs(got - want) / np.abs(want))))
            np.testing.assert_array_equal(ds.response.values[c, :, 0, j], 0.0)
        assert abs(ds.q.values[c, 1] - (-0.5 - m * G / k)) < 1e-12
        assert ds.n_free.values[c] == 1 and ds.stability.values[c] == "stable"
    print(f"worst relative error {worst:.2g}")
    assert worst < 1e-13, worst


def test_two_blocks_against_numpy_per_case() -> None:
    """Two blocks on springs damped at one end, the damping and the first spring swept:
    (K - w^2 M + i w C) x = e_1 of each case's own matrices, solved by numpy."""
    m = 0.5
    model = damped_pair(3.0, m, 200.0)
    name = [p for p in model.parameters() if p.startswith("force.shaker.fx")][0]
    springs = [p for p in model.parameters() if p.endswith(".stiffness")]
    cases = {"force.damper.damping": [0.5, 3.0, 12.0, 40.0], springs[0]: [150.0, 200.0,
                                                                         250.0, 400.0]}
    f = np.linspace(0.0, 8.0, 9)
    ds = mbd2d.sweep(model, cases, "frf", inputs=[name], frequencies=f, workers=1)
    for c in range(4):
        k1, k2, damp = cases[springs[0]][c], 200.0, cases["force.damper.damping"][c]
        kk = np.array([[k1 + k2, -k2], [-k2, k2]])
        for j, fj in enumerate(f):
            w = 2 * np.pi * fj
            want = np.linalg.solve(kk - w**2 * m * np.eye(2) + 1j * w * np.diag([0.0, damp]),
                                   [1.0, 0.0])
            np.testing.assert_allclose(ds.response.values[c, j, [0, 3], 0], want, rtol=1e-11,
                                       atol=1e-13 * abs(want).max())


def test_each_case_is_its_own_frequency_response_bit_for_bit() -> None:
    """The batch gives every case what model.with_params(case).frequency_response gives,
    bit for bit (equilibrium, response, free motions), about q0 too."""
    cases = block_cases()
    model = block()
    for equilibrium in (True, False):
        ds = mbd2d.sweep(model, cases, "frf", inputs=INPUTS[:2], frequencies=FREQS,
                         equilibrium=equilibrium, workers=1)
        for c in (0, 7, 17):
            one = model.with_params({n: v[c] for n, v in cases.items()}).frequency_response(
                INPUTS[:2], FREQS, equilibrium=equilibrium)
            assert np.array_equal(one.response, ds.response.values[c])
            assert np.array_equal(one.q, ds.q.values[c]) and one.n_free == ds.n_free[c]
        if not equilibrium:
            assert set(ds.stability.values) == {"not examined"}


def test_a_failing_case_keeps_its_status_and_message() -> None:
    """A case without a spring has no equilibrium (a ConvergenceError alone): its row says
    so, its response is NaN, and the other cases are untouched. About q0, a case without a
    spring is unbounded at 0 Hz: the message names the frequency."""
    model = block()
    cases = {"force.s.stiffness": [36.0, 0.0, 50.0]}
    ds = mbd2d.sweep(model, cases, "frf", inputs=INPUTS[1:2], frequencies=FREQS, workers=1)
    with pytest.raises(mbd2d.ConvergenceError) as err:
        model.with_params({"force.s.stiffness": 0.0}).frequency_response(INPUTS[1], FREQS)
    assert list(ds.status.values) == [0, err.value.status, 0]
    assert ds.message.values[1] == str(err.value) and ds.attrs["failed"] == 1
    assert np.isnan(ds.response.values[1]).all() and np.isnan(ds.q.values[1]).all()
    assert np.isfinite(ds.response.values[[0, 2]]).all()
    at_q0 = mbd2d.sweep(model, cases, "frf", inputs=INPUTS[1:2], frequencies=FREQS,
                        equilibrium=False, workers=1)
    with pytest.raises(mbd2d.SingularJacobianError) as err:
        model.with_params({"force.s.stiffness": 0.0}).frequency_response(
            INPUTS[1], FREQS, equilibrium=False)
    assert "at 0 Hz is unbounded" in str(err.value)
    assert at_q0.message.values[1] == str(err.value)
    assert at_q0.status.values[1] == err.value.status


@pytest.mark.parametrize("kw, needle", [
    ({"frequencies": FREQS}, "inputs"),
    ({"inputs": INPUTS[:1]}, "frequencies"),
    ({"inputs": INPUTS[:1], "frequencies": [-1.0]}, "frequencies must be"),
    ({"inputs": ["force.s.stifness"], "frequencies": FREQS}, "force.s.stiffness"),
    ({"inputs": INPUTS[:1], "frequencies": FREQS, "t_end": 1.0}, "t_end"),
    ({"inputs": INPUTS[:1], "frequencies": FREQS, "sensitivities": INPUTS[1:2]},
     "no design sensitivities"),
    ({"inputs": INPUTS[:1], "frequencies": FREQS, "measures": "dead_centre_distance"},
     "measures"),
])
def test_bad_settings_are_model_errors(kw: dict, needle: str) -> None:
    with pytest.raises(mbd2d.ModelError, match=needle):
        mbd2d.sweep(block(), {"force.s.stiffness": [30.0, 40.0]}, "frf", workers=1, **kw)


def test_files_and_the_command_line(tmp_path: Path) -> None:
    """CSV: one row per case and frequency with the columns of a single response's CSV;
    netCDF keeps the complex response; `mbd2d sweep --analysis frf` writes the same CSV."""
    model = block()
    cases = {"force.s.stiffness": np.linspace(20.0, 50.0, 4)}
    f = np.linspace(0.0, 3.0, 5)
    ds = mbd2d.sweep(model, cases, "frf", inputs=INPUTS[:1], frequencies=f, workers=1)
    mbd2d.write_sweep(ds, tmp_path / "s.csv")
    rows = list(csv.reader((tmp_path / "s.csv").read_text().splitlines()))
    one = model.frequency_response(INPUTS[0], f)
    one.to_csv(tmp_path / "one.csv")
    single = list(csv.reader((tmp_path / "one.csv").read_text().splitlines()))
    assert rows[0][:5] == ["case", "force.s.stiffness", "frequency_hz", "status", "message"]
    assert rows[0][5:] == single[0][1:] and len(rows) == 1 + 4 * 5
    assert [float(v) for v in rows[1 + 5][5:]] == [float(v) for v in
                                                   _row_of(ds, 1, 0)]
    mbd2d.write_sweep(ds, tmp_path / "s.nc")
    import xarray as xr
    with xr.open_dataset(tmp_path / "s.nc") as back:
        assert np.array_equal(back.response.values, ds.response.values)
    toml = tmp_path / "block.toml"
    toml.write_text(_block_text())
    r = subprocess.run([sys.executable, "-m", "mbd2d", "sweep", str(toml), "--param",
                        "force.s.stiffness=20:50:4", "--analysis", "frf", "--input",
                        INPUTS[0], "--f", "0:3:5", "--out", str(tmp_path / "c.csv")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "c.csv").read_text() == (tmp_path / "s.csv").read_text()
    r = subprocess.run([sys.executable, "-m", "mbd2d", "sweep", str(toml), "--param",
                        "force.s.stiffness=20:50:4", "--input", INPUTS[0], "--t-end", "1",
                        "--steps", "4", "--out", str(tmp_path / "k.csv")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--analysis frf" in r.stderr


def _row_of(ds: object, c: int, k: int) -> list[float]:
    """Case c's response at frequency k as the CSV's re, im pairs."""
    h = ds.response.values[c, k, :, 0]                         # type: ignore[attr-defined]
    return [v for z in h for v in (z.real + 0.0, z.imag + 0.0)]


def _block_text() -> str:
    from test_modes import block_text
    return block_text(36.0, 1.5, 2.0)


def test_mbd2d_solve_runs_a_frf_sweep_as_python(tmp_path: Path) -> None:
    """export_sweep(..., "frf") and mbd2d-solve: the CSV of write_sweep byte for byte (a
    failing case among them: its status, with the program's own message)."""
    from test_standalone import solve_file
    model = block()
    cases = {"force.s.stiffness": [20.0, 0.0, 36.0, 90.0],
             "force.s.damping": [0.0, 1.5, 1.5, 30.0]}
    kw = {"inputs": INPUTS, "frequencies": FREQS}
    ds = mbd2d.sweep(model, cases, "frf", workers=1, **kw)
    assert list(ds.status.values != 0) == [False, True, False, False]
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    mbd2d.export_sweep(model, tmp_path / "s.mbd", cases, "frf", **kw)
    py = list(csv.reader((tmp_path / "py.csv").read_text().splitlines()))
    fo = list(csv.reader(solve_file(tmp_path / "s.mbd", tmp_path / "f.csv").splitlines()))
    assert len(py) == len(fo) == 1 + 3 * FREQS.size + 1
    msg = py[0].index("message")
    for a, b in zip(py, fo):
        assert a[:msg] + a[msg + 1:] == b[:msg] + b[msg + 1:]
    good = {k: np.delete(np.asarray(v), 1) for k, v in cases.items()}
    mbd2d.export_sweep(model, tmp_path / "good.mbd", good, "frf", **kw)
    mbd2d.write_sweep(mbd2d.sweep(model, good, "frf", workers=1, **kw), tmp_path / "g.csv")
    assert solve_file(tmp_path / "good.mbd", tmp_path / "gf.csv") == \
        (tmp_path / "g.csv").read_text()


def test_bode_family_picture(tmp_path: Path) -> None:
    """plot_sweep of a frequency response sweep: magnitude and phase rows per coordinate
    drawn (by default those that move: the block's y alone), each case's peak against the
    parameter (the closed form's peak sqrt(k/m) / (2 pi) for light damping); a failed case
    marked; bad names are ModelErrors."""
    pytest.importorskip("matplotlib")
    from mbd2d.plots import plot_sweep
    k = np.array([20.0, 0.0, 36.0, 90.0])
    f = np.linspace(0.05, 2.0, 400)
    ds = mbd2d.sweep(block(c=0.05), {"force.s.stiffness": k}, "frf", inputs=INPUTS[:2],
                     frequencies=f, workers=1)
    fig = plot_sweep(ds)
    assert len(fig.axes) == 4 + 1 and "1 failed" in fig._suptitle.get_text()
    peak_f = fig.axes[3].lines[0].get_ydata()
    want = np.sqrt(k[[0, 2, 3]] / 2.0) / (2 * np.pi)
    assert np.all(np.abs(peak_f - want) <= f[1] - f[0])
    assert fig.axes[3].lines[1].get_xdata()[0] == 0.0            # the failed case, marked
    two = plot_sweep(ds, coordinates=["block.y", "block.x"], input=INPUTS[1])
    assert len(two.axes) == 8 + 2
    for kw, needle in [({"coordinates": ["block.z"]}, "no coordinate"),
                       ({"input": "force.s.damping"}, "no input"),
                       ({"measures": ["dead_centre_distance"]}, "no measures")]:
        with pytest.raises(mbd2d.ModelError, match=needle):
            plot_sweep(ds, **kw)
    toml = tmp_path / "block.toml"
    toml.write_text(_block_text())
    r = subprocess.run([sys.executable, "-m", "mbd2d", "sweep", str(toml), "--param",
                        "force.s.stiffness=20:50:4", "--analysis", "frf", "--input",
                        INPUTS[0], "--f", "0.1:3:50", "--log", "--out",
                        str(tmp_path / "c.nc"), "--plot", str(tmp_path / "bode.png")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "bode.png").read_bytes()[:4] == b"\x89PNG"


def held_block() -> mbd2d.Model:
    """A base held at y = 0 by a driver ("hold") on a vertical guide, and a 2 kg block on
    another guide hanging from it by a spring-damper; a vertical push on the block (the
    input: its amplitude)."""
    m = mbd2d.Model("held block", gravity=(0.0, -G))
    m.add_body("base", (0.0, 0.0, 0.0), mass=1.0, inertia=0.1)
    m.add_body("block", (0.0, -1.0, 0.0), mass=2.0, inertia=0.01)
    for body in ("base", "block"):
        m.add_translational(["ground", body], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 1.0], [0.0, 1.0]],
                            name=f"guide_{body}")
    m.add_driver("absolute", {"poly": [0.0]}, body="base", coordinate="y", name="hold")
    m.add_force("spring", bodies=["base", "block"], points=[[0.0, 0.0], [0.0, 0.0]],
                stiffness=36.0, damping=1.5, length0=0.5, name="s")
    m.add_force("point", body="block", point=[0.0, 0.0], fx=0.0, fy={"poly": [0.0]},
                name="push")
    return m


def test_the_drivers_effort_response_against_the_closed_form(tmp_path: Path) -> None:
    """The driver's effort per unit push, -(k + i c w) / (k - m w^2 + i c w) (the
    spring-damper's force on the base, held against; -1 at 0 Hz), for each case (k, c, m);
    lam_response and effort_response of every case equal to its own frequency_response()'s
    lam_response and effort_response() bit for bit (a name that is no driver: KeyError); the
    CSV's effort columns from Python and from mbd2d-solve
    byte for byte."""
    from test_standalone import solve_file
    model = held_block()
    cases = mbd2d.grid({"force.s.stiffness": [20.0, 36.0], "force.s.damping": [0.0, 1.5],
                        "body.block.mass": [0.5, 2.0]})
    kw = {"inputs": ["force.push.fy.poly.0"], "frequencies": FREQS[1:]}
    ds = mbd2d.sweep(model, cases, "frf", workers=1, **kw)
    assert ds.effort_response.dims == ("case", "frequency", "driver", "input")
    assert list(ds.driver.values) == ["hold"] and (ds.status.values == 0).all()
    w = 2 * np.pi * FREQS[1:]
    for c in range(ds.sizes["case"]):
        k, cd, m = (float(ds[n].values[c]) for n in cases)
        want = -(k + 1j * cd * w) / (k - m * w**2 + 1j * cd * w)
        got = ds.effort_response.values[c, :, 0, 0]
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
        one = model.with_params({n: float(ds[n].values[c]) for n in cases}) \
            .frequency_response(**kw)
        np.testing.assert_array_equal(ds.lam_response.values[c], one.lam_response)
        np.testing.assert_array_equal(got, one.effort_response("hold"))
    with pytest.raises(KeyError, match="no driver 's'"):
        one.effort_response("s")
    mbd2d.write_sweep(ds, tmp_path / "py.csv")
    rows = list(csv.reader((tmp_path / "py.csv").read_text().splitlines()))
    col = rows[0].index("d(effort.hold)/d(force.push.fy.poly.0).re")
    assert rows[0][col + 1] == "d(effort.hold)/d(force.push.fy.poly.0).im"
    assert float(rows[1][col]) == ds.effort_response.values[0, 0, 0, 0].real
    mbd2d.export_sweep(model, tmp_path / "s.mbd", cases, "frf", **kw)
    assert solve_file(tmp_path / "s.mbd", tmp_path / "f.csv") == \
        (tmp_path / "py.csv").read_text()


@pytest.mark.parametrize("reactions", [False, True])
def test_one_runs_csv_has_the_efforts_response(tmp_path: Path, reactions: bool) -> None:
    """One frequency response's CSV (Python, ``mbd2d frf --out``, mbd2d-solve) carries each
    driver's effort after each input's coordinates, as a sweep's: the held base's effort per
    unit push against -(k + i c w) / (k - m w^2 + i c w), columns and bytes equal in the
    three writers; the reactions (asked for) after the efforts."""
    from test_standalone import solve_file
    model, inp = held_block(), "force.push.fy.poly.0"
    res = model.frequency_response(inp, FREQS)
    header, rows = res.table(reactions=reactions)
    col = header.index(f"d(effort.hold)/d({inp}).re")
    assert header[col - 1] == f"d(block.theta)/d({inp}).im"
    assert header[col + 1] == f"d(effort.hold)/d({inp}).im"
    if reactions:
        assert header[col + 2] == f"d(guide_base.fx)/d({inp}).re"
    assert len(header) == 1 + 2 * (6 + 1) + (2 * 6 * 3 if reactions else 0)   # 3 constraints
    w = 2 * np.pi * FREQS
    want = -(36.0 + 1j * 1.5 * w) / (36.0 - 2.0 * w**2 + 1j * 1.5 * w)
    np.testing.assert_allclose(rows[:, col] + 1j * rows[:, col + 1], want, rtol=1e-12, atol=0)
    py = tmp_path / "py.csv"
    res.to_csv(py, reactions=reactions)
    model.export(tmp_path / "m.mbd", analysis="frf", inputs=[inp], frequencies=FREQS,
                 outputs=["reactions"] if reactions else None)
    assert solve_file(tmp_path / "m.mbd", tmp_path / "f.csv") == py.read_text()
    toml = tmp_path / "held.toml"
    toml.write_text(mbd2d.description.toml_io.dumps(model))
    r = subprocess.run([sys.executable, "-m", "mbd2d", "frf", str(toml), "--input", inp,
                        "--f", f"{FREQS[0]}:{FREQS[-1]}:{FREQS.size}", "--out",
                        str(tmp_path / "c.csv")] + (["--reactions"] if reactions else []),
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    lin = model.frequency_response(inp, np.linspace(FREQS[0], FREQS[-1], FREQS.size))
    lin.to_csv(tmp_path / "lin.csv", reactions=reactions)
    assert (tmp_path / "c.csv").read_text() == (tmp_path / "lin.csv").read_text()
