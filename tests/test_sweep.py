"""Sweeps (mbd2d.sweep): every case of a batched sweep is checked, bit for bit, against the
same variant run alone, ``model.with_params(case).<analysis>(...)`` -- the arrays, and for a
failing variant its status, its message (the text of the exception it raises alone) and the
rows it keeps. The variants are chosen so that what packing and the core derive from the
raw numbers changes with them: the length scale (a power of 2 from the largest geometry
entry), unit axes, spline coefficients, gear centres and phases from the revolutes and q0,
open rack phases. Process pools and a Dask LocalCluster must give the serial result exactly.
"""
from __future__ import annotations

import csv
import math
import subprocess
import sys
import warnings
from typing import Any

import numpy as np
import pytest

import mbd2d
from mbd2d.studies import runner

from conftest import load_example, model_from_toml
import test_contact_friction_parameters as cfp

xr = pytest.importorskip("xarray")


# ------------------------------------------------------------------ the oracle

def alone(model: mbd2d.Model, ds: Any, j: int, analysis: str, **kw: Any) -> None:
    """Case j of ds against the variant run by itself."""
    names = ds.attrs["parameters"].split(", ")
    variant = model.with_params({n: float(ds[n].values[j]) for n in names})
    st, msg = int(ds.status.values[j]), str(ds.message.values[j])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # redundancy and passage warnings
            res = getattr(variant, analysis)(**kw)
    except mbd2d.ModelError as exc:
        assert st < 0 and msg == str(exc), (j, st, msg, str(exc))
        assert np.isnan(ds.q.values[j]).all()
        return
    except mbd2d.AnalysisError as exc:
        assert (st, msg) == (exc.status, str(exc)), (j, st, msg, exc.status, str(exc))
        kept = exc.results
        n = 0 if kept is None or not hasattr(kept, "t") else len(kept.t)
        if n:
            assert np.array_equal(kept.q, ds.q.values[j, :n])
            assert np.array_equal(kept.qdd, ds.qdd.values[j, :n])
        assert np.isnan(ds.q.values[j, n:]).all()
        return
    assert (st, msg) == (0, ""), (j, st, msg)
    if analysis == "statics":
        assert np.array_equal(res.q, ds.q.values[j, 0])
        assert np.array_equal(res.lam, ds.lam.values[j, 0])
        assert ds.stability.values[j] == res.stability
        return
    for name in ("q", "qd", "qdd"):
        assert np.array_equal(getattr(res, name), ds[name].values[j]), (j, name)
    if "lam" in ds:
        assert np.array_equal(res.lam, ds.lam.values[j])
        for d in (ds.driver.values if "driver" in ds.coords else []):
            assert np.array_equal(res.effort(str(d)), ds.effort.sel(driver=d).values[j])
        assert np.array_equal(res.kinetic, ds.kinetic.values[j])


def check_all(model: mbd2d.Model, cases: Any, analysis: str = "kinematics",
              **kw: Any) -> Any:
    ds = mbd2d.sweep(model, cases, analysis, workers=1, **kw)
    for j in range(ds.sizes["case"]):
        alone(model, ds, j, analysis, **kw)
    return ds


# ------------------------------------------------------------------ bit for bit, per analysis

def test_fourbar_kinematics_dead_centres_and_length_scale() -> None:
    """Coupler lengths from dead centres through Grashof to no assembly, and a ground link
    whose length moves the model's length scale from 2 to 4."""
    m = load_example("fourbar_grashof.toml")
    cases = mbd2d.grid({"joint.B.points.0.0": [-0.6, 1.2, 1.75, 4.05],
                        "joint.O4.points.1.0": [3.0, 4.3]})
    ds = check_all(m, cases, t_end=1.0, steps=40)
    assert ds.q.dims == ("case", "time", "coordinate")
    assert ds.sizes["case"] == 8 and set(ds.status.values) >= {0, 3}
    assert ds.attrs["failed"] == int((ds.status.values != 0).sum())
    dead = int(np.flatnonzero(ds.status.values == 3)[0])
    assert "dead centre" in str(ds.message.values[dead])
    assert 0 < np.isfinite(ds.q.values[dead, :, 0]).sum() < 41   # rows up to the failure


