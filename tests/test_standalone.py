"""The standalone executable mbd2d-solve reproduces the Python path from an exported file."""
from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import warnings

import numpy as np
import pytest

import mbd2d
from mbd2d.description import joints as J
from mbd2d.description.contacts import CONTACT_TYPES
from mbd2d.description.forces import FORCE_KEYS
from mbd2d.results import read_csv

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"


def find_solver() -> str:
    """mbd2d-solve from PATH, next to this Python, or a build directory of the checkout."""
    candidates = [shutil.which("mbd2d-solve"), str(Path(sys.executable).parent / "mbd2d-solve")]
    candidates += [str(p) for p in sorted(ROOT.glob("build*/mbd2d-solve"))]
    for c in candidates:
        if c and os.access(c, os.X_OK):
            return c
    raise AssertionError("mbd2d-solve not found: `pip install .` installs it next to `mbd2d`")


def solve_file(mbd: Path, out: Path) -> str:
    """Run mbd2d-solve on the file mbd, writing out; the CSV's text (the run must succeed)."""
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    return out.read_text()


@pytest.fixture(scope="module")
def solver() -> str:
    return find_solver()


@pytest.mark.parametrize("name", ["fourbar_grashof", "slider_crank", "cam_follower"])
def test_matches_python(tmp_path: Path, solver: str, name: str) -> None:
    model = mbd2d.load(EX / f"{name}.toml")
    mbd = tmp_path / f"{name}.mbd"
    model.export(mbd, t_end=1.0, steps=200)
    out = tmp_path / "fortran.csv"
    r = subprocess.run([solver, str(mbd), str(out)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    res = model.kinematics(t_end=1.0, steps=200)
    py = tmp_path / "python.csv"
    res.to_csv(py)
    hf, rf = read_csv(out)
    hp, rp = read_csv(py)
    assert hf == hp
    assert rf.shape == rp.shape == (201, 1 + 9 * len(model.bodies))
    np.testing.assert_allclose(rf, rp, rtol=0, atol=1e-12)


def test_toggle_partial_output(tmp_path: Path, solver: str) -> None:
    model = mbd2d.load(EX / "fourbar_seed.toml")
    mbd = tmp_path / "seed.mbd"
    model.export(mbd, t_end=1.0, steps=1000)
    out = tmp_path / "seed.csv"
    r = subprocess.run([solver, str(mbd), str(out)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 3
    assert "Singular configuration (dead centre) at t = 0.88591864" in r.stderr
    assert '"motor"' in r.stderr
    _, rows = read_csv(out)
    with pytest.raises(mbd2d.SingularConfigurationError) as err:
        model.kinematics(t_end=1.0, steps=1000)
    res = err.value.results
    assert rows.shape[0] == len(res.t) == 886
    np.testing.assert_allclose(rows[:, 1:4], res.q[:, 0:3], rtol=0, atol=1e-12)


def test_file_is_documented(tmp_path: Path) -> None:
    mbd = tmp_path / "m.mbd"
    mbd2d.load(EX / "cam_follower.toml").export(mbd, t_end=1.0, steps=10)
    text = mbd.read_text()
    assert text.startswith("# mbd2d model file, format 3")
    for key in ("bodies", "constraints", "params", "KIND (joints): 1 revolute", "end"):
        assert key in text


@pytest.mark.parametrize("content, needle", [
    ("hello\n", "not an mbd2d model file"),
    ("mbd2d 1\nbodies 1\nb 0 0 0\nconstraints 1\nc 999 1 0 0 0 1 0\nparams 0\nend\n",
     "unknown constraint kind"),
    ("mbd2d 1\nbodies 1\nb 0 0\n", "bad body line"),
    ("mbd2d 1\nbodies 1\nb 0 0 0\n", 'missing "end"'),
])
def test_bad_files(tmp_path: Path, solver: str, content: str, needle: str) -> None:
    f = tmp_path / "bad.mbd"
    f.write_text(content)
    r = subprocess.run([solver, str(f), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2
    assert needle in r.stderr


def test_missing_file(tmp_path: Path, solver: str) -> None:
    r = subprocess.run([solver, str(tmp_path / "none.mbd"), str(tmp_path / "o.csv")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "cannot open" in r.stderr


# ----------------------------------------------------------------------------- every analysis
from mbd2d.analysis.mbdfile import (DRIVER_KINDS, ELEMENT_KINDS, FORCE_KINDS,  # noqa: E402
                                    JOINT_KINDS)

ALL = ["energy", "multipliers", "reactions", "efforts"]


def solve_and_compare(tmp_path: Path, exe: str, model: mbd2d.Model, py_result,
                      name: str, **export) -> str:
    """Export, run mbd2d-solve, and compare its CSV with the Python result's: the same
    header, the same numbers to 1e-12 (relative, with an absolute floor of 1e-12 times the
    column's largest value) and, as both write '%.16e', the same text. Returns the CSV."""
    mbd = tmp_path / f"{name}.mbd"
    model.export(mbd, **export)
    out = tmp_path / f"{name}_solve.csv"
    r = subprocess.run([exe, str(mbd), str(out)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    py = tmp_path / f"{name}_python.csv"
    py_result.to_csv(py, **{k: True for k in export.get("outputs") or []})
    hf, rf = read_csv(out)
    hp, rp = read_csv(py)
    assert hf == hp
    assert rf.shape == rp.shape
    scale = np.maximum(np.abs(rp).max(axis=0), 1.0)
    np.testing.assert_allclose(rf, rp, rtol=1e-12, atol=0)
    assert np.all(np.abs(rf - rp) <= 1e-12 * scale)
    assert out.read_text() == py.read_text()
    return out.read_text()


@pytest.mark.parametrize("name, every, solver_name", [("fourbar_grashof", 1, "dense"),
                                                      ("cam_follower", 7, "auto"),
                                                      ("door_two_hinges", 3, "auto")])
def test_kinematics_settings(tmp_path: Path, solver: str, name: str, every: int,
                             solver_name: str) -> None:
    model = mbd2d.load(EX / f"{name}.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.RedundantConstraintWarning)
        res = model.kinematics(t_end=1.0, steps=100, every=every, solver=solver_name)
    solve_and_compare(tmp_path, solver, model, res, name, t_end=1.0, steps=100, every=every,
                      solver=solver_name)


def test_inverse_dynamics_every_column(tmp_path: Path, solver: str) -> None:
    model = mbd2d.load(EX / "fourbar_masses.toml")
    res = model.inverse_dynamics(t_end=1.0, steps=120, every=2)
    text = solve_and_compare(tmp_path, solver, model, res, "inverse", t_end=1.0, steps=120,
                             every=2, analysis="inverse-dynamics", outputs=ALL)
    assert "motor.effort" in text.splitlines()[0] and "lambda.O2.x" in text.splitlines()[0]


@pytest.mark.parametrize("method, settings", [
    ("dopri5", {"rtol": 1e-9, "atol": 1e-10}),
    ("dopri5", {}),
    ("generalized-alpha", {"h": 2e-3, "rho_inf": 0.6}),
    ("generalized-alpha", {"rtol": 1e-5, "atol": 1e-7, "rho_inf": 0.8}),
    ("baumgarte-rk4", {"h": 1e-3, "alpha": 5.0, "beta": 8.0}),
    ("partitioned", {"rtol": 1e-8, "atol": 1e-9, "max_steps": 10**6}),
])
def test_dynamics_each_method(tmp_path: Path, solver: str, method: str, settings: dict) -> None:
    """A free four-bar with a spring (no driver) and a driven one with masses."""
    sys.path.insert(0, str(EX))
    import free_fourbar

    for k, model in enumerate((free_fourbar.build(), mbd2d.load(EX / "fourbar_masses.toml"))):
        res = model.dynamics(t_end=1.0, steps=50, method=method, **settings)
        solve_and_compare(tmp_path, solver, model, res, f"dyn{k}", t_end=1.0, steps=50,
                          analysis="dynamics", method=method, outputs=ALL, **settings)


def test_statics_and_the_number_format(tmp_path: Path, solver: str) -> None:
    """Statics with its columns; the time column carries numbers whose text shows the format
    of both writers: three-digit exponents, a subnormal, the largest double, minus zero."""
    model = mbd2d.load(EX / "pendulum_spring.toml")
    firsts = []
    for k, t in enumerate([0.0, 1e-200, 5e-324, 1.7976931348623157e308, -0.0, 1e150]):
        res = model.statics(t=t)
        text = solve_and_compare(tmp_path, solver, model, res, f"statics{k}",
                                 analysis="statics", t=t,
                                 outputs=["multipliers", "reactions", "efforts"])
        firsts.append(text.splitlines()[1].split(",")[0])
        assert float(firsts[-1]) == t
    assert firsts[0] == "0.0000000000000000e+00" and firsts[4] == "-0.0000000000000000e+00"
    assert re.fullmatch(r"\d\.\d{16}e-\d{3}", firsts[1]), firsts[1]     # 3-digit exponents
    assert firsts[2] == "4.9406564584124654e-324"                      # the smallest subnormal
    assert firsts[3] == "1.7976931348623157e+308"


def test_partial_results_of_every_analysis_match(tmp_path: Path, solver: str) -> None:
    """The seed four-bar with masses stops at its toggle: inverse dynamics writes the rows up
    to there in both paths (exit code 3)."""
    text = (EX / "fourbar_seed.toml").read_text()
    for b in ("crank", "coupler", "rocker"):
        text = text.replace(f'name = "{b}"\n', f'name = "{b}"\nmass = 1.0\ninertia = 0.1\n')
    model = mbd2d.loads(text)
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        model.inverse_dynamics(t_end=1.0, steps=200)
    mbd = tmp_path / "seed.mbd"
    model.export(mbd, t_end=1.0, steps=200, analysis="inverse-dynamics", outputs=ALL)
    out = tmp_path / "seed.csv"
    r = subprocess.run([solver, str(mbd), str(out)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 3 and "dead centre" in r.stderr
    py = tmp_path / "py.csv"
    info.value.results.to_csv(py, **{k: True for k in ALL})
    assert out.read_text() == py.read_text()


def contact_models() -> list[tuple[str, mbd2d.Model]]:
    """A cam whose follower lifts off (follower-profile contact), a ball bouncing on the floor
    and against a wall disc (circle-line, circle-circle, contact friction), a pin with
    clearance (circle-in-circle), a pendulum with a rubbing pin and a block on a rough guide
    (joint friction, stick-slip and regularized)."""
    law = {"model": "hunt-crossley", "stiffness": 1e6, "restitution": 0.8}
    ball = mbd2d.Model("ball")
    ball.add_body("ball", q0=[0.0, 0.3, 0.0], mass=1.0, inertia=0.004, v0=[1.0, 0.0, 0.0])
    ball.add_body("disc", q0=[0.6, 0.1, 0.0], mass=2.0, inertia=0.02)
    ball.add_contact("circle-line", ["ball", "ground"], name="floor",
                     circle={"center": [0, 0], "radius": 0.1},
                     line={"point": [0, 0], "normal": [0, 1]}, law=law,
                     friction={"mu": 0.3})
    ball.add_contact("circle-circle", ["ball", "disc"], name="hit",
                     circle=[{"center": [0, 0], "radius": 0.1},
                             {"center": [0, 0], "radius": 0.1}], law=law)
    ball.add_contact("circle-line", ["disc", "ground"], name="rest",
                     circle={"center": [0, 0], "radius": 0.1},
                     line={"point": [0, 0], "normal": [0, 1]}, law=law)
    pin = mbd2d.Model("clearance")
    pin.add_body("arm", q0=[0.5, 0.0, 0.0], mass=1.0, inertia=0.02)
    pin.add_contact("circle-in-circle", ["arm", "ground"], name="pin",
                    circle=[{"center": [-0.5, 0.0], "radius": 0.02},
                            {"center": [0.0, 0.0], "radius": 0.021}], law=law)
    pend = mbd2d.Model("rubbing")
    pend.add_body("bob", q0=[0.5 * math.sin(1.0), -0.5 * math.cos(1.0), 1.0], mass=1.0,
                  inertia=0.0)
    pend.add_revolute(["ground", "bob"], [[0, 0], [0, 0.5]], name="pin",
                      friction={"mu": 0.3, "mu_static": 0.35, "pin_radius": 0.05,
                                "model": "stick-slip"})
    block = mbd2d.Model("guide")
    block.add_body("block", q0=[0.0, 0.0, 0.0], mass=2.0, inertia=0.1, v0=[1.0, 0.0, 0.0])
    block.add_translational(["ground", "block"], [[0, 0], [0, 0]], [[1, 0], [1, 0]],
                            name="slide", friction={"mu": 0.2})
    return [("cam", mbd2d.load(EX / "cam_liftoff.toml")), ("ball", ball), ("pin", pin),
            ("pendulum", pend), ("block", block)]


@pytest.mark.parametrize("k", range(5))
def test_contacts_and_friction_run_in_mbd2d_solve(tmp_path: Path, solver: str, k: int) -> None:
    """Every contact type and joint friction goes through the file: mbd2d-solve writes the
    Python run's CSV, every column, in dynamics (dopri5 and generalized-alpha where the
    model allows), and statics and inverse dynamics where the model has them."""
    name, model = contact_models()[k]
    methods = ["dopri5"] if name == "pendulum" else ["dopri5", "generalized-alpha"]
    for method in methods:
        res = model.dynamics(t_end=0.3, steps=30, method=method)
        solve_and_compare(tmp_path, solver, model, res, f"{name}_{method}", t_end=0.3,
                          steps=30, analysis="dynamics", method=method, outputs=ALL)
    if name == "pin":
        res = model.statics()
        solve_and_compare(tmp_path, solver, model, res, f"{name}_statics", analysis="statics",
                          outputs=["multipliers", "reactions", "efforts"])


def test_joint_friction_on_the_band_path_runs_in_mbd2d_solve(tmp_path: Path, solver: str):
    """The 100-loop chain with three rubbing pins (603 coordinates: the band path with joint
    friction): mbd2d-solve writes the Python run's CSV, every column, for dopri5 and for
    the driven chain's inverse dynamics."""
    sys.path.insert(0, str(ROOT / "tests"))
    from test_friction_band import rubbing_chain
    pins = ("O0", "L50", "R99")
    free = rubbing_chain(100, pins)
    res = free.dynamics(t_end=0.2, steps=4)
    assert res.stats["solver"] == "banded"
    solve_and_compare(tmp_path, solver, free, res, "chain_dynamics", t_end=0.2, steps=4,
                      analysis="dynamics", method="dopri5", outputs=ALL)
    driven = rubbing_chain(100, pins, model="regularized", driven=True)
    res = driven.inverse_dynamics(t_end=0.5, steps=5)
    solve_and_compare(tmp_path, solver, driven, res, "chain_inverse", t_end=0.5, steps=5,
                      analysis="inverse-dynamics", outputs=ALL)


def test_header_lists_every_kind_and_the_docs_describe_them(tmp_path: Path) -> None:
    """The file's header and docs/mbd-format.md name every joint, driver and force kind the
    format holds, with its code."""
    mbd = tmp_path / "m.mbd"
    mbd2d.load(EX / "fourbar_grashof.toml").export(mbd, t_end=1.0, steps=10)
    text = mbd.read_text()
    doc = (ROOT / "docs" / "mbd-format.md").read_text()
    types = set(J.joint_keys()) | {"absolute driver", "relative-angle driver",
                                   "relative-distance driver"} | set(FORCE_KEYS) | \
        set(CONTACT_TYPES) | {"friction"}
    listed = {t for _, t, _ in JOINT_KINDS + DRIVER_KINDS + FORCE_KINDS + ELEMENT_KINDS}
    assert listed == types
    for code, kind, _ in JOINT_KINDS + DRIVER_KINDS + FORCE_KINDS + ELEMENT_KINDS:
        assert f"{code} {kind}" in text, kind
        assert f"| {code} | `{kind}` |" in doc, kind
    for key in ("analysis", "every", "method", "rtol", "max_steps", "outputs", "gravity",
                "labels", "forces", "fparams"):
        assert f"`{key}" in doc, key


@pytest.mark.parametrize("change, needle", [
    (("analysis inverse-dynamics", "analysis sideways"), "unknown analysis"),
    (("method dopri5", "method euler"), "unknown method"),
    (("rtol ", "rtol 5.0 #"), "rtol must be 0"),
    (("h ", "h 1e-20 #"), "h must be 0"),
    (("rho_inf ", "rho_inf 2.0 #"), "rho_inf must be -1"),
    (("max_steps ", "max_steps -3 #"), "max_steps must be a whole number"),
    (("every ", "every 0 #"), "every must be a whole number"),
    (("outputs ", "outputs energy torque #"), "unknown output"),
    (("forces 0", "forces 100000"), "more force lines than the file has left"),
    (("forces 0", "forces 1"), "bad force line"),
    (("labels 9", "labels 5"), "more labels than the label count"),
    (("gravity ", "gravity 1.0 #"), "gravity"),
])
def test_bad_settings_name_their_line(tmp_path: Path, solver: str, change: tuple,
                                      needle: str) -> None:
    model = mbd2d.load(EX / "fourbar_masses.toml")
    mbd = tmp_path / "d.mbd"
    analysis = "inverse-dynamics" if "analysis" in change[0] else "dynamics"
    model.export(mbd, t_end=1.0, steps=10, analysis=analysis, outputs=["energy"])
    lines = mbd.read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith(change[0]))
    if change[1].endswith("#"):
        lines[i] = change[1][:-1]
    else:
        lines[i] = lines[i].replace(change[0], change[1])
    bad = tmp_path / "bad.mbd"
    bad.write_text("\n".join(lines) + "\n")
    r = subprocess.run([solver, str(bad), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr and r.stderr.startswith("mbd2d-solve: "), r.stderr


def test_dynamics_needs_masses_in_the_file(tmp_path: Path, solver: str) -> None:
    model = mbd2d.load(EX / "pendulum_spring.toml")
    mbd = tmp_path / "d.mbd"
    model.export(mbd, t_end=1.0, steps=10, analysis="dynamics")
    lines = [" ".join(ln.split()[:4]) if ln.startswith("bar ") else ln
             for ln in mbd.read_text().splitlines()]
    mbd.write_text("\n".join(lines) + "\n")
    r = subprocess.run([solver, str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "needs the masses" in r.stderr


@pytest.mark.parametrize("kwargs, match", [
    ({"analysis": "kinematics", "outputs": ["reactions"]}, "need multipliers"),
    ({"analysis": "statics", "outputs": ["energy"]}, "no energy"),
    ({"analysis": "dynamics", "method": "baumgarte-rk4"}, "give h"),
    ({"analysis": "sideways"}, "unknown analysis"),
    ({"analysis": "dynamics", "outputs": ["torque"]}, "unknown output"),
    ({"analysis": "inverse-dynamics", "t_end": None}, "needs t_end"),
])
def test_export_checks_like_a_run(tmp_path: Path, kwargs: dict, match: str) -> None:
    model = mbd2d.load(EX / "fourbar_masses.toml")
    kw = {"t_end": 1.0, "steps": 10, **kwargs}
    with pytest.raises(mbd2d.ModelError, match=match):
        model.export(tmp_path / "x.mbd", **kw)


def test_the_runs_warnings_on_standard_error(tmp_path: Path, solver: str) -> None:
    """mbd2d-solve says what the Python path warns: the N-four-bar's passage through its
    collinear position at t = pi/2 (theta = pi/2 - t: closed form), and the redundant row of
    the parallelogram with an extra link (the row Python's run names)."""
    sys.path.insert(0, str(EX))
    import nfourbar
    mbd = tmp_path / "chain.mbd"
    nfourbar.build(2).export(mbd, t_end=4.0, steps=100)
    run = subprocess.run([solver, str(mbd), str(tmp_path / "chain.csv")], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    text = run.stderr.split("at t = ")[1]
    assert "passed through 1 singular configuration(s)" in run.stderr
    assert float(text.split()[0]) == pytest.approx(np.pi / 2, abs=1e-5)
    par = mbd2d.load(EX / "parallelogram_extra_link.toml")
    with pytest.warns(mbd2d.RedundantConstraintWarning):
        rows = par.kinematics(1.0, 4).stats["redundant_rows"]
    par.export(tmp_path / "par.mbd", t_end=1.0, steps=4)
    run = subprocess.run([solver, str(tmp_path / "par.mbd"), str(tmp_path / "par.csv")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert f"warning: redundant constraints: {', '.join(rows)} repeat" in run.stderr
