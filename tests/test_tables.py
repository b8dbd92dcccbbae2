"""Tables in functions of time: y(t) through points (t_k, y_k), for drivers from measured
motion and forces from a recorded history.

References computed here without mbd2d: polynomials the interpolation must reproduce
exactly, sin data whose errors must fall at the interpolation's orders, the slider-crank's
closed form through a tabulated crank angle, and central differences of runs for the
sensitivities to the table's values.
"""
from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.description import toml_io
from test_motion_laws import slider_chain
from test_standalone import find_solver


def values(tab: tuple[np.ndarray, np.ndarray], t: np.ndarray, extra: dict | None = None
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """f, f', f'' of a function with the table, through a driven slider's kinematics-free
    constraint pieces (the core's own evaluation: phi, nu, gamma of an absolute driver)."""
    m = mbd2d.Model("probe")
    m.add_body("s", q0=[0.0, 0.0, 0.0])
    m.add_driver("absolute", body="s", coordinate="x",
                 f={"table": {"t": list(tab[0]), "y": list(tab[1])}, **(extra or {})})
    q, qd = np.zeros(3), np.zeros(3)
    out = np.array([[-m.phi(q, tk)[0], m.nu(q, tk)[0], m.gamma(q, qd, tk)[0]] for tk in t])
    return out[:, 0], out[:, 1], out[:, 2]


def test_quartic_data_are_reproduced_exactly() -> None:
    """Five or more uneven points of a quartic: f, f', f'' are the quartic's between the
    points, the line with the end slope outside."""
    tk = np.array([0.0, 0.07, 0.31, 0.4, 0.66, 0.9, 1.0, 1.3])
    p = np.polynomial.Polynomial([0.2, -0.4, 1.1, 0.7, -0.9])
    t = np.linspace(-0.3, 1.6, 97)
    f, f1, f2 = values((tk, p(tk)), t)
    inside = (t >= tk[0]) & (t < tk[-1])
    np.testing.assert_allclose(f[inside], p(t[inside]), rtol=0, atol=1e-13)
    np.testing.assert_allclose(f1[inside], p.deriv()(t[inside]), rtol=0, atol=1e-11)
    np.testing.assert_allclose(f2[inside], p.deriv(2)(t[inside]), rtol=0, atol=1e-9)
    for end, sel in ((tk[0], t < tk[0]), (tk[-1], t >= tk[-1])):
        np.testing.assert_allclose(f[sel], p(end) + p.deriv()(end) * (t[sel] - end),
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(f1[sel], p.deriv()(end), rtol=0, atol=1e-11)
        assert np.all(f2[sel] == 0.0)


def test_errors_fall_at_the_interpolations_orders() -> None:
    """sin(3t) sampled at n uneven points: the errors of f, f', f'' fall like h^5, h^4, h^3
    (measured 32x, 16x, 8x per halving)."""
    rng = np.random.default_rng(4)
    errs = []
    for n in (21, 41, 81, 161):
        tk = np.linspace(0.0, 2.0, n)
        tk[1:-1] += rng.uniform(-0.2, 0.2, n - 2) * (tk[1] - tk[0])   # uneven
        t = np.linspace(0.0, 2.0, 1001)[:-1]
        f, f1, f2 = values((tk, np.sin(3 * tk)), t)
        errs.append([np.abs(f - np.sin(3 * t)).max(), np.abs(f1 - 3 * np.cos(3 * t)).max(),
                     np.abs(f2 + 9 * np.sin(3 * t)).max()])
    e = np.array(errs)
    rate = np.log2(e[:-1] / e[1:])
    assert np.all(rate[:, 0] > 4.5) and np.all(rate[:, 1] > 3.5) and np.all(rate[:, 2] > 2.5), \
        rate


def test_twice_differentiable_at_the_points() -> None:
    """Left and right limits of f, f', f'' agree at every inner point (C2), to the
    differences' truncation."""
    tk = np.array([0.0, 0.2, 0.35, 0.7, 0.8, 1.1, 1.5])
    yk = np.array([0.0, 0.4, -0.1, 0.3, 0.9, 0.2, -0.5])
    d = 1e-7
    for t in tk[1:-1]:
        lo = np.array(values((tk, yk), np.array([t - d]))).ravel()
        hi = np.array(values((tk, yk), np.array([t + d]))).ravel()
        for k, tol in enumerate((1e-5, 1e-4, 1e-2)):    # (f, f', f'': O(d) apart)
            assert abs(lo[k] - hi[k]) < tol, (t, k, lo[k], hi[k])


def crank_table(n: int) -> tuple[list[float], list[float]]:
    """theta(t) = 0.3 + 2 t + 0.4 sin(5 t), sampled at n points over [0, 1.2]."""
    t = np.linspace(0.0, 1.2, n)
    return list(t), list(0.3 + 2 * t + 0.4 * np.sin(5 * t))


def slider_crank(n: int) -> mbd2d.Model:
    m = mbd2d.load(Path(__file__).resolve().parents[1] / "examples" / "slider_crank.toml")
    t, y = crank_table(n)
    m.drivers[0].f = mbd2d.TimeFunction(table=mbd2d.Table(tuple(t), tuple(y)))
    return m


def slider_exact(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The slider's x and x_ddot (examples/slider_crank.toml: crank 1, rod 3, offset 0.5)
    through the crank angle's closed form."""
    x, _, a = slider_chain(0.3 + 2 * t + 0.4 * np.sin(5 * t), 2 + 2 * np.cos(5 * t),
                           -10 * np.sin(5 * t), r=1.0, rod=3.0, e=0.5)
    return x, a


def test_tabulated_crank_drives_the_slider_crank() -> None:
    """A crank angle given as a table of n points: the slider's position and acceleration
    against the closed form, falling as the table is refined (the last row, the table's
    end, has the acceleration after it: the line's, 0)."""
    errs = []
    for n in (25, 49, 97):
        res = slider_crank(n).kinematics(1.2, 240)
        x, a = slider_exact(res.t)
        sl = res.body("slider")
        errs.append((np.abs(sl.x - x).max(), np.abs(sl.x_ddot - a)[:-1].max()))
        assert res.body("crank").theta_ddot[-1] == 0.0
    e = np.array(errs)
    assert e[-1, 0] < 1e-7 and e[-1, 1] < 1e-2
    assert np.all(e[:-1, 0] / e[1:, 0] > 20) and np.all(e[:-1, 1] / e[1:, 1] > 5)


def test_sensitivity_to_a_table_value() -> None:
    """d(slider x, x_dot, x_ddot)/d(y_k) against central differences of with_params runs."""
    m = slider_crank(25)
    names = ["driver.motor.f.table.y.6", "driver.motor.f.table.y.12"]
    assert all(n in m.parameters() for n in names)
    res = m.kinematics(1.2, 120, tol=1e-13, sensitivities=names)
    for j, name in enumerate(names):
        d = 1e-6
        v = m.parameters()[name]
        hi = m.with_params({name: v + d}).kinematics(1.2, 120, tol=1e-13)
        lo = m.with_params({name: v - d}).kinematics(1.2, 120, tol=1e-13)
        for got, a, b in ((res.dq_dp, hi.q, lo.q), (res.dqd_dp, hi.qd, lo.qd),
                          (res.dqdd_dp, hi.qdd, lo.qdd)):
            want = (a - b) / (2 * d)
            scale = np.abs(want).max()
            assert scale > 1e-3
            assert np.abs(got[:, :, j] - want).max() < 1e-6 * scale
        # local: nothing moves far from the point (three intervals either side)
        k = int(name.rsplit(".", 1)[1])
        tk = crank_table(25)[0]
        far = (res.t < tk[max(k - 4, 0)]) | (res.t > tk[min(k + 4, 24)])
        assert np.all(res.dq_dp[far, :, j] == 0.0)


def test_force_history_from_a_table_in_dynamics() -> None:
    """A block pushed by a tabulated force F(t) = 6 t (1 - t) on [0, 1] (a quadratic: the
    table is exact): x(t) = (t^3 - t^4/2)/m, against dopri5 to 1e-10."""
    tk = np.linspace(0.0, 1.0, 7)
    m = mbd2d.Model("pushed")
    m.gravity = (0.0, 0.0)
    m.add_body("block", q0=[0.0, 0.0, 0.0], mass=2.0, inertia=0.1)
    m.add_translational(["ground", "block"], [[0, 0], [0, 0]], [[1, 0], [1, 0]], name="g")
    m.add_point_force("block", [0.0, 0.0],
                      fx={"table": {"t": list(tk), "y": list(6 * tk * (1 - tk))}}, name="push")
    res = m.dynamics(1.0, 50, rtol=1e-11, atol=1e-13)
    x = (res.t**3 - res.t**4 / 2) / 2.0
    assert np.abs(res.body("block").x - x).max() < 1e-10


@pytest.mark.parametrize("table, needle", [
    ({"t": [0.0], "y": [1.0]}, "2 to"),
    ({"t": [0.0, 1.0], "y": [1.0]}, "one length"),
    ({"t": [0.0, 1.0, 1.0], "y": [1.0, 2.0, 3.0]}, "must increase"),
    ({"t": [0.0, 2.0, 1.0], "y": [1.0, 2.0, 3.0]}, "must increase"),
    ({"t": [0.0, float("nan")], "y": [1.0, 2.0]}, "t"),
    ({"t": [0.0, 1.0], "y": [1.0, float("inf")]}, "y"),
    ({"t": [0.0, 1.0]}, "must be a table"),
    ([[0.0, 1.0], [1.0, 2.0]], "must be a table"),
    ({"t": "0 1", "y": [1.0, 2.0]}, "list of numbers"),
])
def test_bad_tables_are_model_errors(table: object, needle: str) -> None:
    m = mbd2d.Model("m")
    m.add_body("b", q0=[0.0, 0.0, 0.0])
    with pytest.raises(mbd2d.ModelError, match=needle):
        m.add_driver("absolute", body="b", coordinate="x", f={"table": table})


def test_huge_table_times_are_refused_by_the_core() -> None:
    m = mbd2d.Model("m")
    m.add_body("b", q0=[0.0, 0.0, 0.0])
    m.add_driver("absolute", body="b", coordinate="x",
                 f={"table": {"t": [0.0, 1e13], "y": [0.0, 1.0]}})
    with pytest.raises(mbd2d.ModelError, match="table time 1 must be within"):
        m.kinematics(1.0, 10)


def test_round_trip_and_the_standalone_program(tmp_path: Path) -> None:
    """TOML keeps the table; mbd2d-solve gives Python's CSV (with a table sensitivity)."""
    m = slider_crank(13)
    again = mbd2d.loads(toml_io.dumps(m))
    assert again.parameters() == m.parameters()
    names = ["driver.motor.f.table.y.5"]
    mbd = tmp_path / "m.mbd"
    m.export(mbd, t_end=1.2, steps=30, sensitivities=names)
    out = tmp_path / "f.csv"
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    py = tmp_path / "p.csv"
    m.kinematics(1.2, 30, sensitivities=names).to_csv(py, sensitivities=True)
    assert out.read_text() == py.read_text()
    assert math.isfinite(float(out.read_text().splitlines()[-1].split(",")[-1]))


def test_a_table_from_a_file(tmp_path: Path) -> None:
    """table = { file = ... } next to the model (a header, comments, commas or spaces,
    columns picked), the same model as the inline table; bad files name file and line."""
    t, y = crank_table(25)
    (tmp_path / "data").mkdir()
    rows = "\n".join(f"{a:.17g}, 0.0, {b:.17g}" if i % 2 else f"{a:.17g} 0.0 {b:.17g}"
                     for i, (a, b) in enumerate(zip(t, y)))
    (tmp_path / "data" / "crank.csv").write_text("time, dummy, angle\n# measured\n" + rows + "\n")
    text = (Path(__file__).resolve().parents[1] / "examples" / "slider_crank.toml").read_text()
    text = text.replace("f = { poly = [0.0, 6.283185307179586] }",
                        'f = { table = { file = "data/crank.csv", columns = [0, 2] } }')
    assert "data/crank.csv" in text
    (tmp_path / "m.toml").write_text(text)
    m = mbd2d.load(tmp_path / "m.toml")
    ref = slider_crank(25)
    assert m.parameters() == ref.parameters()
    assert mbd2d.Table.from_file(tmp_path / "data" / "crank.csv", columns=(0, 2)) == \
        ref.drivers[0].f.table
    np.testing.assert_array_equal(m.kinematics(1.2, 24).q, ref.kinematics(1.2, 24).q)
    for body, needle in (("1 2 3\n3 x 4\n", "crank.csv:2: not a row of numbers"),
                         ("1 2 3\n3 4\n", "crank.csv:2: 2 columns, column 2 asked")):
        (tmp_path / "data" / "crank.csv").write_text(body)
        with pytest.raises(mbd2d.ModelError, match=needle):
            mbd2d.load(tmp_path / "m.toml")
    (tmp_path / "m.toml").write_text(text.replace("data/crank.csv", "data/none.csv"))
    with pytest.raises(mbd2d.ModelError, match="cannot read the table file"):
        mbd2d.load(tmp_path / "m.toml")
    with pytest.raises(mbd2d.ModelError, match="base must be a directory path"):
        mbd2d.loads(text, base=5)