def test_slider_crank_axes_and_offset() -> None:
    """Translational axes (normalised in the core) and the guide offset."""
    m = load_example("slider_crank.toml")
    cases = {"joint.guide.axes.0.0": [1.0, 2.0, 0.7], "joint.guide.axes.0.1": [0.0, 0.1, -0.2],
             "joint.guide.points.0.1": [0.5, 0.45, 0.6], "joint.A.points.1.0": [-1.5, -1.6, -1.4]}
    check_all(m, cases, t_end=0.5, steps=20, every=3)


def test_cam_profiles_circle_and_spline() -> None:
    """A circle cam (centre, radius, roller) and a spline cam (its points: the spline
    coefficients are rebuilt per case)."""
    m = load_example("cam_follower.toml")
    check_all(m, {"joint.contact.profile.circle.radius": [1.0, 1.1, 0.9],
                  "joint.contact.profile.circle.center.0": [0.4, 0.3, 0.45],
                  "joint.contact.follower.roller.radius": [0.25, 0.2, 0.3]},
              t_end=1.0, steps=16)
    pts = [[0.4 + math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 9)[:-1]]
    spline = model_from_toml(f"""
[[body]]
name = "cam"
q0 = [0, 0, 0]
[[body]]
name = "follower"
q0 = [0, 1.2, 0]
[[joint]]
type = "revolute"
bodies = ["ground", "cam"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "translational"
bodies = ["ground", "follower"]
points = [[0, 0], [0, 0]]
axes = [[0, 1], [0, 1]]
[[joint]]
name = "contact"
type = "cam"
bodies = ["cam", "follower"]
profile = {{ spline = {{ points = {pts} }} }}
follower = {{ roller = {{ center = [0, 0], radius = 0.25 }} }}
[[driver]]
type = "absolute"
body = "cam"
coordinate = "theta"
f = {{ poly = [0, 6.283185307179586] }}
""")
    check_all(spline, {"joint.contact.profile.spline.points.2.1": [pts[2][1], 1.1, 0.9],
                       "joint.contact.profile.spline.points.5.0": [pts[5][0], -0.4, -0.7]},
              t_end=1.0, steps=16)


def gear_pair() -> mbd2d.Model:
    """A pinion driven at constant acceleration meshing with a wheel on a ground pivot,
    masses and gravity; the gear's centres come from the revolutes, its phase from q0."""
    m = mbd2d.Model("pair", gravity=(0.0, -9.81))
    m.add_body("pinion", (0.0, 0.0, 0.0), mass=1.0, inertia=0.02)
    m.add_body("wheel", (2.0, 0.0, 0.3), mass=3.0, inertia=0.5)
    m.add_revolute(["ground", "pinion"], [[0.0, 0.0], [0.0, 0.0]], name="O1")
    m.add_revolute(["ground", "wheel"], [[2.0, 0.0], [0.0, 0.0]], name="O2")
    m.add_gear(["pinion", "wheel"], [0.5, 1.5], name="mesh")
    m.add_driver("absolute", body="pinion", coordinate="theta", f={"poly": [0.0, 0.0, 1.5]},
                 name="motor")
    return m


def test_gear_pair_inverse_dynamics() -> None:
    """Radii (and the open phase from q0 with them), the wheel's pivot (the gear centres
    are taken from it), masses, inertia, gravity, the pressure angle."""
    m = gear_pair()
    cases = {"joint.mesh.radii.0": [0.5, 0.6, 0.45, 0.5],
             "joint.mesh.radii.1": [1.5, 1.4, 1.55, 1.5],
             "joint.O2.points.0.0": [2.0, 2.0, 2.0, 2.1],
             "joint.O2.points.1.1": [0.0, 0.01, 0.0, 0.0],
             "body.wheel.mass": [3.0, 2.5, 4.0, 3.0],
             "body.pinion.inertia": [0.02, 0.03, 0.01, 0.02],
             "model.gravity.1": [-9.81, -1.6, 0.0, -9.81],
             "joint.mesh.pressure_angle": [0.35, 0.3, 0.0, 0.25]}
    ds = check_all(m, cases, "inverse_dynamics", t_end=0.5, steps=10)
    assert list(ds.driver.values) == ["motor"] and ds.lam.dims == ("case", "time", "equation")
    # and "kinematics" of a model with masses is inverse dynamics, as Model.kinematics
    ds2 = mbd2d.sweep(m, cases, t_end=0.5, steps=10, workers=1)
    assert ds2.attrs["run"] == "inverse" and ds2.identical(ds.assign_attrs(
        analysis="kinematics", settings=ds2.attrs["settings"]))


