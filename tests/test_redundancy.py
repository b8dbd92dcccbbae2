"""Degrees of freedom, redundant constraints, and contradicting constraints."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES

W = 2.0 * np.pi


def load(name: str) -> mbd2d.Model:
    return mbd2d.load(EXAMPLES / f"{name}.toml")


@pytest.mark.parametrize("name, coords, eqs, rank, mobility, rows", [
    ("door_two_hinges", 3, 5, 3, 1, ["upper.x", "upper.y"]),
    ("parallelogram_extra_link", 12, 13, 12, 1, None),
    ("fourbar_redundant", 9, 10, 9, 1, ["tie.distance"]),
    ("fourbar_grashof", 9, 9, 9, 1, []),
])
def test_dof_report(name: str, coords: int, eqs: int, rank: int, mobility: int,
                    rows: list[str] | None) -> None:
    rep = load(name).analyze_dof()
    assert (rep.coordinates, rep.equations, rep.rank, rep.dof, rep.mobility) == \
        (coords, eqs, rank, coords - rank, mobility)
    assert len(rep.redundant_rows) == eqs - rank
    if rows is not None:
        assert rep.redundant_rows == rows
    text = str(rep)
    assert f"rank of J          {rank}" in text


def test_parallelogram_extra_link_names_one_of_its_joints() -> None:
    rep = load("parallelogram_extra_link").analyze_dof()
    assert len(rep.redundant_constraints) == 1
    assert rep.redundant_constraints[0] in {"O1", "O2", "O3", "A1", "A2", "A3"}


def test_dof_of_an_undriven_mechanism() -> None:
    m = load("fourbar_grashof")
    m.drivers.clear()
    rep = m.analyze_dof()
    assert (rep.equations, rep.rank, rep.dof, rep.mobility) == (8, 8, 1, 1)


def test_door_runs_with_a_warning_and_matches_the_closed_form() -> None:
    with pytest.warns(mbd2d.RedundantConstraintWarning, match="upper.x, upper.y"):
        res = load("door_two_hinges").kinematics(t_end=1.0, steps=100)
    th = 0.8 * np.sin(W * res.t)
    d = res.body("door")
    assert_allclose(d.theta, th, atol=1e-12)
    assert_allclose(d.x, 0.45 * np.cos(th), atol=1e-12)
    assert_allclose(d.y_dot, 0.45 * np.cos(th) * 0.8 * W * np.cos(W * res.t), atol=1e-10)
    assert res.stats["redundant_rows"] == ["upper.x", "upper.y"]


def test_redundant_four_bar_equals_the_plain_one() -> None:
    plain = load("fourbar_grashof").kinematics(t_end=1.0, steps=200)
    with pytest.warns(mbd2d.RedundantConstraintWarning, match="tie.distance"):
        red = load("fourbar_redundant").kinematics(t_end=1.0, steps=200)
    assert_allclose(red.q, plain.q, atol=1e-10)
    assert_allclose(red.qd, plain.qd, atol=1e-9)
    assert_allclose(red.qdd, plain.qdd, atol=1e-8)


def test_parallelogram_with_extra_link_keeps_cranks_parallel() -> None:
    with pytest.warns(mbd2d.RedundantConstraintWarning):
        res = load("parallelogram_extra_link").kinematics(t_end=1.0, steps=100)
    th = np.pi / 2 + 0.6 * np.sin(W * res.t)
    for c in ("crank1", "crank2", "crank3"):
        assert_allclose(res.body(c).theta, th, atol=1e-12)
    assert_allclose(res.body("coupler").x, 1.0 + np.cos(th), atol=1e-12)


def test_inconsistent_hinges_are_named_with_the_residual() -> None:
    text = (EXAMPLES / "door_two_hinges.toml").read_text().replace(
        'points = [[0.0, 0.0], [-0.45, 0.0]]\n\n[[driver]]',
        'points = [[0.0, 0.1], [-0.45, 0.0]]\n\n[[driver]]')
    m = mbd2d.loads(text)
    with pytest.raises(mbd2d.InconsistentConstraintsError, match=r"upper\.y") as err:
        m.kinematics(t_end=1.0, steps=10)
    assert {"lower", "upper"} <= set(err.value.constraints)
    assert err.value.residual == pytest.approx(0.05, rel=1e-6)
    assert "residual" in str(err.value)
    with pytest.raises(mbd2d.InconsistentConstraintsError, match="lower"):
        m.analyze_dof()


def test_one_driver_too_many_that_contradicts() -> None:
    text = (EXAMPLES / "slider_crank.toml").read_text() + (
        '\n[[driver]]\nname = "extra"\ntype = "absolute"\nbody = "rod"\ncoordinate = "x"\n'
        'f = 1.0\n')
    with pytest.raises(mbd2d.InconsistentConstraintsError,
                       match=r"extra\.x \(1 redundant equation\(s\): 10 equations, rank 9\)"):
        mbd2d.loads(text).kinematics(t_end=1.0, steps=10)


def twin_driver(extra_poly: str) -> mbd2d.Model:
    """The slider-crank with a second driver on the crank angle."""
    return mbd2d.loads((EXAMPLES / "slider_crank.toml").read_text() + (
        '\n[[driver]]\nname = "twin"\ntype = "absolute"\nbody = "crank"\ncoordinate = "theta"\n'
        f'f = {{ poly = [0.0, 6.283185307179586, {extra_poly}] }}\n'))


def test_redundant_drivers_that_part_ways_during_the_run() -> None:
    """Two drivers that agree in position, velocity and acceleration at t = 0
    (2 pi t and 2 pi t + t^3) and then part ways: stopped after t = 0, both named."""
    with pytest.raises(mbd2d.InconsistentConstraintsError, match=r"twin\.theta") as err:
        twin_driver("0.0, 1.0").kinematics(t_end=1.0, steps=100)
    assert err.value.t > 0.0
    assert {"motor", "twin"} <= set(err.value.constraints)
    assert len(err.value.results.t) >= 1


def test_redundant_drivers_contradicting_in_acceleration() -> None:
    """2 pi t and 2 pi t + t^2 agree in position and velocity at t = 0 but not in
    acceleration: reported at t = 0, at acceleration level."""
    with pytest.raises(mbd2d.InconsistentConstraintsError, match="at acceleration level"):
        twin_driver("1.0").kinematics(t_end=1.0, steps=100)


def test_undriven_with_redundancy_is_not_determined() -> None:
    m = load("door_two_hinges")
    m.drivers.clear()
    with pytest.raises(mbd2d.ModelError, match="J has rank 2 for 3 coordinates"):
        m.kinematics(t_end=1.0, steps=10)


def test_check_command_prints_the_report() -> None:
    r = subprocess.run([sys.executable, "-m", "mbd2d", "check",
                        str(EXAMPLES / "door_two_hinges.toml")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert "degrees of freedom 0" in r.stdout
    assert "upper.x" in r.stdout and "upper.y" in r.stdout


@pytest.mark.parametrize("n, extra", [(5, 2), (400, 5)])
def test_dof_of_a_large_chain_with_redundant_links(n: int, extra: int) -> None:
    """The N-four-bar (a chain of parallelograms, one degree of freedom) with `extra` middle
    cranks, each a parallelogram's third link (one redundant equation each, by construction):
    rank = equations - extra, one degree of freedom, mobility 1 with and without the driver.
    N = 400 (2403 coordinates and more) takes the band assembly and rank analysis (the dense
    ones took 44 s there; no n x n array now), N = 5 (42 coordinates) the dense ones."""
    sys.path.insert(0, str(EXAMPLES))
    from nfourbar import build
    for driven in (True, False):
        m = build(n, driven=driven)
        for k in range(extra):
            x = 2 * k + 0.5                            # between pivots 2k and 2k + 1
            m.add_body(f"mid{k}", q0=[x, 0.5, np.pi / 2])
            m.add_revolute(["ground", f"mid{k}"], [[x, 0.0], [-0.5, 0.0]], name=f"M{k}")
            m.add_revolute([f"mid{k}", f"coupler{2 * k}"], [[0.5, 0.0], [0.0, 0.0]],
                           name=f"N{k}")
        rep = m.analyze_dof()
        nq = 3 * (2 * n + 1 + extra)
        neq = 2 * (3 * n + 1) + 4 * extra + (1 if driven else 0)
        assert (rep.coordinates, rep.equations) == (nq, neq)
        assert rep.rank == neq - extra and len(rep.redundant_rows) == extra
        assert rep.dof == (0 if driven else 1) and rep.mobility == 1


@pytest.mark.parametrize("method,opts", [("dopri5", {"rtol": 1e-10, "atol": 1e-12}),
                                         ("partitioned", {"rtol": 1e-10, "atol": 1e-12}),
                                         ("generalized-alpha", {"h": 1e-4}),
                                         ("baumgarte-rk4", {"h": 1e-3})])
def test_band_rank_analysis_keeps_the_redundant_parallelogram_well_posed(method, opts):
    """Three parallel cranks under one coupler (examples/parallelogram_extra_link.toml,
    1 kg bars with inertia 0.1) started upright (theta = 1.5708) and turning at 1 rad/s. Its
    one dependency is the extra crank's self-stress, forces along the cranks: at upright the
    x rows weigh cos(theta) ~ 4e-6 in it. The band rank analysis left out the dependency's
    last row in its order, O1.x, which left the other rows nearly dependent (started at
    rest, dopri5 stopped at t = 2.9e-3: the constraints could not be satisfied;
    generalized-alpha and partitioned as well; here dopri5 ran 1.2e-7 off). It now leaves
    out the heaviest row of the dependency (as the dense QR does), and
    both paths follow J th'' = -c g cos(th), J = 3 (0.1 + 0.25) + 1, c = 3 / 2 + 1
    (scipy DOP853 at 1e-12)."""
    from scipy.integrate import solve_ivp
    import dataclasses
    m = load("parallelogram_extra_link")
    m.drivers.clear()
    for i, b in enumerate(m.bodies):
        v0 = [-0.5, 0.0, 1.0] if b.name.startswith("crank") else [-1.0, 0.0, 0.0]
        m.bodies[i] = dataclasses.replace(b, mass=1.0, inertia=0.1, v0=tuple(v0))
    inertia, c, g = 3 * 0.35 + 1.0, 2.5, 9.81
    for solver in ("dense", "banded"):
        with pytest.warns(mbd2d.RedundantConstraintWarning):
            res = m.dynamics(0.5, 10, method=method, solver=solver, **opts)
        th0, w0 = res.body("crank1").theta[0], res.body("crank1").theta_dot[0]
        ref = solve_ivp(lambda t, y: [y[1], -c * g * np.cos(y[0]) / inertia], [0.0, 0.5],
                        [th0, w0], method="DOP853", rtol=1e-12, atol=1e-14,
                        dense_output=True)
        th = np.array([res.body(f"crank{k}").theta for k in (1, 2, 3)])
        assert np.abs(th - ref.sol(res.t)[0]).max() < (1e-7 if "h" not in opts else 1e-5)
        rows = res.stats["redundant_rows"]
        assert len(rows) == 1 and rows[0].endswith(".y"), rows
