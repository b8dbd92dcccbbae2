"""`mbd2d tolerance`: the tolerance analysis from the command line, one row per time in a CSV
(or a netCDF file), a summary on the terminal.

Oracle of the first-order columns: |dq/dp| sigma with dq/dp from central differences of
runs of ``model.with_params`` (no sensitivity code); of a point's: the same for the point
P = r + A(theta) s' computed here from those runs. The Monte Carlo columns are the API's
sweep (same seed), already checked against the first order in tests/test_tolerance.py.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.cli import main
from mbd2d.results import read_csv
from mbd2d.studies import write_sweep, write_tolerance

pytest.importorskip("xarray")

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
FOURBAR = str(EX / "fourbar_grashof.toml")
PRM, SIG = "joint.B.points.0.0", 2e-3


def _fd_q(model: mbd2d.Model, prm: str, **kw) -> tuple[np.ndarray, np.ndarray]:
    """q and dq/dp by central differences (at the tightest Newton tolerance)."""
    v = model.parameters()[prm]
    dp = 1e-5 * max(1.0, abs(v))
    run = lambda m: m.kinematics(tol=1e-15, **kw).q  # noqa: E731
    return run(model), (run(model.with_params({prm: v + dp}))
                        - run(model.with_params({prm: v - dp}))) / (2 * dp)


def test_csv_first_order_columns_are_differences_times_sigma(tmp_path: Path, capsys) -> None:
    out = tmp_path / "tol.csv"
    assert main(["tolerance", FOURBAR, "--sigma", f"{PRM}={SIG}", "--samples", "40",
                 "--workers", "1", "--t-end", "1", "--steps", "20", "--point", "coupler:0,1",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "largest first-order standard deviation" in text and f"wrote {out}" in text
    header, rows = read_csv(out)
    model = mbd2d.load(FOURBAR)
    _, dq = _fd_q(model, PRM, t_end=1.0, steps=20)
    q = model.kinematics(1.0, 20).q                   # the nominal run, as the command's
    names = [str(c) for c in model.kinematics(1.0, 1).coordinate_names]
    np.testing.assert_allclose(rows[:, 0], np.linspace(0, 1, 21), rtol=0, atol=1e-15)
    for j, c in enumerate(names):
        np.testing.assert_array_equal(rows[:, header.index(c)], q[:, j])
        lin = rows[:, header.index(f"{c}.std_linear")]
        np.testing.assert_allclose(lin, np.abs(dq[:, j]) * SIG, rtol=1e-6,
                                   atol=1e-9 * SIG, err_msg=c)
    # the point (0, 1) of the coupler: P = r + A(theta) s'
    i = 3 * [n.split(".")[0] for n in names[::3]].index("coupler")

    def point(qq: np.ndarray) -> np.ndarray:
        th = qq[:, i + 2]
        return np.column_stack([qq[:, i] - np.sin(th), qq[:, i + 1] + np.cos(th)])
    v = model.parameters()[PRM]
    dp = 1e-5 * max(1.0, abs(v))
    runs = [model.with_params({PRM: v + s * dp}).kinematics(1.0, 20, tol=1e-15).q
            for s in (1, -1)]
    dpt = (point(runs[0]) - point(runs[1])) / (2 * dp)
    for k, xy in enumerate("xy"):
        np.testing.assert_allclose(rows[:, header.index(f"coupler(0;1).{xy}.std_linear")],
                                   np.abs(dpt[:, k]) * SIG, rtol=1e-6, atol=1e-9 * SIG)
    # the Monte Carlo columns are the API's (same seed, same draws)
    tol = mbd2d.tolerance(model, {PRM: SIG}, samples=40, workers=1, t_end=1.0, steps=20)
    for j, c in enumerate(names):
        np.testing.assert_array_equal(rows[:, header.index(f"{c}.std_mc")],
                                      tol.dataset.q_std_mc.values[:, j])
        np.testing.assert_array_equal(rows[:, header.index(f"{c}_ddot.mean_mc")],
                                      tol.dataset.qdd_mean_mc.values[:, j])


def test_netcdf_and_statics(tmp_path: Path, capsys) -> None:
    """A .nc file holds the dataset and the points (point1_x ...); statics gives one row."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    out = tmp_path / "tol.nc"
    assert main(["tolerance", FOURBAR, "--sigma", f"{PRM}={SIG}", "--samples", "0",
                 "--t-end", "1", "--steps", "10", "--point", "coupler:0,1",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    ds = xr.open_dataset(out)
    tol = mbd2d.tolerance(mbd2d.load(FOURBAR), {PRM: SIG}, samples=0, t_end=1.0, steps=10)
    np.testing.assert_array_equal(ds.q_std_linear.values, tol.dataset.q_std_linear.values)
    np.testing.assert_array_equal(ds.point1_y_std_linear.values,
                                  tol.point("coupler", (0, 1)).y_std_linear.values)
    assert ds.attrs["point1"] == "coupler(0;1)" and "q_std_mc" not in ds
    ds.close()
    spring = str(EX / "pendulum_spring.toml")
    csv = tmp_path / "st.csv"
    assert main(["tolerance", spring, "--analysis", "statics", "--sigma", "body.bar.mass=0.01",
                 "--samples", "0", "--out", str(csv)]) == 0
    header, rows = read_csv(csv)
    st = mbd2d.load(spring).statics(sensitivities=["body.bar.mass"])
    assert rows.shape == (1, len(header))
    np.testing.assert_allclose(rows[0, header.index("bar.theta.std_linear")],
                               abs(st.dq_dp[2, 0]) * 0.01, rtol=1e-14)
    assert "lambda.pivot.x.std_linear" in header


@pytest.mark.parametrize("argv, needle", [
    (["--sigma", "joint.B.points.0.0"], "write NAME=STD"),
    (["--sigma", "joint.B.points.0.0=abc"], "write NAME=STD"),
    (["--sigma", "joint.B.point.0.0=1e-3"], "did you mean joint.B.points.0.0"),
    (["--sigma", "joint.B.points.0.0=-1e-3"], "must be >= 0"),
    (["--sigma", "joint.B.points.0.0=1e-3", "--samples", "1"], "at least 2"),
    (["--sigma", "joint.B.points.0.0=1e-3", "--point", "coupler:0"], "BODY:X,Y"),
    (["--sigma", "joint.B.points.0.0=1e-3", "--point", "ground:0,0"], "no moving body 'ground'"),
    (["--sigma", "joint.B.points.0.0=nan"], "must be finite"),
    (["--sigma", "joint.B.points.0.0=1.7e308", "--samples", "0"],
     "exceeds the floating-point range"),
])
def test_bad_input_is_refused(tmp_path: Path, capsys, argv: list[str], needle: str) -> None:
    out = tmp_path / "t.csv"
    assert main(["tolerance", FOURBAR, *argv, "--t-end", "1", "--steps", "4",
                 "--out", str(out)]) == 2
    assert needle in " ".join(capsys.readouterr().err.split())
    assert not out.exists()


def test_needs_a_span_and_a_known_suffix(tmp_path: Path, capsys) -> None:
    assert main(["tolerance", FOURBAR, "--sigma", f"{PRM}=1e-3", "--out",
                 str(tmp_path / "t.csv")]) == 2
    assert "needs --t-end and --steps" in capsys.readouterr().err
    assert main(["tolerance", FOURBAR, "--sigma", f"{PRM}=1e-3", "--t-end", "1", "--steps",
                 "4", "--out", str(tmp_path / "t.txt")]) == 2
    assert "must end in .nc or .csv" in capsys.readouterr().err


def test_monte_carlo_draws_run_in_mbd2d_solve(tmp_path: Path, capsys) -> None:
    """--export-samples writes the Monte Carlo draws as a sweep file; mbd2d-solve's CSV is
    the tolerance analysis's own sample sweep (the same draws, byte for byte), and the sample
    standard deviation taken from it is the analysis's q_std_mc."""
    import csv
    import subprocess
    from test_standalone import find_solver
    mbd = tmp_path / "mc.mbd"
    sig = {PRM: SIG, "joint.O4.points.1.0": 1e-3}
    argv = ["tolerance", FOURBAR, "--t-end", "1", "--steps", "10", "--samples", "60",
            "--seed", "3", "--export-samples", str(mbd)]
    for k, v in sig.items():
        argv += ["--sigma", f"{k}={v}"]
    assert main(argv) == 0
    assert "60 Monte Carlo variants" in capsys.readouterr().out
    out = tmp_path / "solve.csv"
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    model = mbd2d.load(FOURBAR)
    tol = mbd2d.tolerance(model, sig, samples=60, seed=3, workers=1, t_end=1.0, steps=10)
    py = tmp_path / "py.csv"
    mbd2d.write_sweep(tol.samples, py)
    assert out.read_bytes() == py.read_bytes()
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    col = rows[0].index("rocker.theta")
    x = np.array([[float(r[col]) for r in rows[1:] if r[0] == str(c)] for c in range(60)])
    np.testing.assert_allclose(x.std(axis=0, ddof=1),
                               tol.dataset.q_std_mc.sel(coordinate="rocker.theta").values,
                               rtol=1e-12, atol=0)
    assert np.array_equal(mbd2d.tolerance_samples(model, sig, 60, 3)[PRM],
                          tol.samples[PRM].values)


def test_study_files_refuse_bad_paths(tmp_path: Path) -> None:
    """A sweep or a tolerance analysis goes to .nc or .csv; a path that cannot be written
    is a ModelError naming it (the command line's exit code 2)."""
    model = mbd2d.load(FOURBAR)
    ds = mbd2d.sweep(model, {PRM: [1.7, 1.8]}, t_end=1.0, steps=4, workers=1)
    tol = mbd2d.tolerance(model, {PRM: SIG}, samples=0, t_end=1.0, steps=4)
    for write, what in ((mbd2d.write_sweep, "a sweep"),
                        (mbd2d.studies.write_tolerance, "a tolerance analysis")):
        data = ds if write is mbd2d.write_sweep else tol.dataset
        with pytest.raises(mbd2d.ModelError, match=f"{what} is written as .nc"):
            write(data, tmp_path / "x.txt")
        with pytest.raises(mbd2d.ModelError, match="cannot write"):
            write(data, tmp_path / "no" / "dir" / "x.csv")


def test_draws_beyond_the_memory_are_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """The Monte Carlo draws are checked against the memory before numpy makes them (here a
    machine of 1 MiB): an InsufficientMemoryError naming the size, not a MemoryError."""
    from mbd2d.analysis import settings
    monkeypatch.setattr(settings, "physical_memory", lambda: 2.0**20)
    model = mbd2d.load(FOURBAR)
    with pytest.raises(mbd2d.InsufficientMemoryError, match="tolerance: the run would need"):
        mbd2d.tolerance_samples(model, {PRM: SIG}, samples=100000)


def test_kinematics_of_a_model_with_masses_is_inverse_dynamics(tmp_path: Path, capsys) -> None:
    """As Model.kinematics and the sweep: a model with masses runs inverse dynamics, so the
    tolerance has the efforts too (it raised a TypeError; found by tests/test_cli_fuzz.py).
    Reference: the motor torque is linear in the coupler's mass, so its first-order standard
    deviation is |central difference of inverse-dynamics runs| x sigma."""
    heavy = EX / "fourbar_masses.toml"
    out = tmp_path / "t.csv"
    sig = 0.01
    assert main(["tolerance", str(heavy), "--sigma", f"body.coupler.mass={sig}", "--samples",
                 "0", "--t-end", "1", "--steps", "8", "--out", str(out)]) == 0
    header, rows = read_csv(out)
    model = mbd2d.load(heavy)
    m0 = model.parameters()["body.coupler.mass"]
    dm = 1e-3 * m0
    tau = [model.with_params({"body.coupler.mass": m0 + s * dm}).inverse_dynamics(1.0, 8)
           .effort("motor") for s in (1, -1)]
    np.testing.assert_allclose(rows[:, header.index("motor.effort.std_linear")],
                               np.abs(tau[0] - tau[1]) / (2 * dm) * sig, rtol=1e-7,
                               atol=1e-12)


def test_dynamics_studies_take_the_integrator(tmp_path: Path, capsys) -> None:
    """--method, --rtol, --atol and --h reach a study's dynamics: a tolerance study by
    generalized-alpha at a fixed step writes the API's own file (the same draws), and a
    sweep by it the API's sweep; a setting the method refuses is a typed error."""
    toml = EX / "pendulum_spring.toml"
    model = mbd2d.load(toml)
    kw = dict(t_end=0.5, steps=5, method="generalized-alpha", h=1e-3)
    out = tmp_path / "tol.csv"
    assert main(["tolerance", str(toml), "--sigma", "body.bar.mass=0.01", "--analysis",
                 "dynamics", "--method", "generalized-alpha", "--h", "1e-3", "--t-end", "0.5",
                 "--steps", "5", "--samples", "12", "--workers", "1", "--out", str(out)]) == 0
    tol = mbd2d.tolerance(model, {"body.bar.mass": 0.01}, "dynamics", samples=12, workers=1,
                          **kw)
    py = tmp_path / "py.csv"
    write_tolerance(tol.dataset, py)
    assert out.read_text() == py.read_text()
    sw = tmp_path / "sweep.csv"
    assert main(["sweep", str(toml), "--param", "body.bar.mass=0.8:1.2:3", "--analysis",
                 "dynamics", "--method", "generalized-alpha", "--h", "1e-3", "--t-end", "0.5",
                 "--steps", "5", "--workers", "1", "--out", str(sw)]) == 0
    ds = mbd2d.sweep(model, {"body.bar.mass": np.linspace(0.8, 1.2, 3)}, "dynamics",
                     workers=1, **kw)
    py_sw = tmp_path / "py_sweep.csv"
    write_sweep(ds, py_sw)
    assert sw.read_text() == py_sw.read_text()
    capsys.readouterr()
    assert main(["sweep", str(toml), "--param", "body.bar.mass=0.8:1.2:3", "--analysis",
                 "dynamics", "--method", "dopri5", "--h", "1e-3", "--t-end", "0.5",
                 "--steps", "5", "--workers", "1", "--out", str(sw)]) == 2
    assert "h is for" in capsys.readouterr().err


def test_modes_from_the_command_line(tmp_path: Path, capsys) -> None:
    """`--analysis modes`: one CSV row with the equilibrium's and every natural frequency's
    Monte Carlo columns (the API's, same seed), the frequencies in the summary."""
    car = str(EX / "half_car.toml")
    sig = {"force.front_tyre.stiffness": 1e4, "body.body.mass": 20.0}
    out = tmp_path / "tol.csv"
    assert main(["tolerance", car, "--analysis", "modes", "--samples", "30", "--workers", "1"]
                + [a for k, v in sig.items() for a in ("--sigma", f"{k}={v}")]
                + ["--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "natural frequencies (Hz)" in text and "mode 4" in text
    header, rows = read_csv(out)
    tol = mbd2d.tolerance(mbd2d.load(car), sig, "modes", samples=30, workers=1)
    assert rows.shape[0] == 1
    for k in range(4):
        np.testing.assert_array_equal(rows[0, header.index(f"mode{k + 1}.frequency.std_mc")],
                                      tol.dataset.frequency_std_mc.values[k])


def test_frf_from_the_command_line(tmp_path: Path, capsys) -> None:
    """`--analysis frf --input NAME --f START:STOP:NUM`: one CSV row per frequency with the
    magnitudes' and phases' Monte Carlo columns (the API's, same seed), each response's peak
    in the summary; --point is refused there, --input without --analysis frf too."""
    car = str(EX / "half_car.toml")
    sig = {"force.front_suspension.damping": 200.0, "body.body.mass": 20.0}
    inp = "force.front_tyre.points.0.1"
    out = tmp_path / "tol.csv"
    args = ["tolerance", car, "--analysis", "frf", "--input", inp, "--f", "0.5:15:12", "--log",
            "--samples", "20", "--workers", "1"] + \
        [a for k, v in sig.items() for a in ("--sigma", f"{k}={v}")]
    assert main(args + ["--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "frequency response peaks" in text and f"d(body.y)/d({inp}): |H|" in text
    header, rows = read_csv(out)
    tol = mbd2d.tolerance(mbd2d.load(car), sig, "frf", samples=20, workers=1, inputs=[inp],
                          frequencies=np.geomspace(0.5, 15, 12))
    assert rows.shape == (12, len(header))
    col = header.index(f"d(body.y)/d({inp}).abs.std_mc")
    j = list(tol.dataset.coordinate.values).index("body.y")
    np.testing.assert_array_equal(rows[:, col], tol.dataset.magnitude_std_mc.values[:, j, 0])
    assert main(args + ["--out", str(out), "--point", "body:0,0"]) == 2
    assert "--point is a scatter over time" in capsys.readouterr().err
    assert main(["tolerance", car, "--input", inp, "--sigma", "body.body.mass=1", "--out",
                 str(out)]) == 2
    assert "--analysis frf needs" in capsys.readouterr().err