RACK = """
[[body]]
name = "pinion"
q0 = [0, 0, 0.2]
[[body]]
name = "rack"
q0 = [0.1, -0.3, 0]
[[joint]]
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
type = "translational"
bodies = ["ground", "rack"]
points = [[0, -0.3], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
name = "rp"
type = "rack-pinion"
bodies = ["pinion", "rack"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = 0.3
[[driver]]
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { poly = [0.2, 6.283185307179586] }
"""


def test_rack_pinion_open_phase() -> None:
    """A rack-pinion whose phase is left open: the core sets it again per case from q0."""
    m = model_from_toml(RACK)
    ds = check_all(m, {"joint.rp.radius": [0.3, 0.35, 0.25],
                       "joint.rp.point.0": [0.0, 0.05, -0.1]}, t_end=0.5, steps=10)
    x = ds.q.sel(coordinate="rack.x").values
    assert not np.allclose(x[0], x[1])
    # the phase itself swept: no longer open
    check_all(m, {"joint.rp.phase": [0.0, 0.01], "joint.rp.radius": [0.3, 0.31]},
              t_end=0.5, steps=10)


def test_statics_pendulum_spring() -> None:
    m = load_example("pendulum_spring.toml")
    cases = {"force.torsion.stiffness": [10.0, 20.0, 5.0, 0.0],
             "body.bar.mass": [1.0, 2.0, 0.5, 1.0], "model.gravity.1": [-9.81, -9.81, -3.0, 0.0],
             "joint.pivot.points.1.0": [-0.5, -0.6, -0.4, -0.5]}
    ds = check_all(m, cases, "statics", t=0.0)
    assert ds.sizes["time"] == 1 and ds.stability.values[0] == "stable"
    assert ds.stability.values[3] == "neutral"              # no stiffness, no gravity


@pytest.mark.parametrize("method, extra", [("dopri5", {}),
                                           ("generalized-alpha", {"h": 1e-3})])
def test_dynamics_pendulum_spring(method: str, extra: dict) -> None:
    m = load_example("pendulum_spring.toml")
    cases = {"force.torsion.stiffness": [10.0, 30.0, 2.0],
             "body.bar.inertia": [0.0833, 0.2, 0.05], "force.torsion.damping": [0.0, 0.5, 1.0]}
    check_all(m, cases, "dynamics", t_end=0.5, steps=10, method=method, **extra)


# ------------------------------------------------------------------ failures and inputs

def test_bad_variant_is_reported_not_raised() -> None:
    """A variant the core refuses (a zero axis) keeps the sweep going; its message is the
    ModelError it raises alone."""
    m = load_example("slider_crank.toml")
    ds = check_all(m, {"joint.guide.axes.0.0": [1.0, 0.0], "joint.guide.axes.0.1": [0.0, 0.0]},
                   t_end=0.5, steps=5)
    assert ds.status.values[0] == 0 and ds.status.values[1] < 0
    assert "guide" in str(ds.message.values[1])


@pytest.mark.parametrize("cases, match", [
    ({"joint.B.points.0.9": [1.0]}, "did you mean joint.B.points"),
    ({"joint.B.points.0.0": [1.0, 2.0], "joint.A.points.0.0": [0.5]}, "one value per case"),
    ({"joint.B.points.0.0": [1.0, float("nan")]}, "not a finite number in case 1"),
    ({"joint.B.points.0.0": []}, "non-empty"),
    ({"joint.B.points.0.0": [[1.0]]}, "1-D"),
    ({"joint.B.points.0.0": ["a"]}, "numbers"),
    ({}, "dict"), ([1.0, 2.0], "dict"), ({1: [1.0]}, "not a parameter name")])
def test_bad_case_tables(cases: Any, match: str) -> None:
    m = load_example("fourbar_grashof.toml")
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.sweep(m, cases, t_end=1.0, steps=4)


@pytest.mark.parametrize("analysis, kw, match", [
    ("kinematic", {"t_end": 1.0, "steps": 4}, "unknown analysis"),
    ("kinematics", {"t_end": 1.0}, "steps"),
    ("kinematics", {"t_end": 1.0, "steps": 4, "rtol": 1e-6}, "the settings are"),
    ("kinematics", {"t_end": 1.0, "steps": 4, "sensitivities": ["x"]}, "unknown parameter"),
    ("kinematics", {"t_end": -1.0, "steps": 4}, "greater than t0"),
    ("kinematics", {"t_end": 1.0, "steps": 4, "solver": "lu"}, "unknown solver"),
    ("dynamics", {"t_end": 1.0, "steps": 4}, "mass"),
    ("statics", {"t": float("inf")}, "finite")])
def test_bad_settings(analysis: str, kw: dict, match: str) -> None:
    m = load_example("fourbar_grashof.toml")
    with pytest.raises(mbd2d.ModelError, match=match):
        mbd2d.sweep(m, {"joint.B.points.0.0": [1.75]}, analysis, **kw)


def test_dynamics_settings_checked_as_the_front_door() -> None:
    m = load_example("pendulum_spring.toml")
    for kw, match in (({"method": "euler"}, "unknown method"),
                      ({"method": "baumgarte-rk4"}, "fixed-step"),
                      ({"h": 1e-3}, "chooses its own steps"), ({"max_steps": 0}, "max_steps")):
        with pytest.raises(mbd2d.ModelError, match=match):
            mbd2d.sweep(m, {"body.bar.mass": [1.0]}, "dynamics", t_end=1.0, steps=4, **kw)
    with pytest.raises(mbd2d.ModelError, match="workers"):
        mbd2d.sweep(m, {"body.bar.mass": [1.0]}, "statics", workers=0)
    with pytest.raises(mbd2d.ModelError, match="progress"):
        mbd2d.sweep(m, {"body.bar.mass": [1.0]}, "statics", progress="yes")
    with pytest.raises(mbd2d.ModelError, match="distributed.Client"):
        mbd2d.sweep(m, {"body.bar.mass": [1.0]}, "statics", client=object())
    with pytest.raises(mbd2d.ModelError, match="needs a model"):
        mbd2d.sweep("model.toml", {"body.bar.mass": [1.0]}, "statics")


def test_dataframe_and_grid() -> None:
    pd = pytest.importorskip("pandas")
    m = load_example("fourbar_grashof.toml")
    g = mbd2d.grid({"joint.B.points.0.0": [1.7, 1.8], "joint.O4.points.1.0": [2.9, 3.0, 3.1]})
    assert g["joint.B.points.0.0"].tolist() == [1.7] * 3 + [1.8] * 3
    assert g["joint.O4.points.1.0"].tolist() == [2.9, 3.0, 3.1] * 2
    a = mbd2d.sweep(m, g, t_end=1.0, steps=5, workers=1)
    b = mbd2d.sweep(m, pd.DataFrame(g), t_end=1.0, steps=5, workers=1)
    assert a.identical(b)
    with pytest.raises(mbd2d.ModelError, match="grid"):
        mbd2d.grid([1, 2])


def test_missing_extra_names_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "xarray", None)
    m = load_example("fourbar_grashof.toml")
    with pytest.raises(ImportError, match=r"mbd2d\[sweep\]"):
        mbd2d.sweep(m, {"joint.B.points.0.0": [1.75]}, t_end=1.0, steps=4)
    with pytest.raises(ImportError, match=r"mbd2d\[sweep\]"):
        mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, t_end=1.0, steps=4)


def test_import_does_not_load_the_extras() -> None:
    code = ("import sys, mbd2d; bad = [m for m in ('xarray', 'dask', 'distributed', 'pandas', "
            "'tqdm') if m in sys.modules]; print(bad); sys.exit(1 if bad else 0)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


# ------------------------------------------------------------------ where the cases run

def fourbar_cases(n: int) -> dict[str, np.ndarray]:
    return {"joint.B.points.0.0": np.linspace(-0.7, 4.2, n),
            "joint.A.points.0.0": np.linspace(0.45, 0.55, n)}


#: the cases' measures and sensitivities travel with them
EXTRAS = dict(measures=["transmission_angle:B", "dead_centre_distance",
                        "velocity_ratio:motor:rocker.theta"],
              sensitivities=["joint.O4.points.1.0"])         # (and so dmeasures_dp)


def test_process_pool_gives_the_serial_result(monkeypatch: pytest.MonkeyPatch) -> None:
    m = load_example("fourbar_grashof.toml")
    cases = fourbar_cases(23)
    serial = mbd2d.sweep(m, cases, t_end=1.0, steps=30, workers=1, **EXTRAS)
    monkeypatch.setattr(runner, "POOL_MIN_SECONDS", 0.0)
    monkeypatch.setattr(runner, "PROBE_SECONDS", 0.0)
    pooled = mbd2d.sweep(m, cases, t_end=1.0, steps=30, workers=2, **EXTRAS)
    assert serial.identical(pooled)
    assert (serial.status.values != 0).any() and (serial.status.values == 0).any()


def test_dask_local_cluster_gives_the_serial_result() -> None:
    distributed = pytest.importorskip("distributed")
    m = load_example("fourbar_grashof.toml")
    cases = fourbar_cases(17)
    serial = mbd2d.sweep(m, cases, t_end=1.0, steps=30, workers=1, **EXTRAS)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        remote = mbd2d.sweep(m, cases, client=client, t_end=1.0, steps=30, **EXTRAS)
        tol = mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, client=client, samples=20,
                              t_end=1.0, steps=30)
        local = mbd2d.tolerance(m, {"joint.B.points.0.0": 1e-3}, samples=20, workers=1,
                                t_end=1.0, steps=30)
        # joint friction's and a contact's numbers as swept parameters, on the cluster too
        incline = cfp.incline()
        fric = {"joint.slide.friction.mu": [0.0, 0.1, 0.2, 0.3],
                "joint.slide.friction.mu_static": [0.0, 0.15, 0.25, 0.5]}
        fkw = {"analysis": "dynamics", "t_end": 0.5, "steps": 5, "rtol": 1e-9, "atol": 1e-11}
        fric_remote = mbd2d.sweep(incline, fric, client=client, **fkw)
        # a modes sweep (the half car's struts' damping) on the cluster too
        car = load_example("half_car.toml")
        damping = {"force.front_suspension.damping": np.linspace(0.0, 3000.0, 9),
                   "force.rear_suspension.damping": np.linspace(3000.0, 0.0, 9)}
        modes_remote = mbd2d.sweep(car, damping, "modes", client=client)
        # and its frequency response to a road rise under the front wheel
        road = {"inputs": ["force.front_tyre.points.0.1"], "frequencies": [0.5, 1.2, 8.0]}
        frf_remote = mbd2d.sweep(car, damping, "frf", client=client, **road)
    assert mbd2d.sweep(car, damping, "modes", workers=1).identical(modes_remote)
    assert mbd2d.sweep(car, damping, "frf", workers=1, **road).identical(frf_remote)
    assert serial.identical(remote)
    assert tol.dataset.identical(local.dataset)
    assert mbd2d.sweep(incline, fric, workers=1, **fkw).identical(fric_remote)


def test_back_to_back_dask_sweeps_of_one_model() -> None:
    """Sweeps of the same model one right after another on one client (as a benchmark or a
    notebook does): each shares the model under a key of its own; with the content's hash
    as the key, about one in four of them was cancelled for 'lost dependencies' while the
    scheduler released the previous sweep's copy."""
    distributed = pytest.importorskip("distributed")
    m = load_example("fourbar_grashof.toml")
    cases = {"joint.B.points.0.0": np.linspace(1.6, 1.9, 1000)}
    kw = {"t_end": 1.0, "steps": 400, "every": 50, "progress": False}
    serial = mbd2d.sweep(m, cases, workers=1, **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                      dashboard_address=":0") as cluster, \
                distributed.Client(cluster) as client:
            runs = [mbd2d.sweep(m, cases, client=client, **kw) for _ in range(8)]
    assert all(serial.identical(r) for r in runs)


def test_chunks_cover_the_cases() -> None:
    for n, parts in ((1, 8), (10, 3), (23, 8), (5, 50)):
        c = runner.chunks(2, 2 + n, parts)
        assert c[0][0] == 2 and c[-1][1] == 2 + n and len(c) <= parts
        assert all(a < z and z == c[k + 1][0] for k, (a, z) in enumerate(c[:-1]))


def test_progress_bar(capsys: pytest.CaptureFixture) -> None:
    pytest.importorskip("tqdm")
    m = load_example("fourbar_grashof.toml")
    mbd2d.sweep(m, fourbar_cases(6), t_end=1.0, steps=5, workers=1, progress=True)
    assert "case" in capsys.readouterr().err
    mbd2d.sweep(m, fourbar_cases(6), t_end=1.0, steps=5, workers=1, progress=False)
    mbd2d.sweep(m, fourbar_cases(6), t_end=1.0, steps=5, workers=1)   # fast: no bar
    assert capsys.readouterr().err == ""


# ------------------------------------------------------------------ files and command line

def test_netcdf_and_csv(tmp_path: Any) -> None:
    pytest.importorskip("h5netcdf")
    m = load_example("fourbar_grashof.toml")
    ds = mbd2d.sweep(m, fourbar_cases(5), t_end=1.0, steps=4, workers=1)
    mbd2d.write_sweep(ds, tmp_path / "s.nc")
    back = xr.load_dataset(tmp_path / "s.nc")
    assert np.array_equal(back.q.values, ds.q.values, equal_nan=True)
    assert list(back.message.values) == list(ds.message.values)
    assert np.array_equal(back["joint.B.points.0.0"].values, ds["joint.B.points.0.0"].values)
    mbd2d.write_sweep(ds, tmp_path / "s.csv")
    with open(tmp_path / "s.csv", newline="") as f:
        head, *rows = list(csv.reader(f))
    assert head[:6] == ["case", "joint.B.points.0.0", "joint.A.points.0.0", "t", "status",
                        "message"]
    assert "rocker.theta_ddot" in head
    kept = [int(np.isfinite(ds.q.values[c, :, 0]).sum()) or 1 for c in range(5)]
    assert len(rows) == sum(kept)             # the rows each case kept (a case with none: 1)
    assert float(rows[0][head.index("crank.theta")]) == ds.q.values[0, 0, 2]
    last = [r for r in rows if int(r[0]) == 4]
    assert [int(r[4]) for r in last] == [int(ds.status.values[4])] * len(last)
    assert last[0][5] == ds.message.values[4]
    with pytest.raises(mbd2d.ModelError, match=".nc"):
        mbd2d.write_sweep(ds, tmp_path / "s.txt")


def test_cli_sweep(tmp_path: Any, capsys: pytest.CaptureFixture) -> None:
    from mbd2d.cli import main
    model = str(load_example_path("fourbar_grashof.toml"))
    out = tmp_path / "s.csv"
    assert main(["sweep", model, "--param", "joint.B.points.0.0=1.6:1.9:3", "--param",
                 "joint.O4.points.1.0=2.9:3.1:2", "--grid", "--t-end", "1", "--steps", "4",
                 "--out", str(out), "--workers", "1"]) == 0
    with open(out, newline="") as f:
        text = list(csv.reader(f))
    assert len(text) == 1 + 6 * 5
    m = load_example("fourbar_grashof.toml")
    ds = mbd2d.sweep(m, mbd2d.grid({"joint.B.points.0.0": np.linspace(1.6, 1.9, 3),
                                    "joint.O4.points.1.0": np.linspace(2.9, 3.1, 2)}),
                     t_end=1.0, steps=4, workers=1)
    last = text[-1]
    assert float(last[-1]) == ds.qdd.values[-1, -1, -1]
    nc = tmp_path / "s.nc"
    assert main(["sweep", model, "--param", "joint.B.points.0.0=1.6:1.9:3", "--param",
                 "joint.A.points.0.0=0.4:0.6:3", "--t-end", "1", "--steps", "4",
                 "--out", str(nc)]) == 0
    assert xr.load_dataset(nc).sizes["case"] == 3
    capsys.readouterr()
    for bad in (["--param", "joint.B.points.0.0=1.6:1.9"],
                ["--param", "joint.B.points.0.0=1.6:1.9:3", "--param",
                 "joint.A.points.0.0=0.4:0.6:2"],
                ["--param", "joint.B.points.0.9=1.6:1.9:3"],
                ["--param", "joint.B.points.0.0=1.6:1.9:0"]):
        assert main(["sweep", model, *bad, "--t-end", "1", "--steps", "4",
                     "--out", str(out)]) == 2
        assert "mbd2d:" in capsys.readouterr().err
    assert main(["sweep", model, "--param", "joint.B.points.0.0=1:2:2", "--steps", "4",
                 "--out", str(out)]) == 2
    assert main(["sweep", model, "--param", "joint.B.points.0.0=1:2:2", "--t-end", "1",
                 "--steps", "4", "--out", str(out), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    assert "cannot reach the Dask scheduler" in capsys.readouterr().err
    assert main(["sweep", model, "--param", "joint.B.points.0.0=1:2:2", "--t-end", "1",
                 "--steps", "4", "--out", str(tmp_path / "s.txt")]) == 2


def load_example_path(name: str) -> Any:
    from conftest import example_path
    return example_path(name)


# ------------------------------------------------------------------ hostile values

HOSTILE = [1e300, -1e300, 0.0, 1e-300, 5e-324, 1e15, -1e15, 1e-12]


@pytest.mark.parametrize("example, name, analysis, kw", [
    ("fourbar_grashof.toml", "joint.B.points.0.0", "kinematics", {}),
    ("fourbar_grashof.toml", "joint.O4.points.1.0", "kinematics", {}),
    ("fourbar_grashof.toml", "driver.motor.f.poly.1", "kinematics", {}),
    ("slider_crank.toml", "joint.guide.axes.0.1", "kinematics", {}),
    ("cam_follower.toml", "joint.contact.profile.circle.radius", "kinematics", {}),
    ("pendulum_spring.toml", "force.torsion.stiffness", "statics", {}),
    ("pendulum_spring.toml", "body.bar.inertia", "dynamics", {"max_steps": 20000}),
    (None, "joint.mesh.radii.0", "inverse_dynamics", {}),
    (None, "body.wheel.mass", "inverse_dynamics", {}),
    (None, "model.gravity.1", "dynamics", {"max_steps": 20000})])
def test_hostile_values(example: str | None, name: str, analysis: str, kw: dict) -> None:
    """Huge, tiny, zero and subnormal values: every variant gives a status and what it
    gives alone (a typed error or a finite result), and the sweep goes on."""
    m = gear_pair() if example is None else load_example(example)
    t = {} if analysis == "statics" else {"t_end": 0.5, "steps": 5}
    ds = check_all(m, {name: HOSTILE}, analysis, **t, **kw)
    q = ds.q.values
    ok = ds.status.values == 0
    assert np.isfinite(q[ok]).all()
    assert all(m for m, s in zip(ds.message.values, ds.status.values) if s != 0)


def test_a_bad_mass_names_the_body() -> None:
    """The core's code of a bad body in a dynamic build names that body (it named no entry
    and failed with an IndexError in inverse dynamics)."""
    m = gear_pair().with_params({"body.wheel.mass": -1.0})
    for run in (lambda: m.inverse_dynamics(0.5, 5), lambda: m.dynamics(0.5, 5), m.statics):
        with pytest.raises(mbd2d.ModelError, match="body 'wheel'.*finite and >= 0"):
            run()


def test_too_large_a_sweep_is_refused_before_it_runs() -> None:
    m = load_example("fourbar_grashof.toml")
    with pytest.raises(mbd2d.InsufficientMemoryError, match="sweep"):
        mbd2d.sweep(m, {"joint.B.points.0.0": np.full(10**6, 1.75)}, t_end=1.0, steps=10**5)
